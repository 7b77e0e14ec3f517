"""The compiled chain core: one joint transform, one chaining step, one compiler setting.

Every numba kernel of dynid (forward kinematics, Jacobians, inverse dynamics, the mass
matrix, the regressors and inverse kinematics) builds on these helpers, so the joint
transform and the chaining are written once. This module imports numba; it is imported
only by the kernel modules, which are loaded lazily (:func:`dynid._compiled.kernels`).

The robot is the packed constant array ``C`` of :func:`dynid._compiled.pack`.

Joint transform (pose of link ``i + 1`` in link ``i``): ``T_i = T_parent_joint[i]
T_joint(q_i)`` with, for a revolute joint about the unit axis ``a`` (``K = [a]x``),
Rodrigues' ``R = E + sin q K + (1 - cos q) K K`` (``K K = a a^T - E``) and no translation;
for a prismatic joint ``R = E`` and the translation ``q a``. :func:`joint_sc` takes
``(s, c, d) = (sin q, cos q, 0)`` or ``(0, 1, q)``, exact selectors that change no rounding,
so that a loop over samples has no branch and vectorises. Chaining (:func:`compose`):
``p_b' = p_b + R_b p``, ``R_b' = R_b R`` (Craig, *Introduction to Robotics*, 2005, ch. 3).

Compiler settings (:func:`jit`): ``cache=True`` (compiled once, then loaded from disk) and
``fastmath={"contract"}``: ``a * b + c`` may be one fused multiply-add, no other fast-math
flag, so kernels and the numpy paths differ by rounding only.

Sine and cosine (:func:`sincos`) are Cephes' ``sin.c``/``cos.c`` (S. L. Moshier)
polynomials with its three-part reduction by pi/4, branch-free so that they vectorise; the
error is below 2.3e-16 absolute for ``|q| <= 1e8`` (:data:`SINCOS_MAX`; the math library is
used above).
"""

from __future__ import annotations

import math

import numba
import numpy as np

from .._compiled import C_AXIS, C_PRISMATIC, C_T

__all__ = [
    "jit",
    "sincos",
    "fixed",
    "joint_from",
    "joint_sc",
    "joint",
    "compose",
    "motion",
    "IDENTITY",
    "SINCOS_MAX",
]

#: a * b + c may be one fused multiply-add; no reassociation, no approximate functions
FASTMATH = {"contract"}
#: |q| above which the math library's sin and cos are used
SINCOS_MAX = 1.0e8

# Cephes sin.c: pi/4 = DP1 + DP2 + DP3 (DP1 and DP2 with short mantissas, so that y * DP1
# and y * DP2 are exact for the y that occur) and the minimax polynomials on [-pi/4, pi/4]
_FOPI = 1.27323954473516268615  # 4 / pi
_DP1 = 7.85398125648498535156e-1
_DP2 = 3.77489470793079817668e-8
_DP3 = 2.69515142907905952645e-15
_S0, _S1, _S2 = 1.58962301576546568060e-10, -2.50507477628578072866e-8, 2.75573136213857245213e-6
_S3, _S4, _S5 = -1.98412698295895385996e-4, 8.33333333332211858878e-3, -1.66666666666666307295e-1
_C0, _C1, _C2 = -1.13585365213876817300e-11, 2.08757008419747316778e-9, -2.75573141792967388112e-7
_C3, _C4, _C5 = 2.48015872888517045348e-5, -1.38888888888730564116e-3, 4.16666666666665929218e-2

#: the identity pose as (R row-major, p): 12 floats
IDENTITY = (1.0, 0.0, 0.0, 0.0, 1.0, 0.0, 0.0, 0.0, 1.0, 0.0, 0.0, 0.0)


def jit(fn=None, **options):
    """``numba.njit(cache=True, fastmath={"contract"}, **options)``; the one compiler setting.

    Without the disk cache when numba finds no writable cache folder.
    """
    if fn is None:
        return lambda f: jit(f, **options)
    try:
        return numba.njit(cache=True, fastmath=FASTMATH, **options)(fn)
    except RuntimeError:  # no writable cache location
        return numba.njit(fastmath=FASTMATH, **options)(fn)


def inline(fn):
    """A helper inlined into its callers (numba ``inline="always"``)."""
    return numba.njit(inline="always", fastmath=FASTMATH)(fn)


