"""`dynid demo`: the whole paper on the simulated Panda, end to end."""

from __future__ import annotations

import base64
import json
import re
from pathlib import Path

import numpy as np
import pytest
from test_html_report import CHROMIUM, Page, check_in_browser

from dynid.cli.__main__ import main

DATA = Path(__file__).resolve().parent / "data"


@pytest.mark.slow
def test_demo_runs_every_stage_and_writes_the_report(tmp_path, capsys, monkeypatch):
    """The demo writes every stage's files, figures, paper.json and report.html, with the
    expected outcomes; the report sets dynid's numbers beside the paper's.

    The penalty retrievals (stages 4 and 5) make 2 runs of Algorithm 1, one per worker,
    instead of 10 (``make demo`` makes 10): 9 s instead of 21 s, with the same outcomes
    (seed 1: relative residuals 9e-16 and 1.2e-05 against 1e-16 and 1.2e-05 with 10 runs,
    all feasible, the limits 1e-4)."""
    import functools

    import dynid.feasibility.penalty.fit as penalty_fit
    from dynid.feasibility.penalty import RetrievalOptions

    monkeypatch.setattr(
        penalty_fit, "RetrievalOptions", functools.partial(RetrievalOptions, runs=2)
    )
    out = tmp_path / "out"
    assert main(["demo", "--out", str(out), "--seed", "1"]) == 0
    text = capsys.readouterr().out
    for stage in ("stage 1", "stage 2", "stage 3", "stage 4", "stage 5"):
        assert stage in text
    for line in ("IK converged", "rank 43", "RMS + friction", "RMS NE", "truth: the published"):
        assert line in text, line
    for rel in (
        "ik_joint_motion.png",
        "identification/identification.json",
        "identification/static.csv",
        "friction/friction.json",
        "friction/validation_torques.png",
        "friction/friction.png",
        "feasible/feasible.json",
        "feasible/robot.urdf",
        "feasible/robot.toml",
        "feasible/report.json",
        "consistent/comparison.json",
        "consistent/comparison.png",
        "consistent/feasible.json",
        "paper.json",
        "report.html",
    ):
        assert (out / rel).stat().st_size > 0, rel
    ident = json.loads((out / "identification" / "identification.json").read_text())
    assert ident["rank"] == 43 and ident["dropped_rows"] == ["g1"]
    fr = json.loads((out / "friction" / "friction.json").read_text())
    assert all(j["rms_after"] < 0.06 < j["rms_before"] for j in fr["joints"])
    rep = json.loads((out / "feasible" / "report.json").read_text())
    assert rep["feasible"] and rep["relative_residual"] < 1e-4
    # stage 5: the convex method is consistent with margin and plausible on data with model
    # error; both methods reproduce the coefficients
    cmp = {
        m["method"]: m
        for m in json.loads((out / "consistent" / "comparison.json").read_text())["methods"]
    }
    assert set(cmp) == {"sdp", "penalty", "penalty + prior"}
    sdp = cmp["sdp"]
    assert sdp["feasible"] and sdp["min_margin"]["pseudo_inertia"] >= 1e-4 * (1 - 1e-9)
    assert sdp["lightest_link_kg"] >= 0.3 and sdp["relative_residual"] < 0.05
    assert cmp["penalty"]["relative_residual"] < 1e-4
    # report.html over every stage: each stage's figures embedded, its data files linked
    page = (out / "report.html").read_text(encoding="utf-8")
    for png in sorted(out.rglob("*.png")):
        assert base64.b64encode(png.read_bytes()).decode("ascii") in page, png.name
    for rel in ("identification/static.csv", "feasible/robot.urdf", "paper.json"):
        assert f'href="{rel}"' in page, rel
    assert not (out / "report.md").exists()  # one report
    _paper_tables_match_the_reference(out, page)
    if CHROMIUM is not None:
        check_in_browser(out / "report.html", tmp_path, verdict=True, torques=False)


