"""`dynid acquire-static`, `identify` and `predict` through main(argv) in a temporary folder."""

from __future__ import annotations

import json

import numpy as np
import pytest

import dynid
from dynid.cli.__main__ import main
from dynid.cli.demo_stages import save_identification_stage
from dynid.cli.summaries import format_identification
from dynid.pipeline import identification_stage

from conftest import random_states


@pytest.fixture(scope="module")
def identified(tmp_path_factory):
    """acquire-static (noise-free, CSV) then identify; returns the folder."""
    tmp = tmp_path_factory.mktemp("cli")
    assert (
        main(
            [
                "acquire-static",
                "--robot",
                "panda",
                "--n",
                "300",
                "--seed",
                "3",
                "--out",
                str(tmp / "static.csv"),
            ]
        )
        == 0
    )
    assert (
        main(
            [
                "identify",
                "--robot",
                "panda",
                "--data",
                str(tmp / "static.csv"),
                "--out",
                str(tmp / "res"),
            ]
        )
        == 0
    )
    return tmp


def _one_error_line(capsys) -> str:
    err = capsys.readouterr().err.strip().splitlines()
    assert len(err) == 1, err
    return err[0]


def test_acquire_identify_writes_identification_json_with_the_keys(identified):
    """identification.json holds rank 43, the metrics, g1 dropped and 43 coefficients."""
    d = json.loads((identified / "res" / "identification.json").read_text())
    assert d["rank"] == 43 and d["dropped_rows"] == ["g1"] and d["route"] == "static"
    assert d["relative_error_percent"] < 1e-8 and 1.0 < d["condition_number"] < 100.0
    assert d["seed"] == 3
    c = d["coefficients"]
    assert len(c) == 43 and all(
        {"name", "expression", "value", "std_percent", "kept"} <= set(x) for x in c
    )
    # exact data: the coefficients are those of the published parameters
    robot = dynid.panda()
    from dynid.regressors.base import base_parameters

    true = base_parameters(robot).beta_from_phi(robot.phi)
    np.testing.assert_allclose(
        [x["value"] for x in c], true, rtol=0, atol=1e-9 * np.abs(true).max()
    )


def test_identify_prints_a_summary_table(tmp_path, identified, capsys):
    """The summary names the rank, the dropped row and one line per coefficient."""
    assert main(["identify", "--data", str(identified / "static.csv"), "--out", str(tmp_path)]) == 0
    out = capsys.readouterr().out
    assert "rank 43" in out and "dropped rows g1" in out
    assert (
        sum(line.strip().startswith(f"{k} ") for line in out.splitlines() for k in range(1, 44))
        == 43
    )


def test_predict_json_gives_m_g_and_with_dq_ddq_c_tau(identified, capsys):
    """predict --json: M (7x7), g (7); with --dq/--ddq also c and tau, equal to the truth."""
    robot = dynid.panda()
    q, dq, ddq = random_states(robot, 1, seed=301)
    vec = lambda v: ",".join(repr(float(x)) for x in v)  # noqa: E731
    model = str(identified / "res" / "identification.json")
    capsys.readouterr()
    assert main(["predict", "--model", model, f"--q={vec(q[0])}", "--json"]) == 0
    d = json.loads(capsys.readouterr().out)
    assert set(d) == {"M", "g"}
    assert np.shape(d["M"]) == (7, 7) and np.shape(d["g"]) == (7,)
    np.testing.assert_allclose(d["M"], dynid.mass_matrix(robot, q[0]), atol=1e-9)
    assert (
        main(
            [
                "predict",
                "--model",
                model,
                f"--q={vec(q[0])}",
                f"--dq={vec(dq[0])}",
                f"--ddq={vec(ddq[0])}",
                "--json",
            ]
        )
        == 0
    )
    d = json.loads(capsys.readouterr().out)
    assert set(d) == {"M", "g", "c", "tau"}
    np.testing.assert_allclose(d["g"], dynid.gravity_torques(robot, q[0]), atol=1e-9)
    np.testing.assert_allclose(d["c"], dynid.coriolis(robot, q[0], dq[0]), atol=1e-9)
    np.testing.assert_allclose(d["tau"], dynid.rnea(robot, q[0], dq[0], ddq[0]), atol=1e-8)
    assert main(["predict", "--model", model, f"--q={vec(q[0])}"]) == 0
    text = capsys.readouterr().out
    assert "M(q) [kg m^2]" in text and "g(q) [N m]" in text
    assert main(["predict", "--params", model, f"--q={vec(q[0])}"]) == 2  # the other file
    assert capsys.readouterr().err.rstrip().endswith("hint: --model reads identification.json")


