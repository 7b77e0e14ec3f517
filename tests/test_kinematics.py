"""Forward kinematics, geometric Jacobians and angle-axis: finite differences, batching, errors."""

from __future__ import annotations

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

import dynid
from dynid import spatial

from conftest import random_states

BATCH_SHAPES = [(), (1,), (3, 2)]


def _fd_jacobian(robot, q, frame="flange", tool=None, h=1e-6):
    """Central differences of fk: position, and angle-axis of R(q + h) R(q - h)^T / 2h."""
    J = np.zeros((6, robot.n))
    for i in range(robot.n):
        dq = np.zeros(robot.n)
        dq[i] = h
        Tp = dynid.fk(robot, q + dq, frame, tool)
        Tm = dynid.fk(robot, q - dq, frame, tool)
        J[:3, i] = (Tp[:3, 3] - Tm[:3, 3]) / (2 * h)
        J[3:, i] = spatial.angle_axis_from_matrix(Tp[:3, :3] @ Tm[:3, :3].T) / (2 * h)
    return J


@pytest.mark.parametrize("frame", ["flange", "link4", "link7"])
def test_jacobian_equals_central_differences_of_fk(panda, frame):
    """J(q) matches central differences of the frame's position and orientation."""
    q, _, _ = random_states(panda, 20, seed=11)
    for qs in q:
        np.testing.assert_allclose(
            dynid.jacobian(panda, qs, frame), _fd_jacobian(panda, qs, frame), atol=1e-8
        )


def test_tool_jacobian_via_jacobian_to_tool_equals_direct_and_finite_differences(panda):
    """jacobian_to_tool(J_flange) == jacobian(tool=...) == finite differences of the tool pose."""
    rng = np.random.default_rng(12)
    q, _, _ = random_states(panda, 20, seed=12)
    for qs in q:
        T_flange_tool = spatial.transform_from_xyz_rpy(
            rng.uniform(-0.2, 0.2, 3), rng.uniform(-np.pi, np.pi, 3)
        )
        J_direct = dynid.jacobian(panda, qs, tool=T_flange_tool)
        J_carried = dynid.jacobian_to_tool(
            dynid.jacobian(panda, qs), dynid.fk(panda, qs), T_flange_tool
        )
        np.testing.assert_allclose(J_carried, J_direct, atol=1e-12)
        np.testing.assert_allclose(J_direct, _fd_jacobian(panda, qs, tool=T_flange_tool), atol=1e-8)


def test_jacobian_to_tool_batched_equals_loop(panda):
    """jacobian_to_tool on a (4, n) batch equals the per-sample result."""
    q, _, _ = random_states(panda, 4, seed=13)
    T_tool = spatial.transform_from_xyz_rpy([0.01, -0.02, 0.15], [0.1, 0.2, 0.3])
    Jb = dynid.jacobian_to_tool(dynid.jacobian(panda, q), dynid.fk(panda, q), T_tool)
    assert Jb.shape == (4, 6, panda.n)
    for s in range(4):
        np.testing.assert_allclose(Jb[s], dynid.jacobian(panda, q[s], tool=T_tool), atol=1e-12)


@settings(max_examples=15, deadline=None)
@given(shape=st.sampled_from(BATCH_SHAPES), seed=st.integers(0, 2**31 - 1))
def test_fk_and_jacobian_batch_equal_loop(shape, seed):
    """fk and jacobian on a batch keep its shape and equal the per-sample results."""
    robot = dynid.panda()
    rng = np.random.default_rng(seed)
    q = rng.uniform(robot.q_min, robot.q_max, shape + (robot.n,))
    tool = spatial.transform_from_xyz_rpy(rng.uniform(-0.1, 0.1, 3), rng.uniform(-1, 1, 3))
    T = dynid.fk(robot, q, "link5", tool)
    J = dynid.jacobian(robot, q, "link5", tool)
    assert T.shape == shape + (4, 4)
    assert J.shape == shape + (6, robot.n)
    for idx in np.ndindex(*shape):
        qs = q[idx]
        np.testing.assert_allclose(T[idx], dynid.fk(robot, qs, "link5", tool), atol=1e-14)
        np.testing.assert_allclose(J[idx], dynid.jacobian(robot, qs, "link5", tool), atol=1e-14)


