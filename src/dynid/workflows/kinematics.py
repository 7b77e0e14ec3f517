"""Goals of the kinematics commands: the policy of ``dynid ik``'s goal, so that the Python
API reaches it as the command does.

A goal given by its position alone keeps the orientation the frame (or the tool) has at the
start configuration: the solver then moves the point without turning the frame.
"""

from __future__ import annotations

import numpy as np
from numpy.typing import ArrayLike, NDArray

from ..exceptions import OptionError
from ..kinematics.forward import fk
from ..model.robot import Robot
from ..spatial import matrix_from_rpy, transform

__all__ = ["goal_pose"]


def goal_pose(
    robot: Robot,
    q0: NDArray[np.float64],
    xyz: ArrayLike,
    rpy: ArrayLike | None = None,
    *,
    frame: str = "flange",
    tool: NDArray[np.float64] | None = None,
) -> NDArray[np.float64]:
    """``T_base_goal`` (4, 4) from a position and, optionally, an orientation.

    Parameters
    ----------
    robot : Robot
    q0 : ndarray, shape (n,)
        The start configuration [rad or m].
    xyz : array_like, shape (3,)
        The goal position in the base frame [m].
    rpy : array_like, shape (3,), optional
        URDF roll, pitch, yaw [rad] of the goal in the base frame; default: the
        orientation of ``frame`` (with ``tool``) at ``q0``.
    frame : str
        The frame the goal is for.
    tool : ndarray, shape (4, 4), optional
        ``T_frame_tool`` of a tool fixed to ``frame``.

    Returns
    -------
    ndarray, shape (4, 4)

    Raises
    ------
    OptionError
        ``xyz`` or ``rpy`` not 3 finite numbers (``field`` names it).
    """
    p = _three(xyz, "goal_xyz")
    if rpy is None:
        R = fk(robot, q0, frame, tool)[:3, :3]
    else:
        R = matrix_from_rpy(_three(rpy, "goal_rpy"))
    return np.asarray(transform(R, p), dtype=np.float64)


def _three(v: ArrayLike, field: str) -> NDArray[np.float64]:
    a = np.asarray(v, dtype=np.float64).reshape(-1)
    if a.shape != (3,) or not np.all(np.isfinite(a)):
        raise OptionError(f"must be 3 finite numbers; got {a.tolist()}", field=field)
    return a
