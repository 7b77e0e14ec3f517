"""``feasible.json``: the feasible link parameters of a retrieval or a consistent fit.

:func:`save_feasible_json` and :func:`load_feasible_json`: the parameters of every moving
link, in the schema of the robot description's inertials (:mod:`dynid.io.robot.toml`):
``mass`` [kg], ``com`` [m] in the link frame, ``inertia`` ``[xx, xy, xz, yy, yz, zz]``
[kg m^2] **about the CoM**, link-frame axes. It also holds the robot's kinematics
(:mod:`dynid.io.robot_json`) and its sigmoid friction, so that it loads back as a complete
:class:`~dynid.model.robot.Robot`::

    {"schema": "dynid-feasible-parameters/1", "dynid_version": ..., "name": ...,
     "links": [{"name": "link1", "mass": 4.97, "com": [...], "inertia": [...]}, ...],
     "friction": null | {"model": "sigmoid", "phi1": [...], "phi2": [...], "phi3": [...]},
     "linear_friction": null | {"model": "classical", "fv": [...], "fc": [...], "fo": [...]},
     "drive": null | {dynid-drive/1 record, rotor_inertia: the identified values},
     "kinematics": {...}, "feasible": true, "relative_residual": ..., "seed": ...,
     "units": {...}, "conventions": {...}}
"""

from __future__ import annotations

import warnings
from collections.abc import Mapping
from pathlib import Path
from typing import Any

import numpy as np
from numpy.typing import NDArray

from .. import __version__, _checks
from ..exceptions import DataError, DynidWarning, ModelError, ShapeError
from ..feasibility.result import FeasibleResult
from ..friction.model import ClassicalFriction, Friction
from ..model.drive import Drive
from ..model.inertia import (
    INERTIA_ORDER,
    inertia6_from_matrix,
    inertial_problems,
    matrix_from_inertia6,
)
from ..model.robot import MAX_LINK_MASS, MAX_LINK_OFFSET, Robot
from .drive_file import drive_from_record
from .json_files import finite_or_none, load_json, save_json
from .robot_json import robot_from_dict, robot_to_dict

__all__ = [
    "FEASIBLE_SCHEMA",
    "feasible_to_dict",
    "load_feasible_drive",
    "load_feasible_json",
    "load_feasible_linear_friction",
    "robot_from_feasible_dict",
    "save_feasible_json",
]

FEASIBLE_SCHEMA = "dynid-feasible-parameters/1"

_UNITS = {"mass": "kg", "com": "m", "inertia": "kg m^2"}
_CONVENTIONS = {
    "com": "centre of mass in the link frame",
    "inertia": "about the CoM, link-frame axes, order " + " ".join(INERTIA_ORDER),
    "friction": "tau_f = phi1/(1+exp(-phi2 (dq+phi3))) - phi1/(1+exp(-phi2 phi3)) "
    "[phi1 N m, phi2 s/rad, phi3 rad/s] (Gaz et al. 2019, eq. 25)",
}
_LINK_KEYS = {"name", "mass", "com", "inertia"}
#: the keys :func:`feasible_to_dict` writes
_KEYS = {
    "schema",
    "dynid_version",
    "name",
    "links",
    "friction",
    "linear_friction",
    "kinematics",
    "units",
    "conventions",
    "drive",
    "method",
    "feasible",
    "relative_residual",
    "seed",
    "heldout",
}
#: the farthest a link's centre of mass may lie from its frame [m], as in the robot
#: readers (1e300 overflowed the parallel-axis inertia into NaN)
MAX_COM_DISTANCE = MAX_LINK_OFFSET


def _numbers(v: Any, size: int, where: str) -> NDArray[np.float64]:
    return _checks.numbers(v, size, where, DataError)