def _random_axis(rng):
    u = rng.normal(size=3)
    return u / np.linalg.norm(u)


ANGLES = st.one_of(
    st.floats(0.0, 1e-6),  # near 0
    st.floats(1e-6, np.pi - 1e-3),  # regular
    st.floats(np.pi - 1e-3, np.pi),  # near pi
)


@settings(max_examples=200, deadline=None)
@given(angle=ANGLES, seed=st.integers(0, 2**31 - 1))
def test_angle_axis_from_matrix_round_trips_near_0_and_pi(angle, seed):
    """matrix_from_angle_axis(angle_axis_from_matrix(R)) == R, and the vector comes back."""
    rng = np.random.default_rng(seed)
    w = angle * _random_axis(rng)
    R = spatial.matrix_from_angle_axis(w)
    w_back = spatial.angle_axis_from_matrix(R)
    assert np.all(np.isfinite(w_back))
    np.testing.assert_allclose(spatial.matrix_from_angle_axis(w_back), R, atol=1e-12)
    assert abs(np.linalg.norm(w_back) - angle) < 1e-9
    if angle < np.pi - 1e-6:  # at pi, u and -u are the same rotation
        np.testing.assert_allclose(w_back, w, atol=1e-8)


def test_angle_axis_from_matrix_batch_near_pi_equals_loop():
    """A batch mixing tiny, regular and near-pi angles equals the per-sample results."""
    rng = np.random.default_rng(14)
    angles = np.array([0.0, 1e-10, 0.5, 2.0, 2.8, np.pi - 1e-7, np.pi])
    w = angles[:, None] * np.stack([_random_axis(rng) for _ in angles])
    R = spatial.matrix_from_angle_axis(w)
    out = spatial.angle_axis_from_matrix(R)
    assert out.shape == (len(angles), 3)
    for i in range(len(angles)):
        np.testing.assert_allclose(out[i], spatial.angle_axis_from_matrix(R[i]), atol=1e-15)
        np.testing.assert_allclose(spatial.matrix_from_angle_axis(out[i]), R[i], atol=1e-12)


@pytest.mark.parametrize("func", [dynid.fk, dynid.jacobian])
def test_unknown_frame_raises_unknown_name_error(panda, func):
    """An unknown frame name raises UnknownNameError listing the available frames."""
    with pytest.raises(dynid.UnknownNameError, match="Unknown frame 'gripper'; available"):
        func(panda, np.zeros(7), "gripper")


@pytest.mark.parametrize("func", [dynid.fk, dynid.jacobian])
def test_wrong_shapes_raise_shape_error(panda, func):
    """q without n trailing entries, or a tool that is not 4x4, raises ShapeError."""
    with pytest.raises(dynid.ShapeError, match=r"q must have shape \(\.\.\., 7\); got \(6,\)"):
        func(panda, np.zeros(6))
    with pytest.raises(dynid.ShapeError, match=r"q must have shape .*got \(3, 8\)"):
        func(panda, np.zeros((3, 8)))
    with pytest.raises(dynid.ShapeError, match=r"tool must have shape \(4, 4\)"):
        func(panda, np.zeros(7), tool=np.eye(3))


@pytest.mark.parametrize("func", [dynid.fk, dynid.jacobian])
def test_non_finite_q_raises_non_finite_error(panda, func):
    """NaN or inf in q raises NonFiniteError naming the first bad index."""
    q = np.zeros((2, 7))
    q[1, 3] = np.nan
    with pytest.raises(dynid.NonFiniteError, match=r"q must be finite; got nan at index \(1, 3\)"):
        func(panda, q)
    with pytest.raises(dynid.NonFiniteError, match="q must be finite"):
        func(panda, [0, 0, np.inf, 0, 0, 0, 0])
