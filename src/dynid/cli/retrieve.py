"""Retrieve physically consistent link parameters from identified coefficients.

--method sdp (default): convex retrieval. Every link's 4x4 pseudo-inertia J is kept
positive definite (lambda_min(J) >= --margin * tr(J), default 1e-4: the parameters can come
from a real mass density), masses and CoMs stay in their boxes and the total mass in its
band, and the parameters are pulled towards a prior (--prior panda|FILE; default the
link inertials of the robot's description, kept in identification.json, else a solid
cylinder per link from the kinematics) by the log-det divergence (--objective). Exact
coefficients are met exactly; noisy ones are weighed by their covariance, and the prior's
weight is by default the largest that keeps the identification's residual RMS within 1 % of
the unconstrained fit (printed; --prior-weight W sets it: larger trusts the prior more).
Solves in about a second. With --static, the same problem is solved on the static data
directly (one step).

--method penalty: the paper's method (Gaz et al. 2019, Sec. V, Algorithm 1): Q independent
runs (--runs) of K stages (--stages) of simulated annealing and local refinement on the
coefficients' error plus penalties on the violated constraints (positive mass,
positive-definite inertia, triangle inequality, total-mass band), inside a box per
parameter (--bounds). The runs are spread over --workers processes; --seed makes the result
reproducible whatever the number of workers.

Input: --model DIR/identification.json (from `dynid identify`; pruned coefficients are
ignored), or --static FILE (static data, single-step variant: the objective is taken
directly on [tril M; g], no identification step) with --robot; a file of another tool is
read with --columns/--units as identify reads it (libfranka's flat M: --columns
'q=q{i0},M=M{k0},g=g{i0}').

Static data whose gravity torques are the prior's (or the description's) plus a mass at
the flange (a hand the controller's model holds and the description lacks) get a note
naming the mass: the retrieval puts it on the last links; `dynid payload` weighs it.

--total-mass MIN,MAX sets the band on the total mass [kg] (--no-total-mass drops the
default one); --friction friction.json (sigmoid) puts a friction model on the exported
robot.

Writes DIR2/feasible.json (mass, CoM, inertia about the CoM per link, with the
kinematics), DIR2/robot.urdf, DIR2/robot.xml (MJCF), DIR2/robot.toml (all written by the
code of `dynid export`), DIR2/report.json (relative residual,
every constraint margin, stage costs, run time, seed) and DIR2/retrieval.png; prints
the progress on stderr and a summary on stdout. Exit code 1 when no feasible parameter
set was found (the least-violating one is written and reported).

Bounds files (--bounds, JSON or TOML): {"total_mass": [MIN, MAX], "links": [{"name":
"link1", "mass": [MIN, MAX], "com_min": [x, y, z], "com_max": [x, y, z], "inertia_min":
[xx, xy, xz, yy, yz, zz], "inertia_max": [...]}, ...]}; every key but "name" is optional.
Without a file: the Panda's bounds of Gaz et al. for the Panda, else boxes from the link
lengths; with a prior (sdp), masses also within a factor 3 of the prior's.

example:
  dynid retrieve --model result/identification.json --prior panda --out feasible
  dynid retrieve --model result/identification.json --method penalty --runs 10 --out feasible
"""

from __future__ import annotations

import argparse
from pathlib import Path

from ..feasibility.methods import METHODS
from ..feasibility.penalty import RetrievalOptions, RetrievalResult
from ..io.feasible_bundle import save_feasible_bundle
from ..workflows.retrieve import RetrieveOptions, retrieve_files
from .applies import Applies, urdf_chain
from .common import (
    add_column_options,
    add_consistency_options,
    add_drop_invalid,
    add_robot_options,
    add_seed_option,
    add_subcommand,
    count_type,
    flag,
    load_robot,
    options_from,
    output_path,
    parse_mass_band,
)
from .console import Console
from .figures import save_retrieval_figure
from .summaries import format_consistent, format_retrieval, progress_printer

