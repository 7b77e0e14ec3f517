"""The noise a held-out fold's own coefficients put into its prediction.

A fold of the held-out judgement predicts data with coefficients fitted on the other
folds' data alone: their noise moves the coefficients, and the prediction of a model of
the right structure errs by that much more than the sensors' noise. With few data per fold
the part is not small: a UR5 identified from two 7 s recordings (the truth's structure,
58 coefficients) predicted each recording from the other with a wrist error of 0.022 N m
RMS against the truth, beside 0.020 N m of sensor noise (1.38 x its noise, "friction the
law misses"), where the final fit on both erred 0.009 N m.

The coefficients of least squares on rows ``Y_i`` (each sample's (n, p) regressor) of
torques with white noise of variance ``sigma_j^2`` on joint ``j`` have the covariance

.. math:: \\Sigma = G^{+} \\Big(\\sum_i Y_i^T S Y_i\\Big) G^{+}, \\qquad
   G = \\sum_i Y_i^T Y_i \\quad (\\text{ols}), \\qquad
   \\Sigma = \\Big(\\sum_i Y_i^T S^{-1} Y_i\\Big)^{+} \\quad (\\text{wls})

with ``S = diag(sigma^2)``. A fit on the low-passed, decimated rows of a recording has the
same: the regressor's columns lie within the pass band, where the filter passes the
noise's spectrum unchanged, and the long-run variance of the decimated filtered noise is
``sigma^2 / k`` per kept sample for ``k`` samples per kept one. The weights are the
sensors' noise, not the fit's residual: a structure that misses a term is judged against
what the noise alone leaves, its systematic residual does not widen the floor. The
prediction's variance at a held-out sample is ``diag(Y Sigma Y^T)`` (n,).

Where the structure is near the truth's but not at it (a smooth Coulomb's width 8 %
off the truth's), its residual within the pass band is above the filtered noise, and the
folds' coefficients vary with it: the UR5's wrist folds above erred 1.7 x what the noise
alone gives. Each joint's part is therefore counted at the fit's own spread where that is
larger: the variance the final fit's covariance (HAC, :mod:`~dynid.identification.serial`:
it holds for the residual as it is) puts into its prediction of its own samples over the
variance the noise alone would, at most :data:`MOST_FIT_FACTOR` (a structure that misses
a term is still judged against little more than its noise: its residual does not widen
the floor without bound).

The part is one draw, not a mean over the samples: the coefficients of a fold move the
prediction of all its samples together, along the few directions the data leave loose,
and the squared error they add, ``delta^T A delta`` with ``A = sum_i Y_i^T Y_i`` over the
held-out samples, spreads about its mean ``tr(A Sigma)`` by ``sqrt(2 tr((A Sigma)^2))``.
It is counted at its mean plus that standard deviation (:func:`draw_margin`): at its mean
alone, a planar 2R arm of the truth's structure predicted from 2 s recordings was judged
above its noise on one joint in two.

* :func:`coefficient_covariance`: ``Sigma`` of rows given at every k-th sample (the
  pieces' sums :func:`piece_sums`, added by :func:`covariance_of_sums`: a piece in several
  folds' training data formed once);
* :func:`prediction_variance`: ``diag(Y Sigma Y^T)`` per sample;
* :func:`fit_factors`: each joint's factor of the fit's own spread over the noise's;
* :func:`draw_margin`: each joint's factor from the part's mean to its mean plus one
  standard deviation (:func:`draw_margin_of` of the rows' sums, :func:`joint_grams`).
"""

from __future__ import annotations

from collections.abc import Sequence

import numpy as np
from numpy.typing import NDArray

__all__ = [
    "LOOSE_FOLDS",
    "MOST_FIT_FACTOR",
    "PieceSums",
    "coefficient_covariance",
    "covariance_of_sums",
    "draw_margin",
    "draw_margin_of",
    "fit_factors",
    "joint_grams",
    "loose_folds",
    "piece_sums",
    "prediction_variance",
]

#: A fold's coefficients noise through the model more than this times the sensors' noise
#: on a joint (RMS) is not counted in the floor: the folds are too loose for their error
#: to judge the model (a planar 2R arm's offsets over 2 s recordings: 7e5 N m), which the
#: verdict says (:func:`loose_folds`).
LOOSE_FOLDS = 2.0
#: The largest factor :func:`fit_factors` gives a joint's part: 1.5^2, the pooled
#: verdict's own margin (:data:`~dynid.identification.verdict.FLOOR_GOOD`) squared.
MOST_FIT_FACTOR = 2.25

