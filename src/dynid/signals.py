"""Signal conditioning of measured time series: resampling, zero-phase filtering, derivatives.

Time series are ``t`` (N,) [s] and signals (N, ...) with time along axis 0.

Pipeline used for torque logs (Gaz et al. 2019, Sec. VI; Swevers et al. 1997):

1. :func:`resample_uniform`: a log with jittered or missing timestamps is interpolated
   (linearly, per column) onto a uniform grid ``t0 + k / fs``. Digital filters assume
   uniform sampling; at 1 kHz the interpolation error of a signal band-limited to a few
   Hz is far below sensor noise. The recorded timestamps are taken as the true sample
   times.
2. :func:`lowpass`: a Butterworth low-pass applied forward and backward
   (:mod:`dynid.butterworth`, as ``scipy.signal.sosfiltfilt``). The designed ``order``
   (default 4, as in the paper) is applied twice, so the magnitude response is the square
   of the order-4 response: effectively order 8, -6 dB (not -3 dB) at the cutoff, zero
   phase (no lag).
3. :func:`derivative`: second-order accurate central differences
   (``numpy.gradient(..., edge_order=2)``), valid on non-uniform grids, e.g. the
   acceleration from the filtered velocity.
4. :func:`trim_edges`: the first and last samples carry the filter's start-up
   transient and one-sided differences. :func:`lowpass` continues each end with the
   cubic polynomial fitted to its last period of the cut-off (value, slope, curvature and
   jerk carried on, so that the filter meets no corner there). :func:`edge_seconds`
   gives the default amount trimmed at each end: :data:`EDGE_PERIODS` (two) periods of
   the cut-off, where the edge error of a signal up to a third of the cut-off is about
   1e-4 of its amplitude; or, for a motion a decade below the cut-off (the cut-off read
   from the motion, :mod:`dynid.identification.rate`), :data:`MOTION_EDGE_PERIODS` (half
   a period), where the accelerations derived from the filtered velocities err as much
   as in the interior (1e-4 of their scale without noise; at the end sample about 1e-3,
   where the odd extension of one period alone left 5-15 %, decaying over two periods).
   A log cut into pieces of a few tenths of a second then keeps most of each piece.
"""

from __future__ import annotations

import numpy as np
from numpy.typing import ArrayLike, NDArray

from . import _checks
from .butterworth import butter_sos, zero_phase
from .exceptions import DataError, ShapeError

__all__ = [
    "BUTTERWORTH_ORDER",
    "DECADE_TOLERANCE",
    "EDGE_PERIODS",
    "EXACT_DERIVATIVE_ORDER",
    "MAD_TO_STD",
    "MOTION_EDGE_PERIODS",
    "below_nyquist",
    "derivative",
    "exact_derivative",
    "derivative_noise_gain",
    "edge_seconds",
    "filtered_derivative",
    "grid_steps",
    "is_uniform",
    "lowpass",
    "lowpass_noise_gain",
    "resample_uniform",
    "robust_std",
    "sample_rate",
    "stamp_resolution",
    "trim_edges",
]

#: Designed order of the Butterworth low-pass (Gaz et al. 2019); applied forward and
#: backward, so the effective order is twice this.
BUTTERWORTH_ORDER = 4

#: Periods of the cut-off trimmed at each end after filtering (:func:`edge_seconds`) when
#: nothing is known of the signal's frequencies (module docstring).
EDGE_PERIODS = 2.0

#: Periods trimmed at each end of a motion a decade (or more) below the cut-off: with the
#: ends continued by their cubic (:func:`lowpass`), the accelerations derived from its
#: filtered velocities are there as accurate as in the interior (module docstring).
MOTION_EDGE_PERIODS = 0.5

#: Relative tolerance of "a decade below" (:func:`edge_seconds`): an automatic cut-off is
#: exactly 10 times its recordings' motion frequency, and another recording of the same
#: excitation reads that frequency to about 1e-6, so a tie decided by round-off gave the
#: same log half a period or two trimmed by models whose cut-offs differed in the sixth
#: digit (5.349790 and 5.349801 Hz: 4840 and 4951 samples validated).
DECADE_TOLERANCE = 1e-3

#: Periods of the cut-off over which each end's cubic is fitted, and by which it
#: continues the signal (beyond it, the odd extension of one period).
_FIT_PERIODS, _EXTEND_PERIODS = 1.0, 3.0


def _time(t: ArrayLike, name: str = "t") -> NDArray[np.float64]:
    t = _checks.as_array(name, t)
    if t.ndim != 1 or t.shape[0] < 2:
        raise ShapeError(f"{name} must have shape (N,) with N >= 2; got {t.shape}")
    dt = np.diff(t)
    bad = np.flatnonzero(dt <= 0)
    if bad.size:
        k = int(bad[0])
        raise DataError(
            f"{name} must be strictly increasing; got {name}[{k}] = {float(t[k])!r} and "
            f"{name}[{k + 1}] = {float(t[k + 1])!r}; hint: clean the log (TorqueLog.from_raw)"
        )
    return t


