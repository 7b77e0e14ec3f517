"""The convex problem of :mod:`dynid.feasibility.convex` solved for one data term
(:func:`solve_consistent`): bounds and prior checked, the exact fit or the weighted one."""

from __future__ import annotations

import time
from collections.abc import Callable, Sequence
from typing import Any

import numpy as np
from numpy.typing import NDArray

from ...exceptions import InfeasibleError, ModelError, OptionError, ShapeError, SolverError
from ...model.robot import Robot
from ..bounds import Bounds, default_bounds
from ..heldout import HeldOutJudgement
from ..prior import Prior, default_prior, prior_from_robot
from .data_term import DataTerm
from .options import SDPOptions
from .problem import ConvexProblem, check_band, fallback_note, mass_bounds, polish, solution_x
from .result import ConsistentResult, build_result
from .weight import auto_weight, auto_weight_note, fold_terms, judged, solved, with_training

__all__ = ["solve_consistent"]


def solve_consistent(
    robot: Robot,
    term: DataTerm,
    *,
    prior: Prior | Robot | None = None,
    bounds: Bounds | None = None,
    total_mass: tuple[float, float] | None = None,
    options: SDPOptions | None = None,
    constraints: Sequence[Callable[..., Any]] = (),
    kind: str = "coefficients",
    friction_nonneg: bool = True,
) -> ConsistentResult:
    """Solve the convex problem of the module docstring for a data term.

    Parameters
    ----------
    robot : Robot
        Kinematics, gravity and friction of the result (its inertials are the default
        prior).
    term : DataTerm
        From :func:`coefficient_term` (or built by the one-step routes).
    prior : Prior or Robot, optional
        A :class:`~dynid.feasibility.prior.Prior`, a robot with link inertials (checked
        and repaired by :func:`~dynid.feasibility.prior.prior_from_robot`), or None for
        :func:`~dynid.feasibility.prior.default_prior`: ``robot``'s own inertials when it
        has them, else the generic prior.
    bounds : Bounds, optional
        Mass and CoM boxes and the total-mass band; default
        :func:`~dynid.feasibility.bounds.default_bounds`. The inertia-entry bounds of
        the penalty method are not used (the pseudo-inertia LMI replaces them).
    total_mass : (float, float), optional
        Overrides ``bounds.total_mass`` [kg].
    options : SDPOptions, optional
    constraints : sequence of callables
        Convex constraints of the user's: ``make(phi, J) -> list of cvxpy constraints``,
        ``phi`` the list of the links' (10,) cvxpy expressions (m, h, J_o) and ``J`` their
        4x4 pseudo-inertias; e.g. ``lambda phi, J: [cp.norm(phi[6][1:3]) <= 0.02 * phi[6][0]]``
        keeps link 7's CoM within 2 cm of its z axis.
    kind : str
        Recorded in the result (``"coefficients"``, ``"log"``, ``"static"``).
    friction_nonneg : bool
        The friction unknowns physical as their terms declare (``nonnegative`` and the
        data term's ``dissipation`` rows).

    Raises
    ------
    InfeasibleError
        The bounds themselves contradict each other (a total-mass band outside what the
        link mass bounds allow).
    SolverError
        The solver failed; its status is named.
    OptionError
        The solver failed at the given ``prior_weight`` (``field``): the solver's statuses
        are named.
    ShapeError
        The prior or the bounds are for another number of links.
    """
    t0 = time.perf_counter()
    opts = SDPOptions() if options is None else options
    b, band = _checked_bounds(robot, term, bounds, total_mass)
    pr = _resolved_prior(prior, robot, band)
    lo, hi, notes = mass_bounds(pr, b, opts.mass_factor)
    notes = list(term.notes) + notes
    check_band(lo, hi, band)
    nb = Bounds(lo, hi, b.com_min, b.com_max, b.inertia_min, b.inertia_max, band, b.link_names)
    equality = opts.fit == "equality" or (opts.fit == "auto" and term.exact)
    if not equality and term.A.shape[0] == 0:
        raise ModelError("the data term has no covariance; use fit='equality'")
    common = (term, pr, lo, hi, nb, band, opts)
    search: list[tuple[float, float]] = []

    def finish(
        phi: NDArray[np.float64],
        f: NDArray[np.float64] | None,
        ia: NDArray[np.float64] | None,
        w: float,
        fit: str,
        status: str,
        judgement: HeldOutJudgement | None = None,
    ) -> ConsistentResult:
        return build_result(
            robot,
            phi,
            f,
            term,
            pr,
            w,
            search,
            nb,
            band,
            opts,
            fit,
            status,
            kind,
            t0,
            notes,
            ia,
            judgement,
        )

    if equality:
        return _solve_equality(common, friction_nonneg, constraints, notes, finish)
    if opts.prior_weight is None:
        return _solve_weighted(common, friction_nonneg, constraints, notes, search, finish)
    try:
        return _solve_weighted(common, friction_nonneg, constraints, notes, search, finish)
    except SolverError as exc:  # at the user's weight: the option to change
        raise OptionError(
            f"{opts.prior_weight:g}: {exc}; hint: a smaller weight, or none (the automatic choice)",
            field="prior_weight",
        ) from exc