#: Relative eigenvalue (of the column-scaled normal equations) below which a direction is
#: left out of the pseudo-inverse, as the fold's own solve leaves it out
#: (:meth:`~dynid.identification.holdout.Normals.solve`, ``rtol^2``).
_RCOND = 1e-20


def coefficient_covariance(
    rows: Sequence[tuple[int, NDArray[np.float64]]],
    noise_var: NDArray[np.float64],
    *,
    weighted: bool,
) -> NDArray[np.float64]:
    """The covariance (p, p) of least-squares coefficients fitted on ``rows`` whose
    torques carry white noise of variance ``noise_var`` (n,) [N^2 m^2] per joint
    (module docstring).

    Parameters
    ----------
    rows : sequence of (int, ndarray (M, n, p))
        Per piece of the training data, the step ``k`` and the regressor at its every k-th
        sample (each row counts ``k`` samples).
    noise_var : ndarray, shape (n,)
        Each joint's noise variance [N^2 m^2], positive.
    weighted : bool
        Each joint's rows weighed by its noise (wls); False: unweighted (ols).

    Returns
    -------
    ndarray, shape (p, p)
        In the coefficients' units squared; zero rows and columns for a column no row
        excites.
    """
    return covariance_of_sums(piece_sums(rows, noise_var, weighted=weighted), weighted=weighted)


#: One piece's step ``k`` and the sums :func:`coefficient_covariance` adds up for it:
#: ``sum_i Y_i^T S^{-1} Y_i`` (wls) or ``sum_i Y_i^T Y_i`` and ``sum_i Y_i^T S Y_i`` (ols).
PieceSums = tuple[int, NDArray[np.float64], NDArray[np.float64] | None]


def piece_sums(
    rows: Sequence[tuple[int, NDArray[np.float64]]],
    noise_var: NDArray[np.float64],
    *,
    weighted: bool,
) -> list[PieceSums]:
    """Per piece of ``rows`` (as :func:`coefficient_covariance` takes them), its step and
    the products of its rows that the covariance sums (:data:`PieceSums`, (p, p) each):
    computed once, a piece shared by several folds' training data is summed into each
    (:func:`covariance_of_sums`) without forming them again."""
    s = np.asarray(noise_var, dtype=np.float64)
    out: list[PieceSums] = []
    for k, Y in rows:
        if weighted:
            out.append((k, _weighted_gram(Y, 1.0 / s), None))
        else:
            flat = Y.reshape(-1, Y.shape[-1])
            out.append((k, flat.T @ flat, _weighted_gram(Y, s)))
    return out


def covariance_of_sums(sums: Sequence[PieceSums], *, weighted: bool) -> NDArray[np.float64]:
    """:func:`coefficient_covariance` (p, p) of the pieces whose products ``sums``
    (:func:`piece_sums`) holds, added in their order."""
    p = sums[0][1].shape[-1]
    G, meat = np.zeros((p, p)), np.zeros((p, p))
    for k, A, B in sums:
        G += k * A
        if not weighted and B is not None:
            meat += k * B
    Gp = _pinv(G)
    return Gp if weighted else Gp @ meat @ Gp


def prediction_variance(Y: NDArray[np.float64], cov: NDArray[np.float64]) -> NDArray[np.float64]:
    """``diag(Y_i Sigma Y_i^T)`` (M, n) [N^2 m^2]: the variance coefficients of covariance
    ``cov`` (p, p) put into the prediction ``Y_i x`` at each sample ``i`` of ``Y``
    (M, n, p)."""
    flat = Y.reshape(-1, Y.shape[-1])
    out = np.einsum("ip,ip->i", flat @ cov, flat).reshape(Y.shape[:-1])
    return np.asarray(np.maximum(out, 0.0), dtype=np.float64)  # round-off below zero


def fit_factors(
    rows: Sequence[tuple[int, NDArray[np.float64]]],
    noise_cov: NDArray[np.float64],
    fit_cov: NDArray[np.float64],
) -> NDArray[np.float64]:
    """Per joint (n,), the variance the fit's own covariance ``fit_cov`` (p, p) puts into
    its prediction at ``rows`` (each piece's step and every k-th sample's regressor
    (M, n, p)) over the variance the noise's ``noise_cov`` puts there, within 1 and
    :data:`MOST_FIT_FACTOR` (1 where the noise puts none)."""
    fit = sum((k * prediction_variance(Y, fit_cov).sum(axis=0) for k, Y in rows), 0.0)
    noise = sum((k * prediction_variance(Y, noise_cov).sum(axis=0) for k, Y in rows), 0.0)
    f = np.divide(fit, noise, out=np.ones_like(noise), where=noise > 0)
    return np.asarray(np.clip(f, 1.0, MOST_FIT_FACTOR), dtype=np.float64)


