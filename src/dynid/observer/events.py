"""Contact events of a residual, from the whole log or a block of samples at a time.

An event is a run of samples where some ``|r_j|`` exceeds its contact threshold
(:func:`~dynid.observer.thresholds.threshold_series`), runs closer than ``merge_s``
joined unless the observer started again between them (a log cut at its gaps: no event
spans a cut). Each event has its start and end [s] (first and last sample over the
threshold), the joints over it (1-based), the peak residual of every joint [N m] (signed,
at its first largest magnitude between its start and end) and its level (``collision``
when some joint passed its collision threshold).

One contact is one event by default. A push near the threshold (a joint at rest, whose
threshold rises and falls with the standstill margin as the velocity noise crosses the
band) crosses it again and again: runs closer than :data:`DEFAULT_MERGE_S` (0.2 s) are
one event. A crossing of a few samples is the velocity noise, which the residual passes
unfiltered through ``M(q) dq``: an event shorter than :data:`DEFAULT_MIN_DURATION_S`
(0.01 s from its first to its last sample over the threshold) is dropped unless it
reached the collision level. Before runs are joined, an *isolated crossing* is dropped:
a run shorter than ``min_duration_s`` at the contact level with no other run within
:data:`ISOLATION_FRACTION` of ``merge_s`` (0.1 s by default) before or after it in its
piece. It neither starts, extends nor joins an event: a one-sample crossing 0.136 s
before a contact on a TALOS arm was joined to it and put its start there. A contact near
the threshold whose residual the noise dips below it makes crossings closer together,
which are kept and joined. An event's start is its first sample over the threshold that
is not an isolated crossing. ``merge_s = 0`` and ``min_duration_s = 0`` give every run
over the threshold as its own event.

:class:`EventDetector` finds them a block of samples at a time: the last run over the
threshold (not judged until the next run says whether it is isolated), the event still
open (its start, last sample over the threshold, peaks, joints and level) and the largest
residual since its last sample over the threshold are carried to the next block, so a
long log is read with one block's temporaries and gives the events of the whole log
exactly. :func:`detect` is the detector fed the whole log as one block.

A crossing the minimum duration drops is not a contact, but it is not silence either: the
detector counts every one (:attr:`EventDetector.dropped_count`) and keeps the
:data:`MAX_DROPPED` that went furthest over the threshold as :class:`DroppedCrossing`
records (:attr:`EventDetector.dropped`: start, end, joints, peaks, the largest ``|r|``
over the threshold and the rule that dropped it, ``isolated`` or ``short``), so that a
joint whose residual passed its threshold with no event says why.

Every span is compared with ``merge_s``, ``min_duration_s`` and the isolation window with
a slack of :data:`SLACK_FRACTION` of the sample period (:func:`time_slack`): a span of
whole sample periods read from stamps carries their rounding, and at 100 Hz a two-sample
crossing from 48.03 s to 48.04 s spans 0.00999999999999801 s, which a bare comparison
dropped as shorter than 0.01 s while the same crossing 0.02 s later was kept.
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import Literal

import numpy as np
from numpy.typing import ArrayLike, NDArray

from .. import _checks
from ..exceptions import OptionError, ShapeError
from .thresholds import Thresholds, threshold_series

__all__ = [
    "DEFAULT_MERGE_S",
    "DEFAULT_MIN_DURATION_S",
    "ISOLATION_FRACTION",
    "MAX_DROPPED",
    "SLACK_FRACTION",
    "ContactEvent",
    "DroppedCrossing",
    "EventDetector",
    "detect",
    "time_slack",
]

#: Runs over the threshold closer than this [s] are one event (module docstring).
DEFAULT_MERGE_S = 0.2
#: Events shorter than this [s] (first to last sample over the threshold) are dropped
#: unless they reached the collision level (module docstring).
DEFAULT_MIN_DURATION_S = 0.01
#: A run shorter than ``min_duration_s`` with no other run within this fraction of
#: ``merge_s`` before or after it is an isolated crossing, dropped before runs are joined
#: (module docstring).
ISOLATION_FRACTION = 0.5
#: Dropped crossings kept as records (those furthest over the threshold); all are counted.
MAX_DROPPED = 100
#: The slack of every comparison of a span with a duration, as a fraction of the sample
#: period (module docstring): far above the stamps' rounding, far below a sample.
SLACK_FRACTION = 0.01


def time_slack(t: ArrayLike) -> float:
    """The slack [s] of a comparison of spans between the samples ``t`` (N,) [s] with a
    duration: :data:`SLACK_FRACTION` of the median positive step (0: fewer than two
    distinct samples)."""
    steps = np.diff(np.asarray(t, dtype=np.float64).reshape(-1))
    steps = steps[steps > 0]
    return SLACK_FRACTION * float(np.median(steps)) if steps.size else 0.0


@dataclass(frozen=True, slots=True)
class ContactEvent:
    """A detected contact (module docstring).

    Attributes
    ----------
    start, end : float
        First and last sample over the threshold [s].
    joints : tuple of int
        Joints over their threshold during the event, 1-based.
    peak : tuple of float
        Every joint's residual at its largest magnitude in the event [N m] (signed).
    level : {"contact", "collision", "load"}
        ``load``: the onset of a load carried at the flange (its pick), an external force
        read as a weight (:mod:`~dynid.observer.carried_load`); its span the load's.
    """

    start: float
    end: float
    joints: tuple[int, ...]
    peak: tuple[float, ...]
    level: Literal["contact", "collision", "load"]


@dataclass(frozen=True, slots=True)
class DroppedCrossing:
    """A run over the contact threshold that the minimum duration dropped: not a contact
    (module docstring).

    Attributes
    ----------
    start, end : float
        First and last sample over the threshold [s].
    joints : tuple of int
        Joints over their threshold, 1-based.
    peak : tuple of float
        Every joint's residual at its largest magnitude in the crossing [N m] (signed).
    ratio : tuple of float
        Every joint's largest ``|r| / contact threshold`` in it (the threshold as it stood
        at each sample); over 1 on its ``joints``.
    rule : {"isolated", "short"}
        ``isolated``: a run shorter than the minimum duration with no other within the
        isolation window; ``short``: runs joined into an event still shorter than it.
    """

    start: float
    end: float
    joints: tuple[int, ...]
    peak: tuple[float, ...]
    ratio: tuple[float, ...]
    rule: Literal["isolated", "short"]

    @property
    def duration(self) -> float:
        """``end - start`` [s], the span the minimum duration is compared with."""
        return self.end - self.start

    @property
    def joint(self) -> int:
        """The joint (1-based) furthest over its threshold."""
        return max(self.joints, key=lambda j: self.ratio[j - 1])


@dataclass(slots=True)
class _Stretch:
    """What a stretch of samples contributes to an event: per joint the largest ``|r|``
    (n,) and ``r`` at its first occurrence, the largest ``|r| / contact threshold``, the
    joints over the contact threshold, and whether some joint passed its collision
    threshold."""

    top: NDArray[np.float64]
    value: NDArray[np.float64]
    joints: NDArray[np.bool_]
    collision: bool
    ratio: NDArray[np.float64]

    @staticmethod
    def empty(n: int) -> _Stretch:
        return _Stretch(
            np.full(n, -np.inf), np.zeros(n), np.zeros(n, dtype=bool), False, np.zeros(n)
        )

    @staticmethod
    def of(
        r: NDArray[np.float64],
        over: NDArray[np.bool_],
        beyond: NDArray[np.bool_],
        ratio: NDArray[np.float64],
    ) -> _Stretch:
        """Of the samples ``r`` (m, n), over the contact (``over``) and the collision
        (``beyond``) thresholds (m, n), ``|r|`` over the contact threshold ``ratio`` (m, n;
        0 where not observed)."""
        n = r.shape[1]
        if r.shape[0] == 0:
            return _Stretch.empty(n)
        k = np.argmax(np.abs(r), axis=0)
        value = r[k, np.arange(n)]
        joints: NDArray[np.bool_] = np.asarray(over.any(axis=0))
        return _Stretch(np.abs(value), value, joints, bool(beyond.any()), ratio.max(axis=0))

    def then(self, later: _Stretch) -> _Stretch:
        """This stretch followed by ``later``: a peak of ``later`` replaces one of this
        stretch only when larger (the first of equal magnitudes kept, as ``argmax``)."""
        take = later.top > self.top
        return _Stretch(
            np.where(take, later.top, self.top),
            np.where(take, later.value, self.value),
            self.joints | later.joints,
            self.collision or later.collision,
            np.fmax(self.ratio, later.ratio),
        )

    def dropped(self, start: float, end: float, rule: str) -> DroppedCrossing:
        """The stretch as a crossing from ``start`` to ``end`` [s] dropped by ``rule``."""
        return DroppedCrossing(
            start,
            end,
            tuple(int(j) + 1 for j in np.flatnonzero(self.joints)),
            tuple(float(x) for x in self.value),
            tuple(float(x) for x in self.ratio),
            "isolated" if rule == "isolated" else "short",
        )


@dataclass(slots=True)
class _Run:
    """A run of samples over the threshold one after the other in one piece, not judged
    yet (the next run decides whether it is isolated): its first and last sample (time
    [s], and the last one's index in the log), its piece, whether another run ends within
    the isolation window before it, what its samples hold and what the samples after it
    hold."""

    start: float
    last: float
    last_k: int
    piece: int
    near: bool
    held: _Stretch
    tail: _Stretch


@dataclass(slots=True)
class _Open:
    """An event not closed yet: its first and last sample over the threshold (time [s]
    and piece), what its samples hold, and what the samples after its last one over
    the threshold hold (joined to it only if a kept run follows within ``merge_s``)."""

    start: float
    last: float
    piece: int
    held: _Stretch
    after: _Stretch

    def closed(self) -> ContactEvent:
        level: Literal["contact", "collision"] = "collision" if self.held.collision else "contact"
        joints = tuple(int(j) + 1 for j in np.flatnonzero(self.held.joints))
        return ContactEvent(
            self.start, self.last, joints, tuple(float(x) for x in self.held.value), level
        )


class EventDetector:
    """Contact events of one log's residual fed a block of samples at a time (module
    docstring).

    Parameters
    ----------
    thresholds : Thresholds
    merge_s : float
        Runs over the threshold closer than this [s] are one event (>= 0); an isolated
        crossing (:data:`ISOLATION_FRACTION` of it) is dropped first.
    min_duration_s : float
        Events shorter than this [s] at the contact level are dropped, and so are
        isolated crossings shorter than it (>= 0).
    restarts : array_like of int, optional
        Samples of the log (counted from its first, over every block) where the observer
        started again (the first of each piece of a log cut at its gaps): no event spans
        one.
    sample_period_s : float, optional
        The log's sample period [s], whose :data:`SLACK_FRACTION` is the slack of every
        comparison of a span with a duration (module docstring); default: the median
        step of the first samples fed (the first block of two or more).

    Raises
    ------
    OptionError
        A negative ``merge_s``, ``min_duration_s`` or ``sample_period_s``.

    Examples
    --------
    >>> det = EventDetector(th)                                  # doctest: +SKIP
    >>> events = [e for t, r in blocks for e in det.feed(t, r)]  # doctest: +SKIP
    >>> events += det.finish()                                   # doctest: +SKIP
    """

    def __init__(
        self,
        thresholds: Thresholds,
        *,
        merge_s: float = DEFAULT_MERGE_S,
        min_duration_s: float = DEFAULT_MIN_DURATION_S,
        restarts: ArrayLike | None = None,
        sample_period_s: float | None = None,
    ) -> None:
        if sample_period_s is not None and not sample_period_s >= 0:
            raise OptionError(f"sample_period_s must be >= 0 [s]; got {sample_period_s}")
        if not merge_s >= 0:
            raise OptionError(f"merge_s must be >= 0 [s]; got {merge_s}")
        if not min_duration_s >= 0:
            raise OptionError(f"min_duration_s must be >= 0 [s]; got {min_duration_s}")
        self.thresholds, self.merge_s = thresholds, float(merge_s)
        self.min_duration_s = float(min_duration_s)
        #: A run shorter than ``min_duration_s`` with no other run this close [s] is an
        #: isolated crossing (module docstring).
        self.isolation_s = ISOLATION_FRACTION * self.merge_s
        self._restarts = np.sort(np.asarray([] if restarts is None else restarts, dtype=np.int64))
        self._next = 0  # the log's sample the next block starts at
        self._open: _Open | None = None
        self._run: _Run | None = None  # a run that reached the end of the last block
        self._ratio = np.full(thresholds.n, np.nan)
        self._dropped: list[DroppedCrossing] = []
        self._dropped_count = 0
        #: The slack [s] of the comparisons of spans with durations (module docstring);
        #: None until the sample period is known.
        self.slack_s: float | None = (
            None if sample_period_s is None else SLACK_FRACTION * float(sample_period_s)
        )
        self._last_t: float | None = None  # the last sample fed, for the period

    def _longer(self, span: float, duration: float) -> bool:
        """``span > duration`` [s] beyond the slack."""
        return span > duration + (self.slack_s or 0.0)

    def _shorter(self, span: float, duration: float) -> bool:
        """``span < duration`` [s] beyond the slack."""
        return span < duration - (self.slack_s or 0.0)

    @property
    def dropped(self) -> tuple[DroppedCrossing, ...]:
        """The crossings over the contact threshold dropped so far by the minimum
        duration (module docstring), in time order: the :data:`MAX_DROPPED` furthest over
        the threshold when there were more (:attr:`dropped_count` counts them all)."""
        return tuple(sorted(self._kept_dropped(), key=lambda d: d.start))

    @property
    def dropped_count(self) -> int:
        """Every crossing dropped so far by the minimum duration."""
        return self._dropped_count

    def _kept_dropped(self) -> list[DroppedCrossing]:
        """The :data:`MAX_DROPPED` records furthest over the threshold."""
        if len(self._dropped) > MAX_DROPPED:
            self._dropped.sort(key=lambda d: -max(d.ratio))
            del self._dropped[MAX_DROPPED:]
        return self._dropped

    def _drop(self, crossing: DroppedCrossing) -> None:
        self._dropped_count += 1
        self._dropped.append(crossing)
        if len(self._dropped) > 2 * MAX_DROPPED:  # bounded memory on a noisy log
            self._kept_dropped()

    @property
    def largest_ratio(self) -> NDArray[np.float64]:
        """The largest ``|r| / contact threshold`` of each joint (n,) over the samples fed
        so far, the threshold as it stood at each sample (uncertainty and standstill
        margin included); NaN where never observed. 1 or more where a run over the
        threshold began (an event, unless too short or isolated)."""
        return self._ratio.copy()

    def feed(
        self,
        t: ArrayLike,
        r: ArrayLike,
        *,
        std: ArrayLike | None = None,
        standstill: ArrayLike | None = None,
        levels: tuple[NDArray[np.float64], NDArray[np.float64]] | None = None,
    ) -> list[ContactEvent]:
        """The events closed by the next block of samples (an event still open at its
        end, and a run over the threshold that reaches it, are carried to the next block
        or :meth:`finish`).

        Parameters
        ----------
        t : array_like, shape (m,)
            The block's sample times [s] (after the previous block's).
        r : array_like, shape (m, n)
            Its residual [N m]; NaN where the observer did not run (never an event there).
        std, standstill : array_like, shape (m, n), optional
            :func:`~dynid.observer.detection.residual_std` and
            :func:`~dynid.observer.detection.standstill_series` of the block (for
            thresholds that use them; NaN std where ``r`` is NaN).
        levels : (ndarray, ndarray), each shape (m, n), optional
            The contact and collision thresholds at the block's samples [N m]
            (:func:`~dynid.observer.thresholds.threshold_series` of ``std`` and
            ``standstill``), built once by a caller that needs them too; ``std`` and
            ``standstill`` are then not read. Their values where ``r`` is NaN are never
            read.

        Raises
        ------
        ShapeError
            Shapes that disagree, thresholds of another joint count, an infinite ``r``.
        """
        ta = _checks.as_array("t", t)
        m = ta.shape[0]
        ra = _checks.as_exact("r", r, (m, self.thresholds.n), allow_nonfinite=True)
        if np.any(np.isinf(ra)):
            raise ShapeError("r must be finite or NaN (not observed); got inf")
        if m:
            if self.slack_s is None:  # the period of the first steps fed
                before = [] if self._last_t is None else [self._last_t]
                if slack := time_slack(np.concatenate((before, ta))):
                    self.slack_s = slack
            self._last_t = float(ta[-1])
        seen: NDArray[np.bool_] = np.all(np.isfinite(ra), axis=1)
        if levels is not None:
            contact = _checks.as_exact("contact", levels[0], ra.shape, allow_nonfinite=True)
            collision = _checks.as_exact("collision", levels[1], ra.shape, allow_nonfinite=True)
        else:
            if std is not None:  # NaN where not observed, as r
                std = np.where(seen[:, None], np.asarray(std, dtype=np.float64), 0.0)
            contact, collision = threshold_series(self.thresholds, m, std, standstill)
        ra = np.where(seen[:, None], ra, 0.0)
        with np.errstate(divide="ignore", invalid="ignore"):
            ratio = np.abs(ra) / contact
        ratio = np.where((ratio >= 0) & seen[:, None], ratio, np.nan)  # NaN: not observed
        if seen.any():
            self._ratio = np.fmax(self._ratio, np.nanmax(ratio[seen], 0))
        ratio = np.nan_to_num(ratio, nan=0.0, posinf=np.finfo(float).max)
        first, self._next = self._next, self._next + m
        over = np.abs(ra) > contact
        beyond = np.abs(ra) > collision

        def stretch(a: int, b: int) -> _Stretch:
            return _Stretch.of(ra[a:b], over[a:b], beyond[a:b], ratio[a:b])

        hit = np.flatnonzero(over.any(axis=1))
        piece = np.searchsorted(self._restarts, first + hit, side="right")
        # runs: samples over the threshold one after the other, in one piece
        cut = np.flatnonzero((np.diff(hit) > 1) | (piece[1:] != piece[:-1])) + 1
        bounds = zip([0, *cut], [*cut, hit.size], strict=True) if hit.size else ()
        out: list[ContactEvent] = []
        run, done = self._run, 0  # done: the block's samples given to a run or the event
        for i, j in bounds:
            a, b, p = int(hit[i]), int(hit[j - 1]) + 1, int(piece[i])
            gap = stretch(done, a)
            if run is not None and p == run.piece and first + a == run.last_k + 1:
                # the run at the end of the last block goes on
                run.held = run.held.then(gap).then(stretch(a, b))
                run.last, run.last_k = float(ta[b - 1]), first + b - 1
            else:
                near = False
                if run is not None:
                    near = p == run.piece and not self._longer(
                        float(ta[a]) - run.last, self.isolation_s
                    )
                    run.tail = run.tail.then(gap)
                    out += self._judged(run, near)
                else:
                    self._between(gap)
                run = _Run(
                    float(ta[a]), float(ta[b - 1]), first + b - 1, p, near, stretch(a, b),
                    _Stretch.empty(ra.shape[1]),
                )  # fmt: skip
            done = b
        if run is not None:  # the next run, in this block or a later one, judges it
            run.tail = run.tail.then(stretch(done, m))
        else:
            self._between(stretch(done, m))
        self._run = run
        return out

    def finish(self) -> list[ContactEvent]:
        """The event still open after the last block (none or one)."""
        out = [] if self._run is None else self._judged(self._run, False)
        self._run = None
        if self._open is not None:
            out += self._closed(self._open)
        self._open = None
        return out

    def _between(self, held: _Stretch) -> None:
        """Samples after the open event's last one over the threshold (an isolated
        crossing's included): its peaks take them only if a run joins it later."""
        if self._open is not None:
            self._open.after = self._open.after.then(held)

    def _judged(self, run: _Run, near: bool) -> list[ContactEvent]:
        """A run whose next run is known (``near``: within the isolation window, in the
        same piece): an isolated crossing is dropped (it neither starts, extends nor
        joins an event); another run is joined to the open event when within ``merge_s``
        of it in the same piece, else the open event is closed (returned unless too
        short) and the run opens the next."""
        short = self._shorter(run.last - run.start, self.min_duration_s)
        short = short and not run.held.collision
        if short and not (run.near or near):
            self._drop(run.held.dropped(run.start, run.last, "isolated"))
            self._between(run.held)
            self._between(run.tail)
            return []
        ev = self._open
        if (
            ev is not None
            and ev.piece == run.piece
            and not self._longer(run.start - ev.last, self.merge_s)
        ):
            ev.held = ev.held.then(ev.after).then(run.held)
            ev.last, ev.after = run.last, run.tail
            return []
        self._open = _Open(run.start, run.last, run.piece, run.held, run.tail)
        return [] if ev is None else self._closed(ev)

    def _closed(self, event: _Open) -> list[ContactEvent]:
        """The event closed, or none when it is shorter than ``min_duration_s`` and
        stayed at the contact level."""
        if (
            self._shorter(event.last - event.start, self.min_duration_s)
            and not event.held.collision
        ):
            self._drop(event.held.dropped(event.start, event.last, "short"))
            return []
        return [event.closed()]


