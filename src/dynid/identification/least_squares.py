"""Ordinary least squares on a base regressor, with the statistics of Gaz et al. 2019.

.. math:: \\hat\\beta = \\arg\\min_\\beta \\| W \\beta - y \\|^2 \\quad \\text{(eq. 21)}

solved on the column-scaled ``W`` (never with a normal-equation inverse); see Method.
Statistics:

* ``condition_number`` ``sigma_max / sigma_min`` of ``W`` itself, unscaled, as Gaz et al.
  report it (48.9 for the static Panda data, rows ``[tril M; g]`` of their 1010
  configurations, and 121.88 for the exciting trajectory, base regressor with friction
  columns), and ``scaled_condition_number`` of the column-scaled ``W`` (unit column
  norms; the one that decides rank and accuracy, independent of units);
* ``relative_error_percent`` ``= 100 ||y - W beta|| / ||y||``;
* ``sigma^2 = ||y - W beta||^2 / (m - r)`` and ``cov(beta) = sigma^2 (W^T W)^{-1}``
  (from ``R^{-1}``), ``std`` its root diagonal and ``std_percent = 100 std / |beta|``
  (``std="classical"``, the paper's formula, which assumes errors of equal
  variance in every row);
* or, with ``std="robust"``, the heteroscedasticity-consistent covariance (White
  1980, HC1) ``m / (m - r) (W^T W)^{-1} W^T diag(e^2) W (W^T W)^{-1}``, valid when the
  rows' errors differ in size: the static data stack kg m^2 and N m, and a relative error
  scales with each entry.

Method: corrected semi-normal equations (Björck 1987) for a tall ``W`` whose scaled
condition number is at most 100, Householder QR with column pivoting otherwise (short,
ill-conditioned or rank-deficient ``W``); both work on the column-scaled ``W`` and give
the same estimates and covariance to about 1e-13 relative. The semi-normal route is about
three times faster on the static Panda problem. The steps, the accuracy argument and the
rank guard are in ``docs/least-squares.md``.

:func:`conditioning_advice` turns a fit into warnings: an ill-conditioned ``W`` (the
columns that are nearly dependent, from the right singular vector of the smallest
singular value) and coefficients whose relative standard deviation exceeds 1000 %.

Coefficients whose ``std_percent`` exceeds a threshold (the paper used 30 %) can be
removed and the rest re-fitted (:func:`fit_with_pruning`).
"""

from __future__ import annotations

from dataclasses import dataclass, field
from typing import Literal, get_args

import numpy as np
import scipy.linalg
from numpy.typing import ArrayLike, NDArray

from .. import _checks
from ..exceptions import NonFiniteError, OptionError, RankDeficientError, ShapeError

__all__ = [
    "LeastSquaresFit",
    "assembled",
    "STD_METHODS",
    "StdMethod",
    "block_grams",
    "checked_std",
    "conditioning_advice",
    "fit_least_squares",
    "fit_with_pruning",
    "unexcited_combinations",
]

#: How the standard deviations are estimated (``std=``, ``--std``): ``"classical"``
#: ``sigma^2 (W^T W)^{-1}`` (Gaz et al. 2019) or ``"robust"``, heteroscedasticity-consistent
#: (White 1980, HC1).
StdMethod = Literal["classical", "robust"]

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
        ``sigma_max / sigma_min`` of the (unscaled) regressor of the kept columns, the
        figure Gaz et al. 2019 report.
    relative_error_percent : float
    residual_rms : float
    sigma : float
        Residual standard deviation ``sqrt(||e||^2 / (m - r))``.
    n_rows : int
    rtol : float
    covariance : ndarray, shape (r, r), optional
        Full covariance of ``beta`` (same estimator as ``std``; zero rows and columns for
        removed coefficients), so that ``std = sqrt(diag(covariance))``. None when not
        known (files written before it was kept).
    scaled_condition_number : float
        Of the column-scaled regressor (unit column norms) of the kept columns.
    weakest : ndarray, shape (r,)
        Unit right singular vector of the smallest singular value of the column-scaled
        regressor (0 for removed columns): its large entries are the columns that are
        nearly dependent. Empty when unknown.
    effect_percent : ndarray, shape (r,)
        ``100 std_k ||W_k|| / ||y||``: how much one standard deviation of each coefficient
        moves the fitted data, in % of their norm (0 for removed coefficients; empty when
        unknown). A coefficient with a large ``std_percent`` but a negligible effect is
        merely near zero, not undetermined.
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
    covariance: NDArray[np.float64] | None = None
    scaled_condition_number: float = float("nan")
    weakest: NDArray[np.float64] = field(default_factory=lambda: np.zeros(0))
    effect_percent: NDArray[np.float64] = field(default_factory=lambda: np.zeros(0))

    def nearly_dependent(self, labels: tuple[str, ...], *, share: float = 0.1) -> list[str]:
        """Labels of the columns that carry the weakest direction (``|v_k| >= share``).

        Sorted by weight, largest first; empty when ``weakest`` is unknown.
        """
        v = np.abs(np.asarray(self.weakest))
        if v.size != len(labels) or not v.any():
            return []
        order = np.argsort(-v)
        return [labels[k] for k in order if v[k] >= share * v.max()]


