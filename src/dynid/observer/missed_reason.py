"""Why a labelled contact was missed: the torque it put on a joint against the threshold
the detection applied there, sample by sample.

A contact no event detects (:class:`~dynid.observer.scoring.MissedContact`) is read per
joint and sample over the contact: its torque (the true ``|tau_ext|`` where the log holds
it, else ``|r|``, the residual) against the contact threshold in force at that sample
(:func:`~dynid.observer.thresholds.threshold_series`: the series the detection compared
``|r|`` with, ``k sigma(t) + nu`` with the model's uncertainty, plus the standstill margin
where the joint stood still). The joint and sample reported are those whose torque came
closest to the threshold (the largest ratio); the reason:

* :data:`DROPPED`: the detection dropped a crossing over the contact threshold that
  starts where an event would have detected the contact (from the score's lead before
  its start to its tolerance after its end): shorter than the minimum duration
  (:attr:`~dynid.observer.events.EventDetector.dropped`);
* :data:`BELOW_AT_REST`: that joint stood still there (inside its friction's standstill
  band: the threshold holds the standstill margin) and its torque stayed below it (a
  limit of detection at rest: the friction there may hold any torque up to its Coulomb
  level);
* :data:`BELOW_MOVING`: it moved, and its torque stayed below the threshold;
* :data:`UNEXPLAINED`: its torque passed the threshold, and nothing here explains the
  miss (labels off in time, or an event that started before the contact's window).

(A 37 N push on a UR5's shoulder standing still, residual 5.14 N m: called unexplained
against the fixed at-rest level 4.85 N m when the threshold in force there, with the
standstill margin as it stood, was 6.3 N m.)
"""

from __future__ import annotations

import dataclasses
from collections.abc import Sequence

import numpy as np
from numpy.typing import ArrayLike, NDArray

from .events import DroppedCrossing
from .scoring import MissedContact

__all__ = [
    "BELOW_AT_REST",
    "BELOW_MOVING",
    "DROPPED",
    "UNEXPLAINED",
    "LabelledSamples",
    "explained",
    "interval_rows",
    "reason_words",
]

#: The joint stood still and its torque stayed below the threshold in force (its
#: standstill margin included).
BELOW_AT_REST = "below_at_rest"
#: The joint moved and its torque stayed below the threshold in force.
BELOW_MOVING = "below_moving"
#: The detection dropped a crossing there as shorter than the minimum duration.
DROPPED = "dropped_crossing"
#: The torque passed the threshold in force: nothing here explains the miss.
UNEXPLAINED = "unexplained"


def interval_rows(t: ArrayLike, start: float, end: float) -> tuple[int, int]:
    """The samples ``[i, j)`` of times ``t`` (N,) [s] from ``start`` to ``end`` [s]."""
    t = np.asarray(t, dtype=np.float64)
    return int(np.searchsorted(t, start, "left")), int(np.searchsorted(t, end, "right"))


def explained(
    m: MissedContact,
    t: ArrayLike,
    torque: ArrayLike,
    level: ArrayLike,
    still: ArrayLike,
    *,
    true_torque: bool,
    dropped: Sequence[DroppedCrossing] = (),
    window: tuple[float, float] = (0.0, 0.0),
) -> MissedContact:
    """``m`` with its reason (module docstring).

    Parameters
    ----------
    m : MissedContact
    t : array_like, shape (k,)
        The times of the contact's samples [s].
    torque : array_like, shape (k, n)
        The true ``|tau_ext|`` (``true_torque``) or ``|r|`` at each of them [N m] (NaN:
        not observed).
    level : array_like, shape (k, n)
        The contact threshold in force at each [N m] (NaN: not observed).
    still : array_like of bool, shape (k, n)
        The joint inside its friction's standstill band there
        (:func:`~dynid.observer.rest_margin.at_rest`; the threshold then holds the
        standstill margin).
    true_torque : bool
        ``torque`` is the true external torque, not the residual.
    dropped : sequence of DroppedCrossing
        The crossings the detection dropped on the log.
    window : (float, float)
        How long before the contact's start and after its end [s] an event starting
        detects it (the score's ``lead_s`` and ``tolerance_s``).

    Returns
    -------
    MissedContact
        With ``reason``, ``joint`` (0-based), ``torque`` and ``threshold`` [N m] at the
        time ``at`` [s] (the crossing's start and peak for :data:`DROPPED`),
        ``true_torque``; unchanged where no joint's torque is known.
    """
    for d in dropped:
        if m.start - window[0] <= d.start <= m.end + window[1]:
            j = d.joint - 1
            top = abs(d.peak[j])
            return dataclasses.replace(
                m, reason=DROPPED, joint=j, torque=top, threshold=top / d.ratio[j],
                true_torque=False, at=d.start,
            )  # fmt: skip
    x = np.asarray(torque, dtype=np.float64)
    lev = np.asarray(level, dtype=np.float64)
    with np.errstate(divide="ignore", invalid="ignore"):
        ratio = np.where(np.isfinite(x) & (lev > 0), x / lev, np.nan)
    if not np.any(np.isfinite(ratio)):
        return m
    s, j = (int(k) for k in np.unravel_index(int(np.nanargmax(ratio)), ratio.shape))
    at_rest = bool(np.asarray(still, dtype=bool)[s, j])
    reason = UNEXPLAINED if ratio[s, j] > 1.0 else BELOW_AT_REST if at_rest else BELOW_MOVING
    return dataclasses.replace(
        m,
        reason=reason,
        joint=j,
        torque=float(x[s, j]),
        threshold=float(lev[s, j]),
        true_torque=true_torque,
        at=float(np.asarray(t, dtype=np.float64)[s]),
    )


