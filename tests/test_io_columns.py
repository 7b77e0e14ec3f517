"""Column mapping and unit scaling of torque logs and static data; velocities from positions.

References: the same values written under dynid's names (a renamed, rescaled file must read
back to them), the closed-form derivative of a sinusoid, the error messages documented.
"""

from __future__ import annotations

import logging

import numpy as np
import pytest

import dynid
from dynid.cli.__main__ import main
from dynid.exceptions import DataError
from dynid.identification.log import TorqueLog
from dynid.io.columns import (
    ColumnMap,
    load_column_map,
    load_mapped_static_data,
    load_mapped_torque_log,
    parse_column_map,
)
from dynid.io.model_json import load_model_json
from dynid.io.static_data import save_static_csv


def _log(seed: int, n: int = 3, N: int = 2000) -> TorqueLog:
    rng = np.random.default_rng(seed)
    t = np.arange(N) * 1e-3
    f = rng.uniform(0.2, 1.0, n)
    q = np.sin(2 * np.pi * f * t[:, None])
    return TorqueLog(
        t, q, 2 * np.pi * f * np.cos(2 * np.pi * f * t[:, None]), rng.normal(size=(N, n))
    )


def _write_renamed(path, log: TorqueLog, *, with_dq: bool = True) -> None:
    """A log as another tool writes it: ms, degrees, mN m, 0-based names, extra columns."""
    n = log.n
    cols = {"time_ms": log.t * 1e3, "seq": np.arange(len(log.t))}
    for i in range(n):
        cols[f"position_{i}"] = np.degrees(log.q[:, i])
        if with_dq:
            cols[f"velocity_{i}"] = np.degrees(log.dq[:, i])
        cols[f"effort_{i}"] = log.tau[:, i] * 1e3
    names = list(cols)[::-1]
    data = np.stack([cols[k] for k in names], axis=1)
    np.savetxt(path, data, delimiter=",", header=",".join(names), comments="", fmt="%.17g")


def test_renamed_rescaled_log_reads_as_the_original(tmp_path):
    """position_{i0} [deg], velocity_{i0} [deg/s], effort_{i0} [mN m], time [ms] -> SI log."""
    log = _log(1)
    path = tmp_path / "other.csv"
    _write_renamed(path, log)
    cmap = parse_column_map(
        "t=time_ms,q=position_{i0},dq=velocity_{i0},tau=effort_{i0}",
        "t=ms,q=deg,dq=deg/s,tau=mNm",
    )
    got = load_mapped_torque_log(path, cmap)
    np.testing.assert_allclose(got.log.t, log.t, rtol=1e-15, atol=1e-18)
    for k in ("q", "dq", "tau"):
        np.testing.assert_allclose(getattr(got.log, k), getattr(log, k), rtol=1e-14, atol=1e-15)
    assert not got.conversions and not got.notes  # the units given: the map's one note
    assert cmap.unit_note() == (
        "data read with --units t in ms (x 0.001 to SI), q in deg (x 0.017453292519943295 "
        "to SI), dq in deg/s (x 0.017453292519943295 to SI), tau in mNm (x 0.001 to SI)"
    )


def test_positions_only_gives_filtered_derivative_velocities(tmp_path):
    """No velocity columns: dq from the filtered derivative matches the analytic derivative."""
    log = _log(2, N=10_000)
    path = tmp_path / "pos.csv"
    _write_renamed(path, log, with_dq=False)
    cmap = parse_column_map("t=time_ms,q=position_{i0},tau=effort_{i0}", "t=ms,q=deg,tau=mNm")
    got = load_mapped_torque_log(path, cmap, n=3)
    assert any("velocities derived" in s for s in got.notes)
    inner = slice(1000, -1000)  # 1 s at each end: the filter's transient (1e-4 relative)
    err = np.abs(got.log.dq[inner] - log.dq[inner])
    assert np.max(err) < 1e-4 * np.max(np.abs(log.dq))


