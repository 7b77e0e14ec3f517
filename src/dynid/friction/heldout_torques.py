"""Identify's prediction of the torques it held out: the verdict a run is read by first
(``heldout.json`` and the held-out figures of ``dynid identify``).

:func:`heldout_torques` predicts data the fit did not see: the last of the contiguous time
blocks of the held-out judgement (:mod:`dynid.identification.holdout`), with the
coefficients and friction of the fold fitted on the other blocks (solved from the folds'
normal equations the model keeps), every recording with the fit of the others (pooled;
the last alone when the others are not given), or the
separate ``--validate-on`` log with the model itself; from the logs as the identification
read them (:func:`dynid.workflows.identify.identify_files` passes those it holds: no file
is read again). The torques are compared unfiltered
(:func:`dynid.friction.validation.validate_torques`) and judged as ``validate`` judges a
log, by the same engine (:func:`~dynid.identification.floor_verdict.judged_prediction`):
against the sensors' noise, taken from the identification's record
(``info.heldout["noise_rms"]``: the noise of the training fit's floor the summary prints)
when it holds it, else read from the same torques, at least the held-out torques'
rounding (a quantized sensor's ``step / sqrt(12)``), and the noise the held-out pieces'
prepared states put into the prediction (:mod:`~dynid.identification.input_noise`), each
sample against its own noise. The true structure of an SO-101 with quantized currents and
positions-only logs was "usable, 2.47 x the noise floor of 0.554 %" on the sensors' noise
alone (now 1.01 x a floor of 0.872 %). The held-out torques are judged as the fit used
them: their one-sample spikes replaced (:func:`~dynid.identification.spikes.despiked`, as
identification replaces them before filtering), the verdict saying how many.
"""

from __future__ import annotations

import dataclasses
import warnings
from collections.abc import Callable, Mapping, Sequence
from dataclasses import dataclass, field
from typing import Any, Literal

import numpy as np
from numpy.typing import NDArray

from .._times import stamp_text
from ..dynamics.terms import gravity_torques
from ..exceptions import DynidError, DynidWarning
from ..identification.derived_cutoff import with_derived_cutoff_hint
from ..identification.drive_gains import DriveGains, drive_gains
from ..identification.floor_verdict import input_step, judged_prediction, prediction_input_noise
from ..identification.fold_offsets import fold_solution, kept_labels
from ..identification.fold_spread import (
    PieceSums,
    covariance_of_sums,
    draw_margin,
    fit_factors,
    loose_folds,
    piece_sums,
    prediction_variance,
)
from ..identification.gravity_tilt import GravityTilt, gravity_tilt, tilt_columns
from ..identification.holdout import DEFAULT_FOLDS, block_labels
from ..identification.input_noise import (
    NoiseFloor,
    quantized_noise_std,
    rounding_std,
    state_noise,
)
from ..identification.log import TorqueLog, joint_side_log
from ..identification.log_rows import term_regressor
from ..identification.low_speed import low_speed_hint
from ..identification.model import IdentifiedModel
from ..identification.model_sign import gravity_loaded
from ..identification.pieces import split_at_gaps, unwrapped, wrappable
from ..identification.recording_level import RecordingLevels, recording_levels
from ..identification.residual_dependence import (
    BINS,
    MIN_PER_BIN,
    Dependence,
    at_standstill,
    friction_left_out,
    held_terms,
    judged_springs,
    offsets_of,
    residual_dependence,
    round_off,
    with_dependence_hint,
)
from ..identification.residual_spring import ResidualSpring, residual_spring
from ..identification.rotor_sign import per_joint
from ..identification.spikes import despiked
from ..identification.training_range import OutsideTraining
from ..identification.verdict import (
    NOISE_FLOOR_SHARE,
    SYSTEMATIC_RATIO,
    Verdict,
    with_caveat,
    with_hint,
    with_replaced_spikes,
)
from ..model.drive import Drive
from ..model.robot import Robot
from ..model.units import units_said
from ..regressors.terms import LinearFriction
from .fit import model_drive, torques_through
from .model import joint_separable
from .pooled import joined_validation
from .validation import KEPT_SAMPLES, Validation, own_friction, validate_torques

__all__ = [
    "HeldOutTorques",
    "beside_columns",
    "heldout_torques",
    "residual_gains",
    "residual_springs",
    "residual_tilt",
]

#: Samples the gains' fit uses at most (evenly spread).
_GAIN_SAMPLES = 2_000


