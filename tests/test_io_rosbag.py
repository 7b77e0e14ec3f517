"""ROS bags in: JointState from ROS 1 and ROS 2 (sqlite3, MCAP) bags to torque logs.

Reference: bags written with rosbags' own writers from a torque log CSV; the import must
give that CSV's log back (times to 1e-9 s, values exactly), and count what it dropped.
"""

from __future__ import annotations

import dataclasses

import numpy as np
import pytest

import dynid
from dynid.cli.__main__ import main
from dynid.exceptions import DataError
from dynid.identification.log import TorqueLog
from dynid.io.joint_states import match_joints
from dynid.io.rosbag import load_joint_state_bag
from dynid.io.torque_log import load_torque_log, save_torque_log

rosbags = pytest.importorskip("rosbags")
from rosbags.rosbag1 import Writer as Writer1  # noqa: E402
from rosbags.rosbag2 import StoragePlugin  # noqa: E402
from rosbags.rosbag2 import Writer as Writer2  # noqa: E402
from rosbags.typesys import Stores, get_typestore  # noqa: E402

from conftest import TWO_LEAVES  # noqa: E402

JS = "sensor_msgs/msg/JointState"
T0_NS = 1_700_000_000_123_456_789  # an epoch stamp: float64 seconds would lose the ns


def _bag_names(robot):
    return [f"panda_{name}" for name in robot.joint_names]


def _message(ts, ros1, k, stamp_ns, names, q, dq, tau):
    types = ts.types
    stamp = types["builtin_interfaces/msg/Time"](
        sec=stamp_ns // 1_000_000_000, nanosec=stamp_ns % 1_000_000_000
    )
    Header = types["std_msgs/msg/Header"]
    header = Header(seq=k, stamp=stamp, frame_id="") if ros1 else Header(stamp=stamp, frame_id="")
    return types[JS](
        header=header,
        name=list(names),
        position=np.asarray(q, float),
        velocity=np.asarray(dq, float),
        effort=np.asarray(tau, float),
    )


def write_bag(path, kind, messages, *, extra_topic=0, topic="/joint_states", more_js=()):
    """Write ``messages`` (receive_ns, stamp_ns, names, q, dq, tau) to a bag of ``kind`` on
    the JointState ``topic``; the first message again on each JointState topic of
    ``more_js``."""
    ros1 = kind == "ros1"
    ts = get_typestore(Stores.ROS1_NOETIC if ros1 else Stores.ROS2_HUMBLE)
    if ros1:
        writer = Writer1(path)
    else:
        plugin = StoragePlugin.MCAP if kind == "mcap" else StoragePlugin.SQLITE3
        writer = Writer2(path, version=9, storage_plugin=plugin)
    ser = ts.serialize_ros1 if ros1 else ts.serialize_cdr
    with writer as w:
        conn = w.add_connection(topic, JS, typestore=ts)
        other = w.add_connection("/chatter", "std_msgs/msg/String", typestore=ts)
        for k, (recv, stamp, names, q, dq, tau) in enumerate(messages):
            w.write(conn, recv, ser(_message(ts, ros1, k, stamp, names, q, dq, tau), JS))
        for name in more_js:
            recv, stamp, names, q, dq, tau = messages[0]
            js = w.add_connection(name, JS, typestore=ts)
            w.write(js, recv, ser(_message(ts, ros1, 0, stamp, names, q, dq, tau), JS))
        String = ts.types["std_msgs/msg/String"]
        for k in range(extra_topic):
            w.write(other, T0_NS + k, ser(String(data="hello"), "std_msgs/msg/String"))
    return path


def _shuffled(log, robot, seed, t0=T0_NS):
    """Messages of a log with the joint names in a new random order in every message."""
    rng = np.random.default_rng(seed)
    names = np.array(_bag_names(robot))
    out = []
    for k in range(log.n_samples):
        p = rng.permutation(robot.n)
        stamp = t0 + int(round(log.t[k] * 1e9))
        out.append((stamp + 1000, stamp, names[p], log.q[k, p], log.dq[k, p], log.tau[k, p]))
    return out


#: Messages of the shuffled-names bags: 2 s at 1 kHz, more than the 1,024 the reader's
#: arrays start with when a bag does not count its messages (what is checked, every
#: message mapped by its names and stamped to 1e-9 s, does not depend on the length).
N_SHUFFLED = 2_000


@pytest.fixture(scope="module")
def csv_log(tmp_path_factory):
    """A 2 s, 1 kHz Panda log written to CSV and read back (the reference)."""
    rng = np.random.default_rng(11)
    N, n = N_SHUFFLED, 7
    t = np.arange(N) * 1e-3
    log = TorqueLog(t, rng.normal(size=(N, n)), rng.normal(size=(N, n)), rng.normal(size=(N, n)))
    path = save_torque_log(tmp_path_factory.mktemp("csv") / "log.csv", log)
    return load_torque_log(path)


