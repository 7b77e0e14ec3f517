"""report.html (issue 21): one self-contained page per run, with the run's inputs, its
results as tables, its figures embedded, its warnings and notes, and links to its files.

The pages are read back with the standard library's HTML parser (and, where Chromium is
installed, rendered by it): what a browser sees, not our own strings.
"""

from __future__ import annotations

import base64
import html
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
from dynid.outputs.run_output import MANIFEST
from dynid.report import (
    REPORT_NAME,
    ReportTable,
    RunSummary,
    input_files,
    render_html_report,
    save_html_report,
)


class Page(HTMLParser):
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
    page = Page(page_text)
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
    page = Page(render_html_report(RunSummary(command="demo"), files, out=tmp_path))
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
    page = Page(render_html_report(RunSummary(command="validate"), {"r.json": p}, out=tmp_path))
    rows = [r for t in page.tables for r in t]
    assert ["rank", "43"] in rows and ["feasible", "yes"] in rows
    assert ["relative_error_percent", "0.1235"] in rows
    assert ["name", "rms [N m]", "mse"] in rows  # every column named
    assert ["j2", "0.25", "0.0625"] in rows
    assert ["j3", "3.5", "0.75", "0.05"] in rows  # records named by the joint names
    assert ["2", "3", "4"] in rows  # the 2 x 2 matrix
    assert ["#", "column 1", "column 2"] in rows
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
#: The commands that write a folder, each with a short run (output folder -> argv); identify
#: on a log with its structure fixed (the search's table: test_model_structure_table_...).
COMMANDS = {
    "identify": ["identify", "--data", "{d}/s.csv"],
    "identify-log": ["identify", "--data", "{d}/l6.csv", "--terms", "viscous,coulomb,offset"],
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
    sim6 = ["simulate", "--trajectory", "sinusoid", "--duration", "6", "--rate", "200"]
    assert main([*sim6, "--seed", "2", "--out", f"{d}/l6.csv", "-q"]) == 0  # noise 0.05 N m
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
    page = Page(page_text)
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


def check_in_browser(
    page: Path, tmp_path: Path, *, verdict: bool = False, torques: bool = False
) -> str:
    """The rendered page: every figure decoded at its file's width, the tables in the
    document, and a screenshot that is not blank; with ``verdict``, the verdict ends within
    the first screen (1200 x 900), with ``torques`` a figure starts in it. Returns the DOM.

    One browser start gives the DOM and the screenshot (1200 x 2000): the page's layout
    depends on the window's width alone (no height-relative units), so where the verdict
    ends and the first figure starts are the positions a 1200 x 900 window gives (the same
    DOM to the byte on an identify and an observe report), each start costing seconds."""
    text = page.read_text(encoding="utf-8")
    widths = [
        struct.unpack(">I", base64.b64decode(src)[16:20])[0]  # IHDR width of the PNG
        for src in re.findall(r'src="data:image/png;base64,([^"]+)"', text)
    ]
    shot = tmp_path / "shot.png"
    dom = _browser(
        page, tmp_path / "profile", "--dump-dom", f"--screenshot={shot}", "--window-size=1200,2000"
    )
    if dom.returncode != 0 or "<body" not in dom.stdout:
        pytest.skip(f"chromium cannot run here: {dom.stderr.strip()[-300:]}")
    decoded = re.search(r'data-figures-decoded="(\d+)"', dom.stdout)
    assert decoded is not None, "the page's script did not run"
    assert int(decoded.group(1)) == len(widths)
    assert widths or not torques  # a page of torques has their figure
    assert [int(w) for w in re.findall(r'data-natural-width="(\d+)"', dom.stdout)] == widths
    assert len(Page(dom.stdout).tables) == len(Page(text).tables) >= 3
    if verdict:
        bottom = re.search(r'data-verdict-bottom="(-?\d+)"', dom.stdout)
        assert bottom is not None and 0 < int(bottom.group(1)) <= SCREEN[1], page
    if torques:
        top = re.search(r'data-first-figure-top="(-?\d+)"', dom.stdout)
        assert top is not None and 0 < int(top.group(1)) < SCREEN[1], page
    assert shot.is_file(), dom.stderr[-300:]
    image = pytest.importorskip("PIL.Image")
    with image.open(shot) as im:
        gray = np.asarray(im.convert("L"), dtype=float)
    assert gray.shape == (2000, 1200)
    assert gray.std() > 10 and (gray < 128).mean() > 0.01  # text, tables and figures drawn
    return dom.stdout


#: The first screen a user sees [CSS px]: width, height.
SCREEN = (1200, 900)


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
    check_in_browser(out / REPORT_NAME, tmp_path)


#: The verdict each command's page opens with (command folder -> words of its headline),
#: and whether a figure of torques is in the first screen.
VERDICTS = {
    "identify": ("The model reproduces M(q) and g(q) to", False),
    "identify-log": ("The model predicts held-out torques to", True),
    "consistent": ("The model reproduces M(q) and g(q) to", False),
    "friction": ("Friction law chosen:", True),
    "validate": ("The model predicts the log's torques to", True),
    "retrieve": ("The link parameters are physically consistent", False),
    "payload": ("The payload weighs 1 kg", False),
}


@pytest.mark.slow
@needs_chromium
@pytest.mark.parametrize("name", list(VERDICTS))
def test_each_report_opens_with_its_verdict_in_chromium(runs, name, tmp_path):
    """Each command's page, rendered headless: every figure decoded, the tables present,
    the verdict ending in the first screen (and a torque figure starting in it where the
    command has torques), the headline the command's answer."""
    words, torques = VERDICTS[name]
    dom = check_in_browser(runs / name / REPORT_NAME, tmp_path, verdict=True, torques=torques)
    headline = re.search(r'<p class="headline">(.*?)</p>', dom, re.S)
    assert headline is not None and words in re.sub(r"<[^>]+>", "", headline.group(1))


@pytest.mark.slow
def test_identify_on_a_log_judges_held_out_torques_against_the_sensor_noise(runs):
    """identify on a log stages heldout.json and the two figures; the sensors' noise it
    reads above the cut-off is the simulated sensor's (0.05 N m), the fit's record; the
    page's verdict sets the held-out error beside the floor the verdict line printed (the
    sensors' and the states' noise), and its tables name their columns with units."""
    out = runs / "identify-log"
    held = json.loads((out / "heldout.json").read_text())
    noise = np.array(held["sensor_noise_rms"])
    assert np.all(np.abs(noise / 0.05 - 1.0) < 0.2), noise
    for f in ("heldout_torques.png", "heldout_residuals.png"):
        assert (out / f).read_bytes().startswith(b"\x89PNG")
    page = Page((out / REPORT_NAME).read_text(encoding="utf-8"))
    text = " ".join(" ".join(page.text).split())
    recorded = _identification_doc(runs)["metadata"]["heldout"]
    floor = f"{held['noise_floor_percent']:.3g} %"  # the one the verdict line prints
    assert f"noise floor of {floor}" in text, text[:800]
    assert f"{held['verdict']['ratio']:.3g} x the floor" in text
    assert held["sensor_noise_rms"] == recorded["noise_rms"]  # the sensors': the fit's record
    headers = {h for t in page.tables for h in t[0]}
    assert {"held-out RMS error [N m]", "sensor noise RMS [N m]", "fv [N m s/rad]"} <= headers
    assert not any(h.isdigit() for h in headers)  # no "1, 2, 3" column names


def _identification_doc(runs: Path) -> dict:
    return json.loads((runs / "identify-log" / "identification.json").read_text())


@pytest.mark.slow
def test_model_structure_table_marks_the_chosen_candidate(runs, tmp_path):
    """An identification record with ``metadata.selection`` gets the model-structure table,
    the chosen candidate's row marked; one without it renders without that table."""
    doc = _identification_doc(runs)
    doc["metadata"].pop("terms", None)  # the structure held: the chosen one's (not said)
    doc["metadata"]["selection"] = {
        "rule": "lowest held-out error within one standard error",
        "validation": "5 contiguous time blocks",
        "chosen": "classical",
        "candidates": [
            {"name": "rigid", "terms": [], "n_params": 43, "train_error_percent": 2.5,
             "heldout_error_percent": 2.6, "heldout_se_percent": 0.1},
            {"name": "classical", "terms": ["fv", "fc", "fo"], "n_params": 64,
             "train_error_percent": 0.38, "heldout_error_percent": 0.40,
             "heldout_se_percent": 0.02},
            {"name": "quadratic", "terms": ["fv", "fq", "fc", "fo"], "n_params": 71,
             "train_error_percent": 0.30, "heldout_error_percent": 0.35,
             "heldout_se_percent": 0.02, "not_dissipative": ["fq3 < 0 (joint 3)"]},
            {"name": "coulomb - fo2", "terms": ["fc", "fo", "-fo2"], "n_params": 56,
             "train_error_percent": 0.39, "heldout_error_percent": 0.40,
             "heldout_se_percent": 0.02, "left_out": ["fv1", "fv2", "fo2"]},
        ],
    }  # fmt: skip
    p = tmp_path / "identification.json"
    p.write_text(json.dumps(doc))
    page_text = render_html_report(RunSummary(command="identify"), {p.name: p}, out=tmp_path)
    page = Page(page_text)
    structure = next(t for t in page.tables if "candidate" in t[0])
    assert structure[0][:2] == ["", "candidate"] and "held-out error [%]" in structure[0]
    assert structure[2][:2] == ["\u2713 chosen", "classical"] and structure[1][0] == ""
    assert structure[3][:2] == ["skipped: not dissipative", "quadratic"]
    assert structure[0][-1] == "left out per joint" and structure[4][-1] == "fv1 fv2 fo2"
    assert '<tr class="marked"><td>&#10003; chosen</td><td>classical' in page_text
    assert "Terms chosen: classical" in " ".join(" ".join(page.text).split())
    doc["metadata"]["selection"]["heldout_per_recording"] = [
        {"file": "a.csv", "heldout_error_percent": 0.41},
        {"file": "hit.csv", "heldout_error_percent": 7.5},
    ]
    doc["metadata"]["selection"]["outlying_recordings"] = ["hit.csv"]
    p.write_text(json.dumps(doc))
    page = Page(render_html_report(RunSummary(command="identify"), {p.name: p}, out=tmp_path))
    per = next(t for t in page.tables if t[0][0] == "recording")
    assert per[1][0] == "a.csv" and per[1][2] == ""
    assert per[2][0] == "hit.csv" and per[2][2].startswith("outlying")
    assert per[2][2].endswith("fitted (--keep-outlying)")  # no record of it left out
    doc["metadata"]["recordings"] = [{"file": "a.csv"}, {"file": "hit.csv", "left_out": True}]
    p.write_text(json.dumps(doc))
    page = Page(render_html_report(RunSummary(command="identify"), {p.name: p}, out=tmp_path))
    per = next(t for t in page.tables if t[0][0] == "recording")
    assert per[2][2] == "outlying: left out of the judgement and of the fit"
    del doc["metadata"]["selection"]
    p.write_text(json.dumps(doc))
    page = Page(render_html_report(RunSummary(command="identify"), {p.name: p}, out=tmp_path))
    assert not any("candidate" in t[0] for t in page.tables)
    # a structure given (--terms): its held-out error per recording, the outlying one
    # left out of the fit (no judgement of structures to leave it out of)
    doc["metadata"]["terms"] = ["viscous", "coulomb"]
    doc["metadata"]["heldout_per_recording"] = [
        {"file": "a.csv", "heldout_error_percent": 0.41},
        {"file": "hit.csv", "heldout_error_percent": 7.5},
    ]
    doc["metadata"]["outlying_recordings"] = ["hit.csv"]
    p.write_text(json.dumps(doc))
    page = Page(render_html_report(RunSummary(command="identify"), {p.name: p}, out=tmp_path))
    per = next(t for t in page.tables if t[0][0] == "recording")
    assert per[1][:2] == ["a.csv", "0.41"] and per[2][2] == "outlying: left out of the fit"
    assert "Structure given: viscous, coulomb." in " ".join(" ".join(page.text).split())


def test_figures_left_out_are_said_in_the_first_lines(tmp_path):
    """A run without matplotlib: the page says first which figures were left out and how
    to get them."""
    notes = (
        "matplotlib is not installed; skipped the figure validation_torques.png",
        "matplotlib is not installed; skipped the figure validation_rms.png",
    )
    page_text = render_html_report(RunSummary(command="validate", notes=notes), {}, out=tmp_path)
    text = " ".join(" ".join(Page(page_text).text).split())
    said = "Figures left out: validation_torques.png, validation_rms.png."
    assert said in text and "pip install matplotlib" in text
    heading = text.rindex("dynid validate:")  # the heading (the first is the <title>)
    assert 0 < text.index(said) - heading < 200  # after the heading and the run's time only


@needs_chromium
def test_an_observer_report_shows_residuals_thresholds_and_events(tmp_path):
    """The observer's files (events, thresholds, residuals) are read generically: the
    verdict counts the events, the figure and the tables are shown, the CSV is linked."""
    out = tmp_path / "observe"
    out.mkdir()
    events = {
        "schema": "x/1",
        "events": [
            {"t": 1.25, "joint": "joint4", "residual": 3.2},
            {"t": 4.5, "joint": "joint2", "residual": 5.0},
        ],
    }
    (out / "events.json").write_text(json.dumps(events))
    (out / "thresholds.json").write_text(
        json.dumps(
            {
                "joint_names": ["joint1", "joint2"],
                "threshold": [1.5, 2.0],
                "units": {"threshold": "N m"},
            }
        )
    )
    (out / "residuals.csv").write_text("t,r1,r2\n0,0,0\n")
    (out / "residuals.png").write_bytes(_png(300, 200, seed=5))
    files = {f.name: f for f in out.iterdir()}
    summary = RunSummary(command="observe", argv=("dynid", "observe"))
    save_html_report(out / REPORT_NAME, summary, files)
    page_text = (out / REPORT_NAME).read_text(encoding="utf-8")
    page = Page(page_text)
    assert "2 events detected." in " ".join(page.text)
    assert ["joint4", "1.25", "3.2"] in [r[:3] for t in page.tables for r in t] or any(
        "joint4" in r for t in page.tables for r in t
    )
    assert ["joint2", "2"] in [r for t in page.tables for r in t]
    assert "residuals.csv" in {urllib.parse.unquote(h) for h in page.links}
    check_in_browser(out / REPORT_NAME, tmp_path, verdict=True, torques=True)


@pytest.mark.slow
def test_torques_of_the_opposite_sign_make_the_verdict_unusable(runs, tmp_path):
    """A run that warned that the torques are anti-correlated with the model's gravity
    torques (a log of the other sign convention fits as well) gets 'unusable: check the
    data' with the warning in the verdict, whatever its errors (a regression: it said GOOD;
    then 'not good enough', as a model 3.9 x the noise floor)."""
    doc = _identification_doc(runs)
    p = tmp_path / "identification.json"
    p.write_text(json.dumps(doc))
    warning = "torques are anti-correlated with the model's gravity torques (correlation -0.86)"
    page_text = render_html_report(
        RunSummary(command="identify", warnings=(warning,)), {p.name: p}, out=tmp_path
    )
    assert '<section class="verdict unusable"' in page_text
    box = page_text.split('id="verdict"')[1].split("</section>")[0]
    assert "anti-correlated" in box and "unusable: check the data" in box
    good = render_html_report(RunSummary(command="identify"), {p.name: p}, out=tmp_path)
    assert '<section class="verdict unusable"' not in good


def _verdict_of(page_text: str) -> tuple[str, str]:
    """The level (class) and the text of a page's verdict box."""
    m = re.search(r'<section class="verdict (\w+)" id="verdict">(.*?)</section>', page_text, re.S)
    assert m is not None
    return m.group(1), re.sub(r"<[^>]+>", "", m.group(2))


def test_validate_is_not_good_while_a_joint_errs_by_15_percent(tmp_path):
    """validate's verdict judges the worst joint too: 3 % over the log but 15-19 % on the
    wrist joints is usable, not good (it said GOOD), and names the worst joint."""
    per = [2.0, 2.5, 3.0, 4.0, 15.0, 19.0, 17.0]
    doc = {
        "schema": "dynid-validation/1",
        "relative_error_percent": 3.0,
        "joint_names": [f"panda_joint{j}" for j in range(1, 8)],
        "n_samples": 1000,
        "without_friction": {
            "rms": [1.0] * 7,
            "relative_error_percent": 3.0,
            "relative_error_percent_per_joint": per,
        },
    }
    p = tmp_path / "validation.json"
    p.write_text(json.dumps(doc))
    level, text = _verdict_of(render_html_report(RunSummary(command="validate"), {p.name: p}))
    assert level == "fair", text
    assert "Worst joint by relative error panda_joint6" in text and "19" in text
    doc["without_friction"]["relative_error_percent_per_joint"] = [2.0] * 7
    p.write_text(json.dumps(doc))
    assert _verdict_of(render_html_report(RunSummary(command="validate"), {p.name: p}))[0] == (
        "good"
    )


def test_a_consistent_set_with_an_implausible_link_is_not_good(tmp_path):
    """identify --consistent / retrieve: a consistent set that reproduces the coefficients
    but carries an 'implausible' note (a link under 1 % of the mass) is usable with
    reservations, the note in the verdict (it said GOOD)."""
    links = [{"name": f"link{k}", "mass": m} for k, m in enumerate((5.0, 3.0, 0.01), 1)]
    feas = {"schema": "dynid-feasible/1", "feasible": True, "relative_residual": 0.001}
    note = "implausible: link3 weighs 0.01 kg, under 1 % of the total"
    rep = {"schema": "dynid-report/1", "on_bound": [], "notes": ["generic prior", note]}
    p, r = tmp_path / "feasible.json", tmp_path / "report.json"
    p.write_text(json.dumps(feas | {"links": links}))
    r.write_text(json.dumps(rep))
    files = {p.name: p, r.name: r}
    level, text = _verdict_of(render_html_report(RunSummary(command="retrieve"), files))
    assert level == "fair", text
    assert "link3 weighs 0.01 kg" in text and "implausible" in text
    r.write_text(json.dumps(rep | {"notes": ["generic prior"]}))
    assert _verdict_of(render_html_report(RunSummary(command="retrieve"), files))[0] == "good"


def test_a_fit_at_the_noise_floor_is_not_called_over_fitted(tmp_path):
    """Held-out error 1.41 x the training error, and 1.22 x the sensor-noise floor on
    unfiltered held-out torques: the fit follows some noise yet predicts as well as the
    noise allows, which is no reservation (the page said "usable ... the fit over-fits"
    beside "only noise is left"); 2.4 x the floor with the same ratio is one."""
    ident = {
        "schema": "dynid-identification/1",
        "route": "classical",
        "rank": 43,
        "metadata": {"heldout": {"training_error_percent": 1.0, "heldout_error_percent": 1.41,
                                 "scheme": "blocks", "folds": 5}},
    }  # fmt: skip
    held = {"schema": "dynid-heldout/1", "relative_error_percent": 1.22,
            "noise_floor_percent": 1.0, "block": "the last block"}  # fmt: skip
    p, h = tmp_path / "identification.json", tmp_path / "heldout.json"
    p.write_text(json.dumps(ident))
    files = {p.name: p, h.name: h}
    h.write_text(json.dumps(held))
    level, text = _verdict_of(render_html_report(RunSummary(command="identify"), files))
    assert "over-fits" not in text and "predicts to the noise floor" in text, text
    assert "ratio 1.41" in text
    h.write_text(json.dumps(held | {"relative_error_percent": 2.4}))
    level2, text2 = _verdict_of(render_html_report(RunSummary(command="identify"), files))
    assert "a check of extrapolation" in text2 and level2 == "fair", text2  # the floor's
    assert level == "good", text  # the ratio alone is no reservation at the floor


@pytest.mark.parametrize(
    "error, floor, level, label",
    [
        (0.5, 0.4, "good", "at the noise floor"),  # 1.25 x the floor
        (1.56, 0.4, "fair", "usable, with reservations"),  # 3.9 x the floor, 1.56 %
        (39.0, 0.4, "poor", "poor: improve the model"),
        (60.0, 0.4, "unusable", "unusable: check the data"),
    ],
)
def test_the_held_out_verdict_has_levels_a_person_can_act_on(tmp_path, error, floor, level, label):
    """identify's verdict grades the held-out error against the noise floor: at the floor,
    usable, poor, unusable (3.9 x the floor at 1.56 % and torques of the wrong sign were
    both 'not good enough')."""
    ident = {
        "schema": "dynid-identification/1",
        "route": "classical",
        "rank": 2,
        "base": {"rank": 2},
        "coefficients": [
            {"name": "beta1", "expression": "m1"},
            {"name": "beta2", "expression": "m2"},
        ],
        "metadata": {
            "heldout": {
                "training_error_percent": error,
                "heldout_error_percent": error,
                "scheme": "blocks",
                "folds": 5,
            }
        },
    }
    held = {
        "relative_error_percent": error,
        "noise_floor_percent": floor,
        "block": "the last block",
    }
    (tmp_path / "identification.json").write_text(json.dumps(ident))
    (tmp_path / "heldout.json").write_text(json.dumps(held))
    files = {p.name: p for p in tmp_path.glob("*.json")}
    got, text = _verdict_of(render_html_report(RunSummary(command="identify"), files))
    assert got == level, text
    assert text.strip().lower().startswith(label), text


def _identification(train: float, test: float, floor: float) -> dict:
    """An identification.json of the classical route held out over 5 time blocks: its
    training and held-out errors and noise floor [%]."""
    held = {"training_error_percent": train, "heldout_error_percent": test,
            "scheme": "blocks", "folds": 5, "noise_floor_percent": floor}  # fmt: skip
    return {
        "schema": "dynid-identification/1",
        "route": "classical",
        "rank": 2,
        "metadata": {"heldout": held},
    }


def test_a_consistent_fit_heads_its_page_with_its_own_held_out_error(tmp_path):
    """identify --consistent: the verdict's headline is the consistent fit's held-out error
    against the noise floor the command printed, least squares' the comparison (the page
    opened on the least-squares fit's error, which the user had not asked for)."""
    ident = _identification(1.0, 1.1, 0.5)
    heldout = {
        "scheme": "blocks",
        "folds": 5,
        "least_squares": {"training_error_percent": 1.0, "heldout_error_percent": 1.1},
        "consistent": {"training_error_percent": 1.2, "heldout_error_percent": 1.3},
    }
    (tmp_path / "identification.json").write_text(json.dumps(ident))
    (tmp_path / "report.json").write_text(json.dumps({"schema": "x/1", "heldout": heldout}))
    (tmp_path / "feasible.json").write_text(
        json.dumps({"schema": "x/1", "feasible": True, "links": [{"name": "l1", "mass": 1.0}]})
    )
    files = {p.name: p for p in tmp_path.glob("*.json")}
    page = render_html_report(RunSummary(command="identify"), files)
    headline = re.sub(r"<[^>]+>", "", re.search(r'class="headline">(.*?)</p>', page, re.S)[1])
    assert "consistent fit predicts held-out torques to 1.3 %" in headline, headline
    assert "least squares: 1.1 %" in headline and "2.6 times" in headline, headline
    level, text = _verdict_of(page)
    assert level == "fair"  # 2.6 x the floor: usable
    assert text.count("sensor-noise floor") == 2, text  # the headline's and its fact, once


def test_a_calibration_says_it_calibrated_thresholds_not_that_it_has_no_events(tmp_path):
    """observe --calibrate writes thresholds and residuals but no events: its badge says
    the thresholds were calibrated, on how many samples of which logs (it said "no events
    file to judge" with a reservation, as if a detection had lost its file)."""
    out = tmp_path / "cal"
    out.mkdir()
    thresholds = {
        "schema": "dynid-thresholds/1",
        "joints": ["joint1", "joint2"],
        "contact": [0.5, 0.25],
        "collision": [1.0, 0.5],
        "calibration": {"samples": 1200, "data": ["free.csv"], "model": "m.json"},
    }
    (out / "thresholds.json").write_text(json.dumps(thresholds))
    (out / "residuals.png").write_bytes(_png(300, 200, seed=6))
    files = {f.name: f for f in out.iterdir()}
    page = render_html_report(RunSummary(command="observe"), files)
    level, text = _verdict_of(page)
    assert "events file" not in text and level == "info", text
    assert text.strip().startswith("thresholds calibrated Thresholds calibrated on 1200"), text
    assert "free.csv" in text and "above 0.25 to 0.5 N m is detected while a joint moves" in text


def test_calibration_thresholds_table_names_its_rows_by_joint(tmp_path):
    """Regression: the calibration page's thresholds table numbered its rows 1..6 though
    thresholds.json lists the joints by name; events as many as the joints are still
    numbered, not named after the joints."""
    from dynid.io.observer_files import save_events, save_thresholds
    from dynid.observer.detection import Thresholds
    from dynid.observer.events import ContactEvent
    from dynid.observer.residual import ObserverOptions
    from dynid.report.json_tables import json_section

    names = ["shoulder_pan_joint", "shoulder_lift_joint", "elbow_joint"]
    th = Thresholds(
        contact=np.array([0.5, 0.25, 0.125]),
        collision=np.array([1.0, 0.5, 0.25]),
        margin=1.5,
        quantile=1.0,
        collision_factor=2.0,
        options=ObserverOptions(gain=(10.0, 20.0, 30.0)),
        samples=1200,
    )
    out = tmp_path / "cal"
    out.mkdir()
    save_thresholds(out / "thresholds.json", th, joints=names, calibration={"data": ["a.csv"]})
    page = render_html_report(
        RunSummary(command="observe"), {"thresholds.json": out / "thresholds.json"}
    )
    rows = [r for t in Page(page).tables for r in t]
    assert ["shoulder_lift_joint", "0.25", "0.5"] in [r[:3] for r in rows], rows
    assert ["elbow_joint", "30"] in rows, rows  # the observer's gains, nested
    assert not any(r[0] in ("1", "2", "3") for r in rows), rows
    events = [
        ContactEvent(float(k), k + 0.5, (k + 1,), (1.0, 2.0, 3.0), "contact") for k in range(3)
    ]
    save_events(out / "events.json", events, joints=names)
    doc = json.loads((out / "events.json").read_text())
    rows = [r for t in Page(json_section("events.json", doc)).tables for r in t]
    assert [r[0] for r in rows if r[0] in ("1", "2", "3") + tuple(names)] == ["1", "2", "3"]


def test_the_page_shows_the_noise_floor_the_command_printed(tmp_path):
    """identify's page judges the held-out error against the record's noise floor
    (``metadata.heldout``, the one the summary prints: 0.327 %), not a second estimate
    from the last block of heldout.json (0.315 %: the page and the console disagreed)."""
    ident = _identification(0.348, 0.35, 0.327)
    held = {"relative_error_percent": 0.343, "noise_floor_percent": 0.315, "block": "the last"}
    (tmp_path / "identification.json").write_text(json.dumps(ident))
    (tmp_path / "heldout.json").write_text(json.dumps(held))
    files = {p.name: p for p in tmp_path.glob("*.json")}
    level, text = _verdict_of(render_html_report(RunSummary(command="identify"), files))
    assert "floor of 0.327 %" in text and "1.07 x the floor" in text, text
    assert "0.315" not in text and level == "good", text


def test_recordings_that_differ_are_not_called_over_fitted(tmp_path):
    """Held-out 1.43 x the training error, leaving out each of two recordings, with 40
    coefficients on 35,784 rows: least squares cannot over-fit that (held-out over training
    about 1 + p/m = 1.001 on noise), the recordings differ in effects outside the model (a
    UR10 with a gravity tilt: the page said "the fit over-fits"). With 40 coefficients on
    1,000 rows the same ratio is over-fitting."""
    ho = {"training_error_percent": 0.1624, "heldout_error_percent": 0.2318,
          "scheme": "recordings", "folds": 2}  # fmt: skip
    ident = {
        "schema": "dynid-identification/1",
        "route": "classical",
        "rank": 40,
        "coefficients": [{"name": f"beta{i}"} for i in range(40)],
        "metadata": {"heldout": ho, "n_rows": 35784},
    }
    p = tmp_path / "identification.json"
    p.write_text(json.dumps(ident))
    _, text = _verdict_of(render_html_report(RunSummary(command="identify"), {p.name: p}))
    assert "over-fits" not in text and "not over-fitting, 0.0011 coefficients per row" in text
    p.write_text(json.dumps(ident | {"metadata": {"heldout": ho, "n_rows": 1000}}))
    _, text = _verdict_of(render_html_report(RunSummary(command="identify"), {p.name: p}))
    assert "the fit over-fits" in text, text


def test_the_friction_page_names_what_friction_json_holds(tmp_path):
    """Regression: the page said "Friction law chosen: stribeck ... held-out error 3.12 %,
    the lowest" while the candidate kept at 3.12 % was the model's own friction (stribeck
    scored 3.136 %), and labelled the motors' coefficients "joint 1..6". A sum at the
    motors and at the joints is named as written, its error is the own candidate's, and
    the motors' table has motor rows."""
    from dynid.friction.laws import LAWS
    from dynid.friction.model import FrictionSum
    from dynid.io.friction_json import save_friction_json
    from dynid.model.drive import Drive

    K = np.diag([100.0, 50.0])
    K[1, 0] = 20.0
    drive = Drive(transmission=K, offset=np.zeros(2))
    at_motors = LAWS["classical"].model(np.array([[1e-3, 0.05, 0.0], [1e-3, 0.02, 0.0]]))
    at_joints = LAWS["classical"].model(np.array([[0.0, 0.0, 0.0], [0.0, 0.3, 0.0]]))
    own = FrictionSum((at_motors.at(drive), at_joints))
    rows = [("stribeck", 3.136), ("classical", 3.141), ("own", 3.120)]
    selection = {
        "method": "leave one recording out (3 recordings)",
        "folds": 3,
        "rule": "the simplest within one standard error of the lowest held-out error",
        "chosen": "own",
        "candidates": [
            {"model": m, "parameters": [], "train_error_percent": e, "heldout_error_percent": e}
            for m, e in rows
        ],
    }
    p = save_friction_json(tmp_path / "friction.json", own, selection=selection)
    page = render_html_report(RunSummary(command="friction"), {p.name: p})
    text = html.unescape(_verdict_of(page)[1])
    assert "chosen: classical at the motors + classical at the joints" in text, text
    assert "the model's own friction (classical at the motors" in text and "3.12 %" in text
    assert "3.136" not in text and "the lowest of" not in text
    assert ">motor 1<" in page and ">motor 2<" in page


@pytest.mark.parametrize(
    ("said", "shown"),
    [
        ("free.csv: no velocity columns", "free.csv: no velocity columns"),
        ("hit.csv", "hit.csv"),
        ("shoulder_lift_joint moves fast", "shoulder_lift_joint moves fast"),
        ("q2 wraps", "q2 wraps"),
        ("friction is in the logs: 0.3 N m", "Friction is in the logs: 0.3 N m"),
        ("the friction is panda's own", "The friction is panda's own"),
        ("low-speed error", "Low-speed error"),
        ("", ""),
    ],
)
def test_a_note_opening_with_a_file_name_keeps_its_case(said, shown):
    """Only an ordinary opening word is capitalised: a file name or an identifier keeps
    its case (the report wrote 'Note: Free.csv'), and the rest is never changed."""
    from dynid.report.html import capitalised

    assert capitalised(said) == shown


def test_the_reports_logged_notes_name_options_by_their_flags(caplog):
    """A note the library logs names its Python option (``max_std_percent=...``); the run's
    record of it, which the report lists, says it as the command line prints it
    (``--max-std-percent``)."""
    import logging

    from dynid.cli.run_report import RunRecord
    from dynid.progress import NOTE

    log = logging.getLogger("dynid.identification.least_squares")
    caplog.set_level(NOTE, logger="dynid")  # as the command sets it
    with RunRecord() as rec:
        log.log(NOTE, "2 coefficient(s) loose; max_std_percent=... removes them")
    (said,) = [m for m in rec.lines("note: ") if "loose" in m]
    assert "--max-std-percent removes them" in said and "max_std_percent" not in said
