"""Estimators (issue 18): OLS, per-joint WLS (Gautier) and Huber IRLS, on every route.

References: the truth of simulated data (the Panda's published parameters), closed-form
weighted least squares, and the statistics of repeated noisy fits.
"""

from __future__ import annotations

import numpy as np
import pytest

import dynid
from dynid.exceptions import OptionError
from dynid.identification.classical import identify_from_log
from dynid.identification.engine import fit_stacked
from dynid.identification.estimators import IRLS, OLS, WLS, estimator_named
from dynid.identification.log import TorqueLog
from dynid.regressors.base import base_parameters
from dynid.simulation.measurement import sample_times, simulate_measurement
from dynid.simulation.trajectories import random_fourier


def _linear_problem(seed: int, sigmas=(0.01, 0.01, 1.0), m: int = 3000):
    """A linear model with three row groups of very different noise."""
    rng = np.random.default_rng(seed)
    W = rng.normal(size=(m, 4))
    beta = np.array([1.0, -2.0, 0.5, 3.0])
    groups = np.arange(m) % 3
    y = W @ beta + rng.normal(size=m) * np.asarray(sigmas)[groups]
    return W, y, groups, beta


def test_wls_equals_the_closed_form_weighted_solution():
    """WLS with the residual noise of each group equals (W^T S^-1 W)^-1 W^T S^-1 y with those
    noise levels, and beats OLS when one group is 100 times noisier."""
    W, y, groups, beta = _linear_problem(0)
    ols = fit_stacked(W, y, groups, OLS(), rtol=1e-10, std="classical")
    wls = fit_stacked(W, y, groups, WLS(), rtol=1e-10, std="classical")
    e = y - W @ ols.beta
    s = np.array(
        [
            np.sqrt(np.sum(e[groups == g] ** 2) / (np.sum(groups == g) * (1 - 4 / 3000)))
            for g in range(3)
        ]
    )
    w = 1.0 / s[groups]
    ref = np.linalg.lstsq(W * w[:, None], y * w, rcond=None)[0]
    np.testing.assert_allclose(wls.beta, ref, rtol=1e-12)
    assert np.linalg.norm(wls.beta - beta) < 0.3 * np.linalg.norm(ols.beta - beta)
    # the residual statistics are those of the unweighted data
    r = y - W @ wls.beta
    assert wls.residual_rms == pytest.approx(np.sqrt(np.mean(r**2)), rel=1e-12)


