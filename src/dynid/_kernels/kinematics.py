"""Compiled (numba) kernels: link poses, frame poses and geometric Jacobians.

Imported lazily, on the first kinematics call (:func:`dynid._kernels.dispatch.compiled`), never by
``import dynid``; compiled once and cached on disk (:func:`dynid._kernels.chain.jit`).

Arguments: ``C``, the robot's packed constants (:func:`dynid._kernels.layout.pack`), with a
last row for the frame (:func:`dynid._kernels.layout.pack_frame`: its ``link``, 0 = base, and its
pose ``T_lf`` in that link, a tool already multiplied in) for :func:`frame_pose` and
:func:`jacobian`; joint positions ``q``, flat float64 of length ``B * n``,
sample-major (a (B, n) array reshaped). Results go into a C-contiguous output array of
any shape, read flat, row-major:
``B * (n + 1) * 16`` for the link poses, ``B * 16`` for a frame pose, ``B * 6 * n`` for a
Jacobian. Every kernel checks that ``q`` is finite and returns ``ok``; with ``ok = False``
the output is unfinished and the caller raises the error that names the bad entry. The
kernels allocate nothing, so they are compiled lean (:func:`dynid._kernels.chain.lean`):
a single-sample call enters them at half the cost. Their scratch (the joints' sines and
cosines, :func:`dynid._kernels.chain.angles`) is on the stack; a chain too long for it
(over ``STACK / 3`` joints) returns ``ok = False`` and the caller takes the numpy path.

Equations: the joint transform and chaining of :mod:`dynid._kernels.chain`. Column
``i`` of the Jacobian of the frame origin ``p`` is ``[z_i x (p - o_i); z_i]`` (revolute)
or ``[z_i; 0]`` (prismatic), ``z_i = R_i a_i``, ``o_i = p_i`` (Siciliano et al.,
*Robotics*, 2009, eq. 3.30); columns of joints after the frame's link are zero.
"""

from __future__ import annotations

from .chain import IDENTITY, STACK, angles, compose, flat_view, inline, joint_at, lean, stack
from .layout import C_AXIS, C_PRISMATIC

__all__ = ["link_poses", "frame_pose", "jacobian", "jacobian_one"]


@inline
def _put_pose(P, out, o):
    """Pose ``P`` (12 floats) as a 4x4 row-major matrix into ``out[o : o + 16]``."""
    for r in range(3):
        out[o + 4 * r] = P[3 * r]
        out[o + 4 * r + 1] = P[3 * r + 1]
        out[o + 4 * r + 2] = P[3 * r + 2]
        out[o + 4 * r + 3] = P[9 + r]
    out[o + 12] = 0.0
    out[o + 13] = 0.0
    out[o + 14] = 0.0
    out[o + 15] = 1.0


@inline
def _frame(P, C, f, out, o):
    """``[R p; 0 1] @ T_lf`` into ``out[o : o + 16]``, row-major; ``T_lf`` is row ``f`` of C."""
    for r in range(3):
        a0, a1, a2, a3 = P[3 * r], P[3 * r + 1], P[3 * r + 2], P[9 + r]
        for c in range(4):
            out[o + 4 * r + c] = (
                a0 * C[f, c] + a1 * C[f, 4 + c] + a2 * C[f, 8 + c] + a3 * C[f, 12 + c]
            )
    for c in range(4):
        out[o + 12 + c] = C[f, 12 + c]


@lean
def link_poses(C, q, out):
    """Link poses into ``out`` (B (n + 1) 16,) for q (B n,); returns ``ok``."""
    out = flat_view(out)
    n = C.shape[0] - 1
    B = q.shape[0] // n
    if 3 * n > STACK:
        return False
    A = stack(3, n)
    for b in range(B):
        if not angles(C, q, b * n, A):
            return False
        P = IDENTITY
        o = b * (n + 1) * 16
        _put_pose(P, out, o)
        for i in range(n):
            P = compose(P, joint_at(C, i, A))
            _put_pose(P, out, o + (i + 1) * 16)
    return True


