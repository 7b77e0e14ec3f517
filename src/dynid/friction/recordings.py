"""Several recordings for validation and the friction fit: each recording, and each piece
of one cut at a gap, prepared on its own and never joined to another.

As identification does (:mod:`dynid.identification.recordings`,
:func:`~dynid.identification.pieces.recording_pieces`): a time column in ms is refused,
every log is cut at each gap longer than ``max_gap_s`` (by default the rule the model was
identified with), the joints (motors, on a motor-side log) that can wrap and were recorded
wrapped into ``[-pi, pi]`` are unwrapped piece by piece, whatever the drive, each piece is
read at the joints (through the model's drive) and filtered and differentiated on its own
(:func:`~dynid.identification.prepare.prepare_log`) at one cut-off, its ends trimmed by the
rule identification applies (:func:`~dynid.identification.trim.edge_seconds`: half a period
of the cut-off when the motion lies a decade below it), and decimated as the model was
identified: a model is judged on the samples identification prepared from the same
recording.
Unlike identification, the measured torques stay unfiltered (the RMS of a correct model
is the sensor noise). A piece too short to filter is left out
with a warning naming its file and times; a recording left without any piece, or of
another joint count, is an error naming the file: no recording is dropped silently.

* :func:`prepare_pieces`: the :class:`Pieces` of a model's recordings;
* :func:`validate_pieces`: the model's errors pooled over every sample of every piece, and
  per recording (:class:`RecordingsValidation`);
* :func:`pieces_residual`: the model's torque residual of every piece, with each sample's
  recording, for the friction fit and its held-out selection
  (:func:`~dynid.friction.select.select_friction` leaves one recording out at a time).
"""

from __future__ import annotations

import dataclasses
import warnings
from collections.abc import Mapping, Sequence
from dataclasses import dataclass
from typing import Any, Literal

import numpy as np
from numpy.typing import NDArray

from .. import _checks
from .._checks import caller_level
from ..exceptions import DataError, DynidWarning, OptionError
from ..identification.cut_loss import left_out_finding
from ..identification.input_noise import StateNoise, state_noise
from ..identification.log import DEFAULT_CUTOFF_HZ, TorqueLog, joint_side_log
from ..identification.metrics import TorqueErrors
from ..identification.model import IdentifiedModel
from ..identification.pieces import (
    check_below_nyquist,
    gaps_between,
    nyquist_cutoff,
    recording_line,
    recording_pieces,
    skipped_piece,
    timing_record,
    wrappable,
)
from ..identification.prepare import Preprocessing, at_measured_samples, prepare_log, resamples
from ..identification.recordings import standstill_band
from ..identification.trim import common_cutoff, edge_seconds
from ..identification.velocity_noise import NOISE_BAND_STD
from ..model.drive import Drive
from ..model.robot import Robot
from .fit import FrictionResidual, TorqueModel, model_drive, torques_through
from .model import FrictionModel, FrictionSum, friction_words
from .pooled import pooled_errors
from .validation import (
    RECORDED,
    Validation,
    holds_cutoff,
    recorded_cutoff,
    validated,
    validated_log,
)

__all__ = [
    "Pieces",
    "RecordingErrors",
    "RecordingsValidation",
    "pieces_residual",
    "prepare_pieces",
    "validate_pieces",
    "validate_recordings",
]


