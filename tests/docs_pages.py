"""Running the documentation's pages as the tests of ``tests/test_docs_*.py`` do: every
```bash and ```python block of a page under docs/, in order, in a fresh folder per page,
with this checkout's ``dynid`` and Python; and every JSON file they write is described in
docs/file-formats.md.

Blocks fenced ```console or ```text are shown, not run (``make`` targets, a URDF template
the reader supplies). A page's ``dynid`` commands are processes forked from one that has
imported the command line (:mod:`docs_commands`; the first of each subcommand starts
afresh): they spent most of a second each on imports. The pages are shared among a few
test files (:data:`OWN_FILE`): each file runs on one test worker (``--dist loadscope``),
and one file of all the pages kept its worker busy for over a minute.
"""

from __future__ import annotations

import atexit
import json
import os
import re
import shutil
import subprocess
import sys
import tempfile
from pathlib import Path

import pytest

ROOT = Path(__file__).resolve().parents[1]
DOCS = ROOT / "docs"
_FENCE = re.compile(r"^```(bash|python)[ \t]*\n(.*?)^```[ \t]*$", re.M | re.S)
#: the longest a block may run [s]; the pages keep their data small
BLOCK_TIMEOUT = 600


def runnable_blocks(text: str) -> list[tuple[str, str]]:
    """The ``(language, code)`` of the page's ```bash and ```python blocks, in order."""
    return [(m.group(1), m.group(2)) for m in _FENCE.finditer(text)]


def all_pages() -> list[Path]:
    """Every page under docs/ with a runnable block, sorted."""
    return sorted(p for p in DOCS.rglob("*.md") if runnable_blocks(p.read_text("utf-8")))


def _base_environment() -> dict[str, str]:
    """This checkout's sources first on PYTHONPATH, figures without a display."""
    env = dict(os.environ)
    src = str(ROOT / "src")
    env["PYTHONPATH"] = os.pathsep.join(p for p in (src, env.get("PYTHONPATH")) if p)
    env["MPLBACKEND"] = "Agg"
    return env


class _Server:
    """The process that forks the pages' ``dynid`` commands (:mod:`docs_commands`), one
    per test process, started on first use and stopped when the process exits."""

    proc: subprocess.Popen | None = None
    socket: str | None = None

    @classmethod
    def path(cls) -> str | None:
        """The server's socket, or None (the commands then run fresh)."""
        if cls.proc is None:
            folder = tempfile.mkdtemp(prefix="dynid-docs-")
            cls.socket = os.path.join(folder, "s")
            cls.proc = subprocess.Popen(
                [sys.executable, str(Path(__file__).with_name("docs_commands.py")), "serve",
                 cls.socket],
                stdin=subprocess.PIPE, stdout=subprocess.PIPE, stderr=subprocess.DEVNULL,
                env=_base_environment(), text=True,
            )  # fmt: skip
            atexit.register(cls.stop, folder)
            if cls.proc.stdout is None or cls.proc.stdout.readline() != "ready\n":
                cls.socket = None
        return cls.socket

    @classmethod
    def stop(cls, folder: str) -> None:
        if cls.proc is not None:
            cls.proc.terminate()
            cls.proc.wait()
        shutil.rmtree(folder, ignore_errors=True)


def _environment(tmp: Path) -> dict[str, str]:
    """PATH with ``dynid`` and ``python`` of this interpreter first (``dynid`` through the
    server of :mod:`docs_commands` when it runs), :func:`_base_environment`."""
    bin_dir = tmp / ".bin"
    bin_dir.mkdir()
    server = _Server.path()
    dynid = f'"{sys.executable}" -m dynid'
    if server is not None:
        client = Path(__file__).with_name("docs_commands.py")
        dynid = f'"{sys.executable}" -S "{client}" run "{server}"'
    (bin_dir / "dynid").write_text(f'#!/bin/sh\nexec {dynid} "$@"\n')
    (bin_dir / "python").write_text(f'#!/bin/sh\nexec "{sys.executable}" "$@"\n')
    for f in bin_dir.iterdir():
        f.chmod(0o755)
    env = _base_environment()
    env["PATH"] = f"{bin_dir}{os.pathsep}{env.get('PATH', '')}"
    return env


def _run(language: str, code: str, k: int, cwd: Path, env: dict[str, str]) -> None:
    script = cwd / f".block{k}.{'sh' if language == 'bash' else 'py'}"
    script.write_text(code)
    argv = ["bash", "-e", "-o", "pipefail", str(script)]
    if language == "python":
        argv = [sys.executable, str(script)]
    done = subprocess.run(
        argv, cwd=cwd, env=env, capture_output=True, text=True, timeout=BLOCK_TIMEOUT
    )
    if done.returncode != 0:
        pytest.fail(
            f"block {k + 1} ({language}) exited with {done.returncode}:\n{code}\n"
            f"--- stdout (end)\n{done.stdout[-3000:]}\n--- stderr (end)\n{done.stderr[-3000:]}"
        )


def _written_json(folder: Path) -> list[tuple[Path, dict]]:
    out = []
    for path in sorted(folder.rglob("*.json")):
        doc = json.loads(path.read_text("utf-8"))
        if isinstance(doc, dict) and "schema" in doc:
            out.append((path, doc))
    return out


#: pages run by a test file of their own (the longest; file name -> pages), so that the
#: workers share the pages' minutes; every other page is run by test_docs_tutorials.py
OWN_FILE: dict[str, tuple[str, ...]] = {
    "test_docs_collision_page.py": ("tutorials/collision-detection.md",),
    "test_docs_paper_pages.py": ("tutorials/paper.md", "tutorials/ros2-bag.md"),
}


def pages_of(test_file: str) -> list[Path]:
    """The pages the test file ``test_file`` (its ``__file__``) runs."""
    name = Path(test_file).name
    own = {p for pages in OWN_FILE.values() for p in pages}
    if name in OWN_FILE:
        return [DOCS / p for p in OWN_FILE[name]]
    return [p for p in all_pages() if p.relative_to(DOCS).as_posix() not in own]


def page_id(page: Path) -> str:
    """A page's test id: its path under docs/."""
    return page.relative_to(DOCS).as_posix()


def check_page(page: Path, tmp: Path) -> None:
    """Run ``page``'s blocks in ``tmp`` and check the JSON files and reports they write
    (the docstring of ``test_page_runs_as_written``)."""
    env = _environment(tmp)
    for k, (language, code) in enumerate(runnable_blocks(page.read_text("utf-8"))):
        _run(language, code, k, tmp, env)
    formats = (DOCS / "file-formats.md").read_text("utf-8")
    for path, doc in _written_json(tmp):
        where = path.relative_to(tmp)
        assert f"`{doc['schema']}`" in formats, f"{where}: schema {doc['schema']} undocumented"
        missing = [k for k in doc if not re.search(rf"`{re.escape(k)}(\[\])?`", formats)]
        assert not missing, f"{where}: keys {missing} not in docs/file-formats.md"
    # every output folder a page writes holds its run's report, which the page describes
    for manifest in tmp.rglob(".dynid-run.json"):
        where = manifest.parent.relative_to(tmp)
        assert "report.html" in json.loads(manifest.read_text("utf-8"))["files"], where
        assert (manifest.parent / "report.html").is_file(), where
        assert "### report.html" in formats
