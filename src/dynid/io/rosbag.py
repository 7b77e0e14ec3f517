"""Torque logs from ROS bags: ``sensor_msgs/JointState`` in ROS 1 and ROS 2 recordings.

:func:`load_joint_state_bag` reads a ROS 1 bag (``.bag``) or a ROS 2 bag (a folder with
``metadata.yaml``, sqlite3 or MCAP storage) with ``rosbags`` (pure Python, optional extra
``dynid[ros]``) and returns a :class:`BagImport`: the torque log and what was found.

* **Joints by name.** Each message's ``name`` list may come in any order. A bag name
  matches a robot joint when the names are equal, or when one is the other preceded by a
  prefix ending in ``_`` (``panda_joint1`` matches ``joint1``); of several, the equal
  name, else the one whose prefix matches the most robot joints (franka_ros's
  ``panda_finger_joint1`` does not take ``joint1`` from ``panda_joint1``; see
  :func:`match_joints`). Bag joints that match no robot joint (fingers) are left out,
  said in ``notes``. A missing or ambiguous match is an error unless ``joints=`` names the
  bag's joints in the robot's joint order (the message gives the value to pass).
* **Signals.** ``position`` -> ``q`` [rad or m], ``velocity`` -> ``dq``, ``effort`` ->
  ``tau`` [N m or N]. When no message carries velocities the log is one of positions
  and torques (``velocity_derived``): its ``dq`` is the zero-phase filtered derivative of
  the positions (:func:`~dynid.identification.log.with_derived_velocities`), marked
  derived, so that every command derives it again at its own cut-off and
  :func:`~dynid.io.torque_log.save_torque_log` writes no velocities. Messages without
  effort cannot make a torque log.
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
from numpy.typing import NDArray

from .. import _checks
from ..exceptions import DataError
from ..identification.log import DEFAULT_CUTOFF_HZ, TorqueLog, with_derived_velocities
from .input_files import regular_file

__all__ = [
    "JOINT_STATE_TYPES",
    "BagImport",
    "load_joint_state_bag",
    "match_joints",
    "unused_joints",
]

JOINT_STATE_TYPES = ("sensor_msgs/msg/JointState", "sensor_msgs/JointState")


def _prefix(bag: str, name: str) -> tuple[str, str] | None:
    """How bag name ``bag`` matches robot joint ``name``: ``("", "")`` equal names,
    ``("bag", p)`` the bag's name is ``p + name`` (``p`` ending in ``_``), ``("robot", p)``
    the robot's is ``p + bag``; None: no match (whole ``_``-separated tokens only)."""
    if bag == name:
        return ("", "")
    if bag.endswith("_" + name):
        return ("bag", bag[: -len(name)])
    if name.endswith("_" + bag):
        return ("robot", name[: -len(bag)])
    return None


