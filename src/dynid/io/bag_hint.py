"""The hint for a ROS bag given where a torque log is read (``--data`` of every command):
the ``dynid import`` that converts it into one, the one place every reader takes it from.

The command names the bag's ``sensor_msgs/JointState`` topic when it is not the default
``/joint_states`` (a Baxter's ``/robot/joint_states``), read from the bag's index or
metadata (:func:`~dynid.io.rosbag.joint_state_topics`: never its messages); its robot is
:data:`ROBOT`, which the command line replaces by the robot options typed
(:func:`dynid.workflows.data_files.with_import_robot`).
"""

from __future__ import annotations

from pathlib import Path

from .. import _checks
from .rosbag import joint_state_topics

__all__ = ["DEFAULT_TOPIC", "ROBOT", "bag_hint"]

#: The robot of a suggested ``dynid import`` in a message, for the caller to fill in.
ROBOT = "--robot ROBOT"

#: The JointState topic ``dynid import`` reads without ``--topic``.
DEFAULT_TOPIC = "/joint_states"

#: The store files of a ROS 2 bag (its folder is the bag).
_STORES = (".db3", ".mcap")


def bag_hint(path: str | Path, lead: str = "; ") -> str:
    """``lead`` and what ``path`` is when it is or holds a ROS bag, and the ``dynid
    import`` that converts it (``; it is a ROS 1 bag: convert it into a torque log with
    'dynid import train1.bag --robot ROBOT --topic /robot/joint_states --out train1.csv'
    and give that file to --data``); empty for any other path. ``path``: a ROS 1
    ``.bag``, a ROS 2 bag's ``.db3``/``.mcap`` store or folder, or a folder holding bags."""
    said = _hint(Path(path))
    return lead + said if said else ""


def _hint(path: Path) -> str:
    """:func:`bag_hint` without its lead."""
    try:
        if path.is_dir():
            return _folder_hint(path)
        if not path.exists():  # a missing file is said as missing, not as a bag
            return ""
    except OSError:  # unreadable: its reader says so
        return ""
    suffix = path.suffix.lower()
    if suffix == ".bag":
        bag, what = path, "a ROS 1 bag"
    elif suffix in _STORES:
        bag, what = path.parent, f"the {suffix} store of a ROS 2 bag, its folder"
    else:
        return ""
    name = bag.name or str(bag)
    return (
        f"it is {what}: convert it into a torque log with {_command(bag, Path(name).stem)} "
        "and give that file to --data"
    )


def _folder_hint(folder: Path) -> str:
    """:func:`bag_hint` of a folder: a ROS 2 bag, or a folder holding bags (the command
    for its first, in name order)."""
    stores = sorted(f.name for f in folder.iterdir() if f.suffix.lower() in _STORES)
    if (folder / "metadata.yaml").exists() or stores:
        held = ", ".join(["metadata.yaml"] * (folder / "metadata.yaml").exists() + stores[:3])
        return (
            f"it is a ROS 2 bag ({held}); convert it into a torque log with "
            f"{_command(folder, folder.name)} and give that file to --data"
        )
    bags = sorted(
        f.name
        for f in folder.iterdir()
        if f.suffix.lower() == ".bag" or (f.is_dir() and (f / "metadata.yaml").exists())
    )
    if not bags:
        return ""
    return (
        f"it holds ROS bag(s) {_checks.names(bags[:5])}; convert each into a torque log "
        f"with {_command(folder / bags[0], Path(bags[0]).stem)} and give those files to --data"
    )


def _command(bag: Path, stem: str) -> str:
    """``'dynid import BAG --robot ROBOT [--topic T] --out STEM.csv'``: with ``--topic``
    when the bag's one JointState topic is not :data:`DEFAULT_TOPIC`, ``--topic TOPIC``
    and its JointState topics when it has several; said when it has none. A bag that
    cannot be opened (no ``rosbags``) gets the command without ``--topic``."""
    topics = joint_state_topics(bag)
    topic, said = "", ""
    if topics is not None and topics != [DEFAULT_TOPIC]:
        if len(topics) == 1:
            topic = f" --topic {topics[0]}"
        elif topics:
            topic = " --topic TOPIC"
            said = f" (TOPIC: one of its JointState topics {_checks.names(topics)})"
        else:
            said = " (it holds no sensor_msgs/JointState topic, the messages it reads)"
    return f"'dynid import {bag} {ROBOT}{topic} --out {stem}.csv'{said}"
