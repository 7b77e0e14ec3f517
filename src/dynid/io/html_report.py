"""The HTML report of one run: ``report.html`` in the output folder, a single file.

:func:`save_html_report` is called once at the end of every run that writes a folder
(``identify``, ``validate``, ``friction``, ``retrieve``, ``payload``, ``excite``,
``demo``), when the folder's files are complete and before they move into place. The
report is built from what the run recorded (:class:`RunSummary`: command line, options,
printed summary, warnings and notes, tables a command adds) and from the files it wrote:

* the JSON results become tables (their scalars, their records such as ``coefficients[]``
  or ``joints[]``, per-joint vectors side by side, small matrices; larger arrays are named
  with their shape and left in the file);
* the PNG figures are embedded as base64 ``data:`` URIs;
* every file is linked by a relative address, so the links work where the folder is.

The page needs no network access: inline CSS, no fonts or scripts from elsewhere. A short
inline script records, once the page has loaded, each figure's decoded width in its
``data-natural-width`` attribute and the number of decoded figures in the body's
``data-figures-decoded`` (what a headless browser test reads back). Every text that comes
from a user or a file (names, values, messages) is escaped.

Pure string building: no template engine, no plotting library.
"""

from __future__ import annotations

import base64
import hashlib
import html
import json
import math
import os
import time
import urllib.parse
from collections.abc import Mapping, Sequence
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

from .atomic import write_text

__all__ = [
    "REPORT_NAME",
    "ReportTable",
    "RunSummary",
    "input_files",
    "render_html_report",
    "save_html_report",
]

#: Name of the report in the output folder.
REPORT_NAME = "report.html"
#: Records (rows) of one JSON list shown in a table; the rest stay in the file.
MAX_ROWS = 80
#: Largest matrix shown as a table (rows, columns); larger arrays are named by shape.
MAX_MATRIX = (12, 12)
#: Longest numeric vector shown inline.
MAX_VECTOR = 12
#: Nesting of JSON objects shown (deeper ones are named and left in the file).
MAX_DEPTH = 3
#: Tables of more rows than this start collapsed.
LONG_TABLE = 50
#: Printed output longer than this many lines starts collapsed.
LONG_PRINTOUT = 60

#: Results shown first, found by key at the top of a JSON file or one object down:
#: (key, label).
KEY_NUMBERS = (
    ("feasible", "feasible"),
    ("relative_error_percent", "relative error [%]"),
    ("rank", "rank"),
    ("condition_number", "condition number"),
    ("residual_rms", "residual RMS"),
    ("sigma", "noise estimate"),
    ("relative_residual", "relative residual"),
    ("residual_ratio", "residual ratio"),
    ("mass", "mass [kg]"),
    ("constraint_active", "constraint active"),
    ("status", "status"),
    ("n_samples", "samples"),
)


#: Columns of JSON records (``joints[]``) whose largest value is a key number: (key, label).
KEY_COLUMNS = (("rms_before", "RMS before"), ("rms_after", "RMS after"))


@dataclass(frozen=True)
class ReportTable:
    """A table a command adds to its report: a title, column headers and rows of text."""

    title: str
    headers: tuple[str, ...]
    rows: tuple[tuple[str, ...], ...]


@dataclass(frozen=True)
class RunSummary:
    """What a run was given and what it said, for its report.

    Parameters
    ----------
    command : str
        The command (``identify``).
    argv : tuple of str
        The command line as typed (``("dynid", "identify", "--data", ...)``).
    options : tuple of (str, str)
        Every option of the command with the value used (defaults included).
    printed : str
        What the run printed on stdout (its summary).
    warnings, notes : tuple of str
        The warning and note lines, without their prefix.
    tables : tuple of ReportTable
        Tables the command added.
    exit_code : int
        The run's exit status (1: a documented negative result, such as no feasible set).
    elapsed_s : float or None
        Wall time of the run [s].
    """

    command: str
    argv: tuple[str, ...] = ()
    options: tuple[tuple[str, str], ...] = ()
    printed: str = ""
    warnings: tuple[str, ...] = ()
    notes: tuple[str, ...] = ()
    tables: tuple[ReportTable, ...] = field(default_factory=tuple)
    exit_code: int = 0
    elapsed_s: float | None = None


