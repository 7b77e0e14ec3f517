"""Validate a model against measured torque logs: the entry point of ``dynid validate``,
with every policy the command applies, so that the Python API behaves as the command does.

* The recordings (one or more files, or a folder) are read strictly with the model's
  joint count, through the column map the model's data were read with when none is given
  (:mod:`dynid.workflows.recordings`); their invalid rows dropped and their gaps bridged as
  the identification's were, unless given (:mod:`dynid.workflows.as_identified`).
* The friction added to the model: its own (an identified model's classical friction, a
  robot's published sigmoid, the friction stored in a ``feasible.json``), none, a
  friction file, or a friction model (:class:`ValidateOptions` ``friction``).
* The drive: the model's own (a ``feasible.json``'s), or the one given for a model without
  one (another one is refused, :func:`~dynid.friction.fit.model_drive`).
* The cut-off: the identification's recorded one, else the one identification reads from
  the recordings' motion (:func:`~dynid.friction.validation.recorded_cutoff`).
* Each recording, and each piece of one cut at a gap longer than ``max_gap_s``, is
  filtered and differentiated on its own; the errors are pooled over every sample and
  given per recording (:func:`~dynid.friction.recordings.validate_recordings`: a long
  piece prepared and predicted a block at a time).
* One-sample torque spikes (a sensor or logging fault) are replaced by the line between
  their neighbours before judging, by the rule ``identify`` replaces them by before
  fitting (:func:`~dynid.workflows.recordings.despiked_recordings`), with a warning per
  file; the verdict's reason and ``torque_spikes_replaced`` say how many: a model at the
  noise floor on clean data is judged at the floor on the same data with spikes.
* The verdict (:func:`~dynid.identification.verdict.judge_prediction`): the error against
  the noise floor, and whether the torques are anti-correlated with the model's. The floor
  is the sensors' noise read from the measured torques (a quantized sensor's at least
  ``step / sqrt(12)``) and the noise the prepared velocities and accelerations put into
  the model's prediction (:mod:`~dynid.identification.input_noise`), each sample weighed
  against its own noise: the true model of quantized positions is at the floor, while an
  error spread over the moving samples is not excused by the noise at a few reversals;
  over all recordings and per recording, the worst recording named when the recordings
  differ; an error mostly at low speed said so
  (:func:`~dynid.identification.low_speed.with_low_speed_hint`), and joints moved far
  faster than in an identified model's data
  (:func:`~dynid.identification.motion_range.with_motion_range_hint`).
* An error above the noise that sits in a few short spans of a recording (a contact, a
  logging fault) is said first, with the rest of the recording's error over the noise
  (:func:`~dynid.identification.error_spans.error_spans`), and the residual is then not
  diagnosed for a spring, a tilt or a load; a span at a velocity reversal of its joints
  that stands off by no more than the model's friction steps there is said to be
  friction's step at those reversals, not a contact
  (:func:`~dynid.identification.friction_steps.friction_step`).
"""

from __future__ import annotations

import dataclasses
import functools
import logging
import warnings
from collections.abc import Callable, Sequence
from dataclasses import dataclass
from pathlib import Path
from typing import Any, Literal

import numpy as np
from numpy.typing import NDArray

from .. import _checks
from .._checks import caller_level
from ..exceptions import DataError, DynidWarning, OptionError
from ..friction.delay_check import validations_delay
from ..friction.fit import model_drive, same_drive, torques_through
from ..friction.model import (
    FrictionModel,
    FrictionSum,
    joint_separable,
    own_at_motors_note,
    placed_friction,
)
from ..friction.recordings import RecordingsValidation, validate_recordings
from ..friction.validation import RECORDED, own_friction, recorded_cutoff
from ..identification.coefficient_noise import coefficient_noise
from ..identification.drive_gains import DriveGains
from ..identification.error_spans import ErrorSpans, error_spans
from ..identification.floor_verdict import (
    judged_prediction,
    opposite_sign,
    prediction_input_noise,
    sensor_variance,
)
from ..identification.gravity_scale import recorded_scale
from ..identification.gravity_tilt import GravityTilt
from ..identification.log import TorqueLog
from ..identification.metrics import TorqueErrors
from ..identification.model import IdentifiedModel, kinematics_of
from ..identification.motion_range import motion_range_hint, with_motion_range_hint
from ..identification.pieces import check_below_nyquist
from ..identification.recorded_signs import SignFinding
from ..identification.residual_spring import ResidualSpring
from ..identification.spikes import SPIKES_BEFORE_JUDGING
from ..identification.torque_delay import AppliedDelay, TorqueDelay, applied_delay
from ..identification.training_range import OutsideTraining, endless_joints
from ..identification.velocity_noise import noise_band
from ..identification.verdict import LEVELS, Verdict, with_hint, with_replaced_spikes
from ..io.feasible import load_feasible_drive, load_feasible_linear_friction
from ..io.friction_json import load_friction_json
from ..model.drive import Drive
from ..model.robot import Robot
from ..observer.friction import banded_if_narrow, banding_note, noise_bands
from ..observer.residual_load import ResidualLoad
from ..progress import NOTE
from .as_identified import identification_beside, read_as_identified
from .data_files import ColumnSpec, data_files, data_kind, in_file
from .options import (
    NO_FILTER,
    Cutoff,
    check_number,
    checked_options,
    library_cutoff,
    velocity_cutoff,
)
from .recordings import (
    Recorded,
    despiked_recordings,
    read_recordings,
    recorded_sign_map_findings,
    unwrapped_recorded,
    warn_signs,
)
from .validate_hints import JudgedNoise, ResidualHints, residual_hints, terms_held
from .validate_outside import outside_said, training_record

__all__ = ["ValidateOptions", "ValidateResult", "identification_beside", "validate_files"]

_log = logging.getLogger(__name__)

#: The validation's own sign warning (:mod:`dynid.friction.validation`), which names no
#: joint and no ``--units``: left out where the sign findings were said.
_VAGUE_SIGN = r"the measured torques are anti-correlated with the model's \(correlation"


