"""Progress of a long run: the steps the library passes, told to a callback.

The library never prints. A run that wants its progress installs a callback (one line of
text per step) with :func:`reporting`; the steps deep in the library (reading a file,
preparing recordings, each regressor of the structure search, the blocks of a pass over a
log's rows) call :func:`report`, which does nothing without a callback, so that no function
between the two carries it. A :func:`stage` names what the steps belong to
(``"structure search, regressor 2 of 6: 240,000 rows"``). The command line installs a
renderer for every command (throttled, on a terminal, silent with ``-q``:
:meth:`dynid.cli.console.Console.progress_callback`); in Python::

    with dynid.progress.reporting(print):
        identify_files(robot, ["long.csv"])
"""

from __future__ import annotations

import contextlib
from collections.abc import Callable, Iterator
from contextvars import ContextVar

__all__ = ["Progress", "report", "reporting", "stage"]

#: A progress callback: one line of text per step.
Progress = Callable[[str], None]

_CURRENT: ContextVar[Progress | None] = ContextVar("dynid_progress", default=None)
_STAGE: ContextVar[str] = ContextVar("dynid_progress_stage", default="")


@contextlib.contextmanager
def reporting(progress: Progress | None) -> Iterator[None]:
    """Tell the steps of the run in this block to ``progress`` (None: to nobody); the
    callback of an enclosing block is restored after it."""
    token = _CURRENT.set(progress)
    try:
        yield
    finally:
        _CURRENT.reset(token)


@contextlib.contextmanager
def stage(name: str) -> Iterator[None]:
    """Report ``name`` and prefix the steps reported within the block with it."""
    report(name)
    token = _STAGE.set(name)
    try:
        yield
    finally:
        _STAGE.reset(token)


def report(step: str) -> None:
    """Tell ``step`` (one line; within a :func:`stage`, prefixed with its name) to the
    callback installed by :func:`reporting`, if any."""
    progress = _CURRENT.get()
    if progress is not None:
        name = _STAGE.get()
        progress(f"{name}: {step}" if name else step)
