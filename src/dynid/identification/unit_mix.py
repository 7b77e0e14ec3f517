"""A recording in degrees among recordings in radians, found before any fit.

A recording whose positions and velocities are both in degrees passes the check of
velocities against the derivative of the positions (one unit for both), and its torques
are those of the others: alone among the checks across recordings, nothing says it is
wrong, and the fit ends in a model that explains no recording (76 % training error on a
Panda, exit 0). What gives it away is the scale of its positions against the others' and
against the joint limits:

* its positions lie outside the joint limits (beyond a margin) while divided by
  ``180 / pi`` they fit them;
* the other recordings' positions fit the limits as they are;
* the RMS of its positions (revolute joints, about zero) is ``180 / pi`` times the others'
  median, within a factor :data:`DEGREE_TOLERANCE` (one pose differs from another; a
  recording of another robot or of a continuous joint that turns many times does not
  scale so).

The finding names which columns to convert: the positions, and the velocities when their
RMS is also ``180 / pi`` times the others' (a velocity in radians beside positions in
degrees also shows in :func:`dynid.workflows.recordings.check_units`).

Within one recording, a joint in degrees among joints in radians
(:func:`joints_in_degrees`): its positions lie outside its limits (beyond a margin), they
span more than the joint can travel (the width of its limits: a recording of another
robot, shifted, does not), divided by ``180 / pi`` they fit the limits, and its velocities
do not say radians (where they agree with the positions' derivative and stay below the
joint's speed limit, an unwrapped continuous joint turning several times, they do).
A joint without position limits (continuous) is judged by its velocities alone: ``180 /
pi`` times slower than the derivative of its positions, or agreeing with it and
:data:`FREE_SPEED_FACTOR` times its speed limit. When every joint that moves reads as
degrees the hint is ``--units q=deg,dq=deg/s``; when every joint with limits does and the
continuous ones do not tell (slow), it is still that first, the conversion of the joints
named second: a file is written in one unit.

:func:`unit_findings` checks a file's time unit, its degrees and its velocity columns'
unit against its positions' (:mod:`~dynid.identification.velocity_scale`: ``dq=deg/s``
forgotten beside ``q=deg``) in one pass (the positions judged on the time column read in
its unit): a log in ms and degrees is told ``--units t=ms,q=deg`` at once, not one unit a
run, written into the ``--units`` given.
"""

from __future__ import annotations

import dataclasses
from collections.abc import Sequence

import numpy as np
from numpy.typing import NDArray

from ..model.drive import Drive
from ..model.robot import Robot
from .angle_time_units import (
    RATE_AGREES,
    GivenUnits,
    joined_unit_findings,
    joint_rate_factor,
    rate_verdict,
    time_unit,
    time_unit_said,
    unit_name,
)
from .log import TorqueLog, joint_side_log
from .velocity_scale import prismatic_scale_finding, velocity_scale_finding

__all__ = [
    "DEGREE_TOLERANCE",
    "FREE_SPEED_FACTOR",
    "LIMIT_MARGIN",
    "degrees_among_radians",
    "joints_in_degrees",
    "time_unit_read",
    "unit_findings",
]

#: Margin [rad or m] beyond the joint limits before positions are called outside them.
LIMIT_MARGIN = 0.2

#: A scale ratio within this factor of ``180 / pi`` reads as degrees against radians.
DEGREE_TOLERANCE = 2.0
#: A joint without position limits whose velocities, in the unit of its positions, reach
#: this many times its speed limit reads as degrees (within the limit read in degrees per
#: second): radians that fast are no motion of the arm (the Kinova's continuous joints in
#: degrees reach 41-45 times theirs).
FREE_SPEED_FACTOR = 10.0
_DEG = 180.0 / np.pi
_MAX_SAMPLES = 20_000  # statistics: evenly spaced samples


def _inside(q: NDArray[np.float64], robot: Robot, margin: float) -> bool:
    """Whether positions (N, n) fit the joint limits within ``margin`` [rad or m]."""
    lo = np.asarray(robot.q_min) - margin
    hi = np.asarray(robot.q_max) + margin
    return bool(np.all(q.min(axis=0) >= lo) and np.all(q.max(axis=0) <= hi))


