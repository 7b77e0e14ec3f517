"""Figures of measured against predicted joint torques (Gaz et al. 2019, Fig. 3).

matplotlib is imported inside the functions (never by ``import dynid``); the functions
return a Figure and never show it. Use the ``Agg`` backend for files.
"""

from __future__ import annotations

from collections.abc import Mapping, Sequence
from typing import TYPE_CHECKING

import numpy as np
from numpy.typing import ArrayLike, NDArray

from ..friction.validation import Validation
from .envelope import envelope_indices
from .layout import tight_layout
from .style import COLOURS

if TYPE_CHECKING:  # pragma: no cover
    from matplotlib.axes import Axes
    from matplotlib.figure import Figure

__all__ = ["plot_rms_comparison", "plot_torque_validation", "plot_validation_rms"]

_MEASURED = dict(color=COLOURS["measured"], lw=0.6, label="measured")
_NO_FRICTION = dict(color=COLOURS["no_friction"], lw=1.1, label="model, no friction")
_FRICTION = dict(color=COLOURS["model"], lw=1.1, ls="--", label="model + friction")


def _gaps(t: NDArray[np.float64]) -> NDArray[np.intp]:
    """Where the times ``t`` [s] jump by more than ten median steps (pieces of a log cut at
    its gaps, one after another): the indices before which a line is broken."""
    dt = np.diff(t)
    if dt.size == 0:
        return np.zeros(0, dtype=np.intp)
    return np.flatnonzero(dt > 10.0 * float(np.median(dt))) + 1


