"""The consistent-parameter methods side by side on the same identified coefficients.

:func:`compare_methods` runs the convex retrieval
(:func:`~dynid.feasibility.convex.fit.retrieve_sdp`) and the paper's penalty method
(:func:`~dynid.feasibility.penalty.fit.retrieve`, without and with the prior term) on one
:class:`~dynid.identification.model.IdentifiedModel`, and summarises each
(:class:`MethodSummary`): the residual on the coefficients, the smallest margin of every
physical constraint, the distances to the prior and, in simulation, to the true
parameters, and the wall time.
"""

from __future__ import annotations

import time
from dataclasses import dataclass
from typing import Any

import numpy as np
from numpy.typing import NDArray

from ..identification.model import IdentifiedModel
from ..model.inertia import inertial_from_phi, phi_from_inertial
from ..model.robot import Robot
from .bounds import Bounds
from .constraints import feasibility_report
from .convex import SDPOptions, retrieve_sdp
from .lmi import repair_pseudo_inertia
from .penalty import RetrievalOptions, retrieve
from .prior import Prior, prior_from_robot
from .result import FeasibleResult

__all__ = ["MethodSummary", "compare_methods", "perturbed_robot"]

_PHYSICAL = ("mass_positive", "inertia_positive_definite", "triangle_inequality")


@dataclass(frozen=True, slots=True, eq=False)
class MethodSummary:
    """One method's result on the coefficients.

    Attributes
    ----------
    name : str
        ``"sdp"``, ``"penalty"`` or ``"penalty + prior"``.
    result : FeasibleResult
        :class:`~dynid.feasibility.convex.result.ConsistentResult` or
        :class:`~dynid.feasibility.penalty.result.RetrievalResult`.
    feasible : bool
    relative_residual : float
        ``||P phi - beta|| / ||beta||`` over the kept coefficients.
    min_margin : dict of str to float
        Smallest margin per physical constraint (``mass_positive`` [kg],
        ``inertia_positive_definite`` and ``triangle_inequality`` [kg m^2]) and
        ``pseudo_inertia`` (``lambda_min(J)/tr(J)``, dimensionless).
    lightest_link : float
        Smallest link mass [kg].
    mass_error_truth : float or None
        Median over links 2..n of ``|m - m_true| / m_true`` (link 1 of a fixed-base arm is
        mostly unidentifiable).
    mass_distance_prior : float
        The same against the prior.
    time : float
        Wall time [s].
    """

    name: str
    result: FeasibleResult
    feasible: bool
    relative_residual: float
    min_margin: dict[str, float]
    lightest_link: float
    mass_error_truth: float | None
    mass_distance_prior: float
    time: float

    def as_dict(self) -> dict[str, Any]:
        """JSON-ready (without the result itself)."""
        return {
            "method": self.name,
            "feasible": self.feasible,
            "relative_residual": self.relative_residual,
            "min_margin": dict(self.min_margin),
            "lightest_link_kg": self.lightest_link,
            "median_mass_error_truth": self.mass_error_truth,
            "median_mass_distance_prior": self.mass_distance_prior,
            "time_s": self.time,
        }


def perturbed_robot(
    robot: Robot, rng: np.random.Generator, spread: float = 0.2, margin: float = 2e-4
) -> Robot:
    """A plausible other robot of the same kind, for simulation studies: every mass, CoM
    coordinate and inertia entry of ``robot`` scaled by a factor drawn in
    ``1 +- spread``, then kept physically consistent (pseudo-inertia eigenvalues floored
    at ``margin`` times the trace, :func:`~dynid.feasibility.lmi.repair_pseudo_inertia`)."""
    n = robot.n
    m, c, I = inertial_from_phi(robot.phi.reshape(n, 10))
    I2 = I * (1 + rng.uniform(-spread, spread, (n, 3, 3)))
    phi = phi_from_inertial(
        m * (1 + rng.uniform(-spread, spread, n)),
        c * (1 + rng.uniform(-spread, spread, (n, 3))),
        0.5 * (I2 + np.swapaxes(I2, 1, 2)),
    )
    return robot.with_params(repair_pseudo_inertia(phi, margin)[0])


def _median_rel(m: NDArray[np.float64], ref: NDArray[np.float64]) -> float:
    return float(np.median(np.abs(m[1:] - ref[1:]) / np.abs(ref[1:])))


def _summary(
    name: str,
    res: FeasibleResult,
    model: IdentifiedModel,
    prior: Prior,
    truth: Robot | None,
    t: float,
) -> MethodSummary:
    phi = res.phi
    ia = res.rotor_inertia
    if model.base.n_std > phi.size and ia is None:  # a method of the links alone
        model = model.links_only()
    keep = np.asarray(model.fit.kept, dtype=bool)
    P = model.base.projection[keep]
    beta = np.asarray(model.fit.beta)[keep]
    std = phi.reshape(-1) if model.base.n_std == phi.size else np.concatenate([phi.ravel(), ia])
    rel = float(np.linalg.norm(P @ std - beta) / np.linalg.norm(beta))
    rep = feasibility_report(res.robot)
    margins = {n: float(rep.min_margin(n)) for n in _PHYSICAL}
    margins["pseudo_inertia"] = float(res.pseudo_inertia_margin.min())
    return MethodSummary(
        name=name,
        result=res,
        feasible=bool(res.feasible),
        relative_residual=rel,
        min_margin=margins,
        lightest_link=float(res.robot.mass.min()),
        mass_error_truth=None if truth is None else _median_rel(res.robot.mass, truth.mass),
        mass_distance_prior=_median_rel(res.robot.mass, prior.mass),
        time=t,
    )


def compare_methods(
    model: IdentifiedModel,
    prior: Prior | Robot,
    *,
    truth: Robot | None = None,
    bounds: Bounds | None = None,
    sdp_options: SDPOptions | None = None,
    penalty_options: RetrievalOptions | None = None,
    workers: int | None = None,
    seed: int = 0,
    progress: Any = None,
) -> list[MethodSummary]:
    """Convex retrieval, penalty method and penalty method with the prior, summarised.

    Parameters
    ----------
    model : IdentifiedModel
        The coefficients (with their covariance) all methods start from; the penalty
        method gets :meth:`~dynid.identification.model.IdentifiedModel.links_only` (its
        rotor inertias of their own left out), the convex one identifies them too.
    prior : Prior or Robot
        Prior parameters (the convex method, and the third run of the penalty method).
    truth : Robot, optional
        The true parameters, in simulation.
    bounds, sdp_options, penalty_options, workers, seed, progress
        Passed to the methods (``progress`` to the penalty runs).

    Returns
    -------
    list of MethodSummary
        In the order ``sdp``, ``penalty``, ``penalty + prior``.
    """
    pr = prior if isinstance(prior, Prior) else prior_from_robot(prior)
    out = []
    t0 = time.perf_counter()
    sdp = retrieve_sdp(model, prior=pr, bounds=bounds, options=sdp_options)
    out.append(_summary("sdp", sdp, model, pr, truth, time.perf_counter() - t0))
    links = model.links_only()  # the penalty method knows link parameters only
    for name, p in (("penalty", None), ("penalty + prior", pr)):
        t0 = time.perf_counter()
        res = retrieve(
            links,
            bounds=bounds,
            options=penalty_options,
            workers=workers,
            seed=seed,
            progress=progress,
            prior=p,
        )
        out.append(_summary(name, res, model, pr, truth, time.perf_counter() - t0))
    return out
