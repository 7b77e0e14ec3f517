"""Exciting trajectories and obstacles to and from files.

* ``trajectory.csv``: a units line, the row count (``# rows: N``), then columns ``t,
  q1..qn, dq1..dqn, ddq1..ddqn`` [s, rad, rad/s, rad/s^2], one row per sample (1 kHz from
  ``dynid excite``), ready for a position or velocity controller.
* ``trajectory.json`` (schema ``dynid-exciting-trajectory/1``): the coefficients and the
  form (:meth:`~dynid.simulation.excitation.ExcitingTrajectory.to_dict`), the limits and
  margins, the obstacles, the capsule radii, the condition numbers and the smallest margin
  to every limit and obstacle at 1 kHz, the seed.
* obstacles (JSON, schema ``dynid-obstacles/1``), in the base frame [m]::

      {"schema": "dynid-obstacles/1",
       "planes": [{"name": "table", "point": [0, 0, 0], "normal": [0, 0, 1]}],
       "boxes": [{"name": "fixture", "center": [0.5, 0, 0.1], "size": [0.2, 0.3, 0.2]}]}

  A plane's normal points to the free side; boxes are axis-aligned.

Every file is read strictly, with the rules of torque logs: strict JSON (a duplicated key,
such as a second ``planes`` list that would silently replace the first, is an error),
unknown keys and columns refused, numbers finite and never booleans or strings, the
recorded row count of a CSV checked.
"""

from __future__ import annotations

import math
import re
from collections.abc import Mapping, Sequence
from pathlib import Path
from typing import Any

import numpy as np

from .. import __version__, _checks
from ..exceptions import DataError, DynidError
from ..model.robot import Robot
from ..simulation.clearance import Approach
from ..simulation.collision import Box, Obstacles, Plane, capsule_model
from ..simulation.excitation import ExcitationResult, ExcitingTrajectory, design_limits
from ..simulation.trajectories import Trajectory
from .atomic import open_atomic
from .csv_tables import csv_table
from .json_files import finite_or_none
from .schema import Field, Format, Record, fault, load_document, save_document

__all__ = [
    "EXCITATION",
    "EXCITATION_SCHEMA",
    "OBSTACLES",
    "OBSTACLES_SCHEMA",
    "load_obstacles",
    "inadmissible_note",
    "load_exciting_trajectory",
    "load_trajectory",
    "obstacles_from_dict",
    "obstacles_to_dict",
    "save_excitation_json",
    "save_trajectory_csv",
    "trajectory_columns",
]

EXCITATION_SCHEMA = "dynid-exciting-trajectory/1"
OBSTACLES_SCHEMA = "dynid-obstacles/1"
_UNITS = "# dynid trajectory; units: t [s], q [rad], dq [rad/s], ddq [rad/s^2]"


def save_trajectory_csv(path: str | Path, traj: Trajectory) -> Path:
    """Write ``t, q, dq, ddq`` to a CSV (columns named, units in the first line)."""
    path = Path(path)
    cols = trajectory_columns(traj.n)
    data = np.column_stack([traj.t, traj.q, traj.dq, traj.ddq])
    header = "\n".join([_UNITS, f"# rows: {len(data)}", ",".join(cols)])
    with open_atomic(path, "w") as fh:
        np.savetxt(fh, data, delimiter=",", fmt="%.10g", header=header, comments="")
    return path


def obstacles_to_dict(obstacles: Obstacles) -> dict[str, Any]:
    """The obstacles as in an obstacles file."""
    names = list(obstacles.names)
    k = len(obstacles.planes)
    return {
        "schema": OBSTACLES_SCHEMA,
        "planes": [
            {"name": names[i], "point": list(p.point), "normal": list(p.normal)}
            for i, p in enumerate(obstacles.planes)
        ],
        "boxes": [
            {"name": names[k + i], "center": list(b.center), "size": list(b.size)}
            for i, b in enumerate(obstacles.boxes)
        ],
    }


