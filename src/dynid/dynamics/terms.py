"""Terms of the joint-space equation of motion, batched.

.. math:: M(q) \\ddot q + c(q, \\dot q) + g(q) = \\tau, \\qquad c = S(q, \\dot q) \\dot q

``M`` [kg m^2] is built column by column from RNEA with unit accelerations and gravity off;
``g`` [N m] is RNEA at rest; ``c`` [N m] is RNEA with zero acceleration and gravity off.
``S`` is the Coriolis matrix from the Christoffel symbols of the first kind, for which
:math:`\\dot M - 2 S` is skew-symmetric; its symbols are read exactly off the quadratic
form ``c(q, v)`` by polarization.

With numba installed (see :func:`dynid.dynamics.rnea.kernels`), ``M`` comes from the
composite-rigid-body algorithm and ``g`` and the RNEA calls from the compiled kernels of
:mod:`dynid._kernels.dynamics` (a single sample of :func:`forward_dynamics` is one compiled
call: RNEA for ``c + g``, the composite-rigid-body ``M`` and its Cholesky solve);
:func:`mass_matrix_numpy` and :func:`gravity_torques_numpy` are the numpy reference path
(``DYNID_NO_NUMBA=1`` selects it everywhere). Both agree to rounding.
"""

from __future__ import annotations

import numpy as np
from numpy.typing import ArrayLike, NDArray

from .. import _checks, _kernels
from ..exceptions import ModelError
from ..model.robot import Robot, checked_robot
from .rnea import ZERO_GRAVITY, _rnea, _rnea_numpy, prepare_states

__all__ = [
    "mass_matrix",
    "mass_matrix_numpy",
    "gravity_torques",
    "gravity_torques_numpy",
    "coriolis",
    "coriolis_matrix",
    "forward_dynamics",
    "forward_dynamics_numpy",
]

_ZERO_G = ZERO_GRAVITY
_KERNELS = _kernels.KERNELS
_RNEA, _MASS = _KERNELS["rnea"], _KERNELS["mass_matrix"]
_GRAVITY, _FORWARD = _KERNELS["gravity_torques"], _KERNELS["forward_dynamics"]


def _mass_matrix(robot: Robot, q2: NDArray[np.float64]) -> NDArray[np.float64]:
    """(B, n, n) mass matrices for validated (B, n) positions (kernel when available)."""
    B, n = q2.shape
    if _kernels.compiled(_MASS, 1 + (B > 1)) is not None:
        M = np.empty((B, n, n))
        if _MASS.batch(_kernels.constants(robot), _kernels.flat(q2), M.reshape(-1)):
            return M
    return _mass_matrix_numpy(robot, q2)


def _mass_matrix_numpy(robot: Robot, q2: NDArray[np.float64]) -> NDArray[np.float64]:
    """(B, n, n) mass matrices for validated (B, n) positions, numpy path: RNEA columns."""
    B, n = q2.shape
    qs = np.repeat(q2, n, axis=0)  # sample-major: row b*n + k
    E = np.tile(np.eye(n), (B, 1))
    cols = _rnea_numpy(robot, robot.phi, qs, np.zeros_like(qs), E, _ZERO_G)  # (B*n, n): column k
    M = np.swapaxes(cols.reshape(B, n, n), 1, 2)
    return 0.5 * (M + np.swapaxes(M, 1, 2))


@_kernels.single_sample(_MASS, "configuration", "matrix")
def mass_matrix(robot: Robot, q: ArrayLike) -> NDArray[np.float64]:
    """Joint-space inertia matrix M(q).

    Parameters
    ----------
    q : array_like, shape (..., n)
        Joint positions [rad].

    Returns
    -------
    M : ndarray, shape (..., n, n)
        Symmetric positive definite [kg m^2] (kg for prismatic rows/columns).

    Raises
    ------
    ShapeError, NonFiniteError

    Notes
    -----
    Composite-rigid-body algorithm in the compiled kernel when available; otherwise
    :func:`mass_matrix_numpy`.
    """
    checked_robot(robot)
    n = len(robot.joint_names)
    out = _kernels.run(_MASS, robot, (q,), (n, n))
    if out is not None:
        return out
    q = _checks.as_batch("q", q, (robot.n,))
    return _mass_matrix(robot, q.reshape(-1, robot.n)).reshape(q.shape + (robot.n,))


