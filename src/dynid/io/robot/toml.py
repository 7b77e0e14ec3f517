"""dynid's own TOML robot description, read and written.

:func:`load_toml` (or :func:`robot_from_toml_string`) reads a description,
:func:`save_toml` (or :func:`toml_from_robot`) writes one. The description holds everything
a :class:`~dynid.model.robot.Robot` holds: kinematics, inertial parameters, limits,
friction, gravity and named frames. Units are SI throughout (m, rad, kg, kg m^2, s);
angles are never in degrees. Writing and reading a robot gives the same robot to about
1e-15 (floats are written with ``repr``).

Layout: optional top-level ``format_version = 1``, ``name``, ``gravity`` and
``q_neutral``; one ``[[joints]]`` table per joint from the base to the tip (``name``,
``type`` "revolute" or "prismatic", ``parent``, ``child``, an ``origin`` (xyz, URDF rpy) or
``mdh`` pose, ``axis``, ``limits``, ``friction`` and a ``[joints.inertial]`` table with
``mass``, ``com`` and ``inertia`` about the CoM); optional ``[[frames]]``. The full schema,
with an annotated example, is in ``docs/robot-description.md``.

Unknown keys are rejected, so that a misspelt key does not silently fall back to a
default; numbers must be finite TOML numbers (never booleans or strings), an axis of a
squared length beyond the float range and a mass outside ``[0, MAX_LINK_MASS]`` are refused.
Every error names the joint or frame and the key.
"""

from __future__ import annotations

import math
import warnings
from collections.abc import Mapping, Sequence
from dataclasses import dataclass
from pathlib import Path
from typing import Any

import numpy as np
from numpy.typing import NDArray

from ... import _checks, spatial
from ...exceptions import DynidError, DynidWarning, ModelError
from ...model.drive import Drive
from ...model.inertia import (
    inertia6_from_matrix,
    inertial_problems,
    matrix_from_inertia6,
    phi_from_inertial,
)
from ...model.robot import (
    MAX_LINK_MASS,
    MAX_LINK_OFFSET,
    STANDARD_GRAVITY,
    Frame,
    Robot,
    mdh_transform,
)
from ..atomic import write_text
from ..drive_file import drive_toml
from ..input_files import file_text
from .export_options import ExportOptions

__all__ = [
    "FORMAT_VERSION",
    "export_toml",
    "load_toml",
    "robot_from_toml_string",
    "save_toml",
    "toml_from_robot",
]

#: Version of the schema written by :func:`toml_from_robot`.
FORMAT_VERSION = 1

_TOP_KEYS = {"format_version", "name", "gravity", "q_neutral", "joints", "frames", "drive"}
#: ``[drive]`` (a drive train) is read by :func:`dynid.io.drive_file.load_drive`, not here.
_JOINT_KEYS = {
    "name",
    "type",
    "parent",
    "child",
    "origin",
    "mdh",
    "axis",
    "limits",
    "friction",
    "inertial",
}
_ORIGIN_KEYS = {"xyz", "rpy"}
_MDH_KEYS = {"a", "d", "alpha", "theta"}
_LIMIT_KEYS = ("lower", "upper", "velocity", "acceleration", "effort")
_INERTIAL_KEYS = {"mass", "com", "inertia"}
_FRAME_KEYS = {"name", "parent", "xyz", "rpy", "mdh"}
_TYPES = {"revolute": False, "prismatic": True}


# ---------------------------------------------------------------------- reading helpers
def _check_keys(table: Mapping[str, Any], allowed: set[str], where: str) -> None:
    unknown = sorted(set(table) - allowed)
    if unknown:
        raise ModelError(
            f"{where}: unknown key {_checks.short(unknown[0])}; allowed: {sorted(allowed)}"
        )


def _table(value: Any, where: str) -> Mapping[str, Any]:
    if not isinstance(value, Mapping):
        raise ModelError(f"{where} must be a table; got {type(value).__name__}")
    return value


def _require(table: Mapping[str, Any], key: str, where: str) -> Any:
    if key not in table:
        raise ModelError(f"{where}: missing key {_checks.short(key)}")
    return table[key]


def _string(table: Mapping[str, Any], key: str, where: str) -> str:
    value = _require(table, key, where)
    if not isinstance(value, str) or not value:
        raise ModelError(
            f"{where}: key {key!r} must be a non-empty string; got {_checks.short(value)}"
        )
    return value


