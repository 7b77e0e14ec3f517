"""Figures of the momentum observer: residuals, thresholds and detected events.

matplotlib is imported inside the functions; they return a Figure and never show it.
"""

from __future__ import annotations

from collections.abc import Sequence
from typing import TYPE_CHECKING

import numpy as np
from numpy.typing import NDArray

from ..observer.detection import ContactEvent
from .envelope import envelope_indices
from .layout import tight_layout
from .style import COLOURS

if TYPE_CHECKING:  # pragma: no cover
    from matplotlib.figure import Figure

__all__ = ["plot_residuals"]


def plot_residuals(
    t: NDArray[np.float64],
    r: NDArray[np.float64],
    contact: NDArray[np.float64],
    collision: NDArray[np.float64],
    *,
    events: Sequence[ContactEvent] = (),
    tau_ext: NDArray[np.float64] | None = None,
    joint_names: Sequence[str] | None = None,
    max_points: int = 20000,
    title: str | None = None,
    labelled: Sequence[tuple[float, float]] = (),
) -> Figure:
    """One panel per joint: the residual over time with its thresholds and the events.

    Parameters
    ----------
    t : ndarray, shape (N,)
        [s], the log's own stamps; drawn from the first (``t - t[0]``), the events and
        labelled contacts with them.
    r : ndarray, shape (N, n)
        Residual [N m].
    contact, collision : ndarray, shape (N, n)
        Thresholds [N m] (drawn at plus and minus).
    events : sequence of ContactEvent
        Shaded over their windows (contact orange, collision red).
    tau_ext : ndarray, shape (N, n), optional
        The true external torques (a simulated contact), drawn thin.
    joint_names : sequence of str, optional
    max_points : int
        Samples drawn per curve at most: of a longer log, each bin's smallest and largest
        sample (:func:`~dynid.plots.envelope.envelope_indices`), so that a contact of a
        few samples stays on the figure.
    title : str, optional
    labelled : sequence of (float, float)
        Labelled contacts ``(start, end)`` [s] (:mod:`dynid.observer.scoring`), hatched
        grey over the full height.

    Returns
    -------
    matplotlib.figure.Figure
    """
    import matplotlib.pyplot as plt

    n = r.shape[1]
    names = list(joint_names) if joint_names is not None else [f"joint {j + 1}" for j in range(n)]
    fig, axes = plt.subplots(n, 1, sharex=True, figsize=(10, 1.6 * n + 0.8), squeeze=False)
    bins = max(1, max_points // 2)

    def drawn(y: NDArray[np.float64]) -> tuple[NDArray[np.float64], NDArray[np.float64]]:
        k = envelope_indices(y, bins)  # every spike and extreme kept
        return t[k], y[k]

    t0 = float(t[0]) if t.size else 0.0
    t = t - t0  # from the log's start (a log of absolute stamps too)
    labelled = [(a - t0, b - t0) for a, b in labelled]
    for j in range(n):
        ax = axes[j, 0]
        for k, (a, b) in enumerate(labelled):
            ax.axvspan(
                a, max(b, a + 1e-3), facecolor="none", edgecolor=COLOURS["label"],
                hatch="///", lw=0, label="labelled contact" if k == 0 else None,
            )  # fmt: skip
        for e in events:
            ax.axvspan(
                e.start - t0, max(e.end, e.start + 1e-3) - t0,
                color=COLOURS["collision" if e.level == "collision" else "contact"],
                alpha=0.25, lw=0,
            )  # fmt: skip
        ax.plot(*drawn(r[:, j]), color=COLOURS["residual"], lw=0.9, label="residual")
        if tau_ext is not None:
            ax.plot(
                *drawn(tau_ext[:, j]), color=COLOURS["external"], lw=0.8,
                label="true external torque",
            )  # fmt: skip
        for th, style, label in ((contact, "--", "contact"), (collision, ":", "collision")):
            line = dict(color=COLOURS["reference"], ls=style, lw=0.7)
            tt, y = drawn(th[:, j])
            ax.plot(tt, y, **line, label=f"{label} threshold")
            ax.plot(tt, -y, **line)
        ax.set_ylabel(f"{names[j]}\n[N m]", fontsize=8)
        ax.tick_params(labelsize=7)
    axes[-1, 0].set_xlabel("time from the log's start [s]")
    fig.suptitle(title or "momentum observer: residual, thresholds and events", fontsize=10)
    handles, labels = axes[0, 0].get_legend_handles_labels()
    top = 1.0 - 0.45 / fig.get_figheight()  # the legend above the axes, over no data
    fig.legend(handles, labels, loc="upper center", ncol=len(labels), fontsize=7,
               frameon=False, bbox_to_anchor=(0.5, top))  # fmt: skip
    tight_layout(fig, rect=(0, 0, 1, top - 0.1 / fig.get_figheight()))
    return fig
