"""Messages that tell the truth and refusals in one line (a reliability campaign of the
command line): an interrupt while the modules load, solver failures at extreme prior
weights, options of the other retrieval method, single-file outputs that are not dynid's,
an unwritable --out, too short logs, --columns, --cutoff above Nyquist, tab-separated
files, and smaller wording defects."""

from __future__ import annotations

import importlib
import os
import subprocess
import sys
import textwrap

import numpy as np
import pytest

import dynid
from dynid.cli.__main__ import main
from dynid.exceptions import OptionError, SolverError
from dynid.feasibility.compare import perturbed_robot
from dynid.feasibility.convex import SDPOptions, retrieve_sdp
from dynid.feasibility.prior import prior_from_robot
from dynid.io.model_json import save_model_json
from dynid.workflows.retrieve import RetrieveOptions

from conftest import exact_model


def _env() -> dict[str, str]:
    return {**os.environ, "MPLBACKEND": "Agg", "OPENBLAS_NUM_THREADS": "1"}


# ---------------------------------------------------------------------- Ctrl-C at start-up
def test_the_entry_module_imports_no_library_module():
    """What the console script imports before ``main`` runs is the standard library
    alone: an interrupt there could not be caught."""
    code = (
        "import sys, dynid.cli.__main__\n"
        "print(sorted(m for m in sys.modules if m in ('numpy', 'scipy')))"
    )
    out = subprocess.run(
        [sys.executable, "-c", code], capture_output=True, text=True, env=_env(), check=True
    )
    assert out.stdout.strip() == "[]"


def test_ctrl_c_while_the_modules_load_is_one_line_and_exit_130(tmp_path):
    """SIGINT delivered while numpy is being imported (inside ``main``, as the console
    script runs it): one line naming the command, exit 130, no traceback, no output."""
    script = textwrap.dedent(
        """
        import os, signal, sys
        class Interrupt:
            def find_spec(self, name, path=None, target=None):
                if name == "numpy":
                    sys.meta_path.remove(self)
                    os.kill(os.getpid(), signal.SIGINT)
                return None
        sys.meta_path.insert(0, Interrupt())
        from dynid.cli.__main__ import main
        sys.argv = ["dynid", "acquire-static", "--n", "5", "--out", sys.argv[1]]
        sys.exit(main())
        """
    )
    out = tmp_path / "s.csv"
    r = subprocess.run(
        [sys.executable, "-c", script, str(out)], capture_output=True, text=True, env=_env()
    )
    assert r.returncode == 130
    assert r.stderr.splitlines() == ["dynid acquire-static: interrupted; no partial output left"]
    assert not out.exists()


# ---------------------------------------------------------------------- huge prior weights
@pytest.fixture(scope="module")
def noisy_panda_model():
    """Coefficients of noisy static data of the Panda (a weighted convex fit) and a
    perturbed Panda as the prior (which the data do not fit)."""
    robot = dynid.panda()
    ctl = dynid.SimulatedController(robot, relative_noise=1e-4, rng=np.random.default_rng(51))
    data = dynid.acquire_static(ctl, 200, np.random.default_rng(52))
    prior = perturbed_robot(robot, np.random.default_rng(3), spread=0.2)
    return dynid.identify_static(robot, data), prior


@pytest.mark.parametrize("weight", [1e200, 1e308])
def test_an_overwhelming_prior_weight_returns_the_prior(noisy_panda_model, weight):
    """As the weight grows the minimiser tends to the prior itself (it meets the
    constraints): any finite weight is solved, to the prior within the solver's tolerance."""
    model, prior = noisy_panda_model
    res = retrieve_sdp(model, prior=prior, options=SDPOptions(prior_weight=weight))
    ref = prior_from_robot(prior).phi
    np.testing.assert_allclose(res.phi, ref, atol=1e-5 * np.abs(ref).max())
    assert res.prior_weight == weight


