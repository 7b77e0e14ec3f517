"""Inertial parameters of a rigid link and the standard parameter vector.

Layout of the standard parameters of one link (Gaz et al. 2019, eqs. 3-4), 10 entries::

    phi_i = [m, m*cx, m*cy, m*cz, Jxx, Jxy, Jxz, Jyy, Jyz, Jzz]

with the centre of mass ``c`` [m] in the link frame and ``J`` [kg m^2] the inertia tensor
**about the link-frame origin**, in link-frame axes. The barycentric inertia ``I`` (about the
CoM, link-frame axes) follows from the parallel-axis theorem (Gaz et al. eq. 26):

.. math:: J = I + m (c^T c \\, E - c c^T)

The robot's vector ``phi`` concatenates the links in joint order: shape ``(n * 10,)``;
:func:`param_labels` names every entry (``m3``, ``mc3x``, ``J3xx``, ...).
"""

from __future__ import annotations

import numpy as np
from numpy.typing import ArrayLike, NDArray

from .. import _checks
from ..exceptions import ShapeError

__all__ = [
    "PARAMS_PER_LINK",
    "READ_AS_GIVEN",
    "INERTIA_ORDER",
    "param_labels",
    "matrix_from_inertia6",
    "inertia6_from_matrix",
    "phi_from_inertial",
    "inertial_from_phi",
    "parallel_axis",
    "DECISION_FIELDS",
    "decision_labels",
    "params_from_inertial",
    "inertial_from_params",
    "inertial_problems",
]

PARAMS_PER_LINK = 10
INERTIA_ORDER = ("xx", "xy", "xz", "yy", "yz", "zz")
_I6 = ((0, 0), (0, 1), (0, 2), (1, 1), (1, 2), (2, 2))
#: Per-link decision variables of the feasibility retrieval, in order: mass [kg], CoM [m],
#: inertia about the CoM [kg m^2].
DECISION_FIELDS = ("m", "cx", "cy", "cz") + tuple(f"I{ax}" for ax in INERTIA_ORDER)


def param_labels(n: int) -> tuple[str, ...]:
    """Labels of the ``10 n`` standard parameters, links numbered from 1.

    ``m<i>`` [kg], ``mc<i>x`` ... [kg m], ``J<i>xx`` ... [kg m^2] (about the link origin).
    """
    if isinstance(n, bool) or not isinstance(n, int | np.integer):
        raise _checks.wrong_type("n", n, "an int (the number of links)")
    out: list[str] = []
    for i in range(1, n + 1):
        out += [f"m{i}", f"mc{i}x", f"mc{i}y", f"mc{i}z"]
        out += [f"J{i}{ax}" for ax in INERTIA_ORDER]
    return tuple(out)


def matrix_from_inertia6(i6: ArrayLike) -> NDArray[np.float64]:
    """Symmetric 3x3 tensor from ``(xx, xy, xz, yy, yz, zz)``; (..., 6) -> (..., 3, 3)."""
    a = _checks.as_batch("inertia", i6, (6,))
    xx, xy, xz, yy, yz, zz = np.moveaxis(a, -1, 0)
    return np.stack(
        [np.stack([xx, xy, xz], -1), np.stack([xy, yy, yz], -1), np.stack([xz, yz, zz], -1)], -2
    )


def inertia6_from_matrix(I: ArrayLike) -> NDArray[np.float64]:
    """``(xx, xy, xz, yy, yz, zz)`` of a 3x3 tensor (upper triangle); (..., 3, 3) -> (..., 6)."""
    a = _checks.as_batch("inertia", I, (3, 3))
    return np.stack([a[..., i, j] for i, j in _I6], axis=-1)


def parallel_axis(mass: ArrayLike, com: ArrayLike) -> NDArray[np.float64]:
    """The term ``m (c^T c E - c c^T)`` [kg m^2] moving an inertia from the CoM to the origin."""
    m = np.asarray(mass, dtype=np.float64)
    c = np.asarray(com, dtype=np.float64)
    cc = np.einsum("...i,...i->...", c, c)
    return m[..., None, None] * (
        cc[..., None, None] * np.eye(3) - c[..., :, None] * c[..., None, :]
    )


def phi_from_inertial(mass: ArrayLike, com: ArrayLike, inertia: ArrayLike) -> NDArray[np.float64]:
    """Standard parameters from mass, CoM and inertia about the CoM.

    Parameters
    ----------
    mass : array_like, shape (...)
        Link masses [kg].
    com : array_like, shape (..., 3)
        Centres of mass in the link frame [m].
    inertia : array_like, shape (..., 3, 3) or (..., 6)
        Inertia about the CoM, link-frame axes [kg m^2]; 6-vectors in ``INERTIA_ORDER``.

    Returns
    -------
    phi : ndarray, shape (..., 10)
    """
    m = _checks.as_array("mass", mass)
    c = _checks.as_batch("com", com, (3,))
    I = _checks.as_array("inertia", inertia)
    if I.shape[-1:] == (6,):
        I = matrix_from_inertia6(I)
    I = _checks.as_batch("inertia", I, (3, 3))
    J = I + parallel_axis(m, c)
    shape = np.broadcast_shapes(m.shape, c.shape[:-1], J.shape[:-2])
    out = np.empty(shape + (10,))
    out[..., 0] = m
    out[..., 1:4] = m[..., None] * c
    out[..., 4:] = inertia6_from_matrix(J)
    return out


