"""The standstill margin: a friction law with a standstill band on an arm whose true
Coulomb friction switches at every reversal raises no contact on collision-free logs with
slow reversals, and a push is still found within the delay bound of a step contact."""

from __future__ import annotations

import numpy as np
import pytest

import dynid
from dynid.friction.laws import LAWS
from dynid.friction.model import ClassicalFriction, LawFriction
from dynid.observer import from_robot, observe
from dynid.observer.detection import calibrate, detect, standstill_series
from dynid.observer.friction import standstill_margin
from dynid.observer.residual import ObserverOptions, first_order_lag
from dynid.simulation.measurement import SensorNoise, simulate_measurement
from dynid.simulation.trajectories import random_fourier, uniform_times

FV = np.array([0.5, 0.5, 0.4, 0.4, 0.2, 0.2, 0.2])
FC = np.array([3.0, 3.0, 2.0, 2.0, 1.0, 1.0, 1.0])
BAND = 0.01  # rad/s: the identified law's Coulomb term is off below it
K = 50.0


def _log(seed: float, duration: float = 10.0):
    """A slow collision-free motion (reversals at a few rad/s^2 at most), true Coulomb
    friction without a band, torque noise 0.05 N m."""
    robot = dynid.panda()
    rng = np.random.default_rng(seed)
    traj = random_fourier(robot, rng, n_harmonics=3, w_f=2 * np.pi * 0.1)(
        uniform_times(duration, 1000.0)
    )
    truth = ClassicalFriction(FV, FC, np.zeros(7))
    return simulate_measurement(robot, traj, rng=rng, noise=SensorNoise(), friction=truth)


@pytest.fixture(scope="module")
def case():
    model = from_robot(dynid.panda()).with_friction(
        ClassicalFriction(FV, FC, np.zeros(7), np.full(7, BAND))
    )
    opts = ObserverOptions(gain=K)
    cal, free = _log(1), _log(2)
    return model, opts, cal, free


def _residual(model, opts, log, tau=None):
    return np.asarray(observe(model, log.t, log.q, log.dq, log.tau if tau is None else tau, opts).r)


def test_the_margin_is_the_coulomb_level_inside_the_band_and_the_tanh_gap_outside():
    """Inside the band the whole Coulomb level (plus the Stribeck bump the band turns off);
    a smooth law's fc (1 - tanh(|v| / v_s)); nothing for a plain sign law."""
    dq = np.array([[0.0, 0.005, -0.02, 0.3]])
    band = ClassicalFriction(np.ones(4), np.full(4, 2.0), np.zeros(4), np.full(4, 0.01))
    assert standstill_margin(band, dq) == pytest.approx(np.array([[2.0, 2.0, 0.0, 0.0]]))
    smooth = LawFriction(LAWS["smooth"], np.tile([1.0, 2.0, 0.0], (4, 1)), np.full(4, 0.01))
    expected = 2.0 * (1.0 - np.tanh(np.abs(dq) / 0.01))
    assert standstill_margin(smooth, dq) == pytest.approx(expected, abs=1e-15)
    P = np.tile([1.0, 2.0, 3.0, 0.1, 0.0], (4, 1))  # fv, fc, fs, vst, fo
    stribeck = LawFriction(LAWS["stribeck"], P, np.full(4, 0.01))
    assert standstill_margin(stribeck, dq) == pytest.approx(np.array([[3.0, 3.0, 0.0, 0.0]]))
    sign = ClassicalFriction(np.ones(4), np.full(4, 2.0), np.zeros(4))
    assert not np.any(standstill_margin(sign, dq + 1e-4))


