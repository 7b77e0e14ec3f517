"""Exact (noise-free) logs identified to round-off, and the noise they are read to hold.

A simulated log without sensor noise was filtered like a measured one: the zero-phase
low-pass bent the motion the rigid body's torques follow, its edges and the decimation cost
samples, the accelerations of a log without them were second-order differences, and the
noise read from the torques' differences of order 2 and 3 was the motion's (6e-6 % of the
torques on a geared six-axis arm). The held-out error sat at 1.7e-6 % with accelerations
logged and 1.7e-4 % without, at every gear ratio.

References: the six-axis arm with a coupled wrist of the gear-ratio sweep
(``tests/test_rank_invariance.py``) simulated with known rotor inertias and motor friction,
judged on a second exact log the fit did not see; closed-form derivatives of harmonics and
polynomials; white noise of known std.
"""

from __future__ import annotations

import dataclasses
import warnings

import numpy as np
import pytest
from test_rank_invariance import _drive, _industrial

from dynid.cli.summaries import format_identification
from dynid.exceptions import DynidWarning
from dynid.friction.heldout_torques import heldout_torques
from dynid.friction.model import ClassicalFriction
from dynid.friction.validation import recorded_cutoff, validate_torques
from dynid.identification.input_noise import exact_to_round_off, quantized_noise_std
from dynid.identification.selection import identify_recordings
from dynid.identification.structure import Structure
from dynid.identification.velocity_noise import (
    at_round_off,
    signal_noise_std,
    smooth_noise_std,
    velocity_noise_std,
)
from dynid.signals import derivative, exact_derivative
from dynid.simulation.measurement import SensorNoise

from conftest import recordings

#: The truth's rotor inertias at the motors [kg m^2] and friction at the motors.
ROTORS = np.full(6, 1e-4)
FRICTION = ClassicalFriction(np.full(6, 2e-3), np.full(6, 4e-3), np.zeros(6))
#: Held-out relative error of an exact fit [%]: 1e-9 of the torques.
EXACT_PERCENT = 1e-7


def _exact_logs(
    ratio: float, seeds: tuple[int, ...], *, friction: bool = True, ddq: bool = True,
    duration: float = 10.0,
):  # fmt: skip
    """Noise-free motor-side logs (``duration`` s at 200 Hz) of the arm at gear ratio ``ratio`` with
    the truth's rotors (and motor friction), and the drive they are read through (its
    rotor inertias to identify)."""
    truth = dataclasses.replace(_drive(ratio), rotor_inertia=ROTORS)
    logs = recordings(
        _industrial(), seeds, friction=FRICTION if friction else None, drive=truth,
        duration=duration, fs=200.0,
    )  # fmt: skip
    if not ddq:
        logs = [dataclasses.replace(log, ddq=None) for log in logs]
    return logs, _drive(ratio)


def _heldout_percent(model, train, test) -> float:
    """The model's relative error [%] on the log ``test`` it was not fitted to."""
    held = heldout_torques(model, train, separate=test, others=[])
    return float(held.as_dict()["relative_error_percent"])


@pytest.mark.parametrize(
    ("ratio", "ddq"),
    [(1.0, True), (10.0, True), (50.0, True), (100.0, True), (200.0, True), (1.0, False),
     (200.0, False)],
)  # fmt: skip
def test_exact_geared_logs_fit_to_round_off_at_every_gear_ratio(ratio, ddq):
    """Regression: exact logs of the coupled-wrist arm were filtered at 6 Hz, trimmed and
    decimated, held-out error 1.7e-6 % (1.7e-4 % without ddq); now fitted unfiltered,
    within 1e-9 of the torques, at every gear ratio from 1 to 200 (without ddq columns:
    accelerations differentiated to order 8, at both ends of the sweep)."""
    (train, test), drive = _exact_logs(ratio, (1, 2), ddq=ddq)
    structure = Structure.parse("armature,viscous,coulomb,at:motor")
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", DynidWarning)
        model = identify_recordings(_industrial(), [train], structure=structure, drive=drive)
    assert model.info.log.cutoff_hz is None and model.info.log.decimate == 1
    assert any("exact to round-off" in note for note in model.info.notes)
    assert _heldout_percent(model, train, test) <= EXACT_PERCENT


