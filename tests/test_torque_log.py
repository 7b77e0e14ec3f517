"""Torque logs: validation, cleaning, preparation, and CSV/NPZ files."""

from __future__ import annotations

import numpy as np
import pytest

from dynid.exceptions import DataError, NonFiniteError, ShapeError
from dynid.identification.log import TorqueLog
from dynid.identification.prepare import Preprocessing, prepare_log
from dynid.io.torque_log import load_torque_log, save_torque_log, torque_log_columns
from dynid.simulation.measurement import SensorNoise, sample_times, simulate_measurement
from dynid.simulation.trajectories import sinusoid_trajectory


def _log(rng, N=50, n=3, ddq=False):
    t = np.arange(N) * 1e-3
    a = [rng.normal(size=(N, n)) for _ in range(4)]
    return TorqueLog(t, a[0], a[1], a[2], a[3] if ddq else None)


@pytest.mark.parametrize("suffix", [".csv", ".npz"])
@pytest.mark.parametrize("with_ddq", [False, True])
def test_round_trip_is_exact(tmp_path, suffix, with_ddq):
    """Writing then reading a log gives back the same arrays, bit for bit."""
    log = _log(np.random.default_rng(41), ddq=with_ddq)
    back = load_torque_log(save_torque_log(tmp_path / f"log{suffix}", log))
    for k in ("t", "q", "dq", "tau"):
        np.testing.assert_array_equal(getattr(back, k), getattr(log, k))
    if with_ddq:
        np.testing.assert_array_equal(back.ddq, log.ddq)
    else:
        assert back.ddq is None
    assert back.cleaning.n_nan_rows == 0 and back.cleaning.n_duplicates == 0


def test_csv_header_names_columns_and_units(tmp_path):
    """The CSV starts with a units comment and the t, q1..qn, dq1..dqn, tau1..taun header."""
    path = save_torque_log(tmp_path / "log.csv", _log(np.random.default_rng(42), n=2))
    lines = path.read_text().splitlines()
    assert lines[0].startswith("#") and "tau [N m]" in lines[0]
    assert lines[1] == "# rows: 50"
    assert lines[2] == "t,q1,q2,dq1,dq2,tau1,tau2"
    assert torque_log_columns(2, with_ddq=True)[-2:] == ["ddq1", "ddq2"]


def test_strict_log_rejects_duplicates_nan_and_shapes():
    """TorqueLog itself rejects repeated timestamps, NaN and inconsistent shapes."""
    z = np.zeros((4, 2))
    with pytest.raises(DataError, match=r"row 2 \(t = 0.1\) repeats row 1"):
        TorqueLog(np.array([0.0, 0.1, 0.1, 0.2]), z, z, z)
    bad = z.copy()
    bad[2, 1] = np.nan
    with pytest.raises(NonFiniteError, match=r"tau must be finite; got nan at index \(2, 1\)"):
        TorqueLog(np.arange(4.0), z, z, bad)
    with pytest.raises(ShapeError, match="dq must have shape"):
        TorqueLog(np.arange(4.0), z, np.zeros((4, 3)), z)


def test_from_raw_drops_nan_rows_and_duplicates_and_reports_gaps():
    """Cleaning drops and counts NaN rows and duplicate stamps, and lists gaps."""
    t = np.array([0.0, 0.001, 0.002, 0.002, 0.003, 0.004, 0.008, 0.009, 0.010])
    q = np.arange(9.0)[:, None] * np.ones((1, 2))
    q[4, 0] = np.nan
    log = TorqueLog.from_raw(t, q, q, q)
    c = log.cleaning
    assert (c.n_input_rows, c.n_nan_rows, c.n_duplicates) == (9, 1, 1)
    np.testing.assert_array_equal(log.t, [0.0, 0.001, 0.002, 0.004, 0.008, 0.009, 0.010])
    np.testing.assert_array_equal(log.q[:, 0], [0, 1, 2, 5, 6, 7, 8])  # first duplicate kept
    assert c.gaps == ((0.002, 0.004), (0.004, 0.008))
    assert c.dt_median == pytest.approx(0.001)


def test_select_keeps_rows_and_cleaning():
    """select() picks rows of every array (ddq included) and keeps the cleaning record."""
    t = np.array([0.0, 0.001, 0.001, 0.002, 0.003])
    a = np.arange(10.0).reshape(5, 2)
    log = TorqueLog.from_raw(t, a, a + 1, a + 2, a + 3)
    sub = log.select(np.array([0, 2]))
    np.testing.assert_array_equal(sub.t, [0.0, 0.002])
    np.testing.assert_array_equal(sub.ddq, [[3.0, 4.0], [9.0, 10.0]])
    assert sub.cleaning.n_duplicates == 1


