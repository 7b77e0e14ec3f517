"""Fit joint friction to the torque residual of a dynamic model on a measured log.

The residual tau_measured - (M ddq + c + g) of the model (an identification.json, or a
robot's own link parameters with --robot) is fitted per joint by a friction law:
--friction-model auto (default) fits every law (none, classical, smooth, asymmetric,
stribeck, sigmoid) on 5 contiguous blocks of the log in turn, predicts the block left out,
keeps the law with the lowest held-out error (the model's own friction is a candidate too,
so the result never predicts worse than it) and prints the table; a law's name fits that
law. Coulomb friction is off where |dq| is inside the velocity noise band. The states are
low-pass filtered with zero phase (--cutoff) and the accelerations differentiated from the
filtered velocities. With a drive (--drive, or the
model's own) the log is read through it and the law is fitted per motor at the motor
velocities where the drive's friction acts there (tau_f = K^T f(K dq)).

Writes OUT/friction.json (parameters, RMS of the residual before and after, the held-out
table) and
OUT/friction.png (residual against velocity with the fitted curve, per joint; skipped,
with a note, without matplotlib). The log is read strictly: rows with NaN/inf or a
repeated timestamp are an error unless --drop-invalid; gaps up to --max-gap are bridged.

Example:
  dynid friction --model out/identification.json --data traj.csv --out out/friction
"""

from __future__ import annotations

import argparse
from pathlib import Path
from typing import TYPE_CHECKING, Any

import numpy as np

from ..exceptions import DataError, DynidError
from ..friction.fit import (
    FrictionFit,
    FrictionResidual,
    fit_friction_through,
    friction_residual,
    model_drive,
)
from ..friction.laws import LAWS
from ..friction.select import select_friction
from ..friction.validation import Validation, own_friction
from ..identification.log import DEFAULT_CUTOFF_HZ
from ..identification.model import IdentifiedModel
from ..io.friction_json import save_friction_json
from ..io.json_files import save_json
from ..model.robot import Robot
from .common import (
    about,
    add_column_options,
    add_drive_option,
    add_log_options,
    add_subcommand,
    load_drive_arg,
    load_robot,
    positive_type,
    read_log,
    reuse_columns,
    save_figure,
    shown,
)

if TYPE_CHECKING:  # pragma: no cover
    from ..pipeline.stages import FrictionStageResult

NAME = "friction"
#: ``--out`` is a folder: its files are one output set (:mod:`dynid.io.run_output`).
OUTPUT = "folder"

#: ``schema`` of validation.json (written by ``validate`` and by the demo).
VALIDATION_SCHEMA = "dynid-validation/1"


def register(subparsers: argparse._SubParsersAction) -> argparse.ArgumentParser:
    """Add the ``friction`` subcommand."""
    p = add_subcommand(
        subparsers,
        NAME,
        __doc__,
        help="fit joint friction (the law chosen on held-out data) to a model's torque residual",
    )
    src = p.add_mutually_exclusive_group(required=True)
    src.add_argument("--model", type=Path, help="identification.json of an identified model")
    src.add_argument("--robot", help="'panda', 'fr3', a .urdf or a .toml: its link parameters")
    p.add_argument("--base", default=None, help="URDF base link (with --robot)")
    p.add_argument("--tip", default=None, help="URDF tip link (with --robot)")
    p.add_argument("--data", type=Path, required=True, help="torque log (.csv or .npz)")
    add_column_options(p)
    add_drive_option(p)
    p.add_argument("--out", type=Path, required=True, help="output directory")
    p.add_argument(
        "--friction-model",
        choices=("auto", *LAWS),
        default="auto",
        help="friction law; auto (default): the one with the lowest held-out error",
    )
    p.add_argument(
        "--cutoff",
        type=positive_type,
        default=DEFAULT_CUTOFF_HZ,
        help=f"low-pass cutoff of the states [Hz] (default {DEFAULT_CUTOFF_HZ:g})",
    )
    add_log_options(p)
    p.add_argument("--no-figures", action="store_true", help="skip the PNG figures")
    return p


def load_torque_model(args: argparse.Namespace) -> IdentifiedModel | Robot:
    """The rigid-body model named by ``--model`` (identification.json) or ``--robot``."""
    if getattr(args, "model", None) is not None:
        from ..io.model_json import load_model_json

        return load_model_json(args.model)
    if getattr(args, "robot", None) is not None:
        return load_robot(args)
    raise DynidError("give --model identification.json or --robot ROBOT")


def _joint_count(model: IdentifiedModel | Robot) -> int:
    return (model.robot if isinstance(model, IdentifiedModel) else model).n


def _joint_names(model: IdentifiedModel | Robot) -> list[str]:
    robot = model.robot if isinstance(model, IdentifiedModel) else model
    return list(robot.joint_names)


def save_friction_figure(
    path: Path, residual: FrictionResidual, fit: FrictionFit, *, names: list[str], **kw: Any
) -> Path | None:
    """Write the residual-vs-velocity figure (Fig. 4) to ``path`` (None: no matplotlib)."""
    from ..plots.friction import plot_friction_fit

    return save_figure(lambda: plot_friction_fit(residual, fit, joint_names=names, **kw), path)


