"""URDF import: chains of example-robot-data robots and synthetic URDFs against Pinocchio."""

from __future__ import annotations

import warnings

import numpy as np
import pytest

import dynid
from dynid.io.robot.urdf import load_urdf, robot_from_urdf_string

from conftest import random_states, robot_data_urdf

pin = pytest.importorskip("pinocchio")

PANDA = "panda_description/urdf/panda.urdf"
UR5 = "ur_description/urdf/ur5_robot.urdf"


def pin_model(model, robot: dynid.Robot):
    """Set Pinocchio's gravity to the robot's and return (model, data)."""
    model.gravity.linear[:] = robot.gravity
    return model, model.createData()


def assert_matches_pinocchio(robot: dynid.Robot, model, data, n_states: int, seed: int) -> None:
    """FK and Jacobian of every frame, RNEA, M, g and c equal Pinocchio's on random states."""
    q, dq, ddq = random_states(robot, n_states, seed=seed)
    frames = [k for k in robot.frames if k != "flange" or model.existFrame(k)]
    assert all(model.existFrame(k) for k in frames)
    T = {k: dynid.fk(robot, q, k) for k in frames}
    J = {k: dynid.jacobian(robot, q, k) for k in frames}
    tau = dynid.rnea(robot, q, dq, ddq)
    M = dynid.mass_matrix(robot, q)
    g = dynid.gravity_torques(robot, q)
    c = dynid.coriolis(robot, q, dq)
    for s in range(n_states):
        pin.forwardKinematics(model, data, q[s])
        pin.updateFramePlacements(model, data)
        pin.computeJointJacobians(model, data, q[s])
        for k in frames:
            fid = model.getFrameId(k)
            np.testing.assert_allclose(T[k][s], data.oMf[fid].homogeneous, atol=1e-12, err_msg=k)
            Jp = pin.getFrameJacobian(model, data, fid, pin.LOCAL_WORLD_ALIGNED)
            np.testing.assert_allclose(J[k][s], Jp, atol=1e-12, err_msg=k)
        np.testing.assert_allclose(tau[s], pin.rnea(model, data, q[s], dq[s], ddq[s]), atol=1e-10)
        Mp = pin.crba(model, data, q[s])
        np.testing.assert_allclose(M[s], np.triu(Mp) + np.triu(Mp, 1).T, atol=1e-10)
        gp = pin.computeGeneralizedGravity(model, data, q[s])
        np.testing.assert_allclose(g[s], gp, atol=1e-10)
        cp = pin.nonLinearEffects(model, data, q[s], dq[s]) - gp
        np.testing.assert_allclose(c[s], cp, atol=1e-10)


# ---------------------------------------------------------------------------- Panda
@pytest.fixture(scope="module")
def panda_urdf() -> str:
    return robot_data_urdf(PANDA)


@pytest.mark.parametrize("tip", ["panda_link8", "panda_hand"])
def test_panda_urdf_matches_pinocchio_on_random_states(panda_urdf, tip):
    """URDF Panda equals Pinocchio on the same file with the fingers locked at neutral:
    FK, J, RNEA, M, g, c (the fingers past the tip lumped into link 7 at their zero
    position, as Pinocchio's reduced model does; before, they were left out and a test
    had to add them as tools)."""
    robot = load_urdf(panda_urdf, "panda_link0", tip)
    full = pin.buildModelFromUrdf(panda_urdf)
    fingers = [full.getJointId(k) for k in ("panda_finger_joint1", "panda_finger_joint2")]
    model, data = pin_model(pin.buildReducedModel(full, fingers, pin.neutral(full)), robot)
    assert robot.n == model.nv == 7
    assert robot.frames["flange"].link == 7
    np.testing.assert_allclose(
        dynid.fk(robot, np.zeros(7), "flange"), dynid.fk(robot, np.zeros(7), tip), atol=0
    )
    assert_matches_pinocchio(robot, model, data, n_states=100, seed=11)


def test_panda_urdf_structure_names_limits_and_frames(panda_urdf):
    """Names, limits, gravity and frames are read from the URDF as written in it."""
    robot = dynid.Robot.from_urdf(panda_urdf, "panda_link0", "panda_hand")
    assert robot.name == "panda"
    assert robot.joint_names == tuple(f"panda_joint{i}" for i in range(1, 8))
    assert robot.link_names == tuple(f"panda_link{i}" for i in range(8))
    np.testing.assert_array_equal(
        robot.q_min, [-2.8973, -1.7628, -2.8973, -3.0718, -2.8973, -0.0175, -2.8973]
    )
    np.testing.assert_array_equal(
        robot.q_max, [2.8973, 1.7628, 2.8973, -0.0698, 2.8973, 3.7525, 2.8973]
    )
    np.testing.assert_array_equal(robot.dq_max, [2.175] * 4 + [2.61] * 3)
    np.testing.assert_array_equal(robot.tau_max, [87.0] * 4 + [12.0] * 3)
    assert np.all(np.isinf(robot.ddq_max))
    np.testing.assert_array_equal(robot.gravity, [0.0, 0.0, -9.80665])
    assert not np.any(robot.prismatic)
    # <dynamics damping="0.003" friction="0.0"/> on every arm joint: viscous friction only
    assert robot.friction.kind == "classical"
    np.testing.assert_array_equal(robot.friction.params, [[0.003, 0.0, 0.0]] * 7)
    assert set(robot.frames) == {f"panda_link{i}" for i in range(9)} | {
        "panda_hand",
        "panda_hand_tcp",
        "flange",
    }
    assert {"panda_leftfinger", "panda_rightfinger"}.isdisjoint(robot.frames)
    # link8 is 0.107 m along z7, the hand turned by -pi/4 about z, the TCP 0.1034 m further
    T7_hand = robot.frames["panda_hand"].T_link_frame
    c, s = np.cos(-np.pi / 4), np.sin(-np.pi / 4)
    np.testing.assert_allclose(T7_hand[:3, :3], [[c, -s, 0], [s, c, 0], [0, 0, 1]], atol=1e-16)
    np.testing.assert_allclose(T7_hand[:3, 3], [0, 0, 0.107], atol=1e-16)
    np.testing.assert_allclose(
        robot.frames["panda_hand_tcp"].T_link_frame[:3, 3], [0, 0, 0.107 + 0.1034], atol=1e-15
    )
    assert robot.frames["flange"].link == 7
    np.testing.assert_array_equal(robot.frames["flange"].T_link_frame, T7_hand)


