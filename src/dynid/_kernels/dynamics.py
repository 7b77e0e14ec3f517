"""Compiled (numba) kernels: inverse dynamics, gravity torques and the mass matrix.

Imported lazily, on the first dynamics call (:func:`dynid._kernels.dispatch.compiled`), never by
``import dynid``; compiled once and cached on disk (:func:`dynid._kernels.chain.jit`).

Arguments: ``C``, the robot's packed constants (:func:`dynid._kernels.layout.pack`: joint
transforms, axes, joint types, standard parameters ``phi`` and gravity [m/s^2] in the base
frame). Joint arrays are flat C-contiguous float64, length ``B * n``, sample-major (a
(B, n) array reshaped); ``dq`` and ``ddq`` of :func:`rnea` may also have length ``n``, one
row for every sample. Results go into a flat output array, ``B * n`` (the mass matrices:
any C-contiguous shape, read flat, row-major), which spares the boxing of a new array.
Every kernel checks that its joint inputs are finite and returns ``ok``; with
``ok = False`` the output is unfinished and the caller raises the error that names the
bad entry.

Equations. :func:`rnea` implements the same recursion as the numpy reference path of
:mod:`dynid.dynamics.rnea` (Featherstone, Rigid Body Dynamics Algorithms, 2008, ch. 5):
link velocities and accelerations outward in link coordinates with the base accelerating
at ``-g``, then forces and moments about each link origin inward, from the standard
parameters ``m, h = m c, J`` (about the origin). :func:`mass_matrix` is the
composite-rigid-body algorithm (Featherstone 2008, sec. 6.2) with the spatial inertia of a
link about its origin

.. math:: I_i = \\begin{bmatrix} J_i & [h_i]_\\times \\\\ [h_i]_\\times^T & m_i E \\end{bmatrix}.

Layout. :func:`rnea` works on blocks of ``BLOCK`` samples held in one scratch array
``X[link, row, sample]`` (link 0 the base, link ``n + 1`` a virtual identity link after
the last one); the loop over the samples of a block is innermost, free of branches and
calls, so that the compiler vectorises it (SIMD over samples): its helpers are inlined
(called, they lose the vectorisation: the batch RNEA 2.6 x slower). The scalar recursions
of one sample, :func:`_rnea_sample` and :func:`_crba_sample`, and the few-sample path
:func:`_rnea_few` are compiled on their own and called (:func:`~dynid._kernels.chain.called`),
once for the kernels that share them (the dynamics and the observer kernels compile in
about 20 s of one core, from 24 s inlined; no measurable change in run time). Revolute
and prismatic joints go through the same arithmetic with exact 0/1 selectors (a
prismatic joint has ``sin = 0, cos = 1``, a revolute one no translation), which changes
no rounding.

The joint transform is the chain core's (:mod:`dynid._kernels.chain`), as are the
compiler settings (fused multiply-add only) and the sine and cosine (Cephes, vectorisable);
kernels and numpy path differ by rounding only (the tests hold them to 1e-12 relative).
"""

from __future__ import annotations

import math

import numpy as np

from .chain import (
    IDENTITY,
    angles,
    called,
    compose,
    finite,
    fixed,
    flat_view,
    inline,
    jit,
    joint_at,
    joint_from,
    lean,
    motion,
    stack,
)
from .chain import SINCOS_MAX as _SINCOS_MAX
from .chain import STACK as _STACK
from .chain import sincos as _sincos
from .dense import cholesky, cholesky_solve
from .layout import C_AXIS, C_PHI, C_PRISMATIC, SINGULAR_PIVOT

__all__ = [
    "BLOCK",
    "rnea",
    "gravity_torques",
    "mass_matrix",
    "rnea_one",
    "gravity_torques_one",
    "mass_matrix_one",
    "forward_dynamics_one",
]

#: Samples per block of :func:`rnea` (the length of the vectorised inner loop).
BLOCK = 32
#: Fewer samples than this take the scalar recursion (no block scratch to set up).
SMALL = 4

