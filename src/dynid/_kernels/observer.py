"""Compiled (numba) kernels of the momentum observer: ``p = M dq``, ``g - C^T dq`` and the
residual's update, in one pass per sample.

Imported lazily (:func:`dynid._kernels.dispatch.compiled`), never by ``import dynid``.

Terms. With ``v_i = (w_i, v_oi)`` the spatial velocity of link ``i`` (link coordinates,
reference point its origin), ``S_i`` its joint's axis and ``H_i = (P_i, L_i)`` the momentum
of links ``i..n`` about origin ``i`` (linear, angular),

.. math:: p_i = S_i^T H_i, \\qquad (C^T \\dot q)_i = (v_i \\times S_i)^T H_i

(the derivative of ``p_i = S_i^T H_i`` is ``(v_i x S_i)^T H_i`` plus the RNEA torque without
gravity, ``M ddq + C dq``, and ``Mdot = C + C^T``; Featherstone 2008, sec. 2.9 and 5.3).
One outward pass gives every link's velocity and the static acceleration ``-g``; one inward
pass carries the link momenta ``P = m v + w x h``, ``L = J w + h x v`` and the gravity
wrenches ``(m a, h x a)`` to the joints (``h = m c``, ``J`` about the link origin: the
standard parameters of the packed constants, :mod:`dynid._kernels.layout`). No Coriolis
matrix is formed. A rotor term adds ``M_r dq`` to ``p``.

The observer (De Luca et al., 2006; Haddadin et al., 2017) in its recursive form, exact for
any sample time ``T_k = t_k - t_{k-1}``:

.. math:: r_k = r_{k-1} + \\gamma_k \\Big(\\frac{p_k - p_{k-1}}{T_k} - u_k - r_{k-1}\\Big),
          \\quad u = \\tau - \\tau_f(\\dot q) - (g - C^T \\dot q)

with ``gamma = K_O T`` (Euler: De Luca's ``r_k = K_O (p_k - p_0 - I_k)`` rearranged) or
``1 - exp(-K_O T)`` (exact first-order discretisation), per joint; ``u_k`` or, with the
trapezoidal rule, ``(u_k + u_{k-1}) / 2``.

Packed observer constants ``D`` (one read-only array, :func:`dynid.observer.residual`):
rows ``0..n`` the robot's packed constants ``C``; rows ``n+1..2n`` the rotor mass matrix
``M_r``; rows ``2n+1..3n`` the friction transmission ``K_f`` (motor ``m`` a row); rows
``3n+1..4n`` each motor's friction parameters (:data:`FRICTION_WIDTH` columns, the
canonical form of :mod:`dynid.observer.friction`); row ``4n+1`` the gains ``K_O`` [1/s];
row ``4n+2`` the options ``exact, trapezoid, friction``. State ``S`` (``4 n + 3``):
started, ``t``, ``p``, ``u`` and ``r`` of the last sample, then the last step ``T`` and its
``gamma`` per joint (computed again only when the step changes).
"""

from __future__ import annotations

import math

import numpy as np

from .chain import SINCOS_MAX as _SINCOS_MAX
from .chain import STACK as _STACK
from .chain import (
    angles,
    called,
    exact,
    finite,
    fixed,
    inline,
    jit,
    joint_at,
    joint_from,
    lean,
    stack,
)
from .chain import sincos as _sincos
from .dynamics import carry
from .layout import C_AXIS, C_PHI, C_PRISMATIC

__all__ = [
    "BLOCK",
    "FRICTION_WIDTH",
    "first_order_filter",
    "first_order_lag",
    "momentum_terms",
    "momentum_terms_one",
    "observer_step",
    "observer_batch",
]

#: columns of a motor's canonical friction parameters (the 14 of
#: :mod:`dynid.observer.friction` and the sigmoid's value at rest)
FRICTION_WIDTH = 15


