"""A file's own units, external torques read through a column map, and the hint for a
file of dynid's own names read through another map.

Reference: small libfranka-style CSVs written here from known arrays (``time``,
``q_0..``, ``dq_0..``, ``tau_J_0..``, ``tau_ext_hat_filtered_0..``), one of them with its
time column in milliseconds; the values read back are compared with the arrays written,
scaled by the units' exact factors. Before, a folder of recordings in seconds and one in
milliseconds could not be read in one run (``--units rec4.csv:t=ms`` was refused, and the
hint of ``t=ms`` named no file), ``--columns tau_ext=...`` was an unknown quantity, and a
dynid-named file under a model's map was told ``hint: --columns ''`` alone.
"""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest

import dynid
from dynid.exceptions import DataError
from dynid.identification.angle_time_units import GivenUnits
from dynid.identification.log import TorqueLog
from dynid.identification.time_units_among import time_units_hint
from dynid.io.columns import (
    load_external_torques,
    load_mapped_torque_log,
    parse_column_map,
    unread_columns,
    unread_note,
)
from dynid.workflows.recordings import Recorded, check_unit_findings, given_units

MAP = "t=time,q=q_{i0},dq=dq_{i0},tau=tau_J_{i0}"
N = 7


def _arrays(seed: int, rows: int = 400, rate: float = 200.0) -> dict[str, np.ndarray]:
    """Time [s], positions and their exact derivative, torques and external torques."""
    rng = np.random.default_rng(seed)
    t = np.arange(rows) / rate
    a, w, ph = rng.uniform(0.2, 0.4, N), rng.uniform(1.0, 3.0, N), rng.uniform(0, 6, N)
    q = a * np.sin(w * t[:, None] + ph) + np.array([0, 0, 0, -1.9, 0, 1.9, 0])
    dq = a * w * np.cos(w * t[:, None] + ph)
    return {
        "t": t,
        "q": q,
        "dq": dq,
        "tau": rng.normal(size=(rows, N)),
        "ext": rng.normal(size=(rows, N)),
    }


def _write(path: Path, x: dict[str, np.ndarray], time_ms: bool = False) -> Path:
    """A libfranka-style CSV of ``x`` (its time in ms with ``time_ms``)."""
    cols = {"time": x["t"] * (1e3 if time_ms else 1.0)}
    for label, key in (("q", "q"), ("dq", "dq"), ("tau_J", "tau"), ("tau_ext_hat_filtered", "ext")):
        cols |= {f"{label}_{j}": x[key][:, j] for j in range(N)}
    return _save_columns(path, cols)


def _save_columns(path: Path, cols: dict[str, np.ndarray]) -> Path:
    """A CSV of the columns ``cols``, their names as its header."""
    head = ",".join(cols)
    np.savetxt(path, np.column_stack(list(cols.values())), delimiter=",", header=head, comments="")
    return path


def test_a_files_own_time_unit_reads_that_file_alone(tmp_path):
    """``--units rec4.csv:t=ms`` reads rec4.csv's times in ms and rec1.csv's in s."""
    x1, x4 = _arrays(1), _arrays(4)
    p1 = _write(tmp_path / "rec1.csv", x1)
    p4 = _write(tmp_path / "rec4.csv", x4, time_ms=True)
    cmap = parse_column_map(MAP, "rec4.csv:t=ms")
    assert cmap.own_files == ("rec4.csv",)
    np.testing.assert_allclose(load_mapped_torque_log(p4, cmap).log.t, x4["t"], rtol=1e-12)
    np.testing.assert_allclose(load_mapped_torque_log(p1, cmap).log.t, x1["t"], rtol=1e-15)
    assert "rec4.csv alone: t in ms (x 0.001 to SI)" in (cmap.unit_note() or "")


def test_a_files_own_units_take_what_every_files_take(tmp_path):
    """Per-file entries take every unit ``--units`` takes: angles, torques, a factor, a
    length and an angle unit as a pair; the file's sign entry still negates its unit."""
    x = _arrays(2)
    p = _write(tmp_path / "b.csv", x)
    cmap = parse_column_map(MAP, "tau=mNm,b.csv:q=deg,b.csv:dq=deg/s,b.csv:tau=0.5")
    log = load_mapped_torque_log(p, cmap).log
    np.testing.assert_allclose(log.q, x["q"] * np.pi / 180, rtol=1e-14)
    np.testing.assert_allclose(log.dq, x["dq"] * np.pi / 180, rtol=1e-14)
    np.testing.assert_allclose(log.tau, 0.5 * x["tau"], rtol=1e-15)
    other = load_mapped_torque_log(_write(tmp_path / "a.csv", x), cmap).log
    np.testing.assert_allclose(other.tau, 1e-3 * x["tau"], rtol=1e-15)
    np.testing.assert_array_equal(
        other.q, load_mapped_torque_log(tmp_path / "a.csv", parse_column_map(MAP)).log.q
    )
    pair = parse_column_map(MAP, "b.csv:q=mm,b.csv:q=deg")
    assert dict(pair.for_file("b.csv").lengths) == {"q": "mm"}
    assert dict(pair.for_file("b.csv").names) == {"q": "deg"}
    assert dict(pair.for_file("a.csv").names) == {}
    with pytest.raises(DataError, match=r"--units b.csv:t: unknown unit 'sec' for 't'"):
        parse_column_map(MAP, "b.csv:t=sec")
    with pytest.raises(DataError, match=r"unknown quantity 'x'"):
        parse_column_map(MAP, "b.csv:x=ms")


def _log(x: dict[str, np.ndarray], scale: float) -> TorqueLog:
    """``x`` as read with its time column scaled by ``scale`` (a wrong unit)."""
    return TorqueLog(x["t"] * scale, x["q"], x["dq"], x["tau"])


