"""Compiled (numba) kernel of the low-pass filter's second-order sections
(:mod:`dynid.butterworth`).

Imported lazily (:func:`dynid._kernels.dispatch.load`), never by ``import dynid``.
"""

from __future__ import annotations

from .chain import exact

__all__ = ["sections"]


@exact
def sections(sos, x, zi, out):
    """``x`` (m, k) through the cascade of second-order sections ``sos`` (s, 6) (rows
    ``b0 b1 b2 1 a1 a2``) along its first axis, from the states ``zi`` (s, 2, k) (updated)
    into ``out`` (m, k): each section in the transposed direct form II,
    ``y = b0 x + z0``, ``z0 = b1 x - a1 y + z1``, ``z1 = b2 x - a2 y``, the operations of
    ``scipy.signal.sosfilt`` in its order, without fused multiply-adds (the same numbers,
    bit for bit)."""
    m, k = x.shape
    s = sos.shape[0]
    for n in range(m):
        for c in range(k):
            cur = x[n, c]
            for j in range(s):
                new = sos[j, 0] * cur + zi[j, 0, c]
                zi[j, 0, c] = sos[j, 1] * cur - sos[j, 4] * new + zi[j, 1, c]
                zi[j, 1, c] = sos[j, 2] * cur - sos[j, 5] * new
                cur = new
            out[n, c] = cur
