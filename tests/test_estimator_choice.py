"""The estimator chosen on held-out data (``estimator="auto"``): weighted least squares
where the joints' noise differs, ordinary where it is equal; judged against the simulated
truth."""

from __future__ import annotations

import warnings

import numpy as np
import pytest

from dynid.cli.summaries import format_identification
from dynid.exceptions import DynidWarning
from dynid.identification.selection import identify_recordings
from dynid.identification.structure import Structure
from dynid.io.model_json import model_from_dict, model_to_dict
from dynid.simulation.measurement import SensorNoise

from conftest import planar_2r, recordings


def _logs(tau_std: tuple[float, float], seed: int = 1) -> list:
    """A 6 s noisy recording of the planar 2R arm, no friction, each joint's torque noise
    ``tau_std`` [N m]."""
    noise = SensorNoise(tau_std=tau_std, q_std=1e-5, dq_std=1e-3)
    return recordings(planar_2r(), [seed], friction=None, duration=6.0, noise=noise, fs=200.0)


def _identified(logs: list, **kw):
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", DynidWarning)
        return identify_recordings(planar_2r(), logs, **kw)


def _beta_error_percent(model) -> np.ndarray:
    """Each base parameter's error against the simulated arm's [%] of its true value."""
    truth = model.base.beta_from_phi(planar_2r().phi)
    beta = model.beta[: model.base.rank]
    return 100 * np.abs(beta - truth) / np.maximum(np.abs(truth), 1e-12)


def _torque_error_percent(model) -> np.ndarray:
    """Per joint, the model's torques on a noise-free recording of another motion minus
    the true ones, RMS [%] of the true torques' RMS."""
    (exact,) = recordings(planar_2r(), [7], friction=None, duration=4.0, fs=200.0)
    e = model.torques(exact.q, exact.dq, exact.ddq) - exact.tau
    return 100 * np.sqrt(np.mean(e**2, 0) / np.mean(exact.tau**2, 0))


def test_weighted_least_squares_is_chosen_where_one_joints_noise_is_twenty_times_the_others():
    """Joint 1's torque noise 20 times joint 2's: ordinary least squares lets joint 1's
    noise set the parameters joint 2's small torques determine (J2zz 7 % off the truth);
    the choice on held-out data, each joint in units of its own noise, keeps weighted
    least squares, whose joint-2 parameters and torques are closer to the truth."""
    logs = _logs((0.4, 0.02))
    chosen = _identified(logs, structure=Structure.parse("links"))
    plain = _identified(logs, structure=Structure.parse("links"), estimator="ols")
    assert chosen.info.estimator == "wls"
    choice = chosen.info.estimator_choice
    assert choice is not None and choice["chosen"] == "wls"
    ols, wls = choice["candidates"]
    assert (ols["estimator"], wls["estimator"]) == ("ols", "wls")
    assert (
        wls["heldout_whitened_percent"] + ols["heldout_se_vs_best_percent"]
        < (ols["heldout_whitened_percent"])
    )
    labels = ("mc2x", "J2zz")  # joint 2's own parameters (beta4, beta6)
    at = [chosen.base.expressions.index(lab) for lab in labels]
    assert np.all(_beta_error_percent(chosen)[at] < 0.5 * _beta_error_percent(plain)[at])
    assert _torque_error_percent(chosen)[1] < 0.5 * _torque_error_percent(plain)[1]
    assert plain.info.estimator == "ols" and plain.info.estimator_choice is None


def test_ordinary_least_squares_is_kept_where_the_joints_noise_is_equal():
    """Equal torque noise on both joints: the weighted fit predicts the held-out data no
    better (within one standard error), and the simpler ordinary least squares is kept,
    the structure chosen as before (the search is the same) and the parameters those of
    ``estimator="ols"``."""
    logs = _logs((0.05, 0.05))
    chosen = _identified(logs)
    plain = _identified(logs, estimator="ols")
    assert chosen.info.estimator == "ols"
    assert chosen.info.estimator_choice is not None
    assert chosen.info.estimator_choice["chosen"] == "ols"
    assert chosen.info.selection is not None and plain.info.selection is not None
    assert chosen.info.selection["chosen"] == plain.info.selection["chosen"]
    np.testing.assert_allclose(chosen.beta, plain.beta, rtol=0, atol=1e-12)
    assert np.max(_beta_error_percent(chosen)[[0, 2, 3, 5]]) < 2.0  # the truth, to noise


@pytest.mark.parametrize("estimator", ["ols", "wls"])
def test_an_estimator_given_is_kept_as_is(estimator):
    """An estimator given is fitted as given, however the joints' noise differs: nothing
    is chosen nor recorded as chosen."""
    model = _identified(_logs((0.4, 0.02)), structure=Structure.parse("links"), estimator=estimator)
    assert model.info.estimator == estimator
    assert model.info.estimator_choice is None


def test_the_estimators_choice_is_saved_read_back_and_printed():
    """``metadata.estimator_choice`` of identification.json holds the rule, the choice
    and each estimator's held-out errors, read back as written; the summary prints one
    row per estimator, the one kept marked ``*``, with its whitened held-out error."""
    model = _identified(_logs((0.4, 0.02)), structure=Structure.parse("links"))
    text = format_identification(model)
    assert "estimator chosen on the same held-out data: wls" in text
    lines = text.splitlines()
    rows = {ln[4:].split()[0]: ln for ln in lines if ln[4:].startswith(("ols ", "wls "))}
    assert rows["wls"].startswith("  * ") and rows["ols"].startswith("    ")
    for c in model.info.estimator_choice["candidates"]:
        assert f"{c['heldout_whitened_percent']:.4g}" in rows[c["estimator"]]
    d = model_to_dict(model)
    assert d["metadata"]["estimator_choice"]["chosen"] == "wls"
    back = model_from_dict(d)
    assert back.info.estimator_choice == model.info.estimator_choice
    assert back.info.estimator == "wls"