def test_from_raw_rejects_time_running_backwards():
    """A timestamp below its predecessor is rejected with the row number."""
    t = np.array([0.0, 0.1, 0.2, 0.15, 0.3])
    z = np.zeros((5, 1))
    with pytest.raises(DataError, match="timestamps run backwards at row 3"):
        TorqueLog.from_raw(t, z, z, z)


def test_csv_with_empty_and_nan_cells_is_refused_or_dropped_on_request(tmp_path, caplog):
    """Empty or 'nan' cells make a row invalid: refused by default (issue 12), dropped and
    counted with drop_invalid, with a warning that says how many and where."""
    path = save_torque_log(tmp_path / "log.csv", _log(np.random.default_rng(43), N=20, n=2))
    lines = path.read_text().splitlines()
    cells = lines[5].split(",")
    cells[3] = ""
    lines[5] = ",".join(cells)
    cells = lines[9].split(",")
    cells[6] = "nan"
    lines[9] = ",".join(cells)
    path.write_text("\n".join(lines) + "\n")
    with pytest.raises(DataError, match=r"2 row\(s\) hold NaN.*first row 2 \(line 6\) in 'dq1'"):
        load_torque_log(path)
    log = load_torque_log(path, drop_invalid=True)
    assert log.n_samples == 18 and log.cleaning.n_nan_rows == 2
    assert "dropped 2 row(s) of 20" in caplog.text and "row 6 (line 10)" in caplog.text


def test_csv_errors_name_the_line_and_column(tmp_path):
    """Non-numeric cells, short rows and missing columns raise DataError with the place."""
    path = save_torque_log(tmp_path / "log.csv", _log(np.random.default_rng(44), N=10, n=2))
    lines = path.read_text().splitlines()
    bad = lines.copy()
    cells = bad[4].split(",")
    cells[5] = "abc"
    bad[4] = ",".join(cells)
    (tmp_path / "a.csv").write_text("\n".join(bad))
    with pytest.raises(DataError, match=r"a.csv, line 5, column 'tau1': not a number: 'abc'"):
        load_torque_log(tmp_path / "a.csv")
    bad = lines.copy()
    bad[6] = ",".join(bad[6].split(",")[:-1])
    (tmp_path / "b.csv").write_text("\n".join(bad))
    with pytest.raises(DataError, match="b.csv, line 7: expected 7 fields"):
        load_torque_log(tmp_path / "b.csv")
    bad = lines.copy()
    bad[2] = bad[2].replace("tau2", "torque2")
    (tmp_path / "c.csv").write_text("\n".join(bad))
    with pytest.raises(DataError, match=r"missing column\(s\) tau2 "):
        load_torque_log(tmp_path / "c.csv")
    with pytest.raises(DataError, match="must be a .csv or .npz"):
        load_torque_log(tmp_path / "log.txt")


def test_npz_errors(tmp_path):
    """A missing array or an object array in an NPZ raises DataError."""
    np.savez(tmp_path / "a.npz", t=np.arange(3.0), q=np.zeros((3, 1)), dq=np.zeros((3, 1)))
    with pytest.raises(DataError, match=r"missing array\(s\) tau;"):
        load_torque_log(tmp_path / "a.npz")
    np.savez(
        tmp_path / "b.npz",
        t=np.arange(3.0),
        q=np.zeros((3, 1)),
        dq=np.zeros((3, 1)),
        tau=np.array([[{}], [{}], [{}]], dtype=object),
    )
    with pytest.raises(DataError, match="b.npz"):
        load_torque_log(tmp_path / "b.npz")


def test_prepare_log_resamples_jittered_and_dropped_samples(panda):
    """Jittered timestamps and 2 % dropped samples: the prepared log is uniform and its
    filtered states and accelerations match the true trajectory."""
    rng = np.random.default_rng(45)
    t = sample_times(10.0, 1000.0, jitter_std=5e-5, rng=rng)
    q0 = np.array([0.0, -0.3, 0.0, -2.0, 0.0, 1.6, 0.0])
    A = np.array([0.5, -0.4, 0.6, 0.5, -0.7, 0.6, 0.8])
    T = np.array([4.0, 3.0, 5.0, 2.5, 3.5, 4.5, 2.0])
    log = simulate_measurement(
        panda,
        sinusoid_trajectory(t, q0, A, T),
        rng=rng,
        noise=SensorNoise(tau_std=0.05, q_std=0.0, dq_std=1e-3),
        drop_fraction=0.02,
    )
    raw = TorqueLog.from_raw(log.t, log.q, log.dq, log.tau)
    assert len(raw.cleaning.gaps) > 50 and raw.cleaning.dt_jitter > 0.05
    p = prepare_log(raw, Preprocessing(cutoff_hz=10.0))
    np.testing.assert_allclose(np.diff(p.t), 1e-3, rtol=1e-6)
    ref = sinusoid_trajectory(p.t, q0, A, T)
    assert np.max(np.abs(p.q - ref.q)) < 1e-5
    assert np.max(np.abs(p.dq - ref.dq)) < 2e-3
    assert np.max(np.abs(p.ddq - ref.ddq)) < 0.05
    assert p.t[0] == pytest.approx(0.2, abs=1e-3)  # 2 / cutoff trimmed


