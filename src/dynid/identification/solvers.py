"""The solvers of the least-squares engine on rows held in memory, column scaled.

Corrected semi-normal equations over the row blocks (Björck 1987) for a tall, well
conditioned regressor, Householder QR with column pivoting otherwise; the accuracy
argument and the rank guard are in ``docs/least-squares.md``
(:mod:`dynid.identification.least_squares` assembles their statistics). Also the naming of
what a rank-deficient regressor leaves unexcited.
"""

from __future__ import annotations

from typing import Literal, get_args

import numpy as np
from numpy.typing import NDArray

from .. import _checks
from ..exceptions import OptionError, RankDeficientError

__all__ = [
    "STD_METHODS",
    "StdMethod",
    "block_grams",
    "checked_std",
    "column_scale",
    "pivoted_rank",
    "scaled_lstsq",
    "tall_pivoted_qr",
    "tall_r",
    "unexcited_columns",
    "unexcited_combinations",
]

#: How the standard deviations are estimated (``std=``, ``--std``): ``"classical"``
#: ``sigma^2 (W^T W)^{-1}`` (Gaz et al. 2019), ``"robust"``, heteroscedasticity-consistent
#: (White 1980, HC1), or ``"hac"``, heteroskedasticity-and-autocorrelation-consistent over
#: the samples of each piece of a recording (Newey and West 1987,
#: :mod:`dynid.identification.serial`; HC1 for rows without a time structure).
StdMethod = Literal["classical", "robust", "hac"]

#: The values of :data:`StdMethod` (the choices of ``--std``).
STD_METHODS: tuple[StdMethod, ...] = get_args(StdMethod)


def checked_std(std: str) -> StdMethod:
    """``std`` as a :data:`StdMethod`.

    Raises
    ------
    OptionError
        ``std`` not one of :data:`STD_METHODS`.
    """
    if std not in STD_METHODS:
        choices = " or ".join(repr(s) for s in STD_METHODS)
        raise OptionError(f"std must be {choices} (--std); got {std!r}")
    return std


def column_scale(A: NDArray[np.float64]) -> NDArray[np.float64]:
    """The Euclidean norm of each column of ``A`` (m, k), 1 for a zero column: the scaling
    that makes every rank reading of this project the same in any unit or gear ratio
    (``A / column_scale(A)`` has unit columns; coefficients come back divided by it)."""
    norms = np.sqrt(np.einsum("ij,ij->j", A, A))
    return np.where(norms > 0, norms, 1.0)


def pivoted_rank(R: NDArray[np.float64], rtol: float) -> int:
    """The numerical rank of a column-pivoted triangular factor ``R`` (of a column-scaled
    matrix): its diagonal entries above ``rtol`` times the first (0 when that is 0)."""
    d = np.abs(np.diag(R))
    return int(np.sum(d > rtol * d[0])) if d.size and d[0] > 0 else 0


def scaled_lstsq(W: NDArray[np.float64], Y: NDArray[np.float64]) -> NDArray[np.float64]:
    """The minimum-norm least-squares coefficients of ``W X = Y`` (``W`` (m, k), ``Y``
    (m,) or (m, r)), in the units of ``W``'s columns, fitted with the columns scaled to
    unit norm (:func:`column_scale`: the minimum norm of the scaled coefficients, so a
    column's unit does not decide which combination the rank-deficient part takes)."""
    s = column_scale(W)
    X = np.linalg.lstsq(W / s, Y, rcond=None)[0]
    out: NDArray[np.float64] = X / (s if X.ndim == 1 else s[:, None])
    return out


def _column_names(
    labels: tuple[str, ...] | None, v: NDArray[np.float64], keep: NDArray[np.bool_]
) -> tuple[str, ...]:
    """The columns with large weight in ``v`` (a null or weakest direction), named, largest
    first (at most 8; empty when ``v`` is zero)."""
    a = np.abs(v)
    if not a.size or not a.max() > 0:
        return ()
    idx = np.flatnonzero(a >= 0.1 * a.max())
    idx = np.flatnonzero(keep)[idx[np.argsort(-a[idx])][:8]]
    return tuple(labels[k] if labels is not None else f"column {k}" for k in idx)


