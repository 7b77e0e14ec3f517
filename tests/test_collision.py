"""Capsule model, obstacle and self-collision distances (issue 9)."""

from __future__ import annotations

import numpy as np
import pytest

import dynid
from dynid.exceptions import OptionError, ShapeError
from dynid.simulation.collision import (
    DEFAULT_RADIUS,
    Box,
    Obstacles,
    Plane,
    _segment_distance,
    capsule_model,
    capsule_segments,
    obstacle_distances,
    self_distances,
)


def _brute_segment_distance(P, k=401):
    u = np.linspace(0.0, 1.0, k)[:, None]
    out = []
    for p in P:
        A, B = p[0] + u * (p[1] - p[0]), p[2] + u * (p[3] - p[2])
        out.append(np.linalg.norm(A[:, None] - B[None], axis=-1).min())
    return np.array(out)


def test_segment_distance_matches_dense_sampling_including_degenerate_segments():
    """Closest points of two segments against a 401 x 401 sampling (points included)."""
    rng = np.random.default_rng(61)
    P = rng.normal(size=(120, 4, 3))
    P[:40, 1] = P[:40, 0]  # first segment a point
    P[40:80, 3] = P[40:80, 2]  # second a point
    P[80:100, 3] = P[80:100, 2] + (P[80:100, 1] - P[80:100, 0])  # parallel
    d = _segment_distance(P[:, 0], P[:, 1], P[:, 2], P[:, 3])
    ref = _brute_segment_distance(P)
    # sampling overestimates by at most the spacing times the segment lengths
    assert np.all(d <= ref + 1e-12) and np.all(ref - d < 1e-3 * (1 + np.abs(P).max()))


def test_panda_capsules_follow_the_mdh_constants_and_skip_touching_neighbours():
    """Lengths from the MDH table; pairs separated by a zero-length link are not checked."""
    caps = capsule_model(dynid.panda())
    L = [0.333, 0.0, 0.316, 0.0825, np.hypot(0.384, 0.0825), 0.0, 0.088, 0.107]
    np.testing.assert_allclose(caps.lengths, L, atol=1e-12)
    pairs = {tuple(p) for p in caps.pairs.tolist()}
    assert (4, 6) not in pairs and (0, 2) not in pairs  # joined by links 5 and 1 (length 0)
    assert (2, 4) not in pairs  # link 3 (0.0825 m) shorter than two radii
    assert {(0, 7), (2, 7), (3, 5)} <= pairs
    assert np.all(caps.radii == DEFAULT_RADIUS)
    with pytest.raises(ShapeError, match="radii must be positive"):
        capsule_model(dynid.panda(), [0.1, 0.1])


def test_floor_distance_is_the_lowest_capsule_point_minus_its_radius():
    """Closed form from the link poses: min z over capsules 2..n minus the radius."""
    robot = dynid.panda()
    rng = np.random.default_rng(62)
    q = rng.uniform(robot.q_min, robot.q_max, (50, 7))
    caps = capsule_model(robot, 0.05)
    d = obstacle_distances(robot, q, Obstacles.floor(0.1), caps)
    T = dynid.link_poses(robot, q)
    flange = dynid.fk(robot, q)[..., 2, 3]
    z = np.concatenate([T[:, 2:, 2, 3], flange[:, None]], axis=1)
    np.testing.assert_allclose(d[:, 0], z.min(axis=1) - 0.1 - 0.05, atol=1e-12)


def test_box_around_the_flange_gives_a_negative_distance_and_a_far_box_a_positive_one():
    """A box containing the flange penetrates; one 1 m beyond the reach is 1 m minus reach away."""
    robot = dynid.panda()
    q = np.asarray(robot.q_neutral)
    p = dynid.fk(robot, q)[:3, 3]
    obs = Obstacles(boxes=(Box(tuple(p), (0.1, 0.1, 0.1)), Box((5.0, 0.0, 0.5), (1.0, 1.0, 1.0))))
    d = obstacle_distances(robot, q, obs, capsule_model(robot))
    seg = capsule_segments(robot, q)[2:]
    assert d[0] < -0.05
    gap = 4.5 - seg[:, :, 0].max() - DEFAULT_RADIUS  # the far box's face is at x = 4.5
    assert d[1] == pytest.approx(gap, abs=1e-9)
    assert obs.names == ("box1", "box2")


def test_self_distance_of_a_folded_panda_is_negative():
    """Elbow folded onto the base: the forearm capsule enters the base capsule."""
    robot = dynid.panda()
    caps = capsule_model(robot)
    q = np.array([0.0, -1.76, 0.0, -3.07, 0.0, 0.5, 0.0])
    assert self_distances(robot, q, caps).min() < 0
    assert self_distances(robot, np.asarray(robot.q_neutral), caps).min() > 0.1


def test_obstacle_validation_names_the_problem():
    """A zero normal, a non-positive box size and a name count mismatch are rejected."""
    with pytest.raises(OptionError, match="normal must be non-zero"):
        Plane((0, 0, 0), (0, 0, 0))
    with pytest.raises(OptionError, match="box size must be positive"):
        Box((0, 0, 0), (1, 0, 1))
    with pytest.raises(ShapeError, match="obstacles need 1 names"):
        Obstacles(planes=(Plane((0, 0, 0), (0, 0, 1)),), names=("a", "b"))


def test_a_one_joint_arm_has_no_capsule_to_check_against_obstacles():
    """Capsules 0 and 1 stand on the support, so a one-joint arm is infinitely far from
    every obstacle: shape (..., k) of inf, not a reduction over nothing (issue 20)."""
    robot = dynid.Robot.from_mdh([0.3], [0.0], [0.0])
    obstacles = Obstacles(planes=(Plane((0, 0, 0), (0, 0, 1)),), boxes=(Box((0, 0, 0), (1, 1, 1)),))
    d = obstacle_distances(robot, np.zeros((4, 1)), obstacles, capsule_model(robot))
    assert d.shape == (4, 2) and np.all(d == np.inf)
