"""Identify the dynamic coefficients (base parameters) from a data file.

Static data (a CSV or NPZ of q, M(q), g(q) at rest, as written by `dynid acquire-static`):
the stacked static regressor [tril M; g] (Gaz et al. 2019, Sec. IV-A, eq. 20) is solved by
least squares; rows without information (g1 of the Panda) are dropped and reported.
With --max-std-percent, coefficients above that relative standard deviation are removed
and the rest re-fitted (the paper used 30).

Torque logs (a CSV with a `t` column, or an NPZ with `t` and `tau`, as written by
`dynid simulate`) go to the classical route: zero-phase filtering, accelerations by
differentiation, the torque regressor in the base parameters plus viscous, Coulomb and
offset friction columns per joint, and the same least squares and statistics.

Checks that the data belong to --robot: a static data file that records another robot
(name, joint count or kinematics) is an error; configurations outside the joint limits,
and a relative error far above the recorded noise level (noise-free data must fit to
rounding), are reported as one-line warnings with the numbers. On exact data the
residual and the standard deviations are 0 (said in the summary), never NaN.

Torque logs are read strictly: rows with NaN/inf or a repeated timestamp are an error
unless --drop-invalid; gaps up to --max-gap are bridged.

Writes DIR/identification.json (coefficients, expressions, std, metrics, kinematics,
identifiability of every standard parameter) and prints a summary table.

Rank and conditioning. The base parameters come from the robot's kinematics: their number
(the rank) is read from the first clear gap (a factor >= 1e3, below 1e-3 of the largest)
in the singular values of the column-scaled regressor, and the gap is printed. A URDF
whose angles are rounded (rpy="1.5708 0 0") has near-dependencies near 1e-4 that are
treated as dependencies. --rtol overrides this with a fixed relative threshold: singular
values (and column norms) at or below RTOL times the largest count as dependencies; set it
above the near-dependencies (1e-4 for 4-digit angles) to drop them, below (1e-10) to keep
them, at the price of an ill-conditioned fit. The summary gives the paper's condition
number (unscaled regressor; 48.9 for the Panda's static data, 122 for its exciting
trajectory) and the scaled one (unit column norms; above 1e3 the data are ill-conditioned
and a warning names the nearly dependent columns). Each standard parameter is
identifiable, identifiable only in combination, or unidentifiable.

Pruning. --max-std-percent PCT (default: off, every coefficient kept) removes the
coefficients whose relative standard deviation exceeds PCT and re-fits the rest; the
paper used 30. Coefficients above 1000 % are always reported. Prune only with noisy data
and a well-conditioned regressor: on ill-conditioned data a large std may belong to a
dominant coefficient, which then goes too (fix the conditioning first).

With --consistent, the link parameters are identified physically consistent in one step
(convex, every link's pseudo-inertia positive definite, pulled towards --prior; see
`dynid retrieve --help`): from a torque log with the classical friction (fv, fc >= 0), or
from static data. Writes next to identification.json (the unconstrained fit) the files of
`dynid retrieve`: feasible.json (links, and the friction identified with them), robot.urdf,
robot.toml, report.json, retrieval.png. Exit code 1 when no consistent set satisfies the
constraints (the closest one is written and reported).

example:
  dynid identify --robot panda --data static.csv --out result --max-std-percent 30
  dynid identify --robot panda --data log.csv --consistent --prior panda --out result
"""

from __future__ import annotations

import argparse
import logging
import sys
import warnings
import zipfile
from pathlib import Path
from typing import TYPE_CHECKING, Any

import numpy as np

from ..exceptions import DataError, DynidWarning
from ..identification.consistency import fit_mismatch, limit_violations, recorded_robot_mismatch
from ..identification.data import StaticDataset
from ..identification.model import IdentifiedModel
from ..identification.static import identify_static
from ..io.model_json import save_model_json
from ..io.static_data import load_static_data, save_static_data
from ..model.robot import Robot
from ..regressors.base import identifiability
from .common import (
    about,
    add_column_options,
    add_consistency_options,
    add_drive_option,
    add_log_options,
    add_robot_options,
    add_subcommand,
    column_map,
    load_drive_arg,
    load_prior,
    load_robot,
    number,
    parse_vector,
    positive_type,
    read_log,
    record_columns,
    sdp_options,
    warn,
)

if TYPE_CHECKING:  # pragma: no cover
    from ..pipeline.stages import IdentificationStageResult

NAME = "identify"
#: ``--out`` is a folder: its files are one output set (:mod:`dynid.io.run_output`).
OUTPUT = "folder"

_log = logging.getLogger(__name__)