def test_the_hint_names_the_one_file_whose_time_unit_differs():
    """Three recordings in s and one in ms: the hint is ``--units rec4.csv:t=ms``, read
    without units or with ``t=ms`` for all; with ``rec4.csv:t=ms`` nothing is found."""
    panda = dynid.fr3()
    xs = [_arrays(k) for k in (1, 2, 3, 4)]
    names = tuple(Path(f"rec{k}.csv") for k in (1, 2, 3, 4))
    plain = Recorded(tuple(_log(x, 1e3 if k == 3 else 1.0) for k, x in enumerate(xs)), names)
    with pytest.raises(DataError, match=r"^rec4.csv: .*hint: --units rec4.csv:t=ms \(") as e:
        check_unit_findings(plain, panda, GivenUnits())
    assert "rec4.csv in ms, rec1.csv, rec2.csv, rec3.csv in s" in str(e.value)
    every = Recorded(tuple(_log(x, 1.0 if k == 3 else 1e-3) for k, x in enumerate(xs)), names)
    given = given_units(parse_column_map(None, "t=ms,tau=-1"), "t=ms,tau=-1")
    with pytest.raises(DataError, match=r"^rec1.csv: .*hint: --units tau=-1,rec4.csv:t=ms \("):
        check_unit_findings(every, panda, given)
    own = given_units(parse_column_map(None, "rec4.csv:t=ms"), "rec4.csv:t=ms")
    read = Recorded(tuple(_log(x, 1.0) for x in xs), names)
    check_unit_findings(read, panda, own)  # every file in its own unit: no finding


def test_time_units_hint_writes_the_majority_for_every_file():
    """The unit most files are in is every file's (seconds unsaid), the others their own."""
    assert time_units_hint(["a", "b"], ["s", "s"], "t=ms") is None
    assert time_units_hint(["a", "b", "c"], ["ms", "ms", "s"], None) == "t=ms,c:t=s"
    assert time_units_hint(["a", "b"], ["ms", "s"], "q=deg,a:t=us") == "q=deg,a:t=ms"


def test_external_torques_are_read_through_the_map(tmp_path):
    """``--columns tau_ext=tau_ext_hat_filtered_{i0}`` (and ``--units tau_ext=mNm``)
    reads those columns as the reference, with the times through the map's ``t``."""
    x = _arrays(5)
    p = _write(tmp_path / "hit.csv", x, time_ms=True)
    cmap = parse_column_map(MAP + ",tau_ext=tau_ext_hat_filtered_{i0}", "t=ms,tau_ext=mNm")
    found = load_external_torques(p, cmap, N)
    assert found is not None
    said, t, ext = found
    assert said == "columns tau_ext_hat_filtered_0..tau_ext_hat_filtered_6"
    np.testing.assert_allclose(ext, 1e-3 * x["ext"], rtol=1e-15)
    np.testing.assert_allclose(t, x["t"], rtol=1e-12)
    assert load_external_torques(p, parse_column_map(MAP), N) is None  # not mapped: none
    with pytest.raises(DataError, match=r"no column 'ext_0' for 'tau_ext'"):
        load_external_torques(p, parse_column_map(MAP + ",tau_ext=ext_{i0}"), N)


def test_dynids_own_tau_ext_columns_are_read_under_any_map(tmp_path):
    """A map that does not name ``tau_ext`` reads dynid's ``tau_ext1..n`` beside the log
    (a quantity not mapped keeps dynid's name), in N m."""
    x = _arrays(6)
    cols = {"time": x["t"]} | {f"pos{j}": x["q"][:, j] for j in range(N)}
    cols |= {f"tau_ext{j + 1}": x["ext"][:, j] for j in range(N)}
    p = _save_columns(tmp_path / "sim.csv", cols)
    found = load_external_torques(p, parse_column_map("t=time,q=pos{i0}"), N)
    assert found is not None
    np.testing.assert_array_equal(found[2], x["ext"])


def test_a_map_that_leaves_out_external_torques_says_how_to_map_them(tmp_path):
    """The unread note names libfranka's tau_ext_hat_filtered family as external torques
    and the entry that maps them; mapped, they are no longer unread."""
    x = _arrays(7)
    header = _write(tmp_path / "a.csv", x).read_text().splitlines()[0].split(",")
    unread = unread_columns(header, parse_column_map(MAP))
    note = unread_note(unread, N)
    assert "tau_ext_hat_filtered_0..tau_ext_hat_filtered_6 look like external" in note
    assert "--columns tau_ext=tau_ext_hat_filtered_{i0}" in note
    assert "scored as if it were the truth" in note
    mapped = parse_column_map(MAP + ",tau_ext=tau_ext_hat_filtered_{i0}")
    assert not any(c.startswith("tau_ext") for c in unread_columns(header, mapped))


def test_a_dynid_named_file_under_another_map_is_told_what_the_empty_map_means(tmp_path):
    """A file of dynid's names read through a libfranka map: the hint says the file has
    dynid's own names and that ``--columns ''`` reads them as they are."""
    x = _arrays(8)
    cols = {"t": x["t"]} | {f"q{j + 1}": x["q"][:, j] for j in range(N)}
    cols |= {f"tau{j + 1}": x["tau"][:, j] for j in range(N)}
    p = _save_columns(tmp_path / "own.csv", cols)
    with pytest.raises(DataError, match=r"hint: the file has dynid's own column names") as e:
        load_mapped_torque_log(p, parse_column_map(MAP))
    assert "--columns '' (an empty map) reads them as they are" in str(e.value)
    np.testing.assert_array_equal(load_mapped_torque_log(p, parse_column_map("")).log.q, x["q"])
