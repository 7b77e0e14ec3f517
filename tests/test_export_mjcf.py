"""MJCF export: MuJoCo loads it and its inverse dynamics equal dynid's RNEA; friction fit.

References: MuJoCo's ``mj_inverse`` (an independent implementation of rigid-body inverse
dynamics) on the exported file; the closed form of a step-like sigmoid's odd part.
"""

from __future__ import annotations

import numpy as np
import pytest

import dynid
from dynid.exceptions import DataError, ShapeError
from dynid.friction.mujoco import coulomb_viscous_from_sigmoid
from dynid.io.export import export_format, save_robot
from dynid.io.robot.mjcf import mjcf_from_robot, save_mjcf

from conftest import mujoco_inverse, planar_2r, random_states, robot_data_urdf

mujoco = pytest.importorskip("mujoco")


def _rpp_robot() -> dynid.Robot:
    """A 3-joint arm with two prismatic joints, tilted gravity and off-axis inertials."""
    rng = np.random.default_rng(7)
    mass = np.array([2.0, 1.5, 0.7])
    sides = rng.uniform(0.05, 0.3, (3, 3))  # solid boxes [m], rotated at random
    box = mass[:, None] / 12 * (np.sum(sides**2, axis=1, keepdims=True) - sides**2)
    R = np.linalg.qr(rng.normal(size=(3, 3, 3)))[0]
    inertia = R @ (box[:, :, None] * np.eye(3)) @ np.swapaxes(R, 1, 2)
    return dynid.Robot.from_mdh(
        [0.0, 0.2, 0.1],
        [0.3, 0.1, 0.05],
        [0.0, -np.pi / 2, np.pi / 2],
        [0.1, 0.2, -0.3],
        joint_types="RPP",
        flange=(0.0, 0.1, 0.0, 0.0),
        mass=mass,
        com=rng.normal(scale=0.05, size=(3, 3)),
        inertia=inertia,
        q_min=[-2.0, -0.2, -0.1],
        q_max=[2.0, 0.3, 0.2],
        gravity=(0.5, -1.0, -9.7),
        name="rpp",
    )


def _ur5_from_urdf() -> dynid.Robot:
    """UR5 of example-robot-data: URDF joint frames with rpy, fixed links as sites."""
    path = robot_data_urdf("ur_description/urdf/ur5_robot.urdf")
    return dynid.Robot.from_urdf(path, "base_link", "tool0")


@pytest.mark.parametrize("make", [dynid.panda, planar_2r, _rpp_robot, _ur5_from_urdf])
def test_mj_inverse_equals_rnea_at_random_states(make, tmp_path):
    """MuJoCo's mj_inverse on the frictionless export equals dynid rnea to 1e-9 relative."""
    robot = make()
    path = save_mjcf(tmp_path / "robot.xml", robot, friction=False)
    model = mujoco.MjModel.from_xml_path(str(path))
    assert model.nv == robot.n
    np.testing.assert_allclose(model.opt.gravity, robot.gravity, rtol=0, atol=0)
    q, dq, ddq = random_states(robot, 100, seed=3)
    tau_mj = mujoco_inverse(model, q, dq, ddq)
    tau = dynid.rnea(robot, q, dq, ddq)
    scale = np.max(np.abs(tau), axis=1, keepdims=True)
    assert np.max(np.abs(tau_mj - tau) / scale) < 1e-9


def test_mjcf_keeps_names_limits_and_flange_site(tmp_path):
    """Bodies and joints carry the robot's names; ranges are the limits; flange is a site."""
    robot = dynid.panda()
    model = mujoco.MjModel.from_xml_path(str(save_mjcf(tmp_path / "p.xml", robot)))
    for i, name in enumerate(robot.joint_names):
        j = mujoco.mj_name2id(model, mujoco.mjtObj.mjOBJ_JOINT, name)
        assert j == i
        np.testing.assert_allclose(model.jnt_range[j], [robot.q_min[i], robot.q_max[i]])
        assert model.jnt_limited[j]
    for name in robot.link_names:
        assert mujoco.mj_name2id(model, mujoco.mjtObj.mjOBJ_BODY, name) >= 0
    data = mujoco.MjData(model)
    q = dynid.PANDA_NEUTRAL_Q
    data.qpos[:] = q
    mujoco.mj_kinematics(model, data)
    site = mujoco.mj_name2id(model, mujoco.mjtObj.mjOBJ_SITE, "flange")
    np.testing.assert_allclose(data.site_xpos[site], dynid.fk(robot, q)[:3, 3], atol=1e-12)
    np.testing.assert_allclose(model.actuator_ctrlrange[:, 1], robot.tau_max)


