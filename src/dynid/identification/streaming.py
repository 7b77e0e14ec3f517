"""Least squares over blocks of rows: the stacked regressor is never held whole.

A long torque log stacks a regressor of millions of rows (5 million samples at 1 kHz,
decimated by 20, of a 7-joint arm: 1.75 million rows of 65 columns, 0.9 GB, and the
estimators' weighted copies on top). Here the rows come in blocks from a *block source*,
a callable that returns a fresh iterable of ``(W_b, y_b, groups_b)`` (rows of the
regressor, their targets, their noise groups) each time it is called, always in the same
order; only small triangular factors are kept between blocks.

**Factors by groups (one pass).** An estimator that weighs (WLS, IRLS) gets, for every
noise group ``g`` (a joint of a torque log,
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

An estimator that does not weigh (OLS) gets the factor of all rows only, each block put
under it in place (one ``dgeqrf`` a block), and, when given the folds of a held-out
judgement, the normal equations of each fold from the same pass.

The fit on a factor is the one of :func:`~dynid.identification.least_squares.fit_least_squares`
(column-scaled Householder QR with column pivoting, its rank guard and statistics); the
estimates and standard deviations agree with the stacked fit to about 1e-12 relative.

The engine (:func:`~dynid.identification.engine.fit_rows`) fits these rows through
:class:`~dynid.identification.streamed.BlockRows`, any estimator alike.

**Passes over the data.** OLS and WLS with classical standard deviations take one pass;
the heteroscedasticity-consistent covariance (``"robust"``) needs ``W^T diag(e^2) W`` of
the final residual: one pass more (two with pruning). Huber IRLS reweights every row from
the median of its group's residuals: two passes per iteration (the weighted factor, then
the residuals), holding the residuals, weights and groups of every row (24 bytes a row,
not ``8 c``); so does any estimator that weighs rows one by one (``per_row``).
"""

from __future__ import annotations

import os
from collections.abc import Callable, Iterable
from dataclasses import dataclass

import numpy as np
from numpy.typing import NDArray

from .. import _checks
from ..exceptions import OptionError, ShapeError
from ..progress import rows_read
from .holdout import Normals, rows_labelled

__all__ = [
    "BLOCK_ROWS",
    "Block",
    "BlockSource",
    "GROUP_FACTOR_BYTES",
    "GroupFactors",
    "MAX_STACK_BYTES",
    "group_factors",
    "max_stack_bytes",
    "normals_by_label",
    "normals_by_label_scaled",
    "streams",
]

#: A source of row blocks: called once per pass, it returns ``(W_b (m_b, c), y_b (m_b,),
#: groups_b (m_b,) int)`` triples in the same order every time.
Block = tuple[NDArray[np.float64], NDArray[np.float64], NDArray[np.intp]]
BlockSource = Callable[[], Iterable[Block]]

#: Rows per block a source should aim at (about 11 MB of the 170 columns of the structure
#: selection's largest model of a 7-joint arm; the kinematics and the QR's copy of a
#: block come on top, so that a long log's fit holds a few tens of MB beside its data:
#: ``identify`` of a 5-million-row log peaks at 1.46 GB with it, 1.50 GB with twice as
#: many rows, for 3 % less CPU).
BLOCK_ROWS = 8_192

#: Largest stacked regressor [bytes] a route holds whole before it streams its rows
#: (``DYNID_MAX_STACK_BYTES`` overrides): below it the stacked fit is the faster one
#: (``benchmarks/bench_streaming.py``: the same CPU at 109 MB, streamed 0.73 x stacked at
#: 255 MB).
MAX_STACK_BYTES = 128 << 20

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
    normals : tuple of Normals, optional
        The normal equations of the rows of each label, when :func:`group_factors` was
        given labels.
    """

    R: NDArray[np.float64] | None
    rows: NDArray[np.intp]
    groups: NDArray[np.intp] | None = None
    total: NDArray[np.float64] | None = None
    target: NDArray[np.float64] | None = None
    source: BlockSource | None = None
    normals: tuple[Normals, ...] | None = None

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
    import scipy.linalg  # scipy on first use (start-up time)

    k = X.shape[1]
    R = scipy.linalg.qr(X, mode="r", overwrite_a=True, check_finite=False)[0][:k]
    if R.shape[0] < k:
        R = np.vstack([R, np.zeros((k - R.shape[0], k))])
    return R


def _stacked_r(buf: NDArray[np.float64]) -> NDArray[np.float64]:
    """The upper triangular factor (k, k) of ``buf`` (M, k), M >= k, column-major,
    overwritten (LAPACK ``dgeqrf`` in place: no copy of the block)."""
    import scipy.linalg  # scipy on first use (start-up time)

    k = buf.shape[1]
    qr, _, _, info = scipy.linalg.lapack.dgeqrf(buf, overwrite_a=1)
    if info != 0:  # pragma: no cover - LAPACK argument error
        raise ShapeError(f"LAPACK dgeqrf failed with info={info}")
    return np.triu(qr[:k])


def _blocks(source: BlockSource) -> Iterable[Block]:
    """The source's blocks checked: shapes, finite values, integer groups."""
    c = None
    rows = 0
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
        rows += y.size
        rows_read(rows)
        yield W, y, g


