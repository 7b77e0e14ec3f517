"""One recording cut at its gaps into pieces, checked and unwrapped piece by piece.

* :func:`split_at_gaps`: the pieces between the gaps longer than ``max_gap_s``;
* :func:`wrappable`: the recorded position columns that can hold a wrap into
  ``[-pi, pi]`` (joints whose limits span a turn; a motor-side log's motors);
* :func:`unwrapped`: the wraps of a piece taken out;
* :func:`recording_pieces`: all three for one recording, its time column checked first
  (:func:`~dynid.identification.sanity.time_unit_finding`);
* :func:`joined`: the pieces of one recording as one log for its checks;
* :func:`skipped_piece`: the line (and warning) of a piece left out.

Used by identification (:mod:`dynid.identification.recordings`), validation and the
friction fit (:mod:`dynid.friction.recordings`) and the payload.
"""

from __future__ import annotations

import warnings

import numpy as np
from numpy.typing import NDArray

from ..exceptions import DataError, DynidWarning, OptionError
from ..model.drive import Drive
from ..model.robot import Robot
from .log import TorqueLog, default_max_gap
from .sanity import time_unit_finding

__all__ = [
    "WRAP_SPAN",
    "joined",
    "recording_pieces",
    "skipped_piece",
    "split_at_gaps",
    "unwrapped",
    "wrappable",
]

#: Positions recorded wrapped span at most this many turns (one, and the noise or offset
#: a logger may add after wrapping).
WRAP_SPAN = 1.05


def split_at_gaps(
    log: TorqueLog, max_gap_s: float | None = None, name: str = "the log"
) -> list[TorqueLog]:
    """The pieces of ``log`` between its gaps longer than ``max_gap_s`` [s] (default
    :func:`~dynid.identification.log.default_max_gap` of the median step); a sample
    isolated between two gaps is no piece (:func:`recording_pieces` counts it).

    Raises
    ------
    OptionError
        ``max_gap_s`` below the median sample step of ``log`` (named ``name``): every
        sample would be a piece of its own.
    """
    dt = np.diff(log.t)
    step = float(np.median(dt)) if dt.size else 0.0
    if max_gap_s is not None and dt.size and float(max_gap_s) < step:
        raise OptionError(
            f"--max-gap {float(max_gap_s):g} s is below the sample step {step:g} s of {name}: "
            "every sample would be cut from the next; hint: --max-gap of at least the sample "
            "step (a gap is a step longer than it), or leave it out for 2.5 steps"
        )
    limit = default_max_gap(step) if max_gap_s is None else float(max_gap_s)
    cuts = np.concatenate([[0], np.flatnonzero(dt > limit) + 1, [log.n_samples]])
    if cuts.size == 2 and log.n_samples > 1:  # no gap: the log itself, not a copy
        return [log]
    return [
        log.select(np.arange(a, b)) for a, b in zip(cuts[:-1], cuts[1:], strict=True) if b - a > 1
    ]


def wrappable(robot: Robot, drive: Drive | None = None) -> NDArray[np.bool_]:
    """The recorded position columns that can hold a wrap into ``[-pi, pi]``.

    Without a drive, or with one whose log is joint side (an identity drive, the armature
    of ``rotor_inertia = "identify"`` included): the revolute joints whose limits span at
    least a whole turn (unbounded ones included); a joint whose limits span less cannot
    wrap. On a motor-side log: the motors whose angle spans at least a turn over the
    joints' limits (``|K| (q_max - q_min)``, ``K`` the transmission; any unbounded joint
    they drive included), prismatic joints' motors too (a ball screw turns).
    """
    span = np.asarray(robot.q_max, dtype=np.float64) - np.asarray(robot.q_min, dtype=np.float64)
    turn = 2 * np.pi * (1.0 - 1e-9)
    if drive is None or drive.side == "joint":
        return ~np.asarray(robot.prismatic, dtype=bool) & (span >= turn)
    K = np.abs(np.asarray(drive.transmission, dtype=np.float64))
    motor = np.array([float(np.sum(span[row > 0] * row[row > 0])) for row in K])
    return np.asarray(motor >= turn, dtype=bool)


