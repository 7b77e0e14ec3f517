"""Acquire a static data set from a simulated controller (Gaz et al. 2019, Sec. IV-A).

The simulated controller stands in for the robot controller's model library: it returns
the inertia matrix M(q) [kg m^2] and the gravity torques g(q) [N m] of the robot (for the
built-in Panda, the published parameters of Gaz et al.) at N configurations drawn
uniformly within the joint limits, away from them by --margin [rad]. --noise multiplies
every entry by (1 + REL z), z standard normal (M stays symmetric).

With --pool K the N configurations are chosen from K*N random ones (collision-free:
capsules around the links, optional --obstacles JSON as for `dynid excite`) to minimise the
condition number of the stacked static regressor [tril M; g] (greedy construction, then
exchanges; seeded). For the Panda, N = 1010 and K = 5 give about 36 instead of about 48
for random configurations (unscaled, the paper's measure: 48.9 for theirs).

The file is CSV (columns q1..qn, M<i>_<j> for i >= j, g1..gn; units in the first line) or
NPZ (arrays q, M, g), by the extension of --out.

example:
  dynid acquire-static --robot panda --n 1010 --noise 1e-4 --seed 1 --out static.csv
  dynid acquire-static --robot panda --n 1010 --pool 5 --seed 1 --out chosen.csv
"""

from __future__ import annotations

import argparse
from pathlib import Path

from ..io.static_data import save_static_data
from ..simulation.controller import DEFAULT_MARGIN
from ..workflows.acquire_static import AcquireStaticOptions, acquire_static_data
from .applies import urdf_chain
from .common import (
    add_robot_options,
    add_seed_option,
    add_subcommand,
    count_type,
    load_robot,
    nonnegative_type,
    options_from,
    output_path,
)
from .console import Console

NAME = "acquire-static"
#: ``--out`` is the one file written (:mod:`dynid.outputs.run_output`).
OUTPUT = "file"
#: Options that apply to one route only (:mod:`dynid.cli.applies`).
APPLIES = (urdf_chain(),)


def register(subparsers: argparse._SubParsersAction) -> argparse.ArgumentParser:
    """Add the ``acquire-static`` subcommand."""
    p = add_subcommand(
        subparsers,
        NAME,
        __doc__,
        help="M(q) and g(q) from a simulated controller at random static configurations",
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
    p.add_argument(
        "--pool",
        type=int,
        default=None,
        metavar="K",
        help="choose the N configurations from K*N random collision-free ones (K >= 2)",
    )
    p.add_argument(
        "--obstacles", type=Path, default=None, help="with --pool: obstacles JSON (default none)"
    )
    p.add_argument(
        "--unmodelled",
        action="store_true",
        help="add effects outside the rigid-body model, as real arms have (rotor inertia on "
        "the diagonal of M, a 0.3 deg gravity tilt; drawn from --seed, recorded in the file)",
    )
    p.add_argument("--out", type=output_path, required=True, help="output file, .csv or .npz")
    return p


def run(args: argparse.Namespace, console: Console) -> int:
    """Acquire and write the data set; returns the exit code."""
    options = options_from(args, AcquireStaticOptions)
    robot = load_robot(args)
    result = acquire_static_data(robot, options)
    chosen = result.describe()
    if chosen is not None:
        console.print(chosen)
    path = save_static_data(args.out, result.data)
    console.print(
        f"wrote {result.data.n_configurations} configurations of {robot.name} "
        f"(noise {args.noise:g}, seed {args.seed}) to {path}"
    )
    return 0
