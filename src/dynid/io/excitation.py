"""Exciting trajectories and obstacles to and from files.

* ``trajectory.csv``: a units line, then columns ``t, q1..qn, dq1..dqn, ddq1..ddqn``
  [s, rad, rad/s, rad/s^2], one row per sample (1 kHz from ``dynid excite``), ready for a
  position or velocity controller.
* ``trajectory.json`` (schema ``dynid-exciting-trajectory/1``): the coefficients and the
  form (:meth:`~dynid.simulation.excitation.ExcitingTrajectory.to_dict`), the limits and
  margins, the obstacles, the capsule radii, the condition numbers and the smallest margin
  to every limit and obstacle at 1 kHz, the seed.
* obstacles (JSON, schema ``dynid-obstacles/1``), in the base frame [m]::

      {"schema": "dynid-obstacles/1",
       "planes": [{"name": "table", "point": [0, 0, 0], "normal": [0, 0, 1]}],
       "boxes": [{"name": "fixture", "center": [0.5, 0, 0.1], "size": [0.2, 0.3, 0.2]}]}

  A plane's normal points to the free side; boxes are axis-aligned.
"""

from __future__ import annotations

import json
import math
from pathlib import Path
from typing import Any

import numpy as np

from .. import __version__
from ..exceptions import DataError, DynidError
from ..model.robot import Robot
from ..simulation.collision import Box, Obstacles, Plane, capsule_model
from ..simulation.excitation import ExcitationResult, ExcitingTrajectory
from ..simulation.trajectories import Trajectory

__all__ = [
    "EXCITATION_SCHEMA",
    "OBSTACLES_SCHEMA",
    "load_obstacles",
    "load_trajectory",
    "obstacles_to_dict",
    "save_excitation_json",
    "save_trajectory_csv",
]

EXCITATION_SCHEMA = "dynid-exciting-trajectory/1"
OBSTACLES_SCHEMA = "dynid-obstacles/1"
_UNITS = "# dynid trajectory; units: t [s], q [rad], dq [rad/s], ddq [rad/s^2]"


def _jsonable(x: Any) -> Any:
    if isinstance(x, dict):
        return {str(k): _jsonable(v) for k, v in x.items()}
    if isinstance(x, (list, tuple)):
        return [_jsonable(v) for v in x]
    if isinstance(x, (float, np.floating)):
        return float(x) if math.isfinite(float(x)) else None
    if isinstance(x, np.integer):
        return int(x)
    if isinstance(x, np.ndarray):
        return _jsonable(x.tolist())
    return x


def _write_text(path: Path, text: str) -> Path:
    """Write atomically: a temporary file in the same folder, then rename."""
    tmp = path.with_name(path.name + ".tmp")
    tmp.write_text(text, encoding="utf-8")
    tmp.replace(path)
    return path


def save_trajectory_csv(path: str | Path, traj: Trajectory) -> Path:
    """Write ``t, q, dq, ddq`` to a CSV (columns named, units in the first line)."""
    path = Path(path)
    n = traj.n
    cols = ["t"] + [f"{k}{j + 1}" for k in ("q", "dq", "ddq") for j in range(n)]
    data = np.column_stack([traj.t, traj.q, traj.dq, traj.ddq])
    tmp = path.with_name(path.name + ".tmp")
    np.savetxt(
        tmp, data, delimiter=",", fmt="%.10g", header=_UNITS + "\n" + ",".join(cols), comments=""
    )
    tmp.replace(path)
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
        "iterations": result.iterations,
        "evaluations": result.evaluations,
        "limits": {
            "q_min_rad": robot.q_min.tolist(),
            "q_max_rad": robot.q_max.tolist(),
            "dq_max_rad_s": robot.dq_max.tolist(),
            "ddq_max_rad_s2": robot.ddq_max.tolist(),
            "tau_max_nm": robot.tau_max.tolist(),
        },
        "margins_required": {
            "position_rad": o.position_margin,
            "velocity_rad_s": o.velocity_margin,
            "acceleration_fraction": o.acceleration_margin,
            "torque_fraction": o.torque_margin,
            "obstacle_clearance_m": o.obstacle_clearance,
            "self_clearance_m": o.self_clearance,
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
        },
        "history": list(result.history),
    }
    text = json.dumps(_jsonable(d), indent=1, allow_nan=False) + "\n"
    return _write_text(Path(path), text)


