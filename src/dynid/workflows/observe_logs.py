"""A log as ``dynid observe`` runs the momentum observer on it (:mod:`dynid.workflows.observe`).

:func:`prepared_log` brings it to the joints through the model's drive, unwraps joints
recorded in ``[-pi, pi]``, cuts it at its gaps (steps longer than the rule ``identify``
cuts at: rows dropped for NaN or inf leaving a shorter step are bridged), and again where
positions jump more than the velocities explain (each with a warning naming the file),
and keeps the spans the observer runs on. :func:`observed_blocks` then runs one
observer per piece a block of :data:`OBSERVE_BLOCK` samples at a time, with the residual's
std from the model's covariance and the standstill margin of the same samples: a long log
is observed with one block's temporaries (a calibration keeps only running statistics;
:class:`Series` fills full-length series when they are wanted).
"""

from __future__ import annotations

import logging
import warnings
from collections.abc import Iterator
from dataclasses import dataclass
from pathlib import Path
from typing import Any

import numpy as np
from numpy.typing import NDArray

from .._checks import caller_level
from .._times import said_times, stamp_text
from ..exceptions import DataError, DynidWarning
from ..exceptions import in_file as about_file
from ..friction.model import FrictionModel, FrictionSum
from ..identification.log import TorqueLog, default_max_gap, joint_side_log
from ..identification.pieces import (
    recording_line,
    tell_wrapped,
    timing_record,
    unwrapped,
    with_start_turns,
    wrappable,
    wrapped_finding,
)
from ..identification.position_jumps import log_jitter
from ..identification.prepare import states_in_step
from ..observer.detection import (
    residual_std_blocks,
    standstill_blocks,
    standstill_rest_blocks,
)
from ..observer.friction import (
    DERIVED_CUTOFF_HZ,
    banded_if_narrow,
    derived_cutoff,
    derived_velocity_bands,
    velocity_bands,
)
from ..observer.model import ObserverModel
from ..observer.motion_range import log_speed_max, speed_window
from ..observer.pieces import PositionJump, pieces, position_jumps
from ..observer.residual import MomentumObserver, ObserverOptions
from ..observer.thresholds import RestMargin
from ..progress import NOTE, report
from ..signals import edge_seconds, filtered_derivative

_log = logging.getLogger(__name__)

__all__ = [
    "OBSERVE_BLOCK",
    "ObservedBlock",
    "PreparedLog",
    "Series",
    "margin_series",
    "observed_blocks",
    "observed_rows",
    "prepared_log",
    "speeds_of",
]


@dataclass(frozen=True, slots=True)
class PreparedLog:
    """A log brought to the joints, with the velocities and the spans the observer runs
    on (:func:`prepared_log`), and the cut-off [Hz] velocities derived from its positions
    are low-passed at (:func:`~dynid.observer.friction.derived_cutoff`)."""

    path: Path
    log: TorqueLog
    dq: NDArray[np.float64]
    spans: list[tuple[int, int]]
    cutoff_hz: float = DERIVED_CUTOFF_HZ


@dataclass(frozen=True, slots=True)
class ObservedBlock:
    """The residual of samples ``[a, a + len(r))`` of a log, their std and margin, the
    friction the observer evaluated there (the model's, or the model's banded for the
    velocity noise: :func:`~dynid.observer.friction.banded_if_narrow`) and, with the
    margin, the seconds into the settled part of each joint's rest (NaN elsewhere;
    :mod:`dynid.observer.rest_margin`)."""

    a: int
    r: NDArray[np.float64]
    std: NDArray[np.float64] | None
    margin: NDArray[np.float64] | None
    friction: FrictionModel | FrictionSum | None = None
    settled: NDArray[np.float64] | None = None


@dataclass(frozen=True, slots=True)
class Series:
    """Full-length series of a log filled block by block (NaN where not observed)."""

    r: NDArray[np.float64]
    std: NDArray[np.float64] | None
    margin: NDArray[np.float64] | None

    @staticmethod
    def new(prep: PreparedLog, n: int, wants_std: bool, wants_margin: bool) -> Series:
        N = prep.log.t.shape[0]
        r = np.full((N, n), np.nan)
        return Series(
            r,
            np.full_like(r, np.nan) if wants_std else None,
            np.zeros(r.shape) if wants_margin else None,  # untouched where it stays 0
        )

    def put(self, blk: ObservedBlock) -> None:
        k = slice(blk.a, blk.a + blk.r.shape[0])
        self.r[k] = blk.r
        if self.std is not None and blk.std is not None:
            self.std[k] = blk.std
        if self.margin is not None and blk.margin is not None:
            self.margin[k] = blk.margin


