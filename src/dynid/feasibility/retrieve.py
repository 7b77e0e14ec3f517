"""Retrieval of physically feasible link parameters (Gaz et al. 2019, Sec. V, Algorithm 1).

Identified coefficients (base parameters) fix only combinations of the link parameters,
and a least-squares estimate of the combinations need not come from any physical body.
The retrieval searches the link parameters ``p = (m_i, c_i, I_i)`` (mass, CoM, inertia
about the CoM, per link) inside a box (:class:`~dynid.feasibility.bounds.Bounds`)
that reproduce the coefficients and satisfy the feasibility constraints, by the penalised
objective of :mod:`dynid.feasibility.penalty`:

.. math:: F_k(p) = \\| \\pi(p) - \\hat\\pi \\|_S^2 + \\xi_k \\sum_j g(h_j(p))^2
          \\quad \\text{(eq. 29, squared distances: see the penalty module)}

Algorithm 1 (``Q`` runs of ``kappa`` stages):

1. Each run starts from a point drawn uniformly in the box.
2. Stage ``k = 1 .. kappa`` with penalty weight ``xi_k`` (``xi_1 = 0``, then increasing,
   default ``1, 100, 10^4, ...``): a bounded global search by generalised simulated
   annealing (``scipy.optimize.dual_annealing`` without its own local search, on the
   stage objective ``F_k``), then a local refinement of ``F_k`` by a bounded
   Levenberg-Marquardt method (analytic Jacobian; see :mod:`~dynid.feasibility.penalty`),
   both warm-started from the previous stage.
3. The runs are independent: they run in parallel over ``workers`` processes, each
   seeded by its own child of ``np.random.SeedSequence(seed).spawn(Q)``, so the results do
   not depend on the number of workers.
4. The best feasible run (lowest final stage cost among those whose every constraint
   holds, :func:`~dynid.feasibility.constraints.feasibility_report`) is kept; when no run
   is feasible the least-violating one is returned with ``feasible = False``. Every run
   is returned too.

Entry points: :func:`retrieve` (an :class:`~dynid.identification.model.IdentifiedModel`),
:func:`retrieve_from_coefficients` (coefficients given directly) and
:func:`retrieve_from_static` (the single-step variant of the supplementary material: the
objective is taken on the static data ``||Y_s pi(p) - s||^2``, no identification step).

A specification that cannot be met (a total-mass band the coefficients contradict, say)
gives ``feasible = False`` with the least-violating solution and its margins: either a
constraint stays violated, or the penalties win and the data are missed, which the
``data_fit`` entry of the report flags (:attr:`RetrievalOptions.residual_tol`). Nothing
is raised unless ``require_feasible=True`` (:class:`~dynid.exceptions.InfeasibleError`).
"""

from __future__ import annotations

import logging
import math
import os
import time
from collections.abc import Callable, Sequence
from concurrent.futures import as_completed
from dataclasses import dataclass
from typing import Any, ClassVar

import numpy as np
import scipy.linalg
from numpy.typing import ArrayLike, NDArray
from scipy.optimize import dual_annealing

from .._parallel import process_pool
from ..exceptions import InfeasibleError, ModelError, OptionError, ShapeError
from ..identification.model import IdentifiedModel
from ..model.inertia import matrix_from_inertia6
from ..model.robot import Robot
from ..regressors.base import BaseParameters
from .bounds import Bounds, default_bounds
from .constraints import Constraint, FeasibilityReport, feasibility_report, link_params
from .penalty import (
    DEFAULT_MARGIN,
    DEFAULT_SCALE_FLOOR,
    PenaltyProblem,
    coefficient_problem,
    static_problem,
    with_prior,
)
from .result import FeasibleResult

__all__ = [
    "ParameterDistance",
    "RetrievalOptions",
    "RetrievalProgress",
    "RetrievalResult",
    "RetrievalRun",
    "retrieve",
    "retrieve_from_coefficients",
    "retrieve_from_static",
]

_log = logging.getLogger(__name__)

#: Refinement stops when the cost fell by less than 1 % over the last 50 iterations.
_STALL_WINDOW, _STALL_FACTOR = 50, 0.99


