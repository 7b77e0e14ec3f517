"""Detect contacts and collisions with the identified model: the momentum observer.

The generalized-momentum residual of De Luca et al. estimates the external joint torques
from the measured q, dq and tau, without accelerations: r = K_O (p - p_0 - integral of
(tau - tau_f + C^T dq - g + r)), p = M(q) dq, a first-order lag K_O / (s + K_O) of the
true external torque on an exact model. The model is an identification.json (--model: its
base parameters, rotor inertias, drive and friction) or a robot (--params: a
feasible.json with its drive and friction, a URDF, or a TOML robot with its [drive]
table); --drive gives the drive of a robot without one (as validate takes it; another
drive than the model's or the feasible.json's is refused); --friction replaces the
friction (a friction.json of `dynid friction`, with its standstill band). A model that
holds no friction (identified from static data, a URDF without <dynamics friction>)
leaves the arm's friction in the residual, where it reads as an external torque: a note
says how much the logs' residual at speed holds per joint (RMS [N m] of a Coulomb and
viscous fit while the joint moves; none above its noise: nothing to do) and the
`dynid friction` command that identifies it for --friction; a note also names
the friction a URDF brings of its own (<dynamics damping friction>) when no --friction
is given, and a sharp Coulomb law without a standstill band (or with one well inside the
velocity noise), which is observed with the noise band as its band.

Two steps:
  --calibrate on collision-free logs writes OUT/thresholds.json: per joint, the largest
  |r| of the logs (--quantile) times --margin for contact and --collision-factor times
  that for collision; with an identified model's covariance the thresholds also grow with
  the model's uncertainty (k sigma + noise, sigma the covariance of the base parameters
  propagated through the momentum regressor; --no-uncertainty turns it off). Inside a
  friction law's standstill band the model's Coulomb term is off while the true friction
  of a slow reversal lies anywhere within its Coulomb level: that level, through the
  observer's lag, is left out of the calibration and added to the thresholds (the
  standstill margin; --no-standstill-margin turns it off). --gain,
  --discretisation and --rule choose the observer, which the thresholds keep. A log
  whose torques have the opposite sign to the model's on some joint (the residual there
  twice the torque) is refused, naming the file and the joints; so, by the rule identify
  refuses by, is a log with columns recorded reversed (a motor mounted the other way,
  --units q6=-1,tau6=-1) and, among several --calibrate logs (collision-free), one whose
  motor the links barely load reads with the opposite sign to the others' (--units
  b.csv:tau5=-1).
  thresholds.json records the model's files and a SHA-256 of their content: detecting with
  another model warns; and the calibration logs' sample rate: detecting on a log sampled
  more than 20 % away from it warns (the velocities' noise in the residual, and the
  thresholds, change with the rate; calibrate at the log's rate), and so does a log whose
  velocities are derived from its positions where the calibration's were measured, or the
  reverse, or any log where the calibration held both kinds (one set of thresholds for
  both is set by the noisier kind: calibrating on both warns, naming each log's kind and
  the cost; calibrate per kind, on logs of the kind the detection will see). A log
  without velocity columns has them derived from its positions (a zero-phase low-pass at
  20 Hz, then differences), at a quarter of its rate when it is sampled at 40 Hz or less
  (a note says so; calibrate and detect at the same rate).
  Whether the observer is
  good enough is printed below the table, kept in thresholds.json's calibration and put
  first in the report: the false alarms the thresholds raise on the calibration logs (the
  events --thresholds would find there, and per minute) and the smallest external torque
  detected per joint while it moves (the largest contact threshold along the motion; at
  rest: its column), and how well the model predicts the calibration logs' torques, judged
  as `dynid validate` judges it (relative error against the noise floor, validate's
  verdict): a model above the floor makes the thresholds wider, and the line says so;
  calibration logs the model was fitted on (an identification.json's recordings, or those
  of the one beside a --params feasible.json) are counted there as in-sample.
  --thresholds thresholds.json on any logs writes OUT/events.json (dynid-events/1: start
  and end [s], joints (1-based) and joint_names, peak [N m] per joint and level, contact
  or collision, and the log of every event), OUT/residuals.csv (t, r1..rn and, with
  --frame, the external wrench at that frame by damped least squares, the least-norm
  one where fewer than 6 joints move the frame, NaN where the residual is; --wrench force:
  the force of a point contact at the frame's origin instead, the moment taken as zero,
  which 3 joints or more determine whole, as on a 5-joint arm; the summary, the table's
  units line and events.json say which) and
  OUT/residuals.png (residuals, thresholds, events, and the true tau_ext that `dynid
  simulate --contact` writes beside a log; the summary then gives the RMS of the residual
  against it per joint, and the score below), and prints the largest |r| of each log and
  the events with the time they cover (seconds and % of the logs' duration;
  events.json's flagged_s and duration_s per log): fewer events can cover more time.
  Its first line says how far to trust them (events.json's trust, the report's
  headline): good, fair or poor from the residual outside the events and labelled
  contacts (the 95th percentile of max_j |r_j| / contact_j there) against the
  calibration's own level and false alarms per minute (thresholds.json's
  calibration.residual_level, false_alarms), the time the events cover and, with
  labels, the false alarms counted per minute: a residual well over the calibration's
  is a model that misfits this log, and its events may be false alarms.
A residual off contacts that follows the weight of a load at the flange the model lacks
(a fit of its mass and centre of mass explaining more than a quarter of the residual under
the threshold and reaching 15 % of some joint's threshold) gets a note with the mass and
the way out: dynid payload on collision-free logs with the load, or identify again.
A long event (1 s or more) that a weight at the flange explains is read as a load carried
(or a steady push along gravity: the joint torques cannot tell them apart): its event
keeps the level load and is scored as any event, and detection runs again without its
torque for the contacts on top; --no-loads reads no event as a load.
A log with labelled contacts is scored: a 0/1 column (nonzero in contact; NaN none) named
collision, contact or label (the first the log has), or mapped with --columns label=NAME,
else the true tau_ext that `dynid simulate --contact` writes beside a log, or the columns
--columns tau_ext=NAME{i0} maps (in contact where some joint's |tau_ext| exceeds 0.1 N m):
whatever is mapped is taken as the truth, so a robot's own estimate (libfranka's
tau_ext_hat_filtered) scores the observer against that estimate's errors. A contact is
detected when an event starts from --label-tolerance (0.1 s) before a label column's
contact (labels made by hand are late or early by tens of ms; from tau_ext, the true
start: 0.02 s or 3 samples) to --label-tolerance (0.1 s, the observer's lag) after its end
(an event still open over a later contact detects only the one it started in); an event
that detects no contact is a false alarm (one starting long before any contact, such as a
whole-log event: the contacts it covers are missed), marked so in events.json
(false_alarm) and the report's events table; several false alarms that each start shortly
before a missed contact and run into it get a note: the labels look shifted by about that
much. The summary prints per log and in total the contacts labelled, detected and missed
(each missed one with its times and, from tau_ext, its peak true torque, and why where it
can be read: the joint stood still and its torque is below its at-rest threshold, or below
its moving one), the false alarms and their rate per minute of contact-free time, and the
delays (event start less contact start, median and max; with velocities derived from the
positions, the zero-phase low-pass sees ahead, and the delays, shorter than an online
observer's, say so); events.json holds them under score; residuals.png hatches the
labelled contacts. A log without labels is not scored. One contact is one event: runs over
the threshold closer than --merge (0.2 s) are joined (a push near the threshold on a joint
at rest crosses it again and again as the standstill margin follows the velocity noise),
and an event shorter than --min-duration (0.01 s) that stays at the contact level is
dropped (the velocity noise crosses for a few samples). A crossing shorter than
--min-duration with no other within half of --merge is dropped before runs are joined: it
neither starts nor extends an event. --merge 0 --min-duration 0: every run over the
threshold. The crossings dropped are not contacts but are said: the summary counts them
and names those furthest over the threshold (time, joint, peak, |r|/contact, duration
against --min-duration, the rule), and events.json holds them under dropped. A torque
sample off both neighbours by more than 20 times the noise while the joint moves (a
one-sample spike, a sensor or logging fault, as identify finds them) is replaced by the
line between its neighbours before the observer runs, calibrating or detecting, with a
warning naming the file, the joints, the counts and the times: never an event. Several
logs (or a folder of them): residuals_<name>.csv and .png each, one events.json; logs of
one name in different folders are named by their folder. With --thresholds the
calibration's options (--gain, --discretisation, --rule, --margin, --quantile,
--collision-factor, --k-sigma, --no-uncertainty, --no-standstill-margin) are refused: the
file fixes them; --frame, --wrench, --merge, --min-duration and --label-tolerance apply to
detection only. A model identified with --torque-delay prepares the logs with that delay
(their states read that much earlier): the summary, thresholds.json's calibration and
events.json ("torque_delay_used") and the report's options say the delay and whether it
was given or the model's; --torque-delay 0 observes without it.

Examples:
  dynid observe --model id/identification.json --data free.csv --calibrate --out cal
  dynid observe --model id/identification.json --thresholds cal/thresholds.json \\
      --data hit.csv --out obs
"""

