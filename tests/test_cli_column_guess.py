"""What a new user sees when a torque log's columns carry other names (``time, pos1..pos7,
eff1..eff7``) or hold no torques at all: the error gives one ``--columns`` map, guessed
from the header, that reads the whole file (pasted, the command runs), and a log of
positions only is told that identification needs measured torques."""

from __future__ import annotations

import shlex

import numpy as np
import pytest

from dynid.cli.__main__ import main
from dynid.io.columns import load_mapped_torque_log, parse_column_map

N = 7


def _write(path, header: list[str], seed: int) -> np.ndarray:
    """A 300-row log at 1 kHz of a Panda-like motion with the given header; its body."""
    rng = np.random.default_rng(seed)
    t = np.arange(300) / 1000.0
    q = 0.3 * np.sin(2 * np.pi * t[:, None] * rng.uniform(0.5, 2.0, N))
    cols = [t, *q.T]
    if len(header) > 1 + N:
        cols += list(rng.normal(0.0, 5.0, (300, N)).T)
    body = np.column_stack(cols)
    np.savetxt(path, body, delimiter=",", header=",".join(header), comments="", fmt="%.17g")
    return body


def _error(argv, capsys) -> str:
    assert main(argv) == 2
    (line,) = capsys.readouterr().err.strip().splitlines()
    return line


def _pasted(line: str) -> list[str]:
    """The options of the error's hint, as a shell would split them when pasted."""
    return shlex.split(line.split("hint: ")[-1].split(" reads ")[0])


POS_EFF = ["time", *(f"pos{j}" for j in range(1, N + 1)), *(f"eff{j}" for j in range(1, N + 1))]


@pytest.mark.parametrize(
    "given",
    [[], ["--columns", "q=pos{i},tau=eff{i}"], ["--columns", "t=time"]],
    ids=["no-map", "map-without-time", "map-of-time-only"],
)
def test_the_hint_of_pos_eff_columns_is_a_map_that_reads_the_file(tmp_path, capsys, given):
    """Regression: ``time, pos1..pos7, eff1..eff7`` got an example map naming neither q nor
    t, then "map it with --columns t=NAME"; now every error gives the whole map (the
    user's templates kept), and identify run with it pasted reads the file."""
    path = tmp_path / "rec.csv"
    body = _write(path, POS_EFF, seed=1)
    base = ["identify", "--robot", "panda", "--data", str(path), "--no-figures"]
    line = _error([*base, *given, "--out", str(tmp_path / "o")], capsys)
    pasted = _pasted(line)
    assert pasted[0] == "--columns" and len(pasted) == 2, line
    assert set(pasted[1].split(",")) == {"t=time", "q=pos{i}", "tau=eff{i}"}, line
    if given:
        assert pasted[1].startswith(given[1]), line  # what the user typed comes first
    log = load_mapped_torque_log(path, parse_column_map(pasted[1])).log
    np.testing.assert_array_equal(log.q, body[:, 1 : 1 + N])
    np.testing.assert_array_equal(log.tau, body[:, 1 + N :])
    if not given:  # the same map each time: identify run once with it pasted
        assert main([*base, *pasted, "--out", str(tmp_path / "o"), "-q"]) == 0
        assert (tmp_path / "o" / "identification.json").is_file()


def test_motor_currents_and_a_time_in_ms_are_guessed_with_their_units(tmp_path, capsys):
    """``Time_ms, Angle_1..7, Current_1..7``: the hint maps the currents as tau in A and
    the time in ms, and says that a drive of current effort must go with them."""
    header = [
        "Time_ms",
        *(f"Angle_{j}" for j in range(1, N + 1)),
        *(f"Current_{j}" for j in range(1, N + 1)),
    ]
    path = tmp_path / "rec.csv"
    _write(path, header, seed=2)
    argv = ["identify", "--robot", "panda", "--data", str(path), "--out", str(tmp_path / "o")]
    line = _error(argv, capsys)
    assert "t=Time_ms,q=Angle_{i},tau=Current_{i}" in line, line
    assert "--units 't=ms,tau=A'" in line and "--drive whose effort is current" in line, line


def test_a_servos_present_readings_are_guessed_and_read(tmp_path, capsys):
    """Regression: a serial-bus servo arm's ``timestamp_ms, present_position_1..7,
    present_current_1..7`` got no map (the reading's prefix hid the names); the hint maps
    them and, pasted, reads the file's positions and currents."""
    header = [
        "timestamp_ms",
        *(f"present_position_{j}" for j in range(1, N + 1)),
        *(f"present_current_{j}" for j in range(1, N + 1)),
    ]
    path = tmp_path / "rec.csv"
    body = _write(path, header, seed=3)
    argv = ["identify", "--robot", "panda", "--data", str(path), "--out", str(tmp_path / "o")]
    line = _error(argv, capsys)
    spec = "t=timestamp_ms,q=present_position_{i},tau=present_current_{i}"
    assert spec in line and "--units 't=ms,tau=A'" in line, line
    log = load_mapped_torque_log(path, parse_column_map(spec)).log
    np.testing.assert_array_equal(log.q, body[:, 1 : 1 + N])
    np.testing.assert_array_equal(log.tau, body[:, 1 + N :])


