"""Simulate a torque log: the entry point of ``dynid simulate``, with every policy the
command applies, so that the Python API behaves as the command does.

* The trajectory: the paper's velocity sinusoids (Gaz et al. 2019, eq. 31; Table I's
  amplitudes and periods for 7 joints, given ones otherwise), a seeded random Fourier series
  (Swevers et al. 1997), or a trajectory file of ``dynid excite`` (``.csv`` at its own
  times, ``.json`` sampled at the rate).
* The limits are checked over the whole trajectory, a block of samples at a time; one that
  exceeds them is scaled in amplitude or in time, or kept (``scale``), and the result says
  so (:attr:`SimulatedLog.notes`).
* The friction: the robot's own, none, a friction file, or a friction model.
* The effects outside the rigid-body model come from their own seed (``arm_seed``), so
  that recordings of several seeds are of one arm.
* The log is a :class:`~dynid.simulation.measurement.MeasuredBlocks`: computed again a
  block at a time whenever it is read, never held whole; :mod:`dynid.io.torque_log` writes it.
"""

from __future__ import annotations

from collections.abc import Callable, Iterator
from dataclasses import dataclass
from pathlib import Path
from typing import Literal

import numpy as np

from ..exceptions import OptionError
from ..friction.model import FrictionModel, own_at_motors_note
from ..io.excitation import inadmissible_note, load_exciting_trajectory, load_trajectory
from ..io.friction_json import load_friction_json
from ..model.drive import Drive
from ..model.robot import Robot, checked_robot
from ..simulation.contact import Contact
from ..simulation.limits import check_limits_blocks, limit_scaling
from ..simulation.measurement import (
    BLOCK_SAMPLES,
    MeasuredBlocks,
    SensorNoise,
    measured_blocks,
    sample_times,
)
from ..simulation.trajectories import (
    GAZ2019_SINUSOID_AMPLITUDES,
    GAZ2019_SINUSOID_PERIODS,
    Trajectory,
    centered_start,
    random_fourier,
    sinusoid_trajectory,
    uniform_times,
)
from .options import check_choice, check_count, check_number, checked_options, only_with

__all__ = ["SimulateOptions", "SimulatedLog", "simulate_log"]

_Slice = Callable[[slice], Trajectory]


@dataclass(frozen=True, slots=True)
class SimulateOptions:
    """How :func:`simulate_log` simulates a log.

    Attributes
    ----------
    trajectory : "sinusoid", "fourier", str or Path
        The paper's sinusoids, a random Fourier series, or a ``trajectory.csv``/``.json``.
    duration_s, rate_hz : float
        Length [s] and sample rate [Hz] (a ``.csv`` trajectory keeps its own times).
    noise, q_noise, dq_noise : float
        Standard deviations of the torque [N m], position [rad] and velocity [rad/s] noise.
    jitter_s : float
        Standard deviation of the timestamps' jitter [s].
    drop_fraction : float
        Fraction of samples dropped at random, in [0, 0.5).
    friction : "robot", "none", str, Path or FrictionModel
        The ground-truth friction: the robot's own, none, a ``friction.json`` or a model.
    scale : {"amplitude", "time", "none"}
        How a trajectory outside the limits is brought into them (``none``: kept).
    amplitudes, periods : sequence of float, optional
        Sinusoids: ``A_i`` [rad/s] and ``T_i`` [s], one per joint (default: Table I, for
        7 joints).
    q0 : sequence of float, optional
        Start (sinusoid) or offset (fourier) [rad], one per joint.
    harmonics : int
        Fourier harmonics L.
    base_freq_hz : float
        Fourier base frequency [Hz].
    with_ddq : bool
        Also give the true accelerations.
    unmodelled : bool
        Add effects outside the rigid-body model (rotor inertia, torque offsets, a tilt).
    arm_seed : int, optional
        ``unmodelled``: the seed of those effects (default 0).
    contacts : tuple of Contact
        External wrenches over time windows (the true external torques go beside the log).
    drive : Drive, optional
        The drive train: the log is written on its side.
    seed : int
        Seed of the Fourier series, the noise, the jitter and the dropped samples.

    Raises
    ------
    OptionError
        A value out of its range, ``arm_seed`` without ``unmodelled``, a friction that is
        none of the above (``field`` names it).
    """

    trajectory: Literal["sinusoid", "fourier"] | str | Path = "sinusoid"
    duration_s: float = 20.0
    rate_hz: float = 1000.0
    noise: float = 0.05
    q_noise: float = 1e-4
    dq_noise: float = 1e-3
    jitter_s: float = 0.0
    drop_fraction: float = 0.0
    friction: Literal["robot", "none"] | str | Path | FrictionModel = "robot"
    scale: Literal["amplitude", "time", "none"] = "amplitude"
    amplitudes: tuple[float, ...] | None = None
    periods: tuple[float, ...] | None = None
    q0: tuple[float, ...] | None = None
    harmonics: int = 5
    base_freq_hz: float = 0.1
    with_ddq: bool = False
    unmodelled: bool = False
    arm_seed: int | None = None
    contacts: tuple[Contact, ...] = ()
    drive: Drive | None = None
    seed: int = 0

    def __post_init__(self) -> None:
        for name in ("duration_s", "rate_hz", "base_freq_hz"):
            check_number(self, name, optional=False)
        for name in ("noise", "q_noise", "dq_noise", "jitter_s"):
            check_number(self, name, low_open=False, optional=False)
        check_number(self, "drop_fraction", low_open=False, high=0.5, high_open=True)
        check_count(self, "harmonics", optional=False)
        check_count(self, "seed", low=0, optional=False)
        check_count(self, "arm_seed", low=0)
        check_choice(self, "scale", ("amplitude", "time", "none"), optional=False)
        only_with(self, ("arm_seed",), "unmodelled")
        fr = self.friction
        if not isinstance(fr, str | Path) and not hasattr(fr, "torques"):
            raise OptionError(
                "must be 'robot', 'none', a friction file or a friction model; got "
                f"{type(fr).__name__}",
                field="friction",
            )