@dataclass(frozen=True, slots=True, eq=False)
class HeldOutTorques:
    """Predicted against measured torques on data the fit did not see.

    Attributes
    ----------
    validation : Validation
        The prediction on the held-out samples (unfiltered measured torques).
    noise_rms : ndarray, shape (n,)
        The torque sensors' noise per joint [N m]: the identification's record, else read
        from the held-out torques; at least the held-out torques' rounding.
    block : str
        What was held out (``"the last of 5 time blocks, 8.2-10.0 s"``).
    joint_names : tuple of str
    logs : tuple of TorqueLog
        The held-out log(s) as the identification took them: velocities derived from
        positions at a cut-off well above the motion's add the hint to lower it to the
        verdict (:mod:`~dynid.identification.derived_cutoff`).
    cutoff_hz : float or None
        The cut-off [Hz] the held-out data were prepared at.
    caveat : str or None
        What the held-out data cannot tell (time blocks of a motion that leaves parameters
        loose: :func:`~dynid.identification.least_squares.within_motion_caveat`), which
        keeps the verdict from the noise floor (:func:`~dynid.identification.verdict.
        with_caveat`).
    spikes : int
        Torque samples of the held-out data replaced as one-sample spikes before they were
        judged, as the fit replaced them
        (:func:`~dynid.identification.spikes.despiked`).
    inputs : tuple of (int, ndarray) or None
        The variance [N^2 m^2] the held-out states' noise puts into the prediction at every
        k-th sample (:func:`~dynid.identification.floor_verdict.prediction_input_noise`);
        None: not known (the floor is the sensors' noise alone).
    terms : frozenset of str
        The names of the terms the model holds beside the rigid bodies
        (:func:`~dynid.identification.residual_dependence.held_terms`): the remedies of the
        verdict name only what it lacks.
    tilt : GravityTilt or None
        The tilt of the gravity vector the held-out residual points to
        (:func:`~dynid.identification.gravity_tilt.gravity_tilt`, the model's columns
        projected out); the verdict names it first when it explains the residual.
    springs : ResidualSpring or None
        The stiffness per joint the held-out residual points to
        (:func:`residual_springs`); the verdict gives a named joint's.
    offsets : mapping of int to (str, bool)
        The model's offset per joint, its label and whether the model holds it
        (:func:`~dynid.identification.residual_dependence.offsets_of`): a constant
        held-out residual where the structure chosen on held-out data left the offset out
        is said so, not called an offset.
    prepared : tuple of TorqueLog
        Every piece of every recording the fit used, prepared (joint side, every sample),
        in the fit's order, when the held-out data are those recordings (each predicted by
        the fit of the others), none of their torques replaced as spikes and at most
        :data:`~dynid.friction.validation.KEPT_SAMPLES` samples in all: the model's
        residual on them is read (:func:`~dynid.friction.delay_check.logs_delay`) without
        preparing them again; empty otherwise.
    left_out : mapping of int to tuple of str
        The friction coefficients the model left out per joint
        (:func:`~dynid.identification.residual_dependence.friction_left_out`): a held-out
        residual that follows the velocity there is said to be that friction.
    gains : DriveGains or None
        The gain per motor (or joint) of the logged efforts the held-out residual points
        to (:func:`residual_gains`); when it names some
        (:attr:`~dynid.identification.drive_gains.DriveGains.named`), the verdict says
        them in place of what each joint's residual follows (the springs and the tilt
        they explain are not judged).
    robot : Robot or None
        The model's robot: the units of ``as_dict`` per joint kind (a prismatic joint's
        force in N, :func:`~dynid.model.units.unit_said`); None: every joint's in N m.
    fitted : tuple of (int, ndarray) or None
        The variance [N^2 m^2] the held-out folds' own coefficients, fitted without the
        samples they predict, put into the prediction at the samples of ``inputs``
        (:mod:`~dynid.identification.fold_spread`: every recording predicted by the fit
        of the others); a part of the floor. None: not counted (the model itself
        predicts, or its columns are not the folds').
    recording : ndarray of int, shape (N,), or None
        Each held-out sample's recording, where every recording is predicted by the fit
        of the others: a residual that is one steady constant over each is said as the
        recordings' own torque offsets (:mod:`~dynid.identification.recording_level`),
        as ``validate`` says it; None: one held-out block or log.
    outside : OutsideTraining or None
        Of a separate recording (``validate_on``), the joints it takes outside the
        positions and velocities the model was fitted on
        (:mod:`~dynid.identification.training_range`): said in the verdict, which names no
        cause of a residual where it lies clearly outside the training's poses; None:
        none, or held-out data of the training's own recordings.
    """

    validation: Validation
    noise_rms: NDArray[np.float64]
    block: str
    joint_names: tuple[str, ...]
    logs: tuple[TorqueLog, ...] = ()
    cutoff_hz: float | None = None
    caveat: str | None = None
    spikes: int = 0
    inputs: tuple[tuple[int, NDArray[np.float64]], ...] | None = None
    terms: frozenset[str] = frozenset()
    tilt: GravityTilt | None = None
    springs: ResidualSpring | None = None
    offsets: Mapping[int, tuple[str, bool]] = field(default_factory=dict)
    prepared: tuple[TorqueLog, ...] = ()
    left_out: Mapping[int, tuple[str, ...]] = field(default_factory=dict)
    gains: DriveGains | None = None
    robot: Robot | None = None
    fitted: tuple[tuple[int, NDArray[np.float64]], ...] | None = None
    recording: NDArray[np.intp] | None = None
    outside: OutsideTraining | None = None

    def _judged(self) -> tuple[Verdict, NoiseFloor]:
        """:func:`~dynid.identification.floor_verdict.judged_prediction` of the held-out
        pieces pooled (no sign check: a fold fit's prediction of a short block is no
        measure of the torques' sign, :func:`heldout_torques`' Notes)."""
        v = self.validation
        return judged_prediction(
            [v.log.tau],
            [v.log.tau - v.tau_hat],
            [self.noise_rms**2],
            v.errors,
            self.joint_names,
            self.inputs,
            fitted=self.fitted,
        )

    @property
    def floor(self) -> NoiseFloor:
        """The noise floor of the held-out torques: the sensors' noise and the states'
        through the model, the error weighed against it
        (:func:`~dynid.identification.input_noise.noise_floor`)."""
        return self._judged()[1]

    @property
    def noise_floor_percent(self) -> float:
        """The noise relative to the measured torques' norm [%]: the smallest relative
        error a model can reach on these torques (the sensors' and the states' noise)."""
        return self.floor.percent

    @property
    def verdict(self) -> Verdict:
        """The held-out prediction judged as ``validate`` judges one, by the same engine
        (:func:`~dynid.identification.floor_verdict.judged_prediction`): the error against
        the noise floor (:attr:`floor`), each joint's against its noise and in relative
        terms; above the floor, with the hint of a cut-off too high for velocities derived
        from positions (:func:`~dynid.identification.derived_cutoff.with_derived_cutoff_hint`)
        and that of an error mostly at low speed
        (:func:`~dynid.identification.low_speed.with_low_speed_hint`); the torque spikes
        replaced before judging counted
        (:func:`~dynid.identification.verdict.with_replaced_spikes`); each joint above its
        noise, what its residual follows
        (:func:`~dynid.identification.residual_dependence.with_dependence_hint`)."""
        verdict, fl = self._judged()
        v = self.validation
        said = None if self.gains is None else self.gains.sentence()
        own = None if said is not None else self._own_offsets(verdict)
        line, hedge = self._extrapolated(verdict, fl.joint_ratios, own)
        own_said = None if own is None or hedge else own.sentence(self.joint_names)
        verdict = with_hint(verdict, own_said)
        verdict = (
            with_hint(verdict, said)
            if said is not None or hedge is not None
            else with_dependence_hint(
                verdict,
                [v.log.q],
                [v.log.dq],
                [v.log.tau - v.tau_hat],
                fl.total_rms,
                self.joint_names,
                self.terms,
                self.tilt,
                fl.joint_ratios,
                self.springs,
                [v.log.tau],
                self.offsets,
                self.left_out,
                prismatic=None if self.robot is None else tuple(map(bool, self.robot.prismatic)),
                levels=None if own is None else {j: own.of(j) or () for j in own.joints},
                t=[v.log.t],
            )
        )
        if said is not None and verdict.level == "good":  # at the floor, the factors said
            verdict = dataclasses.replace(verdict, reason=f"{verdict.reason}; {said}")
        for clause in (line, hedge):
            if clause is not None:
                verdict = dataclasses.replace(verdict, reason=f"{verdict.reason}; {clause}")
        verdict = with_derived_cutoff_hint(verdict, self.logs, self.cutoff_hz)
        verdict = with_hint(verdict, self.low_speed, ", ")
        verdict = with_caveat(verdict, self.caveat)
        return with_replaced_spikes(verdict, self.spikes, ", as the fit replaced them")

    def _extrapolated(
        self,
        verdict: Verdict,
        ratios: NDArray[np.float64] | None,
        own: RecordingLevels | None,
    ) -> tuple[str | None, str | None]:
        """The clause naming the joints the held-out recording takes outside the training
        (:attr:`outside`; None: none), and, above the floor where it lies clearly outside
        the training's poses on a joint the residual concerns (above its noise, or named by
        a cause), the clause that puts the model's extrapolation before any cause (None:
        the causes are said as before)."""
        if self.outside is None:
            return None, None
        line = self.outside.sentence(self.joint_names)
        springs = () if self.springs is None else tuple(self.springs.named)
        joints = set(springs) | (set() if own is None else set(own.joints))
        if ratios is not None:
            joints |= {int(j) for j in np.flatnonzero(np.asarray(ratios) >= SYSTEMATIC_RATIO)}
        clear = self.outside.concerned(joints)
        if verdict.level == "good" or not clear:
            return line, None
        causes = [] if own is None else ["the recording's own torque offset"]
        causes += ["a tilted gravity vector"] if self.tilt is not None and self.tilt.named else []
        causes += ["a joint spring"] if springs else []
        return line, self.outside.hedge(clear, causes, self.joint_names)

    def _own_offsets(self, verdict: Verdict) -> RecordingLevels | None:
        """Above the floor, the joints whose model holds an offset and whose held-out
        residual is one steady constant over each recording (:attr:`recording`): the
        recordings' own torque offsets
        (:func:`~dynid.identification.recording_level.recording_levels`); None where
        there is none, the samples' recordings are not known or the verdict is good."""
        rec = self.recording
        v = self.validation
        if verdict.level == "good" or rec is None or not self.offsets:
            return None
        if rec.size != v.log.tau.shape[0]:
            return None
        error = v.log.tau - v.tau_hat
        ks = [int(k) for k in np.unique(rec)]
        return recording_levels(
            [error[rec == k] for k in ks],
            [v.log.tau[rec == k] for k in ks],
            ks,
            self.noise_rms,
            tuple(self.offsets),
        )

    @property
    def systematic(self) -> tuple[Dependence, ...]:
        """The joints whose held-out residual is above their noise and what it follows
        (:func:`~dynid.identification.residual_dependence.residual_dependence`); none when
        the residual is exact to round-off (:attr:`round_off`)."""
        v = self.validation
        if self.round_off is not None:
            return ()
        fl = self._judged()[1]
        error = [v.log.tau - v.tau_hat]
        return residual_dependence(
            [v.log.q], [v.log.dq], error, fl.total_rms, fl.joint_ratios, t=[v.log.t]
        )

    @property
    def round_off(self) -> float | None:
        """The held-out residual's RMS over the torques' when the prediction is exact to
        round-off (:func:`~dynid.identification.residual_dependence.round_off`), else None."""
        v = self.validation
        return round_off([v.log.tau - v.tau_hat], [v.log.tau])

    @property
    def low_speed(self) -> str | None:
        """Where most of the error above the noise sits at low speed, the sentence that says
        so (:func:`~dynid.identification.low_speed.low_speed_hint`), or None."""
        v = self.validation
        return low_speed_hint([v.log.dq], [v.log.tau - v.tau_hat], self.noise_rms, self.joint_names)

    def as_dict(self) -> dict[str, Any]:
        """JSON-ready: the errors per joint, the noise (``noise_rms``: the sensors' and the
        states' and the folds' coefficients', root sum of squares; ``sensor_noise_rms``,
        ``input_noise_rms``, ``fit_noise_rms`` (:attr:`fitted`): its parts,
        the latter null when not known), the floor, the torque spikes replaced before
        judging, each joint's error over its noise as the verdict weighs it
        (``joint_ratios``: the numbers its reason and the report name), the verdict (with
        its ``ratio`` to the floor, each sample weighed against its own noise) and, above
        the floor, the low-speed note (``low_speed``, the report's own line) and the tilt
        of the gravity vector the residual points to (``gravity_tilt``, null when not
        judged), and the stiffness per joint it points to (``springs``, null when not
        judged; schema ``heldout.json``), and the gain per motor of the logged efforts
        (``drive_gains``, null when not judged), and of a separate recording the joints it
        takes outside the training's motion (``outside_training``, when any:
        :meth:`~dynid.identification.training_range.OutsideTraining.as_dict`)."""
        e, v, fl = self.validation.errors, self.verdict, self.floor
        return {
            "block": self.block,
            "joint_names": list(self.joint_names),
            "n_samples": int(len(self.validation.log.tau)),
            "rms": e.rms.tolist(),
            "noise_rms": fl.total_rms.tolist(),
            "sensor_noise_rms": self.noise_rms.tolist(),
            "input_noise_rms": None if fl.input_rms is None else fl.input_rms.tolist(),
            "fit_noise_rms": None if fl.fit_rms is None else fl.fit_rms.tolist(),
            "relative_error_percent": float(e.relative_error_percent),
            "relative_error_percent_per_joint": e.relative_error_percent_per_joint.tolist(),
            "noise_floor_percent": fl.percent,
            "joint_ratios": None if fl.joint_ratios is None else fl.joint_ratios.tolist(),
            "torque_spikes_replaced": self.spikes,
            "verdict": {"level": v.level, "label": v.label, "reason": v.reason, "ratio": v.ratio},
            "low_speed": None if v.level == "good" else self.low_speed,
            "gravity_tilt": None if self.tilt is None else self.tilt.as_dict(),
            "springs": None if self.springs is None else self.springs.as_dict(),
            "drive_gains": None if self.gains is None else self.gains.as_dict(),
            **({"outside_training": o.as_dict()} if (o := self.outside) is not None else {}),
            "units": units_said(
                self.robot,
                {
                    "rms": "N m",
                    "noise_rms": "N m",
                    "sensor_noise_rms": "N m",
                    "input_noise_rms": "N m",
                    "fit_noise_rms": "N m",
                    "relative_error_percent": "%",
                },
            ),
        }