def prepared_log(
    path: Path,
    log: TorqueLog,
    model: ObserverModel,
    max_gap: float | None,
    side: TorqueLog | None = None,
    torque_delay_s: float = 0.0,
) -> PreparedLog:
    """The log at the joints, unwrapped, cut at its gaps and jumps, with the velocities
    and the spans the observer runs on (warnings name the file). ``side``: ``log`` already
    on the joint side (the checks' :attr:`~dynid.workflows.recordings.Recorded.sides`),
    used unless its motors' whole turns change it. ``torque_delay_s`` [s]: how far the
    torques lag the positions; the states are read that much earlier, as identify reads
    them (:func:`~dynid.identification.prepare.states_in_step`)."""
    # motors recorded wrapped given their whole turns (refused when the limits leave several)
    whole = with_start_turns(path.name, log, model.robot, model.drive, max_gap_s=max_gap)
    if side is None or whole is not log:
        side = joint_side_log(whole, model.drive)
    # M(q) is periodic; velocities derived across a wrap are not
    log, turned = unwrapped(side, wrappable(model.robot))
    if turned:
        said = wrapped_finding(sorted(turned), robot=model.robot, log=side)
        tell_wrapped(said, sorted(turned), False, model.robot, path.name)
    starts = _pieces(path, log, max_gap)
    fc = _derived_cutoff(path, log)
    dq = _piece_velocities(log, starts, fc)  # of a log of positions: from the unwrapped ones
    cut = _cut_at_jumps(path, log, dq, starts)  # jumps of the log as recorded
    if torque_delay_s:  # the torques paired with their states (its extrapolated ends
        log = states_in_step(log, torque_delay_s)  # are left unobserved)
        dq = _piece_velocities(log, cut, fc)
    elif cut != starts and log.dq_derived:  # derived again, never across a jump
        dq = _piece_velocities(log, cut, fc)
    spans = _observed_spans(path, log, cut, abs(torque_delay_s), fc)
    return PreparedLog(path, log, dq, _finite(spans, dq), fc)


def _derived_cutoff(path: Path, log: TorqueLog) -> float:
    """The cut-off [Hz] the velocities of a log of positions are derived at
    (:func:`~dynid.observer.friction.derived_cutoff`), with a note where the log's rate
    lowers it; :data:`~dynid.observer.friction.DERIVED_CUTOFF_HZ` for a log with
    velocities (unused)."""
    if not log.dq_derived:
        return DERIVED_CUTOFF_HZ
    fc = derived_cutoff(log.t)
    if fc < DERIVED_CUTOFF_HZ:
        _log.log(
            NOTE,
            f"{path.name}: velocities derived from the positions at {fc:.4g} Hz, a quarter "
            f"of the rate ({4 * fc:.4g} Hz): the observer's {DERIVED_CUTOFF_HZ:g} Hz is not "
            "below half of it",
        )
    return fc


def _finite(spans: list[tuple[int, int]], dq: NDArray[np.float64]) -> list[tuple[int, int]]:
    """The spans whose velocities are finite throughout (a piece too short to filter has
    NaN derived velocities: it is not observed, never an error about a velocity column)."""
    return [(a, b) for a, b in spans if np.isfinite(dq[a:b]).all()]


def speeds_of(prep: PreparedLog, model: ObserverModel) -> NDArray[np.float64]:
    """Each joint's largest speed (n,) [rad/s] over the samples the observer runs on,
    measured as the model's identification measured its own (velocities averaged over a
    quarter period of its cut-off, else of the observer's:
    :func:`~dynid.observer.motion_range.log_speed_max`)."""
    info = model.logs_read
    cutoff = prep.cutoff_hz if info is None or info.cutoff_hz is None else info.cutoff_hz
    return log_speed_max(prep.dq, prep.spans, speed_window(prep.log.t, cutoff))


