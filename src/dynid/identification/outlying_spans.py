"""Where an outlying recording's residual stands off: its time spans and joints.

A recording left out of the structure's judgement as outlying
(:mod:`dynid.identification.selection`) holds torques the model does not (a contact, a
burst on one joint). Predicted by the fit of the other recordings, its residual is at
their level but where those torques act: :func:`outlying_spans` finds the samples whose
residual stands off its joint's robust level (the median absolute deviation, scaled to a
Gaussian standard deviation) by more than :data:`OFF_SIGMAS`, joins those less than
:data:`JOIN_S` apart into spans, and :func:`spans_text` says the spans that hold the most
of the residual (at least :data:`MIN_SHARE`), with their joints. Times [s] as the log
holds them, torques [N m].
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np
from numpy.typing import NDArray

from .._times import offset_text, stamp_text
from ..signals import MAD_TO_STD

__all__ = [
    "CUT_MAX_TIME_SHARE",
    "CUT_REST_RATIO",
    "JOIN_S",
    "MIN_SHARE",
    "OFF_SIGMAS",
    "SPANS_SHOWN",
    "Span",
    "cut_intervals",
    "cut_text",
    "outlying_spans",
    "robust_levels",
    "spans_text",
    "widened_intervals",
    "without_intervals",
]

#: A residual sample this many robust levels of its joint off the joint's median stands off.
OFF_SIGMAS = 6.0
#: Samples that stand off closer than this [s] belong to one span.
JOIN_S = 0.1
#: The spans said at most (those holding most of the squared residual).
SPANS_SHOWN = 3
#: A span holding less than this share of the recording's squared residual is not said [1]
#: (a noise sample of 6 robust levels: 0.002 % beside a 50 N m burst).
MIN_SHARE = 0.01
#: An outlying recording's spans are cut out of it, not the whole recording left out,
#: when the rest of it would stand at most this many times the other recordings' median
#: held-out error (:func:`cut_intervals`; a recording is outlying above 3).
CUT_REST_RATIO = 1.5
#: ... and the spans cut, with their margins, hold at most this share of its duration [1].
CUT_MAX_TIME_SHARE = 0.2


@dataclass(frozen=True, slots=True)
class Span:
    """A time span of a recording whose residual stands off.

    Attributes
    ----------
    t0, t1 : float
        Its first and last sample's time [s].
    joints : tuple of int
        The joints (0-based) standing off in it.
    peak : float
        The largest residual magnitude there [N m], over those joints.
    share : float
        Its share of the recording's squared residual (all joints) [1].
    """

    t0: float
    t1: float
    joints: tuple[int, ...]
    peak: float
    share: float


def outlying_spans(
    t: NDArray[np.float64],
    e: NDArray[np.float64],
    *,
    sigmas: float = OFF_SIGMAS,
    join_s: float = JOIN_S,
) -> tuple[Span, ...]:
    """The spans where the residual ``e`` stands off, the largest share first.

    Parameters
    ----------
    t : ndarray, shape (N,)
        Sample times [s], ascending (pieces one after another).
    e : ndarray, shape (N, n)
        Residual [N m]: measured torques less the prediction of a fit without them.
    sigmas : float
        Robust levels a sample stands off by (:data:`OFF_SIGMAS`).
    join_s : float
        Samples closer than this [s] are one span.

    Returns
    -------
    tuple of Span
        Empty where no sample stands off.
    """
    e = np.asarray(e, dtype=np.float64)
    t = np.asarray(t, dtype=np.float64)
    dev, level = robust_levels(e)
    off = np.abs(dev) > sigmas * np.where(level > 0, level, np.inf)
    rows = np.flatnonzero(off.any(axis=1))
    if rows.size == 0:
        return ()
    total = float(np.sum(e**2)) or 1.0
    cuts = np.flatnonzero(np.diff(t[rows]) > join_s) + 1
    out = []
    for run in np.split(rows, cuts):
        a, b = int(run[0]), int(run[-1])
        joints = tuple(int(j) for j in np.flatnonzero(off[run].any(axis=0)))
        peak = float(np.abs(e[a : b + 1][:, joints]).max())
        out.append(
            Span(float(t[a]), float(t[b]), joints, peak, float(np.sum(e[a : b + 1] ** 2)) / total)
        )
    return tuple(sorted(out, key=lambda s: -s.share))


def robust_levels(e: NDArray[np.float64]) -> tuple[NDArray[np.float64], NDArray[np.float64]]:
    """The residual ``e`` (N, n) less each joint's median (N, n), and each joint's robust
    level (n,): the median absolute deviation, scaled to a Gaussian standard deviation;
    in ``e``'s units. A sample stands off its joint's median by more than
    :data:`OFF_SIGMAS` levels (:func:`outlying_spans`)."""
    dev = e - np.median(e, axis=0)
    return dev, MAD_TO_STD * np.median(np.abs(dev), axis=0)


def spans_text(
    spans: tuple[Span, ...],
    joint_names: tuple[str, ...],
    t0: float | None = None,
    name: str | None = None,
) -> str:
    """``t = 3.000 to 3.196 s on elbow_joint (up to 49.6 N m, 93 % of its squared
    residual)``: the first :data:`SPANS_SHOWN` of ``spans`` that hold at least
    :data:`MIN_SHARE` of the squared residual, the time as the file holds it and its
    offset from the log's first stamp ``t0`` [s] (none said when it is 0 or None); empty
    without such spans."""
    said = []
    big = [s for s in spans if s.share >= MIN_SHARE]
    for s in big[:SPANS_SHOWN]:
        into = offset_text([s.t0 - float(t0 or 0.0)], t0, name)
        said.append(
            f"t = {stamp_text(s.t0)} to {stamp_text(s.t1)} s"
            + (f" ({into})" if into else "")
            + f" on {', '.join(joint_names[j] for j in s.joints)} (up to {s.peak:.3g} N m, "
            f"{100 * s.share:.3g} % of its squared residual)"
        )
    more = len(big) - len(said)
    return "; ".join(said) + (f"; and {more} more span(s)" if more > 0 else "")


def cut_intervals(
    spans: tuple[Span, ...],
    ratio: float,
    t: NDArray[np.float64],
    margin_s: float,
    bridged_s: float,
) -> tuple[tuple[float, float], ...]:
    """The time intervals [s] to cut out of an outlying recording instead of leaving it
    out, or none.

    Parameters
    ----------
    spans : tuple of Span
        Where its residual stands off (:func:`outlying_spans`); those holding at least
        :data:`MIN_SHARE` of its squared residual are cut.
    ratio : float
        Its held-out error over the other recordings' median (each fitted without it).
    t : ndarray, shape (N,)
        Its sample times [s] (as the spans').
    margin_s : float
        Widening of each span on both sides [s]: the filter's edge and a decimated step,
        so that no sample of what stood off is left at a piece's end.
    bridged_s : float
        The longest gap the preparation bridges [s]: an interval no longer would be
        bridged, not cut.

    Returns
    -------
    tuple of (float, float)
        The spans widened (joined where they overlap), ascending; none where the rest of
        the recording (:data:`MIN_SHARE`'s spans' complement, ``ratio sqrt(1 - share)``)
        would stand above :data:`CUT_REST_RATIO`, where they hold more than
        :data:`CUT_MAX_TIME_SHARE` of its duration, or where one is no longer than
        ``bridged_s``.
    """
    big = [s for s in spans if s.share >= MIN_SHARE]
    share = sum(s.share for s in big)
    if not big or ratio * math.sqrt(max(0.0, 1.0 - share)) > CUT_REST_RATIO:
        return ()
    return widened_intervals(tuple(big), t, margin_s, bridged_s)


def widened_intervals(
    spans: tuple[Span, ...],
    t: NDArray[np.float64],
    margin_s: float,
    bridged_s: float,
) -> tuple[tuple[float, float], ...]:
    """The time intervals [s] that cut ``spans`` out of a recording of sample times ``t``
    [s]: each widened by ``margin_s`` [s] on both sides, joined where they overlap,
    ascending; none where they hold more than :data:`CUT_MAX_TIME_SHARE` of its
    duration or where one is no longer than ``bridged_s`` [s] (the preparation would
    bridge it, not cut it). The one widening of :func:`cut_intervals` and of the spans a
    fit's own residual holds (:mod:`~dynid.identification.own_bursts`)."""
    if not spans:
        return ()
    out: list[list[float]] = []
    for a, b in sorted((s.t0 - margin_s, s.t1 + margin_s) for s in spans):
        if out and a <= out[-1][1]:
            out[-1][1] = max(out[-1][1], b)
        else:
            out.append([a, b])
    t = np.asarray(t, dtype=np.float64)
    span = float(t[-1] - t[0]) if t.size > 1 else 0.0
    if sum(b - a for a, b in out) > CUT_MAX_TIME_SHARE * span:
        return ()
    if any(b - a <= bridged_s for a, b in out):
        return ()
    return tuple((a, b) for a, b in out)


def without_intervals(
    t: NDArray[np.float64], intervals: tuple[tuple[float, float], ...]
) -> NDArray[np.bool_]:
    """The samples of ``t`` [s] outside every one of ``intervals`` (closed, [s]): the rows
    a recording keeps once those are cut out."""
    t = np.asarray(t, dtype=np.float64)
    keep = np.ones(t.size, dtype=bool)
    for a, b in intervals:
        keep &= ~((t >= a) & (t <= b))
    return keep


def cut_text(intervals: tuple[tuple[float, float], ...]) -> str:
    """``t = 4.672 to 5.428 s``: the intervals cut out, as the file holds the times."""
    return ", ".join(f"t = {stamp_text(a)} to {stamp_text(b)} s" for a, b in intervals)
