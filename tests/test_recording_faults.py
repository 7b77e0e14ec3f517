"""Faults of one recording that every command refuses alike, before any fit or residual.

Reference: a simulated Panda log (the robot's own model) in radians and N m, rewritten
with one fault: one joint's columns in degrees (``x 180 / pi``), the torques of every joint
or of some joints negated. The Panda's joint limits and gravity torques are the model's.
Before, ``identify`` never checked the joint limits (one joint in degrees: exit 0, a model
of 16.8 % training error), ``observe --calibrate`` calibrated on torques of the opposite
sign (thresholds 80 times too wide), and a sign flipped on some joints was told to flip
them all with ``--units tau=-1``.
"""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest

import dynid
from dynid.cli.__main__ import main
from dynid.dynamics.terms import gravity_torques
from dynid.exceptions import DataError, DynidWarning
from dynid.identification.log import TorqueLog
from dynid.identification.model_sign import opposite_sign
from dynid.identification.sanity import check_torque_log
from dynid.io.torque_log import save_torque_log
from dynid.simulation.measurement import sample_times, simulate_measurement
from dynid.simulation.trajectories import random_fourier
from dynid.workflows.recordings import Recorded, check_limits

DEG = 180.0 / np.pi


@pytest.fixture(scope="module")
def panda():
    return dynid.panda()


@pytest.fixture(scope="module")
def log(panda) -> TorqueLog:
    traj = random_fourier(panda, np.random.default_rng(4))(sample_times(4.0, 200.0))
    g = simulate_measurement(panda, traj, rng=np.random.default_rng(5))
    return TorqueLog(g.t, g.q, g.dq, g.tau)


def _joint_in_degrees(log: TorqueLog, j: int) -> TorqueLog:
    q, dq = log.q.copy(), log.dq.copy()
    q[:, j] *= DEG
    dq[:, j] *= DEG
    return TorqueLog(log.t, q, dq, log.tau)


def _flipped(log: TorqueLog, joints: list[int]) -> TorqueLog:
    tau = log.tau.copy()
    tau[:, joints] *= -1
    return TorqueLog(log.t, log.q, log.dq, tau)


def test_one_joint_in_degrees_is_refused_naming_the_file_the_joint_and_the_fix(panda, log):
    """Joint 1 in degrees (it spans more than its limits' width, which it fits read in
    degrees): refused; the same log shifted by 3 rad (another robot) only warned about."""
    deg = _joint_in_degrees(log, 0)
    assert np.ptp(deg.q[:, 0]) > panda.q_max[0] - panda.q_min[0]
    with pytest.raises(DataError) as e:
        check_limits(Recorded((deg,), (Path("one.csv"),)), panda)
    said = str(e.value)
    assert said.startswith("one.csv: joint(s) in degrees among joints in radians")
    first, second = panda.joint_names[:2]
    assert f"convert the positions and velocities of {first} to radians" in said
    assert f"{second} spans" not in said
    whole = TorqueLog(log.t, log.q * DEG, log.dq * DEG, log.tau)
    with pytest.raises(DataError, match=r"w.csv: positions in degrees.*--units q=deg,dq=deg/s"):
        check_limits(Recorded((whole,), (Path("w.csv"),)), panda)
    shifted = TorqueLog(log.t, log.q + 3.0, log.dq, log.tau)
    with pytest.warns(UserWarning, match="far outside the limits"):
        check_limits(Recorded((shifted,), (Path("s.csv"),)), panda)


def test_identify_refuses_one_joint_in_degrees(panda, log, tmp_path, capsys):
    """The command: exit 2 with one line naming the file and the joint (it fitted, exit
    0)."""
    save_torque_log(tmp_path / "deg1.csv", _joint_in_degrees(log, 0))
    argv = ["identify", "--robot", "panda", "--data", str(tmp_path / "deg1.csv")]
    assert main([*argv, "--out", str(tmp_path / "i"), "--no-figures"]) == 2
    err = [s for s in capsys.readouterr().err.splitlines() if "error" in s]
    assert len(err) == 1 and "deg1.csv" in err[0] and panda.joint_names[0] in err[0], err