def unexcited_combinations(
    R: NDArray[np.float64],
    scale: NDArray[np.float64],
    rank: int,
    labels: tuple[str, ...] | None = None,
) -> tuple[str, ...]:
    """Every combination of coefficients the data do not excite, one string each.

    ``R`` (k, k) is the triangular factor of the column-scaled regressor (columns in the
    order of ``scale``, any pivoting undone by the caller's ordering of ``scale``) whose
    numerical rank is ``rank < k``. The ``k - rank`` right singular vectors of its smallest
    singular values span the directions ``v`` with ``W v ~ 0``: moving the coefficients
    along them leaves every fitted value unchanged. The basis is put in reduced echelon
    form (each direction has coefficient 1 on a label of its own, 0 on the others'), the
    labels chosen by their weight, so that the same null space is named the same way
    whatever basis the factorisation gave (in the order of those labels' columns):
    ``"beta39"`` (a column the data never excite),
    ``"beta40 - 0.31*fc6"`` (two columns the data cannot tell apart). Coefficients are in
    the coefficients' own units, to 4 significant digits; entries below 1e-3 of a
    direction's largest (scaled) weight are left out.
    """
    d = R.shape[1] - rank
    if d <= 0:
        return ()
    B, piv = _null_echelon(R, scale, rank)
    E = np.linalg.solve(B[:, piv], B)  # reduced echelon: E[:, piv] = identity
    k = R.shape[1]
    names = labels if labels is not None else tuple(f"column {j}" for j in range(k))
    out = []
    for i in np.argsort(piv):  # in the order of the columns the directions are named by
        p = piv[i]
        w = np.abs(E[i] * scale)
        parts = [names[p]]
        for j in np.argsort(-w):
            if j == p or w[j] < 1e-3 * w.max() or j in piv:
                continue
            c = float(E[i, j])
            parts.append(f"{'-' if c < 0 else '+'} {abs(c):.4g}*{names[j]}")
        out.append(" ".join(parts))
    return tuple(out)


def unexcited_columns(
    R: NDArray[np.float64], scale: NDArray[np.float64], rank: int
) -> NDArray[np.intp]:
    """The columns (``k - rank`` of them, in column order) that name the combinations the
    data do not excite (:func:`unexcited_combinations`, same arguments): each combination
    holds one of them and no other, so that without them the other columns have full rank.
    """
    if R.shape[1] - rank <= 0:
        return np.zeros(0, dtype=np.intp)
    return np.sort(_null_echelon(R, scale, rank)[1])


def _null_echelon(
    R: NDArray[np.float64], scale: NDArray[np.float64], rank: int
) -> tuple[NDArray[np.float64], NDArray[np.intp]]:
    """The ``k - rank`` null directions of ``R`` in the coefficients' units (d, k) and the
    column of largest (scaled) weight naming each."""
    import scipy.linalg  # scipy on first use (start-up time)

    k = R.shape[1]
    d = k - rank
    Vt = np.linalg.svd(R)[2]
    N = Vt[k - d :]  # (d, k), scaled coefficients
    piv = scipy.linalg.qr(N, mode="r", pivoting=True)[1][:d]  # labels of largest weight
    return N / scale[None, :], piv


def _merged(blk: NDArray[np.intp]) -> NDArray[np.intp]:
    """Adjacent row blocks with the same first non-zero column joined (fewer BLAS calls)."""
    if not blk.size:
        return blk
    out = [list(blk[0])]
    for a, b, c in blk[1:]:
        if a == out[-1][1] and c == out[-1][2]:
            out[-1][1] = b
        else:
            out.append([a, b, c])
    return np.array(out, dtype=np.intp)


def _gram(W: NDArray[np.float64], blk: NDArray[np.intp]) -> NDArray[np.float64]:
    """``W^T W`` over the row blocks.

    One symmetric rank-k product (BLAS ``syrk``) per block, on its non-zero columns.
    """
    r = W.shape[1]
    G = np.zeros((r, r))
    for a, b, c in blk:
        Wb = W[a:b, c:]
        G[c:, c:] += Wb.T @ Wb
    return G


def block_grams(W: NDArray[np.float64], blk: NDArray[np.intp]) -> NDArray[np.float64]:
    """``W_b^T W_b`` of each row block: W (M, r), ``blk`` (k, 3) rows of ``(start, stop,
    first)`` -> (k, r, r); the block's leading ``first`` columns (exactly zero) are skipped."""
    r = W.shape[1]
    out = np.zeros((len(blk), r, r))
    for k, (a, b, c) in enumerate(blk):
        Wb = W[a:b, c:]
        out[k, c:, c:] = Wb.T @ Wb
    return out