# rows of the scratch array X[link, row, sample] of the block kernel
_Q, _V, _AC, _S, _C = 0, 1, 2, 3, 4  # q, dq, ddq, sin q, cos q of the joint into the link
_R = 5  # R[a][b] of the link in its parent at row _R + 3 a + b
_P = 14  # origin of the link in its parent (3 rows)
_W, _DW, _A = 17, 20, 23  # angular velocity, acceleration, origin acceleration - g (3 rows each)
_F, _N = 26, 29  # force and moment on the link (and its children) about its origin
_TAU = 32
_ROWS = 33


@inline
def inertial(C, i):
    """Link ``i + 1``'s standard parameters ``(m, hx, hy, hz, Jxx, Jxy, Jxz, Jyy, Jyz, Jzz)``."""
    return (
        C[i, C_PHI], C[i, C_PHI + 1], C[i, C_PHI + 2], C[i, C_PHI + 3], C[i, C_PHI + 4],
        C[i, C_PHI + 5], C[i, C_PHI + 6], C[i, C_PHI + 7], C[i, C_PHI + 8], C[i, C_PHI + 9],
    )  # fmt: skip


@inline
def wrench(phi, w, dw, a):
    """Wrench ``(f, n)`` (6 floats) on a link about its origin, link coordinates.

    ``f = m a + dw x h + w x (w x h)``, ``n = J dw + w x (J w) + h x a`` with the link's
    standard parameters ``phi = (m, h = m c, J)`` (:func:`inertial`, J about the origin).
    """
    m, hx, hy, hz, Jxx, Jxy, Jxz, Jyy, Jyz, Jzz = phi
    wx, wy, wz = w
    dwx, dwy, dwz = dw
    a0x, a0y, a0z = a
    ux = wy * hz - wz * hy
    uy = wz * hx - wx * hz
    uz = wx * hy - wy * hx
    jx = Jxx * wx + Jxy * wy + Jxz * wz
    jy = Jxy * wx + Jyy * wy + Jyz * wz
    jz = Jxz * wx + Jyz * wy + Jzz * wz
    return (
        m * a0x + (dwy * hz - dwz * hy) + (wy * uz - wz * uy),
        m * a0y + (dwz * hx - dwx * hz) + (wz * ux - wx * uz),
        m * a0z + (dwx * hy - dwy * hx) + (wx * uy - wy * ux),
        (Jxx * dwx + Jxy * dwy + Jxz * dwz) + (wy * jz - wz * jy) + (hy * a0z - hz * a0y),
        (Jxy * dwx + Jyy * dwy + Jyz * dwz) + (wz * jx - wx * jz) + (hz * a0x - hx * a0z),
        (Jxz * dwx + Jyz * dwy + Jzz * dwz) + (wx * jy - wy * jx) + (hx * a0y - hy * a0x),
    )


@inline
def carry(T, F, N):
    """A link's wrench ``(F, N)`` about its origin carried into its parent (pose ``T``).

    ``(R F, R N + p x R F)``, 6 floats.
    """
    r00, r01, r02, r10, r11, r12, r20, r21, r22, px, py, pz = T
    Fx, Fy, Fz = F
    Nx, Ny, Nz = N
    RFx = r00 * Fx + r01 * Fy + r02 * Fz
    RFy = r10 * Fx + r11 * Fy + r12 * Fz
    RFz = r20 * Fx + r21 * Fy + r22 * Fz
    RNx = r00 * Nx + r01 * Ny + r02 * Nz
    RNy = r10 * Nx + r11 * Ny + r12 * Nz
    RNz = r20 * Nx + r21 * Ny + r22 * Nz
    return (
        RFx,
        RFy,
        RFz,
        RNx + (py * RFz - pz * RFy),
        RNy + (pz * RFx - px * RFz),
        RNz + (px * RFy - py * RFx),
    )


