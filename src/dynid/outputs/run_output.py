"""The output set of one command run: staged beside ``--out``, moved into place complete.

:func:`run_output` is what the command line wraps around every command that writes into
``--out`` (a folder, or a single file for ``simulate``, ``acquire-static``, ``import`` and
``export``). The rules, in the order a run meets them:

* **Staging.** Every file the run writes under ``--out`` (through :mod:`dynid.io.atomic`,
  which every writer uses) goes into a fresh hidden folder beside it,
  ``.<name>.dynid-<random>``; nothing under ``--out`` changes while the command computes.
* **Failure.** A run that fails, is interrupted or is terminated removes its staging
  folder (and any parent folder it created): ``--out`` is left exactly as it was, and no
  empty new folder stays.
* **Success.** The complete set moves into place: onto a new ``--out`` by one rename;
  into an existing folder file by file (each a rename, with the previous version kept
  aside until the whole set is in place, and put back if a move fails). Termination
  signals are held back from the move to the run's end: one that arrives once the set
  is in place is reported as late and the run completes; one before, nothing moved.
* **Ownership.** A folder records the set of its last run in ``.dynid-run.json`` (command,
  files, time). A run of the same command replaces that set as a whole: files of the old
  set that the new run does not write are removed once the new set is complete. Files
  the run did not write are never touched, except where it must write the same name:
  a file of another command's set, or a file no dynid run recorded (the user's), is
  replaced only with ``--force``; otherwise the run refuses before moving anything, with
  a line naming the files. A single ``--out FILE`` is recorded in ``.dynid-files.json``
  of its folder (:mod:`.file_record`); the next run of the same command replaces it, and
  a file that record does not hold as it is now (the user's, one another command wrote,
  or one changed since) is replaced only with ``--force``.
* **Read-only files** (no write permission) are never replaced without ``--force``. A
  read-only or foreign target is refused as soon as the run writes the file (before the
  command says it wrote it), and again when the set moves.
* **Concurrent runs** into one folder are serialised at the moment of moving: each moves
  its complete set while holding a lock (``flock`` on the parent folder, released by the
  kernel when a process dies), so two sets never interleave; the last run's set stands.
* **Stale files** of earlier runs that were killed (SIGKILL, power loss) are removed by
  the next run: staging folders no live process holds (each run keeps a lock on its
  own) and temporary files of the writers (``.<name>.<random>.tmp<suffix>``).

Without ``fcntl`` (not POSIX) runs are not locked against each other; the rest holds.
"""

from __future__ import annotations

import contextlib
import logging
import os
import shutil
import signal
import tempfile
import time
from collections.abc import Iterator, Sequence
from pathlib import Path

from ..exceptions import DataError, OutputError
from ..io import atomic
from ..io.json_files import load_json, save_json
from .file_record import FILES_RECORD, record_file, recorded_writer
from .held_signals import signals_held

try:
    import fcntl
except ImportError:  # pragma: no cover - not POSIX
    fcntl = None  # type: ignore[assignment]

__all__ = ["FILES_RECORD", "MANIFEST", "RunOutput", "run_output"]

#: Name of the record of a folder's output set (hidden, strict JSON).
MANIFEST = ".dynid-run.json"
_SCHEMA = "dynid-run/1"
_STAGING = ".dynid-"
_log = logging.getLogger(__name__)


def _flock(fd: int, *, block: bool) -> bool:
    """Lock ``fd`` exclusively; False when ``block`` is off and another process holds it."""
    if fcntl is None:  # pragma: no cover - not POSIX
        return True
    try:
        fcntl.flock(fd, fcntl.LOCK_EX | (0 if block else fcntl.LOCK_NB))
    except BlockingIOError:
        return False
    return True


@contextlib.contextmanager
def _folder_lock(folder: Path) -> Iterator[None]:
    """Hold an exclusive lock on ``folder`` (blocking; none if it cannot be opened)."""
    try:
        fd = os.open(folder, os.O_RDONLY)
    except OSError:  # an unreadable folder: no lock, the rest still holds
        yield
        return
    try:
        _flock(fd, block=True)
        yield
    finally:
        os.close(fd)  # releases the lock


