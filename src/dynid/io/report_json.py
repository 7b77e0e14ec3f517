"""``report.json``: what a retrieval or a consistent fit reports, JSON-ready.

:func:`report_to_dict` (the penalty method) and :func:`consistent_report_to_dict` (the
convex method), written by :func:`save_report_json`: the relative residual on the
coefficients, every constraint with its margin, the run time, the seed, the options, the
bounds (:mod:`dynid.io.bounds_file`) and what each method adds (the penalty method's stage
costs and runs; the convex method's prior, weight and held-out judgement).
"""

from __future__ import annotations

from pathlib import Path
from typing import Any

import numpy as np

from .. import __version__
from ..feasibility.constraints import FeasibilityReport
from ..feasibility.retrieve import RetrievalResult
from ..feasibility.sdp import ConsistentResult
from ..model.inertia import inertial_from_phi
from .bounds_file import bounds_to_dict
from .json_files import finite_or_none, save_json

__all__ = ["REPORT_SCHEMA", "consistent_report_to_dict", "report_to_dict", "save_report_json"]

REPORT_SCHEMA = "dynid-feasibility-report/1"


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


def report_to_dict(result: RetrievalResult) -> dict[str, Any]:
    """Everything a retrieval reports, JSON-ready.

    Keys: ``relative_residual``, ``cost``, ``feasible``, ``min_margin`` (per constraint
    name), ``constraints`` (name, link, margin, unit, satisfied), ``stage_costs``,
    ``xi``, ``run_time_s``, ``seed``, ``workers``, ``best_run``, ``runs`` (per run:
    final cost, stage costs, relative residual, feasible, violation, evaluations, time),
    ``options``, ``total_mass``, ``bounds``, ``kind``, ``link_names``.
    """
    opts = result.options
    rep = result.report
    return {
        "schema": REPORT_SCHEMA,
        "dynid_version": __version__,
        "kind": result.kind,
        "robot": result.robot.name,
        "link_names": list(result.robot.link_names[1:]),
        "relative_residual": finite_or_none(result.relative_residual),
        "cost": finite_or_none(result.cost),
        "feasible": bool(result.feasible),
        "min_margin": {name: finite_or_none(rep.min_margin(name)) for name in rep.names},
        "constraints": _report_constraints(rep),
        "stage_costs": [finite_or_none(x) for x in result.stage_costs],
        "xi": list(opts.schedule()),
        "run_time_s": float(result.run_time),
        "seed": result.seed,
        "workers": int(result.workers),
        "best_run": int(result.best_run),
        "n_feasible_runs": int(result.n_feasible_runs),
        "runs": [
            {
                "index": r.index,
                "cost": finite_or_none(r.stage_costs[-1]),
                "stage_costs": [finite_or_none(x) for x in r.stage_costs],
                "relative_residual": finite_or_none(r.relative_residual),
                "feasible": bool(r.feasible),
                "violation": finite_or_none(r.violation),
                "n_evaluations": int(r.n_evaluations),
                "time_s": float(r.time),
            }
            for r in result.runs
        ],
        "options": {
            "runs": opts.runs,
            "stages": opts.stages,
            "anneal_maxiter": opts.anneal_maxiter,
            "anneal_temperature": opts.anneal_temperature,
            "local_maxiter": opts.local_maxiter,
            "margin": opts.margin,
            "scale_floor": opts.scale_floor,
            "tol": opts.tol,
            "residual_tol": opts.residual_tol,
        },
        "total_mass": None if result.total_mass is None else list(result.total_mass),
        "bounds": bounds_to_dict(result.bounds),
        "units": {
            "relative_residual": "1",
            "margin": "per constraint (see unit)",
            "run_time_s": "s",
        },
    }


