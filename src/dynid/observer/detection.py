"""Contact and collision detection on the residual: thresholds, the model's uncertainty,
events.

**Thresholds** per joint are calibrated on collision-free data (:func:`calibrate`):

* the distribution rule: ``theta_j = margin * Q_q(|r_j|)``, ``Q_q`` the ``q`` quantile of
  the residual's magnitude over the calibration samples (``q = 1``: its largest value);
* with the model's uncertainty, a threshold that grows where the model is less certain:

  .. math:: \\theta_j(t) = k \\sqrt{(Z \\Sigma Z^T)_{jj}} + \\nu_j

  with ``Sigma`` the covariance of the identified base parameters and ``Z = dr/dbeta`` the
  residual's sensitivity to them: the observer's own filter applied to the momentum
  regressor, ``Z_k = Z_{k-1} + gamma ((Y_{p,k} - Y_{p,k-1}) / T + Y_{beta,k} - Z_{k-1})``
  (:func:`residual_std`; ``Y_p`` and ``Y_beta`` of
  :func:`~dynid.observer.terms.base_momentum_regressor`, the rule's mean of ``Y_beta``
  with the trapezoid rule). The noise floor ``nu_j = margin * Q_q((|r_j| - k sigma_j)^+)``
  is what the uncertainty leaves unexplained on the calibration data. The terms of the
  positions (a joint spring ``k (q - q0)``, whose torque the residual takes off the
  measured one as it takes ``g``) add their columns to ``Y_beta`` and their
  coefficients' variances to ``Sigma`` (uncorrelated with the base parameters: an
  identification file keeps no covariance between them).

**The standstill margin** (``standstill``): inside a friction law's standstill band its
Coulomb term is off, while the true friction of a slow reversal lies anywhere in
``[-f_c, f_c]`` (:func:`~dynid.observer.friction.standstill_margin`): a torque the model
cannot know, which the residual passes through its lag ``K_O/(s + K_O)``. That lagged bound
``m_j(t)`` (:func:`standstill_series`, a bound because the lag's impulse response is
positive) is added to both levels of the joint's threshold; the calibration leaves it out
of the residual it reads (``(|r_j| - m_j)^+``), so one reversal does not raise the
threshold everywhere. Without it, a model with a band raises contacts at the slow
reversals of a collision-free motion. At a *settled* rest (inside the band for ``10 / K_O``
already and still) the margin is ``min(f_c, the rest level calibrated at the calibration's
rests)`` where the calibration logs held enough rests (``rest``, :attr:`Thresholds.rest`:
:mod:`dynid.observer.rest_margin`): an arm whose friction vanishes at rest shows so there,
and a push below ``f_c`` at rest is detected; one whose motors hold static friction keeps
about ``f_c``.

Two levels, as robot controllers have them: ``contact`` (the threshold) and ``collision``
(``collision_factor`` times it).

**Events** (:func:`~dynid.observer.events.detect`, a block of samples at a time with
:class:`~dynid.observer.events.EventDetector`): the samples where some ``|r_j|`` exceeds
its contact threshold, runs closer than ``merge_s`` joined; each event has its start and
end, the joints over the threshold, every joint's peak and its level
(:mod:`dynid.observer.events`).
"""

from __future__ import annotations

from collections.abc import Iterable, Iterator
from typing import Any

import numpy as np
from numpy.typing import ArrayLike, NDArray

from .. import _checks
from ..exceptions import DataError, OptionError, ShapeError
from .events import ContactEvent, EventDetector, detect
from .friction import (
    derived_cutoff,
    derived_velocity_bands,
    standstill_margin,
    velocity_bands,
)
from .model import ObserverModel
from .residual import DEFAULT_OPTIONS, ObserverOptions, first_order_filtered, first_order_lag
from .rest_margin import RestClock, RestTally, at_rest, settle_seconds
from .terms import base_momentum_regressor
from .thresholds import RestMargin, Thresholds, threshold_series