def test_no_event_at_slow_reversals_and_a_push_within_the_delay_bound(case):
    """Without the margin the reversals of a free log raise contacts (the defect); with
    it none, and a 6 N m step on joint 4 crosses the threshold within the delay of a step
    contact, ln(A / (A - theta -+ e)) / K_O (e the free residual's size there) plus a
    sample."""
    model, opts, cal, free = case
    r_cal, r_free = _residual(model, opts, cal), _residual(model, opts, free)
    plain = calibrate([r_cal], opts)
    assert len(detect(free.t, r_free, plain)) >= 1  # slow reversals taken for contacts
    w_cal = standstill_series(model, cal.t, cal.dq, opts)
    w_free = standstill_series(model, free.t, free.dq, opts)
    th = calibrate([r_cal], opts, standstill=[w_cal])
    assert th.standstill and np.all(th.contact <= plain.contact)
    assert detect(free.t, r_free, th, standstill=w_free) == []
    # the margin is the band's Coulomb level through the lag, and bounds what it explains
    lag = first_order_lag(free.t, FC * (np.abs(free.dq) <= BAND), K)
    assert w_free == pytest.approx(lag, abs=1e-12)

    j, A, t0 = 3, 6.0, 5.0
    quiet = w_free[:, j] < 1e-6
    k0 = int(np.flatnonzero((free.t >= t0) & quiet)[0])  # a push away from a reversal
    ext = np.zeros_like(free.tau)
    ext[k0:, j] = A
    r = _residual(model, opts, free, free.tau - ext)
    events = detect(free.t, r, th, standstill=w_free)
    assert len(events) == 1 and j + 1 in events[0].joints
    theta = th.contact[j]
    e = np.abs(r_free[k0 : k0 + 200, j]).max()
    delay = events[0].start - free.t[k0]
    low, high = (np.log(A / (A - theta + s * e)) / K for s in (1, -1))
    assert low - 1e-3 <= delay <= high + 1e-3


def test_the_lag_is_the_closed_form_step_response_at_any_sample_times():
    """A step of A (rectangle rule: held over each step at its new value) from sample k0
    on: A (1 - exp(-K (t - t_{k0-1}))) per joint gain, on jittered sample times."""
    rng = np.random.default_rng(4)
    t = np.cumsum(rng.uniform(0.5e-3, 1.5e-3, 3000))
    x = np.zeros((3000, 2))
    x[1000:] = [2.0, -3.0]
    gains = np.array([20.0, 60.0])
    y = first_order_lag(t, x, gains, "rectangle")
    expected = np.zeros_like(x)
    expected[1000:] = [2.0, -3.0] * -np.expm1(-gains * (t[1000:, None] - t[999]))
    np.testing.assert_allclose(y, expected, rtol=0, atol=1e-12)


def test_calibrating_on_a_log_at_rest_is_refused_naming_the_joints(case):
    """At rest every sample is inside the band: the margin covers the whole residual and
    the thresholds would be 0 N m (a moving free log then flags everything). Refused, the
    joints named; a log moving every joint calibrates."""
    from dynid.exceptions import DataError
    from dynid.simulation.trajectories import Trajectory

    model, opts, cal, _ = case
    t = uniform_times(2.0, 1000.0)
    q = np.tile(cal.q[0], (t.shape[0], 1))
    rest = Trajectory(t, q, np.zeros_like(q), np.zeros_like(q))
    log = simulate_measurement(dynid.panda(), rest, rng=np.random.default_rng(5))
    r = _residual(model, opts, log)
    w = standstill_series(model, log.t, log.dq, opts)
    with pytest.raises(DataError, match=r"joint\(s\) 1, 2, 3, 4, 5, 6, 7: .*moves every joint"):
        calibrate([r], opts, standstill=[w])
    assert calibrate([r], opts).contact.min() > 0  # without the margin: the noise's level
    # a joint at rest beside moving ones is named alone
    r_cal = _residual(model, opts, cal)
    w_cal = np.array(standstill_series(model, cal.t, cal.dq, opts))
    w_cal[:, 4] = np.abs(r_cal[:, 4]) + 1.0  # joint 5 covered everywhere
    with pytest.raises(DataError, match=r"joint\(s\) 5: only 0 of"):
        calibrate([r_cal], opts, standstill=[w_cal])


