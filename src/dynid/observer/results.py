"""What an observation of logs gives: every log's residual and events, and the thresholds.

:class:`ObserveResult` is what :func:`dynid.workflows.observe.observe_files` returns and
what :func:`dynid.io.observer_files.save_observation` writes.
"""

from __future__ import annotations

import dataclasses
from dataclasses import dataclass
from pathlib import Path

import numpy as np
from numpy.typing import NDArray

from ..exceptions import DataError
from ..friction.model import FrictionModel, FrictionSum
from ..identification.motion_range import BEYOND
from .calibration_check import CalibrationCheck
from .carried_load import NO_LOADS, CarriedLoad, load_words, unread_load_words
from .detection import ContactEvent, Thresholds
from .events import DroppedCrossing
from .friction import banding_note
from .gain_noise import GainNoise
from .model import ObserverModel
from .motion_range import FASTER, beyond_joints, motion_hint
from .scoring import ContactScore, combined, early_by_chance, shifted_labels_note
from .thresholds import ModelFingerprint
from .trust import QuietResidual, TrustVerdict, trust_verdict
from .unmodelled import MOST_FLAGGED, UnmodelledFriction, no_friction_note
from .unmodelled_load import UnmodelledLoad, load_note
from .wrench import FULL, WrenchEstimate, WrenchKind, underdetermined_note

__all__ = [
    "MOST_FLAGGED_TIME",
    "NO_FRICTION",
    "FigureSeries",
    "LogObservation",
    "ObserveResult",
    "beyond_lines",
    "dropped_words",
    "flagged_words",
    "robot_friction_note",
]


@dataclass(frozen=True, slots=True, eq=False)
class FigureSeries:
    """Every ``step``-th sample of a log's residual, thresholds and true torques, kept
    for its figure when the series are not (detection a block at a time).

    Attributes
    ----------
    step : int
        Samples between two kept ones.
    t : ndarray, shape (M,)
        [s].
    r : ndarray, shape (M, n)
        Residual [N m] (NaN where not observed).
    contact, collision : ndarray, shape (M, n)
        The thresholds at those samples [N m] (NaN where not observed).
    tau_ext : ndarray, shape (M, n), or None
        The true external torques stored beside a simulated log.
    """

    step: int
    t: NDArray[np.float64]
    r: NDArray[np.float64]
    contact: NDArray[np.float64]
    collision: NDArray[np.float64]
    tau_ext: NDArray[np.float64] | None


