"""Exciting trajectories of a small arm (the SO-101 of ``tests/data/so101_arm.urdf``).

The optimiser filled every joint's range at the start; on the SO-101 the elbow's top then
folds the forearm into the shoulder's capsule and the gripper below the floor. Started
there, it never found an admissible iterate: a rest position clipped to where the motion
fits, and an amplitude fixed at the largest that fits, left it no direction that shrank a
motion or moved it away from the fold, and ``excite`` fell back to amplitudes reduced after
the optimisation (status ``reduced``, condition number 206 against a start of 155). Its
iterations, thousands of evaluations each when a line search struggled, took up to a
minute with the bar still: the bar now counts the evaluations. An xArm7 trial's design ran
46-139 s with no line at all when stderr was a file, even with -v: the iterations and
evaluations are now told to the progress facility (the command's progress lines) and each
iteration logged at INFO.
"""

from __future__ import annotations

import logging

import numpy as np
import pytest

from dynid.io.robot.urdf import load_urdf
from dynid.progress import reporting
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
    every objective evaluation, every progress line and every INFO log line recorded."""
    seen: list[tuple[int, int]] = []
    lines: list[str] = []
    logged: list[str] = []
    handler = logging.Handler(logging.INFO)
    handler.emit = lambda record: logged.append(record.getMessage())  # type: ignore[method-assign]
    log = logging.getLogger("dynid.simulation.excitation")
    level = log.level
    log.addHandler(handler)
    log.setLevel(logging.INFO)
    try:
        with reporting(lines.append):
            res = optimise_excitation(
                so101,
                np.random.default_rng(0),
                ExcitationOptions(**SHORT),
                evaluated=lambda k, budget: seen.append((k, budget)),
            )
    finally:
        log.removeHandler(handler)
        log.setLevel(level)
    return res, seen, lines, logged


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
    res = so101_design[0]
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
    res, seen = so101_design[:2]
    counts = [k for k, _ in seen]
    assert counts == list(range(1, res.evaluations + 1))
    budget = seen[-1][1]
    starts = (1 + len(_START_FRACTIONS)) * SHORT["n_starts"]  # full amplitude, then each fraction
    assert SHORT["max_evaluations"] < budget <= SHORT["max_evaluations"] + starts


def test_iterations_and_evaluations_are_told_to_the_progress_facility_and_logged(so101_design):
    """Regression (xArm7 trial: 46-139 s without a line, even with -v, stderr a file):
    each evaluation and each iteration is told to :mod:`dynid.progress` (which the command
    line renders on a terminal), counted as the optimiser counts them, and each iteration
    is logged at INFO (``-v``) with its condition number, the one in the history."""
    res, seen, lines, logged = so101_design
    budget = seen[-1][1]
    evaluations = [x for x in lines if "evaluations" in x]
    assert len(evaluations) == res.evaluations
    assert evaluations[-1].endswith(f"{res.evaluations:,} of {budget:,} evaluations")
    k = int(evaluations[-1].split()[1])  # the line search after the last one may not end
    assert k in (res.iterations - 1, res.iterations)
    said = f"iteration {k} of {SHORT['max_iter']} (condition number {res.history[k - 1]:.4g}), "
    assert evaluations[-1].startswith(said)
    iterations = [x for x in lines if " done, " in x]
    want = [
        f"iteration {k} of {SHORT['max_iter']} done, condition number {c:.4g}"
        for k, c in enumerate(res.history, 1)
    ]
    assert iterations == want and len(want) == res.iterations > 0
    info = [x for x in logged if x.startswith("excitation: iteration ")]
    assert len(info) == res.iterations
    assert info[0].startswith(f"excitation: iteration 1 of {SHORT['max_iter']}, condition")