__all__ = [
    "ContactEvent",
    "EventDetector",
    "Thresholds",
    "calibrate",
    "detect",
    "residual_std",
    "residual_std_blocks",
    "standstill_blocks",
    "standstill_rest_blocks",
    "standstill_series",
    "threshold_series",
    "undetected_at_rest",
]

#: Samples of the momentum regressor held at once by :func:`residual_std`.
BLOCK = 8192
#: Calibration samples per joint that the standstill margin must leave over (a residual
#: above it) at least, and the fraction of the samples: fewer is refused (:func:`calibrate`).
MIN_OUTSIDE = 200
MIN_OUTSIDE_FRACTION = 0.01


def residual_std(
    model: ObserverModel,
    t: ArrayLike,
    q: ArrayLike,
    dq: ArrayLike,
    options: ObserverOptions = DEFAULT_OPTIONS,
) -> NDArray[np.float64]:
    """Standard deviation (N, n) [N m] of the residual from the base parameters' covariance.

    ``sqrt(diag(Z Sigma Z^T))`` with ``Z = dr/dbeta`` (module docstring), the filter run at
    the log's median sample time; a block of :data:`BLOCK` samples at a time.

    Raises
    ------
    DataError
        A model without base parameters or covariance (a robot's own parameters).
    ShapeError, NonFiniteError
        Bad shapes, NaN.
    """
    if model.base is None or model.covariance is None:
        raise DataError(
            "the model's uncertainty needs identified base parameters with their covariance "
            "(an identification.json); a robot's own parameters have none"
        )
    n = model.n
    ta = _checks.as_array("t", t)
    N = ta.shape[0]
    qa, dqa = _checks.as_exact("q", q, (N, n)), _checks.as_exact("dq", dq, (N, n))
    out = np.zeros((N, n))
    for a, s in residual_std_blocks(model, ta, qa, dqa, options):
        out[a : a + s.shape[0]] = s
    return out


def residual_std_blocks(
    model: ObserverModel,
    t: NDArray[np.float64],
    q: NDArray[np.float64],
    dq: NDArray[np.float64],
    options: ObserverOptions = DEFAULT_OPTIONS,
) -> Iterator[tuple[int, NDArray[np.float64]]]:
    """:func:`residual_std` of validated ``t`` (N,), ``q, dq`` (N, n), a block of
    :data:`BLOCK` samples at a time: ``(first sample, std (m, n) [N m])`` (the filter's
    state carried; only a block's regressor held). The filter is one compiled pass
    (:func:`dynid._kernels.observer.first_order_filter`, the numbers of
    ``scipy.signal.lfilter``, which runs without the kernels)."""
    if model.base is None or model.covariance is None:
        raise DataError("the model's uncertainty needs its base parameters' covariance")
    n = model.n
    ta, qa, dqa = t, q, dq
    N = ta.shape[0]
    T = float(np.median(np.diff(ta))) if N > 1 else 1.0
    K = options.gains(n)
    gam = -np.expm1(-K * T) if options.discretisation == "exact" else K * T
    trap = options.rule == "trapezoid"
    w, V = np.linalg.eigh(_covariance(model))
    L = V * np.sqrt(np.clip(w, 0.0, None))  # Sigma = L L^T
    r = L.shape[0]
    zi = np.zeros((n, r))
    prev_p = prev_b = None
    for a in range(0, N, BLOCK):
        Yp, Yb = base_momentum_regressor(model, qa[a : a + BLOCK], dqa[a : a + BLOCK])
        Ys = model.position_columns(qa[a : a + BLOCK])
        if Ys is not None and model.position_covariance is not None:
            # a spring's torque enters the integral as g does; it holds no momentum
            Yp = np.concatenate([Yp, np.zeros_like(Ys)], axis=-1)
            Yb = np.concatenate([Yb, Ys], axis=-1)
        dp = np.empty_like(Yp)
        dp[1:] = np.diff(Yp, axis=0) / T
        dp[0] = 0.0 if prev_p is None else (Yp[0] - prev_p) / T
        yb = Yb.copy()
        if trap:
            yb[1:] = 0.5 * (Yb[1:] + Yb[:-1])
            if prev_b is not None:
                yb[0] = 0.5 * (Yb[0] + prev_b)
        x = dp + yb
        if prev_p is None:
            x[0] = 0.0  # r_0 = 0 whatever the parameters
        Z = np.empty_like(x)
        first_order_filtered(gam, x, zi, Z)
        prev_p, prev_b = Yp[-1], Yb[-1]
        yield a, np.sqrt(np.sum((Z @ L) ** 2, axis=-1))