def test_mjcf_friction_is_the_fitted_approximation(tmp_path):
    """Joint frictionloss and damping in MuJoCo are the Coulomb/viscous fit of the sigmoid."""
    robot = dynid.panda()
    text, approx = mjcf_from_robot(robot)
    model = mujoco.MjModel.from_xml_string(text)
    np.testing.assert_allclose(model.dof_frictionloss, approx.coulomb, rtol=1e-15)
    np.testing.assert_allclose(model.dof_damping, approx.viscous, rtol=1e-15)
    assert np.all(approx.coulomb > 0)
    _, none = mjcf_from_robot(robot, friction=False)
    assert none is None


def test_sigmoid_fit_of_a_step_is_coulomb():
    """A steep sigmoid centred at zero velocity has odd part phi1/2 sign(dq): f_c = phi1/2."""
    friction = np.array([[2.0, 1e6, 0.0], [0.6, 1e6, 0.0]])
    fit = coulomb_viscous_from_sigmoid(friction, [2.0, np.inf])
    np.testing.assert_allclose(fit.coulomb, [1.0, 0.3], rtol=1e-9)
    np.testing.assert_allclose(fit.viscous, 0.0, atol=1e-9)
    np.testing.assert_allclose(fit.offset, 0.0, atol=1e-9)
    np.testing.assert_allclose(fit.dq_max, [2.0, 2.0])


def test_sigmoid_fit_offset_is_the_even_part():
    """A shifted sigmoid saturates at phi1(1-s0) and -phi1 s0: the dropped offset is their mean."""
    p1, p2, p3 = 1.5, 1e3, 0.2
    s0 = 1.0 / (1.0 + np.exp(-p2 * p3))
    fit = coulomb_viscous_from_sigmoid([[p1, p2, p3]], [2.0])
    np.testing.assert_allclose(fit.offset, [p1 * (0.5 - s0)], rtol=1e-9)


def test_sigmoid_fit_rejects_bad_shapes():
    """friction must be (n, 3)."""
    with pytest.raises(ShapeError, match="friction must have shape"):
        coulomb_viscous_from_sigmoid(np.zeros((2, 2)), [1.0, 1.0])


def test_export_format_by_suffix_and_errors(tmp_path):
    """The format follows the suffix; an unknown suffix or a template for MJCF is refused."""
    assert export_format("a.urdf") == "urdf" and export_format("a.xml") == "mjcf"
    assert export_format("a.toml") == "toml" and export_format("a.txt", "mjcf") == "mjcf"
    with pytest.raises(DataError, match="cannot tell the format"):
        export_format("robot.txt")
    with pytest.raises(DataError, match="format must be one of"):
        export_format("robot.txt", "sdf")
    with pytest.raises(DataError, match="URDF template applies"):
        save_robot(tmp_path / "a.xml", dynid.panda(), template=tmp_path / "t.urdf")
    path = save_robot(tmp_path / "a.toml", dynid.panda())
    np.testing.assert_allclose(dynid.Robot.from_toml(path).phi, dynid.panda().phi, rtol=1e-15)


def test_a_format_is_one_line_of_the_table(tmp_path, monkeypatch):
    """A format registered in ROBOT_FORMATS is chosen by name and suffix, gets the export
    options, is a --format choice's source and has its file in an output folder."""
    from dynid.io import export
    from dynid.io.atomic import write_text
    from dynid.io.robot.export_options import ExportOptions, RobotFormat

    seen = []

    def export_names(path, robot, options):
        seen.append(options)
        return write_text(path, "\n".join(robot.joint_names) + "\n")

    monkeypatch.setitem(
        export.ROBOT_FORMATS, "names", RobotFormat("names", (".names", ".txt"), export_names)
    )
    panda = dynid.panda()
    assert export_format("a.txt") == "names"
    path = save_robot(tmp_path / "a.names", panda, all_frames=True)
    assert path.read_text().split() == [f"joint{i}" for i in range(1, 8)]
    assert seen[-1].all_frames is True
    with pytest.raises(DataError, match="URDF template applies"):
        save_robot(tmp_path / "b.txt", panda, template=tmp_path / "t.urdf")
    files = export.save_robot_files(tmp_path / "out", panda, ExportOptions(friction=False))
    assert [f.name for f in files] == ["robot.urdf", "robot.xml", "robot.toml", "robot.names"]
    assert seen[-1].friction is False
    back = dynid.Robot.from_urdf(files[0])  # the table's other writers wrote theirs
    np.testing.assert_allclose(back.phi, panda.phi, rtol=1e-15, atol=1e-18)
    np.testing.assert_allclose(dynid.Robot.from_toml(files[2]).phi, panda.phi, rtol=1e-15)


