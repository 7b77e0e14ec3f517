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
import functools
import multiprocessing
import os
import signal
import sys
import threading
import time
from collections.abc import Callable, Iterator
from concurrent.futures import Future, ProcessPoolExecutor
from typing import Any

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


#: Signals blocked while workers are forked, until each worker has set its own handlers.
_STOP_SIGNALS = frozenset(
    getattr(signal, s) for s in ("SIGINT", "SIGTERM", "SIGHUP", "SIGQUIT") if hasattr(signal, s)
)


def _init_worker(parent: int) -> None:
    """Set a worker's handlers, then take the signals that arrived meanwhile; the worker
    exits with ``parent`` (the caller's process id, taken before the fork).

    A forked worker starts with its caller's handlers (a SIGTERM would raise the caller's
    exception inside the worker, which then died with a traceback, as a broken pool) but
    also with its caller's signals blocked (:func:`_signals_blocked` around the forks):
    what arrived during the start-up is delivered here, to the worker's own handlers.
    """
    _die_with_parent(parent)
    signal.signal(signal.SIGINT, signal.SIG_IGN)
    for name in ("SIGTERM", "SIGHUP", "SIGQUIT"):
        if hasattr(signal, name):
            signal.signal(getattr(signal, name), signal.SIG_DFL)
    if hasattr(signal, "pthread_sigmask"):
        signal.pthread_sigmask(signal.SIG_UNBLOCK, _STOP_SIGNALS)


@contextlib.contextmanager
def _signals_blocked() -> Iterator[None]:
    """Block the stop signals in this thread for the block (the workers forked in it
    inherit the mask); a signal that arrives meanwhile is taken when the block ends."""
    if not hasattr(signal, "pthread_sigmask"):  # pragma: no cover - not POSIX
        yield
        return
    old = signal.pthread_sigmask(signal.SIG_BLOCK, _STOP_SIGNALS)
    try:
        yield
    finally:
        signal.pthread_sigmask(signal.SIG_SETMASK, old)


class _Pool(ProcessPoolExecutor):
    """A pool whose workers are forked with the stop signals blocked (see
    :func:`_init_worker`); the caller takes a signal after the fork, when the worker is
    recorded, so that the clean-up of :func:`process_pool` finds every worker."""

    def submit(self, fn: Any, /, *args: Any, **kwargs: Any) -> Future[Any]:
        with _signals_blocked():
            return super().submit(fn, *args, **kwargs)


def _workers(ex: ProcessPoolExecutor) -> list[Any]:
    """The worker processes of ``ex``: those it recorded and those started but not yet
    recorded (a signal between the start and the record)."""
    procs = list((getattr(ex, "_processes", None) or {}).values())
    queue = getattr(ex, "_call_queue", None)
    for p in multiprocessing.active_children():
        args = getattr(p, "_args", ())
        if queue is not None and args and args[0] is queue and p not in procs:
            procs.append(p)
    return procs


def _again(step: Callable[[], object]) -> None:
    """Run ``step``; when a signal (its exception) interrupts it, run it again (a flood of
    signals: at most 100 times); an error ends it (a worker already gone)."""
    for _ in range(100):
        try:
            step()
            return
        except Exception:
            return
        except BaseException:  # a second signal: the caller is already stopping on the first
            continue


def _stop(ex: ProcessPoolExecutor) -> None:
    """Cancel the pending tasks, terminate and join the workers of ``ex`` and its manager
    thread, each step done again when a second signal interrupts it (the caller is already
    stopping)."""
    procs: list[Any] = []
    _again(lambda: procs.extend(p for p in _workers(ex) if p not in procs))
    # taken before the shutdown, which forgets it (``_executor_manager_thread = None``)
    manager = getattr(ex, "_executor_manager_thread", None)
    _again(lambda: ex.shutdown(wait=False, cancel_futures=True))
    for p in procs:
        _again(p.terminate)
    for p in procs:
        _again(functools.partial(p.join, timeout=5.0))
    # the executor's manager thread closes its wake-up pipe when it ends; the interpreter's
    # exit hook writes to that pipe if the thread has not ended, and a close between its
    # check and its write prints a traceback (Python 3.11): let the thread end first
    if manager is not None:
        _again(functools.partial(manager.join, timeout=5.0))


@contextlib.contextmanager
def process_pool(max_workers: int) -> Iterator[ProcessPoolExecutor]:
    """A process pool of ``max_workers`` workers (at most :func:`available_cores`),
    terminated if the block raises (its workers are forked with the stop signals blocked
    until they have their own handlers, and the clean-up survives a second signal)."""
    ex = _Pool(
        max_workers=max(1, min(max_workers, available_cores())),
        initializer=_init_worker,
        initargs=(os.getpid(),),
    )
    try:
        yield ex
    except BaseException:
        _stop(ex)  # the executor has no public way to stop running tasks
        raise
    ex.shutdown(wait=True)
