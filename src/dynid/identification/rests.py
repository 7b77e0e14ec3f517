"""Rests: a joint standing still, told apart from a pass through zero velocity.

A joint *rests* where its velocity stays inside its standstill band for at least
:data:`MIN_REST_S` seconds, from the first sample inside to the last. A reversal passes
through the band in a few samples (a joint reversing at 1 rad/s^2 crosses a band of
1e-3 rad/s in 2 ms): there the friction steps from one sign to the other and the torque is
no holding torque, whatever the residual does. The observer counts the rests its
calibration reads (:mod:`dynid.observer.rest_margin`) by the same length; ``validate``
says a residual is the holding torque at rest only over the samples of rests
(:mod:`~dynid.identification.residual_dependence`). Times [s], one array per piece (a
rest never spans a gap).
"""

from __future__ import annotations

from collections.abc import Sequence

import numpy as np
from numpy.typing import NDArray

from ..exceptions import ShapeError

__all__ = ["MIN_REST_S", "lasting_rests"]

#: Seconds [s] a joint must stay inside its standstill band for a rest.
MIN_REST_S = 0.5


def lasting_rests(inside: NDArray[np.bool_], t: Sequence[NDArray[np.float64]]) -> NDArray[np.bool_]:
    """The samples of the runs of ``inside`` that last at least :data:`MIN_REST_S`.

    Parameters
    ----------
    inside : ndarray of bool, shape (N, n)
        Per sample and joint: the velocity inside the standstill band, the pieces' samples
        one after the other.
    t : sequence of ndarray, each (N_k,)
        Each piece's sample times [s], ascending; ``sum(N_k) == N``.

    Returns
    -------
    ndarray of bool, shape (N, n)
        True at the samples of a run inside the band, within one piece, whose last sample
        is at least :data:`MIN_REST_S` after its first.
    """
    x = np.asarray(inside, dtype=bool)
    sizes = [len(tk) for tk in t]
    if x.ndim != 2 or sum(sizes) != x.shape[0]:
        raise ShapeError(f"inside must have shape (N, n) with N = {sum(sizes)}; got {x.shape}")
    out = np.zeros(x.shape, dtype=bool)
    start = 0
    for tk, size in zip(t, sizes, strict=True):
        piece, tt = x[start : start + size], np.asarray(tk, dtype=np.float64)
        edge = np.diff(piece.astype(np.int8), axis=0, prepend=0, append=0)
        for j in range(piece.shape[1]):
            first = np.flatnonzero(edge[:, j] == 1)
            last = np.flatnonzero(edge[:, j] == -1) - 1
            keep = tt[last] - tt[first] >= MIN_REST_S
            mark = np.zeros(size + 1, dtype=np.int64)
            np.add.at(mark, first[keep], 1)
            np.add.at(mark, last[keep] + 1, -1)
            out[start : start + size, j] = np.cumsum(mark[:-1]) > 0
        start += size
    return out
