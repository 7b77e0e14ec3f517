"""The model's structure chosen on held-out data: which terms beside the links' parameters.

A joint-torque log of a real arm holds more than the rigid links: the rotors' inertia
(an armature ``I_a ddq`` per joint, or the rotors of a drive), viscous and Coulomb friction,
torque offsets. Which of them the data support cannot be read from the training error (a
larger model always fits better); it is read from data the fit did not see.

A :class:`Structure` names the terms: ``armature`` (per joint ``I_a ddq`` without a drive,
the drive's rotor inertias with one) and the parts of the joint (motor) friction
(:data:`~dynid.regressors.terms.FRICTION_PARTS`: ``viscous``, ``coulomb`` with the
standstill band, ``offset``). :func:`select_structure` fits the largest model once per
armature choice, keeps the normal equations of every held-out fold
(:mod:`dynid.identification.holdout`), and judges every candidate (a subset of the
columns) by its pooled held-out error; it keeps the **simplest candidate within one
standard error of the best** (the one-standard-error rule of cross-validation: Hastie,
Tibshirani and Friedman, *The Elements of Statistical Learning*, 2nd ed., Sec. 7.10),
the standard error being that of the difference of the two candidates' errors paired
over the folds (:func:`~dynid.identification.candidates.paired_se`; of fewer recordings
than the folds, over contiguous time blocks of each held-out recording), and differences
under 1 % of the lowest error counting as ties. A coefficient the data determine (its
relative standard deviation in the fit that holds it at most
:data:`~dynid.identification.candidates.DETERMINED_STD_PERCENT`, the standard deviation
that holds for the filtered log's coloured residual) is never left out that way: a term
leaves when held-out data do not miss it **and** the fit cannot tell it from zero (a wrist
armature whose torque stays within the noise at the training's accelerations, yet
determined to 3 %, kept ``M(q)`` of the wrist right;
:attr:`~.candidates.Selection.determined` names what was kept so). An armature (a
rotor's inertia, at least zero) fitted above zero is determined at three standard
deviations,
:data:`~dynid.identification.candidates.ADMISSIBLE_STD_PERCENT` (a Kinova Jaco2's wrist
armatures at 31 % and 23 % had been left out, its ``M44`` and ``M66`` 53 % and 76 % low).
A smooth Coulomb's width is then chosen per joint (:mod:`dynid.identification.widths`),
and the Stribeck bump on the smooth sign judged at the width of the best smooth law
(:mod:`dynid.identification.bumps`); the chosen Stribeck velocity is refined between its
grid neighbours on the same held-out error (:mod:`dynid.identification.shape_refinement`),
then chosen per joint where that predicts better (:mod:`dynid.identification.stribeck_joints`).
The folds leave one recording out at a time when there are several, contiguous time
blocks otherwise (:meth:`~dynid.identification.recordings.Recordings.fold_labels`), or
judge on a separate recording. A recording that holds what no candidate models is left
out of the judgement and named (:mod:`dynid.identification.candidates`); a candidate
whose friction is not dissipative within the velocity limits is not chosen
(:mod:`dynid.identification.dissipation`); when it predicts best, its offending
coefficients are left out joint by joint and the candidate reached is judged instead.
When no dissipative candidate predicts as well, friction that puts energy in at every
speed (:func:`reversed_friction`) on a joint gravity does not load is a torque of the
opposite sign there: :func:`identify_recordings` refuses it. Last, a friction coefficient
of the choice fitted below zero (viscous, Coulomb or quadratic: friction that pushes the
arm by itself) that the data do not determine (relative standard deviation above
:data:`~dynid.identification.candidates.DETERMINED_STD_PERCENT`) is left out whatever the
held-out error says (:func:`_without_pushing`), and a note names it.

:func:`identify_recordings` is the classical route over one or more recordings with the
structure chosen (or given).
"""

from __future__ import annotations

import warnings
from collections.abc import Callable, Collection, Sequence
from dataclasses import dataclass, replace
from functools import partial
from typing import Any, Literal, TypeVar

import numpy as np
from numpy.typing import NDArray

from .._checks import caller_level
from ..exceptions import DynidWarning, OptionError
from ..model.drive import Drive
from ..model.robot import Robot
from ..progress import stage
from ..regressors.base import BaseParameters
from ..regressors.terms import PART_LABELS, ModelTerm
from ..signals import lowpass_noise_gain
from .bumps import bump_widths
from .candidates import (
    DETERMINED_STD_PERCENT,
    OUTLIER_RATIO,
    Candidate,
    Selection,
    candidate_judged,
    cut_record,
    heldout_of,
    paired_se,
    recording_oddness,
    within_best,
    without_recordings,
)
from .core import model_advice, model_columns, shared_bases
from .differing_recording import with_differing
from .dissipation import (
    ReversedSignError,
    Violation,
    friction_columns,
    friction_violations,
    reversed_sign_finding,
    warn_unphysical,
)
from .estimator_choice import choose_estimator
from .estimators import OLS, WLS, Estimator, EstimatorName, estimator_named
from .holdout import DEFAULT_FOLDS, HeldOut, shared_eigen
from .input_noise import exact_note, exact_to_round_off
from .judge import heldout_judge
from .largest import Fitted, LeftOut, fit_largest
from .least_squares import StdMethod, within_motion_caveat
from .log import TorqueLog
from .log_rows import shared_steps
from .metrics import noise_floor_percent
from .model import IdentifiedModel
from .model_sign import gravity_loaded, sign_confirmed
from .once_per_run import once_per_run
from .one_way_friction import FRICTION_LABEL
from .outlying_recordings import (
    _burst_cuts,
    _Cut,
    _cut_out,
    _cut_said,
    _final_fit,
    _fitted_given,
    _Gone,
    _outlying,
    _per_recording_fitted,
    _residual_spans,
    _spans_said,
    _warn_outlying,
    cut_log,
)
from .outlying_spans import Span
from .recordings import Recordings
from .rotor_sign import warned_negative_inertias
from .shape_refinement import refined_shape
from .spring_candidate import tried_joints, with_spring
from .stribeck_joints import per_joint_vst
from .structural import absorbed_by
from .structure import (
    ERROR_FLOOR_PERCENT,
    Structure,
    candidate_columns,
    candidate_structures,
    check_placement,
    coefficient_labels,
    column_labels,
    friction_placements,
    joint_side_joints,
    own_rotors,
    regressor_group,
    smooth_stribeck_candidates,
    width_text,
)
from .structure_fit import _fitted, _recordings, _terms_of
from .verdict import ROUND_OFF_PERCENT
from .widths import per_joint_widths, regressor_widths

__all__ = [
    "OUTLIER_RATIO",
    "Candidate",
    "Selection",
    "fitted_logs",
    "identify_recordings",
    "reversed_friction",
    "select_structure",
]


def _with_floor(heldout: Any, data: Recordings) -> Any:
    """The held-out record with the noise floor of the torques it was judged on, ``data``
    (the recordings of the folds, or the separate recording; as measured, or filtered when
    the recordings were not; less the rotor torques of a drive's known rotor inertias, as
    the fit's errors are: :meth:`~.prepared_log.PreparedLog.targets`)
    (:func:`~dynid.identification.metrics.noise_floor_percent`) and the sensor noise it
    is made of, each joint's raw torque noise [N m] as the RMS over the samples used
    (``noise_rms``: the one value the summary, heldout.json and the report read), when
    both are known."""
    pieces = data.pieces
    if heldout is None or any(p.torque_noise_std is None for p in pieces):
        return heldout
    measured = data.measured  # judged on the torques as measured (less known rotors')
    taus = [p.targets(None if p.tau_raw is None or not measured else p.tau_raw) for p in pieces]
    stds = [p.torque_noise_std for p in pieces]
    noise = [np.asarray(s, dtype=np.float64) for s in stds if s is not None]
    floor = noise_floor_percent(
        taus,
        noise,
        [1.0 if measured else lowpass_noise_gain(p.sample_rate_hz, p.cutoff_hz) for p in pieces],
    )
    if floor is None:
        return heldout
    counts = np.array([np.shape(t)[0] for t in taus], dtype=np.float64)
    rms = np.sqrt(counts @ np.square(np.stack(noise)) / counts.sum())
    return {**heldout, "noise_floor_percent": floor, "noise_rms": rms.tolist()}


def _heldout_record(model: IdentifiedModel, data: Recordings) -> Any:
    """The model's held-out record with its noise floor (:func:`_with_floor`) and, judged
    on time blocks of an ill-conditioned motion, the caveat of what they cannot tell
    (:func:`~dynid.identification.least_squares.within_motion_caveat`)."""
    heldout = _with_floor(model.info.heldout, data)
    caveat = within_motion_caveat(model.fit, None if heldout is None else heldout.get("scheme"))
    return heldout if caveat is None else {**heldout, "caveat": caveat}


def _physical(candidates: Sequence[Candidate]) -> list[Candidate]:
    """The candidates not skipped: friction dissipative within the velocity limits and no
    Stribeck bump below zero (:attr:`~.candidates.Candidate.skipped`; all of them when
    every one is)."""
    return [c for c in candidates if not c.skipped] or list(candidates)


def _within(c: Candidate, best: Candidate) -> bool:
    """Whether ``c`` predicts as well as ``best``: its held-out error above the lowest by
    at most one standard error of the difference, paired over the folds
    (:func:`~.candidates.paired_se`), or by less than :data:`~.candidates.RELATIVE_TIE` of
    the lowest (or :data:`~.structure.ERROR_FLOOR_PERCENT`): :func:`~.candidates.within_best`."""
    return within_best(c, best)


