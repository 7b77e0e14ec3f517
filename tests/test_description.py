"""TOML robot descriptions: exact round trips, the MDH input form and malformed files."""

from __future__ import annotations

import numpy as np
import pytest

import dynid
from dynid.exceptions import DataError
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
        assert a.friction.kind == b.friction.kind
        np.testing.assert_array_equal(a.friction.params, b.friction.params)
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
    ur5 = ur5.with_friction(
        dynid.SigmoidFriction.from_array(rng.uniform(0.1, 5.0, (6, 3)))
    ).with_gravity(rng.normal(size=3))
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


#: (edit of GOOD, the key path named, the rest of the one-line message)
_FAULTS = [
    ('name = "j1"\n', "", "joints[0].name", "missing; expected a non-empty string"),
    ('type = "revolute"\nparent = "base"', 'parent = "base"', "joints[0].type", "missing; "),
    ('parent = "l1"\n', "", "joints[1].parent", "missing; expected a non-empty string"),
    ('child = "l2"\n', "", "joints[1].child", "missing; expected a non-empty string"),
    ("mass = 1.0\n", "", "joints[0].inertial.mass", "missing; expected a number in [0, "),
    ("com = [0.0, 0.0, 0.1]\n", "", "joints[0].inertial.com", "missing; expected a list of 3"),
    ('name = "tool"\n', "", "frames[0].name", "missing; expected a non-empty string"),
    ("com = [0.0, 0.0, 0.1]", "com = [0.0, 0.1]", "joints[0].inertial.com",
     "expected a list of 3 numbers in [-10000, 10000] [m]; got [0.0, 0.1]"),
    ("inertia = [0.1, 0.0, 0.0, 0.1, 0.0, 0.1]", "inertia = [0.1, 0.1, 0.1]",
     "joints[0].inertial.inertia", "expected a list of 6 numbers [kg m^2]"),
    ("xyz = [0.0, 0.0, 0.1]", "xyz = [0.0, 0.1]", "joints[0].origin.xyz",
     "expected a list of 3 numbers"),
    ('child = "l2"', 'child = "l2"\naxis = [1, 0]', "joints[1].axis", "expected a list of 3"),
    ('child = "l2"', 'child = "l2"\naxis = [0, 0, 0]', "joints[1].axis",
     "expected a non-zero axis; got [0.0, 0.0, 0.0]"),
    ('child = "l2"', 'child = "l2"\nfriction = [1.0, 2.0]', "joints[1].friction",
     "expected a list of 3 numbers"),
    ('parent = "l1"', 'parent = "l9"', "joints[1].parent", "unknown parent 'l9'"),
    ('parent = "l1"', 'parent = ""', "joints[1].parent", "expected a non-empty string; got ''"),
    ('parent = "l2"', 'parent = "nowhere"', "frames[0].parent", "unknown parent 'nowhere'"),
    ('type = "revolute"\nparent = "l1"', 'type = "spherical"\nparent = "l1"', "joints[1].type",
     "expected one of 'revolute', 'prismatic'; got 'spherical'"),
    ('child = "l1"', 'child = "l1"\ninertal = 3', "joints[0].inertal", "unknown key; allowed: "),
    ('name = "r"', 'name = "r"\ngravty = [0, 0, -9.81]', "gravty", "unknown key; allowed: "),
    ('name = "r"', 'name = "r"\ngravity = [0, -9.81]', "gravity",
     "expected a list of 3 numbers [m/s^2]"),
    ("lower = -1.0", "lower = 1.0", "joints[0].limits.lower",
     "expected a number below 'limits.upper'; got 1.0 >= 1.0"),
    ("lower = -1.0", "lower = -1.0, velocity = 0.0", "joints[0].limits.velocity",
     "expected a number > 0; got 0.0"),
    ("lower = -1.0", "lower = -1.0, velocity = -1.0", "joints[0].limits.velocity",
     "expected a number or inf >= 0; got -1.0"),
    ("lower = -1.0", "lowr = -1.0", "joints[0].limits.lowr", "unknown key; allowed: "),
    ("lower = -1.0", 'lower = "a"', "joints[0].limits.lower",
     "expected a number or inf [rad or m]; got 'a'"),
    ("lower = -1.0", "lower = true", "joints[0].limits.lower", "expected a number or inf"),
    ("mass = 1.0", "mass = nan", "joints[0].inertial.mass", "expected a finite number; got nan"),
    ("mass = 1.0", "mass = -1.0", "joints[0].inertial.mass", "expected a number in [0, "),
    ('child = "l1"', 'child = "l1"\nfriction = [1.0, 2.0, 3.0]', "joints[1].friction",
     "missing; it is given for joint 'j1'"),
    ("origin = { xyz = [0.0, 0.0, 0.1] }",
     "origin = { xyz = [0.0, 0.0, 0.1] }\nmdh = { a = 0.0, d = 0.1, alpha = 0.0 }",
     "joints[0].mdh", "give either 'origin' or 'mdh', not both"),
    ("origin = { xyz = [0.0, 0.0, 0.1] }", "mdh = { a = 0.0, alpha = 0.0 }", "joints[0].mdh.d",
     "missing; expected a number"),
    ('name = "r"', 'name = "r"\nformat_version = 2', "format_version",
     "expected one of 1; got 2"),
    ('name = "tool"', 'name = "tool"\nmdh = { a = 0.0, d = 0.1, alpha = 0.0 }', "frames[0].mdh",
     "give either 'xyz' or 'mdh', not both"),
]  # fmt: skip


