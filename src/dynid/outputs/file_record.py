"""The record of the single output files that runs wrote into a folder.

A command whose ``--out`` is one file (``simulate``, ``acquire-static``, ``import``,
``export``) records it in ``.dynid-files.json`` of the file's folder: the command, the
file's size and modification time, the command line, the time. A later run replaces the
file without ``--force`` only when that record holds it as it is now and names the same
command: a file the user wrote, one another command wrote, or one changed since (edited,
copied over) is not the run's to replace (:class:`~dynid.outputs.run_output.RunOutput`).
"""

from __future__ import annotations

import logging
from pathlib import Path
from typing import Any

from ..exceptions import DataError
from ..io.json_files import load_json, save_json

__all__ = ["FILES_RECORD", "record_file", "recorded_writer"]

#: Name of the record, in a folder, of the single files that runs wrote there.
FILES_RECORD = ".dynid-files.json"
_SCHEMA = "dynid-files/1"
_log = logging.getLogger(__name__)


def _read(folder: Path) -> dict[str, dict[str, Any]]:
    """The files recorded in ``folder``: name -> entry (empty when the record is absent
    or unreadable: no file recorded)."""
    try:
        doc = load_json(folder / FILES_RECORD, schema=_SCHEMA, what="dynid file record")
    except (OSError, DataError):
        return {}
    files = doc.get("files")
    if not isinstance(files, dict):
        return {}
    return {k: v for k, v in files.items() if isinstance(k, str) and isinstance(v, dict)}


def _state(path: Path) -> tuple[int, int]:
    """What tells a file unchanged: (size [bytes], modification time [ns])."""
    st = path.stat()
    return int(st.st_size), int(st.st_mtime_ns)


def recorded_writer(path: Path) -> str | None:
    """The command whose run wrote the file ``path`` as it is now, or None (no run
    recorded it, or it changed since)."""
    entry = _read(path.parent).get(path.name)
    if entry is None or path.is_symlink() or not path.is_file():
        return None
    try:
        same = (entry.get("size"), entry.get("mtime_ns")) == _state(path)
    except OSError:
        return None
    command = entry.get("command")
    return command if same and isinstance(command, str) else None


def record_file(path: Path, command: str, **about: Any) -> None:
    """Record the file ``path`` that a run of ``command`` just put in place (``about``:
    the command line, the version, the time); entries of files no longer there are
    dropped. The caller holds the folder's lock. A record that cannot be written is a
    logged warning: the file is in place, only a later run's check is lost."""
    folder = path.parent
    files = {k: v for k, v in _read(folder).items() if (folder / k).is_file()}
    size, mtime = _state(path)
    files[path.name] = {"command": command, "size": size, "mtime_ns": mtime, **about}
    try:
        save_json(folder / FILES_RECORD, {"files": files}, schema=_SCHEMA)
    except OSError as exc:
        _log.warning("could not record %s in %s: %s", path.name, FILES_RECORD, exc)