def save_excitation_json(
    path: str | Path, result: ExcitationResult, robot: Robot, *, seed: int | None = None
) -> Path:
    """Write ``trajectory.json``: coefficients, limits, margins, obstacles, conditioning."""
    o = result.options
    given = robot
    robot = design_limits(robot, o)  # the limits the design kept to
    d = {
        "schema": EXCITATION_SCHEMA,
        "dynid_version": __version__,
        "robot": robot.name,
        "joint_names": list(robot.joint_names),
        "seed": seed,
        "trajectory": result.trajectory.to_dict(),
        "condition_number": result.condition_number,
        "scaled_condition_number": result.scaled_condition_number,
        "initial_condition_number": result.initial_condition_number,
        "criterion": o.criterion,
        "condition_number_of": "classical regressor [Y_b, F] (base parameters, then fv, fc, fo "
        "per joint), unscaled, samples at 200 Hz (Gaz et al. 2019 report 121.88 for theirs)",
        "status": result.status,
        "improved": result.improved,
        "start_admissible": result.start_admissible,
        "iterations": result.iterations,
        "evaluations": result.evaluations,
        "limits": {
            "q_min_rad": robot.q_min.tolist(),
            "q_max_rad": robot.q_max.tolist(),
            "dq_max_rad_s": robot.dq_max.tolist(),
            "ddq_max_rad_s2": robot.ddq_max.tolist(),
            "tau_max_nm": robot.tau_max.tolist(),
        },
        # the joint ranges given (--range): the limits above, narrowed from the robot's
        "ranges": {
            given.joint_names[j]: {"joint": j + 1, "lo_rad": lo, "hi_rad": hi}
            for j, lo, hi in o.ranges
        },
        # the limits given (--max-velocity, ...): the limits above, tightened from the robot's
        "limits_given": {
            k: {given.joint_names[j]: v for j, v in getattr(o, k)}
            for k in ("max_velocity", "max_acceleration", "max_torque")
        },
        "robot_limits": {
            "q_min_rad": given.q_min.tolist(),
            "q_max_rad": given.q_max.tolist(),
            "dq_max_rad_s": given.dq_max.tolist(),
            "ddq_max_rad_s2": given.ddq_max.tolist(),
            "tau_max_nm": given.tau_max.tolist(),
        },
        "margins_required": {
            "position_rad": o.position_margin,
            "velocity_rad_s": o.velocity_margin,
            "acceleration_fraction": o.acceleration_margin,
            "torque_fraction": o.torque_margin,
            "obstacle_clearance_m": o.obstacle_clearance,
            "self_clearance_m": o.self_clearance,
            "scaled_to_the_arm": list(result.derived),
            "chain_length_m": None if result.sizes is None else result.sizes.chain_length,
            "scale": None if result.sizes is None else result.sizes.scale,
        },
        "capsule_radii_m": capsule_model(robot, o.radii).radii.tolist(),
        "obstacles": obstacles_to_dict(result.obstacles),
        "smallest_margins_at_1khz": {
            "position_rad": result.margins["position"],
            "velocity_rad_s": result.margins["velocity"],
            "acceleration_rad_s2": result.margins["acceleration"],
            "torque_nm": result.margins["torque"],
            "obstacles_m": result.margins["obstacles"],
            "self_collision_m": result.margins["self_collision"],
            "closest": [_approach(a) for a in result.margins.get("closest", ())],
        },
        "history": list(result.history),
        # the drive whose known rotor inertias the torques checked include (null: none)
        "drive": None if result.drive is None else result.drive.as_dict(),
    }
    # limits, margins and condition numbers may be infinite (no limit, no obstacle): null
    return save_document(path, EXCITATION, finite_or_none(d))


def _approach(a: Approach) -> dict[str, Any]:
    """An :class:`~dynid.simulation.clearance.Approach` as ``trajectory.json`` writes it."""
    return {
        "link": a.link,
        ("obstacle" if a.obstacle else "other_link"): a.other,
        "distance_m": a.distance,
        "required_m": a.required,
        "t_s": a.t,
    }


