"""Several recordings as one data set: each recording, and each piece of one cut at a gap,
prepared on its own and never joined to another.

A robot is rarely recorded in one take: a data set is several logs, and a log has gaps
(dropped samples, cut-out stretches). Joining them before filtering makes the zero-phase
filter and the derivatives run across the joins, where positions jump: the accelerations
there are artefacts, and the cut-off read from the motion sees the joins as fast motion.
Here:

1. every log's time column is checked against its recorded velocities (a time column in
   ms, us or ns is refused with the remedy,
   :func:`~dynid.identification.angle_time_units.time_unit_finding`), then cut at each gap longer
   than ``max_gap_s`` (default :func:`~dynid.identification.log.default_max_gap`: one or
   two lost samples are bridged, longer gaps cut) into **pieces**;
2. in each piece, the joints that can wrap (a continuous joint, a motor of a motor-side
   log: :func:`~dynid.identification.pieces.wrappable`) and were recorded wrapped into
   ``[-pi, pi]`` are unwrapped (:func:`~dynid.identification.pieces.unwrapped`, a warning
   names them; a jump across a cut-out stretch is no wrap);
3. one cut-off serves every piece (or the one given): the median of the recordings'
   :func:`~dynid.identification.rate.cutoff_from_motion`, each weighted by its samples,
   each read from its pieces on its own time axis
   (:func:`~dynid.identification.trim.common_cutoff`);
4. each piece is read through the drive, filtered, differentiated and decimated on its own
   (:func:`~dynid.identification.prepared_log.prepare_torque_log`), the filter's edges
   trimmed at both of its ends (:func:`~dynid.identification.trim.edge_seconds`, half a
   period of the cut-off; the rule validation and the friction fit apply too); a piece
   too short for the filter is left out with a warning naming its file and times, never
   silently; each recording's samples not used are counted by cause (:class:`SampleCounts`);
5. the pieces' regressor rows are stacked (:class:`Recordings`, a
   :class:`~dynid.identification.core.Dataset`); held-out judgement leaves one recording
   out at a time when there are several (:meth:`Recordings.fold_labels`), contiguous time
   blocks otherwise.
"""

from __future__ import annotations

import contextlib
import dataclasses
import warnings
from collections.abc import Iterator, Mapping, Sequence
from dataclasses import dataclass
from typing import Any, Literal

import numpy as np
from numpy.typing import ArrayLike, NDArray

from .._checks import caller_level
from ..exceptions import DataError, DynidWarning, OptionError, ShapeError
from ..model.drive import Drive
from ..model.robot import Robot
from ..progress import report
from ..signals import lowpass_noise_gain
from .core import ModelColumns, RegressorBlock
from .cut_loss import left_out_finding
from .dataset import TorqueRoute
from .derived_band import derived_velocity_band
from .holdout import DEFAULT_FOLDS, block_labels
from .info import IdentificationInfo, LogInfo
from .log import DEFAULT_CUTOFF_HZ, TorqueLog, joint_side_log, log_digest
from .log_rows import log_blocks, still_columns
from .once_per_run import once_per_run
from .pieces import (
    WRAP_SPAN,
    check_below_nyquist,
    check_samples_and_time,
    gaps_between,
    joined,
    nyquist_cutoff,
    recording_pieces,
    skipped_piece,
    split_at_gaps,
    tell_wrapped,
    timing_record,
    unwrapped,
    wrappable,
    wrapped_finding,
)
from .prepare import (
    Preprocessing,
    at_instants,
    dropped_places,
    grid_samples,
    measured_instants,
)
from .prepared_log import PreparedLog, prepare_torque_log
from .rate import CUTOFF_MULTIPLE
from .recorded_signs import recording_sign_findings
from .reversed_among import reversed_among
from .sanity import check_torque_log
from .serial import Serial, serial_of_pieces
from .spikes import despiked, spike_finding
from .streaming import streams
from .training_range import motion_ranges
from .trim import common_cutoff, edge_seconds, within_edges
from .velocity_noise import noise_band, pieces_noise_std

# read back within shared_run: a run prepares the same recordings again
# (identify_with_offsets with the cut-off the fit read; the spring trial)
_spike_finding = once_per_run(spike_finding)
_sign_findings = once_per_run(recording_sign_findings)
_reversed_among = once_per_run(reversed_among)
_check_torque_log = once_per_run(check_torque_log)
_prepare_torque_log = once_per_run(prepare_torque_log)

__all__ = [
    "WRAP_SPAN",
    "Recordings",
    "SampleCounts",
    "common_cutoff",
    "prepare_recordings",
    "recording_pieces",
    "skipped_piece",
    "split_at_gaps",
    "standstill_band",
    "unwrapped",
    "wrappable",
]


