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
columns tau_ext1..n (ground truth: no reader takes them as data; `dynid observe` plots
them and reports its residual against them).
Limits are
checked; by default a trajectory that exceeds them is scaled down in amplitude
(--scale amplitude), or slowed down (--scale time), or kept (--scale none).

Example:
  dynid simulate --robot panda --trajectory sinusoid --duration 20 --seed 1 --out traj.csv
  dynid simulate --robot panda --duration 10 --contact link5:0,0,-20:4,4.5 --out hit.csv
"""

from __future__ import annotations

import argparse
from pathlib import Path

from ..exceptions import OptionError
from ..io.torque_log import save_torque_log_pieces
from ..simulation.contact import Contact
from ..workflows.simulate import SimulateOptions, simulate_log
from .applies import Applies, urdf_chain
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
    options_from,
    output_path,
    parse_vector,
    positive_type,
)
from .console import Console

NAME = "simulate"
#: ``--out`` is the one file written (:mod:`dynid.outputs.run_output`).
OUTPUT = "file"
#: Options that apply to one route only (:mod:`dynid.cli.applies`).
APPLIES = (
    urdf_chain(),
    Applies(
        ("harmonics", "base_freq"), lambda a: a.trajectory == "fourier", "--trajectory fourier"
    ),
    Applies(
        ("amplitudes", "periods"), lambda a: a.trajectory == "sinusoid", "--trajectory sinusoid"
    ),
    Applies(
        ("q0",),
        lambda a: a.trajectory in ("sinusoid", "fourier"),
        "--trajectory sinusoid or fourier",
        "a trajectory file holds its start",
    ),
)


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
        "--rate",
        type=positive_type,
        default=1000.0,
        help="sample rate [Hz] (default 1000); a trajectory.csv keeps its own times, one "
        "row in k when its rate is k times this",
    )
    p.add_argument(
        "--noise",
        type=nonnegative_type,
        default=0.05,
        help="torque sensor noise std [N m] (default 0.05); with --drive added at the joints "
        "before the log is written on the drive's side (a motor sees it through the gear)",
    )
    p.add_argument(
        "--q-noise",
        type=nonnegative_type,
        default=1e-4,
        help="position noise std [rad] (default 1e-4), at the joints as --noise",
    )
    p.add_argument(
        "--dq-noise",
        type=nonnegative_type,
        default=1e-3,
        help="velocity noise std [rad/s] (default 1e-3), at the joints as --noise",
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
        help="rise and fall time of the contacts [s] (default 0: steps); with --contact only",
    )
    add_seed_option(p)
    p.add_argument("--out", required=True, type=output_path, help="output .csv or .npz")
    return p


def _contacts(args: argparse.Namespace) -> tuple[Contact, ...]:
    """The contacts of ``--contact FRAME:WRENCH:START,END`` (parsed; the library checks
    the frames)."""
    if args.contact_ramp and not args.contact:
        raise OptionError(
            "applies with {contacts} only", field="contact_ramp", others=("contacts",)
        )
    out = []
    for text in args.contact:
        parts = text.rsplit(":", 2)
        if len(parts) != 3:
            raise OptionError(f"--contact must read FRAME:WRENCH:START,END; got {text!r}")
        frame, wrench, window = parts
        w = parse_vector(wrench, "--contact WRENCH")
        if w.size not in (3, 6):
            raise OptionError(f"--contact WRENCH must be fx,fy,fz or 6 numbers; got {wrench!r}")
        start, end = parse_vector(window, "--contact START,END", 2)
        out.append(Contact(frame, tuple(w), float(start), float(end), args.contact_ramp))
    return tuple(out)


def _vector(text: str | None, name: str) -> tuple[float, ...] | None:
    return None if text is None else tuple(parse_vector(text, name).tolist())


def run(args: argparse.Namespace, console: Console) -> int:
    """Simulate and write the log, a block of samples at a time; prints the limit report
    and a summary (unless -q)."""
    robot = load_robot(args)
    options = options_from(
        args,
        SimulateOptions,
        friction="none" if args.no_friction else (args.friction or "robot"),
        amplitudes=_vector(args.amplitudes, "--amplitudes"),
        periods=_vector(args.periods, "--periods"),
        q0=_vector(args.q0, "--q0"),
        contacts=_contacts(args),
        drive=load_drive_arg(args, robot.n),
    )
    result = simulate_log(robot, options)
    console.print(*result.notes)
    log = result.log
    extra = None if log.external is None else ("tau_ext", log.external)
    save_torque_log_pieces(
        args.out,
        log,
        n=log.n,
        n_rows=log.n_samples,
        with_ddq=log.with_ddq,
        extra=extra,
        tau_unit="N m" if options.drive is None else options.drive.effort_unit,
    )
    console.print(f"wrote {args.out}: {result.describe(options)}")
    return 0
