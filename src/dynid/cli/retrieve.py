"""Retrieve physically consistent link parameters from identified coefficients.

--method sdp (default): convex retrieval. Every link's 4x4 pseudo-inertia J is kept
positive definite (lambda_min(J) >= --margin * tr(J), default 1e-4: the parameters can come
from a real mass density), masses and CoMs stay in their boxes and the total mass in its
band, and the parameters are pulled towards a prior (--prior panda|FILE; default a solid
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
directly on [tril M; g], no identification step) with --robot.

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
import sys
from pathlib import Path
from typing import TYPE_CHECKING, Any

import numpy as np

from ..exceptions import DynidError
from ..feasibility.bounds import default_bounds
from ..feasibility.constraints import principal_moments
from ..feasibility.heldout import HeldOutJudgement
from ..feasibility.retrieve import (
    RetrievalOptions,
    RetrievalProgress,
    RetrievalResult,
    retrieve,
    retrieve_from_static,
)
from ..feasibility.sdp import ConsistentResult
from ..friction.model import ClassicalFriction, DriveFriction
from ..friction.validation import NewtonEulerValidation
from ..identification.model import IdentifiedModel
from ..io.export import ExportOptions, save_robot_files
from ..io.feasible import load_bounds, save_feasible_json, save_report_json
from ..io.json_files import save_json
from ..model.robot import Robot
from .common import (
    add_consistency_options,
    add_robot_options,
    add_seed_option,
    add_subcommand,
    count_type,
    load_prior,
    load_robot,
    parse_vector,
    save_figure,
    sdp_options,
)

if TYPE_CHECKING:  # pragma: no cover
    from ..pipeline.stages import FeasibleStageResult

NAME = "retrieve"
#: ``--out`` is a folder: its files are one output set (:mod:`dynid.io.run_output`).
OUTPUT = "folder"


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
        choices=("sdp", "penalty"),
        default="sdp",
        help="convex LMI retrieval with a prior (default) or the paper's penalty method",
    )
    add_consistency_options(p)
    p.add_argument("--bounds", type=Path, default=None, help="bounds file (.json or .toml)")
    p.add_argument(
        "--total-mass", default=None, metavar="MIN,MAX", help="band on the total mass [kg]"
    )
    p.add_argument("--no-total-mass", action="store_true", help="drop the default total-mass band")
    d = RetrievalOptions()
    p.add_argument(
        "--runs", type=count_type, default=d.runs, help=f"independent runs Q (default {d.runs})"
    )
    p.add_argument(
        "--stages", type=count_type, default=d.stages, help=f"stages K per run (default {d.stages})"
    )
    p.add_argument(
        "--workers",
        type=count_type,
        default=None,
        help="processes (default: min(runs, cores); more than that is capped, with a note)",
    )
    add_seed_option(p)
    p.add_argument(
        "--friction", type=Path, default=None, help="friction.json (sigmoid) to put on the robot"
    )
    p.add_argument("--out", type=Path, required=True, help="output folder")
    p.add_argument("--no-figures", action="store_true", help="skip retrieval.png")
    return p


def _band(args: argparse.Namespace) -> tuple[float, float] | None:
    if args.total_mass is None:
        return None
    v = parse_vector(args.total_mass, "--total-mass", 2)
    if not 0.0 <= v[0] <= v[1]:
        raise DynidError(f"--total-mass must be MIN,MAX, 0 <= MIN <= MAX; got {args.total_mass}")
    return float(v[0]), float(v[1])


def progress_printer(stream: Any = None) -> Any:
    """A ``progress`` callback that prints one line per finished run on ``stream`` (stderr)."""

    def show(p: RetrievalProgress) -> None:
        out = sys.stderr if stream is None else stream
        state = "feasible" if p.feasible else "INFEASIBLE"
        out.write(
            f"  run {p.done:>2}/{p.total} (#{p.run}): cost {p.cost:.3e}, relative residual "
            f"{p.relative_residual:.2e}, {state}  [{p.elapsed:6.1f} s]\n"
        )
        out.flush()

    return show


def _band_margin(r: RetrievalResult) -> float:
    return min(r.report.min_margin("total_mass_min"), r.report.min_margin("total_mass_max"))


def format_summary(result: RetrievalResult) -> str:
    """Readable summary: per link mass, CoM, principal moments and triangle margin; totals."""
    r = result
    lam = principal_moments(r.inertia)
    tri = {c.link: c.margin for c in r.report.select("triangle_inequality")}
    names = r.robot.link_names[1:]
    w = max(len(s) for s in names)
    lines = [
        f"{'link':<{w}}  {'mass [kg]':>9}  {'CoM [m]':^26}  "
        f"{'principal moments [kg m^2]':^30}  {'triangle':>9}",
    ]
    for i, name in enumerate(names):
        c = " ".join(f"{x:+.4f}" for x in r.com[i])
        m = " ".join(f"{x:.3e}" for x in lam[i])
        lines.append(f"{name:<{w}}  {r.mass[i]:>9.4f}  {c:^26}  {m:^30}  {tri[i + 1]:>9.2e}")
    status = "FEASIBLE" if r.feasible else "INFEASIBLE (least-violating solution)"
    lines += [
        f"total mass {float(np.sum(r.mass)):.4f} kg"
        + ("" if r.total_mass is None else f" (band {r.total_mass[0]:g}..{r.total_mass[1]:g} kg)"),
        f"{status}: relative residual {r.relative_residual:.3e} ({r.kind}); "
        f"{r.n_feasible_runs}/{len(r.runs)} runs feasible; kept run {r.best_run}",
        "min margins: "
        + ", ".join(
            f"{n} {r.report.min_margin(n):.3g}"
            for n in (
                "mass_positive",
                "inertia_positive_definite",
                "triangle_inequality",
                "com_in_box",
            )
            if r.report.select(n)
        )
        + (f", total mass {_band_margin(r):.3g} kg" if r.report.select("total_mass_min") else ""),
        f"stage costs {', '.join(f'{x:.3g}' for x in r.stage_costs)}; "
        f"{r.run_time:.1f} s on {r.workers} worker(s), seed {r.seed}",
    ]
    if not r.feasible:
        lines.append(str(r.report))
    return "\n".join(lines)


def format_consistent_summary(result: ConsistentResult) -> str:
    """Readable summary of a convex retrieval: per link mass, CoM, margin; fit; notes."""
    r = result
    names = r.robot.link_names[1:]
    w = max(len(s) for s in names)
    lines = [
        f"{'link':<{w}}  {'mass [kg]':>9}  {'prior [kg]':>10}  {'CoM [m]':^26}  "
        f"{'lambda_min(J)/tr(J)':>19}",
    ]
    for i, name in enumerate(names):
        c = " ".join(f"{x:+.4f}" for x in r.com[i])
        lines.append(
            f"{name:<{w}}  {r.mass[i]:>9.4f}  {r.prior.mass[i]:>10.4f}  {c:^26}  "
            f"{r.pseudo_inertia_margin[i]:>19.3e}"
        )
    status = "CONSISTENT" if r.feasible else "NOT CONSISTENT WITH THE SPECIFICATION (closest set)"
    lines += [
        f"total mass {float(np.sum(r.mass)):.4f} kg"
        + ("" if r.total_mass is None else f" (band {r.total_mass[0]:g}..{r.total_mass[1]:g} kg)"),
        f"{status}: method sdp ({r.options.objective}, prior {r.prior.source}), fit {r.fit}, "
        f"relative residual on the coefficients {r.relative_residual:.3e}, data residual "
        f"{100 * (r.residual_ratio - 1):.3f} % above the unconstrained fit",
        f"solver {r.solver}: {r.status}, {r.run_time:.2f} s",
    ]
    if r.heldout is not None:
        lines += heldout_table(r.heldout)
    if r.friction is not None:
        at = "motors" if r.drive is not None and r.drive.friction_at == "motor" else "joints"
        lines.append(
            f"friction at the {at}: fv [N m s/rad]: "
            + " ".join(f"{x:.4g}" for x in r.friction[:, 0])
            + "; fc [N m]: "
            + " ".join(f"{x:.4g}" for x in r.friction[:, 1])
        )
    if r.rotor_inertia is not None:
        lines.append(
            "rotor inertia at the motors [kg m^2] (>= 0): "
            + " ".join(f"{x:.4g}" for x in r.rotor_inertia)
        )
    lines += [f"note: {s}" for s in r.notes]
    if not r.feasible:
        lines.append(str(r.report))
    return "\n".join(lines)


def heldout_table(j: HeldOutJudgement) -> list[str]:
    """Training against held-out errors of least squares and of the consistent fit."""
    how = "the --validate-on log" if j.scheme == "file" else f"{j.folds} contiguous time blocks"
    verdict = "accepted" if j.accepted else "NOT accepted"
    return [
        f"torque error [%]      {'training':>9}  {'held-out':>9}   (held out: {how})",
        f"least squares         {j.ls_training_percent:>9.4g}  {j.ls_heldout_percent:>9.4g}",
        f"consistent            {j.training_percent:>9.4g}  {j.heldout_percent:>9.4g}",
        f"{verdict}: held-out error {100 * (j.ratio - 1):+.3g} % against least squares "
        f"(tolerance +{100 * j.tolerance:g} %); the training residual does not decide",
    ]


def write_outputs(
    out: Path,
    result: RetrievalResult | ConsistentResult,
    *,
    figures: bool = True,
    **report_extra: Any,
) -> list[Path]:
    """Write feasible.json, the robot files (robot.urdf, robot.xml, robot.toml: one per export
    format), report.json (and retrieval.png)."""
    files = [save_feasible_json(out / "feasible.json", result)]
    fr = getattr(result, "friction", None)  # one-step on a log: classical fv, fc, fo
    drive = getattr(result, "drive", None)
    mj: Any = True
    if fr is not None:
        law = ClassicalFriction.from_array(fr)
        at_motors = drive is not None and drive.friction_at == "motor"
        mj = DriveFriction(law, drive) if drive is not None and at_motors else law
    files += save_robot_files(out, result.robot, ExportOptions(friction=mj, drive=drive))
    files.append(save_report_json(out / "report.json", result, **report_extra))
    if figures:
        from ..plots.feasible import plot_consistent, plot_retrieval

        fig = save_figure(
            lambda: (
                plot_consistent([result])
                if isinstance(result, ConsistentResult)
                else plot_retrieval(result)
            ),
            out / "retrieval.png",
        )
        files += [fig] if fig is not None else []
    return files


def _load_model(args: argparse.Namespace) -> tuple[IdentifiedModel, Robot]:
    """The identified model of --model, its robot carrying the friction of --friction."""
    from ..io.model_json import load_model_json

    model = load_model_json(args.model)
    robot = _friction_robot(model.robot, args.friction)
    if robot is not model.robot:
        model = IdentifiedModel(
            robot, model.base, model.fit, model.friction, dict(model.metadata), drive=model.drive
        )
    return model, robot


def _friction_robot(robot: Robot, path: Path | None) -> Robot:
    if path is None:
        return robot
    from ..friction.model import SigmoidFriction
    from ..io.friction_json import load_friction_json

    fr = load_friction_json(path)
    if not isinstance(fr, SigmoidFriction):
        raise DynidError(f"{path.name}: a robot holds sigmoid friction; got a {fr.kind} model")
    return robot.with_friction(fr.as_array())


def run(args: argparse.Namespace) -> int:
    """Retrieve, write the outputs, print the summary; 0 if feasible, 1 if not."""
    if args.method == "sdp":
        return run_sdp(args)
    for flag, value in (("--margin", args.margin), ("--objective", args.objective)):
        if value is not None:
            raise DynidError(f"{flag} applies to --method sdp only")
    quiet = bool(getattr(args, "quiet", False))
    try:
        extra_opts = {} if args.prior_weight is None else {"prior_weight": args.prior_weight}
        options = RetrievalOptions(runs=args.runs, stages=args.stages, **extra_opts)
    except ValueError as exc:
        raise DynidError(f"--runs/--stages/--prior-weight: {exc}") from None
    band = _band(args)
    if args.workers is not None and args.workers < 1:
        raise DynidError(f"--workers must be >= 1; got {args.workers}")
    if args.workers is not None:
        from .._parallel import available_cores

        cores = available_cores()
        cap = min(cores, args.runs)
        if args.workers > cap:
            print(
                f"note: --workers {args.workers}: using {cap} ({cores} cores, {args.runs} runs)",
                file=sys.stderr,
            )
            args.workers = cap
    common: dict[str, Any] = dict(
        options=options,
        workers=args.workers,
        seed=args.seed,
        progress=None if quiet else progress_printer(),
    )
    if args.model is not None:
        model, robot = _load_model(args)
        bounds = _bounds(args, robot)
        source = str(args.model)
        if not quiet:
            print(
                f"retrieving feasible parameters of {robot.name} from {args.model} ...",
                file=sys.stderr,
            )
        result = retrieve(
            model, bounds=bounds, total_mass=band, prior=load_prior(args, robot), **common
        )
    else:
        from ..io.static_data import load_static_data

        robot = _friction_robot(load_robot(args), args.friction)
        data, _ = load_static_data(args.static, robot)
        from ..identification.consistency import recorded_robot_mismatch

        mismatch = recorded_robot_mismatch(robot, data.metadata)
        if mismatch is not None:
            raise DynidError(
                f"{args.static.name}: {mismatch}; hint: pass --robot for the arm that "
                "recorded the data"
            )
        bounds = _bounds(args, robot)
        source = str(args.static)
        if not quiet:
            print(
                f"retrieving feasible parameters of {robot.name} from {args.static} ...",
                file=sys.stderr,
            )
        result = retrieve_from_static(
            robot, data, bounds=bounds, total_mass=band, prior=load_prior(args, robot), **common
        )
    files = write_outputs(args.out, result, figures=not args.no_figures, source=source)
    if not quiet:
        print(format_summary(result))
        print("wrote " + ", ".join(str(f) for f in files))
    return 0 if result.feasible else 1


def _bounds(args: argparse.Namespace, robot: Robot) -> Any:
    bounds = load_bounds(args.bounds, robot) if args.bounds else default_bounds(robot)
    return bounds.with_total_mass(None) if args.no_total_mass else bounds


def run_sdp(args: argparse.Namespace) -> int:
    """Convex retrieval (or one-step on --static), outputs, summary; 0 if consistent, else 1."""
    quiet = bool(getattr(args, "quiet", False))
    band = _band(args)
    options = sdp_options(args)
    if args.model is not None:
        from ..feasibility.sdp import retrieve_sdp

        model, robot = _load_model(args)
        prior = load_prior(args, robot)
        source = str(args.model)
        result = retrieve_sdp(
            model, prior=prior, bounds=_bounds(args, robot), total_mass=band, options=options
        )
    else:
        from ..feasibility.one_step import identify_consistent
        from ..io.static_data import load_static_data

        robot = _friction_robot(load_robot(args), args.friction)
        data, _ = load_static_data(args.static, robot)
        source = str(args.static)
        result = identify_consistent(
            robot,
            data,
            prior=load_prior(args, robot),
            bounds=_bounds(args, robot),
            total_mass=band,
            options=options,
        )
    files = write_outputs(args.out, result, figures=not args.no_figures, source=source)
    if not quiet:
        print(format_consistent_summary(result))
        print("wrote " + ", ".join(str(f) for f in files))
    return 0 if result.feasible else 1


# ------------------------------------------------------------------------------ demo
def save_demo_stage(out_dir: Path, res: FeasibleStageResult) -> list[Path]:
    """Write the demo's feasible stage under ``out_dir``: the files of :func:`write_outputs`
    (with the seed), ``feasible_validation.json`` and ``feasible_validation.png``."""
    from ..plots.feasible import plot_newton_euler_validation

    out_dir = Path(out_dir)
    files = write_outputs(out_dir, res.retrieval, seed=res.seed)
    doc = res.validation.as_dict() | {"seed": res.seed}
    files.append(save_json(out_dir / "feasible_validation.json", doc))
    fig = save_figure(
        lambda: plot_newton_euler_validation(
            res.validation,
            title="Newton-Euler with the retrieved feasible parameters (validation trajectory)",
        ),
        out_dir / "feasible_validation.png",
    )
    return files + ([fig] if fig is not None else [])


def format_demo_stage(res: FeasibleStageResult) -> str:
    """The demo's feasible stage: the retrieval summary, the Newton-Euler RMS table and the
    largest difference to the identified model."""
    return "\n".join(
        [
            format_summary(res.retrieval),
            _rms_table(res.validation),
            "max |NE(feasible) - identified model| on the validation states: "
            f"{res.max_torque_difference:.3g} N m",
        ]
    )


def _rms_table(val: NewtonEulerValidation) -> str:
    names = val.joint_names
    w = max(len(s) for s in names)
    head = f"{'joint':<{w}}  {'RMS NE [N m]':>12}" + (
        "  {:>18}".format("RMS identified [N m]") if val.errors_reference is not None else ""
    )
    rows = [head]
    for j, name in enumerate(names):
        row = f"{name:<{w}}  {val.errors.rms[j]:>12.4f}"
        if val.errors_reference is not None:
            row += f"  {val.errors_reference.rms[j]:>20.4f}"
        rows.append(row)
    fr = "with " + val.friction_kind + " friction" if val.friction_kind else "without friction"
    rows.append(f"(torques {fr}; relative error NE {val.errors.relative_error_percent:.2f} %)")
    return "\n".join(rows)