def _fold_model(model: IdentifiedModel, fold: int) -> IdentifiedModel | None:
    """The model fitted on every block but ``fold`` (None: the columns are not the base
    parameters followed by ``fv, fc, fo`` per joint), an offset its training rows do not
    tell from the joint's Coulomb friction left out at zero, as the structure search
    judged it (:func:`~dynid.identification.fold_offsets.fold_solution`)."""
    assert model.holdout is not None
    x = _fold_solution(model, fold)[0]
    if x.size != model.base.rank + sum(len(t.labels) for t in model.appended):
        return None
    return model.with_coefficients(x)


def _fold_solution(
    model: IdentifiedModel, fold: int
) -> tuple[NDArray[np.float64], NDArray[np.bool_]]:
    """The coefficients fitted on every block but ``fold`` and the columns fitted
    (:func:`~dynid.identification.fold_offsets.fold_solution`)."""
    assert model.holdout is not None
    train = model.holdout.train[fold]
    return fold_solution(train, labels=kept_labels(model, np.arange(train.p)))


def heldout_torques(
    model: IdentifiedModel,
    log: TorqueLog,
    *,
    separate: TorqueLog | None = None,
    others: Sequence[TorqueLog] = (),
) -> HeldOutTorques | None:
    """The torques of data the identification held out, predicted.

    Parameters
    ----------
    model : IdentifiedModel
        Identified from ``log`` by the classical route (with its held-out folds).
    log : TorqueLog
        The log it was identified from, as the identification took it (several
        recordings: the last one; a motor-side log with the whole turns of ``q_start``).
        Held-out samples with gaps longer than the identification's ``max_gap_s`` are
        prepared piece by piece and pooled, joints recorded wrapped into ``[-pi, pi]``
        unwrapped, and its one-sample torque spikes replaced, as the identification took
        them.
    separate : TorqueLog, optional
        The ``--validate-on`` log (the model judged on it), as read (its spikes replaced).
    others : sequence of TorqueLog
        The recordings before ``log``, in the identification's order, as it took them:
        with them every recording is predicted by the fit of the others and the
        predictions pooled (the verdict of one recording, the last, could differ from the
        leave-one-recording-out judgement printed under it: 2.8 % against 2.57 %).

    Returns
    -------
    HeldOutTorques or None
        None when the model keeps no held-out folds (static data) or its columns are not
        the base parameters and the classical friction.

    Raises
    ------
    DynidError
        Every held-out piece too short to filter (the first one's error).

    Notes
    -----
    What the prediction warns is not said: the logs were checked when identified, and a
    fold fit's prediction of a short block is no measure of the torques' sign (a
    right-signed 2 s UR5 log read "anti-correlated ... sign probably opposite" from it).
    """
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", DynidWarning)
        return _predicted(model, log, separate, tuple(others))