def _covariance(model: ObserverModel) -> NDArray[np.float64]:
    """The covariance of the parameters the residual's uncertainty is taken over: the
    base parameters', then the position terms' (a joint spring's stiffnesses), taken as
    uncorrelated with them (a file keeps no covariance between the two)."""
    import scipy.linalg

    base = np.asarray(model.covariance, dtype=np.float64)
    held = model.position_covariance
    if held is None or not model.position_terms:
        return base
    out: NDArray[np.float64] = scipy.linalg.block_diag(base, np.asarray(held))
    return out


def standstill_series(
    model: ObserverModel,
    t: ArrayLike,
    dq: ArrayLike,
    options: ObserverOptions = DEFAULT_OPTIONS,
    *,
    q: ArrayLike | None = None,
    cutoff_hz: float | None = None,
) -> NDArray[np.float64]:
    """The standstill margin (N, n) [N m] of the model's friction at the velocities ``dq``
    (N, n) [rad/s], through the observer's lag ``K_O/(s + K_O)`` over the times ``t`` (N,)
    [s] (module docstring): a bound of the residual that friction the model cannot know
    (inside its standstill band, within the velocity noise band of its smooth Coulomb
    steps: :func:`~dynid.observer.friction.standstill_margin`) leaves; zeros for a friction
    without either. The noise band is estimated on ``dq`` (one piece of a log), or, for
    velocities derived from the positions ``q`` (N, n) [rad] at ``cutoff_hz`` [Hz] (default
    the observer's, :func:`~dynid.observer.friction.derived_cutoff` of ``t``), it is
    their noise through the derivative filter
    (:func:`~dynid.observer.friction.derived_velocity_bands`).

    Raises
    ------
    ShapeError, NonFiniteError
        Bad shapes, NaN.
    """
    n = model.n
    ta = _checks.as_array("t", t)
    dqa = _checks.as_exact("dq", dq, (ta.shape[0], n))
    out = np.zeros((ta.shape[0], n))
    kw: dict[str, Any] = {}
    if q is not None and model.friction is not None:
        qa = _checks.as_exact("q", q, dqa.shape)
        fc = derived_cutoff(ta) if cutoff_hz is None else cutoff_hz
        kw = {"bands": derived_velocity_bands(model.friction, ta, qa, fc), "derived": True}
    for a, m in standstill_blocks(model, ta, dqa, options, **kw):
        out[a : a + m.shape[0]] = m
    return out


def standstill_blocks(
    model: ObserverModel,
    t: NDArray[np.float64],
    dq: NDArray[np.float64],
    options: ObserverOptions = DEFAULT_OPTIONS,
    block: int | None = None,
    *,
    bands: tuple[NDArray[np.float64], ...] | None = None,
    derived: bool = False,
    rest: RestMargin | None = None,
) -> Iterator[tuple[int, NDArray[np.float64]]]:
    """:func:`standstill_series` of one piece ``t`` (N,), ``dq`` (N, n) (validated) a block
    of ``block`` samples (default :data:`_MARGIN_BLOCK`) at a time: ``(first sample, margin
    (m, n) [N m])``, only one block's temporaries held (a long log). The lag continues from
    block to block (its free response ``exp(-K_O (t - t_prev))`` added), as the whole
    piece's to rounding; a margin that is zero everywhere yields nothing. ``bands``: the
    velocity bands of the friction's parts (default
    :func:`~dynid.observer.friction.velocity_bands` of ``dq``); ``derived``: ``dq``
    derived from the positions, ``bands`` of
    :func:`~dynid.observer.friction.derived_velocity_bands`
    (:func:`~dynid.observer.friction.standstill_margin`); ``rest``: the calibrated margin
    at settled rests (:func:`standstill_rest_blocks`)."""
    for a, y, _ in standstill_rest_blocks(
        model, t, dq, options, block, bands=bands, derived=derived, rest=rest, settle=False
    ):
        if y is not None:
            yield a, y