def test_npz_arrays_and_toml_map(tmp_path):
    """A TOML map renames NPZ arrays and scales them."""
    log = _log(3)
    np.savez(tmp_path / "log.npz", stamp=log.t, pos=np.degrees(log.q), vel=log.dq, eff=log.tau)
    (tmp_path / "map.toml").write_text(
        '[columns]\nt = "stamp"\nq = "pos"\ndq = "vel"\ntau = "eff"\n[units]\nq = "deg"\n'
    )
    got = load_mapped_torque_log(tmp_path / "log.npz", load_column_map(tmp_path / "map.toml"))
    np.testing.assert_allclose(got.log.q, log.q, rtol=1e-14, atol=1e-15)
    np.testing.assert_array_equal(got.log.tau, log.tau)


def test_column_map_errors_name_what_is_wrong(tmp_path):
    """Unknown quantity, unknown unit, malformed text, missing columns, bad TOML keys."""
    with pytest.raises(DataError, match="unknown quantity 'qq'"):
        parse_column_map("qq=x{i}")
    with pytest.raises(DataError, match="unknown unit 'furlong' for 'q'"):
        parse_column_map(None, "q=furlong")
    with pytest.raises(DataError, match="quantity=value"):
        parse_column_map("q")
    with pytest.raises(DataError, match="finite and non-zero"):
        ColumnMap.from_units({}, {"tau": 0.0})
    path = tmp_path / "other.csv"
    _write_renamed(path, _log(4))
    with pytest.raises(DataError, match=r"no column 'effort1' for 'tau'.*--columns"):
        load_mapped_torque_log(path, parse_column_map("t=time_ms,q=position_{i0},tau=effort{i}"))
    with pytest.raises(DataError, match="no time column 't'"):
        load_mapped_torque_log(path, parse_column_map("q=position_{i0}"))
    (tmp_path / "bad.toml").write_text('[cols]\nq = "x"\n')
    with pytest.raises(DataError, match=r"bad.toml: unknown key\(s\) \['cols'\]"):
        load_column_map(tmp_path / "bad.toml")


def test_static_data_through_a_map(tmp_path):
    """Static data with 0-based names, M by upper triangle, g in mN m, q in degrees."""
    robot = dynid.panda()
    data = dynid.acquire_static(dynid.SimulatedController(robot), 20, np.random.default_rng(5))
    n = robot.n
    cols = {}
    for i in range(n):
        cols[f"joint{i}_deg"] = np.degrees(data.q[:, i])
        cols[f"gravity{i}"] = data.g[:, i] * 1e3
        for j in range(i, n):
            cols[f"inertia_{i}_{j}"] = data.M[:, i, j]
    names = list(cols)
    path = tmp_path / "static_other.csv"
    table = np.stack([cols[k] for k in names], axis=1)
    np.savetxt(path, table, delimiter=",", header=",".join(names), comments="", fmt="%.17g")
    cmap = parse_column_map("q=joint{i0}_deg,M=inertia_{i0}_{j0},g=gravity{i0}", "q=deg,g=mNm")
    got = load_mapped_static_data(path, cmap, robot).data
    np.testing.assert_allclose(got.q, data.q, rtol=1e-14, atol=1e-15)
    np.testing.assert_array_equal(got.M, data.M)
    np.testing.assert_allclose(got.g, data.g, rtol=1e-14, atol=1e-13)


def test_cli_identify_and_friction_accept_a_column_map(tmp_path, capsys):
    """identify on renamed static data equals identify on dynid's columns; notes on stderr."""
    robot = dynid.panda()
    data = dynid.acquire_static(dynid.SimulatedController(robot), 60, np.random.default_rng(6))
    save_static_csv(tmp_path / "static.csv", data)
    text = (tmp_path / "static.csv").read_text().replace("g", "grav").replace("M", "inertia")
    (tmp_path / "renamed.csv").write_text(text)
    assert (
        main(["identify", "--data", str(tmp_path / "static.csv"), "--out", str(tmp_path / "a")])
        == 0
    )
    argv = ["identify", "--data", str(tmp_path / "renamed.csv"), "--out", str(tmp_path / "b")]
    assert main(argv + ["--columns", "M=inertia{i}_{j},g=grav{i}", "--units", "g=1"]) == 0
    a = load_model_json(tmp_path / "a" / "identification.json").fit.beta
    b = load_model_json(tmp_path / "b" / "identification.json").fit.beta
    np.testing.assert_array_equal(a, b)
    capsys.readouterr()
    assert main(argv + ["--columns", "M=nope{i}_{j},g=grav{i}"]) == 2
    assert "nope1_1" in capsys.readouterr().err