def _predicted(
    model: IdentifiedModel,
    log: TorqueLog,
    separate: TorqueLog | None,
    others: tuple[TorqueLog, ...],
) -> HeldOutTorques | None:
    """:func:`heldout_torques`, its warnings said."""
    if model.holdout is None or model.info.log is None:
        return None
    turns = wrappable(model.robot, model.drive)  # wrapped joints unwrapped, as identified
    k = model.holdout.folds
    if model.holdout.scheme == "recordings" and len(others) + 1 == k:
        return _each_recording(model, (*others, log), turns)
    if model.holdout.scheme == "file" and separate is not None:
        (held, spikes), fitted = _despiked_from(separate), model
        block = "the separate log (--validate-on)"
    elif model.holdout.scheme == "blocks":
        k = model.holdout.folds
        fold = _fold_model(model, k - 1)
        if fold is None:
            return None
        trim = model.info.log.trim_s
        t0, t1 = float(log.t[0]) + trim, float(log.t[-1]) - trim
        start = t0 + (k - 1) / k * (t1 - t0)
        first = int(np.searchsorted(log.t, start - trim))  # the block's rows: a view
        (held, spikes), fitted = _despiked_from(log, first), fold  # found on the whole log
        log0, end = float(log.t[0]), float(log.t[-1])
        into = f" ({start - log0:.4g}-{end - log0:.4g} s into the log)" if log0 else ""
        block = (
            f"the last of {k} time blocks, t = {stamp_text(start)}-{stamp_text(end)} s{into}, "
            f"predicted by the fit of the other {k - 1}"
        )
    elif model.holdout.scheme == "recordings":  # ``log``: the last recording alone
        k = model.holdout.folds
        fold = _fold_model(model, k - 1)
        if fold is None:
            return None
        (held, spikes), fitted = _despiked_from(log), fold
        block = f"the last of {k} recordings, predicted by the fit of the other {k - 1}"
    else:
        return None
    pieces = _pieces(model, held, turns)
    v, said, _ = _pieces_validation(fitted, pieces)
    read = (held if model.holdout.scheme == "file" else log,)  # the motion of a whole log
    caveat = (model.info.heldout or {}).get("caveat") if model.holdout.scheme == "blocks" else None
    whole = None  # a time block too short to fit the springs with the model's columns
    if model.holdout.scheme == "blocks":

        def whole() -> Validation:
            return _pieces_validation(model, _pieces(model, _despiked_from(log)[0], turns))[0]

    inputs = _input_noise(fitted, v, pieces)
    return _held_out(model, v, block + said, read, caveat, spikes, inputs, whole)