def test_an_inaccurate_clarabel_answer_is_kept_without_scs(noisy_panda_model, monkeypatch):
    """Both Clarabel attempts ending ``optimal_inaccurate``: SCS ran after them (12-20 s a
    solve on a weight search's hard data, ending inaccurate too, its answer not kept); now
    the first inaccurate answer is kept and SCS is not run."""
    import cvxpy as cp

    import dynid.feasibility.convex.problem as problem

    calls: list[str] = []
    solve = cp.Problem.solve

    def inaccurate(self, *args, **kwargs):
        out = solve(self, *args, **kwargs)
        name = type(kwargs.get("solver")).__name__
        calls.append(name)
        if "CLARABEL" in name.upper():
            self._status = "optimal_inaccurate"
        return out

    def no_scs():
        raise AssertionError("SCS run after an inaccurate Clarabel answer")

    monkeypatch.setattr(cp.Problem, "solve", inaccurate)
    monkeypatch.setattr(problem, "scs", no_scs)
    model, prior = noisy_panda_model
    res = retrieve_sdp(model, prior=prior, options=SDPOptions(prior_weight=1.0))
    assert calls and all("CLARABEL" in c.upper() for c in calls), calls
    assert res.phi.shape == prior_from_robot(prior).phi.shape


def test_a_solver_panic_is_a_failed_solve(noisy_panda_model, monkeypatch, tmp_path, capsys):
    """A panic of the compiled solver (a BaseException, no Exception) is a failed attempt:
    the next solver is tried, and when every one fails at the given weight the one line
    names --prior-weight and the attempts."""
    import dynid.feasibility.convex.problem as problem
    from dynid.feasibility.convex import solvers

    class PanicException(BaseException):  # as pyo3 names Rust panics
        pass

    def panic(*args, **kwargs):
        raise PanicException("Eigval error:\n Eigen(1)")

    def panicking(make):
        def made():
            solver = make()  # the one instance the process shares: patched until teardown
            monkeypatch.setattr(solver, "solve_via_data", panic)
            return solver

        return made

    monkeypatch.setattr(problem, "clarabel", panicking(solvers.clarabel))
    monkeypatch.setattr(problem, "scs", panicking(solvers.scs))
    model, prior = noisy_panda_model
    with pytest.raises(OptionError, match=r"CLARABEL: panicked \(Eigval error: Eigen\(1\)\)") as e:
        retrieve_sdp(model, prior=prior, options=SDPOptions(prior_weight=1.0))
    assert e.value.field == "prior_weight" and isinstance(e.value.__cause__, SolverError)
    save_model_json(tmp_path / "identification.json", model)
    argv = ["retrieve", "--model", str(tmp_path / "identification.json"), "--prior-weight", "3"]
    assert main([*argv, "--out", str(tmp_path / "r")]) == 2
    err = capsys.readouterr().err.splitlines()
    assert len(err) == 1 and err[0].startswith("dynid retrieve: error: --prior-weight 3: ")
    assert "SCS: panicked" in err[0] and not (tmp_path / "r").exists()


# ---------------------------------------------------------------------- options of a method
@pytest.mark.parametrize(
    "option", [["--prior", "panda"], ["--prior-base", "link0"], ["--prior-tip", "link7"]]
)
def test_the_penalty_method_refuses_the_convex_methods_prior(option, tmp_path, capsys):
    """``--prior`` (and its chain) belongs to the convex method: with ``--method penalty``
    it is one line and exit 2, before any work, and no folder."""
    path = save_model_json(
        tmp_path / "identification.json", exact_model(dynid.panda(), dynid.panda())
    )
    argv = ["retrieve", "--model", str(path), "--method", "penalty", *option]
    assert main([*argv, "--runs", "1", "--out", str(tmp_path / "o")]) == 2
    err = capsys.readouterr().err.splitlines()
    # the prior's chain without a prior is refused as such first
    assert len(err) == 1 and err[0].startswith(f"dynid retrieve: error: {option[0]} applies to")
    assert not (tmp_path / "o").exists()
    with pytest.raises(OptionError, match="prior applies to method sdp only"):
        RetrieveOptions(method="penalty", prior="panda")


