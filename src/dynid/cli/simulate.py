"""Simulate a torque log: the robot follows a trajectory, torque sensors read with noise.

Trajectories:
  sinusoid  velocity-mode sinusoids dq_i = A_i sin(2 pi t / T_i) (Gaz et al. 2019, eq. 31;
            default A, T of their Table I for 7 joints), started so that each sweep is
            centred in its joint range
  fourier   a seeded random finite Fourier series (Swevers et al. 1997) inside the limits
  FILE      a trajectory.csv (t, q, dq, ddq; its own sample times) or trajectory.json
            (coefficients, sampled at --rate over its whole length) written by `dynid excite`

The measured torques are M ddq + c + g + friction(dq) + noise, with the robot's own
friction (the published sigmoid for the built-in Panda), or any law of a friction.json
(--friction FILE, as `dynid friction` writes it), unless --no-friction. With --drive
the drive's known rotor inertias are added and the log is written on its side (motor
positions and torques, or currents) with its encoder offsets. --contact
FRAME:WRENCH:START,END pushes with a wrench (fx,fy,fz [N] and optionally mx,my,mz [N m],
base axes) at a frame's origin (a link, flange) over a window [s] (repeatable;
--contact-ramp rounds the edges): the arm still follows the trajectory, so its torques
lose tau_ext = J^T w, and the true external joint torques are written beside the log as
columns tau_ext1..n (every reader of the log ignores them; `dynid observe` plots them).
Limits are
checked; by default a trajectory that exceeds them is scaled down in amplitude
(--scale amplitude), or slowed down (--scale time), or kept (--scale none).

Example:
  dynid simulate --robot panda --trajectory sinusoid --duration 20 --seed 1 --out traj.csv
  dynid simulate --robot panda --duration 10 --contact link5:0,0,-20:4,4.5 --out hit.csv
"""

from __future__ import annotations

import argparse
import logging
from collections.abc import Callable, Iterator
from pathlib import Path
from typing import Any

import numpy as np

from ..exceptions import DynidError, OptionError
from ..friction.model import FrictionModel
from ..io.friction_json import load_friction_json
from ..io.torque_log import save_torque_log_pieces
from ..model.robot import Robot
from ..simulation.contact import Contact
from ..simulation.measurement import BLOCK_SAMPLES, SensorNoise, measured_blocks, sample_times
from ..simulation.trajectories import (
    GAZ2019_SINUSOID_AMPLITUDES,
    GAZ2019_SINUSOID_PERIODS,
    Trajectory,
    centered_start,
    check_limits_blocks,
    limit_scaling,
    random_fourier,
    sinusoid_trajectory,
)
from .common import (
    add_drive_option,
    add_robot_options,
    add_seed_option,
    add_subcommand,
    count_type,
    load_drive_arg,
    load_robot,
    nonnegative_type,
    number,
    output_path,
    parse_vector,
    positive_type,
)
from .console import Console

NAME = "simulate"
#: ``--out`` is the one file written (:mod:`dynid.outputs.run_output`).
OUTPUT = "file"
log = logging.getLogger(__name__)