def test_the_calibration_summary_prints_the_residual_the_rule_read_and_the_level_at_rest(case):
    """The table's residual is the one the rule used, max (|r| - margin)^+ (so contact =
    margin x it), not the raw max |r|; the level below which a contact at rest goes
    undetected is the Coulomb level plus the contact threshold."""
    from pathlib import Path

    from dynid.cli.summaries import format_observation
    from dynid.observer.detection import undetected_at_rest
    from dynid.observer.results import LogObservation, ObserveResult

    model, opts, cal, _ = case
    r = _residual(model, opts, cal)
    w = standstill_series(model, cal.t, cal.dq, opts)
    th = calibrate([r], opts, standstill=[w])
    np.testing.assert_allclose(undetected_at_rest(model, th), FC + th.contact, rtol=1e-12)
    log = LogObservation(Path("cal.csv"), cal.t, r, None, [], None, None, w)
    text = format_observation(
        ObserveResult(model, th, (log,)), [f"j{k}" for k in range(1, 8)], calibrating=True
    )
    head, *rows = text.splitlines()[:8]
    assert head.split()[1:5] == ["|r|", "read", "past", "margin"] and "at rest [N m]" in head
    read = np.max(np.clip(np.abs(r) - w, 0.0, None), axis=0)
    raw = np.max(np.abs(r), axis=0)
    assert np.any(raw - read > 1e-3)  # the margin left samples out: the two differ
    printed = np.array([[float(v) for v in row.split()[1:]] for row in rows])
    np.testing.assert_allclose(printed[:, 0], read, atol=6e-5)
    np.testing.assert_allclose(printed[:, 3], FC + 1.5 * read, atol=6e-5)
    assert "contact = 1.5 x the largest |r| of the calibration after the standstill margin" in text


def test_the_calibration_report_gives_the_thresholds_at_rest_beside_the_moving_ones(case, tmp_path):
    """The report's headline gave only the thresholds in motion (0.12-0.49 N m on an
    xArm7), not those of a joint standing still (2.2-3.5 N m): thresholds.json records
    them (the Coulomb level plus the contact threshold) and the headline names both."""
    import json
    import re
    from pathlib import Path

    from dynid.io.observer_files import load_thresholds, save_observation
    from dynid.observer.results import LogObservation, ObserveResult
    from dynid.report import RunSummary, render_html_report

    model, opts, cal, _ = case
    r = _residual(model, opts, cal)
    w = standstill_series(model, cal.t, cal.dq, opts)
    th = calibrate([r], opts, standstill=[w])
    log = LogObservation(Path("cal.csv"), cal.t, r, None, [], None, None, w)
    names = [f"j{k}" for k in range(1, 8)]
    (path,) = save_observation(
        tmp_path, ObserveResult(model, th, (log,)), joints=names, calibrating=True
    )
    rest = np.array(json.loads(path.read_text())["calibration"]["at_rest"])
    np.testing.assert_allclose(rest, FC + th.contact, rtol=1e-12)
    np.testing.assert_array_equal(load_thresholds(path).contact, th.contact)  # still read
    page = render_html_report(RunSummary(command="observe"), {path.name: path})
    box = re.search(r'<section class="verdict \w+" id="verdict">(.*?)</section>', page, re.S)
    text = re.sub(r"<[^>]+>", "", box[1])
    moving = f"above {th.contact.min():.3g} to {th.contact.max():.3g} N m is detected while a joint"
    assert moving in text, text
    assert f"above {rest.min():.3g} to {rest.max():.3g} N m on a joint at rest" in text, text


def test_the_margin_of_a_coupled_drive_is_taken_at_the_motors():
    """Friction at the motors of a coupled drive (K = [[100, 0], [50, 50]], motor 2 turns
    with both joints): each motor's Coulomb level where its own velocity K dq is inside
    its band, brought to the joints by |K|^T (hand-computed)."""
    from dynid.model.drive import Drive

    K2 = np.array([[100.0, 0.0], [50.0, 50.0]])
    drive = Drive(K2, np.zeros(2), side="motor", friction_at="motor")
    fr = ClassicalFriction(np.zeros(2), np.array([2.0, 1.0]), np.zeros(2), np.full(2, 0.05)).at(
        drive
    )
    dq = np.array([[0.0, 0.0], [0.001, -0.001], [0.0, 0.01]])  # motors (0, 0), (0.1, 0), (0, 0.5)
    expected = np.array([[250.0, 50.0], [50.0, 50.0], [200.0, 0.0]])
    assert standstill_margin(fr, dq) == pytest.approx(expected, abs=1e-12)


