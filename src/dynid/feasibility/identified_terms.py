"""What an identified model holds beside its links, carried onto a retrieval's result.

A retrieval from coefficients (:func:`~dynid.feasibility.convex.fit.retrieve_sdp`,
:func:`~dynid.feasibility.penalty.fit.retrieve`) fits the links' parameters (and the rotor
inertias in the base) to the model's coefficients; the model's other terms are not part
of that fit and are carried unchanged by :func:`with_identified_terms`: its friction (every
part of its law, offsets included, at the joints or at the motors of its drive), its joint
springs, its drive, and which retrieved parameters its data determine. The result then
predicts the model's torques, and ``feasible.json``, the robot files and
:func:`dynid.io.export.save_robot` of the result write what was identified: the one path of
``dynid retrieve`` and of the Python API.
"""

from __future__ import annotations

from dataclasses import replace
from typing import TypeVar

from ..friction.model import combined, through_drive
from ..identification.model import IdentifiedModel
from .determined import determined_by_data
from .result import FeasibleResult

__all__ = ["with_identified_terms"]

R = TypeVar("R", bound=FeasibleResult)


def with_identified_terms(result: R, model: IdentifiedModel) -> R:
    """``result`` (links retrieved from ``model``'s coefficients) with what ``model``
    identified beside the links, unchanged.

    Parameters
    ----------
    result : FeasibleResult
        A retrieval from ``model``'s coefficients.
    model : IdentifiedModel
        The identified model.

    Returns
    -------
    FeasibleResult
        Of the same type: ``friction`` the model's friction (its law's parameters per
        joint, offsets included; a :class:`~dynid.friction.model.FrictionSum` for
        friction at the motors and at the joints), its parts at the motors acting through
        the result's drive (its rotor inertias the identified ones); ``drive`` the
        result's, else the model's; ``spring`` the model's joint springs; ``determined``
        the result's, else :func:`~dynid.feasibility.determined.determined_by_data`. A
        field the result already holds is kept.
    """
    if result.spring is None and model.spring is not None:
        result = replace(result, spring=model.spring)
    if result.determined is None:
        result = replace(result, determined=determined_by_data(model))
    fr = combined(model.frictions)
    if result.friction is not None or fr is None:
        return result
    drive = result.drive or model.drive
    # at the motors, through the result's drive: its rotor inertias the identified ones
    return replace(result, friction=fr if drive is None else through_drive(fr, drive), drive=drive)
