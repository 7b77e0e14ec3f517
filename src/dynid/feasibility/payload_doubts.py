"""When a payload estimate is not a load to trust.

* a mass less than :data:`MIN_MASS_SIGMAS` standard deviations above zero: the data
  cannot tell the load from none (unloaded data, or a load too light for them); its CoM
  is then the first moment ``m c`` divided by a mass near zero, and its inertia noise;
* a CoM farther from the frame than the arm is long (:func:`arm_length`): no load the arm
  carries reaches past its own base.

Such an estimate is not handed to a controller (``payload.json`` leaves libfranka's
``setLoad`` values out).
"""

from __future__ import annotations

import numpy as np
from numpy.typing import NDArray

from ..kinematics.forward import link_poses
from ..model.robot import Robot

__all__ = ["MIN_MASS_SIGMAS", "arm_length", "doubts_about"]

#: A load's mass must lie this many standard deviations above zero to be told from none.
MIN_MASS_SIGMAS = 3.0


def arm_length(robot: Robot) -> float:
    """The arm's length [m]: the distances between consecutive link frames (fixed for
    revolute joints) summed, plus the longest offset of a frame from its link."""
    p = np.asarray(link_poses(robot, np.zeros(robot.n)))[:, :3, 3]
    links = float(np.sum(np.linalg.norm(np.diff(p, axis=0), axis=1)))
    offsets = [float(np.linalg.norm(f.T_link_frame[:3, 3])) for f in robot.frames.values()]
    return links + max(offsets, default=0.0)


def doubts_about(
    robot: Robot, frame: str, m: float, sm: float, c: NDArray[np.float64]
) -> tuple[str, ...]:
    """Why the estimate is not a load to trust (module docstring); empty when none."""
    out = []
    if not m > MIN_MASS_SIGMAS * sm:
        out.append(
            f"the load's mass {m:.3g} kg is not significantly above zero (std {sm:.2g} kg, "
            f"{m / sm if sm > 0 else float('inf'):.1f} std; at least {MIN_MASS_SIGMAS:g} "
            "needed): the data cannot tell this load from none (unloaded data, or a load too "
            "light for them); its CoM and inertia are noise divided by that mass"
        )
    reach = arm_length(robot)
    dist = float(np.linalg.norm(c))
    if dist > reach:
        out.append(
            f"the load's CoM lies {dist:.3g} m from frame {frame!r}, farther than the arm is "
            f"long ({reach:.3g} m): no load the arm carries reaches that far; the first "
            "moment m c was divided by a mass near zero, or the arm's model is wrong"
        )
    return tuple(out)
