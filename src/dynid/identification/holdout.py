"""Held-out judgement: contiguous time blocks, their normal equations, cross-validated errors.

A fit judged on the data it was fitted to rewards over-fitting: unconstrained least squares
absorbs noise and effects outside the model into coefficients that predict new data worse.
Every decision that weighs a fit against another (the consistent fit's acceptance, the
prior's weight, a friction law) is therefore taken on **held-out** data:

* **k-fold over contiguous time blocks** (default :data:`DEFAULT_FOLDS` = 5): the rows are
  cut into ``k`` contiguous blocks of samples (never interleaved: neighbouring samples of a
  filtered log are correlated, a random split would leak them into the training set); fold
  ``j`` is fitted on the other ``k - 1`` blocks and predicts block ``j``. The pooled
  held-out error is ``sqrt(sum_j SSE_j / sum_j ||y_j||^2)``.
* **a separate recording** (``--validate-on FILE``): fitted on all of the identification
  data, predicting the other log.

Both are built from the **normal equations of each block**, ``G = W^T W``, ``b = W^T y``,
``c = y^T y`` and the number of rows (:class:`Normals`): the fit of a fold is the total
minus its block, and the squared error of *any* candidate ``x`` on a block is the
quadratic form ``x^T G x - 2 b^T x + c``, so a constrained fit (the consistent one) is judged
without the raw rows. Errors are relative, in % of the measured torques' norm, on the
unweighted rows.
"""

from __future__ import annotations

import math
from collections import OrderedDict
from collections.abc import Hashable, Iterator, Sequence
from contextlib import contextmanager
from contextvars import ContextVar
from dataclasses import dataclass, replace

import numpy as np
from numpy.typing import NDArray

from .._memo import scoped
from ..exceptions import OptionError, ShapeError

__all__ = [
    "DEFAULT_FOLDS",
    "HeldOut",
    "HeldOutErrors",
    "Normals",
    "block_labels",
    "block_normals",
    "cross_validate",
    "fold_errors_percent",
    "rows_labelled",
    "shared_eigen",
]

#: Default number of contiguous time blocks (folds) of the held-out judgement.
DEFAULT_FOLDS = 5
#: Fewest samples a block may hold.
MIN_BLOCK_SAMPLES = 10

#: The column scales ``d`` (p,) and a factorisation of the column-scaled ``G``: ``(d, R,
#: None)`` with ``R`` (p, p) its upper Cholesky factor, or ``(d, U, s)`` its eigenpairs kept.
_Factor = tuple[NDArray[np.float64], NDArray[np.float64], NDArray[np.float64] | None]
#: The column-scaled factorisations :meth:`Normals.solve` made while
#: :func:`shared_eigen` is active: (shape, ``G``'s bytes, rtol) -> :data:`_Factor`, read
#: only, the most recently used first to stay.
_EIGEN: ContextVar[OrderedDict[Hashable, _Factor] | None] = ContextVar("_EIGEN", default=None)
#: Factorisations :func:`shared_eigen` holds at most (the least recently used
#: dropped first): about 40 MB for 70 columns, with their keys.
EIGEN_HELD = 512


@contextmanager
def shared_eigen() -> Iterator[None]:
    """Within the block, the factorisation behind :meth:`Normals.solve` and
    :meth:`Normals.std` of normal equations whose ``G`` holds the same numbers is computed
    once and read back (a structure search judges the same columns of the same folds
    again: 16 % of its solves on a Panda log's tests): the same numbers, not recomputed.
    Nested blocks share the outer one's; what it holds is dropped at its end."""
    with scoped(_EIGEN, OrderedDict):
        yield


#: The column-scaled ``G`` is solved by Cholesky when LAPACK's estimate of its reciprocal
#: condition number (1-norm) is above this: its solution then equals the eigenvectors' to
#: round-off (at most ``cond * eps``, 1e-10 relative) at a tenth of the cost.
CHOLESKY_RCOND = 1e-6