@inline
def sincos(x):
    """``(sin x, cos x)`` for ``|x| <= 1e8``, branch-free (Cephes ``sin.c``, ``cos.c``)."""
    ax = abs(x)
    j = np.int64(ax * _FOPI)
    j += j & 1  # even octant: z in [-pi/4, pi/4]
    y = float(j)
    z = ((ax - y * _DP1) - y * _DP2) - y * _DP3
    zz = z * z
    ps = z + z * zz * (((((_S0 * zz + _S1) * zz + _S2) * zz + _S3) * zz + _S4) * zz + _S5)
    pc = (
        1.0
        - 0.5 * zz
        + zz * zz * (((((_C0 * zz + _C1) * zz + _C2) * zz + _C3) * zz + _C4) * zz + _C5)
    )
    m = (j >> 1) & 3  # quadrant: x = m pi/2 + z (mod 2 pi)
    s = pc if m & 1 else ps
    c = ps if m & 1 else pc
    s = -s if (m >> 1) & 1 else s
    c = -c if ((m + 1) >> 1) & 1 else c
    s = -s if x < 0.0 else s
    return s, c


@inline
def joint_scd(C, i, qi):
    """``(s, c, d)`` of joint ``i`` at ``qi``: ``(sin q, cos q, 0)`` or ``(0, 1, q)``."""
    if C[i, C_PRISMATIC] != 0.0:
        return 0.0, 1.0, qi
    if abs(qi) > SINCOS_MAX:
        return math.sin(qi), math.cos(qi), 0.0
    s, c = sincos(qi)
    return s, c, 0.0


@inline
def fixed(C, i):
    """Joint ``i``'s fixed transform (12 floats ``(R row-major, p)``) and unit axis (3)."""
    T = (
        C[i, C_T], C[i, C_T + 1], C[i, C_T + 2], C[i, C_T + 4], C[i, C_T + 5], C[i, C_T + 6],
        C[i, C_T + 8], C[i, C_T + 9], C[i, C_T + 10], C[i, C_T + 3], C[i, C_T + 7],
        C[i, C_T + 11],
    )  # fmt: skip
    return T, (C[i, C_AXIS], C[i, C_AXIS + 1], C[i, C_AXIS + 2])


@inline
def joint_from(F, a, s, c, d):
    """Pose of a link in its parent (12 floats) from its joint's :func:`fixed` constants.

    ``F [Rot(a, s, c), d a; 0, 1]`` (Rodrigues, ``K K = a a^T - E``); see the module
    docstring. Loops over samples hoist ``fixed`` out and call this inside.
    """
    ax, ay, az = a
    v = 1.0 - c
    q00 = 1.0 + v * (ax * ax - 1.0)
    q11 = 1.0 + v * (ay * ay - 1.0)
    q22 = 1.0 + v * (az * az - 1.0)
    q01 = -s * az + v * (ax * ay)
    q10 = s * az + v * (ax * ay)
    q02 = s * ay + v * (ax * az)
    q20 = -s * ay + v * (ax * az)
    q12 = -s * ax + v * (ay * az)
    q21 = s * ax + v * (ay * az)
    dx, dy, dz = d * ax, d * ay, d * az
    t00, t01, t02, t10, t11, t12, t20, t21, t22, t03, t13, t23 = F
    return (
        t00 * q00 + t01 * q10 + t02 * q20,
        t00 * q01 + t01 * q11 + t02 * q21,
        t00 * q02 + t01 * q12 + t02 * q22,
        t10 * q00 + t11 * q10 + t12 * q20,
        t10 * q01 + t11 * q11 + t12 * q21,
        t10 * q02 + t11 * q12 + t12 * q22,
        t20 * q00 + t21 * q10 + t22 * q20,
        t20 * q01 + t21 * q11 + t22 * q21,
        t20 * q02 + t21 * q12 + t22 * q22,
        t03 + (t00 * dx + t01 * dy + t02 * dz),
        t13 + (t10 * dx + t11 * dy + t12 * dz),
        t23 + (t20 * dx + t21 * dy + t22 * dz),
    )


@inline
def joint_sc(C, i, s, c, d):
    """Pose of link ``i + 1`` in link ``i`` as 12 floats ``(R row-major, p)``."""
    F, a = fixed(C, i)
    return joint_from(F, a, s, c, d)


