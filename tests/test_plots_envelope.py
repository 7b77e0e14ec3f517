"""A long time series drawn as its envelope keeps every extreme: per bin of consecutive
samples the smallest and largest sample, against a brute-force minimum and maximum over
each bin; the torque figure's lines reach the data's extremes and keep a one-sample spike
an even stride dropped, and the observer's residual figure keeps a contact of three
samples.

Reference: ``min`` and ``max`` of each bin computed one bin at a time.
"""

from __future__ import annotations

import numpy as np
import pytest

from dynid.plots.envelope import envelope_indices


def _bins(N: int, bins: int, breaks: list[int]) -> list[tuple[int, int]]:
    """The bins ``(start, stop)`` one at a time: equal counts to within one, cut at breaks."""
    edges = sorted({round(k * N / bins) for k in range(bins + 1)} | set(breaks))
    return [(a, b) for a, b in zip(edges[:-1], edges[1:], strict=True) if b > a]


@pytest.mark.parametrize(("N", "bins", "breaks"), [(1000, 37, []), (5003, 400, [1200, 1201, 4000])])
def test_envelope_holds_each_bins_min_and_max_and_nothing_else(N, bins, breaks):
    """Each bin (cut at the breaks too) contributes exactly its first minimum and first
    maximum sample, found here bin by bin; repeated values pick the first."""
    rng = np.random.default_rng(7)
    y = np.round(rng.normal(size=N), 1)  # ties within bins
    k = envelope_indices(y, bins, breaks=breaks)
    expected: set[int] = set()
    for a, b in _bins(N, bins, breaks):
        expected |= {a + int(np.argmin(y[a:b])), a + int(np.argmax(y[a:b]))}
    assert k.tolist() == sorted(expected)


def test_envelope_keeps_every_sample_of_a_short_or_non_finite_series():
    """A series of at most two samples per bin, or one holding a NaN, is drawn whole."""
    rng = np.random.default_rng(8)
    y = rng.normal(size=300)
    assert envelope_indices(y, 150).tolist() == list(range(300))
    y[40] = np.nan
    assert envelope_indices(y, 10).tolist() == list(range(300))


def test_the_torque_figure_draws_the_datas_extremes_and_a_one_sample_spike():
    """A 40000-sample log with a 25 N m one-sample spike (an even stride of 8 stepped over
    it): each drawn line's largest and smallest value equal the data's, the spike is drawn,
    and each line holds at most 1600 points plus the gap's NaN."""
    pytest.importorskip("matplotlib")
    from dynid.friction.validation import Validation
    from dynid.identification.log import TorqueLog
    from dynid.identification.metrics import torque_errors
    from dynid.plots.torques import plot_torque_validation

    rng = np.random.default_rng(9)
    N, n = 40000, 2
    t = 0.001 * np.arange(N)
    t[20000:] += 5.0  # a gap between two pieces
    tau = np.sin(t)[:, None] * [3.0, 5.0] + rng.normal(0.0, 0.2, (N, n))
    tau[12345, 1] += 25.0
    model = tau + rng.normal(0.0, 0.3, (N, n))
    friction = rng.normal(0.0, 0.1, (N, n))
    q = rng.normal(size=(N, n))
    v = Validation(
        TorqueLog(t, q, q, tau, q), model, friction,
        torque_errors(tau, model), torque_errors(tau, model + friction), None,
    )  # fmt: skip
    fig = plot_torque_validation(v)
    for j in range(n):
        drawn = {
            "measured": tau[:, j], "no": model[:, j], "with": model[:, j] + friction[:, j],
        }  # fmt: skip
        for line, y in zip(fig.axes[2 * j].lines, drawn.values(), strict=True):
            d = np.asarray(line.get_ydata(), dtype=float)
            assert np.nanmax(d) == y.max() and np.nanmin(d) == y.min()
            assert d.size <= 1600 + 1 and np.isnan(d).sum() == 1
        errors = fig.axes[2 * j + 1].lines[0].get_ydata()
        e = tau[:, j] - model[:, j]
        assert np.nanmax(errors) == e.max() and np.nanmin(errors) == e.min()
    spike = fig.axes[2].lines[0]
    assert 20.0 < np.nanmax(spike.get_ydata()) == tau[12345, 1]
    assert np.nanmax(tau[::8, 1]) < 20.0  # the old stride's line missed it
    fig.clf()


def test_the_observer_figure_draws_a_contact_of_three_samples():
    """A 100000-sample residual with a contact of three samples (12 N m, an even stride of
    10 stepped over it): the residual's drawn line reaches it and the data's extremes, the
    true external torque's too, and each line holds at most 20000 points."""
    pytest.importorskip("matplotlib")
    from dynid.plots.observer import plot_residuals

    rng = np.random.default_rng(4)
    N, n = 100_000, 2
    t = 1.7e9 + 0.001 * np.arange(N)  # a log of absolute stamps
    r = rng.normal(0.0, 0.3, (N, n))
    ext = np.zeros((N, n))
    ext[54321:54324, 1] = 12.0
    r += ext
    assert r[::10, 1].max() < 5.0  # the stride of the old drawing missed it
    fig = plot_residuals(t, r, np.full_like(r, 2.0), np.full_like(r, 4.0), tau_ext=ext)

    def drawn(ax, label):  # the line of ``label``, whatever the thresholds drawn before it
        (line,) = [x for x in ax.lines if x.get_label() == label]
        return line

    for j in range(n):
        residual = drawn(fig.axes[j], "residual")
        external = drawn(fig.axes[j], "true external torque")
        d = np.asarray(residual.get_ydata(), dtype=float)
        assert d.max() == r[:, j].max() and d.min() == r[:, j].min()
        assert np.asarray(external.get_ydata()).max() == ext[:, j].max()
        assert all(np.asarray(line.get_ydata()).size <= 20000 for line in fig.axes[j].lines)
    line = drawn(fig.axes[1], "residual")
    at = np.asarray(line.get_xdata())[np.argmax(line.get_ydata())]
    assert 54.321 - 1e-6 <= at <= 54.323 + 1e-6  # at its time from the log's start
