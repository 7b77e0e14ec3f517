"""Design an exciting trajectory for the classical identification (Gaz et al. 2019, suppl. II).

A finite Fourier series per joint (--harmonics of --base-frequency) for --duration seconds
between (1 - cos) ramps of 0.5 s that start and end at rest, whose coefficients and start
position minimise the condition number of the classical regressor [Y_b, F] (base
parameters plus viscous, Coulomb and offset friction per joint; unscaled, the figure the
paper reports: 121.88 for theirs) or, with --criterion logdet, maximise log det of its
scaled Gram matrix. It respects, with margins: joint positions (--position-margin, 5 deg),
velocities (--velocity-margin, 10 deg/s), accelerations and the model's torques (10 % of
each limit), and clearances: capsules of --radius around the links keep
--obstacle-clearance from obstacles and --self-clearance between non-adjacent links. By
default these scale with the arm: 0.06, 0.05 and 0.02 m for an arm whose chain (base to
flange, the links' lengths summed) is 1.3 m or longer, such as the Panda (1.32 m), and
that times chain / 1.3 m for a shorter one (an SO-101 of 0.55 m: 0.025, 0.021 and
0.0085 m); the summary says which were used and why. Obstacles: the floor z = 0 of the
base frame by default, or planes and boxes from --obstacles FILE (JSON):

  {"schema": "dynid-obstacles/1",
   "planes": [{"name": "table", "point": [0, 0, 0], "normal": [0, 0, 1]}],
   "boxes": [{"name": "fixture", "center": [0.5, 0, 0.1], "size": [0.2, 0.3, 0.2]}]}

Writes DIR/trajectory.csv (t, q, dq, ddq at 1 kHz, or at --rate HZ, for a position or
velocity controller), DIR/trajectory.json (coefficients, limits, margins, obstacles, condition
numbers, the smallest margin to every limit and obstacle at 1 kHz) and
DIR/excitation.png (joint motion and swept workspace). Seeded; about ten seconds for
the Panda: on a terminal, progress lines tell the iterations (-v logs each one), and the
summary's first line ends with the time the design took.
`dynid simulate --trajectory DIR/trajectory.csv` records a torque log along it.
The result is the best admissible iterate, never worse than an admissible start (the
start itself then, said in a third line, as is a result worse than a start that violated
a limit). Exit status 1 when no admissible trajectory was found, naming the violated
limits: the files are written for inspection (as retrieve's when no feasible set exists).
A violated clearance names the two links (or the link and the obstacle), their distance,
when, and the options that change it.

With --drive FILE.toml (default: the [drive] table of a --robot TOML, as simulate reads it)
the torques checked include the drive's known rotor inertias, reflected through its gears
(K^T diag(I_a) K ddq: k^2 I_a ddq on an uncoupled joint of gear ratio k); a drive that
leaves them to be identified is said to leave them out of the torque margins.

A known load (a gripper, a tool) counts in the torque margins through --robot: the arm
carrying it as a robot TOML, such as robot_with_payload.toml of `dynid payload`, or one
written from known values with Robot.with_tool and toml_from_robot (fk's --tool is a
frame's offset, not a load, and no command takes a load's mass by itself).

--range qJ=LO:HI,... keeps joints within narrower ranges [rad] than their limits (qJ or J
a joint's number from 1, or its name), the position margin kept inside them: an arm whose
joints turn +-2 pi reaches the floor and itself in most of that range, and a motion over
all of it seldom clears them. --max-velocity, --max-acceleration and --max-torque give a
cell's limits tighter than the robot's [rad/s, rad/s^2, N m]: one value for every joint
(--max-velocity 1.0), per joint (dq2=0.8,ddq3=...,tau1=...; J a joint's number from 1 or
its name), or both (1.0,dq2=0.8). Each joint keeps the smaller of its own limit and the one
given, never a larger one (said in one note), with the margins above kept inside it. A URDF
holds no acceleration limits: without --max-acceleration a warning says the accelerations
are then bounded only by the design's own 10 rad/s^2 and the torque limits.
trajectory.json records the drive, the ranges and the limits given (its "limits" are those
kept, "robot_limits" the robot's).

The condition number is that of [Y_b, F] on the trajectory's exact samples, rows
unweighted; identify's on a log of it is of the structure it chooses, on the log's filtered
rows weighted per joint by their noise (wls), which changes the unscaled number most.

status (the first line of the summary, and trajectory.json's "status"):
  ok          the optimised trajectory keeps every limit and clearance when checked at
              1 kHz (or, when nothing admissible was better, the optimiser's admissible
              start is returned: said in a third line)
  reduced     the optimised trajectory violated a torque or clearance limit between the
              samples it was optimised on; its amplitudes were reduced (in 3 % steps about
              its start position) until it kept every limit at 1 kHz: admissible, but less
              exciting than optimised (the condition number is the reduced one's)
  infeasible  no admissible trajectory was found, even with reduced amplitudes: the
              optimiser's trajectory is written, unreduced, for inspection, the violated
              limits named, and the exit status is 1

example:
  dynid excite --robot panda --duration 20 --seed 1 --out excite
"""

