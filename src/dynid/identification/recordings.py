"""Several recordings as one data set: each recording, and each piece of one cut at a gap,
prepared on its own and never joined to another.

A robot is rarely recorded in one take: a data set is several logs, and a log has gaps
(dropped samples, cut-out stretches). Joining them before filtering makes the zero-phase
filter and the derivatives run across the joins, where positions jump: the accelerations
there are artefacts, and the cut-off read from the motion sees the joins as fast motion.
Here:

1. every log is cut at each gap longer than ``max_gap_s`` (default
   :func:`~dynid.identification.log.default_max_gap`: one or two lost samples are
   bridged, longer gaps cut) into **pieces**;
2. continuous revolute joints recorded wrapped into ``[-pi, pi]`` are unwrapped first
   (:func:`unwrapped`, a warning names them);
3. one cut-off serves every piece: the median of the pieces'
   :func:`~dynid.identification.rate.cutoff_from_motion`, each weighted by its samples
   (or the one given);
4. each piece is read through the drive, filtered, differentiated and decimated on its own
   (:func:`~dynid.identification.classical.prepare_torque_log`); a piece too short for
   the filter is left out with a warning naming its file and times, never silently;
5. the pieces' regressor rows are stacked (:class:`Recordings`, a
   :class:`~dynid.identification.core.Dataset`); held-out judgement leaves one recording
   out at a time when there are several (:meth:`Recordings.fold_labels`), contiguous time
   blocks otherwise.
"""

from __future__ import annotations

import dataclasses
import warnings
from collections.abc import Iterator, Mapping, Sequence
from dataclasses import dataclass
from typing import Any, Literal

import numpy as np
from numpy.typing import NDArray

from ..exceptions import DataError, DynidWarning, ShapeError
from ..model.drive import Drive
from ..model.robot import Robot
from .classical import PreparedLog, log_blocks, prepare_torque_log, still_columns
from .core import ModelColumns, RegressorBlock
from .holdout import DEFAULT_FOLDS, block_labels
from .info import IdentificationInfo, LogInfo
from .log import TorqueLog, default_max_gap, joint_side_log
from .rate import CUTOFF_MULTIPLE, cutoff_from_motion
from .sanity import noise_band, spike_finding, velocity_noise_std
from .streaming import streams

__all__ = [
    "Recordings",
    "common_cutoff",
    "prepare_recordings",
    "skipped_piece",
    "split_at_gaps",
    "unwrapped",
]


def split_at_gaps(log: TorqueLog, max_gap_s: float | None = None) -> list[TorqueLog]:
    """The pieces of ``log`` between its gaps longer than ``max_gap_s`` [s] (default
    :func:`~dynid.identification.log.default_max_gap` of the median step)."""
    dt = np.diff(log.t)
    limit = default_max_gap(float(np.median(dt))) if max_gap_s is None else float(max_gap_s)
    cuts = np.concatenate([[0], np.flatnonzero(dt > limit) + 1, [log.n_samples]])
    if cuts.size == 2:  # no gap: the log itself, not a copy
        return [log]
    return [log.select(slice(a, b)) for a, b in zip(cuts[:-1], cuts[1:], strict=True)]


def unwrapped(log: TorqueLog, revolute: NDArray[np.bool_]) -> tuple[TorqueLog, tuple[int, ...]]:
    """The log with revolute joints recorded wrapped into ``[-pi, pi]`` unwrapped.

    A joint is wrapped when its position jumps by nearly a whole turn more than its
    recorded velocity explains (``dq dt``, the mean of the two samples'; the raw step for
    velocities derived from the positions) while the rest of the jump is as small as its
    other unexplained steps: a fast motor turning more than half a turn between two samples
    is motion, not a wrap. Returns the log with those turns taken out and the joints
    unwrapped (0-based; the log itself when none).
    """
    h = np.diff(log.t)
    found: dict[int, NDArray[np.float64]] = {}
    for j in np.flatnonzero(np.asarray(revolute, dtype=bool)).tolist():  # a joint at a time
        d = np.diff(log.q[:, j])
        if not log.dq_derived:
            d -= 0.5 * (log.dq[:-1, j] + log.dq[1:, j]) * h
        turns = np.round(d / (2 * np.pi))
        moved = turns != 0
        if not moved.any():
            continue
        typical = float(np.max(np.abs(d[~moved]), initial=0.0))
        rest = np.abs(d[moved] - 2 * np.pi * turns[moved])
        if np.all(rest <= max(2 * typical, 1e-9)):
            found[j] = turns
    if not found:
        return log, ()
    q = np.array(log.q)
    for j, turns in found.items():
        q[1:, j] -= 2 * np.pi * np.cumsum(turns)
    out = TorqueLog(log.t, q, log.dq, log.tau, log.ddq, log.cleaning, log.dq_derived)
    return out, tuple(sorted(found))