@dataclass(frozen=True, slots=True, eq=False)
class LogObservation:
    """The residual of one log and what was found in it.

    Attributes
    ----------
    path : Path
    t : ndarray, shape (N,)
    r : ndarray, shape (N, n), or None
        Residual [N m]; None when no series was kept (a long log a block at a time:
        ``keep_series`` of :class:`~dynid.workflows.observe.ObserveOptions`).
    std : ndarray, shape (N, n), or None
        Its standard deviation from the model's uncertainty (when used).
    events : list of ContactEvent
        Empty when calibrating.
    wrench : WrenchEstimate or None
        At ``frame``, when one was given.
    tau_ext : ndarray, shape (N, n), or None
        The true external torques stored beside the log (a simulated contact).
    standstill : ndarray, shape (N, n), or None
        The lagged standstill margin of the model's friction
        (:func:`~dynid.observer.detection.standstill_series`), when the thresholds use it.
    restarts : tuple of int
        First sample of each piece the observer ran on (the log cut at its gaps).
    standstill_peak : ndarray, shape (n,), or None
        The largest standstill margin of each joint over the log [N m] (kept without the
        series).
    peak : ndarray, shape (n,), or None
        The largest ``|r|`` of each joint over the log [N m] (NaN: never observed), kept
        without the series.
    truth_rms : ndarray, shape (n,), or None
        :meth:`truth_error` computed while observing (kept without the series).
    peak_ratio : ndarray, shape (n,), or None
        The largest ``|r|`` over the contact threshold at the same sample of each joint
        (:attr:`~dynid.observer.events.EventDetector.largest_ratio`; NaN: never
        observed), when detecting.
    figure : FigureSeries or None
        Every few samples of the series for a figure (kept without the series).
    friction : FrictionModel, FrictionSum or None
        The friction the observer evaluated on this log when it is not the model's own:
        the model's banded for the log's velocity noise
        (:func:`~dynid.observer.friction.banded_if_narrow`); None: the model's own.
    score : ContactScore or None
        The events against the log's labelled contacts (a label column, or the true
        external torques of a simulated log: :mod:`~dynid.observer.scoring`); None: no
        label.
    dropped : tuple of DroppedCrossing
        Crossings over the contact threshold the minimum duration dropped (not contacts;
        :attr:`~dynid.observer.events.EventDetector.dropped`: those furthest over the
        threshold when there were more than
        :data:`~dynid.observer.events.MAX_DROPPED`), when detecting.
    dropped_count : int
        Every such crossing.
    damped : tuple of float or None
        Of a detection with a wrench estimated at a frame: the share (0 to 1) of each
        event's samples where the estimate was damped (near a singular configuration of
        the joints that move the frame: the wrench there is unreliable), in the order of
        ``events``; None: no wrench estimated.
    unexplained : tuple of float or None
        Of a detection with a wrench estimated at a frame: the share (0 to 1; NaN: no
        sample) of each event's ``|r|`` the estimate leaves unexplained,
        ``sqrt(sum |r - J^T w|^2 / sum |r|^2)``
        (:func:`~dynid.observer.wrench_fit.unexplained_shares`), in the order of
        ``events``; None: no wrench estimated.
    loads : tuple of CarriedLoad
        Loads carried at the flange over a long event (:mod:`~dynid.observer.carried_load`):
        each load's own event is in ``events`` with the level ``load`` (an external force,
        scored as any event); the other events and the residual are those of the
        detection run again without their torque.
    recording : str or None
        The log's stamps as ``identify`` and ``validate`` say them when jittered or
        missing samples of their grid (``rec4.csv: 1 piece, 10000 samples; stamps
        jittered, std 0.2 ms at a 2 ms period``); None: uniform.
    speed_max : ndarray, shape (n,), or None
        Each joint's largest speed over the observed samples [rad/s]
        (:func:`~dynid.observer.motion_range.log_speed_max`), compared with the
        identification's (:meth:`ObserveResult.beyond`); None: not measured.
    unread_loads : tuple of CarriedLoad
        Of a detection with the reading of loads off (``--no-loads``): the loads that fit
        the residual of a long event as the default reading fits them
        (:mod:`~dynid.observer.carried_load`), not applied: a note names them.
    quiet : QuietResidual or None
        Of a detection: the residual outside its events and labelled contacts against the
        contact threshold (:mod:`~dynid.observer.trust`), which the trust verdict reads;
        None: not read (a calibration).
    """

    path: Path
    t: NDArray[np.float64]
    r: NDArray[np.float64] | None
    std: NDArray[np.float64] | None
    events: list[ContactEvent]
    wrench: WrenchEstimate | None
    tau_ext: NDArray[np.float64] | None
    standstill: NDArray[np.float64] | None = None
    restarts: tuple[int, ...] = (0,)
    standstill_peak: NDArray[np.float64] | None = None
    peak: NDArray[np.float64] | None = None
    truth_rms: NDArray[np.float64] | None = None
    figure: FigureSeries | None = None
    peak_ratio: NDArray[np.float64] | None = None
    friction: FrictionModel | FrictionSum | None = None
    score: ContactScore | None = None
    dropped: tuple[DroppedCrossing, ...] = ()
    dropped_count: int = 0
    damped: tuple[float, ...] | None = None
    unexplained: tuple[float, ...] | None = None
    loads: tuple[CarriedLoad, ...] = ()
    recording: str | None = None
    speed_max: NDArray[np.float64] | None = None
    unread_loads: tuple[CarriedLoad, ...] = ()
    quiet: QuietResidual | None = None

    @property
    def series(self) -> NDArray[np.float64]:
        """The residual ``r`` (N, n) [N m].

        Raises
        ------
        DataError
            An observation that kept no series (``keep_series`` off).
        """
        if self.r is None:
            raise DataError(f"{self.path.name}: no residual series kept (keep_series off)")
        return self.r

    def flagged_seconds(self, *, loads: bool = True) -> float:
        """Time [s] the log's events cover: the length of the union of their ``[start,
        end]`` (a carried load's event holds the contacts on top of it); ``loads`` False:
        without the loads' events (level ``load``)."""
        spans = sorted((e.start, e.end) for e in self.events if loads or e.level != "load")
        total, reach = 0.0, -np.inf
        for a, b in spans:
            total += max(b - max(a, reach), 0.0)
            reach = max(reach, b)
        return float(total)

    def duration(self) -> float:
        """The log's duration [s], first to last sample (0 for fewer than two)."""
        return float(self.t[-1] - self.t[0]) if self.t.shape[0] > 1 else 0.0

    def largest(self) -> NDArray[np.float64]:
        """The largest ``|r|`` of each joint (n,) [N m] (NaN: never observed).

        Raises
        ------
        DataError
            Neither the series nor its peak kept.
        """
        if self.peak is not None:
            return self.peak
        r = self.series
        ran = np.all(np.isfinite(r), axis=1)
        if not ran.any():
            return np.full(r.shape[1], np.nan)
        out: NDArray[np.float64] = np.max(np.abs(r[ran]), axis=0)
        return out

    def truth_error(self) -> NDArray[np.float64] | None:
        """RMS [N m] (n,) per joint of the residual against the true external torques
        ``r - tau_ext`` (the observer's first-order lag included), over the samples the
        observer ran on; None without ``tau_ext``."""
        if self.truth_rms is not None:
            return self.truth_rms
        if self.tau_ext is None or self.r is None:
            return None
        e = self.r - self.tau_ext
        ran = np.all(np.isfinite(e), axis=1)
        if not ran.any():
            return None
        out: NDArray[np.float64] = np.sqrt(np.mean(e[ran] ** 2, axis=0))
        return out


