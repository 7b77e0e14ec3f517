"""validation.json: a model's torques compared with a measured log (schema
``dynid-validation/1``; written by ``dynid validate`` and the demo's friction stage).

::

    {"schema": "dynid-validation/1",
     "rms": [...], "mse": [...], "relative_error_percent": x,
     "relative_error_percent_per_joint": [...], "n_samples": N, "friction_model": ...,
     "friction_terms": "friction" | "offsets" | "friction and offsets",
     "without_friction": {...}, "with_friction": {...},  (the model without and with them)
     "recordings": [{"file": ..., "pieces": k, "rms": [...], ...}, ...],  (several recordings)
     ...the caller's keys (model, friction_source, data, cutoff_hz; seed)...,
     "units": {"rms": "N m", "mse": "N^2 m^2", "relative_error_percent": "%"}}

On static data (``dynid validate`` given ``q, M, g``), schema
``dynid-static-validation/1``: the model's ``M`` and ``g`` against the file's
(:meth:`~dynid.identification.static_validation.StaticValidation.as_dict`: the relative
errors of M, g and both, ``g_rms``, ``m_rms``, per joint, the noise floor and the
verdict), then ``model``, ``data``, ``joint_names`` and ``units``.

The units are a revolute joint's; on an arm with prismatic joints each says theirs too
(``"N m (rail: N)"``, :func:`~dynid.model.units.unit_said`).
"""

from __future__ import annotations

from pathlib import Path
from typing import Any

from ..friction.recordings import RecordingsValidation
from ..friction.validation import Validation
from ..identification.static_validation import StaticValidation
from ..model.units import JointKinds, units_said
from .json_files import save_json

__all__ = [
    "STATIC_VALIDATION_SCHEMA",
    "VALIDATION_SCHEMA",
    "VALIDATION_UNITS",
    "save_static_validation_json",
    "save_validation_json",
]

#: ``schema`` of validation.json.
VALIDATION_SCHEMA = "dynid-validation/1"
#: ``schema`` of validation.json on static data.
STATIC_VALIDATION_SCHEMA = "dynid-static-validation/1"
#: ``units`` of validation.json on static data.
STATIC_VALIDATION_UNITS = {"g_rms": "N m", "m_rms": "kg m^2", "errors": "%"}
#: ``units`` of validation.json.
VALIDATION_UNITS = {"rms": "N m", "mse": "N^2 m^2", "relative_error_percent": "%"}


def save_validation_json(
    path: str | Path,
    validation: Validation | RecordingsValidation,
    *,
    robot: JointKinds | None = None,
    **metadata: Any,
) -> Path:
    """Write ``validation`` (:meth:`~dynid.friction.validation.Validation.as_dict`), then
    ``metadata`` (the files compared, the cut-off, the seed: JSON values), then ``units``.

    Parameters
    ----------
    path : str or Path
        The file to write (atomically).
    validation : Validation or RecordingsValidation
        Errors of the model without and with friction (pooled over several recordings,
        and per recording).
    robot : Robot, optional
        The model's robot: the units said per joint kind (a prismatic joint's in N);
        None: a revolute joint's.
    **metadata
        Extra top-level keys, JSON values (``model``, ``friction_source``, ``data``,
        ``cutoff_hz``, ``seed``).

    Returns
    -------
    Path
        ``path``.

    Raises
    ------
    NonFiniteError
        A NaN or infinite number (the message names the file and the key).
    """
    doc = {**validation.as_dict(), **metadata, "units": units_said(robot, VALIDATION_UNITS)}
    return save_json(path, doc, schema=VALIDATION_SCHEMA)


def save_static_validation_json(
    path: str | Path,
    result: StaticValidation,
    *,
    robot: JointKinds,
    model: str,
    data: str,
) -> Path:
    """Write a static validation (schema ``dynid-static-validation/1``): ``result``'s
    errors and verdict, the ``model`` and ``data`` compared, ``robot``'s joint names and
    the units per joint kind; returns ``path``."""
    doc = {
        **result.as_dict(),
        "model": model,
        "data": data,
        "joint_names": list(robot.joint_names),
        "units": units_said(robot, STATIC_VALIDATION_UNITS, ("g_rms",)),
    }
    return save_json(path, doc, schema=STATIC_VALIDATION_SCHEMA)