@called
def _terms_sample(C, n, A, dq, o, W, p, beta, po):
    """``p = M dq`` (links only) and ``g - C^T dq`` of one sample into ``p[po:po+n]`` and
    ``beta[po:po+n]``; ``A`` the angles of ``q``, ``dq[o:o+n]`` the rates, scratch W (n, 21)."""
    wx = wy = wz = 0.0
    vx = vy = vz = 0.0
    ax, ay, az = -C[n, 0], -C[n, 1], -C[n, 2]
    for i in range(n):
        T = joint_at(C, i, A)
        r00, r01, r02, r10, r11, r12, r20, r21, r22, px, py, pz = T
        # parent's origin velocity carried to this origin: v + w x p
        bx = vx + (wy * pz - wz * py)
        by = vy + (wz * px - wx * pz)
        bz = vz + (wx * py - wy * px)
        ep = C[i, C_PRISMATIC]
        er = 1.0 - ep
        ex, ey, ez = C[i, C_AXIS], C[i, C_AXIS + 1], C[i, C_AXIS + 2]
        d = dq[o + i]
        nwx = r00 * wx + r10 * wy + r20 * wz + er * d * ex
        nwy = r01 * wx + r11 * wy + r21 * wz + er * d * ey
        nwz = r02 * wx + r12 * wy + r22 * wz + er * d * ez
        nvx = r00 * bx + r10 * by + r20 * bz + ep * d * ex
        nvy = r01 * bx + r11 * by + r21 * bz + ep * d * ey
        nvz = r02 * bx + r12 * by + r22 * bz + ep * d * ez
        nax = r00 * ax + r10 * ay + r20 * az
        nay = r01 * ax + r11 * ay + r21 * az
        naz = r02 * ax + r12 * ay + r22 * az
        wx, wy, wz, vx, vy, vz, ax, ay, az = nwx, nwy, nwz, nvx, nvy, nvz, nax, nay, naz
        for k in range(12):
            W[i, k] = T[k]
        W[i, 12], W[i, 13], W[i, 14] = wx, wy, wz
        W[i, 15], W[i, 16], W[i, 17] = vx, vy, vz
        W[i, 18], W[i, 19], W[i, 20] = ax, ay, az
    Px = Py = Pz = Lx = Ly = Lz = 0.0
    Fx = Fy = Fz = Nx = Ny = Nz = 0.0
    for i in range(n - 1, -1, -1):
        if i < n - 1:
            Tc = (
                W[i + 1, 0], W[i + 1, 1], W[i + 1, 2], W[i + 1, 3], W[i + 1, 4], W[i + 1, 5],
                W[i + 1, 6], W[i + 1, 7], W[i + 1, 8], W[i + 1, 9], W[i + 1, 10], W[i + 1, 11],
            )  # fmt: skip
            Px, Py, Pz, Lx, Ly, Lz = carry(Tc, (Px, Py, Pz), (Lx, Ly, Lz))
            Fx, Fy, Fz, Nx, Ny, Nz = carry(Tc, (Fx, Fy, Fz), (Nx, Ny, Nz))
        m = C[i, C_PHI]
        hx, hy, hz = C[i, C_PHI + 1], C[i, C_PHI + 2], C[i, C_PHI + 3]
        Jxx, Jxy, Jxz = C[i, C_PHI + 4], C[i, C_PHI + 5], C[i, C_PHI + 6]
        Jyy, Jyz, Jzz = C[i, C_PHI + 7], C[i, C_PHI + 8], C[i, C_PHI + 9]
        wx, wy, wz = W[i, 12], W[i, 13], W[i, 14]
        vx, vy, vz = W[i, 15], W[i, 16], W[i, 17]
        ax, ay, az = W[i, 18], W[i, 19], W[i, 20]
        # momentum of the link about its origin: P = m v + w x h, L = J w + h x v
        Px += m * vx + (wy * hz - wz * hy)
        Py += m * vy + (wz * hx - wx * hz)
        Pz += m * vz + (wx * hy - wy * hx)
        Lx += (Jxx * wx + Jxy * wy + Jxz * wz) + (hy * vz - hz * vy)
        Ly += (Jxy * wx + Jyy * wy + Jyz * wz) + (hz * vx - hx * vz)
        Lz += (Jxz * wx + Jyz * wy + Jzz * wz) + (hx * vy - hy * vx)
        # gravity wrench at rest: f = m a, n = h x a (a = the static acceleration -g)
        Fx += m * ax
        Fy += m * ay
        Fz += m * az
        Nx += hy * az - hz * ay
        Ny += hz * ax - hx * az
        Nz += hx * ay - hy * ax
        ex, ey, ez = C[i, C_AXIS], C[i, C_AXIS + 1], C[i, C_AXIS + 2]
        # w x e and v x e
        cx, cy, cz = wy * ez - wz * ey, wz * ex - wx * ez, wx * ey - wy * ex
        if C[i, C_PRISMATIC] != 0.0:
            p[po + i] = Px * ex + Py * ey + Pz * ez
            ct = Px * cx + Py * cy + Pz * cz
            g = Fx * ex + Fy * ey + Fz * ez
        else:
            sx, sy, sz = vy * ez - vz * ey, vz * ex - vx * ez, vx * ey - vy * ex
            p[po + i] = Lx * ex + Ly * ey + Lz * ez
            ct = (Lx * cx + Ly * cy + Lz * cz) + (Px * sx + Py * sy + Pz * sz)
            g = Nx * ex + Ny * ey + Nz * ez
        beta[po + i] = g - ct