@dataclass(frozen=True, slots=True)
class ValidateOptions:
    """How :func:`validate_files` compares a model with its recordings.

    Attributes
    ----------
    friction : "own", "none", str, Path or FrictionModel
        The friction added to the model: its own (default), none, a friction file
        (``friction.json``) or a friction model.
    columns : (str or None, str or None), optional
        Column names and units of another tool's files; default: the model's recorded ones.
    drop_invalid : bool
        Drop rows with NaN/inf or a repeated timestamp (counted) instead of failing;
        False: as the identification did (:func:`~dynid.workflows.as_identified.
        read_as_identified`, with a note), else refused.
    cutoff_hz : float or "none", optional
        Low-pass cut-off of the states [Hz]; default: the identification's recorded one
        (no filter if it was identified without), else the one read from the recordings'
        motion; ``"none"`` (:data:`~dynid.workflows.options.NO_FILTER`): no low-pass.
    max_gap_s : float, optional
        Longest gap bridged by interpolation [s]; a longer one cuts a recording into
        pieces; default: the identification's recorded one (a note names it), else the
        default rule.
    torque_delay_s : float, optional
        How far the torques lag the positions [s] (positive: the torques late): each
        piece's torques read that much later before filtering
        (:attr:`~dynid.identification.prepare.Preprocessing.torque_delay_s`); default:
        the identification's recorded one, 0 for a robot.
    drive : Drive, optional
        The drive the recordings were recorded through, for a model without one.
    q_start : tuple of float, optional
        Joint positions [rad] at the first sample of one motor-side recording whose motor
        encoders wrap every turn: the motors' whole turns are those that put the joints
        nearest them (:func:`~dynid.workflows.recordings.given_start`).

    Raises
    ------
    OptionError
        A cut-off or a longest gap that is not a positive number; a friction that is
        none of the above.
    """

    friction: Literal["own", "none"] | str | Path | FrictionModel = "own"
    columns: ColumnSpec | None = None
    drop_invalid: bool = False
    cutoff_hz: Cutoff = None
    max_gap_s: float | None = None
    torque_delay_s: float | None = None
    drive: Drive | None = None
    q_start: tuple[float, ...] | None = None

    def __post_init__(self) -> None:
        for name, what in (
            ("cutoff_hz", "the low-pass cut-off [Hz]"),
            ("max_gap_s", "the longest gap bridged [s]"),
        ):
            v = getattr(self, name)
            if name == "cutoff_hz" and v == NO_FILTER:
                continue
            if v is not None and not (isinstance(v, int | float) and np.isfinite(v) and v > 0):
                raise OptionError(
                    f"{name} ({what}) must be a positive number; got {_checks.short(v)}"
                )
        check_number(self, "torque_delay_s", low=-1.0, high=1.0)
        fr = self.friction
        if not isinstance(fr, str | Path) and not hasattr(fr, "torques"):
            raise OptionError(
                "friction (the friction added to the model) must be 'own', 'none', a "
                f"friction file or a friction model; got {type(fr).__name__}"
            )


