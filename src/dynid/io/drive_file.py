"""Drive descriptions in TOML: a file of its own, or a ``[drive]`` table in a robot TOML.

Keys (all optional but ``schema`` in a file of its own; n = the robot's joint count)::

    schema = "dynid-drive/1"
    side = "joint" | "motor"          # what the log's q, dq, ddq, tau columns are (joint)
    gear_ratio = [...]                # n motor turns per joint unit (1; one number: all)
    coupling = [[motor, joint, value], ...]   # 1-based entries of K off the diagonal
    offset = [...]                    # n encoder zero offsets [rad or m], q = K^-1 qm + offset
    effort = "torque" | "current"     # what the tau columns hold (torque)
    torque_constant = [...]           # n [N m / A]: at the motor for side = "motor"
    rotor_inertia = "identify" | [...]  # n [kg m^2] at the motors (identify)
    friction_at = "motor" | "joint"   # where identified friction acts (default below)

Every per-joint list (``gear_ratio``, ``offset``, ``torque_constant``, ``rotor_inertia``)
may be one number, used for every joint (``gear_ratio = 1``: a direct drive).
Without ``friction_at`` the friction identified through the drive acts at the motors when
``K`` is not the identity (else at the joints), and a robot description's own friction
(URDF ``<dynamics>``, MJCF ``damping``/``frictionloss``, a robot TOML's sigmoid per joint),
the joints' by definition, stays at the joints; ``friction_at = "motor"`` given moves that
too to the motors (said in one note), ``friction_at = "joint"`` puts identified friction at
the joints. A model's friction that records its place (``at`` in ``identification.json``,
``feasible.json``, a robot TOML's ``[friction]`` table) acts there whatever the drive says.
``qm = K (q - offset)``, ``dqm = K dq``, ``tau_joint = K^T tau_motor``
(:mod:`dynid.model.drive`). Every fault (an unknown key, a wrong type or length, a singular
``K``, a coupling outside the chain or given twice, currents without constants) is one
:class:`~dynid.exceptions.DataError` naming the file and the key, before anything is computed.
"""

from __future__ import annotations

import dataclasses
import tomllib
from collections.abc import Mapping
from pathlib import Path
from typing import Any

import numpy as np
from numpy.typing import NDArray

from .. import _checks
from ..exceptions import DataError, DynidError
from ..model.drive import DRIVE_SCHEMA, Drive
from .input_files import file_text
from .schema import Field, Record, check, fault

__all__ = [
    "DRIVE_JSON",
    "DRIVE_RECORD",
    "drive_from_mapping",
    "drive_from_record",
    "drive_of_robot_file",
    "drive_toml",
    "load_drive",
    "with_file_rotors",
]

_CHOICES = {
    "side": ("joint", "motor"),
    "effort": ("torque", "current"),
    "friction_at": ("motor", "joint"),
}
_PER_JOINT = Field("any")  # one number for every joint, or one per joint (_vector)
#: a drive description in TOML (module docstring)
DRIVE_RECORD = Record(
    {
        "schema": Field("string", choices=(DRIVE_SCHEMA,)),
        **{k: Field("string", choices=v) for k, v in _CHOICES.items()},
        "gear_ratio": _PER_JOINT,
        "coupling": Field("any"),
        "offset": _PER_JOINT,
        "torque_constant": _PER_JOINT,
        "rotor_inertia": _PER_JOINT,
    }
)
#: the JSON record of a drive (:meth:`~dynid.model.drive.Drive.as_dict`)
DRIVE_JSON = Record(
    {
        "schema": Field("string", required=True, choices=(DRIVE_SCHEMA,)),
        **{k: Field("string", choices=v) for k, v in _CHOICES.items()},
        "transmission": Field("numbers", required=True, shape=("n", "n")),
        "offset": Field("any", nullable=True),
        "torque_constant": Field("any", nullable=True),
        "rotor_inertia": _PER_JOINT,
    }
)


def _vector(
    table: Mapping[str, Any], key: str, n: int, source: str, at: str = ""
) -> NDArray[np.float64]:
    """A list of ``n`` numbers, or one number for every joint (``gear_ratio = 1``); ``at``:
    the key path of ``table`` in ``source``."""
    value = table[key]
    unit = "kg m^2" if key == "rotor_inertia" else ""
    one = Field("numbers", shape=(n,), unit=unit) if isinstance(value, list) else Field("number")
    check({key: value}, Record({key: one}), source, at=at)
    return np.array(value, dtype=float) if isinstance(value, list) else np.full(n, float(value))