def test_panda_urdf_loads_without_warnings(panda_urdf, caplog):
    """The Panda URDF's inertials are consistent and its two fingers (prismatic joints off
    the hand, past the tip) are lumped into link 7: loading it warns about nothing, and a
    note names the fingers with their 0.015 kg each as the file writes (before: a warning
    that they were left out)."""
    from dynid.progress import NOTE

    with warnings.catch_warnings(record=True) as caught, caplog.at_level(NOTE, logger="dynid"):
        warnings.simplefilter("always")
        load_urdf(panda_urdf, tip_link="panda_hand")
    assert [str(w.message) for w in caught] == []
    (said,) = [r.getMessage() for r in caplog.records if "lumped" in r.getMessage()]
    assert "panda_leftfinger (0.015 kg, inertia up to" in said
    assert "through prismatic joint 'panda_finger_joint1' on panda_hand" in said
    assert "panda_rightfinger (0.015 kg" in said


def test_panda_urdf_equals_builtin_mdh_panda(panda_urdf):
    """URDF and MDH (Gaz et al. 2019) Pandas agree in FK and, with equal inertials, in dynamics."""
    mdh = dynid.panda()
    urdf = load_urdf(panda_urdf, "panda_link0", "panda_link8")
    q, dq, ddq = random_states(mdh, 100, seed=12)
    np.testing.assert_allclose(
        dynid.link_poses(urdf, q)[:, 1:], dynid.link_poses(mdh, q)[:, 1:], atol=1e-12
    )
    np.testing.assert_allclose(
        dynid.fk(urdf, q, "panda_link8"), dynid.fk(mdh, q, "flange"), atol=1e-12
    )
    np.testing.assert_allclose(dynid.jacobian(urdf, q), dynid.jacobian(mdh, q), atol=1e-12)
    same = mdh.with_params(urdf.phi)
    np.testing.assert_allclose(
        dynid.rnea(urdf, q, dq, ddq), dynid.rnea(same, q, dq, ddq), atol=1e-10
    )
    np.testing.assert_allclose(dynid.mass_matrix(urdf, q), dynid.mass_matrix(same, q), atol=1e-10)
    # the URDF holds Gaz et al.'s values for links 1..6 (link 1's unidentifiable CoM z aside)
    np.testing.assert_allclose(urdf.mass[:6], mdh.mass[:6], rtol=1e-14)
    np.testing.assert_allclose(urdf.com[1:6], mdh.com[1:6], atol=1e-15)
    np.testing.assert_allclose(urdf.com[0, :2], mdh.com[0, :2], atol=1e-15)
    np.testing.assert_allclose(urdf.inertia[:6], mdh.inertia[:6], atol=1e-14)


def test_panda_hand_inertia_folds_into_link7(panda_urdf):
    """Link 7 carries link 7 plus the hand (0.73 kg at (-0.01, 0, 0.03) in the hand frame)
    plus the two fingers at rest (0.015 kg each, 0.0584 m past the hand along its z)."""
    robot = load_urdf(panda_urdf, "panda_link0", "panda_link8")
    m7, c7 = 0.735522, np.array([1.0517e-02, -4.252e-03, 6.1597e-02])
    T7_hand = robot.frames["panda_hand"].T_link_frame
    c_hand = T7_hand[:3, :3] @ [-0.01, 0.0, 0.03] + T7_hand[:3, 3]
    c_fingers = T7_hand[:3, :3] @ [0.0, 0.0, 0.0584] + T7_hand[:3, 3]
    np.testing.assert_allclose(robot.mass[6], m7 + 0.73 + 0.03, rtol=1e-15)
    np.testing.assert_allclose(
        robot.phi[6, 1:4], m7 * c7 + 0.73 * c_hand + 0.03 * c_fingers, atol=1e-15
    )


# ---------------------------------------------------------------------------- UR5
def test_ur5_urdf_matches_pinocchio_on_random_states():
    """UR5 (not modified DH; fixed world and tool links) equals Pinocchio: FK, J, RNEA, M, g, c."""
    path = robot_data_urdf(UR5)
    robot = load_urdf(path, tip_link="tool0")
    assert robot.link_names[0] == "world"
    assert robot.joint_names[0] == "shoulder_pan_joint"
    assert {"base_link", "base", "ee_link", "tool0"} <= set(robot.frames)
    assert robot.frames["base"].link == 0 and robot.frames["ee_link"].link == 6
    np.testing.assert_array_equal(
        robot.q_max, [6.28318530718] * 2 + [3.14159265359] + [6.28318530718] * 3
    )
    model, data = pin_model(pin.buildModelFromUrdf(path), robot)
    assert_matches_pinocchio(robot, model, data, n_states=100, seed=13)