def _number(value: Any, where: str, key: str, *, finite: bool = True) -> float:
    if not finite and isinstance(value, float) and math.isinf(value):
        return value  # limits may be inf (none)
    return _checks.number(value, f"{where}: key {key!r}", ModelError)


def _vector(value: Any, size: int, where: str, key: str) -> NDArray[np.float64]:
    if not isinstance(value, list) or len(value) != size:
        got = f"{len(value)} entries" if isinstance(value, list) else _checks.short(value)
        raise ModelError(f"{where}: key {key!r} must be a list of {size} numbers; got {got}")
    return np.array([_number(v, where, key) for v in value])


def _pose(table: Mapping[str, Any], where: str, *, nested: bool) -> NDArray[np.float64]:
    """Pose (4, 4) from ``xyz``/``rpy`` (in ``origin = {...}`` when ``nested``) or ``mdh``."""
    origin_keys = ("origin",) if nested else ("xyz", "rpy")
    if "mdh" in table:
        if any(k in table for k in origin_keys):
            what = " and ".join(repr(k) for k in origin_keys if k in table)
            raise ModelError(f"{where}: give either {what} or 'mdh', not both")
        mdh = _table(table["mdh"], f"{where}: key 'mdh'")
        _check_keys(mdh, _MDH_KEYS, f"{where}: mdh")
        a, d, alpha = (
            _number(_require(mdh, k, f"{where}: mdh"), where, f"mdh.{k}")
            for k in ("a", "d", "alpha")
        )
        theta = _number(mdh.get("theta", 0.0), where, "mdh.theta")
        return mdh_transform(a, d, alpha, theta)
    origin, prefix = table, ""
    if nested:
        origin, prefix = _table(table.get("origin", {}), f"{where}: key 'origin'"), "origin."
        _check_keys(origin, _ORIGIN_KEYS, f"{where}: origin")
    xyz = _vector(origin.get("xyz", [0.0, 0.0, 0.0]), 3, where, f"{prefix}xyz")
    rpy = _vector(origin.get("rpy", [0.0, 0.0, 0.0]), 3, where, f"{prefix}rpy")
    return spatial.transform_from_xyz_rpy(xyz, rpy)


@dataclass(frozen=True, slots=True)
class _JointRow:
    """One ``[[joints]]`` table, read and checked."""

    name: str
    parent: str
    child: str
    T_parent_joint: NDArray[np.float64]
    axis: NDArray[np.float64]
    prismatic: bool
    limits: dict[str, float]
    mass: float
    com: NDArray[np.float64]
    inertia: NDArray[np.float64]
    friction: NDArray[np.float64] | None


def _axis(jt: Mapping[str, Any], where: str) -> NDArray[np.float64]:
    """The joint axis (3,) as given (the robot normalises it); zero or overflowing refused."""
    axis = _vector(jt.get("axis", [0.0, 0.0, 1.0]), 3, where, "axis")
    with np.errstate(over="ignore"):
        norm = float(np.linalg.norm(axis))
    if norm < 1e-12:
        raise ModelError(f"{where}: key 'axis' must not be zero")
    if not math.isfinite(norm):
        raise ModelError(
            f"{where}: key 'axis' = {axis.tolist()} is too large to normalise "
            "(its squared length overflows a float); give the axis as a unit vector"
        )
    return axis


def _limits(jt: Mapping[str, Any], where: str) -> dict[str, float]:
    """``lower``, ``upper``, ``velocity``, ``acceleration``, ``effort`` (inf where none)."""
    lim = dict.fromkeys(_LIMIT_KEYS, math.inf)
    lim["lower"] = -math.inf
    table = _table(jt.get("limits", {}), f"{where}: key 'limits'")
    _check_keys(table, set(_LIMIT_KEYS), f"{where}: limits")
    for k, v in table.items():
        lim[k] = _number(v, where, f"limits.{k}", finite=False)
        if k not in ("lower", "upper") and not lim[k] > 0.0:
            raise ModelError(f"{where}: key 'limits.{k}' must be positive; got {_checks.short(v)}")
    if not lim["lower"] < lim["upper"]:
        raise ModelError(
            f"{where}: key 'limits.lower' must be below 'limits.upper'; "
            f"got {lim['lower']!r} >= {lim['upper']!r}"
        )
    return lim


