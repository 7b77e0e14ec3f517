"""Compiled (numba) kernels: link poses, frame poses and geometric Jacobians.

This module imports numba, so it is imported lazily, on the first call of a kinematics
function (see :func:`dynid.kinematics.forward.kernels`), never by ``import dynid``. Each
kernel is compiled on its first call for the argument types it meets and cached on disk
(``cache=True``); later processes load it instead of compiling it again.

The kernels take the robot's constant arrays as arguments: ``T`` (``T_parent_joint``,
(n, 4, 4)), ``axes`` (n, 3, unit joint axes in the child link's frame, any direction) and
``prismatic`` (n,) bool; see :mod:`dynid.model.robot`. A frame is given by its ``link``
(0 = base) and its pose ``T_lf`` (4, 4) in that link, a tool already multiplied in.
Joint positions ``q`` are a flat, C-contiguous float64 array of length ``B * n``,
sample-major (a (B, n) array reshaped). Results are written into a flat output array,
row-major: ``B * (n + 1) * 16`` for the link poses, ``B * 16`` for a frame pose,
``B * 6 * n`` for a Jacobian. Every kernel checks that ``q`` is finite and returns ``ok``;
with ``ok = False`` the output is unfinished and the caller raises the error that names
the bad entry.

Equations: the same as the numpy reference path of :mod:`dynid.kinematics.forward` and
:mod:`dynid.kinematics.jacobian`, in the same order of operations. The motion of a
revolute joint about the unit axis ``a`` is Rodrigues' ``E + sin q K + (1 - cos q) K K``
with ``K = [a]x``; a prismatic joint translates by ``q a``. Then
``T_{i-1,i} = T_parent_joint[i] T_joint(q_i)`` and the poses are chained from the base,
``p_i = p_{i-1} + R_{i-1} p_{i-1,i}``, ``R_i = R_{i-1} R_{i-1,i}``. Column ``i`` of the
Jacobian of the frame origin ``p`` is ``[z_i x (p - o_i); z_i]`` (revolute) or
``[z_i; 0]`` (prismatic), ``z_i = R_i a_i``, ``o_i = p_i`` (Siciliano et al., *Robotics*,
2009, eq. 3.30); columns of joints after the frame's link are zero.

The compiler may fuse ``a * b + c`` into one multiply-add (numba ``fastmath={"contract"}``,
no other fast-math flag), so the kernels and the numpy path differ by rounding only (the
tests hold them to 1e-12). Sine and cosine are the math library's.
"""

from __future__ import annotations

import math

import numba
import numpy as np

__all__ = ["link_poses", "frame_pose", "jacobian"]

# a * b + c may be one fused multiply-add (one rounding instead of two); no reassociation,
# no approximate functions, NaN and inf semantics kept
_FASTMATH = {"contract"}


def _jit(fn):
    """``numba.njit(cache=True)`` allowing fused multiply-add, and nothing else of fastmath.

    Without the disk cache when numba finds no writable cache folder.
    """
    try:
        return numba.njit(cache=True, fastmath=_FASTMATH)(fn)
    except RuntimeError:  # no writable cache location
        return numba.njit(fastmath=_FASTMATH)(fn)


@numba.njit(inline="always")
def _kk(axes, KK):
    """``K K`` (n, 3, 3) for ``K = [a]x`` of every axis, summed as ``K @ K`` is."""
    n = axes.shape[0]
    K = np.zeros((3, 3))
    for i in range(n):
        ax, ay, az = axes[i, 0], axes[i, 1], axes[i, 2]
        K[0, 1], K[0, 2], K[1, 2] = -az, ay, -ax
        K[1, 0], K[2, 0], K[2, 1] = az, -ay, ax
        for r in range(3):
            for c in range(3):
                KK[i, r, c] = K[r, 0] * K[0, c] + K[r, 1] * K[1, c] + K[r, 2] * K[2, c]


@numba.njit(inline="always")
def _finite(q, b, n):
    """All of sample ``b``'s ``n`` joint positions are finite."""
    for i in range(n):
        if not math.isfinite(q[b * n + i]):
            return False
    return True


