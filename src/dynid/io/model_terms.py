"""The model terms of ``identification.json`` (:mod:`dynid.io.model_json`): the ``terms``
list, and the friction of files written before it.

Each term is written with its ``kind`` (a key of :data:`~dynid.regressors.terms.TERM_KINDS`,
which reads it back), its own ``definition``, ``labels``, ``values``, ``std`` (``null``
where undefined) and ``kept``. A file without ``terms`` holds its friction as the law's
parameters (``friction``, n rows) with the coefficients' labels, standard deviations and
kept flags in ``metadata`` (``friction_labels``, ``friction_std``, ``friction_kept``,
``friction_band``, ``friction_law``); its rotor inertias follow from the drive.
"""

from __future__ import annotations

from collections.abc import Mapping
from typing import Any

import numpy as np

from .. import _checks
from ..exceptions import DynidError
from ..identification.model import IdentifiedModel, IdentifiedTerm
from ..model.drive import Drive
from ..regressors.terms import FRICTION_PARTS, TERM_KINDS, LinearFriction, term_from_definition
from .json_files import finite_or_none
from .schema import Field, Record, fault

__all__ = [
    "FRICTION_LAWS",
    "TERM_RECORD",
    "friction_metadata",
    "older_terms",
    "terms_from_list",
    "terms_to_list",
]

#: The parameters per joint of each law a file's ``friction`` may hold.
FRICTION_LAWS = {"classical": 3, "smooth": 3, "quadratic": 4, "stribeck": 5}
FRICTION_LAWS["smooth_stribeck"] = 5
#: One entry of ``terms``.
TERM_RECORD = Record(
    {
        "name": Field("string", required=True),
        "kind": Field("string", required=True, choices=tuple(TERM_KINDS)),
        "definition": Field("object", required=True),
        "labels": Field("strings", required=True),
        "values": Field("numbers", required=True),
        "std": Field("numbers", required=True, null_items=True),
        "kept": Field("bools", required=True),
        "regrouped_in": Field("strings"),
    }
)


def terms_to_list(model: IdentifiedModel) -> list[dict[str, Any]]:
    """The ``terms`` of ``model``, JSON-ready, in order; a term in the base with
    coefficients regrouped with link inertias also names, per coefficient, the base
    parameters that hold it (``regrouped_in``: ``"beta1"``, ``""`` where none)."""
    out = []
    for name, t in model.terms.items():
        rec = {
            "name": t.term.name,
            "kind": t.term.kind,
            "definition": dict(t.term.definition()),
            "labels": list(t.labels),
            "values": [float(x) for x in t.values],
            "std": [finite_or_none(x) for x in t.std],
            "kept": [bool(x) for x in t.kept],
        }
        held = model.regrouped_in(name)
        if any(held):
            rec["regrouped_in"] = list(held)
        out.append(rec)
    return out


def friction_metadata(model: IdentifiedModel) -> dict[str, Any]:
    """The ``metadata`` keys of the appended terms' coefficients that earlier files wrote:
    ``friction_labels``, ``friction_std``, ``friction_kept``, and with one friction term its
    ``friction_band`` and ``friction_law``."""
    app = model.appended
    if not app:
        return {}
    out: dict[str, Any] = {
        "friction_labels": [lab for t in app for lab in t.labels],
        "friction_std": [finite_or_none(x) for t in app for x in t.std],
        "friction_kept": [bool(x) for t in app for x in t.kept],
    }
    fr = model.frictions
    if len(fr) == 1:
        if np.any(fr[0].band):
            out["friction_band"] = [float(x) for x in fr[0].band]
        if fr[0].law != "classical":
            out["friction_law"] = fr[0].law
    return out


