"""Does a data set belong to this robot? Checks of recorded robot, limits and fit.

Data sets record the robot they were acquired with (``metadata["robot"]``, and from
``dynid acquire-static`` its kinematics ``metadata["kinematics"]``: ``T_parent_joint``
(n, 4, 4) [m], ``axes`` (n, 3), ``gravity`` (3,) [m/s^2]). Identifying data with another
robot's kinematics gives coefficients that are silently wrong (an xArm7's data read as
a Panda's fit with a 5.6 % relative error, exit 0), so:

* :func:`recorded_robot_mismatch` names a different robot name, joint count or
  kinematics (with the largest difference);
* :func:`limit_violations` counts configurations outside the joint limits;
* :func:`fit_mismatch` flags a relative error far above what the recorded noise level
  explains (noise-free data must fit to rounding).
"""

from __future__ import annotations

from collections.abc import Mapping
from typing import Any

import numpy as np
from numpy.typing import NDArray

from ..model.robot import Robot

__all__ = [
    "fit_mismatch",
    "kinematics_record",
    "limit_violations",
    "recorded_robot_mismatch",
]

#: Relative error [%] allowed on data recorded without noise (rounding of 17-digit files).
NOISE_FREE_RELATIVE_ERROR_PERCENT = 1e-6

#: A fit is suspicious when its relative error exceeds this many times the recorded
#: relative noise (in %).
NOISE_FACTOR = 10.0

#: A joint transform differing by at most this [rad, as rotation entries] is named as a
#: URDF angle rounded near a multiple of pi/2 read as written once and snapped once (the
#: band of :data:`dynid.io.robot.urdf_angles.ROUNDED_BAND`).
_ROUNDING = 1e-3


def kinematics_record(robot: Robot) -> dict[str, Any]:
    """The kinematics to record with a data set: ``T_parent_joint``, ``axes``, ``gravity``."""
    return {
        "T_parent_joint": robot.T_parent_joint.tolist(),
        "axes": robot.axes.tolist(),
        "gravity": robot.gravity.tolist(),
    }


def recorded_robot_mismatch(
    robot: Robot, metadata: Mapping[str, Any], *, atol: float = 1e-9
) -> str | None:
    """Why the data's recorded robot is not ``robot`` (one line), or None.

    Compares the recorded name, the joint count of the recorded kinematics, then the
    kinematics entry by entry (largest absolute difference, tolerance ``atol``).
    """
    name = metadata.get("robot")
    if isinstance(name, str) and name != robot.name:
        return f"the data were recorded with robot {name!r}; the robot given is {robot.name!r}"
    kin = metadata.get("kinematics")
    if not isinstance(kin, Mapping):
        return None
    for key, mine in (
        ("T_parent_joint", robot.T_parent_joint),
        ("axes", robot.axes),
        ("gravity", robot.gravity),
    ):
        if key not in kin:
            continue
        try:
            theirs = np.asarray(kin[key], dtype=np.float64)
        except (TypeError, ValueError):
            return f"the recorded kinematics' {key!r} is not an array of numbers"
        if theirs.shape != mine.shape:
            return (
                f"the recorded kinematics' {key} has shape {theirs.shape}; robot "
                f"{robot.name!r} has {mine.shape} ({robot.n} joints)"
            )
        diff = float(np.max(np.abs(theirs - mine))) if theirs.size else 0.0
        if not diff <= atol:
            snap = key == "T_parent_joint" and diff <= _ROUNDING
            return (
                f"the recorded kinematics differ from those of robot {robot.name!r}: largest "
                f"difference {diff:.3g} in {key}"
                + (
                    " (the size of a URDF angle rounded near a multiple of pi/2: read as "
                    "written for one and snapped for the other? give --snap-angles to both "
                    "commands or to neither)"
                    if snap
                    else ""
                )
            )
    return None


def limit_violations(robot: Robot, q: NDArray[np.float64]) -> str | None:
    """One line on the configurations ``q`` (N, n) outside the joint limits, or None."""
    below = q < robot.q_min
    above = q > robot.q_max
    bad = np.any(below | above, axis=1)
    if not bad.any():
        return None
    excess = np.maximum(robot.q_min - q, q - robot.q_max)
    s, j = np.unravel_index(int(np.argmax(excess)), excess.shape)
    return (
        f"{int(bad.sum())} of {q.shape[0]} configurations lie outside the joint limits of "
        f"{robot.name!r}; worst: row {int(s)}, {robot.joint_names[j]} = {q[s, j]:.6g} "
        f"(limits {robot.q_min[j]:.6g}..{robot.q_max[j]:.6g})"
    )


def fit_mismatch(relative_error_percent: float, metadata: Mapping[str, Any]) -> str | None:
    """One line when the fit's relative error is far above the recorded noise, or None."""
    noise = metadata.get("relative_noise")
    if not isinstance(noise, (int, float)) or isinstance(noise, bool) or not noise >= 0:
        return None
    allowed = max(NOISE_FREE_RELATIVE_ERROR_PERCENT, NOISE_FACTOR * 100.0 * float(noise))
    if relative_error_percent <= allowed:
        return None
    return (
        f"relative error {relative_error_percent:.4g} % on data recorded with relative noise "
        f"{noise:g} (expected at most {allowed:.3g} %): the data do not fit this robot's "
        "model; check --robot"
    )
