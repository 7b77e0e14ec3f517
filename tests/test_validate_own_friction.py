"""A robot's own friction (a description's: the joints') through a geared drive stays at
the joints unless the drive file says ``friction_at = "motor"``; validate, simulate and
observe say so in one note when it does (an exported URDF's joint friction read at the
motors of a gear-345 drive gave 6e6 % with no word why). And a prediction whose friction
at the motors outweighs the rigid body's torques is judged on the whole prediction: its
own simulated log, predicted to 0.45 %, was "unusable: the measured torques are
anti-correlated with the model's"."""

from __future__ import annotations

import json
import logging

import pytest

from dynid.cli.__main__ import main
from dynid.progress import NOTE

DRIVE = 'schema = "dynid-drive/1"\nside = "joint"\ngear_ratio = [50, 50, 50, 50, 20, 20, 20]\n'


@pytest.mark.parametrize("at", [None, "joint", "motor"])
def test_the_robots_own_friction_at_the_motors_is_said(tmp_path, caplog, capsys, at):
    """friction_at = "motor" in the drive file: simulate and validate say the robot's own
    friction is read at the motors, validate in one note naming it; unset (the joints for
    a description's friction) or "joint": neither. Either way the log the model simulated
    is at its noise floor (the sign judged on the prediction with its friction)."""
    drive = tmp_path / "drive.toml"
    drive.write_text(DRIVE + ("" if at is None else f'friction_at = "{at}"\n'))
    log = tmp_path / "log.csv"
    sim = ["simulate", "--drive", str(drive), "--duration", "2", "--rate", "200"]
    with caplog.at_level(logging.INFO):
        assert main([*sim, "--trajectory", "fourier", "--out", str(log)]) == 0
    simulated = capsys.readouterr()
    assert ("read at the motors" in simulated.out + simulated.err) == (at == "motor")
    argv = ["validate", "--robot", "panda", "--drive", str(drive), "--data", str(log)]
    with caplog.at_level(logging.INFO):
        assert main([*argv, "--no-figures", "-q", "--out", str(tmp_path / "v")]) == 0
    doc = json.loads((tmp_path / "v" / "validation.json").read_text())
    assert doc["verdict"]["level"] == "good", doc["verdict"]
    said = [r for r in caplog.records if "read at the motors" in r.getMessage()]
    if at == "motor":
        assert [r.levelno for r in said] == [NOTE], said
        assert 'the drive file says friction_at = "motor"' in said[0].getMessage()
    else:
        assert not said


def test_observe_says_the_robots_own_friction_acts_at_the_motors(tmp_path, caplog):
    """observe --params through a geared drive saying friction_at = "motor" says, as validate
    and simulate do, that the robot's own friction is read at the motors (it did not: a
    URDF's joint friction read there gave thresholds of another model without a word)."""
    drive = tmp_path / "drive.toml"
    drive.write_text(DRIVE + 'friction_at = "motor"\n')
    log = tmp_path / "log.csv"
    sim = ["simulate", "--drive", str(drive), "--duration", "2", "--rate", "200"]
    assert main([*sim, "--trajectory", "fourier", "--out", str(log), "-q"]) == 0
    caplog.clear()
    argv = ["observe", "--params", "panda", "--drive", str(drive), "--data", str(log)]
    with caplog.at_level(logging.INFO):
        assert main([*argv, "--calibrate", "--no-figures", "-q", "--out", str(tmp_path / "o")]) == 0
    said = [r for r in caplog.records if "read at the motors" in r.getMessage()]
    assert [r.levelno for r in said] == [NOTE], said
