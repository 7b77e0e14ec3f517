"""What the penalty method returns: :class:`RetrievalResult` with every run
(:class:`RetrievalRun`), the progress callback's record (:class:`RetrievalProgress`) and
the distance between parameter sets (:class:`ParameterDistance`)."""

from __future__ import annotations

from dataclasses import dataclass
from typing import Any, ClassVar

import numpy as np
from numpy.typing import NDArray

from ...exceptions import OptionError
from ...model.inertia import matrix_from_inertia6
from ..constraints import link_params
from ..result import FeasibleResult
from .options import RetrievalOptions

__all__ = ["ParameterDistance", "RetrievalProgress", "RetrievalResult", "RetrievalRun"]


@dataclass(frozen=True, slots=True, eq=False)
class RetrievalRun:
    """One independent run of Algorithm 1.

    Attributes
    ----------
    index : int
        Run number (0-based); its seed is child ``index`` of ``SeedSequence(seed)``.
    p : ndarray, shape (n, 10)
        Final decision parameters (mass, CoM, inertia about the CoM per link).
    stage_costs : ndarray, shape (kappa,)
        Stage objective ``F_k`` at the end of each stage.
    relative_residual : float
    feasible : bool
    violation : float
        Sum of the scaled violation distances ``sum_j g_j`` at the end (data fit not
        included).
    n_evaluations : int
        Objective evaluations (annealing and refinement).
    time : float
        Wall time of the run [s].
    """

    index: int
    p: NDArray[np.float64]
    stage_costs: NDArray[np.float64]
    relative_residual: float
    feasible: bool
    violation: float
    n_evaluations: int
    time: float


@dataclass(frozen=True, slots=True)
class RetrievalProgress:
    """What the ``progress`` callback receives when a run finishes.

    Attributes
    ----------
    done, total : int
        Runs finished and runs in all.
    run : int
        Index of the run that finished.
    cost : float
        Its final stage cost.
    relative_residual : float
    feasible : bool
    elapsed : float
        Wall time since the retrieval started [s].
    """

    done: int
    total: int
    run: int
    cost: float
    relative_residual: float
    feasible: bool
    elapsed: float


@dataclass(frozen=True, slots=True)
class ParameterDistance:
    """Distance between two parameter sets, per link.

    Attributes
    ----------
    mass : ndarray, shape (n,)
        ``|m - m_ref|`` [kg].
    com : ndarray, shape (n,)
        ``||c - c_ref||`` [m].
    inertia : ndarray, shape (n,)
        Frobenius norm of ``I - I_ref`` (about the respective CoMs) [kg m^2].
    """

    mass: NDArray[np.float64]
    com: NDArray[np.float64]
    inertia: NDArray[np.float64]


@dataclass(frozen=True, slots=True, eq=False)
class RetrievalResult(FeasibleResult):
    """Result of the penalty method: a :class:`~dynid.feasibility.result.FeasibleResult`
    (robot, relative residual, report, bounds, run time, seed, notes, ...) with the runs.

    Attributes
    ----------
    cost : float
        Final stage objective of the kept run.
    stage_costs : ndarray, shape (kappa,)
        Stage objectives of the kept run.
    runs : tuple of RetrievalRun
        Every run, in index order.
    best_run : int
        Index of the kept run.
    options : RetrievalOptions
    workers : int
        Processes used.

    Notes
    -----
    ``relative_residual`` is ``||pi(p) - pi_hat|| / ||pi_hat||`` over the kept coefficients
    (two-step) or ``||Y_s phi(p) - s|| / ||s||`` (single-step); ``report`` holds the physical
    constraints, the bounds, the total mass, the user's and ``data_fit``
    (``residual_tol - relative_residual``, see :class:`RetrievalOptions`); ``kind`` is
    ``"coefficients"`` or ``"static"``.
    """

    cost: float
    stage_costs: NDArray[np.float64]
    runs: tuple[RetrievalRun, ...]
    best_run: int
    options: RetrievalOptions
    workers: int

    method: ClassVar[str] = "penalty"
    nullable_fields: ClassVar[frozenset[str]] = frozenset({"cost", "stage_costs", "runs"})

    @property
    def p(self) -> NDArray[np.float64]:
        """Decision parameters (n, 10) of the kept run: ``m, cx, cy, cz, Ixx, Ixy, Ixz, Iyy,
        Iyz, Izz`` (inertia about the CoM)."""
        return self.runs[self.best_run].p

    @property
    def n_feasible_runs(self) -> int:
        """Number of runs that ended feasible."""
        return sum(r.feasible for r in self.runs)

    def distance_from(self, reference: Any) -> ParameterDistance:
        """Per-link distance of the retrieved parameters from ``reference`` (a Robot, or
        anything :func:`~dynid.feasibility.constraints.link_params` accepts)."""
        q = link_params(reference)
        if q.shape != self.p.shape:
            raise OptionError(f"reference has {q.shape[0]} links; the result has {self.p.shape[0]}")
        d_I = matrix_from_inertia6(self.p[:, 4:]) - matrix_from_inertia6(q[:, 4:])
        return ParameterDistance(
            mass=np.abs(self.p[:, 0] - q[:, 0]),
            com=np.linalg.norm(self.p[:, 1:4] - q[:, 1:4], axis=1),
            inertia=np.linalg.norm(d_I, axis=(1, 2)),
        )

    def report_fields(self) -> dict[str, Any]:
        """``report.json``'s entries of the penalty method: ``cost``, ``stage_costs``, ``xi``
        (the penalty weights), ``workers``, ``best_run``, ``n_feasible_runs``, ``runs`` (per
        run: final cost, stage costs, relative residual, feasible, violation, evaluations,
        time [s]) and ``options``."""
        o = self.options
        return {
            "cost": float(self.cost),
            "stage_costs": [float(x) for x in self.stage_costs],
            "xi": list(o.schedule()),
            "workers": int(self.workers),
            "best_run": int(self.best_run),
            "n_feasible_runs": int(self.n_feasible_runs),
            "runs": [
                {
                    "index": r.index,
                    "cost": float(r.stage_costs[-1]),
                    "stage_costs": [float(x) for x in r.stage_costs],
                    "relative_residual": float(r.relative_residual),
                    "feasible": bool(r.feasible),
                    "violation": float(r.violation),
                    "n_evaluations": int(r.n_evaluations),
                    "time_s": float(r.time),
                }
                for r in self.runs
            ],
            "options": {
                "runs": o.runs,
                "stages": o.stages,
                "anneal_maxiter": o.anneal_maxiter,
                "anneal_temperature": o.anneal_temperature,
                "local_maxiter": o.local_maxiter,
                "margin": o.margin,
                "scale_floor": o.scale_floor,
                "tol": o.tol,
                "residual_tol": o.residual_tol,
            },
        }
