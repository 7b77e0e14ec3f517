"""Static data sets to/from CSV and NPZ, and identified models to/from JSON."""

from __future__ import annotations

import json
import logging

import numpy as np
import pytest

import dynid
from dynid.exceptions import DataError
from dynid.identification.data import StaticDataset
from dynid.identification.static import identify_static
from dynid.io.model_json import load_model_json, model_from_dict, model_to_dict, save_model_json
from dynid.io.robot_json import robot_from_dict, robot_to_dict
from dynid.io.static_data import (
    load_static_csv,
    load_static_data,
    load_static_npz,
    save_static_data,
    static_columns,
)
from dynid.simulation.controller import SimulatedController, acquire_static

from conftest import planar_2r, random_states


@pytest.fixture(scope="module")
def panda_data():
    """200 noisy Panda configurations with metadata."""
    robot = dynid.panda()
    rng = np.random.default_rng(201)
    data = acquire_static(SimulatedController(robot, 1e-3, rng=rng), 200, rng)
    return robot, data.with_metadata(seed=201)


def _csv_table(path):
    """(comment lines, header, rows of cells) of a CSV file written by save_static_csv."""
    lines = path.read_text().splitlines()
    comments = [x for x in lines if x.startswith("#")]
    body = [x for x in lines if not x.startswith("#")]
    return comments, body[0].split(","), [r.split(",") for r in body[1:]]


def _write_csv(path, comments, header, rows):
    path.write_text("\n".join(comments + [",".join(header)] + [",".join(r) for r in rows]) + "\n")


# ------------------------------------------------------------------ round trips
@pytest.mark.parametrize("suffix", [".csv", ".npz"])
def test_static_data_round_trip_is_exact(tmp_path, panda_data, suffix):
    """Saving and loading gives bit-identical q, M, g and keeps the metadata."""
    robot, data = panda_data
    path = save_static_data(tmp_path / f"static{suffix}", data)
    back, dropped = load_static_data(path, robot)
    assert dropped == 0
    np.testing.assert_array_equal(back.q, data.q)
    np.testing.assert_array_equal(back.M, data.M)
    np.testing.assert_array_equal(back.g, data.g)
    assert back.metadata["seed"] == 201 and back.metadata["relative_noise"] == 1e-3
    assert back.metadata["file"] == path.name and back.metadata["dropped_invalid_rows"] == 0


def test_csv_has_units_line_and_the_documented_columns(tmp_path, panda_data):
    """First line states the units; columns q1..q7, M<i>_<j> (i >= j) in tril order, g1..g7."""
    _, data = panda_data
    path = save_static_data(tmp_path / "static.csv", data)
    comments, header, rows = _csv_table(path)
    assert "[rad]" in comments[0] and "[kg m^2]" in comments[0] and "[N m]" in comments[0]
    assert header[:8] == ["q1", "q2", "q3", "q4", "q5", "q6", "q7", "M1_1"]
    assert header[8:11] == ["M2_1", "M2_2", "M3_1"] and header[-1] == "g7"
    assert tuple(header) == static_columns(7) and len(header) == 7 + 28 + 7
    assert float(rows[5][header.index("M4_2")]) == data.M[5, 3, 1]


def test_csv_columns_may_come_in_any_order(tmp_path, panda_data):
    """Columns are read by name."""
    robot, data = panda_data
    path = save_static_data(tmp_path / "static.csv", data)
    comments, header, rows = _csv_table(path)
    perm = np.random.default_rng(202).permutation(len(header))
    _write_csv(path, comments, [header[k] for k in perm], [[r[k] for k in perm] for r in rows])
    back, _ = load_static_csv(path, robot)
    np.testing.assert_array_equal(back.M, data.M)


# ------------------------------------------------------------------ loading errors
def test_csv_missing_column_is_named(tmp_path, panda_data):
    """A missing M3_2 column raises DataError naming it."""
    robot, data = panda_data
    path = save_static_data(tmp_path / "static.csv", data)
    comments, header, rows = _csv_table(path)
    k = header.index("M3_2")
    _write_csv(path, comments, header[:k] + header[k + 1 :], [r[:k] + r[k + 1 :] for r in rows])
    with pytest.raises(DataError, match=r"missing columns M3_2;"):
        load_static_csv(path, robot)


