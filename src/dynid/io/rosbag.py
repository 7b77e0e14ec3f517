"""Torque logs from ROS bags: ``sensor_msgs/JointState`` in ROS 1 and ROS 2 recordings.

:func:`load_joint_state_bag` reads a ROS 1 bag (``.bag``) or a ROS 2 bag (a folder with
``metadata.yaml``, sqlite3 or MCAP storage) with ``rosbags`` (pure Python, optional extra
``dynid[ros]``) and returns a :class:`BagImport`: the torque log and what was found.

* **Joints by name.** Each message's ``name`` list may come in any order. A bag name
  matches a robot joint when the names are equal, or when one is the other preceded by a
  prefix ending in ``_`` (``panda_joint1`` matches ``joint1``; see :func:`match_joints`).
  A missing or ambiguous match is an error unless ``joints=`` names the bag's joints in
  the robot's joint order.
* **Signals.** ``position`` -> ``q`` [rad or m], ``velocity`` -> ``dq``, ``effort`` ->
  ``tau`` [N m or N]. When no message carries velocities they come from the zero-phase
  filtered derivative of the positions (:func:`dynid.signals.filtered_derivative`), said
  in ``notes``. Messages without effort cannot make a torque log.
* **Time.** ``header.stamp``; when any stamp on the topic is zero (unset), the receive
  times of the bag are used for all messages instead, said in ``notes``. Times are
  seconds **from the first message** (``t0_ns`` holds the first stamp in nanoseconds), so
  float64 keeps nanoseconds over days.
* **Cleaning, counted.** Messages on other topics are skipped; a message lacking one of
  the joints or with fewer ``position``/``velocity``/``effort`` entries than names is
  dropped; one holding NaN or inf in a used value is dropped; messages are sorted by time
  (counted when out of order) and a repeated stamp keeps the first message only.
"""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import dataclass
from pathlib import Path

import numpy as np

from .. import _checks, signals
from ..exceptions import DataError
from ..identification.log import DEFAULT_CUTOFF_HZ, TorqueLog

__all__ = ["JOINT_STATE_TYPES", "BagImport", "match_joints", "load_joint_state_bag"]

JOINT_STATE_TYPES = ("sensor_msgs/msg/JointState", "sensor_msgs/JointState")


def _same(a: str, b: str) -> bool:
    return a == b or a.endswith("_" + b) or b.endswith("_" + a)


def match_joints(
    robot_joints: Sequence[str], bag_joints: Sequence[str], joints: Sequence[str] | None = None
) -> list[str]:
    """The bag's joint name for each robot joint, in the robot's order.

    Parameters
    ----------
    robot_joints : sequence of str
        The robot's joint names (``robot.joint_names``).
    bag_joints : sequence of str
        Every joint name seen in the bag.
    joints : sequence of str, optional
        The bag names in the robot's joint order (overrides the rule).

    Returns
    -------
    list of str, length n

    Raises
    ------
    DataError
        ``joints`` of the wrong length or naming a joint not in the bag; a robot joint
        with no or several matching bag names (the message lists them; hint ``--joints``).
    """
    bag = list(dict.fromkeys(bag_joints))
    if joints is not None:
        joints = list(joints)
        if len(joints) != len(robot_joints):
            raise DataError(
                f"--joints must name {len(robot_joints)} joints (the robot's); got {len(joints)}"
            )
        unknown = [j for j in joints if j not in bag]
        if unknown:
            raise DataError(f"joint(s) {unknown} not in the bag; the bag has {bag}")
        return joints
    out = []
    for name in robot_joints:
        exact = [b for b in bag if b == name]
        cands = exact or [b for b in bag if _same(b, name)]
        if len(cands) != 1:
            what = "no" if not cands else f"several ({cands})"
            raise DataError(
                f"{what} bag joint(s) match robot joint {name!r}; the bag has {bag}; "
                "hint: --joints NAME,... in the robot's joint order"
            )
        out.append(cands[0])
    return out


@dataclass(frozen=True, slots=True)
class BagImport:
    """A torque log read from a bag and what the reading found.

    Attributes
    ----------
    log : TorqueLog
        ``t`` [s] from the first kept message, ``q``, ``dq``, ``tau`` in the robot's order.
    topic : str
    joints : tuple of str
        The bag's joint name for each robot joint.
    time_source : str
        ``"header"`` (header stamps) or ``"receive"`` (bag receive times).
    t0_ns : int
        Time of the first kept message [ns] (the log's ``t = 0``).
    n_messages : int
        Messages on the topic.
    n_other_topics : int
        Messages on other topics (skipped).
    n_missing : int
        Messages dropped for a missing joint or field.
    n_nonfinite : int
        Messages dropped for NaN or inf.
    n_out_of_order : int
        Messages whose time was below the previous one's (sorted).
    n_duplicate_stamps : int
        Messages dropped because their time repeated the previous one.
    velocity_derived : bool
        Velocities from the filtered derivative of positions.
    notes : tuple of str
    """

    log: TorqueLog
    topic: str
    joints: tuple[str, ...]
    time_source: str
    t0_ns: int
    n_messages: int
    n_other_topics: int
    n_missing: int
    n_nonfinite: int
    n_out_of_order: int
    n_duplicate_stamps: int
    velocity_derived: bool
    notes: tuple[str, ...]