def _is_temporary(name: str, targets: set[str]) -> bool:
    """``.<target>.<random>.tmp<suffix>``: a writer's temporary file of one of ``targets``."""
    if not name.startswith(".") or ".tmp" not in name:
        return False
    return any(name.startswith(f".{t}.") for t in targets)


def _read_manifest(folder: Path) -> dict | None:
    """The output record of ``folder``, or None (absent or unreadable: no recorded set)."""
    try:
        doc = load_json(folder / MANIFEST, schema=_SCHEMA, what="dynid run record")
    except (OSError, DataError):
        return None
    files = doc.get("files")
    if not isinstance(files, list) or not all(isinstance(f, str) for f in files):
        return None
    return doc


def _write_manifest(folder: Path, doc: dict) -> None:
    """Write the record directly into ``folder`` (not staged), atomically, as strict JSON."""
    save_json(folder / MANIFEST, doc, schema=_SCHEMA)


def _can_write(folder: Path) -> bool:
    """Whether this process may create files in ``folder`` (always, for root)."""
    return os.access(folder, os.W_OK | os.X_OK)


def _writable(path: Path) -> bool:
    """False for a file without its owner's write permission (also when we are root, who
    could write it) or one we may not write."""
    if path.is_symlink():
        return True  # replaced as a link, its target untouched
    return bool(path.stat().st_mode & 0o200) and os.access(path, os.W_OK)


