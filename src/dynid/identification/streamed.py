"""The engine's fits on rows read in blocks (:mod:`dynid.identification.streaming`).

:class:`BlockRows` gives :func:`~dynid.identification.engine.fit_rows` the fits of the
weighted rows from the triangular factors of the noise groups: the column-scaled Householder
QR with column pivoting of a factor (the rank guard and statistics of
:func:`~dynid.identification.least_squares.fit_least_squares`), the heteroscedasticity-
consistent covariance from one more pass.
"""

from __future__ import annotations

import dataclasses
from collections.abc import Callable
from dataclasses import dataclass

import numpy as np
from numpy.typing import NDArray

from ..exceptions import DataError, NonFiniteError, RankDeficientError
from .engine import fit_rows
from .estimators import Estimator, Weights
from .least_squares import LeastSquaresFit, StdMethod, assembled, hac_covariance
from .serial import Serial, SerialMeat
from .solvers import (
    _conditioning,
    column_scale,
    pivoted_rank,
    unexcited_columns,
    unexcited_combinations,
)
from .streaming import (
    BlockSource,
    GroupFactors,
    _blocks,
    _triangular,
    _weighted_factor,
    group_factors,
)

__all__ = ["BlockRows", "fit_streamed"]


@dataclass(frozen=True, slots=True)
class _Solved:
    """A fit on a triangular factor, over the kept columns."""

    rank: int
    cond: float
    cond_u: float
    vmin: NDArray[np.float64]
    beta: NDArray[np.float64]
    ss: float
    gi: NDArray[np.float64]  # (R^T R)^-1 of the column-scaled kept columns
    scale: NDArray[np.float64]


def _solve(
    Raug: NDArray[np.float64],
    m: int,
    keep: NDArray[np.bool_],
    rtol: float,
    labels: tuple[str, ...] | None,
) -> _Solved:
    """The least-squares fit of the kept columns from the factor ``Raug`` of ``[W y]``."""
    import scipy.linalg  # scipy on first use (start-up time)

    c = Raug.shape[1] - 1
    idx = np.flatnonzero(keep)
    rk = idx.size
    T = Raug[:, np.append(idx, c)]
    if rk < c:
        T = _triangular(np.array(T))
    A, b, rres = T[:rk, :rk], T[:rk, rk], float(T[rk, rk])
    scale = column_scale(A)
    Q, R, piv = scipy.linalg.qr(A / scale, mode="economic", pivoting=True)
    rank = pivoted_rank(R, rtol)
    cond, cond_u, vp = _conditioning(R, scale[piv])
    vmin = np.empty(rk)
    vmin[piv] = vp
    if m < rk or rank < rk:
        names = _names(labels, vmin, idx)
        combos: tuple[str, ...] = ()
        redundant: tuple[str, ...] = ()
        if rank < rk and m >= rk:
            kl = tuple(labels[k] if labels is not None else f"column {k}" for k in idx)
            combos = unexcited_combinations(R[:, np.argsort(piv)], scale, rank, kl)
            cols = unexcited_columns(R[:, np.argsort(piv)], scale, rank)
            redundant = tuple(kl[i] for i in cols) if labels is not None else ()
        why = (
            f"{m} rows for {rk} coefficients; add configurations"
            if m < rk
            else (
                f"at rtol={rtol:g} (scaled cond {cond:.3g}); add configurations or excite the "
                "trajectory more, or drop unidentifiable parameters"
            )
        )
        raise RankDeficientError(
            f"Regressor rank {rank} < {rk} {why}; nearly dependent columns: "
            f"{', '.join(names) or 'none named'}"
            + (f"; not excited by the data: {'; '.join(combos)}" if combos else ""),
            rank=rank,
            needed=rk,
            dependent=names,
            combinations=combos,
            redundant=redundant,
        )
    z = scipy.linalg.solve_triangular(R, Q.T @ b)
    bs = np.empty(rk)
    bs[piv] = z
    beta = bs / scale
    r = A @ beta - b
    Rinv = scipy.linalg.solve_triangular(R, np.eye(rk))
    gi = np.empty((rk, rk))
    gi[np.ix_(piv, piv)] = Rinv @ Rinv.T
    ss = float(r @ r) + rres * rres
    return _Solved(rank, cond, cond_u, vmin, beta, ss, gi, scale)


def _names(
    labels: tuple[str, ...] | None, v: NDArray[np.float64], idx: NDArray[np.intp]
) -> tuple[str, ...]:
    """The kept columns with large weight in ``v``, named (largest first, at most 8)."""
    a = np.abs(v)
    if not a.size or not a.max() > 0:
        return ()
    big = np.flatnonzero(a >= 0.1 * a.max())
    cols = idx[big[np.argsort(-a[big])][:8]]
    return tuple(labels[k] if labels is not None else f"column {k}" for k in cols)