from __future__ import annotations

import argparse
import shlex
from pathlib import Path
from typing import Any

from ..identification.torque_delay import applied_delay
from ..observer.events import DEFAULT_MERGE_S, DEFAULT_MIN_DURATION_S
from ..observer.residual import DEFAULT_GAIN
from ..observer.results import NO_FRICTION
from ..observer.scoring import DEFAULT_TOLERANCE_S
from ..observer.wrench import WRENCH_KINDS
from ..workflows.observe import ObserveOptions, observe_files
from .common import (
    add_column_options,
    add_drive_option,
    add_drop_invalid,
    add_q_start_option,
    add_snap_angles_option,
    add_subcommand,
    add_torque_delay,
    nonnegative_type,
    output_path,
    parse_vector,
    positive_type,
    say_torque_delay,
)
from .console import Console
from .figures import save_observer_figures
from .summaries import format_observation

NAME = "observe"
#: Samples drawn per curve of a detection's figure (every k-th of a long log).
FIGURE_POINTS = 20000
#: ``--out`` is a folder: its files are one output set (:mod:`dynid.outputs.run_output`).
OUTPUT = "folder"


#: Help of the observer's options of discretisation (:mod:`dynid.observer.residual`).
_GAIN = "the observer's gain per sample: exact, 1 - exp(-K T) (default), or euler, K T"
_RULE = "a sample step's integral: the mean of its ends (trapezoid, default) or its new value"
_MARGIN = "calibration: the contact threshold's factor over the largest |r| (default 1.5)"