@dataclass(frozen=True, slots=True)
class SampleCounts:
    """Where one recording's samples went.

    Attributes
    ----------
    recorded : int
        Samples as read.
    isolated : int
        Samples alone between two gaps longer than the longest gap bridged (no piece).
    too_short : int
        Samples of pieces too short to filter, left out.
    trimmed : int
        Samples within the filter's edge transient at the pieces' ends, trimmed
        (:func:`~dynid.signals.edge_seconds`).
    decimated : int
        Samples between the decimated samples kept (on the uniform grid of a resampled
        piece).
    added : int
        Points the uniform grid of a resampled piece holds beyond its samples within the
        trimmed edges (negative: it holds fewer): the places of dropped samples
        (``dropped``) and the grid's ends against jittered stamps (the rest).
    dropped : int
        Of ``added``, the places of dropped samples: steps between stamps of at least
        1.5 periods (:func:`~dynid.identification.prepare.dropped_places`).
    used : int
        Samples used: ``recorded`` less the others, plus ``added``.
    """

    recorded: int
    isolated: int = 0
    too_short: int = 0
    trimmed: int = 0
    decimated: int = 0
    added: int = 0
    dropped: int = 0

    @property
    def used(self) -> int:
        """Samples used."""
        lost = self.isolated + self.too_short + self.trimmed + self.decimated
        return self.recorded - lost + self.added

    def as_dict(self) -> dict[str, int]:
        """``recorded``, ``isolated``, ``too_short``, ``trimmed``, ``decimated``,
        ``added``, ``dropped``."""
        return {
            "recorded": self.recorded,
            "isolated": self.isolated,
            "too_short": self.too_short,
            "trimmed": self.trimmed,
            "decimated": self.decimated,
            "added": self.added,
            "dropped": self.dropped,
        }


