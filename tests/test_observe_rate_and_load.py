"""What a detection says of logs unlike its calibration's, against simulated truth.

* thresholds.json records the calibration logs' sample rate (the simulation's --rate)
  and their velocities' kind; a detection on a log sampled at another rate, or whose
  velocities are derived from its positions where the calibration's were measured, warns
  in one line (thresholds calibrated at 1 kHz used on a 100 Hz log were silently too
  low), an older file without them reads as before and says nothing;
* a load at the flange that the model lacks (simulated on the arm carrying it) is said
  once with its mass, held through the whole log (it was read as a pick from 1.13 s),
  and nothing is said of the arm without it;
* the report's events table leaves out the column of the log's clock when every log
  starts at 0; the residual figure draws a short event wider than a hairline and names
  the events' shading in its legend.
"""

from __future__ import annotations

import dataclasses
import json
import warnings

import numpy as np
import pytest

import dynid
from dynid.cli.__main__ import main
from dynid.io.observer_files import save_thresholds
from dynid.io.robot.toml import save_toml
from dynid.observer.unmodelled_load import LOAD_FRAME
from dynid.workflows.observe import ObserveOptions, observe_files

#: The load carried by the arm of the loaded log [kg], its CoM in the flange's axes [m].
MASS, COM = 0.1, (0.0, 0.0, 0.05)


@pytest.fixture(scope="module")
def logs(tmp_path_factory):
    """Panda logs of 4 s: free at 1 kHz (calibrated) and at 250 Hz; one contact on the
    arm as described and on the arm carrying a 0.1 kg load at its flange."""
    d = tmp_path_factory.mktemp("rate_load")
    sim = ["simulate", "--trajectory", "fourier", "-q", "--duration", "4"]
    assert main([*sim, "--seed", "2", "--out", str(d / "free.csv")]) == 0
    assert main([*sim, "--seed", "4", "--rate", "250", "--out", str(d / "free250.csv")]) == 0
    hit = ["--contact", "link6:0,0,-15:1.5,1.8"]
    assert main([*sim, "--seed", "3", *hit, "--out", str(d / "hit.csv")]) == 0
    loaded = dynid.panda().with_tool(
        np.eye(4), mass=MASS, com=COM, inertia=np.diag([1e-4] * 3), parent=LOAD_FRAME
    )
    save_toml(d / "loaded.toml", loaded)
    robot = ["--robot", str(d / "loaded.toml")]
    assert main([*sim, *robot, "--seed", "3", *hit, "--out", str(d / "loaded.csv")]) == 0
    cal = ["observe", "--params", "panda", "--no-figures", "-q", "--calibrate"]
    assert main([*cal, "--data", str(d / "free.csv"), "--out", str(d / "cal")]) == 0
    return d


def _detect(d, name, thresholds=None):
    """The observation of log ``name`` and the warnings said."""
    opts = ObserveOptions(
        data=(d / name,), params="panda", thresholds=thresholds or d / "cal" / "thresholds.json"
    )
    with warnings.catch_warnings(record=True) as said:
        warnings.simplefilter("always")
        result = observe_files(opts)
    return result, [str(w.message) for w in said]


