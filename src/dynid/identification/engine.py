"""The one least-squares engine: rows in blocks, weighted by an estimator, fitted.

Every fit of the library (static data, torque logs, several recordings, held whole or read
in blocks) is :func:`fit_rows`: an estimator (:mod:`dynid.identification.estimators`) is a
row-weighting policy, and the engine

1. fits the rows unweighted (for an estimator that does not weigh, ``weighted`` False,
   this is the estimate);
2. shows the estimator the residual (:class:`~dynid.identification.estimators.base.Residuals`:
   each noise group's sum of squares, and every row's residual when it asks) and fits again
   with the weights it gives, until it answers None (ordinary least squares at once,
   weighted least squares after one reweighting, Huber IRLS when converged);
3. returns the last fit with its standard deviations (``"classical"``, ``"robust"`` or
   ``"hac"``),
   pruned when asked, and the residual statistics of the unweighted rows.

The rows come as :class:`Rows`, which accumulate and solve them. Two kinds, chosen by where
the rows live, with the same estimates to about 1e-12 relative and the statistics assembled
in one place (:func:`~dynid.identification.least_squares.assembled`):

* :class:`HeldRows`: rows held in memory, in blocks of a stacked regressor whose leading
  columns may be zero. Passes over them are cheap: the block normal equations, column
  scaled, solved by Cholesky with one correction step (corrected semi-normal equations,
  Björck 1987) when the scaled condition number is at most 100, Householder QR with column
  pivoting otherwise (:mod:`dynid.identification.least_squares`, ``docs/least-squares.md``);
* :class:`~dynid.identification.streaming.BlockRows`: rows read in blocks from a source that
  computes them again at every pass (a log too long to stack). A pass costs the regressor, so
  the rows are accumulated once into the triangular factors of ``[W_g y_g]`` of every noise
  group (a streamed QR), from which the unweighted and every group-weighted fit, and each
  group's residual, follow without another pass; per-row weights (IRLS) take one pass for the
  weighted factor and one for the residuals.
"""

from __future__ import annotations

import dataclasses
import itertools
from typing import Protocol

import numpy as np
from numpy.typing import ArrayLike, NDArray

from .. import _checks
from ..exceptions import ShapeError
from .estimators import Estimator, Residuals, Weights, noise_from_squares
from .least_squares import LeastSquaresFit, StdMethod, _fit_with_pruning, checked_std
from .serial import Serial

__all__ = ["HeldRows", "Rows", "fit_rows", "fit_stacked", "weighted_fit"]


class Rows(Protocol):
    """Rows of a least-squares problem as the engine needs them (module docstring)."""

    @property
    def n_columns(self) -> int:
        """Columns c of the regressor."""
        ...

    @property
    def cheap(self) -> bool:
        """True when a pass over the rows costs little against a solve (rows in memory)."""
        ...

    def fit(
        self,
        weights: Weights | None,
        *,
        rtol: float,
        std: StdMethod,
        max_std_percent: float | None,
        labels: tuple[str, ...] | None,
    ) -> LeastSquaresFit:
        """The fit of the weighted rows (None: unweighted), pruned once above
        ``max_std_percent``, with the residual statistics of the unweighted rows."""
        ...

    def residuals(
        self, beta: NDArray[np.float64], per_row: bool
    ) -> tuple[
        NDArray[np.float64],
        NDArray[np.intp],
        NDArray[np.float64] | None,
        NDArray[np.intp] | None,
    ]:
        """``(group_squares (k,), group_rows (k,), e (m,) or None, groups (m,) or None)`` of
        the unweighted residual ``y - W beta``; ``e`` and ``groups`` when ``per_row``."""
        ...