def standstill_rest_blocks(
    model: ObserverModel,
    t: NDArray[np.float64],
    dq: NDArray[np.float64],
    options: ObserverOptions = DEFAULT_OPTIONS,
    block: int | None = None,
    *,
    bands: tuple[NDArray[np.float64], ...] | None = None,
    derived: bool = False,
    rest: RestMargin | None = None,
    settle: bool = True,
) -> Iterator[tuple[int, NDArray[np.float64] | None, NDArray[np.float64] | None]]:
    """:func:`standstill_blocks` with the settled part of every joint's rests: ``(first
    sample, margin (m, n) [N m] or None where it is zero so far, seconds into the settled
    part of a rest (m, n) [s], NaN elsewhere)`` (:func:`~dynid.observer.rest_margin.at_rest`,
    :class:`~dynid.observer.rest_margin.RestClock`: at rest for ``settle_s`` or longer
    already and still for ``settle_s`` or longer, the velocities read that far ahead). With
    ``rest``, the margin of a joint in the settled part of a rest is ``min(its Coulomb
    bound, its calibrated rest level)`` before the lag (:mod:`dynid.observer.rest_margin`);
    ``settle_s`` is ``rest``'s, else
    :func:`~dynid.observer.rest_margin.settle_seconds` of the gains. ``settle`` False
    without ``rest``: the settled parts are not needed, not read (None).
    """
    N, n = dq.shape
    size = _MARGIN_BLOCK if block is None else int(block)
    if bands is None and model.friction is not None:
        bands = velocity_bands(model.friction, dq)
    gains = options.gains(n)
    clock = RestClock(n, settle_seconds(gains) if rest is None else rest.settle_s)
    prev: tuple[float, NDArray[np.float64], NDArray[np.float64]] | None = None
    for a in range(0, N, size):
        b = min(a + size, N)
        e = min(N, int(np.searchsorted(t, t[b - 1] + clock.settle_s, "right")) + 1)
        w = standstill_margin(model.friction, dq[a:b], bands, derived=derived)
        settled = None
        if settle or rest is not None:
            mask = at_rest(model.friction, dq[a:e], bands)  # read settle_s ahead
            settled = clock.settled(t[a:e], mask, b - a)
        if rest is not None and settled is not None:
            w = np.where(np.isfinite(settled), rest.at_rest(w), w)
        if prev is None and not np.any(w):
            yield a, None, settled  # zero so far: its lag is zero too
            continue
        if prev is None:  # the first nonzero block: the lag of zeros before it is zero
            c = max(a - 1, 0)
            x = np.concatenate([np.zeros((a - c, n)), w])
            y = first_order_lag(t[c:b], x, gains, options.rule)[a - c :]
        else:
            t0, x0, y0 = prev
            y = first_order_lag(np.concatenate([[t0], t[a:b]]), np.concatenate([x0[None], w]),
                                gains, options.rule)[1:]  # fmt: skip
            y += y0 * np.exp(-gains * (t[a:b, None] - t0))
        prev = (float(t[b - 1]), w[-1].copy(), y[-1].copy())
        yield a, y, settled


#: Samples of the standstill margin computed at a time (about ten temporaries of a block).
_MARGIN_BLOCK = 1 << 16