def _chosen(candidates: Sequence[Candidate]) -> Structure:
    """The simplest candidate within one standard error of the lowest held-out error
    (:func:`_within`) that holds every coefficient the lowest's fit determines
    (:meth:`~.candidates.Candidate.determined`), among those whose friction is dissipative
    within the velocity limits."""
    candidates = _physical(candidates)
    best = min(candidates, key=lambda c: c.score)
    within = [c for c in candidates if _within(c, best) and not _lacks(c, best)]
    # of as many parameters, the one with fewer terms: an armature whose every own rotor
    # is left out holds only rotors that regroup with the links (the same columns)
    return min(
        within,
        key=lambda c: (
            c.n_params,
            c.structure.armature + len(c.structure.friction),
            c.score,
        ),
    ).structure


def _lacks(c: Candidate, best: Candidate) -> dict[str, float]:
    """The coefficients ``best``'s fit determines that ``c`` does not hold (the armature
    of joint 5 in a candidate without it), and their relative standard deviations [%]."""
    held = {lab for lab, _ in c.relative_std}
    return {lab: r for lab, r in best.determined().items() if lab not in held}


@once_per_run
@shared_steps()
@shared_bases()
@shared_eigen()
def select_structure(
    robot: Robot,
    data: Recordings,
    *,
    drive: Drive | None = None,
    candidates: Sequence[Structure] | None = None,
    estimator: EstimatorName | Estimator = "ols",
    folds: int = DEFAULT_FOLDS,
    validation: Recordings | None = None,
    rtol: float | None = None,
    per_joint: bool = True,
    keep: bool | None = None,
) -> Selection | None:
    """Judge candidate structures on held-out data and choose one (module docstring).

    Parameters
    ----------
    robot : Robot
    data : Recordings
        The prepared recordings (:func:`~dynid.identification.recordings.prepare_recordings`).
    drive : Drive, optional
        The drive the data were read through.
    candidates : sequence of Structure, optional
        Default :func:`candidate_structures` (the armature only where the rotor inertias
        are not known; the friction at the motors and at the joints of a coupled drive,
        :func:`~dynid.identification.structure.friction_placements`).
    estimator, folds, rtol, keep
        As :func:`identify_recordings` (``keep``: its ``keep_outlying``, None: not said).
    validation : Recordings, optional
        A separate recording to judge on instead of the folds.
    per_joint : bool
        Also judge per-joint structures: a smooth Coulomb's width per joint
        (:func:`~dynid.identification.widths.per_joint_widths`), a Stribeck velocity per
        joint (:func:`~dynid.identification.stribeck_joints.per_joint_vst`), single joints' friction
        coefficients left out within one standard error of the lowest held-out error,
        none the fit determines (:attr:`~dynid.identification.structure.Structure.drop`).

    Returns
    -------
    Selection or None
        None when the data are too short for held-out judgement.
    """
    est = estimator_named(estimator)
    armature_ok = drive is None or drive.identifies_rotor_inertia
    cands = (
        tuple(candidates)
        if candidates is not None
        else candidate_structures(armature_ok, friction_placements(drive))
    )
    judged: list[Candidate] = []
    notes: list[str] = []
    judge, how, fold_labels = heldout_judge(robot, data, est, folds, validation)
    fit_rtol = 1e-10 if rtol is None else rtol
    groups: _Groups = {}
    columns: list[tuple[Structure, NDArray[np.bool_], _Key]] = []
    unexcited: set[str] = set()  # single joints' coefficients the data do not excite
    left_out: list[LeftOut] = []  # shaped candidates left out, said once the choice is made

    def fit(
        mine: list[Structure], what: str = "structure search, a Stribeck bump on the smooth sign"
    ) -> list[Fitted]:
        """The regressor of ``mine`` (one group) fitted with the judge; ``what``: its step."""
        arm = mine[0].armature
        with stage(what, rows=data.n_rows):
            return fit_largest(
                robot, data, mine, arm, drive, est, rtol, judge, notes, fold_labels, unexcited,
                left_out,
            )  # fmt: skip

    keys = sorted({regressor_group(c) for c in cands})
    for i, key in enumerate(keys):
        arm, mine = key[0], [c for c in cands if regressor_group(c) == key]
        for family, model, terms, held in fit(
            mine, f"structure search, regressor {i + 1} of {len(keys)}"
        ):  # a smooth width judged apart: its own key
            if model.holdout is None:
                return None
            own = (arm, key[1], family)
            groups[own] = (model, terms)
            for c in held:
                use = candidate_columns(c, model, terms)
                columns.append((c, use, own))
                judged.append(_judged(c, use, model, terms, model.holdout, fit_rtol))
    if not judged:
        return None
    full = list(judged)
    names = data.names if validation is None else ()  # judged on a separate one: none odd
    judged, skip, ratios = _without_odd(judged, columns, groups, names, fit_rtol, notes, keep)
    # each candidate's regressor; a per-joint structure's that of the candidate its search
    # began at (a smooth-sign Stribeck law without its bumps, in the Stribeck law's)
    where = {c: key for c, _, key in columns}
    by_group = {
        g: (m, t, without_recordings(m, skip) if skip else heldout_of(m))
        for g, (m, t) in groups.items()
    }
    if per_joint:
        judged += _widths_per_joint(judged, by_group, robot.n, fit_rtol, where)
    off = _OffGrid(fit, groups, by_group, where, skip, fit_rtol)
    judged += _smooth_bumps(judged, cands, off)
    chosen = _shaped_choice(judged, off, robot.n, per_joint, notes)
    chosen = _without_pushing(chosen, judged, by_group, robot.n, where, notes, fit_rtol)
    notes[:0] = [lo.note(chosen, where.get(chosen)) for lo in left_out]
    best = min(_physical(judged), key=lambda c: c.score)
    determined = _kept_determined(chosen, best, judged, by_group, robot.n, fit_rtol, where)
    judged = [replace(c, se_vs_best_percent=paired_se(c, best)) for c in judged]
    notes += _candidate_notes(judged)
    per = _per_recording(chosen, full, groups, where, names, fit_rtol)
    cut = _said_outlying(skip, ratios, per, keep, chosen, off, data, robot, notes)
    return Selection(
        tuple(judged),
        chosen,
        how + (f", judged without {', '.join(data.names[i] for i in skip)}" if skip else ""),
        notes=(*notes, *_disagreement_note(per, skip, _with_floor({}, data))),
        per_recording=per,
        outlying=tuple(data.names[i] for i in skip),
        determined=determined,
        cut=tuple((data.names[i], c) for i, c in cut.items()),
    )


def _shaped_choice(
    judged: list[Candidate], off: _OffGrid, n: int, per_joint: bool, notes: list[str]
) -> Structure:
    """The structure chosen once the shapes are refined: the smooth width of one for
    every joint (:func:`_refined_width`), per-joint structures (``per_joint``,
    :func:`_per_joint`), the Stribeck velocity of the choice (:func:`_refined_stribeck`)
    and (``per_joint``) one per joint (:func:`_stribeck_joints`); every candidate judged
    appended to ``judged``, ``notes`` saying the shapes refined."""
    judged += _refined_width(judged, off, notes)
    if per_joint:
        judged += _per_joint(judged, off.by_group, n, off.rtol, off.where)
    chosen = _refined_stribeck(judged, off, notes)
    return _stribeck_joints(chosen, judged, off, n, notes) if per_joint else chosen


def _kept_determined(
    chosen: Structure,
    best: Candidate,
    judged: Sequence[Candidate],
    groups: _Folds,
    n: int,
    rtol: float,
    where: dict[Structure, _Key],
) -> tuple[tuple[str, float], ...]:
    """The coefficients of ``chosen`` that its fit determines
    (:meth:`~.candidates.Candidate.determined`) and whose absence the held-out error would
    not miss (``chosen`` without it within one standard error of ``best``): kept for being
    determined alone, each with its relative standard deviation [%]."""
    here = next(c for c in judged if c.structure == chosen)
    mine = here.determined()
    if not mine:
        return ()
    model, terms, held = groups[where[chosen]]
    out = []
    for c in _dropped(here, model, terms, held, n, rtol, among=mine):
        (lab,) = set(c.structure.drop) - set(chosen.drop)
        if _within(c, best):
            out.append((lab, mine[lab]))
    return tuple(out)