#: A Gaussian's standard deviation over its median absolute deviation: the robust noise
#: level of the checks and robust estimators (a sample far off moves it by one rank).
MAD_TO_STD = 1.4826


def robust_std(x: ArrayLike, axis: int | None = None) -> NDArray[np.float64]:
    """Robust standard deviation of ``x`` along ``axis`` (all of it for ``None``), in the
    unit of ``x``: :data:`MAD_TO_STD` times the median absolute deviation about the median;
    0 for an empty ``x``. Of differences of consecutive independent samples, divide by
    ``sqrt(2)`` for the samples' own."""
    a = np.asarray(x, dtype=np.float64)
    if a.size == 0:
        return np.zeros(() if axis is None else np.delete(a.shape, axis))
    med = np.median(a, axis=axis, keepdims=True)
    return np.asarray(MAD_TO_STD * np.median(np.abs(a - med), axis=axis), dtype=np.float64)


def sample_rate(t: ArrayLike) -> float:
    """Nominal sample rate [Hz] of timestamps ``t`` (N,) [s], robust to jitter and gaps.

    Each step is counted as ``m_i = round(dt_i / h0)`` nominal periods, with ``h0`` the
    median step (a gap of dropped samples counts as several periods); the period is the
    least-squares slope of ``t`` against the cumulative count, whose error falls as
    ``N^-1.5``. When some step lies far from a whole number of periods (``|dt_i / h0 -
    m_i| > 0.4``: jitter too large to count periods by steps), each stamp is given its
    place on the grid instead (:func:`_grid_indices`, on the runs between gaps longer
    than :data:`_RUN_GAP` periods), and the period is the slope of the stamps against
    those places, pooled over the runs. For uniform ``t`` both give ``1 / dt``.

    The median of the steps errs as ``1.25 sigma_dt / sqrt(N)`` and is biased by dropped
    samples (1 kHz stamps with Gaussian jitter of 0.2 ms, 2 % dropped, 5 million of them:
    998.43 Hz, the grid 1000.0000 Hz); it is kept for a jitter beyond
    :data:`_GRID_JITTER` periods, where the grid's indices slip.
    """
    t = _time(t)
    m = np.diff(t)
    h0 = float(np.median(m))
    m /= h0  # in place (and below): a long log's temporaries are a few columns, not seven
    whole = np.round(m)
    np.subtract(m, whole, out=m)
    counted = bool(np.all(np.abs(m, out=m) <= 0.4) and np.all(whole >= 1))
    del m
    if counted:
        kc = np.empty(t.shape[0])
        kc[0] = 0.0
        np.cumsum(whole, out=kc[1:])
        del whole
        kc -= kc.mean()
        h = float(kc @ (t - t.mean()) / (kc @ kc))
    else:
        h = _lattice_period(t, h0)
    return 1.0 / h


#: Steps longer than this many median steps split the stamps into runs, each placed on
#: its own grid: a pause that is no whole number of periods (logs joined) does not shift
#: the grid of the stamps after it. (Shorter, it would split at drops whose jitter makes
#: them long: each run's ends biased, and short runs.)
_RUN_GAP = 10.0
#: Stamps of the first run whose grid is found by scanning periods (:func:`_grid_indices`).
_FIRST_BLOCK = 256
#: Stamp jitter (std, in periods) up to which the stamps are placed on a grid; beyond,
#: an index is often a period off and the median step errs less (Gaussian jitter of 0.3
#: periods: up to 12 % on 4000 stamps, the median 2.5 %). A grid whose period is more
#: than 5 % from the median step's is not taken either.
_GRID_JITTER = 0.25


def _lattice_period(t: NDArray[np.float64], h0: float) -> float:
    """The period [s] of stamps ``t`` (N,) whose steps are too jittered to count: the
    least-squares slope of the stamps against their grid indices (:func:`_grid_indices`),
    pooled over the runs between steps longer than :data:`_RUN_GAP` ``h0`` (each run its
    own offset; the longest first); the median of the steps within ``(0.5, 1.5) h0`` when
    no run has three stamps or the stamps' jitter exceeds :data:`_GRID_JITTER` periods
    (read from the steps' median absolute deviation)."""
    dt = np.diff(t)
    median = float(np.median(dt[(dt > 0.5 * h0) & (dt < 1.5 * h0)]))
    jitter = MAD_TO_STD * float(np.median(np.abs(dt - h0))) / np.sqrt(2.0)
    if jitter > _GRID_JITTER * h0:
        return median
    cuts = np.concatenate([[0], np.flatnonzero(dt > _RUN_GAP * h0) + 1, [t.size]])
    runs = sorted(zip(cuts[:-1], cuts[1:], strict=True), key=lambda r: int(r[0] - r[1]))
    num = den = 0.0
    h: float | None = None  # the period: scanned on the longest run, then as fitted
    for a, b in runs:
        if b - a < 3:
            break
        n = _grid_indices(t[a:b] - t[a], h0 if h is None else h, scan=h is None)
        n -= n.mean()
        num += float(n @ (t[a:b] - t[a:b].mean()))
        den += float(n @ n)
        h = num / den
    return median if h is None or abs(h / median - 1.0) > 0.05 else h


