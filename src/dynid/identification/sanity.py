"""Checks of a torque log before fitting: sign, scale, units and joints that never move.

Real logs come with conventions of their own. Each check here returns one line that says
what looks wrong, the numbers, and the remedy as the user types it; identification warns
with them before fitting (:func:`log_findings`). None of them changes the data.

* **Sign**: the measured torques against the model's gravity torques ``g(q)`` at the logged
  configurations and against its whole rigid-body torques ``M ddq + c + g`` along the
  logged motion (with the robot's own link parameters, when it has any): a correlation
  below ``-0.5`` with both on a joint that gravity loads (or, where the whole torques
  explain a joint's at about their own scale, a correlation of -0.8 or below) means the
  torque sign is opposite to the model's, refused by ``identify`` and ``observe`` and
  warned by ``validate``: on every joint judged, ``--units tau=-1``; on some, naming them
  and the ``--units tau2=-1`` entries that flip them alone. Each
  comparison alone can be fooled: on 2 s of fast motion a Panda's elbow torques of the
  right sign correlated -0.70 with its gravity torques (+0.99 with the whole torques),
  and a description's poor inertias could turn the whole torques. Where the whole torques
  explain other joints at their scale, a joint is called opposite only if the negated
  ones explain it at about its own (least-squares factor within :data:`CONFIRMED_SLOPE`):
  a 60 N m/rad spring the rigid bodies lack turned a Panda shoulder's correlation to
  -0.51 at a factor of -0.29, and that is no sign to flip; nor where the torques as read
  are the model's plus a function of the joint's own position and friction, far better
  than the negated ones (:func:`_reads_right`: on another recording the same spring gave
  -0.96 at -1.17, as a flipped sign would; the samples whose velocity is within its noise
  left out, where a Coulomb friction of 80 N m steps). Where friction outweighs a loaded
  joint's rigid bodies the correlations cannot see a flip: a joint whose negated torques
  are so explained while its friction as read pushes is called opposite
  (:func:`_pushing_as_read`). A robot's joint spring
  (:attr:`~dynid.model.robot.Robot.spring`) is part of its torques at rest and in motion.
* **Scale**: the least-squares factor ``a`` in ``tau ~ a g(q)`` over the gravity-loaded
  joints; ``a`` near 1e3 or 1e-3 is a unit off by a power of ten (mN m against N m:
  :func:`torque_unit_finding`, refused by the commands unless ``--units`` names the
  torques' unit), and currents logged as torques show as a factor far from 1 (a drive
  file with ``torque_constant``; currents read through one: its ``torque_constant`` or
  ``gear_ratio`` is off by the factor). Sign and scale compare variations: not made on a log at rest
  (every joint frozen), whose variations are noise, nor on a joint whose gravity torques
  span less than :data:`GRAVITY_RANGE_SHARE` of the log's largest (a short stretch, whose
  torque variations are the motion's).
* **Degrees**: positions whose range exceeds ``2 pi`` on a revolute joint while the range
  divided by ``180 / pi`` fits in the joint's limits, unless the velocities say otherwise:
  where ``dq`` agrees with the derivative of ``q`` (one unit for both) the positions are
  radians unless the velocities are too fast for radians (above the joint's ``dq_max``,
  or ``2 pi`` rad/s without one); an unwrapped continuous joint that turns several times
  is not degrees. Velocities ``180 / pi`` times slower than the derivative of ``q`` are
  (``--units q=deg``; both in degrees: ``--units q=deg,dq=deg/s``). Said first, and
  instead of the sign and scale findings: the gravity torques at positions in degrees
  say nothing of the torques' units.
* **Milliseconds**: logged velocities ``1e3`` times the derivative of the positions (or a
  median time step of at least 0.5 s with integer steps when no velocities were logged):
  ``--units t=ms``.
* **Reversed columns**: a motor or encoder mounted the other way, its position and
  velocity (with its effort or without) of the opposite sign; several at once, named in
  the log's own columns (a motor-side log's motors) with one ``--units`` hint, judged
  through the drive before the sign (:func:`reversed_joint`). Of several recordings, one
  motor (joint) the links barely load of the opposite sign to the others' is told by its
  own friction and rotor (:func:`opposite_friction_among`). :func:`recording_sign_findings`
  runs these sign checks in the one order ``identify``, ``validate`` and ``observe`` share.
* **Frozen joints**: a joint whose velocity never leaves its noise band (fewer than 1 % of
  the samples beyond 5 times the robust noise level, :func:`velocity_noise_std`, and
  :data:`MIN_MOTION`); its friction cannot be identified (:func:`moving_joints`).
* **Torque spikes**: samples that stand off both neighbours, on the same side, by more
  than :data:`SPIKE_SIGMAS` robust noise levels (:func:`torque_spikes`); a sensor or
  logging fault that least squares weighs by its square (:func:`spike_finding` names the
  file, the joints, the counts and the times). The one change to the data:
  :func:`despiked` replaces them by the line between their neighbours, before filtering
  spreads them; ``identify`` (before fitting), ``validate`` and identify's held-out
  verdict (before judging) and ``observe`` (before the observer runs) apply the same rule.
"""

from __future__ import annotations

import dataclasses
import math
from collections.abc import Iterable, Iterator, Sequence
from dataclasses import dataclass

import numpy as np
from numpy.typing import ArrayLike, NDArray

from .. import _checks, signals
from ..dynamics.rnea import rnea
from ..dynamics.terms import gravity_torques
from ..exceptions import ShapeError
from ..model.drive import Drive
from ..model.robot import Robot
from .log import TorqueLog, joint_side_log

__all__ = [
    "CONFIRMED_CORRELATION",
    "CONFIRMED_SLOPE",
    "MIN_MOTION",
    "MOTION_HALF_SPAN_S",
    "MOTION_MIN_SAMPLES",
    "anticorrelated",
    "MOVING_FRACTION",
    "NOISE_BAND_STD",
    "check_torque_log",
    "GRAVITY_RANGE_SHARE",
    "gravity_loaded",
    "joint_rate_factor",
    "opposite_sign",
    "opposite_friction_among",
    "opposite_sign_among",
    "reversed_joint",
    "recording_sign_findings",
    "SignFinding",
    "REVERSED_MODEL_SHARE",
    "REVERSED_STEP_SHARE",
    "moving_joints",
    "noise_band",
    "OPPOSITE_CORRELATION",
    "MIN_LOG_SAMPLES",
    "SLOW_SPIKE_SHARE",
    "SPIKES_BEFORE_FIT",
    "SPIKES_BEFORE_JUDGING",
    "SPIKES_BEFORE_OBSERVER",
    "SPIKE_SIGMAS",
    "SPIKE_TIMES_SHOWN",
    "despiked",
    "spike_finding",
    "time_unit_finding",
    "too_few_samples",
    "sign_confirmed",
    "torque_spikes",
    "torque_unit_finding",
    "UNIT_SCALE_TOLERANCE",
    "velocity_noise_std",
    "velocity_rate_factor",
]

_MAX_SAMPLES = 4000  # samples used by the checks (evenly spaced): they are statistics

#: Width of the velocity noise band, in standard deviations of the velocity noise.
NOISE_BAND_STD = 5.0
#: Smallest velocity [rad/s] (m/s for a prismatic joint) counted as motion, whatever the
#: noise: below it no friction law can be told apart (noise-free logs of a frozen joint).
MIN_MOTION = 1e-3
#: Fraction of the samples that must lie outside the noise band for a joint to move.
MOVING_FRACTION = 0.01
#: The sign and scale checks judge a joint only where its gravity torques span at least
#: this share of the log's largest gravity torque (a UR5's shoulder: 0.9 over 20 s of
#: Fourier motion, 0.14 over 0.5 s, 0.008 over 0.05 s, where the correlation was -0.95
#: on a log of the right sign).
GRAVITY_RANGE_SHARE = 0.1
#: A joint whose torques correlate below this with its gravity torques has the opposite
#: sign (gravity explains a quarter or more of their variance, with the other sign).
OPPOSITE_CORRELATION = -0.5
#: Half the span [s] of the central difference of the logged velocities that gives the
#: sign check its accelerations (:func:`opposite_sign`): a 20 Hz smoothing, whose bias
#: is 2 % of a 2 Hz motion's accelerations and which divides velocity noise by 35 at 1 kHz.
MOTION_HALF_SPAN_S = 0.025
#: Fewest samples with known accelerations for the sign check to use the whole torques.
MOTION_MIN_SAMPLES = 20
#: A joint's torque sign is confirmed by the model (:func:`sign_confirmed`) when its
#: torques correlate at least this with the whole rigid-body torques...
CONFIRMED_CORRELATION = 0.8
#: ... and the least-squares factor of those torques on them lies within this range.
CONFIRMED_SLOPE = (0.5, 2.0)
#: A torque scale (:func:`torque_unit_finding`) within this factor of ``1e3`` or ``1e-3``
#: reads as torques in mN m or kN m read as N m (a URDF whose masses are off by tens of
#: percent gives a factor near 1, currents one near the inverse torque constant).
UNIT_SCALE_TOLERANCE = 2.0
#: A torque sample this many robust noise levels off both its neighbours is a spike.
SPIKE_SIGMAS = 20.0


