"""The seam of the robot exports: the options every writer receives and one format's entry.

A format is one module of :mod:`dynid.io.robot` with a writer
``export_X(path, robot, options) -> Path`` that takes what it can hold from
:class:`ExportOptions` and ignores the rest, and one :class:`RobotFormat` line in
:data:`dynid.io.export.ROBOT_FORMATS`; ``dynid export --format``, the suffix dispatch of
:func:`dynid.io.export.save_robot` and the robot files of an output folder
(:func:`dynid.io.export.save_robot_files`) all read that table.
"""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import dataclass
from pathlib import Path

from ...friction.model import Friction, FrictionSum
from ...model.drive import Drive
from ...model.robot import Robot

__all__ = ["ExportOptions", "RobotFormat"]


@dataclass(frozen=True, slots=True)
class ExportOptions:
    """What a robot export may write beside the robot; each format takes what it can hold.

    Attributes
    ----------
    template : Path or None
        URDF: the original URDF, written back with only the chain's inertials replaced.
    base, tip : str or None
        URDF template: the chain's base and tip links.
    merged : {"subtract", "move"}
        URDF template: how a body is split over its moving and fixed links.
    friction : bool, Friction or FrictionSum
        True: the robot's own friction where the format holds it; a friction model of any
        law (at the joints, or at the motors of a drive); False: none.
    all_frames : bool
        URDF chain: every named frame as a fixed, massless link.
    drive : Drive or None
        A drive train: MJCF ``armature`` from its rotor inertias, a TOML ``[drive]`` table.
    note : str or None
        A remark on the friction written, put in the file's leading comment (URDF chain,
        MJCF, TOML): coefficients that hold structurally combined ones left out.
    """

    template: Path | None = None
    base: str | None = None
    tip: str | None = None
    merged: str = "subtract"
    friction: bool | Friction | FrictionSum = True
    all_frames: bool = False
    drive: Drive | None = None
    note: str | None = None


@dataclass(frozen=True, slots=True)
class RobotFormat:
    """One robot file format the exports can write.

    Attributes
    ----------
    name : str
        The name ``--format`` takes (``"urdf"``).
    suffixes : tuple of str
        File suffixes that select it, lower case with the dot; the first names the file
        in an output folder (``robot.urdf``).
    save : callable
        ``save(path, robot, options) -> Path``: writes the file atomically.
    template : bool
        Whether the format takes ``ExportOptions.template`` (others refuse one).
    """

    name: str
    suffixes: tuple[str, ...]
    save: Callable[[str | Path, Robot, ExportOptions], Path]
    template: bool = False
