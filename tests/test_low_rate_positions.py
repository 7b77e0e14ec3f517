"""Logs of positions only sampled at 30 Hz (hobby servos over USB). The observer's fixed
20 Hz velocity cut-off lay above half the rate: every piece's derived velocities were NaN
and ``observe`` stopped with "dq must be finite", a column the log does not have. A
cut-off given or recorded at or above half the rate (``--cutoff 20``, a model identified
at 20 Hz on a faster log) was refused by ``validate``, ``friction``, ``identify`` and
``payload``, and the reader's 5 Hz refused a 10 Hz log. Every cut-off not below half the
rate now runs at a quarter of it, with a note.

Reference: a planar 2R arm (Spong's closed form, written out here) moving along sines,
sampled at 30 Hz with jittered stamps and quantised positions; its velocities are the
sines' closed-form derivatives, its torques the closed form's, and a step contact of
known size is taken from the torques the motors supply.
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


def _phase(seed: int) -> float:
    """The sines' phase of :func:`_log`'s ``seed``."""
    rng = np.random.default_rng(seed)
    rng.normal(0.0, 0.003, int(24 * RATE))
    return float(rng.uniform(0, 2 * np.pi))


def _log(seed: int, contact: bool, counts: int = 4096) -> tuple[TorqueLog, np.ndarray]:
    """A 24 s log at 30 Hz of positions only (stamps jittered by 3 ms, positions
    quantised to ``counts`` a turn, torque noise 0.01 N m) and its true velocities."""
    rng = np.random.default_rng(seed)
    t = np.arange(int(24 * RATE)) / RATE + rng.normal(0.0, 0.003, int(24 * RATE))
    t = np.sort(t - t[0])
    q, dq, tau = _closed_form(t, phase=rng.uniform(0, 2 * np.pi))
    if contact:
        a, b, j, size = HIT
        tau[(t >= a) & (t < b), j] -= size  # the motors supply the model's less the push
    step = 2 * np.pi / counts
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


def test_a_cut_off_above_half_the_rate_prepares_a_30_hz_log_at_a_quarter_of_it(caplog):
    """Regression (``identify --cutoff 20`` on a 30 Hz log: "20 Hz: must be below half the
    sample rate"): the recordings are prepared at 7.5 Hz with a note, their velocities the
    sines' closed-form derivatives to 2 % of their peak; a cut-off at or above the rate
    itself (no cut-off for these samples: another unit, another log) is still refused."""
    from dynid.exceptions import OptionError
    from dynid.identification.recordings import prepare_recordings

    log, _ = _log(5, contact=False)
    with caplog.at_level(NOTE), warnings.catch_warnings():
        warnings.simplefilter("ignore")
        rec = prepare_recordings(planar_2r(), [log], ["servo.csv"], cutoff_hz=20.0)
    assert rec.cutoff_hz == pytest.approx(RATE / 4, rel=1e-3)
    said = [r.getMessage() for r in caplog.records if r.levelno == NOTE]
    assert any("20 Hz is not below half the sample rate" in n and "7.5 Hz" in n for n in said)
    (piece,) = rec.pieces
    t = piece.log.t
    true = _closed_form(t, phase=_phase(5))[1]
    assert np.all(np.abs(piece.log.dq - true).max(axis=0) < 0.02 * np.abs(true).max(axis=0))
    with pytest.raises(OptionError, match="must be below half the sample rate"):
        prepare_recordings(planar_2r(), [log], ["servo.csv"], cutoff_hz=30.0)


def test_a_30_hz_log_is_validated_at_a_quarter_of_its_rate_against_the_closed_form():
    """Regression (``validate --cutoff 20`` refused a 30 Hz log of positions only): the
    model that made the log (the 2R arm's closed form) predicts its torques at 7.5 Hz
    within three times their noise's relative error (positions read to 2^24 counts a
    turn; the states interpolated between stamps jittered by 3 ms add about as much as
    the noise again: 0.26 % for 0.13 %)."""
    from dynid.friction.recordings import validate_recordings

    log, _ = _log(6, contact=False, counts=1 << 24)
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        val = validate_recordings(planar_2r(), [log], ["servo.csv"], cutoff_hz=20.0)
    assert val.pieces.cutoff_hz == pytest.approx(RATE / 4, rel=1e-3)
    tau = _closed_form(log.t, phase=_phase(6))[2]
    noise = 100 * 0.01 * np.sqrt(tau.size) / np.linalg.norm(tau)  # [%]
    assert val.without_friction.relative_error_percent < 3.0 * noise


def test_a_10_hz_log_of_positions_is_read_at_a_quarter_of_its_rate():
    """Regression (``identify`` on 10 Hz servo logs: "cutoff_hz must lie in (0, fs/2) =
    (0, 4.99824) Hz; got 5 Hz", the reader's default against jittered stamps): the
    reader derives the velocities at a quarter of the rate, the sines' closed-form
    derivatives to 5 % of their peak inside the filter's edges (0.8 s)."""
    from dynid.identification.log import DEFAULT_CUTOFF_HZ, with_derived_velocities

    log, true = _log(7, contact=False, counts=1 << 24)
    slow = log.select(slice(None, None, 3))  # every third sample: 10 Hz, jittered
    dq = with_derived_velocities(slow, DEFAULT_CUTOFF_HZ).dq
    inner = (slow.t > slow.t[0] + 0.8) & (slow.t < slow.t[-1] - 0.8)
    err = np.abs(dq[inner] - true[::3][inner]).max(axis=0)
    assert np.all(err < 0.05 * np.abs(true).max(axis=0))
