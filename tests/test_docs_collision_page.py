"""The collision-detection tutorial runs as written (:mod:`docs_pages`; a file of its own
so that the test workers share the pages' minutes)."""

from __future__ import annotations

import pytest
from docs_pages import check_page, page_id, pages_of


@pytest.mark.slow
@pytest.mark.parametrize("page", pages_of(__file__), ids=page_id)
def test_page_runs_as_written(page, tmp_path):
    """Each block exits 0, in order, in one folder; the JSON files written name a schema
    and top-level keys that docs/file-formats.md describes (a list of records as
    ``key[]``); every output folder holds its report.html."""
    check_page(page, tmp_path)