def test_csv_extra_and_duplicated_columns_are_named(tmp_path, panda_data):
    """An extra column 'temperature' or a duplicated g2 raises DataError naming it."""
    robot, data = panda_data
    path = save_static_data(tmp_path / "static.csv", data)
    comments, header, rows = _csv_table(path)
    _write_csv(path, comments, header + ["temperature"], [r + ["21.5"] for r in rows])
    with pytest.raises(DataError, match=r"unexpected columns temperature;"):
        load_static_csv(path, robot)
    _write_csv(path, comments, header + ["g2"], [r + ["0.0"] for r in rows])
    with pytest.raises(DataError, match=r"duplicated columns g2$"):
        load_static_csv(path, robot)


def test_csv_nan_non_number_and_short_row_name_line_row_and_column(tmp_path, panda_data):
    """Bad cells raise DataError with the line, the row and the column."""
    robot, data = panda_data
    path = save_static_data(tmp_path / "static.csv", data)
    comments, header, rows = _csv_table(path)
    first_line = len(comments) + 2  # 1-based line of data row 0
    for value, what in (("nan", "holds nan"), ("abc", "'abc' is not a number")):
        bad = [list(r) for r in rows]
        bad[4][header.index("g2")] = value
        _write_csv(path, comments, header, bad)
        with pytest.raises(
            DataError,
            match=rf"static.csv, line {first_line + 4}: row 4 column 'g2':? {what}",
        ):
            load_static_csv(path, robot)
    bad = [list(r) for r in rows]
    bad[7] = bad[7][:-1]
    _write_csv(path, comments, header, bad)
    with pytest.raises(
        DataError, match=rf"static.csv, line {first_line + 7}: row 7 has 41 cells, the header 42"
    ):
        load_static_csv(path, robot)


def test_wrong_joint_count_for_the_robot_is_rejected(tmp_path, panda_data):
    """Panda data (7 joints) loaded for a 2-joint robot: DataError from CSV and NPZ."""
    _, data = panda_data
    for suffix in (".csv", ".npz"):
        path = save_static_data(tmp_path / f"static{suffix}", data)
        with pytest.raises(DataError, match=r"data for 7 joints .* robot 'planar2r' has 2"):
            load_static_data(path, planar_2r())


def test_npz_non_symmetric_m_and_nan_name_the_row(tmp_path, panda_data):
    """NPZ rows with a non-symmetric M or a NaN raise DataError naming the first bad row."""
    robot, data = panda_data
    M = np.array(data.M)
    M[3, 0, 6] += 1e-3
    path = tmp_path / "static.npz"
    np.savez(path, q=data.q, M=M, g=data.g)
    with pytest.raises(DataError, match=r"row 3: M is not symmetric"):
        load_static_npz(path, robot)
    g = np.array(data.g)
    g[2, 5] = np.nan
    np.savez(path, q=data.q, M=M, g=g)
    with pytest.raises(DataError, match=r"row 2: g holds NaN or inf \(2 bad row\(s\) in all\)"):
        load_static_npz(path, robot)


def test_npz_missing_extra_and_misshaped_arrays_are_named(tmp_path, panda_data):
    """Missing 'g', an extra 't' or M of the wrong shape raise DataError naming the array."""
    robot, data = panda_data
    path = tmp_path / "static.npz"
    np.savez(path, q=data.q, M=data.M)
    with pytest.raises(DataError, match=r"missing arrays g;"):
        load_static_npz(path, robot)
    np.savez(path, q=data.q, M=data.M, g=data.g, t=np.arange(200.0))
    with pytest.raises(DataError, match=r"unexpected arrays t;"):
        load_static_npz(path, robot)
    np.savez(path, q=data.q, M=data.M[:, :6, :6], g=data.g)
    with pytest.raises(
        DataError, match=r"array 'M' must have shape \(200, 7, 7\); got \(200, 6, 6\)"
    ):
        load_static_npz(path, robot)
    np.savez(path, q=data.q, M=np.array([object()] * 3, dtype=object), g=data.g)
    with pytest.raises(DataError, match="array .M. holds Python objects .pickles refused."):
        load_static_npz(path, robot)


