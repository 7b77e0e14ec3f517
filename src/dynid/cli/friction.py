"""Fit joint friction to the torque residual of a dynamic model on a measured log.

The residual tau_measured - (M ddq + c + g) of the model (an identification.json, or a
robot's own link parameters with --robot) is fitted per joint by a friction law:
--friction-model auto (default) fits every law of the registry (listed below, with none:
no extra friction) on 4 of 5 contiguous blocks of the log in turn (with several
recordings: on all but one recording in turn), predicts the block left out, keeps the
simplest law within one standard error of the lowest held-out error, each joint in units
of its own torque noise, as identify chooses its structure, among the laws whose
friction is dissipative within the robot's velocity limits, the offset aside (a law that
pushes the arm somewhere by more than 2 standard deviations of its fitted torque, a linear
law's uncertainty, is marked x and set aside, as identify skips such a structure;
when every law does, the choice says so in a warning) (the model's own friction is a
candidate too, judged on the same blocks: as it is, or its own law, band and coefficients
refitted on the other blocks when --model was identified from these recordings, the law
it was trained with; a robot's own friction is never refitted; kept, it is kept as it is,
friction at the motors and at the joints both; shown as own (classical), its law
named) and prints the table; a law's name fits
that law. The smooth law's width tanh(dq / w) is chosen on the same held-out blocks among
the widths identify searches (0.3 to 300 standstill bands), by name and in the
comparison. smooth_stribeck is compared only when the model's own friction is that law.
The rigid-body model is not refitted per block: on the recordings --model was identified
from, the errors are training errors of the links (validate judges new data). --data
takes several recordings (or a folder of them): each recording, and each piece of one
cut at a gap longer than --max-gap, is filtered on its own, and the laws are fitted on
the residual of all pieces together, at the torques as measured (not low-passed: the
torques validate judges; a log of jittered stamps at its own samples, not on a grid
between them), every k-th sample of a model identified with a decimation of k.
Coulomb friction is off where |dq| is inside the velocity noise band of the filtered
velocities, the band identify gives its Coulomb terms on the same recordings. The states are
low-pass filtered with zero phase (--cutoff) and the accelerations differentiated from
the filtered velocities. With a drive (--drive, the model's own, or a --robot TOML's
[drive] table) the log is read through it, a robot's links get the drive's known rotor
torques K^T diag(I_a) K ddq as validate adds them, and the law is fitted per motor at
the motor velocities where the drive's friction acts there (tau_f = K^T f(K dq)).

Writes OUT/friction.json (parameters, RMS of the residual before and after, the torques'
sensor noise per joint, the held-out table) and
OUT/friction.png (residual against velocity with the fitted curve, per joint, or per
motor against the motor velocity where the law was fitted at the motors; skipped, with a
note, without matplotlib). The model's own friction is the table's row "own (classical)"
(its law named, as the figure's title and validate name it). The log is read strictly:
rows with NaN/inf or a repeated timestamp are an error unless --drop-invalid (or the
model's identification dropped them: a note says so); gaps up to --max-gap (the
identification's by default) are bridged, longer ones cut the log into pieces.

Example:
  dynid friction --model out/identification.json --data traj.csv --out out/friction
"""

from __future__ import annotations

import argparse
from pathlib import Path

from ..exceptions import DynidError
from ..friction.laws import LAWS
from ..identification.model import IdentifiedModel
from ..identification.torque_delay import applied_delay
from ..io.friction_json import save_friction_json
from ..io.model_json import load_model_json
from ..model.robot import Robot
from ..workflows.friction import FrictionOptions, fit_friction_files
from .applies import urdf_chain
from .common import (
    CUTOFF_NONE_HELP,
    add_column_options,
    add_drive_option,
    add_log_options,
    add_q_start_option,
    add_recordings_option,
    add_snap_angles_option,
    add_subcommand,
    cutoff_type,
    load_drive_arg,
    load_robot,
    options_from,
    output_path,
    say_torque_delay,
    shown,
)
from .console import Console
from .figures import save_friction_figure
from .summaries import format_friction_rms

NAME = "friction"
#: ``--out`` is a folder: its files are one output set (:mod:`dynid.outputs.run_output`).
OUTPUT = "folder"
#: Options that apply to one route only (:mod:`dynid.cli.applies`).
APPLIES = (urdf_chain(),)


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
    add_snap_angles_option(p)
    add_recordings_option(p)
    add_column_options(p)
    add_drive_option(p)
    add_q_start_option(p)
    p.add_argument("--out", type=output_path, required=True, help="output directory")
    p.add_argument(
        "--friction-model",
        choices=("auto", *LAWS),
        default="auto",
        help="friction law; auto (default): the simplest within one standard error of the "
        "lowest held-out error; the laws "
        "and their parameters per joint: "
        + ", ".join(f"{law.name} ({' '.join(law.params) or 'zero'})" for law in LAWS.values()),
    )
    p.add_argument(
        "--cutoff",
        type=cutoff_type,
        default=None,
        metavar="HZ",
        help="low-pass cutoff of the states [Hz] (default: the one --model was identified "
        "with, else the one identification reads from the log's motion)" + CUTOFF_NONE_HELP,
    )
    add_log_options(p, torque_delay="recorded")
    p.add_argument("--no-figures", action="store_true", help="skip the PNG figures")
    return p


def load_torque_model(args: argparse.Namespace) -> IdentifiedModel | Robot:
    """The rigid-body model named by ``--model`` (identification.json) or ``--robot``."""
    if getattr(args, "model", None) is not None:
        return load_model_json(args.model)
    if getattr(args, "robot", None) is not None:
        return load_robot(args)
    raise DynidError("give --model identification.json or --robot ROBOT")


def run(args: argparse.Namespace, console: Console) -> int:
    """Fit friction, write friction.json and the figure, print the RMS table (unless -q)."""
    model = load_torque_model(args)
    robot = model.robot if isinstance(model, IdentifiedModel) else model
    options = options_from(
        args,
        FrictionOptions,
        columns=(args.columns, args.units),
        drive=load_drive_arg(args, robot.n),
    )
    result = fit_friction_files(model, args.data, options)
    fit, sel = result.fit, result.selection
    meta = result.metadata(str(args.model.name) if args.model is not None else args.robot)
    selection = None if sel is None else sel.as_dict()
    save_friction_json(
        args.out / "friction.json", fit, metadata=meta, selection=selection, robot=robot
    )
    names = list(robot.joint_names)
    if not args.no_figures:
        law = fit.kind if sel is None else sel.label(sel.chosen)  # as the table names it
        title = shown(f"{law} friction fitted to the torque residual ({meta['data']})")
        save_friction_figure(
            args.out / "friction.png", result.residual, fit, names=names, title=title
        )
    if sel is not None:
        console.print(sel.table())
    console.print(format_friction_rms(names, fit, result.noise_std, result.decimate, robot))
    if result.pieces is not None:
        console.print(result.pieces.describe())
    own = model.info.log if isinstance(model, IdentifiedModel) else None
    say_torque_delay(console, applied_delay(args.torque_delay, own.torque_delay_s if own else 0.0))
    console.wrote(args.out / "friction.json")
    return 0
