"""Inverse kinematics: convergence on random reachable goals, limits, unreachable goals, errors."""

from __future__ import annotations

import importlib
import os

import numpy as np
import pytest

import dynid
from dynid import spatial
from dynid.exceptions import DataError, LimitError, ShapeError
from dynid.kinematics import IKOptions, IKResult, default_q0, ik

from conftest import random_states

# the IK driver module and its numpy reference loop
ik_module = importlib.import_module("dynid.kinematics.inverse")
ik_numpy = importlib.import_module("dynid.kinematics._ik_numpy")

TOOL = spatial.transform_from_xyz_rpy([0.0, 0.0, 0.1])


def _errors(robot, q, T_goal, frame="flange", tool=None):
    """Position [m] and orientation [rad] errors at q, from fk (independent of the solver).

    The angle of ``R_goal R^T`` is ``atan2(|skew part|, (trace - 1) / 2)``, accurate over
    ``[0, pi]``.
    """
    T = dynid.fk(robot, q, frame, tool)
    e_p = np.linalg.norm(T_goal[:3, 3] - T[:3, 3])
    R = T_goal[:3, :3] @ T[:3, :3].T
    s = 0.5 * np.linalg.norm([R[2, 1] - R[1, 2], R[0, 2] - R[2, 0], R[1, 0] - R[0, 1]])
    e_o = np.arctan2(s, 0.5 * (np.trace(R) - 1.0))
    return e_p, e_o


def _within_limits(robot, path):
    return np.all(path >= robot.q_min) and np.all(path <= robot.q_max)


@pytest.mark.parametrize("tool", [None, TOOL], ids=["flange", "tool"])
def test_ik_converges_on_at_least_99_percent_of_200_random_reachable_goals(panda, tool):
    """From the neutral pose, >= 99 % of 200 goals fk(random q in limits) converge to 1e-6."""
    q_true, _, _ = random_states(panda, 200, seed=21)
    T_goal = dynid.fk(panda, q_true, tool=tool)
    converged = 0
    for T in T_goal:
        res = ik(panda, T, tool=tool)
        assert _within_limits(panda, res.path)
        np.testing.assert_array_equal(res.path[0], dynid.PANDA_NEUTRAL_Q)
        if res.converged:
            converged += 1
            e_p, e_o = _errors(panda, res.q, T, tool=tool)
            assert e_p <= 1e-6 and e_o <= 1e-6
            np.testing.assert_allclose(
                [res.position_error, res.orientation_error], [e_p, e_o], atol=1e-12
            )
    assert converged >= 198, f"{converged}/200 converged"


def test_ik_unreachable_goal_returns_best_q_with_its_errors(panda):
    """A goal 2 m away gives converged=False, the best q in the limits and its true errors."""
    T_goal = spatial.transform_from_xyz_rpy([2.0, 0.0, 0.3], [np.pi, 0.0, 0.0])
    res = ik(panda, T_goal, rng=np.random.default_rng(22))
    assert not res.converged
    assert res.position_error > 1.0
    e_p, e_o = _errors(panda, res.q, T_goal)
    np.testing.assert_allclose([res.position_error, res.orientation_error], [e_p, e_o], atol=1e-12)
    assert _within_limits(panda, res.path)
    assert res.path.shape == (res.iterations + 1, panda.n)
    assert any(np.array_equal(res.q, row) for row in res.path)
    # no point of the path is much closer (the best one is returned; the reach is ~0.86 m)
    d = np.linalg.norm(dynid.fk(panda, res.path)[:, :3, 3] - T_goal[:3, 3], axis=-1)
    assert res.position_error <= d.min() + 0.05