@pytest.mark.parametrize("kind", ["mcap", "sqlite3", "ros1"])
def test_bag_with_shuffled_names_imports_to_the_csv_log(kind, csv_log, tmp_path):
    """2 s at 1 kHz, names shuffled per message: t to 1e-9 s, q, dq, tau exactly."""
    robot = dynid.panda()
    path = tmp_path / ("log.bag" if kind == "ros1" else "bag")
    write_bag(path, kind, _shuffled(csv_log, robot, seed=1), extra_topic=5)
    res = load_joint_state_bag(path, robot.joint_names)
    assert res.joints == tuple(_bag_names(robot)) and res.time_source == "header"
    assert res.t0_ns == T0_NS and res.n_messages == N_SHUFFLED and res.n_other_topics == 5
    np.testing.assert_allclose(res.log.t, csv_log.t, rtol=0, atol=1e-9)
    for k in ("q", "dq", "tau"):
        np.testing.assert_array_equal(getattr(res.log, k), getattr(csv_log, k))
    assert not res.velocity_derived and res.n_missing == res.n_duplicate_stamps == 0


def test_memory_of_a_bag_in_many_name_orders_grows_with_its_messages_only(tmp_path):
    """200 messages, each listing the joints in its own order: the reader holds a small
    chunk per order (it held 16,384 rows per order, 2.75 MB each: 550 MB here, 4.5 GB for
    the 2,000 messages above). Peak traced memory of the read is bounded by 1,000 bytes a
    message of 7 joints (3 fields of 7 float64 are 168 bytes)."""
    import tracemalloc

    robot = dynid.panda()
    log = _small(robot, N=200)
    write_bag(tmp_path / "b", "mcap", _shuffled(log, robot, seed=4))
    tracemalloc.start()
    try:
        res = load_joint_state_bag(tmp_path / "b", robot.joint_names)
        _, peak = tracemalloc.get_traced_memory()
    finally:
        tracemalloc.stop()
    np.testing.assert_array_equal(res.log.q, log.q)
    np.testing.assert_array_equal(res.log.tau, log.tau)
    assert peak < 200 * 7 * 1000 + 2_000_000  # (a fixed 2 MB for the reader itself)


def _small(robot, N=50, seed=3):
    rng = np.random.default_rng(seed)
    t = np.arange(N) * 1e-2
    return TorqueLog(
        t,
        rng.normal(size=(N, robot.n)),
        rng.normal(size=(N, robot.n)),
        rng.normal(size=(N, robot.n)),
    )


def test_bad_messages_are_dropped_and_counted(tmp_path):
    """Missing joint, short effort, NaN, repeated and out-of-order stamps, other topics."""
    robot = dynid.panda()
    log = _small(robot)
    msgs = _shuffled(log, robot, seed=2)
    recv, stamp, names, q, dq, tau = msgs[5]
    msgs[5] = (recv, stamp, names[:-1], q[:-1], dq[:-1], tau[:-1])  # a joint missing
    recv, stamp, names, q, dq, tau = msgs[6]
    msgs[6] = (recv, stamp, names, q, dq, tau[:3])  # effort too short
    recv, stamp, names, q, dq, tau = msgs[7]
    msgs[7] = (recv, stamp, names, np.where(np.arange(7) == 2, np.nan, q), dq, tau)
    msgs.insert(10, msgs[9])  # a repeated stamp
    a, b = msgs[20], msgs[21]  # stamps out of order, received in order
    msgs[20], msgs[21] = (a[0], *b[1:]), (b[0], *a[1:])
    write_bag(tmp_path / "b", "mcap", msgs, extra_topic=3)
    res = load_joint_state_bag(tmp_path / "b", robot.joint_names)
    assert (res.n_missing, res.n_nonfinite, res.n_duplicate_stamps) == (2, 1, 1)
    assert res.n_out_of_order == 1 and res.n_other_topics == 3
    keep = np.setdiff1d(np.arange(log.n_samples), [5, 6, 7])
    np.testing.assert_array_equal(res.log.q, log.q[keep])
    np.testing.assert_allclose(res.log.t, log.t[keep] - log.t[keep][0], atol=1e-9)
    assert any("repeated stamp" in s for s in res.notes)


def test_unset_stamps_fall_back_to_receive_time(tmp_path):
    """Zero header stamps: receive times are used, and the notes say so."""
    robot = dynid.panda()
    log = _small(robot)
    msgs = [(T0_NS + 10**7 * k, 0, *m[2:]) for k, m in enumerate(_shuffled(log, robot, 4))]
    write_bag(tmp_path / "b.bag", "ros1", msgs)
    res = load_joint_state_bag(tmp_path / "b.bag", robot.joint_names)
    assert res.time_source == "receive" and any("receive times" in s for s in res.notes)
    np.testing.assert_allclose(res.log.t, log.t, atol=1e-9)


