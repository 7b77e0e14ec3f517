"""One recording cut at its gaps into pieces, checked and unwrapped piece by piece.

* :func:`split_at_gaps`: the pieces between the gaps longer than ``max_gap_s``;
* :func:`wrappable`: the recorded position columns that can hold a wrap into
  ``[-pi, pi]`` (revolute joints; a motor-side log's motors that turn a whole turn);
  :func:`turn_limited`: the joints whose limits do not allow the whole turn a wrap needs;
* :func:`unwrapped`: the wraps of a piece taken out; :func:`unwrapped_log`: a whole
  recording's, piece by piece, for the checks across recordings;
* :func:`start_turns`: the whole turns a motor recorded wrapped had at a piece's start,
  from the joints' limits (refused when they leave several), or, at the log's first
  sample, the turns that put the joints nearest the positions given there (``--q-start``);
* :func:`with_start_turns`: a motor-side log with its wrapped motors unwrapped and given
  their whole turns, the first piece's from the joint positions given at its start;
* :func:`recording_pieces`: all four for one recording, its time column checked first
  (:func:`~dynid.identification.angle_time_units.time_unit_finding`);
* :func:`joined`: the pieces of one recording as one log for its checks;
* :func:`skipped_piece`: the line of a piece left out, for the record.

Used by identification (:mod:`dynid.identification.recordings`), validation and the
friction fit (:mod:`dynid.friction.recordings`) and the payload.
"""

from __future__ import annotations

import itertools
import logging
import warnings
from collections.abc import Mapping, Sequence
from typing import Any

import numpy as np
from numpy.typing import NDArray

from .._checks import caller_level
from .._times import longest_gaps, offset_text, said_times, stamp_text
from ..exceptions import DataError, DynidWarning, OptionError
from ..model.drive import Drive
from ..model.robot import Robot
from ..progress import NOTE
from ..signals import below_nyquist
from .angle_time_units import time_unit_finding
from .log import (
    DEFAULT_CUTOFF_HZ,
    LogCleaning,
    TorqueLog,
    default_max_gap,
    jitter_text,
    with_derived_velocities,
)
from .sanity import too_few_samples
from .training_range import endless_joints

_log = logging.getLogger(__name__)

__all__ = [
    "wrapped_finding",
    "wrapped_range",
    "Q_START_TOLERANCE",
    "WRAP_SPAN",
    "check_below_nyquist",
    "check_samples_and_time",
    "gaps_between",
    "gaps_text",
    "recording_line",
    "timing_record",
    "joined",
    "nearest_turns",
    "nyquist_cutoff",
    "recording_pieces",
    "skipped_piece",
    "split_at_gaps",
    "start_turns",
    "unwrapped",
    "with_start_turns",
    "turn_limited",
    "unwrapped_log",
    "wrappable",
]

#: Positions recorded wrapped span at most this many turns (one, and the noise or offset
#: a logger may add after wrapping).
WRAP_SPAN = 1.05


def check_below_nyquist(pieces: list[TorqueLog], cutoff_hz: float | None) -> None:
    """Refuse a cut-off [Hz] given at or above the sample rate of every piece: no cut-off
    for these samples at all (a value for another log, or in another unit), the option at
    fault, not the recording. One between half the rate and the rate is lowered
    (:func:`nyquist_cutoff`).

    Raises
    ------
    OptionError
        ``cutoff_hz`` (``field``), with the sample rate.
    """
    rates = [p.sample_rate for p in pieces if p.n_samples >= 2]
    if cutoff_hz is None or not rates or any(cutoff_hz < fs for fs in rates):
        return
    fs = max(rates)
    raise OptionError(
        f"{cutoff_hz:g} Hz: must be below half the sample rate, {0.5 * fs:.4g} Hz (the "
        f"recording is sampled at {fs:.4g} Hz)",
        field="cutoff_hz",
    )


def nyquist_cutoff(
    pieces: Sequence[TorqueLog], cutoff_hz: float | None, whose: str = "--cutoff"
) -> float | None:
    """The cut-off [Hz] the pieces are filtered at: ``cutoff_hz`` where it lies below half
    the rate of the slowest piece, else a quarter of that rate
    (:func:`~dynid.signals.below_nyquist`), with a note naming ``whose`` value it was
    (``--cutoff``, the model's): a model identified on a 1 kHz log at 20 Hz, or
    ``--cutoff 20``, on a 30 Hz servo log was refused, its velocities underived."""
    rates = [p.sample_rate for p in pieces if p.n_samples >= 2]
    if cutoff_hz is None or not rates:
        return cutoff_hz
    fs = min(rates)
    fc = below_nyquist(cutoff_hz, fs)
    if fc != cutoff_hz:
        _log.log(
            NOTE,
            f"{whose} {cutoff_hz:g} Hz is not below half the sample rate, {0.5 * fs:.4g} Hz "
            f"(the recording is sampled at {fs:.4g} Hz): filtered at a quarter of the rate, "
            f"{fc:.4g} Hz",
        )
    return fc


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


