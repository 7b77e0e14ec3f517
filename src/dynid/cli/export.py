"""Write a robot with its (identified, feasible) parameters as URDF, MJCF or TOML.

--params takes feasible.json (from `dynid retrieve`), a robot .toml, a .urdf (the chain
from --base to --tip; by default its only root and leaf), 'panda' or 'fr3'. The format
comes from --format or the suffix of --out (.urdf, .xml/.mjcf, .toml).

URDF without a template: the chain with the source robot's link and joint names. With
--urdf-template ORIGINAL.urdf (the robot's own URDF that you supply, such as its maker's:
dynid ships and writes none; --base/--tip for its chain): the original file written
back with only the chain's <inertial> elements and the damping and friction of its joints'
<dynamics> replaced (read back, a vendor's <dynamics> would be the robot's friction;
removed, and said so, when no friction is written); names, meshes, other links and the
gripper are kept. Links fixed to a moving link (a hand): they keep their
inertials and the moving link gets the rest of the identified body (--merged subtract,
default: the body was identified with them); they keep their inertials and the moving link
gets the whole identified body (--merged keep: identified without them, such as a Panda
identified without its hand exported into the vendor's URDF with the hand); or the moving
link gets the whole body and they lose their inertials (--merged move). Links moving on
joints of their own past the tip (a gripper's fingers) were on the arm when it was
recorded, so the identified last body holds them (the reader lumps them into it at their
joints' zero): they keep their inertials, and with subtract and move the moving link gets
the body without them (a note names them; the file's total mass is the identified one);
when the template gives them more inertia than the body holds, they lose their inertials
instead, in a warning. The file opens with a comment of what dynid wrote into it.

MJCF (MuJoCo): bodies, hinge/slide joints with ranges, full inertials, gravity, motors, and
the friction as frictionloss + damping: the linear friction a consistent identification
stored in feasible.json, else the sigmoid approximated (its odd part fitted over the
velocity range); --no-friction for frictionless joints. MuJoCo's frictionloss is a soft
constraint, a ramp of the velocity up to frictionloss: each joint's solreffriction and
solimpfriction set its slope at rest, a smooth law's fc tanh(dq / width) as the closest
ramp (fv and fc written as identified), a sharp law as the steepest. Near a velocity
reversal the constraint's torque in mj_inverse follows the acceleration's sign (for about 2
ms before it): a warning says how far mj_inverse's friction is from the law's along a sine
of each joint (--trajectory: along yours; RMS, and the worst case and where);
--no-frictionloss leaves frictionloss out (damping only), for inverse dynamics that adds
the Coulomb friction itself. A drive (feasible.json's, a robot TOML's [drive] table, or
--drive) adds its rotor inertias as armature and reflects friction at the motors to the
joints; what MJCF cannot hold (a coupled rotor's off-diagonal inertia) is named in a
warning. TOML keeps the drive as a [drive] table and the identified friction as a
[friction] table (exactly, as feasible.json does). URDF holds per joint damping and sharp
Coulomb friction (<dynamics>); MJCF and URDF name in one warning what they cannot hold of
the friction (URDF: a smooth law's rounding; a standstill band, the offsets, a Stribeck
peak, a quadratic term, an asymmetry, friction at the motors, a coupled drive's
off-diagonal terms: its motors' Coulomb friction, which follows the motors' velocities, is
left out up to the N m named at each joint it acts on) and of the drive (MJCF: a coupled
rotor's off-diagonal inertia); URDF names the rotor inertias it drops, by joint, in a
warning of its own.

A feasible.json of a fit that was not accepted ("feasible": false: its held-out error too
far above least squares', or a constraint that does not hold) is refused with the reason
it records; --allow-rejected writes it anyway, with a warning that says why.

examples:
  dynid export --params feasible/feasible.json --out panda.xml
  dynid export --params feasible/feasible.json --out panda.urdf \\
      --urdf-template VENDOR_PANDA.urdf --base panda_link0 --tip panda_hand
"""

from __future__ import annotations

import argparse
from pathlib import Path

from ..exceptions import DynidError
from ..io.export import EXPORT_FORMATS, export_format
from ..io.robot.urdf_patch import MERGED_POLICIES
from ..workflows.export import ExportRobotOptions, export_robot, save_export
from .applies import Applies
from .common import (
    add_drive_option,
    add_snap_angles_option,
    add_subcommand,
    options_from,
    output_path,
)
from .console import Console

NAME = "export"
#: ``--out`` is the one file written (:mod:`dynid.outputs.run_output`).
OUTPUT = "file"