def fit_rows(
    rows: Rows,
    estimator: Estimator,
    *,
    rtol: float,
    std: StdMethod = "classical",
    max_std_percent: float | None = None,
    labels: tuple[str, ...] | None = None,
) -> LeastSquaresFit:
    """Fit ``W beta = y`` with an estimator (module docstring).

    Parameters
    ----------
    rows : Rows
    estimator : Estimator
    rtol : float
        Relative rank tolerance on the diagonal of R of the column-scaled regressor.
    std : {"classical", "robust", "hac"}
        Standard deviations of the last fit (``"hac"``: over the time structure the rows
        carry, :class:`HeldRows` and :class:`~dynid.identification.streamed.BlockRows`'
        ``serial``).
    max_std_percent : float, optional
        Remove the coefficients above this relative standard deviation from the last fit
        and re-fit once.
    labels : tuple of str, length c, optional
        Column names for a rank-deficiency message.

    Raises
    ------
    OptionError
        ``std`` unknown.
    RankDeficientError
        Rank below the column count (``rank``, ``needed``, ``dependent`` set).
    NonFiniteError
        NaN or inf in the rows.
    """
    checked_std(std)
    if not estimator.weighted:
        return rows.fit(None, rtol=rtol, std=std, max_std_percent=max_std_percent, labels=labels)
    # the weighted fits' own standard deviations where a pass over the rows is cheap
    each = std if rows.cheap else "classical"
    fit = rows.fit(None, rtol=rtol, std=each, max_std_percent=None, labels=labels)
    beta, previous = np.asarray(fit.beta), None
    noise = None
    weights = None
    for step in itertools.count():
        squares, counts, e, g = rows.residuals(beta, estimator.per_row)
        if noise is None:  # the noise levels of the unweighted fit
            m, c = int(counts.sum()), rows.n_columns
            noise = noise_from_squares(squares, counts, 1.0 - c / max(m, 1))
        nxt = estimator.reweight(Residuals(step, beta, previous, squares, counts, noise, e, g))
        if nxt is None:
            break
        weights = nxt
        fit = rows.fit(weights, rtol=rtol, std=each, max_std_percent=None, labels=labels)
        previous, beta = beta, np.asarray(fit.beta)
    if std == each and max_std_percent is None:
        return fit
    return rows.fit(weights, rtol=rtol, std=std, max_std_percent=max_std_percent, labels=labels)


def fit_stacked(
    W: ArrayLike,
    y: ArrayLike,
    groups: ArrayLike,
    estimator: Estimator,
    *,
    rtol: float = 1e-10,
    std: StdMethod = "classical",
    max_std_percent: float | None = None,
    labels: tuple[str, ...] | None = None,
) -> LeastSquaresFit:
    """:func:`fit_rows` on a stacked regressor ``W`` (m, c), targets ``y`` (m,) and the
    noise group ``groups`` (m,) of every row.

    Raises
    ------
    ShapeError
        ``W`` not (m, c), or ``y`` or ``groups`` not (m,), or negative groups.
    NonFiniteError, RankDeficientError, OptionError
        As :func:`fit_rows`.
    """
    W = _checks.as_array("W", W)
    y = _checks.as_array("y", y)
    g = np.asarray(groups, dtype=np.intp)
    if W.ndim != 2 or y.shape != (W.shape[0],) or g.shape != y.shape:
        raise ShapeError(
            f"W must be (m, c), y and groups (m,); got {W.shape}, {y.shape}, {g.shape}"
        )
    if g.size and g.min() < 0:
        raise ShapeError("noise groups must be non-negative integers")
    return fit_rows(
        HeldRows(W, y, g),
        estimator,
        rtol=rtol,
        std=std,
        max_std_percent=max_std_percent,
        labels=labels,
    )


