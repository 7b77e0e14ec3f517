"""Detection on one log a block of samples at a time (``dynid observe --thresholds``).

The observer runs over the log's pieces a block at a time
(:func:`~dynid.workflows.observe_logs.observed_rows`, its state carried), and each block
goes at once to the events (:class:`~dynid.observer.events.EventDetector`, the event open
at a block's end carried), to the residual table of a ``sink`` (written a block at a
time), to the wrench at ``frame`` (:func:`observed_wrench`: NaN where the observer did
not run) and to running statistics (the largest residual, the
error against the true external torques ``tau_ext`` of a simulated log, the largest
standstill margin): a long log is detected with one block's temporaries. The
full-length series are kept only when asked (``keep_series``, the Python API); a figure
gets every k-th sample of the residual, its thresholds and the true torques
(``figure_points``: the samples the figure draws).
"""

from __future__ import annotations

import warnings
from collections.abc import Callable, Sequence
from contextlib import AbstractContextManager, nullcontext
from dataclasses import dataclass, replace
from pathlib import Path
from typing import Any, Protocol

import numpy as np
from numpy.typing import NDArray

from .. import _checks
from .._checks import caller_level
from ..exceptions import DataError, DynidWarning
from ..exceptions import in_file as about_file
from ..io.columns import ColumnMap, load_external_torques, load_label_column
from ..observer.carried_load import (
    MIN_LOAD_S,
    CarriedLoad,
    LoadSamples,
    LoadTorque,
    at_load_edge,
    carried_loads,
    load_events,
)
from ..observer.events import ContactEvent, DroppedCrossing, EventDetector, time_slack
from ..observer.friction import velocity_bands
from ..observer.missed_reason import LabelledSamples, explained, interval_rows
from ..observer.model import ObserverModel
from ..observer.residual import ObserverOptions
from ..observer.rest_margin import at_rest
from ..observer.results import FigureSeries, LogObservation
from ..observer.scoring import (
    DEFAULT_TOLERANCE_S,
    TRUTH_LEVEL,
    ContactScore,
    interval_peaks,
    label_intervals,
    lead_for,
    score_events,
    truth_flags,
)
from ..observer.sign import TorqueSign, opposite_finding
from ..observer.thresholds import Thresholds, threshold_series
from ..observer.trust import QuietResidual, guard_s, quiet_residual, sample_ratio
from ..observer.unmodelled import FrictionTally
from ..observer.unmodelled_load import LoadTally
from ..observer.wrench import FULL, WrenchEstimate, WrenchKind, external_wrench, wrench_rank
from ..observer.wrench_fit import (
    force_peaks,
    force_torques,
    off_frame_warning,
    unexplained_shares,
)
from ..signals import filtered_derivative
from .data_files import in_file
from .observe_logs import ObservedBlock, PreparedLog, Series, observed_rows, recording_note

__all__ = [
    "Labels",
    "ResidualSink",
    "contact_labels",
    "counted_events",
    "damped_shares",
    "detected_log",
    "observed_wrench",
    "scored",
    "true_torques",
]


@dataclass(frozen=True, slots=True, eq=False)
class Labels:
    """A log's contact labels: ``source`` (``column 'collision'``) and ``flags`` (N,),
    one per row of the cleaned log, nonzero in contact (NaN: no label)."""

    source: str
    flags: NDArray[np.float64]


class ResidualSink(Protocol):
    """Where the residual tables go while the logs are observed
    (:class:`dynid.io.observer_files.ResidualTables`)."""

    def table(
        self,
        paths: Sequence[Path],
        index: int,
        rows: int,
        n: int,
        frame: str | None,
        kind: WrenchKind = FULL,
        loads: Sequence[CarriedLoad] = (),
        unit: str = "N m",
    ) -> AbstractContextManager[Callable[..., None]]:
        """A writer ``put(t, r, wrench, damped)`` of log ``index`` of ``paths`` (``rows``
        samples, ``n`` joints, the estimate ``kind`` at ``frame`` or none, the carried
        ``loads`` whose torque the residual lacks, the residual's ``unit`` said per joint
        kind: :func:`~dynid.model.units.unit_said`), called for consecutive blocks of
        samples."""
        ...