@dataclass(frozen=True, slots=True, eq=False)
class ObserveResult:
    """What :func:`observe_files` computed: the model, the thresholds (calibrated or read)
    and every log's observation; ``fingerprint``, the files the model was read from, and
    ``friction_source``, the robot file whose own friction the model holds (a URDF's
    ``<dynamics>``; None: a friction given or identified); ``frame``, where the wrench was
    estimated (None: nowhere), and ``wrench``, what was estimated there (the whole wrench
    or the force of a point contact); ``gain_noise``, of a calibration: how much of its
    residual is the velocities' noise times the gain (None: not calibrated);
    ``min_duration_s`` and ``merge_s`` [s], the event rules a detection applied (None:
    calibrated); ``unmodelled``, of a model that holds no friction: the friction its
    residual shows at speed (:mod:`~dynid.observer.unmodelled`; None: a model with
    friction, or no sample at speed); ``check``, of a calibration: its false alarms on its
    own logs and the smallest external torques it detects
    (:mod:`~dynid.observer.calibration_check`); ``load``, of a detection: a load at the
    flange fitted to the residual off contacts (:mod:`~dynid.observer.unmodelled_load`;
    None: not fitted)."""

    model: ObserverModel
    thresholds: Thresholds
    logs: tuple[LogObservation, ...]
    fingerprint: ModelFingerprint | None = None
    friction_source: str | None = None
    frame: str | None = None
    wrench: WrenchKind = FULL
    gain_noise: GainNoise | None = None
    min_duration_s: float | None = None
    merge_s: float | None = None
    unmodelled: UnmodelledFriction | None = None
    check: CalibrationCheck | None = None
    load: UnmodelledLoad | None = None

    def dropped_count(self) -> int:
        """The crossings over the contact threshold every log's minimum duration dropped
        (not contacts)."""
        return sum(x.dropped_count for x in self.logs)

    def score(self) -> ContactScore | None:
        """The events of every log with labelled contacts against them, in total
        (:func:`~dynid.observer.scoring.combined`); None: no log has labels."""
        scores = [x.score for x in self.logs if x.score is not None]
        return combined(scores) if scores else None

    def trust(self) -> TrustVerdict | None:
        """Of a detection: how far to trust its events, in one verdict
        (:func:`~dynid.observer.trust.trust_verdict`: the residual outside the events of
        every log against the threshold, the calibration's level and false alarms, the
        time the events cover and the false alarms counted against labels); None: a
        calibration, or no log read outside its events."""
        quiet = [x.quiet for x in self.logs if x.quiet is not None]
        if self.min_duration_s is None or not quiet:
            return None
        pooled = QuietResidual.pooled(quiet)
        flagged, logged = self.flagged(loads=False)  # a load's event is no model error
        sc = self.score()
        return trust_verdict(
            pooled,
            self.thresholds.calibrated,
            flagged_share=flagged / logged if logged > 0 else 0.0,
            labelled=None if sc is None else (sc.false_alarms, sc.contact_free_s),
        )

    def flagged(self, *, loads: bool = True) -> tuple[float, float]:
        """``(flagged, logged)`` [s]: the time every log's events cover (``loads`` False:
        without the carried loads' events) and the logs' total duration. An event count
        alone misleads as a false-alarm measure: a lower threshold can give fewer events
        that cover more time (runs merged into one)."""
        return (
            float(sum(x.flagged_seconds(loads=loads) for x in self.logs)),
            float(sum(x.duration() for x in self.logs)),
        )

    @property
    def notes(self) -> tuple[str, ...]:
        """What the run's reader should know, one line each: the logs whose stamps are
        jittered or miss samples (:attr:`LogObservation.recording`); a model without friction
        (static data identify none) leaves the joints' friction in the residual, and in
        thresholds calibrated on it, where it reads as an external torque: how much the
        logs show at speed per joint, or that they show none
        (:func:`~dynid.observer.unmodelled.no_friction_note`); the friction
        a robot file holds of its own, used when none is given (a URDF's ``<dynamics>``:
        often a vendor's rough values); a friction
        whose Coulomb step is narrower than the logs' velocity noise is observed with the
        noise band (:func:`~dynid.observer.friction.banding_note`); a wrench at a frame that
        fewer than six joints move is the least-norm one
        (:func:`~dynid.observer.wrench.underdetermined_note`), a force alone at a frame
        that fewer than three joints move too; a residual off contacts that follows the
        weight of a load at the flange (:func:`~dynid.observer.unmodelled_load.load_note`),
        first a load carried over an event, held through a log or picked and released
        (:func:`~dynid.observer.carried_load.load_words`);
        a calibration on logs moved beyond the identification's speeds, or a detection's
        such log with events (:meth:`beyond`); with ``--no-loads``, the loads that fit an
        event (:func:`~dynid.observer.carried_load.unread_load_words`);
        false alarms that each start shortly before a missed labelled contact: labels that
        look late (:func:`~dynid.observer.scoring.shifted_labels_note`), left out for a log
        beyond the identification's speeds or whose other false alarms come at a similar
        rate (:meth:`_shifted_note`)."""
        identified = self.model.source == "identified"
        carried = [ld for x in self.logs for ld in x.loads]
        out: tuple[str, ...] = tuple(x.recording for x in self.logs if x.recording)
        out += tuple(
            f"{x.path.name}: {load_words(ld, identified=identified)}"
            for x in self.logs
            for ld in x.loads
        )
        if self.model.friction is None:
            out += (no_friction_note(self.unmodelled, self.model.robot.joint_names),)
        if self.model.friction is not None:
            own = None
            if self.friction_source is not None:
                own = robot_friction_note(self.friction_source, self.model.friction)
            banded = banding_note(self.model.friction, [x.friction for x in self.logs])
            out += tuple(x for x in (own, banded) if x is not None)
        out += self._motion_notes()
        u = self.unmodelled  # its note says the same of a model without friction
        said = u is not None and u.overall is not None and u.flagged_share() > MOST_FLAGGED
        held = any(ld.whole for ld in carried)  # its note names the cause, not the model
        if not said and not held and (flagged := self.mostly_flagged_note()) is not None:
            out += (flagged,)
        out += tuple(
            f"{x.path.name}: {unread_load_words(ld, identified=identified)}"
            for x in self.logs
            for ld in x.unread_loads
        )
        load = load_note(self.load, self.model.robot.joint_names, identified=identified)
        if load and not held:  # the load held throughout is that load, named above
            out += (load,)
        if (
            self.frame is not None
            and (note := underdetermined_note(self.model.robot, self.frame, self.wrench))
            is not None
        ):
            out += (note,)
        if (shifted := self._shifted_note()) is not None:
            out += (shifted,)
        return out

    def beyond(self) -> list[tuple[LogObservation, list[tuple[int, float, float]]]]:
        """The logs that move a joint more than
        :data:`~dynid.identification.motion_range.BEYOND` times as fast as the model's
        identification data (its record's ``speed_max``), each with those joints (0-based),
        their largest speed in the log and in the identification's data [rad/s]
        (:func:`~dynid.observer.motion_range.beyond_joints`)."""
        ident = self._identified_speeds()
        return [(x, found) for x in self.logs if (found := beyond_joints(ident, x.speed_max))]

    def _identified_speeds(self) -> tuple[float, ...] | None:
        info = self.model.logs_read
        return None if info is None else info.speed_max

    def _beyond_hint(self, x: LogObservation) -> str | None:
        """``validate``'s words on the log ``x`` moved beyond the identification's speeds."""
        return motion_hint(self._identified_speeds(), x.speed_max, self.model.robot.joint_names)

    def _motion_notes(self) -> tuple[str, ...]:
        """A calibration on logs moved beyond the identification's speeds: its thresholds
        hold the model's error there; a detection's log so moved, with events, when the
        note on most of the logs flagged does not say it: its events may be the model's
        error."""
        calibrating = self.min_duration_s is None
        flagged = self.mostly_flagged_note() is not None
        out = []
        for x, _ in self.beyond():
            hint = self._beyond_hint(x)
            if hint is None:
                continue
            if calibrating:
                out.append(
                    f"{x.path.name}: thresholds calibrated on motion beyond the model's "
                    f"identification data hold its error at those speeds: {hint}"
                )
            elif x.events and not flagged:
                out.append(
                    f"{x.path.name}: its events may be the model's error rather than "
                    f"contacts: {hint}"
                )
        return tuple(out)

    def _shifted_note(self) -> str | None:
        """The note on labels that look late (:func:`~dynid.observer.scoring.shifted_labels_note`)
        over the logs whose false alarms before missed contacts no other cause explains: a
        log moved beyond the identification's speeds (the model's error at speed) or one
        with false alarms elsewhere at a similar rate
        (:func:`~dynid.observer.scoring.early_by_chance`) does not count."""
        beyond = {id(x) for x, _ in self.beyond()}
        scores = []
        for x in self.logs:
            if (sc := x.score) is None:
                continue
            if id(x) in beyond or early_by_chance(sc):
                sc = dataclasses.replace(sc, early=())
            scores.append(sc)
        return shifted_labels_note(combined(scores)) if scores else None

    def mostly_flagged_note(self) -> str | None:
        """Of a detection whose events cover more than half of the logs
        (:data:`MOST_FLAGGED_TIME`): a residual over the contact threshold through most of
        the motion is the model's error, not contacts; None otherwise (a calibration).
        Where a log moves beyond the identification's speeds, the note names that as the
        cause (``validate``'s words); where a load fits the residual with ``--no-loads``,
        the load."""
        if self.min_duration_s is None:
            return None
        flagged, logged = self.flagged(loads=False)  # a load's event is no model error
        if not (logged > 0 and flagged > MOST_FLAGGED_TIME * logged):
            return None
        head = (
            f"events cover {100.0 * flagged / logged:.3g} % of the logs: a residual over "
            "the contact threshold through most of the motion"
        )
        if any(x.unread_loads for x in self.logs):
            return (
                f"{head} is not contacts: a load at the flange that the model lacks fits "
                f"it (named below; {NO_LOADS} reads it as the model's error)"
            )
        beyond = [f"{x.path.name}: {h}" for x, _ in self.beyond() if (h := self._beyond_hint(x))]
        if beyond:
            return f"{head} is the model's error, not contacts: " + "; ".join(beyond)
        names = self.model.robot.joint_names
        faster = [
            f"{x.path.name} moves "
            + ", ".join(f"{names[j]} up to {h:.3g} rad/s" for j, h, _ in found)
            + " ("
            + ", ".join(f"{i:.3g}" for *_, i in found)
            + " in the identification's data)"
            for x in self.logs
            if (found := beyond_joints(self._identified_speeds(), x.speed_max, FASTER))
        ]
        where = (
            ""
            if not faster
            else f"; {'; '.join(faster)}: the model extrapolates there (friction growing "
            "faster with speed than its law)"
        )
        return (
            f"{head} is the model's error (friction "
            "or other terms it misses, or thresholds calibrated with another model), not "
            f"contacts{where}; check the model on a collision-free log with dynid validate"
        )


