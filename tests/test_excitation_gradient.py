"""The excitation design's gradient and its batched evaluations against finite differences,
and the compiled self-collision distances against dense sampling.

The design's optimiser took a forward-difference gradient of ``len(x) + 1`` evaluations
one at a time (78 for the Panda's 20 s design, most of a design's time); the ``cond``
criterion's gradient now comes from the chain rule through the samples, and ``logdet``'s
finite differences are evaluated in one batch.
"""

from __future__ import annotations

import numpy as np
import pytest

import dynid
from dynid import _kernels
from dynid.regressors.base import base_parameters
from dynid.simulation import excitation_gradient as G
from dynid.simulation.collision import (
    Box,
    Obstacles,
    _segment_distance,
    capsule_model,
    capsule_segments,
    self_distances,
)
from dynid.simulation.excitation import (
    ExcitationOptions,
    _fd_steps,
    _preferred_rest,
    _Problem,
    design_limits,
)


def _problem(criterion: str = "cond") -> _Problem:
    """A 2 s design of the Panda whose random start violates a torque limit (joint 2 kept
    to 30 N m), the floor (raised to 0.3 m) and its self-clearance (0.15 m)."""
    opts = ExcitationOptions(
        duration=2.0,
        harmonics=2,
        base_frequency=0.5,
        max_torque=((1, 30.0),),
        self_clearance=0.15,
        criterion=criterion,
    )
    robot = design_limits(dynid.panda(), opts)
    opts = opts.sized_for(robot)
    caps = capsule_model(robot, opts.radii, clearance=opts.self_clearance)
    base = base_parameters(robot, kind="torque")
    return _Problem(robot, opts, Obstacles.floor(0.3), caps, base, _preferred_rest(robot, None))


def _variables(prob: _Problem, seed: int) -> np.ndarray:
    rng = np.random.default_rng(seed)
    return prob.initial(rng.standard_normal(prob.n * 2 * prob.L), 0.3 * rng.standard_normal(prob.n))


def _central(prob: _Problem, x: np.ndarray, h: float = 1e-6) -> np.ndarray:
    """Central differences of the objective, one variable at a time."""
    E = h * np.eye(len(x))
    return np.array([(prob.objective(x + e) - prob.objective(x - e)) / (2 * h) for e in E])


@pytest.mark.parametrize("seed", [4, 7])
def test_the_cond_gradient_agrees_with_central_differences_of_the_objective(seed):
    """Chain rule through the samples (criterion, torque and clearance penalties, the
    coefficients scaled to the limits) against central differences of the objective, at a
    start that violates a torque, the floor and the self-clearance (seed 4) and at one
    clear of the torques (seed 7)."""
    prob = _problem()
    x = _variables(prob, seed)
    c, q0 = prob.coefficients(x)
    assert G._clearance_part(prob, c, q0)[0] > 0
    assert (G._torque_part(prob, c, q0)[0] > 0) == (seed == 4)
    value, grad = G.objective_gradient(prob, x)
    assert value == pytest.approx(prob.objective(x), rel=1e-12)
    ref = _central(prob, x)
    # the coefficients' map by scipy's forward steps (1e-4): its error, about 1e-5
    assert np.linalg.norm(grad - ref) <= 1e-4 * np.linalg.norm(ref)


def test_the_criterion_gradient_alone_agrees_with_central_differences():
    """Without penalties (no obstacle, no torque limit, no capsule pair): the derivative of
    log cond through the eigenvectors of W^T W and the regressor's states, closer than
    scipy's forward differences of 1e-4."""
    prob = _problem()
    prob.tmax = np.full(prob.n, np.inf)
    prob.obstacles = Obstacles()
    prob.caps = capsule_model(prob.robot, 0.01, clearance=10.0)  # no pair checked
    x = _variables(prob, 11)
    _, grad = G.objective_gradient(prob, x)
    ref = _central(prob, x)
    h = _fd_steps(x)
    fwd = np.array(
        [
            (prob.objective(x + hi * e) - prob.objective(x)) / hi
            for hi, e in zip(h, np.eye(len(x)), strict=True)
        ]
    )
    err = np.linalg.norm(grad - ref) / np.linalg.norm(ref)
    assert err < 1e-4 and err < np.linalg.norm(fwd - ref) / np.linalg.norm(ref)


