"""A robot TOML's ``[friction]`` table acts where its ``at`` says, through any drive.

Reference: closed forms of the classical law on a geared drive (gear ratio ``k`` per joint,
rotor inertia ``I_a``): at the joints ``tau_f = fv dq + fc sign(dq) + fo``; at the motors
``tau_f = k (fv k dq + fc sign(dq) + fo)``; the rotors add ``k^2 I_a ddq``; the rigid body
is the frictionless Panda's inverse dynamics. Before, a table written ``at = "joint"``
beside a geared ``[drive]`` was placed at the motors by that drive (``x k^2`` on the viscous
term: a validation error of 9e4 %), and ``at`` written or not changed nothing.
"""

from __future__ import annotations

import numpy as np
import pytest

import dynid
from dynid.dynamics.rnea import rnea
from dynid.friction.model import robot_friction
from dynid.friction.validation import own_friction, validate_torques
from dynid.io.drive_file import drive_of_robot_file
from dynid.io.robot.toml import load_toml, save_toml
from dynid.model.drive import Drive
from dynid.simulation.measurement import SensorNoise, sample_times, simulate_measurement
from dynid.simulation.trajectories import random_fourier

GEAR = np.array([100.0, 100.0, 100.0, 80.0, 80.0, 50.0, 50.0])
IA = np.full(7, 2e-5)  # kg m^2 at the motors
FV = np.linspace(1.0, 0.2, 7)  # N m s/rad
FC = np.linspace(1.5, 0.3, 7)  # N m
FO = np.linspace(0.2, -0.1, 7)  # N m
BAND = np.full(7, 1e-3)  # rad/s


def _list(x: np.ndarray) -> str:
    return "[" + ", ".join(repr(float(v)) for v in x) + "]"


def _file(tmp_path, at: str | None, drive: bool = True, name: str = "r.toml"):
    """The frictionless Panda with a ``[drive]`` table (or none) and a classical
    ``[friction]`` table written ``at`` (no line for None)."""
    text = save_toml(tmp_path / "base.toml", dynid.panda().with_friction(None)).read_text()
    if drive:
        text += f"\n[drive]\ngear_ratio = {_list(GEAR)}\nrotor_inertia = {_list(IA)}\n"
    text += '\n[friction]\nmodel = "classical"\n' + ("" if at is None else f'at = "{at}"\n')
    text += f"fv = {_list(FV)}\nfc = {_list(FC)}\nfo = {_list(FO)}\n"
    text += f"standstill_band = {_list(BAND)}\n"
    path = tmp_path / name
    path.write_text(text)
    return path


def _sign(v: np.ndarray) -> np.ndarray:
    """``sign(v)``, 0 inside the standstill band."""
    return np.where(np.abs(v) > BAND, np.sign(v), 0.0)


def _at_joints(dq: np.ndarray) -> np.ndarray:
    return FV * dq + FC * _sign(dq) + FO


def _at_motors(dq: np.ndarray) -> np.ndarray:
    return GEAR * (FV * GEAR * dq + FC * _sign(GEAR * dq) + FO)


@pytest.fixture(scope="module")
def motion():
    """Exact joint states of a Panda."""
    panda = dynid.panda()
    t = sample_times(1.0, 200.0)
    return random_fourier(panda, np.random.default_rng(3))(t)


