"""Velocity columns in another angle unit than the positions, found before any fit.

A log whose positions are converted from degrees (``--units q=deg``) while its velocity
columns are not (``dq=deg/s`` forgotten) holds velocities ``180 / pi`` times the
derivative of its positions; a fit takes them as they are (a simulated Kinova Jaco2's log
read so was identified with exit 0, verdict "usable 17.8 %", its gravity torques 62 %
off). The reverse, velocities ``pi / 180`` times that derivative, is a log of positions in
degrees read as radians, or of velocities in rad/s read with ``dq=deg/s``.

Per joint that moves, ``k`` of ``d q / dt ~ k dq`` by least squares
(:func:`joint_rate_factors`; both sides averaged over the same short window, the steps at a
gap or a wrap left out, a joint whose two do not share their shape, correlation below
:data:`SHAPE_CORRELATION`, not judged). Where ``k`` is within
:data:`~dynid.identification.angle_time_units.RATE_AGREES` of ``pi / 180`` or of ``180 /
pi`` on most joints judged, :func:`velocity_scale_finding` says which column is in which
unit and the ``--units`` entry that reads it right: the speeds decide between the
velocities and the positions (the one whose velocities fit the joints' speed limits, 1.5
times theirs, or ``2 pi`` rad/s without one; both or neither: the velocities when they are
too fast, ``dq=deg/s``, the positions when too slow, ``q=deg``); acceleration columns read
in the velocities' unit are named with them (``ddq=deg/s^2``).

On a robot with prismatic and revolute joints, velocity columns of the prismatic joints
``1000`` times (or ``1 / 1000`` of) the derivative of their positions while the revolute
joints' agree are a length unit forgotten (``dq=mm/s`` beside ``q=mm``), not a time column
in ms, which would scale every joint alike (:func:`prismatic_scale_finding`, judged before
the time column).

A scale is not a lag: :mod:`~dynid.identification.derivative_columns` reads the lag of
columns of the positions' scale only.
"""

from __future__ import annotations

import math
from collections.abc import Sequence

import numpy as np
from numpy.typing import NDArray

from ..model.robot import Robot
from .angle_time_units import RATE_AGREES, GivenUnits, named_unit, unit_name
from .log import TorqueLog

__all__ = [
    "MAX_SAMPLES",
    "acceleration_rate_factors",
    "SHAPE_CORRELATION",
    "WINDOW_S",
    "joint_rate_factors",
    "prismatic_scale_finding",
    "velocity_scale_finding",
]

#: Samples read at most (the first ones).
MAX_SAMPLES = 200_000
#: The window [s] both sides are averaged over (the positions' differences' noise).
WINDOW_S = 0.01
#: Correlation of the positions' derivative with the recorded velocities below which a
#: joint is not judged (noise against noise, a joint at rest).
SHAPE_CORRELATION = 0.5
_DEG = 180.0 / math.pi
#: Speed [rad/s] of a joint without a speed limit above which velocities are too fast.
_FAST_RAD_S = 2 * math.pi


def _box(x: NDArray[np.float64], w: int) -> NDArray[np.float64]:
    """Moving average of the columns of ``x`` over ``w`` samples (valid part)."""
    if w <= 1:
        return x
    c = np.cumsum(np.vstack([np.zeros((1, x.shape[1])), x]), axis=0)
    return (c[w:] - c[:-w]) / w


