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

__all__ = ["MIN_SHADE", "plot_residuals"]

#: Narrowest window drawn for an event or a labelled contact, as a fraction of the log's
#: duration: a 50 ms impact over a 58 s axis would be a hairline.
MIN_SHADE = 0.004


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
        Thresholds [N m]: the band within plus and minus the contact threshold filled
        light grey (the standstill margin's rises at each velocity reversal show as the
        band's light bulges, not as black lines over the residual), the collision
        threshold dotted grey at plus and minus.
    events : sequence of ContactEvent
        Shaded over their windows (contact gold, collision red), each at least
        :data:`MIN_SHADE` of the log's duration wide, centred on it.
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
        grey over the full height, as wide as events at the least.

    Returns
    -------
    matplotlib.figure.Figure
    """
    import matplotlib.pyplot as plt
    from matplotlib.patches import Patch

    n = r.shape[1]
    names = list(joint_names) if joint_names is not None else [f"joint {j + 1}" for j in range(n)]
    fig, axes = plt.subplots(n, 1, sharex=True, figsize=(10, 1.6 * n + 0.8), squeeze=False)
    bins = max(1, max_points // 2)

    def drawn(y: NDArray[np.float64]) -> tuple[NDArray[np.float64], NDArray[np.float64]]:
        k = envelope_indices(y, bins)  # every spike and extreme kept
        return t[k], y[k]

    t0 = float(t[0]) if t.size else 0.0
    t = t - t0  # from the log's start (a log of absolute stamps too)
    least = max(1e-3, MIN_SHADE * (float(t[-1]) if t.size else 0.0))

    def shown(a: float, b: float) -> tuple[float, float]:
        """``[a, b]`` [s], widened about its middle to ``least`` at the least."""
        grow = max(0.0, least - (b - a)) / 2.0
        return a - grow, b + grow

    labelled = [shown(a - t0, b - t0) for a, b in labelled]
    shades = [(shown(e.start - t0, e.end - t0), e.level) for e in events]
    for j in range(n):
        ax = axes[j, 0]
        for k, (a, b) in enumerate(labelled):
            ax.axvspan(
                a, b, facecolor="none", edgecolor=COLOURS["label"],
                hatch="///", lw=0, label="labelled contact" if k == 0 else None,
            )  # fmt: skip
        for (a, b), level in shades:
            ax.axvspan(a, b, color=COLOURS[level], alpha=0.25, lw=0)
        tt, y = drawn(contact[:, j])
        ax.fill_between(
            tt, -y, y, color=COLOURS["reference"], alpha=0.1, lw=0, label="contact threshold"
        )
        ax.plot(tt, y, tt, -y, color=COLOURS["reference"], alpha=0.35, lw=0.5)
        tt, y = drawn(collision[:, j])
        line = dict(color=COLOURS["reference"], ls=":", lw=0.6, alpha=0.35)
        ax.plot(tt, y, **line, label="collision threshold")
        ax.plot(tt, -y, **line)
        ax.plot(*drawn(r[:, j]), color=COLOURS["residual"], lw=0.9, label="residual")
        if tau_ext is not None:
            ax.plot(
                *drawn(tau_ext[:, j]), color=COLOURS["external"], lw=0.8,
                label="true external torque",
            )  # fmt: skip
        ax.set_ylabel(f"{names[j]}\n[N m]", fontsize=8)
        ax.tick_params(labelsize=7)
    axes[-1, 0].set_xlabel("time from the log's start [s]")
    fig.suptitle(title or "momentum observer: residual, thresholds and events", fontsize=10)
    handles, labels = axes[0, 0].get_legend_handles_labels()
    for level in ("contact", "collision", "load"):  # the events' shading, those drawn
        if any(e.level == level for e in events):
            handles.append(Patch(color=COLOURS[level], alpha=0.25, lw=0))
            labels.append(f"{level} event")
    top = 1.0 - 0.45 / fig.get_figheight()  # the legend above the axes, over no data
    fig.legend(handles, labels, loc="upper center", ncol=len(labels), fontsize=7,
               frameon=False, bbox_to_anchor=(0.5, top))  # fmt: skip
    tight_layout(fig, rect=(0, 0, 1, top - 0.1 / fig.get_figheight()))
    return fig
