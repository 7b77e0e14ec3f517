"""Write a robot with its (identified, feasible) parameters as URDF, MJCF or TOML.

--params takes feasible.json (from `dynid retrieve`), a robot .toml, 'panda' or 'fr3'. The
format comes from --format or the suffix of --out (.urdf, .xml/.mjcf, .toml).

URDF without a template: the chain with the source robot's link and joint names. With
--urdf-template ORIGINAL.urdf (and --base/--tip for its chain): the original file written
back with only the chain's <inertial> elements replaced; names, meshes, other links, the
gripper and <dynamics> are kept. Links fixed to a moving link (a hand): they keep their
inertials and the moving link gets the rest of the identified body (--merged subtract,
default: the body was identified with them); they keep their inertials and the moving link
gets the whole identified body (--merged keep: identified without them, such as a Panda
identified without its hand exported into the vendor's URDF with the hand); or the moving
link gets the whole body and they lose their inertials (--merged move).

MJCF (MuJoCo): bodies, hinge/slide joints with ranges, full inertials, gravity, motors, and
the friction as frictionloss + damping: the linear friction a consistent identification
stored in feasible.json, else the sigmoid approximated (its odd part fitted over the
velocity range); --no-friction for frictionless joints. A drive (feasible.json's, a robot
TOML's [drive] table, or --drive) adds its rotor inertias as armature and reflects friction
at the motors to the joints; what MJCF cannot hold (a coupled rotor's off-diagonal inertia)
is named in a warning. TOML keeps the drive as a [drive] table.

examples:
  dynid export --params feasible/feasible.json --out panda.xml
  dynid export --params feasible/feasible.json --out panda.urdf \\
      --urdf-template panda_original.urdf --base panda_link0 --tip panda_hand
"""

from __future__ import annotations

import argparse
from pathlib import Path
from typing import Any

from ..exceptions import DynidError
from ..friction.mujoco import coulomb_viscous_from_sigmoid
from ..io.export import EXPORT_FORMATS, export_format, model_terms_of, save_robot
from ..io.robot.urdf_patch import MERGED_POLICIES
from ..model.robot import Robot
from .common import add_drive_option, add_subcommand, load_drive_arg, output_path
from .console import Console

NAME = "export"
#: ``--out`` is the one file written (:mod:`dynid.io.run_output`).
OUTPUT = "file"


def register(subparsers: argparse._SubParsersAction) -> argparse.ArgumentParser:
    """Add the ``export`` subcommand."""
    p = add_subcommand(
        subparsers,
        NAME,
        __doc__,
        help="write a robot as URDF (optionally patching the original), MJCF or TOML",
    )
    p.add_argument("--params", required=True, help="feasible.json, a robot .toml, 'panda' or 'fr3'")
    p.add_argument("--format", choices=EXPORT_FORMATS, default=None, help="default: by suffix")
    p.add_argument("--out", type=output_path, required=True, help="output file")
    p.add_argument("--urdf-template", type=Path, default=None, help="the original URDF file")
    p.add_argument("--base", default=None, help="base link of the template's chain")
    p.add_argument("--tip", default=None, help="tip link of the template's chain")
    p.add_argument(
        "--merged",
        choices=MERGED_POLICIES,
        default="subtract",
        help="template: links fixed to a moving link (a hand) keep their inertials and the "
        "moving link gets the rest of the body (subtract, default) or the whole body (keep: "
        "identified without them), or they give theirs to it (move)",
    )
    p.add_argument("--no-friction", action="store_true", help="MJCF: frictionless joints")
    p.add_argument("--all-frames", action="store_true", help="URDF chain: every named frame")
    add_drive_option(p)
    return p


def load_params(spec: str) -> Robot:
    """The robot of ``--params``: feasible.json, a robot .toml, ``panda`` or ``fr3``."""
    from ..io.robot_file import load_robot

    if Path(spec).suffix.lower() == ".urdf":
        raise DynidError(
            f"--params must be feasible.json, a robot .toml, 'panda' or 'fr3'; got {spec!r}"
        )
    return load_robot(spec, what="--params")


def run(args: argparse.Namespace, console: Console) -> int:
    """Load, write, print a summary; returns the exit code."""
    robot = load_params(args.params)
    if args.urdf_template is None and (args.base or args.tip):
        raise DynidError("--base/--tip choose the chain of --urdf-template; give the template")
    linear, drive = model_terms_of(args.params, robot.n)
    if args.drive is not None:
        drive = load_drive_arg(args, robot.n)
    friction: Any = False if args.no_friction else True
    if linear is not None and not args.no_friction:
        friction = linear
        if drive is not None and drive.friction_at == "motor" and linear.drive is None:
            friction = linear.at(drive)
    path = save_robot(
        args.out,
        robot,
        format=args.format,
        template=args.urdf_template,
        base=args.base,
        tip=args.tip,
        merged=args.merged,
        friction=friction,
        all_frames=args.all_frames,
        drive=drive,
    )
    console.print(f"wrote {path}")
    if drive is not None:
        console.print(f"drive: {drive.describe()}")
    mjcf = export_format(path, args.format) == "mjcf"
    if mjcf and friction is True and robot.friction is not None:
        approx = coulomb_viscous_from_sigmoid(robot.friction, robot.dq_max)
        console.print("friction as MuJoCo holds it (odd part of the sigmoid, fitted up to dq_max):")
        for j, name in enumerate(robot.joint_names):
            console.print(
                f"  {name}: frictionloss {approx.coulomb[j]:.4g} N m, damping "
                f"{approx.viscous[j]:.4g} N m s/rad, dropped offset {approx.offset[j]:+.3g} "
                f"N m, fit RMS {approx.rms_error[j]:.3g} N m"
            )
    return 0
