"""Weighted least squares with one noise level per group (Gautier 1997, "Dynamic
identification of robots with power model"; Khalil and Dombre ch. 12).

The noise std of each group from the residual of a first, unweighted fit,
``sigma_g^2 = ||e_g||^2 / (m_g - r m_g / m)``; the rows are divided by ``sigma_g``, so
joints with noisy sensors weigh less.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
from numpy.typing import NDArray

from .base import Residuals, Weights, group_noise

__all__ = ["WLS"]


@dataclass(frozen=True, slots=True)
class WLS:
    """Weighted least squares, one noise level per group from a first OLS fit (Gautier)."""

    name: str = "wls"
    weighted: bool = True
    per_row: bool = False

    def reweight(self, residuals: Residuals) -> Weights | None:
        """``1 / sigma_g`` after the first fit; then done."""
        if residuals.step > 0:
            return None
        return Weights(group=1.0 / residuals.first_noise)

    def row_weights(
        self, e: NDArray[np.float64], groups: NDArray[np.intp], n_columns: int
    ) -> NDArray[np.float64]:
        """``1 / sigma_g``, the group's noise level from the residual."""
        s = group_noise(e, groups, 1.0 - n_columns / max(e.size, 1))
        return np.asarray(1.0 / s[groups], dtype=np.float64)