def calibrate(
    residuals: Iterable[ArrayLike],
    options: ObserverOptions,
    *,
    std: Iterable[ArrayLike] | None = None,
    standstill: Iterable[ArrayLike] | None = None,
    rest: Iterable[ArrayLike] | None = None,
    margin: float = 1.5,
    quantile: float = 1.0,
    collision_factor: float = 2.0,
    k_sigma: float = 3.0,
) -> Thresholds:
    """Per-joint thresholds from the residuals of collision-free logs (module docstring).

    Parameters
    ----------
    residuals : iterable of array_like, shape (N_i, n)
        Residuals [N m] of collision-free motions: whole logs or consecutive blocks of
        them (a generator: each block is read once and dropped; with ``quantile`` 1 only
        running maxima and counts are kept, so a long log is calibrated in bounded memory).
    options : ObserverOptions
        The observer they were computed with (kept with the thresholds).
    std : iterable of array_like, shape (N_i, n), optional
        :func:`residual_std` of the same samples: the thresholds then also grow with the
        model's uncertainty (``k_sigma``).
    standstill : iterable of array_like, shape (N_i, n), optional
        :func:`standstill_series` of the same samples: left out of the residual read here
        and added to the thresholds at detection.
    rest : iterable of array_like, shape (N_i, n), optional
        With ``standstill``: seconds into settled rests (NaN elsewhere,
        :func:`standstill_rest_blocks`): the margin there calibrated on them
        (:mod:`dynid.observer.rest_margin`); without, the Coulomb level stays.
    margin : float
        Factor over the calibration residuals (>= 1).
    quantile : float
        Of ``|r|`` over the calibration samples, in (0, 1]; 1: the largest.
    collision_factor : float
        Collision over contact level (>= 1).
    k_sigma : float
        ``k`` of the uncertainty-grown threshold (> 0).

    Returns
    -------
    Thresholds

    Raises
    ------
    OptionError
        A parameter out of its range.
    ShapeError
        Residuals of different joint counts, ``std`` not of their shapes, no sample.
    DataError
        With ``standstill``: a joint whose residual the margin covers at all but fewer than
        :data:`MIN_OUTSIDE` samples (or 1 % of them), as on a log at rest: inside its
        standstill band the calibration learns nothing (a threshold of about 0 N m).
    """
    _check_rule(margin, quantile, collision_factor, k_sigma)
    n_joints: int | None = None
    count, top, top_excess = 0, None, None
    outside = None
    kept: list[NDArray[np.float64]] = []  # quantile < 1: every sample's |r| (and excess)
    kept_excess: list[NDArray[np.float64]] = []
    stds = iter(std) if std is not None else None
    margins = iter(standstill) if standstill is not None else None
    rests = iter(rest) if rest is not None and standstill is not None else None
    tally: RestTally | None = None
    for x in residuals:
        R = _checks.as_array("residual", x)
        if R.ndim != 2 or (n_joints is not None and R.shape[1] != n_joints):
            raise ShapeError("residuals must be one or more (N, n) arrays of one joint count")
        n_joints = R.shape[1]
        A = np.abs(R)
        if margins is not None:
            W = _checks.as_exact("standstill", _next(margins, "standstill"), R.shape)
            A = np.clip(A - W, 0.0, None)
            left = np.count_nonzero(A > 0.0, axis=0)
            outside = left if outside is None else outside + left
        excess, S = None, None
        if stds is not None:
            S = _checks.as_exact("std", _next(stds, "std"), R.shape)
            excess = np.clip(A - k_sigma * S, 0.0, None)
        if rests is not None:
            tally = _rest_tallied(tally, R, _next(rests, "rest"), S, options, quantile, k_sigma)
        count += A.shape[0]
        if quantile < 1.0:
            kept.append(A)
            if excess is not None:
                kept_excess.append(excess)
        elif A.shape[0]:
            top = _running_max(top, A)
            if excess is not None:
                top_excess = _running_max(top_excess, excess)
    if n_joints is None:
        raise ShapeError("residuals must be one or more (N, n) arrays of one joint count")
    if count == 0:
        raise ShapeError("no calibration sample")
    if outside is not None:
        _check_outside_band(outside, count)
    if quantile < 1.0:
        contact = margin * np.quantile(np.concatenate(kept), quantile, axis=0)
        noise = None
        if stds is not None:
            noise = margin * np.quantile(np.concatenate(kept_excess), quantile, axis=0)
    else:
        assert top is not None
        contact = margin * top
        noise = None if top_excess is None else margin * top_excess
    return Thresholds(
        contact=contact,
        collision=collision_factor * contact,
        margin=margin,
        quantile=quantile,
        collision_factor=collision_factor,
        options=options,
        samples=int(count),
        k_sigma=k_sigma if std is not None else None,
        noise=noise,
        standstill=standstill is not None,
        rest=None if tally is None else tally.result(margin, contact, noise),
    )


