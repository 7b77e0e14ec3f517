"""Positions in degrees and times in milliseconds read as radians and seconds.

* **Degrees**: positions whose range exceeds ``2 pi`` on a revolute joint while the range
  divided by ``180 / pi`` fits in the joint's limits, unless the velocities say otherwise:
  where ``dq`` agrees with the derivative of ``q`` (one unit for both) the positions are
  radians unless the velocities are too fast for radians (above the joint's ``dq_max``, or
  ``2 pi`` rad/s without one); an unwrapped continuous joint that turns several times is not
  degrees. Velocities ``180 / pi`` times slower than the derivative of ``q`` are
  (``--units q=deg``; both in degrees: ``--units q=deg,dq=deg/s``).
* **Milliseconds**: logged velocities ``1e3`` times the derivative of the positions (or a
  median time step of at least 0.5 s with integer steps when no velocities were logged):
  ``--units t=ms`` (:func:`time_unit_finding`).

A log may hold both (times in ms and positions in degrees): the checks that find them say
them in one message with one hint, ``--units t=ms,q=deg`` (:func:`joined_unit_findings`).
"""

from __future__ import annotations

from collections.abc import Sequence

import numpy as np

from .. import signals
from ..model.robot import Robot
from .log import TorqueLog

__all__ = [
    "RATE_AGREES",
    "degrees_findings",
    "joined_unit_findings",
    "time_unit",
    "time_unit_said",
    "milliseconds_findings",
    "rate_verdict",
    "joint_rate_factor",
    "time_unit_finding",
    "velocity_rate_factor",
]


#: Relative tolerance of "``dq`` agrees with the derivative of ``q``" (filtered velocities
#: lag and smooth: 25 % is far from the factor 57.3 of degrees either way).
RATE_AGREES = 0.25
#: Speed [rad/s] above which velocities are too fast for radians on a joint without dq_max.
_FAST_RAD_S = 2 * np.pi