def recording_note(prep: PreparedLog) -> str | None:
    """The line ``identify``, ``validate``, ``friction`` and ``payload`` give a recording
    whose stamps are jittered or miss samples of their grid
    (:func:`~dynid.identification.pieces.recording_line`: ``rec4.csv: 1 piece, 10000
    samples; stamps jittered, std 0.2 ms at a 2 ms period``); its gaps are warned apart
    (the observer's cuts); None: uniform stamps."""
    rec = timing_record((), None, prep.log.cleaning)
    if not rec:
        return None
    head = {"file": prep.path.name, "pieces": len(prep.spans), "samples": prep.log.t.shape[0]}
    return recording_line({**head, **rec})


def observed_blocks(
    prep: PreparedLog,
    model: ObserverModel,
    options: ObserverOptions,
    wants_std: bool,
    wants_margin: bool,
    rest: RestMargin | None = None,
) -> Iterator[ObservedBlock]:
    """The residual of every observed span, :data:`OBSERVE_BLOCK` samples at a time (one
    observer per piece, its state carried from block to block), with the std and the
    standstill margin of the same samples (``rest``: the thresholds' margin calibrated at
    rests, :attr:`~dynid.observer.thresholds.Thresholds.rest`) and the settled part of
    the rests (errors name the file)."""
    t, q, tau, dq = prep.log.t, prep.log.q, prep.log.tau, prep.dq
    with about_file(prep.path.name):
        for a, b in prep.spans:
            kw, here = _span_friction(prep, model, a, b)
            obs = MomentumObserver(here, options)
            stds = _rechunked(
                residual_std_blocks(model, t[a:b], q[a:b], dq[a:b], options)
                if wants_std
                else iter(()),
                OBSERVE_BLOCK,
            )
            margins = (
                standstill_rest_blocks(
                    here, t[a:b], dq[a:b], options, OBSERVE_BLOCK, rest=rest, **kw
                )
                if wants_margin
                else iter(())
            )
            for c in range(a, b, OBSERVE_BLOCK):
                d = min(c + OBSERVE_BLOCK, b)
                report(f"observing {prep.path.name}: sample {d:,} of {t.shape[0]:,}")
                _, m, settled = next(margins, (c, None, None))
                yield ObservedBlock(
                    c,
                    obs.run(t[c:d], q[c:d], dq[c:d], tau[c:d]),
                    next(stds) if wants_std else None,
                    m,
                    here.friction,
                    settled,
                )


def margin_series(
    prep: PreparedLog, model: ObserverModel, options: ObserverOptions, rest: RestMargin | None
) -> NDArray[np.float64]:
    """The standstill margin (N, n) [N m] of a prepared log as :func:`observed_blocks`
    gives it with the thresholds' margin calibrated at rests ``rest`` (0 where the observer
    does not run), without running the observer: a calibration's kept series once its
    rest levels are known."""
    t, dq = prep.log.t, prep.dq
    out = np.zeros(dq.shape)
    for a, b in prep.spans:
        kw, here = _span_friction(prep, model, a, b)
        for c, m in standstill_blocks(here, t[a:b], dq[a:b], options, rest=rest, **kw):
            out[a + c : a + c + m.shape[0]] = m
    return out


def _span_friction(
    prep: PreparedLog, model: ObserverModel, a: int, b: int
) -> tuple[dict[str, Any], ObserverModel]:
    """The velocity bands of samples ``[a, b)`` (:func:`_bands`, else estimated on the
    velocities) and the model with the friction the observer evaluates there (a smooth
    law narrower than the noise banded: :func:`~dynid.observer.friction.banded_if_narrow`)."""
    kw = _bands(prep, model, a, b)
    if model.friction is None:
        return kw, model
    kw.setdefault("bands", velocity_bands(model.friction, prep.dq[a:b]))
    seen = banded_if_narrow(model.friction, kw["bands"], derived=kw.get("derived", False))
    return kw, model.with_friction(seen)


def observed_rows(
    prep: PreparedLog,
    model: ObserverModel,
    options: ObserverOptions,
    wants_std: bool,
    wants_margin: bool,
    rest: RestMargin | None = None,
) -> Iterator[ObservedBlock]:
    """:func:`observed_blocks` with the samples the observer does not run on between them
    (NaN residual and std, no margin), at most :data:`OBSERVE_BLOCK` at a time: blocks that
    cover every sample of the log in order (a residual table, the detection)."""
    N, n = prep.log.t.shape[0], prep.log.q.shape[1]
    done = 0
    for blk in observed_blocks(prep, model, options, wants_std, wants_margin, rest):
        yield from _unobserved(done, blk.a, n, wants_std)
        yield blk
        done = blk.a + blk.r.shape[0]
    yield from _unobserved(done, N, n, wants_std)


