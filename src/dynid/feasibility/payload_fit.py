"""The least squares of a load's parameters and their physical consistency.

* :func:`fit_load`: the least squares of the load's ``p`` parameters (and the friction
  beside them), refused when the data do not excite every direction of the load's
  parameters (a load rotated about one axis only), the unexcited ones named;
* :func:`friction_told_apart`: the friction columns beside the load without those the
  data do not tell apart (a joint that turns one way throughout: its Coulomb friction is
  its offset), and the note that names them;
* :func:`load_parameters`: the estimate checked for a positive mass and, for the full 10,
  moved into the physically consistent set by the pseudo-inertia LMI when it is not in it
  (the closest point in the metric of the data; Wensing, Kim, Slotine, RA-L 2018);
* :func:`summary`: mass, CoM, inertia about the CoM and their standard deviations;
* :func:`serial_correlation_factor`: how much the variances of a fit to low-pass filtered
  samples exceed those of independent rows;
* :func:`misfit_covariance`: the largest change of the estimate an unmodelled torque as
  large as the fit's misfit can make, which the residual's covariance does not see;
* :func:`block_jackknife_covariance`: the spread of the estimate over held-out time
  blocks, which an error of the arm's model that varies along the motion widens (the
  residual's covariance does not see the part of that error the load's columns absorb).
"""

from __future__ import annotations

import numpy as np
from numpy.typing import NDArray

from ..exceptions import DataError, RankDeficientError, SolverError
from ..identification.least_squares import LeastSquaresFit, fit_least_squares
from ..identification.one_way_friction import columns_left_out, one_way_joints
from ..identification.solvers import (
    column_scale,
    pivoted_rank,
)
from ..model.inertia import inertia6_from_matrix, inertial_from_phi
from ..regressors.base import RANK_FLOOR
from ..regressors.terms import friction_labels
from .lmi import pseudo_inertia, pseudo_inertia_margin

__all__ = [
    "FIT_RTOL",
    "HELD_OUT_BLOCKS",
    "block_jackknife_covariance",
    "fit_load",
    "friction_told_apart",
    "held_out_widening",
    "load_parameters",
    "misfit_covariance",
    "serial_correlation_factor",
    "summary",
]

#: Contiguous time blocks of :func:`block_jackknife_covariance`.
HELD_OUT_BLOCKS = 10

#: The relative rank tolerance of the load's least squares without ``rtol``
#: (:func:`fit_load`), and of the friction columns told apart beside it
#: (:func:`friction_told_apart`).
FIT_RTOL = 1e-10


def summary(phi: NDArray[np.float64], cov: NDArray[np.float64], full: bool):
    """Mass, CoM, inertia (about CoM) and their standard deviations from phi and its cov."""

    def f(p: NDArray[np.float64]) -> NDArray[np.float64]:
        m, c, I = inertial_from_phi(p)
        return np.concatenate([[m], c, inertia6_from_matrix(I)])

    p = phi.copy()
    k = cov.shape[0]
    scale = np.maximum(np.abs(p[:k]), 1e-6 * max(float(np.max(np.abs(p[:k]))), 1e-12))
    Jac = np.empty((10, k))
    for i in range(k):
        h = 1e-6 * scale[i]
        a, b = p.copy(), p.copy()
        a[i] += h
        b[i] -= h
        Jac[:, i] = (f(a) - f(b)) / (2 * h)
    C = Jac @ cov @ Jac.T
    std = np.sqrt(np.maximum(np.diag(C), 0.0))
    m, c, I = inertial_from_phi(p)
    if not full:
        std[4:] = np.nan
        I = np.zeros((3, 3))
    return float(m), c, I, float(std[0]), std[1:4], std[4:]