def test_positions_only_bag_derives_velocities(tmp_path):
    """No velocity field: dq from the filtered derivative of q matches the analytic one."""
    robot = dynid.panda()
    t = np.arange(6000) * 1e-3
    f = np.linspace(0.2, 0.8, robot.n)
    q = np.sin(2 * np.pi * f * t[:, None])
    names = _bag_names(robot)
    msgs = [(T0_NS + int(t[k] * 1e9),) * 2 + (names, q[k], [], np.zeros(7)) for k in range(len(t))]
    write_bag(tmp_path / "b", "sqlite3", msgs)
    res = load_joint_state_bag(tmp_path / "b", robot.joint_names)
    assert res.velocity_derived and res.log.dq_derived
    dq = 2 * np.pi * f * np.cos(2 * np.pi * f * t[:, None])
    inner = slice(1000, -1000)
    assert np.max(np.abs(res.log.dq[inner] - dq[inner])) < 1e-4 * np.max(np.abs(dq))


def test_cli_import_of_a_bag_without_velocities_writes_none(tmp_path, capsys):
    """A bag without velocities: the CSV and NPZ hold positions and torques only (they
    held velocities derived at a fixed 5 Hz that every command then took for measured
    ones), the summary line says so, and the log read back is marked derived with the
    bag's positions and torques; a bag with velocities keeps them, and says nothing."""
    robot = dynid.panda()
    log = _small(robot, N=400)
    no_dq = [(*m[:4], [], m[5]) for m in _shuffled(log, robot, 8)]
    write_bag(tmp_path / "p.bag", "ros1", no_dq)
    for out in ("p.csv", "p.npz"):
        assert main(["import", str(tmp_path / "p.bag"), "--out", str(tmp_path / out)]) == 0
        first = capsys.readouterr().out.splitlines()[0]
        assert first.endswith(
            "; positions and torques only: the bag has no velocities (every command derives "
            "them from the positions at its own cut-off)"
        )
        back = load_torque_log(tmp_path / out)
        assert back.dq_derived
        np.testing.assert_array_equal(back.q, log.q)
        np.testing.assert_array_equal(back.tau, log.tau)
    header = (tmp_path / "p.csv").read_text().splitlines()[2].split(",")
    assert header == ["t", *(f"q{j}" for j in range(1, 8)), *(f"tau{j}" for j in range(1, 8))]
    assert set(np.load(tmp_path / "p.npz").files) == {"t", "q", "tau", "n_rows"}
    write_bag(tmp_path / "v.bag", "ros1", _shuffled(log, robot, 8))
    assert main(["import", str(tmp_path / "v.bag"), "--out", str(tmp_path / "v.csv")]) == 0
    assert "velocities" not in capsys.readouterr().out
    back = load_torque_log(tmp_path / "v.csv")
    assert not back.dq_derived
    np.testing.assert_array_equal(back.dq, log.dq)


def test_match_joints_rule_and_override():
    """Exact names first, then the '_' prefix rule; ambiguity and absence need --joints."""
    robot = ("joint1", "joint2")
    assert match_joints(robot, ["panda_joint2", "panda_joint1"]) == ["panda_joint1", "panda_joint2"]
    assert match_joints(robot, ["joint2", "joint1", "x_joint1"]) == ["joint1", "joint2"]
    with pytest.raises(DataError, match="several .* robot joint 'joint1'.*--joints"):
        match_joints(robot, ["a_joint1", "b_joint1", "joint2"])
    with pytest.raises(DataError, match="no bag joint"):
        match_joints(robot, ["joint10", "joint2"])
    assert match_joints(robot, ["A", "B"], joints=["B", "A"]) == ["B", "A"]
    with pytest.raises(DataError, match="not in the bag"):
        match_joints(robot, ["A", "B"], joints=["B", "C"])
    with pytest.raises(DataError, match="must name 2 joints"):
        match_joints(robot, ["A", "B"], joints=["B"])