@dataclass(frozen=True, slots=True, eq=False)
class ValidateResult:
    """Result of :func:`validate_files`.

    Attributes
    ----------
    validation : RecordingsValidation
        The errors pooled and per recording, every piece's prediction.
    model : str
        What the model is (its file, or ``robot panda``).
    friction_source : str or None
        ``"model"`` (its own), a friction file's name, ``"given"``, or None.
    files : tuple of str
        The recordings' file names.
    cutoff_hz : float or None
        The low-pass cut-off every piece was filtered at [Hz].
    verdict : Verdict
        Over every recording, or, when the recordings differ, the worst one's (its ``reason``
        names the file).
    noise_rms : ndarray, shape (n,)
        The noise a perfect model leaves per joint, over every piece [N m]: the torque
        sensors' (``sensor_noise_rms``), that of the states it is evaluated at
        (``input_noise_rms``) and, of an identified model, that of its coefficients
        (``fit_noise_rms``), root sum of squares.
    noise_floor_percent : float
        The noise relative to the measured torques' norm [%]: the smallest relative error
        a model can reach on them.
    joint_names : tuple of str
        The robot's joints, in the columns' order (empty: not known).
    spikes : tuple of int
        Torque samples of each recording replaced as one-sample spikes before judging
        (empty: not known).
    sensor_noise_rms, input_noise_rms : ndarray, shape (n,), optional
        The parts of ``noise_rms`` [N m].
    fit_noise_rms : ndarray, shape (n,), optional
        The part of ``noise_rms`` an identified model's coefficients put into its
        prediction through their recorded covariance [N m]
        (:mod:`~dynid.identification.coefficient_noise`); None: not counted (a robot's
        parameters, a model whose file records no covariance of every coefficient).
    joint_ratios : ndarray, shape (n,), optional
        Each joint's error over its noise as the verdict weighed it (each sample against
        its own noise), the numbers its reason gives; None: not known.
    sign_map : str, optional
        Where the torque signs the applied ``--units`` negate (the model's recorded ones,
        ``tau=-1`` or ``tau3=-1``, or those given) look wrong for a recording, the
        finding (naming the file, the joints and the ``--units`` that read it right given
        those applied: ``tau=1`` for a file already in dynid's sign;
        :func:`~dynid.workflows.recordings.recorded_sign_map_findings`), also the start of
        ``verdict``'s reason; None otherwise.
    opposite_sign : tuple of (str, str)
        Per recording whose torques read with the opposite sign to the model's on some
        joints or on all, its name and the finding (naming the joints and the
        ``--units`` entries that read them, the recording's own, ``rec2.csv:tau4=-1``,
        when another reads right: :func:`~dynid.workflows.recordings.sign_findings`, the
        rule ``identify`` and ``observe`` refuse by), said at the start of ``verdict``'s
        reason (after ``sign_map``) in place of a diagnosis of the residual; empty
        otherwise.
    springs : ResidualSpring, optional
        The stiffness per joint [N m/rad] the residual points to, fitted with the model's
        columns to the recordings joined (:func:`~dynid.friction.heldout_torques.
        residual_springs`; its named joints the verdict's reason names with their
        stiffness); None: not judged (a good verdict, or no diagnosis of the residual).
    reversed_columns : tuple of (str, str)
        Per recording with columns recorded reversed (a motor or encoder mounted the
        other way: its position, velocity and effort negated), its name and the finding
        (the joints or motors and the ``--units`` entries, ``q6=-1,tau6=-1``, in the log's
        own columns), said at the start of ``verdict``'s reason as ``opposite_sign`` is;
        empty otherwise.
    torque_delay : TorqueDelay, optional
        The lag of the torques behind the positions the residual points to
        (:func:`~dynid.friction.delay_check.validations_delay`); said in ``verdict``'s
        reason when :attr:`~dynid.identification.torque_delay.TorqueDelay.named`.
    applied_delay : AppliedDelay, optional
        The delay the recordings were prepared with and where it came from (given, or the
        model's record); None: none applied.
    gravity_tilt : GravityTilt, optional
        The tilt of the gravity vector the residual points to, fitted with the model's
        columns to the recordings joined (:func:`~dynid.friction.heldout_torques.
        residual_tilt`; said in ``verdict``'s reason when
        :attr:`~dynid.identification.gravity_tilt.GravityTilt.named`); None: not judged.
    gains : DriveGains, optional
        The gain per motor of the logged efforts the residual points to, judged on the
        recordings' contiguous time blocks held out in turn as identify's held-out verdict
        judges them (:func:`~dynid.friction.heldout_torques.residual_gains`; its named
        motors' factors the verdict's reason names, in place of a spring or a tilt); judged
        on a current log even beside a sign finding; None: not judged (a good verdict).
    flange_load : ResidualLoad, optional
        The rigid load at the flange fitted to the residual
        (:func:`~dynid.observer.residual_load.residual_load`; named first in ``verdict``'s
        reason, the joints diagnosed on what it leaves, when
        :attr:`~dynid.observer.residual_load.ResidualLoad.named`); None: not judged.
    outside : OutsideTraining, optional
        The joints the recordings take outside the positions and velocities the model was
        identified on (:mod:`~dynid.workflows.validate_outside`, said in ``verdict``'s
        reason); None: none, or no record of them.
    """

    validation: RecordingsValidation
    model: str
    friction_source: str | None
    files: tuple[str, ...]
    cutoff_hz: float | None
    verdict: Verdict
    noise_rms: NDArray[np.float64]
    noise_floor_percent: float
    joint_names: tuple[str, ...] = ()
    spikes: tuple[int, ...] = ()
    sensor_noise_rms: NDArray[np.float64] | None = None
    input_noise_rms: NDArray[np.float64] | None = None
    fit_noise_rms: NDArray[np.float64] | None = None
    joint_ratios: NDArray[np.float64] | None = None
    sign_map: str | None = None
    opposite_sign: tuple[tuple[str, str], ...] = ()
    springs: ResidualSpring | None = None
    reversed_columns: tuple[tuple[str, str], ...] = ()
    torque_delay: TorqueDelay | None = None
    applied_delay: AppliedDelay | None = None
    gravity_tilt: GravityTilt | None = None
    gains: DriveGains | None = None
    flange_load: ResidualLoad | None = None
    error_spans: ErrorSpans | None = None
    outside: OutsideTraining | None = None

    def metadata(self) -> dict[str, Any]:
        """The keys ``validation.json`` records beside the errors: ``model``,
        ``friction_source``, ``data`` (the files, comma-separated), ``files``,
        ``cutoff_hz``, ``noise_rms``, ``noise_floor_percent``, ``sensor_noise_rms``,
        ``input_noise_rms`` and ``fit_noise_rms`` (its parts, when known),
        ``joint_ratios`` (each joint's error over its noise as the verdict weighed it,
        when known), ``torque_spikes_replaced`` (per file,
        when known), ``sign_map`` (the recorded sign map's finding, when there is one),
        ``opposite_sign`` (by file, the finding that its torques read with the opposite
        sign on some joints or on all, with the ``--units`` that reads them; when there is
        one), ``reversed_columns`` (by file, the finding that columns were recorded
        reversed, with the ``--units`` that reads them; when there is one),
        ``verdict`` (``level``, ``label``, ``reason``), ``joint_names`` (when known) and
        ``springs`` (the stiffness per joint the residual points to, when judged:
        :meth:`~dynid.identification.residual_spring.ResidualSpring.as_dict`),
        ``gravity_tilt`` (the tilt of the gravity vector the residual points to, as
        ``heldout.json`` records it: null when not judged),
        ``flange_load`` (the rigid load at the flange the residual was fitted with:
        :meth:`~dynid.observer.residual_load.ResidualLoad.as_dict`, its ``named`` whether
        the verdict names it; null when not judged),
        ``drive_gains`` (the gains per motor, when judged:
        :meth:`~dynid.identification.drive_gains.DriveGains.as_dict`) and
        ``torque_delay`` (the torques' lag behind the positions, when named:
        :meth:`~dynid.identification.torque_delay.TorqueDelay.as_dict`) and
        ``torque_delay_used`` (the delay the recordings were prepared with and its source,
        when one was applied or given:
        :meth:`~dynid.identification.torque_delay.AppliedDelay.as_dict`) and
        ``outside_training`` (the joints the recordings take outside the positions and
        velocities the model was identified on, when any:
        :meth:`~dynid.identification.training_range.OutsideTraining.as_dict`)."""
        v = self.verdict
        spikes = dict(zip(self.files, self.spikes, strict=True)) if self.spikes else None
        parts = {
            k: [float(x) for x in a]
            for k, a in (
                ("sensor_noise_rms", self.sensor_noise_rms),
                ("input_noise_rms", self.input_noise_rms),
                ("fit_noise_rms", self.fit_noise_rms),
                ("joint_ratios", self.joint_ratios),
            )
            if a is not None
        }
        return {
            "model": self.model,
            "friction_source": self.friction_source,
            "data": ", ".join(self.files),
            "files": list(self.files),
            "cutoff_hz": self.cutoff_hz,
            "noise_rms": [float(x) for x in self.noise_rms],
            "noise_floor_percent": self.noise_floor_percent,
            **parts,
            **({"torque_spikes_replaced": spikes} if spikes is not None else {}),
            **({"sign_map": self.sign_map} if self.sign_map is not None else {}),
            **({"opposite_sign": dict(self.opposite_sign)} if self.opposite_sign else {}),
            **({"reversed_columns": dict(self.reversed_columns)} if self.reversed_columns else {}),
            "verdict": {"level": v.level, "label": v.label, "reason": v.reason},
            **({"springs": self.springs.as_dict()} if self.springs is not None else {}),
            "gravity_tilt": None if self.gravity_tilt is None else self.gravity_tilt.as_dict(),
            "flange_load": None if self.flange_load is None else self.flange_load.as_dict(),
            "error_spans": None if (b := self.error_spans) is None else b.as_dict(),
            **({"drive_gains": self.gains.as_dict()} if self.gains is not None else {}),
            **({"torque_delay": d.as_dict()} if (d := self.torque_delay) and d.named else {}),
            **({"torque_delay_used": a.as_dict()} if (a := self.applied_delay) else {}),
            **({"outside_training": o.as_dict()} if (o := self.outside) is not None else {}),
        } | ({"joint_names": list(self.joint_names)} if self.joint_names else {})


