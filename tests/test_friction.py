"""Friction models, friction fits on simulated data, validation and friction.json."""

from __future__ import annotations

import json

import numpy as np
import pytest

from dynid.exceptions import DataError, OptionError, ShapeError
from dynid.friction.fit import fit_classical, fit_friction, fit_sigmoid, friction_residual
from dynid.friction.model import (
    ClassicalFriction,
    SigmoidFriction,
    classical_friction,
    sigmoid_friction,
)
from dynid.friction.validation import own_friction, validate_torques
from dynid.io.friction_json import load_friction_json, save_friction_json
from dynid.simulation.limits import scale_into_limits
from dynid.simulation.measurement import SensorNoise, sample_times, simulate_measurement
from dynid.simulation.trajectories import centered_start, sinusoid_trajectory

NOISE = 0.05  # torque sensor noise [N m]


@pytest.fixture(scope="module")
def sinusoid_log(panda):
    """20 s at 1 kHz of the Table I sinusoids (scaled into the limits), published friction."""
    t = sample_times(20.0, 1000.0)
    traj, _ = scale_into_limits(panda, sinusoid_trajectory(t, centered_start(panda)))
    log = simulate_measurement(
        panda, traj, rng=np.random.default_rng(21), noise=SensorNoise(tau_std=NOISE)
    )
    return traj, log


def _reference_sigmoid(dq, P):
    """Gaz et al. 2019 eq. 25 written out with exp (independent of the library's expit)."""
    p1, p2, p3 = P[:, 0], P[:, 1], P[:, 2]
    return p1 / (1 + np.exp(-p2 * (dq + p3))) - p1 / (1 + np.exp(-p2 * p3))


def test_sigmoid_friction_matches_the_published_formula(panda):
    """The sigmoid equals eq. 25, is zero at rest, and saturates at its two levels."""
    rng = np.random.default_rng(22)
    P = panda.friction.as_array()
    dq = rng.uniform(-3, 3, (4, 5, 7))
    fr = SigmoidFriction.from_array(P)
    tau = fr.torques(dq)
    assert tau.shape == (4, 5, 7)
    np.testing.assert_allclose(tau, _reference_sigmoid(dq, P), atol=1e-14)
    np.testing.assert_allclose(fr.torques(np.zeros(7)), 0.0, atol=1e-15)
    s = 1 / (1 + np.exp(-P[:, 1] * P[:, 2]))
    np.testing.assert_allclose(fr.torques(np.full(7, 1e3)), P[:, 0] * (1 - s), atol=1e-12)
    np.testing.assert_allclose(fr.torques(np.full(7, -1e3)), -P[:, 0] * s, atol=1e-12)
    np.testing.assert_allclose(fr.as_array(), P)
    np.testing.assert_allclose(sigmoid_friction(dq, *P.T), tau, atol=0)


def test_classical_friction_formula_and_sign_at_rest():
    """fv dq + fc sign(dq) + fo with sign(0) = 0; batch shape kept."""
    fr = ClassicalFriction([0.1, 0.2], [0.3, 0.4], [0.01, -0.02])
    dq = np.array([[1.0, -2.0], [0.0, 0.5]])
    expect = np.array([[0.1 + 0.3 + 0.01, -0.4 - 0.4 - 0.02], [0.01, 0.1 + 0.4 - 0.02]])
    np.testing.assert_allclose(fr.torques(dq), expect)
    np.testing.assert_allclose(classical_friction(dq, fr.fv, fr.fc, fr.fo), expect)
    with pytest.raises(ShapeError, match="dq must have shape"):
        fr.torques(np.zeros(3))
    with pytest.raises(ShapeError, match="fc must have shape"):
        ClassicalFriction([0.1, 0.2], [0.3], [0.0, 0.0])


def test_sigmoid_fit_reproduces_the_true_friction_curve(panda, sinusoid_log):
    """Fitted to the residual of the true rigid-body model, the sigmoid matches the published
    friction over the visited velocities to far below the sensor noise, and the RMS after
    compensation is the noise level."""
    traj, log = sinusoid_log
    fit = fit_friction(panda, log, kind="sigmoid")
    truth = panda.friction
    v = np.linspace(-1, 1, 2001)[:, None] * np.max(np.abs(traj.dq), axis=0)
    curve_rms = np.sqrt(np.mean((fit.friction.torques(v) - truth.torques(v)) ** 2, axis=0))
    assert np.all(curve_rms < 0.05 * NOISE), curve_rms
    # 19 600 samples: RMS of pure noise is NOISE within a few 0.5 %
    np.testing.assert_allclose(fit.rms_after, NOISE, rtol=0.03)
    assert np.all(fit.rms_before > 2.5 * NOISE)
    assert fit.converged.all() and fit.kind == "sigmoid"
    np.testing.assert_allclose(fit.friction.phi1, panda.friction.phi1, rtol=0.02)


