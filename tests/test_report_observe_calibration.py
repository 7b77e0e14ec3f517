"""The first screen of a calibration's report: is the observer good enough.

It listed only the thresholds table. It now opens with the false alarms on the
calibration logs (count and rate per minute), the smallest external torque detected per
joint, the residual's figure with the thresholds, then the table. References: the
numbers recomputed from thresholds.json and from events.json of a detection run with
those thresholds on the same log, and the log's own duration.
"""

from __future__ import annotations

import dataclasses
import html
import json
import re

import numpy as np
import pytest

import dynid
from dynid.cli.__main__ import main
from dynid.io.torque_log import save_torque_log
from dynid.report.html import number
from dynid.simulation.measurement import SensorNoise, sample_times, simulate_measurement
from dynid.simulation.trajectories import random_fourier


@pytest.fixture(scope="module")
def free(tmp_path_factory):
    """A collision-free 3 s, 500 Hz noisy log of the Panda with its own friction."""
    panda = dynid.panda()
    rng = np.random.default_rng(44)
    traj = random_fourier(panda, rng)(sample_times(3.0, 500.0))
    log = simulate_measurement(panda, traj, rng=rng, noise=SensorNoise())
    return save_torque_log(tmp_path_factory.mktemp("cal") / "free.csv", log), log


@pytest.mark.parametrize("rule", [[], ["--margin", "1", "--quantile", "0.6"]])
def test_the_calibration_report_opens_with_false_alarms_detectable_torques_and_figure(
    free, tmp_path, rule, capsys
):
    """The answer box holds the false alarms (equal to the events a detection with the
    thresholds finds on the same log) and their rate per minute of the log, the smallest
    detectable torque of every joint (the contact threshold of thresholds.json), and the
    figure comes before the thresholds table."""
    path, log = free
    cal, det = tmp_path / "cal", tmp_path / "det"
    base = ["observe", "--params", "panda", "--data", str(path)]
    capsys.readouterr()
    assert main([*base, "--calibrate", *rule, "--out", str(cal)]) == 0
    th = json.loads((cal / "thresholds.json").read_text())
    # the printout's residual column is the one past the standstill margin (contact /
    # margin), labelled so: the report's "largest |r| read" is the raw peak, margin in
    head = next(x for x in capsys.readouterr().out.splitlines() if "past margin [N m]" in x)
    assert head.split()[0] == "joint"
    assert th["rule"]["standstill_margin"]  # the default: the margin is left out
    over = th["rule"]["margin"]
    assert any(p > c / over for p, c in zip(th["calibration"]["peak"], th["contact"], strict=True))
    assert main([*base, "--thresholds", str(cal / "thresholds.json"), "--no-figures",
                 "--out", str(det)]) == 0  # fmt: skip
    events = json.loads((det / "events.json").read_text())["events"]
    page = (cal / "report.html").read_text()
    answer = page[page.index('id="verdict"') : page.index("</section>", page.index('id="verdict"'))]
    k, duration = len(events), float(log.t[-1] - log.t[0])
    assert th["calibration"]["false_alarms"] == k and th["calibration"]["duration_s"] == duration
    word = "false alarm" if k == 1 else "false alarms"
    assert f"{k} {word} on them ({60.0 * k / duration:.3g} per minute)" in answer
    assert (k > 0) == bool(rule)  # the lower quantile leaves samples over the threshold
    cells = re.findall(r"<tr><td>(joint\d)</td><td>([^<]*)</td>", answer)
    assert [c[0] for c in cells] == [f"joint{j}" for j in range(1, 8)]
    assert [c[1] for c in cells] == [number(x) for x in th["contact"]]  # no uncertainty
    assert f"above {min(th['contact']):.3g} to {max(th['contact']):.3g} N m" in answer
    figure, thresholds = page.index('id="residuals"'), page.index('id="thresholds"')
    assert figure < thresholds and "<img" in page[figure:thresholds]


