"""Output folders a user can trust (issue 20): runs write, fail, are killed and race into
one ``--out``; the folder always holds one complete set, of one run. Real processes where
the case is about processes (a full disk under RLIMIT_FSIZE, signals, concurrent runs); the
command line in-process where it is about the folder's contents.

Every case compares the folder with a snapshot taken before (names, bytes, modes), so a
failed run that touched anything is caught, whatever it touched.
"""

from __future__ import annotations

import contextlib
import fcntl
import importlib
import io
import json
import os
import signal
import subprocess
import sys
import time
from pathlib import Path

import pytest

from dynid.cli.__main__ import main
from dynid.outputs.run_output import FILES_RECORD, MANIFEST

pytestmark = pytest.mark.skipif(sys.platform == "win32", reason="POSIX locks and signals")


def _env() -> dict[str, str]:
    return {**os.environ, "MPLBACKEND": "Agg", "OPENBLAS_NUM_THREADS": "1"}


def _dynid(*args: str, **kw) -> subprocess.Popen:
    return subprocess.Popen(
        [sys.executable, "-m", "dynid", *args],
        stdout=subprocess.PIPE,
        stderr=subprocess.PIPE,
        text=True,
        env=_env(),
        **kw,
    )


def _run(*args: str, **kw) -> subprocess.CompletedProcess:
    proc = _dynid(*args, **kw)
    out, err = proc.communicate(timeout=120)
    return subprocess.CompletedProcess(proc.args, proc.returncode, out, err)


def _main(*args: str) -> subprocess.CompletedProcess:
    """``dynid *args`` in this process: its exit code, stdout and stderr."""
    out, err = io.StringIO(), io.StringIO()
    with contextlib.redirect_stdout(out), contextlib.redirect_stderr(err):
        code = main(list(args))
    return subprocess.CompletedProcess(["dynid", *args], code, out.getvalue(), err.getvalue())


def _snapshot(folder: Path) -> dict[str, tuple[bytes, int]]:
    """Every entry under ``folder`` (hidden ones too): relative name -> (bytes, mode)."""
    snap = {}
    for p in sorted(folder.rglob("*")):
        st = p.lstat()
        snap[p.relative_to(folder).as_posix()] = (
            p.read_bytes() if p.is_file() else b"",
            st.st_mode,
        )
    return snap


def _staging(parent: Path) -> list[str]:
    """Staging folders and leftovers (the record of single files is no leftover)."""
    return sorted(
        p.name for p in parent.iterdir() if ".dynid-" in p.name and p.name != FILES_RECORD
    )


def _complete_set(folder: Path) -> list[str]:
    """The names of the folder's recorded set, checked to be exactly what it holds."""
    doc = json.loads((folder / MANIFEST).read_text())
    assert doc["state"] == "complete"
    present = sorted(p.name for p in folder.iterdir() if p.name != MANIFEST)
    assert present == sorted(doc["files"]), (present, doc["files"])
    for name in doc["files"]:
        if name.endswith(".json"):
            json.loads((folder / name).read_text())  # complete, parseable
    return present


CONSISTENT_SET = [
    "feasible.json",
    "identification.json",
    "report.html",
    "report.json",
    "retrieval.png",
    "robot.toml",
    "robot.urdf",
    "robot.xml",
]


@pytest.fixture(scope="module")
def data(tmp_path_factory) -> Path:
    """Two static data sets (60 configurations, seeds 3 and 4) and a model from the first."""
    d = tmp_path_factory.mktemp("run_output")
    for seed in (3, 4):
        r = _main(
            "acquire-static", "--n", "60", "--seed", str(seed), "--out", str(d / f"s{seed}.csv")
        )
        assert r.returncode == 0, r.stderr
    r = _main("identify", "--data", str(d / "s3.csv"), "--out", str(d / "model"), "-q")
    assert r.returncode == 0, r.stderr
    return d


