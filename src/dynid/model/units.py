"""Units per joint kind: a revolute joint's quantities in rad, rad/s, N m, N m s/rad and
kg m^2 (rotor inertia), a prismatic joint's in m, m/s, N, N s/m and kg.

dynid writes a unit once, spelled for a revolute joint (``"N m"``, ``"N m s/rad"``);
:func:`joint_unit` turns it into a joint's own (``"N"``, ``"N s/m"`` for a prismatic
one), and :func:`unit_said` says it for a whole arm: the revolute spelling alone for an
arm of revolute joints (as before prismatic joints were said), the prismatic one alone for
an arm of prismatic joints, else the revolute one with the prismatic joints' own
(``"N m (rail: N)"``). :func:`values_said` writes per-joint values with their units
(``"0.96, 0.059 N m"``, or ``"0.96 N, 0.059 N m"`` on a mixed arm).
"""

from __future__ import annotations

import re
from collections.abc import Mapping, Sequence
from dataclasses import dataclass
from typing import Any, Protocol

__all__ = [
    "JointKinds",
    "Joints",
    "joint_unit",
    "joint_units",
    "unit_said",
    "units_said",
    "values_said",
]


class JointKinds(Protocol):
    """What the units need of a robot: its joints' names and kinds (a ``Robot``)."""

    @property
    def joint_names(self) -> tuple[str, ...]: ...

    @property
    def prismatic(self) -> Any: ...


@dataclass(frozen=True)
class Joints:
    """Joints' names and kinds read from a file (a robot record's ``joint_names`` and
    ``prismatic``), for :func:`unit_said` where no ``Robot`` is at hand."""

    joint_names: tuple[str, ...]
    prismatic: tuple[bool, ...]


#: A revolute unit's words -> a prismatic joint's, in order (a force for a torque, a
#: length for an angle, a mass for a moment of inertia).
_PRISMATIC = (
    (re.compile(r"N\^2 m\^2"), "N^2"),
    (re.compile(r"kg m\^2"), "kg"),
    (re.compile(r"N m\b"), "N"),
    (re.compile(r"\brad\b"), "m"),
)


def joint_unit(unit: str, prismatic: bool) -> str:
    """``unit``, spelled for a revolute joint (``"N m s/rad"``), as a joint of that kind
    has it (``"N s/m"`` for a prismatic one; ``"N m"`` -> ``"N"``, ``"rad/s"`` ->
    ``"m/s"``, ``"kg m^2"`` -> ``"kg"``; ``"s"``, ``"%"``, ``"1/s"`` kept)."""
    if not prismatic:
        return unit
    for pattern, word in _PRISMATIC:
        unit = pattern.sub(word, unit)
    return unit


def _kinds(robot: JointKinds) -> list[bool]:
    return [bool(p) for p in robot.prismatic]


def joint_units(robot: JointKinds, unit: str) -> list[str]:
    """``unit`` (a revolute joint's spelling) as each of ``robot``'s joints has it (n,)."""
    return [joint_unit(unit, p) for p in _kinds(robot)]


def unit_said(robot: JointKinds | None, unit: str) -> str:
    """``unit`` (a revolute joint's spelling) said for every joint of ``robot``: as given
    for revolute joints alone (or no robot known), the prismatic spelling for prismatic
    joints alone, else ``"N m (rail: N)"``: the revolute one and the prismatic joints'
    own, named."""
    kinds = [] if robot is None else _kinds(robot)
    own = joint_unit(unit, True)
    if not any(kinds) or own == unit:
        return unit
    if all(kinds):
        return own
    assert robot is not None
    names = [n for n, p in zip(robot.joint_names, kinds, strict=False) if p]
    return f"{unit} ({', '.join(names)}: {own})"


def units_said(
    robot: JointKinds | None, units: Mapping[str, str], keys: Sequence[str] | None = None
) -> dict[str, str]:
    """A file's ``units`` (key -> a revolute joint's spelling) with the per-joint ones,
    ``keys`` (all when None), said for ``robot``'s joints (:func:`unit_said`)."""
    return {k: unit_said(robot, u) if keys is None or k in keys else u for k, u in units.items()}


def values_said(robot: JointKinds | None, texts: Sequence[str], unit: str, sep: str = ", ") -> str:
    """Per-joint values already formatted (``texts``, one per joint) with ``unit`` (a
    revolute joint's spelling): ``"0.96, 0.059 N m"`` where every joint has the same unit,
    each value with its own on a mixed arm (``"0.96 N, 0.059 N m"``)."""
    kinds = [] if robot is None else _kinds(robot)
    units = {joint_unit(unit, p) for p in kinds} or {unit}
    if len(units) == 1 or len(kinds) != len(texts):
        return f"{sep.join(texts)} {units.pop() if len(units) == 1 else unit}"
    return sep.join(f"{t} {joint_unit(unit, p)}" for t, p in zip(texts, kinds, strict=True))
