"""A log made of short pieces keeps most of each: the zero-phase filter's edges are
continued by their cubic (:func:`dynid.signals.lowpass`), so that, the motion a decade below
the cut-off, only half a period of it is trimmed at each piece's end (two periods were: a
log of 0.3-0.5 s pieces filtered at 7.4 Hz lost every piece), and the record says where
each recording's samples went.

References: the exact accelerations and velocities of the simulated trajectory (a random
Fourier series, noise-free), and the samples of the pieces counted here.
"""

from __future__ import annotations

import numpy as np
import pytest

import dynid
from dynid import signals
from dynid.identification.log import TorqueLog
from dynid.identification.rate import decimation
from dynid.identification.recordings import prepare_recordings
from dynid.simulation.measurement import SensorNoise, sample_times, simulate_measurement
from dynid.simulation.trajectories import random_fourier

RATE = 200.0  # [Hz]


@pytest.fixture(scope="module")
def pieces():
    """A noise-free 8 s Panda log with its exact accelerations, and the rows of 10 pieces
    of 0.3-0.5 s separated by 0.3 s cut out."""
    panda = dynid.panda()
    rng = np.random.default_rng(5)
    traj = random_fourier(panda, rng)(sample_times(8.0, RATE))
    log = simulate_measurement(panda, traj, rng=rng, noise=SensorNoise.none(), with_ddq=True)
    spans, t = [], 0.0
    for length in rng.uniform(0.3, 0.5, 10):
        spans.append(np.arange(round(t * RATE), round((t + length) * RATE)))
        t += length + 0.3
    return panda, log, spans


def test_short_pieces_keep_most_samples_with_accurate_derivatives(pieces):
    panda, log, spans = pieces
    rows = np.concatenate(spans)
    cut = TorqueLog(log.t[rows], log.q[rows], log.dq[rows], log.tau[rows])
    rec = prepare_recordings(panda, [cut], ["pieces.csv"], decimate=1)  # cut-off: the motion's
    assert rec.cutoff_hz is not None and 5.0 < rec.cutoff_hz < 10.0
    assert len(rec.pieces) == 10 and not rec.skipped
    assert rec.n_samples >= 0.6 * rows.size  # two periods trimmed per end kept none
    scale = np.sqrt(np.mean(log.ddq**2, axis=0))
    for p in rec.pieces:
        k = np.rint(p.log.t * RATE).astype(int)  # the exact samples' rows
        np.testing.assert_allclose(p.log.t, log.t[k], atol=1e-9)
        assert np.max(np.abs(p.log.ddq - log.ddq[k]) / scale) < 1e-3
        assert np.max(np.abs(p.log.dq - log.dq[k]) / np.abs(log.dq).max(axis=0)) < 1e-4
    # where the samples went: trimmed half a period of the cut-off at each piece's end
    (counts,) = rec.counts
    edge = signals.edge_seconds(rec.cutoff_hz, rec.cutoff_hz / 10.0)
    assert edge == pytest.approx(0.5 / rec.cutoff_hz)
    expected = sum(
        int(np.sum((log.t[s] < log.t[s[0]] + edge) | (log.t[s] > log.t[s[-1]] - edge)))
        for s in spans
    )
    assert (counts.recorded, counts.trimmed, counts.decimated) == (rows.size, expected, 0)
    assert counts.used == rec.n_samples
    (summary,) = rec.summary()
    assert summary["trimmed"] == expected and summary["recorded"] == rows.size


def test_dropped_samples_are_counted_as_grid_points_added_not_as_negative_decimation():
    """A 100 Hz log missing every 25th sample is resampled onto a uniform grid that holds
    the missing places: the recording lines printed "-84 between the decimated samples";
    now the grid points added are counted as such, every count is non-negative and the
    counts add up to the samples used."""
    from dynid.cli.summaries import recordings_lines

    panda = dynid.panda()
    rng = np.random.default_rng(7)
    traj = random_fourier(panda, rng)(sample_times(8.0, 100.0))
    log = simulate_measurement(panda, traj, rng=rng, noise=SensorNoise.none())
    dropped = np.arange(12, log.n_samples - 1, 25)
    rows = np.setdiff1d(np.arange(log.n_samples), dropped)
    cut = TorqueLog(log.t[rows], log.q[rows], log.dq[rows], log.tau[rows])
    rec = prepare_recordings(panda, [cut, cut], ["a.csv", "b.csv"], decimate=1)
    p = rec.pieces[0]
    inside = (log.t[dropped] >= p.log.t[0]) & (log.t[dropped] <= p.log.t[-1])
    counts = rec.counts[0]
    assert counts.added == int(np.sum(inside)) > 0
    assert counts.decimated == 0 and counts.trimmed > 0
    assert counts.used == p.log.n_samples == rows.size - counts.trimmed + counts.added
    line = recordings_lines(rec.summary())[0]
    assert f"{counts.added} added by resampling onto a uniform grid" in line
    assert " -" not in line, line