def true_torques(
    prep: PreparedLog, model: ObserverModel, columns: ColumnMap | None
) -> NDArray | None:
    """The external torques ``tau_ext`` (N, n) [N m] stored beside a log, one per row of
    the cleaned log: the columns ``columns`` maps ``tau_ext`` to, else dynid's
    ``tau_ext1..n`` (``dynid simulate --contact``) (:func:`~dynid.io.columns.
    load_external_torques`), taken as the truth the residual is scored against; rows
    dropped while reading (``--drop-invalid``) are matched by their times, as the labels
    are (:func:`contact_labels`); or None (none stored).

    Raises
    ------
    DataError
        A ``tau_ext`` mapped that the log lacks.

    Warns
    -----
    DynidWarning
        True torques whose times are not the log's: no score and no error against them.
    """
    path, log_t = prep.path, prep.log.t
    if path.suffix.lower() not in (".csv", ".npz"):
        return None
    found = load_external_torques(path, columns, model.n)
    if found is None:
        return None
    _, t, ext = found
    if ext.shape[0] == log_t.shape[0]:
        return ext
    rows = None if t is None or t.shape[0] != ext.shape[0] else _stored_rows(t, log_t)
    if rows is None:
        warnings.warn(
            f"{path.name}: the true external torques tau_ext ({ext.shape[0]} rows) do not "
            f"align with the {log_t.shape[0]} rows kept: no score and no RMS r - tau_ext "
            "against them",
            DynidWarning,
            stacklevel=caller_level(),
        )
        return None
    return ext[rows]


def _stored_rows(t: NDArray, log_t: NDArray) -> NDArray[np.intp] | None:
    """The rows of a file's times ``t`` (N0,) [s] as stored (NaN kept) at the cleaned
    log's times ``log_t`` (N,) [s], or None where some time of the log is not stored."""
    (ok,) = np.nonzero(np.isfinite(t))
    if ok.size == 0:
        return None
    k = np.clip(np.searchsorted(t[ok], log_t), 0, ok.size - 1)
    return ok[k] if np.array_equal(t[ok][k], log_t) else None


def contact_labels(prep: PreparedLog, columns: ColumnMap | None) -> Labels | None:
    """The contact labels of a log, one per row of its cleaned log (N,), nonzero in
    contact (:func:`~dynid.io.columns.load_label_column`: the column ``columns`` maps
    ``label`` to, else ``collision``, ``contact`` or ``label``), with the words of their
    source (``column 'collision'``), or None when the log has none. Rows dropped while
    reading (``--drop-invalid``) are matched by their times.

    Raises
    ------
    DataError
        A ``label`` mapped that the log lacks; labels whose times are not the log's.
    """
    found = load_label_column(prep.path, columns)
    if found is None:
        return None
    name, t, flags = found
    log_t = prep.log.t
    if t.shape != log_t.shape or not np.array_equal(t, log_t):
        rows = _stored_rows(t, log_t)
        if rows is None:
            ok = int(np.count_nonzero(np.isfinite(t)))
            raise DataError(
                f"the times of label {name!r} are not the log's ({ok} rows against "
                f"{log_t.size}); hint: one label per row of the log"
            )
        flags = flags[rows]
    return Labels(f"column {name!r}", _checks.frozen(np.asarray(flags, dtype=np.float64)))