def _e(text: object) -> str:
    """``text`` escaped for HTML text and attribute values; a name given under an ASCII
    locale (undecodable bytes held as surrogates) shows as the characters its bytes spell."""
    return html.escape(_shown(str(text)), quote=True)


def _shown(text: str) -> str:
    """``text`` with surrogate escapes turned back into the characters of their UTF-8 bytes
    (U+FFFD where the bytes are not UTF-8), so that the page can be written as UTF-8."""
    return text.encode("utf-8", "surrogateescape").decode("utf-8", "replace")


def _href(path: str) -> str:
    """A relative address for ``path`` (POSIX separators), percent-encoded from its bytes as
    the file system holds them, and escaped."""
    raw = os.fsencode(path.replace(os.sep, "/"))
    return html.escape(urllib.parse.quote(raw, safe="/"), quote=True)


def _size(n: int) -> str:
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
def _is_number(v: object) -> bool:
    return isinstance(v, (int, float)) and not isinstance(v, bool)


def _is_scalar(v: object) -> bool:
    return v is None or isinstance(v, (str, int, float, bool))


def _is_vector(v: object) -> bool:
    return isinstance(v, list) and len(v) > 0 and all(_is_number(x) for x in v)


def _is_matrix(v: object) -> bool:
    return (
        isinstance(v, list)
        and len(v) > 0
        and all(_is_vector(r) for r in v)
        and len({len(r) for r in v}) == 1
    )


def _is_records(v: object) -> bool:
    return isinstance(v, list) and len(v) > 0 and all(isinstance(r, dict) for r in v)


def _number(v: float | int) -> str:
    if isinstance(v, int):
        return str(v)
    if not math.isfinite(v):
        return str(v)
    if v != 0 and (abs(v) >= 1e5 or abs(v) < 1e-3):
        return f"{v:.3e}"
    return f"{v:.4g}"


def _shape(v: Any) -> str:
    dims = []
    while isinstance(v, list):
        dims.append(len(v))
        v = v[0] if v else None
    return " x ".join(map(str, dims))


def _cell(v: Any) -> str:
    """One value as the HTML of a table cell's content."""
    if v is None:
        return '<span class="dim">&ndash;</span>'
    if isinstance(v, bool):
        return '<span class="yes">yes</span>' if v else '<span class="no">no</span>'
    if _is_number(v):
        return _number(v)
    if isinstance(v, str):
        return _e(v)
    if _is_vector(v) and len(v) <= MAX_VECTOR:
        return "[" + ", ".join(_number(x) for x in v) + "]"
    if isinstance(v, list) and all(isinstance(x, str) for x in v) and len(v) <= MAX_VECTOR:
        return _e(", ".join(v)) if v else '<span class="dim">none</span>'
    if isinstance(v, list):
        return f'<span class="dim">{_e(_shape(v))} values (in the file)</span>'
    if isinstance(v, dict):
        inner = [f"{_e(k)}: {_cell(x)}" for k, x in v.items() if _is_scalar(x)]
        if len(inner) == len(v) and len(inner) <= 6:
            return "; ".join(inner)
        return f'<span class="dim">{len(v)} entries (in the file)</span>'
    return _e(v)  # pragma: no cover - JSON holds nothing else


def _table(headers: Sequence[str], rows: Sequence[Sequence[str]], *, cls: str = "") -> str:
    """An HTML table; ``headers`` are text, ``rows`` hold cell HTML."""
    head = "".join(f"<th>{_e(h)}</th>" for h in headers)
    body = "".join("<tr>" + "".join(f"<td>{c}</td>" for c in r) + "</tr>" for r in rows)
    attr = f' class="{cls}"' if cls else ""
    return f"<table{attr}><thead><tr>{head}</tr></thead><tbody>{body}</tbody></table>"


# ---------------------------------------------------------------------- JSON as tables
def _with_unit(key: str, units: Mapping[str, str]) -> str:
    """``key [unit]`` when ``units`` gives a short unit for ``key``."""
    unit = units.get(key)
    if isinstance(unit, str) and unit and len(unit) <= 14:
        return f"{key} [{unit}]"
    return key


