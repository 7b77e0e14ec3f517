"""The penalised objective of the feasible-parameter retrieval (Gaz et al. 2019, Sec. V).

Decision variables: ``p = (m_i, c_i, I_i)`` per link
(:data:`~dynid.model.inertia.DECISION_FIELDS`, inertia about the CoM), inside the box of
:class:`~dynid.feasibility.bounds.Bounds`. The optimisers work on normalised
variables ``z`` in ``[0, 1]^{10 n}``, ``p = lo + z (hi - lo)``.

**Data term.** The standard parameters follow from ``p`` by the parallel-axis theorem,
``phi(p) = [m, m c, I + m (c^T c E - c c^T)]`` (:func:`~dynid.model.inertia.
phi_from_inertial`), and every data term is linear in ``phi``: a matrix ``A`` and a
vector ``b`` precomputed once,

.. math:: f_0(p) = \\| A \\phi(p) - b \\|^2 + f_{off}

from the identified coefficients, each divided by its size or standard deviation
(two-step, :func:`coefficient_problem`, eq. 29), or from the static data compressed by a QR
factorisation (single-step, :func:`static_problem`).

**Constraints** ``h_j(p) >= delta_j``, each divided by a scale ``s_j``: per link the
triangle inequality and positive definiteness of the inertia [kg m^2], the total-mass band
[kg], and user constraints. The violation distance (eq. 32) is
``g_j = max(0, delta_j - h_j) / s_j``.

**Stage objective** (eq. 29, stage ``k`` with penalty weight ``xi_k``):

.. math:: F_k(p) = f_0(p) + \\xi_k \\sum_j g_j(p)^2

(:meth:`PenaltyProblem.stage_cost`). Departure from the paper, on purpose: Gaz et al. add
the distances ``g_j`` themselves; their squares have the same minimisers where the
constraints can be met and make ``F_k`` a differentiable sum of squares, which the
Levenberg-Marquardt refinement minimises too. The scalings, the target margins and the
reasons are in ``docs/feasible-retrieval-penalty.md``.
"""

from __future__ import annotations

import dataclasses
from collections.abc import Sequence
from dataclasses import dataclass
from typing import Any

import numpy as np
from numpy.typing import ArrayLike, NDArray

from ... import _checks
from ...exceptions import DataError, OptionError, ShapeError
from ...model.robot import Robot
from ...regressors.base import BaseParameters, base_parameters
from ...regressors.static import static_vector
from ..bounds import Bounds, default_bounds
from ..constraints import UserConstraint, user_constraints
from ..prior import prior_scales
from .static_blocks import StaticBlocks, r_factor

__all__ = [
    "DEFAULT_MARGIN",
    "DEFAULT_SCALE_FLOOR",
    "PenaltyProblem",
    "coefficient_problem",
    "coefficient_scales",
    "static_problem",
    "phi_from_params",
    "with_prior",
]

#: Relative target margin of the constraints and relative shrink of the box.
DEFAULT_MARGIN = 1e-6
#: Floor of the coefficient scales, relative to the largest kept coefficient of a unit.
DEFAULT_SCALE_FLOOR = 1e-3

_IU = np.array([0, 1, 2, 1, 3, 4, 2, 4, 5])  # (6,) -> 3x3 symmetric, row-major
_HALF_TRACE = np.array([0.5, 0.0, 0.0, 0.5, 0.0, 0.5])  # d(tr I / 2) / d(xx, xy, ..., zz)


def phi_from_params(p: NDArray[np.float64]) -> NDArray[np.float64]:
    """Standard parameters (n, 10) from decision parameters (n, 10) (validated input)."""
    m, c = p[:, 0], p[:, 1:4]
    mc = m[:, None] * c
    phi = np.empty_like(p)
    phi[:, 0] = m
    phi[:, 1:4] = mc
    phi[:, 4:] = p[:, 4:]
    phi[:, 4] += mc[:, 1] * c[:, 1] + mc[:, 2] * c[:, 2]
    phi[:, 5] -= mc[:, 0] * c[:, 1]
    phi[:, 6] -= mc[:, 0] * c[:, 2]
    phi[:, 7] += mc[:, 0] * c[:, 0] + mc[:, 2] * c[:, 2]
    phi[:, 8] -= mc[:, 1] * c[:, 2]
    phi[:, 9] += mc[:, 0] * c[:, 0] + mc[:, 1] * c[:, 1]
    return phi