# ---------------------------------------------------------------------- single-file outputs
@pytest.mark.parametrize(
    "argv",
    [
        ["simulate", "--duration", "0.1", "--rate", "100"],
        ["acquire-static", "--n", "3"],
        ["export", "--params", "panda"],
    ],
)
def test_a_single_file_no_dynid_run_wrote_is_not_replaced_without_force(argv, tmp_path, capsys):
    """The user's file at --out is refused in one line before any work; a file the same
    command wrote is replaced; a file changed since it was written is the user's again;
    --force replaces it."""
    out = tmp_path / ("robot.urdf" if argv[0] == "export" else "out.csv")
    out.write_text("my hand-written notes\n")
    assert main([*argv, "--out", str(out)]) == 2
    err = capsys.readouterr().err.splitlines()
    assert err == [
        f"dynid {argv[0]}: error: --out {out}: exists and no dynid run wrote it (or it changed "
        "since); pass --force to replace, or choose another --out"
    ]
    assert out.read_text() == "my hand-written notes\n"
    assert main([*argv, "--out", str(out), "--force"]) == 0
    assert main([*argv, "--out", str(out)]) == 0  # its own file: replaced
    written = out.read_text()
    assert written != "my hand-written notes\n"
    out.write_text(written + "\n")  # edited since
    capsys.readouterr()
    assert main([*argv, "--out", str(out)]) == 2
    assert "exists and no dynid run wrote it" in capsys.readouterr().err


def test_a_single_file_of_another_command_needs_force(tmp_path, capsys):
    out = tmp_path / "data.csv"
    assert main(["simulate", "--duration", "0.1", "--rate", "100", "--out", str(out)]) == 0
    capsys.readouterr()
    assert main(["acquire-static", "--n", "3", "--out", str(out)]) == 2
    assert "holds the output of `dynid simulate`" in capsys.readouterr().err


# ---------------------------------------------------------------------- unwritable --out
def test_an_unwritable_out_folder_is_refused_before_any_work(tmp_path, capsys, monkeypatch):
    """--out a folder this process may not write into: one line naming --out before the
    command computes or says "wrote" (root may write anywhere: the permission is faked)."""
    run_output = importlib.import_module("dynid.outputs.run_output")
    out = tmp_path / "ro"
    out.mkdir()
    monkeypatch.setattr(run_output, "_can_write", lambda folder: folder != out)
    called = []
    monkeypatch.setattr("dynid.cli.identify.run", lambda *a: called.append(a) or 0)
    assert main(["identify", "--data", str(tmp_path / "s.csv"), "--out", str(out)]) == 2
    captured = capsys.readouterr()
    assert captured.err.splitlines() == [
        f"dynid identify: error: --out {out}: this folder is not writable (permission denied); "
        "choose another --out"
    ]
    assert captured.out == "" and not called and list(out.iterdir()) == []
    # a file --out in a folder it may not write into
    monkeypatch.setattr(run_output, "_can_write", lambda folder: folder != tmp_path)
    assert main(["acquire-static", "--n", "3", "--out", str(tmp_path / "new" / "s.csv")]) == 2
    err = capsys.readouterr().err
    assert f"--out {tmp_path / 'new' / 's.csv'}: the nearest existing folder {tmp_path} is " in err
    assert not (tmp_path / "new").exists()


def test_a_failed_move_is_one_line_naming_out(tmp_path, capsys, monkeypatch):
    """The move into --out fails: one line naming --out, not a hidden temporary file's
    name; what --out held stays."""
    run_output = importlib.import_module("dynid.outputs.run_output")
    out = tmp_path / "s.csv"
    assert main(["acquire-static", "--n", "3", "--out", str(out)]) == 0
    before = out.read_bytes()

    def denied(*args, **kwargs):
        raise PermissionError(13, "Permission denied", str(tmp_path / ".s.csv.x.tmp.csv"))

    monkeypatch.setattr(run_output.RunOutput, "_commit_file", denied)
    capsys.readouterr()
    assert main(["acquire-static", "--n", "4", "--out", str(out)]) == 2
    err = capsys.readouterr().err.splitlines()
    assert err == [
        f"dynid acquire-static: error: --out {out}: the outputs could not be put in place "
        "(Permission denied); choose another --out"
    ]
    assert out.read_bytes() == before


