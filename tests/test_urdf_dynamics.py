"""A URDF's ``<dynamics damping friction>`` read as the robot's own joint friction, as
Pinocchio reads it (``model.damping``, ``model.friction``)."""

from __future__ import annotations

import json
import logging
import re

import numpy as np
import pytest

import dynid
from dynid.cli.__main__ import main
from dynid.exceptions import ModelError
from dynid.friction.model import ClassicalFriction, robot_friction
from dynid.identification.classical import identify_from_log
from dynid.io.robot.export_options import ExportOptions
from dynid.io.robot.toml import load_toml, save_toml
from dynid.io.robot.urdf import export_urdf, load_urdf, robot_from_urdf_string
from dynid.model.drive import Drive
from dynid.simulation.measurement import SensorNoise, sample_times, simulate_measurement
from dynid.simulation.trajectories import random_fourier

from conftest import planar_2r, robot_data_urdf

pin = pytest.importorskip("pinocchio")

FV = np.array([0.37, 0.0])  # N m s/rad
FC = np.array([0.81, 0.23])  # N m


def _pinocchio_friction(path: str, names: tuple[str, ...]) -> tuple[np.ndarray, np.ndarray]:
    """Pinocchio's damping and friction of the joints ``names`` read from ``path``."""
    model = pin.buildModelFromUrdf(path)
    idx = [model.joints[model.getJointId(name)].idx_v for name in names]
    return np.asarray(model.damping)[idx], np.asarray(model.friction)[idx]


def _planar() -> dynid.Robot:
    """The planar two-link arm with limits (a trajectory can be drawn for it)."""
    lim = np.array([2.5, 2.5])
    return planar_2r().replace(q_min=-lim, q_max=lim, dq_max=lim, ddq_max=4 * lim)


def _arm(tmp_path, fv=FV, fc=FC) -> str:
    """The planar two-link arm written by dynid's export with joint friction ``fv, fc``."""
    path = tmp_path / "arm.urdf"
    export_urdf(path, _planar(), ExportOptions(friction=ClassicalFriction(fv, fc, 0 * fv)))
    return str(path)


def test_export_then_load_gives_the_same_friction_as_pinocchio_reads(tmp_path, caplog):
    """export_urdf -> load_urdf: the coefficients to 1e-12, equal to Pinocchio's reading of
    the same file, and one log line naming the joints that hold friction."""
    path = _arm(tmp_path)
    with caplog.at_level(logging.INFO, logger="dynid.io.robot.urdf_parse"):
        robot = load_urdf(path)
    fr = robot.friction
    assert fr.kind == "classical" and fr.drive is None  # per joint: a description's
    np.testing.assert_allclose(fr.fv, FV, rtol=0, atol=1e-12)
    np.testing.assert_allclose(fr.fc, FC, rtol=0, atol=1e-12)
    np.testing.assert_array_equal(fr.fo, 0.0)
    damping, friction = _pinocchio_friction(path, robot.joint_names)
    np.testing.assert_allclose(fr.fv, damping, rtol=0, atol=1e-12)
    np.testing.assert_allclose(fr.fc, friction, rtol=0, atol=1e-12)
    notes = [r.getMessage() for r in caplog.records if "<dynamics>" in r.getMessage()]
    assert len(notes) == 1 and "of joints joint1, joint2" in notes[0]


def test_damping_only_is_viscous_friction_of_that_joint(tmp_path, caplog):
    """``<dynamics damping="0.5"/>`` on the second joint alone: fv = (0, 0.5), no Coulomb
    friction, as Pinocchio reads it; the note names that joint alone."""
    text = tmp_path / "x.urdf"
    export_urdf(text, _planar(), ExportOptions(friction=False))
    xml = re.sub(
        r'(<joint name="joint2"[^>]*>)', r'\1\n    <dynamics damping="0.5"/>', text.read_text()
    )
    assert xml.count("<dynamics") == 1
    text.write_text(xml)
    with caplog.at_level(logging.INFO, logger="dynid.io.robot.urdf_parse"):
        robot = load_urdf(text)
    np.testing.assert_array_equal(robot.friction.params, [[0.0, 0.0, 0.0], [0.5, 0.0, 0.0]])
    damping, friction = _pinocchio_friction(str(text), robot.joint_names)
    np.testing.assert_array_equal(robot.friction.fv, damping)
    np.testing.assert_array_equal(robot.friction.fc, friction)
    notes = [r.getMessage() for r in caplog.records if "<dynamics>" in r.getMessage()]
    assert len(notes) == 1 and notes[0].endswith("of joints joint2 (damping as viscous N m s/rad, "
                                                 "friction as Coulomb N m)")  # fmt: skip


@pytest.mark.parametrize(
    ("rel", "base", "tip", "held"),
    [
        ("panda_description/urdf/panda.urdf", "panda_link0", "panda_hand_tcp", True),
        ("xarm_description/urdf/xarm7.urdf", None, None, True),
        ("z1_description/urdf/z1.urdf", None, None, True),
        ("ur_description/urdf/ur5_robot.urdf", "base_link", "tool0", False),
    ],
)
def test_example_robot_data_friction_is_pinocchios(rel, base, tip, held):
    """example-robot-data's arms: the chain's joint friction is Pinocchio's (the Panda's
    damping 0.003 with friction 0, the xArm's and Z1's tuning values); the UR5's zeros are
    no friction."""
    path = robot_data_urdf(rel)
    robot = load_urdf(path, base, tip, snap_angles=True)
    damping, friction = _pinocchio_friction(path, robot.joint_names)
    if not held:
        assert robot.friction is None
        assert not np.any(damping) and not np.any(friction)
        return
    np.testing.assert_array_equal(robot.friction.fv, damping)
    np.testing.assert_array_equal(robot.friction.fc, friction)


