"""How much of each retrieved parameter the prior sets: the share of the prior in the
consistent fit's value, from the fit linearised at its solution.

The convex fit minimises ``w D(phi || phi_0) + 1/2 ||A (x - x_hat)||^2`` (:mod:`.convex`),
``x = [P [phi; I_a]; f]``. About its solution both terms are quadratic: the data's
information ``G^T A^T A G`` (``G = diag(P, 1)``) and the prior's ``w M``, ``M`` the
divergence's Hessian (log-det: ``M_ab = tr(J^-1 E_a J^-1 E_b)``, ``E_a`` the
pseudo-inertia of the unit parameter ``a``; its mixed derivative in ``phi_0`` is
``-w M_0``, ``M_0`` at the prior). With ``H`` the sum, a change ``d phi_0`` of the prior
moves the value by ``H^-1 w M_0 d phi_0``; the noise of the data moves it by
``H^-1 G^T A^T A G H^-1``'s share. The **prior share** of parameter ``j`` is

.. math:: s_j = \\frac{[H^{-1} w M_0 H^{-1}]_{jj}}
                     {[H^{-1} w M_0 H^{-1}]_{jj} + [H^{-1} G^T A^T A G H^{-1}]_{jj}},

the part of its spread that the prior's spread (its covariance ``(w M_0)^-1``) makes: 0 when
the data fix the value whatever the prior, 1 when the prior alone does. A parameter the
data give only in combinations (``e_j`` outside the row space of ``P``: the value is the
prior plus a share of the combination) tends to 1 as the data grow; a parameter the data
give alone tends to 0, unless it is poorly excited. Active bounds are not linearised (the
bound decides such a value; :attr:`~.convex.result.ConsistentResult.on_bound` names it).
"""

from __future__ import annotations

import numpy as np
from numpy.typing import NDArray

from .lmi import pseudo_inertia

__all__ = ["PRIOR_SHARE", "divergence_hessian", "prior_sensitivity", "prior_share"]

#: A parameter whose value the prior sets more than the data (share above this) is marked.
PRIOR_SHARE = 0.5

#: Pseudo-inertia of each unit standard parameter (10, 4, 4): ``J`` is linear in ``phi``.
_E = pseudo_inertia(np.eye(10))


def divergence_hessian(phi: NDArray[np.float64]) -> NDArray[np.float64]:
    """Hessian of ``-log det J(phi)`` per link (n, 10, 10) [1 / parameter units^2]:
    ``tr(J^-1 E_a J^-1 E_b)``, with ``phi`` (n, 10) standard parameters about the link
    origin (``m, m c, I_o``)."""
    Ji = np.linalg.inv(pseudo_inertia(np.asarray(phi, dtype=np.float64).reshape(-1, 10)))
    F = np.einsum("nij,ajk->naik", Ji, _E)  # J^-1 E_a
    return np.einsum("naij,nbji->nab", F, F)


def _block(blocks: NDArray[np.float64], size: int) -> NDArray[np.float64]:
    """``blocks`` (n, 10, 10) on the diagonal of a (size, size) zero matrix."""
    out = np.zeros((size, size))
    for i, b in enumerate(blocks):
        out[10 * i : 10 * i + 10, 10 * i : 10 * i + 10] = b
    return out


def _information(
    P: NDArray[np.float64],
    A: NDArray[np.float64],
    phi: NDArray[np.float64],
    prior_phi: NDArray[np.float64],
    weight: float,
    objective: str,
) -> tuple[NDArray[np.float64], NDArray[np.float64], NDArray[np.float64]]:
    """``H^-1``, the data's information ``G^T A^T A G`` and the prior's ``w M_0`` over the
    unknowns ``[phi; I_a; f]`` (module docstring; arguments as :func:`prior_share`), all
    three over ``max(w, 1)``: the shares and ``H^-1 w M_0`` are the same, and a weight near
    the largest float (a fit that returns the prior) does not overflow."""
    phi = np.asarray(phi, dtype=np.float64).reshape(-1, 10)
    p, kf = P.shape[1], A.shape[1] - P.shape[0]
    G = np.zeros((P.shape[0] + kf, p + kf))
    G[: P.shape[0], :p] = P
    G[P.shape[0] :, p:] = np.eye(kf)
    scale = max(float(weight), 1.0)
    data = G.T @ (A.T @ A) @ G / scale
    weight = float(weight) / scale
    m0 = divergence_hessian(prior_phi)
    factor = 2.0 if objective != "logdet" else 1.0
    at = m0 if objective != "logdet" else divergence_hessian(phi)
    H = data + weight * factor * _block(at, p + kf)
    d = 1.0 / np.sqrt(np.maximum(np.abs(np.diag(H)), 1e-300))  # equilibrated: data and
    Hs = 0.5 * (H + H.T) * d[:, None] * d[None, :]  # prior information differ by 1e10
    Hi = np.linalg.pinv(Hs, rcond=1e-13, hermitian=True) * d[:, None] * d[None, :]
    return Hi, data, weight * factor * _block(m0, p + kf)


def prior_sensitivity(
    P: NDArray[np.float64],
    A: NDArray[np.float64],
    phi: NDArray[np.float64],
    prior_phi: NDArray[np.float64],
    weight: float,
    *,
    objective: str = "logdet",
) -> NDArray[np.float64]:
    """``d value / d prior`` (10 n + k, 10 n): how the fit's standard parameters and rotor
    inertias move per unit change of the prior's standard parameters, ``H^-1 w M_0``
    (module docstring; arguments as :func:`prior_share`). Linearised at the solution, with
    no bound active."""
    Hi, _, Q = _information(P, A, phi, prior_phi, weight, objective)
    n10 = np.asarray(prior_phi).size
    return (Hi @ Q)[: P.shape[1], :n10]


def prior_share(
    P: NDArray[np.float64],
    A: NDArray[np.float64],
    phi: NDArray[np.float64],
    prior_phi: NDArray[np.float64],
    weight: float,
    *,
    objective: str = "logdet",
) -> NDArray[np.float64]:
    """The prior share of each standard parameter and rotor inertia (module docstring).

    Parameters
    ----------
    P : ndarray, shape (r, 10 n + k)
        Standard parameters (links, then ``k`` rotor inertias) to the kept coefficients.
    A : ndarray, shape (s, r + f)
        The data term's whitening over the coefficients and ``f`` friction unknowns
        (``A^T A`` the inverse covariance).
    phi, prior_phi : ndarray, shape (n, 10)
        The solution's and the prior's standard parameters (``m, m c, I_o``).
    weight : float
        The prior's weight ``w`` (> 0).
    objective : {"logdet", "euclidean"}
        The divergence (the Euclidean one on the whitened ``J``: ``M = 2 M_0`` at any
        ``phi``).

    Returns
    -------
    ndarray, shape (10 n + k,)
        Shares in ``[0, 1]``, labels in the order of ``P``'s columns.
    """
    Hi, data, Q = _information(P, A, phi, prior_phi, weight, objective)
    pri = np.einsum("ij,jk,ik->i", Hi, Q, Hi)
    dat = np.einsum("ij,jk,ik->i", Hi, data, Hi)
    tot = pri + dat
    with np.errstate(divide="ignore", invalid="ignore"):
        share = np.where(tot > 0, pri / np.where(tot > 0, tot, 1.0), 1.0)
    return np.clip(share[: P.shape[1]], 0.0, 1.0)