_V3 = Field("numbers", required=True, shape=(3,), unit="m")
_SHAPE_KEYS = {"planes": ("plane", "point", "normal"), "boxes": ("box", "center", "size")}
#: an obstacles file (module docstring)
OBSTACLES = Format(
    OBSTACLES_SCHEMA,
    Record(
        {
            kind: Field("objects", record=Record({"name": Field("string"), k1: _V3, k2: _V3}))
            for kind, (_, k1, k2) in _SHAPE_KEYS.items()
        }
    ),
    "obstacles file",
)
_NUMBER = Field("number")
_OPTIONAL = Field("number", nullable=True)
#: ``trajectory.json`` (:func:`save_excitation_json`; n joints, L harmonics)
EXCITATION = Format(
    EXCITATION_SCHEMA,
    Record(
        {
            "dynid_version": Field("string"),
            "robot": Field("string"),
            "joint_names": Field("strings"),
            "seed": Field("integer", nullable=True),
            "trajectory": Field(
                "object",
                required=True,
                record=Record(
                    {
                        "form": Field("string"),
                        "w_f_rad_s": Field("number", required=True, unit="rad/s"),
                        "base_frequency_hz": _NUMBER,
                        "harmonics": _NUMBER,
                        "duration_s": Field("number", required=True, unit="s"),
                        "ramp_s": Field("number", required=True, unit="s"),
                        "total_duration_s": _NUMBER,
                        "a_rad_s": Field("numbers", required=True, shape=("n", "L")),
                        "b_rad_s": Field("numbers", required=True, shape=("n", "L")),
                        "q_start_rad": Field("numbers", required=True, shape=("n",)),
                    }
                ),
            ),
            "condition_number": _OPTIONAL,
            "scaled_condition_number": _OPTIONAL,
            "initial_condition_number": _OPTIONAL,
            "criterion": Field("string"),
            "condition_number_of": Field("string"),
            "status": Field("any"),
            "improved": Field("bool"),
            "start_admissible": Field("bool"),
            "iterations": Field("any"),
            "evaluations": Field("any"),
            "limits": Field("any"),
            "margins_required": Field("any"),
            "capsule_radii_m": Field("any"),
            "obstacles": Field("object", record=OBSTACLES.top),
            "smallest_margins_at_1khz": Field("any"),
            "history": Field("any"),
            "ranges": Field("any"),
            "robot_limits": Field("any"),
            "limits_given": Field("any"),
            "drive": Field("any"),
        }
    ),
    "trajectory file (dynid excite)",
)


def load_obstacles(path: str | Path) -> Obstacles:
    """Read an obstacles file (see the module docstring), strictly.

    Raises
    ------
    DataError
        Not strict JSON (duplicated keys included: a second ``planes`` list would drop the
        first), wrong schema, an unknown key, a plane or box that is not an object of a
        name (without control characters) and three finite numbers per vector, a zero
        normal or a box without volume, or two obstacles of one name (each message names
        the file and the key, :mod:`dynid.io.schema`).
    OSError
        The file cannot be read.
    """
    path = Path(path)
    return obstacles_from_dict(load_document(path, OBSTACLES), path.name)


def obstacles_from_dict(d: Mapping[str, Any], source: str) -> Obstacles:
    """The obstacles of an obstacles record checked against :data:`OBSTACLES`."""
    shapes: dict[str, list[Plane | Box]] = {"planes": [], "boxes": []}
    names: list[str] = []
    for kind, (one, k1, k2) in _SHAPE_KEYS.items():
        for k, item in enumerate(d.get(kind) or []):
            where = f"{kind}[{k}]"
            name = item.get("name", f"{one}{k + 1}")
            bad = _checks.control_character(name)
            if not name or bad is not None:  # as robot names: it was printed raw
                got = _checks.short(name) + (f" (holds {ascii(bad)})" if bad else "")
                want = "a non-empty name without control characters"
                raise fault(source, f"{where}.name", f"expected {want}; got {got}")
            if name in names:
                want = "a name of one obstacle"
                raise fault(source, f"{where}.name", f"expected {want}; got {name!r} again")
            v1, v2 = tuple(item[k1]), tuple(item[k2])
            try:
                shapes[kind].append(Plane(v1, v2) if kind == "planes" else Box(v1, v2))
            except DynidError as exc:
                raise fault(source, where, str(exc)) from None
            names.append(name)
    return Obstacles(
        planes=tuple(x for x in shapes["planes"] if isinstance(x, Plane)),
        boxes=tuple(x for x in shapes["boxes"] if isinstance(x, Box)),
        names=tuple(names),
    )