@dataclass(frozen=True, slots=True, eq=False)
class Pieces:
    """Prepared pieces of one or more recordings (module docstring).

    Attributes
    ----------
    logs : tuple of TorqueLog
        Every piece at the joints, filtered, with ``ddq``, trimmed; recording after
        recording, in time order.
    recording : tuple of int
        The recording (index into ``names``) of each piece.
    names : tuple of str
        One name per recording (its file name).
    cutoff_hz : float or None
        The one low-pass cut-off of every piece [Hz].
    dq_noise_std : ndarray, shape (n,)
        White-noise std of the prepared (low-passed) joint velocities [rad/s], read as
        identification reads it from the raw pieces: its standstill band
        (:func:`~dynid.identification.recordings.standstill_band`) over
        :data:`~dynid.identification.velocity_noise.NOISE_BAND_STD`, so that the friction laws
        switch Coulomb friction off within the band identification gave the model's (the
        raw velocities' noise band, 25 times wider on a UR5 log at 5 Hz of 500 Hz, left
        the classical law 0.75 N m RMS where the model's reached 0.43 N m).
    skipped : tuple of str
        One line per piece left out (too short to filter), naming its file.
    unwrapped : tuple of int
        Joints (0-based) unwrapped in some recording.
    drive : Drive or None
        The drive the recordings were read through.
    samples, durations : tuple, optional
        Prepared samples and duration [s] of each piece, when ``logs`` keep only every
        k-th sample of long pieces (:func:`validate_recordings`); default: the logs' own.
    state_noise : StateNoise or None
        The white noise of the prepared velocities and accelerations, read from the raw
        pieces (:func:`~dynid.identification.input_noise.state_noise`); None: not known.
    timing : tuple of dict, optional
        Per recording, its gaps and its stamps' jitter as ``identify`` records them
        (:func:`~dynid.identification.pieces.timing_record`); empty: not known.
    """

    logs: tuple[TorqueLog, ...]
    recording: tuple[int, ...]
    names: tuple[str, ...]
    cutoff_hz: float | None
    dq_noise_std: NDArray[np.float64]
    skipped: tuple[str, ...] = ()
    unwrapped: tuple[int, ...] = ()
    drive: Drive | None = None
    samples: tuple[int, ...] | None = None
    durations: tuple[float, ...] | None = None
    state_noise: StateNoise | None = None
    timing: tuple[Mapping[str, Any], ...] = ()

    def __post_init__(self) -> None:
        if self.samples is None:  # the logs hold every prepared sample
            object.__setattr__(self, "samples", tuple(p.n_samples for p in self.logs))
            object.__setattr__(self, "durations", tuple(p.duration for p in self.logs))

    @property
    def n_samples(self) -> int:
        """Samples over every piece."""
        assert self.samples is not None
        return sum(self.samples)

    def labels(self) -> NDArray[np.intp]:
        """The recording of every sample (N,), pieces in order."""
        return np.concatenate(
            [
                np.full(p.n_samples, r, np.intp)
                for p, r in zip(self.logs, self.recording, strict=True)
            ]
        )

    def summary(self) -> tuple[dict[str, Any], ...]:
        """Per recording: ``file``, ``pieces``, ``samples`` and ``duration_s`` used, and
        the ``gaps`` it was cut at (with ``start_s``) and its stamps' jitter
        (``stamp_jitter_s``, ``period_s``) when there are (:attr:`timing`)."""
        out = []
        assert self.samples is not None and self.durations is not None
        for r, name in enumerate(self.names):
            mine = [i for i, k in enumerate(self.recording) if k == r]
            out.append(
                {
                    "file": name,
                    "pieces": len(mine),
                    "samples": sum(self.samples[i] for i in mine),
                    "duration_s": float(sum(self.durations[i] for i in mine)),
                    **(self.timing[r] if r < len(self.timing) else {}),
                }
            )
        return tuple(out)

    def describe(self) -> str:
        """``"a.csv: 2 pieces, 3000 samples, cut at the gap(s) after t = ... (7 s into
        a.csv; 0.3 s long); stamps jittered, std 0.04 ms at a 1 ms period"``, a line per
        recording (:func:`~dynid.identification.pieces.recording_line`, as ``identify``
        says the gaps and the jitter)."""
        return "\n".join(recording_line(s) for s in self.summary())