@pytest.mark.parametrize("at", ["joint", None])
def test_friction_written_at_the_joints_acts_there_through_a_geared_drive(tmp_path, motion, at):
    """Simulation, validation, the observer and payload identification read the robot's
    friction through :func:`robot_friction`: the friction at the joints, not ``x k^2``."""
    path = _file(tmp_path, at)
    robot, drive = load_toml(path), drive_of_robot_file(path, 7)
    assert drive.friction_place == "motor"  # the [drive] table alone would put it there
    q, dq, ddq = motion.q, motion.dq, motion.ddq
    truth = rnea(dynid.panda(), q, dq, ddq) + _at_joints(dq) + GEAR**2 * IA * ddq
    log = simulate_measurement(
        robot, motion, rng=np.random.default_rng(0), noise=SensorNoise.none(), drive=drive
    )
    np.testing.assert_allclose(log.tau, truth, rtol=0, atol=1e-9)
    for other in (drive, Drive.from_gears(np.full(7, 30.0)), None):  # any drive given with it
        np.testing.assert_allclose(
            own_friction(robot, other).torques(dq), _at_joints(dq), rtol=0, atol=1e-12
        )
    v = validate_torques(robot, log, friction=own_friction(robot, drive), drive=drive)
    assert v.errors.relative_error_percent < 1.0  # 9e4 % when placed at the motors
    back = load_toml(save_toml(tmp_path / "back.toml", robot))  # the place is written back
    np.testing.assert_allclose(
        robot_friction(back, drive).torques(dq), _at_joints(dq), rtol=0, atol=1e-12
    )


def test_friction_written_at_the_motors_acts_there(tmp_path, motion):
    path = _file(tmp_path, "motor")
    robot, dq = load_toml(path), motion.dq
    for other in (drive_of_robot_file(path, 7), Drive.identity(7), None):
        np.testing.assert_allclose(
            own_friction(robot, other).torques(dq), _at_motors(dq), rtol=1e-12, atol=1e-9
        )


def test_friction_at_the_joints_without_a_drive_table_stays_there(tmp_path, motion):
    """A description without ``[drive]`` used with a geared drive of its own (``--drive``):
    the friction stays at the joints, and the description written back has no drive."""
    robot, dq = load_toml(_file(tmp_path, "joint", drive=False)), motion.dq
    geared = Drive.from_gears(GEAR, rotor_inertia=IA)
    np.testing.assert_allclose(
        robot_friction(robot, geared).torques(dq), _at_joints(dq), rtol=0, atol=1e-12
    )
    text = save_toml(tmp_path / "back.toml", robot).read_text()
    assert "[drive]" not in text and 'at = "joint"' in text


def test_a_friction_file_acts_where_simulation_put_it_for_validate_and_observe(tmp_path):
    """A per-joint friction file given to simulate, validate and observe through a geared
    drive (friction at the motors): the three place it alike, per motor. validate read
    the true model on its own simulated log as "unusable, 100 %" (the file at the joints)
    and observe --calibrate set thresholds of about 1e5 N m without a word."""
    import json

    from dynid.cli.__main__ import main
    from dynid.friction.model import ClassicalFriction
    from dynid.io.friction_json import save_friction_json

    fr = save_friction_json(
        tmp_path / "fr.json",
        ClassicalFriction(np.full(7, 2e-4), np.full(7, 2e-3), np.zeros(7)),
    )
    drive = tmp_path / "drive.toml"
    drive.write_text(
        'schema = "dynid-drive/1"\nside = "motor"\ngear_ratio = [50.0, 50, 50, 50, 30, 30, 30]\n'
    )
    common = ["--robot", "panda", "--drive", str(drive), "--friction", str(fr)]
    log = tmp_path / "log.csv"
    argv = ["simulate", *common, "--duration", "6", "--rate", "500", "--seed", "2", "-q"]
    assert main([*argv, "--out", str(log)]) == 0
    argv = ["validate", *common, "--data", str(log), "--no-figures", "-q"]
    assert main([*argv, "--out", str(tmp_path / "v")]) == 0
    doc = json.loads((tmp_path / "v" / "validation.json").read_text())
    assert doc["with_friction"]["relative_error_percent"] < 2 * doc["noise_floor_percent"]
    common[common.index("--robot")] = "--params"
    argv = ["observe", *common, "--data", str(log), "--calibrate", "--no-figures", "-q"]
    assert main([*argv, "--out", str(tmp_path / "c")]) == 0
    th = json.loads((tmp_path / "c" / "thresholds.json").read_text())
    assert max(th["contact"]) < 5.0  # N m: the model's error, not the file misplaced
