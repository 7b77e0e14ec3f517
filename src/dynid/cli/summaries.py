"""The tables and summaries the commands print (text only: printing is the console's)."""

from __future__ import annotations

import sys
from collections.abc import Mapping, Sequence
from typing import Any

import numpy as np
from numpy.typing import NDArray

from ..feasibility.constraints import principal_moments
from ..feasibility.convex import ConsistentResult
from ..feasibility.determined import PRIOR, PRIOR_MARK, SUM
from ..feasibility.heldout import HeldOutJudgement
from ..feasibility.penalty import RetrievalProgress, RetrievalResult
from ..feasibility.prior_share import PRIOR_SHARE
from ..feasibility.result import FeasibleResult
from ..friction.fit import FrictionFit
from ..friction.model import friction_parts
from ..friction.validation import NewtonEulerValidation
from ..identification.dissipation import SIGNIFICANCE, negative_viscous
from ..identification.info import IdentificationInfo, LogInfo
from ..identification.log import jitter_text
from ..identification.model import IdentifiedModel
from ..identification.outlying_spans import cut_text
from ..identification.pieces import gaps_text
from ..identification.structural import mixed_sign
from ..identification.structure import JOINT_PREFIX, MIN_WIDTH, joint_side_joints, own_rotors
from ..identification.vs_description import description_comparison
from ..io.observer_files import log_labels
from ..model.robot import Robot
from ..model.units import JointKinds, joint_unit, unit_said, values_said
from ..observer.calibration_check import CalibrationCheck
from ..observer.detection import undetected_at_rest
from ..observer.friction import standstill_margin
from ..observer.gain_noise import GainNoise
from ..observer.missed_reason import reason_words
from ..observer.rest_margin import rest_margin_lines
from ..observer.results import (
    LogObservation,
    ObserveResult,
    beyond_lines,
    dropped_words,
    flagged_words,
)
from ..observer.scoring import score_words
from ..observer.wrench import estimate_words
from ..pipeline.collision import CollisionStageResult
from ..regressors.base import identifiability
from ..regressors.terms import LinearFriction
from .structure_table import estimator_lines, per_recording_lines, selection_lines, text_width

__all__ = [
    "format_consistent",
    "format_identification",
    "format_newton_euler_rms",
    "format_retrieval",
    "format_friction_rms",
    "format_rms_table",
    "heldout_line",
    "heldout_table",
    "term_lines",
    "progress_printer",
]


def _fitted_rows(info: IdentificationInfo) -> str:
    """What the least-squares rows hold: the low-passed, decimated torques of a filtered
    log (not the torques as measured that the training and held-out errors predict), or
    the rows as given."""
    if info.log is not None and info.log.cutoff_hz is not None:
        return f"torques low-passed at {info.log.cutoff_hz:.3g} Hz"
    return "rows"