@called
def _rnea_sample(C, A, dq, ddq, oq, ov, oa, tau, S):
    """RNEA of one sample into ``tau[oq : oq + n]``; scratch ``S`` (n, 21).

    The recursion of the block kernel in scalar form, for few samples (no block scratch):
    ``A`` the :func:`~dynid._kernels.chain.angles` of ``q``, the rates
    ``dq[ov : ov + n]``, the accelerations ``ddq[oa : oa + n]``.
    """
    n = C.shape[0] - 1
    w = (0.0, 0.0, 0.0)
    dw = (0.0, 0.0, 0.0)
    a = (-C[n, 0], -C[n, 1], -C[n, 2])
    for i in range(n):
        T = joint_at(C, i, A)
        ep = C[i, C_PRISMATIC]
        ex, ey, ez = C[i, C_AXIS], C[i, C_AXIS + 1], C[i, C_AXIS + 2]
        M = motion(T, w, dw, a, ex, ey, ez, ep, dq[ov + i], ddq[oa + i])
        w, dw, a = (M[0], M[1], M[2]), (M[3], M[4], M[5]), (M[6], M[7], M[8])
        for k in range(12):
            S[i, k] = T[k]
        for k in range(9):
            S[i, 12 + k] = M[k]
    F = (0.0, 0.0, 0.0)
    N = (0.0, 0.0, 0.0)
    for i in range(n - 1, -1, -1):
        f = wrench(
            inertial(C, i), (S[i, 12], S[i, 13], S[i, 14]), (S[i, 15], S[i, 16], S[i, 17]),
            (S[i, 18], S[i, 19], S[i, 20]),
        )  # fmt: skip
        if i < n - 1:
            Tc = (
                S[i + 1, 0], S[i + 1, 1], S[i + 1, 2], S[i + 1, 3], S[i + 1, 4], S[i + 1, 5],
                S[i + 1, 6], S[i + 1, 7], S[i + 1, 8], S[i + 1, 9], S[i + 1, 10], S[i + 1, 11],
            )  # fmt: skip
            W = carry(Tc, F, N)
            F = (f[0] + W[0], f[1] + W[1], f[2] + W[2])
            N = (f[3] + W[3], f[4] + W[4], f[5] + W[5])
        else:
            F, N = (f[0], f[1], f[2]), (f[3], f[4], f[5])
        ex, ey, ez = C[i, C_AXIS], C[i, C_AXIS + 1], C[i, C_AXIS + 2]
        if C[i, C_PRISMATIC] != 0.0:
            tau[oq + i] = F[0] * ex + F[1] * ey + F[2] * ez
        else:
            tau[oq + i] = N[0] * ex + N[1] * ey + N[2] * ez


@called
def _rnea_few(C, q, dq, ddq, tau, sv, sa):
    """:func:`rnea` for a few samples: the scalar recursion per sample, no block scratch."""
    n = C.shape[0] - 1
    B = q.shape[0] // n
    S = np.empty((n, 21))
    A = np.empty((3, n))
    for b in range(B):
        ov, oa = b * n if sv else 0, b * n if sa else 0
        ok = angles(C, q, b * n, A)
        if not (ok and finite(dq, ov, n) and finite(ddq, oa, n)):
            return False
        _rnea_sample(C, A, dq, ddq, b * n, ov, oa, tau, S)
    return True


@inline
def _block_scratch(C):
    """The block scratch ``X`` (n + 2, rows, BLOCK) with the base and the virtual last link.

    The base (link 0) is at rest, accelerating at ``-g``; the virtual link ``n + 1`` is the
    identity and carries no wrench. The block length is a compile-time constant, so the
    row stride of X is known and the sample loops vectorise without run-time aliasing
    checks.
    """
    n = C.shape[0] - 1
    X = np.empty((n + 2, _ROWS, BLOCK))
    X[0, _W : _A + 3] = 0.0
    X[0, _A] = -C[n, 0]
    X[0, _A + 1] = -C[n, 1]
    X[0, _A + 2] = -C[n, 2]
    X[n + 1] = 0.0
    X[n + 1, _R] = 1.0
    X[n + 1, _R + 4] = 1.0
    X[n + 1, _R + 8] = 1.0
    return X