@inline
def _rotor(D, n, dq, o, p):
    """``p[0:n] += M_r dq[o:o+n]`` (rows ``n+1..2n`` of ``D``)."""
    for i in range(n):
        s = 0.0
        for j in range(n):
            s += D[n + 1 + i, j] * dq[o + j]
        p[i] += s


@inline
def _law(F, m, v):
    """Friction [N m] at velocity ``v`` from the canonical parameters in row ``m`` of ``F``."""
    fvp, fvn, fcp, fcn, fo, band = F[m, 0], F[m, 1], F[m, 2], F[m, 3], F[m, 4], F[m, 5]
    s = 1.0 if v > band else (-1.0 if v < -band else 0.0)
    f = fvp * max(v, 0.0) + fvn * min(v, 0.0) + fo
    if s > 0.0:
        f += fcp
    elif s < 0.0:
        f -= fcn
    dfs, vst = F[m, 6], F[m, 7]
    ft, vs = F[m, 8], F[m, 9]
    if vst > 0.0 and dfs != 0.0:  # the bump takes the Coulomb term's sign: tanh where vs > 0
        x = v / vst
        f += dfs * math.exp(-x * x) * (math.tanh(v / vs) if vs > 0.0 else s)
    if ft != 0.0:
        if vs > 0.0:
            f += ft * math.tanh(v / vs)
        else:
            f += ft * (1.0 if v > 0.0 else (-1.0 if v < 0.0 else 0.0))
    s1, s2, s3 = F[m, 10], F[m, 11], F[m, 12]
    if s1 != 0.0:  # column 14: the logistic at rest, sigma(phi2 phi3), made once
        f += s1 * (1.0 / (1.0 + math.exp(-s2 * (v + s3))) - F[m, 14])
    f += F[m, 13] * v * abs(v)  # quadratic viscous
    return f


@inline
def _friction(D, n, dq, o, tf, V):
    """Joint friction ``K_f^T f(K_f dq[o:o+n])`` into ``tf[0:n]``; scratch ``V`` (n,)."""
    k = 2 * n + 1
    for m in range(n):
        v = 0.0
        for j in range(n):
            v += D[k + m, j] * dq[o + j]
        V[m] = _law(D, 3 * n + 1 + m, v)
    for j in range(n):
        s = 0.0
        for m in range(n):
            s += D[k + m, j] * V[m]
        tf[j] = s


@inline
def _update(D, n, S, t, p, u, po, uo, r, ro):
    """One step of the residual (module docstring) from ``p[po:po+n]``, ``u[uo:uo+n]`` at
    time ``t``; the state ``S`` advanced, ``r[ro:ro+n]`` written. False for a time that does
    not increase."""
    if S[0] == 0.0:
        S[0] = 1.0
        S[1] = t
        for j in range(n):
            S[2 + j] = p[po + j]
            S[2 + n + j] = u[uo + j]
            S[2 + 2 * n + j] = 0.0
            r[ro + j] = 0.0
        return True
    T = t - S[1]
    if not T > 0.0:
        return False
    g = 4 * n + 1
    trap = D[g + 1, 1] != 0.0
    c = 3 * n + 2
    if S[c] != T:  # the gains of this step (uniform sampling: once)
        exact = D[g + 1, 0] != 0.0
        for j in range(n):
            k = D[g, j]
            S[c + 1 + j] = -math.expm1(-k * T) if exact else k * T
        S[c] = T
    for j in range(n):
        gam = S[c + 1 + j]
        uj = u[uo + j]
        ub = 0.5 * (uj + S[2 + n + j]) if trap else uj
        rj = S[2 + 2 * n + j]
        rj += gam * ((p[po + j] - S[2 + j]) / T - ub - rj)
        S[2 + j] = p[po + j]
        S[2 + n + j] = uj
        S[2 + 2 * n + j] = rj
        r[ro + j] = rj
    S[1] = t
    return True


