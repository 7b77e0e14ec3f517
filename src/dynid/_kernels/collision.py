"""Compiled (numba) kernel of the self-collision distances of capsule segments
(:func:`dynid.simulation.collision.self_distances`).

The closest points of two segments (Ericson, *Real-Time Collision Detection*, 2005,
5.1.9), the operations of the numpy path (``collision._segment_distance_xyz``) in its
order, without fused multiply-adds: the same numbers, bit for bit, one pass over the
samples without the numpy path's temporaries. Imported lazily
(:func:`dynid._kernels.dispatch.load`), never by ``import dynid``.
"""

from __future__ import annotations

import numpy as np

from .chain import exact

__all__ = ["segment_pair_distances"]

#: Below this a squared length or the determinant is zero (the numpy path's ``eps``).
_EPS = 1e-12


@exact
def _clip01(x):  # pragma: no cover (compiled)
    """``x`` within [0, 1] (numpy's ``clip``: ``min(max(x, 0), 1)``)."""
    return min(max(x, 0.0), 1.0)


@exact
def segment_pair_distances(seg, pairs, out):  # pragma: no cover (compiled)
    """Distances [m] of the segments of each pair of ``pairs`` (k, 2) in every sample of
    ``seg`` (M, c, 2, 3) (segment ``i``'s ends ``seg[m, i, 0]`` and ``seg[m, i, 1]``)
    into ``out`` (M, k)."""
    M, k = seg.shape[0], pairs.shape[0]
    eps = _EPS
    for m in range(M):
        for p in range(k):
            i, j = pairs[p, 0], pairs[p, 1]
            p1x, p1y, p1z = seg[m, i, 0, 0], seg[m, i, 0, 1], seg[m, i, 0, 2]
            p2x, p2y, p2z = seg[m, j, 0, 0], seg[m, j, 0, 1], seg[m, j, 0, 2]
            d1x, d1y, d1z = seg[m, i, 1, 0] - p1x, seg[m, i, 1, 1] - p1y, seg[m, i, 1, 2] - p1z
            d2x, d2y, d2z = seg[m, j, 1, 0] - p2x, seg[m, j, 1, 1] - p2y, seg[m, j, 1, 2] - p2z
            rx, ry, rz = p1x - p2x, p1y - p2y, p1z - p2z
            # the products summed (x + z) + y, as the numpy path sums them
            a = (d1x * d1x + d1z * d1z) + d1y * d1y
            e = (d2x * d2x + d2z * d2z) + d2y * d2y
            f = (d2x * rx + d2z * rz) + d2y * ry
            c = (d1x * rx + d1z * rz) + d1y * ry
            b = (d1x * d2x + d1z * d2z) + d1y * d2y
            denom = a * e - b * b
            s = _clip01((b * f - c * e) / denom) if denom > eps * max(a * e, eps) else 0.0
            t = (b * s + f) / e if e > eps else 0.0
            if t < 0:
                s = _clip01(-c / a) if a > eps else 0.0
            elif t > 1:
                s = _clip01((b - c) / a) if a > eps else 0.0
            t = _clip01(t)
            if e <= eps:  # the second segment a point: t = 0, s from the first alone
                s = _clip01(-c / a) if a > eps else 0.0
                t = 0.0
            x = (p1x + s * d1x) - (p2x + t * d2x)
            y = (p1y + s * d1y) - (p2y + t * d2y)
            z = (p1z + s * d1z) - (p2z + t * d2z)
            out[m, p] = np.sqrt((x * x + y * y) + z * z)
