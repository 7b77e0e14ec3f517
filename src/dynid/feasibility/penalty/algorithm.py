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

This module runs the algorithm on a
:class:`~dynid.feasibility.penalty.objective.PenaltyProblem` (:func:`solve`). Entry points
(:mod:`dynid.feasibility.penalty.fit`): :func:`~dynid.feasibility.penalty.fit.retrieve` (an
:class:`~dynid.identification.model.IdentifiedModel`),
:func:`~dynid.feasibility.penalty.fit.retrieve_from_coefficients` (coefficients given
directly) and :func:`~dynid.feasibility.penalty.fit.retrieve_from_static` (the single-step
variant of the supplementary material: the objective is taken on the static data
``||Y_s pi(p) - s||^2``, no identification step).

A specification that cannot be met (a total-mass band the coefficients contradict, say)
gives ``feasible = False`` with the least-violating solution and its margins: either a
constraint stays violated, or the penalties win and the data are missed, which the
``data_fit`` entry of the report flags (:attr:`RetrievalOptions.residual_tol`). Nothing
is raised unless ``require_feasible=True`` (:class:`~dynid.exceptions.InfeasibleError`).
"""

from __future__ import annotations

import logging
import os
import time
from collections.abc import Callable
from concurrent.futures import as_completed

import numpy as np
from numpy.typing import NDArray

from ..._parallel import process_pool
from ...exceptions import InfeasibleError, OptionError
from ...model.inertia import inertial_from_phi
from ...model.robot import Robot
from ..bounds import Bounds
from ..constraints import Constraint, FeasibilityReport, feasibility_report
from ..plausible import implausible_notes
from .objective import (
    PenaltyProblem,
)
from .options import RetrievalOptions
from .result import RetrievalProgress, RetrievalResult, RetrievalRun

__all__ = ["solve"]


_log = logging.getLogger(__name__)

#: Refinement stops when the cost fell by less than 1 % over the last 50 iterations.
_STALL_WINDOW, _STALL_FACTOR = 50, 0.99


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
    from scipy.linalg.lapack import dpotrs  # scipy on first use (start-up time)

    e, sl = problem.lsq_residual_slacks(z, xi)
    cost = float(e @ e)
    nfev = 1
    lam = -1.0
    history = [cost]
    for _ in range(maxiter):
        if cost <= 1e-30:
            break
        J = problem.lsq_jacobian(z, xi, slacks=sl)
        grad = J.T @ e
        H = J.T @ J
        hmax = max(float(H.diagonal().max(initial=0.0)), 1e-300)
        if lam < 0:
            lam = 1e-3 * hmax
        accepted = False
        while lam < 1e20 * hmax:
            fixed = ((z <= 0.0) & (grad > 0.0)) | ((z >= 1.0) & (grad < 0.0))
            step = np.zeros_like(z)
            ok = True
            for _ in range(5):
                free = ~fixed
                Hf = H.copy() if free.all() else H[np.ix_(free, free)]
                Hf.flat[:: Hf.shape[0] + 1] += lam  # H + lam E on the free variables
                try:
                    L = np.linalg.cholesky(Hf)
                except np.linalg.LinAlgError:
                    ok = False
                    break
                step[:] = 0.0
                if L.shape[0]:  # cho_solve's LAPACK call, without its wrappers
                    step[free] = -dpotrs(L, grad[free], lower=1)[0]
                out = ((z <= 0.0) & (step < 0.0)) | ((z >= 1.0) & (step > 0.0))
                if not out.any():
                    break
                fixed |= out
            if not ok:
                lam *= 10.0
                continue
            z_new = np.clip(z + step, 0.0, 1.0)
            e_new, sl_new = problem.lsq_residual_slacks(z_new, xi)
            nfev += 1
            c_new = float(e_new @ e_new)
            if c_new < cost:
                z, e, sl, cost = z_new, e_new, sl_new, c_new
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
    from scipy.optimize import dual_annealing  # scipy on first use (start-up time)

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
    import scipy.optimize  # noqa: F401 (imported before the workers fork, not in each)

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


def solve(
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
    # the masses the data do not give are the optimizer's: say the implausible ones
    m, _, I = inertial_from_phi(new_robot.phi)
    notes = (*notes, *implausible_notes(robot, m, I, robot.phi))
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