def inertial_from_phi(
    phi: ArrayLike,
) -> tuple[NDArray[np.float64], NDArray[np.float64], NDArray[np.float64]]:
    """Mass [kg], CoM [m] and inertia about the CoM [kg m^2, (..., 3, 3)] from ``(..., 10)``.

    A link of zero mass has its CoM set to the origin (its first moment must then be zero
    for the result to describe the same body; this is not checked here, see
    ``feasibility.constraints.is_physically_valid``).
    """
    p = _checks.as_batch("phi", phi, (10,))
    m = p[..., 0]
    safe = np.where(m != 0.0, m, 1.0)
    c = np.where((m != 0.0)[..., None], p[..., 1:4] / safe[..., None], 0.0)
    J = matrix_from_inertia6(p[..., 4:])
    return m.copy(), c, J - parallel_axis(m, c)


# ------------------------------------------------ the retrieval's layout (about the CoM)
def decision_labels(n: int) -> tuple[str, ...]:
    """Labels of the ``10 n`` decision variables: ``m1, c1x, c1y, c1z, I1xx, ..., I1zz, m2``..."""
    out: list[str] = []
    for i in range(1, n + 1):
        out += [f"m{i}", f"c{i}x", f"c{i}y", f"c{i}z"] + [f"I{i}{ax}" for ax in INERTIA_ORDER]
    return tuple(out)


def params_from_inertial(
    mass: ArrayLike, com: ArrayLike, inertia: ArrayLike
) -> NDArray[np.float64]:
    """Decision parameters ``p`` (n, 10) from masses (n,) [kg], CoMs (n, 3) [m] and
    inertias about the CoM (n, 3, 3) or (n, 6) [kg m^2]."""
    m = _checks.as_array("mass", mass)
    if m.ndim != 1:
        raise ShapeError(f"mass must have shape (n,); got {m.shape}")
    n = m.shape[0]
    c = _checks.as_exact("com", com, (n, 3))
    I = _checks.as_array("inertia", inertia)
    if I.shape == (n, 3, 3):
        I = inertia6_from_matrix(I)
    elif I.shape != (n, 6):
        raise ShapeError(f"inertia must have shape ({n}, 3, 3) or ({n}, 6); got {I.shape}")
    return np.concatenate([m[:, None], c, I], axis=1)


def inertial_from_params(
    p: ArrayLike,
) -> tuple[NDArray[np.float64], NDArray[np.float64], NDArray[np.float64]]:
    """Masses (n,) [kg], CoMs (n, 3) [m] and inertias about the CoM (n, 3, 3) [kg m^2]
    from decision parameters ``p`` of shape (n, 10) or (10 n,)."""
    a = _checks.as_array("p", p)
    if a.ndim == 1 and a.size % 10 == 0:
        a = a.reshape(-1, 10)
    if a.ndim != 2 or a.shape[1] != 10:
        raise ShapeError(f"p must have shape (n, 10) or (10 n,); got {a.shape}")
    return a[:, 0].copy(), a[:, 1:4].copy(), matrix_from_inertia6(a[:, 4:])


#: What a robot description's physically inconsistent inertial becomes when read.
READ_AS_GIVEN = (
    "read as given (identification fits the links anew; a consistent fit repairs it where it "
    "takes the description as its prior)"
)


def inertial_problems(mass: float, inertia: ArrayLike) -> list[str]:
    """What makes one link's mass and inertia about its CoM physically inconsistent.

    Parameters
    ----------
    mass : float
        [kg].
    inertia : array_like, shape (3, 3)
        Inertia about the CoM [kg m^2], symmetric.

    Returns
    -------
    list of str
        One phrase per problem (a negative mass, a tensor not positive semi-definite,
        principal moments violating the triangle inequality ``a + b >= c``); empty when
        consistent, up to a relative tolerance of 1e-9 of the moments' sum.
    """
    problems = []
    if mass < 0.0:
        problems.append(f"negative mass {mass}")
    lam = np.linalg.eigvalsh(np.asarray(inertia, dtype=np.float64))
    tol = 1e-9 * max(float(np.sum(np.abs(lam))), 1e-300)
    moments = ", ".join(f"{x:.4g}" for x in lam)
    if lam[0] < -tol:
        problems.append(f"inertia not positive semi-definite (eigenvalues {moments} kg m^2)")
    elif lam[0] + lam[1] < lam[2] - tol:
        problems.append(
            f"principal moments {moments} kg m^2 violate the triangle inequality "
            f"({lam[0]:.4g} + {lam[1]:.4g} < {lam[2]:.4g})"
        )
    return problems