@pytest.mark.parametrize(
    ("attrs", "said"),
    [
        ('damping="-0.1"', "'damping' must be a finite number >= 0"),
        ('friction="inf"', "'friction' must be a finite number >= 0"),
        ('damping="x"', "'damping' must be a number"),
    ],
)
def test_a_negative_or_unreadable_coefficient_is_refused_naming_the_joint(attrs, said):
    xml = (
        '<robot name="r"><link name="a"/><link name="b"/>'
        '<joint name="j" type="continuous"><parent link="a"/><child link="b"/>'
        f"<dynamics {attrs}/></joint></robot>"
    )
    with pytest.raises(ModelError, match=f"joint 'j' <dynamics> attribute {said}"):
        robot_from_urdf_string(xml)


def test_simulated_torques_hold_pinocchios_friction(tmp_path):
    """simulate's ground truth with the robot's own friction: the log's torques minus
    Pinocchio's RNEA are damping dq + friction sign(dq), with Pinocchio's coefficients."""
    path = _arm(tmp_path)
    robot = load_urdf(path)
    t = sample_times(1.0, 200.0)
    log = simulate_measurement(
        robot,
        random_fourier(robot, np.random.default_rng(3))(t),
        rng=np.random.default_rng(4),
        noise=SensorNoise.none(),
        with_ddq=True,
    )
    model = pin.buildModelFromUrdf(path)
    model.gravity.linear[:] = robot.gravity
    data = model.createData()
    rnea = np.array(
        [pin.rnea(model, data, q, v, a) for q, v, a in zip(log.q, log.dq, log.ddq, strict=True)]
    )
    damping, friction = _pinocchio_friction(path, robot.joint_names)
    expected = damping * log.dq + friction * np.sign(log.dq)
    np.testing.assert_allclose(log.tau - rnea, expected, rtol=0, atol=1e-9)


def test_toml_export_and_validate_use_the_urdf_friction(tmp_path):
    """The URDF robot's friction is its own everywhere: the TOML export holds it (read back
    equal), and validate --robot arm.urdf adds it to the rigid body (the friction-free log
    of a friction-free robot would not need it: here without it the error is large)."""
    path = _arm(tmp_path)
    robot = load_urdf(path)
    save_toml(tmp_path / "arm.toml", robot)
    np.testing.assert_array_equal(load_toml(tmp_path / "arm.toml").friction.params,
                                  robot.friction.params)  # fmt: skip
    log = tmp_path / "log.csv"
    sim = ["simulate", "--robot", path, "--trajectory", "fourier", "--duration", "6"]
    assert main([*sim, "--rate", "250", "--seed", "2", "--out", str(log)]) == 0
    out = tmp_path / "v"
    argv = ["validate", "--robot", path, "--data", str(log), "--no-figures", "--out", str(out)]
    assert main(argv) == 0
    doc = json.loads((out / "validation.json").read_text())
    assert (
        doc["with_friction"]["relative_error_percent"]
        < 0.2 * (doc["without_friction"]["relative_error_percent"])
    )


def test_identify_does_not_read_the_robots_friction(tmp_path):
    """identify selects its own friction: the same log identified with the URDF robot (its
    friction read) and with the robot without friction gives the same coefficients."""
    robot = load_urdf(_arm(tmp_path))
    t = sample_times(4.0, 200.0)
    log = simulate_measurement(
        robot,
        random_fourier(robot, np.random.default_rng(5))(t),
        rng=np.random.default_rng(6),
        noise=SensorNoise.none(),
        with_ddq=True,
    )
    a = identify_from_log(robot, log, cutoff_hz=None, structure="classical", estimator="ols")
    b = identify_from_log(
        robot.with_friction(None), log, cutoff_hz=None, structure="classical", estimator="ols"
    )
    np.testing.assert_array_equal(a.fit.beta, b.fit.beta)
    np.testing.assert_allclose(a.frictions[0].params[:, :2], np.c_[FV, FC], atol=1e-6)


def test_the_urdf_friction_stays_at_the_joints_through_a_geared_drive(tmp_path):
    """``<dynamics>`` is joint friction: read through a drive of gear ratio 50 (whose own
    friction acts at the motors) it stays ``fv dq + fc sign(dq)`` at the joints; it was
    placed at the motors, ``K^T f(K dq)``, 2500 times the viscous torque."""
    robot = load_urdf(_arm(tmp_path))
    drive = Drive.from_gears([50.0, 50.0])
    assert drive.friction_place == "motor"
    dq = np.array([[0.3, -0.2], [-0.05, 0.4]])
    placed = robot_friction(robot, drive)
    np.testing.assert_allclose(placed.torques(dq), FV * dq + FC * np.sign(dq), atol=1e-12)
