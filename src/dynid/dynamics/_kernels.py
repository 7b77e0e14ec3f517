"""Compiled (numba) kernels: inverse dynamics, gravity torques and the mass matrix.

Imported lazily, on the first dynamics call (:func:`dynid._compiled.kernels`), never by
``import dynid``; compiled once and cached on disk (:func:`dynid.kinematics._chain.jit`).

Arguments: ``C``, the robot's packed constants (:func:`dynid._compiled.pack`: joint
transforms, axes, joint types, standard parameters ``phi`` and gravity [m/s^2] in the base
frame). Joint arrays are C-contiguous float64 read flat, length ``B * n``, sample-major (a
(B, n) array); ``dq`` and ``ddq`` of :func:`rnea` may also have length ``n``, one row for
every sample. Results go into a C-contiguous output array read flat, ``B * n`` (``B * n *
n`` for the mass matrices, row-major), which spares the boxing of a new array on each call.
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
calls, so that the compiler vectorises it (SIMD over samples). Revolute and prismatic
joints go through the same arithmetic with exact 0/1 selectors (a prismatic joint has
``sin = 0, cos = 1``, a revolute one no translation), which changes no rounding.

The joint transform is the chain core's (:mod:`dynid.kinematics._chain`), as are the
compiler settings (fused multiply-add only) and the sine and cosine (Cephes, vectorisable);
kernels and numpy path differ by rounding only (the tests hold them to 1e-12 relative).
"""

from __future__ import annotations

import math

import numpy as np

from .._compiled import C_AXIS, C_PHI, C_PRISMATIC
from ..kinematics._chain import SINCOS_MAX as _SINCOS_MAX
from ..kinematics._chain import jit, joint, joint_sc
from ..kinematics._chain import sincos as _sincos

__all__ = ["BLOCK", "rnea", "gravity_torques", "mass_matrix"]

#: Samples per block of :func:`rnea` (the length of the vectorised inner loop).
BLOCK = 32

# rows of the scratch array X[link, row, sample] of the block kernel
_Q, _V, _AC, _S, _C = 0, 1, 2, 3, 4  # q, dq, ddq, sin q, cos q of the joint into the link
_R = 5  # R[a][b] of the link in its parent at row _R + 3 a + b
_P = 14  # origin of the link in its parent (3 rows)
_W, _DW, _A = 17, 20, 23  # angular velocity, acceleration, origin acceleration - g (3 rows each)
_F, _N = 26, 29  # force and moment on the link (and its children) about its origin
_TAU = 32
_ROWS = 33


