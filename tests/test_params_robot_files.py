"""``validate --params`` and ``payload --params`` read a robot description (a URDF, a robot
TOML, an MJCF) as ``--robot`` reads it, as ``observe --params`` and ``export --params`` do:
an xArm7's exported robot.toml given to ``validate --params`` was refused with "not a
JSON file (Expecting value at line 1, column 1)", with no word of --robot."""

from __future__ import annotations

import json

from dynid.cli.__main__ import main


def test_validate_params_reads_a_robot_toml_as_robot_does(tmp_path):
    """validate --params arm.toml (an export of the Panda with its friction) gives the
    errors and the verdict of validate --robot arm.toml on the Panda's simulated log."""
    arm, log = tmp_path / "arm.toml", tmp_path / "log.csv"
    assert main(["export", "--params", "panda", "--out", str(arm), "-q"]) == 0
    sim = ["simulate", "--robot", "panda", "--duration", "2", "--rate", "200", "--seed", "2"]
    assert main([*sim, "--out", str(log), "-q"]) == 0
    got = {}
    for flag in ("--robot", "--params"):
        out = tmp_path / flag.strip("-")
        argv = ["validate", flag, str(arm), "--data", str(log), "--no-figures", "-q"]
        assert main([*argv, "--out", str(out)]) == 0
        got[flag] = json.loads((out / "validation.json").read_text())
    for key in ("relative_error_percent", "noise_floor_percent"):
        assert got["--params"][key] == got["--robot"][key], key
    assert got["--params"]["verdict"] == got["--robot"]["verdict"]