def _names(n: int, labels: Sequence[list[str]]) -> list[str]:
    """The first of ``labels`` (joint names, link names) with ``n`` entries, else 1..n."""
    return next((names for names in labels if len(names) == n), [str(i + 1) for i in range(n)])


def _records_table(
    key: str, records: list[dict], units: Mapping[str, str], labels: Sequence[list[str]] = ()
) -> str:
    """Records (``joints[]``) as a table, one row each; rows without a name of their own
    are named by ``labels`` (the joint names, when as many) or numbered. A long table
    starts collapsed."""
    columns: list[str] = []
    for r in records:
        columns += [k for k in r if k not in columns]
    shown = records[:MAX_ROWS]
    rows = [[_cell(r.get(c)) for c in columns] for r in shown]
    headers = [_with_unit(c, units) for c in columns]
    if not {"name", "link", "joint", "method"} & set(columns):
        names = _names(len(records), labels)
        headers.insert(0, "")
        for i, row in enumerate(rows):
            row.insert(0, _e(names[i]))
    more = len(records) - len(shown)
    tail = f'<p class="dim">{more} more rows in the file.</p>' if more > 0 else ""
    table = _table(headers, rows) + tail
    if len(records) > LONG_TABLE:
        return f"<details><summary>{_e(key)} ({len(records)} rows)</summary>{table}</details>"
    return f"<h4>{_e(key)}</h4>" + table


def _vectors_table(
    vectors: dict[str, list], labels: Sequence[list[str]], units: Mapping[str, str]
) -> str:
    """Same-length numeric vectors side by side, one row per element (joint, link)."""
    n = len(next(iter(vectors.values())))
    names = _names(n, labels)
    rows = [[_e(names[i])] + [_number(v[i]) for v in vectors.values()] for i in range(n)]
    return _table(["", *(_with_unit(k, units) for k in vectors)], rows)


def _matrix_table(key: str, m: list[list]) -> str:
    rows = [[_e(i + 1)] + [_number(x) for x in r] for i, r in enumerate(m)]
    headers = ["", *(str(j + 1) for j in range(len(m[0])))]
    return f"<h4>{_e(key)}</h4>" + _table(headers, rows, cls="matrix")


def _object_html(
    doc: Mapping[str, Any],
    depth: int,
    labels: Sequence[list[str]] = (),
    units: Mapping[str, str] | None = None,
) -> str:
    """A JSON object: its scalars as a key/value table, then its vectors, records,
    matrices and nested objects (nested objects in collapsible blocks). ``labels`` name
    the rows of per-joint vectors (``joint_names``); ``units`` (the file's ``units``)
    give units to keys."""
    own = [doc[k] for k in ("joint_names", "link_names") if _is_string_list(doc.get(k))]
    labels = [*own, *labels]
    own_units = doc.get("units") if isinstance(doc.get("units"), dict) else None
    units = own_units or units or {}
    scalars, vectors, records, matrices, objects, other = [], {}, [], [], [], []
    for key, v in doc.items():
        if key == "schema":
            continue
        if _is_scalar(v) or (isinstance(v, list) and not v):
            scalars.append((key, v))
        elif _is_vector(v):
            vectors[key] = v
        elif _is_records(v):
            records.append((key, v))
        elif _is_matrix(v) and len(v) <= MAX_MATRIX[0] and len(v[0]) <= MAX_MATRIX[1]:
            matrices.append((key, v))
        elif isinstance(v, dict):
            objects.append((key, v))
        else:
            other.append((key, v))
    parts = []
    by_length: dict[int, dict[str, list]] = {}
    for key, v in vectors.items():
        by_length.setdefault(len(v), {})[key] = v
    for group in by_length.values():
        n = len(next(iter(group.values())))
        if not _has_names(n, labels) and (n <= 3 or (len(group) == 1 and n <= MAX_VECTOR)):
            scalars += list(group.items())  # xyz, a few values: inline
        elif len(next(iter(group.values()))) <= MAX_ROWS:
            parts.append(_vectors_table(group, labels, units))
        else:
            other += list(group.items())
    rows = [[_e(k), _cell(v), _e(units.get(k, ""))] for k, v in scalars + other]
    if rows:
        with_units = any(r[2] for r in rows)
        headers = ["key", "value", "unit"] if with_units else ["key", "value"]
        parts.insert(0, _table(headers, [r if with_units else r[:2] for r in rows], cls="kv"))
    parts += [_records_table(k, v, units, labels) for k, v in records]
    parts += [_matrix_table(k, v) for k, v in matrices]
    for key, v in objects:
        if depth >= MAX_DEPTH:
            parts.append(f'<p class="dim">{_e(key)}: {len(v)} entries (in the file)</p>')
            continue
        inner = _object_html(v, depth + 1, labels, units) if v else '<p class="dim">empty</p>'
        parts.append(f"<details><summary>{_e(key)}</summary>{inner}</details>")
    return "".join(parts)