# ---------------------------------------------------------------------------- synthetic URDFs
def _origin(rng: np.random.Generator) -> str:
    xyz = " ".join(repr(float(x)) for x in rng.uniform(-0.3, 0.3, 3))
    rpy = " ".join(repr(float(x)) for x in rng.uniform(-np.pi, np.pi, 3))
    return f'<origin xyz="{xyz}" rpy="{rpy}"/>'


def _inertial(rng: np.random.Generator) -> str:
    """A physically consistent inertial with a rotated principal frame."""
    x, y, z = rng.uniform(0.01, 0.1, 3)
    I = np.diag([y + z, x + z, x + y])  # principal moments meet the triangle inequality
    R = dynid.spatial.matrix_from_angle_axis(rng.normal(size=3))
    I = R @ I @ R.T
    vals = dict(ixx=I[0, 0], ixy=I[0, 1], ixz=I[0, 2], iyy=I[1, 1], iyz=I[1, 2], izz=I[2, 2])
    attrs = " ".join(f'{k}="{float(v)!r}"' for k, v in vals.items())
    return (
        f'<inertial>{_origin(rng)}<mass value="{float(rng.uniform(0.5, 3.0))!r}"/>'
        f"<inertia {attrs}/></inertial>"
    )


def _axis(rng: np.random.Generator) -> str:
    return " ".join(repr(float(x)) for x in rng.normal(size=3))


def synthetic_urdf(rng: np.random.Generator) -> str:
    """A URDF exercising every merge: fixed joints before, inside and after the chain, fixed
    links with inertia on and off the chain, unaligned axes, a prismatic joint, an off-chain
    moving branch and a floating joint off the chain."""
    return f"""<?xml version="1.0"?>
<robot name="synthetic">
  <link name="world"/>
  <link name="pedestal">{_inertial(rng)}</link>
  <link name="l1">{_inertial(rng)}</link>
  <link name="l1_cover">{_inertial(rng)}</link>
  <link name="l2">{_inertial(rng)}</link>
  <link name="l2_sensor">{_inertial(rng)}</link>
  <link name="l3">{_inertial(rng)}</link>
  <link name="l3_branch"/>
  <link name="l4">{_inertial(rng)}</link>
  <link name="tool">{_inertial(rng)}</link>
  <link name="tcp"/>
  <link name="drone"/>
  <joint name="mount" type="fixed"><parent link="world"/><child link="pedestal"/>
    {_origin(rng)}</joint>
  <joint name="j1" type="revolute"><parent link="pedestal"/><child link="l1"/>{_origin(rng)}
    <axis xyz="{_axis(rng)}"/><limit lower="-2" upper="2" effort="50" velocity="3"/></joint>
  <joint name="cover" type="fixed"><parent link="l1"/><child link="l1_cover"/>{_origin(rng)}</joint>
  <joint name="j2" type="prismatic"><parent link="l1_cover"/><child link="l2"/>{_origin(rng)}
    <axis xyz="{_axis(rng)}"/><limit lower="-0.2" upper="0.3" effort="100" velocity="0.5"/></joint>
  <joint name="sensor" type="fixed"><parent link="l2"/><child link="l2_sensor"/>
    {_origin(rng)}</joint>
  <joint name="j3" type="revolute"><parent link="l2"/><child link="l3"/>{_origin(rng)}
    <axis xyz="{_axis(rng)}"/><limit lower="-2.5" upper="1.5" effort="30" velocity="2"/></joint>
  <joint name="branch" type="revolute"><parent link="l3"/><child link="l3_branch"/>{_origin(rng)}
    <axis xyz="0 0 1"/><limit lower="-1" upper="1" effort="1" velocity="1"/></joint>
  <joint name="j4" type="revolute"><parent link="l3"/><child link="l4"/>{_origin(rng)}
    <axis xyz="{_axis(rng)}"/><limit lower="-3" upper="3" effort="10" velocity="4"/></joint>
  <joint name="tool_mount" type="fixed"><parent link="l4"/><child link="tool"/>
    {_origin(rng)}</joint>
  <joint name="tcp_joint" type="fixed"><parent link="tool"/><child link="tcp"/>
    {_origin(rng)}</joint>
  <joint name="fly" type="floating"><parent link="world"/><child link="drone"/></joint>
  <transmission name="t1"><joint name="j1"/></transmission>
</robot>"""


@pytest.mark.parametrize("seed", [21, 22, 23])
def test_synthetic_urdf_with_fixed_joints_matches_pinocchio(seed):
    """Fixed-joint merging (transforms, CoM, rotated inertia) equals Pinocchio's on random URDFs."""
    rng = np.random.default_rng(seed)
    text = synthetic_urdf(rng)
    robot = robot_from_urdf_string(text, "world", "tcp")
    assert robot.joint_names == ("j1", "j2", "j3", "j4")
    assert robot.link_names == ("world", "l1", "l2", "l3", "l4")
    np.testing.assert_array_equal(robot.prismatic, [False, True, False, False])
    np.testing.assert_allclose(np.linalg.norm(robot.axes, axis=1), 1.0, rtol=1e-15)
    assert {"pedestal", "l1_cover", "l2_sensor", "tool", "tcp"} <= set(robot.frames)
    assert {"l3_branch", "drone"}.isdisjoint(robot.frames)
    np.testing.assert_array_equal(
        robot.frames["flange"].T_link_frame, robot.frames["tcp"].T_link_frame
    )
    full = pin.buildModelFromXML(text)
    locked = [full.getJointId(k) for k in ("branch", "fly")]  # off our chain
    model, data = pin_model(pin.buildReducedModel(full, locked, pin.neutral(full)), robot)
    assert_matches_pinocchio(robot, model, data, n_states=100, seed=seed)


