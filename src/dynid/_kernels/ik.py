"""Compiled (numba) inverse kinematics: the whole solve for one goal, and batches of goals.

Imported lazily by :func:`dynid.kinematics.inverse.ik` through the dispatcher
(:func:`dynid._kernels.dispatch.compiled`), never by ``import dynid``; compiled once and
cached on disk. The loop, its damping, limits and restarts are documented in
:mod:`dynid.kinematics.inverse`; :func:`_solve` takes the same steps as the numpy loop
:func:`dynid.kinematics._ik_numpy.solve_numpy` (the tests hold their paths to 1e-9). The
frame pose and Jacobian come from the chain core
(:func:`dynid._kernels.kinematics.frame_jacobian`), so forward kinematics is not written
again here.

:func:`solve_batch` solves many goals in parallel (numba ``prange``, one goal per
iteration; the threads are numba's, ``NUMBA_NUM_THREADS``), without keeping the paths.
"""

from __future__ import annotations

import math

import numba
import numpy as np

from .chain import angles, called, inline, jit
from .dense import cholesky, cholesky_solve
from .kinematics import frame_jacobian

__all__ = ["solve_one", "solve_batch"]


@called
def _min_eigenvalue(G, d, A, w, off):
    """Smallest eigenvalue of the symmetric ``G[:d, :d]`` (scratch ``A`` (6, 6), ``w``, ``off``).

    Householder reduction to tridiagonal form, then the implicit QL iteration with
    Wilkinson shifts, eigenvalues only (Press et al., *Numerical Recipes*, 3rd ed., 2007,
    sec. 11.3-11.4, ``tred2`` and ``tqli``); absolute error about ``1e-16 |G|``. The
    rotations' radii are ``sqrt(f^2 + g^2)`` rather than ``hypot``: the entries are bounded
    by ``|G|`` and the shift ratio by about ``1e16`` (larger off-diagonals are split off), so
    nothing overflows, and the library call cost a third of an iteration of the solver.
    """
    for i in range(d):
        for j in range(d):
            A[i, j] = G[i, j]
    for i in range(d - 1, 0, -1):
        lo = i - 1
        h = 0.0
        scale = 0.0
        if lo > 0:
            for k in range(i):
                scale += abs(A[i, k])
            if scale == 0.0:
                off[i] = A[i, lo]
            else:
                for k in range(i):
                    A[i, k] /= scale
                    h += A[i, k] * A[i, k]
                f = A[i, lo]
                g = -math.sqrt(h) if f >= 0.0 else math.sqrt(h)
                off[i] = scale * g
                h -= f * g
                A[i, lo] = f - g
                f = 0.0
                for j in range(i):
                    g = 0.0
                    for k in range(j + 1):
                        g += A[j, k] * A[i, k]
                    for k in range(j + 1, i):
                        g += A[k, j] * A[i, k]
                    off[j] = g / h
                    f += off[j] * A[i, j]
                hh = f / (h + h)
                for j in range(i):
                    f = A[i, j]
                    g = off[j] - hh * f
                    off[j] = g
                    for k in range(j + 1):
                        A[j, k] -= f * off[k] + g * A[i, k]
        else:
            off[i] = A[i, lo]
    for i in range(d):
        w[i] = A[i, i]
    for i in range(1, d):
        off[i - 1] = off[i]
    off[d - 1] = 0.0
    for lo in range(d):
        for _ in range(60):
            mm = lo
            while mm < d - 1:
                dd = abs(w[mm]) + abs(w[mm + 1])
                if abs(off[mm]) <= 2.2e-16 * dd:
                    break
                mm += 1
            if mm == lo:
                break
            g = (w[lo + 1] - w[lo]) / (2.0 * off[lo])
            r = math.sqrt(g * g + 1.0)
            g = w[mm] - w[lo] + off[lo] / (g + (r if g >= 0.0 else -r))
            sn = 1.0
            c = 1.0
            p = 0.0
            underflow = False
            for i in range(mm - 1, lo - 1, -1):
                f = sn * off[i]
                b = c * off[i]
                r = math.sqrt(f * f + g * g)
                off[i + 1] = r
                if r == 0.0:
                    w[i + 1] -= p
                    off[mm] = 0.0
                    underflow = True
                    break
                sn = f / r
                c = g / r
                g = w[i + 1] - p
                r = (w[i] - g) * sn + 2.0 * c * b
                p = sn * r
                w[i + 1] = g + p
                g = c * r - b
            if underflow:
                continue
            w[lo] -= p
            off[lo] = g
            off[mm] = 0.0
    w_min = w[0]
    for i in range(1, d):
        w_min = min(w_min, w[i])
    return w_min


