"""The standstill margin: a friction law with a standstill band on an arm whose true
Coulomb friction switches at every reversal raises no contact on collision-free logs with
slow reversals, and a push is still found within the delay bound of a step contact."""

from __future__ import annotations

import numpy as np
import pytest

import dynid
from dynid.friction.laws import LAWS
from dynid.friction.model import ClassicalFriction, LawFriction
from dynid.observer import from_robot, observe
from dynid.observer.detection import calibrate, detect, standstill_series
from dynid.observer.friction import standstill_margin
from dynid.observer.residual import ObserverOptions, first_order_lag
from dynid.simulation.measurement import SensorNoise, simulate_measurement
from dynid.simulation.trajectories import random_fourier, uniform_times

FV = np.array([0.5, 0.5, 0.4, 0.4, 0.2, 0.2, 0.2])
FC = np.array([3.0, 3.0, 2.0, 2.0, 1.0, 1.0, 1.0])
BAND = 0.01  # rad/s: the identified law's Coulomb term is off below it
K = 50.0


def _log(seed: float, duration: float = 10.0):
    """A slow collision-free motion (reversals at a few rad/s^2 at most), true Coulomb
    friction without a band, torque noise 0.05 N m."""
    robot = dynid.panda()
    rng = np.random.default_rng(seed)
    traj = random_fourier(robot, rng, n_harmonics=3, w_f=2 * np.pi * 0.1)(
        uniform_times(duration, 1000.0)
    )
    truth = ClassicalFriction(FV, FC, np.zeros(7))
    return simulate_measurement(robot, traj, rng=rng, noise=SensorNoise(), friction=truth)


@pytest.fixture(scope="module")
def case():
    model = from_robot(dynid.panda()).with_friction(
        ClassicalFriction(FV, FC, np.zeros(7), np.full(7, BAND))
    )
    opts = ObserverOptions(gain=K)
    cal, free = _log(1), _log(2)
    return model, opts, cal, free


def _residual(model, opts, log, tau=None):
    return np.asarray(observe(model, log.t, log.q, log.dq, log.tau if tau is None else tau, opts).r)


def test_the_margin_is_the_coulomb_level_inside_the_band_and_the_tanh_gap_outside():
    """Inside the band the whole Coulomb level (plus the Stribeck bump the band turns off);
    a smooth law's fc (1 - tanh(|v| / v_s)); nothing for a plain sign law."""
    dq = np.array([[0.0, 0.005, -0.02, 0.3]])
    band = ClassicalFriction(np.ones(4), np.full(4, 2.0), np.zeros(4), np.full(4, 0.01))
    assert standstill_margin(band, dq) == pytest.approx(np.array([[2.0, 2.0, 0.0, 0.0]]))
    smooth = LawFriction(LAWS["smooth"], np.tile([1.0, 2.0, 0.0], (4, 1)), np.full(4, 0.01))
    expected = 2.0 * (1.0 - np.tanh(np.abs(dq) / 0.01))
    assert standstill_margin(smooth, dq) == pytest.approx(expected, abs=1e-15)
    P = np.tile([1.0, 2.0, 3.0, 0.1, 0.0], (4, 1))  # fv, fc, fs, vst, fo
    stribeck = LawFriction(LAWS["stribeck"], P, np.full(4, 0.01))
    assert standstill_margin(stribeck, dq) == pytest.approx(np.array([[3.0, 3.0, 0.0, 0.0]]))
    sign = ClassicalFriction(np.ones(4), np.full(4, 2.0), np.zeros(4))
    assert not np.any(standstill_margin(sign, dq + 1e-4))


def test_no_event_at_slow_reversals_and_a_push_within_the_delay_bound(case):
    """Without the margin the reversals of a free log raise contacts (the defect); with
    it none, and a 6 N m step on joint 4 crosses the threshold within the delay of a step
    contact, ln(A / (A - theta -+ e)) / K_O (e the free residual's size there) plus a
    sample."""
    model, opts, cal, free = case
    r_cal, r_free = _residual(model, opts, cal), _residual(model, opts, free)
    plain = calibrate([r_cal], opts)
    assert len(detect(free.t, r_free, plain)) >= 1  # slow reversals taken for contacts
    w_cal = standstill_series(model, cal.t, cal.dq, opts)
    w_free = standstill_series(model, free.t, free.dq, opts)
    th = calibrate([r_cal], opts, standstill=[w_cal])
    assert th.standstill and np.all(th.contact <= plain.contact)
    assert detect(free.t, r_free, th, standstill=w_free) == []
    # the margin is the band's Coulomb level through the lag, and bounds what it explains
    lag = first_order_lag(free.t, FC * (np.abs(free.dq) <= BAND), K)
    assert w_free == pytest.approx(lag, abs=1e-12)

    j, A, t0 = 3, 6.0, 5.0
    quiet = w_free[:, j] < 1e-6
    k0 = int(np.flatnonzero((free.t >= t0) & quiet)[0])  # a push away from a reversal
    ext = np.zeros_like(free.tau)
    ext[k0:, j] = A
    r = _residual(model, opts, free, free.tau - ext)
    events = detect(free.t, r, th, standstill=w_free)
    assert len(events) == 1 and j + 1 in events[0].joints
    theta = th.contact[j]
    e = np.abs(r_free[k0 : k0 + 200, j]).max()
    delay = events[0].start - free.t[k0]
    low, high = (np.log(A / (A - theta + s * e)) / K for s in (1, -1))
    assert low - 1e-3 <= delay <= high + 1e-3


def test_the_lag_is_the_closed_form_step_response_at_any_sample_times():
    """A step of A (rectangle rule: held over each step at its new value) from sample k0
    on: A (1 - exp(-K (t - t_{k0-1}))) per joint gain, on jittered sample times."""
    rng = np.random.default_rng(4)
    t = np.cumsum(rng.uniform(0.5e-3, 1.5e-3, 3000))
    x = np.zeros((3000, 2))
    x[1000:] = [2.0, -3.0]
    gains = np.array([20.0, 60.0])
    y = first_order_lag(t, x, gains, "rectangle")
    expected = np.zeros_like(x)
    expected[1000:] = [2.0, -3.0] * -np.expm1(-gains * (t[1000:, None] - t[999]))
    np.testing.assert_allclose(y, expected, rtol=0, atol=1e-12)