def _units(doc: Mapping[str, Any]) -> Mapping[str, str]:
    """The ``units`` of a JSON result (key -> unit), or none."""
    units = doc.get("units")
    return units if isinstance(units, dict) else {}


def _has_names(n: int, labels: Sequence[list[str]]) -> bool:
    return any(len(names) == n for names in labels)


def _is_string_list(v: object) -> bool:
    return isinstance(v, list) and bool(v) and all(isinstance(x, str) for x in v)


def _json_section(rel: str, doc: Any) -> str:
    schema = doc.get("schema") if isinstance(doc, dict) else None
    tag = f' <span class="schema">{_e(schema)}</span>' if isinstance(schema, str) else ""
    head = f'<h3><a href="{_href(rel)}">{_e(rel)}</a>{tag}</h3>'
    if isinstance(doc, dict):
        body = _object_html(doc, 1)
    elif _is_records(doc):
        body = _records_table(rel, doc, {})
    elif doc is None:
        body = '<p class="dim">not readable as JSON; see the file</p>'
    else:
        body = f"<p>{_cell(doc)}</p>"
    return f'<section class="result">{head}{body}</section>'


def _key_numbers(docs: Sequence[tuple[str, Any]]) -> list[tuple[str, str, Any]]:
    """(file, label, value) of the :data:`KEY_NUMBERS` found in the JSON results, at the
    top of each file or one result object down (``with_friction``); a number another
    file already showed is not repeated."""
    found, seen = [], set()
    for rel, doc in docs:
        if not isinstance(doc, dict):
            continue
        places = [("", doc)] + [
            (f"{k.replace('_', ' ')}: ", v)
            for k, v in doc.items()
            if isinstance(v, dict)
            and k not in _NOT_RESULTS
            and sum(key in v for key, _ in KEY_NUMBERS) >= 2
        ]
        for prefix, obj in places:
            for key, label in KEY_NUMBERS:
                v = obj.get(key)
                if not _is_scalar(v) or v is None or (key, _cell(v)) in seen:
                    continue
                seen.add((key, _cell(v)))
                found.append((rel, prefix + label, v))
        for key, records in doc.items():
            if not _is_records(records):
                continue
            for column, label in KEY_COLUMNS:
                values = [r.get(column) for r in records]
                if values and all(_is_number(x) for x in values):
                    unit = _with_unit(column, _units(doc))[len(column) :]
                    text = f"{label}{unit}, largest of {len(values)} {key}"
                    found.append((rel, text, max(values)))
    return found


#: Objects of a JSON result that describe rather than result (not searched for key numbers).
_NOT_RESULTS = frozenset(
    {"units", "conventions", "base", "metadata", "robot", "kinematics", "options", "bounds", "std"}
)