def _torque_logs(
    data: str | Path | Sequence[str | Path],
) -> str | Path | Sequence[str | Path]:
    """``data``, torque logs: static data (``q, M, g``) among them refused, saying what
    judges a model there.

    Raises
    ------
    DataError
        Naming the file and :func:`~dynid.workflows.validate_static.validate_static_file`.
    """
    for path in data_files(data):
        try:
            static = data_kind(path) == "static"
        except (DataError, OSError):  # the torque log's reader names it in its own words
            continue
        if static:
            raise DataError(
                f"{path.name} holds static data (q, M, g): validate_files judges a model's "
                "torques on torque logs (t, q, dq, tau); hint: validate_static_file(model, "
                "path) judges its M and g at the file's configurations (as `dynid validate` "
                "does given static data)"
            )
    return data


def validate_files(
    model: IdentifiedModel | Robot,
    data: str | Path | Sequence[str | Path],
    options: ValidateOptions | None = None,
    *,
    feasible: str | Path | None = None,
    label: str | None = None,
    recorded: Recorded | None = None,
    source: str | Path | None = None,
) -> ValidateResult:
    """Compare ``model``'s torques, without and with friction, with the recordings ``data``.

    The data are read and prepared as an identified model records (column map, cut-off, gap
    rule, torque delay; an option given replaces its part): ``model``, or the one beside a
    ``feasible`` file (:func:`identification_beside`), with a note (:func:`_own_record`).

    Parameters
    ----------
    model : IdentifiedModel or Robot
        An identified model, or a robot's own link parameters (RNEA).
    data : str, Path or a sequence of them
        One or more torque logs (``.csv``/``.npz``; a folder: its data files).
    options : ValidateOptions, optional
    feasible : str or Path, optional
        The ``feasible.json`` the robot ``model`` was read from: the friction and the drive
        stored in it are the model's own, the record of the identification beside it the
        data's reading and preparation.
    label : str, optional
        What the model is, for the record (default: its robot's name).
    recorded : Recorded, optional
        The recordings ``data`` already read and checked for this model (``dynid observe
        --calibrate`` judging its model on its logs): not read again.
    source : str or Path, optional
        The ``identification.json`` an identified ``model`` was read from: a note names a
        consistent model's ``feasible.json`` beside it (``identify --consistent``).

    Returns
    -------
    ValidateResult

    Raises
    ------
    DataError
        A bad file, static data, another joint count, invalid rows without ``drop_invalid``,
        other units, no piece long enough to filter, another drive, overflowing errors (named).
    ShapeError
        A friction model of another joint count.
    """
    robot = kinematics_of(model)
    own = _own_record(model, feasible, source)  # whose record reads and prepares the data
    opt = _as_identified(checked_options(options, ValidateOptions), own)  # as identify read
    drive, placed = _drives(model, opt.drive, feasible)
    rec = recorded or read_recordings(
        _torque_logs(data), robot, recorded=None if own is None else own.info.column_map,
        columns=opt.columns, drop_invalid=opt.drop_invalid, q_start=opt.q_start,
        cutoff_hz=velocity_cutoff(opt.cutoff_hz), owner=f"the model ({label or robot.name})",
        drive=placed, max_gap_s=opt.max_gap_s, reference=_reference(model),
    )  # fmt: skip
    checked = unwrapped_recorded(rec, robot, opt.max_gap_s)  # as the preparation reads them
    sign_map, opposite = _said_signs(checked, model, opt, own)  # before the verdict
    _say_training_data(model if own is None else own, rec.names)
    rec, spikes = despiked_recordings(rec, robot.joint_names, SPIKES_BEFORE_JUDGING)
    friction, fr_source = _friction(model, opt.friction, feasible, placed)
    cut, gap, lag = _prepared_as(opt, model, own, rec.logs)

    def run(fr: FrictionModel | FrictionSum | None) -> RecordingsValidation:
        with warnings.catch_warnings():
            if sign_map is not None or opposite:  # said with the joints and the --units
                warnings.filterwarnings("ignore", _VAGUE_SIGN, DynidWarning)
            return validate_recordings(
                model, rec.logs, rec.names, friction=fr, cutoff_hz=cut, max_gap_s=gap,
                drive=drive, torque_delay_s=lag,
            )  # fmt: skip

    val = in_file(rec.paths[0], lambda: _banded(run, friction)) if len(rec.paths) == 1 else None
    val = _banded(run, friction) if val is None else val  # friction as observe evaluates it
    errors, names = _finite(val, rec.names, label, opt), robot.joint_names
    parts = _input_noise(model, val.friction, val), _coefficient_noise(
        model, val, fr_source == "model" and feasible is None, rec.names)  # fmt: skip
    verdict, noise, floor = _judged(val, np.ones(len(val.parts), bool), errors, names, *parts)
    verdict = _worst_recording(val, verdict, rec.names, names, *parts)
    burst = _error_spans(verdict, val, rec.logs, noise)  # a contact: not the model's
    speeds, dq = _identified_speeds(model if own is None else own), [v.log.dq for v in val.parts]
    # a motion beyond the identification's is the likelier cause of what the residual follows
    beyond = motion_range_hint(speeds, dq, names) is not None
    # a torque of the opposite sign leaves twice the torque, which no term of the model
    # explains: what the residual follows is not diagnosed (a current log's gains are)
    current = not beyond and placed is not None and placed.effort == "current"
    hints, outside = _hinted(model if own is None else own, functools.partial(
            residual_hints, model, verdict, val, rec.logs, noise, names,
            held=terms_held(model, placed, label), gains_too=current,
            payload=_payload_command(model, data, label, feasible, source),
        ), not beyond and not opposite and sign_map is None and burst is None, val, noise,
    )  # fmt: skip
    verdict, gains = with_motion_range_hint(hints.verdict, speeds, dq, names), hints.gains
    named = gains is not None and bool(gains.named)  # a scale off leaves no lag to name
    verdict, delay, applied = _with_delay(model, verdict, val, opt.torque_delay_s, named, own)
    files = ", ".join(f"{n} {c}" for n, c in zip(rec.names, spikes, strict=True) if c)
    verdict = with_replaced_spikes(verdict, sum(spikes), f" before judging ({files})")
    verdict = _spans_first(verdict, burst, names, len(rec.names))  # first, after a sign's
    verdict = _signs_first(verdict, opposite, sign_map)
    return ValidateResult(
        validation=val,
        model=label or f"robot {robot.name}",
        friction_source=fr_source,
        files=rec.names,
        cutoff_hz=val.pieces.cutoff_hz,
        verdict=verdict,
        noise_rms=noise.total,
        noise_floor_percent=floor,
        joint_names=tuple(robot.joint_names),
        spikes=spikes,
        sensor_noise_rms=noise.sensor, input_noise_rms=noise.inputs, fit_noise_rms=noise.fitted,
        joint_ratios=noise.ratios,
        sign_map=sign_map,
        opposite_sign=tuple((f.name, f.text) for f in opposite if f.kind == "opposite"),
        reversed_columns=tuple((f.name, f.text) for f in opposite if f.kind == "reversed"),
        springs=hints.springs, gains=gains, torque_delay=delay, applied_delay=applied,
        gravity_tilt=hints.tilt, flange_load=hints.load, error_spans=burst, outside=outside,
    )  # fmt: skip