def gaps_between(pieces: Sequence[TorqueLog]) -> tuple[tuple[float, float], ...]:
    """The gaps between consecutive ``pieces`` of one recording (:func:`split_at_gaps`):
    per gap the last time stamp before it and its length, both [s]."""
    return tuple(
        (float(a.t[-1]), float(b.t[0] - a.t[-1])) for a, b in zip(pieces, pieces[1:], strict=False)
    )


def gaps_text(gaps: Sequence[Sequence[float]], t0: float | None, name: str | None) -> str:
    """``cut at the gap(s) after t = 86412.300 s (11.3 s into rec1.csv; 0.4 s long)``: the
    gaps a recording was cut at (``[t_before, length]`` [s] each, :func:`gaps_between`),
    the four longest (:func:`~dynid._times.longest_gaps`), each stamp as in the file with
    its offset from the recording's first stamp ``t0`` [s] (when that is not 0); empty
    without gaps. How ``identify``, ``validate``, ``friction`` and ``payload`` say where a
    recording was cut."""
    if not gaps:
        return ""
    said = []
    shown, more = longest_gaps(gaps)
    for t, length in shown:
        into = offset_text([t - (t0 or 0.0)], t0, name)
        said.append(f"t = {stamp_text(t)} s ({into + '; ' if into else ''}{length:.3g} s long)")
    return f"cut at the gap(s) after {', '.join(said)}{more}"


def timing_record(
    gaps: Sequence[Sequence[float]], start_s: float | None, cleaning: LogCleaning
) -> dict[str, Any]:
    """What a recording's record (``recordings[]`` of a result file) keeps of its time
    stamps: the ``gaps`` it was cut at (``[t_before, length]`` [s] each,
    :func:`gaps_between`) with ``start_s``, its first stamp [s] (when known); and ``stamp_jitter_s``
    with ``period_s`` [s] where its stamps are jittered (its reader's ``cleaning``, said
    as :func:`~dynid.identification.log.jitter_text` says it). Empty for a recording of
    uniform stamps without gaps; ``samples_missing``, the samples missing from the stamps'
    grid (:attr:`~dynid.identification.log.LogCleaning.n_dropped`: dropped samples, those
    of the gaps included), when any."""
    out: dict[str, Any] = {}
    if gaps:
        out["gaps"] = [[float(t), float(length)] for t, length in gaps]
        if start_s is not None:
            out["start_s"] = float(start_s)
    if jitter_text(cleaning.stamp_jitter_s, cleaning.period_s) is not None:
        out["stamp_jitter_s"] = float(cleaning.stamp_jitter_s)
        out["period_s"] = float(cleaning.period_s)
    if cleaning.n_dropped:
        out["samples_missing"] = int(cleaning.n_dropped)
    return out


def recording_line(rec: Mapping[str, Any]) -> str:
    """``a.csv: 2 pieces, 3000 samples, cut at the gap(s) after t = ... (7 s into a.csv;
    0.3 s long); stamps jittered, std 0.04 ms at a 1 ms period; 305 sample(s) missing from
    the stamps' grid (dropped, the gaps' included)``: a recording's record
    (``file``, ``pieces``, ``samples``, and :func:`timing_record`'s keys when there),
    its gaps as ``identify`` says them (:func:`gaps_text`) and its stamps' jitter
    (:func:`~dynid.identification.log.jitter_text`)."""
    k = rec["pieces"]
    line = f"{rec['file']}: {k} piece{'s' if k != 1 else ''}, {rec['samples']} samples"
    if cut := gaps_text(rec.get("gaps") or (), rec.get("start_s"), rec.get("file")):
        line += f", {cut}"
    jitter = rec.get("stamp_jitter_s")
    if jitter is not None and (said := jitter_text(jitter, rec.get("period_s", np.nan))):
        line += f"; {said}"
    if missing := rec.get("samples_missing"):
        line += f"; {missing} sample(s) missing from the stamps' grid (dropped" + (
            ", the gaps' included)" if rec.get("gaps") else ")"
        )
    return line


