"""Recorded derivative columns checked against the derivative of what they derive from.

A torque log's velocity columns ``dq`` are trusted as the derivative of its positions
``q``, and its acceleration columns ``ddq`` as better than the derivative of ``dq``. Two
ways a logger breaks that, each found here on the log as read (SI, joint order):

* **velocities that lag the positions** (a logger writing the previous sample's ``dq``, a
  causal velocity filter's delay): the lag ``L`` [samples] at which ``dq[i]`` matches the
  central difference of ``q`` at ``i - L`` best, over the joints that move
  (:func:`velocity_lag`: the normalized cross-correlation of the two, both low-passed at
  :data:`LAG_FILTER_SHARE` of the rate (at least :data:`LAG_FILTER_MIN_HZ`, at most a
  fifth of the rate) by one zero-phase filter, which shifts neither,
  over ``|s| <= MAX_SHIFT`` samples; the peak refined to a fraction of a sample by the
  parabola through its neighbours). A lag of :data:`MAX_LAG_SAMPLES` or more is a finding
  (:func:`velocity_finding`; the velocities are then derived from the positions): a
  one-sample lag at 1 kHz turned six of the 43 base parameters of a simulated FR3 more
  than 3 std from the truth, ten samples 33 of them,
  read by the fit as a torque delay. Half a sample (a backward difference ``(q[i] -
  q[i-1]) / dt`` logged as ``dq[i]``, a common convention) passes; the estimate on a
  noisy 20 s log errs by a few hundredths of a sample;
* **velocity columns that hold no motion** (zeros written where the velocity was not
  logged, or a constant): joints whose positions move while their ``dq`` varies by less
  than :data:`STILL_SHARE` of the positions' derivative, both low-passed as above
  (:func:`velocity_finding`);
* **acceleration columns noisier than the derivative of the velocities**
  (:func:`acceleration_noise_ratio`): a finite difference of noisy velocities logged as
  ``ddq`` holds the noise of the velocities times ``1 / dt``; the identification would
  low-pass it at its cut-off, but the noise floor its verdicts judge against counts it as
  it is (:func:`~dynid.identification.input_noise.state_noise`). The ratio compares the
  noise the columns carry at the cut-off with that of the velocities' derivative there
  (the accelerations the preparation derives without them); above
  :data:`DDQ_NOISE_RATIO` the columns are better left out.

A lag is read only of velocity columns at the scale of the positions' derivative: columns
:data:`SCALE_OFF` times larger or smaller than it on some joint
(:func:`~dynid.identification.velocity_scale.joint_rate_factors`) are said to be off by
that scale, not to lag (velocities in deg/s beside positions in rad read as a lag of 12.86
samples on a Kinova log, and as a lead of 0.91 on another).

The remedy for the first two is to read the log without its velocity columns
(``--columns dq=none``, :mod:`dynid.io.columns`): the velocities are then derived from the
positions.
"""

from __future__ import annotations

import dataclasses
from dataclasses import dataclass

import numpy as np
from numpy.typing import NDArray

from .. import signals
from .input_noise import derived_noise_gains, quantized_noise_std
from .log import TorqueLog
from .position_jumps import jump_steps, log_jitter
from .rate import cutoff_from_motion
from .velocity_noise import at_round_off, moving_joints, velocity_noise_std
from .velocity_scale import joint_rate_factors

__all__ = [
    "DDQ_NOISE_RATIO",
    "LAG_FILTER_MIN_HZ",
    "LAG_FILTER_SHARE",
    "MAX_LAG_SAMPLES",
    "MAX_SHIFT",
    "SCALE_OFF",
    "STILL_SHARE",
    "VelocityCheck",
    "acceleration_noise_ratio",
    "velocity_finding",
    "velocity_lag",
]

#: Shifts [samples] searched each way for the velocities' lag.
MAX_SHIFT = 40
#: A lag of the velocities [samples] from which they are not used (half a sample, a
#: backward difference, passes).
MAX_LAG_SAMPLES = 0.75
#: The cut-off of the filter both signals pass before the lag is read, as a share of the
#: rate (at 1 kHz: 50 Hz; a shift commutes with the filter).
LAG_FILTER_SHARE = 0.05
#: The filter's cut-off [Hz] at least (a fifth of the rate at most): a slow log's motion
#: kept (at 100 Hz: 20 Hz, not 5).
LAG_FILTER_MIN_HZ = 20.0
#: A joint whose velocity column varies by less than this share of its positions'
#: derivative (standard deviations) holds no motion.
STILL_SHARE = 0.05
#: Acceleration columns whose noise at the cut-off exceeds the velocities' derivative's
#: by this factor (std; 9 times the variance) are left out.
DDQ_NOISE_RATIO = 3.0
#: Velocity columns this many times larger or smaller than the positions' derivative on a
#: joint are off by a scale (a unit), not read for a lag.
SCALE_OFF = 1.5
#: Samples read at most (the first ones): enough for a lag to a hundredth of a sample.
MAX_SAMPLES = 200_000


