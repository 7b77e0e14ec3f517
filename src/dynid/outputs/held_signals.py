"""Termination signals held back while a run's output set moves into place
(:class:`~dynid.outputs.run_output.RunOutput`): a signal that arrives once the set is in
place does not turn a complete run into an interrupted one."""

from __future__ import annotations

import contextlib
import signal
import threading
from collections.abc import Iterator

__all__ = ["HELD", "signals_held"]

#: Signals held back while a set moves into place (the command line turns them into exits).
HELD = tuple(
    getattr(signal, s) for s in ("SIGINT", "SIGTERM", "SIGHUP", "SIGQUIT") if hasattr(signal, s)
)


@contextlib.contextmanager
def signals_held(*, deliver: bool = False) -> Iterator[list[int]]:
    """Hold the termination signals back inside the block; yields the list of those that
    arrived meanwhile (filled when the block ends), which are not delivered when the block
    ends normally and are delivered again when it raises.

    With ``deliver`` they are delivered when the block ends, also normally: the block is a
    step an interrupt must not cut in two (a folder made and its name not yet kept, which
    then nothing would remove), and the run stops right after it as asked.

    Blocked in this thread, and, in the main thread, their handlers replaced by a record
    of their arrival: a signal that another thread takes still runs its handler in the
    main thread, and one left pending would arrive right after the block, both when the
    set is already in place (a complete folder, and an exit as interrupted).
    """
    arrived: list[int] = []
    handlers = {}
    if threading.current_thread() is threading.main_thread():
        for s in HELD:
            h = signal.getsignal(s)
            if h is not None:  # a handler Python can put back
                handlers[s] = h
                signal.signal(s, lambda signum, frame: arrived.append(signum))
    blocking = hasattr(signal, "pthread_sigmask")
    old = signal.pthread_sigmask(signal.SIG_BLOCK, HELD) if blocking else set()
    ok = False
    try:
        yield arrived
        ok = True
    finally:
        if blocking:
            for s in sorted(signal.sigpending() & set(HELD)):  # taken here, not after
                with contextlib.suppress(OSError):
                    if signal.sigtimedwait([s], 0) is not None:
                        arrived.append(s)
            signal.pthread_sigmask(signal.SIG_SETMASK, old)
        for s, h in handlers.items():
            signal.signal(s, h)
        if deliver or not ok:
            for s in dict.fromkeys(arrived):  # (the set did not move): stop as asked
                signal.raise_signal(s)
