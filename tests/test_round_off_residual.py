"""A prediction exact to round-off is not called a systematic residual.

On noise-free data the noise floor is the file's rounding, and the residual the filter and
the CSV leave is tens of times that floor while a millionth of the torques: judged by its
ratio alone every joint read as "a systematic residual" (the report) and the diagnosis of
what it follows named friction or springs the model does not lack.

References: simulated motor-side current logs of the geared Panda with its coupled wrist
(the truth's friction and rotor inertias known, no sensor noise), and residuals of a known
spring plus white noise as the control.
"""

from __future__ import annotations

import dataclasses
import warnings

import numpy as np
import pytest

import dynid
from dynid.exceptions import DynidWarning
from dynid.friction.model import ClassicalFriction
from dynid.identification.residual_dependence import (
    ROUND_OFF,
    residual_dependence,
    round_off,
    with_dependence_hint,
)
from dynid.identification.verdict import Verdict, joint_levels
from dynid.io.torque_log import save_torque_log
from dynid.workflows.identify import IdentifyOptions, identify_files

from conftest import geared_drive, recordings


@pytest.fixture(scope="module")
def exact_heldout(tmp_path_factory):
    """identify's held-out prediction of two noise-free 3 s geared logs (the last time
    block predicted by the fit of the others)."""
    robot, truth = dynid.panda(), geared_drive()
    fr = ClassicalFriction(np.full(7, 2e-3), np.full(7, 4e-3), np.zeros(7))
    logs = recordings(robot, (71, 72), friction=fr, drive=truth, duration=3.0)
    d = tmp_path_factory.mktemp("exact")
    paths = [d / f"g{k}.csv" for k in range(2)]
    for path, log in zip(paths, logs, strict=True):
        save_torque_log(path, log)
    drive = dataclasses.replace(truth, rotor_inertia=None)
    opt = IdentifyOptions(drive=drive, terms="armature,viscous,coulomb,at:motor")
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", DynidWarning)
        held = identify_files(robot, paths, opt).heldout
    assert held is not None
    return held


def test_an_exact_fit_is_round_off_not_a_systematic_residual(exact_heldout):
    """Regression: noise-free geared logs left 2e-5 to 1e-4 % per joint, 5.5 to 40 x a
    floor at the file's rounding, and every joint was judged fair ("a systematic
    residual" in the report) and diagnosed; now each joint is good and none diagnosed."""
    held = exact_heldout
    doc = held.as_dict()
    per, ratios = doc["relative_error_percent_per_joint"], doc["joint_ratios"]
    assert max(per) < 1e-3 and max(ratios) > 5.0, (per, ratios)  # round-off, far above
    assert joint_levels(per, ratios) == ("good",) * 7  # what the report reads
    assert held.verdict.level == "good", held.verdict
    assert held.round_off is not None and held.round_off < ROUND_OFF
    assert held.systematic == ()


def test_a_verdict_over_a_round_off_residual_says_exact_not_what_it_follows(exact_heldout):
    """A verdict above its floor on an exact prediction says the prediction is exact to
    round-off, where the diagnosis named what the round-off followed."""
    v = exact_heldout.validation
    error, q, dq = [v.log.tau - v.tau_hat], [v.log.q], [v.log.dq]
    noise = np.full(7, float(np.sqrt(np.mean(error[0] ** 2))) / 30.0)
    fair = Verdict("fair", "usable", "error 30 x the noise floor")
    names = [f"joint{j + 1}" for j in range(7)]
    said = with_dependence_hint(fair, q, dq, error, noise, names, torques=[v.log.tau])
    assert "is exact to round-off (residual " in said.reason, said.reason
    assert "follows" not in said.reason
    assert residual_dependence(q, dq, error, noise)  # the ratio alone calls them above


def test_a_noisy_residual_or_a_springs_is_not_round_off():
    """Control: a residual of white noise (0.05 N m on torques of 10 N m) or of a spring
    is far above round-off, and the diagnosis of the spring stands."""
    rng = np.random.default_rng(12)
    N = 4000
    q = rng.uniform(-1.0, 1.0, (N, 1))
    tau = 10.0 * np.sin(3.0 * q) + rng.normal(0.0, 1.0, (N, 1))
    noise = rng.normal(0.0, 0.05, (N, 1))
    assert round_off([noise], [tau]) is None
    spring = 0.6 * q + noise
    assert round_off([spring], [tau]) is None
    fair = Verdict("fair", "usable", "error 5 x the noise floor")
    said = with_dependence_hint(fair, [q], [np.zeros_like(q)], [spring], np.full(1, 0.05),
                                ["joint1"], torques=[tau])  # fmt: skip
    assert "joint1: " in said.reason and "follows its position" in said.reason, said.reason