def feasible_to_dict(source: FeasibleResult | Robot, *, seed: int | None = None) -> dict[str, Any]:
    """The link parameters (and kinematics, friction) of a consistent result or a robot.

    Parameters
    ----------
    source : FeasibleResult or Robot
        A result (either method) also records ``method``, ``feasible``,
        ``relative_residual`` and its seed; the classical friction identified with the links
        (``linear_friction``: ``fv, fc >= 0``; per motor with a drive whose friction acts
        at the motors), its drive's record (``drive``, the identified rotor inertias
        [kg m^2] in ``rotor_inertia``) and its held-out judgement (``heldout``) when it has
        them.
    seed : int, optional
        Recorded when ``source`` is a Robot.

    Returns
    -------
    dict
        JSON-ready (module docstring).
    """
    result = None if isinstance(source, Robot) else source
    robot = source if isinstance(source, Robot) else source.robot
    I6 = inertia6_from_matrix(robot.inertia)
    links = [
        {
            "name": robot.link_names[i + 1],
            "mass": float(robot.mass[i]),
            "com": [float(x) for x in robot.com[i]],
            "inertia": [float(x) for x in I6[i]],
        }
        for i in range(robot.n)
    ]
    fr = None
    if robot.friction is not None:
        fr = {"model": "sigmoid"} | {
            f"phi{k + 1}": [float(x) for x in robot.friction[:, k]] for k in range(3)
        }
    lin = None if result is None else result.friction
    drive = None if result is None else result.drive
    d: dict[str, Any] = {
        "schema": FEASIBLE_SCHEMA,
        "dynid_version": __version__,
        "name": robot.name,
        "links": links,
        "friction": fr,
        "linear_friction": None
        if lin is None
        else {"model": "classical"}
        | {k: [float(x) for x in lin[:, j]] for j, k in enumerate(("fv", "fc", "fo"))},
        "kinematics": robot_to_dict(robot),
        "units": _UNITS,
        "conventions": _CONVENTIONS,
        "drive": None if drive is None else drive.as_dict(),
    }
    if result is None:
        return d if seed is None else d | {"seed": seed}
    d["method"] = result.method
    d["feasible"] = bool(result.feasible)
    d["relative_residual"] = finite_or_none(result.relative_residual)
    d["seed"] = result.seed
    if result.heldout is not None:
        d["heldout"] = result.heldout.as_dict()
    return d


def save_feasible_json(path: str | Path, source: FeasibleResult | Robot) -> Path:
    """Write ``feasible.json`` (see :func:`feasible_to_dict`); returns the path.

    Raises
    ------
    NonFiniteError
        A NaN or infinite number in the parameters (named).
    """
    return save_json(path, feasible_to_dict(source))


def robot_from_feasible_dict(d: Mapping[str, Any], robot: Robot | None = None) -> Robot:
    """A robot with the link parameters of a :func:`feasible_to_dict` dictionary.

    Parameters
    ----------
    d : mapping
    robot : Robot, optional
        Kinematics to put the parameters on (its link names must match the file's);
        default the kinematics and friction held in the file.

    Raises
    ------
    DataError
        Wrong schema, an unknown key, a missing or malformed field, a mass beyond
        ``MAX_LINK_MASS`` or a CoM beyond :data:`MAX_COM_DISTANCE`, link names that do not
        match ``robot``.

    Warns
    -----
    DynidWarning
        A link whose parameters are not physically consistent (kept as given).
    """
    if d.get("schema") != FEASIBLE_SCHEMA:
        raise DataError(
            f"not a feasible-parameter file (schema {d.get('schema')!r}, "
            f"expected {FEASIBLE_SCHEMA!r})"
        )
    unknown = sorted(set(d) - _KEYS)
    if unknown:
        raise DataError(f"feasible parameters: unknown key(s) {_checks.short(unknown)}")
    if not isinstance(d.get("feasible", False), bool):
        raise DataError(
            f"feasible parameters: 'feasible' must be true or false; got "
            f"{_checks.short(d['feasible'])}"
        )
    try:
        links = list(d["links"])
    except (KeyError, TypeError):
        raise DataError("feasible parameters: missing field 'links'") from None
    if robot is None:
        if "kinematics" not in d:
            raise DataError("feasible parameters: no 'kinematics'; pass the robot")
        robot = robot_from_dict(d["kinematics"])
        fr = d.get("friction")
        if fr is not None:
            try:
                F = np.stack(
                    [_numbers(fr[f"phi{k}"], robot.n, f"friction phi{k}") for k in (1, 2, 3)],
                    axis=1,
                )
            except (KeyError, TypeError):
                raise DataError("feasible parameters: friction needs phi1, phi2, phi3") from None
            robot = robot.with_friction(F)
    if len(links) != robot.n:
        raise DataError(
            f"feasible parameters for {len(links)} links; robot {robot.name!r} has {robot.n}"
        )
    mass = np.empty(robot.n)
    com = np.empty((robot.n, 3))
    I6 = np.empty((robot.n, 6))
    for i, link in enumerate(links):
        where = f"feasible parameters, link {i + 1}"
        if not isinstance(link, Mapping):
            raise DataError(f"{where}: expected an object")
        unknown = sorted(set(link) - _LINK_KEYS)
        if unknown:
            raise DataError(f"{where}: unknown keys {unknown}")
        name = link.get("name")
        if name is not None and name != robot.link_names[i + 1]:
            raise DataError(
                f"{where} is named {name!r}; robot {robot.name!r} has "
                f"{robot.link_names[i + 1]!r} there"
            )
        try:
            mass[i] = _numbers([link["mass"]], 1, f"{where} mass")[0]
            com[i] = _numbers(link["com"], 3, f"{where} com")
            I6[i] = _numbers(link["inertia"], 6, f"{where} inertia")
        except KeyError as exc:
            raise DataError(f"{where}: missing {exc.args[0]!r}") from None
        _check_link(where, mass[i], com[i], I6[i])
    try:
        return robot.with_inertials(mass, com, I6)
    except (ModelError, ShapeError) as exc:
        raise DataError(f"feasible parameters: {exc}") from exc