# ---------------------------------------------------------------------- page parts
def input_files(argv: Sequence[str], out: str | Path | None = None) -> list[tuple[str, Path]]:
    """The files named on a command line: (option, path) of each argument that is an
    existing file outside the output folder ``out``.

    Parameters
    ----------
    argv : sequence of str
        The command line (``--opt value`` and ``--opt=value`` forms).
    out : str or Path, optional
        The output folder; files under it are outputs, not inputs.

    Returns
    -------
    list of (str, Path)
        In command-line order; the option is ``""`` for a positional argument.
    """
    outdir = Path(os.path.abspath(out)) if out is not None else None
    found: list[tuple[str, Path]] = []
    flag = ""
    for arg in argv:
        if arg.startswith("--") and "=" in arg:
            flag, value = arg.split("=", 1)
        elif arg.startswith("-") and not _looks_numeric(arg):
            flag = arg
            continue
        else:
            value = arg
        p = Path(value)
        try:
            is_file = p.is_file()
        except (OSError, ValueError):
            is_file = False
        ap = Path(os.path.abspath(p))
        if is_file and (outdir is None or outdir not in ap.parents):
            found.append((flag, p))
        flag = ""
    return found


def _looks_numeric(arg: str) -> bool:
    try:
        float(arg.split(",")[0])
    except ValueError:
        return False
    return True


def _sha256(path: Path) -> str:
    h = hashlib.sha256()
    with open(path, "rb") as fh:
        for block in iter(lambda: fh.read(1 << 20), b""):
            h.update(block)
    return h.hexdigest()


def _inputs_html(summary: RunSummary, out: Path | None) -> str:
    line = " ".join(_quote_arg(a) for a in summary.argv) or summary.command
    parts = [f'<pre class="cmd">{_e(line)}</pre>']
    rows = []
    for flag, p in input_files(summary.argv[1:], out):
        try:
            st, digest = p.stat(), _sha256(p)
        except OSError:
            continue
        ap = os.path.abspath(p)
        rel = os.path.relpath(ap, out) if out is not None else ap
        rows.append(
            [
                f"<code>{_e(flag)}</code>",
                f'<a href="{_href(rel)}">{_e(p)}</a>',
                _e(_size(st.st_size)),
                f'<code title="sha256 {_e(digest)}">{_e(digest[:12])}</code>',
            ]
        )
    if rows:
        parts.append(_table(["option", "input file", "size", "sha256"], rows))
    if summary.options:
        opts = [[f"<code>{_e(k)}</code>", _e(v)] for k, v in summary.options]
        parts.append(
            "<details><summary>all options, defaults included</summary>"
            + _table(["option", "value"], opts, cls="kv")
            + "</details>"
        )
    return "".join(parts)


def _quote_arg(a: str) -> str:
    safe = a and all(c.isalnum() or c in "-_./=,:+@%" for c in a)
    return a if safe else "'" + a.replace("'", "'\\''") + "'"


def _figure_html(rel: str, path: Path) -> str:
    data = base64.b64encode(path.read_bytes()).decode("ascii")
    return (
        f'<figure><a href="{_href(rel)}"><img alt="{_e(rel)}" '
        f'src="data:image/png;base64,{data}"></a>'
        f"<figcaption>{_e(rel)}</figcaption></figure>"
    )


def _messages_html(summary: RunSummary) -> str:
    if not summary.warnings and not summary.notes:
        return '<p class="dim">None.</p>'
    items = [f'<li class="warning"><b>warning</b> {_e(w)}</li>' for w in summary.warnings]
    items += [f'<li class="note"><b>note</b> {_e(n)}</li>' for n in summary.notes]
    return f'<ul class="messages">{"".join(items)}</ul>'


def _files_html(files: Mapping[str, Path]) -> str:
    rows = []
    for rel, path in sorted(files.items()):
        try:
            size = _size(path.stat().st_size)
        except OSError:
            size = ""
        rows.append([f'<a href="{_href(rel)}">{_e(rel)}</a>', _e(size)])
    rows.append([f"{_e(REPORT_NAME)} (this page)", ""])
    return _table(["file", "size"], rows)


def _load_json(path: Path) -> Any:
    try:
        return json.loads(path.read_text(encoding="utf-8"))
    except (OSError, ValueError, RecursionError):
        return None


def _groups(files: Mapping[str, Path]) -> list[tuple[str, list[str]]]:
    """The files by folder (``""`` the output folder itself), in the order written."""
    groups: dict[str, list[str]] = {}
    for rel in files:
        folder = rel.rsplit("/", 1)[0] if "/" in rel else ""
        groups.setdefault(folder, []).append(rel)
    root = groups.pop("", None)
    return ([("", root)] if root else []) + list(groups.items())