from __future__ import annotations

import argparse
import sys
from pathlib import Path
from typing import Any

import numpy as np

from ..exceptions import OptionError
from ..io.excitation import save_excitation_json, save_trajectory_csv
from ..model.robot import Robot
from ..simulation.excitation import ExcitationOptions
from ..workflows.excite import (
    EXCITE_RATE_HZ,
    ExcitationDesign,
    design_excitation,
    loosened_note,
    unlimited_warnings,
)
from .applies import urdf_chain
from .common import (
    add_drive_option,
    add_robot_options,
    add_subcommand,
    flag,
    load_drive_arg,
    load_robot,
    output_path,
    positive_type,
    save_figure,
)
from .console import Console

NAME = "excite"
#: ``--out`` is a folder: its files are one output set (:mod:`dynid.outputs.run_output`).
OUTPUT = "folder"
#: Options that apply to one route only (:mod:`dynid.cli.applies`).
APPLIES = (urdf_chain(),)


def register(subparsers: argparse._SubParsersAction) -> argparse.ArgumentParser:
    """Add the ``excite`` subcommand."""
    p = add_subcommand(
        subparsers,
        NAME,
        __doc__,
        help="optimise an exciting trajectory within limits and obstacles",
    )
    add_robot_options(p)
    add_drive_option(p)
    d = ExcitationOptions()
    p.add_argument("--duration", type=float, default=d.duration, help="Fourier part [s] (20)")
    p.add_argument("--harmonics", type=int, default=d.harmonics, help="harmonics L (5)")
    p.add_argument(
        "--base-frequency",
        type=float,
        default=d.base_frequency,
        metavar="HZ",
        help="w_f / (2 pi) [Hz] (default 0.075, the paper's 0.15 pi rad/s)",
    )
    p.add_argument("--obstacles", type=Path, default=None, help="obstacles JSON (default: floor)")
    p.add_argument(
        "--radius",
        type=float,
        default=None,
        metavar="M",
        help="capsule radius [m] (default scaled to the arm: 0.06 for a chain of 1.3 m or longer)",
    )
    p.add_argument(
        "--self-clearance",
        type=float,
        default=None,
        metavar="M",
        help="distance kept between non-adjacent links' capsules [m] (default scaled to the "
        "arm: 0.02 for a chain of 1.3 m or longer)",
    )
    p.add_argument(
        "--obstacle-clearance",
        type=float,
        default=None,
        metavar="M",
        help="distance kept from obstacles [m] (default scaled to the arm: 0.05 for a chain "
        "of 1.3 m or longer)",
    )
    p.add_argument(
        "--position-margin",
        type=float,
        default=float(np.rad2deg(d.position_margin)),
        metavar="DEG",
        help="distance kept from the position limits [deg] (5)",
    )
    p.add_argument(
        "--velocity-margin",
        type=float,
        default=float(np.rad2deg(d.velocity_margin)),
        metavar="DEG_S",
        help="subtracted from the velocity limits [deg/s] (10)",
    )
    p.add_argument(
        "--range",
        default=None,
        metavar="qJ=LO:HI,...",
        help="narrow joints' ranges for the design [rad], qJ (or J) a joint's number from 1, "
        "or its name (e.g. 'q1=-1.5:1.5,q2=-2.6:-0.5'); default: the robot's limits",
    )
    for option, symbol, unit, what in (
        ("--max-velocity", "dq", "rad/s", "velocity"),
        ("--max-acceleration", "ddq", "rad/s^2", "acceleration"),
        ("--max-torque", "tau", "N m", "torque"),
    ):
        p.add_argument(
            option,
            default=None,
            metavar=f"V|{symbol}J=V,...",
            help=f"the cell's {what} limit [{unit}], tighter than the robot's: one for every "
            f"joint, or per joint ({symbol}J or J a joint's number from 1, or its name; e.g. "
            f"'{symbol}2=0.8,{symbol}3=0.5'); each joint keeps the smaller of its own and the "
            "one given, the margins kept inside it",
        )
    p.add_argument("--criterion", choices=("cond", "logdet"), default=d.criterion)
    p.add_argument("--max-iter", type=int, default=d.max_iter, help="optimiser iterations (60)")
    p.add_argument("--seed", type=int, default=0, help="random seed (default 0)")
    p.add_argument(
        "--rate",
        type=positive_type,
        default=EXCITE_RATE_HZ,
        metavar="HZ",
        help="sample rate of trajectory.csv [Hz] (1000): the rate the controller takes "
        "set points at (a servo bus's goal positions at 50 Hz: --rate 50); the limits are "
        "checked at 1 kHz whatever it is",
    )
    p.add_argument(
        "--no-figures",
        "--no-figure",
        dest="no_figure",
        action="store_true",
        help="do not write excitation.png",
    )
    p.add_argument("--out", type=output_path, required=True, help="output folder")
    return p