def _inertial(
    jt: Mapping[str, Any], where: str
) -> tuple[float, NDArray[np.float64], NDArray[np.float64]]:
    """Mass [kg], CoM [m] (3,) and inertia about the CoM (6,) of ``[joints.inertial]``."""
    if "inertial" not in jt:
        return 0.0, np.zeros(3), np.zeros(6)
    inertial = _table(jt["inertial"], f"{where}: key 'inertial'")
    _check_keys(inertial, _INERTIAL_KEYS, f"{where}: inertial")
    inside = f"{where}: inertial"
    mass = _number(_require(inertial, "mass", inside), where, "inertial.mass")
    if not 0.0 <= mass <= MAX_LINK_MASS:
        raise ModelError(
            f"{where}: key 'inertial.mass' must lie in [0, {MAX_LINK_MASS:g}] kg; got {mass!r}"
        )
    com = _vector(_require(inertial, "com", inside), 3, where, "inertial.com")
    if not float(np.max(np.abs(com))) <= MAX_LINK_OFFSET:  # 1e300: the inertia became NaN
        raise ModelError(
            f"{where}: key 'inertial.com' must lie within {MAX_LINK_OFFSET:g} m of the link "
            f"frame; got {com.tolist()}"
        )
    inertia = _vector(_require(inertial, "inertia", inside), 6, where, "inertial.inertia")
    problems = inertial_problems(mass, matrix_from_inertia6(inertia))
    if problems:  # as the URDF reader: kept, as a real description may round its numbers
        warnings.warn(
            f"{where}: the inertial is physically inconsistent: {'; '.join(problems)}; "
            "kept as given",
            DynidWarning,
            stacklevel=2,
        )
    return mass, com, inertia


def _joint_row(i: int, raw: Any) -> _JointRow:
    """Joint ``i`` (0-based) of the ``[[joints]]`` array, every key checked."""
    jt = _table(raw, f"joints[{i}]")
    jname = _string(jt, "name", f"joints[{i}]")
    where = f"joints[{i}] ({jname!r})"
    _check_keys(jt, _JOINT_KEYS, where)
    kind = _string(jt, "type", where)
    if kind not in _TYPES:
        raise ModelError(
            f"{where}: key 'type' must be one of {sorted(_TYPES)}; got {_checks.short(kind)}"
        )
    parent, child = _string(jt, "parent", where), _string(jt, "child", where)
    T, axis, limits = _pose(jt, where, nested=True), _axis(jt, where), _limits(jt, where)
    mass, com, inertia = _inertial(jt, where)
    friction = _vector(jt["friction"], 3, where, "friction") if "friction" in jt else None
    return _JointRow(
        jname, parent, child, T, axis, _TYPES[kind], limits, mass, com, inertia, friction
    )


def _joint_rows(joints: list[Any], source: str) -> list[_JointRow]:
    """Every joint, checked to form a chain and to give friction for all joints or none."""
    rows: list[_JointRow] = []
    for i, raw in enumerate(joints):
        row = _joint_row(i, raw)
        if rows and row.parent != rows[-1].child:
            raise ModelError(
                f"joints[{i}] ({row.name!r}): unknown parent {row.parent!r}; joints must form "
                f"a chain, so the parent must be the previous joint's child {rows[-1].child!r}"
            )
        rows.append(row)
    given = [r.friction is not None for r in rows]
    if any(given) and not all(given):
        missing = rows[given.index(False)].name
        raise ModelError(
            f"{source}: key 'friction' is given for some joints but not for joint {missing!r}; "
            "give it for every joint or for none"
        )
    return rows


def _frames(doc: Mapping[str, Any], source: str, link_names: list[str]) -> dict[str, Frame]:
    """The ``[[frames]]``, each fixed to a link or to an earlier frame."""
    frames: dict[str, Frame] = {}
    raw_frames = doc.get("frames", [])
    if not isinstance(raw_frames, list):
        raise ModelError(f"{source}: 'frames' must be an array of tables ([[frames]])")
    for i, raw in enumerate(raw_frames):
        ft = _table(raw, f"frames[{i}]")
        fname = _string(ft, "name", f"frames[{i}]")
        where = f"frames[{i}] ({fname!r})"
        _check_keys(ft, _FRAME_KEYS, where)
        if fname in frames:
            raise ModelError(f"{where}: duplicate frame name {fname!r}")
        parent = _string(ft, "parent", where)
        if parent in link_names:
            link, T_link_parent = link_names.index(parent), np.eye(4)
        elif parent in frames:
            link, T_link_parent = frames[parent].link, frames[parent].T_link_frame
        else:
            raise ModelError(
                f"{where}: unknown parent {parent!r}; available: links {link_names} "
                f"and earlier frames {list(frames)}"
            )
        frames[fname] = Frame(link, T_link_parent @ _pose(ft, where, nested=False))
    return frames