def test_mapped_csv_is_read_strictly_and_frugally(tmp_path, monkeypatch):
    """Through a map, a CSV is read by the torque logs' chunked reader: only the mapped
    columns are kept (a text column of another tool and an empty cell outside them are
    ignored), a duplicated column, a recorded row count other than the rows and a word in
    a mapped column are refused with the line, and reading 100,000 rows allocates less
    than twice the arrays (numpy.genfromtxt held a Python object per cell)."""
    import tracemalloc

    from dynid.io import csv_tables

    log = _log(5, N=100_000)
    path = tmp_path / "other.csv"
    _write_renamed(path, log)
    cmap = parse_column_map(
        "t=time_ms,q=position_{i0},dq=velocity_{i0},tau=effort_{i0}",
        "t=ms,q=deg,dq=deg/s,tau=mNm",
    )
    monkeypatch.setattr(csv_tables, "_CHUNK_BYTES", 1 << 20)
    tracemalloc.start()
    got = load_mapped_torque_log(path, cmap)
    peak = tracemalloc.get_traced_memory()[1]
    tracemalloc.stop()
    np.testing.assert_allclose(got.log.t, log.t, rtol=1e-15, atol=1e-18)
    assert peak < 2 * 2 * 10 * 8 * 100_000, peak  # t, q, dq, tau, and their copies in SI
    lines = path.read_text().splitlines()
    lines[0] += ",frame"
    lines[1:] = [s + ",base_link" for s in lines[1:]]
    cells = lines[7].split(",")
    cells[lines[0].split(",").index("seq")] = ""  # an empty cell in an unused column
    lines[7] = ",".join(cells)
    path.write_text("\n".join(lines) + "\n")
    got = load_mapped_torque_log(path, cmap)
    np.testing.assert_allclose(got.log.tau, log.tau, rtol=1e-14, atol=1e-15)
    head = lines[0].split(",")
    dup = tmp_path / "dup.csv"
    dup.write_text(",".join(head[:-1] + ["seq"]) + "\n" + "\n".join(lines[1:4]) + "\n")
    with pytest.raises(DataError, match=r"line 1: duplicate column\(s\) seq$"):
        load_mapped_torque_log(dup, cmap)
    short = tmp_path / "short.csv"
    short.write_text("# rows: 5\n" + "\n".join(lines[:4]) + "\n")
    with pytest.raises(DataError, match="5"):
        load_mapped_torque_log(short, cmap)
    word = tmp_path / "word.csv"
    k = head.index("effort_1")
    bad = lines[3].split(",")
    bad[k] = "high"
    word.write_text("\n".join(lines[:3] + [",".join(bad)] + lines[4:6]) + "\n")
    with pytest.raises(DataError, match=r"line 4, column 'effort_1': not a number"):
        load_mapped_torque_log(word, cmap)


def test_a_log_without_a_row_count_is_read_into_arrays_allocated_once(tmp_path, monkeypatch):
    """A log of another tool (no '# rows:' line, a text column the map does not name) is
    read by numpy's C reader, only the mapped columns, into arrays allocated once: the
    peak is the arrays, one copy of the largest and a chunk of text, not the chunks kept
    and joined (issue 28: 1.85 GB on 5 million rows), and the values equal the file's."""
    import tracemalloc

    from dynid.io import csv_tables

    N, n = 60_000, 3
    rng = np.random.default_rng(71)
    t = np.arange(N) * 1e-3
    q, dq, tau = (rng.normal(size=(N, n)) for _ in range(3))
    names = ["time_s", *(f"{k}_{i}" for k in ("pos", "vel", "eff") for i in range(n)), "status"]
    with open(tmp_path / "other.csv", "w") as fh:
        fh.write(",".join(names) + "\n")
        for r in range(N):
            cells = [t[r], *q[r], *dq[r], *tau[r]]
            fh.write(",".join(repr(float(x)) for x in cells) + ",ok é\n")

    def refuse(*args, **kw):
        raise AssertionError("the slow reader was used")

    monkeypatch.setattr(csv_tables, "_slow_table", refuse)
    monkeypatch.setattr(csv_tables, "_CHUNK_BYTES", 1 << 20)
    cmap = parse_column_map("t=time_s,q=pos_{i0},dq=vel_{i0},tau=eff_{i0}")
    tracemalloc.start()
    got = load_mapped_torque_log(tmp_path / "other.csv", cmap).log
    peak = tracemalloc.get_traced_memory()[1]
    tracemalloc.stop()
    np.testing.assert_array_equal(got.t, t)
    for k, x in (("q", q), ("dq", dq), ("tau", tau)):
        np.testing.assert_array_equal(getattr(got, k), x)
    arrays = 8 * N * (1 + 3 * n)
    assert peak < arrays + 8 * N * n + 3 * (1 << 20) * 3, (peak, arrays)