def test_observe_refuses_torques_of_the_opposite_sign(log, tmp_path, capsys):
    """observe --calibrate on a log whose torques are all negated: refused in one line
    naming the file and --units tau=-1, as identify refuses it."""
    save_torque_log(tmp_path / "neg.csv", TorqueLog(log.t, log.q, log.dq, -log.tau))
    argv = ["observe", "--params", "panda", "-q", "--calibrate"]
    assert main([*argv, "--data", str(tmp_path / "neg.csv"), "--out", str(tmp_path / "c")]) == 2
    err = [s for s in capsys.readouterr().err.splitlines() if "error" in s]
    assert len(err) == 1 and "neg.csv" in err[0] and "--units tau=-1" in err[0], err


@pytest.mark.parametrize("flipped", [[3], [6], [3, 6]])
def test_observe_calibrate_refuses_a_sign_flipped_on_some_joints(
    panda, log, flipped, tmp_path, capsys
):
    """Joint 4 (one of three joints gravity loads, computed here) or joint 7 (which
    gravity does not load: that check cannot tell) negated: ``observe --calibrate`` exits
    2 with one line naming the file, the joints (those gravity loads when there are any,
    told first) and the columns to flip (it wrote thresholds blind on them, the residual
    there twice the torque); the unflipped
    log calibrates. Detecting on the flipped log with the right thresholds: refused as
    identify refuses it where gravity tells the sign (joint 4), else it reports its events
    and warns once, naming the file."""
    g = gravity_torques(panda, log.q)
    loaded = np.std(g, axis=0) > 0.05 * np.std(g, axis=0).max()
    assert loaded[3] and not loaded[6] and np.sum(loaded) >= 3
    save_torque_log(tmp_path / "some.csv", _flipped(log, flipped))
    save_torque_log(tmp_path / "free.csv", log)
    argv = ["observe", "--params", "panda", "-q", "--calibrate", "--no-figures"]
    assert main([*argv, "--data", str(tmp_path / "free.csv"), "--out", str(tmp_path / "f")]) == 0
    assert main([*argv, "--data", str(tmp_path / "some.csv"), "--out", str(tmp_path / "c")]) == 2
    err = [s for s in capsys.readouterr().err.splitlines() if "error" in s]
    assert len(err) == 1 and "some.csv" in err[0], err
    head = err[0].split(" are anti-correlated")[0].split("the measured torques of ")[1]
    # the gravity check names the joints gravity loads, before any residual is read
    named = {panda.joint_names[j] for j in flipped if loaded[j]}
    assert set(head.split(", ")) == (named or {panda.joint_names[j] for j in flipped})
    flags = ",".join(f"tau{panda.joint_names.index(x) + 1}=-1" for x in sorted(named))
    assert not named or f"hint: --units {flags} reads" in err[0]
    assert not (tmp_path / "c" / "thresholds.json").exists()
    detect = ["observe", "--params", "panda", "--no-figures", "--data", str(tmp_path / "some.csv")]
    th = ["--thresholds", str(tmp_path / "f" / "thresholds.json"), "--out", str(tmp_path / "d")]
    if 3 in flipped:  # gravity tells joint 4's sign: refused, as identify refuses it
        assert main([*detect, *th]) == 2
        err = [s for s in capsys.readouterr().err.splitlines() if "error" in s]
        assert len(err) == 1 and "some.csv" in err[0] and "tau4" in err[0], err
        return
    assert main([*detect, *th]) == 0  # detection reports, and says why
    warned = [s for s in capsys.readouterr().err.splitlines() if "anti-correlated" in s]
    assert len(warned) == 1 and warned[0].startswith("dynid observe: warning: some.csv: ")