def test_bag_errors(tmp_path):
    """Missing bag, wrong topic, no effort: DataError naming the bag and what is wrong."""
    robot = dynid.panda()
    with pytest.raises(DataError, match="bag not found"):
        load_joint_state_bag(tmp_path / "none.bag", robot.joint_names)
    log = _small(robot)
    write_bag(tmp_path / "b", "mcap", _shuffled(log, robot, 5), extra_topic=1)
    with pytest.raises(
        DataError, match=r"no topic '/js'; the bag has \['/chatter', '/joint_states'\]"
    ):
        load_joint_state_bag(tmp_path / "b", robot.joint_names, topic="/js")
    with pytest.raises(DataError, match="holds std_msgs/msg/String, not JointState"):
        load_joint_state_bag(tmp_path / "b", robot.joint_names, topic="/chatter")
    msgs = [(*m[:5], []) for m in _shuffled(log, robot, 6)]
    write_bag(tmp_path / "c", "mcap", msgs)
    with pytest.raises(DataError, match="holds effort"):
        load_joint_state_bag(tmp_path / "c", robot.joint_names)


def test_a_bag_whose_messages_share_one_stamp_names_them(tmp_path):
    """Every message with the same header stamp: the error says so and gives the stamp (it
    said "fewer than 2 usable messages (0 missing a joint or field, 0 with NaN)")."""
    robot = dynid.panda()
    msgs = [(T0_NS + k, T0_NS, *m[2:]) for k, m in enumerate(_shuffled(_small(robot), robot, 7))]
    write_bag(tmp_path / "b", "mcap", msgs)
    with pytest.raises(DataError, match=r"50 sharing one header stamp \(1700000000\.123456789 s\)"):
        load_joint_state_bag(tmp_path / "b", robot.joint_names)


def test_cli_import_writes_a_log_every_command_reads(tmp_path, capsys):
    """dynid import writes CSV/NPZ logs equal to the bag's; errors exit 2 with one line."""
    robot = dynid.panda()
    log = _small(robot, N=200)
    write_bag(tmp_path / "b.bag", "ros1", _shuffled(log, robot, 7))
    for out in ("log.csv", "log.npz"):
        assert main(["import", str(tmp_path / "b.bag"), "--out", str(tmp_path / out)]) == 0
        back = load_torque_log(tmp_path / out)
        np.testing.assert_array_equal(back.tau, log.tau)
    assert "joint1 <- panda_joint1" in capsys.readouterr().out
    argv = ["import", str(tmp_path / "b.bag"), "--out", str(tmp_path / "x.csv")]
    assert main(argv + ["--topic", "/nope"]) == 2
    err = capsys.readouterr().err
    assert err.startswith("dynid import: error:") and err.count("\n") == 1


@pytest.mark.parametrize(
    "yaml_text",
    [
        "rosbag2_bagfile_information:\n  version: [1,\n  storage_identifier: mcap\n: : :\n",
        "rosbag2_bagfile_information:\n\tversion: 5\n",
        "x: " + "[" * 5000 + "]" * 5000 + "\n",
    ],
    ids=["broken-flow", "tab-indent", "nested-5000"],
)
def test_malformed_bag_metadata_is_one_line(tmp_path, capsys, yaml_text):
    """A ROS 2 bag whose metadata.yaml is not YAML: one short error line naming the bag
    (issue 20: YAML errors spread over 4-5 lines)."""
    robot = dynid.panda()
    write_bag(tmp_path / "b", "mcap", _shuffled(_small(robot), robot, 8))
    (tmp_path / "b" / "metadata.yaml").write_text(yaml_text)
    code = main(["import", str(tmp_path / "b"), "--out", str(tmp_path / "x.csv")])
    err = capsys.readouterr().err
    assert code == 2 and err.count("\n") == 1 and len(err) < 800, err
    assert (
        err.startswith("dynid import: error: b: cannot read the bag (") and "Traceback" not in err
    )
    assert not (tmp_path / "x.csv").exists()


def test_a_message_naming_a_joint_twice_is_refused(tmp_path):
    """joint7 listed twice with 0.1 and 5.0 rad: the last value was imported silently."""
    robot = dynid.panda()
    names = [*robot.joint_names, "joint7"]
    q = np.r_[np.full(7, 0.1), 5.0]
    msgs = [
        (T0_NS + k * 10**7 + 1000, T0_NS + k * 10**7, names, q, np.zeros(8), np.ones(8))
        for k in range(20)
    ]
    path = write_bag(tmp_path / "bag", "mcap", msgs)
    with pytest.raises(DataError, match=r"bag: message 0 names joint\(s\) \['joint7'\] more"):
        load_joint_state_bag(path, robot.joint_names)


