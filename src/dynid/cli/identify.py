"""Identify the dynamic coefficients (base parameters) from a data file.

Static data (a CSV or NPZ of q, M(q), g(q) at rest, as written by `dynid acquire-static`):
the stacked static regressor [tril M; g] (Gaz et al. 2019, Sec. IV-A, eq. 20) is solved by
least squares; rows without information (g1 of the Panda) are dropped and reported.
With --max-std-percent, coefficients above that relative standard deviation are removed
and the rest re-fitted (the paper used 30).

Torque logs (a CSV with a `t` column, or an NPZ with `t` and `tau`, as written by
`dynid simulate`) go to the classical route: zero-phase filtering, accelerations by
differentiation (a `ddq` column set, when the log has one, is used instead and only
filtered), the torque regressor in the base parameters plus the model's terms, and the
same least squares and statistics. Several recordings are given as several files (or a
folder): each recording, and each piece of one cut at a gap longer than --max-gap, is
filtered, differentiated and decimated on its own and never joined to another; one
cut-off serves all. Continuous joints recorded wrapped into [-pi, pi] are unwrapped.
A log without velocity columns gets its velocities from the positions at that cut-off.

Model structure. Beside the links' base parameters a torque log may need an armature (I_a
ddq per joint; with a drive file, the rotor inertias at the motors), viscous and Coulomb
friction (sign(dq) off inside each joint's velocity noise band, or a smooth tanh(dq/w) at
seven widths w from 0.3 to 300 bands, the narrowest about the velocity noise, then chosen
per joint, the best single width refined between its grid neighbours on the held-out
error), a Stribeck bump exp(-(dq/vst)^2) at seven Stribeck velocities from 0.02 to 0.2
rad/s (on the banded sign or on the narrowest smooth one; the chosen velocity then refined
between its grid neighbours on the same held-out error, a few fits more; a bump fitted
below zero, static friction under Coulomb, is skipped: marked x), and torque
offsets, each
identified with the links. By default every combination is fitted and judged on data it
was not fitted to (one recording left out at a time when there are several, else --folds
contiguous time blocks, or --validate-on), with every joint's torques in units of its own
noise, and the simplest within one standard error of the lowest held-out error (of the
difference, paired over the folds) is kept, never without a coefficient the fit
determines to 20 % (an armature above zero to 33 %, 3 std: a wrist
armature whose torque the held-out error hardly sees, named under the choice). The
summary prints the table of candidates
(each smooth or Stribeck law at its best shape) and the choice, and the terms'
coefficients per joint; identification.json records them all. --terms fixes the structure
by hand (e.g. --terms armature,viscous,coulomb,offset). Through a --drive that logs
currents, when the chosen structure's held-out error or the error its gains leave is over
2 x the noise, its gains name a factor, or a rotor inertia is negative, the torque
constants are judged with the richest structure (armature, viscous, coulomb, offset): the
factors the held-out data confirm correct the currents for a second search, whose model,
fitted to the corrected currents, is the one kept (identification.json's drive holds the
corrected constants), and the verdict names the factors (a note in the summary says why);
with --consistent the consistent fit is of that model, fitted to the corrected currents too
(feasible.json's drive holds the corrected constants; a note names the factors). A rotor
inertia fitted below zero is a warning naming the joint and its likely cause. Of several
recordings, one whose held-out error is far above the others' (a payload or contacts the
model lacks) is named in a warning and left out of the structure's choice and of the
final fit (--keep-outlying fits it).

Gravity vector. The robot's gravity vector is the description's (--gravity sets it).
A base mounted off level by a few tenths of a degree, or a description whose base frame is
not aligned with gravity, loads the joints with gravity torques the fit takes into its
terms (a Panda tilted 0.3 deg about x: joint 3's offset +0.021 N m for a true +0.1, 0.81 %
held out for a 0.35 % noise floor). Torque logs: where the held-out verdict names such a
tilt, the identification is made again with the gravity vector the data read as (again
while a tilt is still named, at most 3 times), and the model held out better is kept: its
robot in identification.json holds that gravity (validate, observe and export of the file
use it), the metadata hold gravity_fitted, and a note in the summary gives the angles, both
held-out errors and the --gravity to identify with it from the start (the Panda above: 0.30
deg about x, 0.37 % held out, the offsets and rotor inertias within 3 std of the truth). A
level arm is identified once, as before.

Checks that the data belong to --robot: a static data file that records another robot
(name, joint count or kinematics) is an error; configurations outside the joint limits,
and a relative error far above the recorded noise level (noise-free data must fit to
rounding), are reported as one-line warnings with the numbers. On exact data the
residual and the standard deviations are 0 (said in the summary), never NaN.

Torque logs are read strictly: rows with NaN/inf or a repeated timestamp are an error
unless --drop-invalid; gaps up to --max-gap are bridged. Accelerations: a log with a
complete ddq1..ddqn set (or a `ddq` array in an NPZ, or `--columns ddq=...`) has them
used as given, low-pass filtered at the cut-off with the other signals; without one they
are the derivative of the filtered velocities (an incomplete set is an error). A log exact
to round-off (a noise-free simulation: every column's noise, read from its differences up
to order 10, at most 1e-12 of its RMS) is fitted unfiltered at every sample, nothing
trimmed or decimated, its accelerations as logged or differentiated from its velocities
to order 8; a note in the summary says so (--cutoff still sets a filter).

Writes DIR/identification.json (coefficients, expressions, std, metrics, kinematics,
identifiability of every standard parameter), from torque logs heldout.json and the
held-out figures (heldout_torques.png, heldout_residuals.png; not with --no-figures),
and report.html, and prints a summary table.

Rank and conditioning. The base parameters come from the robot's kinematics: their number
(the rank) is read from the first clear gap (a factor >= 1e3, below 1e-3 of the largest)
in the singular values of the column-scaled regressor, and the gap is printed. A URDF
whose angles are rounded (rpy="1.5708 0 0") has near-dependencies near 1e-4 that are
treated as dependencies; reading it names the rounded joints in a note (without -v), with
the unscaled condition numbers and the leftovers of the size of the rounding that the
base-parameter expressions then hold (-7.3e-06*mc3y for rpy="3.1416"), and --snap-angles
reads such angles as the multiples of pi/2 (no leftovers). --rtol overrides
this with a fixed relative threshold: singular values (and column norms) at or below RTOL
times the largest count as dependencies; set it above the near-dependencies (1e-4 for
4-digit angles) to drop them, below (1e-10) to keep them, at the price of an
ill-conditioned fit. The summary gives the paper's condition
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
`dynid retrieve --help`): from torque logs (one or more, prepared as above) with the
friction of the structure chosen (viscous and Coulomb >= 0) and the armature when it has
one (rotor inertias >= 0; --terms armature forces it), and the joint springs with
--terms ...,spring (stiffnesses >= 0), or from static data. Writes next
to identification.json (the unconstrained fit) the files of `dynid retrieve`:
feasible.json (links, and the friction and springs identified with them), robot.urdf,
robot.xml (springs as stiffness and springref), robot.toml (a [spring] table),
report.json, retrieval.png; URDF holds no spring and says so. Exit code 1 when no
consistent set satisfies the constraints (the closest one is written and reported).

example:
  dynid identify --robot panda --data static.csv --out result --max-std-percent 30
  dynid identify --robot panda --data log.csv --consistent --prior panda --out result
"""