def mass_matrix_numpy(robot: Robot, q: ArrayLike) -> NDArray[np.float64]:
    """:func:`mass_matrix` by the numpy reference path (columns of RNEA), never the kernel."""
    q = _checks.as_batch("q", q, (robot.n,))
    return _mass_matrix_numpy(robot, q.reshape(-1, robot.n)).reshape(q.shape + (robot.n,))


@_kernels.single_sample(_GRAVITY, "configuration", "vector")
def gravity_torques(robot: Robot, q: ArrayLike) -> NDArray[np.float64]:
    """Gravity torques g(q) = rnea(q, 0, 0) [N m], shape (..., n), for ``robot.gravity``.

    Raises
    ------
    ShapeError, NonFiniteError
    """
    checked_robot(robot)
    out = _kernels.run(_GRAVITY, robot, (q,), (len(robot.joint_names),))
    if out is not None:
        return out
    q = _checks.as_batch("q", q, (robot.n,))
    q2 = q.reshape(-1, robot.n)
    z = np.zeros((1, robot.n))
    return _rnea(robot, robot.phi, q2, z, z, robot.gravity).reshape(q.shape)


def gravity_torques_numpy(robot: Robot, q: ArrayLike) -> NDArray[np.float64]:
    """:func:`gravity_torques` by the numpy reference path, never the kernel."""
    q = _checks.as_batch("q", q, (robot.n,))
    q2 = q.reshape(-1, robot.n)
    z = np.zeros_like(q2)
    return _rnea_numpy(robot, robot.phi, q2, z, z, robot.gravity).reshape(q.shape)


@_kernels.single_sample(_RNEA, "velocities", "vector")
def coriolis(robot: Robot, q: ArrayLike, dq: ArrayLike) -> NDArray[np.float64]:
    """Coriolis and centrifugal torques c(q, dq) = rnea(q, dq, 0) without gravity [N m].

    Parameters
    ----------
    q, dq : array_like, shape (..., n)
        Positions [rad] and velocities [rad/s]; batch shapes broadcast.

    Returns
    -------
    c : ndarray, shape (..., n)
    """
    checked_robot(robot)
    shape, (q2, dq2, _) = prepare_states(robot, q, dq, np.zeros(robot.n))
    if shape == (robot.n,) and _kernels.loaded(_RNEA) is not None:
        _kernels.packed(robot)  # the next single sample takes the thin path
    return _rnea(robot, robot.phi, q2, dq2, np.zeros((1, robot.n)), _ZERO_G).reshape(shape)


def christoffel(robot: Robot, q: ArrayLike) -> NDArray[np.float64]:
    """Christoffel symbols of the first kind ``G[..., i, j, k]`` [kg m^2], symmetric in j, k.

    .. math:: \\Gamma_{ijk} = \\tfrac12 (\\partial_k M_{ij} + \\partial_j M_{ik}
              - \\partial_i M_{jk}),
              \\qquad c_i = \\sum_{jk} \\Gamma_{ijk} \\dot q_j \\dot q_k
    """
    q = _checks.as_batch("q", q, (robot.n,))
    n = robot.n
    q2 = q.reshape(-1, n)
    B = q2.shape[0]
    pairs = [(j, k) for j in range(n) for k in range(j, n)]
    V = np.zeros((len(pairs), n))
    for r, (j, k) in enumerate(pairs):
        V[r, j] = V[r, k] = 1.0
    qs = np.repeat(q2, len(pairs), axis=0)
    vs = np.tile(V, (B, 1))
    cv = _rnea(robot, robot.phi, qs, vs, np.zeros_like(qs), _ZERO_G).reshape(B, len(pairs), n)
    G = np.empty((B, n, n, n))
    diag = {j: r for r, (j, k) in enumerate(pairs) if j == k}
    for r, (j, k) in enumerate(pairs):
        if j == k:
            G[:, :, j, j] = cv[:, r]
        else:  # c(e_j + e_k) = G_jj + G_kk + 2 G_jk
            G[:, :, j, k] = G[:, :, k, j] = 0.5 * (cv[:, r] - cv[:, diag[j]] - cv[:, diag[k]])
    return G.reshape(q.shape[:-1] + (n, n, n))