@dataclass(frozen=True, slots=True)
class RetrievalOptions:
    """Settings of Algorithm 1.

    Attributes
    ----------
    runs : int
        Independent runs ``Q`` (Gaz et al. used 10).
    stages : int
        Stages ``kappa`` per run (Gaz et al. used 5).
    xi : tuple of float, optional
        Penalty weight of every stage (length ``stages``, ``xi[0]`` normally 0). Default
        ``(0, xi_first, xi_first * xi_growth, ...)``.
    xi_first, xi_growth : float
        Default schedule: the weight of stage 2 and the factor between later stages.
    anneal_maxiter : int
        Iterations of the simulated annealing per stage (each visits ``2 * 10 n``
        points); 0 skips the annealing.
    anneal_temperature : float
        Initial temperature of the annealing (scipy's ``initial_temp``, in (0.01, 5e4]),
        for the stage objective divided by its value at the warm start: the annealing
        explores around the current point rather than restarting from scratch.
    local_maxiter : int
        Iterations of the local refinement per stage.
    margin : float
        Relative target margin of the constraints and shrink of the box
        (:mod:`~dynid.feasibility.penalty`).
    scale_floor : float
        Floor of the coefficient scales (two-step objective).
    tol : float
        Relative tolerance of the feasibility report.
    residual_tol : float or None
        Largest relative residual on the data for which the parameters count as
        reproducing them: the report holds a ``data_fit`` constraint with margin
        ``residual_tol - relative_residual``, so that a specification that contradicts
        the data (a total-mass band the coefficients rule out, say) is reported
        infeasible even when the penalties gave in to it. None leaves it out. 5 % by
        default: noise-free or well-identified coefficients are met to round-off, the
        single-step residual is about the noise level of the static data.
    prior_weight : float
        Weight of the pull towards a prior, when one is given
        (:func:`~dynid.feasibility.penalty.with_prior`): each relative deviation of a
        standard parameter from the prior's counts ``prior_weight`` times a relative
        coefficient error. Small by default (1e-6: the coefficients are still met to
        about 1e-6 relative): among parameter sets that fit equally, the one closest to the
        prior wins.
    """

    runs: int = 10
    stages: int = 5
    xi: tuple[float, ...] | None = None
    xi_first: float = 1.0
    xi_growth: float = 100.0
    anneal_maxiter: int = 5
    anneal_temperature: float = 0.1
    local_maxiter: int = 1000
    margin: float = DEFAULT_MARGIN
    scale_floor: float = DEFAULT_SCALE_FLOOR
    tol: float = 1e-9
    residual_tol: float | None = 0.05
    prior_weight: float = 1e-6

    def __post_init__(self) -> None:
        if self.residual_tol is not None and not self.residual_tol > 0:
            raise OptionError(f"residual_tol must be positive or None; got {self.residual_tol}")
        if not (math.isfinite(self.prior_weight) and self.prior_weight >= 0):
            raise OptionError(f"prior_weight must be finite and >= 0; got {self.prior_weight}")
        if self.runs < 1 or self.stages < 1:
            raise OptionError(f"runs and stages must be >= 1; got {self.runs}, {self.stages}")
        if self.anneal_maxiter < 0 or self.local_maxiter < 0:
            raise OptionError("anneal_maxiter and local_maxiter must be >= 0")
        if self.xi is not None:
            xi = tuple(float(x) for x in self.xi)
            if len(xi) != self.stages:
                raise OptionError(
                    f"xi must have one weight per stage ({self.stages}); got {len(xi)}"
                )
            if any(x < 0 or not math.isfinite(x) for x in xi):
                raise OptionError(f"xi must be finite and >= 0; got {xi}")
            object.__setattr__(self, "xi", xi)

    def schedule(self) -> tuple[float, ...]:
        """Penalty weights ``xi_1 .. xi_kappa``."""
        if self.xi is not None:
            return self.xi
        return (0.0,) + tuple(self.xi_first * self.xi_growth**k for k in range(self.stages - 1))


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


