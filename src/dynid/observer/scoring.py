"""Detected events scored against labelled contacts: intervals, matching and counts.

A label is a series over a log's samples, nonzero where the robot is in contact (a
``collision`` or ``contact`` column of a public collision data set), or the true external
torques of a simulated log, in contact where some joint's ``|tau_ext|`` exceeds
:data:`TRUTH_LEVEL` (:func:`truth_flags`). A NaN label reads as no contact.

* :func:`label_intervals`: each run of labelled samples as ``[t_first, t_last]`` [s],
  the convention of an event's start and end (first and last sample over the threshold);
* :func:`match_events`: an event ``[s, e]`` *detects* a labelled contact ``[a, b]`` when
  it starts within ``[a - lead, b + tolerance]`` (the observer's first-order lag
  ``K_O / (s + K_O)`` brings the residual over the threshold after a short contact has
  ended; ``lead``, a few samples, allows for velocities from a zero-phase filter, which
  sees ahead). Contacts less than ``tolerance`` apart form one group, which one event
  detects as a whole: two events in one contact are one detection; one event over two
  contacts that close detects both. An event still open over a later group detects only
  the group it started in: the later one, with no onset of its own, is missed unless
  another event starts in its window. An event that starts earlier than ``lead`` before
  any contact (a whole-log event of a joint with a flipped torque sign, say) detects
  nothing: it is a *false alarm*, and the contacts it covers are missed. Hand-made labels
  are late or early by up to ~0.1 s: the lead of a label column is the tolerance itself
  (:func:`lead_for`: an event starting up to ``tolerance`` before a label's start detects
  it), while the true torques of a simulated log keep the few samples of the exact lead;
* :func:`score_events`: the counts of one log (:class:`ContactScore`), the missed
  contacts with their times and peak true torque where known, the false alarms per minute
  of contact-free time (the log's duration less the labelled contacts, the lead before
  and the tolerance after each) and the detection delays (the first detecting event's
  start less the contact's start, never below ``-lead``; none for a contact whose event
  was already open over an earlier contact of its group), which events were false alarms
  (:attr:`ContactScore.false_events`) and how long before a missed contact each false
  alarm that runs into it started (:attr:`ContactScore.early`: several such, labels that
  look late, :func:`shifted_labels_note`); :func:`combined` the total over logs.

Delays measured on velocities from a zero-phase low-pass (derived from the positions)
are shorter than an online observer's: the filter sees ahead. A score says so
(:attr:`ContactScore.look_ahead`), and so do its words (:data:`LOOK_AHEAD_WORDS`),
beside the delay they qualify.

Times in seconds, torques in N m. Pure functions over arrays.
"""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import dataclass

import numpy as np
from numpy.typing import ArrayLike, NDArray

from ..exceptions import ShapeError

__all__ = [
    "DEFAULT_LEAD_S",
    "DEFAULT_TOLERANCE_S",
    "EARLY_WINDOW_S",
    "EARLY_CONCENTRATION",
    "EARLY_ELSEWHERE_MIN",
    "LEAD_SAMPLES",
    "LEADING_MIN",
    "LEADING_SHARE",
    "LOOK_AHEAD_WORDS",
    "TRUTH_LEVEL",
    "ContactScore",
    "MissedContact",
    "combined",
    "delay_words",
    "early_by_chance",
    "interval_peaks",
    "label_intervals",
    "labels_lead",
    "lead_for",
    "match_events",
    "score_events",
    "score_words",
    "shifted_labels_note",
    "truth_flags",
]

