"""Processes and signals (issue 20): workers die with their parent whatever kills it,
SIGHUP and SIGQUIT stop a run as SIGTERM does, --workers is capped at the cores, a closed
stdout exits quietly with its own code, and failing figures never cost a data file."""

from __future__ import annotations

import contextlib
import os
import signal
import subprocess
import sys
import time
from pathlib import Path

import pytest

from dynid.cli.__main__ import main

pytestmark = pytest.mark.skipif(
    not Path("/proc").exists(), reason="needs /proc to find worker processes"
)
NEUTRAL = "0,-0.785,0,-2.356,0,1.571,0.785"


def _env(**extra: str) -> dict[str, str]:
    return {**os.environ, "MPLBACKEND": "Agg", "OPENBLAS_NUM_THREADS": "1", **extra}


def _dynid(*args: str, env: dict[str, str] | None = None, **kw) -> subprocess.Popen:
    kw.setdefault("stdout", subprocess.PIPE)
    kw.setdefault("stderr", subprocess.PIPE)
    return subprocess.Popen(
        [sys.executable, "-m", "dynid", *args],
        text=True,
        env=env or _env(),
        **kw,
    )


def _children(pid: int) -> list[int]:
    """Process ids whose parent is ``pid`` (from /proc)."""
    out = []
    for p in Path("/proc").iterdir():
        if p.name.isdigit():
            with contextlib.suppress(OSError, IndexError):
                fields = (p / "stat").read_text().rsplit(")", 1)[1].split()
                if int(fields[1]) == pid and fields[0] != "Z":
                    out.append(int(p.name))
    return out


def _alive(pid: int) -> bool:
    with contextlib.suppress(OSError, IndexError):
        state = (Path(f"/proc/{pid}") / "stat").read_text().rsplit(")", 1)[1].split()[0]
        return state != "Z"
    return False


def _wait_for(cond, timeout: float) -> bool:
    end = time.monotonic() + timeout
    while time.monotonic() < end:
        if cond():
            return True
        time.sleep(0.05)
    return False


@pytest.fixture(scope="module")
def model(tmp_path_factory) -> Path:
    """identification.json of noise-free static data (60 configurations)."""
    d = tmp_path_factory.mktemp("processes")
    sink = open(os.devnull, "w")  # noqa: SIM115
    with contextlib.redirect_stdout(sink):
        assert main(["acquire-static", "--n", "60", "--seed", "3", "--out", str(d / "s.csv")]) == 0
        assert main(["identify", "--data", str(d / "s.csv"), "--out", str(d / "res")]) == 0
    sink.close()
    return d / "res" / "identification.json"


def _penalty(model: Path, out: Path, *extra: str) -> subprocess.Popen:
    return _dynid(
        "retrieve", "--model", str(model), "--method", "penalty", "--runs", "4",
        "--workers", "2", "--seed", "0", "--out", str(out), *extra,
    )  # fmt: skip


@pytest.mark.slow
@pytest.mark.skipif((os.cpu_count() or 1) < 2, reason="needs two cores for two workers")
@pytest.mark.parametrize(
    "sig, code",
    [(signal.SIGKILL, -signal.SIGKILL), (signal.SIGHUP, 129), (signal.SIGQUIT, 131)],
    ids=["SIGKILL", "SIGHUP", "SIGQUIT"],
)
def test_workers_die_with_their_parent(model, tmp_path, sig, code):
    """Whatever stops retrieve --method penalty, its workers go too (issue 20: after
    SIGKILL, SIGHUP or SIGQUIT they ran on at 100 % CPU); SIGHUP and SIGQUIT exit with
    128 + the signal and one line, and leave no output."""
    out = tmp_path / "feasible"
    proc = _penalty(model, out)
    assert _wait_for(lambda: len(_children(proc.pid)) >= 2, 60), "workers did not start"
    workers = _children(proc.pid)
    time.sleep(0.3)
    proc.send_signal(sig)
    _, err = proc.communicate(timeout=30)
    assert proc.returncode == code, err
    try:
        assert _wait_for(lambda: not any(_alive(w) for w in workers), 10), "a worker outlived it"
    finally:  # do not leave them running if they did
        for w in workers:
            with contextlib.suppress(OSError):
                os.kill(w, signal.SIGKILL)
    if sig != signal.SIGKILL:
        name = signal.Signals(sig).name
        assert err.strip().splitlines()[-1] == (
            f"dynid retrieve: terminated ({name}); no partial output left"
        )
        assert "Traceback" not in err
    assert not out.exists()


@pytest.mark.skipif(
    len(os.sched_getaffinity(0)) > 8, reason="the cap is only visible with few cores"
)
def test_workers_are_capped_at_the_cores(model, tmp_path):
    """--workers 64 on a small machine starts no more processes than cores, with a note
    (issue 20: 64 processes, 3.5 GB)."""
    cores = len(os.sched_getaffinity(0))
    proc = _dynid(
        "retrieve", "--model", str(model), "--method", "penalty", "--runs", "2", "--stages",
        "1", "--workers", "64", "--out", str(tmp_path / "f"), "-q",
    )  # fmt: skip
    most = 0
    while proc.poll() is None:
        most = max(most, len(_children(proc.pid)))
        time.sleep(0.05)
    _, err = proc.communicate(timeout=60)
    assert proc.returncode in (0, 1), err
    assert f"note: --workers 64: using {min(cores, 2)}" in err, err
    assert most <= min(cores, 2)


