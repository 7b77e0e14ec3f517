"""The sign check of the observer (:mod:`dynid.observer.sign`): the correlation of the
measured torques with ``tau + r`` fed in blocks equals numpy's ``corrcoef`` of the whole
(observed) samples, and a residual of twice the torque on a joint (the sign of its torque
opposite to the model's: ``r = K_O / (s + K_O) (tau_model - tau)`` with ``tau_model =
-tau``) names that joint, while a model without torques (``r`` the lagged measured torque)
never does."""

from __future__ import annotations

import re

import numpy as np
import pytest

from dynid.exceptions import ShapeError
from dynid.observer.residual import first_order_lag
from dynid.observer.sign import TorqueSign, opposite_finding, unexplained_finding


@pytest.mark.parametrize("block", [1, 7, 1000])
def test_correlation_fed_in_blocks_is_numpys_over_the_observed_samples(block):
    """Torques with large offsets (the running sums stay exact about their mean) and NaN
    residual rows (not observed: skipped)."""
    rng = np.random.default_rng(3)
    N, n = 600, 3
    tau = 40.0 + rng.standard_normal((N, n)) * [1.0, 0.1, 3.0]
    r = rng.standard_normal((N, n)) * 0.5 - tau * [0.0, 2.0, 0.3]
    r[100:130] = np.nan
    s = TorqueSign(n)
    for a in range(0, N, block):
        s.add(tau[a : a + block], r[a : a + block])
    ok = np.all(np.isfinite(r), axis=1)
    want = [np.corrcoef(tau[ok, j], tau[ok, j] + r[ok, j])[0, 1] for j in range(n)]
    np.testing.assert_allclose(s.correlation(), want, rtol=1e-10, atol=1e-12)


def test_a_residual_of_twice_the_torque_names_the_joint_a_model_without_torques_none():
    """A 1 Hz torque at 500 Hz with noise, K_O = 50/s (closed-form lag of
    :func:`first_order_lag`): joint 2 of the opposite sign to the model (r the lag of
    ``-2 tau``) is named alone with its columns to flip; every joint flipped gives
    ``--units tau=-1``; a model without torques (r the lag of ``-tau``) names none."""
    t = np.arange(0.0, 4.0, 2e-3)
    rng = np.random.default_rng(1)
    tau = np.stack([np.sin(2 * np.pi * t), 0.3 * np.cos(2 * np.pi * t + 0.4)], axis=1)
    tau = tau + 0.02 * rng.standard_normal(tau.shape)
    lag = lambda x: first_order_lag(t, x, 50.0)  # noqa: E731
    names = ("a", "b")
    one = TorqueSign(2)
    one.add(tau, lag(tau * [0.01, -2.0]))
    assert one.opposite().tolist() == [False, True]
    said = opposite_finding(one, names)
    assert said is not None and said.startswith("the measured torques of b are")
    assert "hint: --units tau2=-1 reads it flipped" in said
    every = TorqueSign(2)
    every.add(tau, lag(-2.0 * tau))
    assert "hint: --units tau=-1" in (opposite_finding(every, names) or "")
    none = TorqueSign(2)
    none.add(tau, lag(-tau))
    assert not none.opposite().any() and opposite_finding(none, names) is None
    with pytest.raises(ShapeError):
        opposite_finding(none, ("a",))


def test_the_velocities_noise_through_the_gain_is_not_called_the_models_error():
    """A model exact to the torques, its residual white noise of 0.8 N m RMS (the
    velocities' noise through ``K_O M(q)``, known) on a joint whose torque spreads 1 N m:
    the residual's spread is 0.8 of the torques', but none of it is the model's, so nothing
    is said once that noise is taken out; a model error of 0.9 times the torque on top is
    still named alone, its share 0.9 to 0.01."""
    t = np.arange(0.0, 20.0, 1e-3)
    rng = np.random.default_rng(4)
    tau = np.sqrt(2.0) * np.stack([np.sin(2 * np.pi * t), np.cos(3 * t)], axis=1)
    noise = 0.8 * rng.standard_normal(tau.shape)
    names = ("a", "b")
    exact = TorqueSign(2)
    exact.add(tau, noise)
    assert unexplained_finding(exact, names) is not None  # 0.8 > 0.5 without the noise
    assert unexplained_finding(exact, names, [0.8, 0.8]) is None
    wrong = TorqueSign(2)
    wrong.add(tau, noise + tau * [0.9, 0.0])
    said = unexplained_finding(wrong, names, [0.8, 0.8])
    found = re.search(r"taken out: (.*?)\)", said or "")
    assert found is not None and found.group(1).startswith("a "), said
    assert abs(float(found.group(1)[2:]) - 0.9) < 0.01, said
    with pytest.raises(ShapeError):
        unexplained_finding(wrong, names, [0.8])


def test_a_model_that_explains_little_of_the_log_is_said_at_calibration(tmp_path, capsys):
    """Calibrated on a log whose friction the model does not hold (Coulomb 15 N m against
    the Panda's own sigmoid), the residual spreads over most of the torques' on the joints
    it dominates: a warning names them (the thresholds were written without a word); the
    model's own log gives none."""
    import json

    from dynid.cli.__main__ import main
    from dynid.friction.model import ClassicalFriction
    from dynid.io.friction_json import save_friction_json

    big = save_friction_json(
        tmp_path / "big.json", ClassicalFriction(np.zeros(7), np.full(7, 15.0), np.zeros(7))
    )
    for name, extra in (("own", []), ("big", ["--friction", str(big)])):
        log = tmp_path / f"{name}.csv"
        argv = ["simulate", "--robot", "panda", "--duration", "6", "--rate", "500", "-q"]
        assert main([*argv, "--seed", "3", *extra, "--out", str(log)]) == 0
    said = {}
    for name in ("own", "big"):
        capsys.readouterr()
        argv = ["observe", "--params", "panda", "--data", str(tmp_path / f"{name}.csv")]
        out = tmp_path / f"c_{name}"
        assert main([*argv, "--calibrate", "--no-figures", "--out", str(out)]) == 0
        err = capsys.readouterr().err.splitlines()
        said[name] = [line for line in err if "unexplained" in line]
        assert json.loads((out / "thresholds.json").read_text())["contact"]
    assert not said["own"], said["own"]
    assert len(said["big"]) == 1 and "big.csv: the model leaves" in said["big"][0], said["big"]