#: An event starting up to this long [s] after a labelled contact's last sample still
#: detects it: five time constants of the observer's lag at the default gain (50/s).
DEFAULT_TOLERANCE_S = 0.1
#: An event starting up to this long [s] before a labelled contact's first sample still
#: detects it: a few samples of a 200 Hz-1 kHz log, and the look-ahead of velocities from a
#: zero-phase low-pass at the observer's cut-off (20 Hz: a time constant of 8 ms).
#: :func:`lead_for` widens it to :data:`LEAD_SAMPLES` samples of a slower log.
DEFAULT_LEAD_S = 0.02
#: The fewest sample periods of lead (:func:`lead_for`).
LEAD_SAMPLES = 3
#: A false alarm starting up to this long [s] before a missed contact's start, and running
#: into it, reads as the same contact under a late label (:attr:`ContactScore.early`).
EARLY_WINDOW_S = 1.0
#: The false alarms running into missed contacts read as late labels only where their
#: rate in the windows before those contacts is more than this many times the rate of the
#: log's other false alarms over the rest of its contact-free time
#: (:func:`early_by_chance`).
EARLY_CONCENTRATION = 3.0
#: Fewest other false alarms that make a rate to compare with (:func:`early_by_chance`):
#: one or two strays beside labels that look late leave the hint.
EARLY_ELSEWHERE_MIN = 3
#: Detections lead their labels (:func:`labels_lead`) when more than this share of the
#: detected contacts' events start before their labels' starts ...
LEADING_SHARE = 0.5
#: ... and at least this many do (:func:`labels_lead`).
LEADING_MIN = 3
#: A simulated log is in contact where some joint's true external torque exceeds this
#: [N m] (``tau_ext`` of ``dynid simulate --contact``, zero outside its windows).
TRUTH_LEVEL = 0.1


def label_intervals(t: ArrayLike, flags: ArrayLike) -> NDArray[np.float64]:
    """The runs of labelled samples of a log as intervals.

    Parameters
    ----------
    t : array_like, shape (N,)
        Sample times [s], increasing.
    flags : array_like, shape (N,)
        Nonzero in contact; zero or NaN not.

    Returns
    -------
    ndarray, shape (k, 2)
        ``[t_first, t_last]`` [s] of each run, in time order (a one-sample run has zero
        length).

    Raises
    ------
    ShapeError
        ``t`` and ``flags`` not of one length ``(N,)``.
    """
    t = np.asarray(t, dtype=np.float64)
    f = np.asarray(flags, dtype=np.float64)
    if t.ndim != 1 or f.shape != t.shape:
        raise ShapeError(f"t and flags must both be (N,); got {t.shape} and {f.shape}")
    on = np.isfinite(f) & (f != 0.0)
    edges = np.diff(np.concatenate(([False], on, [False])).astype(np.int8))
    first = np.flatnonzero(edges == 1)
    last = np.flatnonzero(edges == -1) - 1
    return np.stack([t[first], t[last]], axis=1)


def truth_flags(tau_ext: ArrayLike, level: float = TRUTH_LEVEL) -> NDArray[np.bool_]:
    """In contact (N,) where some joint's ``|tau_ext|`` (N, n) [N m] exceeds ``level``
    [N m]; NaN is no contact."""
    ext = np.asarray(tau_ext, dtype=np.float64)
    with np.errstate(invalid="ignore"):
        out: NDArray[np.bool_] = np.any(np.abs(ext) > level, axis=-1)
    return out


def interval_peaks(t: ArrayLike, tau_ext: ArrayLike, intervals: ArrayLike) -> NDArray[np.float64]:
    """The largest ``|tau_ext|`` [N m] over the joints and samples of each interval
    (k, 2) [s] of a log at times ``t`` (N,); (k,)."""
    t = np.asarray(t, dtype=np.float64)
    ext = np.abs(np.asarray(tau_ext, dtype=np.float64))
    iv = np.asarray(intervals, dtype=np.float64).reshape(-1, 2)
    a = np.searchsorted(t, iv[:, 0], side="left")
    b = np.searchsorted(t, iv[:, 1], side="right")
    return np.array([np.nanmax(ext[i:j]) if j > i else np.nan for i, j in zip(a, b, strict=True)])


def _as_intervals(x: ArrayLike, name: str) -> NDArray[np.float64]:
    a = np.asarray(x, dtype=np.float64)
    if a.size == 0:
        return np.zeros((0, 2))
    if a.ndim != 2 or a.shape[1] != 2:
        raise ShapeError(f"{name} must be (k, 2) [start, end]; got {a.shape}")
    return a


