"""What a command prints, by the common flags ``-q`` and ``-v``.

:func:`dynid.cli.__main__.main` makes one :class:`Console` from the flags and hands it to
the command's ``run(args, console)``; commands print only through it, so that ``-q``
means the same for every command: errors only. Tables, summaries, ``wrote ...`` lines,
progress, notes and warnings are dropped; a result asked for on stdout with ``--json``
is still printed (it is the command's output, as a file under ``--out`` is still written),
and so is a notice that something asked for was not done as asked (:meth:`Console.notice`).
What ``-q`` keeps off the terminal still goes to the run's record
(:class:`~dynid.cli.run_report.RunRecord`), so that a run's report holds its summary and
warnings either way.
"""

from __future__ import annotations

import logging
import sys
import time
from collections.abc import Callable, Mapping
from typing import Any

from .._checks import text as as_text
from ..io.json_files import dumps
from ..progress import NOTE
from .run_report import RunRecord

__all__ = ["PROGRESS_AFTER_S", "PROGRESS_EVERY_S", "Console", "LogFormat", "log_to_stderr"]

#: Progress lines (:meth:`Console.progress_callback`) start once a run has taken this long
#: [s], and come at most one every :data:`PROGRESS_EVERY_S` [s].
PROGRESS_AFTER_S = 3.0
PROGRESS_EVERY_S = 2.0


class Console:
    """The printer of one command run.

    Parameters
    ----------
    command : str
        The command's name as typed (``retrieve``, ``acquire-static``): prefixes notes and
        warnings (``dynid retrieve: warning: ...``).
    quiet : bool
        ``-q``: print errors only (and ``--json`` results).
    verbose : int
        ``-v`` count: 1 shows informational log lines, 2 debug ones (set up by ``main``).
    record : RunRecord, optional
        The run's record: receives what ``-q`` keeps off the terminal.
    """

    def __init__(
        self,
        command: str,
        *,
        quiet: bool = False,
        verbose: int = 0,
        record: RunRecord | None = None,
    ) -> None:
        self.command, self.quiet, self.verbose = command, bool(quiet), int(verbose)
        self._record = record

    def _write(self, text: str, *, stdout: bool) -> None:
        text = as_text(text)  # file names of an ASCII locale: their characters
        if self.quiet:
            if self._record is not None:
                (self._record.out_parts if stdout else self._record.err_parts).append(text)
            return
        stream = sys.stdout if stdout else sys.stderr
        stream.write(text)
        if not stdout:
            stream.flush()

    def print(self, *lines: str) -> None:
        """The command's tables and summaries on stdout, one argument per line; nothing
        with ``-q``."""
        self._write("".join(f"{line}\n" for line in lines), stdout=True)

    def option_used(self, dest: str, text: str) -> None:
        """Show ``text`` as the value of the option ``dest`` in the report's options (a
        default the run resolved, such as the delay a model was identified with, or a
        value in the unit it was typed in)."""
        if self._record is not None:
            self._record.options_used[dest] = text

    def wrote(self, *paths: Any) -> None:
        """``wrote A, B`` on stdout; nothing with ``-q``."""
        self.print("wrote " + ", ".join(str(p) for p in paths))

    def progress(self, text: str) -> None:
        """A progress line on stderr (flushed); nothing with ``-q``."""
        self._write(f"{text}\n", stdout=False)

    def progress_callback(self) -> Callable[[str], None] | None:
        """A renderer of the library's progress (:mod:`dynid.progress`) for a long run:
        ``dynid CMD: <step> (12 s)`` on stderr once the run has taken
        :data:`PROGRESS_AFTER_S`, at most one line every :data:`PROGRESS_EVERY_S`; None
        with ``-q`` or when stderr is not a terminal (a file or a pipe gets no lines that
        depend on the machine's speed)."""
        try:
            tty = bool(sys.stderr.isatty())
        except (AttributeError, ValueError):  # no stream, or a closed one
            tty = False
        if self.quiet or not tty:
            return None
        start = time.monotonic()
        last = [start - PROGRESS_EVERY_S]

        def show(step: str) -> None:
            now = time.monotonic()
            if now - start < PROGRESS_AFTER_S or now - last[0] < PROGRESS_EVERY_S:
                return
            last[0] = now
            self.progress(f"dynid {self.command}: {step} ({now - start:.0f} s)")

        return show

    def note(self, message: str) -> None:
        """``dynid CMD: note: message`` on stderr; nothing with ``-q``."""
        self.progress(f"dynid {self.command}: note: {message}")

    def warn(self, message: str) -> None:
        """``dynid CMD: warning: message`` on stderr; nothing with ``-q``."""
        self.progress(f"dynid {self.command}: warning: {message}")

    def notice(self, text: str) -> None:
        """A line on stderr printed also with ``-q``: something asked for was not done as
        asked (``--workers`` capped at the cores; a figure skipped)."""
        sys.stderr.write(f"{as_text(text)}\n")
        sys.stderr.flush()

    def json(self, obj: Mapping[str, Any]) -> None:
        """One strict JSON object on stdout (a NaN or infinity is an error), also with
        ``-q``: it is the result asked for."""
        sys.stdout.write(dumps(obj, indent=None) + "\n")


class LogFormat(logging.Formatter):
    """Log lines as the command's own: a note, warning or error logged by the library reads
    ``dynid identify: warning: r1.csv: ...`` like :meth:`Console.warn` (a note like
    :meth:`Console.note`, level :data:`~dynid.progress.NOTE`); the informational
    and debug lines of ``-v`` keep their level and logger (``INFO dynid.identification.core:
    ...``)."""

    def __init__(self, command: str) -> None:
        super().__init__()
        self.command = command

    def format(self, record: logging.LogRecord) -> str:
        """One line of ``record``."""
        if record.levelno >= NOTE:  # the library's Python options named by their flags
            from .common import cli_text

            said = cli_text(record.getMessage())
            return f"dynid {self.command}: {record.levelname.lower()}: {said}"
        return f"{record.levelname} {record.name}: {record.getMessage()}"


class NoteOnce(logging.Filter):
    """Lets a note (level :data:`~dynid.progress.NOTE`) through once: the same note logged
    again in the run (a robot name resolved for ``--robot`` and ``--prior``) is dropped."""

    def __init__(self) -> None:
        super().__init__()
        self.said: set[str] = set()

    def filter(self, record: logging.LogRecord) -> bool:
        """False for a note already let through."""
        if record.levelno != NOTE:
            return True
        text = record.getMessage()
        if text in self.said:
            return False
        self.said.add(text)
        return True


def log_to_stderr(command: str, level: int) -> None:
    """Print the library's log records of ``level`` and above on stderr as ``command``'s
    own lines (:class:`LogFormat`; each note once, :class:`NoteOnce`), as
    :func:`logging.basicConfig` does: only when the process has no logging set up of its
    own (a handler of an earlier run replaced)."""
    root = logging.getLogger()
    for h in [h for h in root.handlers if isinstance(h.formatter, LogFormat)]:
        root.removeHandler(h)
    if root.handlers:
        return
    handler = logging.StreamHandler()
    handler.setFormatter(LogFormat(command))
    handler.addFilter(NoteOnce())
    root.addHandler(handler)
    root.setLevel(level)