def _phi_jacobian(p: NDArray[np.float64]) -> NDArray[np.float64]:
    """d phi_i / d p_i per link, shape (n, 10, 10)."""
    n = p.shape[0]
    m, cx, cy, cz = p[:, 0], p[:, 1], p[:, 2], p[:, 3]
    J = np.zeros((n, 10, 10))
    J[:, 0, 0] = 1.0
    for a in range(3):
        J[:, 1 + a, 0] = p[:, 1 + a]
        J[:, 1 + a, 1 + a] = m
    J[:, 4, 0] = cy * cy + cz * cz
    J[:, 5, 0] = -cx * cy
    J[:, 6, 0] = -cx * cz
    J[:, 7, 0] = cx * cx + cz * cz
    J[:, 8, 0] = -cy * cz
    J[:, 9, 0] = cx * cx + cy * cy
    J[:, 4, 2], J[:, 4, 3] = 2 * m * cy, 2 * m * cz
    J[:, 5, 1], J[:, 5, 2] = -m * cy, -m * cx
    J[:, 6, 1], J[:, 6, 3] = -m * cz, -m * cx
    J[:, 7, 1], J[:, 7, 3] = 2 * m * cx, 2 * m * cz
    J[:, 8, 2], J[:, 8, 3] = -m * cz, -m * cy
    J[:, 9, 1], J[:, 9, 2] = 2 * m * cx, 2 * m * cy
    idx = np.arange(4, 10)
    J[:, idx, idx] = 1.0
    return J


