"""Files in and out: data sets, logs, models, parameters, robot descriptions.

One verb pair: ``save_*`` writes (atomically: a temporary file in the same folder, then a
rename) and ``load_*`` reads and checks (strict JSON with a ``schema`` key, row counts, named
columns). The names below are loaded on first use, so that importing one module of this
package does not import the others (or their optional dependencies, such as ``rosbags``).
"""

from __future__ import annotations

import importlib
from typing import Any

_NAMES = {
    "save_torque_log": "torque_log",
    "load_torque_log": "torque_log",
    "save_static_data": "static_data",
    "load_static_data": "static_data",
    "save_model_json": "model_json",
    "load_model_json": "model_json",
    "save_friction_json": "friction_json",
    "load_friction_json": "friction_json",
    "save_feasible_json": "feasible",
    "load_feasible_json": "feasible",
    "load_feasible_linear_friction": "feasible",
    "load_feasible_drive": "feasible",
    "load_feasible_spring": "feasible",
    "load_drive": "drive_file",
    "save_report_json": "report_json",
    "save_bounds": "bounds_file",
    "load_bounds": "bounds_file",
    "save_robot": "export",
    "load_robot": "robot_file",
    "save_urdf": "robot.urdf",
    "load_urdf": "robot.urdf",
    "save_toml": "robot.toml",
    "load_toml": "robot.toml",
    "save_mjcf": "robot.mjcf",
    "save_payload_json": "payload_json",
    "save_validation_json": "validation_json",
    "save_feasible_bundle": "feasible_bundle",
    "save_trajectory_csv": "excitation",
    "save_excitation_json": "excitation",
    "load_trajectory": "excitation",
    "load_obstacles": "excitation",
    "load_column_map": "columns",
    "load_mapped_torque_log": "columns",
    "load_mapped_static_data": "columns",
    "load_joint_state_bag": "rosbag",
    "save_thresholds": "observer_files",
    "load_thresholds": "observer_files",
    "save_events": "observer_files",
    "save_residuals_csv": "observer_files",
}

__all__ = sorted(_NAMES)


def __getattr__(name: str) -> Any:
    module = _NAMES.get(name)
    if module is None:
        raise AttributeError(f"module 'dynid.io' has no attribute {name!r}")
    return getattr(importlib.import_module(f".{module}", __name__), name)


def __dir__() -> list[str]:
    return sorted(set(globals()) | set(_NAMES))