def test_false_alarms_are_counted_without_figures_below_quantile_one(free, tmp_path, capsys):
    """Regression: --quantile 0.6 with --no-figures wrote false_alarms null (the residual
    was not kept to count them on). The count is now the events a detection with the
    thresholds finds on the same log, figures or not, in thresholds.json, the report and
    the printed summary."""
    path, log = free
    base = ["observe", "--params", "panda", "--data", str(path)]
    cal, det = tmp_path / "cal", tmp_path / "det"
    args = [*base, "--calibrate", "--margin", "1", "--quantile", "0.6", "--no-figures"]
    capsys.readouterr()
    assert main([*args, "--out", str(cal)]) == 0
    printed = capsys.readouterr().out
    th = json.loads((cal / "thresholds.json").read_text())
    args = [*base, "--thresholds", str(cal / "thresholds.json"), "--no-figures"]
    assert main([*args, "--out", str(det)]) == 0
    k = len(json.loads((det / "events.json").read_text())["events"])
    assert k > 0  # the lower quantile leaves samples over the threshold
    assert th["calibration"]["false_alarms"] == k
    rate = 60.0 * k / float(log.t[-1] - log.t[0])
    assert f"{k} false alarm(s) on the calibration logs ({rate:.3g} per minute)" in printed
    said = f"{k} false alarm{'s' if k != 1 else ''} on them ({rate:.3g} per minute)"
    assert said in (cal / "report.html").read_text()


def test_the_smallest_detectable_torque_grows_with_the_largest_uncertainty():
    """With the model's uncertainty the contact threshold while moving is ``nu + k
    sigma(t)``: its largest value, ``nu + k max sigma``, is the smallest torque detected
    wherever the joint moves; without it, the fixed threshold."""
    from dynid.observer.calibration_check import CalibrationCheck, detectable
    from dynid.observer.residual import ObserverOptions
    from dynid.observer.thresholds import Thresholds

    nu, s = np.array([0.5, 0.2]), np.array([0.1, 0.02])
    fixed = Thresholds(np.array([0.9, 0.3]), np.array([1.8, 0.6]), 1.5, 1.0, 2.0,
                       ObserverOptions(), 100)  # fmt: skip
    grown = Thresholds(np.array([0.9, 0.3]), np.array([1.8, 0.6]), 1.5, 1.0, 2.0,
                       ObserverOptions(), 100, k_sigma=3.0, noise=nu)  # fmt: skip
    np.testing.assert_allclose(detectable(grown, s), [0.8, 0.26], rtol=1e-12)
    np.testing.assert_allclose(detectable(fixed, s), [0.9, 0.3], rtol=1e-12)
    check = CalibrationCheck(30.0, 2, s, detectable(grown, s), np.array([0.3, 0.1]))
    assert check.false_alarms_per_min == pytest.approx(4.0, rel=1e-12)


