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

The units are a revolute joint's; on an arm with prismatic joints each says theirs too
(``"N m (rail: N)"``, :func:`~dynid.model.units.unit_said`).
"""

from __future__ import annotations

from pathlib import Path
from typing import Any

from ..friction.recordings import RecordingsValidation
from ..friction.validation import Validation
from ..model.units import JointKinds, units_said
from .json_files import save_json

__all__ = ["VALIDATION_SCHEMA", "VALIDATION_UNITS", "save_validation_json"]

#: ``schema`` of validation.json.
VALIDATION_SCHEMA = "dynid-validation/1"
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
