"""TOML robot descriptions: exact round trips, the MDH input form and malformed files."""

from __future__ import annotations

import numpy as np
import pytest

import dynid
from dynid.io.export import save_robot
from dynid.io.robot.toml import load_toml, robot_from_toml_string, toml_from_robot

from conftest import random_states, robot_data_urdf


def assert_same_robot(a: dynid.Robot, b: dynid.Robot, seed: int) -> None:
    """Names, limits, friction, gravity and frames equal; FK of every frame and RNEA to 1e-12."""
    assert (a.name, a.joint_names, a.link_names) == (b.name, b.joint_names, b.link_names)
    np.testing.assert_array_equal(a.prismatic, b.prismatic)
    for k in ("q_min", "q_max", "dq_max", "ddq_max", "tau_max", "gravity"):
        np.testing.assert_array_equal(getattr(a, k), getattr(b, k), err_msg=k)
    if a.friction is None:
        assert b.friction is None
    else:
        np.testing.assert_array_equal(a.friction, b.friction)
    assert set(a.frames) == set(b.frames)
    for k, f in a.frames.items():
        assert f.link == b.frames[k].link, k
        np.testing.assert_allclose(f.T_link_frame, b.frames[k].T_link_frame, atol=1e-15, err_msg=k)
    np.testing.assert_allclose(a.T_parent_joint, b.T_parent_joint, atol=1e-15)
    np.testing.assert_allclose(a.axes, b.axes, atol=1e-16)
    np.testing.assert_allclose(a.phi, b.phi, rtol=1e-14, atol=1e-16)
    q, dq, ddq = random_states(a, 100, seed=seed)
    for k in a.frames:
        np.testing.assert_allclose(dynid.fk(a, q, k), dynid.fk(b, q, k), atol=1e-12, err_msg=k)
    np.testing.assert_allclose(dynid.rnea(a, q, dq, ddq), dynid.rnea(b, q, dq, ddq), atol=1e-12)


def test_panda_round_trip_through_a_file_keeps_the_robot(tmp_path):
    """dynid.panda() written to TOML and read back is the same robot (limits, friction, frames)."""
    panda = dynid.panda()
    path = tmp_path / "panda.toml"
    text = toml_from_robot(panda)
    save_robot(path, panda)
    assert path.read_text() == text
    assert_same_robot(panda, dynid.Robot.from_toml(path), seed=41)
    assert_same_robot(panda, load_toml(str(path)), seed=41)


def test_ur5_round_trip_keeps_the_robot():
    """The URDF UR5 with friction, tilted gravity and a tool round-trips (base frames too)."""
    rng = np.random.default_rng(42)
    ur5 = dynid.Robot.from_urdf(
        robot_data_urdf("ur_description/urdf/ur5_robot.urdf"), tip_link="tool0"
    )
    ur5 = ur5.with_friction(rng.uniform(0.1, 5.0, (6, 3))).with_gravity(rng.normal(size=3))
    ur5 = ur5.with_tool(
        dynid.spatial.transform_from_xyz_rpy(rng.normal(size=3), rng.normal(size=3)),
        1.5,
        rng.normal(size=3) * 0.1,
        np.diag([0.01, 0.02, 0.025]),
        parent="tool0",
    )
    back = robot_from_toml_string(toml_from_robot(ur5))
    assert back.frames["base"].link == 0
    assert_same_robot(ur5, back, seed=43)


def test_round_trip_is_exact_near_gimbal_lock():
    """Origins with pitch near ±pi/2 (and rounding noise) still round-trip to 1e-15."""
    rng = np.random.default_rng(44)
    n = 6
    T = np.empty((n, 4, 4))
    for i in range(n):
        pitch = np.pi / 2 * rng.choice([-1, 1]) - 10.0 ** rng.uniform(-13, -5) * rng.choice([-1, 1])
        A = dynid.spatial.matrix_from_rpy(rng.uniform(-3, 3, 3))
        R = dynid.spatial.matrix_from_rpy([rng.uniform(-3, 3), pitch, rng.uniform(-3, 3)]) @ A @ A.T
        T[i] = dynid.spatial.transform(R, rng.normal(size=3))
    robot = dynid.Robot.from_mdh(np.zeros(n), np.zeros(n), np.zeros(n)).replace(T_parent_joint=T)
    back = robot_from_toml_string(toml_from_robot(robot))
    np.testing.assert_allclose(back.T_parent_joint, robot.T_parent_joint, atol=1e-15)