def format_identification(
    model: IdentifiedModel, *, width: int = 60, verdict_below: bool = False
) -> str:
    """A readable summary: metrics (and, where a current log's torque constants were judged
    before the structure search, why), then one line per coefficient (expressions shortened).
    ``verdict_below``: a held-out verdict is printed after it, the one ratio to the noise
    floor the summary gives (:func:`heldout_line`)."""
    fit, info = model.fit, model.info
    if info.static is not None:
        data = f"{info.static.n_configurations} configurations"
    elif info.log is not None:
        data = samples_text(info.log, _decimations(info.recordings), info.recordings)
    else:
        data = "? samples"
    head = [
        f"{info.route or '?'} identification of {model.robot.name}: {data}"
        + f", {fit.n_rows} rows"
        + (f", dropped rows {', '.join(info.dropped_rows)}" if info.dropped_rows else ""),
        f"{columns_text(model)}, condition number {fit.condition_number:.4g} (unscaled, as the "
        f"paper), scaled {fit.scaled_condition_number:.4g}, residual "
        f"{fit.relative_error_percent:.4g} % of the {_fitted_rows(info)} fitted, estimator "
        f"{info.estimator}, "
        f"std {info.std or '?'}"
        + (
            f", pruned {len(info.pruned)} above {info.max_std_percent:g} %"
            if info.pruned and info.max_std_percent is not None
            else ""
        ),
    ]
    if fit.residual_rms == 0.0 or not np.any(fit.std[fit.kept]):
        head.append("the residual is zero to rounding (exact data): standard deviations are 0")
    ho = info.heldout
    if ho:
        effort = "torque" if model.drive is None else model.drive.effort
        filtered = info.log is not None and info.log.cutoff_hz is not None
        head.append(heldout_line(dict(ho), effort, verdict_below=verdict_below, filtered=filtered))
    if model.base.gap is not None:
        hi, lo = model.base.gap
        head.append(
            f"the {model.base.rank} base parameters: rank cut between singular values {hi:.3g} "
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
    head += recordings_lines(info.recordings)
    head += per_recording_lines(info.extra, given=True)  # a structure given (--terms)
    first = info.extra.get("gains_first")  # why the torque constants were judged first:
    head += [f"note: {first}"] if isinstance(first, str) else []  # before the table it explains
    unknown = info.extra.get("unknown_scale")  # the motors whose constants the data leave unknown
    head += [f"note: {unknown['finding']}"] if isinstance(unknown, dict) else []
    gravity = info.extra.get("gravity_fitted")  # the gravity vector a tilted base reads
    head += [f"note: {gravity['note']}"] if isinstance(gravity, dict) and "note" in gravity else []
    offsets = info.extra.get("recording_offsets")  # one torque offset per recording
    head += [f"note: {offsets['note']}"] if isinstance(offsets, dict) and "note" in offsets else []
    head += selection_lines(info.selection)
    head += estimator_lines(info.estimator_choice)
    return "\n".join(head + _base_table(model, width) + term_lines(model))


def _base_table(model: IdentifiedModel, width: int) -> list[str]:
    """The base parameters' table: value, std %, kept and expression (cut at ``width``);
    where the description holds inertials, its value of each and ``z`` (the difference in
    standard deviations, :mod:`~dynid.identification.vs_description`), with the one line
    that sums them up below the table."""
    fit, base = model.fit, model.base
    vs = description_comparison(model)
    lw = text_width("name", base.labels[: base.rank], 7)
    described = f" {'description':>13} {'z':>7}" if vs is not None else ""
    rows = [f"{'#':>3}  {'name':<{lw}} {'value':>13} {'std %':>9}{described}  kept  expression"]
    for k in range(base.rank):
        e = base.expressions[k]
        e = e if len(e) <= width else e[: width - 3] + "..."
        pct = fit.std_percent[k]
        cells = ""
        if vs is not None:
            d, z = float(vs.values[k]), float(vs.z[k])
            cells = (
                f" {'-' if not np.isfinite(d) else f'{d:+.6g}':>13}"
                f" {'-' if not np.isfinite(z) else f'{z:+.1f}':>7}"
            )
        rows.append(
            f"{k + 1:>3}  {base.labels[k]:<{lw}} {fit.beta[k]:>+13.6g} "
            f"{'-' if not np.isfinite(pct) else f'{pct:.3g}':>9}{cells}  "
            f"{'yes' if fit.kept[k] else 'no':<4}  {e}"
        )
    return rows + ([] if vs is None else [vs.sentence()])


def term_lines(model: IdentifiedModel) -> list[str]:
    """The terms identified with the links (friction, armature), one table each: a row per
    joint (motor, where the term acts at the motors), a column per coefficient, each
    value with its standard deviation in %; ``in beta1`` where the coefficient is
    regrouped into a base parameter (a rotor with a link's inertia: ``beta1 = J1zz + ... +
    Ia1``), ``-`` where left out, ``combined`` where it holds a coefficient left out as
    structurally combined with it (named below the table with what it holds)."""
    out: list[str] = []
    for name, t in model.terms.items():
        if not t.labels:
            continue
        stems = list(dict.fromkeys(lab.rstrip("0123456789") for lab in t.labels))
        cells: dict[tuple[str, int], str] = {}
        units: dict[str, str] = {}
        holders = model.regrouped_in(name)
        for k, lab in enumerate(t.labels):
            stem = lab.rstrip("0123456789")
            units[stem] = t.term.units[k] if k < len(t.term.units) else ""
            cells[(stem, int(lab[len(stem) :]))] = _coefficient(
                float(t.values[k]), float(t.std[k]), bool(t.kept[k]), holders[k]
            ) + (f" {COMBINED}" if lab in model.info.combined and t.kept[k] else "")
        drive = getattr(t.term, "drive", None)
        row = "motor" if drive is not None and drive.friction_place == "motor" else "joint"
        n = getattr(drive, "n", None) or max(j for _, j in cells)
        scales = _velocity_scales(t.term, n)
        for stem, values in scales.items():
            stems.append(stem)
            units[stem] = "rad/s"
            cells |= {(stem, j + 1): f"{float(x):.3g}" for j, x in enumerate(values)}
        kinds = model.robot if row == "joint" else None  # a motor turns: rad
        heads = [
            f"{stem} [{unit_said(kinds, units[stem])}]" if units[stem] else stem for stem in stems
        ]
        widths = [
            max(len(h), *(len(cells.get((stem, j), "-")) for j in range(1, n + 1)))
            for h, stem in zip(heads, stems, strict=True)
        ]
        alone = _motors_hold(t.term, model)
        out.append(f"{name} identified with the links (value, std %; - left out):")
        titles = [f"{h:<{w}}" for h, w in zip(heads, widths, strict=True)]
        out.append(f"  {row:<5}  " + "  ".join(titles).rstrip())
        for j in range(1, n + 1):
            cols = [
                f"{cells.get((stem, j), MOTORS if j in alone and stem not in scales else '-'):<{w}}"
                for stem, w in zip(stems, widths, strict=True)
            ]
            out.append(f"  {j:<5}  " + "  ".join(cols).rstrip())
        if alone:
            out.append(
                f"  {MOTORS}: a motor turns joint(s) {', '.join(map(str, alone))} alone: "
                "their friction at the joint acts on the motor's columns and is identified "
                "in the motor's (its fc holds fc_motor + fc_joint / gear ratio)"
            )
        held = sorted({h for h in holders if h}, key=lambda h: (len(h), h))
        if held:
            out.append(
                f"  in {'/'.join(held)}: regrouped with link inertias into that base "
                "parameter (listed above); the data give the sum, not this coefficient alone"
            )
        out += _scales_lines(scales, model)
        out += _shape_line(t.term, model)
        out += _rest_line(t, model)
        out += _negative_viscous_line(t, mixed_sign(model.info.combined))
        mine = [lab for lab in t.labels if lab in model.info.combined]
        if mine:
            out.append(
                f"  {COMBINED}: holds a coefficient left out as structurally dependent on it "
                "(no data tell them apart), not its own value alone: "
                + "; ".join(f"{lab} holds {model.info.combined[lab]}" for lab in mine)
            )
    return out


def _rest_line(t: Any, model: IdentifiedModel) -> list[str]:
    """For a spring term: where each determined spring (kept, std under 20 % of k) and the
    joint's torque offset, when the model holds one at the joint (``fo``; ``jfo`` with a
    drive), leave no torque: ``q0 - fo / k`` [rad], ``q0`` the spring's own rest position
    (the joint's mid-range)."""
    stiff = t.stiffness
    if stiff is None:
        return []
    at_joints = "fo" if model.drive is None else f"{JOINT_PREFIX}fo"  # a motor's acts on all
    offsets = {
        lab.removeprefix(JOINT_PREFIX): float(v)
        for other in model.appended
        for lab, v, kept in zip(other.labels, other.values, other.kept, strict=True)
        if kept and lab.rstrip("0123456789") == at_joints
    }
    said = []
    for k, lab in enumerate(t.labels):
        j = int(lab[len(lab.rstrip("0123456789")) :]) - 1
        if not (t.kept[k] and np.isfinite(t.std[k]) and abs(t.std[k]) < 0.2 * abs(t.values[k])):
            continue
        fo = offsets.get(f"fo{j + 1}", 0.0)
        rest = float(stiff.q0[j]) - fo / float(stiff.k[j])
        with_fo = f" - fo{j + 1}/k" if f"fo{j + 1}" in offsets else ""
        said.append(f"joint {j + 1} at {rest:+.4g} rad (q0 {float(stiff.q0[j]):+.4g}{with_fo})")
    if not said:
        return []
    return [
        "  rest position (the spring's torque, with the joint's offset, is zero there): "
        + "; ".join(said)
    ]


def _negative_viscous_line(t: Any, differences: frozenset[str] = frozenset()) -> list[str]:
    """One line naming the viscous coefficients a friction term fitted below zero (not
    dissipative): within one std of zero, indistinguishable from 0; beyond it, the law
    misfits (a negative slope stands in for a shape the law lacks). Those that hold a
    difference of coefficients (``differences``: ``fv6`` holding ``fv6 - fv5``,
    :func:`~dynid.identification.structural.mixed_sign`) are not judged: the "combined"
    line names what they hold."""
    if not isinstance(t.term, LinearFriction):
        return []
    kept = np.asarray(t.kept) & np.array([lab not in differences for lab in t.labels], bool)
    found = negative_viscous(t.labels, np.asarray(t.values), np.asarray(t.std), kept, t.term.prefix)
    if not found:
        return []
    near = [f for f in found if f.indistinguishable]
    far = [f for f in found if not f.indistinguishable]
    said = []
    if far:
        said.append(
            ", ".join(f"{f.label} {f.value:+.4g} ({f.stds:.2g} std from 0)" for f in far)
            + f": each {SIGNIFICANCE:g} std or more below zero, so the friction law "
            "misfits there (a negative slope "
            "stands in for a shape the law lacks, such as friction that levels off at speed; "
            "dynid friction compares other laws)"
        )
    if near:
        said.append(
            ", ".join(f"{f.label} {f.value:+.4g}" for f in near)
            + f": within {SIGNIFICANCE:g} std of zero, indistinguishable from 0"
        )
    return ["  viscous friction below zero (not dissipative): " + "; ".join(said)]


#: The mark of a coefficient that holds a structurally combined one left out.
COMBINED = "combined"


#: A standstill band below this [rad/s] is said to be near 0 under the friction table.
NEAR_ZERO_BAND = 1e-6

#: The cell of a joint's friction at the joint that the motor's friction holds.
MOTORS = "motor's"


def _motors_hold(term: Any, model: IdentifiedModel) -> list[int]:
    """The joints (1-based) whose friction at the joint a motor's friction holds: for the
    friction at the joints beside friction at the motors of a drive, those a motor turns
    alone (:func:`~dynid.identification.structure.joint_side_joints`); none for another
    term (a rotor inertia left out is left out: without a drive no motor holds it)."""
    drive = getattr(term, "drive", None)
    if not isinstance(term, LinearFriction) or drive is None or drive.friction_place != "joint":
        return []
    at_motors = any(
        isinstance(t.term, LinearFriction) and t.term.drive.friction_place == "motor"
        for t in model.appended
    )
    if not at_motors:
        return []
    beside = set(joint_side_joints(drive))
    return [j + 1 for j in range(drive.n) if j not in beside]


def _velocity_scales(term: Any, n: int) -> dict[str, tuple[float, ...]]:
    """A friction term's velocities per joint (motor) [rad/s]: its standstill band and,
    for a smooth Coulomb, its width (none for another term)."""
    out = {}
    for key in ("band", "width"):
        v = getattr(term, key, ())
        if isinstance(v, tuple) and len(v) == n and (key == "band" or "smooth" in term.parts):
            out[key] = v
    return out


def _scales_lines(scales: dict[str, tuple[float, ...]], model: IdentifiedModel) -> list[str]:
    """What the band and the smooth width of the friction table mean."""
    if not scales:
        return []
    out = [
        "  band: the standstill band of the velocities as prepared (5 std of their noise; of "
        "velocities derived from positions, the positions' noise through the derivative filter)"
    ]
    near_zero = [k + 1 for k, b in enumerate(scales.get("band", ())) if 0 <= b < NEAR_ZERO_BAND]
    if near_zero:
        out.append(
            f"  a band near 0 ({', '.join(map(str, near_zero))}): no white noise read there "
            "(exact, or positions quantized to encoder steps, which keep the derived "
            "velocity's sign: no band is needed; docs: validation.md)"
        )
    if "width" in scales:
        given = [str(x) for x in model.info.extra.get("terms", ()) if str(x).startswith("smooth")]
        k = given[0].split(":")[1] if given and ":" in given[0] else "K"
        each = "/" in k  # one width per joint: smooth:K1/K2/..
        out.append(
            f"  width: the smooth Coulomb fc tanh(dq / width), smooth:{k} = "
            + ("K_j x max(band_j, " if each else f"{k} x max(band, ")
            + f"{MIN_WIDTH:g} {unit_said(model.robot, 'rad/s')})"
            + (" per joint j" if each else "")
        )
    return out


def _shape_line(term: Any, model: IdentifiedModel) -> list[str]:
    """What ``fsp`` of the friction table means (a Stribeck part), with its Stribeck
    velocity, and that the stds take the law's shape as given: the velocity and the smooth
    widths are given (``--terms``) or chosen on held-out data from a grid, not fitted with
    the coefficients."""
    parts = getattr(term, "parts", ())
    if "stribeck" not in parts:
        return []
    given = model.info.selection is None  # the structure given (--terms), not chosen
    shape = "the Stribeck velocity" + (" and the widths" if "smooth" in parts else "")
    return [
        f"  fsp: the Stribeck bump fsp exp(-(dq / vst)^2) times the Coulomb part's sign, vst = "
        f"{_vst_text(term.vst)} "
        + ("as given" if given else "chosen on held-out data")
        + f"; the std % hold {shape} fixed at these values (a vst a few % off moves fsp by "
        "more than its std)"
    ]


def _vst_text(vst: float | tuple[float, ...]) -> str:
    """A Stribeck velocity as the summary says it: ``0.1 rad/s``, or one per joint where
    they differ (``0.08/0.08/0.1/... rad/s (per joint)``, joint 1 first)."""
    if isinstance(vst, (int, float)):
        return f"{float(vst):.3g} rad/s"
    return "/".join(f"{float(v):.3g}" for v in vst) + " rad/s (per joint)"


def _coefficient(value: float, std: float, kept: bool, holder: str) -> str:
    """One coefficient of a term's table (:func:`term_lines`); ``holder``: the base
    parameters a regrouped coefficient is in (``beta1``), or ``""``."""
    if not kept:
        return f"in {holder}" if holder else "-"
    if not np.isfinite(std) or not value:
        return f"{value:+.4g}"
    return f"{value:+.4g} ({abs(100.0 * std / value):.2g} %)"


#: How a recording left out of the fit begins its line (:func:`recordings_lines`).
_LEFT_OUT = "left out of the fit (outlying; --keep-outlying fits it): "


def recordings_lines(recordings: Any) -> list[str]:
    """One line per recording when there are several or one was cut into pieces, with
    where each was cut (the time stamp before each gap and its length), each one's rate
    where they differ; a recording left out of the fit as outlying (``left_out``) says
    so."""
    recs = list(recordings or ())
    if len(recs) < 2 and all(r.get("pieces", 1) == 1 for r in recs):
        return []
    each = len(_decimations(recs)) > 1  # recordings at other rates: each its own
    rates = {round(float(r["sample_rate_hz"]), 3) for r in recs if "sample_rate_hz" in r}
    return [
        f"recording {r['file']}: "
        + (_LEFT_OUT if r.get("left_out") else "")
        + f"{r['pieces']} piece(s), {r['samples']} samples "
        + ("prepared " if r.get("left_out") else "used ")
        + f"({r['duration_s']:.4g} s"
        + (f", at {r['sample_rate_hz']:.4g} Hz" if len(rates) > 1 else "")
        + (f", 1 in {r['decimate']}" if each else "")
        + ")"
        + _gaps(r)
        + _lost(r)
        + _jitter(r)
        + _cut_out(r)
        for r in recs
    ]


def _jitter(rec: Any) -> str:
    """``; stamps jittered, std 0.58 ms at a 5 ms period`` of a recording whose record
    holds its stamps' jitter (:func:`~dynid.identification.pieces.timing_record`), else
    empty: of several recordings, the one whose stamps jitter is named."""
    jitter = rec.get("stamp_jitter_s")
    said = jitter_text(jitter, rec.get("period_s", np.nan)) if jitter is not None else None
    return f"; {said}" if said else ""


def _cut_out(rec: Any) -> str:
    """``; t = 4.672 to 5.428 s cut out as a burst (...)``: the intervals cut out of a
    recording's fit (``cut_out``: spans of an outlying recording's residual, or of the
    fit's own), empty for none; the gaps they leave are not said as gaps."""
    cut = rec.get("cut_out") or ()
    if not cut:
        return ""
    n = rec.get("cut_samples")
    return (
        f"; {cut_text(tuple((float(a), float(b)) for a, b in cut))} cut out as a burst the "
        "model does not hold ("
        + (f"{n} recorded samples, " if n else "")
        + "with the filter's edge beside it; --keep-outlying fits it whole)"
    )


def _gaps(rec: Any) -> str:
    """``, cut at the gap(s) after t = 86412.300 s (11.3 s into rec1.csv; 0.4 s long)``
    (empty for a record without gaps): the stamp as in the file, its offset from the
    recording's start when that is not 0."""
    cut = gaps_text(rec.get("gaps") or (), rec.get("start_s"), rec.get("file"))
    return f", {cut}" if cut else ""


def _decimations(recordings: Any) -> tuple[int, ...]:
    """The recordings' decimations, each once, smallest first (a record without them:
    none)."""
    return tuple(sorted({int(r["decimate"]) for r in recordings or () if "decimate" in r}))


#: The causes a recording's samples are not used for, as a recording's record counts them
_LOST = (
    ("trimmed", "trimmed at the pieces' ends (the filter's edge transient)"),
    ("decimated", "between the decimated samples"),
    ("too_short", "in pieces too short to filter"),
    ("isolated", "alone between gaps"),
)


def _lost(rec: Any) -> str:
    """`` of 820 recorded: 274 trimmed at the pieces' ends (...), ...`` (empty when the
    record does not count them), with the points a uniform grid added to resampled
    pieces: at the places of dropped samples, and the rest (either sign) at the grid's
    ends against jittered stamps."""
    if "recorded" not in rec:
        return ""
    parts = [f"{rec[k]} {why}" for k, why in _LOST if rec.get(k)]
    added = rec.get("added", 0)
    dropped = rec.get("dropped", added if added > 0 else 0)  # a record without: as it said
    if dropped:  # the uniform grid of resampled pieces holds the dropped samples' places
        parts.append(
            f"{dropped} added by resampling onto a uniform grid (the places of dropped samples)"
        )
    if rest := added - dropped:  # jittered stamps: the grid's ends fall elsewhere
        parts.append(
            f"{abs(rest)} {'more' if rest > 0 else 'fewer'} on the uniform grid the jittered "
            "stamps were resampled onto (the grid's ends against the stamps'"
            + ("; no sample dropped)" if not dropped else ")")
        )
    return f" of {rec['recorded']} recorded" + (": " + ", ".join(parts) if parts else "")


def samples_text(
    log: LogInfo, decimations: Sequence[int] = (), recordings: Sequence[Any] = ()
) -> str:
    """The samples of a torque log: used and recorded, the filter and decimation that chose
    them (``decimations``: the recordings', when they differ, e.g. at other rates), the
    resampling when the timestamps were not uniform, and the gaps the logs were cut at
    apart from the bursts cut out of them (``recordings``' ``cut_out``, their ``gaps``
    the recordings' own)."""
    cut = log.cutoff_hz
    how = "no low-pass" if cut is None else f"{cut:.3g} Hz low-pass"
    if log.cutoff_source == "motion" and log.motion_frequency_hz:
        how += f" (10 x the motion's {log.motion_frequency_hz:.3g} Hz)"
    k = (
        f"{decimations[0]} to {decimations[-1]}, per recording below,"
        if len(decimations) > 1
        else str(log.decimate)
    )
    every = "every sample" if k == "1" else f"1 in {k}"  # "1 in 1" read as a riddle
    text = (
        f"{log.n_samples_used} samples used ({every} after the {how} and trimming "
        f"of {log.n_samples_log} recorded"
        if cut is not None
        else f"{log.n_samples_used} samples used ({every}, unfiltered, after the trimming "
        f"of {log.n_samples_log} recorded"
    )
    fitted = [r for r in recordings if isinstance(r, Mapping) and not r.get("left_out")]
    if log.resampled:
        # of several recordings each line below says its own stamps' jitter
        pooled = len(recordings) < 2
        jitter = jitter_text(log.stamp_jitter_s, 1.0 / log.sample_rate_hz) if pooled else None
        if jitter is not None:  # steps long by jitter alone are no gaps
            text += f", {jitter}"
        text += ", resampled onto a uniform grid"
        if log.n_gaps:
            dropped = log.n_dropped and not log.n_cuts  # the drops of the gaps bridged
            text += f", {log.n_gaps} gap(s) bridged" + (
                f" ({log.n_dropped} sample(s) dropped)" if dropped else ""
            )
        elif jitter is not None and not log.n_dropped and not log.n_cuts:
            text += ", no sample dropped"
    bursts = sum(len(r.get("cut_out") or ()) for r in fitted)
    gaps = sum(len(r.get("gaps") or ()) for r in fitted) if bursts else log.n_cuts
    if gaps:
        text += f", cut into pieces at {gaps} longer gap(s)"
    if bursts:
        text += f", {bursts} burst(s) cut out"
    return text + ")"


#: How the columns summary names a term's columns that are not friction, by its kind.
_KIND_WORDS = {"rotor_inertia": "rotor inertia", "joint_spring": "spring"}


def columns_text(model: IdentifiedModel) -> str:
    """The base parameters, the appended terms' columns by what they are (friction,
    offsets, rotor inertias) and the rank, counted separately."""
    r = model.base.rank
    k = 0 if model.joint_fit is None else int(np.size(model.joint_fit.beta)) - r
    counts: dict[str, int] = {}
    for t in model.appended:
        for label in t.term.labels:
            what = (
                _KIND_WORDS[t.term.kind]
                if t.term.kind in _KIND_WORDS
                else "offset"
                if label.removeprefix(JOINT_PREFIX).startswith("fo")  # fo1 .. fon, jfo1 ..
                else "friction"
            )
            counts[what] = counts.get(what, 0) + 1
    said = " and ".join(f"{c} {what}" for what, c in counts.items()) or str(k)
    rotors = len(own_rotors(model.base, model.robot.n))
    of_them = f" ({rotors} of them rotor inertias of their own)" if rotors else ""
    cols = f"{r} base parameters{of_them}" + (f" and {said} columns" if k else "")
    return f"columns: {cols}, rank {model.fit.rank} of {r + k}"


def heldout_line(
    ho: dict[str, Any],
    effort: str = "torque",
    *,
    verdict_below: bool = False,
    filtered: bool = True,
) -> str:
    """The training and held-out errors of least squares (``info.heldout``: every fold
    predicted by the fit of the others, pooled; the structure's choice reads them).

    With ``verdict_below`` (the held-out verdict printed after it, ``heldout.json``'s:
    one block, or the separate log, against the floor of the torques' noise and the
    states', each sample against its own noise) the line gives no ratio of its own and
    points to the verdict, the judged figure: beside it, the pooled error over the
    torques' noise alone was a second ratio for the same fit, of another error (every
    fold's) over another floor (the torques' noise alone). Its own floor
    (``noise_floor_percent``, that of identification.json) is given beside it, so that
    each held-out figure stands next to its own floor. Without, how many times the
    noise of the measured torques (``effort="current"``: of the motor currents the
    torques were read from) the held-out error is."""
    measured = "motor currents'" if effort == "current" else "measured torques'"
    how = {
        "file": "on the --validate-on log",
        "recordings": f"leaving out each of {ho.get('folds')} recordings in turn",
    }.get(str(ho.get("scheme")), f"over {ho.get('folds')} contiguous time blocks")
    floor = ho.get("noise_floor_percent")
    own = (  # the figure beside its own floor: no ratio, the verdict below judges
        f", the {measured} noise there {floor:.4g} %" if floor is not None and floor > 0 else ""
    )
    said = (
        f"{own}; the held-out verdict below judges its unfiltered samples against their own floor"
        if verdict_below
        else ""
        if floor is None
        else f"; {ho['heldout_error_percent'] / floor:.3g} x the {measured} noise alone "
        f"({floor:.3g} %)"
        if floor > 0
        else ""
    )
    if verdict_below:  # (logs exact to round-off are fitted as they are: ``filtered`` False)
        how += ", filtered and decimated samples" if filtered else ", every sample unfiltered"
    return (
        f"least squares: training error {ho['training_error_percent']:.4g} %, held-out "
        f"error {ho['heldout_error_percent']:.4g} % ({how}{said})"
        if verdict_below
        else f"least squares: training error {ho['training_error_percent']:.4g} %, held-out "
        f"error {ho['heldout_error_percent']:.4g} % ({how}){said}"
    )


def heldout_table(j: HeldOutJudgement) -> list[str]:
    """Training against held-out errors of least squares and of the consistent fit."""
    how = {
        "file": "the --validate-on log",
        "recordings": f"each of {j.folds} recordings in turn",
    }.get(j.scheme, f"{j.folds} contiguous time blocks")
    verdict = "accepted" if j.accepted else "NOT accepted"
    return [
        f"torque error [%]      {'training':>9}  {'held-out':>9}   (held out: {how})",
        f"least squares         {j.ls_training_percent:>9.4g}  {j.ls_heldout_percent:>9.4g}",
        f"consistent            {j.training_percent:>9.4g}  {j.heldout_percent:>9.4g}",
        f"{verdict}: held-out error {100 * (j.ratio - 1):+.3g} % against least squares "
        f"(tolerance +{100 * j.tolerance:g} %); the training residual does not decide",
    ]


def progress_printer(stream: Any = None, *, header: str | None = None) -> Any:
    """A ``progress`` callback that prints one line per finished run on ``stream`` (stderr),
    after ``header`` (printed with the first run's line)."""
    pending = [header] if header is not None else []

    def show(p: RetrievalProgress) -> None:
        out = sys.stderr if stream is None else stream
        while pending:
            out.write(f"{pending.pop()}\n")
        state = "feasible" if p.feasible else "INFEASIBLE"
        out.write(
            f"  run {p.done:>2}/{p.total} (#{p.run}): cost {p.cost:.3e}, relative residual "
            f"{p.relative_residual:.2e}, {state}  [{p.elapsed:6.1f} s]\n"
        )
        out.flush()

    return show


def _band_margin(r: RetrievalResult) -> float:
    return min(r.report.min_margin("total_mass_min"), r.report.min_margin("total_mass_max"))


def format_retrieval(result: RetrievalResult) -> str:
    """Readable summary: per link mass, CoM, principal moments and triangle margin; totals."""
    r = result
    lam = principal_moments(r.inertia)
    tri = {c.link: c.margin for c in r.report.select("triangle_inequality")}
    names = r.robot.link_names[1:]
    w = text_width("link", names)
    lines = [
        f"{'link':<{w}}  {'mass [kg]':>10}  {'CoM [m]':^29}  "
        f"{'principal moments [kg m^2]':^30}  {'triangle':>9}",
    ]
    mk_m, mk_c = _prior_marks(r)
    for i, name in enumerate(names):
        c = " ".join(f"{x:+.4f}{mk_c[i, k]}" for k, x in enumerate(r.com[i]))
        m = " ".join(f"{x:.3e}" for x in lam[i])
        mass = f"{r.mass[i]:.4f}{mk_m[i]}"
        lines.append(f"{name:<{w}}  {mass:>10}  {c:^29}  {m:^30}  {tri[i + 1]:>9.2e}")
    lines += _prior_mark_line(r, prior=False)
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
        f"{_stage_costs(r.stage_costs)}; {r.run_time:.1f} s on {r.workers} worker(s), "
        f"seed {r.seed}",
    ]
    lines += _determined_lines(r)
    if not r.feasible:
        lines.append(str(r.report))
    return "\n".join(lines)


