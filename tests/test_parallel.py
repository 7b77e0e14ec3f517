"""Process pools that stop with their caller (dynid._parallel), signals included."""

from __future__ import annotations

import os
import signal
import subprocess
import sys
import time
from pathlib import Path

import pytest

SRC = Path(__file__).resolve().parents[1] / "src"

#: A caller that turns SIGTERM into an exception (as the command line does) and starts a
#: pool whose workers' start-up is made long (a sleep before their initializer), so that
#: a signal to the process group arrives while the workers start.
SCRIPT = r"""
import os, signal, sys, time
from dynid import _parallel

class Terminated(BaseException):
    pass

def terminate(signum, frame):
    raise Terminated(signum)

signal.signal(signal.SIGTERM, terminate)
init = _parallel._init_worker

def slow_init(*args):
    os.write(1, b"worker\n")  # one write: the lines of two workers are not mixed
    time.sleep(float(sys.argv[1]))
    init(*args)

_parallel._init_worker = slow_init
try:
    with _parallel.process_pool(2) as ex:
        futs = [ex.submit(time.sleep, 60) for _ in range(2)]
        print("submitted", flush=True)
        for f in futs:
            f.result()
except Terminated:
    print("terminated", flush=True)
    sys.exit(143)
"""


def _in_session(sid: int) -> list[int]:
    """The processes of session ``sid`` (from /proc)."""
    out = []
    for d in Path("/proc").iterdir():
        if d.name.isdigit():
            try:
                fields = (d / "stat").read_text().rsplit(")", 1)[1].split()
            except OSError:
                continue
            if int(fields[3]) == sid and fields[0] != "Z":
                out.append(int(d.name))
    return out


@pytest.mark.skipif(not sys.platform.startswith("linux"), reason="reads /proc, forks")
def test_sigterm_while_the_workers_start_leaves_no_worker_and_no_traceback():
    """SIGTERM to the process group while the workers run their start-up: the caller
    stops cleanly (its own exception, exit 143), the workers die by the signal without
    running the caller's handler (before the fix each raised the caller's exception and
    died with a traceback), and no process of the run is left."""
    env = dict(os.environ, PYTHONPATH=str(SRC))
    proc = subprocess.Popen(
        [sys.executable, "-c", SCRIPT, "1.0"],
        stdout=subprocess.PIPE,
        stderr=subprocess.PIPE,
        text=True,
        env=env,
        start_new_session=True,
    )
    try:
        seen = ""  # the workers' and the caller's writes may interleave within a line
        assert proc.stdout is not None
        while seen.count("worker") < 2 or "submitted" not in seen:  # both in their start-up
            line = proc.stdout.readline()
            assert line, proc.stderr.read() if proc.stderr else ""
            seen += line
        assert seen.count("worker") == 2, seen
        os.killpg(proc.pid, signal.SIGTERM)
        out, err = proc.communicate(timeout=30)
    finally:
        if proc.poll() is None:
            os.killpg(proc.pid, signal.SIGKILL)
            proc.wait()
    assert proc.returncode == 143, err
    assert "terminated" in out
    assert "Traceback" not in err, err
    for _ in range(50):  # the workers are reaped by the caller's clean-up
        if not _in_session(proc.pid):
            break
        time.sleep(0.1)
    assert _in_session(proc.pid) == []


@pytest.mark.skipif(not sys.platform.startswith("linux"), reason="forks")
def test_a_stopped_pool_leaves_no_manager_thread_for_the_exit_hook():
    """After the clean-up of a block that raised, the executor's manager thread has ended:
    the interpreter's exit hook writes to the thread's wake-up pipe while the thread lives,
    and the thread closing the pipe meanwhile printed ``OSError: [Errno 9] Bad file
    descriptor`` as a SIGHUP run's last line (the shutdown forgets the thread, and the
    clean-up found nothing to join)."""
    from dynid import _parallel

    with pytest.raises(KeyboardInterrupt), _parallel.process_pool(2) as ex:
        futs = [ex.submit(time.sleep, 60) for _ in range(2)]
        manager = ex._executor_manager_thread  # type: ignore[attr-defined]
        assert manager is not None and manager.is_alive()
        time.sleep(0.2)
        raise KeyboardInterrupt
    assert not manager.is_alive()
    assert all(f.cancelled() or f.done() for f in futs)
