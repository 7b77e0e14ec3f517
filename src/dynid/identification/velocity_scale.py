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

A scale is not a lag: :mod:`~dynid.identification.derivative_columns` reads the lag of
columns of the positions' scale only.
"""

from __future__ import annotations

import math
from collections.abc import Sequence

import numpy as np
from numpy.typing import NDArray

from ..model.robot import Robot
from .angle_time_units import RATE_AGREES, GivenUnits, unit_name
from .log import TorqueLog

__all__ = [
    "MAX_SAMPLES",
    "SHAPE_CORRELATION",
    "WINDOW_S",
    "joint_rate_factors",
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


def joint_rate_factors(log: TorqueLog) -> NDArray[np.float64]:
    """Per joint (n,), ``k`` [1] of ``d q / dt ~ k dq``: 1 when positions and velocities
    share a unit, ``pi / 180`` for velocities in deg/s beside positions in rad (module
    docstring); NaN for a joint not judged, and for every joint of velocities derived from
    the positions or a log of fewer than 8 samples."""
    n = log.n
    out = np.full(n, np.nan)
    if log.dq_derived or log.n_samples < 8:
        return out
    m = min(log.n_samples, MAX_SAMPLES)
    t, q, dq = log.t[:m], np.asarray(log.q[:m]), np.asarray(log.dq[:m])
    dt = np.diff(t)
    step = float(np.median(dt))
    dqs = np.diff(q, axis=0)
    keep = (dt <= 1.5 * step)[:, None] & (np.abs(dqs) <= np.pi)
    x = np.where(keep, dqs / dt[:, None], 0.0)
    y = np.where(keep, 0.5 * (dq[1:] + dq[:-1]), 0.0)
    w = max(1, min(int(round(WINDOW_S / step)), (m - 1) // 4))
    x, y = _box(x, w), _box(y, w)
    for j in range(n):
        xj, yj = x[:, j], y[:, j]
        sx, sy = float(np.std(xj)), float(np.std(yj))
        if not (sx > 0 and sy > 0):
            continue
        c = float(np.mean((xj - xj.mean()) * (yj - yj.mean()))) / (sx * sy)
        if c >= SHAPE_CORRELATION:
            out[j] = float(xj @ yj) / float(yj @ yj)
    return out


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
    """One line saying a joint-side ``log``'s velocity columns are in another angle unit
    than its positions, with the ``--units`` entries that read them right given the units
    ``given`` applied (module docstring); None otherwise.

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
    judged = np.isfinite(k)
    fast = judged & (np.abs(k * _DEG - 1.0) < RATE_AGREES)
    slow = judged & (np.abs(k / _DEG - 1.0) < RATE_AGREES)
    scaled = fast if fast.sum() >= slow.sum() else slow
    if not scaled.any() or 2 * int(scaled.sum()) < int(judged.sum()):
        return None
    joints = np.flatnonzero(scaled)
    c = math.pi / 180 if scaled is fast else _DEG  # the velocities' true scale
    blame = _blamed(robot, log, joints, c, given)
    if blame == "dq":
        entries = {"dq": unit_name("dq", given.factor("dq") * c)}
        if log.ddq is not None and math.isclose(given.factor("ddq"), given.factor("dq")):
            entries["ddq"] = unit_name("ddq", given.factor("ddq") * c)
    else:
        entries = {"q": unit_name("q", given.factor("q") / c)}
    names = robot.joint_names
    ks = ", ".join(f"{names[j]} {1 / k[j]:.3g}" for j in joints[:3])
    more = f" (and {joints.size - 3} more)" if joints.size > 3 else ""
    what = f"its velocity columns are {1 / float(np.median(k[joints])):.3g} times the derivative"
    said = (
        f"{what} of its positions ({ks}{more}): {_said(blame, c, given)}, a unit, not a lag "
        "(a fit would take the velocities as they are)"
    )
    hint = "--units " + ",".join(f"{q}={u}" for q, u in entries.items())
    if not np.array_equal(scaled, judged):
        others = ", ".join(names[j] for j in np.flatnonzero(judged & ~scaled))
        return (
            f"{said}, while those of {others} agree with their positions; hint: convert "
            f"the {'velocity' if blame == 'dq' else 'position'} columns of "
            f"{', '.join(names[j] for j in joints)} in the file ({hint} converts every "
            "joint alike)"
        )
    return f"{said}; hint: {hint}"