def test_jittered_stamps_without_dropped_samples_add_no_dropped_places():
    """Regression: a 1 kHz log with 50 us of jitter and no sample dropped (largest step
    1.27 ms) read "2 added by resampling onto a uniform grid (the places of dropped
    samples)"; the dropped samples are counted over the span now (here the three
    removed, known), and the grid's other points are said to be jitter."""
    from dynid.cli.summaries import recordings_lines

    panda = dynid.panda()
    rng = np.random.default_rng(11)
    t = sample_times(6.0, 1000.0)
    traj = random_fourier(panda, rng)(t)
    log = simulate_measurement(panda, traj, rng=rng, noise=SensorNoise.none())
    jitter = t + rng.normal(0.0, 50e-6, t.size)
    jitter[0] = t[0]
    assert np.diff(jitter).max() < 1.5e-3
    whole = TorqueLog(jitter, log.q, log.dq, log.tau)
    rows = np.setdiff1d(np.arange(t.size), [2000, 4000, 4001])  # 3 dropped, inside
    cut = TorqueLog(jitter[rows], log.q[rows], log.dq[rows], log.tau[rows])
    rec = prepare_recordings(panda, [whole, cut], ["a.csv", "b.csv"], cutoff_hz=10.0)
    a, b = rec.counts
    assert a.dropped == 0 and b.dropped == 3
    assert b.added - b.dropped == a.added  # the same grid: jitter alike
    lines = recordings_lines(rec.summary())
    assert a.added != 0  # the grid's ends fall other than the jittered stamps'
    assert "places of dropped samples" not in lines[0], lines
    assert "on the uniform grid the jittered stamps were resampled onto" in lines[0]
    assert "no sample dropped" in lines[0]
    assert "3 added by resampling onto a uniform grid (the places of dropped samples)" in lines[1]


def test_heavy_jitter_counts_only_the_samples_dropped():
    """Regression: 100 Hz stamps jittered by up to +-3 ms (0.3 of a period) with 1 % of the
    samples dropped: 68 were counted dropped where 20 were (every step of 1.5 periods
    counted, and jitter alone makes steps of 1.6); now the count is the known one."""
    panda = dynid.panda()
    rng = np.random.default_rng(12)
    t = sample_times(20.0, 100.0)
    log = simulate_measurement(
        panda, random_fourier(panda, rng)(t), rng=rng, noise=SensorNoise.none()
    )
    stamps = t + rng.uniform(-3e-3, 3e-3, t.size)
    stamps[0], stamps[-1] = t[0], t[-1]
    gone = np.sort(rng.choice(np.arange(300, t.size - 300), 20, replace=False))
    gone = gone[np.diff(gone, prepend=0) > 1]  # no two in a row: each its own place
    rows = np.setdiff1d(np.arange(t.size), gone)
    cut = TorqueLog(stamps[rows], log.q[rows], log.dq[rows], log.tau[rows])
    rec = prepare_recordings(panda, [cut], ["j.csv"], cutoff_hz=2.0)
    assert rec.counts[0].dropped == gone.size


def test_recordings_at_other_rates_say_each_its_own_decimation():
    """A 1 kHz and a 200 Hz recording of the same motion: each is decimated at its own
    rate (1 in 10 and 1 in 4 at a 4.5 Hz cut-off, ``rate.decimation``); the summary
    printed "1 in 10" for both, now each recording line says its own and the header the
    range."""
    from dynid.cli.summaries import recordings_lines, samples_text

    panda = dynid.panda()
    traj = random_fourier(panda, np.random.default_rng(8))
    logs = [
        simulate_measurement(
            panda, traj(sample_times(6.0, fs)), rng=np.random.default_rng(1), noise=SensorNoise()
        )
        for fs in (1000.0, 200.0)
    ]
    rec = prepare_recordings(panda, logs, ["fast.csv", "slow.csv"], cutoff_hz=4.5)
    expected = [decimation(fs, 4.5) for fs in (1000.0, 200.0)]
    assert expected == [10, 4]
    lines = recordings_lines(rec.summary())
    for line, k in zip(lines, expected, strict=True):
        assert f", 1 in {k})" in line, line
    head = samples_text(rec.record(1).log, [4, 10])
    assert "1 in 4 to 10, per recording below," in head, head


def test_the_filter_edge_of_a_smooth_signal_is_as_accurate_as_its_interior():
    """A velocity sinusoid well below the cut-off, 0.4 s long: the acceleration derived
    from its filtered samples within 3e-3 of its amplitude at the end samples and within
    2e-4 half a period of the cut-off in (the odd extension alone left 3.7 % and 5e-3)."""
    fs, fc, f = 200.0, 7.4, 0.7
    w = 2 * np.pi * f
    t = np.arange(80) / fs
    v = np.sin(w * t + 0.4)
    exact = w * np.cos(w * t + 0.4)
    err = np.abs(signals.derivative(t, signals.lowpass(v, fs, fc)) - exact) / w
    inner = int(np.ceil(signals.MOTION_EDGE_PERIODS * fs / fc))
    assert err.max() < 3e-3
    assert err[inner:-inner].max() < 2e-4


def test_of_several_recordings_the_jittered_one_is_named():
    """Regression: identify's samples line said "stamps jittered, std 0.58 ms" pooled over
    three recordings without naming the one whose stamps jitter; each recording's line
    says its own now, and the pooled line none."""
    from dynid.cli.summaries import recordings_lines

    panda = dynid.panda()
    rng = np.random.default_rng(12)
    t = sample_times(4.0, 200.0)
    log = simulate_measurement(
        panda, random_fourier(panda, rng)(t), rng=rng, noise=SensorNoise.none()
    )
    shaken = t + rng.normal(0.0, 0.6e-3, t.size)  # 0.6 ms std at a 5 ms period
    shaken[0] = t[0]
    logs = [TorqueLog.from_raw(s, log.q, log.dq, log.tau) for s in (t, shaken)]
    rec = prepare_recordings(panda, logs, ["even.csv", "shaken.csv"], cutoff_hz=5.0)
    lines = recordings_lines(rec.summary())
    assert "jittered" not in lines[0], lines
    said = lines[1].split("stamps jittered, std ")[1]
    assert abs(float(said.split(" ms")[0]) - 0.6) < 0.1, said
