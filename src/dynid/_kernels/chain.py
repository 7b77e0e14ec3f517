"""The compiled chain core: one joint transform, one chaining step, one compiler setting.

Every numba kernel of dynid (forward kinematics, Jacobians, inverse dynamics, the mass
matrix, the regressors and inverse kinematics) builds on these helpers, so the joint
transform and the chaining are written once. This module imports numba; it is imported
only by the kernel modules, which are loaded lazily (:func:`dynid._kernels.dispatch.compiled`).

The robot is the packed constant array ``C`` of :func:`dynid._kernels.layout.pack`.

Joint transform (pose of link ``i + 1`` in link ``i``): ``T_i = T_parent_joint[i]
T_joint(q_i)`` with, for a revolute joint about the unit axis ``a`` (``K = [a]x``),
Rodrigues' ``R = a a^T + cos q (E - a a^T) + sin q K`` and no translation; for a prismatic
joint ``R = E`` and the translation ``q a``. With ``F`` the rotation of ``T_parent_joint[i]``
the products ``A0 = F a a^T``, ``A1 = F (E - a a^T)``, ``A2 = F K`` (``0, F, 0`` for a
prismatic joint) and ``u = F a`` are made once (:func:`dynid._kernels.layout.pack`), so a joint
costs 21 multiply-adds: ``R = A0 + c A1 + s A2``, ``p = p0 + d u``. :func:`joint_from` takes
``(s, c, d) = (sin q, cos q, 0)`` or ``(0, 1, q)``, exact selectors, so that a loop over
samples has no branch and vectorises. For an axis along z (every modified-DH joint) the
products are exact (they only pick and negate entries of ``F``). Chaining (:func:`compose`):
``p_b' = p_b + R_b p``, ``R_b' = R_b R`` (Craig, *Introduction to Robotics*, 2005, ch. 3).

Compiler settings (:func:`jit`): ``cache=True`` (compiled once, then loaded from disk) and
``fastmath={"contract"}``: ``a * b + c`` may be one fused multiply-add, no other fast-math
flag, so kernels and the numpy paths differ by rounding only. Kernels that allocate nothing
(the kinematics kernels and the one-sample dynamics kernels) are compiled :func:`lean`,
without numba's memory manager, which halves the cost of entering them; their scratch is
on the stack (:func:`stack`), and :func:`flat_view` views an output flat.

Sine and cosine (:func:`sincos`) are Cephes' ``sin.c``/``cos.c`` (S. L. Moshier)
polynomials with its three-part reduction by pi/4, branch-free so that they vectorise; the
error is below 2.3e-16 absolute for ``|q| <= 1e8`` (:data:`SINCOS_MAX`; the math library is
used above).
"""

from __future__ import annotations

import math
from typing import Any

import numba
import numpy as np
from numba import types
from numba.core import cgutils
from numba.core.imputils import impl_ret_borrowed
from numba.extending import intrinsic
from numba.np.arrayobj import make_array, populate_array

from .layout import C_PRISMATIC, C_ROT, C_SLIDE, C_T