def _rmatvec(
    W: NDArray[np.float64], blk: NDArray[np.intp], v: NDArray[np.float64]
) -> NDArray[np.float64]:
    """``W^T v`` over the row blocks (``v`` over the rows used)."""
    out = np.zeros(W.shape[1])
    o = 0
    for a, b, c in blk:
        out[c:] += W[a:b, c:].T @ v[o : o + b - a]
        o += b - a
    return out


def _residual(
    W: NDArray[np.float64],
    blk: NDArray[np.intp],
    y: NDArray[np.float64],
    x: NDArray[np.float64],
    then: str,
) -> tuple[NDArray[np.float64], NDArray[np.float64]]:
    """``e = y - W x`` on the rows used, then ``W^T e`` or ``W^T diag(e^2) W``.

    ``then`` is ``"rmatvec"`` (``W^T e``) or ``"meat"`` (``W^T diag(e^2) W``); ``e`` is in
    block order. Each block's second product is taken while the block is still in cache
    (one pass over ``W`` instead of two); the sums are those of :func:`_rmatvec` and
    :func:`_gram`.
    """
    r = W.shape[1]
    e = np.empty(y.size)
    acc = np.zeros(r) if then == "rmatvec" else np.zeros((r, r))
    o = 0
    for a, b, c in blk:
        Wb = W[a:b, c:]
        eb = e[o : o + b - a]
        np.subtract(y[o : o + b - a], Wb @ x[c:], out=eb)
        if then == "rmatvec":
            acc[c:] += Wb.T @ eb
        else:
            We = Wb * eb[:, None]
            acc[c:, c:] += We.T @ We
        o += b - a
    return e, acc


#: Largest condition number of the column-scaled ``W`` solved by the semi-normal equations.
_CSNE_MAX_COND = 1e2
#: Margin of the semi-normal path's rank guarantee: it requires ``cond * rtol`` below this.
_CSNE_RANK_MARGIN = 0.1
#: Range of the squared column norms on the semi-normal path (no overflow or underflow).
_GRAM_RANGE = (1e-250, 1e250)

_Solved = tuple[
    int,
    float,
    NDArray[np.float64],
    NDArray[np.float64],
    NDArray[np.float64],
    NDArray[np.float64],
    float,
    NDArray[np.float64],
]


class _RankDeficient(Exception):
    """Internal: rank deficiency, with the null direction (column order) for the message."""

    def __init__(
        self,
        msg: str,
        null: NDArray[np.float64],
        rank: int,
        combinations: tuple[str, ...],
        redundant: NDArray[np.intp] | None = None,
    ) -> None:
        super().__init__(msg)
        self.null = null
        self.rank = rank
        self.combinations = combinations
        self.redundant = np.zeros(0, np.intp) if redundant is None else redundant


def _conditioning(
    R: NDArray[np.float64], scale: NDArray[np.float64]
) -> tuple[float, float, NDArray[np.float64]]:
    """Scaled and unscaled condition numbers of ``R`` and ``R D``, and the weakest direction.

    ``R`` (k, k) is the triangular factor of the column-scaled regressor (columns in the
    order of ``scale``); the unscaled regressor is ``Q R D``. Returns ``(cond(R),
    cond(R D), v)`` with ``v`` the unit right singular vector of the smallest singular
    value of ``R``.
    """
    cond, v = _scaled_conditioning(R)
    return cond, _unscaled_cond(R, scale), v


def _scaled_conditioning(R: NDArray[np.float64]) -> tuple[float, NDArray[np.float64]]:
    """``cond(R)`` and the weakest direction of :func:`_conditioning`."""
    _, sv, Vt = np.linalg.svd(R)
    cond = float(sv[0] / sv[-1]) if sv.size and sv[-1] > 0 else float("inf")
    return cond, Vt[-1] if sv.size else np.zeros(0)


def _unscaled_cond(R: NDArray[np.float64], scale: NDArray[np.float64]) -> float:
    """``cond(R D)`` of :func:`_conditioning`."""
    su = np.linalg.svd(R * scale[None, :], compute_uv=False)
    return float(su[0] / su[-1]) if su.size and su[-1] > 0 else float("inf")