def _unobserved(a: int, b: int, n: int, wants_std: bool) -> Iterator[ObservedBlock]:
    for c in range(a, b, OBSERVE_BLOCK):
        r = np.full((min(c + OBSERVE_BLOCK, b) - c, n), np.nan)
        yield ObservedBlock(c, r, r if wants_std else None, None)


def _bands(prep: PreparedLog, model: ObserverModel, a: int, b: int) -> dict[str, Any]:
    """The velocity bands of the standstill margin of samples ``[a, b)``: for velocities
    derived from the positions, the position noise through the derivative filter
    (:func:`~dynid.observer.friction.derived_velocity_bands`); none otherwise (estimated
    on the velocities)."""
    if not prep.log.dq_derived or model.friction is None:
        return {}
    t, q = prep.log.t[a:b], prep.log.q[a:b]
    return {
        "bands": derived_velocity_bands(model.friction, t, q, prep.cutoff_hz),
        "derived": True,
    }


def _rechunked(
    blocks: Iterator[tuple[int, NDArray[np.float64]]], size: int
) -> Iterator[NDArray[np.float64]]:
    """Consecutive blocks ``(first sample, array)`` cut again into arrays of ``size``
    samples (the last shorter): the std's blocks as the observer's."""
    pending: list[NDArray[np.float64]] = []
    have = 0
    for _, x in blocks:
        pending.append(x)
        have += x.shape[0]
        while have >= size:
            cat = np.concatenate(pending)
            yield cat[:size]
            pending, have = [cat[size:]], cat.shape[0] - size
    if have:
        yield np.concatenate(pending)


#: Samples the observer runs on at a time (its state carried from block to block).
OBSERVE_BLOCK = 1 << 16


def _piece_velocities(log: TorqueLog, starts: list[int], cutoff_hz: float) -> NDArray[np.float64]:
    """The velocities the observer runs on: the log's, or, for a log of positions only,
    derived from the positions of each piece on its own (never across a gap) at
    ``cutoff_hz`` [Hz]."""
    if not log.dq_derived:
        return np.asarray(log.dq)
    dq = np.array(log.dq)
    for a, b in zip(starts, [*starts[1:], log.t.shape[0]], strict=True):
        try:
            dq[a:b] = filtered_derivative(log.t[a:b], log.q[a:b], cutoff_hz)
        except DataError:  # too short to filter: its span is not observed
            dq[a:b] = np.nan
    return dq


def _observed_spans(
    path: Path,
    log: TorqueLog,
    starts: list[int],
    trim_s: float = 0.0,
    cutoff_hz: float = DERIVED_CUTOFF_HZ,
) -> list[tuple[int, int]]:
    """The samples ``[a, b)`` the observer runs on: every piece without its first and
    last ``trim_s`` seconds (the torques' delay: states read that much earlier there are
    extrapolated, as identify drops them); for a log of positions only, also without the
    first and last ``2 / cut-off`` seconds, where the derived velocities carry the
    low-pass's transient (a note says so; their residual is NaN)."""
    ends = [*starts[1:], log.t.shape[0]]
    if not log.dq_derived and trim_s == 0.0:
        return list(zip(starts, ends, strict=True))
    edge = trim_s + (edge_seconds(cutoff_hz) if log.dq_derived else 0.0)
    spans = []
    for a, b in zip(starts, ends, strict=True):
        t = log.t[a:b]
        inside = np.flatnonzero((t >= t[0] + edge) & (t <= t[-1] - edge))
        if inside.size > 1:
            spans.append((a + int(inside[0]), a + int(inside[-1]) + 1))
    if not log.dq_derived:
        return spans
    warnings.warn(
        f"{path.name}: velocities derived from the positions of each piece: the first and "
        f"last {edge:g} s of each piece (the low-pass's transient) are not observed (NaN "
        "residuals)"
        + ("" if spans else "; no piece is long enough: nothing is observed")
        + "; the low-pass is zero-phase (it sees ahead), so detection delays are shorter "
        "than an online observer's",
        DynidWarning,
        stacklevel=caller_level(),
    )
    return spans


