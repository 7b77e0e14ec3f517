"""Feasible link parameters, retrieval reports and retrieval bounds as files.

**feasible.json** (:func:`save_feasible_json`, :func:`load_feasible_json`): the
parameters of every moving link, in the schema of the robot description's inertials
(:mod:`dynid.io.robot.toml`): ``mass`` [kg], ``com`` [m] in the link frame,
``inertia`` ``[xx, xy, xz, yy, yz, zz]`` [kg m^2] **about the CoM**, link-frame axes.
It also holds the robot's kinematics (:mod:`dynid.io.robot_json`) and its sigmoid
friction, so that it loads back as a complete :class:`~dynid.model.robot.Robot`::

    {"schema": "dynid-feasible-parameters/1", "dynid_version": ..., "name": ...,
     "links": [{"name": "link1", "mass": 4.97, "com": [...], "inertia": [...]}, ...],
     "friction": null | {"model": "sigmoid", "phi1": [...], "phi2": [...], "phi3": [...]},
     "linear_friction": null | {"model": "classical", "fv": [...], "fc": [...], "fo": [...]},
     "drive": null | {dynid-drive/1 record, rotor_inertia: the identified values},
     "kinematics": {...}, "feasible": true, "relative_residual": ..., "seed": ...,
     "units": {...}, "conventions": {...}}

**report.json** (:func:`report_to_dict`, :func:`save_report_json`): the relative residual
on the coefficients, every constraint with its margin, the stage costs, the run time, the
seed, the options, the bounds and a summary of every run.

**Bounds files** (:func:`load_bounds`, :func:`save_bounds`), JSON or TOML (by suffix),
for any robot::

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

import json
from collections.abc import Mapping
from pathlib import Path
from typing import Any

import numpy as np

from .. import __version__, _checks
from ..exceptions import DataError, ModelError, ShapeError
from ..feasibility.bounds import Bounds, default_bounds
from ..feasibility.constraints import FeasibilityReport
from ..feasibility.retrieve import RetrievalResult
from ..feasibility.sdp import ConsistentResult
from ..friction.model import ClassicalFriction, DriveFriction
from ..model.drive import Drive
from ..model.inertia import INERTIA_ORDER, inertia6_from_matrix, inertial_from_phi
from ..model.robot import Robot
from .atomic import write_text
from .drive_file import drive_from_record
from .json_files import finite_or_none, load_json, save_json
from .robot_json import robot_from_dict, robot_to_dict

__all__ = [
    "BOUNDS_SCHEMA",
    "FEASIBLE_SCHEMA",
    "REPORT_SCHEMA",
    "bounds_from_dict",
    "bounds_to_dict",
    "feasible_to_dict",
    "load_bounds",
    "consistent_report_to_dict",
    "load_feasible_json",
    "load_feasible_drive",
    "load_feasible_linear_friction",
    "report_to_dict",
    "robot_from_feasible_dict",
    "save_bounds",
    "save_feasible_json",
    "save_report_json",
]

FEASIBLE_SCHEMA = "dynid-feasible-parameters/1"
REPORT_SCHEMA = "dynid-feasibility-report/1"
BOUNDS_SCHEMA = "dynid-feasibility-bounds/1"

_UNITS = {"mass": "kg", "com": "m", "inertia": "kg m^2"}
_CONVENTIONS = {
    "com": "centre of mass in the link frame",
    "inertia": "about the CoM, link-frame axes, order " + " ".join(INERTIA_ORDER),
    "friction": "tau_f = phi1/(1+exp(-phi2 (dq+phi3))) - phi1/(1+exp(-phi2 phi3)) "
    "[phi1 N m, phi2 s/rad, phi3 rad/s] (Gaz et al. 2019, eq. 25)",
}
_LINK_KEYS = {"name", "mass", "com", "inertia"}
_BOUND_KEYS = {"name", "mass", "com_min", "com_max", "inertia_min", "inertia_max"}


def _write_json(path: str | Path, d: Mapping[str, Any]) -> Path:
    return save_json(path, d)


def _read_json(path: str | Path) -> dict[str, Any]:
    return load_json(path)


# ------------------------------------------------------------------ feasible parameters
def feasible_to_dict(source: Any, *, seed: int | None = None) -> dict[str, Any]:
    """The link parameters (and kinematics, friction) of a retrieval result or a robot.

    Parameters
    ----------
    source : RetrievalResult, ConsistentResult or Robot
        A result also records ``method``, ``feasible``, ``relative_residual`` and its seed;
        a consistent identification from a torque log its classical friction
        (``linear_friction``: ``fv, fc >= 0`` identified with the links; per motor with a
        drive whose friction acts at the motors), and with a drive its record (``drive``,
        the identified rotor inertias [kg m^2] in ``rotor_inertia``).
    seed : int, optional
        Recorded when ``source`` is a Robot.
    """
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
    lin = getattr(source, "friction", None) if not isinstance(source, Robot) else None
    d: dict[str, Any] = {
        "schema": FEASIBLE_SCHEMA,
        "dynid_version": __version__,
        "name": robot.name,
        "links": links,
        "friction": fr,
        "linear_friction": None
        if lin is None
        else {"model": "classical"}
        | {k: [float(x) for x in np.asarray(lin)[:, j]] for j, k in enumerate(("fv", "fc", "fo"))},
        "kinematics": robot_to_dict(robot),
        "units": _UNITS,
        "conventions": _CONVENTIONS,
    }
    drive = getattr(source, "drive", None) if not isinstance(source, Robot) else None
    d["drive"] = None if drive is None else drive.as_dict()
    if not isinstance(source, Robot):
        d["method"] = getattr(source, "method", "penalty")
        d["feasible"] = bool(source.feasible)
        d["relative_residual"] = finite_or_none(source.relative_residual)
        d["seed"] = source.seed
        ho = getattr(source, "heldout", None)
        if ho is not None:
            d["heldout"] = ho.as_dict()
    elif seed is not None:
        d["seed"] = seed
    return d


def save_feasible_json(path: str | Path, source: Any) -> Path:
    """Write ``feasible.json`` (see :func:`feasible_to_dict`); returns the path."""
    return _write_json(path, feasible_to_dict(source))


def _vec(v: Any, size: int, where: str) -> np.ndarray:
    """A list of ``size`` finite numbers, strictly (a boolean or a string is refused)."""
    if not isinstance(v, list | tuple) or len(v) != size:
        raise DataError(f"{where} must be a list of {size} numbers; got {_checks.short(v)}")
    return np.array([_checks.number(x, f"{where}[{k}]", DataError) for k, x in enumerate(v)])


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
        Wrong schema, missing or malformed field, link names that do not match ``robot``.
    """
    if d.get("schema") != FEASIBLE_SCHEMA:
        raise DataError(
            f"not a feasible-parameter file (schema {d.get('schema')!r}, "
            f"expected {FEASIBLE_SCHEMA!r})"
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
                    [_vec(fr[f"phi{k}"], robot.n, f"friction phi{k}") for k in (1, 2, 3)], axis=1
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
            mass[i] = _vec([link["mass"]], 1, f"{where} mass")[0]
            com[i] = _vec(link["com"], 3, f"{where} com")
            I6[i] = _vec(link["inertia"], 6, f"{where} inertia")
        except KeyError as exc:
            raise DataError(f"{where}: missing {exc.args[0]!r}") from None
    try:
        return robot.with_inertials(mass, com, I6)
    except (ModelError, ShapeError) as exc:
        raise DataError(f"feasible parameters: {exc}") from exc


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
        return robot_from_feasible_dict(_read_json(path), robot)
    except DataError as exc:
        name = Path(path).name
        if str(exc).startswith(name):
            raise
        raise DataError(f"{name}: {exc}") from exc


def load_feasible_linear_friction(path: str | Path) -> ClassicalFriction | DriveFriction | None:
    """The classical friction (``fv, fc, fo`` per joint) held by ``feasible.json``, or None.

    Written by a consistent identification from a torque log; ``dynid validate --params``
    uses it unless another friction is given. With a drive whose friction acts at the
    motors, the law per motor mapped through the transmission (:class:`DriveFriction`).
    """
    d = _read_json(path)
    lin = d.get("linear_friction")
    if lin is None:
        return None
    name = Path(path).name
    try:
        n = len(d["links"])
        law = ClassicalFriction(
            *(_vec(lin[k], n, f"{name}: linear_friction {k}") for k in ("fv", "fc", "fo"))
        )
    except (KeyError, TypeError):
        raise DataError(f"{name}: linear_friction needs fv, fc, fo per joint") from None
    drive = load_feasible_drive(path)
    return DriveFriction(law, drive) if drive is not None and drive.friction_at == "motor" else law


def load_feasible_drive(path: str | Path) -> Drive | None:
    """The drive train held by ``feasible.json`` (its rotor inertias the identified ones), or
    None."""
    d = _read_json(path)
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


# ------------------------------------------------------------------------ the report
def _report_constraints(report: FeasibilityReport) -> list[dict[str, Any]]:
    return [
        {
            "name": c.name,
            "link": c.link,
            "margin": finite_or_none(c.margin),
            "unit": c.unit,
            "satisfied": bool(c.satisfied),
        }
        for c in report.constraints
    ]


def report_to_dict(result: RetrievalResult) -> dict[str, Any]:
    """Everything a retrieval reports, JSON-ready.

    Keys: ``relative_residual``, ``cost``, ``feasible``, ``min_margin`` (per constraint
    name), ``constraints`` (name, link, margin, unit, satisfied), ``stage_costs``,
    ``xi``, ``run_time_s``, ``seed``, ``workers``, ``best_run``, ``runs`` (per run:
    final cost, stage costs, relative residual, feasible, violation, evaluations, time),
    ``options``, ``total_mass``, ``bounds``, ``kind``, ``link_names``.
    """
    opts = result.options
    rep = result.report
    return {
        "schema": REPORT_SCHEMA,
        "dynid_version": __version__,
        "kind": result.kind,
        "robot": result.robot.name,
        "link_names": list(result.robot.link_names[1:]),
        "relative_residual": finite_or_none(result.relative_residual),
        "cost": finite_or_none(result.cost),
        "feasible": bool(result.feasible),
        "min_margin": {name: finite_or_none(rep.min_margin(name)) for name in rep.names},
        "constraints": _report_constraints(rep),
        "stage_costs": [finite_or_none(x) for x in result.stage_costs],
        "xi": list(opts.schedule()),
        "run_time_s": float(result.run_time),
        "seed": result.seed,
        "workers": int(result.workers),
        "best_run": int(result.best_run),
        "n_feasible_runs": int(result.n_feasible_runs),
        "runs": [
            {
                "index": r.index,
                "cost": finite_or_none(r.stage_costs[-1]),
                "stage_costs": [finite_or_none(x) for x in r.stage_costs],
                "relative_residual": finite_or_none(r.relative_residual),
                "feasible": bool(r.feasible),
                "violation": finite_or_none(r.violation),
                "n_evaluations": int(r.n_evaluations),
                "time_s": float(r.time),
            }
            for r in result.runs
        ],
        "options": {
            "runs": opts.runs,
            "stages": opts.stages,
            "anneal_maxiter": opts.anneal_maxiter,
            "anneal_temperature": opts.anneal_temperature,
            "local_maxiter": opts.local_maxiter,
            "margin": opts.margin,
            "scale_floor": opts.scale_floor,
            "tol": opts.tol,
            "residual_tol": opts.residual_tol,
        },
        "total_mass": None if result.total_mass is None else list(result.total_mass),
        "bounds": bounds_to_dict(result.bounds),
        "units": {
            "relative_residual": "1",
            "margin": "per constraint (see unit)",
            "run_time_s": "s",
        },
    }


def consistent_report_to_dict(result: ConsistentResult) -> dict[str, Any]:
    """Everything a convex retrieval or consistent identification reports, JSON-ready.

    Keys: ``method`` ("sdp"), ``kind``, ``fit`` ("equality" or "weighted"), ``prior``
    (source, repaired links, notes), ``prior_weight`` and the automatic ``weight_search``
    (``[w, residual_ratio]``), ``relative_residual`` (on the coefficients),
    ``residual_ratio`` (data residual RMS over the unconstrained fit's), ``feasible``,
    ``min_margin`` and ``constraints`` (every margin, with ``pseudo_inertia`` as
    ``lambda_min(J)/tr(J)``), ``pseudo_inertia_margin`` and ``divergence`` per link,
    ``distance_to_prior`` (mass [kg], CoM [m] per link), ``friction`` (classical, when
    identified), ``solver``, ``status``, ``run_time_s``, ``notes``, ``options``,
    ``total_mass``, ``bounds``; ``heldout`` (training and held-out torque errors of least
    squares and of the consistent fit, the weight search ``[w, held-out error %]``, the
    acceptance; None without held-out folds) and ``on_bound`` (parameters decided by a
    bound, not the data).
    """
    rep = result.report
    o = result.options
    pm, pc, _ = inertial_from_phi(result.prior.phi)
    return {
        "schema": REPORT_SCHEMA,
        "dynid_version": __version__,
        "method": result.method,
        "kind": result.kind,
        "fit": result.fit,
        "robot": result.robot.name,
        "link_names": list(result.robot.link_names[1:]),
        "prior": {
            "source": result.prior.source,
            "repaired_links": list(result.prior.repaired),
            "mass": [float(x) for x in pm],
        },
        "prior_weight": finite_or_none(result.prior_weight),
        "weight_search": [[finite_or_none(w), finite_or_none(r)] for w, r in result.weight_search],
        "relative_residual": finite_or_none(result.relative_residual),
        "residual_ratio": finite_or_none(result.residual_ratio),
        "feasible": bool(result.feasible),
        "min_margin": {name: finite_or_none(rep.min_margin(name)) for name in rep.names},
        "constraints": _report_constraints(rep),
        "pseudo_inertia_margin": [finite_or_none(x) for x in result.pseudo_inertia_margin],
        "divergence": [finite_or_none(x) for x in result.divergence],
        "distance_to_prior": {
            "mass": [float(x) for x in np.abs(result.mass - pm)],
            "com": [float(x) for x in np.linalg.norm(result.com - pc, axis=1)],
        },
        "friction": None
        if result.friction is None
        else {
            k: [float(x) for x in result.friction[:, j]] for j, k in enumerate(("fv", "fc", "fo"))
        },
        "solver": result.solver,
        "status": result.status,
        "run_time_s": float(result.run_time),
        "seed": result.seed,
        "notes": list(result.notes),
        "heldout": None if result.heldout is None else result.heldout.as_dict(),
        "on_bound": list(result.on_bound),
        "options": {
            "objective": o.objective,
            "prior_weight": o.prior_weight,
            "residual_increase": o.residual_increase,
            "margin": o.margin,
            "fit": o.fit,
            "mass_factor": o.mass_factor,
            "residual_tol": o.residual_tol,
            "heldout_tol": o.heldout_tol,
            "tol": o.tol,
        },
        "total_mass": None if result.total_mass is None else list(result.total_mass),
        "bounds": bounds_to_dict(result.bounds),
        "units": {
            "relative_residual": "1",
            "residual_ratio": "1",
            "margin": "per constraint (see unit)",
            "pseudo_inertia_margin": "1",
            "run_time_s": "s",
        },
    }


def save_report_json(path: str | Path, result: Any, **extra: Any) -> Path:
    """Write ``report.json`` (:func:`report_to_dict` or :func:`consistent_report_to_dict`,
    plus ``extra`` entries)."""
    d = (
        consistent_report_to_dict(result)
        if isinstance(result, ConsistentResult)
        else report_to_dict(result)
    )
    d.update(extra)
    return _write_json(path, d)


# ------------------------------------------------------------------------ bounds files
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


def bounds_from_dict(d: Mapping[str, Any], robot: Robot, *, source: str = "bounds") -> Bounds:
    """Bounds for ``robot`` from a bounds file's content; gaps filled from its defaults.

    Raises
    ------
    DataError
        Unknown keys, a link name the robot does not have, malformed or inconsistent
        values (lower above upper, negative mass).
    """
    unknown = sorted(set(d) - {"schema", "total_mass", "links", "units"})
    if unknown:
        raise DataError(f"{source}: unknown keys {_checks.short(unknown)}")
    schema = d.get("schema", BOUNDS_SCHEMA)
    if schema != BOUNDS_SCHEMA:
        raise DataError(f"{source}: schema {schema!r}, expected {BOUNDS_SCHEMA!r}")
    base = default_bounds(robot)
    lo, hi = base.lower.copy(), base.upper.copy()
    names = list(robot.link_names[1:])
    links = d.get("links", []) or []
    if not isinstance(links, list):
        raise DataError(f"{source}: 'links' must be a list of tables/objects")
    for k, link in enumerate(links):
        where = f"{source}: links[{k}]"
        if not isinstance(link, Mapping):
            raise DataError(f"{where} must be a table/object")
        bad = sorted(set(link) - _BOUND_KEYS)
        if bad:
            raise DataError(
                f"{where}: unknown keys {_checks.short(bad)}; allowed: {sorted(_BOUND_KEYS)}"
            )
        name = link.get("name")
        if name not in names:
            raise DataError(f"{where}: unknown link {_checks.short(name)}; available: {names}")
        i = names.index(name)
        if "mass" in link:
            lo[i, 0], hi[i, 0] = _vec(link["mass"], 2, f"{where} mass")
        for key, arr, sl, size in (
            ("com_min", lo, slice(1, 4), 3),
            ("com_max", hi, slice(1, 4), 3),
            ("inertia_min", lo, slice(4, 10), 6),
            ("inertia_max", hi, slice(4, 10), 6),
        ):
            if key in link:
                arr[i, sl] = _vec(link[key], size, f"{where} {key}")
    band: Any = base.total_mass
    if "total_mass" in d:
        tm = d["total_mass"]
        band = (
            None
            if tm is None or (isinstance(tm, list) and not tm)
            else tuple(_vec(tm, 2, f"{source}: total_mass"))
        )
    try:
        return Bounds.from_arrays(lo, hi, band, names)
    except (ValueError, ShapeError) as exc:
        raise DataError(f"{source}: {exc}") from exc


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
        d = _read_json(path)
    elif suffix == ".toml":
        try:
            text = path.read_text(encoding="utf-8-sig")
        except UnicodeDecodeError as exc:
            raise DataError(f"{path.name}: not a UTF-8 text file ({exc.reason})") from None
        d = _checks.parse_toml(text, path.name, DataError)
    else:
        raise DataError(f"{path.name}: bounds files are .json or .toml; got {suffix!r}")
    return bounds_from_dict(d, robot, source=path.name)


def _toml_value(v: Any) -> str:
    if isinstance(v, str):
        return json.dumps(v)
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
        raise DataError(f"{path.name}: bounds files are .json or .toml; got {path.suffix!r}")
    return _write_json(path, d)
