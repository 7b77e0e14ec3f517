"""Identify a load (tool, gripper) on the arm: mass, CoM and inertia, with uncertainty.

The arm's model is known: --robot (built-in or a description with its parameters),
--model identification.json (identified) or --params feasible.json (feasible). --data is
recorded with the load: static data (q, M, g; --gravity-only uses g alone and gives the
mass and CoM only) or torque logs (friction is estimated alongside: the classical
viscous, Coulomb and offset per joint, or, when that leaves more than 3 x the torque
noise, the friction law identify chooses on held-out data from the same recordings (a
smooth Coulomb, a Stribeck bump), or the one --terms names; several
recordings, or a folder of them: each recording, and each piece of one cut at a gap
longer than --max-gap, is filtered on its own and never joined to another; --model's
recorded cut-off and decimation are reused unless --cutoff is given). The arm's torques
are its model's whole prediction: an identified model's armature (or rotor inertias) and
friction, a robot's drive (--drive, or the [drive] table of a --robot TOML) and friction,
a feasible.json's drive and friction. With --unloaded DATA0 ... (the same kind of data
without the load) the arm is identified from DATA0 first (difference method), with the
structure identify chooses (or --model's); it cancels the arm's model errors when DATA0
repeats the loaded motion (the recordings --model was identified from give the model
itself, which a note says). Without --unloaded, recordings --model was identified from
(the same samples, whatever the files are called) are refused: that model already holds
the load. The estimate is physically consistent (pseudo-inertia LMI). --columns/--units
read files of other tools.

A mass less than 3 standard deviations above zero, a CoM farther from --frame than the
arm is long, or (--robot, --params) measured torques more than 5 % and 3 standard
deviations off the arm description's (a torque constant or gear ratio off: the factor is
fitted beside the load, or on the --unloaded data, and the load's mass divided by it is
said), or a fit of torque logs that leaves more than 3 x the torque noise after the
low-pass (torques the arm's model does not explain, a spring, friction or a tilt, which
go into the mass and CoM too; their standard deviations then raised to the largest
change a torque as large as the misfit makes) is warned about and no setLoad values are
written. With --unloaded logs of the same motion the residual judged is the difference
of the loaded fit's and the unloaded arm's at matched states, against the noise of both:
an arm's misfit common to both recordings cancels, a load that moved or another load
does not (the residual judged and its ratio are printed). An inertia whose
moments lie less than 3 standard deviations above zero, or whose products have a
standard deviation above a third of their largest possible magnitude, or that the
consistency constraint set on its bound, is not determined: warned about (naming the
elements and what to record), and setLoad's
load_inertia is not written. Standard deviations from torque logs are widened to the
estimate's spread over 10 held-out time blocks where that is larger (errors of the arm's
model that vary along the motion).

Writes DIR/payload.json (mass, com [m] in --frame, inertia about the CoM, their std, the
torques' scale against the description, the preprocessing used, and libfranka's setLoad
values load_mass, F_x_Cload, load_inertia) and the arm carrying the load, for the other
commands: with --robot or --params DIR/robot_with_payload.toml (what `dynid export`
writes of the arm, as TOML: its links, the load added to the link of --frame, its
friction and drive); with --model DIR/model_with_payload.json (an identification.json:
its base parameters with the load's, its friction, rotor inertias and offsets; base
parameters are combinations of the links' parameters, which no robot description holds,
so no TOML is written). The standard deviations in it are the arm's.

example:
  dynid payload --robot panda --data static_with_gripper.csv --out payload
"""

from __future__ import annotations

import argparse
from pathlib import Path
from typing import Any