def _closed_pipe() -> int:
    """The write end of a pipe whose read end is already closed (``| true``)."""
    r, w = os.pipe()
    os.close(r)
    return w


@pytest.mark.parametrize("json_flag", [False, True], ids=["table", "json"])
def test_a_closed_stdout_exits_quietly_with_its_own_code(json_flag):
    """`dynid fk ... | true`: exit 141 (not 1, 'no feasible set'), nothing on stderr."""
    w = _closed_pipe()
    try:
        proc = _dynid("fk", "--q", NEUTRAL, *(["--json"] if json_flag else []), stdout=w)
    finally:
        os.close(w)
    _, err = proc.communicate(timeout=60)
    assert (proc.returncode, err) == (141, "")


def test_a_closed_stdout_keeps_the_files_of_a_run(model, tmp_path):
    """identify ... | true: the output set is written all the same, exit 141."""
    w = _closed_pipe()
    data = model.parent.parent / "s.csv"
    try:
        proc = _dynid("identify", "--data", str(data), "--out", str(tmp_path / "r"), stdout=w)
    finally:
        os.close(w)
    _, err = proc.communicate(timeout=60)
    assert (proc.returncode, err) == (141, "")
    assert (tmp_path / "r" / "identification.json").is_file()


def _closed_fd(fd: int) -> None:
    """Run in the child before exec: start it with file descriptor ``fd`` closed (``>&-``)."""
    os.close(fd)


def test_a_run_started_without_stdout_keeps_its_files_and_exits_141(model, tmp_path):
    """`dynid identify ... >&-` (Python's sys.stdout is None): exit 141 with the files, not
    'unexpected AttributeError' (exit 2, no files) and 'Exception ignored' (exit 120)."""
    data = model.parent.parent / "s.csv"
    out = tmp_path / "r"
    args = ("identify", "--data", str(data), "--out", str(out))
    proc = _dynid(*args, stdout=None, preexec_fn=lambda: _closed_fd(1))
    _, err = proc.communicate(timeout=60)
    assert (proc.returncode, err) == (141, "")
    assert (out / "identification.json").is_file()


def test_an_error_without_stderr_never_goes_to_stdout():
    """`dynid ... 2>&-` failing: exit 2 and nothing on stdout (print(file=None) wrote the
    error line into the data stream)."""
    proc = _dynid("fk", "--q", "nan,0,0,0,0,0,0", stderr=None, preexec_fn=lambda: _closed_fd(2))
    out, _ = proc.communicate(timeout=60)
    assert (proc.returncode, out) == (2, "")


def test_a_bad_backend_skips_the_figures_and_keeps_the_data(model, tmp_path):
    """MPLBACKEND=nonexistent: validate exits 0 with its data file and one note per figure
    (issue 20: exit 2 and the data files removed)."""
    log = tmp_path / "log.csv"  # written in-process: only validate needs the backend
    assert main(["simulate", "--duration", "2", "--rate", "200", "--out", str(log), "-q"]) == 0
    out = tmp_path / "val"
    proc = _dynid(
        "validate", "--robot", "panda", "--data", str(log), "--out", str(out),
        env=_env(MPLBACKEND="nonexistent"),
    )  # fmt: skip
    _, err = proc.communicate(timeout=60)
    assert proc.returncode == 0, err
    notes = [s for s in err.splitlines() if s.startswith("note:")]
    assert len(notes) == 2 and all("skipped the figure validation_" in s for s in notes), err
    assert all("nonexistent" in s for s in notes), err
    assert (out / "validation.json").is_file()
    assert not list(out.glob("*.png"))


def test_a_failing_figure_is_skipped_with_a_note(model, tmp_path, monkeypatch, capsys):
    """Any error while drawing (here: the plotting function raises) skips that figure with
    a note naming the error; the data files are written and the run exits 0."""
    import dynid.plots.feasible as feasible_plots

    def broken(*a, **k):
        raise RuntimeError("the plot is broken")

    monkeypatch.setattr(feasible_plots, "plot_consistent", broken)
    out = tmp_path / "f"
    assert main(["retrieve", "--model", str(model), "--out", str(out), "-q"]) in (0, 1)
    err = capsys.readouterr().err
    assert "note: skipped the figure retrieval.png: RuntimeError: the plot is broken" in err
    assert (out / "feasible.json").is_file() and not (out / "retrieval.png").exists()


