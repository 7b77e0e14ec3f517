"""``--cutoff none``: the low-pass turned off from the command line. On exact simulated
data the held-out torques are then predicted to round-off (the default filter leaves
about 5e-5 % of its own), and validate reuses the recorded choice."""

from __future__ import annotations

import json
import warnings

import pytest

from dynid.cli.__main__ import main
from dynid.exceptions import DynidWarning
from dynid.io.model_json import load_model_json
from dynid.io.robot_file import load_robot
from dynid.io.torque_log import save_torque_log

from conftest import SO101_URDF, recordings


@pytest.fixture(scope="module")
def exact_logs(tmp_path_factory):
    """Two exact 4 s recordings of the SO-101 arm (no noise, no friction), saved."""
    robot = load_robot(str(SO101_URDF), snap_angles=True)
    a, b = recordings(robot, (3, 4), friction=None, duration=4.0)
    d = tmp_path_factory.mktemp("exact")
    return save_torque_log(d / "a.npz", a), save_torque_log(d / "b.npz", b)


def _robot() -> list[str]:
    return ["--robot", str(SO101_URDF), "--snap-angles"]


def test_cutoff_none_predicts_exact_held_out_torques_to_round_off(exact_logs, tmp_path):
    """identify --cutoff none on exact data: held-out joint torques within 1e-9 relative;
    the model records no filter and validate --model reuses it on another recording."""
    a, b = exact_logs
    out = tmp_path / "id"
    args = ["identify", *_robot(), "--data", str(a), "--out", str(out), "--terms", "links"]
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", DynidWarning)
        assert main([*args, "--cutoff", "none", "--no-figures", "-q"]) == 0
    held = json.loads((out / "heldout.json").read_text())
    assert held["relative_error_percent"] < 1e-7  # percent: 1e-9 relative
    assert load_model_json(out / "identification.json").info.log.cutoff_hz is None
    val = tmp_path / "val"
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", DynidWarning)
        args = ["validate", "--model", str(out / "identification.json"), "--data", str(b)]
        assert main([*args, "--out", str(val), "--no-figures", "-q"]) == 0
    got = json.loads((val / "validation.json").read_text())
    assert got["cutoff_hz"] is None
    assert got["relative_error_percent"] < 1e-7


@pytest.mark.parametrize("command", ["identify", "validate", "friction", "payload"])
def test_cutoff_refuses_zero_and_names_none(command, capsys):
    """--cutoff 0 is refused on every command that has it, and the message offers none."""
    assert main([command, "--cutoff", "0"]) == 2
    assert "or none (no low-pass); got '0'" in capsys.readouterr().err