from ..exceptions import DataError
from ..feasibility.payload import PayloadEstimate
from ..feasibility.payload_scale import (
    SCALE_OFF,
    SCALE_SIGMAS,
    TorqueScale,
    known_mass_scale,
    scale_mass,
    unjudged_ratio,
)
from ..identification.model import IdentifiedModel
from ..identification.verdict import FLOOR_FAIR
from ..io.model_json import save_model_json
from ..io.payload_json import save_payload_json
from ..model.inertia import INERTIA_ORDER, inertia6_from_matrix
from ..model.robot import Robot
from ..model.units import unit_said
from ..workflows.export import ExportRobotOptions, save_export
from ..workflows.payload import PayloadFileResult, identify_payload_files
from .applies import is_urdf, urdf_chain
from .common import (
    CUTOFF_NONE_HELP,
    add_column_options,
    add_drive_option,
    add_log_options,
    add_q_start_option,
    add_snap_angles_option,
    add_subcommand,
    cutoff_type,
    load_drive_arg,
    output_path,
)
from .console import Console
from .sources import load_model_source, params_as_robot

NAME = "payload"
#: ``--out`` is a folder: its files are one output set (:mod:`dynid.outputs.run_output`).
OUTPUT = "folder"
#: Options that apply to one route only (:mod:`dynid.cli.applies`).
APPLIES = (urdf_chain(also=("params",)),)
#: The arm carrying the load: a robot's (what ``dynid export`` writes of it, as TOML), an
#: identified model's (its base parameters with the load's).
ROBOT_WITH_LOAD = "robot_with_payload.toml"
MODEL_WITH_LOAD = "model_with_payload.json"


def register(subparsers: argparse._SubParsersAction) -> argparse.ArgumentParser:
    """Add the ``payload`` subcommand."""
    p = add_subcommand(
        subparsers, NAME, __doc__, help="identify a load's mass, CoM and inertia on a known arm"
    )
    src = p.add_mutually_exclusive_group(required=True)
    src.add_argument("--robot", help="'panda', 'fr3', a .urdf or a .toml with the arm's parameters")
    src.add_argument("--model", type=Path, help="identification.json of the arm")
    src.add_argument(
        "--params",
        type=Path,
        help="feasible.json of the arm (a .urdf, .toml or .xml: read as --robot reads it)",
    )
    p.add_argument("--base", default=None, help="URDF base link (with --robot or --params)")
    p.add_argument("--tip", default=None, help="URDF tip link (with --robot or --params)")
    add_snap_angles_option(p)
    p.add_argument(
        "--data",
        type=Path,
        nargs="+",
        action="extend",
        required=True,
        help="data with the load (.csv/.npz): static data (one file) or torque logs (one "
        "or more, or a folder of them)",
    )
    p.add_argument(
        "--unloaded",
        type=Path,
        nargs="+",
        action="extend",
        default=None,
        help="the same kind of data without the load (difference method): one static data "
        "file, or torque logs (one or more, or a folder of them)",
    )
    add_column_options(p)
    p.add_argument("--frame", default="flange", help="frame the load is fixed to")
    p.add_argument("--gravity-only", action="store_true", help="static data: use g alone")
    p.add_argument(
        "--cutoff",
        type=cutoff_type,
        default=None,
        metavar="HZ",
        help="torque logs: low-pass [Hz] (default: the one --model was identified with, and "
        "its decimation, else the one identification reads from the logs' motion; static "
        "data are not filtered)" + CUTOFF_NONE_HELP,
    )
    p.add_argument(
        "--terms",
        default=None,
        metavar="TERMS",
        help="torque logs: the friction estimated beside the load, as identify's --terms "
        "names it (its friction parts: viscous, quadratic, coulomb, smooth[:W], "
        "stribeck[:V], offset; an offset per joint always); default: auto, the classical "
        "viscous,coulomb,offset, or, when that leaves more than 3 x the torque noise, the "
        "friction identify chooses on held-out data from the same recordings if it leaves "
        "less",
    )
    p.add_argument(
        "--known-mass",
        type=float,
        default=None,
        metavar="KG",
        help="the load's true mass [kg], when known: the identified mass over it is the "
        "torques' scale (a drive's torque constants off by that factor in common), printed "
        "and written to payload.json (known_mass)",
    )
    add_drive_option(p)
    add_q_start_option(p)
    add_log_options(p)
    p.add_argument(
        "--no-figures",
        action="store_true",
        help="accepted as every command with an output folder accepts it; payload writes "
        "no figures",
    )
    p.add_argument("--out", type=output_path, required=True, help="output folder")
    return p