def test_a_log_in_other_units_is_scaled_in_place_as_it_is_read(tmp_path, monkeypatch):
    """ms, degrees and mN m: each signal scaled to SI in place while read (issue 28: a
    scaled copy of each array beside the one read), one immutable copy at a time; the
    values are the SI ones."""
    import tracemalloc

    log = _log(9, N=60_000)
    path = tmp_path / "other.csv"
    _write_renamed(path, log)
    cmap = parse_column_map(
        "t=time_ms,q=position_{i0},dq=velocity_{i0},tau=effort_{i0}",
        "t=ms,q=deg,dq=deg/s,tau=mNm",
    )
    from dynid.io import csv_tables

    monkeypatch.setattr(csv_tables, "_CHUNK_BYTES", 1 << 18)
    tracemalloc.start()
    got = load_mapped_torque_log(path, cmap).log
    peak = tracemalloc.get_traced_memory()[1]
    tracemalloc.stop()
    np.testing.assert_allclose(got.t, log.t, rtol=1e-15, atol=1e-18)
    for k in ("q", "dq", "tau"):
        np.testing.assert_allclose(getattr(got, k), getattr(log, k), rtol=1e-14, atol=1e-15)
    N, n = 60_000, 3
    arrays, one, stamps = 8 * N * (1 + 3 * n), 8 * N * n, 8 * N
    # the arrays, a copy, a chunk, and a few vectors of the stamps' length (their steps
    # counted against the grid, signals.grid_steps): none of the joints' arrays copied twice
    assert peak < arrays + one + 4 * stamps + (2 << 20), (peak, arrays)


def test_validate_reads_a_log_in_other_units_than_the_models(tmp_path, caplog):
    """A model identified from a log in mN m validates an SI log given --units tau=Nm as it
    validates the mN m log (the model's recorded units were forced onto every later log)."""
    import json

    from dynid.io.torque_log import load_torque_log, save_torque_log

    si = tmp_path / "si.csv"
    argv = ["simulate", "--robot", "panda", "--duration", "6", "--rate", "200", "--seed", "3"]
    assert main(argv + ["--out", str(si), "-q"]) == 0
    log = load_torque_log(si)
    mnm = tmp_path / "mnm.csv"
    save_torque_log(mnm, TorqueLog(log.t, log.q, log.dq, log.tau * 1e3))
    ident = ["identify", "--data", str(mnm), "--units", "tau=mNm", "--terms", "viscous,coulomb"]
    assert main(ident + ["--no-figures", "--out", str(tmp_path / "id"), "-q"]) == 0
    model = str(tmp_path / "id" / "identification.json")
    errors = []
    for data, units in ((mnm, []), (si, ["--units", "tau=Nm"])):
        out = tmp_path / data.stem
        argv = ["validate", "--model", model, "--data", str(data), *units, "--no-figures"]
        assert main(argv + ["--out", str(out), "-q"]) == 0
        errors.append(json.loads((out / "validation.json").read_text())["relative_error_percent"])
    assert "the model's data were read with" in caplog.text
    assert errors[1] == pytest.approx(errors[0], rel=1e-9)
    assert errors[0] < 5.0