# ---------------------------------------------------------------------- the page
def render_html_report(
    summary: RunSummary,
    files: Mapping[str, Path],
    *,
    out: str | Path | None = None,
    title: str | None = None,
) -> str:
    """The report page of a run, as one self-contained HTML document.

    Parameters
    ----------
    summary : RunSummary
        What the run was given and said.
    files : mapping of str to Path
        The files of the run: name relative to the output folder (POSIX separators) ->
        where its content is now (its staged copy while the run completes).
    out : str or Path, optional
        The output folder (for the relative links to the input files).
    title : str, optional
        The page's title (default: ``dynid <command>: <folder name>``).

    Returns
    -------
    str
        The HTML document.

    Raises
    ------
    OSError
        A figure of ``files`` cannot be read (JSON files that cannot be read or parsed
        are shown as such, not raised).
    """
    outdir = Path(os.path.abspath(out)) if out is not None else None
    folder_name = outdir.name if outdir is not None else ""
    title = title or f"dynid {summary.command}" + (f": {folder_name}" if folder_name else "")
    docs = [(rel, _load_json(p)) for rel, p in files.items() if rel.endswith(".json")]
    from .. import __version__

    meta = [time.strftime("%Y-%m-%d %H:%M UTC", time.gmtime()), f"dynid {__version__}"]
    if summary.elapsed_s is not None:
        meta.append(f"{summary.elapsed_s:.1f} s")
    meta.append(f"exit status {summary.exit_code}")
    body = [f"<h1>{_e(title)}</h1>", f'<p class="meta">{_e(" | ".join(meta))}</p>']
    if summary.warnings or summary.notes:
        counts = [
            f"{n} {word}{'' if n == 1 else 's'}"
            for n, word in ((len(summary.warnings), "warning"), (len(summary.notes), "note"))
            if n
        ]
        body.append(f'<p class="banner"><a href="#messages">{", ".join(counts)}</a></p>')
    body.append(f'<h2 id="inputs">Run</h2>{_inputs_html(summary, outdir)}')
    keys = _key_numbers(docs)
    if keys:
        cards = "".join(
            f'<div class="card"><div class="value">{_cell(v)}</div>'
            f'<div class="label">{_e(label)}</div><div class="src">{_e(rel)}</div></div>'
            for rel, label, v in keys
        )
        body.append(f'<h2 id="key-numbers">Key numbers</h2><div class="cards">{cards}</div>')
    for t in summary.tables:
        rows = [[_e(c) for c in r] for r in t.rows]
        body.append(f"<h2>{_e(t.title)}</h2>" + _table(t.headers, rows))
    doc_of = dict(docs)
    for folder, names in _groups(files):
        heading = "Results" if not folder else f"Results: {folder}/"
        parts = [_json_section(rel, doc_of[rel]) for rel in names if rel in doc_of]
        figures = [_figure_html(rel, files[rel]) for rel in names if rel.endswith(".png")]
        if figures:
            parts.append(f'<div class="figures">{"".join(figures)}</div>')
        if parts:
            anchor = "results" + (f"-{_href(folder)}" if folder else "")
            body.append(f'<h2 id="{anchor}">{_e(heading)}</h2>' + "".join(parts))
    if summary.printed.strip():
        long = summary.printed.count("\n") > LONG_PRINTOUT
        body.append(
            f'<h2 id="printed">Printed summary</h2><details{"" if long else " open"}>'
            f"<summary>what the command printed</summary>"
            f'<pre class="printed">{_e(summary.printed.rstrip())}</pre></details>'
        )
    body.append(f'<h2 id="messages">Warnings and notes</h2>{_messages_html(summary)}')
    body.append(f'<h2 id="files">Files</h2>{_files_html(files)}')
    return _PAGE.format(title=_e(title), style=_STYLE, body="\n".join(body), script=_SCRIPT)


