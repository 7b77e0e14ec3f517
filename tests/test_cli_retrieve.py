"""The ``dynid retrieve`` subcommand and the demo stage of the feasible-parameter retrieval.

References: the files are read back with the library's readers (feasible.json, URDF,
report.json) and compared with the identified model's torques.
"""

from __future__ import annotations

import contextlib
import io
import json

import numpy as np
import pytest

import dynid
from dynid.cli.__main__ import main
from dynid.feasibility.bounds import panda_bounds
from dynid.identification.data import StaticDataset
from dynid.identification.log import TorqueLog
from dynid.identification.model import IdentifiedModel
from dynid.io.bounds_file import save_bounds
from dynid.io.feasible import load_feasible_json
from dynid.io.friction_json import save_friction_json
from dynid.io.model_json import save_model_json
from dynid.io.static_data import save_static_data

from conftest import exact_model, random_states


def _model() -> IdentifiedModel:
    """Exact coefficients of the published Panda."""
    panda = dynid.panda()
    return exact_model(panda, panda)


@pytest.fixture(scope="module")
def model_file(tmp_path_factory):
    path = tmp_path_factory.mktemp("ident") / "identification.json"
    save_model_json(path, _model())
    return path


@pytest.fixture(scope="module")
def retrieved(model_file):
    """``dynid retrieve --method penalty`` (2 runs: exact coefficients are met by any run)
    of ``model_file``, run once for the tests that read its files: (output folder, exit
    code, stdout, stderr)."""
    out = model_file.parent / "feasible"
    argv = ["retrieve", "--method", "penalty", "--model", str(model_file), "--runs", "2"]
    stdout, stderr = io.StringIO(), io.StringIO()
    with contextlib.redirect_stdout(stdout), contextlib.redirect_stderr(stderr):
        rc = main([*argv, "--workers", "1", "--seed", "0", "--out", str(out)])
    return out, rc, stdout.getvalue(), stderr.getvalue()


def test_retrieve_writes_feasible_parameters_urdf_toml_and_report(retrieved):
    """dynid retrieve writes the four files, reports progress on stderr and a summary on stdout."""
    out, rc, stdout, stderr = retrieved
    assert rc == 0
    assert "run  2/2" in stderr and "FEASIBLE" in stdout
    for name in (
        "feasible.json",
        "robot.urdf",
        "robot.xml",
        "robot.toml",
        "report.json",
        "retrieval.png",
    ):
        assert (out / name).is_file(), name
    rep = json.loads((out / "report.json").read_text())
    assert rep["feasible"] and rep["relative_residual"] <= 1e-4 and rep["seed"] == 0
    robot = load_feasible_json(out / "feasible.json")
    model = _model()
    q, dq, ddq = random_states(robot, 200, 21)
    tau = model.torques(q, dq, ddq)
    np.testing.assert_allclose(dynid.rnea(robot, q, dq, ddq), tau, atol=1e-6 * np.abs(tau).max())
    for loaded in (
        dynid.Robot.from_urdf(out / "robot.urdf"),
        dynid.Robot.from_toml(out / "robot.toml"),
    ):
        np.testing.assert_allclose(loaded.phi, robot.phi, atol=1e-14)
    mujoco = pytest.importorskip("mujoco")
    mj = mujoco.MjModel.from_xml_path(str(out / "robot.xml"))  # feasible: MuJoCo compiles it
    np.testing.assert_allclose(mj.body_mass[2:], robot.mass, rtol=1e-12)


def test_retrieve_reports_a_contradictory_total_mass_band(model_file, tmp_path, capsys):
    """A total-mass band the coefficients rule out gives exit code 1 and feasible false."""
    out = tmp_path / "bad"
    rc = main(
        [
            "retrieve",
            "--method",
            "penalty",
            "--model",
            str(model_file),
            "--runs",
            "2",
            "--stages",
            "4",
            "--workers",
            "1",
            "--total-mass",
            "1,3",
            "--no-figures",
            "--out",
            str(out),
        ]
    )
    cap = capsys.readouterr()
    assert rc == 1 and "INFEASIBLE" in cap.out
    rep = json.loads((out / "report.json").read_text())
    assert rep["feasible"] is False and rep["total_mass"] == [1.0, 3.0]
    assert not json.loads((out / "feasible.json").read_text())["feasible"]


