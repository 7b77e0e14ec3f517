"""report.html (issue 21): one self-contained page per run, with the run's inputs, its
results as tables, its figures embedded, its warnings and notes, and links to its files.

The pages are read back with the standard library's HTML parser (and, where Chromium is
installed, rendered by it): what a browser sees, not our own strings.
"""

from __future__ import annotations

import base64
import json
import re
import shutil
import struct
import subprocess
import urllib.parse
import zlib
from html.parser import HTMLParser
from pathlib import Path

import numpy as np
import pytest

import dynid
from dynid.cli.__main__ import main
from dynid.io.robot.toml import save_toml
from dynid.io.run_output import MANIFEST
from dynid.report import (
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
    rng = np.random.default_rng(seed)
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
        "joints": [
            {"fv": 1.5, "fc": 0.25, "rms_after": 0.03},
            {"fv": 2.5, "fc": 0.5, "rms_after": 0.07},
            {"fv": 3.5, "fc": 0.75, "rms_after": 0.05},
        ],
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
    assert ["j3", "3.5", "0.75", "0.05"] in rows  # records named by the joint names
    assert ["2", "3", "4"] in rows  # the 2 x 2 matrix
    assert any(r[0] == "covariance" and "43 x 43" in r[1] for r in rows)
    # the key numbers come first; the largest RMS after friction over the joints is one
    text = " ".join(page.text)
    assert text.index("Key numbers") < text.index("r.json")
    assert re.search(r"0\.07\s+RMS after, largest of 3 joints", text)


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


# ---------------------------------------------------------------------- every command
#: The commands that write a folder, each with a short run (output folder -> argv).
COMMANDS = {
    "identify": ["identify", "--data", "{d}/s.csv"],
    "consistent": ["identify", "--data", "{d}/s.csv", "--consistent"],
    "friction": ["friction", "--model", "{d}/identify/identification.json", "--data", "{d}/l.csv"],
    "validate": [
        "validate",
        "--model",
        "{d}/identify/identification.json",
        "--friction",
        "{d}/friction/friction.json",
        "--data",
        "{d}/l.csv",
    ],
    "retrieve": ["retrieve", "--model", "{d}/identify/identification.json"],
    "payload": ["payload", "--robot", "panda", "--data", "{d}/loaded.csv"],
    "excite": [
        "excite",
        "--duration",
        "1",
        "--harmonics",
        "1",
        "--base-frequency",
        "0.5",
        "--max-iter",
        "1",
    ],
}


@pytest.fixture(scope="module")
def runs(tmp_path_factory) -> Path:
    """One short run of each command, in order, each into its own folder."""
    d = tmp_path_factory.mktemp("reports")
    assert main(["acquire-static", "--n", "60", "--seed", "3", "--out", f"{d}/s.csv", "-q"]) == 0
    # a 1 kg load at the flange, for payload (data without a load are refused)
    loaded = dynid.panda().with_tool(np.eye(4), mass=1.0, inertia=np.diag([1e-3] * 3))
    save_toml(d / "loaded.toml", loaded)
    static = ["acquire-static", "--robot", f"{d}/loaded.toml", "--n", "60", "--seed", "3"]
    assert main([*static, "--out", f"{d}/loaded.csv", "-q"]) == 0
    sim = ["simulate", "--trajectory", "sinusoid", "--duration", "2", "--rate", "200"]
    assert main([*sim, "--seed", "1", "--out", f"{d}/l.csv", "-q"]) == 0
    for name, argv in COMMANDS.items():
        code = main([a.format(d=d) for a in argv] + ["--out", str(d / name), "-q"])
        assert code == 0, name
    return d


@pytest.mark.slow
@pytest.mark.parametrize("name", list(COMMANDS))
def test_every_command_writes_its_report(runs, name):
    """report.html is part of the folder's set; it embeds every figure of the run and
    links every other file; the JSON results are tables, the command line is shown."""
    out = runs / name
    files = json.loads((out / MANIFEST).read_text())["files"]
    assert REPORT_NAME in files
    page_text = (out / REPORT_NAME).read_text(encoding="utf-8")
    page = _Page(page_text)
    pngs = sorted(f for f in files if f.endswith(".png"))
    embedded = {img["alt"]: base64.b64decode(img["src"].split(",", 1)[1]) for img in page.images}
    assert embedded == {f: (out / f).read_bytes() for f in pngs}
    linked = {urllib.parse.unquote(h) for h in page.links if not h.startswith("#")}
    assert set(files) - {REPORT_NAME} <= linked
    assert all((out / h).exists() for h in linked if not h.startswith("../"))
    anchors = {h[1:] for h in page.links if h.startswith("#")}
    assert all(f'id="{a}"' in page_text for a in anchors)  # in-page links land
    for f in files:
        if f.endswith(".json"):
            schema = json.loads((out / f).read_text())["schema"]
            assert schema in page.cells() or schema in "".join(page.text)
    assert len(page.tables) >= 3  # inputs, files, and at least one result
    assert COMMANDS[name][0] in "".join(page.text) and page.external == []
    inputs = {a.replace("{d}/", "../") for a in COMMANDS[name] if a.startswith("{d}/")}
    assert inputs <= linked  # the input files, linked from the folder


# ---------------------------------------------------------------------- in a browser
CHROMIUM = next(
    (p for p in map(shutil.which, ("chromium", "chromium-browser", "google-chrome")) if p), None
)
needs_chromium = pytest.mark.skipif(
    CHROMIUM is None, reason="no chromium on PATH (make test installs it where apt-get can)"
)


def _browser(page: Path, profile: Path, *args: str) -> subprocess.CompletedProcess:
    assert CHROMIUM is not None
    argv = [CHROMIUM, "--headless", "--no-sandbox", "--disable-gpu", "--hide-scrollbars"]
    argv += [f"--user-data-dir={profile}", "--virtual-time-budget=10000", *args]
    return subprocess.run(
        [*argv, page.resolve().as_uri()], capture_output=True, text=True, timeout=180
    )


def _check_in_browser(page: Path, tmp_path: Path) -> None:
    """The rendered page: every figure decoded at its file's width, the tables in the
    document, and a screenshot that is not blank."""
    text = page.read_text(encoding="utf-8")
    widths = [
        struct.unpack(">I", base64.b64decode(src)[16:20])[0]  # IHDR width of the PNG
        for src in re.findall(r'src="data:image/png;base64,([^"]+)"', text)
    ]
    dom = _browser(page, tmp_path / "profile", "--dump-dom")
    if dom.returncode != 0 or "<body" not in dom.stdout:
        pytest.skip(f"chromium cannot run here: {dom.stderr.strip()[-300:]}")
    decoded = re.search(r'data-figures-decoded="(\d+)"', dom.stdout)
    assert decoded is not None, "the page's script did not run"
    assert int(decoded.group(1)) == len(widths) > 0
    assert [int(w) for w in re.findall(r'data-natural-width="(\d+)"', dom.stdout)] == widths
    assert len(_Page(dom.stdout).tables) == len(_Page(text).tables) >= 3
    shot = tmp_path / "shot.png"
    r = _browser(page, tmp_path / "profile", f"--screenshot={shot}", "--window-size=1200,2000")
    assert r.returncode == 0 and shot.is_file(), r.stderr[-300:]
    image = pytest.importorskip("PIL.Image")
    with image.open(shot) as im:
        gray = np.asarray(im.convert("L"), dtype=float)
    assert gray.shape == (2000, 1200)
    assert gray.std() > 10 and (gray < 128).mean() > 0.01  # text, tables and figures drawn


@needs_chromium
def test_a_report_renders_in_chromium(tmp_path):
    """A report of synthetic results with two figures, rendered headless."""
    out = tmp_path / "run"
    (out / "sub").mkdir(parents=True)
    (out / "a.png").write_bytes(_png(400, 300, seed=3))
    (out / "sub" / "b.png").write_bytes(_png(250, 120, seed=4))
    doc = {"schema": "dynid-test/1", "rank": 7, "joints": [{"fv": 1.0}, {"fv": 2.0}]}
    (out / "r.json").write_text(json.dumps(doc))
    files = {f: out / f for f in ("r.json", "a.png", "sub/b.png")}
    summary = RunSummary(command="demo", argv=("dynid", "demo"), warnings=("w",))
    save_html_report(out / REPORT_NAME, summary, files)
    _check_in_browser(out / REPORT_NAME, tmp_path)


@pytest.mark.slow
@needs_chromium
def test_the_validate_report_renders_in_chromium(runs, tmp_path):
    """validate's report (two figures of the command) shows its figures in Chromium."""
    _check_in_browser(runs / "validate" / REPORT_NAME, tmp_path)
