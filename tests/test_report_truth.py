"""The HTML report of a run says what the run did: the options as given, each recording a
folder stood for, the structure a consistent fit used, and a figure whose legend names only
what it draws.

References: the recordings themselves (their rows counted with the csv module), the
command line, the identification record's structure, and the bars matplotlib drew.
"""

from __future__ import annotations

import csv
import json
from types import SimpleNamespace

import numpy as np
import pytest
from test_html_report import Page, _verdict_of
from test_input_noise import FC, FV, _quantized_log

import dynid
from dynid.cli.__main__ import main
from dynid.friction.model import ClassicalFriction
from dynid.report import RunSummary, render_html_report


def _rows(path) -> int:
    with open(path, newline="") as fh:
        lines = [r for r in csv.reader(fh) if r and not r[0].startswith("#")]
    return len(lines) - 1  # the header


def _table(page: Page, *head: str) -> list[list[str]]:
    return next(t for t in page.tables if t and t[0][: len(head)] == list(head))


def test_a_data_folder_lists_each_recording_and_options_show_plain_paths(tmp_path):
    logs = tmp_path / "logs"
    logs.mkdir()
    sim = ["simulate", "--trajectory", "sinusoid", "--duration", "1.5", "--rate", "200", "-q"]
    for seed in (1, 2):
        assert main([*sim, "--seed", str(seed), "--out", str(logs / f"r{seed}.csv")]) == 0
    out = tmp_path / "run"
    argv = ["identify", "--data", f"{logs}/", "--terms", "viscous,coulomb", "--no-figures"]
    assert main([*argv, "--out", str(out), "-q"]) == 0
    page = Page((out / "report.html").read_text())
    inputs = _table(page, "option", "input file")
    assert inputs[0][2:5] == ["rows in the file", "pieces", "samples used"]
    listed = {r[1]: r for r in inputs[1:]}
    recs = json.loads((out / "identification.json").read_text())["metadata"]["recordings"]
    assert sorted(listed) == [str(logs / "r1.csv"), str(logs / "r2.csv")]
    for rec in recs:
        row = listed[str(logs / rec["file"])]
        assert row[0] == "--data" and int(row[2]) == _rows(logs / rec["file"]) == 301
        assert int(row[3]) == rec["pieces"] == 1 and int(row[4]) == rec["samples"]
    options = dict(_table(page, "option", "value")[1:])
    assert options["--data"] == str(logs) and "PosixPath" not in " ".join(page.text)
    assert options["--out"] == str(out)


def test_the_terms_and_the_consistent_fit_name_the_same_structure(tmp_path):
    """The model holds (and the consistent fit uses) ``metadata.terms``; a record whose
    selection named another structure says both, and the consistent part names the one
    used and the law feasible.json holds."""
    ident = {
        "schema": "dynid-identified-model/1",
        "route": "classical",
        "coefficients": [],
        "terms": [
            {
                "name": "friction",
                "kind": "linear_friction",
                "labels": ["fv1", "fc1"],
                "values": [0.5, 0.8],
                "std": [0.01, 0.01],
                "definition": {"parts": ["viscous", "smooth"], "at": "joint"},
            },
        ],  # fmt: skip
        "metadata": {
            "terms": ["viscous", "coulomb", "-fc5"],
            "selection": {
                "rule": "lowest held-out error",
                "chosen": "links + viscous + coulomb",
                "candidates": [{"name": "links + viscous + coulomb", "terms": ["viscous"]}],
                "heldout_per_recording": [{"file": "a.csv", "heldout_error_percent": 0.1}],
            },
        },
    }
    smooth = {"model": "smooth", "fv": [1.0], "fc": [1.0], "fo": [0.0]}
    feas = {"links": [{"name": "l1", "mass": 1.0}], "feasible": True, "linear_friction": smooth}
    (tmp_path / "identification.json").write_text(json.dumps(ident))
    (tmp_path / "feasible.json").write_text(json.dumps(feas))
    files = {p.name: p for p in tmp_path.iterdir()}
    text = " ".join("".join(Page(render_html_report(RunSummary("identify"), files)).text).split())
    used = "links + viscous + coulomb - fc5"
    assert f"Terms used: {used}" in text
    assert "chosen on held-out data was links + viscous + coulomb" in text
    said = f"Structure of the consistent fit: {used}; friction identified with the links: "
    assert said + "smooth law at the joints" in text
    assert "Friction at the joints: viscous + smooth (value \u00b1 std)" in text
    page = Page(render_html_report(RunSummary("identify"), files))
    assert _table(page, "recording") == [["recording", "held-out error [%]"], ["a.csv", "0.1"]]
    ident["metadata"]["selection"]["chosen"] = used
    (tmp_path / "identification.json").write_text(json.dumps(ident))
    text = " ".join("".join(Page(render_html_report(RunSummary("identify"), files)).text).split())
    assert f"Terms chosen: {used}" in text and "Terms used" not in text