@numba.njit(inline="always")
def _step(T, axes, prismatic, KK, i, qi, Rb, pb):
    """Carry the base pose ``(Rb, pb)`` of link ``i`` to link ``i + 1`` in place."""
    # motion of the joint in its own frame: Rq, pq
    if prismatic[i]:
        # R = Rf (Rq = E), p = pf + Rf (q a)
        dx, dy, dz = qi * axes[i, 0], qi * axes[i, 1], qi * axes[i, 2]
        r00, r01, r02 = T[i, 0, 0], T[i, 0, 1], T[i, 0, 2]
        r10, r11, r12 = T[i, 1, 0], T[i, 1, 1], T[i, 1, 2]
        r20, r21, r22 = T[i, 2, 0], T[i, 2, 1], T[i, 2, 2]
        px = T[i, 0, 3] + (r00 * dx + r01 * dy + r02 * dz)
        py = T[i, 1, 3] + (r10 * dx + r11 * dy + r12 * dz)
        pz = T[i, 2, 3] + (r20 * dx + r21 * dy + r22 * dz)
    else:
        s, c = math.sin(qi), math.cos(qi)
        v = 1.0 - c
        ax, ay, az = axes[i, 0], axes[i, 1], axes[i, 2]
        # E + s K + v K K
        q00 = 1.0 + v * KK[i, 0, 0]
        q01 = -s * az + v * KK[i, 0, 1]
        q02 = s * ay + v * KK[i, 0, 2]
        q10 = s * az + v * KK[i, 1, 0]
        q11 = 1.0 + v * KK[i, 1, 1]
        q12 = -s * ax + v * KK[i, 1, 2]
        q20 = -s * ay + v * KK[i, 2, 0]
        q21 = s * ax + v * KK[i, 2, 1]
        q22 = 1.0 + v * KK[i, 2, 2]
        t00, t01, t02 = T[i, 0, 0], T[i, 0, 1], T[i, 0, 2]
        t10, t11, t12 = T[i, 1, 0], T[i, 1, 1], T[i, 1, 2]
        t20, t21, t22 = T[i, 2, 0], T[i, 2, 1], T[i, 2, 2]
        r00 = t00 * q00 + t01 * q10 + t02 * q20
        r01 = t00 * q01 + t01 * q11 + t02 * q21
        r02 = t00 * q02 + t01 * q12 + t02 * q22
        r10 = t10 * q00 + t11 * q10 + t12 * q20
        r11 = t10 * q01 + t11 * q11 + t12 * q21
        r12 = t10 * q02 + t11 * q12 + t12 * q22
        r20 = t20 * q00 + t21 * q10 + t22 * q20
        r21 = t20 * q01 + t21 * q11 + t22 * q21
        r22 = t20 * q02 + t21 * q12 + t22 * q22
        px, py, pz = T[i, 0, 3], T[i, 1, 3], T[i, 2, 3]
    # pb += Rb p, then Rb = Rb R
    b00, b01, b02 = Rb[0], Rb[1], Rb[2]
    b10, b11, b12 = Rb[3], Rb[4], Rb[5]
    b20, b21, b22 = Rb[6], Rb[7], Rb[8]
    pb[0] = pb[0] + (b00 * px + b01 * py + b02 * pz)
    pb[1] = pb[1] + (b10 * px + b11 * py + b12 * pz)
    pb[2] = pb[2] + (b20 * px + b21 * py + b22 * pz)
    Rb[0] = b00 * r00 + b01 * r10 + b02 * r20
    Rb[1] = b00 * r01 + b01 * r11 + b02 * r21
    Rb[2] = b00 * r02 + b01 * r12 + b02 * r22
    Rb[3] = b10 * r00 + b11 * r10 + b12 * r20
    Rb[4] = b10 * r01 + b11 * r11 + b12 * r21
    Rb[5] = b10 * r02 + b11 * r12 + b12 * r22
    Rb[6] = b20 * r00 + b21 * r10 + b22 * r20
    Rb[7] = b20 * r01 + b21 * r11 + b22 * r21
    Rb[8] = b20 * r02 + b21 * r12 + b22 * r22


@numba.njit(inline="always")
def _reset(Rb, pb):
    """The base pose: identity."""
    for k in range(9):
        Rb[k] = 0.0
    Rb[0] = Rb[4] = Rb[8] = 1.0
    pb[0] = pb[1] = pb[2] = 0.0


@numba.njit(inline="always")
def _frame(Rb, pb, T_lf, out, o):
    """``[Rb pb; 0 0 0 1] @ T_lf`` into ``out[o : o + 16]``, row-major."""
    for r in range(3):
        a0, a1, a2, a3 = Rb[3 * r], Rb[3 * r + 1], Rb[3 * r + 2], pb[r]
        for c in range(4):
            out[o + 4 * r + c] = (
                a0 * T_lf[0, c] + a1 * T_lf[1, c] + a2 * T_lf[2, c] + a3 * T_lf[3, c]
            )
    for c in range(4):
        out[o + 12 + c] = T_lf[3, c]