def consistent_report_to_dict(result: ConsistentResult) -> dict[str, Any]:
    """Everything a convex retrieval or consistent identification reports, JSON-ready.

    Keys: ``method`` ("sdp"), ``kind``, ``fit`` ("equality" or "weighted"), ``prior``
    (source, repaired links, notes), ``prior_weight`` and the automatic ``weight_search``
    (``[w, residual_ratio]``), ``relative_residual`` (on the coefficients),
    ``residual_ratio`` (data residual RMS over the unconstrained fit's), ``feasible``,
    ``min_margin`` and ``constraints`` (every margin, with ``pseudo_inertia`` as
    ``lambda_min(J)/tr(J)``), ``pseudo_inertia_margin`` and ``divergence`` per link,
    ``distance_to_prior`` (mass [kg], CoM [m] per link), ``friction`` (classical, when
    identified), ``solver``, ``status``, ``run_time_s``, ``notes``, ``options``,
    ``total_mass``, ``bounds``; ``heldout`` (training and held-out torque errors of least
    squares and of the consistent fit, the weight search ``[w, held-out error %]``, the
    acceptance; None without held-out folds) and ``on_bound`` (parameters decided by a
    bound, not the data).
    """
    rep = result.report
    o = result.options
    pm, pc, _ = inertial_from_phi(result.prior.phi)
    return {
        "schema": REPORT_SCHEMA,
        "dynid_version": __version__,
        "method": result.method,
        "kind": result.kind,
        "fit": result.fit,
        "robot": result.robot.name,
        "link_names": list(result.robot.link_names[1:]),
        "prior": {
            "source": result.prior.source,
            "repaired_links": list(result.prior.repaired),
            "mass": [float(x) for x in pm],
        },
        "prior_weight": finite_or_none(result.prior_weight),
        "weight_search": [[finite_or_none(w), finite_or_none(r)] for w, r in result.weight_search],
        "relative_residual": finite_or_none(result.relative_residual),
        "residual_ratio": finite_or_none(result.residual_ratio),
        "feasible": bool(result.feasible),
        "min_margin": {name: finite_or_none(rep.min_margin(name)) for name in rep.names},
        "constraints": _report_constraints(rep),
        "pseudo_inertia_margin": [finite_or_none(x) for x in result.pseudo_inertia_margin],
        "divergence": [finite_or_none(x) for x in result.divergence],
        "distance_to_prior": {
            "mass": [float(x) for x in np.abs(result.mass - pm)],
            "com": [float(x) for x in np.linalg.norm(result.com - pc, axis=1)],
        },
        "friction": None
        if result.friction is None
        else {
            k: [float(x) for x in result.friction[:, j]] for j, k in enumerate(("fv", "fc", "fo"))
        },
        "solver": result.solver,
        "status": result.status,
        "run_time_s": float(result.run_time),
        "seed": result.seed,
        "notes": list(result.notes),
        "heldout": None if result.heldout is None else result.heldout.as_dict(),
        "on_bound": list(result.on_bound),
        "options": {
            "objective": o.objective,
            "prior_weight": o.prior_weight,
            "residual_increase": o.residual_increase,
            "margin": o.margin,
            "fit": o.fit,
            "mass_factor": o.mass_factor,
            "residual_tol": o.residual_tol,
            "heldout_tol": o.heldout_tol,
            "tol": o.tol,
        },
        "total_mass": None if result.total_mass is None else list(result.total_mass),
        "bounds": bounds_to_dict(result.bounds),
        "units": {
            "relative_residual": "1",
            "residual_ratio": "1",
            "margin": "per constraint (see unit)",
            "pseudo_inertia_margin": "1",
            "run_time_s": "s",
        },
    }


def save_report_json(path: str | Path, result: Any, **extra: Any) -> Path:
    """Write ``report.json`` (:func:`report_to_dict` or :func:`consistent_report_to_dict`,
    plus ``extra`` entries)."""
    d = (
        consistent_report_to_dict(result)
        if isinstance(result, ConsistentResult)
        else report_to_dict(result)
    )
    d.update(extra)
    return save_json(path, d)
