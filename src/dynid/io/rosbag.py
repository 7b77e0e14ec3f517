"""Torque logs from ROS bags: ``sensor_msgs/JointState`` in ROS 1 and ROS 2 recordings.

:func:`load_joint_state_bag` reads a ROS 1 bag (``.bag``) or a ROS 2 bag (a folder with
``metadata.yaml``, sqlite3 or MCAP storage) with ``rosbags`` (pure Python, optional extra
``dynid[ros]``) and returns a :class:`~dynid.io.joint_states.JointStateImport`: the torque
log and what was found. Joints are matched by name, signals, times and cleaning follow
:mod:`dynid.io.joint_states`; messages on other topics are skipped and counted.
"""

from __future__ import annotations

from collections.abc import Mapping, Sequence
from pathlib import Path

from .. import _checks
from ..exceptions import DataError
from ..identification.log import DEFAULT_CUTOFF_HZ
from .input_files import regular_file
from .joint_states import JointStateImport, JointStateMessages, assemble

__all__ = ["JOINT_STATE_TYPES", "held_bags", "joint_state_topics", "load_joint_state_bag"]

JOINT_STATE_TYPES = ("sensor_msgs/msg/JointState", "sensor_msgs/JointState")

#: The store files of a ROS 2 bag (its folder is the bag).
STORES = (".db3", ".mcap")


def held_bags(folder: str | Path) -> list[Path]:
    """The ROS bags ``folder`` holds, in name order: its ROS 1 ``.bag`` files and its
    sub-folders with ``metadata.yaml`` (ROS 2 bags); empty when ``folder`` is a bag itself
    (a ``metadata.yaml`` or a ``.db3``/``.mcap`` store in it), is not a folder, or cannot
    be read. Not looking deeper."""
    folder = Path(folder)
    try:
        if not folder.is_dir() or (folder / "metadata.yaml").exists():
            return []
        entries = sorted(folder.iterdir())
        if any(f.suffix.lower() in STORES for f in entries):
            return []
        return [
            f
            for f in entries
            if (f.suffix.lower() == ".bag" and f.is_file())
            or (f.is_dir() and (f / "metadata.yaml").exists())
        ]
    except OSError:  # unreadable: its reader says so
        return []


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
        if bags := held_bags(path):
            raise DataError(
                f"a folder holding {len(bags)} ROS bag(s) ({_checks.names(b.name for b in bags)}), "
                "not one bag; hint: give one of them, or give the folder to dynid import, which "
                "writes one torque log per bag into the folder --out names",
                file=path.name,
            )
        raise DataError("a ROS 2 bag folder needs metadata.yaml", file=path.name)
    if not path.is_dir():
        regular_file(path)  # not a device (/dev/zero) that rosbags fails on unexpectedly
    if not path.is_dir() and path.suffix != ".bag":
        raise DataError("give a ROS 1 .bag file or a ROS 2 bag folder", file=path.name)
    store = Stores.ROS1_NOETIC if path.suffix == ".bag" else Stores.ROS2_HUMBLE
    return AnyReader([path], default_typestore=get_typestore(store))


def joint_state_topics(path: str | Path) -> list[str] | None:
    """The ``sensor_msgs/JointState`` topics of the bag ``path`` (a ROS 1 ``.bag`` or a
    ROS 2 bag folder), sorted; None when it cannot be opened (``rosbags`` missing, not a
    bag, unreadable). Opening reads the bag's index or metadata only, never its messages:
    cheap for a bag of any length, so that a message may name them."""
    try:
        reader = _open(Path(path))
        reader.open()
    except Exception:  # noqa: BLE001 (rosbags' own error classes): not known, nothing said
        return None
    try:
        return _joint_state_topics(reader.connections)
    finally:
        reader.close()


def _joint_state_topics(connections: Sequence[object]) -> list[str]:
    """The topics of ``connections`` (a rosbags reader's) that hold JointState, sorted."""
    return sorted(
        {
            str(getattr(c, "topic", ""))
            for c in connections
            if getattr(c, "msgtype", None) in JOINT_STATE_TYPES
        }
    )


def _topic_hint(connections: Sequence[object]) -> str:
    """``; hint: ...``: the ``--topic`` of the bag's JointState topic (one), or its
    JointState topics to choose from (several); a bag without one is told so."""
    found = _joint_state_topics(connections)
    if len(found) == 1:
        return f"; hint: its JointState topic is {found[0]}: pass --topic {found[0]}"
    if found:
        return f"; hint: pass --topic with one of its JointState topics {_checks.names(found)}"
    return "; it holds no sensor_msgs/JointState topic"


def load_joint_state_bag(
    path: str | Path,
    robot_joints: Sequence[str],
    *,
    topic: str = "/joint_states",
    joints: Sequence[str] | None = None,
    velocity_cutoff_hz: float = DEFAULT_CUTOFF_HZ,
    gap_factor: float = 1.5,
    past_tip: Mapping[str, tuple[str | None, str]] | None = None,
) -> JointStateImport:
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
        The bag's joint names in the robot's order (default:
        :func:`~dynid.io.joint_states.match_joints`).
    velocity_cutoff_hz : float
        Low-pass cutoff [Hz] of the velocities derived from positions when the bag has
        none (the returned log's ``dq``, never saved).
    gap_factor : float
        See :meth:`TorqueLog.from_raw`.
    past_tip : mapping, optional
        The robot description's joints past its tip, held at 0 in the model (a URDF
        chain's: :func:`~dynid.io.robot.urdf_parse.joints_past_tip`), each with the tip
        that keeps it (or None) and its unit: a recorded one that moves, or rests away
        from 0, is said in ``notes`` with its range and that tip.

    Returns
    -------
    JointStateImport

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
                f"no topic {topic!r}; the bag has {_checks.short(topics)}"
                + _topic_hint(reader.connections),
                file=path.name,
            )
        bad = [c.msgtype for c in conns if c.msgtype not in JOINT_STATE_TYPES]
        if bad:
            raise DataError(f"topic {topic!r} holds {bad[0]}, not JointState", file=path.name)
        n_total = int(reader.message_count)
        msgs = JointStateMessages(sum(int(getattr(c, "msgcount", 0) or 0) for c in conns))
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
    return assemble(
        path.name,
        topic,
        msgs,
        n_total,
        robot_joints,
        joints,
        velocity_cutoff_hz,
        gap_factor,
        past_tip=past_tip,
    )
