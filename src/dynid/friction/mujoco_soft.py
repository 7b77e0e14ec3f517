"""MuJoCo's joint ``frictionloss`` as the soft constraint it is: a ramp, not a sign.

MuJoCo's dry friction of a joint is a soft constraint row of the joint's velocity. Its
force, in ``mj_inverse`` and in the forward solver alike, is the linear law of the soft
constraint clamped to ``[-f_c, f_c]``:

.. math:: \\tau = \\mathrm{clip}\\big((\\ddot q + b \\dot q) / R, \\; -f_c, f_c\\big),
          \\quad R = \\frac{1 - d}{d} A_0, \\quad b = \\frac{2}{d_{max} \\tau_c}

(MuJoCo's documentation, Computation: soft constraints; ``d`` the impedance at zero
violation, solimp's ``dmin``; ``dmax`` its second value; ``tau_c`` solref's time
constant, which MuJoCo raises to at least twice the timestep; ``A_0`` the dof's inverse
weight at ``qpos0``, ``dof_invweight0``, the diagonal of ``M(qpos0)^{-1}`` with the
armature). At rest the torque rises with the velocity at the slope

.. math:: S = \\frac{b}{R} = \\frac{2}{\\tau_c (1 - d) A_0} \\quad (d_{min} = d_{max} = d)

[N m s/rad] (MuJoCo's defaults, ``d = 0.9``, ``dmax = 0.95``, ``tau_c = 0.02`` s: about
``1000 / A_0``) and saturates at ``f_c``. A smooth Coulomb law ``fc tanh(dq / w)`` is a
ramp of slope ``fc / w`` saturating at ``fc``: per joint ``solreffriction`` (``tau_c``
two timesteps, the shortest MuJoCo keeps, the fastest stable response) and
``solimpfriction`` (``d``) set the slope closest to the law, with ``frictionloss = fc``
and ``damping = fv`` as identified; any other law the ramp closest to it, a sharp law
without a band the steepest slope MuJoCo holds (``d = 0.9999``). The acceleration term
shifts the ramp by ``-ddq d tau_c / 2`` in velocity (2 mrad/s per rad/s^2 at MuJoCo's
default timestep, 0.002 s): a longer time constant would move it further, a shorter one
(solref's direct form) would hold it closer in ``mj_inverse`` but makes the forward step
chatter at rest. The shift is what ``mj_inverse`` meets at a velocity reversal: for
``d tau_c / 2`` before it the torque takes the acceleration's sign, up to ``2 f_c`` off
the law, and the RMS over a motion grows with the square root of its reversals a second
(:func:`mujoco_dry_friction` is that torque, :func:`dry_friction_error` its difference
from a law along a motion, :func:`representative_motion` the sine the export says it on).
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
from numpy.typing import ArrayLike, NDArray

from .model import FrictionModel, FrictionSum

__all__ = [
    "MAX_IMPEDANCE",
    "MIN_IMPEDANCE",
    "MOTION_PERIOD_S",
    "MOTION_STEP_S",
    "DryFrictionError",
    "SoftFrictionLoss",
    "dry_friction_error",
    "frictionloss_slope",
    "impedance_for_slope",
    "mujoco_dry_friction",
    "representative_motion",
    "soft_frictionloss",
]

#: MuJoCo's impedance bounds (``mjMINIMP``, ``mjMAXIMP``): solimp outside is clamped.
MIN_IMPEDANCE = 0.0001
MAX_IMPEDANCE = 0.9999


@dataclass(frozen=True, slots=True)
class SoftFrictionLoss:
    """Per-joint settings of MuJoCo's soft dry friction (n joints).

    Attributes
    ----------
    slope : ndarray, shape (n,)
        Torque per velocity at rest [N m s/rad], :func:`frictionloss_slope` of the
        settings below.
    timeconst : ndarray, shape (n,)
        ``solreffriction`` time constant [s] (damping ratio 1, which friction rows do not
        use).
    impedance : ndarray, shape (n,)
        ``solimpfriction`` ``dmin = dmax`` (width 0.001, MuJoCo's).
    rms_error : ndarray, shape (n,)
        RMS difference [N m] at each joint, moving alone over ``(0, dq_max]``, between the
        law's odd part and ``min(slope dq, frictionloss) + damping dq``.
    """

    slope: NDArray[np.float64]
    timeconst: NDArray[np.float64]
    impedance: NDArray[np.float64]
    rms_error: NDArray[np.float64]


def frictionloss_slope(
    timeconst: ArrayLike, impedance: ArrayLike, invweight: ArrayLike
) -> NDArray[np.float64]:
    """MuJoCo's dry friction torque per velocity at rest [N m s/rad],
    ``S = 2 / (tau_c (1 - d) A_0)`` (module docstring), for time constants ``tau_c`` [s]
    (at least two timesteps), impedances ``d`` (``dmin = dmax``) and inverse weights
    ``A_0`` [1/(kg m^2)] (``dof_invweight0``), broadcast."""
    tc, d, A = (np.asarray(x, dtype=np.float64) for x in (timeconst, impedance, invweight))
    return np.asarray(2.0 / (tc * (1.0 - d) * A), dtype=np.float64)


def impedance_for_slope(
    slope: ArrayLike, timeconst: ArrayLike, invweight: ArrayLike
) -> NDArray[np.float64]:
    """The impedance ``d`` that gives the slope ``S`` [N m s/rad] at time constant
    ``tau_c`` [s] and inverse weight ``A_0``: ``1 - 2 / (tau_c A_0 S)``, within MuJoCo's
    bounds :data:`MIN_IMPEDANCE`, :data:`MAX_IMPEDANCE`."""
    S, tc, A = (np.asarray(x, dtype=np.float64) for x in (slope, timeconst, invweight))
    d = 1.0 - 2.0 / (tc * A * S)
    return np.asarray(np.clip(d, MIN_IMPEDANCE, MAX_IMPEDANCE), dtype=np.float64)


def _odd_alone(friction: FrictionModel | FrictionSum, j: int, v: NDArray[np.float64]) -> NDArray:
    """The odd part [N m] of joint ``j``'s friction torque with that joint alone moving
    at the velocities ``v`` [rad/s] (a law at the motors reflected, ``K^T f(K dq)``)."""
    grid = np.zeros((v.size, friction.n))
    grid[:, j] = v
    return np.asarray(0.5 * (friction.torques(grid)[:, j] - friction.torques(-grid)[:, j]))


def _best_slope(
    odd: NDArray[np.float64], v: NDArray[np.float64], fc: float, fv: float, bounds: tuple
) -> tuple[float, float]:
    """The slope in ``bounds`` [N m s/rad] whose ramp ``min(S v, fc) + fv v`` is closest
    (RMS) to ``odd`` on the velocities ``v``, and that RMS [N m]."""
    from scipy.optimize import minimize_scalar  # scipy on first use (start-up time)

    def rms(log_s: float) -> float:
        ramp = np.minimum(np.exp(log_s) * v, fc) + fv * v
        return float(np.sqrt(np.mean((ramp - odd) ** 2)))

    grid = np.linspace(np.log(bounds[0]), np.log(bounds[1]), 61)  # the valley first
    k = int(np.argmin([rms(x) for x in grid]))
    if k == grid.size - 1:  # sharp: the steepest
        return float(bounds[1]), rms(grid[k])
    lo, hi = grid[max(k - 1, 0)], grid[k + 1]
    res = minimize_scalar(rms, bounds=(lo, hi), method="bounded", options={"xatol": 1e-4})
    return float(np.exp(res.x)), float(res.fun)


def soft_frictionloss(
    friction: FrictionModel | FrictionSum,
    damping: ArrayLike,
    frictionloss: ArrayLike,
    dq_max: ArrayLike,
    invweight: ArrayLike,
    timestep: float,
    n_points: int = 4000,
) -> SoftFrictionLoss:
    """The ``solreffriction`` and ``solimpfriction`` per joint that make MuJoCo's dry
    friction ``frictionloss`` [N m] (n,), beside ``damping`` [N m s/rad] (n,), closest to
    the friction model at each joint moving alone.

    The slope at rest is fitted (RMS over ``n_points`` velocities spread evenly over
    ``(0, dq_max_j]`` [rad/s]) between the ramp that reaches ``frictionloss`` at
    ``dq_max`` and the steepest MuJoCo holds at the time constant ``2 timestep`` [s]
    (:data:`MAX_IMPEDANCE`): a smooth law's ``fc tanh(dq / w)`` near ``0.8 fc / w``, a
    sharp one the steepest. A slope below what ``2 timestep`` reaches takes a longer time
    constant. ``invweight`` (n,) [1/(kg m^2)]: MuJoCo's ``dof_invweight0``, the diagonal of
    the inverse mass matrix (armature included) at the joints' zero.

    Returns
    -------
    SoftFrictionLoss
        Joints without ``frictionloss`` get MuJoCo's defaults' impedance 0.9 and an RMS
        difference of their friction's odd part against ``damping dq``.
    """
    n = friction.n
    fv, fc, vmax, A = (
        np.broadcast_to(np.asarray(x, dtype=np.float64), (n,))
        for x in (damping, frictionloss, dq_max, invweight)
    )
    tc = np.full(n, 2.0 * float(timestep))
    steepest = frictionloss_slope(tc, MAX_IMPEDANCE, A)
    slope, rms = np.zeros(n), np.zeros(n)
    for j in range(n):
        v = np.linspace(vmax[j] / n_points, vmax[j], n_points)
        odd = _odd_alone(friction, j, v)
        if fc[j] <= 0:
            rms[j] = float(np.sqrt(np.mean((fv[j] * v - odd) ** 2)))
            continue
        bounds = (min(fc[j] / vmax[j], steepest[j]), steepest[j])
        slope[j], rms[j] = _best_slope(odd, v, float(fc[j]), float(fv[j]), bounds)
    held = fc > 0
    # a slope below the one two timesteps reach: the time constant that reaches it
    floor = frictionloss_slope(tc, MIN_IMPEDANCE, A)
    slow = held & (slope < floor)
    tc = np.where(slow, 2.0 / ((1.0 - MIN_IMPEDANCE) * A * np.where(slow, slope, 1.0)), tc)
    d = np.where(held, impedance_for_slope(np.where(held, slope, 1.0), tc, A), 0.9)
    return SoftFrictionLoss(slope, tc, d, rms)


#: The representative motion the MJCF export measures MuJoCo's dry friction along
#: (:func:`representative_motion`): each joint's velocity a sine of this period [s], two
#: reversals per period (0.4 a second; ``dynid excite``'s trajectories reverse each joint
#: up to about 0.4 times a second), sampled every :data:`MOTION_STEP_S` [s], finer than the
#: time the constraint takes the acceleration's sign at a reversal (``d tau_c / 2``).
MOTION_PERIOD_S = 5.0
MOTION_STEP_S = 1e-4


@dataclass(frozen=True, slots=True)
class DryFrictionError:
    """MuJoCo's friction of the joints against the law's along a motion (n joints).

    Attributes
    ----------
    rms : ndarray, shape (n,)
        RMS difference [N m] over the motion, per joint.
    worst : ndarray, shape (n,)
        The largest difference [N m] per joint, and the velocity ``worst_dq`` [rad/s] and
        acceleration ``worst_ddq`` [rad/s^2] of the joint where it happens.
    worst_dq, worst_ddq : ndarray, shape (n,)
    window_s : ndarray, shape (n,)
        ``d tau_c / 2`` [s]: how long before each velocity reversal the constraint's torque
        already takes the sign of the acceleration (the ramp shifted by ``-ddq d tau_c / 2``
        in velocity, the velocity changing at ``ddq``).
    """

    rms: NDArray[np.float64]
    worst: NDArray[np.float64]
    worst_dq: NDArray[np.float64]
    worst_ddq: NDArray[np.float64]
    window_s: NDArray[np.float64]


def representative_motion(
    dq_max: ArrayLike, period: float = MOTION_PERIOD_S, step: float = MOTION_STEP_S
) -> tuple[NDArray[np.float64], NDArray[np.float64]]:
    """Velocities [rad/s] and accelerations [rad/s^2] (N, n) of the motion the export
    measures MuJoCo's friction along: every joint's velocity ``V_j sin(2 pi t / period)``,
    ``V_j`` half its velocity limit ``dq_max`` (n,) [rad/s] (1 rad/s where none is
    finite), over one ``period`` [s] at the instants ``(k + 1/2) step`` [s] (none exactly
    at a reversal)."""
    vmax = np.asarray(dq_max, dtype=np.float64)
    amp = 0.5 * np.where(np.isfinite(vmax) & (vmax > 0), vmax, 2.0)
    w = 2.0 * np.pi / period
    t = (np.arange(int(round(period / step))) + 0.5) * step
    dq = np.sin(w * t)[:, None] * amp[None, :]
    ddq = w * np.cos(w * t)[:, None] * amp[None, :]
    return dq, ddq


def mujoco_dry_friction(
    dq: ArrayLike, ddq: ArrayLike, frictionloss: ArrayLike, soft: SoftFrictionLoss
) -> NDArray[np.float64]:
    """MuJoCo's dry friction torque [N m] (N, n) at joint velocities ``dq`` [rad/s] and
    accelerations ``ddq`` [rad/s^2] (N, n), as ``mj_inverse`` gives it (the forward step's
    constraint force alike): ``clip((ddq + b dq) / R, -fc, fc)``, with ``b / R`` the
    slope at rest ``S`` and ``b = 2 / (d tau_c)`` (module docstring), so
    ``clip(S (dq + ddq d tau_c / 2), -fc, fc)`` for ``frictionloss`` ``fc`` (n,) [N m] and
    the joints' settings ``soft`` (:func:`soft_frictionloss`)."""
    v, a = np.asarray(dq, dtype=np.float64), np.asarray(ddq, dtype=np.float64)
    fc = np.asarray(frictionloss, dtype=np.float64)
    shift = 0.5 * soft.impedance * soft.timeconst
    return np.asarray(np.clip(soft.slope * (v + a * shift), -fc, fc), dtype=np.float64)


def dry_friction_error(
    friction: FrictionModel | FrictionSum,
    damping: ArrayLike,
    frictionloss: ArrayLike,
    soft: SoftFrictionLoss,
    dq: ArrayLike,
    ddq: ArrayLike,
) -> DryFrictionError:
    """How far the friction MuJoCo's joints hold (``damping`` [N m s/rad] and
    ``frictionloss`` [N m] (n,) with ``soft``'s slopes, :func:`mujoco_dry_friction`) is
    from the odd part of the law ``friction`` at the velocities ``dq`` [rad/s] and
    accelerations ``ddq`` [rad/s^2] (N, n) of a motion (:func:`representative_motion`, a
    trajectory), as ``mj_inverse`` of the file gives it there."""
    dq, ddq = np.asarray(dq, dtype=np.float64), np.asarray(ddq, dtype=np.float64)
    odd = 0.5 * (friction.torques(dq) - friction.torques(-dq))
    err = mujoco_dry_friction(dq, ddq, frictionloss, soft) + np.asarray(damping) * dq - odd
    k = np.argmax(np.abs(err), axis=0)
    cols = np.arange(err.shape[1])
    return DryFrictionError(
        rms=np.sqrt(np.mean(err**2, axis=0)),
        worst=np.abs(err[k, cols]),
        worst_dq=dq[k, cols],
        worst_ddq=ddq[k, cols],
        window_s=0.5 * soft.impedance * soft.timeconst,
    )