#: Scaled condition number above which :func:`conditioning_advice` warns.
ILL_CONDITIONED = 1e3
#: Relative standard deviation [%] above which a kept coefficient is reported...
LARGE_STD_PERCENT = 1e3
#: ... unless one standard deviation moves the data by less than this [% of their norm]
#: (round-off of exact data: the coefficient is zero, not undetermined).
NEGLIGIBLE_EFFECT_PERCENT = 1e-7


def conditioning_advice(
    fit: LeastSquaresFit, labels: tuple[str, ...], *, what: str = "the data"
) -> list[str]:
    """Warnings about a fit's conditioning, each one sentence with a remedy (may be empty).

    Parameters
    ----------
    fit : LeastSquaresFit
    labels : tuple of str, length r
        Column labels of the fit.
    what : str
        Names the data in the messages ("the configurations", "the trajectory").
    """
    out = []
    if fit.scaled_condition_number > ILL_CONDITIONED:
        cols = fit.nearly_dependent(labels)
        out.append(
            f"the regressor of {what} is ill-conditioned (scaled condition number "
            f"{fit.scaled_condition_number:.3g} > {ILL_CONDITIONED:g}); nearly dependent "
            f"columns: {', '.join(cols[:8]) or '?'}; hint: use more or different "
            "configurations (dynid acquire-static --pool) or a longer, optimised trajectory "
            "(dynid excite), or fix these parameters (--max-std-percent drops them)"
        )
    pct = np.asarray(fit.std_percent)
    eff = np.asarray(fit.effect_percent)
    moves = eff > NEGLIGIBLE_EFFECT_PERCENT if eff.shape == pct.shape else np.ones(pct.shape, bool)
    big = np.flatnonzero(np.asarray(fit.kept) & (pct > LARGE_STD_PERCENT) & moves)
    if big.size:
        names = ", ".join(f"{labels[k]} ({pct[k]:.3g} %)" for k in big[:8])
        out.append(
            f"{big.size} kept coefficient(s) have a standard deviation above "
            f"{LARGE_STD_PERCENT:g} %: {names}; they are indistinguishable from zero with "
            f"{what}; hint: --max-std-percent removes them, or add excitation"
        )
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
    k = R.shape[1]
    d = k - rank
    if d <= 0:
        return ()
    Vt = np.linalg.svd(R)[2]
    N = Vt[k - d :]  # (d, k), scaled coefficients
    piv = scipy.linalg.qr(N, mode="r", pivoting=True)[1][:d]  # labels of largest weight
    B = N / scale[None, :]  # the same directions in the coefficients' units
    E = np.linalg.solve(B[:, piv], B)  # reduced echelon: E[:, piv] = identity
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