def test_the_calibration_judges_the_model_behind_the_thresholds(free, tmp_path, capsys):
    """The calibration says how well the model predicts the calibration log's torques,
    judged as dynid validate judges it: the true Panda (the simulation's own) at the noise
    floor; the Panda with link 4's parameters 30 % too large usable, the thresholds said to
    hold its error; twice too large poor, the thresholds said to be wide because of it and
    the report's badge poor. In thresholds.json, the report's first screen and the printed
    summary; the verdict is validate's on the same log."""
    from dynid.io.robot.toml import save_toml

    path, _ = free
    panda = dynid.panda()
    said = {}
    for name, factor in (("true", 1.0), ("30 %", 1.3), ("twice", 2.0)):
        phi = np.array(panda.phi)
        phi[3] *= factor  # link 4: mass, first moments and inertia
        params = str(save_toml(tmp_path / f"{factor}.toml", panda.with_params(phi)))
        out = tmp_path / f"cal{factor}"
        args = ["observe", "--params", params, "--data", str(path), "--calibrate"]
        capsys.readouterr()
        assert main([*args, "--no-figures", "--out", str(out)]) == 0
        printed = capsys.readouterr().out
        check = json.loads((out / "thresholds.json").read_text())["calibration"]["model_check"]
        if factor == 2.0:  # the verdict is validate's
            args = ["validate", "--params", params, "--data", str(path), "--no-figures", "-q"]
            assert main([*args, "--out", str(tmp_path / "val")]) == 0
            val = json.loads((tmp_path / "val" / "validation.json").read_text())
            assert check["verdict"] == val["verdict"] | {"ratio": check["verdict"]["ratio"]}
        label = check["verdict"]["label"]
        err = check["relative_error_percent"]
        line = f"the model predicts the calibration logs' torques to {err:.3g} %"
        assert line in printed and f"(validate's verdict: {label})" in printed, printed
        page = (out / "report.html").read_text()
        badge = re.search(r'<section class="verdict (\w+)" id="verdict">', page)[1]
        box = page[
            page.index('id="verdict"') : page.index("</section>", page.index('id="verdict"'))
        ]
        box = html.unescape(box)
        assert line in box and f"(validate's verdict: {label})" in box, box
        said[name] = (check["verdict"]["level"], label, box, badge)
    assert said["true"][:2] == ("good", "at the noise floor") and said["true"][3] == "info"
    assert "a better model" not in said["true"][2]
    assert said["30 %"][:2] == ("fair", "usable") and said["30 %"][3] == "info"
    assert "the thresholds hold the model's error" in said["30 %"][2]
    assert said["twice"][:2] == ("poor", "poor") and said["twice"][3] == "poor"
    assert "the thresholds are wide because of the model's error" in said["twice"][2]
    assert "thresholds calibrated on a poor model" in said["twice"][2]


@pytest.mark.parametrize(("level", "said"), [("unusable", "an unusable"), ("poor", "a poor")])
def test_the_badge_of_thresholds_on_a_poor_or_unusable_model_takes_its_article(
    free, tmp_path, level, said
):
    """A calibration whose model validate would call unusable is badged "thresholds
    calibrated on an unusable model" (not "a unusable"), a poor one "on a poor model"."""
    from dynid.report import RunSummary, render_html_report

    path, _ = free
    cal = tmp_path / "cal"
    args = ["observe", "--params", "panda", "--data", str(path), "--calibrate", "-q"]
    assert main([*args, "--no-figures", "--out", str(cal)]) == 0
    doc = json.loads((cal / "thresholds.json").read_text())
    doc["calibration"]["model_check"]["verdict"] |= {"level": level, "label": level}
    (cal / "thresholds.json").write_text(json.dumps(doc))
    page = render_html_report(
        RunSummary(command="observe"), {"thresholds.json": cal / "thresholds.json"}
    )
    badge = re.search(r'<span class="level">([^<]*)</span>', page)
    assert badge is not None and badge[1] == f"thresholds calibrated on {said} model"


def test_the_report_shows_the_residual_read_as_the_summary_does(free, tmp_path, capsys):
    """Regression: the report's "largest |r| read" was the raw peak (a UR5 joint's 0.309
    N m, inside the standstill margin, over its own contact level beside 0 false alarms)
    while the summary's "|r| read past margin" said 0.096. The report now shows the
    summary's column (contact / margin of thresholds.json, equal to its printed values)
    and names the raw peak as such."""
    path, _ = free
    out = tmp_path / "cal"
    capsys.readouterr()
    assert main(["observe", "--params", "panda", "--data", str(path), "--calibrate",
                 "--no-figures", "--out", str(out)]) == 0  # fmt: skip
    printed = capsys.readouterr().out.splitlines()
    th = json.loads((out / "thresholds.json").read_text())
    read = [float(x.split()[1]) for x in printed if re.match(r"joint\d ", x)]
    np.testing.assert_allclose(read, np.array(th["contact"]) / th["rule"]["margin"], rtol=1e-3)
    page = html.unescape((out / "report.html").read_text())
    table = page[page.index('class="calibration"') :]
    table = table[: table.index("</table>")]
    heads = re.findall(r"<th>([^<]*)</th>", table)
    k = heads.index(
        "|r| read past the standstill margin (the fixed contact level is 1.5 x it) [N m]"
    )
    assert "largest raw |r|, standstill margin not taken off [N m]" in heads
    rows = re.findall(r"<tr>(.*?)</tr>", table, flags=re.S)[1:]
    cells = [re.findall(r"<td>([^<]*)</td>", r)[k] for r in rows]
    assert cells == [number(c / 1.5) for c in th["contact"]]