@inline
def _damping(s_min, eps, lam, err, e_damp):
    """Squared damping: ``(1 - (s_min/eps)^2) lam^2`` below ``eps``, scaled down by
    ``err / e_damp`` near the goal."""
    lam2 = (1.0 - (s_min / eps) ** 2) * lam * lam if s_min < eps else 0.0
    if err < e_damp:
        lam2 *= err / e_damp
    return lam2


@inline
def _rhs(Jf, e, nf, d, bvec):
    """``b = e`` (6 or more free joints) or ``J^T e`` (fewer) into ``bvec[:d]``."""
    for a in range(d):
        acc = 0.0
        if nf >= 6:
            acc = e[a]
        else:
            for r in range(6):
                acc += Jf[r, a] * e[r]
        bvec[a] = acc


@inline
def _transfer_step(q, target, dq, m, dt, use_vmax, inv_vmax, q_min, q_max):
    """One step towards the restart configuration ``target`` at the velocity limits; True
    when it is reached (``q`` is then ``target``)."""
    ratio = 0.0
    for j in range(m):
        dq[j] = (target[j] - q[j]) / dt
        if use_vmax:
            ratio = max(ratio, abs(dq[j]) * inv_vmax[j])
    if ratio <= 1.0:
        for j in range(m):
            q[j] = target[j]
        return True
    for j in range(m):
        q[j] = min(max(q[j] + (dt / ratio) * dq[j], q_min[j]), q_max[j])
    return False


@called
def _pose_error(C, m, q, Aq, Jflat, Te, M, p_goal, R_goal, e):
    """Pose error ``e`` (6,) of the frame at ``q`` in the base frame, and its Jacobian.

    The frame pose ``Te`` and the Jacobian (into ``Jflat``, (6, m)) come from the chain
    core's kernels; ``e`` is the position error, then the angle-axis vector of
    ``R_goal Te^T`` (as :func:`dynid.kinematics._ik_numpy.rotvec`). Returns the position
    and orientation errors [m, rad].
    """
    angles(C, q, 0, Aq)
    P = frame_jacobian(C, Aq, m, Jflat, 0, m)
    f = C.shape[0] - 1
    for r in range(3):
        a0, a1, a2, a3 = P[3 * r], P[3 * r + 1], P[3 * r + 2], P[9 + r]
        for col in range(4):
            Te[r, col] = (
                a0 * C[f, col] + a1 * C[f, 4 + col] + a2 * C[f, 8 + col] + a3 * C[f, 12 + col]
            )
    for r in range(3):
        e[r] = p_goal[r] - Te[r, 3]
    for r in range(3):
        for col in range(3):
            M[r, col] = (
                R_goal[r, 0] * Te[col, 0] + R_goal[r, 1] * Te[col, 1] + R_goal[r, 2] * Te[col, 2]
            )
    vx, vy, vz = 0.5 * (M[2, 1] - M[1, 2]), 0.5 * (M[0, 2] - M[2, 0]), 0.5 * (M[1, 0] - M[0, 1])
    cs = min(1.0, max(-1.0, 0.5 * (M[0, 0] + M[1, 1] + M[2, 2] - 1.0)))
    sn = math.sqrt(vx * vx + vy * vy + vz * vz)
    theta = math.atan2(sn, cs)
    if cs > -0.9:
        g = theta / sn if sn > 1e-12 else 1.0 + theta * theta / 6.0
        e[3], e[4], e[5] = g * vx, g * vy, g * vz
    else:
        w = 1.0 / (1.0 - cs)
        dx, dy, dz = (M[0, 0] - cs) * w, (M[1, 1] - cs) * w, (M[2, 2] - cs) * w
        sxy, sxz = 0.5 * (M[0, 1] + M[1, 0]) * w, 0.5 * (M[0, 2] + M[2, 0]) * w
        syz = 0.5 * (M[1, 2] + M[2, 1]) * w
        if dx >= dy and dx >= dz:
            ux, uy, uz = dx, sxy, sxz
        elif dy >= dz:
            ux, uy, uz = sxy, dy, syz
        else:
            ux, uy, uz = sxz, syz, dz
        norm = math.sqrt(ux * ux + uy * uy + uz * uz)
        if ux * vx + uy * vy + uz * vz < -1e-12 * norm:  # as in _ik_numpy.rotvec
            norm = -norm
        e[3], e[4], e[5] = theta * ux / norm, theta * uy / norm, theta * uz / norm
    err_p = math.sqrt(e[0] * e[0] + e[1] * e[1] + e[2] * e[2])
    if err_p > 1e150:  # a goal absurdly far: the squares overflow, scale them
        big = max(abs(e[0]), abs(e[1]), abs(e[2]))
        err_p = big * math.sqrt((e[0] / big) ** 2 + (e[1] / big) ** 2 + (e[2] / big) ** 2)
    return err_p, theta