def test_retrieve_single_step_from_static_data_with_a_bounds_file(tmp_path, capsys):
    """--static with --bounds: the single-step variant on a static data file (exact data: two
    runs, each meets them)."""
    panda = dynid.panda()
    q = random_states(panda, 40, 22)[0]
    data = StaticDataset(q, dynid.mass_matrix(panda, q), dynid.gravity_torques(panda, q))
    static = save_static_data(tmp_path / "static.csv", data)
    bounds = save_bounds(tmp_path / "bounds.json", panda_bounds())
    out = tmp_path / "single"
    rc = main(
        [
            "retrieve",
            "--method",
            "penalty",
            "--static",
            str(static),
            "--robot",
            "panda",
            "--bounds",
            str(bounds),
            "--runs",
            "2",
            "--workers",
            "1",
            "--no-figures",
            "-q",
            "--out",
            str(out),
        ]
    )
    assert rc == 0 and capsys.readouterr().out == ""
    rep = json.loads((out / "report.json").read_text())
    assert rep["kind"] == "static" and rep["feasible"] and rep["relative_residual"] <= 1e-4


@pytest.mark.parametrize(
    "extra, match",
    [
        ([], "not a JSON file"),
        (["--method", "penalty", "--runs", "0"], "--runs"),
        (["--prior", "missing.urdf"], "does not exist"),
        (["--prior-weight", "-2"], "--prior-weight: must be a finite number > 0"),
        (["--prior-weight", "0"], "--prior-weight: must be a finite number > 0"),
        (["--total-mass", "5,1"], "--total-mass"),
    ],
)
def test_retrieve_error_is_one_line_with_exit_code_2(model_file, tmp_path, capsys, extra, match):
    """A malformed model file or bad options give a one-line error and exit code 2."""
    path = model_file
    if not extra:
        path = tmp_path / "identification.json"
        path.write_text("{not json")
    rc = main(["retrieve", "--model", str(path), "--out", str(tmp_path / "o")] + extra)
    err = capsys.readouterr().err
    assert rc == 2 and err.startswith("dynid retrieve: error:") and match in err
    assert len(err.strip().splitlines()) == 1


def test_demo_feasible_stage_retrieves_validates_and_writes_its_files(tmp_path, monkeypatch):
    """The demo's stage 4 (library): feasible parameters validated by Newton-Euler against a
    log; the CLI writes the exports and the validation. Two retrieval runs instead of the
    default ten (exact coefficients are met by any run; the demo test runs the default)."""
    import functools

    import dynid.pipeline.stages as stages
    from dynid.cli.demo_stages import format_feasible_stage, save_feasible_stage
    from dynid.feasibility.penalty import RetrievalOptions
    from dynid.pipeline import feasible_stage

    short = RetrievalOptions(runs=2)
    monkeypatch.setattr(stages, "retrieve", functools.partial(stages.retrieve, options=short))

    panda = dynid.panda()
    rng = np.random.default_rng(23)
    t = np.arange(400) * 1e-3
    q, dq, ddq = random_states(panda, 1, 23)
    q = q + 0.2 * np.sin(2 * np.pi * t)[:, None]
    dq = np.broadcast_to(0.2 * 2 * np.pi * np.cos(2 * np.pi * t)[:, None], q.shape).copy()
    ddq = np.broadcast_to(-0.2 * (2 * np.pi) ** 2 * np.sin(2 * np.pi * t)[:, None], q.shape).copy()
    fr = panda.friction
    tau = dynid.rnea(panda, q, dq, ddq) + fr.torques(dq) + rng.normal(0, 0.01, q.shape)
    log = TorqueLog(t, q, dq, tau, ddq)
    runs = []
    out = feasible_stage(_model(), log, fr, seed=0, progress=runs.append)
    assert out.feasible and out.relative_residual <= 1e-4
    assert out.max_torque_difference < 1e-6
    assert np.all(out.rms_newton_euler < 0.05)
    assert out.retrieval.options.runs == 2 == len(runs) and runs[-1].done == runs[-1].total
    assert "RMS NE" in format_feasible_stage(out)
    files = save_feasible_stage(tmp_path / "demo", out)
    assert {f.name for f in files} >= {"feasible.json", "robot.urdf", "feasible_validation.json"}
    for f in files:
        assert (tmp_path / "demo" / f.name).is_file()


