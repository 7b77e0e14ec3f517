"""Zero-phase filtering, differentiation, resampling and trimming of sampled signals."""

from __future__ import annotations

import numpy as np
import pytest

from dynid import signals
from dynid.exceptions import DataError, NonFiniteError, ShapeError

FS = 1000.0


def _amplitude_phase(t, x, f):
    """Amplitude and phase of the component of frequency f (least squares on sin/cos)."""
    A = np.stack([np.sin(2 * np.pi * f * t), np.cos(2 * np.pi * f * t)], axis=1)
    a, b = np.linalg.lstsq(A, x, rcond=None)[0]
    return np.hypot(a, b), np.arctan2(b, a)


def test_lowpass_passes_a_slow_sinusoid_without_lag_or_attenuation():
    """A 0.5 Hz sinusoid through the 5 Hz zero-phase filter keeps amplitude and phase."""
    t = np.arange(20000) / FS
    x = 1.3 * np.sin(2 * np.pi * 0.5 * t + 0.4)
    y = signals.lowpass(x, FS, 5.0)
    keep = signals.trim_edges(t, signals.edge_seconds(5.0))
    a, ph = _amplitude_phase(t[keep], y[keep], 0.5)
    a0, ph0 = _amplitude_phase(t[keep], x[keep], 0.5)
    # |H_B(0.1 fc)|^2 = 1 / (1 + 0.1^8): attenuation 1e-8
    assert a == pytest.approx(a0, rel=1e-6)
    assert abs(ph - ph0) < 1e-6
    np.testing.assert_allclose(y[keep], x[keep], atol=1e-4 * 1.3)  # edge residue, see signals


def test_lowpass_gain_is_the_squared_butterworth_response():
    """Forward-backward doubles the order: gain 1/2 (-6 dB) at the cutoff, 1/(1+2^8) at 2 fc."""
    t = np.arange(30000) / FS
    fc = 4.0
    keep = signals.trim_edges(t, signals.edge_seconds(fc))
    for f, gain in ((fc, 0.5), (2 * fc, 1.0 / (1.0 + 2.0**8)), (0.5 * fc, 1.0 / (1.0 + 0.5**8))):
        x = np.sin(2 * np.pi * f * t)
        y = signals.lowpass(x, FS, fc)
        a, ph = _amplitude_phase(t[keep], y[keep], f)
        assert a == pytest.approx(gain, rel=2e-3)
        assert abs(ph) < 1e-4  # zero phase


def test_lowpass_filters_columns_independently_and_keeps_shape():
    """A (N, 3) signal filtered at once equals each column filtered alone."""
    rng = np.random.default_rng(1)
    x = rng.normal(size=(3000, 3))
    y = signals.lowpass(x, FS, 10.0)
    assert y.shape == x.shape
    for k in range(3):
        np.testing.assert_allclose(y[:, k], signals.lowpass(x[:, k], FS, 10.0), atol=1e-14)


def test_lowpass_edges_are_small_after_trimming():
    """After trimming 2 / fc seconds the edge error of a smooth signal is about 1e-4."""
    t = np.arange(20000) / FS
    x = np.sin(2 * np.pi * 0.3 * t + 0.7) + 0.025 * t
    y = signals.lowpass(x, FS, 1.0)
    keep = signals.trim_edges(t, signals.edge_seconds(1.0))
    assert np.max(np.abs(y[keep] - x[keep])) < 5e-4
    assert np.max(np.abs(y - x)) > 1e-3  # the untrimmed edges are worse


def test_lowpass_ends_do_not_jump_with_the_last_bit_of_the_rate():
    """A rate read as 1000.0000000000002 Hz from a window of a log (the least-squares
    slope's rounding) filters as 1000 Hz does: the ends' lengths came from ceil(fs / f_c),
    which jumped from 40 to 41 samples and moved a block's derived velocities by 1e-4 of
    the whole log's."""
    rng = np.random.default_rng(7)
    x = np.cumsum(rng.normal(size=(3000, 2)), axis=0)
    a = signals.lowpass(x, 1000.0, 25.0)
    b = signals.lowpass(x, 1000.0 * (1 + 2e-16), 25.0)
    np.testing.assert_allclose(b, a, rtol=0, atol=1e-9 * float(np.abs(a).max()))


def test_lowpass_rejects_bad_cutoff_short_signal_and_nan():
    """Cutoff at or above Nyquist, too few samples and NaN raise clear errors."""
    x = np.zeros(100)
    with pytest.raises(DataError, match="cutoff_hz must lie in"):
        signals.lowpass(x, FS, 500.0)
    with pytest.raises(DataError, match="cutoff_hz must lie in"):
        signals.lowpass(x, FS, 0.0)
    with pytest.raises(DataError, match="needs more than"):
        signals.lowpass(np.zeros(10), FS, 5.0)
    x[5] = np.nan
    with pytest.raises(NonFiniteError, match="x must be finite"):
        signals.lowpass(x, FS, 5.0)


