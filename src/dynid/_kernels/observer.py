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
row ``4n+2`` the options ``exact, trapezoid, friction``. State ``S`` (``3 n + 2``):
started, ``t``, ``p``, ``u`` and ``r`` of the last sample.
"""

from __future__ import annotations

import math

import numpy as np

from .chain import STACK as _STACK
from .chain import angles, finite, inline, jit, joint_at, lean, stack
from .dynamics import carry
from .layout import C_AXIS, C_PHI, C_PRISMATIC

__all__ = [
    "FRICTION_WIDTH",
    "momentum_terms",
    "momentum_terms_one",
    "observer_step",
    "observer_batch",
]

#: columns of a motor's canonical friction parameters
FRICTION_WIDTH = 13


@inline
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
    if vst > 0.0 and dfs != 0.0:
        x = v / vst
        f += dfs * math.exp(-x * x) * s
    ft, vs = F[m, 8], F[m, 9]
    if ft != 0.0:
        if vs > 0.0:
            f += ft * math.tanh(v / vs)
        else:
            f += ft * (1.0 if v > 0.0 else (-1.0 if v < 0.0 else 0.0))
    s1, s2, s3 = F[m, 10], F[m, 11], F[m, 12]
    if s1 != 0.0:
        f += s1 * (1.0 / (1.0 + math.exp(-s2 * (v + s3))) - 1.0 / (1.0 + math.exp(-s2 * s3)))
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
    exact = D[g + 1, 0] != 0.0
    trap = D[g + 1, 1] != 0.0
    for j in range(n):
        k = D[g, j]
        gam = -math.expm1(-k * T) if exact else k * T
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


@jit
def observer_batch(D, S, t, q, dq, tau, r):
    """The observer over ``B`` samples: ``r`` (B n,) from ``t`` (B,), ``q, dq, tau`` (B n,),
    continuing from the state ``S``; friction as in :func:`observer_step`.

    Returns -1, or the first sample that stopped it (a non-finite input, a time that does
    not increase); the state then holds the samples before it.
    """
    B = t.shape[0]
    n = q.shape[0] // B if B > 0 else 0
    W = np.empty((n, 21))
    A = np.empty((3, n))
    X = np.empty((4, n))
    pk, bk, tf, V = X[0], X[1], X[2], X[3]
    friction = D[4 * n + 2, 2] != 0.0
    for b in range(B):
        o = b * n
        if not (angles(D, q, o, A) and finite(dq, o, n) and finite(tau, o, n)):
            return b
        if not math.isfinite(t[b]) or (S[0] != 0.0 and not t[b] > S[1]):
            return b
        _terms_sample(D, n, A, dq, o, W, pk, bk, 0)
        _rotor(D, n, dq, o, pk)
        if friction:
            _friction(D, n, dq, o, tf, V)
            for i in range(n):
                bk[i] = tau[o + i] - tf[i] - bk[i]
        else:
            for i in range(n):
                bk[i] = tau[o + i] - bk[i]
        _update(D, n, S, t[b], pk, bk, 0, 0, r, o)
    return -1