def test_prismatic_joint_names_with_quotes_and_unbounded_limits_round_trip():
    """Prismatic joints, unbounded limits, escaped names and a massless link round-trip."""
    robot = dynid.Robot.from_mdh(
        [0.0, 0.1],
        [0.2, 0.0],
        [0.0, np.pi / 2],
        joint_types="RP",
        name='arm "x" \\ ünï',
        joint_names=['j "1"', "j\t2"],
        link_names=["base", "l1", "l2"],
        mass=[0.0, 2.0],
        com=[[0, 0, 0], [0.1, 0.0, -0.05]],
        inertia=np.zeros((2, 6)),
        q_min=[-1.0, -np.inf],
        q_max=[np.inf, 0.4],
    )
    text = toml_from_robot(robot)
    assert "inf" not in text
    assert_same_robot(robot, robot_from_toml_string(text), seed=45)


PANDA_MDH_TOML = """
name = "panda"
{joints}
[[frames]]
name = "flange"
parent = "link7"
mdh = {{ a = 0.0, d = 0.107, alpha = 0.0 }}

[[frames]]
name = "tcp"
parent = "flange"
xyz = [0.0, 0.0, 0.1034]
rpy = [0.0, 0.0, -0.7853981633974483]
"""


def panda_mdh_toml() -> str:
    """The Panda's MDH table (Gaz et al. 2019, Fig. 1) in the TOML ``mdh`` form, no inertials."""
    a = [0.0, 0.0, 0.0, 0.0825, -0.0825, 0.0, 0.088]
    d = [0.333, 0.0, 0.316, 0.0, 0.384, 0.0, 0.0]
    alpha = [0.0, -np.pi / 2, np.pi / 2, np.pi / 2, -np.pi / 2, np.pi / 2, np.pi / 2]
    joints = "".join(
        f'\n[[joints]]\nname = "joint{i + 1}"\ntype = "revolute"\nparent = "link{i}"\n'
        f'child = "link{i + 1}"\n'
        f"mdh = {{ a = {a[i]!r}, d = {d[i]!r}, alpha = {alpha[i]!r}, theta = 0.0 }}\n"
        for i in range(7)
    )
    return PANDA_MDH_TOML.format(joints=joints)


def test_mdh_form_equals_the_urdf_panda_and_the_builtin_panda():
    """Joints and frames given as MDH rows give the Panda's kinematics (URDF and built-in)."""
    robot = robot_from_toml_string(panda_mdh_toml())
    urdf = dynid.Robot.from_urdf(
        robot_data_urdf("panda_description/urdf/panda.urdf"), "panda_link0", "panda_hand_tcp"
    )
    q, _, _ = random_states(dynid.panda(), 100, seed=46)
    T = dynid.link_poses(robot, q)
    np.testing.assert_allclose(T, dynid.link_poses(urdf, q), atol=1e-12)
    np.testing.assert_allclose(T, dynid.link_poses(dynid.panda(), q), atol=1e-15)
    np.testing.assert_allclose(
        dynid.fk(robot, q, "flange"), dynid.fk(urdf, q, "panda_link8"), atol=1e-12
    )
    np.testing.assert_allclose(
        dynid.fk(robot, q, "tcp"), dynid.fk(urdf, q, "panda_hand_tcp"), atol=1e-12
    )
    np.testing.assert_array_equal(robot.axes, np.tile([0.0, 0.0, 1.0], (7, 1)))
    np.testing.assert_array_equal(robot.phi, np.zeros((7, 10)))
    assert robot.friction is None and np.all(np.isinf(robot.q_max))
    np.testing.assert_array_equal(robot.gravity, [0.0, 0.0, -9.80665])