#: Stage costs printed in full up to this many; more: the first and last three.
_STAGE_COSTS_SHOWN = 8


def _stage_costs(costs: NDArray[np.float64]) -> str:
    """``stage costs a, b, c``; a long schedule as its first and last three and the count
    (every cost is in report.json)."""
    shown = [f"{x:.3g}" for x in costs]
    if len(shown) <= _STAGE_COSTS_SHOWN:
        return f"stage costs {', '.join(shown)}"
    return (
        f"stage costs {', '.join(shown[:3])}, ..., {', '.join(shown[-3:])} ({len(shown)} "
        "stages; all in report.json)"
    )


def consistent_structure_lines(result: ConsistentResult) -> list[str]:
    """Which structure the one-step consistent fit of a torque log uses (the one chosen on
    held-out data, or given, its terms kept physical as each declares) and the held-out
    error of least squares of it."""
    model = result.identified
    if model is None or result.kind != "log":
        return []
    terms = [str(t) for t in model.info.extra.get("terms", ())]
    kept = [t for t in terms if not t.startswith("-")]
    used = " + ".join(["links", *kept]) + "".join(f" - {t[1:]}" for t in terms if t[:1] == "-")
    free = sorted(mixed_sign(model.info.combined))  # a difference: no sign to keep
    out = [
        f"structure of the consistent fit: {used} (its friction law, leave-outs and armature "
        "as fitted by least squares; kept physical: fv, fc, rotor inertias"
        + (", spring stiffnesses" if result.spring is not None else "")
        + " >= 0 and the friction opposing the motion within the velocity limits, the "
        "offset free"
        + (f"; {', '.join(free)} free too, holding a difference (combined)" if free else "")
        + ")"
    ]
    sel = model.info.selection
    if sel:
        held = {c["name"]: c["heldout_error_percent"] for c in sel.get("candidates", ())}
        chosen = str(sel.get("chosen"))
        mine = held.get(used)
        out.append(
            f"structure chosen on held-out data: {chosen}, held-out error "
            f"{held.get(chosen, float('nan')):.4g} %"
            + (
                ""
                if chosen == used or mine is None
                else f"; least squares of the consistent fit's structure: {mine:.4g} %"
            )
            + f" ({sel.get('validation')})"
        )
    return out