@dataclass(frozen=True, slots=True, eq=False)
class SimulatedLog:
    """Result of :func:`simulate_log`.

    Attributes
    ----------
    log : MeasuredBlocks
        The measured log, computed a block at a time whenever it is read
        (:func:`dynid.io.torque_log.save_torque_log_pieces` writes it).
    notes : tuple of str
        What was done to get it: the limits exceeded and the scaling, the drive, the
        effects outside the model, the contacts.
    start_s, end_s : float
        The first and last sample times [s].
    """

    log: MeasuredBlocks
    notes: tuple[str, ...]
    start_s: float
    end_s: float

    def describe(self, options: SimulateOptions) -> str:
        """One line: samples, duration, joints, torque noise and seed."""
        return (
            f"{self.log.n_samples} samples, {self.end_s - self.start_s:.2f} s, {self.log.n} "
            f"joints, torque noise {options.noise:g} N m, seed {options.seed}"
        )


def simulate_log(robot: Robot, options: SimulateOptions | None = None) -> SimulatedLog:
    """A torque log of ``robot`` following a trajectory, measured with noise.

    Parameters
    ----------
    robot : Robot
    options : SimulateOptions, optional

    Returns
    -------
    SimulatedLog

    Raises
    ------
    OptionError
        The default sinusoids for a robot without 7 joints (give ``amplitudes`` and
        ``periods``), ``amplitudes``/``periods``/``q0`` of another joint count (``field``
        names it).
    UnknownNameError
        A contact at a frame the robot lacks.
    OptionError
        A contact whose window lies outside the log (``field`` ``contacts``).
    DataError
        An unreadable trajectory or friction file.
    """
    checked_robot(robot)
    opt = checked_options(options, SimulateOptions)
    for c in opt.contacts:
        robot.frame(c.frame)  # an unknown frame: UnknownNameError naming the robot's frames
    rng = np.random.default_rng(opt.seed)
    t = sample_times(opt.duration_s, opt.rate_hz, jitter_std=opt.jitter_s, rng=rng)
    notes: list[str] = []
    traj_at, N = _trajectory(opt, robot, t, rng, notes)
    traj_at = _in_limits(opt, robot, traj_at, N, notes)
    first, last = traj_at(slice(0, 1)).t[0], traj_at(slice(N - 1, N)).t[0]
    for c in opt.contacts:
        if c.end <= first or c.start >= last:
            raise OptionError(
                f"{c.frame}: the window {c.start:g} to {c.end:g} s lies outside the log "
                f"({first:g} to {last:g} s)",
                field="contacts",
            )
    if opt.drive is not None:
        notes.append(
            f"drive: {_drive_line(opt, robot)}; the log is written on the {opt.drive.side} side"
        )
        if opt.friction == "robot" and (said := own_at_motors_note(robot, opt.drive)):
            notes.append(said)
    if robot.spring is not None and np.any(robot.spring.k):
        on = np.flatnonzero(robot.spring.k)
        notes.append(
            "joint springs in the torques, k (q - q0): "
            + ", ".join(
                f"{robot.joint_names[j]} {robot.spring.k[j]:.4g} N m/rad about "
                f"{robot.spring.q0[j]:+.4g} rad"
                for j in on
            )
        )
    effects = None
    if opt.unmodelled:
        from ..simulation.unmodelled import UnmodelledEffects

        arm = 0 if opt.arm_seed is None else opt.arm_seed
        effects = UnmodelledEffects.typical(robot.n, np.random.default_rng([arm, 7]))
        notes.append(f"effects outside the rigid-body model: {effects.describe()}")
    log = measured_blocks(
        robot,
        traj_at,
        N,
        rng=rng,
        noise=SensorNoise(tau_std=opt.noise, q_std=opt.q_noise, dq_std=opt.dq_noise),
        friction=_friction(opt.friction),
        drop_fraction=opt.drop_fraction,
        with_ddq=opt.with_ddq,
        effects=effects,
        drive=opt.drive,
        contacts=opt.contacts,
    )
    notes += [
        f"contact at {c.frame}: wrench {list(c.wrench)} from {c.start:g} s to {c.end:g} s "
        f"(true external torques in columns tau_ext1..tau_ext{robot.n})"
        for c in opt.contacts
    ]
    return SimulatedLog(log, tuple(notes), float(first), float(last))


