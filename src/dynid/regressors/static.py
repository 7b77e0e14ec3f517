"""Static regressor of ``s(q) = [tril M(q); g(q)]`` (Gaz et al. 2019, eqs. 17-20), batched.

.. math:: s(q) = \\begin{bmatrix} \\mathrm{tril}\\, M(q) \\\\ g(q) \\end{bmatrix} = Y_s(q) \\, \\phi

The lower triangle is ordered by ``np.tril_indices(n)`` (row-major: ``M11, M21, M22, M31,
...``); then the ``n`` gravity torques. Rows: ``n (n + 1) / 2 + n`` (35 for the Panda).
Column ``k`` of ``M`` is the inverse dynamics at rest with unit acceleration ``e_k`` and no
gravity, so each row of ``Y_s`` is a row of the torque regressor.

The rows are computed in closed form from the link Jacobians rather than by ``n + 1``
regressor passes. With ``v_k``, ``w_k`` the linear velocity of the origin of link ``l`` and
its angular velocity for a unit rate of joint ``k`` (link-``l`` coordinates; zero for
``k > l``), the kinetic energy of link ``l`` gives (``h = m c``, ``J`` about the origin)

.. math:: M_{ij} = \\sum_l m_l v_i \\cdot v_j + h_l \\cdot (v_i \\times w_j + v_j \\times w_i)
          + w_i^T J_l w_j

and its potential energy ``-g_0 \\cdot (m_l p_l + R_l h_l)`` gives
:math:`g_k = \\sum_l -m_l\\, g_l \\cdot v_k + h_l \\cdot (w_k \\times g_l)`, ``g_l`` the gravity
vector in link ``l`` coordinates.
"""

from __future__ import annotations

import numpy as np
from numpy.typing import ArrayLike, NDArray

from .. import _checks
from ..kinematics.forward import _link_poses
from ..model.robot import Robot

__all__ = ["static_regressor", "static_labels", "static_vector", "static_rows"]


def static_rows(n: int) -> int:
    """Number of rows of ``s``: ``n (n + 1) / 2 + n``."""
    return n * (n + 1) // 2 + n


def static_labels(n: int) -> tuple[str, ...]:
    """Labels of the rows of ``s``: ``M1_1, M2_1, M2_2, ...`` (1-based, i >= j), ``g1..gn``."""
    i, j = np.tril_indices(n)
    return tuple(f"M{a + 1}_{b + 1}" for a, b in zip(i, j, strict=True)) + tuple(
        f"g{k + 1}" for k in range(n)
    )


def static_vector(M: ArrayLike, g: ArrayLike) -> NDArray[np.float64]:
    """Stack ``[tril M; g]``: M (..., n, n), g (..., n) -> (..., n (n + 1) / 2 + n)."""
    g = _checks.as_array("g", g)
    n = g.shape[-1]
    M = _checks.as_batch("M", M, (n, n))
    i, j = np.tril_indices(n)
    return np.concatenate([M[..., i, j], np.broadcast_to(g, M.shape[:-2] + (n,))], axis=-1)


def _static_regressor(robot: Robot, q2: NDArray[np.float64]) -> NDArray[np.float64]:
    """(B, n (n + 1) / 2 + n, 10 n) static regressor for validated (B, n) positions.

    A transposed view of :func:`_static_regressor_samples_last` (not C-contiguous).
    """
    return _static_regressor_samples_last(robot, q2).transpose(2, 0, 1)


def _static_regressor_samples_last(robot: Robot, q2: NDArray[np.float64]) -> NDArray[np.float64]:
    """The static regressor with the samples on the last axis: (n (n + 1) / 2 + n, 10 n, B)."""
    B, n = q2.shape
    T = _link_poses(robot, q2)
    # samples on the last axis: the arithmetic below runs on contiguous (.., B) rows
    R = np.ascontiguousarray(T[:, 1:, :3, :3].transpose(1, 2, 3, 0))  # (n, 3, 3, B)
    o = np.ascontiguousarray(T[:, 1:, :3, 3].transpose(1, 2, 0))  # (n, 3, B)
    z = np.einsum("lijb,lj->lib", R, robot.axes)  # joint axes in the base frame (n, 3, B)
    pri = robot.prismatic
    ii, jj = np.tril_indices(n)
    nm = ii.size
    Yt = np.zeros((nm + n, 10 * n, B))
    for l in range(n):
        k = l + 1
        # base-frame Jacobian columns of the origin of link l for joints 0..l
        lin = _cross_rows(z[:k], o[l][None] - o[:k])
        ang = z[:k].copy()
        if pri[:k].any():
            lin[pri[:k]] = z[:k][pri[:k]]
            ang[pri[:k]] = 0.0
        Rl = R[l]
        v = np.einsum("jib,kjb->kib", Rl, lin)  # link-l coordinates (k, 3, B)
        w = np.einsum("jib,kjb->kib", Rl, ang)
        rows = np.flatnonzero(ii <= l)  # pairs (i, j), j <= i <= l: the first rows
        vi, vj, wi, wj = v[ii[rows]], v[jj[rows]], w[ii[rows]], w[jj[rows]]
        blk = Yt[: rows.size, 10 * l : 10 * l + 10]
        blk[:, 0] = np.einsum("pkb,pkb->pb", vi, vj)
        blk[:, 1:4] = _cross_rows(vi, wj) + _cross_rows(vj, wi)
        ax, ay, az = wi[:, 0], wi[:, 1], wi[:, 2]
        bx, by, bz = wj[:, 0], wj[:, 1], wj[:, 2]
        blk[:, 4] = ax * bx
        blk[:, 5] = ax * by + ay * bx
        blk[:, 6] = ax * bz + az * bx
        blk[:, 7] = ay * by
        blk[:, 8] = ay * bz + az * by
        blk[:, 9] = az * bz
        gl = np.einsum("jib,j->ib", Rl, robot.gravity)  # gravity in link-l coordinates (3, B)
        gb = Yt[nm : nm + k, 10 * l : 10 * l + 4]
        gb[:, 0] = -np.einsum("kib,ib->kb", v, gl)
        gb[:, 1:4] = _cross_rows(w, gl[None])
    return Yt


def _cross_rows(a: NDArray[np.float64], b: NDArray[np.float64]) -> NDArray[np.float64]:
    """Cross product along axis 1 of (k, 3, B) arrays (broadcast over k)."""
    out = np.empty(np.broadcast_shapes(a.shape, b.shape))
    out[:, 0] = a[:, 1] * b[:, 2] - a[:, 2] * b[:, 1]
    out[:, 1] = a[:, 2] * b[:, 0] - a[:, 0] * b[:, 2]
    out[:, 2] = a[:, 0] * b[:, 1] - a[:, 1] * b[:, 0]
    return out


def static_regressor(robot: Robot, q: ArrayLike) -> NDArray[np.float64]:
    """Regressor of ``[tril M(q); g(q)]`` in the standard parameters.

    Parameters
    ----------
    q : array_like, shape (..., n)
        Joint positions [rad].

    Returns
    -------
    Y_s : ndarray, shape (..., n (n + 1) / 2 + n, 10 n)
        ``Y_s @ phi == static_vector(mass_matrix(q), gravity_torques(q))``; rows as in
        :func:`static_labels`, columns as ``robot.param_labels``.
    """
    q = _checks.as_batch("q", q, (robot.n,))
    Y = _static_regressor(robot, q.reshape(-1, robot.n))
    return Y.reshape(q.shape[:-1] + Y.shape[1:])