def run(args: argparse.Namespace, console: Console) -> int:
    """Optimise, write the trajectory files and the figure; returns the exit code."""
    robot = load_robot(args)
    opts = _options(args, robot)
    for line in unlimited_warnings(robot, opts, flag):
        console.warn(line)
    loosened = loosened_note(robot, opts, flag)
    if loosened is not None:
        console.note(loosened)
    design = design_excitation(
        robot,
        opts,
        obstacles=args.obstacles,
        seed=args.seed,
        drive=load_drive_arg(args, robot.n),
    )
    written = _save(args, robot, design)
    console.print(*design.describe(robot, flag), *(f"wrote {p}" for p in written))
    if not design.admissible:  # a negative result, as retrieve's: exit 1, files kept
        print(f"dynid {NAME}: {design.failure(robot, flag)}", file=sys.stderr)
        return 1
    if not design.result.improved:
        console.note(
            "more --max-iter, another --seed or narrower joint ranges (--range "
            "q1=LO:HI,...) may find a trajectory better than the start"
        )
    return 0


def _options(args: argparse.Namespace, robot: Robot) -> ExcitationOptions:
    """The design's options from the flags (margins given in degrees)."""
    joints = robot.joint_names
    return ExcitationOptions(
        ranges=() if args.range is None else parse_ranges(args.range, joints),
        max_velocity=parse_limits(args.max_velocity, joints, "--max-velocity", "dq"),
        max_acceleration=parse_limits(args.max_acceleration, joints, "--max-acceleration", "ddq"),
        max_torque=parse_limits(args.max_torque, joints, "--max-torque", "tau"),
        duration=args.duration,
        harmonics=args.harmonics,
        base_frequency=args.base_frequency,
        position_margin=float(np.deg2rad(args.position_margin)),
        velocity_margin=float(np.deg2rad(args.velocity_margin)),
        radii=args.radius,
        self_clearance=args.self_clearance,
        obstacle_clearance=args.obstacle_clearance,
        criterion=args.criterion,
        max_iter=args.max_iter,
    )


