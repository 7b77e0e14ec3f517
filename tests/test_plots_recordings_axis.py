"""Several recordings on a held-out or validation figure, each readable.

Four 6 s recordings stamped on the epoch's clock 100 s apart were drawn on one 0-300 s
axis, each a sliver of it. Each is now drawn from its own start, one after another with a
line between two and its name over the top panels. The references are the recordings'
stamps and boundaries written here.
"""

from __future__ import annotations

import matplotlib

matplotlib.use("Agg")

import numpy as np

from dynid.friction.pooled import joined_validation
from dynid.friction.validation import Validation
from dynid.identification.log import TorqueLog
from dynid.identification.metrics import torque_errors
from dynid.plots.torques import plot_torque_validation, recording_of

#: Each recording's first stamp [s] (ns since the epoch, read as s) and its duration [s].
STARTS = (1765040000.0, 1765040100.0, 1765040200.0, 1765040300.0)
DURATION = 6.0


def _part(t, rng):
    """A validation of one piece stamped ``t`` [s], two joints."""
    n = t.shape[0]
    tau = np.sin(t - t[0])[:, None] * [3.0, 5.0] + rng.normal(0.0, 0.2, (n, 2))
    model = tau + rng.normal(0.0, 0.3, (n, 2))
    q = rng.normal(size=(n, 2))
    return Validation(
        TorqueLog(t, q, q, tau, q), model, None, torque_errors(tau, model), None, None
    )


def _recordings(rng):
    """Four recordings, the second cut by a 0.15 s gap into two pieces, pooled in order:
    the validation, each sample's recording and the recordings' (name, first, last)."""
    parts, truth, spans = [], [], []
    for k, a in enumerate(STARTS):
        t = a + 1e-3 * np.arange(int(DURATION * 1000))
        pieces = [t[:2000], t[2150:]] if k == 1 else [t]
        for p in pieces:
            parts.append(_part(p, rng))
            truth.append(np.full(p.size, k))
        spans.append((f"rec{k + 1}.csv", float(t[0]), float(t[-1])))
    return joined_validation(parts), np.concatenate(truth), spans


def test_each_sample_is_given_its_recording():
    """recording_of puts every sample in the recording it was stamped in, the second
    recording's gap within it."""
    v, truth, spans = _recordings(np.random.default_rng(3))
    got = recording_of(v.log.t, [(a, b) for _, a, b in spans])
    np.testing.assert_array_equal(got, truth)


def test_recordings_minutes_apart_are_drawn_each_from_its_own_start():
    """The x axis spans about the four recordings' 24 s, not 300 s; each recording's
    samples are drawn from its own start (the first at 0, each spanning 6 s), after the
    one before; three boundary lines and the four names over the top panels."""
    v, truth, spans = _recordings(np.random.default_rng(4))
    fig = plot_torque_validation(v, recordings=spans, max_points=4000)
    ax = fig.axes[0]
    lo, hi = ax.get_xlim()
    assert hi - lo < 1.2 * 4 * DURATION
    x = np.asarray(ax.lines[0].get_xdata(), dtype=float)
    x = x[np.isfinite(x)]
    cuts = np.flatnonzero(np.diff(x) > 0.5) + 1  # between recordings; the gap is 0.15 s
    blocks = np.split(x, cuts)
    assert len(blocks) == 4
    assert abs(blocks[0][0]) < 0.02  # the envelope keeps a sample of the first bin
    for k, b in enumerate(blocks):
        assert abs((b[-1] - b[0]) - DURATION) < 0.02
        if k:
            assert b[0] > blocks[k - 1][-1]
    vertical = [ln for ln in ax.lines if np.ptp(np.asarray(ln.get_xdata(), float)) == 0]
    assert len(vertical) == 3
    names = {t.get_text() for t in ax.texts}
    assert names == {"rec1.csv", "rec2.csv", "rec3.csv", "rec4.csv"}


def test_recordings_each_stamped_from_zero_are_named_one_after_another():
    """Three recordings each stamped from 0 (which the pooling lays one after another, each
    one sample step after the one before): the three names over the top panels, two
    boundary lines, and each recording's samples drawn from its own start."""
    rng = np.random.default_rng(6)
    lengths = (3000, 2500, 3300)
    parts = [_part(1e-3 * np.arange(m), rng) for m in lengths]
    spans = [(f"r{k + 1}.csv", 0.0, 1e-3 * (m - 1)) for k, m in enumerate(lengths)]
    fig = plot_torque_validation(joined_validation(parts), recordings=spans, max_points=8000)
    ax = fig.axes[0]
    assert {t.get_text() for t in ax.texts} == {"r1.csv", "r2.csv", "r3.csv"}
    vertical = [ln for ln in ax.lines if np.ptp(np.asarray(ln.get_xdata(), float)) == 0]
    assert len(vertical) == 2
    x = np.asarray(ax.lines[0].get_xdata(), dtype=float)
    blocks = np.split(x[np.isfinite(x)], np.flatnonzero(np.diff(x[np.isfinite(x)]) > 0.05) + 1)
    assert [round(b[-1] - b[0], 3) for b in blocks] == [1e-3 * (m - 1) for m in lengths]


def test_one_recording_keeps_the_log_axis():
    """Without several recordings the figure draws time from the log's start as before."""
    rng = np.random.default_rng(5)
    t = STARTS[0] + 1e-3 * np.arange(3000)
    fig = plot_torque_validation(
        _part(t, rng), recordings=[("rec1.csv", t[0], t[-1])], max_points=8000
    )
    x = np.asarray(fig.axes[0].lines[0].get_xdata(), dtype=float)
    assert abs(np.nanmin(x)) < 1e-9 and abs(np.nanmax(x) - 2.999) < 1e-5
    assert not fig.axes[0].texts
