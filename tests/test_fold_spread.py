"""identify's held-out verdict over recordings counts the noise of the folds' own
coefficients in its floor: each recording is predicted by coefficients fitted on the others
alone, which the sensors' noise moves.

Regression: a UR5 identified from two 7 s recordings (the truth's structure) was judged
"usable, wrist_1 at 1.38 x its noise: friction the law misses"; the folds' predictions
erred 0.022 N m RMS on that wrist against the truth's torques beside 0.020 N m of noise,
where the final fit, validated on another recording, sat at the floor.

References: the covariance and the spread of least-squares fits drawn on fresh noise
(Monte Carlo); a simulated planar 2R arm with known viscous and Coulomb friction and sensor
noise, identified with the truth's structure and with its Coulomb friction left out.
"""

from __future__ import annotations

import warnings

import numpy as np
import pytest

from dynid.exceptions import DynidWarning
from dynid.friction.model import ClassicalFriction
from dynid.identification.fold_spread import (
    coefficient_covariance,
    covariance_of_sums,
    draw_margin,
    piece_sums,
    prediction_variance,
)
from dynid.identification.verdict import SYSTEMATIC_RATIO
from dynid.simulation.measurement import SensorNoise
from dynid.workflows.identify import IdentifyOptions, identify_logs

from conftest import planar_2r, recordings

FRICTION = ClassicalFriction(np.array([0.3, 0.2]), np.array([0.8, 0.5]), np.zeros(2))


@pytest.mark.parametrize("weighted", [False, True])
def test_the_covariance_is_the_spread_of_fits_on_fresh_noise(weighted):
    """Least squares (ols, or each joint weighed by its noise) of 4 000 draws of white
    noise of a different level per joint: the coefficients' sample covariance equals
    coefficient_covariance within 10 %, rows given at every 2nd sample counted twice."""
    rng = np.random.default_rng(3)
    M, n, p = 60, 2, 3
    Y = rng.normal(size=(M, n, p))
    var = np.array([0.04, 0.0025])
    w = 1.0 / np.sqrt(var) if weighted else np.ones(n)
    A = (Y * w[None, :, None]).reshape(-1, p)
    draws = []
    for _ in range(4000):
        e = rng.normal(size=(M, n)) * np.sqrt(var)
        draws.append(np.linalg.lstsq(A, (e * w).ravel(), rcond=None)[0])
    sample = np.cov(np.array(draws).T)
    twice = coefficient_covariance([(2, Y[::2]), (2, Y[1::2])], var, weighted=weighted)
    once = coefficient_covariance([(1, Y)], var, weighted=weighted)
    assert np.allclose(np.diag(once), np.diag(sample), rtol=0.1), (np.diag(once), np.diag(sample))
    assert np.allclose(once, sample, atol=0.1 * np.sqrt(np.outer(np.diag(sample), np.diag(sample))))
    assert np.all(np.diag(twice) > 0)
    moved = np.einsum("mjp,dp->dmj", Y, np.array(draws)) ** 2  # each draw's prediction
    assert np.allclose(prediction_variance(Y, once).mean(0), moved.mean(axis=(0, 1)), rtol=0.1)


