"""The HTML pieces every part of a report is built from: escaped text, numbers, table cells,
tables with named columns, embedded figures, bars, a verdict box.

Every text that comes from a user or a file (names, values, messages) goes through
:func:`esc`; everything here is pure string building.
"""

from __future__ import annotations

import base64
import html
import math
import os
import re
import urllib.parse
from collections.abc import Sequence
from pathlib import Path
from typing import Any, TypeGuard

__all__ = [
    "MAX_VECTOR",
    "bar",
    "capitalised",
    "cell",
    "esc",
    "figure",
    "file_unit",
    "href",
    "is_matrix",
    "is_number",
    "is_records",
    "is_scalar",
    "is_string_list",
    "is_vector",
    "number",
    "percent",
    "section",
    "shape",
    "size",
    "table",
    "verdict",
]

#: Longest numeric vector shown inline.
MAX_VECTOR = 12


#: A first word that is an ordinary word (letters, hyphens, apostrophes), not a file name
#: or an identifier (``free.csv``, ``shoulder_lift_joint``, ``q2``).
_WORD = re.compile(r"[A-Za-z][A-Za-z'-]*(?=[\s,;:!?)]|$)")


def capitalised(text: str) -> str:
    """``text`` with its first letter upper case when it opens with an ordinary word;
    unchanged when it opens with a file name or an identifier (``"free.csv: ..."``,
    ``"shoulder_lift_joint ..."``), whose case is theirs. The rest is never changed."""
    if not _WORD.match(text):
        return text
    return text[0].upper() + text[1:]


def esc(text: object) -> str:
    """``text`` escaped for HTML text and attribute values; a name given under an ASCII
    locale (undecodable bytes held as surrogates) shows as the characters its bytes spell."""
    shown = str(text).encode("utf-8", "surrogateescape").decode("utf-8", "replace")
    return html.escape(shown, quote=True)


def file_unit(doc: Any, key: str, default: str = "N m") -> str:
    """The unit a JSON result's ``units`` give ``key`` (``"N m (rail: N)"`` on an arm with
    a prismatic joint), ``default`` for a file without it (an earlier one)."""
    units = doc.get("units") if isinstance(doc, dict) else None
    unit = units.get(key) if isinstance(units, dict) else None
    return unit if isinstance(unit, str) else default


def href(path: str) -> str:
    """A relative address for ``path`` (POSIX separators), percent-encoded from its bytes as
    the file system holds them, and escaped."""
    raw = os.fsencode(path.replace(os.sep, "/"))
    return html.escape(urllib.parse.quote(raw, safe="/"), quote=True)


def size(n: int) -> str:
    """A file size for people: ``812 B``, ``54.3 kB``, ``1.4 MB``."""
    if n < 1000:
        return f"{n} B"
    value = float(n)
    for unit in ("kB", "MB"):
        value /= 1000
        if value < 1000:
            return f"{value:.1f} {unit}"
    return f"{value / 1000:.1f} GB"


# ---------------------------------------------------------------------- values
def is_number(v: object) -> TypeGuard[float]:
    return isinstance(v, (int, float)) and not isinstance(v, bool)


def is_scalar(v: object) -> bool:
    return v is None or isinstance(v, (str, int, float, bool))


def is_vector(v: object) -> bool:
    return isinstance(v, list) and len(v) > 0 and all(is_number(x) for x in v)


def is_matrix(v: object) -> bool:
    return (
        isinstance(v, list)
        and len(v) > 0
        and all(is_vector(r) for r in v)
        and len({len(r) for r in v}) == 1
    )


def is_records(v: object) -> bool:
    return isinstance(v, list) and len(v) > 0 and all(isinstance(r, dict) for r in v)


def is_string_list(v: object) -> bool:
    return isinstance(v, list) and bool(v) and all(isinstance(x, str) for x in v)


def number(v: float | int, digits: int = 4) -> str:
    """A number as text: integers as they are, others to ``digits`` significant digits
    (exponent form below 1e-3 and from 1e5)."""
    if isinstance(v, int):
        return str(v)
    if not math.isfinite(v):
        return str(v)
    if v != 0 and (abs(v) >= 1e5 or abs(v) < 1e-3):
        return f"{v:.{max(digits - 1, 1)}e}"
    return f"{v:.{digits}g}"


def percent(v: Any) -> str:
    """A percentage for a sentence (``0.402 %``), or a dash."""
    return f"{number(float(v), 3)} %" if is_number(v) else "&ndash;"