def save_validation_figures(
    out: Path,
    validation: Validation,
    *,
    names: list[str],
    prefix: str = "validation",
    noise_std: float | None = None,
    title: str | None = None,
) -> list[Path]:
    """Write ``<prefix>_torques.png`` (Fig. 3) and ``<prefix>_rms.png`` under ``out``
    (none without matplotlib)."""
    from ..plots.torques import plot_rms_comparison, plot_torque_validation

    rms = {"without friction": validation.without_friction.rms}
    if validation.with_friction is not None:
        rms["with friction"] = validation.with_friction.rms
    paths = [
        save_figure(
            lambda: plot_torque_validation(validation, joint_names=names, title=title),
            out / f"{prefix}_torques.png",
            dpi=100,
        ),
        save_figure(
            lambda: plot_rms_comparison(rms, noise_std=noise_std, title=title),
            out / f"{prefix}_rms.png",
        ),
    ]
    return [p for p in paths if p is not None]


def format_rms_table(names: list[str], columns: dict[str, np.ndarray]) -> str:
    """A per-joint table of RMS values [N m]."""
    head = f"{'joint':<10}" + "".join(f"{k:>22}" for k in columns)
    rows = [head]
    for j, name in enumerate(names):
        rows.append(f"{name:<10}" + "".join(f"{float(v[j]):>22.4f}" for v in columns.values()))
    return "\n".join(rows)


def run(args: argparse.Namespace) -> int:
    """Fit friction, write friction.json and the figure, print the RMS table (unless -q)."""
    say = (lambda *a: None) if getattr(args, "quiet", False) else print
    model = load_torque_model(args)
    if isinstance(model, IdentifiedModel):
        reuse_columns(args, model.metadata)
    n = _joint_count(model)
    log = read_log(args, args.data, n)
    if log.n != n:
        raise DataError(f"{args.data.name}: the log has {log.n} joints; the model has {n}")
    drive = model_drive(model, load_drive_arg(args, n))
    with about(args.data):
        res = friction_residual(
            model, log, cutoff_hz=args.cutoff, max_gap_s=args.max_gap, drive=drive
        )
        if args.friction_model == "auto":
            sel = select_friction(res, drive, own=own_friction(model))
            fit, selection = sel.fit, sel.as_dict()
            print(sel.table())
        else:
            fit, selection = fit_friction_through(res, drive, args.friction_model), None
    meta = {
        "data": str(args.data.name),
        "model": str(args.model.name) if args.model is not None else args.robot,
        "cutoff_hz": args.cutoff,
        "n_samples": fit.n_samples,
        "converged": [bool(x) for x in fit.converged],
    }
    save_friction_json(args.out / "friction.json", fit, metadata=meta, selection=selection)
    names = _joint_names(model)
    if not args.no_figures:
        save_friction_figure(
            args.out / "friction.png",
            res,
            fit,
            names=names,
            title=shown(f"{fit.kind} friction fitted to the torque residual ({args.data.name})"),
        )
    print(
        format_rms_table(
            names, {"RMS before [N m]": fit.rms_before, "RMS after [N m]": fit.rms_after}
        )
    )
    say(f"wrote {args.out / 'friction.json'}")
    return 0


def save_demo_stage(out_dir: Path, res: FrictionStageResult) -> list[Path]:
    """Write the demo's friction stage under ``out_dir``: ``friction.json``,
    ``validation.json``, ``friction.png`` and the validation figures; returns the paths."""
    out_dir = Path(out_dir)
    names = list(res.truth.joint_names)
    save_friction_json(
        out_dir / "friction.json", res.fit, metadata={"seed": res.seed, "source": "demo, sinusoids"}
    )
    doc = res.validation.as_dict()
    doc["seed"] = res.seed
    doc["units"] = {"rms": "N m", "mse": "N^2 m^2", "relative_error_percent": "%"}
    save_json(out_dir / "validation.json", doc, schema=VALIDATION_SCHEMA)
    files: list[Path | None] = [out_dir / "friction.json", out_dir / "validation.json"]
    files.append(
        save_friction_figure(
            out_dir / "friction.png",
            res.residual,
            res.fit,
            names=names,
            reference=res.reference_friction,
            reference_label="true (published) friction",
            title="sigmoid friction fitted to the residual of the identified model",
        )
    )
    files += save_validation_figures(
        out_dir,
        res.validation,
        names=names,
        noise_std=float(np.max(res.noise.tau_std)),  # one level for every joint: the largest
        title="validation on the sinusoids of Gaz et al. 2019 (eq. 31)",
    )
    return [f for f in files if f is not None]


def format_demo_stage(res: FrictionStageResult) -> str:
    """The demo's friction stage: the limit note (if the sinusoids were scaled), the
    per-joint RMS without and with friction, the relative errors."""
    lines = []
    if not res.limits.ok:
        lines.append(
            f"sinusoids of Table I exceed the limits; amplitudes scaled by {res.scale:.4f}:\n"
            f"{res.limits}"
        )
    names = list(res.truth.joint_names)
    lines.append(
        format_rms_table(
            names,
            {
                "RMS no friction [N m]": res.rms_without_friction,
                "RMS + friction [N m]": res.rms_with_friction,
            },
        )
    )
    lines.append(
        f"relative error: {res.relative_error_percent_without:.2f} % without friction, "
        f"{res.relative_error_percent_with:.2f} % with (sensor noise {res.noise.tau_std} N m)"
    )
    return "\n".join(lines)