def test_validate_with_retrieved_parameters_uses_rnea(retrieved, tmp_path):
    """dynid validate --params feasible.json validates RNEA with the retrieved parameters."""
    out, rc, _, _ = retrieved
    assert rc == 0
    log = tmp_path / "log.npz"
    assert (
        main(
            [
                "simulate",
                "--trajectory",
                "fourier",
                "--duration",
                "6",
                "--seed",
                "4",
                "--out",
                str(log),
                "-q",
            ]
        )
        == 0
    )
    val = tmp_path / "val"
    assert (
        main(
            [
                "validate",
                "--params",
                str(out / "feasible.json"),
                "--data",
                str(log),
                "--out",
                str(val),
                "--no-figures",
                "-q",
            ]
        )
        == 0
    )
    d = json.loads((val / "validation.json").read_text())
    assert len(d["rms"]) == 7 and len(d["mse"]) == 7
    assert max(d["rms"]) > 0.1  # the log carries friction that this model lacks
    # with the published sigmoid friction the residual falls to the sensor noise (0.05 N m)
    fr = tmp_path / "friction.json"
    save_friction_json(fr, dynid.panda().friction)
    assert (
        main(
            [
                "validate",
                "--params",
                str(out / "feasible.json"),
                "--friction",
                str(fr),
                "--data",
                str(log),
                "--out",
                str(val),
                "--no-figures",
                "-q",
            ]
        )
        == 0
    )
    d = json.loads((val / "validation.json").read_text())
    assert max(d["rms"]) < 0.1


def test_retrieve_sdp_default_with_a_prior_writes_consistent_files(model_file, tmp_path, capsys):
    """--method sdp (default) with --prior panda: exact coefficients met, margins in report.json."""
    out = tmp_path / "sdp"
    rc = main(["retrieve", "--model", str(model_file), "--prior", "panda", "--out", str(out)])
    cap = capsys.readouterr()
    assert rc == 0 and "CONSISTENT" in cap.out
    rep = json.loads((out / "report.json").read_text())
    assert rep["method"] == "sdp" and rep["fit"] == "equality" and rep["feasible"]
    assert rep["relative_residual"] <= 1e-9
    assert min(rep["pseudo_inertia_margin"]) >= 1e-4 * (1 - 1e-9)
    assert rep["prior"]["source"] == "panda" and rep["status"] == "optimal"
    robot = load_feasible_json(out / "feasible.json")
    q, dq, ddq = random_states(robot, 100, 23)
    tau = _model().torques(q, dq, ddq)
    np.testing.assert_allclose(dynid.rnea(robot, q, dq, ddq), tau, atol=1e-8 * np.abs(tau).max())
    assert dynid.Robot.from_urdf(out / "robot.urdf").n == 7


