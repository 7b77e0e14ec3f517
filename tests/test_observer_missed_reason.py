"""Why a labelled contact was missed (dynid.observer.missed_reason), against a simulated
truth: a Panda held still at one configuration (its torques the gravity torques, closed
by Pinocchio-free RNEA at zero velocity, less the external torque the log's ``tau_ext``
holds), a model with Coulomb friction ``f_c`` and fixed thresholds that add the
standstill margin: the threshold of a joint standing still is its contact level plus
its Coulomb level (closed form). A push below it is missed with that reason and those
numbers; one above it is detected."""

from __future__ import annotations

import json

import numpy as np
import pytest

import dynid
from dynid.cli.__main__ import main
from dynid.friction.model import ClassicalFriction
from dynid.io.friction_json import save_friction_json
from dynid.io.observer_files import load_thresholds, save_thresholds
from dynid.observer.missed_reason import (
    BELOW_AT_REST,
    BELOW_MOVING,
    UNEXPLAINED,
    explained,
)
from dynid.observer.residual import ObserverOptions
from dynid.observer.scoring import MissedContact
from dynid.observer.thresholds import Thresholds

FS = 500.0  # Hz
FC = np.array([1.0, 1.0, 0.8, 0.54, 0.4, 0.3, 0.3])  # N m: joint 4's at-rest margin
CONTACT = 0.3  # N m, every joint: joint 4 at rest 0.3 + 0.54 = 0.84 N m
WEAK, STRONG = (1.0, 1.5, 0.5), (2.5, 3.0, 1.5)  # (start, end [s], torque [N m]) on joint 4


@pytest.fixture(scope="module")
def observed(tmp_path_factory):
    """A 4 s log of the Panda standing still with a weak and a strong push on joint 4,
    observed with friction f_c and the fixed thresholds plus the standstill margin."""
    d = tmp_path_factory.mktemp("missed")
    robot = dynid.panda()
    rng = np.random.default_rng(7)
    t = np.arange(int(4.0 * FS)) / FS
    q0 = (np.asarray(robot.q_min) + np.asarray(robot.q_max)) / 2
    q = np.tile(q0, (t.size, 1))
    dq = np.zeros_like(q)
    g = np.asarray(dynid.gravity_torques(robot, q0))
    ext = np.zeros_like(q)
    for a, b, size in (WEAK, STRONG):
        ext[(t >= a) & (t < b), 3] = size
    tau = g - ext + rng.normal(0.0, 0.01, q.shape)
    rows = np.column_stack([t, q, dq, tau, ext])
    head = ",".join(["t"] + [f"{c}{j}" for c in ("q", "dq", "tau", "tau_ext") for j in range(1, 8)])
    with open(d / "still.csv", "w") as f:
        f.write("# dynid torque log; units: t [s], q [rad], dq [rad/s], tau [N m]\n")
        f.write(f"# rows: {t.size}\n{head}\n")
        np.savetxt(f, rows, delimiter=",", fmt="%.10g")
    flags = (ext[:, 3] != 0).astype(float)  # the same log with a label column alone
    with open(d / "labelled.csv", "w") as f:
        f.write("# dynid torque log; units: t [s], q [rad], dq [rad/s], tau [N m]\n")
        f.write(f"# rows: {t.size}\n{head.split(',tau_ext')[0]},collision\n")
        np.savetxt(f, np.column_stack([rows[:, :22], flags]), delimiter=",", fmt="%.10g")
    save_friction_json(d / "friction.json", ClassicalFriction(np.zeros(7), FC, np.zeros(7)))
    th = Thresholds(
        contact=np.full(7, CONTACT),
        collision=np.full(7, 2 * CONTACT),
        margin=1.5,
        quantile=1.0,
        collision_factor=2.0,
        options=ObserverOptions(),
        samples=1,
        standstill=True,
    )
    save_thresholds(d / "thresholds.json", th, joints=[f"joint{j}" for j in range(1, 8)])
    argv = ["observe", "--params", "panda", "--friction", str(d / "friction.json"),
            "--thresholds", str(d / "thresholds.json"), "--data", str(d / "still.csv"),
            "--no-figures", "--out", str(d / "obs")]  # fmt: skip
    return d, argv


