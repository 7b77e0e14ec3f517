"""A robot's kinematic description to and from a JSON-ready dictionary.

Written next to identified coefficients, which are valid only for the kinematics and the
gravity vector they were identified with. Fields (see :class:`dynid.Robot`): ``name``,
``joint_names``, ``link_names`` (base first), ``T_parent_joint`` (n, 4, 4) [m],
``axes`` (n, 3) (unit, link coordinates), ``prismatic`` (n,), ``limits`` (``q_min``,
``q_max`` [rad or m], ``dq_max`` [rad/s], ``ddq_max`` [rad/s^2], ``tau_max`` [N m]; ``null``
where there is no limit), ``gravity`` (3,) [m/s^2] in the base frame, and ``frames``
(name -> ``{"link": index, "T_link_frame": 4x4}``, and ``"joint"``: the fixed joint that
attaches it in the source URDF, when it has one), and, written beside identified
coefficients, ``phi`` (n, 10): the description's standard parameters per link (m [kg],
mc [kg m], J [kg m^2] about the link origin), the prior a later consistent fit starts from,
never the identified values (:attr:`~dynid.identification.model.IdentifiedModel.
description_phi`: a robot read back has zero standard parameters).

Friction is not written, nor the inertial parameters unless asked; a robot read back has
no friction model. Floats are
written with Python's shortest round-trip representation, so the kinematics read back are
bit-identical.
"""

from __future__ import annotations

from collections.abc import Mapping
from typing import Any

import numpy as np

from ..exceptions import DataError, ModelError, ShapeError
from ..model.robot import Frame, Robot
from .json_files import finite_or_none
from .schema import Field, Record, check

__all__ = ["ROBOT_RECORD", "ROBOT_SCHEMA", "robot_from_dict", "robot_to_dict"]

ROBOT_SCHEMA = "dynid-robot-kinematics/1"
_LIMITS = ("q_min", "q_max", "dq_max", "ddq_max", "tau_max")
_N = "n"
#: the fields :func:`robot_to_dict` writes (n: the joint count)
ROBOT_RECORD = Record(
    {
        "schema": Field("string", choices=(ROBOT_SCHEMA,)),
        "name": Field("string", required=True),
        "joint_names": Field("strings", required=True, shape=(_N,)),
        "link_names": Field("strings", required=True),
        "T_parent_joint": Field("numbers", required=True, shape=(_N, 4, 4), unit="m"),
        "axes": Field("numbers", required=True, shape=(_N, 3)),
        "prismatic": Field("bools", required=True, shape=(_N,)),
        "limits": Field(
            "object",
            required=True,
            record=Record(
                {k: Field("numbers", required=True, shape=(_N,), null_items=True) for k in _LIMITS}
            ),
        ),
        "gravity": Field("numbers", required=True, shape=(3,), unit="m/s^2"),
        "phi": Field("numbers", shape=(_N, 10)),
        "frames": Field(
            "named",
            required=True,
            record=Record(
                {
                    "link": Field("integer", required=True, low=0),
                    "T_link_frame": Field("numbers", required=True, shape=(4, 4)),
                    "joint": Field("string"),
                }
            ),
        ),
        "units": Field("any"),
    }
)


def robot_to_dict(robot: Robot, *, inertials: bool = False) -> dict[str, Any]:
    """The kinematic fields of a robot as a JSON-ready dictionary; with ``inertials`` also
    its standard parameters ``phi`` (n, 10) when it has any (the description's, kept as the
    default prior of a consistent fit from the file)."""
    phi = np.asarray(robot.phi, dtype=float)
    kept = {"phi": phi.tolist()} if inertials and np.any(phi) else {}
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
        **kept,
        "frames": {
            name: {
                "link": int(f.link),
                "T_link_frame": f.T_link_frame.tolist(),
                **({} if f.joint is None else {"joint": f.joint}),
            }
            for name, f in robot.frames.items()
        },
        "units": {
            "T_parent_joint": "m",
            "q_min/q_max": "rad (m if prismatic)",
            "dq_max": "rad/s",
            "ddq_max": "rad/s^2",
            "tau_max": "N m",
            "gravity": "m/s^2, base frame",
            **({"phi": "per link m kg, mc kg m, J kg m^2 about the link origin"} if kept else {}),
        },
    }


def robot_from_dict(
    d: Mapping[str, Any], *, source: str = "robot description", at: str = ""
) -> Robot:
    """A robot (zero inertial parameters, ``phi`` left to the caller; no friction) from
    :func:`robot_to_dict` output.

    ``source`` and ``at``: the file and the key path of ``d`` in it, for messages.

    Raises
    ------
    DataError
        An unknown key, a missing or malformed field (a boolean or a string where a number
        belongs included; named in the message, :mod:`dynid.io.schema`), or kinematics the
        robot refuses.
    """
    check(d, ROBOT_RECORD, source, at=at)
    n = len(d["joint_names"])
    inf = {k: (-np.inf if k == "q_min" else np.inf) for k in _LIMITS}
    lim: dict[str, Any] = {
        k: np.array([inf[k] if v is None else float(v) for v in d["limits"][k]], dtype=float)
        for k in _LIMITS
    }
    try:
        return Robot(
            name=d["name"],
            joint_names=tuple(d["joint_names"]),
            link_names=tuple(d["link_names"]),
            T_parent_joint=np.array(d["T_parent_joint"], dtype=float).reshape(n, 4, 4),
            axes=np.array(d["axes"], dtype=float).reshape(n, 3),
            prismatic=np.array(d["prismatic"], dtype=bool).reshape(n),
            phi=np.zeros((n, 10)),
            gravity=np.array(d["gravity"], dtype=float),
            frames={
                str(name): Frame(
                    f["link"], np.array(f["T_link_frame"], dtype=float), f.get("joint")
                )
                for name, f in d["frames"].items()
            },
            **lim,
        )
    except (ModelError, ShapeError, ValueError) as exc:
        raise DataError(f"key {at!r}: {exc}" if at else str(exc), file=source) from exc
