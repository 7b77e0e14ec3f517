"""The standstill margin at rest calibrated from the calibration log's rests.

Reference: a simulated Panda with noisy torque and velocity sensors, moving point to point
with rests, whose true friction (classical: viscous and Coulomb, the sign of the true
velocity) is what the model holds, the model's law with a standstill band of 0.01 rad/s.
At the rests the truth holds either no friction (the sign of a zero velocity, as a Z1 in
motor currents did) or static friction the simulation adds: a level drawn anywhere in
``[-f_c, f_c]`` for each rest and joint. A push of known size and time at a rest is the
contact to find; the held-out logs are other motions with other noise and other held
levels.
"""

from __future__ import annotations

import dataclasses
import json
from pathlib import Path

import numpy as np
import pytest

import dynid
from dynid.friction.model import ClassicalFriction
from dynid.observer import from_robot, observe
from dynid.observer.detection import calibrate, detect, standstill_rest_blocks
from dynid.observer.residual import ObserverOptions
from dynid.observer.rest_margin import MIN_REST_S, MIN_RESTS
from dynid.simulation.measurement import SensorNoise, simulate_measurement
from dynid.simulation.trajectories import Trajectory

FV = np.array([0.5, 0.5, 0.4, 0.4, 0.2, 0.2, 0.2])  # N m s/rad
FC = np.array([3.0, 3.0, 2.0, 2.0, 1.0, 1.0, 1.0])  # N m
BAND = 0.01  # rad/s: the model's Coulomb term is off below it
FS = 500.0  # Hz
OPTS = ObserverOptions(gain=50.0)
NOISE = SensorNoise(tau_std=0.05, q_std=1e-5, dq_std=1e-3)


def _moves(seed: int, count: int, rest_s: float = 1.2, move_s: float = 0.8):
    """``count`` quintic moves between random configurations, each followed by a rest
    of ``rest_s``; the trajectory and each sample's rest number (-1 moving)."""
    robot = dynid.panda()
    rng = np.random.default_rng(seed)
    lo, hi = np.asarray(robot.q_min), np.asarray(robot.q_max)
    mid, half = (lo + hi) / 2, 0.3 * (hi - lo) / 2
    s = np.arange(int(move_s * FS)) / FS / move_s
    h = (10 * s**3 - 15 * s**4 + 6 * s**5, (30 * s**2 - 60 * s**3 + 30 * s**4) / move_s,
         (60 * s - 180 * s**2 + 120 * s**3) / move_s**2)  # fmt: skip
    still = int(rest_s * FS)
    q, dq, ddq, which = [], [], [], []
    here = mid.copy()
    for k in range(count):
        d = rng.choice([-1.0, 1.0], 7) * rng.uniform(0.15, 0.5, 7)  # every joint moves
        d = np.where(np.abs(here + d - mid) > half, -d, d)
        there = here + d
        q += [here + np.outer(h[0], d), np.tile(there, (still, 1))]
        dq += [np.outer(h[1], d), np.zeros((still, 7))]
        ddq += [np.outer(h[2], d), np.zeros((still, 7))]
        which += [np.full(s.size, -1), np.full(still, k)]
        here = there
    Q = np.vstack(q)
    traj = Trajectory(np.arange(Q.shape[0]) / FS, Q, np.vstack(dq), np.vstack(ddq))
    return traj, np.concatenate(which)


