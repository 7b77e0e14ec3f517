"""Standard deviations that hold for serially correlated residuals (Newey and West 1987).

A torque log's torques and regressor are low-passed and then decimated: the residual of
the fit is coloured, correlated over several samples, and ``sigma^2 (W^T W)^{-1}``, which
assumes independent rows, understates the spread of the estimates (2 to 3 times on the
small coefficients of a filtered log). The heteroskedasticity-and-autocorrelation-
consistent (HAC) covariance is

.. math:: \\mathrm{cov}(\\hat\\beta) = \\frac{m}{m - r} (W^T W)^{-1} \\Big(\\sum_k
   \\frac{B_k B_k^T}{L + 1}\\Big) (W^T W)^{-1}, \\qquad
   B_k = \\sum_{j = k - L}^{k} s_j, \\quad s_j = \\sum_{i \\in \\text{sample } j} W_i^T e_i

with ``s_j`` the score of sample ``j`` (the rows of its joints summed: any correlation
between the joints at one instant is kept) and ``B_k`` the moving sums of ``L + 1``
consecutive scores within one piece of a recording (zero outside it, ``k`` over every
window that meets the piece). The sum is Bartlett's kernel, ``Gamma_0 + sum_l (1 - l /
(L + 1)) (Gamma_l + Gamma_l^T)``, written as a sum of squares: positive semidefinite
whatever the data. A weighted fit passes its weighted rows and residual (the sandwich of
weighted least squares).

Assumptions: the residual of a piece is correlated over at most about ``L`` samples
(:func:`hac_lag` ties ``L`` to the low-pass: two periods of the cut-off at the decimated
rate, where the filtered noise has forgotten itself), uncorrelated between pieces and
recordings (they are never joined: a window never spans two pieces), and the pieces are
long against ``L`` (the estimate's own relative error is about ``sqrt(L / N)``). With
``L = 0`` and one row per sample it is White's HC1 (``std="robust"``).

The meat is accumulated block by block (:class:`SerialMeat`), carrying the last ``L``
scores of a piece from one block to the next: rows held whole and rows read in blocks give
the same sum.
"""

from __future__ import annotations

import math
from collections.abc import Sequence
from dataclasses import dataclass

import numpy as np
from numpy.typing import NDArray

from ..exceptions import ShapeError

__all__ = [
    "LAG_PERIODS",
    "Serial",
    "SerialMeat",
    "hac_lag",
    "serial_meat",
    "serial_of_pieces",
]

#: Periods of the cut-off frequency spanned by the HAC window: the zero-phase Butterworth
#: low-pass of white noise (order 4, applied twice) leaves a correlation that has decayed
#: below 1 % after about 1.5 periods.
LAG_PERIODS = 2.0


@dataclass(frozen=True, slots=True)
class Serial:
    """The time structure of the rows of a fit, for the HAC covariance (module docstring).

    Attributes
    ----------
    rows_per_sample : int
        Consecutive rows of one sample (the joints of a torque log: row ``k n + j``).
    lag : int
        Bartlett window ``L`` [samples]: scores up to ``L`` samples apart are correlated.
    starts : tuple of int
        First row of every piece (recording, or piece of one cut at a gap) in the rows of
        the fit, increasing, the first 0; windows never span two pieces.
    """

    rows_per_sample: int = 1
    lag: int = 0
    starts: tuple[int, ...] = (0,)

    def __post_init__(self) -> None:
        if self.rows_per_sample < 1 or self.lag < 0:
            raise ShapeError(
                f"rows_per_sample must be >= 1 and lag >= 0; got {self.rows_per_sample}, {self.lag}"
            )
        s = np.asarray(self.starts)
        if s.size == 0 or s[0] != 0 or np.any(np.diff(s) <= 0):
            raise ShapeError(f"piece starts must be increasing from 0; got {self.starts}")
        if np.any(s % self.rows_per_sample):
            raise ShapeError(
                f"piece starts {self.starts} must be whole samples of {self.rows_per_sample} rows"
            )


def hac_lag(cutoff_hz: float | None, rate_hz: float) -> int:
    """The HAC window [samples] of a log low-passed at ``cutoff_hz`` and sampled (after
    decimation) at ``rate_hz``: ``ceil(LAG_PERIODS rate / cutoff)``; 0 when unfiltered
    (``cutoff_hz`` None: the noise is taken as white)."""
    if cutoff_hz is None or not cutoff_hz > 0:
        return 0
    return int(math.ceil(LAG_PERIODS * rate_hz / cutoff_hz - 1e-9))


def serial_of_pieces(samples: Sequence[int], n: int, lags: Sequence[int]) -> Serial:
    """The :class:`Serial` of pieces of ``samples`` samples each, ``n`` rows a sample,
    concatenated in order; the window the longest of the pieces' ``lags``."""
    starts = np.concatenate([[0], np.cumsum(np.asarray(samples, dtype=np.intp) * n)[:-1]])
    return Serial(n, max(lags, default=0), tuple(int(s) for s in starts))


