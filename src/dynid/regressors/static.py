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

Two implementations compute the same rows (to rounding): the compiled kernel of
:mod:`dynid._kernels.regressors` (numba; one pass over the samples, writing only the
columns asked for), used when :func:`dynid._kernels.dispatch.compiled` finds the compiled
kernels, and the numpy path (samples vectorised, a loop over links), used otherwise or
with ``DYNID_NO_NUMBA=1`` (:func:`static_regressor_numpy` always takes it).
"""

from __future__ import annotations

from types import ModuleType

import numpy as np
from numpy.typing import ArrayLike, NDArray

from .. import _checks, _kernels
from ..exceptions import ShapeError
from ..kinematics.forward import link_poses_prepared
from ..model.robot import Robot, checked_robot

__all__ = [
    "static_first_columns",
    "static_regressor",
    "static_regressor_columns",
    "static_regressor_numpy",
    "static_labels",
    "static_vector",
    "static_rows",
]


_STATIC = _kernels.KERNELS["static_regressor"]


def _kernel() -> ModuleType | None:
    """The compiled regressor kernels, or None (numpy path): :func:`dynid._kernels.load`."""
    return _kernels.load(_STATIC.module)


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


def static_first_columns(n: int, columns: NDArray[np.intp]) -> NDArray[np.intp]:
    """For each row of ``s``, the first of ``columns`` where its regressor can be non-zero.

    Row ``(i, j)`` of ``tril M`` and row ``g_i`` depend only on the parameters of links
    ``i .. n - 1`` (0-based: ``v_k = w_k = 0`` for a joint ``k`` after link ``l``), and the
    regressor holds exact zeros elsewhere. With ``columns`` (standard-parameter indices,
    ``robot.param_labels`` order) increasing, the row's entries in the columns before the
    returned index are therefore exactly zero. Zeros (no structure) when ``columns`` does
    not increase. Returns shape (n (n + 1) / 2 + n,).
    """
    ii, _ = np.tril_indices(n)
    first_link = np.concatenate([ii, np.arange(n)])
    cols = np.asarray(columns, dtype=np.intp)
    if np.any(np.diff(cols) <= 0):
        return np.zeros(first_link.size, dtype=np.intp)
    return np.searchsorted(cols // 10, first_link, side="left").astype(np.intp)


def _static_regressor(robot: Robot, q2: NDArray[np.float64]) -> NDArray[np.float64]:
    """(B, n (n + 1) / 2 + n, 10 n) static regressor for validated (B, n) positions.

    A transposed view of :func:`static_regressor_columns` (not C-contiguous).
    """
    return _static_columns(robot, q2, None, False).transpose(2, 1, 0)


def static_regressor_columns(
    robot: Robot,
    q: ArrayLike,
    columns: NDArray[np.intp] | None = None,
    *,
    numpy_path: bool = False,
) -> NDArray[np.float64]:
    """Columns of the static regressor, samples last: (c, n (n + 1) / 2 + n, B), C order.

    ``Y[c, k, b]`` is standard parameter ``columns[c]`` (all ``10 n`` in order when None),
    row ``k`` of ``s``, sample ``b`` of the (B, n) positions ``q`` [rad]; a column of the
    stacked regressor (rows, then samples) is contiguous. The compiled kernel writes only
    these columns; the numpy path (``numpy_path=True`` or no kernel) gathers them.

    Raises
    ------
    ShapeError
        ``q`` not (B, n) for the robot's ``n`` joints.
    NonFiniteError
        NaN or inf in ``q``.
    """
    q2 = _checks.as_batch("q", q, (robot.n,))
    if q2.ndim != 2:
        raise ShapeError(f"q must have shape (B, {robot.n}); got {q2.shape}")
    return _static_columns(robot, q2, columns, numpy_path)


def _static_columns(
    robot: Robot,
    q2: NDArray[np.float64],
    columns: NDArray[np.intp] | None,
    numpy_path: bool,
) -> NDArray[np.float64]:
    """:func:`static_regressor_columns` for validated (B, n) positions."""
    B, n = q2.shape
    p = 10 * n
    idx = np.arange(p) if columns is None else np.asarray(columns, dtype=np.intp)
    K = None if numpy_path else _kernel()
    if K is not None and np.unique(idx).size == idx.size:  # (a repeated column: gather)
        cols = np.full(p, -1, dtype=np.int64)  # output column of each standard parameter
        cols[idx] = np.arange(idx.size)
        Y = np.zeros((idx.size, static_rows(n), B))  # the kernel writes the non-zeros
        f = _kernels.compiled(_STATIC, 2)
        if f is not None and f(_kernels.constants(robot), _kernels.flat(q2), cols, Y):
            return Y
    Yt = _static_regressor_numpy(robot, q2).transpose(1, 0, 2)  # (10 n, s, B) view
    return np.ascontiguousarray(Yt if columns is None else Yt[idx])


def _static_regressor_numpy(robot: Robot, q2: NDArray[np.float64]) -> NDArray[np.float64]:
    """Numpy path: the static regressor with the samples on the last axis (s, 10 n, B)."""
    B, n = q2.shape
    T = link_poses_prepared(robot, q2)
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
    checked_robot(robot)
    q = _checks.as_batch("q", q, (robot.n,))
    Y = _static_regressor(robot, q.reshape(-1, robot.n))
    return Y.reshape(q.shape[:-1] + Y.shape[1:])


def static_regressor_numpy(robot: Robot, q: ArrayLike) -> NDArray[np.float64]:
    """:func:`static_regressor` by the numpy path, never the compiled kernel."""
    q = _checks.as_batch("q", q, (robot.n,))
    Y = _static_regressor_numpy(robot, q.reshape(-1, robot.n)).transpose(2, 0, 1)
    return Y.reshape(q.shape[:-1] + Y.shape[1:])
