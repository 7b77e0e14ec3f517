"""Compiled (numba) kernel of the static regressor ``[tril M(q); g(q)]``.

This module imports numba, so it is imported lazily, on the first call of
:func:`dynid.regressors.static.static_regressor` (or of a function built on it) when
:func:`dynid.dynamics.rnea.kernels` finds the compiled kernels (numba installed and
``DYNID_NO_NUMBA`` unset), never by ``import dynid``. The kernel is compiled on its first
call and cached on disk (``cache=True``), with the same compiler options as
:mod:`dynid.dynamics._kernels` (fused multiply-add allowed, no other fast-math flag) and
its sine and cosine (Cephes, :func:`dynid.dynamics._kernels._sincos`).

Equations: those of the numpy path, :mod:`dynid.regressors.static` (link poses in the
base frame, the Jacobian columns of each link origin in link coordinates, then the rows of
``tril M`` and ``g`` from the link's kinetic and potential energy). The two agree to
rounding.

Layout. ``Y[c, k, b]``: output column ``c``, row ``k`` of ``s`` (``tril M`` by
``np.tril_indices(n)``, then ``g``), sample ``b`` last, so that a column of the stacked
regressor (all rows, all samples) is contiguous. ``cols[j]`` is the output column of
standard parameter ``j`` (``robot.param_labels`` order), or ``-1`` to skip it: the base
regressor is written without forming the full one. ``Y`` must hold zeros on entry
(``np.zeros``, whose pages the system zeroes only when they are first touched): the kernel
writes only the entries that can be non-zero, which leaves untouched the rows of the links
after the row's joint (about half of the entries).
"""

from __future__ import annotations

import math

import numpy as np

from ..dynamics._kernels import _SINCOS_MAX, _jit, _sincos

__all__ = ["BLOCK", "static_regressor"]

#: Samples per block (the length of the inner loops and of the runs written into ``Y``).
BLOCK = 128
#: Axes of the products ``(w_i)_a (w_j)_c`` of the inertia columns Jxx, Jxy, Jxz, Jyy, Jyz, Jzz.
_JPAIR = np.array([[0, 0], [0, 1], [0, 2], [1, 1], [1, 2], [2, 2]], dtype=np.int64)