def test_irls_resists_outliers_and_its_std_holds():
    """5 % of the rows hit by gross outliers: IRLS stays within a few of its std of the
    truth, ten times closer than OLS; on clean data IRLS is within its std too."""
    W, y, groups, beta = _linear_problem(1, sigmas=(0.01, 0.02, 0.05))
    rng = np.random.default_rng(2)
    bad = rng.choice(y.size, y.size // 20, replace=False)
    yb = y.copy()
    yb[bad] += rng.choice([-1, 1], bad.size) * rng.uniform(5, 20, bad.size)
    ols = fit_stacked(W, yb, groups, OLS(), rtol=1e-10, std="classical")
    irls = fit_stacked(W, yb, groups, IRLS(), rtol=1e-10, std="classical")
    assert np.max(np.abs(irls.beta - beta) / irls.std) < 5
    assert np.linalg.norm(irls.beta - beta) < 0.1 * np.linalg.norm(ols.beta - beta)
    clean = fit_stacked(W, y, groups, IRLS(), rtol=1e-10, std="classical")
    assert np.max(np.abs(clean.beta - beta) / clean.std) < 5


def test_estimator_names_and_errors():
    """Names map to the classes; an unknown name is an OptionError naming the choices."""
    assert isinstance(estimator_named("wls"), WLS)
    assert estimator_named(IRLS(c=2.0)).c == 2.0
    with pytest.raises(OptionError, match="irls"):
        estimator_named("huber")


@pytest.mark.filterwarnings("ignore:.*indistinguishable from zero")  # expected: weak coefficients
def test_classical_route_with_outliers_and_a_noisy_joint():
    """A Panda log whose joint 7 is 20 times noisier and whose torques carry 1 % spikes:
    IRLS predicts held-out torques better than OLS, and its base parameters are closer to
    the truth."""
    robot = dynid.panda()
    series = random_fourier(robot, np.random.default_rng(0))
    t = sample_times(20.0, 500.0)
    noise = dynid.simulation.measurement.SensorNoise(tau_std=np.r_[np.full(6, 0.05), 1.0])
    log = simulate_measurement(
        robot, series(t), rng=np.random.default_rng(1), friction=None, noise=noise, with_ddq=True
    )
    tau = np.array(log.tau)
    rng = np.random.default_rng(3)
    rows = rng.choice(tau.shape[0], tau.shape[0] // 100, replace=False)
    tau[rows, rng.integers(0, 7, rows.size)] += rng.choice([-1, 1], rows.size) * 30.0
    spiky = TorqueLog(log.t, log.q, log.dq, tau, log.ddq)
    truth = base_parameters(robot, kind="torque").beta_from_phi(robot.phi)
    fits = {
        name: identify_from_log(
            robot, spiky, cutoff_hz=None, decimate=1, estimator=name, structure="classical"
        )
        for name in ("ols", "wls", "irls")
    }
    err = {k: np.linalg.norm(m.beta - truth) / np.linalg.norm(truth) for k, m in fits.items()}
    assert err["irls"] < 0.5 * err["ols"]
    assert err["wls"] < err["ols"]
    assert fits["irls"].info.estimator == "irls"


def test_cli_std_and_estimator_are_honoured_on_both_routes(tmp_path):
    """--std robust on a torque log is recorded and used (it was ignored); --estimator wls on
    static data too (--std with --consistent: tests/test_workflows.py)."""
    import json

    from dynid.cli.__main__ import main

    assert (
        main(
            [
                "simulate",
                "--duration",
                "6",
                "--rate",
                "250",
                "--seed",
                "1",
                "--out",
                str(tmp_path / "log.csv"),
                "-q",
            ]
        )
        == 0
    )
    assert (
        main(
            [
                "identify",
                "--data",
                str(tmp_path / "log.csv"),
                "--std",
                "robust",
                "--estimator",
                "irls",
                "--terms",  # one fit: the structure search is not what is checked here
                "viscous,coulomb,offset",
                "--no-figures",
                "--out",
                str(tmp_path / "r"),
                "-q",
            ]
        )
        == 0
    )
    d = json.loads((tmp_path / "r" / "identification.json").read_text())
    assert d["std_estimator"] == "robust" and d["metadata"]["estimator"] == "irls"
    assert (
        main(
            [
                "acquire-static",
                "--n",
                "80",
                "--noise",
                "1e-4",
                "--seed",
                "1",
                "--out",
                str(tmp_path / "s.csv"),
                "-q",
            ]
        )
        == 0
    )
    assert (
        main(
            [
                "identify",
                "--data",
                str(tmp_path / "s.csv"),
                "--estimator",
                "wls",
                "--out",
                str(tmp_path / "s"),
                "-q",
            ]
        )
        == 0
    )
    d = json.loads((tmp_path / "s" / "identification.json").read_text())
    assert d["std_estimator"] == "robust" and d["metadata"]["estimator"] == "wls"


def test_weights_of_groups_or_rows_give_numpys_weighted_solution_and_bad_ones_are_refused():
    """The engine fits group weights and the same weights given row by row alike, both equal
    to numpy's lstsq of the weighted rows; weights that are neither, both, 2-D or negative
    are refused."""
    from dynid.exceptions import DataError, ShapeError
    from dynid.identification.engine import HeldRows
    from dynid.identification.estimators import Weights

    W, y, groups, _ = _linear_problem(3)
    wg = np.array([2.0, 0.5, 1.0])
    rows = HeldRows(W, y, groups)
    kw = {"rtol": 1e-10, "std": "classical", "max_std_percent": None, "labels": None}
    by_group = rows.fit(Weights(group=wg), **kw)
    by_row = rows.fit(Weights(row=wg[groups]), **kw)
    ref = np.linalg.lstsq(W * wg[groups][:, None], y * wg[groups], rcond=None)[0]
    np.testing.assert_allclose(by_group.beta, ref, rtol=1e-12)
    np.testing.assert_allclose(by_row.beta, ref, rtol=1e-12)
    with pytest.raises(ShapeError):
        Weights()
    with pytest.raises(ShapeError):
        Weights(group=wg, row=wg[groups])
    with pytest.raises(ShapeError):
        Weights(row=np.ones((2, 2)))
    with pytest.raises(DataError):
        Weights(group=-wg)