def test_classical_fit_recovers_linear_friction(panda, sinusoid_log):
    """With classical friction as the truth, the linear fit recovers fv, fc, fo."""
    traj, _ = sinusoid_log
    truth = ClassicalFriction(
        np.linspace(0.05, 0.2, 7), np.linspace(0.3, 0.1, 7), np.linspace(-0.03, 0.03, 7)
    )
    log = simulate_measurement(
        panda, traj, rng=np.random.default_rng(23), noise=SensorNoise(tau_std=NOISE), friction=truth
    )
    res = friction_residual(panda, log)
    fit = fit_classical(res.dq, res.residual)
    np.testing.assert_allclose(fit.friction.as_array(), truth.as_array(), atol=0.01)
    np.testing.assert_allclose(fit.rms_after, NOISE, rtol=0.05)
    assert fit.kind == "classical"


def test_sigmoid_fit_rejects_bad_shapes():
    """dq and residual must be (N, n) of the same shape."""
    with pytest.raises(ShapeError, match="dq and residual"):
        fit_sigmoid(np.zeros((10, 2)), np.zeros((10, 3)))
    with pytest.raises(OptionError, match="--friction-model must be one of"):
        fit_friction(lambda q, dq, ddq: q, None, kind="stribek")


def test_validation_of_the_true_model_is_at_the_noise_level(panda, sinusoid_log):
    """The robot's own parameters and friction predict the measured torques to the noise."""
    _, log = sinusoid_log
    val = validate_torques(panda, log, friction=own_friction(panda))
    np.testing.assert_allclose(val.with_friction.rms, NOISE, rtol=0.03)
    np.testing.assert_allclose(val.with_friction.mse, val.with_friction.rms**2)
    assert np.all(val.without_friction.rms > 2.5 * NOISE)
    # relative error: noise over signal norm, both independent of the library's metrics
    e = val.log.tau - val.tau_hat
    ref = 100 * np.linalg.norm(e) / np.linalg.norm(val.log.tau)
    assert val.errors.relative_error_percent == pytest.approx(ref, rel=1e-12)
    d = val.as_dict()
    assert set(d) >= {"rms", "mse", "relative_error_percent", "without_friction"}
    with pytest.raises(ShapeError, match="friction model has 2 joints"):
        validate_torques(panda, log, friction=ClassicalFriction([0, 0], [0, 0], [0, 0]))


def test_validate_accepts_a_callable_model(panda, sinusoid_log):
    """A callable f(q, dq, ddq) is a model; a wrong output shape is rejected."""
    _, log = sinusoid_log
    from dynid import rnea

    val = validate_torques(lambda q, dq, ddq: rnea(panda, q, dq, ddq), log)
    assert val.with_friction is None and val.errors is val.without_friction
    with pytest.raises(ShapeError, match="model torques must have shape"):
        validate_torques(lambda q, dq, ddq: q[:, :3], log)


def test_friction_json_round_trip(tmp_path, panda):
    """Sigmoid and classical parameters survive write/read; bad files raise DataError."""
    sig = panda.friction
    cls = ClassicalFriction([0.1, 0.2], [0.3, 0.4], [0.0, -0.1])
    for fr in (sig, cls):
        p = save_friction_json(tmp_path / f"{fr.kind}.json", fr)
        back = load_friction_json(p)
        assert type(back) is type(fr)
        np.testing.assert_array_equal(back.as_array(), fr.as_array())
    doc = json.loads((tmp_path / "sigmoid.json").read_text())
    assert doc["model"] == "sigmoid" and set(doc["joints"][0]) == {"phi1", "phi2", "phi3"}
    del doc["joints"][2]["phi2"]
    (tmp_path / "bad.json").write_text(json.dumps(doc))
    with pytest.raises(DataError, match=r"key 'joints\[2\].phi2': missing; expected a number"):
        load_friction_json(tmp_path / "bad.json")
    (tmp_path / "bad2.json").write_text(
        '{"schema": "dynid-friction/1", "model": "stribek", "joints": []}'
    )
    with pytest.raises(DataError, match="key 'model': expected one of"):
        load_friction_json(tmp_path / "bad2.json")


def test_friction_json_of_a_fit_holds_rms(tmp_path):
    """A saved fit carries rms_before and rms_after per joint."""
    rng = np.random.default_rng(24)
    dq = rng.uniform(-1, 1, (500, 2))
    r = 0.2 * dq + 0.1 * np.sign(dq) + rng.normal(0, 0.01, dq.shape)
    fit = fit_classical(dq, r)
    doc = json.loads(save_friction_json(tmp_path / "f.json", fit).read_text())
    assert doc["joints"][1]["rms_after"] == pytest.approx(fit.rms_after[1])
    assert doc["joints"][0]["fv"] == pytest.approx(0.2, abs=0.01)


def _frozen(traj, joint, q_hold):
    """``traj`` with joint ``joint`` (0-based) held at ``q_hold``."""
    from dynid.simulation.trajectories import Trajectory

    q, dq, ddq = traj.q.copy(), traj.dq.copy(), traj.ddq.copy()
    q[:, joint], dq[:, joint], ddq[:, joint] = q_hold, 0.0, 0.0
    return Trajectory(t=traj.t, q=q, dq=dq, ddq=ddq)