@pytest.mark.parametrize("margins", [[0.01, -0.002, 0.003], [0.01, 0.002, 0.003]])
def test_the_comparison_figure_draws_what_its_legend_says(margins):
    """A link whose pseudo-inertia margin is not positive is a red bar a reader can see
    (over the log axis' height), named in the legend and the title; without one, neither
    speaks of red."""
    pytest.importorskip("matplotlib")
    import matplotlib

    matplotlib.use("Agg")
    from matplotlib.colors import to_rgb

    from dynid.plots.feasible import plot_consistent

    robot = dynid.panda()
    res = [
        SimpleNamespace(robot=robot, pseudo_inertia_margin=np.array(margins + [0.01] * 4)),
        SimpleNamespace(robot=robot, pseudo_inertia_margin=np.full(7, 0.02)),
    ]
    fig = plot_consistent(res, labels=["penalty", "sdp"])
    ax = fig.axes[1]
    red = [p for p in ax.patches if np.allclose(to_rgb(p.get_facecolor()), to_rgb("tab:red"))]
    legend = [t.get_text() for t in ax.get_legend().get_texts()]
    bad = int(np.sum(np.array(margins) <= 0))
    assert len(red) == bad
    lo, hi = ax.get_ylim()
    for p in red:  # visible: from the bottom of the axis to its top
        assert p.get_y() <= lo * 1.01 and p.get_y() + p.get_height() >= hi * 0.99
    named = any("not physically consistent" in t for t in legend)
    assert named == bool(bad) and ("red" in ax.get_title()) == bool(bad)
    import matplotlib.pyplot as plt

    plt.close(fig)


def test_the_headline_and_its_fact_give_the_same_ratio_to_the_noise_floor(tmp_path):
    """The held-out error over the noise floor, 897355.81: one number in the headline and
    in the fact behind it (897355.8 and 897355.81 before)."""
    err, floor = 0.2123, 0.2123 / 897355.81
    ident = {
        "route": "classical",
        "coefficients": [],
        "metadata": {"heldout": {"training_error_percent": 0.05, "heldout_error_percent": 0.15}},
    }
    held = {"relative_error_percent": err, "noise_floor_percent": floor, "block": "b.csv"}
    (tmp_path / "identification.json").write_text(json.dumps(ident))
    (tmp_path / "heldout.json").write_text(json.dumps(held))
    files = {p.name: p for p in tmp_path.iterdir()}
    text = " ".join("".join(Page(render_html_report(RunSummary("identify"), files)).text).split())
    said = f"{err / floor:.3g}"
    assert f"{said} times the sensor-noise floor" in text and f"{said} x the floor" in text


