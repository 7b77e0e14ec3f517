"""The numpy reference of the inverse-kinematics solve (the documented fallback).

The same simulation loop as the compiled :mod:`dynid._kernels.ik`, step for step:
a damped least-squares velocity towards the goal, joint limits and velocity scaling,
restarts from the given configurations when a solve stalls (see
:mod:`dynid.kinematics.inverse` for the method and its options). Used when numba is absent
or ``DYNID_NO_NUMBA`` is set; the tests hold both paths to 1e-9.
"""

from __future__ import annotations

import math

import numpy as np
from numpy.typing import NDArray

from ..model.robot import Robot
from .jacobian import _frame_pose_jacobian_numpy

__all__ = ["Chain", "rotvec", "solve_numpy"]

#: Relative decrease of the error norm that counts as progress (see ``stall_iterations``;
#: the compiled loop writes the same 1e-3).
_PROGRESS = 1e-3


class Chain:
    """Pose and Jacobian of one frame for one sample, for the numpy loop.

    The numpy reference path of :func:`dynid.kinematics.forward.fk` and
    :func:`dynid.kinematics.jacobian.jacobian` (one pass of link poses for both), so the
    forward kinematics is not written again here. Only the ``m = link`` joints up to the
    frame's link move it.
    """

    __slots__ = ("robot", "m", "T_link_frame")

    def __init__(self, robot: Robot, link: int, T_link_frame: NDArray[np.float64]) -> None:
        self.robot = robot
        self.m = link
        self.T_link_frame = np.array(T_link_frame)

    def pose_jacobian(self, q: NDArray[np.float64]) -> tuple[NDArray, NDArray]:
        """``T_base_frame`` (4, 4) and the Jacobian (6, m) of the first ``m`` joints."""
        T, J = _frame_pose_jacobian_numpy(self.robot, q[None], self.m, self.T_link_frame)
        return T[0], J[0, :, : self.m]


def rotvec(R: NDArray[np.float64]) -> tuple[float, float, float, float]:
    """Angle-axis vector (x, y, z) [rad] and angle in [0, pi] of one rotation matrix.

    Scalar form of :func:`dynid.spatial.angle_axis_from_matrix`: the skew part is
    ``sin(theta) u``; near pi the axis comes from the symmetric part
    ``(R + R^T) / 2 = cos(theta) I + (1 - cos(theta)) u u^T``, signed by the skew part
    (within 1e-12 of pi the skew part is rounding noise and ``u`` keeps the sign of its
    largest entry, so that the numpy loop and the kernel turn the same way).
    """
    (r00, r01, r02), (r10, r11, r12), (r20, r21, r22) = R.tolist()
    vx, vy, vz = 0.5 * (r21 - r12), 0.5 * (r02 - r20), 0.5 * (r10 - r01)
    c = min(1.0, max(-1.0, 0.5 * (r00 + r11 + r22 - 1.0)))
    s = math.sqrt(vx * vx + vy * vy + vz * vz)
    theta = math.atan2(s, c)
    if c > -0.9:
        f = theta / s if s > 1e-12 else 1.0 + theta * theta / 6.0
        return f * vx, f * vy, f * vz, theta
    w = 1.0 / (1.0 - c)  # u u^T = (S - c I) / (1 - c); read the row of the largest diagonal
    dx, dy, dz = (r00 - c) * w, (r11 - c) * w, (r22 - c) * w
    sxy, sxz, syz = 0.5 * (r01 + r10) * w, 0.5 * (r02 + r20) * w, 0.5 * (r12 + r21) * w
    if dx >= dy and dx >= dz:
        ux, uy, uz = dx, sxy, sxz
    elif dy >= dz:
        ux, uy, uz = sxy, dy, syz
    else:
        ux, uy, uz = sxz, syz, dz
    norm = math.sqrt(ux * ux + uy * uy + uz * uz)
    if ux * vx + uy * vy + uz * vz < -1e-12 * norm:  # within 1e-12 of pi: keep u as read
        norm = -norm
    return theta * ux / norm, theta * uy / norm, theta * uz / norm, theta