def format_consistent(result: ConsistentResult) -> str:
    """Readable summary of a convex retrieval: per link mass, CoM, margin; fit; notes."""
    r = result
    names = r.robot.link_names[1:]
    w = text_width("link", names)
    lines = [
        f"{'link':<{w}}  {'mass [kg]':>10}  {'prior [kg]':>10}  {'CoM [m]':^29}  "
        f"{'lambda_min(J)/tr(J)':>19}",
    ]
    mk_m, mk_c = _prior_marks(r)
    for i, name in enumerate(names):
        c = " ".join(f"{x:+.4f}{mk_c[i, k]}" for k, x in enumerate(r.com[i]))
        mass = f"{r.mass[i]:.4f}{mk_m[i]}"
        lines.append(
            f"{name:<{w}}  {mass:>10}  {r.prior.mass[i]:>10.4f}  {c:^29}  "
            f"{r.pseudo_inertia_margin[i]:>19.3e}"
        )
    lines += _prior_mark_line(r)
    status = "CONSISTENT" if r.feasible else "NOT CONSISTENT WITH THE SPECIFICATION (closest set)"
    over = f"{100 * (r.residual_ratio - 1):.3f} % above the unconstrained fit"
    lines += [
        f"total mass {float(np.sum(r.mass)):.4f} kg"
        + ("" if r.total_mass is None else f" (band {r.total_mass[0]:g}..{r.total_mass[1]:g} kg)"),
        f"{status}: method sdp ({r.options.objective}, prior {r.prior.source}), fit {r.fit}, "
        f"relative residual on the coefficients {r.relative_residual:.3e}, "
        + (
            f"data residual {over}"
            if r.heldout is None
            else "judged on held-out data (below): its training residual, above least "
            f"squares' by construction, does not decide ({over} in the covariance-weighted "
            "data term)"
        ),
        f"solver {r.solver}: {r.status}, {r.run_time:.2f} s",
    ]
    lines += consistent_structure_lines(r)
    if r.heldout is not None:
        lines += heldout_table(r.heldout)
    for fr in friction_parts(r.friction):
        at = "motors" if fr.at_motors else "joints"
        kinds = None if fr.at_motors else r.robot  # a motor turns: rad
        lines.append(
            f"friction at the {at}: "
            + "; ".join(
                f"{name} [{unit_said(kinds, unit)}]: "
                + " ".join(f"{x:.4g}" for x in fr.params[:, j])
                for j, (name, unit) in enumerate(zip(fr.names, fr.law.units, strict=True))
            )
        )
    if r.spring is not None:
        lines.append(
            f"joint spring k (q - q0): k [{unit_said(r.robot, 'N m/rad')}] (>= 0): "
            + " ".join(f"{x:.4g}" for x in r.spring.k)
            + f"; q0 [{unit_said(r.robot, 'rad')}]: "
            + " ".join(f"{x:.4g}" for x in r.spring.q0)
        )
    lines += _determined_lines(r)
    lines += [f"note: {s}" for s in r.notes]
    if not r.feasible:
        lines.append(str(r.report))
    return "\n".join(lines)