def _meat(
    source: BlockSource,
    beta: NDArray[np.float64],
    keep: NDArray[np.bool_],
    weights: Callable[[int, NDArray[np.intp]], NDArray[np.float64]] | None,
    serial: Serial | None = None,
) -> NDArray[np.float64]:
    """``Ww^T diag(ew^2) Ww`` over the kept columns, ``Ww`` the weighted rows and ``ew``
    the weighted residual of ``beta`` (one pass; HC1's middle factor), or with ``serial``
    the HAC one (:class:`~dynid.identification.serial.SerialMeat`, the last scores of a
    piece carried from block to block)."""
    rk = int(keep.sum())
    meat = np.zeros((rk, rk))
    acc = None if serial is None else SerialMeat(serial, rk)
    o = 0
    for W, y, g in _blocks(source):
        Wk = W[:, keep]
        e = y - Wk @ beta
        if weights is not None:
            w = weights(o, g)
            Wk, e = Wk * w[:, None], e * w
        if acc is None:
            We = Wk * e[:, None]
            meat += We.T @ We
        else:
            acc.add_products(Wk, e)
        o += y.size
    return meat if acc is None else acc.result()


def _fit_factor(
    Raug: NDArray[np.float64],
    m: int,
    *,
    keep: NDArray[np.bool_],
    rtol: float,
    std: StdMethod,
    labels: tuple[str, ...] | None,
    meat: Callable[[NDArray[np.float64], NDArray[np.bool_]], NDArray[np.float64]],
) -> LeastSquaresFit:
    """:func:`~dynid.identification.least_squares.fit_least_squares` from the factor of
    ``[W y]`` (m rows); ``meat(beta, keep)`` gives HC1's middle factor by a pass."""
    c = Raug.shape[1] - 1
    s = _solve(Raug, m, keep, rtol, labels)
    rk = s.beta.size
    dof = max(m - rk, 1)
    if std == "classical":
        cov_s = s.gi * (s.ss / dof)
    else:  # HC1 or HAC: the middle factor ``meat`` gives
        cov_s = hac_covariance(s.gi, meat(s.beta, keep), s.scale, m)
    if not (np.all(np.isfinite(s.beta)) and np.all(np.isfinite(cov_s)) and np.isfinite(s.ss)):
        raise NonFiniteError(
            "least squares overflowed: the data or the regressor hold values too large to be "
            "measurements; check the data"
        )
    ny = float(np.linalg.norm(Raug[:, c]))
    return assembled(
        keep, s.beta, cov_s, s.scale, s.ss, ny, m, s.rank, s.cond, s.cond_u, s.vmin, rtol
    )


def _fit_pruned(
    Raug: NDArray[np.float64],
    m: int,
    *,
    rtol: float,
    std: StdMethod,
    max_std_percent: float | None,
    labels: tuple[str, ...] | None,
    meat: Callable[[NDArray[np.float64], NDArray[np.bool_]], NDArray[np.float64]],
) -> LeastSquaresFit:
    """Fit, then (``max_std_percent``) remove the coefficients above it and re-fit once."""
    keep = np.ones(Raug.shape[1] - 1, dtype=bool)
    kw = {"rtol": rtol, "std": std, "labels": labels, "meat": meat}
    fit = _fit_factor(Raug, m, keep=keep, **kw)  # type: ignore[arg-type]
    if max_std_percent is None:
        return fit
    keep = ~(np.asarray(fit.std_percent) > max_std_percent)
    if keep.all():
        return fit
    return _fit_factor(Raug, m, keep=keep, **kw)  # type: ignore[arg-type]


def _unweighted(fit: LeastSquaresFit, F: GroupFactors) -> LeastSquaresFit:
    """The fit with the residual statistics of the unweighted rows (as every estimator)."""
    ss = float(F.residual_ss(np.asarray(fit.beta)).sum())
    ny = float(np.sqrt(F.target_ss().sum()))
    return dataclasses.replace(
        fit,
        relative_error_percent=100.0 * np.sqrt(ss) / ny if ny > 0 else 0.0,
        residual_rms=float(np.sqrt(ss / max(F.n_rows, 1))),
    )