@dataclass(frozen=True, slots=True, eq=False)
class PenaltyProblem:
    """The precomputed data term, box and constraints of one retrieval.

    Attributes
    ----------
    n : int
        Number of links.
    A : ndarray, shape (m, 10 n)
        Scaled linear map of the standard parameters (``robot.param_labels`` order).
    b : ndarray, shape (m,)
    offset : float
        Constant part of the data term (0 for the two-step objective).
    lower, upper : ndarray, shape (10 n,)
        The (shrunk) box of the decision parameters, decision layout.
    inertia_scale : ndarray, shape (n,)
        ``s_I`` per link [kg m^2].
    total_mass : (float, float) or None
        Total-mass band [kg].
    extra : tuple of UserConstraint
    margin : float
        Relative target margin ``delta / s``.
    report_A, report_b, report_offset, report_norm
        Unscaled data term for the relative residual:
        ``sqrt(||report_A phi - report_b||^2 + report_offset) / report_norm``.
    kind : str
        ``"coefficients"`` or ``"static"``.
    """

    n: int
    A: NDArray[np.float64]
    b: NDArray[np.float64]
    offset: float
    lower: NDArray[np.float64]
    upper: NDArray[np.float64]
    inertia_scale: NDArray[np.float64]
    total_mass: tuple[float, float] | None
    extra: tuple[UserConstraint, ...]
    margin: float
    report_A: NDArray[np.float64]
    report_b: NDArray[np.float64]
    report_offset: float
    report_norm: float
    kind: str

    # ------------------------------------------------------------------ variables
    @property
    def dim(self) -> int:
        """Number of decision variables, ``10 n``."""
        return 10 * self.n

    @property
    def width(self) -> NDArray[np.float64]:
        """``upper - lower`` (10 n,)."""
        return self.upper - self.lower

    def p_from_z(self, z: NDArray[np.float64]) -> NDArray[np.float64]:
        """Decision parameters (n, 10) from normalised variables (10 n,)."""
        return (self.lower + np.asarray(z) * (self.upper - self.lower)).reshape(self.n, 10)

    # ------------------------------------------------------------------ data term
    def residual(self, z: NDArray[np.float64]) -> NDArray[np.float64]:
        """Scaled data residual ``A phi(p) - b`` (m,)."""
        return self._residual_p(self.p_from_z(z))

    def _residual_p(self, p: NDArray[np.float64]) -> NDArray[np.float64]:
        return self.A @ phi_from_params(p).reshape(-1) - self.b

    def residual_jacobian(self, z: NDArray[np.float64]) -> NDArray[np.float64]:
        """d residual / d z, shape (m, 10 n)."""
        p = self.p_from_z(z)
        An = self.A.reshape(self.A.shape[0], self.n, 10)
        J = np.einsum("rik,ikl->ril", An, _phi_jacobian(p)).reshape(self.A.shape[0], -1)
        return J * self.width

    def data_cost(self, z: NDArray[np.float64]) -> float:
        """``f_0 = ||A phi - b||^2 + offset``."""
        r = self.residual(z)
        return float(r @ r) + self.offset

    def relative_residual(self, p: ArrayLike) -> float:
        """Unscaled relative residual of the data term at decision parameters (n, 10).

        Two-step: ``||pi(p) - pi_hat|| / ||pi_hat||`` over the kept coefficients;
        single-step: ``||Y_s phi(p) - s|| / ||s||`` over the static data.
        """
        phi = phi_from_params(np.asarray(p, dtype=np.float64).reshape(self.n, 10)).reshape(-1)
        e = self.report_A @ phi - self.report_b
        ss = max(float(e @ e) + self.report_offset, 0.0)
        return float(np.sqrt(ss) / self.report_norm) if self.report_norm > 0 else float(np.sqrt(ss))

    # ------------------------------------------------------------------ constraints
    @property
    def n_constraints(self) -> int:
        """Number of penalised constraints: 2 per link, 2 for a mass band, the user's."""
        return 2 * self.n + (2 if self.total_mass is not None else 0) + len(self.extra)

    def constraint_names(self) -> tuple[str, ...]:
        """Names of the penalised constraints, in the order of :meth:`violations`."""
        names = [f"triangle_inequality[{i + 1}]" for i in range(self.n)]
        names += [f"inertia_positive_definite[{i + 1}]" for i in range(self.n)]
        if self.total_mass is not None:
            names += ["total_mass_min", "total_mass_max"]
        names += [uc.name for uc in self.extra]
        return tuple(names)

    def _eig(self, p: NDArray[np.float64], vectors: bool):
        I = p[:, 4:][:, _IU].reshape(self.n, 3, 3)
        return np.linalg.eigh(I) if vectors else np.linalg.eigvalsh(I)

    def slacks(self, z: NDArray[np.float64]) -> NDArray[np.float64]:
        """Scaled signed violations ``(delta_j - h_j) / s_j`` (positive when violated;
        user constraints: their violation ``v >= 0``), :meth:`constraint_names` order."""
        return self._slacks_p(self.p_from_z(z))

    def _slacks_p(self, p: NDArray[np.float64]) -> NDArray[np.float64]:
        n = self.n
        lam = self._eig(p, False)
        sI = self.inertia_scale
        d = self.margin
        out = np.empty(self.n_constraints)
        out[:n] = d - 0.5 * (lam[:, 0] + lam[:, 1] - lam[:, 2]) / sI
        out[n : 2 * n] = d - lam[:, 0] / sI
        k = 2 * n
        if self.total_mass is not None:
            lo, hi = self.total_mass
            M = float(p[:, 0].sum())
            out[k], out[k + 1] = d - (M - lo) / hi, d - (hi - M) / hi
            k += 2
        for uc in self.extra:
            out[k] = max(0.0, float(uc.violation(p.copy())))
            k += 1
        return out

    def violations(self, z: NDArray[np.float64]) -> NDArray[np.float64]:
        """Scaled violation distances ``g_j = max(0, slack_j) >= 0`` (eq. 32)."""
        return np.maximum(self.slacks(z), 0.0)

    def violation_jacobian(
        self,
        z: NDArray[np.float64],
        band: float = 0.0,
        *,
        slacks: NDArray[np.float64] | None = None,
    ) -> NDArray[np.float64]:
        """Jacobian of the violations w.r.t. ``z``, shape (n_constraints, 10 n).

        Rows of constraints with ``slack_j > -band`` (violated, or within ``band`` of
        their target) hold ``d slack_j / d z``; the others are zero. ``band > 0`` gives the
        refinement a sticky active set: a constraint at its target is held there
        instead of being released and violated again by the next step. Eigenvalue
        derivatives ``d lambda = v^T dI v`` (simple eigenvalues); user constraints by
        forward differences (only when violated). ``slacks``: :meth:`slacks` at ``z`` when
        the caller has them already.
        """
        z = np.asarray(z, dtype=np.float64)
        sl = self.slacks(z) if slacks is None else slacks
        n, w = self.n, self.width
        p = self.p_from_z(z)
        lam, V = self._eig(p, True)
        K = np.zeros((self.n_constraints, 10 * n))
        sI = self.inertia_scale
        act = sl > -band

        def d_lam(v: NDArray[np.float64]) -> NDArray[np.float64]:
            # derivative of v^T I v w.r.t. (xx, xy, xz, yy, yz, zz), (n, 6)
            x, y, zz = v[:, 0], v[:, 1], v[:, 2]
            return np.stack([x * x, 2 * x * y, 2 * x * zz, y * y, 2 * y * zz, zz * zz], axis=1)

        dT = _HALF_TRACE - d_lam(V[:, :, 2])  # d(tr/2 - lambda_max)
        dP = d_lam(V[:, :, 0])  # d lambda_min
        Kl = K[: 2 * n].reshape(2 * n, n, 10)  # a view: row j, link i, field
        links = np.arange(n)
        on = act[:n]
        Kl[links[on], links[on], 4:] = -dT[on] / sI[on, None]
        on = act[n : 2 * n]
        Kl[n + links[on], links[on], 4:] = -dP[on] / sI[on, None]
        k = 2 * n
        if self.total_mass is not None:
            hi = self.total_mass[1]
            mcols = np.arange(n) * 10
            if act[k]:
                K[k, mcols] = -1.0 / hi
            if act[k + 1]:
                K[k + 1, mcols] = 1.0 / hi
            k += 2
        K *= w  # analytic rows: d/dp -> d/dz
        for uc in self.extra:
            if sl[k] > 0:  # forward differences in z
                h = 1e-7
                for j in range(10 * n):
                    zj = z.copy()
                    step = h if zj[j] + h <= 1.0 else -h
                    zj[j] += step
                    gj = max(0.0, float(uc.violation(self.p_from_z(zj))))
                    K[k, j] = (gj - sl[k]) / step
            k += 1
        return K

    # ------------------------------------------------------------------ objectives
    def stage_cost(self, z: NDArray[np.float64], xi: float = 0.0) -> float:
        """Stage objective ``F = f_0 + xi * sum_j g_j^2`` (eq. 29; squared eq. 32 distances)."""
        p = self.p_from_z(z)
        r = self._residual_p(p)
        f = float(r @ r) + self.offset
        if xi > 0.0:
            g = np.maximum(self._slacks_p(p), 0.0)
            f += xi * float(g @ g)
        return f

    def lsq_residual(self, z: NDArray[np.float64], xi: float) -> NDArray[np.float64]:
        """Residual ``[A phi - b; sqrt(xi) g]``: ``||.||^2 + offset`` is :meth:`stage_cost`."""
        return self.lsq_residual_slacks(z, xi)[0]

    def lsq_residual_slacks(
        self, z: NDArray[np.float64], xi: float
    ) -> tuple[NDArray[np.float64], NDArray[np.float64] | None]:
        """:meth:`lsq_residual` and the :meth:`slacks` it was made from (``None`` when
        ``xi <= 0``: no penalty term), for :meth:`lsq_jacobian` at the same ``z``."""
        p = self.p_from_z(z)
        r = self._residual_p(p)
        if xi <= 0.0:
            return r, None
        sl = self._slacks_p(p)
        return np.concatenate([r, np.sqrt(xi) * np.maximum(sl, 0.0)]), sl

    def lsq_jacobian(
        self,
        z: NDArray[np.float64],
        xi: float,
        band: float = 0.0,
        *,
        slacks: NDArray[np.float64] | None = None,
    ) -> NDArray[np.float64]:
        """Jacobian of :meth:`lsq_residual` w.r.t. ``z`` (``band``, ``slacks``: see
        :meth:`violation_jacobian`)."""
        J = self.residual_jacobian(z)
        if xi <= 0.0:
            return J
        return np.vstack([J, np.sqrt(xi) * self.violation_jacobian(z, band, slacks=slacks)])


