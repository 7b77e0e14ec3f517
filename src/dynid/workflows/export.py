"""Export a robot's parameters: the entry point of ``dynid export``, with every policy the
command applies, so that the Python API behaves as the command does.

* The robot: a ``feasible.json``, a robot ``.toml``, a ``.urdf`` (the chain from ``base``
  to ``tip``; default the file's only root and leaf) or a built-in name.
* ``base``/``tip`` choose the chain of a URDF robot and of the URDF template; given with
  neither they would do nothing, and are refused.
* The friction written: the linear friction identified with the links (a
  ``feasible.json``'s; reflected from the motors when its drive has friction there), else
  the robot's own; none on request. The drive: the file's own, or the one given.
* A ``feasible.json`` of a fit that was not accepted (``"feasible": false``: its held-out
  error too far above least squares', or a constraint that does not hold) is refused,
  naming the reason the file records, unless ``allow_rejected``; written then, it is said
  in a warning (:func:`~dynid.io.feasible.load_feasible_json`) and in a comment at the
  top of the file (:func:`~dynid.io.feasible.rejection_caveat`).
* MJCF holds friction as ``frictionloss`` and ``damping``: the robot's sigmoid is
  approximated and the fit is part of the result
  (:func:`~dynid.friction.mujoco.coulomb_viscous_from_sigmoid`); ``frictionloss`` is
  MuJoCo's soft dry friction, its slope at rest set per joint
  (:mod:`dynid.friction.mujoco_soft`); how far ``mj_inverse``'s friction is from the
  law's near velocity reversals is said in a warning, and ``frictionloss=False`` leaves
  it out.
* Rotor inertias a ``feasible.json``'s identified structure left out while it kept
  others (``armature_left_out``: the data did not determine them) are written as 0: one
  note names their joints, and the file says so at its top
  (:func:`~dynid.io.feasible.armature_left_out_note`).
"""

from __future__ import annotations

import json
import logging
from dataclasses import dataclass
from pathlib import Path
from typing import Any

from ..exceptions import OptionError
from ..friction.model import Friction, sigmoid_parameters
from ..friction.mujoco import CoulombViscous, coulomb_viscous_from_sigmoid
from ..friction.mujoco_soft import MOTION_STEP_S
from ..io.drive_file import load_drive
from ..io.excitation import load_trajectory
from ..io.export import EXPORT_FORMATS, ROBOT_FORMATS, export_format, model_terms_of
from ..io.feasible import (
    armature_left_out_note,
    load_armature_left_out,
    load_fit_rejection,
    load_unknown_scale_caveat,
    rejection_caveat,
)
from ..io.robot.export_options import Along, ExportOptions
from ..io.robot.urdf_patch import MERGED_POLICIES
from ..io.robot_file import ROBOT_FILE_SUFFIXES, load_robot
from ..model.builtin import BUILTIN_ROBOTS
from ..model.drive import Drive
from ..model.robot import Robot
from ..progress import NOTE
from .options import check_choice

__all__ = ["ExportRobotOptions", "RobotExport", "export_robot"]

_log = logging.getLogger(__name__)


@dataclass(frozen=True, slots=True)
class ExportRobotOptions:
    """How :func:`export_robot` exports a robot.

    Attributes
    ----------
    format : {"urdf", "mjcf", "toml"}, optional
        Default: from the output's suffix.
    urdf_template : str or Path, optional
        URDF: the original file, written back with only the chain's inertials replaced.
    base, tip : str, optional
        The chain's base and tip links in a URDF robot and in the template (default: the
        file's only root and leaf).
    snap_angles : bool
        Read a URDF robot's joint angles rounded near multiples of pi/2 as those multiples.
    merged : {"subtract", "keep", "move"}
        Template: how a body is split over its moving link and the links fixed to it.
    friction : bool
        Write friction (the identified linear friction, else the robot's own).
    all_frames : bool
        URDF chain: every named frame as a fixed, massless link.
    drive : Drive, str or Path, optional
        The drive train (or its ``.toml`` file), in place of the robot file's own.
    allow_rejected : bool
        Write a ``feasible.json`` whose fit was not accepted (``"feasible": false``),
        with a warning that says why, instead of refusing it.
    frictionloss : bool
        MJCF: the Coulomb friction as ``frictionloss``, MuJoCo's dry friction as a
        constraint (whose ``mj_inverse`` torque near a velocity reversal follows the
        acceleration, said in a warning); False: left out, ``damping`` only.
    trajectory : str or Path, optional
        MJCF: the trajectory (``trajectory.csv`` or ``.json`` of ``dynid excite``; a JSON
        sampled at 10 kHz) the warning measures ``mj_inverse``'s friction along, against
        the law's; default: a sine of each joint
        (:func:`~dynid.friction.mujoco_soft.representative_motion`).

    Raises
    ------
    OptionError
        An unknown format or merge policy (``field`` names it).
    """

    format: str | None = None
    urdf_template: str | Path | None = None
    base: str | None = None
    tip: str | None = None
    snap_angles: bool = False
    merged: str = "subtract"
    friction: bool = True
    all_frames: bool = False
    drive: Drive | str | Path | None = None
    allow_rejected: bool = False
    frictionloss: bool = True
    trajectory: str | Path | None = None

    def __post_init__(self) -> None:
        check_choice(self, "format", EXPORT_FORMATS)
        check_choice(self, "merged", MERGED_POLICIES, optional=False)


