"""Simulated torque measurements of a robot following a joint trajectory.

The robot tracks the trajectory exactly (``q``, ``dq``, ``ddq`` of the
:class:`~dynid.simulation.trajectories.Trajectory` are the true states). The link-side
torque sensors then read

.. math:: \\tau_{meas} = M(q)\\ddot q + c(q, \\dot q) + g(q) + \\tau_f(\\dot q) + e_\\tau

with the ground-truth friction ``tau_f`` (by default the robot's own sigmoid friction,
for the built-in Panda the published values of Gaz et al. 2019) and white Gaussian noise
``e_tau``; the logged positions and velocities carry their own white noise. The sign
convention of ``tau_f`` is that of :mod:`dynid.friction.model`.

Default noise levels (:class:`SensorNoise`) are assumptions of the order reported for
the Panda, not datasheet values: 0.05 N m on each torque sensor, 1e-4 rad on positions
(high-resolution link encoders) and 1e-3 rad/s on velocities (the controller's
differentiated, filtered encoder signal). Timing imperfections are optional:
:func:`sample_times` draws jittered sample times, and ``drop_fraction`` removes random
samples (dropped packets) from the log.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
from numpy.typing import NDArray

from .. import _checks
from ..dynamics.rnea import rnea
from ..exceptions import OptionError, ShapeError
from ..friction.model import FrictionModel, SigmoidFriction
from ..identification.log import TorqueLog, recorded_side_log
from ..model.drive import Drive
from ..model.robot import Robot
from .trajectories import Trajectory
from .unmodelled import UnmodelledEffects

__all__ = ["SensorNoise", "sample_times", "simulate_measurement"]


@dataclass(frozen=True, slots=True)
class SensorNoise:
    """Standard deviations of the white measurement noise (per joint or one for all).

    Attributes
    ----------
    tau_std : float or tuple of float
        Joint torque sensors [N m].
    q_std : float or tuple of float
        Joint positions [rad].
    dq_std : float or tuple of float
        Joint velocities [rad/s].
    """

    tau_std: float | tuple[float, ...] = 0.05
    q_std: float | tuple[float, ...] = 1e-4
    dq_std: float | tuple[float, ...] = 1e-3

    @classmethod
    def none(cls) -> SensorNoise:
        """No noise at all."""
        return cls(0.0, 0.0, 0.0)


def sample_times(
    duration: float,
    fs: float = 1000.0,
    *,
    jitter_std: float = 0.0,
    rng: np.random.Generator | None = None,
) -> NDArray[np.float64]:
    """Sample times of a log at nominal rate ``fs`` with optional Gaussian jitter.

    ``t_k = k / fs + e_k`` for ``k = 0 .. round(duration fs)``, ``e_k ~ N(0, jitter_std^2)``
    clipped to ``+-0.4 / fs`` so that the times stay strictly increasing; ``e_0 = 0``.

    Parameters
    ----------
    duration : float
        [s], positive.
    fs : float
        Nominal sample rate [Hz].
    jitter_std : float
        Standard deviation of the timing error [s].
    rng : numpy.random.Generator
        Required when ``jitter_std > 0``.

    Returns
    -------
    t : ndarray, shape (N,)
        [s].
    """
    if not (duration > 0 and fs > 0):
        raise OptionError(f"duration and fs must be positive; got {duration} s and {fs} Hz")
    t = np.arange(int(round(duration * fs)) + 1) / float(fs)
    if jitter_std > 0:
        if rng is None:
            raise OptionError("rng is required when jitter_std > 0")
        e = np.clip(rng.normal(0.0, jitter_std, t.shape), -0.4 / fs, 0.4 / fs)
        e[0] = 0.0
        t = t + e
    return t


def _std(name: str, v: float | tuple[float, ...], n: int) -> NDArray[np.float64]:
    a = _checks.as_array(name, v)
    if a.ndim == 0:
        a = np.full(n, float(a))
    elif a.shape != (n,):
        raise ShapeError(f"{name} must be a number or have shape ({n},); got {a.shape}")
    if np.any(a < 0):
        raise OptionError(f"{name} must be >= 0; got {a}")
    return a


def simulate_measurement(
    robot: Robot,
    traj: Trajectory,
    *,
    rng: np.random.Generator,
    noise: SensorNoise = SensorNoise(),
    friction: FrictionModel | None | str = "robot",
    drop_fraction: float = 0.0,
    with_ddq: bool = False,
    effects: UnmodelledEffects | None = None,
    drive: Drive | None = None,
) -> TorqueLog:
    """Simulated torque log of ``robot`` following ``traj``.

    Parameters
    ----------
    robot : Robot
        Kinematics, standard parameters ``phi`` (the ground truth) and gravity.
    traj : Trajectory
        True joint states at the sample times (uniform or jittered, see
        :func:`sample_times`).
    rng : numpy.random.Generator
        Source of all noise and dropped samples.
    noise : SensorNoise
        Measurement noise levels.
    friction : FrictionModel, None or "robot"
        Ground-truth friction: a model, None for no friction, or ``"robot"`` (default)
        for the robot's sigmoid parameters ``robot.friction`` (none if it has none).
    drop_fraction : float
        Fraction of samples removed at random (never the first or last), in [0, 0.5).
    with_ddq : bool
        Store the true (noise-free) accelerations in the log (for tests of the
        identification without differentiation).
    effects : UnmodelledEffects, optional
        Rotor inertia, torque offsets and a gravity tilt added to the torques
        (:mod:`dynid.simulation.unmodelled`); None: a rigid body.
    drive : Drive, optional
        A drive train (:mod:`dynid.model.drive`): its known rotor inertias add
        ``K^T diag(I_a) K ddq`` to the joint torques (none when they are to be identified),
        and the log is written on the drive's side with its effort (motor positions and
        torques or currents, encoder offsets); the noise is added at the joints.

    Returns
    -------
    TorqueLog
        Measured ``t``, ``q``, ``dq``, ``tau`` [s, rad, rad/s, N m].

    Raises
    ------
    ShapeError
        ``traj.n != robot.n``, a friction model for another number of joints.
    OptionError
        Negative noise, ``drop_fraction`` outside [0, 0.5), an unknown ``friction`` name.
    """
    n = robot.n
    if traj.n != n:
        raise ShapeError(f"trajectory has {traj.n} joints; robot {robot.name!r} has {n}")
    if not 0.0 <= drop_fraction < 0.5:
        raise OptionError(f"drop_fraction must be in [0, 0.5); got {drop_fraction}")
    if isinstance(friction, str):
        if friction != "robot":
            raise OptionError(
                f"friction must be a friction model, None or 'robot'; got {friction!r}"
            )
        friction = None if robot.friction is None else SigmoidFriction.from_array(robot.friction)
    if friction is not None and friction.n != n:
        raise ShapeError(f"friction model has {friction.n} joints; robot has {n}")
    if effects is not None:
        effects.check(robot)
        tau = rnea(effects.true_robot(robot), traj.q, traj.dq, traj.ddq) + effects.torques(traj.ddq)
    else:
        tau = rnea(robot, traj.q, traj.dq, traj.ddq)
    if friction is not None:
        tau = tau + friction.torques(traj.dq)
    if drive is not None:
        drive.check(n)
        if drive.rotor_inertia is not None:
            tau = tau + drive.rotor_torques(traj.ddq, drive.rotor_inertia)
    N = len(traj)
    sd_tau = _std("noise.tau_std", noise.tau_std, n)
    sd_q = _std("noise.q_std", noise.q_std, n)
    sd_dq = _std("noise.dq_std", noise.dq_std, n)
    tau = tau + rng.standard_normal((N, n)) * sd_tau
    q = traj.q + rng.standard_normal((N, n)) * sd_q
    dq = traj.dq + rng.standard_normal((N, n)) * sd_dq
    rows = np.arange(N)
    if drop_fraction > 0 and N > 2:
        k = int(round(drop_fraction * (N - 2)))
        drop = rng.choice(np.arange(1, N - 1), size=k, replace=False)
        rows = np.setdiff1d(rows, drop)
    log = TorqueLog(
        t=traj.t[rows],
        q=q[rows],
        dq=dq[rows],
        tau=tau[rows],
        ddq=traj.ddq[rows] if with_ddq else None,
    )
    return log if drive is None else recorded_side_log(log, drive)
