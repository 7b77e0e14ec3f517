"""Messages that tell the truth and refusals in one line (a reliability campaign of the
command line): an interrupt while the modules load, solver failures at extreme prior
weights, options of the other retrieval method, single-file outputs that are not dynid's,
an unwritable --out, too short logs, --columns, --cutoff above Nyquist, tab-separated
files, and smaller wording defects."""

from __future__ import annotations

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
            solver = make()
            solver.solve_via_data = panic
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
    assert err == [f"dynid retrieve: error: {option[0]} applies to --method sdp only"]
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
