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

__all__ = [
    "plot_rms_comparison",
    "plot_torque_validation",
    "plot_validation_rms",
    "recording_of",
]

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


#: The space left between two recordings laid one after another, as a share of their time.
_SPACER = 0.04


def recording_of(t: NDArray[np.float64], spans: Sequence[tuple[float, float]]) -> NDArray[np.intp]:
    """The recording of each sample: ``t`` [s] (N,) holds the samples of the recordings of
    ``spans`` (each recording's first and last stamp [s]) one recording after another, in
    their order (pieces of a recording in time order); a recording ends where the times
    go back or leave its span (recordings stamped each from 0 too).

    Returns
    -------
    ndarray of int, shape (N,)
        The index into ``spans`` of each sample (-1 for samples after the last span's).
    """
    n = t.shape[0]
    out = np.full(n, -1, dtype=np.intp)
    back = np.concatenate([[False], np.diff(t) < 0.0])  # a new recording stamped earlier
    i = 0
    for k, (a, b) in enumerate(spans):
        if i >= n:
            break
        tol = 1e-9 * max(abs(a), abs(b), 1.0)
        leave = (t[i:] < a - tol) | (t[i:] > b + tol)
        leave[1:] |= back[i + 1 :]
        ends = np.flatnonzero(leave)
        j = n if ends.size == 0 else i + int(ends[0])
        out[i:j] = k
        i = j
    return out


def _one_after_another(
    t: NDArray[np.float64], spans: Sequence[tuple[float, float]]
) -> tuple[NDArray[np.float64], NDArray[np.float64], NDArray[np.intp]] | None:
    """The times [s] (N,) drawn with each recording from its own start, the recordings one
    after another with a space between; where each recording starts on that axis; and the
    indices where a recording begins (the lines broken there). Recordings each stamped
    from 0 are found where the pooling laid them (:func:`_pooled_spans`). None where a
    sample lies in no recording's span or a recording has no sample."""
    which = recording_of(t, spans)
    if np.any(which < 0) or np.unique(which).size != len(spans):
        spans = _pooled_spans(t, spans)
        which = recording_of(t, spans)
    if np.any(which < 0) or np.unique(which).size != len(spans):
        return None
    length = np.array([b - a for a, b in spans], dtype=np.float64)
    spacer = _SPACER * float(length.sum())
    at = np.concatenate([[0.0], np.cumsum(length + spacer)[:-1]])
    first = np.array([a for a, _ in spans], dtype=np.float64)
    k = np.maximum(which, 0)
    drawn = np.where(which >= 0, t - first[k] + at[k], np.nan)
    begins = np.flatnonzero(np.diff(which) != 0) + 1
    return drawn, at, begins


def _pooled_spans(
    t: NDArray[np.float64], spans: Sequence[tuple[float, float]]
) -> list[tuple[float, float]]:
    """The recordings' ``spans`` [s] where the pooled prediction laid them on one axis
    (:func:`~dynid.friction.pooled.joined_validation`: a recording that starts no later
    than the one before ends moved to begin one sample step after it; the step the median
    of ``t``'s)."""
    step = float(np.median(np.diff(t))) if t.size > 1 else 1.0
    out = [(float(spans[0][0]), float(spans[0][1]))] if spans else []
    for a, b in spans[1:]:
        end = out[-1][1]
        out.append((a, b) if a > end else (end + step, end + step + (b - a)))
    return out


def _mark_recordings(
    axes: Sequence[Axes], names: Sequence[str], at: NDArray[np.float64], length: NDArray[np.float64]
) -> None:
    """Each recording's name over the top panels, a boundary line between two recordings
    on every panel, and ticks that read each recording's own time from its start [s]."""
    from matplotlib.ticker import MaxNLocator

    step = MaxNLocator(nbins=max(2, int(8 / len(names))), steps=[1, 2, 2.5, 5, 10])
    local = np.asarray(step.tick_values(0.0, float(length.max())), dtype=np.float64)
    dt = float(local[1] - local[0]) if local.size > 1 else float(length.max()) or 1.0
    ticks, labels = [], []
    for a, d in zip(at, length, strict=True):
        own = np.arange(0.0, d + 1e-9 * max(d, 1.0), dt)
        ticks += list(a + own)
        labels += [f"{x:g}" for x in own]
    spacer = _SPACER * float(length.sum())
    for ax in axes:
        for a in at[1:]:
            ax.axvline(a - spacer / 2, color="0.3", lw=1.0, ls="-")
        ax.set_xticks(ticks, labels)
        ax.set_xlim(at[0] - spacer / 4, at[-1] + length[-1] + spacer / 4)
    for ax in axes[:2]:
        for a, d, name in zip(at, length, names, strict=True):
            ax.text(a + d / 2, 1.02, name, transform=ax.get_xaxis_transform(), ha="center",
                    va="bottom", fontsize=7, clip_on=False)  # fmt: skip


def plot_torque_validation(
    validation: Validation,
    *,
    joint_names: Sequence[str] | None = None,
    max_points: int = 1600,
    title: str | None = None,
    fig: Figure | None = None,
    t0: float | None = None,
    recordings: Sequence[tuple[str, float, float]] = (),
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
    recordings : sequence of (str, float, float)
        Of a validation of several recordings pooled one after another in the log
        (:func:`recording_of`): each one's name and its first and last stamp [s]. With two
        or more, each recording is drawn from its own start, the recordings one after
        another, each named over the top panels, a line between two (``t0`` unused): on one
        clock, recordings minutes apart left each a sliver of the axis.

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
    spans = [(float(a), float(b)) for _, a, b in recordings]
    laid = _one_after_another(log.t, spans) if len(spans) > 1 else None
    several = laid is not None
    if laid is not None:  # each recording from its own start, one after another
        time, begins_at, begins = laid
        cut = np.union1d(_gaps(time), begins).astype(np.intp)
    else:
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
    pad = 16.0 if several else 6.0  # room for the recordings' names
    axes[0, 0].set_title("joint torques [N m]", fontsize=10, pad=pad)
    axes[0, 1].set_title("error: measured - model [N m]", fontsize=10, pad=pad)
    handles, labels = axes[0, 0].get_legend_handles_labels()
    top = 1.0 - (0.6 if title else 0.3) / fig.get_figheight()  # room for the legend above
    fig.legend(handles, labels, loc="upper center", ncol=len(labels), fontsize=8,
               frameon=False, bbox_to_anchor=(0.5, top))  # fmt: skip
    xlabel = "time from the log's start [s]"
    if several:
        length = np.array([b - a for _, a, b in recordings], dtype=np.float64)
        _mark_recordings(list(axes.ravel()), [n for n, _, _ in recordings], begins_at, length)
        xlabel = "time from each recording's start [s], the recordings one after another"
    axes[-1, 0].set_xlabel(xlabel)
    axes[-1, 1].set_xlabel(xlabel)
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
    tight_layout(fig)
    return fig