def _as_identified(opt: ValidateOptions, own: IdentifiedModel | None) -> ValidateOptions:
    """``opt`` with ``drop_invalid`` and ``max_gap_s`` as given, else as ``own``'s
    identification read its logs (:func:`~dynid.workflows.as_identified.read_as_identified`,
    with a note)."""
    record = None if own is None else own.info.log
    drop, gap = read_as_identified(record, opt.drop_invalid, opt.max_gap_s)
    return dataclasses.replace(opt, drop_invalid=drop, max_gap_s=gap)


def _drives(
    model: IdentifiedModel | Robot, given: Drive | None, feasible: str | Path | None
) -> tuple[Drive | None, Drive | None]:
    """The drive the recordings were recorded through (``given``, or a ``feasible`` file's,
    which holds the rotor inertias identified; refused where they differ) and the one the
    model's friction is placed by (an identified model's own without either)."""
    drive = given
    if feasible is not None:
        held = load_feasible_drive(feasible)
        drive = same_drive(drive, held, Path(feasible).name, f"the one {Path(feasible).name} holds")
    elif isinstance(model, IdentifiedModel) and drive is not None:  # read as the fit reads
        drive = model_drive(model, drive)  # (constants identify read x a shared gear ratio)
    placed = model.drive if drive is None and isinstance(model, IdentifiedModel) else drive
    return drive, placed


def _recorded_delay(model: IdentifiedModel | Robot | None) -> float:
    """The delay [s] an identified model was identified with (0: a robot, static data)."""
    own = model.info.log if isinstance(model, IdentifiedModel) else None
    return 0.0 if own is None else float(own.torque_delay_s)


def _own_record(
    model: IdentifiedModel | Robot, feasible: str | Path | None, source: str | Path | None
) -> IdentifiedModel | None:
    """The identified model whose record the data are read and prepared by: ``model``
    itself (with a note where a ``feasible.json`` beside its ``source`` holds the
    consistent model of the same run), the one beside a ``feasible`` file (a note names
    it), or None."""
    if isinstance(model, IdentifiedModel):
        read = None if source is None else Path(source)
        other = None if read is None else read.with_name("feasible.json")
        if read is not None and other is not None and other != read and other.is_file():
            _log.log(
                NOTE,
                "%s holds the least-squares model, which is validated here; the physically "
                "consistent model beside it is validated with --params %s",
                read.name,
                other,
            )
        return model
    own = None if feasible is None else identification_beside(feasible, model)
    if own is not None:
        _log.log(
            NOTE,
            "%s: the data read and prepared as identification.json beside it records (its "
            "--columns/--units, cut-off, gap rule and torque delay), as --model reads them; "
            "each given replaces its part",
            Path(str(feasible)).name,
        )
    return own


def _prepared_as(
    opt: ValidateOptions,
    model: IdentifiedModel | Robot,
    own: IdentifiedModel | None,
    logs: Sequence[TorqueLog],
) -> tuple[Any, float | None, float | None]:
    """The cut-off [Hz] (or ``"recorded"``, None: no filter), the longest gap bridged [s]
    and the torque delay [s] the recordings ``logs`` are prepared with: each option given,
    else the record of ``own`` (:func:`_own_record`); ``model``'s own where it is
    ``own``."""
    cut = library_cutoff(opt.cutoff_hz, RECORDED)
    if own is None or own is model or own.info.log is None:
        return cut, opt.max_gap_s, opt.torque_delay_s
    log = own.info.log
    gap = log.preprocessing.max_gap_s if opt.max_gap_s is None else opt.max_gap_s
    lag = float(log.torque_delay_s) if opt.torque_delay_s is None else opt.torque_delay_s
    return (recorded_cutoff(own, logs) if cut == RECORDED else cut), gap, lag


def _with_delay(
    model: IdentifiedModel | Robot,
    verdict: Verdict,
    val: RecordingsValidation,
    given_s: float | None,
    gains_named: bool = False,
    own: IdentifiedModel | None = None,
) -> tuple[Verdict, TorqueDelay | None, AppliedDelay | None]:
    """``verdict`` with the torques' lag behind the positions the residual points to
    (:func:`~dynid.friction.delay_check.validations_delay`) appended when it is named, the
    delay, and the one the recordings were prepared with (``given_s`` [s], else the model's,
    ``own``'s: :func:`_own_record`). Of an identified model the hint is to identify it again
    with the whole delay (the one applied and the residual's): its coefficients were fitted
    to the lagging torques. Where the verdict names a gain per motor (``gains_named``), no
    delay is said: efforts read through a torque constant 1.3 times off left a residual that
    read as the torques leading by 3.0 ms (std 0.9) on a log without any lag."""
    applied = applied_delay(given_s, _recorded_delay(model if own is None else own))
    delay = None if gains_named else validations_delay(model, val.parts)
    if delay is not None and delay.named:
        before = 0.0 if applied is None else applied.delay_s
        refit = isinstance(model, IdentifiedModel) and model.info.log is not None
        verdict = with_hint(verdict, delay.sentence(before, refit=refit, fit=False))
    return verdict, delay, applied


