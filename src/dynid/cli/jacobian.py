"""Geometric Jacobian of a frame (or of a tool fixed to it), expressed in the base frame.

Rows vx, vy, vz [m/rad] (linear velocity of the frame's origin) and wx, wy, wz [rad/rad]
(angular velocity), one column per joint: [v; w] = J(q) dq. --q defaults to the
documented start pose (the Panda's neutral pose PANDA_NEUTRAL_Q, else the middle of the
joint limits). Write a first negative value as --q=-0.1,... so that it is not read as an
option.

--json prints one object: {"J": [[...] x 6], "rows": ["vx","vy","vz","wx","wy","wz"]}.

Example:
  dynid jacobian --robot panda --frame flange --tool 0,0,0.1 --json
"""

from __future__ import annotations

import argparse

from ..kinematics.jacobian import jacobian
from .applies import urdf_chain
from .common import (
    add_frame_tool_options,
    add_q_option,
    add_robot_options,
    add_subcommand,
    format_joint_table,
    joint_positions,
    load_robot,
    parse_tool,
)
from .console import Console

NAME = "jacobian"
#: Options that apply to one route only (:mod:`dynid.cli.applies`).
APPLIES = (urdf_chain(),)

#: Row labels of the geometric Jacobian (linear, then angular velocity; base frame).
ROWS = ("vx", "vy", "vz", "wx", "wy", "wz")


def register(subparsers: argparse._SubParsersAction) -> argparse.ArgumentParser:
    """Add the ``jacobian`` subcommand."""
    p = add_subcommand(
        subparsers, NAME, __doc__, help="geometric Jacobian of a frame or tool (base frame)"
    )
    add_robot_options(p)
    add_q_option(p)
    add_frame_tool_options(p)
    p.add_argument("--json", action="store_true", help="print one JSON object")
    return p


def run(args: argparse.Namespace, console: Console) -> int:
    """Print the Jacobian (table or JSON)."""
    robot = load_robot(args, parameters=False)
    q = joint_positions(args, robot)
    J = jacobian(robot, q, args.frame, parse_tool(args.tool))
    if args.json:
        console.json({"J": J, "rows": list(ROWS)})
        return 0
    what = f"tool on frame {args.frame!r}" if args.tool else f"frame {args.frame!r}"
    console.print(f"{robot.name}: geometric Jacobian of the {what}, base frame")
    console.print(f"q:\n{format_joint_table(robot, q)}")
    width = max(10, *(len(s) + 1 for s in robot.joint_names))
    console.print("    " + "".join(f"{s:>{width}}" for s in robot.joint_names))
    for label, row in zip(ROWS, J, strict=True):
        console.print(f"{label:<4}" + "".join(f"{v:>+{width}.6f}" for v in row))
    return 0
