"""A long time series thinned for drawing: the smallest and largest sample of each bin.

A line of many more samples than its axes has pixel columns is drawn through, per bin of
consecutive samples, the bin's smallest and largest sample, in time order: every spike and
extreme stays on the figure (an evenly strided line dropped the samples between its
strides) with two points per bin. Bins never span a break (the gap between two pieces of a
log), so a line broken there stays broken. Pure numpy; matplotlib is not imported.
"""

from __future__ import annotations

from collections.abc import Sequence

import numpy as np
from numpy.typing import ArrayLike, NDArray

__all__ = ["envelope_indices"]


def envelope_indices(
    y: ArrayLike, bins: int, *, breaks: Sequence[int] | NDArray[np.intp] = ()
) -> NDArray[np.intp]:
    """Indices of the samples of ``y`` a line draws: the first smallest and the first
    largest sample of each of about ``bins`` bins of consecutive samples, ascending.

    Parameters
    ----------
    y : array_like, shape (N,)
        The series (any unit).
    bins : int
        Bins over the whole series (at least 1), of equal sample counts to within one;
        about the pixel columns of the axes the line is drawn in.
    breaks : sequence of int
        Sample indices before which a new piece starts; a bin ends at each.

    Returns
    -------
    ndarray of intp, shape (M,)
        Ascending, without repeats; ``M <= 2 * (bins + len(breaks))``. Every sample
        (``arange(N)``) when that is as few, or when ``y`` holds a NaN or an infinity (a
        line broken by its own NaN samples stays broken).
    """
    y = np.asarray(y, dtype=np.float64)
    N = y.shape[0]
    bins = max(1, int(bins))
    edges = np.round(np.linspace(0.0, N, bins + 1)).astype(np.intp)
    cuts = np.asarray(breaks, dtype=np.intp)
    edges = np.unique(np.concatenate([edges, cuts[(cuts > 0) & (cuts < N)]]))
    starts = edges[:-1]  # unique and ascending with N last: every bin holds a sample
    if N <= 2 * starts.size or not np.isfinite(y).all():
        return np.arange(N, dtype=np.intp)
    which = np.repeat(np.arange(starts.size), np.diff(edges))
    low = _first_where(y == np.minimum.reduceat(y, starts)[which], which)
    high = _first_where(y == np.maximum.reduceat(y, starts)[which], which)
    return np.union1d(low, high).astype(np.intp)


def _first_where(hit: NDArray[np.bool_], which: NDArray[np.intp]) -> NDArray[np.intp]:
    """Per bin (``which``: each sample's bin, ascending), the first sample where ``hit``."""
    at = np.flatnonzero(hit)
    _, first = np.unique(which[at], return_index=True)
    return at[first]