def prepare_pieces(
    model: TorqueModel,
    logs: Sequence[TorqueLog],
    names: Sequence[str] | None = None,
    *,
    cutoff_hz: float | None | Literal["recorded"] = RECORDED,
    trim_s: float | None = None,
    max_gap_s: float | None | Literal["recorded"] = RECORDED,
    filter_tau: bool = False,
    drive: Drive | None = None,
    decimate: int | Literal["recorded"] = RECORDED,
    measured_samples: bool = False,
    torque_delay_s: float | None = None,
) -> Pieces:
    """Read every recording at the joints, unwrap, cut at its gaps and prepare each piece.

    Parameters
    ----------
    model : TorqueModel
        The model the recordings are compared with (its drive and recorded cut-off).
    logs : sequence of TorqueLog
        The recordings, as read (motor side or currents when the drive says so).
    names : sequence of str, optional
        One name per recording (default ``log1, log2, ...``), for messages.
    cutoff_hz : float, None or "recorded"
        One low-pass cut-off for every piece [Hz]; ``"recorded"`` (default): the one the
        model was identified with, else the one identification reads from the pieces'
        motion (:func:`~dynid.friction.validation.recorded_cutoff`); None: no filter.
    trim_s, filter_tau
        As :func:`~dynid.identification.prepare.prepare_log`.
    max_gap_s : float, None or "recorded"
        Gaps up to this long [s] are bridged; longer ones cut a recording into pieces.
        ``"recorded"`` (default) and None: the rule the model was identified with
        (``info.log.max_gap_s``), else the default
        (:func:`~dynid.identification.log.default_max_gap`).
    decimate : int or "recorded"
        Every ``decimate``-th sample of each prepared piece is compared; ``"recorded"``
        (default): the model's identification's decimation (1 for another model), so that
        the model is judged on the samples it was identified on.
    drive : Drive, optional
        The drive the logs were recorded through, for a model without one
        (:func:`~dynid.friction.fit.model_drive`).
    measured_samples : bool
        With ``decimate=1`` and the torques as measured: a piece the preparation resamples
        (jittered or dropped stamps) is read back at its own samples, the torques as
        measured (:func:`~dynid.identification.prepare.at_measured_samples`), as
        validation judges it; else the grid (whose linear interpolation averages a
        sample's noise with its neighbour's: an xArm7 at 100 Hz, stamps +-2 ms, fitted
        0.277 N m RMS on a joint whose sensor noise is 0.3 N m).
    torque_delay_s : float, optional
        How far the torques lag the positions [s]
        (:attr:`~dynid.identification.prepare.Preprocessing.torque_delay_s`); None
        (default): the delay the model was identified with (0 for another model).

    Returns
    -------
    Pieces

    Raises
    ------
    DataError
        No recording; a recording of another joint count than the model's, or with no
        piece long enough to filter (the file is named); another drive than the model's.
    """
    prep = _recorded_preparation(model, max_gap_s, decimate, filter_tau, torque_delay_s)
    raw = _raw_pieces(model, logs, names, cutoff_hz, prep.max_gap_s, drive, trim_s)
    prep = dataclasses.replace(prep, cutoff_hz=raw.cutoff_hz, trim_s=raw.trim_s)
    own = measured_samples and not prep.filter_tau and prep.decimate == 1
    prepared, recording, skipped, left = [], [], [], []
    for k, (r, piece) in enumerate(raw.pieces):
        try:
            p = prepare_log(piece, prep)
        except DataError as exc:
            skipped.append(skipped_piece(raw.names[r], piece, exc))
            left.append((k, str(exc)))
            continue
        if own and resamples(piece, prep):  # its own samples, not a grid between them
            p = next(at_measured_samples([p], piece), p)
        prepared.append(p)
        recording.append(r)
    _say_left_out(raw, left, prep.max_gap_s)
    return _kept(raw, prepared, recording, skipped)


@dataclass(frozen=True, slots=True, eq=False)
class _Raw:
    """The pieces of the recordings before preparation, and what holds for all of them."""

    pieces: list[tuple[int, TorqueLog]]
    names: tuple[str, ...]
    cutoff_hz: float | None
    trim_s: float | None
    unwrapped: tuple[int, ...]
    drive: Drive | None
    timing: tuple[dict[str, Any], ...] = ()