def test_identify_consistent_on_a_log_writes_both_models_and_validate_uses_its_friction(
    tmp_path, capsys
):
    """identify --consistent: identification.json + feasible.json with linear friction (fv, fc
    >= 0), which validate --params uses (the structure fixed: the search is not the case)."""
    from dynid.io.feasible import load_feasible_linear_friction
    from dynid.io.torque_log import save_torque_log
    from dynid.simulation.measurement import sample_times, simulate_measurement
    from dynid.simulation.trajectories import random_fourier

    panda = dynid.panda()
    rng = np.random.default_rng(31)
    traj = random_fourier(panda, rng, n_harmonics=5)(sample_times(12.0, 500.0))
    log = simulate_measurement(panda, traj, rng=rng)
    path = save_torque_log(tmp_path / "log.csv", log)
    out = tmp_path / "c"
    argv = ["identify", "--data", str(path), "--consistent", "--prior", "panda"]
    argv += ["--terms", "viscous,coulomb,offset"]
    rc = main([*argv, "--no-figures", "--out", str(out)])  # (the figures are not read)
    cap = capsys.readouterr()
    assert rc == 0, cap.err
    for name in ("identification.json", "feasible.json", "robot.urdf", "report.json"):
        assert (out / name).is_file(), name
    fr = load_feasible_linear_friction(out / "feasible.json")
    assert fr is not None and np.all(fr.fv >= -1e-9) and np.all(fr.fc >= -1e-9)
    rep = json.loads((out / "report.json").read_text())
    assert rep["kind"] == "log" and rep["feasible"] and rep["friction"] is not None
    rc = main(
        [
            "validate",
            "--params",
            str(out / "feasible.json"),
            "--data",
            str(path),
            "--no-figures",
            "--out",
            str(tmp_path / "v"),
        ]
    )
    assert rc == 0
    val = json.loads((tmp_path / "v" / "validation.json").read_text())
    assert val["friction_source"] == "model"
    assert (
        val["with_friction"]["relative_error_percent"]
        < val["without_friction"]["relative_error_percent"]
    )


def test_consistent_routes_fail_in_one_line_and_write_nothing(tmp_path, capsys):
    """Rank-deficient static data, a contradictory mass band, a prior of another arm: exit 2,
    one line, no output folder."""
    panda = dynid.panda()
    q = random_states(panda, 1, 24)[0]
    few = save_static_data(
        tmp_path / "few.csv",
        StaticDataset(q, dynid.mass_matrix(panda, q), dynid.gravity_torques(panda, q)),
    )
    q = random_states(panda, 60, 25)[0]
    ok = save_static_data(
        tmp_path / "ok.csv",
        StaticDataset(q, dynid.mass_matrix(panda, q), dynid.gravity_torques(panda, q)),
    )
    cases = [
        (["identify", "--data", str(few), "--consistent"], "rank"),
        (
            ["identify", "--data", str(ok), "--consistent", "--total-mass", "100,120"],
            "cannot be met",
        ),
        (["retrieve", "--static", str(ok), "--total-mass", "100,120"], "cannot be met"),
        (
            ["identify", "--data", str(ok), "--consistent", "--prior", "missing.toml"],
            "does not exist",
        ),
    ]
    for k, (argv, match) in enumerate(cases):
        out = tmp_path / f"out{k}"
        rc = main(argv + ["--out", str(out)])
        err = capsys.readouterr().err
        assert rc == 2 and match in err and len(err.strip().splitlines()) == 1, (argv, err)
        assert not out.exists(), argv


def test_a_friction_file_for_a_model_with_its_own_friction_is_refused(tmp_path, capsys):
    """A model identified from torque logs holds friction identified with the links, which
    feasible.json and the exports carry: a friction.json beside it was dropped without a
    word; it is refused in one line naming the option, before any work."""
    from dynid.friction.model import ClassicalFriction
    from dynid.identification.selection import identify_recordings
    from dynid.identification.structure import Structure

    from conftest import recordings

    panda = dynid.panda()
    fr = ClassicalFriction(np.full(7, 0.2), np.full(7, 0.5), np.zeros(7))
    logs = recordings(panda, (5, 6), friction=fr, duration=3.0)
    model = identify_recordings(panda, logs, structure=Structure(False, ("viscous", "coulomb")))
    path = save_model_json(tmp_path / "identification.json", model)
    sig = save_friction_json(tmp_path / "friction.json", panda.friction)
    argv = ["retrieve", "--model", str(path), "--friction", str(sig), "--out", str(tmp_path / "o")]
    assert main(argv) == 2
    err = capsys.readouterr().err.strip().splitlines()
    assert len(err) == 1 and "--friction applies to a model without friction" in err[0], err
    assert (
        "classical friction identified with the links" in err[0] and not (tmp_path / "o").exists()
    )