def parse_ranges(text: str, joints: tuple[str, ...]) -> tuple[tuple[int, float, float], ...]:
    """``--range`` (``qJ=LO:HI,...``, ``qJ`` or ``J`` a joint's number from 1, or its
    name) as
    :attr:`~dynid.simulation.excitation.ExcitationOptions.ranges` (index from 0, [rad]).

    Raises
    ------
    OptionError
        An item not ``J=LO:HI``, an unknown joint, numbers that are not, a joint twice.
    """
    out: dict[int, tuple[int, float, float]] = {}
    for item in (x.strip() for x in text.split(",") if x.strip()):
        name, eq, span = item.partition("=")
        lo, colon, hi = span.partition(":")
        if not (eq and colon):
            raise OptionError(f"--range: {item!r} is not qJ=LO:HI (e.g. q1=-1.5:1.5)")
        j = _joint(name.strip(), joints, "--range", "q")
        try:
            lo_hi = float(lo), float(hi)
        except ValueError:
            raise OptionError(f"--range: {item!r}: LO and HI must be numbers [rad]") from None
        if j in out:
            raise OptionError(f"--range: joint {j + 1} given twice")
        out[j] = (j, *lo_hi)
    if not out:
        raise OptionError("--range: no J=LO:HI given")
    return tuple(out[j] for j in sorted(out))


def parse_limits(
    text: str | None, joints: tuple[str, ...], flag: str, symbol: str
) -> tuple[tuple[int, float], ...]:
    """``--max-velocity`` and its kin (``V`` for every joint, ``symbolJ=V,...`` per joint,
    ``symbolJ`` or ``J`` a joint's number from 1, or its name, as :func:`parse_ranges`
    reads them; a number before the items sets the joints they leave) as
    :attr:`~dynid.simulation.excitation.ExcitationOptions.max_velocity` and its kin
    (index from 0, the value in the option's unit); ``()`` for None.

    Raises
    ------
    OptionError
        An item neither a number nor ``J=V``, two numbers for every joint, an unknown
        joint, a value that is not a number, a joint twice.
    """
    if text is None:
        return ()
    out: dict[int, float] = {}
    every: float | None = None
    example = f"e.g. {flag} 1.0 or {flag} {symbol}1=1.0,{symbol}2=0.8"
    for item in (x.strip() for x in text.split(",") if x.strip()):
        name, eq, value = item.rpartition("=")
        try:
            v = float(value)
        except ValueError:
            raise OptionError(f"{flag}: {item!r} is not a number or J=V ({example})") from None
        if not eq:
            if every is not None:
                raise OptionError(f"{flag}: two values for every joint ({every:g}, {v:g})")
            every = v
            continue
        j = _joint(name.strip(), joints, flag, symbol)
        if j in out:
            raise OptionError(f"{flag}: joint {j + 1} given twice")
        out[j] = v
    if every is None and not out:
        raise OptionError(f"{flag}: no value given ({example})")
    if every is not None:
        out = {j: out.get(j, every) for j in range(len(joints))}
    return tuple((j, out[j]) for j in sorted(out))


def _joint(name: str, joints: tuple[str, ...], flag: str, symbol: str) -> int:
    """The index from 0 of the joint ``name``: its name, its number from 1, or
    ``symbol`` and its number (``q2``, ``dq2``).

    Raises
    ------
    OptionError
        No such joint.
    """
    rest = name[len(symbol) :] if name.startswith(symbol) else name
    if name in joints:
        return joints.index(name)
    if rest.isdigit() and 1 <= int(rest) <= len(joints):
        return int(rest) - 1
    raise OptionError(
        f"{flag}: no joint {name!r}; give its number 1..{len(joints)} ({symbol}1..) or one "
        f"of {', '.join(joints)}"
    )


def _save(args: argparse.Namespace, robot: Robot, design: ExcitationDesign) -> list[Path]:
    """trajectory.csv, trajectory.json and (unless --no-figure) excitation.png."""
    res = design.result
    written = [save_trajectory_csv(args.out / "trajectory.csv", design.sampled(args.rate))]
    written.append(save_excitation_json(args.out / "trajectory.json", res, robot, seed=args.seed))
    if not args.no_figure:
        written += save_excitation_figure(args.out, robot, design)
    return written


def save_excitation_figure(out: Path, robot: Any, design: Any) -> list[Path]:
    """``excitation.png`` (skipped without matplotlib)."""
    from ..plots.excitation import plot_excitation

    samples, obstacles = design.samples, design.result.obstacles
    png = save_figure(
        lambda: plot_excitation(robot, samples, obstacles=obstacles),
        out / "excitation.png",
        dpi=110,
    )
    return [] if png is None else [png]
