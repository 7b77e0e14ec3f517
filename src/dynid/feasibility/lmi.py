"""The pseudo-inertia matrix of a link: physical consistency as a linear matrix inequality.

For a rigid body with standard parameters ``phi = [m, h, J_o]`` (mass [kg], first moment
``h = m c`` [kg m], inertia ``J_o`` about the frame origin [kg m^2], :mod:`dynid.model.inertia`)

.. math:: \\mathcal J(\\phi) = \\begin{bmatrix} \\Sigma & h \\\\ h^T & m \\end{bmatrix}, \\qquad
          \\Sigma = \\tfrac12 \\mathrm{tr}(J_o) \\mathbf 1 - J_o = \\int r r^T \\rho \\, dV

is linear in ``phi``, and ``phi`` comes from a real (non-negative) mass density exactly when
``J(phi)`` is positive semidefinite (Wensing, Kim, Slotine, IEEE RA-L 2018). That implies
``m >= 0``, a positive-semidefinite inertia about the CoM and its triangle inequality.
A body is *strictly* consistent when ``J`` is positive definite; the margin used here is
the smallest eigenvalue relative to the trace, ``lambda_min(J) / tr(J)`` (dimensionless;
the published Panda links lie between 2e-4 and 2e-3).

The Bregman (log-det) divergence of ``J`` from a prior ``J0`` (Lee, Wensing, Park, IEEE
T-RO 2020) is

.. math:: d(\\mathcal J, \\mathcal J_0) = -\\log\\det \\mathcal J + \\log\\det \\mathcal J_0
          + \\mathrm{tr}(\\mathcal J_0^{-1} \\mathcal J) - 4 \\;\\ge 0,

zero only at ``J = J0``, invariant to the choice of frame and units of length, and infinite
on the boundary of the consistent set.
"""

from __future__ import annotations

import numpy as np
from numpy.typing import ArrayLike, NDArray

from .. import _checks
from ..exceptions import ModelError

__all__ = [
    "log_det_divergence",
    "phi_from_pseudo_inertia",
    "pseudo_inertia",
    "pseudo_inertia_margin",
    "repair_pseudo_inertia",
]

_TRIU = ((0, 0), (0, 1), (0, 2), (1, 1), (1, 2), (2, 2))


def pseudo_inertia(phi: ArrayLike) -> NDArray[np.float64]:
    """Pseudo-inertia ``J`` of standard parameters: (..., 10) -> (..., 4, 4) [kg, kg m, kg m^2]."""
    p = _checks.as_batch("phi", phi, (10,))
    Jo = np.empty(p.shape[:-1] + (3, 3))
    for k, (i, j) in enumerate(_TRIU):
        Jo[..., i, j] = Jo[..., j, i] = p[..., 4 + k]
    tr = np.trace(Jo, axis1=-2, axis2=-1)
    out = np.empty(p.shape[:-1] + (4, 4))
    out[..., :3, :3] = 0.5 * tr[..., None, None] * np.eye(3) - Jo
    out[..., :3, 3] = out[..., 3, :3] = p[..., 1:4]
    out[..., 3, 3] = p[..., 0]
    return out


def phi_from_pseudo_inertia(J: ArrayLike) -> NDArray[np.float64]:
    """Standard parameters of a pseudo-inertia: (..., 4, 4) -> (..., 10).

    ``J_o = tr(Sigma) 1 - Sigma`` (the inverse of ``Sigma = tr(J_o)/2 1 - J_o``).
    """
    a = _checks.as_batch("J", J, (4, 4))
    a = 0.5 * (a + np.swapaxes(a, -1, -2))
    S = a[..., :3, :3]
    Jo = np.trace(S, axis1=-2, axis2=-1)[..., None, None] * np.eye(3) - S
    out = np.empty(a.shape[:-2] + (10,))
    out[..., 0] = a[..., 3, 3]
    out[..., 1:4] = a[..., :3, 3]
    for k, (i, j) in enumerate(_TRIU):
        out[..., 4 + k] = Jo[..., i, j]
    return out


def pseudo_inertia_margin(phi: ArrayLike) -> NDArray[np.float64]:
    """``lambda_min(J) / tr(J)`` of each link (dimensionless), (..., 10) -> (...).

    Positive for a strictly consistent body, zero on the boundary (a point mass, a rod, a
    lamina), negative for parameters no mass density can have. ``-inf`` when ``tr J <= 0``.
    """
    J = pseudo_inertia(phi)
    lam = np.linalg.eigvalsh(J)
    tr = np.trace(J, axis1=-2, axis2=-1)
    with np.errstate(divide="ignore", invalid="ignore"):
        return np.where(tr > 0, lam[..., 0] / np.where(tr > 0, tr, 1.0), -np.inf)


def repair_pseudo_inertia(
    phi: ArrayLike, margin: float
) -> tuple[NDArray[np.float64], NDArray[np.bool_]]:
    """Floor the eigenvalues of each link's ``J`` so that ``lambda_min(J) = margin * tr(J)``.

    Returns the repaired parameters (..., 10) and which links were changed (...). A link
    whose ``J`` has a non-positive trace cannot be repaired this way and is returned as
    it is (flagged False; :func:`pseudo_inertia_margin` is ``-inf`` there).
    """
    p = _checks.as_batch("phi", phi, (10,))
    J = pseudo_inertia(p)
    lam, V = np.linalg.eigh(J)
    tr = np.trace(J, axis1=-2, axis2=-1)
    floor = margin * np.maximum(tr, 0.0)
    bad = (lam[..., 0] < floor) & (tr > 0)
    for _ in range(50):  # the floor counts in the trace: f = margin * sum(max(lam, f))
        floor = margin * np.sum(np.maximum(lam, floor[..., None]), axis=-1)
    lam_fixed = np.maximum(lam, floor[..., None])
    Jf = np.einsum("...ij,...j,...kj->...ik", V, lam_fixed, V)
    out = np.where(bad[..., None], phi_from_pseudo_inertia(Jf), p)
    return out, bad


def log_det_divergence(J: ArrayLike, J0: ArrayLike) -> NDArray[np.float64]:
    """Bregman log-det divergence ``d(J, J0)`` (dimensionless), (..., 4, 4) -> (...).

    ``inf`` when ``J`` is not positive definite; ``J0`` must be positive definite.
    """
    a = _checks.as_batch("J", J, (4, 4))
    b = _checks.as_batch("J0", J0, (4, 4))
    if np.any(np.linalg.eigvalsh(b)[..., 0] <= 0):
        raise ModelError("J0 must be positive definite")
    pd = np.linalg.eigvalsh(a)[..., 0] > 0
    lda = np.linalg.slogdet(a)[1]
    ldb = np.linalg.slogdet(b)[1]
    tr = np.trace(np.linalg.solve(b, a), axis1=-2, axis2=-1)
    return np.where(pd, -lda + ldb + tr - 4.0, np.inf)