def test_ik_path_respects_position_and_velocity_limits_and_starts_at_q0(panda):
    """Every path row lies within [q_min, q_max]; steps respect dq_max * dt; row 0 is q0."""
    rng = np.random.default_rng(23)
    q_true, _, _ = random_states(panda, 30, seed=23)
    opts = IKOptions(dt=0.05, gain=20.0)
    for qt in q_true:
        q0 = rng.uniform(panda.q_min, panda.q_max)
        res = ik(panda, dynid.fk(panda, qt), q0, options=opts, rng=rng)
        assert res.path.shape == (res.iterations + 1, panda.n)
        np.testing.assert_array_equal(res.path[0], q0)
        assert _within_limits(panda, res.path)
        speed = np.abs(np.diff(res.path, axis=0)) / opts.dt
        assert np.all(speed <= panda.dq_max * (1 + 1e-9))
        if res.converged:
            np.testing.assert_array_equal(res.q, res.path[-1])


def test_ik_goal_near_joint_limits_converges_with_joints_on_their_limits(panda):
    """Goals from configurations with joints at their limits are reached within the limits."""
    rng = np.random.default_rng(24)
    for _ in range(10):
        qt = rng.uniform(panda.q_min, panda.q_max)
        j = rng.choice(panda.n, 2, replace=False)
        qt[j] = np.where(rng.random(2) < 0.5, panda.q_min[j], panda.q_max[j])
        res = ik(panda, dynid.fk(panda, qt), rng=rng)
        assert res.converged
        assert _within_limits(panda, res.path)


def test_ik_goal_at_start_takes_no_iteration(panda):
    """When q0 already reaches the goal, ik returns q0 after 0 iterations."""
    q0 = default_q0(panda)
    res = ik(panda, dynid.fk(panda, q0, tool=TOOL), q0, tool=TOOL)
    assert res.converged and res.iterations == 0 and res.path.shape == (1, 7)
    np.testing.assert_array_equal(res.q, q0)


def test_ik_on_intermediate_frame_moves_only_the_joints_before_it(panda):
    """A goal for link4 is reached and joints 5..7 never move."""
    q_true, _, _ = random_states(panda, 10, seed=25)
    for qt in q_true:
        T = dynid.fk(panda, qt, "link4")
        res = ik(panda, T, frame="link4")
        assert res.converged
        np.testing.assert_array_equal(res.path[:, 4:], np.tile(res.path[0, 4:], (len(res.path), 1)))


def test_ik_reaches_a_goal_given_with_6_decimals(panda):
    """A goal rounded to 6 decimals (rotation orthonormal to ~1e-6) is reached to 1e-6."""
    T = np.round(dynid.fk(panda, [0.3, -0.2, 0.1, -2.0, 0.4, 1.9, -0.3], tool=TOOL), 6)
    res = ik(panda, T, tool=TOOL)
    assert res.converged


def test_ik_prismatic_and_non_panda_robot_converges_from_mid_range():
    """An RRPRR arm (not the Panda) starts at the middle of its limits and reaches fk goals."""
    robot = dynid.Robot.from_mdh(
        a=[0.0, 0.3, 0.0, 0.0, 0.0],
        d=[0.2, 0.0, 0.3, 0.0, 0.1],
        alpha=[0.0, np.pi / 2, 0.0, -np.pi / 2, np.pi / 2],
        joint_types="RRPRR",
        q_min=[-2.5, -2.0, 0.1, -2.5, -2.5],
        q_max=[2.5, 2.0, 0.6, 2.5, 2.5],
        dq_max=[2.0, 2.0, 0.5, 2.0, 2.0],
        name="rrprr",
    )
    np.testing.assert_allclose(default_q0(robot), [0.0, 0.0, 0.35, 0.0, 0.0])
    rng = np.random.default_rng(26)
    q_true = rng.uniform(robot.q_min, robot.q_max, (20, robot.n))
    for qt in q_true:  # 5 joints: position and two orientation components are reachable
        T = dynid.fk(robot, qt)
        res = ik(robot, T, rng=rng)
        assert res.converged
        assert _within_limits(robot, res.path)