def _grid_indices(s: NDArray[np.float64], h: float, scan: bool = True) -> NDArray[np.float64]:
    """The grid index of each stamp ``s`` (N,) [s] (from 0 at the first) of a run whose
    period is about ``h`` (within 10 %; ``scan`` False: ``h`` fitted already on a run
    before), dropped samples skipped.

    The first :data:`_FIRST_BLOCK` stamps give the period that puts them nearest to a
    grid (``scan``: the largest ``|sum_k exp(2 pi i s_k / h)|`` over periods within 10 %
    of ``h``, no index needed) and the grid's offset (its phase); then, on a prefix
    doubled each time, the stamps are rounded to that grid and the period and offset
    refitted by least squares, whose error over ``L`` stamps (``sqrt(12) sigma / L^1.5``
    for a jitter ``sigma``) moves the grid by a fraction of a period only well beyond
    ``2 L``. Each index is right while the stamp's own jitter stays within half a period;
    beyond, it is one off, either way alike.
    """
    L = min(s.size, _FIRST_BLOCK)
    block = s[:L]
    if scan:
        periods = h * (1.0 + np.arange(-0.1, 0.1, 0.25 / L))
        power = np.abs(np.exp(2j * np.pi * block[None, :] / periods[:, None]).sum(axis=1))
        h = float(periods[np.argmax(power)])
    offset = h * float(np.angle(np.exp(2j * np.pi * block / h).sum())) / (2 * np.pi)
    while True:
        n = np.round((s[:L] - offset) / h)
        nc = n - n.mean()
        h = float(nc @ (s[:L] - s[:L].mean()) / (nc @ nc))
        offset = float(s[:L].mean() - h * n.mean())
        if L == s.size:
            out: NDArray[np.float64] = np.round((s - offset) / h)
            return out
        L = min(2 * L, s.size)


def grid_steps(t: ArrayLike) -> tuple[NDArray[np.int64], float, float]:
    """The nominal periods each step of stamps ``t`` (N,) [s] spans, the period [s] and the
    jitter of the stamps about their grid (standard deviation [s]).

    A step spanning 2 periods or more holds dropped samples; one spanning 1 is a sample
    after the last, however jittered. Steps are counted against the stamps' grid, not
    their own length: at 100 Hz with stamps jittered by 2 ms (std), 3.8 % of the steps are
    longer than 1.5 periods with no sample dropped. The period is :func:`sample_rate`'s.
    When every step lies within 0.4 of a period of a whole number, each is rounded.
    Otherwise, on each run between steps over :data:`_RUN_GAP` periods (those rounded):
    with a jitter (read from the steps' distance to whole periods, which the dropped
    samples' steps do not widen) up to :data:`_ROUND_JITTER` periods, each stamp is given
    its place on the run's grid (:func:`_grid_indices`); beyond, the stamps' lag behind a
    grid without drops (in periods) is a staircase rising by one at each dropped sample,
    blurred by the jitter: its mean over :data:`_SMOOTH` stamps, rounded, counts the drops
    (a jitter of 0.25 periods errs by 0.06 there), and each rise is put, a drop at a time,
    on the step near it longest beyond the periods it holds, one holding drops already
    favoured by half a period (a gap is more likely than two side by side; two gaps within
    :data:`_SMOOTH` stamps stay two). With a jitter beyond :data:`_GRID_JITTER` periods
    each step is rounded to whole periods (at least 1). The jitter is that of the stamps
    about the grid fitted to each run (its own offset); 0 for fewer than 3 stamps.

    Returns
    -------
    steps : ndarray of int64, shape (N - 1,)
        Periods each step spans (1: no sample dropped).
    period : float
        The period [s] (``1 / sample_rate(t)``).
    jitter : float
        Standard deviation of the stamps about their grid [s].
    """
    t = _time(t)
    dt = np.diff(t)
    h = 1.0 / sample_rate(t)
    m = dt / h
    steps = np.maximum(np.round(m), 1).astype(np.int64)
    if t.size < 3:
        return steps, h, 0.0
    frac = m - np.round(m)
    counted = bool(np.all(np.abs(frac) <= 0.4))
    jitter = MAD_TO_STD * float(np.median(np.abs(dt - h))) / np.sqrt(2.0)
    if not counted and jitter <= _GRID_JITTER * h:
        # the steps' distance to whole periods: the jitter without the dropped samples' steps
        rounded = MAD_TO_STD * float(np.median(np.abs(frac))) / np.sqrt(2.0) <= _ROUND_JITTER
        cuts = np.concatenate([[0], np.flatnonzero(m > _RUN_GAP) + 1, [t.size]])
        for a, b in zip(cuts[:-1], cuts[1:], strict=True):
            if b - a >= 3 and rounded:
                steps[a : b - 1] = _index_steps(_grid_indices(t[a:b] - t[a], h, scan=False))
            elif b - a >= 3:
                steps[a : b - 1] = _run_steps(t[a:b], h)
    place = np.concatenate([[0], np.cumsum(steps)]) * h
    r = t - place
    cuts = np.concatenate([[0], np.flatnonzero(steps > _RUN_GAP) + 1, [t.size]])
    for a, b in zip(cuts[:-1], cuts[1:], strict=True):
        r[a:b] -= r[a:b].mean()
    return steps, h, float(np.std(r))