@dataclass(frozen=True, slots=True, eq=False)
class Recordings:
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
        (:func:`~dynid.identification.sanity.noise_band`).
    skipped : tuple of str
        One line per piece left out (too short to filter).
    unwrapped : tuple of int
        Joints (0-based) unwrapped in some recording.
    bands : dict
        With a drive: the standstill band at its motors (``"motor"``) and at the joints
        (``"joint"``), for a friction placed where the drive does not say
        (:attr:`~dynid.identification.structure.Structure.at`); empty without one.
    """

    pieces: tuple[PreparedLog, ...]
    recording: tuple[int, ...]
    names: tuple[str, ...]
    band: NDArray[np.float64]
    skipped: tuple[str, ...] = ()
    unwrapped: tuple[int, ...] = ()
    bands: Mapping[str, NDArray[np.float64]] = dataclasses.field(default_factory=dict)

    @property
    def route(self) -> Literal["classical"]:
        """``"classical"`` (Gaz et al. 2019, Sec. IV-B)."""
        return "classical"

    @property
    def regressor_kind(self) -> Literal["torque"]:
        """Joint torques."""
        return "torque"

    @property
    def moving(self) -> bool:
        """True: friction acts."""
        return True

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

    def blocks(self, robot: Robot, columns: ModelColumns) -> Iterator[RegressorBlock]:
        """The pieces' rows stacked in one block (sample-major within each piece), or the
        pieces' blocks one after another when they are too many to stack."""
        n = self.n
        if streams(self.n_samples * n, len(columns.labels)):
            for p in self.pieces:
                yield from log_blocks(robot, p.log, columns, stream=True, cutoff_hz=p.cutoff_hz)
            return
        parts = [
            b for p in self.pieces for b in log_blocks(robot, p.log, columns, cutoff_hz=p.cutoff_hz)
        ]
        if len(parts) == 1:
            yield parts[0]
            return
        yield RegressorBlock(
            W=np.concatenate([b.W for b in parts]),
            y=np.concatenate([b.y for b in parts]),
            groups=np.concatenate([b.groups for b in parts]),
        )

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

    def summary(self) -> tuple[dict[str, Any], ...]:
        """Per recording: ``file``, ``pieces``, ``samples`` used and ``duration_s`` used."""
        out = []
        for r, name in enumerate(self.names):
            mine = [p for p, k in zip(self.pieces, self.recording, strict=True) if k == r]
            out.append(
                {
                    "file": name,
                    "pieces": len(mine),
                    "samples": sum(p.log.n_samples for p in mine),
                    "duration_s": float(sum(p.log.duration for p in mine)),
                }
            )
        return tuple(out)

    def record(self, n_rows: int) -> IdentificationInfo:
        """Filtering, decimation and sample counts over every piece, and each recording."""
        ps = self.pieces
        first = ps[0]
        log = LogInfo(
            cutoff_hz=first.cutoff_hz,
            trim_s=first.trim_s,
            decimate=max(p.decimate for p in ps),
            sample_rate_hz=first.sample_rate_hz,
            n_samples_log=sum(p.n_samples_log for p in ps),
            n_samples_used=self.n_samples,
            duration_s=float(sum(p.duration_s for p in ps)),
            n_nan_rows=sum(p.cleaning.n_nan_rows for p in ps),
            n_duplicates=sum(p.cleaning.n_duplicates for p in ps),
            n_gaps=sum(len(p.cleaning.gaps) for p in ps),
            cutoff_source="given" if first.motion_frequency_hz is None else "motion",
            motion_frequency_hz=first.motion_frequency_hz,
            resampled=any(p.resampled for p in ps),
        )
        notes = tuple(self.skipped)
        if self.unwrapped:
            notes += (
                "joint(s) "
                + ", ".join(str(j + 1) for j in self.unwrapped)
                + " recorded wrapped into [-pi, pi]: unwrapped",
            )
        return IdentificationInfo(
            reference="Gaz et al. 2019, Sec. IV-B, eq. 24 (classical friction)",
            log=log,
            recordings=self.summary(),
            notes=notes,
        )


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
) -> Recordings:
    """Cut, unwrap, filter, differentiate and decimate every recording (module docstring).

    Parameters
    ----------
    robot : Robot
    logs : sequence of TorqueLog
        The recordings, as read (motor side or currents when ``drive`` says so).
    names : sequence of str, optional
        One name per recording (default ``log1, log2, ...``), for messages and the record.
    cutoff_hz, trim_s, decimate, drive
        As :func:`~dynid.identification.classical.prepare_torque_log`; one cut-off for all.
    max_gap_s : float, optional
        Gaps up to this long [s] are bridged; longer ones cut the log into pieces.

    Raises
    ------
    DataError
        No recording, or no piece long enough to filter (the files are named).
    ShapeError
        A recording with another number of joints than the robot (named).
    """
    if not logs:
        raise DataError("no recording given")
    names = tuple(names) if names is not None else tuple(f"log{k + 1}" for k in range(len(logs)))
    if len(names) != len(logs):
        raise ShapeError(f"{len(names)} names for {len(logs)} recordings")
    revolute = ~np.asarray(robot.prismatic, dtype=bool)
    pieces: list[tuple[int, TorqueLog]] = []
    turned: set[int] = set()
    for r, (name, log) in enumerate(zip(names, logs, strict=True)):
        if log.n != robot.n:
            raise ShapeError(f"{name}: log has {log.n} joints; robot {robot.name!r} has {robot.n}")
        # a motor-side log: every motor turns (a joint-side one: the robot's revolute joints)
        turns = revolute if drive is None or drive.side == "joint" else np.ones(robot.n, bool)
        log, joints = unwrapped(log, turns)
        if (spikes := spike_finding(name, log, robot.joint_names)) is not None:
            warnings.warn(spikes, DynidWarning, stacklevel=2)
        if joints:
            turned.update(joints)
            warnings.warn(
                f"{name}: joint(s) {', '.join(str(j + 1) for j in joints)} recorded wrapped "
                "into [-pi, pi] (jumps of a whole turn): unwrapped",
                DynidWarning,
                stacklevel=2,
            )
        pieces += [(r, p) for p in split_at_gaps(log, max_gap_s)]
    cutoff: float | None = None if cutoff_hz == "auto" else cutoff_hz
    if cutoff_hz == "auto":
        cutoff = common_cutoff([joint_side_log(p, drive) for _, p in pieces])
        if cutoff is None:
            raise DataError("no piece is long enough to read the motion's frequency from")
    prepared, recording, skipped = [], [], []
    for r, piece in pieces:
        try:
            p = prepare_torque_log(
                robot,
                piece,
                cutoff_hz=cutoff,
                trim_s=trim_s,
                max_gap_s=max_gap_s,
                decimate=decimate,
                drive=drive,
            )
        except DataError as exc:
            skipped.append(skipped_piece(names[r], piece, exc))
            continue
        prepared.append(p)
        recording.append(r)
    if not prepared:
        raise DataError(
            f"no piece of {', '.join(names)} is long enough to filter at {cutoff} Hz; "
            "hint: record longer stretches without gaps, or raise --max-gap"
        )
    used = sorted(set(recording))
    if len(used) < len(names):
        lost = [names[r] for r in range(len(names)) if r not in used]
        raise DataError(f"{', '.join(lost)}: no piece long enough to filter at {cutoff} Hz")
    if cutoff_hz == "auto" and cutoff is not None:  # read from the motion: recorded so
        f_q = cutoff / CUTOFF_MULTIPLE
        prepared = [dataclasses.replace(p, motion_frequency_hz=f_q) for p in prepared]
    return Recordings(
        pieces=tuple(prepared),
        recording=tuple(recording),
        names=names,
        band=_band([piece for _, piece in pieces], drive),
        skipped=tuple(skipped),
        unwrapped=tuple(sorted(turned)),
        bands=_bands([piece for _, piece in pieces], drive),
    )