def _raw_pieces(
    model: TorqueModel,
    logs: Sequence[TorqueLog],
    names: Sequence[str] | None,
    cutoff_hz: float | None | Literal["recorded"],
    max_gap_s: float | None,
    drive: Drive | None,
    trim_s: float | None = None,
) -> _Raw:
    """Every recording at the joints, unwrapped, cut at its gaps; the one cut-off (lowered
    to a quarter of the rate where it is not below half of it, with a note:
    :func:`~dynid.identification.pieces.nyquist_cutoff`) and the seconds trimmed at each
    piece's ends (``trim_s``, else identification's rule,
    :func:`~dynid.identification.trim.edge_seconds`)."""
    if not logs:
        raise DataError("no recording given")
    names = tuple(names) if names is not None else tuple(f"log{k + 1}" for k in range(len(logs)))
    d = model_drive(model, drive)
    robot = _robot(model)
    raw: list[tuple[int, TorqueLog]] = []
    turned: set[int] = set()
    timing = []
    for r, (name, log) in enumerate(zip(names, logs, strict=True)):
        if robot is not None and log.n != robot.n:
            raise DataError(
                f"the log has {log.n} joints; robot {robot.name!r} has {robot.n}; "
                "hint: a recording of the robot the model describes",
                file=name,
            )
        # unwrapped where recorded (motor angles on a motor-side log), as identification
        turns = wrappable(robot, d) if robot is not None else np.zeros(log.n, bool)
        mine, joints = recording_pieces(name, log, turns, max_gap_s, robot=robot, drive=d)
        turned.update(joints)
        timing.append(timing_record(gaps_between(mine), float(log.t[0]), log.cleaning))
        raw += [(r, joint_side_log(p, d)) for p in mine]
    jpieces, labels = [p for _, p in raw], [r for r, _ in raw]
    # joint-side pieces of a motor-side log differ by turns of the motors, not joints
    jturns = None if robot is None or (d is not None and d.side == "motor") else wrappable(robot)
    read = isinstance(cutoff_hz, str) and not holds_cutoff(model, jpieces)
    cut = common_cutoff(jpieces, labels, jturns) if read else None
    from_motion = cut is not None
    if cut is None:
        cut = recorded_cutoff(model, jpieces, labels) if isinstance(cutoff_hz, str) else cutoff_hz
    check_below_nyquist(jpieces, None if isinstance(cutoff_hz, str) else cut)  # as given
    given = not isinstance(cutoff_hz, str)
    if given or cut != DEFAULT_CUTOFF_HZ:  # the default: moved by the preparation, warned
        cut = nyquist_cutoff(jpieces, cut, "--cutoff" if given else "the model's cut-off")
    if trim_s is None:
        trim_s = edge_seconds(jpieces, labels, cut, from_motion=from_motion, turns=jturns)
    return _Raw(raw, names, cut, trim_s, tuple(sorted(turned)), d, tuple(timing))


def _say_left_out(raw: _Raw, left: list[tuple[int, str]], max_gap_s: float | None) -> None:
    """One warning for every piece left out (:func:`left_out_finding`)."""
    if (
        finding := left_out_finding(raw.names, raw.pieces, left, raw.trim_s, max_gap_s)
    ) is not None:
        warnings.warn(finding, DynidWarning, stacklevel=caller_level())


def _kept(
    raw: _Raw,
    logs: list[TorqueLog],
    recording: list[int],
    skipped: list[str],
    **counts: tuple[Any, ...],
) -> Pieces:
    """The :class:`Pieces` of the pieces kept (every recording holding one: checked)."""
    _check_kept(raw, recording)
    return Pieces(
        logs=tuple(logs),
        recording=tuple(recording),
        names=raw.names,
        cutoff_hz=raw.cutoff_hz,
        dq_noise_std=_prepared_noise_std([p for _, p in raw.pieces], raw.cutoff_hz),
        skipped=tuple(skipped),
        unwrapped=raw.unwrapped,
        drive=raw.drive,
        state_noise=state_noise([p for _, p in raw.pieces], raw.cutoff_hz),
        timing=raw.timing,
        **counts,
    )


def _check_kept(raw: _Raw, recording: list[int]) -> None:
    """Refuse a recording left without any piece long enough to filter (named)."""
    lost = [raw.names[r] for r in range(len(raw.names)) if r not in recording]
    if lost:
        raise DataError(  # the file named once (a caller's in_file adds no second name)
            f"no piece long enough to filter at {raw.cutoff_hz or 0:.4g} Hz (gaps longer "
            "than --max-gap cut a recording into pieces); hint: record longer stretches "
            "without gaps, or raise --max-gap",
            file=", ".join(lost),
        )