def _detected_once(
    prep: PreparedLog,
    model: ObserverModel,
    columns: ColumnMap | None,
    thresholds: Thresholds,
    options: ObserverOptions,
    *,
    wants: tuple[bool, bool],
    merge_s: float,
    min_duration_s: float,
    frame: str | None,
    keep_series: bool,
    figure_points: int | None = None,
    table: AbstractContextManager[Callable[..., None] | None] | None = None,
    kind: WrenchKind = FULL,
    labels: Labels | None = None,
    tolerance_s: float = DEFAULT_TOLERANCE_S,
    unmodelled: FrictionTally | None = None,
    load: LoadTally | None = None,
    carried: Sequence[CarriedLoad] = (),
    samples: LoadSamples | None = None,
    motion: tuple[NDArray, NDArray, NDArray, NDArray] | None = None,
    picks: Sequence[ContactEvent] = (),
) -> LogObservation:
    """The events of one prepared log (module docstring; ``merge_s`` and ``min_duration_s``
    of :class:`~dynid.observer.events.EventDetector`), ``wants`` the residual's std and
    the standstill margin, ``table`` the sink's writer of its residual table (or none);
    ``figure_points``: keep every k-th sample (at most that many) for a figure; ``kind``:
    the wrench or the force alone at ``frame``; the events scored against ``labels``
    (:func:`contact_labels`), else against the true torques stored beside the log (in
    contact above :data:`~dynid.observer.scoring.TRUTH_LEVEL`), with ``tolerance_s``
    (:func:`scored`); ``unmodelled`` (a model without friction) and ``load`` (the fit of
    a load at the flange) are fed the samples under the contact threshold; ``carried``:
    loads whose torque is taken from the residual first; ``samples`` keeps the samples
    over the threshold for their fit; ``motion`` the log's accelerations beside
    (:func:`_load_motion`), for their inertia; ``picks``: the loads' own events (level
    ``load``, :func:`~dynid.observer.carried_load.load_events`), joined to the events and
    scored with them (no wrench fit: NaN unexplained)."""
    log, n = prep.log, model.n
    starts = tuple(a for a, _ in prep.spans)
    period = _period(log.t)
    det = EventDetector(thresholds, merge_s=merge_s, min_duration_s=min_duration_s,
                        restarts=starts, sample_period_s=period)  # fmt: skip
    keep = Series.new(prep, n, *wants) if keep_series else None
    ext = in_file(prep.path, lambda: true_torques(prep, model, columns))
    stats, sign = _Running(n), TorqueSign(n)
    strided = None if not figure_points else _Strided(log.t.shape[0], figure_points, thresholds)
    events: list[ContactEvent] = []
    wrenches: list[WrenchEstimate] = []
    fits = None if frame is None else _FrameFit(model, frame, log.t.shape[0])
    seen = model.friction
    if unmodelled is not None:
        unmodelled.new_log()
    labelled = _labelled_samples(labels, ext, n)
    less = LoadTorque(model.robot, carried, options.gains(n)) if carried else None
    rho = np.full(log.t.shape[0], np.nan)  # max_j |r_j| / contact_j: outside events, trust
    with about_file(prep.path.name), table or nullcontext(None) as put:
        for blk in _less_load(
            prep, observed_rows(prep, model, options, *wants, thresholds.rest), less, motion
        ):
            a, b = blk.a, blk.a + blk.r.shape[0]
            if blk.friction is not None and blk.friction is not model.friction:
                seen = blk.friction  # banded for the velocity noise (a note says so)
            levels = threshold_series(thresholds, b - a, blk.std, blk.margin)  # built once
            events += det.feed(log.t[a:b], blk.r, levels=levels)
            rho[a:b] = sample_ratio(blk.r, levels[0])
            w = None if frame is None else observed_wrench(model, log.q[a:b], blk.r, frame, kind)
            if put is not None:
                put(log.t[a:b], blk.r, *((None, None) if w is None else (w.wrench, w.damped)))
            if w is not None and fits is not None:
                fits.add(a, log.q[a:b], blk.r, w)
            if w is not None and keep is not None:
                wrenches.append(w)
            stats.add(blk.r, blk.margin, None if ext is None else ext[a:b])
            sign.add(log.tau[a:b], blk.r)
            _tallied(prep, levels[0], blk, unmodelled, load, samples, labelled)
            if keep is not None:
                keep.put(blk)
            if strided is not None:
                strided.add(log.t, blk, levels, None if ext is None else ext[a:b])
        events += det.finish()
    events = [e for e in events if not at_load_edge(e.start, e.end, carried)]
    if (opposite := opposite_finding(sign, model.robot.joint_names)) is not None:
        warnings.warn(  # a whole-log "collision" on each such joint follows
            f"{prep.path.name}: {opposite}", DynidWarning, stacklevel=caller_level()
        )
    unexplained = None
    if frame is not None and fits is not None:
        unexplained = _off_frame(prep, model, frame, kind, events, fits, thresholds)
    events, unexplained = _with_picks(events, unexplained, picks)
    score = _log_score(
        prep, model, thresholds, events, labels, ext, tolerance_s, labelled, det.dropped
    )
    return LogObservation(
        prep.path,
        log.t,
        None if keep is None else keep.r,
        None if keep is None else keep.std,
        events,
        _joined(wrenches, frame) if keep is not None else None,
        ext if keep is not None else None,
        None if keep is None else keep.margin,
        starts,
        stats.margin,
        peak=stats.peak,
        truth_rms=stats.truth(),
        figure=None if strided is None else strided.series(),
        peak_ratio=det.largest_ratio,
        friction=None if seen is model.friction else seen,
        score=score,
        dropped=det.dropped,
        dropped_count=det.dropped_count,
        damped=None if fits is None else damped_shares(log.t, events, fits.damped),
        unexplained=unexplained,
        loads=tuple(carried),
        recording=recording_note(prep),
        quiet=_quiet(log.t, rho, events, score, guard_s(options.gains(n)), period),
    )