def wrappable(robot: Robot, drive: Drive | None = None) -> NDArray[np.bool_]:
    """The recorded position columns that can hold a wrap into ``[-pi, pi]``.

    Without a drive, or with one whose log is joint side (an identity drive, the armature
    of ``rotor_inertia = "identify"`` included): every revolute joint. A joint whose
    limits span less than a turn (:func:`turn_limited`) cannot wrap as described, but a
    log of it can (its description's limits narrower than the arm's, or an encoder read
    modulo a turn): its jumps of a whole turn are a wrap, not degrees, and
    :func:`wrapped_finding` says the limits do not allow them. On a motor-side log: the
    motors whose angle spans at least a turn over the joints' limits (``|K| (q_max -
    q_min)``, ``K`` the transmission; any unbounded joint they drive included), prismatic
    joints' motors too (a ball screw turns).
    """
    span = np.asarray(robot.q_max, dtype=np.float64) - np.asarray(robot.q_min, dtype=np.float64)
    turn = 2 * np.pi * (1.0 - 1e-9)
    if drive is None or drive.side == "joint":
        return ~np.asarray(robot.prismatic, dtype=bool)
    K = np.abs(np.asarray(drive.transmission, dtype=np.float64))
    motor = np.array([float(np.sum(span[row > 0] * row[row > 0])) for row in K])
    return np.asarray(motor >= turn, dtype=bool)


def turn_limited(robot: Robot) -> NDArray[np.bool_]:
    """The revolute joints whose limits span less than a whole turn (n,): recorded
    wrapped, they moved where their description does not let them (the revolute joints
    not :func:`~dynid.identification.training_range.endless_joints`)."""
    revolute = ~np.asarray(robot.prismatic, dtype=bool)
    return revolute & ~endless_joints(robot.q_min, robot.q_max, robot.prismatic)


