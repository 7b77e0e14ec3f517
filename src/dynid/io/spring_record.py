"""The record of joint springs in a file: ``{"k": [...], "q0": [...]}``.

One per joint: the stiffness ``k`` [N m/rad] about the rest position ``q0`` [rad]
(:class:`~dynid.model.stiffness.JointStiffness`, ``tau = k (q - q0)``). ``feasible.json``
holds it as ``spring`` and a TOML robot description as its ``[spring]`` table; both are
checked by :data:`SPRING_FIELD` (``n``: the file's joint count).
"""

from __future__ import annotations

from collections.abc import Mapping
from typing import Any

import numpy as np

from ..model.stiffness import JointStiffness
from .schema import Field, Record

__all__ = ["SPRING_FIELD", "SPRING_FORMULA", "spring_from_record", "spring_record"]

#: the convention written beside the record
SPRING_FORMULA = "tau_s = k (q - q0) [k N m/rad, q0 rad], added to the rigid-body torques"

#: the record's keys, for a format's :class:`~dynid.io.schema.Record`
SPRING_FIELD = Field(
    "object",
    nullable=True,
    record=Record(
        {
            "k": Field("numbers", required=True, shape=("n",), low=0.0, unit="N m/rad"),
            "q0": Field("numbers", required=True, shape=("n",), unit="rad"),
        }
    ),
)


def spring_record(spring: JointStiffness) -> dict[str, Any]:
    """``{"k": [...], "q0": [...]}`` of ``spring``, JSON- and TOML-ready."""
    return {"k": [float(x) for x in spring.k], "q0": [float(x) for x in spring.q0]}


def spring_from_record(record: Mapping[str, Any] | None) -> JointStiffness | None:
    """The springs of a record checked by :data:`SPRING_FIELD` (None: none)."""
    if record is None:
        return None
    return JointStiffness(np.asarray(record["k"], float), np.asarray(record["q0"], float))