def test_a_header_with_units_is_refused_with_the_map_that_reads_it(tmp_path):
    """'q1 [rad]' headers: the refusal names the --columns map, and that map reads the log
    back to its values (a header with units was refused without a way out)."""
    from dynid.io.torque_log import load_torque_log

    log = _log(4, n=2, N=50)
    names = ["t [s]", "q1 [rad]", "q2 [rad]", "dq1 [rad/s]", "dq2 [rad/s]"]
    names += ["tau1 (Nm)", "tau2 (Nm)"]
    data = np.column_stack([log.t, log.q, log.dq, log.tau])
    path = tmp_path / "units.csv"
    np.savetxt(path, data, delimiter=",", header=",".join(names), comments="", fmt="%.17g")
    with pytest.raises(DataError, match="hint: names with units") as err:
        load_torque_log(path)
    spec = str(err.value).split("--columns '")[1].split("'")[0]
    assert spec == "t=t [s],q=q{i} [rad],dq=dq{i} [rad/s],tau=tau{i} (Nm)"
    got = load_mapped_torque_log(path, parse_column_map(spec, None)).log
    for k in ("t", "q", "dq", "tau"):
        np.testing.assert_array_equal(getattr(got, k), getattr(log, k))


def test_the_recorded_units_are_said_with_how_to_read_another_file(caplog):
    """A model identified from mN m logs reads a new file in mN m unless told: the warning
    said so without saying how to read an SI file, and the user met "unusable, 9.99e4 %";
    it now names the option."""
    import logging

    from dynid.workflows.data_files import recorded_columns

    with caplog.at_level(logging.WARNING):
        used = recorded_columns({"columns": None, "units": "tau=mNm"}, None, None)
    assert used == (None, "tau=mNm")
    (said,) = [r.getMessage() for r in caplog.records]
    assert "(--units tau=mNm)" in said and "--units tau=Nm for SI torques" in said, said


def test_currents_in_ma_are_read_through_a_current_drive_and_said_once(tmp_path, caplog):
    """Regression (--units tau=mA refused, tau=0.001 warned on every file): with a drive
    of effort = current, mA and A read the file's numbers x 1e-3 and x 1, said once as a
    note, never as a warning per file; a torque drive or none refuses them, naming
    --units and the drive."""
    import logging

    from dynid.exceptions import OptionError
    from dynid.model.drive import Drive
    from dynid.workflows.data_files import column_map, read_torque_log

    log = _log(4)
    paths = [tmp_path / "a.csv", tmp_path / "b.csv"]
    for p in paths:
        dynid.io.save_torque_log(p, TorqueLog(log.t, log.q, log.dq, log.tau * 1e3))
    n = log.n
    current = Drive(np.eye(n), np.zeros(n), effort="current", torque_constant=np.ones(n))
    for unit, factor in (("mA", 1e-3), ("A", 1.0), ("0.001", 1e-3)):
        caplog.clear()
        with caplog.at_level(logging.INFO):
            cmap = column_map(None, f"tau={unit}", drive=current)
            got = [read_torque_log(p, n, columns=cmap) for p in paths]
        for g in got:
            np.testing.assert_allclose(g.tau, log.tau * 1e3 * factor, rtol=1e-15)
        assert not [r for r in caplog.records if r.levelno >= logging.WARNING]
        notes = [r.getMessage() for r in caplog.records if "--units" in r.getMessage()]
        assert len(notes) == (unit != "A"), notes
    assert "tau in mA (x 0.001 to A)" in column_map(None, "tau=mA", drive=current).unit_note()
    torque = Drive(np.eye(n), np.zeros(n))
    with pytest.raises(OptionError, match="--units tau=mA declares motor currents, but no --drive"):
        column_map(None, "tau=mA")
    with pytest.raises(OptionError, match="the drive's effort is 'torque'"):
        column_map(None, "tau=A", drive=torque)


