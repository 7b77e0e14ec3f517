"""CSV exports of a JointState topic (``rostopic echo -p``, PlotJuggler) to torque logs.

Reference: a torque log written as such an export, joints in a shuffled order per row,
with a gripper joint, other topics, epoch stamps to the nanosecond; the import must give
the log back (times to 1e-9 s, values exactly) and count the rows it dropped.
"""

from __future__ import annotations

import numpy as np
import pytest

import dynid
from dynid.cli.__main__ import main
from dynid.exceptions import DataError
from dynid.identification.log import TorqueLog
from dynid.io.joint_state_csv import joint_state_layout, load_joint_state_csv
from dynid.io.torque_log import load_torque_log

T0_NS = 1_700_000_000_123_456_789  # an epoch stamp: float64 seconds would lose the ns
NAMES = [f"panda_joint{j}" for j in range(1, 8)]


def _log(N=400, seed=3):
    rng = np.random.default_rng(seed)
    t = np.arange(N) * 1e-3
    return TorqueLog(t, *(rng.normal(size=(N, 7)) for _ in range(3)))


def _stamp(log, k):
    return T0_NS + int(round(log.t[k] * 1e9))


def _rostopic(path, log, *, seed=0, fields=("position", "velocity", "effort")):
    """``rostopic echo -p`` rows of ``log``: 8 joints (a finger) in a random order each."""
    rng = np.random.default_rng(seed)
    names = NAMES + ["panda_finger_joint1"]
    head = ["%time", "field.header.seq", "field.header.stamp", "field.header.frame_id"]
    head += [f"field.name{i}" for i in range(8)]
    head += [f"field.{f}{i}" for f in fields for i in range(8)]
    lines = [",".join(head)]
    sig = {"position": log.q, "velocity": log.dq, "effort": log.tau}
    for k in range(log.n_samples):
        p = rng.permutation(8)
        row = [str(_stamp(log, k) + 20_000), str(k), str(_stamp(log, k)), ""]
        row += [names[i] for i in p]
        for f in fields:
            v = np.append(sig[f][k], 0.04)  # the finger
            row += [repr(float(v[i])) for i in p]
        lines.append(",".join(row))
    path.write_text("\n".join(lines) + "\n")
    return lines


def test_rostopic_export_imports_to_the_log_joints_by_name(tmp_path):
    """Names shuffled per row, a finger joint: t to 1e-9 s, q, dq, tau exactly."""
    log = _log()
    _rostopic(tmp_path / "js.csv", log)
    res = load_joint_state_csv(tmp_path / "js.csv", dynid.panda().joint_names)
    assert res.joints == tuple(NAMES) and res.time_source == "header"
    assert res.t0_ns == T0_NS and res.n_messages == log.n_samples
    np.testing.assert_allclose(res.log.t, log.t, rtol=0, atol=1e-9)
    for k in ("q", "dq", "tau"):
        np.testing.assert_array_equal(getattr(res.log, k), getattr(log, k))
    assert any("panda_finger_joint1" in n and "left out" in n for n in res.notes)


def test_bad_rostopic_rows_are_dropped_and_counted(tmp_path):
    """A NaN row, a row of another width and a repeated stamp: dropped, each counted."""
    log = _log(N=100)
    lines = _rostopic(tmp_path / "js.csv", log)
    cells = lines[11].split(",")
    cells[20] = "nan"  # a position of row 10
    lines[11] = ",".join(cells)
    lines[21] = ",".join(lines[21].split(",")[:-3])  # row 20 lost 3 cells
    lines[31] = lines[30].replace(lines[30].split(",")[1], "x", 1)  # row 30 again
    (tmp_path / "js.csv").write_text("\n".join(lines) + "\n")
    res = load_joint_state_csv(tmp_path / "js.csv", dynid.panda().joint_names)
    assert (res.n_nonfinite, res.n_missing, res.n_duplicate_stamps) == (1, 1, 1)
    keep = np.setdiff1d(np.arange(100), [10, 20, 30])
    np.testing.assert_array_equal(res.log.tau, log.tau[keep])