def robot_from_toml_string(text: str, *, source: str = "TOML text") -> Robot:
    """Robot from the text of a dynid TOML description (schema: see the module docstring).

    Parameters
    ----------
    text : str
        The TOML document.
    source : str
        Name of the document used in error messages (a file path, say).

    Returns
    -------
    Robot

    Raises
    ------
    ModelError
        The text is not valid TOML, or a key is missing, unknown, of the wrong type or
        length, a joint's parent is not the previous joint's child, a frame's parent is
        unknown, names repeat, or the robot is otherwise invalid (limits, axes); the
        message names the joint or frame and the key.
    """
    doc = _checks.parse_toml(text, source, ModelError)
    _check_keys(doc, _TOP_KEYS, source)
    version = doc.get("format_version", FORMAT_VERSION)
    if version != FORMAT_VERSION:
        raise ModelError(
            f"{source}: key 'format_version' must be {FORMAT_VERSION}; got {_checks.short(version)}"
        )
    name = doc.get("name", "robot")
    if not isinstance(name, str):
        raise ModelError(f"{source}: key 'name' must be a string; got {_checks.short(name)}")
    gravity = _vector(doc.get("gravity", [0.0, 0.0, -STANDARD_GRAVITY]), 3, source, "gravity")
    q_neutral = (
        _vector(doc["q_neutral"], len(doc.get("joints", [])), source, "q_neutral")
        if "q_neutral" in doc
        else None
    )
    joints = _require(doc, "joints", source)
    if not isinstance(joints, list) or not joints:
        raise ModelError(f"{source}: 'joints' must be a non-empty array of tables ([[joints]])")
    rows = _joint_rows(joints, source)
    link_names = [rows[0].parent] + [r.child for r in rows]
    frames = _frames(doc, source, link_names)
    lim = {k: np.array([r.limits[k] for r in rows]) for k in _LIMIT_KEYS}
    friction = [r.friction for r in rows if r.friction is not None]
    try:
        return Robot(
            name=name,
            joint_names=tuple(r.name for r in rows),
            link_names=tuple(link_names),
            T_parent_joint=np.stack([r.T_parent_joint for r in rows]),
            axes=np.stack([r.axis for r in rows]),
            prismatic=np.array([r.prismatic for r in rows]),
            phi=phi_from_inertial(
                np.array([r.mass for r in rows]),
                np.stack([r.com for r in rows]),
                np.stack([r.inertia for r in rows]),
            ),
            q_min=lim["lower"],
            q_max=lim["upper"],
            dq_max=lim["velocity"],
            ddq_max=lim["acceleration"],
            tau_max=lim["effort"],
            gravity=gravity,
            frames=frames,
            friction=np.stack(friction) if len(friction) == len(rows) else None,
            q_neutral=q_neutral,
        )
    except DynidError as exc:
        raise ModelError(f"{source}: {exc}") from exc


def load_toml(path: str | Path) -> Robot:
    """Robot from a dynid TOML description file (schema: see the module docstring).

    Parameters
    ----------
    path : str or Path
        The ``.toml`` file (UTF-8).

    Returns
    -------
    Robot

    Raises
    ------
    ModelError
        The file does not exist or cannot be read, is not valid TOML, or does not follow
        the schema (the message names the joint or frame and the key).
    """
    p = Path(path)
    try:
        text = file_text(p)
    except FileNotFoundError as exc:
        raise ModelError(f"TOML description not found: {str(p)!r}") from exc
    except (OSError, UnicodeDecodeError) as exc:
        raise ModelError(f"cannot read TOML description {str(p)!r}: {exc}") from exc
    return robot_from_toml_string(text, source=f"TOML file {str(p)!r}")


# ---------------------------------------------------------------------- writing
def _f(x: float) -> str:
    """A float as a TOML literal that reads back to the same float (-0.0 written as 0.0)."""
    x = float(x) + 0.0
    if math.isnan(x):
        return "nan"
    if math.isinf(x):
        return "inf" if x > 0 else "-inf"
    return repr(x)


def _arr(v: Sequence[float] | NDArray[np.float64]) -> str:
    return "[" + ", ".join(_f(x) for x in v) + "]"


def _s(text: str) -> str:
    """A TOML basic string (:func:`dynid._checks.toml_string`)."""
    return _checks.toml_string(text)