def _consistent(
    phi_ls: NDArray[np.float64], R: NDArray[np.float64], margin: float
) -> tuple[NDArray[np.float64], bool]:
    """The LMI-constrained estimate closest to ``phi_ls`` in ``||R (phi - phi_ls)||``."""
    if pseudo_inertia_margin(phi_ls) >= margin:
        return phi_ls, False
    import cvxpy as cp

    from .convex.solvers import clarabel

    s = np.maximum(np.abs(phi_ls), 1e-9 * max(float(np.max(np.abs(phi_ls))), 1e-12))
    x = cp.Variable(10)  # phi = s * x, so the variables are of order one
    phi = cp.multiply(s, x)
    J = _pseudo_inertia_expr(phi)
    Rs = R * s[None, :]
    obj = cp.sum_squares(Rs @ x - R @ phi_ls)
    cons = [J - margin * cp.trace(J) * np.eye(4) >> 0]
    prob = cp.Problem(cp.Minimize(obj), cons)
    try:
        prob.solve(solver=clarabel())
    except (cp.error.SolverError, ArithmeticError, ValueError) as exc:
        raise SolverError(f"payload: the consistent estimate was not found ({exc})") from exc
    if prob.status not in ("optimal", "optimal_inaccurate") or x.value is None:
        raise SolverError(f"payload: the consistent estimate was not found (status {prob.status})")
    return s * np.asarray(x.value), True


def _pseudo_inertia_expr(phi):  # noqa: ANN001, ANN202 (cvxpy expressions)
    """cvxpy expression of :func:`~dynid.feasibility.lmi.pseudo_inertia` (linear in phi)."""
    E = np.eye(10)
    return sum(phi[i] * pseudo_inertia(E[i]) for i in range(10))


_LOAD_LABELS = ("m", "mcx", "mcy", "mcz", "Jxx", "Jxy", "Jxz", "Jyy", "Jyz", "Jzz")


