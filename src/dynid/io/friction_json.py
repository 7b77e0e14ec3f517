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
from ..exceptions import DataError
from ..friction.fit import FrictionFit
from ..friction.laws import LAWS
from ..friction.model import FrictionModel
from .drive_file import drive_from_record
from .json_files import load_json, save_json

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
    return save_json(path, doc)


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
    doc = load_json(path, what="friction file (dynid friction)")
    tag = doc.get("schema", doc.get("format"))  # "format": files of dynid 0.1
    if tag != FORMAT:
        raise DataError(
            f"{path.name}: not a friction file: 'schema' must be {FORMAT!r}; got {tag!r}"
        )
    kind = doc.get("model")
    if kind not in LAWS:
        raise DataError(f"{path.name}: 'model' must be one of {', '.join(LAWS)}; got {kind!r}")
    unknown = sorted(set(doc) - _KEYS)
    if unknown:
        raise DataError(f"{path.name}: unknown key(s) {_checks.short(unknown)}")
    joints = doc.get("joints")
    if not isinstance(joints, list) or not joints:
        raise DataError(f"{path.name}: 'joints' must be a non-empty list of objects")
    law = LAWS[kind]
    names = law.params + ("standstill_band",)
    P = np.zeros((len(joints), len(names)))
    for j, d in enumerate(joints):
        if isinstance(d, dict):
            _check_joint(d, set(names), f"{path.name}: joint {j + 1}")
        for i, k in enumerate(names):
            if k == "standstill_band" and isinstance(d, dict) and k not in d:
                continue  # files of earlier versions: the plain sign
            if not isinstance(d, dict) or k not in d:
                raise DataError(f"{path.name}: joint {j + 1} has no {k!r} (model {kind!r})")
            P[j, i] = _checks.number(d[k], f"{path.name}: joint {j + 1}, {k!r}", DataError)
    if not np.all(np.isfinite(P)):
        raise DataError(f"{path.name}: non-finite friction parameters")
    if np.any(P[:, -1] < 0):
        raise DataError(f"{path.name}: 'standstill_band' must be >= 0")
    fr = law.model(P[:, :-1], P[:, -1])
    if doc.get("drive") is None:
        return fr
    try:
        return fr.at(drive_from_record(doc["drive"], len(joints)))
    except DataError as exc:
        raise DataError(f"{path.name}: {exc}") from exc


#: the keys :func:`save_friction_json` writes (``format``: files of dynid 0.1)
_KEYS = {"schema", "format", "dynid_version", "model", "convention", "units", "joints"}
_KEYS |= {"drive", "metadata", "selection"}
#: the keys of a joint beside its law's parameters and ``standstill_band``
_FIT_KEYS = {"rms_before", "rms_after", "identified"}


def _check_joint(d: dict[str, Any], params: set[str], where: str) -> None:
    """Refuse a joint's unknown key or a record of the fit of the wrong type."""
    unknown = sorted(set(d) - params - _FIT_KEYS)
    if unknown:
        raise DataError(f"{where}: unknown key(s) {_checks.short(unknown)}")
    for k in ("rms_before", "rms_after"):
        if k in d:
            _checks.number(d[k], f"{where}, {k!r}", DataError)
    if "identified" in d and not isinstance(d["identified"], bool):
        raise DataError(
            f"{where}, 'identified' must be true or false; got {_checks.short(d['identified'])}"
        )