def _static_regressor(T, axes, prismatic, g, q, cols, Y):
    """Static regressor into the zeroed ``Y`` (c, s, B) for q (B n,), columns ``cols``; ``ok``."""
    n = T.shape[0]
    B = q.shape[0] // n
    nm = n * (n + 1) // 2
    # per block of samples, the sample index innermost (contiguous runs of Y, SIMD)
    Rb = np.empty((n, 9, BLOCK))  # rotation of each link in the base frame, row-major
    ob = np.empty((n, 3, BLOCK))  # origin of each link in the base frame
    z = np.empty((n, 3, BLOCK))  # joint axes in the base frame
    v = np.empty((n, 3, BLOCK))  # velocity of the origin of link l, unit rate of joint k
    w = np.empty((n, 3, BLOCK))  # angular velocity of link l, unit rate of joint k
    gl = np.empty((3, BLOCK))  # gravity in link-l coordinates
    for b0 in range(0, B, BLOCK):
        nb = min(BLOCK, B - b0)
        # link poses: R_l = R_{l-1} R_{l-1,l}, o_l = o_{l-1} + R_{l-1} p_{l-1,l}
        for kk in range(nb):
            for i in range(n):
                qi = q[(b0 + kk) * n + i]
                if not math.isfinite(qi):
                    return False
                ax, ay, az = axes[i, 0], axes[i, 1], axes[i, 2]
                if prismatic[i]:
                    q00, q01, q02 = 1.0, 0.0, 0.0
                    q10, q11, q12 = 0.0, 1.0, 0.0
                    q20, q21, q22 = 0.0, 0.0, 1.0
                    dx, dy, dz = qi * ax, qi * ay, qi * az
                else:
                    if abs(qi) > _SINCOS_MAX:
                        s, c = math.sin(qi), math.cos(qi)
                    else:
                        s, c = _sincos(qi)
                    u = 1.0 - c
                    q00 = 1.0 + u * (ax * ax - 1.0)
                    q11 = 1.0 + u * (ay * ay - 1.0)
                    q22 = 1.0 + u * (az * az - 1.0)
                    q01 = -s * az + u * (ax * ay)
                    q10 = s * az + u * (ax * ay)
                    q02 = s * ay + u * (ax * az)
                    q20 = -s * ay + u * (ax * az)
                    q12 = -s * ax + u * (ay * az)
                    q21 = s * ax + u * (ay * az)
                    dx = dy = dz = 0.0
                # R_rel = T_fix Rot(axis, q), p_rel = p_fix + R_fix (q a)
                t0, t1, t2 = T[i, 0, 0], T[i, 0, 1], T[i, 0, 2]
                a00 = t0 * q00 + t1 * q10 + t2 * q20
                a01 = t0 * q01 + t1 * q11 + t2 * q21
                a02 = t0 * q02 + t1 * q12 + t2 * q22
                p0 = T[i, 0, 3] + (t0 * dx + t1 * dy + t2 * dz)
                t0, t1, t2 = T[i, 1, 0], T[i, 1, 1], T[i, 1, 2]
                a10 = t0 * q00 + t1 * q10 + t2 * q20
                a11 = t0 * q01 + t1 * q11 + t2 * q21
                a12 = t0 * q02 + t1 * q12 + t2 * q22
                p1 = T[i, 1, 3] + (t0 * dx + t1 * dy + t2 * dz)
                t0, t1, t2 = T[i, 2, 0], T[i, 2, 1], T[i, 2, 2]
                a20 = t0 * q00 + t1 * q10 + t2 * q20
                a21 = t0 * q01 + t1 * q11 + t2 * q21
                a22 = t0 * q02 + t1 * q12 + t2 * q22
                p2 = T[i, 2, 3] + (t0 * dx + t1 * dy + t2 * dz)
                if i == 0:
                    Rb[0, 0, kk], Rb[0, 1, kk], Rb[0, 2, kk] = a00, a01, a02
                    Rb[0, 3, kk], Rb[0, 4, kk], Rb[0, 5, kk] = a10, a11, a12
                    Rb[0, 6, kk], Rb[0, 7, kk], Rb[0, 8, kk] = a20, a21, a22
                    ob[0, 0, kk], ob[0, 1, kk], ob[0, 2, kk] = p0, p1, p2
                else:
                    for a in range(3):
                        P0 = Rb[i - 1, 3 * a, kk]
                        P1 = Rb[i - 1, 3 * a + 1, kk]
                        P2 = Rb[i - 1, 3 * a + 2, kk]
                        ob[i, a, kk] = ob[i - 1, a, kk] + (P0 * p0 + P1 * p1 + P2 * p2)
                        Rb[i, 3 * a, kk] = P0 * a00 + P1 * a10 + P2 * a20
                        Rb[i, 3 * a + 1, kk] = P0 * a01 + P1 * a11 + P2 * a21
                        Rb[i, 3 * a + 2, kk] = P0 * a02 + P1 * a12 + P2 * a22
                for a in range(3):
                    z[i, a, kk] = (
                        Rb[i, 3 * a, kk] * ax
                        + Rb[i, 3 * a + 1, kk] * ay
                        + Rb[i, 3 * a + 2, kk] * az
                    )
        for l in range(n):
            # Jacobian columns of the origin of link l for joints k <= l, link-l coordinates
            for k in range(l + 1):
                pk = prismatic[k]
                for kk in range(nb):
                    r00, r01, r02 = Rb[l, 0, kk], Rb[l, 1, kk], Rb[l, 2, kk]
                    r10, r11, r12 = Rb[l, 3, kk], Rb[l, 4, kk], Rb[l, 5, kk]
                    r20, r21, r22 = Rb[l, 6, kk], Rb[l, 7, kk], Rb[l, 8, kk]
                    zx, zy, zz = z[k, 0, kk], z[k, 1, kk], z[k, 2, kk]
                    if pk:
                        lx, ly, lz = zx, zy, zz
                        ux = uy = uz = 0.0
                    else:
                        px = ob[l, 0, kk] - ob[k, 0, kk]
                        py = ob[l, 1, kk] - ob[k, 1, kk]
                        pz = ob[l, 2, kk] - ob[k, 2, kk]
                        lx = zy * pz - zz * py
                        ly = zz * px - zx * pz
                        lz = zx * py - zy * px
                        ux, uy, uz = zx, zy, zz
                    v[k, 0, kk] = r00 * lx + r10 * ly + r20 * lz
                    v[k, 1, kk] = r01 * lx + r11 * ly + r21 * lz
                    v[k, 2, kk] = r02 * lx + r12 * ly + r22 * lz
                    w[k, 0, kk] = r00 * ux + r10 * uy + r20 * uz
                    w[k, 1, kk] = r01 * ux + r11 * uy + r21 * uz
                    w[k, 2, kk] = r02 * ux + r12 * uy + r22 * uz
            for kk in range(nb):
                gl[0, kk] = Rb[l, 0, kk] * g[0] + Rb[l, 3, kk] * g[1] + Rb[l, 6, kk] * g[2]
                gl[1, kk] = Rb[l, 1, kk] * g[0] + Rb[l, 4, kk] * g[1] + Rb[l, 7, kk] * g[2]
                gl[2, kk] = Rb[l, 2, kk] * g[0] + Rb[l, 5, kk] * g[1] + Rb[l, 8, kk] * g[2]
            c0 = 10 * l
            # rows of tril M: pair (i, j), j <= i, at i (i + 1) / 2 + j (zero for i > l)
            for i in range(l + 1):
                for j in range(i + 1):
                    row = i * (i + 1) // 2 + j
                    for e in range(10):
                        oc = cols[c0 + e]
                        if oc < 0:
                            continue
                        out = Y[oc, row, b0 : b0 + nb]
                        if e == 0:
                            for kk in range(nb):
                                out[kk] = (
                                    v[i, 0, kk] * v[j, 0, kk]
                                    + v[i, 1, kk] * v[j, 1, kk]
                                    + v[i, 2, kk] * v[j, 2, kk]
                                )
                        elif e <= 3:
                            # (v_i x w_j + v_j x w_i) along axis e - 1
                            a1 = e % 3  # the next two axes after e - 1, cyclically
                            a2 = (e + 1) % 3
                            for kk in range(nb):
                                out[kk] = (
                                    v[i, a1, kk] * w[j, a2, kk] - v[i, a2, kk] * w[j, a1, kk]
                                ) + (v[j, a1, kk] * w[i, a2, kk] - v[j, a2, kk] * w[i, a1, kk])
                        else:
                            # J entries xx, xy, xz, yy, yz, zz: (w_i)_a (w_j)_c, symmetrised
                            a1, a2 = _JPAIR[e - 4, 0], _JPAIR[e - 4, 1]
                            if a1 == a2:
                                for kk in range(nb):
                                    out[kk] = w[i, a1, kk] * w[j, a1, kk]
                            else:
                                for kk in range(nb):
                                    out[kk] = (
                                        w[i, a1, kk] * w[j, a2, kk] + w[i, a2, kk] * w[j, a1, kk]
                                    )
            # rows of g: -m g_l . v_k + h . (w_k x g_l) for k <= l (zero for k > l, and in
            # the inertia columns)
            for k in range(l + 1):
                row = nm + k
                for e in range(4):
                    oc = cols[c0 + e]
                    if oc < 0:
                        continue
                    out = Y[oc, row, b0 : b0 + nb]
                    if e == 0:
                        for kk in range(nb):
                            out[kk] = -(
                                v[k, 0, kk] * gl[0, kk]
                                + v[k, 1, kk] * gl[1, kk]
                                + v[k, 2, kk] * gl[2, kk]
                            )
                    else:
                        a1 = e % 3
                        a2 = (e + 1) % 3
                        for kk in range(nb):
                            out[kk] = w[k, a1, kk] * gl[a2, kk] - w[k, a2, kk] * gl[a1, kk]
    return True


#: ``static_regressor(T, axes, prismatic, g, q, cols, Y) -> ok``
static_regressor = _jit(_static_regressor)