def test_a_sign_flipped_on_some_joints_names_them(panda, log):
    """Joints 1-3 negated (as in the trial): the finding names exactly those three (joint
    1, which gravity does not load (computed here), by the whole rigid-body torques: it
    went unnamed), gives the --units entries that flip them alone, and does not say
    --units tau=-1 would fix it; all negated: --units tau=-1."""
    flipped = [0, 1, 2]
    g = gravity_torques(panda, log.q)
    loaded = np.std(g, axis=0) > 0.05 * np.std(g, axis=0).max()
    assert not loaded[0]
    said = opposite_sign(panda, _flipped(log, flipped))
    assert said is not None and "some joints only" in said
    head = said.split("is probably opposite")[0].split("the torque sign of ")[1]
    assert set(head.strip().split(", ")) == {panda.joint_names[j] for j in flipped}
    assert "hint: --units tau1=-1,tau2=-1,tau3=-1 reads them flipped" in said
    assert "--units tau=-1" not in said
    every = opposite_sign(panda, _flipped(log, list(range(7))))
    assert every is not None and "hint: --units tau=-1" in every


def _joint(name: str, parent: str, child: str, axis: str) -> str:
    return (
        f'<joint name="{name}" type="revolute"><parent link="{parent}"/><child link="{child}"/>'
        f'<origin xyz="0 0 0.3"/><axis xyz="{axis}"/>'
        '<limit lower="-2" upper="2" effort="10" velocity="2"/></joint>'
        f'<link name="{child}"><inertial><origin xyz="0 0 0.1"/><mass value="1.0"/>'
        '<inertia ixx="0.01" ixy="0" ixz="0" iyy="0.01" iyz="0" izz="0.01"/></inertial></link>'
    )


ARM_WITH_GRIPPER = (
    '<robot name="arm"><link name="base"/>'
    + _joint("shoulder", "base", "upper", "0 0 1")
    + _joint("elbow", "upper", "fore", "0 1 0")
    + _joint("finger_joint", "fore", "finger", "1 0 0")
    + "</robot>"
)


@pytest.mark.parametrize("command", ["identify --robot", "validate --robot", "observe --params"])
def test_a_log_without_the_gripper_joint_names_it_and_the_tip(tmp_path, capsys, command):
    """A URDF chain of 3 joints whose last is a gripper's, a log of the arm's 2: one line
    naming the gripper joint and --tip with the link before it (it said only "6 joints;
    model has 7"); the robot read up to that link has the log's joint count."""
    urdf = tmp_path / "arm.urdf"
    urdf.write_text(ARM_WITH_GRIPPER)
    t = np.arange(0.0, 1.0, 0.01)
    q = 0.3 * np.stack([np.sin(t), np.cos(t)], axis=1)
    save_torque_log(tmp_path / "arm.csv", TorqueLog(t, q, np.gradient(q, t, axis=0), 0 * q))
    argv = [*command.split(), str(urdf), "--data", str(tmp_path / "arm.csv")]
    if command.startswith("observe"):
        argv.append("--calibrate")
    assert main([*argv, "--out", str(tmp_path / "o")]) == 2
    err = [s for s in capsys.readouterr().err.splitlines() if "error" in s]
    assert len(err) == 1 and "arm.csv" in err[0], err
    assert "finger_joint" in err[0] and "--tip fore" in err[0], err
    assert dynid.Robot.from_urdf(urdf, tip_link="fore").n == 2


