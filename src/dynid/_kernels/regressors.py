"""Compiled (numba) kernel of the static regressor ``[tril M(q); g(q)]``.

This module imports numba, so it is imported lazily, on the first call of
:func:`dynid.regressors.static.static_regressor` (or of a function built on it) when
:func:`dynid.dynamics.rnea.kernels` finds the compiled kernels (numba installed and
``DYNID_NO_NUMBA`` unset), never by ``import dynid``. The kernel is compiled on its first
call and cached on disk (``cache=True``), with the same compiler options as
:mod:`dynid._kernels.dynamics` (fused multiply-add allowed, no other fast-math flag) and
its sine and cosine (Cephes, :func:`dynid._kernels.dynamics._sincos`).

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

from .chain import IDENTITY, compose, finite, inline, jit, joint, motion
from .layout import C_AXIS, C_PRISMATIC

__all__ = ["BLOCK", "static_regressor"]

#: Samples per block (the length of the inner loops and of the runs written into ``Y``).
BLOCK = 128
#: Axes of the products ``(w_i)_a (w_j)_c`` of the inertia columns Jxx, Jxy, Jxz, Jyy, Jyz, Jzz.
_JPAIR = np.array([[0, 0], [0, 1], [0, 2], [1, 1], [1, 2], [2, 2]], dtype=np.int64)


@inline
def _base_poses(C, q, b0, nb, Rb, ob, z):
    """Base-frame rotation ``Rb``, origin ``ob`` and joint axis ``z`` of every link for the
    samples ``b0 .. b0 + nb`` (sample index last); False if a ``q`` is not finite.

    ``R_l = R_{l-1} R_{l-1,l}``, ``o_l = o_{l-1} + R_{l-1} p_{l-1,l}``.
    """
    n = C.shape[0] - 1
    for kk in range(nb):
        for i in range(n):
            qi = q[(b0 + kk) * n + i]
            if not math.isfinite(qi):
                return False
            ax, ay, az = C[i, C_AXIS], C[i, C_AXIS + 1], C[i, C_AXIS + 2]
            a00, a01, a02, a10, a11, a12, a20, a21, a22, p0, p1, p2 = joint(C, i, qi)
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
                    Rb[i, 3 * a, kk] * ax + Rb[i, 3 * a + 1, kk] * ay + Rb[i, 3 * a + 2, kk] * az
                )
    return True


@inline
def _link_columns(C, l, nb, Rb, ob, z, v, w, gl):
    """Jacobian columns ``v[k]``, ``w[k]`` of the origin of link ``l`` for joints ``k <= l``
    and the gravity ``gl``, all in link-``l`` coordinates, for a block of ``nb`` samples."""
    n = C.shape[0] - 1
    g0, g1, g2 = C[n, 0], C[n, 1], C[n, 2]
    for k in range(l + 1):
        pk = C[k, C_PRISMATIC] != 0.0
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
        gl[0, kk] = Rb[l, 0, kk] * g0 + Rb[l, 3, kk] * g1 + Rb[l, 6, kk] * g2
        gl[1, kk] = Rb[l, 1, kk] * g0 + Rb[l, 4, kk] * g1 + Rb[l, 7, kk] * g2
        gl[2, kk] = Rb[l, 2, kk] * g0 + Rb[l, 5, kk] * g1 + Rb[l, 8, kk] * g2


@inline
def _mass_rows(l, cols, b0, nb, v, w, Y):
    """Link ``l``'s share of the rows of ``tril M``: pair ``(i, j)``, ``j <= i <= l``, at row
    ``i (i + 1) / 2 + j`` (zero for ``i > l``), into the columns ``cols`` of ``Y``."""
    c0 = 10 * l
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
                        out[kk] = (v[i, a1, kk] * w[j, a2, kk] - v[i, a2, kk] * w[j, a1, kk]) + (
                            v[j, a1, kk] * w[i, a2, kk] - v[j, a2, kk] * w[i, a1, kk]
                        )
                else:
                    # J entries xx, xy, xz, yy, yz, zz: (w_i)_a (w_j)_c, symmetrised
                    a1, a2 = _JPAIR[e - 4, 0], _JPAIR[e - 4, 1]
                    if a1 == a2:
                        for kk in range(nb):
                            out[kk] = w[i, a1, kk] * w[j, a1, kk]
                    else:
                        for kk in range(nb):
                            out[kk] = w[i, a1, kk] * w[j, a2, kk] + w[i, a2, kk] * w[j, a1, kk]


@inline
def _gravity_rows(l, nm, cols, b0, nb, v, w, gl, Y):
    """Link ``l``'s share of the rows of ``g``: ``-m g_l . v_k + h . (w_k x g_l)`` for
    ``k <= l`` (zero for ``k > l``, and in the inertia columns), at row ``nm + k``."""
    c0 = 10 * l
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
                        v[k, 0, kk] * gl[0, kk] + v[k, 1, kk] * gl[1, kk] + v[k, 2, kk] * gl[2, kk]
                    )
            else:
                a1 = e % 3
                a2 = (e + 1) % 3
                for kk in range(nb):
                    out[kk] = w[k, a1, kk] * gl[a2, kk] - w[k, a2, kk] * gl[a1, kk]


@jit
def static_regressor(C, q, cols, Y):
    """Static regressor into the zeroed ``Y`` (c, s, B) for q (B n,), columns ``cols``; ``ok``.

    Per block of samples, the sample index innermost (contiguous runs of Y, SIMD): the
    link poses (:func:`_base_poses`), then per link its Jacobian columns
    (:func:`_link_columns`) and its share of the rows of ``tril M`` (:func:`_mass_rows`)
    and ``g`` (:func:`_gravity_rows`).
    """
    n = C.shape[0] - 1
    B = q.shape[0] // n
    nm = n * (n + 1) // 2
    Rb = np.empty((n, 9, BLOCK))  # rotation of each link in the base frame, row-major
    ob = np.empty((n, 3, BLOCK))  # origin of each link in the base frame
    z = np.empty((n, 3, BLOCK))  # joint axes in the base frame
    v = np.empty((n, 3, BLOCK))  # velocity of the origin of link l, unit rate of joint k
    w = np.empty((n, 3, BLOCK))  # angular velocity of link l, unit rate of joint k
    gl = np.empty((3, BLOCK))  # gravity in link-l coordinates
    for b0 in range(0, B, BLOCK):
        nb = min(BLOCK, B - b0)
        if not _base_poses(C, q, b0, nb, Rb, ob, z):
            return False
        for l in range(n):
            _link_columns(C, l, nb, Rb, ob, z, v, w, gl)
            _mass_rows(l, cols, b0, nb, v, w, Y)
            _gravity_rows(l, nm, cols, b0, nb, v, w, gl, Y)
    return True


@jit
def torque_regressor(C, q, dq, ddq, cols, Y):
    """Torque regressor into ``Y`` (B, n, width) for q, dq, ddq (B n,); returns ``ok``.

    Standard parameter ``j`` goes to column ``cols[j]`` of ``Y`` (``-1``: skipped); the
    other columns of ``Y`` are left as they are. Every entry of a written column is
    written (zeros where link ``l`` comes before joint ``i``).
    """
    n = C.shape[0] - 1
    B = q.shape[0] // n
    WF = np.empty((n, 3, 4))  # force columns (m, mc) of link l's wrench, base frame
    WN = np.empty((n, 3, 10))  # moment columns about the base origin, base frame
    A = np.empty((n, 6))  # joint i's projection of a base-frame wrench [F; N]
    for b in range(B):
        o = b * n
        if not (finite(q, o, n) and finite(dq, o, n) and finite(ddq, o, n)):
            return False
        P = IDENTITY
        wx = wy = wz = 0.0
        dwx = dwy = dwz = 0.0
        ax0, ay0, az0 = -C[n, 0], -C[n, 1], -C[n, 2]
        for i in range(n):
            T = joint(C, i, q[o + i])
            ex, ey, ez = C[i, C_AXIS], C[i, C_AXIS + 1], C[i, C_AXIS + 2]
            M = motion(
                T, (wx, wy, wz), (dwx, dwy, dwz), (ax0, ay0, az0), ex, ey, ez,
                C[i, C_PRISMATIC], dq[o + i], ddq[o + i],
            )  # fmt: skip
            wx, wy, wz, dwx, dwy, dwz, ax0, ay0, az0 = M
            P = compose(P, T)  # base pose of link i + 1
            R00, R01, R02, R10, R11, R12, R20, R21, R22, ox, oy, oz = P
            # joint axis z in the base frame and the projection [F; N] -> tau_i
            zx = R00 * ex + R01 * ey + R02 * ez
            zy = R10 * ex + R11 * ey + R12 * ez
            zz = R20 * ex + R21 * ey + R22 * ez
            if C[i, C_PRISMATIC] != 0.0:
                A[i, 0], A[i, 1], A[i, 2] = zx, zy, zz
                A[i, 3], A[i, 4], A[i, 5] = 0.0, 0.0, 0.0
            else:
                A[i, 0] = oy * zz - oz * zy
                A[i, 1] = oz * zx - ox * zz
                A[i, 2] = ox * zy - oy * zx
                A[i, 3], A[i, 4], A[i, 5] = zx, zy, zz
            # wrench regressor of link i + 1 about its origin, link coordinates:
            # f = m a + (S(dw) + w w^T - |w|^2 E) h, n = -S(a) h + (L(dw) + S(w) L(w)) J
            ww = wx * wx + wy * wy + wz * wz
            F = (
                (ax0, wx * wx - ww, wx * wy - dwz, wx * wz + dwy),
                (ay0, wy * wx + dwz, wy * wy - ww, wy * wz - dwx),
                (az0, wz * wx - dwy, wz * wy + dwx, wz * wz - ww),
            )
            # columns Jxx, Jxy, Jxz, Jyy, Jyz, Jzz: L(dw) + w x L(w), with the columns of
            # L(v): (x,0,0) (y,x,0) (z,0,x) (0,y,0) (0,z,y) (0,0,z)
            N = (
                (0.0, 0.0, az0, -ay0, dwx, dwy - wz * wx, dwz + wx * wy, -wz * wy,
                 wy * wy - wz * wz, wy * wz),
                (0.0, -az0, 0.0, ax0, wz * wx, dwx + wz * wy, wz * wz - wx * wx, dwy,
                 dwz - wx * wy, -wx * wz),
                (0.0, ay0, -ax0, 0.0, -wy * wx, wx * wx - wy * wy, dwx - wy * wz, wx * wy,
                 dwy + wx * wz, dwz),
            )  # fmt: skip
            for c in range(4):
                f0 = R00 * F[0][c] + R01 * F[1][c] + R02 * F[2][c]
                f1 = R10 * F[0][c] + R11 * F[1][c] + R12 * F[2][c]
                f2 = R20 * F[0][c] + R21 * F[1][c] + R22 * F[2][c]
                WF[i, 0, c], WF[i, 1, c], WF[i, 2, c] = f0, f1, f2
                WN[i, 0, c] = oy * f2 - oz * f1
                WN[i, 1, c] = oz * f0 - ox * f2
                WN[i, 2, c] = ox * f1 - oy * f0
            for c in range(1, 10):
                m0 = R00 * N[0][c] + R01 * N[1][c] + R02 * N[2][c]
                m1 = R10 * N[0][c] + R11 * N[1][c] + R12 * N[2][c]
                m2 = R20 * N[0][c] + R21 * N[1][c] + R22 * N[2][c]
                if c < 4:
                    WN[i, 0, c] += m0
                    WN[i, 1, c] += m1
                    WN[i, 2, c] += m2
                else:
                    WN[i, 0, c], WN[i, 1, c], WN[i, 2, c] = m0, m1, m2
        # tau_i = A_i . [F; N] of every link l >= i (links before joint i do not act on it)
        for i in range(n):
            A0, A1, A2, A3, A4, A5 = A[i, 0], A[i, 1], A[i, 2], A[i, 3], A[i, 4], A[i, 5]
            for l in range(n):
                for e in range(10):
                    oc = cols[10 * l + e]
                    if oc < 0:
                        continue
                    if l < i:
                        Y[b, i, oc] = 0.0
                    elif e < 4:
                        Y[b, i, oc] = (A0 * WF[l, 0, e] + A1 * WF[l, 1, e] + A2 * WF[l, 2, e]) + (
                            A3 * WN[l, 0, e] + A4 * WN[l, 1, e] + A5 * WN[l, 2, e]
                        )
                    else:
                        Y[b, i, oc] = A3 * WN[l, 0, e] + A4 * WN[l, 1, e] + A5 * WN[l, 2, e]
    return True