def _without_pushing(
    chosen: Structure,
    judged: list[Candidate],
    groups: _Folds,
    n: int,
    where: dict[Structure, _Key],
    notes: list[str],
    rtol: float,
) -> Structure:
    """``chosen`` without the friction coefficients its fit puts below zero and does not
    determine (:attr:`~.candidates.Candidate.loose_pushing`), left out a step at a time
    until none is (leaving one out moves the others), judged on the folds of ``chosen``'s
    regressor and added to ``judged`` (unless a candidate of the same structure is
    there), said in ``notes``; ``chosen`` itself when it holds none, or when the candidate
    reached is skipped and ``chosen`` is not.

    The held-out error alone kept them: a geared UR10 without joint friction chose
    ``viscous + at:joint - fv1 - fv3 - fv4 - fv5 - fv6``, ``fv2 = -0.20`` at 48 % (-0.23
    at 36 % in the table's weighted fit), whose absence the ols fits' held-out error
    missed by six standard errors though its torque, under 0.08 N m, is a fifteenth of
    the joint's noise: friction that pushes the arm, which nothing determines."""
    start = here = next(c for c in judged if c.structure == chosen)
    judge = _judge_in(groups[where[chosen]], rtol)
    gone: dict[str, tuple[float, float]] = {}
    while here.loose_pushing:
        fewer = here.structure.without([lab for lab, _, _ in here.loose_pushing])
        if fewer == here.structure:
            break
        gone |= {lab: (x, r) for lab, x, r in here.loose_pushing if lab not in gone}
        here = judge(fewer)
    if not gone or (here.skipped and not start.skipped):
        return chosen
    drive = groups[where[chosen]][0].drive if chosen.at == "both" else None
    reached = here.structure.collapsed(n, () if drive is None else joint_side_joints(drive))
    reached = reached if reached.friction else replace(reached, at="")  # as the ladder's
    if all(c.structure != reached for c in judged):
        where[reached] = where[chosen]
        left = tuple(dict.fromkeys((*start.left_out, *gone)))
        judged.append(replace(here, structure=reached, left_out=left))
    said = ", ".join(f"{lab} = {x:.3g} (std {r:.3g} %)" for lab, (x, r) in gone.items())
    notes.append(
        f"{', '.join(gone)} left out of {chosen.name}: {said}, friction below zero (it pushes "
        f"the arm) that the data do not determine (std above {DETERMINED_STD_PERCENT:g} %)"
    )
    return reached


def reversed_friction(selection: Selection) -> tuple[Violation, ...]:
    """The joints whose friction puts energy in at every speed in the candidate of
    ``selection`` that predicts best, when no dissipative candidate predicts as well
    (:func:`_within`): the held-out data need friction of the opposite sign there."""
    best_any = min(selection.candidates, key=lambda c: c.score)
    best = min(_physical(selection.candidates), key=lambda c: c.score)
    if best.unphysical or _within(best, best_any):
        return ()
    return tuple(v for v in best_any.unphysical if v.everywhere)


def _said_outlying(
    skip: tuple[int, ...],
    ratios: dict[int, float],
    per: tuple[tuple[str, float], ...],
    keep: bool | None,
    chosen: Structure,
    off: _OffGrid,
    data: Recordings,
    robot: Robot,
    notes: list[str],
) -> dict[int, _Cut]:
    """The warning of the recordings ``skip`` found outlying (``ratios``: each one's
    held-out error over the others' median), with where each one's residual stands off
    (:func:`_outlying_where`), and the spans cut out of each whose residual stands off in
    short spans (:func:`_cut_out`; not with ``keep`` or ``keep`` not said), its note in
    ``notes`` saying so; returns those cuts by recording."""
    found = {k: _outlying_where(k, chosen, off, data, robot) for k in skip}
    cuts = {} if keep is None or keep else _cut_out(found, ratios, data)
    for k, c in cuts.items():  # the note said it left out whole
        was, now = _final_fit(False, 1), _cut_said(c, data.names[k])
        notes[:] = [n.replace(was, now) if n.startswith(f"{data.names[k]}: ") else n for n in notes]
    _warn_outlying(skip, per, keep, _spans_said(found, data, robot), cuts=cuts)
    return cuts


def _outlying_where(
    k: int, chosen: Structure, off: _OffGrid, data: Recordings, robot: Robot
) -> tuple[Span, ...]:
    """Where recording ``k``'s residual stands off (:func:`_residual_spans`) with
    ``chosen`` fitted on the other recordings (its fold's training rows, in the regressor
    ``off.where`` says, of ``off.groups``); none where it has no regressor there."""
    key = off.where.get(chosen)
    if key is None:
        return ()
    model, terms = off.groups[key]
    fit = model.joint_fit if model.joint_fit is not None else model.fit
    idx = np.flatnonzero(candidate_columns(chosen, model, terms) & np.asarray(fit.kept, bool))
    return _residual_spans(k, model, tuple(t for t, _ in terms), idx, data, robot, off.rtol)


#: Recordings disagree (:func:`_disagreement_note`) when each one's held-out error is at
#: least this many times the noise floor and their spread (largest less smallest) too.
DISAGREE_RATIO = 3.0
#: How the note of recordings that disagree begins (:func:`_disagreement_note`).
DISAGREE_NOTE = "the recordings disagree"


def _disagreement_note(
    per: tuple[tuple[str, float], ...], skip: tuple[int, ...], floor: Any
) -> list[str]:
    """A note when the recordings' held-out errors (each left out of the others' fit,
    ``per``) are every one far above the noise floor (``floor["noise_floor_percent"]``)
    and spread widely: at least :data:`DISAGREE_RATIO` x the floor both. Consistent
    recordings of an adequate model sit near the floor and within about a floor of one
    another (a 7-DoF arm's four: 1.62 to 1.91 % against 0.59 %); recordings whose friction
    differs by 10 to 20 % and whose offsets shift spread far wider (5.2 to 10.7 %), none
    of them outlying (:data:`~.candidates.OUTLIER_RATIO` x the others' median), and the
    standard deviations, computed within the recordings, do not hold that spread (fv1
    2.04 +- 3.5 % for a truth of 1.46). None with an outlying recording (``skip``, said
    on its own), fewer than three recordings or a floor at round-off."""
    fl = floor.get("noise_floor_percent") if isinstance(floor, dict) else None
    if skip or len(per) < 3 or fl is None or not fl > ROUND_OFF_PERCENT:
        return []  # a floor at round-off: noise-free logs, whose errors say nothing of it
    errors = np.array([e for _, e in per], dtype=np.float64)
    spread = float(errors.max() - errors.min())
    if not (errors.min() >= DISAGREE_RATIO * fl and spread >= DISAGREE_RATIO * fl):
        return []
    return [
        f"{DISAGREE_NOTE}: their held-out errors ({errors.min():.3g} to "
        f"{errors.max():.3g} %, each left out of the others' fit) are all "
        f"{errors.min() / fl:.3g} x the noise floor ({fl:.3g} %) or more, and spread "
        f"{spread / fl:.3g} x it, none outlying: effects that differ between recordings "
        "(friction with temperature, sensor offsets that shift, a payload) or a motion "
        "that excites what the model lacks more than the others; the standard deviations, "
        "computed within the recordings, do not include this (the coefficients are "
        "uncertain by more than they say)"
    ]


def _candidate_notes(judged: Sequence[Candidate]) -> list[str]:
    """Notes on the candidates that predict held-out data far worse than they fit, and on
    those skipped because their friction is not dissipative."""
    notes = []
    wild = [c for c in judged if c.heldout_error_percent > max(100.0, 10 * c.train_error_percent)]
    if wild:
        notes.append(
            f"{len(wild)} candidate(s) predict held-out data far worse than they fit (up to "
            f"{max(c.heldout_error_percent for c in wild):.3g} %): some folds' training data "
            "hardly excite their columns (a Stribeck term whose velocities the held-out data "
            "reach and the others seldom do), so their fits on those folds extrapolate"
        )
    some = len(_physical(judged)) < len(judged)
    skipped = [c for c in judged if c.unphysical] if some else []
    bumps = [c for c in judged if c.negative_bump and not c.unphysical] if some else []
    if bumps:
        joints = sorted({lab for c in bumps for lab in c.negative_bump}, key=_label_key)
        notes.append(
            f"{len(bumps)} candidate(s) marked x skipped: their Stribeck bump is below zero "
            f"(static friction under Coulomb: {', '.join(joints)}), no Stribeck effect but a "
            "correction of the sign's shape; on those joints the law without the bump is "
            "judged instead (where: metadata.selection.candidates[].negative_bump)"
        )
    if skipped:  # one line: the table marks each (metadata.selection names the joints)
        notes.append(
            f"{len(skipped)} candidate(s) marked x skipped: their friction is not dissipative "
            "within the velocity limits (where: metadata.selection.candidates[].not_dissipative)"
        )
    return notes


_T = TypeVar("_T")
_Key = tuple[bool, str, str]  # regressor_group
_Groups = dict[_Key, tuple[IdentifiedModel, list[tuple[ModelTerm, Any]]]]
#: The regressors and the folds they are judged on.
_Folds = dict[_Key, tuple[IdentifiedModel, list[tuple[ModelTerm, Any]], HeldOut]]


def _without_odd(
    judged: list[Candidate],
    columns: list[tuple[Structure, NDArray[np.bool_], _Key]],
    groups: _Groups,
    names: Sequence[str],
    rtol: float,
    notes: list[str],
    keep: bool | None = None,
) -> tuple[list[Candidate], tuple[int, ...], dict[int, float]]:
    """The candidates judged without the recordings that hold what no candidate models
    (contacts, a payload), which spoil the fit of every other fold while among them
    (:func:`~.candidates.recording_oddness` above :data:`OUTLIER_RATIO`), with those
    recordings; the candidates as they were and none when none is odd or fewer than two
    would be left (of two recordings or fewer, none), and each one's ratio. A note names
    each, with what the final fit does with it (``keep``, :func:`_final_fit`)."""
    if len(names) < 3:
        return judged, (), {}
    ref = min(judged, key=lambda c: c.heldout_error_percent)
    _, use0, g0 = columns[next(i for i, c in enumerate(judged) if c is ref)]
    scores = recording_oddness(use0, groups[g0][0], rtol)
    skip = tuple(i for i, x in enumerate(scores) if x > OUTLIER_RATIO)
    if not skip or len(names) - len(skip) < 2:
        return judged, (), {}
    notes += [
        f"{names[i]}: held-out error {ref.fold_errors_percent[i]:.3g} %, "
        f"{scores[i]:.3g} x the other recordings' median when it is left out of "
        "their fits too: it holds torques the model does not (contacts, a payload, "
        "another set-up?); the structure is chosen on the other recordings"
        + ("" if keep is None else f", {_final_fit(keep, 1)}")
        for i in skip
    ]
    return (
        [
            _judged(
                c, use, groups[g][0], groups[g][1], without_recordings(groups[g][0], skip), rtol
            )
            for c, use, g in columns
        ],
        skip,
        {i: scores[i] for i in skip},
    )