# ------------------------------------------------------------------------ builders
def _box(bounds: Bounds, margin: float) -> tuple[NDArray[np.float64], NDArray[np.float64]]:
    lo, hi = bounds.lower.reshape(-1), bounds.upper.reshape(-1)
    shrink = margin * (hi - lo)
    return lo + shrink, hi - shrink


def _unit_class(base: BaseParameters) -> NDArray[np.intp]:
    """0 for coefficients led by a mass (kg), 1 by a first moment (kg m), 2 by an inertia."""
    k = np.asarray(base.independent) % 10
    return np.where(k == 0, 0, np.where(k < 4, 1, 2))


def coefficient_scales(
    base: BaseParameters,
    beta: NDArray[np.float64],
    std: NDArray[np.float64] | None,
    kept: NDArray[np.bool_],
    scale_floor: float = DEFAULT_SCALE_FLOOR,
) -> NDArray[np.float64]:
    """Scales ``s_k = max(|pi_hat_k|, sigma_k, floor_u(k))`` of the coefficients (r,).

    ``floor_u = scale_floor * max |pi_hat_j|`` over kept ``j`` of the same unit class
    (kg, kg m, kg m^2), or over all kept coefficients when the class has none nonzero.
    """
    u = _unit_class(base)
    a = np.abs(beta)
    top = float(np.max(a[kept], initial=0.0)) or 1.0
    floors = np.array([float(np.max(a[kept & (u == c)], initial=0.0)) or top for c in range(3)])
    s = np.maximum(a, scale_floor * floors[u])
    if std is not None:
        s = np.maximum(s, np.abs(std))
    return s