def _identified_speeds(model: IdentifiedModel | Robot) -> Any:
    """Each joint's largest speed [rad/s] over the identification's samples, or None (a
    robot, a model of static data)."""
    if isinstance(model, IdentifiedModel) and model.info.log is not None:
        return model.info.log.speed_max
    return None


def _hinted(
    trained: IdentifiedModel | Robot,
    hints: Callable[..., ResidualHints],
    dependence: bool,
    val: RecordingsValidation,
    noise: JudgedNoise,
) -> tuple[ResidualHints, OutsideTraining | None]:
    """The verdict's hints (``hints``, :func:`~.validate_hints.residual_hints` given all but
    ``dependence``), with the joints the recordings take outside the motion ``trained``
    was identified on said, and no cause asserted where they lie clearly outside its poses
    (:func:`~.validate_outside.outside_said`)."""
    robot = kinematics_of(trained)
    units = ["m" if p else "rad" for p in robot.prismatic]
    return outside_said(
        training_record(trained), hints(dependence=dependence),
        lambda: hints(dependence=False), val, noise, robot.joint_names, units,
        endless_joints(robot.q_min, robot.q_max, robot.prismatic),
    )  # fmt: skip


def _payload_command(
    model: IdentifiedModel | Robot,
    data: str | Path | Sequence[str | Path],
    label: str | None,
    feasible: str | Path | None,
    source: str | Path | None,
) -> str:
    """The ``dynid payload`` command that measures a load on the recordings ``data`` with
    the model validated: ``--model`` its file, ``--params`` a feasible file's, else
    ``--robot`` (``label`` ``"robot panda"``)."""
    files = [data] if isinstance(data, str | Path) else list(data)
    given = " ".join(str(f) for f in files)
    if isinstance(model, IdentifiedModel):
        what = f"--model {source or label or 'identification.json'}"
    elif feasible is not None:
        what = f"--params {feasible}"
    else:
        what = f"--robot {(label or model.name).removeprefix('robot ')}"
    return f"`dynid payload {what} --data {given} --out DIR`"


def _input_noise(
    model: IdentifiedModel | Robot,
    friction: FrictionModel | FrictionSum | None,
    val: RecordingsValidation,
) -> list[tuple[int, NDArray[np.float64]]] | None:
    """Per piece, the states' noise through the model's prediction
    (:func:`~dynid.identification.floor_verdict.prediction_input_noise`), or None when the
    states' noise is not known."""
    drive = val.pieces.drive

    def rigid(
        q: NDArray[np.float64], dq: NDArray[np.float64], ddq: NDArray[np.float64]
    ) -> NDArray[np.float64]:
        return np.asarray(torques_through(model, drive, q, dq, ddq), dtype=np.float64)

    fr = None if friction is None else friction.torques
    logs = [v.log for v in val.parts]
    separable = joint_separable(friction)
    return prediction_input_noise(rigid, fr, logs, val.pieces.state_noise, separable)


#: How the verdict's floor names the part the model's coefficients put into its prediction.
_FITTED_WORDS = "that of the model's coefficients (their recorded covariance) through the model"


def _coefficient_noise(
    model: IdentifiedModel | Robot,
    val: RecordingsValidation,
    own_friction: bool,
    files: Sequence[str],
) -> list[tuple[int, NDArray[np.float64]]] | None:
    """Per piece, the variance an identified ``model``'s coefficients put into its
    prediction as the floor counts it, at its mean plus one standard deviation of their
    one draw (:func:`~dynid.identification.coefficient_noise.coefficient_noise`; its
    friction's columns with its ``own_friction``), none on the pieces of recordings
    (``files``) it was identified from; None for a robot or a model that records no
    covariance of every coefficient."""
    if not isinstance(model, IdentifiedModel):
        return None
    trained = set(model.info.fitted_on(files))
    seen = [files[r] in trained for r in val.pieces.recording]
    logs, tau = [v.log for v in val.parts], [v.tau_model for v in val.parts]
    found = coefficient_noise(model, logs, tau, friction=own_friction, seen=seen)
    return None if found is None else found.counted


def _judged(
    val: RecordingsValidation,
    sel: NDArray[np.bool_],
    errors: TorqueErrors,
    names: Sequence[str],
    inputs: list[tuple[int, NDArray[np.float64]]] | None = None,
    fitted: list[tuple[int, NDArray[np.float64]]] | None = None,
) -> tuple[Verdict, JudgedNoise, float]:
    """The verdict, the noise per joint and the noise floor [%] of the pieces ``sel`` (bool
    per piece), whose pooled errors are ``errors``
    (:func:`~dynid.identification.floor_verdict.judged_prediction`): the sensors' noise
    read from each piece's measured torques
    (:func:`~dynid.identification.floor_verdict.sensor_variance`) and the states' through
    the model (``inputs``: :func:`_input_noise`; None: not known) and the model's
    coefficients' (``fitted``: :func:`_coefficient_noise`; None: not counted); the
    model's torques checked for the opposite sign."""
    chosen = [k for k, s in enumerate(sel) if s]
    parts = [val.parts[k] for k in chosen]
    verdict, fl = judged_prediction(
        [v.log.tau for v in parts],
        [v.log.tau - v.tau_hat for v in parts],
        [sensor_variance(v.log) for v in parts],
        errors,
        names,
        None if inputs is None else [inputs[k] for k in chosen],
        opposite=opposite_sign([v.log.tau for v in parts], [v.tau_hat for v in parts]),
        fitted=None if fitted is None else [fitted[k] for k in chosen],
        fitted_words=_FITTED_WORDS,
    )
    return (
        verdict,
        JudgedNoise(fl.sensor_rms, fl.input_rms, fl.total_rms, fl.joint_ratios, fl.fit_rms),
        fl.percent,
    )