def test_derivative_of_a_sinusoid_on_a_uniform_grid():
    """Second-order differences match the analytic derivative to O(h^2)."""
    t = np.arange(5000) / FS
    w = 2 * np.pi * 1.5
    x = np.stack([np.sin(w * t), np.cos(w * t)], axis=1)
    dx = signals.derivative(t, x)
    ref = np.stack([w * np.cos(w * t), -w * np.sin(w * t)], axis=1)
    # central difference error w^3 h^2 / 6, one-sided ends w^3 h^2 / 3
    assert np.max(np.abs(dx - ref)) < w**3 / FS**2 / 2


def test_derivative_on_non_uniform_timestamps():
    """On jittered timestamps the derivative is exact for quadratics and accurate for sines."""
    rng = np.random.default_rng(2)
    t = np.arange(4000) / FS + rng.uniform(-3e-4, 3e-4, 4000)
    t.sort()
    quad = 3.0 * t**2 - 2.0 * t + 1.0
    np.testing.assert_allclose(signals.derivative(t, quad), 6.0 * t - 2.0, atol=1e-8)
    w = 2 * np.pi * 2.0
    err = signals.derivative(t, np.sin(w * t)) - w * np.cos(w * t)
    assert np.max(np.abs(err)) < 5e-3 * w


def test_resample_uniform_on_jittered_timestamps():
    """Linear interpolation of a smooth signal onto k / fs is accurate to (pi f / fs)^2 / 2."""
    rng = np.random.default_rng(3)
    n = 5000
    t = np.arange(n) / FS + np.clip(rng.normal(0, 2e-4, n), -4e-4, 4e-4)
    t[0] = 0.0
    f = 2.0
    x = np.stack([np.sin(2 * np.pi * f * t), np.cos(2 * np.pi * f * t)], axis=1)
    tu, xu = signals.resample_uniform(t, x, FS)
    np.testing.assert_allclose(np.diff(tu), 1.0 / FS, rtol=1e-9)
    assert tu[0] == t[0] and tu[-1] <= t[-1]
    ref = np.stack([np.sin(2 * np.pi * f * tu), np.cos(2 * np.pi * f * tu)], axis=1)
    # linear interpolation error <= h^2 max|x''| / 8 with h <= 1.8 ms
    assert np.max(np.abs(xu - ref)) < (1.8e-3) ** 2 * (2 * np.pi * f) ** 2 / 8


def test_sample_rate_and_uniformity():
    """The nominal rate of a uniform grid is 1 / dt; jitter makes a grid non-uniform."""
    t = np.arange(100) / 500.0
    assert signals.sample_rate(t) == pytest.approx(500.0, rel=1e-12)
    assert signals.is_uniform(t)
    t2 = t.copy()
    t2[10] += 1e-4
    assert not signals.is_uniform(t2)


def test_epoch_stamps_exact_to_their_floats_are_uniform():
    """Regression: stamps exactly 4000 us apart since the epoch (2024), read in seconds,
    step by 4 ms give or take their floats' 2.4e-7 s, and the log was resampled as
    jittered; uniform now, while a stamp 0.01 ms off (40 times that resolution) is not."""
    from dynid.identification.log import TorqueLog
    from dynid.identification.prepare import resamples

    us = 1_733_000_000_000_000 + 4000 * np.arange(2000, dtype=np.int64)
    t = us.astype(np.float64) * 1e-6
    assert not np.all(np.diff(t) == np.diff(t)[0])  # the floats' steps do differ
    assert signals.is_uniform(t)
    z = np.zeros((t.size, 1))
    assert not resamples(TorqueLog(t, z, z, z))
    t2 = t.copy()
    t2[10] += 1e-5
    assert not signals.is_uniform(t2)
    assert resamples(TorqueLog(t2, z, z, z))


def test_sample_rate_with_jitter_and_dropped_samples():
    """Jitter and gaps do not bias the nominal rate (counted periods, or windowed median)."""
    rng = np.random.default_rng(6)
    k = np.sort(rng.choice(20000, 19000, replace=False))  # 5 % dropped
    small = k / FS + rng.normal(0, 3e-5, k.size)  # periods countable: least squares
    assert signals.sample_rate(small) == pytest.approx(FS, rel=1e-6)
    large = k / FS + np.clip(rng.normal(0, 2e-4, k.size), -4e-4, 4e-4)  # windowed median
    assert signals.sample_rate(large) == pytest.approx(FS, rel=1e-2)


