"""The classical law (Gaz et al. 2019, eq. 24): viscous, Coulomb and offset, linear.

.. math:: \\tau_f(\\dot q) = f_v \\dot q + f_c \\, s(\\dot q) + f_o

with ``s`` the sign outside the standstill band (:func:`~dynid.friction.model.coulomb_sign`).
``fv`` [N m s/rad] and ``fc`` [N m] are non-negative (a dissipative joint, as the
consistent fit constrains them), the offset ``fo`` [N m] has either sign. Its columns are
those of the classical identification route (``fv, fc, fo`` per joint,
:func:`~dynid.identification.classical.friction_regressor`). MuJoCo holds ``fv`` as
``damping`` and ``fc`` as ``frictionloss``; the offset has no MJCF counterpart.
"""

from __future__ import annotations

import numpy as np
from numpy.typing import NDArray

from ..torques import classical_friction, coulomb_sign
from .base import MjcfTerms, canonical_rows, linear_law

__all__ = ["LAW", "columns"]


def columns(dq: NDArray[np.float64], band: NDArray[np.float64]) -> NDArray[np.float64]:
    """Regressor (..., n, 3): ``(dq, s(dq), 1)`` per joint."""
    return np.stack([dq, coulomb_sign(dq, band), np.ones_like(dq)], axis=-1)


def _mjcf(P: NDArray[np.float64], dq_max: NDArray[np.float64]) -> MjcfTerms:
    return MjcfTerms(P[:, 0].copy(), P[:, 1].copy(), P[:, 2].copy())


def _canonical(P: NDArray[np.float64], band: NDArray[np.float64]) -> NDArray[np.float64]:
    fv, fc, fo = P.T
    return canonical_rows(band, fv_pos=fv, fv_neg=fv, fc_pos=fc, fc_neg=fc, fo=fo)


def _torques(
    dq: NDArray[np.float64], P: NDArray[np.float64], band: NDArray[np.float64]
) -> NDArray[np.float64]:
    """``fv dq + fc s(dq) + fo`` in closed form (the columns' product, faster)."""
    return classical_friction(dq, P[:, 0], P[:, 1], P[:, 2], band)


LAW = linear_law(
    "classical",
    ("fv", "fc", "fo"),
    ("N m s/rad", "N m", "N m"),
    "tau_f = fv dq + fc s(dq) + fo, s(dq) = sign(dq) where |dq| > standstill_band, else 0 "
    "(Gaz et al. 2019, eq. 24)",
    columns,
    (0.0, 0.0, -np.inf),
    (np.inf, np.inf, np.inf),
    _mjcf,
    _canonical,
    _torques,
)