def _prior_marks(r: FeasibleResult) -> tuple[list[str], NDArray[np.str_]]:
    """Per link, the mark of its mass (n,) and of its CoM components (n, 3):
    :data:`~dynid.feasibility.determined.PRIOR_MARK` where the prior sets the value
    (:meth:`~dynid.feasibility.determined.Determined.link_marks`), a space elsewhere (and
    everywhere without a determination: static data)."""
    n = r.robot.n
    det = r.determined
    if det is None or det.n != n:
        return [" "] * n, np.full((n, 3), " ")
    mass, com = det.link_marks()
    return [PRIOR_MARK if x else " " for x in mass], np.where(com, PRIOR_MARK, " ")


def _prior_mark_line(r: FeasibleResult, *, prior: bool = True) -> list[str]:
    """The line under the links' table saying what the mark means (none unmarked); of a
    method without a prior (``prior=False``: the penalty method), that the value marked is
    where its best run landed among the many that fit."""
    det = r.determined
    if det is None or det.n != r.robot.n or not any(det.by_prior[: 10 * det.n]):
        return []
    if not prior:
        return [
            f"{PRIOR_MARK} not measured: the data give only combinations holding it (the base "
            "parameters), and the penalty method uses no prior: its value is one of many that "
            "fit them, where the best run landed (another --seed may land elsewhere); "
            "unmarked: the data determine it"
        ]
    share = (
        ""
        if det.prior_share is None
        else f", or too little of it (the prior's share above {100 * PRIOR_SHARE:g} %)"
    )
    return [
        f"{PRIOR_MARK} set by the prior, not measured: the data give only combinations "
        f"holding it (the base parameters){share}: its value is the prior's, moved with "
        "those combinations (a marked mass can end far from the prior and still not be "
        "measured); unmarked: the data determine it (each standard parameter's prior "
        "share: report.json determined.prior_share)"
    ]


