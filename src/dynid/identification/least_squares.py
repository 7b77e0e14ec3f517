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
  scales with each entry;
* or, with ``std="hac"``, the heteroskedasticity-and-autocorrelation-consistent one
  (Newey and West 1987) over the samples of each piece of a recording
  (:mod:`dynid.identification.serial`, ``serial=``): a filtered, decimated log's residual
  is correlated over several samples. Without a time structure it is HC1.

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

import numpy as np
from numpy.typing import ArrayLike, NDArray

from .. import _checks
from ..exceptions import NonFiniteError, RankDeficientError, ShapeError
from .serial import Serial, serial_meat
from .solvers import (
    STD_METHODS,
    StdMethod,
    _column_names,
    _merged,
    _RankDeficient,
    _solve_qr,
    _solve_semi_normal,
    block_grams,
    checked_std,
    unexcited_combinations,
)

__all__ = [
    "LeastSquaresFit",
    "assembled",
    "STD_METHODS",
    "StdMethod",
    "block_grams",
    "checked_std",
    "LOOSE_ADVICE",
    "conditioning_advice",
    "fit_least_squares",
    "fit_with_pruning",
    "hac_covariance",
    "loose_coefficients",
    "loose_note",
    "unexcited_combinations",
]


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


def within_motion_caveat(fit: LeastSquaresFit, scheme: str | None) -> str | None:
    """The caveat of a held-out judgement on time blocks (``scheme`` ``"blocks"``) of the
    motion ``fit`` was fitted to, when its regressor is ill-conditioned (scaled condition
    number above :data:`ILL_CONDITIONED`): the blocks share the motion, so they do not test
    the directions it hardly excites, which a new trajectory does (the Panda, 2 s of one
    recording: 2.5 % on its own blocks, 15.7 % on another trajectory; at condition numbers
    below 100, 4-8 s, the blocks' error was the new trajectory's or above). Coefficients
    of large relative deviation are no sign of it: a coefficient near zero has one in
    well-excited fits too. None otherwise."""
    if scheme != "blocks" or not fit.scaled_condition_number > ILL_CONDITIONED:
        return None
    return (
        "the held-out blocks are of the motion the model was fitted to, whose regressor is "
        f"ill-conditioned (scaled condition number {fit.scaled_condition_number:.3g}): a new "
        "trajectory tests the directions this motion hardly excites, and may err far more; "
        "hint: --validate-on a recording of another trajectory, or identify from longer or "
        "several recordings (dynid excite)"
    )


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
            "(dynid excite), or fix these parameters (max_std_percent=... drops them)"
        )
    loose = loose_coefficients(fit, labels)
    if loose:
        out.append(
            f"{len(loose)} {LOOSE_ADVICE} {LARGE_STD_PERCENT:g} %: {_named(loose)}; they are "
            f"indistinguishable from zero with {what}; hint: max_std_percent=... removes them, "
            "or add excitation"
        )
    return out


#: The words that tell :func:`conditioning_advice`'s advice on loose coefficients.
LOOSE_ADVICE = "kept coefficient(s) have a standard deviation above"


def loose_coefficients(fit: LeastSquaresFit, labels: tuple[str, ...]) -> list[tuple[str, float]]:
    """The kept coefficients of ``fit`` (``labels``, length r) whose relative standard
    deviation is above :data:`LARGE_STD_PERCENT` and whose standard deviation moves the
    data (:data:`NEGLIGIBLE_EFFECT_PERCENT`): each label and its deviation [%]."""
    pct = np.asarray(fit.std_percent)
    eff = np.asarray(fit.effect_percent)
    moves = eff > NEGLIGIBLE_EFFECT_PERCENT if eff.shape == pct.shape else np.ones(pct.shape, bool)
    big = np.flatnonzero(np.asarray(fit.kept) & (pct > LARGE_STD_PERCENT) & moves)
    return [(labels[k], float(pct[k])) for k in big]


def loose_note(loose: list[tuple[str, float]], what: str = "the trajectory") -> str:
    """The note that says the ``loose`` coefficients (:func:`loose_coefficients`) of a
    model whose held-out prediction is at the noise floor: they do not change its
    predictions, one line in place of :func:`conditioning_advice`'s warning."""
    return (
        f"{len(loose)} coefficient(s) {what} leaves loose (standard deviation above "
        f"{LARGE_STD_PERCENT:g} %: {_named(loose)}) do not change the predictions, held out "
        "at the noise floor; max_std_percent=... removes them"
    )


def _named(loose: list[tuple[str, float]]) -> str:
    """The first 8 of ``loose`` in words: ``"beta19 (1.08e+03 %), ..."``."""
    return ", ".join(f"{name} ({pct:.3g} %)" for name, pct in loose[:8])


