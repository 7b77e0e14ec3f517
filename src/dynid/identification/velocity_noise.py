"""The white noise of logged velocities, its band, and the joints that move beyond it.

A joint whose velocity never leaves its noise band (fewer than 1 % of the samples beyond 5
times the robust noise level, :func:`velocity_noise_std`, and :data:`MIN_MOTION`) is
frozen: its friction cannot be identified (:func:`moving_joints`).

A signal without noise (a simulation) is told by differences of higher order
(:func:`smooth_noise_std`): a smooth motion's shrink by ``(2 pi f dt)`` an order, white
noise's keep its std; a column whose estimate falls to :data:`ROUND_OFF_SHARE` of its RMS
is exact to round-off (:func:`at_round_off`), and its noise is read as that
(:func:`signal_noise_std`).
"""

from __future__ import annotations

from collections.abc import Sequence

import numpy as np
from numpy.typing import ArrayLike, NDArray

from .. import _checks
from ..exceptions import ShapeError
from ..signals import MAD_TO_STD, robust_std

__all__ = [
    "MAX_DIFFERENCE_ORDER",
    "MIN_MOTION",
    "MOVING_FRACTION",
    "NOISE_BAND_STD",
    "PROBE_SAMPLES",
    "ROUND_OFF_SHARE",
    "at_round_off",
    "moving_joints",
    "noise_band",
    "pieces_noise_std",
    "signal_noise_std",
    "smooth_noise_std",
    "velocity_noise_std",
]

#: Width of the velocity noise band, in standard deviations of the velocity noise.
NOISE_BAND_STD = 5.0
#: Smallest velocity [rad/s] (m/s for a prismatic joint) counted as motion, whatever the
#: noise: below it no friction law can be told apart (noise-free logs of a frozen joint).
MIN_MOTION = 1e-3
#: Fraction of the samples that must lie outside the noise band for a joint to move.
MOVING_FRACTION = 0.01
#: Highest order of the differences :func:`smooth_noise_std` reads: a motion of 1 Hz at
#: 200 Hz falls below 1e-15 of its amplitude by the 8th (simulated arms: 6e-16 of the
#: torques' RMS from the 9th on), while white noise's difference of order 10 holds the
#: noise times 427 (``sqrt(C(20, 10))``), still far within float64.
MAX_DIFFERENCE_ORDER = 10
#: Samples :func:`at_round_off` reads first: a column with noise there is not exact, and
#: the whole column is read only when they are (a long measured log costs no more).
PROBE_SAMPLES = 2048
#: The white noise, as a share of a column's RMS, at or below which the column is exact to
#: round-off (:func:`at_round_off`): float64's rounding is 1.1e-16 of a value, a noise-free
#: simulation reads 6e-16 to 8e-16, a CSV of 9 significant digits 3e-10 and any sensor more.
ROUND_OFF_SHARE = 1e-12
#: Samples per block :func:`at_round_off` reads on its own besides the whole column: a
#: stretch of noise of half a block or more makes its block's median, and the column, not
#: exact (a log exact but for 1 s of noise in 5 s at 200 Hz read exact from its medians).
ROUND_OFF_BLOCK = 64


#: Elements of the differences :func:`velocity_noise_std` takes the medians of at once
#: (joints together up to this, one joint of a longer log at a time: 8 MB of temporaries).
_MEDIAN_ELEMENTS = 1 << 20