def _index_steps(n: NDArray[np.float64]) -> NDArray[np.int64]:
    """Periods each step spans from the stamps' indices ``n`` (L,) on their grid.

    A stamp jittered past half a period is rounded onto its neighbour's index: its steps
    read 2 then 0 (or 0 then 2), which is no dropped sample but one stamp late (early).
    Each step of 0 takes a period from the step of 2 or more beside it (the one before
    first), so that the steps sum to the periods the stamps span; a step of 0 with none
    beside it counts as 1. A stamp jittered by 0.15 periods (std) lies past half a period
    about once in 2000 (a 3.3 sigma excursion); each had counted as a dropped sample and
    moved the grid by a period from there on, its jitter read near half a period.
    """
    d = np.diff(n).astype(np.int64)
    for j in np.flatnonzero(d <= 0):
        if j > 0 and d[j - 1] >= 2:
            d[j - 1] -= 1
            d[j] += 1
        elif j + 1 < d.size and d[j + 1] >= 2:
            d[j + 1] -= 1
            d[j] += 1
    return np.maximum(d, 1)


#: Stamps over which :func:`grid_steps` averages the stamps' lag behind the grid.
_SMOOTH = 16
#: Stamp jitter (std, in periods, read from the steps' distance to whole periods) up to
#: which :func:`grid_steps` rounds each stamp to its run's grid (an index one off at a
#: stamp in 1e3 at 0.15 periods) rather than counting drops on the smoothed lag, which
#: merges gaps within :data:`_SMOOTH` stamps of each other into one.
_ROUND_JITTER = 0.15


