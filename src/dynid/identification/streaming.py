"""Least squares over blocks of rows: the stacked regressor is never held whole.

A long torque log stacks a regressor of millions of rows (5 million samples at 1 kHz,
decimated by 20, of a 7-joint arm: 1.75 million rows of 65 columns, 0.9 GB, and the
estimators' weighted copies on top). Here the rows come in blocks from a *block source*,
a callable that returns a fresh iterable of ``(W_b, y_b, groups_b)`` (rows of the
regressor, their targets, their noise groups) each time it is called, always in the same
order; only small triangular factors are kept between blocks.

**Factors by groups (one pass).** For every noise group ``g`` (a joint of a torque log,
a row of ``[tril M; g]`` of static data) the triangular factor ``R_g`` (c+1, c+1) of
``[W_g y_g]`` is updated block by block, ``R_g <- qr([R_g; W_gb y_gb])`` (a tall-skinny
QR, TSQR; Demmel et al. 2012): the same factor as the QR of the whole stack, better
conditioned than the normal equations ``W^T W`` (whose condition number is the square).
From these factors alone:

* the factor of all rows is the QR of ``[R_1; R_2; ...]`` and that of the rows weighted
  by ``w_g`` per group the QR of ``[w_1 R_1; w_2 R_2; ...]`` (exact: ``diag(w) [W y] =
  diag(w) Q R``);
* the residual of any estimate in group ``g`` has norm ``||R_g [beta; -1]||`` (WLS's
  per-group noise, the unweighted residual of a weighted fit);
* the factor of a subset of the columns is the QR of those columns of ``R`` (pruning).

The fit on a factor is the one of :func:`~dynid.identification.least_squares.fit_least_squares`
(column-scaled Householder QR with column pivoting, its rank guard and statistics); the
estimates and standard deviations agree with the stacked fit to about 1e-12 relative.

**Passes over the data.** OLS and WLS with classical standard deviations take one pass;
the heteroscedasticity-consistent covariance (``"robust"``) needs ``W^T diag(e^2) W`` of
the final residual: one pass more (two with pruning). Huber IRLS reweights every row from
the median of its group's residuals: two passes per iteration (the weighted factor, then
the residuals), holding the residuals, weights and groups of every row (24 bytes a row,
not ``8 c``).
"""

from __future__ import annotations

import dataclasses
import os
from collections.abc import Callable, Iterable
from dataclasses import dataclass

import numpy as np
import scipy.linalg
from numpy.typing import NDArray

from .. import _checks
from ..exceptions import DataError, NonFiniteError, OptionError, RankDeficientError, ShapeError
from .engine import fit_rows
from .estimators import Estimator, Weights
from .holdout import Normals
from .least_squares import (
    LeastSquaresFit,
    StdMethod,
    _conditioning,
    assembled,
    unexcited_combinations,
)

__all__ = [
    "BLOCK_ROWS",
    "Block",
    "BlockSource",
    "GROUP_FACTOR_BYTES",
    "GroupFactors",
    "MAX_STACK_BYTES",
    "fit_streamed",
    "group_factors",
    "max_stack_bytes",
    "normals_by_label",
    "streams",
]

#: A source of row blocks: called once per pass, it returns ``(W_b (m_b, c), y_b (m_b,),
#: groups_b (m_b,) int)`` triples in the same order every time.
Block = tuple[NDArray[np.float64], NDArray[np.float64], NDArray[np.intp]]
BlockSource = Callable[[], Iterable[Block]]

#: Rows per block a source should aim at (about 17 MB of a 65-column regressor).
BLOCK_ROWS = 32_768

#: Largest stacked regressor [bytes] a route holds whole before it streams its rows
#: (``DYNID_MAX_STACK_BYTES`` overrides): below it the stacked fit is the faster one.
MAX_STACK_BYTES = 256 << 20

_ENV = "DYNID_MAX_STACK_BYTES"


def max_stack_bytes() -> int:
    """The largest stacked regressor [bytes] held whole: ``DYNID_MAX_STACK_BYTES`` when
    set (an integer number of bytes), else :data:`MAX_STACK_BYTES`.

    Raises
    ------
    OptionError
        ``DYNID_MAX_STACK_BYTES`` is not a non-negative integer.
    """
    text = os.environ.get(_ENV)
    if text is None or not text.strip():
        return MAX_STACK_BYTES
    try:
        value = int(text.strip())
    except ValueError:
        value = -1
    if value < 0:
        raise OptionError(f"{_ENV} must be a non-negative number of bytes; got {text!r}")
    return value