def test_continuous_joint_is_unbounded_and_moves_like_revolute():
    """A continuous joint gets -inf/inf position limits and the kinematics of a revolute joint."""
    rng = np.random.default_rng(31)
    origin, axis = _origin(rng), _axis(rng)
    urdf = """<robot name="r"><link name="a"/><link name="b"><inertial><mass value="1"/>
      <inertia ixx="0.1" iyy="0.1" izz="0.1"/></inertial></link>
      <joint name="j" type="{t}"><parent link="a"/><child link="b"/>{o}<axis xyz="{ax}"/>
      <limit lower="-1" upper="1" effort="5" velocity="2"/></joint></robot>"""
    cont = robot_from_urdf_string(urdf.format(t="continuous", o=origin, ax=axis))
    rev = robot_from_urdf_string(urdf.format(t="revolute", o=origin, ax=axis))
    assert cont.q_min[0] == -np.inf and cont.q_max[0] == np.inf
    assert cont.dq_max[0] == 2.0 and cont.tau_max[0] == 5.0
    q = rng.uniform(-5, 5, (20, 1))
    np.testing.assert_array_equal(dynid.fk(cont, q), dynid.fk(rev, q))


def test_missing_inertial_axis_and_limits_give_defaults():
    """No inertial -> zero mass; no axis -> URDF default x; no limit -> unbounded."""
    robot = robot_from_urdf_string(
        '<robot name="r"><link name="a"/><link name="b"/>'
        '<joint name="j" type="revolute"><parent link="a"/><child link="b"/></joint></robot>'
    )
    np.testing.assert_array_equal(robot.phi, np.zeros((1, 10)))
    np.testing.assert_array_equal(robot.axes, [[1.0, 0.0, 0.0]])
    np.testing.assert_array_equal(robot.T_parent_joint, [np.eye(4)])
    for k in ("q_max", "dq_max", "ddq_max", "tau_max"):
        assert getattr(robot, k)[0] == np.inf
    assert robot.q_min[0] == -np.inf
    assert robot.frames["flange"].link == 1


def test_default_tip_is_the_unique_leaf():
    """Without tip_link the chain ends at the only leaf below the base."""
    robot = robot_from_urdf_string(
        '<robot name="r"><link name="a"/><link name="b"/><link name="c"/>'
        '<joint name="j" type="prismatic"><parent link="a"/><child link="b"/>'
        '<axis xyz="0 0 1"/></joint>'
        '<joint name="f" type="fixed"><parent link="b"/><child link="c"/>'
        '<origin xyz="0 0 0.5"/></joint></robot>'
    )
    assert robot.link_names == ("a", "b")
    np.testing.assert_array_equal(
        robot.frames["flange"].T_link_frame, robot.frames["c"].T_link_frame
    )
    np.testing.assert_allclose(dynid.fk(robot, [0.25])[:3, 3], [0, 0, 0.75], atol=0)


def _gripper_arm(jaw: str) -> str:
    """One revolute joint carrying an arm (1 kg) with a fixed TCP (0.1 kg) and a tip
    frame, and a jaw (12 g, with a 3 g pad fixed to it) on a joint of type ``jaw``."""

    def link(name: str, mass: float | None = None) -> str:
        if mass is None:
            return f'<link name="{name}"/>'
        inertia = 'ixx="1e-4" iyy="1e-4" izz="1e-4" ixy="0" ixz="0" iyz="0"'
        return (
            f'<link name="{name}"><inertial><mass value="{mass}"/>'
            f"<inertia {inertia}/></inertial></link>"
        )

    def joint(name: str, kind: str, parent: str, child: str) -> str:
        axis = '<axis xyz="0 0 1"/><limit lower="-1" upper="1" effort="1" velocity="1"/>'
        return (
            f'<joint name="{name}" type="{kind}"><parent link="{parent}"/>'
            f'<child link="{child}"/><origin xyz="0 0.1 0"/>'
            f"{axis if kind != 'fixed' else ''}</joint>"
        )

    return (
        '<robot name="g">'
        + link("base")
        + link("stand", 2.0)
        + link("arm", 1.0)
        + link("tcp", 0.1)
        + link("tip")
        + link("jaw", 0.012)
        + link("pad", 0.003)
        + joint("stand_joint", "fixed", "base", "stand")
        + joint("j1", "revolute", "base", "arm")
        + joint("tcp_joint", "fixed", "arm", "tcp")
        + joint("tip_joint", "fixed", "arm", "tip")
        + joint("jaw_joint", jaw, "arm", "jaw")
        + joint("pad_joint", "fixed", "jaw", "pad")
        + "</robot>"
    )