def test_a_push_below_the_at_rest_threshold_is_missed_with_that_reason(observed, capsys):
    """A 0.5 N m push on joint 4 standing still (threshold 0.3 + f_c 0.54 = 0.84 N m) is
    missed, and the summary, events.json and the report say why with those numbers; the
    1.5 N m push is detected."""
    d, argv = observed
    assert main(argv) == 0
    out = capsys.readouterr().out
    assert "2 labelled, 1 detected, 1 missed" in out
    line = next(x for x in out.splitlines() if "missed in" in x)
    assert "1.000 s .. 1.498 s" in line
    assert (
        "joint4 stood still: its true torque 0.5 N m is below its at-rest threshold 0.84 N m"
        in line
    )
    (m,) = json.loads((d / "obs" / "events.json").read_text())["score"]["missed_contacts"]
    assert m["reason"] == BELOW_AT_REST and m["joint"] == 4 and m["joint_name"] == "joint4"
    assert m["torque"] == pytest.approx(WEAK[2], abs=1e-9)
    assert m["threshold"] == pytest.approx(CONTACT + FC[3], abs=1e-9)
    assert m["torque_source"] == "true"
    report = (d / "obs" / "report.html").read_text()
    assert "joint4 stood still: true torque 0.5 N m below its at-rest threshold 0.84" in report


def test_the_push_above_the_at_rest_threshold_is_detected(observed, capsys):
    """The 1.5 N m push on joint 4 (over 0.84 N m) starts an event within 0.1 s of its start."""
    d, argv = observed
    assert main(argv) == 0
    capsys.readouterr()
    doc = json.loads((d / "obs" / "events.json").read_text())
    starts = [e["start"] for e in doc["events"] if 4 in e["joints"]]
    assert any(STRONG[0] - 0.02 <= s <= STRONG[0] + 0.1 for s in starts)
    assert not any(WEAK[0] - 0.02 <= s <= WEAK[1] + 0.1 for s in starts)


@pytest.mark.parametrize(
    ("torque", "still", "reason", "joint", "threshold"),
    [
        ([0.15, 0.5], [False, True], BELOW_AT_REST, 1, 0.84),  # 0.5/0.84 beats 0.15/0.3
        ([0.25, 0.1], [False, True], BELOW_MOVING, 0, 0.3),
        ([0.4, 0.1], [False, False], UNEXPLAINED, 0, 0.3),
    ],
)
def test_the_reason_is_read_on_the_joint_closest_to_its_threshold(
    torque, still, reason, joint, threshold
):
    """The joint with the largest torque over its threshold (at rest where it stood still)
    names the reason: below the at-rest level, below the moving level, or none."""
    m = explained(
        MissedContact(1.0, 1.5), torque, still, [0.84, 0.84], [0.3, 0.3], true_torque=True
    )
    assert (m.reason, m.joint, m.threshold) == (reason, joint, threshold)
    assert m.torque == torque[joint]


def test_with_a_label_column_alone_the_reason_reads_the_residuals_peak(observed, capsys):
    """Without the true torques, the missed push's torque is the residual's peak over its
    label: 0.5 N m within the noise (the observer's lag has settled after 0.1 s of 0.5 s)."""
    d, argv = observed
    argv = [*argv[:-4], str(d / "labelled.csv"), "--no-figures", "--out", str(d / "lab")]
    assert main(argv) == 0
    assert "joint4 stood still: its residual's peak 0.5" in capsys.readouterr().out
    (m,) = json.loads((d / "lab" / "events.json").read_text())["score"]["missed_contacts"]
    assert (m["reason"], m["joint"], m["torque_source"]) == (BELOW_AT_REST, 4, "residual")
    assert m["torque"] == pytest.approx(WEAK[2], abs=0.05)
    assert m["threshold"] == pytest.approx(CONTACT + FC[3], abs=1e-9)


def test_the_moving_level_compared_is_the_calibrations_detectable_when_recorded(observed, capsys):
    """Regression (a UR5's at-rest threshold said 0.833 N m beside thresholds.json's 0.838:
    the fixed contact level stood for the calibration's ``detectable``): with
    ``detectable`` 0.4 N m recorded, joint 4's threshold at rest is 0.4 + 0.54 N m."""
    d, argv = observed
    th = load_thresholds(d / "thresholds.json")
    cal = {"samples": 1, "detectable": [0.4] * 7}
    save_thresholds(d / "recorded.json", th, joints=[f"joint{j}" for j in range(1, 8)],
                    calibration=cal)  # fmt: skip
    assert load_thresholds(d / "recorded.json").detectable.tolist() == [0.4] * 7
    at = argv.index("--thresholds") + 1
    argv = [*argv[:at], str(d / "recorded.json"), *argv[at + 1 : -1], str(d / "rec")]
    assert main(argv) == 0
    capsys.readouterr()
    (m,) = json.loads((d / "rec" / "events.json").read_text())["score"]["missed_contacts"]
    assert (m["reason"], m["joint"]) == (BELOW_AT_REST, 4)
    assert m["threshold"] == pytest.approx(0.4 + FC[3], abs=1e-9)