def run(args: argparse.Namespace, console: Console) -> int:
    """Identify, write payload.json and the arm's model with the load, print a summary."""
    args = params_as_robot(args)  # a URDF, TOML or MJCF --params: as --robot reads it
    arm, label = load_model_source(args)
    kin = arm.robot if isinstance(arm, IdentifiedModel) else arm
    drive = load_drive_arg(args, kin.n)
    result = identify_payload_files(arm, args.data, **_options(args, kin.n, drive))
    if isinstance(arm, IdentifiedModel):
        loaded = save_model_json(args.out / MODEL_WITH_LOAD, result.model_with_load(arm))
    else:
        spec = args.robot if args.robot is not None else args.params
        chain = dict(base=args.base, tip=args.tip, snap_angles=args.snap_angles)
        plan = result.export_with_load(
            spec,
            args.out / ROBOT_WITH_LOAD,
            ExportRobotOptions(format="toml", drive=drive, **(chain if is_urdf(spec) else {})),
        )
        loaded = save_export(args.out / ROBOT_WITH_LOAD, plan)
    known = args.known_mass
    if known is not None and not known > 0:
        raise DataError(f"--known-mass must be above 0 kg, got {known:g}")
    path = save_payload_json(
        args.out / "payload.json", result.estimate, kin, with_tool=loaded.name, known_mass=known
    )
    print_payload(console, result, label, kin, known_mass=known)
    if isinstance(arm, IdentifiedModel):
        console.print(
            f"note: {args.model.name} holds base parameters (combinations of the links' "
            f"parameters), which no robot description holds: the model carrying the load is "
            f"{loaded.name} (with its friction, rotor inertias and offsets; validate and "
            "observe read it as --model), no robot_with_payload.toml"
        )
    console.print(f"wrote {path} and {loaded}")
    return 0


def _options(args: argparse.Namespace, n: int, drive: Any) -> dict[str, Any]:
    """The keyword arguments of :func:`~dynid.workflows.payload.identify_payload_files`."""
    return dict(
        unloaded=args.unloaded,
        frame=args.frame,
        gravity_only=args.gravity_only,
        columns=(args.columns, args.units),
        drop_invalid=args.drop_invalid,
        cutoff_hz=args.cutoff,
        max_gap_s=args.max_gap,
        drive=drive,
        feasible=args.params,
        q_start=args.q_start,
        terms=args.terms,
    )


def print_payload(
    console: Console,
    result: PayloadFileResult,
    label: str,
    robot: Robot | None = None,
    *,
    known_mass: float | None = None,
) -> None:
    """The estimate (mass, CoM, inertia with their std), the recordings, the preprocessing,
    the notes and whether setLoad values were written (the torques' units per joint kind
    of ``robot``); ``known_mass`` [kg]: the load's true mass, the torques' scale it reads
    (:func:`known_mass_line`)."""
    est = result.estimate
    console.print(f"payload on frame {est.frame!r} ({est.route}; arm: {label})")
    doubt = "  in doubt" if est.doubts else ""
    console.print(f"  mass     {est.mass:.6g} kg  (std {est.std_mass:.2g}){doubt}")
    com = ", ".join(f"{x:+.5f}" for x in est.com)
    std = ", ".join(f"{x:.2g}" for x in est.std_com)
    console.print(f"  com      [{com}] m  (std [{std}]){doubt}")
    if est.inertia_identified:
        for name, v, s in zip(
            INERTIA_ORDER, inertia6_from_matrix(est.inertia), est.std_inertia, strict=True
        ):
            flag = "  not determined" if f"I{name}" in est.undetermined else ""
            console.print(f"  I{name}      {v:+.4e} kg m^2  (std {s:.2g}){flag}")
    unit = unit_said(robot, "N m")
    console.print(f"  {residual_line(est, unit)}")
    if (judged := judged_line(est, unit)) is not None:
        console.print(f"  {judged}")
    if est.torque_scale is not None:
        console.print(f"  {scale_line(est.torque_scale, est.mass, est.floor_rms)}")
    elif est.scale_unchecked:
        console.print(
            f"  torques  not checked against the arm description's: {est.scale_unchecked}"
        )
    if known_mass is not None:
        console.print(f"  {known_mass_line(est, known_mass)}")
    if result.recordings:
        console.print(result.describe())
    prep = est.preprocessing
    if prep:
        source = {"given": "given", "model": "the model's", "motion": "read from the motion"}
        cut = prep["cutoff_hz"]
        console.print(
            f"preprocessing: cut-off {'none' if cut is None else f'{cut:.4g} Hz'} "
            f"({source.get(prep['cutoff_source'], prep['cutoff_source'])}), "
            f"decimation {prep['decimate']}"
            + (
                f", torque delay {1e3 * lag:g} ms (the model's)"
                if (lag := prep.get("torque_delay_s"))
                else ""
            )
        )
    for note in est.notes:
        console.print(f"note: {note}")
    if est.doubts:
        console.print("not a load to trust: no setLoad values written (see the warnings)")
    elif est.inertia_identified and not est.inertia_determined:
        console.print(
            f"inertia not determined ({', '.join(est.undetermined)}): setLoad's mass and CoM "
            "written, its inertia not (see the warnings)"
        )