def test_franka_ros_names_with_finger_joints_match_without_joints_option(tmp_path, capsys):
    """franka_ros's ``panda_joint1..7`` and ``panda_finger_joint1/2``: the finger joints
    also end in ``_joint1``/``_joint2`` and the import was refused as ambiguous ("--joints
    NAME,..."); the prefix that matches every robot joint wins, the fingers are left out
    with a note, and the log is the CSV's."""
    robot = dynid.panda()
    log = _small(robot)
    names = [*_bag_names(robot), "panda_finger_joint1", "panda_finger_joint2"]
    assert match_joints(robot.joint_names, names) == _bag_names(robot)
    messages = [
        (s, s, names, [*log.q[k], 0.02, 0.02], [*log.dq[k], 0.0, 0.0], [*log.tau[k], 0.0, 0.0])
        for k, s in enumerate(T0_NS + int(round(x * 1e9)) for x in log.t)
    ]
    write_bag(tmp_path / "b", "sqlite3", messages)
    res = load_joint_state_bag(tmp_path / "b", robot.joint_names)
    for k in ("q", "dq", "tau"):
        np.testing.assert_array_equal(getattr(res.log, k), getattr(log, k))
    assert any(
        "panda_finger_joint1, panda_finger_joint2 match no robot joint" in s for s in res.notes
    )
    out = tmp_path / "log.csv"
    assert main(["import", str(tmp_path / "b"), "--robot", "panda", "--out", str(out)]) == 0
    np.testing.assert_array_equal(load_torque_log(out).q, log.q)


def test_an_ambiguous_or_missing_match_says_what_to_pass():
    """The hint names the robot's joints in order and a --joints value to start from."""
    with pytest.raises(
        DataError,
        match=r"--joints with the bag's name of each robot joint "
        r"\(joint1, joint2\), in that order, e.g. --joints a_joint1,joint2",
    ):
        match_joints(("joint1", "joint2"), ["a_joint1", "b_joint1", "joint2"])
    with pytest.raises(DataError, match=r"e.g. --joints A,B$"):
        match_joints(("shoulder", "elbow"), ["A", "B", "C"])


def test_a_bag_folder_given_to_data_names_the_import_that_converts_it(
    tmp_path, capsys, monkeypatch
):
    """Regression: identify --data on a ROS 2 bag folder said only "the folder holds no .csv
    or .npz data file"; it names the bag and the dynid import that converts it, and that
    command, run as given, writes the log the bag holds."""
    robot = dynid.panda()
    log = _small(robot, N=60, seed=9)
    write_bag(tmp_path / "rec_a", "sqlite3", _shuffled(log, robot, 10))
    monkeypatch.chdir(tmp_path)
    assert main(["identify", "--robot", "panda", "--data", "rec_a", "--out", "o"]) == 2
    err = capsys.readouterr().err
    assert (
        "rec_a: the folder holds no .csv or .npz data file: it is a ROS 2 bag (metadata.yaml" in err
    )
    command = err.split("'dynid ")[1].split("'")[0].replace("ROBOT", "panda")
    assert command == "import rec_a --robot panda --out rec_a.csv", err
    assert main(command.split()) == 0
    back = load_torque_log(tmp_path / "rec_a.csv")
    np.testing.assert_array_equal(back.tau, log.tau)
    np.testing.assert_allclose(back.t, log.t, atol=1e-9)


def test_a_ros1_bag_given_to_data_names_the_import_that_converts_it(tmp_path, capsys, monkeypatch):
    """Regression (a Baxter trial's identify --data train1.bag said only "a data file must
    be .csv or .npz"): it names the dynid import that converts the bag, as the bag-folder
    case does, and that command, run as given, writes the log the bag holds."""
    robot = dynid.panda()
    log = _small(robot, N=60, seed=9)
    write_bag(tmp_path / "train1.bag", "ros1", _shuffled(log, robot, 10))
    monkeypatch.chdir(tmp_path)
    assert main(["identify", "--robot", "panda", "--data", "train1.bag", "--out", "o"]) == 2
    err = capsys.readouterr().err
    assert "train1.bag: a data file must be .csv or .npz; it is a ROS 1 bag" in err, err
    command = err.split("'dynid ")[1].split("'")[0].replace("ROBOT", "panda")
    assert command == "import train1.bag --robot panda --out train1.csv", err
    assert main(command.split()) == 0
    back = load_torque_log(tmp_path / "train1.csv")
    np.testing.assert_array_equal(back.tau, log.tau)
    np.testing.assert_allclose(back.t, log.t, atol=1e-9)


