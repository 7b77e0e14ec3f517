"""A model fitted with ``--units tau3=-1`` records that sign map and ``validate --model``
reads its files with it: on a file whose tau3 already reads right the map is said to look
wrong, first, naming the joint and the ``--units`` that overrides it (it once judged such a
file "unusable" with only a sign warning that hinted at the very flip applied)."""

from __future__ import annotations

import dataclasses
import html
import json
import re
import warnings

import numpy as np
import pytest

from dynid.cli.__main__ import main
from dynid.exceptions import DynidWarning
from dynid.io.robot_file import load_robot
from dynid.io.torque_log import save_torque_log
from dynid.simulation.measurement import SensorNoise

from conftest import SO101_URDF, recordings

ROBOT = ["--robot", str(SO101_URDF), "--snap-angles"]


def _flipped(log, joints):
    """``log`` with the torque columns ``joints`` (from 0) negated."""
    sign = np.ones(log.tau.shape[1])
    sign[list(joints)] = -1.0
    return dataclasses.replace(log, tau=log.tau * sign)


@pytest.fixture(scope="module")
def flipped_model(tmp_path_factory):
    """identification.json fitted with --units tau3=-1 on a log whose tau3 column is
    negated, and two held-out logs: b.csv as the robot's torques read, c.csv with tau3
    negated as the training log's."""
    robot = load_robot(str(SO101_URDF), snap_angles=True)
    noise = SensorNoise(tau_std=0.005)
    a, b = recordings(robot, (3, 4), friction=None, duration=4.0, noise=noise)
    d = tmp_path_factory.mktemp("signs")
    save_torque_log(d / "a.csv", _flipped(a, [2]))
    save_torque_log(d / "b.csv", b)
    save_torque_log(d / "c.csv", _flipped(b, [2]))
    args = ["identify", *ROBOT, "--data", str(d / "a.csv"), "--out", str(d / "id")]
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", DynidWarning)
        assert main([*args, "--terms", "links", "--units", "tau3=-1", "-q", "--no-figures"]) == 0
    return d


def _validate(d, name, out, *extra):
    """validate --model on ``name``: validation.json and the report's verdict box, text."""
    args = ["validate", "--model", str(d / "id" / "identification.json")]
    main([*args, "--data", str(d / name), "--out", str(out), "--no-figures", *extra])
    page = (out / "report.html").read_text()
    box = page[page.index('id="verdict"') :].split("</section>")[0]
    return json.loads((out / "validation.json").read_text()), html.unescape(
        re.sub(r"<[^>]+>", " ", box)
    )


def test_recorded_sign_map_wrong_for_the_file_is_said_first(flipped_model, tmp_path, capsys):
    """b.csv's tau3 reads right: the finding names elbow_flex and --units tau=Nm, opens
    the verdict and the report's headline, and is the first sign line printed."""
    doc, box = _validate(flipped_model, "b.csv", tmp_path / "v")
    said = doc["sign_map"]
    assert "elbow_flex (tau3)" in said and "--units tau=Nm" in said
    assert doc["verdict"]["reason"].startswith("b.csv: the model's recorded sign map")
    assert box.index("recorded sign map looks wrong") < box.index("does not explain")
    err = capsys.readouterr().err
    assert "recorded sign map (--units tau3=-1) looks wrong" in err  # before the table
    assert "anti-correlated" not in err  # the hint to flip tau3 again is not given
    assert "recorded sign map" in box[: box.index("Relative error")]  # the first items


def test_following_the_hint_validates_the_file_at_its_noise(flipped_model, tmp_path):
    """--units tau=Nm (the hint) reads b.csv as held: the error is at the noise floor of
    the simulated sensors (0.005 N m), and no sign map is said."""
    doc, _ = _validate(flipped_model, "b.csv", tmp_path / "v", "--units", "tau=Nm")
    assert "sign_map" not in doc
    assert doc["verdict"]["level"] == "good"
    assert max(doc["without_friction"]["rms"]) < 2 * 0.005


def test_recorded_sign_map_right_for_the_file_is_not_doubted(flipped_model, tmp_path):
    """c.csv holds tau3 negated as the training log: read with the map, no finding."""
    doc, _ = _validate(flipped_model, "c.csv", tmp_path / "v")
    assert "sign_map" not in doc
    assert doc["verdict"]["level"] == "good"


def test_sign_warning_is_on_the_reports_first_screen(flipped_model, tmp_path):
    """A robot validated on a file of the opposite torque sign everywhere: the sign
    finding is in the report's verdict box, once (the verdict's reason opens with it, so
    the warning is not listed again)."""
    robot = load_robot(str(SO101_URDF), snap_angles=True)
    (log,) = recordings(robot, (5,), friction=None, duration=4.0)
    save_torque_log(tmp_path / "neg.csv", _flipped(log, range(robot.n)))
    out = tmp_path / "v"
    args = ["validate", *ROBOT, "--data", str(tmp_path / "neg.csv"), "--out", str(out)]
    main([*args, "--no-figures"])  # (its warnings are the report's)
    page = (out / "report.html").read_text()
    box = page[page.index('id="verdict"') :].split("</section>")[0]
    said = html.unescape(box)
    assert said.count("neg.csv: the measured torques are anti-correlated") == 1
    assert '<li class="warning"><b>warning</b> neg.csv: ' not in box


