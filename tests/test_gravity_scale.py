"""A model identified through a wrong torque constant (one factor on every inertial
parameter) against the robot description: named with the factor; a description whose
masses are off joint by joint, or a factor near 1, is not.

Reference: models holding a known robot's exact gravity coefficients (the factor is the
one applied to its parameters), not fitted ones.
"""

from __future__ import annotations

import numpy as np
import pytest

import dynid
from dynid.identification.gravity_scale import gravity_ratios, gravity_scale_finding
from dynid.model.drive import Drive

from conftest import exact_model, perturbed_robot


@pytest.fixture(scope="module")
def q():
    """Configurations of a Panda spread over its range."""
    robot = dynid.panda()
    return np.random.default_rng(4).uniform(robot.q_min, robot.q_max, (400, 7))


def test_one_factor_on_every_parameter_is_named_with_the_torque_constant(q):
    """Parameters scaled by 0.83 (a torque constant guessed 1 for 1.2 N m/A): the ratio
    0.83 on every loaded joint, and the drive's torque constant to multiply by 1.2."""
    robot = dynid.panda()
    model = exact_model(robot, robot.with_params(0.83 * robot.phi))
    r, c, loaded = gravity_ratios(robot, model, q)
    np.testing.assert_allclose(r[loaded], 0.83, rtol=1e-9)
    drive = Drive(np.eye(7), np.zeros(7), effort="current", torque_constant=np.ones(7))
    said = gravity_scale_finding(robot, model, [q], drive)
    assert said is not None and "0.83 times the robot description's" in said
    assert "torque_constant" in said and "multiply it by 1.2" in said
    plain = gravity_scale_finding(robot, model, [q])
    assert plain is not None and "--units tau=1.2" in plain and "currents" not in plain
    # currents read as torques (3 times the model's): the drive of currents is named too,
    # its torque constants one per motor (a single --units factor fits one joint at most)
    currents = exact_model(robot, robot.with_params(1 / 3 * robot.phi))
    said = gravity_scale_finding(robot, currents, [q])
    assert said is not None and "--units tau=3" in said
    assert 'effort = "current"' in said and "torque_constant" in said


def test_masses_off_joint_by_joint_or_a_factor_near_one_say_nothing(q):
    """A description 20 % off per parameter at random, or every parameter 5 % off: None;
    the exact model: None."""
    robot = dynid.panda()
    other = perturbed_robot(robot, np.random.default_rng(3), spread=0.2)
    assert gravity_scale_finding(robot, exact_model(robot, other), [q]) is None
    near = exact_model(robot, robot.with_params(0.95 * robot.phi))
    assert gravity_scale_finding(robot, near, [q]) is None
    assert gravity_scale_finding(robot, exact_model(robot, robot), [q]) is None


def test_one_factor_near_a_shared_gear_ratio_names_constants_given_at_the_motors(q):
    """A joint-side drive of gear ratio 100 on every joint whose model came out 1/90 of
    the description (constants given at the motors, the masses 10 % off): the finding says
    the constants look given at the motors and what a joint-side log wants; with gear
    ratio 1, or a factor far from the gear ratio, it does not."""
    robot = dynid.panda()
    model = exact_model(robot, robot.with_params(robot.phi / 90.0))
    geared = Drive(100.0 * np.eye(7), np.zeros(7), effort="current", torque_constant=np.ones(7))
    said = gravity_scale_finding(robot, model, [q], geared)
    assert said is not None and "multiply it by 90" in said
    assert "near the gear ratio, 100: torque_constant looks given at the motors" in said
    plain = Drive(np.eye(7), np.zeros(7), effort="current", torque_constant=np.ones(7))
    assert "given at the motors" not in (gravity_scale_finding(robot, model, [q], plain) or "")
    far = exact_model(robot, robot.with_params(robot.phi / 2.0))
    assert "given at the motors" not in (gravity_scale_finding(robot, far, [q], geared) or "x")