def test_identified_classical_friction_is_written_as_it_is():
    """Classical fv, fc go to damping and frictionloss exactly; the offset fo is reported."""
    robot = dynid.panda()
    fr = dynid.ClassicalFriction(np.linspace(0.1, 0.7, 7), np.linspace(0.2, 0.8, 7), np.ones(7))
    from dynid.exceptions import DynidWarning

    with pytest.warns(DynidWarning, match=r"offsets fo \(up to \+1 N m"):
        text, approx = mjcf_from_robot(robot, friction=fr)
    model = mujoco.MjModel.from_xml_string(text)
    np.testing.assert_array_equal(model.dof_damping, fr.fv)
    np.testing.assert_array_equal(model.dof_frictionloss, fr.fc)
    np.testing.assert_array_equal(approx.offset, fr.fo)
    with pytest.raises(ShapeError, match="friction has 2 joints"):
        mjcf_from_robot(robot, friction=dynid.ClassicalFriction(np.ones(2), np.ones(2), np.ones(2)))


def test_every_friction_law_is_written_as_its_mujoco_terms():
    """Each law of the registry: MuJoCo's compiled damping and frictionloss are what the
    law holds of viscous and dry friction (the smooth law's fv, fc; the asymmetric law's
    means; the Stribeck law's fv, fc), and what MJCF cannot hold is named in a warning."""
    from dynid.exceptions import DynidWarning
    from dynid.friction.laws import law_named

    robot = dynid.panda()
    r = np.linspace(1.0, 2.0, 7)[:, None]
    cases = {
        "smooth": (np.hstack([0.1 * r, 0.3 * r, 0.05 * r]), 0.1 * r, 0.3 * r, None),
        "asymmetric": (
            np.hstack([0.1 * r, 0.3 * r, 0.5 * r, 0.3 * r]), 0.2 * r, 0.4 * r, "asymmetry"
        ),
        "stribeck": (
            np.hstack([0.1 * r, 0.3 * r, 0.6 * r, 0.05 + 0 * r, 0 * r]), 0.1 * r, 0.3 * r,
            "Stribeck peak",
        ),
    }  # fmt: skip
    for name, (P, damping, loss, note) in cases.items():
        fr = law_named(name).model(P)
        if note is None:
            text, _ = mjcf_from_robot(robot, friction=fr)
        else:
            with pytest.warns(DynidWarning, match=note):
                text, _ = mjcf_from_robot(robot, friction=fr)
        model = mujoco.MjModel.from_xml_string(text)
        np.testing.assert_allclose(model.dof_damping, damping[:, 0], rtol=1e-12)
        np.testing.assert_allclose(model.dof_frictionloss, loss[:, 0], rtol=1e-12)


def test_massless_link_compiles_with_negligible_bound(tmp_path):
    """A massless moving link compiles (bounded to 1e-10 kg) and mj_inverse still equals rnea."""
    inertia = np.stack([np.zeros((3, 3)), np.diag([0.01, 0.02, 0.025])])
    robot = dynid.Robot.from_mdh(
        [0.0, 1.0],
        [0.0, 0.0],
        [0.0, np.pi / 2],
        mass=[0.0, 1.0],
        com=[[0, 0, 0], [0.5, 0, 0.1]],
        inertia=inertia,
    )
    model = mujoco.MjModel.from_xml_path(str(save_mjcf(tmp_path / "r.xml", robot)))
    np.testing.assert_allclose(model.body_mass[2:], [1e-10, 1.0])
    q, dq, ddq = random_states(robot, 50, seed=9)
    tau = dynid.rnea(robot, q, dq, ddq)
    assert np.max(np.abs(mujoco_inverse(model, q, dq, ddq) - tau)) < 1e-9 * np.max(np.abs(tau))


def test_mj_inverse_with_armature_equals_rnea_plus_rotor_torques(tmp_path):
    """A diagonal drive's rotor inertia exported as armature: MuJoCo's mj_inverse equals
    rnea + K^T diag(Ia) K ddq (issue 17) to 1e-9 relative."""
    from dynid.model.drive import Drive

    robot = _ur5_from_urdf()
    drive = Drive.from_gears(
        [101.0, 101.0, 101.0, 81.0, 81.0, 51.0], rotor_inertia=np.full(6, 2e-5), side="motor"
    )
    path = save_mjcf(tmp_path / "robot.xml", robot, friction=False, drive=drive)
    model = mujoco.MjModel.from_xml_path(str(path))
    np.testing.assert_allclose(
        model.dof_armature, np.diag(drive.rotor_mass_matrix(np.full(6, 2e-5)))
    )
    q, dq, ddq = random_states(robot, 50, seed=4)
    tau_mj = mujoco_inverse(model, q, dq, ddq)
    tau = dynid.rnea(robot, q, dq, ddq) + drive.rotor_torques(ddq, drive.rotor_inertia)
    scale = np.max(np.abs(tau), axis=1, keepdims=True)
    assert np.max(np.abs(tau_mj - tau) / scale) < 1e-9


