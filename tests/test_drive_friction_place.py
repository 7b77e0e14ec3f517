"""Where friction acts through a geared drive: a description's at the joints, identified
friction where it was identified, the drive file's own ``friction_at`` when it says one.

A URDF's ``<dynamics>`` and an MJCF's ``damping``/``frictionloss`` are joint friction by
definition; a geared drive file without ``friction_at`` read them at the motors
(``K^T f(K dq)``, a viscous term the gear ratio squared too large), so an MJCF exported from
a model identified through the drive, read back with the same drive file, validated at
6.3e5 % (unusable). References: closed forms (``r^2 fv`` at the joint for ``fv`` at a
gear-``r`` motor; ``fv dq + fc sign(dq)`` at the joints), MuJoCo's compiled model of the
export, and a simulated geared arm judged on a log the model did not see.
"""

from __future__ import annotations

import dataclasses
import warnings

import mujoco
import numpy as np

from dynid.exceptions import DynidWarning
from dynid.friction.model import ClassicalFriction, own_at_motors_note, robot_friction
from dynid.io.drive_file import drive_toml, load_drive, with_file_rotors
from dynid.io.robot.export_options import ExportOptions
from dynid.io.robot.mjcf import save_mjcf
from dynid.io.robot.mjcf_read import load_mjcf
from dynid.io.robot.urdf import export_urdf, load_urdf
from dynid.io.torque_log import save_torque_log
from dynid.model.drive import Drive
from dynid.simulation.measurement import SensorNoise
from dynid.workflows.validate import ValidateOptions, validate_files

from conftest import planar_2r, recordings

GEARS = np.array([100.0, 50.0])
ROTORS = np.array([3e-4, 2e-4])  # kg m^2 at the motors
FV_M, FC_M = np.array([2e-4, 3e-4]), np.array([4e-3, 5e-3])  # N m s/rad, N m at the motors
NOISE = SensorNoise(tau_std=0.02)


def _arm():
    lim = np.array([2.5, 2.5])
    return planar_2r().replace(q_min=-lim, q_max=lim, dq_max=lim, ddq_max=4 * lim)


def _drive(**kw):
    """The drive file of the tests: gears 100 and 50, joint-side torques, rotors known."""
    return Drive.from_gears(GEARS, side="joint", rotor_inertia=ROTORS, **kw)


def test_a_drive_keeps_friction_at_as_given(tmp_path):
    """friction_at not given stays None through replace and the TOML table; the resolved
    place is the motors for a geared K and the joints for K = 1; given, it is kept."""
    d = _drive()
    assert d.friction_at is None and not d.friction_at_given and d.friction_place == "motor"
    assert dataclasses.replace(d, rotor_inertia=None).friction_at is None
    assert Drive.identity(2).friction_place == "joint"
    assert _drive(friction_at="joint").friction_place == "joint"
    assert _drive(friction_at="motor").friction_at_given
    path = tmp_path / "drive.toml"
    for given in (None, "joint", "motor"):
        path.write_text(drive_toml(_drive(friction_at=given)).replace("[drive]\n", ""))
        assert load_drive(path, 2).friction_at == given


def test_viscous_friction_at_a_gear_r_motor_is_r_squared_at_the_joint():
    """Closed form: fv at the motor of a gear-r drive is r^2 fv at the joint, fc is r fc."""
    r, fv, fc = 80.0, 3e-4, 2e-3
    law = ClassicalFriction(np.array([fv]), np.array([fc]), np.zeros(1))
    dq = np.array([[0.3], [-0.7]])
    at_motor = law.at(Drive.from_gears([r]))
    np.testing.assert_allclose(at_motor.torques(dq), r**2 * fv * dq + r * fc * np.sign(dq))


def _mjcf(tmp_path, fv, fc):
    """A hand-written 2R MJCF with joint damping fv and frictionloss fc."""
    path = tmp_path / "arm.xml"
    joint = '<joint name="j{k}" type="hinge" axis="0 0 1" damping="{v}" frictionloss="{c}"/>'
    inertial = '<inertial pos="0.2 0 0" mass="1" diaginertia="0.01 0.01 0.01"/>'
    path.write_text(
        "<mujoco><worldbody>"
        f'<body name="l1">{joint.format(k=1, v=fv[0], c=fc[0])}{inertial}'
        f'<body name="l2" pos="0.4 0 0">{joint.format(k=2, v=fv[1], c=fc[1])}{inertial}'
        "</body></body></worldbody></mujoco>"
    )
    return path