def detect(
    t: ArrayLike,
    r: ArrayLike,
    thresholds: Thresholds,
    *,
    std: ArrayLike | None = None,
    standstill: ArrayLike | None = None,
    merge_s: float = DEFAULT_MERGE_S,
    min_duration_s: float = DEFAULT_MIN_DURATION_S,
    restarts: ArrayLike | None = None,
    sample_period_s: float | None = None,
) -> list[ContactEvent]:
    """Contact events of a whole residual (module docstring): :class:`EventDetector` fed
    the log as one block.

    Parameters
    ----------
    t : array_like, shape (N,)
        Sample times [s].
    r : array_like, shape (N, n)
        Residual [N m]; NaN where the observer did not run (never an event there).
    thresholds : Thresholds
    std : array_like, shape (N, n), optional
        :func:`~dynid.observer.detection.residual_std` of the samples (for thresholds
        that use the uncertainty).
    standstill : array_like, shape (N, n), optional
        :func:`~dynid.observer.detection.standstill_series` of the samples (for
        thresholds that use it).
    merge_s : float
        Runs over the threshold closer than this [s] are one event (>= 0).
    min_duration_s : float
        Events shorter than this [s] at the contact level are dropped (>= 0).
    restarts : array_like of int, optional
        Samples where the observer started again (the first of each piece of a log cut
        at its gaps): no event spans one.
    sample_period_s : float, optional
        See :class:`EventDetector` (default: the median step of ``t``).

    Returns
    -------
    list of ContactEvent
        In time order.

    Raises
    ------
    ShapeError
        Shapes that disagree, thresholds of another joint count.
    OptionError
        A negative ``merge_s`` or ``min_duration_s``.
    """
    det = EventDetector(
        thresholds,
        merge_s=merge_s,
        min_duration_s=min_duration_s,
        restarts=restarts,
        sample_period_s=sample_period_s,
    )
    return det.feed(t, r, std=std, standstill=standstill) + det.finish()