def coriolis_matrix(robot: Robot, q: ArrayLike, dq: ArrayLike) -> NDArray[np.float64]:
    """Coriolis matrix S(q, dq) from the Christoffel symbols, ``S dq = c``.

    .. math:: S_{ij} = \\sum_k \\Gamma_{ijk}(q) \\dot q_k

    With this choice :math:`\\dot M - 2S` is skew-symmetric.

    Returns
    -------
    S : ndarray, shape (..., n, n)
    """
    checked_robot(robot)
    q = _checks.as_batch("q", q, (robot.n,))
    dq = _checks.as_batch("dq", dq, (robot.n,))
    G = christoffel(robot, q)
    return np.einsum("...ijk,...k->...ij", G, dq)


@_kernels.single_sample(_FORWARD, "torques", "vector")
def forward_dynamics(
    robot: Robot, q: ArrayLike, dq: ArrayLike, tau: ArrayLike
) -> NDArray[np.float64]:
    """Joint accelerations from torques, ``ddq = M^{-1} (tau - c - g)`` (solved, not inverted).

    Parameters
    ----------
    q, dq, tau : array_like, shape (..., n)
        Positions [rad], velocities [rad/s], torques [N m] (friction not included).

    Returns
    -------
    ddq : ndarray, shape (..., n) [rad/s^2]

    Raises
    ------
    ShapeError, NonFiniteError
        An input does not end in ``n``, the shapes do not broadcast, or NaN/inf.
    ModelError
        ``M`` is singular (to rounding: a Cholesky pivot^2 below ``1e-12`` of its diagonal,
        a joint that moves no inertia of its own), so the accelerations are undefined.
    """
    checked_robot(robot)
    shape, (q2, dq2, tau2) = prepare_states(robot, q, dq, tau, ("q", "dq", "tau"))
    if shape == (robot.n,) and _kernels.loaded(_FORWARD) is not None:
        _kernels.packed(robot)  # the next single sample takes the thin path
    bias = _rnea(robot, robot.phi, q2, dq2, np.zeros_like(q2), robot.gravity)
    M = _mass_matrix(robot, q2)
    return _solve_mass_matrix(robot, M, tau2 - bias).reshape(shape)


def forward_dynamics_numpy(
    robot: Robot, q: ArrayLike, dq: ArrayLike, tau: ArrayLike
) -> NDArray[np.float64]:
    """:func:`forward_dynamics` by the numpy reference path, never the compiled kernels.

    Same parameters, result, shapes and errors as :func:`forward_dynamics`.
    """
    shape, (q2, dq2, tau2) = prepare_states(robot, q, dq, tau, ("q", "dq", "tau"))
    bias = _rnea_numpy(robot, robot.phi, q2, dq2, np.zeros_like(q2), robot.gravity)
    M = _mass_matrix_numpy(robot, q2)
    return _solve_mass_matrix(robot, M, tau2 - bias).reshape(shape)


def _solve_mass_matrix(
    robot: Robot, M: NDArray[np.float64], rhs: NDArray[np.float64]
) -> NDArray[np.float64]:
    """``M^-1 rhs`` for (B, n, n) and (B, n); :class:`ModelError` when an ``M`` is singular.

    Positive definite ``M`` (a physical model) are checked by their Cholesky pivots;
    others (parameters that are not physical) are solved by LU, which reports exact
    singularity only.
    """
    B = M.shape[0]
    try:
        L = np.linalg.cholesky(M)
    except np.linalg.LinAlgError:
        L = None
    bad: tuple[int, int] | None = None
    if L is not None:
        share = np.diagonal(L, axis1=-2, axis2=-1) ** 2 / np.diagonal(M, axis1=-2, axis2=-1)
        low = np.argwhere(share < _kernels.SINGULAR_PIVOT)
        if low.size:
            bad = (int(low[0, 0]), int(low[0, 1]))
    if bad is None:
        try:
            return np.asarray(np.linalg.solve(M, rhs[..., None])[..., 0], dtype=np.float64)
        except np.linalg.LinAlgError:
            bad = (-1, -1)
    where = "" if B == 1 or bad[0] < 0 else f" at sample {bad[0]}"
    who = "" if bad[1] < 0 else f": joint {robot.joint_names[bad[1]]} moves no inertia of its own"
    raise ModelError(
        f"the mass matrix is singular{where}{who}; the forward dynamics is undefined "
        "(check the link inertials: a massless link, or joints that move the same inertia)"
    )