def _period(t: NDArray) -> float | None:
    """The median positive step of ``t`` (N,) [s]; None: fewer than two distinct
    samples."""
    steps = np.diff(t)
    return float(np.median(steps[steps > 0])) if np.any(steps > 0) else None


def _quiet(
    t: NDArray,
    rho: NDArray,
    events: Sequence[ContactEvent],
    score: ContactScore | None,
    guard: float,
    period: float | None,
) -> QuietResidual:
    """The residual outside the ``events`` and the labelled contacts of ``score`` (from
    its lead before each to its tolerance after), each widened by ``guard`` [s]: the
    histogram of ``rho`` (N,) at ``t`` (N,) [s] (:func:`~dynid.observer.trust.quiet_residual`)
    a trust verdict reads."""
    spans = [(e.start, e.end) for e in events]
    if score is not None:
        spans += [(a - score.lead_s, b + score.tolerance_s) for a, b in score.intervals]
    return quiet_residual(t, rho, spans, guard, step=period)


def detected_log(
    prep: PreparedLog,
    model: ObserverModel,
    columns: ColumnMap | None,
    thresholds: Thresholds,
    options: ObserverOptions,
    *,
    table: AbstractContextManager[Callable[..., None] | None] | None = None,
    retable: Callable[..., AbstractContextManager[Callable[..., None] | None] | None] | None = None,
    loads: bool = True,
    **kw: Any,
) -> LogObservation:
    """The events of one prepared log (:func:`_detected_once`, its keywords), and where
    an event is a load carried at the flange (:mod:`~dynid.observer.carried_load`), the
    detection run again on the residual without the load's torque: its events inside the
    load's window are the contacts on top of it, and the load is kept beside them
    (:attr:`~dynid.observer.results.LogObservation.loads`); the load's own event (its
    pick: an external force, a weight or a steady push along gravity alike) is kept with
    the level ``load`` and scored as any event. ``retable`` opens the residual table
    again for that second run (``retable(loads=...)``: its header names the loads);
    ``loads`` False (``--no-loads``): no event is read as a load; those that fit one are
    kept as :attr:`~dynid.observer.results.LogObservation.unread_loads` (a note names
    them)."""
    log = prep.log
    steps = np.diff(log.t)
    period = float(np.median(steps[steps > 0])) if np.any(steps > 0) else None
    samples = LoadSamples(period)
    with warnings.catch_warnings(record=True) as said:
        warnings.simplefilter("always")
        first = _detected_once(
            prep, model, columns, thresholds, options, table=table, samples=samples, **kw
        )
    if not log.t.shape[0]:
        _said_again(said)
        return first
    span = (float(log.t[0]), float(log.t[-1]))
    events = [(e.start, e.end) for e in first.events]
    long = any(b - a >= MIN_LOAD_S for a, b in events)
    motion = _load_motion(prep) if long else None
    found = carried_loads(model.robot, samples, events, options.gains(model.n), span, motion)
    if not found or not loads:  # --no-loads: the loads that fit are named, not applied
        _said_again(said)
        return replace(first, unread_loads=tuple(found)) if found else first
    kw = {**kw, "unmodelled": None, "load": None, "motion": motion}  # fed once, by the first
    kw["picks"] = load_events(found, first.events)
    again = None if retable is None else retable(loads=found)  # its header names them
    return _detected_once(
        prep, model, columns, thresholds, options, table=again, carried=found, **kw
    )


def _with_picks(
    events: list[ContactEvent], unexplained: Any, picks: Sequence[ContactEvent]
) -> tuple[list[ContactEvent], Any]:
    """The ``events`` with the loads' events ``picks`` joined in time order, and their
    ``unexplained`` shares (None, or one per event) with NaN for the picks."""
    if not picks:
        return events, unexplained
    both = [(e, u) for e, u in zip(events, unexplained or [None] * len(events), strict=True)]
    both += [(p, float("nan")) for p in picks]
    both.sort(key=lambda x: x[0].start)
    joined = [e for e, _ in both]
    return joined, None if unexplained is None else tuple(u for _, u in both)