def test_ik_unbounded_limits_default_start_is_zero(planar2r):
    """A robot without limits starts at 0 and reaches a planar goal."""
    np.testing.assert_array_equal(default_q0(planar2r), [0.0, 0.0])
    T = dynid.fk(planar2r, [0.7, -1.2])
    res = ik(planar2r, T)
    assert res.converged
    np.testing.assert_allclose(dynid.fk(planar2r, res.q), T, atol=1e-6)


def test_ik_compiled_kernel_and_numpy_loop_agree(panda, monkeypatch):
    """The numba kernel and the numpy loop give the same path (with restarts and a tool)."""
    pytest.importorskip("numba")
    if os.environ.get("DYNID_NO_NUMBA"):
        pytest.skip("DYNID_NO_NUMBA is set: only the numpy loop runs")
    q_true, _, _ = random_states(panda, 25, seed=27)
    goals = [(dynid.fk(panda, qt, tool=TOOL), TOOL) for qt in q_true[:15]]
    goals += [(dynid.fk(panda, qt), None) for qt in q_true[15:]]
    goals.append((spatial.transform_from_xyz_rpy([1.5, 0.0, 0.3]), None))  # unreachable
    flipped = dynid.fk(panda, dynid.PANDA_NEUTRAL_Q)
    flipped[:3, :3] = flipped[:3, :3] @ np.diag([1.0, -1.0, -1.0])
    goals.append((flipped, None))  # exactly pi from the start: the axis sign is a convention
    opts = IKOptions(max_restarts=3)
    compiled = [ik(panda, T, tool=tool, options=opts) for T, tool in goals]
    assert ik_module._kernel(1) is not None
    monkeypatch.setattr(ik_module, "_kernel", lambda ndim: None)
    restarts = 0
    for (T, tool), rc in zip(goals, compiled, strict=True):
        rn = ik(panda, T, tool=tool, options=opts)
        assert (rn.converged, rn.iterations) == (rc.converged, rc.iterations)
        assert rn.restarts == rc.restarts
        np.testing.assert_allclose(rn.path, rc.path, atol=1e-9)
        np.testing.assert_allclose(rn.position_error, rc.position_error, rtol=1e-6, atol=1e-12)
        restarts += rn.restarts
    assert restarts > 0  # the restart branch was exercised


def test_ik_batch_of_goals_equals_the_loop_of_single_goals(panda, monkeypatch):
    """Goals (3, 2, 4, 4) with q0 broadcast: each result equals its one-goal solve (issue 11)."""
    rng = np.random.default_rng(31)
    q_true = rng.uniform(panda.q_min, panda.q_max, (3, 2, 7))
    goals = dynid.fk(panda, q_true, tool=TOOL)
    goals[2, 1] = spatial.transform_from_xyz_rpy([1.5, 0.0, 0.3])  # unreachable: restarts
    q0 = np.array(dynid.PANDA_NEUTRAL_Q)
    opts = IKOptions(max_restarts=2)
    for numpy_loop in (False, True):
        if numpy_loop:
            monkeypatch.setattr(ik_module, "_kernel", lambda ndim: None)
        res = ik(panda, goals, q0, tool=TOOL, options=opts)
        assert res.q.shape == (3, 2, 7) and res.path is None
        for name in ("converged", "iterations", "position_error", "orientation_error"):
            assert getattr(res, name).shape == (3, 2)
        for idx in np.ndindex(3, 2):
            one = ik(panda, goals[idx], q0, tool=TOOL, options=opts)
            assert (res.converged[idx], res.iterations[idx]) == (one.converged, one.iterations)
            assert res.restarts[idx] == one.restarts
            np.testing.assert_allclose(res.q[idx], one.q, atol=1e-9)
            np.testing.assert_allclose(res.position_error[idx], one.position_error, atol=1e-9)
        assert res.converged.sum() >= 4 and not res.converged[2, 1]