def fit_least_squares(
    W: ArrayLike,
    y: ArrayLike,
    *,
    kept: ArrayLike | None = None,
    rtol: float = 1e-10,
    std: StdMethod = "classical",
    serial: Serial | None = None,
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
    std : {"classical", "robust", "hac"}
        ``"classical"``: ``sigma^2 (W^T W)^{-1}`` (Gaz et al. 2019); ``"robust"``: the
        heteroscedasticity-consistent (HC1) estimate, for rows of unequal error variance;
        ``"hac"``: also consistent for errors correlated in time (``serial``).
    serial : Serial, optional
        The rows' samples and pieces and the HAC window (``std="hac"``); default one row
        a sample, window 0 (HC1).

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
    return _fit(W, y, kept=kept, rtol=rtol, std=std, serial=serial)


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
    serial: Serial | None = None,
) -> LeastSquaresFit:
    """:func:`fit_least_squares` on validated ``W`` (M, r) and ``y`` (M,).

    ``blocks`` (k, 3) of ``(start, stop, first)`` selects the rows used, ``start:stop``
    for each block, and states that ``W[start:stop, :first]`` is exactly zero, so that the
    products over the rows skip those columns (default: every row, one block, ``first``
    0). ``gram``, when given, is ``W^T W`` over the rows used (r, r). ``serial``: the
    time structure of the rows used (``std="hac"``).
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
                    redundant=tuple(str(kl[i]) for i in exc.redundant) if kl else (),
                ) from None
    rank, cond, bk, e, cov_s, scale, cond_u, vmin = solved
    if std == "hac":
        cov_s = _hac(cov_s, float(e @ e), serial_meat(Wk, blk, e, serial or Serial()), scale, m)
    if not (np.all(np.isfinite(bk)) and np.all(np.isfinite(e)) and np.all(np.isfinite(cov_s))):
        k = int(np.argmax(np.abs(yu)))
        raise NonFiniteError(
            f"least squares overflowed: the data hold values up to {float(np.abs(yu[k])):.3g} "
            f"(y[{k}]) and the regressor up to {float(np.max(np.abs(Wk))):.3g}; values this "
            "large are not measurements: check the data"
        )
    ny = float(np.linalg.norm(yu))
    return assembled(keep, bk, cov_s, scale, float(e @ e), ny, m, rank, cond, cond_u, vmin, rtol)


def hac_covariance(
    gi: NDArray[np.float64], meat: NDArray[np.float64], scale: NDArray[np.float64], m: int
) -> NDArray[np.float64]:
    """The HAC covariance of the column-scaled coefficients: ``m / (m - r) G^-1 M G^-1``
    from ``gi`` (r, r) the inverse Gram matrix of the scaled columns and ``meat`` (r, r)
    the unscaled middle factor (:mod:`dynid.identification.serial`)."""
    rk = gi.shape[0]
    mt = meat / np.outer(scale, scale)
    return np.asarray(gi @ mt @ gi * (m / max(m - rk, 1)), dtype=np.float64)


def _hac(
    cov_s: NDArray[np.float64],
    ss: float,
    meat: NDArray[np.float64],
    scale: NDArray[np.float64],
    m: int,
) -> NDArray[np.float64]:
    """:func:`hac_covariance` from a solver's classical covariance ``cov_s`` (``G^-1``
    times ``ss / (m - r)``, ``ss`` the residual sum of squares)."""
    if not ss > 0:  # an exact fit: no residual, no spread
        return np.zeros_like(cov_s)
    gi = cov_s * (max(m - cov_s.shape[0], 1) / ss)
    return hac_covariance(gi, meat, scale, m)


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


def fit_with_pruning(
    W: ArrayLike,
    y: ArrayLike,
    *,
    max_std_percent: float | None = None,
    rtol: float = 1e-10,
    std: StdMethod = "classical",
    labels: tuple[str, ...] | None = None,
    serial: Serial | None = None,
) -> LeastSquaresFit:
    """Fit, then (optionally) remove coefficients with ``std_percent > max_std_percent`` and re-fit.

    Gaz et al. 2019 discard coefficients whose relative standard deviation exceeds 30 %.
    One removal pass, as in the paper. ``std`` and ``serial`` as in
    :func:`fit_least_squares`; ``labels`` (r,) name the columns in a rank-deficiency error.
    """
    W, y = _validated(W, y, std)
    return _fit_with_pruning(
        W, y, max_std_percent=max_std_percent, rtol=rtol, std=std, labels=labels, serial=serial
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
    serial: Serial | None = None,
) -> LeastSquaresFit:
    """:func:`fit_with_pruning` on validated input; ``blocks``, ``gram``, ``labels``,
    ``serial`` as in :func:`_fit`."""
    fit = _fit(W, y, rtol=rtol, std=std, blocks=blocks, gram=gram, labels=labels, serial=serial)
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
        serial=serial,
    )
