"""Base parameters: a minimal, identifiable set of linear combinations of ``phi``.

The columns of a regressor ``W`` (stacked over samples) are linearly dependent: some
standard parameters never act (``m1`` of a base-mounted revolute joint), others act only
in fixed combinations. QR with column pivoting of the column-scaled ``W`` splits ``phi``
into independent parameters ``phi_b`` (r of them, r = rank) and dependent ones ``phi_d``
with ``W_d = W_b K_d`` exactly, so

.. math:: W \\phi = W_b (\\phi_b + K_d \\phi_d) = W_b \\beta

(Gautier 1991; Gaz et al. 2019, Sec. IV-A, obtain the same space by Gauss-Jordan
elimination). Each base parameter ``beta_k`` is a standard parameter plus a combination
of dependent ones, printed as ``J3yy + J2zz + 0.099856*m3 + ...``. The coefficients of
``K_d`` are products of the kinematic constants; they are cleaned of round-off to 10
significant digits (``clean_digits``).

Columns are scaled to unit norm before the rank decision (parameters mix kg, kg m and
kg m^2); the rank threshold is ``rtol`` times the largest scaled column norm, returned.

Which standard parameters are independent is decided by the pivot order. After scaling
every column has norm 1, so pivoting on the largest norm (LAPACK's ``geqp3``) would choose
by rounding noise and by the samples, and the expressions would change from one data set
or machine to the next. Here the first column in parameter order that is independent of
the columns chosen before it is taken, as Gauss-Jordan elimination does: the base
parameters depend on the robot's structure only (see :func:`_pivoted_r`).
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
import scipy.linalg
from numpy.typing import ArrayLike, NDArray

from .. import _checks
from ..exceptions import OptionError, ShapeError
from ..model.robot import Robot
from .static import static_regressor
from .torque import _torque_regressor

__all__ = ["BaseParameters", "base_parameters", "base_parameters_from_regressor"]


@dataclass(frozen=True, slots=True, eq=False)
class BaseParameters:
    """The base-parameter map ``beta = phi_b + K_d phi_d``.

    Attributes
    ----------
    std_labels : tuple of str, length p
        Labels of the standard parameters (columns of the full regressor).
    independent : ndarray of int, shape (r,)
        Columns of the independent standard parameters, in pivot order.
    dependent : ndarray of int, shape (p - r,)
        The remaining columns.
    K_d : ndarray, shape (r, p - r)
        Combination coefficients [m or m^2 per entry, as the units demand].
    rank : int
    rtol : float
        Relative rank threshold used.
    labels : tuple of str, length r
        ``beta1 .. beta_r``.
    expressions : tuple of str, length r
        Each base parameter in the standard ones.
    """

    std_labels: tuple[str, ...]
    independent: NDArray[np.intp]
    dependent: NDArray[np.intp]
    K_d: NDArray[np.float64]
    rank: int
    rtol: float
    labels: tuple[str, ...]
    expressions: tuple[str, ...]

    @property
    def n_std(self) -> int:
        """Number of standard parameters p."""
        return len(self.std_labels)

    @property
    def projection(self) -> NDArray[np.float64]:
        """The (r, p) matrix ``P`` with ``beta = P phi``."""
        P = np.zeros((self.rank, self.n_std))
        P[np.arange(self.rank), self.independent] = 1.0
        P[:, self.dependent] = self.K_d
        return P

    def beta_from_phi(self, phi: ArrayLike) -> NDArray[np.float64]:
        """Base parameters of standard parameters: (..., p) or (n, 10) -> (..., r)."""
        p = _checks.as_array("phi", phi)
        if p.ndim == 2 and p.shape[0] * p.shape[1] == self.n_std and p.shape[1] == 10:
            p = p.reshape(-1)
        if p.shape[-1:] != (self.n_std,):
            raise ShapeError(f"phi must have shape (..., {self.n_std}); got {p.shape}")
        return p[..., self.independent] + p[..., self.dependent] @ self.K_d.T

    def reduce(self, Y: ArrayLike) -> NDArray[np.float64]:
        """Base regressor ``Y_b`` from a full regressor ``Y`` (..., p) -> (..., r)."""
        Y = _checks.as_array("Y", Y)
        if Y.shape[-1:] != (self.n_std,):
            raise ShapeError(f"Y must have shape (..., {self.n_std}); got {Y.shape}")
        return Y[..., self.independent]


def _clean(x: NDArray[np.float64], digits: int, scale: float) -> NDArray[np.float64]:
    """``x`` rounded to ``digits`` significant digits; 0 below ``1e-11 max(scale, 1)``."""
    out = np.zeros(x.shape)
    keep = ~(np.abs(x) < 1e-11 * max(scale, 1.0))  # only these are formatted
    out[keep] = [float(f"{v:.{digits}g}") for v in x[keep]]
    return out


def _term(coef: float, label: str) -> str:
    if coef == 1.0:
        return f"+ {label}"
    if coef == -1.0:
        return f"- {label}"
    sign = "-" if coef < 0 else "+"
    return f"{sign} {abs(coef):.10g}*{label}"


#: A column whose part not explained by the columns already chosen keeps at least this
#: fraction of its (unit) norm counts as independent of them; the first such column in
#: parameter order is chosen, as Gauss-Jordan elimination does (Gaz et al. 2019).
INDEPENDENCE_THRESHOLD = 1e-6


def _pivoted_r(
    A: NDArray[np.float64], rtol: float
) -> tuple[NDArray[np.float64], NDArray[np.intp], int]:
    """``R`` (min(m, p), p), pivots and rank of a QR with column pivoting of ``A`` (m, p).

    First the triangular factor ``R0`` of ``A`` without pivoting: an orthogonal
    transformation keeps every column norm and the pivoted factorisation. Then Householder
    steps on the small ``R0``: at each step the first column (in parameter order) whose
    remaining norm is at least ``INDEPENDENCE_THRESHOLD`` is chosen; if none is, the
    column of largest remaining norm while it exceeds ``rtol`` times the first step's
    largest norm; the rank is the number of steps taken. The choice then depends on the
    structure of the regressor, not on rounding or on the particular samples.
    """
    m, p = A.shape
    R0 = scipy.linalg.qr(A, mode="r", overwrite_a=True, check_finite=False)[0]
    R = np.array(R0[: min(m, p)], dtype=np.float64)
    piv = np.arange(p)
    first = None
    rank = 0
    for k in range(R.shape[0]):
        norms = np.sqrt(np.einsum("ij,ij->j", R[k:, k:], R[k:, k:]))
        top = norms.max(initial=0.0)
        first = top if first is None else first
        if top == 0.0 or top <= rtol * first:
            break
        ok = np.flatnonzero(norms >= INDEPENDENCE_THRESHOLD)
        j = k + (int(ok[np.argmin(piv[k + ok])]) if ok.size else int(np.argmax(norms)))
        if j != k:
            R[:, [k, j]] = R[:, [j, k]]
            piv[[k, j]] = piv[[j, k]]
        x = R[k:, k]
        alpha = -np.copysign(np.linalg.norm(x), x[0])
        v = x.copy()
        v[0] -= alpha
        vv = float(v @ v)
        if vv > 0.0:
            R[k:, k:] -= np.outer(v, (2.0 / vv) * (v @ R[k:, k:]))
        R[k + 1 :, k] = 0.0
        rank = k + 1
    return np.triu(R), piv, rank


def base_parameters_from_regressor(
    W: ArrayLike,
    std_labels: tuple[str, ...] | None = None,
    *,
    rtol: float = 1e-10,
    clean_digits: int = 10,
) -> BaseParameters:
    """Base parameters of a stacked regressor.

    Parameters
    ----------
    W : array_like, shape (m, p)
        Stacked regressor (``m >= p`` rows that excite every identifiable combination).
    std_labels : tuple of str, length p, optional
    rtol : float
        Relative rank tolerance on the diagonal of R (scaled columns).
    clean_digits : int
        Significant digits kept in ``K_d`` (removes round-off; 0 keeps raw values).

    Returns
    -------
    BaseParameters
    """
    W = _checks.as_array("W", W)
    if W.ndim != 2:
        raise ShapeError(f"W must have shape (m, p); got {W.shape}")
    m, p = W.shape
    labels = tuple(std_labels) if std_labels is not None else tuple(f"phi{k + 1}" for k in range(p))
    if len(labels) != p:
        raise ShapeError(f"std_labels must have {p} entries; got {len(labels)}")
    norms = np.linalg.norm(W, axis=0)
    null, scale = _null_and_scale(norms)
    Ws = np.empty((m, p), order="F")  # column-major, as LAPACK takes it (no further copy)
    np.divide(W, scale, out=Ws)
    Ws[:, null] = 0.0
    return _from_scaled(Ws, scale, labels, rtol, clean_digits)


def _null_and_scale(
    norms: NDArray[np.float64],
) -> tuple[NDArray[np.bool_], NDArray[np.float64]]:
    """Columns at round-off level, and the column scales (1 for those)."""
    # columns at round-off level relative to the largest act on nothing: zero them, since
    # scaling them to unit norm would turn round-off into a spurious direction
    null = norms <= 1e-12 * np.max(norms, initial=0.0)
    return null, np.where(null, 1.0, norms)


def _from_scaled(
    Ws: NDArray[np.float64],
    scale: NDArray[np.float64],
    labels: tuple[str, ...],
    rtol: float,
    clean_digits: int,
) -> BaseParameters:
    """Base parameters from the column-scaled regressor ``Ws`` (m, p), column-major.

    ``Ws`` is overwritten by its QR factorisation.
    """
    m, p = Ws.shape
    R, piv, r = _pivoted_r(Ws, rtol)
    ind, dep = np.sort(piv[:r]), np.sort(piv[r:])
    # K_d from the scaled problem: Ws_b K = Ws_d  <=>  R11 K = R12 (pivot order); then rows
    # and columns in sorted column order
    Kp = scipy.linalg.solve_triangular(R[:r, :r], R[:r, r:]) if r else np.zeros((0, p - r))
    Ks = Kp[np.argsort(piv[:r])][:, np.argsort(piv[r:])]
    K_d = (Ks / scale[ind][:, None]) * scale[dep][None, :]
    if clean_digits:
        K_d = _clean(K_d, clean_digits, float(np.max(np.abs(K_d), initial=0.0)))
    exprs = []
    for k in range(r):
        parts = [labels[ind[k]]]
        nz = np.flatnonzero(K_d[k])
        parts += [_term(K_d[k, j], labels[dep[j]]) for j in nz]
        exprs.append(" ".join(parts))
    return BaseParameters(
        std_labels=labels,
        independent=_checks.frozen(ind),
        dependent=_checks.frozen(dep),
        K_d=_checks.frozen(K_d),
        rank=r,
        rtol=rtol,
        labels=tuple(f"beta{k + 1}" for k in range(r)),
        expressions=tuple(exprs),
    )


def base_parameters(
    robot: Robot,
    *,
    kind: str = "static",
    n_samples: int = 64,
    rng: np.random.Generator | None = None,
    rtol: float = 1e-10,
) -> BaseParameters:
    """Base parameters of a robot's structure, from random states.

    The identifiable combinations depend on the kinematics only; they are found from the
    regressor on ``n_samples`` random states (positions within the limits, or within
    ``[-pi, pi]`` where unlimited).

    Parameters
    ----------
    kind : {"static", "torque"}
        Regressor used: ``[tril M; g]`` at rest, or the torque regressor with random
        velocities and accelerations. Both give the same space for a fixed base.
    rng : numpy.random.Generator, optional
        Source of the random states (default: seeded 0, reproducible).
    """
    rng = np.random.default_rng(0) if rng is None else rng
    lo = np.where(np.isfinite(robot.q_min), robot.q_min, -np.pi)
    hi = np.where(np.isfinite(robot.q_max), robot.q_max, np.pi)
    q = rng.uniform(lo, hi, (n_samples, robot.n))
    if kind == "static":
        W = static_regressor(robot, q).reshape(-1, 10 * robot.n)
    elif kind == "torque":
        dq = rng.uniform(-2, 2, q.shape)
        ddq = rng.uniform(-5, 5, q.shape)
        W = _torque_regressor(robot, q, dq, ddq, robot.gravity).reshape(-1, 10 * robot.n)
    else:
        raise OptionError(f"kind must be 'static' or 'torque'; got {kind!r}")
    return base_parameters_from_regressor(W, robot.param_labels, rtol=rtol)
