"""Exciting trajectories of a small arm (the SO-101 of ``tests/data/so101_arm.urdf``).

The optimiser filled every joint's range at the start; on the SO-101 the elbow's top then
folds the forearm into the shoulder's capsule and the gripper below the floor. Started
there, it never found an admissible iterate: a rest position clipped to where the motion
fits, and an amplitude fixed at the largest that fits, left it no direction that shrank a
motion or moved it away from the fold, and ``excite`` fell back to amplitudes reduced after
the optimisation (status ``reduced``, condition number 206 against a start of 155). Its
iterations, thousands of evaluations each when a line search struggled, took up to a
minute with the bar still: the bar now counts the evaluations.
"""

from __future__ import annotations

import numpy as np
import pytest

from dynid.cli.excite import _Bar
from dynid.io.robot.urdf import load_urdf
from dynid.simulation.collision import (
    Obstacles,
    capsule_model,
    obstacle_distances,
    self_distances,
)
from dynid.simulation.excitation import (
    _START_FRACTIONS,
    ExcitationOptions,
    limit_margins,
    optimise_excitation,
)

from conftest import SHORT_EXCITATION as SHORT
from conftest import SO101_URDF as SO101


@pytest.fixture(scope="module")
def so101():
    """The SO-101's five arm joints, base to the gripper's frame."""
    return load_urdf(SO101, tip_link="gripper_frame_link", snap_angles=True)


@pytest.fixture(scope="module")
def so101_design(so101):
    """The SO-101 designed with the short options and the default sizes, seed 0, with
    every objective evaluation recorded."""
    seen: list[tuple[int, int]] = []
    res = optimise_excitation(
        so101,
        np.random.default_rng(0),
        ExcitationOptions(**SHORT),
        evaluated=lambda k, budget: seen.append((k, budget)),
    )
    return res, seen


def test_the_so101_start_at_full_amplitude_folds_the_elbow_into_the_shoulder(so101):
    """The premise of the regression below: with the elbow at the top of its range (5
    degrees kept) and the shoulder lifted, the capsules of the shoulder and the forearm
    overlap, so a motion filling every joint's range must collide."""
    opts = ExcitationOptions().sized_for(so101)
    caps = capsule_model(so101, opts.radii, clearance=opts.self_clearance)
    q = np.zeros(so101.n)
    q[1] = 0.5 * so101.q_max[1]
    q[2] = so101.q_max[2] - opts.position_margin
    assert self_distances(so101, q, caps).min() < 0


def test_a_small_arm_gets_an_admissible_optimised_design(so101, so101_design):
    """Regression (SO-101 trial, status ``reduced`` on every seed of the default design;
    here, with these options, condition number 171 reduced, against a start of 100): the
    optimiser itself reaches an admissible trajectory better than its start (status
    ``ok``), checked here at 1 kHz from the limits and the capsules' distances."""
    res, _ = so101_design
    assert res.status == "ok" and res.improved
    assert res.condition_number < res.initial_condition_number
    o = res.options
    tr = res.trajectory.sample(1000.0)
    margins = limit_margins(so101, tr, o)
    assert min(min(v) for v in margins.values()) >= -1e-9
    caps = capsule_model(so101, o.radii, clearance=o.self_clearance)
    assert self_distances(so101, tr.q, caps).min() >= o.self_clearance
    floor = obstacle_distances(so101, tr.q, Obstacles.floor(), caps).min()
    assert floor >= o.obstacle_clearance


def test_every_objective_evaluation_is_told_with_its_budget(so101_design):
    """Regression: an iteration took about a minute with no progress (the bar moved per
    iteration only); each evaluation is now told, counted up to the result's total,
    against the evaluations allowed plus those that chose the start."""
    res, seen = so101_design
    counts = [k for k, _ in seen]
    assert counts == list(range(1, res.evaluations + 1))
    budget = seen[-1][1]
    starts = (1 + len(_START_FRACTIONS)) * SHORT["n_starts"]  # full amplitude, then each fraction
    assert SHORT["max_evaluations"] < budget <= SHORT["max_evaluations"] + starts


def test_the_bar_moves_within_an_iteration_at_the_evaluations_share(capsys):
    """Regression: the bar moved only after each iteration; it is drawn at the first
    evaluation and at the larger share of the iterations' and evaluations' budgets."""
    bar = _Bar(60)
    bar.on_evaluation(1, 6016)
    err = capsys.readouterr().err
    assert err.startswith("\r[" + " " * 30 + "] iteration 0/60, 1/6,016 evaluations"), err
    assert "cond" not in err  # none known before the first iteration
    bar.on_iteration(3, 60, 52.6)
    capsys.readouterr()
    bar.last = float("-inf")  # the next evaluation draws, however soon
    bar.on_evaluation(3008, 6016)
    err = capsys.readouterr().err
    assert err.startswith("\r[" + "#" * 15 + " " * 15 + "]"), err
    assert "iteration 3/60, 3,008/6,016 evaluations, cond 52.6" in err