def test_the_held_out_fact_agrees_with_an_unusable_badge(tmp_path):
    """Regression: a run whose torques contradict the robot (a warning: anti-correlated)
    is unusable whatever its errors; the held-out fact under that badge said "poor" (124 x
    the floor). It says unusable, and without the warning it keeps its own level."""
    ident = {
        "route": "classical",
        "coefficients": [],
        "metadata": {"heldout": {"training_error_percent": 26.2, "heldout_error_percent": 29.2}},
    }
    held = {"relative_error_percent": 31.0, "noise_floor_percent": 0.25, "block": "b.csv"}
    (tmp_path / "identification.json").write_text(json.dumps(ident))
    (tmp_path / "heldout.json").write_text(json.dumps(held))
    files = {p.name: p for p in tmp_path.iterdir()}
    warning = "the measured torques of j2 are anti-correlated with the model's gravity torques"
    for warnings, level in (((warning,), "unusable"), ((), "poor")):
        summary = RunSummary("identify", warnings=warnings)
        text = " ".join("".join(Page(render_html_report(summary, files)).text).split())
        box = text.split("Held-out error")[1].split("Sensor")[0]
        fact = box.split("x the floor):")[1][:40]
        assert fact.strip().startswith(level), fact
        assert ("poor" in box) == (level == "poor"), box


def test_torques_a_hundred_times_off_the_gravity_torques_make_the_report_unusable(tmp_path):
    """Regression: currents read through a torque constant 100 times too small fit as well
    as the right ones (the relative error cannot see a scale), and the report showed a
    green "at the noise floor" with the scale warning folded away; the masses are 100
    times off. The scale warning now makes it unusable, the warning shown."""
    ident = {
        "route": "classical",
        "coefficients": [],
        "metadata": {"heldout": {"training_error_percent": 1.0, "heldout_error_percent": 1.05,
                                 "noise_floor_percent": 0.95}},
    }  # fmt: skip
    (tmp_path / "identification.json").write_text(json.dumps(ident))
    files = {p.name: p for p in tmp_path.iterdir()}
    warning = (
        "the measured torques (the currents times the drive's torque constants and gear "
        "ratios) are 0.0104 times the model's gravity torques: the drive file's "
        "torque_constant or gear_ratio looks off by that factor"
    )
    for warnings, level in (((warning,), "unusable"), ((), "at the noise floor")):
        summary = RunSummary("identify", warnings=warnings)
        text = " ".join("".join(Page(render_html_report(summary, files)).text).split())
        fact = text.split("x the floor):")[1][:40]
        assert fact.strip().startswith(level), fact
        assert ("The data contradict the robot" in text) == bool(warnings)


def test_the_low_speed_note_of_the_held_out_prediction_is_on_the_first_screen(tmp_path):
    """Regression: the held-out prediction's note that its error sits at low speed was in
    the console's verdict line and heldout.json, but the report's first screen said only
    "usable: effects outside the model remain"; it now holds the note as a fact."""
    ident = {
        "route": "classical",
        "coefficients": [],
        "metadata": {"heldout": {"training_error_percent": 3.0, "heldout_error_percent": 3.1,
                                 "noise_floor_percent": 0.44}},
    }  # fmt: skip
    note = "at low speed: 99 % of the error above the noise sits where |dq| is under 5 %"
    held = {"relative_error_percent": 3.5, "noise_floor_percent": 0.5, "block": "p3.csv",
            "low_speed": note}  # fmt: skip
    (tmp_path / "identification.json").write_text(json.dumps(ident))
    (tmp_path / "heldout.json").write_text(json.dumps(held))
    files = {p.name: p for p in tmp_path.iterdir()}
    text = " ".join("".join(Page(render_html_report(RunSummary("identify"), files)).text).split())
    box = text.split("Held-out error")[1].split("Torques on held-out data")[0]
    assert "At low speed: 99 % of the error above the noise" in box, box