def _each_recording(
    model: IdentifiedModel, logs: tuple[TorqueLog, ...], turns: NDArray[np.bool_]
) -> HeldOutTorques | None:
    """Every recording of ``logs`` (the folds' order) predicted by the fold fitted on the
    others, pooled; the states' noise through ``model`` itself (the floor, not the
    prediction: the folds' coefficients barely move it)."""
    parts: list[Validation] = []
    folds: list[NDArray[np.intp]] = []  # each sample's recording
    pieces: list[TorqueLog] = []
    prepared: list[TorqueLog] | None = []  # every piece whole, for the delay's check
    spikes = 0
    for fold, rec in enumerate(logs):
        fitted = _fold_model(model, fold)
        if fitted is None:
            return None
        held, replaced = _despiked_from(rec)
        mine = _pieces(model, held, turns)
        v, _, each = _pieces_validation(fitted, mine)
        parts.append(v)  # pooled one after another
        folds.append(np.full(v.log.q.shape[0], fold, np.intp))
        pieces += mine
        spikes += replaced
        whole = replaced == 0 and all(p.step == 1 for p in each)
        prepared = prepared + [p.log for p in each] if whole and prepared is not None else None
    v = joined_validation(parts)
    k = len(logs)
    block = f"each of the {k} recordings, predicted by the fit of the other {k - 1}"
    if len(pieces) > k:
        block += f" ({len(pieces)} pieces between gaps)"
    inputs = _input_noise(model, v, pieces)
    labels = np.concatenate(folds)
    held_out = _held_out(model, v, block, logs, None, spikes, inputs, folds=labels)
    spread = _fold_spread(model, parts, v, labels, held_out.noise_rms)
    if spread is not None:
        fit_rms = np.sqrt(np.mean(spread[0][1], axis=0))
        loose = loose_folds(fit_rms, held_out.noise_rms, held_out.joint_names)
        held_out = dataclasses.replace(
            held_out, fitted=None if loose else spread, caveat=loose or held_out.caveat
        )
    if prepared is None or sum(p.n_samples for p in prepared) > KEPT_SAMPLES:
        return held_out
    return dataclasses.replace(held_out, prepared=tuple(prepared))


#: Samples of each recording at most whose regressor the folds' covariance is summed over
#: (every k-th: the regressor is smooth, its normal equations barely change).
_SPREAD_SAMPLES = 1_500