@jit
def rnea(C, q, dq, ddq, tau):
    """Joint torques into ``tau`` (B n,) for q (B n,), dq and ddq (B n,) or (n,); ``ok``."""
    q, dq, ddq, tau = (
        q.reshape(q.size),
        dq.reshape(dq.size),
        ddq.reshape(ddq.size),
        tau.reshape(tau.size),
    )
    n = C.shape[0] - 1
    B = q.shape[0] // n
    # the block length is a compile-time constant, so the row stride of X is known and the
    # sample loops vectorise without run-time aliasing checks
    X = np.empty((n + 2, _ROWS, BLOCK))
    sv, sa = dq.shape[0] == q.shape[0], ddq.shape[0] == q.shape[0]  # else one row for all
    # base (link 0): at rest, accelerating at -g; virtual link n + 1: identity, no wrench
    X[0, _W : _A + 3] = 0.0
    X[0, _A] = -C[n, 0]
    X[0, _A + 1] = -C[n, 1]
    X[0, _A + 2] = -C[n, 2]
    X[n + 1] = 0.0
    X[n + 1, _R] = 1.0
    X[n + 1, _R + 4] = 1.0
    X[n + 1, _R + 8] = 1.0
    for b0 in range(0, B, BLOCK):
        nb = min(BLOCK, B - b0)
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
        # outward pass: link l from its parent l - 1
        for l in range(1, n + 1):
            i = l - 1
            ax, ay, az = C[i, C_AXIS], C[i, C_AXIS + 1], C[i, C_AXIS + 2]
            ep = C[i, C_PRISMATIC]
            er = 1.0 - ep
            for k in range(nb):
                # pose of link l in link l - 1 (the chain core's joint transform)
                r00, r01, r02, r10, r11, r12, r20, r21, r22, px, py, pz = joint_sc(
                    C, i, X[l, _S, k], X[l, _C, k], ep * X[l, _Q, k]
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
                wx, wy, wz = X[i, _W, k], X[i, _W + 1, k], X[i, _W + 2, k]
                dwx, dwy, dwz = X[i, _DW, k], X[i, _DW + 1, k], X[i, _DW + 2, k]
                # acceleration of the origin, parent coordinates: a0 + dw0 x p + w0 x (w0 x p)
                ux = wy * pz - wz * py
                uy = wz * px - wx * pz
                uz = wx * py - wy * px
                bx = X[i, _A, k] + (dwy * pz - dwz * py) + (wy * uz - wz * uy)
                by = X[i, _A + 1, k] + (dwz * px - dwx * pz) + (wz * ux - wx * uz)
                bz = X[i, _A + 2, k] + (dwx * py - dwy * px) + (wx * uy - wy * ux)
                # into link coordinates: R^T
                apx = r00 * bx + r10 * by + r20 * bz
                apy = r01 * bx + r11 * by + r21 * bz
                apz = r02 * bx + r12 * by + r22 * bz
                wpx = r00 * wx + r10 * wy + r20 * wz
                wpy = r01 * wx + r11 * wy + r21 * wz
                wpz = r02 * wx + r12 * wy + r22 * wz
                dpx = r00 * dwx + r10 * dwy + r20 * dwz
                dpy = r01 * dwx + r11 * dwy + r21 * dwz
                dpz = r02 * dwx + r12 * dwy + r22 * dwz
                vi, ai = X[l, _V, k], X[l, _AC, k]
                vx, vy, vz = vi * ax, vi * ay, vi * az
                cx = wpy * vz - wpz * vy
                cy = wpz * vx - wpx * vz
                cz = wpx * vy - wpy * vx
                # revolute: w += dq a, dw += w x dq a + ddq a; prismatic: a += 2 w x dq a + ddq a
                X[l, _W, k] = wpx + er * vx
                X[l, _W + 1, k] = wpy + er * vy
                X[l, _W + 2, k] = wpz + er * vz
                X[l, _DW, k] = dpx + er * (cx + ai * ax)
                X[l, _DW + 1, k] = dpy + er * (cy + ai * ay)
                X[l, _DW + 2, k] = dpz + er * (cz + ai * az)
                X[l, _A, k] = apx + ep * (2.0 * cx + ai * ax)
                X[l, _A + 1, k] = apy + ep * (2.0 * cy + ai * ay)
                X[l, _A + 2, k] = apz + ep * (2.0 * cz + ai * az)
        # inward pass: wrench on link l and its children, about origin l, link-l coordinates
        for l in range(n, 0, -1):
            i = l - 1
            m = C[i, C_PHI]
            hx, hy, hz = C[i, C_PHI + 1], C[i, C_PHI + 2], C[i, C_PHI + 3]
            Jxx, Jxy, Jxz = C[i, C_PHI + 4], C[i, C_PHI + 5], C[i, C_PHI + 6]
            Jyy, Jyz, Jzz = C[i, C_PHI + 7], C[i, C_PHI + 8], C[i, C_PHI + 9]
            ax, ay, az = C[i, C_AXIS], C[i, C_AXIS + 1], C[i, C_AXIS + 2]
            ep = C[i, C_PRISMATIC]
            er = 1.0 - ep
            c = l + 1
            for k in range(nb):
                wx, wy, wz = X[l, _W, k], X[l, _W + 1, k], X[l, _W + 2, k]
                dwx, dwy, dwz = X[l, _DW, k], X[l, _DW + 1, k], X[l, _DW + 2, k]
                a0x, a0y, a0z = X[l, _A, k], X[l, _A + 1, k], X[l, _A + 2, k]
                # f = m a + dw x h + w x (w x h)
                ux = wy * hz - wz * hy
                uy = wz * hx - wx * hz
                uz = wx * hy - wy * hx
                fx = m * a0x + (dwy * hz - dwz * hy) + (wy * uz - wz * uy)
                fy = m * a0y + (dwz * hx - dwx * hz) + (wz * ux - wx * uz)
                fz = m * a0z + (dwx * hy - dwy * hx) + (wx * uy - wy * ux)
                # n = J dw + w x (J w) + h x a
                jx = Jxx * wx + Jxy * wy + Jxz * wz
                jy = Jxy * wx + Jyy * wy + Jyz * wz
                jz = Jxz * wx + Jyz * wy + Jzz * wz
                nx = (
                    (Jxx * dwx + Jxy * dwy + Jxz * dwz)
                    + (wy * jz - wz * jy)
                    + (hy * a0z - hz * a0y)
                )
                ny = (
                    (Jxy * dwx + Jyy * dwy + Jyz * dwz)
                    + (wz * jx - wx * jz)
                    + (hz * a0x - hx * a0z)
                )
                nz = (
                    (Jxz * dwx + Jyz * dwy + Jzz * dwz)
                    + (wx * jy - wy * jx)
                    + (hx * a0y - hy * a0x)
                )
                # plus the child's wrench carried into this frame: R F, R N + p x R F
                r00, r01, r02 = X[c, _R, k], X[c, _R + 1, k], X[c, _R + 2, k]
                r10, r11, r12 = X[c, _R + 3, k], X[c, _R + 4, k], X[c, _R + 5, k]
                r20, r21, r22 = X[c, _R + 6, k], X[c, _R + 7, k], X[c, _R + 8, k]
                px, py, pz = X[c, _P, k], X[c, _P + 1, k], X[c, _P + 2, k]
                Fx, Fy, Fz = X[c, _F, k], X[c, _F + 1, k], X[c, _F + 2, k]
                Nx, Ny, Nz = X[c, _N, k], X[c, _N + 1, k], X[c, _N + 2, k]
                RFx = r00 * Fx + r01 * Fy + r02 * Fz
                RFy = r10 * Fx + r11 * Fy + r12 * Fz
                RFz = r20 * Fx + r21 * Fy + r22 * Fz
                RNx = r00 * Nx + r01 * Ny + r02 * Nz
                RNy = r10 * Nx + r11 * Ny + r12 * Nz
                RNz = r20 * Nx + r21 * Ny + r22 * Nz
                Nx = nx + RNx + (py * RFz - pz * RFy)
                Ny = ny + RNy + (pz * RFx - px * RFz)
                Nz = nz + RNz + (px * RFy - py * RFx)
                Fx, Fy, Fz = fx + RFx, fy + RFy, fz + RFz
                X[l, _F, k] = Fx
                X[l, _F + 1, k] = Fy
                X[l, _F + 2, k] = Fz
                X[l, _N, k] = Nx
                X[l, _N + 1, k] = Ny
                X[l, _N + 2, k] = Nz
                X[l, _TAU, k] = ep * (Fx * ax + Fy * ay + Fz * az) + er * (
                    Nx * ax + Ny * ay + Nz * az
                )
        for k in range(nb):
            for i in range(n):
                tau[(b0 + k) * n + i] = X[i + 1, _TAU, k]
    return True


@jit
def gravity_torques(C, q, tau):
    """Gravity torques into ``tau`` (B n,) for q (B n,); returns ``ok``."""
    zero = np.zeros(C.shape[0] - 1)
    return rnea(C, q, zero, zero, tau)


@jit
def mass_matrix(C, q, M):
    """Mass matrices into ``M`` (B n n,) for q (B n,), composite-rigid-body; returns ``ok``."""
    q, M = q.reshape(q.size), M.reshape(M.size)
    n = C.shape[0] - 1
    B = q.shape[0] // n
    R = np.empty((n, 3, 3))
    p = np.empty((n, 3))
    for b in range(B):
        for i in range(n):
            qi = q[b * n + i]
            if not math.isfinite(qi):
                return False
            Ti = joint(C, i, qi)
            for r in range(3):
                R[i, r, 0], R[i, r, 1], R[i, r, 2] = Ti[3 * r], Ti[3 * r + 1], Ti[3 * r + 2]
                p[i, r] = Ti[9 + r]
        # composite inertia (mc, h, J) of links i.. about origin i, link-i axes
        mc = 0.0
        hx = hy = hz = 0.0
        Jxx = Jxy = Jxz = Jyy = Jyz = Jzz = 0.0
        for i in range(n - 1, -1, -1):
            if i < n - 1:
                # carry the composite from frame i + 1 into frame i (u = R h):
                # h' = u + m p,  J' = R J R^T + m (p.p E - p p^T) + 2 (p.u) E - u p^T - p u^T
                k = i + 1
                r00, r01, r02 = R[k, 0, 0], R[k, 0, 1], R[k, 0, 2]
                r10, r11, r12 = R[k, 1, 0], R[k, 1, 1], R[k, 1, 2]
                r20, r21, r22 = R[k, 2, 0], R[k, 2, 1], R[k, 2, 2]
                px, py, pz = p[k, 0], p[k, 1], p[k, 2]
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
                M[(b * n + j) * n + i] = e
                M[(b * n + i) * n + j] = e
                if j == 0:
                    break
                # the wrench from frame j into frame j - 1
                r00, r01, r02 = R[j, 0, 0], R[j, 0, 1], R[j, 0, 2]
                r10, r11, r12 = R[j, 1, 0], R[j, 1, 1], R[j, 1, 2]
                r20, r21, r22 = R[j, 2, 0], R[j, 2, 1], R[j, 2, 2]
                px, py, pz = p[j, 0], p[j, 1], p[j, 2]
                RFx = r00 * Fx + r01 * Fy + r02 * Fz
                RFy = r10 * Fx + r11 * Fy + r12 * Fz
                RFz = r20 * Fx + r21 * Fy + r22 * Fz
                RNx = r00 * Nx + r01 * Ny + r02 * Nz
                RNy = r10 * Nx + r11 * Ny + r12 * Nz
                RNz = r20 * Nx + r21 * Ny + r22 * Nz
                Nx = RNx + (py * RFz - pz * RFy)
                Ny = RNy + (pz * RFx - px * RFz)
                Nz = RNz + (px * RFy - py * RFx)
                Fx, Fy, Fz = RFx, RFy, RFz
                j -= 1
    return True