def _run_steps(s: NDArray[np.float64], h: float) -> NDArray[np.int64]:
    """Periods each step of a run of stamps ``s`` (L >= 3,) [s] spans at the period ``h``
    [s] (:func:`grid_steps`)."""
    L = s.size
    lag = (s - s[0]) / h - np.arange(L)  # periods: one more after each dropped sample
    lag -= float(np.angle(np.exp(2j * np.pi * lag).mean())) / (2 * np.pi)
    w = min(_SMOOTH, L)
    cs = np.concatenate([[0.0], np.cumsum(lag)])
    lo = np.clip(np.arange(L) - w // 2, 0, L - w)
    drops = np.maximum.accumulate(np.round((cs[lo + w] - cs[lo]) / w))
    steps = 1 + np.diff(drops).astype(np.int64)
    m = np.diff(s) / h
    for i in np.flatnonzero(steps > 1):  # the mean rises over w stamps: the long step,
        a, b = max(0, int(i) - w), min(L - 1, int(i) + w + 1)  # one holding drops first
        rise, steps[i] = steps[i] - 1, 1
        for _ in range(rise):  # a drop at a time: two gaps near each other stay two
            room = m[a:b] - steps[a:b] + 0.5 * (steps[a:b] > 1)
            steps[a + int(np.argmax(room))] += 1
    return steps


def is_uniform(t: ArrayLike, *, rtol: float = 1e-6) -> bool:
    """True when every step of ``t`` (N,) equals the median step within ``rtol`` of it, or
    within the stamps' own resolution (:func:`stamp_resolution`: epoch stamps in seconds,
    1.7e9 s, hold steps to 2.4e-7 s, 6e-5 of the exact 4 ms steps of a 250 Hz log)."""
    t = _time(t)
    dt = np.diff(t)
    h = np.median(dt)
    return bool(np.all(np.abs(dt - h) <= max(rtol * h, stamp_resolution(t))))


def stamp_resolution(t: ArrayLike) -> float:
    """The resolution [s] of float stamps ``t`` (N,): 4 units in the last place of the
    largest in magnitude (a step between two stamps errs by up to 2 of them)."""
    t = np.asarray(t, dtype=np.float64)
    if t.size == 0:
        return 0.0
    return 4.0 * float(np.spacing(max(abs(float(t[0])), abs(float(t[-1])))))


def resample_uniform(
    t: ArrayLike, x: ArrayLike, fs: float | None = None
) -> tuple[NDArray[np.float64], NDArray[np.float64]]:
    """Linear interpolation of a signal onto a uniform time grid.

    Parameters
    ----------
    t : array_like, shape (N,)
        Strictly increasing sample times [s] (jittered, possibly with gaps).
    x : array_like, shape (N, ...)
        Signal values at ``t``; each column is interpolated independently.
    fs : float, optional
        Sample rate of the new grid [Hz]; default :func:`sample_rate` of ``t``.

    Returns
    -------
    t_uniform : ndarray, shape (M,)
        ``t[0] + k / fs`` for ``k = 0 .. M-1``, the last one not after ``t[-1]``.
    x_uniform : ndarray, shape (M, ...)

    Raises
    ------
    ShapeError
        ``t`` not 1-D, or ``x`` does not have ``N`` rows.
    DataError
        ``t`` not strictly increasing.
    NonFiniteError
        NaN or inf in ``t`` or ``x``.

    Notes
    -----
    Linear interpolation attenuates a sinusoid of frequency ``f`` by at most
    ``(pi f / fs)^2 / 2`` (relative): 5e-5 at 3 Hz and 1 kHz. Gaps (dropped samples) are
    bridged by straight lines; callers bound the gap length (``max_gap_s`` of
    :func:`dynid.identification.prepare.prepare_log`).
    """
    t = _time(t)
    x = _checks.as_array("x", x)
    if x.ndim < 1 or x.shape[0] != t.shape[0]:
        raise ShapeError(f"x must have shape ({t.shape[0]}, ...) like t; got {x.shape}")
    fs = sample_rate(t) if fs is None else float(fs)
    if not fs > 0:
        raise DataError(f"fs must be positive; got {fs}")
    m = int(np.floor((t[-1] - t[0]) * fs * (1.0 + 1e-12))) + 1
    tu = t[0] + np.arange(m) / fs
    flat = x.reshape(x.shape[0], -1)
    out = np.empty((m, flat.shape[1]))
    for k in range(flat.shape[1]):
        out[:, k] = np.interp(tu, t, flat[:, k])
    return tu, out.reshape((m,) + x.shape[1:])


def lowpass(
    x: ArrayLike,
    fs: float,
    cutoff_hz: float,
    *,
    order: int = BUTTERWORTH_ORDER,
    axis: int = 0,
) -> NDArray[np.float64]:
    """Zero-phase Butterworth low-pass filter (forward-backward).

    .. math:: |H_{zp}(f)| = |H_B(f)|^2 = \\frac{1}{1 + (f / f_c)^{2 \\cdot order}}

    Parameters
    ----------
    x : array_like, shape (N, ...)
        Uniformly sampled signal (time along ``axis``).
    fs : float
        Sample rate [Hz].
    cutoff_hz : float
        Cutoff frequency of the designed filter [Hz], ``0 < cutoff_hz < fs / 2``; the
        zero-phase response is -6 dB there. Gaz et al. 2019 used 1 Hz.
    order : int
        Designed Butterworth order (applied twice: effective order ``2 order``).
    axis : int
        Time axis.

    Returns
    -------
    y : ndarray, same shape as ``x``
        Filtered signal, no phase lag; a new array.

    Raises
    ------
    DataError
        Cutoff not in ``(0, fs / 2)``, or not more samples than the minimum padding
        ``3 (2 ceil(order / 2) + 1)``.
    NonFiniteError
        NaN or inf in ``x``.

    Notes
    -----
    Each end is continued over three periods of the cutoff by the cubic polynomial
    fitted (least squares) to its last period (the whole signal when shorter), which
    keeps the value and its first three derivatives nearly continuous, and that
    extension is padded with an odd extension of one period; the start-up transient
    decays within the extension and the corner left at the signal's end is small (the
    edge error of a smooth signal's second derivative falls about 50-fold against an odd
    extension alone).
    """
    x = _checks.as_array("x", x)
    fs, cutoff_hz = float(fs), float(cutoff_hz)
    if not (fs > 0 and 0 < cutoff_hz < fs / 2):
        raise DataError(
            f"cutoff_hz must lie in (0, fs/2) = (0, {fs / 2:g}) Hz; got {cutoff_hz:g} Hz"
        )
    if order < 1:
        raise DataError(f"order must be >= 1; got {order}")
    sos = butter_sos(order, cutoff_hz, fs)
    minimum = 3 * (2 * len(sos) + 1)
    N = x.shape[axis]
    if N <= minimum:
        raise DataError(f"lowpass needs more than {minimum} samples along axis {axis}; got {N}")
    # samples; rounded so that a rate read as 1000.0000000000002 Hz from a window of a log
    # does not lengthen the ends by a sample (a block then differs from the whole log)
    period = round(fs / cutoff_hz, 9)
    ends = _CubicEnds(N, min(N, max(4, int(np.ceil(_FIT_PERIODS * period)))), period)
    padlen = max(minimum, int(np.ceil(period)))

    def filtered(cols: NDArray[np.float64]) -> NDArray[np.float64]:  # (N, k) -> (N, k)
        ext = ends.extended(cols)
        pad = min(ext.shape[0] - 1, padlen)
        return zero_phase(sos, ext, pad)[ends.length : ends.length + N]

    if x.ndim < 2:
        return filtered(np.ravel(x)[:, None])[:, 0]
    # signals in groups of at most _FILTER_ELEMENTS samples: the filter's padded
    # temporaries stay a few times that (a 2-million-sample log would otherwise need
    # several copies of every signal), and short signals are filtered many at a time
    y = np.empty(x.shape)
    xt, yt = np.moveaxis(x, axis, 0), np.moveaxis(y, axis, 0)
    flat = xt.reshape(N, -1)  # a view where it can be, else a copy
    out = np.empty(flat.shape)
    k = max(1, _FILTER_ELEMENTS // N)
    for a in range(0, flat.shape[1], k):
        out[:, a : a + k] = filtered(np.ascontiguousarray(flat[:, a : a + k]))
    yt[...] = out.reshape(xt.shape)
    return y


def lowpass_noise_gain(
    fs: float, cutoff_hz: float | None, *, order: int = BUTTERWORTH_ORDER
) -> float:
    """The std of white noise after :func:`lowpass`, per unit std before it.

    .. math:: g = \\Big(\\sum_k h_k^2\\Big)^{1/2}

    with ``h`` the impulse response of the zero-phase filter (forward and backward), far
    from the ends of the signal; for ``cutoff_hz << fs`` it tends to
    ``sqrt((2 cutoff_hz / fs) int_0^inf dx / (1 + x^(2 order))^2)``.

    Parameters
    ----------
    fs : float
        Sample rate [Hz].
    cutoff_hz : float or None
        Cutoff of :func:`lowpass` [Hz]; None (no filter): 1.
    order : int
        Designed Butterworth order.

    Returns
    -------
    float
        In (0, 1].
    """
    if cutoff_hz is None or not 0 < cutoff_hz < fs / 2:
        return 1.0
    sos = butter_sos(order, float(cutoff_hz), float(fs))
    half = max(64, int(np.ceil(40.0 * fs / cutoff_hz)))
    impulse = np.zeros((2 * half + 1, 1))
    impulse[half] = 1.0
    h = zero_phase(sos, impulse, 0)
    return float(min(1.0, np.sqrt(np.sum(h * h))))


#: Samples filtered at once by :func:`lowpass` (signals grouped up to this size).
_FILTER_ELEMENTS = 1 << 18


class _CubicEnds:
    """Each end of a signal of ``n`` samples continued by ``length`` samples (three
    periods of the cut-off, ``period`` samples each) of the cubic fitted to its ``m``
    end samples (:func:`lowpass`); the fit's projection computed once for every column."""

    def __init__(self, n: int, m: int, period: float) -> None:
        self.n, self.m = n, m
        self.length = int(np.ceil(_EXTEND_PERIODS * period))
        s = np.arange(m) / m  # scaled abscissa: a well-conditioned fit
        fit = np.linalg.pinv(np.vander(s, 4, increasing=True))  # (4, m)
        before = np.vander(np.arange(-self.length, 0) / m, 4, increasing=True)
        after = np.vander((m - 1 + np.arange(1, self.length + 1)) / m, 4, increasing=True)
        self.left = before @ fit  # (length, m): the continuation before the first sample
        self.right = after @ fit  # ... after the last, from the last m samples

    def extended(self, cols: NDArray[np.float64]) -> NDArray[np.float64]:
        """``cols`` (n, k) with their two continuations, (n + 2 length, k)."""
        return np.concatenate([self.left @ cols[: self.m], cols, self.right @ cols[-self.m :]])


def derivative(t: ArrayLike, x: ArrayLike) -> NDArray[np.float64]:
    """Time derivative of a sampled signal by second-order finite differences.

    Central differences inside, one-sided second-order differences at both ends
    (``numpy.gradient(x, t, axis=0, edge_order=2)``); exact for quadratics on any grid.

    Parameters
    ----------
    t : array_like, shape (N,)
        Strictly increasing sample times [s], uniform or not; N >= 3.
    x : array_like, shape (N, ...)
        Signal (e.g. filtered joint velocities [rad/s]).

    Returns
    -------
    dx : ndarray, shape (N, ...)
        Derivative [unit of x per s].

    Raises
    ------
    ShapeError
        ``t`` not 1-D with N >= 3, or ``x`` without N rows.
    DataError
        ``t`` not strictly increasing.
    """
    t = _time(t)
    x = _checks.as_array("x", x)
    if t.shape[0] < 3 or x.ndim < 1 or x.shape[0] != t.shape[0]:
        raise ShapeError(
            f"derivative needs t (N,) with N >= 3 and x (N, ...); got {t.shape} and {x.shape}"
        )
    if x.ndim < 2:
        return _gradient(x, t)
    # one signal at a time: np.gradient's temporaries stay the size of one column
    out = np.empty(x.shape)
    flat, fout = x.reshape(x.shape[0], -1), out.reshape(x.shape[0], -1)
    for k in range(flat.shape[1]):
        fout[:, k] = _gradient(flat[:, k], t)
    return out


#: Samples of a signal differentiated at a time by :func:`derivative` (np.gradient on a
#: non-uniform grid takes about ten temporaries of its input's size).
_GRADIENT_BLOCK = 1 << 18


def _gradient(x: NDArray[np.float64], t: NDArray[np.float64]) -> NDArray[np.float64]:
    """``np.gradient(x, t, edge_order=2)`` of a 1-D signal, a block of samples at a time
    with one sample of overlap: each value is the same formula on the same samples."""
    N = x.shape[0]
    if N <= 2 * _GRADIENT_BLOCK:
        return np.gradient(x, t, edge_order=2)
    out = np.empty(N)
    for a in range(0, N, _GRADIENT_BLOCK):
        b = min(a + _GRADIENT_BLOCK, N)
        lo, hi = max(a - 1, 0), min(b + 1, N)
        if hi - lo < 3:  # a last sample alone: with the two before it
            lo = hi - 3
        out[a:b] = np.gradient(x[lo:hi], t[lo:hi], edge_order=2)[a - lo : b - lo]
    return out


#: Order of accuracy of :func:`exact_derivative`: its stencils span this many steps plus one
#: sample (nine), its error falls as ``(2 pi f dt)^8`` of a harmonic's derivative.
EXACT_DERIVATIVE_ORDER = 8


def exact_derivative(t: ArrayLike, x: ArrayLike) -> NDArray[np.float64]:
    """Time derivative of a noise-free signal on a uniform grid by finite differences of
    order :data:`EXACT_DERIVATIVE_ORDER`: the derivative at each sample of the polynomial
    of degree 8 through the nine samples centred on it (the nine first or last at the
    ends), the weights exact fractions (Lagrange) rounded once.

    A harmonic of frequency ``f`` at the step ``dt`` is differentiated to
    ``(2 pi f dt)^8 / 630`` of its derivative inside (second-order differences,
    :func:`derivative`: ``(2 pi f dt)^2 / 6``): a noise-free simulation's accelerations from
    its velocities to round-off. White noise is amplified about twice as much as by
    :func:`derivative`: for exact data, not noisy.

    Parameters
    ----------
    t : array_like, shape (N,)
        Uniform, strictly increasing sample times [s]; N >= 9.
    x : array_like, shape (N, ...)
        Signal (e.g. velocities [rad/s]).

    Returns
    -------
    dx : ndarray, shape (N, ...)
        Derivative [unit of x per s].

    Raises
    ------
    ShapeError
        ``t`` not 1-D with N >= 9, or ``x`` without N rows.
    DataError
        ``t`` not strictly increasing or not uniform.
    """
    t = _time(t)
    x = _checks.as_array("x", x)
    m = EXACT_DERIVATIVE_ORDER
    N = t.shape[0]
    if N < m + 1 or x.ndim < 1 or x.shape[0] != N:
        raise ShapeError(
            f"exact_derivative needs t (N,) with N >= {m + 1} and x (N, ...); got {t.shape} "
            f"and {x.shape}"
        )
    if not is_uniform(t):
        raise DataError("exact_derivative needs uniform sample times; hint: resample first")
    dt = float((t[-1] - t[0]) / (N - 1))
    h = m // 2
    flat = x.reshape(N, -1)
    out = np.empty(flat.shape)
    w = _stencil(tuple(range(-h, h + 1)))
    out[h : N - h] = sum(w[k] * flat[k : N - m + k] for k in range(m + 1))
    for i in range(h):  # the ends: the nine first (last) samples
        out[i] = _stencil(tuple(range(-i, m + 1 - i))) @ flat[: m + 1]
        out[N - 1 - i] = _stencil(tuple(range(i - m, i + 1))) @ flat[N - m - 1 :]
    return (out / dt).reshape(x.shape)


def _stencil(nodes: tuple[int, ...]) -> NDArray[np.float64]:
    """The weights of the derivative at 0 of the polynomial through the samples at the
    integer ``nodes`` (steps of 1): ``L_k'(0)`` of the Lagrange basis, exact fractions."""
    from fractions import Fraction

    weights = []
    for k, sk in enumerate(nodes):
        total = Fraction(0)
        for j, sj in enumerate(nodes):
            if j == k:
                continue
            term = Fraction(1, sk - sj)
            for i, si in enumerate(nodes):
                if i not in (j, k):
                    term *= Fraction(-si, sk - si)
            total += term
        weights.append(float(total))
    return np.array(weights)


def filtered_derivative(
    t: ArrayLike, x: ArrayLike, cutoff_hz: float, *, order: int = BUTTERWORTH_ORDER
) -> NDArray[np.float64]:
    """Derivative of a signal after a zero-phase low-pass: :func:`lowpass`, then :func:`derivative`.

    Used for velocities from positions when a log has positions only. A jittered ``t``
    (or one with gaps) is resampled onto a uniform grid first (:func:`resample_uniform`)
    and the derivative interpolated back onto ``t``; the first and last
    ``edge_seconds(cutoff_hz)`` carry the filter's transient (:func:`trim_edges`).

    Parameters
    ----------
    t : array_like, shape (N,)
        Strictly increasing sample times [s].
    x : array_like, shape (N, ...)
        Signal, e.g. joint positions [rad].
    cutoff_hz : float
        Cutoff of the low-pass [Hz], ``0 < cutoff_hz < fs / 2``.
    order : int
        Designed Butterworth order.

    Returns
    -------
    dx : ndarray, shape (N, ...)
        Derivative of the filtered signal [unit of x per s].

    Raises
    ------
    DataError
        Cutoff not below the Nyquist frequency, too few samples, ``t`` not increasing.
    """
    t = _time(t)
    if is_uniform(t):
        return derivative(t, lowpass(x, sample_rate(t), cutoff_hz, order=order))
    x = _checks.as_array("x", x)
    tu, xu = resample_uniform(t, x)
    du = derivative(tu, lowpass(xu, sample_rate(tu), cutoff_hz, order=order))
    flat = du.reshape(du.shape[0], -1)
    out = np.stack([np.interp(t, tu, flat[:, k]) for k in range(flat.shape[1])], axis=1)
    return out.reshape((t.shape[0],) + x.shape[1:])


def derivative_noise_gain(dt: float, cutoff_hz: float, *, lowpassed: bool = False) -> float:
    """The std [1/s] of :func:`filtered_derivative`'s output for white input noise of std 1.

    .. math:: g = \\Big(\\sum_k h_k^2\\Big)^{1/2}

    with ``h`` the impulse response (far from the ends) of :func:`filtered_derivative` at
    the step ``dt`` [s] and ``cutoff_hz`` [Hz], followed by :func:`lowpass` at the same
    cut-off with ``lowpassed`` (the velocities identification prepares from positions).
    Velocities derived from positions with white noise of std ``s`` [rad] hold noise of
    std ``g s`` [rad/s]."""
    half = int(np.ceil(4.0 * edge_seconds(cutoff_hz) / dt)) + 8
    x = np.zeros((2 * half + 1, 1))
    x[half] = 1.0
    h = filtered_derivative(dt * np.arange(2 * half + 1), x, cutoff_hz)[:, 0]
    if lowpassed:
        h = lowpass(h, 1.0 / dt, cutoff_hz)
    return float(np.sqrt(np.sum(h**2)))


def below_nyquist(cutoff_hz: float, fs: float) -> float:
    """The cut-off [Hz] a low-pass of samples at ``fs`` [Hz] runs at: ``cutoff_hz`` where
    it lies below half the rate, else a quarter of the rate (the highest cut-off
    identification reads from a log's motion, and the one a slow log's default is moved
    to): a 20 Hz cut-off on a 30 Hz log filters at 7.5 Hz. Callers say so where the value
    was the user's."""
    fc, fs = float(cutoff_hz), float(fs)
    return fc if fc < 0.5 * fs else 0.25 * fs


def edge_seconds(cutoff_hz: float, motion_hz: float | None = None) -> float:
    """Default time trimmed at each end after filtering [s]: :data:`EDGE_PERIODS` (two)
    periods of the cut-off, or :data:`MOTION_EDGE_PERIODS` (half a period) when the
    motion's highest significant frequency ``motion_hz`` [Hz] lies a decade or more below
    the cut-off, within :data:`DECADE_TOLERANCE` (module docstring)."""
    fc = float(cutoff_hz)
    near = motion_hz is None or not 10.0 * float(motion_hz) <= fc * (1.0 + DECADE_TOLERANCE)
    return (EDGE_PERIODS if near else MOTION_EDGE_PERIODS) / fc


def trim_edges(t: ArrayLike, seconds: float) -> NDArray[np.bool_]:
    """Mask of the samples more than ``seconds`` away from both ends of ``t``.

    Parameters
    ----------
    t : array_like, shape (N,)
        Sample times [s].
    seconds : float
        Time dropped at each end [s] (``>= 0``).

    Returns
    -------
    keep : ndarray of bool, shape (N,)

    Raises
    ------
    DataError
        Nothing would be left.
    """
    t = _checks.as_array("t", t)
    if seconds < 0:
        raise DataError(f"seconds must be >= 0; got {seconds}")
    keep = (t >= t[0] + seconds) & (t <= t[-1] - seconds)
    if not keep.any():
        raise DataError(
            f"trimming {seconds:g} s at each end leaves no sample of a {t[-1] - t[0]:g} s "
            "series; hint: record longer or trim less"
        )
    return keep