def _factored(G: NDArray[np.float64], rtol: float) -> _Factor:
    """The column scales ``d`` (``sqrt(diag G)``, 1 for a zero column) and the column-scaled
    ``G``'s factorisation: Cholesky when it is well conditioned (:data:`CHOLESKY_RCOND`,
    and far from any eigenvalue ``rtol^2`` times the largest would leave out: every
    direction is kept, the unique solution), else its eigenpairs with a scaled eigenvalue
    below ``rtol^2`` times the largest left out."""
    from scipy.linalg.lapack import dpocon, dpotrf

    d = np.sqrt(np.maximum(np.diag(G), 0.0))
    d = np.where(d > 0, d, 1.0)
    Gs = G / np.outer(d, d)
    Gs = 0.5 * (Gs + Gs.T)
    if Gs.size:
        R, info = dpotrf(Gs, lower=0, clean=1)
        if info == 0:
            rcond, info = dpocon(R, float(np.abs(Gs).sum(axis=0).max()))
            floor = max(CHOLESKY_RCOND, 1e4 * Gs.shape[0] * rtol**2)
            if info == 0 and rcond > floor:
                return d, np.asarray(R, dtype=np.float64), None
    s, U = np.linalg.eigh(Gs)
    keep = s > (rtol**2) * max(float(s[-1]), 0.0) if s.size else s > 0
    return d, U[:, keep], s[keep]