def test_drop_invalid_drops_and_reports_the_count(tmp_path, panda_data, caplog):
    """drop_invalid=True removes the 3 bad rows, returns 3, logs it and keeps the good rows."""
    robot, data = panda_data
    path = save_static_data(tmp_path / "static.csv", data)
    comments, header, rows = _csv_table(path)
    bad = [list(r) for r in rows]
    bad[1][header.index("q3")] = "nan"
    bad[50][header.index("M7_7")] = "oops"
    bad[199] = bad[199][:10]
    _write_csv(path, comments, header, bad)
    with caplog.at_level(logging.WARNING, logger="dynid.io.static_data"):
        back, dropped = load_static_csv(path, robot, drop_invalid=True)
    assert dropped == 3 and back.metadata["dropped_invalid_rows"] == 3
    assert "dropped 3 invalid row(s) of 200" in caplog.text
    keep = np.setdiff1d(np.arange(200), [1, 50, 199])
    np.testing.assert_array_equal(back.q, data.q[keep])
    np.testing.assert_array_equal(back.M, data.M[keep])
    # NPZ: a non-symmetric M and a NaN
    M, g = np.array(data.M), np.array(data.g)
    M[10, 2, 1] = 5.0
    g[20, 0] = np.inf
    npz = tmp_path / "static.npz"
    np.savez(npz, q=data.q, M=M, g=g)
    back, dropped = load_static_npz(npz, robot, drop_invalid=True)
    assert dropped == 2 and len(back) == 198
    # nothing valid left
    _write_csv(path, comments, header, [r[:3] for r in rows])
    with pytest.raises(DataError, match=r"no valid configuration \(200 invalid row\(s\)\)"):
        load_static_csv(path, robot, drop_invalid=True)


def test_unsupported_extension_and_missing_header_raise(tmp_path, panda_data):
    """A .txt file or a CSV without a header raise DataError."""
    _, data = panda_data
    with pytest.raises(DataError, match=r"must end in .csv or .npz; got 'static.txt'"):
        save_static_data(tmp_path / "static.txt", data)
    empty = tmp_path / "empty.csv"
    empty.write_text("# only a comment\n")
    with pytest.raises(DataError, match="no header line"):
        load_static_csv(empty)


# ------------------------------------------------------------------ model JSON
@pytest.fixture(scope="module")
def panda_model(panda_data):
    """A pruned static identification (some coefficients removed)."""
    robot, data = panda_data
    return robot, identify_static(robot, data, max_std_percent=2.0)


def test_model_json_round_trip_predicts_identically(tmp_path, panda_model):
    """The model read back gives bit-identical M, g, c, tau and the same coefficients."""
    robot, model = panda_model
    assert not model.fit.kept.all()  # pruning is part of what is saved
    path = save_model_json(tmp_path / "identification.json", model)
    back = load_model_json(path)
    q, dq, ddq = random_states(robot, 100, seed=203)
    np.testing.assert_array_equal(back.mass_matrix(q), model.mass_matrix(q))
    np.testing.assert_array_equal(back.gravity_torques(q), model.gravity_torques(q))
    np.testing.assert_array_equal(back.coriolis(q, dq), model.coriolis(q, dq))
    np.testing.assert_array_equal(back.torques(q, dq, ddq), model.torques(q, dq, ddq))
    for f in ("beta", "std", "kept"):
        np.testing.assert_array_equal(getattr(back.fit, f), getattr(model.fit, f))
    np.testing.assert_array_equal(np.isnan(back.fit.std_percent), np.isnan(model.fit.std_percent))
    for f in (
        "rank",
        "condition_number",
        "relative_error_percent",
        "residual_rms",
        "sigma",
        "n_rows",
        "scaled_condition_number",
    ):
        assert getattr(back.fit, f) == getattr(model.fit, f)
    assert back.base.expressions == model.base.expressions and back.base.gap == model.base.gap
    np.testing.assert_array_equal(back.base.K_d, model.base.K_d)
    assert back.info.dropped_rows == ("g1",)


