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
reached the collision level. Neither moves an event's start: it is the first sample over
the threshold (a dropped run only goes unreported). ``merge_s = 0`` and
``min_duration_s = 0`` give every run over the threshold as its own event.

:class:`EventDetector` finds them a block of samples at a time: the event still open at
the end of a block (its start, last sample over the threshold, peaks, joints and level)
and the largest residual since its last sample over the threshold are carried to the
next block, so a long log is read with one block's temporaries and gives the events of
the whole log exactly. :func:`detect` is the detector fed the whole log as one block.
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import Literal

import numpy as np
from numpy.typing import ArrayLike, NDArray

from .. import _checks
from ..exceptions import OptionError, ShapeError
from .thresholds import Thresholds, threshold_series

__all__ = ["DEFAULT_MERGE_S", "DEFAULT_MIN_DURATION_S", "ContactEvent", "EventDetector", "detect"]

#: Runs over the threshold closer than this [s] are one event (module docstring).
DEFAULT_MERGE_S = 0.2
#: Events shorter than this [s] (first to last sample over the threshold) are dropped
#: unless they reached the collision level (module docstring).
DEFAULT_MIN_DURATION_S = 0.01


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
    level : {"contact", "collision"}
    """

    start: float
    end: float
    joints: tuple[int, ...]
    peak: tuple[float, ...]
    level: Literal["contact", "collision"]


@dataclass(slots=True)
class _Stretch:
    """What a stretch of samples contributes to an event: per joint the largest ``|r|``
    (n,) and ``r`` at its first occurrence, the joints over the contact threshold, and
    whether some joint passed its collision threshold."""

    top: NDArray[np.float64]
    value: NDArray[np.float64]
    joints: NDArray[np.bool_]
    collision: bool

    @staticmethod
    def empty(n: int) -> _Stretch:
        return _Stretch(np.full(n, -np.inf), np.zeros(n), np.zeros(n, dtype=bool), False)

    @staticmethod
    def of(r: NDArray[np.float64], over: NDArray[np.bool_], beyond: NDArray[np.bool_]) -> _Stretch:
        """Of the samples ``r`` (m, n), over the contact (``over``) and the collision
        (``beyond``) thresholds (m, n)."""
        n = r.shape[1]
        if r.shape[0] == 0:
            return _Stretch.empty(n)
        k = np.argmax(np.abs(r), axis=0)
        value = r[k, np.arange(n)]
        joints: NDArray[np.bool_] = np.asarray(over.any(axis=0))
        return _Stretch(np.abs(value), value, joints, bool(beyond.any()))

    def then(self, later: _Stretch) -> _Stretch:
        """This stretch followed by ``later``: a peak of ``later`` replaces one of this
        stretch only when larger (the first of equal magnitudes kept, as ``argmax``)."""
        take = later.top > self.top
        return _Stretch(
            np.where(take, later.top, self.top),
            np.where(take, later.value, self.value),
            self.joints | later.joints,
            self.collision or later.collision,
        )


@dataclass(slots=True)
class _Open:
    """An event not closed yet: its first and last sample over the threshold (time [s]
    and piece), what its samples hold, and what the samples after its last one over
    the threshold hold (joined to it only if another sample over the threshold follows
    within ``merge_s``)."""

    start: float
    last: float
    piece: int
    held: _Stretch
    after: _Stretch
    since: int = 0  # samples fed after its last one over the threshold

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
        Runs over the threshold closer than this [s] are one event (>= 0).
    min_duration_s : float
        Events shorter than this [s] at the contact level are dropped (>= 0).
    restarts : array_like of int, optional
        Samples of the log (counted from its first, over every block) where the observer
        started again (the first of each piece of a log cut at its gaps): no event spans
        one.

    Raises
    ------
    OptionError
        A negative ``merge_s`` or ``min_duration_s``.

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
    ) -> None:
        if not merge_s >= 0:
            raise OptionError(f"merge_s must be >= 0 [s]; got {merge_s}")
        if not min_duration_s >= 0:
            raise OptionError(f"min_duration_s must be >= 0 [s]; got {min_duration_s}")
        self.thresholds, self.merge_s = thresholds, float(merge_s)
        self.min_duration_s = float(min_duration_s)
        self._restarts = np.sort(np.asarray([] if restarts is None else restarts, dtype=np.int64))
        self._next = 0  # the log's sample the next block starts at
        self._open: _Open | None = None

    def feed(
        self,
        t: ArrayLike,
        r: ArrayLike,
        *,
        std: ArrayLike | None = None,
        standstill: ArrayLike | None = None,
    ) -> list[ContactEvent]:
        """The events closed by the next block of samples (an event still open at its
        end is carried to the next block or :meth:`finish`).

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
        seen: NDArray[np.bool_] = np.all(np.isfinite(ra), axis=1)
        if std is not None:  # NaN where not observed, as r
            std = np.where(seen[:, None], np.asarray(std, dtype=np.float64), 0.0)
        ra = np.where(seen[:, None], ra, 0.0)
        contact, collision = threshold_series(self.thresholds, m, std, standstill)
        first, self._next = self._next, self._next + m
        over = np.abs(ra) > contact
        hit = np.flatnonzero(over.any(axis=1))
        out: list[ContactEvent] = []
        if hit.size == 0:
            if self._open is not None:
                beyond = np.abs(ra) > collision
                self._open.after = self._open.after.then(_Stretch.of(ra, over, beyond))
                self._open.since += m
            return out
        piece = np.searchsorted(self._restarts, first + hit, side="right")
        # a run: samples over the threshold one after the other, or closer than merge_s
        apart = (np.diff(hit) > 1) & (ta[hit[1:]] - ta[hit[:-1]] > self.merge_s)
        split = apart | (piece[1:] != piece[:-1])
        runs = np.split(np.arange(hit.size), np.flatnonzero(split) + 1)
        beyond = np.abs(ra) > collision
        for i, run in enumerate(runs):
            a, b = int(hit[run[0]]), int(hit[run[-1]]) + 1
            joins = (
                i == 0
                and self._open is not None
                and (
                    (a == 0 and self._open.since == 0)  # the next sample after the last block's
                    or not ta[a] - self._open.last > self.merge_s
                )
                and int(piece[run[0]]) == self._open.piece
            )
            if joins:
                assert self._open is not None
                held = self._open.held.then(self._open.after)
                held = held.then(_Stretch.of(ra[:b], over[:b], beyond[:b]))
                self._open.held = held
            else:
                if self._open is not None:
                    out += self._closed(self._open)
                self._open = _Open(
                    float(ta[a]), 0.0, 0, _Stretch.of(ra[a:b], over[a:b], beyond[a:b]),
                    _Stretch.empty(ra.shape[1]),
                )  # fmt: skip
            self._open.last, self._open.piece = float(ta[b - 1]), int(piece[run[-1]])
            self._open.after = _Stretch.empty(ra.shape[1])
            if i < len(runs) - 1:
                out += self._closed(self._open)
                self._open = None
        assert self._open is not None
        b = int(hit[-1]) + 1
        self._open.after = _Stretch.of(ra[b:], over[b:], beyond[b:])
        self._open.since = m - b
        return out

    def finish(self) -> list[ContactEvent]:
        """The event still open after the last block (none or one)."""
        done, self._open = self._open, None
        return [] if done is None else self._closed(done)

    def _closed(self, event: _Open) -> list[ContactEvent]:
        """The event closed, or none when it is shorter than ``min_duration_s`` and
        stayed at the contact level."""
        if event.last - event.start < self.min_duration_s and not event.held.collision:
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
        thresholds, merge_s=merge_s, min_duration_s=min_duration_s, restarts=restarts
    )
    return det.feed(t, r, std=std, standstill=standstill) + det.finish()
