"""Iteratively reweighted least squares with Huber's weights (Huber 1981; Holland and
Welsch 1977).

From the WLS start, every row is weighted ``w = sqrt(min(1, c / |e / s_g|)) / s_g``
(``c = 1.345``, ``s_g`` the group's robust scale, 1.4826 times its median absolute
residual) until the estimates move by less than ``tol`` relative: outliers (spikes,
dropped packets read as zeros) lose their pull.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
from numpy.typing import NDArray

from .base import Residuals, Weights, group_noise, huber_weights

__all__ = ["IRLS"]


@dataclass(frozen=True, slots=True)
class IRLS:
    """Huber-weighted iteratively reweighted least squares, per-group scales.

    Attributes
    ----------
    c : float
        Huber's threshold in robust standard deviations (1.345: 95 % efficiency on
        Gaussian noise).
    max_iter : int
        Weighted fits at most.
    tol : float
        Relative change of the estimates that ends the iteration.
    """

    c: float = 1.345
    max_iter: int = 30
    tol: float = 1e-8
    name: str = "irls"
    weighted: bool = True
    per_row: bool = True

    def reweight(self, residuals: Residuals) -> Weights | None:
        """WLS's ``1 / sigma_g`` after the first fit, then Huber's weights at each residual
        (a group whose residual is exactly zero keeps its WLS level) until converged."""
        if residuals.step == 0:
            return Weights(group=1.0 / residuals.first_noise)
        if residuals.step > self.max_iter or not residuals.moved(self.tol):
            return None
        assert residuals.e is not None and residuals.groups is not None
        return Weights(
            row=huber_weights(residuals.e, residuals.groups, residuals.first_noise, self.c)
        )

    def row_weights(
        self, e: NDArray[np.float64], groups: NDArray[np.intp], n_columns: int
    ) -> NDArray[np.float64]:
        """Huber's weights at the residual, scales as in the fit."""
        s = group_noise(e, groups, 1.0 - n_columns / max(e.size, 1))
        return huber_weights(e, groups, s, self.c)