def test_a_sign_flipped_on_one_joint_of_three_loaded_is_said(panda, log):
    """Joint 4 negated, one of the three joints gravity loads (computed here): refused,
    naming that joint alone (nothing was said: a model of 30 % error, exit 0; then a
    warning, while the documentation said refused)."""
    g = gravity_torques(panda, log.q)
    loaded = np.flatnonzero(np.std(g, axis=0) > 0.05 * np.std(g, axis=0).max())
    assert 3 in loaded and loaded.size >= 3
    refused = opposite_sign(panda, _flipped(log, [3]))
    assert refused is not None and "some joints only" in refused
    found = [f for f in check_torque_log(panda, _flipped(log, [3])) if "anti-correlated" in f]
    assert len(found) == 1 and found[0].startswith(
        f"the measured torques of {panda.joint_names[3]} are anti-correlated"
    )
    assert not [f for f in check_torque_log(panda, log) if "anti-correlated" in f]


@pytest.mark.parametrize("j", [1, 3])
def test_identify_refuses_one_joint_of_the_opposite_sign(panda, log, j, tmp_path, capsys):
    """Regression: one joint gravity loads negated (as documented, the refusal names it):
    identify warned and fitted (a UR5: 29 % held out, exit 0); it exits 2 with one line
    naming the file, the joint and its torque column to flip."""
    save_torque_log(tmp_path / "one.csv", _flipped(log, [j]))
    argv = ["identify", "--robot", "panda", "--data", str(tmp_path / "one.csv"), "--no-figures"]
    assert main([*argv, "--out", str(tmp_path / "i")]) == 2
    err = [s for s in capsys.readouterr().err.splitlines() if "error" in s]
    assert len(err) == 1 and "one.csv" in err[0], err
    head = err[0].split(" are anti-correlated")[0].split("the measured torques of ")[1]
    assert head == panda.joint_names[j], err[0]
    assert f"hint: --units tau{j + 1}=-1 reads it flipped" in err[0]
    assert not (tmp_path / "i" / "identification.json").exists()


def _arm_joint(name: str, parent: str, child: str, axis: str, limits: str) -> str:
    return (
        f'<joint name="{name}" type="{"continuous" if not limits else "revolute"}">'
        f'<parent link="{parent}"/><child link="{child}"/><origin xyz="0 0 0.3"/>'
        f'<axis xyz="{axis}"/><limit {limits} effort="10" velocity="1"/></joint>'
        f'<link name="{child}"><inertial><origin xyz="0.05 0 0.1"/><mass value="1.0"/>'
        '<inertia ixx="0.01" ixy="0" ixz="0" iyy="0.01" iyz="0" izz="0.01"/></inertial></link>'
    )


#: An arm whose base and wrist joints turn without limits (as a Kinova's 1, 4 and 6).
ARM_WITH_CONTINUOUS_JOINTS = (
    '<robot name="arm"><link name="base"/>'
    + _arm_joint("yaw", "base", "l1", "0 0 1", "")
    + _arm_joint("shoulder", "l1", "l2", "0 1 0", 'lower="-2" upper="2"')
    + _arm_joint("elbow", "l2", "l3", "0 1 0", 'lower="-2.5" upper="2.5"')
    + _arm_joint("wrist", "l3", "l4", "1 0 0", "")
    + "</robot>"
)


@pytest.fixture(scope="module")
def arm_log(tmp_path_factory):
    """The arm and a simulated log of it in radians (the reference every conversion of
    the degrees below must give back)."""
    urdf = tmp_path_factory.mktemp("arm") / "arm.urdf"
    urdf.write_text(ARM_WITH_CONTINUOUS_JOINTS)
    arm = dynid.Robot.from_urdf(urdf)
    assert list(np.isfinite(arm.q_max)) == [False, True, True, False]
    traj = random_fourier(arm, np.random.default_rng(7))(sample_times(4.0, 200.0))
    g = simulate_measurement(arm, traj, rng=np.random.default_rng(8))
    return arm, TorqueLog(g.t, g.q, g.dq, g.tau)


def _in_degrees(log: TorqueLog, joints: list[int]) -> TorqueLog:
    q, dq = log.q.copy(), log.dq.copy()
    q[:, joints] *= DEG
    dq[:, joints] *= DEG
    return TorqueLog(log.t, q, dq, log.tau)