def test_inertial_about_the_com_becomes_standard_parameters():
    """mass, com and inertia about the CoM give phi by the parallel-axis theorem (Gaz eq. 26)."""
    rng = np.random.default_rng(47)
    m, c = 2.5, rng.normal(size=3) * 0.1
    com = ", ".join(repr(float(x)) for x in c)
    I6 = [0.03, 0.001, -0.002, 0.04, 0.003, 0.05]
    text = (
        '[[joints]]\nname = "j"\ntype = "prismatic"\nparent = "a"\nchild = "b"\n'
        "axis = [0, 2, 0]\nlimits = { lower = -0.5, upper = 0.5 }\n"
        f"[joints.inertial]\nmass = {m}\ncom = [{com}]\ninertia = {I6}\n"
    )
    robot = robot_from_toml_string(text)
    I = np.array([[I6[0], I6[1], I6[2]], [I6[1], I6[3], I6[4]], [I6[2], I6[4], I6[5]]])
    J = I + m * (c @ c * np.eye(3) - np.outer(c, c))
    np.testing.assert_allclose(robot.phi[0, :4], [m, *(m * c)], rtol=1e-15)
    np.testing.assert_allclose(robot.phi[0, 4:], J[np.triu_indices(3)], rtol=1e-14)
    np.testing.assert_array_equal(robot.axes, [[0.0, 1.0, 0.0]])
    assert robot.prismatic[0] and robot.dq_max[0] == np.inf


# ---------------------------------------------------------------------------- errors
GOOD = """
name = "r"
[[joints]]
name = "j1"
type = "revolute"
parent = "base"
child = "l1"
origin = { xyz = [0.0, 0.0, 0.1] }
limits = { lower = -1.0, upper = 1.0 }
[joints.inertial]
mass = 1.0
com = [0.0, 0.0, 0.1]
inertia = [0.1, 0.0, 0.0, 0.1, 0.0, 0.1]
[[joints]]
name = "j2"
type = "revolute"
parent = "l1"
child = "l2"
[[frames]]
name = "tool"
parent = "l2"
xyz = [0.0, 0.0, 0.2]
"""


def test_good_reference_file_loads():
    """The base file of the error tests is valid, so each error below comes from its one edit."""
    robot = robot_from_toml_string(GOOD)
    assert robot.n == 2 and robot.frames["tool"].link == 2