# ------------------------------------------------------------------------- local step
def _refine(
    problem: PenaltyProblem, z: NDArray[np.float64], xi: float, maxiter: int
) -> tuple[NDArray[np.float64], int]:
    """Projected Levenberg-Marquardt on ``||lsq_residual(z, xi)||^2`` in ``[0, 1]^d``.

    Levenberg damping ``(J^T J + lam E) dz = -J^T e`` in the normalised variables (the box
    gives them a common scale; Marquardt's diagonal scaling would let the directions
    the data do not see take huge steps). Variables at a bound whose gradient or step
    points outwards are held and the step is solved again; steps are clipped to the box
    and accepted when they lower the cost. Stops after ``maxiter`` iterations, when no
    step lowers the cost, or when the cost falls by less than 1 % over 50 iterations
    (the slow zig-zag of constraints switching at their target). Returns the point and
    the number of residual evaluations.
    """
    e = problem.lsq_residual(z, xi)
    cost = float(e @ e)
    nfev = 1
    lam = -1.0
    history = [cost]
    for _ in range(maxiter):
        if cost <= 1e-30:
            break
        J = problem.lsq_jacobian(z, xi)
        grad = J.T @ e
        H = J.T @ J
        hmax = max(float(np.max(np.diag(H), initial=0.0)), 1e-300)
        if lam < 0:
            lam = 1e-3 * hmax
        accepted = False
        while lam < 1e20 * hmax:
            fixed = ((z <= 0.0) & (grad > 0.0)) | ((z >= 1.0) & (grad < 0.0))
            step = np.zeros_like(z)
            ok = True
            for _ in range(5):
                free = ~fixed
                try:
                    L = np.linalg.cholesky(H[np.ix_(free, free)] + lam * np.eye(int(free.sum())))
                except np.linalg.LinAlgError:
                    ok = False
                    break
                step[:] = 0.0
                step[free] = -scipy.linalg.cho_solve((L, True), grad[free], check_finite=False)
                out = ((z <= 0.0) & (step < 0.0)) | ((z >= 1.0) & (step > 0.0))
                if not out.any():
                    break
                fixed |= out
            if not ok:
                lam *= 10.0
                continue
            z_new = np.clip(z + step, 0.0, 1.0)
            e_new = problem.lsq_residual(z_new, xi)
            nfev += 1
            c_new = float(e_new @ e_new)
            if c_new < cost:
                z, e, cost = z_new, e_new, c_new
                lam = max(lam / 10.0, 1e-14 * hmax)
                accepted = True
                break
            lam *= 10.0
        if not accepted:
            break
        history.append(cost)
        if len(history) > _STALL_WINDOW and cost > _STALL_FACTOR * history[-_STALL_WINDOW - 1]:
            break
    return z, nfev


def _inertials(
    p: NDArray[np.float64],
) -> tuple[NDArray[np.float64], NDArray[np.float64], NDArray[np.float64]]:
    """``(mass, com, inertia6)`` of decision parameters (n, 10)."""
    return p[:, 0], p[:, 1:4], p[:, 4:]


class _Counter:
    """Stage objective divided by ``ref``, with an evaluation counter."""

    def __init__(self, problem: PenaltyProblem, xi: float, ref: float = 1.0) -> None:
        self.problem, self.xi, self.ref, self.count = problem, xi, ref, 0

    def __call__(self, z: NDArray[np.float64]) -> float:
        self.count += 1
        return self.problem.stage_cost(z, self.xi) / self.ref


def _one_run(
    problem: PenaltyProblem, seq: np.random.SeedSequence, options: RetrievalOptions, index: int
) -> RetrievalRun:
    """Run ``index`` of Algorithm 1 (executed in a worker process or in-process)."""
    t0 = time.perf_counter()
    rng = np.random.default_rng(seq)
    d = problem.dim
    z = rng.uniform(0.0, 1.0, d)
    box = list(zip(np.zeros(d), np.ones(d), strict=True))
    costs = []
    nfev = 0
    for xi in options.schedule():
        if options.anneal_maxiter > 0:
            ref = max(problem.stage_cost(z, xi), 1e-300)
            f = _Counter(problem, xi, ref)
            res = dual_annealing(
                f,
                box,
                x0=z,
                maxiter=options.anneal_maxiter,
                rng=rng,
                no_local_search=True,
                initial_temp=options.anneal_temperature,
            )
            nfev += f.count
            if f(res.x) <= f(z):
                z = np.clip(np.asarray(res.x, dtype=np.float64), 0.0, 1.0)
        if options.local_maxiter > 0:
            z, k = _refine(problem, z, xi, options.local_maxiter)
            nfev += k
        costs.append(problem.stage_cost(z, xi))
    p = problem.p_from_z(z)
    return RetrievalRun(
        index=index,
        p=p,
        stage_costs=np.array(costs),
        relative_residual=problem.relative_residual(p),
        feasible=False,  # decided by the caller, with the full report
        violation=float(problem.violations(z).sum()),
        n_evaluations=nfev,
        time=time.perf_counter() - t0,
    )


