"""Acquire a static data set from a simulated controller (Gaz et al. 2019, Sec. IV-A).

The simulated controller stands in for the robot controller's model library: it returns
the inertia matrix M(q) [kg m^2] and the gravity torques g(q) [N m] of the robot (for the
built-in Panda, the published parameters of Gaz et al.) at N configurations drawn
uniformly within the joint limits, away from them by --margin [rad]. --noise multiplies
every entry by (1 + REL z), z standard normal (M stays symmetric).

The file is CSV (columns q1..qn, M<i>_<j> for i >= j, g1..gn; units in the first line) or
NPZ (arrays q, M, g), by the extension of --out.

example:
  dynid acquire-static --robot panda --n 1010 --noise 1e-4 --seed 1 --out static.csv
"""

from __future__ import annotations

import argparse
from pathlib import Path

import numpy as np

from ..identification.consistency import kinematics_record
from ..io.static_data import save_static_data
from ..simulation.controller import DEFAULT_MARGIN, SimulatedController, acquire_static
from .common import add_robot_options, add_seed_option, count_type, load_robot, nonnegative_type

NAME = "acquire-static"


def register(subparsers: argparse._SubParsersAction) -> argparse.ArgumentParser:
    """Add the ``acquire-static`` subcommand."""
    p = subparsers.add_parser(
        NAME,
        help="M(q) and g(q) from a simulated controller at random static configurations",
        description=__doc__,
        formatter_class=argparse.RawDescriptionHelpFormatter,
    )
    add_robot_options(p)
    p.add_argument(
        "--n", type=count_type, default=1010, help="number of configurations (default: 1010)"
    )
    p.add_argument(
        "--noise",
        type=nonnegative_type,
        default=0.0,
        metavar="REL",
        help="relative standard deviation of the multiplicative noise (default: 0)",
    )
    add_seed_option(p)
    p.add_argument(
        "--margin",
        type=nonnegative_type,
        default=DEFAULT_MARGIN,
        help=f"distance kept from the joint limits [rad] (default: {DEFAULT_MARGIN})",
    )
    p.add_argument("--out", type=Path, required=True, help="output file, .csv or .npz")
    return p


def streams(seed: int) -> tuple[np.random.Generator, np.random.Generator]:
    """Two independent generators from one seed: configurations, then noise."""
    a, b = np.random.SeedSequence(seed).spawn(2)
    return np.random.default_rng(a), np.random.default_rng(b)


def run(args: argparse.Namespace) -> int:
    """Acquire and write the data set; returns the exit code."""
    robot = load_robot(args)
    rng_q, rng_noise = streams(args.seed)
    controller = SimulatedController(robot, args.noise, rng=rng_noise)
    data = acquire_static(controller, args.n, rng_q, margin=args.margin)
    data = data.with_metadata(seed=args.seed, kinematics=kinematics_record(robot))
    path = save_static_data(args.out, data)
    if not args.quiet:
        print(
            f"wrote {data.n_configurations} configurations of {robot.name} "
            f"(noise {args.noise:g}, seed {args.seed}) to {path}"
        )
    return 0