def lead_for(t: ArrayLike, tolerance_s: float | None = None) -> float:
    """The lead [s] of a log sampled at times ``t`` (N,) [s]: :data:`DEFAULT_LEAD_S`, or
    :data:`LEAD_SAMPLES` median sample periods where that is longer; with ``tolerance_s``
    [s] (labels made by hand, off by tens of ms either way), that tolerance where it is
    longer still: the tolerance then applies on both sides of a label."""
    t = np.asarray(t, dtype=np.float64)
    dt = float(np.median(np.diff(t))) if t.shape[0] > 1 else 0.0
    lead = max(DEFAULT_LEAD_S, LEAD_SAMPLES * dt)
    return lead if tolerance_s is None else max(lead, float(tolerance_s))


def match_events(
    events: ArrayLike,
    labels: ArrayLike,
    tolerance_s: float = DEFAULT_TOLERANCE_S,
    lead_s: float = DEFAULT_LEAD_S,
    slack_s: float = 0.0,
) -> tuple[NDArray[np.intp], NDArray[np.bool_]]:
    """Which event detects each labelled contact, and which events are false alarms
    (module docstring).

    Parameters
    ----------
    events : array_like, shape (m, 2)
        ``[start, end]`` [s] of the detected events, in time order.
    labels : array_like, shape (k, 2)
        ``[start, end]`` [s] of the labelled contacts, in time order
        (:func:`label_intervals`).
    tolerance_s : float
        How long after a contact's end [s] an event may start and still detect it;
        contacts closer than this form one group.
    lead_s : float
        How long before a contact's start [s] an event may start and still detect it.
    slack_s : float
        Added to ``tolerance_s`` and ``lead_s`` in the comparisons [s]: a span of whole
        sample periods read from stamps carries their rounding
        (:func:`~dynid.observer.events.time_slack`, a hundredth of the sample period).

    Returns
    -------
    first : ndarray of int, shape (k,)
        Index of the earliest-starting event that detects each contact (starts within
        ``[a - lead_s, b + tolerance_s]`` of its group); -1: missed.
    false : ndarray of bool, shape (m,)
        Events that detect no contact.

    Raises
    ------
    ShapeError
        Intervals not of shape (m, 2) or (k, 2).
    """
    ev = _as_intervals(events, "events")
    lab = _as_intervals(labels, "labels")
    if ev.shape[0] == 0:  # no event: every contact missed
        return np.full(lab.shape[0], -1, dtype=np.intp), np.zeros(0, dtype=bool)
    if lab.shape[0] == 0:  # no contact: every event a false alarm
        return np.zeros(0, dtype=np.intp), np.ones(ev.shape[0], dtype=bool)
    opens = np.concatenate(([True], lab[1:, 0] - lab[:-1, 1] > tolerance_s + slack_s))
    group = np.cumsum(opens) - 1  # each contact's group
    a = lab[opens, 0]  # the groups' first and last samples
    b = lab[np.concatenate((opens[1:], [True])), 1]
    s = ev[None, :, 0]
    hit = (s >= a[:, None] - lead_s - slack_s) & (s <= b[:, None] + tolerance_s + slack_s)
    over = hit[group]
    starts = np.where(over, ev[None, :, 0], np.inf)
    first = np.where(over.any(axis=1), np.argmin(starts, axis=1), -1).astype(np.intp)
    false: NDArray[np.bool_] = np.logical_not(over.any(axis=0))
    return first, false


@dataclass(frozen=True, slots=True)
class MissedContact:
    """A labelled contact no event overlaps: ``start``, ``end`` [s] and ``peak``, its
    largest true external torque [N m] (None: not known, a label column); where read
    (:mod:`~dynid.observer.missed_reason`), the ``reason`` it was missed, the ``joint``
    (0-based) whose ``torque`` came closest to its ``threshold`` [N m], the one in force at
    the time ``at`` [s] of that sample, and whether that torque is the true one
    (``true_torque``) or the residual."""

    start: float
    end: float
    peak: float | None = None
    reason: str | None = None
    joint: int | None = None
    torque: float | None = None
    threshold: float | None = None
    true_torque: bool = False
    at: float | None = None


