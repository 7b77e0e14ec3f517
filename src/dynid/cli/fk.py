"""Forward kinematics: the pose of a frame (or of a tool fixed to it) in the base frame.

Prints T_base_frame (4x4, translation in m), its position [m] and its URDF roll, pitch,
yaw [rad]. --q defaults to the documented start pose (the Panda's neutral pose
PANDA_NEUTRAL_Q, else the middle of the joint limits). Write a first negative value as
--q=-0.1,... so that it is not read as an option.

--json prints one object: {"T": [[...], [...], [...], [...]]} (row-major, base frame, m).

Example:
  dynid fk --robot panda --q=0,-0.785,0,-2.356,0,1.571,0.785 --tool 0,0,0.1 --json
"""

from __future__ import annotations

import argparse

from ..kinematics.forward import fk
from ..spatial import rpy_from_matrix
from .applies import urdf_chain
from .common import (
    add_frame_tool_options,
    add_q_option,
    add_robot_options,
    add_subcommand,
    format_joint_table,
    format_matrix,
    joint_positions,
    load_robot,
    parse_tool,
)
from .console import Console

NAME = "fk"
#: Options that apply to one route only (:mod:`dynid.cli.applies`).
APPLIES = (urdf_chain(),)


def register(subparsers: argparse._SubParsersAction) -> argparse.ArgumentParser:
    """Add the ``fk`` subcommand."""
    p = add_subcommand(subparsers, NAME, __doc__, help="pose of a frame or tool in the base frame")
    add_robot_options(p)
    add_q_option(p)
    add_frame_tool_options(p)
    p.add_argument("--json", action="store_true", help="print one JSON object")
    return p


def run(args: argparse.Namespace, console: Console) -> int:
    """Print the pose (table or JSON)."""
    robot = load_robot(args, parameters=False)
    q = joint_positions(args, robot)
    T = fk(robot, q, args.frame, parse_tool(args.tool))
    if args.json:
        console.json({"T": T})
        return 0
    what = f"tool on frame {args.frame!r}" if args.tool else f"frame {args.frame!r}"
    console.print(f"{robot.name}: pose of the {what} in the base frame")
    console.print(f"q:\n{format_joint_table(robot, q)}")
    console.print(f"T_base_{'tool' if args.tool else args.frame} [m]:\n{format_matrix(T)}")
    console.print(f"position x, y, z [m]:        {format_matrix(T[:3, 3])}")
    console.print(f"URDF roll, pitch, yaw [rad]: {format_matrix(rpy_from_matrix(T[:3, :3]))}")
    return 0
