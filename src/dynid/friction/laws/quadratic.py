"""Quadratic viscous friction: the classical law with a viscous term that grows with speed.

.. math:: \\tau_f(\\dot q) = f_v \\dot q + f_q \\dot q |\\dot q| + f_c \\, s(\\dot q) + f_o

with ``s`` the sign outside the standstill band
(:func:`~dynid.regressors.friction_columns.standstill_sign`): the drag of a gearbox's
lubricant rises faster than linearly at speed. Linear in ``fv`` [N m s/rad], ``fq``
[N m s^2/rad^2], ``fc`` [N m] (each ``>= 0``) and ``fo`` [N m]. MuJoCo holds ``fv`` as
``damping`` and ``fc`` as ``frictionloss``; the quadratic term and the offset are dropped
(the export says so).
"""

from __future__ import annotations

import numpy as np
from numpy.typing import NDArray

from ...regressors.friction_columns import standstill_sign
from .base import MjcfTerms, canonical_rows, linear_law

__all__ = ["LAW", "columns"]


def columns(dq: NDArray[np.float64], band: NDArray[np.float64]) -> NDArray[np.float64]:
    """Regressor (..., n, 4): ``(dq, dq |dq|, s(dq), 1)`` per joint."""
    return np.stack([dq, dq * np.abs(dq), standstill_sign(dq, band), np.ones_like(dq)], axis=-1)


def _mjcf(P: NDArray[np.float64], dq_max: NDArray[np.float64]) -> MjcfTerms:
    dropped = "the quadratic viscous term fq dq |dq|" if np.any(P[:, 1] != 0) else ""
    return MjcfTerms(P[:, 0].copy(), P[:, 2].copy(), P[:, 3].copy(), dropped)


def _canonical(P: NDArray[np.float64], band: NDArray[np.float64]) -> NDArray[np.float64]:
    fv, fq, fc, fo = P.T
    return canonical_rows(band, fv_pos=fv, fv_neg=fv, fc_pos=fc, fc_neg=fc, fo=fo, fq=fq)


LAW = linear_law(
    "quadratic",
    ("fv", "fq", "fc", "fo"),
    ("N m s/rad", "N m s^2/rad^2", "N m", "N m"),
    "tau_f = fv dq + fq dq |dq| + fc s(dq) + fo, s(dq) = sign(dq) where |dq| > "
    "standstill_band, else 0",
    columns,
    (0.0, 0.0, 0.0, -np.inf),
    (np.inf, np.inf, np.inf, np.inf),
    _mjcf,
    _canonical,
)