def match_joints(
    robot_joints: Sequence[str], bag_joints: Sequence[str], joints: Sequence[str] | None = None
) -> list[str]:
    """The bag's joint name for each robot joint, in the robot's order.

    A bag name matches a robot joint when the names are equal, or when one is the other
    preceded by a prefix ending in ``_`` (``panda_joint1`` matches ``joint1``). Where
    several match (``panda_joint1`` and ``panda_finger_joint1`` for ``joint1``), the equal
    name wins, else the one of the prefix that matches the most robot joints
    (``panda_``: all seven; ``panda_finger_``: two). Bag joints that match no robot joint
    (a gripper's) are left out (:func:`unused_joints`).

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
        with no matching bag name, or several that the rule does not tell apart (the
        message lists them and the ``--joints`` value to pass).
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
    cands = {
        name: {b: k for b in bag if (k := _prefix(b, name)) is not None} for name in robot_joints
    }
    reach: dict[tuple[str, str], int] = {}  # robot joints each prefix matches
    for found in cands.values():
        for k in set(found.values()):
            reach[k] = reach.get(k, 0) + 1
    out = []
    for name in robot_joints:
        found = cands[name]
        best = [b for b, k in found.items() if k == ("", "")]
        if not best and found:
            top = max(reach[k] for k in found.values())
            best = [b for b, k in found.items() if reach[k] == top]
        if len(best) != 1:
            what = "no" if not found else f"several ({list(found)})"
            raise DataError(
                f"{what} bag joint(s) match robot joint {name!r}; the bag has {bag}; hint: "
                f"--joints with the bag's name of each robot joint ({', '.join(robot_joints)}), "
                f"in that order, e.g. --joints {_guess(robot_joints, bag, cands)}"
            )
        out.append(best[0])
    return out


def _guess(
    robot_joints: Sequence[str], bag: list[str], cands: dict[str, dict[str, tuple[str, str]]]
) -> str:
    """A ``--joints`` value to start from: each robot joint's first match, else the bag's
    name at its place."""
    names = [
        next(iter(cands[r]), bag[i] if i < len(bag) else r) for i, r in enumerate(robot_joints)
    ]
    return ",".join(names)


def unused_joints(bag_joints: Sequence[str], used: Sequence[str]) -> list[str]:
    """The bag's joints that no robot joint reads (a gripper's fingers), in bag order."""
    return [b for b in dict.fromkeys(bag_joints) if b not in set(used)]


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
        No message carried velocities: the log's ``dq`` is derived from its positions
        (marked so; a saved log holds none).
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
        raise DataError("a ROS 2 bag folder needs metadata.yaml", file=path.name)
    if not path.is_dir():
        regular_file(path)  # not a device (/dev/zero) that rosbags fails on unexpectedly
    if not path.is_dir() and path.suffix != ".bag":
        raise DataError("give a ROS 1 .bag file or a ROS 2 bag folder", file=path.name)
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
        Low-pass cutoff [Hz] of the velocities derived from positions when the bag has
        none (the returned log's ``dq``, never saved).
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
        raise DataError(
            f"cannot read the bag ({_checks.one_line(str(exc))})", file=path.name
        ) from exc
    try:
        conns = [c for c in reader.connections if c.topic == topic]
        if not conns:
            topics = sorted({c.topic for c in reader.connections})
            raise DataError(
                f"no topic {topic!r}; the bag has {_checks.short(topics)}", file=path.name
            )
        bad = [c.msgtype for c in conns if c.msgtype not in JOINT_STATE_TYPES]
        if bad:
            raise DataError(f"topic {topic!r} holds {bad[0]}, not JointState", file=path.name)
        n_total = int(reader.message_count)
        msgs = _Messages(sum(int(getattr(c, "msgcount", 0) or 0) for c in conns))
        for conn, recv_ns, raw in reader.messages(connections=conns):
            msgs.add(recv_ns, reader.deserialize(raw, conn.msgtype))
    except DataError as exc:
        if str(exc).startswith(f"{path.name}:"):
            raise
        raise DataError(str(exc), file=path.name) from None
    except Exception as exc:
        raise DataError(
            f"cannot read the bag ({_checks.one_line(str(exc))})", file=path.name
        ) from exc
    finally:
        reader.close()
    return _assemble(
        path.name, topic, msgs, n_total, robot_joints, joints, velocity_cutoff_hz, gap_factor
    )


#: Messages per chunk of the arrays a bag is read into (at most; the chunks of one
#: joint-name list start at :data:`_FIRST` and double, so that a bag whose messages list the
#: joints in many orders holds a small chunk per order, not a full one).
_CHUNK = 16_384
_FIRST = 4


class _Chunk:
    """Up to ``capacity`` messages of one joint-name list: their index in the bag and
    their ``position``, ``velocity``, ``effort`` in the list's order (NaN where short)."""

    def __init__(self, width: int, capacity: int) -> None:
        self.index = np.empty(capacity, dtype=np.int64)
        self.values = np.full((3, capacity, width), np.nan)
        self.capacity = capacity
        self.size = 0