def _common(
    robot: Robot,
    bounds: Bounds | None,
    total_mass: tuple[float, float] | None,
    extra: Sequence[Any],
    margin: float,
) -> tuple[Bounds, tuple[float, float] | None, tuple[UserConstraint, ...]]:
    if not 0.0 <= margin < 0.5:
        raise OptionError(f"margin must be in [0, 0.5); got {margin}")
    b = default_bounds(robot) if bounds is None else bounds
    if b.n != robot.n:
        raise ShapeError(f"bounds are for {b.n} links; robot {robot.name!r} has {robot.n}")
    if total_mass is not None:  # checked as the bounds' own band is
        b = b.with_total_mass(total_mass)
    return b, b.total_mass, user_constraints(extra)


def with_prior(problem: PenaltyProblem, phi0: ArrayLike, weight: float) -> PenaltyProblem:
    """``problem`` with a pull towards prior standard parameters ``phi0`` (n, 10) added to
    its data term: ``weight * sum_j ((phi_j - phi0_j) / s_j)^2``, ``s`` the prior's scales
    (:func:`~dynid.feasibility.prior.prior_scales`). It is linear in ``phi``, so it enters
    as extra rows of ``A`` and ``b``; the reported relative residual is unchanged."""
    if not (np.isfinite(weight) and weight >= 0):
        raise DataError(f"prior weight must be finite and >= 0; got {weight}")
    p0 = _checks.as_exact("phi0", phi0, (problem.n, 10)).reshape(-1)
    if weight == 0:
        return problem
    s = prior_scales(p0)
    k = np.sqrt(weight)
    A = np.vstack([problem.A, np.diag(k / s)])
    b = np.concatenate([problem.b, k * p0 / s])
    return dataclasses.replace(problem, A=_checks.frozen(A), b=_checks.frozen(b))