def _solve_semi_normal(
    Wk: NDArray[np.float64],
    blk: NDArray[np.intp],
    y: NDArray[np.float64],
    G: NDArray[np.float64] | None,
    rtol: float,
    std: StdMethod,
) -> _Solved | None:
    """Corrected semi-normal equations, or None when the QR path must decide.

    ``y`` holds the rows used (in block order), ``G`` is ``W^T W`` or None. Returns
    ``(rank, cond, beta, e, cov_s, scale)`` as :func:`_solve_qr`; None when the Gram
    matrix is not finite or out of range, its Cholesky factorisation fails or the
    condition number exceeds the guard (see the module docstring).
    """
    import scipy.linalg  # scipy on first use (start-up time)

    m, rk = y.size, Wk.shape[1]
    if G is None:
        G = _gram(Wk, blk)
    if not np.all(np.isfinite(G)):
        _checks.finite("W", Wk)  # raises when W holds NaN or inf; else G overflowed
        return None
    d = np.diag(G).copy()
    if not (d.min() > _GRAM_RANGE[0] and d.max() < _GRAM_RANGE[1]):
        return None
    scale = np.sqrt(d)
    Gs = G / scale[:, None] / scale[None, :]
    R, info = scipy.linalg.lapack.dpotrf(Gs, lower=0, clean=1, overwrite_a=1)
    if info != 0:
        return None
    cond, vmin = _scaled_conditioning(R)  # the unscaled one only once this path holds
    if not np.isfinite(cond):
        return None
    if not (cond <= _CSNE_MAX_COND and cond * rtol < _CSNE_RANK_MARGIN):
        return None
    cond_u = _unscaled_cond(R, scale)
    # R^T R z = D^{-1} W^T y, then one correction with the residual (Björck 1987)
    z = scipy.linalg.cho_solve((R, False), _rmatvec(Wk, blk, y) / scale, check_finite=False)
    e, g = _residual(Wk, blk, y, z / scale, "rmatvec")  # g = W^T e
    z += scipy.linalg.cho_solve((R, False), g / scale, check_finite=False)
    bk = z / scale
    e, meat = _residual(Wk, blk, y, bk, "meat" if std == "robust" else "rmatvec")
    dof = max(m - rk, 1)
    Rinv = scipy.linalg.solve_triangular(R, np.eye(rk), check_finite=False)
    Gi = Rinv @ Rinv.T
    if std != "robust":  # "hac": from this by the caller (least_squares._fit)
        cov_s = Gi * (float(e @ e) / dof)
    else:  # HC1: (R^T R)^{-1} D^{-1} W^T diag(e^2) W D^{-1} (R^T R)^{-1}
        meat = meat / scale[:, None] / scale[None, :]
        cov_s = Gi @ meat @ Gi * (m / dof)
    return rk, cond, bk, e, cov_s, scale, cond_u, vmin


#: Rows of each block of :func:`tall_r`: a block and its factor stay in cache.
_QR_BLOCK_ROWS = 2048


def tall_r(
    Wk: NDArray[np.float64], scale: NDArray[np.float64], y: NDArray[np.float64]
) -> NDArray[np.float64]:
    """The upper triangular factor (k, k) of ``[Wk / scale, y]`` (m, k), ``y`` (m,) or (m,
    q), m > k: by Cholesky QR done twice (:func:`_cholesky_qr2`) where the columns are
    conditioned for it, else by unpivoted Householder QR (LAPACK ``geqrf``) of blocks of
    :data:`_QR_BLOCK_ROWS` rows, then of their factors stacked (tall-skinny QR: the same
    factor up to the signs of its rows, in about half the time of one ``geqrf`` over rows
    that leave the cache)."""
    Y = y.reshape(y.shape[0], -1)
    m, c = Wk.shape
    k = c + Y.shape[1]
    if m >= 4 * k:
        R = _cholesky_qr2(Wk, scale, Y)
        if R is not None:
            return R
    parts: list[NDArray[np.float64]] = []
    for a in range(0, m, _QR_BLOCK_ROWS):
        b = min(a + _QR_BLOCK_ROWS, m)
        blk = np.empty((b - a, k), order="F")
        np.divide(Wk[a:b], scale, out=blk[:, :c])
        blk[:, c:] = Y[a:b]
        # a short last block joins the factors' QR as it is
        parts.append(blk if b - a < k and parts else _geqrf_r(blk))
    if len(parts) == 1:
        return parts[0]
    return _geqrf_r(np.asfortranarray(np.vstack(parts)))


