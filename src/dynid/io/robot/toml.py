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
``mass``, ``com`` and ``inertia`` about the CoM); optional ``[[frames]]``; an optional
``[spring]`` table, ``k`` [N m/rad] and ``q0`` [rad] per joint (the joint springs a
consistent fit identified, ``tau_s = k (q - q0)``: :mod:`dynid.io.spring_record`). The full schema,
with an annotated example, is in ``docs/robot-description.md``.

The keys are declared once (:data:`ROBOT_TOML`) and checked by the one strict codec of
dynid's files (:mod:`dynid.io.schema`): unknown keys are rejected, so that a misspelt key
does not silently fall back to a default; numbers must be finite TOML numbers (never booleans
or strings; ``inf`` only for a limit), a mass outside ``[0, MAX_LINK_MASS]`` and an offset
beyond ``MAX_LINK_OFFSET`` are refused; so is an axis of a squared length beyond the float
range. Every error is one line in the codec's wording naming the file and the key path:
``robot.toml: key 'joints[1].limits.velocity': expected a number > 0; got 0.0``.
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
from ..._checks import caller_level
from ...exceptions import DataError, DynidError, DynidWarning, ModelError
from ...friction.model import (
    Friction,
    FrictionSum,
    SigmoidFriction,
    robot_friction,
    sigmoid_parameters,
)
from ...model.drive import Drive
from ...model.inertia import (
    READ_AS_GIVEN,
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
from ..schema import Field, Record, check, fault
from ..spring_record import SPRING_FIELD, spring_from_record, spring_record
from .export_options import ExportOptions, with_caveat
from .toml_friction import FRICTION_TABLE, friction_tables, table_friction

__all__ = [
    "FORMAT_VERSION",
    "ROBOT_TOML",
    "export_toml",
    "load_toml",
    "robot_from_toml_string",
    "save_toml",
    "toml_from_robot",
]

#: Version of the schema written by :func:`toml_from_robot`.
FORMAT_VERSION = 1

_L = MAX_LINK_OFFSET
_XYZ = Field("numbers", shape=(3,), low=-_L, high=_L, unit="m")
_RPY = Field("numbers", shape=(3,), unit="rad")
_MDH = Record(
    {
        "a": Field("number", required=True, low=-_L, high=_L, unit="m"),
        "d": Field("number", required=True, low=-_L, high=_L, unit="m"),
        "alpha": Field("number", required=True, unit="rad"),
        "theta": Field("number", unit="rad"),
    }
)
_LIMIT = Field("number", infinite=True, unit="rad or m")
_RATE = Field("number", infinite=True, low=0.0)
_LIMITS = Record(
    {
        "lower": _LIMIT,
        "upper": _LIMIT,
        "velocity": _RATE,
        "acceleration": _RATE,
        "effort": _RATE,
    }
)
_INERTIAL = Record(
    {
        "mass": Field("number", required=True, low=0.0, high=MAX_LINK_MASS, unit="kg"),
        "com": Field("numbers", required=True, shape=(3,), low=-_L, high=_L, unit="m"),
        "inertia": Field("numbers", required=True, shape=(6,), unit="kg m^2"),
    }
)
_TYPES = {"revolute": False, "prismatic": True}
_JOINT = Record(
    {
        "name": Field("string", required=True, non_empty=True),
        "type": Field("string", required=True, choices=tuple(_TYPES)),
        "parent": Field("string", required=True, non_empty=True),
        "child": Field("string", required=True, non_empty=True),
        "origin": Field("object", record=Record({"xyz": _XYZ, "rpy": _RPY})),
        "mdh": Field("object", record=_MDH),
        "axis": Field("numbers", shape=(3,)),
        "limits": Field("object", record=_LIMITS),
        "friction": Field("numbers", shape=(3,)),
        "inertial": Field("object", record=_INERTIAL),
    }
)
_FRAME = Record(
    {
        "name": Field("string", required=True, non_empty=True),
        "parent": Field("string", required=True, non_empty=True),
        "xyz": _XYZ,
        "rpy": _RPY,
        "mdh": Field("object", record=_MDH),
    }
)
#: The robot description's keys (module docstring; ``n`` the joint count), checked by the
#: one strict codec (:func:`dynid.io.schema.check`). ``[drive]`` is read by
#: :func:`dynid.io.drive_file.load_drive`, not here.
ROBOT_TOML = Record(
    {
        "format_version": Field("integer", choices=(FORMAT_VERSION,)),
        "name": Field("string"),
        "gravity": Field("numbers", shape=(3,), unit="m/s^2"),
        "q_neutral": Field("numbers", shape=("n",), unit="rad or m"),
        "joints": Field("objects", required=True, non_empty=True, shape=("n",), record=_JOINT),
        "frames": Field("objects", record=_FRAME),
        "drive": Field("any"),
        "friction": FRICTION_TABLE,
        "joint_friction": FRICTION_TABLE,
        "spring": SPRING_FIELD,
    }
)
#: Rate limits: ``limits.velocity`` [rad/s or m/s], ``acceleration``, ``effort`` [N m or N].
_RATES = ("velocity", "acceleration", "effort")


# ---------------------------------------------------------------------- reading helpers
def _vector(value: Any, default: Sequence[float]) -> NDArray[np.float64]:
    return np.array(default if value is None else value, dtype=np.float64)


def _pose(table: Mapping[str, Any], source: str, at: str, *, nested: bool) -> NDArray[np.float64]:
    """Pose (4, 4) from ``xyz``/``rpy`` (in ``origin = {...}`` when ``nested``) or ``mdh``
    (the table checked already)."""
    origin_keys = ("origin",) if nested else ("xyz", "rpy")
    if "mdh" in table:
        given = [k for k in origin_keys if k in table]
        if given:
            what = " and ".join(repr(k) for k in given)
            raise fault(source, f"{at}.mdh", f"give either {what} or 'mdh', not both")
        mdh = table["mdh"]
        return mdh_transform(mdh["a"], mdh["d"], mdh["alpha"], mdh.get("theta", 0.0))
    origin = table.get("origin", {}) if nested else table
    xyz = _vector(origin.get("xyz"), (0.0, 0.0, 0.0))
    rpy = _vector(origin.get("rpy"), (0.0, 0.0, 0.0))
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


def _axis(jt: Mapping[str, Any], source: str, at: str) -> NDArray[np.float64]:
    """The joint axis (3,) as given (the robot normalises it); zero or overflowing refused."""
    axis = _vector(jt.get("axis"), (0.0, 0.0, 1.0))
    with np.errstate(over="ignore"):
        norm = float(np.linalg.norm(axis))
    if norm < 1e-12:
        raise fault(source, f"{at}.axis", f"expected a non-zero axis; got {axis.tolist()}")
    if not math.isfinite(norm):
        raise fault(
            source,
            f"{at}.axis",
            f"{axis.tolist()} is too large to normalise (its squared length overflows a "
            "float); give the axis as a unit vector",
        )
    return axis


def _limits(jt: Mapping[str, Any], source: str, at: str) -> dict[str, float]:
    """``lower``, ``upper``, ``velocity``, ``acceleration``, ``effort`` (inf where none)."""
    lim = {"lower": -math.inf, "upper": math.inf} | dict.fromkeys(_RATES, math.inf)
    lim |= {k: float(v) for k, v in jt.get("limits", {}).items()}
    for k in _RATES:
        if not lim[k] > 0.0:
            raise fault(source, f"{at}.limits.{k}", f"expected a number > 0; got {lim[k]!r}")
    if not lim["lower"] < lim["upper"]:
        raise fault(
            source,
            f"{at}.limits.lower",
            f"expected a number below 'limits.upper'; got {lim['lower']!r} >= {lim['upper']!r}",
        )
    return lim


def _inertial(
    jt: Mapping[str, Any], source: str, at: str
) -> tuple[float, NDArray[np.float64], NDArray[np.float64]]:
    """Mass [kg], CoM [m] (3,) and inertia about the CoM (6,) of ``[joints.inertial]``."""
    if "inertial" not in jt:
        return 0.0, np.zeros(3), np.zeros(6)
    inertial = jt["inertial"]
    mass = float(inertial["mass"])
    com, inertia = _vector(inertial["com"], ()), _vector(inertial["inertia"], ())
    problems = inertial_problems(mass, matrix_from_inertia6(inertia))
    if problems:  # as the URDF reader: kept, as a real description may round its numbers
        warnings.warn(
            f"{source}: key '{at}.inertial': the inertial is physically inconsistent: "
            f"{'; '.join(problems)}; {READ_AS_GIVEN}",
            DynidWarning,
            stacklevel=caller_level(),
        )
    return mass, com, inertia


def _joint_row(jt: Mapping[str, Any], source: str, at: str) -> _JointRow:
    """The joint table at ``at`` (checked by the codec) as a row."""
    T, axis, limits = (
        _pose(jt, source, at, nested=True),
        _axis(jt, source, at),
        _limits(jt, source, at),
    )
    mass, com, inertia = _inertial(jt, source, at)
    friction = _vector(jt["friction"], ()) if "friction" in jt else None
    return _JointRow(
        jt["name"],
        jt["parent"],
        jt["child"],
        T,
        axis,
        _TYPES[jt["type"]],
        limits,
        mass,
        com,
        inertia,
        friction,
    )


def _joint_rows(joints: list[Any], source: str) -> list[_JointRow]:
    """Every joint, checked to form a chain and to give friction for all joints or none."""
    rows: list[_JointRow] = []
    for i, jt in enumerate(joints):
        row = _joint_row(jt, source, f"joints[{i}]")
        if rows and row.parent != rows[-1].child:
            raise fault(
                source,
                f"joints[{i}].parent",
                f"unknown parent {row.parent!r}; joints must form a chain, so the parent must "
                f"be the previous joint's child {rows[-1].child!r}",
            )
        rows.append(row)
    given = [r.friction is not None for r in rows]
    if any(given) and not all(given):
        i = given.index(False)
        raise fault(
            source,
            f"joints[{i}].friction",
            f"missing; it is given for joint {rows[given.index(True)].name!r}: give it for "
            "every joint or for none",
        )
    return rows


def _frames(doc: Mapping[str, Any], source: str, link_names: list[str]) -> dict[str, Frame]:
    """The ``[[frames]]``, each fixed to a link or to an earlier frame."""
    frames: dict[str, Frame] = {}
    for i, ft in enumerate(doc.get("frames", [])):
        at, fname, parent = f"frames[{i}]", ft["name"], ft["parent"]
        if fname in frames:
            raise fault(source, f"{at}.name", f"duplicate frame name {fname!r}")
        if parent in link_names:
            link, T_link_parent = link_names.index(parent), np.eye(4)
        elif parent in frames:
            link, T_link_parent = frames[parent].link, frames[parent].T_link_frame
        else:
            raise fault(
                source,
                f"{at}.parent",
                f"unknown parent {parent!r}; available: links {link_names} and earlier "
                f"frames {list(frames)}",
            )
        frames[fname] = Frame(link, T_link_parent @ _pose(ft, source, at, nested=False))
    return frames


def robot_from_toml_string(text: str, *, source: str = "TOML text") -> Robot:
    """Robot from the text of a dynid TOML description (schema: see the module docstring).

    Parameters
    ----------
    text : str
        The TOML document.
    source : str
        Name of the document used in error messages (a file name, say).

    Returns
    -------
    Robot
        With the joints' sigmoid ``friction`` as a ``dynid.SigmoidFriction`` (none when
        the description gives none), and the ``[spring]`` table as its ``spring``.

    Raises
    ------
    DataError
        The text is not valid TOML, or a key is missing, unknown, of the wrong type, length
        or out of its limits (:data:`ROBOT_TOML`, checked by :func:`dynid.io.schema.check`),
        a joint's parent is not the previous joint's child, a frame's parent is unknown,
        names repeat, or the robot is otherwise invalid (limits, axes); one line
        ``SOURCE: key 'joints[0].limits.lower': ...`` naming the key.
    """
    doc = _checks.parse_toml(text, source, DataError)
    joints = doc.get("joints")
    check(doc, ROBOT_TOML, source, sizes={"n": len(joints)} if isinstance(joints, list) else {})
    rows = _joint_rows(doc["joints"], source)
    link_names = [rows[0].parent] + [r.child for r in rows]
    frames = _frames(doc, source, link_names)
    lim = {k: np.array([r.limits[k] for r in rows]) for k in ("lower", "upper", *_RATES)}
    sigmoid = [r.friction for r in rows if r.friction is not None]
    law = table_friction(doc, len(rows), source)
    try:
        return Robot(
            name=doc.get("name", "robot"),
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
            gravity=_vector(doc.get("gravity"), (0.0, 0.0, -STANDARD_GRAVITY)),
            frames=frames,
            friction=SigmoidFriction.from_array(np.stack(sigmoid)) if sigmoid else law,
            q_neutral=_vector(doc["q_neutral"], ()) if "q_neutral" in doc else None,
            spring=spring_from_record(doc.get("spring")),
        )
    except DynidError as exc:
        raise DataError(str(exc), file=source) from exc


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
        The file does not exist or cannot be read.
    DataError
        The file is not valid TOML or does not follow the schema
        (:func:`robot_from_toml_string`; the message starts with the file's name).
    """
    p = Path(path)
    try:
        text = file_text(p)
    except FileNotFoundError as exc:
        raise ModelError(f"TOML description not found: {str(p)!r}") from exc
    except (OSError, UnicodeDecodeError) as exc:
        raise ModelError(f"cannot read TOML description {str(p)!r}: {exc}") from exc
    return robot_from_toml_string(text, source=p.name)


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


def toml_from_robot(
    robot: Robot,
    *,
    drive: Drive | None = None,
    friction: Friction | FrictionSum | None = None,
) -> str:
    """The dynid TOML description of a robot (schema: see the module docstring).

    Joint origins are written as ``origin = {xyz, rpy}``, inertials as mass, CoM and
    inertia about the CoM, finite limits only, friction when the robot has a friction
    model, and every frame except the links' own frames (``flange`` always). Floats are
    written with ``repr``, so :func:`robot_from_toml_string` gives back the same robot to
    about 1e-15 (the inertia about the CoM and the rpy angles are recomputed).

    Parameters
    ----------
    robot : Robot
    drive : Drive, optional
        A drive train, written as a ``[drive]`` table
        (:func:`dynid.io.drive_file.drive_toml`); default: the drive a friction at the
        motors acts through, if any.
    friction : Friction or FrictionSum, optional
        Written instead of the robot's own (the friction identified with the links; a sum
        of friction at the motors and at the joints as ``[friction]`` and
        ``[joint_friction]``, :mod:`dynid.io.robot.toml_friction`).

    Returns
    -------
    text : str
        The TOML document.

    Another law than the sigmoid at the joints (the friction identified with the links,
    say) is the ``[friction]`` table (:mod:`dynid.io.robot.toml_friction`); with friction
    at the motors, the drive it acts through is needed beside it (:func:`save_toml`).
    """
    held = robot_friction(robot) if friction is None else friction
    if isinstance(held, FrictionSum) or held is not robot.friction:
        robot = robot.with_friction(None if isinstance(held, FrictionSum) else held)
    sigmoid = sigmoid_parameters(held)
    if drive is None and held is not None and held.drive is not None:
        # the drive the friction acts through (none for a friction that only holds its
        # place at the joints: the identity drive, which a description leaves out)
        drive = None if held.drive.is_bare else held.drive
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
        if sigmoid is not None:
            out.append(f"friction = {_arr(sigmoid[i])}")
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
    if robot.spring is not None:  # a table of its own, after the arrays of tables
        rec = spring_record(robot.spring)
        out += ["", "[spring]", f"k = {_arr(rec['k'])}", f"q0 = {_arr(rec['q0'])}"]
    text = "\n".join(out) + "\n"
    tables = friction_tables(held)
    text = text if not tables else text + "\n" + tables
    return text if drive is None else text + "\n" + drive_toml(drive)


def save_toml(
    path: str | Path,
    robot: Robot,
    *,
    drive: Drive | None = None,
    friction: Friction | FrictionSum | None = None,
    caveat: str | None = None,
) -> Path:
    """Write the TOML description of ``robot`` (:func:`toml_from_robot`) to ``path``.

    Parameters
    ----------
    path : str or Path
    robot : Robot
    drive, friction
        As :func:`toml_from_robot`.
    caveat : str, optional
        A comment at the top of the file: why the fit was not accepted.

    Returns
    -------
    Path
        The path written.
    """
    text = toml_from_robot(robot, drive=drive, friction=friction)
    return write_text(path, with_caveat(text, caveat, xml=False))


def export_toml(path: str | Path, robot: Robot, options: ExportOptions) -> Path:
    """:func:`save_toml` with the export options' ``drive`` and ``friction`` (the entry of
    ``toml`` in the exports): ``True`` the robot's own friction, ``False`` none, a friction
    model (the one identified with the links) written in its place."""
    f, caveat = options.friction, options.caveat
    if f is True:
        return save_toml(path, robot, drive=options.drive, caveat=caveat)
    held = robot if f else robot.with_friction(None)
    return save_toml(path, held, drive=options.drive, friction=f or None, caveat=caveat)