@pytest.mark.parametrize("ratio", [1.0, 200.0])
def test_the_search_on_exact_friction_free_data_keeps_no_friction(ratio):
    """Regression: on an exact friction-free log without accelerations the search chose
    viscous friction at the motors at ratio 1, its noise floor read 1e-5 %; now the
    truth's structure, links and rotors, at both ends of the sweep, none kept for being
    determined, the floor at round-off and the note said in the selection; the summary's
    held-out line says its samples were not filtered."""
    (train,), drive = _exact_logs(ratio, (3,), friction=False, ddq=False, duration=3.0)
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", DynidWarning)
        model = identify_recordings(_industrial(), [train], drive=drive)
    sel = model.info.selection
    assert sel is not None
    assert sel["chosen"] == "links + armature", sel["chosen"]
    assert sel["kept_determined"] == []
    assert "exact to round-off" in sel["notes"][0]
    floor = model.info.heldout["noise_floor_percent"]
    assert floor < 1e-10, floor  # the noise read is the rounding
    text = format_identification(model, verdict_below=True)  # the summary says it as done
    assert "every sample unfiltered" in text and "filtered and decimated" not in text, text
    assert "after the no low-pass" not in text and "(every sample, unfiltered, after" in text, text


def test_a_noisy_log_is_not_read_as_exact():
    """Control: a geared log with sensor noise (0.05 N m, 1e-5 rad, 1e-3 rad/s) is
    filtered at the cut-off read from its motion, no note, its torques' noise the
    differences' estimate as before (about 0.05 N m through the gears)."""
    truth = dataclasses.replace(_drive(50.0), rotor_inertia=ROTORS)
    noise = SensorNoise(tau_std=0.05, q_std=1e-5, dq_std=1e-3)
    (log,) = recordings(_industrial(), (4,), friction=FRICTION, drive=truth, duration=3.0,
                        fs=200.0, noise=noise)  # fmt: skip
    assert not exact_to_round_off([log])
    np.testing.assert_array_equal(
        signal_noise_std(log.tau, log.t), velocity_noise_std(log.tau, log.t)
    )
    structure = Structure.parse("armature,viscous,coulomb,at:motor")
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", DynidWarning)
        model = identify_recordings(_industrial(), [log], structure=structure, drive=_drive(50.0))
    assert model.info.log.cutoff_hz is not None
    assert not any("exact to round-off" in note for note in model.info.notes)


@pytest.mark.parametrize(("start", "seconds"), [(2.0, 0.3), (2.0, 1.0), (4.5, 0.5)])
def test_a_log_exact_but_for_a_stretch_of_noise_is_not_read_as_exact(start, seconds):
    """Regression: an exact log with 0.05 N m of torque noise over 0.3 s or 1 s of its 5 s
    (fewer than half its samples) read exact from the medians of its whole columns and was
    fitted unfiltered, its noise floor printed as 3e-13 %; the blocks of 64 samples read
    on their own find the stretch (at the log's end too), and the exact log stays exact."""
    (log,), _ = _exact_logs(1.0, (5,), duration=5.0)
    assert exact_to_round_off([log])
    rng = np.random.default_rng(6)
    on = (log.t >= log.t[0] + start) & (log.t < log.t[0] + start + seconds)
    tau = log.tau + on[:, None] * rng.normal(0.0, 0.05, log.tau.shape)
    assert not exact_to_round_off([dataclasses.replace(log, tau=tau)])
    assert not at_round_off(tau, log.t).any()