def test_a_descriptions_friction_stays_at_the_joints_unless_the_drive_file_says_motor(tmp_path):
    """MJCF and URDF joint friction through a geared drive without friction_at: fv dq +
    fc sign(dq) at the joints (MuJoCo's compiled damping and frictionloss), no note; the
    drive file saying friction_at = "motor": K^T f(K dq), named in one line."""
    fv, fc = np.array([0.5, 0.3]), np.array([0.8, 0.4])
    path = _mjcf(tmp_path, fv, fc)
    m = mujoco.MjModel.from_xml_path(str(path))
    np.testing.assert_allclose(m.dof_damping, fv)
    np.testing.assert_allclose(m.dof_frictionloss, fc)
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", DynidWarning)
        mjcf = load_mjcf(path)
        hard = mjcf.with_friction(ClassicalFriction(fv, fc, np.zeros(2)))  # the law given
        urdf = load_urdf(export_urdf(tmp_path / "arm.urdf", hard, ExportOptions(friction=True)))
    dq = np.array([[0.3, -0.2], [-0.05, 0.4]])
    for robot in (mjcf, urdf):
        placed = robot_friction(robot, _drive())
        # MJCF: MuJoCo's frictionloss is read as the ramp it applies (a smooth law about
        # 1e-3 rad/s wide at its default solreffriction), saturated at these speeds
        tol = 1e-4 if robot is mjcf else 1e-12
        np.testing.assert_allclose(placed.torques(dq), fv * dq + fc * np.sign(dq), rtol=tol)
        assert own_at_motors_note(robot, _drive()) is None
        moved = robot_friction(robot, _drive(friction_at="motor"))
        v = dq * GEARS
        np.testing.assert_allclose(moved.torques(dq), GEARS * (fv * v + fc * np.sign(v)), rtol=tol)
        said = own_at_motors_note(robot, _drive(friction_at="motor"))
        assert said is not None and 'friction_at = "motor"' in said and "\n" not in said


def test_an_export_of_motor_friction_read_back_with_its_drive_file_validates_at_the_noise(
    tmp_path,
):
    """A 2R arm with gears 100 and 50 and Coulomb and viscous friction at the motors,
    exported to MJCF and URDF (friction reflected to the joints) and read back with the
    same drive: on a held-out noisy log both predict as the true model does (0.47 %, its
    noise floor; a classical law reflects exactly through a diagonal drive); read at the
    motors, as a geared drive's default did, the MJCF gave 9.9e4 %."""
    drive = _drive()
    law = ClassicalFriction(FV_M, FC_M, np.zeros(2)).at(drive)
    arm = _arm().with_friction(law)
    rotors = GEARS**2 * ROTORS  # K^T diag(I_a) K of a diagonal K, at the joints
    (log,) = recordings(
        arm.with_friction(None), [5], friction=law, armature=rotors, duration=4.0, noise=NOISE
    )
    csv = save_torque_log(tmp_path / "held_out.csv", log)
    opts = ValidateOptions(drive=drive, cutoff_hz=20.0)
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", DynidWarning)
        xml = save_mjcf(tmp_path / "arm.xml", arm, friction=law, drive=drive)
        urdf = export_urdf(tmp_path / "arm.urdf", arm, ExportOptions(friction=law, drive=drive))
        truth = validate_files(arm, csv, opts).validation.errors.relative_error_percent
        errors = {}
        for name, robot in (("mjcf", load_mjcf(xml)), ("urdf", load_urdf(urdf))):
            robot = robot.replace(gravity=arm.gravity)  # a URDF holds no gravity
            errors[name] = validate_files(robot, csv, opts).validation.errors
        wrong = dataclasses.replace(drive, friction_at="motor")
        moved = validate_files(load_mjcf(xml), csv, dataclasses.replace(opts, drive=wrong))
    # the URDF holds the law exactly; the MJCF the ramp MuJoCo applies in its place (read
    # back as that ramp), within 1 % of the law's error
    assert abs(errors["urdf"].relative_error_percent - truth) < 1e-6, (errors["urdf"], truth)
    assert abs(errors["mjcf"].relative_error_percent - truth) < 0.01 * truth, (errors, truth)
    assert moved.validation.errors.relative_error_percent > 100 * truth


def test_a_drive_file_that_identifies_its_rotors_takes_the_mjcf_armature(tmp_path):
    """A drive file leaving the rotors to identify, validating an MJCF export: the rotor
    inertias at the motors are those whose K^T diag(I_a) K diagonal MuJoCo compiled as
    armature (exact for the coupled K of the export), said in a note; a URDF holds none,
    said too (the Panda export validated at 19.5 % with no word)."""
    drive = Drive.from_gears(GEARS, [(2, 1, 20.0)], side="joint", rotor_inertia=ROTORS)
    K = drive.transmission
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", DynidWarning)
        xml = save_mjcf(tmp_path / "arm.xml", _arm(), friction=False, drive=drive)
        urdf = export_urdf(tmp_path / "arm.urdf", _arm(), ExportOptions(friction=False))
    armature = mujoco.MjModel.from_xml_path(str(xml)).dof_armature
    np.testing.assert_allclose(armature, np.diag(K.T @ np.diag(ROTORS) @ K), rtol=1e-12)
    unknown = dataclasses.replace(drive, rotor_inertia=None)
    got, said = with_file_rotors(unknown, xml, 2)
    np.testing.assert_allclose(got.rotor_inertia, ROTORS, rtol=1e-9)
    assert said is not None and "armature" in said
    got, said = with_file_rotors(unknown, urdf, 2)
    assert got.rotor_inertia is None and said is not None and "holds none" in said
