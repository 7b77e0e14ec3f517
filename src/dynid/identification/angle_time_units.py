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
  ``--units t=ms`` (:func:`time_unit_finding`). The unit is read from the data against
  the one the time column was read in (:class:`GivenUnits`): stamps in microseconds read
  with ``--units t=ms`` are told ``t=us``, not the ``t=ms`` already given.

A log may hold both (times in ms and positions in degrees): the checks that find them say
them in one message with one hint, ``--units t=ms,q=deg`` (:func:`joined_unit_findings`),
written into the ``--units`` given (:func:`units_with`: ``--units t=us,q=deg,dq=deg/s,tau=-1``,
the whole option to run again).
"""

from __future__ import annotations

import math
from collections.abc import Mapping, Sequence
from dataclasses import dataclass, field

import numpy as np

from .. import signals
from ..model.robot import Robot
from .log import TorqueLog

__all__ = [
    "RATE_AGREES",
    "GivenUnits",
    "named_unit",
    "unit_name",
    "units_with",
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

#: The ``--units`` spellings of each quantity a unit finding names, and their factor to SI.
_UNIT_NAMES: dict[str, dict[str, float]] = {
    "t": {"s": 1.0, "ms": 1e-3, "us": 1e-6, "ns": 1e-9},
    "q": {"rad": 1.0, "deg": math.pi / 180},
    "dq": {"rad/s": 1.0, "deg/s": math.pi / 180},
    "ddq": {"rad/s^2": 1.0, "deg/s^2": math.pi / 180},
}
#: The ``--units`` spellings of a prismatic joint's quantities [to SI].
_LENGTH_NAMES: dict[str, dict[str, float]] = {
    "q": {"m": 1.0, "mm": 1e-3},
    "dq": {"m/s": 1.0, "mm/s": 1e-3},
    "ddq": {"m/s^2": 1.0, "mm/s^2": 1e-3},
}
#: The quantities in the order ``--units`` entries are written (a new one goes after its
#: neighbour: ``q=deg,dq=deg/s``).
_ORDER = ("t", "q", "dq", "ddq")


@dataclass(frozen=True, slots=True)
class GivenUnits:
    """The ``--units`` a log was read with, for the unit findings to say the whole option.

    Attributes
    ----------
    text : str or None
        The ``--units`` text as given (``"t=us,q=deg,tau=-1"``); None when not known (a
        TOML map, the defaults).
    factors : mapping of str to float
        Quantity -> the factor to SI it was read with (``{"q": pi / 180}``; of ``q``,
        ``dq``, ``ddq`` the revolute joints'); missing: 1.
    lengths : mapping of str to float
        Quantity -> the factor to SI the prismatic joints' ``q``, ``dq``, ``ddq`` were
        read with (``{"dq": 1e-3}`` for ``dq=mm/s``); missing: 1.
    files : mapping of str to GivenUnits
        A file's name -> the units it was read with where they are its own (``--units
        rec4.csv:t=ms``), the same ``text``; the other files read with these.
    """

    text: str | None = None
    factors: Mapping[str, float] = field(default_factory=dict)
    lengths: Mapping[str, float] = field(default_factory=dict)
    files: Mapping[str, GivenUnits] = field(default_factory=dict)

    def of(self, name: str) -> GivenUnits:
        """The units the file ``name`` was read with (:attr:`files`, else these)."""
        return self.files.get(name, self)

    def factor(self, quantity: str) -> float:
        """The factor [1] ``quantity`` was read with, its sign left out (a sign flip is no
        unit)."""
        return abs(float(self.factors.get(quantity, 1.0)))

    def length_factor(self, quantity: str) -> float:
        """The factor [1] a prismatic joint's ``quantity`` was read with, its sign left
        out."""
        return abs(float(self.lengths.get(quantity, 1.0)))


def unit_name(quantity: str, factor: float) -> str:
    """The ``--units`` spelling of ``factor`` [1, to SI] for ``quantity``: ``deg/s`` for
    ``dq`` at ``pi / 180``, ``us`` for ``t`` at ``1e-6``; the number otherwise."""
    return named_unit(quantity, factor) or f"{factor:.10g}"


def named_unit(
    quantity: str, factor: float, length: bool = False, rel_tol: float = 1e-9
) -> str | None:
    """The ``--units`` unit name of ``factor`` [1, to SI] for ``quantity`` (of a
    prismatic joint's with ``length``: ``mm/s`` for ``dq`` at ``1e-3``), or None when no
    name has it (within ``rel_tol``)."""
    for name, f in (_LENGTH_NAMES if length else _UNIT_NAMES).get(quantity, {}).items():
        if math.isclose(factor, f, rel_tol=rel_tol):
            return name
    return None


def units_with(text: str | None, entries: Mapping[str, str] | Sequence[tuple[str, str]]) -> str:
    """The ``--units`` text ``text`` with ``entries`` (quantity -> unit, or such pairs) in
    place of its own for those quantities, a new one written after its neighbour in ``t,
    q, dq, ddq`` (``units_with("t=us,q=deg,tau=-1", {"dq": "deg/s"})`` is
    ``"t=us,q=deg,dq=deg/s,tau=-1"``); ``entries`` alone without a text. A joint
    quantity's unit replaces the one of its kind alone (``q=mm,q=deg`` with ``dq=mm/s``
    and ``dq=deg/s`` for a robot of prismatic and revolute joints)."""
    parts = [p.strip() for p in (text or "").split(",") if p.strip()]
    keys = [p.partition("=")[0].strip() for p in parts]
    kinds = [_kind(p.partition("=")[2]) for p in parts]
    pairs = list(entries.items()) if isinstance(entries, Mapping) else list(entries)
    for key, unit in pairs:
        entry = f"{key}={unit}"
        same = [i for i, k in enumerate(keys) if k == key and kinds[i] in (None, _kind(unit))]
        if same:
            parts[same[0]] = entry
            kinds[same[0]] = _kind(unit)
            continue
        before = _ORDER[: _ORDER.index(key) + 1] if key in _ORDER else ()
        at = max((i + 1 for i, k in enumerate(keys) if k in before), default=0)
        at = at if key in _ORDER else len(parts)
        parts.insert(at, entry)
        keys.insert(at, key)
        kinds.insert(at, _kind(unit))
    return ",".join(parts)


def _kind(unit: str) -> str | None:
    """``"length"`` or ``"angle"`` of a joint quantity's unit (``mm/s``, ``deg``); None
    for another (a number, a time unit)."""
    head = unit.strip().partition("/")[0]
    return "length" if head in ("m", "mm") else "angle" if head in ("rad", "deg") else None


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


def velocity_rate_factor(log: TorqueLog, skip: Sequence[int] = ()) -> float:
    """``k`` of ``d q / dt ~ k dq`` [1]: 1 when ``t``, ``q`` and ``dq`` share their units.

    The positions' differences over their time steps against the mean of the two samples'
    recorded velocities, pooled over every joint by least squares; a step where a position
    jumps by more than half a turn (a wrap) or the time by more than 1.5 median steps (a
    gap) is left out; the joints ``skip`` (from 0) are left out too (a prismatic joint's
    velocities in mm/s, another finding). NaN for velocities derived from the positions,
    fewer than 5 samples or a log that does not move.
    """
    if log.dq_derived or log.n_samples < 5:
        return float("nan")
    dt = np.diff(log.t)
    ok = dt <= 1.5 * float(np.median(dt))
    num = den = 0.0
    for j in range(log.n):  # one joint at a time: temporaries of one column (long logs)
        if j in skip:
            continue
        dqj = np.diff(log.q[:, j])
        v = 0.5 * (log.dq[1:, j] + log.dq[:-1, j])
        keep = ok & (np.abs(dqj) <= np.pi)
        num += float(np.sum(dqj[keep] / dt[keep] * v[keep]))
        den += float(np.sum(v[keep] * v[keep]))
    return num / den if den > 0 else float("nan")


def time_unit(
    log: TorqueLog, given: float = 1.0, skip: Sequence[int] = ()
) -> tuple[str, float] | None:
    """The unit of ``log``'s time column when it is not the one it was read in: its
    recorded velocities a power of ten (within 25 %) times the rate of change of its
    positions per second as read, so that the column's unit is ``given`` [s] (the factor
    it was read with: 1e-3 for ``--units t=ms``) times that factor, one of s, ms, us, ns:
    its ``--units t=`` spelling and its length [s] (``("ms", 1e-3)``; ``("us", 1e-6)`` for
    stamps in microseconds read as ms); None otherwise, or when it is ``given``
    (:func:`velocity_rate_factor`, without the joints ``skip``)."""
    k = velocity_rate_factor(log, skip)
    if not np.isfinite(k) or k <= 0:
        return None
    for unit, size in (("s", 1.0), *_TIME_UNITS):
        if abs(k * given / size - 1.0) < RATE_AGREES:
            return None if math.isclose(size, given, rel_tol=1e-9) else (unit, size)
    return None


def joined_unit_findings(findings: Sequence[str], given: str | None = None) -> str:
    """One line of several unit findings of one file, each ``what; hint: --units a=b``:
    their reasons joined, and one hint, ``--units t=ms,q=deg`` (a hint that is not a
    plain ``--units`` list is kept after it), written into the ``--units`` text ``given``
    when there is one (:func:`units_with`: the whole option to run again)."""
    whats, units, others = [], [], []
    for f in findings:
        what, _, hint = f.partition("; hint: ")
        whats.append(what)
        head, _, rest = hint.partition(" ")
        if hint.startswith("--units ") and " " not in rest:
            units.append(rest)
        elif hint:
            others.append(hint)
    if units and given:
        pairs = (u.partition("=") for u in ",".join(units).split(","))
        units = [units_with(given, [(k, v) for k, _, v in pairs])]
    hints = ([f"--units {','.join(units)}"] if units else []) + others
    return "; and ".join(whats) + (f"; hint: {'; '.join(hints)}" if hints else "")


def time_unit_finding(name: str, log: TorqueLog, given: float = 1.0) -> str | None:
    """One line naming the file ``name`` when its time column is in another unit than
    the one it was read in, ``given`` [s] (:func:`time_unit`); None otherwise."""
    said = time_unit_said(log, given)
    return None if said is None else f"{name}: {said}"


def time_unit_said(log: TorqueLog, given: float = 1.0, skip: Sequence[int] = ()) -> str | None:
    """:func:`time_unit_finding` without the file's name (judged without the joints
    ``skip``)."""
    found = time_unit(log, given, skip)
    if found is None:
        return None
    unit, size = found
    k = velocity_rate_factor(log, skip)
    read = unit_name("t", given)
    if math.isclose(given, 1.0, rel_tol=1e-9):
        per, said = "per unit of its time column", f"{unit}, not seconds (t x {1 / size:g})"
    else:
        per = f"per second of its time column as read (--units t={read})"
        r = given / size
        too = "long" if r > 1 else "short"
        said = f"{unit}, not {read} (its times read {max(r, 1 / r):g} times too {too})"
    return (
        f"its recorded velocities are {1 / k:.4g} times the rate of change of its positions "
        f"{per}: the time column looks like {said}; every filter, derivative and frequency "
        f"read from it would be off by that factor; hint: --units t={unit}"
    )