def _said_again(said: list[warnings.WarningMessage]) -> None:
    """The warnings of a run held back, said (the run's answer stands)."""
    for w in said:
        warnings.warn_explicit(w.message, w.category, w.filename, w.lineno)


def _load_motion(prep: PreparedLog) -> tuple[NDArray, NDArray, NDArray, NDArray]:
    """The log's times [s], positions [rad], the observer's velocities [rad/s] and their
    accelerations [rad/s^2] for a carried load's inertia: each piece's velocities
    low-passed at the observer's cut-off (:attr:`PreparedLog.cutoff_hz`, as a log without
    velocities has them derived) and differentiated, on its own (NaN
    where a piece is too short to filter: none of its samples is fitted)."""
    log = prep.log
    ddq = np.full_like(prep.dq, np.nan)
    for a, b in prep.spans:
        try:
            ddq[a:b] = filtered_derivative(log.t[a:b], prep.dq[a:b], prep.cutoff_hz)
        except DataError:
            pass
    return log.t, log.q, prep.dq, np.nan_to_num(ddq)


def _less_load(
    prep: PreparedLog,
    blocks: Any,
    less: LoadTorque | None,
    motion: tuple[NDArray, NDArray, NDArray, NDArray] | None = None,
) -> Any:
    """The observed ``blocks`` with the carried loads' torque ``less`` taken from their
    residual (the lag restarted at each piece of the log); ``motion``
    (:func:`_load_motion`) gives a rigid load's inertia."""
    starts = {a for a, _ in prep.spans}
    for blk in blocks:
        if less is None:
            yield blk
            continue
        if blk.a in starts:
            less.restart()
        b = blk.a + blk.r.shape[0]
        t, q = prep.log.t[blk.a : b], prep.log.q[blk.a : b]
        dq, ddq = (None, None) if motion is None else (motion[2][blk.a : b], motion[3][blk.a : b])
        yield replace(blk, r=blk.r - less.block(t, q, dq, ddq))


def _tallied(
    prep: PreparedLog,
    contact: NDArray[np.float64],
    blk: ObservedBlock,
    unmodelled: FrictionTally | None,
    load: LoadTally | None,
    samples: LoadSamples | None,
    labelled: LabelledSamples | None = None,
) -> None:
    """One block fed to the tallies off contacts (``unmodelled``: the friction the model
    misses; ``load``: a load at the flange it misses) and its samples over the threshold
    to ``samples`` (a carried load's fit); ``contact`` (m, n) [N m] the block's contact
    threshold (:func:`~dynid.observer.thresholds.threshold_series`, NaN where not
    observed); its residual and that threshold over labelled contacts to ``labelled``
    (why one was missed)."""
    if labelled is not None:
        labelled.add(blk.a, blk.r, contact)
    if unmodelled is None and load is None and samples is None:
        return
    log = prep.log
    a, b = blk.a, blk.a + blk.r.shape[0]
    under = ~(np.abs(blk.r) > contact)
    if unmodelled is not None:  # the friction the model misses
        unmodelled.add(log.t[a:b], prep.dq[a:b], blk.r, under)
    if load is not None:  # a load at the flange the model misses
        load.add(log.q[a:b], blk.r, contact)
    if samples is not None:
        samples.add(log.t[a:b], log.q[a:b], blk.r, contact)


class _FrameFit:
    """Per sample of a log of ``N``, what the wrench at ``frame`` leaves and says: the
    flag ``damped`` (N,), ``left`` ``|r - J^T w|^2`` (N,) [N^2 m^2], the residual ``rows``
    (N, n) [N m], the force part's torques ``pushed`` ``J_v^T f`` (N, n) [N m]
    (:func:`~dynid.observer.wrench_fit.force_torques`) and the components ``determined``
    (NaN where the observer did not run)."""

    def __init__(self, model: ObserverModel, frame: str, N: int) -> None:
        self.robot, self.frame, n = model.robot, frame, model.n
        self.damped = np.zeros(N, dtype=bool)
        self.left = np.full(N, np.nan)
        self.rows = np.full((N, n), np.nan)
        self.pushed = np.full((N, n), np.nan)
        self.determined = n

    def add(self, a: int, q: NDArray, r: NDArray, w: WrenchEstimate) -> None:
        """The block from sample ``a``: positions ``q`` (m, n) [rad], residual ``r``
        (m, n) [N m] and its estimate ``w``."""
        b = a + r.shape[0]
        self.damped[a:b] = w.damped
        self.left[a:b] = np.nan if w.unexplained is None else w.unexplained
        self.rows[a:b], self.determined = r, w.determined
        self.pushed[a:b] = force_torques(self.robot, q, w.wrench, self.frame)


