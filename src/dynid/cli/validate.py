"""Validate a dynamic model against a measured torque log (Gaz et al. 2019, Sec. VI).

The model's torques M ddq + c + g, without and with friction, are compared with the
measured ones, per joint (RMS, MSE) and overall (relative error). Model sources:

  --model identification.json   an identified model (its classical friction, if it has
                                one, is used unless --friction or --no-friction)
  --robot ROBOT                 a robot's own link parameters and friction ('panda': the
                                published feasible parameters and sigmoid friction)
  --params feasible.json        retrieved feasible link parameters (dynid retrieve), with
                                the sigmoid friction stored beside them: Newton-Euler
                                torques (RNEA) with those parameters (the paper's Fig. 5)

--friction friction.json replaces the model's own friction. The states are low-pass
filtered with zero phase (--cutoff), the accelerations differentiated from the filtered
velocities; the measured torques are compared unfiltered.

Writes OUT/validation.json {"rms": [...], "mse": [...], "relative_error_percent": x, ...}
(for the full model, plus a "without_friction" block) and the figures
OUT/validation_torques.png and OUT/validation_rms.png (skipped, with a note, without
matplotlib). The log is read strictly: rows with NaN/inf or a repeated timestamp are an
error unless --drop-invalid; gaps up to --max-gap are bridged.

Example:
  dynid validate --robot panda --data traj.csv --out out/validation
"""

from __future__ import annotations

import argparse
from pathlib import Path

import numpy as np

from ..exceptions import DataError
from ..friction.validation import (
    Validation,
    own_friction,
    recorded_cutoff,
    validate_torques,
)
from ..identification.log import DEFAULT_CUTOFF_HZ
from ..identification.model import IdentifiedModel
from ..io.feasible import load_feasible_drive, load_feasible_linear_friction
from ..io.friction_json import load_friction_json
from ..io.validation_json import save_validation_json
from .common import (
    about,
    add_column_options,
    add_drive_option,
    add_log_options,
    add_subcommand,
    load_drive_arg,
    output_path,
    positive_type,
    shown,
)
from .console import Console
from .figures import save_validation_figures
from .sources import load_model_source, read_data_log
from .summaries import format_rms_table

NAME = "validate"
#: ``--out`` is a folder: its files are one output set (:mod:`dynid.io.run_output`).
OUTPUT = "folder"


def register(subparsers: argparse._SubParsersAction) -> argparse.ArgumentParser:
    """Add the ``validate`` subcommand."""
    p = add_subcommand(
        subparsers,
        NAME,
        __doc__,
        help="compare a model's torques (without and with friction) with a measured log",
    )
    src = p.add_mutually_exclusive_group(required=True)
    src.add_argument("--model", type=Path, help="identification.json of an identified model")
    src.add_argument("--robot", help="'panda', 'fr3', a .urdf or a .toml: its own parameters")
    src.add_argument(
        "--params", type=Path, help="feasible.json of retrieved link parameters (RNEA)"
    )
    p.add_argument("--base", default=None, help="URDF base link (with --robot)")
    p.add_argument("--tip", default=None, help="URDF tip link (with --robot)")
    fr = p.add_mutually_exclusive_group()
    fr.add_argument("--friction", type=Path, help="friction.json to add to the model")
    fr.add_argument("--no-friction", action="store_true", help="ignore the model's own friction")
    p.add_argument("--data", type=Path, required=True, help="torque log (.csv or .npz)")
    add_column_options(p)
    p.add_argument("--out", type=output_path, required=True, help="output directory")
    p.add_argument(
        "--cutoff",
        type=positive_type,
        default=None,
        help="low-pass cutoff of the states [Hz] (default: the one --model was identified "
        f"with, else {DEFAULT_CUTOFF_HZ:g})",
    )
    add_drive_option(p)
    add_log_options(p)
    p.add_argument("--no-figures", action="store_true", help="skip the PNG figures")
    return p


def run(args: argparse.Namespace, console: Console) -> int:
    """Validate, write validation.json and the figures, print the RMS table (unless -q)."""
    model, label = load_model_source(args)
    robot = model.robot if isinstance(model, IdentifiedModel) else model
    recorded = model.info.column_map if isinstance(model, IdentifiedModel) else None
    log = read_data_log(args, robot.n, owner=f"the model ({label})", recorded=recorded)
    logs = [log]  # handed over: validate frees the raw signals once it has filtered them
    del log
    if args.friction is not None:
        friction = load_friction_json(args.friction)
    elif args.no_friction:
        friction = None
    else:
        friction = own_friction(model)
        if args.params is not None:
            friction = load_feasible_linear_friction(args.params) or friction
    cutoff = recorded_cutoff(model) if args.cutoff is None else args.cutoff
    drive = load_drive_arg(args, robot.n)
    if drive is None and args.params is not None:
        drive = load_feasible_drive(args.params)
    with about(args.data):
        val = validate_torques(
            model,
            logs.pop(),
            friction=friction,
            cutoff_hz=cutoff,
            max_gap_s=args.max_gap,
            drive=drive,
        )
    errors = val.errors
    if not np.isfinite(errors.relative_error_percent) or not np.all(np.isfinite(errors.rms)):
        raise DataError(_overflow(args, val, label))
    path = save_validation_json(
        args.out / "validation.json",
        val,
        model=label,
        friction_source=(
            str(args.friction.name)
            if args.friction is not None
            else ("model" if friction is not None else None)
        ),
        data=str(args.data.name),
        cutoff_hz=cutoff,
    )
    names = list(robot.joint_names)
    if not args.no_figures:
        save_validation_figures(
            args.out, val, names=names, title=shown(f"{label} on {args.data.name}")
        )
    cols = {"RMS no friction [N m]": val.without_friction.rms}
    if val.with_friction is not None:
        cols["RMS + friction [N m]"] = val.with_friction.rms
    console.print(
        format_rms_table(names, cols),
        f"relative error {val.errors.relative_error_percent:.3f} %; wrote {path}",
    )
    return 0


def _overflow(args: argparse.Namespace, val: Validation, label: str) -> str:
    """Why the torque errors overflow: the largest of the log's torques, the rigid-body
    model's and the friction's, named with its source."""
    with np.errstate(over="ignore", invalid="ignore"):
        peaks = {
            "log": float(np.max(np.abs(val.log.tau))),
            "model": float(np.max(np.abs(val.tau_model))),
            "friction": 0.0
            if val.tau_friction is None
            else float(np.max(np.abs(val.tau_friction))),
        }
    worst = max(peaks, key=lambda k: peaks[k] if np.isfinite(peaks[k]) else np.inf)
    where = {
        "log": "the log holds values far outside a robot's range",
        "model": f"the model's torques are far outside a robot's range; check {label}'s parameters",
        "friction": "the friction torques are far outside a robot's range; check the "
        f"coefficients of {args.friction.name if args.friction is not None else label}",
    }[worst]
    return (
        f"{args.data.name}: the torque errors overflow (relative error "
        f"{val.errors.relative_error_percent}); {where} (largest |tau| [N m]: log "
        f"{peaks['log']:.3g}, rigid-body model {peaks['model']:.3g}, "
        f"friction {peaks['friction']:.3g})"
    )
