"""Checks of a torque log before fitting: sign, scale, units and joints that never move.

Real logs come with conventions of their own. Each check returns one line that says what
looks wrong, the numbers, and the remedy as the user types it; identification warns with
them before fitting. None of them changes the data. :func:`check_torque_log` runs the checks
of one joint-side log in order; each check lives in a module of its own:

* **Degrees** and **milliseconds**
  (:mod:`~dynid.identification.angle_time_units`), said first and instead of the sign and
  scale findings: the gravity torques at positions in degrees say nothing of the torques'
  units.
* **Sign** against the model's gravity and rigid-body torques
  (:mod:`~dynid.identification.model_sign`); columns recorded reversed and one recording of
  the opposite sign to the others (:mod:`~dynid.identification.recorded_signs`).
* **Frozen joints** (:mod:`~dynid.identification.velocity_noise`).
* **Torque spikes** (:mod:`~dynid.identification.spikes`), the one change to the data.
* **Scale** (here): the least-squares factor ``a`` in ``tau ~ a g(q)`` over the
  gravity-loaded joints; ``a`` near 1e3 or 1e-3 is a unit off by a power of ten (mN m
  against N m: :func:`torque_unit_finding`, refused by the commands unless ``--units`` names
  the torques' unit), and currents logged as torques show as a factor far from 1 (a drive
  file with ``torque_constant``; currents read through one: its ``torque_constant`` or
  ``gear_ratio`` is off by the factor). Sign and scale compare variations: not made on a log
  at rest (every joint frozen), whose variations are noise, nor on a joint whose gravity
  torques span less than :data:`~dynid.identification.model_sign.GRAVITY_RANGE_SHARE` of
  the log's largest (a short stretch, whose torque variations are the motion's).
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np
from numpy.typing import NDArray

from ..model.drive import Drive
from ..model.robot import Robot
from .angle_time_units import degrees_findings, milliseconds_findings
from .gravity_scale import at_the_motors
from .log import TorqueLog
from .model_sign import CHECKED_SAMPLES, gravity_spread, opposite_sign
from .velocity_noise import moving_joints

__all__ = [
    "gravity_torque_scale",
    "check_torque_log",
    "MIN_LOG_SAMPLES",
    "too_few_samples",
    "torque_unit_finding",
    "UNIT_SCALE_TOLERANCE",
]
#: A torque scale (:func:`torque_unit_finding`) within this factor of ``1e3`` or ``1e-3``
#: reads as torques in mN m or kN m read as N m (a URDF whose masses are off by tens of
#: percent gives a factor near 1, currents one near the inverse torque constant).
UNIT_SCALE_TOLERANCE = 2.0


#: Fewest samples of a recording that the checks and the filter are asked to read: two
#: samples correlate at +-1 with anything, three give one curvature.
MIN_LOG_SAMPLES = 10


def too_few_samples(log: TorqueLog) -> str | None:
    """The finding that ``log`` holds too few samples to be checked or filtered (fewer
    than :data:`MIN_LOG_SAMPLES`), or None; said before any statistic of it."""
    n = log.n_samples
    if n >= MIN_LOG_SAMPLES:
        return None
    return (
        f"{n} sample{'' if n == 1 else 's'}: too few to check or filter a torque log (at "
        f"least {MIN_LOG_SAMPLES} are needed); hint: check that the file holds the whole "
        "recording"
    )


def check_torque_log(robot: Robot, log: TorqueLog, drive: Drive | None = None) -> list[str]:
    """One line per finding on a joint-side log of ``robot`` (module docstring), read
    through ``drive`` (its torque constants and gear ratios are named by the scale
    finding); empty when nothing looks wrong."""
    seen = _against_gravity(robot, log)
    out = list(seen.degrees)
    a = seen.scale
    if seen.opposite is not None:
        out.append(seen.opposite)
    elif a is not None and (abs(a) > 30 or 0 < abs(a) < 1 / 30):
        out.append(_scale_line(a, drive=drive))
    out += milliseconds_findings(log)
    frozen, names = seen.frozen, robot.joint_names
    if np.any(frozen) and not np.all(frozen):
        which = ", ".join(names[j] for j in np.flatnonzero(frozen))
        out.append(
            f"joint(s) {which} never leave their velocity noise band: their friction is "
            "unidentifiable and is left out (zero) rather than fitted from noise; hint: a "
            "trajectory that moves every joint identifies them"
        )
    return out


@dataclass(frozen=True, slots=True)
class _GravitySaid:
    """What a joint-side log says against the robot's gravity torques: the sign and scale
    findings' guards, one for :func:`check_torque_log` and :func:`torque_unit_finding`.

    Attributes
    ----------
    degrees : tuple of str
        The degrees finding (said first, and instead of sign and scale: the gravity
        torques at positions in degrees say nothing of the torques).
    frozen : ndarray of bool, shape (n,)
        The joints that never leave their velocity noise band.
    opposite : str or None
        The sign finding (:func:`~dynid.identification.model_sign.opposite_sign`).
    scale : float or None
        ``a`` of ``tau ~ a g(q)`` (:func:`_torque_scale`); None where not compared: a
        robot without inertial parameters, every joint frozen (at rest the variations are
        noise, whose ratio says nothing of the units), degrees, the opposite sign, no
        joint gravity loads.
    """

    degrees: tuple[str, ...]
    frozen: NDArray[np.bool_]
    opposite: str | None = None
    scale: float | None = None


def _against_gravity(robot: Robot, log: TorqueLog) -> _GravitySaid:
    """The degrees, frozen joints, sign and scale of ``log`` against ``robot``'s gravity
    torques (:class:`_GravitySaid`), each judged only where the ones before allow."""
    degrees = tuple(degrees_findings(robot, log))
    frozen = ~moving_joints(log.dq)
    if not np.any(robot.phi) or degrees or np.all(frozen):
        return _GravitySaid(degrees, frozen)
    if (opposite := opposite_sign(robot, log)) is not None:
        return _GravitySaid(degrees, frozen, opposite)
    step = max(1, log.n_samples // CHECKED_SAMPLES)
    return _GravitySaid(degrees, frozen, None, _torque_scale(robot, log.q[::step], log.tau[::step]))


def gravity_torque_scale(robot: Robot, log: TorqueLog) -> float | None:
    """The factor ``a`` of ``tau ~ a g(q)`` of a joint-side ``log`` against ``robot``'s
    gravity torques (:func:`check_torque_log`'s scale finding), or None where it is not
    compared (:class:`_GravitySaid`'s ``scale``) or the log is too short to check."""
    if too_few_samples(log) is not None:
        return None
    return _against_gravity(robot, log).scale


def _torque_scale(robot: Robot, q: NDArray[np.float64], tau: NDArray[np.float64]) -> float | None:
    """The least-squares factor ``a`` of ``tau ~ a g(q)`` over the joints gravity loads,
    their means removed (None when gravity loads none)."""
    centred = gravity_spread(robot, q, tau)
    if centred is None:
        return None
    gc, tc, loaded = centred
    return float(np.sum(gc[:, loaded] * tc[:, loaded]) / np.sum(gc[:, loaded] ** 2))


def _scale_line(a: float, refused: bool = False, drive: Drive | None = None) -> str:
    """The scale finding of factor ``a``, with its hint (and, ``refused``, the way to read
    the torques as they are); through a ``drive`` of currents, the torque constants and
    gear ratios the torques were made with are named, not a missing drive file."""
    p = round(math.log10(abs(a)))
    if drive is not None and drive.effort == "current":
        at = "at the motor" if drive.side == "motor" else "at the joint"
        hint = (
            f"check torque_constant (N m per A, {at}) and gear_ratio in the drive file"
            + ("; currents in mA: units='tau=0.001'" if p == 3 else "")
            + (" (units='tau=1' reads the currents as they are)" if refused else "")
        )
        return (
            f"the measured torques (the currents times the drive's torque constants) are "
            f"{abs(a):.3g} times the model's gravity torques: the drive file's torque_constant "
            f"or gear_ratio looks off by that factor{at_the_motors(drive, 1 / abs(a))}; "
            f"hint: {hint}"
        )
    hint = (
        "units='tau=mNm'"
        if p == 3
        else "units='tau=1000' (kN m)"
        if p == -3
        else 'currents need a drive file with effort = "current" and torque_constant'
    )
    if refused:
        hint += " (units='tau=Nm' reads them as N m)"
    return (
        f"the measured torques are {abs(a):.3g} times the model's gravity torques: a unit "
        f"off by a power of ten, or currents logged as torques; hint: {hint}"
    )


def torque_unit_finding(robot: Robot, log: TorqueLog, drive: Drive | None = None) -> str | None:
    """The finding that a joint-side log's torques are in mN m (or kN m) read as N m, or
    None: their factor to ``robot``'s gravity torques (:func:`check_torque_log`'s scale)
    within :data:`UNIT_SCALE_TOLERANCE` of ``1e3`` (or ``1e-3``).

    The commands refuse such a log unless the torques' unit is said (``--units tau=...``):
    a fit of it is a model 1000 times too heavy that predicts its own log to the noise
    floor. A factor far from a power of ten (a model that is wrong, currents) is only
    warned. None too where :func:`check_torque_log` makes no scale finding: a robot without
    inertial parameters, every joint frozen, positions that look like degrees, torques of
    the opposite sign, a log too short to check (:func:`too_few_samples`). Through a
    ``drive`` of currents, the line names its torque constants and gear ratios."""
    if too_few_samples(log) is not None:
        return None
    a = _against_gravity(robot, log).scale
    if a is None or a == 0:
        return None
    off = math.log10(abs(a))
    if abs(abs(off) - 3) > math.log10(UNIT_SCALE_TOLERANCE):
        return None
    return _scale_line(a, refused=True, drive=drive)
