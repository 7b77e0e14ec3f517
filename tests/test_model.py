"""The robot model: construction checks, variants, inertial parameter conversions."""

from __future__ import annotations

import numpy as np
import pytest

import dynid
from dynid.model.inertia import inertial_from_phi, parallel_axis, phi_from_inertial
from dynid.model.robot import mdh_transform
from dynid.spatial import rot_x, rot_z, transform, translation


def test_panda_matches_published_tables(panda):
    """Built-in Panda: 7 joints, total mass 16.062132 kg (Gaz et al. p_hat), flange 0.107 m."""
    assert panda.n == 7
    np.testing.assert_allclose(panda.mass.sum(), 16.062132, rtol=1e-12)
    np.testing.assert_allclose(panda.frame("flange").T_link_frame[:3, 3], [0, 0, 0.107])
    np.testing.assert_allclose(panda.q_max[3], -0.0698)
    assert panda.friction.kind == "sigmoid" and panda.friction.drive is None
    np.testing.assert_array_equal(panda.friction.params, dynid.model.panda.PANDA_FRICTION)
    # Gaz et al. 2019, supplementary Table I: joint 1's phi1, phi2, phi3
    np.testing.assert_array_equal(panda.friction.params[0], [0.54615, 5.1181, 0.039533])


def test_mdh_transform_is_the_product_of_elementary_transforms():
    """RotX(alpha) TransX(a) RotZ(theta) TransZ(d) from elementary factors."""
    a, d, al, th = 0.3, -0.2, 0.7, -1.1
    Rx = transform(rot_x(al), np.zeros(3))
    Rz = transform(rot_z(th), np.zeros(3))
    expected = Rx @ translation([a, 0, 0]) @ Rz @ translation([0, 0, d])
    np.testing.assert_allclose(mdh_transform(a, d, al, th), expected, atol=1e-15)


def test_parallel_axis_round_trip_and_point_mass():
    """phi <-> (m, c, I) round trip; a point mass has J = m (|c|^2 E - c c^T) about the origin."""
    rng = np.random.default_rng(20)
    m = rng.uniform(0.5, 3, 4)
    c = rng.normal(size=(4, 3))
    A = rng.normal(size=(4, 3, 3))
    I = A @ np.swapaxes(A, 1, 2)
    phi = phi_from_inertial(m, c, I)
    m2, c2, I2 = inertial_from_phi(phi)
    np.testing.assert_allclose(m2, m)
    np.testing.assert_allclose(c2, c)
    np.testing.assert_allclose(I2, I, atol=1e-13)
    J = phi_from_inertial(2.0, [1.0, 0, 0], np.zeros((3, 3)))[4:]
    np.testing.assert_allclose(J, [0, 0, 0, 2.0, 0, 2.0])
    np.testing.assert_allclose(parallel_axis(1.0, [0, 0, 1.0]), np.diag([1.0, 1.0, 0.0]))


def test_robot_arrays_are_read_only(panda):
    """The model is immutable: its arrays cannot be written."""
    with pytest.raises(ValueError):
        panda.phi[0, 0] = 1.0
    with pytest.raises(AttributeError):
        panda.name = "x"


def test_with_tool_adds_frame_and_inertia(panda):
    """with_tool adds a 'tool' frame and the tool's mass to link 7; M grows accordingly."""
    T = translation([0, 0, 0.1])
    r = panda.with_tool(T, mass=0.5, com=[0, 0, 0.02])
    np.testing.assert_allclose(r.mass[6], panda.mass[6] + 0.5)
    np.testing.assert_allclose(
        dynid.fk(r, dynid.PANDA_NEUTRAL_Q, "tool"), dynid.fk(panda, dynid.PANDA_NEUTRAL_Q) @ T
    )
    # a point mass at the tool CoM adds m * Jv^T Jv to M
    q = dynid.PANDA_NEUTRAL_Q
    Jv = dynid.jacobian(panda, q, "flange", tool=translation([0, 0, 0.12]))[:3]
    np.testing.assert_allclose(
        dynid.mass_matrix(r, q) - dynid.mass_matrix(panda, q), 0.5 * Jv.T @ Jv, atol=1e-12
    )


def test_bad_models_are_rejected():
    """Bad structure raises ModelError/ShapeError with a clear message."""
    with pytest.raises(dynid.ModelError, match="lower position limit"):
        dynid.Robot.from_mdh([0, 0], [0, 0], [0, 0], q_min=[0, 1], q_max=[1, 0])
    with pytest.raises(dynid.ShapeError, match="same shape"):
        dynid.Robot.from_mdh([0, 0], [0], [0, 0])
    with pytest.raises(dynid.ModelError, match="joint_types"):
        dynid.Robot.from_mdh([0, 0], [0, 0], [0, 0], joint_types="RX")
    with pytest.raises(dynid.NonFiniteError, match="mass"):
        dynid.Robot.from_mdh([0], [0], [0], mass=[np.nan])


def test_unknown_frame_lists_available(panda):
    """An unknown frame name raises UnknownNameError listing the frames."""
    with pytest.raises(dynid.UnknownNameError, match="Unknown frame 'hand'; available"):
        dynid.fk(panda, np.zeros(7), "hand")
    with pytest.raises(KeyError):
        panda.joint_index("panda_joint8")


def test_a_robot_pickles_and_copies_bit_for_bit(panda):
    """pickle and copy.deepcopy give the same model (for process pools); arrays stay frozen."""
    import copy
    import pickle

    from dynid import _kernels

    robot = panda.with_friction(
        dynid.SigmoidFriction.from_array(np.tile([0.5, 30.0, 0.01], (7, 1)))
    ).with_frame("tcp", np.diag([1.0, -1.0, -1.0, 1.0]))
    q = np.linspace(-1.0, 1.0, 7)
    dynid.rnea(robot, q, q, q)  # the packed arrays exist and must not travel
    for other in (pickle.loads(pickle.dumps(robot)), copy.deepcopy(robot)):
        assert _kernels.cached(other) is None and other.frames.keys() == robot.frames.keys()
        for name in ("T_parent_joint", "axes", "prismatic", "phi", "q_min", "q_max", "dq_max",
                     "ddq_max", "tau_max", "gravity", "q_neutral"):  # fmt: skip
            a, b = getattr(robot, name), getattr(other, name)
            np.testing.assert_array_equal(a, b)
            assert not b.flags.writeable
        assert other.friction.kind == robot.friction.kind
        np.testing.assert_array_equal(other.friction.params, robot.friction.params)
        assert not other.friction.params.flags.writeable
        tcp = (r.frame("tcp").T_link_frame for r in (other, robot))
        np.testing.assert_array_equal(*tcp)
        np.testing.assert_array_equal(dynid.rnea(other, q, q, q), dynid.rnea(robot, q, q, q))
        assert (other.name, other.joint_names, other.link_names) == (
            robot.name,
            robot.joint_names,
            robot.link_names,
        )
