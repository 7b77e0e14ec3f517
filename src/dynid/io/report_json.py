"""``report.json``: what a retrieval or a consistent fit reports, JSON-ready.

One converter for every method, :func:`report_to_dict` over the shared result
(:class:`~dynid.feasibility.result.FeasibleResult`), written by :func:`save_report_json`.
The shared part: the method, what was fitted, the relative residual on the coefficients,
every constraint with its margin, each link's pseudo-inertia margin, the friction
identified with the links, the held-out judgement, the run time, the seed, the notes, the
bounds (:mod:`dynid.io.bounds_file`). Each method adds its own entries through
:meth:`~dynid.feasibility.result.FeasibleResult.report_fields` (the penalty method's stage
costs and runs; the convex method's prior, weight and solver).
"""

from __future__ import annotations

from pathlib import Path
from typing import Any

from .. import __version__
from ..feasibility.constraints import FeasibilityReport
from ..feasibility.result import FeasibleResult
from ..friction.model import Friction, FrictionSum, friction_parts
from .bounds_file import bounds_to_dict
from .json_files import finite_or_none, save_json

__all__ = ["REPORT_SCHEMA", "report_to_dict", "save_report_json"]

REPORT_SCHEMA = "dynid-feasibility-report/1"

_UNITS = {
    "relative_residual": "1",
    "margin": "per constraint (see unit)",
    "pseudo_inertia_margin": "1",
    "run_time_s": "s",
}


def _report_constraints(report: FeasibilityReport) -> list[dict[str, Any]]:
    return [
        {
            "name": c.name,
            "link": c.link,
            "margin": finite_or_none(c.margin),
            "unit": c.unit,
            "satisfied": bool(c.satisfied),
        }
        for c in report.constraints
    ]


def report_to_dict(result: FeasibleResult) -> dict[str, Any]:
    """Everything a retrieval or a consistent fit reports, JSON-ready.

    Parameters
    ----------
    result : FeasibleResult
        A :class:`~dynid.feasibility.convex.result.ConsistentResult` or a
        :class:`~dynid.feasibility.penalty.result.RetrievalResult`.

    Returns
    -------
    dict
        The shared keys: ``schema``, ``dynid_version``, ``method`` (``"sdp"`` or
        ``"penalty"``), ``kind``, ``robot``, ``link_names``, ``relative_residual`` [1],
        ``feasible``, ``min_margin`` (per constraint name), ``constraints`` (name, link,
        margin, unit, satisfied), ``pseudo_inertia_margin`` (``lambda_min(J)/tr(J)`` per
        link [1]), ``friction`` (the friction identified with the links: ``model``, its law,
        and the law's parameters, ``fv, fc, fo`` of the classical law; or None), ``heldout``
        (the held-out judgement, or None), ``determined`` (of an identified model's
        coefficients: ``link_base_parameters``, ``rotor_inertias``, each standard
        parameter's ``source``, ``"data"``, ``"sum"`` or ``"prior"``, and per motor
        ``rotor_inertia`` [kg m^2] with its ``rotor_source``; or None), ``run_time_s`` [s],
        ``seed``, ``notes``, ``total_mass`` [kg], ``bounds`` (a bounds file's content) and
        ``units``; then the method's own
        (:meth:`~dynid.feasibility.result.FeasibleResult.report_fields`), their numbers that
        may have no value written None. A convex fit's ``weight_search`` is the search
        that chose its weight, and ``weight_search_on`` says on what: ``"heldout"``
        (``[w, held-out error %]``, as ``heldout.weight_search``; the convex search on the
        training data is then not run) or ``"training"`` (``[w, residual_ratio]``)."""
    rep = result.report
    fr = result.friction
    d: dict[str, Any] = {
        "schema": REPORT_SCHEMA,
        "dynid_version": __version__,
        "method": result.method,
        "kind": result.kind,
        "robot": result.robot.name,
        "link_names": list(result.robot.link_names[1:]),
        "relative_residual": finite_or_none(result.relative_residual),
        "feasible": bool(result.feasible),
        "min_margin": {name: finite_or_none(rep.min_margin(name)) for name in rep.names},
        "constraints": _report_constraints(rep),
        "pseudo_inertia_margin": finite_or_none(result.pseudo_inertia_margin),
        "friction": None if fr is None else _friction_record(fr),
        "heldout": None if result.heldout is None else result.heldout.as_dict(),
        "determined": _determined_record(result),
        "run_time_s": float(result.run_time),
        "seed": result.seed,
        "notes": list(result.notes),
        "total_mass": None if result.total_mass is None else list(result.total_mass),
        "bounds": bounds_to_dict(result.bounds),
    }
    nullable = result.nullable_fields
    d |= {k: finite_or_none(v) if k in nullable else v for k, v in result.report_fields().items()}
    d["units"] = _UNITS | dict(result.field_units)
    if "weight_search" in d:  # the convex method's: the search that chose the weight
        held = d["heldout"]["weight_search"] if d["heldout"] is not None else []
        on = "heldout" if held and not d["weight_search"] else "training"
        d["weight_search"] = held if on == "heldout" else d["weight_search"]
        d["weight_search_on"] = on
    return d


def save_report_json(path: str | Path, result: FeasibleResult, **extra: Any) -> Path:
    """Write ``report.json`` (:func:`report_to_dict` plus ``extra`` entries, such as
    ``source``); returns the path.

    Raises
    ------
    NonFiniteError
        A NaN or infinite number where the report admits none (named).
    """
    return save_json(path, report_to_dict(result) | extra)


def _determined_record(result: FeasibleResult) -> dict[str, Any] | None:
    """:meth:`~dynid.feasibility.determined.Determined.as_dict` with the rotor inertias
    retrieved [kg m^2] (None without a determination)."""
    det = result.determined
    if det is None:
        return None
    ia = result.rotor_inertia
    return det.as_dict() | {"rotor_inertia": None if ia is None else [float(x) for x in ia]}


def _friction_record(fr: Friction | FrictionSum) -> dict[str, Any]:
    """``{"model": law, name: per-joint values}`` of the law's parameters (``fv, fc, fo``
    of the classical or the smooth law, ...); of friction at the motors and at the joints,
    the part at the joints under ``"joints"``."""
    parts = friction_parts(fr)

    def record(f: Friction) -> dict[str, Any]:
        cols = {k: [float(x) for x in f.params[:, j]] for j, k in enumerate(f.names)}
        return {"model": f.kind} | cols

    out = record(parts[0])
    if len(parts) > 1:
        out["joints"] = record(parts[1])
    return out