def test_a_log_all_in_degrees_is_told_by_every_joint_and_given_units(arm_log):
    """Regression: positions and velocities of every joint in degrees. The joints without
    limits are judged by their speeds (in radians, 57 times what the arm reaches), so the
    refusal says the whole file is in degrees, names every joint and gives --units
    q=deg,dq=deg/s (it named only the joints with limits and said to convert those: the
    others left in degrees read as 1000 % error, 'another robot?'). The log in radians,
    which that option reads the file as, passes."""
    arm, log = arm_log
    with pytest.raises(DataError) as e:
        check_limits(Recorded((_in_degrees(log, [0, 1, 2, 3]),), (Path("deg.csv"),)), arm)
    said = str(e.value)
    assert said.startswith("deg.csv: positions in degrees: ")
    assert said.endswith("hint: --units q=deg,dq=deg/s")
    assert all(name in said for name in arm.joint_names)
    assert "yaw (no position limits) moves at up to" in said
    check_limits(Recorded((log,), (Path("rad.csv"),)), arm)


def test_joints_without_limits_left_in_degrees_are_named(arm_log):
    """Regression: the joints with limits converted to radians, the two without left in
    degrees (following the earlier hint): refused, naming those two and not the others
    (nothing was said: 1000 % error, 'a log of another robot')."""
    arm, log = arm_log
    with pytest.raises(DataError) as e:
        check_limits(Recorded((_in_degrees(log, [0, 3]),), (Path("half.csv"),)), arm)
    said = str(e.value)
    assert said.startswith("half.csv: joint(s) in degrees among joints in radians: yaw ")
    assert "convert the positions and velocities of yaw, wrist to radians" in said
    assert "shoulder" not in said and "elbow" not in said


def test_slow_joints_without_limits_do_not_hide_a_file_in_degrees(arm_log):
    """The joints with limits in degrees and those without too slow to tell (a tenth of a
    degree per second reads as plausible radians per second): --units comes first, the conversion of
    the joints with limits as the alternative."""
    arm, log = arm_log
    scale = np.array([1e-3, 1.0, 1.0, 1e-3])
    slow = TorqueLog(log.t, log.q * scale, log.dq * scale, log.tau)
    with pytest.raises(DataError) as e:
        check_limits(Recorded((_in_degrees(slow, [0, 1, 2, 3]),), (Path("s.csv"),)), arm)
    said = str(e.value)
    assert "positions in degrees on every joint with position limits" in said
    assert "hint: --units q=deg,dq=deg/s if the whole file is in degrees" in said
    assert "the speeds of yaw, wrist, without position limits, do not tell" in said


def test_validate_names_the_joint_of_the_opposite_sign(panda, log, tmp_path, capsys):
    """Regression: validate judged a log with joint 4's torques negated "unusable" with a
    generic hint (another robot, units, sign?) where identify and observe name the joint;
    the verdict stands (exit 1, its files written) and one warning names the file, the
    joint and the --units entry that reads it."""
    save_torque_log(tmp_path / "one.csv", _flipped(log, [3]))
    argv = ["validate", "--robot", "panda", "--data", str(tmp_path / "one.csv"), "--no-figures"]
    assert main([*argv, "--out", str(tmp_path / "v")]) == 1
    said = [s for s in capsys.readouterr().err.splitlines() if "anti-correlated" in s]
    assert len(said) == 1 and "warning: one.csv: " in said[0], said
    assert f"the measured torques of {panda.joint_names[3]} are anti-correlated" in said[0]
    assert "hint: --units tau4=-1 reads it flipped" in said[0]
    assert (tmp_path / "v" / "validation.json").is_file()