@pytest.mark.parametrize("folder", [False, True], ids=["bag", "folder-of-bags"])
def test_the_suggested_import_keeps_the_robot_options_given(tmp_path, capsys, folder):
    """Regression (a Baxter trial: identify --robot baxter.urdf --base ... --tip ... --data
    train1.bag suggested 'dynid import train1.bag --robot ROBOT', which on that URDF of
    many leaves failed with "several leaf links"): the suggestion carries the --robot,
    --base and --tip typed, and the bag as given, and run as given it writes the log the
    bag holds (joints matched by the chain's names)."""
    urdf = tmp_path / "two.urdf"
    urdf.write_text(TWO_LEAVES)
    names = ["shoulder", "elbow"]
    rng = np.random.default_rng(4)
    t = np.arange(40) * 1e-2
    q, dq, tau = (rng.normal(size=(40, 2)) for _ in range(3))
    stamps = [T0_NS + int(round(x * 1e9)) for x in t]
    msgs = [(s + 1000, s, names, q[k], dq[k], tau[k]) for k, s in enumerate(stamps)]
    (tmp_path / "logs").mkdir()
    bag = write_bag(tmp_path / "logs" / "train1.bag", "ros1", msgs)
    robot = ["--robot", str(urdf), "--base", "world", "--tip", "lower"]
    data = str(bag.parent if folder else bag)
    argv = ["identify", *robot, "--data", data, "--out", str(tmp_path / "o")]
    assert main(argv) == 2
    err = capsys.readouterr().err
    command = err.split("'dynid ")[1].split("'")[0]
    out = tmp_path / "train1.csv"
    assert command == f"import {bag} {' '.join(robot)} --out train1.csv", err
    assert main([*command.split()[:-1], str(out), "-q"]) == 0
    back = load_torque_log(out)
    np.testing.assert_array_equal(back.tau, tau)
    np.testing.assert_array_equal(back.q, q)


@pytest.mark.parametrize(
    ("command", "kind"),
    [
        (["validate", "--robot", "panda"], "ros1"),
        (["friction", "--robot", "panda"], "ros1"),
        (["observe", "--params", "panda", "--calibrate"], "ros1"),
        (["validate", "--robot", "panda", "--columns", "tau=effort_{i}"], "ros1"),
        (["friction", "--robot", "panda"], "sqlite3"),
    ],
    ids=["validate", "friction", "observe", "validate-columns", "friction-db3"],
)
def test_every_log_reader_names_the_import_of_a_bag_with_its_topic(
    tmp_path, capsys, monkeypatch, command, kind
):
    """Regression (a Baxter trial): validate, friction and observe given a bag said only
    "torque log must be a .csv or .npz file" (a mapped read "expected a .csv or .npz
    file"), and identify's suggested import lacked the --topic of a bag whose JointState
    topic is not /joint_states (Baxter's /robot/joint_states), so that following it ended
    in "no topic '/joint_states'". Every reader names the import, with the bag's topic,
    and that command, run as given, writes the log the bag holds."""
    robot = dynid.panda()
    log = _small(robot, N=40, seed=14)
    ros1 = kind == "ros1"
    bag = write_bag(
        tmp_path / ("train1.bag" if ros1 else "train1"),
        kind,
        _shuffled(log, robot, 15),
        extra_topic=2,
        topic="/robot/joint_states",
    )
    data = bag if ros1 else next(bag.glob("*.db3"))
    monkeypatch.chdir(tmp_path)
    assert main([*command, "--data", str(data.relative_to(tmp_path)), "--out", "o"]) == 2
    err = capsys.readouterr().err
    assert err.split(": error: ")[1].startswith(f"{data.name}: "), err
    command = err.split("'dynid ")[1].split("'")[0].replace("ROBOT", "panda")
    given = "train1.bag" if ros1 else "train1"  # a ROS 2 bag's store: its folder
    topic = "--topic /robot/joint_states"
    assert command == f"import {given} --robot panda {topic} --out train1.csv", err
    assert main([*command.split(), "-q"]) == 0
    back = load_torque_log(tmp_path / "train1.csv")
    np.testing.assert_array_equal(back.tau, log.tau)
    np.testing.assert_allclose(back.t, log.t, atol=1e-9)


def test_the_suggested_import_lists_several_joint_state_topics(tmp_path, capsys):
    """A bag of several JointState topics (or none): the suggestion leaves --topic to the
    user and lists the JointState topics written; a bag without one says so; the import
    on a missing topic names the bag's one JointState topic."""
    robot = dynid.panda()
    msgs = _shuffled(_small(robot, N=10, seed=16), robot, 17)
    bag = write_bag(tmp_path / "two.bag", "ros1", msgs, more_js=["/left/joint_states"])
    assert main(["validate", "--robot", "panda", "--data", str(bag), "--out", "o"]) == 2
    err = capsys.readouterr().err
    assert (
        f"'dynid import {bag} --robot panda --topic TOPIC --out two.csv' (TOPIC: one of its "
        "JointState topics /joint_states, /left/joint_states)" in err
    ), err
    none = tmp_path / "none.bag"
    with Writer1(none) as w:
        ts = get_typestore(Stores.ROS1_NOETIC)
        conn = w.add_connection("/chatter", "std_msgs/msg/String", typestore=ts)
        w.write(
            conn,
            T0_NS,
            ts.serialize_ros1(ts.types["std_msgs/msg/String"](data="x"), "std_msgs/msg/String"),
        )
    assert main(["validate", "--robot", "panda", "--data", str(none), "--out", "o"]) == 2
    assert "--out none.csv' (it holds no sensor_msgs/JointState topic" in capsys.readouterr().err
    one = write_bag(tmp_path / "one.bag", "ros1", msgs, topic="/robot/joint_states")
    said = r"hint: its JointState topic is /robot/joint_states: pass --topic /robot/joint_states$"
    with pytest.raises(DataError, match=said):
        load_joint_state_bag(one, robot.joint_names)


