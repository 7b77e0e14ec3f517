"""The torque-sign check on joints whose Coulomb friction outweighs their rigid bodies.

References: simulated recordings with a known sign and known friction (80 N m Coulomb and
10 N m s/rad viscous on one shoulder joint): a UR5 (example-robot-data) whose shoulder
creeps slowly up at the top of its stroke and down at the bottom, so that its friction
runs against its gravity torques, and the Panda on a random Fourier trajectory; the same
torques with that joint's column negated are the truly flipped logs.
"""

from __future__ import annotations

import dataclasses

import numpy as np
from scipy.ndimage import gaussian_filter1d

import dynid
from dynid.friction.model import ClassicalFriction
from dynid.identification.model_sign import opposite_sign
from dynid.io.robot.urdf_parse import load_urdf
from dynid.simulation.measurement import SensorNoise, sample_times, simulate_measurement
from dynid.simulation.trajectories import Trajectory, random_fourier

from conftest import recordings, robot_data_urdf

FC, FV = 80.0, 10.0  # N m, N m s/rad: the shoulder's friction


def _friction(n: int, j: int) -> ClassicalFriction:
    """Light friction on every joint, 80 N m Coulomb and 10 N m s/rad on joint ``j``."""
    v, c = np.full(n, 0.3), np.full(n, 0.5)
    v[j], c[j] = FV, FC
    return ClassicalFriction(v, c, np.zeros(n))


def _creeping_ur5_log(robot: dynid.Robot, seed: int):
    """16 s at 500 Hz: the shoulder (joint 2) rises fast to the top of a 1.2 rad stroke
    about -0.8 rad, creeps up at 8 mrad/s for most of 8 s, falls fast and creeps down
    likewise; the other joints on a slow random Fourier trajectory."""
    t = sample_times(16.0, 500.0)
    k = 0.1  # the other joints' motion slowed tenfold
    base = random_fourier(robot, np.random.default_rng(seed))(t * k)
    q, dq, ddq = base.q.copy(), base.dq * k, base.ddq * k * k
    u = (t % 16.0) / 16.0
    vel = np.where(u < 0.08, 1.0, np.where(u < 0.5, 0.008, np.where(u < 0.58, -1.0, -0.008)))
    vel = gaussian_filter1d(vel, 150.0, mode="wrap")
    vel -= vel.mean()
    dt = float(t[1] - t[0])
    s = np.cumsum(vel) * dt
    scale = 1.2 / (s.max() - s.min())
    q[:, 1] = (s - (s.max() + s.min()) / 2) * scale - 0.8
    dq[:, 1] = vel * scale
    ddq[:, 1] = np.gradient(dq[:, 1], dt)
    return simulate_measurement(
        robot,
        Trajectory(t, q, dq, ddq),
        rng=np.random.default_rng(seed + 100),
        noise=SensorNoise(tau_std=0.05, q_std=1e-5, dq_std=1e-3),
        friction=_friction(robot.n, 1),
        with_ddq=False,
    )


def _negated(log, j: int):
    """``log`` with joint ``j``'s torque column negated."""
    tau = log.tau.copy()
    tau[:, j] *= -1.0
    return dataclasses.replace(log, tau=tau)


def test_large_coulomb_friction_against_gravity_is_no_flipped_sign():
    """Regression: a right-signed UR5 shoulder with 80 N m Coulomb friction running
    against its gravity torques correlated -0.52 with its model's torques and was called
    flipped (hint --units tau2=-1): the veto's fit left the friction's full step at every
    reversal, where the velocity is within its noise, and those few samples outweighed
    the rest. It is now read as friction; the same torques negated are found flipped."""
    robot = load_urdf(robot_data_urdf("ur_description/urdf/ur5_robot.urdf"), tip_link="tool0")
    log = _creeping_ur5_log(robot, 64)
    assert opposite_sign(robot, log) is None
    said = opposite_sign(robot, _negated(log, 1))
    assert said is not None and "tau2=-1" in said and robot.joint_names[1] in said, said
    assert "as read its friction would push the arm" in said, said


def test_a_flipped_joint_whose_friction_outweighs_gravity_is_found(panda):
    """A Panda shoulder with 80 N m Coulomb friction on a random Fourier trajectory: its
    torques correlate -0.2 to -0.4 with the model's when negated, and the flip went
    unnoticed; the friction that pushes as read, the negated torques the model's plus
    friction, now names it, and the torques of the right sign are not named."""
    logs = recordings(
        panda,
        (61, 62),
        friction=_friction(7, 1),
        duration=6.0,
        noise=SensorNoise(tau_std=0.05, q_std=1e-5, dq_std=1e-3),
    )
    for log in logs:
        assert opposite_sign(panda, log) is None
        said = opposite_sign(panda, _negated(log, 1))
        assert said is not None and "tau2=-1" in said, said
        m = said.split("Coulomb ")[1].split(" N m")[0]
        assert abs(float(m) + FC) < 0.1 * FC, said


def test_every_flipped_joint_is_named_at_once(panda):
    """Regression: a log flipped on a shoulder and on a wrist joint gravity barely loads
    was refused naming the shoulder alone, and the wrist only on the next run (by the
    fit's friction that puts energy into the arm); beside a joint found opposite, the
    joints the model's torques do not tell are asked of their friction too, and both
    flips are named in one hint. The right-signed log names none."""
    friction = ClassicalFriction(np.full(7, 2.0), np.full(7, 2.0), np.zeros(7))
    (log,) = recordings(
        panda,
        (65,),
        friction=friction,
        duration=6.0,
        noise=SensorNoise(tau_std=0.05, q_std=1e-5, dq_std=1e-3),
    )
    assert opposite_sign(panda, log) is None
    said = opposite_sign(panda, _negated(_negated(log, 1), 6))
    assert said is not None and "tau2=-1,tau7=-1" in said, said