def velocity_noise_std(dq: ArrayLike, t: ArrayLike | None = None) -> NDArray[np.float64]:
    """Std [rad/s] (n,) of the white noise on velocity samples ``dq`` (N, n), robustly.

    .. math:: \\hat\\sigma_j = 1.4826 \\, \\min\\big(\\mathrm{MAD}(\\Delta^2 \\dot q_j) / \\sqrt 6,
              \\; \\mathrm{MAD}(\\Delta^3 \\dot q_j) / \\sqrt{20}\\big)

    The second and third differences of white noise of std ``sigma`` have std
    ``sqrt(6) sigma`` and ``sqrt(20) sigma``, while those of a smooth motion sampled fast
    are far smaller, the third smaller than the second: the smaller of the two estimates
    leaves a noise-free log (a simulation) with a band near zero. The median absolute
    deviation (scaled to a std for Gaussian noise) ignores the few steps of a fast reversal. Give
    the measured velocities: a low-pass filter hides the noise from this estimate.

    Samples at uneven times ``t`` (jitter, dropped samples): the differences become the
    residuals of each sample from the line through its two neighbours and from the
    parabola through the previous one and the next two, at their own times (Lagrange),
    each scaled to the noise's std; on even times they are the differences above. The
    differences of unevenly timed samples hold the motion itself (an xArm7 at 100 Hz,
    stamps +-2 ms: torque noise read 0.07 N m for 0.05). Residuals across a step back in
    time (logs joined) are left out.

    Parameters
    ----------
    dq : array_like, shape (N, n)
        Measured joint velocities [rad/s], N >= 3.
    t : array_like, shape (N,), optional
        The samples' times [s]; default: evenly spaced.

    Returns
    -------
    ndarray, shape (n,)

    Raises
    ------
    ShapeError
        ``dq`` not of shape (N, n) with N >= 3.
    """
    a = _checks.as_array("dq", dq)
    if a.ndim != 2 or a.shape[0] < 3:
        raise ShapeError(f"dq must have shape (N, n), N >= 3; got {a.shape}")
    if t is not None:
        tt = _checks.as_array("t", t)
        if tt.shape != (a.shape[0],):
            raise ShapeError(f"t must have shape ({a.shape[0]},) like dq's rows; got {tt.shape}")
        dt = np.diff(tt)
        h = float(np.median(dt))
        if not (h > 0 and np.all(np.abs(dt - h) <= 1e-6 * h)):  # pieces joined: uneven too
            return _uneven_noise_std(a, tt)
    est = []
    for order, var in ((2, 6.0), (3, 20.0)):
        if a.shape[0] <= order:  # three samples: no third difference
            continue
        mad = np.empty(a.shape[1])
        w = max(1, _MEDIAN_ELEMENTS // a.shape[0])  # joints at a time: bounded temporaries
        for j in range(0, a.shape[1], w):
            d = np.diff(a[:, j : j + w], n=order, axis=0)
            d -= np.median(d, axis=0)
            mad[j : j + w] = np.median(np.abs(d, out=d), axis=0)
        est.append(MAD_TO_STD * mad / np.sqrt(var))
    out: NDArray[np.float64] = np.minimum.reduce(est)
    return out


def smooth_noise_std(x: ArrayLike) -> NDArray[np.float64]:
    """The white-noise std (n,) of the evenly sampled columns of ``x`` (N, n) read from
    differences of every order 2 to :data:`MAX_DIFFERENCE_ORDER`, the smallest estimate.

    .. math:: \\hat\\sigma_j = 1.4826 \\min_{k} \\mathrm{MAD}(\\Delta^k x_j) / \\sqrt{C(2k, k)}

    White noise's difference of order ``k`` has std ``sqrt(C(2k, k)) sigma`` at every
    order; a smooth motion's shrinks by ``2 pi f dt`` an order, so that the estimate of a
    noise-free signal falls to its rounding. On noisy data it reads the noise as
    :func:`velocity_noise_std` does, a little lower (the least of more estimates): it
    tells round-off (:func:`at_round_off`), it does not replace that estimate. Raises
    as :func:`velocity_noise_std` (N >= 3; fewer orders than ``N - 1`` are read).
    """
    a = _checks.as_array("x", x)
    if a.ndim != 2 or a.shape[0] < 3:
        raise ShapeError(f"x must have shape (N, n), N >= 3; got {a.shape}")
    return _differences_noise(a)


def _differences_noise(a: NDArray[np.float64]) -> NDArray[np.float64]:
    """:func:`smooth_noise_std` of each stack of ``a`` (..., N, n) along its samples
    (axis -2): (..., n)."""
    from math import comb

    d = a
    out = np.full(a.shape[:-2] + a.shape[-1:], np.inf)
    for order in range(1, min(MAX_DIFFERENCE_ORDER, a.shape[-2] - 1) + 1):
        d = np.diff(d, axis=-2)
        if order < 2:
            continue
        out = np.minimum(out, robust_std(d, axis=-2) / np.sqrt(comb(2 * order, order)))
    return out


def at_round_off(x: ArrayLike, t: ArrayLike | None = None) -> NDArray[np.bool_]:
    """Which columns (n,) of ``x`` (N, n), sampled at the times ``t`` (N,) [s], hold no
    noise beyond round-off: :func:`smooth_noise_std` at most :data:`ROUND_OFF_SHARE` of
    the column's RMS, over its first :data:`PROBE_SAMPLES` samples and then over all, and
    over each block of :data:`ROUND_OFF_BLOCK` consecutive samples. None at uneven times
    (jitter, gaps: the differences hold the motion) nor with fewer than 4 samples. The
    medians read the majority of each block's samples (a few steps of Coulomb friction at
    reversals do not count): a stretch of noise shorter than half a block may read exact.
    Raises as :func:`velocity_noise_std`."""
    a = _checks.as_array("x", x)
    if a.ndim != 2:
        raise ShapeError(f"x must have shape (N, n), N >= 3; got {a.shape}")
    if a.shape[0] < 4 or not np.all(np.isfinite(a)):
        return np.zeros(a.shape[1], dtype=bool)
    if t is not None:
        dt = np.diff(_checks.as_array("t", t))
        h = float(np.median(dt))
        if not (h > 0 and np.all(np.abs(dt - h) <= 1e-6 * h)):
            return np.zeros(a.shape[1], dtype=bool)
    out = _round_off(a[:PROBE_SAMPLES])  # a noisy log told from its first samples
    if a.shape[0] > PROBE_SAMPLES and out.any():
        out[out] = _round_off(a[:, out])
    return out


def _round_off(a: NDArray[np.float64]) -> NDArray[np.bool_]:
    """:func:`at_round_off` of the evenly sampled columns of ``a`` (N, n), N >= 4."""
    rms = np.sqrt(np.mean(np.square(a), axis=0))
    out: NDArray[np.bool_] = smooth_noise_std(a) <= ROUND_OFF_SHARE * rms
    if out.any() and a.shape[0] >= 2 * ROUND_OFF_BLOCK:
        out[out] = _blocks_noise_std(a[:, out]) <= ROUND_OFF_SHARE * rms[out]
    return out


def _blocks_noise_std(a: NDArray[np.float64]) -> NDArray[np.float64]:
    """The largest over the blocks of :data:`ROUND_OFF_BLOCK` consecutive samples of ``a``
    (N, n) (the last partial block left out) of :func:`smooth_noise_std` of each (n,)."""
    nb = a.shape[0] // ROUND_OFF_BLOCK
    blocks = a[: nb * ROUND_OFF_BLOCK].reshape(nb, ROUND_OFF_BLOCK, a.shape[1])
    out: NDArray[np.float64] = _differences_noise(blocks).max(axis=0)
    return out


def signal_noise_std(x: ArrayLike, t: ArrayLike | None = None) -> NDArray[np.float64]:
    """:func:`velocity_noise_std` of ``x`` (N, n) at the times ``t`` (N,) [s], but
    :func:`smooth_noise_std` on the columns exact to round-off (:func:`at_round_off`):
    the noise of a noise-free simulation is its rounding, where the differences of order 2
    and 3 read the motion (a geared arm's torques at 200 Hz: 6e-7 of their RMS). On a
    column with noise the two are the same numbers."""
    out = velocity_noise_std(x, t)
    exact = at_round_off(x, t)
    if exact.any():
        out = np.where(exact, smooth_noise_std(x), out)
    return out


def pieces_noise_std(
    pieces: Sequence[tuple[NDArray[np.float64], NDArray[np.float64]]],
) -> NDArray[np.float64]:
    """The white-noise std (n,) of the columns of several pieces ``(t, x)`` (times (N_k,)
    [s], samples (N_k, n)) read as one signal: :func:`velocity_noise_std` of the pieces
    joined (the differences across their joins left out), but a column exact to round-off
    in every piece of at least 4 samples (:func:`at_round_off`) read as its rounding: the
    largest piece's :func:`smooth_noise_std`, at least float64's epsilon times the
    column's RMS.

    The differences of order 2 and 3 read a noise-free motion itself (a geared arm's motor
    velocities at 200 Hz: 2e-5 rad/s for velocities of 40 rad/s RMS), and a standstill
    band of 5 times that switched the Coulomb torque off at a sample that moved (1e-5
    rad/s), an error 1e9 times the round-off of the rest. Raises :class:`ShapeError` when
    the pieces joined have fewer than 3 samples.
    """
    t = np.concatenate([np.asarray(tk, dtype=np.float64) for tk, _ in pieces])
    x = np.concatenate([np.asarray(xk, dtype=np.float64) for _, xk in pieces])
    out = velocity_noise_std(x, t)
    long = [(tk, xk) for tk, xk in pieces if xk.shape[0] >= 4]
    if not long:
        return out
    exact = np.logical_and.reduce([at_round_off(xk, tk) for tk, xk in long])
    if exact.any():
        rounding = np.max([smooth_noise_std(xk[:, exact]) for _, xk in long], axis=0)
        floor = np.finfo(np.float64).eps * np.sqrt(np.mean(np.square(x[:, exact]), axis=0))
        out[exact] = np.maximum(rounding, floor)
    return out


def _uneven_noise_std(a: NDArray[np.float64], t: NDArray[np.float64]) -> NDArray[np.float64]:
    """:func:`velocity_noise_std` of ``a`` (N, n) sampled at the uneven times ``t`` (N,)."""
    est = []
    for nodes in ((-1, 1), (-1, 1, 2)):
        lo, hi = -min(nodes), max(nodes)
        i = np.arange(lo, a.shape[0] - hi)
        if i.size == 0:
            continue
        ti = t[i]
        tk = [t[i + k] for k in nodes]
        w = []
        for k, tn in enumerate(tk):
            wk = np.ones_like(ti)
            for m, tm in enumerate(tk):
                if m != k:
                    with np.errstate(divide="ignore", invalid="ignore"):
                        wk *= (ti - tm) / (tn - tm)
            w.append(wk)
        times = np.stack([t[i + k] for k in range(-lo, hi + 1)])
        ok = np.all(np.diff(times, axis=0) > 0, axis=0)
        if not ok.any():
            continue
        scale = np.sqrt(1.0 + sum(x**2 for x in w))[ok]
        mad = np.empty(a.shape[1])
        for j in range(a.shape[1]):
            r = a[i, j] - sum(wk * a[i + k, j] for wk, k in zip(w, nodes, strict=True))
            r = r[ok] / scale
            r -= np.median(r)
            mad[j] = np.median(np.abs(r))
        est.append(MAD_TO_STD * mad)
    out: NDArray[np.float64] = np.minimum.reduce(est) if est else np.zeros(a.shape[1])
    return out


def noise_band(noise_std: ArrayLike) -> NDArray[np.float64]:
    """The velocity noise band [rad/s]: ``NOISE_BAND_STD * noise_std``.

    Joints whose velocity stays inside it (or below :data:`MIN_MOTION`) do not move
    (:func:`moving_joints`), and friction laws do not switch Coulomb friction on inside it
    (:mod:`dynid.friction.laws.base`).

    Parameters
    ----------
    noise_std : array_like, shape (n,) or scalar
        White-noise std of the measured velocities [rad/s] (:func:`velocity_noise_std`).

    Returns
    -------
    ndarray, same shape as ``noise_std``
    """
    out: NDArray[np.float64] = NOISE_BAND_STD * np.asarray(noise_std, dtype=np.float64)
    return out


def moving_joints(dq: ArrayLike, noise_std: ArrayLike | None = None) -> NDArray[np.bool_]:
    """Which joints move beyond their velocity noise band (n,) bool.

    A joint moves when more than :data:`MOVING_FRACTION` of its samples ``|dq|`` exceed
    ``max(NOISE_BAND_STD * noise_std, MIN_MOTION)``.

    Parameters
    ----------
    dq : array_like, shape (N, n)
        Joint velocities [rad/s] (filtered or not).
    noise_std : array_like, shape (n,) or scalar, optional
        White-noise std of the measured velocities [rad/s]; default
        :func:`velocity_noise_std` of ``dq`` (right for unfiltered velocities).

    Returns
    -------
    ndarray of bool, shape (n,)

    Raises
    ------
    ShapeError
        ``dq`` not of shape (N, n) with N >= 3, or ``noise_std`` of another joint count.
    """
    a = _checks.as_array("dq", dq)
    if a.ndim != 2 or a.shape[0] < 3:
        raise ShapeError(f"dq must have shape (N, n), N >= 3; got {a.shape}")
    sd = velocity_noise_std(a) if noise_std is None else _checks.as_array("noise_std", noise_std)
    sd = np.broadcast_to(sd, (a.shape[1],)) if sd.ndim == 0 else sd
    if sd.shape != (a.shape[1],):
        raise ShapeError(f"noise_std must have shape ({a.shape[1]},); got {sd.shape}")
    band = np.maximum(noise_band(sd), MIN_MOTION)
    level = np.array(
        [np.quantile(np.abs(a[:, j]), 1.0 - MOVING_FRACTION) for j in range(a.shape[1])]
    )
    out: NDArray[np.bool_] = level > band
    return out
