"""The HTML report of one run: ``report.html`` in the output folder, a single file.

:func:`save_html_report` is called once at the end of every run that writes a folder
(``identify``, ``validate``, ``friction``, ``retrieve``, ``payload``, ``excite``,
``demo``), when the folder's files are complete and before they move into place. The
report is built from what the run recorded (:class:`RunSummary`: command line, options,
printed summary, warnings and notes, tables a command adds) and from the files it wrote:

* it opens with the command's answer (:mod:`dynid.report.answers`): a verdict, the figures
  and the tables that answer the command's question; figures a run left out (matplotlib
  missing) are named in the first lines with how to get them;
* the JSON results become tables (their scalars, their records such as ``coefficients[]``
  or ``joints[]``, per-joint vectors side by side, small matrices; larger arrays are named
  with their shape and left in the file);
* the PNG figures are embedded as base64 ``data:`` URIs;
* every file is linked by a relative address, so the links work where the folder is.

The page needs no network access: inline CSS, no fonts or scripts from elsewhere. A short
inline script records, once the page has loaded, each figure's decoded width in its
``data-natural-width`` attribute, and in the body's attributes the number of decoded
figures (``data-figures-decoded``), where the verdict ends and where the first figure
starts [CSS px] (``data-verdict-bottom``, ``data-first-figure-top``): what a headless
browser test reads back. Every text that comes from a user or a file (names, values,
messages) is escaped.

Pure string building: no template engine, no plotting library.
"""

from __future__ import annotations

import hashlib
import json
import os
import time
from collections.abc import Mapping, Sequence
from pathlib import Path
from typing import Any

from .._times import longest_gaps, said_time
from ..io.atomic import write_text
from .answers import answer_for
from .html import cell, esc, figure, href, number, size, table
from .json_tables import json_section, key_numbers
from .run import REPORT_NAME, ReportTable, RunFiles, RunSummary

__all__ = [
    "REPORT_NAME",
    "ReportTable",
    "RunSummary",
    "input_files",
    "render_html_report",
    "save_html_report",
]

#: Printed output longer than this many lines starts collapsed.
LONG_PRINTOUT = 60


# ---------------------------------------------------------------------- page parts
def input_files(argv: Sequence[str], out: str | Path | None = None) -> list[tuple[str, Path]]:
    """The files named on a command line: (option, path) of each argument that is an
    existing file outside the output folder ``out``, and of each data file (``.csv``,
    ``.npz``, in name order) of an argument that is a folder (``--data folder/``).

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
        outside = outdir is None or (outdir != ap and outdir not in ap.parents)
        if is_file and outside:
            found.append((flag, p))
        elif outside and _is_dir(p):
            found += [(flag, f) for f in sorted(p.iterdir()) if f.suffix.lower() in _DATA]
        flag = ""
    return found


#: the suffixes of the data files a folder given as data stands for
_DATA = (".csv", ".npz")


def _is_dir(p: Path) -> bool:
    try:
        return p.is_dir()
    except (OSError, ValueError):
        return False


def _recordings(docs: Mapping[str, Any]) -> dict[str, dict[str, Any]]:
    """What the run's files say of each recording read, by file name: ``pieces`` and
    ``samples`` used (``recordings`` of ``identification.json``'s metadata, of
    ``validation.json``, ``payload.json``, ...)."""
    out: dict[str, dict[str, Any]] = {}
    for doc in docs.values():
        if not isinstance(doc, dict):
            continue
        meta = doc.get("metadata")
        for recs in (
            doc.get("recordings"),
            meta.get("recordings") if isinstance(meta, dict) else None,
        ):
            for r in recs if isinstance(recs, list) else ():
                if isinstance(r, dict) and isinstance(r.get("file"), str):
                    out[r["file"]] = {**r, **out.get(r["file"], {})}  # the first file's first
    return out


def _pieces(rec: Mapping[str, Any]) -> str:
    """A recording's pieces, with where it was cut: ``2 (gap after t = 86412.300 s
    (11.3 s into rec1.csv), 1 s long)``: the stamp as in the file and its offset."""
    gaps = [g for g in rec.get("gaps") or () if isinstance(g, list) and len(g) == 2]
    t0 = rec.get("start_s") if isinstance(rec.get("start_s"), (int, float)) else None
    name = rec.get("file") if isinstance(rec.get("file"), str) else None
    shown, more = longest_gaps(gaps)
    said = "; ".join(
        f"gap after {esc(said_time(t, t0, name))}, {number(n, 3)} s long" for t, n in shown
    )
    more = more.replace(" and", ";", 1)
    return esc(rec.get("pieces", "")) + (f" ({said}{more})" if said else "")


def _rows(path: Path) -> str:
    """The data rows of a recording: a CSV's lines after its header (comments and blank
    lines apart), an NPZ's length of ``t``; "" when it cannot tell."""
    try:
        if path.suffix.lower() == ".npz":
            import numpy as np

            with np.load(path) as z:
                return str(len(z["t"])) if "t" in z.files else ""
        with open(path, encoding="utf-8", errors="replace") as fh:
            lines = sum(1 for line in fh if line.strip() and not line.startswith("#"))
        return str(max(lines - 1, 0))
    except (OSError, ValueError, KeyError):
        return ""


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


