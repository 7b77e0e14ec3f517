"""Physically consistent parameters by convex optimisation (LMI, semidefinite programming).

Every link's pseudo-inertia ``J_i(phi)`` (:mod:`dynid.feasibility.lmi`) is kept positive
definite with a margin, and the parameters are pulled towards a prior ``J0_i``
(:mod:`dynid.feasibility.prior`) in the directions the data cannot see:

.. math:: \\min_{\\phi, f} \\; w \\sum_i d(J_i(\\phi), J_{0,i})
          + \\tfrac12 \\| A (x - \\hat x) \\|^2, \\quad x = [P \\phi;\\, f]

subject to ``J_i >= epsilon tr(J_i) 1`` (every link), ``m_min <= m_i <= m_max``, the CoM box
``m_i c_min <= h_i <= m_i c_max`` and ``M_min <= sum m_i <= M_max``

(Wensing, Kim, Slotine, RA-L 2018; Lee, Wensing, Park, T-RO 2020). ``P`` maps the standard
parameters to the base parameters, ``x_hat`` is the least-squares estimate and ``A^T A`` the
inverse of its covariance, so the data term is the increase of the identification's
residual sum of squares in units of its noise variance (``Delta chi^2``).

* **Two-step** (:func:`retrieve_sdp`, the paper's setting): ``x = beta``, the identified
  coefficients with their full covariance. When the coefficients are exact (a residual below
  1e-9 relative), the data term becomes the equality ``P phi = beta`` and the result is
  polished by a minimum-norm correction so that it holds to round-off.
* **One-step** (:func:`identify_consistent`): the same problem on data, with the classical
  friction ``f = (fv, fc, fo)`` per joint as extra unknowns, ``fv, fc >= 0`` (torque logs),
  or on static ``[tril M; g]`` data. The data term is then exactly
  ``||W x - y||^2 / sigma^2`` up to a constant, ``W`` the stacked regressor.

**The prior's weight** ``w``: when the data term holds held-out folds (torque logs: k-fold
over contiguous time blocks, or a separate log), the largest weight whose *held-out* error
is within ``residual_increase`` (1 %) of the best, and the result is accepted when its
held-out error is within ``heldout_tol`` (5 %) of unconstrained least squares', whatever its
training residual (:mod:`dynid.feasibility.heldout`). Otherwise (static data,
coefficients) the largest weight (over a logarithmic search) whose fit keeps the
identification's residual RMS within ``residual_increase`` (1 %) of the unconstrained
least squares, ``Delta chi^2 <= ((1 + 0.01)^2 - 1) dof``. Either way the prior decides
only what the data leave open. A larger weight trusts the prior more.

**Margin** ``epsilon`` (default 1e-4): ``lambda_min(J) >= epsilon tr(J)`` for every link;
the published Panda's links lie between 2e-4 and 2e-3 of their trace.

**Objectives**: ``"logdet"`` (the Bregman divergence above, default) or ``"euclidean"``,
``sum_i ||S0_i^{-1} J_i S0_i^{-T} - 1||_F^2`` (the prior's own metric).

**Solver**: cvxpy with Clarabel, in whitened variables ``X_i = S0_i^{-1} J_i S0_i^{-T}``
(``J0_i = S0_i S0_i^T``); when the interior-point method stalls it is retried with
``max_iter=500`` and static regularisation ``1e-7``, then with SCS (``eps=1e-7``, 20 000
iterations); a failure raises
:class:`~dynid.exceptions.SolverError` with the solver's status. An equality that no
consistent set meets is reported (``feasible = False``, status ``"infeasible"``) with the
closest consistent set (least relative coefficient error) and how far it is.
"""

from __future__ import annotations

import dataclasses
import math
import time
import warnings
from collections.abc import Callable, Mapping, Sequence
from dataclasses import dataclass
from types import MappingProxyType
from typing import Any, ClassVar

import numpy as np
from numpy.typing import NDArray

from ..exceptions import DataError, InfeasibleError, ModelError, ShapeError, SolverError
from ..identification.holdout import HeldOut, cross_validate
from ..identification.least_squares import LeastSquaresFit
from ..identification.model import IdentifiedModel
from ..model.drive import Drive
from ..model.inertia import inertial_from_phi
from ..model.robot import Robot
from .bounds import Bounds, default_bounds, segment_points
from .constraints import Constraint, FeasibilityReport, feasibility_report
from .heldout import DEFAULT_HELDOUT_TOL, HeldOutJudgement, search_weight
from .lmi import (
    log_det_divergence,
    pseudo_inertia,
    pseudo_inertia_margin,
    repair_pseudo_inertia,
)
from .prior import Prior, generic_prior, prior_from_robot, prior_scales
from .result import FeasibleResult

