"""Retrieval bounds as files: the box of every link's mass, CoM and inertia, and the
total-mass band, for any robot, in JSON or TOML (by suffix).

:func:`load_bounds` and :func:`save_bounds` (``dynid retrieve --bounds``); the dictionary
form, :func:`bounds_to_dict`, is also the ``bounds`` entry of ``report.json``::

    {"schema": "dynid-feasibility-bounds/1",
     "total_mass": [16.0, 20.0],            # [kg]; null or []: no band; absent: the default's
     "links": [{"name": "link1",            # a link of the robot (robot.link_names[1:])
                "mass": [0.0, 10.0],         # [kg]
                "com_min": [-0.05, -0.05, -0.4], "com_max": [0.05, 0.05, 0.05],   # [m]
                "inertia_min": [0, -0.5, -0.5, 0, -0.5, 0],                       # [kg m^2]
                "inertia_max": [1, 0.5, 0.5, 1, 0.5, 1]}, ...]}

or in TOML ``total_mass = [16.0, 20.0]`` and one ``[[links]]`` table per link with the same
keys. Every key but ``name`` is optional: what a file leaves out comes from
:func:`dynid.feasibility.bounds.default_bounds` of the robot. Unknown keys are
rejected. Floats are written with Python's shortest round-trip representation.
"""

from __future__ import annotations

from collections.abc import Mapping
from pathlib import Path
from typing import Any

from .. import _checks
from ..exceptions import DataError, ShapeError
from ..feasibility.bounds import Bounds, default_bounds
from ..model.inertia import INERTIA_ORDER
from ..model.robot import Robot
from .atomic import write_text
from .input_files import file_text
from .json_files import load_json
from .schema import Field, Format, Record, check, fault, save_document

__all__ = [
    "BOUNDS_RECORD",
    "BOUNDS_SCHEMA",
    "bounds_from_dict",
    "bounds_to_dict",
    "load_bounds",
    "save_bounds",
]

BOUNDS_SCHEMA = "dynid-feasibility-bounds/1"

_BOUND_KEYS = {"name", "mass", "com_min", "com_max", "inertia_min", "inertia_max"}


def bounds_to_dict(bounds: Bounds) -> dict[str, Any]:
    """A bounds file's content (JSON-ready); link names ``link<i>`` when unnamed."""
    names = bounds.link_names or tuple(f"link{i}" for i in range(1, bounds.n + 1))
    return {
        "schema": BOUNDS_SCHEMA,
        "total_mass": None if bounds.total_mass is None else list(bounds.total_mass),
        "links": [
            {
                "name": names[i],
                "mass": [float(bounds.mass_min[i]), float(bounds.mass_max[i])],
                "com_min": [float(x) for x in bounds.com_min[i]],
                "com_max": [float(x) for x in bounds.com_max[i]],
                "inertia_min": [float(x) for x in bounds.inertia_min[i]],
                "inertia_max": [float(x) for x in bounds.inertia_max[i]],
            }
            for i in range(bounds.n)
        ],
        "units": {
            "mass": "kg",
            "com": "m, link frame",
            "inertia": "kg m^2, about the CoM, link axes, order " + " ".join(INERTIA_ORDER),
            "total_mass": "kg",
        },
    }


#: The unit each ``units`` entry must start with (what follows describes the frame).
_UNITS = {"mass": "kg", "com": "m", "inertia": "kg m^2", "total_mass": "kg"}
_LINK = Record(
    {
        "name": Field("string", required=True),
        "mass": Field("numbers", shape=(2,), unit="kg"),
        "com_min": Field("numbers", shape=(3,), unit="m"),
        "com_max": Field("numbers", shape=(3,), unit="m"),
        "inertia_min": Field("numbers", shape=(6,), unit="kg m^2"),
        "inertia_max": Field("numbers", shape=(6,), unit="kg m^2"),
    }
)
#: a bounds file, JSON or TOML (module docstring)
BOUNDS_RECORD = Record(
    {
        "schema": Field("string", choices=(BOUNDS_SCHEMA,)),
        "total_mass": Field("numbers", nullable=True, unit="kg"),
        "links": Field("objects", nullable=True, record=_LINK),
        "units": Field("object", record=Record({k: Field("string") for k in _UNITS})),
    }
)