def _fold_spread(
    model: IdentifiedModel,
    parts: Sequence[Validation],
    v: Validation,
    labels: NDArray[np.intp],
    noise: NDArray[np.float64],
) -> tuple[tuple[int, NDArray[np.float64]], ...] | None:
    """The variance [N^2 m^2] the coefficients of each fold, fitted on the other
    recordings (``parts``: each recording's prediction, in the folds' order) with the
    sensors' ``noise`` (n,) [N m], put into the prediction of ``v`` (``parts`` joined;
    ``labels`` each sample's fold), at its every k-th sample as the states' noise is
    carried (:func:`~dynid.identification.floor_verdict.input_step`;
    :mod:`~dynid.identification.fold_spread`); None when the folds' columns are not the
    model's regressor (their prediction differs from it) or the noise is not known."""
    assert model.holdout is not None
    top = float(np.max(noise, initial=0.0))
    if not top > 0 or any(p.log.ddq is None for p in parts):
        return None
    var = np.maximum(noise, NOISE_FLOOR_SHARE * top) ** 2
    terms = tuple(t.term for t in model.terms.values())

    def rows(log: TorqueLog, at: NDArray[np.intp]) -> NDArray[np.float64]:
        assert log.ddq is not None
        return term_regressor(model.robot, model.base, terms, log.q[at], log.dq[at], log.ddq[at])[0]

    own = []
    for p in parts:
        k = max(1, p.log.n_samples // _SPREAD_SAMPLES)
        own.append((k * p.step, rows(p.log, np.arange(0, p.log.n_samples, k))))
    weighted = model.info.estimator != "ols"
    formed: dict[tuple[int, bytes], PieceSums] = {}

    def sums(f: int, columns: NDArray[np.bool_]) -> PieceSums:
        """Recording ``f``'s sums of its rows' ``columns``, formed once for each columns
        (the folds and the final fit share them: each recording trains two of three)."""
        key = (f, columns.tobytes())
        if key not in formed:
            step, Y = own[f]
            formed[key] = piece_sums([(step, Y[..., columns])], var, weighted=weighted)[0]
        return formed[key]

    factor = _fit_factors(model, own, var, sums)
    k = input_step(v.log.n_samples)
    at = np.arange(0, v.log.n_samples, k)
    out = np.zeros((at.size, v.log.n))
    drawn = []
    for fold in range(len(parts)):
        mine = at[labels[at] == fold]
        normals = model.holdout.train[fold]
        x, fitted = _fold_solution(model, fold)
        fitted &= np.diag(normals.G) > 0
        Y = rows(v.log, mine)
        scale = max(float(np.sqrt(np.mean(v.log.tau[mine] ** 2))), 1e-300)
        if not np.allclose(Y @ x, v.tau_hat[mine], rtol=0.0, atol=1e-6 * scale):
            return None  # not the folds' columns: no part said
        train = [sums(f, fitted) for f in range(len(own)) if f != fold]
        cov = covariance_of_sums(train, weighted=weighted)
        out[labels[at] == fold] = prediction_variance(Y[..., fitted], cov)
        drawn.append((k, Y[..., fitted], cov))
    return ((k, out * factor * draw_margin(drawn)),)


def _fit_factors(
    model: IdentifiedModel,
    own: list[tuple[int, NDArray[np.float64]]],
    var: NDArray[np.float64],
    sums: Callable[[int, NDArray[np.bool_]], PieceSums],
) -> NDArray[np.float64] | float:
    """Each joint's factor of the final fit's own spread over the noise's on its samples
    ``own`` (:func:`~dynid.identification.fold_spread.fit_factors`; ``sums(f, columns)``
    the noise's sums of recording ``f``'s rows, :func:`~dynid.identification.fold_spread.
    piece_sums`); 1 without the fit's covariance."""
    fit = model.joint_fit if model.joint_fit is not None else model.fit
    cov = fit.covariance
    width = own[0][1].shape[-1]
    if cov is None or np.shape(cov) != (width, width):
        return 1.0
    kept = np.asarray(fit.kept, dtype=bool)
    rows = [(k, Y[..., kept]) for k, Y in own]
    weighted = model.info.estimator != "ols"
    noise = covariance_of_sums([sums(f, kept) for f in range(len(own))], weighted=weighted)
    return fit_factors(rows, noise, np.asarray(cov)[np.ix_(kept, kept)])


def _pieces(model: IdentifiedModel, held: TorqueLog, turns: NDArray[np.bool_]) -> list[TorqueLog]:
    """``held`` cut at the identification's gaps, its wrapped joints unwrapped."""
    assert model.info.log is not None
    return [unwrapped(p, turns)[0] for p in split_at_gaps(held, model.info.log.max_gap_s)]


def _held_out(
    model: IdentifiedModel,
    v: Validation,
    block: str,
    read: tuple[TorqueLog, ...],
    caveat: str | None,
    spikes: int,
    inputs: tuple[tuple[int, NDArray[np.float64]], ...] | None,
    whole: Callable[[], Validation] | None = None,
    folds: NDArray[np.intp] | None = None,
) -> HeldOutTorques:
    """The held-out prediction ``v`` judged against the sensors' noise: the
    identification's record, at least the held-out torques' rounding; above the noise
    floor, the springs fitted on ``whole()`` (the model on the whole log of a held-out
    time block, whose few samples leave a stiffness fitted with the model's columns
    loose: 776 N m/rad for 20 on a Panda's last 1.4 s) or on ``v``; the gains per motor on
    the same, judged on the identification's folds (``folds``, each sample's recording
    of ``v``; else its contiguous time blocks)."""
    assert model.info.log is not None
    recorded = _recorded_noise(model)
    noise = (
        quantized_noise_std(v.log.tau, v.log.t)
        if recorded is None
        else np.maximum(recorded, rounding_std(v.log.tau))
    )
    names = tuple(model.robot.joint_names)
    given = None if model.info.log.cutoff_source == "motion" else model.info.log.cutoff_hz
    held = HeldOutTorques(
        v, noise, block, names, read, given, caveat, spikes, inputs, held_terms(model),
        offsets=offsets_of(model), left_out=friction_left_out(model), robot=model.robot,
        recording=folds if folds is not None and folds.size == v.log.q.shape[0] else None,
    )  # fmt: skip
    verdict, floor = held._judged()
    total = floor.total_rms
    springs = gains = None  # said only above the floor: a good verdict takes no hint
    every = v
    above = verdict.level != "good"
    if above or _logs_currents(model):  # a current log's constants: at the floor too
        every = v if whole is None else whole()
        if folds is None or folds.size != every.log.q.shape[0]:
            ho = model.holdout
            k = ho.folds if ho is not None and ho.scheme == "blocks" else DEFAULT_FOLDS
            folds = _block_folds(every.log.q.shape[0], k)
        gains = residual_gains(model, every, total, folds, floor=not above)
        if gains is not None and gains.named:  # the gains explain it: no spring, no tilt
            return dataclasses.replace(held, gains=gains)
    if above:
        springs = residual_springs(model, every, total, v)
    else:
        every = v
    # above the floor, a time block's tilt on the whole log as its springs: the block's
    # few samples, the model's columns projected out, left none (a Panda tilted 0.3 deg,
    # one 6 s log, 2.3 x the floor: no tilt judged)
    tilt = residual_tilt(model, every, total, springs)
    if tilt is not None and every is not v:  # what it leaves is the whole log's, not v's
        tilt = dataclasses.replace(tilt, rest=tilt.rest[:0], rows=tilt.rows[:0])
    return dataclasses.replace(held, tilt=tilt, springs=springs, gains=gains)


def _logs_currents(model: IdentifiedModel) -> bool:
    """Whether ``model``'s drive reads motor currents through torque constants: their
    gains per motor are judged at the noise floor too (a UR5's joints 2 and 4 read
    through constants 1.15 and 0.85 times the true ones left a held-out verdict at 1.09 x
    the floor, the model's torques 12.7 % off the truth, joint 2's factor 0.893 with std
    0.005 where nothing was judged)."""
    return model.drive is not None and model.drive.effort == "current"


def residual_tilt(
    model: IdentifiedModel | Robot,
    v: Validation,
    noise: NDArray[np.float64],
    springs: ResidualSpring | None = None,
) -> GravityTilt | None:
    """The tilt of the gravity vector the residual of the prediction ``v`` points to (of
    several pieces: :func:`~dynid.friction.pooled.joined_validation`)
    (:func:`~dynid.identification.gravity_tilt.gravity_tilt`; ``noise`` (n,) [N m] each
    joint's): of an identified model, its own columns projected out and with them each
    motor's viscous, Coulomb, offset and rotor-inertia columns mapped to the joints
    through the model's drive as the fit maps them (:func:`beside_columns`: terms the
    structure chosen may have left out: a tilt the fit partly took as offsets made it drop
    the offset of joint 3, which then pulled the tilt to 0.17 deg for 0.3), the torques of
    the springs ``springs`` names (:func:`residual_springs`, fitted beside a tilt, on the
    whole log of a time block) taken out first (a 20 N m/rad spring on a Panda shoulder had
    read as a tilt of 0.89 and 1.8 deg); of a robot's own parameters, on the residual as it
    is. The tilt's columns are of the description's links
    (:attr:`~dynid.identification.model.IdentifiedModel.description`: a model read back
    from its file holds none in its robot, and a UR5 tilted 0.3 deg was told of springs).
    ``v`` is at the joints (a motor-side log or currents read through the drive). None
    without accelerations."""
    log = v.log
    if log.ddq is None:
        return None
    error = log.tau - v.tau_hat
    if isinstance(model, Robot):
        return gravity_tilt(model, log.q, error, noise)
    columns = beside_columns(model, log)
    if columns is None:
        return None
    tau = log.tau
    if springs is not None and springs.named:  # fitted beside a tilt: no tilt's part
        named = list(springs.named)
        spring = np.zeros_like(tau)
        spring[:, named] = log.q[:, named] * springs.stiffness[named]
        tau, error = tau - spring, error - spring
    return gravity_tilt(model.description, log.q, error, noise, tau, columns)


def residual_springs(
    model: IdentifiedModel | Robot,
    v: Validation,
    noise: NDArray[np.float64],
    judged: Validation | None = None,
) -> ResidualSpring | None:
    """The stiffness per joint the residual of the prediction ``v`` points to
    (:func:`~dynid.identification.residual_spring.residual_spring`; ``noise`` (n,) [N m]
    each joint's): the measured torques fitted with the identified model's own columns,
    each joint's viscous, Coulomb, offset and rotor-inertia columns, a tilt of the gravity
    vector's (:func:`~dynid.identification.gravity_tilt.tilt_columns` of the description's
    links: a tilted base is no spring) and a spring per joint; the residual a spring must
    explain that of ``judged`` (a held-out time block of ``v``'s log; default ``v``). A
    joint whose residual over ``v`` follows its velocity more than its position is named
    no spring
    (:func:`~dynid.identification.residual_dependence.judged_springs`), judged over
    ``v``'s whole log: over a short time block the positions and velocities follow each
    other (a 20 N m/rad spring's residual over a Panda log's last 1.1 s followed both
    alike, 0.194 and 0.195 N m RMS; over the whole 7.4 s, 0.070 and 0.040). None for a robot's own
    parameters, a model that holds a spring already, or a log without accelerations."""
    log = v.log
    if isinstance(model, Robot) or log.ddq is None or model.spring is not None:
        return None
    beside = beside_columns(model, log)
    if beside is None:
        return None

    keep = _moving_rows(log.dq)
    if keep.size < BINS * MIN_PER_BIN:
        return None  # at standstill the friction is static: no spring told apart from it

    def columns(rows: NDArray[np.intp]) -> NDArray[np.float64]:
        at = keep[rows]
        return np.concatenate([beside(at), tilt_columns(model.description, log.q[at])], axis=-1)

    seen = v if judged is None else judged
    held = _moving_rows(seen.log.dq)
    error = (seen.log.tau - seen.tau_hat)[held if held.size >= BINS * MIN_PER_BIN else slice(None)]
    found = residual_spring(log.q[keep], log.tau[keep], error, noise, columns)
    return judged_springs(found, log.q[keep], log.dq[keep], (log.tau - v.tau_hat)[keep])


def _moving_rows(dq: NDArray[np.float64]) -> NDArray[np.intp]:
    """The samples (indices) at which every joint moves beyond its velocity noise band
    (:func:`~dynid.identification.residual_dependence.at_standstill`): at standstill the
    sensors read the holding torque (static friction, anything within its limits, set by
    the last motion), which a spring fitted there takes for one (a 7-DoF arm resting
    51 % of a point-to-point log: -0.81 N m/rad on joint 2 held out, 213 N m/rad
    validated, where it has none)."""
    return np.flatnonzero(~at_standstill(np.asarray(dq, dtype=np.float64)).any(axis=1))


def _block_folds(samples: int, folds: int) -> NDArray[np.intp] | None:
    """``folds`` contiguous time blocks of ``samples`` (None when too few to cut)."""
    try:
        return block_labels(samples, max(folds, 2))
    except DynidError:
        return None


def residual_gains(
    model: IdentifiedModel | Robot,
    v: Validation,
    noise: NDArray[np.float64],
    folds: NDArray[np.intp] | None = None,
    *,
    described: bool = False,
    floor: bool = False,
) -> DriveGains | None:
    """The gain per motor of the logged efforts the prediction ``v`` points to
    (:func:`~dynid.identification.drive_gains.drive_gains`; ``noise`` (n,) [N m] each
    joint's): the efforts of ``v``'s log per motor through the model's drive
    (:func:`~dynid.identification.drive_gains.effort_columns`; a joint-side log per joint)
    fitted with the model's own columns and each motor's friction and rotor inertia
    (:func:`beside_columns`), their common scale the description's gravity torques at the
    joints gravity loads; a motor named only where fitting its gain improves the prediction
    of the held-out fold (``folds`` (M,): each sample's, the identification's recordings or
    time blocks; default :data:`~dynid.identification.holdout.DEFAULT_FOLDS` contiguous
    time blocks). ``described``: the common scale from the description's links also for a
    model read from its file (whose robot holds none: the gains then relative), as a
    current log's constants at the noise floor are judged; above the floor a model read
    back keeps relative gains, which do not take up a tilted base's gravity (a UR5 tilted
    0.3 deg: its wrist's torques named 1.12 x with the description's scale, the tilt
    unsaid). ``floor``: the prediction is at the noise floor, each motor named only clear
    of 1 over the folds too (:attr:`~dynid.identification.drive_gains.DriveGains.floor`).
    None for a robot's own parameters or a log without accelerations."""
    log = v.log
    if isinstance(model, Robot) or log.ddq is None:
        return None
    beside = beside_columns(model, log)
    if beside is None:
        return None
    n_rows = log.q.shape[0]
    rows = np.unique(np.linspace(0, n_rows - 1, min(n_rows, _GAIN_SAMPLES)).astype(np.intp))
    W = beside(rows)
    q = log.q[rows]
    drive = model.drive
    motor = drive is not None and drive.side == "motor"
    K = drive.transmission if motor and drive is not None else None
    robot = model.description if described else model.robot
    G = gd = None
    if np.any(robot.phi):
        rest = np.zeros_like(q)
        Y, _ = term_regressor(robot, model.base, (), q, rest, rest)
        rigid = int(np.count_nonzero(np.asarray(model.base.independent) < 10 * robot.n))
        G = np.zeros_like(W)
        G[..., :rigid] = Y[..., :rigid]
        gd = gravity_torques(robot, q) * gravity_loaded(robot, q)
    labels = None if folds is None else folds[rows]
    found = drive_gains(W, log.tau[rows], noise, K, G, gd, labels)
    if found is None:
        return None
    per: Literal["joint", "motor"] = "joint" if per_joint(drive) else "motor"  # gear ratio 1
    if drive is not None and drive.effort == "current":
        kt = None if drive.torque_constant is None else np.asarray(drive.torque_constant)
        return dataclasses.replace(found, effort="current", per=per, floor=floor, constants=kt)
    return dataclasses.replace(found, per=per, floor=floor)


def beside_columns(
    model: IdentifiedModel, log: TorqueLog
) -> Callable[[NDArray[np.intp]], NDArray[np.float64]] | None:
    """The regressor (M, n, p) of ``model``'s own columns at the rows ``rows`` (M,) of the
    prepared joint-side ``log``, with each motor's viscous, Coulomb, offset and
    rotor-inertia columns mapped to the joints through the model's drive as the fit maps
    them (``K_f^T`` of the friction at ``K_f dq``, ``K^T`` of the rotor at ``K ddq``; each
    joint's own without a drive); None for a log without accelerations."""
    if log.ddq is None:
        return None
    terms = tuple(t.term for t in model.terms.values())
    q, dq, ddq = log.q, log.dq, log.ddq
    drive = Drive.identity(q.shape[1]) if model.drive is None else model.drive
    own = LinearFriction(drive)

    def columns(rows: NDArray[np.intp]) -> NDArray[np.float64]:
        Y, _ = term_regressor(model.robot, model.base, terms, q[rows], dq[rows], ddq[rows])
        friction = own.torque_columns(q[rows], dq[rows], ddq[rows])
        rotor = drive.rotor_columns(ddq[rows])  # each motor's rotor inertia
        return np.concatenate([Y, friction, rotor], axis=-1)

    return columns


def _input_noise(
    model: IdentifiedModel, v: Validation, pieces: list[TorqueLog]
) -> tuple[tuple[int, NDArray[np.float64]], ...] | None:
    """The variance the noise of the raw held-out ``pieces``' states, prepared at the
    identification's cut-off (:func:`~dynid.identification.input_noise.state_noise`), puts
    into ``model``'s prediction ``v`` (:func:`~dynid.identification.floor_verdict.
    prediction_input_noise`), or None when it is not known."""
    assert model.info.log is not None  # identified from logs
    drive = model_drive(model, None)
    noise = state_noise([joint_side_log(p, drive) for p in pieces], model.info.log.cutoff_hz)

    def rigid(
        q: NDArray[np.float64], dq: NDArray[np.float64], ddq: NDArray[np.float64]
    ) -> NDArray[np.float64]:
        return np.asarray(torques_through(model, drive, q, dq, ddq), dtype=np.float64)

    friction = own_friction(model)
    fr = None if friction is None else friction.torques
    inputs = prediction_input_noise(rigid, fr, [v.log], noise, joint_separable(friction))
    return None if inputs is None else tuple(inputs)


def _despiked_from(log: TorqueLog, first: int = 0) -> tuple[TorqueLog, int]:
    """Rows ``first:`` of ``log`` with its torque spikes replaced as the identification
    replaced them before fitting (found on the whole log,
    :func:`~dynid.identification.spikes.despiked`), and how many of those rows' torque
    samples were replaced."""
    clean, _ = despiked(log)
    if clean is log:
        held = log if first == 0 else log.select(slice(first, None))
        return held, 0
    replaced = int(np.count_nonzero(clean.tau[first:] != log.tau[first:]))
    return (clean if first == 0 else clean.select(slice(first, None))), replaced


def _recorded_noise(model: IdentifiedModel) -> NDArray[np.float64] | None:
    """Each joint's sensor noise [N m] as the identification recorded it
    (``info.heldout["noise_rms"]``, the noise of its printed floor), or None for a record
    without it."""
    noise = (model.info.heldout or {}).get("noise_rms")
    if noise is None or np.shape(noise) != (model.robot.n,):
        return None
    return np.asarray(noise, dtype=np.float64)


def _pieces_validation(
    model: IdentifiedModel, pieces: list[TorqueLog]
) -> tuple[Validation, str, list[Validation]]:
    """``model`` on the pieces of a log cut at its gaps, each prepared on its own as the
    identification prepared them (one too short to filter is left out), pooled; what
    to add to the block's description; and each piece's validation.

    Raises
    ------
    DynidError
        Every piece too short (the first one's error).
    """
    friction = own_friction(model)
    parts, first = [], None
    for p in pieces:
        try:
            parts.append(validate_torques(model, p, friction=friction))
        except DynidError as exc:
            first = first or exc
    if not parts:
        assert first is not None
        raise first
    said = "" if len(pieces) == 1 else f" ({len(pieces)} pieces between gaps"
    if len(parts) < len(pieces):
        said += f", {len(pieces) - len(parts)} too short to filter left out"
    return joined_validation(parts), said + (")" if said else ""), parts