@dataclass(frozen=True, slots=True)
class ContactScore:
    """Detected events against labelled contacts (module docstring).

    Attributes
    ----------
    source : str
        Where the labels came from: ``column 'collision'`` or ``tau_ext > 0.1 N m``.
    tolerance_s : float
        How long after a contact's end [s] an event may start and still detect it.
    labelled : int
        Labelled contacts.
    detected : int
        Of them, those some event detects (:func:`match_events`).
    missed : tuple of MissedContact
        The others, in time order.
    false_alarms : int
        Events that detect no labelled contact.
    contact_free_s : float
        The log's duration less the labelled contacts, the lead before and the tolerance
        after each [s].
    delays : tuple of float
        Detection delays [s] (event start less contact start, ``-lead_s`` at the least)
        of the detected contacts whose event started after the previous contact's end.
    intervals : tuple of (float, float)
        The labelled contacts ``(start, end)`` [s].
    look_ahead : bool
        The observer ran on velocities from a zero-phase low-pass, which sees ahead: the
        delays are shorter than an online observer's.
    lead_s : float
        How long before a contact's start [s] an event may start and still detect it.
    false_events : tuple of int
        The indices (0-based, in the log's event order) of the events counted as false
        alarms (empty for a total over logs: :func:`combined`).
    early : tuple of float
        For each false alarm that starts up to :data:`EARLY_WINDOW_S` before a missed
        contact and runs to within ``tolerance_s`` of its start: how long before the
        contact's start it started [s]. Several such read as labels late by about that
        much (:func:`shifted_labels_note`).
    early_window_s : float
        The time [s] those false alarms may start in: the union of the windows from
        :data:`EARLY_WINDOW_S` to the lead before each missed contact's start, within the
        log (summed over logs by :func:`combined`); :func:`early_by_chance` compares the
        rates inside and outside it.
    """

    source: str
    tolerance_s: float
    labelled: int
    detected: int
    missed: tuple[MissedContact, ...]
    false_alarms: int
    contact_free_s: float
    delays: tuple[float, ...]
    intervals: tuple[tuple[float, float], ...] = ()
    look_ahead: bool = False
    lead_s: float = DEFAULT_LEAD_S
    false_events: tuple[int, ...] = ()
    early: tuple[float, ...] = ()
    early_window_s: float = 0.0

    @property
    def false_alarms_per_min(self) -> float | None:
        """False alarms per minute of contact-free time (None: no such time)."""
        return 60.0 * self.false_alarms / self.contact_free_s if self.contact_free_s > 0 else None

    @property
    def delay_median(self) -> float | None:
        """Median detection delay [s] (None: no delay)."""
        return float(np.median(self.delays)) if self.delays else None

    @property
    def delay_max(self) -> float | None:
        """Largest detection delay [s] (None: no delay)."""
        return float(np.max(self.delays)) if self.delays else None


def score_events(
    events: ArrayLike,
    labels: ArrayLike,
    span: tuple[float, float],
    *,
    tolerance_s: float = DEFAULT_TOLERANCE_S,
    peaks: ArrayLike | None = None,
    source: str = "",
    look_ahead: bool = False,
    lead_s: float = DEFAULT_LEAD_S,
    slack_s: float = 0.0,
) -> ContactScore:
    """The score of one log's events against its labelled contacts.

    Parameters
    ----------
    events : array_like, shape (m, 2)
        ``[start, end]`` [s] of the detected events, in time order.
    labels : array_like, shape (k, 2)
        ``[start, end]`` [s] of the labelled contacts, in time order.
    span : (float, float)
        The log's first and last sample time [s].
    tolerance_s : float
        See :func:`match_events`.
    peaks : array_like, shape (k,), optional
        The largest true external torque of each contact [N m] (:func:`interval_peaks`).
    source : str
        Where the labels came from.
    look_ahead : bool
        See :class:`ContactScore`.
    lead_s, slack_s : float
        See :func:`match_events`.

    Returns
    -------
    ContactScore

    Raises
    ------
    ShapeError
        Intervals not (m, 2) or (k, 2), ``peaks`` not (k,).
    """
    ev = _as_intervals(events, "events")
    lab = _as_intervals(labels, "labels")
    top = None if peaks is None else np.asarray(peaks, dtype=np.float64).reshape(-1)
    if top is not None and top.shape != (lab.shape[0],):
        raise ShapeError(f"peaks must be ({lab.shape[0]},); got {top.shape}")
    first, false = match_events(ev, lab, tolerance_s, lead_s, slack_s)
    missed = tuple(
        MissedContact(
            float(lab[k, 0]),
            float(lab[k, 1]),
            None if top is None or not np.isfinite(top[k]) else float(top[k]),
        )
        for k in np.flatnonzero(first < 0)
    )
    delays = []
    for k in np.flatnonzero(first >= 0):
        start = ev[first[k], 0]
        if k == 0 or start > lab[k - 1, 1]:  # not an event still open from the last one
            delays.append(float(start - lab[k, 0]))
    early = _early(ev, lab, first, false, tolerance_s, lead_s + slack_s)
    t0, t1 = span
    before = np.array([[a - EARLY_WINDOW_S, a - lead_s - slack_s] for a, _ in (lab[first < 0])])
    window = _union_length(np.clip(before.reshape(-1, 2), t0, t1)) if before.size else 0.0
    covered = _union_length(np.clip(lab + [-lead_s, tolerance_s], t0, t1))
    return ContactScore(
        source,
        float(tolerance_s),
        int(lab.shape[0]),
        int(np.count_nonzero(first >= 0)),
        missed,
        int(np.count_nonzero(false)),
        float(max(t1 - t0 - covered, 0.0)),
        tuple(delays),
        tuple((float(a), float(b)) for a, b in lab),
        look_ahead,
        float(lead_s),
        tuple(int(i) for i in np.flatnonzero(false)),
        early,
        float(window),
    )