from __future__ import annotations

import argparse
from pathlib import Path

import numpy as np

from ..exceptions import OptionError
from ..identification.estimators import ESTIMATORS
from ..identification.least_squares import STD_METHODS
from ..identification.selection import fitted_logs
from ..identification.torque_delay import TorqueDelay, applied_delay
from ..identification.verdict import Verdict
from ..io.feasible_bundle import save_feasible_bundle
from ..io.json_files import save_json
from ..io.model_json import save_model_json
from ..workflows.gravity_refit import tilt_rotation
from ..workflows.identify import IdentifyOptions, identify_files
from .applies import urdf_chain
from .common import (
    CUTOFF_NONE_HELP,
    add_column_options,
    add_consistency_options,
    add_drive_option,
    add_log_options,
    add_q_start_option,
    add_robot_options,
    add_subcommand,
    cutoff_type,
    load_drive_arg,
    load_robot,
    number,
    numbers_type,
    options_from,
    output_path,
    parse_mass_band,
    positive_type,
    say_torque_delay,
)
from .console import Console
from .figures import save_heldout_figures, save_retrieval_figure
from .summaries import format_consistent, format_identification

NAME = "identify"
#: ``--out`` is a folder: its files are one output set (:mod:`dynid.outputs.run_output`).
OUTPUT = "folder"
#: Options that apply to one route only (:mod:`dynid.cli.applies`).
APPLIES = (urdf_chain(), urdf_chain("prior", ("prior_base", "prior_tip")))