def test_ik_batch_checks_every_goal_and_start(panda):
    """A bad goal or start in a batch raises and names its index."""
    goals = np.stack([np.eye(4)] * 3)
    goals[1, 0, 0] = 2.0
    with pytest.raises(DataError, match=r"T_goal\[1\] rotation block"):
        ik(panda, goals)
    q0 = np.tile(np.array(dynid.PANDA_NEUTRAL_Q), (3, 1))
    q0[2, 0] = 10.0
    with pytest.raises(LimitError, match="start 2"):
        ik(panda, np.stack([np.eye(4)] * 3), q0)
    with pytest.raises(ShapeError, match="broadcast"):
        ik(panda, np.stack([np.eye(4)] * 3), np.zeros((2, 7)))


def test_single_sample_chain_equals_fk_and_jacobian(panda):
    """The solver's single-sample fk + Jacobian equals fk and jacobian (tool, prismatic)."""
    q, _, _ = random_states(panda, 10, seed=28)
    T_link_frame = panda.frame("flange").T_link_frame @ TOOL
    chain = ik_numpy.Chain(panda, 7, T_link_frame)
    for qs in q:
        T, J = chain.pose_jacobian(qs)
        np.testing.assert_allclose(T, dynid.fk(panda, qs, tool=TOOL), atol=1e-14)
        np.testing.assert_allclose(J, dynid.jacobian(panda, qs, tool=TOOL), atol=1e-14)
    robot = dynid.Robot.from_mdh([0, 0.2, 0.1], [0.1, 0, 0.2], [0, 1.0, -0.5], joint_types="RPR")
    chain = ik_numpy.Chain(robot, 3, robot.frame("flange").T_link_frame)
    rng = np.random.default_rng(28)
    for qs in rng.uniform(-1, 1, (5, 3)):
        T, J = chain.pose_jacobian(qs)
        np.testing.assert_allclose(T, dynid.fk(robot, qs), atol=1e-14)
        np.testing.assert_allclose(J, dynid.jacobian(robot, qs), atol=1e-14)


def test_orientation_error_helper_round_trips_near_0_and_pi():
    """The solver's scalar angle-axis inverts matrix_from_angle_axis for angles in [0, pi]."""
    rng = np.random.default_rng(29)
    angles = np.concatenate(
        [[0.0, 1e-12, 1e-7], rng.uniform(0, np.pi, 50), np.pi - np.logspace(-12, -1, 12), [np.pi]]
    )
    for a in angles:
        u = rng.normal(size=3)
        w = a * u / np.linalg.norm(u)
        R = spatial.matrix_from_angle_axis(w)
        *v, theta = ik_numpy.rotvec(R)
        assert abs(theta - a) < 1e-9
        np.testing.assert_allclose(spatial.matrix_from_angle_axis(v), R, atol=1e-12)
        if a < np.pi - 1e-6:
            np.testing.assert_allclose(v, w, atol=1e-8)


def test_ik_result_is_frozen_with_read_only_arrays(panda):
    """IKResult is a frozen dataclass and its arrays cannot be written."""
    res = ik(panda, dynid.fk(panda, [0.1, -0.5, 0.2, -2.0, 0.1, 1.8, 0.5]))
    assert isinstance(res, IKResult)
    with pytest.raises(AttributeError):
        res.converged = False  # type: ignore[misc]
    with pytest.raises(ValueError):
        res.q[0] = 1.0
    with pytest.raises(ValueError):
        res.path[0, 0] = 1.0


def test_ik_does_not_modify_its_inputs(panda):
    """T_goal, q0 and tool are left unchanged."""
    T = dynid.fk(panda, [0.1, -0.5, 0.2, -2.0, 0.1, 1.8, 0.5], tool=TOOL)
    T[:3, :3] += 1e-7  # slightly non-orthonormal: re-orthonormalised on a copy
    q0, tool = default_q0(panda), TOOL.copy()
    copies = T.copy(), q0.copy(), tool.copy()
    ik(panda, T, q0, tool=tool)
    for a, b in zip((T, q0, tool), copies, strict=True):
        np.testing.assert_array_equal(a, b)