def _check_rule(margin: float, quantile: float, collision_factor: float, k_sigma: float) -> None:
    """The calibration rule's parameters in their ranges (:func:`calibrate`)."""
    if not margin >= 1.0 or not 0.0 < quantile <= 1.0 or not collision_factor >= 1.0:
        raise OptionError(
            f"margin >= 1, quantile in (0, 1] and collision factor >= 1 are needed; got "
            f"{margin}, {quantile}, {collision_factor}"
        )
    if not k_sigma > 0:
        raise OptionError(f"k_sigma must be > 0; got {k_sigma}")


def _rest_tallied(
    tally: RestTally | None,
    R: NDArray[np.float64],
    rest: ArrayLike,
    S: NDArray[np.float64] | None,
    options: ObserverOptions,
    quantile: float,
    k_sigma: float,
) -> RestTally:
    """``tally`` (a new one for the first block) with the block's residual ``R``, its
    seconds at rest ``rest`` and std ``S`` added
    (:class:`~dynid.observer.rest_margin.RestTally`)."""
    n = R.shape[1]
    if tally is None:
        tally = RestTally(n, settle_seconds(options.gains(n)), quantile, k_sigma)
    tally.add(R, _checks.as_exact("rest", rest, R.shape, allow_nonfinite=True), S)
    return tally


def _next(it: Iterator[ArrayLike], name: str) -> ArrayLike:
    """The next block of ``std`` or ``standstill`` beside a residual block."""
    try:
        return next(it)
    except StopIteration:
        raise ShapeError(f"{name} must have one array per residual array") from None


def _running_max(top: NDArray[np.float64] | None, A: NDArray[np.float64]) -> NDArray:
    m = np.max(A, axis=0)
    return m if top is None else np.maximum(top, m)


def _check_outside_band(left: NDArray[np.int64], N: int) -> None:
    """Refuse joints whose calibration residual the standstill margin covers (almost)
    everywhere: fewer than :data:`MIN_OUTSIDE` samples (or 1 % of them) of the ``N`` left
    over (``left`` (n,) per joint), as on a log at rest, would calibrate a threshold of
    about 0 N m."""
    need = max(MIN_OUTSIDE_FRACTION * N, min(MIN_OUTSIDE, N))
    bad = np.flatnonzero(left < need)
    if bad.size:
        joints = ", ".join(str(j + 1) for j in bad)
        counts = ", ".join(str(int(left[j])) for j in bad)
        raise DataError(
            f"joint(s) {joints}: only {counts} of {N} calibration samples outside the "
            "friction's standstill band (inside it the standstill margin covers the "
            "residual, leaving a threshold of about 0 N m); calibrate on collision-free "
            "motion that moves every joint"
        )


def undetected_at_rest(
    model: ObserverModel, thresholds: Thresholds, contact: ArrayLike | None = None
) -> NDArray[np.float64]:
    """Per joint (n,) [N m]: the contact torque below which a contact on a joint at rest
    inside its standstill band goes undetected, its standstill margin at rest (the
    largest static friction the law can hold without a motion, or the level calibrated
    from the calibration's rests where smaller: :attr:`Thresholds.rest`) plus its contact
    level
    ``contact`` (n,) [N m] (the level while moving,
    :func:`~dynid.observer.calibration_check.detectable`; default: the fixed contact
    threshold); the level alone for thresholds without the margin."""
    level = np.array(thresholds.contact if contact is None else contact, dtype=np.float64)
    if not thresholds.standstill:
        return level
    rest = standstill_margin(model.friction, np.zeros((1, model.n)))[0]
    if thresholds.rest is not None:  # calibrated from the calibration's rests
        rest = thresholds.rest.at_rest(rest)
    return np.asarray(level + rest)