def streams(n_rows: int, n_columns: int) -> bool:
    """True when a regressor of ``n_rows`` x ``n_columns`` float64 exceeds
    :func:`max_stack_bytes` (the route then fits with :func:`fit_streamed`)."""
    return 8 * int(n_rows) * (int(n_columns) + 1) > max_stack_bytes()


#: Largest memory [bytes] of the factors of every noise group. Above it (static data of
#: a 50-joint arm: 1325 groups, the rows of ``[tril M; g]``, of 345 columns: 1.3 GB) one
#: factor of all rows is kept, with each group's row count and ``||y_g||^2``; what needs a
#: group's residual (WLS's noise levels, a weighted factor) takes a pass over the blocks.
GROUP_FACTOR_BYTES = 64 << 20


@dataclass(frozen=True, slots=True, eq=False)
class GroupFactors:
    """Triangular factors of ``[W_g y_g]`` per noise group (module docstring).

    Attributes
    ----------
    R : ndarray, shape (k, c + 1, c + 1), or None
        Upper triangular factor of each group's rows (zero for a group without rows);
        None when they would exceed :data:`GROUP_FACTOR_BYTES` (then ``total``).
    rows : ndarray of int, shape (k,)
        Rows of each group.
    groups : ndarray of int, shape (m,) or None
        The group of every row in block order (kept for IRLS only).
    total : ndarray, shape (c + 1, c + 1), or None
        The factor of all rows, when ``R`` is None.
    target : ndarray, shape (k,), or None
        ``||y_g||^2`` of each group, when ``R`` is None.
    source : BlockSource or None
        The blocks again, for the passes that replace ``R`` when it is None.
    """

    R: NDArray[np.float64] | None
    rows: NDArray[np.intp]
    groups: NDArray[np.intp] | None = None
    total: NDArray[np.float64] | None = None
    target: NDArray[np.float64] | None = None
    source: BlockSource | None = None

    @property
    def n_rows(self) -> int:
        """Rows over all groups."""
        return int(self.rows.sum())

    @property
    def n_columns(self) -> int:
        """Columns c of the regressor."""
        F = self.R if self.R is not None else self.total
        assert F is not None
        return int(F.shape[-1]) - 1

    def combined(self, w: NDArray[np.float64] | None = None) -> NDArray[np.float64]:
        """The factor (c+1, c+1) of all rows, each group's rows times ``w[g]`` (default 1)."""
        if self.R is None:
            assert self.total is not None and self.source is not None
            if w is None:
                return self.total
            wg = w
            return _weighted_factor(self.source, lambda o, g: wg[g], self.n_columns)
        R = self.R if w is None else self.R * w[:, None, None]
        return _triangular(R.reshape(-1, R.shape[-1]))

    def residual_ss(self, beta: NDArray[np.float64]) -> NDArray[np.float64]:
        """``||y_g - W_g beta||^2`` of each group (k,)."""
        if self.R is None:
            assert self.source is not None
            ss = np.zeros(self.rows.size)
            for W, y, g in _blocks(self.source):
                e = y - W @ beta
                ss += np.bincount(g, e * e, minlength=ss.size)[: ss.size]
            return ss
        v = np.append(beta, -1.0)
        r = self.R @ v
        return np.einsum("kj,kj->k", r, r)

    def target_ss(self) -> NDArray[np.float64]:
        """``||y_g||^2`` of each group (k,)."""
        if self.R is None:
            assert self.target is not None
            return self.target
        return np.einsum("kj,kj->k", self.R[:, :, -1], self.R[:, :, -1])


def _on_top(R: NDArray[np.float64], X: NDArray[np.float64]) -> NDArray[np.float64]:
    """``[R; X]`` in column-major order (as LAPACK takes it, no further copy)."""
    out = np.empty((R.shape[0] + X.shape[0], X.shape[1]), order="F")
    out[: R.shape[0]] = R
    out[R.shape[0] :] = X
    return out


def _triangular(X: NDArray[np.float64]) -> NDArray[np.float64]:
    """The upper triangular factor (c+1, c+1) of ``X`` (M, c+1), M >= c+1, zero-padded."""
    k = X.shape[1]
    R = scipy.linalg.qr(X, mode="r", overwrite_a=True, check_finite=False)[0][:k]
    if R.shape[0] < k:
        R = np.vstack([R, np.zeros((k - R.shape[0], k))])
    return R


