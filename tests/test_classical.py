"""Classical identification from torque logs of exciting (Fourier) trajectories."""

from __future__ import annotations

import numpy as np
import pytest

from dynid.exceptions import RankDeficientError, ShapeError
from dynid.friction.model import ClassicalFriction
from dynid.identification.classical import (
    auto_decimation,
    friction_labels,
    friction_regressor,
    identify_from_log,
)
from dynid.identification.log import TorqueLog
from dynid.identification.metrics import mse, relative_error_percent, rms, torque_errors
from dynid.regressors.base import base_parameters
from dynid.simulation.measurement import SensorNoise, sample_times, simulate_measurement
from dynid.simulation.trajectories import random_fourier, sinusoid_trajectory

NOISE = 0.05


@pytest.fixture(scope="module")
def torque_base(panda):
    return base_parameters(panda, kind="torque")


def test_noise_free_identification_recovers_base_parameters_and_friction(panda, torque_base):
    """Noise-free Fourier data with exact ddq: beta equals beta_from_phi(phi) to 1e-9."""
    series = random_fourier(panda, np.random.default_rng(31))
    truth = ClassicalFriction(
        np.linspace(0.05, 0.2, 7), np.linspace(0.3, 0.1, 7), np.linspace(-0.03, 0.03, 7)
    )
    log = simulate_measurement(
        panda,
        series(sample_times(10.0, 500.0)),
        rng=np.random.default_rng(32),
        noise=SensorNoise.none(),
        friction=truth,
        with_ddq=True,
    )
    model = identify_from_log(
        panda, log, cutoff_hz=None, base=torque_base, structure="classical", estimator="ols"
    )
    beta = torque_base.beta_from_phi(panda.phi)
    np.testing.assert_allclose(model.beta, beta, rtol=1e-6, atol=1e-9 * np.max(np.abs(beta)))
    np.testing.assert_allclose(model.friction.params, truth.as_array(), atol=1e-9)
    assert model.fit.relative_error_percent < 1e-7
    assert model.info.route == "classical"
    assert model.terms["friction"].labels[:4] == ("fv1", "fc1", "fo1", "fv2")
    assert np.isfinite(model.fit.condition_number) and model.fit.rank == torque_base.rank + 21


def test_noise_free_identification_from_filtered_velocities(panda, torque_base):
    """Without given ddq (differentiated from a slowly filtered dq) beta is still close."""
    series = random_fourier(panda, np.random.default_rng(33))
    log = simulate_measurement(
        panda,
        series(sample_times(20.0, 1000.0)),
        rng=np.random.default_rng(34),
        noise=SensorNoise.none(),
        friction=None,
    )
    model = identify_from_log(
        panda,
        log,
        cutoff_hz=20.0,
        friction=False,
        base=torque_base,
        structure="classical",
        estimator="ols",
    )
    beta = torque_base.beta_from_phi(panda.phi)
    # filtering bias only: relative error of the fit tiny, parameters within 1e-3 of scale
    assert model.fit.relative_error_percent < 0.01
    assert np.max(np.abs(model.beta - beta)) < 1e-3 * np.max(np.abs(beta))


@pytest.mark.filterwarnings("ignore:.*indistinguishable from zero")  # expected: weak coefficients
def test_noisy_identification_predicts_held_out_torques_to_the_noise_level(panda, torque_base):
    """With 0.05 N m sensor noise the model predicts another trajectory to the noise level."""
    t = sample_times(20.0, 1000.0)
    train = simulate_measurement(
        panda,
        random_fourier(panda, np.random.default_rng(35))(t),
        rng=np.random.default_rng(36),
        friction=None,
    )
    model = identify_from_log(
        panda, train, friction=True, base=torque_base, structure="classical", estimator="ols"
    )
    held = random_fourier(panda, np.random.default_rng(37))(t)
    test = simulate_measurement(panda, held, rng=np.random.default_rng(38), friction=None)
    pred = model.torques(held.q, held.dq, held.ddq)
    pred = pred + ClassicalFriction.from_array(model.friction.params).torques(held.dq)
    r = rms(test.tau, pred)
    assert np.all(r < 1.1 * NOISE), r
    assert np.all(r > 0.9 * NOISE), r  # the noise itself
    # no friction in the data: identified friction is small
    assert np.max(np.abs(model.friction.params)) < 0.02
    # the estimated sigma of the fit reflects the filtered noise, well below the raw noise
    assert model.fit.sigma < NOISE


def test_identification_rejects_a_trajectory_that_does_not_excite(panda, torque_base):
    """Only joint 7 moving cannot identify the 43 base parameters: RankDeficientError."""
    A = np.zeros(7)
    A[6] = 1.0
    q0 = np.array([0.0, -0.5, 0.0, -2.0, 0.0, 1.5, 0.0])
    traj = sinusoid_trajectory(sample_times(5.0, 200.0), q0, A, np.full(7, 2.0))
    log = simulate_measurement(
        panda, traj, rng=np.random.default_rng(39), noise=SensorNoise.none(), with_ddq=True
    )
    with pytest.raises(RankDeficientError, match="rank"):
        identify_from_log(
            panda, log, cutoff_hz=None, base=torque_base, structure="classical", estimator="ols"
        )


def test_identification_rejects_a_log_of_another_robot(panda, torque_base):
    """A log with a different joint count is a ShapeError."""
    t = np.arange(10) * 0.01
    z = np.zeros((10, 3))
    with pytest.raises(ShapeError, match="log has 3 joints"):
        identify_from_log(
            panda, TorqueLog(t, z, z, z), base=torque_base, structure="classical", estimator="ols"
        )


def test_friction_regressor_layout():
    """Row j holds (dq_j, sign dq_j, 1) in columns 3j..3j+2, labels fv, fc, fo per joint."""
    dq = np.array([[0.5, -2.0, 0.0]])
    F = friction_regressor(dq)
    assert F.shape == (1, 3, 9)
    np.testing.assert_array_equal(F[0, 1, 3:6], [-2.0, -1.0, 1.0])
    np.testing.assert_array_equal(F[0, 2, 6:9], [0.0, 0.0, 1.0])
    assert F[0, 0, 3:].sum() == 0.0
    assert friction_labels(2) == ("fv1", "fc1", "fo1", "fv2", "fc2", "fo2")
    assert auto_decimation(1000.0, 10.0) == 10 and auto_decimation(1000.0, None) == 1


def test_torque_metrics_against_hand_computed_values():
    """RMS, MSE and relative error of a small example computed by hand."""
    tau = np.array([[1.0, 2.0], [3.0, -4.0]])
    hat = np.array([[1.0, 1.0], [2.0, -4.0]])
    np.testing.assert_allclose(rms(tau, hat), [np.sqrt(0.5), np.sqrt(0.5)])
    np.testing.assert_allclose(mse(tau, hat), [0.5, 0.5])
    assert relative_error_percent(tau, hat) == pytest.approx(100 * np.sqrt(2) / np.sqrt(30))
    e = torque_errors(tau, hat)
    np.testing.assert_allclose(
        e.relative_error_percent_per_joint, [100 / np.sqrt(10), 100 / np.sqrt(20)]
    )
    with pytest.raises(ShapeError, match="tau and tau_hat"):
        rms(tau, hat[:1])