def test_a_rerun_replaces_the_set_as_a_whole(data, tmp_path):
    """identify --consistent, then plain identify into the same folder: the consistent
    files of the first run go once the second set is complete; a file of the user stays."""
    out = tmp_path / "res"
    r = _main("identify", "--data", str(data / "s3.csv"), "--consistent", "--out", str(out), "-q")
    assert r.returncode == 0, r.stderr
    assert _complete_set(out) == CONSISTENT_SET
    (out / "notes.txt").write_text("mine\n")
    r = _main("identify", "--data", str(data / "s4.csv"), "--out", str(out), "-q")
    assert r.returncode == 0, r.stderr
    assert sorted(p.name for p in out.iterdir()) == [
        MANIFEST,
        "identification.json",
        "notes.txt",
        "report.html",
    ]
    assert (out / "notes.txt").read_text() == "mine\n"
    assert "s4.csv" in json.loads((out / MANIFEST).read_text())["argv"][3]
    assert _staging(tmp_path) == []


def test_another_commands_folder_and_foreign_files_need_force(data, tmp_path):
    """retrieve into identify's folder, or over a file no run wrote: refused before any
    computation, the folder unchanged; --force writes."""
    out = tmp_path / "res"
    assert (
        _main("identify", "--data", str(data / "s3.csv"), "--out", str(out), "-q").returncode == 0
    )
    before = _snapshot(out)
    model = str(data / "model" / "identification.json")
    r = _main("retrieve", "--model", model, "--out", str(out), "-q")
    assert r.returncode == 2
    assert r.stderr.strip() == (
        f"dynid retrieve: error: --out {out}: holds the outputs of `dynid identify` "
        "(identification.json, report.html); choose another --out or pass --force to write into it"
    )
    assert _snapshot(out) == before
    theirs = tmp_path / "theirs"
    theirs.mkdir()
    (theirs / "feasible.json").write_text("{}\n")
    r = _main("retrieve", "--model", model, "--out", str(theirs), "-q")
    assert r.returncode == 2 and "feasible.json exists and no dynid run recorded it" in r.stderr
    assert (theirs / "feasible.json").read_text() == "{}\n"
    assert sorted(p.name for p in theirs.iterdir()) == ["feasible.json"]
    r = _main("retrieve", "--model", model, "--out", str(theirs), "--force", "-q")
    assert r.returncode == 0, r.stderr
    assert json.loads((theirs / "feasible.json").read_text())["schema"].startswith("dynid-feasible")
    assert _staging(tmp_path) == []


def test_a_read_only_file_is_not_replaced_without_force(data, tmp_path):
    """A 0444 file of the folder's own set, and a 0444 --out file: refused, kept; --force
    replaces them."""
    out = tmp_path / "res"
    args = ("identify", "--data", str(data / "s3.csv"), "--out", str(out), "-q")
    assert _main(*args).returncode == 0
    (out / "identification.json").chmod(0o444)
    before = _snapshot(out)
    r = _main(*args)
    assert r.returncode == 2
    assert "identification.json is read-only; pass --force" in r.stderr, r.stderr
    assert _snapshot(out) == before
    r = _main(*args[:-1])  # not quiet: it printed "wrote .../identification.json", then refused
    assert r.returncode == 2 and "wrote" not in r.stdout, r.stdout
    assert _main(*args, "--force").returncode == 0
    assert (out / "identification.json").stat().st_mode & 0o200  # a new file, writable

    log = tmp_path / "log.csv"
    log.write_text("precious\n")
    log.chmod(0o444)
    sim = ("simulate", "--duration", "1", "--rate", "100", "--out", str(log), "-q")
    r = _main(*sim[:-1])
    assert r.returncode == 2 and "log.csv is read-only" in r.stderr, r.stderr
    assert "wrote" not in r.stdout, r.stdout
    assert log.read_text() == "precious\n"
    assert _main(*sim, "--force").returncode == 0
    assert log.read_text().startswith("#")
    assert _staging(tmp_path) == []


def _limit_file_size(limit: int):
    """preexec_fn: files larger than ``limit`` bytes cannot be written (a full disk);
    SIGXFSZ ignored so that the write fails with EFBIG instead of killing the process."""
    import resource

    def apply() -> None:
        signal.signal(signal.SIGXFSZ, signal.SIG_IGN)
        resource.setrlimit(resource.RLIMIT_FSIZE, (limit, limit))

    return apply


