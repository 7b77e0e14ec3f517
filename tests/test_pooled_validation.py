"""Validations of pieces joined into one: the pooled errors are those of every sample of
every piece at once (numpy on the concatenated residuals as the reference)."""

from __future__ import annotations

import numpy as np
import pytest

from dynid.friction.pooled import joined_validation
from dynid.friction.validation import Validation
from dynid.identification.log import TorqueLog
from dynid.identification.metrics import torque_errors


def _part(rng: np.random.Generator, t0: float, N: int, n: int = 3) -> Validation:
    t = t0 + 0.01 * np.arange(N)
    q, dq, ddq = (rng.normal(size=(N, n)) for _ in range(3))
    tau, hat = rng.normal(size=(N, n)), rng.normal(size=(N, n))
    log = TorqueLog(t, q, dq, tau, ddq)
    return Validation(log, hat, None, torque_errors(tau, hat), None, None)


def test_joined_pieces_pool_every_sample():
    rng = np.random.default_rng(4)
    parts = [_part(rng, 0.0, 50), _part(rng, 2.0, 80)]
    v = joined_validation(parts)
    tau = np.concatenate([p.log.tau for p in parts])
    e = tau - np.concatenate([p.tau_model for p in parts])
    np.testing.assert_allclose(v.without_friction.rms, np.sqrt(np.mean(e**2, axis=0)), rtol=1e-12)
    rel = 100 * np.linalg.norm(e) / np.linalg.norm(tau)
    np.testing.assert_allclose(v.without_friction.relative_error_percent, rel, rtol=1e-12)
    assert v.without_friction.n_samples == 130 and v.log.n_samples == 130
    np.testing.assert_array_equal(v.log.t, np.concatenate([p.log.t for p in parts]))
    assert joined_validation(parts[:1]) is parts[0]


def test_the_torque_figure_breaks_its_lines_at_a_gap():
    """Pieces one after another are drawn as pieces (no line across the gap)."""
    pytest.importorskip("matplotlib")
    from dynid.plots.torques import plot_torque_validation

    rng = np.random.default_rng(5)
    fig = plot_torque_validation(joined_validation([_part(rng, 0.0, 50), _part(rng, 2.0, 80)]))
    x = fig.axes[0].lines[0].get_xdata()
    assert np.isnan(x).sum() == 1 and np.isnan(x[50])
    fig.clf()


def test_the_torque_figure_draws_absolute_stamps_from_the_log_start():
    """Regression: a log of absolute stamps (86401 s on) was drawn on an axis starting at
    86400 s; the figure draws the times from the log's first stamp (or a given one) and
    its axis says so."""
    pytest.importorskip("matplotlib")
    from dynid.plots.torques import plot_torque_validation

    rng = np.random.default_rng(6)
    part = _part(rng, 86401.0, 50)
    for t0, first in ((None, 0.0), (86400.0, 1.0)):
        fig = plot_torque_validation(part, t0=t0)
        x = fig.axes[0].lines[0].get_xdata()
        np.testing.assert_allclose(x, first + 0.01 * np.arange(50), atol=1e-9)
        assert fig.axes[-1].get_xlabel() == "time from the log's start [s]"
        fig.clf()