def terms_from_list(
    records: list[Mapping[str, Any]], drive: Drive | None, n: int, source: str
) -> dict[str, IdentifiedTerm]:
    """The ``terms`` of a file, each rebuilt by its kind (:data:`~dynid.regressors.terms.
    TERM_KINDS`) and checked against its labels."""
    out = {}
    for k, rec in enumerate(records):
        at = f"terms[{k}]"
        try:
            term = term_from_definition(rec["kind"], rec["name"], rec["definition"], drive, n)
        except (DynidError, TypeError, ValueError, KeyError) as exc:
            raise fault(source, f"{at}.definition", f"malformed ({exc})") from exc
        if tuple(rec["labels"]) != term.labels:
            want = f"the labels of its definition {list(term.labels)}"
            raise fault(
                source, f"{at}.labels", f"expected {want}; got {_checks.short(rec['labels'])}"
            )
        p = len(term.labels)
        for key in ("values", "std", "kept"):
            if len(rec[key]) != p:
                raise fault(
                    source, f"{at}.{key}", f"expected {p} entries (labels); got {len(rec[key])}"
                )
        std = np.array([_float(x) for x in rec["std"]])
        out[term.name] = IdentifiedTerm(
            term, np.array(rec["values"], float), std, np.array(rec["kept"], bool)
        )
    return out


def older_terms(
    friction: Any, metadata: Mapping[str, Any], drive: Drive | None, n: int, source: str
) -> dict[str, IdentifiedTerm]:
    """The friction term of a file without ``terms``: its law's parameters (n, k) in
    ``friction`` and its coefficients' labels, std and kept flags in ``metadata``."""
    if friction is None:
        return {}
    law = metadata.get("friction_law", "classical")
    k = FRICTION_LAWS[law]
    if any(len(row) != k for row in friction):
        want = f"null or {n} rows of the {law} law's {k} parameters"
        raise fault(source, "friction", f"expected {want}; got {_checks.short(friction)}")
    P = np.array(friction, dtype=np.float64).reshape(n, k)
    labels = [str(x) for x in metadata.get("friction_labels") or ()]
    if not labels:
        labels = [f"{c}{j + 1}" for j in range(n) for c in ("fv", "fc", "fo")]
    smooth = law in ("smooth", "smooth_stribeck")
    part = {"fv": "viscous", "fc": "smooth" if smooth else "coulomb"}
    part |= {"fq": "quadratic", "fsp": "stribeck", "fo": "offset"}
    try:
        held = [(part[lab.rstrip("0123456789")], int(lab.lstrip("fvcqspo")) - 1) for lab in labels]
    except (KeyError, ValueError) as exc:
        raise fault(source, "metadata.friction_labels", f"malformed ({exc})") from exc
    parts = tuple(p for p in FRICTION_PARTS if any(h[0] == p for h in held))
    mask = tuple((p, j) in held for j in range(n) for p in parts)
    band = tuple(_float(x) for x in metadata.get("friction_band") or ())
    at = Drive.identity(n) if drive is None else drive
    term = LinearFriction(
        at,
        parts=parts,
        band=() if smooth else band,
        width=band if smooth else (),
        vst=_vsts(P[:, 3]) if law.endswith("stribeck") else 0.0,
        mask=() if all(mask) else mask,
    )
    p = len(term.labels)
    std = [_float(x) for x in metadata.get("friction_std") or ()] or [np.nan] * p
    kept = [bool(x) for x in metadata.get("friction_kept") or ()] or [True] * p
    if len(std) != p or len(kept) != p:
        raise fault(source, "metadata.friction_std", f"expected {p} entries (friction_labels)")
    return {term.name: IdentifiedTerm(term, term.values_of(P), np.array(std), np.array(kept))}


def _vsts(v: Any) -> tuple[float, ...]:
    """The Stribeck velocity [rad/s] of each joint of a law's parameters, a joint left
    unidentified (0: it never moved) at the largest."""
    v = np.asarray(v, dtype=np.float64)
    return tuple(float(x) for x in np.where(v > 0, v, np.max(v)))


def _float(x: Any) -> float:
    """A checked number; ``null`` as NaN."""
    return float("nan") if x is None else float(x)