def validate_recordings(
    model: TorqueModel,
    logs: Sequence[TorqueLog],
    names: Sequence[str] | None = None,
    *,
    friction: FrictionModel | FrictionSum | None = None,
    cutoff_hz: float | None | Literal["recorded"] = RECORDED,
    trim_s: float | None = None,
    max_gap_s: float | None | Literal["recorded"] = RECORDED,
    filter_tau: bool = False,
    drive: Drive | None = None,
    torque_delay_s: float | None = None,
) -> RecordingsValidation:
    """:func:`validate_pieces` of :func:`prepare_pieces`, each piece prepared and predicted
    a block at a time when it is long (:func:`~dynid.friction.validation.validated_log`):
    the errors over every sample, the prepared logs and predictions of a long piece kept
    at every k-th sample only (``Validation.step``), so that a long recording is never
    held prepared whole. Parameters and errors as the two."""
    # every sample judged
    prep = _recorded_preparation(model, max_gap_s, 1, filter_tau, torque_delay_s)
    raw = _raw_pieces(model, logs, names, cutoff_hz, prep.max_gap_s, drive, trim_s)
    prep = dataclasses.replace(prep, cutoff_hz=raw.cutoff_hz, trim_s=raw.trim_s)
    parts, recording, skipped, left = [], [], [], []
    for k, (r, piece) in enumerate(raw.pieces):
        try:
            v = validated_log(model, piece, friction, raw.drive, prep)
        except DataError as exc:
            skipped.append(skipped_piece(raw.names[r], piece, exc))
            left.append((k, str(exc)))
            continue
        parts.append(v)
        recording.append(r)
    _say_left_out(raw, left, prep.max_gap_s)
    pieces = _kept(
        raw,
        [v.log for v in parts],
        recording,
        skipped,
        samples=tuple(v.errors.n_samples for v in parts),
        durations=tuple(v.log.duration for v in parts),
    )
    return _pooled(tuple(parts), pieces, friction)


def _recorded_preparation(
    model: TorqueModel,
    max_gap_s: float | None | Literal["recorded"],
    decimate: int | Literal["recorded"],
    filter_tau: bool,
    torque_delay_s: float | None = None,
) -> Preprocessing:
    """The gap rule, the decimation and the torques' delay: as given, or as the model was
    identified with (:attr:`~dynid.identification.info.LogInfo.preprocessing`; the
    library defaults for another model), with the torques filtered as ``filter_tau``
    says; the cut-off and the trim are the recordings' (:func:`_raw_pieces`).

    Raises
    ------
    OptionError
        ``decimate`` below 1.
    """
    log = model.info.log if isinstance(model, IdentifiedModel) else None
    own = Preprocessing() if log is None else log.preprocessing
    if max_gap_s is None or isinstance(max_gap_s, str):
        max_gap_s = own.max_gap_s
    if isinstance(decimate, str):
        decimate = own.decimate
    if int(decimate) < 1:
        raise OptionError(f"decimate must be at least 1; got {decimate}")
    delay = own.torque_delay_s if torque_delay_s is None else float(torque_delay_s)
    return Preprocessing(
        max_gap_s=max_gap_s, decimate=int(decimate), filter_tau=filter_tau, torque_delay_s=delay
    )


def _robot(model: TorqueModel) -> Robot | None:
    if isinstance(model, IdentifiedModel):
        return model.robot
    return model if isinstance(model, Robot) else None


def _prepared_noise_std(pieces: list[TorqueLog], cutoff_hz: float | None) -> NDArray[np.float64]:
    """The white-noise std [rad/s] (n,) of the prepared joint velocities: identification's
    standstill band of the raw pieces at ``cutoff_hz``
    (:func:`~dynid.identification.recordings.standstill_band`) over
    :data:`~dynid.identification.velocity_noise.NOISE_BAND_STD`; zeros when no piece has 8
    samples."""
    if not any(p.n_samples >= 8 for p in pieces):
        return _checks.frozen(np.zeros(pieces[0].n))
    return _checks.frozen(standstill_band(pieces, cutoff_hz) / NOISE_BAND_STD)


