"""One entry point for writing a robot description: URDF, MJCF or dynid TOML.

:func:`save_robot` picks the writer by ``format`` (or the file suffix: ``.urdf``;
``.xml``/``.mjcf``; ``.toml``) and passes its options on:

* URDF: :func:`dynid.io.robot.urdf.save_urdf` (chain export, or ``template=`` the
  original URDF patched with the new inertials);
* MJCF: :func:`dynid.io.robot.mjcf.save_mjcf` (``friction`` as ``frictionloss`` and
  ``damping``);
* TOML: :func:`dynid.io.robot.toml.save_toml` (kinematics, inertials, limits, sigmoid
  friction, a drive as a ``[drive]`` table).

``dynid export``, ``dynid retrieve`` and ``identify --consistent`` write through it.
"""

from __future__ import annotations

from pathlib import Path

from ..exceptions import DataError
from ..friction.model import ClassicalFriction, DriveFriction
from ..friction.mujoco import joint_coulomb_viscous
from ..model.drive import Drive
from ..model.robot import Robot
from .robot.mjcf import save_mjcf
from .robot.toml import save_toml
from .robot.urdf import save_urdf

__all__ = ["EXPORT_FORMATS", "export_format", "save_mjcf", "save_robot", "save_urdf"]

EXPORT_FORMATS = ("urdf", "mjcf", "toml")
_BY_SUFFIX = {".urdf": "urdf", ".xml": "mjcf", ".mjcf": "mjcf", ".toml": "toml"}


def export_format(path: str | Path, format: str | None = None) -> str:
    """The export format: ``format`` when given, else from the suffix of ``path``.

    Raises
    ------
    DataError
        Unknown format, or a suffix that names none.
    """
    if format is not None:
        if format not in EXPORT_FORMATS:
            raise DataError(f"format must be one of {EXPORT_FORMATS}; got {format!r}")
        return format
    suffix = Path(path).suffix.lower()
    if suffix not in _BY_SUFFIX:
        raise DataError(
            f"cannot tell the format of {Path(path).name!r} from its suffix; "
            f"use .urdf, .xml/.mjcf or .toml, or give the format ({EXPORT_FORMATS})"
        )
    return _BY_SUFFIX[suffix]


def save_robot(
    path: str | Path,
    robot: Robot,
    *,
    format: str | None = None,
    template: str | Path | None = None,
    base: str | None = None,
    tip: str | None = None,
    merged: str = "subtract",
    friction: bool | ClassicalFriction | DriveFriction = True,
    all_frames: bool = False,
    drive: Drive | None = None,
) -> Path:
    """Write ``robot`` as URDF, MJCF or TOML; returns the path.

    Parameters
    ----------
    path : str or Path
    robot : Robot
    format : {"urdf", "mjcf", "toml"}, optional
        Default: from the suffix of ``path``.
    template, base, tip, merged, all_frames
        URDF only (:func:`dynid.io.robot.urdf.save_urdf`).
    friction : bool, ClassicalFriction or DriveFriction
        MJCF: the robot's friction, identified classical friction (at the joints or the
        motors), or none (:func:`dynid.io.robot.mjcf.save_mjcf`); URDF chain: identified
        classical friction as ``<dynamics damping friction>``.
    drive : Drive, optional
        MJCF: a drive with known rotor inertias, written as ``armature``; TOML: the drive
        as a ``[drive]`` table.

    Raises
    ------
    DataError
        Unknown format; a URDF template given for another format.
    ModelError
        The template's chain does not match the robot.
    """
    fmt = export_format(path, format)
    if template is not None and fmt != "urdf":
        raise DataError(f"a URDF template applies to the urdf format only; got format {fmt!r}")
    if fmt == "urdf":
        dyn = None
        if isinstance(friction, ClassicalFriction | DriveFriction):
            jt = joint_coulomb_viscous(friction)
            dyn = (jt.damping, jt.frictionloss)
        return save_urdf(
            path,
            robot,
            all_frames=all_frames,
            template=template,
            base=base,
            tip=tip,
            merged=merged,
            dynamics=dyn,
        )
    if fmt == "mjcf":
        return save_mjcf(path, robot, friction=friction, drive=drive)
    return save_toml(path, robot, drive=drive)


def model_terms_of(
    spec: str | Path, n: int
) -> tuple[ClassicalFriction | DriveFriction | None, Drive | None]:
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