def _early(
    ev: NDArray[np.float64],
    lab: NDArray[np.float64],
    first: NDArray[np.intp],
    false: NDArray[np.bool_],
    tolerance_s: float,
    lead_s: float,
) -> tuple[float, ...]:
    """How long [s] before each missed contact's start the latest false alarm that runs
    into it started (:attr:`ContactScore.early`): one starting ``lead_s`` to
    :data:`EARLY_WINDOW_S` before it and ending no earlier than ``tolerance_s`` before
    it."""
    out = []
    for k in np.flatnonzero(first < 0):
        a = lab[k, 0]
        near = false & (ev[:, 0] < a - lead_s) & (ev[:, 0] >= a - EARLY_WINDOW_S)
        near &= ev[:, 1] >= a - tolerance_s
        if near.any():
            out.append(float(a - ev[np.flatnonzero(near)[-1], 0]))
    return tuple(out)


def early_by_chance(sc: ContactScore) -> bool:
    """True where the false alarms that run into missed contacts (:attr:`ContactScore.early`)
    are no sign of late labels: the log's other false alarms (at least
    :data:`EARLY_ELSEWHERE_MIN`), over the rest of its contact-free time, come at a rate of
    more than 1 / :data:`EARLY_CONCENTRATION` of theirs in the windows before the missed
    contacts
    (:attr:`ContactScore.early_window_s`). Labels that are late gather the false alarms
    just before them; a model off at speed scatters them over the log, and some fall
    before a contact by chance (a UR5 with exact labels observed on motion beyond its
    identification's: 3 before its 6 missed contacts in 6 s of windows, 7 in the other
    8.1 s contact-free, 0.5 against 0.86 per second)."""
    elsewhere = sc.false_alarms - len(sc.early)
    if not sc.early or elsewhere < EARLY_ELSEWHERE_MIN:
        return False
    near = len(sc.early) / max(sc.early_window_s, 1e-9)
    rest = sc.contact_free_s - sc.early_window_s
    if rest <= 0.0:
        return False
    far = elsewhere / rest
    return EARLY_CONCENTRATION * far >= near


def labels_lead(sc: ContactScore) -> tuple[int, float] | None:
    """How many detected contacts' events start before their labels' starts, and their
    median lead [s] (> 0), when more than :data:`LEADING_SHARE` of the delays and at
    least :data:`LEADING_MIN` of them do: labels late by about that much, the delays
    measured from them short by as much; None otherwise. (A UR5 whose labels were set
    21-58 ms late: all 7 events started 5-32 ms before their labels, delay median -16 ms,
    +13 to +57 ms from the true onsets.)"""
    lead = [-d for d in sc.delays if d < 0.0]
    if len(lead) < LEADING_MIN or len(lead) <= LEADING_SHARE * len(sc.delays):
        return None
    return len(lead), float(np.median(lead))