def test_prepare_log_rejects_long_gaps():
    """A gap longer than max_gap_s is a DataError naming where it is."""
    t = np.concatenate([np.arange(100), np.arange(150, 250)]) * 1e-3
    z = np.zeros((200, 2))
    with pytest.raises(DataError, match=r"gap of 0.051 s .* t = 0.099 s"):
        prepare_log(TorqueLog(t, z, z, z), Preprocessing(cutoff_hz=None))


def test_blank_lines_keep_the_fast_reader_and_the_same_arrays(tmp_path, monkeypatch):
    """A log with blank lines (one after the header, one inside, two at a block's end) is
    read by the fast reader, not the slow per-cell one, into the same arrays (issue 20: one
    blank line in 2 million rows took 38 s and 2.3 GB instead of 23 s and 1.2 GB)."""
    from dynid.io import csv_tables

    log = _log(np.random.default_rng(47), N=300)
    lines = save_torque_log(tmp_path / "log.csv", log).read_text().splitlines()
    h = lines.index(",".join(torque_log_columns(3)))
    blank = lines[: h + 1] + [""] + lines[h + 1 : h + 100] + ["", ""] + lines[h + 100 :] + [""]
    (tmp_path / "blank.csv").write_text("\n".join(blank) + "\n")

    def refuse(*args, **kw):
        raise AssertionError("the slow reader was used")

    monkeypatch.setattr(csv_tables, "_slow_table", refuse)
    back = load_torque_log(tmp_path / "blank.csv")
    for k in ("t", "q", "dq", "tau"):
        np.testing.assert_array_equal(getattr(back, k), getattr(log, k))
    monkeypatch.setattr(csv_tables, "_CHUNK_BYTES", 1000)  # blank lines across block ends
    back = load_torque_log(tmp_path / "blank.csv")
    np.testing.assert_array_equal(back.tau, log.tau)


def test_a_declared_row_count_the_file_cannot_hold_is_refused_before_allocating(tmp_path):
    """'# rows: 1000000000000' over a few kB of rows: refused by the file's size, before
    arrays of 1e12 rows are allocated (issue 20: they were allocated)."""
    lines = save_torque_log(tmp_path / "log.csv", _log(np.random.default_rng(48))).read_text()
    text = lines.replace("# rows: 50", "# rows: 1000000000000")
    (tmp_path / "big.csv").write_text(text)
    size = len(text.split("tau3\n", 1)[1].encode())
    with pytest.raises(DataError, match=f"records 1000000000000 rows but its {size} bytes"):
        load_torque_log(tmp_path / "big.csv")


def _npz_with(path, members):
    """An NPZ written member by member: name -> (bytes of the .npy, compression)."""
    import zipfile

    with zipfile.ZipFile(path, "w") as z:
        for name, (data, method) in members.items():
            z.writestr(name, data, compress_type=method)
    return path


def _npy(a, shape=None):
    """The .npy bytes of ``a``; ``shape`` overrides the shape its header declares."""
    import io

    buf = io.BytesIO()
    np.lib.format.write_array_header_1_0(
        buf, {"descr": np.lib.format.dtype_to_descr(a.dtype), "fortran_order": False,
              "shape": a.shape if shape is None else shape}
    )  # fmt: skip
    return buf.getvalue() + a.tobytes()


