"""The documentation's commands run as written: every ```bash and ```python block of a page
under docs/, in order, in a fresh folder per page, with this checkout's ``dynid`` and
Python; and every JSON file they write is described in docs/file-formats.md.

Blocks fenced ```console or ```text are shown, not run (``make`` targets, a URDF template
the reader supplies).
"""

from __future__ import annotations

import json
import os
import re
import subprocess
import sys
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


def _pages() -> list[Path]:
    return sorted(p for p in DOCS.rglob("*.md") if runnable_blocks(p.read_text("utf-8")))


def _environment(tmp: Path) -> dict[str, str]:
    """PATH with ``dynid`` and ``python`` of this interpreter first, this checkout's sources
    first on PYTHONPATH, figures without a display."""
    bin_dir = tmp / ".bin"
    bin_dir.mkdir()
    (bin_dir / "dynid").write_text(f'#!/bin/sh\nexec "{sys.executable}" -m dynid "$@"\n')
    (bin_dir / "python").write_text(f'#!/bin/sh\nexec "{sys.executable}" "$@"\n')
    for f in bin_dir.iterdir():
        f.chmod(0o755)
    env = dict(os.environ)
    env["PATH"] = f"{bin_dir}{os.pathsep}{env.get('PATH', '')}"
    src = str(ROOT / "src")
    env["PYTHONPATH"] = os.pathsep.join(p for p in (src, env.get("PYTHONPATH")) if p)
    env["MPLBACKEND"] = "Agg"
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


def test_the_pages_have_commands():
    """The getting-started page, every tutorial and the validation page hold runnable
    blocks (a fence typo would silently drop a page from the test below)."""
    names = {p.relative_to(DOCS).as_posix() for p in _pages()}
    tutorials = {p.relative_to(DOCS).as_posix() for p in (DOCS / "tutorials").glob("*.md")}
    assert tutorials and tutorials <= names
    assert {"getting-started.md", "validation.md"} <= names


@pytest.mark.slow
@pytest.mark.parametrize("page", _pages(), ids=lambda p: p.relative_to(DOCS).as_posix())
def test_page_runs_as_written(page, tmp_path):
    """Each block exits 0, in order, in one folder; the JSON files written name a schema
    and top-level keys that docs/file-formats.md describes (a list of records as
    ``key[]``); every output folder holds its report.html."""
    env = _environment(tmp_path)
    for k, (language, code) in enumerate(runnable_blocks(page.read_text("utf-8"))):
        _run(language, code, k, tmp_path, env)
    formats = (DOCS / "file-formats.md").read_text("utf-8")
    for path, doc in _written_json(tmp_path):
        where = path.relative_to(tmp_path)
        assert f"`{doc['schema']}`" in formats, f"{where}: schema {doc['schema']} undocumented"
        missing = [k for k in doc if not re.search(rf"`{re.escape(k)}(\[\])?`", formats)]
        assert not missing, f"{where}: keys {missing} not in docs/file-formats.md"
    # every output folder a page writes holds its run's report, which the page describes
    for manifest in tmp_path.rglob(".dynid-run.json"):
        where = manifest.parent.relative_to(tmp_path)
        assert "report.html" in json.loads(manifest.read_text("utf-8"))["files"], where
        assert (manifest.parent / "report.html").is_file(), where
        assert "### report.html" in formats


def test_every_urdf_template_the_docs_name_is_shipped_written_or_a_placeholder():
    """A file the README, a page or export's --help gives to --urdf-template is shipped,
    written by a command of the same text (--out FILE), or an upper-case placeholder for
    the reader's own URDF (they named panda_original.urdf and fr3_original.urdf, which no
    one has: neither shipped nor written by any command)."""
    from dynid.cli import export

    texts = {p.name: p.read_text("utf-8") for p in [ROOT / "README.md", *DOCS.rglob("*.md")]}
    texts["dynid export --help"] = export.__doc__ or ""
    shipped = {p.name for p in ROOT.rglob("*.urdf") if ".git" not in p.parts}
    named = 0
    for where, text in texts.items():
        for name in re.findall(r"--urdf-template[ =]+([^\s`]+)", text):
            named += 1
            placeholder = Path(name).stem.isupper()
            written = re.search(rf"--out[ =]+{re.escape(name)}(?![\w.])", text) is not None
            assert placeholder or written or Path(name).name in shipped, f"{where}: {name}"
    assert named >= 3  # the README, the paper's tutorial, export's --help