def test_the_demo_counts_the_coefficients_the_paper_prints(tmp_path):
    """Regression: the demo's first screen said "37 of 37 printed coefficients agree"
    where the paper prints 41 of Table III's 43, 4 of them with a transcription error:
    the count compared and the count printed are now said apart."""
    rows = [
        {"index": k + 1, "expression": f"c{k}", "dynid": 0.1, "dynid_std": 1e-5,
         "published": 0.1, "difference": 1e-5}
        for k in range(43)
    ]  # fmt: skip
    for k in (5, 6):
        rows[k].update(published=None, difference=None)
    for k in (10, 11, 12, 13):
        rows[k].update(difference=0.5, transcription_error=True)
    (tmp_path / "paper.json").write_text(json.dumps({"table_iii": rows}))
    files = {p.name: p for p in tmp_path.iterdir()}
    text = " ".join("".join(Page(render_html_report(RunSummary("demo"), files)).text).split())
    assert "Table III: 37 of the 37 coefficients compared agree" in text, text[:2000]
    assert "the paper prints 41 of the 43, 4 of them with a transcription error" in text


def test_the_page_shows_the_held_out_verdict_the_command_printed(tmp_path, capsys):
    """Regression: identify's held-out verdict counts the held-out states' noise (a
    quantized positions-only log: at the noise floor), while the page judged the record's
    held-out error against the sensors' noise alone (usable, several times the floor): the
    page's level, ratio and floor are the printed line's."""
    panda = dynid.panda()
    fr = ClassicalFriction(FV, 0.2 * FC, np.zeros(7))
    train = _quantized_log(panda, fr, 8, tmp_path / "t.csv", 60.0)
    held = _quantized_log(panda, fr, 7, tmp_path / "h.csv")
    out = tmp_path / "run"
    argv = ["identify", "--data", str(train), "--validate-on", str(held), "--no-figures"]
    assert main([*argv, "--terms", "viscous,coulomb", "--out", str(out)]) == 0
    line = next(x for x in capsys.readouterr().out.splitlines() if x.startswith("held-out verdict"))
    doc = json.loads((out / "heldout.json").read_text())
    v = doc["verdict"]
    assert f": {v['label']}: " in line and f"{v['ratio']:.3g} x the noise floor" in line
    assert v["level"] == "good" and doc["input_noise_rms"] is not None, line
    recorded = json.loads((out / "identification.json").read_text())["metadata"]["heldout"]
    assert recorded["heldout_error_percent"] > 3 * recorded["noise_floor_percent"]
    level, text = _verdict_of((out / "report.html").read_text())
    text = " ".join(text.split())
    assert level == v["level"] and text.lower().startswith(v["label"]), text
    assert f"{v['ratio']:.3g} x the floor" in text, text
    assert f"noise floor of {doc['noise_floor_percent']:.3g} %" in text, text


def test_an_older_held_out_file_is_judged_on_the_record_s_floor(tmp_path):
    """A heldout.json without the states' noise (an older run) is judged as before, on the
    record's held-out error against its sensors' floor; a newer one by its own verdict."""
    ident = {
        "route": "classical",
        "coefficients": [],
        "metadata": {"heldout": {"training_error_percent": 1.4, "heldout_error_percent": 1.43,
                                 "noise_floor_percent": 0.553}},
    }  # fmt: skip
    held = {"relative_error_percent": 1.37, "noise_floor_percent": 0.554, "block": "lo4.csv"}
    (tmp_path / "identification.json").write_text(json.dumps(ident))
    h = tmp_path / "heldout.json"
    h.write_text(json.dumps(held))
    files = {p.name: p for p in tmp_path.iterdir()}
    level, text = _verdict_of(render_html_report(RunSummary("identify"), files))
    assert level == "fair" and "2.59 x the floor" in " ".join(text.split()), text
    verdict = {"level": "good", "label": "at the noise floor", "reason": "r", "ratio": 1.01}
    newer = held | {"noise_floor_percent": 0.872, "sensor_noise_rms": [0.002], "verdict": verdict}
    h.write_text(json.dumps(newer))
    level, text = _verdict_of(render_html_report(RunSummary("identify"), files))
    text = " ".join(text.split())
    assert level == "good" and "1.01 x the floor" in text and "0.872 %" in text, text
    assert "2.59" not in text, text