@exact
def first_order_filter(gam, x, zi, out):
    """``x`` (m, n, r) through ``gam / (1 + (gam - 1) z^-1)`` along its first axis, ``gam``
    (n,) a filter per joint, from the state ``zi`` (n, r) (updated) into ``out`` (m, n, r):
    the transposed direct form ``y = gam x + z``, ``z = 0 x - (gam - 1) y``, the operations
    of ``scipy.signal.lfilter([gam], [1, gam - 1])`` in its order, without fused
    multiply-adds (the same numbers, bit for bit)."""
    m, n, r = x.shape
    for j in range(n):
        g = gam[j]
        a1 = g - 1.0
        for c in range(r):
            z = zi[j, c]
            for k in range(m):
                xk = x[k, j, c]
                y = z + g * xk
                out[k, j, c] = y
                z = xk * 0.0 - y * a1
            zi[j, c] = z


@jit
def first_order_lag(t, x, K, trapezoid, out):
    """``x`` (N, n) at the times ``t`` (N,) through ``K/(s + K)`` (``K`` (n,) [1/s]) from 0
    into ``out`` (N, n): exact for ``x`` held over each step at its new value or, with
    ``trapezoid``, at the mean of both ends (:func:`dynid.observer.residual.first_order_lag`)."""
    N, n = x.shape
    if N == 0:
        return
    for j in range(n):
        out[0, j] = 0.0
    for k in range(1, N):
        T = t[k] - t[k - 1]
        for j in range(n):
            a = -math.expm1(-K[j] * T)
            xk = 0.5 * (x[k, j] + x[k - 1, j]) if trapezoid else x[k, j]
            out[k, j] = out[k - 1, j] + a * (xk - out[k - 1, j])


@jit
def momentum_terms(C, q, dq, p, beta):
    """``p = M dq`` and ``beta = g - C^T dq`` (links only) into ``p``, ``beta`` (B n,) for
    q, dq (B n,); returns ``ok`` (False: a non-finite input)."""
    n = C.shape[0] - 1
    B = q.shape[0] // n
    W = np.empty((n, 21))
    A = np.empty((3, n))
    for b in range(B):
        if not (angles(C, q, b * n, A) and finite(dq, b * n, n)):
            return False
        _terms_sample(C, n, A, dq, b * n, W, p, beta, b * n)
    return True


@lean
def momentum_terms_one(C, q, dq, p, beta):
    """:func:`momentum_terms` of one sample (any strides), scratch on the stack; ``ok``."""
    n = C.shape[0] - 1
    if n * 21 > _STACK:
        return False
    A = stack(3, n)
    if not (angles(C, q, 0, A) and finite(dq, 0, n)):
        return False
    _terms_sample(C, n, A, dq, 0, stack(n, 21), p, beta, 0)
    return True