def _drive_line(opt: SimulateOptions, robot: Robot) -> str:
    """The drive's line (:meth:`~dynid.model.drive.Drive.describe`) with where the
    simulated friction acts in place of the drive's default place for a law: none
    simulated, or a description's own at the joints where the drive file does not put it
    at the motors (:func:`~dynid.friction.model.own_at_motors_note`)."""
    assert opt.drive is not None
    line = opt.drive.describe()
    place = f"friction at the {opt.drive.friction_place}s"
    own = opt.friction == "robot"
    if opt.friction == "none" or (own and robot.friction is None):
        return line.replace(place, "no friction simulated")
    if own and opt.drive.friction_at is None:
        return line.replace(place, f"the robot's own friction at the joints ({robot.name})")
    return line


def _friction(friction: str | Path | FrictionModel) -> FrictionModel | str | None:
    """The ground-truth friction: ``"robot"``, None, or a friction model."""
    if isinstance(friction, str) and friction in ("robot", "none"):
        return None if friction == "none" else "robot"
    if isinstance(friction, str | Path):
        loaded = load_friction_json(friction)
        if not isinstance(loaded, FrictionModel):  # a sum: no one law to put on the robot
            raise OptionError(
                f"{Path(friction).name} holds {loaded.kind} friction (at the motors and at "
                "the joints); simulate takes one law: give a friction.json of one law "
                "(`dynid friction --friction-model classical`)",
                field="friction",
            )
        return loaded
    return friction


def _per_joint(opt: SimulateOptions, name: str, n: int) -> np.ndarray | None:
    """``opt.name`` as an (n,) array of finite numbers, or None."""
    v = getattr(opt, name)
    if v is None:
        return None
    a = np.asarray(v, dtype=np.float64).reshape(-1)
    if a.shape != (n,) or not np.all(np.isfinite(a)):
        raise OptionError(
            f"must be {n} finite numbers (one per joint); got {a.size}: {a.tolist()}",
            field=name,
        )
    return a