def test_sample_rate_of_gaussian_jitter_is_not_the_median_step():
    """Regression: stamps whose Gaussian jitter (0.15-0.2 periods) is too large to count
    periods by steps fell back to the median step, off by up to 1.3 % on 4000 stamps and
    biased by dropped samples (-0.15 % mean at 2 % dropped, -0.87 % at 10 %); each stamp
    is now placed on the grid, within 2e-5 of the true rate, and so are two logs joined
    across a pause of no whole number of periods."""
    true = 100.0
    for seed, (sigma, drop) in enumerate([(0.15, 0.0), (0.2, 0.02), (0.2, 0.1)] * 3):
        rng = np.random.default_rng(seed)
        k = np.arange(4000)
        k = k[rng.random(k.size) >= drop]
        t = np.sort((k + rng.normal(0, sigma, k.size)) / true)
        assert signals.sample_rate(t) == pytest.approx(true, rel=2e-5), (sigma, drop)
    rng = np.random.default_rng(11)
    k = np.concatenate([np.arange(2000), np.arange(2000) + 2013.37])  # a pause
    t = (k + rng.normal(0, 0.15, k.size)) / true
    assert signals.sample_rate(t) == pytest.approx(true, rel=2e-5)


def test_time_checks_raise_on_non_increasing_timestamps():
    """Repeated or decreasing timestamps are rejected with the offending index."""
    with pytest.raises(DataError, match=r"t\[2\]"):
        signals.derivative([0.0, 0.1, 0.2, 0.2, 0.3], np.zeros(5))
    with pytest.raises(ShapeError, match="N >= 3"):
        signals.derivative([0.0, 0.1], np.zeros(2))
    with pytest.raises(ShapeError, match="x must have shape"):
        signals.resample_uniform([0.0, 0.1, 0.2], np.zeros(4))


def test_trim_edges_mask_and_error():
    """Trimming keeps the samples at least `seconds` from both ends; too much raises."""
    t = np.arange(11) * 0.1
    keep = signals.trim_edges(t, 0.25)
    np.testing.assert_array_equal(np.flatnonzero(keep), np.arange(3, 8))
    with pytest.raises(DataError, match="leaves no sample"):
        signals.trim_edges(t, 0.6)


def test_filtered_derivative_of_a_jittered_sinusoid():
    """Jittered times with a gap: resampled, differentiated, back on t; matches 2 pi f cos."""
    rng = np.random.default_rng(21)
    t = np.arange(8000) * 1e-3 + rng.uniform(-2e-5, 2e-5, 8000)
    t = np.delete(t, np.arange(4000, 4005))  # 5 dropped samples
    f = np.array([0.3, 0.7])
    x = np.sin(2 * np.pi * f * t[:, None])
    dx = signals.filtered_derivative(t, x, 5.0)
    inner = (t > 1.0) & (t < t[-1] - 1.0)
    expect = 2 * np.pi * f * np.cos(2 * np.pi * f * t[:, None])
    assert dx.shape == x.shape
    assert np.max(np.abs(dx[inner] - expect[inner])) < 1e-3 * np.max(np.abs(expect))


def test_a_motion_a_decade_below_the_cutoff_within_the_tolerance_trims_half_a_period():
    """Two recordings of one excitation read its frequency 2e-6 apart: the cut-off of
    one (10 times its motion frequency) trims the other's pieces half a period, as its
    own (the tie was decided by round-off: 4840 or 4951 samples of one log validated);
    a motion 1 % above a decade below trims two periods."""
    fc = 5.349790
    assert signals.edge_seconds(fc, fc / 10.0 * (1.0 + 2e-6)) == signals.MOTION_EDGE_PERIODS / fc
    assert signals.edge_seconds(fc, fc / 10.0) == signals.MOTION_EDGE_PERIODS / fc
    assert signals.edge_seconds(fc, fc / 10.0 * 1.01) == signals.EDGE_PERIODS / fc


def test_robust_std_is_scipys_normal_scaled_mad_and_a_gaussians_sigma() -> None:
    from scipy.stats import median_abs_deviation

    rng = np.random.default_rng(3)
    x = 0.7 * rng.standard_normal((4000, 3)) + np.array([1.0, -5.0, 40.0])
    x[::97, 1] = 1e6  # one sample in a hundred far off: the level barely moves
    want = median_abs_deviation(x, axis=0, scale="normal")
    np.testing.assert_allclose(signals.robust_std(x, axis=0), want, rtol=1e-4)
    np.testing.assert_allclose(signals.robust_std(x[:, 0]), 0.7, rtol=0.05)
    assert signals.robust_std(x[:, 1]) < 0.75
    assert float(signals.robust_std(np.zeros(0))) == 0.0