def _ur5_log(seed: int, flip: list[int]):
    """8 s at 200 Hz of a UR5 (example-robot-data) moving by up to 0.75 rad about its
    zero pose, where gravity barely varies: Pinocchio's RNEA plus armature, viscous and
    Coulomb friction and sensor noise, the torques of ``flip`` negated."""
    import pinocchio as pin

    from conftest import robot_data_urdf

    path = robot_data_urdf("ur_description/urdf/ur5_robot.urdf")
    robot = dynid.Robot.from_urdf(path, "base_link", "tool0")
    model = pin.buildModelFromUrdf(path)
    model.gravity.linear = np.asarray(robot.gravity)
    data = model.createData()
    rng = np.random.default_rng(seed)
    t = np.arange(0.0, 8.0, 1 / 200)
    w = 2 * np.pi * rng.uniform(0.1, 0.4, (3, 6))
    a = rng.uniform(0.05, 0.25, (3, 6))
    arg = t[:, None, None] * w[None] + rng.uniform(0, 2 * np.pi, (3, 6))[None]
    q, dq = np.sum(a * np.sin(arg), 1), np.sum(a * w * np.cos(arg), 1)
    ddq = -np.sum(a * w**2 * np.sin(arg), 1)
    tau = np.array([pin.rnea(model, data, *s) for s in zip(q, dq, ddq, strict=True)])
    tau += (
        np.array([0.6, 0.6, 0.3, 0.05, 0.05, 0.05]) * ddq + np.array([3, 3, 2, 0.6, 0.6, 0.6]) * dq
    )
    tau += np.array([4, 4, 3, 1, 1, 1]) * np.sign(dq)
    tau += rng.normal(0, 1, tau.shape) * np.array([0.4, 0.4, 0.3, 0.08, 0.08, 0.08])
    tau[:, flip] *= -1
    return robot, TorqueLog(t, q, dq, tau)


@pytest.mark.parametrize("seed", [0, 1, 3])
def test_a_flipped_joint_whose_gravity_barely_varies_is_found_by_its_mean(seed):
    """Regression (a UR5 elbow logged with the opposite sign held +15 N m where the model's
    gravity held -15 N m; its variations, mostly armature and friction, correlated -0.01 to
    -0.43 with the model's, and identify fitted it without a word, its verdict pointing to
    friction and a spring): the torques lie far closer to the negated model's, means
    included, and the finding names the joint and its --units entry; the same log of the
    right sign is not called flipped."""
    robot, log = _ur5_log(seed, [2])
    said = opposite_sign(robot, log)
    assert said is not None and "the measured torques of elbow_joint are" in said, said
    assert "from the negated model's torques" in said and "--units tau3=-1" in said
    assert opposite_sign(*_ur5_log(seed, [])) is None


def test_one_recording_of_another_convention_is_flipped_alone(panda, log, tmp_path):
    """Two recordings, the second logged with joint 4's torque of the opposite sign: the
    fit refuses it naming that file and the entry that flips it alone, which reads it
    alone flipped: the fit is the one of both recordings logged alike (bit for bit); an
    entry naming a file not given is refused in one line. A recording of every joint's
    torque of the opposite sign is named with the file's one entry, c.csv:tau=-1, which
    reads it alike (bit for bit)."""
    from dynid.workflows.identify import IdentifyOptions, identify_files

    half = len(log.t) // 2
    a = TorqueLog(log.t[:half], log.q[:half], log.dq[:half], log.tau[:half])
    b = TorqueLog(log.t[half:], log.q[half:], log.dq[half:], log.tau[half:])
    flipped = b.tau.copy()
    flipped[:, 3] *= -1
    save_torque_log(tmp_path / "a.csv", a)
    save_torque_log(tmp_path / "alike" / "b.csv", b)
    save_torque_log(tmp_path / "b.csv", TorqueLog(b.t, b.q, b.dq, flipped))
    both = [tmp_path / "a.csv", tmp_path / "b.csv"]
    with pytest.raises(DataError, match="b.csv") as exc:
        identify_files(panda, both)
    assert "hint: --units b.csv:tau4=-1 reads it flipped" in str(exc.value), str(exc.value)
    own = identify_files(panda, both, IdentifyOptions(columns=(None, "b.csv:tau4=-1")))
    alike = identify_files(panda, [tmp_path / "a.csv", tmp_path / "alike" / "b.csv"])
    np.testing.assert_array_equal(own.model.fit.beta, alike.model.fit.beta)
    with pytest.raises(DataError, match="c.csv is none of the files given"):
        identify_files(panda, both, IdentifyOptions(columns=(None, "c.csv:tau4=-1")))
    with pytest.raises(DataError, match="unknown unit 'mNn' for 'tau'"):
        identify_files(panda, both, IdentifyOptions(columns=(None, "b.csv:tau=mNn")))
    save_torque_log(tmp_path / "c.csv", TorqueLog(b.t, b.q, b.dq, -b.tau))  # every joint
    every = [tmp_path / "a.csv", tmp_path / "c.csv"]
    with pytest.raises(DataError, match="c.csv") as exc:
        identify_files(panda, every)
    assert "--units c.csv:tau=-1" in str(exc.value), str(exc.value)
    own = identify_files(panda, every, IdentifyOptions(columns=(None, "c.csv:tau=-1")))
    np.testing.assert_array_equal(own.model.fit.beta, alike.model.fit.beta)