__all__ = [
    "DEFAULT_SDP_MARGIN",
    "ConsistentResult",
    "DataTerm",
    "SDPOptions",
    "coefficient_term",
    "retrieve_sdp",
    "solve_consistent",
]

#: Default margin ``epsilon``: ``lambda_min(J_i) >= epsilon tr(J_i)``.
DEFAULT_SDP_MARGIN = 1e-4
#: Relative residual below which identified coefficients count as exact.
EXACT_RTOL = 1e-9
#: Range of the automatic weight search and its number of bisection steps.
WEIGHT_RANGE = (1e-4, 1e6)
WEIGHT_BISECTIONS = 6

#: Boxes and the band are shrunk by this fraction of their width inside the solver, so
#: that its tolerance (about 1e-8) cannot put the solution outside them.
_SHRINK = 1e-6
_OBJECTIVES = ("logdet", "euclidean")
_FITS = ("auto", "equality", "weighted")
#: T (10, 16): phi of a link from vec(J) (row-major 4x4): m, h, J_o = tr(S) 1 - S.
_T = np.zeros((10, 16))
_T[0, 15] = 1.0
_T[1, 3] = _T[2, 7] = _T[3, 11] = 1.0
for _k, (_i, _j) in enumerate(((0, 0), (0, 1), (0, 2), (1, 1), (1, 2), (2, 2))):
    if _i == _j:
        for _d in range(3):
            if _d != _i:
                _T[4 + _k, 5 * _d] = 1.0
    else:
        _T[4 + _k, 4 * _i + _j] = -1.0


@dataclass(frozen=True, slots=True)
class SDPOptions:
    """Settings of the convex retrieval (module docstring).

    Attributes
    ----------
    objective : {"logdet", "euclidean"}
        Distance to the prior.
    prior_weight : float or None
        ``w``; None chooses it automatically (``residual_increase``).
    residual_increase : float
        Automatic weight: largest increase of the residual RMS allowed (0.01 = 1 %).
    margin : float
        ``epsilon`` of ``lambda_min(J) >= epsilon tr(J)`` (dimensionless, >= 0).
    fit : {"auto", "equality", "weighted"}
        ``"equality"``: ``P phi = beta``; ``"weighted"``: the covariance-weighted data
        term; ``"auto"``: equality for exact coefficients, weighted otherwise.
    mass_factor : float or None
        Masses within ``[m0 / f, f m0]`` of the prior's (intersected with the bounds);
        None: the bounds alone. Not applied with the generic prior (a guess).
    residual_tol : float
        The report's ``data_fit`` holds when the parameters reproduce the data: with an
        exact fit, a relative residual on the coefficients below 1e-6; with a weighted fit,
        a residual RMS at most ``residual_tol`` (default 10 %) above the unconstrained
        fit's. Beyond it the result is reported not consistent with the specification: the
        constraints (margin, bounds, total-mass band) or the prior exclude what the data
        say. Not used when the data term holds held-out folds (``heldout_tol`` decides).
    heldout_tol : float
        With held-out folds: ``data_fit`` holds when the consistent fit's held-out error is
        at most this fraction (default 5 %) above unconstrained least squares'.
    tol : float
        Relative tolerance of the feasibility report.
    """

    objective: str = "logdet"
    prior_weight: float | None = None
    residual_increase: float = 0.01
    margin: float = DEFAULT_SDP_MARGIN
    fit: str = "auto"
    mass_factor: float | None = 3.0
    residual_tol: float = 0.10
    heldout_tol: float = DEFAULT_HELDOUT_TOL
    tol: float = 1e-9

    def __post_init__(self) -> None:
        if self.objective not in _OBJECTIVES:
            raise ModelError(f"objective must be one of {_OBJECTIVES}; got {self.objective!r}")
        if self.fit not in _FITS:
            raise ModelError(f"fit must be one of {_FITS}; got {self.fit!r}")
        if self.prior_weight is not None and not (
            math.isfinite(self.prior_weight) and self.prior_weight > 0
        ):
            raise ModelError(f"prior weight must be finite and > 0; got {self.prior_weight}")
        if not (math.isfinite(self.margin) and 0.0 <= self.margin < 0.25):
            raise ModelError(f"margin must be in [0, 0.25); got {self.margin}")
        if not self.residual_increase > 0:
            raise ModelError(f"residual_increase must be > 0; got {self.residual_increase}")
        if self.mass_factor is not None and not self.mass_factor > 1:
            raise ModelError(f"mass_factor must be > 1 or None; got {self.mass_factor}")