@pytest.mark.parametrize("kind", ["sigmoid", "classical"])
def test_a_joint_that_never_moves_gets_no_friction_and_the_others_are_recovered(
    panda, sinusoid_log, kind
):
    """Joint 4 held still (its velocity only noise): a warning names it, its friction is
    zero, and on a held-out log where every joint moves the other joints' fitted friction
    matches the truth (issue 20: phi1 = -9.4e6 N m was fitted from the noise)."""
    from dynid.exceptions import DynidWarning

    traj, _ = sinusoid_log
    log = simulate_measurement(
        panda, _frozen(traj, 3, -1.5), rng=np.random.default_rng(2001),
        noise=SensorNoise(tau_std=NOISE),
    )  # fmt: skip
    with pytest.warns(DynidWarning, match=r"joint\(s\) \[4\] never move beyond their velocity"):
        fit = fit_friction(panda, log, kind=kind)
    assert fit.identified.tolist() == [True, True, True, False, True, True, True]
    np.testing.assert_array_equal(fit.friction.as_array()[3], 0.0)
    # held out: every joint moves (another noise draw of the sinusoids)
    held = simulate_measurement(
        panda, traj, rng=np.random.default_rng(2002), noise=SensorNoise(tau_std=NOISE)
    )
    truth = panda.friction
    tau_fit, tau_true = fit.friction.torques(held.dq), truth.torques(held.dq)
    np.testing.assert_array_equal(tau_fit[:, 3], 0.0)
    err = np.sqrt(np.mean((tau_fit - tau_true) ** 2, axis=0))
    others = [0, 1, 2, 4, 5, 6]
    # the sigmoid is the true law (far below the noise); the classical law is a different
    # curve, so it is held to a fraction of each joint's friction RMS instead
    limit = 0.05 * NOISE if kind == "sigmoid" else 0.3 * np.sqrt(np.mean(tau_true**2, axis=0))
    assert np.all(err[others] < np.broadcast_to(limit, (7,))[others]), err
    # validation with the fitted friction: joint 4 misses only its own friction (< phi1)
    val = validate_torques(panda, held, friction=fit.friction)
    assert val.with_friction.rms[3] < panda.friction.phi1[3], val.with_friction.rms


def test_friction_from_a_log_where_no_joint_moves_is_refused(panda):
    """Every joint at rest (velocities pure noise, or exactly zero without noise): the fit
    raises DataError instead of writing spans of millions of N m (issue 20)."""
    from dynid.simulation.trajectories import Trajectory

    t = sample_times(4.0, 1000.0)
    q0 = centered_start(panda)
    rest = Trajectory(t=t, q=np.tile(q0, (t.size, 1)), dq=np.zeros((t.size, 7)),
                      ddq=np.zeros((t.size, 7)))  # fmt: skip
    for noise in (SensorNoise(tau_std=NOISE), SensorNoise.none()):
        log = simulate_measurement(panda, rest, rng=np.random.default_rng(2003), noise=noise)
        for kind in ("sigmoid", "classical"):
            with pytest.raises(DataError, match="no joint moves beyond its velocity noise band"):
                fit_friction(panda, log, kind=kind)


def test_velocity_noise_estimate_matches_the_simulated_noise(panda, sinusoid_log):
    """The robust noise estimate of the measured velocities is the simulated std (1e-3
    rad/s) within 3 % on 20 000 samples, on moving and on still joints alike, and
    moving_joints tells the two apart."""
    from dynid.friction.fit import moving_joints, velocity_noise_std

    traj, _ = sinusoid_log
    sd = np.linspace(5e-4, 2e-3, 7)
    log = simulate_measurement(
        panda, _frozen(traj, 1, 0.0), rng=np.random.default_rng(2004),
        noise=SensorNoise(tau_std=NOISE, dq_std=tuple(sd)),
    )  # fmt: skip
    np.testing.assert_allclose(velocity_noise_std(log.dq), sd, rtol=0.03)
    assert moving_joints(log.dq).tolist() == [True, False, True, True, True, True, True]
    with pytest.raises(ShapeError, match="noise_std must have shape"):
        moving_joints(log.dq, np.ones(3))


def test_validation_warns_when_the_log_s_torque_sign_is_opposite_to_the_model_s(
    panda, sinusoid_log
):
    """The same log with its torques negated (another recorder's convention) is about 200 %
    off: validate_torques says why, and says nothing on the log as recorded."""
    import dataclasses
    import warnings

    from dynid.exceptions import DynidWarning

    _, log = sinusoid_log
    with warnings.catch_warnings():
        warnings.simplefilter("error", DynidWarning)
        validate_torques(panda, log)
    flipped = dataclasses.replace(log, tau=-log.tau)
    with pytest.warns(DynidWarning, match="torque sign is probably opposite"):
        v = validate_torques(panda, flipped)
    assert v.without_friction.relative_error_percent > 150