def register(subparsers: argparse._SubParsersAction) -> argparse.ArgumentParser:
    """Add the ``observe`` subcommand."""
    p = add_subcommand(
        subparsers, NAME, __doc__, help="detect contacts with a momentum observer on the model"
    )
    src = p.add_mutually_exclusive_group(required=True)
    src.add_argument("--model", type=Path, help="identification.json of an identified model")
    src.add_argument("--params", help="a robot: feasible.json, a .urdf or .toml, or a name")
    p.add_argument("--base", help="--params URDF: base link of the chain (default: the root)")
    p.add_argument("--tip", help="--params URDF: tip link of the chain (default: the only leaf)")
    add_snap_angles_option(p, "--params")
    p.add_argument("--friction", type=Path, help="friction.json replacing the model's friction")
    add_drive_option(p)
    add_q_start_option(p)
    p.add_argument(
        "--data",
        type=Path,
        nargs="+",
        action="extend",
        required=True,
        help="torque log(s) or folder(s)",
    )
    mode = p.add_mutually_exclusive_group(required=True)
    mode.add_argument(
        "--calibrate", action="store_true", help="thresholds from collision-free logs"
    )
    mode.add_argument("--thresholds", type=Path, help="thresholds.json of --calibrate")
    p.add_argument("--frame", help="also estimate the external wrench at this frame")
    p.add_argument(
        "--wrench",
        choices=tuple(WRENCH_KINDS),
        default="full",
        help="what --frame estimates: full, the wrench (force and moment; the least-norm one "
        "where fewer than 6 joints move the frame), or force, the force of a point contact "
        "at the frame's origin (moment zero: 3 unknowns, which 3 joints or more determine; "
        "a moment there reads as a wrong force) (default full)",
    )
    p.add_argument(
        "--gain",
        default=str(DEFAULT_GAIN),
        help=(
            f"K_O [1/s], one or per joint (default {DEFAULT_GAIN:g}): a larger gain shortens "
            "the lag, but the velocities' noise enters the residual times the gain and the "
            "calibrated thresholds grow with it, so it is not always sooner; calibrate at "
            "two gains and compare the thresholds"
        ),
    )
    p.add_argument("--discretisation", choices=("exact", "euler"), default="exact", help=_GAIN)
    p.add_argument("--rule", choices=("trapezoid", "rectangle"), default="trapezoid", help=_RULE)
    p.add_argument("--margin", type=positive_type, default=1.5, help=_MARGIN)
    p.add_argument("--quantile", type=positive_type, default=1.0, help="of |r| (default 1: max)")
    p.add_argument("--collision-factor", type=positive_type, default=2.0, help="(default 2)")
    p.add_argument("--k-sigma", type=positive_type, default=3.0, help="uncertainty k (3)")
    p.add_argument("--no-uncertainty", action="store_true", help="fixed thresholds only")
    p.add_argument(
        "--no-standstill-margin",
        action="store_true",
        help="calibrating: no margin for the friction inside the standstill band",
    )
    p.add_argument(
        "--merge",
        type=nonnegative_type,
        default=DEFAULT_MERGE_S,
        metavar="SECONDS",
        help=f"join runs over the threshold closer than this (default {DEFAULT_MERGE_S:g} s)",
    )
    p.add_argument(
        "--min-duration",
        type=nonnegative_type,
        default=DEFAULT_MIN_DURATION_S,
        metavar="SECONDS",
        help="drop contact-level events shorter than this, and crossings shorter than it "
        f"with no other within --merge / 2 (default {DEFAULT_MIN_DURATION_S:g} s; 0 with "
        "--merge 0: every run over the threshold); those dropped are counted and named "
        "(events.json's dropped), not called contacts",
    )
    p.add_argument(
        "--label-tolerance",
        type=nonnegative_type,
        default=DEFAULT_TOLERANCE_S,
        metavar="SECONDS",
        help="logs with labelled contacts (a label column, or the true tau_ext of a "
        "simulated log): an event starting up to this long after a contact's end still "
        f"detects it, the observer's lag (default {DEFAULT_TOLERANCE_S:g} s), and, of a "
        "label column (made by hand, off either way), up to this long before its start "
        "(from tau_ext: 0.02 s or 3 samples); contacts closer than this are one, which "
        "one event detects",
    )
    add_column_options(p)
    add_drop_invalid(p)
    p.add_argument(
        "--max-gap",
        type=positive_type,
        default=None,
        metavar="SECONDS",
        help="longest step the observer integrates over [s], rows dropped by "
        "--drop-invalid included (bridged as identify bridges them); the log is cut at "
        "longer ones and the observer starts again (default: the --model's identification's, "
        "else 2.5 median steps, at least 0.02 s)",
    )
    add_torque_delay(p, recorded=True)
    p.add_argument(
        "--no-loads",
        action="store_true",
        help="detecting: read no event as a load carried at the flange (a weight and a "
        "steady push along gravity look alike to the joint torques)",
    )
    p.add_argument("--no-figures", action="store_true", help="skip the PNG figures")
    p.add_argument("--out", type=output_path, required=True, help="output directory")
    return p


