"""The built-in Franka Research 3: Franka's published limits, the Panda's kinematics and
parameters, and the commands that take ``--robot fr3``."""

from __future__ import annotations

import argparse
import json
import logging
from pathlib import Path

import numpy as np
import pytest

import dynid
from dynid.cli.__main__ import main
from dynid.cli.common import load_prior
from dynid.cli.console import Console, log_to_stderr
from dynid.exceptions import UnknownNameError
from dynid.io.robot_file import load_robot
from dynid.model import fr3 as fr3_module
from dynid.model.builtin import BUILTIN_ROBOTS, builtin_robot
from dynid.progress import NOTE

from conftest import random_states

#: Franka's published FR3 limits (source in tests/data/README.md).
PUBLISHED = json.loads(
    (Path(__file__).parent / "data" / "fr3_limits_franka.json").read_text(encoding="utf-8")
)


def test_fr3_limits_equal_frankas_published_values():
    """Every limit the package holds for the FR3 is Franka's number, per joint, exactly."""
    robot = dynid.fr3()
    for key in ("q_min", "q_max", "dq_max", "ddq_max", "tau_max"):
        np.testing.assert_array_equal(getattr(robot, key), PUBLISHED[key], err_msg=key)
    np.testing.assert_array_equal(fr3_module.FR3_DDDQ_MAX, PUBLISHED["dddq_max"])
    np.testing.assert_array_equal(fr3_module.FR3_DTAU_MAX, PUBLISHED["dtau_max"])
    assert PUBLISHED["units"] == {
        "q": "rad",
        "dq": "rad/s",
        "ddq": "rad/s^2",
        "dddq": "rad/s^3",
        "tau": "N m",
        "dtau": "N m/s",
    }


def test_fr3_limits_differ_from_the_pandas():
    """The FR3 is not the Panda under another name: its joint 6 cannot reach the Panda's
    lower limit, and its wrist is faster."""
    panda, fr3 = dynid.panda(), dynid.fr3()
    assert fr3.q_min[5] > 0.5 > panda.q_min[5]
    assert np.all(fr3.dq_max[4:] > panda.dq_max[4:])


def test_fr3_has_the_pandas_kinematics_flange_and_parameters():
    """Same poses of every link and the flange, same link parameters, friction and gravity."""
    panda, fr3 = dynid.panda(), dynid.fr3()
    q, dq, ddq = random_states(fr3, 50, seed=21)
    np.testing.assert_array_equal(dynid.link_poses(fr3, q), dynid.link_poses(panda, q))
    np.testing.assert_array_equal(dynid.fk(fr3, q), dynid.fk(panda, q))
    T_link7_flange = fr3.frame("flange").T_link_frame
    np.testing.assert_allclose(T_link7_flange[:3, 3], [0.0, 0.0, 0.107], atol=1e-15)
    np.testing.assert_array_equal(fr3.phi, panda.phi)
    np.testing.assert_array_equal(fr3.friction.params, panda.friction.params)
    assert fr3.friction.kind == panda.friction.kind
    np.testing.assert_array_equal(fr3.gravity, panda.gravity)
    np.testing.assert_array_equal(dynid.rnea(fr3, q, dq, ddq), dynid.rnea(panda, q, dq, ddq))
    assert fr3.name == "fr3" and fr3.joint_names == panda.joint_names


def test_fr3_neutral_pose_is_inside_its_limits():
    """The Panda's neutral pose, which the FR3 reuses, lies within the FR3's position limits."""
    fr3 = dynid.fr3()
    assert np.all(fr3.q_neutral > PUBLISHED["q_min"]) and np.all(fr3.q_neutral < PUBLISHED["q_max"])


def test_builtin_names_read_through_one_table():
    """'panda' and 'fr3' are read by the robot-file dispatch; an unknown name lists both."""
    assert set(BUILTIN_ROBOTS) == {"panda", "fr3"}
    assert load_robot("fr3").name == "fr3" and load_robot("panda").name == "panda"
    assert BUILTIN_ROBOTS["fr3"].parameter_note is not None
    assert BUILTIN_ROBOTS["panda"].parameter_note is None
    with pytest.raises(UnknownNameError, match=r"available: \['fr3', 'panda'\]"):
        builtin_robot("ur5")


def test_fr3_parameters_are_said_once_per_run_where_the_name_is_resolved(
    tmp_path, capsys, monkeypatch
):
    """Regression (only --prior fr3 said that the FR3's link parameters are the Panda's;
    acquire-static, simulate, payload, validate and observe --params said nothing): the
    note is logged where the name is resolved, so every command on fr3 prints it, once per
    run however often the name is resolved (--robot and --prior); -q silences it; the
    Panda has none."""
    root = logging.getLogger()  # a process without logging of its own, as the command's
    monkeypatch.setattr(root, "handlers", [])
    monkeypatch.setattr(root, "level", root.level)
    line = f"dynid acquire-static: note: {fr3_module.FR3_PARAMETER_NOTE}"
    out = str(tmp_path / "s.csv")
    for robot, quiet, said in (("fr3", [], [line]), ("fr3", ["-q"], []), ("panda", [], [])):
        argv = ["acquire-static", "--robot", robot, "--n", "5", "--seed", "1", "--out", out]
        assert main(argv + quiet) == 0
        err = capsys.readouterr().err.splitlines()
        assert [s for s in err if "note:" in s] == said
    log_to_stderr("identify", NOTE)
    for run in range(2):
        if run:
            log_to_stderr("identify", NOTE)  # the next run says it again
        for _ in range(2):  # --robot fr3 --prior fr3
            load_robot("fr3")
            args = argparse.Namespace(prior="fr3", prior_base=None, prior_tip=None)
            assert load_prior(args, dynid.fr3(), Console("identify")) is not None
        err = capsys.readouterr().err.strip().splitlines()
        assert err == [f"dynid identify: note: {fr3_module.FR3_PARAMETER_NOTE}"]
    assert "Panda's" in err[0]