@pytest.mark.parametrize("weighted", [False, True])
def test_the_pieces_sums_formed_once_give_each_folds_covariance(weighted):
    """Three pieces' sums formed once (piece_sums) and added for each fold's training
    data, the other two (covariance_of_sums), equal the closed form of the two pieces'
    rows stacked: (Y^T S^-1 Y)^-1 (wls) or (Y^T Y)^-1 Y^T S Y (Y^T Y)^-1 (ols), each row
    counted k times, to 1e-12."""
    rng = np.random.default_rng(8)
    n, p = 3, 4
    pieces = [(k, rng.normal(size=(m, n, p))) for k, m in ((1, 30), (2, 25), (3, 40))]
    var = np.array([0.04, 0.01, 0.0025])
    sums = piece_sums(pieces, var, weighted=weighted)
    for fold in range(3):
        train = [pieces[f] for f in range(3) if f != fold]
        A = np.concatenate([np.sqrt(k) * Y.reshape(-1, p) for k, Y in train])
        s = np.tile(var, A.shape[0] // n)
        if weighted:
            truth = np.linalg.inv(A.T @ (A / s[:, None]))
        else:
            G = np.linalg.inv(A.T @ A)
            truth = G @ A.T @ (A * s[:, None]) @ G
        got = covariance_of_sums([sums[f] for f in range(3) if f != fold], weighted=weighted)
        np.testing.assert_allclose(got, truth, rtol=1e-12, atol=1e-12 * np.abs(truth).max())
        direct = coefficient_covariance(train, var, weighted=weighted)
        np.testing.assert_allclose(direct, truth, rtol=1e-12, atol=1e-12 * np.abs(truth).max())


def test_the_margin_is_one_standard_deviation_of_the_added_squared_error():
    """The squared error a fold's coefficients add, drawn 20 000 times from their
    covariance: draw_margin is its mean plus its standard deviation over its mean, per
    joint, within 5 %."""
    rng = np.random.default_rng(4)
    Y = rng.normal(size=(40, 2, 3))
    L = rng.normal(size=(3, 3))
    cov = L @ L.T
    d = rng.multivariate_normal(np.zeros(3), cov, size=20_000)
    added = (np.einsum("mjp,dp->dmj", Y, d) ** 2).sum(axis=1)  # (draws, n)
    want = (added.mean(0) + added.std(0)) / added.mean(0)
    got = draw_margin([(1, Y, cov)])
    assert np.allclose(got, want, rtol=0.05), (got, want)


@pytest.fixture(scope="module")
def arm():
    return planar_2r().replace(q_min=(-2.5, -2.5), q_max=(2.5, 2.5))


def _held(arm, seeds, terms, duration=2.0, friction=FRICTION):
    """The held-out prediction of identify on noisy recordings of the arm (200 Hz)."""
    logs = recordings(
        arm, seeds, friction=friction, duration=duration, fs=200.0, noise=SensorNoise()
    )
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", DynidWarning)
        return identify_logs(arm, logs, IdentifyOptions(terms=terms)).heldout


def test_two_short_recordings_of_the_truths_structure_are_at_the_floor(arm):
    """Two 2 s recordings, the truth's structure (viscous and Coulomb): each recording
    predicted by the fit of the other is at the noise floor, every joint within its noise
    (it read "usable", joint 1 at 1.59 x, with the sensors' and the states' noise alone);
    the floor names the folds' coefficients' part and heldout.json holds it."""
    held = _held(arm, (3, 4), "viscous,coulomb")
    v, floor = held.verdict, held.floor
    assert v.level == "good", v.reason
    assert np.all(floor.joint_ratios <= SYSTEMATIC_RATIO), floor.joint_ratios
    assert "that of the coefficients fitted without these samples" in v.reason
    assert str(v) == f"{v.label}: {v.reason}" and str(v).startswith("at the noise floor: ")
    assert floor.fit_rms is not None and np.all(floor.fit_rms > 0)
    assert held.as_dict()["fit_noise_rms"] == pytest.approx(floor.fit_rms.tolist())


def test_a_missing_coulomb_friction_is_still_named(arm):
    """The same recordings fitted without the Coulomb friction the truth holds (0.8 and
    0.5 N m, 16 and 10 x the noise): both joints named above their noise, more than 3 x,
    what follows the velocity said."""
    held = _held(arm, (3, 4), "viscous")
    v = held.verdict
    assert v.level != "good", v.reason
    assert np.all(held.floor.joint_ratios > 3.0), held.floor.joint_ratios
    assert "joint1 at" in v.reason and "joint2 at" in v.reason, v.reason
    assert "velocity" in v.reason, v.reason


def test_folds_too_loose_to_judge_are_said_not_counted(arm):
    """Offsets the truth lacks over 2 s recordings leave the folds' coefficients loose
    (their noise above twice the sensors'): not counted in the floor (which they would
    make explain anything) but said, and the verdict is not at the floor."""
    held = _held(arm, (1, 2), "viscous,coulomb,offset")
    assert held.fitted is None and held.floor.fit_rms is None
    assert held.verdict.level != "good"
    assert "leave coefficients loose" in held.verdict.reason, held.verdict.reason
