"""Import sensor_msgs/JointState from a ROS bag or a CSV export into a torque log.

RECORDING is a ROS 1 .bag file or a ROS 2 bag folder (sqlite3 or MCAP; reading needs the
optional package rosbags: pip install 'dynid[ros]'), or a .csv export of the JointState
topic: `rostopic echo -p /joint_states > log.csv` (ROS 1), or a PlotJuggler CSV export
(its columns <topic>/<joint>/position, velocity, effort; --topic picks the topic, rows of
other topics are skipped). Joints are matched by name to the robot's, whatever order the
messages list them in: equal names, or one name preceded by a prefix ending in '_'
(panda_joint1 matches joint1; of several, the prefix matching the most robot joints, so
panda_finger_joint1 is not taken for joint1); recorded joints matching none (a
gripper's) are left out, said in a note; otherwise give --joints with the recorded names
in the robot's joint order. Times are header stamps (receive times when stamps are unset,
said so), in seconds from the first message, read to the nanosecond. Messages on other
topics, missing joints or fields, NaN, out-of-order and repeated stamps are handled and
counted. Without velocities in the recording the log holds positions and torques only
(said so): every command derives the velocities from the positions at its own cut-off,
and none takes them for measured ones. A JointState's effort is whatever its driver puts
there: with a --drive whose effort is "current" the log's units line gives the tau columns
as motor currents (tau [A]), which identify and validate then read through that drive;
without one, as joint torques (tau [N m]). --model identification.json takes the robot
and drive of an identified model instead of --robot and --drive.

Writes the torque log (--out .csv or .npz) that identify, friction and validate read.
Several recordings, or a folder holding bags (ROS 2 bag folders, ROS 1 .bag files), are
imported in one run: --out is then a folder, holding one torque log per recording named
for it (train1/ -> train1.csv), which --data takes as it is (several recordings are given
to identify as a folder or as several files).

A URDF chain cut before a recorded joint (--tip before a gripper's jointGripper) holds
that joint's links at rest past the tip; where the recording shows the joint moving, or
resting away from 0, a note gives its recorded range and the --tip that keeps it.

examples:
  dynid import recording/ --out log.csv --robot panda --topic /joint_states
  dynid import train1/ train2/ --out logs --robot arm.urdf   (logs/train1.csv, train2.csv)
  dynid import bags/ --out logs --robot arm.urdf              (every bag bags/ holds)
  dynid import joint_states.csv --out log.csv --robot arm.urdf   (rostopic echo -p)
  dynid import recording/ --out log.csv --model id/identification.json
"""

from __future__ import annotations

import argparse
from collections.abc import Sequence
from pathlib import Path
from typing import Any

from ..exceptions import OptionError
from ..io.joint_states import JointStateImport
from ..io.model_json import load_model_json
from ..io.robot.urdf_parse import joints_past_tip
from ..io.ros_recordings import load_joint_state_recording, recording_paths
from ..io.rosbag import held_bags
from ..io.torque_log import save_torque_log
from .applies import Applies, urdf_chain
from .common import (
    add_drive_option,
    add_robot_options,
    add_subcommand,
    cli_text,
    load_drive_arg,
    load_robot,
    output_path,
)
from .console import Console

NAME = "import"


def _output(args: argparse.Namespace) -> str:
    """What ``--out`` names (:mod:`dynid.outputs.run_output`): the one file written, or
    the folder of one log per recording of several (or of a folder holding bags)."""
    several = len(args.bag) > 1 or bool(held_bags(args.bag[0]))
    return "folder" if several else "file"


#: ``--out`` as :func:`_output` decides (the command line asks it before the run).
OUTPUT = _output
#: A folder of torque logs gets no report page (``--data`` reads the folder as it is).
REPORT = False
#: Options that apply to one route only (:mod:`dynid.cli.applies`).
APPLIES = (
    urdf_chain(),
    Applies(
        ("robot", "drive"),
        lambda a: a.model is None,
        "a run without --model",
        "--model carries the identified robot and drive",
    ),
)