def _log(seed: int, count: int, held: bool, push: tuple[int, int, float] | None = None):
    """A log of :func:`_moves` whose true friction at rest is ``held`` (a level drawn in
    ``[-f_c, f_c]`` per rest and joint) or none; ``push``: (rest, joint, torque [N m]) a
    step of 0.3 s in the middle of that rest. Returns the log and the push's interval."""
    traj, which = _moves(seed, count)
    rng = np.random.default_rng(seed + 50)
    truth = ClassicalFriction(FV, FC, np.zeros(7))
    log = simulate_measurement(dynid.panda(), traj, rng=rng, noise=NOISE, friction=truth)
    tau = np.array(log.tau)
    if held:
        levels = rng.uniform(-1, 1, (count, 7)) * FC
        tau[which >= 0] += levels[which[which >= 0]]
    span = None
    if push is not None:
        k, j, size = push
        at = np.flatnonzero(which == k)
        a = at[at.size // 2 - int(0.15 * FS)]
        b = a + int(0.3 * FS)
        tau[a:b, j] -= size  # the external torque the residual reads: +size
        span = (log.t[a], log.t[b - 1])
    return log.__class__(t=log.t, q=log.q, dq=log.dq, tau=tau), span


def _model():
    return from_robot(dynid.panda()).with_friction(
        ClassicalFriction(FV, FC, np.zeros(7), np.full(7, BAND))
    )


def _observed(model, log, rest=None):
    """The residual, the standstill margin (with the calibrated ``rest`` levels, or the
    Coulomb bound) and the settled rests of a log."""
    r = np.asarray(observe(model, log.t, log.q, log.dq, log.tau, OPTS).r)
    margin, settled = np.zeros_like(r), np.full_like(r, np.nan)
    t, dq = np.asarray(log.t), np.asarray(log.dq)
    for a, y, s in standstill_rest_blocks(model, t, dq, OPTS, rest=rest):
        if y is not None:
            margin[a : a + y.shape[0]] = y
        settled[a : a + s.shape[0]] = s
    return r, margin, settled


def _calibrated(model, log):
    r, w, s = _observed(model, log)
    return calibrate([r], OPTS, standstill=[w], rest=[s]), calibrate([r], OPTS, standstill=[w])


@pytest.fixture(scope="module")
def free_at_rest():
    """Thresholds calibrated on 14 rests of an arm that holds no friction at rest, with
    its rests read and without (the Coulomb bound)."""
    model = _model()
    cal, _ = _log(1, 14, held=False)
    return (model, *_calibrated(model, cal))


def test_a_push_at_rest_below_the_coulomb_level_is_found_without_false_alarms(free_at_rest):
    """The truth holds nothing at rest: every joint's rest level is calibrated (14 rests)
    well below its Coulomb level, and a 1.2 N m push on joint 4 (f_c 2 N m) at a rest of a
    held-out log is detected, at its time, where the Coulomb bound missed it; a held-out
    collision-free log raises no event with either."""
    model, th, coulomb = free_at_rest
    assert th.rest is not None and coulomb.rest is None
    assert np.all(th.rest.rests == 14) and np.all(th.rest.calibrated)
    assert np.all(th.rest.at_rest(FC) < 0.25 * FC)
    hit, (t0, t1) = _log(2, 12, held=False, push=(5, 3, 1.2))
    r, w, _ = _observed(model, hit, th.rest)
    events = detect(hit.t, r, th, standstill=w)
    assert len(events) == 1 and 4 in events[0].joints
    assert t0 <= events[0].start <= t0 + 0.05 and events[0].end <= t1 + 0.1
    r, w, _ = _observed(model, hit)  # the Coulomb bound at rest: missed
    assert detect(hit.t, r, coulomb, standstill=w) == []
    free, _ = _log(3, 12, held=False)
    r, w, _ = _observed(model, free, th.rest)
    assert detect(free.t, r, th, standstill=w) == []


def test_an_arm_holding_static_friction_at_rest_keeps_about_its_coulomb_margin():
    """The truth holds a level anywhere in [-f_c, f_c] at each rest: the calibrated rest
    margin stays near the Coulomb level (at least 0.8 f_c on every joint), and held-out
    collision-free logs with other held levels raise no event; with no margin at settled
    rests (the level of an arm that holds nothing there) they do."""
    model = _model()
    cal, _ = _log(4, 14, held=True)
    th, _ = _calibrated(model, cal)
    assert th.rest is not None and np.all(th.rest.calibrated)
    assert np.all(th.rest.at_rest(FC) >= 0.8 * FC)
    for seed in (5, 6):
        free, _ = _log(seed, 12, held=True)
        r, w, _ = _observed(model, free, th.rest)
        assert detect(free.t, r, th, standstill=w) == [], seed
    none = dataclasses.replace(th, rest=dataclasses.replace(th.rest, level=np.zeros(7)))
    r, w, _ = _observed(model, free, none.rest)  # no margin at settled rests: false alarms
    assert len(detect(free.t, r, none, standstill=w)) >= 3


def test_few_rests_keep_the_coulomb_bound_and_the_summary_says_so(free_at_rest, tmp_path):
    """Six rests (fewer than MIN_RESTS) of an arm that holds nothing at rest: no joint's
    rest level is calibrated, the margin at rest is the Coulomb level (as without the rests
    read), and the calibration's summary and thresholds.json say why, per joint; the
    fourteen rests' thresholds round-trip through the file and their summary names the
    calibrated levels."""
    from dynid.cli.summaries import format_observation
    from dynid.io.observer_files import load_thresholds, save_observation
    from dynid.observer.detection import undetected_at_rest
    from dynid.observer.results import LogObservation, ObserveResult

    model = _model()
    cal, _ = _log(7, 6, held=False)
    th, coulomb = _calibrated(model, cal)
    assert th.rest is not None and not np.any(th.rest.calibrated)
    assert np.all(th.rest.rests == 6) and MIN_RESTS > 6 and MIN_REST_S <= 1.0
    np.testing.assert_allclose(undetected_at_rest(model, th), FC + th.contact, rtol=1e-12)
    np.testing.assert_allclose(undetected_at_rest(model, coulomb), FC + th.contact, rtol=1e-12)
    names = [f"j{k}" for k in range(1, 8)]
    log = LogObservation(Path("cal.csv"), cal.t, None, None, [], None, None)
    text = format_observation(ObserveResult(model, th, (log,)), names, calibrating=True)
    for j in range(7):
        assert f"  j{j + 1}: Coulomb bound {FC[j]:.3g} N m: too few rests (6 of the 10" in text
    (path,) = save_observation(
        tmp_path, ObserveResult(model, th, (log,)), joints=names, calibrating=True
    )
    rule = json.loads(path.read_text())["rule"]["rest_margin"]
    assert rule["level"] == [None] * 7 and rule["rests"] == [6] * 7
    assert load_thresholds(path).rest.rests.tolist() == [6] * 7

    _, many, _ = free_at_rest
    text = format_observation(ObserveResult(model, many, (log,)), names, calibrating=True)
    (path,) = save_observation(
        tmp_path / "many", ObserveResult(model, many, (log,)), joints=names, calibrating=True
    )
    back = load_thresholds(path)
    np.testing.assert_array_equal(back.rest.level, many.rest.level)
    np.testing.assert_allclose(
        undetected_at_rest(model, back), many.contact + np.minimum(FC, many.rest.level), rtol=1e-12
    )
    level = many.rest.level[3]
    assert f"  j4: {level:.3g} N m calibrated from 14 rests (Coulomb bound 2 N m)" in text


def test_a_thresholds_file_without_rest_levels_keeps_the_coulomb_bound(free_at_rest, tmp_path):
    """A thresholds.json of an earlier version (no rule.rest_margin) reads as before: the
    Coulomb level at every rest."""
    from dynid.io.observer_files import load_thresholds, save_observation
    from dynid.observer.detection import undetected_at_rest
    from dynid.observer.results import LogObservation, ObserveResult

    model, th, _ = free_at_rest
    log = LogObservation(Path("cal.csv"), np.zeros(2), None, None, [], None, None)
    (path,) = save_observation(
        tmp_path, ObserveResult(model, th, (log,)), joints=list("abcdefg"), calibrating=True
    )
    doc = json.loads(path.read_text())
    del doc["rule"]["rest_margin"]
    path.write_text(json.dumps(doc))
    old = load_thresholds(path)
    assert old.rest is None and old.standstill
    np.testing.assert_allclose(undetected_at_rest(model, old), FC + th.contact, rtol=1e-12)


def test_the_settled_rests_and_their_margin_are_the_same_a_block_at_a_time(free_at_rest):
    """The settled part of a rest is read 0.2 s ahead and carried across blocks: blocks of
    997 samples give the whole log's margin (to rounding) and settled seconds exactly; a
    rest is settled from 0.2 s after the joint enters its band (the last of the stop) to
    0.2 s before it leaves it (the first of the next move), never while moving."""
    model, th, _ = free_at_rest
    log, _ = _log(2, 12, held=False)
    t, dq = np.asarray(log.t), np.asarray(log.dq)
    whole = list(standstill_rest_blocks(model, t, dq, OPTS, rest=th.rest))
    parts = list(standstill_rest_blocks(model, t, dq, OPTS, 997, rest=th.rest))
    assert len(whole) == 1 and len(parts) > 10
    margin = np.concatenate([y for _, y, _ in parts])
    settled = np.concatenate([s for _, _, s in parts])
    np.testing.assert_allclose(margin, whole[0][1], rtol=0, atol=1e-12)
    np.testing.assert_array_equal(settled, whole[0][2])
    _, which = _moves(2, 12)
    for k in (0, 5, 10):  # 1.2 s still, inside the band from up to 0.05 s before to after
        inside = np.isfinite(settled[which == k]).mean(axis=0)
        assert np.all((inside >= 0.8 / 1.2) & (inside <= 0.9 / 1.2)), inside
    assert not np.isfinite(settled[which == -1]).any()
    last = np.isfinite(settled[which == 11]).mean(axis=0)  # to the log's end: no move after
    assert np.all(last >= 1.0 / 1.2), last  # settled from 0.2 s in to the end


def test_the_calibration_report_says_the_margin_at_rest_per_joint(free_at_rest, tmp_path):
    """report.html's calibration table gives each joint's margin at rest as the file
    holds it: its calibrated level and the rests read, or the Coulomb level for too few."""
    import re

    from dynid.io.observer_files import save_observation
    from dynid.observer.results import LogObservation, ObserveResult
    from dynid.report import RunSummary, render_html_report

    model, th, _ = free_at_rest
    few = dataclasses.replace(
        th, rest=dataclasses.replace(th.rest, level=np.full(7, np.nan), rests=np.full(7, 3))
    )
    log = LogObservation(Path("cal.csv"), np.zeros(2), None, None, [], None, None)
    for name, got in (("many", th), ("few", few)):
        (path,) = save_observation(
            tmp_path / name, ObserveResult(model, got, (log,)), joints=list("abcdefg"),
            calibrating=True,
        )  # fmt: skip
        page = re.sub(
            r"<[^>]+>", " ", render_html_report(RunSummary(command="observe"), {path.name: path})
        )
        assert "standstill margin at rest" in page
        if name == "many":
            level = th.rest.level[1]
            assert f"min(Coulomb bound, {level:.3g} N m): calibrated from 14 rests" in page
        else:
            assert page.count("Coulomb bound: too few rests (3 of the 10 needed)") == 7


def test_a_smooth_laws_margin_at_rest_is_said_by_the_printout_and_the_report(tmp_path, capsys):
    """Regression (the Panda's sigmoid friction, zero at rest: the printout left out the
    margin at rest on every joint while report.html said "too few rests" on each): both
    say it per joint, the printout with the margin the calibration applied at rest (the
    law's step within the velocity noise band, its "up to" line)."""
    import re
    import warnings

    from dynid.cli.__main__ import main

    sim = ["simulate", "--trajectory", "fourier", "-q", "--duration", "3", "--seed", "2"]
    assert main([*sim, "--out", str(tmp_path / "free.csv")]) == 0
    out = tmp_path / "cal"
    cal = ["observe", "--params", "panda", "--no-figures", "--calibrate", "--no-report"]
    capsys.readouterr()
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        assert main([*cal[:-1], "--data", str(tmp_path / "free.csv"), "--out", str(out)]) == 0
    text = capsys.readouterr().out
    up_to = re.search(r"standstill margin of the friction .*up to ([^)]*) N m\)", text)
    assert up_to is not None, text
    applied = [float(v) for v in up_to.group(1).split(", ")]
    assert len(applied) == 7 and min(applied) > 0  # the law's step within the band
    for j, v in enumerate(applied):
        line = f"  joint{j + 1}: Coulomb bound {v:.3g} N m: too few rests (0 of the 10"
        assert line in text, text
    page = re.sub(r"<[^>]+>", " ", (out / "report.html").read_text())
    assert page.count("Coulomb bound: too few rests (0 of the 10 needed)") == 7