def _determined_lines(r: FeasibleResult) -> list[str]:
    """What the identified coefficients hold (``N link base parameters + K rotor inertias
    (armatures)``), the rotor inertias retrieved with those the data do not give alone
    marked ``*`` (taken from the prior), and the link masses the data do not excite; at the
    motors with a drive, the armature at the joints without one (joint-side torques)."""
    det = r.determined
    out = [] if det is None else [f"coefficients: {det.counts()}"]
    src = None if det is None else det.rotor_source
    if r.rotor_inertia is not None:
        ia = np.asarray(r.rotor_inertia)
        marked = [s in (SUM, PRIOR) for s in src] if src and len(src) == ia.size else []
        d = r.drive  # a direct drive (K = 1, joint-side torques): the armature term's
        bare = d is None or (d.is_identity and np.array_equal(d.transmission, np.eye(d.n)))
        where = "armature (joint side)" if bare else "rotor inertia at the motors"
        unit = unit_said(r.robot if bare else None, "kg m^2")
        out.append(
            f"{where} [{unit}] (>= 0): "
            + " ".join(f"{x:.4g}" + ("*" if marked and marked[m] else "") for m, x in enumerate(ia))
        )
        if any(marked):
            summed = [str(m + 1) for m, s in enumerate(src or ()) if s == SUM]
            unexcited = [str(m + 1) for m, s in enumerate(src or ()) if s == PRIOR]
            if summed:
                out.append(
                    f"  * rotor(s) {', '.join(summed)}: from the prior: the data give each only "
                    "in a sum with link inertias (in beta): the prior and the constraints "
                    "decide its share"
                )
            if unexcited:
                out.append(
                    f"  * rotor(s) {', '.join(unexcited)}: from the prior: the data do not "
                    "excite them"
                )
    masses = (
        [] if det is None else [f"m{i + 1}" for i, s in enumerate(det.mass_source) if s == PRIOR]
    )
    if masses:
        out.append(
            "note: masses the data do not give (unidentifiable: "
            + ", ".join(masses)
            + "): the prior, the bounds and the total-mass band decide them"
        )
    return out


def format_rms_table(names: list[str], columns: dict[str, np.ndarray]) -> str:
    """A per-joint table of RMS values [N m]: columns as wide as their longest name, four
    decimals from 0.1 up, four significant digits below (an error of 2.8e-5 N m is not
    0.0000)."""
    w = text_width("joint", names, 9) + 1
    cw = {k: max(22, len(k) + 2) for k in columns}
    head = f"{'joint':<{w}}" + "".join(f"{k:>{cw[k]}}" for k in columns)
    rows = [head]
    for j, name in enumerate(names):
        rows.append(
            f"{name:<{w}}"
            + "".join(f"{_rms_text(float(v[j])):>{cw[k]}}" for k, v in columns.items())
        )
    return "\n".join(rows)


def format_friction_rms(
    names: list[str],
    fit: FrictionFit,
    noise: np.ndarray | None,
    decimate: int = 1,
    robot: JointKinds | None = None,
) -> str:
    """``dynid friction``'s table: per joint the residual RMS before and after the friction
    [N m; a prismatic joint of ``robot`` in N] and the torques' sensor noise, and what they
    are: on the recordings the friction was fitted to, the torques as measured at every
    sample (every ``decimate``-th, the identification's decimation)."""
    unit = unit_said(robot, "N m")
    cols = {f"RMS before [{unit}]": fit.rms_before, f"RMS after [{unit}]": fit.rms_after}
    if noise is not None:
        cols[f"sensor noise [{unit}]"] = noise
    at = (
        "every sample"
        if decimate <= 1
        else f"every {_ordinal(decimate)} sample (the identification's decimation)"
    )
    return (
        format_rms_table(names, cols)
        + "\nRMS on the recordings the friction was fitted to (training data of the friction, "
        f"and of the rigid-body model when identified from them), the torques as measured at "
        f"{at}; validate judges new recordings"
    )


def _ordinal(k: int) -> str:
    """``2nd``, ``3rd``, ``9th``, ``11th``, ``21st``."""
    tail = "th" if 10 <= k % 100 <= 20 else {1: "st", 2: "nd", 3: "rd"}.get(k % 10, "th")
    return f"{k}{tail}"


def _rms_text(x: float) -> str:
    """``x`` with four decimals from 0.1 up (and 0), else four significant digits."""
    return f"{x:.4f}" if abs(x) >= 0.1 or x == 0 or not np.isfinite(x) else f"{x:.4g}"


