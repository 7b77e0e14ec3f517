"""What a command prints, by the common flags ``-q`` and ``-v``.

:func:`dynid.cli.__main__.main` makes one :class:`Console` from the flags and hands it to
the command's ``run(args, console)``; commands print only through it, so that ``-q``
means the same for every command: errors only. Tables, summaries, ``wrote ...`` lines,
progress, notes and warnings are dropped; a result asked for on stdout with ``--json``
is still printed (it is the command's output, as a file under ``--out`` is still written),
and so is a notice that something asked for was not done as asked (:meth:`Console.notice`).
"""

from __future__ import annotations

import sys
from collections.abc import Mapping
from typing import Any

from ..io.json_files import dumps

__all__ = ["Console"]


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
    """

    def __init__(self, command: str, *, quiet: bool = False, verbose: int = 0) -> None:
        self.command, self.quiet, self.verbose = command, bool(quiet), int(verbose)

    def print(self, *lines: str) -> None:
        """The command's tables and summaries on stdout, one argument per line; nothing
        with ``-q``."""
        if not self.quiet:
            for line in lines:
                sys.stdout.write(f"{line}\n")

    def wrote(self, *paths: Any) -> None:
        """``wrote A, B`` on stdout; nothing with ``-q``."""
        self.print("wrote " + ", ".join(str(p) for p in paths))

    def progress(self, text: str) -> None:
        """A progress line on stderr (flushed); nothing with ``-q``."""
        if not self.quiet:
            sys.stderr.write(f"{text}\n")
            sys.stderr.flush()

    def note(self, message: str) -> None:
        """``dynid CMD: note: message`` on stderr; nothing with ``-q``."""
        self.progress(f"dynid {self.command}: note: {message}")

    def warn(self, message: str) -> None:
        """``dynid CMD: warning: message`` on stderr; nothing with ``-q``."""
        self.progress(f"dynid {self.command}: warning: {message}")

    def notice(self, text: str) -> None:
        """A line on stderr printed also with ``-q``: something asked for was not done as
        asked (``--workers`` capped at the cores; a figure skipped)."""
        sys.stderr.write(f"{text}\n")
        sys.stderr.flush()

    def json(self, obj: Mapping[str, Any]) -> None:
        """One strict JSON object on stdout (a NaN or infinity is an error), also with
        ``-q``: it is the result asked for."""
        sys.stdout.write(dumps(obj, indent=None) + "\n")