def load_obstacles(path: str | Path) -> Obstacles:
    """Read an obstacles file (see the module docstring).

    Raises
    ------
    DataError
        Not JSON, wrong schema, or a malformed plane or box (named).
    """
    path = Path(path)
    d = _read_json(path)
    if d.get("schema") != OBSTACLES_SCHEMA:
        raise DataError(
            f"{path.name}: schema must be {OBSTACLES_SCHEMA!r}; got {d.get('schema')!r}"
        )
    planes, boxes, names = [], [], []
    try:
        for k, p in enumerate(d.get("planes", [])):
            names.append(str(p.get("name", f"plane{k + 1}")))
            planes.append(Plane(tuple(p["point"]), tuple(p["normal"])))
        for k, b in enumerate(d.get("boxes", [])):
            names.append(str(b.get("name", f"box{k + 1}")))
            boxes.append(Box(tuple(b["center"]), tuple(b["size"])))
    except KeyError as exc:
        raise DataError(f"{path.name}: obstacle {len(names)} misses {exc.args[0]!r}") from None
    except (TypeError, ValueError, DynidError) as exc:
        raise DataError(f"{path.name}: obstacle {names[-1]!r} is malformed ({exc})") from None
    return Obstacles(planes=tuple(planes), boxes=tuple(boxes), names=tuple(names))


def _read_json(path: Path) -> dict[str, Any]:
    try:
        d = json.loads(path.read_text(encoding="utf-8"))
    except (json.JSONDecodeError, UnicodeDecodeError) as exc:
        raise DataError(f"{path.name}: not a JSON file ({exc})") from exc
    if not isinstance(d, dict):
        raise DataError(f"{path.name}: expected a JSON object")
    return d


def load_trajectory(path: str | Path, n: int, *, fs: float = 1000.0) -> Trajectory:
    """A trajectory from ``trajectory.csv`` or ``trajectory.json`` (sampled at ``fs`` [Hz]).

    Raises
    ------
    DataError
        Unknown suffix, wrong schema, missing columns, a joint count other than ``n``.
    """
    path = Path(path)
    suffix = path.suffix.lower()
    if suffix == ".json":
        d = _read_json(path)
        if d.get("schema") != EXCITATION_SCHEMA:
            raise DataError(
                f"{path.name}: schema must be {EXCITATION_SCHEMA!r}; got {d.get('schema')!r}"
            )
        try:
            traj = ExcitingTrajectory.from_dict(d["trajectory"])
        except (KeyError, TypeError, ValueError, DynidError) as exc:
            raise DataError(f"{path.name}: malformed trajectory ({exc})") from None
        if traj.n != n:
            raise DataError(f"{path.name}: trajectory has {traj.n} joints; the robot has {n}")
        return traj.sample(fs)
    if suffix != ".csv":
        raise DataError(f"--trajectory file must be .csv or .json; got {path.name!r}")
    lines = [ln for ln in path.read_text(encoding="utf-8").splitlines() if ln.strip()]
    lines = [ln for ln in lines if not ln.lstrip().startswith("#")]
    if not lines:
        raise DataError(f"{path.name}: empty")
    cols = [c.strip() for c in lines[0].split(",")]
    want = ["t"] + [f"{k}{j + 1}" for k in ("q", "dq", "ddq") for j in range(n)]
    missing = [c for c in want if c not in cols]
    if missing:
        raise DataError(f"{path.name}: missing column(s) {missing} for {n} joints")
    try:
        data = np.loadtxt(lines[1:], delimiter=",", ndmin=2)
    except ValueError as exc:
        raise DataError(f"{path.name}: non-numeric cell ({exc})") from None
    if data.shape[1] != len(cols):
        raise DataError(f"{path.name}: rows have {data.shape[1]} fields; header {len(cols)}")
    idx = [cols.index(c) for c in want]
    a = data[:, idx]
    try:
        return Trajectory(
            t=a[:, 0], q=a[:, 1 : n + 1], dq=a[:, n + 1 : 2 * n + 1], ddq=a[:, 2 * n + 1 :]
        )
    except DynidError as exc:
        raise DataError(f"{path.name}: {exc}") from None