@dataclass(frozen=True, slots=True)
class VelocityCheck:
    """What :func:`velocity_lag` reads of a log's velocity columns.

    Attributes
    ----------
    lag_samples : float
        The lag of ``dq`` behind the derivative of ``q`` [samples] (positive: ``dq``
        late), pooled over the joints in ``lag_joints``; NaN when none.
    dt : float
        The median sampling step [s].
    lag_joints : tuple of int
        The joints (0-based) the lag was read on: their positions move and their
        velocity columns do too.
    still : tuple of int
        The joints (0-based) whose positions move while their velocity column holds no
        motion (zero or constant).
    at_edge : bool
        The best shift is the last searched: the lag is at least ``MAX_SHIFT``.
    """

    lag_samples: float
    dt: float
    lag_joints: tuple[int, ...]
    still: tuple[int, ...]
    at_edge: bool = False


def _position_derivative(log: TorqueLog, m: int) -> tuple[NDArray[np.float64], float]:
    """Central differences of the first ``m`` positions [rad/s] (m, n), the rows at a gap,
    a jump of half a turn or more, or a jump the recorded velocities and the stamps'
    jitter do not explain (a stretch of samples lost under even stamps, a glitch: the rule
    of :func:`~dynid.identification.position_jumps.jump_steps`) set to the recorded
    velocity (not motion), and the median step [s]."""
    t, q, dq = log.t[:m], log.q[:m], log.dq[:m]
    dt = float(np.median(np.diff(t)))
    v = np.gradient(q, t, axis=0)
    gap = np.diff(t) > 1.5 * dt
    starts = np.concatenate([[0], np.flatnonzero(gap) + 1])
    jump = jump_steps(t, q, dq, starts, log_jitter(log.cleaning))
    bad_step = gap[:, None] | (np.abs(np.diff(q, axis=0)) >= np.pi) | jump
    bad = np.zeros(q.shape, dtype=bool)
    bad[1:] |= bad_step
    bad[:-1] |= bad_step
    return np.where(bad, dq, v), dt


