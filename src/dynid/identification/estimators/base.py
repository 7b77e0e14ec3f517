"""What an estimator is: a row-weighting policy, with or without iteration.

The one least-squares engine (:mod:`dynid.identification.engine`) fits ``W beta = y`` with
the weights an estimator gives; between fits it shows the estimator the residual of the
last estimate (:class:`Residuals`) and asks for the next weights (:meth:`Estimator.reweight`)
until the estimator answers None. An estimator never solves anything itself, so every
estimator works on rows held whole and on rows read in blocks alike.
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import Protocol, runtime_checkable

import numpy as np
from numpy.typing import NDArray

from ... import _checks
from ...exceptions import DataError, ShapeError
from ...signals import MAD_TO_STD

__all__ = [
    "Estimator",
    "Residuals",
    "Weights",
    "group_noise",
    "huber_weights",
    "noise_from_squares",
    "row_weights",
]


@dataclass(frozen=True, slots=True, eq=False)
class Weights:
    """Row weights (the square roots of the weights of the squared residuals), in 1 / the
    unit of ``y``: one per noise group or one per row.

    Attributes
    ----------
    group : ndarray, shape (k,), optional
        The weight of every row of group ``g`` (the engine then needs no pass over the rows
        to weigh them when it keeps a factor per group).
    row : ndarray, shape (m,), optional
        The weight of every row, in the rows' order.
    """

    group: NDArray[np.float64] | None = None
    row: NDArray[np.float64] | None = None

    def __post_init__(self) -> None:
        if (self.group is None) == (self.row is None):
            raise ShapeError("Weights holds either group or row weights")
        for name in ("group", "row"):
            v = getattr(self, name)
            if v is not None:
                v = _checks.as_array(f"weights.{name}", v)
                if v.ndim != 1:
                    raise ShapeError(f"weights.{name} must be 1-D; got shape {v.shape}")
                if not np.all(v >= 0):
                    raise DataError(f"weights.{name} must be non-negative")
                object.__setattr__(self, name, v)

    def of_rows(self, groups: NDArray[np.intp], start: int = 0) -> NDArray[np.float64]:
        """The weights (m_b,) of the rows ``start .. start + m_b`` of groups ``groups``."""
        if self.group is not None:
            return self.group[groups]
        assert self.row is not None
        return self.row[start : start + groups.size]


@dataclass(frozen=True, slots=True, eq=False)
class Residuals:
    """The residual of an estimate, as an estimator sees it to choose the next weights.

    Attributes
    ----------
    step : int
        0 after the first, unweighted fit; ``k`` after the ``k``-th weighted fit.
    beta : ndarray, shape (c,)
        The estimate.
    previous : ndarray, shape (c,), optional
        The estimate before (None at step 0).
    group_squares : ndarray, shape (k,)
        ``||y_g - W_g beta||^2`` of each noise group (unweighted).
    group_rows : ndarray of int, shape (k,)
        Rows of each group.
    first_noise : ndarray, shape (k,)
        Noise std of each group from the residual of the first, unweighted fit
        (:func:`noise_from_squares`).
    e : ndarray, shape (m,), optional
        The residual of every row (in the rows' order), when the estimator asks for it
        (``per_row``).
    groups : ndarray of int, shape (m,), optional
        The group of every row, with ``e``.
    """

    step: int
    beta: NDArray[np.float64]
    previous: NDArray[np.float64] | None
    group_squares: NDArray[np.float64]
    group_rows: NDArray[np.intp]
    first_noise: NDArray[np.float64]
    e: NDArray[np.float64] | None = None
    groups: NDArray[np.intp] | None = None

    @property
    def n_rows(self) -> int:
        """Rows over all groups."""
        return int(self.group_rows.sum())

    @property
    def n_columns(self) -> int:
        """Coefficients of the estimate."""
        return int(self.beta.size)

    def moved(self, tol: float) -> bool:
        """True unless the estimate moved by at most ``tol`` relative since the one before."""
        if self.previous is None:
            return True
        scale = max(float(np.linalg.norm(self.beta)), 1e-300)
        return bool(np.linalg.norm(self.beta - self.previous) > tol * scale)


@runtime_checkable
class Estimator(Protocol):
    """What the engine needs of an estimator (module docstring)."""

    @property
    def name(self) -> str:
        """``"ols"``, ``"wls"``, ``"irls"``: recorded in the results."""
        ...

    @property
    def weighted(self) -> bool:
        """False when the first, unweighted fit is the estimate (:meth:`reweight` is then
        never asked)."""
        ...

    @property
    def per_row(self) -> bool:
        """True when :meth:`reweight` needs the residual of every row (``Residuals.e``),
        False when the groups' sums of squares do."""
        ...

    def reweight(self, residuals: Residuals) -> Weights | None:
        """The weights of the next fit from the residual of the last one, or None when the
        last fit is the estimate (ordinary least squares answers None at once)."""
        ...

    def row_weights(
        self, e: NDArray[np.float64], groups: NDArray[np.intp], n_columns: int
    ) -> NDArray[np.float64]:
        """The weight (m,) of every row at the residual ``e`` (m,) of a fit of ``n_columns``
        coefficients, as the estimator weighs it (held-out data are judged with these)."""
        ...


def noise_from_squares(
    squares: NDArray[np.float64], rows: NDArray[np.intp], dof_share: float
) -> NDArray[np.float64]:
    """Noise std of each group from its residual sum of squares, corrected by the share of
    the degrees of freedom ``1 - r/m``; a group with zero residual gets the smallest non-zero
    level (Gautier 1997).

    Parameters
    ----------
    squares : ndarray, shape (k,)
        ``||e_g||^2``, in the unit of the data squared.
    rows : ndarray of int, shape (k,)
        Rows of each group.
    dof_share : float
        ``1 - r/m`` of a fit of ``r`` coefficients on ``m`` rows.
    """
    s = np.sqrt(squares / np.maximum(rows * dof_share, 1.0))
    pos = s[s > 0]
    floor = float(pos.min()) if pos.size else 1.0
    return np.asarray(np.where(s > 0, s, floor), dtype=np.float64)


def group_noise(
    e: NDArray[np.float64], groups: NDArray[np.intp], dof_share: float
) -> NDArray[np.float64]:
    """Noise std of each group's residual (:func:`noise_from_squares` of ``e`` (m,) by
    ``groups`` (m,)); shape (max(groups) + 1,), in the unit of ``e``."""
    k = int(groups.max()) + 1 if groups.size else 0
    ss = np.asarray(np.bincount(groups, weights=e * e, minlength=k), dtype=np.float64)
    rows = np.bincount(groups, minlength=k).astype(np.intp)
    return noise_from_squares(ss, rows, dof_share)


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
            s[g] = MAD_TO_STD * mad
    u = np.abs(e) / s[groups]
    hub = np.minimum(1.0, c / np.maximum(u, 1e-300))
    return np.asarray(np.sqrt(hub) / s[groups], dtype=np.float64)


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