class SerialMeat:
    """The HAC middle factor, accumulated over the rows' scores in order, block by block.

    Parameters
    ----------
    serial : Serial
    r : int
        Columns of the scores.
    """

    def __init__(self, serial: Serial, r: int) -> None:
        self.serial = serial
        self.r = r
        self.meat = np.zeros((r, r))
        self._row = 0  # rows seen
        self._piece = 0  # index of the current piece
        self._rest = np.zeros((0, r))  # rows of a sample not yet complete
        self._tail = np.zeros((serial.lag, r))  # the piece's last L sample scores

    def add(self, scores: NDArray[np.float64]) -> None:
        """Add the scores ``W_i e_i`` (m_b, r) of the next ``m_b`` rows."""
        starts = self.serial.starts
        while scores.shape[0]:
            nxt = starts[self._piece + 1] if self._piece + 1 < len(starts) else None
            take = scores.shape[0] if nxt is None else min(scores.shape[0], nxt - self._row)
            self._rows(scores[:take])
            scores = scores[take:]
            if nxt is not None and self._row == nxt:
                self._close()
                self._piece += 1

    def add_products(self, W: NDArray[np.float64], e: NDArray[np.float64], first: int = 0) -> None:
        """Add the scores ``W_i e_i`` of the next ``m_b`` rows ``W`` (m_b, r) with their
        residual ``e`` (m_b,), the columns before ``first`` zero: as :meth:`add` of those
        scores, whole samples summed in one pass without the scores written out."""
        starts, n = self.serial.starts, self.serial.rows_per_sample
        while e.size:
            nxt = starts[self._piece + 1] if self._piece + 1 < len(starts) else None
            take = e.size if nxt is None else min(e.size, nxt - self._row)
            whole = 0 if self._rest.size else take - take % n
            if whole:
                k = whole // n
                S = np.zeros((k, self.r))
                Wk = W[:whole, first:].reshape(k, n, self.r - first)
                S[:, first:] = np.einsum("kjr,kj->kr", Wk, e[:whole].reshape(k, n))
                self._row += whole
                self._samples(S)
            if take > whole:
                sc = np.zeros((take - whole, self.r))
                sc[:, first:] = W[whole:take, first:] * e[whole:take, None]
                self._rows(sc)
            W, e = W[take:], e[take:]
            if nxt is not None and self._row == nxt:
                self._close()
                self._piece += 1

    def _rows(self, scores: NDArray[np.float64]) -> None:
        """Rows of the current piece: whole samples summed, the rest kept."""
        self._row += scores.shape[0]
        n = self.serial.rows_per_sample
        rows = np.concatenate([self._rest, scores]) if self._rest.size else scores
        k = rows.shape[0] // n
        self._rest = rows[k * n :].copy()
        if k:
            self._samples(rows[: k * n].reshape(k, n, self.r).sum(axis=1))

    def _samples(self, S: NDArray[np.float64]) -> None:
        """The windows ending at each of the sample scores ``S`` (k, r)."""
        L = self.serial.lag
        if L == 0:  # each window one sample's score
            self.meat += S.T @ S
            return
        T = np.concatenate([self._tail, S])
        C = np.concatenate([np.zeros((1, self.r)), np.cumsum(T, axis=0)])
        B = C[L + 1 :] - C[: -L - 1]
        self.meat += B.T @ B
        self._tail = T[T.shape[0] - L :]

    def _close(self) -> None:
        """End the piece: the windows past its last sample, then a fresh start."""
        if self._rest.size:
            raise ShapeError(
                f"a piece ends inside a sample of {self.serial.rows_per_sample} rows (row "
                f"{self._row})"
            )
        L = self.serial.lag
        if L:
            self._samples(np.zeros((L, self.r)))
        self._tail = np.zeros((L, self.r))

    def result(self) -> NDArray[np.float64]:
        """The middle factor (r, r) over every row added (the last piece closed)."""
        self._close()
        out = self.meat / (self.serial.lag + 1)
        return np.asarray(0.5 * (out + out.T), dtype=np.float64)


def serial_meat(
    W: NDArray[np.float64],
    blk: NDArray[np.intp],
    e: NDArray[np.float64],
    serial: Serial,
) -> NDArray[np.float64]:
    """The HAC middle factor (r, r) of the rows ``blk`` (``(start, stop, first)``, in order)
    of ``W`` (M, r) with the residual ``e`` over those rows (in block order)."""
    r = W.shape[1]
    acc = SerialMeat(serial, r)
    o = 0
    for a, b, c in blk:
        acc.add_products(W[a:b], e[o : o + b - a], c)
        o += b - a
    return acc.result()