def run(args: argparse.Namespace, console: Console) -> int:
    """Calibrate or detect, print the thresholds and events, save the files."""
    from ..io.observer_files import ResidualTables, save_observation

    gain = parse_vector(args.gain, "--gain")
    opts = ObserveOptions(
        data=tuple(args.data), model=args.model, params=args.params, friction=args.friction,
        drive=args.drive,
        calibrate=args.calibrate, thresholds=args.thresholds, frame=args.frame,
        wrench=args.wrench,
        gain=float(gain[0]) if gain.size == 1 else tuple(gain), discretisation=args.discretisation,
        rule=args.rule, margin=args.margin, quantile=args.quantile,
        collision_factor=args.collision_factor, k_sigma=args.k_sigma,
        uncertainty=not args.no_uncertainty, standstill=not args.no_standstill_margin,
        merge_s=args.merge, min_duration_s=args.min_duration,
        columns=(args.columns, args.units), drop_invalid=args.drop_invalid,
        max_gap=args.max_gap, base=args.base, tip=args.tip, snap_angles=args.snap_angles,
        q_start=args.q_start, torque_delay_s=args.torque_delay,
        # the series serve the figures only: a calibration's whole, a detection's strided
        keep_series=args.calibrate and not args.no_figures,
        figure_points=None if args.no_figures else FIGURE_POINTS,
        label_tolerance_s=args.label_tolerance, loads=not args.no_loads,
    )  # fmt: skip
    tables = ResidualTables(args.out)  # written a block at a time while detecting
    result = observe_files(opts, tables)
    names = list(result.model.robot.joint_names)
    console.print(format_observation(result, names, calibrating=args.calibrate))
    applied = applied_delay(args.torque_delay, result.model.torque_delay_s)
    say_torque_delay(console, applied)
    for note in result.notes:
        asks = note.startswith(NO_FRICTION) and note.endswith("--friction")
        console.note(note + (_friction_recipe(args) if asks else ""))
    meta: dict[str, Any] = {"model": str(args.model or args.params), "source": result.model.source}
    if applied is not None:  # the delay the logs were prepared with, and its source
        meta["torque_delay_used"] = applied.as_dict()
    saved = save_observation(
        args.out, result, joints=names, calibrating=args.calibrate, meta=meta, residuals=False
    )
    for path in saved + tables.written:
        console.wrote(path)
    if not args.no_figures:
        save_observer_figures(args.out, result, names=names)
    return 0