def _open(path: Path):  # noqa: ANN202 (a rosbags reader)
    try:
        from rosbags.highlevel import AnyReader
        from rosbags.typesys import Stores, get_typestore
    except ImportError as exc:  # pragma: no cover - depends on the installation
        raise DataError(
            "reading ROS bags needs the optional package rosbags: pip install 'dynid[ros]'"
        ) from exc
    if not path.exists():
        raise DataError(f"bag not found: {str(path)!r}")
    if path.is_dir() and not (path / "metadata.yaml").exists():
        raise DataError(f"{path.name}: a ROS 2 bag folder needs metadata.yaml")
    if path.is_file() and path.suffix != ".bag":
        raise DataError(f"{path.name}: give a ROS 1 .bag file or a ROS 2 bag folder")
    store = Stores.ROS1_NOETIC if path.suffix == ".bag" else Stores.ROS2_HUMBLE
    return AnyReader([path], default_typestore=get_typestore(store))


def load_joint_state_bag(
    path: str | Path,
    robot_joints: Sequence[str],
    *,
    topic: str = "/joint_states",
    joints: Sequence[str] | None = None,
    velocity_cutoff_hz: float = DEFAULT_CUTOFF_HZ,
    gap_factor: float = 1.5,
) -> BagImport:
    """Read ``sensor_msgs/JointState`` messages of a ROS 1 or ROS 2 bag into a torque log.

    Parameters
    ----------
    path : str or Path
        A ROS 1 ``.bag`` file or a ROS 2 bag folder (sqlite3 or MCAP).
    robot_joints : sequence of str
        The robot's joint names; the log's columns follow this order.
    topic : str
        The JointState topic.
    joints : sequence of str, optional
        The bag's joint names in the robot's order (default: :func:`match_joints`).
    velocity_cutoff_hz : float
        Low-pass cutoff [Hz] when velocities are derived from positions.
    gap_factor : float
        See :meth:`TorqueLog.from_raw`.

    Returns
    -------
    BagImport

    Raises
    ------
    DataError
        The bag cannot be read (rosbags' message), the topic is absent or not
        JointState (the topics are listed), joints do not match, no message holds effort,
        fewer than 2 messages survive.
    """
    path = Path(path)
    reader = _open(path)
    try:
        reader.open()
    except Exception as exc:  # rosbags raises its own error classes
        raise DataError(f"{path.name}: cannot read the bag ({_checks.one_line(str(exc))})") from exc
    try:
        conns = [c for c in reader.connections if c.topic == topic]
        if not conns:
            topics = sorted({c.topic for c in reader.connections})
            raise DataError(f"{path.name}: no topic {topic!r}; the bag has {_checks.short(topics)}")
        bad = [c.msgtype for c in conns if c.msgtype not in JOINT_STATE_TYPES]
        if bad:
            raise DataError(f"{path.name}: topic {topic!r} holds {bad[0]}, not JointState")
        n_total = int(reader.message_count)
        msgs = []
        for conn, recv_ns, raw in reader.messages(connections=conns):
            msgs.append((recv_ns, reader.deserialize(raw, conn.msgtype)))
    except DataError:
        raise
    except Exception as exc:
        raise DataError(f"{path.name}: cannot read the bag ({_checks.one_line(str(exc))})") from exc
    finally:
        reader.close()
    return _assemble(
        path.name, topic, msgs, n_total, robot_joints, joints, velocity_cutoff_hz, gap_factor
    )