def shape(v: Any) -> str:
    dims = []
    while isinstance(v, list):
        dims.append(len(v))
        v = v[0] if v else None
    return " x ".join(map(str, dims))


def cell(v: Any) -> str:
    """One value as the HTML of a table cell's content."""
    if v is None:
        return '<span class="dim">&ndash;</span>'
    if isinstance(v, bool):
        return '<span class="yes">yes</span>' if v else '<span class="no">no</span>'
    if is_number(v):
        return f'<span class="n">{number(v)}</span>'
    if isinstance(v, str):
        return esc(v)
    if is_vector(v) and len(v) <= MAX_VECTOR:
        return "[" + ", ".join(number(x) for x in v) + "]"
    if isinstance(v, list) and all(isinstance(x, str) for x in v) and len(v) <= MAX_VECTOR:
        return esc(", ".join(v)) if v else '<span class="dim">none</span>'
    if isinstance(v, list):
        return f'<span class="dim">{esc(shape(v))} values (in the file)</span>'
    if isinstance(v, dict):
        inner = [f"{esc(k)}: {cell(x)}" for k, x in v.items() if is_scalar(x)]
        if len(inner) == len(v) and len(inner) <= 6:
            return "; ".join(inner)
        return f'<span class="dim">{len(v)} entries (in the file)</span>'
    return esc(v)  # pragma: no cover - JSON holds nothing else


def table(
    headers: Sequence[str],
    rows: Sequence[Sequence[str]],
    *,
    cls: str = "",
    marked: Sequence[bool] = (),
) -> str:
    """An HTML table; ``headers`` are text, ``rows`` hold cell HTML; rows ``marked`` are
    highlighted (a chosen candidate)."""
    head = "".join(f"<th>{esc(h)}</th>" for h in headers)
    body = "".join(
        ('<tr class="marked">' if k < len(marked) and marked[k] else "<tr>")
        + "".join(f"<td>{c}</td>" for c in r)
        + "</tr>"
        for k, r in enumerate(rows)
    )
    attr = f' class="{cls}"' if cls else ""
    return f"<table{attr}><thead><tr>{head}</tr></thead><tbody>{body}</tbody></table>"


def figure(rel: str, path: Path, caption: str = "") -> str:
    """A PNG embedded as a ``data:`` URI, linked to its file, with a caption."""
    data = base64.b64encode(path.read_bytes()).decode("ascii")
    text = f'{esc(caption)} <span class="dim">({esc(rel)})</span>' if caption else esc(rel)
    return (
        f'<figure><a href="{href(rel)}"><img alt="{esc(rel)}" '
        f'src="data:image/png;base64,{data}"></a>'
        f"<figcaption>{text}</figcaption></figure>"
    )


def bar(value: float, top: float, *, log: bool = False, bad: float | None = None) -> str:
    """A horizontal bar (cell HTML) of ``value`` on a scale up to ``top``; logarithmic from
    0.01 with ``log``; red from ``bad`` on."""
    if not (is_number(value) and math.isfinite(value)) or top <= 0:
        return ""
    if log:
        lo = 1e-2
        frac = (math.log10(max(value, lo)) - math.log10(lo)) / max(
            math.log10(max(top, lo * 10)) - math.log10(lo), 1e-9
        )
    else:
        frac = value / top
    width = max(1.0, min(100.0, 100.0 * frac))
    cls = "bar bad" if bad is not None and value > bad else "bar"
    return f'<span class="{cls}" style="width:{width:.1f}%"></span>'


def section(anchor: str, title: str, *parts: str) -> str:
    """A titled part of the page (``<h2 id=anchor>``)."""
    return f'<h2 id="{esc(anchor)}">{esc(title)}</h2>' + "".join(parts)


def verdict(level: str, headline: str, facts: Sequence[str], label: str | None = None) -> str:
    """The answer box at the top of a page: ``level`` good, fair, poor or unusable (a
    judgement, :mod:`dynid.identification.verdict`), or info (a finding, such as events
    detected); ``label`` the level in words (default: the level's own: "good", "usable,
    with reservations", "poor: improve the model", "unusable: check the data");
    ``headline`` and ``facts`` are HTML."""
    items = "".join(f"<li>{f}</li>" for f in facts)
    labels = {
        "good": "good",
        "fair": "usable, with reservations",
        "poor": "poor: improve the model",
        "unusable": "unusable: check the data",
        "info": "found",
    }
    return (
        f'<section class="verdict {esc(level)}" id="verdict"><p class="headline">'
        f'<span class="level">{esc(label or labels.get(level, level))}</span> {headline}</p>'
        f"<ul>{items}</ul></section>"
    )
