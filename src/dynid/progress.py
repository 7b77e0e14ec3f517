"""Progress of a long run: the steps the library passes, told to a callback.

The library never prints. A run that wants its progress installs a callback (one line of
text per step) with :func:`reporting`; the steps deep in the library (reading a file,
preparing recordings, each regressor of the structure search, the blocks of a pass over a
log's rows) call :func:`report`, which does nothing without a callback, so that no function
between the two carries it. A :func:`stage` names what the steps belong to
(``"structure search, regressor 2 of 6: a pass over the rows, 240,000 of 480,000
read"``): every count it knows the total of is told with it (:func:`rows_read`: the rows
of a stage that says how many it holds). The command line installs a
renderer for every command (throttled, on a terminal, silent with ``-q``:
:meth:`dynid.cli.console.Console.progress_callback`); in Python::

    with dynid.progress.reporting(print):
        identify_files(robot, ["long.csv"])
"""

from __future__ import annotations

import contextlib
import logging
from collections.abc import Callable, Iterator
from contextvars import ContextVar

__all__ = ["NOTE", "Progress", "report", "reporting", "rows_read", "stage"]

#: Logging level of a note, between ``INFO`` and ``WARNING``: what the reader should know
#: that is no problem (a unit converted as asked, a sign flipped by ``--units tau=-1``).
#: The command line prints it as ``dynid CMD: note: ...`` (silent with ``-q``).
NOTE = 25
logging.addLevelName(NOTE, "NOTE")

#: A progress callback: one line of text per step.
Progress = Callable[[str], None]

_CURRENT: ContextVar[Progress | None] = ContextVar("dynid_progress", default=None)
_STAGE: ContextVar[str] = ContextVar("dynid_progress_stage", default="")
_ROWS: ContextVar[int | None] = ContextVar("dynid_progress_rows", default=None)


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
def stage(name: str, *, rows: int | None = None) -> Iterator[None]:
    """Report ``name`` and prefix the steps reported within the block with it; ``rows``:
    the rows a pass over the stage's data reads, the total of :func:`rows_read` within
    the block (none: the stage's rows are not known, and an enclosing stage's are not
    its)."""
    report(name)
    token, rows_token = _STAGE.set(name), _ROWS.set(rows)
    try:
        yield
    finally:
        _ROWS.reset(rows_token)
        _STAGE.reset(token)


def rows_read(done: int) -> None:
    """Report a pass over the rows at ``done`` rows read, of the stage's ``rows`` when it
    said them (:func:`stage`) and the pass is within them."""
    total = _ROWS.get()
    of = f" of {total:,}" if total is not None and done <= total else ""
    report(f"a pass over the rows, {done:,}{of} read")


def report(step: str) -> None:
    """Tell ``step`` (one line; within a :func:`stage`, prefixed with its name) to the
    callback installed by :func:`reporting`, if any."""
    progress = _CURRENT.get()
    if progress is not None:
        name = _STAGE.get()
        progress(f"{name}: {step}" if name else step)