def _judged(
    structure: Structure,
    use: NDArray[np.bool_],
    model: IdentifiedModel,
    terms: list[tuple[ModelTerm, Any]],
    held: HeldOut | None,
    rtol: float,
) -> Candidate:
    """``structure`` judged (:func:`~.candidates.candidate_judged`), its friction fitted
    on all data checked for dissipation within the robot's velocity limits."""
    assert held is not None  # models of the candidates are judged on held-out data
    columns = friction_columns(terms, model.base.rank)
    dq_max = model.robot.dq_max

    def check(x: NDArray[np.float64], sd: NDArray[np.float64]) -> tuple[Violation, ...]:
        return friction_violations(
            [(t, x[sl]) for t, sl in columns], dq_max, [sd[sl] for _, sl in columns]
        )

    return candidate_judged(structure, use, model, held, rtol, check, column_labels(model, terms))


def _per_recording(
    chosen: Structure,
    judged: Sequence[Candidate],
    groups: _Groups,
    where: dict[Structure, _Key],
    names: Sequence[str],
    rtol: float,
) -> tuple[tuple[str, float], ...]:
    """Each recording's name and the held-out error [%] of ``chosen`` on it, fitted on
    every other recording (its columns in the regressor ``where`` says); none for fewer
    than two ``names`` (judged on time blocks or a separate recording)."""
    if len(names) < 2:
        return ()
    here = next((c for c in judged if c.structure == chosen), None)
    if here is None:  # a per-joint structure: judged again on every recording
        m, t = groups[where[chosen]]
        use = candidate_columns(chosen, m, t)
        here = _judged(chosen, use, m, t, heldout_of(m), rtol)
    return tuple(zip(names, here.fold_errors_percent, strict=True))


def _per_recording_of(
    model: IdentifiedModel, selection: Selection, gone: _Gone | None = None
) -> Selection:
    """``selection`` with each recording's held-out error (:attr:`~.candidates.Selection.
    per_recording`) that of ``model``, the chosen structure's final fit
    (:func:`_per_recording_fitted`). The search's regressor holds every candidate's
    columns, whose round-off on exact data (1e-6 % about another model's coefficients)
    the summary printed beside the pooled 3.5e-12 % of the same structure."""
    per = _per_recording_fitted(model, selection.per_recording, gone)
    return replace(selection, per_recording=per)


def _widths_per_joint(
    judged: Sequence[Candidate],
    groups: _Folds,
    n: int,
    rtol: float,
    where: dict[Structure, _Key],
) -> list[Candidate]:
    """Smooth Coulomb widths per joint (:func:`~.widths.per_joint_widths`) from the smooth
    candidate with the lowest held-out error and from the one chosen (not the smooth-sign
    Stribeck law: its bumps are judged at one width), each among the widths of its
    regressor; the candidates reached where they differ from where they started."""
    smooth = [
        c
        for c in _physical(judged)
        if "smooth" in c.structure.friction and "stribeck" not in c.structure.friction
    ]
    if not smooth:
        return []
    chosen = _chosen(judged)
    starts = [min(smooth, key=lambda c: c.score), *[c for c in smooth if c.structure == chosen]]
    out: list[Candidate] = []
    for start in dict.fromkeys(starts):
        group = groups[where[start.structure]]
        reached = per_joint_widths(
            start, regressor_widths(group[1]), n, _judge_in(group, rtol), _better
        )
        if reached is not start and reached.structure not in [c.structure for c in out]:
            where[reached.structure] = where[start.structure]
            out.append(reached)
    return out


def _smooth_bumps(
    judged: Sequence[Candidate],
    cands: Sequence[Structure],
    off: _OffGrid,
) -> list[Candidate]:
    """The Stribeck bump on the smooth sign at the width of the smooth law that predicts
    held-out data best (:func:`~.bumps.bump_widths`; one width or, from
    :func:`_widths_per_joint`, one per joint) at each Stribeck velocity of ``cands``,
    the widths walked along those of ``cands``' smooth laws: the candidates not judged
    yet, each width's fitted in a regressor of its own and judged (:meth:`_OffGrid.judged`,
    without the recordings ``off.skip``). None when
    ``cands`` hold no Stribeck law, no smooth law was judged, or the best predicts no
    better than the laws without a Coulomb term (beyond one standard error)."""
    smooth = [c for c in _physical(judged) if _plain_smooth(c.structure)]
    vsts = sorted({c.vst for c in cands if "stribeck" in c.friction and isinstance(c.vst, float)})
    if not smooth or not vsts:
        return []
    start = min(smooth, key=lambda c: c.score)
    signless = [
        c for c in _physical(judged) if not {"coulomb", "smooth"} & set(c.structure.friction)
    ]
    if signless and not _better(start, min(signless, key=lambda c: c.score)):
        return []  # no Coulomb friction in the data: no bump on it either
    widths = sorted({c.width for c in cands if _plain_smooth(c) and isinstance(c.width, float)})
    mine = {(c.structure, off.where.get(c.structure)): c for c in judged}
    new: list[Candidate] = []

    def at_width(w: float | tuple[float, ...]) -> list[Candidate]:
        structures = smooth_stribeck_candidates(replace(start.structure, width=w), vsts)
        key = regressor_group(structures[0])
        if any(regressor_group(c) == key for c in cands):  # in the grid: judged already
            return [m for s in structures if (m := mine.get((s, key))) is not None]
        out = off.judged(list(structures))
        new.extend(out)
        return out

    bump_widths(start, widths, at_width, _better)
    return new


def _refined_width(judged: Sequence[Candidate], off: _OffGrid, notes: list[str]) -> list[Candidate]:
    """The smooth Coulomb law of one width that predicts held-out data best, its width
    refined between its grid neighbours on the held-out error
    (:func:`~.shape_refinement.refined_shape`, from the scores of the same law at the
    grid's widths), once the Stribeck bumps are judged (from the grid's widths: a smooth
    law without its bump is fitted at a width rounded to make up for it, the start of the
    bump's walk, :mod:`~.bumps`, not its answer): the candidates judged at the
    new widths (each width's fitted in a regressor of its own and recorded,
    :meth:`_OffGrid.judged`), said in ``notes`` when one predicts better than the
    grid's; none when no such law was judged, the best predicts no better than the laws
    without a Coulomb term (beyond one standard error: no Coulomb friction in the data) or
    a law of the banded sign predicts better than it (beyond one standard error)."""
    smooth = [
        c
        for c in _physical(judged)
        if _plain_smooth(c.structure)
        and isinstance(c.structure.width, float)
        and not c.structure.drop
        and not c.skipped
    ]
    if not smooth:
        return []
    start = min(smooth, key=lambda c: c.score)
    signless = [
        c for c in _physical(judged) if not {"coulomb", "smooth"} & set(c.structure.friction)
    ]
    if signless and not _better(start, min(signless, key=lambda c: c.score)):
        return []  # no Coulomb friction in the data: no width to refine
    banded = [c for c in _physical(judged) if "coulomb" in c.structure.friction]
    if banded and _better(min(banded, key=lambda c: c.score), start):
        return []  # a sharp sign predicts better: the smooth law is not in the running
    full = start.structure
    scores = {
        c.structure.width: c.score
        for c in smooth
        if isinstance(c.structure.width, float)
        and c.structure == replace(full, width=c.structure.width)
    }
    new: list[Candidate] = []

    def at(w: float) -> float | None:
        mine = replace(full, width=w)
        new.extend(off.judged([mine], "structure search, the smooth width", value=f"{w:g}"))
        return next((c.score for c in new if c.structure == mine and not c.skipped), None)

    assert isinstance(full.width, float)  # one width: the smooth laws of the grid
    tried = refined_shape(scores, full.width, at, probe=True)
    best = min([start, *(c for c in new if not c.skipped)], key=lambda c: c.score)
    if best is not start:
        new += _siblings_at(best.structure, smooth, off)
        grid = sorted(scores)
        k = grid.index(full.width)
        lo, hi = grid[max(k - 1, 0)], grid[min(k + 1, len(grid) - 1)]
        notes.append(
            f"smooth Coulomb width refined on held-out data between the grid's {lo:g} and "
            f"{hi:g} bands ({len(tried)} more fit(s), at {', '.join(f'{w:g}' for w in tried)}): "
            f"smooth:{width_text(best.structure.width)}, held-out error "
            f"{best.heldout_error_percent:.4g} % (at the grid's {full.width:g}: "
            f"{start.heldout_error_percent:.4g} %)"
        )
    return new


