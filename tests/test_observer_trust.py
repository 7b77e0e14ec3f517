"""The trust verdict of a detection (:mod:`dynid.observer.trust`): the residual outside
events read against numpy's own quantiles and shares, and the verdict's levels on
residuals whose level and false alarms are set by construction."""

from __future__ import annotations

import numpy as np
import pytest

from dynid.observer.trust import (
    RATIO_STEP,
    CalibratedOn,
    QuietResidual,
    quiet_residual,
    sample_ratio,
    trust_verdict,
)


def test_the_residual_outside_events_is_read_as_numpy_reads_it():
    """Ratios of a 1 kHz log with two events and NaN samples: the level is numpy's 95th
    percentile of the samples outside the events widened by the guard (to one bin), the
    share above half its exact share, the time their count of periods; two logs pooled
    read as one."""
    rng = np.random.default_rng(3)
    t = np.arange(5000) * 1e-3
    rho = rng.uniform(0.0, 0.9, t.shape[0])
    rho[100:120] = np.nan  # not observed
    spans, guard = [(1.0, 1.3), (3.0, 3.05)], 0.1
    got = quiet_residual(t, rho, spans, guard)
    keep = np.isfinite(rho) & ~((t >= 0.9 - 1e-9) & (t <= 1.4 + 1e-9))
    keep &= ~((t >= 2.9 - 1e-9) & (t <= 3.15 + 1e-9))
    want = np.quantile(rho[keep], 0.95)
    assert got.samples == keep.sum()
    assert got.level() - RATIO_STEP <= want <= got.level()
    assert got.above(0.5) == pytest.approx(np.mean(rho[keep] >= 0.5))
    assert got.seconds == pytest.approx(keep.sum() * 1e-3)
    both = quiet_residual(t[:2500], rho[:2500], spans, guard).plus(
        quiet_residual(t[2500:], rho[2500:], spans, guard)
    )
    np.testing.assert_array_equal(both.counts, got.counts)


def test_the_sample_ratio_is_the_largest_joint_share_of_its_threshold():
    r = np.array([[0.1, -0.6], [np.nan, 0.2], [3.0, 0.0]])
    contact = np.array([[0.5, 1.0], [0.5, 1.0], [1.0, 1.0]])
    np.testing.assert_allclose(sample_ratio(r, contact), [0.6, np.nan, 3.0])


def _constant(level: float, samples: int = 1000) -> QuietResidual:
    return quiet_residual(np.arange(samples) * 1e-3, np.full(samples, level))


@pytest.mark.parametrize(
    ("level", "labelled", "want", "reasons"),
    [
        (0.40, (0, 60.0), "good", ()),
        (0.60, None, "fair", ("level", "worse")),  # 1.28 x the calibration's 0.47
        (0.80, None, "poor", ("level", "worse")),
        (0.40, (3, 60.0), "poor", ("false_alarms",)),  # 3 per minute, the calibration's 0
    ],
)
def test_the_verdict_compares_the_log_with_its_calibration(level, labelled, want, reasons):
    cal = CalibratedOn(("free.csv",), 60.0, 0, 0.47)
    v = trust_verdict(_constant(level), cal, labelled=labelled)
    assert v.level == want and v.reasons == reasons
    assert v.words.startswith(f"trust: {want} - outside events the residual sits at")
    assert "calibrated on free.csv (0 false alarms per minute, residual at 47 %)" in v.words
    if labelled is not None:
        assert v.false_alarms_per_min == pytest.approx(60.0 * labelled[0] / labelled[1])


def test_events_over_most_of_the_log_or_no_calibration_lower_the_verdict():
    """Events over 80 % of the logs: poor whatever the residual left; thresholds of no
    recorded calibration: fair at best, and the line says to calibrate."""
    cal = CalibratedOn(("free.csv",), 60.0, 0, 0.47)
    assert trust_verdict(_constant(0.3), cal, flagged_share=0.8).level == "poor"
    v = trust_verdict(_constant(0.3), None)
    assert v.level == "fair" and v.reasons == ("uncalibrated",)
    assert "calibrate the thresholds" in v.words
    empty = trust_verdict(QuietResidual.empty(), cal, flagged_share=1.0)
    assert empty.level == "poor" and empty.quiet_level is None