def test_predict_takes_feasible_parameters(tmp_path, capsys):
    """Regression: ``predict --model feasible.json`` was refused ("expected
    'dynid-identified-model/1'") and predict had no other source; ``--params feasible.json``
    gives the feasible robot's M, g, c and tau (the Panda's, written as feasible.json);
    a drive's rotor inertias add ``diag(I_a)`` through a gear ratio of 1."""
    import dataclasses

    from dynid.io.feasible import save_feasible_json
    from dynid.model.drive import Drive
    from dynid.workflows.predict import model_terms

    robot = dynid.panda()
    path = save_feasible_json(tmp_path / "feasible.json", robot)
    q, dq, ddq = random_states(robot, 1, seed=302)
    vec = lambda v: ",".join(repr(float(x)) for x in v)  # noqa: E731
    argv = ["predict", "--params", str(path), f"--q={vec(q[0])}", f"--dq={vec(dq[0])}"]
    assert main([*argv, f"--ddq={vec(ddq[0])}", "--json"]) == 0
    d = json.loads(capsys.readouterr().out)
    np.testing.assert_allclose(d["M"], dynid.mass_matrix(robot, q[0]), atol=1e-12)
    np.testing.assert_allclose(d["tau"], dynid.rnea(robot, q[0], dq[0], ddq[0]), atol=1e-10)
    ia = np.linspace(0.1, 0.4, 7)
    drive = dataclasses.replace(Drive.identity(7), rotor_inertia=ia)
    got = model_terms(robot, q[0], dq[0], ddq[0], drive)
    np.testing.assert_allclose(got["M"], dynid.mass_matrix(robot, q[0]) + np.diag(ia), atol=1e-12)
    want = dynid.rnea(robot, q[0], dq[0], ddq[0]) + ia * ddq[0]
    np.testing.assert_allclose(got["tau"], want, atol=1e-10)
    assert main(["predict", "--model", str(path), f"--q={vec(q[0])}"]) == 2  # the schema said
    assert capsys.readouterr().err.rstrip().endswith("hint: --params reads feasible.json")


def test_npz_route_and_pruning_option(tmp_path, capsys):
    """acquire-static to .npz with noise, identify with --max-std-percent: pruned ones recorded."""
    npz = tmp_path / "static.npz"
    assert (
        main(["acquire-static", "--n", "200", "--noise", "1e-2", "--seed", "4", "--out", str(npz)])
        == 0
    )
    assert (
        main(
            ["identify", "--data", str(npz), "--out", str(tmp_path / "r"), "--max-std-percent", "5"]
        )
        == 0
    )
    d = json.loads((tmp_path / "r" / "identification.json").read_text())
    pruned = [x["name"] for x in d["coefficients"] if not x["kept"]]
    assert pruned and d["pruned"] == pruned and d["rank"] == 43 - len(pruned)


def test_bad_inputs_exit_non_zero_with_one_stderr_line(tmp_path, identified, capsys):
    """Missing file, malformed logs, bad vector, --ddq without --dq, bad suffix: exit 2."""
    model = str(identified / "res" / "identification.json")
    capsys.readouterr()
    assert main(["identify", "--data", str(tmp_path / "nope.csv"), "--out", str(tmp_path)]) == 2
    assert "nope.csv" in _one_error_line(capsys)
    log = tmp_path / "log.csv"
    log.write_text("t,q1,q2,q3,q4,q5,q6,q7,tau1\n0.0,0,0,0,0,0,0,0,0\n")
    assert main(["identify", "--data", str(log), "--out", str(tmp_path)]) == 2
    # positions only are accepted (velocities derived), the missing torques are not
    assert "missing column(s) tau2..tau7" in _one_error_line(capsys)
    npz = tmp_path / "log.npz"
    np.savez(npz, t=np.arange(3.0), tau=np.zeros((3, 7)))
    assert main(["identify", "--data", str(npz), "--out", str(tmp_path)]) == 2
    assert "missing array(s) q;" in _one_error_line(capsys)
    assert main(["predict", "--model", model, "--q=0,0,0"]) == 2
    assert "--q must have 7 values; got 3" in _one_error_line(capsys)
    assert main(["predict", "--model", model, "--q=0,0,0,-1,0,1,0", "--ddq=0,0,0,0,0,0,0"]) == 2
    assert "--ddq needs --dq" in _one_error_line(capsys)
    assert main(["acquire-static", "--n", "10", "--out", str(tmp_path / "x.txt")]) == 2
    assert "must end in .csv or .npz" in _one_error_line(capsys)
    bad = tmp_path / "bad.csv"
    text = (identified / "static.csv").read_text().splitlines()
    text[5] = text[5].replace(text[5].split(",")[3], "nan", 1)
    bad.write_text("\n".join(text) + "\n")
    assert main(["identify", "--data", str(bad), "--out", str(tmp_path)]) == 2
    line = _one_error_line(capsys)
    assert "pass --drop-invalid to drop" in line and "drop_invalid=True" not in line
    assert (
        main(["identify", "--data", str(bad), "--out", str(tmp_path / "ok"), "--drop-invalid"]) == 0
    )


def test_demo_identification_stage_returns_the_key_numbers_and_writes_its_files(tmp_path):
    """The demo's stage 2 (library) gives rank, cond, errors; the CLI writes data and model."""
    out = identification_stage(dynid.panda(), seed=5)
    assert out.rank == 43 and out.n_configurations == 1010 and out.dropped_rows == ["g1"]
    assert out.relative_error_percent < 0.05 and out.max_error_in_std < 5.0
    files = save_identification_stage(tmp_path, out)
    assert files == [tmp_path / "static.csv", tmp_path / "identification.json"]
    assert (tmp_path / "static.csv").exists() and (tmp_path / "identification.json").exists()
    assert "rank 43" in format_identification(out.model)
