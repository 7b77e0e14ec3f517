"""Rotations, homogeneous transforms, skew matrices and angle-axis, batched.

Conventions: ``T_a_b`` (shape ``(..., 4, 4)``) is the pose of frame b in frame a, so
``p_a = T_a_b @ p_b``; ``R_a_b`` is its rotation block. Roll-pitch-yaw follow URDF:
``R = Rz(yaw) @ Ry(pitch) @ Rx(roll)`` (fixed axes x, y, z). Angles in rad, lengths in m.
Every function accepts any leading batch shape and returns the same batch shape.
"""

from __future__ import annotations

import numpy as np
from numpy.typing import ArrayLike, NDArray

from . import _checks

__all__ = [
    "skew",
    "rot_x",
    "rot_y",
    "rot_z",
    "matrix_from_rpy",
    "rpy_from_matrix",
    "matrix_from_angle_axis",
    "angle_axis_from_matrix",
    "transform",
    "inverse_transform",
    "transform_from_xyz_rpy",
    "translation",
]


def skew(v: ArrayLike) -> NDArray[np.float64]:
    """Skew-symmetric matrix ``[v]x`` with ``[v]x @ w == cross(v, w)``; (..., 3) -> (..., 3, 3)."""
    v = _checks.as_batch("v", v, (3,))
    S = np.zeros(v.shape[:-1] + (3, 3))
    S[..., 0, 1], S[..., 0, 2] = -v[..., 2], v[..., 1]
    S[..., 1, 0], S[..., 1, 2] = v[..., 2], -v[..., 0]
    S[..., 2, 0], S[..., 2, 1] = -v[..., 1], v[..., 0]
    return S


def _rot(angle: ArrayLike, i: int, j: int) -> NDArray[np.float64]:
    a = _checks.as_array("angle", angle)
    c, s = np.cos(a), np.sin(a)
    R = np.zeros(a.shape + (3, 3))
    k = 3 - i - j
    R[..., k, k] = 1.0
    R[..., i, i], R[..., i, j] = c, -s
    R[..., j, i], R[..., j, j] = s, c
    return R


def rot_x(angle: ArrayLike) -> NDArray[np.float64]:
    """Rotation about x by ``angle`` [rad]; shape (...) -> (..., 3, 3)."""
    return _rot(angle, 1, 2)


def rot_y(angle: ArrayLike) -> NDArray[np.float64]:
    """Rotation about y by ``angle`` [rad]; shape (...) -> (..., 3, 3)."""
    return _rot(angle, 2, 0)


def rot_z(angle: ArrayLike) -> NDArray[np.float64]:
    """Rotation about z by ``angle`` [rad]; shape (...) -> (..., 3, 3)."""
    return _rot(angle, 0, 1)


def matrix_from_rpy(rpy: ArrayLike) -> NDArray[np.float64]:
    """Rotation from URDF roll-pitch-yaw [rad], ``Rz(y) Ry(p) Rx(r)``; (..., 3) -> (..., 3, 3)."""
    rpy = _checks.as_batch("rpy", rpy, (3,))
    return rot_z(rpy[..., 2]) @ rot_y(rpy[..., 1]) @ rot_x(rpy[..., 0])


def rpy_from_matrix(R: ArrayLike) -> NDArray[np.float64]:
    """URDF roll-pitch-yaw [rad] of a rotation matrix (inverse of :func:`matrix_from_rpy`).

    Roll is read first, then pitch and yaw from ``R Rx(-roll) = Rz(yaw) Ry(pitch)``, whose
    entries stay O(1) near gimbal lock (pitch = ±pi/2), so ``matrix_from_rpy`` of the result
    reproduces ``R`` to rounding error everywhere; (..., 3, 3) -> (..., 3).
    """
    R = _checks.as_batch("R", R, (3, 3))
    roll = np.arctan2(R[..., 2, 1], R[..., 2, 2])
    Rr = R @ rot_x(-roll)
    pitch = np.arctan2(-Rr[..., 2, 0], Rr[..., 2, 2])
    yaw = np.arctan2(-Rr[..., 0, 1], Rr[..., 1, 1])
    return np.stack([roll, pitch, yaw], axis=-1)


def matrix_from_angle_axis(rotvec: ArrayLike) -> NDArray[np.float64]:
    """Rotation from a rotation vector ``theta * u`` [rad] (Rodrigues); (..., 3) -> (..., 3, 3)."""
    w = _checks.as_batch("rotvec", rotvec, (3,))
    theta = np.linalg.norm(w, axis=-1)
    small = theta < 1e-8
    t = np.where(small, 1.0, theta)
    # sin(t)/t and (1-cos t)/t^2 with their Taylor series near 0
    a = np.where(small, 1.0 - theta**2 / 6.0, np.sin(t) / t)
    b = np.where(small, 0.5 - theta**2 / 24.0, (1.0 - np.cos(t)) / t**2)
    K = skew(w)
    return np.eye(3) + a[..., None, None] * K + b[..., None, None] * (K @ K)