@pytest.mark.parametrize("command", ["identify", "observe"])
def test_a_log_of_positions_only_is_told_that_torques_are_needed(tmp_path, capsys, command):
    """Regression: a 1 kHz log of t, q1..q7 only was told to "name the columns
    tau1..tau7" though nothing could be renamed; now the error says the command needs
    measured joint torques (or motor currents with a drive) and what the file holds."""
    path = tmp_path / "pos.csv"
    _write(path, ["t", *(f"q{j}" for j in range(1, N + 1))], seed=3)
    model = ["--robot", "panda"]
    model = model if command == "identify" else ["--params", "panda", "--calibrate"]
    line = _error([command, *model, "--data", str(path), "--out", str(tmp_path / "o")], capsys)
    assert "missing column(s) tau1..tau7" in line, line
    assert "holds no joint torques, only t, q1..q7" in line, line
    assert "need measured joint torques" in line and "--drive" in line, line
    assert "name the columns" not in line, line


def test_a_log_with_some_other_family_keeps_the_naming_hint(tmp_path, capsys):
    """t, q1..q7, sig1..sig7: sig might be the torques, so the error still says to name or
    map them rather than that the file holds none."""
    path = tmp_path / "x.csv"
    header = ["t", *(f"q{j}" for j in range(1, N + 1)), *(f"sig{j}" for j in range(1, N + 1))]
    _write(path, header, seed=4)
    argv = ["identify", "--robot", "panda", "--data", str(path), "--out", str(tmp_path / "o")]
    line = _error(argv, capsys)
    assert "present but unused: sig1..sig7" in line and "name the columns" in line, line
    assert "holds no joint torques" not in line, line


def test_units_without_columns_get_the_whole_map_with_the_units_given(tmp_path, capsys):
    """Regression (a Kortex trial: ``--units 't=us,q=deg,dq=deg/s,tau=-1'`` without
    ``--columns`` on ``timestamp_us, joint_0_position_deg, ...`` got only "map them with
    --columns"): the hint is the ready-made map with the user's --units kept, and pasted it
    reads the file (positions from degrees, torques negated, times from microseconds)."""
    signals = ("position_deg", "velocity_degps", "torque_Nm")
    header = ["timestamp_us", *(f"joint_{j}_{s}" for s in signals for j in range(N))]
    rng = np.random.default_rng(5)
    t_us = np.arange(300) * 1000.0
    body = np.column_stack([t_us, rng.normal(0.0, 20.0, (300, 3 * N))])
    path = tmp_path / "rec.csv"
    np.savetxt(path, body, delimiter=",", header=",".join(header), comments="", fmt="%.17g")
    units = "t=us,q=deg,dq=deg/s,tau=-1"
    argv = ["identify", "--robot", "panda", "--data", str(path), "--units", units]
    line = _error([*argv, "--out", str(tmp_path / "o")], capsys)
    pasted = _pasted(line)
    assert pasted[0] == "--columns" and pasted[2:] == ["--units", units], line
    log = load_mapped_torque_log(path, parse_column_map(pasted[1], pasted[3])).log
    np.testing.assert_allclose(log.t, t_us * 1e-6, rtol=0, atol=1e-12)
    np.testing.assert_allclose(log.q, np.deg2rad(body[:, 1 : 1 + N]), rtol=1e-15)
    np.testing.assert_allclose(log.dq, np.deg2rad(body[:, 1 + N : 1 + 2 * N]), rtol=1e-15)
    np.testing.assert_array_equal(log.tau, -body[:, 1 + 2 * N :])


def test_the_naming_hint_counts_the_chains_joints_not_the_servos(tmp_path, capsys):
    """Regression (an SO-100 trial: five arm joints, the gripper's servo a sixth column):
    the hint offered "name them q1..q6" for a 5-joint chain; now the chain's joints are
    named (the Panda's 7 beside 8 servo columns), and the map still reads the file."""
    header = [
        "timestamp",
        *(f"present_position_{j}" for j in range(1, N + 2)),
        *(f"present_current_{j}" for j in range(1, N + 2)),
    ]
    rng = np.random.default_rng(6)
    body = np.column_stack([np.arange(300) / 1000.0, rng.normal(0.0, 0.3, (300, 2 * N + 2))])
    path = tmp_path / "rec.csv"
    np.savetxt(path, body, delimiter=",", header=",".join(header), comments="", fmt="%.17g")
    argv = ["identify", "--robot", "panda", "--data", str(path), "--out", str(tmp_path / "o")]
    line = _error(argv, capsys)
    assert line.endswith("or name them q1..q7, tau1..tau7"), line
    assert "t=timestamp,q=present_position_{i},tau=present_current_{i}" in line, line