def test_thresholds_record_their_rate_and_a_log_at_another_rate_is_warned(logs):
    d = logs
    doc = json.loads((d / "cal" / "thresholds.json").read_text())
    assert doc["calibration"]["sample_rate_hz"] == pytest.approx(1000.0, rel=1e-9)
    _, said = _detect(d, "free250.csv")
    rate = [s for s in said if "calibrated at" in s]
    assert len(rate) == 1 and "\n" not in rate[0]
    assert "free250.csv: sampled at 250 Hz" in rate[0] and "calibrated at 1000 Hz" in rate[0]
    assert "calibrate at this rate" in rate[0]
    _, said = _detect(d, "hit.csv")  # the calibration's rate: nothing said
    assert not [s for s in said if "calibrated at" in s]
    assert doc["calibration"]["velocities"] == "measured"
    lines = [x for x in (d / "hit.csv").read_text().splitlines() if not x.startswith("#")]
    keep = [i for i, h in enumerate(lines[0].split(",")) if not h.startswith("dq")]
    rows = (",".join(x.split(",")[i] for i in keep) for x in lines)
    (d / "derived.csv").write_text("\n".join(rows) + "\n")  # no velocity column
    _, said = _detect(d, "derived.csv")
    kind = [s for s in said if "calibrated on measured" in s]
    assert len(kind) == 1 and kind[0].startswith("derived.csv: velocities derived")
    del doc["calibration"]["sample_rate_hz"]  # a file of an earlier version
    del doc["calibration"]["velocities"]
    (d / "old.json").write_text(json.dumps(doc))
    for name in ("free250.csv", "derived.csv"):
        result, said = _detect(d, name, d / "old.json")
        assert result.thresholds.sample_rate_hz is None and result.thresholds.velocities is None
        assert not [s for s in said if "calibrated" in s], name


def test_a_load_the_model_lacks_is_said_with_its_mass_and_none_without_it(logs):
    d = logs
    result, _ = _detect(d, "loaded.csv")
    assert result.load is not None and result.load.seen
    assert result.load.mass == pytest.approx(MASS, rel=0.15)
    (log,) = result.logs  # held from start to end: one load, never a pick (it was one)
    assert [ld.whole for ld in log.loads] == [True] and log.loads[0].mass == pytest.approx(
        MASS, rel=0.15
    )
    assert not [e for e in log.events if e.level == "load"]
    note = [n for n in result.notes if "weight of a load" in n or "held through the whole" in n]
    assert len(note) == 1 and "dynid payload" in note[0]  # said once
    assert "robot_with_payload.toml" in note[0]  # a robot: payload's file
    for name in ("hit.csv", "free.csv"):
        result, _ = _detect(d, name)
        assert result.load is not None and not result.load.seen, name
        assert abs(result.load.mass) < 0.1 * MASS
        assert not [n for n in result.notes if "weight of" in n], name


def test_the_events_table_has_no_empty_clock_column(tmp_path):
    """Logs stamped from 0: the column of the log's clock would repeat nothing; the
    event's times read as written."""
    import html
    import re

    from dynid.report.observe import answer
    from dynid.report.run import RunFiles, RunSummary

    ev = {"start": 48.03, "end": 48.04, "joints": [1], "joint_names": ["j1"],
          "peak": [1.93], "level": "contact", "log": "hit.csv"}  # fmt: skip
    doc = {"schema": "dynid-events/1", "joints": ["j1"], "events": [ev], "data": ["hit.csv"]}
    t = np.arange(0.0, 58.0, 0.01)
    rows = "\n".join(f"{x!r},0" for x in t)
    table = tmp_path / "residuals.csv"
    table.write_text(f"# dynid residuals; units: t [s], r [N m]\n# rows: {t.size}\nt,r1\n{rows}\n")
    (tmp_path / "events.json").write_text(json.dumps(doc))
    files = {"events.json": tmp_path / "events.json", "residuals.csv": table}
    got = answer(RunFiles(RunSummary("observe"), files, {"events.json": doc}))
    assert got is not None
    page = "".join(got.sections)
    text = html.unescape(re.sub(r"\s*\|[\s|]*", " | ", re.sub(r"<[^>]+>", "|", page)))
    assert "log's clock" not in text
    assert "| hit.csv | contact | j1 | 48.030 | 48.040 | 10 | [1.93] |" in text