def register(subparsers: argparse._SubParsersAction) -> argparse.ArgumentParser:
    """Add the ``simulate`` subcommand."""
    p = add_subcommand(
        subparsers,
        NAME,
        __doc__,
        help="simulate a torque log of a trajectory (sinusoids or Fourier series)",
    )
    add_robot_options(p)
    add_drive_option(p)
    p.add_argument(
        "--trajectory",
        default="sinusoid",
        metavar="{sinusoid,fourier,FILE}",
        help="sinusoid (default), fourier, or a trajectory .csv/.json from dynid excite",
    )
    p.add_argument("--duration", type=positive_type, default=20.0, help="seconds (default 20)")
    p.add_argument(
        "--rate", type=positive_type, default=1000.0, help="sample rate [Hz] (default 1000)"
    )
    p.add_argument(
        "--noise",
        type=nonnegative_type,
        default=0.05,
        help="torque sensor noise std [N m] (default 0.05)",
    )
    p.add_argument(
        "--q-noise", type=nonnegative_type, default=1e-4, help="position noise std [rad]"
    )
    p.add_argument(
        "--dq-noise", type=nonnegative_type, default=1e-3, help="velocity noise std [rad/s]"
    )
    p.add_argument(
        "--jitter", type=nonnegative_type, default=0.0, help="timestamp jitter std [s] (default 0)"
    )
    p.add_argument(
        "--drop",
        type=number(float, min=0, max=0.5, max_open=True),
        default=0.0,
        help="fraction of samples dropped at random (default 0)",
    )
    fr = p.add_mutually_exclusive_group()
    fr.add_argument("--no-friction", action="store_true", help="simulate without joint friction")
    fr.add_argument(
        "--friction",
        type=Path,
        default=None,
        help="friction.json: the ground-truth friction (any law; default the robot's own)",
    )
    p.add_argument(
        "--scale",
        choices=("amplitude", "time", "none"),
        default="amplitude",
        help="how to bring the trajectory into the limits (default amplitude)",
    )
    p.add_argument(
        "--amplitudes",
        default=None,
        help="sinusoid amplitudes A_i [rad/s], comma-separated (default: Table I)",
    )
    p.add_argument(
        "--periods",
        default=None,
        help="sinusoid periods T_i [s], comma-separated (default: Table I)",
    )
    p.add_argument("--q0", default=None, help="start (sinusoid) or offset (fourier) [rad]")
    p.add_argument(
        "--harmonics", type=count_type, default=5, help="Fourier harmonics L (default 5)"
    )
    p.add_argument(
        "--base-freq",
        type=positive_type,
        default=0.1,
        help="Fourier base frequency [Hz] (default 0.1)",
    )
    p.add_argument("--with-ddq", action="store_true", help="also write the true accelerations")
    p.add_argument(
        "--unmodelled",
        action="store_true",
        help="add effects outside the rigid-body model, as real arms have (rotor inertia, "
        "torque-sensor offsets, a 0.3 deg gravity tilt; drawn from --arm-seed and printed)",
    )
    p.add_argument(
        "--arm-seed",
        type=number(int, min=0),
        default=None,
        metavar="N",
        help="--unmodelled: the seed of the arm's effects (default 0), apart from --seed so "
        "that recordings of several --seed are of one arm",
    )
    p.add_argument(
        "--contact",
        action="append",
        default=[],
        metavar="FRAME:WRENCH:START,END",
        help="an external wrench fx,fy,fz[,mx,my,mz] [N, N m] (base axes) at FRAME's origin "
        "from START to END [s], e.g. link5:0,0,-20:4,4.5; repeatable; writes the true "
        "tau_ext1..n beside the log",
    )
    p.add_argument(
        "--contact-ramp",
        type=nonnegative_type,
        default=0.0,
        help="rise and fall time of the contacts [s] (default 0: steps)",
    )
    add_seed_option(p)
    p.add_argument("--out", required=True, type=output_path, help="output .csv or .npz")
    return p


def _contacts(args: argparse.Namespace, robot: Robot) -> tuple[Contact, ...]:
    """The contacts of ``--contact FRAME:WRENCH:START,END`` (frames checked)."""
    out = []
    for text in args.contact:
        parts = text.rsplit(":", 2)
        if len(parts) != 3:
            raise DynidError(f"--contact must read FRAME:WRENCH:START,END; got {text!r}")
        frame, wrench, window = parts
        robot.frame(frame)
        w = parse_vector(wrench, "--contact WRENCH")
        if w.size not in (3, 6):
            raise DynidError(f"--contact WRENCH must be fx,fy,fz or 6 numbers; got {wrench!r}")
        start, end = parse_vector(window, "--contact START,END", 2)
        out.append(Contact(frame, tuple(w), float(start), float(end), args.contact_ramp))
    return tuple(out)


def _friction(args: argparse.Namespace) -> FrictionModel | str:
    """The ground-truth friction: a friction.json's law (--friction), else the robot's."""
    if args.friction is None:
        return "robot"
    return load_friction_json(args.friction)


def _trajectory(
    args: argparse.Namespace, robot: Robot, t: np.ndarray, rng: np.random.Generator
) -> tuple[Callable[[slice], Trajectory], int]:
    """The true trajectory, a slice of the sample times ``t`` at a time (a file's
    trajectory is held; the sinusoids and the Fourier series are evaluated per slice),
    and its number of samples."""
    n = robot.n
    q0 = None if args.q0 is None else parse_vector(args.q0, "--q0", n)
    if args.trajectory not in ("sinusoid", "fourier"):
        from ..io.excitation import load_exciting_trajectory, load_trajectory
        from ..simulation.trajectories import uniform_times

        path = Path(args.trajectory)
        if path.suffix.lower() == ".json":  # the series, evaluated a block at a time
            exciting = load_exciting_trajectory(path, n)
            t_file = uniform_times(exciting.total_duration, args.rate)
            return lambda b: exciting(t_file[b]), t_file.size
        traj = load_trajectory(path, n, fs=args.rate)
        return lambda b: Trajectory(traj.t[b], traj.q[b], traj.dq[b], traj.ddq[b]), len(traj)
    if args.trajectory == "fourier":
        series = random_fourier(
            robot, rng, n_harmonics=args.harmonics, w_f=2 * np.pi * args.base_freq, q0=q0
        )
        return lambda b: series(t[b]), t.size
    if n != len(GAZ2019_SINUSOID_AMPLITUDES) and (args.amplitudes is None or args.periods is None):
        raise DynidError(
            f"the default sinusoids are for 7 joints; robot {robot.name!r} has {n}: "
            "give --amplitudes and --periods"
        )
    A = (
        GAZ2019_SINUSOID_AMPLITUDES
        if args.amplitudes is None
        else parse_vector(args.amplitudes, "--amplitudes", n)
    )
    T = (
        GAZ2019_SINUSOID_PERIODS
        if args.periods is None
        else parse_vector(args.periods, "--periods", n)
    )
    start = centered_start(robot, A, T) if q0 is None else q0
    return lambda b: sinusoid_trajectory(t[b], start, A, T), t.size


