"""Time stamps in a report read to the millisecond.

A log stamped on the epoch's clock (ns since 1970, read as s) gave an events table of
``1.765e+09`` for both the start and the end of a 184 ms collision, and a recordings table
of ``1.765e+09`` for each recording's start. The references are the stamps written into
the files here.
"""

from __future__ import annotations

import html
import json
import re

import numpy as np

from dynid.report.json_tables import json_section
from dynid.report.observe import answer
from dynid.report.run import RunFiles, RunSummary

#: The first stamp of the log on the epoch's clock [s].
T0 = 1765040500.0


def _text(page: str) -> str:
    """The page's text, tags dropped, cells separated by ``|``."""
    return html.unescape(re.sub(r"\s*\|[\s|]*", " | ", re.sub(r"<[^>]+>", "|", page)))


def _residuals(path, t):
    """A residual table as observe writes it, its stamps ``t`` [s]."""
    rows = "\n".join(f"{float(x)!r},0,0" for x in t)
    path.write_text(
        f"# dynid residuals; units: t [s], r [N m]\n# rows: {len(t)}\nt,r1,r2\n{rows}\n"
    )
    return path


def test_event_times_on_the_epoch_clock_read_to_the_millisecond_from_the_log_start(tmp_path):
    """An event at 3.003-3.187 s into a log stamped from 1765040500 s reads 3.003 and
    3.187 s with 184 ms and its start 1765040503.003 on the log's clock; the log's clock
    is said once; a second log stamped from 0 keeps its stamps; no 4-digit stamp."""
    rng = np.random.default_rng(7)
    t = T0 + np.arange(6000) * 1e-3 + rng.normal(0.0, 4e-5, 6000).clip(-4e-4, 4e-4)
    t[0] = T0
    events = [
        {"start": T0 + 3.003, "end": T0 + 3.187, "joints": [2], "joint_names": ["j2"],
         "peak": [0.1, 26.2], "level": "collision", "log": "hit.csv"},
        {"start": 12.3456, "end": 12.4001, "joints": [1], "joint_names": ["j1"],
         "peak": [4.0, 0.2], "level": "contact", "log": "free.csv"},
    ]  # fmt: skip
    doc = {"schema": "dynid-events/1", "joints": ["j1", "j2"], "events": events,
           "data": ["hit.csv", "free.csv"], "units": {"start": "s", "end": "s"}}  # fmt: skip
    files = {
        "events.json": tmp_path / "events.json",
        "residuals_hit.csv": _residuals(tmp_path / "residuals_hit.csv", t),
        "residuals_free.csv": _residuals(
            tmp_path / "residuals_free.csv", np.arange(0.0, 20.0, 1e-3)
        ),
    }
    files["events.json"].write_text(json.dumps(doc))
    got = answer(RunFiles(RunSummary("observe"), files, {"events.json": doc}))
    assert got is not None
    text = _text("".join(got.sections))
    assert "hit.csv: t = 1765040500.000 s" in text
    assert "| hit.csv | collision | j2 | 3.003 | 3.187 | 184 | 1765040503.003 |" in text
    assert "| free.csv | contact | j1 | 12.346 | 12.400 | 55 | [4, 0.2] |" in text
    assert "e+09" not in text


def test_recordings_start_stamps_read_to_the_millisecond():
    """identification.json's recordings: a start of 1765040200.0 s reads 1765040200.000,
    a gap's length beside it keeps its four digits."""
    recs = [{"file": "rec3.csv", "duration_s": 5.550001, "start_s": 1765040200.0},
            {"file": "rec1.csv", "duration_s": 5.639995, "start_s": 86412.3004}]  # fmt: skip
    text = _text(json_section("identification.json", {"recordings": recs}))
    assert "| rec3.csv | 5.55 | 1765040200.000 |" in text
    assert "| rec1.csv | 5.64 | 86412.300 |" in text