def _dls(J: NDArray[np.float64], e: NDArray[np.float64], lam_max: float, eps: float) -> NDArray:
    """Damped least-squares solution ``J^# e`` with singular-value dependent damping."""
    # numpy's driver (LAPACK gesdd): importing scipy.linalg for it would cost a one-shot
    # command line call more (0.13 s) than all its iterations
    U, s, Vt = np.linalg.svd(J, full_matrices=False)
    s_min = s[-1]
    lam2 = (1.0 - (s_min / eps) ** 2) * lam_max**2 if s_min < eps else 0.0
    keep = s > 1e-12 * s[0]
    inv = np.where(keep, s / np.where(keep, s * s + lam2, 1.0), 0.0)
    return Vt.T @ (inv * (U.T @ e))


# ---------------------------------------------------------------------- numpy loop
def solve_numpy(
    chain: Chain,
    q_min: NDArray,
    q_max: NDArray,
    inv_vmax: NDArray,
    q_restart: NDArray,
    p_goal: NDArray,
    R_goal: NDArray,
    fpar: NDArray,
    ipar: NDArray,
    path: NDArray,
) -> tuple[int, int, float, float, bool, int, bool]:
    """The simulation loop with numpy; same steps as :mod:`dynid._kernels.ik`."""
    dt, K, lam, eps, tol_p, tol_o, step_p, step_o, e_damp = (float(x) for x in fpar)
    max_iter, stall, max_restarts = int(ipar[0]), int(ipar[1]), int(ipar[2])
    m = chain.m
    use_vmax = bool(np.any(inv_vmax > 0))
    q = path[0].copy()
    e = np.empty(6)
    k = best_k = 0
    best_err = best_p = best_o = math.inf
    ref, k_ref, restarts, converged = math.inf, 0, 0, False
    target: NDArray | None = None
    while True:
        if target is not None:  # transfer to a restart configuration at the velocity limits
            dq = (target - q[:m]) / dt
            ratio = float(np.max(np.abs(dq) * inv_vmax)) if use_vmax else 0.0
            if ratio <= 1.0:
                q[:m] = target
                target, ref, k_ref = None, math.inf, k + 1
            else:
                q[:m] = np.minimum(np.maximum(q[:m] + (dt / ratio) * dq, q_min), q_max)
            k += 1
            path[k] = q
            if k >= max_iter:
                break
            continue
        T, J = chain.pose_jacobian(q)
        e[:3] = p_goal - T[:3, 3]
        ox, oy, oz, err_o = rotvec(R_goal @ T[:3, :3].T)
        e[3], e[4], e[5] = ox, oy, oz
        err_p = math.hypot(e[0], e[1], e[2])  # no overflow for a goal absurdly far
        err = math.sqrt(err_p * err_p + err_o * err_o) if err_p < 1e150 else err_p
        if (err_p <= tol_p and err_o <= tol_o) or err < best_err:
            best_k, best_err, best_p, best_o = k, err, err_p, err_o
        if err_p <= tol_p and err_o <= tol_o:
            converged = True
            break
        if err < ref * (1.0 - _PROGRESS):
            ref, k_ref = err, k
        if k >= max_iter or m == 0:
            break
        if k - k_ref >= stall:
            if restarts == max_restarts:
                break
            if restarts == q_restart.shape[0]:  # ask the caller for restart configurations
                return k, best_k, best_p, best_o, converged, restarts, True
            target = q_restart[restarts]
            restarts += 1
            continue
        if err_p > step_p:
            e[:3] *= step_p / err_p
        if err_o > step_o:
            e[3:] *= step_o / err_o
        qm = q[:m]
        at_lo, at_hi = qm <= q_min, qm >= q_max
        free = np.ones(m, dtype=bool)
        lam_e = lam * math.sqrt(min(1.0, err / e_damp))
        dq = _dls(J, e, lam_e, eps)
        for _ in range(m):  # active set: joints pushed beyond a limit they rest on stay put
            push = free & ((at_lo & (dq < 0.0)) | (at_hi & (dq > 0.0)))
            if not push.any():
                break
            free &= ~push
            dq = np.zeros(m)
            if free.any():
                dq[free] = _dls(J[:, free], e, lam_e, eps)
        dq *= K
        if use_vmax:
            ratio = float(np.max(np.abs(dq) * inv_vmax))
            if ratio > 1.0:
                dq /= ratio
        q[:m] = np.minimum(np.maximum(qm + dt * dq, q_min), q_max)
        k += 1
        path[k] = q
    return k, best_k, best_p, best_o, converged, restarts, False