class HeldRows:
    """Rows held in memory: ``W`` (M, c), ``y`` (M,), ``groups`` (M,) and the blocks used.

    Parameters
    ----------
    W, y, groups : ndarray
        Every row of the stack.
    blocks : ndarray of int, shape (k, 3), optional
        ``(start, stop, first)`` of each block used (``W[start:stop, :first]`` exactly zero,
        so the products skip it); default every row, one block.
    gram : ndarray, shape (c, c), optional
        ``W^T W`` over the rows used, when known.
    serial : Serial, optional
        The samples and pieces of the rows used (``std="hac"``; default: rows
        independent).
    """

    def __init__(
        self,
        W: NDArray[np.float64],
        y: NDArray[np.float64],
        groups: NDArray[np.intp],
        blocks: NDArray[np.intp] | None = None,
        gram: NDArray[np.float64] | None = None,
        serial: Serial | None = None,
    ) -> None:
        self.W, self.y, self.groups, self.blocks, self.gram = W, y, groups, blocks, gram
        self.serial = serial
        self._rows: tuple[NDArray[np.float64], NDArray[np.float64], NDArray[np.intp]] | None
        self._rows = None

    #: Passes over rows in memory are cheap.
    cheap = True

    @property
    def n_columns(self) -> int:
        """Columns c of the regressor."""
        return int(self.W.shape[1])

    def _used(self) -> tuple[NDArray[np.float64], NDArray[np.float64], NDArray[np.intp]]:
        """The rows used, in block order (copied once, when not all rows in order)."""
        if self._rows is None:
            blk = self.blocks
            M = self.y.size
            if blk is None or (
                blk.size
                and blk[0, 0] == 0
                and blk[-1, 1] == M
                and np.all(blk[1:, 0] == blk[:-1, 1])
            ):
                self._rows = self.W, self.y, self.groups
            else:
                idx = np.concatenate(
                    [np.arange(a, b) for a, b, _ in blk] + [np.zeros(0, dtype=np.intp)]
                )
                W = np.empty((idx.size, self.W.shape[1]), order="F")
                o = 0
                for a, b, _ in blk:
                    W[o : o + b - a] = self.W[a:b]
                    o += b - a
                self._rows = W, self.y[idx], self.groups[idx]
        return self._rows

    def fit(
        self,
        weights: Weights | None,
        *,
        rtol: float,
        std: StdMethod,
        max_std_percent: float | None,
        labels: tuple[str, ...] | None,
    ) -> LeastSquaresFit:
        """:meth:`Rows.fit` on the rows held."""
        if weights is None:
            return _fit_with_pruning(
                self.W,
                self.y,
                max_std_percent=max_std_percent,
                rtol=rtol,
                std=std,
                blocks=self.blocks,
                gram=self.gram,
                labels=labels,
                serial=self.serial,
            )
        W, y, g = self._used()
        _checks.finite("regressor", W)
        w = weights.of_rows(g)
        return _weighted(W, y, w, rtol, std, max_std_percent, labels, self.serial)

    def residuals(
        self, beta: NDArray[np.float64], per_row: bool
    ) -> tuple[
        NDArray[np.float64],
        NDArray[np.intp],
        NDArray[np.float64] | None,
        NDArray[np.intp] | None,
    ]:
        """:meth:`Rows.residuals` on the rows held."""
        W, y, g = self._used()
        e = y - W @ beta
        k = int(g.max()) + 1 if g.size else 0
        squares = np.asarray(np.bincount(g, weights=e * e, minlength=k), dtype=np.float64)
        counts = np.bincount(g, minlength=k).astype(np.intp)
        return squares, counts, (e if per_row else None), (g if per_row else None)


def _weighted(
    W: NDArray[np.float64],
    y: NDArray[np.float64],
    w: NDArray[np.float64],
    rtol: float,
    std: StdMethod,
    max_std_percent: float | None,
    labels: tuple[str, ...] | None,
    serial: Serial | None = None,
) -> LeastSquaresFit:
    """The fit of ``diag(w) W beta = diag(w) y`` with the unweighted residual statistics
    (the HAC covariance, ``serial``, of the weighted rows: the weighted sandwich)."""
    fit = _fit_with_pruning(
        W * w[:, None],
        y * w,
        max_std_percent=max_std_percent,
        rtol=rtol,
        std=std,
        labels=labels,
        serial=serial,
    )
    e = y - W @ fit.beta
    ss, ny = float(e @ e), float(np.linalg.norm(y))
    return dataclasses.replace(
        fit,
        relative_error_percent=100.0 * np.sqrt(ss) / ny if ny > 0 else 0.0,
        residual_rms=float(np.sqrt(ss / max(y.size, 1))),
    )


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
    (``relative_error_percent``, ``residual_rms``) of the unweighted rows.

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
    return _weighted(W, y, w, rtol, checked_std(std), max_std_percent, labels)
