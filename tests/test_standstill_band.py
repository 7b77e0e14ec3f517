"""The Coulomb sign's standstill band counts the noise the velocities hold as prepared
(low-passed), not the raw noise: a slowly moving joint keeps its Coulomb friction through
most of its reversals."""

from __future__ import annotations

import math
import warnings

import numpy as np
import pytest
import scipy.integrate

import dynid
from dynid.exceptions import DynidWarning
from dynid.friction.model import ClassicalFriction
from dynid.friction.validation import own_friction
from dynid.identification.recordings import prepare_recordings
from dynid.identification.selection import identify_recordings
from dynid.identification.structure import Structure
from dynid.signals import lowpass, lowpass_noise_gain
from dynid.simulation.measurement import SensorNoise, sample_times, simulate_measurement
from dynid.simulation.trajectories import random_fourier

NOISE = 0.05  # N m, the default simulated torque noise


@pytest.mark.parametrize(("fs", "fc"), [(1000.0, 5.0), (500.0, 6.0), (100.0, 2.0)])
def test_noise_gain_of_the_zero_phase_butterworth_is_the_closed_form(fs, fc):
    """White noise through ``|H|^2 = 1 / (1 + (f / fc)^8)^2``: the variance falls by
    ``(2 fc / fs) int_0^inf dx / (1 + x^8)^2`` (the digital filter's warping aside)."""
    integral = scipy.integrate.quad(lambda x: 1.0 / (1.0 + x**8) ** 2, 0.0, np.inf)[0]
    closed = math.sqrt(2.0 * fc / fs * integral)
    assert lowpass_noise_gain(fs, fc) == pytest.approx(closed, rel=2e-3)
    assert lowpass_noise_gain(fs, None) == 1.0


def test_noise_gain_is_what_the_lowpass_leaves_of_white_noise():
    x = np.random.default_rng(0).standard_normal(400_000)
    left = float(np.std(lowpass(x, 500.0, 6.0)[2000:-2000]))
    assert left == pytest.approx(lowpass_noise_gain(500.0, 6.0), rel=0.02)


@pytest.fixture(scope="module")
def slow_arm():
    """A Panda moving slowly (peak 0.2-0.3 rad/s) with Coulomb friction 0.3-0.8 N m and
    velocity noise 2e-3 rad/s (a raw standstill band of 0.01 rad/s): three recordings and a
    fourth held out with its true states."""
    panda = dynid.panda()
    fr = ClassicalFriction(np.full(7, 0.2), np.linspace(0.8, 0.3, 7), np.zeros(7))
    t = sample_times(8.0, 500.0)

    def recording(seed, noise):
        traj = random_fourier(panda, np.random.default_rng(seed), margin=0.15)(t)
        log = simulate_measurement(
            panda, traj, rng=np.random.default_rng(seed + 100), noise=noise, friction=fr
        )
        return traj, log

    logs = [recording(s, SensorNoise(dq_std=2e-3))[1] for s in (31, 32, 33)]
    return panda, fr, logs, recording(34, SensorNoise())


def test_the_band_is_the_filtered_noise_band(slow_arm):
    panda, _, logs, _ = slow_arm
    data = prepare_recordings(panda, logs)
    gain = lowpass_noise_gain(500.0, data.cutoff_hz)
    assert data.band_gain == pytest.approx(gain)
    np.testing.assert_allclose(data.band, 5 * 2e-3, rtol=0.1)  # the raw noise band
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", DynidWarning)
        model = identify_recordings(panda, logs, structure=Structure(False, ("viscous", "coulomb")))
    np.testing.assert_allclose(model.friction.band, gain * data.band, rtol=1e-12)
    # a smooth Coulomb's width counts in the same band
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", DynidWarning)
        smooth = identify_recordings(panda, logs, structure=Structure.parse("viscous + smooth:3"))
    np.testing.assert_allclose(smooth.friction.band, 3 * gain * data.band, rtol=1e-12)


def test_a_slow_arm_keeps_its_coulomb_friction_through_reversals(slow_arm):
    """With the raw noise's band (0.01 rad/s) the fit lost the Coulomb torque of every
    slow reversal and predicted the held-out recording at up to 3 times its noise; with
    the filtered noise's band, within 2.5 times on every joint."""
    panda, fr, logs, (held, test) = slow_arm
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", DynidWarning)
        model = identify_recordings(panda, logs)
    pred = model.torques(held.q, held.dq, held.ddq) + own_friction(model).torques(held.dq)
    rms = np.sqrt(np.mean((test.tau - pred) ** 2, axis=0))
    assert np.all(rms < 2.5 * NOISE), rms / NOISE