@lean
def observer_step(D, S, q, dq, tau, t, r):
    """One sample of the observer: ``r`` (n,) [N m] from ``q, dq, tau`` (n,) at ``t`` [s].

    Friction from ``D``'s canonical parameters when its option says so (else ``tau`` is
    taken as ``tau - tau_f``). Returns ``ok``: False for a non-finite input, a time that
    does not increase, or a chain too long for the stack (the state is then unchanged).
    """
    n = q.shape[0]
    if n * 21 > _STACK or not (math.isfinite(t) and finite(tau, 0, n)):
        return False
    A = stack(3, n)
    if not (angles(D, q, 0, A) and finite(dq, 0, n)):
        return False
    if S[0] != 0.0 and not t > S[1]:
        return False
    X = stack(4, n)
    pk, bk, u, V = X[0], X[1], X[2], X[3]
    _terms_sample(D, n, A, dq, 0, stack(n, 21), pk, bk, 0)
    _rotor(D, n, dq, 0, pk)
    if D[4 * n + 2, 2] != 0.0:
        _friction(D, n, dq, 0, u, V)
        for j in range(n):
            u[j] = tau[j] - u[j] - bk[j]
    else:
        for j in range(n):
            u[j] = tau[j] - bk[j]
    return _update(D, n, S, t, pk, u, 0, 0, r, 0)


# ------------------------------------------------------------------ the batch, in blocks
#: Samples per block of :func:`observer_batch` (the vectorised inner loop's length).
BLOCK = 32
# rows of the block scratch X[link, row, sample]
_BQ, _BV, _BS, _BC = 0, 1, 2, 3  # q, dq, sin q, cos q
_BR = 4  # rotation of the link in its parent, R[a][b] at _BR + 3 a + b
_BP = 13  # origin of the link in its parent
_BW, _BVO, _BA = 16, 19, 22  # angular velocity, origin velocity, static acceleration -g
_BH, _BL, _BF, _BN = 25, 28, 31, 34  # subtree momentum (P, L) and gravity wrench (F, N)
_BOUT_P, _BOUT_B = 37, 38  # p_i and g_i - (C^T dq)_i
_BROWS = 39


@inline
def _block_scratch(D, n):
    """``X`` (n + 2, rows, BLOCK): the base (link 0) at rest accelerating at ``-g``, the
    virtual link ``n + 1`` the identity carrying nothing."""
    X = np.zeros((n + 2, _BROWS, BLOCK))
    for k in range(BLOCK):
        X[0, _BA, k] = -D[n, 0]
        X[0, _BA + 1, k] = -D[n, 1]
        X[0, _BA + 2, k] = -D[n, 2]
        X[n + 1, _BR, k] = 1.0
        X[n + 1, _BR + 4, k] = 1.0
        X[n + 1, _BR + 8, k] = 1.0
    return X


@inline
def _load_block(D, n, q, dq, b0, nb, X):
    """Samples ``b0 .. b0 + nb`` into ``X``: q, dq, sin q, cos q (exact selectors for a
    prismatic joint). False for a non-finite input."""
    big = False
    for k in range(nb):
        o = (b0 + k) * n
        for i in range(n):
            x, v = q[o + i], dq[o + i]
            if not (math.isfinite(x) and math.isfinite(v)):
                return False
            big = big or abs(x) > _SINCOS_MAX
            X[i + 1, _BQ, k] = x
            X[i + 1, _BV, k] = v
    for l in range(1, n + 1):
        if D[l - 1, C_PRISMATIC] != 0.0:
            for k in range(nb):
                X[l, _BS, k] = 0.0
                X[l, _BC, k] = 1.0
        elif big:
            for k in range(nb):
                X[l, _BS, k] = math.sin(X[l, _BQ, k])
                X[l, _BC, k] = math.cos(X[l, _BQ, k])
        else:
            for k in range(nb):
                sn, cs = _sincos(X[l, _BQ, k])
                X[l, _BS, k] = sn
                X[l, _BC, k] = cs
    return True


