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

from collections.abc import Callable, Iterator
from dataclasses import dataclass

import numpy as np
from numpy.typing import NDArray

from .. import _checks
from ..dynamics.rnea import rnea
from ..exceptions import OptionError, ShapeError
from ..friction.model import FrictionModel, FrictionSum, placed_friction, robot_friction
from ..identification.log import TorqueLog, recorded_side_log
from ..model.drive import Drive
from ..model.robot import Robot, checked_robot
from .contact import Contact, contact_torques
from .trajectories import TRAJECTORY_EXPECTED, Trajectory, uniform_times
from .unmodelled import UnmodelledEffects

__all__ = [
    "BLOCK_SAMPLES",
    "MeasuredBlocks",
    "SensorNoise",
    "measured_blocks",
    "sample_times",
    "simulate_measurement",
]


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

    Raises
    ------
    OptionError
        ``duration`` or ``fs`` not positive, more samples than
        :data:`~dynid.simulation.trajectories.MAX_SAMPLES`, jitter without ``rng``.
    """
    t = uniform_times(duration, fs)
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
    contacts: tuple[Contact, ...] = (),
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
        for the robot's own friction (:func:`~dynid.friction.model.robot_friction`; none if
        it has none). With a ``drive`` whose friction acts at the motors, a law at the
        joints acts per motor (``K^T f(K dq)``), as identification models it; a model with
        its own drive acts as it says.
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
    contacts : tuple of Contact
        External wrenches (:mod:`dynid.simulation.contact`): the arm still follows
        ``traj``, so the torques lose ``tau_ext = J^T w`` over each contact's window.

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
    _checks.checked_rng(rng)
    checked_robot(robot)
    traj = _checks.of_type("traj", traj, Trajectory, TRAJECTORY_EXPECTED)
    n = robot.n
    if traj.n != n:
        raise ShapeError(f"trajectory has {traj.n} joints; robot {robot.name!r} has {n}")
    placed = _checked(robot, drop_fraction, friction, effects, drive)
    tau = _true_torques(robot, traj, placed, effects, drive, contacts)
    N = len(traj)
    sd_tau, sd_q, sd_dq = _stds(noise, n)
    tau = tau + rng.standard_normal((N, n)) * sd_tau
    q = traj.q + rng.standard_normal((N, n)) * sd_q
    dq = traj.dq + rng.standard_normal((N, n)) * sd_dq
    rows = np.flatnonzero(_kept_rows(N, drop_fraction, rng))
    log = TorqueLog(
        t=traj.t[rows],
        q=q[rows],
        dq=dq[rows],
        tau=tau[rows],
        ddq=traj.ddq[rows] if with_ddq else None,
    )
    return log if drive is None else recorded_side_log(log, drive)


def _checked(
    robot: Robot,
    drop_fraction: float,
    friction: FrictionModel | None | str,
    effects: UnmodelledEffects | None,
    drive: Drive | None,
) -> FrictionModel | FrictionSum | None:
    """Check the options of a simulation; the friction model (``"robot"`` resolved)."""
    n = robot.n
    if not 0.0 <= drop_fraction < 0.5:
        raise OptionError(f"drop_fraction must be in [0, 0.5); got {drop_fraction}")
    if isinstance(friction, str) and friction != "robot":
        raise OptionError(f"friction must be a friction model, None or 'robot'; got {friction!r}")
    if friction is not None and not isinstance(friction, str) and friction.n != n:
        raise ShapeError(f"friction model has {friction.n} joints; robot has {n}")
    if effects is not None:
        effects.check(robot)
    if drive is not None:
        drive.check(n)
    # the robot's own (a description's): the joints' unless the drive file says motor; a
    # ground truth given: where the drive puts a given friction (placed_friction)
    if isinstance(friction, str):
        return robot_friction(robot, drive)
    return placed_friction(friction, drive)


def _true_torques(
    robot: Robot,
    traj: Trajectory,
    friction: FrictionModel | FrictionSum | None,
    effects: UnmodelledEffects | None,
    drive: Drive | None,
    contacts: tuple[Contact, ...] = (),
) -> NDArray[np.float64]:
    """Joint torques (N, n) [N m] of the robot following ``traj``, before the noise."""
    if effects is not None:
        tau = rnea(effects.true_robot(robot), traj.q, traj.dq, traj.ddq) + effects.torques(traj.ddq)
    else:
        tau = rnea(robot, traj.q, traj.dq, traj.ddq)
    if robot.spring is not None:  # the motors hold the joint springs too
        tau = tau + robot.spring.torques(traj.q)
    if friction is not None:  # placed where the drive puts it (_checked)
        tau = tau + friction.torques(traj.dq)
    if drive is not None and drive.rotor_inertia is not None:
        tau = tau + drive.rotor_torques(traj.ddq, drive.rotor_inertia)
    if contacts:
        tau = tau - contact_torques(robot, contacts, traj.t, traj.q)
    return tau


def _stds(noise: SensorNoise, n: int) -> tuple[NDArray[np.float64], ...]:
    """The noise levels (n,) of the torques, positions and velocities."""
    return (
        _std("noise.tau_std", noise.tau_std, n),
        _std("noise.q_std", noise.q_std, n),
        _std("noise.dq_std", noise.dq_std, n),
    )


def _kept_rows(N: int, drop_fraction: float, rng: np.random.Generator) -> NDArray[np.bool_]:
    """The samples (N,) kept after dropping ``drop_fraction`` at random (never the first
    or last)."""
    keep = np.ones(N, dtype=bool)
    if drop_fraction > 0 and N > 2:
        k = int(round(drop_fraction * (N - 2)))
        keep[rng.choice(np.arange(1, N - 1), size=k, replace=False)] = False
    return keep


#: Samples simulated at a time by :func:`measured_blocks` (about 7 MB per array of 7 joints).
BLOCK_SAMPLES = 1 << 17


@dataclass(frozen=True, slots=True, eq=False)
class MeasuredBlocks:
    """A simulated log in consecutive pieces, computed again at every call (never whole).

    Calling it yields the :class:`TorqueLog` pieces that :func:`simulate_measurement`
    would return joined: the same noise (each signal's generator restarted where its
    whole-array draw starts) and the same dropped samples.

    Attributes
    ----------
    n : int
        Joints.
    n_samples : int
        Samples over all pieces (after dropping).
    with_ddq : bool
        Whether the pieces hold the true accelerations.
    external : callable or None
        With contacts: ``external()`` yields, piece by piece, the true external joint
        torques ``tau_ext`` (rows of the pieces, joint side) [N m]; else None.
    """

    n: int
    n_samples: int
    with_ddq: bool
    pieces: Callable[[], Iterator[TorqueLog]]
    external: Callable[[], Iterator[NDArray[np.float64]]] | None = None

    def __call__(self) -> Iterator[TorqueLog]:
        return self.pieces()


def measured_blocks(
    robot: Robot,
    traj_at: Callable[[slice], Trajectory],
    N: int,
    *,
    rng: np.random.Generator,
    noise: SensorNoise = SensorNoise(),
    friction: FrictionModel | None | str = "robot",
    drop_fraction: float = 0.0,
    with_ddq: bool = False,
    effects: UnmodelledEffects | None = None,
    drive: Drive | None = None,
    block: int = BLOCK_SAMPLES,
    contacts: tuple[Contact, ...] = (),
) -> MeasuredBlocks:
    """:func:`simulate_measurement` of a long trajectory, a block of samples at a time.

    Parameters
    ----------
    traj_at : callable
        ``traj_at(slice)`` gives samples ``slice`` of the true trajectory (``N`` samples
        in all); called once per block and pass.
    N : int
        Samples of the trajectory.
    block : int
        Samples per piece.
    rng, noise, friction, drop_fraction, with_ddq, effects, drive, contacts
        As :func:`simulate_measurement`; ``rng`` is advanced as that function advances it.

    Returns
    -------
    MeasuredBlocks

    Raises
    ------
    ShapeError, OptionError
        As :func:`simulate_measurement`.
    """
    n = robot.n
    fr = _checked(robot, drop_fraction, friction, effects, drive)
    sds = _stds(noise, n)
    states = []
    for _ in sds:  # where each signal's draw starts; rng ends where the whole draws end
        states.append(rng.bit_generator.state)
        for a in range(0, N, block):
            rng.standard_normal((min(block, N - a), n))
    keep = _kept_rows(N, drop_fraction, rng)

    def pieces() -> Iterator[TorqueLog]:
        gens = []
        for st in states:
            bg = type(rng.bit_generator)()
            bg.state = st
            gens.append(np.random.Generator(bg))
        for a in range(0, N, block):
            traj = traj_at(slice(a, a + block))
            if traj.n != n:
                raise ShapeError(f"trajectory has {traj.n} joints; robot {robot.name!r} has {n}")
            m = len(traj)
            tau = _true_torques(robot, traj, fr, effects, drive, contacts)
            tau = tau + gens[0].standard_normal((m, n)) * sds[0]
            q = traj.q + gens[1].standard_normal((m, n)) * sds[1]
            dq = traj.dq + gens[2].standard_normal((m, n)) * sds[2]
            rows = np.flatnonzero(keep[a : a + m])
            log = TorqueLog(
                t=traj.t[rows],
                q=q[rows],
                dq=dq[rows],
                tau=tau[rows],
                ddq=traj.ddq[rows] if with_ddq else None,
            )
            yield log if drive is None else recorded_side_log(log, drive)

    def external() -> Iterator[NDArray[np.float64]]:
        for a in range(0, N, block):
            traj = traj_at(slice(a, a + block))
            rows = np.flatnonzero(keep[a : a + len(traj)])
            yield contact_torques(robot, contacts, traj.t[rows], traj.q[rows])

    return MeasuredBlocks(n, int(keep.sum()), with_ddq, pieces, external if contacts else None)
