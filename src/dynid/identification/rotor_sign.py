"""Rotor inertias (armatures) identified below zero: what no rotor has, named with what
likely causes it.

A rotor inertia ``I_a`` [kg m^2] is a mass property, never negative. A fit that gives one
below zero by more than its standard deviation takes up something else in its column
``ddq`` (``K^T diag(I_a) K ddq`` with a drive): an effort read at the wrong scale on that
joint (a guessed torque constant, a torque sensor's scale: their fitted factors are the
held-out verdict's, :mod:`~dynid.identification.drive_gains`), or a term the model lacks
that follows the acceleration there; within its standard deviation of zero the log does
not determine it. A simulated Panda logged through joint 4's torque constant guessed 0.7
times the true one, fitted without friction, gave ``Ia4 = -0.545 +- 0.088 kg m^2``.
"""

from __future__ import annotations

import warnings

import numpy as np

from .._checks import caller_level
from ..exceptions import DynidWarning
from ..model.drive import Drive
from .model import IdentifiedModel

__all__ = [
    "negative_inertias",
    "negative_rotor_inertias",
    "per_joint",
    "warned_negative_inertias",
]


def per_joint(drive: Drive | None) -> bool:
    """Whether each motor of ``drive`` turns its own joint one to one (no drive, or a
    transmission ``K`` with ``|K| = 1``: a gear ratio of 1 and no coupling), so that a
    motor's quantities are said per joint."""
    if drive is None:
        return True
    K = np.asarray(drive.transmission, dtype=np.float64)
    return bool(np.array_equal(np.abs(K), np.eye(K.shape[0])))


def negative_rotor_inertias(model: IdentifiedModel) -> tuple[tuple[str, float, float], ...]:
    """Each rotor inertia of ``model`` identified below zero (a term's ``inertia``
    coefficients, kept and not regrouped): its label, value [kg m^2] and standard
    deviation [kg m^2]; empty for none."""
    found = []
    for t in model.terms.values():
        if t.term.inertia(np.zeros(len(t.labels))) is None:
            continue
        kept = np.asarray(t.kept, dtype=bool)
        for k in np.flatnonzero(kept & (np.asarray(t.values) < 0)):
            found.append((t.labels[k], float(t.values[k]), float(t.std[k])))
    return tuple(found)


def negative_inertias(model: IdentifiedModel) -> tuple[str, ...]:
    """One sentence per rotor inertia of ``model`` identified below zero
    (:func:`negative_rotor_inertias`), naming the joint (a motor of a geared or coupled
    drive: the motor), the value, its standard deviation and the likely cause (module
    docstring); empty for none."""
    said = []
    unit = "joint" if per_joint(model.drive) else "motor"
    for label, value, std in negative_rotor_inertias(model):
        index = _index(label)
        where = f"{label}" + ("" if index is None else f" of {unit} {index}")
        if np.isfinite(std) and abs(value) > std:
            cause = (
                "an effort read at the wrong scale on that "
                f"{unit} (its torque_constant or torque sensor's scale: see the held-out "
                "verdict's gains), or a term the model lacks taken up by it"
            )
        else:
            cause = "within its standard deviation of zero: the log does not determine it"
        said.append(
            f"the identified rotor inertia {where} is negative ({value:.3g} kg m^2, std "
            f"{std:.2g}), which no rotor has: {cause}"
        )
    return tuple(said)


def warned_negative_inertias(model: IdentifiedModel) -> tuple[str, ...]:
    """:func:`negative_inertias` of ``model``, each also a
    :class:`~dynid.exceptions.DynidWarning`; the sentences for the model's notes."""
    said = negative_inertias(model)
    for line in said:
        warnings.warn(line, DynidWarning, stacklevel=caller_level())
    return said


def _index(label: str) -> int | None:
    """The joint or motor number (from 1) a label ends in (``Ia4`` -> 4), or None."""
    digits = label[len(label.rstrip("0123456789")) :]
    return int(digits) if digits else None
