"""Settings of the convex method (:class:`SDPOptions`) and its constants."""

from __future__ import annotations

import math
from dataclasses import dataclass

from ...exceptions import ModelError
from ..heldout import DEFAULT_HELDOUT_TOL

__all__ = ["DEFAULT_SDP_MARGIN", "EXACT_RTOL", "WEIGHT_BISECTIONS", "WEIGHT_RANGE", "SDPOptions"]


#: Default margin ``epsilon``: ``lambda_min(J_i) >= epsilon tr(J_i)``.
DEFAULT_SDP_MARGIN = 1e-4
#: Relative residual below which identified coefficients count as exact.
EXACT_RTOL = 1e-9
#: Range of the automatic weight search and its number of bisection steps.
WEIGHT_RANGE = (1e-4, 1e6)
WEIGHT_BISECTIONS = 6

_OBJECTIVES = ("logdet", "euclidean")
_FITS = ("auto", "equality", "weighted")


@dataclass(frozen=True, slots=True)
class SDPOptions:
    """Settings of the convex retrieval (module docstring).

    Attributes
    ----------
    objective : {"logdet", "euclidean"}
        Distance to the prior.
    prior_weight : float or None
        ``w``; None chooses it automatically (``residual_increase``).
    residual_increase : float
        Automatic weight: largest increase of the residual RMS allowed (0.01 = 1 %).
    margin : float
        ``epsilon`` of ``lambda_min(J) >= epsilon tr(J)`` (dimensionless, >= 0).
    fit : {"auto", "equality", "weighted"}
        ``"equality"``: ``P phi = beta``; ``"weighted"``: the covariance-weighted data
        term; ``"auto"``: equality for exact coefficients, weighted otherwise.
    mass_factor : float or None
        Masses within ``[m0 / f, f m0]`` of the prior's (intersected with the bounds);
        None: the bounds alone. Not applied with the generic prior (a guess).
    residual_tol : float
        The report's ``data_fit`` holds when the parameters reproduce the data: with an
        exact fit, a relative residual on the coefficients below 1e-6; with a weighted fit,
        a residual RMS at most ``residual_tol`` (default 10 %) above the unconstrained
        fit's. Beyond it the result is reported not consistent with the specification: the
        constraints (margin, bounds, total-mass band) or the prior exclude what the data
        say. Not used when the data term holds held-out folds (``heldout_tol`` decides).
    heldout_tol : float
        With held-out folds: ``data_fit`` holds when the consistent fit's held-out error is
        at most this fraction (default 5 %) above unconstrained least squares'.
    tol : float
        Relative tolerance of the feasibility report.
    """

    objective: str = "logdet"
    prior_weight: float | None = None
    residual_increase: float = 0.01
    margin: float = DEFAULT_SDP_MARGIN
    fit: str = "auto"
    mass_factor: float | None = 3.0
    residual_tol: float = 0.10
    heldout_tol: float = DEFAULT_HELDOUT_TOL
    tol: float = 1e-9

    def __post_init__(self) -> None:
        if self.objective not in _OBJECTIVES:
            raise ModelError(f"objective must be one of {_OBJECTIVES}; got {self.objective!r}")
        if self.fit not in _FITS:
            raise ModelError(f"fit must be one of {_FITS}; got {self.fit!r}")
        if self.prior_weight is not None and not (
            math.isfinite(self.prior_weight) and self.prior_weight > 0
        ):
            raise ModelError(f"prior weight must be finite and > 0; got {self.prior_weight}")
        if not (math.isfinite(self.margin) and 0.0 <= self.margin < 0.25):
            raise ModelError(f"margin must be in [0, 0.25); got {self.margin}")
        if not self.residual_increase > 0:
            raise ModelError(f"residual_increase must be > 0; got {self.residual_increase}")
        if self.mass_factor is not None and not self.mass_factor > 1:
            raise ModelError(f"mass_factor must be > 1 or None; got {self.mass_factor}")