def register(subparsers: argparse._SubParsersAction) -> argparse.ArgumentParser:
    """Add the ``identify`` subcommand."""
    p = add_subcommand(
        subparsers,
        NAME,
        __doc__,
        help="identify the base parameters from static data (or a torque log)",
    )
    add_robot_options(p)
    add_drive_option(p)
    p.add_argument("--data", type=Path, required=True, help="data file: .csv or .npz")
    add_column_options(p)
    p.add_argument("--out", type=Path, required=True, help="output folder")
    p.add_argument(
        "--max-std-percent",
        type=positive_type,
        default=None,
        metavar="PCT",
        help="remove coefficients above this relative std [%%] and re-fit (default: keep all; "
        "paper: 30; see Pruning above)",
    )
    p.add_argument(
        "--drop-invalid",
        action="store_true",
        help="drop rows with NaN, non-numbers or a non-symmetric M (static data), or with "
        "NaN/inf or a repeated timestamp (torque logs), instead of failing; says how many "
        "and where",
    )
    add_log_options(p, drop_invalid=False)
    p.add_argument(
        "--std",
        choices=("robust", "classical"),
        default=None,
        help="standard deviations: heteroscedasticity-consistent or sigma^2 (W^T W)^-1 "
        "(default: robust for static data, classical for torque logs; honoured on both)",
    )
    p.add_argument(
        "--estimator",
        choices=("ols", "wls", "irls"),
        default="ols",
        help="least squares: ordinary (default), weighted by each joint's (static: each row's) "
        "noise level from a first fit, or Huber-reweighted against outliers",
    )
    p.add_argument(
        "--rtol",
        type=number(float, min=0, max=1, min_open=True, max_open=True),
        default=None,
        help="fixed relative rank tolerance on the singular values of the column-scaled "
        "regressor, 0 < RTOL < 1 (default: the first clear gap, see above; 1e-4 drops the "
        "near-dependencies of 4-digit URDF angles)",
    )
    p.add_argument(
        "--consistent",
        action="store_true",
        help="identify physically consistent link parameters in one step (convex, with a prior)",
    )
    add_consistency_options(p)
    p.add_argument(
        "--total-mass",
        default=None,
        metavar="MIN,MAX",
        help="--consistent: band on the total mass [kg]",
    )
    p.add_argument("--no-figures", action="store_true", help="--consistent: skip retrieval.png")
    p.add_argument(
        "--cutoff",
        type=positive_type,
        default=None,
        metavar="HZ",
        help="torque logs: zero-phase low-pass cutoff [Hz] (default: the library's)",
    )
    p.add_argument(
        "--folds",
        type=number(int, min=2),
        default=None,
        metavar="K",
        help="torque logs: contiguous time blocks of the held-out judgement (default 5)",
    )
    p.add_argument(
        "--validate-on",
        type=Path,
        default=None,
        metavar="FILE",
        help="torque logs: judge on this separate log (read as --data) instead of time blocks",
    )
    return p


def heldout_options(args: argparse.Namespace, n: int) -> dict[str, Any]:
    """``folds`` and ``validate_on`` of the torque-log routes from ``--folds``/``--validate-on``."""
    kw: dict[str, Any] = {} if args.folds is None else {"folds": args.folds}
    if args.validate_on is not None:
        with about(args.validate_on):
            kw["validate_on"] = read_log(args, args.validate_on, n)
    return kw


def data_kind(path: Path, columns: Any = None) -> str:
    """``"static"`` or ``"torque_log"``: a CSV with a ``t`` column or an NPZ with ``t``/``tau``
    is a torque log; with a column map, mapping ``t``, ``dq`` or ``tau`` makes a torque log
    and mapping ``M`` or ``g`` static data."""
    if columns is not None:
        if any(columns.mapped(k) for k in ("t", "dq", "tau", "ddq")):
            return "torque_log"
        if any(columns.mapped(k) for k in ("M", "g")):
            return "static"
    suffix = path.suffix.lower()
    if suffix == ".csv":
        with path.open(encoding="utf-8-sig", errors="replace") as fh:
            for line in fh:
                s = line.strip()
                if s and not s.startswith("#"):
                    cols = [c.strip() for c in s.split(",")]
                    return "torque_log" if "t" in cols else "static"
        raise DataError(f"{path.name}: no header line")
    if suffix == ".npz":
        try:
            with np.load(path, allow_pickle=False) as z:
                keys = set(z.files)
        except (ValueError, EOFError, zipfile.BadZipFile) as exc:
            raise DataError(f"{path.name}: not a readable NPZ file ({exc})") from exc
        except (AttributeError, TypeError):  # a single .npy array: np.load gives an array
            raise DataError(f"{path.name}: a single array, not an NPZ archive") from None
        return "torque_log" if "t" in keys or "tau" in keys else "static"
    raise DataError(f"--data must be a .csv or .npz file; got {path.name!r}")


