"""Small dense linear algebra for the compiled kernels: a Cholesky factor and its solve.

Numba helpers, inlined into their callers (the IK kernel's damped least squares, the
single-sample forward dynamics); imported only by kernel modules. The matrices are the
leading ``d x d`` block of a 2-d array, factors in the lower triangle.
"""

from __future__ import annotations

import math

from .chain import inline

__all__ = ["cholesky", "cholesky_solve"]


@inline
def cholesky(G, d, shift, L):
    """Cholesky factor of ``G[:d, :d] - shift E`` into ``L``; False unless positive definite."""
    for j in range(d):
        s = G[j, j] - shift
        for k in range(j):
            s -= L[j, k] * L[j, k]
        if not s > 0.0:
            return False
        ljj = math.sqrt(s)
        L[j, j] = ljj
        for i in range(j + 1, d):
            t = G[i, j]
            for k in range(j):
                t -= L[i, k] * L[j, k]
            L[i, j] = t / ljj
    return True


@inline
def cholesky_solve(L, d, b, y):
    """``y = (L L^T)^-1 b`` for the factor of :func:`cholesky`."""
    for i in range(d):
        t = b[i]
        for k in range(i):
            t -= L[i, k] * y[k]
        y[i] = t / L[i, i]
    for i in range(d - 1, -1, -1):
        t = y[i]
        for k in range(i + 1, d):
            t -= L[k, i] * y[k]
        y[i] = t / L[i, i]
