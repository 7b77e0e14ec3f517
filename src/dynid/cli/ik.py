"""Inverse kinematics: joint positions that put a frame (or a tool) at a goal pose.

The goal is the pose of the frame (of the tool with --tool) in the base frame, either
  --goal     16 comma-separated numbers, a row-major 4x4 transform [m], or
  --goal-xyz x,y,z [m] with --goal-rpy roll,pitch,yaw [rad] (URDF convention); without
             --goal-rpy the frame keeps its orientation at --q0.
The solver simulates the joint motion of a resolved-rate controller (damped least
squares, joint position and velocity limits, restarts when it stalls; see
dynid.kinematics.ik) from --q0, by default the documented start pose: the Panda's
neutral pose PANDA_NEUTRAL_Q, else the middle of the joint limits. Write a first
negative value as --goal=-0.1,... so that it is not read as an option.

--json prints one object: {"q": [...], "converged": bool, "iterations": k,
"position_error": m, "orientation_error": rad}. The exit status is 1 when the goal was
not reached (the best configuration found is still printed), 2 on bad input.

Example:
  dynid ik --robot panda --tool 0,0,0.1 --goal-xyz 0.4,0.1,0.4 --goal-rpy 3.1416,0,0 --json
"""

from __future__ import annotations

import argparse
from typing import Any

import numpy as np
from numpy.typing import NDArray

from ..exceptions import DynidError
from ..kinematics.inverse import IKOptions, IKResult, default_q0, ik
from ..model.robot import Robot
from ..workflows.kinematics import goal_pose
from .applies import urdf_chain
from .common import (
    add_frame_tool_options,
    add_robot_options,
    add_subcommand,
    count_type,
    format_joint_table,
    format_matrix,
    load_robot,
    parse_q,
    parse_tool,
    parse_vector,
    positive_type,
    seed_type,
)
from .console import Console

NAME = "ik"
#: Options that apply to one route only (:mod:`dynid.cli.applies`).
APPLIES = (urdf_chain(),)


def register(subparsers: argparse._SubParsersAction) -> argparse.ArgumentParser:
    """Add the ``ik`` subcommand."""
    p = add_subcommand(
        subparsers, NAME, __doc__, help="joint positions for a goal pose (inverse kinematics)"
    )
    add_robot_options(p)
    add_frame_tool_options(p)
    p.add_argument(
        "--goal",
        default=None,
        metavar="T11,...,T44",
        help="goal pose: 16 numbers, row-major 4x4 in the base frame [m]",
    )
    p.add_argument("--goal-xyz", default=None, metavar="X,Y,Z", help="goal position [m]")
    p.add_argument(
        "--goal-rpy",
        default=None,
        metavar="R,P,Y",
        help="goal roll, pitch, yaw [rad] (default: the orientation at --q0)",
    )
    p.add_argument(
        "--q0",
        default=None,
        metavar="Q1,...,QN",
        help="start [rad or m] (default: the neutral pose)",
    )
    defaults = IKOptions()
    p.add_argument(
        "--position-tolerance",
        type=positive_type,
        default=defaults.position_tolerance,
        help=f"[m] (default {defaults.position_tolerance:g})",
    )
    p.add_argument(
        "--orientation-tolerance",
        type=positive_type,
        default=defaults.orientation_tolerance,
        help=f"[rad] (default {defaults.orientation_tolerance:g})",
    )
    p.add_argument(
        "--max-iterations",
        type=count_type,
        default=defaults.max_iterations,
        help=f"simulation steps, restarts included (default {defaults.max_iterations})",
    )
    p.add_argument(
        "--seed",
        type=seed_type,
        default=0,
        help="seed of the restart configurations (default 0)",
    )
    p.add_argument("--json", action="store_true", help="print one JSON object")
    return p


def _goal(
    args: argparse.Namespace, robot: Robot, q0: np.ndarray, tool: np.ndarray | None
) -> np.ndarray:
    """``T_base_goal`` (4, 4) from ``--goal`` or ``--goal-xyz``/``--goal-rpy``
    (:func:`dynid.workflows.kinematics.goal_pose`)."""
    if (args.goal is None) == (args.goal_xyz is None):
        raise DynidError("give the goal as either --goal (16 numbers) or --goal-xyz [--goal-rpy]")
    if args.goal is not None:
        if args.goal_rpy is not None:
            raise DynidError("--goal-rpy goes with --goal-xyz, not with --goal")
        return parse_vector(args.goal, "--goal", 16).reshape(4, 4)
    xyz = parse_vector(args.goal_xyz, "--goal-xyz", 3)
    rpy = None if args.goal_rpy is None else parse_vector(args.goal_rpy, "--goal-rpy", 3)
    return goal_pose(robot, q0, xyz, rpy, frame=args.frame, tool=tool)


def run(args: argparse.Namespace, console: Console) -> int:
    """Solve and print (table or JSON); exit status 1 when not converged."""
    robot = load_robot(args, parameters=False)
    tool = parse_tool(args.tool)
    q0 = default_q0(robot) if args.q0 is None else parse_q(args.q0, robot, "--q0")
    T_goal = _goal(args, robot, q0, tool)
    options = IKOptions(
        position_tolerance=args.position_tolerance,
        orientation_tolerance=args.orientation_tolerance,
        max_iterations=args.max_iterations,
    )
    res = ik(robot, T_goal, q0, args.frame, tool, options, rng=np.random.default_rng(args.seed))
    if args.json:
        console.json(_summary(res))
    else:
        print_ik(console, args, robot, T_goal, res)
    return 0 if res.converged else 1


def _summary(res: IKResult) -> dict[str, Any]:
    """What ``--json`` prints: the configuration, convergence and the errors."""
    return {
        "q": res.q,
        "converged": res.converged,
        "iterations": res.iterations,
        "position_error": res.position_error,
        "orientation_error": res.orientation_error,
    }


def print_ik(
    console: Console,
    args: argparse.Namespace,
    robot: Robot,
    T_goal: NDArray[np.float64],
    res: IKResult,
) -> None:
    """The goal pose, convergence, the position and orientation errors and the joint table."""
    what = f"tool on frame {args.frame!r}" if args.tool else f"frame {args.frame!r}"
    console.print(f"{robot.name}: inverse kinematics of the {what}")
    console.print(
        f"goal T_base_{'tool' if args.tool else args.frame} [m]:\n{format_matrix(T_goal)}"
    )
    status = "converged" if res.converged else "NOT converged (best configuration found)"
    console.print(f"{status} after {res.iterations} iterations, {res.restarts} restarts")
    console.print(f"position error:    {res.position_error:.3e} m")
    console.print(f"orientation error: {res.orientation_error:.3e} rad")
    console.print(f"q:\n{format_joint_table(robot, res.q)}")
