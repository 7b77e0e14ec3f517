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
kg m^2, and a rotor's column grows with the square of its gear ratio), so that the rank and
the base set do not depend on units, gear ratios or the size of a term's columns. A column
is first zeroed when it acts on nothing: below 1e-12 of the largest (round-off), or below
a clear gap in the column norms, each measured against the largest of its *family* (the
links' masses, first moments, inertias: one unit each; a rotor's column alone). The rank
is read from a clear gap in the singular values ``s`` of the
scaled regressor (:func:`rank_from_gap`): the first cut, from the top, between ``s[k-1]``
and ``s[k]`` with ``s[k] <= RANK_FLOOR s[0]`` and ``s[k-1] / s[k] >= RANK_GAP``. A
near-dependency below that floor (a URDF whose angles are rounded, ``rpy="1.5708 0 0"``,
leaves singular values near 1e-4 where the exact kinematics have zeros) is a dependency:
fitting it would give coefficients with standard deviations of 1e8 %. The gap found is
returned (``gap``, the two singular values relative to ``s[0]``) and ``rtol`` is the cut
level, their geometric mean. An explicit ``rtol`` instead cuts at ``rtol s[0]``.

:func:`identifiability` classifies every standard parameter: identifiable alone,
unidentifiable (it acts on nothing) or identifiable only in combination, from the zeros of
``K_d`` the scaled problem set, so that it too holds at any unit and gear ratio (a rotor of
gear ratio 200 enters ``beta1`` as ``40000*Ia1`` and is still only in combination).