def fit_load(
    W: NDArray[np.float64],
    y: NDArray[np.float64],
    kept: NDArray[np.bool_] | None,
    rtol: float | None,
    p: int,
    static: bool,
) -> LeastSquaresFit:
    """The least squares of the load (and friction) columns.

    Without ``rtol``, every direction of the load's ``p`` parameters must be excited
    (:func:`_excited`): a load rotated about one axis only excites some of its 10
    parameters, and the noise of the measured positions would otherwise fill the others.
    The friction columns ``kept`` are those the data tell apart
    (:func:`friction_told_apart`).

    Raises
    ------
    RankDeficientError
        Naming the load's parameters the data do not excite, and what would excite them;
        or, when the columns not told apart are friction columns alone (``kept`` holding
        some the data do not tell apart), naming those and not the load.
    """
    labels = _LOAD_LABELS[:p] + friction_labels((W.shape[1] - p) // 3)
    if rtol is None:
        r, names = _excited(W, p, kept, labels)
        if r < p:
            raise _not_excited(r, p, names, static)
    try:
        return fit_least_squares(
            W, y, kept=kept, rtol=FIT_RTOL if rtol is None else rtol, std="robust"
        )
    except RankDeficientError as exc:
        by_column = {f"column {i}": label for i, label in enumerate(labels)}
        shown = tuple(by_column.get(d, d) for d in exc.dependent)
        if shown and not set(shown) & set(_LOAD_LABELS[:p]):
            raise _not_told_apart(exc.rank, exc.needed, shown) from None
        raise _not_excited(exc.rank, exc.needed, shown, static) from None


def friction_told_apart(
    W: NDArray[np.float64],
    kept: NDArray[np.bool_],
    labels: tuple[str, ...],
    p: int,
    rtol: float = FIT_RTOL,
) -> tuple[NDArray[np.bool_], str | None]:
    """``kept`` without the friction columns the data do not tell apart, and the note
    that says which (None when none).

    The friction columns (those after the load's first ``p``, labelled ``labels``) kept
    are scaled to unit norm and their rank read from the pivoted QR's diagonal at
    ``rtol`` (the least squares' own tolerance, :data:`FIT_RTOL`). Each combination they
    do not excite (:func:`~dynid.identification.solvers.unexcited_combinations`) loses
    the column that names it, the offset in place of a Coulomb coefficient it holds with
    it (:func:`~dynid.identification.one_way_friction.offset_instead`, as identification
    does): a joint that turns one way throughout has ``sign(dq_j)`` constant, its offset's
    column. This is the friction's confound, not the load's, whose columns
    :func:`fit_load` then judges against the friction left.

    Parameters
    ----------
    W : ndarray, shape (N, p + f)
        The rows: the load's ``p`` columns, then ``f`` friction columns.
    kept : ndarray of bool, shape (p + f,)
        The columns fitted.
    labels : tuple of str, length f
        The friction columns' labels (``fv1, fc1, fo1, ...``).
    p : int
        The load's columns, left as they are.
    rtol : float
        The relative rank tolerance.

    Returns
    -------
    kept : ndarray of bool, shape (p + f,)
    note : str or None
    """
    out = np.array(kept, dtype=bool)
    combinations: list[str] = []
    for _ in range(len(labels)):  # each round leaves one column out at least
        idx = np.flatnonzero(out[p:])
        named = _not_told_apart_columns(W[:, p + idx], tuple(labels[i] for i in idx), rtol)
        if named is None:
            break
        combinations += named[1]
        out[[p + labels.index(lab) for lab in named[0]]] = False
    if not combinations:
        return out, None
    left = [lab for i, lab in enumerate(labels) if kept[p + i] and not out[p + i]]
    return out, _told_apart_note(tuple(combinations), left)


def _not_told_apart_columns(
    F: NDArray[np.float64], names: tuple[str, ...], rtol: float
) -> tuple[set[str], tuple[str, ...]] | None:
    """The columns of ``F`` (N, f), labelled ``names``, whose leaving out gives the others
    full rank at ``rtol`` (an offset in place of a Coulomb coefficient it makes a
    combination with) and the combinations; None at full rank (or fewer rows than
    columns: the least squares says so)."""
    import scipy.linalg  # as the rest of the module: scipy on first use

    if not names or F.shape[0] < F.shape[1]:
        return None
    scale = column_scale(F)
    R, piv = scipy.linalg.qr(F / scale, mode="r", pivoting=True)
    rank = pivoted_rank(R, rtol)
    if rank == len(names):
        return None
    R = R[: len(names), np.argsort(piv)]  # the columns back in their order
    return columns_left_out(R, scale, rank, names)


def _told_apart_note(combinations: tuple[str, ...], left: list[str]) -> str:
    """The note of :func:`friction_told_apart`: the joints that turn one way named, the
    combinations and the columns left out."""
    joints = one_way_joints(combinations)
    which = ", ".join(str(j) for j in joints)
    why, kept = (
        (
            f"joint(s) {which} turn one way throughout the data: the Coulomb friction of "
            "each is a constant torque, which the data do not tell from its offset",
            "its Coulomb coefficient holding both",
        )
        if joints
        else (
            "the data do not tell apart the friction coefficients beside the load",
            "the coefficients kept holding them",
        )
    )
    return (
        f"{why} ({'; '.join(combinations)}): {', '.join(left)} left out, {kept} (a "
        "confound of the friction, not of the load, which is fitted beside it)"
    )


def _excited(
    W: NDArray[np.float64], p: int, kept: NDArray[np.bool_] | None, labels: tuple[str, ...]
) -> tuple[int, tuple[str, ...]]:
    """How many directions of the load's parameters (the first ``p`` columns) the data
    excite, and the labels of the others' large entries.

    Every column is scaled to unit norm; the load's columns are then freed of what the
    other fitted columns (friction, offsets) explain, and a direction whose singular
    value stays below :data:`~dynid.regressors.base.RANK_FLOOR` (a 1e-3 part of a unit
    column) is not excited: its estimate would be noise amplified a thousandfold.
    """
    import scipy.linalg  # as the rest of the module: scipy on first use

    cols = np.arange(W.shape[1]) if kept is None else np.flatnonzero(kept)
    other = cols[cols >= p]
    M = np.concatenate([W[:, other], W[:, :p]], axis=1)
    if M.shape[0] < M.shape[1]:
        return p, ()  # fewer rows than columns: the least squares says so
    M /= column_scale(M)
    R = scipy.linalg.qr(M, mode="r")[0]
    _, sv, Vt = np.linalg.svd(R[other.size : other.size + p, other.size :])
    r = int(np.sum(sv > RANK_FLOOR))
    null = np.abs(Vt[r:])
    names = tuple(labels[i] for i in np.flatnonzero(null.max(axis=0, initial=0.0) > 0.3))
    return r, names


def _not_excited(
    rank: int | None, needed: int | None, names: tuple[str, ...], static: bool
) -> RankDeficientError:
    hint = (
        "static data at more varied configurations (with --gravity-only: mass and CoM only)"
        if static
        else "a log that moves the joints carrying the load, its wrist included, so that "
        "the load rotates about several axes (or static data)"
    )
    return RankDeficientError(
        f"the data do not excite the load's parameters (rank {rank} of {needed}; "
        f"unexcited combinations of {', '.join(names) or '?'}); hint: {hint}",
        rank=rank,
        needed=needed,
        dependent=names,
    )


def _not_told_apart(
    rank: int | None, needed: int | None, names: tuple[str, ...]
) -> RankDeficientError:
    """The friction columns beside the load, not the load's, not told apart by the data."""
    return RankDeficientError(
        f"the data do not tell apart the friction coefficients estimated beside the load "
        f"(rank {rank} of {needed}; nearly dependent: {', '.join(names)}); the load's "
        "parameters are not among them; hint: terms=... with fewer friction parts, or a "
        "log in which each moving joint reverses",
        rank=rank,
        needed=needed,
        dependent=names,
    )


def load_parameters(
    est: NDArray[np.float64],
    std_mass: float,
    W: NDArray[np.float64],
    margin: float,
    notes: list[str],
) -> tuple[NDArray[np.float64], bool, float]:
    """The load's 10 parameters from the least-squares ``est`` (checked for a positive
    mass; 4: mass and first moments; 10: moved into the consistent set by the LMI)."""
    phi_ls = np.zeros(10)
    phi_ls[: est.size] = est
    if phi_ls[0] <= 0:  # both routes: the LMI would turn no load into 1e-22 kg, silently
        raise DataError(
            f"the estimated load mass is {phi_ls[0]:.6g} kg (std {std_mass:.2g} kg; not "
            "positive); is a load mounted, and is the arm's model right (its armature, "
            "rotor inertias and friction included)?"
        )
    if est.size == 4:
        return phi_ls, False, float("nan")
    import scipy.linalg  # as the rest of the module: scipy on first use

    R = scipy.linalg.qr(W[:, :10], mode="r")[0][:10]
    phi, active = _consistent(phi_ls, R, margin)
    if active:
        notes.append(
            "the least-squares estimate was not physically consistent; the LMI "
            f"(margin {margin:g}) moved it; standard deviations are the unconstrained ones"
        )
    return phi, active, float(pseudo_inertia_margin(phi))


def serial_correlation_factor(
    residual: NDArray[np.float64], n: int, max_lag: int
) -> tuple[float, int]:
    """The variance inflation of a least squares whose residual is serially correlated,
    and the lags used.

    Rows of filtered recordings (sample-major, ``n`` joints a sample) are not independent:
    a zero-phase low-pass at ``f_c`` correlates the noise over about ``f_s / f_c``
    samples, so the covariance of independent rows is too small by about that factor
    (the standard deviations by its square root). With the residual's autocorrelation
    ``rho_l`` pooled over the joints, the factor is the Newey-West long-run variance
    ratio with Bartlett weights, ``1 + 2 sum_l (1 - l / (L + 1)) rho_l`` for
    ``l = 1 .. L = max_lag`` (Newey and West, Econometrica 55, 1987), at least 1.
    """
    R = np.asarray(residual, dtype=np.float64).reshape(-1, n)
    R = R - R.mean(axis=0)
    var = float(np.sum(R * R))
    L = int(min(max(max_lag, 0), R.shape[0] // 4))
    if var <= 0 or L < 1:
        return 1.0, 0
    f = 1.0
    for lag in range(1, L + 1):
        rho = float(np.sum(R[lag:] * R[:-lag])) / var
        f += 2.0 * (1.0 - lag / (L + 1)) * rho
    return max(f, 1.0), L


def misfit_covariance(
    W: NDArray[np.float64],
    residual: NDArray[np.float64],
    noise_rms: float,
    p: int,
    *,
    rows: int | None = None,
) -> NDArray[np.float64]:
    """The squared largest change of each of the first ``p`` coefficients of the least
    squares ``W b = y`` that an unmodelled torque as large as the fit's misfit can make.

    A torque ``e`` the model lacks moves the estimate by ``G W^T e`` with
    ``G = (W^T W)^{-1}``; by Cauchy-Schwarz ``|db_i| <= sqrt(G_ii) ||e||``, with equality
    for ``e`` along the estimator's row. ``||e||^2`` is taken as the residual's sum of
    squares less the noise's, ``||r||^2 - m noise_rms^2`` (``m`` rows): the misfit the
    residual shows. The part of ``e`` the columns absorb does not show in the residual,
    so this is no strict bound; on a simulated Panda with unmodelled springs, tilts or
    friction at 7 to 79 x the noise, the mass's error stayed under 0.9 of it (a spring's
    0.46 kg error on a 1.5 kg load against 0.71 kg), where the residual's covariance,
    which treats the misfit as noise, gave 0.125 kg.

    Parameters
    ----------
    W : ndarray, shape (m, k)
        The fitted columns only.
    residual : ndarray, shape (m,)
        The fit's residual [SI of the rows].
    noise_rms : float
        The RMS the noise alone leaves in a row [SI of the rows].
    p : int
        The coefficients returned.
    rows : int, optional
        The rows the misfit spreads over, when ``residual`` is another one's (a judged
        residual on some of them): ``||e||^2 = rows (mean(r^2) - noise_rms^2)``;
        default ``m``.

    Returns
    -------
    ndarray, shape (p, p)
        ``G[:p, :p] (||r||^2 - m noise_rms^2)``, zero when the residual is at the noise.
    """
    import scipy.linalg  # as the rest of the module: scipy on first use

    m = residual.size if rows is None else rows
    s = column_scale(W)
    R = scipy.linalg.qr(W / s, mode="r")[0][: W.shape[1]]
    Rinv = scipy.linalg.solve_triangular(R, np.eye(W.shape[1]))[:p]  # rows of R^-1
    G = (Rinv @ Rinv.T) / np.outer(s[:p], s[:p])  # (W^T W)^-1 = R^-1 R^-T, columns unscaled
    misfit = max(float(residual @ residual) - residual.size * noise_rms**2, 0.0)
    misfit *= m / residual.size
    return G * misfit


def block_jackknife_covariance(
    W: NDArray[np.float64],
    y: NDArray[np.float64],
    n: int,
    blocks: int = HELD_OUT_BLOCKS,
    wanted: int | None = None,
) -> NDArray[np.float64] | None:
    """The delete-one-block jackknife covariance of the least squares ``W b = y``.

    The rows (sample-major, ``n`` a sample) are cut into ``blocks`` contiguous blocks of
    whole samples; ``b_i`` is the fit without block ``i`` and the covariance
    ``(K - 1) / K sum_i (b_i - b_bar)(b_i - b_bar)^T`` (``K = blocks``; Kuensch, Ann.
    Statist. 17, 1989). Each block's normal equations of the column-scaled rows are formed
    once, so the ``K`` fits cost one pass over the rows.

    Parameters
    ----------
    W : ndarray, shape (m, p)
        The fitted columns only.
    y : ndarray, shape (m,)
    n : int
        Rows per sample.
    blocks : int
        ``K`` (at least 2).
    wanted : int, optional
        Only the first ``wanted`` columns' estimates are wanted (a load's, before the
        arm's friction columns): a fit without a block need determine just those, the
        other columns' directions that block alone excites (a joint's Coulomb and offset
        columns alike where it reverses in that block only) taken out of them
        (:func:`_fold_wanted`). Default: every column's.

    Returns
    -------
    ndarray, shape (p, p) or (wanted, wanted), or None
        None when there are fewer than ``2 K`` samples or a fit without a block does not
        determine the wanted columns (that block alone excites some direction of them).
    """
    import scipy.linalg  # as the rest of the module: scipy on first use

    samples = W.shape[0] // n
    if blocks < 2 or samples < 2 * blocks:
        return None
    s = column_scale(W)
    edges = np.linspace(0, samples, blocks + 1).astype(int) * n
    G = [(W[a:b] / s).T @ (W[a:b] / s) for a, b in zip(edges[:-1], edges[1:], strict=True)]
    h = [(W[a:b] / s).T @ y[a:b] for a, b in zip(edges[:-1], edges[1:], strict=True)]
    G_all, h_all = sum(G), sum(h)
    k = W.shape[1] if wanted is None else min(wanted, W.shape[1])
    est = []
    for Gi, hi in zip(G, h, strict=True):
        A, rhs = G_all - Gi, h_all - hi
        if k < A.shape[0]:
            got = _fold_wanted(A, rhs, k)
            if got is None:
                return None
            est.append(got / s[:k])
            continue
        if np.linalg.cond(A) > 1.0 / RANK_FLOOR**2:  # the normal equations square it
            return None
        est.append(scipy.linalg.solve(A, rhs, assume_a="pos") / s)
    b = np.asarray(est)
    d = b - b.mean(axis=0)
    return (blocks - 1) / blocks * (d.T @ d)


def _fold_wanted(
    A: NDArray[np.float64], rhs: NDArray[np.float64], k: int
) -> NDArray[np.float64] | None:
    """The first ``k`` entries of a least-squares solution of the normal equations
    ``A x = rhs`` (``A`` (p, p) of column-scaled rows), which are unique where the
    Schur complement ``S = A_kk - A_kr A_rr^+ A_rk`` of the other columns is regular
    (the other columns' null directions are those of their rows, which ``A_kr`` and
    ``rhs_r`` do not see); None where ``S``'s condition number exceeds ``1 /
    RANK_FLOOR^2`` (the normal equations square it). ``A_rr^+``: the pseudo-inverse,
    eigenvalues below ``RANK_FLOOR^2`` of the largest left out."""
    Akk, Akr, Arr = A[:k, :k], A[:k, k:], A[k:, k:]
    w, V = np.linalg.eigh(Arr)
    keep = w > RANK_FLOOR**2 * max(float(w.max(initial=0.0)), 0.0)
    P = (V[:, keep] / w[keep]) @ V[:, keep].T
    S = Akk - Akr @ P @ Akr.T
    if not np.all(np.isfinite(S)) or np.linalg.cond(S) > 1.0 / RANK_FLOOR**2:
        return None
    return np.asarray(np.linalg.solve(S, rhs[:k] - Akr @ P @ rhs[k:]), dtype=np.float64)


def held_out_widening(
    cov: NDArray[np.float64], jack: NDArray[np.float64]
) -> tuple[NDArray[np.float64], NDArray[np.float64]]:
    """``cov`` (k, k) with each variance raised to the block jackknife's ``jack`` (the
    first k of its diagonal, :func:`block_jackknife_covariance`) where that is larger, the
    correlations kept; and the factor (k,) each standard deviation was widened by (>= 1)."""
    var = np.diag(cov)
    k = var.shape[0]
    widen = np.sqrt(np.maximum(1.0, np.diag(jack)[:k] / np.where(var > 0, var, np.inf)))
    return cov * np.outer(widen, widen), widen