@dataclass(frozen=True, slots=True, eq=False)
class Recordings(TorqueRoute):
    """Prepared pieces of one or more recordings: a
    :class:`~dynid.identification.core.Dataset` of the classical route (module docstring).

    Attributes
    ----------
    pieces : tuple of PreparedLog
        Every piece, recording after recording, in time order.
    recording : tuple of int
        The recording (index into ``names``) of each piece.
    names : tuple of str
        One name per recording (its file name).
    band : ndarray, shape (n,)
        Standstill band [rad/s] per joint (motor, where the drive's friction acts there):
        the velocity noise band of the raw logs
        (:func:`~dynid.identification.velocity_noise.noise_band`; of velocities exact to
        round-off, their rounding: :func:`~dynid.identification.velocity_noise.
        pieces_noise_std`); for velocities derived from the
        positions, the noise they carry divided by ``band_gain``
        (:mod:`~dynid.identification.derived_band`).
    skipped : tuple of str
        One line per piece left out (too short to filter).
    unwrapped : tuple of int
        Joints (0-based) unwrapped in some recording.
    bands : dict
        With a drive: the standstill band at its motors (``"motor"``) and at the joints
        (``"joint"``), for a friction placed where the drive does not say
        (:attr:`~dynid.identification.structure.Structure.at`); empty without one.
    max_gap_s : float or None
        The longest gap bridged, as given [s] (None: the default rule,
        :func:`~dynid.identification.log.default_max_gap` of each recording's step).
    cuts : tuple of int
        Per recording, the gaps longer than ``max_gap_s`` it was cut at.
    torque_delay_s : float
        How far the torques were taken to lag the positions [s] (each piece's read that
        much later before filtering).
    gaps : tuple of tuple of (float, float)
        Per recording, each gap it was cut at: the last time stamp before it [s, the
        recording's own time] and its length [s] (empty: not recorded).
    starts : tuple of float
        Per recording, its first time stamp as read [s] (empty: not recorded): where the
        gaps lie in the recording.
    n_recorded : int
        Samples of every recording as read (pieces left out included); 0: the pieces'.
    band_gain : float
        The velocity noise left by the low-pass, per unit of the raw noise
        (:func:`~dynid.signals.lowpass_noise_gain` at the cut-off; 1 without one): a
        Coulomb sign is switched off within ``band_gain * band`` of the velocities as
        prepared, the noise they still hold; a smooth Coulomb's width counts in
        ``band_gain * band`` too.
    counts : tuple of SampleCounts
        Per recording, where its samples went (empty: not counted).
    digests : tuple of str
        Per recording, the SHA-256 of its samples as read
        (:func:`~dynid.identification.log.log_digest`; empty: not taken).
    """

    pieces: tuple[PreparedLog, ...]
    recording: tuple[int, ...]
    names: tuple[str, ...]
    band: NDArray[np.float64]
    skipped: tuple[str, ...] = ()
    unwrapped: tuple[int, ...] = ()
    bands: Mapping[str, NDArray[np.float64]] = dataclasses.field(default_factory=dict)
    max_gap_s: float | None = None
    torque_delay_s: float = 0.0
    cuts: tuple[int, ...] = ()
    gaps: tuple[tuple[tuple[float, float], ...], ...] = ()
    starts: tuple[float, ...] = ()
    n_recorded: int = 0
    band_gain: float = 1.0
    counts: tuple[SampleCounts, ...] = ()
    digests: tuple[str, ...] = ()

    @property
    def n(self) -> int:
        """Joints."""
        return self.pieces[0].n

    @property
    def drive(self) -> Drive | None:
        """The drive the logs were read through."""
        return self.pieces[0].drive

    @property
    def n_samples(self) -> int:
        """Samples used, over every piece."""
        return sum(p.log.n_samples for p in self.pieces)

    @property
    def n_rows(self) -> int:
        """Rows of :meth:`blocks` (and of :meth:`measured_blocks`): samples times joints."""
        return self.n_samples * self.n

    @property
    def cutoff_hz(self) -> float | None:
        """The one cut-off of every piece [Hz]."""
        return self.pieces[0].cutoff_hz

    @property
    def still(self) -> NDArray[np.bool_]:
        """Joints (motors) that stand still in every piece: their friction is not fitted."""
        return np.logical_and.reduce([p.still for p in self.pieces])

    @property
    def source(self) -> str:
        """``"2 torque logs (3 pieces) of N samples"``."""
        k, m = len(self.names), len(self.pieces)
        what = "torque log" if k == 1 else f"{k} torque logs"
        return (
            f"{what} ({m} pieces) of {self.n_samples} samples"
            if m > 1
            else (f"{what} of {self.n_samples} samples")
        )

    @property
    def hint(self) -> str:
        """What to do when the data do not excite every column."""
        return self.pieces[0].hint

    def check_robot(self, robot: Robot) -> None:
        """Raise :class:`ShapeError` unless the logs have ``robot.n`` joints."""
        self.pieces[0].check_robot(robot)

    def frozen_columns(self, columns: ModelColumns) -> NDArray[np.bool_]:
        """The friction columns of the joints (motors) that never move in any piece."""
        return still_columns(columns, self.still)

    @property
    def serial(self) -> Serial:
        """The pieces of :meth:`blocks` in order, samples of ``n`` rows, the longest of
        their HAC windows: a window never spans two pieces."""
        p = self.pieces
        return serial_of_pieces([x.log.n_samples for x in p], self.n, [x.lag for x in p])

    @property
    def measured(self) -> bool:
        """Whether every piece holds its torques as measured beside the low-passed ones
        (``tau_raw``: the pieces were filtered); :meth:`measured_blocks` predicts them."""
        return all(p.tau_raw is not None for p in self.pieces)

    def blocks(self, robot: Robot, columns: ModelColumns) -> Iterator[RegressorBlock]:
        """The pieces' rows stacked in one block (sample-major within each piece), or the
        pieces' blocks one after another when they are too many to stack."""
        n = self.n
        if streams(self.n_samples * n, len(columns.labels)):
            for p in self.pieces:
                yield from log_blocks(robot, p.log, columns, stream=True, **p.filtering)
            return
        parts = [b for p in self.pieces for b in log_blocks(robot, p.log, columns, **p.filtering)]
        if len(parts) == 1:
            yield parts[0]
            return
        yield RegressorBlock(
            W=np.concatenate([b.W for b in parts]),
            y=np.concatenate([b.y for b in parts]),
            groups=np.concatenate([b.groups for b in parts]),
        )

    def measured_blocks(self, robot: Robot, columns: ModelColumns) -> Iterator[RegressorBlock]:
        """The rows of :meth:`blocks` in the same order, in blocks, with the torques as
        measured and the columns that step at a reversal (Coulomb, smooth, Stribeck) as the
        model applies them, not through the torques' low-pass: what a held-out recording
        is judged on (a piece whose torques were not filtered: its own rows). The one
        computation of these rows: the held-out judgement of stacked rows and of rows in
        blocks both pass over them (:mod:`dynid.identification.selection`)."""
        for p in self.pieces:
            log = p.log if p.tau_raw is None else dataclasses.replace(p.log, tau=p.tau_raw)
            if p.stamps is not None and p.tau_raw is not None:  # at the measured instants
                log = at_instants(log, measured_instants(log.t, p.stamps))
            yield from log_blocks(robot, log, columns, stream=True, cutoff_hz=None)

    def fold_labels(self, folds: int = DEFAULT_FOLDS) -> tuple[NDArray[np.intp], str]:
        """The held-out fold of every row (rows of :meth:`blocks`, in order) and how they
        were made: one recording left out at a time when there are several, else
        ``folds`` contiguous time blocks.

        Raises
        ------
        OptionError
            One recording too short for ``folds`` blocks.
        """
        n = self.n
        if len(self.names) > 1:
            labels = np.concatenate(
                [
                    np.full(p.log.n_samples * n, r, np.intp)
                    for p, r in zip(self.pieces, self.recording, strict=True)
                ]
            )
            return labels, f"leave one recording out ({len(self.names)} recordings)"
        labels = np.repeat(block_labels(self.n_samples, folds), n)
        return labels, f"{folds} contiguous time blocks"

    def part_labels(
        self, folds: int = DEFAULT_FOLDS
    ) -> tuple[NDArray[np.intp], tuple[int, ...]] | None:
        """Of fewer recordings than ``folds`` (two or more), each recording's rows cut into
        ``ceil(folds / recordings)`` contiguous time blocks (over its pieces in order, as
        :func:`~.holdout.block_labels` cuts; one block for a recording too short): the
        block of every row (rows of :meth:`blocks`) and the recording (fold of
        :meth:`fold_labels`) each block belongs to. The fold still leaves its whole
        recording out of the fit; its held-out error is scored per block, so that the
        standard error of two candidates' difference, paired over the blocks
        (:func:`~.candidates.paired_se`), has more than the one degree of freedom two
        recordings give. None for one recording, or ``folds`` recordings or more."""
        k_rec = len(self.names)
        if k_rec < 2 or k_rec >= folds:
            return None
        per = -(-folds // k_rec)
        counts = np.zeros(k_rec, np.int64)
        for p, r in zip(self.pieces, self.recording, strict=True):
            counts[r] += p.log.n_samples
        cuts = [_blocks_or_one(int(c), per) for c in counts]
        first = np.concatenate([[0], np.cumsum([int(c.max()) + 1 for c in cuts])])
        done = np.zeros(k_rec, np.int64)
        out = []
        for p, r in zip(self.pieces, self.recording, strict=True):
            m = p.log.n_samples
            out.append(np.repeat(first[r] + cuts[r][done[r] : done[r] + m], self.n))
            done[r] += m
        fold = tuple(r for r, c in enumerate(cuts) for _ in range(int(c.max()) + 1))
        return np.concatenate(out).astype(np.intp), fold

    def summary(self) -> tuple[dict[str, Any], ...]:
        """Per recording: ``file``, ``pieces``, ``samples`` used and ``duration_s`` used,
        ``decimate`` (every k-th sample kept: at its own rate, 10 times the cut-off or
        more), ``sample_rate_hz`` (its rate as recorded [Hz]), the ``gaps`` it was cut at
        (``[t_before, length]`` [s] each, when any, with ``start_s``, the recording's
        first time stamp [s]), where the others went (:meth:`SampleCounts.as_dict`) when
        counted, and the ``sha256`` of its samples as read when taken (:attr:`digests`)."""
        out = []
        for r, name in enumerate(self.names):
            mine = [p for p, k in zip(self.pieces, self.recording, strict=True) if k == r]
            rec: dict[str, Any] = {
                "file": name,
                "pieces": len(mine),
                "samples": sum(p.log.n_samples for p in mine),
                "duration_s": float(sum(p.log.duration for p in mine)),
                "decimate": max(p.decimate for p in mine),
                "sample_rate_hz": float(mine[0].sample_rate_hz),
            }
            gaps = self.gaps[r] if r < len(self.gaps) else ()
            start = self.starts[r] if r < len(self.starts) else None
            rec.update(timing_record(gaps, start, mine[0].cleaning))
            if self.counts:
                rec.update(self.counts[r].as_dict())
            if r < len(self.digests):
                rec["sha256"] = self.digests[r]
            out.append(rec)
        return tuple(out)

    def record(self, n_rows: int) -> IdentificationInfo:
        """Filtering, decimation, the gap rule and sample counts over every piece; what
        cleaning found counted once per recording (every piece carries its recording's),
        gaps bridged apart from the gaps cut at; and each recording."""
        ps = self.pieces
        first = ps[0]
        found = {r: p.cleaning for p, r in zip(ps, self.recording, strict=True)}
        cuts = self.cuts or (0,) * len(self.names)
        log = LogInfo(
            cutoff_hz=first.cutoff_hz,
            trim_s=first.trim_s,
            decimate=max(p.decimate for p in ps),
            sample_rate_hz=first.sample_rate_hz,
            n_samples_log=self.n_recorded or sum(p.n_samples_log for p in ps),
            n_samples_used=self.n_samples,
            duration_s=float(sum(p.duration_s for p in ps)),
            n_nan_rows=sum(c.n_nan_rows for c in found.values()),
            n_duplicates=sum(c.n_duplicates for c in found.values()),
            n_gaps=sum(max(0, len(c.gaps) - cuts[r]) for r, c in found.items()),
            cutoff_source="given" if first.motion_frequency_hz is None else "motion",
            motion_frequency_hz=first.motion_frequency_hz,
            resampled=any(p.resampled for p in ps),
            n_cuts=sum(cuts),
            speed_max=tuple(
                float(x) for x in np.max([np.max(np.abs(p.log.dq), axis=0) for p in ps], axis=0)
            ),
            position_range=motion_ranges([p.log.q for p in ps]),
            velocity_range=motion_ranges([p.log.dq for p in ps]),
            max_gap_s=self.max_gap_s,
            torque_delay_s=self.torque_delay_s,
            n_dropped=sum(c.n_dropped for c in found.values()),
            stamp_jitter_s=max(c.stamp_jitter_s for c in found.values()),
        )
        notes = tuple(self.skipped)
        if self.unwrapped:
            motors = self.drive is not None and self.drive.side == "motor"
            notes += (
                ("motor(s) " if motors else "joint(s) ")
                + ", ".join(str(j + 1) for j in self.unwrapped)
                + " recorded wrapped (jumps of a whole turn): unwrapped",
            )
        return IdentificationInfo(
            reference="Gaz et al. 2019, Sec. IV-B, eq. 24 (classical friction)",
            log=log,
            recordings=self.summary(),
            notes=notes,
        )


def _at(cutoff_hz: float | None) -> str:
    """`` at 11.25 Hz`` (empty without a cut-off)."""
    return "" if cutoff_hz is None else f" at {cutoff_hz:.4g} Hz"


@contextlib.contextmanager
def _named_findings(name: str | None, r: int, said: set[tuple[int, str]]) -> Iterator[None]:
    """The findings a piece's preparation warns (a torque sign, degrees, a unit), once per
    recording and, of several recordings, named with the recording's file."""
    with warnings.catch_warnings(record=True) as caught:
        warnings.simplefilter("always")
        yield
    for w in caught:
        text = str(w.message)
        if (r, text) in said:
            continue
        said.add((r, text))
        shown = text if name is None or text.startswith(name) else f"{name}: {text}"
        warnings.warn_explicit(shown, w.category, w.filename, w.lineno)


def prepare_recordings(
    robot: Robot,
    logs: Sequence[TorqueLog],
    names: Sequence[str] | None = None,
    *,
    cutoff_hz: float | Literal["auto"] | None = "auto",
    trim_s: float | None = None,
    max_gap_s: float | None = None,
    decimate: int | None = None,
    drive: Drive | None = None,
    torque_delay_s: float = 0.0,
) -> Recordings:
    """Cut, unwrap, filter, differentiate and decimate every recording (module docstring).

    Parameters
    ----------
    robot : Robot
    logs : sequence of TorqueLog
        The recordings, as read (motor side or currents when ``drive`` says so).
    names : sequence of str, optional
        One name per recording (default ``log1, log2, ...``), for messages and the record.
    cutoff_hz, trim_s, decimate, drive, torque_delay_s
        As :func:`~dynid.identification.prepared_log.prepare_torque_log`; one cut-off for all.
    max_gap_s : float, optional
        Gaps up to this long [s] are bridged; longer ones cut the log into pieces.

    Raises
    ------
    DataError
        No recording, or no piece long enough to filter (the files are named); a
        recording with columns recorded reversed or torques of the opposite sign to the
        robot's or to the other recordings' (the first finding of
        :func:`~dynid.identification.recorded_signs.recording_sign_findings`, named).
    ShapeError
        A recording with another number of joints than the robot (named).
    """
    if not logs:
        raise DataError("no recording given")
    names = tuple(names) if names is not None else tuple(f"log{k + 1}" for k in range(len(logs)))
    if len(names) != len(logs):
        raise ShapeError(f"{len(names)} names for {len(logs)} recordings")
    _check_cutoff(names, logs, cutoff_hz)
    # a motor-side log: its motors turn (a joint-side one: its revolute joints)
    turns, motors = wrappable(robot, drive), drive is not None and drive.side == "motor"
    pieces: list[tuple[int, TorqueLog]] = []
    turned: set[int] = set()
    cuts: list[int] = []
    gaps: list[tuple[tuple[float, float], ...]] = []
    found: dict[str, list[str]] = {}  # each finding and the recordings it holds for
    wrapped: dict[tuple[str, tuple[int, ...]], list[str]] = {}  # each finding, its files
    for r, (name, log) in enumerate(zip(names, logs, strict=True)):
        if log.n != robot.n:
            raise ShapeError(
                f"log has {log.n} joints; robot {robot.name!r} has {robot.n}", file=name
            )
        if (spikes := _spike_finding(name, log, robot.joint_names)) is not None:
            warnings.warn(spikes, DynidWarning, stacklevel=caller_level())
            log = despiked(log)[0]  # before the filter spreads them
        mine, joints = recording_pieces(
            name, log, turns, max_gap_s, robot=robot, drive=drive, say_wrapped=False
        )
        turned.update(joints)
        if joints:  # the joints named with their limits (a motor-side log: the motors)
            said = wrapped_finding(joints, motors, robot=robot, log=log)
            wrapped.setdefault((said, tuple(joints)), []).append(name)
        cuts.append(max(0, len(mine) - 1))
        gaps.append(gaps_between(mine))
        pieces += [(r, p) for p in mine]
    have = [r for r in range(len(logs)) if any(k == r for k, _ in pieces)]
    wholes = [joined([p for k, p in pieces if k == r]) for r in have]
    # signs: a fit would bend to mirrored motion, negate the masses, or average a joint's
    # friction to nothing
    for bad in _sign_findings(robot, wholes, [names[r] for r in have], drive, first=True):
        raise DataError(bad.text, file=bad.name)
    if (other := _reversed_among(robot, wholes, [names[r] for r in have], drive)) is not None:
        raise DataError(other.text, file=other.name)  # a wrist's the description cannot tell
    for r, whole in zip(have, wholes, strict=True):  # units, frozen joints: said once
        for finding in _check_torque_log(robot, joint_side_log(whole, drive), drive):
            found.setdefault(finding, []).append(names[r])
    for (finding, js), which in wrapped.items():  # a note of joints turning without end
        tell_wrapped(finding, js, motors, robot, ", ".join(which))
    for finding, which in found.items():  # one warning a finding, its recordings named
        shown = finding if len(names) == 1 else f"{', '.join(which)}: {finding}"
        warnings.warn(shown, DynidWarning, stacklevel=caller_level())
    cutoff, edge = _cutoff_and_edge(pieces, drive, turns, cutoff_hz, trim_s)
    kw = dict(cutoff_hz=cutoff, trim_s=edge, max_gap_s=max_gap_s, decimate=decimate)
    kw["torque_delay_s"] = float(torque_delay_s)
    prepared, recording, skipped, gone = _prepared(robot, pieces, names, drive, **kw)
    if not prepared:
        raise DataError(
            f"no piece of {', '.join(names)} is long enough to filter{_at(cutoff)}; "
            "hint: record longer stretches without gaps, or raise --max-gap"
        )
    used = sorted(set(recording))
    if len(used) < len(names):
        lost = [names[r] for r in range(len(names)) if r not in used]
        raise DataError(f"no piece long enough to filter{_at(cutoff)}", file=", ".join(lost))
    if cutoff_hz == "auto" and cutoff is not None:  # read from the motion: recorded so
        f_q = cutoff / CUTOFF_MULTIPLE
        prepared = [dataclasses.replace(p, motion_frequency_hz=f_q) for p in prepared]
    derived = _derived([p for _, p in pieces], cutoff)
    gain = derived[2]
    return Recordings(
        pieces=tuple(prepared),
        recording=tuple(recording),
        names=names,
        band=_band([piece for _, piece in pieces], drive, derived),
        skipped=tuple(skipped),
        unwrapped=tuple(sorted(turned)),
        bands=_bands([piece for _, piece in pieces], drive, derived),
        band_gain=gain,
        max_gap_s=None if max_gap_s is None else float(max_gap_s),
        torque_delay_s=float(torque_delay_s),
        cuts=tuple(cuts),
        gaps=tuple(gaps),
        starts=tuple(float(log.t[0]) for log in logs),
        n_recorded=sum(log.n_samples for log in logs),
        counts=_counts(logs, pieces, gone),
        digests=tuple(log_digest(log) for log in logs),
    )


def _counts(
    logs: Sequence[TorqueLog],
    pieces: list[tuple[int, TorqueLog]],
    gone: dict[int, dict[str, int]],
) -> tuple[SampleCounts, ...]:
    """Per recording, its samples: recorded, isolated between gaps, and ``gone``'s."""
    return tuple(
        SampleCounts(
            recorded=log.n_samples,
            isolated=log.n_samples - sum(p.n_samples for k, p in pieces if k == r),
            **gone[r],
        )
        for r, log in enumerate(logs)
    )


def _check_cutoff(
    names: Sequence[str], logs: Sequence[TorqueLog], cutoff_hz: float | str | None
) -> None:
    """A cut-off given [Hz] refused at or above every recording's Nyquist rate
    (:func:`~.pieces.check_below_nyquist`) before the data's own checks (a log read
    reversed is no reason for it), once each time column reads in seconds and holds
    enough samples (:func:`~.pieces.check_samples_and_time`)."""
    if isinstance(cutoff_hz, int | float):
        for name, log in zip(names, logs, strict=True):
            check_samples_and_time(name, log)
        check_below_nyquist(list(logs), float(cutoff_hz))


def _cutoff_and_edge(
    pieces: list[tuple[int, TorqueLog]],
    drive: Drive | None,
    turns: Any,
    cutoff_hz: float | Literal["auto"] | None,
    trim_s: float | None,
) -> tuple[float | None, float | None]:
    """The cut-off [Hz] of every piece (read from the motion with ``"auto"``, else as
    given, lowered to a quarter of the rate where it is not below half of it:
    :func:`~.pieces.nyquist_cutoff`) and the seconds trimmed at the pieces' ends
    (``trim_s``, else the filter's edge transient)."""
    cutoff: float | None = None if cutoff_hz == "auto" else cutoff_hz
    # joint-side pieces of a motor-side log differ by turns of the motors, not joints
    jturns = None if drive is not None and drive.side == "motor" else turns
    logs = [joint_side_log(p, drive) for _, p in pieces]
    if cutoff_hz == "auto":
        cutoff = common_cutoff(logs, [r for r, _ in pieces], jturns)
        if cutoff is None:
            n = sum(log.n_samples for log in logs)
            span = max(float(log.t[-1] - log.t[0]) for log in logs)
            raise DataError(
                f"too short to identify ({n} samples, {span:.3g} s, the longest piece): no "
                "piece is long enough to read the motion's frequency from; hint: record "
                "several periods of the motion (seconds, not a fraction of one)"
            )
    else:
        check_below_nyquist(logs, cutoff)
        cutoff = nyquist_cutoff(logs, cutoff, "the cut-off")
    if trim_s is not None:
        return cutoff, trim_s
    edge = edge_seconds(
        logs, [r for r, _ in pieces], cutoff, from_motion=cutoff_hz == "auto", turns=jturns
    )
    return cutoff, edge


def _prepared(
    robot: Robot,
    pieces: list[tuple[int, TorqueLog]],
    names: tuple[str, ...],
    drive: Drive | None,
    **kw: Any,
) -> tuple[list[PreparedLog], list[int], list[str], dict[int, dict[str, int]]]:
    """Each piece prepared (:func:`~dynid.identification.prepared_log.prepare_torque_log`
    with ``kw``), the pieces too short to filter left out with one warning
    (:func:`~dynid.identification.cut_loss.left_out_finding`); per recording, the
    samples left out, trimmed and decimated away, and the grid points a resampled piece
    added (:class:`SampleCounts`)."""
    prepared, recording, skipped = [], [], []
    keys = ("too_short", "trimmed", "decimated", "added", "dropped")
    gone = {r: dict.fromkeys(keys, 0) for r in range(len(names))}
    said: set[tuple[int, str]] = set()
    left: list[tuple[int, str]] = []
    for k, (r, piece) in enumerate(pieces):
        several = f", piece {k + 1} of {len(pieces)}" if len(pieces) > 1 else ""
        report(f"preparing {names[r]}{several}")
        try:
            with _named_findings(names[r] if len(names) > 1 else None, r, said):
                p = _prepare_torque_log(robot, piece, drive=drive, check=False, **kw)
        except DataError as exc:
            skipped.append(skipped_piece(names[r], piece, exc))
            left.append((k, str(exc)))
            gone[r]["too_short"] += piece.n_samples
            continue
        prepared.append(p)
        recording.append(r)
        kept = within_edges(piece.t, kw["trim_s"] or 0.0)
        prep = Preprocessing(
            cutoff_hz=kw["cutoff_hz"],
            trim_s=kw["trim_s"],
            max_gap_s=kw["max_gap_s"],
            decimate=p.decimate,
            torque_delay_s=kw["torque_delay_s"],
        )
        grid = grid_samples(piece, prep)  # kept, on the uniform grid of a resampled piece
        gone[r]["trimmed"] += piece.n_samples - kept
        gone[r]["added"] += grid - kept
        gone[r]["dropped"] += dropped_places(piece, prep)
        gone[r]["decimated"] += grid - p.log.n_samples
    if (
        finding := left_out_finding(names, pieces, left, kw["trim_s"], kw["max_gap_s"])
    ) is not None:
        warnings.warn(finding, DynidWarning, stacklevel=caller_level())
    return prepared, recording, skipped, gone


def _bands(
    pieces: list[TorqueLog], drive: Drive | None, derived: tuple[float, bool, float]
) -> dict[str, NDArray[np.float64]]:
    """The standstill bands at a drive's motors and at the joints (none without a drive)."""
    if drive is None:
        return {}
    places: tuple[Literal["motor", "joint"], ...] = ("motor", "joint")
    return {at: _band(pieces, dataclasses.replace(drive, friction_at=at), derived) for at in places}


def _band(
    pieces: list[TorqueLog], drive: Drive | None, derived: tuple[float, bool, float]
) -> NDArray[np.float64]:
    """The standstill band [rad/s] from the raw velocities of every piece (at the motors
    where the drive's friction acts there), per unit of ``band_gain``: measured ones' noise
    band; for velocities derived from the positions, the positions' noise through the
    derivative filter (:mod:`~dynid.identification.derived_band`; ``derived`` is its
    cut-off, whether the preparation low-passes them again, and ``band_gain``), divided by
    ``band_gain`` (the noise the prepared velocities hold is this band times it). The
    larger of the two where both kinds of piece are given."""
    sides = [joint_side_log(p, drive) for p in pieces]
    K = None if drive is None else np.asarray(drive.friction_transmission)
    return _sides_band(sides, K, derived)


def _sides_band(
    sides: Sequence[TorqueLog],
    K: NDArray[np.float64] | None,
    derived: tuple[float, bool, float],
) -> NDArray[np.float64]:
    """:func:`_band` of pieces already at the joints, at the velocities ``dq K^T`` (``K``
    None: the joints')."""
    measured = [x for x in sides if not x.dq_derived]
    n = sides[0].dq.shape[1] if K is None else K.shape[0]
    out = np.zeros(n)
    if measured:
        dq = [x.dq if K is None else x.dq @ K.T for x in measured]
        if sum(v.shape[0] for v in dq) >= 8:  # the times of joined pieces step back
            std = pieces_noise_std([(x.t, v) for x, v in zip(measured, dq, strict=True)])
            out = np.asarray(noise_band(std), dtype=np.float64)
    cutoff, lowpassed, gain = derived
    of_q = [(x.t, x.q if K is None else x.q @ K.T) for x in sides if x.dq_derived]
    band = derived_velocity_band(of_q, cutoff, lowpassed=lowpassed) if of_q else None
    return out if band is None else np.maximum(out, band / gain)


def _derived(pieces: Sequence[TorqueLog], cutoff: float | None) -> tuple[float, bool, float]:
    """The cut-off of velocities derived from the positions, whether the preparation
    low-passes them again, and the low-pass noise gain at the pieces' median rate."""
    gain = lowpass_noise_gain(float(np.median([p.sample_rate for p in pieces])), cutoff)
    # velocities derived from positions: at this cut-off and low-passed again when filtering,
    # else as read (at the readers' default cut-off)
    return (DEFAULT_CUTOFF_HZ if cutoff is None else cutoff, cutoff is not None, gain)


def standstill_band(
    sides: Sequence[TorqueLog], cutoff_hz: float | None, transmission: ArrayLike | None = None
) -> NDArray[np.float64]:
    """The standstill band [rad/s] (n,) of velocities prepared at ``cutoff_hz``: the band
    identification gives its Coulomb terms,
    ``band_gain * band`` (:class:`Recordings`), read from the raw pieces ``sides``.

    Parameters
    ----------
    sides : sequence of TorqueLog
        The pieces at the joints, before filtering (measured velocities, or velocities
        derived from the positions, ``dq_derived``), each with N >= 1.
    cutoff_hz : float or None
        The low-pass cut-off of the preparation [Hz] (None: not filtered).
    transmission : array_like, shape (n, n), optional
        ``K``: the band of the velocities ``dq K^T`` (a drive's motors); default the
        joints'.

    Returns
    -------
    ndarray, shape (n,)
        ``lowpass_noise_gain`` at the pieces' median rate times the raw velocities' noise
        band (:func:`~dynid.identification.velocity_noise.noise_band`; for derived velocities the
        band of :mod:`~dynid.identification.derived_band`, divided by that gain): the
        noise band of the prepared velocities (a UR5 at 500 Hz, 0.002 rad/s of velocity
        noise, 5 Hz: 0.0004 rad/s, against 0.01 rad/s for the raw velocities).
    """
    derived = _derived(sides, cutoff_hz)
    K = None if transmission is None else np.asarray(transmission, dtype=np.float64)
    return np.asarray(derived[2] * _sides_band(sides, K, derived), dtype=np.float64)


def _blocks_or_one(n_samples: int, k: int) -> NDArray[np.intp]:
    """:func:`~.holdout.block_labels` of ``n_samples`` into ``k`` blocks, one block where
    they are too few."""
    try:
        return block_labels(n_samples, k)
    except OptionError:
        return np.zeros(n_samples, np.intp)