def _xyz_rpy(T: NDArray[np.float64]) -> tuple[str, str]:
    return _arr(T[:3, 3]), _arr(spatial.rpy_from_matrix(T[:3, :3]))


def toml_from_robot(robot: Robot) -> str:
    """The dynid TOML description of a robot (schema: see the module docstring).

    Joint origins are written as ``origin = {xyz, rpy}``, inertials as mass, CoM and
    inertia about the CoM, finite limits only, friction when the robot has a friction
    model, and every frame except the links' own frames (``flange`` always). Floats are
    written with ``repr``, so :func:`robot_from_toml_string` gives back the same robot to
    about 1e-15 (the inertia about the CoM and the rpy angles are recomputed).

    Parameters
    ----------
    robot : Robot

    Returns
    -------
    text : str
        The TOML document.

    Warns
    -----
    DynidWarning
        The robot holds friction of another law than the sigmoid
        (``Robot.friction_model``), which a description does not hold: it is not written
        (``friction.json`` holds any law).
    """
    if robot.friction_model is not None:
        warnings.warn(
            f"TOML export: the robot's {robot.friction_model.kind} friction is not part of a "
            "robot description (which holds the sigmoid) and is not written; save it as "
            "friction.json",
            DynidWarning,
            stacklevel=2,
        )
    out = [
        "# dynid robot description; schema: dynid.io.robot.toml",
        "# units: m, rad, kg, kg m^2, s; inertia about the CoM, in link axes",
        f"format_version = {FORMAT_VERSION}",
        f"name = {_s(robot.name)}",
        f"gravity = {_arr(robot.gravity)}",
    ]
    if robot.q_neutral is not None:
        out.append(f"q_neutral = {_arr(robot.q_neutral)}")
    mass, com, inertia = robot.mass, robot.com, robot.inertia
    for i in range(robot.n):
        xyz, rpy = _xyz_rpy(robot.T_parent_joint[i])
        limits = {
            "lower": robot.q_min[i],
            "upper": robot.q_max[i],
            "velocity": robot.dq_max[i],
            "acceleration": robot.ddq_max[i],
            "effort": robot.tau_max[i],
        }
        finite = [f"{k} = {_f(v)}" for k, v in limits.items() if math.isfinite(v)]
        out += [
            "",
            "[[joints]]",
            f"name = {_s(robot.joint_names[i])}",
            f"type = {_s('prismatic' if robot.prismatic[i] else 'revolute')}",
            f"parent = {_s(robot.link_names[i])}",
            f"child = {_s(robot.link_names[i + 1])}",
            f"origin = {{ xyz = {xyz}, rpy = {rpy} }}",
            f"axis = {_arr(robot.axes[i])}",
        ]
        if finite:
            out.append("limits = { " + ", ".join(finite) + " }")
        if robot.friction is not None:
            out.append(f"friction = {_arr(robot.friction[i])}")
        out += [
            "",
            "[joints.inertial]",
            f"mass = {_f(mass[i])}",
            f"com = {_arr(com[i])}",
            f"inertia = {_arr(inertia6_from_matrix(inertia[i]))}",
        ]
    for name, frame in robot.frames.items():
        T = frame.T_link_frame
        own = name in robot.link_names and robot.link_names.index(name) == frame.link
        if own and name != "flange" and np.array_equal(T, np.eye(4)):
            continue
        xyz, rpy = _xyz_rpy(T)
        out += [
            "",
            "[[frames]]",
            f"name = {_s(name)}",
            f"parent = {_s(robot.link_names[frame.link])}",
            f"xyz = {xyz}",
            f"rpy = {rpy}",
        ]
    return "\n".join(out) + "\n"


def save_toml(path: str | Path, robot: Robot, *, drive: Drive | None = None) -> Path:
    """Write the TOML description of ``robot`` (:func:`toml_from_robot`) to ``path``.

    Parameters
    ----------
    path : str or Path
    robot : Robot
    drive : Drive, optional
        A drive train, written with the robot as a ``[drive]`` table
        (:func:`dynid.io.drive_file.drive_toml`).

    Returns
    -------
    Path
        The path written.
    """
    text = toml_from_robot(robot)
    if drive is not None:
        text = text.rstrip("\n") + "\n\n" + drive_toml(drive)
    return write_text(path, text)


def export_toml(path: str | Path, robot: Robot, options: ExportOptions) -> Path:
    """:func:`save_toml` with the export options' ``drive`` (the entry of ``toml`` in the
    exports; the robot's own sigmoid friction is part of the description)."""
    return save_toml(path, robot, drive=options.drive)