def common_cutoff(pieces: Sequence[TorqueLog]) -> float | None:
    """The cut-off [Hz] read from the motion of the pieces long enough to read it
    (:func:`~dynid.identification.rate.cutoff_from_motion`): their median, each piece
    weighted by its samples (a short piece reads its edges as fast motion); None when no
    piece is long enough."""
    found, weight = [], []
    for piece in pieces:
        if piece.n_samples < 64:
            continue
        try:
            found.append(cutoff_from_motion(piece.q, piece.dq, piece.sample_rate))
        except DataError:
            if len(pieces) == 1:
                raise
            continue
        weight.append(piece.n_samples)
    if not found:
        return None
    order = np.argsort(found)
    cum = np.cumsum(np.asarray(weight, dtype=np.float64)[order])
    return float(np.asarray(found)[order][np.searchsorted(cum, 0.5 * cum[-1])])


def skipped_piece(name: str, piece: TorqueLog, exc: Exception, stacklevel: int = 3) -> str:
    """Warn that a piece of recording ``name`` is left out (too short to filter, the
    reason ``exc``); returns the line, for the record."""
    line = (
        f"{name}: piece {piece.t[0]:.6g}-{piece.t[-1]:.6g} s ({piece.n_samples} samples) "
        f"left out: {exc}"
    )
    warnings.warn(line, DynidWarning, stacklevel=stacklevel)
    return line


def _bands(pieces: list[TorqueLog], drive: Drive | None) -> dict[str, NDArray[np.float64]]:
    """The standstill bands at a drive's motors and at the joints (none without a drive)."""
    if drive is None:
        return {}
    places: tuple[Literal["motor", "joint"], ...] = ("motor", "joint")
    return {at: _band(pieces, dataclasses.replace(drive, friction_at=at)) for at in places}


def _band(pieces: list[TorqueLog], drive: Drive | None) -> NDArray[np.float64]:
    """The standstill band [rad/s] from the raw velocities of every piece (at the motors
    where the drive's friction acts there)."""
    if len(pieces) == 1:  # one piece: its velocities as they are, not a copy
        dq = joint_side_log(pieces[0], drive).dq
    else:
        dq = np.concatenate([joint_side_log(p, drive).dq for p in pieces])
    if drive is not None:
        dq = dq @ drive.friction_transmission.T
    if dq.shape[0] < 8:
        return np.zeros(dq.shape[1])
    return np.asarray(noise_band(velocity_noise_std(dq)), dtype=np.float64)
