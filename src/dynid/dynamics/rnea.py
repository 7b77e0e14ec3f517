"""Recursive Newton-Euler inverse dynamics (Featherstone, Rigid Body Dynamics Algorithms,
2008, ch. 5; Craig, Introduction to Robotics, 3rd ed., sec. 6.5), batched over samples.

Quantities are propagated in link coordinates. The base's linear acceleration is set to
``-gravity`` so that gravity enters every link's acceleration. Link wrenches are taken
about the link-frame origin using the standard parameters (``m``, ``m c``, ``J`` about the
origin), which makes the torques linear in ``phi`` (the basis of the regressors).

Two implementations compute the same torques (to rounding, about 1e-15 relative):

* the compiled kernels of :mod:`dynid._kernels.dynamics` (numba), used when numba is
  installed: a loop over samples and joints, compiled on the first call and cached on
  disk; importing dynid does not import numba;
* the numpy reference path (:func:`rnea_numpy`): samples vectorised, a loop over joints.

The public functions of :mod:`dynid.dynamics` use the kernels when :func:`kernels` finds
them and the numpy path otherwise. Set the environment variable ``DYNID_NO_NUMBA=1``
before the first dynamics call to force the numpy path; :func:`rnea_numpy` always takes
it.
"""

from __future__ import annotations

from types import ModuleType
from typing import NamedTuple

import numpy as np
from numpy.typing import ArrayLike, NDArray

from .. import _checks, _kernels
from ..exceptions import ShapeError
from ..kinematics.forward import joint_rotations_translations
from ..model.inertia import matrix_from_inertia6
from ..model.robot import Robot, checked_robot

__all__ = ["rnea", "rnea_numpy", "kernels", "LinkMotion", "link_motion"]

_RNEA = _kernels.KERNELS["rnea"]
#: gravity off (the Coriolis and centrifugal torques, the mass matrix's columns)
ZERO_GRAVITY = _checks.frozen(np.zeros(3))


def kernels() -> ModuleType | None:
    """The compiled dynamics kernels, or None when numba is missing or ``DYNID_NO_NUMBA``
    is set (:func:`dynid._kernels.dispatch.load`; ``DYNID_NO_NUMBA`` is read on the first
    call, and any value other than ``""`` and ``"0"`` selects the numpy reference path)."""
    return _kernels.load("dynamics")


def cross(a: NDArray[np.float64], b: NDArray[np.float64]) -> NDArray[np.float64]:
    """Cross product of (..., 3) arrays (faster than ``np.cross`` on small batches)."""
    out = np.empty(np.broadcast_shapes(a.shape, b.shape))
    out[..., 0] = a[..., 1] * b[..., 2] - a[..., 2] * b[..., 1]
    out[..., 1] = a[..., 2] * b[..., 0] - a[..., 0] * b[..., 2]
    out[..., 2] = a[..., 0] * b[..., 1] - a[..., 1] * b[..., 0]
    return out


class LinkMotion(NamedTuple):
    """Output of the forward (outward) pass, all arrays batched over B samples.

    R : (B, n, 3, 3)  rotation of link i in link i-1
    p : (B, n, 3)     origin of link i in link i-1 [m]
    w : (B, n, 3)     angular velocity of link i, link-i coordinates [rad/s]
    dw : (B, n, 3)    angular acceleration [rad/s^2]
    a : (B, n, 3)     linear acceleration of the link origin minus gravity [m/s^2]
    """

    R: NDArray[np.float64]
    p: NDArray[np.float64]
    w: NDArray[np.float64]
    dw: NDArray[np.float64]
    a: NDArray[np.float64]


def _rt(R: NDArray[np.float64], v: NDArray[np.float64]) -> NDArray[np.float64]:
    """R^T v for (B, 3, 3) and (B, 3)."""
    return (v[:, None, :] @ R)[:, 0, :]


def _rv(R: NDArray[np.float64], v: NDArray[np.float64]) -> NDArray[np.float64]:
    """R v for (B, 3, 3) and (B, 3)."""
    return (R @ v[:, :, None])[..., 0]