@dataclass(frozen=True, slots=True, eq=False)
class Normals:
    """Normal equations of a set of rows ``W x = y``.

    Attributes
    ----------
    G : ndarray, shape (p, p)
        ``W^T W``.
    b : ndarray, shape (p,)
        ``W^T y``.
    c : float
        ``y^T y``.
    rows : int
        Number of rows.
    origin : ndarray, shape (p,), optional
        A point ``x0`` near the rows' least-squares solution (the fit's coefficients)...
    sse0 : float
        ... and ``||W x0 - y||^2`` summed over the rows themselves: :meth:`sse` is then
        taken about ``x0``, whose residual the rows gave exactly, and resolves a residual
        far below ``eps ||y||^2``, which ``x^T G x - 2 b^T x + c`` loses to cancellation
        (an exact log fitted without a low-pass read "training error 0 %", or 1.3e-06 %
        for 2.8e-14 %). Kept by a sum or difference of normal equations about the same
        ``x0``; None: :meth:`sse` from ``G``, ``b`` and ``c`` alone.
    """

    G: NDArray[np.float64]
    b: NDArray[np.float64]
    c: float
    rows: int
    origin: NDArray[np.float64] | None = None
    sse0: float = 0.0

    @property
    def p(self) -> int:
        """Number of columns."""
        return int(self.b.shape[0])

    def __add__(self, other: Normals) -> Normals:
        G, b, c, rows = self.G + other.G, self.b + other.b, self.c + other.c, self.rows + other.rows
        if (x0 := self._same_origin(other)) is None:
            return Normals(G, b, c, rows)
        return Normals(G, b, c, rows, x0, self.sse0 + other.sse0)

    def __sub__(self, other: Normals) -> Normals:
        G, b, c, rows = self.G - other.G, self.b - other.b, self.c - other.c, self.rows - other.rows
        if (x0 := self._same_origin(other)) is None:
            return Normals(G, b, c, rows)
        return Normals(G, b, c, rows, x0, max(self.sse0 - other.sse0, 0.0))

    def _same_origin(self, other: Normals) -> NDArray[np.float64] | None:
        """The origin both share (:attr:`origin`), or None."""
        a, b = self.origin, other.origin
        return a if a is not None and b is not None and np.array_equal(a, b) else None

    def sse(self, x: NDArray[np.float64]) -> float:
        """``||W x - y||^2`` of a candidate ``x`` (p,) (floored at 0 against round-off):
        about :attr:`origin` ``x0`` when known, ``sse0 + 2 (G x0 - b)^T d + d^T G d`` with
        ``d = x - x0``, whose round-off scales with the residual at ``x0``, not ``||y||^2``."""
        x = np.asarray(x, dtype=np.float64)
        if self.origin is None:
            return max(float(x @ self.G @ x - 2.0 * self.b @ x + self.c), 0.0)
        d = x - self.origin
        grad = self.G @ self.origin - self.b
        return max(float(self.sse0 + 2.0 * grad @ d + d @ self.G @ d), 0.0)

    def relative_error_percent(self, x: NDArray[np.float64]) -> float:
        """``100 ||W x - y|| / ||y||``."""
        return 100.0 * math.sqrt(self.sse(x) / self.c) if self.c > 0 else 0.0

    def _scaled_eigen(self, rtol: float) -> _Factor:
        """The column scales ``d`` and a factorisation of the column-scaled ``G``
        (:func:`_factored`); read from :func:`shared_eigen` when it holds it."""
        held = _EIGEN.get()
        if held is None:
            return _factored(self.G, rtol)
        key = (self.G.shape, self.G.dtype.str, self.G.tobytes(), float(rtol))
        got = held.get(key)
        if got is not None:
            held.move_to_end(key)
            return got
        got = _factored(self.G, rtol)
        for a in got:
            if a is not None:
                a.flags.writeable = False
        held[key] = got
        if len(held) > EIGEN_HELD:
            held.popitem(last=False)
        return got

    def rank(self, rtol: float = 1e-10, floor: float | None = None) -> int:
        """The number of directions :meth:`solve` keeps at ``rtol`` (``p``: every one, the
        unique solution), read from the same factorisation; with ``floor`` (between
        ``rtol`` and 1e-3), those whose scaled eigenvalue is above ``floor^2`` times the
        largest (a Cholesky factorisation, condition below 1e6, keeps every one)."""
        s = self._scaled_eigen(rtol)[2]
        if s is None:
            return self.p
        if floor is None or not s.size:
            return int(s.size)
        return int(np.count_nonzero(s > floor**2 * float(s.max())))

    def scaled_root(self) -> tuple[NDArray[np.float64], NDArray[np.float64]]:
        """``R`` (p, p) with ``R^T R`` the column-scaled ``G`` (``G / (d d^T)``), and the
        column scales ``d`` (p,) (``sqrt(diag G)``, 1 for a zero column): a triangular
        factor's stand-in for naming what the rows do not excite
        (:func:`~dynid.identification.solvers.unexcited_combinations`)."""
        d = np.sqrt(np.maximum(np.diag(self.G), 0.0))
        d = np.where(d > 0, d, 1.0)
        s, U = np.linalg.eigh(0.5 * (self.G + self.G.T) / np.outer(d, d))
        return np.asarray(np.sqrt(np.maximum(s, 0.0))[:, None] * U.T, dtype=np.float64), d

    def solve(self, rtol: float = 1e-10) -> NDArray[np.float64]:
        """Least-squares ``x`` (p,): minimum norm in the column-scaled coordinates,
        directions with a scaled eigenvalue below ``rtol^2`` times the largest left out."""
        return self.solve_with_std(rtol, std=False)[0]

    def std(self, x: NDArray[np.float64], rtol: float = 1e-10) -> NDArray[np.float64]:
        """Classical standard deviations (p,) of the least-squares ``x``:
        ``sqrt(diag(sigma^2 G^+))`` with ``sigma^2 = ||W x - y||^2 / (rows - p)`` and the
        pseudo-inverse of :meth:`solve` (0 for a direction left out)."""
        return self._std(x, self._scaled_eigen(rtol))

    def solve_with_std(
        self, rtol: float = 1e-10, *, std: bool = True
    ) -> tuple[NDArray[np.float64], NDArray[np.float64] | None]:
        """:meth:`solve` and (``std``) :meth:`std` of its solution from one
        factorisation."""
        f = self._scaled_eigen(rtol)
        d, A, s = f
        if s is None:  # Cholesky: A = R, upper, with R^T R the scaled G
            from scipy.linalg.lapack import dpotrs

            x = np.asarray(dpotrs(A, self.b / d, lower=0)[0] / d, dtype=np.float64)
        else:
            x = np.asarray((A @ ((A.T @ (self.b / d)) / s)) / d, dtype=np.float64)
        return x, self._std(x, f) if std else None

    def _std(self, x: NDArray[np.float64], f: _Factor) -> NDArray[np.float64]:
        d, A, s = f
        if s is None:  # diag((R^T R)^-1): the rows' squares of R^-1
            from scipy.linalg.lapack import dtrtri

            var = np.sum(dtrtri(A, lower=0)[0] ** 2, axis=1) / d**2
        else:
            var = np.sum(A**2 / s, axis=1) / d**2
        s2 = self.sse(x) / max(self.rows - self.p, 1)
        return np.asarray(np.sqrt(s2 * var), dtype=np.float64)

    def sqrt(self) -> NDArray[np.float64]:
        """``A`` (s, p) with ``A^T A = G`` (directions of zero eigenvalue dropped)."""
        s, U = np.linalg.eigh(0.5 * (self.G + self.G.T))
        keep = s > 1e-14 * max(float(s[-1]), 0.0) if s.size else s > 0
        return np.asarray((U[:, keep] * np.sqrt(s[keep])).T, dtype=np.float64)

    def restricted(self, columns: NDArray[np.intp]) -> Normals:
        """The normal equations of the columns ``columns`` only."""
        return self._restricted(_Restriction.of(columns, self.p))

    def _restricted(self, on: _Restriction) -> Normals:
        """:meth:`restricted` to the columns ``on`` names."""
        G, b = self.G[on.grid], self.b[on.ix]
        x0 = self.origin
        if x0 is None:
            return Normals(G, b, self.c, self.rows)
        if np.any(x0[on.left_out]):  # the origin moved onto the kept columns, its residual
            x1 = np.where(on.left_out, 0.0, x0)  # taken about the old one: no cancellation
            return Normals(G, b, self.c, self.rows, x1[on.ix], self.sse(x1))
        return Normals(G, b, self.c, self.rows, x0[on.ix], self.sse0)

    def expanded(self, mask: NDArray[np.bool_]) -> Normals:
        """Written over ``mask.size`` columns, these at ``mask`` (zero for the others)."""
        ix = np.flatnonzero(mask)
        G = np.zeros((mask.size, mask.size))
        G[np.ix_(ix, ix)] = self.G
        b = np.zeros(mask.size)
        b[ix] = self.b
        if self.origin is None:
            return Normals(G, b, self.c, self.rows)
        x0 = np.zeros(mask.size)
        x0[ix] = self.origin
        return Normals(G, b, self.c, self.rows, x0, self.sse0)