@inline
def _outward_terms(D, n, nb, X):
    """Outward pass over a block: each link's pose in its parent, angular velocity, origin
    velocity and static acceleration, in link coordinates (:func:`_terms_sample`)."""
    for l in range(1, n + 1):
        i = l - 1
        ex, ey, ez = D[i, C_AXIS], D[i, C_AXIS + 1], D[i, C_AXIS + 2]
        ep = D[i, C_PRISMATIC]
        er = 1.0 - ep
        F = fixed(D, i)
        for k in range(nb):
            r00, r01, r02, r10, r11, r12, r20, r21, r22, px, py, pz = joint_from(
                F, X[l, _BS, k], X[l, _BC, k], ep * X[l, _BQ, k]
            )
            X[l, _BR, k] = r00
            X[l, _BR + 1, k] = r01
            X[l, _BR + 2, k] = r02
            X[l, _BR + 3, k] = r10
            X[l, _BR + 4, k] = r11
            X[l, _BR + 5, k] = r12
            X[l, _BR + 6, k] = r20
            X[l, _BR + 7, k] = r21
            X[l, _BR + 8, k] = r22
            X[l, _BP, k] = px
            X[l, _BP + 1, k] = py
            X[l, _BP + 2, k] = pz
            wx, wy, wz = X[i, _BW, k], X[i, _BW + 1, k], X[i, _BW + 2, k]
            bx = X[i, _BVO, k] + (wy * pz - wz * py)
            by = X[i, _BVO + 1, k] + (wz * px - wx * pz)
            bz = X[i, _BVO + 2, k] + (wx * py - wy * px)
            ax, ay, az = X[i, _BA, k], X[i, _BA + 1, k], X[i, _BA + 2, k]
            d = X[l, _BV, k]
            X[l, _BW, k] = r00 * wx + r10 * wy + r20 * wz + er * d * ex
            X[l, _BW + 1, k] = r01 * wx + r11 * wy + r21 * wz + er * d * ey
            X[l, _BW + 2, k] = r02 * wx + r12 * wy + r22 * wz + er * d * ez
            X[l, _BVO, k] = r00 * bx + r10 * by + r20 * bz + ep * d * ex
            X[l, _BVO + 1, k] = r01 * bx + r11 * by + r21 * bz + ep * d * ey
            X[l, _BVO + 2, k] = r02 * bx + r12 * by + r22 * bz + ep * d * ez
            X[l, _BA, k] = r00 * ax + r10 * ay + r20 * az
            X[l, _BA + 1, k] = r01 * ax + r11 * ay + r21 * az
            X[l, _BA + 2, k] = r02 * ax + r12 * ay + r22 * az


@inline
def _inward_terms(D, n, nb, X):
    """Inward pass over a block: subtree momenta and gravity wrenches carried from the
    child, the link's own added, projected into ``p_i`` and ``g_i - (C^T dq)_i``."""
    for l in range(n, 0, -1):
        i = l - 1
        c = l + 1
        m = D[i, C_PHI]
        hx, hy, hz = D[i, C_PHI + 1], D[i, C_PHI + 2], D[i, C_PHI + 3]
        Jxx, Jxy, Jxz = D[i, C_PHI + 4], D[i, C_PHI + 5], D[i, C_PHI + 6]
        Jyy, Jyz, Jzz = D[i, C_PHI + 7], D[i, C_PHI + 8], D[i, C_PHI + 9]
        ex, ey, ez = D[i, C_AXIS], D[i, C_AXIS + 1], D[i, C_AXIS + 2]
        ep = D[i, C_PRISMATIC]
        er = 1.0 - ep
        for k in range(nb):
            Tc = (
                X[c, _BR, k], X[c, _BR + 1, k], X[c, _BR + 2, k],
                X[c, _BR + 3, k], X[c, _BR + 4, k], X[c, _BR + 5, k],
                X[c, _BR + 6, k], X[c, _BR + 7, k], X[c, _BR + 8, k],
                X[c, _BP, k], X[c, _BP + 1, k], X[c, _BP + 2, k],
            )  # fmt: skip
            Px, Py, Pz, Lx, Ly, Lz = carry(
                Tc,
                (X[c, _BH, k], X[c, _BH + 1, k], X[c, _BH + 2, k]),
                (X[c, _BL, k], X[c, _BL + 1, k], X[c, _BL + 2, k]),
            )
            Fx, Fy, Fz, Nx, Ny, Nz = carry(
                Tc,
                (X[c, _BF, k], X[c, _BF + 1, k], X[c, _BF + 2, k]),
                (X[c, _BN, k], X[c, _BN + 1, k], X[c, _BN + 2, k]),
            )
            wx, wy, wz = X[l, _BW, k], X[l, _BW + 1, k], X[l, _BW + 2, k]
            vx, vy, vz = X[l, _BVO, k], X[l, _BVO + 1, k], X[l, _BVO + 2, k]
            ax, ay, az = X[l, _BA, k], X[l, _BA + 1, k], X[l, _BA + 2, k]
            Px += m * vx + (wy * hz - wz * hy)
            Py += m * vy + (wz * hx - wx * hz)
            Pz += m * vz + (wx * hy - wy * hx)
            Lx += (Jxx * wx + Jxy * wy + Jxz * wz) + (hy * vz - hz * vy)
            Ly += (Jxy * wx + Jyy * wy + Jyz * wz) + (hz * vx - hx * vz)
            Lz += (Jxz * wx + Jyz * wy + Jzz * wz) + (hx * vy - hy * vx)
            Fx += m * ax
            Fy += m * ay
            Fz += m * az
            Nx += hy * az - hz * ay
            Ny += hz * ax - hx * az
            Nz += hx * ay - hy * ax
            X[l, _BH, k] = Px
            X[l, _BH + 1, k] = Py
            X[l, _BH + 2, k] = Pz
            X[l, _BL, k] = Lx
            X[l, _BL + 1, k] = Ly
            X[l, _BL + 2, k] = Lz
            X[l, _BF, k] = Fx
            X[l, _BF + 1, k] = Fy
            X[l, _BF + 2, k] = Fz
            X[l, _BN, k] = Nx
            X[l, _BN + 1, k] = Ny
            X[l, _BN + 2, k] = Nz
            cx, cy, cz = wy * ez - wz * ey, wz * ex - wx * ez, wx * ey - wy * ex
            sx, sy, sz = vy * ez - vz * ey, vz * ex - vx * ez, vx * ey - vy * ex
            ePL = Px * ex + Py * ey + Pz * ez
            eL = Lx * ex + Ly * ey + Lz * ez
            cP = Px * cx + Py * cy + Pz * cz
            ct = er * ((Lx * cx + Ly * cy + Lz * cz) + (Px * sx + Py * sy + Pz * sz)) + ep * cP
            g = er * (Nx * ex + Ny * ey + Nz * ez) + ep * (Fx * ex + Fy * ey + Fz * ez)
            X[l, _BOUT_P, k] = er * eL + ep * ePL
            X[l, _BOUT_B, k] = g - ct