@inline
def joint(C, i, qi):
    """Pose of link ``i + 1`` in link ``i`` at joint position ``qi`` (12 floats)."""
    s, c, d = joint_scd(C, i, qi)
    return joint_sc(C, i, s, c, d)


@inline
def compose(A, B):
    """``A B`` of two poses given as 12 floats ``(R row-major, p)``."""
    return (
        A[0] * B[0] + A[1] * B[3] + A[2] * B[6],
        A[0] * B[1] + A[1] * B[4] + A[2] * B[7],
        A[0] * B[2] + A[1] * B[5] + A[2] * B[8],
        A[3] * B[0] + A[4] * B[3] + A[5] * B[6],
        A[3] * B[1] + A[4] * B[4] + A[5] * B[7],
        A[3] * B[2] + A[4] * B[5] + A[5] * B[8],
        A[6] * B[0] + A[7] * B[3] + A[8] * B[6],
        A[6] * B[1] + A[7] * B[4] + A[8] * B[7],
        A[6] * B[2] + A[7] * B[5] + A[8] * B[8],
        A[9] + (A[0] * B[9] + A[1] * B[10] + A[2] * B[11]),
        A[10] + (A[3] * B[9] + A[4] * B[10] + A[5] * B[11]),
        A[11] + (A[6] * B[9] + A[7] * B[10] + A[8] * B[11]),
    )


@inline
def finite(q, o, n):
    """All of ``q[o : o + n]`` are finite."""
    for i in range(n):
        if not math.isfinite(q[o + i]):
            return False
    return True


@inline
def motion(T, w, dw, a, ex, ey, ez, ep, v, acc):
    """Angular velocity, angular acceleration and origin acceleration (minus gravity) of a link.

    ``T`` (12 floats) is the link's pose in its parent, ``w, dw, a`` (3-tuples) the parent's
    motion in parent coordinates, ``(ex, ey, ez)`` the joint axis, ``ep`` 1.0 for a
    prismatic joint (0.0 revolute), ``v, acc`` the joint rate and acceleration. Returns the
    link's ``(w, dw, a)`` in link coordinates (9 floats; Featherstone 2008, sec. 5.3):
    ``a' = R^T (a + dw x p + w x (w x p))``, then for a revolute joint ``w' += v e``,
    ``dw' += w' x v e + acc e``, for a prismatic one ``a' += 2 w' x v e + acc e``.
    """
    r00, r01, r02, r10, r11, r12, r20, r21, r22, px, py, pz = T
    wx, wy, wz = w
    dwx, dwy, dwz = dw
    ux = wy * pz - wz * py
    uy = wz * px - wx * pz
    uz = wx * py - wy * px
    bx = a[0] + (dwy * pz - dwz * py) + (wy * uz - wz * uy)
    by = a[1] + (dwz * px - dwx * pz) + (wz * ux - wx * uz)
    bz = a[2] + (dwx * py - dwy * px) + (wx * uy - wy * ux)
    apx = r00 * bx + r10 * by + r20 * bz
    apy = r01 * bx + r11 * by + r21 * bz
    apz = r02 * bx + r12 * by + r22 * bz
    wpx = r00 * wx + r10 * wy + r20 * wz
    wpy = r01 * wx + r11 * wy + r21 * wz
    wpz = r02 * wx + r12 * wy + r22 * wz
    dpx = r00 * dwx + r10 * dwy + r20 * dwz
    dpy = r01 * dwx + r11 * dwy + r21 * dwz
    dpz = r02 * dwx + r12 * dwy + r22 * dwz
    vx, vy, vz = v * ex, v * ey, v * ez
    cx = wpy * vz - wpz * vy
    cy = wpz * vx - wpx * vz
    cz = wpx * vy - wpy * vx
    er = 1.0 - ep
    return (
        wpx + er * vx,
        wpy + er * vy,
        wpz + er * vz,
        dpx + er * (cx + acc * ex),
        dpy + er * (cy + acc * ey),
        dpz + er * (cz + acc * ez),
        apx + ep * (2.0 * cx + acc * ex),
        apy + ep * (2.0 * cy + acc * ey),
        apz + ep * (2.0 * cz + acc * ez),
    )
