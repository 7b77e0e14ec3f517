"""The convex problem in cvxpy (:class:`ConvexProblem`), built once per data term and
re-solved at each prior weight, with the solver fallback (Clarabel, Clarabel with
regularisation, SCS; each lets a Ctrl-C end its solve, :mod:`.solvers`) and the solution's
read-out (margins enforced, exact fits polished)."""

from __future__ import annotations

import math
import warnings
from collections.abc import Callable, Sequence
from typing import Any

import numpy as np
from numpy.typing import NDArray

from ...exceptions import InfeasibleError, SolverError
from ...model.robot import MAX_LINK_MASS
from ...progress import report
from ..bounds import Bounds
from ..lmi import (
    pseudo_inertia_margin,
    repair_pseudo_inertia,
)
from ..prior import Prior, prior_scales
from .data_term import DataTerm
from .options import SDPOptions
from .solvers import SCS_SIGINT, clarabel, scs

__all__ = ["SCS_SIGINT", "ConvexProblem", "Values", "data_scale", "fallback_note"]


#: The weighted fit's duality gap, in the data term's own unit: ``Delta chi^2``, the increase
#: of the residual sum of squares over the noise variance (:func:`gap_tolerance`).
GAP_CHI2 = 1e-2

#: Boxes and the band are shrunk by this fraction inside the solver, so that its tolerance
#: (about 1e-8) cannot put the solution outside them (:func:`_inset`).
_SHRINK = 1e-6


def _inset(lo: float, hi: float, ref: float) -> float:
    """How far the solver's bounds lie inside ``[lo, hi]``: :data:`_SHRINK` of the width, or
    of the quantity's own magnitude (``|lo|`` or ``ref``, the prior's) where that is
    smaller, so that a loose bound (a band ``0..7e6`` kg) does not move its end by the
    width's share (7 kg)."""
    return _SHRINK * min(float(hi) - float(lo), max(abs(float(lo)), float(ref)))


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


# ------------------------------------------------------------------------- the problem
def mass_bounds(
    prior: Prior, bounds: Bounds, factor: float | None
) -> tuple[NDArray[np.float64], NDArray[np.float64], list[str]]:
    """Link mass bounds [kg] (n,) each: ``bounds``' narrowed to ``prior.mass / factor ..
    prior.mass * factor``, except for a generic prior and the links a prior guessed
    (:attr:`~dynid.feasibility.prior.Prior.guessed`: the generic cylinder in place of a
    massless or placeholder link), which keep ``bounds``' alone; and a note per link
    whose ranges had to be reconciled."""
    lo = np.array(bounds.mass_min, dtype=float)
    hi = np.array(bounds.mass_max, dtype=float)
    notes: list[str] = []
    if factor is None or prior.generic:  # a guess does not bound the masses
        return lo, hi, notes
    m0 = prior.mass
    plo, phi_ = m0 / factor, m0 * factor
    free = np.zeros(len(m0), dtype=bool)
    free[np.asarray(prior.guessed, dtype=int) - 1] = True  # a guess bounds no mass
    guessed = np.asarray(bounds.mass_guessed or (False,) * len(m0), dtype=bool)
    above = guessed & (m0 > hi) & ~free  # a description's mass against a guess from a length
    for i in np.flatnonzero(above):
        notes.append(
            f"link {i + 1}: the prior's mass {m0[i]:.4g} kg lies above the generic bound "
            f"{hi[i]:.4g} kg (from the link's length); the prior's range up to "
            f"{min(phi_[i], MAX_LINK_MASS):.4g} kg is used"
        )
    hi = np.where(above, np.minimum(phi_, MAX_LINK_MASS), hi)
    nlo, nhi = np.maximum(lo, plo), np.minimum(hi, phi_)
    nlo, nhi = np.where(free, lo, nlo), np.where(free, hi, nhi)
    empty = nlo > nhi
    for i in np.flatnonzero(empty):
        notes.append(
            f"link {i + 1}: the prior's mass range {plo[i]:.3g}..{phi_[i]:.3g} kg lies outside "
            f"the bounds {lo[i]:g}..{hi[i]:g} kg; the bounds alone are used"
        )
    return np.where(empty, lo, nlo), np.where(empty, hi, nhi), notes