def scale_line(t: TorqueScale, mass: float, noise_rms: float | None = None) -> str:
    """``torques  1.0471 x the arm description's (std 0.0013, on the data without the
    load): 4.7 % off 1 (clear of it by 36 std), within the 5 % the check accepts; the
    load's mass carries it: at the description's scale the load is m / a = 2.462 kg (std
    0.017)``, or ``within 3 std of 1: no sign of a scale`` (:attr:`PayloadEstimate.
    torque_scale`, :func:`~dynid.feasibility.payload_scale.scale_mass`; ``mass``: the
    load's estimate [kg], :meth:`TorqueScale.off`: beyond what the check accepts, a doubt
    of its own); with a fit that leaves more than 3 x the torque noise ``noise_rms`` [N m],
    the factor not judged (:func:`~dynid.feasibility.payload_scale.unjudged_ratio`)."""
    where = "the data without the load" if t.data == "unloaded" else "the loaded data"
    head = f"torques  {t.value:.4f} x the arm description's (std {t.std:.2g}, on {where})"
    if (ratio := unjudged_ratio(t, noise_rms)) is not None:
        return (
            f"{head}: not judged, the fit with the factor leaves {ratio:.3g} x the torque "
            "noise: the arm's description lacks torques of these data (a spring, friction, "
            "inertials off), which the factor takes in, so it says nothing of the sensors' "
            "scale; hint: judge it with an arm identified from these recordings (--model)"
        )
    at = f"at the description's scale the load is {scale_mass(t)}"
    d = abs(t.value - 1.0)
    if not d > SCALE_SIGMAS * t.std:
        return f"{head}: within {SCALE_SIGMAS:g} std of 1, no sign of a scale; {at}"
    off = f"{100 * d:.2g} % off 1 (clear of it by {d / t.std:.3g} std)" if t.std > 0 else ""
    if t.off(mass):
        return f"{head}: {off or f'{100 * d:.2g} % off 1'}, a doubt (the warning); {at}"
    return (
        f"{head}: {off}, within the {100 * SCALE_OFF:g} % the check accepts; the load's mass "
        f"carries it (scaled by about as much): {at}"
    )


def known_mass_line(est: PayloadEstimate, known: float) -> str:
    """``known    2.5 kg: the torques read 1.0318 x it (std 0.0076): 3.2 % off 1, the
    drive's torque constants off by about that in common`` (:func:`~dynid.feasibility.
    payload_scale.known_mass_scale`; ``known`` [kg])."""
    a, std = known_mass_scale(est.mass, est.std_mass, known)
    d = abs(a - 1.0)
    clear = (
        f"clear of 1 by {d / std:.3g} std"
        if std > 0 and d > SCALE_SIGMAS * std
        else f"within {SCALE_SIGMAS:g} std of 1"
    )
    if not (std > 0 and d > SCALE_SIGMAS * std):  # the known mass confirms the scale
        return (
            f"known    {known:.6g} kg: the torques read {a:.4f} x it (std {std:.2g}; "
            f"{100 * d:.2g} % off 1, {clear}): the torque constants and gear ratios agree with "
            "it in common over the joints the load loads"
        )
    return (
        f"known    {known:.6g} kg: the torques read {a:.4f} x it (std {std:.2g}; {100 * d:.2g} % "
        f"off 1, {clear}): a torque constant or gear ratio off by about that in common over "
        "the joints the load loads"
    )