def angle_axis_from_matrix(R: ArrayLike) -> NDArray[np.float64]:
    """Rotation vector ``theta * u`` [rad] of a rotation matrix, ``theta`` in [0, pi].

    Robust over the whole range: near 0 it uses the first-order series of the log map,
    near pi it reads the axis from the symmetric part ``(R + R^T)/2 = cos I + (1 - cos) u u^T``
    with the sign fixed by the skew part.

    Parameters
    ----------
    R : array_like, shape (..., 3, 3)
        Rotation matrices (orthonormal, det +1).

    Returns
    -------
    rotvec : ndarray, shape (..., 3)
    """
    R = _checks.as_batch("R", R, (3, 3))
    v = 0.5 * np.stack(
        [R[..., 2, 1] - R[..., 1, 2], R[..., 0, 2] - R[..., 2, 0], R[..., 1, 0] - R[..., 0, 1]],
        axis=-1,
    )  # sin(theta) * u
    cos = np.clip((np.trace(R, axis1=-2, axis2=-1) - 1.0) / 2.0, -1.0, 1.0)
    sin = np.linalg.norm(v, axis=-1)
    theta = np.arctan2(sin, cos)
    out = np.empty(R.shape[:-2] + (3,))
    # regular and small angles: theta / sin(theta) * v (-> v as theta -> 0)
    near_pi = cos < -0.9
    safe_sin = np.where(sin > 1e-300, sin, 1.0)
    scale = np.where(sin > 1e-12, theta / safe_sin, 1.0 + theta**2 / 6.0)
    out[...] = scale[..., None] * v
    if np.any(near_pi):
        Rp = R[near_pi]
        S = 0.5 * (Rp + np.swapaxes(Rp, -1, -2))
        one_minus_cos = (1.0 - cos[near_pi])[..., None, None]
        cos_p = cos[near_pi][..., None, None]
        uu = (S - cos_p * np.eye(3)) / one_minus_cos  # u u^T
        k = np.argmax(np.diagonal(uu, axis1=-2, axis2=-1), axis=-1)
        rows = np.take_along_axis(uu, k[:, None, None], axis=-2)[:, 0, :]
        u = rows / np.sqrt(np.take_along_axis(rows, k[:, None], axis=-1))
        vp = v[near_pi]
        # within 1e-12 of pi the skew part is rounding noise: keep u's largest entry positive
        sign = np.where(np.einsum("...i,...i->...", u, vp) < -1e-12, -1.0, 1.0)
        out[near_pi] = (sign * theta[near_pi])[..., None] * u
    return out


def transform(R: ArrayLike, p: ArrayLike) -> NDArray[np.float64]:
    """Homogeneous transform from rotation (..., 3, 3) and translation (..., 3) [m]."""
    R = _checks.as_batch("R", R, (3, 3))
    p = _checks.as_batch("p", p, (3,))
    shape = np.broadcast_shapes(R.shape[:-2], p.shape[:-1])
    T = np.zeros(shape + (4, 4))
    T[..., :3, :3] = R
    T[..., :3, 3] = p
    T[..., 3, 3] = 1.0
    return T


def translation(p: ArrayLike) -> NDArray[np.float64]:
    """Pure translation transform; (..., 3) -> (..., 4, 4)."""
    p = _checks.as_batch("p", p, (3,))
    return transform(np.broadcast_to(np.eye(3), p.shape[:-1] + (3, 3)), p)


def transform_from_xyz_rpy(xyz: ArrayLike, rpy: ArrayLike = (0.0, 0.0, 0.0)) -> NDArray[np.float64]:
    """Transform from a URDF origin: translation ``xyz`` [m] and roll-pitch-yaw ``rpy`` [rad]."""
    return transform(matrix_from_rpy(rpy), xyz)


def inverse_transform(T: ArrayLike) -> NDArray[np.float64]:
    """Inverse of a rigid transform, ``T_b_a`` from ``T_a_b``, without a general inverse."""
    T = _checks.as_batch("T", T, (4, 4))
    Rt = np.swapaxes(T[..., :3, :3], -1, -2)
    return transform(Rt, -np.einsum("...ij,...j->...i", Rt, T[..., :3, 3]))