def test_model_json_has_the_documented_keys_and_is_strict_json(tmp_path, panda_model):
    """Top-level keys and per-coefficient fields; no NaN/Infinity tokens."""
    _, model = panda_model
    path = save_model_json(tmp_path / "identification.json", model, seed=7)

    def bad(token):
        raise AssertionError(f"non-standard JSON token {token}")

    d = json.loads(path.read_text(), parse_constant=bad)
    for key in (
        "rank",
        "condition_number",
        "scaled_condition_number",
        "relative_error_percent",
        "dropped_rows",
        "coefficients",
        "dynid_version",
        "seed",
        "robot",
        "base",
        "route",
    ):
        assert key in d
    # rank of the fit: the kept coefficients (all 43 base parameters in "base")
    assert d["rank"] == int(model.fit.kept.sum()) < d["base"]["rank"] == 43
    assert d["dropped_rows"] == ["g1"] and d["seed"] == 7 and d["route"] == "static"
    assert d["dynid_version"] == dynid.__version__
    c = d["coefficients"]
    assert len(c) == 43 and set(c[0]) >= {"name", "expression", "value", "std_percent", "kept"}
    removed = [x for x in c if not x["kept"]]
    assert removed and all(x["value"] == 0.0 and x["std_percent"] is None for x in removed)


def test_model_json_errors_name_the_problem(tmp_path, panda_model):
    """Wrong schema, a missing field and invalid JSON raise DataError."""
    _, model = panda_model
    d = model_to_dict(model)
    with pytest.raises(DataError, match="key 'schema': expected 'dynid-identified-model/1'"):
        model_from_dict({**d, "schema": "something-else"})
    broken = dict(d)
    del broken["base"]
    with pytest.raises(DataError, match="key 'base': missing; expected an object"):
        model_from_dict(broken)
    path = tmp_path / "identification.json"
    path.write_text("{not json")
    with pytest.raises(DataError, match="identification.json: not a JSON file"):
        load_model_json(path)


def test_robot_json_round_trip_keeps_the_kinematics(panda_data):
    """Kinematic fields survive; forward kinematics are identical; inertia is not stored."""
    robot, _ = panda_data
    back = robot_from_dict(json.loads(json.dumps(robot_to_dict(robot))))
    for f in (
        "T_parent_joint",
        "axes",
        "prismatic",
        "q_min",
        "q_max",
        "dq_max",
        "ddq_max",
        "tau_max",
        "gravity",
    ):
        np.testing.assert_array_equal(getattr(back, f), getattr(robot, f))
    assert back.joint_names == robot.joint_names and back.link_names == robot.link_names
    assert set(back.frames) == set(robot.frames)
    q, _, _ = random_states(robot, 20, seed=204)
    np.testing.assert_array_equal(dynid.fk(back, q), dynid.fk(robot, q))
    np.testing.assert_array_equal(back.phi, 0.0)
    unlimited = robot_from_dict(robot_to_dict(planar_2r()))
    assert np.all(np.isneginf(unlimited.q_min)) and np.all(np.isposinf(unlimited.tau_max))
    with pytest.raises(DataError, match="key 'axes': missing; expected a 7 x 3 nested list"):
        robot_from_dict({k: v for k, v in robot_to_dict(robot).items() if k != "axes"})


def test_loaded_data_identify_like_the_original(tmp_path, panda_data):
    """Identification from the CSV equals that from the in-memory data set."""
    robot, data = panda_data
    back, _ = load_static_data(save_static_data(tmp_path / "s.csv", data), robot)
    a, b = identify_static(robot, data), identify_static(robot, back)
    np.testing.assert_array_equal(a.beta, b.beta)
    assert isinstance(back, StaticDataset)