def _off_frame(
    prep: PreparedLog,
    model: ObserverModel,
    frame: str,
    kind: Any,
    events: Sequence[ContactEvent],
    fits: _FrameFit,
    thresholds: Thresholds,
) -> Any:
    """Each event's share of the residual the wrench at ``frame`` leaves unexplained
    (:func:`unexplained_shares`), with the warning of contacts on a link before the frame
    (:func:`off_frame_warning`) said; ``fits``: the estimate's series over the log."""
    t, contact = prep.log.t, thresholds.contact
    left, rows, pushed = fits.left, fits.rows, fits.pushed
    shares, over = unexplained_shares(t, events, left, rows, contact, fits.determined)
    robot = model.robot
    said = off_frame_warning(
        prep.path.name, frame, kind.noun, events, shares, over, thresholds.contact,
        robot.joint_names, robot.link_names, int(robot.frame(frame).link),
        force_peaks(t, events, pushed),
    )  # fmt: skip
    if said is not None:
        warnings.warn(said, DynidWarning, stacklevel=caller_level())
    return shares


def damped_shares(
    t: NDArray, events: Sequence[ContactEvent], damped: NDArray[np.bool_]
) -> tuple[float, ...]:
    """The share (0 to 1) of each event's samples, ``start`` to ``end`` [s] of the log's
    times ``t`` (N,), where the wrench estimate was ``damped`` (N,) (near a singular
    configuration: unreliable there)."""
    out = []
    for e in events:
        a, b = np.searchsorted(t, e.start, "left"), np.searchsorted(t, e.end, "right")
        out.append(float(np.mean(damped[a:b])) if b > a else 0.0)
    return tuple(out)


def counted_events(
    prep: PreparedLog,
    model: ObserverModel,
    thresholds: Thresholds,
    options: ObserverOptions,
    wants: tuple[bool, bool],
) -> tuple[int, QuietResidual]:
    """The events the default rules raise on one prepared log against ``thresholds`` and
    the residual's histogram against them, the observer run again a block at a time
    (``wants`` its std and standstill margin): what
    :func:`~dynid.observer.calibration_check.calibration_false_alarms` and
    :func:`~dynid.observer.calibration_check.calibration_quiet` read on a kept series,
    without keeping one (a calibration without figures)."""
    det = EventDetector(thresholds)
    count, quiet, step = 0, QuietResidual.empty(), _period(prep.log.t) or 0.0
    with about_file(prep.path.name):
        for blk in observed_rows(prep, model, options, *wants, thresholds.rest):
            a, b = blk.a, blk.a + blk.r.shape[0]
            levels = threshold_series(thresholds, b - a, blk.std, blk.margin)
            count += len(det.feed(prep.log.t[a:b], blk.r, levels=levels))
            t = prep.log.t[a:b]
            quiet = quiet.plus(quiet_residual(t, sample_ratio(blk.r, levels[0]), step=step))
        return count + len(det.finish()), quiet


def scored(
    t: NDArray,
    events: Sequence[ContactEvent],
    labels: Labels | None,
    ext: NDArray | None,
    tolerance_s: float = DEFAULT_TOLERANCE_S,
    *,
    look_ahead: bool = False,
) -> ContactScore | None:
    """The ``events`` of a log at times ``t`` (N,) [s] scored against its ``labels``, else
    against the true external torques ``ext`` (N, n) [N m] (in contact where some joint
    exceeds :data:`~dynid.observer.scoring.TRUTH_LEVEL`); the missed contacts' peaks known
    wherever the true torques are, the labels' contacts too; None with neither
    (:mod:`dynid.observer.scoring`, the lead of :func:`~dynid.observer.scoring.lead_for`:
    ``tolerance_s`` on both sides of a label column's contacts, made by hand, a few
    samples before the true torques' exact ones);
    ``look_ahead``: the velocities came from a zero-phase
    low-pass (:attr:`~dynid.observer.scoring.ContactScore.look_ahead`)."""
    if labels is not None:  # made by hand: off either way, the tolerance on both sides
        intervals, source = label_intervals(t, labels.flags), labels.source
        peaks = None if ext is None else interval_peaks(t, ext, intervals)
        lead = lead_for(t, tolerance_s)
    elif ext is not None:  # the true contacts: the exact lead
        intervals = label_intervals(t, truth_flags(ext))
        source = f"tau_ext > {TRUTH_LEVEL:g} N m"
        peaks = interval_peaks(t, ext, intervals)
        lead = lead_for(t)
    else:
        return None
    ev = np.array([(e.start, e.end) for e in events], dtype=np.float64).reshape(-1, 2)
    span = (float(t[0]), float(t[-1])) if t.shape[0] else (0.0, 0.0)
    return score_events(
        ev,
        intervals,
        span,
        tolerance_s=tolerance_s,
        peaks=peaks,
        source=source,
        look_ahead=look_ahead,
        lead_s=lead,
        slack_s=time_slack(t),
    )