def test_the_margin_of_friction_at_the_motors_and_the_joints_adds_both():
    """A friction sum (``at:both``): the motors' Coulomb levels through ``|K|^T`` where each
    motor's velocity is inside its band, plus the joints' own where each joint's is
    (hand-computed; it was zero)."""
    from dynid.friction.model import FrictionSum
    from dynid.model.drive import Drive

    K2 = np.array([[100.0, 0.0], [50.0, 50.0]])
    drive = Drive(K2, np.zeros(2), side="motor", friction_at="motor")
    z = np.zeros(2)
    motor = ClassicalFriction(z, np.array([2.0, 1.0]), z, np.full(2, 0.05)).at(drive)
    joint = ClassicalFriction(z, np.array([0.0, 0.3]), z, np.full(2, 0.002))
    dq = np.array([[0.0, 0.0], [0.001, -0.001], [0.0, 0.01]])
    # motors as in the coupled test; joint 2's own 0.3 where |dq_2| <= 0.002
    expected = np.array([[250.0, 50.3], [50.0, 50.3], [200.0, 0.0]])
    assert standstill_margin(FrictionSum((motor, joint)), dq) == pytest.approx(expected, abs=1e-12)


def test_a_smooth_law_narrower_than_the_noise_band_is_observed_with_the_band():
    """``fc tanh(dq / w)`` with ``w`` (0.5 mrad/s) inside the velocity noise band (5
    mrad/s), the law identification chooses for motion: the observer evaluates it as the
    classical law with the band (0 inside it, the sign outside), so that a joint at rest
    is bounded by ``fc``, not by the ``2 fc`` a tanh of the noise needs; a wider law is
    evaluated as it is."""
    from dynid.friction.laws import LAWS
    from dynid.observer.friction import banded_if_narrow, standstill_margin

    n = 2
    P = np.array([[0.4, 2.0, 0.1], [0.2, 1.0, -0.05]])  # fv, fc, fo
    band = np.full(n, 5e-3)
    narrow = LAWS["smooth"].model(P, np.full(n, 5e-4))
    seen = banded_if_narrow(narrow, (band,))
    assert seen.kind == "classical"
    v = np.array([[-0.2, 0.3], [0.004, -0.001], [0.006, -0.02]])
    sign = np.where(np.abs(v) > band, np.sign(v), 0.0)
    np.testing.assert_allclose(seen.torques(v), P[:, 0] * v + P[:, 1] * sign + P[:, 2], atol=1e-12)
    at_rest = np.zeros((1, n))
    np.testing.assert_allclose(
        standstill_margin(narrow, at_rest, (band,)), [2 * P[:, 1]], rtol=1e-6
    )
    np.testing.assert_allclose(standstill_margin(seen, at_rest, (band,)), [P[:, 1]], rtol=1e-12)
    wide = LAWS["smooth"].model(P, np.full(n, 5e-2))
    assert banded_if_narrow(wide, (band,)) is wide


def _observed(model, log, name):
    """The residual and the standstill margin of ``log`` as ``dynid observe`` runs it
    (velocity bands estimated on the log, the friction banded where narrower), and the
    friction it was observed with."""
    from pathlib import Path

    from dynid.identification.log import TorqueLog
    from dynid.workflows.observe_logs import observed_blocks, prepared_log

    log = TorqueLog(t=log.t, q=log.q, dq=log.dq, tau=log.tau)
    prep = prepared_log(Path(name), log, model, None)
    blocks = list(observed_blocks(prep, model, ObserverOptions(gain=K), False, True))
    r = np.concatenate([x.r for x in blocks])
    w = np.concatenate([x.margin for x in blocks])
    return log.t, r, w, blocks[0].friction