def fit_least_squares(
    W: ArrayLike,
    y: ArrayLike,
    *,
    kept: ArrayLike | None = None,
    rtol: float = 1e-10,
    std: StdMethod = "classical",
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
    std : {"classical", "robust"}
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
    W, y = _validated(W, y, std)
    return _fit(W, y, kept=kept, rtol=rtol, std=std)


def _validated(
    W: ArrayLike, y: ArrayLike, std: StdMethod
) -> tuple[NDArray[np.float64], NDArray[np.float64]]:
    """``W`` and ``y`` as float64 arrays of matching shapes; ``std`` checked.

    The finiteness of ``W`` is checked by :func:`_fit` (on its Gram matrix on the
    semi-normal path: a non-finite ``W`` gives a non-finite Gram matrix).
    """
    W = _checks.as_array("W", W, allow_nonfinite=True)
    y = _checks.as_array("y", y)
    if W.ndim != 2 or y.shape != (W.shape[0],):
        raise ShapeError(f"W must be (m, r) and y (m,); got {W.shape} and {y.shape}")
    checked_std(std)
    return W, y


def _fit(
    W: NDArray[np.float64],
    y: NDArray[np.float64],
    *,
    kept: ArrayLike | None = None,
    rtol: float,
    std: StdMethod,
    blocks: ArrayLike | None = None,
    gram: NDArray[np.float64] | None = None,
    labels: tuple[str, ...] | None = None,
) -> LeastSquaresFit:
    """:func:`fit_least_squares` on validated ``W`` (M, r) and ``y`` (M,).

    ``blocks`` (k, 3) of ``(start, stop, first)`` selects the rows used, ``start:stop``
    for each block, and states that ``W[start:stop, :first]`` is exactly zero, so that the
    products over the rows skip those columns (default: every row, one block, ``first``
    0). ``gram``, when given, is ``W^T W`` over the rows used (r, r).
    """
    M, r = W.shape
    if blocks is None:
        blk = np.array([[0, M, 0]], dtype=np.intp)
    else:
        blk = np.asarray(blocks, dtype=np.intp).reshape(-1, 3)
    m = int(np.sum(blk[:, 1] - blk[:, 0]))
    keep = np.ones(r, bool) if kept is None else np.asarray(kept, dtype=bool)
    if keep.shape != (r,):
        raise ShapeError(f"kept must have shape ({r},); got {keep.shape}")
    if keep.all():
        Wk, G = W, gram
    else:
        _checks.finite("W", W)
        Wk = W[:, keep]
        blk = blk.copy()
        blk[:, 2] = np.concatenate([[0], np.cumsum(keep)])[blk[:, 2]]  # kept columns before
        G = None if gram is None else gram[np.ix_(keep, keep)]
    rk = Wk.shape[1]
    blk = _merged(blk)
    every_row = bool(
        blk.size and blk[0, 0] == 0 and blk[-1, 1] == M and np.all(blk[1:, 0] == blk[:-1, 1])
    )
    used = None  # rows used, when not all of them in order
    if not every_row:
        used = np.concatenate([np.arange(a, b) for a, b, _ in blk] + [np.zeros(0, np.intp)])
    yu = y if used is None else y[used]
    solved = None
    # entries near the float range (1e300) overflow in the products: checked below, once
    with np.errstate(over="ignore", invalid="ignore", divide="ignore"):
        if m > 4 * (rk + 1) and rk > 0:
            solved = _solve_semi_normal(Wk, blk, yu, G, rtol, std)
        if solved is None:
            Wu = Wk if used is None else Wk[used]
            _checks.finite("W", W if used is None else Wu)
            kl = None if labels is None else tuple(np.asarray(labels, dtype=object)[keep])
            try:
                solved = _solve_qr(Wu, yu, rtol, std, kl)
            except _RankDeficient as exc:
                names = _column_names(labels, exc.null, keep)
                raise RankDeficientError(
                    f"{exc.args[0]}; nearly dependent columns: {', '.join(names) or 'none named'}"
                    + (
                        f"; not excited by the data: {'; '.join(exc.combinations)}"
                        if exc.combinations
                        else ""
                    ),
                    rank=exc.rank,
                    needed=rk,
                    dependent=names,
                    combinations=exc.combinations,
                ) from None
    rank, cond, bk, e, cov_s, scale, cond_u, vmin = solved
    if not (np.all(np.isfinite(bk)) and np.all(np.isfinite(e)) and np.all(np.isfinite(cov_s))):
        k = int(np.argmax(np.abs(yu)))
        raise NonFiniteError(
            f"least squares overflowed: the data hold values up to {float(np.abs(yu[k])):.3g} "
            f"(y[{k}]) and the regressor up to {float(np.max(np.abs(Wk))):.3g}; values this "
            "large are not measurements: check the data"
        )
    ny = float(np.linalg.norm(yu))
    return assembled(keep, bk, cov_s, scale, float(e @ e), ny, m, rank, cond, cond_u, vmin, rtol)


def assembled(
    keep: NDArray[np.bool_],
    bk: NDArray[np.float64],
    cov_s: NDArray[np.float64],
    scale: NDArray[np.float64],
    ss: float,
    ny: float,
    m: int,
    rank: int,
    cond: float,
    cond_u: float,
    vmin: NDArray[np.float64],
    rtol: float,
) -> LeastSquaresFit:
    """The statistics of a fit, assembled in one place for every solver.

    ``keep`` (r,) the columns fitted; over them ``bk`` (k,) the estimates, ``cov_s`` (k, k)
    the covariance of the column-scaled coefficients (divided by ``outer(scale, scale)``
    for ``bk``'s), ``vmin`` (k,) the weakest direction; ``ss`` the residual sum of squares
    and ``ny`` the norm of the targets of the ``m`` rows; ``rank``, ``cond`` (scaled) and
    ``cond_u`` (unscaled) of the regressor.
    """
    r = keep.size
    rk = bk.size
    sigma = np.sqrt(ss / max(m - rk, 1))
    cov_k = cov_s / np.outer(scale, scale)
    cov_k = 0.5 * (cov_k + cov_k.T)
    sk = np.sqrt(np.maximum(np.diag(cov_k), 0.0))
    beta = np.zeros(r)
    sd = np.zeros(r)
    cov = np.zeros((r, r))
    beta[keep], sd[keep] = bk, sk
    cov[np.ix_(keep, keep)] = cov_k
    effect = np.zeros(r)
    effect[keep] = 100.0 * sk * scale / ny if ny > 0 else 0.0
    weakest = np.zeros(r)
    weakest[keep] = vmin
    with np.errstate(divide="ignore", invalid="ignore"):
        pct = np.where(keep, 100.0 * sd / np.abs(beta), np.nan)
    pct = np.where(keep & (sd == 0.0), 0.0, pct)
    return LeastSquaresFit(
        beta=_checks.frozen(beta),
        std=_checks.frozen(sd),
        std_percent=_checks.frozen(pct),
        kept=_checks.frozen(keep.copy()),
        rank=rank,
        condition_number=cond_u,
        relative_error_percent=100.0 * np.sqrt(ss) / ny if ny > 0 else 0.0,
        residual_rms=float(np.sqrt(ss / max(m, 1))),
        sigma=float(sigma),
        n_rows=m,
        rtol=rtol,
        covariance=_checks.frozen(cov),
        scaled_condition_number=cond,
        weakest=_checks.frozen(weakest),
        effect_percent=_checks.frozen(effect),
    )


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
        self, msg: str, null: NDArray[np.float64], rank: int, combinations: tuple[str, ...]
    ) -> None:
        super().__init__(msg)
        self.null = null
        self.rank = rank
        self.combinations = combinations