def test_a_full_disk_leaves_no_new_folder_and_an_old_folder_as_it_was(data, tmp_path):
    """RLIMIT_FSIZE: a run into a new folder (with new parents) leaves nothing; a rerun
    into an existing folder whose writes fail half-way leaves it byte for byte as it was
    (issue 20: new feasible.json and robot.* next to the old report.json)."""
    new = tmp_path / "a" / "b" / "res"
    r = _run(
        "identify", "--data", str(data / "s3.csv"), "--out", str(new), "-q",
        preexec_fn=_limit_file_size(20_000),
    )  # fmt: skip
    assert r.returncode == 2 and "File too large" in r.stderr, r.stderr
    assert list(tmp_path.iterdir()) == []

    out = tmp_path / "feasible"
    model = str(data / "model" / "identification.json")
    r = _main("retrieve", "--model", model, "--objective", "euclidean", "--out", str(out), "-q")
    assert r.returncode in (0, 1), r.stderr  # 1: not consistent; its files are written
    before = _snapshot(out)
    # feasible.json (~9 kB) and robot.* fit, report.json (~11 kB) does not
    r = _run(
        "retrieve", "--model", model, "--out", str(out), "-q",
        preexec_fn=_limit_file_size(10_000),
    )  # fmt: skip
    assert r.returncode == 2 and "File too large" in r.stderr, r.stderr
    assert _snapshot(out) == before
    assert _staging(tmp_path) == []


def _wait_for(cond, timeout: float) -> bool:
    end = time.monotonic() + timeout
    while time.monotonic() < end:
        if cond():
            return True
        time.sleep(0.05)
    return False


@pytest.mark.slow
def test_sigkill_then_rerun_removes_the_stale_files(data, tmp_path):
    """A run killed with SIGKILL leaves its staging folder; the next run removes it and a
    writer's temporary file of a killed older run, and writes the complete set (the runs
    before and after the killed one in this process: what they do is the folder's)."""
    out = tmp_path / "res"
    args = ("identify", "--data", str(data / "s3.csv"), "--consistent", "--out", str(out), "-q")
    assert _main(*args).returncode == 0
    stale_tmp = out / ".feasible.json.k2j4x9.tmp.json"
    stale_tmp.write_text('{"half": ')
    before = _snapshot(out)
    proc = _dynid(*args)
    assert _wait_for(lambda: _staging(tmp_path), 30), "no staging folder appeared"
    time.sleep(0.5)
    proc.send_signal(signal.SIGKILL)
    proc.communicate(timeout=30)
    assert proc.returncode == -signal.SIGKILL
    assert _snapshot(out) == before  # nothing of the killed run in the folder
    assert len(_staging(tmp_path)) == 1
    r = _main(*args)
    assert r.returncode == 0, r.stderr
    assert _staging(tmp_path) == []
    assert not stale_tmp.exists()
    assert _complete_set(out) == CONSISTENT_SET


def test_a_failing_run_never_removes_files_of_a_concurrent_run(data, tmp_path):
    """Run A (identify --consistent, seconds, a process) and run B (a bad data file, fails
    at once, in this process) into one new folder: A's set is complete (issue 20: B's
    clean-up removed A's files)."""
    out = tmp_path / "res"
    bad = tmp_path / "bad.csv"
    bad.write_text("q1,q2\n1,2\n")
    a = _dynid("identify", "--data", str(data / "s3.csv"), "--consistent", "--out", str(out), "-q")
    assert _wait_for(lambda: _staging(tmp_path), 30)
    b = _main("identify", "--data", str(bad), "--consistent", "--out", str(out), "-q")
    assert b.returncode == 2
    _, err = a.communicate(timeout=120)
    assert a.returncode == 0, err
    assert _complete_set(out) == CONSISTENT_SET
    assert _staging(tmp_path) == []


@pytest.mark.slow
def test_concurrent_runs_wait_for_each_other_and_never_mix(data, tmp_path):
    """While another process holds the folder's lock (``flock`` on its parent), a finished
    run waits with its set staged (nothing moves); released, it moves the whole set. Two
    identical runs at once both succeed and leave one complete set (issue 20: one failed
    on a vanished file)."""
    out = tmp_path / "res"
    args = ("identify", "--data", str(data / "s3.csv"), "--consistent", "--out", str(out), "-q")
    proc = _dynid(*args)
    assert _wait_for(lambda: _staging(tmp_path), 30), "no staging folder appeared"
    fd = os.open(tmp_path, os.O_RDONLY)
    try:
        fcntl.flock(fd, fcntl.LOCK_EX)

        def staged_png() -> bool:
            return any((tmp_path / s / "retrieval.png").exists() for s in _staging(tmp_path))

        assert _wait_for(staged_png, 60), "the run did not finish its files"
        time.sleep(0.5)
        assert proc.poll() is None and not out.exists()
    finally:
        os.close(fd)  # releases the lock
    _, err = proc.communicate(timeout=60)
    assert proc.returncode == 0, err
    assert _complete_set(out) == CONSISTENT_SET

    other = ("identify", "--data", str(data / "s4.csv"), "--consistent", "--out", str(out), "-q")
    procs = [_dynid(*args), _dynid(*other)]
    for p in procs:
        _, err = p.communicate(timeout=120)
        assert p.returncode == 0, err
    assert _complete_set(out) == CONSISTENT_SET
    winner = json.loads((out / MANIFEST).read_text())["argv"][3]
    report = json.loads((out / "report.json").read_text())
    assert Path(winner).name in json.dumps(report)  # the report of the same run
    assert _staging(tmp_path) == []


