"""What the convex method returns (:class:`ConsistentResult`) and how a solution becomes
one: the report's constraints, the data fit, the bounds the solution sits on, notes."""

from __future__ import annotations

import math
import time
from collections.abc import Mapping
from dataclasses import dataclass
from types import MappingProxyType
from typing import Any, ClassVar

import numpy as np
from numpy.typing import NDArray

from ...friction.model import combined
from ...identification.model import IdentifiedModel
from ...model.inertia import inertial_from_phi
from ...model.robot import Robot
from ..bounds import Bounds
from ..constraints import Constraint, FeasibilityReport, feasibility_report
from ..heldout import HeldOutJudgement
from ..lmi import (
    log_det_divergence,
    pseudo_inertia,
    pseudo_inertia_margin,
)
from ..plausible import implausible_notes
from ..prior import Prior
from ..result import FeasibleResult
from .data_term import DataTerm
from .options import SDPOptions
from .problem import solution_x

__all__ = [
    "AT_BOUND",
    "DETERMINED_SHARE",
    "MOVED_SD",
    "ConsistentResult",
    "build_result",
    "moved_note",
]

#: A coefficient the data determine (to :data:`DETERMINED_SHARE` of its value) that the
#: consistent fit moves by more than this many of its standard deviations is named.
MOVED_SD = 5.0
DETERMINED_SHARE = 0.3
#: A link's mass (or the total in its band) within this fraction of its bound (of the
#: bound's magnitude, or of the range where that is narrower) is at the bound, decided by
#: it: one tolerance for every link, wide enough for a solver that ends inaccurate short
#: of the bound (a placeholder link at 0.00299 kg against 0.003 kg: 0.19 %).
AT_BOUND = 1e-2


@dataclass(frozen=True, slots=True, eq=False)
class ConsistentResult(FeasibleResult):
    """Result of the convex retrieval or identification: a
    :class:`~dynid.feasibility.result.FeasibleResult` (robot, relative residual, report,
    bounds, run time, notes, friction and rotor inertias identified with the links, drive,
    held-out judgement) with the prior, its weight and the solver's account.

    Attributes
    ----------
    residual_ratio : float
        Residual RMS of the identification's data with these parameters over that of the
        unconstrained least squares (1 for exact data met exactly): ``sqrt(1 + chi2/dof)``.
    prior : Prior
    prior_weight : float
        The weight used (the automatic choice, or the one given).
    weight_search : tuple of (float, float)
        ``(w, residual_ratio)`` of every weight tried by the automatic choice.
    divergence : ndarray, shape (n,)
        Log-det divergence of each link from the prior.
    fit : str
        ``"equality"`` or ``"weighted"``.
    status : str
        Solver status (``"optimal"``, ``"optimal_inaccurate"``, ``"infeasible"`` when the
        equality has no consistent solution and the closest set is returned).
    solver : str
    options : SDPOptions
    identified : IdentifiedModel or None
        One-step: the unconstrained least-squares identification of the same data.
    on_bound : tuple of str
        Parameters that sit on a bound (mass box, CoM box, total-mass band): decided by the
        bound, not the data.

    Notes
    -----
    ``relative_residual`` is ``||P phi - beta|| / ||beta||`` over the kept coefficients;
    ``report`` holds the physical constraints, the bounds, the total mass,
    ``pseudo_inertia`` (margin ``lambda_min(J)/tr(J)``) and ``data_fit``; ``bounds`` are
    the masses narrowed by the prior; ``kind`` is ``"coefficients"`` (two-step), ``"log"``
    or ``"static"`` (one-step); ``friction`` (one-step on a torque log) is physical as its
    terms declare; ``drive`` is the data's drive train with the identified rotor inertias
    (:func:`with_drive`); ``notes`` the prior's repairs and the weight's choice.
    """

    residual_ratio: float
    prior: Prior
    prior_weight: float
    weight_search: tuple[tuple[float, float], ...]
    divergence: NDArray[np.float64]
    fit: str
    status: str
    solver: str
    options: SDPOptions
    identified: IdentifiedModel | None = None
    on_bound: tuple[str, ...] = ()

    method: ClassVar[str] = "sdp"
    nullable_fields: ClassVar[frozenset[str]] = frozenset(
        {"prior_weight", "weight_search", "residual_ratio", "divergence"}
    )
    field_units: ClassVar[Mapping[str, str]] = MappingProxyType({"residual_ratio": "1"})

    def report_fields(self) -> dict[str, Any]:
        """``report.json``'s entries of the convex method: ``fit``, ``prior`` (source,
        repaired links, links held at the margin, mass [kg] per link), ``prior_weight``,
        ``weight_search`` (``[w, residual_ratio]``), ``residual_ratio``, ``divergence`` per link,
        ``distance_to_prior`` (mass [kg], CoM [m] per link), ``solver``, ``status``,
        ``on_bound`` and ``options``."""
        pm, pc, _ = inertial_from_phi(self.prior.phi)
        o = self.options
        return {
            "fit": self.fit,
            "prior": {
                "source": self.prior.source,
                "repaired_links": list(self.prior.repaired),
                "held_links": list(self.prior.held),
                "placeholder_links": list(self.prior.placeholders),
                "mass": [float(x) for x in pm],
            },
            "prior_weight": float(self.prior_weight),
            "weight_search": [[float(w), float(r)] for w, r in self.weight_search],
            "residual_ratio": float(self.residual_ratio),
            "divergence": [float(x) for x in self.divergence],
            "distance_to_prior": {
                "mass": [float(x) for x in np.abs(self.mass - pm)],
                "com": [float(x) for x in np.linalg.norm(self.com - pc, axis=1)],
            },
            "solver": self.solver,
            "status": self.status,
            "on_bound": list(self.on_bound),
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
        }


