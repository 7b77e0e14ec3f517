"""`dynid demo`: the whole paper on the simulated Panda, end to end."""

from __future__ import annotations

import base64
import json

import pytest

from dynid.cli.__main__ import main


@pytest.mark.slow
def test_demo_runs_every_stage_and_writes_the_report(tmp_path, capsys):
    """The demo writes every stage's files, figures, report.md and report.html, with the
    expected outcomes."""
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
        "report.md",
    ):
        assert (out / rel).stat().st_size > 0, rel
    ident = json.loads((out / "identification" / "identification.json").read_text())
    assert ident["rank"] == 43 and ident["dropped_rows"] == ["g1"]
    fr = json.loads((out / "friction" / "friction.json").read_text())
    assert all(j["rms_after"] < 0.06 < j["rms_before"] for j in fr["joints"])
    rep = json.loads((out / "feasible" / "report.json").read_text())
    assert rep["feasible"] and rep["relative_residual"] < 1e-4
    md = (out / "report.md").read_text()
    assert "## 4. Feasible link parameters" in md and "](friction/friction.png)" in md
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
    assert "## 5. Physically consistent parameters" in md
    # report.html over every stage: each stage's figures embedded, its data files linked
    page = (out / "report.html").read_text(encoding="utf-8")
    for png in sorted(out.rglob("*.png")):
        assert base64.b64encode(png.read_bytes()).decode("ascii") in page, png.name
    for rel in ("identification/static.csv", "feasible/robot.urdf", "report.md"):
        assert f'href="{rel}"' in page, rel