@inline
def _load_block(C, q, dq, ddq, sv, sa, b0, nb, X):
    """Samples ``b0 .. b0 + nb`` into ``X`` (q, dq, ddq, sin q, cos q); False if not finite."""
    n = C.shape[0] - 1
    big = False
    for k in range(nb):
        b = b0 + k
        for i in range(n):
            x = q[b * n + i]
            v = dq[b * n + i if sv else i]
            a = ddq[b * n + i if sa else i]
            if not (math.isfinite(x) and math.isfinite(v) and math.isfinite(a)):
                return False
            big = big or abs(x) > _SINCOS_MAX
            X[i + 1, _Q, k] = x
            X[i + 1, _V, k] = v
            X[i + 1, _AC, k] = a
    for l in range(1, n + 1):
        if C[l - 1, C_PRISMATIC] != 0.0:
            for k in range(nb):
                X[l, _S, k] = 0.0
                X[l, _C, k] = 1.0
        elif big:
            for k in range(nb):
                X[l, _S, k] = math.sin(X[l, _Q, k])
                X[l, _C, k] = math.cos(X[l, _Q, k])
        else:
            for k in range(nb):
                s, c = _sincos(X[l, _Q, k])
                X[l, _S, k] = s
                X[l, _C, k] = c
    return True


@inline
def _outward_block(C, nb, X):
    """Outward pass over a block: link ``l``'s pose in its parent and its motion."""
    n = C.shape[0] - 1
    for l in range(1, n + 1):
        i = l - 1
        ax, ay, az = C[i, C_AXIS], C[i, C_AXIS + 1], C[i, C_AXIS + 2]
        ep = C[i, C_PRISMATIC]
        F = fixed(C, i)  # constants out of the sample loop (it vectorises)
        for k in range(nb):
            # pose of link l in link l - 1 (the chain core's joint transform)
            r00, r01, r02, r10, r11, r12, r20, r21, r22, px, py, pz = joint_from(
                F, X[l, _S, k], X[l, _C, k], ep * X[l, _Q, k]
            )
            X[l, _R, k] = r00
            X[l, _R + 1, k] = r01
            X[l, _R + 2, k] = r02
            X[l, _R + 3, k] = r10
            X[l, _R + 4, k] = r11
            X[l, _R + 5, k] = r12
            X[l, _R + 6, k] = r20
            X[l, _R + 7, k] = r21
            X[l, _R + 8, k] = r22
            X[l, _P, k] = px
            X[l, _P + 1, k] = py
            X[l, _P + 2, k] = pz
            M = motion(
                (r00, r01, r02, r10, r11, r12, r20, r21, r22, px, py, pz),
                (X[i, _W, k], X[i, _W + 1, k], X[i, _W + 2, k]),
                (X[i, _DW, k], X[i, _DW + 1, k], X[i, _DW + 2, k]),
                (X[i, _A, k], X[i, _A + 1, k], X[i, _A + 2, k]),
                ax,
                ay,
                az,
                ep,
                X[l, _V, k],
                X[l, _AC, k],
            )
            X[l, _W, k] = M[0]
            X[l, _W + 1, k] = M[1]
            X[l, _W + 2, k] = M[2]
            X[l, _DW, k] = M[3]
            X[l, _DW + 1, k] = M[4]
            X[l, _DW + 2, k] = M[5]
            X[l, _A, k] = M[6]
            X[l, _A + 1, k] = M[7]
            X[l, _A + 2, k] = M[8]


