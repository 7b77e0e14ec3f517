"""Static regressor of ``s(q) = [tril M(q); g(q)]`` (Gaz et al. 2019, eqs. 17-20), batched.

.. math:: s(q) = \\begin{bmatrix} \\mathrm{tril}\\, M(q) \\\\ g(q) \\end{bmatrix} = Y_s(q) \\, \\phi

The lower triangle is ordered by ``np.tril_indices(n)`` (row-major: ``M11, M21, M22, M31,
...``); then the ``n`` gravity torques. Rows: ``n (n + 1) / 2 + n`` (35 for the Panda).
Column ``k`` of ``M`` is the inverse dynamics at rest with unit acceleration ``e_k`` and no
gravity, so each row of ``Y_s`` is a row of the torque regressor.
"""

from __future__ import annotations

import numpy as np
from numpy.typing import ArrayLike, NDArray

from .. import _checks
from ..model.robot import Robot
from .torque import _torque_regressor

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
    B, n = q2.shape
    # n + 1 evaluations per sample: unit accelerations without gravity, then rest with gravity
    qs = np.repeat(q2, n + 1, axis=0)
    acc = np.tile(np.vstack([np.eye(n), np.zeros((1, n))]), (B, 1))
    grav = np.tile(np.vstack([np.zeros((n, 3)), robot.gravity[None]]), (B, 1))
    Y = _torque_regressor(robot, qs, np.zeros_like(qs), acc, grav).reshape(B, n + 1, n, -1)
    i, j = np.tril_indices(n)
    # M[i, j] = Y_i(q, 0, e_j) phi
    return np.concatenate([Y[:, j, i, :], Y[:, n, :, :]], axis=1)


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