def _error_spans(
    verdict: Verdict, val: RecordingsValidation, logs: Sequence[TorqueLog], noise: JudgedNoise
) -> ErrorSpans | None:
    """Above the noise floor, the recording whose error above the noise sits in a few short
    spans (:func:`~dynid.identification.error_spans.error_spans`, each recording's pieces
    joined against the noise per joint; the spans of friction's step at the prepared
    velocities' reversals, their standstill band that of the pieces' velocity noise, told
    from a contact), the largest error first; None: none."""
    if verdict.level == "good":
        return None
    found = []
    band = noise_band(val.pieces.dq_noise_std)
    for k, name in enumerate(val.pieces.names):
        mine = [v for v, r in zip(val.parts, val.pieces.recording, strict=True) if r == k]
        if not mine:
            continue
        t = np.concatenate([np.asarray(v.log.t, dtype=np.float64) for v in mine])
        e = np.concatenate([v.log.tau - v.tau_hat for v in mine])
        dq = np.concatenate([np.asarray(v.log.dq, dtype=np.float64) for v in mine])
        f = np.concatenate(
            [np.zeros_like(v.tau_hat) if v.tau_friction is None else v.tau_friction for v in mine]
        )
        t0 = float(logs[k].t[0]) if k < len(logs) and len(logs[k].t) else None
        spans = error_spans(t, e, noise.total, name, t0, dq=dq, friction=f, band=band)
        if spans is not None:
            found.append((float(np.sum(e**2)), spans))
    return max(found, key=lambda f: f[0])[1] if found else None


def _spans_first(
    verdict: Verdict, burst: ErrorSpans | None, names: Sequence[str], files: int
) -> Verdict:
    """``verdict`` with where its error sits (:func:`_error_spans`) first in its reason,
    naming the recording among ``files`` > 1."""
    if burst is None:
        return verdict
    said = burst.sentence(tuple(names), named=files > 1)
    rest = verdict.reason  # its remedy blames the model, which the span clears
    for blame in (_MISSES, _MISSES.replace("show", "show there")):
        rest = rest.replace(f": {blame}", "")
    return dataclasses.replace(verdict, reason=f"{said}; over every sample: {rest}")


#: The remedy of a poor verdict (:mod:`~dynid.identification.verdict`), left out after a
#: span that holds the error.
_MISSES = "the model misses effects the data show (model terms, excitation, the drive)"


def _worst_recording(
    val: RecordingsValidation,
    verdict: Verdict,
    files: Sequence[str],
    names: Sequence[str],
    inputs: list[tuple[int, NDArray[np.float64]]] | None,
    fitted: list[tuple[int, NDArray[np.float64]]] | None = None,
) -> Verdict:
    """The pooled ``verdict``, or with several recordings (``files``) judged apart the
    worst one's, named, where they differ and it is at least as bad as the pooled one
    (``names``: the joints'; ``inputs`` and ``fitted`` the floor's parts per piece as
    :func:`_judged` takes them)."""
    if len(files) < 2:
        return verdict
    labels = np.asarray(val.pieces.recording)
    each = [
        _judged(val, labels == r, val.recordings[r].errors, names, inputs, fitted)[0]
        for r in range(len(files))
    ]
    rank = [LEVELS.index(v.level) for v in each]
    r = int(np.argmax(rank))
    if min(rank) < rank[r] and rank[r] >= LEVELS.index(verdict.level):
        v = each[r]
        return Verdict(v.level, v.label, f"{files[r]}: {v.reason}", v.ratio)
    return verdict


def _said_signs(
    rec: Recorded, model: IdentifiedModel | Robot, opt: ValidateOptions, own: IdentifiedModel | None
) -> tuple[str | None, tuple[SignFinding, ...]]:
    """Warn of the recordings whose torques look of the opposite sign: first those for
    which the model's recorded sign map looks wrong
    (:func:`~dynid.workflows.recordings.recorded_sign_map_findings`), then the others
    (:func:`~dynid.workflows.recordings.warn_signs`, the rule ``identify`` and ``observe``
    refuse by: columns recorded reversed, torques of the opposite sign, a motor of the
    opposite sign to the other recordings' or to the model's own friction and rotor,
    :func:`_model_friction`); the former's findings, joined, or None, and the latter's.
    A cut-off given at or above half the sample rate is refused first
    (:func:`~dynid.identification.pieces.check_below_nyquist`): the option is at fault,
    not the data (a short log read a joint reversed before it was refused)."""
    given = library_cutoff(opt.cutoff_hz, RECORDED)
    if isinstance(given, int | float):
        check_below_nyquist(list(rec.logs), float(given))
    robot = model.robot if isinstance(model, IdentifiedModel) else model
    ref = _reference(model) or robot
    recorded = None if own is None else own.info.column_map  # the record the data are read by
    units = None if opt.columns is None else opt.columns[1]
    found = recorded_sign_map_findings(rec, ref, recorded, units)
    for text in found.values():
        warnings.warn(text, DynidWarning, stacklevel=caller_level())
    opposite = warn_signs(rec, ref, skip=tuple(found), reference=_model_friction(model, rec.drive))
    return "; ".join(found.values()) or None, opposite


def _model_friction(
    model: IdentifiedModel | Robot, drive: Drive | None
) -> NDArray[np.float64] | None:
    """An identified model's own ``fv, fc, Ia`` (n, 3) per motor (joint) where ``drive``
    puts the friction, the reference a recording's own friction and rotor are compared
    with (:func:`~dynid.identification.recorded_signs.opposite_friction_among`): its one friction
    term's viscous and Coulomb coefficients, its rotor inertias (zeros without them);
    None for a robot, a model of several friction terms, or friction placed elsewhere."""
    if not isinstance(model, IdentifiedModel) or len(model.frictions) != 1:
        return None
    fr = model.frictions[0]
    at_joints = drive is None or np.allclose(drive.friction_transmission, np.eye(drive.n))
    coulomb = {"classical": 1, "smooth": 1, "stribeck": 1, "quadratic": 2}.get(fr.law)
    n = model.robot.n
    if coulomb is None or (fr.drive is None) != at_joints or fr.params.shape[0] != n:
        return None
    ia = model.rotor_inertia
    ia = np.zeros(n) if ia is None or np.shape(ia) != (n,) else np.asarray(ia)
    return np.column_stack([fr.params[:, 0], fr.params[:, coulomb], ia])


def _signs_first(
    verdict: Verdict, opposite: Sequence[SignFinding], sign_map: str | None
) -> Verdict:
    """``verdict`` with the sign findings (:func:`_said_signs`), the likelier causes, at
    the start of its reason: the recorded sign map's, then each recording's columns
    recorded reversed or torques of the opposite sign after its name."""
    for said in ("; ".join(f"{f.name}: {f.text}" for f in opposite) or None, sign_map):
        if said is not None:
            verdict = dataclasses.replace(verdict, reason=f"{said}; {verdict.reason}")
    return verdict