def _paper_tables_match_the_reference(out: Path, page: str) -> None:
    """paper.json and the page against the published Table III (tests/data, transcribed
    from the paper): the printed values and the transcription errors are the paper's,
    dynid's coefficients (identified from the published robot's noisy M, g) lie within
    3 std of the expressions evaluated at the published p_hat, and the page shows the
    43 rows with dynid's value, its std, the published value and the difference."""
    ref = json.loads((DATA / "gaz2019_coefficients.json").read_text())["coefficients"]
    paper = json.loads((out / "paper.json").read_text())
    rows = paper["table_iii"]
    assert [r["published"] for r in rows] == [c["pi_of_p_hat"] for c in ref]
    typo = json.loads((DATA / "gaz2019_coefficients.json").read_text())["transcription_errors"]
    assert [r["index"] for r in rows if r["transcription_error"]] == typo["indices"]
    truth = np.array([c["pi_of_p_hat_recomputed_from_printed_p_hat"] for c in ref])
    ours, std = np.array([r["dynid"] for r in rows]), np.array([r["dynid_std"] for r in rows])
    assert np.all(np.abs(ours - truth) <= 3 * std + 1e-6), np.abs(ours - truth) / std
    diff = [r["difference"] for r in rows if r["published"] is not None]
    printed = [r for r in rows if r["published"] is not None]
    np.testing.assert_allclose(diff, [r["dynid"] - r["published"] for r in printed], rtol=1e-12)
    p = Page(page)
    table = next(t for t in p.tables if t and "published pi(p_hat)" in t[0])
    assert len(table) == 44 and "difference (dynid - published)" in table[0]
    assert [r[0] for r in table[1:]] == [str(k) for k in range(1, 44)]
    headline = re.search(r'<p class="headline">(.*?)</p>', page, re.S).group(1)
    assert "dynid reproduces the paper" in headline
    assert len(paper["friction"]) == 21 and len(paper["links"]) == 7


def test_the_shipped_table_iii_is_the_papers():
    """pipeline.paper's Table III (expressions and printed values, what the demo's report
    compares with) against the transcription in tests/data: the same printed values and
    transcription errors, and its expressions, evaluated at the published p_hat, give the
    reference's recomputed column (6 decimals)."""
    import dynid
    from dynid.pipeline.paper import (
        TABLE_III,
        TABLE_III_TRANSCRIPTION_ERRORS,
        table_iii_matrix,
    )

    ref = json.loads((DATA / "gaz2019_coefficients.json").read_text())
    assert [p for _, p in TABLE_III] == [c["pi_of_p_hat"] for c in ref["coefficients"]]
    assert list(TABLE_III_TRANSCRIPTION_ERRORS) == ref["transcription_errors"]["indices"]
    robot = dynid.panda()
    A = table_iii_matrix(tuple(robot.param_labels))
    recomputed = [c["pi_of_p_hat_recomputed_from_printed_p_hat"] for c in ref["coefficients"]]
    np.testing.assert_allclose(A @ robot.phi.ravel(), recomputed, rtol=0, atol=0.5e-6 + 1e-12)


def test_the_demo_renders_a_stage_by_what_it_is_not_by_its_place(tmp_path, monkeypatch):
    """The renderer reads the stage's kind: a collision stage announced as number 1 is
    rendered as a collision, and every kind of stage has its rendering."""
    from typing import get_args

    import dynid.cli.demo as demo
    from dynid.cli.console import Console
    from dynid.pipeline import Stage, StageFinished, StageKind

    assert set(demo._RENDER) == set(get_args(StageKind))
    shown = []
    monkeypatch.setattr(demo, "format_collision_stage", lambda res: f"collision of {res}")
    render = demo._Renderer(tmp_path, None, Console("demo"))
    render.console.print = shown.append  # type: ignore[method-assign]
    render(StageFinished(Stage("collision", 1, "first"), "result"))
    assert shown == ["collision of result"] and render.files == []
