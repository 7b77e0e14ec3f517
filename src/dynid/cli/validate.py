"""Validate a dynamic model against a measured torque log (Gaz et al. 2019, Sec. VI).

The model's torques M ddq + c + g, without and with friction, are compared with the
measured ones, per joint (RMS, MSE) and overall (relative error). Model sources:

  --model identification.json   an identified model (its classical friction, if it has
                                one, is used unless --friction or --no-friction); of a
                                folder identify --consistent wrote, the least-squares
                                model (a note says so, and that --params feasible.json
                                validates the consistent one)
  --robot ROBOT                 a robot's own link parameters and friction ('panda': the
                                published feasible parameters and sigmoid friction)
  --params feasible.json        retrieved feasible link parameters (dynid retrieve), with
                                the friction stored in them (the law identified with the
                                links, or a sigmoid): Newton-Euler torques (RNEA) with
                                those parameters (the paper's Fig. 5); a robot
                                .urdf, .toml or .xml (MJCF) given here is read
                                as --robot reads it; the data are read and
                                prepared as the identification.json beside it
                                records (identify --consistent writes both), as
                                --model reads them

--friction friction.json replaces the model's own friction. A Coulomb step whose
standstill band lies well inside the noise of the velocities it is evaluated at (none at
all: a URDF's <dynamics friction>, MJCF's frictionloss) is judged with that noise band,
as observe bands it (a note says so): sign(dq) of the noise at every rest would flip it.
The states are low-pass filtered with zero phase (--cutoff), the accelerations
differentiated from the filtered velocities; the measured torques are compared
unfiltered. One-sample torque spikes (a
sample off both neighbours by more than 20 times the noise while the joint moves: a sensor
or logging fault) are replaced by the line between their neighbours before judging, as
identify replaces them before fitting; a warning names the file, the joints, the counts and
the times, and the verdict says how many.

--data takes several recordings (or a folder of them): each recording, and each piece of
one cut at a gap longer than --max-gap, is filtered on its own and never joined to
another. The errors are pooled over every sample of every recording (RMS per joint,
relative error over all), and given per recording; the torque figure shows every
recording, each from its own start, one after another and named (one recording: its longest
piece), the RMS figure the pooled errors.

--torque-delay MS reads each piece's states MS earlier (torques that lag the positions);
a model identified with a delay is validated with it. The summary, validation.json
("torque_delay_used") and the report's options say the delay applied and whether it was
given or the model's; --torque-delay 0 validates without it. A delay the residual points
to is said in the verdict: of an identified model, with the hint to identify it again
with --torque-delay (its coefficients were fitted to the lagging torques).

The verdict weighs the relative error against the sensor-noise floor read from the
measured torques (the smallest error a model can reach on them): "at the noise floor"
(at most 1.5 x the floor), "usable" (at most 3 x, or below 15 %), "poor" (below 50 %: the
model misses effects the data show), "unusable" (50 % or more, or torques anti-correlated
with the model's: a log of another robot, in other units or of the other sign). Each
joint is judged against its own noise too (at the floor within 1.25 x it, usable within 3
x or below 25 % relative error, poor otherwise) and the verdict is the worst joint's where
that is worse (never worse than poor), naming those joints: a pooled error within 1.5 x
the floor is "poor" when a joint errs over 3 x its noise and 25 % of its torque. A
recording whose torques read with the opposite sign on some joints or on all (the check
identify and observe refuse it by) is named at the start of the verdict with those joints
and the --units entries that read them (of that file alone, --units rec2.csv:tau4=-1, when
the other recordings read right), and in validation.json's "opposite_sign"; so is, by the
same rule, a recording with columns recorded reversed (a motor mounted the other way:
--units q6=-1,tau6=-1, in "reversed_columns"), and one whose motor the links barely load
reads with the opposite sign to the other recordings' or to the model's own friction
(--units b.csv:tau5=-1). Through a
drive that logs currents, torque constants off by a factor per motor are named where a gain
per motor fitted with the model's columns explains the residual and predicts the log's
held-out time blocks better, as identify's held-out verdict names them, even beside such a
sign finding (the factors in validation.json's "drive_gains"). With
several recordings, a recording worse than the whole is named. When most of the error
above the noise sits at low speed (standstill, reversals, the edges of a move: where the
velocities' noise and low-pass blur a friction step) the verdict says so, with the error
elsewhere against the noise.

Static data (q, M, g at configurations, as acquire-static writes them: the controller's
M(q) and g(q) the paper identifies from) given to --data are judged as such: the model's
M and g at the file's configurations against the file's, the relative errors of M, g and
both, per joint (g_j and row j of M) against the noise the file records (its
relative_noise, with an identified model's coefficients' own error), and the verdict by
the same rules; validation.json then has schema dynid-static-validation/1 and the figure
is OUT/validation_static.png. One static file a call; the torque logs' options (--cutoff,
--friction, --drive, --columns, ...) are refused there.

Exit status: 0 when the model explains the log (at the noise floor, usable or poor); 1
when it is unusable, its files written all the same (the verdict line says why); 2 an
error (a bad file, another joint count: one line naming the file).

Writes OUT/validation.json {"rms": [...], "mse": [...], "relative_error_percent": x, ...}
(for the full model, plus a "without_friction" block, one entry per recording in
"recordings", the noise floor and the verdict) and the figures
OUT/validation_torques.png and OUT/validation_rms.png (skipped, with a note, without
matplotlib). The log is read strictly: rows with NaN/inf or a repeated timestamp are an
error unless --drop-invalid (or the model's identification dropped them: a note says
so); gaps up to --max-gap (the identification's by default) are bridged, longer ones cut
the log.

Example:
  dynid validate --robot panda --data traj.csv --out out/validation
  dynid validate --model out/identification.json --data static_held.csv --out out/static
  dynid validate --model out/identification.json --data held/ --out out/validation
"""

