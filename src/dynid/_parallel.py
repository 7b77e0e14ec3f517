"""Process pools that stop with their caller.

:func:`process_pool` is a :class:`~concurrent.futures.ProcessPoolExecutor` whose workers
ignore Ctrl-C (SIGINT goes to the whole process group; the caller decides) and take the
default action on SIGTERM. When the block ends with an exception (an error, Ctrl-C, a
termination signal turned into an exception), pending tasks are cancelled and the
worker processes are terminated and joined, so none is left running (reparented to
init) after the caller exits.
"""

from __future__ import annotations

import contextlib
import signal
from collections.abc import Iterator
from concurrent.futures import ProcessPoolExecutor

__all__ = ["process_pool"]


def _init_worker() -> None:
    signal.signal(signal.SIGINT, signal.SIG_IGN)
    signal.signal(signal.SIGTERM, signal.SIG_DFL)


@contextlib.contextmanager
def process_pool(max_workers: int) -> Iterator[ProcessPoolExecutor]:
    """A process pool of ``max_workers`` workers, terminated if the block raises."""
    ex = ProcessPoolExecutor(max_workers=max_workers, initializer=_init_worker)
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
