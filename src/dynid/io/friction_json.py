"""friction.json: fitted joint friction parameters.

::

    {"schema": "dynid-friction/1", "dynid_version": "...",
     "model": "sigmoid",
     "convention": "tau = M ddq + c + g + tau_f(dq); tau_f = ...",
     "units": {"phi1": "N m", "phi2": "s/rad", "phi3": "rad/s", "rms_before": "N m", ...},
     "joints": [{"phi1": ..., "phi2": ..., "phi3": ..., "rms_before": ..., "rms_after": ...}, ...],
     "metadata": {...}}

The classical model stores ``fv``, ``fc``, ``fo`` per joint instead (Gaz et al. 2019,
eqs. 24 and 25; :mod:`dynid.friction.model`). ``rms_before``/``rms_after`` and ``identified``
(false: the joint never moved beyond its velocity noise band, its parameters are zero) are
written when a :class:`~dynid.friction.fit.FrictionFit` is saved and are optional on
reading.
"""

from __future__ import annotations

from pathlib import Path
from typing import Any

import numpy as np

from ..exceptions import DataError
from ..friction.fit import FrictionFit
from ..friction.model import ClassicalFriction, DriveFriction, FrictionModel, SigmoidFriction
from .drive_file import drive_from_record
from .json_files import load_json, save_json

__all__ = ["FORMAT", "load_friction_json", "save_friction_json"]

FORMAT = "dynid-friction/1"

_CONVENTION = {
    "sigmoid": "tau = M ddq + c + g + tau_f(dq); "
    "tau_f = phi1/(1+exp(-phi2 (dq+phi3))) - phi1/(1+exp(-phi2 phi3)) (Gaz et al. 2019, eq. 25)",
    "classical": "tau = M ddq + c + g + tau_f(dq); tau_f = fv dq + fc sign(dq) + fo "
    "(Gaz et al. 2019, eq. 24)",
}
_UNITS = {
    "sigmoid": {"phi1": "N m", "phi2": "s/rad", "phi3": "rad/s"},
    "classical": {"fv": "N m s/rad", "fc": "N m", "fo": "N m"},
}
_CLASSES: dict[str, type[SigmoidFriction] | type[ClassicalFriction]] = {
    "sigmoid": SigmoidFriction,
    "classical": ClassicalFriction,
}


def save_friction_json(
    path: str | Path,
    friction: FrictionModel | FrictionFit,
    *,
    metadata: dict[str, Any] | None = None,
) -> Path:
    """Write a friction model (or a fit, with its RMS before/after) to ``path``.

    Returns
    -------
    Path
    """
    from .. import __version__

    path = Path(path)
    fit: FrictionFit | None
    if isinstance(friction, FrictionFit):
        fit, model = friction, friction.friction
    else:
        fit, model = None, friction
    drive = model.drive if isinstance(model, DriveFriction) else None
    P = model.as_array()
    joints = []
    for j in range(model.n):
        d: dict[str, float | bool] = {k: float(P[j, i]) for i, k in enumerate(model.names)}
        if fit is not None:
            d["rms_before"] = float(fit.rms_before[j])
            d["rms_after"] = float(fit.rms_after[j])
            d["identified"] = bool(fit.identified[j])
        joints.append(d)
    units = dict(_UNITS[model.kind])
    if fit is not None:
        units.update(rms_before="N m", rms_after="N m")
    doc = {
        "schema": FORMAT,
        "dynid_version": __version__,
        "model": model.kind,
        "convention": _CONVENTION[model.kind],
        "units": units,
        "joints": joints,
        "drive": None if drive is None else drive.as_dict(),
        "metadata": metadata or {},
    }
    return save_json(path, doc)


def load_friction_json(path: str | Path) -> FrictionModel:
    """Read a friction model from ``path``.

    Raises
    ------
    DataError
        Not JSON, unknown ``model``, no ``joints``, or a joint without a parameter (the
        message names the joint and the key).
    OSError
        The file cannot be read.
    """
    path = Path(path)
    doc = load_json(path, what="friction file (dynid friction)")
    tag = doc.get("schema", doc.get("format"))  # "format": files of dynid 0.1
    if tag != FORMAT:
        raise DataError(
            f"{path.name}: not a friction file: 'schema' must be {FORMAT!r}; got {tag!r}"
        )
    kind = doc.get("model")
    if kind not in _CLASSES:
        raise DataError(f"{path.name}: 'model' must be 'sigmoid' or 'classical'; got {kind!r}")
    joints = doc.get("joints")
    if not isinstance(joints, list) or not joints:
        raise DataError(f"{path.name}: 'joints' must be a non-empty list of objects")
    cls = _CLASSES[kind]
    P = np.zeros((len(joints), 3))
    for j, d in enumerate(joints):
        for i, k in enumerate(cls.names):
            if not isinstance(d, dict) or k not in d:
                raise DataError(f"{path.name}: joint {j + 1} has no {k!r} (model {kind!r})")
            try:
                P[j, i] = float(d[k])
            except (TypeError, ValueError):
                raise DataError(
                    f"{path.name}: joint {j + 1}, {k!r} is not a number: {d[k]!r}"
                ) from None
    if not np.all(np.isfinite(P)):
        raise DataError(f"{path.name}: non-finite friction parameters")
    law = cls.from_array(P)
    if doc.get("drive") is None:
        return law
    try:
        return DriveFriction(law, drive_from_record(doc["drive"], len(joints)))
    except DataError as exc:
        raise DataError(f"{path.name}: {exc}") from exc
