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
without it, as those of earlier versions: 0, the plain ``sign(dq)``); a smooth law
(``smooth``, ``smooth_stribeck``) writes ``width`` instead, the width of its
``tanh(dq / width)`` (a multiple of the standstill band; files of earlier versions wrote
it as ``standstill_band``, which is read as the width). ``rms_before``/
``rms_after`` and ``identified`` (false: the joint never moved beyond its velocity noise
band, its parameters are zero) are written when a
:class:`~dynid.friction.fit.FrictionFit` is saved and are optional on reading;
``selection`` (the held-out comparison of :mod:`dynid.friction.select`) when the law was
chosen on held-out data.

Friction at the motors and at the joints together (a coupled drive's ``at:both``,
:class:`~dynid.friction.model.FrictionSum`) is ``"model": "sum"`` with its ``parts``, each
``{"model", "at": "motor" | "joint", "convention", "units", "joints"}`` holding that law's
parameters (and band) per joint, acting at the motors of ``drive`` or at the joints;
``joints`` then holds the fit's ``rms_before``/``rms_after``/``identified`` alone.
"""

from __future__ import annotations

from pathlib import Path
from typing import Any

import numpy as np

from .. import _checks
from ..exceptions import DataError, DynidError
from ..friction.fit import FrictionFit
from ..friction.laws import LAWS
from ..friction.model import FrictionModel, FrictionSum, friction_parts
from ..model.units import JointKinds, units_said
from .drive_file import drive_from_record
from .json_files import load_json
from .schema import Field, Format, Record, check, describe, fault, save_document

__all__ = ["FORMAT", "load_friction_json", "save_friction_json"]

FORMAT = "dynid-friction/1"
#: ``model`` of friction at the motors and at the joints together (module docstring).
SUM = "sum"

_CONVENTION = "tau = M ddq + c + g + tau_f(dq); "


def save_friction_json(
    path: str | Path,
    friction: FrictionModel | FrictionSum | FrictionFit,
    *,
    metadata: dict[str, Any] | None = None,
    selection: dict[str, Any] | None = None,
    robot: JointKinds | None = None,
) -> Path:
    """Write a friction model (or a fit, with its RMS before/after) to ``path``.

    ``robot``: the joints' names and kinds (a ``Robot``), the units of the friction at
    the joints said per joint kind (:func:`~dynid.model.units.unit_said`: a prismatic
    joint's ``fv`` in N s/m); None: every joint's as a revolute joint's.

    ``selection``: the held-out comparison of the candidate laws
    (:meth:`~dynid.friction.select.FrictionSelection.as_dict`), written as ``selection``.
    A :class:`~dynid.friction.model.FrictionSum` is written part by part (module
    docstring).

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
    parts = [_law_doc(p, robot) for p in friction_parts(model)]
    joints: list[dict[str, float | bool]] = (
        parts[0]["joints"] if len(parts) == 1 else [{} for _ in range(model.n)]
    )
    units: dict[str, str] = parts[0]["units"] if len(parts) == 1 else {}
    if fit is not None:
        for j, d in enumerate(joints):
            d["rms_before"] = float(fit.rms_before[j])
            d["rms_after"] = float(fit.rms_after[j])
            d["identified"] = bool(fit.identified[j])
        units.update(units_said(robot, {"rms_before": "N m", "rms_after": "N m"}))
    drive = model.drive
    doc: dict[str, Any] = {
        "schema": FORMAT,
        "dynid_version": __version__,
        "model": model.kind if len(parts) == 1 else SUM,
        "convention": parts[0]["convention"]
        if len(parts) == 1
        else _CONVENTION + "tau_f = the sum of the parts' (each at its motors or joints)",
        "units": units,
        "joints": joints,
    }
    if len(parts) > 1:
        doc["parts"] = parts
    doc |= {"drive": None if drive is None else drive.as_dict(), "metadata": metadata or {}}
    if selection is not None:
        doc["selection"] = selection
    return save_document(path, Format(FORMAT, _record(str(doc["model"])), _WHAT), doc)


def _law_doc(model: FrictionModel, robot: JointKinds | None = None) -> dict[str, Any]:
    """One law's ``model``, ``at``, ``convention``, ``units`` and ``joints`` (its
    parameters and standstill band per joint; the units of a law at the joints said per
    joint kind of ``robot``, a law at the motors' as the motors turn)."""
    law, P = model.law, model.as_array()
    band = model.band if law.standstill else None
    joints = []
    for j in range(model.n):
        d: dict[str, float | bool] = {k: float(P[j, i]) for i, k in enumerate(model.names)}
        if band is not None:
            d[law.band_key] = float(band[j])
        joints.append(d)
    units = dict(zip(law.params, law.units, strict=True))
    if band is not None:
        units[law.band_key] = "rad/s"
    if not model.at_motors:
        units = units_said(robot, units)
    return {
        "model": model.kind,
        "at": "motor" if model.at_motors else "joint",
        "convention": _CONVENTION + law.formula,
        "units": units,
        "joints": joints,
    }


def load_friction_json(path: str | Path) -> FrictionModel | FrictionSum:
    """Read a friction model from ``path`` (a sum of friction at the motors and at the
    joints: :class:`~dynid.friction.model.FrictionSum`, module docstring).

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
    if kind not in LAWS and kind != SUM:
        raise fault(path.name, "model", f"expected {describe(_MODEL)}; got {_checks.short(kind)}")
    check(doc, _record(kind), path.name)
    n = len(doc["joints"])
    drive = None
    if doc.get("drive") is not None:
        drive = drive_from_record(doc["drive"], n, source=path.name, at="drive")
    if kind != SUM:
        fr = _law_from(doc, kind, path.name)
        return fr if drive is None else fr.at(drive)
    parts = []
    for i, part in enumerate(doc["parts"]):
        where = f"parts[{i}]"
        if part.get("model") not in LAWS:
            raise fault(path.name, f"{where}.model", f"expected one of {', '.join(LAWS)}")
        check(part, _part_record(part["model"]), path.name, at=where)
        if len(part["joints"]) != n:
            raise fault(path.name, f"{where}.joints", f"expected {n} joints")
        fr = _law_from(part, part["model"], path.name)
        if part["at"] == "motor":
            if drive is None:
                raise fault(path.name, f"{where}.at", "a part at the motors needs the drive")
            fr = fr.at(drive)
        parts.append(fr)
    try:
        return FrictionSum(tuple(parts))
    except DynidError as exc:
        raise DataError(str(exc), file=path.name) from exc


def _law_from(doc: dict[str, Any], kind: str, source: str) -> FrictionModel:
    """The law ``kind`` with the parameters and bands of ``doc["joints"]``."""
    joints = doc["joints"]
    law = LAWS[kind]
    P = np.zeros((len(joints), len(law.params)))
    for j, d in enumerate(joints):
        P[j] = [d[k] for k in law.params]
    # no band: files of earlier versions, the plain sign(dq); a smooth law's width under
    # standstill_band: files of earlier versions
    band = np.array(
        [d.get(law.band_key, d.get("standstill_band", 0.0)) for d in joints], dtype=float
    )
    try:
        return law.model(P, band)
    except DynidError as exc:
        raise DataError(str(exc), file=source) from exc


_WHAT = "friction file (dynid friction)"
_MODEL = Field("string", required=True, choices=(*LAWS, SUM))


def _law_fields(kind: str) -> dict[str, Field]:
    """A joint's parameters of the law ``kind`` and its standstill band."""
    law = LAWS[kind]
    joint = {
        p: Field("number", required=True, unit=u)
        for p, u in zip(law.params, law.units, strict=True)
    }
    band = Field("number", low=0.0, unit="rad/s")
    return joint | {law.band_key: band, "standstill_band": band}  # the latter: earlier files


def _part_record(kind: str) -> Record:
    """The fields of one part of a sum (module docstring)."""
    return Record(
        {
            "model": Field("string", required=True, choices=tuple(LAWS)),
            "at": Field("string", required=True, choices=("motor", "joint")),
            "convention": Field("string"),
            "units": Field("any"),
            "joints": Field(
                "objects", required=True, non_empty=True, record=Record(_law_fields(kind))
            ),
        }
    )


def _record(kind: str) -> Record:
    """The fields of a friction file of the law ``kind``, or of a sum (module docstring)."""
    joint = {} if kind == SUM else _law_fields(kind)
    joint |= {
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
    if kind == SUM:
        top["parts"] = Field("objects", required=True, non_empty=True)
    return Record(top)