def _siblings_at(refined: Structure, smooth: Sequence[Candidate], off: _OffGrid) -> list[Candidate]:
    """The other smooth laws of one width judged on the grid (``smooth``: with and
    without the armature, the offset), each at the refined width of ``refined`` (fitted
    in a regressor per armature choice and placement, :meth:`_OffGrid.judged`): the
    terms the grid's best left out at a grid width far from the data's (an offset, an
    armature whose columns a misshapen sign pulled) judged again where the sign fits,
    so that the choice weighs them at that width too."""
    w = refined.width
    mine = [replace(c.structure, width=w) for c in smooth]
    rest = [s for s in dict.fromkeys(mine) if s != refined]
    out: list[Candidate] = []
    for key in dict.fromkeys(regressor_group(s) for s in rest):
        group = [s for s in rest if regressor_group(s) == key]
        group.sort(key=lambda s: -len(s.friction))  # the largest first: its regressor
        out += off.judged(group, "structure search, the smooth width", value=f"{w:g} terms")
    return out


def _refined_stribeck(judged: list[Candidate], off: _OffGrid, notes: list[str]) -> Structure:
    """The structure chosen (:func:`_chosen`) with its Stribeck velocity refined between
    its grid neighbours on the held-out error (:func:`~.shape_refinement.refined_shape`,
    driven by the scores of the chosen law without its coefficients left out at the grid's
    velocities): the candidates judged at the new velocities appended to ``judged`` (each
    velocity's fitted in a regressor of its own and recorded, :meth:`_OffGrid.judged`),
    and the structure of lowest held-out error among the chosen and those at its
    coefficients, dissipative, said in ``notes``; the chosen itself where it holds no
    Stribeck law or its grid was not judged."""
    chosen = _chosen(judged)
    if "stribeck" not in chosen.friction or not isinstance(chosen.vst, float):
        return chosen
    full = replace(chosen, drop=())
    scores = {
        c.structure.vst: c.score
        for c in judged
        if c.structure == replace(full, vst=c.structure.vst)
        and isinstance(c.structure.vst, float)
        and not c.unphysical
    }
    new: list[Candidate] = []

    def at(v: float) -> float | None:
        mine = [replace(full, vst=v), *([replace(chosen, vst=v)] if chosen.drop else [])]
        new.extend(off.judged(mine, "structure search, the Stribeck velocity", value=f"{v:g}"))
        return next((c.score for c in new if c.structure == mine[0]), None)

    tried = refined_shape(scores, chosen.vst, at)
    here = [c for c in judged if c.structure == chosen]
    judged += new
    same = [c for c in new if c.structure.drop == chosen.drop and not c.skipped]
    best = min(here + same, key=lambda c: c.score, default=None)
    if best is None or not here or not tried:
        return chosen
    grid = sorted(scores)
    k = grid.index(chosen.vst)
    lo, hi = grid[max(k - 1, 0)], grid[min(k + 1, len(grid) - 1)]
    notes.append(
        f"Stribeck velocity refined on held-out data between the grid's {lo:g} and {hi:g} "
        f"rad/s ({len(tried)} more fit(s), at {', '.join(f'{v:g}' for v in tried)}): "
        f"{best.structure.vst:g} rad/s, held-out error {best.heldout_error_percent:.4g} % "
        f"(at the grid's {chosen.vst:g}: {here[0].heldout_error_percent:.4g} %)"
    )
    return best.structure


def _stribeck_joints(
    chosen: Structure, judged: list[Candidate], off: _OffGrid, n: int, notes: list[str]
) -> Structure:
    """``chosen`` with a Stribeck velocity per joint where that predicts held-out data
    better (:func:`~.stribeck_joints.per_joint_vst`; each round's trial velocities fitted
    in one regressor, :meth:`_OffGrid.judged`): the candidates judged appended to
    ``judged``, said in ``notes`` when the velocities differ; ``chosen`` itself where it
    holds no Stribeck law of one velocity."""
    start = next((c for c in judged if c.structure == chosen), None)
    if start is None or "stribeck" not in chosen.friction or not isinstance(chosen.vst, float):
        return chosen

    def at(structures: list[Structure], r: int) -> list[Candidate | None]:
        what = "structure search, the Stribeck velocity per joint"
        got = {c.structure: c for c in off.judged(structures, what, value=f"per joint {r}")}
        return [got.get(x) for x in structures]

    reached, new = per_joint_vst(start, n, at, _lower_beyond_se)
    judged += [c for c in new if c.structure != chosen]
    if reached is start:
        return chosen
    notes.append(
        f"Stribeck velocity chosen per joint on held-out data ({len(new)} more candidate(s) "
        f"judged, each joint's alone against the common {chosen.vst:g} rad/s): "
        f"stribeck:{width_text(reached.structure.vst)}, held-out error "
        f"{reached.heldout_error_percent:.4g} % (at the common velocity: "
        f"{start.heldout_error_percent:.4g} %)"
    )
    return reached.structure


@dataclass(frozen=True)
class _OffGrid:
    """What judging structures off the grid needs (a smooth width, a Stribeck velocity, a
    bump's width): ``fit`` fits one regressor group (with its step's label), ``groups``,
    ``by_group`` and ``where`` record each new regressor and its folds as the grid's are
    recorded (updated in place), ``skip`` the recordings left out of the judgement and
    ``rtol`` the fit's rank tolerance."""

    fit: Callable[..., list[Fitted]]
    groups: _Groups
    by_group: _Folds
    where: dict[Structure, _Key]
    skip: tuple[int, ...]
    rtol: float

    def judged(self, structures: list[Structure], *label: str, value: str = "") -> list[Candidate]:
        """``structures`` (one regressor group) fitted in a regressor of their own (``label``:
        the step's, else ``fit``'s default) and judged on its folds (the recordings
        ``skip`` left out); the regressor's key that of ``structures[0]`` with each
        family's name, followed by ``value`` (the shape parameter off the grid) when
        given."""
        out: list[Candidate] = []
        first = structures[0]
        for family, model, terms, held in self.fit(structures, *label):
            own = (first.armature, first.at, f"{family} {value}" if value else family)
            self.groups[own] = (model, terms)
            folds = without_recordings(model, self.skip) if self.skip else heldout_of(model)
            self.by_group[own] = (model, terms, folds)
            for c in held:
                self.where[c] = own
                use = candidate_columns(c, model, terms)
                out.append(_judged(c, use, model, terms, folds, self.rtol))
        return out


def _plain_smooth(c: Structure) -> bool:
    """A smooth Coulomb law without a Stribeck bump."""
    return "smooth" in c.friction and "stribeck" not in c.friction


def _judge_in(
    group: tuple[IdentifiedModel, list[tuple[ModelTerm, Any]], HeldOut], rtol: float
) -> Callable[[Structure], Candidate]:
    """A structure judged on the folds of the regressor ``group`` (its model, terms and
    folds)."""
    model, terms, held = group
    return lambda s: _judged(s, candidate_columns(s, model, terms), model, terms, held, rtol)


def _better(c: Candidate, than: Candidate) -> bool:
    """Whether ``c`` predicts held-out data better than ``than`` beyond one standard
    error of the difference (``than`` not :func:`_within` it)."""
    return not _within(than, c)


def _lower_beyond_se(c: Candidate, than: Candidate) -> bool:
    """Whether ``c``'s held-out error is below ``than``'s by more than one standard error
    of the difference, paired over the folds (:func:`~.candidates.paired_se`), without
    :func:`_within`'s tie of 1 % of the lowest: the choice between one joint's shapes, of
    as many coefficients, whose difference is that joint's alone (its torques in units of
    its own noise) but read on the error pooled over every joint, where 1 % of the pooled
    error hid a joint's Stribeck velocity (0.0812 against 0.0934 rad/s, 5.4 standard
    errors, for a true 0.08)."""
    return c.score < than.score - max(paired_se(c, than), ERROR_FLOOR_PERCENT)


def _per_joint(
    judged: Sequence[Candidate],
    groups: _Folds,
    n: int,
    rtol: float,
    where: dict[Structure, _Key],
) -> list[Candidate]:
    """Per-joint structures: from the candidate with the lowest held-out error and from
    the one chosen, friction coefficients and armatures (rotors that are base parameters
    of their own) of single joints left out one at a time (the one whose absence the
    held-out data miss least first) while the held-out error stays within one standard
    error of the lowest, none that the fit it is left out of determines
    (:meth:`~.candidates.Candidate.determined`); the candidates reached, when they hold
    fewer coefficients than where they started.

    When the lowest held-out error is a candidate whose friction is not dissipative, its
    offending coefficients are left out first (:func:`_repaired`): a joint's small
    negative viscous coefficient does not cost the whole candidate its place."""
    best_any = min(judged, key=lambda c: c.score)
    best = min(_physical(judged), key=lambda c: c.score)
    repaired = None
    if best_any.skipped and not best.skipped:
        group = groups[where[best_any.structure]]
        repaired = _repaired(_without_bumps(best_any, *group, rtol), *group, n, rtol)
        if repaired is not None:
            where[repaired.structure] = where[best_any.structure]
    starts = [best, *([] if repaired is None else [repaired])]
    best = min(starts, key=lambda c: c.score)
    chosen = _chosen(judged)
    starts += [c for c in judged if c.structure == chosen][:1]
    out: list[Candidate] = []
    for start in dict.fromkeys(starts):
        if not start.structure.friction and not start.structure.armature:
            continue
        model, terms, held = groups[where[start.structure]]
        here = start
        while True:
            trials = [
                c
                for c in _dropped(here, model, terms, held, n, rtol, keep=here.determined())
                if not c.skipped or here.skipped
            ]
            step = min(trials, key=lambda c: c.score, default=None)
            if step is None or not _within(step, best):
                break
            here = step
        drive = model.drive if start.structure.at == "both" else None
        reached = here.structure.collapsed(n, () if drive is None else joint_side_joints(drive))
        if reached not in [c.structure for c in (*judged, *out)]:
            where[reached] = where[start.structure]
            origin = best_any.structure if start is repaired else start.structure
            left = tuple(lab for lab in here.structure.drop if lab not in origin.drop)
            out.append(replace(here, structure=reached, left_out=left))
    return out


