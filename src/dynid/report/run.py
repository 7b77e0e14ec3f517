"""What a report is built from: the run's record and its files.

:class:`RunSummary` is what a run was given and said (command line, options, printed
summary, warnings and notes); :class:`RunFiles` adds the files it wrote, their JSON
content read once, for the parts of the page.
"""

from __future__ import annotations

from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

__all__ = ["REPORT_NAME", "Answer", "ReportTable", "RunFiles", "RunSummary"]

#: Name of the report in the output folder.
REPORT_NAME = "report.html"


@dataclass(frozen=True)
class ReportTable:
    """A table a command adds to its report: a title, column headers and rows of text."""

    title: str
    headers: tuple[str, ...]
    rows: tuple[tuple[str, ...], ...]


@dataclass(frozen=True)
class RunSummary:
    """What a run was given and what it said, for its report.

    Parameters
    ----------
    command : str
        The command (``identify``).
    argv : tuple of str
        The command line as typed (``("dynid", "identify", "--data", ...)``).
    options : tuple of (str, str)
        Every option of the command with the value used (defaults included).
    printed : str
        What the run printed on stdout (its summary).
    warnings, notes : tuple of str
        The warning and note lines, without their prefix.
    tables : tuple of ReportTable
        Tables the command added.
    exit_code : int
        The run's exit status (1: a documented negative result, such as no feasible set).
    elapsed_s : float or None
        Wall time of the run [s].
    """

    command: str
    argv: tuple[str, ...] = ()
    options: tuple[tuple[str, str], ...] = ()
    printed: str = ""
    warnings: tuple[str, ...] = ()
    notes: tuple[str, ...] = ()
    tables: tuple[ReportTable, ...] = field(default_factory=tuple)
    exit_code: int = 0
    elapsed_s: float | None = None


@dataclass(frozen=True)
class RunFiles:
    """A run's record and its files, as the parts of a report read them.

    Attributes
    ----------
    summary : RunSummary
    files : dict of str to Path
        Name relative to the output folder (POSIX separators) -> where the content is now.
    docs : dict of str to object
        The parsed content of each JSON file (None: not readable as JSON).
    """

    summary: RunSummary
    files: dict[str, Path]
    docs: dict[str, Any]

    def doc(self, name: str) -> dict[str, Any] | None:
        """The JSON object of the file ``name`` (or of the one file whose name ends with
        ``/name``), or None."""
        if isinstance(self.docs.get(name), dict):
            return self.docs[name]
        found = [d for rel, d in self.docs.items() if rel.endswith("/" + name)]
        return found[0] if len(found) == 1 and isinstance(found[0], dict) else None

    def png(self, name: str) -> str | None:
        """The relative name of the figure ``name`` (at the top or in one folder), or None."""
        if name in self.files:
            return name
        found = [rel for rel in self.files if rel.endswith("/" + name)]
        return found[0] if len(found) == 1 else None


@dataclass(frozen=True)
class Answer:
    """A command's answer at the top of its report.

    Attributes
    ----------
    verdict : str
        HTML of the verdict box (:func:`dynid.report.html.verdict`): can the result be
        trusted, and why.
    sections : tuple of str
        HTML of the parts that follow it (figures, tables with named columns and units).
    shown : frozenset of str
        Files the answer showed in full (their figures are not repeated below).
    """

    verdict: str
    sections: tuple[str, ...] = ()
    shown: frozenset[str] = frozenset()
