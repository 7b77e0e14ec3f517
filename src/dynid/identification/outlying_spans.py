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

from dataclasses import dataclass

import numpy as np
from numpy.typing import NDArray

from .._times import offset_text, stamp_text

__all__ = [
    "JOIN_S",
    "MIN_SHARE",
    "OFF_SIGMAS",
    "SPANS_SHOWN",
    "Span",
    "outlying_spans",
    "spans_text",
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
_MAD_TO_STD = 1.4826  # a Gaussian's standard deviation over its median absolute deviation


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
    dev = e - np.median(e, axis=0)
    level = _MAD_TO_STD * np.median(np.abs(dev), axis=0)
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