#: Share of the logs' duration that events may cover before the notes call it the
#: model's error rather than contacts (:meth:`ObserveResult.mostly_flagged_note`).
MOST_FLAGGED_TIME = 0.5

#: How the note of a model that holds no friction begins (:attr:`ObserveResult.notes`).
NO_FRICTION = "the model holds no friction"


def robot_friction_note(source: str, friction: FrictionModel | FrictionSum) -> str:
    """The note of a model whose friction is the robot file ``source``'s own (the law and
    its largest Coulomb and viscous coefficients)."""
    parts = friction.parts if isinstance(friction, FrictionSum) else (friction,)
    sizes = []
    for name, unit in (("fc", "N m"), ("fv", "N m s/rad")):
        values = [np.abs(getattr(p, name)) for p in parts if name in p.law.params]
        if values:
            sizes.append(f"{name} up to {max(float(v.max()) for v in values):.3g} {unit}")
    where = " <dynamics damping friction>" if source.lower().endswith(".urdf") else ""
    return (
        f"the friction is {source}'s own{where} ({friction.kind}"
        + (f": {', '.join(sizes)}" if sizes else "")
        + "); --friction friction.json (of `dynid friction`) replaces it"
    )


def beyond_lines(result: ObserveResult, labels: dict[int, str] | None = None) -> list[str]:
    """The summary's lines on the logs moved beyond the identification's speeds
    (:meth:`ObserveResult.beyond`): a head, then per log its joints with both speeds;
    ``labels``: each log's name by its ``id`` (default its file name); none without such a
    log."""
    found = result.beyond()
    if not found:
        return []
    names = result.model.robot.joint_names
    rows = [
        f"motion beyond the identification's data (over {BEYOND:g} x a joint's largest "
        "speed there): the model extrapolates"
        + (", and the thresholds hold its error there" if result.min_duration_s is None else "")
    ]
    for x, joints in found:
        name = x.path.name if labels is None else labels.get(id(x), x.path.name)
        said = ", ".join(
            f"{names[j]} {here:.3g} rad/s ({ident:.3g} in the identification's data)"
            for j, here, ident in joints
        )
        rows.append(f"  {name}: {said}")
    return rows


