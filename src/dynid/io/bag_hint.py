"""The hint for a ROS bag given where a torque log is read (``--data`` of every command):
the ``dynid import`` that converts it into one, the one place every reader takes it from.

The command names the bag's ``sensor_msgs/JointState`` topic when it is not the default
``/joint_states`` (a Baxter's ``/robot/joint_states``), read from the bag's index or
metadata (:func:`~dynid.io.rosbag.joint_state_topics`: never its messages); its robot is
:data:`ROBOT`, which the command line replaces by the robot options typed
(:func:`dynid.workflows.data_files.with_import_robot`). Several bags given at once
(:func:`several_bags_hint`) get one command that imports them all, one torque log each
into a folder.
"""

from __future__ import annotations

from collections.abc import Sequence
from pathlib import Path

from .. import _checks
from .rosbag import STORES, held_bags, joint_state_topics

__all__ = ["DEFAULT_TOPIC", "ROBOT", "bag_hint", "bags_given", "several_bags_hint"]

#: The robot of a suggested ``dynid import`` in a message, for the caller to fill in.
ROBOT = "--robot ROBOT"

#: The JointState topic ``dynid import`` reads without ``--topic``.
DEFAULT_TOPIC = "/joint_states"

#: The folder a suggested import of several bags writes their torque logs into.
LOGS = "logs"


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
    elif suffix in STORES:
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
    for its one bag, or for the folder, which imports each of several)."""
    stores = sorted(f.name for f in folder.iterdir() if f.suffix.lower() in STORES)
    if (folder / "metadata.yaml").exists() or stores:
        held = ", ".join(["metadata.yaml"] * (folder / "metadata.yaml").exists() + stores[:3])
        return (
            f"it is a ROS 2 bag ({held}); convert it into a torque log with "
            f"{_command(folder, folder.name)} and give that file to --data"
        )
    bags = held_bags(folder)
    if not bags:
        return ""
    if len(bags) == 1:
        return (
            f"it holds the ROS bag {bags[0].name}; convert it into a torque log with "
            f"{_command(bags[0], bags[0].stem)} and give that file to --data"
        )
    return (
        f"it holds {len(bags)} ROS bags ({_checks.names(b.name for b in bags)}); convert them "
        f"into torque logs, one each, with {_several_command([folder], bags)} and give that "
        "folder to --data"
    )


def bags_given(paths: Sequence[str | Path]) -> list[Path]:
    """The ROS bags among ``paths``, in their order: each a ROS 1 ``.bag`` file, a ROS 2 bag
    folder (or its ``.db3``/``.mcap`` store: the folder), or a folder holding bags (each
    of them, :func:`~dynid.io.rosbag.held_bags`)."""
    out: list[Path] = []
    for p in map(Path, paths):
        try:
            if p.is_dir():
                own = (p / "metadata.yaml").exists() or any(
                    f.suffix.lower() in STORES for f in p.iterdir()
                )
                out += [p] if own else held_bags(p)
            elif p.suffix.lower() == ".bag" and p.exists():
                out.append(p)
            elif p.suffix.lower() in STORES and p.exists():
                out.append(p.parent)
        except OSError:  # unreadable: its reader says so
            continue
    return out


def several_bags_hint(paths: Sequence[str | Path]) -> str:
    """What ``paths`` (``--data``) are when they hold two or more ROS bags, and the one
    ``dynid import`` that converts them all, one torque log each into the folder
    :data:`LOGS` (``train1, train2: ROS bags, not torque logs; convert them ... with
    'dynid import train1 train2 --robot ROBOT --out logs' and give --data logs``); empty
    when they hold fewer."""
    bags = bags_given(paths)
    if len(bags) < 2:
        return ""
    given: list[Path] = []  # as typed: a bag, a folder of bags; a store's folder
    for p in map(Path, paths):
        q = p.parent if p.suffix.lower() in STORES else p
        if (q in bags or held_bags(q)) and q not in given:
            given.append(q)
    out = _logs_folder(bags)
    return (
        f"{_checks.names(b.name for b in bags)}: {len(bags)} ROS bags, not torque logs; "
        f"convert them into torque logs, one each, with {_several_command(given, bags)} "
        f"and give --data {out}"
    )


def _logs_folder(bags: Sequence[Path]) -> str:
    """:data:`LOGS`, or ``torque_logs`` when a bag or its folder is named so."""
    names = {b.name for b in bags} | {b.parent.name for b in bags}
    return LOGS if LOGS not in names else f"torque_{LOGS}"


def _several_command(given: Sequence[Path], bags: Sequence[Path]) -> str:
    """``'dynid import A B --robot ROBOT [--topic T] --out logs'`` for the paths ``given``
    that hold ``bags``: the ``--topic`` of :func:`_command` when every bag has the same
    JointState topics, else ``--topic TOPIC``."""
    topics = {tuple(joint_state_topics(b) or ()) for b in bags}
    topic, said = _topic(bags[0]) if len(topics) == 1 else (" --topic TOPIC", "")
    paths = " ".join(str(g) for g in given)
    return f"'dynid import {paths} {ROBOT}{topic} --out {_logs_folder(bags)}'{said}"


def _command(bag: Path, stem: str) -> str:
    """``'dynid import BAG --robot ROBOT [--topic T] --out STEM.csv'``, its ``--topic``
    as :func:`_topic` gives it."""
    topic, said = _topic(bag)
    return f"'dynid import {bag} {ROBOT}{topic} --out {stem}.csv'{said}"


def _topic(bag: Path) -> tuple[str, str]:
    """The `` --topic T`` of an import of ``bag`` and what is said after the command:
    ``--topic`` when the bag's one JointState topic is not :data:`DEFAULT_TOPIC`, ``--topic
    TOPIC`` and its JointState topics when it has several; said when it has none. A bag
    that cannot be opened (no ``rosbags``) gets no ``--topic``."""
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
    return topic, said