def drive_from_mapping(table: Mapping[str, Any], n: int, *, source: str = "drive") -> Drive:
    """A :class:`~dynid.model.drive.Drive` of ``n`` joints from a parsed TOML table.

    Raises
    ------
    DataError
        An unknown key, a wrong type, length or choice (:mod:`dynid.io.schema`), or an
        invalid drive (singular ``K``, currents without torque constants, ...): the message
        names ``source`` and the key.
    """
    check(table, DRIVE_RECORD, source)
    kw: dict[str, Any] = {k: table[k] for k in _CHOICES if k in table}
    gear = _vector(table, "gear_ratio", n, source) if "gear_ratio" in table else np.ones(n)
    entries = _coupling(table.get("coupling", []), n, source)
    for key in ("offset", "torque_constant"):
        if key in table:
            kw[key] = _vector(table, key, n, source)
    ia = table.get("rotor_inertia", "identify")
    if ia != "identify":
        if isinstance(ia, str):
            want = f"'identify', a number or a list of {n} numbers [kg m^2]"
            raise fault(source, "rotor_inertia", f"expected {want}; got {_checks.short(ia)}")
        kw["rotor_inertia"] = _vector(table, "rotor_inertia", n, source)
    try:
        return Drive.from_gears(gear, entries, **kw)
    except DynidError as exc:
        raise DataError(str(exc), file=source) from exc


def _coupling(coupling: Any, n: int, source: str) -> list[tuple[int, int, float]]:
    """The entries of K off the diagonal: ``[motor, joint, value]``, 1-based, each once."""
    want = "a list of [motor, joint, value]"
    if not isinstance(coupling, list):
        raise fault(source, "coupling", f"expected {want}; got {_checks.short(coupling)}")
    entries: list[tuple[int, int, float]] = []
    index = Field("integer", required=True, low=1, high=n)
    entry = Record({"motor": index, "joint": index, "value": Field("number", required=True)})
    for k, e in enumerate(coupling):
        at = f"coupling[{k}]"
        if not isinstance(e, list) or len(e) != 3:
            raise fault(source, at, f"expected [motor, joint, value]; got {_checks.short(e)}")
        check(dict(zip(("motor", "joint", "value"), e, strict=True)), entry, source, at=at)
        m, j = e[0], e[1]
        if m == j:
            raise fault(
                source, at, f"expected motor and joint apart; got {m} and {j}: use gear_ratio"
            )
        if any(x[:2] == (m, j) for x in entries):
            raise fault(
                source, at, f"expected each entry of K once; got motor {m} on joint {j} again"
            )
        entries.append((m, j, float(e[2])))
    return entries


def load_drive(path: str | Path, n: int) -> Drive:
    """The drive of a TOML file: a drive description, or a robot TOML's ``[drive]`` table.

    Parameters
    ----------
    path : str or Path
        ``.toml`` file.
    n : int
        The robot's joint count.

    Raises
    ------
    DataError
        A missing or unreadable file, invalid TOML, a robot TOML without ``[drive]``, or an
        invalid description (:func:`drive_from_mapping`).
    """
    p = Path(path)
    try:
        text = file_text(p)
    except (OSError, UnicodeDecodeError) as exc:
        raise DataError(f"drive file {p}: cannot read ({exc})") from exc
    try:
        doc = tomllib.loads(text)
    except (tomllib.TOMLDecodeError, RecursionError) as exc:
        raise DataError(f"drive file {p.name} is not valid TOML: {str(exc)[:200]}") from None
    if "joints" in doc:  # a robot description
        if "drive" not in doc:
            raise DataError("a robot TOML without a [drive] table", file=p.name)
        return drive_from_mapping(doc["drive"], n, source=f"{p.name} [drive]")
    if "schema" not in doc:
        raise fault(p.name, "schema", f"missing; expected {DRIVE_SCHEMA!r}")
    return drive_from_mapping(doc, n, source=p.name)


def drive_from_record(
    record: Mapping[str, Any], n: int, *, source: str = "drive", at: str = ""
) -> Drive:
    """The drive of a JSON record (:meth:`~dynid.model.drive.Drive.as_dict`: the
    transmission as rows), as identification.json and feasible.json hold it; ``at``: its
    key path in ``source`` (``"drive"``).

    Raises
    ------
    DataError
        A malformed record (the key named, :mod:`dynid.io.schema`).
    """
    check(record, DRIVE_JSON, source, at=at, sizes={"n": n})
    kw: dict[str, Any] = {
        k: _vector(record, k, n, source, at)
        for k in ("offset", "torque_constant")
        if record.get(k) is not None
    }
    if record.get("rotor_inertia", "identify") != "identify":
        kw["rotor_inertia"] = _vector(record, "rotor_inertia", n, source, at)
    kw.update({k: record[k] for k in _CHOICES if k in record})
    kw.setdefault("offset", np.zeros(n))
    try:
        return Drive(transmission=np.array(record["transmission"], dtype=float), **kw)
    except DynidError as exc:
        raise fault(source, at, str(exc)) if at else DataError(str(exc), file=source) from exc


