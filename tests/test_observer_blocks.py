"""A long log observed a block at a time: the standstill margin's lag continued from block
to block, the calibration from running statistics, and ``observe --calibrate`` without its
series give what the whole log at once gives."""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest

import dynid
from dynid.friction.model import ClassicalFriction
from dynid.io.torque_log import save_torque_log
from dynid.observer import from_robot, observe
from dynid.observer.detection import calibrate, standstill_blocks, standstill_series
from dynid.observer.friction import standstill_margin, velocity_bands
from dynid.observer.residual import ObserverOptions, first_order_lag
from dynid.simulation.measurement import SensorNoise, simulate_measurement
from dynid.simulation.trajectories import random_fourier, uniform_times
from dynid.workflows.observe import ObserveOptions, observe_files

FRICTION = ClassicalFriction(np.full(7, 0.3), np.full(7, 1.0), np.zeros(7), np.full(7, 0.01))


def _log(seed: int, duration: float = 3.0):
    robot = dynid.panda()
    rng = np.random.default_rng(seed)
    traj = random_fourier(robot, rng, n_harmonics=3, w_f=2 * np.pi * 0.2)(
        uniform_times(duration, 1000.0)
    )
    return simulate_measurement(robot, traj, rng=rng, noise=SensorNoise(), friction=FRICTION)


@pytest.fixture(scope="module")
def case():
    model = from_robot(dynid.panda()).with_friction(FRICTION)
    return model, ObserverOptions(gain=40.0), _log(1)


def test_margin_blocks_continue_the_lag_of_the_whole_piece(case):
    """Blocks of 37 samples: their concatenation is the lag of the whole piece's margin
    (first_order_lag of standstill_margin at once), to 1e-12 of its size."""
    model, opts, log = case
    bands = velocity_bands(model.friction, log.dq)
    w = standstill_margin(model.friction, log.dq, bands)
    want = first_order_lag(log.t, w, opts.gains(7), opts.rule)
    got = np.zeros_like(want)
    for a, m in standstill_blocks(model, log.t, np.asarray(log.dq), opts, block=37):
        got[a : a + m.shape[0]] = m
    assert np.max(want) > 0.1
    np.testing.assert_allclose(got, want, rtol=0, atol=1e-12 * np.max(want))
    np.testing.assert_allclose(standstill_series(model, log.t, log.dq, opts), want, atol=1e-12)


def test_calibration_from_blocks_is_the_rule_on_the_whole_log(case):
    """Blocks of 100 samples through generators: the thresholds are margin times the
    largest (|r| - w)^+ (computed here at once) and its excess over k sigma."""
    model, opts, log = case
    r = np.asarray(observe(model, log.t, log.q, log.dq, log.tau, opts).r)
    w = standstill_series(model, log.t, log.dq, opts)
    s = np.full_like(r, 0.05)

    def chunks(x):
        return (x[a : a + 100] for a in range(0, x.shape[0], 100))

    th = calibrate(chunks(r), opts, std=chunks(s), standstill=chunks(w), margin=1.5, k_sigma=3.0)
    A = np.clip(np.abs(r) - w, 0.0, None)
    np.testing.assert_allclose(th.contact, 1.5 * A.max(axis=0), rtol=1e-15)
    np.testing.assert_allclose(th.noise, 1.5 * np.clip(A - 0.15, 0.0, None).max(axis=0))
    assert th.samples == r.shape[0]
    q = calibrate(chunks(r), opts, standstill=chunks(w), quantile=0.9)
    np.testing.assert_allclose(q.contact, 1.5 * np.quantile(A, 0.9, axis=0), rtol=1e-15)


def test_calibrating_without_series_gives_the_same_thresholds(case, tmp_path: Path, monkeypatch):
    """observe_files a block of 700 samples at a time, with keep_series=False (the command
    with --no-figures): no residual kept, the thresholds of the residual kept whole, which
    is the observer's over the whole log at once to 1e-12, and the rule on it."""
    monkeypatch.setattr("dynid.workflows.observe_logs.OBSERVE_BLOCK", 700)
    model, opts, log = case
    path = tmp_path / "free.csv"
    save_torque_log(path, log)
    fr = tmp_path / "friction.json"
    from dynid.io.friction_json import save_friction_json

    save_friction_json(fr, FRICTION)
    base = dict(data=(path,), params="panda", friction=fr, calibrate=True, gain=40.0)
    kept = observe_files(ObserveOptions(**base))
    lean = observe_files(ObserveOptions(**base, keep_series=False))
    assert lean.logs[0].r is None and kept.logs[0].r is not None
    np.testing.assert_array_equal(lean.thresholds.contact, kept.thresholds.contact)
    np.testing.assert_array_equal(lean.logs[0].standstill_peak, kept.logs[0].standstill_peak)
    whole = observe(model, kept.logs[0].t, log.q, log.dq, log.tau, opts).r
    np.testing.assert_allclose(kept.logs[0].r, whole, rtol=0, atol=1e-12)
    w = standstill_series(model, log.t, log.dq, opts)
    want = 1.5 * np.clip(np.abs(whole) - w, 0.0, None).max(axis=0)
    np.testing.assert_allclose(lean.thresholds.contact, want, rtol=1e-9)
