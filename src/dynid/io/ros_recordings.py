"""A recording of a ``sensor_msgs/JointState`` topic, by its name: a ROS 1 ``.bag``, a
ROS 2 bag folder (:mod:`dynid.io.rosbag`) or a CSV export of the topic
(:mod:`dynid.io.joint_state_csv`), read into a torque log with joints matched by name."""

from __future__ import annotations

from collections.abc import Sequence
from pathlib import Path

from ..identification.log import DEFAULT_CUTOFF_HZ
from .joint_state_csv import load_joint_state_csv
from .joint_states import JointStateImport
from .rosbag import load_joint_state_bag

__all__ = ["load_joint_state_recording"]


def load_joint_state_recording(
    path: str | Path,
    robot_joints: Sequence[str],
    *,
    topic: str = "/joint_states",
    joints: Sequence[str] | None = None,
    velocity_cutoff_hz: float = DEFAULT_CUTOFF_HZ,
    gap_factor: float = 1.5,
) -> JointStateImport:
    """:func:`~dynid.io.joint_state_csv.load_joint_state_csv` for a ``.csv`` file, else
    :func:`~dynid.io.rosbag.load_joint_state_bag`; same parameters, result and errors."""
    load = load_joint_state_csv if Path(path).suffix.lower() == ".csv" else load_joint_state_bag
    return load(
        path,
        robot_joints,
        topic=topic,
        joints=joints,
        velocity_cutoff_hz=velocity_cutoff_hz,
        gap_factor=gap_factor,
    )