def test_batched_finite_differences_equal_those_of_single_evaluations():
    """logdet's gradient: the len(x) + 1 evaluations in one batch give the forward
    differences of the objective evaluated one variable at a time (scipy's steps)."""
    prob = _problem("logdet")
    x = _variables(prob, 4)
    value, grad = prob.finite_difference_gradient(x)
    f0 = prob.objective(x)
    h = _fd_steps(x)
    ref = [
        (prob.objective(x + hi * e) - f0) / ((x[i] + hi) - x[i])
        for i, (hi, e) in enumerate(zip(h, np.eye(len(x)), strict=True))
    ]
    assert value == pytest.approx(f0, rel=1e-12)
    np.testing.assert_allclose(grad, ref, rtol=1e-6, atol=1e-6 * np.abs(ref).max())
    assert prob.evaluations == 1 + len(x) + 1 + len(x)


def _brute_segment_distance(P: np.ndarray, k: int = 401) -> np.ndarray:
    """Smallest distance of 401 points along each of two segments (rows of P (M, 4, 3))."""
    u = np.linspace(0.0, 1.0, k)[:, None]
    out = []
    for p in P:
        A, B = p[0] + u * (p[1] - p[0]), p[2] + u * (p[3] - p[2])
        out.append(np.linalg.norm(A[:, None] - B[None], axis=-1).min())
    return np.array(out)


@pytest.mark.skipif(_kernels.load("collision") is None, reason="numba missing or turned off")
def test_compiled_segment_distances_match_dense_sampling_and_the_numpy_path():
    """Random segment pairs (points and parallel ones included) against 401 x 401 points,
    and bit for bit the numpy path's numbers."""
    rng = np.random.default_rng(62)
    P = rng.normal(size=(120, 4, 3))
    P[:40, 1] = P[:40, 0]
    P[40:80, 3] = P[40:80, 2]
    P[80:100, 3] = P[80:100, 2] + (P[80:100, 1] - P[80:100, 0])
    seg = np.ascontiguousarray(P.reshape(-1, 2, 2, 3))  # two segments per sample
    out = np.empty((len(P), 1))
    _kernels.load("collision").segment_pair_distances(seg, np.array([[0, 1]]), out)
    ref = _brute_segment_distance(P)
    assert np.all(out[:, 0] <= ref + 1e-12) and np.all(
        ref - out[:, 0] < 1e-3 * (1 + np.abs(P).max())
    )
    np.testing.assert_array_equal(out[:, 0], _segment_distance(P[:, 0], P[:, 1], P[:, 2], P[:, 3]))


def test_self_distances_of_a_batch_match_dense_sampling_of_the_capsules():
    """The Panda's pair distances at random configurations (a batch, compiled when numba
    is there): each pair's segments sampled densely, minus both radii."""
    robot = dynid.panda()
    caps = capsule_model(robot)
    rng = np.random.default_rng(63)
    q = rng.uniform(robot.q_min, robot.q_max, size=(3, robot.n))
    d = self_distances(robot, q, caps)
    seg = capsule_segments(robot, q)
    i, j = caps.pairs[:, 0], caps.pairs[:, 1]
    P = np.stack([seg[:, i, 0], seg[:, i, 1], seg[:, j, 0], seg[:, j, 1]], axis=2).reshape(-1, 4, 3)
    ref = _brute_segment_distance(P, 201).reshape(d.shape) - caps.radii[i] - caps.radii[j]
    assert np.all(d <= ref + 1e-12) and np.all(ref - d < 5e-3)


def test_a_rank_deficient_regressor_gives_a_finite_gradient():
    """Regression: one harmonic leaves no motion once the accelerations are made
    continuous (a static regressor, lambda_min at the criterion's floor of 1e-300); the
    chain rule divided by that floor (a gradient of 4e288, then NaN states, where
    ``excite`` was to say "no admissible trajectory"). Now finite and the central
    differences' (the floored term is constant)."""
    opts = ExcitationOptions(duration=2.0, harmonics=1).sized_for(dynid.panda())
    robot = dynid.panda()
    caps = capsule_model(robot, opts.radii, clearance=opts.self_clearance)
    room = Obstacles(boxes=(Box((0.0, 0.0, 0.5), (10.0, 10.0, 10.0)),))
    base = base_parameters(robot, kind="torque")
    prob = _Problem(robot, opts, room, caps, base, _preferred_rest(robot, None))
    x = _variables(prob, 0)
    _, grad = G.objective_gradient(prob, x)
    ref = _central(prob, x)
    assert np.all(np.isfinite(grad))
    assert np.linalg.norm(grad - ref) <= 1e-4 * np.linalg.norm(ref)