NAME = "retrieve"
#: ``--out`` is a folder: its files are one output set (:mod:`dynid.outputs.run_output`).
OUTPUT = "folder"
#: Methods with independent seeded runs (``--seed`` applies to them).
_SEEDED = tuple(name for name, m in METHODS.items() if m.parallel)
#: Options that apply to one route only (:mod:`dynid.cli.applies`).
APPLIES = (
    Applies(("robot",), lambda a: a.static is not None, "--static", "--model holds its robot"),
    Applies(
        ("drop_invalid", "columns", "units"),
        lambda a: a.static is not None,
        "--static",
        "--model holds no rows",
    ),
    urdf_chain(),
    urdf_chain("prior", ("prior_base", "prior_tip")),
    Applies(
        ("seed",), lambda a: a.method in _SEEDED, " or ".join(f"--method {m}" for m in _SEEDED)
    ),
)


def register(subparsers: argparse._SubParsersAction) -> argparse.ArgumentParser:
    """Add the ``retrieve`` subcommand."""
    p = add_subcommand(
        subparsers,
        NAME,
        __doc__,
        help="retrieve feasible link parameters from identified coefficients",
    )
    src = p.add_mutually_exclusive_group(required=True)
    src.add_argument("--model", type=Path, help="identification.json of an identified model")
    src.add_argument(
        "--static", type=Path, help="static data (.csv/.npz) for the single-step variant"
    )
    add_robot_options(p)
    p.add_argument(
        "--method",
        choices=tuple(METHODS),
        default=next(iter(METHODS)),
        help="; ".join(f"{m.name}: {m.description}" for m in METHODS.values()),
    )
    add_consistency_options(p)
    p.add_argument("--bounds", type=Path, default=None, help="bounds file (.json or .toml)")
    p.add_argument(
        "--total-mass", default=None, metavar="MIN,MAX", help="band on the total mass [kg]"
    )
    p.add_argument("--no-total-mass", action="store_true", help="drop the default total-mass band")
    d = RetrievalOptions()
    p.add_argument(
        "--runs",
        type=count_type,
        default=None,
        help=f"--method penalty: independent runs Q (default {d.runs})",
    )
    p.add_argument(
        "--stages",
        type=count_type,
        default=None,
        help=f"--method penalty: stages K per run (default {d.stages})",
    )
    p.add_argument(
        "--workers",
        type=count_type,
        default=None,
        help="--method penalty: processes (default: min(runs, cores); more than that is "
        "capped, with a note)",
    )
    add_seed_option(p)
    add_drop_invalid(p)
    add_column_options(p)
    p.add_argument(
        "--friction", type=Path, default=None, help="friction.json (sigmoid) to put on the robot"
    )
    p.add_argument("--out", type=output_path, required=True, help="output folder")
    p.add_argument("--no-figures", action="store_true", help="skip retrieval.png")
    return p


def run(args: argparse.Namespace, console: Console) -> int:
    """Retrieve, write the outputs, print the summary; 0 if feasible, 1 if not."""
    static = args.static is not None
    source = args.static if static else args.model
    options = options_from(
        args,
        RetrieveOptions,
        total_mass_band=not args.no_total_mass,
        total_mass=parse_mass_band(args.total_mass),
        columns=(args.columns, args.units),
    )
    retrieval = retrieve_files(
        source,
        options,
        kind="static" if static else "model",
        robot=load_robot(args) if static else None,
        progress=None if console.quiet else progress_printer(header=f"retrieving from {source}:"),
    )
    for field, what in retrieval.notes:
        console.notice(f"note: {flag(field)} {what}")
    result = retrieval.result
    files = save_feasible_bundle(
        args.out, result, column_map=retrieval.column_map, source=str(source)
    )
    files += [] if args.no_figures else save_retrieval_figure(args.out, result)
    summary = format_retrieval if isinstance(result, RetrievalResult) else format_consistent
    console.print(summary(result))  # type: ignore[arg-type]
    console.wrote(*files)
    return 0 if result.feasible else 1