def _conditioning(
    R: NDArray[np.float64], scale: NDArray[np.float64]
) -> tuple[float, float, NDArray[np.float64]]:
    """Scaled and unscaled condition numbers of ``R`` and ``R D``, and the weakest direction.

    ``R`` (k, k) is the triangular factor of the column-scaled regressor (columns in the
    order of ``scale``); the unscaled regressor is ``Q R D``. Returns ``(cond(R),
    cond(R D), v)`` with ``v`` the unit right singular vector of the smallest singular
    value of ``R``.
    """
    _, sv, Vt = np.linalg.svd(R)
    cond = float(sv[0] / sv[-1]) if sv.size and sv[-1] > 0 else float("inf")
    su = np.linalg.svd(R * scale[None, :], compute_uv=False)
    cond_u = float(su[0] / su[-1]) if su.size and su[-1] > 0 else float("inf")
    v = Vt[-1] if sv.size else np.zeros(0)
    return cond, cond_u, v


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
    cond, cond_u, vmin = _conditioning(R, scale)
    if not np.isfinite(cond):
        return None
    if not (cond <= _CSNE_MAX_COND and cond * rtol < _CSNE_RANK_MARGIN):
        return None
    # R^T R z = D^{-1} W^T y, then one correction with the residual (Björck 1987)
    z = scipy.linalg.cho_solve((R, False), _rmatvec(Wk, blk, y) / scale, check_finite=False)
    e, g = _residual(Wk, blk, y, z / scale, "rmatvec")  # g = W^T e
    z += scipy.linalg.cho_solve((R, False), g / scale, check_finite=False)
    bk = z / scale
    e, meat = _residual(Wk, blk, y, bk, "meat" if std == "robust" else "rmatvec")
    dof = max(m - rk, 1)
    Rinv = scipy.linalg.solve_triangular(R, np.eye(rk), check_finite=False)
    Gi = Rinv @ Rinv.T
    if std == "classical":
        cov_s = Gi * (float(e @ e) / dof)
    else:  # HC1: (R^T R)^{-1} D^{-1} W^T diag(e^2) W D^{-1} (R^T R)^{-1}
        meat = meat / scale[:, None] / scale[None, :]
        cov_s = Gi @ meat @ Gi * (m / dof)
    return rk, cond, bk, e, cov_s, scale, cond_u, vmin


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
    m, rk = Wk.shape
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
            raise RankDeficientError(f"LAPACK dgeqrf failed with info={info}")
        R0 = np.triu(qr0[: rk + 1])
        A, b = R0[:rk, :rk], R0[:rk, rk]
    else:
        A, b = Wk / scale, y
    Q, R, piv = scipy.linalg.qr(A, mode="economic", pivoting=True)
    d = np.abs(np.diag(R))
    rank = int(np.sum(d > rtol * d[0])) if d.size and d[0] > 0 else 0
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
    if std == "classical":
        cov_p = G * sigma**2
    else:  # HC1: (R^T R)^{-1} Ws^T diag(e^2) Ws (R^T R)^{-1}, in pivoted order
        We = Wk * e[:, None]
        meat = (We.T @ We) / np.outer(scale, scale)
        cov_p = G @ meat[np.ix_(piv, piv)] @ G * (m / dof)
    cov_s = np.empty((rk, rk))
    cov_s[np.ix_(piv, piv)] = cov_p
    return rank, cond, bk, e, cov_s, scale, cond_u, vmin