def velocity_noise_std(dq: ArrayLike, t: ArrayLike | None = None) -> NDArray[np.float64]:
    """Std [rad/s] (n,) of the white noise on velocity samples ``dq`` (N, n), robustly.

    .. math:: \\hat\\sigma_j = 1.4826 \\, \\min\\big(\\mathrm{MAD}(\\Delta^2 \\dot q_j) / \\sqrt 6,
              \\; \\mathrm{MAD}(\\Delta^3 \\dot q_j) / \\sqrt{20}\\big)

    The second and third differences of white noise of std ``sigma`` have std
    ``sqrt(6) sigma`` and ``sqrt(20) sigma``, while those of a smooth motion sampled fast
    are far smaller, the third smaller than the second: the smaller of the two estimates
    leaves a noise-free log (a simulation) with a band near zero. The median absolute
    deviation (scaled to a std for Gaussian noise) ignores the few steps of a fast reversal. Give
    the measured velocities: a low-pass filter hides the noise from this estimate.

    Samples at uneven times ``t`` (jitter, dropped samples): the differences become the
    residuals of each sample from the line through its two neighbours and from the
    parabola through the previous one and the next two, at their own times (Lagrange),
    each scaled to the noise's std; on even times they are the differences above. The
    differences of unevenly timed samples hold the motion itself (an xArm7 at 100 Hz,
    stamps +-2 ms: torque noise read 0.07 N m for 0.05). Residuals across a step back in
    time (logs joined) are left out.

    Parameters
    ----------
    dq : array_like, shape (N, n)
        Measured joint velocities [rad/s], N >= 3.
    t : array_like, shape (N,), optional
        The samples' times [s]; default: evenly spaced.

    Returns
    -------
    ndarray, shape (n,)

    Raises
    ------
    ShapeError
        ``dq`` not of shape (N, n) with N >= 3.
    """
    a = _checks.as_array("dq", dq)
    if a.ndim != 2 or a.shape[0] < 3:
        raise ShapeError(f"dq must have shape (N, n), N >= 3; got {a.shape}")
    if t is not None:
        tt = _checks.as_array("t", t)
        if tt.shape != (a.shape[0],):
            raise ShapeError(f"t must have shape ({a.shape[0]},) like dq's rows; got {tt.shape}")
        dt = np.diff(tt)
        h = float(np.median(dt))
        if not (h > 0 and np.all(np.abs(dt - h) <= 1e-6 * h)):  # pieces joined: uneven too
            return _uneven_noise_std(a, tt)
    est = []
    for order, var in ((2, 6.0), (3, 20.0)):
        if a.shape[0] <= order:  # three samples: no third difference
            continue
        mad = np.empty(a.shape[1])
        for j in range(a.shape[1]):  # one joint at a time: temporaries of one column
            d = np.diff(a[:, j], n=order)
            d -= np.median(d)
            mad[j] = np.median(np.abs(d, out=d))
        est.append(1.4826 * mad / np.sqrt(var))
    out: NDArray[np.float64] = np.minimum.reduce(est)
    return out


def _uneven_noise_std(a: NDArray[np.float64], t: NDArray[np.float64]) -> NDArray[np.float64]:
    """:func:`velocity_noise_std` of ``a`` (N, n) sampled at the uneven times ``t`` (N,)."""
    est = []
    for nodes in ((-1, 1), (-1, 1, 2)):
        lo, hi = -min(nodes), max(nodes)
        i = np.arange(lo, a.shape[0] - hi)
        if i.size == 0:
            continue
        ti = t[i]
        tk = [t[i + k] for k in nodes]
        w = []
        for k, tn in enumerate(tk):
            wk = np.ones_like(ti)
            for m, tm in enumerate(tk):
                if m != k:
                    with np.errstate(divide="ignore", invalid="ignore"):
                        wk *= (ti - tm) / (tn - tm)
            w.append(wk)
        times = np.stack([t[i + k] for k in range(-lo, hi + 1)])
        ok = np.all(np.diff(times, axis=0) > 0, axis=0)
        if not ok.any():
            continue
        scale = np.sqrt(1.0 + sum(x**2 for x in w))[ok]
        mad = np.empty(a.shape[1])
        for j in range(a.shape[1]):
            r = a[i, j] - sum(wk * a[i + k, j] for wk, k in zip(w, nodes, strict=True))
            r = r[ok] / scale
            r -= np.median(r)
            mad[j] = np.median(np.abs(r))
        est.append(1.4826 * mad)
    out: NDArray[np.float64] = np.minimum.reduce(est) if est else np.zeros(a.shape[1])
    return out


def noise_band(noise_std: ArrayLike) -> NDArray[np.float64]:
    """The velocity noise band [rad/s]: ``NOISE_BAND_STD * noise_std``.

    Joints whose velocity stays inside it (or below :data:`MIN_MOTION`) do not move
    (:func:`moving_joints`), and friction laws do not switch Coulomb friction on inside it
    (:mod:`dynid.friction.laws.base`).

    Parameters
    ----------
    noise_std : array_like, shape (n,) or scalar
        White-noise std of the measured velocities [rad/s] (:func:`velocity_noise_std`).

    Returns
    -------
    ndarray, same shape as ``noise_std``
    """
    out: NDArray[np.float64] = NOISE_BAND_STD * np.asarray(noise_std, dtype=np.float64)
    return out


#: Fewest samples of a recording that the checks and the filter are asked to read: two
#: samples correlate at +-1 with anything, three give one curvature.
MIN_LOG_SAMPLES = 10


def too_few_samples(log: TorqueLog) -> str | None:
    """The finding that ``log`` holds too few samples to be checked or filtered (fewer
    than :data:`MIN_LOG_SAMPLES`), or None; said before any statistic of it."""
    n = log.n_samples
    if n >= MIN_LOG_SAMPLES:
        return None
    return (
        f"{n} sample{'' if n == 1 else 's'}: too few to check or filter a torque log (at "
        f"least {MIN_LOG_SAMPLES} are needed); hint: check that the file holds the whole "
        "recording"
    )


def moving_joints(dq: ArrayLike, noise_std: ArrayLike | None = None) -> NDArray[np.bool_]:
    """Which joints move beyond their velocity noise band (n,) bool.

    A joint moves when more than :data:`MOVING_FRACTION` of its samples ``|dq|`` exceed
    ``max(NOISE_BAND_STD * noise_std, MIN_MOTION)``.

    Parameters
    ----------
    dq : array_like, shape (N, n)
        Joint velocities [rad/s] (filtered or not).
    noise_std : array_like, shape (n,) or scalar, optional
        White-noise std of the measured velocities [rad/s]; default
        :func:`velocity_noise_std` of ``dq`` (right for unfiltered velocities).

    Returns
    -------
    ndarray of bool, shape (n,)

    Raises
    ------
    ShapeError
        ``dq`` not of shape (N, n) with N >= 3, or ``noise_std`` of another joint count.
    """
    a = _checks.as_array("dq", dq)
    if a.ndim != 2 or a.shape[0] < 3:
        raise ShapeError(f"dq must have shape (N, n), N >= 3; got {a.shape}")
    sd = velocity_noise_std(a) if noise_std is None else _checks.as_array("noise_std", noise_std)
    sd = np.broadcast_to(sd, (a.shape[1],)) if sd.ndim == 0 else sd
    if sd.shape != (a.shape[1],):
        raise ShapeError(f"noise_std must have shape ({a.shape[1]},); got {sd.shape}")
    band = np.maximum(noise_band(sd), MIN_MOTION)
    level = np.array(
        [np.quantile(np.abs(a[:, j]), 1.0 - MOVING_FRACTION) for j in range(a.shape[1])]
    )
    out: NDArray[np.bool_] = level > band
    return out


def check_torque_log(robot: Robot, log: TorqueLog, drive: Drive | None = None) -> list[str]:
    """One line per finding on a joint-side log of ``robot`` (module docstring), read
    through ``drive`` (its torque constants and gear ratios are named by the scale
    finding); empty when nothing looks wrong."""
    seen = _against_gravity(robot, log)
    out = list(seen.degrees)
    a = seen.scale
    if seen.opposite is not None:
        out.append(seen.opposite)
    elif a is not None and (abs(a) > 30 or 0 < abs(a) < 1 / 30):
        out.append(_scale_line(a, drive=drive))
    out += _milliseconds(log)
    frozen, names = seen.frozen, robot.joint_names
    if np.any(frozen) and not np.all(frozen):
        which = ", ".join(names[j] for j in np.flatnonzero(frozen))
        out.append(
            f"joint(s) {which} never leave their velocity noise band: their friction is "
            "unidentifiable and is left out (zero) rather than fitted from noise; hint: a "
            "trajectory that moves every joint identifies them"
        )
    return out


@dataclass(frozen=True, slots=True)
class _GravitySaid:
    """What a joint-side log says against the robot's gravity torques: the sign and scale
    findings' guards, one for :func:`check_torque_log` and :func:`torque_unit_finding`.

    Attributes
    ----------
    degrees : tuple of str
        The degrees finding (said first, and instead of sign and scale: the gravity
        torques at positions in degrees say nothing of the torques).
    frozen : ndarray of bool, shape (n,)
        The joints that never leave their velocity noise band.
    opposite : str or None
        The sign finding (:func:`_opposite`).
    scale : float or None
        ``a`` of ``tau ~ a g(q)`` (:func:`_torque_scale`); None where not compared: a
        robot without inertial parameters, every joint frozen (at rest the variations are
        noise, whose ratio says nothing of the units), degrees, the opposite sign, no
        joint gravity loads.
    """

    degrees: tuple[str, ...]
    frozen: NDArray[np.bool_]
    opposite: str | None = None
    scale: float | None = None