class _Messages:
    """JointState messages read one at a time into numpy chunks, grouped by their
    joint-name list (a bag of 1.6 million messages is never a list of message objects).

    ``count`` is the expected number of messages (0 when unknown); the per-message
    arrays grow beyond it when needed.
    """

    def __init__(self, count: int) -> None:
        self.n = 0
        self.stamp = np.empty(max(count, 1024), dtype=np.int64)
        self.recv = np.empty_like(self.stamp)
        self.short = np.zeros(self.stamp.size, dtype=bool)  # position or effort short
        self.short_vel = np.zeros(self.stamp.size, dtype=bool)
        self.keys: dict[tuple[str, ...], list[_Chunk]] = {}
        self.any_velocity = False
        self.any_effort = False

    def add(self, recv_ns: int, m: object) -> None:
        """Store one message (``sensor_msgs/JointState``)."""
        k = self.n
        if k == self.stamp.size:
            for a in ("stamp", "recv", "short", "short_vel"):
                old = getattr(self, a)
                new = np.zeros(2 * old.size, dtype=old.dtype)
                new[: old.size] = old
                setattr(self, a, new)
        st = m.header.stamp  # type: ignore[attr-defined]
        self.stamp[k] = int(st.sec) * 1_000_000_000 + int(st.nanosec)
        self.recv[k] = int(recv_ns)
        key = tuple(m.name)  # type: ignore[attr-defined]
        w = len(key)
        chunks = self.keys.setdefault(key, [])
        if not chunks:
            dup = sorted({s for s in key if key.count(s) > 1})
            if dup:  # the last value of the name was taken silently
                raise DataError(
                    f"message {k} names joint(s) {_checks.short(dup)} more than once; a "
                    "JointState message lists each joint once"
                )
            chunks.append(_Chunk(w, _FIRST))
        elif chunks[-1].size == chunks[-1].capacity:
            chunks.append(_Chunk(w, min(2 * chunks[-1].capacity, _CHUNK)))
        c = chunks[-1]
        c.index[c.size] = k
        fields = (m.position, m.velocity, m.effort)  # type: ignore[attr-defined]
        for f, v in enumerate(fields):
            if len(v) >= w:
                c.values[f, c.size] = np.asarray(v[:w], dtype=np.float64)
        self.any_velocity |= len(fields[1]) > 0
        self.any_effort |= len(fields[2]) > 0
        self.short[k] = len(fields[0]) < w or len(fields[2]) < w
        self.short_vel[k] = len(fields[1]) < w
        c.size += 1
        self.n += 1

    def names(self) -> list[str]:
        """Every joint name, in the order of first appearance."""
        seen: dict[str, None] = {}
        for key in self.keys:
            seen.update(dict.fromkeys(key))
        return list(seen)

    def arrays(
        self, mapping: list[str]
    ) -> tuple[NDArray[np.float64], NDArray[np.float64], NDArray[np.float64], NDArray[np.bool_]]:
        """``q, dq, tau`` (N, n) in the order of ``mapping`` and which messages hold every
        joint of it."""
        n, N = len(mapping), self.n
        out = np.full((3, N, n), np.nan)
        has = np.zeros(N, dtype=bool)
        for key, chunks in self.keys.items():
            pos = {s: i for i, s in enumerate(key)}
            if not all(s in pos for s in mapping):
                continue
            idx = [pos[s] for s in mapping]
            for c in chunks:
                rows = c.index[: c.size]
                out[:, rows] = c.values[:, : c.size][:, :, idx]
                has[rows] = True
        return out[0], out[1], out[2], has


def _assemble(
    name: str,
    topic: str,
    msgs: _Messages,
    n_total: int,
    robot_joints: Sequence[str],
    joints: Sequence[str] | None,
    cutoff_hz: float,
    gap_factor: float,
) -> BagImport:
    n_msg = msgs.n
    if n_msg == 0:
        raise DataError(f"topic {topic!r} holds no message", file=name)
    mapping = match_joints(robot_joints, msgs.names(), joints)
    stamps = msgs.stamp[:n_msg]
    notes = []
    extra = unused_joints(msgs.names(), mapping)
    if extra:
        notes.append(f"bag joint(s) {', '.join(extra)} match no robot joint: left out")
    if np.any(stamps == 0):
        stamps = msgs.recv[:n_msg]
        source = "receive"
        notes.append("header stamps unset (zero): receive times of the bag used instead")
    else:
        source = "header"
    has_vel = msgs.any_velocity
    if not msgs.any_effort:
        raise DataError(
            f"no JointState message on {topic!r} holds effort; a torque log needs torques",
            file=name,
        )
    q, dq, tau, keep = msgs.arrays(mapping)
    keep &= ~msgs.short[:n_msg]
    if has_vel:
        keep &= ~msgs.short_vel[:n_msg]
    n_missing = int(np.count_nonzero(~keep))
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
        same = ""
        if n_dup:  # every usable message has the one stamp left
            sec, ns = divmod(int(stamps[0]), 1_000_000_000)
            same = (
                f", {n_dup + 1} sharing one {source} stamp ({sec}.{ns:09d} s): a log needs "
                "messages at distinct times"
            )
        raise DataError(
            f"fewer than 2 usable JointState messages on {topic!r} "
            f"({n_missing} missing a joint or field, {n_nonfinite} with NaN{same})",
            file=name,
        )
    t0 = int(stamps[0])
    t = (stamps - t0).astype(np.float64) * 1e-9
    try:
        if has_vel:
            log = TorqueLog.from_raw(t, q, dq, tau, gap_factor=gap_factor)
        else:
            raw = TorqueLog.from_raw(t, q, np.zeros_like(q), tau, gap_factor=gap_factor)
            log = with_derived_velocities(raw, cutoff_hz)  # marked derived: never saved
    except DataError as exc:
        raise DataError(str(exc), file=name) from exc
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