def unwrapped(log: TorqueLog, revolute: NDArray[np.bool_]) -> tuple[TorqueLog, tuple[int, ...]]:
    """The log with the columns ``revolute`` (:func:`wrappable`) recorded wrapped into
    ``[-pi, pi]`` unwrapped; a log without gaps (a piece, :func:`split_at_gaps`).

    A column is wrapped when its positions stay within one turn (:data:`WRAP_SPAN`), jump
    somewhere by more than half a turn, and every such jump is nearly a whole turn more
    than its recorded velocity explains (``dq dt``, the mean of the two samples'; the raw step for
    velocities derived from the positions) while the rest of the jump is as small as its
    other unexplained steps (scaled by the cube of the step's length, the trapezoid's
    error: a sample dropped at a wrap): a fast motor turning more than half a turn
    between two samples is motion, not a wrap, and smooth positions whose velocities
    disagree with them (a time column in ms) are not wrapped. Returns the log with those
    turns taken out and the columns unwrapped (0-based; the log itself when none).
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
        # the velocities' trapezoid misses a step by about h^3 (a sample dropped at a wrap
        # makes its step 2-3 times as long): each step's allowance grows so
        long = np.maximum(1.0, h / float(np.median(h))) ** 3
        typical = float(np.max(np.abs(d[~moved]) / long[~moved], initial=0.0))
        allowed = np.maximum(2 * typical * long[moved], 1e-9)
        if np.all(np.abs(d[moved] - 2 * np.pi * turns[moved]) <= allowed):
            found[j] = turns
    if not found:
        return log, ()
    q = np.array(log.q)
    for j, turns in found.items():
        q[1:, j] -= 2 * np.pi * np.cumsum(turns)
    out = TorqueLog(log.t, q, log.dq, log.tau, log.ddq, log.cleaning, log.dq_derived)
    joints = tuple(sorted(found))
    return out, joints


def check_samples_and_time(name: str, log: TorqueLog) -> None:
    """Refuse a recording of too few samples
    (:func:`~dynid.identification.sanity.too_few_samples`, before any statistic of it) or
    whose time column looks like ms, us or ns
    (:func:`~dynid.identification.angle_time_units.time_unit_finding`).

    Raises
    ------
    DataError
        Naming the file ``name`` (and for the time column, the factor).
    """
    if (few := too_few_samples(log)) is not None:
        raise DataError(few, file=name)
    if (unit := time_unit_finding(name, log)) is not None:  # it names the file
        raise DataError(unit.removeprefix(f"{name}: "), file=name)


def recording_pieces(
    name: str,
    log: TorqueLog,
    turns: NDArray[np.bool_],
    max_gap_s: float | None = None,
    *,
    robot: Robot | None = None,
    drive: Drive | None = None,
    say_wrapped: bool = True,
) -> tuple[list[TorqueLog], tuple[int, ...]]:
    """One recording checked, cut at its gaps and unwrapped piece by piece.

    The time column is checked against the recorded velocities first
    (:func:`~dynid.identification.angle_time_units.time_unit_finding`); the log is cut at its gaps
    longer than ``max_gap_s`` (:func:`split_at_gaps`) and each piece's columns ``turns``
    (:func:`wrappable`) are unwrapped on their own (:func:`unwrapped`): a jump across a
    cut-out stretch is no wrap and does not keep the other wraps in. On a motor-side log
    (``drive``), the motors found wrapped lost their whole turns at each piece's start,
    which set the joint positions (``2 pi / K`` each): they are found from the joints'
    limits (:func:`start_turns`, ``robot``). A warning names the file and the joints
    (motors) unwrapped.

    Returns
    -------
    pieces : list of TorqueLog
    joints : tuple of int
        The columns (0-based) unwrapped in some piece.

    Raises
    ------
    DataError
        Too few samples (:func:`~dynid.identification.sanity.too_few_samples`); the time
        column looks like ms, us or ns (the file and the factor are named); a
        motor-side log's motors recorded wrapped whose turns the joints' limits do not
        tell (:func:`start_turns`).
    OptionError
        ``max_gap_s`` below the sample step.
    """
    check_samples_and_time(name, log)
    pieces, turned = _unwrapped_pieces(name, log, turns, max_gap_s)
    motors = drive is not None and drive.side == "motor"
    if turned and motors and robot is not None:
        assert drive is not None
        pieces = [
            start_turns(name, p, sorted(turned), robot, drive, log_start=k == 0)
            for k, p in enumerate(pieces)
        ]
    if (alone := log.n_samples - sum(p.n_samples for p in pieces)) > 0:
        warnings.warn(
            f"{name}: {alone} sample(s) isolated between gaps longer than the longest gap "
            "bridged left out",
            DynidWarning,
            stacklevel=caller_level(),
        )
    joints = tuple(sorted(turned))
    if joints and say_wrapped:
        said = wrapped_finding(joints, motors, robot=None if motors else robot, log=log)
        tell_wrapped(said, joints, motors, robot, name)
    return pieces, joints


def _unwrapped_pieces(
    name: str, log: TorqueLog, turns: NDArray[np.bool_], max_gap_s: float | None
) -> tuple[list[TorqueLog], set[int]]:
    """The pieces of ``log`` (:func:`split_at_gaps`), each unwrapped on its own
    (:func:`unwrapped`), and the columns unwrapped in some piece.

    Velocities the reader derived from the positions (``dq_derived``) were derived over
    the wrapped ones: a whole turn's jump spread by the filter over many samples. When
    some column was unwrapped they are derived again as the reader did, over the whole
    log at its cut-off, from the unwrapped positions (each piece after a gap shifted by
    the whole turns nearest the sample before it, as a log unwrapped by hand): every step
    reads the motion, not the jump, and the same velocities as from that log."""
    pieces: list[TorqueLog] = []
    turned: set[int] = set()
    for piece in split_at_gaps(log, max_gap_s, name):
        piece, joints = unwrapped(piece, turns)
        turned.update(joints)
        pieces.append(piece)
    if not turned or not log.dq_derived:
        return pieces, turned
    cols = sorted(turned)
    q = np.array(log.q)
    at = np.searchsorted(log.t, [p.t[0] for p in pieces])
    for start, piece in zip(at, pieces, strict=True):
        q[start : start + piece.n_samples, cols] = piece.q[:, cols]
    step = np.diff(q[:, cols], axis=0)  # the turns left at the gaps (and isolated samples)
    q[1:, cols] -= 2 * np.pi * np.cumsum(np.round(step / (2 * np.pi)), axis=0)
    dq = with_derived_velocities(TorqueLog(log.t, q, log.dq, log.tau), DEFAULT_CUTOFF_HZ).dq
    return [
        TorqueLog(p.t, p.q, dq[k : k + p.n_samples], p.tau, p.ddq, p.cleaning, p.dq_derived)
        for k, p in zip(at, pieces, strict=True)
    ], turned


def unwrapped_log(
    name: str, log: TorqueLog, turns: NDArray[np.bool_], max_gap_s: float | None = None
) -> tuple[TorqueLog, tuple[int, ...]]:
    """``log`` with its columns ``turns`` (:func:`wrappable`) recorded wrapped unwrapped
    piece by piece, by the rule :func:`recording_pieces` applies (the pieces joined
    again, samples isolated between gaps left out), for the checks that read a whole
    recording before it is prepared, and the columns unwrapped (0-based); velocities
    derived from the positions derived again from the unwrapped ones, as there. ``log``
    itself when nothing was wrapped. Warns of nothing: the preparation says it.

    Raises
    ------
    OptionError
        ``max_gap_s`` below the sample step.
    """
    if log.n_samples < 3:
        return log, ()
    pieces, turned = _unwrapped_pieces(name, log, turns, max_gap_s)
    if not turned:
        return log, ()
    out = TorqueLog(
        np.concatenate([p.t for p in pieces]),
        np.concatenate([p.q for p in pieces]),
        np.concatenate([p.dq for p in pieces]),
        np.concatenate([p.tau for p in pieces]),
        None if log.ddq is None else np.concatenate([p.ddq for p in pieces if p.ddq is not None]),
        log.cleaning,
        log.dq_derived,
    )
    return out, tuple(sorted(turned))


def wrapped_finding(
    joints: Sequence[int],
    motors: bool = False,
    *,
    robot: Robot | None = None,
    log: TorqueLog | None = None,
) -> str:
    """The finding of the joints (0-based; ``motors``: the motors) recorded wrapped within a
    turn and unwrapped, without the file's name (:func:`recording_pieces` says it per
    recording; several recordings say it once, naming them); the turn is the one the
    ``log``'s positions show (:func:`wrapped_range`: ``[0, 2 pi)`` for a vendor's 0 to 360
    degrees; ``[-pi, pi]`` without a log). Given the ``robot`` and
    the joint-side ``log`` as recorded, a joint whose limits span less than a turn
    (:func:`turn_limited`) and whose motion, unwrapped, no whole turns put within them
    (:func:`_within_limits`: limits across ``pi`` let a joint cross it) is named with the
    times [s] of its jumps and its limits, which do not allow that motion: the log or the
    description is wrong (not degrees)."""
    what = "motor(s)" if motors else "joint(s)"
    within = "[-pi, pi]" if log is None else wrapped_range(log.q[:, list(joints)])
    said = (
        f"{what} {', '.join(str(j + 1) for j in joints)} recorded wrapped into {within} "
        "(jumps of a whole turn): unwrapped"
    )
    if robot is None or log is None or motors:
        return said
    limited = turn_limited(robot)
    for j in (j for j in joints if limited[j]):
        if _within_limits(log.q[:, j], float(robot.q_min[j]), float(robot.q_max[j])):
            continue  # limits across +-pi: the joint crossed it, no whole turn
        at = log.t[1:][np.abs(np.diff(log.q[:, j])) > np.pi]
        said += (
            f"; {robot.joint_names[j]} jumps a whole turn at "
            f"{said_times(at, float(log.t[0]), shown=5)}, but its limits "
            f"[{robot.q_min[j]:.4g}, {robot.q_max[j]:.4g}] do not allow a whole turn: "
            "unwrapped as a continuous joint; the log or the robot description is wrong "
            "(not degrees: those would be 57 times the radians)"
        )
    return said


def tell_wrapped(
    finding: str, joints: Sequence[int], motors: bool, robot: Robot | None, names: str
) -> None:
    """Say :func:`wrapped_finding`'s ``finding`` of the recordings ``names`` (a prefix, as
    ``"rec1.csv, rec2.csv"``): a note where every joint named turns without end in the
    robot's description (a continuous joint, limits a turn or more apart: its angle read
    within a turn is expected, and unwrapping it is the reading), a warning otherwise (a
    joint whose limits do not allow a whole turn, or a motor)."""
    ends = None if robot is None else endless_joints(robot.q_min, robot.q_max, robot.prismatic)
    if ends is not None and not motors and all(ends[j] for j in joints):
        _log.log(NOTE, "%s: %s", names, finding)
    else:
        warnings.warn(f"{names}: {finding}", DynidWarning, stacklevel=caller_level())


#: Slack [rad] of a recorded range against the turn it is said to be wrapped into.
_RANGE_SLACK = 0.05


def wrapped_range(q: NDArray[np.float64]) -> str:
    """The turn positions ``q`` (N, k) [rad] recorded wrapped lie in, as a message says it:
    ``[-pi, pi]``, ``[0, 2 pi)`` (a vendor's 0 to 360 degrees), else their least and
    greatest values (``[-0.2, 6.1]``)."""
    lo, hi = float(np.min(q)), float(np.max(q))
    if lo >= -np.pi - _RANGE_SLACK and hi <= np.pi + _RANGE_SLACK:
        return "[-pi, pi]"
    if lo >= -_RANGE_SLACK and hi <= 2 * np.pi + _RANGE_SLACK:
        return "[0, 2 pi)"
    return f"[{lo:.3g}, {hi:.3g}]"


#: Slack [rad] of a joint's unwrapped motion against its limits (:func:`_within_limits`).
_WRAP_LIMIT_SLACK = 0.05


def _within_limits(q: NDArray[np.float64], lo: float, hi: float) -> bool:
    """Whether a joint's positions ``q`` (N,) [rad], recorded wrapped into ``[-pi, pi]``,
    unwrapped and moved by some whole turns, lie within its limits ``[lo, hi]`` [rad] (to
    :data:`_WRAP_LIMIT_SLACK`): a joint of limits ``[-0.52, 4.71]`` moving from 0.7 to 4.1
    rad is logged jumping a whole turn at pi without ever turning one."""
    u = np.unwrap(np.asarray(q, dtype=np.float64))
    a, b = float(u.min()), float(u.max())
    if b - a > hi - lo + 2 * _WRAP_LIMIT_SLACK:
        return False
    k = np.ceil((lo - _WRAP_LIMIT_SLACK - a) / (2 * np.pi))  # the fewest turns up to lo
    return b + 2 * np.pi * k <= hi + _WRAP_LIMIT_SLACK


def start_turns(
    name: str,
    piece: TorqueLog,
    motors: list[int],
    robot: Robot,
    drive: Drive,
    q_start: NDArray[np.float64] | None = None,
    *,
    log_start: bool = True,
) -> TorqueLog:
    """The motor-side ``piece`` with its ``motors`` (0-based, recorded wrapped and
    unwrapped, :func:`unwrapped`) given the whole turns they had at its start.

    A wrapped motor angle keeps no count of whole turns: unwrapped, it starts within
    ``[-pi, pi]``, and each turn it lost moves the joints by ``2 pi K^-1 e_j`` (a gear of
    100 turns 0.063 rad at the joint). The turns ``n`` are those that put every sample's
    joint positions ``q = K^-1 (q_m + 2 pi n) + q_0`` within the joints' limits: a joint
    that one motor turns (beside motors already counted) bounds that motor's turns, motor
    after motor; found when each motor is left one count (the joint's limits spanning
    less than its motion plus one turn of the motor), then checked on every joint.

    With ``q_start`` (n,) [rad or m], the joint positions at the piece's first sample (the
    log's, ``--q-start``), the turns are those that put the first sample's joint positions
    nearest to it (:func:`nearest_turns`), whatever the limits say. ``log_start``: the
    piece starts the log (False: it follows a gap, said in the error).

    Raises
    ------
    DataError
        The limits leave several counts (or none) for some motor: the joint positions are
        unknown by whole turns of the motors (the file, the motors and the counts named;
        the hint names ``--q-start``); ``q_start`` nearly as near to two counts.
    """
    if q_start is not None:
        n = nearest_turns(name, piece, motors, drive, q_start)
        qm = np.array(piece.q)
        qm[:, motors] += 2 * np.pi * n
        return TorqueLog(
            piece.t, qm, piece.dq, piece.tau, piece.ddq, piece.cleaning, piece.dq_derived
        )
    q = drive.joint_states(np.asarray(piece.q, dtype=np.float64))[0]
    lo = np.asarray(robot.q_min, dtype=np.float64) - q.min(axis=0)
    hi = np.asarray(robot.q_max, dtype=np.float64) - q.max(axis=0)
    A = 2 * np.pi * np.linalg.inv(np.asarray(drive.transmission, dtype=np.float64))[:, motors]
    acts = np.abs(A) > 1e-12 * np.abs(A).max()
    n = np.zeros(len(motors))
    counts = np.full(len(motors), np.inf)  # the counts the limits leave; inf: unbounded
    done = np.zeros(len(motors), dtype=bool)
    while not done.all():
        progress = False
        for k in np.flatnonzero(~done):
            others = acts & ~done & (np.arange(len(motors)) != k)
            rows = np.flatnonzero(acts[:, k] & ~others.any(axis=1))
            if rows.size == 0:
                continue
            rest = A[rows][:, done] @ n[done]  # the motors already counted
            ends = np.sort(np.stack([lo[rows] - rest, hi[rows] - rest]) / A[rows, k], axis=0)
            a, b = float(np.max(ends[0])), float(np.min(ends[1]))
            first = np.ceil(a - 1e-9) if np.isfinite(a) else 0.0
            counts[k] = np.floor(b + 1e-9) - first + 1 if np.isfinite(a + b) else np.inf
            n[k], done[k], progress = first, True, True
        if not progress:
            break
    shift = A @ n
    if np.any(counts != 1) or np.any(shift < lo - 1e-9) or np.any(shift > hi + 1e-9):
        told = [
            f"{m + 1}: {'unbounded' if not np.isfinite(c) else int(max(c, 0))}"
            for m, c in zip(motors, counts, strict=True)
            if c != 1
        ]
        raise DataError(
            f"motor(s) {', '.join(str(m + 1) for m in motors)} recorded wrapped into "
            "[-pi, pi] lost the whole turns that set the joint positions, and the joints' "
            f"limits leave several counts of them at t = {stamp_text(piece.t[0])} s (motor "
            f"{'; motor '.join(told) or 'none fits every joint'}); hint: "
            + (
                "give the joint positions at the log's first sample with --q-start "
                "(comma list, rad; it applies to one recording: give this one alone), log "
                "the motors' multi-turn angles, or the joint positions (a joint-side log)"
                if log_start
                else "this piece follows a gap, across which the turns are lost: "
                "--q-start gives those of the log's first sample only; log the motors' "
                "multi-turn angles, or record without gaps"
            ),
            file=name,
        )
    qm = np.array(piece.q)
    qm[:, motors] += 2 * np.pi * n
    return TorqueLog(piece.t, qm, piece.dq, piece.tau, piece.ddq, piece.cleaning, piece.dq_derived)


def nearest_turns(
    name: str,
    piece: TorqueLog,
    motors: list[int],
    drive: Drive,
    q_start: NDArray[np.float64],
) -> NDArray[np.float64]:
    """The whole turns ``n`` (len(motors),) of the ``motors`` (recorded wrapped) that put
    the joint positions of the piece's first sample, ``K^-1 (q_m + 2 pi n) + q_0``,
    nearest to ``q_start`` (n,) [rad] (Euclidean; the nearest point of the lattice of
    joint shifts ``2 pi K^-1 e_m``, searched around the rounded least-squares counts).

    Raises
    ------
    DataError
        The second-nearest count lies less than twice as far from ``q_start`` as the
        nearest: the positions given do not tell the turns (the gap to close is named).
    """
    q0 = drive.joint_states(np.asarray(piece.q[:1], dtype=np.float64))[0][0]
    A = 2 * np.pi * np.linalg.inv(np.asarray(drive.transmission, dtype=np.float64))[:, motors]
    d = np.asarray(q_start, dtype=np.float64) - q0
    m = len(motors)
    base = np.round(np.linalg.lstsq(A, d, rcond=None)[0])
    steps = (
        np.array(list(itertools.product((-1.0, 0.0, 1.0), repeat=m)))
        if m <= 7
        else np.vstack([np.zeros(m), np.eye(m), -np.eye(m)])
    )
    counts = base + steps
    dist = np.linalg.norm(counts @ A.T - d, axis=1)
    order = np.argsort(dist, kind="stable")
    best, second = counts[order[0]], counts[order[1]]
    d1, d2 = float(dist[order[0]]), float(dist[order[1]])
    if not d2 >= 2.0 * d1:
        apart = float(np.linalg.norm(A @ (best - second)))
        raise DataError(
            f"--q-start lies {d1:.3g} rad from the joint positions of one count of the "
            f"turns of motor(s) {', '.join(str(k + 1) for k in motors)} recorded wrapped and "
            f"{d2:.3g} rad from another's ({apart:.3g} rad apart): it does not tell them; "
            f"hint: give the joint positions at the log's first sample (t = "
            f"{stamp_text(piece.t[0])} s) to within {apart / 3:.3g} rad",
            file=name,
        )
    return best


def with_start_turns(
    name: str,
    log: TorqueLog,
    robot: Robot,
    drive: Drive | None,
    q_start: NDArray[np.float64] | None = None,
    max_gap_s: float | None = None,
) -> TorqueLog:
    """A motor-side ``log`` with its motors recorded wrapped into ``[-pi, pi]`` unwrapped
    and given their whole turns: with ``q_start`` (``--q-start``) the log's first piece
    (up to its first gap longer than ``max_gap_s``) the turns that put its first sample's
    joint positions nearest to ``q_start`` (n,) [rad] (:func:`nearest_turns`); every other
    piece those its joints' limits tell (:func:`start_turns`). The log then holds
    multi-turn motor angles, as :func:`recording_pieces` reads them; its samples isolated
    between gaps are kept as recorded (no piece holds them). A warning names the file and
    the motors. Without ``q_start``, a log that is not motor side or whose motors did not
    wrap is returned as it is.

    Raises
    ------
    OptionError
        ``q_start`` not ``n`` finite numbers, or outside the joint limits (the joints and
        their limits named; degrees said); a drive whose log is not motor side; no motor
        of the log recorded wrapped (its angles tell the turns: ``--q-start`` does not
        apply).
    DataError
        As :func:`start_turns` (a later piece whose turns the limits do not tell) and
        :func:`nearest_turns`.
    """
    if q_start is None and (drive is None or drive.side != "motor"):
        return log
    if q_start is not None:
        _check_q_start(np.asarray(q_start, dtype=np.float64), robot, drive)
    assert drive is not None
    dt = np.diff(log.t)
    limit = default_max_gap(float(np.median(dt))) if max_gap_s is None else float(max_gap_s)
    cuts = np.concatenate([[0], np.flatnonzero(dt > limit) + 1, [log.n_samples]])
    spans = [(a, b) for a, b in zip(cuts[:-1], cuts[1:], strict=True) if b - a > 1]
    turns = wrappable(robot, drive)
    done = [unwrapped(log.select(slice(a, b)), turns) for a, b in spans]
    motors = sorted({j for _, js in done for j in js})
    if not motors and q_start is None:
        return log
    if not motors:
        raise OptionError(
            f"does not apply to {name}: none of its motors was recorded wrapped into "
            "[-pi, pi] (its angles tell the turns); leave it out",
            field="q_start",
        )
    if q_start is not None:
        _check_q_start_limits(np.asarray(q_start, dtype=np.float64), robot)
    q = np.array(log.q)
    for k, ((a, b), (piece, _)) in enumerate(zip(spans, done, strict=True)):
        given = q_start if k == 0 else None
        q[a:b] = start_turns(name, piece, motors, robot, drive, given, log_start=k == 0).q
    source = "from --q-start" if q_start is not None else "from the joints' limits"
    warnings.warn(
        f"{name}: motor(s) {', '.join(str(j + 1) for j in motors)} recorded wrapped into "
        f"[-pi, pi]: unwrapped, their whole turns at the first sample {source}",
        DynidWarning,
        stacklevel=caller_level(),
    )
    out = TorqueLog(log.t, q, log.dq, log.tau, log.ddq, log.cleaning, log.dq_derived)
    if log.dq_derived:  # derived from the wrapped angles as read: a turn's jump at each wrap
        out = with_derived_velocities(out, DEFAULT_CUTOFF_HZ)
    return out


def _check_q_start(q_start: NDArray[np.float64], robot: Robot, drive: Drive | None) -> None:
    """Refuse joint positions at the first sample that are not ``robot.n`` finite numbers,
    or given without a motor-side drive (:func:`with_start_turns`)."""
    if q_start.shape != (robot.n,) or not np.all(np.isfinite(q_start)):
        raise OptionError(
            f"must hold {robot.n} finite joint positions [rad] (one per joint of robot "
            f"{robot.name!r}); got {np.size(q_start)} number(s)",
            field="q_start",
        )
    if drive is None or drive.side != "motor":
        raise OptionError(
            "gives the whole turns of motors recorded wrapped into [-pi, pi] on a motor-side "
            'log; it does not apply without a {drive} of side = "motor"',
            field="q_start",
            others=("drive",),
        )


def _check_q_start_limits(q_start: NDArray[np.float64], robot: Robot) -> None:
    """Refuse joint positions at the first sample outside the joint limits (beyond
    :data:`Q_START_TOLERANCE`), naming the joints and their limits; positions beyond a turn
    that fit them read in degrees are said to be degrees (:func:`with_start_turns`)."""
    lo = np.asarray(robot.q_min, dtype=np.float64) - Q_START_TOLERANCE
    hi = np.asarray(robot.q_max, dtype=np.float64) + Q_START_TOLERANCE
    out = np.flatnonzero((q_start < lo) | (q_start > hi))
    if out.size:
        deg = q_start * np.pi / 180.0
        # beyond a turn, and every joint within its limits read in degrees
        in_degrees = bool(np.any(np.abs(q_start[out]) > 2 * np.pi)) and bool(
            np.all((deg >= lo) & (deg <= hi))
        )
        said = ", ".join(
            f"{robot.joint_names[j]} {q_start[j]:.4g} outside [{robot.q_min[j]:.4g}, "
            f"{robot.q_max[j]:.4g}]"
            for j in out
        )
        raise OptionError(
            f"lies outside the joint limits of robot {robot.name!r} ({said})"
            + (
                ": in degrees? hint: give the joint positions in radians (x pi/180)"
                if in_degrees
                else "; hint: give the joint positions [rad] at the log's first sample"
            ),
            field="q_start",
        )


#: How far [rad or m] ``--q-start`` may lie beyond a joint's limits (a joint stopped
#: at its limit, read by its encoder).
Q_START_TOLERANCE = 0.02

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


def skipped_piece(name: str, piece: TorqueLog, exc: Exception) -> str:
    """The line of a piece of recording ``name`` left out (too short to filter, the reason
    ``exc``), for the record; the warning is one for all the pieces left out
    (:func:`~dynid.identification.cut_loss.left_out_finding`)."""
    return (
        f"{name}: piece t = {stamp_text(piece.t[0])}-{stamp_text(piece.t[-1])} s "
        f"({piece.n_samples} samples) "
        f"left out: {exc}"
    )