def link_motion(
    robot: Robot,
    q: NDArray[np.float64],
    dq: NDArray[np.float64],
    ddq: NDArray[np.float64],
    gravity: NDArray[np.float64],
) -> LinkMotion:
    """Velocities and accelerations of every link for validated (B, n) inputs."""
    B, n = q.shape
    R, p = joint_rotations_translations(robot, q)
    w = np.zeros((B, n, 3))
    dw = np.zeros((B, n, 3))
    a = np.zeros((B, n, 3))
    w0 = np.zeros((B, 3))
    dw0 = np.zeros((B, 3))
    a0 = np.broadcast_to(-gravity, (B, 3))
    for i in range(n):
        ax = robot.axes[i]
        Ri, pi = R[:, i], p[:, i]
        a_par = _rt(Ri, a0 + cross(dw0, pi) + cross(w0, cross(w0, pi)))
        wp, dwp = _rt(Ri, w0), _rt(Ri, dw0)
        v_ax = dq[:, i, None] * ax
        a_ax = ddq[:, i, None] * ax
        if robot.prismatic[i]:
            w0, dw0 = wp, dwp
            a0 = a_par + 2.0 * cross(wp, v_ax) + a_ax
        else:
            w0 = wp + v_ax
            dw0 = dwp + cross(wp, v_ax) + a_ax
            a0 = a_par
        w[:, i], dw[:, i], a[:, i] = w0, dw0, a0
    return LinkMotion(R, p, w, dw, a)


def prepare_states(
    robot: Robot,
    q: ArrayLike,
    dq: ArrayLike,
    ddq: ArrayLike,
    names: tuple[str, str, str] = ("q", "dq", "ddq"),
):
    """Checked states for the batched routines (here and in the regressors): the broadcast
    batch shape and ``q, dq, ddq`` as float64 arrays of shape (B, n); errors use ``names``
    (the third is ``tau`` for the forward dynamics)."""
    n = robot.n
    q = _checks.as_batch(names[0], q, (n,))
    dq = _checks.as_batch(names[1], dq, (n,))
    ddq = _checks.as_batch(names[2], ddq, (n,))
    try:
        shape = np.broadcast_shapes(q.shape, dq.shape, ddq.shape)
    except ValueError:
        raise ShapeError(
            f"{names[0]}, {names[1]} and {names[2]} must broadcast together; got {q.shape}, "
            f"{dq.shape}, {ddq.shape}"
        ) from None
    flat = [np.broadcast_to(x, shape).reshape(-1, n) for x in (q, dq, ddq)]
    return shape, flat


@_kernels.single_sample(_RNEA, "states", "vector")
def rnea(
    robot: Robot,
    q: ArrayLike,
    dq: ArrayLike,
    ddq: ArrayLike,
    *,
    gravity: ArrayLike | None = None,
) -> NDArray[np.float64]:
    """Inverse dynamics of the links: joint torques for given positions, velocities and
    accelerations.

    .. math:: \\tau = M(q) \\ddot q + c(q, \\dot q) + g(q)

    of the links' standard parameters ``robot.phi`` alone. Not included, even where the
    robot holds them: its friction (``robot.friction``, offsets included), its joint spring
    (``robot.spring``, ``k (q - q0)``), rotor inertias (a drive's ``rotor_inertia``, an
    MJCF's ``armature``), nor an identified model's other terms. A model's whole torques,
    as ``validate`` and ``identify`` predict them (a ``feasible.json`` or robot file read
    back, an :class:`~dynid.identification.model.IdentifiedModel`), are
    :func:`dynid.model_torques` (:func:`dynid.friction.validation.model_torques`).

    Parameters
    ----------
    robot : Robot
        Kinematics and standard parameters ``robot.phi``.
    q, dq, ddq : array_like, shape (..., n)
        Joint positions [rad], velocities [rad/s], accelerations [rad/s^2] (m, m/s, m/s^2
        for prismatic joints). Batch shapes broadcast.
    gravity : array_like, shape (3,), optional
        Gravity in the base frame [m/s^2]; default ``robot.gravity``; zeros to remove it.

    Returns
    -------
    tau : ndarray, shape (..., n)
        Joint torques [N m] (forces [N] for prismatic joints) of the links alone.

    Raises
    ------
    ShapeError
        An input does not end in ``n`` or the batch shapes do not broadcast.
    NonFiniteError
        An input holds NaN or inf.

    Notes
    -----
    Uses the compiled kernel when available (see :func:`kernels`), else :func:`rnea_numpy`.
    """
    checked_robot(robot)
    if gravity is None:
        # float64 arrays of one shape (..., n) go to the kernel as they are; the kernel
        # checks finiteness, and anything else (or a failure) falls through to the full
        # validation below
        tau = _kernels.run(_RNEA, robot, (q, dq, ddq), (len(robot.joint_names),))
        if tau is not None:
            return tau
    shape, (q2, dq2, ddq2) = prepare_states(robot, q, dq, ddq)
    g = robot.gravity if gravity is None else _checks.as_exact("gravity", gravity, (3,))
    return _rnea(robot, robot.phi, q2, dq2, ddq2, g).reshape(shape)