def check_band(lo: NDArray[np.float64], hi: NDArray[np.float64], band: Any) -> None:
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


class ConvexProblem:
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
        # the variables X_i = S0_i^-1 J_i S0_i^-T / kappa, kappa the data's scale over the
        # prior's (a power of ten): X_i ~ 1 at the solution, whatever the prior's magnitude
        kappa = self.kappa = data_scale(term, prior)
        self.S0 = math.sqrt(kappa) * np.linalg.cholesky(J0)
        self.X = [cp.Variable((4, 4), symmetric=True, name=f"X{i + 1}") for i in range(n)]
        self.J = [self.S0[i] @ self.X[i] @ self.S0[i].T for i in range(n)]
        B = np.stack([_T @ np.kron(self.S0[i], self.S0[i]) for i in range(n)])  # (n, 10, 16)
        self.B = B
        phis = [B[i] @ cp.vec(self.X[i], order="C") for i in range(n)]
        phi = cp.hstack(phis)
        self.phi_links = phis
        self.w = cp.Parameter(nonneg=True, value=1.0, name="w")
        self.v = cp.Parameter(nonneg=True, value=1.0, name="v")
        eps = self.margin = options.margin
        self.scale = 1.0 if equality or closest else float(max(term.dof, 1))
        self.equality = equality
        self.weighted = not (equality or closest)
        cons: list[Any] = []
        for i in range(n):
            C = self.S0[i].T @ self.S0[i]
            Ci = np.linalg.inv(C)
            Ci = 0.5 * (Ci + Ci.T)
            cons.append(self.X[i] - eps * cp.trace(C @ self.X[i]) * Ci >> 0)
            m, h = phis[i][0], phis[i][1:4]
            dm = _inset(mass_lo[i], mass_hi[i], prior.mass[i])
            dc = _SHRINK * (bounds.com_max[i] - bounds.com_min[i])
            cons += [m >= mass_lo[i] + dm, m <= mass_hi[i] - dm]
            cons += [h >= m * (bounds.com_min[i] + dc), h <= m * (bounds.com_max[i] - dc)]
        if band is not None:
            M = sum(p[0] for p in phis)
            db = _inset(band[0], band[1], float(prior.mass.sum()))
            cons += [M >= band[0] + db, M <= band[1] - db]
        # the divergence times its coefficient c (the weight; 1 for an exact fit, 1e-6 for
        # the closest one): c enters the log-det's cones, not only their cost
        c = 1e-6 if closest else (1.0 if equality else self.w)
        if options.objective == "logdet":  # (constants dropped: -4 log kappa, 4 c log c, 4 c)
            wdiv = 0.0
            for X in self.X:
                term_i, cons_i = weighted_neg_log_det(X, c)
                wdiv = wdiv + term_i + c * kappa * cp.trace(X)
                cons += cons_i
        else:
            wdiv = c * sum(cp.sum_squares(kappa * X - np.eye(4)) for X in self.X)
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
            if friction_nonneg:  # the terms' non-negative coefficients, their dissipation
                pos = np.flatnonzero(term.nonnegative())  # the terms say which
                sel = np.zeros((pos.size, k))
                sel[np.arange(pos.size), pos] = 1.0
                cons.append(sel @ self.f >= 0)
                if term.dissipation is not None:  # f(v) >= 0 within the velocity limits
                    G = term.dissipation / np.maximum(
                        np.max(np.abs(term.dissipation), axis=1, keepdims=True), 1e-300
                    )
                    cons.append(G @ self.f >= 0)
        for make in constraints:
            cons += list(make(phis, self.J))
        if equality:
            s = np.maximum(np.abs(term.x_hat), 1e-6 * max(float(np.abs(term.x_hat).max()), 1e-12))
            cons.append(cp.multiply(1.0 / s, x - term.x_hat) == 0)
            obj = wdiv
        elif closest:
            s = np.maximum(np.abs(term.x_hat), 1e-3 * max(float(np.abs(term.x_hat).max()), 1e-12))
            obj = wdiv + 0.5 * cp.sum_squares(cp.multiply(1.0 / s, x - term.x_hat))
        else:
            # divided by dof (the data term's size at a good fit): same minimiser, better scaled
            # (and, above weight 1, both terms divided by the weight: same minimiser again,
            # and a weight of 1e200 does not make the solver's numbers overflow)
            ks = 1.0 / math.sqrt(self.scale)
            obj = wdiv + self.v * 0.5 * cp.sum_squares(
                (ks * term.A) @ x - (ks * term.A) @ term.x_hat
            )
        self.problem = cp.Problem(cp.Minimize(obj), cons)
        self.term = term
        self.solves = self.retried = self.by_scs = 0  # (:meth:`solve`)

    def solve(self, w: float) -> str:
        """Solve at weight ``w``; the status (retries as in the module docstring).

        The first ``optimal`` attempt is kept; otherwise an ``optimal_inaccurate`` one;
        ``infeasible`` only when every attempt says so (an interior-point method can
        misreport a badly scaled feasible problem). SCS runs only when neither Clarabel
        attempt gave a solution: after an ``optimal_inaccurate`` one it too ended
        inaccurate, at 12-20 s a solve, eight times in one weight search, and the first
        inaccurate answer was kept all the same. Counted in :attr:`solves`, :attr:`retried`
        (the first attempt gave no optimal answer) and :attr:`by_scs` (:func:`fallback_note`).
        """
        self.solves += 1
        seen: list[str] = []
        try:
            return self._attempts(w, seen)
        finally:
            self.retried += len(seen) > 1
            self.by_scs += any(x.startswith("SCS") for x in seen)

    def _attempts(self, w: float, seen: list[str]) -> str:
        """The attempts of :meth:`solve`, each named with its outcome in ``seen``."""
        import cvxpy as cp

        report(f"solving at prior weight {float(w):.3g}")  # (seconds each, dozens a search)
        self.w.value, self.v.value = objective_weights(float(w) / self.scale)
        gap = {"tol_gap_abs": gap_tolerance(self.v.value, self.scale, self.weighted)}
        attempts: list[tuple[str, dict[str, Any]]] = [
            ("CLARABEL", gap),
            ("CLARABEL", {**gap, "max_iter": 500, "static_regularization_constant": 1e-7}),
            ("SCS", {"eps": 1e-7, "max_iters": 20_000}),
        ]
        inaccurate = None
        for solver, kw in attempts:
            if solver == "SCS" and inaccurate is not None:
                break  # Clarabel's inaccurate answer stands
            try:
                with warnings.catch_warnings():  # the status says it; retried below
                    warnings.simplefilter("ignore", UserWarning)
                    self.problem.solve(solver=scs() if solver == "SCS" else clarabel(), **kw)
            except (cp.error.SolverError, ArithmeticError, ValueError) as exc:
                seen.append(f"{solver}: {exc}")
                continue
            except BaseException as exc:  # a panic of the compiled solver is a failed solve
                if not is_solver_panic(exc):
                    raise  # Ctrl-C, termination, exit
                seen.append(f"{solver}: panicked ({' '.join(str(exc).split())})")
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

    def values(self) -> Values:
        """``phi`` (n, 10), the friction (k,) and the rotor inertias (n,) at the solution
        (margins enforced; None for what the problem does not hold)."""
        Xs, f, ia = self._snapshot
        phi = np.stack([self.B[i] @ X.reshape(-1) for i, X in enumerate(Xs)])
        return _with_margin(phi, self.margin), f, ia