# ---------------------------------------------------------------------- too short a log
def _log_rows(path, rows: int) -> None:
    """A torque log of ``rows`` samples of a moving Panda at 1 kHz (the file format's
    header)."""
    robot = dynid.panda()
    t = np.arange(rows) * 1e-3
    q = dynid.PANDA_NEUTRAL_Q + 0.3 * np.sin(2 * np.pi * 0.5 * t)[:, None]
    dq = 0.3 * np.pi * np.cos(2 * np.pi * 0.5 * t)[:, None] + np.zeros((rows, 7))
    tau = dynid.rnea(robot, q, dq, np.zeros_like(q))
    head = ",".join(["t", *(f"{k}{i + 1}" for k in ("q", "dq", "tau") for i in range(7))])
    body = np.column_stack([t, q, dq, tau])
    np.savetxt(path, body, delimiter=",", header=head, comments="")


@pytest.mark.parametrize("rows", [2, 3])
def test_a_log_of_a_few_samples_is_said_to_be_too_short(rows, tmp_path, capsys):
    """Two samples correlate at +-1 with anything: the count is said first, not a sign
    finding or an array shape."""
    log = tmp_path / "two.csv"
    _log_rows(log, rows)
    assert main(["identify", "--data", str(log), "--out", str(tmp_path / "id")]) == 2
    err = capsys.readouterr().err.splitlines()
    assert err == [
        f"dynid identify: error: two.csv: {rows} samples: too few to check or filter a torque "
        "log (at least 10 are needed); hint: check that the file holds the whole recording"
    ]


def test_a_short_log_is_named_once(tmp_path, capsys):
    """validate of a log too short to filter: the file is named once."""
    log = tmp_path / "short.csv"
    _log_rows(log, 20)
    argv = ["validate", "--robot", "panda", "--data", str(log), "--out", str(tmp_path / "v")]
    main([*argv, "--no-figures"])
    err = capsys.readouterr().err.splitlines()[-1]
    assert "short.csv: short.csv" not in err and err.startswith("dynid validate: error: short.csv:")


# ---------------------------------------------------------------------- --columns
def test_a_missing_mapped_column_lists_the_files_columns(tmp_path):
    """The message lists the file's columns, not only those the map already read."""
    from dynid.exceptions import DataError
    from dynid.io.columns import load_mapped_torque_log, parse_column_map

    path = tmp_path / "units.csv"
    header = ["t [s]", "q1 [rad]", "q2 [rad]", "tau1 [Nm]", "tau2 [Nm]"]
    path.write_text(",".join(header) + "\n" + "\n".join(f"{k},0,0,0,0" for k in range(5)) + "\n")
    for cols, missing in (("t=t [s],q=q{i} [rad]", "tau1"), ("t=t [s],q=pos{i}", "pos1")):
        with pytest.raises(DataError, match=f"no column '{missing}'") as e:
            load_mapped_torque_log(path, parse_column_map(cols))
        assert f"the file has {header}" in str(e.value)


# ---------------------------------------------------------------------- --cutoff
@pytest.mark.parametrize("command", ["identify", "validate"])
def test_a_cutoff_above_nyquist_names_the_option_and_the_rate(command, tmp_path, capsys):
    """--cutoff at or above half the sample rate (1 kHz here): one line naming --cutoff
    and the rate, no warning per piece and no hint about gaps."""
    log = tmp_path / "log.csv"
    _log_rows(log, 400)
    source = ["--robot", "panda"] if command == "validate" else []
    argv = [command, *source, "--data", str(log), "--cutoff", "1e6", "--no-figures"]
    assert main([*argv, "--out", str(tmp_path / "o")]) == 2
    assert capsys.readouterr().err.splitlines() == [
        f"dynid {command}: error: --cutoff 1e+06 Hz: must be below half the sample rate, "
        "500 Hz (the recording is sampled at 1000 Hz)"
    ]


