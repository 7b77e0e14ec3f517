"""The friction coefficients of a joint that turns one way only.

A joint whose velocity never changes sign over the data has a Coulomb column
``sign(dq_j)`` that is a constant: its torque offset's column up to the sign, so the data
do not tell the two coefficients apart. The structure search
(:mod:`~dynid.identification.largest`) and the friction beside a payload
(:mod:`~dynid.feasibility.payload_fit`) leave the offset out and keep the Coulomb
coefficient, which then holds both.

* :data:`FRICTION_LABEL`: the label of a friction coefficient of one joint (motor);
* :data:`OFFSET`, :data:`COULOMB`: the labels of a joint's (motor's) torque offset and
  Coulomb coefficient;
* :func:`offset_instead`: the offset in place of the Coulomb coefficient where a
  combination the data do not excite holds both;
* :func:`columns_left_out`: the columns whose leaving out gives the others full rank, an
  offset in place of a Coulomb coefficient it makes a combination with;
* :func:`one_way_joints`: the joints (1-based) whose Coulomb coefficient and offset alone
  make up a combination the data do not excite.
"""

from __future__ import annotations

import re

import numpy as np
from numpy.typing import NDArray

from .solvers import unexcited_columns, unexcited_combinations

__all__ = [
    "COULOMB",
    "FRICTION_LABEL",
    "OFFSET",
    "columns_left_out",
    "offset_instead",
    "one_way_joints",
]

#: A friction coefficient of one joint (motor): ``fc3``, ``jfv7``.
FRICTION_LABEL = re.compile(r"j?f[a-z]+[0-9]+")

#: A Coulomb coefficient, sharp or smooth, at the motor (``fc3``) or at the joint (``jfc7``).
COULOMB = re.compile(r"(j?)fc([0-9]+)")
#: A torque offset of one joint (motor): ``fo3``, or ``jfo7`` at a joint beside the motors.
OFFSET = re.compile(r"j?fo[0-9]+")


def _words(combination: str) -> set[str]:
    """The friction coefficients a combination names (``"fc3 - 1*fo3"``: fc3, fo3)."""
    return set(re.findall(r"j?f[a-z]+[0-9]+", combination))


def offset_instead(label: str, combinations: tuple[str, ...]) -> str:
    """The joint's torque offset (``fo3``) in place of its Coulomb coefficient (``fc3``)
    where a combination the data do not excite holds both (a joint that never reverses:
    its Coulomb friction is a constant torque); ``label`` otherwise. Without the offset,
    the candidates that hold no offset keep their Coulomb friction (left out, it took the
    rotor inertia with it: 1.098 for 0.15 kg m^2 on a UR5 joint that turned one way);
    those with one lose nothing, the Coulomb column being that constant."""
    m = COULOMB.fullmatch(label)
    if m is None:
        return label
    offset = f"{m.group(1)}fo{m.group(2)}"
    return offset if any({label, offset} <= _words(c) for c in combinations) else label


def one_way_joints(combinations: tuple[str, ...]) -> tuple[int, ...]:
    """The joints (1-based, ascending) of the combinations that hold a joint's Coulomb
    coefficient and its offset and nothing else (``"fc4 - 1*fo4"``: 4): the joints that
    turn one way throughout the data."""
    out = set()
    for c in combinations:
        words = _words(c)
        for w in words:
            m = COULOMB.fullmatch(w)
            if m is not None and words == {w, f"{m.group(1)}fo{m.group(2)}"}:
                out.add(int(m.group(2)))
    return tuple(sorted(out))


def columns_left_out(
    R: NDArray[np.float64], scale: NDArray[np.float64], rank: int, names: tuple[str, ...]
) -> tuple[set[str], tuple[str, ...]]:
    """The columns (by ``names``) whose leaving out gives the others full rank, each
    combination the data do not excite naming one, an offset in place of a Coulomb
    coefficient it makes a combination with (:func:`offset_instead`), and those
    combinations; ``R``, ``scale`` and ``rank`` as
    :func:`~dynid.identification.solvers.unexcited_combinations` takes them."""
    combinations = unexcited_combinations(R, scale, rank, names)
    columns = unexcited_columns(R, scale, rank)
    return {offset_instead(names[i], combinations) for i in columns}, combinations