def _solve_weighted(
    common: tuple[Any, ...],
    friction_nonneg: bool,
    constraints: Sequence[Callable[..., Any]],
    notes: list[str],
    search: list[tuple[float, float]],
    finish: Callable[..., ConsistentResult],
) -> ConsistentResult:
    """Noisy coefficients: the covariance-weighted fit at the given prior weight, the
    automatic one, or the one judged on held-out folds."""
    term, pr, lo, hi, nb, band, opts = common
    rest = (False, False, friction_nonneg, constraints)
    prob = ConvexProblem(term, pr, lo, hi, nb, band, opts, *rest)
    if term.holdout is not None:
        folds = [
            ConvexProblem(ft, pr, lo, hi, nb, band, opts, *rest)
            for ft in fold_terms(term, term.holdout)
        ]
        w, judgement = judged(folds, term.holdout, opts)
        status = solved(prob, w)
        values = prob.values()
        judgement = with_training(judgement, term.holdout, solution_x(term, *values))
        notes.append(f"prior weight {w:.3g}: {judgement.choice}")
        _note_fallbacks(notes, [prob, *folds])
        return finish(*values, w, "weighted", status, judgement)
    if opts.prior_weight is not None:
        status = prob.solve(opts.prior_weight)
        if status.startswith("infeasible"):
            raise InfeasibleError("the bounds and constraints admit no consistent parameters")
        _note_fallbacks(notes, [prob])
        return finish(*prob.values(), opts.prior_weight, "weighted", status)
    w, limit, status, (phi, f, ia), search[:] = auto_weight(prob, term, opts)
    notes.append(auto_weight_note(w, limit, search, opts))
    _note_fallbacks(notes, [prob])
    return finish(phi, f, ia, w, "weighted", status)


def _note_fallbacks(notes: list[str], problems: Sequence[ConvexProblem]) -> None:
    """Say once when the solver's first attempt failed (:func:`fallback_note`)."""
    note = fallback_note(problems)
    if note is not None:
        notes.append(note)


def _checked_bounds(
    robot: Robot,
    term: DataTerm,
    bounds: Bounds | None,
    total_mass: tuple[float, float] | None,
) -> tuple[Bounds, tuple[float, float] | None]:
    """The bounds (default :func:`~dynid.feasibility.bounds.default_bounds`) and the total-mass
    band [kg] (``total_mass`` over the bounds' own), both checked against the robot and the
    data term's number of links."""
    n = robot.n
    if not 10 * n <= term.P.shape[1] <= 11 * n:  # the links, then rotor inertias held
        raise ShapeError(f"data term is for {term.P.shape[1] // 10} links; robot has {n}")
    b = default_bounds(robot) if bounds is None else bounds
    if b.n != n:
        raise ShapeError(f"bounds are for {b.n} links; robot {robot.name!r} has {n}")
    if total_mass is not None:  # checked as the bounds' own band is
        b = b.with_total_mass(total_mass)
    return b, b.total_mass


def _resolved_prior(
    prior: Prior | Robot | None, robot: Robot, band: tuple[float, float] | None
) -> Prior:
    """The prior as a :class:`Prior` (for None the robot's own inertials, or the generic
    one when it has none: :func:`~dynid.feasibility.prior.default_prior`), checked against
    the robot."""
    if prior is None:
        pr = default_prior(robot, band)
    elif isinstance(prior, Prior):
        pr = prior
    else:
        pr = prior_from_robot(prior, total_mass=band)
    if pr.n != robot.n:
        raise ShapeError(
            f"prior {pr.source!r} has {pr.n} links; robot {robot.name!r} has {robot.n}"
        )
    return pr


def _solve_equality(
    common: tuple[Any, ...],
    friction_nonneg: bool,
    constraints: Sequence[Callable[..., Any]],
    notes: list[str],
    finish: Callable[..., ConsistentResult],
) -> ConsistentResult:
    """Exact coefficients: ``P phi = beta`` met exactly, or, where the bounds exclude that, the
    closest consistent set (least relative coefficient error) with a note."""
    term, pr, lo, hi, nb, band, opts = common
    prob = ConvexProblem(
        term, pr, lo, hi, nb, band, opts, True, False, friction_nonneg, constraints
    )
    status = prob.solve(1.0)
    if status.startswith("infeasible"):
        notes.append(
            "no consistent parameter set reproduces the coefficients exactly within the "
            "bounds; the closest one (least relative coefficient error) is returned"
        )
        prob = ConvexProblem(
            term, pr, lo, hi, nb, band, opts, False, True, friction_nonneg, constraints
        )
        if prob.solve(1.0).startswith("infeasible"):
            raise InfeasibleError("the bounds and constraints admit no consistent parameters")
        return finish(*prob.values(), 1.0, "equality", "infeasible")
    phi, f, ia = prob.values()
    phi = polish(phi, term, pr, ia)
    if f is not None:
        f = term.x_hat[term.r :].copy()
    return finish(phi, f, ia, 1.0, "equality", status)
