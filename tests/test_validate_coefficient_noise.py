"""validate's floor for an identified model counts the noise of its own coefficients.

A UR5 identified from noisy recordings and validated on an exact held-out log erred
0.05 %, of the size its coefficients' uncertainty allows (0.1 %), and was judged "usable:
effects outside the model remain ... the joint's inertia is off", against a floor of the
exact log's rounding alone (8.6e-14 %). The reference here: a planar 2R arm with viscous
friction simulated exactly, identified from its torques with white noise added, and
validated on an exact recording of another trajectory; the spread of the predictions of
models identified on other draws of the noise is the truth the recorded part is held to.
"""

from __future__ import annotations

import dataclasses

import numpy as np
import pytest

from dynid.friction.model import ClassicalFriction
from dynid.friction.validation import own_friction
from dynid.identification.coefficient_noise import coefficient_noise
from dynid.identification.selection import identify_recordings
from dynid.identification.structure import Structure
from dynid.io.model_json import load_model_json, model_from_dict, model_to_dict, save_model_json
from dynid.io.torque_log import save_torque_log
from dynid.workflows.validate import validate_files

from conftest import planar_2r, recordings

FV = np.array([0.3, 0.2])  # N m s/rad
SIGMA = 0.05  # N m, the torque sensors' white noise
DRAWS = 8  # noise draws identified for the spread of the predictions


def _noisy(logs, seed):
    """``logs`` with white torque noise of ``SIGMA`` drawn from ``seed``, accelerations
    left to be derived (as a recording holds none)."""
    rng = np.random.default_rng(seed)
    return [
        dataclasses.replace(g, tau=g.tau + SIGMA * rng.standard_normal(g.tau.shape), ddq=None)
        for g in logs
    ]


@pytest.fixture(scope="module")
def fitted(tmp_path_factory):
    """Models identified on ``DRAWS`` noise draws of the same two 6 s recordings, the
    exact held-out recording and its file."""
    robot = planar_2r()
    fr = ClassicalFriction(FV, np.zeros(2), np.zeros(2))
    train = recordings(robot, (1, 2), friction=fr, duration=6.0, fs=200.0)
    (held,) = recordings(robot, (9,), friction=fr, duration=3.0, fs=200.0)
    models = [
        identify_recordings(
            robot,
            _noisy(train, s),
            ("train1.csv", "train2.csv"),
            structure=Structure.parse("viscous"),
        )  # fmt: skip
        for s in range(DRAWS)
    ]
    path = save_torque_log(tmp_path_factory.mktemp("held") / "held.csv", held)
    return models, held, path


def test_an_exact_log_is_judged_at_the_floor_of_the_models_coefficients(fitted):
    """The model of noisy data on an exact log: without its coefficients' covariance
    (before) an effect outside the model is blamed; with it, at the noise floor, its
    coefficients' part said in the reason and recorded."""
    models, _, path = fitted
    model = models[0]
    fit = dataclasses.replace(model.joint_fit, covariance=None)
    before = validate_files(dataclasses.replace(model, joint_fit=fit), path)
    assert before.verdict.level != "good", before.verdict.reason
    assert "effects outside the model" in before.verdict.reason, before.verdict.reason
    assert before.fit_noise_rms is None
    after = validate_files(model, path)
    assert after.verdict.label == "at the noise floor", after.verdict.reason
    assert "that of the model's coefficients" in after.verdict.reason
    assert after.fit_noise_rms is not None and np.all(after.fit_noise_rms > 0)
    doc = after.metadata()
    assert doc["fit_noise_rms"] == pytest.approx(list(after.fit_noise_rms))
    total = np.sqrt(after.sensor_noise_rms**2 + after.input_noise_rms**2 + after.fit_noise_rms**2)
    assert after.noise_rms == pytest.approx(total, rel=1e-9)


def test_the_coefficients_part_is_the_spread_of_models_fitted_on_other_noise(fitted):
    """The prediction std the recorded covariance gives at the held-out samples is the
    spread of the predictions of the models identified on the other noise draws within
    1.5 times, per joint; the part the floor counts is that, at its mean plus at most
    sqrt(2) standard deviations of the one draw."""
    models, held, path = fitted
    q, dq, ddq = held.q, held.dq, held.ddq
    P = np.array([m.torques(q, dq, ddq) + own_friction(m).torques(dq) for m in models])
    spread = np.sqrt(np.mean(np.var(P, axis=0, ddof=1), axis=0))
    res = validate_files(models[0], path)
    parts = res.validation.parts
    found = coefficient_noise(
        models[0], [v.log for v in parts], [v.tau_model for v in parts], friction=True
    )
    assert found is not None
    mean = np.sqrt(np.mean(np.concatenate([V for _, V in found.pieces]), axis=0))
    assert np.all(mean / spread < 1.5) and np.all(spread / mean < 1.5), (mean, spread)
    assert np.all(res.fit_noise_rms >= mean * (1 - 1e-9))
    assert np.all(res.fit_noise_rms <= mean * np.sqrt(1 + np.sqrt(2)))


def test_the_covariance_of_every_coefficient_is_saved_and_read_back(fitted, tmp_path):
    """identification.json records the covariance of the base parameters and the
    friction together; read back, validate counts the same part; a file without it (an
    older one) counts none."""
    models, _, path = fitted
    model = models[0]
    read = load_model_json(save_model_json(tmp_path / "identification.json", model))
    assert read.joint_fit is None
    want = np.asarray(model.joint_fit.covariance)
    assert read.coefficient_covariance() == pytest.approx(want, rel=1e-12, abs=0.0)
    again = validate_files(read, path)
    assert again.fit_noise_rms == pytest.approx(validate_files(model, path).fit_noise_rms)
    doc = model_to_dict(model)
    doc["covariance_with_terms"] = None
    assert validate_files(model_from_dict(doc), path).fit_noise_rms is None


def test_the_recordings_the_model_was_fitted_on_count_no_part(fitted, tmp_path):
    """On a recording of a name the model was identified from, the residual holds no
    estimation error of its own: no part of the coefficients is counted there."""
    models, held, _ = fitted
    path = save_torque_log(tmp_path / "train1.csv", held)
    with pytest.warns(Warning, match="training errors"):
        res = validate_files(models[0], path)
    assert res.fit_noise_rms is not None and np.all(res.fit_noise_rms == 0.0)


def test_a_robots_own_parameters_count_no_part(fitted):
    """A robot description has no covariance: its floor is as before, without the part."""
    _, _, path = fitted
    res = validate_files(planar_2r(), path)
    assert res.fit_noise_rms is None
    assert "model's coefficients" not in res.verdict.reason


def test_a_model_whose_own_fit_missed_its_floor_counts_no_part(fitted):
    """A model whose identification held out above its floor (effects outside it) records
    a covariance the misfit inflates: its coefficients' part is not counted, and the
    exact log is judged against its own noise as before; the model as identified (held
    out at its floor) counts it."""
    models, _, path = fitted
    model = models[0]
    held = dict(model.info.heldout or {})
    assert held["heldout_error_percent"] <= 1.25 * held["noise_floor_percent"]
    assert validate_files(model, path).fit_noise_rms is not None
    held["heldout_error_percent"] = 2.0 * held["noise_floor_percent"]
    missed = dataclasses.replace(model, info=dataclasses.replace(model.info, heldout=held))
    res = validate_files(missed, path)
    assert res.fit_noise_rms is None
    assert "effects outside the model" in res.verdict.reason, res.verdict.reason