def fit_with_pruning(
    W: ArrayLike,
    y: ArrayLike,
    *,
    max_std_percent: float | None = None,
    rtol: float = 1e-10,
    std: StdMethod = "classical",
    labels: tuple[str, ...] | None = None,
) -> LeastSquaresFit:
    """Fit, then (optionally) remove coefficients with ``std_percent > max_std_percent`` and re-fit.

    Gaz et al. 2019 discard coefficients whose relative standard deviation exceeds 30 %.
    One removal pass, as in the paper. ``std`` as in :func:`fit_least_squares`;
    ``labels`` (r,) name the columns in a rank-deficiency error.
    """
    W, y = _validated(W, y, std)
    return _fit_with_pruning(
        W, y, max_std_percent=max_std_percent, rtol=rtol, std=std, labels=labels
    )


def _fit_with_pruning(
    W: NDArray[np.float64],
    y: NDArray[np.float64],
    *,
    max_std_percent: float | None,
    rtol: float,
    std: StdMethod,
    blocks: ArrayLike | None = None,
    gram: NDArray[np.float64] | None = None,
    labels: tuple[str, ...] | None = None,
) -> LeastSquaresFit:
    """:func:`fit_with_pruning` on validated input; ``blocks``, ``gram``, ``labels`` as in
    :func:`_fit`."""
    fit = _fit(W, y, rtol=rtol, std=std, blocks=blocks, gram=gram, labels=labels)
    if max_std_percent is None:
        return fit
    keep = ~(fit.std_percent > max_std_percent)
    if keep.all():
        return fit
    return _fit(
        W,
        y,
        kept=keep,
        rtol=rtol,
        std=std,
        blocks=blocks,
        gram=gram,
        labels=labels,
    )