def velocity_lag(log: TorqueLog) -> VelocityCheck | None:
    """The lag of ``log``'s velocity columns behind the derivative of its positions, and
    the joints whose velocity columns hold no motion while their positions move (module
    docstring); None for velocities derived from the positions, or a log too short
    (fewer than ``4 MAX_SHIFT + 16`` samples, or than 32 with a shorter search)."""
    if log.dq_derived or log.n_samples < 32:
        return None
    m = min(log.n_samples, MAX_SAMPLES)
    shift = min(MAX_SHIFT, (m - 16) // 4)
    v, dt = _position_derivative(log, m)
    if not (dt > 0 and np.all(np.isfinite(v))):
        return None
    dq = np.asarray(log.dq[:m], dtype=np.float64)
    fs = 1.0 / dt  # both filtered alike: the noise of q's differences out
    fc = max(LAG_FILTER_SHARE * fs, min(LAG_FILTER_MIN_HZ, 0.2 * fs))
    vf = signals.lowpass(v, fs, fc)
    moves = moving_joints(vf, velocity_noise_std(v) * signals.lowpass_noise_gain(fs, fc))
    if not moves.any():
        return VelocityCheck(float("nan"), dt, (), ())
    a = signals.lowpass(dq[:, moves], fs, fc)
    b = vf[:, moves]
    flat = a.std(axis=0) < STILL_SHARE * b.std(axis=0)
    joints = np.flatnonzero(moves)
    found = tuple(int(j) for j in joints[flat])
    if flat.all():
        return VelocityCheck(float("nan"), dt, (), found)
    a, b, joints = a[:, ~flat], b[:, ~flat], joints[~flat]
    a, b = a[shift:-shift], b  # dq[i] against v[i - s], s in [-shift, shift]
    k = a.shape[0]
    na = np.sqrt(np.sum(a * a, axis=0))
    score = np.empty(2 * shift + 1)
    for r, s in enumerate(range(-shift, shift + 1)):
        bb = b[shift - s : shift - s + k]
        c = np.sum(a * bb, axis=0) / (na * np.sqrt(np.sum(bb * bb, axis=0)) + 1e-300)
        score[r] = float(np.sum(np.abs(c)))
    r = int(np.argmax(score))
    edge = r in (0, 2 * shift)
    lag = float(r - shift)
    if not edge:
        y0, y1, y2 = score[r - 1], score[r], score[r + 1]
        den = y0 - 2.0 * y1 + y2
        if den < 0:
            lag += 0.5 * (y0 - y2) / den
    return VelocityCheck(lag, dt, tuple(int(j) for j in joints), found, edge)


def _joints(joints: tuple[int, ...], names: tuple[str, ...] | None) -> str:
    return ", ".join(names[j] if names else f"joint {j + 1}" for j in joints)


def velocity_finding(log: TorqueLog, joint_names: tuple[str, ...] | None = None) -> str | None:
    """One line saying what is wrong with ``log``'s velocity columns (:func:`velocity_lag`:
    a lag of :data:`MAX_LAG_SAMPLES` or more, joints whose column holds no motion), with
    the remedy ``--columns dq=none``; None when nothing is."""
    found = velocity_lag(log)
    if found is None:
        return None
    parts = []
    k = joint_rate_factors(log)
    off = tuple(
        int(j) for j in np.flatnonzero(np.isfinite(k) & (np.abs(np.log(k)) > np.log(SCALE_OFF)))
    )
    if off:  # a scale shifts the lag read where jumps are told from the velocities
        found = dataclasses.replace(found, lag_joints=())
        parts.append(
            "its velocity columns are off the scale of the derivative of its positions ("
            + ", ".join(
                f"{joint_names[j] if joint_names else f'joint {j + 1}'} {1 / k[j]:.3g} times it"
                for j in off
            )
            + "): a unit or a scale, not a lag"
        )
    if found.still:
        parts.append(
            f"its velocity columns hold no motion (zero or constant) on "
            f"{_joints(found.still, joint_names)}, whose positions move"
        )
    if found.lag_joints and abs(found.lag_samples) >= MAX_LAG_SAMPLES:
        late = found.lag_samples > 0
        size = abs(found.lag_samples)
        at = f"at least {size:.0f}" if found.at_edge else f"{size:.2f}"
        cause = (
            "a logger writing an earlier sample's velocity, or a filtered estimate's delay"
            if late
            else "positions logged late against their velocities"
        )
        parts.append(
            f"its velocity columns {'lag' if late else 'lead'} the derivative of its "
            f"positions by {at} sample(s) ({size * found.dt * 1e3:.3g} ms, read on "
            f"{_joints(found.lag_joints, joint_names)}): {cause}; not a torque delay"
        )
    if not parts:
        return None
    return (
        "; ".join(parts)
        + "; hint: --columns dq=none reads the log without its velocity (and acceleration) "
        "columns: the velocities are derived from the positions"
    )


def acceleration_noise_ratio(log: TorqueLog, cutoff_hz: float | None) -> NDArray[np.float64] | None:
    """Per joint (n,), the noise of ``log``'s acceleration columns low-passed at
    ``cutoff_hz`` [Hz] (as the noise floor counts it: their white-noise std times the
    filter's gain) over that of the derivative of its velocities low-passed there
    (:func:`~dynid.identification.input_noise.derived_noise_gains`), the accelerations the
    preparation derives without them; ``cutoff_hz`` None reads the cut-off from the motion
    (:func:`~dynid.identification.rate.cutoff_from_motion`, ``identify``'s default).
    None without acceleration columns, for columns exact to round-off (a noise-free
    simulation: used as they are), or a log of fewer than 32 samples."""
    if log.ddq is None or log.n_samples < 32:
        return None
    m = min(log.n_samples, MAX_SAMPLES)
    t, ddq = log.t[:m], np.asarray(log.ddq[:m])
    if at_round_off(ddq, t).all():
        return None
    dt = float(np.median(np.diff(t)))
    fs = 1.0 / dt
    fc = cutoff_hz if cutoff_hz is not None else cutoff_from_motion(log.q[:m], log.dq[:m], fs)
    fc = min(fc, 0.25 * fs)
    src = log.q[:m] if log.dq_derived else log.dq[:m]
    _, ga = derived_noise_gains(dt, fc, derived=log.dq_derived)
    own = signals.lowpass_noise_gain(fs, fc) * quantized_noise_std(ddq, t)
    derived = ga * quantized_noise_std(src, t)
    with np.errstate(divide="ignore", invalid="ignore"):
        ratio = np.where(derived > 0, own / derived, np.where(own > 0, np.inf, 1.0))
    return np.asarray(ratio, dtype=np.float64)
