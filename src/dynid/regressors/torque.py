"""Torque regressor ``Y(q, dq, ddq)``, linear in the standard parameters, batched.

.. math:: \\tau = Y(q, \\dot q, \\ddot q) \\, \\phi

``phi`` is the robot's flattened standard parameter vector (10 per link: ``m, m c,
J`` about the link origin; :func:`dynid.param_labels`), so ``Y`` has shape
``(..., n, 10 n)``; friction is not included. The link wrench about its origin, in link
coordinates, is linear in that link's parameters (Atkeson, An and Hollerbach 1986;
Khalil and Dombre 2002, ch. 12):

.. math:: f = m a + \\dot\\omega \\times mc + \\omega \\times (\\omega \\times mc), \\quad
          n = J \\dot\\omega + \\omega \\times J\\omega + mc \\times a

with ``a`` the origin's acceleration minus gravity; a backward pass projects the wrenches
of links ``j >= i`` onto joint ``i``.

Stacking for least squares is sample-major: ``Y.reshape(-1, 10 n)`` has row ``s*n + i``
for sample ``s``, joint ``i``.
"""

from __future__ import annotations

import numpy as np
from numpy.typing import ArrayLike, NDArray

from .. import _checks
from ..dynamics.rnea import _prepare, link_motion
from ..model.robot import Robot

__all__ = ["torque_regressor", "link_wrench_regressor"]


def _skew(v: NDArray[np.float64]) -> NDArray[np.float64]:
    S = np.zeros(v.shape[:-1] + (3, 3))
    S[..., 0, 1], S[..., 0, 2], S[..., 1, 2] = -v[..., 2], v[..., 1], -v[..., 0]
    return S - np.swapaxes(S, -1, -2)


def _inertia_operator(v: NDArray[np.float64]) -> NDArray[np.float64]:
    """L(v), (B, 3, 6), with ``J v = L(v) [Jxx, Jxy, Jxz, Jyy, Jyz, Jzz]``."""
    L = np.zeros(v.shape[:-1] + (3, 6))
    x, y, z = v[..., 0], v[..., 1], v[..., 2]
    L[..., 0, 0], L[..., 0, 1], L[..., 0, 2] = x, y, z
    L[..., 1, 1], L[..., 1, 3], L[..., 1, 4] = x, y, z
    L[..., 2, 2], L[..., 2, 4], L[..., 2, 5] = x, y, z
    return L


def link_wrench_regressor(
    w: NDArray[np.float64], dw: NDArray[np.float64], a: NDArray[np.float64]
) -> NDArray[np.float64]:
    """K (B, 6, 10) with ``[f; n] = K phi_link`` (wrench about the link origin, link axes).

    ``w``, ``dw``, ``a``: (B, 3) angular velocity, angular acceleration and origin
    acceleration minus gravity, in link coordinates.
    """
    B = w.shape[0]
    K = np.zeros((B, 6, 10))
    Sw, Sdw, Sa = _skew(w), _skew(dw), _skew(a)
    K[:, :3, 0] = a
    K[:, :3, 1:4] = Sdw + Sw @ Sw
    K[:, 3:, 1:4] = -Sa
    K[:, 3:, 4:] = _inertia_operator(dw) + Sw @ _inertia_operator(w)
    return K


def _torque_regressor(
    robot: Robot,
    q: NDArray[np.float64],
    dq: NDArray[np.float64],
    ddq: NDArray[np.float64],
    gravity: NDArray[np.float64],
) -> NDArray[np.float64]:
    """(B, n, 10 n) regressor for validated (B, n) inputs; gravity (3,) or (B, 3)."""
    B, n = q.shape
    mot = link_motion(robot, q, dq, ddq, gravity)
    Y = np.zeros((B, n, 10 * n))
    U = np.zeros((B, 6, 0))  # wrench regressor of links > i, columns of those links
    for i in range(n - 1, -1, -1):
        K = link_wrench_regressor(mot.w[:, i], mot.dw[:, i], mot.a[:, i])
        if i < n - 1:
            R, p = mot.R[:, i + 1], mot.p[:, i + 1]
            RF = R @ U[:, :3]
            RN = R @ U[:, 3:] + _skew(p) @ RF
            U = np.concatenate([K, np.concatenate([RF, RN], axis=1)], axis=2)
        else:
            U = K
        rows = U[:, :3] if robot.prismatic[i] else U[:, 3:]
        Y[:, i, 10 * i :] = np.einsum("k,bkp->bp", robot.axes[i], rows)
    return Y


def torque_regressor(
    robot: Robot,
    q: ArrayLike,
    dq: ArrayLike,
    ddq: ArrayLike,
    *,
    gravity: ArrayLike | None = None,
) -> NDArray[np.float64]:
    """Regressor of the inverse dynamics in the standard parameters.

    Parameters
    ----------
    q, dq, ddq : array_like, shape (..., n)
        Joint positions [rad], velocities [rad/s], accelerations [rad/s^2]; broadcast.
    gravity : array_like, shape (3,), optional
        Gravity in the base frame [m/s^2]; default ``robot.gravity``.

    Returns
    -------
    Y : ndarray, shape (..., n, 10 n)
        ``Y @ robot.phi.reshape(-1) == rnea(robot, q, dq, ddq)``; columns labelled by
        ``robot.param_labels``.

    Raises
    ------
    ShapeError, NonFiniteError
    """
    shape, (q2, dq2, ddq2) = _prepare(robot, q, dq, ddq)
    g = robot.gravity if gravity is None else _checks.as_exact("gravity", gravity, (3,))
    Y = _torque_regressor(robot, q2, dq2, ddq2, g)
    return Y.reshape(shape + (10 * robot.n,))


