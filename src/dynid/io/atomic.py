"""Atomic file output: a file appears complete under its name, or not at all.

Every writer of dynid goes through this module:

* :func:`atomic_path` yields a temporary path in the destination's folder (same file
  system, so the rename is atomic); when the block ends normally the file is flushed to
  disk and renamed over the destination with :func:`os.replace`; when it ends with any
  exception (``KeyboardInterrupt`` and termination included) the temporary file is
  deleted and the destination is left as it was.
* :func:`open_atomic`, :func:`write_text` and :func:`write_bytes` are the same for a file
  object, a string and bytes.
* The destination folder is created only when a file is written into it.
* Inside :func:`dynid.outputs.run_output.run_output` (every command that writes into
  ``--out``), a path under ``--out`` is written into that run's staging folder instead;
  :func:`current_location` says where a file written in the run is now.
* :func:`output_transaction` groups the files of one command: on failure, the files and
  folders it created are removed again (files it replaced keep their new content, since
  each was complete when renamed).

Temporary files are named ``.<name>.<random>.tmp<suffix>`` (hidden, the destination's
suffix kept for writers that dispatch on it).
"""

from __future__ import annotations

import contextlib
import os
import tempfile
from collections.abc import Iterator
from pathlib import Path
from typing import IO, Any

__all__ = [
    "atomic_path",
    "current_location",
    "open_atomic",
    "output_transaction",
    "write_bytes",
    "write_text",
]

#: Stack of active transactions; each records (created files, created folders).
_TRANSACTIONS: list[tuple[list[Path], list[Path]]] = []
#: Active run outputs (:class:`dynid.outputs.run_output.RunOutput`): each has ``stage(path)``
#: (the staged path of a file under its ``--out``, or None), ``location(path)`` and
#: ``manages(path)`` (its own record, which it puts back or removes itself).
_REDIRECTS: list[Any] = []


def _staged(path: Path) -> Path | None:
    """The staging path of ``path`` in the innermost run output that holds it, or None."""
    for r in reversed(_REDIRECTS):
        staged = r.stage(path)
        if staged is not None:
            return staged
    return None


def current_location(path: str | Path) -> Path:
    """Where a file written in the current run under ``--out`` is now (its staged copy
    until the run ends); ``path`` itself for any other file."""
    for r in reversed(_REDIRECTS):
        where = r.location(path)
        if where != Path(path):
            return where
    return Path(path)


def _make_parents(folder: Path) -> None:
    """Create ``folder`` and missing parents, recording new ones in the transactions."""
    missing = []
    p = folder
    while not p.exists():
        missing.append(p)
        if p.parent == p:
            break
        p = p.parent
    folder.mkdir(parents=True, exist_ok=True)
    for t in _TRANSACTIONS:
        t[1].extend(reversed(missing))


def _mode() -> int:
    """Permissions of a new file under the current umask (mkstemp makes 0600)."""
    mask = os.umask(0)
    os.umask(mask)
    return 0o666 & ~mask


@contextlib.contextmanager
def atomic_path(path: str | Path) -> Iterator[Path]:
    """Yield a temporary path next to ``path``; rename it to ``path`` when the block succeeds.

    The writer inside the block must create the file at the yielded path (it exists,
    empty, when the block starts).
    """
    path = Path(path)
    staged = _staged(path)
    if staged is not None:  # a file of a run's output set: written into its staging folder
        path = staged
        path.parent.mkdir(parents=True, exist_ok=True)
    else:
        _make_parents(path.parent)
    # staged files and a run output's own record are that run's to keep or drop, not the
    # transaction's (a signal held back during the move must not remove the record)
    existed = path.exists() or staged is not None or any(r.manages(path) for r in _REDIRECTS)
    fd, name = tempfile.mkstemp(
        dir=path.parent, prefix=f".{path.name}.", suffix=f".tmp{path.suffix}"
    )
    try:  # (from here: a Ctrl-C as the file is opened removes it too)
        os.close(fd)
        tmp = Path(name)
        yield tmp
        with open(tmp, "rb+") as fh:
            os.fsync(fh.fileno())
        os.chmod(tmp, _mode())
        os.replace(tmp, path)
    except BaseException:
        with contextlib.suppress(OSError):
            os.unlink(name)
        raise
    if not existed:
        for t in _TRANSACTIONS:
            t[0].append(path)


@contextlib.contextmanager
def open_atomic(
    path: str | Path, mode: str = "w", *, encoding: str | None = "utf-8", newline: str | None = "\n"
) -> Iterator[IO[Any]]:
    """Open a temporary file next to ``path`` for writing; renamed to ``path`` on success.

    ``mode`` is ``"w"`` (text, ``encoding`` and ``newline`` apply) or ``"wb"``.
    """
    if mode not in ("w", "wb"):
        raise ValueError(f"mode must be 'w' or 'wb'; got {mode!r}")  # internal misuse
    with atomic_path(path) as tmp:
        if mode == "wb":
            with open(tmp, "wb") as fh:
                yield fh
        else:
            with open(tmp, "w", encoding=encoding, newline=newline) as fh:
                yield fh


def write_text(path: str | Path, text: str) -> Path:
    """Write ``text`` (UTF-8, ``\\n`` line ends) atomically; returns the path."""
    with open_atomic(path, "w") as fh:
        fh.write(text)
    return Path(path)


def write_bytes(path: str | Path, data: bytes) -> Path:
    """Write ``data`` atomically; returns the path."""
    with open_atomic(path, "wb") as fh:
        fh.write(data)
    return Path(path)


@contextlib.contextmanager
def output_transaction() -> Iterator[None]:
    """Remove the files and folders created inside the block if it raises.

    Used by the command line around each command, so that a failing or interrupted
    command leaves no output of its own behind.
    """
    record: tuple[list[Path], list[Path]] = ([], [])
    _TRANSACTIONS.append(record)
    try:
        yield
    except BaseException:
        files, folders = record
        for f in reversed(files):
            with contextlib.suppress(OSError):
                f.unlink()
        for d in reversed(folders):
            with contextlib.suppress(OSError):
                d.rmdir()  # only when empty: never removes what others put there
        raise
    finally:
        _TRANSACTIONS.remove(record)
