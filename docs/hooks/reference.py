"""MkDocs hooks of dynid's documentation: the CLI reference from the parsers, and a check
that the API reference documents every public module.

``cli.md`` holds the marker ``<!-- dynid-cli-reference -->``; it is replaced at build time
by the ``--help`` text of ``dynid`` and of every subcommand, as
:func:`dynid.cli.__main__.build_parser` makes them, so the page never drifts from the code.
A page under ``api/`` that holds ``<!-- dynid-api-package dynid.PKG -->`` documents the
modules of that package: those its ``::: dynid.PKG.module`` directives name, in the page's
order, then every other public module of the package (no leading underscore, not named on
another page), appended in alphabetical order, so a new module is documented without an
edit. A public module (outside ``dynid.cli``, which the CLI reference covers) of a package
that no page claims is reported as a warning, which ``mkdocs build --strict`` turns into an
error.
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
_PACKAGE = re.compile(r"<!--\s*dynid-api-package\s+(dynid[\w.]*)\s*-->")
#: public modules not named by a directive, by package; filled by :func:`on_files`
_UNNAMED: dict[str, list[str]] = {}


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
    """Fill in the CLI reference, and the modules an API page's package adds."""
    if MARKER in markdown:
        markdown = markdown.replace(MARKER, cli_reference())
    for package in _PACKAGE.findall(markdown):
        markdown += "".join(f"\n\n::: {name}\n" for name in _UNNAMED.get(package, ()))
    return markdown


def on_files(files: Any, config: Any) -> Any:
    """Find the public modules no directive names; warn about those no page claims."""
    docs = Path(config["docs_dir"])
    src = docs.parent / "src" / "dynid"
    named: set[str] = set()
    packages: set[str] = set()
    for page in (docs / "api").glob("*.md"):
        text = page.read_text(encoding="utf-8")
        named.update(_DIRECTIVE.findall(text))
        packages.update(_PACKAGE.findall(text))
    _UNNAMED.clear()
    for name in sorted(_public_modules(src) - named):
        package = name.rsplit(".", 1)[0]
        if package in packages:
            _UNNAMED.setdefault(package, []).append(name)
        else:
            _log.warning("API reference: module %s is on no page under docs/api/", name)
    return files