#: Below this, the data term's coefficient is held (:func:`objective_weights`): its share
#: of the objective is already far below the solver's tolerance (about 1e-8).
_DATA_FLOOR = 1e-16


def objective_weights(w: float) -> tuple[float, float]:
    """The coefficients ``(a, b)`` of the objective ``a divergence + b data`` at the
    (dof-scaled) prior weight ``w``: ``(w, 1)`` up to 1, ``(1, 1 / w)`` above (the same
    minimiser, with numbers the solver can hold for any finite weight; ``b`` is held at
    1e-16 above ``w = 1e16``, where the data's share is below the solver's tolerance)."""
    if not w > 1.0:
        return w, 1.0
    return 1.0, max(1.0 / w, _DATA_FLOOR)


def fallback_note(problems: Sequence[ConvexProblem]) -> str | None:
    """What the user should know when Clarabel's first attempt failed at some solves of
    ``problems`` (None when it never did): how many, and how many SCS answered."""
    n = sum(p.solves for p in problems)
    retried = sum(p.retried for p in problems)
    by_scs = sum(p.by_scs for p in problems)
    if not retried:
        return None
    tail = f", {by_scs} of them by SCS (slower, less accurate)" if by_scs else ""
    return f"the convex solver (Clarabel) needed a second attempt at {retried} of {n} solves{tail}"


