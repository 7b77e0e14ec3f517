"""Steps of a log's positions that neither its recorded velocity nor its noise explains.

One rule for ``identify`` (the positions' derivative the velocity columns are checked
against, :mod:`~dynid.identification.derivative_columns`) and ``observe`` (where the
observer starts again, :func:`~dynid.observer.pieces.position_jumps`): a stretch of
samples lost under even stamps, an encoder glitch, a re-homing. Step ``k`` (from sample
``k`` to ``k + 1``, recorded length ``T_k`` [s]) is a jump when it departs both

* from the step of the recorded velocity, ``d_k = q_{k+1} - q_k - T_k (dq_k + dq_{k+1}) / 2``
  (trapezoid), and
* from its neighbours' steps, ``e_k = q_{k+1} - q_k - T_k (r_{k-1} + r_{k+1}) / 2`` with
  ``r_i`` the neighbours' rates (step over length; the one neighbour inside the piece at
  its ends; a velocity column that lags or holds no motion makes no jump),

by more than :data:`JUMP_FACTOR` times the spread that noise and the stamps' jitter give
it, and by more than :data:`JUMP_FLOOR`. The spread of ``d`` is
``sqrt(s_d^2 + 2 (sigma_t v_k)^2)``: ``s_d`` its robust standard deviation over the log
(1.4826 the median absolute deviation: the sensors' noise), ``sigma_t`` the standard
deviation of the stamps about their grid (:func:`~dynid.signals.grid_steps`) and ``v_k``
the larger recorded speed at the step's two samples: a stamp ``eps`` late lengthens one
step and shortens the next, which then depart from the velocity's by ``v eps`` [rad],
so a step's departure holds ``v (eps_{k+1} - eps_k)`` (std ``sqrt(2) v sigma_t``). That of
``e`` holds up to four stamps' errors, std at most ``sqrt(6) v sigma_t``. At 125 Hz with
stamps jittered by 0.2 ms (std) and motions of 2 rad/s, the departures reached 2.3e-3 rad
where the sensors' noise gives 3e-5: one spread for the whole log made jumps of them. A
stretch of ``m`` samples lost at speed ``v`` departs by ``m T v``: found under jittered
stamps when ``m T`` exceeds about ``28 sigma_t`` (one sample at 125 Hz under 0.2 ms).
"""

from __future__ import annotations

import numpy as np
from numpy.typing import ArrayLike, NDArray

from .. import _checks, signals
from .log import LogCleaning

__all__ = ["JUMP_FACTOR", "JUMP_FLOOR", "jump_steps", "log_jitter", "velocity_departure"]

#: A position step is a jump when it departs from the step of the recorded velocity, and
#: from its neighbours', by more than this many standard deviations that noise and the
#: stamps' jitter give it ...
JUMP_FACTOR = 20.0
#: ... and by more than this [rad or m] (encoder quantisation is far below).
JUMP_FLOOR = 1e-3


def velocity_departure(t: ArrayLike, q: ArrayLike, dq: ArrayLike) -> NDArray[np.float64]:
    """The departure ``d`` (N - 1, ...) [rad or m] of each step of the positions ``q``
    (N, ...) from the step of the velocities ``dq`` (N, ...) [rad/s or m/s] over the
    times ``t`` (N,) [s]: ``q_{k+1} - q_k - T_k (dq_k + dq_{k+1}) / 2`` (trapezoid)."""
    ta = _checks.as_array("t", t)
    qa, dqa = np.asarray(q, dtype=np.float64), np.asarray(dq, dtype=np.float64)
    half = (0.5 * np.diff(ta)).reshape((-1,) + (1,) * (qa.ndim - 1))
    out: NDArray[np.float64] = np.diff(qa, axis=0) - half * (dqa[1:] + dqa[:-1])
    return out


def log_jitter(cleaning: LogCleaning) -> float | None:
    """The stamps' jitter [s] (standard deviation about their grid) a cleaned log carries,
    None for a log built directly (not cleaned: :func:`jump_steps` reads it of the stamps)."""
    return float(cleaning.stamp_jitter_s) if cleaning.n_input_rows else None


def jump_steps(
    t: ArrayLike,
    q: ArrayLike,
    dq: ArrayLike,
    starts: ArrayLike = (0,),
    jitter_s: float | None = None,
) -> NDArray[np.bool_]:
    """Which steps (N - 1, n) of the positions ``q`` (N, n) [rad or m] are jumps (module
    docstring) given the velocities ``dq`` (N, n) [rad/s or m/s] at times ``t`` (N,) [s],
    inside the pieces beginning at the samples ``starts`` (a step across a cut is none and
    no step's neighbour). ``jitter_s``: the stamps' jitter [s] (standard deviation about
    their grid; :func:`log_jitter` of a cleaned log); None reads it of ``t``
    (:func:`~dynid.signals.grid_steps`). One joint at a time: a few (N,) arrays on long
    logs."""
    ta = _checks.as_array("t", t)
    qa, dqa = _checks.as_array("q", q), _checks.as_array("dq", dq)
    N, n = qa.shape
    out = np.zeros((max(N - 1, 0), n), dtype=bool)
    if N < 3:
        return out
    if jitter_s is None:
        jitter_s = signals.grid_steps(ta)[2]
    T = np.diff(ta)
    inside = np.ones(N - 1, dtype=bool)
    across = np.asarray(starts, dtype=np.int64) - 1
    inside[across[(across >= 0) & (across < N - 1)]] = False
    left = np.zeros(N - 1, dtype=bool)  # the neighbour before is in the same piece
    left[1:] = inside[1:] & inside[:-1]
    right = np.zeros(N - 1, dtype=bool)
    right[:-1] = inside[:-1] & inside[1:]
    both = left & right
    weight = np.where(both, 0.5, np.where(left | right, 1.0, 0.0))
    var_t = 2.0 * float(jitter_s) ** 2
    for j in range(n):
        step = np.diff(qa[:, j])
        d = velocity_departure(ta, qa[:, j], dqa[:, j])
        rate = step / T
        near = np.zeros(N - 1)
        near[1:] += np.where(left[1:], rate[:-1], 0.0)
        near[:-1] += np.where(right[:-1], rate[1:], 0.0)
        e = np.where(weight > 0, step - T * weight * near, 0.0)
        speed = np.maximum(np.abs(dqa[1:, j]), np.abs(dqa[:-1, j]))
        s_d, s_e = (
            float(signals.robust_std(d[inside])),
            float(signals.robust_std(e[inside & (weight > 0)])),
        )
        lim_d = JUMP_FACTOR * np.sqrt(s_d**2 + var_t * speed**2)
        lim_e = JUMP_FACTOR * np.sqrt(s_e**2 + 3.0 * var_t * speed**2)
        out[:, j] = (
            inside
            & (np.abs(d) > np.maximum(lim_d, JUMP_FLOOR))
            & (np.abs(e) > np.maximum(lim_e, JUMP_FLOOR))
        )
    return out
