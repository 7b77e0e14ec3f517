"""report.html (issue 21): one self-contained page per run, with the run's inputs, its
results as tables, its figures embedded, its warnings and notes, and links to its files.

The pages are read back with the standard library's HTML parser (and, where Chromium is
installed, rendered by it): what a browser sees, not our own strings.
"""

from __future__ import annotations

import base64
import json
import struct
import urllib.parse
import zlib
from html.parser import HTMLParser

from dynid.io.html_report import (
    REPORT_NAME,
    ReportTable,
    RunSummary,
    input_files,
    render_html_report,
    save_html_report,
)


class _Page(HTMLParser):
    """The parts of a page the tests look at: tables (rows of cell text), images, links,
    scripts, and all text."""

    def __init__(self, text: str) -> None:
        super().__init__(convert_charrefs=True)
        self.tables: list[list[list[str]]] = []
        self.images: list[dict[str, str]] = []
        self.links: list[str] = []
        self.scripts = 0
        self.external: list[str] = []
        self.text: list[str] = []
        self._cell: list[str] | None = None
        self._in_script = False
        self.feed(text)
        self.close()

    def handle_starttag(self, tag: str, attrs: list[tuple[str, str | None]]) -> None:
        a = {k: v or "" for k, v in attrs}
        if tag == "table":
            self.tables.append([])
        elif tag == "tr":
            self.tables[-1].append([])
        elif tag in ("td", "th"):
            self._cell = []
        elif tag == "img":
            self.images.append(a)
        elif tag == "a" and "href" in a:
            self.links.append(a["href"])
        elif tag == "script":
            self.scripts += 1
            self._in_script = True
            if "src" in a:
                self.external.append(a["src"])
        elif tag == "link" and "href" in a:
            self.external.append(a["href"])

    def handle_endtag(self, tag: str) -> None:
        if tag in ("td", "th") and self._cell is not None:
            self.tables[-1][-1].append("".join(self._cell).strip())
            self._cell = None
        elif tag == "script":
            self._in_script = False

    def handle_data(self, data: str) -> None:
        if self._cell is not None:
            self._cell.append(data)
        if not self._in_script:
            self.text.append(data)

    def cells(self) -> set[str]:
        return {c for t in self.tables for r in t for c in r}


def _png(width: int, height: int, seed: int) -> bytes:
    """A valid RGB PNG of random pixels, built from the format's definition (zlib, CRCs)."""
    rng = __import__("numpy").random.default_rng(seed)
    rows = b"".join(
        b"\x00" + rng.integers(0, 256, 3 * width, dtype="uint8").tobytes() for _ in range(height)
    )

    def chunk(kind: bytes, data: bytes) -> bytes:
        return (
            struct.pack(">I", len(data))
            + kind
            + data
            + struct.pack(">I", zlib.crc32(kind + data) & 0xFFFFFFFF)
        )

    header = struct.pack(">IIBBBBB", width, height, 8, 2, 0, 0, 0)
    return (
        b"\x89PNG\r\n\x1a\n"
        + chunk(b"IHDR", header)
        + chunk(b"IDAT", zlib.compress(rows))
        + chunk(b"IEND", b"")
    )


HOSTILE = "données <b>&amp;\"x' #?%"


def test_user_text_is_escaped_everywhere(tmp_path):
    """File names, arguments, JSON values, printed lines, warnings and notes with <&"'>
    and non-ASCII characters come back as the same text, never as markup."""
    out = tmp_path / "o"
    out.mkdir()
    data = tmp_path / f"{HOSTILE}.csv"
    data.write_text("t,q\n0,0\n")
    res = out / f"{HOSTILE}.json"
    res.write_text(json.dumps({"schema": "x/1", "label": "<script>alert(1)</script>"}))
    summary = RunSummary(
        command="identify",
        argv=("dynid", "identify", "--data", str(data), "--out", str(out)),
        options=(("--data", str(data)),),
        printed=f"joint {HOSTILE}\n",
        warnings=(f"bad {HOSTILE}",),
        notes=("<i>note</i>",),
        tables=(ReportTable(HOSTILE, (HOSTILE, "b"), ((HOSTILE, "1"),)),),
    )
    page_text = render_html_report(summary, {res.name: res}, out=out)
    page = _Page(page_text)
    assert page.scripts == 1  # ours only: the JSON's <script> is text
    assert "<script>alert" not in page_text and "<b>&amp;" not in page_text
    text = "".join(page.text)
    for s in (
        f"joint {HOSTILE}",
        f"bad {HOSTILE}",
        "<i>note</i>",
        "<script>alert(1)</script>",
        f"{HOSTILE}.json",
    ):
        assert s in text, s
    assert HOSTILE in page.cells()
    # the links: relative, percent-encoded, naming the files
    targets = {urllib.parse.unquote(h) for h in page.links}
    assert f"{HOSTILE}.json" in targets and f"../{HOSTILE}.csv" in targets
    assert all(not h.startswith(("/", "file:", "http")) for h in page.links)
    assert page.external == []


