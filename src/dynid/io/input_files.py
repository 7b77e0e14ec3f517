"""Opening the files dynid reads: regular files only, whole-file formats bounded in size.

A device, a pipe or a socket given where a file is expected (``/dev/zero``, ``/dev/stdin``,
``<(command)``) is refused before anything is read: it may never end, and a reader would
spend the machine's memory on it without answering a termination signal. A folder is an
:class:`IsADirectoryError`, a missing file a :class:`FileNotFoundError`, as ``open`` says.

JSON, TOML and URDF files are read whole (:func:`file_bytes`, :func:`file_text`), so their
size is checked first against :data:`MAX_TEXT_BYTES` (256 MiB; the environment variable
``DYNID_MAX_TEXT_BYTES`` gives another, in bytes) and no more than that is ever read.
Logs and static data (CSV, NPZ) are only checked to be regular files
(:func:`regular_file`); their readers bound what they allocate by the recorded row count.
"""

from __future__ import annotations

import errno
import os
import stat
from pathlib import Path

from ..exceptions import DataError

__all__ = ["MAX_TEXT_BYTES", "file_bytes", "file_text", "regular_file"]

#: Largest JSON, TOML or URDF file read [bytes] (a Panda's identification.json holds about
#: 80 kB); the environment variable ``DYNID_MAX_TEXT_BYTES`` gives another.
MAX_TEXT_BYTES = 256 << 20
_ENV = "DYNID_MAX_TEXT_BYTES"


def _limit() -> int:
    text = os.environ.get(_ENV, "")
    try:
        return int(text) if text else MAX_TEXT_BYTES
    except ValueError:
        raise DataError(f"{_ENV} must be a number of bytes; got {text[:40]!r}") from None


def regular_file(path: str | Path) -> int:
    """Check that ``path`` is a regular file (symbolic links followed); returns its size.

    Raises
    ------
    DataError
        A device, a pipe or a socket.
    OSError
        Missing, unreadable, a loop of links, or a folder (:class:`IsADirectoryError`).
    """
    p = Path(path)
    st = os.stat(p)
    if stat.S_ISDIR(st.st_mode):
        raise IsADirectoryError(errno.EISDIR, "is a folder; give a file", str(p))
    if not stat.S_ISREG(st.st_mode):
        raise DataError(
            "not a regular file (a device, a pipe or a socket, which may never end); give a file",
            file=p.name,
        )
    return int(st.st_size)


def file_bytes(path: str | Path) -> bytes:
    """The bytes of a regular file of at most :data:`MAX_TEXT_BYTES`.

    Raises
    ------
    DataError
        Not a regular file, or larger than the limit (the message says how to raise it).
    OSError
        As :func:`regular_file`.
    """
    p = Path(path)
    size = regular_file(p)
    limit = _limit()
    with open(p, "rb") as fh:
        data = fh.read(limit + 1) if size <= limit else b""
    if size > limit or len(data) > limit:
        raise DataError(
            f"{max(size, len(data))} bytes, above the {limit} bytes a JSON, TOML "
            f"or URDF file may have; hint: set the environment variable {_ENV} to raise it",
            file=p.name,
        )
    return data


def file_text(path: str | Path, encoding: str = "utf-8-sig") -> str:
    """:func:`file_bytes` decoded, UTF-8 with or without a byte-order mark by default (as
    JSON and CSV files are read); :class:`UnicodeDecodeError` as ``Path.read_text``."""
    return file_bytes(path).decode(encoding)