def reason_words(m: MissedContact, names: Sequence[str]) -> str:
    """``joint4 stood still: its true torque came closest to the threshold in force at
    1.2 s, 0.5 N m against 0.84 N m (its standstill margin included)``: the reason of a
    missed contact in words, its joint by ``names``; empty without one."""
    if m.reason is None or m.joint is None or m.torque is None or m.threshold is None:
        return ""
    name = names[m.joint] if m.joint < len(names) else f"joint {m.joint + 1}"
    at = "" if m.at is None else f" at {m.at:.3f} s"
    if m.reason == DROPPED:
        return (
            f"the detection dropped a crossing there as shorter than the minimum duration "
            f"({name}{at}: its residual's peak {m.torque:.3g} N m, "
            f"{m.torque / m.threshold:.3g} x the threshold in force; events.json's dropped)"
        )
    what = "true torque" if m.true_torque else "residual"
    pair = f"{m.torque:.3g} N m against {m.threshold:.3g} N m"
    if m.reason == BELOW_AT_REST:
        return (
            f"{name} stood still: its {what} came closest to the threshold in force{at}, "
            f"{pair} (its standstill margin included)"
        )
    if m.reason == BELOW_MOVING:
        return f"{name} moved: its {what} came closest to the threshold in force{at}, {pair}"
    return (
        f"unexplained: {name}'s {what} passed the threshold in force{at}, {pair} "
        "(labels off in time, or an event that started before the contact?)"
    )


class LabelledSamples:
    """Over a log's labelled samples, kept a block at a time (the residual's series may
    not be): ``|r|`` and the contact threshold in force, for the reason of a missed
    contact."""

    def __init__(self, flags: ArrayLike, n: int) -> None:
        f = np.asarray(flags, dtype=np.float64)
        self._on = np.nan_to_num(f) != 0  # (N,)
        self._row = np.cumsum(self._on) - 1  # each labelled sample's row
        k = int(self._on.sum())
        self._abs, self._level = np.full((k, n), np.nan), np.full((k, n), np.nan)

    def add(self, a: int, r: NDArray[np.float64], level: NDArray[np.float64]) -> None:
        """The residual ``r`` (m, n) [N m] of samples ``a .. a + m`` and the contact
        threshold ``level`` (m, n) [N m] the detection compared it with."""
        on = self._on[a : a + r.shape[0]]
        if on.any():
            rows = self._row[a : a + r.shape[0]][on]
            self._abs[rows], self._level[rows] = np.abs(r[on]), level[on]

    def samples(self, i: int, j: int) -> NDArray[np.intp]:
        """The indices in the log of the labelled samples among ``[i, j)``."""
        return np.flatnonzero(self._on[i:j]) + i

    def rows(self, i: int, j: int) -> tuple[NDArray[np.float64], NDArray[np.float64]]:
        """``|r|`` and the threshold [N m], each (k, n), of the labelled samples among
        ``[i, j)`` (:meth:`samples`)."""
        rows = self._row[i:j][self._on[i:j]]
        return self._abs[rows], self._level[rows]
