"""Forward kinematics: poses of links and named frames, batched.

``q`` has shape ``(..., n)`` [rad for revolute, m for prismatic joints]; every result keeps
the batch shape ``...``. Poses are ``T_base_x``: frame x in the base frame (link 0) [m].

Two implementations compute the same poses (to rounding, about 1e-16 relative):

* the compiled kernels of :mod:`dynid._kernels.kinematics` (numba), used when numba is
  installed: a loop over samples and joints, compiled on the first call and cached on
  disk; importing dynid does not import numba;
* the numpy reference path (:func:`link_poses_numpy`, :func:`fk_numpy`): samples
  vectorised, a loop over joints.

:func:`link_poses` and :func:`fk` (and :func:`dynid.kinematics.jacobian.jacobian`) use the
kernels when :func:`kernels` finds them and the numpy path otherwise. Set the environment
variable ``DYNID_NO_NUMBA=1`` before the first kinematics call to force the numpy path.
"""

from __future__ import annotations

from types import ModuleType

import numpy as np
from numpy.typing import ArrayLike, NDArray

from .. import _checks, _kernels
from ..model.robot import Robot, checked_robot

__all__ = [
    "joint_transforms",
    "link_poses",
    "link_poses_numpy",
    "fk",
    "fk_numpy",
    "frame_pose_in_link",
    "kernels",
]

_KERNELS = _kernels.KERNELS
_LINK_POSES, _FRAME_POSE = _KERNELS["link_poses"], _KERNELS["frame_pose"]


def kernels() -> ModuleType | None:
    """The compiled kinematics kernels, or None when numba is missing or ``DYNID_NO_NUMBA``
    is set (:func:`dynid._kernels.dispatch.load`; ``DYNID_NO_NUMBA`` is read on the first
    call, and any value other than ``""`` and ``"0"`` selects the numpy reference path)."""
    return _kernels.load("kinematics")


def frame_constants(
    robot: Robot, frame: str, tool: ArrayLike | None
) -> tuple[int, NDArray[np.float64], NDArray[np.float64]]:
    """``(link, T_link_frame, CF)`` of ``frame`` with ``tool`` multiplied in; ``CF`` are the
    kernels' constants with the frame (:func:`dynid._kernels.dispatch.frame_entry`)."""
    if tool is None:
        return _kernels.frame_entry(robot, frame)
    link, T = frame_pose_in_link(robot, frame, tool)
    return link, T, _kernels.pack_frame(_kernels.constants(robot), link, T)


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


def joint_rotations_translations(
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
    checked_robot(robot)
    q = check_q(robot, q)
    R, p = joint_rotations_translations(robot, q.reshape(-1, robot.n))
    T = np.zeros(R.shape[:-2] + (4, 4))
    T[..., :3, :3], T[..., :3, 3], T[..., 3, 3] = R, p, 1.0
    return T.reshape(q.shape[:-1] + (robot.n, 4, 4))


def link_poses_prepared(robot: Robot, q2: NDArray[np.float64]) -> NDArray[np.float64]:
    """(B, n + 1, 4, 4) link poses for validated ``q2`` of shape (B, n)."""
    B, n = q2.shape
    R, p = joint_rotations_translations(robot, q2)
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
    checked_robot(robot)
    T = _kernels.run(_LINK_POSES, robot, (q,), (len(robot.joint_names) + 1, 4, 4))
    if T is not None:
        return T
    return link_poses_numpy(robot, q)


def link_poses_numpy(robot: Robot, q: ArrayLike) -> NDArray[np.float64]:
    """:func:`link_poses` by the numpy reference path, never the compiled kernel.

    Same parameters, result, shapes and errors as :func:`link_poses`.
    """
    q = check_q(robot, q)
    T = link_poses_prepared(robot, q.reshape(-1, robot.n))
    return T.reshape(q.shape[:-1] + (robot.n + 1, 4, 4))


def frame_pose_in_link(
    robot: Robot, frame: str, tool: ArrayLike | None = None
) -> tuple[int, NDArray[np.float64]]:
    """The link that carries ``frame`` and the pose of ``frame`` (then ``tool``) in that link."""
    link, T, _ = _kernels.frame_entry(robot, frame)
    if tool is not None:
        T = _kernels.readonly(T @ _checks.as_exact("tool", tool, (4, 4)))
    return link, T


@_kernels.single_sample(_FRAME_POSE, "frame", "pose")
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

    Notes
    -----
    Uses the compiled kernel when available (see :func:`kernels`), else :func:`fk_numpy`.
    """
    checked_robot(robot)
    link, T_link_frame, CF = frame_constants(robot, frame, tool)
    out = _kernels.run(_FRAME_POSE, robot, (q,), (4, 4), CF)
    if out is not None:
        return out
    return _fk_numpy(robot, q, link, T_link_frame)


def fk_numpy(
    robot: Robot, q: ArrayLike, frame: str = "flange", tool: ArrayLike | None = None
) -> NDArray[np.float64]:
    """:func:`fk` by the numpy reference path, never the compiled kernel.

    Same parameters, result, shapes and errors as :func:`fk`.
    """
    link, T_link_frame = frame_pose_in_link(robot, frame, tool)
    return _fk_numpy(robot, q, link, T_link_frame)


def _fk_numpy(
    robot: Robot, q: ArrayLike, link: int, T_link_frame: NDArray[np.float64]
) -> NDArray[np.float64]:
    """The numpy path of :func:`fk` once the frame is resolved: validates ``q``."""
    q = check_q(robot, q)
    T = link_poses_prepared(robot, q.reshape(-1, robot.n))[:, link] @ T_link_frame
    return T.reshape(q.shape[:-1] + (4, 4))