def residual_line(est: PayloadEstimate, unit: str = "N m") -> str:
    """``residual RMS 0.0067 N m, 1.5 x the torque noise (0.0044 N m after the low-pass)``
    for torque logs, with the states' noise through the arm's model when known (``1.29 x
    the noise (the torques' 0.0073 N m after the low-pass and the states' through the
    arm's model 0.06 N m)``, the ratio the fit's judged one,
    :mod:`~dynid.feasibility.payload_floor`; over
    :data:`~dynid.identification.verdict.FLOOR_FAIR` x, what it means:
    :func:`~dynid.feasibility.payload_doubts.misfit_doubts`); the static rows' residual
    without a unit of its own; ``unit``: the torques' (``N m (rail: N)`` on an arm with a
    prismatic joint, :func:`~dynid.model.units.unit_said`)."""
    if not est.noise_rms:  # static data, or no noise read from the logs
        mixed = est.route.startswith("static M")
        said = " (rows of M [kg m^2] and g [N m])" if mixed else f" {unit}"
        return f"residual RMS {est.residual_rms:.2g}{said}"
    j = est.judged
    fit = j is None or j.kind == "fit"
    ratio = est.residual_rms / est.noise_rms
    noise = f"the torque noise ({est.noise_rms:.2g} {unit} after the low-pass)"
    if j is not None and j.states_rms is not None and fit and j.ratio is not None:
        ratio = j.ratio
        noise += f" and the states' noise through the arm's model ({j.states_rms:.2g} {unit})"
    return f"residual RMS {est.residual_rms:.2g} {unit}, {ratio:.3g} x {noise}" + (
        f": over {FLOOR_FAIR:g} x, torques the arm's model leaves, which the load took"
        if ratio > FLOOR_FAIR and fit
        else ""
    )


def judged_line(est: PayloadEstimate, unit: str = "N m") -> str | None:
    """``judged   the difference from the unloaded arm's residual at matched states (100 %
    of the samples): 0.012 N m, 1.16 x the noise of both recordings (0.01 N m); within 3 x:
    the arm's misfit is common to both, not the load's``: the residual the load's doubt
    was judged on and its ratio (:attr:`PayloadEstimate.judged`,
    :mod:`~dynid.feasibility.payload_difference`); None when not judged (static data, or
    the torque noise not known); ``unit`` as :func:`residual_line`'s."""
    j = est.judged
    if j is None or (ratio := j.ratio) is None:
        return None
    over = ratio > FLOOR_FAIR
    if j.kind == "fit":
        what = "the fit's residual"
        if j.matched or est.route.endswith("difference"):
            what += f" (the motions do not match: {100 * j.matched:.0f} % of the samples)"
        noise = "" if j.states_rms is None else " and the states' through the arm's model"
        return f"judged   {what}: {ratio:.3g} x the torque noise{noise}; " + (
            f"over {FLOOR_FAIR:g} x: the load in doubt" if over else f"within {FLOOR_FAIR:g} x"
        )
    return (
        "judged   the difference from the unloaded arm's residual at matched states "
        f"({100 * j.matched:.0f} % of the samples): {j.residual_rms:.2g} {unit}, {ratio:.3g} x "
        f"the noise of both recordings ({j.noise_rms:.2g} {unit}"
        + ("" if j.states_rms is None else f", the states' {j.states_rms:.2g} {unit}")
        + "); "
        + (
            f"over {FLOOR_FAIR:g} x: the load does not explain what changed between them"
            if over
            else f"within {FLOOR_FAIR:g} x: the arm's misfit is common to both, not the load's"
        )
    )