#: Largest condition number (LAPACK's 1-norm estimate) of the first Cholesky QR's factor
#: for which :func:`_cholesky_qr2` is used: ``eps cond^2`` far below 1, where its factor
#: is as accurate as Householder QR's (Yamamoto et al. 2015).
_CQR2_MAX_COND = 1e6


def _cholesky_qr2(
    Wk: NDArray[np.float64], scale: NDArray[np.float64], Y: NDArray[np.float64]
) -> NDArray[np.float64] | None:
    """The triangular factor of ``X = [Wk / scale, Y]`` (m, k) by Cholesky QR twice
    (CholeskyQR2; Yamamoto, Nakatsukasa, Yanagisawa and Fukaya, "Roundoff error analysis
    of the CholeskyQR2 algorithm", ETNA 44, 2015): ``X^T X = R1^T R1``, ``Q1 = X R1^-1``,
    ``Q1^T Q1 = R2^T R2``, ``R = R2 R1``; the second pass restores the orthogonality the
    first loses to ``eps cond(X)^2``, so that ``R`` is that of Householder QR up to the
    signs of its rows (1e-16 relative on a 40,593 x 119 regressor of condition 5e3) in
    about 0.6 of its time: three passes of level-3 BLAS over the rows against Householder
    steps (one copy of ``X`` held, column-major). None when a Cholesky factorisation
    fails or the first factor's condition number (of the columns scaled, ``Y``'s too)
    exceeds :data:`_CQR2_MAX_COND` (the caller's Householder QR decides: a
    rank-deficient or ill-conditioned ``Wk``, or
    ``Y`` nearly in its span)."""
    import scipy.linalg  # scipy on first use (start-up time)

    lapack, blas = scipy.linalg.lapack, scipy.linalg.blas
    m, c = Wk.shape
    ny = column_scale(Y)  # the targets scaled too, undone in R's last columns
    X = np.empty((m, c + Y.shape[1]), order="F")  # column-major: BLAS's own order
    np.divide(Wk, scale, out=X[:, :c])
    np.divide(Y, ny, out=X[:, c:])
    R1, info = lapack.dpotrf(X.T @ X, lower=0, clean=1, overwrite_a=1)
    if info != 0:
        return None
    rcond, info = lapack.dtrcon(R1, norm="1", uplo="U", diag="N")
    if info != 0 or not rcond * _CQR2_MAX_COND > 1.0:
        return None
    Q = blas.dtrsm(1.0, R1, X, side=1, lower=0, overwrite_b=1)  # in place of X
    R2, info = lapack.dpotrf(Q.T @ Q, lower=0, clean=1, overwrite_a=1)
    if info != 0:
        return None
    R = np.triu(R2 @ R1)
    R[:, c:] *= ny
    return R


def _geqrf(A: NDArray[np.float64]) -> tuple[NDArray[np.float64], NDArray[np.float64]]:
    """LAPACK ``geqrf`` of ``A`` (M, k), column-major, overwritten in place: its packed
    factors and their ``tau``."""
    import scipy.linalg  # scipy on first use (start-up time)

    qr, tau, _, info = scipy.linalg.lapack.dgeqrf(A, overwrite_a=True)
    if info != 0:  # pragma: no cover - LAPACK argument error
        raise RankDeficientError(f"LAPACK dgeqrf failed with info={info}")
    return qr, tau


def _geqrf_r(A: NDArray[np.float64]) -> NDArray[np.float64]:
    """The upper triangular factor (min(M, k), k) of ``A`` (M, k), column-major,
    overwritten by :func:`_geqrf` in place."""
    return np.triu(_geqrf(A)[0][: min(A.shape)])