def bounds_from_dict(d: Mapping[str, Any], robot: Robot, *, source: str = "bounds") -> Bounds:
    """Bounds for ``robot`` from a bounds file's content; gaps filled from its defaults.

    Raises
    ------
    DataError
        Unknown keys, a link name the robot does not have or listed twice, units other
        than SI, malformed or inconsistent values (lower above upper, negative mass).
    """
    check(d, BOUNDS_RECORD, source)
    for key, value in (d.get("units") or {}).items():
        if value.split(",")[0].strip() != _UNITS[key]:  # "lb" was read as kg
            raise fault(
                source,
                f"units.{key}",
                f"expected {_UNITS[key]!r} (bounds are in SI units); got {_checks.short(value)}",
            )
    base = default_bounds(robot)
    lo, hi = base.lower.copy(), base.upper.copy()
    names = list(robot.link_names[1:])
    guessed = list(base.mass_guessed or (False,) * len(names))
    seen: set[str] = set()
    for k, link in enumerate(d.get("links") or []):
        name = link["name"]
        if name not in names:
            want = f"a link of the robot ({', '.join(names)})"
            raise fault(source, f"links[{k}].name", f"expected {want}; got {_checks.short(name)}")
        if name in seen:
            raise fault(source, f"links[{k}].name", f"expected each link once; got {name!r} again")
        seen.add(name)
        i = names.index(name)
        if "mass" in link:
            lo[i, 0], hi[i, 0] = link["mass"]
            guessed[i] = False
        for key, arr, sl in (
            ("com_min", lo, slice(1, 4)),
            ("com_max", hi, slice(1, 4)),
            ("inertia_min", lo, slice(4, 10)),
            ("inertia_max", hi, slice(4, 10)),
        ):
            if key in link:
                arr[i, sl] = link[key]
    band: Any = base.total_mass
    if "total_mass" in d:
        tm = d["total_mass"]
        if tm is not None and len(tm) not in (0, 2):
            raise fault(
                source,
                "total_mass",
                f"expected [min, max] [kg], [] or null; got {_checks.short(tm)}",
            )
        band = tuple(float(x) for x in tm) if tm else None
    try:
        return Bounds.from_arrays(lo, hi, band, names, guessed)
    except (ValueError, ShapeError) as exc:
        raise DataError(str(exc), file=source) from exc


def load_bounds(path: str | Path, robot: Robot) -> Bounds:
    """Read a bounds file (``.json`` or ``.toml``) for ``robot``; see the module docstring.

    Raises
    ------
    DataError
        Unreadable file, unknown suffix, or content rejected by :func:`bounds_from_dict`.
    """
    path = Path(path)
    suffix = path.suffix.lower()
    if suffix == ".json":
        d = load_json(path)
    elif suffix == ".toml":
        try:
            text = file_text(path)
        except UnicodeDecodeError as exc:
            raise DataError(f"not a UTF-8 text file ({exc.reason})", file=path.name) from None
        d = _checks.parse_toml(text, path.name, DataError)
    else:
        raise DataError(f"bounds files are .json or .toml; got {suffix!r}", file=path.name)
    return bounds_from_dict(d, robot, source=path.name)


def _toml_value(v: Any) -> str:
    if isinstance(v, str):
        return _checks.toml_string(v)
    if isinstance(v, (list, tuple)):
        return "[" + ", ".join(_toml_value(x) for x in v) + "]"
    return repr(float(v))


def save_bounds(path: str | Path, bounds: Bounds) -> Path:
    """Write a bounds file, JSON or TOML by the suffix of ``path``; returns the path."""
    path = Path(path)
    d = bounds_to_dict(bounds)
    if path.suffix.lower() == ".toml":
        band = [] if d["total_mass"] is None else d["total_mass"]  # TOML has no null
        lines = [f"schema = {_toml_value(d['schema'])}", f"total_mass = {_toml_value(band)}"]
        for link in d["links"]:
            lines += ["", "[[links]]"] + [f"{k} = {_toml_value(v)}" for k, v in link.items()]
        return write_text(path, "\n".join(lines) + "\n")
    if path.suffix.lower() != ".json":
        raise DataError(f"bounds files are .json or .toml; got {path.suffix!r}", file=path.name)
    return save_document(path, Format(BOUNDS_SCHEMA, BOUNDS_RECORD, "bounds file"), d)