@inline
def _inward_block(C, nb, X):
    """Inward pass over a block: the wrench on link ``l`` and its children, about origin
    ``l`` in link-``l`` coordinates, and the joint torque."""
    n = C.shape[0] - 1
    for l in range(n, 0, -1):
        i = l - 1
        ax, ay, az = C[i, C_AXIS], C[i, C_AXIS + 1], C[i, C_AXIS + 2]
        ep = C[i, C_PRISMATIC]
        er = 1.0 - ep
        c = l + 1
        phi = inertial(C, i)  # constants out of the sample loop (it vectorises)
        for k in range(nb):
            f = wrench(
                phi,
                (X[l, _W, k], X[l, _W + 1, k], X[l, _W + 2, k]),
                (X[l, _DW, k], X[l, _DW + 1, k], X[l, _DW + 2, k]),
                (X[l, _A, k], X[l, _A + 1, k], X[l, _A + 2, k]),
            )
            # plus the child's wrench carried into this frame
            W = carry(
                (
                    X[c, _R, k], X[c, _R + 1, k], X[c, _R + 2, k],
                    X[c, _R + 3, k], X[c, _R + 4, k], X[c, _R + 5, k],
                    X[c, _R + 6, k], X[c, _R + 7, k], X[c, _R + 8, k],
                    X[c, _P, k], X[c, _P + 1, k], X[c, _P + 2, k],
                ),
                (X[c, _F, k], X[c, _F + 1, k], X[c, _F + 2, k]),
                (X[c, _N, k], X[c, _N + 1, k], X[c, _N + 2, k]),
            )  # fmt: skip
            Fx, Fy, Fz = f[0] + W[0], f[1] + W[1], f[2] + W[2]
            Nx, Ny, Nz = f[3] + W[3], f[4] + W[4], f[5] + W[5]
            X[l, _F, k] = Fx
            X[l, _F + 1, k] = Fy
            X[l, _F + 2, k] = Fz
            X[l, _N, k] = Nx
            X[l, _N + 1, k] = Ny
            X[l, _N + 2, k] = Nz
            X[l, _TAU, k] = ep * (Fx * ax + Fy * ay + Fz * az) + er * (Nx * ax + Ny * ay + Nz * az)


@jit
def rnea(C, q, dq, ddq, tau):
    """Joint torques into ``tau`` (B n,) for q (B n,), dq and ddq (B n,) or (n,); ``ok``.

    A few samples: :func:`_rnea_few`; more: blocks of ``BLOCK`` samples in the scratch
    ``X`` (:func:`_block_scratch`): :func:`_load_block`, :func:`_outward_block`,
    :func:`_inward_block`, then the torques out.
    """
    n = C.shape[0] - 1
    B = q.shape[0] // n
    sv, sa = dq.shape[0] == q.shape[0], ddq.shape[0] == q.shape[0]  # else one row for all
    if B < SMALL:
        return _rnea_few(C, q, dq, ddq, tau, sv, sa)
    X = _block_scratch(C)
    for b0 in range(0, B, BLOCK):
        nb = min(BLOCK, B - b0)
        if not _load_block(C, q, dq, ddq, sv, sa, b0, nb, X):
            return False
        _outward_block(C, nb, X)
        _inward_block(C, nb, X)
        for k in range(nb):
            for i in range(n):
                tau[(b0 + k) * n + i] = X[i + 1, _TAU, k]
    return True


@lean
def rnea_one(C, q, dq, ddq, tau):
    """:func:`rnea` of one sample (q, dq, ddq of length n, any strides), scratch on the stack.

    Returns ``ok``; False also for a robot too long for the stack scratch (the caller then
    takes :func:`rnea`).
    """
    n = C.shape[0] - 1
    if n * 21 > _STACK:
        return False
    A = stack(3, n)
    if not (angles(C, q, 0, A) and finite(dq, 0, n) and finite(ddq, 0, n)):
        return False
    _rnea_sample(C, A, dq, ddq, 0, 0, 0, tau, stack(n, 21))
    return True


