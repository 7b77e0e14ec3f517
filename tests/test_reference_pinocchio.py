"""Cross-checks of kinematics and dynamics against Pinocchio on the Panda URDF."""

from __future__ import annotations

import numpy as np
import pytest

import dynid

from conftest import pinocchio_panda_urdf, random_states

pin = pytest.importorskip("pinocchio")


@pytest.fixture(scope="module")
def pin_panda():
    """Pinocchio's Panda (fingers locked) with the built-in Panda's inertials and gravity."""
    robot = dynid.panda()
    full = pin.buildModelFromUrdf(pinocchio_panda_urdf())
    lock = [full.getJointId(n) for n in ("panda_finger_joint1", "panda_finger_joint2")]
    model = pin.buildReducedModel(full, lock, pin.neutral(full))
    model.gravity.linear[:] = robot.gravity
    for i in range(1, 8):
        model.inertias[i] = pin.Inertia(robot.mass[i - 1], robot.com[i - 1], robot.inertia[i - 1])
    return robot, model, model.createData()


def test_fk_jacobian_dynamics_match_pinocchio_on_random_states(pin_panda):
    """FK of every link, Jacobian, RNEA, M, g and c equal Pinocchio's on 100 random states."""
    robot, model, data = pin_panda
    q, dq, ddq = random_states(robot, 100, seed=1)
    T = dynid.link_poses(robot, q)
    J = {k: dynid.jacobian(robot, q, f"link{k}") for k in range(1, 8)}
    tau = dynid.rnea(robot, q, dq, ddq)
    M = dynid.mass_matrix(robot, q)
    g = dynid.gravity_torques(robot, q)
    c = dynid.coriolis(robot, q, dq)
    for s in range(len(q)):
        pin.forwardKinematics(model, data, q[s])
        pin.updateFramePlacements(model, data)
        pin.computeJointJacobians(model, data, q[s])
        for k in range(1, 8):
            fid = model.getFrameId(f"panda_link{k}")
            np.testing.assert_allclose(T[s, k], data.oMf[fid].homogeneous, atol=1e-12)
            Jp = pin.getFrameJacobian(model, data, fid, pin.LOCAL_WORLD_ALIGNED)
            np.testing.assert_allclose(J[k][s], Jp, atol=1e-12)
        np.testing.assert_allclose(tau[s], pin.rnea(model, data, q[s], dq[s], ddq[s]), atol=1e-10)
        Mp = pin.crba(model, data, q[s])
        Mp = np.triu(Mp) + np.triu(Mp, 1).T
        np.testing.assert_allclose(M[s], Mp, atol=1e-10)
        gp = pin.computeGeneralizedGravity(model, data, q[s])
        np.testing.assert_allclose(g[s], gp, atol=1e-10)
        np.testing.assert_allclose(
            c[s], pin.nonLinearEffects(model, data, q[s], dq[s]) - gp, atol=1e-10
        )