def test_a_file_out_is_staged_too(tmp_path):
    """simulate --out FILE: the old log stays until the new one is complete; SIGTERM
    during the run leaves it untouched and no staging folder."""
    log = tmp_path / "log.csv"
    assert (
        _main("simulate", "--duration", "1", "--rate", "100", "--out", str(log), "-q").returncode
        == 0
    )
    before = log.read_bytes()
    proc = _dynid("simulate", "--duration", "400", "--rate", "1000", "--out", str(log), "-q")
    assert _wait_for(lambda: _staging(tmp_path), 30)
    time.sleep(0.3)  # into the simulation (400 s of it: minutes of work)
    proc.send_signal(signal.SIGTERM)
    _, err = proc.communicate(timeout=60)
    assert proc.returncode == 143, err
    assert log.read_bytes() == before
    assert sorted(p.name for p in tmp_path.iterdir()) == [FILES_RECORD, "log.csv"]


def test_a_termination_whose_exception_was_dropped_still_ends_the_run(tmp_path, monkeypatch):
    """SIGTERM while numba wrote its cache through a ctypes callback: Python printed the
    Terminated raised there and dropped it, and the run wrote its log and exited 0; the
    signal received now ends the run before its outputs move (143, the old log kept)."""
    import dynid.cli.simulate as sim

    log = tmp_path / "log.csv"
    assert main(["simulate", "--duration", "1", "--rate", "100", "--out", str(log), "-q"]) == 0
    before = log.read_bytes()
    run = sim.run

    def swallowed(args, console):  # the handler's exception lost, as in a C callback
        with contextlib.suppress(BaseException):
            os.kill(os.getpid(), signal.SIGTERM)
        return run(args, console)

    monkeypatch.setattr(sim, "run", swallowed)
    argv = ["simulate", "--duration", "2", "--rate", "100", "--out", str(log), "-q"]
    assert main(argv) == 143
    assert log.read_bytes() == before and _staging(tmp_path) == []
    monkeypatch.setattr(sim, "run", run)
    assert main(argv) == 0  # the next run in this process is not terminated by it


def test_library_writers_outside_a_run_are_unchanged(tmp_path):
    """Without a run, the writers write where they are told (no staging, no manifest)."""
    from dynid.io.atomic import current_location, write_text

    p = write_text(tmp_path / "x" / "a.txt", "a")
    assert p.read_text() == "a" and current_location(p) == p
    assert sorted(q.name for q in tmp_path.rglob("*")) == ["a.txt", "x"]


def test_run_output_stages_and_names_the_staged_location(tmp_path):
    """Inside run_output, a file under --out is written in the staging folder beside it
    and current_location says where; it appears under --out when the block ends."""
    from dynid.io.atomic import current_location, write_text
    from dynid.outputs.run_output import run_output

    out = tmp_path / "o"
    with run_output(out, command="test") as run:
        p = write_text(out / "sub" / "a.txt", "a")
        assert not out.exists()
        staged = current_location(p)
        assert staged != p and staged.read_text() == "a" and staged.parent.parent == run.staging
    assert (out / "sub" / "a.txt").read_text() == "a"
    assert json.loads((out / MANIFEST).read_text())["files"] == ["sub/a.txt"]
    with contextlib.suppress(RuntimeError), run_output(out, command="test"):
        write_text(out / "b.txt", "b")
        raise RuntimeError("fails")
    assert sorted(q.name for q in tmp_path.rglob("*")) == [MANIFEST, "a.txt", "o", "sub"]


