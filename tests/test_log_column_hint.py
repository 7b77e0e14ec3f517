"""A torque log whose joint signals carry another tool's names (ROS JointState's
``position``, ``velocity``, ``effort``; a vendor's ``torque``) is refused, never read by
guess (an ``effort`` is a motor current on some arms), but the error names the columns
left unused and the ``--columns`` map that reads them; the map it gives is then read back
against the values written."""

from __future__ import annotations

import numpy as np
import pytest

from dynid.exceptions import DataError
from dynid.io.columns import load_mapped_torque_log, parse_column_map
from dynid.io.torque_log import load_torque_log

N = 7


def _write(path, names: dict[str, list[str]], seed: int = 0) -> dict[str, np.ndarray]:
    """A 50-sample log at 100 Hz with the given column names per signal; its arrays."""
    rng = np.random.default_rng(seed)
    arrays = {"t": np.arange(50) / 100.0}
    arrays |= {k: rng.uniform(-1, 1, (50, N)) for k in names}
    header = ["t", *(c for cols in names.values() for c in cols)]
    body = np.column_stack([arrays["t"], *(arrays[k] for k in names)])
    np.savetxt(path, body, delimiter=",", header=",".join(header), comments="", fmt="%.17g")
    return arrays


def _cols(prefix: str, first: int = 1) -> list[str]:
    return [f"{prefix}{j + first}" for j in range(N)]


def test_effort_columns_are_named_with_the_map_that_reads_them(tmp_path):
    """Regression: effort1..effort7 in place of tau1..tau7 gave only "missing column(s)
    ['tau1', ..., 'tau7']"; now the error names the unused columns and --columns
    'tau=effort{i}', which reads the torques written."""
    path = tmp_path / "log.csv"
    arrays = _write(path, {"q": _cols("q"), "dq": _cols("dq"), "tau": _cols("effort")})
    with pytest.raises(DataError) as err:
        load_torque_log(path)
    said = str(err.value)
    assert "missing column(s) tau1..tau7 (n = 7 from q1..q7)" in said, said
    assert "present but unused: effort1..effort7" in said, said
    spec = said.split("--columns '")[1].split("'")[0]
    assert spec == "tau=effort{i}" and "motor currents" in said, said
    log = load_mapped_torque_log(path, parse_column_map(spec)).log
    np.testing.assert_array_equal(log.tau, arrays["tau"])


def test_a_joint_state_header_counted_from_zero_gets_its_whole_map(tmp_path):
    """position_0.., velocity_0.., effort_0..: the header error gives the map of all three
    with {i0}, and it reads the positions, velocities and torques written."""
    path = tmp_path / "js.csv"
    names = {"q": _cols("position_", 0), "dq": _cols("velocity_", 0), "tau": _cols("effort_", 0)}
    arrays = _write(path, names)
    with pytest.raises(DataError, match="header must name columns") as err:
        load_torque_log(path)
    spec = str(err.value).split("--columns '")[1].split("'")[0]
    assert spec == "q=position_{i0},dq=velocity_{i0},tau=effort_{i0}", str(err.value)
    log = load_mapped_torque_log(path, parse_column_map(spec)).log
    for k in ("q", "dq", "tau"):
        np.testing.assert_array_equal(getattr(log, k), arrays[k])


def test_two_candidate_torque_families_are_named_but_none_is_chosen(tmp_path):
    """effort1..7 beside torque1..7: both named as unused, no map offered for either."""
    path = tmp_path / "two.csv"
    _write(path, {"q": _cols("q"), "tau": _cols("effort"), "e": _cols("torque")})
    with pytest.raises(DataError) as err:
        load_torque_log(path)
    said = str(err.value)
    assert "effort1..effort7" in said and "torque1..torque7" in said, said
    assert "--columns '" not in said and "name the columns tau1..tau7" in said, said


def test_a_single_missing_torque_column_is_named_without_a_map(tmp_path):
    """tau7 alone missing: named as before, and no map is offered."""
    path = tmp_path / "six.csv"
    _write(path, {"q": _cols("q"), "tau": _cols("tau")[:6] + ["note"]})
    with pytest.raises(DataError, match=r"missing column\(s\) tau7 ") as err:
        load_torque_log(path)
    assert "present but unused: note" in str(err.value) and "--columns '" not in str(err.value)


def test_a_time_column_of_another_name_is_mapped_with_its_unit(tmp_path):
    """Regression (a header time_ms, pos_1.., vel_1.., effort_1.. gave no --columns hint:
    the hint needed a column named t): the hint maps the time column too, with --units
    t=ms from its name, and that map reads the values written."""
    rng = np.random.default_rng(4)
    t = np.arange(50) * 10.0  # ms
    q, dq, tau = (rng.uniform(-1, 1, (50, N)) for _ in range(3))
    header = ["time_ms", *_cols("pos_"), *_cols("vel_"), *_cols("effort_")]
    path = tmp_path / "log.csv"
    np.savetxt(path, np.column_stack([t, q, dq, tau]), delimiter=",", header=",".join(header),
               comments="", fmt="%.17g")  # fmt: skip
    with pytest.raises(DataError) as err:
        load_torque_log(path)
    said = str(err.value)
    spec = "t=time_ms,q=pos_{i},dq=vel_{i},tau=effort_{i}"
    assert f"hint: --columns '{spec}' --units t=ms reads them" in said, said
    log = load_mapped_torque_log(path, parse_column_map(spec, "t=ms")).log
    np.testing.assert_allclose(log.t, t / 1000.0)
    np.testing.assert_array_equal(log.tau, tau)


