"""A verdict says when the error above the noise sits at low speed (standstill, reversals,
the edges of a move), where the velocities' noise and low-pass blur a friction step: the
true arm and law on point-to-point motion were judged at 8 times the noise with "effects
outside the model remain", and the user went after terms the model already had."""

from __future__ import annotations

import numpy as np

from dynid.friction.model import ClassicalFriction
from dynid.identification.low_speed import LOW_SPEED_SHARE, low_speed_hint, with_low_speed_hint
from dynid.identification.verdict import judge_prediction
from dynid.io.torque_log import save_torque_log
from dynid.simulation.measurement import SensorNoise, simulate_measurement
from dynid.workflows.validate import ValidateOptions, validate_files

from conftest import point_to_point

NAMES = ("a", "b")


def _moves(rng: np.random.Generator) -> tuple[np.ndarray, np.ndarray]:
    """Velocities [rad/s] of moves and rests (2000, 2), and a noise of 0.05 N m."""
    t = np.arange(2000) / 500.0
    dq = np.column_stack([np.sin(2 * np.pi * 0.5 * t), np.cos(2 * np.pi * 0.25 * t)])
    dq[np.sin(2 * np.pi * 0.2 * t) > 0.6] = 0.0  # rests
    return dq, 0.05 * rng.standard_normal(dq.shape)


def test_an_error_at_the_friction_step_is_placed_at_low_speed():
    """Noise everywhere and a 2 N m step error on joint ``a`` where its velocity is under
    5 % of its RMS: all of the excess is at low speed, on joint ``a``, the rest at the
    noise."""
    rng = np.random.default_rng(0)
    dq, e = _moves(rng)
    slow = np.abs(dq[:, 0]) < LOW_SPEED_SHARE * np.sqrt(np.mean(dq[:, 0] ** 2))
    edge = slow & (np.abs(dq[:, 0]) > 0)  # near zero, not at rest
    e[edge, 0] += 2.0
    hint = low_speed_hint([dq[:1000], dq[1000:]], [e[:1000], e[1000:]], np.full(2, 0.05), NAMES)
    assert hint is not None
    assert hint.startswith("at low speed: 100 % of the error above the noise sits where")
    assert "on joint(s) a, the moving samples at" in hint
    moving = float(hint.split("the moving samples at ")[1].split(" x")[0])
    assert 0.9 < moving < 1.1, hint


def test_a_missing_viscous_term_is_not_placed_at_low_speed():
    """An error proportional to the velocity (a missing viscous term) sits where the joint
    moves fast: no hint, and the verdict is left as it was."""
    rng = np.random.default_rng(1)
    dq, e = _moves(rng)
    e += 1.0 * dq
    assert low_speed_hint([dq], [e], np.full(2, 0.05), NAMES) is None
    v = judge_prediction(20.0, 1.0)
    assert with_low_speed_hint(v, [dq], [e], np.full(2, 0.05), NAMES) is v


def test_an_error_also_while_moving_gets_no_hint():
    """Most of the excess at low speed but the moving samples at 10 times the noise (a
    Coulomb law half the true one: the step missed everywhere): the model misses more
    than the step's place, and the note, which would say friction near zero velocity, is
    not given."""
    rng = np.random.default_rng(3)
    dq, e = _moves(rng)
    slow = np.abs(dq[:, 0]) < LOW_SPEED_SHARE * np.sqrt(np.mean(dq[:, 0] ** 2))
    e[slow & (dq[:, 0] != 0), 0] += 5.0
    e[~slow, 0] += 0.5 * np.sign(dq[~slow, 0])
    assert low_speed_hint([dq], [e], np.full(2, 0.05), NAMES) is None


def test_a_model_at_the_noise_gets_no_hint():
    """A verdict at the noise floor is not touched, whatever the error's place."""
    rng = np.random.default_rng(2)
    dq, e = _moves(rng)
    v = judge_prediction(1.0, 1.0)
    assert v.level == "good"
    assert with_low_speed_hint(v, [dq], [e + 5.0 * (dq == 0)], np.full(2, 0.05), NAMES) is v


def test_validate_says_the_true_law_errs_only_at_the_standstill_edges(panda, tmp_path):
    """The Panda's true parameters and sharp Coulomb friction (1-3 N m), point-to-point
    moves with rests, velocities with 2e-3 rad/s of noise: ``validate`` with the true law
    banded at 5 times that noise judges it at the noise floor (was 8 x a floor of the
    torques' noise alone), the floor counting the velocities' noise through the friction
    step; judged against the torques' noise alone it is above it, and nearly all of the
    excess sits at low speed, the moving samples within 1.5 times the noise."""
    fr = ClassicalFriction(
        np.linspace(0.6, 0.2, 7), np.linspace(3.0, 1.0, 7), np.zeros(7), band=np.full(7, 0.01)
    )
    log = simulate_measurement(
        panda,
        point_to_point(panda, 5),
        rng=np.random.default_rng(105),
        noise=SensorNoise(dq_std=2e-3),
        friction=fr,
    )
    path = save_torque_log(tmp_path / "p2p.csv", log)
    res = validate_files(panda, path, ValidateOptions(friction=fr))
    assert res.verdict.level == "good", res.verdict.reason
    assert "that of the states through the model" in res.verdict.reason
    val = res.validation
    errors = [v.log.tau - v.tau_hat for v in val.parts]
    tau = np.concatenate([v.log.tau for v in val.parts])
    floor = 100 * np.sqrt(len(tau) * np.sum(res.sensor_noise_rms**2)) / np.linalg.norm(tau)
    sensor = judge_prediction(val.errors.relative_error_percent, floor)
    verdict = with_low_speed_hint(
        sensor, [v.log.dq for v in val.parts], errors, res.sensor_noise_rms, panda.joint_names
    )
    reason = verdict.reason
    assert verdict.level != "good", reason
    assert "at low speed: " in reason, reason
    share = float(reason.split("at low speed: ")[1].split(" %")[0])
    assert share >= 90, reason
    moving = float(reason.split("the moving samples at ")[1].split(" x")[0])
    assert moving < 1.5, reason