@dataclass(frozen=True, slots=True, eq=False)
class RobotExport:
    """Result of :func:`export_robot`: what the writer of ``format`` writes.

    Attributes
    ----------
    robot : Robot
        The robot with its parameters.
    format : str
        The name of its format in :data:`~dynid.io.export.ROBOT_FORMATS`.
    options : ExportOptions
        What the writer writes beside the robot (template, chain, friction, drive).
    mujoco_friction : CoulombViscous or None
        MJCF with the robot's own (sigmoid) friction: the ``frictionloss`` and
        ``damping`` that approximate it, per joint.
    """

    robot: Robot
    format: str
    options: ExportOptions
    mujoco_friction: CoulombViscous | None


def export_robot(
    params: str | Path, out: str | Path, options: ExportRobotOptions | None = None
) -> RobotExport:
    """Read the robot ``params`` and decide how it is written to ``out``.

    Parameters
    ----------
    params : str or Path
        ``feasible.json``, a robot ``.toml`` or ``.urdf``, ``"panda"`` or ``"fr3"``.
    out : str or Path
        The file to write (its suffix chooses the format unless ``options.format``).
    options : ExportRobotOptions, optional

    Returns
    -------
    RobotExport
        :func:`save_export` writes it.

    Raises
    ------
    OptionError
        ``params`` of another kind or missing, or a ``feasible.json`` of a fit that was not
        accepted without ``allow_rejected``; ``base``/``tip`` with neither a URDF robot
        nor a template; a template for another format (``field`` names it).
    DataError, ModelError
        An unreadable robot file; a URDF with several leaves and no ``tip``.
    """
    opt = options or ExportRobotOptions()
    urdf = _check_params(params)
    rejected = _check_accepted(params, opt.allow_rejected)
    for name in ("base", "tip"):
        if getattr(opt, name) is not None and not urdf and opt.urdf_template is None:
            raise OptionError(
                "chooses the chain of a URDF {params} or of {urdf_template}; give one",
                field=name,
                others=("params", "urdf_template"),
            )
    fmt = export_format(out, opt.format)
    if opt.urdf_template is not None and not ROBOT_FORMATS[fmt].template:
        raise OptionError(f"applies to the urdf format only; got {fmt}", field="urdf_template")
    if not opt.frictionloss and fmt != "mjcf":
        raise OptionError(
            f"(no frictionloss) applies to the mjcf format only; got {fmt}", field="frictionloss"
        )
    if opt.trajectory is not None and fmt != "mjcf":
        raise OptionError(f"applies to the mjcf format only; got {fmt}", field="trajectory")
    base, tip = (opt.base, opt.tip) if urdf else (None, None)  # also the template's
    robot = load_robot(params, base=base, tip=tip, snap_angles=opt.snap_angles)
    linear, drive = model_terms_of(params, robot.n)
    if opt.drive is not None:
        drive = opt.drive if isinstance(opt.drive, Drive) else load_drive(opt.drive, robot.n)
    left = None if opt.drive is not None else _armature_left_out(params, robot, drive)
    friction: Any = opt.friction
    if linear is not None and opt.friction:
        friction = linear
        at_joints = isinstance(linear, Friction) and linear.drive is None
        if isinstance(linear, Friction) and at_joints and drive is not None:
            friction = linear.at(drive) if drive.friction_place == "motor" else linear
    written = ExportOptions(
        template=None if opt.urdf_template is None else Path(opt.urdf_template),
        base=opt.base,
        tip=opt.tip,
        merged=opt.merged,
        friction=friction,
        all_frames=opt.all_frames,
        drive=drive,
        source=_friction_source(params, linear is not None and opt.friction),
        caveat="; ".join(c for c in (_caveat(params, rejected), left) if c) or None,
        frictionloss=opt.frictionloss,
        along=_along(opt.trajectory, robot.n),
    )
    approx = None
    sigmoid = sigmoid_parameters(robot.friction)
    if fmt == "mjcf" and friction is True and sigmoid is not None and opt.frictionloss:
        approx = coulomb_viscous_from_sigmoid(sigmoid, robot.dq_max)
    return RobotExport(robot, fmt, written, approx)


