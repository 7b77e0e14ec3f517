"""What a run printed and warned.

:class:`RunRecord` stands in for ``sys.stdout`` and ``sys.stderr`` during a command: it
passes everything through, keeps a copy (the printed summary, the warning and note lines)
and keeps a closed stdout (``dynid fk ... | head -1``) from failing the run: what cannot
be printed is dropped and :attr:`RunRecord.stdout_closed` says so.
"""

from __future__ import annotations

import contextlib
import logging
import sys
import time
from typing import Any, TextIO

__all__ = ["RunRecord"]


class _Tee:
    """A text stream that writes through to ``stream`` and keeps a copy."""

    def __init__(self, stream: TextIO, record: RunRecord, *, stdout: bool) -> None:
        self._stream, self._record, self._stdout = stream, record, stdout

    def write(self, text: str) -> int:
        (self._record.out_parts if self._stdout else self._record.err_parts).append(text)
        if self._stdout and self._record.stdout_closed:
            return len(text)
        try:
            return self._stream.write(text)
        except BrokenPipeError:
            if not self._stdout:
                raise
            self._record.stdout_closed = True
            return len(text)

    def flush(self) -> None:
        if self._stdout and self._record.stdout_closed:
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
        self.tables: list[tuple[str, list[str], list[list[str]]]] = []
        self.started = time.time()
        self._saved: tuple[Any, Any] | None = None
        self._handler = _Collect(self.logged)

    def __enter__(self) -> RunRecord:
        self._saved = (sys.stdout, sys.stderr)
        sys.stdout = _Tee(sys.stdout, self, stdout=True)
        sys.stderr = _Tee(sys.stderr, self, stdout=False)
        logging.getLogger().addHandler(self._handler)
        return self

    def __exit__(self, *exc: object) -> None:
        logging.getLogger().removeHandler(self._handler)
        try:
            sys.stdout.flush()
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
        from the prefix on; logged warnings count as warnings."""
        found = []
        for text in ("".join(self.err_parts), self.printed):
            for line in text.splitlines():
                s = line.strip()
                if prefix in s and not s.startswith("WARNING "):
                    found.append(s[s.index(prefix) + len(prefix) :])
        return found + (self.logged if prefix == "warning: " else [])


class _Collect(logging.Handler):
    """Keeps the messages of the warnings logged during a run."""

    def __init__(self, into: list[str]) -> None:
        super().__init__(logging.WARNING)
        self._into = into

    def emit(self, record: logging.LogRecord) -> None:
        with contextlib.suppress(Exception):
            self._into.append(record.getMessage())