def test_figures_are_embedded_byte_for_byte(tmp_path):
    """Each PNG is in the page as a data URI that decodes to the file's bytes; the page
    loads nothing from elsewhere."""
    pngs = {"a.png": _png(7, 5, seed=1), "sub/b c.png": _png(3, 9, seed=2)}
    files = {}
    for rel, data in pngs.items():
        p = tmp_path / rel
        p.parent.mkdir(parents=True, exist_ok=True)
        p.write_bytes(data)
        files[rel] = p
    page = _Page(render_html_report(RunSummary(command="demo"), files, out=tmp_path))
    decoded = {}
    for img in page.images:
        head, _, payload = img["src"].partition(",")
        assert head == "data:image/png;base64"
        decoded[img["alt"]] = base64.b64decode(payload, validate=True)
    assert decoded == pngs
    assert {urllib.parse.unquote(h) for h in page.links} >= set(pngs)
    assert page.external == []


def test_json_results_become_tables(tmp_path):
    """Scalars as key/value rows, records as rows, per-joint vectors side by side named by
    the joint names, small matrices; large arrays named by their shape."""
    doc = {
        "schema": "dynid-test/1",
        "rank": 43,
        "feasible": True,
        "relative_error_percent": 0.123456,
        "joint_names": ["j1", "j2", "j3"],
        "rms": [0.5, 0.25, 0.125],
        "mse": [0.25, 0.0625, 0.015625],
        "joints": [{"fv": 1.5, "fc": 0.25}, {"fv": 2.5, "fc": 0.5}, {"fv": 3.5, "fc": 0.75}],
        "friction": [[1.0, 2.0], [3.0, 4.0]],
        "covariance": [[0.0] * 43] * 43,
        "units": {"rms": "N m"},
    }
    p = tmp_path / "r.json"
    p.write_text(json.dumps(doc))
    page = _Page(render_html_report(RunSummary(command="validate"), {"r.json": p}, out=tmp_path))
    rows = [r for t in page.tables for r in t]
    assert ["rank", "43"] in rows and ["feasible", "yes"] in rows
    assert ["relative_error_percent", "0.1235"] in rows
    assert ["", "rms [N m]", "mse"] in rows
    assert ["j2", "0.25", "0.0625"] in rows
    assert ["j3", "3.5", "0.75"] in rows  # records named by the joint names
    assert ["2", "3", "4"] in rows  # the 2 x 2 matrix
    assert any(r[0] == "covariance" and "43 x 43" in r[1] for r in rows)
    # the key numbers come first
    text = " ".join(page.text)
    assert text.index("Key numbers") < text.index("r.json")


def test_input_files_are_the_existing_files_outside_the_output(tmp_path):
    data = tmp_path / "log.csv"
    data.write_text("x\n")
    out = tmp_path / "res"
    out.mkdir()
    (out / "identification.json").write_text("{}")
    argv = [
        "identify",
        "--data",
        str(data),
        f"--model={out / 'identification.json'}",
        "--robot",
        "panda",
        "--q=-0.1,0.2",
        "--out",
        str(out),
    ]
    assert input_files(argv, out) == [("--data", data)]


def test_save_writes_the_page(tmp_path):
    p = save_html_report(tmp_path / REPORT_NAME, RunSummary(command="excite"), {})
    assert p.read_text(encoding="utf-8").startswith("<!DOCTYPE html>")