@inline
def _gram(Jf, nf, d, G, V):
    """The Gram matrix ``G`` (``Jf Jf^T`` if ``nf >= 6``, else ``Jf^T Jf``; d x d) of the
    free columns, ``V = E``; returns the squared Frobenius norm of ``G``."""
    tot = 0.0
    for a in range(d):  # G is symmetric: the upper triangle, mirrored
        for b in range(a, d):
            acc = 0.0
            if nf >= 6:
                for t in range(nf):
                    acc += Jf[a, t] * Jf[b, t]
            else:
                for t in range(6):
                    acc += Jf[t, a] * Jf[t, b]
            G[a, b] = acc
            G[b, a] = acc
            V[a, b] = 1.0 if a == b else 0.0
            V[b, a] = V[a, b]
            tot += acc * acc if a == b else 2.0 * acc * acc
    return tot


@called
def _jacobi(G, V, d, tot):
    """Cyclic Jacobi rotations: ``G`` becomes ``diag(w)`` and ``V`` its eigenvectors."""
    for _sweep in range(50):
        off = 0.0
        for a in range(d - 1):
            for b in range(a + 1, d):
                off += G[a, b] * G[a, b]
        if off <= 1e-30 * tot:
            break
        for a in range(d - 1):
            for b in range(a + 1, d):
                gab = G[a, b]
                if gab == 0.0:
                    continue
                th = (G[b, b] - G[a, a]) / (2.0 * gab)
                t = 1.0 / (abs(th) + math.sqrt(th * th + 1.0))
                if th < 0.0:
                    t = -t
                c = 1.0 / math.sqrt(t * t + 1.0)
                sn = t * c
                for r in range(d):
                    g1, g2 = G[r, a], G[r, b]
                    G[r, a], G[r, b] = c * g1 - sn * g2, sn * g1 + c * g2
                for r in range(d):
                    g1, g2 = G[a, r], G[b, r]
                    G[a, r], G[b, r] = c * g1 - sn * g2, sn * g1 + c * g2
                for r in range(d):
                    g1, g2 = V[r, a], V[r, b]
                    V[r, a], V[r, b] = c * g1 - sn * g2, sn * g1 + c * g2


@inline
def _dls_free(Jf, nf, e, m, free, lam, eps, err, e_damp, S, dq):
    """The damped least-squares step ``J^# e`` of the ``nf > 0`` free joints into ``dq``.

    ``Jf`` holds the free columns of ``J``; scratch ``S`` = ``(G, V, L, A6, w6, o6, bvec,
    y)``. See :func:`_solve` for the two ways of solving it.
    """
    G, V, L, A6, w6, o6, bvec, y = S
    d = 6 if nf >= 6 else nf
    tot = _gram(Jf, nf, d, G, V)
    # the smallest eigenvalue w_min = s_min^2 of G decides the damping: none when a
    # Cholesky factorisation of G - eps^2 E succeeds, else from the QL eigenvalues; then
    # a Cholesky solve of (G + lambda^2 E) y = b
    if cholesky(G, d, eps * eps, L):
        fast = cholesky(G, d, 0.0, L)
    else:
        s_min = math.sqrt(max(_min_eigenvalue(G, d, A6, w6, o6), 0.0))
        lam2 = _damping(s_min, eps, lam, err, e_damp)
        fast = lam2 > 0.0 and cholesky(G, d, -lam2, L)
    if fast:
        _rhs(Jf, e, nf, d, bvec)
        cholesky_solve(L, d, bvec, y)
        col = 0
        for j in range(m):
            if free[j]:
                acc = 0.0
                if nf >= 6:  # dq = J^T y
                    for r in range(6):
                        acc += Jf[r, col] * y[r]
                else:  # dq = y
                    acc = y[col]
                dq[j] = acc
                col += 1
        return
    # J^# e from the eigen-decomposition G = V diag(w) V^T (cyclic Jacobi rotations)
    _jacobi(G, V, d, tot)
    w_max, w_min = 0.0, np.inf
    for a in range(d):
        w_max = max(w_max, G[a, a])
        w_min = min(w_min, G[a, a])
    s_min = math.sqrt(max(w_min, 0.0))
    lam2 = _damping(s_min, eps, lam, err, e_damp)
    cut = 1e-24 * w_max
    _rhs(Jf, e, nf, d, bvec)
    for a in range(d):  # y = diag(1 / (w + lam^2)) V^T b, zero where w <= cut
        acc = 0.0
        for r in range(d):
            acc += V[r, a] * bvec[r]
        y[a] = acc / (G[a, a] + lam2) if G[a, a] > cut else 0.0
    col = 0
    for j in range(m):
        if free[j]:
            acc = 0.0
            if nf >= 6:  # dq = J^T V y
                for r in range(6):
                    vy = 0.0
                    for a in range(d):
                        vy += V[r, a] * y[a]
                    acc += Jf[r, col] * vy
            else:  # dq = V y
                for a in range(d):
                    acc += V[col, a] * y[a]
            dq[j] = acc
            col += 1