def _labelled_samples(labels: Labels | None, ext: NDArray | None, n: int) -> LabelledSamples | None:
    """The store of the samples of a log's labelled contacts (its ``labels``, else the
    true torques ``ext`` over :data:`~dynid.observer.scoring.TRUTH_LEVEL`: the contacts
    :func:`scored` reads) for the reasons of the missed ones; None with neither."""
    if labels is not None:
        return LabelledSamples(labels.flags, n)
    return None if ext is None else LabelledSamples(truth_flags(ext), n)


def _log_score(
    prep: PreparedLog,
    model: ObserverModel,
    thresholds: Thresholds,
    events: Sequence[ContactEvent],
    labels: Labels | None,
    ext: NDArray | None,
    tolerance_s: float,
    labelled: LabelledSamples | None,
    dropped: Sequence[DroppedCrossing] = (),
) -> ContactScore | None:
    """The score of one log's ``events`` (:func:`scored`) with the reasons of its missed
    contacts (:func:`with_reasons`)."""
    log = prep.log
    sc = scored(log.t, events, labels, ext, tolerance_s, look_ahead=log.dq_derived)
    return with_reasons(sc, log.t, prep.dq, model, thresholds, ext, labelled, dropped)


def with_reasons(
    score: ContactScore | None,
    t: NDArray,
    dq: NDArray,
    model: ObserverModel,
    thresholds: Thresholds,
    ext: NDArray | None,
    labelled: LabelledSamples | None,
    dropped: Sequence[DroppedCrossing] = (),
) -> ContactScore | None:
    """``score`` with the reason of each missed contact (:mod:`dynid.observer.missed_reason`)
    of a log at times ``t`` (N,) [s] with velocities ``dq`` (N, n) [rad/s]: a crossing
    the detection ``dropped`` where an event would have detected it, else its torque, the
    true external torques ``ext`` (N, n) [N m] or the residual, against the contact
    threshold in force at each of its samples as the detection applied it (kept in
    ``labelled``), each joint standing still where inside its friction's standstill band
    (:func:`~dynid.observer.rest_margin.at_rest`; with thresholds that add the standstill
    margin); unchanged with no missed contact or no samples kept."""
    if score is None or not score.missed or labelled is None:
        return score
    window = (score.lead_s, score.tolerance_s)
    bands = None
    if thresholds.standstill and model.friction is not None:
        bands = velocity_bands(model.friction, dq)
    out = []
    for m in score.missed:
        i, j = interval_rows(t, m.start, m.end)
        rows = labelled.samples(i, j)
        if rows.size == 0:
            out.append(m)
            continue
        size, level = labelled.rows(i, j)
        if ext is not None:
            size = np.abs(ext[rows])
        still = np.zeros(level.shape, dtype=bool)
        if bands is not None and model.friction is not None:
            still = at_rest(model.friction, dq[rows], bands)
        out.append(
            explained(
                m,
                t[rows],
                size,
                level,
                still,
                true_torque=ext is not None,
                dropped=dropped,
                window=window,
            )  # fmt: skip
        )
    return replace(score, missed=tuple(out))


