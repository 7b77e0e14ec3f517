"""friction.json: fitted joint friction parameters.

::

    {"schema": "dynid-friction/1", "dynid_version": "...",
     "model": "sigmoid",
     "convention": "tau = M ddq + c + g + tau_f(dq); tau_f = ...",
     "units": {"phi1": "N m", "phi2": "s/rad", "phi3": "rad/s", "rms_before": "N m", ...},
     "joints": [{"phi1": ..., "phi2": ..., "phi3": ..., "rms_before": ..., "rms_after": ...}, ...],
     "selection": {...},
     "metadata": {...}}

``model`` is a law of the registry (:mod:`dynid.friction.laws`: ``none``, ``classical``,
``smooth``, ``asymmetric``, ``stribeck``, ``sigmoid``) and each joint holds that law's
parameters (``fv``, ``fc``, ``fo`` for the classical law, ...). ``standstill_band``
[rad/s] per joint is the velocity band inside which Coulomb friction is off (files
without it, as those of earlier versions: 0, the plain ``sign(dq)``). ``rms_before``/
``rms_after`` and ``identified`` (false: the joint never moved beyond its velocity noise
band, its parameters are zero) are written when a
:class:`~dynid.friction.fit.FrictionFit` is saved and are optional on reading;
``selection`` (the held-out comparison of :mod:`dynid.friction.select`) when the law was
chosen on held-out data.
"""

from __future__ import annotations

from pathlib import Path
from typing import Any

import numpy as np

from .. import _checks
from ..exceptions import DataError, DynidError
from ..friction.fit import FrictionFit
from ..friction.laws import LAWS
from ..friction.model import FrictionModel
from .drive_file import drive_from_record
from .json_files import load_json
from .schema import Field, Format, Record, check, describe, fault, save_document

__all__ = ["FORMAT", "load_friction_json", "save_friction_json"]

FORMAT = "dynid-friction/1"

_CONVENTION = "tau = M ddq + c + g + tau_f(dq); "


def save_friction_json(
    path: str | Path,
    friction: FrictionModel | FrictionFit,
    *,
    metadata: dict[str, Any] | None = None,
    selection: dict[str, Any] | None = None,
) -> Path:
    """Write a friction model (or a fit, with its RMS before/after) to ``path``.

    ``selection``: the held-out comparison of the candidate laws
    (:meth:`~dynid.friction.select.FrictionSelection.as_dict`), written as ``selection``.

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
    drive, law, P = model.drive, model.law, model.as_array()
    band = model.band if law.standstill else None
    joints = []
    for j in range(model.n):
        d: dict[str, float | bool] = {k: float(P[j, i]) for i, k in enumerate(model.names)}
        if band is not None:
            d["standstill_band"] = float(band[j])
        if fit is not None:
            d["rms_before"] = float(fit.rms_before[j])
            d["rms_after"] = float(fit.rms_after[j])
            d["identified"] = bool(fit.identified[j])
        joints.append(d)
    units = dict(zip(law.params, law.units, strict=True))
    if band is not None:
        units["standstill_band"] = "rad/s"
    if fit is not None:
        units.update(rms_before="N m", rms_after="N m")
    doc = {
        "schema": FORMAT,
        "dynid_version": __version__,
        "model": model.kind,
        "convention": _CONVENTION + law.formula,
        "units": units,
        "joints": joints,
        "drive": None if drive is None else drive.as_dict(),
        "metadata": metadata or {},
    }
    if selection is not None:
        doc["selection"] = selection
    return save_document(path, Format(FORMAT, _record(model.kind), _WHAT), doc)


def load_friction_json(path: str | Path) -> FrictionModel:
    """Read a friction model from ``path``.

    Raises
    ------
    DataError
        Not JSON, an unknown key, unknown ``model``, no ``joints``, a joint without a
        parameter or with one that is not a finite number (a boolean or a string included;
        the message names the joint and the key).
    OSError
        The file cannot be read.
    """
    path = Path(path)
    doc = load_json(path, what=_WHAT)
    tag = doc.get("schema", doc.get("format"))  # "format": files of dynid 0.1
    if tag != FORMAT:
        raise fault(path.name, "schema", f"expected {FORMAT!r} ({_WHAT}); got {_checks.short(tag)}")
    kind = doc.get("model")
    if kind not in LAWS:
        raise fault(path.name, "model", f"expected {describe(_MODEL)}; got {_checks.short(kind)}")
    check(doc, _record(kind), path.name)
    joints = doc["joints"]
    law = LAWS[kind]
    P = np.zeros((len(joints), len(law.params)))
    for j, d in enumerate(joints):
        P[j] = [d[k] for k in law.params]
    # no standstill_band: files of earlier versions, the plain sign(dq)
    band = np.array([d.get("standstill_band", 0.0) for d in joints], dtype=float)
    try:
        fr = law.model(P, band)
    except DynidError as exc:
        raise DataError(str(exc), file=path.name) from exc
    if doc.get("drive") is None:
        return fr
    return fr.at(drive_from_record(doc["drive"], len(joints), source=path.name, at="drive"))


_WHAT = "friction file (dynid friction)"
_MODEL = Field("string", required=True, choices=tuple(LAWS))


def _record(kind: str) -> Record:
    """The fields of a friction file of the law ``kind`` (module docstring)."""
    law = LAWS[kind]
    joint = {
        p: Field("number", required=True, unit=u)
        for p, u in zip(law.params, law.units, strict=True)
    }
    joint |= {
        "standstill_band": Field("number", low=0.0, unit="rad/s"),
        "rms_before": Field("number", unit="N m"),
        "rms_after": Field("number", unit="N m"),
        "identified": Field("bool"),
    }
    top = {
        "schema": Field("string"),
        "format": Field("string"),  # files of dynid 0.1
        "dynid_version": Field("string"),
        "model": _MODEL,
        "convention": Field("string"),
        "units": Field("any"),
        "joints": Field("objects", required=True, non_empty=True, record=Record(joint)),
        "drive": Field("object", nullable=True),
        "metadata": Field("any"),
        "selection": Field("any"),
    }
    return Record(top)