@inline
def _gravity_sample(C, A, o, tau, S):
    """Gravity torques of a sample into ``tau[o : o + n]``; scratch S (n, 9).

    ``A``: the :func:`~dynid._kernels.chain.angles` of the sample's ``q``.

    From the potential energy rather than a full RNEA (the velocities are zero): with
    ``G = -g``, ``o_i``, ``z_i`` the origin and axis of joint i in the base frame and the
    suffix sums ``M_i = sum_{l >= i} m_l``, ``S_i = sum_{l >= i} m_l p_l`` (``m_l p_l =
    m_l o_l + R_l h_l``, the first moment of link l about the base origin),
    ``tau_i = z_i . ((S_i - M_i o_i) x G)`` for a revolute joint and ``z_i . (M_i G)`` for a
    prismatic one (Siciliano et al., *Robotics*, 2009, sec. 7.1.2).
    """
    n = C.shape[0] - 1
    Gx, Gy, Gz = -C[n, 0], -C[n, 1], -C[n, 2]
    P = IDENTITY
    for i in range(n):
        P = compose(P, joint_at(C, i, A))
        r00, r01, r02, r10, r11, r12, r20, r21, r22, ox, oy, oz = P
        ex, ey, ez = C[i, C_AXIS], C[i, C_AXIS + 1], C[i, C_AXIS + 2]
        m = C[i, C_PHI]
        hx, hy, hz = C[i, C_PHI + 1], C[i, C_PHI + 2], C[i, C_PHI + 3]
        S[i, 0], S[i, 1], S[i, 2] = ox, oy, oz
        S[i, 3] = r00 * ex + r01 * ey + r02 * ez
        S[i, 4] = r10 * ex + r11 * ey + r12 * ez
        S[i, 5] = r20 * ex + r21 * ey + r22 * ez
        S[i, 6] = m * ox + (r00 * hx + r01 * hy + r02 * hz)
        S[i, 7] = m * oy + (r10 * hx + r11 * hy + r12 * hz)
        S[i, 8] = m * oz + (r20 * hx + r21 * hy + r22 * hz)
    M = Sx = Sy = Sz = 0.0
    for i in range(n - 1, -1, -1):
        M += C[i, C_PHI]
        Sx += S[i, 6]
        Sy += S[i, 7]
        Sz += S[i, 8]
        zx, zy, zz = S[i, 3], S[i, 4], S[i, 5]
        if C[i, C_PRISMATIC] != 0.0:
            tau[o + i] = M * (zx * Gx + zy * Gy + zz * Gz)
        else:
            rx, ry, rz = Sx - M * S[i, 0], Sy - M * S[i, 1], Sz - M * S[i, 2]
            tau[o + i] = (
                zx * (ry * Gz - rz * Gy) + zy * (rz * Gx - rx * Gz) + zz * (rx * Gy - ry * Gx)
            )


@jit
def gravity_torques(C, q, tau):
    """Gravity torques into ``tau`` (B n,) for q (B n,); returns ``ok``.

    Many samples: :func:`rnea` at rest (vectorised over samples); a few: from the potential
    energy (:func:`_gravity_sample`).
    """
    n = C.shape[0] - 1
    B = q.shape[0] // n
    if B >= SMALL:  # many samples: the vectorised RNEA block kernel at rest is faster
        zero = np.zeros(n)
        return rnea(C, q, zero, zero, tau)
    S = np.empty((n, 9))
    A = np.empty((3, n))
    for b in range(B):
        if not angles(C, q, b * n, A):
            return False
        _gravity_sample(C, A, b * n, tau, S)
    return True


@lean
def gravity_torques_one(C, q, tau):
    """:func:`gravity_torques` of one sample (q of length n, any strides); ``ok``.

    False also for a robot too long for the stack scratch (the caller then takes
    :func:`gravity_torques`).
    """
    n = C.shape[0] - 1
    if n * 9 > _STACK:
        return False
    A = stack(3, n)
    if not angles(C, q, 0, A):
        return False
    _gravity_sample(C, A, 0, tau, stack(n, 9))
    return True


