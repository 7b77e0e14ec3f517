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
so that they compare across estimators.

**A new estimator** is one class with the :class:`Estimator` protocol (``name``, ``fit``
and ``row_weights``, the weight of every row at a residual, with which held-out data are
judged in the estimator's own terms) and its entry in :data:`ESTIMATORS`;
:func:`weighted_fit` is the weighted least-squares step it can build on. Every route, the
held-out judgement and the one-step consistent fit take it from there; a log too long to
stack (``DYNID_MAX_STACK_BYTES``) is fitted block by block by OLS, WLS and IRLS only.
"""

from __future__ import annotations

import dataclasses
from collections.abc import Callable
from dataclasses import dataclass
from typing import Literal, Protocol, runtime_checkable

import numpy as np
from numpy.typing import ArrayLike, NDArray

from .. import _checks
from ..exceptions import OptionError, ShapeError, WrongTypeError
from .least_squares import LeastSquaresFit, StdMethod, _fit_with_pruning, checked_std

__all__ = [
    "ESTIMATORS",
    "IRLS",
    "OLS",
    "WLS",
    "Estimator",
    "EstimatorName",
    "estimator_named",
    "group_noise",
    "huber_weights",
    "row_weights",
    "weighted_fit",
]

EstimatorName = Literal["ols", "wls", "irls"]


@runtime_checkable
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

    def row_weights(
        self, e: NDArray[np.float64], groups: NDArray[np.intp], n_columns: int
    ) -> NDArray[np.float64]:
        """The weight (m,) of every row at the residual ``e`` (m,) of a fit of ``n_columns``
        coefficients, as the estimator weighs it (held-out data are judged with these)."""
        ...


def weighted_fit(
    W: ArrayLike,
    y: ArrayLike,
    w: ArrayLike,
    *,
    rtol: float = 1e-10,
    std: StdMethod = "classical",
    max_std_percent: float | None = None,
    labels: tuple[str, ...] | None = None,
) -> LeastSquaresFit:
    """The least-squares fit of ``diag(w) W beta = diag(w) y``, with the residual statistics
    (``relative_error_percent``, ``residual_rms``) of the unweighted rows: the step a
    reweighting estimator builds on.

    Parameters
    ----------
    W : array_like, shape (m, r)
    y : array_like, shape (m,)
    w : array_like, shape (m,)
        Row weights (the square roots of the weights of the squared residuals), in 1 / the
        unit of ``y``.
    rtol, std, max_std_percent, labels
        As :func:`~dynid.identification.least_squares.fit_with_pruning`.

    Raises
    ------
    ShapeError
        ``W`` not (m, r), or ``y`` or ``w`` not (m,).
    NonFiniteError
        NaN or inf in ``W``, ``y`` or ``w``.
    OptionError
        ``std`` not ``"classical"``/``"robust"``.
    RankDeficientError
        The weighted regressor has rank below its column count.
    """
    W = _checks.as_array("W", W)
    y, w = _checks.as_array("y", y), _checks.as_array("w", w)
    if W.ndim != 2 or y.shape != (W.shape[0],) or w.shape != y.shape:
        raise ShapeError(f"W must be (m, r), y and w (m,); got {W.shape}, {y.shape} and {w.shape}")
    return _weighted(
        W, y, w, rtol=rtol, std=checked_std(std), max_std_percent=max_std_percent, labels=labels
    )


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
    """:func:`weighted_fit` on validated input."""
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
    """Noise std of each group's residual: its RMS, corrected by the share of the degrees of
    freedom ``1 - r/m``; a group with zero residual gets the smallest non-zero level.

    Parameters
    ----------
    e : ndarray, shape (m,)
        Residual, in the unit of the data.
    groups : ndarray of int, shape (m,)
        The noise group of every row (non-negative).
    dof_share : float
        ``1 - r/m`` of a fit of ``r`` coefficients on ``m`` rows.

    Returns
    -------
    ndarray, shape (max(groups) + 1,)
        ``sigma_g``, in the unit of ``e``.
    """
    k = int(groups.max()) + 1 if groups.size else 0
    ss = np.bincount(groups, weights=e * e, minlength=k)
    cnt = np.bincount(groups, minlength=k).astype(float)
    s = np.sqrt(ss / np.maximum(cnt * dof_share, 1.0))
    pos = s[s > 0]
    floor = float(pos.min()) if pos.size else 1.0
    return np.where(s > 0, s, floor)


def huber_weights(
    e: NDArray[np.float64], groups: NDArray[np.intp], fallback: NDArray[np.float64], c: float
) -> NDArray[np.float64]:
    """Huber's row weights ``sqrt(min(1, c / |e / s_g|)) / s_g`` at a residual (Huber 1981).

    Parameters
    ----------
    e : ndarray, shape (m,)
        Residual, in the unit of the data.
    groups : ndarray of int, shape (m,)
        The noise group of every row (non-negative).
    fallback : ndarray, shape (k,)
        Scale of each group whose residual is exactly zero (its MAD gives none).
    c : float
        Huber's threshold in robust standard deviations.

    Returns
    -------
    ndarray, shape (m,)
        The weights, in 1 / the unit of ``e``; ``s_g`` is each group's robust scale,
        1.4826 times its median absolute residual.
    """
    s = np.array(fallback, dtype=np.float64)
    for g in np.flatnonzero(np.bincount(groups)):  # the groups present
        mad = float(np.median(np.abs(e[groups == g])))
        if mad > 0:
            s[g] = 1.4826 * mad
    u = np.abs(e) / s[groups]
    hub = np.minimum(1.0, c / np.maximum(u, 1e-300))
    return np.asarray(np.sqrt(hub) / s[groups], dtype=np.float64)


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

    def row_weights(
        self, e: NDArray[np.float64], groups: NDArray[np.intp], n_columns: int
    ) -> NDArray[np.float64]:
        """Every row weighs 1."""
        return np.ones(np.shape(e))


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

    def row_weights(
        self, e: NDArray[np.float64], groups: NDArray[np.intp], n_columns: int
    ) -> NDArray[np.float64]:
        """``1 / sigma_g``, the group's noise level from the residual."""
        s = group_noise(e, groups, 1.0 - n_columns / max(e.size, 1))
        return np.asarray(1.0 / s[groups], dtype=np.float64)


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
        w = 1.0 / s0[groups]
        beta = None
        for _ in range(self.max_iter):
            fit = _weighted(
                W, y, w, rtol=rtol, std="classical", max_std_percent=None, labels=labels
            )
            # a group whose residual is exactly zero keeps its WLS level
            w = huber_weights(y - W @ fit.beta, groups, s0, self.c)
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

    def row_weights(
        self, e: NDArray[np.float64], groups: NDArray[np.intp], n_columns: int
    ) -> NDArray[np.float64]:
        """Huber's weights at the residual, scales as in the fit."""
        s = group_noise(e, groups, 1.0 - n_columns / max(e.size, 1))
        return huber_weights(e, groups, s, self.c)


#: The estimators by name (``--estimator``): each makes the estimator with its defaults.
ESTIMATORS: dict[str, Callable[[], Estimator]] = {"ols": OLS, "wls": WLS, "irls": IRLS}


def row_weights(
    estimator: Estimator,
    W: NDArray[np.float64],
    y: NDArray[np.float64],
    groups: NDArray[np.intp],
    beta: NDArray[np.float64],
) -> NDArray[np.float64]:
    """The weight of every row (m,) at the estimate ``beta``, as the estimator weighs it
    (:meth:`Estimator.row_weights` of the residual ``y - W beta``): 1 (OLS),
    ``1 / sigma_g`` (WLS), Huber's ``sqrt(min(1, c / |e / s_g|)) / s_g`` (IRLS). For
    held-out judgement in the estimator's terms (an outlier weighs there as in the fit)."""
    return estimator.row_weights(y - W @ beta, groups, W.shape[1])


def estimator_named(estimator: str | Estimator) -> Estimator:
    """An estimator object from its name (or the object itself).

    Raises
    ------
    OptionError
        An unknown name.
    WrongTypeError
        An object without the :class:`Estimator` protocol.
    """
    if not isinstance(estimator, str):
        if not isinstance(estimator, Estimator):
            raise WrongTypeError(
                "estimator must be a name or an object with name, fit and row_weights (the "
                f"Estimator protocol); got {type(estimator).__name__}"
            )
        return estimator
    cls = ESTIMATORS.get(estimator)
    if cls is None:
        raise OptionError(f"estimator must be one of {sorted(ESTIMATORS)}; got {estimator!r}")
    return cls()
