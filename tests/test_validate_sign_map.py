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