def load_trajectory(path: str | Path, n: int, *, fs: float = 1000.0) -> Trajectory:
    """A trajectory from ``trajectory.csv`` or ``trajectory.json`` (sampled at ``fs`` [Hz]).

    Both are read strictly, as torque logs are. CSV: a UTF-8 byte-order mark is accepted;
    the header must name exactly ``t, q1..qn, dq1..dqn, ddq1..ddqn`` (a duplicated or
    unknown column is refused, not silently used or ignored); the ``# rows:`` count, when
    recorded, must match. JSON: strict JSON, the schema, known keys only (at the top and in
    the trajectory), finite numbers, and the derived keys (harmonics, base frequency, total
    duration) consistent with the coefficients.

    Raises
    ------
    DataError
        Unknown suffix, wrong schema, missing, duplicated or unknown columns or keys, a
        joint count other than ``n``, a row count other than the recorded one, a
        malformed cell or row (its line), times not increasing, derived keys that disagree
        with the coefficients.
    OSError
        The file cannot be read.
    """
    path = Path(path)
    suffix = path.suffix.lower()
    if suffix == ".json":
        return load_exciting_trajectory(path, n).sample(fs)
    if suffix != ".csv":
        raise DataError(f"--trajectory file must be .csv or .json; got {path.name!r}")
    return _trajectory_csv(path, n)


def load_exciting_trajectory(path: str | Path, n: int) -> ExcitingTrajectory:
    """The Fourier series of ``trajectory.json`` (as :func:`load_trajectory` reads it), to be
    evaluated at any times (a long log a block of samples at a time).

    Raises
    ------
    DataError
        As :func:`load_trajectory` for a JSON file.
    """
    path = Path(path)
    tr = load_document(path, EXCITATION)["trajectory"]
    try:
        traj = ExcitingTrajectory.from_dict(tr)
    except (TypeError, ValueError) as exc:
        raise fault(path.name, "trajectory", str(exc)) from None
    if traj.n != n:
        raise fault(
            path.name, "trajectory.q_start_rad", f"expected {n} joints (the robot's); got {traj.n}"
        )
    _check_derived(tr, traj, path.name)
    return traj


#: The margins of ``smallest_margins_at_1khz``: their words and units.
_MARGINS = {
    "position_rad": ("position margin", "rad"),
    "velocity_rad_s": ("velocity margin", "rad/s"),
    "acceleration_rad_s2": ("acceleration margin", "rad/s^2"),
    "torque_nm": ("torque margin", "N m"),
    "obstacles_m": ("clearance to", "m"),
    "self_collision_m": ("self-collision clearance", "m"),
}


def inadmissible_note(path: str | Path) -> str | None:
    """What ``dynid excite`` recorded against the trajectory of ``trajectory.json``, for a
    command that runs it: None when its status is not ``"infeasible"``; else the margins
    it violates (each smallest margin below zero, as recorded at 1 kHz, in its unit)."""
    doc = load_document(Path(path), EXCITATION)
    if doc.get("status") != "infeasible":
        return None
    low = []
    for key, v in (doc.get("smallest_margins_at_1khz") or {}).items():
        word, unit = _MARGINS.get(key, (key, ""))
        if isinstance(v, dict):  # obstacles by name
            low += [f"{word} {k} {x:.3g} {unit}" for k, x in v.items() if _below(x)]
        elif isinstance(v, list):  # per joint
            low += [f"{word} of joint {j + 1} {x:.3g} {unit}" for j, x in enumerate(v) if _below(x)]
        elif _below(v):
            low.append(f"{word} {v:.3g} {unit}")
    start = "" if doc.get("start_admissible", True) else "; its start is not admissible either"
    return (
        f"{Path(path).name}: `dynid excite` found no admissible trajectory and wrote this one "
        f"all the same ({', '.join(low) or 'margins violated'}{start}): simulated as given; "
        "a real arm should not run it"
    )