def unwrapped(log: TorqueLog, revolute: NDArray[np.bool_]) -> tuple[TorqueLog, tuple[int, ...]]:
    """The log with the columns ``revolute`` (:func:`wrappable`) recorded wrapped into
    ``[-pi, pi]`` unwrapped; a log without gaps (a piece, :func:`split_at_gaps`).

    A column is wrapped when its positions stay within one turn (:data:`WRAP_SPAN`), jump
    somewhere by more than half a turn, and every such jump is nearly a whole turn more
    than its recorded velocity explains (``dq dt``, the mean of the two samples'; the raw step for
    velocities derived from the positions) while the rest of the jump is as small as its
    other unexplained steps: a fast motor turning more than half a turn between two samples
    is motion, not a wrap, and smooth positions whose velocities disagree with them (a
    time column in ms) are not wrapped. Returns the log with those turns taken out and the
    columns unwrapped (0-based; the log itself when none).
    """
    h = np.diff(log.t)
    found: dict[int, NDArray[np.float64]] = {}
    for j in np.flatnonzero(np.asarray(revolute, dtype=bool)).tolist():  # a column at a time
        q_j = log.q[:, j]
        if q_j.size < 2 or np.ptp(q_j) > 2 * np.pi * WRAP_SPAN:
            continue
        raw = np.diff(q_j)
        d = raw if log.dq_derived else raw - 0.5 * (log.dq[:-1, j] + log.dq[1:, j]) * h
        turns = np.round(d / (2 * np.pi))
        moved = turns != 0
        if not np.any(moved & (np.abs(raw) > np.pi)):
            continue
        typical = float(np.max(np.abs(d[~moved]), initial=0.0))
        if np.all(np.abs(d[moved] - 2 * np.pi * turns[moved]) <= max(2 * typical, 1e-9)):
            found[j] = turns
    if not found:
        return log, ()
    q = np.array(log.q)
    for j, turns in found.items():
        q[1:, j] -= 2 * np.pi * np.cumsum(turns)
    out = TorqueLog(log.t, q, log.dq, log.tau, log.ddq, log.cleaning, log.dq_derived)
    joints = tuple(sorted(found))
    return out, joints


def recording_pieces(
    name: str,
    log: TorqueLog,
    turns: NDArray[np.bool_],
    max_gap_s: float | None = None,
    *,
    stacklevel: int = 3,
) -> tuple[list[TorqueLog], tuple[int, ...]]:
    """One recording checked, cut at its gaps and unwrapped piece by piece.

    The time column is checked against the recorded velocities first
    (:func:`~dynid.identification.sanity.time_unit_finding`); the log is cut at its gaps
    longer than ``max_gap_s`` (:func:`split_at_gaps`) and each piece's columns ``turns``
    (:func:`wrappable`) are unwrapped on their own (:func:`unwrapped`): a jump across a
    cut-out stretch is no wrap and does not keep the other wraps in. A warning names the
    file and the joints unwrapped.

    Returns
    -------
    pieces : list of TorqueLog
    joints : tuple of int
        The columns (0-based) unwrapped in some piece.

    Raises
    ------
    DataError
        The time column looks like ms, us or ns (the file and the factor are named).
    OptionError
        ``max_gap_s`` below the sample step.
    """
    if (unit := time_unit_finding(name, log)) is not None:  # it names the file
        raise DataError(unit.removeprefix(f"{name}: "), file=name)
    pieces: list[TorqueLog] = []
    turned: set[int] = set()
    for piece in split_at_gaps(log, max_gap_s, name):
        piece, joints = unwrapped(piece, turns)
        turned.update(joints)
        pieces.append(piece)
    if (alone := log.n_samples - sum(p.n_samples for p in pieces)) > 0:
        warnings.warn(
            f"{name}: {alone} sample(s) isolated between gaps longer than the longest gap "
            "bridged left out",
            DynidWarning,
            stacklevel=stacklevel,
        )
    joints = tuple(sorted(turned))
    if joints:
        warnings.warn(
            f"{name}: joint(s) {', '.join(str(j + 1) for j in joints)} recorded wrapped "
            "into [-pi, pi] (jumps of a whole turn): unwrapped",
            DynidWarning,
            stacklevel=stacklevel,
        )
    return pieces, joints


#: The checks of a recording cut into pieces read at most about this many of its samples.
_CHECKED_SAMPLES = 200_000


def joined(pieces: list[TorqueLog]) -> TorqueLog:
    """The pieces of one recording as one log for its checks (statistics over its samples,
    every k-th sample of a long one; never prepared)."""
    if len(pieces) == 1:
        return pieces[0]
    k = max(1, sum(p.n_samples for p in pieces) // _CHECKED_SAMPLES)
    ps = [p if k == 1 else p.select(_every_kth(p.n_samples, k)) for p in pieces]
    return TorqueLog(
        np.concatenate([p.t for p in ps]),
        np.concatenate([p.q for p in ps]),
        np.concatenate([p.dq for p in ps]),
        np.concatenate([p.tau for p in ps]),
        None,
        ps[0].cleaning,
        ps[0].dq_derived,
    )


def _every_kth(n: int, k: int) -> NDArray[np.intp]:
    """Every ``k``-th of ``n >= 2`` rows, the last too when that leaves one."""
    rows = np.arange(0, n, k)
    return rows if rows.size > 1 else np.array([0, n - 1])


def skipped_piece(name: str, piece: TorqueLog, exc: Exception, stacklevel: int = 3) -> str:
    """Warn that a piece of recording ``name`` is left out (too short to filter, the
    reason ``exc``); returns the line, for the record."""
    line = (
        f"{name}: piece {piece.t[0]:.6g}-{piece.t[-1]:.6g} s ({piece.n_samples} samples) "
        f"left out: {exc}"
    )
    warnings.warn(line, DynidWarning, stacklevel=stacklevel)
    return line