@called
def _crba_sample(C, A, o, M, S):
    """Mass matrix of a sample into ``M[o n : (o + n) n]`` (flat, row-major).

    Composite-rigid-body algorithm; ``A`` the :func:`~dynid._kernels.chain.angles` of
    the sample's ``q``, scratch S (n, 12) for the joint poses.
    """
    n = C.shape[0] - 1
    for i in range(n):
        T = joint_at(C, i, A)
        for k in range(12):
            S[i, k] = T[k]
    # composite inertia (mc, h, J) of links i.. about origin i, link-i axes
    mc = 0.0
    hx = hy = hz = 0.0
    Jxx = Jxy = Jxz = Jyy = Jyz = Jzz = 0.0
    for i in range(n - 1, -1, -1):
        if i < n - 1:
            # carry the composite from frame i + 1 into frame i (u = R h):
            # h' = u + m p,  J' = R J R^T + m (p.p E - p p^T) + 2 (p.u) E - u p^T - p u^T
            k = i + 1
            r00, r01, r02 = S[k, 0], S[k, 1], S[k, 2]
            r10, r11, r12 = S[k, 3], S[k, 4], S[k, 5]
            r20, r21, r22 = S[k, 6], S[k, 7], S[k, 8]
            px, py, pz = S[k, 9], S[k, 10], S[k, 11]
            ux = r00 * hx + r01 * hy + r02 * hz
            uy = r10 * hx + r11 * hy + r12 * hz
            uz = r20 * hx + r21 * hy + r22 * hz
            # S = J R^T, then R S
            s00 = Jxx * r00 + Jxy * r01 + Jxz * r02
            s10 = Jxy * r00 + Jyy * r01 + Jyz * r02
            s20 = Jxz * r00 + Jyz * r01 + Jzz * r02
            s01 = Jxx * r10 + Jxy * r11 + Jxz * r12
            s11 = Jxy * r10 + Jyy * r11 + Jyz * r12
            s21 = Jxz * r10 + Jyz * r11 + Jzz * r12
            s02 = Jxx * r20 + Jxy * r21 + Jxz * r22
            s12 = Jxy * r20 + Jyy * r21 + Jyz * r22
            s22 = Jxz * r20 + Jyz * r21 + Jzz * r22
            pp = px * px + py * py + pz * pz
            pu2 = 2.0 * (px * ux + py * uy + pz * uz)
            nxx = r00 * s00 + r01 * s10 + r02 * s20 + mc * (pp - px * px) + pu2 - 2.0 * ux * px
            nxy = r00 * s01 + r01 * s11 + r02 * s21 - mc * px * py - ux * py - px * uy
            nxz = r00 * s02 + r01 * s12 + r02 * s22 - mc * px * pz - ux * pz - px * uz
            nyy = r10 * s01 + r11 * s11 + r12 * s21 + mc * (pp - py * py) + pu2 - 2.0 * uy * py
            nyz = r10 * s02 + r11 * s12 + r12 * s22 - mc * py * pz - uy * pz - py * uz
            nzz = r20 * s02 + r21 * s12 + r22 * s22 + mc * (pp - pz * pz) + pu2 - 2.0 * uz * pz
            hx, hy, hz = ux + mc * px, uy + mc * py, uz + mc * pz
            Jxx, Jxy, Jxz, Jyy, Jyz, Jzz = nxx, nxy, nxz, nyy, nyz, nzz
        mc += C[i, C_PHI]
        hx += C[i, C_PHI + 1]
        hy += C[i, C_PHI + 2]
        hz += C[i, C_PHI + 3]
        Jxx += C[i, C_PHI + 4]
        Jxy += C[i, C_PHI + 5]
        Jxz += C[i, C_PHI + 6]
        Jyy += C[i, C_PHI + 7]
        Jyz += C[i, C_PHI + 8]
        Jzz += C[i, C_PHI + 9]
        # wrench (moment N about origin i, force F) of the composite for unit motion of joint i
        ax, ay, az = C[i, C_AXIS], C[i, C_AXIS + 1], C[i, C_AXIS + 2]
        if C[i, C_PRISMATIC] != 0.0:  # F = m a, N = h x a
            Fx, Fy, Fz = mc * ax, mc * ay, mc * az
            Nx = hy * az - hz * ay
            Ny = hz * ax - hx * az
            Nz = hx * ay - hy * ax
        else:  # N = J a, F = a x h
            Nx = Jxx * ax + Jxy * ay + Jxz * az
            Ny = Jxy * ax + Jyy * ay + Jyz * az
            Nz = Jxz * ax + Jyz * ay + Jzz * az
            Fx = ay * hz - az * hy
            Fy = az * hx - ax * hz
            Fz = ax * hy - ay * hx
        j = i
        while True:
            bx, by, bz = C[j, C_AXIS], C[j, C_AXIS + 1], C[j, C_AXIS + 2]
            if C[j, C_PRISMATIC] != 0.0:
                e = Fx * bx + Fy * by + Fz * bz
            else:
                e = Nx * bx + Ny * by + Nz * bz
            M[(o + j) * n + i] = e
            M[(o + i) * n + j] = e
            if j == 0:
                break
            # the wrench from frame j into frame j - 1
            W = carry(
                (
                    S[j, 0], S[j, 1], S[j, 2], S[j, 3], S[j, 4], S[j, 5],
                    S[j, 6], S[j, 7], S[j, 8], S[j, 9], S[j, 10], S[j, 11],
                ),
                (Fx, Fy, Fz),
                (Nx, Ny, Nz),
            )  # fmt: skip
            Fx, Fy, Fz, Nx, Ny, Nz = W
            j -= 1