def observed_wrench(
    model: ObserverModel, q: NDArray, r: NDArray, frame: str, kind: WrenchKind = FULL
) -> WrenchEstimate:
    """The external wrench (or the force alone: ``kind``) at ``frame``
    (:func:`~dynid.observer.wrench.external_wrench`) of the samples the observer ran on;
    NaN wrench and ``sigma_min``, not flagged damped, where the residual ``r`` (m, n) is
    NaN (not observed: a log's unobserved edges)."""
    seen = np.all(np.isfinite(r), axis=1)
    if seen.all():
        return external_wrench(model.robot, q, r, frame, kind=kind)
    m = r.shape[0]
    wrench, smin = np.full((m, 6), np.nan), np.full(m, np.nan)
    damped, left = np.zeros(m, dtype=bool), np.full(m, np.nan)
    if seen.any():
        w = external_wrench(model.robot, q[seen], r[seen], frame, kind=kind)
        wrench[seen], smin[seen], damped[seen] = w.wrench, w.sigma_min, w.damped
        if w.unexplained is not None:
            left[seen] = w.unexplained
    k = wrench_rank(model.robot, frame, kind)
    return WrenchEstimate(frame, wrench, smin, damped, k, kind, left)


def _joined(blocks: list[WrenchEstimate], frame: str | None) -> WrenchEstimate | None:
    """The wrench of every block as one estimate."""
    if frame is None or not blocks:
        return None
    return WrenchEstimate(
        frame,
        np.concatenate([w.wrench for w in blocks]),
        np.concatenate([w.sigma_min for w in blocks]),
        np.concatenate([w.damped for w in blocks]),
        blocks[0].determined,
        blocks[0].kind,
        None
        if any(w.unexplained is None for w in blocks)
        else np.concatenate([w.unexplained for w in blocks if w.unexplained is not None]),
    )


class _Running:
    """Per joint over the blocks of a log: the largest ``|r|`` (NaN where never observed),
    the largest standstill margin, and the squared error against the true torques over
    the observed samples."""

    def __init__(self, n: int) -> None:
        self.peak = np.full(n, np.nan)
        self.margin = np.zeros(n)
        self.square, self.count = np.zeros(n), 0

    def add(self, r: NDArray, margin: NDArray | None, ext: NDArray | None) -> None:
        ran = np.all(np.isfinite(r), axis=1)
        if ran.any():
            self.peak = np.fmax(self.peak, np.max(np.abs(r[ran]), axis=0))
        if margin is not None and margin.shape[0]:
            np.maximum(self.margin, margin.max(axis=0), out=self.margin)
        if ext is not None:
            e = r - ext
            ok = np.all(np.isfinite(e), axis=1)
            self.square += np.sum(e[ok] ** 2, axis=0)
            self.count += int(ok.sum())

    def truth(self) -> Any:
        """RMS of the error against the true torques (n,) [N m], or None."""
        return np.sqrt(self.square / self.count) if self.count else None


class _Strided:
    """Every ``step``-th sample of a log of ``N`` (``step = ceil(N / points)``, the stride
    of :func:`~dynid.plots.observer.plot_residuals`) with its thresholds, a block at a
    time."""

    def __init__(self, N: int, points: int, thresholds: Thresholds) -> None:
        self.step = max(1, int(np.ceil(N / points)))
        self.thresholds = thresholds
        self.parts: list[tuple[NDArray, ...]] = []
        self.ext: list[NDArray] = []

    def add(
        self,
        t: NDArray,
        blk: ObservedBlock,
        levels: tuple[NDArray, NDArray],
        ext: NDArray | None,
    ) -> None:
        """One block with its contact and collision thresholds ``levels`` (each (m, n)
        [N m], :func:`~dynid.observer.thresholds.threshold_series`)."""
        a, m = blk.a, blk.r.shape[0]
        rows = np.arange(-a % self.step, m, self.step)  # the block's samples k*step
        r = blk.r[rows]
        seen = np.all(np.isfinite(r), axis=1)
        c, k = levels[0][rows], levels[1][rows]  # copies: fancy indexing
        c[~seen], k[~seen] = np.nan, np.nan
        self.parts.append((t[a + rows], r, c, k))
        if ext is not None:
            self.ext.append(ext[rows])

    def series(self) -> FigureSeries:
        if not self.parts:  # no sample
            e = np.zeros((0, self.thresholds.n))
            return FigureSeries(self.step, np.zeros(0), e, e, e, None)
        t, r, c, k = (np.concatenate(x) for x in zip(*self.parts, strict=True))
        ext = np.concatenate(self.ext) if self.ext else None
        return FigureSeries(self.step, t, r, c, k, ext)
