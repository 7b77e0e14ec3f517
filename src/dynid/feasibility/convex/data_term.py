"""The convex method's data term ``1/2 ||A (x - x_hat)||^2`` (:class:`DataTerm`) and the
term of identified coefficients (:func:`coefficient_term`): weighted by their covariance
(two steps, from a file), or by the data's own residual ``||W x - y||^2 / sigma^2`` (one
step: the normal equations the fit kept, whatever standard deviations it reports)."""

from __future__ import annotations

from dataclasses import dataclass
from typing import Literal

import numpy as np
from numpy.typing import NDArray

from ...exceptions import DataError, ModelError
from ...identification.holdout import HeldOut
from ...identification.least_squares import LeastSquaresFit
from ...identification.model import IdentifiedModel
from ...identification.structural import mixed_sign
from ...model.stiffness import JointStiffness
from ...regressors.terms import FrictionValues, ModelTerm
from .options import EXACT_RTOL

__all__ = ["DataTerm", "coefficient_term"]


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
        ``k``: 0, or the coefficients of the model's appended terms fitted (friction, less
        the coefficients of joints that never moved).
    friction_index : ndarray of int, shape (k,), optional
        Where each such unknown sits among every coefficient of :attr:`terms`, in order;
        None: all of them in order.
    terms : tuple of ModelTerm
        The appended terms the unknowns are coefficients of (:mod:`dynid.regressors.terms`):
        they say which are kept ``>= 0`` and what friction they are.
    labels : tuple of str
        Names of the entries of ``x``.
    notes : tuple of str
        What the user should know about the data term (a missing covariance).
    holdout : HeldOut, optional
        Normal equations of the held-out folds over the entries of ``x``
        (:mod:`dynid.identification.holdout`): the weight and the acceptance are then
        judged on held-out data.
    dissipation : ndarray, shape (m, k), optional
        Rows ``G`` with ``G f >= 0`` for friction that opposes the motion within the
        velocity limits (each term's :meth:`~dynid.regressors.terms.ModelTerm.
        dissipation_rows`, over the unknowns fitted); None: none.
    std : ndarray, shape (r + k,), optional
        The standard deviations the fit reports for ``x_hat`` (its estimator's: hac,
        robust or classical), against which the result's moves are told; None: unknown.
    free_sign : ndarray of bool, shape (k,), optional
        The unknowns that hold a difference of friction coefficients (``fv6`` holding
        ``fv6 - fv5``, :func:`~dynid.identification.structural.mixed_sign`), kept free of
        :meth:`nonnegative` and of the dissipation rows; None: none.
    """

    P: NDArray[np.float64]
    x_hat: NDArray[np.float64]
    A: NDArray[np.float64]
    dof: int
    exact: bool
    n_friction: int = 0
    friction_index: NDArray[np.intp] | None = None
    terms: tuple[ModelTerm, ...] = ()
    labels: tuple[str, ...] = ()
    notes: tuple[str, ...] = ()
    holdout: HeldOut | None = None
    dissipation: NDArray[np.float64] | None = None
    std: NDArray[np.float64] | None = None
    free_sign: NDArray[np.bool_] | None = None

    @property
    def r(self) -> int:
        """Number of base parameters in ``x``."""
        return int(self.P.shape[0])

    def friction_layout(self) -> NDArray[np.intp]:
        """:attr:`friction_index`, or ``0 .. k-1`` when every coefficient is fitted."""
        if self.friction_index is None:
            return np.arange(self.n_friction)
        return np.asarray(self.friction_index)

    def nonnegative(self) -> NDArray[np.bool_]:
        """(k,): the unknowns a physically consistent model keeps ``>= 0`` (the terms'
        ``nonnegative``: viscous and Coulomb friction, not an offset)."""
        if not self.terms:
            return np.zeros(self.n_friction, dtype=bool)
        every = np.concatenate([np.asarray(t.nonnegative, dtype=bool) for t in self.terms])
        mine = every[self.friction_layout()]
        return mine if self.free_sign is None else mine & ~self.free_sign

    def frictions(self, f: NDArray[np.float64]) -> tuple[FrictionValues, ...]:
        """The unknowns ``f`` (k,) as the friction of each friction term (its law's
        parameters; zero for the coefficients not fitted), in order."""
        every = np.zeros(sum(len(t.labels) for t in self.terms))
        every[self.friction_layout()] = f
        out, c = [], 0
        for t in self.terms:
            k = len(t.labels)
            fr = t.friction(every[c : c + k])
            c += k
            if fr is not None:
                out.append(fr)
        return tuple(out)

    def stiffness(self, f: NDArray[np.float64]) -> JointStiffness | None:
        """The unknowns ``f`` (k,) as the spring of the terms (zero for the stiffnesses not
        fitted); None when no term is a spring."""
        every = np.zeros(sum(len(t.labels) for t in self.terms))
        every[self.friction_layout()] = f
        found, c = None, 0
        for t in self.terms:
            k = len(t.labels)
            spring = t.stiffness(every[c : c + k])
            found = found if spring is None else spring
            c += k
        return found

    def chi2(self, x: NDArray[np.float64]) -> float:
        """``||A (x - x_hat)||^2``: the increase of the residual sum of squares / sigma^2."""
        return float(np.sum((self.A @ (x - self.x_hat)) ** 2))


def _whitening(cov: NDArray[np.float64]) -> NDArray[np.float64]:
    """``A`` with ``A^T A = cov^+`` (directions of zero variance dropped)."""
    cov = 0.5 * (cov + cov.T)
    s, U = np.linalg.eigh(cov)
    keep = s > 1e-14 * max(float(s.max()), 0.0)
    return (U[:, keep] / np.sqrt(s[keep])).T


def coefficient_term(
    model: IdentifiedModel,
    *,
    with_friction: bool = False,
    weight: Literal["covariance", "residual"] = "covariance",
) -> DataTerm:
    """The data term of identified coefficients (and their friction).

    ``weight="covariance"``: ``model.fit.covariance`` (or ``model.joint_fit``'s with
    friction), of the estimator its standard deviations were made with; without a
    covariance (a file written before it was kept) the standard deviations, uncorrelated.
    ``weight="residual"``: the fit's own rows, ``A^T A = W^T W / sigma^2`` from the normal
    equations it kept (``model.holdout.whole``, the rows the folds are cut from), so that
    the term is the increase of the residual sum of squares whatever standard deviations
    the model reports (hac, robust); the covariance, with a note, when none were kept.
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
    terms = tuple(t.term for t in model.appended) if k else ()
    index = np.flatnonzero(kept[r_all:])
    differences = mixed_sign(model.info.combined)  # fv6 holding fv6 - fv5: no sign to keep
    names = _friction_labels(model)
    free = np.array([int(i) < len(names) and names[i] in differences for i in index], bool)
    held = model.holdout
    if held is not None and held.whole.p != kept.size:
        held = None  # folds over other columns (friction left out of the term)
    if held is not None:
        held = held.restricted(np.flatnonzero(kept))
    A = np.zeros((0, x_hat.size))
    if not exact and weight == "residual" and held is not None:
        A = held.whole.sqrt() / max(held.noise, 1e-300)
    elif not exact:
        A = _whitening(cov)
        if weight == "residual" and fit.covariance is not None:
            notes += (
                "no normal equations of the fit kept: the data term is weighted by the "
                "coefficients' covariance (the standard deviations reported)",
            )
    return DataTerm(
        P=P,
        x_hat=x_hat,
        A=A,
        dof=max(int(fit.n_rows) - int(fit.rank), 1),
        exact=exact,
        n_friction=int(kept[r_all:].sum()) if k else 0,
        friction_index=index if k else None,
        terms=terms,
        free_sign=free if k else None,
        dissipation=_dissipation(terms, index, model.robot.dq_max, free) if k else None,
        labels=labels,
        notes=notes,
        holdout=held,
        std=np.asarray(fit.std, dtype=np.float64)[kept],
    )


def _dissipation(
    terms: tuple[ModelTerm, ...],
    index: NDArray[np.intp],
    dq_max: NDArray[np.float64],
    free: NDArray[np.bool_],
) -> NDArray[np.float64] | None:
    """The terms' dissipation rows over the unknowns ``index`` (of every coefficient of
    ``terms``, in order); rows that only touch coefficients not fitted (0) dropped, and
    those that touch an unknown ``free`` (k,) of its sign (a difference of coefficients:
    the row would bound the difference as if it were one motor's coefficient)."""
    blocks = [np.asarray(t.dissipation_rows(dq_max), dtype=np.float64) for t in terms]
    width = sum(len(t.labels) for t in terms)
    rows, c = [], 0
    for t, G in zip(terms, blocks, strict=True):
        full = np.zeros((G.shape[0], width))
        full[:, c : c + len(t.labels)] = G
        rows.append(full)
        c += len(t.labels)
    if not rows:
        return None
    G = np.concatenate(rows)[:, index]
    G = G[np.any(G != 0.0, axis=1) & ~np.any(G[:, free] != 0.0, axis=1)]
    return G if G.shape[0] else None


def _friction_labels(model: IdentifiedModel) -> tuple[str, ...]:
    """The labels of the model's appended terms' columns (friction), in order."""
    return tuple(lab for t in model.appended for lab in t.labels)
