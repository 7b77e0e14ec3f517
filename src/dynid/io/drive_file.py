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
    friction_at = "motor" | "joint"   # default motor when K is not the identity

Every per-joint list (``gear_ratio``, ``offset``, ``torque_constant``, ``rotor_inertia``)
may be one number, used for every joint (``gear_ratio = 1``: a direct drive).
``qm = K (q - offset)``, ``dqm = K dq``, ``tau_joint = K^T tau_motor``
(:mod:`dynid.model.drive`). Every fault (an unknown key, a wrong type or length, a singular
``K``, a coupling outside the chain or given twice, currents without constants) is one
:class:`~dynid.exceptions.DataError` naming the file and the key, before anything is computed.
"""

from __future__ import annotations

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

__all__ = [
    "drive_from_mapping",
    "drive_from_record",
    "drive_of_robot_file",
    "drive_toml",
    "load_drive",
]

_KEYS = {
    "schema",
    "side",
    "gear_ratio",
    "coupling",
    "offset",
    "effort",
    "torque_constant",
    "rotor_inertia",
    "friction_at",
}
_CHOICES = {
    "side": ("joint", "motor"),
    "effort": ("torque", "current"),
    "friction_at": ("motor", "joint"),
}


def _number(value: Any, where: str) -> float:
    return _checks.number(value, where, DataError)


def _vector(table: Mapping[str, Any], key: str, n: int, where: str) -> NDArray[np.float64]:
    """A list of ``n`` numbers, or one number for every joint (``gear_ratio = 1``)."""
    value = table[key]
    if isinstance(value, int | float) and not isinstance(value, bool):
        return np.full(n, _number(value, f"{where}: {key}"))
    if not isinstance(value, list) or len(value) != n:
        got = f"{len(value)} entries" if isinstance(value, list) else _checks.short(value)
        raise DataError(
            f"{where}: key {key!r} must be a number or a list of {n} numbers (one per "
            f"joint); got {got}"
        )
    return np.array([_number(v, f"{where}: {key}[{k}]") for k, v in enumerate(value)])


def drive_from_mapping(table: Mapping[str, Any], n: int, *, source: str = "drive") -> Drive:
    """A :class:`~dynid.model.drive.Drive` of ``n`` joints from a parsed TOML table.

    Raises
    ------
    DataError
        An unknown key, a wrong type, length or choice, or an invalid drive (singular ``K``,
        currents without torque constants, ...): the message names ``source`` and the key.
    """
    if not isinstance(table, Mapping):
        raise DataError(f"{source} must be a table; got {type(table).__name__}")
    unknown = sorted(set(table) - _KEYS)
    if unknown:
        raise DataError(f"{source}: unknown key {unknown[0]!r}; allowed: {sorted(_KEYS)}")
    schema = table.get("schema", DRIVE_SCHEMA)
    if schema != DRIVE_SCHEMA:
        raise DataError(
            f"{source}: key 'schema' must be {DRIVE_SCHEMA!r}; got {_checks.short(schema)}"
        )
    kw: dict[str, Any] = {}
    for key, allowed in _CHOICES.items():
        if key in table:
            if table[key] not in allowed:
                got = _checks.short(table[key])
                raise DataError(f"{source}: key {key!r} must be one of {list(allowed)}; got {got}")
            kw[key] = table[key]
    gear = _vector(table, "gear_ratio", n, source) if "gear_ratio" in table else np.ones(n)
    coupling = table.get("coupling", [])
    if not isinstance(coupling, list):
        raise DataError(f"{source}: key 'coupling' must be a list of [motor, joint, value]")
    entries: list[tuple[int, int, float]] = []
    for k, entry in enumerate(coupling):
        where = f"{source}: coupling[{k}]"
        if not isinstance(entry, list) or len(entry) != 3:
            raise DataError(f"{where} must be [motor, joint, value]; got {_checks.short(entry)}")
        m, j = entry[0], entry[1]
        for what, idx in (("motor", m), ("joint", j)):
            if isinstance(idx, bool) or not isinstance(idx, int) or not 1 <= idx <= n:
                raise DataError(
                    f"{where}: {what} must be an integer in 1..{n} (1-based, the robot has "
                    f"{n} joints); got {_checks.short(idx)}"
                )
        if m == j:
            raise DataError(f"{where}: motor {m} on joint {j} is the gear ratio; use gear_ratio")
        if any(e[:2] == (m, j) for e in entries):
            raise DataError(
                f"{where}: motor {m} on joint {j} is given twice; give each entry of K once"
            )
        entries.append((m, j, _number(entry[2], f"{where}: value")))
    for key in ("offset", "torque_constant"):
        if key in table:
            kw[key] = _vector(table, key, n, source)
    ia = table.get("rotor_inertia", "identify")
    if ia != "identify":
        if isinstance(ia, str):
            raise DataError(
                f"{source}: key 'rotor_inertia' must be 'identify', a number or a list of {n} "
                f"numbers [kg m^2]; got {_checks.short(ia)}"
            )
        kw["rotor_inertia"] = _vector(table, "rotor_inertia", n, source)
    try:
        return Drive.from_gears(gear, entries, **kw)
    except DynidError as exc:
        raise DataError(f"{source}: {exc}") from exc


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
            raise DataError(f"{p.name}: a robot TOML without a [drive] table")
        return drive_from_mapping(doc["drive"], n, source=f"{p.name} [drive]")
    if "schema" not in doc:
        raise DataError(f"{p.name}: missing key 'schema' (expected {DRIVE_SCHEMA!r})")
    return drive_from_mapping(doc, n, source=p.name)


def drive_from_record(record: Mapping[str, Any], n: int) -> Drive:
    """The drive of a JSON record (:meth:`~dynid.model.drive.Drive.as_dict`: the
    transmission as rows), as identification.json and feasible.json hold it.

    Raises
    ------
    DataError
        A malformed record (the field is named).
    """
    if not isinstance(record, Mapping) or record.get("schema") != DRIVE_SCHEMA:
        raise DataError(f"drive: must be an object with schema {DRIVE_SCHEMA!r}")
    K = record.get("transmission")
    if (
        not isinstance(K, list)
        or len(K) != n
        or any(not isinstance(row, list) or len(row) != n for row in K)
    ):
        raise DataError(f"drive: 'transmission' must be {n} rows of {n} numbers")
    rows = [
        [_number(x, f"drive: transmission[{i}][{j}]") for j, x in enumerate(row)]
        for i, row in enumerate(K)
    ]
    table = {k: record[k] for k in ("offset", "torque_constant") if record.get(k) is not None}
    kw: dict[str, Any] = {k: _vector(table, k, n, "drive") for k in table}
    ia = record.get("rotor_inertia", "identify")
    if ia != "identify":
        kw["rotor_inertia"] = _vector({"rotor_inertia": ia}, "rotor_inertia", n, "drive")
    for key in _CHOICES:
        if key in record:
            kw[key] = record[key]
    kw.setdefault("offset", np.zeros(n))
    try:
        return Drive(transmission=np.array(rows), **kw)
    except DynidError as exc:
        raise DataError(f"drive: {exc}") from exc


def drive_of_robot_file(spec: str | Path, n: int) -> Drive | None:
    """The ``[drive]`` table of a robot TOML named by ``--robot``, or None (any other robot
    source, or a TOML without one)."""
    p = Path(spec)
    if p.suffix.lower() != ".toml" or not p.is_file():
        return None
    try:
        doc = tomllib.loads(file_text(p))
    except (OSError, DataError, UnicodeDecodeError, tomllib.TOMLDecodeError, RecursionError):
        return None  # the robot reader reports the file's faults
    if "drive" not in doc:
        return None
    return drive_from_mapping(doc["drive"], n, source=f"{p.name} [drive]")


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
        f'friction_at = "{drive.friction_at}"',
    ]
    if drive.torque_constant is not None:
        lines.append(f"torque_constant = {vec(drive.torque_constant)}")
    ia = drive.rotor_inertia
    lines.append('rotor_inertia = "identify"' if ia is None else f"rotor_inertia = {vec(ia)}")
    return "\n".join(lines) + "\n"
