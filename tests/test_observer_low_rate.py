"""The observer on a log of positions only sampled at 30 Hz (hobby servos over USB): its
fixed 20 Hz velocity cut-off lay above half the rate, every piece's derived velocities
were NaN and ``observe`` stopped with "dq must be finite", a column the log does not have.

Reference: a planar 2R arm (Spong's closed form, written out here) moving along sines,
sampled at 30 Hz with jittered stamps and quantised positions; its velocities are the
sines' closed-form derivatives, and a step contact of known size is taken from the
torques the motors supply.
"""

from __future__ import annotations

import warnings
from pathlib import Path

import numpy as np
import pytest

from dynid.identification.log import TorqueLog
from dynid.observer import from_robot
from dynid.observer.detection import calibrate, detect
from dynid.observer.residual import ObserverOptions
from dynid.progress import NOTE
from dynid.workflows.observe_logs import observed_blocks, prepared_log

from conftest import planar_2r

RATE = 30.0  # [Hz]
F = np.array([0.25, 0.4])  # the sines' frequencies [Hz]
AMP = np.array([0.8, 0.6])  # their amplitudes [rad]
Q0 = np.array([-1.2, 0.9])  # [rad]
HIT = (12.0, 12.6, 0, 3.0)  # a step contact: start, end [s], joint (0-based), size [N m]
OPTS = ObserverOptions()


def _closed_form(t: np.ndarray, phase: float) -> tuple[np.ndarray, ...]:
    """q, dq [rad/s] and the torques [N m] of the 2R arm (Spong et al. ch. 7; l1 0.7,
    lc 0.35 and 0.25, m 2 and 1.5, I 0.05 and 0.03, g 9.81) along the sines."""
    w = 2 * np.pi * F
    arg = np.outer(t, w) + phase
    q, dq, ddq = Q0 + AMP * np.sin(arg), AMP * w * np.cos(arg), -AMP * w**2 * np.sin(arg)
    l1, lc1, lc2, m1, m2, I1, I2, g0 = 0.7, 0.35, 0.25, 2.0, 1.5, 0.05, 0.03, 9.81
    c2, hh = np.cos(q[:, 1]), -m2 * l1 * lc2 * np.sin(q[:, 1])
    d11 = m1 * lc1**2 + m2 * (l1**2 + lc2**2 + 2 * l1 * lc2 * c2) + I1 + I2
    d12 = m2 * (lc2**2 + l1 * lc2 * c2) + I2
    d22 = m2 * lc2**2 + I2
    g2 = m2 * lc2 * g0 * np.cos(q[:, 0] + q[:, 1])
    g1 = (m1 * lc1 + m2 * l1) * g0 * np.cos(q[:, 0]) + g2
    tau1 = d11 * ddq[:, 0] + d12 * ddq[:, 1] + 2 * hh * dq[:, 0] * dq[:, 1] + hh * dq[:, 1] ** 2
    tau2 = d12 * ddq[:, 0] + d22 * ddq[:, 1] - hh * dq[:, 0] ** 2
    return q, dq, np.column_stack([tau1 + g1, tau2 + g2])


def _log(seed: int, contact: bool) -> tuple[TorqueLog, np.ndarray]:
    """A 24 s log at 30 Hz of positions only (stamps jittered by 3 ms, positions
    quantised to 4096 counts a turn, torque noise 0.01 N m) and its true velocities."""
    rng = np.random.default_rng(seed)
    t = np.arange(int(24 * RATE)) / RATE + rng.normal(0.0, 0.003, int(24 * RATE))
    t = np.sort(t - t[0])
    q, dq, tau = _closed_form(t, phase=rng.uniform(0, 2 * np.pi))
    if contact:
        a, b, j, size = HIT
        tau[(t >= a) & (t < b), j] -= size  # the motors supply the model's less the push
    step = 2 * np.pi / 4096
    q = np.round(q / step) * step
    tau = tau + 0.01 * rng.standard_normal(tau.shape)
    return TorqueLog(t, q, np.zeros_like(q), tau, dq_derived=True), dq


def _observed(seed: int, contact: bool):
    model = from_robot(planar_2r(), friction=None)
    log, dq = _log(seed, contact)
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")  # the edges left unobserved
        prep = prepared_log(Path("servo.csv"), log, model, None)
        ((a, b),) = prep.spans
        r = np.concatenate([x.r for x in observed_blocks(prep, model, OPTS, False, False)])
    return prep, log.t[a:b], r, dq[a:b], prep.dq[a:b]


def test_velocities_of_a_30_hz_log_of_positions_are_derived_below_half_its_rate(caplog):
    """Regression ("dq must be finite; got nan" on a 30 Hz log without velocity columns):
    the velocities are derived at a quarter of the rate (7.5 Hz, a note says so) and
    match the sines' closed-form derivatives to 2 % of their peak."""
    with caplog.at_level(NOTE):
        prep, _, _, true, derived = _observed(1, contact=False)
    assert prep.cutoff_hz == pytest.approx(RATE / 4, rel=1e-3)
    notes = [r.getMessage() for r in caplog.records if r.levelno == NOTE]
    assert any("servo.csv: velocities derived from the positions at 7.5 Hz" in n for n in notes)
    peak = np.abs(true).max(axis=0)
    assert np.all(np.abs(derived - true).max(axis=0) < 0.02 * peak)


def test_a_step_contact_on_a_30_hz_log_of_positions_is_found_with_no_false_alarm():
    """Calibrated on one free 30 Hz log, the observer finds the 3 N m step on joint 1 of
    another within two samples of its start, its peak within the free log's largest
    residual of the step (the lag K_O = 50/s settles in 0.1 s of the 0.6 s push), and
    raises nothing on a third, free log."""
    _, _, r, _, _ = _observed(2, contact=False)
    th, noise = calibrate([r], OPTS), np.abs(r).max(axis=0)
    a, b, j, size = HIT
    _, t, r, _, _ = _observed(3, contact=True)
    (event,) = detect(t, r, th)
    assert a <= event.start <= a + 2 / RATE and (j + 1) in event.joints
    inside = (t >= a) & (t < b)
    assert abs(np.abs(r[inside, j]).max() - size) < noise[j]
    _, t, r, _, _ = _observed(4, contact=False)
    assert detect(t, r, th) == []


def test_the_observers_cut_off_stays_at_20_hz_where_the_rate_allows_it():
    """A log at 50 Hz keeps the observer's 20 Hz (below its 25 Hz Nyquist frequency):
    nothing changes for the rates that worked."""
    from dynid.observer.friction import DERIVED_CUTOFF_HZ, derived_cutoff

    assert derived_cutoff(np.arange(200) / 50.0) == DERIVED_CUTOFF_HZ == 20.0
    assert derived_cutoff(np.arange(200) / 40.0) == pytest.approx(10.0)
