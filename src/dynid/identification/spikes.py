"""Torque spikes: samples that stand off both neighbours, on the same side, by more than
:data:`SPIKE_SIGMAS` robust noise levels (:func:`torque_spikes`).

A sensor or logging fault that least squares weighs by its square (:func:`spike_finding`
names the file, the joints, the counts and the times). The one change to the data a check
makes: :func:`despiked` replaces them by the line between their neighbours, before
filtering spreads them; ``identify`` (before fitting), ``validate`` and identify's held-out
verdict (before judging) and ``observe`` (before the observer runs) apply the same rule.
"""

from __future__ import annotations

import dataclasses
import math

import numpy as np
from numpy.typing import ArrayLike, NDArray

from .. import _checks, signals
from .._times import said_times
from ..exceptions import ShapeError
from .log import TorqueLog

__all__ = [
    "SLOW_SPIKE_SHARE",
    "SPIKES_BEFORE_FIT",
    "SPIKES_BEFORE_JUDGING",
    "SPIKES_BEFORE_OBSERVER",
    "SPIKE_SIGMAS",
    "SPIKE_TIMES_SHOWN",
    "despiked",
    "spike_finding",
    "torque_spikes",
]
#: A torque sample this many robust noise levels off both its neighbours is a spike.
SPIKE_SIGMAS = 20.0


#: Samples of a column handled at a time by :func:`torque_spikes` (bounded temporaries).
_SPIKE_BLOCK = 1 << 20


def torque_spikes(
    tau: ArrayLike, dq: ArrayLike | None = None, *, sigmas: float = SPIKE_SIGMAS
) -> list[tuple[int, int, int, float]]:
    """The spikes of each column of ``tau`` (N, n): samples off both neighbours, on the
    same side, by more than ``sigmas`` robust noise levels, away from slow motion.

    A sample's height is ``min(|x_k - x_{k-1}|, |x_k - x_{k+1}|)`` when both differences
    have one sign (0 otherwise: a step is not a spike). The noise level is the first
    differences' median absolute deviation, scaled to a Gaussian std over ``sqrt(2)``, at
    least the data's resolution (the smallest step between samples) and ``1e-9`` of the
    column's largest magnitude (noise-free data); a height must also exceed ``1e-3`` of
    the column's range (p1 to p99). With the velocities ``dq``, samples where the joint
    moves slowly are judged by a higher bar (``|dq|`` at the sample or a neighbour under
    a tenth of its 99th percentile, or of another sign): friction changes abruptly there
    (Coulomb and Stribeck friction at a reversal or a near stop) without any fault, so a
    sample there is a spike only when it stands off by :data:`SLOW_SPIKE_SHARE` of the
    column's range.

    Parameters
    ----------
    tau : array_like, shape (N, n)
        Torques [N m] (or any signal sampled in time).
    dq : array_like, shape (N, n), optional
        Velocities [rad/s] of the same samples.
    sigmas : float
        The threshold in noise levels.

    Returns
    -------
    list of (joint, count, first, largest)
        Per column with spikes: its index, their count, the row of the first and the
        largest height in noise levels.

    Raises
    ------
    ShapeError
        ``tau`` not (N, n), or ``dq`` of another shape.
    """
    a = _checks.as_array("tau", tau)
    if a.ndim != 2:
        raise ShapeError(f"tau must have shape (N, n); got {a.shape}")
    v = None if dq is None else _checks.as_array("dq", dq)
    if v is not None and v.shape != a.shape:
        raise ShapeError(f"dq must have the shape of tau {a.shape}; got {v.shape}")
    return [
        (j, int(rows.size), int(rows[0]), float(heights.max()))
        for j, rows, heights in _spikes_per_column(a, v, sigmas)
    ]


def _spikes_per_column(
    tau: NDArray[np.float64], dq: NDArray[np.float64] | None, sigmas: float = SPIKE_SIGMAS
) -> list[tuple[int, NDArray[np.intp], NDArray[np.float64]]]:
    """``(joint, rows, heights)`` of each column of ``tau`` (N, n) with spikes
    (:func:`_column_spikes`, judged with the velocities ``dq`` when given): the one loop
    :func:`torque_spikes`, :func:`despiked` and :func:`spike_finding` share."""
    out = []
    for j in range(tau.shape[1]):
        rows, heights = _column_spikes(tau[:, j], None if dq is None else dq[:, j], sigmas)
        if rows.size:
            out.append((j, rows, heights))
    return out


#: In slow motion (where :func:`torque_spikes` does not judge by the noise: friction
#: steps there) a sample that stands off both neighbours by more than this share of its
#: column's range (p1 to p99) is still a spike: no friction step is that large.
SLOW_SPIKE_SHARE = 0.5