@called
def _step(J, e, m, q, q_min, q_max, lam, eps, err, e_damp, free, Jf, S, dq):
    """The damped least-squares velocity ``dq`` (m,) with the active set of the joint
    limits: a joint resting on a limit that the step pushes further out is frozen, and the
    step is solved again without it."""
    for j in range(m):
        free[j] = True
    for _ in range(m + 1):
        nf = 0
        for j in range(m):
            if free[j]:
                nf += 1
        for j in range(m):
            dq[j] = 0.0
        if nf > 0:
            col = 0
            for j in range(m):
                if free[j]:
                    for r in range(6):
                        Jf[r, col] = J[r, j]
                    col += 1
            _dls_free(Jf, nf, e, m, free, lam, eps, err, e_damp, S, dq)
        pushed = False
        for j in range(m):
            if free[j] and (
                (q[j] <= q_min[j] and dq[j] < 0.0) or (q[j] >= q_max[j] and dq[j] > 0.0)
            ):
                free[j] = False
                pushed = True
        if not pushed:
            break


@inline
def _solve(C, m, q_min, q_max, inv_vmax, q_restart, goal, fpar, ipar, path, keep, q_best):
    """The simulation loop for one goal; see :func:`dynid.kinematics._ik_numpy.solve_numpy`.

    ``C`` holds the robot and the frame (:func:`dynid._kernels.layout.pack_frame`); joints
    ``0..m-1`` move the frame. ``path`` (rows, n) holds ``q0`` in row 0 and, when ``keep``,
    receives the motion (``max_iterations + 1`` rows); ``q_best`` (n,) receives the best
    point. ``goal`` (4, 4) is the goal pose, ``ipar`` ``(max_iterations, stall_iterations,
    max_restarts)``. Returns ``(iterations, best step, position error, orientation error,
    converged, restarts, need_restarts)``; ``need_restarts`` asks the caller to run again
    with the ``max_restarts`` configurations in ``q_restart`` (drawn only when needed).

    Each step: the pose error (:func:`_pose_error`), the damped least-squares velocity with
    the joint limits' active set (:func:`_step`), or a step of the move to a restart
    configuration (:func:`_transfer_step`). The damped least-squares step
    (:func:`_dls_free`): when the Gram matrix ``G`` (``J J^T`` if 6 or more joints are
    free, else ``J^T J``) has all eigenvalues above ``eps^2`` (a Cholesky factorisation of
    ``G - eps^2 E`` succeeds), no damping applies and the step is solved by a Cholesky
    factorisation of ``G``; otherwise from the eigen-decomposition ``G = V diag(w) V^T``
    (cyclic Jacobi rotations) with the damping of ``s_min``:
    ``J^# e = J^T V (W + lambda^2)^-1 V^T e`` or ``V (W + lambda^2)^-1 V^T J^T e``, the same
    step as the SVD form of the numpy loop.
    """
    dt, K, lam, eps = fpar[0], fpar[1], fpar[2], fpar[3]
    tol_p, tol_o, step_p, step_o, e_damp = fpar[4], fpar[5], fpar[6], fpar[7], fpar[8]
    max_iter, stall, max_restarts = ipar[0], ipar[1], ipar[2]
    n, n_restart = path.shape[1], q_restart.shape[0]
    p_goal = goal[:3, 3]
    R_goal = goal[:3, :3]
    use_vmax = False
    for j in range(m):
        if inv_vmax[j] > 0.0:
            use_vmax = True
    q = path[0].copy()
    for j in range(n):
        q_best[j] = q[j]
    Te = np.empty((3, 4))
    Aq = np.empty((3, m))
    Jflat = np.empty(6 * m)
    J = Jflat.reshape(6, m)
    S = (
        np.empty((6, 6)), np.empty((6, 6)), np.empty((6, 6)), np.empty((6, 6)),
        np.empty(6), np.empty(6), np.empty(6), np.empty(6),
    )  # fmt: skip
    e = np.empty(6)
    M = np.empty((3, 3))
    dq = np.zeros(m)
    free = np.empty(m, dtype=np.bool_)
    target = np.empty(m)
    Jf = np.empty((6, m))
    k = 0
    best_k = 0
    best_err = np.inf
    best_p = np.inf
    best_o = np.inf
    ref = np.inf
    k_ref = 0
    restarts = 0
    converged = False
    transfer = False
    while True:
        if transfer:
            if _transfer_step(q, target, dq, m, dt, use_vmax, inv_vmax, q_min, q_max):
                transfer = False
                ref = np.inf
                k_ref = k + 1
            k += 1
            if keep:
                for j in range(n):
                    path[k, j] = q[j]
            if k >= max_iter:
                break
            continue
        err_p, err_o = _pose_error(C, m, q, Aq, Jflat, Te, M, p_goal, R_goal, e)
        err = math.sqrt(err_p * err_p + err_o * err_o) if err_p < 1e150 else err_p
        done = err_p <= tol_p and err_o <= tol_o
        if done or err < best_err:
            best_k, best_err, best_p, best_o = k, err, err_p, err_o
            for j in range(n):
                q_best[j] = q[j]
        if done:
            converged = True
            break
        if err < ref * (1.0 - 1e-3):  # _PROGRESS
            ref = err
            k_ref = k
        if k >= max_iter or m == 0:
            break
        if k - k_ref >= stall:
            if restarts == max_restarts:
                break
            if restarts == n_restart:  # ask the caller for restart configurations
                return k, best_k, best_p, best_o, converged, restarts, True
            for j in range(m):
                target[j] = q_restart[restarts, j]
            restarts += 1
            transfer = True
            continue
        if err_p > step_p:
            for r in range(3):
                e[r] *= step_p / err_p
        if err_o > step_o:
            for r in range(3, 6):
                e[r] *= step_o / err_o
        _step(J, e, m, q, q_min, q_max, lam, eps, err, e_damp, free, Jf, S, dq)
        ratio = 0.0
        for j in range(m):
            dq[j] *= K
            if use_vmax:
                ratio = max(ratio, abs(dq[j]) * inv_vmax[j])
        scale = dt / ratio if ratio > 1.0 else dt
        for j in range(m):
            q[j] = min(max(q[j] + scale * dq[j], q_min[j]), q_max[j])
        k += 1
        if keep:
            for j in range(n):
                path[k, j] = q[j]
    return k, best_k, best_p, best_o, converged, restarts, False