def register(subparsers: argparse._SubParsersAction) -> argparse.ArgumentParser:
    """Add the ``identify`` subcommand."""
    p = add_subcommand(
        subparsers,
        NAME,
        __doc__,
        help="identify the base parameters from static data (or a torque log)",
    )
    _add_robot_options(p)
    add_drive_option(p)
    add_q_start_option(p)
    p.add_argument(
        "--data",
        type=Path,
        nargs="+",
        action="extend",
        required=True,
        metavar="FILE",
        help="data: one static data file, or one or more torque logs (a folder: its .csv and "
        ".npz files), .csv or .npz",
    )
    p.add_argument(
        "--terms",
        default=None,
        metavar="TERMS",
        help="torque logs: the model's terms beside the links, comma-separated from armature, "
        "spring, viscous, quadratic, coulomb, smooth[:W], stribeck[:V], offset, "
        "at:motor|at:joint|at:both, -LABEL ('links' for none; W the smooth Coulomb's width in "
        "standstill bands (default 1), or one per joint as W1/W2/..., V the Stribeck velocity "
        "[rad/s] (default 0.05; without W or V the held-out data do not choose them); "
        "at: where a coupled drive's friction acts, both: at the motors and at the joints no "
        "motor turns alone; -fo3 leaves joint 3's offset out, -fc5 joint 5's Coulomb "
        "friction, -Ia2 joint 2's armature; spring: a stiffness per joint, with offset); "
        "default: chosen on held-out data (see Model structure above)",
    )
    add_column_options(p)
    p.add_argument("--out", type=output_path, required=True, help="output folder")
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
    add_log_options(p, drop_invalid=False, torque_delay="given", recorded=False)
    p.add_argument(
        "--std",
        choices=STD_METHODS,
        default=None,
        help="standard deviations: hac (consistent for residuals correlated over the filtered, "
        "decimated samples of each recording piece), robust (heteroscedasticity-consistent) "
        "or classical (sigma^2 (W^T W)^-1, Gaz et al.) (default: robust for static data, "
        "hac for torque logs; honoured on both, and with --consistent for its unconstrained fit)",
    )
    p.add_argument(
        "--estimator",
        choices=[*ESTIMATORS, "auto"],
        default="auto",
        help="least squares: ordinary, weighted by each joint's (static: each row's) "
        "noise level from a first fit, or Huber-reweighted against outlying rows after "
        "filtering (one-sample torque spikes are replaced before filtering, whatever the "
        "estimator, with a warning); auto (default): of torque logs, ols or wls chosen for "
        "the chosen structure on its held-out folds, each joint in units of its own noise "
        "(ols kept within one standard error), of static data ols",
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
    p.add_argument(
        "--no-figures",
        action="store_true",
        help="skip the figures (held-out torques of a log; --consistent: retrieval.png); "
        "heldout.json, data, is written all the same",
    )
    p.add_argument(
        "--cutoff",
        type=cutoff_type,
        default=None,
        metavar="HZ",
        help="torque logs: zero-phase low-pass cutoff [Hz] (default: 10 x the motion's highest "
        "significant frequency, read from the log; decimation keeps at least 10 %% of the "
        "samples; none for a log exact to round-off)" + CUTOFF_NONE_HELP,
    )
    _add_heldout_options(p)
    return p


def _add_heldout_options(p: argparse.ArgumentParser) -> None:
    """The held-out judgement's options: time blocks, a separate log, outlying recordings."""
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
    p.add_argument(
        "--keep-outlying",
        action="store_true",
        help="several recordings: fit those found outlying too (default: a recording whose "
        "held-out error is far above the others', a payload or contacts the model lacks, is "
        "left out of the structure's choice and of the final fit, and named in a warning); "
        "static data: fit the configurations whose residual, predicted by the fit of the "
        "others, stands far above the others' (a wrong q; default: left out, named with "
        "their lines in a warning)",
    )


def run(args: argparse.Namespace, console: Console) -> int:
    """Identify, write identification.json (and, with --consistent, the retrieve files),
    print the summary; 0, or 1 when no consistent set satisfies the constraints."""
    robot = load_robot(args)
    if args.gravity is not None:
        given = robot.with_gravity(gravity_vector(args.gravity))
        ax, ay, _ = np.degrees(tilt_rotation(robot.gravity, given.gravity))
        console.note(
            "gravity given (--gravity): ["
            + ", ".join(f"{x:.6g}" for x in given.gravity)
            + f"] m/s^2 in the base frame, the description's tilted {ax:.2f} deg about x "
            f"and {ay:.2f} deg about y"
        )
        robot = given
    options = options_from(
        args,
        IdentifyOptions,
        columns=(args.columns, args.units),
        drive=load_drive_arg(args, robot.n),
        total_mass=parse_mass_band(args.total_mass),
    )
    result = identify_files(robot, args.data, options)
    files = [save_model_json(args.out / "identification.json", result.model)]
    held = result.heldout
    text = [format_identification(result.model, verdict_below=held is not None)]
    if held is not None:  # every sample of the figures' data, not the decimated rows
        doc = held.as_dict()
        files.append(save_json(args.out / "heldout.json", doc, schema="dynid-heldout-torques/1"))
        recs = fitted_logs(result.model, result.model.info.recordings)
        fitted = [Path(str(r.get("file", ""))).name for r in recs]
        files += [] if args.no_figures else save_heldout_figures(args.out, held, fitted)
        v = held.verdict
        text += _delay_first(result.torque_delay, v)
        text.append(f"held-out verdict on {held.block}, every sample: {v.label}: {v.reason}")
        checked = None if held.gains is None else held.gains.constants_words()
        text += [] if checked is None else [checked]  # a current log's: what the data check
    elif result.torque_delay is not None and result.torque_delay.named:
        text.append(f"note: {result.torque_delay.sentence()}")
    if result.consistent is not None:
        # every recording fitted, not the first alone; none left out as outlying
        sources = [str(p) for p in fitted_logs(result.model, args.data)]
        info = result.model.info  # how its data were read, the scales they leave unknown
        files += save_feasible_bundle(
            args.out,
            result.consistent,
            column_map=info.column_map,
            unknown_scale=info.extra.get("unknown_scale"),
            sources=sources,
        )
        files += [] if args.no_figures else save_retrieval_figure(args.out, result.consistent)
        text += ["", format_consistent(result.consistent)]
    console.print(*text)
    say_torque_delay(console, applied_delay(args.torque_delay, 0.0))
    console.wrote(*files)
    return 1 if result.consistent is not None and not result.consistent.feasible else 0


def _add_robot_options(p: argparse.ArgumentParser) -> None:
    """``--robot`` and its chain options, and ``--gravity GX,GY,GZ``: the robot's gravity
    vector (:func:`gravity_vector`)."""
    add_robot_options(p)
    p.add_argument(
        "--gravity",
        type=numbers_type,
        default=None,
        metavar="GX,GY,GZ",
        help="the robot's gravity vector [m/s^2] in its base frame (default: the description's; "
        "(0,0,-9.80665) for panda, fr3 and a URDF): for a base mounted off level, e.g. the "
        "vector the note 'gravity vector fitted' of an earlier identification printed (see "
        "Gravity vector above)",
    )


def gravity_vector(values: tuple[float, ...]) -> tuple[float, ...]:
    """``--gravity``'s three numbers [m/s^2], else a one-line error."""
    if len(values) != 3:
        raise OptionError(
            f"takes the gravity vector's three components gx,gy,gz [m/s^2]; got {len(values)}",
            field="gravity",
        )
    return values


def _delay_first(delay: TorqueDelay | None, verdict: Verdict) -> list[str]:
    """The note of a named torque delay, said before the held-out verdict whose hints
    (what the residual follows, friction at low speed, a spring) it may explain: the
    lag's residual follows the joints' velocities and accelerations."""
    if delay is None or not delay.named:
        return []
    may = " (it may explain the verdict's hints below)" if verdict.level != "good" else ""
    return [f"note: {delay.sentence()}{may}"]