def _inputs_html(
    summary: RunSummary, out: Path | None, docs: Mapping[str, Any] | None = None
) -> str:
    line = " ".join(_quote_arg(a) for a in summary.argv) or summary.command
    parts = [f'<pre class="cmd">{esc(line)}</pre>']
    rows = []
    recs = _recordings(docs or {})
    inputs = input_files(summary.argv[1:], out)
    read = any(p.name in recs for _, p in inputs)
    for flag, p in inputs:
        try:
            st, digest = p.stat(), _sha256(p)
        except OSError:
            continue
        ap = os.path.abspath(p)
        rel = os.path.relpath(ap, out) if out is not None else ap
        rec = recs.get(p.name)
        counts = [] if not read else ["", "", ""]
        if rec is not None:
            counts = [_rows(p), _pieces(rec), esc(rec.get("samples", ""))]
        rows.append(
            [
                f"<code>{esc(flag)}</code>",
                f'<a href="{href(rel)}">{esc(p)}</a>',
                *counts,
                esc(size(st.st_size)),
                f'<code title="sha256 {esc(digest)}">{esc(digest[:12])}</code>',
            ]
        )
    if rows:
        counted = ["rows in the file", "pieces", "samples used"] if read else []
        parts.append(table(["option", "input file", *counted, "size", "sha256"], rows))
    if summary.options:
        opts = [[f"<code>{esc(k)}</code>", esc(v)] for k, v in summary.options]
        parts.append(
            "<details><summary>all options, defaults included</summary>"
            + table(["option", "value"], opts, cls="kv")
            + "</details>"
        )
    return "".join(parts)


def _quote_arg(a: str) -> str:
    safe = a and all(c.isalnum() or c in "-_./=,:+@%" for c in a)
    return a if safe else "'" + a.replace("'", "'\\''") + "'"


def _messages_html(summary: RunSummary) -> str:
    if not summary.warnings and not summary.notes:
        return '<p class="dim">None.</p>'
    items = [f'<li class="warning"><b>warning</b> {esc(w)}</li>' for w in summary.warnings]
    items += [f'<li class="note"><b>note</b> {esc(n)}</li>' for n in summary.notes]
    return f'<ul class="messages">{"".join(items)}</ul>'


def _files_html(files: Mapping[str, Path]) -> str:
    rows = []
    for rel, path in sorted(files.items()):
        try:
            shown = size(path.stat().st_size)
        except OSError:
            shown = ""
        rows.append([f'<a href="{href(rel)}">{esc(rel)}</a>', esc(shown)])
    rows.append([f"{esc(REPORT_NAME)} (this page)", ""])
    return table(["file", "size"], rows)


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
    docs = {rel: _load_json(p) for rel, p in files.items() if rel.endswith(".json")}
    run = RunFiles(summary=summary, files=dict(files), docs=docs)
    answer = answer_for(run)
    body = [f"<h1>{esc(title)}</h1>", f'<p class="meta">{esc(" | ".join(_meta(summary)))}</p>']
    body += _banners(summary)
    if answer is not None:
        body.append(answer.verdict)
        body += answer.sections
    else:
        body.append(_key_numbers_html(list(docs.items())))
    body.append(f'<h2 id="inputs">Run</h2>{_inputs_html(summary, outdir, docs)}')
    for t in summary.tables:
        rows = [[esc(c) for c in r] for r in t.rows]
        body.append(f"<h2>{esc(t.title)}</h2>" + table(t.headers, rows))
    shown = answer.shown if answer is not None else frozenset()
    body += _results_html(files, docs, shown, collapsed=answer is not None)
    if summary.printed.strip():
        long = summary.printed.count("\n") > LONG_PRINTOUT
        body.append(
            f'<h2 id="printed">Printed summary</h2><details{"" if long else " open"}>'
            f"<summary>what the command printed</summary>"
            f'<pre class="printed">{esc(summary.printed.rstrip())}</pre></details>'
        )
    body.append(f'<h2 id="messages">Warnings and notes</h2>{_messages_html(summary)}')
    body.append(f'<h2 id="files">Files</h2>{_files_html(files)}')
    return _PAGE.format(title=esc(title), style=_STYLE, body="\n".join(body), script=_SCRIPT)


def _meta(summary: RunSummary) -> list[str]:
    from .. import __version__

    meta = [time.strftime("%Y-%m-%d %H:%M UTC", time.gmtime()), f"dynid {__version__}"]
    if summary.elapsed_s is not None:
        meta.append(f"{summary.elapsed_s:.1f} s")
    meta.append(f"exit status {summary.exit_code}")
    return meta