def test_ik_bad_inputs_raise(panda):
    """Every documented Raises: shapes, NaN, non-rigid goals, q0 outside limits, frames."""
    T = dynid.fk(panda, default_q0(panda))
    with pytest.raises(dynid.ShapeError, match=r"T_goal must have shape \(4, 4\); got \(3, 4\)"):
        ik(panda, T[:3])
    bad = T.copy()
    bad[0, 3] = np.nan
    with pytest.raises(dynid.NonFiniteError, match=r"T_goal must be finite; got nan at index"):
        ik(panda, bad)
    bad = T.copy()
    bad[:3, :3] *= 1.1
    with pytest.raises(dynid.DataError, match="rotation block must be orthonormal"):
        ik(panda, bad)
    bad = T.copy()
    bad[:3, :3] = T[:3, :3] @ np.diag([1.0, 1.0, -1.0])  # a reflection
    with pytest.raises(dynid.DataError, match="det -1"):
        ik(panda, bad)
    bad = T.copy()
    bad[3, 3] = 2.0
    with pytest.raises(dynid.DataError, match=r"last row \[0, 0, 0, 1\]"):
        ik(panda, bad)
    with pytest.raises(dynid.ShapeError, match=r"q0 must have shape \(7,\); got \(6,\)"):
        ik(panda, T, np.zeros(6))
    with pytest.raises(dynid.NonFiniteError, match="q0 must be finite"):
        ik(panda, T, [0, 0, 0, np.nan, 0, 0, 0])
    with pytest.raises(dynid.LimitError, match=r"q0 must lie within the joint limits; joint4 = 0"):
        ik(panda, T, np.zeros(7))  # joint 4 upper limit is -0.0698
    with pytest.raises(dynid.UnknownNameError, match="Unknown frame 'hand'"):
        ik(panda, T, frame="hand")
    with pytest.raises(dynid.ShapeError, match=r"tool must have shape \(4, 4\)"):
        ik(panda, T, tool=np.eye(3))
    with pytest.raises(TypeError, match="options must be an IKOptions"):
        ik(panda, T, options={"dt": 0.1})  # type: ignore[arg-type]


@pytest.mark.parametrize(
    ("kwargs", "match"),
    [
        ({"dt": 0.0}, "dt must be a positive finite number"),
        ({"gain": float("nan")}, "gain must be a positive finite number"),
        ({"dt": 0.1, "gain": 25.0}, r"dt \* gain must lie in \(0, 2\)"),
        ({"damping": -1.0}, "damping must be a finite number >= 0"),
        ({"position_tolerance": 0.0}, "position_tolerance must be a positive"),
        ({"max_iterations": 0}, "max_iterations must be an integer >= 1"),
        ({"max_iterations": 10.5}, "max_iterations must be an integer >= 1"),
        ({"max_restarts": -1}, "max_restarts must be an integer >= 0"),
    ],
)
def test_ik_options_reject_bad_values(kwargs, match):
    """IKOptions validates its fields when built."""
    with pytest.raises(dynid.DataError, match=match):
        IKOptions(**kwargs)


def test_default_q0_is_the_panda_neutral_pose(panda):
    """The Panda (also with a tool frame) starts at PANDA_NEUTRAL_Q."""
    np.testing.assert_array_equal(default_q0(panda), dynid.PANDA_NEUTRAL_Q)
    np.testing.assert_array_equal(default_q0(panda.with_tool(TOOL, 0.5)), dynid.PANDA_NEUTRAL_Q)


def test_ik_goal_absurdly_far_reports_finite_errors(panda, monkeypatch):
    """A goal 1e160 m away: not converged, q0 kept, errors finite (no overflow), both loops."""
    goal = np.eye(4)
    goal[0, 3] = 1e160
    results = [ik(panda, goal)]
    monkeypatch.setattr(ik_module, "_kernel", lambda ndim: None)
    results.append(ik(panda, goal))
    for r in results:
        assert not r.converged
        np.testing.assert_allclose(r.position_error, 1e160, rtol=1e-6)
        assert np.isfinite(r.orientation_error) and r.orientation_error <= np.pi