def _friction_recipe(args: argparse.Namespace) -> str:
    """The command line that identifies this model's friction, after a note on a model
    without friction that asks for it: the robot and the logs as this run read them (the
    URDF chain's --base, --tip and --snap-angles, the drive, the column map, the log
    options and the torque delay given), so that it runs as printed."""
    if args.model is None and str(args.params).endswith(".json"):
        return ""  # a feasible.json: its friction comes from identify, with the links
    words = ["dynid", "friction"]
    if args.model is not None:
        words += ["--model", str(args.model)]
    else:  # --base, --tip and --snap-angles read the URDF of --robot
        words += ["--robot", str(args.params)]
        words += [
            x for f in ("base", "tip") if getattr(args, f) for x in (f"--{f}", getattr(args, f))
        ]
        words += ["--snap-angles"] if args.snap_angles else []
    given = {
        "--drive": args.drive,
        "--columns": args.columns,
        "--units": args.units,
        "--q-start": None if args.q_start is None else ",".join(f"{v:g}" for v in args.q_start),
        "--max-gap": None if args.max_gap is None else f"{args.max_gap:g}",
        "--torque-delay": None if args.torque_delay is None else f"{1e3 * args.torque_delay:g}",
    }
    words += [x for flag, v in given.items() if v is not None for x in (flag, str(v))]
    words += ["--drop-invalid"] if args.drop_invalid else []
    words += ["--data", *(str(d) for d in args.data), "--out", "fr"]
    return f" ({shlex.join(words)}; then --friction fr/friction.json)"