def _active_and_implausible(
    robot: Robot,
    m: NDArray[np.float64],
    c: NDArray[np.float64],
    I: NDArray[np.float64],
    bounds: Bounds,
    band: tuple[float, float] | None,
    prior_phi: NDArray[np.float64] | None = None,
) -> tuple[list[str], list[str]]:
    """Notes: the bounds the result sits on (they, not the data, decided those values) and
    links whose mass or size is implausible
    (:func:`~dynid.feasibility.plausible.implausible_notes`, against the prior's link,
    ``prior_phi`` (n, 10)); and the parameters on a bound, one string each."""
    out: list[str] = []
    names = robot.link_names[1:]
    act: list[str] = []
    for i in range(robot.n):
        w = max(bounds.mass_max[i] - bounds.mass_min[i], 1e-12)
        for side, b in (("lower", bounds.mass_min[i]), ("upper", bounds.mass_max[i])):
            if abs(m[i] - b) <= AT_BOUND * min(w, max(abs(b), m[i], 1e-12)):
                act.append(f"{names[i]} mass {m[i]:.4g} kg at its {side} bound")
        for k, ax in enumerate("xyz"):
            wc = max(bounds.com_max[i, k] - bounds.com_min[i, k], 1e-12)
            for side, b in (("lower", bounds.com_min[i, k]), ("upper", bounds.com_max[i, k])):
                if abs(c[i, k] - b) <= 1e-4 * wc:
                    act.append(f"{names[i]} CoM {ax} {c[i, k]:+.4f} m at its {side} bound")
    if band is not None:
        M = float(m.sum())
        for side, b in (("lower", band[0]), ("upper", band[1])):
            if abs(M - b) <= AT_BOUND * max(min(band[1] - band[0], max(abs(b), M)), 1e-3):
                act.append(f"total mass {M:.4g} kg at the {side} end of its band")
    if act:
        out.append("decided by the bound, not the data: " + "; ".join(act))
    out += implausible_notes(robot, m, I, prior_phi)
    return out, act