def register(subparsers: argparse._SubParsersAction) -> argparse.ArgumentParser:
    """Add the ``import`` subcommand."""
    p = add_subcommand(
        subparsers,
        NAME,
        __doc__,
        help="torque log from sensor_msgs/JointState in a ROS bag or a CSV export",
    )
    p.add_argument(
        "bag",
        type=Path,
        nargs="+",
        metavar="RECORDING",
        help="ROS 1 .bag file, ROS 2 bag folder, or .csv export (rostopic echo -p, "
        "PlotJuggler); several, or a folder holding bags: one torque log each",
    )
    p.add_argument(
        "--out",
        type=output_path,
        required=True,
        help="torque log to write (.csv or .npz); of several recordings, the folder of "
        "their logs (one NAME.csv per recording)",
    )
    p.add_argument(
        "--topic",
        default="/joint_states",
        help="JointState topic (of a bag or a PlotJuggler export; default /joint_states)",
    )
    add_robot_options(p)
    add_drive_option(p)
    p.add_argument(
        "--model",
        type=Path,
        default=None,
        help="identification.json of an identified model: its robot and drive, instead of "
        "--robot and --drive",
    )
    p.add_argument(
        "--joints",
        default=None,
        help="the recording's joint names in the robot's order, comma-separated",
    )
    p.add_argument(
        "--json",
        action="store_true",
        help='print the import summary as JSON (of several recordings: {"recordings": [...]})',
    )
    return p


def run(args: argparse.Namespace, console: Console) -> int:
    """Read the recordings, write their logs, print what was found; returns the exit code."""
    if args.model is not None:
        model = load_model_json(args.model)
        robot, drive = model.robot, model.drive
    else:
        robot = load_robot(args)
        drive = None
    joints = None if args.joints is None else [s.strip() for s in args.joints.split(",")]
    several = _output(args) == "folder"
    recordings = recording_paths(args.bag)
    if several and args.out.suffix.lower() in (".csv", ".npz"):
        raise OptionError(
            f"--out {args.out}: several recordings, or a folder of bags, write one torque log "
            "each into a folder; give a folder (--out logs)"
        )
    past_tip = {}
    if args.model is None and Path(args.robot).suffix.lower() == ".urdf":
        past_tip = joints_past_tip(args.robot, args.base, args.tip)
    if args.model is None:
        drive = load_drive_arg(args, robot.n)
    unit = "N m" if drive is None else drive.effort_unit
    summaries = []
    for bag, name in recordings.items():
        res = load_joint_state_recording(
            bag, robot.joint_names, topic=args.topic, joints=joints, past_tip=past_tip
        )
        path = save_torque_log(args.out / name if several else args.out, res.log, tau_unit=unit)
        summaries.append(_summary(bag, res, robot.joint_names, path, unit))
        if not args.json:
            if several:
                console.print(f"{bag}:")
            print_import(console, res, robot.joint_names, path, unit)
    if args.json:
        console.json({"recordings": summaries} if several else summaries[0])
    return 0


def _summary(
    bag: Path, res: JointStateImport, names: Sequence[str], path: Path, tau_unit: str
) -> dict[str, Any]:
    """What ``--json`` prints: the bag, the topic, the log written (its ``tau`` columns'
    unit) and what the reading found."""
    return {
        "bag": str(bag.name),
        "topic": res.topic,
        "out": str(path),
        "tau_unit": tau_unit,
        "samples": res.log.n_samples,
        "duration_s": res.log.duration,
        "sample_rate_hz": res.log.sample_rate,
        "joints": dict(zip(names, res.joints, strict=True)),
        "time_source": res.time_source,
        "t0_ns": res.t0_ns,
        "messages": res.n_messages,
        "other_topics": res.n_other_topics,
        "missing": res.n_missing,
        "nonfinite": res.n_nonfinite,
        "out_of_order": res.n_out_of_order,
        "duplicate_stamps": res.n_duplicate_stamps,
        "velocity_derived": res.velocity_derived,
        "velocities_written": not res.velocity_derived,
        "notes": list(res.notes),
    }


def print_import(
    console: Console,
    res: JointStateImport,
    names: Sequence[str],
    path: Path,
    tau_unit: str = "N m",
) -> None:
    """Samples, duration and rate, the time source, the joint map, the notes, the file
    (with its torques' unit when they are motor currents)."""
    console.print(
        f"{res.log.n_samples} samples, {res.log.duration:.3f} s at "
        f"{res.log.sample_rate:.1f} Hz from {res.n_messages} messages on {res.topic}; "
        f"time from {res.time_source} stamps, t = 0 at {res.t0_ns} ns"
        + (
            "; positions and torques only: the bag has no velocities (every command derives "
            "them from the positions at its own cut-off)"
            if res.velocity_derived
            else ""
        )
    )
    for rj, bj in zip(names, res.joints, strict=True):
        console.print(f"  {rj} <- {bj}")
    for note in res.notes:
        console.print(f"note: {cli_text(note)}")  # an option named by its flag
    currents = " (tau in A: motor currents, as the drive's effort is current)"
    console.print(f"wrote {path}" + (currents if tau_unit == "A" else ""))
