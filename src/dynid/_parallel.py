"""Process pools that stop with their caller.

:func:`process_pool` is a :class:`~concurrent.futures.ProcessPoolExecutor` whose workers
ignore Ctrl-C (SIGINT goes to the whole process group; the caller decides) and take the
default action on SIGTERM, SIGHUP and SIGQUIT. When the block ends with an exception (an
error, Ctrl-C, a termination signal turned into an exception), pending tasks are cancelled
and the worker processes are terminated and joined, so none is left running (reparented
to init) after the caller exits.

A caller that dies without running its clean-up (SIGKILL, a crash) takes its workers
along: on Linux each worker asks the kernel for SIGKILL when its parent exits
(``prctl(PR_SET_PDEATHSIG)``); elsewhere a watchdog thread in each worker exits it when its
parent process is gone. :func:`available_cores` counts the cores this process may run on
and :func:`process_pool` never starts more workers than that.
"""

from __future__ import annotations

import contextlib
import ctypes
import ctypes.util
import os
import signal
import sys
import threading
import time
from collections.abc import Iterator
from concurrent.futures import ProcessPoolExecutor

__all__ = ["available_cores", "process_pool"]

#: ``PR_SET_PDEATHSIG`` of ``<linux/prctl.h>``.
_PR_SET_PDEATHSIG = 1


def available_cores() -> int:
    """The number of cores this process may run on (its CPU affinity, else all of them)."""
    try:
        return max(1, len(os.sched_getaffinity(0)))
    except (AttributeError, OSError):  # pragma: no cover - not Linux
        return max(1, os.cpu_count() or 1)


def _die_with_parent(parent: int) -> None:
    """Make this process exit when ``parent`` (its parent process) does."""
    if sys.platform.startswith("linux"):
        with contextlib.suppress(OSError, AttributeError):
            libc = ctypes.CDLL(ctypes.util.find_library("c") or "libc.so.6", use_errno=True)
            if libc.prctl(_PR_SET_PDEATHSIG, signal.SIGKILL, 0, 0, 0) == 0:
                if os.getppid() != parent:  # it died before the request took hold
                    os._exit(1)
                return

    def watch() -> None:  # pragma: no cover - not Linux
        while os.getppid() == parent:
            time.sleep(0.5)
        os._exit(1)

    threading.Thread(target=watch, name="dynid-parent-watchdog", daemon=True).start()


def _init_worker() -> None:
    _die_with_parent(os.getppid())
    signal.signal(signal.SIGINT, signal.SIG_IGN)
    for name in ("SIGTERM", "SIGHUP", "SIGQUIT"):
        if hasattr(signal, name):
            signal.signal(getattr(signal, name), signal.SIG_DFL)


@contextlib.contextmanager
def process_pool(max_workers: int) -> Iterator[ProcessPoolExecutor]:
    """A process pool of ``max_workers`` workers (at most :func:`available_cores`),
    terminated if the block raises."""
    ex = ProcessPoolExecutor(
        max_workers=max(1, min(max_workers, available_cores())), initializer=_init_worker
    )
    try:
        yield ex
    except BaseException:
        # The executor has no public way to stop running tasks: terminate its workers.
        procs = list((getattr(ex, "_processes", None) or {}).values())
        ex.shutdown(wait=False, cancel_futures=True)
        for p in procs:
            with contextlib.suppress(Exception):
                p.terminate()
        for p in procs:
            with contextlib.suppress(Exception):
                p.join(timeout=5.0)
        raise
    ex.shutdown(wait=True)