def _pieces(path: Path, log: TorqueLog, max_gap: float | None) -> list[int]:
    """First sample of each piece the observer runs on (module docstring), with a
    warning of the cuts (file and times). Rows dropped for NaN or inf are bridged where
    the step they leave is within the gap rule, as ``identify`` bridges them (one NaN row
    inside a push split its event in two; on a log of positions only each restart also
    left 0.2 s unobserved); a longer step is a gap like any other."""
    c = log.cleaning
    dt = np.diff(log.t)
    limit = max_gap
    if limit is None:
        limit = default_max_gap(float(np.median(dt)) if dt.size else 1.0)
    starts = [int(k) for k in pieces(log.t, limit)]
    if len(starts) > 1:
        at = said_times([log.t[k] for k in starts[1:]], float(log.t[0]), shown=5)
        after = np.searchsorted(log.t, np.asarray(c.invalid_after, dtype=np.float64), side="right")
        why = f"gaps longer than {limit:.3g} s" + (
            " (some where rows were dropped for NaN/inf)"
            if np.intersect1d(after, starts[1:]).size
            else ""
        )
        warnings.warn(
            f"{path.name}: cut at {why}: the observer starts again at {at} (no event spans a cut)",
            DynidWarning,
            stacklevel=caller_level(),
        )
    return starts


def _cut_at_jumps(
    path: Path, log: TorqueLog, dq: NDArray[np.float64], starts: list[int]
) -> list[int]:
    """The pieces cut again where positions jump more than the velocities ``dq`` explain
    (:func:`~dynid.observer.pieces.position_jumps`) over one regular time step (a stretch
    of samples lost without a gap in the stamps, an encoder glitch), with a warning naming
    the file, the joints and the times: the observer starts again there, so that no event
    is made of the jump (a lost stretch of 0.2 s was a 'collision' on every joint). A
    glitch's jump back is found in the next pass (at most three). A jump across a gap
    that ``max_gap`` (``--max-gap``) bridges beyond the default
    (:func:`~dynid.identification.log.default_max_gap`) is warned about only (bridging was
    asked for); across a shorter step (a sample or two lost, which the default bridges)
    it is cut like any other: a Z1 log that lost 0.3 s in one 4 ms step made a collision
    on every joint there. The stamps' jitter the log was read with widens each step's
    allowance with its speed: a UR5 log at 125 Hz with stamps jittered by 0.2 ms was cut
    12 times on fast motion before."""
    dt = np.diff(log.t)
    # steps longer than the default limit lie inside a piece only when max_gap bridges them
    bridge = default_max_gap(float(np.median(dt))) if dt.size else np.inf
    jitter = log_jitter(log.cleaning)  # a step's share of the stamps' jitter is no jump
    found: list[PositionJump] = []
    bridged: list[PositionJump] = []
    cut = list(starts)
    for _ in range(3):
        jumps = [
            x for x in position_jumps(log.t, log.q, dq, cut, jitter) if x not in found + bridged
        ]
        at: set[int] = set()
        for x in jumps:
            k = int(np.searchsorted(log.t, x.t))
            if k > 0 and log.t[k] - log.t[k - 1] > bridge:
                bridged.append(x)
            elif k not in cut:
                found.append(x)
                at.add(k)
        if not at:
            break
        cut = sorted(set(cut) | at)
    for jumps, what in (
        (
            found,
            "samples lost without a gap in the time stamps, or an encoder glitch; the "
            "observer starts again after each jump (no event spans one)",
        ),
        (bridged, "across a gap bridged by --max-gap: the residual after it is not to be trusted"),
    ):
        if not jumps:
            continue
        jumps.sort(key=lambda x: (x.t, x.joint))
        listed = ", ".join(
            f"joint {x.joint + 1} by {x.size:+.3g} at t = {stamp_text(x.t)} s" for x in jumps[:3]
        )
        more = f" and {len(jumps) - 3} more" if len(jumps) > 3 else ""
        warnings.warn(
            f"{path.name}: position jumps more than the recorded velocity explains "
            f"({listed}{more}): {what}",
            DynidWarning,
            stacklevel=caller_level(),
        )
    return cut