def test_import_labels_the_effort_with_the_drives_unit(tmp_path, capsys):
    """Regression: dynid import wrote 'tau [N m]' on the units line of motor currents; with
    a --drive whose effort is current it writes 'tau [A]' (which identify refuses to read
    without such a drive), and says so; without one 'tau [N m]'."""
    from dynid.io.torque_log import declared_tau_unit

    robot = dynid.panda()
    log = _small(robot, N=40, seed=12)
    write_bag(tmp_path / "b.bag", "ros1", _shuffled(log, robot, 13))
    drive = tmp_path / "drive.toml"
    drive.write_text(
        'schema = "dynid-drive/1"\nside = "joint"\neffort = "current"\n'
        "gear_ratio = [100, 100, 100, 100, 100, 100, 100]\n"
        "torque_constant = [0.1, 0.1, 0.1, 0.1, 0.1, 0.1, 0.1]\n"
    )
    argv = ["import", str(tmp_path / "b.bag"), "--robot", "panda"]
    assert main([*argv, "--drive", str(drive), "--out", str(tmp_path / "a.csv")]) == 0
    assert main([*argv, "--out", str(tmp_path / "t.csv")]) == 0
    assert declared_tau_unit(tmp_path / "a.csv") == "A"
    assert declared_tau_unit(tmp_path / "t.csv") == "N m"
    np.testing.assert_array_equal(load_torque_log(tmp_path / "a.csv").tau, log.tau)
    assert "tau in A: motor currents" in capsys.readouterr().out


def test_the_suggested_import_of_a_model_run_takes_the_model(tmp_path, capsys, monkeypatch):
    """Regression (a Baxter trial): validate --model id.json given a bag suggested
    'dynid import train1.bag --robot ROBOT', a robot the user never typed. The suggestion
    names the model, and ``dynid import --model`` reads the model's robot and drive: run as
    given, it writes the bag's log with the drive's effort unit (a geared arm logged in
    motor currents: tau [A])."""
    from dynid.io.model_json import save_model_json

    from conftest import exact_model, geared_drive

    robot = dynid.panda()
    model = dataclasses.replace(exact_model(robot, robot), drive=geared_drive())
    save_model_json(tmp_path / "id.json", model)
    log = _small(robot, N=40, seed=21)
    write_bag(tmp_path / "train1.bag", "ros1", _shuffled(log, robot, 22))
    monkeypatch.chdir(tmp_path)
    argv = ["validate", "--model", "id.json", "--data", "train1.bag", "--out", "o"]
    assert main(argv) == 2
    err = capsys.readouterr().err
    command = err.split("'dynid ")[1].split("'")[0]
    assert command == "import train1.bag --model id.json --out train1.csv", err
    assert main([*command.split(), "-q"]) == 0
    assert "tau [A]" in (tmp_path / "train1.csv").read_text().splitlines()[0]
    back = load_torque_log(tmp_path / "train1.csv")
    np.testing.assert_array_equal(back.tau, log.tau)
    assert main([*command.split(), "--robot", "panda"]) == 2
    assert "--robot applies to a run without --model only" in capsys.readouterr().err


def _two_bags(tmp_path, robot, folder="bags"):
    """Two ROS 2 bags ``a`` and ``b`` (sqlite3, MCAP) in ``folder``, and their logs."""
    (tmp_path / folder).mkdir(exist_ok=True)
    logs = {"a": _small(robot, N=40, seed=31), "b": _small(robot, N=30, seed=32)}
    for (name, log), kind in zip(logs.items(), ("sqlite3", "mcap"), strict=True):
        write_bag(tmp_path / folder / name, kind, _shuffled(log, robot, 33))
    return logs


