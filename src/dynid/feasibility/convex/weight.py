"""The prior's weight of the convex method: the largest that keeps the residual within
``residual_increase`` of least squares (training residual), or chosen and judged on
held-out folds (:mod:`dynid.feasibility.heldout`)."""

from __future__ import annotations

import dataclasses
import math

import numpy as np
from numpy.typing import NDArray

from ...exceptions import InfeasibleError
from ...identification.holdout import HeldOut, cross_validate
from ..heldout import HeldOutJudgement, search_weight
from .data_term import DataTerm
from .options import WEIGHT_BISECTIONS, WEIGHT_RANGE, SDPOptions
from .problem import ConvexProblem, Values, solution_x

__all__ = ["auto_weight", "auto_weight_note", "fold_terms", "judged", "solved", "with_training"]


def auto_weight_note(
    w: float, limit: float, search: list[tuple[float, float]], opts: SDPOptions
) -> str:
    """What the automatic prior weight (training residual, :func:`auto_weight`) means."""
    if limit > 1.0 + opts.residual_increase:
        return (
            "no parameter set that meets the constraints (margin, bounds, total-mass band) fits "
            f"the data within {100 * opts.residual_increase:g} %: the closest raises the residual "
            f"RMS by {100 * (search[0][1] - 1):.2f} % (effects outside the rigid-body model, "
            "or a constraint that excludes the robot: check --margin, --total-mass, --bounds); "
            f"the prior weight {w:.3g} keeps it within {100 * opts.residual_increase:g} % of that"
        )
    top = w >= WEIGHT_RANGE[1] * (1 - 1e-9)
    return f"prior weight {w:.3g}: " + (
        "the top of the search range (the data leave the prior almost free)"
        if top
        else "the largest keeping the residual RMS within "
        f"{100 * opts.residual_increase:g} % of the unconstrained fit"
    )


def solved(prob: ConvexProblem, w: float) -> str:
    """Solve at ``w``; an infeasible problem raises."""
    status = prob.solve(w)
    if status.startswith("infeasible"):
        raise InfeasibleError("the bounds and constraints admit no consistent parameters")
    return status


def fold_terms(term: DataTerm, held: HeldOut) -> list[DataTerm]:
    """The data term of each fold's training rows, ``||W x - y||^2 / sigma^2`` up to a
    constant, ``sigma`` the noise of the fit on all data."""
    out = []
    for t in held.train:
        out.append(
            dataclasses.replace(
                term,
                x_hat=t.solve(),
                A=t.sqrt() / max(held.noise, 1e-300),
                dof=max(t.rows - t.p, 1),
                exact=False,
                holdout=None,
            )
        )
    return out


def judged(
    folds: list[ConvexProblem],
    held: HeldOut,
    opts: SDPOptions,
) -> tuple[float, HeldOutJudgement]:
    """The weight (the given one, or :func:`~dynid.feasibility.heldout.search_weight`) and
    the held-out errors of the consistent fit and of least squares over the folds. The folds
    are solved at ``w`` times their share of the rows (the full fit's balance of data and
    prior); the training errors are filled in by :func:`replace_training`."""
    share = held.training_share
    fold_terms = [p.term for p in folds]
    per_fold: dict[float, tuple[float, ...]] = {}

    def heldout_at(w: float) -> float:
        xs = []
        for p, ft in zip(folds, fold_terms, strict=True):
            solved(p, w * share)
            xs.append(solution_x(ft, *p.values()))
        per_fold[w] = tuple(t.relative_error_percent(x) for t, x in zip(held.test, xs, strict=True))
        return held.heldout_error_percent(xs)

    if opts.prior_weight is not None:
        w = opts.prior_weight
        search = [(w, heldout_at(w))]
        choice = "given"
    else:
        w, search, choice = search_weight(
            heldout_at, opts.residual_increase, WEIGHT_RANGE, per_fold.__getitem__
        )
    ls = cross_validate(held)
    return w, HeldOutJudgement(
        scheme=held.scheme,
        folds=held.folds,
        ls_training_percent=ls.training_percent,
        ls_heldout_percent=ls.heldout_percent,
        training_percent=math.nan,
        heldout_percent=dict(search)[w],
        tolerance=opts.heldout_tol,
        weight_search=tuple(search),
        choice=choice,
    )


def with_training(
    judgement: HeldOutJudgement, held: HeldOut, x: NDArray[np.float64]
) -> HeldOutJudgement:
    """The judgement with the training error of the fit ``x`` on all data."""
    training = held.judged_whole.relative_error_percent(x)
    return dataclasses.replace(judgement, training_percent=training)


def auto_weight(
    prob: ConvexProblem, term: DataTerm, opts: SDPOptions
) -> tuple[float, float, str, Values, list[tuple[float, float]]]:
    """Largest weight in :data:`WEIGHT_RANGE` whose residual ratio stays within the limit.

    The limit is ``1 + residual_increase``, or, when the consistent fit at the smallest
    weight already exceeds it (data that no rigid body fits within the allowance),
    ``(1 + residual_increase)`` times that fit's ratio. Decades upwards from the smallest
    weight, then :data:`WEIGHT_BISECTIONS` bisections of the logarithm. Returns the weight,
    the limit used, the status, the solution (:meth:`ConvexProblem.values`) and every
    ``(w, ratio)`` tried.
    """
    search: list[tuple[float, float]] = []
    cache: dict[float, tuple[str, Values]] = {}

    def ratio(e: float) -> float:
        w = 10.0**e
        status = prob.solve(w)
        if status.startswith("infeasible"):
            raise InfeasibleError("the bounds and constraints admit no consistent parameters")
        values = prob.values()
        rr = math.sqrt(1.0 + term.chi2(solution_x(term, *values)) / term.dof)
        search.append((w, rr))
        cache[e] = (status, values)
        return rr

    lo_e, hi_e = (math.log10(x) for x in WEIGHT_RANGE)
    r0 = ratio(lo_e)
    allowed = 1.0 + opts.residual_increase
    limit = allowed if r0 <= allowed else r0 * allowed
    good, bad = lo_e, None
    e = lo_e + 2.0
    while e <= hi_e + 1e-9:
        if ratio(e) <= limit:
            good = e
            e += 2.0
        else:
            bad = e
            break
    if bad is not None:
        for _ in range(WEIGHT_BISECTIONS):
            mid = 0.5 * (good + bad)
            if ratio(mid) <= limit:
                good = mid
            else:
                bad = mid
    status, values = cache[good]
    return 10.0**good, limit, status, values, search