def identify_torque_log(robot: Robot, path: Path, args: argparse.Namespace) -> IdentifiedModel:
    """Classical route: read the log (checked), filter, identify base parameters and friction."""
    from ..identification.classical import identify_from_log

    log = read_log(args, path, robot.n)
    if log.n != robot.n:
        raise DataError(
            f"{path.name}: the log has {log.n} joints; robot {robot.name!r} has {robot.n}; "
            "hint: pass the robot the log was recorded with"
        )
    kw = {} if args.cutoff is None else {"cutoff_hz": args.cutoff}
    with about(path):
        return identify_from_log(
            robot,
            log,
            max_std_percent=args.max_std_percent,
            rtol=args.rtol,
            max_gap_s=args.max_gap,
            drive=load_drive_arg(args, robot.n),
            estimator=args.estimator,
            std=args.std or "classical",
            **kw,
            **heldout_options(args, robot.n),
        )


# ---------------------------------------------------------------------------------------


def read_static_file(robot: Robot, path: Path, args: argparse.Namespace) -> StaticDataset:
    """Static data (checked), through ``--columns``/``--units`` when given; notes logged."""
    if args.folds is not None or args.validate_on is not None:
        raise DataError(
            f"{path.name}: --folds and --validate-on apply to torque logs, not static data"
        )
    cmap = column_map(args)
    if cmap is not None:
        from ..io.columns import load_mapped_static_data

        mapped = load_mapped_static_data(path, cmap, robot)
        for note in mapped.notes:
            _log.warning("%s: %s", path.name, note)
        return mapped.data
    data, n_dropped = load_static_data(path, robot, drop_invalid=args.drop_invalid)
    return data


def identify_static_file(robot: Robot, path: Path, args: argparse.Namespace) -> IdentifiedModel:
    """Static route: load (checked), check it belongs to the robot, identify."""
    data = read_static_file(robot, path, args)
    mismatch = recorded_robot_mismatch(robot, data.metadata)
    if mismatch is not None:
        raise DataError(
            f"{path.name}: {mismatch}; hint: pass --robot for the arm that recorded the data"
        )
    outside = limit_violations(robot, data.q)
    if outside is not None:
        warn(args, f"{path.name}: {outside}")
    with about(path):
        model = identify_static(
            robot,
            data,
            max_std_percent=args.max_std_percent,
            rtol=args.rtol,
            std=args.std or "robust",
            drive=load_drive_arg(args, robot.n),
            estimator=args.estimator,
        )
    misfit = fit_mismatch(model.fit.relative_error_percent, data.metadata)
    if misfit is not None:
        warn(args, f"{path.name}: {misfit}")
    return model


def run(args: argparse.Namespace) -> int:
    """Identify, write DIR/identification.json and print the summary; returns the exit code."""
    robot = load_robot(args)
    if args.consistent:
        return run_consistent(robot, args)
    with warnings.catch_warnings(record=True) as caught:
        warnings.simplefilter("always", DynidWarning)
        if data_kind(args.data, column_map(args)) == "torque_log":
            model = identify_torque_log(robot, args.data, args)
        else:
            model = identify_static_file(robot, args.data, args)
    for w in caught:
        if issubclass(w.category, DynidWarning):
            print(f"dynid {NAME}: warning: {w.message}", file=sys.stderr)
        else:
            warnings.warn_explicit(w.message, w.category, w.filename, w.lineno)
    record_columns(args, model.metadata)
    path = save_model_json(args.out / "identification.json", model)
    if not args.quiet:
        print(format_summary(model))
        print(f"wrote {path}")
    return 0


def run_consistent(robot: Robot, args: argparse.Namespace) -> int:
    """One-step consistent identification: identification.json plus the retrieve files."""
    from ..feasibility.one_step import identify_consistent
    from .retrieve import format_consistent_summary, write_outputs

    if args.max_std_percent is not None:
        raise DataError("--max-std-percent does not apply to --consistent (nothing is pruned)")
    if args.std is not None:
        raise DataError(
            "--std does not apply to --consistent: its data term is the residual itself "
            "(weighted by --estimator)"
        )
    data: Any
    if data_kind(args.data, column_map(args)) == "torque_log":
        data = read_log(args, args.data, robot.n)
        if data.n != robot.n:
            raise DataError(
                f"{args.data.name}: the log has {data.n} joints; robot {robot.name!r} has "
                f"{robot.n}; hint: pass the robot the log was recorded with"
            )
        kw = heldout_options(args, robot.n)
    else:
        kw = {}
        data = read_static_file(robot, args.data, args)
        mismatch = recorded_robot_mismatch(robot, data.metadata)
        if mismatch is not None:
            raise DataError(
                f"{args.data.name}: {mismatch}; hint: pass --robot for the arm that recorded "
                "the data"
            )
    band = None
    if args.total_mass is not None:
        v = parse_vector(args.total_mass, "--total-mass", 2)
        if not 0.0 <= v[0] <= v[1]:
            raise DataError(f"--total-mass must be MIN,MAX, 0 <= MIN <= MAX; got {args.total_mass}")
        band = (float(v[0]), float(v[1]))
    if args.cutoff is not None:
        kw["cutoff_hz"] = args.cutoff
    with about(args.data):
        result = identify_consistent(
            robot,
            data,
            prior=load_prior(args, robot),
            total_mass=band,
            options=sdp_options(args),
            rtol=args.rtol,
            drive=load_drive_arg(args, robot.n),
            estimator=args.estimator,
            **kw,
        )
    if result.identified is None:  # pragma: no cover - identify_consistent always sets it
        raise DataError("the one-step identification returned no unconstrained fit")
    record_columns(args, result.identified.metadata)
    files = [save_model_json(args.out / "identification.json", result.identified)]
    files += write_outputs(args.out, result, figures=not args.no_figures, source=str(args.data))
    if not args.quiet:
        print(format_summary(result.identified))
        print()
        print(format_consistent_summary(result))
        print("wrote " + ", ".join(str(f) for f in files))
    return 0 if result.feasible else 1