def _along(path: str | Path | None, n: int) -> Along | None:
    """The trajectory file ``path`` (``n`` joints) the MJCF's friction is measured along,
    a JSON sampled at 10 kHz; None for none."""
    if path is None:
        return None
    return Along(Path(path).name, load_trajectory(path, n, fs=1.0 / MOTION_STEP_S))


def save_export(path: str | Path, export: RobotExport) -> Path:
    """Write ``export`` to ``path`` with its format's writer; returns the path."""
    return ROBOT_FORMATS[export.format].save(path, export.robot, export.options)


def _check_params(params: str | Path) -> bool:
    """Whether ``params`` is a URDF; a built-in name or an existing robot file.

    Raises
    ------
    OptionError
        Another suffix, or a file that does not exist.
    """
    if str(params) in BUILTIN_ROBOTS:
        return False
    path = Path(params)
    if path.suffix.lower() not in ROBOT_FILE_SUFFIXES:
        raise OptionError(
            f"must be feasible.json, a robot .toml, .urdf or .xml (MJCF), or "
            f"{' or '.join(map(repr, BUILTIN_ROBOTS))}; got {str(params)!r}",
            field="params",
        )
    if not path.exists():
        raise OptionError(f": {path} does not exist", field="params")
    if path.suffix.lower() == ".json" and _schema(path) == "dynid-identified-model/1":
        raise OptionError(
            f": {path.name} holds base parameters (combinations of the links' parameters), "
            "not the links' own; run `dynid retrieve --model` on it or `dynid identify "
            "--consistent` first and export their feasible.json",
            field="params",
        )
    return path.suffix.lower() == ".urdf"


def _friction_source(params: str | Path, identified: bool) -> str | None:
    """The file that holds the exported friction exactly, for the writers' warnings: the
    ``feasible.json`` it was identified in, or a robot TOML (its ``[friction]`` table);
    None for a URDF, an MJCF or a built-in robot."""
    suffix = Path(params).suffix.lower()
    return Path(params).name if identified or suffix == ".toml" else None


def _caveat(params: str | Path, rejected: str | None) -> str | None:
    """The comment at the top of the robot file: why the fit was not accepted
    (``rejected``) and the joints whose torques carry an unknown scale (a
    ``feasible.json``'s ``unknown_scale``), or None."""
    path = Path(params)
    said = [] if rejected is None else [rejection_caveat(rejected)]
    if path.suffix.lower() == ".json" and path.exists():
        said += [c for c in (load_unknown_scale_caveat(path),) if c is not None]
    return "; ".join(said) or None


def _armature_left_out(params: str | Path, robot: Robot, drive: Drive | None) -> str | None:
    """The note of the rotor inertias a ``feasible.json``'s identified structure left out
    while it kept others (:func:`~dynid.io.feasible.armature_left_out_note`: the joints
    written with armature 0), said once and returned for the file's top; None for other
    robots, or nothing left out."""
    path = Path(params)
    if path.suffix.lower() != ".json" or not path.exists():
        return None
    note = armature_left_out_note(robot.joint_names, drive, load_armature_left_out(path))
    if note is not None:
        _log.log(NOTE, "%s", note)
    return note


def _check_accepted(params: str | Path, allowed: bool) -> str | None:
    """Refuse a ``feasible.json`` of a fit that was not accepted, unless ``allowed``;
    returns why it was not accepted (None: accepted, or not a ``feasible.json``).

    Raises
    ------
    OptionError
        Its reason, as the file records it (:func:`~dynid.io.feasible.fit_rejection`).
    """
    path = Path(params)
    if path.suffix.lower() != ".json" or not path.exists():
        return None
    rejected = load_fit_rejection(path)
    if rejected is not None and not allowed:
        raise OptionError(
            f": {path.name} holds a fit that was not accepted ({rejected}); fit again "
            "(identify --consistent or retrieve with another --prior, --prior-weight, "
            "--bounds, --total-mass or --margin) or give {allow_rejected} to write it anyway",
            field="params",
            others=("allow_rejected",),
        )
    return rejected


def _schema(path: Path) -> str | None:
    """The ``schema`` of a JSON file, None when it cannot be read (its reader says why)."""
    try:
        doc = json.loads(path.read_text(encoding="utf-8"))
    except (OSError, ValueError):
        return None
    return str(doc.get("schema")) if isinstance(doc, dict) else None
