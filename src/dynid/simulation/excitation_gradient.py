"""The gradient of the excitation design's objective, by the chain rule through its samples.

The objective of :func:`~dynid.simulation.excitation.optimise_excitation` is a function of
the trajectory's samples on three grids (the regressor's, the limits' and the
collisions'), which are linear in the coefficients and the rest position
(:class:`~dynid.simulation.exciting_trajectory.ExcitingTrajectory`'s basis), which are
piecewise smooth functions of the optimiser's variables (each joint's coefficients
projected onto the continuous accelerations, scaled to fit its limits, its rest position
clipped to where the motion fits). :func:`objective_gradient` differentiates each link of
that chain:

* the coefficients and the rest position of the variables (each joint's scaling to its
  limits and the clipping, piecewise smooth): by forward differences of the steps scipy's
  finite differences take, one joint's row at a time (:func:`coefficient_steps`; the
  kinks of the scaling weigh in as they did in those differences);
* the criterion ``log cond = (log lambda_max - log lambda_min) / 2`` of the Gram matrix
  ``W^T W``: ``d lambda = 2 (W v)^T (dW v)`` with ``v`` the eigenvector (Magnus and
  Neudecker, *Matrix Differential Calculus*, 2019, ch. 8); ``dW`` of each joint's
  position, velocity and acceleration at every sample at once (a sample's rows depend on
  that sample's states only) by a forward difference of :data:`STATE_STEP`, the friction
  columns' in closed form (the viscous column's is 1, the Coulomb sign's 0);
* the penalties: of the sample where each violated torque is largest and each violated
  clearance smallest (a maximum's derivative is its largest element's), by forward
  differences of :data:`STATE_STEP` in that sample's states.

A gradient costs about a sixteenth of the ``len(x) + 1`` evaluations of the finite
differences it replaces (the Panda's 20 s design: 22 regressors of the same samples in
place of 78 evaluations; ``benchmarks/bench_excitation.py``). ``logdet`` keeps the finite
differences
(:meth:`~dynid.simulation.excitation._Problem.value_and_gradient`).
"""

from __future__ import annotations

from typing import Any

import numpy as np
from numpy.typing import NDArray

__all__ = ["STATE_STEP", "objective_gradient"]

#: Forward-difference step in a sample's states [rad, rad/s, rad/s^2].
STATE_STEP = 1e-7


def objective_gradient(prob: Any, x: NDArray[np.float64]) -> tuple[float, NDArray[np.float64]]:
    """The objective at ``x`` (n 2L + n) and its gradient (module docstring), for the
    ``cond`` criterion.

    ``prob`` is the design's problem (``_Problem``): its grids' bases, limits, the
    coefficients of the variables, the regressor, the torques and the clearances.
    """
    c, q0 = prob.coefficients(x)
    value, g_c, g_q0 = 0.0, np.zeros_like(c), np.zeros_like(q0)
    for part in (_criterion_part, _torque_part, _clearance_part):
        v, gc, gq0 = part(prob, c, q0)
        value, g_c, g_q0 = value + v, g_c + gc, g_q0 + gq0
    d_c, d_q0 = coefficient_steps(prob, x, c, q0)
    return value, np.einsum("ja,ija->i", g_c, d_c) + np.einsum("j,ij->i", g_q0, d_q0)


def coefficient_steps(
    prob: Any, x: NDArray[np.float64], c: NDArray[np.float64], q0: NDArray[np.float64]
) -> tuple[NDArray[np.float64], NDArray[np.float64]]:
    """The forward differences of the coefficients ``c`` (n, 2L) and the rest position
    ``q0`` (n,) [rad] of the variables ``x`` in each variable: (len(x), n, 2L) and
    (len(x), n), each of the steps scipy's finite differences take (``h``).

    A variable moves one joint's motion only: each step is computed for that joint alone
    (its row of :meth:`_Problem.coefficients_of`), the others' rows are zero.
    """
    n, L2 = c.shape
    h = prob.steps(x)
    X = np.repeat(x[None], len(x), axis=0)
    X[np.diag_indices(len(x))] += h
    joint = np.concatenate([np.repeat(np.arange(n), L2), np.arange(n)])
    c_i, q0_i = prob.joint_coefficients(X, joint)  # (len(x), 2L), (len(x),)
    dx = ((x + h) - x)[:, None]
    d_c = np.zeros((len(x), n, L2))
    d_q0 = np.zeros((len(x), n))
    rows = np.arange(len(x))
    d_c[rows, joint] = (c_i - c[joint]) / dx
    d_q0[rows, joint] = (q0_i - q0[joint]) / dx[:, 0]
    return d_c, d_q0


def _to_coefficients(
    B: tuple[NDArray[np.float64], ...], g: tuple[NDArray[np.float64], ...]
) -> tuple[NDArray[np.float64], NDArray[np.float64]]:
    """A gradient in the samples ``g = (g_q, g_dq, g_ddq)`` (N, n each) on the grid of
    basis ``B`` carried to the coefficients (n, 2L) and the rest position (n,)."""
    g_c = sum(gi.T @ Bi for gi, Bi in zip(g, B, strict=False))
    return np.asarray(g_c), g[0].sum(axis=0)