@dataclass(frozen=True, slots=True, eq=False)
class RecordingErrors:
    """One recording's errors over its pieces.

    Attributes
    ----------
    file : str
    pieces : int
    without_friction : TorqueErrors
    with_friction : TorqueErrors or None
    """

    file: str
    pieces: int
    without_friction: TorqueErrors
    with_friction: TorqueErrors | None

    @property
    def errors(self) -> TorqueErrors:
        """Of the full prediction (with friction when given)."""
        return self.with_friction if self.with_friction is not None else self.without_friction

    def as_dict(self) -> dict[str, object]:
        """``file``, ``pieces``, the full prediction's errors and ``without_friction``."""
        out: dict[str, object] = {"file": self.file, "pieces": self.pieces}
        out.update(self.errors.as_dict())
        out["without_friction"] = self.without_friction.as_dict()
        return out


@dataclass(frozen=True, slots=True, eq=False)
class RecordingsValidation:
    """A model against several recordings: the errors over every sample of every piece
    (RMS over all samples, relative error over all), and per recording.

    Attributes
    ----------
    parts : tuple of Validation
        One per piece (``pieces.logs``).
    pieces : Pieces
    without_friction, with_friction : TorqueErrors (with_friction None without friction)
        Pooled over every sample.
    recordings : tuple of RecordingErrors
        One per recording.
    friction : FrictionModel or None
    """

    parts: tuple[Validation, ...]
    pieces: Pieces
    without_friction: TorqueErrors
    with_friction: TorqueErrors | None
    recordings: tuple[RecordingErrors, ...]
    friction: FrictionModel | FrictionSum | None

    @property
    def errors(self) -> TorqueErrors:
        """Pooled errors of the full prediction (with friction when given)."""
        return self.with_friction if self.with_friction is not None else self.without_friction

    @property
    def added(self) -> str:
        """What ``friction`` adds, in words (:func:`~dynid.friction.model.friction_words`:
        offsets are not friction)."""
        return friction_words(self.friction)

    @property
    def shown(self) -> Validation:
        """The longest piece of the first recording, with the pooled errors: its torques
        are drawn, the errors are every sample's."""
        first = [v for v, r in zip(self.parts, self.pieces.recording, strict=True) if r == 0]
        longest = max(first, key=lambda v: v.log.n_samples)
        return dataclasses.replace(
            longest, without_friction=self.without_friction, with_friction=self.with_friction
        )

    @property
    def shown_start(self) -> float:
        """The first prepared time stamp of the shown recording [s] (its log's start and
        the filter's trim): where :attr:`shown`'s figure draws time from, so that its
        piece sits at its place in the recording."""
        pairs = zip(self.parts, self.pieces.recording, strict=True)
        return min(float(v.log.t[0]) for v, r in pairs if r == 0)

    def as_dict(self) -> dict[str, object]:
        """JSON-ready: the pooled errors as :meth:`Validation.as_dict`, then
        ``recordings`` (one entry per file: pieces, errors, and the gaps it was cut at and
        its stamps' jitter, :attr:`Pieces.timing`), ``skipped`` and ``unwrapped_joints``
        (1-based)."""
        out: dict[str, object] = dict(self.errors.as_dict())
        out["friction_model"] = None if self.friction is None else self.friction.kind
        out["friction_terms"] = self.added
        out["without_friction"] = self.without_friction.as_dict()
        if self.with_friction is not None:
            out["with_friction"] = self.with_friction.as_dict()
        timing = self.pieces.timing
        out["recordings"] = [
            {**r.as_dict(), **(timing[k] if k < len(timing) else {})}
            for k, r in enumerate(self.recordings)
        ]
        out["skipped"] = list(self.pieces.skipped)
        out["unwrapped_joints"] = [j + 1 for j in self.pieces.unwrapped]
        return out