def test_one_recording_with_a_joint_recorded_reversed_is_read_back_alone(panda, log, tmp_path):
    """Regression: two recordings, the second with joint 4 recorded reversed (position,
    velocity and torque negated): the refusal's hint was ``--units q4=-1,tau4=-1``, which
    flips the first recording too, and that one was refused next with the same hint. The
    hint now names the file's own entries, which read it back: the fit is the one of both
    recordings logged alike (bit for bit); both recordings reversed alike get the entries
    of every file, the warning on their positions beyond the joint's limits saying that
    negated they lie within them."""
    from dynid.workflows.identify import IdentifyOptions, identify_files

    half = len(log.t) // 2
    a = TorqueLog(log.t[:half], log.q[:half], log.dq[:half], log.tau[:half])
    b = TorqueLog(log.t[half:], log.q[half:], log.dq[half:], log.tau[half:])
    sign = np.array([1.0, 1, 1, -1, 1, 1, 1])
    save_torque_log(tmp_path / "a.csv", a)
    save_torque_log(tmp_path / "alike" / "b.csv", b)
    save_torque_log(tmp_path / "b.csv", TorqueLog(b.t, b.q * sign, b.dq * sign, b.tau * sign))
    both = [tmp_path / "a.csv", tmp_path / "b.csv"]
    with pytest.raises(DataError, match="b.csv: joint4 looks recorded reversed") as exc:
        identify_files(panda, both)
    said = str(exc.value)
    assert "--units b.csv:q4=-1,b.csv:tau4=-1 reads it so in this recording alone" in said, said
    assert "negative gear_ratio" not in said, said
    entries = "b.csv:q4=-1,b.csv:dq4=-1,b.csv:tau4=-1"
    own = identify_files(panda, both, IdentifyOptions(columns=(None, entries)))
    alike = identify_files(panda, [tmp_path / "a.csv", tmp_path / "alike" / "b.csv"])
    np.testing.assert_array_equal(own.model.fit.beta, alike.model.fit.beta)
    save_torque_log(
        tmp_path / "both" / "a.csv", TorqueLog(a.t, a.q * sign, a.dq * sign, a.tau * sign)
    )
    with (
        pytest.raises(DataError, match="joint4 looks recorded reversed") as exc,
        pytest.warns(DynidWarning, match="negated, they lie within them: recorded reversed"),
    ):
        identify_files(panda, [tmp_path / "both" / "a.csv", tmp_path / "b.csv"])
    assert "--units q4=-1,tau4=-1 reads it so (and" in str(exc.value), str(exc.value)