@pytest.mark.parametrize(("old", "new", "key", "text"), _FAULTS)
def test_malformed_description_is_refused_in_the_codecs_wording(old, new, key, text):
    """Missing, unknown, mistyped, wrong-length and out-of-limit keys, and keys that do not
    fit together: one DataError line ``SOURCE: key 'PATH': ...`` naming the key path, the
    wording of every file format (:mod:`dynid.io.schema`)."""
    assert old in GOOD
    with pytest.raises(DataError) as info:
        robot_from_toml_string(GOOD.replace(old, new, 1), source="arm.toml")
    msg = str(info.value)
    assert msg.startswith(f"arm.toml: key {key!r}: {text}"), msg
    assert "\n" not in msg


def test_a_description_the_robot_refuses_names_the_file():
    """What only the Robot checks (names that repeat) is refused naming the file."""
    with pytest.raises(DataError, match=r"^arm.toml: duplicate joint names: \['j1'\]$"):
        robot_from_toml_string(GOOD.replace('name = "j2"', 'name = "j1"', 1), source="arm.toml")


def test_description_without_joints_or_bad_toml_is_refused(tmp_path):
    """No [[joints]] and invalid TOML raise DataError naming the file; a missing file a
    ModelError."""
    with pytest.raises(DataError, match="^TOML text: key 'joints': missing; expected a non-emp"):
        robot_from_toml_string('name = "r"\n')
    with pytest.raises(DataError, match="not valid TOML"):
        robot_from_toml_string("name = \n")
    bad = tmp_path / "arm.toml"
    bad.write_text(GOOD.replace('name = "r"', 'name = "r"\ngravty = 1', 1))
    with pytest.raises(DataError, match=r"^arm.toml: key 'gravty': unknown key; allowed: drive, "):
        dynid.Robot.from_toml(bad)
    with pytest.raises(dynid.ModelError, match="TOML description not found.*none.toml"):
        load_toml(tmp_path / "none.toml")
    with pytest.raises(dynid.ModelError, match="TOML description not found"):
        dynid.Robot.from_toml(tmp_path / "none.toml")


def test_infinite_limits_are_no_limits():
    """``inf`` is accepted for a limit (none), as the writer leaves them out."""
    robot = robot_from_toml_string(GOOD.replace("lower = -1.0", "lower = -inf, effort = inf", 1))
    assert robot.q_min[0] == -np.inf and robot.tau_max[0] == np.inf and robot.q_max[0] == 1.0


def test_neutral_pose_round_trips_and_is_checked():
    """q_neutral survives the TOML round trip; a wrong length raises ModelError naming the key."""
    panda = dynid.panda()
    text = toml_from_robot(panda)
    np.testing.assert_array_equal(robot_from_toml_string(text).q_neutral, panda.q_neutral)
    with pytest.raises(DataError, match=r"key 'q_neutral': expected a list of 7 numbers \[rad"):
        robot_from_toml_string(text.replace("q_neutral = [", "q_neutral = [1.0, "))