def _against_gravity(robot: Robot, log: TorqueLog) -> _GravitySaid:
    """The degrees, frozen joints, sign and scale of ``log`` against ``robot``'s gravity
    torques (:class:`_GravitySaid`), each judged only where the ones before allow."""
    degrees = tuple(_degrees(robot, log))
    frozen = ~moving_joints(log.dq)
    if not np.any(robot.phi) or degrees or np.all(frozen):
        return _GravitySaid(degrees, frozen)
    if (opposite := opposite_sign(robot, log)) is not None:
        return _GravitySaid(degrees, frozen, opposite)
    step = max(1, log.n_samples // _MAX_SAMPLES)
    return _GravitySaid(degrees, frozen, None, _torque_scale(robot, log.q[::step], log.tau[::step]))


def _correlations(reference: NDArray[np.float64], tau: NDArray[np.float64]) -> NDArray[np.float64]:
    """Per-joint correlation (n,) of ``tau`` with ``reference`` (both centred; 0 where
    either is constant)."""
    with np.errstate(invalid="ignore", divide="ignore"):
        corr = np.sum(reference * tau, axis=0) / np.sqrt(
            np.sum(reference**2, axis=0) * np.sum(tau**2, axis=0)
        )
    return np.where(np.isfinite(corr), corr, 0.0)


def anticorrelated(
    reference: NDArray[np.float64], tau: NDArray[np.float64], loaded: NDArray[np.bool_]
) -> tuple[int, float] | None:
    """The joint and correlation that show ``tau`` (N, n) of the opposite sign to
    ``reference`` (N, n), both with their means removed, or None.

    A sign is called opposite when more of the ``loaded`` joints correlate negatively than
    positively and at least one correlates below -0.5 (that one, the most negative, is
    returned).
    """
    corr = _correlations(reference, tau)
    neg = loaded & (corr < -0.5)
    if not np.any(neg) or np.sum(corr[loaded] < 0) <= np.sum(corr[loaded] > 0):
        return None
    j = int(np.flatnonzero(neg)[np.argmin(corr[neg])])
    return j, float(corr[j])


def _loaded(g: NDArray[np.float64]) -> NDArray[np.bool_]:
    """The joints the gravity torques ``g`` (N, n) load (:func:`_gravity_spread`)."""
    spread = np.std(g, axis=0)
    varied = np.ptp(g, axis=0) >= GRAVITY_RANGE_SHARE * float(np.max(np.abs(g)))
    out: NDArray[np.bool_] = (spread > 0.05 * max(float(spread.max()), 1e-300)) & varied
    return out & bool(np.any(spread > 0))


def _gravity_spread(
    robot: Robot, q: NDArray[np.float64], tau: NDArray[np.float64]
) -> tuple[NDArray[np.float64], NDArray[np.float64], NDArray[np.bool_]] | None:
    """The robot's gravity torques and ``tau`` with their means removed, and the joints
    gravity loads over the log (None when it loads none): those whose gravity torques vary
    by at least 5 % of the most varied joint's and span at least
    :data:`GRAVITY_RANGE_SHARE` of the largest gravity torque (on a short stretch gravity
    barely changes, and the torques' variations are the motion's, of either sign)."""
    g = _static_torques(robot, q)
    loaded = _loaded(g)
    if not np.any(loaded):
        return None
    return g - g.mean(axis=0), tau - tau.mean(axis=0), loaded


def gravity_loaded(robot: Robot, q: ArrayLike) -> NDArray[np.bool_]:
    """The joints (n,) whose torque sign the check against gravity judges at the
    configurations ``q`` (N, n) [rad] (:func:`opposite_sign`): those gravity loads enough
    over them; none for a robot without inertial parameters."""
    qq = _checks.as_array("q", q)
    if qq.ndim != 2 or qq.shape[0] < 2 or not np.any(robot.phi):
        return np.zeros(robot.n, dtype=bool)
    return _loaded(_static_torques(robot, qq[:: max(1, qq.shape[0] // _MAX_SAMPLES)]))


def _static_torques(robot: Robot, q: NDArray[np.float64]) -> NDArray[np.float64]:
    """The torques [N m] (N, n) that hold the robot at rest at ``q`` (N, n): gravity's, and
    its joint springs' where it has them (a gravity-compensation spring opposes gravity:
    without it, a shoulder's torques read as of the opposite sign)."""
    g = gravity_torques(robot, q)
    return g if robot.spring is None else g + robot.spring.torques(q)


def _flips(joints: Iterable[int], file: str | None = None) -> str:
    """The ``--units`` entries that flip the torques of ``joints`` (from 0): ``tau2=-1``,
    or a file's own, ``rec2.csv:tau2=-1``."""
    at = "" if file is None else f"{file}:"
    return ",".join(f"{at}tau{k + 1}=-1" for k in joints)


def opposite_sign(robot: Robot, log: TorqueLog, *, file: str | None = None) -> str | None:
    """The finding that a joint-side log's torques have the opposite sign to ``robot``'s
    (anti-correlated with its gravity torques and with its whole rigid-body torques along
    the logged motion, module docstring), or None; None too for a robot without inertial
    parameters to compare with. ``file``: the hint flips that recording's columns alone
    (``rec2.csv:tau2=-1``: one recording among several whose others read right).

    ``identify`` refuses such a log: a fit of the negated torques returns negated
    masses, and friction that pushes the arm."""
    if not np.any(robot.phi):
        return None
    step = max(1, log.n_samples // _MAX_SAMPLES)
    at = np.arange(0, log.n_samples, step)
    centred = _gravity_spread(robot, log.q[at], log.tau[at])
    if centred is None:  # gravity barely varies: its means and the motion's torques tell
        loaded, corr = np.zeros(robot.n, dtype=bool), np.zeros(robot.n)
    else:
        gc, tc, loaded = centred
        corr = _correlations(gc, tc)
    right = flipped = np.zeros(robot.n, dtype=bool)
    every = corr
    off_scale = np.zeros(robot.n, dtype=bool)
    closer: dict[int, tuple[float, float]] = {}
    pushing: dict[int, float] = {}
    if (whole := _motion_torques(robot, log, at)) is not None:  # each can be fooled alone
        model, ok = whole
        every, slope = _explained(model[ok], log.tau[at][ok])
        corr = np.where(loaded, np.maximum(corr, every), every)
        right, flipped = _confirmed(every, slope), _confirmed(-every, -slope) & ~loaded
        lo, hi = CONFIRMED_SLOPE
        off_scale = right.any() & ((-slope < lo) | (-slope > hi))
        closer = _closer_negated(model[ok], log.tau[at][ok])
        pushing = _pushing_as_read(log, at, model, ok, loaded & ~right)
        flipped = flipped | np.isin(np.arange(robot.n), [*closer, *pushing])
    # where the model explains other joints at their scale, a joint whose negated model
    # torques would not explain its own at about theirs holds something the rigid bodies
    # lack (a spring, a counterbalance), not a flipped sign; nor does one whose torques as
    # read are the model's plus a function of its own position and friction
    strong = (loaded & (corr < OPPOSITE_CORRELATION) & ~off_scale) | flipped
    if strong.any() and whole is not None:
        strong &= ~_reads_right(log, at, whole[0], whole[1], strong)
    if not strong.any():
        return None
    if right.any() or not loaded.any() or not bool(np.all(every[loaded] < 0)):
        return _opposite(corr, strong, loaded | right, robot.joint_names, closer, pushing, file)
    names = robot.joint_names
    j = int(np.flatnonzero(strong)[np.argmin(corr[strong])])
    said = (
        f"the measured torques are anti-correlated with the model's torques (gravity and "
        f"motion; correlation {corr[j]:+.2f} on {names[j]})"
    )
    unjudged = np.flatnonzero(~(loaded | strong))
    if unjudged.size == 0:
        every_joint = "tau=-1" if file is None else _flips(range(robot.n), file)
        return (
            f"{said}: the torque sign is probably opposite to the model's; hint: --units "
            f"{every_joint} reads them flipped"
        )
    seen = np.flatnonzero(loaded | strong)
    return (
        f"{said} on every joint judged ({', '.join(f'{names[k]} {corr[k]:+.2f}' for k in seen)}"
        "): the torque sign is probably opposite to the model's there; the sign of "
        f"{', '.join(names[k] for k in unjudged)}, whose torques the model's do not explain "
        "(gravity barely loads them, and friction or a drive's rotor inertia outweighs their "
        "links'), is not told by this check; hint: --units "
        f"{'tau=-1' if file is None else _flips(range(robot.n), file)} if every joint's is "
        f"opposite, --units {_flips(seen, file)} if these only"
    )


def opposite_sign_among(
    robot: Robot, log: TorqueLog, name: str, others: Iterable[TorqueLog]
) -> str | None:
    """:func:`opposite_sign` of the recording ``log`` named ``name``, its hint the
    recording's own entries (``rec2.csv:tau2=-1``) when one of the ``others`` (read
    lazily, only when ``log`` is found of the opposite sign) reads right: then ``--units
    tau2=-1`` would flip them too."""
    if (found := opposite_sign(robot, log)) is None:
        return None
    if any(opposite_sign(robot, x) is None for x in others):
        return opposite_sign(robot, log, file=name) or found
    return found


#: Position bins of the function of a joint's own position in :func:`_reads_right`.
SIGN_POSITION_BINS = 12
#: :func:`_reads_right` keeps a joint's sign when the torques as read leave at most this
#: share of the residual sum of squares the negated torques leave.
SIGN_RESIDUAL_SHARE = 0.5


def _sign_fits(
    log: TorqueLog,
    at: NDArray[np.intp],
    model: NDArray[np.float64],
    ok: NDArray[np.bool_],
    asked: NDArray[np.bool_],
) -> dict[int, tuple[float, float, float]]:
    """Per joint among ``asked`` (n,): the least-squares residual sums of squares
    [N^2 m^2] of the torques as read and negated, less the model's rigid-body torques
    ``model`` (at the samples ``at`` where ``ok``), on a function of the joint's own
    position (a spring, a counterbalance: linear in it plus a constant per
    :data:`SIGN_POSITION_BINS` bins of it) and friction (``fc sign(dq) + fv dq``), and the
    Coulomb coefficient ``fc`` [N m] of the torques as read. The samples whose velocity is
    within its noise band are left out: friction there is anywhere between ``-fc`` and
    ``fc``, and a Coulomb friction of 80 N m left its full step at the reversals in the
    residual, which then outweighed the rest (a right-signed UR5 shoulder called flipped).
    A joint with too few samples left is not given."""
    out: dict[int, tuple[float, float, float]] = {}
    dq = log.dq[at][ok]
    q = log.q[at][ok]
    tau = log.tau[at][ok]
    band = noise_band(velocity_noise_std(log.dq, log.t))
    for j in np.flatnonzero(asked):
        moving = np.abs(dq[:, j]) > max(band[j], MIN_MOTION)
        qj = q[moving, j]
        edges = np.quantile(qj, np.linspace(0.0, 1.0, SIGN_POSITION_BINS + 1)) if qj.size else ()
        which = np.clip(np.searchsorted(edges, qj, side="right") - 1, 0, None)
        which = np.minimum(which, SIGN_POSITION_BINS - 1)
        X = np.column_stack(
            [
                which[:, None] == np.arange(SIGN_POSITION_BINS),
                qj,
                np.sign(dq[moving, j]),
                dq[moving, j],
            ]
        ).astype(np.float64)
        if X.shape[0] <= 2 * X.shape[1]:
            continue
        left, fc = [], 0.0
        for k, y in enumerate((tau[moving, j], -tau[moving, j])):
            y = y - model[ok][moving, j]
            coef = np.linalg.lstsq(X, y, rcond=None)[0]
            left.append(float(np.sum((y - X @ coef) ** 2)))
            fc = float(coef[-2]) if k == 0 else fc
        out[int(j)] = (left[0], left[1], fc)
    return out


def _reads_right(
    log: TorqueLog,
    at: NDArray[np.intp],
    model: NDArray[np.float64],
    ok: NDArray[np.bool_],
    asked: NDArray[np.bool_],
) -> NDArray[np.bool_]:
    """The joints among ``asked`` (n,) whose torques as read, not negated, are the model's
    rigid-body torques ``model`` (at the samples ``at`` where ``ok``) plus a function of
    the joint's own position and friction (:func:`_sign_fits`): the least-squares
    residual of ``tau - model`` on those columns is at most :data:`SIGN_RESIDUAL_SHARE`
    of that of ``-tau - model``. Under a flipped sign the negated torques are the ones so
    explained, and the torques as read leave twice the rigid-body torques of every
    joint's motion. A 60 N m/rad spring on a Panda shoulder made its torques correlate
    -0.96 with gravity's at a factor of -1.17, as a flipped sign would; read as they are,
    they were its model's torques plus such a function."""
    out = np.zeros(log.n, dtype=bool)
    for j, (read, negated, _) in _sign_fits(log, at, model, ok, asked).items():
        out[j] = read <= SIGN_RESIDUAL_SHARE * negated
    return out


def _pushing_as_read(
    log: TorqueLog,
    at: NDArray[np.intp],
    model: NDArray[np.float64],
    ok: NDArray[np.bool_],
    asked: NDArray[np.bool_],
) -> dict[int, float]:
    """The joints among ``asked`` whose negated torques, not those as read, are the
    model's plus a function of their own position and friction (:func:`_sign_fits`, the
    reverse of :func:`_reads_right`) while the friction as read pushes (a negative Coulomb
    coefficient), with that coefficient [N m]: a flipped sign where friction outweighs
    the rigid bodies, which the correlations cannot see (a UR5 shoulder with 80 N m of
    Coulomb friction, flipped, correlated +0.52 with its model's torques). Asked of the
    joints gravity loads: the sign of one it does not is judged by the identification's
    dissipation check, which offers the structure without its friction as the way on."""
    fits = _sign_fits(log, at, model, ok, asked)
    return {
        j: fc
        for j, (read, negated, fc) in fits.items()
        if negated <= SIGN_RESIDUAL_SHARE * read and fc < 0.0
    }


#: A joint's measured torques are the negated model's (:func:`_closer_negated`) when
#: their RMS distance from those is below this share of that from the model's own...
NEGATED_DISTANCE_SHARE = 0.5
#: ... and the model's torques there have at least this share of the measured torques'
#: RMS (a joint the model barely loads tells nothing).
NEGATED_MODEL_SHARE = 0.3


def _closer_negated(
    model: NDArray[np.float64], tau: NDArray[np.float64]
) -> dict[int, tuple[float, float]]:
    """The joints whose measured torques ``tau`` (N, n) [N m] lie far closer to the negated
    model's torques ``model`` (N, n) than to the model's own, means included
    (:data:`NEGATED_DISTANCE_SHARE`, :data:`NEGATED_MODEL_SHARE`), with the RMS distances
    [N m] from the negated and from the model's torques. The correlations look at the
    variations alone: a UR5 elbow logged with the opposite sign held +15 N m where the
    model's gravity held -15 N m, while its variations correlated -0.01 to -0.43 with
    the model's, and the log was fitted without a word."""
    rms = lambda x: np.sqrt(np.mean(x**2, axis=0))  # noqa: E731
    near, far, size = rms(tau + model), rms(tau - model), rms(tau)
    hit = (near < NEGATED_DISTANCE_SHARE * far) & (rms(model) >= NEGATED_MODEL_SHARE * size)
    return {int(j): (float(near[j]), float(far[j])) for j in np.flatnonzero(hit)}


#: :func:`reversed_joint` questions a log whose residual, each motor's own friction and
#: rotor taken out, is at least this share of the RMS of what they leave of the torques
#: (the links' share; clean simulated Panda logs left 0.04, and 0.05 geared with rotors
#: that outweigh the links; a geared Panda's motor 3 logged reversed 0.37, 0.053 once
#: reversed).
REVERSED_MODEL_SHARE = 0.1
#: :func:`reversed_joint` changes one more column's signs while that leaves at most this
#: share of the sum of squares left before (a Panda's joints 2 and 5 reversed: joint 2
#: alone left 0.004 of it as read, joint 5 alone 0.99, both 1.3e-4; a geared Panda's
#: motors 3 and 6: motor 1 alone left 0.15 against motor 3's 0.18, joints 1 and 3 being
#: parallel near q2 = 0, and the move from motor 1 to motor 3 then 0.011 for 0.072).
REVERSED_STEP_SHARE = 0.75


@dataclass(frozen=True, slots=True)
class _Recorded:
    """A log's samples as recorded, for :func:`reversed_joint`: positions, velocities,
    accelerations (one derivation, :func:`_motion_accelerations`) and efforts (N, n) in
    the log's own columns, and the drive that reads them (None: joint-side torques)."""

    q: NDArray[np.float64]
    dq: NDArray[np.float64]
    ddq: NDArray[np.float64]
    tau: NDArray[np.float64]
    drive: Drive | None

    @property
    def joint_torques(self) -> NDArray[np.float64]:
        """The efforts as joint torques [N m] (N, n)."""
        return self.tau if self.drive is None else self.drive.joint_torques(self.tau)

    def carried(self) -> float:
        """The sum of squares [N^2 m^2] of what each motor's friction and rotor leave of the
        joint torques (:func:`_left_over`): the links' share, which a reversal disturbs (a
        geared arm's rotors outweigh it)."""
        states = (self.q, self.dq, self.ddq)
        _, dq, ddq = states if self.drive is None else self.drive.joint_states(*states)
        return _left_over(self.joint_torques, dq, ddq, self.drive)

    def left(self, robot: Robot, motion: NDArray[np.float64], torque: NDArray[np.float64]) -> float:
        """What the model and each motor's friction and rotor leave [N^2 m^2] (sum of
        squares over the joints) with the columns' signs ``motion`` and ``torque`` (n,)."""
        q, dq, ddq, tau = self.q * motion, self.dq * motion, self.ddq * motion, self.tau * torque
        if self.drive is not None:
            q, dq, ddq = self.drive.joint_states(q, dq, ddq)
            tau = self.drive.joint_torques(tau)
        model = rnea(robot, q, dq, ddq)
        if robot.spring is not None:
            model = model + robot.spring.torques(q)
        return _left_over(tau - model, dq, ddq, self.drive)


def _recorded(log: TorqueLog, drive: Drive | None) -> _Recorded | None:
    """:class:`_Recorded` of ``log`` at every k-th of its samples whose accelerations are
    known (:func:`_motion_accelerations`), or None when too few are."""
    at = np.arange(0, log.n_samples, max(1, log.n_samples // _MAX_SAMPLES))
    found = _motion_accelerations(log, at)
    if found is None:
        return None
    ddq, ok = found
    return _Recorded(log.q[at][ok], log.dq[at][ok], ddq[ok], log.tau[at][ok], drive)


def reversed_joint(robot: Robot, log: TorqueLog, drive: Drive | None = None) -> str | None:
    """The finding that columns of a log were recorded reversed, each position (and
    velocity) of the opposite sign, with or without its effort (a motor mounted or wired
    the other way: its encoder and current both negated; or the encoder alone), or None;
    None too for a robot without inertial parameters.

    ``log`` is as recorded, read through ``drive`` (motor-side positions and efforts,
    currents): a reversed column is the log's own, a motor's of a motor-side log (a
    coupled wrist's motor turns two joints), named so with the ``--units`` entries in the
    log's columns (``q6=-1,tau6=-1``).

    Judged on the robot's whole rigid-body torques over every joint, at the accelerations
    :func:`_motion_accelerations` derives (one derivation for the torques and the rotor
    columns, of the sign check's whole torques too), each joint's residual freed of its
    own viscous, Coulomb, offset and armature torques (least squares on ``dq``,
    ``sign(dq)``, 1, ``ddq``; through a drive, each motor's, where its friction acts, and
    its rotor's ``K^T (K ddq)``: a geared arm's rotors and motor friction, which the
    description lacks), against the torques those columns leave (the links' share: a
    geared arm's rotors outweigh it). The columns' signs change one step at a time
    (:func:`_changes`: a column's position and effort, position or effort reversed, or
    back, or a reversal moved to another column), the step that leaves least first, while
    it leaves at most :data:`REVERSED_STEP_SHARE` of what was left; the reversed columns
    are named when what they leave is within :data:`NEGATED_DISTANCE_SHARE` of the RMS as
    read, where that is at least :data:`REVERSED_MODEL_SHARE` of the links' share (a model
    that explains the log is not questioned), and below :data:`NEGATED_MODEL_SHARE` of it,
    a position among them, and better than every torque negated (then None: that is
    :func:`opposite_sign`'s finding, which a log of every torque negated, joint 2
    reversed, explained to 0.41 of its residual as read; where friction outweighs gravity
    on a joint, an encoder reversed and a torque negated look alike, and the reversal must
    explain it better). Efforts alone negated are named beside a reversal, and left to
    :func:`opposite_sign` without one. Judged before :func:`opposite_sign`, which read an
    encoder reversed as a torque of the opposite sign and asked for ``tau3=-1``. Before, a
    geared arm's motor 3 logged reversed was fitted to 34 % error with a spring suggested
    on joint 3; a coupled wrist's motor, which turns two joints, could not be named.

    Parameters
    ----------
    robot : Robot
    log : TorqueLog
        As recorded (its columns the drive's side and effort).
    drive : Drive, optional
        What reads ``log`` (:func:`~dynid.identification.log.joint_side_log`).

    Returns
    -------
    str or None
        The finding, one line with the ``--units`` entries.
    """
    if not np.any(robot.phi):
        return None
    rec = _recorded(log, drive)
    if rec is None:
        return None
    one = np.ones(log.n)
    total = rec.carried()
    read = rec.left(robot, one, one)
    if read < REVERSED_MODEL_SHARE**2 * total:
        return None
    motion, torque, left = one.copy(), one.copy(), read
    while True:  # the change of one column (or a move to another) that leaves least
        best = min(
            ((rec.left(robot, m, t), m, t) for m, t in _changes(motion, torque)),
            key=lambda x: x[0],
        )
        if not best[0] <= REVERSED_STEP_SHARE * left:
            break
        left, motion, torque = best
    if not left < NEGATED_DISTANCE_SHARE**2 * read or not left < NEGATED_MODEL_SHARE**2 * total:
        return None  # none explains it
    if np.all(motion > 0):
        return None  # torques alone negated explain it best: opposite_sign's
    if rec.left(robot, one, -one) <= left:  # every torque of the opposite sign
        return None
    return _reversed_line(robot, rec.drive, motion < 0, torque < 0, (left, read, total))


def _changes(
    motion: NDArray[np.float64], torque: NDArray[np.float64]
) -> Iterator[tuple[NDArray[np.float64], NDArray[np.float64]]]:
    """Every sign of the columns (``motion``, ``torque``: +-1, n) one step from these: a
    column set to another of its signs (position and effort reversed, position alone,
    effort alone, neither), or a reversed column's signs moved to one not reversed (a
    Panda's joints 1 and 3, parallel when joint 2 is near zero, look alike)."""
    states = ((-1.0, -1.0), (-1.0, 1.0), (1.0, -1.0), (1.0, 1.0))
    for j in range(motion.size):
        for m, t in states:
            if (m, t) != (motion[j], torque[j]):
                ms, ts = motion.copy(), torque.copy()
                ms[j], ts[j] = m, t
                yield ms, ts
    flipped = (motion < 0) | (torque < 0)
    for i in np.flatnonzero(flipped):
        for k in np.flatnonzero(~flipped):
            pair = np.array([i, k])
            ms, ts = motion.copy(), torque.copy()
            ms[pair], ts[pair] = ms[pair[::-1]], ts[pair[::-1]]
            yield ms, ts


def _reversed_line(
    robot: Robot,
    drive: Drive | None,
    motion: NDArray[np.bool_],
    torque: NDArray[np.bool_],
    sums: tuple[float, float, float],
) -> str:
    """:func:`reversed_joint`'s finding: the columns reversed (``motion``, n) and the
    efforts negated (``torque``, n) named in the log's own columns (a motor-side log's
    motors), what is left reversed and as read (``sums``: those and the torques' sums of
    squares), the ``--units`` entries."""
    left, read, total = sums
    motors = drive is not None and drive.side == "motor"
    names = [f"motor {k + 1}" if motors else robot.joint_names[k] for k in range(robot.n)]
    rev = np.flatnonzero(motion)
    alone = np.flatnonzero(torque & ~motion)
    one = rev.size == 1
    what = [
        ("its " if one else f"{names[k]}'s ") + ("position and torque" if torque[k] else "position")
        for k in rev
    ] + [f"{names[k]}'s torque" for k in alone]
    cols = ",".join(
        [f"q{k + 1}=-1" + (f",tau{k + 1}=-1" if torque[k] else "") for k in rev]
        + [f"tau{k + 1}=-1" for k in alone]
    )
    rates = ", ".join(f"dq{k + 1}=-1, ddq{k + 1}=-1" for k in rev)
    gears = drive is not None and not drive.is_coupled and bool(np.all(torque[rev]))
    return (
        f"{', '.join(names[k] for k in rev)} {'looks' if one else 'look'} recorded reversed: "
        f"{', '.join(what)} of the opposite sign to the model's convention (with "
        f"{'it' if one else 'them'} reversed, what the model and each "
        + ("motor's friction and rotor" if drive is not None else "joint's friction and armature")
        + f" leave is {np.sqrt(left / total):.2g} of the RMS of the torques the links carry "
        f"(what that friction leaves of them), {np.sqrt(read / total):.2g} as read): a "
        "motor or encoder mounted the other way; "
        f"hint: --units {cols} reads {'it' if one else 'them'} so (and {rates} for the log's "
        "velocity and acceleration columns, if it has them"
        + ("; the motors' columns of this motor-side log" if motors else "")
        + ")"
        + (
            "; or a negative gear_ratio in the drive file, a motor turning the other way"
            if gears
            else ""
        )
    )


def _left_over(
    r: NDArray[np.float64],
    dq: NDArray[np.float64],
    ddq: NDArray[np.float64],
    drive: Drive | None = None,
) -> float:
    """The sum of squares [N^2 m^2] of the residuals ``r`` (N, n) left by each joint's own
    viscous, Coulomb, offset and armature columns (``dq``, ``sign(dq)``, 1, ``ddq``); with
    a ``drive``, each motor's where its friction acts (``K_f^T`` of those of ``K_f dq``)
    and its rotor's (``K^T`` of ``K ddq``), the joints a motor couples fitted together
    (:func:`_own_terms`)."""
    return sum(g.left for g in _own_terms(r, dq, ddq, drive))


@dataclass(frozen=True)
class _OwnTerms:
    """One group's least-squares fit in :func:`_own_terms`: its motors (joints), per motor
    the coefficients ``fv, fc, fo, Ia`` (4,) and their covariance (4, 4) (white-noise
    formula), the residual sum of squares ``left`` [N^2 m^2], and per motor the mean of
    ``|v|`` and of ``v^2`` at its velocities ``v``."""

    motors: list[int]
    coef: NDArray[np.float64]
    cov: NDArray[np.float64]
    left: float
    speed: NDArray[np.float64]


def _own_terms(
    r: NDArray[np.float64],
    dq: NDArray[np.float64],
    ddq: NDArray[np.float64],
    drive: Drive | None = None,
) -> list[_OwnTerms]:
    """Each joint's (motor's) own viscous, Coulomb, offset and armature coefficients fitted
    to the residuals ``r`` (N, n), group by group (:func:`_motor_groups`: a coupled wrist's
    joints together), as :func:`_left_over` describes."""
    n = r.shape[1]
    Kf = np.eye(n) if drive is None else drive.friction_transmission
    K = np.eye(n) if drive is None else drive.transmission
    v, a = dq @ Kf.T, ddq @ K.T
    out = []
    for joints, motors in _motor_groups((K != 0) | (Kf != 0)):
        cols = []
        for k in motors:  # motor k's columns at the group's joints: (N, m) each
            for f in (v[:, k], np.sign(v[:, k]), np.ones(len(r))):
                cols.append(f[:, None] * Kf[k, joints])
            cols.append(a[:, k, None] * K[k, joints])
        X = np.stack(cols, axis=-1).reshape(len(r) * len(joints), len(cols))
        y = r[:, joints].reshape(-1)
        coef = np.linalg.lstsq(X, y, rcond=None)[0]
        left = float(np.sum((y - X @ coef) ** 2))
        dof = max(X.shape[0] - X.shape[1], 1)
        cov = (left / dof) * np.linalg.pinv(X.T @ X)
        m = len(motors)
        blocks = np.array([cov[4 * i : 4 * i + 4, 4 * i : 4 * i + 4] for i in range(m)])
        speed = np.array([[np.mean(np.abs(v[:, k])), np.mean(v[:, k] ** 2)] for k in motors])
        coefs = np.asarray(coef, dtype=np.float64).reshape(m, 4)
        out.append(_OwnTerms(motors, coefs, blocks, left, speed))
    return out


#: A motor's (joint's) friction and rotor read of the opposite sign in one recording to
#: another's (:func:`opposite_friction_among`) when each is at least this many standard
#: deviations from zero (white-noise formula: samples a few ms apart are correlated, so a
#: wide margin).
OWN_TERMS_SIGNIFICANCE = 8.0
#: ... and the one's size at least this share of the other's (a sign, not a drift).
OWN_TERMS_SIZE_SHARE = 0.3


def _own_signs(
    robot: Robot, log: TorqueLog, drive: Drive | None
) -> dict[int, tuple[float, float, float, float, float, float]] | None:
    """Per motor (joint) of a log as recorded: the power its fitted friction dissipates
    (``fc mean|v| + fv mean(v^2)``) and the rotor inertia fitted (``Ia``), each with its
    standard deviation, fitted to what the robot's links leave of its torques
    (:func:`_own_terms`): both positive for torques of the right sign; then ``mean|v|``
    and ``mean(v^2)`` at the motor. None: too few samples with known accelerations."""
    rec = _recorded(log, drive)
    if rec is None:
        return None
    q, dq, ddq = (rec.q, rec.dq, rec.ddq)
    if rec.drive is not None:
        q, dq, ddq = rec.drive.joint_states(q, dq, ddq)
    model = rnea(robot, q, dq, ddq)
    if robot.spring is not None:
        model = model + robot.spring.torques(q)
    out = {}
    for g in _own_terms(rec.joint_torques - model, dq, ddq, rec.drive):
        for i, k in enumerate(g.motors):
            grad = np.array([g.speed[i, 1], g.speed[i, 0], 0.0, 0.0])  # d power / d coef
            power, power_std = float(grad @ g.coef[i]), math.sqrt(grad @ g.cov[i] @ grad)
            ia, ia_std = float(g.coef[i, 3]), math.sqrt(g.cov[i][3, 3])
            out[k] = (power, power_std, ia, ia_std, float(g.speed[i, 0]), float(g.speed[i, 1]))
    return out


def _comparable(flipped: tuple, right: tuple, share: float) -> bool:
    """Whether a motor's terms read of the opposite sign (``flipped``: its
    :func:`_own_signs` values and the signs of its power and inertia) are of about the
    size of another recording's of the right sign (at least ``share`` of them), judged on
    the power where both tell it, else on the inertia."""
    (p, _, ia, *_), sp, si = flipped
    (q, _, ib, *_), sq, sj = right
    if sp and sq:
        return abs(p) >= share * abs(q)
    return bool(si and sj) and abs(ia) >= share * abs(ib)


def opposite_friction_among(
    robot: Robot,
    logs: Sequence[TorqueLog],
    names: Sequence[str],
    drive: Drive | None = None,
    *,
    reference: ArrayLike | None = None,
) -> str | None:
    """The finding that one recording's torques of a motor (joint) have the opposite sign
    to another recording's, read from the motor's own friction and rotor (:func:`_own_signs`):
    the friction dissipates and the inertia is positive in one, both the other way in
    the other, each beyond :data:`OWN_TERMS_SIGNIFICANCE` standard deviations and of a
    comparable size (:data:`OWN_TERMS_SIZE_SHARE`); or None.

    The check the whole rigid-body torques make (:func:`opposite_sign`) does not tell the
    sign of a joint whose torques the links barely make (a geared wrist: its rotor and
    friction outweigh them), and a fit of several recordings, one of them of the opposite
    sign there, averages that joint's friction to nothing (a current-logged UR5's motor
    4 flipped in one of two recordings: fitted to 9.4 %, its Coulomb friction left out,
    springs suggested). ``logs`` are as recorded (read through ``drive``); the hint is the
    file's own ``--units`` entry in the log's columns.

    ``reference`` (n, 3), a model's own ``fv, fc, Ia`` per motor (joint), where the drive's
    friction acts [N m s/rad, N m, kg m^2]: each recording is compared with it too, its
    power at the recording's own speeds (``fc mean|v| + fv mean(v^2)``), so that one
    recording alone is judged (a model identified on logs of the right sign dissipates
    where a flipped motor's fitted friction puts energy into the arm)."""
    if len(logs) < (1 if reference is not None else 2) or not np.any(robot.phi):
        return None
    signs = [_own_signs(robot, log, drive) for log in logs]
    model = None if reference is None else np.asarray(reference, dtype=np.float64)
    z, share = OWN_TERMS_SIGNIFICANCE, OWN_TERMS_SIZE_SHARE

    def sign(x: float, sd: float) -> int:
        return 0 if not abs(x) > z * sd else (1 if x > 0 else -1)

    def of_model(k: int, s: tuple[float, ...]) -> tuple | None:
        """Motor k of the model at the speeds ``s`` of a recording's terms."""
        if model is None or k >= model.shape[0]:
            return None
        fv, fc, ia = (float(x) for x in model[k])
        power = fc * s[4] + fv * s[5]
        return ((power, 0.0, ia, 0.0), sign(power, 0.0), sign(ia, 0.0))

    found: dict[int, list[int]] = {}  # recording: its motors of the opposite sign
    for k in range(logs[0].n):
        each = [
            None
            if s is None or k not in s
            else (s[k], sign(s[k][0], s[k][1]), sign(s[k][2], s[k][3]))
            for s in signs
        ]
        right = [e for e in each if e is not None and min(e[1:]) >= 0 and max(e[1:]) > 0]
        for r, e in enumerate(each):
            if e is None or not (max(e[1:]) <= 0 and min(e[1:]) < 0):
                continue
            mine = signs[r]
            assert mine is not None  # e is not None
            own = of_model(k, mine[k])
            ok = [o for o in (*right, own) if o is not None and min(o[1:]) >= 0 < max(o[1:])]
            if any(_comparable(e, o, share) for o in ok):
                found.setdefault(r, []).append(k)
    if not found:
        return None
    r = min(found)
    motors = found[r]
    who = "motor" if drive is not None and drive.side == "motor" else "joint"
    named = ", ".join(f"motor {k + 1}" if who == "motor" else robot.joint_names[k] for k in motors)
    others = [names[i] for i in range(len(names)) if i != r and i not in found]
    mine = signs[r]
    assert mine is not None  # found holds recordings with their terms
    power = any(mine[k][0] < -z * mine[k][1] for k in motors)
    inertia = any(mine[k][2] < -z * mine[k][3] for k in motors)
    what = " and ".join(
        w
        for w, said in (
            ("the friction fitted there puts energy into the arm", power),
            ("the rotor inertia fitted there is negative", inertia),
        )
        if said
    )
    against, where = (
        (f"those of {', '.join(others) or 'the other recordings'}", "in the others they are")
        if others or model is None
        else ("the model's", "the model's identified friction and rotor are")
    )
    return (
        f"{names[r]}: the torques of {named} read of the opposite sign to {against}: "
        f"{what}, where {where} of the right sign (a file logged with another sign "
        "convention; the check "
        "against the model's torques does not tell a joint the links barely load); hint: "
        f"--units {_flips(motors, names[r] if len(names) > 1 else None)} reads it flipped"
    )


@dataclass(frozen=True, slots=True)
class SignFinding:
    """One recording's sign finding (:func:`recording_sign_findings`).

    Attributes
    ----------
    name : str
        The recording's name (its file).
    kind : {"reversed", "opposite"}
        Columns recorded reversed (position and effort, :func:`reversed_joint`), or torques
        of the opposite sign (:func:`opposite_sign_among`, :func:`opposite_friction_among`).
    text : str
        The finding, without the name: the joints (motors) and the ``--units`` entries.
    """

    name: str
    kind: str
    text: str


def recording_sign_findings(
    robot: Robot,
    logs: Sequence[TorqueLog],
    names: Sequence[str],
    drive: Drive | None = None,
    *,
    sides: Sequence[TorqueLog] | None = None,
    reference: ArrayLike | None = None,
    first: bool = False,
    among: bool = True,
) -> tuple[SignFinding, ...]:
    """The sign checks of several recordings, in the one order ``identify`` refuses by and
    ``validate`` and ``observe`` judge by: per recording, columns recorded reversed
    (:func:`reversed_joint`, on the log as recorded through ``drive``), else torques of
    the opposite sign to the robot's (:func:`opposite_sign_among`, on its joint side,
    against the others'); then, among the recordings not found so, one whose motor
    (joint) the links barely load reads of the opposite sign to the others', told by its
    own friction and rotor (:func:`opposite_friction_among`; against ``reference`` too,
    a model's ``fv, fc, Ia`` (n, 3), so that one recording alone is judged).

    Parameters
    ----------
    robot : Robot
    logs : sequence of TorqueLog
        The recordings as recorded (the drive's side and effort), each with enough samples
        (:func:`too_few_samples`).
    names : sequence of str
        One name per recording.
    drive : Drive, optional
        What reads ``logs`` (:func:`~dynid.identification.log.joint_side_log`).
    sides : sequence of TorqueLog, optional
        The recordings at the joints, when already mapped (default: mapped here).
    reference : array_like, shape (n, 3), optional
        As :func:`opposite_friction_among`.
    first : bool
        Stop at the first finding (a check that refuses).
    among : bool
        Compare the recordings' own friction and rotors (False: logs that may hold
        contacts, whose external torques the motors' own terms would take for a sign).

    Returns
    -------
    tuple of SignFinding
        In the recordings' order, then the finding among them; empty when all read right.
    """
    if sides is None:
        sides = [joint_side_log(log, drive) for log in logs]
    out: list[SignFinding] = []
    for r, (name, log) in enumerate(zip(names, logs, strict=True)):
        if (mirrored := reversed_joint(robot, log, drive)) is not None:
            out.append(SignFinding(name, "reversed", mirrored))
        else:
            others = (x for i, x in enumerate(sides) if i != r)
            if (opposite := opposite_sign_among(robot, sides[r], name, others)) is not None:
                out.append(SignFinding(name, "opposite", opposite))
        if first and out:
            return tuple(out)
    if not among:
        return tuple(out)
    said = {f.name for f in out}
    rest = [r for r, name in enumerate(names) if name not in said]
    kept = [names[r] for r in rest]
    found = opposite_friction_among(
        robot, [logs[r] for r in rest], kept, drive, reference=reference
    )
    if found is not None:
        name = next(n for n in kept if found.startswith(f"{n}: "))
        out.append(SignFinding(name, "opposite", found.removeprefix(f"{name}: ")))
    return tuple(out)


def _motor_groups(acts: NDArray[np.bool_]) -> list[tuple[list[int], list[int]]]:
    """The joints and motors ``acts`` (motors x joints: motor k acts on joint j) links,
    group by group: a joint alone with its motor, a coupled wrist's joints together."""
    group = list(range(acts.shape[1]))

    def root(j: int) -> int:
        while group[j] != j:
            j = group[j]
        return j

    for row in acts:
        on = np.flatnonzero(row)
        for j in on[1:]:
            group[root(int(j))] = root(int(on[0]))
    roots = sorted({root(j) for j in range(acts.shape[1])})
    out = []
    for g in roots:
        joints = [j for j in range(acts.shape[1]) if root(j) == g]
        out.append((joints, [int(k) for k in np.flatnonzero(acts[:, joints].any(axis=1))]))
    return out


def _explained(
    model: NDArray[np.float64], tau: NDArray[np.float64]
) -> tuple[NDArray[np.float64], NDArray[np.float64]]:
    """The correlation (n,) of the measured torques ``tau`` (N, n) with the model's
    ``model`` (N, n), both centred, and the least-squares factor of ``tau`` on ``model``."""
    m, y = _centred(model), _centred(tau)
    with np.errstate(invalid="ignore", divide="ignore"):
        slope = np.sum(m * y, axis=0) / np.sum(m**2, axis=0)
    return _correlations(m, y), np.where(np.isfinite(slope), slope, 0.0)


def _confirmed(corr: NDArray[np.float64], slope: NDArray[np.float64]) -> NDArray[np.bool_]:
    """The joints whose measured torques the model's explain at about their own scale
    (:data:`CONFIRMED_CORRELATION`, :data:`CONFIRMED_SLOPE`)."""
    lo, hi = CONFIRMED_SLOPE
    out: NDArray[np.bool_] = (corr >= CONFIRMED_CORRELATION) & (slope >= lo) & (slope <= hi)
    return out


def _centred(x: NDArray[np.float64]) -> NDArray[np.float64]:
    out: NDArray[np.float64] = x - x.mean(axis=0)
    return out


def _motion_accelerations(
    log: TorqueLog, at: NDArray[np.intp]
) -> tuple[NDArray[np.float64], NDArray[np.bool_]] | None:
    """The accelerations (at.size, n) at the samples ``at`` of ``log`` that the checks
    against the whole rigid-body torques use, and where they are known: its logged
    accelerations, else the central difference of its velocities over
    +-:data:`MOTION_HALF_SPAN_S` (at least one and a half sample steps), known where that
    span stays inside the log and crosses no gap (a step over three median steps) and the
    states are finite. Linear in the velocities: of a log read through a drive, the
    drive's map of the recorded ones. None when fewer than :data:`MOTION_MIN_SAMPLES`
    samples are known."""
    t, dq = log.t, log.dq
    ts = t[at]
    if log.ddq is not None:
        ddq, ok = log.ddq[at], np.ones(at.size, dtype=bool)
    else:
        dt = np.diff(t)
        h = max(MOTION_HALF_SPAN_S, 1.5 * float(np.median(dt)))
        gaps = np.concatenate([[0], np.cumsum(dt > 3.0 * float(np.median(dt)))])
        lo, hi = np.searchsorted(t, ts - h), np.searchsorted(t, ts + h)
        ok = (ts - h >= t[0]) & (ts + h <= t[-1])
        ok &= gaps[np.minimum(hi, t.size - 1)] == gaps[np.maximum(lo - 1, 0)]
        ddq = np.column_stack(
            [
                (np.interp(ts + h, t, dq[:, j]) - np.interp(ts - h, t, dq[:, j])) / (2 * h)
                for j in range(log.n)
            ]
        )
    ok &= np.all(np.isfinite(ddq) & np.isfinite(log.q[at]) & np.isfinite(dq[at]), axis=1)
    if np.count_nonzero(ok) < MOTION_MIN_SAMPLES:
        return None
    return ddq, ok


def _motion_torques(
    robot: Robot, log: TorqueLog, at: NDArray[np.intp]
) -> tuple[NDArray[np.float64], NDArray[np.bool_]] | None:
    """The robot's rigid-body torques ``M ddq + c + g`` (no friction, its spring
    included) at the samples ``at`` of ``log``, at the accelerations
    :func:`_motion_accelerations` gives, and where they are known (None: too few)."""
    found = _motion_accelerations(log, at)
    if found is None:
        return None
    ddq, ok = found
    dq = log.dq
    model = np.zeros_like(ddq)
    model[ok] = rnea(robot, log.q[at][ok], dq[at][ok], ddq[ok])
    if robot.spring is not None:
        model[ok] += robot.spring.torques(log.q[at][ok])
    return model, ok


def sign_confirmed(robot: Robot, logs: Sequence[TorqueLog]) -> NDArray[np.bool_]:
    """The joints (n,) whose torque sign the robot's whole rigid-body torques confirm over
    the joint-side ``logs`` pooled: they explain the measured torques at about their own
    scale (correlation at least :data:`CONFIRMED_CORRELATION`, least-squares slope within
    :data:`CONFIRMED_SLOPE`). A joint gravity does not load is judged so too: friction
    that a short log's fit leaves pushing there (``fv5 = -0.09`` on 2 s of a Panda's
    motion, whose wrist torques correlate +0.99 with the model's) is no flipped sign.
    Correlation alone can be fooled where friction outweighs the rigid body (the Panda's
    last joint: -0.92 on a log of the right sign), the slope then far from 1."""
    if not np.any(robot.phi) or not logs:
        return np.zeros(robot.n, dtype=bool)
    step = max(1, sum(g.n_samples for g in logs) // _MAX_SAMPLES)
    model, tau = [], []
    for g in logs:
        at = np.arange(0, g.n_samples, step)
        if at.size and (whole := _motion_torques(robot, g, at)) is not None:
            model.append(whole[0][whole[1]])
            tau.append(g.tau[at][whole[1]])
    if not model:
        return np.zeros(robot.n, dtype=bool)
    return _confirmed(*_explained(np.concatenate(model), np.concatenate(tau)))


def _opposite(
    corr: NDArray[np.float64],
    strong: NDArray[np.bool_],
    judged: NDArray[np.bool_],
    names: tuple[str, ...],
    closer: dict[int, tuple[float, float]] | None = None,
    pushing: dict[int, float] | None = None,
    file: str | None = None,
) -> str | None:
    """The finding of the joints ``strong`` (n,) anti-correlated with the model's torques
    (``corr``, n), or closer to its negated torques (``closer``: the RMS distances from
    the negated and from the model's, :func:`_closer_negated`; ``pushing``: the Coulomb
    coefficient [N m] of friction that pushes as read, :func:`_pushing_as_read`), while
    others the checks judge (``judged``) are not: named, with the ``--units`` entries
    that flip their columns alone (``tau2=-1``; of ``file`` alone: ``rec2.csv:tau2=-1``),
    and the joints neither check judges."""
    rest = np.flatnonzero(judged & ~strong)
    free = np.flatnonzero(~judged & ~strong)
    bad = np.flatnonzero(strong)
    which = ", ".join(names[k] for k in bad)
    near = {k: v for k, v in (closer or {}).items() if strong[k]}
    push = {k: v for k, v in (pushing or {}).items() if strong[k]}
    anti = bool(np.all(corr[bad] < OPPOSITE_CORRELATION))
    evidence = (
        f"correlation {', '.join(f'{corr[k]:+.2f}' for k in bad)}"
        if not near and not push
        else "; ".join(
            f"{names[k]}: correlation {corr[k]:+.2f}"
            + (
                f", {near[int(k)][0]:.3g} N m RMS from the negated model's torques against "
                f"{near[int(k)][1]:.3g} from the model's, means included"
                if k in near
                else ""
            )
            + (
                f", friction that pushes as read (Coulomb {push[int(k)]:.3g} N m), the "
                "negated torques the model's plus friction"
                if k in push and k not in near
                else ""
            )
            for k in map(int, bad)
        )
    )
    return (
        f"the measured torques of {which} are "
        + ("anti-correlated with" if anti else "of the opposite sign to")
        + f" the model's torques (gravity and motion; {evidence})"
        + (
            f" while those of {', '.join(f'{names[k]} ({corr[k]:+.2f})' for k in rest)} are "
            "not, on some joints only"
            if rest.size
            else ""
        )
        + f": the torque sign of {which} is probably opposite to the model's"
        + (
            f" (the sign of {', '.join(names[k] for k in free)}, whose torques the model's "
            "do not explain, is not told by this check)"
            if free.size
            else ""
        )
        + (
            f"; hint: --units "
            f"{'tau=-1' if file is None else _flips(range(len(names)), file)} if every "
            f"joint's is opposite, --units {_flips(bad, file)} if these only"
            if rest.size == 0 and bad.size > 1
            else f"; hint: --units {_flips(bad, file)} reads "
            + ("it" if bad.size == 1 else "them")
            + " flipped (beside the torques' unit, if one is given)"
        )
    )


def _torque_scale(robot: Robot, q: NDArray[np.float64], tau: NDArray[np.float64]) -> float | None:
    """The least-squares factor ``a`` of ``tau ~ a g(q)`` over the joints gravity loads,
    their means removed (None when gravity loads none)."""
    centred = _gravity_spread(robot, q, tau)
    if centred is None:
        return None
    gc, tc, loaded = centred
    return float(np.sum(gc[:, loaded] * tc[:, loaded]) / np.sum(gc[:, loaded] ** 2))


def _scale_line(a: float, refused: bool = False, drive: Drive | None = None) -> str:
    """The scale finding of factor ``a``, with its hint (and, ``refused``, the way to read
    the torques as they are); through a ``drive`` of currents, the torque constants and
    gear ratios the torques were made with are named, not a missing drive file."""
    p = round(math.log10(abs(a)))
    if drive is not None and drive.effort == "current":
        at = "at the motor" if drive.side == "motor" else "at the joint"
        hint = (
            f"check torque_constant (N m per A, {at}) and gear_ratio in the drive file"
            + ("; currents in mA: --units tau=0.001" if p == 3 else "")
            + (" (--units tau=1 reads the currents as they are)" if refused else "")
        )
        return (
            f"the measured torques (the currents times the drive's torque constants) are "
            f"{abs(a):.3g} times the model's gravity torques: the drive file's torque_constant "
            f"or gear_ratio looks off by that factor; hint: {hint}"
        )
    hint = (
        "--units tau=mNm"
        if p == 3
        else "--units tau=1000 (kN m)"
        if p == -3
        else 'currents need a drive file with effort = "current" and torque_constant'
    )
    if refused:
        hint += " (--units tau=Nm reads them as N m)"
    return (
        f"the measured torques are {abs(a):.3g} times the model's gravity torques: a unit "
        f"off by a power of ten, or currents logged as torques; hint: {hint}"
    )


def torque_unit_finding(robot: Robot, log: TorqueLog, drive: Drive | None = None) -> str | None:
    """The finding that a joint-side log's torques are in mN m (or kN m) read as N m, or
    None: their factor to ``robot``'s gravity torques (:func:`check_torque_log`'s scale)
    within :data:`UNIT_SCALE_TOLERANCE` of ``1e3`` (or ``1e-3``).

    The commands refuse such a log unless the torques' unit is said (``--units tau=...``):
    a fit of it is a model 1000 times too heavy that predicts its own log to the noise
    floor. A factor far from a power of ten (a model that is wrong, currents) is only
    warned. None too where :func:`check_torque_log` makes no scale finding: a robot without
    inertial parameters, every joint frozen, positions that look like degrees, torques of
    the opposite sign, a log too short to check (:func:`too_few_samples`). Through a
    ``drive`` of currents, the line names its torque constants and gear ratios."""
    if too_few_samples(log) is not None:
        return None
    a = _against_gravity(robot, log).scale
    if a is None or a == 0:
        return None
    off = math.log10(abs(a))
    if abs(abs(off) - 3) > math.log10(UNIT_SCALE_TOLERANCE):
        return None
    return _scale_line(a, refused=True, drive=drive)


#: Relative tolerance of "``dq`` agrees with the derivative of ``q``" (filtered velocities
#: lag and smooth: 25 % is far from the factor 57.3 of degrees either way).
_RATE_AGREES = 0.25
#: Speed [rad/s] above which velocities are too fast for radians on a joint without dq_max.
_FAST_RAD_S = 2 * np.pi


def _degrees(robot: Robot, log: TorqueLog) -> list[str]:
    """The degrees finding (module docstring), or nothing."""
    q = log.q
    rev = ~np.asarray(robot.prismatic)
    lo, hi = np.min(q, axis=0), np.max(q, axis=0)
    span = hi - lo
    lim_lo = np.where(np.isfinite(robot.q_min), robot.q_min, -2 * np.pi)
    lim_hi = np.where(np.isfinite(robot.q_max), robot.q_max, 2 * np.pi)
    r = np.pi / 180.0
    suspect = rev & (span > 2 * np.pi) & (lo * r >= lim_lo - 0.1) & (hi * r <= lim_hi + 0.1)
    why: dict[int, tuple[str, str]] = {}
    for j in map(int, np.flatnonzero(suspect)):
        verdict = _rate_verdict(robot, log, j)
        if verdict is None:
            suspect[j] = False
        else:
            why[j] = verdict
    if np.any(suspect) and np.sum(suspect) >= max(1, int(np.sum(rev & (span > 0.1))) // 2):
        j = int(np.flatnonzero(suspect)[0])
        reason, hint = why[j]
        return [
            f"positions look like degrees: joint {robot.joint_names[j]} spans "
            f"{span[j]:.4g} rad, which in degrees fits its limits{reason}; hint: {hint}"
        ]
    return []


def joint_rate_factor(log: TorqueLog, j: int) -> float:
    """``k`` [1] of ``d q / dt ~ k dq`` on joint ``j`` of ``log``, by least squares: 1 when
    its positions and velocities share a unit, ``180 / pi`` for positions in degrees and
    velocities in radians per second; NaN for fewer than 5 samples or a joint at rest."""
    t, q, v = log.t, log.q[:, j], np.ascontiguousarray(log.dq[:, j])
    den = float(v @ v)
    if t.size < 5 or not den > 0:
        return float("nan")
    return float(signals.derivative(t, q) @ v) / den  # in blocks: a long log's column


def _rate_verdict(robot: Robot, log: TorqueLog, j: int) -> tuple[str, str] | None:
    """What the velocities of joint ``j`` say of positions that may be degrees: None (they
    are radians), or the reason and the hint of the warning.

    ``k`` is the least-squares factor of ``d q / dt ~ k dq``: 1 when ``q`` and ``dq``
    share a unit, ``180 / pi`` when ``q`` is in degrees and ``dq`` in radians per second.
    """
    k = joint_rate_factor(log, j)
    if not np.isfinite(k):
        return "", "--units q=deg"
    v = log.dq[:, j]
    deg = 180.0 / np.pi
    if abs(k / deg - 1.0) < _RATE_AGREES:
        return (
            f", and its velocities are {k:.3g} times slower than the derivative of its "
            "positions (degrees against radians per second)",
            "--units q=deg",
        )
    if abs(k - 1.0) < _RATE_AGREES:
        fast = float(robot.dq_max[j]) if np.isfinite(robot.dq_max[j]) else _FAST_RAD_S
        peak = float(np.quantile(np.abs(v), 0.99))
        if peak <= 1.5 * fast:
            return None  # one unit, and plausible radians per second: radians
        return (
            f", and its velocities, which agree with the derivative of its positions, reach "
            f"{peak:.4g} per second, too fast for radians (limit {fast:.3g} rad/s): both "
            "look like degrees",
            "--units q=deg,dq=deg/s" + (",ddq=deg/s^2" if log.ddq is not None else ""),
        )
    return "", "--units q=deg"


def _milliseconds(log: TorqueLog) -> list[str]:
    t, q, dq = log.t, log.q, log.dq
    if t.size < 5:
        return []
    num = den = 0.0
    for j in range(q.shape[1]):  # one joint at a time: temporaries of one column (long logs)
        v = np.ascontiguousarray(dq[:, j])
        num += float(signals.derivative(t, q[:, j]) @ v)  # in blocks: a long log's column
        den += float(v @ v)
    if den > 0:
        k = num / den
        if 3e-4 < k < 3e-3:
            return [
                f"the velocities are {1 / k:.3g} times the derivative of the positions: the "
                "time column looks like milliseconds; hint: --units t=ms"
            ]
    return []


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
    s = 1.4826 * float(np.median(np.abs(d - np.median(d)))) / math.sqrt(2.0)
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
    shown = ", ".join(f"{float(t[r]):.6g}" for r in rows[:SPIKE_TIMES_SHOWN])
    more = rows.size - min(rows.size, SPIKE_TIMES_SHOWN)
    rest = f" and {more} more" if more else ""
    return f"{rows.size} (at t = {shown} s{rest}, largest {largest:.3g} sigma)"


#: Time units a time column may be recorded in instead of seconds: the ``--units t=``
#: spelling and its length [s].
_TIME_UNITS = (("ms", 1e-3), ("us", 1e-6), ("ns", 1e-9))


def velocity_rate_factor(log: TorqueLog) -> float:
    """``k`` of ``d q / dt ~ k dq`` [1]: 1 when ``t``, ``q`` and ``dq`` share their units.

    The positions' differences over their time steps against the mean of the two samples'
    recorded velocities, pooled over every joint by least squares; a step where a position
    jumps by more than half a turn (a wrap) or the time by more than 1.5 median steps (a
    gap) is left out. NaN for velocities derived from the positions, fewer than 5 samples
    or a log that does not move.
    """
    if log.dq_derived or log.n_samples < 5:
        return float("nan")
    dt = np.diff(log.t)
    ok = dt <= 1.5 * float(np.median(dt))
    num = den = 0.0
    for j in range(log.n):  # one joint at a time: temporaries of one column (long logs)
        dqj = np.diff(log.q[:, j])
        v = 0.5 * (log.dq[1:, j] + log.dq[:-1, j])
        keep = ok & (np.abs(dqj) <= np.pi)
        num += float(np.sum(dqj[keep] / dt[keep] * v[keep]))
        den += float(np.sum(v[keep] * v[keep]))
    return num / den if den > 0 else float("nan")


def time_unit_finding(name: str, log: TorqueLog) -> str | None:
    """One line naming the file ``name`` when its recorded velocities are a power of ten
    (1e3, 1e6, 1e9, within 25 %) times the rate of change of its positions per unit of its
    time column: the time column is then in ms, us or ns, not seconds
    (:func:`velocity_rate_factor`); None otherwise."""
    k = velocity_rate_factor(log)
    if not np.isfinite(k) or k <= 0:
        return None
    for unit, size in _TIME_UNITS:
        if abs(k / size - 1.0) < _RATE_AGREES:
            return (
                f"{name}: its recorded velocities are {1 / k:.4g} times the rate of change of "
                f"its positions per unit of its time column: the time column looks like "
                f"{unit}, not seconds (t x {1 / size:g}); every filter, derivative and "
                f"frequency read from it would be off by that factor; hint: --units t={unit}"
            )
    return None