def test_a_log_whose_comment_lines_say_currents_is_not_read_as_torques(panda, log, tmp_path):
    """A CSV whose units line gives its tau columns in A (dynid's own ``tau [A]``, or
    another tool's ``tau [A] (motor current)``), read without a drive of effort =
    "current", is refused naming the unit and the remedy (before, its currents were fitted
    as torques with no word); ``--units tau=Nm`` reads the columns as torques."""
    from dynid.io.torque_log import declared_tau_unit
    from dynid.workflows.identify import IdentifyOptions, identify_files

    path = save_torque_log(tmp_path / "amps.csv", log)
    text = path.read_text()
    assert "tau [N m]" in text and declared_tau_unit(path) == "N m"
    path.write_text(text.replace("tau [N m]", "tau [A]", 1))
    assert declared_tau_unit(path) == "A"
    with pytest.raises(DataError, match=r"tau columns in A \(motor currents\)") as exc:
        identify_files(panda, [path])
    assert 'effort = "current"' in str(exc.value) and "--units tau=Nm" in str(exc.value)
    res = identify_files(panda, [path], IdentifyOptions(columns=(None, "tau=Nm")))
    assert res.model.fit.beta.size > 0
    other = tmp_path / "other.csv"
    other.write_text("# controller export; units: t [s], q [rad], tau [A] (motor current)\n")
    assert declared_tau_unit(other) == "A"


@pytest.fixture(scope="module")
def recorded_right(panda, tmp_path_factory):
    """A Panda log (friction and armature the description lacks, sensor noise) recorded
    the right way, its CSV file, and its fit with default options: computed once for both
    ways of recording joint 3 reversed."""
    from dynid.friction.model import ClassicalFriction
    from dynid.simulation.measurement import SensorNoise
    from dynid.workflows.identify import identify_files

    from conftest import recordings

    fr = ClassicalFriction(np.full(7, 0.3), np.full(7, 0.4), np.zeros(7))
    noise = SensorNoise(tau_std=0.05, q_std=1e-5, dq_std=1e-3)
    kw = dict(friction=fr, armature=np.full(7, 0.2), duration=4.0, noise=noise)
    (right,) = recordings(panda, (81,), **kw)
    path = tmp_path_factory.mktemp("right") / "right.csv"
    save_torque_log(path, right)
    return right, identify_files(panda, [path])


@pytest.mark.parametrize("torque", [True, False])
def test_a_joint_recorded_reversed_is_found_and_read_back(panda, tmp_path, torque, recorded_right):
    """A Panda log (friction and armature the description lacks, sensor noise) whose
    joint 3 was recorded reversed: its position and velocity negated, with its torque (a
    motor mounted the other way) or without (its encoder alone). The fit refuses it naming
    the joint and the entries that read it back; with them, the fit is that of the log as
    recorded the right way, bit for bit; the log itself is not called reversed."""
    from dynid.identification.recorded_signs import reversed_joint
    from dynid.workflows.identify import IdentifyOptions, identify_files

    right, as_is = recorded_right
    assert reversed_joint(panda, right) is None
    sign = np.array([1.0, 1, -1, 1, 1, 1, 1])
    tau = right.tau * sign if torque else right.tau
    save_torque_log(tmp_path / "rev.csv", TorqueLog(right.t, right.q * sign, right.dq * sign, tau))
    entries = "q3=-1,dq3=-1" + (",tau3=-1" if torque else "")
    with pytest.raises(DataError, match="joint3 looks recorded reversed") as exc:
        identify_files(panda, [tmp_path / "rev.csv"])
    assert f"--units q3=-1{',tau3=-1' if torque else ''} reads it so" in str(exc.value)
    back = identify_files(panda, [tmp_path / "rev.csv"], IdentifyOptions(columns=(None, entries)))
    np.testing.assert_array_equal(back.model.fit.beta, as_is.model.fit.beta)