def flagged_words(flagged: float, logged: float) -> str:
    """``"15.1 s flagged (50.3 % of 30 s logged)"``: the time events cover and its share
    of the logs' duration."""
    share = 100.0 * flagged / logged if logged > 0 else 0.0
    return f"{flagged:.3g} s flagged ({share:.3g} % of {logged:.3g} s logged)"


#: What each rule of :class:`~dynid.observer.events.DroppedCrossing` means, in words.
DROP_RULES = {
    "isolated": "isolated: no other crossing within --merge / 2",
    "short": "short: still under the minimum with the crossings within --merge joined",
}


def dropped_words(
    start: float,
    end: float,
    joint: str,
    peak: float,
    ratio: float,
    rule: str,
    min_duration_s: float | None,
) -> str:
    """``"0.803 s .. 0.806 s, joint2 peak +3.1 N m = 1.93 x contact, 3 ms < 10 ms
    (isolated: ...)"``: a crossing the minimum duration dropped, at ``start``, ``end``
    [s], on ``joint`` (its name, the one furthest over its threshold) with its ``peak``
    residual [N m] and its largest ``|r| / contact threshold`` ``ratio``, its duration
    against ``min_duration_s`` [s] (one sample: ``start == end``) and its ``rule``."""
    least = "" if min_duration_s is None else f" < {1e3 * min_duration_s:.3g} ms"
    when = f"{start:.3f} s" if end <= start else f"{start:.3f} s .. {end:.3f} s"
    lasted = "one sample" if end <= start else f"{1e3 * (end - start):.3g} ms"
    return (
        f"{when}, {joint} peak {peak:+.3g} N m = {ratio:.3g} x contact, "
        f"{lasted}{least} ({DROP_RULES.get(rule, rule)})"
    )
