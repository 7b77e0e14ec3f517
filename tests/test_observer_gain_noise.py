"""The velocities' noise times the observer's gain in a calibration residual.

The docs said "a larger --gain detects sooner"; on a Panda with noisy velocities the
calibrated thresholds grew in proportion to the gain (joint 1: 0.72, 1.79, 5.6 N m at
gains 20, 50, 150) because the residual reads ``K_O M(q) n_dq``. References: a simulated
Panda with known white velocity noise ``sigma`` and no other error (the exact model, no
friction, no torque noise), and ``M(q)`` from Pinocchio on example-robot-data's Panda.
"""

from __future__ import annotations

import numpy as np
import pytest

import dynid
from dynid.observer.gain_noise import DOMINANT, GainNoiseTally
from dynid.observer.model import from_robot
from dynid.observer.residual import ObserverOptions, observe
from dynid.simulation.measurement import SensorNoise, sample_times, simulate_measurement
from dynid.simulation.trajectories import random_fourier

SIGMA = 2e-3  # rad/s, the velocities' white noise


def _log(sigma: float):
    panda = dynid.panda()
    rng = np.random.default_rng(21)
    traj = random_fourier(panda, rng)(sample_times(4.0, 1000.0))
    noise = SensorNoise(tau_std=0.0, q_std=0.0, dq_std=sigma)
    return panda, simulate_measurement(panda, traj, rng=rng, noise=noise, friction=None)


def _pinocchio_diag_rms(q: np.ndarray) -> np.ndarray:
    """``sqrt(mean_t sum_k M_jk(q_t)^2)`` (n,) from Pinocchio's CRBA [kg m^2]."""
    pin = pytest.importorskip("pinocchio")
    from conftest import pinocchio_panda_model

    model = pinocchio_panda_model()  # dynid's Panda inertials (Gaz et al.) on Pinocchio's chain
    data = model.createData()
    total = np.zeros(7)
    for x in q:
        M = pin.crba(model, data, x)
        M = np.triu(M) + np.triu(M, 1).T
        total += np.sum(M**2, axis=1)
    return np.sqrt(total / len(q))


@pytest.mark.parametrize("gain", [20.0, 150.0])
def test_the_velocities_noise_times_the_gain_is_the_residual_of_an_exact_model(gain):
    """An exact model observed on velocities with white noise: the predicted RMS is
    ``K_O sigma sqrt(mean sum_k M_jk^2)`` (Pinocchio's M, within 5 %), it explains the
    residual's (within 15 %) and every joint reads dominated, at either gain."""
    panda, log = _log(SIGMA)
    model = from_robot(panda, friction=None)
    r = observe(model, log.t, log.q, log.dq, log.tau, ObserverOptions(gain=gain)).r
    tally = GainNoiseTally(model, np.array(gain))
    for a in range(0, log.t.size, 1000):  # blocks, as the calibration reads them
        b = a + 1000
        tally.add(log.q[a:b], log.dq[a:b], r[a:b])
    res = tally.result()
    assert res is not None
    expected = gain * SIGMA * _pinocchio_diag_rms(log.q[::10])
    np.testing.assert_allclose(res.predicted, expected, rtol=0.05)
    np.testing.assert_allclose(res.residual, res.predicted, rtol=0.15)
    assert res.dominated == tuple(range(7)) and np.all(res.share >= DOMINANT)


def test_noise_free_velocities_dominate_no_joint():
    """Without velocity noise the residual holds no gain-times-noise part: no joint is
    named, and the predicted RMS is near zero against the residual's."""
    panda, log = _log(0.0)
    model = from_robot(panda, friction=None)
    r = observe(model, log.t, log.q, log.dq, log.tau).r
    tally = GainNoiseTally(model, np.array(50.0))
    tally.add(log.q, log.dq, r)
    res = tally.result()
    assert res is not None and res.dominated == ()
    assert np.all(res.predicted < 1e-6)
