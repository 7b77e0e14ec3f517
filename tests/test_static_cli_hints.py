"""What the static route's messages tell at the command line: the options they name exist
there (--drop-invalid with retrieve --static), the NPZ reader names the option not the
Python argument, data read through --columns take --drop-invalid, and the penalty method's
summary does not credit a prior it has none of.

References: Pinocchio's M(q) (crba) and g(q) on example-robot-data's Panda holding dynid's
Panda inertials; the row made NaN is known by construction.
"""

from __future__ import annotations

import numpy as np

import dynid
from dynid.cli.__main__ import main
from dynid.io.model_json import load_model_json
from dynid.io.static_data import static_columns

from conftest import pinocchio_panda_static


def _truth(seed: int, N: int):
    """Pinocchio's exact ``(q, M, g)`` at ``N`` random configurations within the limits."""
    return pinocchio_panda_static(seed, N)


def _err_lines(capsys) -> list[str]:
    return [ln for ln in capsys.readouterr().err.splitlines() if "error:" in ln]


def test_retrieve_static_takes_the_drop_invalid_its_hint_names(tmp_path, capsys, caplog):
    """Regression: retrieve --static hinted --drop-invalid and refused it."""
    q, M, g = _truth(21, 60)
    M[17, 2, 1] = M[17, 1, 2] = np.nan
    i, j = np.tril_indices(7)
    table = np.concatenate([q, M[:, i, j], g], axis=1)
    header = ",".join(static_columns(7))
    np.savetxt(tmp_path / "s.csv", table, delimiter=",", header=header, comments="")
    argv = ["retrieve", "--robot", "panda", "--static", str(tmp_path / "s.csv")]
    assert main([*argv, "--out", str(tmp_path / "a")]) == 2
    said = _err_lines(capsys)
    assert len(said) == 1 and "pass --drop-invalid" in said[0]
    assert main([*argv, "--out", str(tmp_path / "b"), "--drop-invalid", "--no-figures"]) == 0
    assert "dropped 1 invalid row(s) of 60: line 19 (row 17)" in caplog.text
    argv = ["retrieve", "--model", str(tmp_path / "x.json"), "--drop-invalid"]
    assert main([*argv, "--out", str(tmp_path / "c")]) == 2
    assert "--drop-invalid applies to --static only" in _err_lines(capsys)[0]


def test_npz_and_mapped_static_data_name_the_option(tmp_path, capsys, caplog):
    """Regression: the NPZ reader said 'load with drop_invalid=True' at the command line;
    a file read through --columns took no --drop-invalid. Both now name and take it."""
    q, M, g = _truth(22, 60)
    M[5, 3, 3] = np.inf
    np.savez(tmp_path / "s.npz", q=q, M=M, g=g)
    argv = ["identify", "--robot", "panda", "--data", str(tmp_path / "s.npz")]
    assert main([*argv, "--out", str(tmp_path / "a")]) == 2
    said = _err_lines(capsys)[0]
    assert "pass --drop-invalid" in said and "drop_invalid=True" not in said
    i = np.arange(7)
    names = [f"q{k}" for k in i] + [f"M{k}" for k in range(49)] + [f"g{k}" for k in i]
    table = np.concatenate([q, M.transpose(0, 2, 1).reshape(60, 49), g], axis=1)
    np.savetxt(tmp_path / "f.csv", table, delimiter=",", header=",".join(names), comments="")
    argv = ["identify", "--robot", "panda", "--data", str(tmp_path / "f.csv")]
    argv += ["--columns", "q=q{i0},M=M{k0},g=g{i0}"]
    assert main([*argv, "--out", str(tmp_path / "b")]) == 2
    said = _err_lines(capsys)[0]
    assert "row 5 (line 7)" in said and "pass --drop-invalid" in said
    assert main([*argv, "--out", str(tmp_path / "c"), "--drop-invalid"]) == 0
    assert "dropped 1 row(s) holding NaN or inf of 60: row 5 (line 7)" in caplog.text
    model = load_model_json(tmp_path / "c" / "identification.json")
    qh, Mh, gh = _truth(23, 5)
    np.testing.assert_allclose(model.mass_matrix(qh), Mh, atol=1e-9)
    np.testing.assert_allclose(model.gravity_torques(qh), gh, atol=1e-8)


def test_penalty_summary_does_not_credit_a_prior(tmp_path, capsys):
    """Regression: the penalty method's '~' read 'set by the prior'; it uses none."""
    q, M, g = _truth(24, 60)
    dynid.io.save_static_data(tmp_path / "s.csv", dynid.StaticDataset(q, M, g))
    assert main(["identify", "--robot", "panda", "--data", str(tmp_path / "s.csv"),
                 "--out", str(tmp_path / "m")]) == 0  # fmt: skip
    capsys.readouterr()
    argv = ["retrieve", "--model", str(tmp_path / "m" / "identification.json"), "--method"]
    argv += ["penalty", "--runs", "1", "--stages", "1", "--workers", "1", "--no-figures"]
    main([*argv, "--out", str(tmp_path / "p")])
    out = capsys.readouterr().out
    mark = [ln for ln in out.splitlines() if ln.startswith("~ ")]
    assert len(mark) == 1 and "prior" in mark[0]
    assert "set by the prior" not in mark[0] and "uses no prior" in mark[0]
