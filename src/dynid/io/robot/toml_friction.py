"""The robot TOML's friction of any law: a ``[friction]`` table (and ``[joint_friction]``).

A description holds the Gaz et al. sigmoid per joint (``joints[i].friction``); any other
law of the registry (:mod:`dynid.friction.laws`), such as the friction identified with the
links by ``identify --consistent``, is one top-level table with the law's parameters per
joint (:mod:`dynid.io.law_friction`)::

    [friction]
    model = "classical"
    at = "joint"            # or "motor": tau_f = K^T f(K dq) through the [drive] table
    fv = [0.5, ...]         # N m s/rad
    fc = [0.8, ...]         # N m
    fo = [0.0, ...]         # N m
    standstill_band = [...] # rad/s, optional (width = [...] for a smooth law's tanh)

The place written is the one every command uses, whatever drive the torques are read
through (the description's ``[drive]`` or another one given with the robot): the friction
holds its place (a drive whose ``friction_at`` is ``at``), unlike the sigmoid per joint,
which a drive places. Without ``at``: the ``[drive]`` table's ``friction_at`` when it
writes one, else the joints.

With friction at the motors and at the joints of a coupled drive (``at:both``), the joint
part is ``[joint_friction]`` (same keys, ``at = "joint"``); reading such a file gives the
robot both, a :class:`~dynid.friction.model.FrictionSum` of the two where each says (it
kept ``[friction]`` alone, and a coupled wrist validated at 7.2 x its noise).
"""

from __future__ import annotations

import dataclasses
from collections.abc import Mapping
from typing import Any

from ...friction.laws import LAWS
from ...friction.model import Friction, FrictionSum, friction_parts, sigmoid_parameters
from ...model.drive import Drive
from ..drive_file import drive_from_mapping
from ..law_friction import law_friction, law_record
from ..schema import Field, Record, fault

__all__ = ["FRICTION_TABLE", "friction_tables", "table_friction"]

#: ``[friction]`` and ``[joint_friction]``: the law, where it acts, its parameters (open)
FRICTION_TABLE = Field(
    "object",
    record=Record(
        {
            "model": Field("string", required=True, choices=tuple(LAWS)),
            "at": Field("string", choices=("joint", "motor")),
        },
        open=True,
    ),
)


def friction_tables(friction: Friction | FrictionSum | None) -> str:
    """The TOML tables of a friction that is not the sigmoid at the joints ("" for none,
    or for the sigmoid, which the joints hold)."""
    if friction is None or sigmoid_parameters(friction) is not None:
        return ""
    out = []
    for key, part in zip(("friction", "joint_friction"), friction_parts(friction), strict=False):
        at = "motor" if part.drive is not None and part.drive.friction_place == "motor" else "joint"
        rec = law_record(part)
        lines = [f"[{key}]", f'model = "{rec.pop("model")}"', f'at = "{at}"']
        units = dict(zip(part.law.params, part.law.units, strict=True))
        units[part.law.band_key] = "rad/s"
        lines += [
            f"{k} = [{', '.join(repr(float(x)) for x in v)}]  # {units[k]}" for k, v in rec.items()
        ]
        out.append("\n".join(lines))
    return "\n\n".join(out) + "\n"


def table_friction(doc: Mapping[str, Any], n: int, source: str) -> Friction | FrictionSum | None:
    """The friction of a description's ``[friction]`` table where its ``at`` says (module
    docstring): through its ``[drive]`` table at the motors, at the joints whatever drive
    the robot is later used with; with a ``[joint_friction]`` table beside it, the sum of
    both (each where its ``at`` says); or None.

    Raises
    ------
    DataError
        A malformed table; ``at = "motor"`` without a ``[drive]`` table; a ``[friction]``
        table beside a sigmoid per joint; ``[joint_friction]`` without ``[friction]``.
    """
    rec = doc.get("friction")
    if rec is None:
        if "joint_friction" in doc:
            raise fault(source, "joint_friction", "needs the [friction] table it adds to")
        return None
    if any("friction" in jt for jt in doc.get("joints", [])):
        raise fault(
            source, "friction", "give the sigmoid per joint or a [friction] table, not both"
        )
    friction = _one_table(doc, rec, n, source, "friction")
    if "joint_friction" not in doc:
        return friction
    return FrictionSum(
        (friction, _one_table(doc, doc["joint_friction"], n, source, "joint_friction"))
    )


def _one_table(
    doc: Mapping[str, Any], rec: Mapping[str, Any], n: int, source: str, key: str
) -> Friction:
    """The friction of one table ``key`` where its ``at`` says (without: the ``[drive]``
    table's ``friction_at``, else the joints)."""
    table = doc.get("drive")
    at: Any = rec.get("at")
    if at is None:  # the [drive] table's place, else the joints
        at = table.get("friction_at", "joint") if isinstance(table, Mapping) else "joint"
    if at == "motor" and table is None:
        raise fault(source, f"{key}.at", '"motor" needs the [drive] table it acts through')
    # the friction holds its place: no other drive moves a friction written at the joints
    drive = (
        Drive.identity(n)
        if table is None
        else drive_from_mapping(table, n, source=f"{source} [drive]")
    )
    if drive.friction_place != at:  # a default place that is the table's stays a default
        drive = dataclasses.replace(drive, friction_at=at)
    return law_friction(rec, drive, n, source, key)