def draw_margin(
    folds: Sequence[tuple[int, NDArray[np.float64], NDArray[np.float64]]],
) -> NDArray[np.float64]:
    """Per joint (n,), the factor that takes the squared error the folds' coefficients add
    from its mean to its mean plus one standard deviation (module docstring), the folds
    independent.

    Parameters
    ----------
    folds : sequence of (int, ndarray (M, n, p), ndarray (p, p))
        Per fold, the step ``k`` of its held-out samples, the regressor at its every k-th
        held-out sample and its coefficients' covariance.

    Returns
    -------
    ndarray, shape (n,)
        At least 1 (1 where the coefficients add nothing).
    """
    return draw_margin_of([(joint_grams(Y, k), cov) for k, Y, cov in folds])


def joint_grams(Y: NDArray[np.float64], k: int = 1) -> NDArray[np.float64]:
    """``k Y_j^T Y_j`` (n, p, p) per joint ``j`` of rows ``Y`` (M, n, p) that each count
    ``k`` samples: the sums :func:`draw_margin_of` reads (added over blocks of rows)."""
    out = np.stack([Y[:, j, :].T @ Y[:, j, :] for j in range(Y.shape[1])])
    return np.asarray(k * out, dtype=np.float64)


def draw_margin_of(
    folds: Sequence[tuple[NDArray[np.float64], NDArray[np.float64]]],
) -> NDArray[np.float64]:
    """:func:`draw_margin` (n,) of folds given as their held-out rows' sums
    (:func:`joint_grams`, (n, p, p)) and their coefficients' covariance (p, p); one
    entry for rows that share one set of coefficients (a model predicting several
    pieces)."""
    n = folds[0][0].shape[0]
    mean, var = np.zeros(n), np.zeros(n)
    for A, cov in folds:
        for j in range(n):
            AS = A[j] @ cov
            mean[j] += float(np.trace(AS))
            var[j] += 2.0 * float(np.sum(AS * AS.T))
    out = 1.0 + np.divide(np.sqrt(var), mean, out=np.zeros(n), where=mean > 0)
    return np.asarray(out, dtype=np.float64)


def loose_folds(
    fit_rms: NDArray[np.float64], sensor_rms: NDArray[np.float64], names: Sequence[str]
) -> str | None:
    """The caveat of folds whose coefficients' noise through the model ``fit_rms`` (n,)
    [N m] is above :data:`LOOSE_FOLDS` x the sensors' ``sensor_rms`` (n,) on a joint
    (``names``): their held-out error tells little of the model; None otherwise."""
    with np.errstate(divide="ignore", invalid="ignore"):
        ratio = np.where(sensor_rms > 0, fit_rms / sensor_rms, np.inf)
    if not np.any(ratio > LOOSE_FOLDS):
        return None
    j = int(np.argmax(ratio))
    return (
        "the folds, each fitted without the recording it predicts, leave coefficients loose "
        f"(their noise through the model {ratio[j]:.3g} x the sensors' on {names[j]}): the "
        "held-out error of so few data tells little of the model; hint: --validate-on a "
        "recording of another trajectory, or longer recordings"
    )


def _weighted_gram(Y: NDArray[np.float64], w: NDArray[np.float64]) -> NDArray[np.float64]:
    """``sum_i Y_i^T diag(w) Y_i`` (p, p) of rows ``Y`` (M, n, p) and joint weights ``w``
    (n,), as one product of the stacked rows (BLAS; an einsum of three operands loops)."""
    flat = Y.reshape(-1, Y.shape[-1])
    weighted = (Y * w[None, :, None]).reshape(flat.shape)
    out: NDArray[np.float64] = weighted.T @ flat
    return out


def _pinv(G: NDArray[np.float64]) -> NDArray[np.float64]:
    """The pseudo-inverse of the symmetric ``G`` in column-scaled coordinates, directions
    of a relative eigenvalue below :data:`_RCOND` left out (a column of zeros: zero)."""
    d = np.sqrt(np.maximum(np.diag(G), 0.0))
    d = np.where(d > 0, d, 1.0)
    Gs = G / np.outer(d, d)
    lam, U = np.linalg.eigh(0.5 * (Gs + Gs.T))
    keep = lam > _RCOND * max(float(lam[-1]), 0.0) if lam.size else lam > 0
    inv = (U[:, keep] / lam[keep]) @ U[:, keep].T
    return np.asarray(inv / np.outer(d, d), dtype=np.float64)