@dataclass(frozen=True, slots=True, eq=False)
class _Restriction:
    """The columns ``ix`` (k,) kept of ``p``, their rows and columns of ``G``
    (``np.ix_``) and the columns left out (p,) bool: made once for every set of normal
    equations a :class:`HeldOut` restricts alike."""

    ix: NDArray[np.intp]
    grid: tuple[NDArray[np.intp], ...]
    left_out: NDArray[np.bool_]

    @classmethod
    def of(cls, columns: NDArray[np.intp], p: int) -> _Restriction:
        """The restriction to ``columns`` of ``p`` columns."""
        ix = np.asarray(columns, dtype=np.intp)
        left_out = np.ones(p, dtype=bool)
        left_out[ix] = False
        return cls(ix, np.ix_(ix, ix), left_out)


def _noise(whole: Normals) -> float:
    """``sqrt(SSE / (m - p))`` of least squares on ``whole`` (1 without residual)."""
    s = math.sqrt(whole.sse(whole.solve()) / max(whole.rows - whole.p, 1))
    return s if s > 0 else 1.0


def block_labels(n_samples: int, folds: int = DEFAULT_FOLDS) -> NDArray[np.intp]:
    """The contiguous block (0 .. folds-1) of each sample, blocks as equal as possible.

    Raises
    ------
    OptionError
        ``folds < 2``, or fewer than :data:`MIN_BLOCK_SAMPLES` samples per block.
    """
    if folds < 2:
        raise OptionError(f"--folds must be at least 2; got {folds}")
    if n_samples < folds * MIN_BLOCK_SAMPLES:
        raise OptionError(
            f"{n_samples} samples cannot be cut into {folds} time blocks of at least "
            f"{MIN_BLOCK_SAMPLES} samples; lower --folds or record a longer log"
        )
    return np.minimum((np.arange(n_samples) * folds) // n_samples, folds - 1).astype(np.intp)


def rows_labelled(labels: NDArray[np.intp], j: int) -> slice | NDArray[np.bool_]:
    """The rows labelled ``j`` in ``labels`` (m,): a slice when they are contiguous (a
    fold of contiguous rows: no copy of them made to select them), else a mask."""
    sel = labels == j
    first = int(np.argmax(sel))
    count = int(np.count_nonzero(sel))
    if sel[first : first + count].all():
        return slice(first, first + count)
    return sel


def block_normals(
    W: NDArray[np.float64],
    y: NDArray[np.float64],
    labels: NDArray[np.intp],
    origin: NDArray[np.float64] | None = None,
) -> tuple[Normals, ...]:
    """Normal equations of each block of rows.

    Parameters
    ----------
    W : ndarray, shape (m, p)
        Regressor.
    y : ndarray, shape (m,)
        Measurements.
    labels : ndarray of int, shape (m,)
        The block of each row, ``0 .. k-1`` (every block present).
    origin : ndarray, shape (p,), optional
        The fit's coefficients, whose residual each block keeps (:attr:`Normals.origin`).

    Raises
    ------
    ShapeError
        ``W``, ``y`` and ``labels`` disagree in their rows.
    """
    if W.ndim != 2 or y.shape != (W.shape[0],) or labels.shape != (W.shape[0],):
        raise ShapeError(
            f"block_normals: W {W.shape}, y {y.shape} and labels {labels.shape} must share rows"
        )
    k = int(labels.max()) + 1 if labels.size else 0
    out = []
    whole = W.flags.c_contiguous and y.flags.c_contiguous  # a view is alike a copy
    for j in range(k):
        sel = rows_labelled(labels, j) if whole else labels == j
        Wj, yj = W[sel], y[sel]
        n = Normals(Wj.T @ Wj, Wj.T @ yj, float(yj @ yj), yj.size)
        if origin is not None:
            r = yj - Wj @ origin
            n = replace(n, origin=np.asarray(origin, dtype=np.float64), sse0=float(r @ r))
        out.append(n)
    return tuple(out)


@dataclass(frozen=True, slots=True, eq=False)
class HeldOut:
    """Training and held-out normal equations of every fold.

    Attributes
    ----------
    train : tuple of Normals
        What fold ``j`` is fitted on.
    test : tuple of Normals
        What fold ``j`` predicts.
    whole : Normals
        All of the identification data (the final fit's).
    scheme : str
        ``"blocks"`` (k-fold over contiguous time blocks), ``"recordings"`` (one recording
        left out at a time) or ``"file"`` (a separate log).
    noise : float
        Residual standard deviation of least squares on all data, ``sqrt(SSE / (m - p))``
        (scales a fold's data term).
    whitened : tuple of Normals
        What fold ``j`` predicts with each joint's rows divided by that joint's torque
        noise (every joint counts in units of its own noise: a wrist whose noise is a
        hundredth of the shoulder's is not lost in the pooled error); empty when the
        noise is not known.
    judged : Normals or None
        With a separate log: all of the identification data with the targets the separate
        log is judged on (the measured torques), where the training error is read; None:
        ``whole``.
    parts : tuple of Normals
        Contiguous time blocks of the folds' :attr:`whitened` rows (each a block of one
        held-out recording, :meth:`~.recordings.Recordings.part_labels`), whose errors a
        paired standard error reads; empty: the folds themselves.
    part_fold : tuple of int
        The fold each of :attr:`parts` belongs to (and is predicted by the fit of).
    """

    train: tuple[Normals, ...]
    test: tuple[Normals, ...]
    whole: Normals
    scheme: str
    noise: float = 1.0
    whitened: tuple[Normals, ...] = ()
    judged: Normals | None = None
    parts: tuple[Normals, ...] = ()
    part_fold: tuple[int, ...] = ()

    @classmethod
    def k_fold(cls, blocks: Sequence[Normals], test: Sequence[Normals] | None = None) -> HeldOut:
        """Fold ``j`` fitted on every block but ``j``, predicting block ``j`` (its rows'
        targets as ``test[j]`` holds them when given: the measured torques beside the
        low-passed ones fitted)."""
        whole = blocks[0]
        for blk in blocks[1:]:
            whole = whole + blk
        judged = tuple(blocks) if test is None else tuple(test)
        return cls(tuple(whole - b for b in blocks), judged, whole, "blocks", _noise(whole))

    @classmethod
    def separate(cls, whole: Normals, test: Normals, judged: Normals | None = None) -> HeldOut:
        """One fold: fitted on all of ``whole``, predicting ``test`` (another recording);
        ``judged``: ``whole``'s rows with the targets ``test`` holds (the measured torques
        beside the low-passed ones fitted)."""
        return cls((whole,), (test,), whole, "file", _noise(whole), judged=judged)

    @property
    def folds(self) -> int:
        """Number of folds."""
        return len(self.test)

    @property
    def judged_whole(self) -> Normals:
        """All of the data with the targets the folds are judged on (the measured torques
        when :meth:`k_fold` or :meth:`separate` was given them, else ``whole``): the
        training error is read on it, so that it compares with the held-out error."""
        if self.scheme == "file":
            return self.whole if self.judged is None else self.judged
        out = self.test[0]
        for t in self.test[1:]:
            out = out + t
        return out

    @property
    def training_share(self) -> float:
        """Mean share of all rows a fold is fitted on (``(k-1)/k`` for k blocks, 1 for a file)."""
        return float(np.mean([t.rows for t in self.train])) / max(self.whole.rows, 1)

    def restricted(self, columns: NDArray[np.intp]) -> HeldOut:
        """The same folds over the columns ``columns`` only."""
        on = _Restriction.of(columns, self.whole.p)
        return HeldOut(
            tuple(t._restricted(on) for t in self.train),
            tuple(t._restricted(on) for t in self.test),
            self.whole._restricted(on),
            self.scheme,
            self.noise,
            tuple(t._restricted(on) for t in self.whitened),
            None if self.judged is None else self.judged._restricted(on),
            tuple(t._restricted(on) for t in self.parts),
            self.part_fold,
        )

    def expanded(self, mask: NDArray[np.bool_]) -> HeldOut:
        """Written over ``mask.size`` columns (:meth:`Normals.expanded`)."""
        return HeldOut(
            tuple(t.expanded(mask) for t in self.train),
            tuple(t.expanded(mask) for t in self.test),
            self.whole.expanded(mask),
            self.scheme,
            self.noise,
            tuple(t.expanded(mask) for t in self.whitened),
            None if self.judged is None else self.judged.expanded(mask),
            tuple(t.expanded(mask) for t in self.parts),
            self.part_fold,
        )

    def with_parts(self, parts: Sequence[Normals], part_fold: Sequence[int]) -> HeldOut:
        """The same folds with :attr:`parts` (each block's whitened normal equations) and
        the fold of each; unchanged when no fold holds two of them."""
        fold = tuple(int(f) for f in part_fold)
        if len(set(fold)) == len(fold):
            return self
        return replace(self, parts=tuple(parts), part_fold=fold)

    def without_folds(self, skip: Sequence[int]) -> tuple[tuple[Normals, ...], tuple[int, ...]]:
        """:attr:`parts` and :attr:`part_fold` of the folds not in ``skip``, the folds
        numbered again in order."""
        kept = [j for j in range(self.folds) if j not in skip]
        new = {j: i for i, j in enumerate(kept)}
        mine = [(p, new[f]) for p, f in zip(self.parts, self.part_fold, strict=True) if f in new]
        return tuple(p for p, _ in mine), tuple(f for _, f in mine)

    def heldout_error_percent(
        self, xs: Sequence[NDArray[np.float64]], *, whitened: bool = False
    ) -> float:
        """Pooled held-out error [%] of one candidate per fold,
        ``100 sqrt(sum_j SSE_j(x_j) / sum_j ||y_j||^2)``; of the :attr:`whitened` rows
        with ``whitened``."""
        test = self.whitened if whitened else self.test
        if len(xs) != len(test):
            raise ShapeError(f"{len(xs)} candidates for {len(test)} folds")
        sse = sum(t.sse(x) for t, x in zip(test, xs, strict=True))
        c = sum(t.c for t in test)
        return 100.0 * math.sqrt(sse / c) if c > 0 else 0.0

    def describe(self) -> str:
        """How the data were held out, for a summary."""
        if self.scheme == "file":
            return "a separate log"
        if self.scheme == "recordings":
            return f"{self.folds} recordings, each left out in turn"
        return f"{self.folds} contiguous time blocks (k-fold)"


@dataclass(frozen=True, slots=True)
class HeldOutErrors:
    """Training and held-out errors of unconstrained least squares.

    Attributes
    ----------
    scheme : str
        ``"blocks"`` or ``"file"``.
    folds : int
    training_percent : float
        Relative error [%] of the fit on all data, on those data.
    heldout_percent : float
        Pooled relative error [%] of the folds' fits on their held-out rows.
    """

    scheme: str
    folds: int
    training_percent: float
    heldout_percent: float

    def as_dict(self) -> dict[str, float | int | str]:
        """JSON-ready (``identification.json``'s ``heldout``)."""
        return {
            "scheme": self.scheme,
            "folds": self.folds,
            "training_error_percent": self.training_percent,
            "heldout_error_percent": self.heldout_percent,
        }


def cross_validate(
    held: HeldOut,
    rtol: float = 1e-10,
    fit: NDArray[np.float64] | None = None,
    xs: Sequence[NDArray[np.float64]] | None = None,
) -> HeldOutErrors:
    """Training and held-out errors of unconstrained least squares over the folds.

    Parameters
    ----------
    held : HeldOut
        The folds (:meth:`HeldOut.k_fold` or :meth:`HeldOut.separate`).
    rtol : float
        Rank tolerance of each fold's fit (:meth:`Normals.solve`).
    fit : ndarray, shape (p,), optional
        The coefficients fitted on all data, whose training error is given (the
        identification's, solved on the rows); default: least squares on ``held.whole``.
    xs : sequence of ndarray, optional
        Each fold's coefficients (p,); default: least squares on its training rows at
        ``rtol`` (:func:`~dynid.identification.fold_offsets.fold_fits` leaves out the
        offsets those rows do not tell apart).
    """
    xs = [t.solve(rtol) for t in held.train] if xs is None else list(xs)
    x = held.whole.solve(rtol) if fit is None else np.asarray(fit, dtype=np.float64)
    return HeldOutErrors(
        held.scheme,
        held.folds,
        held.judged_whole.relative_error_percent(x),
        held.heldout_error_percent(xs),
    )


def fold_errors_percent(
    held: HeldOut, rtol: float = 1e-10, xs: Sequence[NDArray[np.float64]] | None = None
) -> tuple[float, ...]:
    """Each fold's relative held-out error [%], ``100 ||W x_j - y_j|| / ||y_j||`` with
    ``x_j`` of ``xs``, default least squares on its training rows (:meth:`Normals.solve`
    at ``rtol``): the folds :func:`cross_validate` pools."""
    fits = [f.solve(rtol) for f in held.train] if xs is None else list(xs)
    return tuple(t.relative_error_percent(x) for x, t in zip(fits, held.test, strict=True))