def test_a_renamed_torque_column_is_named_in_plain_text_by_the_command(tmp_path, capsys):
    """Regression: tau6 written torque6 was reported as "missing column(s) ['tau6']", a
    Python list; the command's error names tau6 and torque6 as plain text."""
    from dynid.cli.__main__ import main

    path = tmp_path / "log.csv"
    taus = _cols("tau")
    _write(path, {"q": _cols("q"), "dq": _cols("dq"), "tau": taus[:5] + ["torque6", "tau7"]})
    rc = main(["validate", "--robot", "panda", "--data", str(path), "--out", str(tmp_path / "o")])
    err = capsys.readouterr().err.strip().splitlines()
    assert rc == 2 and err[-1].startswith(
        "dynid validate: error: log.csv: missing column(s) tau6 (n = 7 from q1..q7); "
        "present but unused: torque6"
    ), err
    assert "[" not in err[-1] and "'tau6'" not in err[-1]


def test_only_the_time_column_renamed_is_mapped_alone(tmp_path):
    """Regression: a header time, q1.., dq1.., tau1.. gave "hint: ; present but unused:
    q1..q7, ..." (columns it does use); the hint maps the time column alone, and that map
    reads the values written."""
    rng = np.random.default_rng(5)
    t = np.arange(50) / 100.0
    q, dq, tau = (rng.uniform(-1, 1, (50, N)) for _ in range(3))
    header = ["time", *_cols("q"), *_cols("dq"), *_cols("tau")]
    path = tmp_path / "log.csv"
    np.savetxt(path, np.column_stack([t, q, dq, tau]), delimiter=",", header=",".join(header),
               comments="", fmt="%.17g")  # fmt: skip
    with pytest.raises(DataError) as err:
        load_torque_log(path)
    said = str(err.value)
    assert said.endswith("got time, q1, q2, q3, q4, q5, q6, q7 and 14 more; hint: --columns "
                         "'t=time' reads time as the time, or name it t"), said  # fmt: skip
    log = load_mapped_torque_log(path, parse_column_map("t=time")).log
    np.testing.assert_array_equal(log.t, t)
    np.testing.assert_array_equal(log.tau, tau)


def test_names_in_messages_are_plain_unless_plain_text_would_garble_them():
    """Column names are joined as text; one with a comma, a space or a line break is quoted,
    and past eight names the rest are counted."""
    from dynid._checks import names

    assert names(["tau6", "tau7"]) == "tau6, tau7"
    assert names(["a,b", "tau 6", "x\ny"]) == "'a,b', 'tau 6', 'x\\ny'"
    assert names([f"c{k}" for k in range(10)]) == "c0, c1, c2, c3, c4, c5, c6, c7 and 2 more"


def _libfranka(path, seed):
    """A libfranka-style log (time, q0.., dq0.., tau_J0.., tau_J_d0..: measured and desired
    torques, joints from 0); its arrays."""
    rng = np.random.default_rng(seed)
    t = np.arange(50) / 1000.0
    q, dq, tau, tau_d = (rng.uniform(-1, 1, (50, N)) for _ in range(4))
    header = ["time", *_cols("q", 0), *_cols("dq", 0), *_cols("tau_J", 0), *_cols("tau_J_d", 0)]
    np.savetxt(path, np.column_stack([t, q, dq, tau, tau_d]), delimiter=",",
               header=",".join(header), comments="", fmt="%.17g")  # fmt: skip
    return {"t": t, "q": q, "dq": dq, "tau": tau}


def test_a_libfranka_header_gets_the_whole_map_with_the_measured_torques(tmp_path):
    """Regression: time, q0.., dq0.., tau_J0.., tau_J_d0.. gave --columns
    't=time,tau=tau_J{i0}' (q1..q6 are there, so q and dq were taken as named right), and
    the next run failed on q7; the hint maps all four, the measured torques tau_J (not the
    desired tau_J_d), and reads the values written."""
    path = tmp_path / "franka.csv"
    arrays = _libfranka(path, seed=6)
    with pytest.raises(DataError, match="header must name columns") as err:
        load_torque_log(path)
    spec = str(err.value).split("--columns '")[1].split("'")[0]
    assert spec == "t=time,q=q{i0},dq=dq{i0},tau=tau_J{i0}", str(err.value)
    log = load_mapped_torque_log(path, parse_column_map(spec)).log
    for k in ("t", "q", "dq", "tau"):
        np.testing.assert_array_equal(getattr(log, k), arrays[k])


def test_a_map_that_counts_the_joints_from_1_gets_the_map_from_0(tmp_path):
    """Regression: --columns 't=time,tau=tau_J{i0}' on q0..q6 said only "missing column(s)
    q7 for 'q'"; the error now gives the whole map with q and dq counted from 0, which
    reads the values written."""
    path = tmp_path / "franka.csv"
    arrays = _libfranka(path, seed=7)
    with pytest.raises(DataError, match=r"missing column\(s\) q7") as err:
        load_mapped_torque_log(path, parse_column_map("t=time,tau=tau_J{i0}"), n=N)
    said = str(err.value)
    assert "hint: the file numbers the joints from 0: --columns " in said, said
    spec = said.split("--columns '")[1].split("'")[0]
    assert spec == "t=time,q=q{i0},dq=dq{i0},tau=tau_J{i0}", said
    log = load_mapped_torque_log(path, parse_column_map(spec)).log
    for k in ("q", "dq", "tau"):
        np.testing.assert_array_equal(getattr(log, k), arrays[k])