def _link_poses(T, axes, prismatic, q, out):
    """Link poses into ``out`` (B (n + 1) 16,) for q (B n,); returns ``ok``."""
    n = T.shape[0]
    B = q.shape[0] // n
    KK = np.empty((n, 3, 3))
    _kk(axes, KK)
    Rb = np.empty(9)
    pb = np.empty(3)
    for b in range(B):
        if not _finite(q, b, n):
            return False
        _reset(Rb, pb)
        for i in range(n + 1):
            if i > 0:
                _step(T, axes, prismatic, KK, i - 1, q[b * n + i - 1], Rb, pb)
            o = (b * (n + 1) + i) * 16
            for r in range(3):
                out[o + 4 * r] = Rb[3 * r]
                out[o + 4 * r + 1] = Rb[3 * r + 1]
                out[o + 4 * r + 2] = Rb[3 * r + 2]
                out[o + 4 * r + 3] = pb[r]
            out[o + 12] = 0.0
            out[o + 13] = 0.0
            out[o + 14] = 0.0
            out[o + 15] = 1.0
    return True


def _frame_pose(T, axes, prismatic, link, T_lf, q, out):
    """Pose of the frame ``T_lf`` of ``link`` into ``out`` (B 16,) for q (B n,); ``ok``."""
    n = T.shape[0]
    B = q.shape[0] // n
    KK = np.empty((n, 3, 3))
    _kk(axes, KK)
    Rb = np.empty(9)
    pb = np.empty(3)
    for b in range(B):
        if not _finite(q, b, n):
            return False
        _reset(Rb, pb)
        for i in range(link):
            _step(T, axes, prismatic, KK, i, q[b * n + i], Rb, pb)
        _frame(Rb, pb, T_lf, out, b * 16)
    return True


def _jacobian(T, axes, prismatic, link, T_lf, q, J):
    """Jacobian of the origin of frame ``T_lf`` of ``link`` into ``J`` (B 6 n,); ``ok``."""
    n = T.shape[0]
    B = q.shape[0] // n
    KK = np.empty((n, 3, 3))
    _kk(axes, KK)
    Rb = np.empty(9)
    pb = np.empty(3)
    for b in range(B):
        if not _finite(q, b, n):
            return False
        o = b * 6 * n
        _reset(Rb, pb)
        # first pass: joint axis z_i into rows 3-5 and link origin o_i into rows 0-2
        for i in range(link):
            _step(T, axes, prismatic, KK, i, q[b * n + i], Rb, pb)
            ax, ay, az = axes[i, 0], axes[i, 1], axes[i, 2]
            J[o + i] = pb[0]
            J[o + n + i] = pb[1]
            J[o + 2 * n + i] = pb[2]
            J[o + 3 * n + i] = Rb[0] * ax + Rb[1] * ay + Rb[2] * az
            J[o + 4 * n + i] = Rb[3] * ax + Rb[4] * ay + Rb[5] * az
            J[o + 5 * n + i] = Rb[6] * ax + Rb[7] * ay + Rb[8] * az
        for i in range(link, n):
            for r in range(6):
                J[o + r * n + i] = 0.0
        # the frame origin p, then the columns
        px = Rb[0] * T_lf[0, 3] + Rb[1] * T_lf[1, 3] + Rb[2] * T_lf[2, 3] + pb[0] * T_lf[3, 3]
        py = Rb[3] * T_lf[0, 3] + Rb[4] * T_lf[1, 3] + Rb[5] * T_lf[2, 3] + pb[1] * T_lf[3, 3]
        pz = Rb[6] * T_lf[0, 3] + Rb[7] * T_lf[1, 3] + Rb[8] * T_lf[2, 3] + pb[2] * T_lf[3, 3]
        for i in range(link):
            zx, zy, zz = J[o + 3 * n + i], J[o + 4 * n + i], J[o + 5 * n + i]
            if prismatic[i]:
                J[o + i], J[o + n + i], J[o + 2 * n + i] = zx, zy, zz
                J[o + 3 * n + i] = 0.0
                J[o + 4 * n + i] = 0.0
                J[o + 5 * n + i] = 0.0
            else:
                rx = px - J[o + i]
                ry = py - J[o + n + i]
                rz = pz - J[o + 2 * n + i]
                J[o + i] = zy * rz - zz * ry
                J[o + n + i] = zz * rx - zx * rz
                J[o + 2 * n + i] = zx * ry - zy * rx
    return True


#: ``link_poses(T, axes, prismatic, q, out) -> ok``
link_poses = _jit(_link_poses)
#: ``frame_pose(T, axes, prismatic, link, T_lf, q, out) -> ok``
frame_pose = _jit(_frame_pose)
#: ``jacobian(T, axes, prismatic, link, T_lf, q, J) -> ok``
jacobian = _jit(_jacobian)