class RunOutput:
    """The output set of one run into ``out``; see the module docstring for the rules.

    Parameters
    ----------
    out : Path
        ``--out`` as given.
    command : str
        The command's name (recorded; a set of another command is not replaced silently).
    kind : {"folder", "file"}
        ``--out`` names a folder of files, or the one file written.
    force : bool
        Replace read-only files, files of another command's set and files no run recorded.
    argv : sequence of str
        The command line, recorded in the folder's manifest.
    flag : str
        How the user typed the option, for messages (``--out``).
    """

    def __init__(
        self,
        out: Path,
        *,
        command: str,
        kind: str = "folder",
        force: bool = False,
        argv: Sequence[str] = (),
        flag: str = "--out",
    ) -> None:
        if kind not in ("folder", "file"):
            raise ValueError(f"kind must be 'folder' or 'file'; got {kind!r}")  # internal misuse
        self.given = Path(out)
        self.out = Path(os.path.abspath(out))
        self.command, self.kind, self.force, self.argv, self.flag = (
            command,
            kind,
            force,
            list(argv),
            flag,
        )
        self.staging: Path | None = None
        self.committed = False
        self._written: dict[str, Path] = {}  # relative name -> staged path, in write order
        self._created_parents: list[Path] = []
        self._fd: int | None = None

    # ------------------------------------------------------------------ life cycle
    def open(self) -> None:
        """Check ``--out``, remove stale staging folders of killed runs, create ours."""
        out = self.out
        if self.kind == "folder" and out.exists() and not out.is_dir():
            raise OutputError(f"{self.flag} {self.given}: is a file; give a folder for the outputs")
        if self.kind == "file" and out.is_dir():
            raise OutputError(f"{self.flag} {self.given}: is a folder; give a file name")
        if self.kind == "folder" and not self.force:
            self._check_other_command(_read_manifest(out) if out.is_dir() else None)
        if self.kind == "file" and os.path.lexists(out):  # refused before any work
            self._check_targets([out.name], set())
        parent = out.parent
        missing = []
        p = parent
        while not p.exists():
            missing.append(p)
            p = p.parent
        if not p.is_dir():
            raise OutputError(
                f"{self.flag} {self.given}: {p} is a file, not a folder; choose another {self.flag}"
            )
        # checked before any work: a run that cannot put its files in place would compute,
        # say "wrote ..." and fail on a hidden temporary file
        if self.kind == "folder" and out.is_dir() and not _can_write(out):
            raise OutputError(
                f"{self.flag} {self.given}: this folder is not writable (permission denied); "
                f"choose another {self.flag}"
            )
        if not _can_write(p):
            where = "the folder" if p == parent else "the nearest existing folder"
            raise OutputError(
                f"{self.flag} {self.given}: {where} {p} is not writable (permission denied; "
                f"the outputs are staged beside {self.flag}); choose another {self.flag}"
            )
        try:
            parent.mkdir(parents=True, exist_ok=True)
            self._created_parents = missing  # deepest first
            with _folder_lock(parent):
                self._remove_stale_staging()
                # held: a Ctrl-C as mkdtemp returns, once its folder exists, left it behind
                with signals_held(deliver=True):
                    self.staging = Path(
                        tempfile.mkdtemp(dir=parent, prefix=f".{out.name}{_STAGING}", suffix="")
                    )
                    self._fd = os.open(self.staging, os.O_RDONLY)
                _flock(self._fd, block=False)
        except OSError as exc:
            self._close(False)
            raise OutputError(
                f"{self.flag} {self.given}: cannot write there ({exc.strerror or exc}); "
                f"choose another {self.flag}"
            ) from exc
        atomic._REDIRECTS.append(self)

    def close(self, ok: bool) -> None:
        """Move the set into place (``ok``) or drop it; the staging folder goes either way.

        With ``ok`` the termination signals are held back from the move to the end (the
        staging folder's removal included): a signal that arrives once the set is in place
        does not turn a complete run into an interrupted one (a warning says it came late);
        one that arrives before is delivered when nothing has moved.
        """
        if not ok:
            self._close(ok)
            return
        with signals_held() as arrived:
            self._close(ok)
        if arrived and self.committed:
            names = ", ".join(signal.Signals(s).name for s in dict.fromkeys(arrived))
            _log.warning(
                "%s arrived once the outputs of %s were in place; the run completed",
                names,
                self.given,
            )

    def _close(self, ok: bool) -> None:
        try:
            if ok:
                self._commit()
        finally:
            with contextlib.suppress(ValueError):
                atomic._REDIRECTS.remove(self)
            if self.staging is not None:
                shutil.rmtree(self.staging, ignore_errors=True)
            if self._fd is not None:
                os.close(self._fd)
                self._fd = None
            if not self.committed:
                for d in self._created_parents:
                    with contextlib.suppress(OSError):
                        d.rmdir()  # only when empty

    # ------------------------------------------------------------------ staging
    def stage(self, path: str | Path) -> Path | None:
        """Where a file ``path`` of this run is written now (None: not under ``--out``).

        Raises :class:`~dynid.exceptions.OutputError` when the file it would replace is
        read-only or no run of this command recorded it (without ``--force``).
        """
        if self.staging is None:
            return None
        p = Path(os.path.abspath(path))
        if self.kind == "file":
            if p != self.out:
                return None
            rel = self.out.name
        else:
            try:
                rel = p.relative_to(self.out).as_posix()
            except ValueError:
                return None
            if rel in (".", "") or rel == MANIFEST:
                return None
        self._check_targets([rel], self._owned())  # refused now, before "wrote" is said
        staged = self.staging / rel
        self._written.pop(rel, None)
        self._written[rel] = staged
        return staged

    def manages(self, path: str | Path) -> bool:
        """True for this run's record of its set (``.dynid-run.json`` in ``--out`` or in
        the staging folder), which the run itself writes, puts back or removes."""
        p = Path(os.path.abspath(path))
        if self.kind == "file":
            return p.name == FILES_RECORD and p.parent == self.out.parent
        return p.name == MANIFEST and p.parent in (self.out, self.staging)

    def written(self) -> dict[str, Path]:
        """The files written so far: name relative to ``--out`` -> where it is now."""
        return {k: v for k, v in self._written.items() if v.exists()}

    def location(self, path: str | Path) -> Path:
        """Where ``path`` is now: its staged copy if this run wrote it, else ``path``."""
        p = Path(os.path.abspath(path))
        for rel, staged in self.written().items():
            final = self.out if self.kind == "file" else self.out / rel
            if final == p:
                return staged
        return Path(path)

    # ------------------------------------------------------------------ checks
    def _owned(self) -> set[str]:
        """The files of the folder's set that a run of this command may replace."""
        old = _read_manifest(self.out) if self.kind == "folder" and self.out.is_dir() else None
        return (
            set(old["files"]) if old is not None and old.get("command") == self.command else set()
        )

    def _check_other_command(self, manifest: dict | None) -> None:
        if manifest is None or manifest.get("command") == self.command:
            return
        names = [f for f in manifest["files"] if (self.out / f).exists()]
        if not names:
            return
        shown = ", ".join(names[:4]) + (", ..." if len(names) > 4 else "")
        raise OutputError(
            f"{self.flag} {self.given}: holds the outputs of `dynid {manifest.get('command')}` "
            f"({shown}); choose another {self.flag} or pass --force to write into it"
        )

    def _check_targets(self, names: list[str], owned: set[str]) -> None:
        """Refuse (before moving anything) to replace read-only or foreign files."""
        if self.force:
            return
        base = self.out.parent if self.kind == "file" else self.out
        read_only = [n for n in names if (base / n).exists() and not _writable(base / n)]
        if read_only:
            raise OutputError(
                f"{self.flag} {self.given}: {', '.join(read_only[:4])} "
                f"{'is' if len(read_only) == 1 else 'are'} read-only; pass --force to "
                "replace, or choose another output"
            )
        if self.kind == "file":
            for n in names:
                if os.path.lexists(base / n):
                    self._check_single_file(base / n)
        if self.kind == "folder":
            foreign = [n for n in names if n not in owned and os.path.lexists(base / n)]
            if foreign:
                raise OutputError(
                    f"{self.flag} {self.given}: {', '.join(foreign[:4])} "
                    f"{'exists' if len(foreign) == 1 else 'exist'} and no dynid run recorded "
                    f"{'it' if len(foreign) == 1 else 'them'} there; pass --force to replace, "
                    f"or choose another {self.flag}"
                )

    def _check_single_file(self, path: Path) -> None:
        """Refuse to replace a single file that no run of this command wrote as it is."""
        writer = recorded_writer(path)
        if writer == self.command:
            return
        if writer is not None:
            raise OutputError(
                f"{self.flag} {self.given}: holds the output of `dynid {writer}`; choose "
                f"another {self.flag} or pass --force to replace it"
            )
        raise OutputError(
            f"{self.flag} {self.given}: exists and no dynid run wrote it (or it changed "
            f"since); pass --force to replace, or choose another {self.flag}"
        )

    # ------------------------------------------------------------------ commit
    def _remove_stale_staging(self) -> None:
        """Staging folders of this ``--out`` that no live run holds (killed runs)."""
        prefix = f".{self.out.name}{_STAGING}"
        with contextlib.suppress(OSError):
            for entry in self.out.parent.iterdir():
                if not entry.name.startswith(prefix) or not entry.is_dir():
                    continue
                if entry.is_symlink():
                    continue
                try:
                    fd = os.open(entry, os.O_RDONLY)
                except OSError:
                    continue
                try:
                    if _flock(fd, block=False):
                        shutil.rmtree(entry, ignore_errors=True)
                finally:
                    os.close(fd)

    def _remove_stale_temporaries(self, folder: Path, targets: set[str]) -> None:
        """Writers' temporary files of ``targets`` in ``folder`` (left by killed runs)."""
        with contextlib.suppress(OSError):
            for entry in folder.iterdir():
                if _is_temporary(entry.name, targets) and entry.is_file():
                    with contextlib.suppress(OSError):
                        entry.unlink()

    def _record(self, files: list[str], state: str) -> dict:
        from .. import __version__

        return {
            "command": self.command,
            "state": state,
            "files": files,
            "argv": self.argv,
            "dynid": __version__,
            "time": time.strftime("%Y-%m-%dT%H:%M:%SZ", time.gmtime()),
        }

    def _commit(self) -> None:
        assert self.staging is not None
        names = list(self.written())
        try:
            with _folder_lock(self.out.parent):
                if self.kind == "file":
                    self._commit_file(names)
                else:
                    self._commit_folder(names)
        except OSError as exc:  # a failed move puts back what --out held (_move_into)
            raise OutputError(
                f"{self.flag} {self.given}: the outputs could not be put in place "
                f"({exc.strerror or exc}); choose another {self.flag}"
            ) from exc
        self.committed = True

    def _commit_file(self, names: list[str]) -> None:
        if not names:
            return
        self._check_targets(names, set())
        assert self.staging is not None
        os.replace(self.staging / names[0], self.out)
        self._remove_stale_temporaries(self.out.parent, {self.out.name, FILES_RECORD})
        self._record_file()

    def _record_file(self) -> None:
        """Record the file just moved into place (:mod:`.file_record`)."""
        rec = self._record([self.out.name], "complete")
        record_file(self.out, self.command, **{k: rec[k] for k in ("argv", "dynid", "time")})

    def _commit_folder(self, names: list[str]) -> None:
        assert self.staging is not None
        out = self.out
        old = _read_manifest(out) if out.is_dir() else None
        if old is not None and old.get("command") != self.command and not self.force:
            self._check_other_command(old)
        owned = self._owned()
        self._check_targets(names, owned)
        if not os.path.lexists(out):
            # a new folder: the whole set appears at once
            _write_manifest(self.staging, self._record(names, "complete"))
            os.chmod(self.staging, 0o777 & ~_umask())
            os.rename(self.staging, out)
            self.staging = None
            return
        self._move_into(out, names, owned)

    def _move_into(self, out: Path, names: list[str], owned: set[str]) -> None:
        """Move the staged ``names`` into the existing ``out``; put everything back on error."""
        assert self.staging is not None
        backup = self.staging / ".dynid-previous"
        before = _read_manifest(out)
        _write_manifest(out, self._record(sorted(set(names) | owned), "moving"))
        done: list[tuple[Path, Path | None]] = []  # (target, its previous version or None)
        made: list[Path] = []
        try:
            for rel in names:
                target = out / rel
                for d in reversed(target.parents):
                    if d != out and out in d.parents and not d.exists():
                        d.mkdir()
                        made.append(d)
                prev = None
                if os.path.lexists(target):
                    prev = backup / rel
                    prev.parent.mkdir(parents=True, exist_ok=True)
                    try:
                        os.link(target, prev, follow_symlinks=False)
                    except OSError:
                        shutil.copy2(target, prev, follow_symlinks=False)
                os.replace(self.staging / rel, target)
                done.append((target, prev))
        except BaseException:
            for target, prev in reversed(done):
                with contextlib.suppress(OSError):
                    if prev is None:
                        target.unlink()
                    else:
                        os.replace(prev, target)
            for d in reversed(made):
                with contextlib.suppress(OSError):
                    d.rmdir()
            with contextlib.suppress(OSError):
                if before is None:
                    (out / MANIFEST).unlink()
                else:
                    _write_manifest(out, before)
            raise
        _write_manifest(out, self._record(names, "complete"))
        new = set(names)
        for rel in sorted(owned - new, reverse=True):  # the old set's files not rewritten
            with contextlib.suppress(OSError):
                (out / rel).unlink()
            parent = (out / rel).parent
            while parent != out and out in parent.parents:
                with contextlib.suppress(OSError):
                    parent.rmdir()
                parent = parent.parent
        folders = {out} | {(out / rel).parent for rel in new | owned}
        for folder in folders:
            self._remove_stale_temporaries(
                folder, {Path(rel).name for rel in new | owned} | {MANIFEST}
            )


def _umask() -> int:
    mask = os.umask(0)
    os.umask(mask)
    return mask


@contextlib.contextmanager
def run_output(
    out: str | Path,
    *,
    command: str,
    kind: str = "folder",
    force: bool = False,
    argv: Sequence[str] = (),
) -> Iterator[RunOutput]:
    """Stage the files written under ``out`` inside the block; move them into place when it
    ends normally, drop them when it raises (any exception, interrupts included).

    Raises
    ------
    OutputError
        ``out`` is a file where a folder is wanted (or the reverse), lies under a file,
        holds another command's set, or the run would replace a read-only file or a file
        no run recorded (each without ``force``). Nothing has moved when it is raised.
    """
    run = RunOutput(Path(out), command=command, kind=kind, force=force, argv=argv)
    ok = False
    try:  # (open inside: a Ctrl-C once the staging folder exists removes it too)
        run.open()
        yield run
        ok = True
    finally:
        run.close(ok)