def test_single_joints_are_flipped_as_read_after_their_quantitys_unit(tmp_path):
    """A controller whose torque convention differs on joints 2 and 3 only: ``--units
    tau=mNm,tau2=-1,tau3=-1`` reads the file's columns (written here) with those joints
    negated and the rest as they are, said as one note; a TOML map's [units] does the same
    (with a CSV and an NPZ file); a joint beyond the file's, or a scale other than -1 or 1,
    is refused in one line (a joint's scale is a drive's torque constant)."""
    log = _log(5)
    path = tmp_path / "other.csv"
    _write_renamed(path, log)
    columns = "t=time_ms,q=position_{i0},dq=velocity_{i0},tau=effort_{i0}"
    sign = np.array([1.0, -1.0, -1.0])
    got = load_mapped_torque_log(
        path, parse_column_map(columns, "t=ms,q=deg,dq=deg/s,tau=mNm,tau2=-1,tau3=-1")
    )
    np.testing.assert_allclose(got.log.tau, log.tau * sign, rtol=1e-14, atol=1e-15)
    np.testing.assert_allclose(got.log.q, log.q, rtol=1e-14, atol=1e-15)
    assert got.conversions == ("tau2, tau3 sign flipped (--units tau2=-1,tau3=-1)",)
    np.savez(tmp_path / "log.npz", t=log.t, q=log.q, dq=log.dq, tau=log.tau)
    (tmp_path / "map.toml").write_text(
        '[columns]\nq = "q"\ndq = "dq"\ntau = "tau"\n[units]\ntau2 = -1\ntau3 = -1\ntau1 = 1\n'
    )
    npz = load_mapped_torque_log(tmp_path / "log.npz", load_column_map(tmp_path / "map.toml"))
    np.testing.assert_array_equal(npz.log.tau, log.tau * sign)
    with pytest.raises(DataError, match=r"--units tau4=-1 names joint 4; the file has 3"):
        load_mapped_torque_log(path, parse_column_map(columns, "t=ms,tau4=-1"))
    with pytest.raises(DataError, match=r"tau2=2: a single joint's entry flips its sign"):
        parse_column_map(None, "tau2=2")


def test_recorded_column_map_warning_names_flags_not_python_none(caplog):
    """Regression: a model read with --units alone warned "columns None, units 'q=deg'"."""
    from dynid.progress import NOTE
    from dynid.workflows.data_files import recorded_columns

    with caplog.at_level(NOTE):
        used = recorded_columns({"columns": None, "units": "q=deg"}, None, None)
        recorded_columns({"columns": None, "units": "q=deg"}, None, "tau=Nm")
    assert used == (None, "q=deg")
    assert "None" not in caplog.text
    assert "(--units q=deg)" in caplog.text
    assert "with --units tau=Nm; the model's data were read with --units q=deg" in caplog.text


def test_the_recorded_sign_flips_reused_are_a_note(caplog):
    """Regression: validate and payload warned "reading the data as the model's data were
    read (--units tau2=-1,tau5=-1)", though reusing the arm's sign convention is right; it
    is a note, and so are named units of times and angles (a new file in other units is
    refused by the time and degrees checks, with its hint), while a recorded torque unit
    (mN m: a new file in SI would read 1000 x off), a factor and a map given that differs
    from the recorded one stay warnings."""
    from dynid.progress import NOTE
    from dynid.workflows.data_files import recorded_columns

    cases = {
        "tau2=-1,tau5=-1": NOTE,
        "rec2.csv:tau=-1,tau3=1": NOTE,
        "tau=mNm,tau2=-1": logging.WARNING,
        "tau=-0.001": logging.WARNING,
        "t=us,q=deg,dq=deg/s,tau=-1": NOTE,  # a new file in other units is refused
        "q=0.01745": logging.WARNING,  # a factor: no unit to check a file against
    }
    for units, level in cases.items():
        caplog.clear()
        with caplog.at_level(NOTE):
            assert recorded_columns({"columns": None, "units": units}, None, None) == (
                None,
                units,
            )
        (record,) = caplog.records
        assert record.levelno == level and f"(--units {units})" in record.getMessage(), units
    caplog.clear()
    with caplog.at_level(NOTE):  # a column map alone (a libfranka log's names): a note
        libfranka = "t=time,q=q_{i0},dq=dq_{i0},tau=tau_J_{i0}"
        assert recorded_columns({"columns": libfranka, "units": None}, None, None) == (
            libfranka,
            None,
        )
    (record,) = caplog.records
    assert record.levelno == NOTE and f"--columns {libfranka}" in record.getMessage()
    caplog.clear()
    with caplog.at_level(NOTE):
        recorded_columns({"columns": None, "units": "tau2=-1"}, None, "tau2=-1,tau3=-1")
    (record,) = caplog.records
    assert record.levelno == logging.WARNING and "the model's data were read with" in (
        record.getMessage()
    )


