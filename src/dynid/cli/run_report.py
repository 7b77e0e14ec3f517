"""What a run printed and warned, and the report made of it.

:class:`RunRecord` stands in for ``sys.stdout`` and ``sys.stderr`` during a command: it
passes everything through, keeps a copy (the printed summary, the warning and note lines)
and keeps a closed stdout (``dynid fk ... | head -1``) from failing the run: what cannot
be printed is dropped and :attr:`RunRecord.stdout_closed` says so.

:func:`save_run_report` writes ``report.html`` (:mod:`dynid.report`) into a
command's output folder from that record and the files the run wrote.
"""

from __future__ import annotations

import argparse
import contextlib
import logging
import os
import sys
import time
from collections.abc import Sequence
from typing import Any, TextIO

from ..outputs.run_output import RunOutput
from ..progress import NOTE
from ..report import REPORT_NAME, ReportTable, RunSummary, save_html_report

__all__ = ["RunRecord", "save_run_report"]


class _Tee:
    """A text stream that writes through to ``stream`` and keeps a copy."""

    def __init__(self, stream: TextIO | None, record: RunRecord, *, stdout: bool) -> None:
        self._stream, self._record, self._stdout = stream, record, stdout
        if stream is None and stdout:  # started with file descriptor 1 closed (``>&-``)
            record.stdout_closed = True

    def write(self, text: str) -> int:
        (self._record.out_parts if self._stdout else self._record.err_parts).append(text)
        if self._stream is None or (self._stdout and self._record.stdout_closed):
            return len(text)
        try:
            return self._stream.write(text)
        except BrokenPipeError:
            if not self._stdout:
                raise
            self._record.stdout_closed = True
            return len(text)

    def flush(self) -> None:
        if self._stream is None or (self._stdout and self._record.stdout_closed):
            return
        try:
            self._stream.flush()
        except BrokenPipeError:
            if not self._stdout:
                raise
            self._record.stdout_closed = True

    def __getattr__(self, name: str) -> Any:
        return getattr(self._stream, name)


class RunRecord:
    """The copy of a run's stdout and stderr; install with ``with RunRecord() as rec``."""

    def __init__(self) -> None:
        self.out_parts: list[str] = []
        self.err_parts: list[str] = []
        self.stdout_closed = False
        self.logged: list[str] = []
        self.logged_notes: list[str] = []
        self.tables: list[tuple[str, list[str], list[list[str]]]] = []
        self.options_used: dict[str, str] = {}  # dest -> the value the run resolved
        self.started = time.time()
        self._saved: tuple[Any, Any] | None = None
        self._handler = _Collect(self.logged, self.logged_notes)

    def __enter__(self) -> RunRecord:
        self._saved = (sys.stdout, sys.stderr)
        sys.stdout = _Tee(sys.stdout, self, stdout=True)
        sys.stderr = _Tee(sys.stderr, self, stdout=False)
        logging.getLogger().addHandler(self._handler)
        return self

    def __exit__(self, *exc: object) -> None:
        logging.getLogger().removeHandler(self._handler)
        try:
            sys.stdout.flush()  # the tee, even over a closed or missing stdout
        except BrokenPipeError:  # pragma: no cover - the tee catches it
            self.stdout_closed = True
        assert self._saved is not None
        sys.stdout, sys.stderr = self._saved

    @property
    def printed(self) -> str:
        """What the run printed on stdout."""
        return "".join(self.out_parts)

    def lines(self, prefix: str) -> list[str]:
        """Lines of stdout and stderr that hold ``prefix`` (``"warning: "``, ``"note: "``),
        from the prefix on; logged warnings and notes count as such (once, printed or
        not), and a line said twice (a built-in robot's note, logged each time the robot
        is read) once."""
        found = []
        for text in ("".join(self.err_parts), self.printed):
            for line in text.splitlines():
                s = line.strip()
                if prefix in s:
                    found.append(s[s.index(prefix) + len(prefix) :])
        logged = {"warning: ": self.logged, "note: ": self.logged_notes}.get(prefix, [])
        return list(dict.fromkeys(found + [m for m in logged if m not in found]))


class _Collect(logging.Handler):
    """Keeps the messages of the warnings and of the notes (:data:`~dynid.progress.NOTE`)
    logged during a run, in the command line's words (:func:`~dynid.cli.common.cli_text`:
    ``--max-std-percent``, not the Python option ``max_std_percent=...``)."""

    def __init__(self, warned: list[str], noted: list[str]) -> None:
        super().__init__(NOTE)
        self._warned, self._noted = warned, noted

    def emit(self, record: logging.LogRecord) -> None:
        from .common import cli_text  # as the console prints them: options by their flags

        with contextlib.suppress(Exception):
            into = self._warned if record.levelno >= logging.WARNING else self._noted
            into.append(cli_text(record.getMessage()))


def option_text(value: object) -> str:
    """An option's value as the user gave it: a path as the path, several values
    space-separated, none as ""."""
    if value is None:
        return ""
    if isinstance(value, list | tuple):
        return " ".join(option_text(v) for v in value)
    if isinstance(value, os.PathLike):
        return os.fspath(value)
    return str(value)


def save_run_report(
    run: RunOutput,
    record: RunRecord,
    args: argparse.Namespace,
    argv: Sequence[str],
    code: int,
) -> None:
    """Write ``report.html`` into the run's output folder (staged with its other files).

    Parameters
    ----------
    run : RunOutput
        The run's output set (a folder).
    record : RunRecord
        What the run printed, warned and noted, and the tables it added.
    args : argparse.Namespace
        The parsed options (every option and its value is listed in the report; one the
        run resolved, ``record.options_used``, as the run said it).
    argv : sequence of str
        The command line after ``dynid``.
    code : int
        The run's exit status.

    Raises
    ------
    OSError
        The report cannot be written.
    """
    options = tuple(
        (f"--{k.replace('_', '-')}", record.options_used.get(k, option_text(v)))
        for k, v in sorted(vars(args).items())
        if not k.startswith("_") and k != "command"
    )
    summary = RunSummary(
        command=args.command,
        argv=("dynid", *argv),
        options=options,
        printed=record.printed,
        warnings=tuple(record.lines("warning: ")),
        notes=tuple(record.lines("note: ")),
        tables=tuple(
            ReportTable(title, tuple(head), tuple(map(tuple, rows)))
            for title, head, rows in record.tables
        ),
        exit_code=code,
        elapsed_s=time.time() - record.started,
    )
    save_html_report(run.out / REPORT_NAME, summary, run.written())
