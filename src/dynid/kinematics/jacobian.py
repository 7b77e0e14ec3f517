"""Geometric Jacobians, batched.

``J`` has shape ``(..., 6, n)`` with rows ``[v; w]`` (linear velocity of the frame's
origin, then angular velocity), both expressed in the base frame: ``[v; w] = J(q) dq``.
Linear rows are in [m/rad] (revolute) or [m/m] (prismatic), angular rows in [rad/rad].

:func:`jacobian` uses the compiled kernel of :mod:`dynid._kernels.kinematics` when numba
is installed and the numpy reference path (:func:`jacobian_numpy`) otherwise or with
``DYNID_NO_NUMBA=1``, as :mod:`dynid.kinematics.forward` does; both agree to rounding.
"""

from __future__ import annotations

import numpy as np
from numpy.typing import ArrayLike, NDArray

from .. import _checks, _kernels
from ..exceptions import ShapeError
from ..model.robot import Robot, checked_robot
from .forward import check_q, frame_constants, frame_pose_in_link, link_poses_prepared

__all__ = ["jacobian", "jacobian_numpy", "jacobian_to_tool"]

_JACOBIAN = _kernels.KERNELS["jacobian"]


@_kernels.single_sample(_JACOBIAN, "frame", "jacobian")
def jacobian(
    robot: Robot, q: ArrayLike, frame: str = "flange", tool: ArrayLike | None = None
) -> NDArray[np.float64]:
    """Geometric Jacobian of a frame's origin (or of a tool fixed to it), in the base frame.

    Column ``i`` is ``[z_i x (p - o_i); z_i]`` for a revolute joint and ``[z_i; 0]`` for a
    prismatic one, ``z_i`` the joint axis and ``o_i`` the origin of link i in the base
    frame, ``p`` the frame's origin; joints after the frame's link give zero columns.

    Parameters
    ----------
    q : array_like, shape (..., n)
    frame : str
        Name of the frame.
    tool : array_like, shape (4, 4), optional
        Pose of a tool in ``frame`` [m]; the Jacobian is then the tool origin's.

    Returns
    -------
    J_base : ndarray, shape (..., 6, n)
        Rows ``vx, vy, vz, wx, wy, wz``; reference point: the frame's (tool's) origin.

    Raises
    ------
    ShapeError, NonFiniteError, UnknownNameError

    Notes
    -----
    Uses the compiled kernel when available (:func:`dynid._kernels.dispatch.compiled`),
    else :func:`jacobian_numpy`.
    """
    checked_robot(robot)
    link, T_link_frame, CF = frame_constants(robot, frame, tool)
    out = _kernels.run(_JACOBIAN, robot, (q,), (6, len(robot.joint_names)), CF)
    if out is not None:
        return out
    return _jacobian_numpy(robot, q, link, T_link_frame)


def jacobian_numpy(
    robot: Robot, q: ArrayLike, frame: str = "flange", tool: ArrayLike | None = None
) -> NDArray[np.float64]:
    """:func:`jacobian` by the numpy reference path, never the compiled kernel.

    Same parameters, result, shapes and errors as :func:`jacobian`.
    """
    link, T_link_frame = frame_pose_in_link(robot, frame, tool)
    return _jacobian_numpy(robot, q, link, T_link_frame)


def _jacobian_numpy(
    robot: Robot, q: ArrayLike, link: int, T_link_frame: NDArray[np.float64]
) -> NDArray[np.float64]:
    """The numpy path of :func:`jacobian` once the frame is resolved: validates ``q``."""
    q = check_q(robot, q)
    J = _frame_pose_jacobian_numpy(robot, q.reshape(-1, robot.n), link, T_link_frame)[1]
    return J.reshape(q.shape[:-1] + (6, robot.n))


def _frame_pose_jacobian_numpy(
    robot: Robot, q2: NDArray[np.float64], link: int, T_link_frame: NDArray[np.float64]
) -> tuple[NDArray[np.float64], NDArray[np.float64]]:
    """Frame pose (B, 4, 4) and Jacobian (B, 6, n) for validated (B, n) ``q2``, numpy path.

    One pass of :func:`dynid.kinematics.forward.link_poses_prepared` for both (the numpy loop of
    :func:`dynid.kinematics.inverse.ik` uses it too).
    """
    T = link_poses_prepared(robot, q2)
    Tf = T[:, link] @ T_link_frame
    p = Tf[:, :3, 3]  # (B, 3)
    z = (T[:, 1:, :3, :3] @ robot.axes[:, :, None])[..., 0]  # (B, n, 3)
    o = T[:, 1:, :3, 3]
    J = np.zeros((q2.shape[0], 6, robot.n))
    rev = ~robot.prismatic
    lin = np.where(rev[:, None], np.cross(z, p[:, None, :] - o), z)
    ang = np.where(rev[:, None], z, 0.0)
    active = np.arange(1, robot.n + 1) <= link
    J[:, :3, :] = np.swapaxes(lin, 1, 2) * active
    J[:, 3:, :] = np.swapaxes(ang, 1, 2) * active
    return Tf, J


def jacobian_to_tool(
    J_base_frame: ArrayLike, T_base_frame: ArrayLike, T_frame_tool: ArrayLike
) -> NDArray[np.float64]:
    """Carry a geometric Jacobian from a frame to a tool rigidly attached to it.

    With ``r = R_base_frame p_frame_tool`` the tool offset in the base frame,

    .. math:: J_{tool} = \\begin{bmatrix} E & -[r]_\\times \\\\ 0 & E \\end{bmatrix} J_{frame}

    Parameters
    ----------
    J_base_frame : array_like, shape (..., 6, n)
        Jacobian of the frame's origin, rows ``[v; w]`` in the base frame.
    T_base_frame : array_like, shape (..., 4, 4)
        Pose of the frame in the base frame [m].
    T_frame_tool : array_like, shape (4, 4) or (..., 4, 4)
        Pose of the tool in the frame [m].

    Returns
    -------
    J_base_tool : ndarray, shape (..., 6, n)
        Jacobian of the tool origin, in the base frame.
    """
    J = _checks.as_array("J_base_frame", J_base_frame)
    if J.ndim < 2 or J.shape[-2] != 6:
        raise ShapeError(f"J_base_frame must have shape (..., 6, n); got {J.shape}")
    T = _checks.as_batch("T_base_frame", T_base_frame, (4, 4))
    Tt = _checks.as_batch("T_frame_tool", T_frame_tool, (4, 4))
    r = np.einsum("...ij,...j->...i", T[..., :3, :3], Tt[..., :3, 3])
    w = J[..., 3:, :]
    out = np.array(np.broadcast_to(J, np.broadcast_shapes(J.shape, r.shape[:-1] + J.shape[-2:])))
    out[..., :3, :] = J[..., :3, :] + np.cross(w, r[..., :, None], axis=-2)
    return out
