"""Identify a load (tool, gripper) on the arm: mass, CoM and inertia, with uncertainty.

The arm's model is known: --robot (built-in or a description with its parameters),
--model identification.json (identified) or --params feasible.json (feasible). --data is
recorded with the load: static data (q, M, g; --gravity-only uses g alone and gives the
mass and CoM only) or a torque log (classical friction is estimated alongside). With
--unloaded DATA0 (the same kind of data without the load) the arm is identified from DATA0
first (difference method). The estimate is physically consistent (pseudo-inertia LMI).
--columns/--units read files of other tools.

Writes DIR/payload.json (mass, com [m] in --frame, inertia about the CoM, their std, and
libfranka's setLoad values load_mass, F_x_Cload, load_inertia) and
DIR/robot_with_payload.toml (the robot carrying the load).

example:
  dynid payload --robot panda --data static_with_gripper.csv --out payload
"""

from __future__ import annotations

import argparse
from pathlib import Path
from typing import Any

from ..exceptions import DynidError
from ..feasibility.payload import identify_payload, robot_with_payload
from ..identification.log import DEFAULT_CUTOFF_HZ
from ..identification.model import IdentifiedModel
from ..io.payload_json import save_payload_json
from ..io.robot.toml import save_toml
from ..model.inertia import INERTIA_ORDER, inertia6_from_matrix
from ..model.robot import Robot
from ..workflows.data_files import column_map, data_kind, read_static_file, read_torque_log
from .common import add_column_options, add_drop_invalid, add_subcommand, output_path, positive_type
from .console import Console
from .sources import load_model_source

NAME = "payload"
#: ``--out`` is a folder: its files are one output set (:mod:`dynid.io.run_output`).
OUTPUT = "folder"


def register(subparsers: argparse._SubParsersAction) -> argparse.ArgumentParser:
    """Add the ``payload`` subcommand."""
    p = add_subcommand(
        subparsers, NAME, __doc__, help="identify a load's mass, CoM and inertia on a known arm"
    )
    src = p.add_mutually_exclusive_group(required=True)
    src.add_argument("--robot", help="'panda', 'fr3', a .urdf or a .toml with the arm's parameters")
    src.add_argument("--model", type=Path, help="identification.json of the arm")
    src.add_argument("--params", type=Path, help="feasible.json of the arm")
    p.add_argument("--base", default=None, help="URDF base link (with --robot)")
    p.add_argument("--tip", default=None, help="URDF tip link (with --robot)")
    p.add_argument("--data", type=Path, required=True, help="data with the load (.csv/.npz)")
    p.add_argument("--unloaded", type=Path, default=None, help="the same data without the load")
    add_column_options(p)
    p.add_argument("--frame", default="flange", help="frame the load is fixed to")
    p.add_argument("--gravity-only", action="store_true", help="static data: use g alone")
    p.add_argument(
        "--cutoff",
        type=positive_type,
        default=None,
        help=f"torque logs: low-pass [Hz] (default {DEFAULT_CUTOFF_HZ:g}; static data are not "
        "filtered)",
    )
    add_drop_invalid(p)
    p.add_argument("--out", type=output_path, required=True, help="output folder")
    return p


def _read(args: argparse.Namespace, path: Path, robot: Robot, kind: str, cmap: Any) -> Any:
    drop = args.drop_invalid
    if kind == "torque_log":
        owner = f"robot {robot.name!r}"
        return read_torque_log(path, robot.n, columns=cmap, drop_invalid=drop, owner=owner)
    return read_static_file(
        path, robot, columns=cmap, drop_invalid=drop, require_M=not args.gravity_only
    )


def run(args: argparse.Namespace, console: Console) -> int:
    """Identify, write payload.json and the robot with the load, print a summary."""
    arm, label = load_model_source(args)
    kin = arm.robot if isinstance(arm, IdentifiedModel) else arm
    cutoff = DEFAULT_CUTOFF_HZ if args.cutoff is None else args.cutoff
    cmap = column_map(args.columns, args.units, cutoff_hz=cutoff)
    kind = data_kind(args.data, cmap)
    if args.gravity_only and kind != "static":
        raise DynidError("--gravity-only applies to static data (q, g), not to a torque log")
    if args.cutoff is not None and kind == "static":
        raise DynidError(
            "--cutoff applies to torque logs (their low-pass); static data are not filtered"
        )
    data = _read(args, args.data, kin, kind, cmap)
    unloaded = None if args.unloaded is None else _read(args, args.unloaded, kin, kind, cmap)
    est = identify_payload(
        arm,
        data,
        frame=args.frame,
        gravity_only=args.gravity_only,
        unloaded=unloaded,
        cutoff_hz=cutoff if kind == "torque_log" else None,
    )
    base = arm.equivalent_robot if isinstance(arm, IdentifiedModel) else arm
    tool = robot_with_payload(base, est)
    save_toml(args.out / "robot_with_payload.toml", tool)
    path = save_payload_json(
        args.out / "payload.json", est, kin, with_tool="robot_with_payload.toml"
    )
    console.print(f"payload on frame {est.frame!r} ({est.route}; arm: {label})")
    console.print(f"  mass     {est.mass:.6g} kg  (std {est.std_mass:.2g})")
    com = ", ".join(f"{x:+.5f}" for x in est.com)
    std = ", ".join(f"{x:.2g}" for x in est.std_com)
    console.print(f"  com      [{com}] m  (std [{std}])")
    if est.inertia_identified:
        for name, v, s in zip(
            INERTIA_ORDER, inertia6_from_matrix(est.inertia), est.std_inertia, strict=True
        ):
            console.print(f"  I{name}      {v:+.4e} kg m^2  (std {s:.2g})")
    for note in est.notes:
        console.print(f"note: {note}")
    console.print(f"wrote {path} and {args.out / 'robot_with_payload.toml'}")
    return 0
