"""A load's pick is an external-force event, never a silent miss; the quiet-joint rule of
the wrench fit blames only a force whose own torque the residual contradicts.

* a simulated 12 N push straight down at the Panda's flange for 1.5 s on a moving arm
  (physically a 1.22 kg weight to the joint torques): one event of level ``load`` at the
  push's onset, the push detected against the true torques, the note reading it as a
  load "or a steady push along gravity"; with ``--no-loads`` the same push is an
  ordinary event and no load is named;
* the same push against a label column that lacks it: a false alarm, said to be a
  load's pick no labelled contact holds;
* a UR5 (6 joints, Pinocchio's Jacobians): a force at tool0 that loads the wrist less
  than its thresholds is not blamed (before: "does not fit", wrist joints "quiet"); a
  force on the forearm still is.
"""

from __future__ import annotations

import re
import warnings

import numpy as np
import pytest

import dynid
from dynid.cli.__main__ import main
from dynid.observer.detection import ContactEvent
from dynid.observer.unmodelled_load import LOAD_FRAME
from dynid.observer.wrench import external_wrench
from dynid.observer.wrench_fit import (
    force_peaks,
    force_torques,
    off_frame_warning,
    unexplained_shares,
)
from dynid.workflows.observe import ObserveOptions, observe_files

from conftest import robot_data_urdf

PUSH_N, ONSET, END = 12.0, 1.0, 2.5


@pytest.fixture(scope="module")
def logs(tmp_path_factory):
    d = tmp_path_factory.mktemp("push_down")
    sim = ["simulate", "--trajectory", "fourier", "-q", "--duration", "5"]
    assert main([*sim, "--seed", "2", "--out", str(d / "free.csv")]) == 0
    push = f"{LOAD_FRAME}:0,0,{-PUSH_N}:{ONSET},{END}"
    assert main([*sim, "--seed", "3", "--contact", push, "--out", str(d / "push.csv")]) == 0
    cal = ["observe", "--params", "panda", "--no-figures", "-q", "--calibrate"]
    assert main([*cal, "--data", str(d / "free.csv"), "--out", str(d / "cal")]) == 0
    return d


def _detect(d, name, **kw):
    opts = ObserveOptions(
        data=(d / name,), params="panda", thresholds=d / "cal" / "thresholds.json", **kw
    )
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        return observe_files(opts)


def test_a_downward_push_at_the_flange_is_an_external_force_event_at_its_onset(logs):
    """Regression: a push along gravity read as a carried load was dropped from the
    contacts (a labelled push missed); now its pick is an event of level load."""
    result = _detect(logs, "push.csv")
    (log,) = result.logs
    (load,) = log.loads
    assert load.mass == pytest.approx(PUSH_N / 9.81, rel=0.05)
    (pick,) = [e for e in log.events if e.level == "load"]
    assert pick.start == pytest.approx(ONSET, abs=0.03)
    assert pick.end == pytest.approx(END, abs=0.1)
    sc = log.score  # against the simulated true torques
    assert sc is not None and sc.labelled == 1 and sc.detected == 1 and not sc.missed
    assert sc.false_alarms == 0
    (said,) = [x for x in result.notes if "read as a load" in x]
    assert f"{load.mass:.2f} kg at the flange (or a steady push along gravity)" in said
    assert "--no-loads" in said


def test_no_loads_reads_the_push_as_an_ordinary_event(logs):
    """--no-loads: no load named, the push one contact or collision event at its onset."""
    (log,) = _detect(logs, "push.csv", loads=False).logs
    assert log.loads == ()
    (e,) = [e for e in log.events if e.start < END]
    assert e.level in ("contact", "collision") and e.start == pytest.approx(ONSET, abs=0.03)
    assert log.score is not None and log.score.detected == 1


def test_a_load_pick_the_labels_lack_is_a_false_alarm_said_so(logs, capsys):
    """Labels holding one contact at 4.0-4.2 s only (none there): the pick counts as a
    false alarm (an event, not hidden), and the summary says it is a load's pick no
    labelled contact holds."""
    lines = (logs / "push.csv").read_text().splitlines()
    head, rows = lines[:3], lines[3:]
    head[2] += ",collision"
    flag = [int(4.0 <= float(r.split(",")[0]) <= 4.2) for r in rows]
    body = [f"{r},{v}" for r, v in zip(rows, flag, strict=True)]
    (logs / "unlabelled.csv").write_text("\n".join(head + body))
    argv = ["observe", "--params", "panda", "--no-figures"]
    argv += ["--thresholds", str(logs / "cal" / "thresholds.json")]
    argv += ["--data", str(logs / "unlabelled.csv"), "--out", str(logs / "unl")]
    assert main(argv) == 0
    out = capsys.readouterr().out
    assert "1 labelled, 0 detected, 1 missed;" in out
    assert "false alarm in unlabelled.csv: 1.0" in out
    assert "is a load's pick no labelled contact holds" in out


def _ur5_case(contact_frame: str, f: np.ndarray, rng: np.random.Generator):
    """Residuals ``J_v^T f`` (Pinocchio's Jacobian at ``contact_frame``) of a force ``f``
    [N] (base axes) held over 200 samples of a moving UR5, with dynid's UR5."""
    pin = pytest.importorskip("pinocchio")
    urdf = robot_data_urdf("ur_description/urdf/ur5_robot.urdf")
    robot = dynid.Robot.from_urdf(urdf, "base_link", "tool0")
    model = pin.buildModelFromUrdf(urdf)
    data, fid = model.createData(), model.getFrameId(contact_frame)
    q0 = rng.uniform(-1.0, 1.0, 6)
    q = q0 + np.linspace(0.0, 0.4, 200)[:, None] * rng.uniform(-1.0, 1.0, 6)
    r = []
    for qs in q:
        pin.computeJointJacobians(model, data, qs)
        pin.updateFramePlacements(model, data)
        J = pin.getFrameJacobian(model, data, fid, pin.LOCAL_WORLD_ALIGNED)
        r.append(J[:3].T @ f)
    return robot, q, np.array(r)