def _check_link(where: str, mass: float, com: NDArray[np.float64], I6: NDArray[np.float64]) -> None:
    """Refuse a mass or a CoM no robot description holds; warn, as the URDF reader does, on
    parameters that are not physically consistent, a negative mass included (kept: those of
    an infeasible result are not consistent)."""
    if not abs(mass) <= MAX_LINK_MASS:
        raise DataError(f"{where}: mass must be at most {MAX_LINK_MASS:g} kg; got {float(mass)!r}")
    if not float(np.max(np.abs(com))) <= MAX_COM_DISTANCE:
        raise DataError(
            f"{where}: com must lie within {MAX_COM_DISTANCE:g} m of the link frame; got "
            f"{com.tolist()}"
        )
    problems = inertial_problems(mass, matrix_from_inertia6(I6))
    if problems:
        warnings.warn(
            f"{where} is physically inconsistent: {'; '.join(problems)}; kept as given",
            DynidWarning,
            stacklevel=4,
        )


def load_feasible_json(path: str | Path, robot: Robot | None = None) -> Robot:
    """Read ``feasible.json``: a Robot with the feasible link parameters.

    With ``robot`` None the kinematics and friction stored in the file are used;
    otherwise the parameters are put on ``robot`` (link names must match). This is what
    ``dynid validate --params feasible.json`` loads.

    Raises
    ------
    DataError
        Not JSON, or not a feasible-parameter file (see :func:`robot_from_feasible_dict`).
    """
    try:
        return robot_from_feasible_dict(load_json(path), robot)
    except DataError as exc:
        name = Path(path).name
        if str(exc).startswith(name):
            raise
        raise DataError(f"{name}: {exc}") from exc


def load_feasible_linear_friction(path: str | Path) -> Friction | None:
    """The classical friction (``fv, fc, fo`` per joint) held by ``feasible.json``, or None.

    Written by a consistent identification from a torque log; ``dynid validate --params``
    uses it unless another friction is given. With a drive whose friction acts at the
    motors, the law per motor mapped through the transmission (a
    :class:`~dynid.friction.model.Friction` with the drive).
    """
    d = load_json(path)
    lin = d.get("linear_friction")
    if lin is None:
        return None
    name = Path(path).name
    try:
        n = len(d["links"])
        law = ClassicalFriction(
            *(_numbers(lin[k], n, f"{name}: linear_friction {k}") for k in ("fv", "fc", "fo"))
        )
    except (KeyError, TypeError):
        raise DataError(f"{name}: linear_friction needs fv, fc, fo per joint") from None
    drive = load_feasible_drive(path)
    return law.at(drive) if drive is not None and drive.friction_at == "motor" else law


def load_feasible_drive(path: str | Path) -> Drive | None:
    """The drive train held by ``feasible.json`` (its rotor inertias the identified ones), or
    None."""
    d = load_json(path)
    if d.get("drive") is None:
        return None
    try:
        n = len(d["links"])
    except (KeyError, TypeError):
        raise DataError(f"{Path(path).name}: 'links' must be a list") from None
    try:
        return drive_from_record(d["drive"], n)
    except DataError as exc:
        raise DataError(f"{Path(path).name}: {exc}") from exc