def degrees_findings(robot: Robot, log: TorqueLog) -> list[str]:
    """The degrees finding (module docstring), or nothing."""
    q = log.q
    rev = ~np.asarray(robot.prismatic)
    lo, hi = np.min(q, axis=0), np.max(q, axis=0)
    span = hi - lo
    lim_lo = np.where(np.isfinite(robot.q_min), robot.q_min, -2 * np.pi)
    lim_hi = np.where(np.isfinite(robot.q_max), robot.q_max, 2 * np.pi)
    r = np.pi / 180.0
    suspect = rev & (span > 2 * np.pi) & (lo * r >= lim_lo - 0.1) & (hi * r <= lim_hi + 0.1)
    why: dict[int, tuple[str, str]] = {}
    for j in map(int, np.flatnonzero(suspect)):
        verdict = rate_verdict(robot, log, j)
        if verdict is None:
            suspect[j] = False
        else:
            why[j] = verdict
    if np.any(suspect) and np.sum(suspect) >= max(1, int(np.sum(rev & (span > 0.1))) // 2):
        j = int(np.flatnonzero(suspect)[0])
        reason, hint = why[j]
        return [
            f"positions look like degrees: joint {robot.joint_names[j]} spans "
            f"{span[j]:.4g} rad, which in degrees fits its limits{reason}; hint: {hint}"
        ]
    return []


def joint_rate_factor(log: TorqueLog, j: int) -> float:
    """``k`` [1] of ``d q / dt ~ k dq`` on joint ``j`` of ``log``, by least squares: 1 when
    its positions and velocities share a unit, ``180 / pi`` for positions in degrees and
    velocities in radians per second; NaN for fewer than 5 samples or a joint at rest."""
    t, q, v = log.t, log.q[:, j], np.ascontiguousarray(log.dq[:, j])
    den = float(v @ v)
    if t.size < 5 or not den > 0:
        return float("nan")
    return float(signals.derivative(t, q) @ v) / den  # in blocks: a long log's column


def rate_verdict(robot: Robot, log: TorqueLog, j: int) -> tuple[str, str] | None:
    """What the velocities of joint ``j`` say of positions that may be degrees: None (they
    are radians), or the reason and the hint of the warning.

    ``k`` is the least-squares factor of ``d q / dt ~ k dq``: 1 when ``q`` and ``dq``
    share a unit, ``180 / pi`` when ``q`` is in degrees and ``dq`` in radians per second.
    """
    k = joint_rate_factor(log, j)
    if not np.isfinite(k):
        return "", "--units q=deg"
    v = log.dq[:, j]
    deg = 180.0 / np.pi
    if abs(k / deg - 1.0) < RATE_AGREES:
        return (
            f", and its velocities are {k:.3g} times slower than the derivative of its "
            "positions (degrees against radians per second)",
            "--units q=deg",
        )
    if abs(k - 1.0) < RATE_AGREES:
        fast = float(robot.dq_max[j]) if np.isfinite(robot.dq_max[j]) else _FAST_RAD_S
        peak = float(np.quantile(np.abs(v), 0.99))
        if peak <= 1.5 * fast:
            return None  # one unit, and plausible radians per second: radians
        return (
            f", and its velocities, which agree with the derivative of its positions, reach "
            f"{peak:.4g} per second, too fast for radians (limit {fast:.3g} rad/s): both "
            "look like degrees",
            "--units q=deg,dq=deg/s" + (",ddq=deg/s^2" if log.ddq is not None else ""),
        )
    return "", "--units q=deg"


def milliseconds_findings(log: TorqueLog) -> list[str]:
    """The milliseconds finding of ``log`` (its velocities about ``1e3`` times the
    derivative of its positions: ``--units t=ms``), or nothing."""
    t, q, dq = log.t, log.q, log.dq
    if t.size < 5:
        return []
    num = den = 0.0
    for j in range(q.shape[1]):  # one joint at a time: temporaries of one column (long logs)
        v = np.ascontiguousarray(dq[:, j])
        num += float(signals.derivative(t, q[:, j]) @ v)  # in blocks: a long log's column
        den += float(v @ v)
    if den > 0:
        k = num / den
        if 3e-4 < k < 3e-3:
            return [
                f"the velocities are {1 / k:.3g} times the derivative of the positions: the "
                "time column looks like milliseconds; hint: --units t=ms"
            ]
    return []


#: Time units a time column may be recorded in instead of seconds: the ``--units t=``
#: spelling and its length [s].
_TIME_UNITS = (("ms", 1e-3), ("us", 1e-6), ("ns", 1e-9))


def velocity_rate_factor(log: TorqueLog) -> float:
    """``k`` of ``d q / dt ~ k dq`` [1]: 1 when ``t``, ``q`` and ``dq`` share their units.

    The positions' differences over their time steps against the mean of the two samples'
    recorded velocities, pooled over every joint by least squares; a step where a position
    jumps by more than half a turn (a wrap) or the time by more than 1.5 median steps (a
    gap) is left out. NaN for velocities derived from the positions, fewer than 5 samples
    or a log that does not move.
    """
    if log.dq_derived or log.n_samples < 5:
        return float("nan")
    dt = np.diff(log.t)
    ok = dt <= 1.5 * float(np.median(dt))
    num = den = 0.0
    for j in range(log.n):  # one joint at a time: temporaries of one column (long logs)
        dqj = np.diff(log.q[:, j])
        v = 0.5 * (log.dq[1:, j] + log.dq[:-1, j])
        keep = ok & (np.abs(dqj) <= np.pi)
        num += float(np.sum(dqj[keep] / dt[keep] * v[keep]))
        den += float(np.sum(v[keep] * v[keep]))
    return num / den if den > 0 else float("nan")


def time_unit(log: TorqueLog) -> tuple[str, float] | None:
    """The unit of ``log``'s time column when its recorded velocities are a power of ten
    (1e3, 1e6, 1e9, within 25 %) times the rate of change of its positions per unit of it:
    its ``--units t=`` spelling and its length [s] (``("ms", 1e-3)``); None otherwise
    (:func:`velocity_rate_factor`)."""
    k = velocity_rate_factor(log)
    if not np.isfinite(k) or k <= 0:
        return None
    for unit, size in _TIME_UNITS:
        if abs(k / size - 1.0) < RATE_AGREES:
            return unit, size
    return None


def joined_unit_findings(findings: Sequence[str]) -> str:
    """One line of several unit findings of one file, each ``what; hint: --units a=b``:
    their reasons joined, and one hint, ``--units t=ms,q=deg`` (a hint that is not a
    plain ``--units`` list is kept after it)."""
    whats, units, others = [], [], []
    for f in findings:
        what, _, hint = f.partition("; hint: ")
        whats.append(what)
        head, _, rest = hint.partition(" ")
        if hint.startswith("--units ") and " " not in rest:
            units.append(rest)
        elif hint:
            others.append(hint)
    hints = ([f"--units {','.join(units)}"] if units else []) + others
    return "; and ".join(whats) + (f"; hint: {'; '.join(hints)}" if hints else "")


def time_unit_finding(name: str, log: TorqueLog) -> str | None:
    """One line naming the file ``name`` when its time column is in ms, us or ns, not
    seconds (:func:`time_unit`); None otherwise."""
    said = time_unit_said(log)
    return None if said is None else f"{name}: {said}"


def time_unit_said(log: TorqueLog) -> str | None:
    """:func:`time_unit_finding` without the file's name."""
    found = time_unit(log)
    if found is None:
        return None
    unit, size = found
    k = velocity_rate_factor(log)
    return (
        f"its recorded velocities are {1 / k:.4g} times the rate of change of "
        f"its positions per unit of its time column: the time column looks like "
        f"{unit}, not seconds (t x {1 / size:g}); every filter, derivative and "
        f"frequency read from it would be off by that factor; hint: --units t={unit}"
    )