def _warned(robot, q, r, contact):
    t = np.arange(q.shape[0]) * 1e-3
    peak = tuple(float(x) for x in r[np.argmax(np.abs(r), axis=0), np.arange(6)])
    over = tuple(int(j) + 1 for j in np.flatnonzero(np.max(np.abs(r), axis=0) > contact))
    e = ContactEvent(float(t[0]), float(t[-1]), over, peak, "collision")
    w = external_wrench(robot, q, r, "tool0", kind="force")
    share, noise = unexplained_shares(t, [e], w.unexplained, r, contact, w.determined)
    pushed = force_peaks(t, [e], force_torques(robot, q, w.wrench, "tool0"))
    names, links = robot.joint_names, robot.link_names
    link = int(robot.frame("tool0").link)
    return off_frame_warning("x.csv", "tool0", "force", [e], share, noise, contact,
                             names, links, link, pushed)  # fmt: skip


def test_a_force_at_tool0_that_loads_the_wrist_little_is_not_blamed():
    """Regression (a UR5-like arm): a force at tool0 whose wrist torques stay under the
    wrist's thresholds was warned "does not fit" (wrist joints quiet); its own force part
    puts no more there, so the quiet wrist says nothing against it."""
    robot, q, r = _ur5_case("tool0", np.array([20.0, -10.0, 15.0]), np.random.default_rng(1))
    top = np.max(np.abs(r), axis=0)
    contact = np.where(np.arange(6) < 3, 0.2 * top, 1.5 * top)  # the wrist under its own
    contact = np.maximum(contact, 1e-3)
    assert _warned(robot, q, r, contact) is None


def test_a_force_at_the_forearms_end_is_still_named_at_tool0():
    """A force at the forearm's far end (wrist_1_link's origin, on wrist 1's axis: nothing
    on the wrist joints) with --frame tool0: the force fitted at tool0 loads wrist 1 and 2
    over their thresholds where the residual leaves them quiet: warned, on the forearm."""
    f = np.array([20.0, -10.0, 15.0])
    robot, q, r = _ur5_case("wrist_1_link", f, np.random.default_rng(2))
    said = _warned(robot, q, r, np.full(6, 0.5))
    assert said is not None and "does not fit 1 event(s)" in said
    assert "wrist_1_joint..wrist_2_joint quiet" in said and "so on forearm_link" in said


def test_observe_says_a_logs_jittered_stamps_as_validate_does(logs, capsys):
    """Regression: observe said nothing of stamps jittered by 0.2 ms (std, simulated)
    where identify, validate, friction and payload give the recording's line."""
    sim = ["simulate", "--trajectory", "fourier", "-q", "--duration", "2", "--seed", "4"]
    out = logs / "jitter.csv"
    assert main([*sim, "--jitter", "0.0002", "--out", str(out)]) == 0
    argv = ["observe", "--params", "panda", "--no-figures", "--data", str(out)]
    argv += ["--thresholds", str(logs / "cal" / "thresholds.json"), "--out", str(logs / "j")]
    assert main(argv) == 0
    err = capsys.readouterr().err
    (line,) = [x for x in err.splitlines() if "stamps jittered" in x]
    assert "note: jitter.csv: 1 piece, 2001 samples" in line and "at a 1 ms period" in line
    std = float(re.search(r"std ([0-9.]+) ms", line).group(1))
    assert std == pytest.approx(0.2, rel=0.1)  # the sample std of 2000 draws


def test_residuals_csv_says_over_which_span_a_loads_torque_was_taken(logs):
    """Regression: residuals.csv did not say that its residual lacks a carried load's
    torque, nor over which span: its first line now gives the load and its pick and
    release, within 20 ms of the simulated push's 1.0 s and 2.5 s; the table still
    starts on its fourth line."""
    argv = ["observe", "--params", "panda", "--no-figures", "-q"]
    argv += ["--thresholds", str(logs / "cal" / "thresholds.json")]
    assert main([*argv, "--data", str(logs / "push.csv"), "--out", str(logs / "res")]) == 0
    first = (logs / "res" / "residuals.csv").read_text().splitlines()[0]
    said = re.search(
        r"carried at the flange .*: ([0-9.]+) kg from ([0-9.]+) s to ([0-9.]+) s", first
    )
    assert said is not None, first
    mass, picked, released = (float(x) for x in said.groups())
    assert mass == pytest.approx(PUSH_N / 9.81, rel=0.05)
    assert picked == pytest.approx(ONSET, abs=0.02) and released == pytest.approx(END, abs=0.02)
    table = np.loadtxt(logs / "res" / "residuals.csv", delimiter=",", skiprows=3)
    assert table.shape == (5001, 8)


def test_no_loads_is_refused_when_calibrating(logs, capsys):
    """--no-loads applies to detection only: a calibration refuses it, named by its flag."""
    argv = ["observe", "--params", "panda", "--calibrate", "--no-loads"]
    assert main([*argv, "--data", str(logs / "free.csv"), "--out", str(logs / "c2")]) == 2
    assert "--no-loads applies when detecting" in capsys.readouterr().err
