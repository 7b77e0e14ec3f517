"""A robot's kinematic description to and from a JSON-ready dictionary.

Written next to identified coefficients, which are valid only for the kinematics and the
gravity vector they were identified with. Fields (see :class:`dynid.Robot`): ``name``,
``joint_names``, ``link_names`` (base first), ``T_parent_joint`` (n, 4, 4) [m],
``axes`` (n, 3) (unit, link coordinates), ``prismatic`` (n,), ``limits`` (``q_min``,
``q_max`` [rad or m], ``dq_max`` [rad/s], ``ddq_max`` [rad/s^2], ``tau_max`` [N m]; ``null``
where there is no limit), ``gravity`` (3,) [m/s^2] in the base frame, and ``frames``
(name -> ``{"link": index, "T_link_frame": 4x4}``).

Inertial parameters and friction are not written: a robot read back has zero standard
parameters and no friction model. Floats are written with Python's shortest round-trip
representation, so the kinematics read back are bit-identical.
"""

from __future__ import annotations

from collections.abc import Mapping
from typing import Any

import numpy as np
from numpy.typing import NDArray

from .. import _checks
from ..exceptions import DataError, ModelError, ShapeError
from ..model.robot import Frame, Robot
from .json_files import finite_or_none

__all__ = ["robot_to_dict", "robot_from_dict", "ROBOT_SCHEMA"]

ROBOT_SCHEMA = "dynid-robot-kinematics/1"
_LIMITS = ("q_min", "q_max", "dq_max", "ddq_max", "tau_max")
#: the keys :func:`robot_to_dict` writes
_KEYS = {"schema", "name", "joint_names", "link_names", "T_parent_joint", "axes", "prismatic"}
_KEYS |= {"limits", "gravity", "frames", "units"}


def robot_to_dict(robot: Robot) -> dict[str, Any]:
    """The kinematic fields of a robot as a JSON-ready dictionary (no inertial parameters)."""
    return {
        "schema": ROBOT_SCHEMA,
        "name": robot.name,
        "joint_names": list(robot.joint_names),
        "link_names": list(robot.link_names),
        "T_parent_joint": robot.T_parent_joint.tolist(),
        "axes": robot.axes.tolist(),
        "prismatic": [bool(p) for p in robot.prismatic],
        "limits": {k: finite_or_none(getattr(robot, k)) for k in _LIMITS},
        "gravity": robot.gravity.tolist(),
        "frames": {
            name: {"link": int(f.link), "T_link_frame": f.T_link_frame.tolist()}
            for name, f in robot.frames.items()
        },
        "units": {
            "T_parent_joint": "m",
            "q_min/q_max": "rad (m if prismatic)",
            "dq_max": "rad/s",
            "ddq_max": "rad/s^2",
            "tau_max": "N m",
            "gravity": "m/s^2, base frame",
        },
    }


def robot_from_dict(d: Mapping[str, Any]) -> Robot:
    """A robot (zero inertial parameters, no friction) from :func:`robot_to_dict` output.

    Raises
    ------
    DataError
        An unknown key, a missing or malformed field (a boolean or a string where a number
        belongs included; named in the message).
    """
    unknown = sorted(set(d) - _KEYS)
    if unknown:
        raise DataError(f"robot description: unknown key(s) {_checks.short(unknown)}")
    try:
        n = len(d["joint_names"])
        limits = d["limits"]
        sign = {"q_min": -1.0}
        lim: dict[str, Any] = {
            k: np.array(
                [
                    sign.get(k, 1.0) * np.inf if v is None else _number(v, f"limits.{k}")
                    for v in limits[k]
                ]
            )
            for k in _LIMITS
        }
        frames = {
            str(name): Frame(_index(f["link"]), _numbers(f["T_link_frame"], f"frames.{name}"))
            for name, f in d["frames"].items()
        }
        prismatic = d["prismatic"]
        if not isinstance(prismatic, list) or not all(isinstance(p, bool) for p in prismatic):
            raise DataError(
                f"robot description: 'prismatic' must be a list of true or false; got "
                f"{_checks.short(prismatic)}"
            )
        return Robot(
            name=str(d["name"]),
            joint_names=tuple(d["joint_names"]),
            link_names=tuple(d["link_names"]),
            T_parent_joint=_numbers(d["T_parent_joint"], "T_parent_joint"),
            axes=_numbers(d["axes"], "axes"),
            prismatic=np.asarray(prismatic, dtype=bool),
            phi=np.zeros((n, 10)),
            gravity=_numbers(d["gravity"], "gravity"),
            frames=frames,
            **lim,
        )
    except KeyError as exc:
        raise DataError(f"robot description: missing field {exc.args[0]!r}") from None
    except DataError:
        raise
    except (TypeError, ValueError, AttributeError) as exc:
        if isinstance(exc, (ModelError, ShapeError)):
            raise DataError(f"robot description: {exc}") from exc
        raise DataError(f"robot description: malformed field ({exc})") from exc


def _number(value: Any, where: str) -> float:
    """A JSON number, strictly: not a boolean or a string (``float`` took both)."""
    return _checks.number(value, f"robot description: {where}", DataError)


def _numbers(value: Any, where: str) -> NDArray[np.float64]:
    """A nested list of JSON numbers as an array (no booleans, no strings)."""

    def walk(v: Any, at: str) -> Any:
        if isinstance(v, list):
            return [walk(x, f"{at}[{i}]") for i, x in enumerate(v)]
        return _number(v, at)

    return np.array(walk(value, where), dtype=np.float64)


def _index(value: Any) -> int:
    if isinstance(value, bool) or not isinstance(value, int):
        raise DataError(f"robot description: a frame's link must be an integer; got {value!r}")
    return value
