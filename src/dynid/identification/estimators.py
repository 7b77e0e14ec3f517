"""Estimators of the base parameters: ordinary, weighted and outlier-robust least squares.

Every route stacks a regressor ``W`` (m, r) and measurements ``y`` (m,) whose rows fall in
*groups* of equal noise: the joints of a torque log (row ``k n + j`` is joint ``j``), the
rows of ``[tril M; g]`` of static data. An estimator turns them into a
:class:`~dynid.identification.least_squares.LeastSquaresFit`:

* :class:`OLS`: ordinary least squares (Gaz et al. 2019, eq. 21), every row weighted alike;
* :class:`WLS`: weighted least squares with one noise level per group from a first OLS fit,
  ``sigma_g^2 = ||e_g||^2 / (m_g - r m_g / m)``, rows divided by ``sigma_g`` (Gautier 1997,
  "Dynamic identification of robots with power model"; Khalil and Dombre ch. 12): joints
  with noisy sensors weigh less;
* :class:`IRLS`: iteratively reweighted least squares with Huber's weights
  ``w = min(1, c / |e / s_g|)`` (``c = 1.345``, ``s_g`` the group's robust scale, 1.4826
  times the median absolute residual), from the WLS start, until the estimates move by less
  than ``tol`` relative (Huber 1981; Holland and Welsch 1977): outliers (spikes, dropped
  packets read as zeros) lose their pull.

Standard deviations come from the last weighted fit (``std`` ``"classical"`` or
``"robust"``, :func:`~dynid.identification.least_squares.fit_least_squares`); the residual
statistics (``relative_error_percent``, ``residual_rms``) are those of the unweighted data,
so that they compare across estimators. A new estimator is one class with the
:class:`Estimator` protocol and its entry in :data:`ESTIMATORS`.
"""

from __future__ import annotations

import dataclasses
from dataclasses import dataclass
from typing import Literal, Protocol

import numpy as np
from numpy.typing import NDArray

from ..exceptions import OptionError
from .least_squares import LeastSquaresFit, StdMethod, _fit_with_pruning

__all__ = [
    "ESTIMATORS",
    "IRLS",
    "OLS",
    "WLS",
    "Estimator",
    "EstimatorName",
    "estimator_named",
    "residual_weights",
    "row_weights",
]

EstimatorName = Literal["ols", "wls", "irls"]


class Estimator(Protocol):
    """What a route needs of an estimator (module docstring)."""

    @property
    def name(self) -> str:
        """``"ols"``, ``"wls"``, ``"irls"``: recorded in the results."""
        ...

    def fit(
        self,
        W: NDArray[np.float64],
        y: NDArray[np.float64],
        groups: NDArray[np.intp],
        *,
        rtol: float,
        std: StdMethod,
        max_std_percent: float | None = None,
        labels: tuple[str, ...] | None = None,
    ) -> LeastSquaresFit:
        """Fit ``W beta = y``; ``groups`` (m,) the noise group of each row."""
        ...


def _weighted(
    W: NDArray[np.float64],
    y: NDArray[np.float64],
    w: NDArray[np.float64],
    *,
    rtol: float,
    std: StdMethod,
    max_std_percent: float | None,
    labels: tuple[str, ...] | None,
) -> LeastSquaresFit:
    """The fit of ``diag(w) W beta = diag(w) y`` with the unweighted residual statistics."""
    fit = _fit_with_pruning(
        W * w[:, None],
        y * w,
        max_std_percent=max_std_percent,
        rtol=rtol,
        std=std,
        labels=labels,
    )
    e = y - W @ fit.beta
    ss, ny = float(e @ e), float(np.linalg.norm(y))
    return dataclasses.replace(
        fit,
        relative_error_percent=100.0 * np.sqrt(ss) / ny if ny > 0 else 0.0,
        residual_rms=float(np.sqrt(ss / max(y.size, 1))),
    )


def group_noise(
    e: NDArray[np.float64], groups: NDArray[np.intp], dof_share: float
) -> NDArray[np.float64]:
    """Noise std of each group's residual (its RMS, corrected by the share of the degrees of
    freedom, ``1 - r/m``); groups with zero residual get the smallest non-zero level."""
    k = int(groups.max()) + 1 if groups.size else 0
    ss = np.bincount(groups, weights=e * e, minlength=k)
    cnt = np.bincount(groups, minlength=k).astype(float)
    s = np.sqrt(ss / np.maximum(cnt * dof_share, 1.0))
    pos = s[s > 0]
    floor = float(pos.min()) if pos.size else 1.0
    return np.where(s > 0, s, floor)


@dataclass(frozen=True, slots=True)
class OLS:
    """Ordinary least squares (every row weighted alike)."""

    name: str = "ols"

    def fit(
        self,
        W: NDArray[np.float64],
        y: NDArray[np.float64],
        groups: NDArray[np.intp],
        *,
        rtol: float,
        std: StdMethod,
        max_std_percent: float | None = None,
        labels: tuple[str, ...] | None = None,
    ) -> LeastSquaresFit:
        """:func:`~dynid.identification.least_squares.fit_with_pruning` as it is."""
        return _fit_with_pruning(
            W, y, max_std_percent=max_std_percent, rtol=rtol, std=std, labels=labels
        )