def tall_pivoted_qr(
    X: NDArray[np.float64],
) -> tuple[NDArray[np.float64], NDArray[np.float64], NDArray[np.intp]]:
    """Economic QR with column pivoting ``X[:, piv] = Q R`` of ``X`` (M, p): ``Q`` (M, p)
    orthonormal, ``R`` (p, p) upper triangular, ``piv`` (p,), as ``scipy.linalg.qr(X,
    mode="economic", pivoting=True)`` (the same ``R`` up to the signs of its rows and
    ``Q`` of its columns, the same pivots). A tall ``X`` (M >= 4 p, several blocks) is
    factored in blocks of :data:`_QR_BLOCK_ROWS` rows without pivoting, the stacked
    factors with pivoting (the column norms the pivots follow are the same), and ``Q``
    assembled block by block: a third of the time of LAPACK's pivoted QR over rows that
    leave the cache."""
    import scipy.linalg  # scipy on first use (start-up time)

    M, p = X.shape
    if M < 4 * p or M <= 2 * _QR_BLOCK_ROWS:
        Q, R, piv = scipy.linalg.qr(X, mode="economic", pivoting=True)
        return Q, R, piv
    lapack = scipy.linalg.lapack
    factors, parts = [], []
    for a in range(0, M, _QR_BLOCK_ROWS):
        qr, tau = _geqrf(np.asfortranarray(X[a : a + _QR_BLOCK_ROWS]))
        factors.append((qr, tau))
        parts.append(np.triu(qr[: min(qr.shape)]))
    Q2, R, piv = scipy.linalg.qr(np.vstack(parts), mode="economic", pivoting=True)
    Q = np.empty((M, p))
    a = o = 0
    for (qr, tau), part in zip(factors, parts, strict=True):
        k = part.shape[0]
        Qb, _, info = lapack.dorgqr(qr[:, :k], tau, overwrite_a=1)
        if info != 0:  # pragma: no cover - LAPACK argument error
            raise RankDeficientError(f"LAPACK dorgqr failed with info={info}")
        Q[a : a + qr.shape[0]] = Qb @ Q2[o : o + k]
        a, o = a + qr.shape[0], o + k
    return Q, R, piv


def _solve_qr(
    Wk: NDArray[np.float64],
    y: NDArray[np.float64],
    rtol: float,
    std: StdMethod,
    labels: tuple[str, ...] | None = None,
) -> _Solved:
    """Column-scaled Householder QR with column pivoting (two stages when ``W`` is tall).

    Returns ``(rank, cond, beta, e, cov_s, scale, cond_u, v)``: the rank at ``rtol``, the
    condition number of the scaled ``W``, the estimates, the residual ``y - W beta``, the
    covariance of the scaled coefficients (divide by ``outer(scale, scale)`` for
    ``beta``'s), the condition number of ``W`` unscaled and the weakest direction (column
    order).

    Raises
    ------
    _RankDeficient
        Rank below the column count, fewer rows than columns included (with the null
        direction, for naming the columns).
    """
    import scipy.linalg  # scipy on first use (start-up time)

    m, rk = Wk.shape
    scale = column_scale(Wk)
    if m > 4 * (rk + 1):
        # stage 1: R of [Ws y] (its last column holds Q0^T y)
        R0 = tall_r(Wk, scale, y)
        A, b = R0[:rk, :rk], R0[:rk, rk]
    else:
        A, b = Wk / scale, y
    Q, R, piv = scipy.linalg.qr(A, mode="economic", pivoting=True)
    rank = pivoted_rank(R, rtol)
    cond, cond_u, vp = _conditioning(R, scale[piv])  # vp: a null direction when m < rk
    vmin = np.empty(rk)
    vmin[piv] = vp
    if m < rk:
        raise _RankDeficient(
            f"Regressor rank {rank} < {rk}: {m} rows for {rk} coefficients; add configurations",
            vmin,
            rank,
            (),
        )
    if rank < rk:
        order = np.argsort(piv)  # R's columns back in the regressor's order
        raise _RankDeficient(
            f"Regressor rank {rank} < {rk} at rtol={rtol:g} (scaled cond {cond:.3g}); add "
            "configurations or excite the trajectory more, or drop unidentifiable parameters",
            vmin,
            rank,
            unexcited_combinations(R[:, order], scale, rank, labels),
            unexcited_columns(R[:, order], scale, rank),
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
    G = Rinv @ Rinv.T
    if std != "robust":  # "hac": from this by the caller (least_squares._fit)
        cov_p = G * sigma**2
    else:  # HC1: (R^T R)^{-1} Ws^T diag(e^2) Ws (R^T R)^{-1}, in pivoted order
        We = Wk * e[:, None]
        meat = (We.T @ We) / np.outer(scale, scale)
        cov_p = G @ meat[np.ix_(piv, piv)] @ G * (m / dof)
    cov_s = np.empty((rk, rk))
    cov_s[np.ix_(piv, piv)] = cov_p
    return rank, cond, bk, e, cov_s, scale, cond_u, vmin