def shifted_labels_note(sc: ContactScore) -> str | None:
    """One line when the labels look shifted late: two or more false alarms each start
    shortly before a missed contact and run into it (:attr:`ContactScore.early`; the
    median of those leads, and a ``--label-tolerance`` covering the longest would count
    them), left out where the log's other false alarms come at a similar rate
    (:func:`early_by_chance`: the model's error, not the labels); or most detections
    start before their labels (:func:`labels_lead`: the median lead, by which the delays
    measured from the labels are short); None with neither."""
    said = []
    if len(sc.early) >= 2 and not early_by_chance(sc):
        med, top = 1e3 * float(np.median(sc.early)), max(sc.early)
        said.append(
            f"{len(sc.early)} false alarm(s) each start shortly before a missed labelled "
            f"contact and run into it ({1e3 * min(sc.early):.0f} to {1e3 * top:.0f} ms "
            f"before its start): the labels look shifted late by ~{med:.0f} ms (labels made "
            f"by hand?); --label-tolerance {np.ceil(top * 20.0) / 20.0:g} (s, applied before "
            "a label's start too) would count those events as detections"
        )
    if (leading := labels_lead(sc)) is not None:
        k, lead = leading
        said.append(
            f"{k} of {len(sc.delays)} detected contacts' events start before their labels, "
            f"by a median lead of {1e3 * lead:.0f} ms: the labels look late by about "
            f"{1e3 * lead:.0f} ms, and the delays measured from them are short by as much"
        )
    return "; ".join(said) if said else None


def _union_length(iv: NDArray[np.float64]) -> float:
    """Length [s] of the union of intervals (k, 2) in order of their starts."""
    total, reach = 0.0, -np.inf
    for a, b in iv:
        if b > reach:
            total += b - max(a, reach)
            reach = b
    return total


def combined(scores: Sequence[ContactScore]) -> ContactScore:
    """The total of several logs' scores (their counts, times, misses and delays pooled);
    ``source`` and ``tolerance_s`` of the first, ``intervals`` and ``false_events`` left
    empty, ``look_ahead`` where any log's is, ``lead_s`` the longest, ``early`` pooled.

    Raises
    ------
    ValueError
        No score.
    """
    if not scores:
        raise ValueError("no score to combine")
    return ContactScore(
        ", ".join(dict.fromkeys(s.source for s in scores)),
        scores[0].tolerance_s,
        sum(s.labelled for s in scores),
        sum(s.detected for s in scores),
        tuple(m for s in scores for m in s.missed),
        sum(s.false_alarms for s in scores),
        float(sum(s.contact_free_s for s in scores)),
        tuple(d for s in scores for d in s.delays),
        look_ahead=any(s.look_ahead for s in scores),
        lead_s=max(s.lead_s for s in scores),
        early=tuple(d for s in scores for d in s.early),
        early_window_s=float(sum(s.early_window_s for s in scores)),
    )


#: What qualifies the delays of a score whose velocities came from a zero-phase low-pass.
LOOK_AHEAD_WORDS = "zero-phase filtered velocities see ahead: an online observer's is longer"


def delay_words(sc: ContactScore) -> str:
    """``delay median 21 ms, max 27 ms``, with :data:`LOOK_AHEAD_WORDS` in brackets when
    the score's velocities saw ahead; empty without a delay."""
    if sc.delay_median is None or sc.delay_max is None:
        return ""
    said = f"delay median {1e3 * sc.delay_median:.0f} ms, max {1e3 * sc.delay_max:.0f} ms"
    return said + (f" ({LOOK_AHEAD_WORDS})" if sc.look_ahead else "")


def score_words(sc: ContactScore) -> str:
    """A score in one line: ``5 labelled, 5 detected, 0 missed; 1 false alarm (3.4 per min of 17.6 s
    contact-free); delay median 21 ms, max 27 ms`` (:func:`delay_words`)."""
    rate = sc.false_alarms_per_min
    per = "" if rate is None else f"{rate:.3g} per min of "
    said = (
        f"{sc.labelled} labelled, {sc.detected} detected, {len(sc.missed)} missed; "
        f"{sc.false_alarms} false alarm(s) ({per}{sc.contact_free_s:.3g} s contact-free)"
    )
    delay = delay_words(sc)
    return said + (f"; {delay}" if delay else "")
