"""An identified model's gravity torques against the robot description's: one factor on
every joint is a scale the fit cannot see.

A log of currents read through a torque constant that is off by a factor ``c`` (a guessed
``torque_constant``), or torques from a sensor of another scale, is fitted as well as the
right one: every identified inertial parameter is scaled by ``1/c`` and the model predicts
the log to its noise. Only something outside the log tells: the robot description's
masses. Its gravity torques at the logged configurations ``g_d(q)`` against the identified
model's ``g_m(q)``, per joint that gravity loads
(:func:`~dynid.identification.model_sign.gravity_loaded`): the least-squares factor ``r_j`` of
``g_m ~ r_j g_d``. A description's masses are off
joint by joint (a cable, a motor left out of the CAD); a factor that is the same on every
loaded joint (within :data:`UNIFORM`) and at least :data:`OFF` away from 1, with the
shapes agreeing (correlation at least :data:`SHAPE`), is a scale: the finding names it and
what to change, for the user to judge (the description may be uniformly off instead).
"""

from __future__ import annotations

from collections.abc import Sequence

import numpy as np
from numpy.typing import NDArray

from ..dynamics.terms import gravity_torques
from ..model.drive import Drive
from ..model.robot import Robot
from .model import IdentifiedModel
from .model_sign import gravity_loaded

__all__ = [
    "GRAVITY_SCALE",
    "OFF",
    "SHAPE",
    "UNIFORM",
    "at_the_motors",
    "gravity_ratios",
    "gravity_scale_factor",
    "gravity_scale_finding",
    "gravity_scale_words",
    "recorded_scale",
]

#: Relative distance from 1 of the common factor that makes a finding.
OFF = 0.10
#: Largest relative spread of the loaded joints' factors about their mean for "the same".
UNIFORM = 0.05
#: Smallest correlation of a loaded joint's identified and described gravity torques.
SHAPE = 0.98
#: Configurations used at most (spread over the logs).
_SAMPLES = 2_000
#: The key of an identified model's metadata that records the finding (``factor`` [-] and
#: ``finding``, its sentence), for the commands that read the model.
GRAVITY_SCALE = "gravity_scale"


def recorded_scale(model: object) -> tuple[float, str] | None:
    """The factor [-] of ``model``'s gravity torques to its description's and the finding's
    sentence, as ``identify`` recorded them in its metadata (:data:`GRAVITY_SCALE`), or
    None: not an identified model, no finding recorded (or a record of another form)."""
    if not isinstance(model, IdentifiedModel):
        return None
    got = model.info.extra.get(GRAVITY_SCALE)
    if not isinstance(got, dict):
        return None
    factor, said = got.get("factor"), got.get("finding")
    if not isinstance(factor, int | float) or not isinstance(said, str) or not factor > 0:
        return None
    return float(factor), said


def gravity_ratios(
    robot: Robot, model: IdentifiedModel, q: NDArray[np.float64]
) -> tuple[NDArray[np.float64], NDArray[np.float64], NDArray[np.bool_]]:
    """Per joint: the factor ``r_j`` of the model's gravity torques to the description's
    at the configurations ``q`` (N, n) [rad] (least squares, means kept: gravity has an
    absolute level), their correlation, and which joints gravity loads (the others' entries
    are NaN)."""
    loaded = gravity_loaded(robot, q)
    gd = gravity_torques(robot, q)
    gm = model.gravity_torques(q)
    r = np.full(robot.n, np.nan)
    c = np.full(robot.n, np.nan)
    for j in np.flatnonzero(loaded):
        d, m = gd[:, j], gm[:, j]
        r[j] = float(d @ m / (d @ d))
        sd, sm = np.std(d), np.std(m)
        c[j] = float(np.mean((d - d.mean()) * (m - m.mean())) / (sd * sm)) if sd * sm > 0 else 0
    return r, c, loaded


