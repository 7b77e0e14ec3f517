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
  is what the uncertainty leaves unexplained on the calibration data.

**The standstill margin** (``standstill``): inside a friction law's standstill band its
Coulomb term is off, while the true friction of a slow reversal lies anywhere in
``[-f_c, f_c]`` (:func:`~dynid.observer.friction.standstill_margin`): a torque the model
cannot know, which the residual passes through its lag ``K_O/(s + K_O)``. That lagged bound
``m_j(t)`` (:func:`standstill_series`, a bound because the lag's impulse response is
positive) is added to both levels of the joint's threshold; the calibration leaves it out
of the residual it reads (``(|r_j| - m_j)^+``), so one reversal does not raise the
threshold everywhere. Without it, a model with a band raises contacts at the slow
reversals of a collision-free motion.

Two levels, as robot controllers have them: ``contact`` (the threshold) and ``collision``
(``collision_factor`` times it).

**Events** (:func:`detect`): the samples where some ``|r_j|`` exceeds its contact
threshold, runs closer than ``merge_s`` joined; each event has its start and end [s]
(first and last sample over the threshold), the joints over it (1-based), the peak
residual of every joint [N m] (signed, at its largest magnitude) and its level
(``collision`` when some joint passed its collision threshold).
"""

from __future__ import annotations

from collections.abc import Iterable, Iterator
from dataclasses import dataclass, field
from typing import Literal

import numpy as np
from numpy.typing import ArrayLike, NDArray

from .. import _checks
from ..exceptions import DataError, OptionError, ShapeError
from .friction import standstill_margin, velocity_bands
from .model import ObserverModel
from .residual import DEFAULT_OPTIONS, ObserverOptions, first_order_lag
from .terms import base_momentum_regressor

__all__ = [
    "ContactEvent",
    "Thresholds",
    "calibrate",
    "detect",
    "residual_std",
    "residual_std_blocks",
    "standstill_blocks",
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


@dataclass(frozen=True, slots=True, eq=False)
class Thresholds:
    """Per-joint detection thresholds (module docstring); arrays read-only.

    Attributes
    ----------
    contact, collision : ndarray, shape (n,)
        Fixed thresholds [N m] (the distribution rule).
    margin, quantile, collision_factor : float
        The rule's parameters.
    k_sigma : float or None
        ``k`` of the uncertainty-grown threshold; None: fixed thresholds only.
    noise : ndarray, shape (n,), or None
        Its noise floor ``nu`` [N m] (the contact level's).
    standstill : bool
        The lagged standstill margin of the model's friction is added to both levels
        (calibrated without it).
    options : ObserverOptions
        The observer the thresholds were calibrated with (the residual they apply to).
    samples : int
        Calibration samples.
    """

    contact: NDArray[np.float64]
    collision: NDArray[np.float64]
    margin: float
    quantile: float
    collision_factor: float
    options: ObserverOptions
    samples: int
    k_sigma: float | None = None
    noise: NDArray[np.float64] | None = field(default=None)
    standstill: bool = False

    def __post_init__(self) -> None:
        n = np.shape(self.contact)[0]
        for name in ("contact", "collision") + (("noise",) if self.noise is not None else ()):
            a = _checks.as_exact(name, getattr(self, name), (n,))
            if np.any(a < 0):
                raise DataError(f"thresholds: {name} must be >= 0 [N m]; got {a.tolist()}")
            object.__setattr__(self, name, _checks.frozen(a))

    @property
    def n(self) -> int:
        """Joints."""
        return int(self.contact.shape[0])

    @property
    def uses_uncertainty(self) -> bool:
        """Whether the thresholds grow with the model's uncertainty."""
        return self.k_sigma is not None and self.noise is not None


@dataclass(frozen=True, slots=True)
class ContactEvent:
    """A detected contact (module docstring).

    Attributes
    ----------
    start, end : float
        First and last sample over the threshold [s].
    joints : tuple of int
        Joints over their threshold during the event, 1-based.
    peak : tuple of float
        Every joint's residual at its largest magnitude in the event [N m] (signed).
    level : {"contact", "collision"}
    """

    start: float
    end: float
    joints: tuple[int, ...]
    peak: tuple[float, ...]
    level: Literal["contact", "collision"]


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
    state carried; only a block's regressor held)."""
    import scipy.signal

    if model.base is None or model.covariance is None:
        raise DataError("the model's uncertainty needs its base parameters' covariance")
    n = model.n
    ta, qa, dqa = t, q, dq
    N = ta.shape[0]
    T = float(np.median(np.diff(ta))) if N > 1 else 1.0
    K = options.gains(n)
    gam = -np.expm1(-K * T) if options.discretisation == "exact" else K * T
    trap = options.rule == "trapezoid"
    w, V = np.linalg.eigh(np.asarray(model.covariance))
    L = V * np.sqrt(np.clip(w, 0.0, None))  # Sigma = L L^T
    r = L.shape[0]
    zi = np.zeros((n, 1, r))
    prev_p = prev_b = None
    for a in range(0, N, BLOCK):
        Yp, Yb = base_momentum_regressor(model, qa[a : a + BLOCK], dqa[a : a + BLOCK])
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
        for j in range(n):
            Z[:, j, :], zf = scipy.signal.lfilter(
                [gam[j]], [1.0, gam[j] - 1.0], x[:, j, :], axis=0, zi=zi[j]
            )
            zi[j] = zf
        prev_p, prev_b = Yp[-1], Yb[-1]
        yield a, np.sqrt(np.sum((Z @ L) ** 2, axis=-1))


def standstill_series(
    model: ObserverModel,
    t: ArrayLike,
    dq: ArrayLike,
    options: ObserverOptions = DEFAULT_OPTIONS,
) -> NDArray[np.float64]:
    """The standstill margin (N, n) [N m] of the model's friction at the velocities ``dq``
    (N, n) [rad/s], through the observer's lag ``K_O/(s + K_O)`` over the times ``t`` (N,)
    [s] (module docstring): a bound of the residual that friction the model cannot know
    (inside its standstill band, within the velocity noise band of its smooth Coulomb
    steps: :func:`~dynid.observer.friction.standstill_margin`) leaves; zeros for a friction
    without either. The noise band is estimated on ``dq`` (one piece of a log).

    Raises
    ------
    ShapeError, NonFiniteError
        Bad shapes, NaN.
    """
    n = model.n
    ta = _checks.as_array("t", t)
    dqa = _checks.as_exact("dq", dq, (ta.shape[0], n))
    out = np.zeros((ta.shape[0], n))
    for a, m in standstill_blocks(model, ta, dqa, options):
        out[a : a + m.shape[0]] = m
    return out


def standstill_blocks(
    model: ObserverModel,
    t: NDArray[np.float64],
    dq: NDArray[np.float64],
    options: ObserverOptions = DEFAULT_OPTIONS,
    block: int | None = None,
) -> Iterator[tuple[int, NDArray[np.float64]]]:
    """:func:`standstill_series` of one piece ``t`` (N,), ``dq`` (N, n) (validated) a block
    of ``block`` samples (default :data:`_MARGIN_BLOCK`) at a time: ``(first sample, margin
    (m, n) [N m])``, only one block's temporaries held (a long log). The lag continues from
    block to block (its free response ``exp(-K_O (t - t_prev))`` added), as the whole
    piece's to rounding; a margin that is zero everywhere yields nothing."""
    N, n = dq.shape
    size = _MARGIN_BLOCK if block is None else int(block)
    bands = velocity_bands(model.friction, dq) if model.friction is not None else None
    gains = options.gains(n)
    prev: tuple[float, NDArray[np.float64], NDArray[np.float64]] | None = None
    for a in range(0, N, size):
        b = min(a + size, N)
        w = standstill_margin(model.friction, dq[a:b], bands)
        if prev is None and not np.any(w):
            continue  # zero so far: its lag is zero too
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
        yield a, y


#: Samples of the standstill margin computed at a time (about ten temporaries of a block).
_MARGIN_BLOCK = 1 << 16


def calibrate(
    residuals: Iterable[ArrayLike],
    options: ObserverOptions,
    *,
    std: Iterable[ArrayLike] | None = None,
    standstill: Iterable[ArrayLike] | None = None,
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
    if not margin >= 1.0 or not 0.0 < quantile <= 1.0 or not collision_factor >= 1.0:
        raise OptionError(
            f"margin >= 1, quantile in (0, 1] and collision factor >= 1 are needed; got "
            f"{margin}, {quantile}, {collision_factor}"
        )
    if not k_sigma > 0:
        raise OptionError(f"k_sigma must be > 0; got {k_sigma}")
    n_joints: int | None = None
    count, top, top_excess = 0, None, None
    outside = None
    kept: list[NDArray[np.float64]] = []  # quantile < 1: every sample's |r| (and excess)
    kept_excess: list[NDArray[np.float64]] = []
    stds = iter(std) if std is not None else None
    margins = iter(standstill) if standstill is not None else None
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
        excess = None
        if stds is not None:
            S = _checks.as_exact("std", _next(stds, "std"), R.shape)
            excess = np.clip(A - k_sigma * S, 0.0, None)
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
    )


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


def undetected_at_rest(model: ObserverModel, thresholds: Thresholds) -> NDArray[np.float64]:
    """Per joint (n,) [N m]: the contact torque below which a contact on a joint at rest
    inside its standstill band goes undetected, its standstill margin at rest (the
    friction's Coulomb level, which may hold any torque up to it without a motion) plus
    its contact threshold; the threshold alone for thresholds without the margin."""
    if not thresholds.standstill:
        return np.array(thresholds.contact)
    rest = standstill_margin(model.friction, np.zeros((1, model.n)))[0]
    return np.asarray(thresholds.contact + rest)


def threshold_series(
    thresholds: Thresholds,
    N: int,
    std: ArrayLike | None = None,
    standstill: ArrayLike | None = None,
) -> tuple[NDArray[np.float64], NDArray[np.float64]]:
    """The contact and collision thresholds at every sample, each (N, n) [N m]: fixed, or
    ``k sigma + nu`` (and its ``collision_factor`` multiple) when ``std`` (N, n) is given
    and the thresholds use the model's uncertainty; plus the standstill margin
    ``standstill`` (N, n) when given and the thresholds use it."""
    n = thresholds.n
    if std is not None and thresholds.uses_uncertainty:
        assert thresholds.k_sigma is not None and thresholds.noise is not None
        s = _checks.as_exact("std", std, (N, n))
        c = thresholds.k_sigma * s + thresholds.noise
        k = thresholds.collision_factor * c
    else:
        c = np.broadcast_to(thresholds.contact, (N, n)).copy()
        k = np.broadcast_to(thresholds.collision, (N, n)).copy()
    if standstill is not None and thresholds.standstill:
        w = _checks.as_exact("standstill", standstill, (N, n))
        c, k = c + w, k + w
    return c, k


def detect(
    t: ArrayLike,
    r: ArrayLike,
    thresholds: Thresholds,
    *,
    std: ArrayLike | None = None,
    standstill: ArrayLike | None = None,
    merge_s: float = 0.05,
    restarts: ArrayLike | None = None,
) -> list[ContactEvent]:
    """Contact events of a residual (module docstring).

    Parameters
    ----------
    t : array_like, shape (N,)
        Sample times [s].
    r : array_like, shape (N, n)
        Residual [N m]; NaN where the observer did not run (never an event there).
    thresholds : Thresholds
    std : array_like, shape (N, n), optional
        :func:`residual_std` of the samples (for thresholds that use the uncertainty).
    standstill : array_like, shape (N, n), optional
        :func:`standstill_series` of the samples (for thresholds that use it).
    merge_s : float
        Runs over the threshold closer than this [s] are one event (>= 0).
    restarts : array_like of int, optional
        Samples where the observer started again (the first of each piece of a log cut
        at its gaps): no event spans one.

    Returns
    -------
    list of ContactEvent
        In time order.

    Raises
    ------
    ShapeError
        Shapes that disagree, thresholds of another joint count.
    OptionError
        A negative ``merge_s``.
    """
    ta = _checks.as_array("t", t)
    N = ta.shape[0]
    ra = _checks.as_exact("r", r, (N, thresholds.n), allow_nonfinite=True)
    if np.any(np.isinf(ra)):
        raise ShapeError("r must be finite or NaN (not observed); got inf")
    if not merge_s >= 0:
        raise OptionError(f"merge_s must be >= 0 [s]; got {merge_s}")
    seen: NDArray[np.bool_] = np.all(np.isfinite(ra), axis=1)
    if std is not None:  # NaN where not observed, as r
        std = np.where(seen[:, None], np.asarray(std, dtype=np.float64), 0.0)
    ra = np.where(seen[:, None], ra, 0.0)
    contact, collision = threshold_series(thresholds, N, std, standstill)
    over = np.abs(ra) > contact
    hit = np.flatnonzero(over.any(axis=1))
    if hit.size == 0:
        return []
    split = ta[hit[1:]] - ta[hit[:-1]] > merge_s
    if restarts is not None:
        piece = np.searchsorted(np.asarray(restarts, dtype=np.int64), hit, side="right")
        split |= piece[1:] != piece[:-1]
    cut = np.flatnonzero(split) + 1
    events = []
    for run in np.split(hit, cut):
        a, b = int(run[0]), int(run[-1]) + 1
        seg = ra[a:b]
        k = np.argmax(np.abs(seg), axis=0)
        peak = seg[k, np.arange(seg.shape[1])]
        joints = tuple(int(j) + 1 for j in np.flatnonzero(over[a:b].any(axis=0)))
        level: Literal["contact", "collision"] = (
            "collision" if np.any(np.abs(seg) > collision[a:b]) else "contact"
        )
        events.append(
            ContactEvent(
                float(ta[a]), float(ta[b - 1]), joints, tuple(float(x) for x in peak), level
            )
        )
    return events
