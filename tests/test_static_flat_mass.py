"""Static data as libfranka dumps it: q0..q6, the mass matrix as one flat column-major
array M0..M48, g0..g6; and the templates of M that cannot read a matrix.

References: Pinocchio's M(q) (crba) and g(q) on example-robot-data's Panda holding dynid's
Panda inertials, written column-major as libfranka's ``std::array<double, 49>``.
"""

from __future__ import annotations

import numpy as np
import pytest

import dynid
from dynid.cli.__main__ import main
from dynid.exceptions import DataError
from dynid.io.columns import load_mapped_static_data, parse_column_map
from dynid.io.static_data import load_static_data

from conftest import pinocchio_panda_static


def _libfranka_csv(path, seed: int, N: int = 6, first: int = 0):
    """A libfranka-style dump of Pinocchio's M and g at ``N`` random configurations:
    ``q{first}..``, ``M{first}..M{first + 48}`` column-major, ``g{first}..``; returns the
    truth ``(q, M, g)``."""
    q, M, g = pinocchio_panda_static(seed, N, margin=0.9)
    names = (
        [f"q{i + first}" for i in range(7)]
        + [f"M{k + first}" for k in range(49)]
        + [f"g{i + first}" for i in range(7)]
    )
    flat = M.transpose(0, 2, 1).reshape(N, 49)  # column-major: k = i + 7 j
    table = np.concatenate([q, flat, g], axis=1)
    np.savetxt(path, table, delimiter=",", header=",".join(names), comments="", fmt="%.17g")
    return q, M, g


@pytest.mark.parametrize("tpl", ["M{i0}", "M{j0}", "M{i}", "M_{k0}_{i0}"])
def test_a_mass_template_without_row_and_column_is_refused(tpl):
    """Regression: M=M{i0} filled a whole row of M from one column, silently (74 % error)."""
    with pytest.raises(DataError, match=r"a template of M needs a row and a column index.*M\{k0\}"):
        parse_column_map(f"q=q{{i0}},M={tpl},g=g{{i0}}")


def test_cli_refuses_a_one_index_mass_template_in_one_line(tmp_path, capsys):
    """identify with M=M{i0} exits 2 with one line naming the flat template that reads M."""
    _libfranka_csv(tmp_path / "franka.csv", 1)
    argv = ["identify", "--data", str(tmp_path / "franka.csv"), "--out", str(tmp_path / "o")]
    assert main(argv + ["--columns", "q=q{i0},M=M{i0},g=g{i0}"]) == 2
    err = [ln for ln in capsys.readouterr().err.splitlines() if "error" in ln]
    assert len(err) == 1 and "M=M{k0}" in err[0]


@pytest.mark.parametrize(("tpl", "first"), [("M{k0}", 0), ("M{k}", 1)])
def test_flat_column_major_mass_reads_pinocchio_truth(tmp_path, tpl, first):
    """M=M{k0} (M=M{k} from 1) reads libfranka's flat array as Pinocchio's M(q)."""
    q, M, g = _libfranka_csv(tmp_path / "franka.csv", 2, first=first)
    field = "{i0}" if first == 0 else "{i}"
    cmap = parse_column_map(f"q=q{field},M={tpl},g=g{field}")
    got = load_mapped_static_data(tmp_path / "franka.csv", cmap, dynid.panda()).data
    np.testing.assert_array_equal(got.q, q)
    np.testing.assert_array_equal(got.M, M)
    np.testing.assert_array_equal(got.g, g)


@pytest.mark.parametrize(("tpl", "column"), [("M{k0}", "M1"), ("M{i0}_{j0}", "M1_0")])
def test_a_full_matrix_is_checked_for_symmetry(tmp_path, tpl, column):
    """Both triangles read: an entry that differs from its mirror is refused, not mirrored
    away (M[1, 0] != M[0, 1])."""
    q, M, g = _libfranka_csv(tmp_path / "franka.csv", 3)
    if tpl != "M{k0}":  # the same matrix under row, column names
        names = [f"q{i}" for i in range(7)] + [f"M{i}_{j}" for j in range(7) for i in range(7)]
        names += [f"g{i}" for i in range(7)]
        flat = M.transpose(0, 2, 1).reshape(len(q), 49)
        table = np.concatenate([q, flat, g], axis=1)
        np.savetxt(tmp_path / "franka.csv", table, delimiter=",", header=",".join(names),
                   comments="", fmt="%.17g")  # fmt: skip
    text = (tmp_path / "franka.csv").read_text().splitlines()
    header = text[0].split(",")
    row = text[1].split(",")
    k = header.index(column)
    row[k] = repr(float(row[k]) + 0.05)
    (tmp_path / "franka.csv").write_text("\n".join([text[0], ",".join(row), *text[2:]]) + "\n")
    cmap = parse_column_map(f"q=q{{i0}},M={tpl},g=g{{i0}}")
    with pytest.raises(DataError, match="M must be symmetric; row 0"):
        load_mapped_static_data(tmp_path / "franka.csv", cmap, dynid.panda())


def test_libfranka_header_is_hinted_the_map_that_reads_it(tmp_path):
    """Regression: q0..q6 read as 'data for 6 joints (columns q1..q6)'; the hint is the
    map, and the map it gives reads Pinocchio's M and g."""
    q, M, g = _libfranka_csv(tmp_path / "franka.csv", 4)
    robot = dynid.panda()
    with pytest.raises(DataError, match=r"q0\.\.q6, M0\.\.M48, g0\.\.g6") as info:
        load_static_data(tmp_path / "franka.csv", robot)
    said = str(info.value)
    assert "6 joints" not in said
    spec = said.split("--columns '")[1].split("'")[0]
    assert spec == "q=q{i0},M=M{k0},g=g{i0}"
    got = load_mapped_static_data(tmp_path / "franka.csv", parse_column_map(spec), robot).data
    np.testing.assert_array_equal(got.M, M)
    np.testing.assert_array_equal(got.g, g)
    partial = parse_column_map("q=q{i0},g=g{i0}")  # M forgotten: its error hints the map
    with pytest.raises(DataError, match=r"no column 'M1_1'.*--columns 'q=q\{i0\},M=M\{k0\}"):
        load_mapped_static_data(tmp_path / "franka.csv", partial, robot)