def test_identify_robot_fr3_runs_on_data_acquired_within_its_limits(tmp_path):
    """acquire-static --robot fr3 samples inside the FR3's limits; identify --robot fr3 fits
    the noise-free data exactly and records the FR3 with its limits."""
    data = tmp_path / "static.csv"
    assert (
        main(["acquire-static", "--robot", "fr3", "--n", "80", "--seed", "2", "--out", str(data)])
        == 0
    )
    header, *rows = [s for s in data.read_text().splitlines() if not s.startswith("#")]
    table = np.array([[float(x) for x in row.split(",")] for row in rows])
    q = table[:, [header.split(",").index(f"q{j}") for j in range(1, 8)]]
    assert np.all(q >= PUBLISHED["q_min"]) and np.all(q <= PUBLISHED["q_max"])
    assert np.any(q[:, 5] > 3.7525)  # beyond the Panda's joint 6 range, inside the FR3's
    out = tmp_path / "res"
    assert main(["identify", "--robot", "fr3", "--data", str(data), "--out", str(out), "-q"]) == 0
    result = json.loads((out / "identification.json").read_text())
    assert result["rank"] == 43 and result["relative_error_percent"] < 1e-8
    assert result["robot"]["name"] == "fr3"
    for key, value in result["robot"]["limits"].items():
        assert value == PUBLISHED[key], key


def test_excite_robot_fr3_keeps_the_fr3_limits(tmp_path):
    """excite --robot fr3 designs within the FR3's limits and records them (a short design)."""
    out = tmp_path / "ex"
    args = ["excite", "--robot", "fr3", "--duration", "1", "--harmonics", "1"]
    args += ["--base-frequency", "0.5", "--max-iter", "1", "--no-figure", "-q", "--out", str(out)]
    assert main(args) == 0
    d = json.loads((out / "trajectory.json").read_text())
    assert d["robot"] == "fr3"
    for key, unit in (("q_min", "rad"), ("q_max", "rad"), ("dq_max", "rad_s")):
        assert d["limits"][f"{key}_{unit}"] == PUBLISHED[key], key
    assert d["limits"]["ddq_max_rad_s2"] == PUBLISHED["ddq_max"]
    assert d["limits"]["tau_max_nm"] == PUBLISHED["tau_max"]
    text = (out / "trajectory.csv").read_text()
    header, *rows = [s for s in text.splitlines() if not s.startswith("#")]
    table = np.array([[float(x) for x in row.split(",")] for row in rows])
    cols = header.split(",")
    q = table[:, [cols.index(f"q{j}") for j in range(1, 8)]]
    dq = table[:, [cols.index(f"dq{j}") for j in range(1, 8)]]
    assert np.all(q > PUBLISHED["q_min"]) and np.all(q < PUBLISHED["q_max"])
    assert np.all(np.abs(dq) < PUBLISHED["dq_max"])


def test_kinematics_commands_on_fr3_say_nothing_of_its_link_parameters(capsys, monkeypatch):
    """Regression (fk, jacobian and ik on fr3 printed the note that its link parameters are
    the Panda's, which they do not use): the kinematics commands print no note; a command
    that uses the parameters still does."""
    root = logging.getLogger()
    monkeypatch.setattr(root, "handlers", [])
    monkeypatch.setattr(root, "level", root.level)
    q = "0,-0.3,0,-2,0,1.8,0.8"
    for argv in (["fk", "--q", q], ["jacobian", "--q", q]):
        assert main([argv[0], "--robot", "fr3", *argv[1:]]) == 0
        assert "note:" not in capsys.readouterr().err
    assert (
        main(["ik", "--robot", "fr3", "--goal-xyz", "0.4,0.1,0.5", "--goal-rpy", "3.14159,0,0"])
        == 0
    )
    assert "note:" not in capsys.readouterr().err
    log_to_stderr("identify", NOTE)
    load_robot("fr3")
    assert capsys.readouterr().err.count("note:") == 1


def test_a_run_in_a_process_leaves_its_logging_as_it_was(monkeypatch):
    """main() called in a process (-q) restores the root logger's level and handlers."""
    root = logging.getLogger()
    monkeypatch.setattr(root, "handlers", [])
    monkeypatch.setattr(root, "level", logging.WARNING)
    q = ",".join(["0"] * 7)
    assert main(["fk", "--q", q, "-q"]) == 0
    assert root.level == logging.WARNING and root.handlers == []