def coefficient_problem(
    robot: Robot,
    base: BaseParameters,
    beta: ArrayLike,
    *,
    std: ArrayLike | None = None,
    kept: ArrayLike | None = None,
    bounds: Bounds | None = None,
    total_mass: tuple[float, float] | None = None,
    extra: Sequence[Any] = (),
    margin: float = DEFAULT_MARGIN,
    scale_floor: float = DEFAULT_SCALE_FLOOR,
) -> PenaltyProblem:
    """The two-step objective: match identified coefficients (Gaz et al. 2019, eq. 29).

    .. math:: f_0(p) = \\sum_{k\\ kept} \\left(\\frac{(P \\phi(p))_k - \\hat\\pi_k}{s_k}\\right)^2

    Parameters
    ----------
    robot : Robot
        Kinematics (its inertial parameters are not used).
    base : BaseParameters
        The coefficients' definition, ``pi = P phi``.
    beta : array_like, shape (r,)
        Identified coefficients ``pi_hat`` [kg, kg m or kg m^2 each].
    std : array_like, shape (r,), optional
        Their standard deviations (same units).
    kept : array_like of bool, shape (r,), optional
        Coefficients to use (pruned ones are ignored); default all.
    bounds : Bounds, optional
        Default :func:`~dynid.feasibility.bounds.default_bounds`.
    total_mass : (float, float), optional
        Overrides ``bounds.total_mass`` [kg].
    extra : sequence
        User constraints (:func:`~dynid.feasibility.constraints.user_constraints`).
    margin, scale_floor : float
        See the module docstring.

    Returns
    -------
    PenaltyProblem

    Raises
    ------
    ShapeError
        Sizes of ``beta``, ``std``, ``kept``, ``base`` and ``bounds`` disagree with the robot.
    DataError
        No kept coefficient.
    """
    if base.n_std != 10 * robot.n:
        raise ShapeError(
            f"base parameters are for {base.n_std} standard parameters; robot has {10 * robot.n}"
        )
    r = base.rank
    beta = _checks.as_exact("beta", beta, (r,))
    sd = None if std is None else np.abs(_checks.as_exact("std", std, (r,)))
    keep = np.ones(r, bool) if kept is None else np.asarray(kept, dtype=bool)
    if keep.shape != (r,):
        raise ShapeError(f"kept must have shape ({r},); got {keep.shape}")
    if not keep.any():
        raise DataError("no kept coefficient to match")
    b, band, ucs = _common(robot, bounds, total_mass, extra, margin)
    s = coefficient_scales(base, beta, sd, keep, scale_floor)
    P = base.projection[keep]
    lo, hi = _box(b, margin)
    return PenaltyProblem(
        n=robot.n,
        A=_checks.frozen(P / s[keep][:, None]),
        b=_checks.frozen(beta[keep] / s[keep]),
        offset=0.0,
        lower=_checks.frozen(lo),
        upper=_checks.frozen(hi),
        inertia_scale=_checks.frozen(b.inertia_scale()),
        total_mass=band,
        extra=ucs,
        margin=float(margin),
        report_A=_checks.frozen(P),
        report_b=_checks.frozen(beta[keep]),
        report_offset=0.0,
        report_norm=float(np.linalg.norm(beta[keep])),
        kind="coefficients",
    )