@jit
def observer_batch(D, S, t, q, dq, tau, r):
    """The observer over ``B`` samples: ``r`` (B n,) from ``t`` (B,), ``q, dq, tau`` (B n,),
    continuing from the state ``S``; friction as in :func:`observer_step`.

    ``p`` and ``g - C^T dq`` of a block of :data:`BLOCK` samples at a time, the loop over
    the block's samples innermost (it vectorises); then the update, sample after sample.
    Returns -1, or the first sample that stopped it (a non-finite input, a time that does
    not increase); the state then holds the samples before it.
    """
    B = t.shape[0]
    n = q.shape[0] // B if B > 0 else 0
    X = _block_scratch(D, n)
    Y = np.empty((4, n))
    pk, bk, tf, V = Y[0], Y[1], Y[2], Y[3]
    friction = D[4 * n + 2, 2] != 0.0
    for b0 in range(0, B, BLOCK):
        full = min(BLOCK, B - b0)
        nb = full
        for k in range(full):  # up to the first non-finite state (the state reaches it)
            o = (b0 + k) * n
            if not (finite(q, o, n) and finite(dq, o, n)):
                nb = k
                break
        _load_block(D, n, q, dq, b0, nb, X)
        _outward_terms(D, n, nb, X)
        _inward_terms(D, n, nb, X)
        for k in range(nb):
            b = b0 + k
            o = b * n
            if not finite(tau, o, n):
                return b
            if not math.isfinite(t[b]) or (S[0] != 0.0 and not t[b] > S[1]):
                return b
            for i in range(n):
                pk[i] = X[i + 1, _BOUT_P, k]
            _rotor(D, n, dq, o, pk)
            if friction:
                _friction(D, n, dq, o, tf, V)
                for i in range(n):
                    bk[i] = tau[o + i] - tf[i] - X[i + 1, _BOUT_B, k]
            else:
                for i in range(n):
                    bk[i] = tau[o + i] - X[i + 1, _BOUT_B, k]
            _update(D, n, S, t[b], pk, bk, 0, 0, r, o)
        if nb < full:
            return b0 + nb
    return -1