@dataclass(frozen=True, slots=True, eq=False)
class DataTerm:
    """The data term ``1/2 ||A (x - x_hat)||^2`` over ``x = [P phi; f]``.

    Attributes
    ----------
    P : ndarray, shape (r, 10 n) or (r, 11 n)
        Standard to base parameters (kept coefficients only); with identified rotor
        inertias (:mod:`dynid.model.drive`) the last ``n`` columns are ``Ia1 .. Ia_n``, kept
        ``>= 0`` in the consistent fit.
    x_hat : ndarray, shape (r + k,)
        Least-squares estimate (base parameters, then ``k`` friction coefficients).
    A : ndarray, shape (s, r + k)
        Whitening: ``A^T A`` is the inverse covariance of ``x_hat``.
    dof : int
        Degrees of freedom of the fit's residual (rows minus coefficients).
    exact : bool
        The estimate is exact (noise-free): the equality ``P phi = beta`` applies.
    n_friction : int
        ``k``: 0, or the classical friction coefficients fitted (``fv, fc, fo`` per joint,
        less those of joints that never moved).
    friction_index : ndarray of int, shape (k,), optional
        Where each friction unknown sits in the ``(n, 3)`` layout ``fv, fc, fo`` per joint
        (flattened); None: all ``3 n`` in order.
    labels : tuple of str
        Names of the entries of ``x``.
    notes : tuple of str
        What the user should know about the data term (a missing covariance).
    holdout : HeldOut, optional
        Normal equations of the held-out folds over the entries of ``x``
        (:mod:`dynid.identification.holdout`): the weight and the acceptance are then
        judged on held-out data.
    """

    P: NDArray[np.float64]
    x_hat: NDArray[np.float64]
    A: NDArray[np.float64]
    dof: int
    exact: bool
    n_friction: int = 0
    friction_index: NDArray[np.intp] | None = None
    labels: tuple[str, ...] = ()
    notes: tuple[str, ...] = ()
    holdout: HeldOut | None = None

    @property
    def r(self) -> int:
        """Number of base parameters in ``x``."""
        return int(self.P.shape[0])

    def friction_layout(self) -> NDArray[np.intp]:
        """:attr:`friction_index`, or ``0 .. k-1`` when every coefficient is fitted."""
        if self.friction_index is None:
            return np.arange(self.n_friction)
        return np.asarray(self.friction_index)

    def friction_table(self, f: NDArray[np.float64], n: int) -> NDArray[np.float64]:
        """The fitted friction unknowns ``f`` (k,) as the (n, 3) table ``fv, fc, fo`` (zero
        for the coefficients not fitted)."""
        out = np.zeros(3 * n)
        out[self.friction_layout()] = f
        return out.reshape(n, 3)

    def chi2(self, x: NDArray[np.float64]) -> float:
        """``||A (x - x_hat)||^2``: the increase of the residual sum of squares / sigma^2."""
        return float(np.sum((self.A @ (x - self.x_hat)) ** 2))


def _whitening(cov: NDArray[np.float64]) -> NDArray[np.float64]:
    """``A`` with ``A^T A = cov^+`` (directions of zero variance dropped)."""
    cov = 0.5 * (cov + cov.T)
    s, U = np.linalg.eigh(cov)
    keep = s > 1e-14 * max(float(s.max()), 0.0)
    return (U[:, keep] / np.sqrt(s[keep])).T


def coefficient_term(model: IdentifiedModel, *, with_friction: bool = False) -> DataTerm:
    """The data term of identified coefficients (and their friction) with their covariance.

    Uses ``model.fit.covariance`` (or ``model.joint_fit``'s with friction); without a
    covariance (a file written before it was kept) the standard deviations, uncorrelated.
    Pruned coefficients are left out.
    """
    fit: LeastSquaresFit = model.fit
    r_all = model.base.rank
    k = 0
    if with_friction:
        if model.joint_fit is None:
            raise ModelError("the model holds no friction identified with the coefficients")
        fit = model.joint_fit
        k = fit.beta.shape[0] - r_all
    kept = np.asarray(fit.kept, dtype=bool)
    kept_b = kept[:r_all]
    P = model.base.projection[kept_b]
    x_hat = np.asarray(fit.beta, dtype=np.float64)[kept]
    notes: tuple[str, ...] = ()
    if fit.covariance is None:
        cov = np.diag(np.asarray(fit.std, dtype=np.float64) ** 2)
        notes = (
            "no covariance of the coefficients (an older file): their standard deviations "
            "are used as if uncorrelated",
        )
    else:
        cov = np.asarray(fit.covariance, dtype=np.float64)
    cov = cov[np.ix_(kept, kept)]
    if cov.size:
        ev = np.linalg.eigvalsh(0.5 * (cov + cov.T))
        if ev[0] < -1e-9 * max(float(ev[-1]), 0.0) or not ev[-1] >= 0:
            raise DataError(
                "the covariance of the coefficients is not positive semidefinite (eigenvalues "
                f"{ev[0]:.3g} .. {ev[-1]:.3g}); re-run the identification"
            )
    rel = fit.relative_error_percent / 100.0
    exact = bool(fit.sigma == 0.0 or rel < EXACT_RTOL or not np.any(cov))
    labels = tuple(
        lab
        for lab, kk in zip(
            model.base.labels + _friction_labels(model)[:k],
            kept,
            strict=False,
        )
        if kk
    )
    held = model.holdout
    if held is not None and held.whole.p != kept.size:
        held = None  # folds over other columns (friction left out of the term)
    return DataTerm(
        P=P,
        x_hat=x_hat,
        A=np.zeros((0, x_hat.size)) if exact else _whitening(cov),
        dof=max(int(fit.n_rows) - int(fit.rank), 1),
        exact=exact,
        n_friction=int(kept[r_all:].sum()) if k else 0,
        friction_index=np.flatnonzero(kept[r_all:]) if k else None,
        labels=labels,
        notes=notes,
        holdout=None if held is None else held.restricted(np.flatnonzero(kept)),
    )


