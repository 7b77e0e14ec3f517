"""Ordinary least squares (Gaz et al. 2019, eq. 21): every row weighted alike."""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
from numpy.typing import NDArray

from .base import Residuals, Weights

__all__ = ["OLS"]


@dataclass(frozen=True, slots=True)
class OLS:
    """Ordinary least squares: the first, unweighted fit is the estimate."""

    name: str = "ols"
    weighted: bool = False
    per_row: bool = False

    def reweight(self, residuals: Residuals) -> Weights | None:
        """None: no reweighting."""
        return None

    def row_weights(
        self, e: NDArray[np.float64], groups: NDArray[np.intp], n_columns: int
    ) -> NDArray[np.float64]:
        """Every row weighs 1."""
        return np.ones(np.shape(e))