def validate_pieces(
    model: TorqueModel, pieces: Pieces, *, friction: FrictionModel | FrictionSum | None = None
) -> RecordingsValidation:
    """The model's torques (without and with ``friction``) against every piece.

    Pooled: ``RMS_j = sqrt(sum_pieces sum_k e_kj^2 / N)`` over all ``N`` samples, the
    relative error ``100 ||E||_F / ||tau||_F`` over all samples; the same per recording.

    Raises
    ------
    ShapeError
        The friction model's joint count differs from the logs'.
    """
    parts = tuple(validated(model, p, friction, pieces.drive) for p in pieces.logs)
    return _pooled(parts, pieces, friction)


def _pooled(
    parts: tuple[Validation, ...], pieces: Pieces, friction: FrictionModel | FrictionSum | None
) -> RecordingsValidation:
    """The errors of the pieces' validations pooled over all and per recording."""
    labels = np.asarray(pieces.recording)

    def pooled(sel: NDArray[np.bool_], with_friction: bool) -> TorqueErrors:
        chosen = [p for p, s in zip(parts, sel, strict=True) if s]
        return pooled_errors(chosen, with_friction, parts[0].log.n)

    fr = friction is not None
    every = np.ones(len(parts), bool)
    recs = tuple(
        RecordingErrors(
            name,
            int(np.sum(labels == r)),
            pooled(labels == r, False),
            pooled(labels == r, True) if fr else None,
        )
        for r, name in enumerate(pieces.names)
    )
    return RecordingsValidation(
        parts=parts,
        pieces=pieces,
        without_friction=pooled(every, False),
        with_friction=pooled(every, True) if fr else None,
        recordings=recs,
        friction=friction,
    )


def thinned(pieces: Pieces, k: int) -> Pieces:
    """``pieces`` with every ``k``-th sample of each piece kept: measured samples, not
    averaged, so their noise is the sensors' (a fit of friction laws on every sample of
    a 30 s, 1 kHz log took 18.7 s against 7.4 s on every tenth, identify's decimation)."""
    if k <= 1:
        return pieces
    logs = tuple(g.select(slice(None, None, k)) for g in pieces.logs)
    return dataclasses.replace(pieces, logs=logs, samples=None, durations=None)


def pieces_residual(model: TorqueModel, pieces: Pieces) -> FrictionResidual:
    """The torque residual of ``model`` on every piece, the pieces one after another.

    The model's torques are those validation compares (:func:`validate_pieces`): a robot's
    links plus the known rotor torques of the drive the pieces were read through
    (:func:`~dynid.friction.fit.torques_through`).

    The returned log holds the pieces' samples in order, their times laid end to end (each
    piece shifted to start one median step after the previous one ends: a time axis for
    figures, not a recording; one piece keeps its times); ``recording`` holds each
    sample's recording, so that the held-out selection leaves one recording out at a time.
    """
    if len(pieces.logs) == 1:  # one piece: its own times
        p = pieces.logs[0]
        assert p.ddq is not None  # prepare_log always fills ddq
        tau_m = torques_through(model, pieces.drive, p.q, p.dq, p.ddq)
        return FrictionResidual(p, tau_m, p.tau - tau_m, pieces.dq_noise_std)
    cols: dict[str, list[NDArray[np.float64]]] = {k: [] for k in ("t", "q", "dq", "tau", "ddq")}
    taus = []
    start = 0.0
    for p in pieces.logs:
        assert p.ddq is not None  # prepare_log always fills ddq
        step = float(np.median(np.diff(p.t)))
        cols["t"].append(p.t - p.t[0] + start)
        start = float(cols["t"][-1][-1]) + step
        for k in ("q", "dq", "tau", "ddq"):
            cols[k].append(getattr(p, k))
        taus.append(torques_through(model, pieces.drive, p.q, p.dq, p.ddq))
    t, q, dq, tau, ddq = (np.concatenate(cols[k]) for k in ("t", "q", "dq", "tau", "ddq"))
    log = TorqueLog(t, q, dq, tau, ddq)
    tau_m = np.concatenate(taus)
    return FrictionResidual(
        log=log,
        tau_model=tau_m,
        residual=log.tau - tau_m,
        dq_noise_std=pieces.dq_noise_std,
        recording=_checks.frozen(pieces.labels()),
    )