def group_factors(
    source: BlockSource,
    *,
    keep_groups: bool = False,
    by_group: bool = True,
    labels: NDArray[np.intp] | None = None,
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
    labels : ndarray of int, shape (m,), optional
        A label ``0 .. k-1`` of every row in block order (the folds of a held-out
        judgement): the normal equations of each label's rows are gathered in the same pass
        (``normals``).

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
    c = o = 0
    L = int(labels.max()) + 1 if labels is not None and labels.size else 0
    LG: NDArray[np.float64] | None = None
    for W, y, g in _blocks(source):
        c = W.shape[1]
        buf = np.empty((c + 1 + W.shape[0], c + 1), order="F")  # [R; W y] for the QR below
        X = buf[c + 1 :]
        X[:, :c] = W
        X[:, c] = y
        if labels is not None:
            if LG is None:
                LG = np.zeros((L, c + 1, c + 1))
            _label_grams(LG, X, labels, o)
        o += y.size
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
            buf[: c + 1] = total
            total = _stacked_r(buf)
        else:
            for gv in np.unique(g):
                sel = X[g == gv]
                prev = R.get(int(gv))
                R[int(gv)] = _triangular(sel if prev is None else np.vstack([prev, sel]))
                rows[int(gv)] = rows.get(int(gv), 0) + sel.shape[0]
        del X, buf
        if keep_groups:
            seen.append(g.copy())
    if not R and total is None:
        raise ShapeError("no regressor rows: the data hold no block")
    groups = np.concatenate(seen) if keep_groups else None
    normals = None
    if labels is not None:
        if o != labels.size or LG is None:
            raise ShapeError(f"labels hold {labels.size} rows; the blocks {o}")
        cnt_l = np.bincount(labels, minlength=L)
        normals = tuple(
            Normals(LG[j, :c, :c], LG[j, :c, c], float(LG[j, c, c]), int(cnt_l[j]))
            for j in range(L)
        )
    if total is not None:
        return GroupFactors(
            None, count, groups, total=total, target=target, source=source, normals=normals
        )
    k = max(R) + 1
    out = np.zeros((k, c + 1, c + 1))
    cnt = np.zeros(k, dtype=np.intp)
    for gv, Rg in R.items():
        out[gv], cnt[gv] = Rg, rows[gv]
    return GroupFactors(R=out, rows=cnt, groups=groups, normals=normals)


def _label_grams(
    LG: NDArray[np.float64], X: NDArray[np.float64], labels: NDArray[np.intp], o: int
) -> None:
    """Add ``X_j^T X_j`` of the rows of each label to ``LG[j]``; ``X`` (m_b, c+1) holds the
    rows ``o .. o + m_b`` (labels in runs, as time folds: one product per run)."""
    lab = labels[o : o + X.shape[0]]
    if lab.size != X.shape[0]:
        raise ShapeError(f"labels hold {labels.size} rows; the blocks more")
    cuts = np.concatenate([[0], np.flatnonzero(np.diff(lab)) + 1, [lab.size]])
    for a, b in zip(cuts[:-1], cuts[1:], strict=True):
        if b > a:
            Xr = X[a:b]
            LG[lab[a]] += Xr.T @ Xr


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
    return normals_by_label_scaled(source, labels, weights)[0]


def _sample_major(g: NDArray[np.intp]) -> int:
    """``n`` when the rows' noise groups ``g`` are ``0 .. n-1`` repeated sample by sample
    (a torque log's rows: row ``k n + j`` is joint ``j``), else 0."""
    if g.size == 0 or g[0] != 0:
        return 0
    n = int(g.max()) + 1
    if g.size % n or not (g.reshape(-1, n) == np.arange(n)).all():
        return 0
    return n


_Sums = tuple[NDArray[np.float64], NDArray[np.float64], float, float]


def _group_normals(
    W: NDArray[np.float64],
    y: NDArray[np.float64],
    n: int,
    scale: NDArray[np.float64],
    origin: NDArray[np.float64] | None,
) -> tuple[_Sums, _Sums]:
    """``(W^T W, W^T y, y^T y, |y - W origin|^2)`` of the sample-major rows ``W`` (m, p),
    ``y`` (m,) of ``n`` noise groups, plain and with each group's rows times ``scale``
    (n,): both sums of the groups' own, each group's Gram computed once (the rows of group
    ``q`` are every ``n``-th from ``q``, read in place) rather than one Gram of the rows
    and another of a scaled copy: half the flops, no copy. The residual's sum is 0 without
    ``origin``."""
    p = W.shape[1]
    G0, G1 = np.zeros((p, p)), np.zeros((p, p))
    b0, b1 = np.zeros(p), np.zeros(p)
    c0 = c1 = e0 = e1 = 0.0
    r = None if origin is None else y - W @ origin
    for q in range(n):
        Wq, yq = W[q::n], y[q::n]
        s2 = float(scale[q]) ** 2
        Gq, bq, cq = Wq.T @ Wq, Wq.T @ yq, float(yq @ yq)
        G0 += Gq
        G1 += s2 * Gq
        b0 += bq
        b1 += s2 * bq
        c0, c1 = c0 + cq, c1 + s2 * cq
        if r is not None:
            eq = float(r[q::n] @ r[q::n])
            e0, e1 = e0 + eq, e1 + s2 * eq
    return (G0, b0, c0, e0), (G1, b1, c1, e1)


def normals_by_label_scaled(
    source: BlockSource,
    labels: NDArray[np.intp],
    weights: NDArray[np.float64] | None = None,
    group_scale: NDArray[np.float64] | None = None,
    origin: NDArray[np.float64] | None = None,
) -> tuple[tuple[Normals, ...], tuple[Normals, ...]]:
    """:func:`normals_by_label` of the rows times ``weights``, and in the same pass those
    of the rows times ``group_scale[group]`` (each row's noise group: a joint) alone (empty
    without ``group_scale``). ``origin`` (p,): the fit's coefficients, whose residual on
    the rows each set's normal equations keep (:attr:`~.holdout.Normals.origin`), so that
    an error far below the torques' norm is resolved.

    Raises
    ------
    ShapeError
        The blocks hold another number of rows than ``labels``.
    """
    k = int(labels.max()) + 1 if labels.size else 0
    sets = 1 if group_scale is None else 2
    G: list[NDArray[np.float64]] = []
    b: list[NDArray[np.float64]] = []
    c = np.zeros((sets, k))
    e0 = np.zeros((sets, k))
    o = 0
    for W, y, g in _blocks(source):
        if not G:
            G = [np.zeros((k, W.shape[1], W.shape[1])) for _ in range(sets)]
            b = [np.zeros((k, W.shape[1])) for _ in range(sets)]
        lab = labels[o : o + y.size]
        if lab.size != y.size:
            raise ShapeError(f"labels hold {labels.size} rows; the blocks more")
        for j in np.unique(lab):
            whole = W.flags.c_contiguous and y.flags.c_contiguous  # a view is alike a copy
            sel = rows_labelled(lab, j) if whole else lab == j
            Ws, ys = W[sel], y[sel]
            n = _sample_major(np.asarray(g)[sel]) if sets == 2 and weights is None else 0
            if n:  # plain and scaled sets from one Gram per noise group
                assert group_scale is not None
                parts = _group_normals(Ws, ys, n, group_scale[:n], origin)
                for s_, (Gs, bs, cs, es) in enumerate(parts):
                    G[s_][j] += Gs
                    b[s_][j] += bs
                    c[s_, j] += cs
                    e0[s_, j] += es
                continue
            for s_ in range(sets):
                Wj, yj = Ws, ys
                if s_ == 0 and weights is not None:
                    wj = weights[o : o + y.size][sel]
                elif s_ == 1:
                    assert group_scale is not None
                    wj = group_scale[np.asarray(g)[sel]]
                else:
                    wj = None
                if wj is not None:
                    Wj, yj = Wj * wj[:, None], yj * wj
                G[s_][j] += Wj.T @ Wj
                b[s_][j] += Wj.T @ yj
                c[s_, j] += float(yj @ yj)
                if origin is not None:
                    r = yj - Wj @ origin
                    e0[s_, j] += float(r @ r)
        o += y.size
    if o != labels.size or not G:
        raise ShapeError(f"labels hold {labels.size} rows; the blocks {o}")
    cnt = np.bincount(labels, minlength=k)
    out = [
        tuple(
            Normals(G[s_][j], b[s_][j], float(c[s_, j]), int(cnt[j]), origin, float(e0[s_, j]))
            for j in range(k)
        )
        for s_ in range(sets)
    ]
    return out[0], (out[1] if sets == 2 else ())