def save_html_report(
    path: str | Path,
    summary: RunSummary,
    files: Mapping[str, Path],
    *,
    title: str | None = None,
) -> Path:
    """Write the report of a run to ``path`` (atomically; staged inside a run).

    Parameters
    ----------
    path : str or Path
        The report's path, normally ``<--out>/report.html``; the links are relative to
        its folder.
    summary : RunSummary
        What the run was given and said.
    files : mapping of str to Path
        The run's files: name relative to the folder -> where the content is now.
    title : str, optional
        The page's title.

    Returns
    -------
    Path
        ``path``.

    Raises
    ------
    OSError
        The report cannot be written.
    """
    page = render_html_report(summary, files, out=Path(path).parent, title=title)
    return write_text(path, page)


_STYLE = """
body{font:15px/1.45 system-ui,-apple-system,"Segoe UI",Roboto,sans-serif;color:#1d232a;
margin:0 auto;max-width:1180px;padding:20px 28px 60px;background:#fff}
h1{font-size:26px;margin:8px 0 2px}h2{font-size:20px;margin:30px 0 10px;padding-bottom:4px;
border-bottom:2px solid #e3e7eb}h3{font-size:16px;margin:18px 0 8px}h4{font-size:14px;
margin:14px 0 6px;color:#444}
a{color:#0b62c4;text-decoration:none}a:hover{text-decoration:underline}
.meta{color:#66707a;margin:0 0 10px}.dim{color:#8a939b}
.banner{background:#fff6dd;border:1px solid #f0d27a;padding:8px 12px;border-radius:6px}
pre{background:#f5f7f9;border:1px solid #e3e7eb;border-radius:6px;padding:10px 12px;
overflow-x:auto;font:13px/1.4 ui-monospace,"DejaVu Sans Mono",Menlo,monospace}
pre.cmd{white-space:pre-wrap;word-break:break-all}
table{border-collapse:collapse;margin:6px 0 12px;font-size:13.5px}
th,td{border:1px solid #dde2e6;padding:3px 9px;text-align:left;vertical-align:top}
th{background:#f0f3f6;font-weight:600}tbody tr:nth-child(even){background:#fafbfc}
table.kv td:first-child{font-family:ui-monospace,"DejaVu Sans Mono",monospace;color:#333}
table.matrix td{text-align:right;font-variant-numeric:tabular-nums}
td{font-variant-numeric:tabular-nums}
.cards{display:flex;flex-wrap:wrap;gap:10px}
.card{border:1px solid #dde2e6;border-radius:8px;padding:8px 14px;min-width:130px;
background:#fafcfe}.card .value{font-size:20px;font-weight:600}
.card .label{color:#333}.card .src{color:#8a939b;font-size:12px}
.yes{color:#137333;font-weight:600}.no{color:#b3261e;font-weight:600}
.schema{font-weight:400;font-size:12px;color:#66707a;background:#eef1f4;padding:1px 6px;
border-radius:4px;margin-left:6px}
.figures{display:flex;flex-wrap:wrap;gap:18px}
figure{margin:6px 0;max-width:100%}figure img{max-width:100%;height:auto;
border:1px solid #e3e7eb;border-radius:4px}figcaption{color:#555;font-size:13px}
details{margin:6px 0}summary{cursor:pointer;color:#0b62c4}
ul.messages{padding-left:0;list-style:none}ul.messages li{padding:5px 10px;margin:4px 0;
border-radius:5px}li.warning{background:#fff6dd;border-left:4px solid #e0a800}
li.note{background:#eef5ff;border-left:4px solid #5b9bd5}
"""

_SCRIPT = """
window.addEventListener("load", function () {
  var images = document.querySelectorAll("img"), decoded = 0;
  for (var i = 0; i < images.length; i++) {
    images[i].setAttribute("data-natural-width", String(images[i].naturalWidth));
    if (images[i].complete && images[i].naturalWidth > 0) { decoded++; }
  }
  document.body.setAttribute("data-figures-decoded", String(decoded));
});
"""

_PAGE = """<!DOCTYPE html>
<html lang="en">
<head>
<meta charset="utf-8">
<meta name="viewport" content="width=device-width, initial-scale=1">
<title>{title}</title>
<style>{style}</style>
</head>
<body>
{body}
<script>{script}</script>
</body>
</html>
"""