def _dropped(
    here: Candidate,
    model: IdentifiedModel,
    terms: list[tuple[ModelTerm, Any]],
    held: HeldOut,
    n: int,
    rtol: float,
    among: Collection[str] | None = None,
    keep: Collection[str] = (),
) -> list[Candidate]:
    """``here`` with one more coefficient left out (one of ``among`` when given, none of
    ``keep``), every way, judged."""
    rotors = tuple(own_rotors(model.base, n))
    return [
        _judged(s, candidate_columns(s, model, terms), model, terms, held, rtol)
        for s in (
            replace(here.structure, drop=here.structure.drop + (lab,))
            for lab in coefficient_labels(here.structure, n, rotors)
            if (among is None or lab in among) and lab not in keep
        )
    ]


def _without_bumps(
    here: Candidate,
    model: IdentifiedModel,
    terms: list[tuple[ModelTerm, Any]],
    held: HeldOut,
    rtol: float,
) -> Candidate:
    """``here`` without its Stribeck coefficients below zero
    (:attr:`~.candidates.Candidate.negative_bump`): on those joints the law without the
    bump, judged; ``here`` itself when it has none, and :func:`_repaired`'s input."""
    for _ in range(len(here.structure.drop) + 8):  # a joint's bump at a time turns negative
        if not here.negative_bump:
            break
        s = replace(here.structure, drop=here.structure.drop + here.negative_bump)
        here = _judged(s, candidate_columns(s, model, terms), model, terms, held, rtol)
    return here


def _label_key(label: str) -> tuple[str, int]:
    """A coefficient's label in joint order: ``fsp2`` before ``fsp10``."""
    head = label.rstrip("0123456789")
    return head, int(label[len(head) :] or 0)


def _repaired(
    here: Candidate,
    model: IdentifiedModel,
    terms: list[tuple[ModelTerm, Any]],
    held: HeldOut,
    n: int,
    rtol: float,
) -> Candidate | None:
    """``here`` (friction not dissipative somewhere) with friction coefficients of the
    joints not dissipative left out one at a time, each step the one that leaves the
    fewest such joints, then the fewest coefficients below zero, at the lowest held-out
    error, until its friction is dissipative; None when a step adds such a joint.

    The other joints keep theirs, and a joint may need several steps: a torque of the
    opposite sign gives ``fv6`` and ``fc6`` below zero, and leaving out ``fc6`` alone can
    turn ``fv6`` negative (counting joints alone called such steps no help, and every
    joint lost its friction for one)."""

    def left(c: Candidate) -> tuple[int, int]:
        return len(c.unphysical), sum(len(v.labels) for v in c.unphysical)

    if here.negative_bump:  # new bumps below zero: the bump has no place there either
        return None

    while here.unphysical:
        parts = [p for p in here.structure.friction if p != "offset"]  # no friction of motion
        mine = frozenset(f"{PART_LABELS[p]}{v.joint + 1}" for v in here.unphysical for p in parts)
        step = min(
            _dropped(here, model, terms, held, n, rtol, mine),
            key=lambda c: (*left(c), c.score),
            default=None,
        )
        if step is None or len(step.unphysical) > len(here.unphysical):
            return None
        here = step
    return here


@shared_steps()
@shared_eigen()
def identify_recordings(
    robot: Robot,
    logs: Sequence[TorqueLog],
    names: Sequence[str] | None = None,
    *,
    structure: Structure | Literal["auto"] = "auto",
    cutoff_hz: float | Literal["auto"] | None = "auto",
    trim_s: float | None = None,
    max_gap_s: float | None = None,
    decimate: int | None = None,
    drive: Drive | None = None,
    estimator: EstimatorName | Estimator | Literal["auto"] = "auto",
    std: StdMethod = "hac",
    max_std_percent: float | None = None,
    rtol: float | None = None,
    folds: int = DEFAULT_FOLDS,
    validate_on: TorqueLog | None = None,
    friction: tuple[str, ...] | None = None,
    base: BaseParameters | None = None,
    torque_delay_s: float = 0.0,
    keep_outlying: bool = False,
    spring_joints: Sequence[int] = (),
) -> IdentifiedModel:
    """Identify the base parameters and the model's terms from one or more torque logs.

    Each recording (each piece between its gaps) prepared on its own (:func:`~.recordings.
    prepare_recordings`), the structure chosen on held-out data (:func:`select_structure`)
    or given (:func:`_fitted_given`) is fitted on all but the recordings found outlying; of
    one or two, the spans holding the fit's own residual are cut out (:func:`_burst_cuts`).

    Parameters
    ----------
    robot : Robot
        Kinematics and gravity; its inertial parameters are not used.
    logs, names : sequence of TorqueLog, sequence of str (optional)
        The recordings, and their names (file names) for messages and the record.
    structure : Structure or "auto"
        The terms beside the links; ``"auto"`` (default) chooses them on held-out data,
        a spring on ``spring_joints`` (0-based) judged too (:mod:`.spring_candidate`).
    cutoff_hz : float, "auto" or None
        Zero-phase low-pass cut-off [Hz] of every recording; ``"auto"`` (default) read from
        their motion (:func:`~.trim.common_cutoff`), none for logs exact to round-off;
        None for noise-free data (the logs' ``ddq`` used if present, else differentiated).
    trim_s, max_gap_s, torque_delay_s
        As :func:`~dynid.identification.recordings.prepare_recordings` (recorded).
    decimate : int, optional
        Keep every ``decimate``-th sample after filtering; default :func:`~.rate.decimation`
        (at least 10 % of the samples).
    drive : Drive, optional
        The drive train the logs were recorded through (:mod:`dynid.model.drive`); default:
        link-side torques of a direct drive.
    estimator, std
        Least squares (``"auto"``: ols or wls chosen, :mod:`.estimator_choice`); standard
        deviations ``"hac"`` (default), ``"robust"`` or ``"classical"`` (:func:`~.core.identify`).
    max_std_percent : float, optional
        Remove coefficients with a larger relative standard deviation [%] and re-fit.
    rtol : float, optional
        Relative rank tolerance of the base parameters and of the least squares (default:
        the first clear gap of the singular values, and ``1e-10``).
    folds : int
        Contiguous time blocks of one recording's held-out judgement (several recordings:
        one left out at a time).
    validate_on : TorqueLog, optional
        Judge on this separate recording instead.
    friction : tuple of str, optional
        The friction parts fitted whatever the chosen structure holds (its armature and
        placement kept; the consistent fit's classical parts): the data prepared once.
    base : BaseParameters, optional
        The base parameters of a structure given (default: the structural ones).
    keep_outlying : bool
        Fit the recordings found outlying (structure chosen or given) and the bursts of one
        or two whole (default: left out or cut, in their ``info.recordings`` entry, warned).

    Returns
    -------
    IdentifiedModel
        With ``info.selection`` (the candidates and the choice) when the structure was
        chosen, ``info.estimator_choice`` when the estimator was, and ``info.recordings``.

    Raises
    ------
    DataError, ShapeError
        From :func:`~dynid.identification.recordings.prepare_recordings`; a DataError
        too where the friction shows a joint's torque sign flipped (:func:`reversed_friction`).
    OptionError
        An armature asked with known rotor inertias; a friction placement (``at:``)
        without a drive that couples joints; ``base`` with ``structure="auto"``.
    RankDeficientError
        The chosen (or given) structure is not identifiable from the data.
    """
    _check_given(structure, drive, base)
    exact, cutoff_hz = _exact(logs, cutoff_hz)  # nothing to filter: it would bend the motion
    prep = {"torque_delay_s": torque_delay_s, "cutoff_hz": cutoff_hz, "trim_s": trim_s}
    prep |= {"max_gap_s": max_gap_s, "decimate": decimate}
    data, validation = _recordings(robot, logs, names, validate_on, drive, **prep)
    est = None if estimator == "auto" else estimator_named(estimator)  # None: chosen
    selection, structure, fitted, validation, gone = _choose(
        robot, logs, data, validation, validate_on, drive, friction, keep_outlying, structure,
        exact, estimator=est or OLS(), folds=folds, rtol=rtol, prep=prep, spring=spring_joints,
    )  # fmt: skip
    kw: dict[str, Any] = dict(std=std, base=base, rtol=rtol, max_std_percent=max_std_percent)
    kw["advise"] = False  # the final fit's advice alone (_warned), not the fits before it
    model, terms, fitted, odd, given = _fitted_chosen(
        robot, logs, fitted, structure, drive, folds, validation, keep_outlying, prep,
        judge=selection is None, estimator=est, **kw,
    )  # fmt: skip
    if bursts := {} if gone or keep_outlying else _burst_cuts(robot, model, terms, data, logs):
        gone, (selection, structure, fitted, validation, given, model, terms) = bursts, _cut_refit(
            robot, logs, data, bursts, selection, structure, validate_on, drive, friction,
            given, estimator=est, folds=folds, prep=prep, **kw,
        )  # fmt: skip
    _warned(model, terms)
    if selection is not None and structure == selection.chosen:
        selection = with_differing(_per_recording_of(model, selection, gone), data)
    heldout = _heldout_record(model, fitted if validation is None else validation)
    combined = _combined(robot, fitted, structure, drive, model.base)
    model = _recorded(model, exact, combined, heldout, structure, selection, given)
    gone |= odd  # left out (or cut) by the choice (auto) or under the structure given
    return _with_left_out(model, data, gone, fitted) if gone else model