def format_newton_euler_rms(val: NewtonEulerValidation) -> str:
    """Per-joint RMS of the Newton-Euler torques with retrieved parameters [N m] (and of
    the identified model, when compared)."""
    names = val.joint_names
    w = text_width("joint", names)
    head = f"{'joint':<{w}}  {'RMS NE [N m]':>12}" + (
        "  {:>20}".format("RMS identified [N m]") if val.errors_reference is not None else ""
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


def _gain_noise_line(noise: GainNoise | None, robot: Robot) -> list[str]:
    """One line when the velocities' noise times the gain dominates some joints'
    calibration residual (:mod:`dynid.observer.gain_noise`): their thresholds grow with
    ``--gain`` (in ``robot``'s units per joint kind)."""
    if noise is None or not noise.dominated:
        return []
    js, names = noise.dominated, robot.joint_names
    own = [joint_unit("N m", bool(robot.prismatic[j])) for j in js]
    gains = sorted({float(noise.gain[j]) for j in js})
    share = noise.share
    return [
        f"velocity noise x gain: on {', '.join(names[j] for j in js)} the velocities' noise "
        f"through K_O M(q) (RMS {_said(noise.predicted, js, own)} at "
        f"K_O {'/'.join(f'{g:g}' for g in gains)} 1/s) makes up "
        f"{', '.join(f'{100 * share[j]:.0f}' for j in js)} % of the residual's mean square: "
        "these thresholds grow in proportion to --gain, so a larger gain does not detect "
        "sooner there (calibrate at two gains and compare the thresholds)"
    ]


def _said(values: NDArray[np.float64], js: Sequence[int], units: Sequence[str]) -> str:
    """``values`` of joints ``js`` with their ``units`` (one each): ``"0.1, 0.2 N m"``, or
    each with its own where they differ (``"0.1 N, 0.2 N m"``)."""
    same = len(set(units)) == 1
    text = ", ".join(
        f"{values[j]:.3g}" + ("" if same else f" {u}") for j, u in zip(js, units, strict=True)
    )
    return text + (f" {units[0]}" if same else "")


def uncertainty_words(
    k_sigma: float | None,
    noise: NDArray[np.float64],
    margin: float,
    robot: JointKinds | None = None,
) -> str:
    """What the contact threshold is when it holds the model's uncertainty: ``k sigma(t)``
    plus a noise floor (in ``robot``'s units per joint kind), not the fixed level plus
    something, so that while moving it can lie below the fixed (``--no-uncertainty``)
    level."""
    floor = values_said(robot, [f"{v:.3g}" for v in noise], "N m")
    return (
        f"contact threshold applied: {k_sigma:g} sigma(t) + a noise floor of "
        f"{floor} (sigma: the model's uncertainty at "
        f"each sample; the floor: {margin:g} x the largest |r| - {k_sigma:g} sigma of the "
        "calibration), its largest along the motion the 'contact, moving' column; it "
        "replaces the fixed level and may lie below it"
    )


def _check_lines(check: CalibrationCheck | None, robot: JointKinds | None = None) -> list[str]:
    """Whether the calibrated observer is good enough: its false alarms on its own logs
    and the smallest external torque it detects per joint while moving (in ``robot``'s
    units per joint kind)."""
    if check is None:
        return []
    out = []
    if check.false_alarms is not None:
        rate = check.false_alarms_per_min
        out.append(
            f"{check.false_alarms} false alarm(s) on the calibration logs"
            + ("" if rate is None else f" ({rate:.3g} per minute)")
        )
    if check.level is not None:  # what a detection's trust verdict compares its own with
        out.append(
            f"the residual on them sits at {100.0 * check.level:.0f} % of the contact "
            "threshold (95 % of the samples under it; thresholds.json's residual_level)"
        )
    out.append(
        "smallest external torque detected while a joint moves: "
        + values_said(robot, [f"{v:.3g}" for v in check.detectable], "N m")
        + " (the largest contact threshold along the motion)"
        + (
            ""
            if check.collision is None
            else "; collision level while moving: "
            + values_said(robot, [f"{v:.3g}" for v in check.collision], "N m")
            + " (the largest collision threshold along it)"
        )
    )
    if check.model is not None:  # the model behind the thresholds
        out.append(check.model.words())
    return out


def _margin_peak(x: LogObservation) -> NDArray[np.float64] | None:
    """A log's largest standstill margin per joint [N m] (its own, or of its series)."""
    if x.standstill_peak is not None:
        return x.standstill_peak
    return None if x.standstill is None else np.max(x.standstill, axis=0)


def format_observation(result: ObserveResult, names: list[str], *, calibrating: bool) -> str:
    """The thresholds per joint (and the largest residual) and, detecting, every event."""
    th, robot = result.thresholds, result.model.robot
    u = unit_said(robot, "N m")
    if calibrating:  # the residual the rule read: after the standstill margin
        read = "|r| read" if th.quantile == 1.0 else f"|r| q{th.quantile:g}"
        read += " past margin" if th.standstill else ""  # not the report's raw largest |r|
        cols = {f"{read} [{u}]": th.contact / th.margin}
    else:
        peaks = [x.largest() for x in result.logs]
        one = len(peaks) == 1
        cols = {(f"max |r| [{u}]" if one else f"max |r| all logs [{u}]"): np.nanmax(peaks, axis=0)}
        ratios = [x.peak_ratio for x in result.logs if x.peak_ratio is not None]
        if ratios:  # what decides: the threshold at each sample, not its base value
            cols["max |r|/contact"] = np.nanmax(ratios, axis=0)
    moving = None if result.check is None else result.check.detectable
    if th.uses_uncertainty and moving is not None:  # the levels applied, then the fixed
        assert result.check is not None
        cols[f"contact, moving [{u}]"] = moving
        if result.check.collision is not None:
            cols[f"collision, moving [{u}]"] = result.check.collision
    fixed = " --no-uncertainty" if th.uses_uncertainty else " base" if th.standstill else ""
    cols |= {f"contact{fixed} [{u}]": th.contact, f"collision{fixed} [{u}]": th.collision}
    rest = undetected_at_rest(result.model, th, moving)
    level = th.contact if moving is None else moving
    at_rest = calibrating and th.standstill and np.any(rest > level)
    if at_rest:
        cols[f"at rest [{u}]"] = rest
    truth = [err for x in result.logs if (err := x.truth_error()) is not None]
    if truth:
        cols[f"RMS r - tau_ext [{u}]"] = np.sqrt(np.mean(np.square(truth), axis=0))
    trust = None if calibrating else result.trust()
    rows = [] if trust is None else [trust.words]  # how far to trust the events: first
    rows.append(format_rms_table(names, cols))
    if truth:
        rows.append(
            f"r - tau_ext: the residual against the true external torques of {len(truth)} "
            "log(s) (columns tau_ext, a simulation's ground truth, or those --columns "
            "tau_ext= maps, taken as the reference), the observer's lag included"
        )
    if calibrating:
        what = "largest" if th.quantile == 1.0 else f"{th.quantile:g} quantile of the"
        rows.append(
            f"contact{' --no-uncertainty' if th.uses_uncertainty else ''} = {th.margin:g} x "
            f"the {what} |r| of the calibration"
            + (" after the standstill margin (left out)" if th.standstill else "")
            + (": the fixed level, applied only then" if th.uses_uncertainty else "")
        )
    if at_rest:
        rows.append(
            "at rest: a contact on a joint standing still inside its standstill band "
            "goes undetected below this (the largest static friction the law may hold, or "
            "the level calibrated at the calibration's rests where smaller, plus the "
            "contact level while moving)"
        )
    if th.uses_uncertainty and th.noise is not None:
        rows.append(uncertainty_words(th.k_sigma, th.noise, th.margin, robot))
    margins = [m for x in result.logs if (m := _margin_peak(x)) is not None]
    if calibrating and th.standstill and th.rest is not None:
        coulomb = standstill_margin(result.model.friction, np.zeros((1, th.n)))[0]
        if margins:  # a smooth law's: its steps within the velocity noise band, applied
            coulomb = np.maximum(coulomb, np.max(margins, axis=0))
        rows += rest_margin_lines(th.rest, coulomb, names, th.margin, robot)
    if th.standstill and margins and np.any(margins):
        top = np.max(margins, axis=0)
        rows.append(
            "plus the standstill margin of the friction (Coulomb level inside its band, "
            "smooth steps within the velocity noise, lagged; "
            f"up to {values_said(robot, [f'{v:.3g}' for v in top], 'N m')})"
        )
    if calibrating:
        rows += _gain_noise_line(result.gain_noise, robot)
        rows.append(f"calibrated on {th.samples} samples of {len(result.logs)} log(s)")
        rows += _check_lines(result.check, robot)
        rows += beyond_lines(result, _labels_by_log(result))
        return "\n".join(rows)
    if "max |r|/contact" in cols:
        least = "" if result.min_duration_s is None else f" for {result.min_duration_s:g} s"
        rows.append(
            "max |r|/contact: the largest residual over the contact threshold at the same "
            f"sample (as it stood then); an event needs 1 or more{least} (--min-duration)"
        )
    labels = log_labels([x.path for x in result.logs])
    if len(result.logs) > 1:  # the pooled column holds the contacts of every log
        rows.append(f"max |r| per log [{u}], joints in the table's order:")
        width = max(map(len, labels))
        for label, x in zip(labels, result.logs, strict=True):
            rows.append(f"  {label:<{width}}  " + "  ".join(f"{v:8.4g}" for v in x.largest()))
    events = [
        (label, e, None if x.damped is None else x.damped[k])
        for x, label in zip(result.logs, labels, strict=True)
        for k, e in enumerate(x.events)
    ]
    rows.append(f"{len(events)} event(s), {flagged_words(*result.flagged())}")
    for log, e, damped in events:
        top = max(e.joints, key=lambda j: abs(e.peak[j - 1]))
        rows.append(
            f"  {log}: {e.level:<9} {e.start:9.3f} s .. {e.end:9.3f} s  joints "
            f"{','.join(map(str, e.joints))}  peak {e.peak[top - 1]:+.2f} "
            f"{joint_unit('N m', bool(robot.prismatic[top - 1]))} (joint {top})"
            + (f"  {result.wrench.noun} damped on {100.0 * damped:.3g} %" if damped else "")
        )
    if any(d for *_, d in events):
        rows.append(
            f"damped: the share of the event's samples where the {result.wrench.noun} at "
            f"{result.frame} was estimated near a singular configuration of the joints "
            f"that move it (damped least squares): the {result.wrench.noun} there is "
            "unreliable (the residual, and the detection, are not)"
        )
    rows += _dropped_lines(result, labels, names)
    rows += _score_lines(result, labels)
    rows += beyond_lines(result, _labels_by_log(result))
    if result.frame is not None:  # what the residual tables' fx..mz hold
        words = estimate_words(result.model.robot, result.frame, result.wrench)
        rows.append(f"estimated (fx..mz of the residual tables): {words}")
    return "\n".join(rows)


def _labels_by_log(result: ObserveResult) -> dict[int, str]:
    """Each log's name as the summary says it (:func:`log_labels`), by the log's ``id``."""
    labels = log_labels([x.path for x in result.logs])
    return {id(x): label for x, label in zip(result.logs, labels, strict=True)}


def format_collision_stage(res: CollisionStageResult) -> str:
    """Stage 6: the push, the events found, the delay and the residual's error."""
    c = res.contact
    rows = [
        f"push: {list(c.wrench[:3])} N on {c.frame} from {c.start:g} s to {c.end:g} s; "
        f"thresholds (contact) [N m]: " + " ".join(f"{x:.2f}" for x in res.thresholds.contact)
    ]
    for e in res.events:
        rows.append(
            f"  {e.level} {e.start:.3f} s .. {e.end:.3f} s, joints {','.join(map(str, e.joints))}"
        )
    found = "not found" if res.delay is None else f"detected {1e3 * res.delay:.0f} ms after it"
    rows.append(
        f"{len(res.events)} event(s); the push {found}; residual vs the true external torque "
        "(first-order lag) RMS [N m]: " + " ".join(f"{x:.3f}" for x in res.residual_error_rms)
    )
    return "\n".join(rows)


#: Dropped crossings printed at most (those furthest over the threshold); events.json
#: holds more.
DROPPED_SHOWN = 10


def _dropped_lines(result: ObserveResult, labels: list[str], names: list[str]) -> list[str]:
    """The crossings over the contact threshold that the minimum duration dropped: how
    many, and those furthest over it (time, joint, peak, ratio, duration against the
    minimum, rule); nothing when there were none."""
    total = result.dropped_count()
    if not total:
        return []
    least = "" if result.min_duration_s is None else f" {result.min_duration_s:g} s"
    rows = [
        f"{total} crossing(s) over the contact threshold dropped as shorter than "
        f"--min-duration{least} (not contacts; events.json's dropped):"
    ]
    found = [(lab, d) for x, lab in zip(result.logs, labels, strict=True) for d in x.dropped]
    shown = sorted(found, key=lambda ld: -ld[1].ratio[ld[1].joint - 1])[:DROPPED_SHOWN]
    for lab, d in sorted(shown, key=lambda ld: (labels.index(ld[0]), ld[1].start)):
        j = d.joint
        words = dropped_words(
            d.start, d.end, names[j - 1], d.peak[j - 1], d.ratio[j - 1], d.rule,
            result.min_duration_s,
        )  # fmt: skip
        rows.append(f"  {lab}: {words}")
    if total > len(shown):
        rows.append(f"  and {total - len(shown)} more, less far over the threshold")
    return rows


def _score_lines(result: ObserveResult, labels: list[str]) -> list[str]:
    """The events against the labelled contacts (:mod:`dynid.observer.scoring`): per log
    with several, then in total, and every missed contact; nothing without labels."""
    total = result.score()
    if total is None:
        return []
    scored = [(lab, x.score) for lab, x in zip(labels, result.logs, strict=True) if x.score]
    rows = [
        f"scored against labelled contacts ({total.source}; an event starting from "
        f"{total.lead_s:g} s before a contact's start to {total.tolerance_s:g} s after its "
        "end detects it; one starting earlier than that before any contact is a false alarm):"
    ]
    width = max(len(lab) for lab, _ in scored)
    parts = [(lab, sc) for lab, sc in scored] if len(scored) > 1 else []
    for lab, sc in [*parts, ("total" if parts else scored[0][0], total)]:
        rows.append(f"  {lab:<{width}}  {score_words(sc)}")
    for lab, sc in scored:
        for m in sc.missed:
            peak = "" if m.peak is None else f", peak true torque {m.peak:.3g} N m"
            why = reason_words(m, result.model.robot.joint_names)
            why = f"; {why}" if why else ""
            rows.append(f"  missed in {lab}: {m.start:.3f} s .. {m.end:.3f} s{peak}{why}")
    for lab, x in zip(labels, result.logs, strict=True):
        if x.score is None:
            continue
        for k in x.score.false_events:
            if (e := x.events[k]).level == "load":
                rows.append(
                    f"  false alarm in {lab}: {e.start:.3f} s .. {e.end:.3f} s is a load's "
                    "pick no labelled contact holds (an external force: a weight picked or "
                    "a steady push along gravity; --no-loads reads none as a load)"
                )
    return rows
