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


def _pinocchio_panda_log(path, n_samples=2000, rate=500.0):
    """A smooth motion of example-robot-data's Panda and its torques from Pinocchio's RNEA
    (fingers locked at rest) plus the URDF's joint damping, written as a torque log."""
    import numpy as np
    import pinocchio as pin

    from conftest import pinocchio_panda_urdf

    full = pin.buildModelFromUrdf(pinocchio_panda_urdf())
    lock = [full.getJointId(n) for n in ("panda_finger_joint1", "panda_finger_joint2")]
    model = pin.buildReducedModel(full, lock, pin.neutral(full))
    model.gravity.linear = np.array([0.0, 0.0, -9.80665])
    data = model.createData()
    t = np.arange(n_samples) / rate
    w = 2 * np.pi * np.linspace(0.2, 0.5, 7)
    amp, mid = np.full(7, 0.4), np.array([0.0, 0.0, 0.0, -1.5, 0.0, 1.5, 0.0])
    q = mid + amp * np.sin(np.outer(t, w))
    dq = amp * w * np.cos(np.outer(t, w))
    ddq = -amp * w**2 * np.sin(np.outer(t, w))
    tau = np.stack([pin.rnea(model, data, *x) for x in zip(q, dq, ddq, strict=True)])
    tau += model.damping * dq  # the URDF's <dynamics damping>, as Pinocchio reads it
    head = ",".join(["t", *(f"{c}{i}" for c in ("q", "dq", "tau", "ddq") for i in range(1, 8))])
    rows = np.column_stack([t, q, dq, tau, ddq])
    with open(path, "w") as f:
        f.write("# units: t [s], q [rad], dq [rad/s], tau [N m], ddq [rad/s^2]\n")
        f.write(f"# rows: {n_samples}\n{head}\n")
        np.savetxt(f, rows, delimiter=",", fmt="%.17g")


def test_validate_params_urdf_takes_base_and_tip_as_robot_does(tmp_path):
    """validate --params panda.urdf --base --tip (a URDF whose hand has two fingers: several
    leaves) reads the chain as --robot does and predicts Pinocchio's torques of the same
    file to the filter's error (before: --base refused, "applies to a URDF --robot only",
    and without it the run failed on the several leaf links)."""
    import pytest

    pytest.importorskip("pinocchio")
    from conftest import pinocchio_panda_urdf

    log = tmp_path / "log.csv"
    _pinocchio_panda_log(log)
    got = {}
    for flag in ("--robot", "--params"):
        out = tmp_path / flag.strip("-")
        argv = ["validate", flag, pinocchio_panda_urdf(), "--data", str(log), "--no-figures"]
        argv += ["--base", "panda_link0", "--tip", "panda_hand", "-q", "--out", str(out)]
        assert main(argv) == 0, flag
        got[flag] = json.loads((out / "validation.json").read_text())
    assert got["--params"]["relative_error_percent"] < 0.05
    for key in ("relative_error_percent", "noise_floor_percent"):
        assert got["--params"][key] == got["--robot"][key], key