Which standard parameters are independent is decided by the pivot order. After scaling
every column has norm 1, so pivoting on the largest norm (LAPACK's ``geqp3``) would choose
by rounding noise and by the samples, and the expressions would change from one data set
or machine to the next. Here the first column in parameter order that is independent of
the columns chosen before it is taken, as Gauss-Jordan elimination does: the base
parameters depend on the robot's structure only (see :func:`_pivoted_r`).
"""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import dataclass

import numpy as np
from numpy.typing import ArrayLike, NDArray

from .. import _checks
from ..exceptions import OptionError, ShapeError
from ..model.robot import Robot, checked_robot
from .static import static_regressor, static_rows
from .terms import ModelTerm
from .torque import torque_regressor_prepared

__all__ = [
    "BLOCK_BYTES",
    "RANK_FLOOR",
    "RANK_GAP",
    "BaseParameters",
    "base_parameters",
    "base_parameters_from_regressor",
    "identifiability",
    "link_families",
    "rank_from_gap",
]

#: Only singular values (of the column-scaled regressor) at or below this fraction of the
#: largest may be cut off as a dependency. Above it a direction is identifiable, if
#: perhaps poorly (the fit warns about ill-conditioning).
RANK_FLOOR = 1e-3
#: A rank cut needs at least this ratio between the singular values on either side.
RANK_GAP = 1e3


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
        Relative rank threshold used: the geometric mean of the gap, or the ``rtol`` given.
    labels : tuple of str, length r
        ``beta1 .. beta_r``.
    expressions : tuple of str, length r
        Each base parameter in the standard ones.
    gap : tuple of float, optional
        Singular values of the column-scaled regressor just above and just below the rank
        cut, relative to the largest (``(s[r-1], s[r]) / s[0]``; ``s[r]`` is 0 when the
        rank is full). None when unknown (a model read from a file).
    """

    std_labels: tuple[str, ...]
    independent: NDArray[np.intp]
    dependent: NDArray[np.intp]
    K_d: NDArray[np.float64]
    rank: int
    rtol: float
    labels: tuple[str, ...]
    expressions: tuple[str, ...]
    gap: tuple[float, float] | None = None

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

    def holding(self, label: str) -> tuple[str, ...]:
        """The base parameters whose combination holds the standard parameter ``label``
        (``("beta1",)`` for ``Ia1`` when ``beta1 = J1zz + ... + Ia1``); empty for a
        standard parameter no base parameter holds (unidentifiable)."""
        k = self.std_labels.index(label)
        own = np.flatnonzero(np.asarray(self.independent) == k)
        if own.size:
            return (self.labels[int(own[0])],)
        d = np.flatnonzero(np.asarray(self.dependent) == k)
        col = np.asarray(self.K_d)[:, int(d[0])]
        return tuple(self.labels[i] for i in np.flatnonzero(col))

    def meaning(self, combinations: Sequence[str], *, width: int = 60) -> str:
        """`` (where beta3 = J3zz + ..., ...)`` for the base labels that ``combinations``
        name (each expression cut at ``width`` characters), or ``""``."""
        words = {w for c in combinations for w in c.split()}
        parts = []
        for lab, expr in zip(self.labels, self.expressions, strict=True):
            if lab in words:
                short = expr if len(expr) <= width else expr[: width - 3].rstrip() + "..."
                parts.append(f"{lab} = {short}")
        return f" (where {', '.join(parts)})" if parts else ""

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


def rank_from_gap(
    sv: ArrayLike, rtol: float | None = None
) -> tuple[int, tuple[float, float], float]:
    """Rank of a column-scaled regressor from its singular values.

    Parameters
    ----------
    sv : array_like, shape (k,)
        Singular values, in decreasing order.
    rtol : float, optional
        If given, the rank is the number of singular values above ``rtol sv[0]``.
        Otherwise it is read from the first clear gap from the top: the smallest ``k``
        with ``sv[k] <= RANK_FLOOR sv[0]`` and ``sv[k-1] >= RANK_GAP sv[k]``; without
        such a gap every singular value counts.

    Returns
    -------
    rank : int
    gap : tuple of float
        ``(sv[rank-1], sv[rank]) / sv[0]`` (0 past the end).
    cut : float
        The relative threshold: ``rtol``, or the geometric mean of the gap (for a full
        rank, half the smallest relative singular value).
    """
    s = np.asarray(sv, dtype=np.float64)
    if s.size == 0 or not s[0] > 0:
        return 0, (0.0, 0.0), float(rtol or 0.0)
    rel = s / s[0]
    if rtol is not None:
        r = int(np.sum(rel > rtol))
    else:
        r = s.size
        for k in range(1, s.size):
            if rel[k] <= RANK_FLOOR and (rel[k] == 0.0 or rel[k - 1] / rel[k] >= RANK_GAP):
                r = k
                break
    above = float(rel[r - 1]) if r > 0 else 1.0
    below = float(rel[r]) if r < s.size else 0.0
    if rtol is not None:
        cut = float(rtol)
    elif below > 0.0:
        cut = float(np.sqrt(above * below))
    else:
        cut = 0.5 * above if r == s.size else min(1e-12, 0.5 * above)
    return r, (above, below), cut


def _pivoted_r(
    A: NDArray[np.float64], rtol: float | None
) -> tuple[NDArray[np.float64], NDArray[np.intp], int, tuple[float, float], float]:
    """``R`` (min(m, p), p), pivots, rank, gap and cut of a pivoted QR of ``A`` (m, p).

    First the triangular factor ``R0`` of ``A`` without pivoting: an orthogonal
    transformation keeps every column norm and the pivoted factorisation. The rank comes
    from the singular values of ``R0`` (:func:`rank_from_gap`). Then Householder steps on
    the small ``R0``: at each step the first column (in parameter order) whose remaining
    norm is at least the cut level (and ``INDEPENDENCE_THRESHOLD``) is chosen; if none
    is, the column of largest remaining norm; ``rank`` steps are taken. The choice then
    depends on the structure of the regressor, not on rounding or on the samples.
    """
    import scipy.linalg  # scipy on first use (start-up time)

    m, p = A.shape
    R0 = scipy.linalg.qr(A, mode="r", overwrite_a=True, check_finite=False)[0]
    R = np.array(R0[: min(m, p)], dtype=np.float64)
    sv = np.linalg.svd(R, compute_uv=False)
    r_target, gap, cut = rank_from_gap(sv, rtol)
    s0 = float(sv[0]) if sv.size else 0.0
    threshold = max(INDEPENDENCE_THRESHOLD, cut * s0)
    piv = np.arange(p)
    rank = 0
    for k in range(min(R.shape[0], r_target)):
        norms = np.sqrt(np.einsum("ij,ij->j", R[k:, k:], R[k:, k:]))
        top = norms.max(initial=0.0)
        if top == 0.0:
            break
        ok = np.flatnonzero(norms >= threshold)
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
    return np.triu(R), piv, rank, gap, cut


def base_parameters_from_regressor(
    W: ArrayLike,
    std_labels: tuple[str, ...] | None = None,
    *,
    rtol: float | None = None,
    clean_digits: int = 10,
    families: ArrayLike | None = None,
) -> BaseParameters:
    """Base parameters of a stacked regressor.

    Parameters
    ----------
    W : array_like, shape (m, p)
        Stacked regressor (``m >= p`` rows that excite every identifiable combination).
    std_labels : tuple of str, length p, optional
    rtol : float, optional
        Relative rank tolerance on the singular values of the scaled columns; default:
        the rank at the first clear gap (:func:`rank_from_gap`).
    clean_digits : int
        Significant digits kept in ``K_d`` (removes round-off; 0 keeps raw values).
    families : array_like of int, shape (p,), optional
        Columns of one family share their unit and their scale (the links' masses, first
        moments, inertias: :func:`link_families`); each column's norm is measured against
        the largest of its family before a gap in the norms is looked for
        (:func:`_null_and_scale`), so that the base does not depend on units or gear
        ratios. Default: one family (every column against the largest).

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
    fam = np.zeros(p, dtype=np.intp) if families is None else np.asarray(families, np.intp)
    if fam.shape != (p,):
        raise ShapeError(f"families must have {p} entries; got shape {fam.shape}")
    null, scale = _null_and_scale(norms, rtol, fam)
    Ws = np.empty((m, p), order="F")  # column-major, as LAPACK takes it (no further copy)
    np.divide(W, scale, out=Ws)
    Ws[:, null] = 0.0
    return _from_scaled(Ws, scale, labels, rtol, clean_digits)


def _null_and_scale(
    norms: NDArray[np.float64],
    rtol: float | None = None,
    families: NDArray[np.intp] | None = None,
) -> tuple[NDArray[np.bool_], NDArray[np.float64]]:
    """Columns that act on nothing, and the column scales (1 for those).

    A column at round-off level relative to the largest acts on nothing; so does one that
    lies below a clear gap in the sorted column norms (:func:`rank_from_gap` on the norms),
    each relative to the largest of its family: a parameter that acts only through a
    rounding error of the kinematics (a link mass seen by gravity through an axis tilted by
    1e-5 rad). Both are zeroed, since scaling them to unit norm would turn round-off into a
    spurious direction. Measuring each column against its own ``families`` (one unit, one
    scale) makes the cut independent of units and gear ratios: a rotor's column, which
    grows with the square of its gear ratio, or the links' masses in other units than their
    inertias never push another family's columns below it. With an explicit ``rtol`` the
    columns at or below ``max(rtol, 1e-12)`` of the largest are.
    """
    top = np.max(norms, initial=0.0)
    null = norms <= (1e-12 if rtol is None else max(rtol, 1e-12)) * top
    if top > 0 and rtol is None:
        rel = norms / top
        if families is not None:
            for f in np.unique(families):
                cols = families == f
                ftop = np.max(norms[cols & ~null], initial=0.0)
                rel[cols] = norms[cols] / ftop if ftop > 0 else 0.0
        order = np.argsort(-rel)
        k = rank_from_gap(rel[order])[0]
        null[order[k:]] = True
    return null, np.where(null, 1.0, norms)


def _from_scaled(
    Ws: NDArray[np.float64],
    scale: NDArray[np.float64],
    labels: tuple[str, ...],
    rtol: float | None,
    clean_digits: int,
) -> BaseParameters:
    """Base parameters from the column-scaled regressor ``Ws`` (m, p), column-major.

    ``Ws`` is overwritten by its QR factorisation.
    """
    import scipy.linalg  # scipy on first use (start-up time)

    m, p = Ws.shape
    R, piv, r, gap, cut = _pivoted_r(Ws, rtol)
    ind, dep = np.sort(piv[:r]), np.sort(piv[r:])
    # K_d from the scaled problem: Ws_b K = Ws_d  <=>  R11 K = R12 (pivot order); then rows
    # and columns in sorted column order
    Kp = scipy.linalg.solve_triangular(R[:r, :r], R[:r, r:]) if r else np.zeros((0, p - r))
    Ks = Kp[np.argsort(piv[:r])][:, np.argsort(piv[r:])]
    # a coefficient below the cut level (scaled units) is a rounding effect, not structure
    Ks = np.where(np.abs(Ks) <= cut, 0.0, Ks)
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
        rtol=cut,
        labels=tuple(f"beta{k + 1}" for k in range(r)),
        expressions=tuple(exprs),
        gap=gap,
    )


def link_families(n: int, n_extra: int = 0) -> NDArray[np.intp]:
    """Families of the standard parameters of ``n`` links then ``n_extra`` term parameters.

    The links' masses (family 0), first moments (1) and inertias (2) share a unit each and
    do not depend on any gear; each term parameter (a rotor inertia, whose column grows with
    the square of its gear ratio) is a family of its own (3, 4, ...). Returns (10 n +
    n_extra,) ints, for :func:`base_parameters_from_regressor`.
    """
    one = np.array([0, 1, 1, 1, 2, 2, 2, 2, 2, 2], dtype=np.intp)
    return np.concatenate([np.tile(one, n), 3 + np.arange(n_extra, dtype=np.intp)])


#: Largest stack of random-state regressor rows [bytes] :func:`base_parameters` holds at
#: once; a longer chain's rows (50 joints: 64 states of 1325 rows and 500 columns, 0.34 GB)
#: are reduced block by block to their triangular factor, which gives the same base
#: parameters (the factor keeps every column norm and every linear dependency).
BLOCK_BYTES = 64 << 20


def base_parameters(
    robot: Robot,
    *,
    kind: str = "static",
    n_samples: int = 64,
    rng: np.random.Generator | None = None,
    rtol: float | None = None,
    terms: Sequence[ModelTerm] = (),
    max_bytes: int = BLOCK_BYTES,
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
    rtol : float, optional
        Relative rank tolerance; default: the rank at the first clear gap of the singular
        values (:func:`rank_from_gap`).
    terms : sequence of ModelTerm
        Extra model terms (:mod:`dynid.regressors.terms`); those ``in_base`` (a rotor
        inertia) join the standard parameters after the links' ``10 n``, with their labels,
        so that they regroup with the link parameters (``beta = J1zz + Ia1``).
    max_bytes : int
        Largest block of stacked regressor rows [bytes] held at once. When the rows of all
        states exceed it, they are computed a block of states at a time and reduced to
        the triangular factor ``R`` of the stack (``W = Q R``, a tall-skinny QR), whose
        column norms and dependencies are those of ``W``: the same base parameters, in
        ``O(p^2)`` memory for ``p`` columns.

    Raises
    ------
    OptionError
        An unknown ``kind``.
    """
    checked_robot(robot)
    import scipy.linalg  # scipy on first use (start-up time)

    rng = np.random.default_rng(0) if rng is None else rng
    if kind not in ("static", "torque"):
        raise OptionError(f"kind must be 'static' or 'torque'; got {kind!r}")
    extra = [t for t in terms if t.in_base]
    lo = np.where(np.isfinite(robot.q_min), robot.q_min, -np.pi)
    hi = np.where(np.isfinite(robot.q_max), robot.q_max, np.pi)
    q = rng.uniform(lo, hi, (n_samples, robot.n))
    dq = ddq = q
    if kind == "torque":
        dq = rng.uniform(-2, 2, q.shape)
        ddq = rng.uniform(-5, 5, q.shape)
    labels = robot.param_labels + tuple(lab for t in extra for lab in t.labels)
    families = link_families(robot.n, len(labels) - 10 * robot.n)
    rows = static_rows(robot.n) if kind == "static" else robot.n
    step = max(1, int(max_bytes) // (8 * rows * len(labels)))
    if step >= n_samples:
        W = _random_rows(robot, kind, extra, q, dq, ddq)
        return base_parameters_from_regressor(W, labels, rtol=rtol, families=families)
    R = np.zeros((0, len(labels)))
    for a in range(0, n_samples, step):
        b = slice(a, a + step)
        W = _random_rows(robot, kind, extra, q[b], dq[b], ddq[b])
        X = np.empty((R.shape[0] + W.shape[0], W.shape[1]), order="F")  # as LAPACK takes it
        X[: R.shape[0]], X[R.shape[0] :] = R, W
        del W
        R = scipy.linalg.qr(X, mode="r", overwrite_a=True, check_finite=False)[0]
        R = R[: len(labels)]
        del X
    return base_parameters_from_regressor(R, labels, rtol=rtol, families=families)


def _random_rows(
    robot: Robot,
    kind: str,
    extra: Sequence[ModelTerm],
    q: NDArray[np.float64],
    dq: NDArray[np.float64],
    ddq: NDArray[np.float64],
) -> NDArray[np.float64]:
    """The stacked regressor rows (B rows per state, p columns) of the states ``q`` (B, n)
    (with ``dq``, ``ddq`` for the torque kind) over the links and the ``extra`` terms."""
    B = q.shape[0]
    if kind == "static":
        blocks = [static_regressor(robot, q)]
        for t in extra:  # (p, s, B) -> (B, s, p); a term that does not act at rest: zeros
            C = t.static_columns(B)
            shape = (B, blocks[0].shape[1], len(t.labels))
            blocks.append(np.zeros(shape) if C is None else C.transpose(2, 1, 0))
    else:
        blocks = [torque_regressor_prepared(robot, q, dq, ddq, robot.gravity)]
        blocks += [t.torque_columns(q, dq, ddq) for t in extra]
    W = np.concatenate(blocks, axis=-1)
    return W.reshape(-1, W.shape[-1])


#: Labels of :func:`identifiability`.
IDENTIFIABLE, UNIDENTIFIABLE, IN_COMBINATION = "identifiable", "unidentifiable", "combination"


def identifiability(base: BaseParameters) -> tuple[str, ...]:
    """Whether each standard parameter can be identified, alone or only in combination.

    With ``P`` the base projection (``beta = P phi``), a standard parameter ``phi_j`` is

    * ``"identifiable"`` when ``e_j`` lies in the row space of ``P`` (``phi_j`` is a
      linear function of ``beta``);
    * ``"unidentifiable"`` when column ``j`` of ``P`` is zero (it acts on nothing);
    * ``"combination"`` otherwise: it is known only through the base parameters whose
      expressions contain it.

    ``P`` is ``[I | K_d]`` up to the order of its columns, so ``e_j`` lies in its row space
    exactly when ``phi_j`` is independent and its row of ``K_d`` is zero (its base
    parameter is ``phi_j`` alone), and column ``j`` is zero exactly when ``phi_j`` is
    dependent with a zero column of ``K_d``. The test reads those zeros, which the base
    set its coefficients to on the column-scaled regressor (a coefficient below the rank
    cut, :func:`base_parameters_from_regressor`). A distance from the row space of the
    unscaled ``P`` would instead depend on units and gear ratios: a rotor's coefficient
    grows with the square of its gear ratio (``beta1 = J1zz + ... + 40000*Ia1`` at a ratio
    of 200 puts ``e_Ia1`` within 1e-9 of the row space), and the decision must not.

    Parameters
    ----------
    base : BaseParameters

    Returns
    -------
    status : tuple of str, length p
        In the order of ``base.std_labels``.
    """
    _checks.of_type("base", base, BaseParameters, "a BaseParameters (dynid.base_parameters(robot))")
    K_d = np.asarray(base.K_d)
    out = [UNIDENTIFIABLE] * base.n_std
    for k, j in enumerate(np.asarray(base.independent)):
        alone = K_d.shape[1] == 0 or not np.any(K_d[k] != 0.0)
        out[int(j)] = IDENTIFIABLE if alone else IN_COMBINATION
    for d, j in enumerate(np.asarray(base.dependent)):
        if K_d.shape[0] and np.any(K_d[:, d] != 0.0):
            out[int(j)] = IN_COMBINATION
    return tuple(out)