def _urdf_chain_export(args: argparse.Namespace) -> bool:
    """The export writes the chain itself as URDF (no template)."""
    if args.urdf_template is not None:
        return False
    try:
        return export_format(args.out, args.format) == "urdf"
    except DynidError:  # an unknown suffix: said by the export itself
        return True


def _format(args: argparse.Namespace) -> str | None:
    """The export's format, None for an unknown suffix (said by the export itself)."""
    try:
        return export_format(args.out, args.format)
    except DynidError:
        return None


#: Options that apply to one route only (:mod:`dynid.cli.applies`).
APPLIES = (
    Applies(("merged",), lambda a: a.urdf_template is not None, "--urdf-template"),
    Applies(("all_frames",), _urdf_chain_export, "a URDF export without --urdf-template"),
    Applies(("no_frictionloss", "trajectory"), lambda a: _format(a) == "mjcf", "an MJCF export"),
)


def register(subparsers: argparse._SubParsersAction) -> argparse.ArgumentParser:
    """Add the ``export`` subcommand."""
    p = add_subcommand(
        subparsers,
        NAME,
        __doc__,
        help="write a robot as URDF (optionally patching the original), MJCF or TOML",
    )
    p.add_argument(
        "--params",
        required=True,
        help="feasible.json, a robot .toml or .urdf (--base/--tip: its chain), 'panda' or 'fr3'",
    )
    p.add_argument("--format", choices=EXPORT_FORMATS, default=None, help="default: by suffix")
    p.add_argument("--out", type=output_path, required=True, help="output file")
    p.add_argument("--urdf-template", type=Path, default=None, help="the original URDF file")
    p.add_argument(
        "--base", default=None, help="base link of the chain of a URDF --params and the template"
    )
    p.add_argument(
        "--tip",
        default=None,
        help="tip link of the chain of a URDF --params and the template (default: the only "
        "leaf; a URDF with several leaves, such as an arm with a two-finger hand, needs it)",
    )
    add_snap_angles_option(p, "--params")
    p.add_argument(
        "--merged",
        choices=MERGED_POLICIES,
        default="subtract",
        help="template: links fixed to a moving link (a hand) keep their inertials and the "
        "moving link gets the rest of the body (subtract, default) or the whole body (keep: "
        "identified without them), or they give theirs to it (move)",
    )
    p.add_argument(
        "--no-friction",
        action="store_true",
        help="no friction: frictionless MJCF joints; URDF without <dynamics> friction",
    )
    p.add_argument(
        "--no-frictionloss",
        action="store_true",
        help="MJCF: no frictionloss (MuJoCo's dry friction as a constraint, whose "
        "mj_inverse torque near a velocity reversal follows the acceleration): damping "
        "only, the Coulomb friction to be added as a force of the velocity",
    )
    p.add_argument(
        "--trajectory",
        default=None,
        help="MJCF: the trajectory (trajectory.csv or .json of dynid excite) along which "
        "the warning measures mj_inverse's friction against the law's (default: a sine of "
        "each joint, 5 s period, at half its velocity limit)",
    )
    p.add_argument("--all-frames", action="store_true", help="URDF chain: every named frame")
    p.add_argument(
        "--allow-rejected",
        action="store_true",
        help='write a feasible.json whose fit was not accepted ("feasible": false), '
        "with a warning that says why, instead of refusing it",
    )
    add_drive_option(p)
    return p


def run(args: argparse.Namespace, console: Console) -> int:
    """Read, write, print a summary; returns the exit code."""
    options = options_from(
        args,
        ExportRobotOptions,
        friction=not args.no_friction,
        frictionloss=not args.no_frictionloss,
    )
    result = export_robot(args.params, args.out, options)
    path = save_export(args.out, result)
    console.print(f"wrote {path}")
    if result.options.drive is not None:
        console.print(f"drive: {result.options.drive.describe()}")
    approx = result.mujoco_friction
    if approx is not None:
        console.print(
            "friction as MuJoCo holds it (odd part of the sigmoid, fitted up to dq_max; how "
            "far mj_inverse's friction is from the sigmoid: the warning):"
        )
        console.print(
            *(
                f"  {name}: frictionloss {approx.coulomb[j]:.4g} N m, damping "
                f"{approx.viscous[j]:.4g} N m s/rad, dropped offset {approx.offset[j]:+.3g} "
                f"N m, fit RMS {approx.rms_error[j]:.3g} N m"
                for j, name in enumerate(result.robot.joint_names)
            )
        )
    return 0
