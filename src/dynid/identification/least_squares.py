"""Ordinary least squares on a base regressor, with the statistics of Gaz et al. 2019.

.. math:: \\hat\\beta = \\arg\\min_\\beta \\| W \\beta - y \\|^2 \\quad \\text{(eq. 21)}

solved by a column-scaled QR factorisation (never a normal-equation inverse). Statistics:

* ``condition_number`` of the column-scaled ``W`` (the paper reports 49 for the static
  Panda data and 122 for the exciting trajectory);
* ``relative_error_percent`` ``= 100 ||y - W beta|| / ||y||``;
* ``sigma^2 = ||y - W beta||^2 / (m - r)`` and ``cov(beta) = sigma^2 (W^T W)^{-1}``
  (from ``R^{-1}``), ``std`` its root diagonal and ``std_percent = 100 std / |beta|``
  (``covariance="classical"``, the paper's formula, which assumes errors of equal
  variance in every row);
* or, with ``covariance="robust"``, the heteroscedasticity-consistent covariance (White
  1980, HC1) ``m / (m - r) (W^T W)^{-1} W^T diag(e^2) W (W^T W)^{-1}``, valid when the
  rows' errors differ in size: the static data stack kg m^2 and N m, and a relative error
  scales with each entry.

For a tall ``W`` (more than four rows per column) ``R`` is obtained in two stages: the
triangular factor of ``[W y]`` by Householder QR without pivoting, then the pivoted QR of
its leading square block. Both stages are orthogonal, so the pivoted ``R``, the rank
decision and ``Q^T y`` are those of a pivoted QR of ``W`` itself, without forming the
``m x r`` matrix ``Q``.

Coefficients whose ``std_percent`` exceeds a threshold (the paper used 30 %) can be
removed and the rest re-fitted (:func:`fit_with_pruning`).
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
import scipy.linalg
from numpy.typing import ArrayLike, NDArray

from .. import _checks
from ..exceptions import RankDeficientError, ShapeError

__all__ = ["LeastSquaresFit", "fit_least_squares", "fit_with_pruning"]


@dataclass(frozen=True, slots=True, eq=False)
class LeastSquaresFit:
    """Result of :func:`fit_least_squares`.

    Attributes
    ----------
    beta : ndarray, shape (r,)
        Estimates; 0 for removed coefficients.
    std : ndarray, shape (r,)
        Standard deviations (0 for removed coefficients).
    std_percent : ndarray, shape (r,)
        ``100 std / |beta|`` (inf where beta is 0 and std is not).
    kept : ndarray of bool, shape (r,)
        False for coefficients removed by pruning.
    rank : int
        Numerical rank of the (scaled) regressor of the kept columns.
    condition_number : float
        Of the column-scaled regressor of the kept columns.
    relative_error_percent : float
    residual_rms : float
    sigma : float
        Residual standard deviation ``sqrt(||e||^2 / (m - r))``.
    n_rows : int
    rtol : float
    """

    beta: NDArray[np.float64]
    std: NDArray[np.float64]
    std_percent: NDArray[np.float64]
    kept: NDArray[np.bool_]
    rank: int
    condition_number: float
    relative_error_percent: float
    residual_rms: float
    sigma: float
    n_rows: int
    rtol: float


def fit_least_squares(
    W: ArrayLike,
    y: ArrayLike,
    *,
    kept: ArrayLike | None = None,
    rtol: float = 1e-10,
    covariance: str = "classical",
) -> LeastSquaresFit:
    """Least-squares estimate of ``beta`` in ``W beta = y`` with its statistics.

    Parameters
    ----------
    W : array_like, shape (m, r)
        Stacked base regressor.
    y : array_like, shape (m,)
        Stacked measurements.
    kept : array_like of bool, shape (r,), optional
        Columns to use (others are fixed to 0).
    rtol : float
        Relative rank tolerance on the diagonal of R of the column-scaled ``W``.
    covariance : {"classical", "robust"}
        ``"classical"``: ``sigma^2 (W^T W)^{-1}`` (Gaz et al. 2019); ``"robust"``: the
        heteroscedasticity-consistent (HC1) estimate, for rows of unequal error variance.

    Raises
    ------
    ShapeError
        ``W`` not 2-D or rows of ``W`` and ``y`` differ.
    NonFiniteError
        NaN or inf in ``W`` or ``y``.
    RankDeficientError
        ``W`` has rank below its column count, or fewer rows than columns; the message
        gives the rank found and the rank needed.
    """
    W = _checks.as_array("W", W)
    y = _checks.as_array("y", y)
    if W.ndim != 2 or y.shape != (W.shape[0],):
        raise ShapeError(f"W must be (m, r) and y (m,); got {W.shape} and {y.shape}")
    if covariance not in ("classical", "robust"):
        raise ValueError(f"covariance must be 'classical' or 'robust'; got {covariance!r}")
    m, r = W.shape
    keep = np.ones(r, bool) if kept is None else np.asarray(kept, dtype=bool)
    if keep.shape != (r,):
        raise ShapeError(f"kept must have shape ({r},); got {keep.shape}")
    Wk = W if keep.all() else W[:, keep]
    rk = Wk.shape[1]
    norms = np.sqrt(np.einsum("ij,ij->j", Wk, Wk))
    scale = np.where(norms > 0, norms, 1.0)
    if m > 4 * (rk + 1):
        # stage 1: R of [Ws y] by unpivoted Householder QR (LAPACK geqrf, column-major, in
        # place); its last column holds Q0^T y
        Ay = np.empty((m, rk + 1), order="F")
        np.divide(Wk, scale, out=Ay[:, :rk])
        Ay[:, rk] = y
        qr0, _, _, info = scipy.linalg.lapack.dgeqrf(Ay, overwrite_a=True)
        if info != 0:  # pragma: no cover - LAPACK argument error
            raise RuntimeError(f"LAPACK dgeqrf failed with info={info}")
        R0 = np.triu(qr0[: rk + 1])
        A, b = R0[:rk, :rk], R0[:rk, rk]
    else:
        A, b = Wk / scale, y
    Q, R, piv = scipy.linalg.qr(A, mode="economic", pivoting=True)
    d = np.abs(np.diag(R))
    rank = int(np.sum(d > rtol * d[0])) if d.size and d[0] > 0 else 0
    if m < rk:
        raise RankDeficientError(
            f"Regressor rank {rank} < {rk}: {m} rows for {rk} coefficients; add configurations"
        )
    sv = np.linalg.svd(R, compute_uv=False)
    cond = float(sv[0] / sv[-1]) if sv[-1] > 0 else float("inf")
    if rank < rk:
        raise RankDeficientError(
            f"Regressor rank {rank} < {rk} at rtol={rtol:g} (cond {cond:.3g}); add configurations "
            "or excite the trajectory more, or drop unidentifiable parameters"
        )
    z = scipy.linalg.solve_triangular(R, Q.T @ b)
    bs = np.empty(rk)
    bs[piv] = z
    bk = bs / scale
    e = y - Wk @ bk
    ss = float(e @ e)
    dof = max(m - rk, 1)
    sigma = np.sqrt(ss / dof)
    Rinv = scipy.linalg.solve_triangular(R, np.eye(rk))
    if covariance == "classical":
        var_p = np.sum(Rinv**2, axis=1) * sigma**2
    else:  # HC1: (R^T R)^{-1} Ws^T diag(e^2) Ws (R^T R)^{-1}, in pivoted order
        We = Wk * e[:, None]
        meat = (We.T @ We) / np.outer(scale, scale)
        G = Rinv @ Rinv.T
        var_p = np.einsum("ij,jk,ik->i", G, meat[np.ix_(piv, piv)], G) * (m / dof)
    var_s = np.empty(rk)
    var_s[piv] = var_p
    sk = np.sqrt(var_s) / scale
    beta = np.zeros(r)
    std = np.zeros(r)
    beta[keep], std[keep] = bk, sk
    with np.errstate(divide="ignore", invalid="ignore"):
        pct = np.where(keep, 100.0 * std / np.abs(beta), np.nan)
    pct = np.where(keep & (std == 0.0), 0.0, pct)
    ny = float(np.linalg.norm(y))
    return LeastSquaresFit(
        beta=_checks.frozen(beta),
        std=_checks.frozen(std),
        std_percent=_checks.frozen(pct),
        kept=_checks.frozen(keep),
        rank=rank,
        condition_number=cond,
        relative_error_percent=100.0 * np.sqrt(ss) / ny if ny > 0 else 0.0,
        residual_rms=float(np.sqrt(ss / m)),
        sigma=float(sigma),
        n_rows=m,
        rtol=rtol,
    )


def fit_with_pruning(
    W: ArrayLike,
    y: ArrayLike,
    *,
    max_std_percent: float | None = None,
    rtol: float = 1e-10,
    covariance: str = "classical",
) -> LeastSquaresFit:
    """Fit, then (optionally) remove coefficients with ``std_percent > max_std_percent`` and re-fit.

    Gaz et al. 2019 discard coefficients whose relative standard deviation exceeds 30 %.
    One removal pass, as in the paper. ``covariance`` as in :func:`fit_least_squares`.
    """
    fit = fit_least_squares(W, y, rtol=rtol, covariance=covariance)
    if max_std_percent is None:
        return fit
    keep = ~(fit.std_percent > max_std_percent)
    if keep.all():
        return fit
    return fit_least_squares(W, y, kept=keep, rtol=rtol, covariance=covariance)