def gravity_scale_factor(
    robot: Robot, model: IdentifiedModel, q: Sequence[NDArray[np.float64]]
) -> tuple[float, NDArray[np.float64], NDArray[np.intp]] | None:
    """The common factor [-] of ``model``'s gravity torques to ``robot``'s description's
    (module docstring), each joint's (n,) and the loaded joints (indices), at the
    configurations ``q`` (one (N, n) array [rad] per log); None where
    :func:`gravity_scale_finding` finds none."""
    if not np.any(robot.phi) or not q:
        return None
    every = np.concatenate([np.asarray(a, dtype=np.float64) for a in q])
    qs = every[:: max(1, every.shape[0] // _SAMPLES)]
    r, c, loaded = gravity_ratios(robot, model, qs)
    js = np.flatnonzero(loaded)
    if js.size < 2 or np.any(c[js] < SHAPE) or np.any(r[js] <= 0):
        return None
    mean = float(np.mean(r[js]))
    if np.max(np.abs(r[js] - mean)) > UNIFORM * mean or abs(mean - 1.0) < OFF:
        return None
    return mean, r, js


def gravity_scale_finding(
    robot: Robot,
    model: IdentifiedModel,
    q: Sequence[NDArray[np.float64]],
    drive: Drive | None = None,
) -> str | None:
    """The finding (module docstring) of ``model`` identified from logs at the
    configurations ``q`` (one (N, n) array per log) of ``robot``, or None: no inertial
    parameters in the description, fewer than 2 loaded joints, factors that differ between
    joints or lie within :data:`OFF` of 1. ``drive``: the drive the log was read through (a
    log of currents: its torque constant is named)."""
    found = gravity_scale_factor(robot, model, q)
    return None if found is None else gravity_scale_words(robot, found, drive)


def gravity_scale_words(
    robot: Robot,
    found: tuple[float, NDArray[np.float64], NDArray[np.intp]],
    drive: Drive | None = None,
) -> str:
    """:func:`gravity_scale_finding`'s sentence of the factor :func:`gravity_scale_factor`
    ``found`` (common factor, each joint's, the loaded joints) of ``robot``."""
    mean, r, js = found
    names = ", ".join(robot.joint_names[j] for j in js)
    said = (
        f"the identified gravity torques are {mean:.3g} times the robot description's on "
        f"every joint gravity loads ({names}: {r[js].min():.3g} to {r[js].max():.3g}): one "
        "factor on every joint is a scale the fit cannot see (it predicts the log as well "
        "with it; its masses and inertias carry it)"
    )
    if drive is not None and drive.effort == "current":
        return (
            f"{said}; if the description's masses are right, the drive file's torque_constant "
            f"is {mean:.3g} times the true one: multiply it by {1 / mean:.3g}"
            f"{at_the_motors(drive, 1 / mean)}"
        )
    currents = (
        '; or the log holds motor currents: a drive file with effort = "current" and each '
        "motor's torque_constant (a factor per joint)"
        if not 0.5 <= mean <= 2.0
        else ""
    )
    return (
        f"{said}; if the description's masses are right, the torques are {1 / mean:.3g} "
        f"times too small (a sensor scale: --units tau={1 / mean:.3g}){currents}"
    )


def at_the_motors(drive: Drive, factor: float) -> str:
    """A clause when ``factor``, the torque constants' correction, is near the gear ratio
    every joint of a joint-side ``drive`` shares (within 1/3 to 3 times): constants given
    at the motors, where ``side = "joint"`` wants each joint's torque per A."""
    ratio = np.abs(np.diag(np.asarray(drive.transmission, dtype=np.float64)))
    if drive.side != "joint" or drive.is_coupled:
        return ""
    if not np.allclose(ratio, ratio[0]) or ratio[0] == 1 or not 1 / 3 <= factor / ratio[0] <= 3:
        return ""
    return (
        f" (near the gear ratio, {ratio[0]:.4g}: torque_constant looks given at the motors; on "
        "a joint-side log, side = \"joint\", it is each joint's torque per A, the motor's "
        "constant times its gear ratio)"
    )