def _in_limits(
    args: argparse.Namespace, robot: Robot, traj_at: Callable[[slice], Trajectory], N: int, say: Any
) -> Callable[[slice], Trajectory]:
    """The trajectory checked against the limits (a pass over its blocks) and, unless
    ``--scale none``, scaled into them (one more pass)."""

    def blocks(at: Callable[[slice], Trajectory]) -> Iterator[Trajectory]:
        return (at(slice(a, a + BLOCK_SAMPLES)) for a in range(0, N, BLOCK_SAMPLES))

    report = check_limits_blocks(robot, blocks(traj_at))
    if report.ok or args.scale == "none":
        if not report.ok:
            say(f"limits exceeded by the {args.trajectory} trajectory:\n{report}")
        return traj_at
    say(f"limits exceeded by the {args.trajectory} trajectory:\n{report}")
    scaling = limit_scaling(robot, lambda: blocks(traj_at), method=args.scale)
    scaled = lambda b: scaling.apply(traj_at(b))  # noqa: E731
    what = "amplitude scaled by" if args.scale == "amplitude" else "time stretched by"
    say(f"{what} {scaling.factor:.4f}; now: {check_limits_blocks(robot, blocks(scaled))}")
    return scaled


def run(args: argparse.Namespace, console: Console) -> int:
    """Simulate and write the log, a block of samples at a time; prints the limit report
    and a summary (unless -q)."""
    say = console.print
    robot = load_robot(args)
    n = robot.n
    rng = np.random.default_rng(args.seed)
    t = sample_times(args.duration, args.rate, jitter_std=args.jitter, rng=rng)
    traj_at, N = _trajectory(args, robot, t, rng)
    traj_at = _in_limits(args, robot, traj_at, N, say)
    noise = SensorNoise(tau_std=args.noise, q_std=args.q_noise, dq_std=args.dq_noise)
    drive = load_drive_arg(args, n)
    if drive is not None:
        say(f"drive: {drive.describe()}; the log is written on the {drive.side} side")
    effects = None
    if args.arm_seed is not None and not args.unmodelled:
        raise OptionError("--arm-seed applies to --unmodelled; add it or leave --arm-seed out")
    if args.unmodelled:
        from ..simulation.unmodelled import UnmodelledEffects

        arm = 0 if args.arm_seed is None else args.arm_seed
        effects = UnmodelledEffects.typical(n, np.random.default_rng([arm, 7]))
        say(f"effects outside the rigid-body model: {effects.describe()}")
    contacts = _contacts(args, robot)
    measured = measured_blocks(
        robot,
        traj_at,
        N,
        rng=rng,
        noise=noise,
        friction=None if args.no_friction else _friction(args),
        drop_fraction=args.drop,
        with_ddq=args.with_ddq,
        effects=effects,
        drive=drive,
        contacts=contacts,
    )
    extra = None if measured.external is None else ("tau_ext", measured.external)
    save_torque_log_pieces(
        args.out, measured, n=n, n_rows=measured.n_samples, with_ddq=args.with_ddq, extra=extra
    )
    for c in contacts:
        say(
            f"contact at {c.frame}: wrench {list(c.wrench)} from {c.start:g} s to {c.end:g} s "
            f"(true external torques in columns tau_ext1..tau_ext{n})"
        )
    first, last = traj_at(slice(0, 1)).t[0], traj_at(slice(N - 1, N)).t[0]
    say(
        f"wrote {args.out}: {measured.n_samples} samples, {last - first:.2f} s, "
        f"{n} joints, torque noise {args.noise:g} N m, seed {args.seed}"
    )
    return 0