def _warned(model: IdentifiedModel, terms: Sequence[ModelTerm]) -> None:
    """The final fit's warnings: its friction where not dissipative (:func:`~.dissipation.
    warn_unphysical`) and its conditioning advice (:func:`~.core.model_advice`). The fits
    before it (the other estimator's, those with recordings left out or spans cut) say
    none: a UR5's ols fit named ``beta19 (1.08e+03 %)`` above a table whose wls fit has
    ``beta19`` at 50.5 %."""
    warn_unphysical(model, terms)
    for msg in model_advice(model):
        warnings.warn(msg, DynidWarning, stacklevel=caller_level())


def _check_given(
    structure: Structure | Literal["auto"], drive: Drive | None, base: BaseParameters | None
) -> None:
    """A structure given checked against ``drive`` (:func:`~.structure.check_placement`);
    ``base`` refused with one chosen (an OptionError)."""
    if isinstance(structure, Structure):
        check_placement(structure, drive)
    elif base is not None:
        raise OptionError("base applies to a structure given, not to one chosen (auto)")


def _cut_refit(
    robot: Robot,
    logs: Sequence[TorqueLog],
    data: Recordings,
    cuts: _Gone,
    selection: Selection | None,
    structure: Structure,
    validate_on: TorqueLog | None,
    drive: Drive | None,
    friction: tuple[str, ...] | None,
    given: dict[str, Any],
    *,
    estimator: Estimator | None,
    folds: int,
    prep: dict[str, Any],
    **kw: Any,
) -> tuple[
    Selection | None,
    Structure,
    Recordings,
    Recordings | None,
    dict[str, Any],
    IdentifiedModel,
    tuple[ModelTerm, ...],
]:
    """The recordings of ``logs`` with the intervals ``cuts`` cut out of them prepared on
    their own, the structure chosen again on them where it was chosen (``selection``,
    :func:`_chosen_without`, its record holding the cuts as an outlying recording's)
    or ``structure`` as given (its record ``given`` holding them), and fitted once
    (:func:`_fitted_chosen` with ``estimator``, None: chosen, and ``kw``); returns the
    selection, the structure, the recordings, the separate validation prepared as they
    are, the record of a structure given, the model and its terms."""
    cut = tuple((data.names[k], c) for k, c in cuts.items())
    if selection is not None:
        joints = tried_joints(selection)  # a spring tried before the cut: tried again
        fitted, validation, selection, structure = _chosen_without(
            robot, logs, data, cuts, replace(selection, cut=cut), validate_on, drive,
            friction, estimator=estimator or OLS(), folds=folds, rtol=kw.get("rtol"), **prep,
        )  # fmt: skip
        if joints:
            sel = (selection, joints, estimator or OLS(), folds, kw.get("rtol"))
            selection, structure = _spring_searched(
                robot, fitted, validation, drive, friction, *sel
            )
    else:
        with warnings.catch_warnings():
            warnings.simplefilter("ignore")  # said when all were prepared
            fitted, validation = _recordings(
                robot, [cut_log(log, cuts.get(i, ())) for i, log in enumerate(logs)],
                data.names, validate_on, drive, **prep,
            )  # fmt: skip
        given = {**given, "cut_out_spans": cut_record(cut)}
    model, terms, fitted, _, _ = _fitted_chosen(
        robot, logs, fitted, structure, drive, folds, validation, False, prep, judge=False,
        estimator=estimator, **kw,
    )  # fmt: skip
    return selection, structure, fitted, validation, given, model, terms


def _fitted_chosen(
    robot: Robot,
    logs: Sequence[TorqueLog],
    data: Recordings,
    structure: Structure,
    drive: Drive | None,
    folds: int,
    validation: Recordings | None,
    keep: bool,
    prep: dict[str, Any],
    *,
    estimator: Estimator | None,
    judge: bool,
    **kw: Any,
) -> tuple[IdentifiedModel, tuple[ModelTerm, ...], Recordings, _Gone, dict[str, Any]]:
    """:func:`_fitted_given` with ``estimator``; None: with ols, then ols or wls chosen on
    the folds of the recordings it fitted (:func:`_estimator_chosen`, ``kw`` as
    :func:`_fitted` takes them)."""
    model, terms, fitted, odd, given = _fitted_given(
        robot, logs, data, structure, drive, folds, validation, keep, prep, judge=judge,
        estimator=estimator or OLS(), **kw,
    )  # fmt: skip
    if estimator is None:
        model = _estimator_chosen(robot, fitted, structure, drive, folds, validation, model, **kw)
    return model, terms, fitted, odd, given


def _choose(
    robot: Robot,
    logs: Sequence[TorqueLog],
    data: Recordings,
    validation: Recordings | None,
    validate_on: TorqueLog | None,
    drive: Drive | None,
    friction: tuple[str, ...] | None,
    keep_outlying: bool,
    given: Structure | Literal["auto"],
    exact: tuple[str, ...],
    *,
    estimator: Estimator,
    folds: int,
    rtol: float | None,
    prep: dict[str, Any],
    spring: Sequence[int] = (),
) -> tuple[Selection | None, Structure, Recordings, Recordings | None, _Gone]:
    """The structure chosen on ``data`` (:func:`select_structure`, the notes ``exact``
    first) and fitted with ``friction``, and the recordings it is fitted on: with
    recordings found outlying and not ``keep_outlying``, chosen again on the others
    prepared alone, those whose spans are cut out with them (:func:`_chosen_without`);
    returns the selection, the structure, the recordings fitted, the separate validation
    prepared as they are, and the outlying ones (:data:`_Gone`). A structure ``given``
    (not ``"auto"``): no selection, it and ``data`` as they are. With ``spring`` (joints,
    0-based), a spring on them judged against the choice (:mod:`.spring_candidate`)."""
    if given != "auto":
        return None, given, data, validation, {}
    selection = select_structure(
        robot, data, drive=drive, estimator=estimator, folds=folds, validation=validation,
        rtol=rtol, keep=keep_outlying,
    )  # fmt: skip
    selection = selection and replace(selection, notes=(*exact, *selection.notes))
    structure = _fitted_structure(robot, data, selection, friction)
    gone = {} if selection is None or keep_outlying else _outlying(data, selection)
    if gone and selection is not None:
        data, validation, selection, structure = _chosen_without(
            robot, logs, data, gone, selection, validate_on, drive, friction,
            estimator=estimator, folds=folds, rtol=rtol, **prep,
        )  # fmt: skip
    if spring and selection is not None:  # a spring the held-out residual names
        sel = (selection, spring, estimator, folds, rtol)
        selection, structure = _spring_searched(robot, data, validation, drive, friction, *sel)
    return selection, structure, data, validation, gone


def _spring_searched(
    robot: Robot,
    data: Recordings,
    validation: Recordings | None,
    drive: Drive | None,
    friction: tuple[str, ...] | None,
    selection: Selection,
    joints: Sequence[int],
    estimator: Estimator,
    folds: int,
    rtol: float | None,
) -> tuple[Selection, Structure]:
    """``selection`` judged against the search with a spring on ``joints`` (0-based) on
    the same recordings and folds (:func:`~.spring_candidate.with_spring`), and the
    structure it keeps, fitted with ``friction`` (:func:`_fitted_structure`)."""
    again = partial(
        select_structure, robot, data, drive=drive, estimator=estimator, folds=folds,
        validation=validation, rtol=rtol, keep=True,
    )  # fmt: skip
    selection = with_spring(selection, joints, robot.n, drive, again)
    return selection, _fitted_structure(robot, data, selection, friction)


def _chosen_without(
    robot: Robot,
    logs: Sequence[TorqueLog],
    data: Recordings,
    gone: _Gone,
    first: Selection,
    validate_on: TorqueLog | None,
    drive: Drive | None,
    friction: tuple[str, ...] | None,
    *,
    estimator: Estimator,
    folds: int,
    rtol: float | None,
    **kw: Any,
) -> tuple[Recordings, Recordings | None, Selection, Structure]:
    """The recordings of ``logs`` but ``gone`` (those of its intervals cut out of them
    kept without those, :func:`cut_log`) prepared on their own (``kw`` as
    :func:`~.recordings.prepare_recordings` takes them), the separate ``validate_on``
    prepared as they are, the structure chosen on them (:func:`select_structure`, none
    left out again; ``friction`` as :func:`identify_recordings` takes it) and its record
    holding ``first``'s outlying recordings, their per-recording
    errors and note: the model of every recording but the outlying ones is the one of those
    recordings given alone, their common cut-off, decimation and standstill band too (an
    outlying xArm7 recording's share in them had dropped joint 7's armature, 9.6 % off the
    truth there against 1.0 %). The recordings' findings were said when all were
    prepared."""
    kept = [i for i in range(len(logs)) if gone.get(i, True)]
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        clean, validation = _recordings(
            robot, [cut_log(logs[i], gone.get(i, ())) for i in kept],
            [data.names[i] for i in kept], validate_on, drive, **kw,
        )  # fmt: skip
    found = select_structure(
        robot, clean, drive=drive, estimator=estimator, folds=folds, validation=validation,
        rtol=rtol, keep=True,
    )  # fmt: skip
    if found is None:  # (no candidate to choose among: the first choice stands)
        return clean, validation, first, _fitted_structure(robot, clean, first, friction)
    odd = tuple(n for n in first.notes if n.startswith(tuple(f"{o}: " for o in first.outlying)))
    mine = dict(found.per_recording)  # the others' held-out errors without the outlying ones
    per = tuple(
        (n, mine.get(n, e)) for n, e in first.per_recording if n in mine or n in first.outlying
    )
    chosen = replace(
        found, outlying=first.outlying, per_recording=per, notes=(*odd, *found.notes), cut=first.cut
    )
    return clean, validation, chosen, _fitted_structure(robot, clean, chosen, friction)


