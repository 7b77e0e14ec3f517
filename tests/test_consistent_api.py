"""The one-step consistent fit of one torque log through the Python API is the command's:
``identify_consistent(robot, log)`` chooses the model's structure on held-out blocks as
``dynid identify --consistent --data one.csv`` does (it fitted classical friction while
the command fitted the chosen structure), and both give the same parameters.

References: the command line run on the same log written to a file (the parameters and
the chosen structure of its feasible.json and identification.json).
"""

from __future__ import annotations

import dataclasses
import json

import numpy as np
import pytest

import dynid
from dynid.cli.__main__ import main
from dynid.feasibility.convex import identify_consistent
from dynid.io.feasible import load_feasible_json, load_feasible_linear_friction
from dynid.io.robot.toml import toml_from_robot
from dynid.io.torque_log import load_torque_log, save_torque_log
from dynid.simulation.measurement import sample_times, simulate_measurement
from dynid.simulation.trajectories import random_fourier

from conftest import planar_2r

pytestmark = pytest.mark.filterwarnings("ignore::dynid.DynidWarning")


def test_one_log_through_the_api_gives_the_commands_parameters(tmp_path, capsys):
    arm = dataclasses.replace(
        planar_2r(), friction=dynid.SigmoidFriction.from_array([[1.0, 30.0, 0.1]] * 2)
    )
    robot = tmp_path / "arm.toml"
    robot.write_text(toml_from_robot(arm))
    rng = np.random.default_rng(5)
    traj = random_fourier(arm, rng, n_harmonics=5)(sample_times(6.0, 100.0))
    path = save_torque_log(tmp_path / "one.csv", simulate_measurement(arm, traj, rng=rng))
    log = load_torque_log(path)  # the samples the command reads
    out = tmp_path / "c"
    argv = ["identify", "--robot", str(robot), "--data", str(path), "--consistent"]
    rc = main([*argv, "--no-figures", "--out", str(out)])
    assert rc == 0, capsys.readouterr().err
    res = identify_consistent(dynid.Robot.from_toml(robot), log)
    # the structure chosen on held-out blocks (it was classical friction, unchosen)
    ident = json.loads((out / "identification.json").read_text())["metadata"]
    assert res.identified is not None and res.identified.info.selection is not None
    assert res.identified.info.selection["chosen"] == ident["selection"]["chosen"]
    cli = load_feasible_json(out / "feasible.json")
    np.testing.assert_allclose(res.phi, cli.phi, rtol=1e-9, atol=1e-9 * np.abs(cli.phi).max())
    friction = load_feasible_linear_friction(out / "feasible.json")
    assert res.friction is not None and friction is not None
    assert res.friction.law.name == friction.law.name
    np.testing.assert_allclose(res.friction.params, friction.params, rtol=1e-9, atol=1e-9)