@jit
def mass_matrix(C, q, M):
    """Mass matrices into ``M`` (B n n,) for q (B n,), composite-rigid-body; returns ``ok``."""
    M = M.reshape(M.size)
    n = C.shape[0] - 1
    B = q.shape[0] // n
    S = np.empty((n, 12))
    A = np.empty((3, n))
    for b in range(B):
        if not angles(C, q, b * n, A):
            return False
        _crba_sample(C, A, b * n, M, S)
    return True


@lean
def mass_matrix_one(C, q, M):
    """:func:`mass_matrix` of one sample (q of length n, any strides, M (n, n)); ``ok``.

    False also for a robot too long for the stack scratch (the caller then takes
    :func:`mass_matrix`).
    """
    n = C.shape[0] - 1
    if n * 12 > _STACK:
        return False
    A = stack(3, n)
    if not angles(C, q, 0, A):
        return False
    _crba_sample(C, A, 0, flat_view(M), stack(n, 12))
    return True


@lean
def forward_dynamics_one(C, q, dq, tau, ddq):
    """Accelerations ``M^-1 (tau - rnea(q, dq, 0))`` of one sample into ``ddq``; ``ok``.

    The bias (RNEA at zero acceleration) and the composite-rigid-body ``M`` share the
    sample's sines and cosines; ``M`` is solved by its Cholesky factor. False also when
    ``M`` is not positive definite or singular to rounding (a Cholesky pivot^2 below
    ``SINGULAR_PIVOT`` of its diagonal; the caller's general path then reports it), or
    the robot is too long for the stack scratch.
    """
    n = C.shape[0] - 1
    if n * 21 > _STACK or n * n > _STACK:
        return False
    A = stack(3, n)
    if not (angles(C, q, 0, A) and finite(dq, 0, n) and finite(tau, 0, n)):
        return False
    W = stack(2, n)
    zero, bias = W[0], W[1]
    for i in range(n):
        zero[i] = 0.0
    S = stack(n, 21)
    _rnea_sample(C, A, dq, zero, 0, 0, 0, bias, S)
    M = stack(n, n)
    _crba_sample(C, A, 0, flat_view(M), S)
    L = stack(n, n)
    if not cholesky(M, n, 0.0, L):
        return False
    for j in range(n):  # singular to rounding: the caller's general path reports it
        if L[j, j] * L[j, j] < SINGULAR_PIVOT * M[j, j]:
            return False
    for i in range(n):
        bias[i] = tau[i] - bias[i]
    cholesky_solve(L, n, bias, ddq)
    return True