def _run_all(
    problem: PenaltyProblem,
    options: RetrievalOptions,
    seed: int | None,
    workers: int,
    on_done: Callable[[RetrievalRun], None],
) -> list[RetrievalRun]:
    seqs = np.random.SeedSequence(seed).spawn(options.runs)
    runs: list[RetrievalRun | None] = [None] * options.runs
    if workers <= 1 or options.runs == 1:
        for i, s in enumerate(seqs):
            run = _one_run(problem, s, options, i)
            runs[i] = run
            on_done(run)
    else:
        with process_pool(workers) as ex:
            futs = {ex.submit(_one_run, problem, s, options, i): i for i, s in enumerate(seqs)}
            for fut in as_completed(futs):
                run = fut.result()
                runs[futs[fut]] = run
                on_done(run)
    return [r for r in runs if r is not None]


def _solve(
    problem: PenaltyProblem,
    robot: Robot,
    bounds: Bounds,
    options: RetrievalOptions,
    *,
    workers: int | None,
    seed: int | None,
    progress: Callable[[RetrievalProgress], None] | None,
    require_feasible: bool,
) -> RetrievalResult:
    t0 = time.perf_counter()
    w = min(options.runs, os.cpu_count() or 1) if workers is None else int(workers)
    if w < 1:
        raise OptionError(f"workers must be >= 1; got {workers}")
    xis = options.schedule()
    _log.info(
        "retrieval (%s): %d runs x %d stages (xi %s), %d workers, seed %s",
        problem.kind,
        options.runs,
        options.stages,
        ", ".join(f"{x:g}" for x in xis),
        w,
        seed,
    )
    band = problem.total_mass
    extra = problem.extra
    reports: dict[int, FeasibilityReport] = {}
    done = 0

    def on_done(run: RetrievalRun) -> None:
        nonlocal done
        rep = feasibility_report(_inertials(run.p), bounds, band, extra, tol=options.tol)
        if options.residual_tol is not None:
            margin = options.residual_tol - run.relative_residual
            fit = Constraint("data_fit", None, float(margin), "1", bool(margin >= 0.0))
            rep = FeasibilityReport(rep.constraints + (fit,), rep.tol)
        reports[run.index] = rep
        done += 1
        _log.info(
            "run %d/%d: cost %.3e, relative residual %.2e, %s, %.1f s",
            done,
            options.runs,
            run.stage_costs[-1],
            run.relative_residual,
            "feasible" if rep.ok else "infeasible",
            run.time,
        )
        if progress is not None:
            progress(
                RetrievalProgress(
                    done,
                    options.runs,
                    run.index,
                    float(run.stage_costs[-1]),
                    run.relative_residual,
                    rep.ok,
                    time.perf_counter() - t0,
                )
            )

    raw = _run_all(problem, options, seed, w, on_done)
    runs = tuple(
        RetrievalRun(
            r.index,
            r.p,
            r.stage_costs,
            r.relative_residual,
            reports[r.index].ok,
            r.violation,
            r.n_evaluations,
            r.time,
        )
        for r in raw
    )
    feasible = [r for r in runs if r.feasible]
    if feasible:
        best = min(feasible, key=lambda r: (r.stage_costs[-1], r.index))
    else:
        best = min(runs, key=lambda r: (r.violation, r.stage_costs[-1], r.index))
    rep = reports[best.index]
    notes: tuple[str, ...] = ()
    if not rep.ok:
        msg = f"no feasible parameters found in {options.runs} runs; least violating: {rep}"
        if require_feasible:
            raise InfeasibleError(msg + "; hint: check the bounds and the total-mass band")
        _log.warning(msg)
        notes = (msg,)
    new_robot = robot.with_inertials(best.p[:, 0], best.p[:, 1:4], best.p[:, 4:])
    return RetrievalResult(
        robot=new_robot,
        relative_residual=best.relative_residual,
        cost=float(best.stage_costs[-1]),
        feasible=rep.ok,
        report=rep,
        stage_costs=best.stage_costs.copy(),
        run_time=time.perf_counter() - t0,
        seed=seed,
        runs=runs,
        best_run=best.index,
        bounds=bounds,
        total_mass=band,
        options=options,
        kind=problem.kind,
        workers=w,
        notes=notes,
    )