_SCS_RUN = """
import numpy as np, cvxpy as cp
from dynid.feasibility.convex.solvers import scs as _scs
rng = np.random.default_rng(0); n = 120
C = rng.normal(size=(n, n)); C = C + C.T
X = cp.Variable((n, n), PSD=True)
prob = cp.Problem(cp.Minimize(cp.trace(C @ X)), [cp.trace(X) == 1, X[0, 1] >= 0.01])
solver = _scs()
solve = solver.solve_via_data

def announced(*args, **kwargs):  # said once cvxpy hands the problem to SCS
    print("ready", flush=True)
    return solve(*args, **kwargs)

solver.solve_via_data = announced
try:
    prob.solve(solver=solver, eps=1e-12, max_iters=10**7)
    print("finished", prob.status)
except cp.error.SolverError as e:
    print("solver error", e)
"""


def test_ctrl_c_during_the_scs_fallback_stops_the_run():
    """SCS catches SIGINT itself and cvxpy reports a failed solve: through cvxpy's own
    interface the convex fit's retries went on and the run ended with exit 0 and all its
    files. The fallback the convex fit uses lets it through as a KeyboardInterrupt."""
    p = subprocess.Popen(
        [sys.executable, "-c", _SCS_RUN],
        stdout=subprocess.PIPE,
        stderr=subprocess.PIPE,
        text=True,
        preexec_fn=lambda: signal.signal(signal.SIGINT, signal.SIG_DFL),
    )
    assert p.stdout is not None and p.stdout.readline().strip() == "ready"
    time.sleep(0.5)  # inside SCS (the tolerance is out of reach: it runs on)
    p.send_signal(signal.SIGINT)
    out, err = p.communicate(timeout=120)
    assert "KeyboardInterrupt" in err and "finished" not in out and "solver error" not in out
    assert p.returncode != 0


_CLARABEL_RUN = """
import os, signal, sys
import clarabel
real = clarabel.DefaultSolver

class Solver:  # Clarabel's solver; a Ctrl-C arrives as its first solve starts
    def __init__(self, *args):
        self.real = real(*args)
    def __getattr__(self, name):
        return getattr(self.real, name)
    def solve(self):
        os.kill(os.getpid(), signal.SIGINT)
        result = self.real.solve()
        print("solver status", result.status, file=sys.stderr, flush=True)
        return result

clarabel.DefaultSolver = Solver
from dynid.cli.__main__ import main
sys.exit(main())
"""


def test_ctrl_c_during_the_clarabel_solve_ends_it_and_the_run(tmp_path):
    """Clarabel never looks at Python's signals: a Ctrl-C waited for the whole solve (and
    a termination callback drops the interrupt raised in it). The convex fit's solver
    records the signal, ends the solve at its next iteration and delivers it: the run
    exits 130 with no output folder, its solve cut short (status CallbackTerminated). The
    structure is fixed (no search before the convex fit: the solve is the case)."""
    import numpy as np

    import dynid
    from dynid.io.torque_log import save_torque_log
    from dynid.simulation.measurement import sample_times, simulate_measurement
    from dynid.simulation.trajectories import random_fourier

    panda = dynid.panda()
    traj = random_fourier(panda, np.random.default_rng(3))(sample_times(5.0, 200.0))
    log = tmp_path / "log.csv"
    save_torque_log(log, simulate_measurement(panda, traj, rng=np.random.default_rng(4)))
    out = tmp_path / "out"
    p = subprocess.Popen(
        [
            sys.executable,
            "-c",
            _CLARABEL_RUN,
            "identify",
            "--robot",
            "panda",
            "--data",
            str(log),
            "--consistent",
            "--terms",
            "viscous,coulomb,offset",
            "--out",
            str(out),
        ],
        stdout=subprocess.PIPE,
        stderr=subprocess.PIPE,
        text=True,
        env=_env(),
        preexec_fn=lambda: signal.signal(signal.SIGINT, signal.SIG_DFL),
    )
    _, err = p.communicate(timeout=300)
    assert p.returncode == 130, err
    assert "solver status CallbackTerminated" in err
    assert "interrupted; no partial output left" in err
    assert not out.exists()


@pytest.mark.parametrize("given", [None, "3"])
def test_a_command_runs_blas_on_one_thread_unless_told(given):
    """A command's process sets OPENBLAS_NUM_THREADS and MKL_NUM_THREADS to 1 before numpy
    loads (which reads them once), and leaves a value the environment gives as it is."""
    env = {
        k: v for k, v in os.environ.items() if k not in ("OPENBLAS_NUM_THREADS", "MKL_NUM_THREADS")
    }
    if given is not None:
        env["OPENBLAS_NUM_THREADS"] = given
    code = (
        "import os, sys; from dynid.cli.__main__ import _one_blas_thread; "
        "assert 'numpy' not in sys.modules; _one_blas_thread(); "
        "print(os.environ['OPENBLAS_NUM_THREADS'], os.environ['MKL_NUM_THREADS'])"
    )
    done = subprocess.run([sys.executable, "-c", code], env=env, capture_output=True, text=True)
    assert done.returncode == 0, done.stderr
    assert done.stdout.split() == [given or "1", "1"]