def _say_training_data(model: IdentifiedModel | Robot, names: Sequence[str]) -> None:
    """Warn when recordings of the names the model was identified from are validated on:
    their errors are training errors, not a judgement on data the fit did not see; and
    when the model's identification recorded its gravity torques one factor off the
    description's (:func:`~dynid.identification.gravity_scale.recorded_scale`): it predicts
    efforts read through the same drive, its torques at the joints carry the factor."""
    if not isinstance(model, IdentifiedModel):
        return
    if (scale := recorded_scale(model)) is not None:
        warnings.warn(
            f"the model records that its gravity torques are {scale[0]:.3g} times the robot "
            "description's (identify's warning: the drive file's torque_constant or "
            f"gear_ratio looks off by that factor; multiply it by {1 / scale[0]:.3g}): it "
            "predicts efforts read through the same drive, and its torques at the joints "
            "carry the factor (payload --model withholds setLoad values)",
            DynidWarning,
            stacklevel=caller_level(),
        )
    if same := model.info.fitted_on(names):
        warnings.warn(
            f"{', '.join(same)}: the model was identified from recording(s) of "
            f"{'this name' if len(same) == 1 else 'these names'}: the errors below are "
            "training errors, not a held-out judgement; hint: validate on a recording the "
            "fit did not see (identify's held-out verdict judges its own recordings)",
            DynidWarning,
            stacklevel=caller_level(),
        )
    if odd := model.info.left_out_of(names):
        warnings.warn(
            f"{', '.join(odd)}: left out of the model's fit as outlying (its held-out error "
            "far above the other recordings', metadata.recordings[].left_out): the "
            "errors below are what it holds beyond the others (a payload, contacts?), not "
            "the model's error on data like its own",
            DynidWarning,
            stacklevel=caller_level(),
        )


def _reference(model: IdentifiedModel | Robot) -> Robot | None:
    """The robot a recording's torque sign is checked against: an identified model's
    equivalent links with its joint spring (a stiff one outweighs gravity on its joint),
    None for a robot (itself)."""
    if not isinstance(model, IdentifiedModel):
        return None
    return model.equivalent_robot.with_spring(model.spring)


def _friction(
    model: IdentifiedModel | Robot,
    friction: str | Path | FrictionModel,
    feasible: str | Path | None,
    drive: Drive | None,
) -> tuple[FrictionModel | FrictionSum | None, str | None]:
    """The friction added to the model (its own where ``drive`` puts it) and where it comes
    from."""
    if isinstance(friction, str) and friction == "none":
        return None, None
    if isinstance(friction, str) and friction == "own":
        own = own_friction(model, drive)
        if feasible is not None:
            own = load_feasible_linear_friction(feasible) or own
        elif isinstance(model, Robot) and (said := own_at_motors_note(model, drive)) is not None:
            _log.log(NOTE, said)
        return own, None if own is None else "model"
    if isinstance(friction, str | Path):  # where the drive puts a robot's own, as simulated
        return placed_friction(load_friction_json(friction), drive), Path(friction).name
    return placed_friction(friction, drive), "given"


def _banded(
    run: Callable[[FrictionModel | FrictionSum | None], RecordingsValidation],
    friction: FrictionModel | FrictionSum | None,
) -> RecordingsValidation:
    """The validation ``run`` gives with ``friction`` as the observer evaluates it on
    velocities of the noise the recordings are prepared to (``state_noise``): a sharp
    Coulomb step whose standstill band lies well inside that noise band, or a smooth step
    narrower than it, gets the noise band
    (:func:`~dynid.observer.friction.banded_if_narrow` of
    :func:`~dynid.observer.friction.noise_bands`), said in a note
    (:func:`~dynid.observer.friction.banding_note`); run again only then. Without it
    ``sign(dq)`` of the noise at every rest flips the whole Coulomb torque (a URDF's
    ``<dynamics friction>``, which holds no band). An identified law's band is that noise
    band already, and a smooth law (identification chose its width for the prediction
    in motion, which validation judges) stays as it is too."""
    val = run(friction)
    noise = val.pieces.state_noise
    if friction is None or noise is None:
        return val
    bands = noise_bands(friction, noise.dq)
    banded = banded_if_narrow(friction, bands, derived=noise.derived, smooth=False)
    if banded is friction:
        return val
    if said := banding_note(friction, [banded], verb="judged", read_as="model error"):
        _log.log(NOTE, said)
    return run(banded)


def _finite(
    val: RecordingsValidation, names: Any, label: str | None, opt: ValidateOptions
) -> TorqueErrors:
    """The pooled errors of ``val``, refused when they overflow (:func:`_overflow`)."""
    errors = val.errors
    if not np.isfinite(errors.relative_error_percent) or not np.all(np.isfinite(errors.rms)):
        raise DataError(_overflow(names, val, label, opt))
    return errors


def _overflow(names: Any, val: Any, label: str | None, opt: ValidateOptions) -> str:
    """Why the torque errors overflow: the largest of the logs' torques, the rigid-body
    model's and the friction's, named with its source."""
    with np.errstate(over="ignore", invalid="ignore"):
        peaks = {
            "log": max(float(np.max(np.abs(v.log.tau))) for v in val.parts),
            "model": max(float(np.max(np.abs(v.tau_model))) for v in val.parts),
            "friction": max(
                0.0 if v.tau_friction is None else float(np.max(np.abs(v.tau_friction)))
                for v in val.parts
            ),
        }
    worst = max(peaks, key=lambda k: peaks[k] if np.isfinite(peaks[k]) else np.inf)
    model = label or "the model"
    given = isinstance(opt.friction, str | Path) and opt.friction not in ("own", "none")
    source = Path(str(opt.friction)).name if given else model
    where = {
        "log": "the log holds values far outside a robot's range",
        "model": f"the model's torques are far outside a robot's range; check {model}'s parameters",
        "friction": "the friction torques are far outside a robot's range; check the "
        f"coefficients of {source}",
    }[worst]
    return (
        f"{', '.join(names)}: the torque errors overflow (relative error "
        f"{val.errors.relative_error_percent}); {where} (largest |tau| [N m]: log "
        f"{peaks['log']:.3g}, rigid-body model {peaks['model']:.3g}, "
        f"friction {peaks['friction']:.3g})"
    )