def _rate_factors(
    t: NDArray[np.float64], x: NDArray[np.float64], v: NDArray[np.float64], wrap: bool
) -> NDArray[np.float64]:
    """Per column, ``k`` of ``d x / dt ~ k v`` by least squares over the steps of ``t``
    [s] (module docstring); the steps at a gap, and with ``wrap`` a jump of half a turn or
    more of ``x``, left out; NaN for a column not judged."""
    out = np.full(x.shape[1], np.nan)
    dt = np.diff(t)
    step = float(np.median(dt))
    dx = np.diff(x, axis=0)
    keep = (dt <= 1.5 * step)[:, None] & ((np.abs(dx) <= np.pi) if wrap else True)
    a = np.where(keep, dx / dt[:, None], 0.0)
    b = np.where(keep, 0.5 * (v[1:] + v[:-1]), 0.0)
    w = max(1, min(int(round(WINDOW_S / step)), (t.size - 1) // 4))
    a, b = _box(a, w), _box(b, w)
    for j in range(x.shape[1]):
        aj, bj = a[:, j], b[:, j]
        sa, sb = float(np.std(aj)), float(np.std(bj))
        if not (sa > 0 and sb > 0):
            continue
        c = float(np.mean((aj - aj.mean()) * (bj - bj.mean()))) / (sa * sb)
        if c >= SHAPE_CORRELATION:
            out[j] = float(aj @ bj) / float(bj @ bj)
    return out


def joint_rate_factors(log: TorqueLog) -> NDArray[np.float64]:
    """Per joint (n,), ``k`` [1] of ``d q / dt ~ k dq``: 1 when positions and velocities
    share a unit, ``pi / 180`` for velocities in deg/s beside positions in rad (module
    docstring); NaN for a joint not judged, and for every joint of velocities derived from
    the positions or a log of fewer than 8 samples."""
    if log.dq_derived or log.n_samples < 8:
        return np.full(log.n, np.nan)
    m = min(log.n_samples, MAX_SAMPLES)
    return _rate_factors(log.t[:m], np.asarray(log.q[:m]), np.asarray(log.dq[:m]), True)


def acceleration_rate_factors(log: TorqueLog) -> NDArray[np.float64]:
    """Per joint (n,), ``k`` [1] of ``d dq / dt ~ k ddq``: 1 when velocities and
    accelerations share a unit, ``pi / 180`` for accelerations in deg/s^2 beside
    velocities in rad/s; NaN for a joint not judged, and for every joint of a log without
    acceleration columns or of fewer than 8 samples."""
    if log.ddq is None or log.n_samples < 8:
        return np.full(log.n, np.nan)
    m = min(log.n_samples, MAX_SAMPLES)
    return _rate_factors(log.t[:m], np.asarray(log.dq[:m]), np.asarray(log.ddq[:m]), False)


def _scaled(k: NDArray[np.float64]) -> tuple[NDArray[np.bool_], float] | None:
    """The joints whose factors ``k`` read ``pi / 180`` (or ``180 / pi``, whichever more),
    and that scale [1] (the true values over those read), when they are at least half
    of those judged; None otherwise."""
    judged = np.isfinite(k)
    fast = judged & (np.abs(k * _DEG - 1.0) < RATE_AGREES)
    slow = judged & (np.abs(k / _DEG - 1.0) < RATE_AGREES)
    scaled, c = (fast, math.pi / 180) if fast.sum() >= slow.sum() else (slow, _DEG)
    if not scaled.any() or 2 * int(scaled.sum()) < int(judged.sum()):
        return None
    return scaled, c


def _blamed(
    robot: Robot, log: TorqueLog, joints: NDArray[np.intp], c: float, given: GivenUnits
) -> str:
    """``"dq"`` or ``"q"``: the column whose unit is wrong when the velocities are ``c``
    times the joints' (module docstring): the speeds first, then the column whose unit
    read right is one ``--units`` names (``rad/s`` for ``dq=deg/s`` given on rad/s), then
    the velocities when they are too fast, the positions when too slow."""
    lim = np.where(np.isfinite(robot.dq_max), robot.dq_max, _FAST_RAD_S)[joints]
    m = min(log.n_samples, MAX_SAMPLES)
    peak = np.quantile(np.abs(log.dq[:m][:, joints]), 0.99, axis=0)
    velocities = bool(np.all(peak * c <= 1.5 * lim))  # the velocities converted fit
    positions = bool(np.all(peak <= 1.5 * lim))  # the velocities as read fit
    if velocities != positions:
        return "dq" if velocities else "q"
    named_dq = _named("dq", given.factor("dq") * c)
    named_q = _named("q", given.factor("q") / c)
    if named_dq != named_q:
        return "dq" if named_dq else "q"
    return "dq" if c < 1.0 else "q"


def _named(quantity: str, factor: float) -> bool:
    """Whether ``factor`` is a unit ``--units`` names for ``quantity``."""
    return not unit_name(quantity, factor)[0].isdigit()


def _said(blame: str, c: float, given: GivenUnits) -> str:
    """What the scale ``c`` of the velocities means for the column ``blame``."""
    if blame == "dq":
        read = unit_name("dq", given.factor("dq"))
        read = read if "/" in read else f"{read} x rad/s"
        unit = "degrees" if c < 1.0 else "radians"
        return f"velocities in {unit} per second read as {read}"
    read = unit_name("q", given.factor("q"))
    read = read if read in ("rad", "deg") else f"{read} x rad"
    unit = "radians" if c < 1.0 else "degrees"
    return f"positions in {unit} read as {read}"


def velocity_scale_finding(
    robot: Robot, log: TorqueLog, given: GivenUnits | None = None, skip: Sequence[int] = ()
) -> str | None:
    """One line saying a joint-side ``log``'s velocity (or acceleration) columns are in
    another angle unit than its positions (velocities), with the ``--units`` entries that
    read them right given the units ``given`` applied (module docstring); None otherwise.

    Parameters
    ----------
    robot : Robot
        The model's robot (speed limits [rad/s], joint names).
    log : TorqueLog
        A joint-side log, read in SI with ``given``.
    given : GivenUnits, optional
        The units it was read with (default: none, every factor 1).
    skip : sequence of int
        Joints (from 0) another finding names already (positions in degrees).
    """
    given = given or GivenUnits()
    k = joint_rate_factors(log)
    k[list(skip)] = np.nan
    pri = np.asarray(robot.prismatic, dtype=bool)
    if not pri.all():  # an angle unit is the revolute joints' (the rail's: prismatic_scale_)
        k[pri] = np.nan
    if (found := _scaled(k)) is None:
        return _acceleration_finding(robot, log, given)
    scaled, c = found
    joints = np.flatnonzero(scaled)
    blame = _blamed(robot, log, joints, c, given)
    if blame == "dq":
        entries = {"dq": unit_name("dq", given.factor("dq") * c)}
        if log.ddq is not None and math.isclose(given.factor("ddq"), given.factor("dq")):
            entries["ddq"] = unit_name("ddq", given.factor("ddq") * c)
    else:
        entries = {"q": unit_name("q", given.factor("q") / c)}
    what = f"its velocity columns are {_times(k, joints, robot, 'positions')}"
    said = (
        f"{what}: {_said(blame, c, given)}, a unit, not a lag (a fit would take them as they are)"
    )
    judged = np.isfinite(k)
    return _with_hint(
        said, entries, robot, joints, judged & ~scaled, "velocity" if blame == "dq" else "position"
    )


def _length_rate(quantity: str, factor: float) -> str | None:
    """The ``--units`` spelling of ``factor`` for a prismatic joint's ``quantity``, or
    None when it is no length unit's."""
    return named_unit(quantity, factor, length=True, rel_tol=1e-6)


def prismatic_scale_finding(
    robot: Robot, log: TorqueLog, given: GivenUnits | None = None
) -> tuple[str, tuple[int, ...]] | None:
    """One line saying the velocity columns of ``robot``'s prismatic joints are in
    another length unit than their positions (``1000`` times the derivative of the
    positions while the revolute joints' agree with theirs: ``dq=mm/s`` forgotten beside
    ``q=mm``), with its ``--units`` hint, and the joints it names (from 0); None
    otherwise, and for a robot of one kind of joint (where a time column in ms reads
    alike).

    Parameters
    ----------
    robot : Robot
        The model's robot (joint kinds and names).
    log : TorqueLog
        The log as read with ``given`` [s, m or rad, m/s or rad/s].
    given : GivenUnits, optional
        The units it was read with: the factor of ``dq`` applies to the prismatic joints
        when it is a length unit's (1 or 1e-3), else they were read in m/s.
    """
    given = given or GivenUnits()
    pri = np.asarray(robot.prismatic, dtype=bool)
    k = joint_rate_factors(log)
    judged = np.isfinite(k) & (k > 0)
    rev = judged & ~pri
    if not rev.any() or not (judged & pri).any():
        return None
    ref = float(np.median(k[rev]))
    degrees = min(abs(ref * _DEG - 1.0), abs(ref / _DEG - 1.0)) < RATE_AGREES
    ref = 1.0 if degrees else ref  # the revolute joints' deg/s: velocity_scale_finding's
    ratio = np.where(judged & pri, k / ref, np.nan)
    read = given.length_factor("dq")
    for c in (1e-3, 1e3):
        joints = np.flatnonzero(np.abs(ratio / c - 1.0) < RATE_AGREES)
        unit = _length_rate("dq", read * c)
        if joints.size == 0 or unit is None:
            continue
        entries = {"dq": unit}
        if log.ddq is not None and math.isclose(
            given.length_factor("ddq"), given.length_factor("dq")
        ):
            entries["ddq"] = _length_rate("ddq", read * c) or f"{read * c:.10g}"
        names = ", ".join(robot.joint_names[j] for j in joints)
        s = "s" if joints.size > 1 else ""
        times = 1.0 / float(np.median(ratio[joints]))
        said = (
            f"the velocity columns of the prismatic joint{s} {names} are {times:.4g} times "
            "the derivative of their positions"
            + ("" if degrees else " while the revolute joints' agree with theirs")
            + ": "
            f"velocities in {unit} read as {_length_rate('dq', read)}, a unit, not a time "
            "column in ms (which would scale every joint alike) nor a lag; hint: --units "
            + ",".join(f"{q}={u}" for q, u in entries.items())
        )
        return said, tuple(int(j) for j in joints)
    return None


def _acceleration_finding(robot: Robot, log: TorqueLog, given: GivenUnits) -> str | None:
    """:func:`velocity_scale_finding` of acceleration columns against the derivative of
    velocities of the right unit: ``ddq=deg/s^2`` forgotten beside ``dq=deg/s``."""
    k = acceleration_rate_factors(log)
    if (found := _scaled(k)) is None:
        return None
    scaled, c = found
    joints = np.flatnonzero(scaled)
    entries = {"ddq": unit_name("ddq", given.factor("ddq") * c)}
    read = unit_name("ddq", given.factor("ddq"))
    read = read if "/" in read else f"{read} x rad/s^2"
    unit = "degrees" if c < 1.0 else "radians"
    said = (
        f"its acceleration columns are {_times(k, joints, robot, 'velocities')}: "
        f"accelerations in {unit} per second squared read as {read}, a unit (a "
        "fit would take them as they are)"
    )
    judged = np.isfinite(k)
    return _with_hint(said, entries, robot, joints, judged & ~scaled, "acceleration")


def _times(k: NDArray[np.float64], joints: NDArray[np.intp], robot: Robot, of: str) -> str:
    """``57.3 times the derivative of its positions (joint1 57.3, ...)``: ``of`` the
    derivative of what, and the joints' own factors (three at most)."""
    names = robot.joint_names
    each = ", ".join(f"{names[j]} {1 / k[j]:.3g}" for j in joints[:3])
    more = f" (and {joints.size - 3} more)" if joints.size > 3 else ""
    return f"{1 / float(np.median(k[joints])):.3g} times the derivative of its {of} ({each}{more})"


def _with_hint(
    said: str,
    entries: dict[str, str],
    robot: Robot,
    joints: NDArray[np.intp],
    others: NDArray[np.bool_],
    column: str,
) -> str:
    """``said`` and its ``--units`` hint; when ``others`` (joints judged right) remain,
    the columns of ``joints`` to convert in the file instead."""
    hint = "--units " + ",".join(f"{q}={u}" for q, u in entries.items())
    if not others.any():
        return f"{said}; hint: {hint}"
    names = robot.joint_names
    return (
        f"{said}, while those of {', '.join(names[j] for j in np.flatnonzero(others))} "
        f"agree; hint: convert the {column} columns of "
        f"{', '.join(names[j] for j in joints)} in the file ({hint} converts every joint alike)"
    )