def static_problem(
    robot: Robot,
    q: ArrayLike,
    M: ArrayLike,
    g: ArrayLike,
    *,
    base: BaseParameters | None = None,
    bounds: Bounds | None = None,
    total_mass: tuple[float, float] | None = None,
    extra: Sequence[Any] = (),
    margin: float = DEFAULT_MARGIN,
) -> PenaltyProblem:
    """The single-step objective on static data (Gaz et al. 2019, supplementary material).

    .. math:: f_0(p) = \\frac{r}{\\|y_w\\|^2} \\| D (Y_s \\phi(p) - s) \\|^2

    with ``s = [tril M; g]`` stacked over the configurations and ``D`` the row weights
    (1 / RMS of each row type); see the module docstring for the QR compression.

    Parameters
    ----------
    robot : Robot
        Kinematics and gravity the data were recorded with.
    q : array_like, shape (N, n)
        Configurations [rad].
    M : array_like, shape (N, n, n)
        Inertia matrices [kg m^2].
    g : array_like, shape (N, n)
        Gravity torques [N m].
    base : BaseParameters, optional
        Default ``base_parameters(robot)``.
    bounds, total_mass, extra, margin
        As for :func:`coefficient_problem`.

    Returns
    -------
    PenaltyProblem

    Raises
    ------
    ShapeError
        Inconsistent shapes.
    DataError
        Fewer stacked rows than coefficients.
    """
    n = robot.n
    q = _checks.as_array("q", q)
    if q.ndim != 2 or q.shape[1] != n:
        raise ShapeError(f"q must have shape (N, {n}); got {q.shape}")
    N = q.shape[0]
    M = _checks.as_exact("M", M, (N, n, n))
    g = _checks.as_exact("g", g, (N, n))
    base = base_parameters(robot) if base is None else base
    r = base.rank
    y = static_vector(M, g)  # (N, rows)
    if y.size < r:
        raise DataError(f"{y.size} stacked rows < {r} coefficients; add configurations")
    blocks = StaticBlocks(robot, q, base)
    ss = np.zeros(y.shape[1])  # per row of s: the sum of squares of its regressor rows
    for _, Yb in blocks:
        ss += np.einsum("bkc,bkc->k", Yb, Yb)
    rms = np.sqrt(np.mean(y**2, axis=0))
    rms_reg = np.sqrt(ss / N)
    informative = rms_reg > 1e-12 * max(float(rms_reg.max(initial=0.0)), 1e-300)
    floor = 1e-6 * float(rms.max(initial=0.0)) or 1.0
    w = np.where(informative, 1.0 / np.maximum(rms, floor), 0.0)
    # R of [W, y] accumulated block by block (weighted, and unweighted for the report):
    # its first r columns are R of W, its last Q^T y and, below, the residual's norm
    Ra = Ru_a = None
    for sl, Yb in blocks:
        Ra = r_factor(Ra, (Yb * w[None, :, None]).reshape(-1, r), (y[sl] * w).reshape(-1))
        Ru_a = r_factor(Ru_a, Yb.reshape(-1, r), y[sl].reshape(-1))
    assert Ra is not None and Ru_a is not None
    yw = y * w[None, :]
    R, qy = Ra[:r, :r], Ra[:r, r]
    Ru, qyu = Ru_a[:r, :r], Ru_a[:r, r]
    ny2 = float(np.sum(yw * yw))
    k = np.sqrt(r / ny2) if ny2 > 0 else 1.0
    yu2 = float(np.sum(y * y))
    P = base.projection
    b, band, ucs = _common(robot, bounds, total_mass, extra, margin)
    lo, hi = _box(b, margin)
    return PenaltyProblem(
        n=n,
        A=_checks.frozen(k * (R @ P)),
        b=_checks.frozen(k * qy),
        offset=max(k * k * (ny2 - float(qy @ qy)), 0.0),
        lower=_checks.frozen(lo),
        upper=_checks.frozen(hi),
        inertia_scale=_checks.frozen(b.inertia_scale()),
        total_mass=band,
        extra=ucs,
        margin=float(margin),
        report_A=_checks.frozen(Ru @ P),
        report_b=_checks.frozen(qyu),
        report_offset=max(yu2 - float(qyu @ qyu), 0.0),
        report_norm=float(np.sqrt(yu2)),
        kind="static",
    )