def _friction_labels(model: IdentifiedModel) -> tuple[str, ...]:
    """The labels of the model's friction columns (empty without friction)."""
    fr = model.info.friction
    return () if fr is None else fr.labels


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
    or ``"static"`` (one-step); ``friction`` (one-step on a torque log) holds ``fv, fc >= 0``;
    ``drive`` is the data's drive train with the identified rotor inertias
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
        repaired links, mass [kg] per link), ``prior_weight``, ``weight_search``
        (``[w, residual_ratio]``), ``residual_ratio``, ``divergence`` per link,
        ``distance_to_prior`` (mass [kg], CoM [m] per link), ``solver``, ``status``,
        ``on_bound`` and ``options``."""
        pm, pc, _ = inertial_from_phi(self.prior.phi)
        o = self.options
        return {
            "fit": self.fit,
            "prior": {
                "source": self.prior.source,
                "repaired_links": list(self.prior.repaired),
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


# ------------------------------------------------------------------------- the problem
def _mass_bounds(
    prior: Prior, bounds: Bounds, factor: float | None
) -> tuple[NDArray[np.float64], NDArray[np.float64], list[str]]:
    lo = np.array(bounds.mass_min, dtype=float)
    hi = np.array(bounds.mass_max, dtype=float)
    notes: list[str] = []
    if factor is None or prior.source == "generic":  # a guess does not bound the masses
        return lo, hi, notes
    m0 = prior.mass
    plo, phi_ = m0 / factor, m0 * factor
    nlo, nhi = np.maximum(lo, plo), np.minimum(hi, phi_)
    empty = nlo > nhi
    for i in np.flatnonzero(empty):
        notes.append(
            f"link {i + 1}: the prior's mass range {plo[i]:.3g}..{phi_[i]:.3g} kg lies outside "
            f"the bounds {lo[i]:g}..{hi[i]:g} kg; the bounds alone are used"
        )
    return np.where(empty, lo, nlo), np.where(empty, hi, nhi), notes


def _check_band(lo: NDArray[np.float64], hi: NDArray[np.float64], band: Any) -> None:
    if band is None:
        return
    a, b = (float(x) for x in band)
    if not (math.isfinite(a) and math.isfinite(b)) or a < 0 or a > b:
        raise InfeasibleError(f"total-mass band must be MIN,MAX with 0 <= MIN <= MAX; got {band}")
    if lo.sum() > b or hi.sum() < a:
        raise InfeasibleError(
            f"total-mass band {a:g}..{b:g} kg cannot be met: the link mass bounds allow "
            f"{lo.sum():.4g}..{hi.sum():.4g} kg in all"
        )


class _Problem:
    """The cvxpy problem, built once; the weight is a parameter (re-solved cheaply)."""

    def __init__(
        self,
        term: DataTerm,
        prior: Prior,
        mass_lo: NDArray[np.float64],
        mass_hi: NDArray[np.float64],
        bounds: Bounds,
        band: tuple[float, float] | None,
        options: SDPOptions,
        equality: bool,
        closest: bool,
        friction_nonneg: bool,
        constraints: Sequence[Callable[..., Any]],
    ) -> None:
        import cvxpy as cp

        n = prior.n
        J0 = prior.pseudo_inertia
        self.S0 = np.linalg.cholesky(J0)
        self.X = [cp.Variable((4, 4), symmetric=True, name=f"X{i + 1}") for i in range(n)]
        self.J = [self.S0[i] @ self.X[i] @ self.S0[i].T for i in range(n)]
        B = np.stack([_T @ np.kron(self.S0[i], self.S0[i]) for i in range(n)])  # (n, 10, 16)
        self.B = B
        phis = [B[i] @ cp.vec(self.X[i], order="C") for i in range(n)]
        phi = cp.hstack(phis)
        self.phi_links = phis
        self.w = cp.Parameter(nonneg=True, value=1.0, name="w")
        eps = self.margin = options.margin
        self.scale = 1.0 if equality or closest else float(max(term.dof, 1))
        self.equality = equality
        cons: list[Any] = []
        for i in range(n):
            C = self.S0[i].T @ self.S0[i]
            Ci = np.linalg.inv(C)
            Ci = 0.5 * (Ci + Ci.T)
            cons.append(self.X[i] - eps * cp.trace(C @ self.X[i]) * Ci >> 0)
            m, h = phis[i][0], phis[i][1:4]
            dm = _SHRINK * (mass_hi[i] - mass_lo[i])
            dc = _SHRINK * (bounds.com_max[i] - bounds.com_min[i])
            cons += [m >= mass_lo[i] + dm, m <= mass_hi[i] - dm]
            cons += [h >= m * (bounds.com_min[i] + dc), h <= m * (bounds.com_max[i] - dc)]
        if band is not None:
            M = sum(p[0] for p in phis)
            db = _SHRINK * (band[1] - band[0])
            cons += [M >= band[0] + db, M <= band[1] - db]
        if options.objective == "logdet":
            div = sum(-cp.log_det(X) + cp.trace(X) - 4.0 for X in self.X)
        else:
            div = sum(cp.sum_squares(X - np.eye(4)) for X in self.X)
        k = term.n_friction
        self.f = cp.Variable(k, name="f") if k else None
        p_links = 10 * n
        self.ia = (
            cp.Variable(term.P.shape[1] - p_links, nonneg=True, name="Ia")
            if term.P.shape[1] > p_links
            else None
        )
        x = term.P[:, :p_links] @ phi
        if self.ia is not None:  # rotor inertias >= 0, regrouped with the links in P
            x = x + term.P[:, p_links:] @ self.ia
        if self.f is not None:
            x = cp.hstack([x, self.f])
            if friction_nonneg:  # fv, fc >= 0 (every joint's fo is free)
                pos = np.flatnonzero(term.friction_layout() % 3 != 2)  # fv, fc (not fo)
                sel = np.zeros((pos.size, k))
                sel[np.arange(pos.size), pos] = 1.0
                cons.append(sel @ self.f >= 0)
        for make in constraints:
            cons += list(make(phis, self.J))
        if equality:
            s = np.maximum(np.abs(term.x_hat), 1e-6 * max(float(np.abs(term.x_hat).max()), 1e-12))
            cons.append(cp.multiply(1.0 / s, x - term.x_hat) == 0)
            obj = div
        elif closest:
            s = np.maximum(np.abs(term.x_hat), 1e-3 * max(float(np.abs(term.x_hat).max()), 1e-12))
            obj = 1e-6 * div + 0.5 * cp.sum_squares(cp.multiply(1.0 / s, x - term.x_hat))
        else:
            # divided by dof (the data term's size at a good fit): same minimiser, better scaled
            ks = 1.0 / math.sqrt(self.scale)
            obj = self.w * div + 0.5 * cp.sum_squares(
                (ks * term.A) @ x - (ks * term.A) @ term.x_hat
            )
        self.problem = cp.Problem(cp.Minimize(obj), cons)
        self.term = term

    def solve(self, w: float) -> str:
        """Solve at weight ``w``; the status (retries as in the module docstring).

        The first ``optimal`` attempt is kept; otherwise an ``optimal_inaccurate`` one;
        ``infeasible`` only when every attempt says so (an interior-point method can
        misreport a badly scaled feasible problem).
        """
        import cvxpy as cp

        self.w.value = float(w) / self.scale
        attempts: list[tuple[str, dict[str, Any]]] = [
            ("CLARABEL", {}),
            ("CLARABEL", {"max_iter": 500, "static_regularization_constant": 1e-7}),
            ("SCS", {"eps": 1e-7, "max_iters": 20_000}),
        ]
        seen: list[str] = []
        inaccurate = None
        for solver, kw in attempts:
            try:
                with warnings.catch_warnings():  # the status says it; retried below
                    warnings.simplefilter("ignore", UserWarning)
                    self.problem.solve(solver=_scs() if solver == "SCS" else solver, **kw)
            except (cp.error.SolverError, ArithmeticError, ValueError) as exc:
                seen.append(f"{solver}: {exc}")
                continue
            status = str(self.problem.status)
            seen.append(f"{solver}: {status}")
            if status == "optimal":
                self._snapshot = self._read()
                return status
            if status == "optimal_inaccurate" and inaccurate is None:
                inaccurate = self._read()
            if status.startswith("infeasible") and self.equality:
                return status  # an exact fit with no consistent solution: a real answer
        if inaccurate is not None:
            self._snapshot = inaccurate
            return "optimal_inaccurate"
        if all(": infeasible" in x for x in seen):
            return "infeasible"
        raise SolverError("convex retrieval: the solver did not converge (" + "; ".join(seen) + ")")

    def _read(self) -> tuple[list[NDArray[np.float64]], NDArray[np.float64] | None, Any]:
        Xs = [np.array(X.value, dtype=float) for X in self.X]
        f = None if self.f is None else np.array(self.f.value, dtype=float)
        ia = None if self.ia is None else np.maximum(np.array(self.ia.value, dtype=float), 0.0)
        return Xs, f, ia

    def values(self) -> _Values:
        """``phi`` (n, 10), the friction (k,) and the rotor inertias (n,) at the solution
        (margins enforced; None for what the problem does not hold)."""
        Xs, f, ia = self._snapshot
        phi = np.stack([self.B[i] @ X.reshape(-1) for i, X in enumerate(Xs)])
        return _with_margin(phi, self.margin), f, ia


#: ``phi`` (n, 10), friction (k,) or None, rotor inertias (n,) or None.
def _scs() -> Any:
    """cvxpy's SCS interface that lets a Ctrl-C through: SCS catches SIGINT itself and
    returns its status -5, which cvxpy reports as a failed solve, so a retry or the rest of
    the run would go on as if nothing were asked; here it is a :class:`KeyboardInterrupt`."""
    from cvxpy.reductions.solvers.conic_solvers.scs_conif import SCS

    class InterruptibleSCS(SCS):
        def name(self) -> str:
            return "DYNID_SCS"  # (cvxpy refuses a custom solver under a built-in name)

        def invert(self, solution: Any, inverse_data: Any) -> Any:
            if solution["info"]["status_val"] == SCS_SIGINT:
                raise KeyboardInterrupt
            return super().invert(solution, inverse_data)

    return InterruptibleSCS()


#: SCS's status after it caught SIGINT
SCS_SIGINT = -5


_Values = tuple[NDArray[np.float64], NDArray[np.float64] | None, NDArray[np.float64] | None]


def _x(term: DataTerm, phi: NDArray[np.float64], f: Any, ia: Any) -> NDArray[np.float64]:
    """``x = [P [phi; Ia]; f]`` of a solution."""
    std = phi.reshape(-1) if ia is None else np.concatenate([phi.reshape(-1), ia])
    x = term.P @ std
    return x if f is None else np.concatenate([x, f])


def _with_margin(phi: NDArray[np.float64], margin: float) -> NDArray[np.float64]:
    """Links the solver left a little below the margin (its tolerance) floored onto it."""
    low = pseudo_inertia_margin(phi) < margin
    if not np.any(low):
        return phi
    out = phi.copy()
    out[low] = repair_pseudo_inertia(phi[low], margin)[0]
    return out


def _polish(
    phi: NDArray[np.float64], term: DataTerm, prior: Prior, ia: Any = None
) -> NDArray[np.float64]:
    """Minimum-norm correction (in the prior's scales) so that ``P phi = beta`` to round-off
    (rotor inertias kept as solved)."""
    scale = prior_scales(prior.phi)
    P = term.P[:, : phi.size]
    target = term.x_hat[: term.r] - (0.0 if ia is None else term.P[:, phi.size :] @ ia)
    x = phi.reshape(-1)
    for _ in range(2):
        e = target - P @ x  # the base part; friction is met exactly
        PD = P * scale
        x = x + scale * np.linalg.lstsq(PD, e, rcond=None)[0]
    return x.reshape(phi.shape)


def _active_and_implausible(
    robot: Robot,
    m: NDArray[np.float64],
    c: NDArray[np.float64],
    I: NDArray[np.float64],
    bounds: Bounds,
    band: tuple[float, float] | None,
) -> tuple[list[str], list[str]]:
    """Notes: the bounds the result sits on (they, not the data, decided those values) and
    links whose mass or size is implausible (a link under 1 % of the total mass, or a
    radius of gyration about the CoM over 1.5 times the link's extent); and the parameters
    on a bound, one string each."""
    out: list[str] = []
    names = robot.link_names[1:]
    act: list[str] = []
    for i in range(robot.n):
        w = max(bounds.mass_max[i] - bounds.mass_min[i], 1e-12)
        for side, b in (("lower", bounds.mass_min[i]), ("upper", bounds.mass_max[i])):
            if abs(m[i] - b) <= 1e-4 * w:
                act.append(f"{names[i]} mass {m[i]:.4g} kg at its {side} bound")
        for k, ax in enumerate("xyz"):
            wc = max(bounds.com_max[i, k] - bounds.com_min[i, k], 1e-12)
            for side, b in (("lower", bounds.com_min[i, k]), ("upper", bounds.com_max[i, k])):
                if abs(c[i, k] - b) <= 1e-4 * wc:
                    act.append(f"{names[i]} CoM {ax} {c[i, k]:+.4f} m at its {side} bound")
    if band is not None:
        M = float(m.sum())
        for side, b in (("lower", band[0]), ("upper", band[1])):
            if abs(M - b) <= 1e-4 * max(band[1] - band[0], 1e-3):
                act.append(f"total mass {M:.4g} kg at the {side} end of its band")
    if act:
        out.append("decided by the bound, not the data: " + "; ".join(act))
    M = float(m.sum())
    lam = np.linalg.eigvalsh(I)
    for i in range(robot.n):
        ext = max(float(np.linalg.norm(np.ptp(segment_points(robot, i), axis=0))), 0.05)
        rg = math.sqrt(max(float(lam[i].sum()), 0.0) / (2.0 * m[i])) if m[i] > 0 else math.inf
        if m[i] < 0.01 * M:
            out.append(f"implausible: {names[i]} weighs {m[i]:.3g} kg, under 1 % of the total")
        elif rg > 1.5 * ext:
            out.append(
                f"implausible: {names[i]} has a radius of gyration of {rg:.3g} m about its CoM, "
                f"more than 1.5 times its extent of {ext:.3g} m (rotor inertia the link "
                "absorbed, or inertia the data cannot see)"
            )
    return out, act


def _finish(
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
        nonneg = term.friction_layout() % 3 != 2
        f[nonneg] = np.maximum(f[nonneg], 0.0)  # fv, fc >= 0 held to the solver's tolerance
    m, c, I = inertial_from_phi(phi)
    out = robot.with_params(phi)
    found, act = _active_and_implausible(robot, m, c, I, bounds, band)
    notes = notes + found
    x = _x(term, phi, f, ia)
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
        friction=None if f is None else term.friction_table(f, robot.n),
        rotor_inertia=ia,
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
        Kinematics, gravity and friction of the result (its inertials are not used).
    term : DataTerm
        From :func:`coefficient_term` (or built by the one-step routes).
    prior : Prior or Robot, optional
        A :class:`~dynid.feasibility.prior.Prior`, a robot with link inertials (checked
        and repaired by :func:`~dynid.feasibility.prior.prior_from_robot`), or None for
        :func:`~dynid.feasibility.prior.generic_prior`.
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
        ``fv, fc >= 0`` for the friction unknowns of the data term.

    Raises
    ------
    InfeasibleError
        The bounds themselves contradict each other (a total-mass band outside what the
        link mass bounds allow).
    SolverError
        The solver failed; its status is named.
    ShapeError
        The prior or the bounds are for another number of links.
    """
    t0 = time.perf_counter()
    opts = SDPOptions() if options is None else options
    b, band = _checked_bounds(robot, term, bounds, total_mass)
    pr = _resolved_prior(prior, robot, band)
    lo, hi, notes = _mass_bounds(pr, b, opts.mass_factor)
    notes = list(term.notes) + notes
    _check_band(lo, hi, band)
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
        return _finish(
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
    prob = _Problem(*common, False, False, friction_nonneg, constraints)
    if term.holdout is not None:
        folds = [
            _Problem(ft, *common[1:], False, False, friction_nonneg, constraints)
            for ft in _fold_terms(term, term.holdout)
        ]
        w, judgement = _judged(folds, term.holdout, opts)
        status = _solved(prob, w)
        values = prob.values()
        judgement = _with_training(judgement, term.holdout, _x(term, *values))
        notes.append(f"prior weight {w:.3g}: {judgement.choice}")
        return finish(*values, w, "weighted", status, judgement)
    if opts.prior_weight is not None:
        status = prob.solve(opts.prior_weight)
        if status.startswith("infeasible"):
            raise InfeasibleError("the bounds and constraints admit no consistent parameters")
        return finish(*prob.values(), opts.prior_weight, "weighted", status)
    w, limit, status, (phi, f, ia), search[:] = _auto_weight(prob, term, opts)
    notes.append(_auto_weight_note(w, limit, search, opts))
    return finish(phi, f, ia, w, "weighted", status)


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
    if term.P.shape[1] not in (10 * n, 11 * n):
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
    """The prior as a :class:`Prior` (the generic one for None), checked against the robot."""
    if prior is None:
        pr = generic_prior(robot, band)
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
    prob = _Problem(term, pr, lo, hi, nb, band, opts, True, False, friction_nonneg, constraints)
    status = prob.solve(1.0)
    if status.startswith("infeasible"):
        notes.append(
            "no consistent parameter set reproduces the coefficients exactly within the "
            "bounds; the closest one (least relative coefficient error) is returned"
        )
        prob = _Problem(term, pr, lo, hi, nb, band, opts, False, True, friction_nonneg, constraints)
        if prob.solve(1.0).startswith("infeasible"):
            raise InfeasibleError("the bounds and constraints admit no consistent parameters")
        return finish(*prob.values(), 1.0, "equality", "infeasible")
    phi, f, ia = prob.values()
    phi = _polish(phi, term, pr, ia)
    if f is not None:
        f = term.x_hat[term.r :].copy()
    return finish(phi, f, ia, 1.0, "equality", status)


def _auto_weight_note(
    w: float, limit: float, search: list[tuple[float, float]], opts: SDPOptions
) -> str:
    """What the automatic prior weight (training residual, :func:`_auto_weight`) means."""
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


def _solved(prob: _Problem, w: float) -> str:
    """Solve at ``w``; an infeasible problem raises."""
    status = prob.solve(w)
    if status.startswith("infeasible"):
        raise InfeasibleError("the bounds and constraints admit no consistent parameters")
    return status


def _fold_terms(term: DataTerm, held: HeldOut) -> list[DataTerm]:
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


def _judged(
    folds: list[_Problem],
    held: HeldOut,
    opts: SDPOptions,
) -> tuple[float, HeldOutJudgement]:
    """The weight (the given one, or :func:`~dynid.feasibility.heldout.search_weight`) and
    the held-out errors of the consistent fit and of least squares over the folds. The folds
    are solved at ``w`` times their share of the rows (the full fit's balance of data and
    prior); the training errors are filled in by :func:`replace_training`."""
    share = held.training_share
    fold_terms = [p.term for p in folds]

    def heldout_at(w: float) -> float:
        xs = []
        for p, ft in zip(folds, fold_terms, strict=True):
            _solved(p, w * share)
            xs.append(_x(ft, *p.values()))
        return held.heldout_error_percent(xs)

    if opts.prior_weight is not None:
        w = opts.prior_weight
        search = [(w, heldout_at(w))]
        choice = "given"
    else:
        w, search, choice = search_weight(heldout_at, opts.residual_increase, WEIGHT_RANGE)
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


def _with_training(
    judgement: HeldOutJudgement, held: HeldOut, x: NDArray[np.float64]
) -> HeldOutJudgement:
    """The judgement with the training error of the fit ``x`` on all data."""
    return dataclasses.replace(judgement, training_percent=held.whole.relative_error_percent(x))


def _auto_weight(
    prob: _Problem, term: DataTerm, opts: SDPOptions
) -> tuple[float, float, str, _Values, list[tuple[float, float]]]:
    """Largest weight in :data:`WEIGHT_RANGE` whose residual ratio stays within the limit.

    The limit is ``1 + residual_increase``, or, when the consistent fit at the smallest
    weight already exceeds it (data that no rigid body fits within the allowance),
    ``(1 + residual_increase)`` times that fit's ratio. Decades upwards from the smallest
    weight, then :data:`WEIGHT_BISECTIONS` bisections of the logarithm. Returns the weight,
    the limit used, the status, the solution (:meth:`_Problem.values`) and every
    ``(w, ratio)`` tried.
    """
    search: list[tuple[float, float]] = []
    cache: dict[float, tuple[str, _Values]] = {}

    def ratio(e: float) -> float:
        w = 10.0**e
        status = prob.solve(w)
        if status.startswith("infeasible"):
            raise InfeasibleError("the bounds and constraints admit no consistent parameters")
        values = prob.values()
        rr = math.sqrt(1.0 + term.chi2(_x(term, *values)) / term.dof)
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


def retrieve_sdp(
    model: IdentifiedModel,
    *,
    prior: Prior | Robot | None = None,
    bounds: Bounds | None = None,
    total_mass: tuple[float, float] | None = None,
    options: SDPOptions | None = None,
    constraints: Sequence[Callable[..., Any]] = (),
) -> ConsistentResult:
    """Consistent link parameters from identified coefficients (two-step, convex).

    The coefficients' full covariance weighs the data term (``model.fit.covariance``);
    exact coefficients are met exactly. Parameters as in :func:`solve_consistent`; the
    result's robot carries ``model.robot``'s kinematics and friction.

    Examples
    --------
    >>> import dynid
    >>> from dynid.feasibility.sdp import retrieve_sdp
    >>> robot = dynid.panda()
    >>> data = dynid.acquire_static(dynid.SimulatedController(robot), 100, np.random.default_rng(0))
    >>> res = retrieve_sdp(dynid.identify_static(robot, data), prior=robot)  # doctest: +SKIP
    """
    res = solve_consistent(
        model.robot,
        coefficient_term(model),
        prior=prior,
        bounds=bounds,
        total_mass=total_mass,
        options=options,
        constraints=constraints,
        kind="coefficients",
    )
    return res if model.drive is None else with_drive(res, model.drive)


def with_drive(res: ConsistentResult, drive: Drive) -> ConsistentResult:
    """The result with its drive, whose rotor inertias are the identified ones (known from
    then on: a simulator or a validation takes them as given)."""
    ia = res.rotor_inertia if drive.rotor_inertia is None else drive.rotor_inertia
    if ia is None:
        return dataclasses.replace(res, drive=drive)
    return dataclasses.replace(res, drive=dataclasses.replace(drive, rotor_inertia=ia))
