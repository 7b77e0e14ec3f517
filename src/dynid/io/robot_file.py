"""One entry point for reading a robot: a built-in name, a URDF, a dynid TOML, a feasible.json
or an MJCF.

:func:`load_robot` takes a name of :data:`dynid.model.builtin.BUILTIN_ROBOTS` (``"panda"``,
``"fr3"``) or picks the reader by the file's suffix; every command line option that names a
robot (``--robot``, ``--prior``, ``--params``) reads through it. It imports only the reader
it needs, so a command on a built-in robot loads no file reader at all.
"""

from __future__ import annotations

from pathlib import Path

from ..exceptions import DataError, OptionError
from ..model.builtin import BUILTIN_ROBOTS, builtin_robot
from ..model.robot import Robot

__all__ = ["ROBOT_FILE_SUFFIXES", "load_robot"]

#: Robot files :func:`load_robot` reads, by suffix.
ROBOT_FILE_SUFFIXES = (".urdf", ".toml", ".json", ".xml")


def load_robot(
    spec: str | Path,
    *,
    base: str | None = None,
    tip: str | None = None,
    what: str = "robot",
    snap_angles: bool = False,
    parameters: bool = True,
    note_angles: bool = True,
) -> Robot:
    """A built-in robot by name, or a robot file by its suffix: the one dispatch of robots.

    A name of :data:`~dynid.model.builtin.BUILTIN_ROBOTS` (``"panda"``, ``"fr3"``); else
    ``.urdf`` (the chain from ``base`` to ``tip``, rounded angles snapped with
    ``snap_angles``: :func:`dynid.io.robot.urdf.load_urdf`),
    ``.toml`` (:func:`dynid.io.robot.toml.load_toml`) or ``.json`` (a ``feasible.json``,
    :func:`dynid.io.feasible.load_feasible_json`, with the friction identified with the links
    when the file holds it, acting where it was identified) or ``.xml`` (an MJCF, read by
    MuJoCo's compiler when the ``mujoco`` package is installed:
    :func:`dynid.io.robot.mjcf_read.load_mjcf`). ``what`` names the option in errors;
    ``parameters`` False: the caller uses the kinematics alone, and a built-in robot's note
    on its link parameters is not given (:func:`~dynid.model.builtin.builtin_robot`);
    ``note_angles`` False: a URDF's rounded angles are not named in a note (a file read for
    its inertials alone).

    Raises
    ------
    DataError
        Another suffix, or a file that does not exist.
    OptionError
        ``base``, ``tip`` or ``snap_angles`` with a robot that is not a URDF (``field``
        names it).
    """
    path = Path(spec)
    suffix = path.suffix.lower()
    chain = {"base": base, "tip": tip, "snap_angles": snap_angles or None}
    given = next((k for k, v in chain.items() if v is not None), None)
    if given is not None and suffix != ".urdf":
        raise OptionError(f"applies to a URDF {what} only; leave it out", field=given)
    if str(spec) in BUILTIN_ROBOTS:
        return builtin_robot(str(spec), parameters=parameters)
    if suffix not in ROBOT_FILE_SUFFIXES:
        raise DataError(
            f"{what} must be {_names()} or a .urdf, .toml, .json (feasible.json) or .xml "
            "(MJCF) file; "
            f"got {str(spec)!r}"
        )
    if not path.exists():
        raise DataError(f"{what}: {path} does not exist")
    if suffix == ".urdf":
        from .robot.urdf import load_urdf

        return load_urdf(
            path, base_link=base, tip_link=tip, snap_angles=snap_angles, note_angles=note_angles
        )
    if suffix == ".toml":
        from .robot.toml import load_toml

        return load_toml(path)
    if suffix == ".xml":
        from .robot.mjcf_read import load_mjcf

        return load_mjcf(path)
    from .feasible import load_feasible_json

    return load_feasible_json(path)  # the friction identified with the links on it


def _names() -> str:
    """The built-in names as a user reads them in an error: ``'panda', 'fr3'``."""
    return ", ".join(repr(k) for k in BUILTIN_ROBOTS)
