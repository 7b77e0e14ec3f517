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

Two implementations compute the same regressor (to rounding): the compiled kernel of
:mod:`dynid._kernels.regressors` (numba; one pass over the samples, the link wrench
regressors carried to the base frame and projected on the joints, writing only the columns
asked for), used when numba is available and ``DYNID_NO_NUMBA`` is unset, and the numpy
path (:func:`torque_regressor_numpy`: samples vectorised, a loop over joints).
"""

from __future__ import annotations

import numpy as np
from numpy.typing import ArrayLike, NDArray

from .. import _checks, _kernels
from ..dynamics.rnea import link_motion, prepare_states
from ..model.robot import Robot, checked_robot
from ..spatial import skew

__all__ = [
    "inertia_operator",
    "link_wrench_regressor",
    "torque_regressor",
    "torque_regressor_numpy",
]

_TORQUE = _kernels.KERNELS["torque_regressor"]


def inertia_operator(v: NDArray[np.float64]) -> NDArray[np.float64]:
    """L(v), (..., 3, 6), with ``J v = L(v) [Jxx, Jxy, Jxz, Jyy, Jyz, Jzz]``."""
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
    Sw, Sdw, Sa = skew(w), skew(dw), skew(a)
    K[:, :3, 0] = a
    K[:, :3, 1:4] = Sdw + Sw @ Sw
    K[:, 3:, 1:4] = -Sa
    K[:, 3:, 4:] = inertia_operator(dw) + Sw @ inertia_operator(w)
    return K


def torque_regressor_prepared(
    robot: Robot,
    q: NDArray[np.float64],
    dq: NDArray[np.float64],
    ddq: NDArray[np.float64],
    gravity: NDArray[np.float64],
    columns: NDArray[np.intp] | None = None,
    width: int | None = None,
) -> NDArray[np.float64]:
    """(B, n, 10 n) regressor for validated (B, n) inputs; gravity (3,) or (B, 3).

    With ``columns`` (distinct standard-parameter indices), only those columns, in that
    order, as the first ``len(columns)`` of a (B, n, ``width``) array (default width:
    ``len(columns)``) whose other columns are uninitialised, for the caller to fill. The
    compiled kernel (:mod:`dynid._kernels.regressors`) writes them directly when it is
    available, else :func:`_torque_regressor_numpy` gathers them.
    """
    B, n = q.shape
    idx = np.arange(10 * n) if columns is None else np.asarray(columns, dtype=np.intp)
    w = idx.size if width is None else int(width)
    K = _kernels.compiled(_TORQUE, 2) if np.ndim(gravity) == 1 else None
    if K is not None:
        cols = np.full(10 * n, -1, dtype=np.int64)  # output column of each parameter
        cols[idx] = np.arange(idx.size)
        C = _kernels.constants_for(robot, robot.phi, gravity)
        Y = np.empty((B, n, w))
        flat = _kernels.flat
        if K(C, flat(q), flat(dq), flat(ddq), cols, Y):
            return Y
    Yn = _torque_regressor_numpy(robot, q, dq, ddq, gravity)
    if columns is None and width is None:
        return Yn
    Y = np.empty((B, n, w))
    Y[..., : idx.size] = Yn[..., idx]
    return Y


def _torque_regressor_numpy(
    robot: Robot,
    q: NDArray[np.float64],
    dq: NDArray[np.float64],
    ddq: NDArray[np.float64],
    gravity: NDArray[np.float64],
) -> NDArray[np.float64]:
    """Numpy path: (B, n, 10 n) regressor for validated (B, n) inputs; gravity (3,) or (B, 3).

    Every link's wrench regressor is carried to the base frame (moment about the base
    origin), then projected on every joint at once: for a revolute joint i with axis z_i
    through o_i, ``tau_i = z_i . N + (o_i x z_i) . F``; for a prismatic one ``z_i . F``;
    links before joint i do not act on it.
    """
    B, n = q.shape
    mot = link_motion(robot, q, dq, ddq, gravity)
    K = link_wrench_regressor(
        mot.w.reshape(-1, 3), mot.dw.reshape(-1, 3), mot.a.reshape(-1, 3)
    ).reshape(B, n, 6, 10)
    R0 = np.empty((B, n, 3, 3))
    p0 = np.empty((B, n, 3))
    Rc = np.broadcast_to(np.eye(3), (B, 3, 3))
    pc = np.zeros((B, 3))
    for i in range(n):
        pc = pc + (Rc @ mot.p[:, i, :, None])[..., 0]
        Rc = Rc @ mot.R[:, i]
        R0[:, i], p0[:, i] = Rc, pc
    W = np.empty((B, n, 6, 10))
    W[:, :, :3] = R0 @ K[:, :, :3]
    W[:, :, 3:] = R0 @ K[:, :, 3:] + skew(p0) @ W[:, :, :3]
    z = (R0 @ robot.axes[:, :, None])[..., 0]  # (B, n, 3)
    A = np.empty((B, n, 6))
    pri = robot.prismatic
    A[:, :, :3] = np.where(pri[:, None], z, np.cross(p0, z))
    A[:, :, 3:] = np.where(pri[:, None], 0.0, z)
    Y = A @ W.transpose(0, 2, 1, 3).reshape(B, 6, 10 * n)
    Y *= _ACTS[n]
    return Y


class _ActsOn(dict):
    """Masks (n, 10 n): link j's columns act on joint i only when j >= i."""

    def __missing__(self, n: int) -> NDArray[np.float64]:
        mask = np.repeat(np.triu(np.ones((n, n))), 10, axis=1)
        mask.setflags(write=False)
        self[n] = mask
        return mask


_ACTS = _ActsOn()


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

    Notes
    -----
    Compiled over the batch (:mod:`dynid._kernels.regressors`) when numba is available,
    else :func:`torque_regressor_numpy`.
    """
    checked_robot(robot)
    shape, (q2, dq2, ddq2) = prepare_states(robot, q, dq, ddq)
    g = robot.gravity if gravity is None else _checks.as_exact("gravity", gravity, (3,))
    Y = torque_regressor_prepared(robot, q2, dq2, ddq2, g)
    return Y.reshape(shape + (10 * robot.n,))


def torque_regressor_numpy(
    robot: Robot,
    q: ArrayLike,
    dq: ArrayLike,
    ddq: ArrayLike,
    *,
    gravity: ArrayLike | None = None,
) -> NDArray[np.float64]:
    """:func:`torque_regressor` by the numpy reference path, never the compiled kernel.

    Same parameters, result, shapes and errors as :func:`torque_regressor`.
    """
    shape, (q2, dq2, ddq2) = prepare_states(robot, q, dq, ddq)
    g = robot.gravity if gravity is None else _checks.as_exact("gravity", gravity, (3,))
    Y = _torque_regressor_numpy(robot, q2, dq2, ddq2, g)
    return Y.reshape(shape + (10 * robot.n,))