def _criterion_part(
    prob: Any, c: NDArray[np.float64], q0: NDArray[np.float64]
) -> tuple[float, NDArray[np.float64], NDArray[np.float64]]:
    """``log cond`` of the regressor and its gradient in ``c`` and ``q0``."""
    n = prob.n
    z = prob.samples(prob.B_reg, c, q0)  # (N, n) each
    W = prob.regressor(c, q0)  # (N n, m)
    lam, V = np.linalg.eigh(W.T @ W)
    lam_min = max(lam[0], 1e-300)
    value = float(0.5 * np.log(lam[-1] / lam_min))
    # the states moved one (kind, joint) at a time, at every sample: (3 n, N, n) each
    moved = [np.repeat(zi[None], 3 * n, axis=0) for zi in z]
    for kind in range(3):
        for j in range(n):
            moved[kind][kind * n + j, :, j] += STATE_STEP
    r = W.shape[-1] - 3 * n
    V2 = V[:, [-1, 0]]  # the eigenvectors of lambda_max and lambda_min
    # dW v of each moved state, the base columns by the forward difference: (3 n, N n, 2)
    Wv = W[:, :r] @ V2[:r]
    dWv = (prob.base_regressor_of(*moved) @ V2[:r] - Wv) / STATE_STEP
    # the friction columns' in closed form: the viscous column's derivative in dq_j is 1
    # (row of joint j), the Coulomb sign's and the offset's 0
    for j in range(n):
        dWv[n + j, j::n] += V2[r + 3 * j]
    u = W @ V2  # (N n, 2)
    # d crit = u_max . dW v_max / lambda_max - u_min . dW v_min / lambda_min, per sample
    # (a rank-deficient regressor, lambda_min held at its floor: that term constant)
    floor = 0.0 if lam[0] <= 1e-300 else 1.0 / lam_min
    per_row = dWv[..., 0] * (u[:, 0] / lam[-1]) - dWv[..., 1] * (u[:, 1] * floor)
    g = per_row.reshape(3, n, -1, n).sum(axis=-1)  # (kind, joint, sample)
    return value, *_to_coefficients(prob.B_reg, tuple(np.swapaxes(g, 1, 2)))


def _state_derivative(
    f: Any, z: tuple[NDArray[np.float64], ...], kinds: int
) -> NDArray[np.float64]:
    """Forward differences of ``f`` (states (S, n) ... -> (S, p)) at the samples ``z``
    (S, n each) in the first ``kinds`` of their states: (S, kinds, n, p)."""
    S, n = z[0].shape
    moved = [np.repeat(zi[:, None, None], kinds, axis=1).repeat(n, axis=2) for zi in z]
    for kind in range(kinds):
        moved[kind][:, kind, np.arange(n), np.arange(n)] += STATE_STEP
    base = f(*z)
    out = f(*(m.reshape(-1, n) for m in moved)).reshape(S, kinds, n, -1)
    return (out - base[:, None, None]) / STATE_STEP


def _torque_part(
    prob: Any, c: NDArray[np.float64], q0: NDArray[np.float64]
) -> tuple[float, NDArray[np.float64], NDArray[np.float64]]:
    """The torque penalty and its gradient: of the sample of each joint's largest torque."""
    n = prob.n
    zero = (0.0, np.zeros((n, 2 * prob.L)), np.zeros(n))
    if not np.any(np.isfinite(prob.tmax)):
        return zero
    z = prob.samples(prob.B_lim, c, q0)
    tau = prob.torques(*z)
    at = np.abs(tau).argmax(axis=0)
    peak = tau[at, np.arange(n)]
    with np.errstate(invalid="ignore"):
        v = np.where(np.isfinite(prob.tmax), (np.abs(peak) - prob.tmax) / prob.tmax, 0.0)
    over = np.flatnonzero(v > 0)
    if not over.size:
        return zero
    d = _state_derivative(prob.torques, tuple(zi[at[over]] for zi in z), 3)  # (o, 3, n, n)
    g = [np.zeros_like(zi) for zi in z]
    for m, j in enumerate(over):
        w = 100.0 * 2.0 * v[j] / prob.tmax[j] * np.sign(peak[j])
        for kind in range(3):
            g[kind][at[j]] += w * d[m, kind, :, j]
    return float(100.0 * np.sum(v[over] ** 2)), *_to_coefficients(prob.B_lim, tuple(g))


def _clearance_part(
    prob: Any, c: NDArray[np.float64], q0: NDArray[np.float64]
) -> tuple[float, NDArray[np.float64], NDArray[np.float64]]:
    """The clearance penalties and their gradient: of the sample of each violated pair's
    (and obstacle's) smallest distance."""
    qc = q0 + prob.B_col @ c.T
    d = prob.distances(qc)  # (N, p): the pairs, then the obstacles
    need = prob.required_distances()  # (p,)
    at = d.argmin(axis=0)
    short = need - d[at, np.arange(d.shape[1])]
    over = np.flatnonzero(short > 0)
    g = np.zeros_like(qc)
    if over.size:
        dd = _state_derivative(prob.distances, (qc[at[over]],), 1)[:, 0]  # (o, n, p)
        for m, p in enumerate(over):
            g[at[p]] -= 100.0 * 2.0 * short[p] / 0.05**2 * dd[m, :, p]
    value = float(100.0 * np.sum(short[over] ** 2) / 0.05**2)
    g_c, g_q0 = _to_coefficients((prob.B_col,), (g,))
    return value, g_c, g_q0