def _below(x: Any) -> bool:
    return isinstance(x, (int, float)) and x < 0


def _trajectory_csv(path: Path, n: int) -> Trajectory:
    """``trajectory.csv`` read strictly (:func:`load_trajectory`)."""
    want = trajectory_columns(n)

    def layout(names: list[str], line: int) -> dict[str, list[int]]:
        at = f"line {line}"
        dup = sorted({c for c in names if names.count(c) > 1})
        if dup:
            raise DataError(
                f"duplicated column(s) {_checks.names(dup)}; each column must appear once",
                file=path.name,
                at=at,
            )
        k = sum(1 for c in names if re.fullmatch(r"q[1-9]\d*", c))
        if k != n and f"q{k}" in names:
            raise DataError(
                f"trajectory has {k} joints (q1..q{k}); the robot has {n}", file=path.name, at=at
            )
        missing = [c for c in want if c not in names]
        if missing:
            raise DataError(
                f"missing column(s) {_checks.names(missing)} for {n} joints"
                + _not_a_trajectory(names, n),
                file=path.name,
                at=at,
            )
        unknown = [c for c in names if c not in want]
        if unknown:
            raise DataError(
                f"unknown column(s) {_checks.names(unknown)}; a trajectory of {n} "
                f"joints has t, q1..q{n}, dq1..dq{n}, ddq1..ddq{n}",
                file=path.name,
                at=at,
            )
        return {"a": [names.index(c) for c in want]}

    arrays, _ = csv_table(path, layout, ",".join(want[:2]) + ",...")
    a = arrays["a"]
    if not np.all(np.isfinite(a)):
        r = int(np.flatnonzero(~np.isfinite(a).all(axis=1))[0])
        raise DataError(f"data row {r} holds NaN, inf or an empty cell", file=path.name)
    try:
        return Trajectory(
            t=a[:, 0], q=a[:, 1 : n + 1], dq=a[:, n + 1 : 2 * n + 1], ddq=a[:, 2 * n + 1 :]
        )
    except DynidError as exc:
        raise DataError(str(exc), file=path.name) from None


def _not_a_trajectory(names: Sequence[str], n: int) -> str:
    """``; ...`` for a trajectory CSV of header ``names`` that lacks columns: what a
    trajectory file is (``dynid excite``'s ``trajectory.csv``, ``t, q, dq, ddq``, or its
    ``trajectory.json``), said of a torque log (``tau`` columns) as such."""
    log = any(re.fullmatch(r"tau[1-9]\d*", c) for c in names)
    return (
        f"; {f'it is a torque log (tau1..tau{n}), not a trajectory; ' if log else ''}hint: "
        f"--trajectory takes the trajectory.csv (t, q1..q{n}, dq1..dq{n}, ddq1..ddq{n}) or "
        "trajectory.json that dynid excite writes"
        + (" (the one the log was recorded along)" if log else "")
    )


def _check_derived(tr: dict[str, Any], traj: ExcitingTrajectory, name: str) -> None:
    """Refuse a ``trajectory.json`` whose derived keys (harmonics, base frequency, total
    duration) disagree with the coefficients they derive from: the file was edited."""
    derived = {
        "harmonics": float(traj.a.shape[1]),
        "base_frequency_hz": traj.w_f / (2 * np.pi),
        "total_duration_s": traj.total_duration,
    }
    for key, want in derived.items():
        if key in tr:
            got = float(tr[key])
            if not math.isclose(got, want, rel_tol=1e-9):
                raise fault(
                    name,
                    f"trajectory.{key}",
                    f"expected {want:.10g} (from the coefficients; the file was edited: "
                    f"regenerate it with dynid excite); got {got:.10g}",
                )


def trajectory_columns(n: int) -> list[str]:
    """Column names of ``trajectory.csv``: ``t, q1..qn, dq1..dqn, ddq1..ddqn``."""
    return ["t"] + [f"{k}{j + 1}" for k in ("q", "dq", "ddq") for j in range(n)]