def drive_of_robot_file(spec: str | Path, n: int) -> Drive | None:
    """The ``[drive]`` table of a robot TOML named by ``--robot``, the joints' armature of
    an MJCF (:func:`~dynid.io.robot.mjcf_read.mjcf_drive`), or None (any other robot
    source, or a file without one)."""
    p = Path(spec)
    if p.suffix.lower() == ".xml" and p.is_file():
        from .robot.mjcf_read import mjcf_drive

        return mjcf_drive(p)
    if p.suffix.lower() != ".toml" or not p.is_file():
        return None
    try:
        doc = tomllib.loads(file_text(p))
    except (OSError, DataError, UnicodeDecodeError, tomllib.TOMLDecodeError, RecursionError):
        return None  # the robot reader reports the file's faults
    if "drive" not in doc:
        return None
    return drive_from_mapping(doc["drive"], n, source=f"{p.name} [drive]")


def with_file_rotors(drive: Drive, spec: str | Path, n: int) -> tuple[Drive, str | None]:
    """``drive`` with the rotor inertias the robot file ``spec`` holds when the drive
    leaves them to identify, and the note that says so; else ``drive`` and None.

    A robot description is validated, not identified: its rotor inertias unknown read as
    none (a Panda export of gears 50..100 validated at 19.5 % through its own drive file).
    The file's (an MJCF's ``armature``, a robot TOML's ``[drive]`` table) are taken as the
    joints' ``diag(K_f^T diag(I_f) K_f)`` [kg m^2] and put at the motors of ``drive``:
    ``I_a`` solving ``(K o K)^T I_a = diag(...)`` (``o`` elementwise), exact when ``K`` is
    the file's own (coupled or not); not taken when that gives a negative inertia. A file
    without rotor inertias (a URDF) gets a note that the prediction holds none."""
    if drive.rotor_inertia is not None:
        return drive, None
    held = drive_of_robot_file(spec, n)
    name = Path(spec).name
    if held is None or held.rotor_inertia is None or not np.any(held.rotor_inertia):
        return drive, (
            f"the drive file leaves the rotor inertias to identify and {name} holds none "
            "(a URDF cannot): the prediction holds no rotor inertia; give rotor_inertia "
            "in the drive file"
        )
    at_joints = np.diag(held.rotor_mass_matrix(held.rotor_inertia))
    K = drive.transmission
    ia = np.linalg.solve((K * K).T, at_joints)
    what = "armature" if Path(spec).suffix.lower() == ".xml" else "[drive] rotor inertias"
    if np.any(ia < -1e-9 * float(np.max(at_joints))):
        return drive, (
            f"the drive file leaves the rotor inertias to identify and {name}'s {what} "
            "give a negative one at its motors: the prediction holds no rotor inertia"
        )
    ia = np.clip(ia, 0.0, None)
    said = (
        f"the drive file leaves the rotor inertias to identify: {name}'s {what} are taken, "
        "at its motors " + " ".join(f"{x:.4g}" for x in ia) + " kg m^2"
    )
    return dataclasses.replace(drive, rotor_inertia=ia), said


def drive_toml(drive: Drive) -> str:
    """The drive as a ``[drive]`` TOML table (gear ratios and coupling entries), which
    :func:`load_drive` reads back to the same drive (floats as ``repr``)."""
    K = drive.transmission
    n = drive.n

    def vec(v: Any) -> str:
        return "[" + ", ".join(repr(float(x)) for x in v) + "]"

    off = [(i, j) for i in range(n) for j in range(n) if i != j and K[i, j] != 0.0]
    lines = [
        "[drive]",
        f'schema = "{DRIVE_SCHEMA}"',
        f'side = "{drive.side}"',
        f'effort = "{drive.effort}"',
        f"gear_ratio = {vec(np.diag(K))}",
        "coupling = [" + ", ".join(f"[{i + 1}, {j + 1}, {float(K[i, j])!r}]" for i, j in off) + "]",
        f"offset = {vec(drive.offset)}",
    ]
    if drive.friction_at is not None:  # as given: a default place stays a default
        lines.append(f'friction_at = "{drive.friction_at}"')
    if drive.torque_constant is not None:
        lines.append(f"torque_constant = {vec(drive.torque_constant)}")
    ia = drive.rotor_inertia
    lines.append('rotor_inertia = "identify"' if ia is None else f"rotor_inertia = {vec(ia)}")
    return "\n".join(lines) + "\n"