def test_a_sign_law_without_a_band_on_noisy_velocities_is_observed_with_the_noise_band():
    """Classical friction typed without a standstill band (``fc sign(dq)``) on velocities
    with noise: at every rest the sign of the noise flips the whole Coulomb torque, which
    the calibration read as collision-free residual (thresholds 4-5 times those of the same
    law with its band on a Z1, weak contacts missed). Observed with the velocity noise band
    as its band, the thresholds are within 1.5 times those of the true banded law
    (simulated truth: the same law, band 5 noise stds), and a push on a joint at rest is
    found at its time, with no other event."""
    from dynid.observer.friction import banded_if_narrow, banding_note

    from conftest import point_to_point

    robot = dynid.panda()
    noise = SensorNoise(tau_std=0.05, q_std=1e-5, dq_std=1e-3)
    truth = ClassicalFriction(FV, FC, np.zeros(7))
    sim = [
        simulate_measurement(
            robot,
            point_to_point(robot, seed),
            rng=np.random.default_rng(seed),
            noise=noise,
            friction=truth,
        )  # fmt: skip
        for seed in (11, 12)
    ]
    bare = from_robot(robot).with_friction(truth)
    banded = from_robot(robot).with_friction(
        ClassicalFriction(FV, FC, np.zeros(7), np.full(7, 5 * 1e-3))
    )
    opts = ObserverOptions(gain=K)
    t, r, w, seen = _observed(bare, sim[0], "cal.csv")
    fixed = calibrate([r], opts, standstill=[w])
    assert seen is not truth and np.all(seen.band > 3e-3) and np.all(seen.band < 7e-3)
    _, r0, w0, _ = _observed(banded, sim[0], "cal.csv")
    reference = calibrate([r0], opts, standstill=[w0])
    plain = _residual(bare, opts, sim[0])  # the defect: the sign of the noise as a residual
    defect = calibrate([plain], opts, standstill=[standstill_series(bare, t, sim[0].dq, opts)])
    assert np.max(defect.contact / reference.contact) > 2.0
    ratio = fixed.contact / reference.contact
    assert np.all(ratio < 1.5) and np.all(ratio > 1 / 1.5), ratio
    note = banding_note(truth, [seen])
    assert note is not None and "joint(s) 1, 2, 3, 4, 5, 6, 7" in note
    assert banded_if_narrow(banded.friction, (seen.band,)) is banded.friction  # its own band
    smooth = LAWS["smooth"].model(np.column_stack([FV, FC, np.zeros(7)]), np.full(7, 1e-4))
    assert banding_note(smooth, [banded_if_narrow(smooth, (seen.band,))]) is None  # as meant

    # a push of 5 N m on joint 2 during the fourth rest (7.8-8.8 s of each point-to-point log)
    j, A, (a, b) = 1, 5.0, (8.0, 8.4)
    log = sim[1]
    hit = (log.t >= a) & (log.t < b)
    tau = np.array(log.tau)
    tau[hit, j] -= A
    pushed = type(log)(t=log.t, q=log.q, dq=log.dq, tau=tau)
    t, r, w, _ = _observed(bare, pushed, "hit.csv")
    events = detect(t, r, fixed, standstill=w)
    assert len(events) == 1 and j + 1 in events[0].joints, events
    assert a <= events[0].start <= a + 0.1


@pytest.mark.parametrize("law", ["stribeck", "smooth_stribeck"])
@pytest.mark.parametrize("fs", [3.0, 1.4])
def test_the_margin_at_rest_is_the_largest_static_friction_the_law_holds(law, fs):
    """At rest the margin is fs for a positive Stribeck bump and fc for a negative one
    (closed forms), the largest |friction less viscous and offset| of the law without a
    band over velocities near rest; never fc + |fs - fc|."""
    fc, vst = 2.0, 0.1
    P = np.tile([0.5, fc, fs, vst, 0.3], (2, 1))  # fv, fc, fs, vst, fo
    rest = standstill_margin(LawFriction(LAWS[law], P, np.full(2, 0.01)), np.zeros((1, 2)))[0]
    assert rest == pytest.approx(np.full(2, max(fc, fs)), rel=1e-12)
    v = np.linspace(1e-6, 10 * vst, 20001)[:, None] * np.array([1.0, -1.0])
    sharp = LawFriction(LAWS["stribeck"], P, np.zeros(2))
    held = np.max(np.abs(sharp.torques(v) - 0.5 * v - 0.3), axis=0)
    assert rest == pytest.approx(held, rel=1e-6)