def test_npz_bombs_and_absurd_headers_are_refused_before_reading(tmp_path, monkeypatch):
    """A member inflating 1000 times, a header declaring 1e12 rows, an archive above the
    documented size limit (raised by DYNID_MAX_NPZ_BYTES) and complex numbers are refused
    with one DataError each, before numpy allocates (issue 20: a 5.8 MB NPZ took 6 GB)."""
    import zipfile

    from dynid.io import npz_files
    from dynid.io.static_data import load_static_npz

    log = _log(np.random.default_rng(49), N=40)
    arrays = {"t": log.t, "q": log.q, "dq": log.dq, "tau": log.tau}
    good = {f"{k}.npy": (_npy(a), zipfile.ZIP_STORED) for k, a in arrays.items()}
    ok = load_torque_log(_npz_with(tmp_path / "ok.npz", good))
    np.testing.assert_array_equal(ok.tau, log.tau)

    bomb = dict(good, **{"dq.npy": (_npy(np.zeros((300_000, 3))), zipfile.ZIP_DEFLATED)})
    with pytest.raises(DataError, match=r"bomb.npz: member 'dq.npy' inflates \d+ times"):
        load_torque_log(_npz_with(tmp_path / "bomb.npz", bomb))
    absurd = dict(good, **{"q.npy": (_npy(log.q, (10**12, 3)), zipfile.ZIP_STORED)})
    with pytest.raises(DataError, match=r"array 'q' declares shape \(1000000000000, 3\)"):
        load_torque_log(_npz_with(tmp_path / "absurd.npz", absurd))
    monkeypatch.setattr(npz_files, "MAX_NPZ_BYTES", 3000)
    with pytest.raises(DataError, match="above the limit of .* DYNID_MAX_NPZ_BYTES"):
        load_torque_log(tmp_path / "ok.npz")
    monkeypatch.setenv("DYNID_MAX_NPZ_BYTES", "100000")
    assert load_torque_log(tmp_path / "ok.npz").n_samples == 40
    monkeypatch.delenv("DYNID_MAX_NPZ_BYTES")
    monkeypatch.setattr(npz_files, "MAX_NPZ_BYTES", 4 << 30)
    q = np.zeros((5, 2), complex)
    np.savez(tmp_path / "c.npz", q=q, M=np.zeros((5, 2, 2)), g=np.zeros((5, 2)))
    with pytest.raises(DataError, match="array 'q' must be real numbers; got dtype complex128"):
        load_static_npz(tmp_path / "c.npz")


def test_extra_columns_are_ignored_with_a_warning_and_read_back_by_name(tmp_path, caplog):
    """A label column and tau_ext1..n beside the log (as simulate --contact writes them) are
    ignored by the reader, named (the contact labels observe scores against and the true
    external torques of dynid's simulations in informational lines, another column in a
    warning); load_joint_columns reads them."""
    import logging

    from dynid.identification.log import TorqueLog
    from dynid.io.columns import load_joint_columns
    from dynid.io.torque_log import load_torque_log, save_torque_log_pieces

    rng = np.random.default_rng(0)
    N, n = 50, 3
    log = TorqueLog(
        t=np.arange(N) * 1e-3, q=rng.normal(size=(N, n)), dq=rng.normal(size=(N, n)),
        tau=rng.normal(size=(N, n)),
    )  # fmt: skip
    ext = rng.normal(size=(N, n))
    for suffix in (".csv", ".npz"):
        path = tmp_path / f"log{suffix}"
        save_torque_log_pieces(
            path, lambda: (log,), n=n, n_rows=N, extra=("tau_ext", lambda: (ext,))
        )
        with caplog.at_level(logging.INFO):
            back = load_torque_log(path)
        said = [r.getMessage() for r in caplog.records]
        truth = [r for r in caplog.records if "hold the true external torques" in r.getMessage()]
        # dynid's own simulations write them: an informational line, not a warning
        assert truth and all(r.levelno == logging.INFO for r in truth), said
        assert not any("tau_ext" in m and "ignored" in m for m in said)
        np.testing.assert_array_equal(back.tau, log.tau)
        np.testing.assert_array_equal(load_joint_columns(path, "tau_ext", n), ext)
        assert load_joint_columns(path, "vendor_tau", n) is None
        caplog.clear()
    text = (tmp_path / "log.csv").read_text().splitlines()
    text[2] += ",label,note"
    text[3:] = [row + ",1,contact" for row in text[3:]]
    (tmp_path / "labelled.csv").write_text("\n".join(text) + "\n")
    with caplog.at_level(logging.INFO):
        np.testing.assert_array_equal(load_torque_log(tmp_path / "labelled.csv").q, log.q)
    levels = {r.getMessage().split(": ", 1)[1]: r.levelno for r in caplog.records}
    assert levels["column(s) label hold contact labels: never read as data (dynid "
                  "observe scores its events against them)"] == logging.INFO  # fmt: skip
    assert levels["column(s) note are not torque-log signals: ignored as data"] == (logging.WARNING)