def test_the_record_is_strict_json_and_outlives_a_signal_after_the_move(tmp_path):
    """.dynid-run.json is written by the one JSON writer (``schema`` first, strict), and a
    termination that arrives after the set moved (held back during the move) no longer
    removes it: the set stays recorded, so a rerun does not call its files foreign."""
    from dynid.io.atomic import output_transaction, write_text
    from dynid.io.json_files import load_json
    from dynid.outputs.run_output import run_output

    out = tmp_path / "o"
    out.mkdir()
    with contextlib.suppress(RuntimeError), output_transaction():
        with run_output(out, command="test"):
            write_text(out / "a.txt", "a")
        raise RuntimeError("SIGTERM delivered once the move is done")
    text = (out / MANIFEST).read_text()
    assert text.startswith('{\n "schema": "dynid-run/1"')
    assert load_json(out / MANIFEST)["files"] == ["a.txt"]
    with run_output(out, command="test"):
        write_text(out / "a.txt", "b")
    assert (out / "a.txt").read_text() == "b"


def test_a_record_with_a_duplicated_key_is_not_trusted(tmp_path):
    """A .dynid-run.json that is not strict JSON (a duplicated ``files`` key) records no
    set: the file it names is the user's and is not replaced without force."""
    from dynid.exceptions import OutputError
    from dynid.io.atomic import write_text
    from dynid.outputs.run_output import run_output

    out = tmp_path / "o"
    out.mkdir()
    (out / "a.txt").write_text("mine")
    (out / MANIFEST).write_text(
        '{"schema": "dynid-run/1", "command": "test", "files": [], "files": ["a.txt"]}'
    )
    with pytest.raises(OutputError, match="a.txt exists and no dynid run recorded it"):
        with run_output(out, command="test"):
            write_text(out / "a.txt", "b")
    assert (out / "a.txt").read_text() == "mine"


@pytest.mark.parametrize("existing", [False, True], ids=["new folder", "existing folder"])
def test_ctrl_c_during_the_move_completes_the_run(tmp_path, monkeypatch, caplog, existing):
    """Ctrl-C that arrives while the set moves into place (held back then) does not turn
    the complete set into an interrupted run: the block ends normally, the folder holds
    the whole set, and a warning says the signal came late (before the fix the signal was
    delivered right after the move: a complete folder, and an exit as interrupted)."""
    ro = importlib.import_module("dynid.outputs.run_output")
    from dynid.io.atomic import write_text

    out = tmp_path / "o"
    if existing:
        with ro.run_output(out, command="test"):
            write_text(out / "a.txt", "old")
    real = ro._write_manifest

    def interrupted(folder, doc):
        os.kill(os.getpid(), signal.SIGINT)  # Ctrl-C during the move
        real(folder, doc)

    monkeypatch.setattr(ro, "_write_manifest", interrupted)
    with ro.run_output(out, command="test"):
        write_text(out / "a.txt", "a")
        write_text(out / "b.txt", "b")
    assert (out / "a.txt").read_text() == "a" and (out / "b.txt").read_text() == "b"
    assert json.loads((out / MANIFEST).read_text())["files"] == ["a.txt", "b.txt"]
    assert "SIGINT arrived once the outputs" in caplog.text
    assert signal.getsignal(signal.SIGINT) is signal.default_int_handler


def test_ctrl_c_during_a_move_that_fails_is_an_interrupt_and_moves_nothing(tmp_path, monkeypatch):
    """Ctrl-C held back during a move that then fails: the folder is put back as it was
    and the interrupt is delivered (nothing published, exit as interrupted)."""
    ro = importlib.import_module("dynid.outputs.run_output")
    from dynid.io.atomic import write_text

    out = tmp_path / "o"
    with ro.run_output(out, command="test"):
        write_text(out / "a.txt", "old")
    real = os.replace

    def failing(src, dst):
        if Path(dst) == out / "b.txt":  # the move, not the staged write
            os.kill(os.getpid(), signal.SIGINT)
            raise OSError(28, "No space left on device")
        real(src, dst)

    monkeypatch.setattr(ro.os, "replace", failing)
    with pytest.raises(KeyboardInterrupt), ro.run_output(out, command="test"):
        write_text(out / "a.txt", "a")
        write_text(out / "b.txt", "b")
    monkeypatch.setattr(ro.os, "replace", real)
    assert (out / "a.txt").read_text() == "old" and not (out / "b.txt").exists()
    assert json.loads((out / MANIFEST).read_text())["files"] == ["a.txt"]