__all__ = [
    "jit",
    "called",
    "lean",
    "stack",
    "flat_view",
    "STACK",
    "sincos",
    "fixed",
    "joint_from",
    "joint",
    "angles",
    "joint_at",
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


def exact(fn):
    """:func:`jit` without ``contract``: no fused multiply-add, each product rounded as a C
    loop of the same operations rounds it (a kernel bit-identical to a library's loop)."""
    try:
        return numba.njit(cache=True)(fn)
    except RuntimeError:  # no writable cache location
        return numba.njit()(fn)


def inline(fn):
    """A helper inlined into its callers (numba ``inline="always"``)."""
    return numba.njit(inline="always", fastmath=FASTMATH)(fn)


def called(fn):
    """A function compiled on its own and called, not inlined: for long code on a rare
    path, each inlined copy of which costs seconds of compilation (its caller's cache
    keeps it)."""
    return numba.njit(fastmath=FASTMATH)(fn)


def lean(fn):
    """:func:`jit` without numba's reference-counted memory manager, for one-sample kernels.

    Entering such a kernel costs about half as much (no memory record is made for each
    array argument), which is most of a single-sample call. The kernel must not allocate
    arrays: its scratch lives on the stack (:func:`stack`). Where numba refuses the option,
    a plain :func:`jit` kernel computes the same.
    """
    try:
        return jit(fn, _nrt=False)
    except (KeyError, TypeError, ValueError):  # pragma: no cover (numba dropped the option)
        return jit(fn)


#: floats of one stack scratch array (:func:`stack`, 8 KiB); robots whose scratch would
#: not fit (over 48 joints for the one-sample RNEA) take the batch kernels
STACK = 1024


@intrinsic
def _stack(typingctx, rows, cols):
    """A (rows, cols) float64 C array on the calling kernel's stack, ``rows * cols <= STACK``.

    Uninitialised, like ``np.empty``, and valid until the kernel returns; no memory manager
    is involved, so lean kernels (:func:`lean`) can use it. The caller checks the size.
    """
    if not (isinstance(rows, types.Integer) and isinstance(cols, types.Integer)):
        return None
    arr = types.Array(types.float64, 2, "C")

    def codegen(context, builder, sig, args):
        intp = context.get_value_type(types.intp)
        r = context.cast(builder, args[0], sig.args[0], types.intp)
        c = context.cast(builder, args[1], sig.args[1], types.intp)
        data = cgutils.alloca_once(builder, context.get_value_type(types.float64), size=STACK)
        item = intp(8)
        ary = make_array(arr)(context, builder)
        populate_array(
            ary,
            data=data,
            shape=cgutils.pack_array(builder, [r, c]),
            strides=cgutils.pack_array(builder, [builder.mul(c, item), item]),
            itemsize=item,
            meminfo=None,
        )
        return ary._getvalue()

    return arr(rows, cols), codegen


#: ``stack(rows, cols)`` in a kernel (an intrinsic's Python signature also has the typing
#: context, which type checkers would ask for)
stack: Any = _stack


@intrinsic
def _flat_view(typingctx, arr):
    """A C-contiguous array seen as 1-d (``arr.reshape(arr.size)`` without its checks)."""
    if not (isinstance(arr, types.Array) and arr.layout == "C"):
        return None
    out = types.Array(arr.dtype, 1, "C")

    def codegen(context, builder, sig, args):
        src = make_array(sig.args[0])(context, builder, args[0])
        dst = make_array(out)(context, builder)
        populate_array(
            dst,
            data=src.data,
            shape=cgutils.pack_array(builder, [src.nitems]),
            strides=cgutils.pack_array(builder, [src.itemsize]),
            itemsize=src.itemsize,
            meminfo=src.meminfo,
            parent=src.parent,
        )
        return impl_ret_borrowed(context, builder, out, dst._getvalue())

    return out(arr), codegen


#: ``flat_view(arr)`` in a kernel (see :data:`stack`)
flat_view: Any = _flat_view


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
    """Joint ``i``'s constants for :func:`joint_from`: ``(A0, A1, A2, p0, u)``.

    ``A0, A1, A2`` (9 floats each, row-major) with ``R = A0 + cos q A1 + sin q A2``, ``p0``
    the joint origin and ``u = R_parent_joint a`` (3 floats each), so that
    ``p = p0 + d u`` (:func:`dynid._kernels.layout.pack`).
    """
    A0 = (
        C[i, C_ROT], C[i, C_ROT + 1], C[i, C_ROT + 2], C[i, C_ROT + 3], C[i, C_ROT + 4],
        C[i, C_ROT + 5], C[i, C_ROT + 6], C[i, C_ROT + 7], C[i, C_ROT + 8],
    )  # fmt: skip
    A1 = (
        C[i, C_ROT + 9], C[i, C_ROT + 10], C[i, C_ROT + 11], C[i, C_ROT + 12],
        C[i, C_ROT + 13], C[i, C_ROT + 14], C[i, C_ROT + 15], C[i, C_ROT + 16],
        C[i, C_ROT + 17],
    )  # fmt: skip
    A2 = (
        C[i, C_ROT + 18], C[i, C_ROT + 19], C[i, C_ROT + 20], C[i, C_ROT + 21],
        C[i, C_ROT + 22], C[i, C_ROT + 23], C[i, C_ROT + 24], C[i, C_ROT + 25],
        C[i, C_ROT + 26],
    )  # fmt: skip
    p0 = (C[i, C_T + 3], C[i, C_T + 7], C[i, C_T + 11])
    u = (C[i, C_SLIDE], C[i, C_SLIDE + 1], C[i, C_SLIDE + 2])
    return A0, A1, A2, p0, u


@inline
def joint_from(F, s, c, d):
    """Pose of a link in its parent (12 floats) from its joint's :func:`fixed` constants.

    ``R = A0 + c A1 + s A2``, ``p = p0 + d u``: Rodrigues' formula with the fixed rotation
    multiplied in once, in :func:`dynid._kernels.layout.pack` (see the module docstring). Loops
    over samples hoist ``fixed`` out and call this inside.
    """
    A0, A1, A2, p0, u = F
    return (
        A0[0] + c * A1[0] + s * A2[0],
        A0[1] + c * A1[1] + s * A2[1],
        A0[2] + c * A1[2] + s * A2[2],
        A0[3] + c * A1[3] + s * A2[3],
        A0[4] + c * A1[4] + s * A2[4],
        A0[5] + c * A1[5] + s * A2[5],
        A0[6] + c * A1[6] + s * A2[6],
        A0[7] + c * A1[7] + s * A2[7],
        A0[8] + c * A1[8] + s * A2[8],
        p0[0] + d * u[0],
        p0[1] + d * u[1],
        p0[2] + d * u[2],
    )


@inline
def joint(C, i, qi):
    """Pose of link ``i + 1`` in link ``i`` at joint position ``qi`` (12 floats)."""
    s, c, d = joint_scd(C, i, qi)
    return joint_from(fixed(C, i), s, c, d)


@inline
def angles(C, q, o, A):
    """``(d, s, c)`` of every joint of the sample ``q[o : o + n]`` into the rows of ``A`` (3, n).

    Row 0 the slide ``d`` (``q`` for a prismatic joint, else 0), rows 1 and 2 ``sin q`` and
    ``cos q`` (``0, 1`` for a prismatic joint): :func:`joint_scd` for the whole chain, with
    exact selectors and the sines and cosines in one loop, which vectorises. Returns
    whether every ``q`` is finite (``A`` is filled either way).
    """
    n = A.shape[1]
    ok = True
    big = False
    for i in range(n):
        x = q[o + i]
        ok = ok & math.isfinite(x)
        big = big | (abs(x) > SINCOS_MAX)
    if big:
        for i in range(n):
            A[1, i] = math.sin(q[o + i])
            A[2, i] = math.cos(q[o + i])
    else:
        for i in range(n):
            s, c = sincos(q[o + i])
            A[1, i] = s
            A[2, i] = c
    for i in range(n):
        ep = C[i, C_PRISMATIC]
        er = 1.0 - ep
        A[0, i] = ep * q[o + i]
        A[1, i] = er * A[1, i]
        A[2, i] = er * A[2, i] + ep
    return ok


@inline
def joint_at(C, i, A):
    """Pose of link ``i + 1`` in link ``i`` (12 floats) from the :func:`angles` ``A``."""
    return joint_from(fixed(C, i), A[1, i], A[2, i], A[0, i])


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