def rnea_numpy(
    robot: Robot,
    q: ArrayLike,
    dq: ArrayLike,
    ddq: ArrayLike,
    *,
    gravity: ArrayLike | None = None,
) -> NDArray[np.float64]:
    """:func:`rnea` by the numpy reference path, never the compiled kernel.

    Same parameters, result, shapes and errors as :func:`rnea`.
    """
    shape, (q2, dq2, ddq2) = prepare_states(robot, q, dq, ddq)
    g = robot.gravity if gravity is None else _checks.as_exact("gravity", gravity, (3,))
    return _rnea_numpy(robot, robot.phi, q2, dq2, ddq2, g).reshape(shape)


def _rnea(
    robot: Robot,
    phi: NDArray[np.float64],
    q: NDArray[np.float64],
    dq: NDArray[np.float64],
    ddq: NDArray[np.float64],
    gravity: NDArray[np.float64],
) -> NDArray[np.float64]:
    """RNEA on validated (B, n) arrays with standard parameters ``phi`` (n, 10).

    The compiled kernel when available, else :func:`_rnea_numpy`. ``dq`` and ``ddq`` may
    also be (1, n), one row for every sample.
    """
    K = _kernels.compiled(_RNEA, 1 + (q.shape[0] > 1))
    if K is not None:
        B, n = q.shape
        if dq.shape[0] in (1, B) and ddq.shape[0] in (1, B):
            tau = np.empty((B, n))
            C = _kernels.constants_for(robot, phi, gravity)
            f = _RNEA.batch  # (the batch kernel takes one row of dq or ddq for all)
            if f(C, _kernels.flat(q), _kernels.flat(dq), _kernels.flat(ddq), tau.reshape(-1)):
                return tau
    return _rnea_numpy(robot, phi, q, dq, ddq, gravity)


def _rnea_numpy(
    robot: Robot,
    phi: NDArray[np.float64],
    q: NDArray[np.float64],
    dq: NDArray[np.float64],
    ddq: NDArray[np.float64],
    gravity: NDArray[np.float64],
) -> NDArray[np.float64]:
    """RNEA on validated (B, n) arrays with standard parameters ``phi`` (n, 10)."""
    B, n = q.shape
    mot = link_motion(robot, q, dq, ddq, gravity)
    m = phi[:, 0]
    mc = phi[:, 1:4]
    J = matrix_from_inertia6(phi[:, 4:])
    tau = np.empty((B, n))
    F = np.zeros((B, 3))
    N = np.zeros((B, 3))
    for i in range(n - 1, -1, -1):
        w, dw, a = mot.w[:, i], mot.dw[:, i], mot.a[:, i]
        f = m[i] * a + cross(dw, mc[i]) + cross(w, cross(w, mc[i]))
        Jw = w @ J[i].T
        nn = dw @ J[i].T + cross(w, Jw) + cross(mc[i], a)
        if i < n - 1:
            Rn, pn = mot.R[:, i + 1], mot.p[:, i + 1]
            RF = _rv(Rn, F)
            N = nn + _rv(Rn, N) + cross(pn, RF)
            F = f + RF
        else:
            F, N = f, nn
        tau[:, i] = (F if robot.prismatic[i] else N) @ robot.axes[i]
    return tau