def _rms(x: NDArray[np.float64]) -> float:
    return float(np.sqrt(np.mean(x**2))) if x.size else float("nan")


def degrees_among_radians(
    robot: Robot, logs: Sequence[TorqueLog], names: Sequence[str], margin: float
) -> tuple[int, str] | None:
    """The first recording that reads as degrees among recordings in radians (module
    docstring), and the finding (one line, without the file's name); or None.

    Parameters
    ----------
    robot : Robot
        The model's robot (its joint limits [rad or m]).
    logs : sequence of TorqueLog
        Joint-side logs (motor angles turned into joint angles by the drive).
    names : sequence of str
        The recordings' names, for the finding.
    margin : float
        Margin [rad or m] beyond the joint limits before positions are outside them.
    """
    if len(logs) < 2:
        return None
    rev = ~np.asarray(robot.prismatic, dtype=bool)
    if not np.any(rev):
        return None
    qs = [log.q[:: max(1, log.n_samples // _MAX_SAMPLES)] for log in logs]
    dqs = [log.dq[:: max(1, log.n_samples // _MAX_SAMPLES)] for log in logs]
    fits = [_inside(q, robot, margin) for q in qs]
    q_rms = np.array([_rms(q[:, rev]) for q in qs])
    dq_rms = np.array([_rms(dq[:, rev]) for dq in dqs])
    for r, q in enumerate(qs):
        others = [i for i in range(len(qs)) if i != r and fits[i]]
        if fits[r] or not others:
            continue
        in_degrees = np.where(rev, q / _DEG, q)
        if not _inside(in_degrees, robot, margin):
            continue
        k = q_rms[r] / float(np.median(q_rms[others]))
        if not abs(np.log(k / _DEG)) <= np.log(DEGREE_TOLERANCE):
            continue
        kv = dq_rms[r] / float(np.median(dq_rms[others]))
        both = abs(np.log(kv / _DEG)) <= np.log(DEGREE_TOLERANCE)
        lo, hi = q.min(axis=0), q.max(axis=0)
        j = int(np.argmax(np.maximum(robot.q_min - lo, hi - robot.q_max)))
        who = [names[i] for i in others]
        said = ", ".join(who) if len(who) <= 3 else "the other recordings"
        what = "positions and velocities" if both else "positions"
        cols = "q and dq" if both else "q"
        own = f"{names[r]}:q=deg" + (f",{names[r]}:dq=deg/s" if both else "")
        return r, (
            f"its {what} look like degrees among recordings in radians: positions "
            f"{k:.3g} times those of {said}"
            + (f" (velocities {kv:.3g} times)" if both else "")
            + f", and joint {robot.joint_names[j]} spans [{lo[j]:.4g}, {hi[j]:.4g}], outside "
            f"its limits [{robot.q_min[j]:.4g}, {robot.q_max[j]:.4g}] unless read in "
            f"degrees; hint: --units {own} reads it in degrees (a file's own entry), or "
            f"convert its {cols} to radians (x pi/180)"
        )
    return None


def _free_in_degrees(robot: Robot, log: TorqueLog, j: int) -> tuple[str, bool] | None:
    """What says joint ``j``, which has no position limits to tell, is in degrees: its
    velocities ``180 / pi`` times slower than the derivative of its positions (positions
    in degrees), or agreeing with it and above :data:`FREE_SPEED_FACTOR` times its speed
    limit (``2 pi`` rad/s without one) while within it read in degrees per second (both
    in degrees); the words and whether the velocities are in degrees too, or None."""
    k = joint_rate_factor(log, j)
    if not np.isfinite(k):
        return None
    name = robot.joint_names[j]
    if abs(k / _DEG - 1.0) < RATE_AGREES:
        return (
            f"{name} (no position limits) has velocities {k:.3g} times slower than the "
            "derivative of its positions",
            False,
        )
    fast = float(robot.dq_max[j]) if np.isfinite(robot.dq_max[j]) else 2 * np.pi
    peak = float(np.quantile(np.abs(log.dq[:, j]), 0.99))
    if abs(k - 1.0) < RATE_AGREES and FREE_SPEED_FACTOR * fast < peak <= 1.5 * fast * _DEG:
        return (
            f"{name} (no position limits) moves at up to {peak:.4g} per second, "
            f"{peak / fast:.3g} times its speed limit {fast:.3g} rad/s",
            True,
        )
    return None


def _span_said(
    j: int,
    lo: NDArray[np.float64],
    hi: NDArray[np.float64],
    recorded: TorqueLog | None,
    step: int,
) -> str:
    """``[-50.08, 58.41]`` (the file's values), or of a motor-side log ``[-50.08, 58.41]
    at the joint side (motor 1 spans [-5008, 5841] in the file)``."""
    span = f"[{lo[j]:.4g}, {hi[j]:.4g}]"
    if recorded is None:
        return span
    m = recorded.q[::step, j]
    motor = f"[{m.min():.4g}, {m.max():.4g}]"
    return f"{span} at the joint side (motor {j + 1} spans {motor} in the file)"


def joints_in_degrees(
    robot: Robot, log: TorqueLog, margin: float, recorded: TorqueLog | None = None
) -> tuple[list[int], str]:
    """The joints of a joint-side ``log`` whose positions read as degrees (module
    docstring), and the finding (one line, without the file's name; empty without them).
    The spans said are the file's values: of ``log``, or, when ``recorded`` is given (a
    motor-side log as read), the joint-side span said as such beside its motor's in the
    file.

    Parameters
    ----------
    robot : Robot
        The model's robot (its joint limits [rad or m] and speed limits [rad/s]).
    log : TorqueLog
        A joint-side log.
    margin : float
        Margin [rad or m] beyond the joint limits before positions are outside them.
    recorded : TorqueLog, optional
        The log as read from the file (motor angles), when ``log`` is its joint side.
    """
    step = max(1, log.n_samples // _MAX_SAMPLES)
    q = log.q[::step]
    lo, hi = q.min(axis=0), q.max(axis=0)
    q_min, q_max = np.asarray(robot.q_min), np.asarray(robot.q_max)
    width = q_max - q_min
    moving = ~np.asarray(robot.prismatic, dtype=bool) & (hi - lo > 1e-3)
    suspect = (
        moving
        & np.isfinite(width)
        & ((lo < q_min - margin) | (hi > q_max + margin))
        & (hi - lo > width)
        & (lo / _DEG >= q_min - margin)
        & (hi / _DEG <= q_max + margin)
    )
    thin = TorqueLog(log.t[::step], q, log.dq[::step], log.tau[::step])
    verdicts = {j: rate_verdict(robot, thin, j) for j in map(int, np.flatnonzero(suspect))}
    hints = {j: v[1] for j, v in verdicts.items() if v is not None}
    found = list(hints)
    unbounded = map(int, np.flatnonzero(moving & ~np.isfinite(width)))
    free = {j: _free_in_degrees(robot, thin, j) for j in unbounded}
    seen = {j: f for j, f in free.items() if f is not None}
    if not found and not seen:
        return [], ""
    both = (
        not log.dq_derived
        and all("dq=deg/s" in h for h in hints.values())
        and all(f[1] for f in seen.values())
    )
    names = robot.joint_names
    said = []
    if found:
        said.append(
            ", ".join(
                f"{names[j]} spans {_span_said(j, lo, hi, recorded, step)}, limits "
                f"[{q_min[j]:.4g}, {q_max[j]:.4g}]"
                for j in found[:3]
            )
            + (f" (and {len(found) - 3} more)" if len(found) > 3 else "")
            + ": more than the joint can travel, and within its limits read in degrees"
        )
    said += [f[0] for f in seen.values()]
    every = sorted(found + list(seen))
    units = "--units q=deg" + (",dq=deg/s" if both else "")
    units += ",ddq=deg/s^2" if both and log.ddq is not None else ""
    cols = "positions and velocities" if both else "positions"
    convert = (
        f"convert the {cols} of {', '.join(names[j] for j in every)} to radians (x pi/180) "
        "in the file"
    )
    unclear = [j for j, f in free.items() if f is None]
    bounded = np.flatnonzero(moving & np.isfinite(width))
    if set(every) >= set(map(int, np.flatnonzero(moving))):
        what, hint = "positions in degrees", units
    elif found and set(found) >= set(map(int, bounded)):
        what = "positions in degrees on every joint with position limits"
        hint = (
            f"{units} if the whole file is in degrees, as a file usually is (the speeds of "
            f"{', '.join(names[j] for j in unclear)}, without position limits, do not tell); "
            f"else {convert}"
        )
    else:
        what = "joint(s) in degrees among joints in radians"
        hint = f"{convert} (--units converts every joint alike)"
    return every, f"{what}: {'; '.join(said)}; hint: {hint}"


def unit_findings(
    robot: Robot,
    log: TorqueLog,
    drive: Drive | None = None,
    time: tuple[str, float] | None = None,
    time_said: str | None = None,
    side: TorqueLog | None = None,
    given: GivenUnits | None = None,
) -> str | None:
    """Every unit finding of one log as read, in one line with one ``--units`` hint
    (:func:`~dynid.identification.angle_time_units.joined_unit_findings`), or None: the
    time column's unit, joints in degrees, and velocity columns in another angle unit than
    the positions (:func:`~dynid.identification.velocity_scale.velocity_scale_finding`, on
    the joints not found in degrees).

    Parameters
    ----------
    robot : Robot
        The model's robot (limits [rad or m], speed limits [rad/s]).
    log : TorqueLog
        The log as read from the file (motor side through a motor-side ``drive``).
    drive : Drive, optional
        The drive it was recorded through: its joints judged on the joint side, the
        file's motor angles quoted beside.
    time : (str, float), optional
        The time column's unit and length [s] when already found (a log unreadable in
        seconds, read again in it), with ``time_said``, what was found; default: looked
        for in the velocities (:func:`~dynid.identification.angle_time_units.time_unit`).
    side : TorqueLog, optional
        ``log`` on the joint side, when mapped already (default: mapped through ``drive``).
    given : GivenUnits, optional
        The ``--units`` the log was read with: the time unit judged against the one given,
        the hint written into them.
    """
    found = []
    given = given or GivenUnits()
    rail = prismatic_scale_finding(robot, log, given)  # mm/s: not a time unit
    skip = () if rail is None else rail[1]
    if rail is not None:
        found.append(rail[0])
    if time is None and (time := time_unit(log, given.factor("t"), skip)) is not None:
        time_said = time_unit_said(log, given.factor("t"), skip)
    mapped = drive is not None and drive.n == log.n
    if side is None:
        side = joint_side_log(log, drive) if mapped else log
    if time is not None and time_said is not None:
        found.append(time_said)  # the velocities were per second: the time column alone
        scale = time[1] / given.factor("t")
        log = dataclasses.replace(log, t=log.t * scale)
        side = dataclasses.replace(side, t=side.t * scale)
    motor = mapped and drive is not None and drive.side == "motor"
    joints, said = joints_in_degrees(robot, side, LIMIT_MARGIN, log if motor else None)
    if joints:
        found.append(said)
    if (scaled := velocity_scale_finding(robot, side, given, [*joints, *skip])) is not None:
        found.append(scaled)
    return joined_unit_findings(found, given.text) if found else None


def time_unit_read(robot: Robot, log: TorqueLog, given: GivenUnits | None = None) -> str:
    """The ``--units t=`` spelling of the unit ``log``'s time column is in: the one its
    velocities tell (:func:`~dynid.identification.angle_time_units.time_unit`, judged as
    :func:`unit_findings` judges it, a prismatic joint's velocities in mm/s left out),
    else the one it was read in (``given``)."""
    given = given or GivenUnits()
    rail = prismatic_scale_finding(robot, log, given)
    found = time_unit(log, given.factor("t"), () if rail is None else rail[1])
    return found[0] if found is not None else unit_name("t", given.factor("t"))