def format_summary(model: IdentifiedModel, *, width: int = 60) -> str:
    """A readable summary: metrics, then one line per coefficient (expressions shortened)."""
    fit, meta = model.fit, model.metadata
    head = [
        f"{meta.get('route', '?')} identification of {model.robot.name}: "
        + (
            f"{meta['n_configurations']} configurations"
            if "n_configurations" in meta
            else f"{meta.get('n_samples_used', '?')} samples of {meta.get('n_samples_log', '?')}"
        )
        + f", {fit.n_rows} rows"
        + (f", dropped rows {', '.join(meta['dropped_rows'])}" if meta.get("dropped_rows") else ""),
        f"rank {fit.rank}, condition number {fit.condition_number:.4g} (unscaled, as the "
        f"paper), scaled {fit.scaled_condition_number:.4g}, relative error "
        f"{fit.relative_error_percent:.4g} %, estimator {meta.get('estimator', 'ols')}, "
        f"std {meta.get('std_estimator', '?')}"
        + (
            f", pruned {len(meta['pruned'])} above {meta['max_std_percent']:g} %"
            if meta.get("pruned")
            else ""
        ),
    ]
    if fit.residual_rms == 0.0 or not np.any(fit.std[fit.kept]):
        head.append("the residual is zero to rounding (exact data): standard deviations are 0")
    ho = meta.get("heldout")
    if ho:
        head.append(heldout_line(ho))
    if model.base.gap is not None:
        hi, lo = model.base.gap
        head.append(
            f"base parameters: {model.base.rank}, rank cut between singular values {hi:.3g} "
            f"and {lo:.3g} (relative to the largest, column-scaled regressor)"
        )
    status = identifiability(model.base)
    groups = {
        k: [lab for lab, st in zip(model.base.std_labels, status, strict=True) if st == k]
        for k in ("identifiable", "combination", "unidentifiable")
    }
    head.append(
        f"standard parameters: {len(groups['identifiable'])} identifiable, "
        f"{len(groups['combination'])} only in combination, "
        f"{len(groups['unidentifiable'])} unidentifiable"
        + (f" ({', '.join(groups['unidentifiable'])})" if groups["unidentifiable"] else "")
    )
    head.append(f"{'#':>3}  {'name':<7} {'value':>13} {'std %':>9}  kept  expression")
    rows = []
    for k in range(model.base.rank):
        e = model.base.expressions[k]
        e = e if len(e) <= width else e[: width - 3] + "..."
        pct = fit.std_percent[k]
        rows.append(
            f"{k + 1:>3}  {model.base.labels[k]:<7} {fit.beta[k]:>+13.6g} "
            f"{'-' if not np.isfinite(pct) else f'{pct:.3g}':>9}  "
            f"{'yes' if fit.kept[k] else 'no':<4}  {e}"
        )
    return "\n".join(head + rows)


def heldout_line(ho: dict[str, Any]) -> str:
    """The training and held-out errors of least squares (``metadata["heldout"]``)."""
    how = (
        "on the --validate-on log"
        if ho.get("scheme") == "file"
        else f"over {ho.get('folds')} contiguous time blocks"
    )
    return (
        f"least squares: training error {ho['training_error_percent']:.4g} %, held-out "
        f"error {ho['heldout_error_percent']:.4g} % ({how})"
    )


def save_demo_stage(out_dir: Path, res: IdentificationStageResult) -> list[Path]:
    """Write the demo's identification stage: ``out_dir/static.csv`` (the data) and
    ``out_dir/identification.json`` (the model, with the seed); returns the two paths."""
    out_dir = Path(out_dir)
    return [
        save_static_data(out_dir / "static.csv", res.data),
        save_model_json(out_dir / "identification.json", res.model, seed=res.seed),
    ]
