"""The penalty method's entry points: from identified coefficients (:func:`retrieve`,
:func:`retrieve_from_coefficients`) and from static data (:func:`retrieve_from_static`, the
single-step variant), each a :class:`~dynid.feasibility.penalty.objective.PenaltyProblem`
solved by Algorithm 1 (:mod:`dynid.feasibility.penalty.algorithm`); the method's registry
entry (:data:`METHOD`, :mod:`dynid.feasibility.methods`)."""

from __future__ import annotations

from collections.abc import Callable, Sequence
from typing import Any

from numpy.typing import ArrayLike

from ...exceptions import ModelError, ShapeError, WrongTypeError
from ...identification.log import TorqueLog
from ...identification.model import IdentifiedModel
from ...model.robot import Robot
from ...regressors.base import BaseParameters
from ..bounds import Bounds, default_bounds
from ..identified_terms import with_identified_terms
from .algorithm import solve
from .objective import (
    PenaltyProblem,
    coefficient_problem,
    static_problem,
    with_prior,
)
from .options import RetrievalOptions
from .result import RetrievalProgress, RetrievalResult

__all__ = [
    "METHOD",
    "PenaltyMethod",
    "retrieve",
    "retrieve_from_coefficients",
    "retrieve_from_static",
]


def _prior_problem(
    problem: PenaltyProblem, robot: Robot, prior: Any, weight: float
) -> PenaltyProblem:
    """``problem`` pulled towards ``prior`` (a Prior, a Robot with inertials, or None)."""
    if prior is None:
        return problem
    from ..prior import Prior, prior_from_robot

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
    return solve(
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
    parameters, the result and the errors. The model's friction (offsets included),
    springs and drive are carried unchanged onto the result
    (:func:`~dynid.feasibility.identified_terms.with_identified_terms`), which
    :func:`dynid.io.export.save_robot` of the result writes.

    Examples
    --------
    >>> import dynid
    >>> from dynid.regressors.base import base_parameters
    >>> from dynid.feasibility.penalty import retrieve_from_coefficients
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
    res = retrieve_from_coefficients(
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
    return with_identified_terms(res, model)


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
    return solve(
        problem,
        robot,
        b,
        options,
        workers=workers,
        seed=seed,
        progress=progress,
        require_feasible=require_feasible,
    )


class PenaltyMethod:
    """The paper's penalty method in the registry of consistent-parameter methods
    (:class:`~dynid.feasibility.methods.ConsistentMethod`): :func:`retrieve` from
    coefficients, :func:`retrieve_from_static` from static data (a torque log is refused:
    identify it first, or take the convex method)."""

    name = "penalty"
    description = "the paper's penalty method (Gaz et al. 2019, Algorithm 1)"
    options_type: type = RetrievalOptions
    parallel = True

    @staticmethod
    def _checked(options: Any) -> RetrievalOptions | None:
        if options is not None and not isinstance(options, RetrievalOptions):
            raise WrongTypeError(
                f"the penalty method takes RetrievalOptions; got {type(options).__name__}"
            )
        return options

    def from_coefficients(
        self,
        model: IdentifiedModel,
        *,
        prior: Any = None,
        bounds: Bounds | None = None,
        total_mass: tuple[float, float] | None = None,
        options: RetrievalOptions | None = None,
        workers: int | None = None,
        seed: int | None = 0,
        progress: Callable[[RetrievalProgress], None] | None = None,
    ) -> RetrievalResult:
        """:func:`retrieve`."""
        return retrieve(
            model,
            prior=prior,
            bounds=bounds,
            total_mass=total_mass,
            options=self._checked(options),
            workers=workers,
            seed=seed,
            progress=progress,
        )

    def from_data(
        self,
        robot: Robot,
        data: Any,
        *,
        prior: Any = None,
        bounds: Bounds | None = None,
        total_mass: tuple[float, float] | None = None,
        options: RetrievalOptions | None = None,
        workers: int | None = None,
        seed: int | None = 0,
        progress: Callable[[RetrievalProgress], None] | None = None,
    ) -> RetrievalResult:
        """:func:`retrieve_from_static`; a torque log raises
        :class:`~dynid.exceptions.WrongTypeError`."""
        if isinstance(data, TorqueLog):
            raise WrongTypeError(
                "the penalty method fits static data in one step, not a torque log: identify "
                "the log first and retrieve from its coefficients, or use the convex method"
            )
        return retrieve_from_static(
            robot,
            data,
            prior=prior,
            bounds=bounds,
            total_mass=total_mass,
            options=self._checked(options),
            workers=workers,
            seed=seed,
            progress=progress,
        )


#: the penalty method's entry in :data:`dynid.feasibility.methods.METHODS`
METHOD = PenaltyMethod()