def test_noise_of_smooth_signals_reads_their_rounding_and_white_noise_its_std():
    """Harmonics at 200 Hz (0.5 to 2 Hz) read noise at 1e-15 of their RMS (the
    differences of order 2 and 3 read 1e-4 to 1e-6); white noise of std 0.01 on them
    reads 0.01 within 10 %, and is not round-off, nor noise of 1e-6 on the last 3000 of
    5000 samples."""
    rng = np.random.default_rng(21)
    t = np.arange(5000) / 200.0
    f = rng.uniform(0.5, 2.0, 3)
    x = 5.0 + np.sin(2 * np.pi * f * t[:, None] + rng.uniform(0, 6, 3))
    rms = np.sqrt(np.mean(x**2, axis=0))
    assert np.all(smooth_noise_std(x) < 1e-14 * rms)
    assert np.all(velocity_noise_std(x) > 1e-9 * rms)
    assert at_round_off(x, t).all()
    noisy = x + rng.normal(0.0, 0.01, x.shape)
    np.testing.assert_allclose(smooth_noise_std(noisy), 0.01, rtol=0.1)
    assert not at_round_off(noisy, t).any()
    np.testing.assert_array_equal(quantized_noise_std(noisy, t), velocity_noise_std(noisy, t))
    late = x.copy()
    late[2000:] += rng.normal(0.0, 1e-6, (3000, 3))  # noise past the first samples read
    assert not at_round_off(late, t).any()
    jittered = t + rng.uniform(-1e-4, 1e-4, t.shape)
    assert not at_round_off(x, jittered).any()  # uneven stamps: never called exact


def test_exact_derivative_matches_closed_forms():
    """A harmonic of 1 Hz at 200 Hz: derivative within 1e-10 of its amplitude (second-order
    differences: 2e-4); a polynomial of degree 8 differentiated exactly (to 1e-9), ends
    included."""
    t = np.arange(1000) / 200.0
    w = 2 * np.pi * 1.0
    x = np.column_stack([np.sin(w * t), 300.0 * np.cos(w * t)])
    ref = np.column_stack([w * np.cos(w * t), -300.0 * w * np.sin(w * t)])
    err = np.max(np.abs(exact_derivative(t, x) - ref), axis=0) / np.array([w, 300.0 * w])
    assert np.all(err < 1e-10), err
    assert np.all(np.max(np.abs(derivative(t, x) - ref), axis=0) / np.array([w, 300 * w]) > 1e-5)
    s = np.arange(30) * 0.1
    c = np.random.default_rng(22).normal(size=9)
    p = np.polynomial.Polynomial(c)
    np.testing.assert_allclose(exact_derivative(s, p(s)), p.deriv()(s), rtol=0, atol=1e-9)


def test_a_model_fitted_on_exact_logs_is_validated_on_a_noisy_one_at_its_own_cutoff():
    """Regression: a model fitted unfiltered on exact logs recorded no cut-off, and
    validating it on a noisy recording left that recording unfiltered (2.7 % against 1.5 %
    filtered on a geared arm). Now it records the cut-off as read for being exact, and a
    noisy recording is filtered at the cut-off read from its own motion, as for a model
    without a cut-off (the truth's description); an exact recording stays unfiltered."""
    (train, exact_test), drive = _exact_logs(50.0, (1, 2), duration=5.0)
    structure = Structure.parse("armature,viscous,coulomb,at:motor")
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", DynidWarning)
        model = identify_recordings(_industrial(), [train], structure=structure, drive=drive)
    assert model.info.log.cutoff_source == "exact" and model.info.log.cutoff_hz is None
    truth = dataclasses.replace(_drive(50.0), rotor_inertia=ROTORS)
    noise = SensorNoise(tau_std=0.05, q_std=1e-5, dq_std=1e-3)
    (noisy,) = recordings(_industrial(), (4,), friction=FRICTION, drive=truth, duration=5.0,
                          fs=200.0, noise=noise)  # fmt: skip
    read = recorded_cutoff(_industrial(), noisy)  # identification's reading of its motion
    assert read is not None and recorded_cutoff(model, noisy) == read
    assert recorded_cutoff(model, exact_test) is None
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", DynidWarning)
        filtered = validate_torques(model, noisy).without_friction.relative_error_percent
        raw = validate_torques(model, noisy, cutoff_hz=None).without_friction
    assert filtered < 0.7 * raw.relative_error_percent, (filtered, raw.relative_error_percent)