@pytest.mark.parametrize(
    ("old", "new", "message"),
    [
        ('name = "j1"\n', "", r"joints\[0\]: missing key 'name'"),
        ('type = "revolute"\nparent = "base"', 'parent = "base"', r"\('j1'\): missing key 'type'"),
        ('parent = "l1"\n', "", r"\('j2'\): missing key 'parent'"),
        ('child = "l2"\n', "", r"\('j2'\): missing key 'child'"),
        ("mass = 1.0\n", "", r"\('j1'\): inertial: missing key 'mass'"),
        ("com = [0.0, 0.0, 0.1]\n", "", r"\('j1'\): inertial: missing key 'com'"),
        ('name = "tool"\n', "", r"frames\[0\]: missing key 'name'"),
        (
            "com = [0.0, 0.0, 0.1]",
            "com = [0.0, 0.1]",
            r"\('j1'\): key 'inertial.com' must be a list of 3 numbers; got 2",
        ),
        (
            "inertia = [0.1, 0.0, 0.0, 0.1, 0.0, 0.1]",
            "inertia = [0.1, 0.1, 0.1]",
            r"key 'inertial.inertia' must be a list of 6",
        ),
        (
            "xyz = [0.0, 0.0, 0.1]",
            "xyz = [0.0, 0.1]",
            r"\('j1'\): key 'origin.xyz' must be a list of 3",
        ),
        (
            'child = "l2"',
            'child = "l2"\naxis = [1, 0]',
            r"\('j2'\): key 'axis' must be a list of 3",
        ),
        (
            'child = "l2"',
            'child = "l2"\naxis = [0, 0, 0]',
            r"\('j2'\): key 'axis' must not be zero",
        ),
        (
            'child = "l2"',
            'child = "l2"\nfriction = [1.0, 2.0]',
            r"\('j2'\): key 'friction' must be a list of 3",
        ),
        ('parent = "l1"', 'parent = "l9"', r"\('j2'\): unknown parent 'l9'"),
        (
            'parent = "l2"',
            'parent = "nowhere"',
            r"frames\[0\] \('tool'\): unknown parent 'nowhere'",
        ),
        (
            'type = "revolute"\nparent = "l1"',
            'type = "spherical"\nparent = "l1"',
            r"key 'type' must be one of",
        ),
        ('child = "l1"', 'child = "l1"\ninertal = 3', r"\('j1'\): unknown key 'inertal'"),
        ('name = "r"', 'name = "r"\ngravty = [0, 0, -9.81]', r"unknown key 'gravty'"),
        ('name = "r"', 'name = "r"\ngravity = [0, -9.81]', r"key 'gravity' must be a list of 3"),
        (
            "lower = -1.0",
            "lower = 1.0",
            r"\('j1'\): key 'limits.lower' must be below 'limits.upper'",
        ),
        (
            "lower = -1.0",
            "lower = -1.0, velocity = 0.0",
            r"\('j1'\): key 'limits.velocity' must be positive",
        ),
        ("lower = -1.0", "lowr = -1.0", r"\('j1'\): limits: unknown key 'lowr'"),
        ("lower = -1.0", 'lower = "a"', r"\('j1'\): key 'limits.lower' must be a number"),
        ("mass = 1.0", "mass = nan", r"key 'inertial.mass' must be finite"),
        (
            'child = "l1"',
            'child = "l1"\nfriction = [1.0, 2.0, 3.0]',
            r"friction' is given for some joints but not for joint 'j2'",
        ),
        (
            "origin = { xyz = [0.0, 0.0, 0.1] }",
            "origin = { xyz = [0.0, 0.0, 0.1] }\nmdh = { a = 0.0, d = 0.1, alpha = 0.0 }",
            r"give either 'origin' or 'mdh'",
        ),
        (
            "origin = { xyz = [0.0, 0.0, 0.1] }",
            "mdh = { a = 0.0, alpha = 0.0 }",
            r"\('j1'\): mdh: missing key 'd'",
        ),
        ('name = "r"', 'name = "r"\nformat_version = 2', r"key 'format_version' must be 1"),
        ('name = "j2"', 'name = "j1"', r"duplicate joint names: \['j1'\]"),
        (
            'name = "tool"',
            'name = "tool"\nmdh = { a = 0.0, d = 0.1, alpha = 0.0 }',
            r"give either 'xyz' or 'mdh'",
        ),
    ],
)
def test_malformed_description_raises_model_error_naming_the_key(old, new, message):
    """Missing, unknown, mistyped and wrong-length keys raise ModelError naming joint and key."""
    assert old in GOOD
    with pytest.raises(dynid.ModelError, match=message):
        robot_from_toml_string(GOOD.replace(old, new, 1))


def test_description_without_joints_or_bad_toml_raises_model_error(tmp_path):
    """No [[joints]], invalid TOML and a missing file raise ModelError."""
    with pytest.raises(dynid.ModelError, match="missing key 'joints'"):
        robot_from_toml_string('name = "r"\n')
    with pytest.raises(dynid.ModelError, match="not valid TOML"):
        robot_from_toml_string("name = \n")
    with pytest.raises(dynid.ModelError, match="TOML description not found.*none.toml"):
        load_toml(tmp_path / "none.toml")
    with pytest.raises(dynid.ModelError, match="TOML description not found"):
        dynid.Robot.from_toml(tmp_path / "none.toml")


def test_neutral_pose_round_trips_and_is_checked():
    """q_neutral survives the TOML round trip; a wrong length raises ModelError naming the key."""
    panda = dynid.panda()
    text = toml_from_robot(panda)
    np.testing.assert_array_equal(robot_from_toml_string(text).q_neutral, panda.q_neutral)
    with pytest.raises(dynid.ModelError, match="'q_neutral' must be a list of 7 numbers"):
        robot_from_toml_string(text.replace("q_neutral = [", "q_neutral = [1.0, "))