def fitted_logs(model: IdentifiedModel, logs: Sequence[_T]) -> list[_T]:
    """Of ``logs`` (one per recording, in the order given to :func:`identify_recordings`),
    those ``model`` was fitted on: all but those its record marks ``left_out``, a torque
    log whose record holds ``cut_out`` intervals without them (:func:`cut_log`)."""
    recs = model.info.recordings or ()
    if len(recs) != len(logs):
        return list(logs)
    out = []
    for log, r in zip(logs, recs, strict=True):
        cut = tuple((float(a), float(b)) for a, b in r.get("cut_out") or ())
        if not r.get("left_out"):
            out.append(cut_log(log, cut) if cut and isinstance(log, TorqueLog) else log)
    return out  # type: ignore[return-value]  # a TorqueLog cut is a TorqueLog


def _estimator_chosen(
    robot: Robot,
    data: Recordings,
    structure: Structure,
    drive: Drive | None,
    folds: int,
    validation: Recordings | None,
    plain: IdentifiedModel,
    *,
    rtol: float | None,
    **kw: Any,
) -> IdentifiedModel:
    """Of ``plain`` (``structure`` fitted by ordinary least squares) and the weighted fit
    of the same structure on the same folds (:func:`_fitted` with ``kw``), the one
    :func:`~.estimator_choice.choose_estimator` keeps, its choice in its record
    (``info.estimator_choice``); ``plain`` alone without held-out folds or the joints'
    noise (nothing to judge on)."""
    if plain.holdout is None or not plain.holdout.whitened:
        return plain
    with stage("the estimator's choice, the weighted fit", rows=data.n_rows):
        weighted, _ = _fitted(
            robot, data, structure, drive, folds, validation, estimator=WLS(), rtol=rtol, **kw
        )  # fmt: skip
    fits = [("ols", plain), ("wls", weighted)]
    choice = choose_estimator(structure, fits, 1e-10 if rtol is None else rtol)
    if choice is None:
        return plain
    kept = weighted if choice.chosen == "wls" else plain
    return replace(kept, info=replace(kept.info, estimator_choice=choice.as_dict()))


def _with_left_out(
    model: IdentifiedModel, data: Recordings, gone: _Gone, fitted: Recordings
) -> IdentifiedModel:
    """``model``, fitted on ``fitted`` (the recordings of ``data`` but those ``gone`` left
    out, those it cuts spans out of without them), with every recording in its record
    (``info.recordings``, :meth:`~.recordings.Recordings.summary`: the fitted ones as
    ``fitted`` prepared them), those left out marked ``left_out``, those cut with their
    ``cut_out`` intervals ([s], ``[t0, t1]`` each)."""
    mine = iter(fitted.summary())
    recordings = tuple(
        {**r, "left_out": True}
        if i in gone and not gone[i]
        else _cut_record(next(mine), r, gone.get(i, ()))
        for i, r in enumerate(data.summary())
    )
    return replace(model, info=replace(model.info, recordings=recordings))


def _cut_record(fitted: dict[str, Any], whole: dict[str, Any], cut: _Cut) -> dict[str, Any]:
    """A recording's record as fitted, and with the intervals ``cut`` out of it: those
    (``cut_out``, ``[t0, t1]`` [s] each) and the samples they held (``cut_samples``, of
    ``whole``'s ``recorded``; ``recorded`` is what was left), the ``sha256`` of the
    recording as read (``whole``'s: ``payload --model`` knows the file by it). The
    ``gaps`` the cuts leave in the stamps are not the recording's (a burst cut out, not a
    gap: :func:`_gaps_not_cut`)."""
    if not cut:
        return fitted
    gone = int(whole.get("recorded", 0)) - int(fitted.get("recorded", 0))
    out = {**fitted, "cut_out": [list(c) for c in cut], "cut_samples": gone}
    out.pop("gaps", None)
    out |= {"gaps": gaps} if (gaps := _gaps_not_cut(fitted.get("gaps") or (), cut)) else {}
    return out | ({"sha256": whole["sha256"]} if "sha256" in whole else {})


def _gaps_not_cut(gaps: Any, cut: _Cut) -> list[list[float]]:
    """Of a recording's ``gaps`` (``[t_before, length]`` [s] each), those no interval of
    ``cut`` ([s], ``(t0, t1)`` each) lies in: the recording's own."""
    return [[float(t), float(n)] for t, n in gaps if not any(t <= b and a <= t + n for a, b in cut)]


def _recorded(
    model: IdentifiedModel,
    exact: tuple[str, ...],
    combined: dict[str, str],
    heldout: Any,
    structure: Structure,
    selection: Selection | None,
    given: dict[str, Any] | None = None,
) -> IdentifiedModel:
    """``model`` with its record completed: the note of exact logs (their cut-off source
    ``"exact"``: validate reads a noisy log's own), the combined coefficients, the held-out
    record, the warned negative inertias, the terms and the structure's selection (or,
    given, its recordings' judgement ``given``, :func:`_fitted_given`)."""
    notes = (*exact, *model.info.notes, *warned_negative_inertias(model))
    info = replace(model.info, combined=combined, heldout=heldout, notes=notes)
    if exact and info.log is not None:
        info = replace(info, log=replace(info.log, cutoff_source="exact"))
    extra = {**model.info.extra, "terms": list(structure.terms), **(given or {})}
    info = replace(info, selection=None if selection is None else selection.as_dict(), extra=extra)
    return replace(model, info=info)


def _exact(
    logs: Sequence[TorqueLog], cutoff_hz: float | Literal["auto"] | None
) -> tuple[tuple[str, ...], float | Literal["auto"] | None]:
    """The note that the logs are fitted unfiltered and no cut-off, when the cut-off is
    read from them (``"auto"``) and they are exact to round-off
    (:func:`~.input_noise.exact_to_round_off`); else no note and ``cutoff_hz``."""
    if cutoff_hz == "auto" and exact_to_round_off(logs):
        return (exact_note(logs),), None
    return (), cutoff_hz


def _combined(
    robot: Robot,
    data: Recordings,
    structure: Structure,
    drive: Drive | None,
    base: BaseParameters | None,
) -> dict[str, str]:
    """What the coefficients fitted hold of the friction coefficients ``structure`` leaves
    out because they are structurally combined with them (:func:`~.structural.absorbed_by`:
    ``{"fv6": "fv6 + 0.0005556*jfv7"}``); empty when it leaves none such out."""
    out: dict[str, str] = {}
    for lab in structure.drop:
        if not FRICTION_LABEL.fullmatch(lab):
            continue
        held = replace(structure, drop=tuple(d for d in structure.drop if d != lab))
        model_drive, terms = _terms_of(held, drive, robot.n, data)
        columns = model_columns(robot, data, drive=model_drive, terms=terms, base=base)
        for k, expr in absorbed_by(robot, columns, lab).items():
            out[k] = expr if k not in out else f"{out[k]}{expr[len(k) :]}"
    return out


def _fitted_structure(
    robot: Robot, data: Recordings, selection: Selection | None, friction: tuple[str, ...] | None
) -> Structure:
    """The structure chosen (the links alone when the data are too short to judge), with
    the friction parts ``friction`` in place of its own when given.

    Refused (:class:`~dynid.exceptions.DataError`), as a flipped joint gravity loads is
    before any fit: friction the held-out data need to put energy in at every speed
    (:func:`reversed_friction`) on a joint whose sign the check against gravity does not
    judge (:func:`~.model_sign.gravity_loaded`) nor the whole rigid-body torques confirm
    (:func:`~.model_sign.sign_confirmed`), a torque of the opposite sign there. On a joint
    they judge the sign is right (a controller's compensation, ``-0.05 dq2``; a short
    log's loose viscous coefficient), and that friction is left out instead."""
    if selection is not None and (pushing := reversed_friction(selection)):
        logs = [p.log for p in data.pieces]
        judged = gravity_loaded(robot, np.concatenate([g.q for g in logs]))
        judged |= sign_confirmed(robot, logs)
        unseen = [v for v in pushing if not judged[v.joint]]
        coupled = frozenset(() if data.drive is None else data.drive.coupled)
        if reversed_sign_finding(unseen, robot.joint_names, selection.chosen, coupled):
            raise ReversedSignError(unseen, robot.joint_names, selection.chosen, coupled)
    chosen = Structure() if selection is None else selection.chosen
    return chosen if friction is None else Structure(chosen.armature, friction, at=chosen.at)
