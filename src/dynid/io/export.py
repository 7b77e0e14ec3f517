"""One entry point for writing a robot, and the table of the formats it can write.

:data:`ROBOT_FORMATS` lists every robot file format of the exports, each one module of
:mod:`dynid.io.robot` and one :class:`~dynid.io.robot.export_options.RobotFormat` line:

* ``urdf`` (``.urdf``): :func:`dynid.io.robot.urdf.export_urdf` (chain export, or
  ``template=`` the original URDF patched with the new inertials);
* ``mjcf`` (``.xml``, ``.mjcf``): :func:`dynid.io.robot.mjcf.export_mjcf` (``friction`` as
  ``frictionloss`` and ``damping``, a drive's rotors as ``armature``, the robot's joint
  spring as ``stiffness`` and ``springref``);
* ``toml`` (``.toml``): :func:`dynid.io.robot.toml.export_toml` (kinematics, inertials,
  limits, sigmoid friction, a drive as a ``[drive]`` table, the spring as ``[spring]``).

URDF holds no spring: its export says, in a warning and a comment, that it leaves it out.

:func:`save_robot` picks the format by ``format`` or the file suffix, and writes a consistent
fit's result (friction, rotor inertias, caveats) as the output folders do;
:func:`save_robot_files` writes one file per format into an output folder. ``dynid export``
(its ``--format`` choices), ``dynid retrieve`` and ``identify --consistent`` read this
table, so a new format is a module and a line here.
"""

from __future__ import annotations

from dataclasses import replace
from pathlib import Path
from typing import TYPE_CHECKING

from ..exceptions import DataError
from ..friction.model import Friction, FrictionSum
from ..model.drive import Drive
from ..model.robot import Robot
from .robot.export_options import ExportOptions, RobotFormat
from .robot.mjcf import export_mjcf
from .robot.toml import export_toml
from .robot.urdf import export_urdf

if TYPE_CHECKING:
    from ..feasibility.result import FeasibleResult

__all__ = [
    "EXPORT_FORMATS",
    "ROBOT_FORMATS",
    "ExportOptions",
    "RobotFormat",
    "export_format",
    "model_terms_of",
    "save_robot",
    "save_robot_files",
]

#: The robot file formats of the exports, by name (``--format``), in the order an output
#: folder lists them.
ROBOT_FORMATS: dict[str, RobotFormat] = {
    f.name: f
    for f in (
        RobotFormat("urdf", (".urdf",), export_urdf, template=True),
        RobotFormat("mjcf", (".xml", ".mjcf"), export_mjcf),
        RobotFormat("toml", (".toml",), export_toml),
    )
}
#: Their names (``dynid export --format`` choices).
EXPORT_FORMATS = tuple(ROBOT_FORMATS)


def export_format(path: str | Path, format: str | None = None) -> str:
    """The export format: ``format`` when given, else from the suffix of ``path``.

    Raises
    ------
    DataError
        Unknown format, or a suffix that names none.
    """
    names = ", ".join(ROBOT_FORMATS)
    if format is not None:
        if format not in ROBOT_FORMATS:
            raise DataError(f"format must be one of {names}; got {format!r}")
        return format
    suffix = Path(path).suffix.lower()
    for f in ROBOT_FORMATS.values():
        if suffix in f.suffixes:
            return f.name
    use = ", ".join("/".join(f.suffixes) for f in ROBOT_FORMATS.values())
    raise DataError(
        f"cannot tell the format of {Path(path).name!r} from its suffix; "
        f"use {use}, or give the format: one of {names}"
    )


