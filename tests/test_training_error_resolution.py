"""The training error ``identify`` prints is the fit's relative residual even where it lies
far below the torques' norm: read from normal equations as ``x^T G x - 2 b^T x + c``, it
lost everything below about ``sqrt(eps)`` to cancellation, and an exact Panda log fitted
without a low-pass (``--cutoff none``) read "training error 0 %" (or 1.3e-06 % for a
residual of 2.8e-14 %)."""

from __future__ import annotations

import dataclasses
import re

import numpy as np
import pytest

import dynid
from dynid.cli.__main__ import main
from dynid.identification.holdout import block_normals
from dynid.io.model_json import load_model_json
from dynid.io.torque_log import save_torque_log

from conftest import recordings


def test_normals_about_the_fit_resolve_a_tiny_residual():
    """Normal equations kept about the least-squares solution give its residual sum of
    squares to 1e-6 where the plain quadratic form is off by orders of magnitude."""
    rng = np.random.default_rng(3)
    W = rng.standard_normal((4000, 12)) * rng.uniform(0.1, 10.0, 12)
    y = W @ rng.standard_normal(12) * 10.0 + 1e-9 * rng.standard_normal(4000)
    x = np.linalg.lstsq(W, y, rcond=None)[0]
    truth = float(np.sum((W @ x - y) ** 2))
    labels = np.zeros(4000, dtype=np.intp)
    (about,) = block_normals(W, y, labels, x)
    (plain,) = block_normals(W, y, labels)
    assert about.sse(x) == pytest.approx(truth, rel=1e-6)
    assert not 0.5 * truth < plain.sse(x) < 2.0 * truth  # lost to cancellation (read 0)
    step = 1e-6 * rng.standard_normal(12)  # away from the origin, still exact
    assert about.sse(x + step) == pytest.approx(float(np.sum((W @ (x + step) - y) ** 2)), rel=1e-6)


def test_training_error_without_low_pass_is_the_fits_relative_residual(tmp_path, capsys):
    """identify --cutoff none on an exact Panda log with 1e-8 N m of noise: the training
    error printed and recorded equals 100 ||tau - model torques|| / ||tau||, computed
    from identification.json's model on the log's own states (about 1e-7 %, not 0 %)."""
    robot = dynid.panda()
    (log,) = recordings(robot, (21,), friction=None, duration=3.0)
    rng = np.random.default_rng(21)
    log = dataclasses.replace(log, tau=log.tau + 1e-8 * rng.standard_normal(log.tau.shape))
    save_torque_log(tmp_path / "exact.npz", log)
    out = tmp_path / "id"
    args = ["identify", "--data", str(tmp_path / "exact.npz"), "--cutoff", "none"]
    assert main([*args, "--terms", "links", "--out", str(out), "--no-figures"]) == 0
    printed = float(re.search(r"training error (\S+) %", capsys.readouterr().out).group(1))
    model = load_model_json(out / "identification.json")
    residual = log.tau - model.torques(log.q, log.dq, log.ddq)
    truth = 100.0 * np.linalg.norm(residual) / np.linalg.norm(log.tau)
    assert 1e-9 < truth < 1e-5
    assert printed == pytest.approx(truth, rel=1e-3)
    assert model.info.heldout["training_error_percent"] == pytest.approx(truth, rel=1e-6)
