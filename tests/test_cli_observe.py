"""dynid observe end to end: calibrate on a collision-free log, detect simulated contacts
(dynid simulate --contact), with an identified model and with a consistent robot."""

from __future__ import annotations

import json

import numpy as np
import pytest

from dynid.cli.__main__ import main
from dynid.io.observer_files import load_thresholds


@pytest.fixture(scope="module")
def logs(tmp_path_factory):
    """A model identified from a 12 s log, a free log and a log with two contacts."""
    d = tmp_path_factory.mktemp("observe")
    sim = ["simulate", "--robot", "panda", "--trajectory", "fourier", "-q"]
    assert main([*sim, "--duration", "12", "--seed", "1", "--out", str(d / "ident.csv")]) == 0
    assert (
        main(
            [
                "identify",
                "--robot",
                "panda",
                "--data",
                str(d / "ident.csv"),
                "--out",
                str(d / "id"),
                "-q",
            ]
        )
        == 0
    )
    assert main([*sim, "--duration", "6", "--seed", "2", "--out", str(d / "free.csv")]) == 0
    hit = [
        "--contact", "link6:0,0,-15:2,2.5", "--contact", "flange:10,0,0,0,0,1:4,4.3",
    ]  # fmt: skip
    assert main([*sim, "--duration", "6", "--seed", "3", *hit, "--out", str(d / "hit.csv")]) == 0
    return d


def test_observe_calibrates_then_finds_both_simulated_contacts(logs, capsys):
    """thresholds.json from the free log (with the model's uncertainty), then events.json
    (dynid-events/1) with the two contacts at their times, residuals.csv with the wrench at
    the flange, residuals.png, report.html."""
    d = logs
    model = ["--model", str(d / "id" / "identification.json")]
    assert (
        main(
            [
                "observe",
                *model,
                "--data",
                str(d / "free.csv"),
                "--calibrate",
                "--out",
                str(d / "cal"),
            ]
        )
        == 0
    )
    th = load_thresholds(d / "cal" / "thresholds.json")
    assert th.uses_uncertainty and th.n == 7 and np.all(th.collision == 2 * th.contact)
    out = d / "obs"
    args = ["--thresholds", str(d / "cal" / "thresholds.json"), "--frame", "flange"]
    assert main(["observe", *model, *args, "--data", str(d / "hit.csv"), "--out", str(out)]) == 0
    doc = json.loads((out / "events.json").read_text())
    assert doc["schema"] == "dynid-events/1"
    starts = [e["start"] for e in doc["events"]]
    assert len(starts) == 2 and 2.0 <= starts[0] < 2.1 and 4.0 <= starts[1] < 4.1
    for e in doc["events"]:
        assert len(e["peak"]) == 7 and e["level"] in ("contact", "collision")
        assert set(e["joints"]) <= set(range(1, 8)) and e["end"] >= e["start"]
    lines = (out / "residuals.csv").read_text().splitlines()
    assert lines[2].startswith("t,r1,") and lines[2].endswith("fx,fy,fz,mx,my,mz,damped")
    table = np.loadtxt(out / "residuals.csv", delimiter=",", comments="#", skiprows=3)
    during = (table[:, 0] > 4.2) & (table[:, 0] < 4.3)
    assert np.median(table[during, 8]) == pytest.approx(10.0, abs=1.0)  # fx of the push
    assert (out / "residuals.png").stat().st_size > 10_000
    assert "residuals.png" in (out / "report.html").read_text()
    assert "2 event(s)" in capsys.readouterr().out


def test_observe_with_a_consistent_robot_raises_no_event_on_a_free_log(logs):
    """--params panda (the robot's own parameters and friction): thresholds from one free
    log, no event on the same motion's log with other noise."""
    d = logs
    sim = ["simulate", "--robot", "panda", "--trajectory", "fourier", "-q", "--duration", "6"]
    assert main([*sim, "--seed", "2", "--noise", "0.06", "--out", str(d / "free2.csv")]) == 0
    p = ["observe", "--params", "panda", "-q"]
    assert main([*p, "--data", str(d / "free.csv"), "--calibrate", "--out", str(d / "calp")]) == 0
    assert load_thresholds(d / "calp" / "thresholds.json").k_sigma is None
    th = ["--thresholds", str(d / "calp" / "thresholds.json")]
    assert main([*p, *th, "--data", str(d / "free2.csv"), "--out", str(d / "obsp")]) == 0
    assert json.loads((d / "obsp" / "events.json").read_text())["events"] == []


def test_observe_refuses_thresholds_of_another_joint_count(logs, capsys):
    """Thresholds of 7 joints with a 7-joint model pass; edited to 6 joints they are refused
    with a message naming the file."""
    d = logs
    doc = json.loads((d / "cal" / "thresholds.json").read_text())
    for k in ("contact", "collision"):
        doc[k] = doc[k][:6]
    doc["observer"]["gain"] = doc["observer"]["gain"][:6]
    doc["uncertainty"]["noise"] = doc["uncertainty"]["noise"][:6]
    (d / "six.json").write_text(json.dumps(doc))
    args = ["observe", "--params", "panda", "--thresholds", str(d / "six.json")]
    assert main([*args, "--data", str(d / "hit.csv"), "--out", str(d / "bad")]) == 2
    assert "thresholds for 6 joints" in capsys.readouterr().err