def save_robot(
    path: str | Path,
    robot: Robot | FeasibleResult,
    *,
    format: str | None = None,
    template: str | Path | None = None,
    base: str | None = None,
    tip: str | None = None,
    merged: str = "subtract",
    friction: bool | Friction | FrictionSum = True,
    all_frames: bool = False,
    drive: Drive | None = None,
) -> Path:
    """Write ``robot`` in one of :data:`ROBOT_FORMATS`; returns the path.

    Given a consistent fit's result (a :class:`~dynid.feasibility.result.FeasibleResult`
    of :func:`~dynid.feasibility.convex.fit.retrieve_sdp`,
    :func:`~dynid.feasibility.convex.fit.identify_consistent` or
    :func:`~dynid.feasibility.penalty.fit.retrieve`), the file is written as ``dynid
    retrieve`` writes its robot files (:func:`~dynid.io.feasible_export.result_export`):
    the friction identified with the links (offsets included where the format holds
    them), the drive's rotor inertias (MJCF ``armature``, the TOML ``[drive]`` table), and
    what the format cannot hold said in a warning (a URDF's armature by joint, with its
    share of the joint's inertia; a friction offset) and at the top of the file. A
    :class:`~dynid.model.robot.Robot` alone (``result.robot``) holds no rotor inertia and
    no identified friction: its file has only the links and the robot's own friction.

    Parameters
    ----------
    path : str or Path
    robot : Robot or FeasibleResult
        The robot, or a consistent fit's result (above).
    format : str, optional
        A name of :data:`ROBOT_FORMATS` (``"urdf"``, ``"mjcf"``, ``"toml"``). Default:
        from the suffix of ``path``.
    template, base, tip, merged, all_frames
        URDF only (:func:`dynid.io.robot.urdf.save_urdf`).
    friction : bool or Friction
        MJCF: the robot's friction, identified classical friction (at the joints or the
        motors), or none (:func:`dynid.io.robot.mjcf.save_mjcf`); URDF chain: identified
        classical friction as ``<dynamics damping friction>``. True with a result: the
        friction identified with the links (else the robot's own).
    drive : Drive, optional
        MJCF: a drive with known rotor inertias, written as ``armature``; TOML: the drive
        as a ``[drive]`` table; URDF: its rotor inertias named in a warning. Default with
        a result: the result's drive.

    Raises
    ------
    DataError
        Unknown format; a URDF template given for another format.
    ModelError
        The template's chain does not match the robot.
    """
    fmt = ROBOT_FORMATS[export_format(path, format)]
    if template is not None and not fmt.template:
        raise DataError(f"a URDF template applies to the urdf format only; got format {fmt.name!r}")
    caveat = None
    if not isinstance(robot, Robot):  # a consistent fit's result: as its output folder
        from .feasible_export import result_export

        robot, fitted = result_export(robot)
        friction = fitted.friction if friction is True else friction
        drive = fitted.drive if drive is None else drive
        caveat = fitted.caveat
    options = ExportOptions(
        template=None if template is None else Path(template),
        base=base,
        tip=tip,
        merged=merged,
        friction=friction,
        all_frames=all_frames,
        drive=drive,
        caveat=caveat,
    )
    return fmt.save(path, robot, options)


def save_robot_files(
    folder: str | Path, robot: Robot, options: ExportOptions, *, stem: str = "robot"
) -> list[Path]:
    """Write ``robot`` once per format of :data:`ROBOT_FORMATS` into ``folder``.

    The files are ``<stem><first suffix>`` (``robot.urdf``, ``robot.xml``, ``robot.toml``),
    each written with ``options`` (a template, which one format takes, is not used here)
    and the others named in its warnings as written beside it (``ExportOptions.beside``).

    Returns
    -------
    list of Path
        The files written, in the table's order.
    """
    folder = Path(folder)
    names = {f.name: f"{stem}{f.suffixes[0]}" for f in ROBOT_FORMATS.values()}
    plain = replace(options, template=None, beside=names)
    return [f.save(folder / names[f.name], robot, plain) for f in ROBOT_FORMATS.values()]


def model_terms_of(spec: str | Path, n: int) -> tuple[Friction | FrictionSum | None, Drive | None]:
    """The model terms a robot file holds beside its links, for an export: the linear
    friction identified with the links and the drive of a ``feasible.json`` (its rotor
    inertias the identified ones), or the ``[drive]`` table of a robot TOML; ``(None, None)``
    for anything else (``panda``, a URDF, a TOML without a drive)."""
    p = Path(spec)
    suffix = p.suffix.lower()
    if suffix == ".json":
        from .feasible import load_feasible_drive, load_feasible_linear_friction

        return load_feasible_linear_friction(p), load_feasible_drive(p)
    if suffix == ".toml":
        from .drive_file import drive_of_robot_file

        return None, drive_of_robot_file(p, n)
    return None, None
