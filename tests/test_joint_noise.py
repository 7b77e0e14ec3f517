"""Every joint judged in units of its own noise: the structure choice and the verdict.

References: simulated arms whose wrist torques are logged with a hundredth of the
shoulder's noise; the truth's per-joint noise is known, and a model is judged on a
recording it was not fitted to against that noise, joint by joint.
"""

from __future__ import annotations

import warnings

import numpy as np
import pytest

from dynid.exceptions import DynidWarning
from dynid.friction.model import ClassicalFriction
from dynid.friction.validation import own_friction
from dynid.identification.selection import identify_recordings
from dynid.identification.verdict import judge_prediction
from dynid.simulation.measurement import SensorNoise, sample_times
from dynid.simulation.trajectories import random_fourier

from conftest import recordings

#: Torque noise per joint [N m]: the wrist's a hundredth of the shoulder's.
NOISE = np.array([1.0, 1.0, 0.5, 0.5, 0.01, 0.01, 0.01])
ARMATURE = np.array([0.3, 0.25, 0.2, 0.15, 0.03, 0.03, 0.02])  # kg m^2
VISCOUS = np.array([0.3, 0.3, 0.2, 0.2, 0.05, 0.05, 0.03])  # N m s/rad


@pytest.mark.parametrize("estimator", ["ols", "wls"])
def test_wrist_terms_are_kept_where_the_wrist_noise_is_small(panda, estimator):
    """Armature and viscous friction on every joint, the wrist's torques 100 times less
    noisy than the shoulder's: in a pooled error the wrist's terms are lost in the
    shoulder's noise; judged in units of each joint's noise they are kept, and the model
    predicts a recording it never saw within 1.5 times each joint's noise. Alike with the
    weighted estimator: its weights (each joint's residual level) must not enter the
    judgement, where a joint's error would vanish with the terms it loses."""
    fr = ClassicalFriction(VISCOUS, np.zeros(7), np.zeros(7))
    noisy = SensorNoise(tau_std=tuple(NOISE), q_std=1e-5, dq_std=1e-3)
    *logs, test = recordings(
        panda, (31, 32, 33, 34), friction=fr, armature=ARMATURE, duration=6.0, noise=noisy
    )
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", DynidWarning)
        model = identify_recordings(panda, logs, estimator=estimator)
    chosen = model.info.selection["chosen"]
    assert chosen.startswith("links + armature + viscous"), chosen
    assert not any(f"Ia{j}" in chosen or f"fv{j}" in chosen for j in (5, 6, 7)), chosen
    held = random_fourier(panda, np.random.default_rng(34))(sample_times(6.0, 500.0))
    own = own_friction(model)
    pred = model.torques(held.q, held.dq, held.ddq) + own.torques(held.dq)
    rms = np.sqrt(np.mean((test.tau - pred) ** 2, axis=0))
    assert np.all(rms < 1.5 * NOISE), rms / NOISE


def test_the_verdict_names_a_joint_far_above_its_noise():
    """A pooled error at the floor with one joint at 9.5 times its noise is poor, one at
    2 times usable, naming the joints; every joint within 1.5 times leaves the pooled
    verdict as it is."""
    v = judge_prediction(5.73, 5.68, joint_ratios=[1.0, 1.0, 1.0, 1.0, 2.7, 3.1, 9.5])
    said = "5 at 2.7 x, 6 at 3.1 x, 7 at 9.5 x their noise"
    assert v.level == "poor" and said in v.reason, v.reason
    v = judge_prediction(5.73, 5.68, joint_ratios=[1.0, 2.0, 1.2])
    assert v.level == "fair" and v.label == "usable", v
    assert "2 at 2 x their noise" in v.reason, v.reason
    v = judge_prediction(5.73, 5.68, joint_ratios=[1.0, 1.4, 1.2])
    assert v.level == "good" and v.label == "at the noise floor"
    assert judge_prediction(60.0, 5.68, joint_ratios=[20.0]).level == "unusable"