@pytest.fixture(scope="module")
def negated_model(tmp_path_factory):
    """identification.json fitted with --units tau=-1 on a log whose torques are negated
    on every joint (a controller of the opposite sign convention), and held-out logs:
    b.csv already in dynid's sign (converted by hand), c.csv negated but on tau3."""
    robot = load_robot(str(SO101_URDF), snap_angles=True)
    noise = SensorNoise(tau_std=0.005)
    a, b = recordings(robot, (3, 4), friction=None, duration=4.0, noise=noise)
    d = tmp_path_factory.mktemp("whole")
    save_torque_log(d / "a.csv", _flipped(a, range(robot.n)))
    save_torque_log(d / "b.csv", b)
    save_torque_log(d / "c.csv", _flipped(b, [k for k in range(robot.n) if k != 2]))
    args = ["identify", *ROBOT, "--data", str(d / "a.csv"), "--out", str(d / "id")]
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", DynidWarning)
        assert main([*args, "--terms", "links", "--units", "tau=-1", "-q", "--no-figures"]) == 0
    return d


def _hint(text):
    """The ``--units`` text of a finding's hint."""
    return re.search(r"hint: --units (\S+)", text).group(1)


@pytest.mark.parametrize("given", [(), ("--units", "tau=-1")], ids=["recorded", "given"])
def test_file_already_in_dynids_sign_gets_the_units_that_read_it(
    negated_model, tmp_path, capsys, given
):
    """Regression: a file already in dynid's sign, read with the model's recorded (or the
    given) --units tau=-1, was judged "unusable, 200 %" with the hint --units tau=-1, the
    flip applied, and no sign_map. The finding says the file looks already in dynid's
    sign and hints --units tau=1; following it, the error falls to the simulated
    sensors' noise (0.005 N m)."""
    doc, box = _validate(negated_model, "b.csv", tmp_path / "v", *given)
    said = doc["sign_map"]
    assert "already in dynid's sign" in said and _hint(said) == "tau=1"
    assert doc["verdict"]["level"] == "unusable"
    assert doc["verdict"]["reason"].startswith("b.csv: the file looks already")
    assert ("given" if given else "recorded") + " sign map looks wrong" in box
    assert "springs" not in doc  # the residual of a sign is not diagnosed
    assert "its torque columns negated" not in capsys.readouterr().err  # the vague hint
    fixed, _ = _validate(negated_model, "b.csv", tmp_path / "w", "--units", _hint(said))
    assert "sign_map" not in fixed and fixed["verdict"]["level"] == "good"
    assert max(fixed["without_friction"]["rms"]) < 2 * 0.005


def test_one_joint_already_in_dynids_sign_gets_the_units_that_read_it(negated_model, tmp_path):
    """c.csv holds every joint negated as the training log but tau3: the recorded
    --units tau=-1 reads tau3 wrong, and the hint keeps the other joints negated
    (--units tau=-1,tau3=-1); following it, the error falls to the sensors' noise."""
    doc, _ = _validate(negated_model, "c.csv", tmp_path / "v")
    said = doc["sign_map"]
    assert "elbow_flex (tau3)" in said and _hint(said) == "tau=-1,tau3=-1"
    fixed, _ = _validate(negated_model, "c.csv", tmp_path / "w", "--units", _hint(said))
    assert "sign_map" not in fixed and fixed["verdict"]["level"] == "good"
    assert max(fixed["without_friction"]["rms"]) < 2 * 0.005


def test_a_file_of_the_models_sign_convention_is_not_doubted(negated_model, tmp_path):
    """The training log's convention (every joint negated), read with the recorded
    --units tau=-1: no finding, the error at the sensors' noise."""
    d = negated_model
    robot = load_robot(str(SO101_URDF), snap_angles=True)
    (log,) = recordings(robot, (6,), friction=None, duration=4.0, noise=SensorNoise(tau_std=0.005))
    save_torque_log(d / "e.csv", _flipped(log, range(robot.n)))
    doc, _ = _validate(d, "e.csv", tmp_path / "v")
    assert "sign_map" not in doc and doc["verdict"]["level"] == "good"


def test_units_negating_writes_the_fewest_entries():
    """The --units text of a sign map with other joints negated, by hand."""
    from dynid.io.sign_entries import units_negating

    assert units_negating("tau=-1", [], 7) == "tau=1"
    assert units_negating("tau3=-1", [], 6) == "tau=Nm"
    assert units_negating("q=deg,tau=-1", [], 6) == "q=deg,tau=1"
    assert units_negating("tau=-1", [0, 1, 3, 4, 5], 6) == "tau=-1,tau3=-1"
    assert units_negating("tau=mNm,tau3=-1,b.csv:tau=-1", [1], 6) == "tau=mNm,tau2=-1"


def test_observe_refuses_a_file_already_in_dynids_sign_with_the_units_that_read_it(
    negated_model, tmp_path, capsys
):
    """observe --calibrate on b.csv (already in dynid's sign, the model's recorded
    --units tau=-1): refused naming the file once, with --units tau=1; following it, the
    calibration runs."""
    d = negated_model
    args = ["observe", "--model", str(d / "id" / "identification.json"), "--calibrate"]
    args += ["--data", str(d / "b.csv")]
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", DynidWarning)
        assert main([*args, "--out", str(tmp_path / "o")]) == 2
        err = capsys.readouterr().err
        assert "b.csv: the file looks already in dynid's sign" in err
        assert "b.csv: b.csv" not in err and _hint(err) == "tau=1"
        assert main([*args, "--units", _hint(err), "--out", str(tmp_path / "p")]) == 0