from __future__ import annotations

import argparse
from pathlib import Path

from ..exceptions import DataError
from ..friction.pooled import joined_validation
from ..identification.model import IdentifiedModel
from ..identification.static_validation import StaticValidation
from ..identification.verdict import FAIR_PERCENT, GOOD_PERCENT, JOINT_FAIR, JOINT_GOOD
from ..io.validation_json import save_static_validation_json, save_validation_json
from ..model.robot import Robot
from ..model.units import unit_said
from ..workflows.validate import ValidateOptions, ValidateResult, validate_files
from ..workflows.validate_static import static_files, validate_static_file
from .applies import Applies, urdf_chain
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
    output_path,
    say_torque_delay,
    shown,
)
from .console import Console
from .figures import save_static_validation_figure, save_validation_figures
from .sources import load_model_source, params_as_robot
from .summaries import format_rms_table

NAME = "validate"
#: ``--out`` is a folder: its files are one output set (:mod:`dynid.outputs.run_output`).
OUTPUT = "folder"
#: Options that apply to one route only (:mod:`dynid.cli.applies`).
APPLIES = (
    urdf_chain(also=("params",)),
    Applies(
        (
            "friction",
            "no_friction",
            "columns",
            "units",
            "cutoff",
            "max_gap",
            "torque_delay",
            "drive",
            "q_start",
        ),
        lambda a: _torque_logs(a),
        "torque logs",
        "static data hold M and g at rest: no motion to filter, no friction, no drive",
    ),  # fmt: skip
)


def _torque_logs(args: argparse.Namespace) -> bool:
    """The route of torque logs: ``--data`` holds no static data (files the readers
    refuse are theirs to name)."""
    try:
        return static_files(args.data) is None
    except (DataError, OSError):
        return True


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
        "--params",
        type=Path,
        help="feasible.json of retrieved link parameters (RNEA); a .urdf, .toml or .xml is "
        "read as --robot reads it",
    )
    p.add_argument("--base", default=None, help="URDF base link (with --robot or --params)")
    p.add_argument("--tip", default=None, help="URDF tip link (with --robot or --params)")
    add_snap_angles_option(p)
    fr = p.add_mutually_exclusive_group()
    fr.add_argument("--friction", type=Path, help="friction.json to add to the model")
    fr.add_argument("--no-friction", action="store_true", help="ignore the model's own friction")
    add_recordings_option(p)
    add_column_options(p)
    p.add_argument("--out", type=output_path, required=True, help="output directory")
    p.add_argument(
        "--cutoff",
        type=cutoff_type,
        default=None,
        metavar="HZ",
        help="low-pass cutoff of the states [Hz] (default: the one --model was identified "
        "with, else the one identification reads from the log's motion)" + CUTOFF_NONE_HELP,
    )
    add_drive_option(p)
    add_q_start_option(p)
    add_log_options(p, torque_delay="recorded")
    p.add_argument("--no-figures", action="store_true", help="skip the PNG figures")
    return p


def run(args: argparse.Namespace, console: Console) -> int:
    """Validate, write validation.json and the figures, print the RMS table (unless -q)."""
    args = params_as_robot(args)  # a URDF, TOML or MJCF --params: as --robot reads it
    model, label = load_model_source(args)
    robot = model.robot if isinstance(model, IdentifiedModel) else model
    static = static_files(args.data)
    if static is not None:
        return _run_static(args, console, model, label, static)
    options = ValidateOptions(
        friction=args.friction or ("none" if args.no_friction else "own"),
        columns=(args.columns, args.units),
        drop_invalid=args.drop_invalid,
        cutoff_hz=args.cutoff,
        max_gap_s=args.max_gap,
        torque_delay_s=args.torque_delay,
        drive=load_drive_arg(args, robot.n, robot_rotors=not isinstance(model, IdentifiedModel)),
        q_start=args.q_start,
    )
    result = validate_files(
        model, args.data, options, feasible=args.params, label=label, source=args.model
    )
    path = save_validation_json(
        args.out / "validation.json", result.validation, robot=robot, **result.metadata()
    )
    if not args.no_figures:
        _save_figures(args.out, result, list(robot.joint_names), label)
    print_validation(console, result, robot, path)
    return 1 if result.verdict.unusable else 0