def test_a_moving_branch_past_the_tip_is_lumped_at_zero_and_fixed_links_merged(caplog):
    """Regression (a gripper's moving jaw, 12 g, dropped from the model; then named in a
    warning with its mass only, its inertia in no link): the jaw and the pad fixed to it
    are lumped into the last body at the jaw joint's zero, as a fixed jaw joint merges
    them (the same phi, 1.115 kg), and a note names them with their 0.015 kg and inertia
    (2 x 1e-4 kg m^2 plus 0.012 kg at 0.02 m and 0.003 kg at 0.08 m from their CoM);
    the fixed TCP is logged as merged into the arm, and noted with its 0.1 kg as it lies
    beyond the tip; nothing is warned. Regression (a Z1 trial: the note called the gripper
    at rest "the best description of them there is" though its joint was recorded moving):
    it names the tip that keeps the jaw's joint, pad, the one leaf below it."""
    import logging

    with caplog.at_level(logging.INFO, logger="dynid"), warnings.catch_warnings():
        warnings.simplefilter("error")
        robot = robot_from_urdf_string(_gripper_arm("revolute"), "base", "tip")
    lumped = [r.getMessage() for r in caplog.records if "lumped" in r.getMessage()]
    assert lumped == [
        "URDF text: links moving on joints of their own past the tip lumped into the last "
        "body at their joints' zero position (0.015 kg in all): jaw and 1 link(s) below it "
        "(0.015 kg, inertia up to 0.000224 kg m^2 about its CoM, through revolute joint "
        "'jaw_joint' on arm); they ride on the arm at whatever opening they have, held at "
        "rest in the model: the best description there is when their joints are not "
        "recorded (where a recording holds them moving: tip_link='pad' keeps jaw_joint as "
        "joint(s) of the model); for an arm run without them, leave them out of the URDF"
    ]
    merged = [r.getMessage() for r in caplog.records if "merged" in r.getMessage()]
    assert merged == [
        "URDF text: links fixed to the chain beyond its own (past the tip or off its side) "
        "merged into its bodies, their inertials added (0.1 kg in all): tcp (0.1 kg) into "
        "arm; for an arm run without them, leave them out of the URDF",
        "URDF text: links fixed to the chain merged (their inertials added): tip into arm "
        "(0 kg), tcp into arm (0.1 kg)",
    ]
    fixed = robot_from_urdf_string(_gripper_arm("fixed"), "base", "tip")
    assert fixed.phi[:, 0].sum() == pytest.approx(1.115, rel=1e-15)
    np.testing.assert_allclose(robot.phi, fixed.phi, rtol=0, atol=1e-17)
    assert "jaw" not in robot.frames and "pad" not in robot.frames


def test_a_moving_branch_off_an_earlier_body_is_named_with_its_mass_and_inertia():
    """A slider on the first of two bodies moves on its own while the chain is recorded:
    it is left out, and the warning names its mass and its inertia about its CoM (the
    largest principal moment of 0.1 kg m^2 about z; before: its mass only)."""
    text = """<robot name="r"><link name="base"/>
  <link name="a"><inertial><mass value="1"/><inertia ixx="0.01" iyy="0.01" izz="0.01"/>
  </inertial></link>
  <link name="b"><inertial><mass value="1"/><inertia ixx="0.01" iyy="0.01" izz="0.01"/>
  </inertial></link>
  <link name="slide"><inertial><mass value="0.2"/><inertia ixx="0.02" iyy="0.08" izz="0.1"/>
  </inertial></link>
  <joint name="j1" type="revolute"><parent link="base"/><child link="a"/><axis xyz="0 0 1"/>
    <limit lower="-1" upper="1" effort="1" velocity="1"/></joint>
  <joint name="j2" type="revolute"><parent link="a"/><child link="b"/><axis xyz="0 1 0"/>
    <origin xyz="0 0 0.5"/><limit lower="-1" upper="1" effort="1" velocity="1"/></joint>
  <joint name="s" type="prismatic"><parent link="a"/><child link="slide"/>
    <axis xyz="1 0 0"/><limit lower="-1" upper="1" effort="1" velocity="1"/></joint>
</robot>"""
    with pytest.warns(dynid.DynidWarning, match="left out of the chain") as caught:
        robot = robot_from_urdf_string(text, "base", "b")
    (said,) = [str(w.message) for w in caught]
    assert "slide (0.2 kg, inertia up to 0.1 kg m^2 about its CoM, through prismatic " in said
    assert "their mass and inertia are in no link of the model" in said
    assert robot.phi[:, 0].sum() == pytest.approx(2.0, rel=1e-15)


# ---------------------------------------------------------------------------- errors
TWO_LINKS = (
    '<robot name="r"><link name="a"/><link name="b"/>'
    '<joint name="j" type="{t}"><parent link="a"/><child link="b"/>{extra}</joint></robot>'
)
BRANCHED = (
    '<robot name="r"><link name="a"/><link name="b"/><link name="c"/>'
    '<joint name="j1" type="revolute"><parent link="a"/><child link="b"/></joint>'
    '<joint name="j2" type="revolute"><parent link="a"/><child link="c"/></joint></robot>'
)


def test_missing_file_raises_model_error(tmp_path):
    """A path that does not exist raises ModelError naming the file."""
    with pytest.raises(dynid.ModelError, match="URDF file not found.*nothere.urdf"):
        load_urdf(tmp_path / "nothere.urdf")


def test_malformed_xml_raises_model_error(tmp_path):
    """Text that is not well-formed XML raises ModelError (wrapping the ParseError)."""
    path = tmp_path / "bad.urdf"
    path.write_text('<robot name="r"><link name="a"></robot>')
    with pytest.raises(dynid.ModelError, match="not well-formed XML") as info:
        load_urdf(path)
    assert info.value.__cause__ is not None


def test_non_robot_root_raises_model_error():
    """A document whose root is not <robot> is rejected."""
    with pytest.raises(dynid.ModelError, match="must be <robot>"):
        robot_from_urdf_string("<sdf/>")


@pytest.mark.parametrize("role", ["base_link", "tip_link"])
def test_unknown_base_or_tip_raises_unknown_name_error_listing_links(role):
    """An unknown base or tip link raises UnknownNameError listing the available links."""
    with pytest.raises(
        dynid.UnknownNameError, match=r"Unknown (base|tip) link 'zz'; available: \['a', 'b'\]"
    ):
        robot_from_urdf_string(TWO_LINKS.format(t="revolute", extra=""), **{role: "zz"})