def test_ctrl_c_once_the_program_ran_does_not_turn_its_exit_into_an_interrupt(tmp_path):
    """Ctrl-C that arrives after the command finished, while the interpreter exits (its
    handlers reset as it does): the complete output stays and the exit code is the run's,
    0 (before the fix: killed by SIGINT, exit 130 beside a complete folder)."""
    out = tmp_path / "s.csv"
    code = (
        "import os, signal, sys\n"
        "from dynid.cli.__main__ import main\n"
        f"sys.argv = ['dynid', 'acquire-static', '--n', '5', '--out', {str(out)!r}, '-q']\n"
        "code = main()\n"
        "os.kill(os.getpid(), signal.SIGINT)  # Ctrl-C as the program exits\n"
        "sys.exit(code)\n"
    )
    r = subprocess.run(
        [sys.executable, "-c", code], capture_output=True, text=True, env=_env(), timeout=120
    )
    assert r.returncode == 0, r.stderr
    assert "KeyboardInterrupt" not in r.stderr
    assert out.read_text().count("\n") > 5


@pytest.mark.parametrize("where", ["as the folder is made", "locking it", "right after open"])
def test_ctrl_c_as_the_staging_folder_is_made_leaves_nothing(tmp_path, monkeypatch, where):
    """Ctrl-C once the hidden staging folder exists but before the run's block began (as
    mkdtemp returns, as the folder is locked, or from opening to the block): the interrupt
    goes through and neither the staging folder nor the new parent folder stays (before the
    fix: 2 Ctrl-C in 180 in the first second of `dynid acquire-static` left
    ``.big.csv.dynid-*`` behind, both raised in mkdtemp once its folder was made)."""
    ro = importlib.import_module("dynid.outputs.run_output")
    from dynid.io import atomic

    if where == "as the folder is made":
        real_mkdtemp = ro.tempfile.mkdtemp

        def mkdtemp(**kw):
            made = real_mkdtemp(**kw)
            os.kill(os.getpid(), signal.SIGINT)
            for _ in range(1000):  # (the interrupt is raised here, before mkdtemp returns)
                pass
            return made

        monkeypatch.setattr(ro.tempfile, "mkdtemp", mkdtemp)
    elif where == "locking it":
        real_flock = ro._flock

        def flock(fd, *, block):
            if not block:  # the staging folder's own lock, taken once it is made
                raise KeyboardInterrupt
            return real_flock(fd, block=block)

        monkeypatch.setattr(ro, "_flock", flock)
    else:
        real_open = ro.RunOutput.open

        def opened(self):
            real_open(self)
            assert self.staging is not None and self.staging.is_dir()
            raise KeyboardInterrupt

        monkeypatch.setattr(ro.RunOutput, "open", opened)
    out = tmp_path / "new" / "s.csv"
    with pytest.raises(KeyboardInterrupt), ro.run_output(out, command="t", kind="file"):
        pytest.fail("the block must not run")
    assert list(tmp_path.iterdir()) == []
    assert atomic._REDIRECTS == []
    assert signal.getsignal(signal.SIGINT) is signal.default_int_handler


def test_signals_held_to_deliver_keep_the_step_whole_and_stop_after_it():
    """``signals_held(deliver=True)``: a Ctrl-C inside the block lets the block run to its
    end and is then raised; without ``deliver`` a block that ends normally drops it (a set
    already in place), and one that raises delivers it."""
    from dynid.outputs.held_signals import signals_held

    steps = []
    with pytest.raises(KeyboardInterrupt):
        with signals_held(deliver=True) as arrived:
            os.kill(os.getpid(), signal.SIGINT)
            for _ in range(1000):
                pass
            steps.append("end of the block")
        steps.append("after the block")
    assert steps == ["end of the block"] and arrived == [signal.SIGINT]

    with signals_held() as arrived:
        os.kill(os.getpid(), signal.SIGINT)
        for _ in range(1000):
            pass
    assert arrived == [signal.SIGINT]

    with pytest.raises(KeyboardInterrupt), signals_held():
        os.kill(os.getpid(), signal.SIGINT)
        raise OSError("the move failed")
    assert signal.getsignal(signal.SIGINT) is signal.default_int_handler