def _column_spikes(
    x: NDArray[np.float64], v: NDArray[np.float64] | None, sigmas: float
) -> tuple[NDArray[np.intp], NDArray[np.float64]]:
    """The spikes of one column ``x`` (N,) (:func:`torque_spikes`; ``v`` its velocities):
    their rows, ascending, and heights in noise levels."""
    N = x.size
    if N < 5:
        return np.zeros(0, np.intp), np.zeros(0)
    k = max(1, N // 200_000)  # the noise level from 200,000 differences spread over the log
    m = (N - 1) // k
    d = x[1::k][:m] - x[0::k][:m]  # consecutive samples, spread over the log
    ad = np.abs(d)
    step = float(np.min(ad[ad > 0])) if np.any(ad > 0) else 0.0
    s = float(signals.robust_std(d)) / math.sqrt(2.0)
    lo, hi = np.quantile(x[::k], [0.01, 0.99])
    level = max(s, step, 1e-9 * float(np.max(np.abs(x[::k]))), 1e-300)
    least = max(sigmas * level, 1e-3 * float(hi - lo))
    huge = max(least, SLOW_SPIKE_SHARE * float(hi - lo))
    slow = 0.1 * float(np.quantile(np.abs(v[::k]), 0.99)) if v is not None else 0.0
    rows, heights = [], []
    for start in range(1, N - 1, _SPIKE_BLOCK):
        stop = min(start + _SPIKE_BLOCK, N - 1)
        d1 = x[start:stop] - x[start - 1 : stop - 1]
        d2 = x[start:stop] - x[start + 1 : stop + 1]
        h = np.where(np.sign(d1) == np.sign(d2), np.minimum(np.abs(d1), np.abs(d2)), 0.0)
        bar = np.full(h.size, least)
        if v is not None:
            w = v[start - 1 : stop + 1]
            fast = (np.abs(w) > slow) & (w > 0)
            up = fast[:-2] & fast[1:-1] & fast[2:]
            fast = (np.abs(w) > slow) & (w < 0)
            bar[~(up | (fast[:-2] & fast[1:-1] & fast[2:]))] = huge
        hit = np.flatnonzero(h > bar)
        rows.append(start + hit)
        heights.append(h[hit] / level)
    return np.concatenate(rows), np.concatenate(heights)


def despiked(log: TorqueLog) -> tuple[TorqueLog, tuple[int, ...]]:
    """``log`` with its torque spikes (:func:`torque_spikes`, judged with its velocities)
    replaced by the straight line between the samples around them, and how many per
    joint; ``log`` itself when it has none.

    A spike is one sample off both neighbours by far more than the noise while the joint
    moves: no rigid-body or friction torque changes so within one sample there. Low-passed
    with the rest, it would spread over the filter's length and bias every fit (robust
    weights too: they see the filtered rows), so it goes before filtering.
    """
    tau = np.array(log.tau, dtype=np.float64)
    t = np.asarray(log.t, dtype=np.float64)
    counts = [0] * log.n
    found = _spikes_per_column(tau, np.asarray(log.dq, dtype=np.float64))
    for j, rows, _ in found:
        counts[j] = int(rows.size)
        good = np.ones(t.size, dtype=bool)
        good[rows] = False
        tau[rows, j] = np.interp(t[rows], t[good], tau[good, j])
    if not found:
        return log, tuple(counts)
    return dataclasses.replace(log, tau=tau), tuple(counts)


#: What replacing the spikes is for, said by :func:`spike_finding`: before identification
#: filters a log (the default), before a prediction is judged (``validate``, the held-out
#: verdict), before the momentum observer runs (``observe``).
SPIKES_BEFORE_FIT = (
    "before filtering (spikes, a sensor or logging fault, would bias the fit by their "
    "square, robust estimators too)"
)
SPIKES_BEFORE_JUDGING = (
    "before judging, as identify replaces them before fitting (spikes, a sensor or "
    "logging fault, would dominate the error by their square)"
)
SPIKES_BEFORE_OBSERVER = (
    "before the observer runs (a sensor or logging fault of one sample, not a contact, "
    "which lasts several samples; not reported as events)"
)
#: Times of the spikes :func:`spike_finding` lists per joint (the rest counted).
SPIKE_TIMES_SHOWN = 3


def spike_finding(
    name: str,
    log: TorqueLog,
    joint_names: tuple[str, ...],
    *,
    before: str = SPIKES_BEFORE_FIT,
    kept: str | None = None,
) -> str | None:
    """One line naming the file ``name``, the joints, the counts and the first times of
    the torque spikes of ``log`` (:func:`torque_spikes`, judged with its velocities, as
    :func:`despiked` finds them), and ``before`` what they are replaced
    (:data:`SPIKES_BEFORE_FIT`, :data:`SPIKES_BEFORE_JUDGING`,
    :data:`SPIKES_BEFORE_OBSERVER`), or why they are ``kept``; None without spikes."""
    found = _spikes_per_column(
        np.asarray(log.tau, dtype=np.float64), np.asarray(log.dq, dtype=np.float64)
    )
    if not found:
        return None
    total = sum(rows.size for _, rows, _ in found)
    parts = ", ".join(
        f"{joint_names[j]} {_spike_times(log.t, rows, float(h.max()))}" for j, rows, h in found
    )
    return (
        f"{name}: {total} torque sample(s) stand off both neighbours by more than "
        f"{SPIKE_SIGMAS:g} times the noise: {parts}; "
        + (f"replaced by the line between their neighbours {before}" if kept is None else kept)
        + "; hint: check the torque sensor's logging"
    )


def _spike_times(t: NDArray[np.float64], rows: NDArray[np.intp], largest: float) -> str:
    """``3 (at t = 1.2, 3.4, 5.6 s and 2 more, largest 600 sigma)``: a joint's spikes."""
    said = said_times(t[rows], float(t[0]), shown=SPIKE_TIMES_SHOWN)
    return f"{rows.size} (at {said}, largest {largest:.3g} sigma)"
