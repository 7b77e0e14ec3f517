"""Why a labelled contact was missed: the torque it put on a joint against that joint's
threshold.

A contact no event detects (:class:`~dynid.observer.scoring.MissedContact`) is read per
joint: its torque (the largest true ``|tau_ext|`` over the contact where the log holds it,
else the largest ``|r|``, the residual) against the threshold that applied, the *at-rest*
one where the joint stood still inside its friction's standstill band through the whole
contact (:func:`~dynid.observer.rest_margin.at_rest`; ``thresholds.json``'s ``at_rest``,
:func:`~dynid.observer.detection.undetected_at_rest`), else the *moving* one
(``detectable``, :func:`~dynid.observer.calibration_check.detectable`). The joint reported
is the one whose torque came closest to its threshold (the largest ratio); the reason:

* :data:`BELOW_AT_REST`: that joint stood still and its torque is below its at-rest
  threshold (a limit of detection at rest: the friction there may hold any torque up to
  its Coulomb level);
* :data:`BELOW_MOVING`: its torque is below its moving threshold;
* :data:`UNEXPLAINED`: its torque reached the threshold, and nothing here explains the
  miss (a crossing the minimum duration dropped, or labels off in time).

(A 0.5 N m push on a UR5's joint 4 standing still, at-rest threshold 0.84 N m: missed
with no reason said before.)
"""

from __future__ import annotations

import dataclasses
from collections.abc import Sequence

import numpy as np
from numpy.typing import ArrayLike, NDArray

from .scoring import MissedContact

__all__ = [
    "BELOW_AT_REST",
    "BELOW_MOVING",
    "UNEXPLAINED",
    "LabelledResidual",
    "explained",
    "interval_rows",
    "reason_words",
]

#: The joint stood still and its torque is below its at-rest threshold.
BELOW_AT_REST = "below_at_rest"
#: The joint moved and its torque is below its moving threshold (``detectable``).
BELOW_MOVING = "below_moving"
#: The torque reached the threshold: nothing here explains the miss.
UNEXPLAINED = "unexplained"


def interval_rows(t: ArrayLike, start: float, end: float) -> tuple[int, int]:
    """The samples ``[i, j)`` of times ``t`` (N,) [s] from ``start`` to ``end`` [s]."""
    t = np.asarray(t, dtype=np.float64)
    return int(np.searchsorted(t, start, "left")), int(np.searchsorted(t, end, "right"))


def explained(
    m: MissedContact,
    torque: ArrayLike,
    still: ArrayLike,
    at_rest: ArrayLike,
    moving: ArrayLike,
    *,
    true_torque: bool,
) -> MissedContact:
    """``m`` with its reason (module docstring).

    Parameters
    ----------
    m : MissedContact
    torque : array_like, shape (n,)
        The largest ``|tau_ext|`` (``true_torque``) or ``|r|`` of each joint over the
        contact [N m] (NaN: not observed).
    still : array_like of bool, shape (n,)
        Each joint inside its standstill band through the whole contact.
    at_rest, moving : array_like, shape (n,)
        Each joint's threshold standing still and moving [N m].
    true_torque : bool
        ``torque`` is the true external torque, not the residual.

    Returns
    -------
    MissedContact
        With ``reason``, ``joint`` (0-based), ``torque`` and ``threshold`` [N m],
        ``true_torque``; unchanged where no joint's torque is known.
    """
    x = np.asarray(torque, dtype=np.float64)
    s = np.asarray(still, dtype=bool)
    level = np.where(s, np.asarray(at_rest, dtype=np.float64), np.asarray(moving, np.float64))
    with np.errstate(divide="ignore", invalid="ignore"):
        ratio = np.where(np.isfinite(x), x / level, np.nan)
    if not np.any(np.isfinite(ratio)):
        return m
    j = int(np.nanargmax(ratio))
    reason = UNEXPLAINED if ratio[j] >= 1.0 else BELOW_AT_REST if s[j] else BELOW_MOVING
    return dataclasses.replace(
        m,
        reason=reason,
        joint=j,
        torque=float(x[j]),
        threshold=float(level[j]),
        true_torque=true_torque,
    )


def reason_words(m: MissedContact, names: Sequence[str]) -> str:
    """``joint4 stood still: its true torque 0.5 N m is below its at-rest threshold 0.84
    N m``: the reason of a missed contact in words, its joint by ``names``; empty without
    one."""
    if m.reason is None or m.joint is None or m.torque is None or m.threshold is None:
        return ""
    name = names[m.joint] if m.joint < len(names) else f"joint {m.joint + 1}"
    what = "true torque" if m.true_torque else "residual's peak"
    size = f"its {what} {m.torque:.3g} N m"
    if m.reason == BELOW_AT_REST:
        return f"{name} stood still: {size} is below its at-rest threshold {m.threshold:.3g} N m"
    if m.reason == BELOW_MOVING:
        return f"{name}: {size} is below its moving threshold {m.threshold:.3g} N m"
    return (
        f"unexplained: {name}'s {what} {m.torque:.3g} N m reached its threshold "
        f"{m.threshold:.3g} N m (a crossing the minimum duration dropped, or labels off "
        "in time?)"
    )


class LabelledResidual:
    """The ``|r|`` of a log's labelled samples, kept a block at a time (the residual's
    series may not be), for the peak over a missed contact."""

    def __init__(self, flags: ArrayLike, n: int) -> None:
        f = np.asarray(flags, dtype=np.float64)
        self._on = np.nan_to_num(f) != 0  # (N,)
        self._row = np.cumsum(self._on) - 1  # each labelled sample's row
        self._abs = np.full((int(self._on.sum()), n), np.nan)

    def add(self, a: int, r: NDArray[np.float64]) -> None:
        """The residual ``r`` (m, n) [N m] of samples ``a .. a + m``."""
        on = self._on[a : a + r.shape[0]]
        if on.any():
            self._abs[self._row[a : a + r.shape[0]][on]] = np.abs(r[on])

    def peak(self, i: int, j: int) -> NDArray[np.float64]:
        """The largest ``|r|`` (n,) [N m] of each joint over the labelled samples ``[i,
        j)`` (NaN: none observed)."""
        rows = self._row[i:j][self._on[i:j]]
        x = self._abs[rows]
        ok = np.isfinite(x)
        out: NDArray[np.float64] = np.where(
            ok.any(axis=0), np.max(np.where(ok, x, -np.inf), axis=0), np.nan
        )
        return out