def test_branching_without_tip_raises_model_error_listing_leaves():
    """Several leaves below the base and no tip_link raise ModelError listing them."""
    with pytest.raises(dynid.ModelError, match=r"several leaf links.*\['b', 'c'\]"):
        robot_from_urdf_string(BRANCHED)
    assert robot_from_urdf_string(BRANCHED, tip_link="c").joint_names == ("j2",)


def test_tip_not_below_base_raises_model_error():
    """A tip on another branch than the base raises ModelError."""
    with pytest.raises(dynid.ModelError, match="tip link 'c' is not below base link 'b'"):
        robot_from_urdf_string(BRANCHED, base_link="b", tip_link="c")


@pytest.mark.parametrize("jtype", ["floating", "planar"])
def test_floating_or_planar_joint_on_chain_raises_model_error(jtype):
    """A floating or planar joint on the chain cannot be modelled."""
    with pytest.raises(dynid.ModelError, match=f"joint 'j' of type '{jtype}' on the chain"):
        robot_from_urdf_string(TWO_LINKS.format(t=jtype, extra=""))


def test_unknown_joint_type_raises_model_error():
    """An unknown joint type on the chain is rejected."""
    with pytest.raises(dynid.ModelError, match="unknown type 'screw'"):
        robot_from_urdf_string(TWO_LINKS.format(t="screw", extra=""))


def test_chain_without_moving_joint_raises_model_error():
    """A chain of fixed joints only has no degree of freedom."""
    with pytest.raises(dynid.ModelError, match="no revolute, continuous or prismatic joint"):
        robot_from_urdf_string(TWO_LINKS.format(t="fixed", extra=""))


def test_mimic_joint_on_chain_raises_model_error():
    """A mimic (coupled) joint on the chain is rejected."""
    with pytest.raises(dynid.ModelError, match="mimics another joint"):
        robot_from_urdf_string(TWO_LINKS.format(t="revolute", extra='<mimic joint="x"/>'))


def test_bad_limits_numbers_and_axis_raise_model_error():
    """Lower >= upper, unparsable numbers, wrong counts and a zero axis name the joint."""
    cases = {
        '<limit lower="1" upper="1"/>': "joint 'j': lower limit must be below",
        '<limit lower="x" upper="1"/>': "attribute 'lower' must be a number",
        '<origin xyz="0 0"/>': "origin xyz must hold 3 numbers",
        '<axis xyz="0 0 0"/>': "joint 'j' has a zero axis",
    }
    for extra, msg in cases.items():
        with pytest.raises(dynid.ModelError, match=msg):
            robot_from_urdf_string(TWO_LINKS.format(t="revolute", extra=extra))


def test_malformed_tree_raises_model_error():
    """Unknown link references, two parents, several roots and duplicate names are rejected."""
    cases = {
        '<robot><link name="a"/><joint name="j" type="fixed"><parent link="a"/>'
        '<child link="q"/></joint></robot>': "unknown child link 'q'",
        '<robot><link name="a"/><link name="b"/><link name="c"/>'
        '<joint name="j1" type="fixed"><parent link="a"/><child link="c"/></joint>'
        '<joint name="j2" type="fixed"><parent link="b"/><child link="c"/></joint>'
        "</robot>": "link 'c' is the child of two joints",
        '<robot><link name="a"/><link name="b"/></robot>': r"2 root links \['a', 'b'\]",
        '<robot><link name="a"/><link name="a"/></robot>': "duplicate link name 'a'",
        '<robot><link name="a"/></robot>': "no revolute, continuous or prismatic joint",
    }
    for text, msg in cases.items():
        with pytest.raises(dynid.ModelError, match=msg):
            robot_from_urdf_string(text)


@pytest.mark.parametrize(
    ("inertial", "problem"),
    [
        ('<mass value="-1"/><inertia ixx="1" iyy="1" izz="1"/>', "negative mass"),
        ('<mass value="1"/><inertia ixx="-1" iyy="1" izz="1"/>', "not positive semi-definite"),
        ('<mass value="1"/><inertia ixx="0.1" iyy="0.1" izz="0.5"/>', "triangle inequality"),
    ],
)
def test_inconsistent_inertial_warns_naming_the_link_and_is_kept(inertial, problem):
    """Negative mass, an indefinite inertia or a broken triangle inequality warn and are kept."""
    text = (
        '<robot name="r"><link name="a"/><link name="b"><inertial>'
        f"{inertial}</inertial></link>"
        '<joint name="j" type="revolute"><parent link="a"/><child link="b"/></joint></robot>'
    )
    with pytest.warns(dynid.DynidWarning, match=f"link 'b'.*{problem}"):
        robot = robot_from_urdf_string(text)
    mass, _, I = dynid.inertial_from_phi(robot.phi)
    assert mass[0] == float(inertial.split('"')[1])
    assert I[0, 0, 0] == float(inertial.split('ixx="')[1].split('"')[0])


def test_missing_mass_in_inertial_raises_model_error():
    """An <inertial> without <mass value> is malformed."""
    text = TWO_LINKS.format(t="revolute", extra="").replace(
        '<link name="b"/>', '<link name="b"><inertial><inertia ixx="1"/></inertial></link>'
    )
    with pytest.raises(dynid.ModelError, match="link 'b' <inertial> needs a finite <mass"):
        robot_from_urdf_string(text)