def test_a_short_event_is_drawn_wider_than_a_hairline_and_named_in_the_legend():
    """A 50 ms collision over a 58 s log: its shading spans MIN_SHADE of the log at the
    least, about the event's middle; the legend names the collision events' shading."""
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt
    from matplotlib.patches import Rectangle

    from dynid.observer.events import ContactEvent
    from dynid.plots.observer import MIN_SHADE, plot_residuals

    t = np.arange(0.0, 58.0, 0.01)
    r = np.zeros((t.size, 1))
    c = np.full((t.size, 1), 1.0)
    ev = ContactEvent(30.0, 30.05, (1,), (3.0,), "collision")
    fig = plot_residuals(t, r, c, 2 * c, events=[ev])
    spans = []
    for p in fig.axes[0].patches:
        if isinstance(p, Rectangle):
            spans.append((p.get_x(), p.get_x() + p.get_width()))
        else:  # an axvspan as a polygon (matplotlib >= 3.9)
            x = p.get_xy()[:, 0]
            spans.append((float(x.min()), float(x.max())))
    ((a, b),) = spans
    assert b - a == pytest.approx(MIN_SHADE * t[-1]) and (a + b) / 2 == pytest.approx(30.025)
    labels = [x.get_text() for x in fig.legends[0].get_texts()]
    assert "collision event" in labels and "contact event" not in labels
    plt.close(fig)


def _positions_only(src, dst) -> None:
    """``src``'s log with its velocity columns left out (as a positions-only log)."""
    lines = [x for x in src.read_text().splitlines() if not x.startswith("#")]
    keep = [i for i, h in enumerate(lines[0].split(",")) if not h.startswith("dq")]
    dst.write_text("\n".join(",".join(x.split(",")[i] for i in keep) for x in lines) + "\n")


def test_calibrating_on_both_kinds_of_velocities_warns_and_detection_says_mixed(logs):
    """Regression (an iiwa trial): calibrating on logs with measured velocities and one of
    positions only recorded "velocities: mixed" in silence, and a positions-only log
    detected with those thresholds (2-3.5x wider than its own kind's) said nothing. The
    same motion with its velocities measured (the simulation's noise on them) and derived
    (low-passed): the calibration names each log's kind and the measured ones as the
    noisier, and a detection on either kind warns that the thresholds are mixed."""
    d = logs
    _positions_only(d / "free.csv", d / "free_q.csv")
    _positions_only(d / "hit.csv", d / "hit_q.csv")
    opts = ObserveOptions(
        data=(d / "free.csv", d / "free_q.csv"), params="panda", calibrate=True, keep_series=False
    )
    with warnings.catch_warnings(record=True) as said:
        warnings.simplefilter("always")
        result = observe_files(opts)
    assert result.thresholds.velocities == "mixed"
    mixed = [str(w.message) for w in said if "one set of thresholds for both" in str(w.message)]
    assert len(mixed) == 1 and "\n" not in mixed[0]
    assert mixed[0].startswith(
        "velocities measured in free.csv and derived from the positions in free_q.csv"
    )
    assert "here the measured ones" in mixed[0] and "calibrate per kind" in mixed[0]
    # the cost said: the mixed thresholds over those of the derived log alone, no warning
    alone = dataclasses.replace(opts, data=(d / "free_q.csv",))
    with warnings.catch_warnings(record=True) as said:
        warnings.simplefilter("always")
        own = observe_files(alone).thresholds
    assert own.velocities == "derived"
    assert not [w for w in said if "one set of thresholds for both" in str(w.message)]
    ratio = result.thresholds.contact / own.contact
    j = int(np.argmax(ratio))
    assert ratio[j] > 1.2 and f"up to {ratio[j]:.3g} x" in mixed[0]
    assert f"{dynid.panda().joint_names[j]} " in mixed[0]
    path = d / "mixed.json"
    save_thresholds(path, result.thresholds, joints=dynid.panda().joint_names)
    for name, kind, other in (
        ("hit_q.csv", "derived", "measured"),
        ("hit.csv", "measured", "derived"),
    ):
        _, said = _detect(d, name, path)
        kinds = [s for s in said if "calibrated on logs of both kinds" in s]
        assert len(kinds) == 1 and kinds[0].startswith(f"{name}: velocities {kind}"), name
        assert f"set partly on {other} velocities" in kinds[0]