def build_result(
    robot: Robot,
    phi: NDArray[np.float64],
    f: NDArray[np.float64] | None,
    term: DataTerm,
    prior: Prior,
    weight: float,
    search: list[tuple[float, float]],
    bounds: Bounds,
    band: tuple[float, float] | None,
    options: SDPOptions,
    fit: str,
    status: str,
    kind: str,
    t0: float,
    notes: list[str],
    ia: NDArray[np.float64] | None = None,
    judgement: HeldOutJudgement | None = None,
) -> ConsistentResult:
    if f is not None and term.n_friction:
        f = f.copy()
        nonneg = term.nonnegative()
        f[nonneg] = np.maximum(f[nonneg], 0.0)  # >= 0 held to the solver's tolerance
    m, c, I = inertial_from_phi(phi)
    out = robot.with_params(phi)
    found, act = _active_and_implausible(robot, m, c, I, bounds, band, prior.phi)
    notes = notes + found
    x = solution_x(term, phi, f, ia)
    moved = moved_note(term, x)
    notes = notes if moved is None else [*notes, moved]
    beta = term.x_hat[: term.r]
    nb = float(np.linalg.norm(beta))
    rel = float(np.linalg.norm(x[: term.r] - beta) / nb) if nb > 0 else 0.0
    ratio = 1.0 if term.exact else math.sqrt(1.0 + term.chi2(x) / term.dof)
    rep = feasibility_report((m, c, I), bounds, band, tol=options.tol)
    marg = pseudo_inertia_margin(phi)
    extra = [
        Constraint("pseudo_inertia", i + 1, float(marg[i]), "1", bool(marg[i] > 0))
        for i in range(robot.n)
    ]
    if fit == "equality":
        extra.append(Constraint("data_fit", None, 1e-6 - rel, "1", bool(rel <= 1e-6)))
    elif judgement is not None:
        extra.append(_heldout_fit(judgement))
        if not judgement.accepted:
            notes = notes + [
                f"the result predicts held-out torques {100 * (judgement.ratio - 1):.3g} % worse "
                f"than least squares (more than {100 * judgement.tolerance:g} %): the "
                f"constraints (margin {options.margin:g}, bounds, total-mass band) or the "
                "prior's weight exclude what the data say; check --margin, --total-mass, "
                "--bounds and --prior-weight"
            ]
    else:
        over = ratio - 1.0
        tol = options.residual_tol
        extra.append(Constraint("data_fit", None, tol - over, "1", bool(over <= tol)))
        if over > tol:
            notes = notes + [
                f"the result fits the data {100 * over:.3g} % worse than least squares (more "
                f"than {100 * tol:g} %): the constraints (margin {options.margin:g}, bounds, "
                "total-mass band) or the prior's weight exclude what the data say; check "
                "--margin, --total-mass, --bounds and --prior-weight"
            ]
    report = FeasibilityReport(
        tuple(c for c in rep.constraints if c.name != "inertia_in_bounds") + tuple(extra), rep.tol
    )
    div = log_det_divergence(pseudo_inertia(phi), prior.pseudo_inertia)
    return ConsistentResult(
        robot=out,
        friction=None if f is None else combined(term.frictions(f)),
        rotor_inertia=ia,
        spring=None if f is None else term.stiffness(f),
        relative_residual=rel,
        residual_ratio=ratio,
        feasible=bool(report.ok) and status != "infeasible",
        report=report,
        prior=prior,
        prior_weight=float(weight),
        weight_search=tuple(search),
        divergence=np.asarray(div, dtype=float),
        fit=fit,
        status=status,
        solver="CLARABEL",
        kind=kind,
        run_time=time.perf_counter() - t0,
        bounds=bounds,
        total_mass=band,
        options=options,
        notes=tuple(prior.notes) + tuple(notes),
        heldout=judgement,
        on_bound=tuple(act),
    )


def _heldout_fit(j: HeldOutJudgement) -> Constraint:
    """``data_fit`` judged on held-out data: the tolerance minus the excess over least
    squares' held-out error (>= 0 holds)."""
    return Constraint("data_fit", None, j.tolerance - (j.ratio - 1.0), "1", j.accepted)


def moved_note(term: DataTerm, x: NDArray[np.float64]) -> str | None:
    """The note naming the coefficients the data determine (``std <= 30 %`` of ``|x_hat|``)
    that the solution ``x`` moves by more than :data:`MOVED_SD` of their reported standard
    deviations (largest first, five at most): the prior and the constraints decide them
    against the data (a generic prior put a 7-joint arm's rotor inertia Ia5, 0.0128 +- 13 %
    by least squares, at 3e-9). None when none is, or the term is exact or has no std."""
    if term.exact or term.std is None or term.std.shape != x.shape:
        return None
    s, xh = term.std, term.x_hat
    with np.errstate(divide="ignore", invalid="ignore"):
        sd = np.abs(x - xh) / s
    hit = np.flatnonzero((s > 0) & (s <= DETERMINED_SHARE * np.abs(xh)) & (sd > MOVED_SD))
    if not hit.size:
        return None
    hit = hit[np.argsort(-sd[hit])]
    labels = (
        term.labels if len(term.labels) == x.size else tuple(f"x{i + 1}" for i in range(x.size))
    )
    told = ", ".join(
        f"{labels[i]} {xh[i]:.4g} +- {100 * s[i] / abs(xh[i]):.2g} % -> {x[i]:.4g} ({sd[i]:.3g} sd)"
        for i in hit[:5]
    )
    more = f" and {hit.size - 5} more" if hit.size > 5 else ""
    return (
        f"the consistent fit moves {hit.size} coefficient(s) the data determine by more than "
        f"{MOVED_SD:g} standard deviations: {told}{more}; the prior (its weight) and the "
        "constraints decide them, not the data: a prior closer to the arm (--prior) or a "
        "smaller --prior-weight keeps them"
    )