@dataclass(frozen=True, slots=True)
class WLS:
    """Weighted least squares, one noise level per group from a first OLS fit (Gautier)."""

    name: str = "wls"

    def noise(
        self, W: NDArray[np.float64], y: NDArray[np.float64], groups: NDArray[np.intp], rtol: float
    ) -> NDArray[np.float64]:
        """Noise std ``sigma_g`` of each group, from the residual of an OLS fit."""
        first = _fit_with_pruning(W, y, max_std_percent=None, rtol=rtol, std="classical")
        e = y - W @ first.beta
        return group_noise(e, groups, 1.0 - W.shape[1] / max(y.size, 1))

    def fit(
        self,
        W: NDArray[np.float64],
        y: NDArray[np.float64],
        groups: NDArray[np.intp],
        *,
        rtol: float,
        std: StdMethod,
        max_std_percent: float | None = None,
        labels: tuple[str, ...] | None = None,
    ) -> LeastSquaresFit:
        """Weights from a first fit, then the weighted fit."""
        w = 1.0 / self.noise(W, y, groups, rtol)[groups]
        return _weighted(
            W,
            y,
            w,
            rtol=rtol,
            std=std,
            max_std_percent=max_std_percent,
            labels=labels,
        )


@dataclass(frozen=True, slots=True)
class IRLS:
    """Huber-weighted iteratively reweighted least squares, per-group scales.

    Attributes
    ----------
    c : float
        Huber's threshold in robust standard deviations (1.345: 95 % efficiency on
        Gaussian noise).
    max_iter : int
    tol : float
        Relative change of the estimates that ends the iteration.
    """

    c: float = 1.345
    max_iter: int = 30
    tol: float = 1e-8
    name: str = "irls"

    def fit(
        self,
        W: NDArray[np.float64],
        y: NDArray[np.float64],
        groups: NDArray[np.intp],
        *,
        rtol: float,
        std: StdMethod,
        max_std_percent: float | None = None,
        labels: tuple[str, ...] | None = None,
    ) -> LeastSquaresFit:
        """WLS start, then Huber reweighting; pruning (if asked) on the last pass."""
        s0 = WLS().noise(W, y, groups, rtol)
        present = np.unique(groups)
        w = 1.0 / s0[groups]
        beta = None
        for _ in range(self.max_iter):
            fit = _weighted(
                W, y, w, rtol=rtol, std="classical", max_std_percent=None, labels=labels
            )
            e = y - W @ fit.beta
            s = s0.copy()  # a group whose residual is exactly zero keeps its WLS level
            for g in present:
                mad = float(np.median(np.abs(e[groups == g])))
                if mad > 0:
                    s[g] = 1.4826 * mad
            u = np.abs(e) / s[groups]
            hub = np.minimum(1.0, self.c / np.maximum(u, 1e-300))
            w = np.sqrt(hub) / s[groups]
            done = beta is not None and np.linalg.norm(fit.beta - beta) <= self.tol * max(
                float(np.linalg.norm(fit.beta)), 1e-300
            )
            beta = fit.beta
            if done:
                break
        return _weighted(
            W,
            y,
            w,
            rtol=rtol,
            std=std,
            max_std_percent=max_std_percent,
            labels=labels,
        )


#: The estimators by name (``--estimator``).
ESTIMATORS: dict[str, type[OLS] | type[WLS] | type[IRLS]] = {"ols": OLS, "wls": WLS, "irls": IRLS}


def row_weights(
    estimator: Estimator,
    W: NDArray[np.float64],
    y: NDArray[np.float64],
    groups: NDArray[np.intp],
    beta: NDArray[np.float64],
) -> NDArray[np.float64]:
    """The weight of every row (m,) at the estimate ``beta``, as the estimator weighs it:
    1 (OLS, and estimators of a user's), ``1 / sigma_g`` (WLS), Huber's
    ``sqrt(min(1, c / |e / s_g|)) / s_g`` (IRLS), from the residual ``e = y - W beta``. For
    held-out judgement in the estimator's terms (an outlier weighs there as in the fit)."""
    if not isinstance(estimator, WLS | IRLS):
        return np.ones(y.size)
    return residual_weights(estimator, y - W @ beta, groups, W.shape[1])


def residual_weights(
    estimator: Estimator, e: NDArray[np.float64], groups: NDArray[np.intp], n_columns: int
) -> NDArray[np.float64]:
    """:func:`row_weights` from the residual ``e`` (m,) of a fit of ``n_columns``
    coefficients (the regressor itself not needed: a streamed fit's rows)."""
    if not isinstance(estimator, WLS | IRLS):
        return np.ones(e.size)
    s = group_noise(e, groups, 1.0 - n_columns / max(e.size, 1))
    if isinstance(estimator, WLS):
        return np.asarray(1.0 / s[groups], dtype=np.float64)
    for g in np.unique(groups):
        mad = float(np.median(np.abs(e[groups == g])))
        if mad > 0:
            s[g] = 1.4826 * mad
    u = np.abs(e) / s[groups]
    hub = np.minimum(1.0, estimator.c / np.maximum(u, 1e-300))
    return np.asarray(np.sqrt(hub) / s[groups], dtype=np.float64)


def estimator_named(estimator: str | Estimator) -> Estimator:
    """An estimator object from its name (or the object itself).

    Raises
    ------
    OptionError
        An unknown name.
    """
    if not isinstance(estimator, str):
        return estimator
    cls = ESTIMATORS.get(estimator)
    if cls is None:
        raise OptionError(f"estimator must be one of {sorted(ESTIMATORS)}; got {estimator!r}")
    return cls()