class BlockRows:
    """Rows read in blocks from a :data:`BlockSource`, for the least-squares engine
    (:class:`~dynid.identification.engine.Rows`; module docstring).

    The first fit reads the blocks once into the triangular factors of every noise group
    (``by_group``) or of all rows; the group-weighted fits and the groups' residuals come
    from the factors, per-row weights and residuals take a pass each.

    Parameters
    ----------
    source : BlockSource
    by_group : bool
        Keep a factor per noise group (an estimator that weighs); False keeps one.
    per_row : bool
        Keep the group of every row (an estimator that weighs rows one by one).
    labels : ndarray of int, shape (m,), optional
        Labels of the rows whose unweighted normal equations the first pass gathers too
        (``factors.normals``: the folds of a held-out judgement, no pass of their own).
    serial : Serial, optional
        The samples and pieces of the rows (``std="hac"``; default: rows independent).
    """

    #: A pass computes the rows again.
    cheap = False

    def __init__(
        self,
        source: BlockSource,
        *,
        by_group: bool,
        per_row: bool,
        labels: NDArray[np.intp] | None = None,
        serial: Serial | None = None,
    ) -> None:
        self.source = source
        self.serial = serial
        self._by_group = by_group
        self._per_row = per_row
        self._labels = labels
        self._factors: GroupFactors | None = None

    @property
    def factors(self) -> GroupFactors:
        """The groups' factors (one pass over the blocks, the first time)."""
        if self._factors is None:
            self._factors = group_factors(
                self.source,
                keep_groups=self._per_row,
                by_group=self._by_group,
                labels=self._labels,
            )
        return self._factors

    @property
    def n_columns(self) -> int:
        """Columns c of the regressor."""
        return self.factors.n_columns

    def fit(
        self,
        weights: Weights | None,
        *,
        rtol: float,
        std: StdMethod,
        max_std_percent: float | None,
        labels: tuple[str, ...] | None,
    ) -> LeastSquaresFit:
        """The fit of the weighted rows, unweighted residual statistics (the engine's)."""
        F = self.factors
        kw = {"rtol": rtol, "std": std, "max_std_percent": max_std_percent, "labels": labels}
        ser = (self.serial or Serial()) if std == "hac" else None
        if weights is None:
            meat = lambda b, k: _meat(self.source, b, k, None, ser)  # noqa: E731
            return _fit_pruned(F.combined(), F.n_rows, meat=meat, **kw)  # type: ignore[arg-type]
        w = weights
        if w.group is not None:
            factor = F.combined(w.group)
        else:
            factor = _weighted_factor(self.source, lambda o, g: w.of_rows(g, o), F.n_columns)
        meat = lambda b, k: _meat(self.source, b, k, lambda o, g: w.of_rows(g, o), ser)  # noqa: E731
        fit = _fit_pruned(factor, F.n_rows, meat=meat, **kw)  # type: ignore[arg-type]
        return _unweighted(fit, F)

    def residuals(
        self, beta: NDArray[np.float64], per_row: bool
    ) -> tuple[
        NDArray[np.float64],
        NDArray[np.intp],
        NDArray[np.float64] | None,
        NDArray[np.intp] | None,
    ]:
        """The groups' residual sums of squares (from the factors), and every row's residual
        when ``per_row`` (one pass)."""
        F = self.factors
        if not per_row:
            return F.residual_ss(beta), F.rows, None, None
        assert F.groups is not None, "BlockRows(per_row=True) keeps the groups"
        m = F.n_rows
        e = np.empty(m)
        o = 0
        for W, y, _g in _blocks(self.source):
            if o + y.size > m:
                break
            np.subtract(y, W @ beta, out=e[o : o + y.size])
            o += y.size
        if o != m:
            raise DataError(f"the regressor blocks changed between passes ({m} rows, then {o})")
        k = F.rows.size
        squares = np.asarray(np.bincount(F.groups, e * e, minlength=k)[:k], dtype=np.float64)
        return squares, F.rows, e, F.groups


def fit_streamed(
    source: BlockSource,
    estimator: Estimator,
    *,
    rtol: float,
    std: StdMethod = "classical",
    max_std_percent: float | None = None,
    labels: tuple[str, ...] | None = None,
    serial: Serial | None = None,
) -> LeastSquaresFit:
    """Fit ``W beta = y`` with an estimator over the blocks of ``source``: the engine
    (:func:`~dynid.identification.engine.fit_rows`) on :class:`BlockRows` (``serial``: the
    rows' time structure, for ``std="hac"``).

    The estimates and statistics are those of the same estimator on the rows stacked, to
    rounding.

    Raises
    ------
    OptionError
        An unknown ``std``.
    ShapeError
        Inconsistent blocks.
    NonFiniteError
        NaN or inf in a block.
    RankDeficientError
        Rank below the column count.
    """
    rows = BlockRows(source, by_group=estimator.weighted, per_row=estimator.per_row, serial=serial)
    return fit_rows(
        rows, estimator, rtol=rtol, std=std, max_std_percent=max_std_percent, labels=labels
    )