def _prior_problem(
    problem: PenaltyProblem, robot: Robot, prior: Any, weight: float
) -> PenaltyProblem:
    """``problem`` pulled towards ``prior`` (a Prior, a Robot with inertials, or None)."""
    if prior is None:
        return problem
    from .prior import Prior, prior_from_robot

    pr = prior if isinstance(prior, Prior) else prior_from_robot(prior)
    if pr.n != robot.n:
        raise ShapeError(
            f"prior {pr.source!r} has {pr.n} links; robot {robot.name!r} has {robot.n}"
        )
    return with_prior(problem, pr.phi, weight)


def retrieve_from_coefficients(
    robot: Robot,
    base: BaseParameters,
    beta: ArrayLike,
    *,
    std: ArrayLike | None = None,
    kept: ArrayLike | None = None,
    bounds: Bounds | None = None,
    total_mass: tuple[float, float] | None = None,
    extra: Sequence[Any] = (),
    options: RetrievalOptions | None = None,
    workers: int | None = None,
    seed: int | None = 0,
    progress: Callable[[RetrievalProgress], None] | None = None,
    require_feasible: bool = False,
    prior: Any = None,
) -> RetrievalResult:
    """Feasible link parameters that reproduce given dynamic coefficients (two-step).

    .. math:: \\min_{p \\in B} \\; \\sum_{k\\ kept}
              \\left(\\frac{\\pi_k(p) - \\hat\\pi_k}{s_k}\\right)^2
              + \\xi_k \\sum_j g(h_j(p))^2

    Parameters
    ----------
    robot : Robot
        Kinematics; the result's robot is this one with the retrieved parameters.
    base : BaseParameters
        Definition of the coefficients (``pi = P phi``).
    beta : array_like, shape (r,)
        Coefficients ``pi_hat`` [kg, kg m or kg m^2].
    std : array_like, shape (r,), optional
        Their standard deviations.
    kept : array_like of bool, shape (r,), optional
        Coefficients to match (pruned ones are ignored).
    bounds : Bounds, optional
        Search box; default :func:`~dynid.feasibility.bounds.default_bounds`.
    total_mass : (float, float), optional
        Band on the total mass [kg]; overrides ``bounds.total_mass``.
    extra : sequence
        User constraints, callables ``p (n, 10) -> violation >= 0``
        (:class:`~dynid.feasibility.constraints.UserConstraint`).
    options : RetrievalOptions, optional
    workers : int, optional
        Processes (default ``min(runs, cpu_count)``); 1 runs in this process. The result
        does not depend on it.
    seed : int or None
        Seed of ``np.random.SeedSequence``; None draws fresh entropy.
    progress : callable, optional
        Called with a :class:`RetrievalProgress` each time a run finishes.
    require_feasible : bool
        Raise :class:`~dynid.exceptions.InfeasibleError` when no run is feasible
        (default: return the least-violating solution with ``feasible = False``).
    prior : Prior or Robot, optional
        Prior link parameters to pull towards (weight ``options.prior_weight``; see
        :func:`~dynid.feasibility.penalty.with_prior`), checked and repaired as in
        :func:`~dynid.feasibility.prior.prior_from_robot`. None: the paper's method.

    Returns
    -------
    RetrievalResult

    Raises
    ------
    ShapeError
        Sizes disagree (coefficients, bounds, robot).
    DataError
        No kept coefficient.
    InfeasibleError
        Only with ``require_feasible=True``.
    """
    options = RetrievalOptions() if options is None else options
    b = default_bounds(robot) if bounds is None else bounds
    problem = coefficient_problem(
        robot,
        base,
        beta,
        std=std,
        kept=kept,
        bounds=b,
        total_mass=total_mass,
        extra=extra,
        margin=options.margin,
        scale_floor=options.scale_floor,
    )
    problem = _prior_problem(problem, robot, prior, options.prior_weight)
    return _solve(
        problem,
        robot,
        b,
        options,
        workers=workers,
        seed=seed,
        progress=progress,
        require_feasible=require_feasible,
    )


