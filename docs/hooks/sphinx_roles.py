"""A griffe extension for dynid's documentation: the reST markup of the docstrings as Markdown.

The docstrings are numpydoc, written for reading in a terminal and with Sphinx-style roles
(``:func:`fk```, ``:class:`~dynid.model.robot.Robot```) and ``.. math::`` blocks. In the
site a role becomes inline code with its target's short name (the text after ``~`` or the
last dot for ``~``-targets, the text itself otherwise) and a math block becomes a code block
holding the formula as written.
"""

from __future__ import annotations

import re
from typing import Any

import griffe

_ROLE = re.compile(r":(?:py:)?(func|class|meth|mod|attr|data|obj|exc|math):`([^`]+)`")
_MATH = re.compile(r"^(?P<indent>[ \t]*)\.\. math::[ \t]*(?P<first>.*)$")


def _role(match: re.Match[str]) -> str:
    text = match.group(2)
    if match.group(1) != "math":
        named = re.fullmatch(r"(.+?)\s*<(.+)>", text)
        if named:
            text = named.group(1)
        elif text.startswith("~"):
            text = text[1:].rsplit(".", 1)[-1]
    return f"`{text}`"


def _continues(line: str, indent: str, started: bool) -> bool:
    """Whether ``line`` belongs to the math block opened at ``indent``: indented deeper, or
    the blank line between ``.. math::`` and a formula on the next lines."""
    if not line.strip():
        return not started
    return len(line) - len(line.lstrip()) > len(indent)


def _math_blocks(text: str) -> str:
    lines = text.splitlines()
    out: list[str] = []
    i = 0
    while i < len(lines):
        m = _MATH.match(lines[i])
        if not m:
            out.append(lines[i])
            i += 1
            continue
        indent = m.group("indent")
        body = [m.group("first").strip()] if m.group("first").strip() else []
        i += 1
        while i < len(lines) and _continues(lines[i], indent, bool(body)):
            if lines[i].strip():
                body.append(lines[i].strip())
            i += 1
        out += [f"{indent}```text", *(f"{indent}{b}" for b in body), f"{indent}```"]
    return "\n".join(out)


def markdown_from_rest(text: str) -> str:
    """``text`` with its roles as inline code and its math blocks as code blocks."""
    return _ROLE.sub(_role, _math_blocks(text))


class SphinxRoles(griffe.Extension):
    """Rewrite every docstring once it is loaded."""

    def on_object(self, *, obj: griffe.Object, **kwargs: Any) -> None:
        if obj.docstring is not None:
            obj.docstring.value = markdown_from_rest(obj.docstring.value)