def test_mjcf_coupled_rotor_says_what_it_drops(tmp_path):
    """A coupled wrist's off-diagonal rotor inertia is named in a warning, not dropped silently."""
    from dynid.exceptions import DynidWarning
    from dynid.model.drive import Drive

    robot = _ur5_from_urdf()
    drive = Drive.from_gears(
        [101.0] * 6, [(6, 5, 30.0)], rotor_inertia=np.full(6, 2e-5), side="motor"
    )
    with pytest.warns(DynidWarning, match="armature: the coupling's off-diagonal terms"):
        path = save_mjcf(tmp_path / "robot.xml", robot, friction=False, drive=drive)
    model = mujoco.MjModel.from_xml_path(str(path))
    # joint 5 carries its own rotor and motor 6's reflected through the coupling: 101^2 + 30^2
    assert model.dof_armature[4] == pytest.approx(2e-5 * (101.0**2 + 30.0**2), rel=1e-12)


def test_urdf_export_names_what_it_drops_and_mjcf_holds_it(tmp_path):
    """A coupled drive with rotor inertias and friction at its motors: the URDF export
    warns, in URDF's words, what of the coupled friction it drops and, on a line of its
    own, that it leaves out the armature (naming the MJCF export, which holds it); the
    URDF holds the reflected diagonal friction and no armature; MuJoCo reads the MJCF's armature as
    diag(K^T diag(I_a) K) and the same diagonal friction."""
    import warnings
    import xml.etree.ElementTree as ET

    from dynid.exceptions import DynidWarning
    from dynid.friction.model import ClassicalFriction
    from dynid.model.drive import Drive

    robot = _ur5_from_urdf()
    ia = np.full(6, 2e-5)
    drive = Drive.from_gears([101.0] * 6, [(6, 5, 30.0)], rotor_inertia=ia, side="motor")
    fv, fc = np.linspace(1e-3, 2e-3, 6), np.linspace(1e-2, 2e-2, 6)
    motor = ClassicalFriction(fv, fc, np.zeros(6)).at(drive)
    with warnings.catch_warnings(record=True) as got:
        warnings.simplefilter("always")
        urdf = save_robot(tmp_path / "r.urdf", robot, friction=motor, drive=drive)
    lines = [str(w.message) for w in got if issubclass(w.category, DynidWarning)]
    assert len(lines) == 2 and all(x.startswith("URDF export: ") for x in lines), lines
    assert "Coulomb friction of coupled motors" in lines[0] and "rotor" not in lines[0]
    assert "MJCF" not in lines[1].split("MJCF export (r.xml, not written)")[0], lines[1]
    assert "leaves out the drive's rotor inertias" in lines[1]
    assert "an MJCF export (r.xml, not written) would hold them as armature" in lines[1]
    K = drive.transmission
    arm = np.diag(K.T @ np.diag(ia) @ K)
    damping = np.diag(K.T @ np.diag(fv) @ K)
    joints = ET.parse(urdf).getroot().findall("joint")
    dyn = [j.find("dynamics") for j in joints if j.get("type") != "fixed"]
    assert [float(d.get("damping")) for d in dyn] == pytest.approx(damping, rel=1e-12)
    assert "armature" not in urdf.read_text()
    with pytest.warns(DynidWarning, match="MJCF export: "):
        xml = save_robot(tmp_path / "r.xml", robot, friction=motor, drive=drive)
    model = mujoco.MjModel.from_xml_path(str(xml))
    np.testing.assert_allclose(model.dof_armature, arm, rtol=1e-12)
    np.testing.assert_allclose(model.dof_damping, damping, rtol=1e-12)
    np.testing.assert_allclose(model.dof_frictionloss, np.abs(np.diag(K)) * fc, rtol=1e-12)


def test_a_coupled_drive_s_dropped_damping_reads_as_its_coupling():
    """Regression: the export sentence read "without viscous friction (damping): the
    coupling's off-diagonal terms have no per-joint term and are dropped" although the
    damping is written; what is left out is the coupling's off-diagonal terms."""
    from dynid.friction.mujoco import drive_joint_terms
    from dynid.io.robot.export_options import friction_losses

    K = np.eye(2)
    K[1, 0] = 0.8  # motor 2 turns with joint 1 too: a coupled wrist
    terms = drive_joint_terms(K, None, np.array([0.5, 0.3]), None)
    _, left = friction_losses("smooth", terms.notes)
    assert left.startswith("the coupling's off-diagonal terms of the viscous friction (damping)")
    assert "(largest: joints 1-2, 0.24 N m s/rad)" in left, left
    np.testing.assert_allclose(terms.damping, [0.5 + 0.8**2 * 0.3, 0.3])  # written: K^T diag K
