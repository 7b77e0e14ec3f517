"""A recording of a ``sensor_msgs/JointState`` topic, by its name: a ROS 1 ``.bag``, a
ROS 2 bag folder (:mod:`dynid.io.rosbag`) or a CSV export of the topic
(:mod:`dynid.io.joint_state_csv`), read into a torque log with joints matched by name;
:func:`recording_paths`: the recordings of several paths, a folder of bags standing for
the bags it holds, each with the name of its torque log."""

from __future__ import annotations

from collections.abc import Mapping, Sequence
from pathlib import Path

from .. import _checks
from ..exceptions import DataError
from ..identification.log import DEFAULT_CUTOFF_HZ
from .joint_state_csv import load_joint_state_csv
from .joint_states import JointStateImport
from .rosbag import held_bags, load_joint_state_bag

__all__ = ["load_joint_state_recording", "recording_paths"]


def recording_paths(paths: str | Path | Sequence[str | Path]) -> dict[Path, str]:
    """The recordings ``paths`` name, each with the file name of its torque log
    (``train1.csv`` for the bag ``train1/`` or ``train1.bag``): each path given, a folder
    that is no bag but holds bags (:func:`~dynid.io.rosbag.held_bags`) standing for them.

    Raises
    ------
    WrongTypeError
        Neither a path nor a list or tuple of paths.
    DataError
        No path, a recording named twice (however written), or two recordings whose
        torque logs would share a name (``a/train1.bag`` and ``b/train1``).
    """
    given = _checks.one_or_many("paths", paths, (str, Path), "a path or a list of paths")
    found = [b for p in map(Path, given) for b in (held_bags(p) or [p])]
    if not found:
        raise DataError("no recording given")
    out: dict[Path, str] = {}
    for p in found:
        name = f"{Path(p.name).stem or p.name}.csv"
        if (twice := next((q for q in out if q.resolve() == p.resolve()), None)) is not None:
            raise DataError(f"{p.name}: recording given twice ({twice} and {p})")
        if (other := next((q for q, n in out.items() if n == name), None)) is not None:
            raise DataError(
                f"{p.name}: its torque log {name} would replace that of {other}; hint: import "
                "recordings of one name separately"
            )
        out[p] = name
    return out


def load_joint_state_recording(
    path: str | Path,
    robot_joints: Sequence[str],
    *,
    topic: str = "/joint_states",
    joints: Sequence[str] | None = None,
    velocity_cutoff_hz: float = DEFAULT_CUTOFF_HZ,
    gap_factor: float = 1.5,
    past_tip: Mapping[str, tuple[str | None, str]] | None = None,
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
        past_tip=past_tip,
    )