# ---------------------------------------------------------------------- delimiters
@pytest.mark.parametrize(("sep", "what"), [("\t", "tab"), (";", "semicolon")])
@pytest.mark.parametrize("kind", ["log", "static"])
def test_a_file_of_another_delimiter_is_named_as_such(sep, what, kind, tmp_path, capsys):
    """A tab- or semicolon-separated file (a torque log or static data): one line saying
    so and what is expected, not a torque log's header rules."""
    csv = tmp_path / "comma.csv"
    if kind == "log":
        _log_rows(csv, 50)
    else:
        assert main(["acquire-static", "--n", "5", "--out", str(csv)]) == 0
    other = tmp_path / "other.csv"
    other.write_text(csv.read_text().replace(",", sep))
    capsys.readouterr()
    assert main(["identify", "--data", str(other), "--out", str(tmp_path / "o")]) == 2
    err = capsys.readouterr().err.splitlines()
    assert len(err) == 1 and err[0].startswith("dynid identify: error: other.csv, line ")
    assert err[0].endswith(
        f": the header holds {what}s and no comma: a {what}-separated file; dynid reads "
        f"comma-separated files; hint: replace each {what} with a comma"
    )


def test_a_semicolon_file_with_decimal_commas_is_told_to_convert_them_first(tmp_path, capsys):
    """A semicolon-separated log with decimal commas (a spreadsheet's export in many
    locales): "replace each semicolon with a comma" alone would make 0,05 two cells; the
    hint converts the decimal commas first, and following it reads the file."""
    csv = tmp_path / "comma.csv"
    _log_rows(csv, 50)
    text = csv.read_text()
    euro = tmp_path / "euro.csv"
    euro.write_text(text.replace(",", ";").replace(".", ","))
    assert main(["identify", "--data", str(euro), "--out", str(tmp_path / "o")]) == 2
    err = capsys.readouterr().err
    assert "hint: the numbers have decimal commas: replace each comma with a point, then " \
        "replace each semicolon with a comma" in err, err  # fmt: skip
    fixed = tmp_path / "fixed.csv"
    fixed.write_text(euro.read_text().replace(",", ".").replace(";", ","))
    assert fixed.read_text() == text


# ---------------------------------------------------------------------- smaller wording
def test_smaller_wording_defects(tmp_path, capsys, caplog):
    """No Python tuple in the export's format line; --prior-weight 0 refused by the parser
    as -1 is, with one rule; a sub-folder of data files in a --data folder is said; a long
    penalty schedule's stage costs are summarised."""
    from dynid.cli.summaries import _stage_costs
    from dynid.workflows.data_files import data_files

    assert main(["export", "--params", "panda", "--out", str(tmp_path / "a.json")]) == 2
    err = capsys.readouterr().err
    assert "give the format: one of urdf, mjcf, toml" in err and "('" not in err
    for w in ("-1", "0"):
        argv = ["retrieve", "--model", "m.json", "--prior-weight", w, "--out", "x"]
        assert main(argv) == 2
        assert "--prior-weight: must be a finite number > 0; got" in capsys.readouterr().err
    (tmp_path / "logs" / "day2").mkdir(parents=True)
    (tmp_path / "logs" / "figures").mkdir()
    (tmp_path / "logs" / "a.csv").write_text("t\n")
    (tmp_path / "logs" / "day2" / "b.csv").write_text("t\n")
    with caplog.at_level("WARNING"):
        assert data_files(tmp_path / "logs") == [tmp_path / "logs" / "a.csv"]
    said = [r.getMessage() for r in caplog.records]
    assert said == [
        "logs: sub-folder(s) holding data files left out (not read): day2; hint: give them "
        "to --data as well"
    ]
    costs = np.array([10.0**-k for k in range(200)])
    line = _stage_costs(costs)
    assert (
        line
        == "stage costs 1, 0.1, 0.01, ..., 1e-197, 1e-198, 1e-199 (200 stages; all in report.json)"
    )
    assert _stage_costs(costs[:3]) == "stage costs 1, 0.1, 0.01"
