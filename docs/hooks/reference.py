"""MkDocs hooks of dynid's documentation: the CLI reference from the parsers, and a check
that the API reference documents every public module.

``cli.md`` holds the marker ``<!-- dynid-cli-reference -->``; it is replaced at build time
by the ``--help`` text of ``dynid`` and of every subcommand, as
:func:`dynid.cli.__main__.build_parser` makes them, so the page never drifts from the code.
A public module of ``dynid`` (no leading underscore in its dotted name, outside
``dynid.cli``) that no ``::: dynid....`` directive under ``api/`` names is reported as a
warning, which ``mkdocs build --strict`` turns into an error.
"""

from __future__ import annotations

import argparse
import logging
import os
import re
from pathlib import Path
from typing import Any

_log = logging.getLogger("mkdocs.hooks.reference")

MARKER = "<!-- dynid-cli-reference -->"
#: width of the help texts [characters], fixed so the page does not depend on the terminal
WIDTH = 100
_DIRECTIVE = re.compile(r"^:::\s*(dynid[\w.]*)\s*$", re.M)


def _help(parser: argparse.ArgumentParser) -> str:
    old = os.environ.get("COLUMNS")
    os.environ["COLUMNS"] = str(WIDTH)
    try:
        return parser.format_help().rstrip()
    finally:
        if old is None:
            del os.environ["COLUMNS"]
        else:
            os.environ["COLUMNS"] = old


def cli_reference() -> str:
    """The Markdown of the CLI reference: ``dynid --help``, then one section per command."""
    from dynid.cli.__main__ import build_parser

    parser = build_parser()
    sub = next(a for a in parser._actions if isinstance(a, argparse._SubParsersAction))
    blocks = ["## dynid", "", "```text", _help(parser), "```"]
    for name, p in sub.choices.items():
        blocks += ["", f"## dynid {name}", "", "```text", _help(p), "```"]
    return "\n".join(blocks)


def _public_modules(src: Path) -> set[str]:
    names = set()
    for path in src.rglob("*.py"):
        parts = path.relative_to(src.parent).with_suffix("").parts
        if parts[-1] == "__init__":
            continue
        if any(p.startswith("_") for p in parts) or parts[1] == "cli":
            continue
        names.add(".".join(parts))
    return names


def on_page_markdown(markdown: str, page: Any, config: Any, files: Any) -> str:
    """Fill in the CLI reference on the page that holds the marker."""
    if MARKER in markdown:
        return markdown.replace(MARKER, cli_reference())
    return markdown


def on_files(files: Any, config: Any) -> Any:
    """Warn about every public module that the API reference leaves out."""
    docs = Path(config["docs_dir"])
    src = docs.parent / "src" / "dynid"
    named = set()
    for page in (docs / "api").glob("*.md"):
        named.update(_DIRECTIVE.findall(page.read_text(encoding="utf-8")))
    for name in sorted(_public_modules(src) - named):
        _log.warning("API reference: module %s is on no page under docs/api/", name)
    return files