def _run_static(
    args: argparse.Namespace,
    console: Console,
    model: IdentifiedModel | Robot,
    label: str,
    path: Path,
) -> int:
    """Static data: the model's M and g at the file's configurations, validation.json
    (schema ``dynid-static-validation/1``), the figure and the table."""
    robot = model.robot if isinstance(model, IdentifiedModel) else model
    result = validate_static_file(model, path, drop_invalid=args.drop_invalid)
    out = save_static_validation_json(
        args.out / "validation.json", result, robot=robot, model=label, data=path.name
    )
    if not args.no_figures:
        title = shown(f"{label} on {path.name}")
        save_static_validation_figure(args.out, result, names=list(robot.joint_names), title=title)
    print_static_validation(console, result, robot, path.name, out)
    return 1 if result.verdict.unusable else 0


def print_static_validation(
    console: Console, result: StaticValidation, robot: Robot, name: str, path: Path
) -> None:
    """The table per joint (g and M errors, the noise floor when known), the errors of M
    and g, the verdict."""
    cols = {
        f"RMS g [{unit_said(robot, 'N m')}]": result.g_rms,
        "RMS M row [kg m^2]": result.m_rms,
        "relative [%]": result.joint_percent,
    }
    if result.joint_floor_percent is not None:
        cols["noise floor [%]"] = result.joint_floor_percent
    floor = result.floor_percent
    console.print(
        format_rms_table(list(robot.joint_names), cols),
        f"{name}: {result.n_configurations} static configurations; relative error of M "
        f"{result.m_error_percent:.3g} %, of g {result.g_error_percent:.3g} %"
        + (
            f"; noise floor {floor:.3g} %"
            if floor
            else f"; the data record no noise: judged on the relative thresholds (below "
            f"{GOOD_PERCENT:g} % good, {FAIR_PERCENT:g} % usable; per joint {JOINT_GOOD:g} "
            f"and {JOINT_FAIR:g} %)"
        ),
        f"relative error {result.relative_error_percent:.3g} %; wrote {path}",
        f"verdict: {result.verdict}",
    )


def _save_figures(out: Path, result: ValidateResult, names: list[str], label: str) -> None:
    """The validation figures, titled with the model and the files: of one recording its
    longest piece; of several, every recording's pieces, each recording from its own
    start, one after another, named (the errors over all)."""
    val = result.validation
    if len(result.files) == 1:
        save_validation_figures(
            out, val.shown, names=names, title=shown(f"{label} on {result.files[0]}"),
            t0=val.shown_start,
        )  # fmt: skip
        return
    spans = []
    for k, name in enumerate(result.files):
        mine = [v.log.t for v, r in zip(val.parts, val.pieces.recording, strict=True) if r == k]
        if mine:
            spans.append((name, float(min(t[0] for t in mine)), float(max(t[-1] for t in mine))))
    save_validation_figures(
        out, joined_validation(val.parts), names=names, recordings=spans,
        title=shown(f"{label} on {len(result.files)} recordings (errors over all)"),
    )  # fmt: skip


def print_validation(console: Console, result: ValidateResult, robot: Robot, path: Path) -> None:
    """The RMS table (in ``robot``'s units per joint kind), the pieces, the error per
    recording and overall, the verdict."""
    val, names = result.validation, list(robot.joint_names)
    unit = unit_said(robot, "N m")
    cols = {f"RMS no {val.added} [{unit}]": val.without_friction.rms}
    if val.with_friction is not None:
        cols[f"RMS + {val.added} [{unit}]"] = val.with_friction.rms
    console.print(format_rms_table(names, cols), val.pieces.describe())
    say_torque_delay(console, result.applied_delay)
    if len(val.recordings) > 1:
        console.print(
            *(
                f"  {r.file}: relative error {r.errors.relative_error_percent:.3g} %"
                for r in val.recordings
            )
        )
    console.print(f"relative error {val.errors.relative_error_percent:.3g} %; wrote {path}")
    v = result.verdict
    console.print(f"verdict: {v.label}: {v.reason}")
    checked = None if result.gains is None else result.gains.constants_words()
    if checked is not None:  # a current log's: which torque constants the data check
        console.print(checked)