@jit
def solve_one(C, m, q_min, q_max, inv_vmax, q_restart, goal, fpar, ipar, path, q_best):
    """One goal; see :func:`_solve`. The path is kept unless ``path`` has a single row.

    :func:`solve_batch` calls it with a single row: one compilation of the solver serves
    both (about 9 s on one core: the pose error and the step, :func:`_pose_error` and
    :func:`_step`, are compiled on their own and called, not inlined: 17 s inlined, for
    no measurable difference in run time), and the parallel loop calls it compiled, not
    inlined, so that numba's parfor array analysis, which fails on the solver's tuples when
    it compiles afresh, does not see them.
    """
    keep = path.shape[0] > 1
    return _solve(C, m, q_min, q_max, inv_vmax, q_restart, goal, fpar, ipar, path, keep, q_best)


@jit(parallel=True)
def solve_batch(C, m, q_min, q_max, inv_vmax, q_restart, goals, fpar, ipar, q0, out, stats):
    """Goals ``goals`` (G, 4, 4) from ``q0`` (G, n), in parallel; the paths are not kept.

    ``q_restart`` (G, max_restarts, m) holds every goal's restart configurations.
    Writes the best point of each goal into ``out`` (G, n) and ``(iterations, position
    error, orientation error, converged, restarts, need_restarts)`` into ``stats`` (G, 6).
    """
    G = goals.shape[0]
    n = q0.shape[1]
    for g in numba.prange(G):
        path = np.empty((1, n))
        for j in range(n):
            path[0, j] = q0[g, j]
        k, _, ep, eo, conv, rs, more = solve_one(
            C, m, q_min, q_max, inv_vmax, q_restart[g], goals[g], fpar, ipar, path, out[g]
        )
        stats[g, 0] = k
        stats[g, 1] = ep
        stats[g, 2] = eo
        stats[g, 3] = 1.0 if conv else 0.0
        stats[g, 4] = rs
        stats[g, 5] = 1.0 if more else 0.0