def _assemble(
    name: str,
    topic: str,
    msgs: list,
    n_total: int,
    robot_joints: Sequence[str],
    joints: Sequence[str] | None,
    cutoff_hz: float,
    gap_factor: float,
) -> BagImport:
    n_msg = len(msgs)
    if n_msg == 0:
        raise DataError(f"{name}: topic {topic!r} holds no message")
    seen: dict[str, None] = {}
    for _, m in msgs:
        seen.update(dict.fromkeys(m.name))
    mapping = match_joints(robot_joints, list(seen), joints)
    n = len(mapping)
    stamps = np.array(
        [int(m.header.stamp.sec) * 1_000_000_000 + int(m.header.stamp.nanosec) for _, m in msgs],
        dtype=np.int64,
    )
    notes = []
    if np.any(stamps == 0):
        stamps = np.array([r for r, _ in msgs], dtype=np.int64)
        source = "receive"
        notes.append("header stamps unset (zero): receive times of the bag used instead")
    else:
        source = "header"
    has_vel = any(len(m.velocity) for _, m in msgs)
    if not any(len(m.effort) for _, m in msgs):
        raise DataError(
            f"{name}: no JointState message on {topic!r} holds effort; a torque log needs torques"
        )
    q = np.full((n_msg, n), np.nan)
    dq = np.full((n_msg, n), np.nan)
    tau = np.full((n_msg, n), np.nan)
    keep = np.ones(n_msg, dtype=bool)
    n_missing = 0
    cache: dict[tuple[str, ...], list[int] | None] = {}
    for k, (_, m) in enumerate(msgs):
        key = tuple(m.name)
        if key in cache:
            idx = cache[key]
        else:
            pos = {s: i for i, s in enumerate(key)}
            idx = [pos[s] for s in mapping] if all(s in pos for s in mapping) else None
            cache[key] = idx
        w = len(key)
        if (
            idx is None
            or len(m.position) < w
            or len(m.effort) < w
            or (has_vel and len(m.velocity) < w)
        ):
            keep[k] = False
            n_missing += 1
            continue
        q[k] = np.asarray(m.position, dtype=np.float64)[idx]
        tau[k] = np.asarray(m.effort, dtype=np.float64)[idx]
        if has_vel:
            dq[k] = np.asarray(m.velocity, dtype=np.float64)[idx]
    finite = np.all(np.isfinite(q), 1) & np.all(np.isfinite(tau), 1)
    if has_vel:
        finite &= np.all(np.isfinite(dq), 1)
    n_nonfinite = int(np.count_nonzero(keep & ~finite))
    keep &= finite
    stamps, q, dq, tau = stamps[keep], q[keep], dq[keep], tau[keep]
    n_out = int(np.count_nonzero(np.diff(stamps) < 0))
    order = np.argsort(stamps, kind="stable")
    stamps, q, dq, tau = stamps[order], q[order], dq[order], tau[order]
    first = np.concatenate([[True], np.diff(stamps) != 0]) if stamps.size else stamps.astype(bool)
    n_dup = int(np.count_nonzero(~first))
    stamps, q, dq, tau = stamps[first], q[first], dq[first], tau[first]
    if stamps.size < 2:
        raise DataError(
            f"{name}: fewer than 2 usable JointState messages on {topic!r} "
            f"({n_missing} missing a joint or field, {n_nonfinite} with NaN)"
        )
    t0 = int(stamps[0])
    t = (stamps - t0).astype(np.float64) * 1e-9
    try:
        if has_vel:
            log = TorqueLog.from_raw(t, q, dq, tau, gap_factor=gap_factor)
        else:
            raw = TorqueLog.from_raw(t, q, np.zeros_like(q), tau, gap_factor=gap_factor)
            dq_d = signals.filtered_derivative(raw.t, raw.q, cutoff_hz)
            log = TorqueLog(raw.t, raw.q, dq_d, raw.tau, None, raw.cleaning)
            notes.append(
                "no velocities in the bag: derived from positions (zero-phase low-pass at "
                f"{cutoff_hz:g} Hz, then central differences)"
            )
    except DataError as exc:
        raise DataError(f"{name}: {exc}") from exc
    for count, what in (
        (n_total - n_msg, "message(s) on other topics skipped"),
        (n_missing, "message(s) missing a joint or field dropped"),
        (n_nonfinite, "message(s) with NaN or inf dropped"),
        (n_out, "message(s) out of time order sorted"),
        (n_dup, "message(s) with a repeated stamp dropped"),
    ):
        if count:
            notes.append(f"{count} {what}")
    if log.cleaning.gaps:
        notes.append(f"{len(log.cleaning.gaps)} gap(s) in time (longer than {gap_factor:g} steps)")
    return BagImport(
        log=log,
        topic=topic,
        joints=tuple(mapping),
        time_source=source,
        t0_ns=t0,
        n_messages=n_msg,
        n_other_topics=n_total - n_msg,
        n_missing=n_missing,
        n_nonfinite=n_nonfinite,
        n_out_of_order=n_out,
        n_duplicate_stamps=n_dup,
        velocity_derived=not has_vel,
        notes=tuple(notes),
    )
