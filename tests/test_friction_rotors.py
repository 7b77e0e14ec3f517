"""``dynid friction --robot`` with a drive's known rotor inertias: the rigid-body torques
the friction is fitted to include the rotors' ``K^T diag(I_a) K ddq``, as validation adds
them, so that the robot's own friction scores alike in both."""

from __future__ import annotations

import numpy as np

from dynid.friction.model import ClassicalFriction
from dynid.io.torque_log import save_torque_log
from dynid.model.drive import Drive
from dynid.simulation.measurement import SensorNoise, sample_times, simulate_measurement
from dynid.simulation.trajectories import random_fourier
from dynid.workflows.friction import FrictionOptions, fit_friction_files
from dynid.workflows.validate import ValidateOptions, validate_files

from conftest import planar_2r

IA = np.array([0.05, 0.03])  # kg m^2 at the joints (gear 1)
FRICTION = ClassicalFriction(np.array([0.4, 0.2]), np.array([0.3, 0.1]), np.array([0.1, -0.05]))


def _arm_and_log(tmp_path):
    lim = np.array([2.5, 2.5])
    robot = planar_2r().replace(
        q_min=-lim, q_max=lim, dq_max=lim, ddq_max=4 * lim, friction=FRICTION
    )
    drive = Drive.from_gears([1.0, 1.0], rotor_inertia=IA, side="joint")
    t = sample_times(6.0, 200.0)
    log = simulate_measurement(
        robot,
        random_fourier(robot, np.random.default_rng(11))(t),
        rng=np.random.default_rng(12),
        noise=SensorNoise.none(),
        drive=drive,
        with_ddq=True,
    )
    return robot, drive, save_torque_log(tmp_path / "arm.csv", log)


def test_friction_residual_of_a_robot_holds_the_drive_s_rotors(tmp_path):
    """The simulation's torques are rnea + I_a ddq + friction: the residual the laws are
    fitted to is the friction alone (the rotors' I_a ddq, closed form, removed; it was
    left in), and the robot's own friction scores what validate gives."""
    robot, drive, path = _arm_and_log(tmp_path)
    res = fit_friction_files(robot, path, FrictionOptions(drive=drive))
    r = res.residual
    rotors = r.log.ddq * IA
    off = r.residual - FRICTION.torques(r.log.dq)
    moving = np.abs(r.log.dq) > 0.05  # the sign's flip is smeared by the filter
    rms = np.sqrt(np.mean(off[moving] ** 2, axis=0))
    assert np.all(rms < 0.02 * np.sqrt(np.mean(rotors**2, axis=0))), rms
    own = {s.name: s for s in res.selection.scores}["own"]
    val = validate_files(robot, path, ValidateOptions(drive=drive))
    assert abs(own.train_error_percent - val.validation.errors.relative_error_percent) < 1e-9
