"""A log that moves a joint beyond the motion the observer's model was identified on.

An identified model predicts a joint moved much faster than in its identification's data by
extrapolation: friction that grows faster than the law's (a term in ``dq^3``), a rotor
inertia or a coefficient the slow data hardly excited, leave a residual that rises with the
speed, over the contact threshold through much of the motion: false alarms that are the
model's error, not contacts (a UR5 identified up to 1.6 rad/s, observed on a log at 3.8
rad/s: 10 false alarms and 67 % of the log flagged, with no word of the speed). The record
of an identification keeps each joint's largest speed over its samples
(``LogInfo.speed_max``); :func:`log_speed_max` measures a log's the same way (velocities
averaged over a quarter period of the identification's cut-off, so that the velocity noise
of a joint at rest does not count as motion), and :func:`beyond_joints` names the joints
moved more than :data:`~dynid.identification.motion_range.BEYOND` times as fast, as
``validate`` does (:func:`~dynid.identification.motion_range.motion_range_hint`, whose words
the notes reuse).
"""

from __future__ import annotations

from collections.abc import Sequence

import numpy as np
from numpy.typing import ArrayLike, NDArray

from ..identification.motion_range import BEYOND, motion_range_hint

__all__ = ["FASTER", "beyond_joints", "log_speed_max", "motion_hint", "speed_window"]

#: A joint moved more than this many times as fast as in the identification's data, though
#: within :data:`~dynid.identification.motion_range.BEYOND`, is named as a likely cause
#: where most of a log is flagged (friction growing faster than its law is extrapolated
#: there: a term in ``dq^3`` at 1.4 times the speed is 2.7 times its largest seen).
FASTER = 1.2


def speed_window(t: NDArray[np.float64], cutoff_hz: float) -> int:
    """Samples of a quarter period of ``cutoff_hz`` [Hz] at the median step of the times
    ``t`` (N,) [s], at least 1: the window :func:`log_speed_max` averages over."""
    steps = np.diff(t)
    steps = steps[steps > 0]
    if not steps.size or not np.isfinite(cutoff_hz) or cutoff_hz <= 0:
        return 1
    return max(1, int(round(0.25 / (cutoff_hz * float(np.median(steps))))))


def log_speed_max(
    dq: NDArray[np.float64], spans: Sequence[tuple[int, int]], window: int
) -> NDArray[np.float64]:
    """Each joint's largest speed (n,) [rad/s or m/s] over the samples ``[a, b)`` of
    ``spans`` of the velocities ``dq`` (N, n): the largest ``|mean|`` over consecutive
    windows of ``window`` samples (the last shorter) within each span; zeros where no
    sample is observed. NaN velocities are left out."""
    n = dq.shape[1]
    top = np.zeros(n)
    step = window * max(1, _CHUNK // window)  # whole windows at a time: bounded memory
    for a, b in spans:
        for c in range(a, b, step):
            np.maximum(top, _windowed_max(dq[c : min(c + step, b)], window), out=top)
    return top


#: Samples read at a time by :func:`log_speed_max`.
_CHUNK = 1 << 16


def _windowed_max(x: NDArray[np.float64], window: int) -> NDArray[np.float64]:
    """The largest ``|mean|`` (n,) of ``x`` (m, n) over consecutive windows of ``window``
    samples (the last shorter), NaN left out; zeros where none is finite."""
    n = x.shape[1]
    if not x.shape[0]:
        return np.zeros(n)
    m = -(-x.shape[0] // window)  # windows, the last padded with NaN
    padded = np.full((m * window, n), np.nan)
    padded[: x.shape[0]] = x
    w = padded.reshape(m, window, n)
    seen = np.isfinite(w)
    count = seen.sum(axis=1)
    mean = np.abs(np.where(seen, w, 0.0).sum(axis=1)) / np.maximum(count, 1)
    out: NDArray[np.float64] = np.max(np.where(count > 0, mean, 0.0), axis=0)
    return out


def beyond_joints(
    speed_max: ArrayLike | None, here: NDArray[np.float64] | None, factor: float = BEYOND
) -> list[tuple[int, float, float]]:
    """The joints (0-based) a log moves more than ``factor`` (default ``BEYOND``) times as
    fast as the identification's largest speeds ``speed_max`` (n,) [rad/s], each with the
    log's speed ``here`` and the identification's; empty without a record or a speed."""
    if speed_max is None or here is None:
        return []
    ident = np.asarray(speed_max, dtype=np.float64).ravel()
    if ident.shape != here.shape:
        return []
    return [
        (int(j), float(here[j]), float(ident[j])) for j in np.flatnonzero(here > factor * ident)
    ]


def motion_hint(
    speed_max: ArrayLike | None, here: NDArray[np.float64] | None, joint_names: Sequence[str]
) -> str | None:
    """``validate``'s words on a recording moved beyond the identification's speeds
    (:func:`~dynid.identification.motion_range.motion_range_hint`) for a log of largest
    speeds ``here`` (n,) [rad/s]; None when none is or no record."""
    if here is None:
        return None
    return motion_range_hint(speed_max, [here[None, :]], joint_names)