def retrieve(
    model: IdentifiedModel,
    *,
    bounds: Bounds | None = None,
    total_mass: tuple[float, float] | None = None,
    extra: Sequence[Any] = (),
    options: RetrievalOptions | None = None,
    workers: int | None = None,
    seed: int | None = 0,
    progress: Callable[[RetrievalProgress], None] | None = None,
    require_feasible: bool = False,
    use_std: bool = True,
    prior: Any = None,
) -> RetrievalResult:
    """Feasible link parameters from an identified model (Gaz et al. 2019, Algorithm 1).

    Matches the model's kept coefficients ``fit.beta[fit.kept]``, each scaled by
    ``max(|beta_k|, std_k, floor)`` (``use_std=False`` ignores the standard deviations);
    pruned coefficients are ignored. See :func:`retrieve_from_coefficients` for the
    parameters, the result and the errors.

    Examples
    --------
    >>> import dynid
    >>> from dynid.regressors.base import base_parameters
    >>> from dynid.feasibility.retrieve import retrieve_from_coefficients
    >>> robot = dynid.panda()
    >>> base = base_parameters(robot)
    >>> res = retrieve_from_coefficients(robot, base, base.beta_from_phi(robot.phi),
    ...                                  workers=1)  # doctest: +SKIP
    >>> res.feasible, res.relative_residual < 1e-4  # doctest: +SKIP
    (True, True)
    """
    if model.base.n_std != 10 * model.robot.n:
        raise ModelError(
            "the penalty method retrieves link parameters only, and this model identified "
            "rotor inertias with them (a drive); use the convex method (--method sdp), which "
            "identifies them with the links (>= 0)"
        )
    return retrieve_from_coefficients(
        model.robot,
        model.base,
        model.fit.beta,
        std=model.fit.std if use_std else None,
        kept=model.fit.kept,
        bounds=bounds,
        total_mass=total_mass,
        extra=extra,
        options=options,
        workers=workers,
        seed=seed,
        progress=progress,
        require_feasible=require_feasible,
        prior=prior,
    )


def retrieve_from_static(
    robot: Robot,
    data: Any,
    *,
    base: BaseParameters | None = None,
    bounds: Bounds | None = None,
    total_mass: tuple[float, float] | None = None,
    extra: Sequence[Any] = (),
    options: RetrievalOptions | None = None,
    workers: int | None = None,
    seed: int | None = 0,
    progress: Callable[[RetrievalProgress], None] | None = None,
    require_feasible: bool = False,
    prior: Any = None,
) -> RetrievalResult:
    """Feasible link parameters directly from static data (single-step variant).

    .. math:: \\min_{p \\in B} \\; \\| D (Y_s(q) \\, \\phi(p) - s) \\|^2
              + \\xi_k \\sum_j g(h_j(p))^2

    (Gaz et al. 2019, supplementary material: the objective on the data, no separate
    identification step; weighting as in :func:`~dynid.feasibility.penalty.static_problem`).

    Parameters
    ----------
    robot : Robot
        Kinematics and gravity the data were recorded with.
    data : StaticDataset or tuple
        A :class:`~dynid.identification.data.StaticDataset`, or a tuple ``(q (N, n),
        M (N, n, n), g (N, n))`` [rad, kg m^2, N m].
    base : BaseParameters, optional
        Default ``base_parameters(robot)``.
    bounds, total_mass, extra, options, workers, seed, progress, require_feasible
        As for :func:`retrieve_from_coefficients`.

    Returns
    -------
    RetrievalResult
        ``relative_residual`` is ``||Y_s phi(p) - s|| / ||s||`` on the data.
    """
    if isinstance(data, tuple) and len(data) == 3:
        q, M, g = data
    else:
        q, M, g = data.q, data.M, data.g
    options = RetrievalOptions() if options is None else options
    b = default_bounds(robot) if bounds is None else bounds
    problem = static_problem(
        robot,
        q,
        M,
        g,
        base=base,
        bounds=b,
        total_mass=total_mass,
        extra=extra,
        margin=options.margin,
    )
    problem = _prior_problem(problem, robot, prior, options.prior_weight)
    return _solve(
        problem,
        robot,
        b,
        options,
        workers=workers,
        seed=seed,
        progress=progress,
        require_feasible=require_feasible,
    )