#: What a note says when a figure was not drawn (:func:`dynid.cli.common.save_figure`).
_SKIPPED = ("skipped the figure ", "matplotlib is not installed")


def _banners(summary: RunSummary) -> list[str]:
    """The figures left out (and how to get them), the count of warnings and notes."""
    out = []
    skipped = [n for n in summary.notes if _SKIPPED[0] in n]
    if skipped:
        names = [n.split(_SKIPPED[0], 1)[1].split(":", 1)[0] for n in skipped]
        how = (
            "install matplotlib (<code>pip install matplotlib</code>) and run the command again"
            if any(_SKIPPED[1] in n for n in skipped)
            else "see the notes below for why, then run the command again"
        )
        out.append(
            f'<p class="banner figures-left-out" id="figures-left-out"><b>Figures left out:</b> '
            f"{esc(', '.join(names))}. To get them, {how}.</p>"
        )
    if summary.warnings or summary.notes:
        counts = [
            f"{n} {word}{'' if n == 1 else 's'}"
            for n, word in ((len(summary.warnings), "warning"), (len(summary.notes), "note"))
            if n
        ]
        out.append(f'<p class="banner"><a href="#messages">{", ".join(counts)}</a></p>')
    return out


def _key_numbers_html(docs: list[tuple[str, Any]]) -> str:
    """The key numbers of a page without a command's own answer (payload, excite)."""
    keys = key_numbers(docs)
    if not keys:
        return ""
    cards = "".join(
        f'<div class="card"><div class="value">{cell(v)}</div>'
        f'<div class="label">{esc(label)}</div><div class="src">{esc(rel)}</div></div>'
        for rel, label, v in keys
    )
    return f'<h2 id="key-numbers">Key numbers</h2><div class="cards">{cards}</div>'


def _results_html(
    files: Mapping[str, Path], docs: Mapping[str, Any], shown: frozenset[str], *, collapsed: bool
) -> list[str]:
    """Every JSON file as tables (collapsed below a command's answer) and the figures the
    answer did not show, by folder."""
    out = []
    for folder, names in _groups(files):
        heading = "Results" if not folder else f"Results: {folder}/"
        if collapsed:
            heading = "In the files" + ("" if not folder else f": {folder}/")
        parts = [json_section(rel, docs[rel], collapsed=collapsed) for rel in names if rel in docs]
        figures = [
            figure(rel, files[rel]) for rel in names if rel.endswith(".png") and rel not in shown
        ]
        if figures:
            parts.append(f'<div class="figures">{"".join(figures)}</div>')
        if parts:
            anchor = "results" + (f"-{href(folder)}" if folder else "")
            out.append(f'<h2 id="{anchor}">{esc(heading)}</h2>' + "".join(parts))
    return out


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
.verdict{border-radius:8px;padding:10px 16px;margin:12px 0 8px;border:1px solid;
border-left-width:8px}.verdict.good{background:#eef8f0;border-color:#2e8540}
.verdict.fair{background:#fff8e6;border-color:#d89b00}.verdict.poor{background:#fdeeee;
border-color:#c0392b}.verdict .headline{font-size:19px;font-weight:600;margin:4px 0 6px}
.verdict .level{text-transform:uppercase;font-size:13px;letter-spacing:.04em;padding:2px 8px;
border-radius:4px;margin-right:6px;color:#fff;vertical-align:middle}
.verdict.info{background:#eef5ff;border-color:#3b73b9}.info .level{background:#3b73b9}
.verdict.unusable{background:#f6e0e0;border-color:#7b1111}
.good .level{background:#2e8540}.fair .level{background:#b07d00}.poor .level{background:#c0392b}
.unusable .level{background:#7b1111}
.verdict ul{margin:4px 0;padding-left:20px}.verdict li{margin:2px 0}
tr.marked{background:#e7f3e9!important;font-weight:600}
.bar{display:inline-block;height:10px;background:#5b8fd5;border-radius:2px;min-width:1px}
.bar.bad{background:#d9534f}table.coefficients td:nth-child(8){width:180px}
.n{white-space:nowrap}.expr{font-size:12px;color:#333;
font-family:ui-monospace,"DejaVu Sans Mono",monospace}
.figures-left-out{background:#fdeeee;border-color:#e0a0a0}
"""

_SCRIPT = """
window.addEventListener("load", function () {
  var images = document.querySelectorAll("img"), decoded = 0;
  for (var i = 0; i < images.length; i++) {
    images[i].setAttribute("data-natural-width", String(images[i].naturalWidth));
    if (images[i].complete && images[i].naturalWidth > 0) { decoded++; }
  }
  var body = document.body, verdict = document.getElementById("verdict");
  var px = function (x) { return String(Math.round(x)); };
  body.setAttribute("data-figures-decoded", String(decoded));
  if (verdict) {
    body.setAttribute("data-verdict-bottom", px(verdict.getBoundingClientRect().bottom));
  }
  if (images.length) {
    body.setAttribute("data-first-figure-top", px(images[0].getBoundingClientRect().top));
  }
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