def plot_torque_validation(
    validation: Validation,
    *,
    joint_names: Sequence[str] | None = None,
    max_points: int = 1600,
    title: str | None = None,
    fig: Figure | None = None,
    t0: float | None = None,
) -> Figure:
    """Per joint: measured and predicted torques (left) and prediction errors (right).

    Parameters
    ----------
    validation : Validation
        From :func:`dynid.friction.validation.validate_torques`.
    joint_names : sequence of str, optional
        Row labels (default ``joint 1 .. n``).
    max_points : int
        Samples drawn per line, about: the smallest and the largest of each of
        ``max_points / 2`` bins of consecutive samples (:mod:`dynid.plots.envelope`; every
        spike stays, about two points per pixel column of the torque panels at 100 dpi),
        every sample of a shorter log; metrics use every sample.
    title : str, optional
    fig : Figure, optional
        Drawn into (cleared first); a new figure by default.
    t0 : float, optional
        The log's first time stamp [s], from which times are drawn (default: the first
        sample's; a held-out block's log's, so that the block sits at its place in it).

    Returns
    -------
    matplotlib.figure.Figure
        ``n`` rows of two axes; the samples' times from ``t0`` [s] on x (a log of absolute
        stamps, 86400 s and on, drawn from 0), the lines broken where the times jump
        (pieces between gaps), torque [N m] on y. Each error panel gives the RMS of each
        prediction.
    """
    import matplotlib.pyplot as plt

    log = validation.log
    n = log.n
    names = list(joint_names) if joint_names is not None else [f"joint {j + 1}" for j in range(n)]
    if fig is None:
        fig = plt.figure(figsize=(13, 1.9 * n + 0.8))
    else:
        fig.clear()
    axes = fig.subplots(n, 2, sharex=True, squeeze=False, gridspec_kw={"width_ratios": [3, 2]})
    start = float(log.t[0]) if t0 is None else float(t0)
    time = np.asarray(log.t, dtype=np.float64) - start  # from the log's start
    cut = _gaps(time)
    e0 = log.tau - validation.tau_model
    e1 = None if validation.tau_friction is None else e0 - validation.tau_friction

    def at(y: NDArray[np.float64]) -> tuple[NDArray[np.float64], NDArray[np.float64]]:
        """The times and values of ``y`` drawn: its envelope, broken at the gaps."""
        k = envelope_indices(y, max_points // 2, breaks=cut)
        broken = np.searchsorted(k, cut)  # a NaN where a piece ends
        return np.insert(time[k], broken, np.nan), np.insert(y[k], broken, np.nan)

    added = validation.added  # offsets are not friction
    for j in range(n):
        ax, axe = axes[j]
        ax.plot(*at(log.tau[:, j]), **_MEASURED)
        ax.plot(*at(validation.tau_model[:, j]), **_NO_FRICTION | {"label": f"model, no {added}"})
        if e1 is not None:
            ax.plot(*at(validation.tau_hat[:, j]), **_FRICTION | {"label": f"model + {added}"})
        ax.set_ylabel(f"{names[j]}\n[N m]")
        ax.grid(alpha=0.3)
        rms = f"RMS [N m]\nno {added} {validation.without_friction.rms[j]:.3f}"
        axe.plot(*at(e0[:, j]), color=_NO_FRICTION["color"], lw=0.8)
        if e1 is not None and validation.with_friction is not None:
            rms += f"\n+ {added} {validation.with_friction.rms[j]:.3f}"
            axe.plot(*at(e1[:, j]), color=_FRICTION["color"], lw=0.6, alpha=0.8)
        axe.axhline(0.0, color="0.5", lw=0.6)
        axe.grid(alpha=0.3)
        axe.yaxis.set_label_position("right")  # beside the data, not over it
        axe.set_ylabel(rms, fontsize=7, rotation=0, ha="left", va="center")
    axes[0, 0].set_title("joint torques [N m]", fontsize=10)
    axes[0, 1].set_title("error: measured - model [N m]", fontsize=10)
    handles, labels = axes[0, 0].get_legend_handles_labels()
    top = 1.0 - (0.6 if title else 0.3) / fig.get_figheight()  # room for the legend above
    fig.legend(handles, labels, loc="upper center", ncol=len(labels), fontsize=8,
               frameon=False, bbox_to_anchor=(0.5, top))  # fmt: skip
    axes[-1, 0].set_xlabel("time from the log's start [s]")
    axes[-1, 1].set_xlabel("time from the log's start [s]")
    if title:
        fig.suptitle(title, fontsize=11)
    tight_layout(fig, rect=(0, 0, 1, top - 0.1 / fig.get_figheight()))
    return fig


def plot_validation_rms(
    validation: Validation,
    *,
    joint_names: Sequence[str] | None = None,
    noise_std: float | None = None,
    title: str | None = None,
) -> Figure:
    """Per joint, the torque RMS error [N m] without and with friction, in the colours
    of :func:`plot_torque_validation` (:data:`~dynid.plots.style.COLOURS`).

    Returns
    -------
    matplotlib.figure.Figure
    """
    rms = {f"without {validation.added}": validation.without_friction.rms}
    colours = [COLOURS["no_friction"]]
    if validation.with_friction is not None:
        rms[f"with {validation.added}"] = validation.with_friction.rms
        colours.append(COLOURS["model"])
    return plot_rms_comparison(
        rms, joint_names=joint_names, noise_std=noise_std, title=title, colours=colours
    )


def plot_rms_comparison(
    rms: Mapping[str, ArrayLike],
    *,
    joint_names: Sequence[str] | None = None,
    noise_std: float | None = None,
    title: str | None = None,
    ax: Axes | None = None,
    colours: Sequence[str] | None = None,
) -> Figure:
    """Grouped bars of per-joint torque RMS [N m] for several predictions, on a log scale
    where one bar is 30 times another (the errors with friction at the noise beside those
    without it), the joint names slanted where they would overlap.

    Parameters
    ----------
    rms : mapping of str to array_like, shape (n,)
        Label -> per-joint RMS [N m] (e.g. without and with friction).
    joint_names : sequence of str, optional
    noise_std : float, optional
        Torque sensor noise [N m], drawn as a horizontal line.
    title : str, optional
    ax : Axes, optional
    colours : sequence of str, optional
        One colour per prediction (default: matplotlib's cycle).

    Returns
    -------
    matplotlib.figure.Figure
    """
    import matplotlib.pyplot as plt
    from matplotlib.figure import Figure

    if ax is None:
        fig, ax = plt.subplots(figsize=(8, 3.6))
    else:
        parent = ax.figure  # a Figure, or a SubFigure inside one: lay out the whole Figure
        fig = parent if isinstance(parent, Figure) else parent.figure
    vals = [np.asarray(v, dtype=float) for v in rms.values()]
    n = vals[0].shape[0]
    names = list(joint_names) if joint_names is not None else [f"{j + 1}" for j in range(n)]
    width = 0.8 / len(vals)
    x = np.arange(n)
    for k, (label, v) in enumerate(zip(rms, vals, strict=True)):
        colour = None if colours is None else colours[k]
        ax.bar(x + (k - (len(vals) - 1) / 2) * width, v, width, label=label, color=colour)
    if noise_std is not None:
        ax.axhline(
            noise_std, color=COLOURS["reference"], ls=":", lw=1.0,
            label=f"sensor noise {noise_std:g} N m",
        )  # fmt: skip
    long_names = max((len(s) for s in names), default=0) * n > 60  # they would overlap
    ax.set_xticks(
        x, names, rotation=30 if long_names else 0, ha="right" if long_names else "center"
    )
    ax.set_xlabel("joint")
    ax.set_ylabel("torque RMS error [N m]")
    positive = np.concatenate([v[np.isfinite(v) & (v > 0)] for v in vals])
    if positive.size and positive.max() > 30.0 * positive.min():  # a bar 30 x another: log
        ax.set_yscale("log")
    ax.grid(axis="y", alpha=0.3)
    ax.legend(fontsize=8, loc="upper left", bbox_to_anchor=(1.01, 1.0), frameon=False)
    if title:
        ax.set_title(title)
    fig.tight_layout()
    return fig