def _blocks(source: BlockSource) -> Iterable[Block]:
    """The source's blocks checked: shapes, finite values, integer groups."""
    c = None
    for W, y, g in source():
        W = np.asarray(W, dtype=np.float64)
        y = np.asarray(y, dtype=np.float64)
        g = np.asarray(g, dtype=np.intp)
        if W.ndim != 2 or y.shape != (W.shape[0],) or g.shape != y.shape:
            raise ShapeError(
                f"a regressor block must be W (m, c), y (m,), groups (m,); got {W.shape}, "
                f"{y.shape}, {g.shape}"
            )
        if c is not None and W.shape[1] != c:
            raise ShapeError(f"regressor blocks must all have {c} columns; got {W.shape[1]}")
        c = W.shape[1]
        if g.size and g.min() < 0:
            raise ShapeError("noise groups must be non-negative integers")
        _checks.finite("regressor", W)
        _checks.finite("y", y)
        yield W, y, g


def group_factors(
    source: BlockSource, *, keep_groups: bool = False, by_group: bool = True
) -> GroupFactors:
    """One pass over the blocks: the triangular factor of ``[W_g y_g]`` of every group (or,
    past :data:`GROUP_FACTOR_BYTES`, of all rows with the groups' counts and targets).

    Parameters
    ----------
    source : BlockSource
    keep_groups : bool
        Also return the group of every row (IRLS).
    by_group : bool
        A factor per group; False keeps the factor of all rows only (an estimator that
        does not weigh).

    Raises
    ------
    ShapeError
        Blocks of inconsistent shapes, negative groups, or no rows at all.
    NonFiniteError
        NaN or inf in a block.
    """
    R: dict[int, NDArray[np.float64]] = {}
    rows: dict[int, int] = {}
    seen: list[NDArray[np.intp]] = []
    total: NDArray[np.float64] | None = None
    count, target = np.zeros(0, dtype=np.intp), np.zeros(0)
    c = 0
    for W, y, g in _blocks(source):
        c = W.shape[1]
        X = np.empty((W.shape[0], c + 1), order="F")
        X[:, :c] = W
        X[:, c] = y
        k = max(count.size, int(g.max(initial=-1)) + 1)
        count = np.bincount(g, minlength=k) + np.pad(count, (0, k - count.size))
        squares = np.asarray(np.bincount(g, y * y, minlength=k), dtype=np.float64)
        target = squares + np.pad(target, (0, k - target.size))
        if total is None and not by_group:
            total = np.zeros((c + 1, c + 1))
        if total is None and 8 * k * (c + 1) ** 2 > GROUP_FACTOR_BYTES:  # too many groups
            total = _triangular(np.vstack([np.zeros((c + 1, c + 1)), *R.values()]))
            R.clear()
        if total is not None:
            total = _triangular(_on_top(total, X))
        else:
            for gv in np.unique(g):
                sel = X[g == gv]
                prev = R.get(int(gv))
                R[int(gv)] = _triangular(sel if prev is None else np.vstack([prev, sel]))
                rows[int(gv)] = rows.get(int(gv), 0) + sel.shape[0]
        del X
        if keep_groups:
            seen.append(g.copy())
    if not R and total is None:
        raise ShapeError("no regressor rows: the data hold no block")
    groups = np.concatenate(seen) if keep_groups else None
    if total is not None:
        return GroupFactors(None, count, groups, total=total, target=target, source=source)
    k = max(R) + 1
    out = np.zeros((k, c + 1, c + 1))
    cnt = np.zeros(k, dtype=np.intp)
    for gv, Rg in R.items():
        out[gv], cnt[gv] = Rg, rows[gv]
    return GroupFactors(R=out, rows=cnt, groups=groups)


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
    c = Raug.shape[1] - 1
    idx = np.flatnonzero(keep)
    rk = idx.size
    T = Raug[:, np.append(idx, c)]
    if rk < c:
        T = _triangular(np.array(T))
    A, b, rres = T[:rk, :rk], T[:rk, rk], float(T[rk, rk])
    norms = np.sqrt(np.einsum("ij,ij->j", A, A))
    scale = np.where(norms > 0, norms, 1.0)
    Q, R, piv = scipy.linalg.qr(A / scale, mode="economic", pivoting=True)
    d = np.abs(np.diag(R))
    rank = int(np.sum(d > rtol * d[0])) if d.size and d[0] > 0 else 0
    cond, cond_u, vp = _conditioning(R, scale[piv])
    vmin = np.empty(rk)
    vmin[piv] = vp
    if m < rk or rank < rk:
        names = _names(labels, vmin, idx)
        combos: tuple[str, ...] = ()
        if rank < rk and m >= rk:
            kl = tuple(labels[k] if labels is not None else f"column {k}" for k in idx)
            combos = unexcited_combinations(R[:, np.argsort(piv)], scale, rank, kl)
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
) -> NDArray[np.float64]:
    """``Ww^T diag(ew^2) Ww`` over the kept columns, ``Ww`` the weighted rows and ``ew``
    the weighted residual of ``beta`` (one pass; HC1's middle factor)."""
    rk = int(keep.sum())
    meat = np.zeros((rk, rk))
    o = 0
    for W, y, g in _blocks(source):
        Wk = W[:, keep]
        e = y - Wk @ beta
        if weights is not None:
            w = weights(o, g)
            Wk, e = Wk * w[:, None], e * w
        We = Wk * e[:, None]
        meat += We.T @ We
        o += y.size
    return meat


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
    else:
        mt = meat(s.beta, keep) / np.outer(s.scale, s.scale)
        cov_s = s.gi @ mt @ s.gi * (m / dof)
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
    """

    def __init__(self, source: BlockSource, *, by_group: bool, per_row: bool) -> None:
        self.source = source
        self._by_group = by_group
        self._per_row = per_row
        self._factors: GroupFactors | None = None

    @property
    def factors(self) -> GroupFactors:
        """The groups' factors (one pass over the blocks, the first time)."""
        if self._factors is None:
            self._factors = group_factors(
                self.source, keep_groups=self._per_row, by_group=self._by_group
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
        if weights is None:
            meat = lambda b, k: _meat(self.source, b, k, None)  # noqa: E731
            return _fit_pruned(F.combined(), F.n_rows, meat=meat, **kw)  # type: ignore[arg-type]
        w = weights
        if w.group is not None:
            factor = F.combined(w.group)
        else:
            factor = _weighted_factor(self.source, lambda o, g: w.of_rows(g, o), F.n_columns)
        meat = lambda b, k: _meat(self.source, b, k, lambda o, g: w.of_rows(g, o))  # noqa: E731
        fit = _fit_pruned(factor, F.n_rows, meat=meat, **kw)  # type: ignore[arg-type]
        return _unweighted(fit, F)

    def residuals(self, beta: NDArray[np.float64], per_row: bool) -> tuple[
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
) -> LeastSquaresFit:
    """Fit ``W beta = y`` with an estimator over the blocks of ``source``: the engine
    (:func:`~dynid.identification.engine.fit_rows`) on :class:`BlockRows`.

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
    rows = BlockRows(source, by_group=estimator.weighted, per_row=estimator.per_row)
    return fit_rows(
        rows, estimator, rtol=rtol, std=std, max_std_percent=max_std_percent, labels=labels
    )


def _weighted_factor(
    source: BlockSource,
    weights: Callable[[int, NDArray[np.intp]], NDArray[np.float64]],
    c: int,
) -> NDArray[np.float64]:
    """The factor (c+1, c+1) of ``diag(w) [W y]`` over every row (one pass);
    ``weights(o, g)`` gives the weights of a block's rows from its first row ``o`` and
    its groups ``g``."""
    R = np.zeros((c + 1, c + 1))
    o = 0
    for W, y, g in _blocks(source):
        X = np.empty((y.size, c + 1), order="F")
        wb = weights(o, g)
        np.multiply(W, wb[:, None], out=X[:, :c])
        np.multiply(y, wb, out=X[:, c])
        R = _triangular(_on_top(R, X))
        o += y.size
    return R


def normals_by_label(
    source: BlockSource,
    labels: NDArray[np.intp],
    weights: NDArray[np.float64] | None = None,
) -> tuple[Normals, ...]:
    """Normal equations (:class:`~dynid.identification.holdout.Normals`) of the rows of each
    label, one pass: ``labels`` (m,) gives the label ``0 .. k-1`` of every row in block
    order (the time block of a held-out judgement); ``weights`` (m,), when given, multiply
    the rows (and their targets) first.

    Raises
    ------
    ShapeError
        The blocks hold another number of rows than ``labels``.
    """
    k = int(labels.max()) + 1 if labels.size else 0
    G: NDArray[np.float64] | None = None
    b = np.zeros((k, 0))
    c = np.zeros(k)
    o = 0
    for W, y, _g in _blocks(source):
        if G is None:
            G, b = np.zeros((k, W.shape[1], W.shape[1])), np.zeros((k, W.shape[1]))
        lab = labels[o : o + y.size]
        if lab.size != y.size:
            raise ShapeError(f"labels hold {labels.size} rows; the blocks more")
        for j in np.unique(lab):
            sel = lab == j
            Wj, yj = W[sel], y[sel]
            if weights is not None:
                wj = weights[o : o + y.size][sel]
                Wj, yj = Wj * wj[:, None], yj * wj
            G[j] += Wj.T @ Wj
            b[j] += Wj.T @ yj
            c[j] += float(yj @ yj)
        o += y.size
    if o != labels.size or G is None:
        raise ShapeError(f"labels hold {labels.size} rows; the blocks {o}")
    cnt = np.bincount(labels, minlength=k)
    return tuple(Normals(G[j], b[j], float(c[j]), int(cnt[j])) for j in range(k))
