"""The documentation's commands run as written (:mod:`docs_pages`): the pages that no
file of their own runs (``docs_pages.OWN_FILE``), the list of pages, and the URDF
templates the pages name.
"""

from __future__ import annotations

import re
from pathlib import Path

import pytest
from docs_pages import DOCS, OWN_FILE, ROOT, all_pages, check_page, page_id, pages_of


def test_the_pages_have_commands():
    """The getting-started page, every tutorial and the validation page hold runnable
    blocks (a fence typo would silently drop a page from the tests below); every page given
    a file of its own has runnable blocks and that file exists (a renamed page or file
    would drop the page)."""
    names = {p.relative_to(DOCS).as_posix() for p in all_pages()}
    tutorials = {p.relative_to(DOCS).as_posix() for p in (DOCS / "tutorials").glob("*.md")}
    assert tutorials and tutorials <= names
    assert {"getting-started.md", "validation.md"} <= names
    for test_file, pages in OWN_FILE.items():
        assert (Path(__file__).parent / test_file).is_file(), test_file
        assert set(pages) <= names, test_file


@pytest.mark.slow
@pytest.mark.parametrize("page", pages_of(__file__), ids=page_id)
def test_page_runs_as_written(page, tmp_path):
    """Each block exits 0, in order, in one folder; the JSON files written name a schema
    and top-level keys that docs/file-formats.md describes (a list of records as
    ``key[]``); every output folder holds its report.html."""
    check_page(page, tmp_path)


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