def test_non_positive_velocity_limit_warns_and_is_unbounded():
    """velocity="0" is treated as no limit, with a warning naming the joint."""
    text = TWO_LINKS.format(
        t="revolute", extra='<limit lower="-1" upper="1" velocity="0" effort="3"/>'
    )
    with pytest.warns(dynid.DynidWarning, match="joint 'j' has velocity limit 0.0"):
        robot = robot_from_urdf_string(text)
    assert robot.dq_max[0] == np.inf and robot.tau_max[0] == 3.0


def test_cycle_of_joints_raises_model_error():
    """Joints that loop back (no root, or a cycle below the base) are rejected."""
    text = (
        '<robot><link name="a"/><link name="b"/>'
        '<joint name="j1" type="revolute"><parent link="a"/><child link="b"/></joint>'
        '<joint name="j2" type="revolute"><parent link="b"/><child link="a"/></joint></robot>'
    )
    with pytest.raises(dynid.ModelError, match="0 root links"):
        robot_from_urdf_string(text)
    with pytest.raises(dynid.ModelError, match="form a cycle"):
        robot_from_urdf_string(text, base_link="a")


def test_urdf_link_named_flange_off_the_tip_keeps_its_own_pose():
    """A moving URDF link 'flange' above the tip is the frame 'flange' at its own pose (it
    was shadowed by the tip's, with a warning), as Pinocchio places it."""
    text = (
        '<robot name="r"><link name="a"/><link name="b"/><link name="flange"/><link name="tcp"/>'
        '<joint name="i" type="revolute"><parent link="a"/><child link="b"/>'
        '<limit lower="-3" upper="3" velocity="2" effort="100"/></joint>'
        '<joint name="j" type="revolute"><parent link="b"/><child link="flange"/>'
        '<origin xyz="0 0 0.2"/><axis xyz="0 1 0"/>'
        '<limit lower="-3" upper="3" velocity="2" effort="100"/></joint>'
        '<joint name="f" type="fixed"><parent link="flange"/><child link="tcp"/>'
        '<origin xyz="0 0 0.1"/></joint></robot>'
    )
    with warnings.catch_warnings():
        warnings.simplefilter("error", dynid.DynidWarning)
        robot = robot_from_urdf_string(text)
    assert robot.frames["flange"].link == 2
    np.testing.assert_array_equal(robot.frames["flange"].T_link_frame, np.eye(4))
    model = pin.buildModelFromXML(text)
    assert_matches_pinocchio(robot, *pin_model(model, robot), n_states=5, seed=41)


# A UR5-like arm whose wrist carries a zero-mass link 'flange' and below it the leaf 'tool0'
# (the first is turned about z, the second 0.05 m further and turned about x).
_HALF_PI = np.pi / 2
_LINKS6 = ("base_link", "l1", "l2", "l3", "l4", "l5", "wrist_3_link")
_FLANGE_ARM = (
    '<robot name="arm6">'
    + "".join(
        f'<link name="{name}"><inertial><mass value="{1.0 + i}"/><origin xyz="0 0.01 0.02"/>'
        '<inertia ixx="0.03" ixy="0" ixz="0" iyy="0.02" iyz="0" izz="0.02"/></inertial></link>'
        for i, name in enumerate(_LINKS6)
    )
    + '<link name="flange"><inertial><mass value="0"/><inertia ixx="0" ixy="0" ixz="0" '
    'iyy="0" iyz="0" izz="0"/></inertial></link><link name="tool0"/>'
    + "".join(
        f'<joint name="j{i}" type="revolute"><parent link="{_LINKS6[i - 1]}"/>'
        f'<child link="{_LINKS6[i]}"/><origin xyz="0 {0.1 * (-1) ** i} 0.3" '
        f'rpy="0 {_HALF_PI * (i % 2)!r} 0"/><axis xyz="0 {i % 2} {1 - i % 2}"/>'
        '<limit lower="-3" upper="3" velocity="2" effort="100"/></joint>'
        for i in range(1, 7)
    )
    + '<joint name="flange_fixed" type="fixed"><parent link="wrist_3_link"/>'
    f'<child link="flange"/><origin xyz="0 0.0823 0" rpy="0 0 {_HALF_PI!r}"/></joint>'
    '<joint name="tool0_fixed" type="fixed"><parent link="flange"/><child link="tool0"/>'
    f'<origin xyz="0 0 0.05" rpy="{-_HALF_PI!r} 0 0"/></joint></robot>'
)


def test_fixed_link_named_flange_before_the_tip_is_its_own_frame():
    """Regression: a fixed URDF link 'flange' with a link 'tool0' fixed below it gave fk,
    jacobian and ik at tool0's pose (0.05 m off) with a warning; every fixed link of the
    chain is now its own frame, equal to Pinocchio's for fk, jacobian, ik and a tool."""
    with warnings.catch_warnings():
        warnings.simplefilter("error", dynid.DynidWarning)
        robot = robot_from_urdf_string(_FLANGE_ARM)
    model = pin.buildModelFromXML(_FLANGE_ARM)
    assert {"flange", "tool0"} <= set(robot.frames)
    assert_matches_pinocchio(robot, *pin_model(model, robot), n_states=20, seed=43)
    data = model.createData()
    rng = np.random.default_rng(44)
    q_goal = rng.uniform(-1.0, 1.0, 6)
    pin.framesForwardKinematics(model, data, q_goal)
    T_tool = np.eye(4)
    T_tool[:3, 3] = [0.01, -0.02, 0.1]
    for frame in ("flange", "tool0"):
        goal = data.oMf[model.getFrameId(frame)].homogeneous
        res = dynid.ik(robot, goal @ T_tool, q_goal + 0.05, frame=frame, tool=T_tool)
        assert res.converged
        pin.framesForwardKinematics(model, data, res.q)
        reached = data.oMf[model.getFrameId(frame)].homogeneous @ T_tool
        np.testing.assert_allclose(reached, goal @ T_tool, atol=1e-5, err_msg=frame)
        pin.framesForwardKinematics(model, data, q_goal)
    tooled = robot.with_tool(T_tool, name="tip")  # mounted at the URDF's flange
    np.testing.assert_allclose(
        dynid.fk(tooled, q_goal, "tip"),
        data.oMf[model.getFrameId("flange")].homogeneous @ T_tool,
        atol=1e-12,
    )