@lean
def frame_pose(C, q, out):
    """Pose of the frame of ``C``'s last row into ``out`` (B 16,) for q (B n,); ``ok``."""
    out = flat_view(out)
    n = C.shape[0] - 2
    link = int(C[n + 1, 16])
    B = q.shape[0] // n
    if 3 * n > STACK:
        return False
    A = stack(3, n)
    for b in range(B):
        if not angles(C, q, b * n, A):
            return False
        P = IDENTITY
        for i in range(link):
            P = compose(P, joint_at(C, i, A))
        _frame(P, C, n + 1, out, b * 16)
    return True


@inline
def frame_jacobian(C, A, link, J, oj, stride):
    """Jacobian columns ``0..link-1`` of the origin of ``C``'s frame (its last row).

    ``A`` holds the :func:`~dynid._kernels.chain.angles` of the sample; column ``i``,
    row ``r`` goes to ``J[oj + r * stride + i]``. Returns the pose of ``link`` in the base
    (12 floats).
    """
    f = C.shape[0] - 1
    P = IDENTITY
    # first pass: joint axis z_i into rows 3-5 and link origin o_i into rows 0-2
    for i in range(link):
        P = compose(P, joint_at(C, i, A))
        ax, ay, az = C[i, C_AXIS], C[i, C_AXIS + 1], C[i, C_AXIS + 2]
        J[oj + i] = P[9]
        J[oj + stride + i] = P[10]
        J[oj + 2 * stride + i] = P[11]
        J[oj + 3 * stride + i] = P[0] * ax + P[1] * ay + P[2] * az
        J[oj + 4 * stride + i] = P[3] * ax + P[4] * ay + P[5] * az
        J[oj + 5 * stride + i] = P[6] * ax + P[7] * ay + P[8] * az
    # the frame origin p, then the columns
    px = P[0] * C[f, 3] + P[1] * C[f, 7] + P[2] * C[f, 11] + P[9] * C[f, 15]
    py = P[3] * C[f, 3] + P[4] * C[f, 7] + P[5] * C[f, 11] + P[10] * C[f, 15]
    pz = P[6] * C[f, 3] + P[7] * C[f, 7] + P[8] * C[f, 11] + P[11] * C[f, 15]
    for i in range(link):
        zx, zy, zz = J[oj + 3 * stride + i], J[oj + 4 * stride + i], J[oj + 5 * stride + i]
        if C[i, C_PRISMATIC] != 0.0:
            J[oj + i], J[oj + stride + i], J[oj + 2 * stride + i] = zx, zy, zz
            J[oj + 3 * stride + i] = 0.0
            J[oj + 4 * stride + i] = 0.0
            J[oj + 5 * stride + i] = 0.0
        else:
            rx = px - J[oj + i]
            ry = py - J[oj + stride + i]
            rz = pz - J[oj + 2 * stride + i]
            J[oj + i] = zy * rz - zz * ry
            J[oj + stride + i] = zz * rx - zx * rz
            J[oj + 2 * stride + i] = zx * ry - zy * rx
    return P


@lean
def jacobian(C, q, J):
    """Jacobian of the origin of the frame of ``C``'s last row into ``J`` (B 6 n,); ``ok``."""
    J = flat_view(J)
    n = C.shape[0] - 2
    link = int(C[n + 1, 16])
    B = q.shape[0] // n
    if 3 * n > STACK:
        return False
    A = stack(3, n)
    for b in range(B):
        if not angles(C, q, b * n, A):
            return False
        o = b * 6 * n
        frame_jacobian(C, A, link, J, o, n)
        for i in range(link, n):
            for r in range(6):
                J[o + r * n + i] = 0.0
    return True


@lean
def jacobian_one(C, q, J):
    """:func:`jacobian` of one sample (q of length n, any strides, J (6, n)); ``ok``.

    The batch kernel without its loop over samples, for the single-sample path.
    """
    n = C.shape[0] - 2
    if 3 * n > STACK:
        return False
    A = stack(3, n)
    if not angles(C, q, 0, A):
        return False
    link = int(C[n + 1, 16])
    frame_jacobian(C, A, link, flat_view(J), 0, n)
    for i in range(link, n):
        for r in range(6):
            J[r, i] = 0.0
    return True