def gap_tolerance(v: float, scale: float, weighted: bool) -> float:
    """Clarabel's absolute duality gap: :data:`GAP_CHI2` in units of the objective, whose data
    term is ``v Delta chi^2 / (2 scale)``, and never below Clarabel's own 1e-8 (only that
    for the exact and the closest fits, whose objective is no ``Delta chi^2``).

    A thousandth of one noise variance over the whole log, far below what the noise can tell
    apart (``chi^2`` itself scatters by ``sqrt(2 dof)``). At 1e-8 a fit on a short log
    stalled a little above it (Clarabel's "AlmostSolved", every residual met but the gap,
    about 5e-7 of the objective) in about one solve in ten of a held-out weight search,
    each then solved a second time.
    """
    if not weighted:
        return 1e-8
    return max(1e-8, float(v) * GAP_CHI2 / (2.0 * float(scale)))


def is_solver_panic(exc: BaseException) -> bool:
    """Whether ``exc`` is a compiled solver's panic (Clarabel's ``pyo3_runtime.PanicException``,
    a :class:`BaseException` that is no :class:`Exception`): a failed solve, not a stop."""
    return type(exc).__name__ == "PanicException"


#: (16, 10): the lower triangle of a 4x4 matrix (row-major) from its 10 entries.
_LOWER = np.zeros((16, 10))
_LOWER[np.ravel_multi_index(np.tril_indices(4), (4, 4)), np.arange(10)] = 1.0


def weighted_neg_log_det(X: Any, c: Any) -> tuple[Any, list[Any]]:
    """``c (-log det X)`` up to the constant ``4 c log c``, and its constraints: ``X``'s
    factor ``[[X, Z], [Z^T, diag Z]] >= 0`` (``Z`` lower triangular) and the exponential
    cones ``(t_k, c, Z_kk)``, i.e. ``t_k <= c log(Z_kk / c)``; the term is ``-sum t``.

    ``c`` sits in the cones rather than in the cost: their dual variables are then about 1
    whatever the weight. With cvxpy's ``log_det`` (cones ``(t, 1, z)``, cost ``-c t``) they
    were ``c``, down to 1e-8 at the small weights of a held-out search, and Clarabel's
    line search stalled (InsufficientProgress) or ended short of its tolerance.
    """
    import cvxpy as cp

    z = cp.Variable(10)
    Z = cp.reshape(_LOWER @ z, (4, 4), order="C")
    d = cp.diag(Z)
    K = cp.bmat([[X, Z], [Z.T, cp.diag(d)]])
    t = cp.Variable(4)
    cons = [0.5 * (K + K.T) >> 0, cp.constraints.ExpCone(t, c * np.ones(4), d)]
    return -cp.sum(t), cons


def data_scale(term: DataTerm, prior: Prior) -> float:
    """The data's scale over the prior's, a power of ten in ``[1e-8, 1e8]``: the coefficients'
    norm over that of the prior's coefficients (1 when either is zero). A prior 1e4 times
    too heavy (other units, a wild guess) would otherwise leave the solver's variables at
    1e-4 and its tolerances coarser than the bounds."""
    n10 = 10 * prior.n
    x0 = term.P[:, :n10] @ np.asarray(prior.phi, dtype=np.float64).reshape(-1)
    a, b = float(np.linalg.norm(term.x_hat[: term.r])), float(np.linalg.norm(x0))
    if not (a > 0 and b > 0 and math.isfinite(a / b)):
        return 1.0
    return float(10.0 ** min(max(round(math.log10(a / b)), -8), 8))


Values = tuple[NDArray[np.float64], NDArray[np.float64] | None, NDArray[np.float64] | None]


def solution_x(term: DataTerm, phi: NDArray[np.float64], f: Any, ia: Any) -> NDArray[np.float64]:
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


def polish(
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