def test_a_training_files_own_flips_do_not_make_a_held_out_files_units_differ(caplog):
    """A model read with ``t=ns`` and a training file's own flips: a held-out file read
    with ``--units t=ns`` reads alike (no warning), one read without ``t=ns`` or with
    a flip of its own does not (the warning names both)."""
    from dynid.workflows.data_files import recorded_columns

    rec = {"columns": None, "units": "t=ns,rec2.csv:tau1=-1,rec2.csv:tau2=-1"}
    with caplog.at_level("WARNING"):
        assert recorded_columns(rec, None, "t=ns", ["held.csv"]) == (None, "t=ns")
    assert caplog.text == ""
    for units in ("t=us", "t=ns,held.csv:tau1=-1", "t=ns,tau1=-1"):
        caplog.clear()
        with caplog.at_level("WARNING"):
            recorded_columns(rec, None, units, ["held.csv"])
        assert f"with --units {units}; the model's data were read with" in caplog.text
    caplog.clear()
    with caplog.at_level("WARNING"):  # the training file itself read without its flips
        recorded_columns(rec, None, "t=ns", ["rec2.csv"])
    assert "the model's data were read with" in caplog.text


def test_a_files_own_sign_negates_every_joint_of_that_file_alone(tmp_path):
    """``--units b.csv:tau=-1`` negates every joint's torques of ``b.csv`` (a driver that
    logs the torque the motor feels) and of no other file, said as the entry given; with
    ``tau=mNm`` every file's torques are scaled too; a unit other than a sign stays
    refused as a file's own entry."""
    from dynid.io.torque_log import save_torque_log

    logs = {"a.csv": _log(7), "b.csv": _log(8)}
    for name, log in logs.items():
        save_torque_log(tmp_path / name, log)
    cmap = parse_column_map(None, "b.csv:tau=-1")
    a = load_mapped_torque_log(tmp_path / "a.csv", cmap)
    b = load_mapped_torque_log(tmp_path / "b.csv", cmap)
    np.testing.assert_array_equal(a.log.tau, logs["a.csv"].tau)
    np.testing.assert_array_equal(b.log.tau, -logs["b.csv"].tau)
    assert a.conversions == () and b.conversions == ("tau sign flipped (--units b.csv:tau=-1)",)
    assert cmap.unknown_files(["a.csv"]) == ("b.csv",)
    scaled = parse_column_map(None, "b.csv:tau=-1,tau=mNm")
    b = load_mapped_torque_log(tmp_path / "b.csv", scaled)
    np.testing.assert_allclose(b.log.tau, -1e-3 * logs["b.csv"].tau, rtol=1e-15)
    assert "(--units b.csv:tau=-1,tau=mNm)" in b.conversions[0], b.conversions
    milli = parse_column_map(None, "b.csv:tau=mNm")  # a file's own unit (once refused)
    b = load_mapped_torque_log(tmp_path / "b.csv", milli)
    np.testing.assert_allclose(b.log.tau, 1e-3 * logs["b.csv"].tau, rtol=1e-15)
    a = load_mapped_torque_log(tmp_path / "a.csv", milli)
    np.testing.assert_array_equal(a.log.tau, logs["a.csv"].tau)


def test_a_files_own_flip_reads_that_file_alone_and_is_said_with_its_name(tmp_path):
    """``--units b.csv:tau2=-1`` negates joint 2's torques of ``b.csv`` (as written) and
    of no other file, said as the entry given; with ``tau3=-1`` for every file too."""
    from dynid.io.torque_log import save_torque_log

    logs = {"a.csv": _log(7), "b.csv": _log(8)}
    for name, log in logs.items():
        save_torque_log(tmp_path / name, log)
    cmap = parse_column_map(None, "b.csv:tau2=-1,tau3=-1")
    a = load_mapped_torque_log(tmp_path / "a.csv", cmap)
    b = load_mapped_torque_log(tmp_path / "b.csv", cmap)
    np.testing.assert_array_equal(a.log.tau, logs["a.csv"].tau * [1.0, 1.0, -1.0])
    np.testing.assert_array_equal(b.log.tau, logs["b.csv"].tau * [1.0, -1.0, -1.0])
    assert a.conversions == ("tau3 sign flipped (--units tau3=-1)",)
    assert b.conversions == ("tau2, tau3 sign flipped (--units b.csv:tau2=-1,tau3=-1)",)
    assert cmap.unknown_files(["a.csv", "b.csv"]) == ()
    assert cmap.unknown_files(["a.csv"]) == ("b.csv",)
