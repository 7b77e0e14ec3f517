"""No torque delay is read from a residual whose torques are on another scale than the
model's: a log of motor currents validated as torques (scale 0.01) read as the torques
leading the positions by 110-220 ms, named, and a `--torque-delay -143` hint followed.

Reference: a simulated Panda with heavy rotors and Coulomb friction whose torques are in
step with its positions (no lag) and whose scale is known (the factor applied).
"""

from __future__ import annotations

import dataclasses
import warnings

import numpy as np
import pytest

import dynid
from dynid.friction.delay_check import torque_scale, validations_delay
from dynid.friction.model import ClassicalFriction
from dynid.friction.validation import validate_torques
from dynid.model.drive import Drive
from dynid.simulation.measurement import SensorNoise, sample_times, simulate_measurement
from dynid.simulation.trajectories import random_fourier

FRICTION = ClassicalFriction(np.full(7, 0.5), np.full(7, 2.0), np.zeros(7))
DRIVE = Drive(transmission=np.eye(7), offset=np.zeros(7), rotor_inertia=np.full(7, 0.7))


@pytest.fixture(scope="module")
def arm_and_log():
    """The Panda and 12 s of its torques at 250 Hz, in step with the positions (a window
    of a Fourier trajectory), heavy rotors and Coulomb friction, sensor noise."""
    panda = dynid.panda().with_friction(None)
    traj = random_fourier(panda, np.random.default_rng(7))
    t = sample_times(12.0, 250.0) + 0.5
    noise = SensorNoise(tau_std=0.05, q_std=1e-5, dq_std=1e-3)
    log = simulate_measurement(
        panda, traj(t), rng=np.random.default_rng(9), noise=noise, friction=FRICTION, drive=DRIVE
    )
    return panda, log


def _validation(panda, log, scale):
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        tau = scale * log.tau
        return validate_torques(
            panda, dataclasses.replace(log, tau=tau), friction=FRICTION, drive=DRIVE
        )


def test_the_torque_scale_is_the_factor_applied(arm_and_log):
    """The logged torques against the prediction: the factor applied, to the noise."""
    panda, log = arm_and_log
    for scale in (1.0, 0.01, 100.0):
        found = torque_scale([_validation(panda, log, scale)])
        assert abs(found / scale - 1.0) < 0.01, (scale, found)


def test_no_delay_is_read_where_the_scale_is_grossly_off(arm_and_log):
    """Torques in step with the positions: at their own scale no delay is named; at a
    hundredth or a hundred times it none is read (before: a lead of about 170 ms named)."""
    panda, log = arm_and_log
    same = validations_delay(panda, [_validation(panda, log, 1.0)])
    assert same is not None and not same.named
    for scale in (0.01, 100.0):
        assert validations_delay(panda, [_validation(panda, log, scale)]) is None