def test_a_calibration_on_the_models_own_recordings_is_said_in_sample(free, tmp_path, capsys):
    """Regression (a TALOS trial): observe --calibrate on logs three of four of which the
    model was identified from said "the model predicts the calibration logs' torques to
    1.04 % ... at the noise floor" as if held out. A calibration log that is one of the
    identification's recordings (by file name) is counted and the judgement said to be
    in-sample, in the summary, thresholds.json and the report; another log is not."""
    from dynid.identification.info import IdentificationInfo
    from dynid.io.model_json import save_model_json

    from conftest import exact_model

    path, _ = free
    panda = dynid.panda()
    said = {}
    for name, files in (("own", ({"file": path.name},)), ("other", ({"file": "r9.csv"},))):
        info = IdentificationInfo(recordings=files)
        model = dataclasses.replace(exact_model(panda, panda), info=info)
        saved = save_model_json(tmp_path / f"{name}.json", model)
        out = tmp_path / name
        args = ["observe", "--model", str(saved), "--data", str(path), "--calibrate"]
        capsys.readouterr()
        assert main([*args, "--no-figures", "--out", str(out)]) == 0
        check = json.loads((out / "thresholds.json").read_text())["calibration"]["model_check"]
        page = html.unescape((out / "report.html").read_text())
        said[name] = (check["fitted"], capsys.readouterr().out, page)
    words = "all are the identification's own recordings, so in-sample"
    assert said["own"][0] == [1, 1] and said["other"][0] == [0, 1]
    assert words in said["own"][1] and words in said["own"][2]
    assert "in-sample" not in said["other"][1] and "in-sample" not in said["other"][2]


def test_a_feasible_json_s_own_recordings_are_said_in_sample(free, tmp_path, capsys):
    """Regression (an iiwa trial): observe --params feasible.json --calibrate on the
    recordings identify --consistent fitted said "at the noise floor" with no word that
    they were its training data (validate --params says it). The identification.json
    beside the feasible.json records them by name: counted and said in-sample; a
    feasible.json with no identification beside it counts none."""
    from dynid.identification.info import IdentificationInfo
    from dynid.io.feasible import save_feasible_json
    from dynid.io.model_json import save_model_json

    from conftest import exact_model

    path, _ = free
    panda = dynid.panda()
    said = {}
    for name, beside in (("own", True), ("alone", False)):
        folder = tmp_path / name
        folder.mkdir()
        params = save_feasible_json(folder / "feasible.json", panda)
        if beside:
            info = IdentificationInfo(recordings=({"file": path.name},))
            model = dataclasses.replace(exact_model(panda, panda), info=info)
            save_model_json(folder / "identification.json", model)
        args = ["observe", "--params", str(params), "--data", str(path), "--calibrate"]
        capsys.readouterr()
        assert main([*args, "--no-figures", "--out", str(folder / "cal")]) == 0
        doc = json.loads((folder / "cal" / "thresholds.json").read_text())
        said[name] = (doc["calibration"]["model_check"]["fitted"], capsys.readouterr().out)
    words = "all are the identification's own recordings, so in-sample"
    assert said["own"][0] == [1, 1] and words in said["own"][1]
    assert said["alone"][0] == [0, 1] and "in-sample" not in said["alone"][1]