def test_import_of_several_bags_or_a_folder_of_them_writes_one_log_each(tmp_path, capsys):
    """Regression (a Z1 trial: 'dynid import bags/' of two bag folders failed with "a ROS 2
    bag folder needs metadata.yaml", and no command imported several bags): a folder of
    bags, or the bags given one by one, write one torque log each into the folder --out
    names, each the log its bag holds; a file --out is refused; read as one bag, the
    folder says it holds two and what to run."""
    robot = dynid.panda()
    logs = _two_bags(tmp_path, robot)
    bags = tmp_path / "bags"
    with pytest.raises(DataError, match=r"bags: a folder holding 2 ROS bag\(s\) \(a, b\), not one"):
        load_joint_state_bag(bags, robot.joint_names)
    for out, given in (("logs", [bags]), ("logs2", [bags / "a", bags / "b"])):
        argv = ["import", *map(str, given), "--out", str(tmp_path / out), "-q"]
        assert main(argv) == 0
        written = sorted(p.name for p in (tmp_path / out).iterdir() if p.name[0] != ".")
        assert written == ["a.csv", "b.csv"]
        for name, log in logs.items():
            back = load_torque_log(tmp_path / out / f"{name}.csv")
            np.testing.assert_array_equal(back.tau, log.tau)
            np.testing.assert_allclose(back.t, log.t, atol=1e-9)
    assert main(["import", str(bags), "--out", str(tmp_path / "x.csv")]) == 2
    assert "give a folder (--out logs)" in capsys.readouterr().err
    assert not (tmp_path / "x.csv").exists()


def test_several_bags_given_to_data_name_one_import_for_them_all(tmp_path, capsys, monkeypatch):
    """Regression (a Z1 trial: identify --data train1 train2, two bag folders, gave the
    import of train1 only): the hint names both bags and one dynid import of them all;
    run as given, it writes both logs into the folder the hint then gives to --data."""
    robot = dynid.panda()
    logs = _two_bags(tmp_path, robot, folder=".")
    monkeypatch.chdir(tmp_path)
    assert main(["identify", "--robot", "panda", "--data", "a", "b", "--out", "o"]) == 2
    err = capsys.readouterr().err
    assert "error: a, b: 2 ROS bags, not torque logs" in err and err.endswith("--data logs\n")
    command = err.split("'dynid ")[1].split("'")[0]
    assert command == "import a b --robot panda --out logs", err
    assert main([*command.split(), "-q"]) == 0
    for name, log in logs.items():
        np.testing.assert_array_equal(load_torque_log(f"logs/{name}.csv").q, log.q)


_GRIPPER_ARM = TWO_LEAVES.replace(
    "</robot>",
    """<link name="finger"><inertial><origin xyz="0.05 0 0"/><mass value="0.2"/>
    <inertia ixx="1e-4" ixy="0" ixz="0" iyy="1e-4" iyz="0" izz="1e-4"/></inertial></link>
  <joint name="grip" type="revolute"><parent link="lower"/><child link="finger"/>
    <origin xyz="0.2 0 0"/><axis xyz="0 0 1"/>
    <limit lower="-1.5" upper="0" effort="5" velocity="3"/></joint>
</robot>""",
)


@pytest.mark.parametrize("grip", [(-0.8, -0.2), (0.0, 0.0)], ids=["moving", "at-zero"])
def test_a_recorded_joint_past_the_tip_is_said_with_its_range(tmp_path, capsys, grip):
    """Regression (a Z1 trial: --tip before the recorded gripper joint called it a joint
    that "match[es] no robot joint", and the URDF note said the gripper at rest "is the
    best description of them there is", though the bag held it moving from -1.29 to
    -0.24 rad): a joint past the tip that the bag records moving is said with its
    recorded range and the --tip that keeps it; one the bag holds at 0 is left out as
    before. (The URDF's own note: tests/test_urdf.py.)"""
    urdf = tmp_path / "arm.urdf"
    urdf.write_text(_GRIPPER_ARM)
    names = ["grip", "elbow", "shoulder"]
    rng = np.random.default_rng(41)
    g = np.linspace(*grip, 30)
    msgs = [
        (T0_NS + k * 10**7, T0_NS + k * 10**7, names, [g[k], *rng.normal(size=2)], [], [0, 1, 2])
        for k in range(30)
    ]
    bag = write_bag(tmp_path / "b", "sqlite3", msgs)
    robot = ["--robot", str(urdf), "--base", "world", "--tip", "lower"]
    assert main(["import", str(bag), *robot, "--out", str(tmp_path / "log.csv")]) == 0
    out = capsys.readouterr().out
    if grip[0] == 0.0:
        assert "note: bag joint(s) grip match no robot joint: left out" in out
        return
    assert (
        "note: bag joint grip lies past the robot's tip, where the model holds its links at "
        "rest (its joint at 0), but the bag records it moving from -0.8 to -0.2 rad, never at "
        "0: the model misdescribes what the arm carries there; --tip finger keeps it" in out
    ), out
    assert "match no robot joint" not in out
    kept = ["import", str(bag), "--robot", str(urdf), "--base", "world", "--tip", "finger"]
    assert main([*kept, "--out", str(tmp_path / "all.csv"), "-q"]) == 0
    np.testing.assert_array_equal(load_torque_log(tmp_path / "all.csv").q[:, 2], g)