def _plotjuggler(path, log, *, with_velocity=False, stamps=True):
    """A PlotJuggler export: /joint_states interleaved with a /imu topic on one time axis,
    blank cells where a topic has no sample; no velocities unless asked."""
    fields = ("position", "effort") + (("velocity",) if with_velocity else ())
    cols = [f"/joint_states/{j}/{f}" for j in NAMES for f in fields]
    head = ["__time", "/imu/linear_acceleration/x"] + (
        ["/joint_states/header/stamp"] if stamps else []
    )
    lines = [",".join(head + cols)]
    sig = {"position": log.q, "velocity": log.dq, "effort": log.tau}
    for k in range(log.n_samples):
        ns = _stamp(log, k)
        sec = f"{ns // 10**9}.{ns % 10**9:09d}"
        imu = f"{ns // 10**9}.{(ns + 500_000) % 10**9:09d}"
        lines.append(",".join([imu, "9.81"] + [""] * (len(head) - 2 + len(cols))))
        vals = [repr(float(sig[f][k, j])) for j in range(7) for f in fields]
        lines.append(",".join([sec, ""] + ([sec] if stamps else []) + vals))
    path.write_text("\n".join(lines) + "\n")


def test_plotjuggler_export_skips_other_topics_and_derives_velocities(tmp_path):
    """Rows of another topic are skipped and counted; positions and torques exact; no
    velocity columns: the log's velocities are derived (marked so)."""
    log = _log(N=300)
    _plotjuggler(tmp_path / "pj.csv", log)
    assert joint_state_layout((tmp_path / "pj.csv").read_text().split("\n")[0].split(","))
    res = load_joint_state_csv(tmp_path / "pj.csv", dynid.panda().joint_names)
    assert res.n_other_topics == 300 and res.n_messages == 300 and res.t0_ns == T0_NS
    np.testing.assert_allclose(res.log.t, log.t, rtol=0, atol=1e-9)
    np.testing.assert_array_equal(res.log.q, log.q)
    np.testing.assert_array_equal(res.log.tau, log.tau)
    assert res.velocity_derived and res.log.dq_derived


def test_plotjuggler_without_stamps_uses_its_time_axis(tmp_path):
    """No header/stamp column: __time is the stamp (read to the nanosecond)."""
    log = _log(N=50)
    _plotjuggler(tmp_path / "pj.csv", log, with_velocity=True, stamps=False)
    res = load_joint_state_csv(tmp_path / "pj.csv", dynid.panda().joint_names)
    np.testing.assert_allclose(res.log.t, log.t, rtol=0, atol=1e-9)
    np.testing.assert_array_equal(res.log.dq, log.dq)


def test_export_errors_name_what_to_fix(tmp_path):
    """Another CSV, a missing topic (the topics listed), a word in a number column."""
    robot = dynid.panda()
    (tmp_path / "a.csv").write_text("t,q1\n0,1\n")
    with pytest.raises(DataError, match="not a CSV export of a JointState topic"):
        load_joint_state_csv(tmp_path / "a.csv", robot.joint_names)
    _plotjuggler(tmp_path / "pj.csv", _log(N=10))
    with pytest.raises(DataError, match=r"no JointState topic '/arm'.*\['/joint_states'\]"):
        load_joint_state_csv(tmp_path / "pj.csv", robot.joint_names, topic="/arm")
    lines = _rostopic(tmp_path / "js.csv", _log(N=10))
    lines[3] = lines[3].replace(lines[3].split(",")[12], "oops", 1)
    (tmp_path / "js.csv").write_text("\n".join(lines) + "\n")
    with pytest.raises(DataError, match=r"column 'field.position0': 'oops' is not a number"):
        load_joint_state_csv(tmp_path / "js.csv", robot.joint_names)


def test_cli_import_of_an_export_and_the_hint_of_identify(tmp_path, capsys):
    """`dynid import js.csv` writes the log identify reads; identify given the export
    itself names the import command."""
    log = _log(N=200)
    _rostopic(tmp_path / "js.csv", log)
    out = tmp_path / "log.csv"
    assert main(["import", str(tmp_path / "js.csv"), "--out", str(out)]) == 0
    np.testing.assert_array_equal(load_torque_log(out).tau, log.tau)
    assert "joint1 <- panda_joint1" in capsys.readouterr().out
    argv = ["identify", "--data", str(tmp_path / "js.csv"), "--out", str(tmp_path / "id")]
    assert main(argv) == 2
    err = capsys.readouterr().err
    assert "`dynid import js.csv --robot ROBOT --out log.csv`" in err and err.count("\n") == 1