def test_absurd_axes_and_masses_are_refused_by_every_reader():
    """An axis [0, 0, 1e300] (its norm overflows, so it became a zero axis) and a link of
    1e12 kg are refused naming the joint or link, by the URDF reader (ModelError), the TOML
    reader (DataError, the key path in the schema codec's wording) and the Robot itself
    (issue 20); an axis of 1e150 still normalises to [0, 0, 1]."""
    from dynid.exceptions import DataError, ModelError
    from dynid.io.robot.toml import robot_from_toml_string

    urdf = """<robot name="r"><link name="a"/><link name="b"><inertial><mass value="{m}"/>
      <inertia ixx="0.1" iyy="0.1" izz="0.1"/></inertial></link>
      <joint name="j" type="revolute"><parent link="a"/><child link="b"/>
      <axis xyz="{ax}"/></joint></robot>"""
    ok = robot_from_urdf_string(urdf.format(m=1, ax="0 0 1e150"))
    np.testing.assert_array_equal(ok.axes, [[0.0, 0.0, 1.0]])
    with pytest.raises(
        ModelError, match=r"joint 'j' axis \[0.0, 0.0, 1e\+300\] is too large to normalise"
    ):
        robot_from_urdf_string(urdf.format(m=1, ax="0 0 1e300"))
    with pytest.raises(ModelError, match=r"link 'b' <inertial> <mass> must be at most 1e\+06"):
        robot_from_urdf_string(urdf.format(m=1e12, ax="0 0 1"))
    toml = '[[joints]]\nname = "j"\ntype = "revolute"\nparent = "a"\nchild = "b"\naxis = {ax}\n'
    with pytest.raises(
        DataError,
        match=r"^TOML text: key 'joints\[0\].axis': \[0.0, 1e\+300, 0.0\] is too large to norm",
    ):
        robot_from_toml_string(toml.format(ax="[0, 1e300, 0]"))
    with pytest.raises(
        DataError, match=r"key 'joints\[0\].inertial.mass': expected a number in \[0, 1e\+06\]"
    ):
        robot_from_toml_string(
            toml.format(ax="[0, 0, 1]") + "inertial = { mass = 1e12, com = [0, 0, 0], "
            "inertia = [1, 0, 0, 1, 0, 1] }\n"
        )
    with pytest.raises(ModelError, match="joint axis of j, .* is too large to normalise"):
        dynid.Robot(
            name="r", joint_names=("j",), link_names=("a", "b"), T_parent_joint=np.eye(4)[None],
            axes=[[1e300, 1e300, 0.0]], prismatic=[False], phi=np.zeros((1, 10)),
            q_min=[-1.0], q_max=[1.0], dq_max=[1.0], ddq_max=[1.0], tau_max=[1.0],
            gravity=[0.0, 0.0, -9.81],
        )  # fmt: skip


def test_a_hand_merged_beyond_the_tip_is_noted_with_its_mass(caplog):
    """Regression (example-robot-data's panda.urdf read to tip panda_link8 for --robot or
    --prior: the hand, 0.73 kg, was merged into link 7 silently): one note names it with
    its mass (the URDF's <mass>); link 7 is Pinocchio's body of joint 7 (link 7, link 8 and
    the hand); read to tip panda_hand, the hand is a link of the chain and no note."""
    import xml.etree.ElementTree as ET

    pin = pytest.importorskip("pinocchio")
    from dynid.progress import NOTE
    from dynid.workflows.prior import load_prior

    urdf = robot_data_urdf("panda_description/urdf/panda.urdf")
    hand = ET.parse(urdf).getroot().find("link[@name='panda_hand']/inertial/mass")
    assert hand is not None
    said = f"panda_hand ({float(hand.get('value', 'nan')):.4g} kg) into panda_link7"

    def notes(read):
        caplog.clear()
        with caplog.at_level(NOTE, logger="dynid"), warnings.catch_warnings():
            warnings.simplefilter("ignore", dynid.DynidWarning)  # the fingers left out
            robot = read()
        return robot, [r.getMessage() for r in caplog.records if r.levelno == NOTE]

    robot, lines = notes(lambda: load_urdf(urdf, tip_link="panda_link8"))
    hanging = [x for x in lines if "merged" in x]
    assert len(hanging) == 1 and said in hanging[0] and "0.73 kg in all" in hanging[0]
    full = pin.buildModelFromUrdf(urdf)
    fingers = [full.getJointId(k) for k in ("panda_finger_joint1", "panda_finger_joint2")]
    reduced = pin.buildReducedModel(full, fingers, pin.neutral(full))  # fingers at rest
    mass7 = reduced.inertias[reduced.getJointId("panda_joint7")].mass
    assert robot.mass[6] == pytest.approx(mass7, rel=1e-12)
    _, lines = notes(lambda: load_prior(urdf, robot, tip="panda_link8"))
    assert len([x for x in lines if said in x]) == 1
    _, lines = notes(lambda: load_urdf(urdf, tip_link="panda_hand"))
    assert [x for x in lines if "merged" in x] == []
