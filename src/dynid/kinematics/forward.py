"""Forward kinematics: poses of links and named frames, batched.

``q`` has shape ``(..., n)`` [rad for revolute, m for prismatic joints]; every result keeps
the batch shape ``...``. Poses are ``T_base_x``: frame x in the base frame (link 0) [m].
"""

from __future__ import annotations

import numpy as np
from numpy.typing import ArrayLike, NDArray

from .. import _checks
from ..model.robot import Robot

__all__ = ["joint_transforms", "link_poses", "fk", "frame_pose_in_link"]


def check_q(robot: Robot, q: ArrayLike, name: str = "q") -> NDArray[np.float64]:
    """Validate joint vectors: shape (..., n), finite."""
    return _checks.as_batch(name, q, (robot.n,))


def _joint_motion(robot: Robot, q: NDArray[np.float64]) -> tuple[NDArray, NDArray]:
    """Rotation (B, n, 3, 3) and translation (B, n, 3) of each joint's motion, in its own frame."""
    B, n = q.shape
    ax = robot.axes
    R = np.broadcast_to(np.eye(3), (B, n, 3, 3)).copy()
    p = np.zeros((B, n, 3))
    rev = ~robot.prismatic
    if np.any(rev):
        qr = q[:, rev]
        a = ax[rev]
        s, c = np.sin(qr)[..., None, None], np.cos(qr)[..., None, None]
        K = np.zeros((a.shape[0], 3, 3))
        K[:, 0, 1], K[:, 0, 2], K[:, 1, 2] = -a[:, 2], a[:, 1], -a[:, 0]
        K = K - np.swapaxes(K, -1, -2)
        R[:, rev] = np.eye(3) + s * K + (1.0 - c) * (K @ K)
    if np.any(robot.prismatic):
        p[:, robot.prismatic] = q[:, robot.prismatic, None] * ax[robot.prismatic]
    return R, p


def _joint_rotations_translations(
    robot: Robot, q: NDArray[np.float64]
) -> tuple[NDArray[np.float64], NDArray[np.float64]]:
    """Rotation R_{i-1,i} (B, n, 3, 3) and origin p_{i-1,i} (B, n, 3) of each link in its parent.

    ``q`` must be validated with shape (B, n).
    """
    Rq, pq = _joint_motion(robot, q)
    Rf = robot.T_parent_joint[:, :3, :3]
    pf = robot.T_parent_joint[:, :3, 3]
    R = Rf @ Rq
    p = pf + (Rf @ pq[..., None])[..., 0]
    return R, p


def joint_transforms(robot: Robot, q: ArrayLike) -> NDArray[np.float64]:
    """Pose of link i in link i-1, ``T_{i-1,i}(q_i)``, for every joint.

    Parameters
    ----------
    q : array_like, shape (..., n)

    Returns
    -------
    T : ndarray, shape (..., n, 4, 4)
    """
    q = check_q(robot, q)
    R, p = _joint_rotations_translations(robot, q.reshape(-1, robot.n))
    T = np.zeros(R.shape[:-2] + (4, 4))
    T[..., :3, :3], T[..., :3, 3], T[..., 3, 3] = R, p, 1.0
    return T.reshape(q.shape[:-1] + (robot.n, 4, 4))


def _link_poses(robot: Robot, q2: NDArray[np.float64]) -> NDArray[np.float64]:
    """(B, n + 1, 4, 4) link poses for validated ``q2`` of shape (B, n)."""
    B, n = q2.shape
    R, p = _joint_rotations_translations(robot, q2)
    T = np.zeros((B, n + 1, 4, 4))
    T[:, :, 3, 3] = 1.0
    T[:, 0, :3, :3] = np.eye(3)
    Rb, pb = np.broadcast_to(np.eye(3), (B, 3, 3)), np.zeros((B, 3))
    for i in range(n):
        pb = pb + (Rb @ p[:, i, :, None])[..., 0]
        Rb = Rb @ R[:, i]
        T[:, i + 1, :3, :3], T[:, i + 1, :3, 3] = Rb, pb
    return T


def link_poses(robot: Robot, q: ArrayLike) -> NDArray[np.float64]:
    """Poses of all link frames in the base frame, ``T_base_link``.

    Parameters
    ----------
    q : array_like, shape (..., n)
        Joint positions [rad or m].

    Returns
    -------
    T_base_link : ndarray, shape (..., n + 1, 4, 4)
        Index 0 is the base (identity), index i is link i; translations in [m].
    """
    q = check_q(robot, q)
    T = _link_poses(robot, q.reshape(-1, robot.n))
    return T.reshape(q.shape[:-1] + (robot.n + 1, 4, 4))


def frame_pose_in_link(
    robot: Robot, frame: str, tool: ArrayLike | None = None
) -> tuple[int, NDArray[np.float64]]:
    """The link that carries ``frame`` and the pose of ``frame`` (then ``tool``) in that link."""
    f = robot.frame(frame)
    T = f.T_link_frame
    if tool is not None:
        T = T @ _checks.as_exact("tool", tool, (4, 4))
    return f.link, T


def fk(
    robot: Robot, q: ArrayLike, frame: str = "flange", tool: ArrayLike | None = None
) -> NDArray[np.float64]:
    """Pose of a named frame (optionally of a tool fixed to it) in the base frame.

    .. math:: T_{base,tool} = T_{base,link}(q) \\; T_{link,frame} \\; T_{frame,tool}

    Parameters
    ----------
    robot : Robot
    q : array_like, shape (..., n)
        Joint positions [rad or m].
    frame : str
        A frame of ``robot.frames`` (``"flange"``, a link name, ...).
    tool : array_like, shape (4, 4), optional
        Pose of a tool in ``frame`` [m].

    Returns
    -------
    T_base_frame : ndarray, shape (..., 4, 4)

    Raises
    ------
    ShapeError
        ``q`` does not end in ``n`` or ``tool`` is not 4x4.
    NonFiniteError
        ``q`` holds NaN or inf.
    UnknownNameError
        ``frame`` is not a frame of the robot.
    """
    link, T_link_frame = frame_pose_in_link(robot, frame, tool)
    q = check_q(robot, q)
    T = _link_poses(robot, q.reshape(-1, robot.n))[:, link] @ T_link_frame
    return T.reshape(q.shape[:-1] + (4, 4))