def _trajectory(
    opt: SimulateOptions,
    robot: Robot,
    t: np.ndarray,
    rng: np.random.Generator,
    notes: list[str],
) -> tuple[_Slice, int]:
    """The true trajectory, a slice of the sample times ``t`` at a time (a file's
    trajectory is held; the sinusoids and the Fourier series are evaluated per slice),
    and its number of samples; ``notes`` say what was found in a trajectory file (a
    ``trajectory.json`` that excite found inadmissible, a ``trajectory.csv`` whose own
    rate is not ``rate_hz``)."""
    n = robot.n
    q0 = _per_joint(opt, "q0", n)
    if opt.trajectory not in ("sinusoid", "fourier"):
        path = Path(opt.trajectory)
        if path.suffix.lower() == ".json":  # the series, evaluated a block at a time
            exciting = load_exciting_trajectory(path, n)
            notes += [x] if (x := inadmissible_note(path)) is not None else []
            t_file = uniform_times(exciting.total_duration, opt.rate_hz)
            return lambda b: exciting(t_file[b]), t_file.size
        traj = _at_rate(load_trajectory(path, n, fs=opt.rate_hz), opt.rate_hz, path.name, notes)
        return lambda b: Trajectory(traj.t[b], traj.q[b], traj.dq[b], traj.ddq[b]), len(traj)
    if opt.trajectory == "fourier":
        series = random_fourier(
            robot, rng, n_harmonics=opt.harmonics, w_f=2 * np.pi * opt.base_freq_hz, q0=q0
        )
        return lambda b: series(t[b]), t.size
    A, T = _per_joint(opt, "amplitudes", n), _per_joint(opt, "periods", n)
    if n != len(GAZ2019_SINUSOID_AMPLITUDES) and (A is None or T is None):
        if A is None and T is None:
            field, said, others = "amplitudes", "and {periods} are needed", ("periods",)
        else:  # the one given needs the other
            field, given = ("periods", "amplitudes") if T is None else ("amplitudes", "periods")
            said, others = f"is needed beside {{{given}}}", (given,)
        raise OptionError(
            f"{said}: the default sinusoids are for 7 joints; robot {robot.name!r} has {n}",
            field=field,
            others=others,
        )
    amp = np.asarray(GAZ2019_SINUSOID_AMPLITUDES if A is None else A, dtype=np.float64)
    per = np.asarray(GAZ2019_SINUSOID_PERIODS if T is None else T, dtype=np.float64)
    start = centered_start(robot, amp, per) if q0 is None else q0
    return lambda b: sinusoid_trajectory(t[b], start, amp, per), t.size


def _at_rate(traj: Trajectory, rate_hz: float, name: str, notes: list[str]) -> Trajectory:
    """A ``trajectory.csv`` at ``rate_hz``: every k-th row when its own rate is k times
    ``rate_hz`` (k >= 2 a whole number); else as it is, a note saying so when its rate
    differs (``--rate 500`` wrote a 1 kHz log without a word)."""
    own = 1.0 / float(np.median(np.diff(traj.t))) if len(traj) > 1 else rate_hz
    k = own / rate_hz
    if abs(k - 1.0) <= 0.01:
        return traj
    if k >= 2.0 - 0.01 and abs(k - round(k)) <= 0.01 * k:
        s = slice(None, None, int(round(k)))
        notes.append(f"{name}: one row in {int(round(k))} of its {own:.6g} Hz, for {rate_hz:g} Hz")
        return Trajectory(traj.t[s], traj.q[s], traj.dq[s], traj.ddq[s])
    notes.append(
        f"{name}: its own sample times kept ({own:.6g} Hz; {rate_hz:g} Hz is not a whole "
        "fraction of it): the rate applies to sinusoid, fourier and a trajectory.json"
    )
    return traj


def _in_limits(
    opt: SimulateOptions, robot: Robot, traj_at: _Slice, N: int, notes: list[str]
) -> _Slice:
    """The trajectory checked against the limits (a pass over its blocks) and, unless
    ``scale`` is ``"none"``, scaled into them (one more pass); ``notes`` say so."""

    def blocks(at: _Slice) -> Iterator[Trajectory]:
        return (at(slice(a, a + BLOCK_SAMPLES)) for a in range(0, N, BLOCK_SAMPLES))

    report = check_limits_blocks(robot, blocks(traj_at))
    if report.ok:
        return traj_at
    what = opt.trajectory if isinstance(opt.trajectory, str) else Path(opt.trajectory).name
    notes.append(f"limits exceeded by the {what} trajectory:\n{report}")
    if opt.scale == "none":
        return traj_at
    scaling = limit_scaling(robot, lambda: blocks(traj_at), method=opt.scale)
    scaled: _Slice = lambda b: scaling.apply(traj_at(b))  # noqa: E731
    how = "amplitude scaled by" if opt.scale == "amplitude" else "time stretched by"
    notes.append(f"{how} {scaling.factor:.4f}; now: {check_limits_blocks(robot, blocks(scaled))}")
    return scaled
