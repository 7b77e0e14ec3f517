"""The generalized momentum ``p = M(q) dq`` and ``g(q) - C^T(q, dq) dq``, and their regressor.

Two paths compute the same numbers (to rounding):

* :func:`momentum_terms`: the compiled pass of :mod:`dynid._kernels.observer` (one outward
  pass for the link velocities, one inward pass for the subtree momenta: ``p_i = S_i^T H_i``,
  ``(C^T dq)_i = (v_i x S_i)^T H_i``), never a Coriolis matrix;
* :func:`momentum_regressor`: ``p`` and ``C^T dq`` are linear in the standard parameters,
  ``p = Y_p(q, dq) phi`` and ``C^T dq = Y_c(q, dq) phi``; each link's momentum about its
  origin is ``P = m v + w x h``, ``L = J w + h x v`` in its own axes, carried to the base and
  projected on the joints (``Y_p``) or on ``v_i x S_i`` (``Y_c``); with the static regressor
  ``Y_g`` (the torque regressor at rest), ``g - C^T dq = (Y_g - Y_c) phi``. Over the base
  parameters (:func:`base_momentum_regressor`) the same columns are picked as for the
  torque regressor: ``p = Y_p,b beta``.

:func:`momentum_terms_numpy` is the numpy twin of the kernel (the regressor times ``phi``).
``C^T dq`` is Pinocchio's ``computeCoriolisMatrix(q, dq).T @ dq``; a rotor term adds to
``p`` and not to ``C^T dq`` (its inertia is constant).
"""

from __future__ import annotations

import numpy as np
from numpy.typing import ArrayLike, NDArray

from .. import _checks, _kernels
from ..dynamics.rnea import cross
from ..kinematics.forward import link_poses
from ..model.robot import Robot
from ..regressors.torque import inertia_operator, torque_regressor
from ..spatial import skew
from .model import ObserverModel

__all__ = [
    "base_momentum_regressor",
    "momentum_regressor",
    "momentum_terms",
    "momentum_terms_numpy",
]

_TERMS = _kernels.KERNELS["momentum_terms"]


def _states(
    robot: Robot, q: ArrayLike, dq: ArrayLike
) -> tuple[tuple[int, ...], NDArray[np.float64], NDArray[np.float64]]:
    n = robot.n
    qa = _checks.as_batch("q", q, (n,))
    dqa = _checks.as_batch("dq", dq, (n,))
    if qa.shape != dqa.shape:
        raise _shape_error(qa.shape, dqa.shape)
    return qa.shape[:-1], qa.reshape(-1, n), dqa.reshape(-1, n)


def _shape_error(a: tuple[int, ...], b: tuple[int, ...]) -> Exception:
    from ..exceptions import ShapeError

    return ShapeError(f"q and dq must have the same shape; got {a} and {b}")


def momentum_terms(
    model: ObserverModel | Robot, q: ArrayLike, dq: ArrayLike
) -> tuple[NDArray[np.float64], NDArray[np.float64]]:
    """Generalized momentum ``p = M(q) dq`` and ``beta = g(q) - C^T(q, dq) dq``.

    Parameters
    ----------
    model : ObserverModel or Robot
        An observer model (its rotor part included in ``p``) or a robot's links alone.
    q, dq : array_like, shape (..., n)
        Joint positions [rad] and velocities [rad/s].

    Returns
    -------
    p : ndarray, shape (..., n)
        [N m s].
    beta : ndarray, shape (..., n)
        [N m]; the observer's ``tau + C^T dq - g`` is ``tau - beta``.

    Raises
    ------
    ShapeError, NonFiniteError
    """
    robot = model.robot if isinstance(model, ObserverModel) else model
    shape, q2, dq2 = _states(robot, q, dq)
    p, b = None, None
    K = _kernels.compiled(_TERMS, 2)
    if K is not None:
        p, b = np.empty(q2.shape), np.empty(q2.shape)
        flat = _kernels.flat
        if not K(_kernels.constants(robot), flat(q2), flat(dq2), p.reshape(-1), b.reshape(-1)):
            p = None
    if p is None or b is None:
        p, b = _terms_numpy(robot, q2, dq2)
    if isinstance(model, ObserverModel):
        p = p + dq2 @ model.rotor_mass.T
    n = robot.n
    return p.reshape(shape + (n,)), b.reshape(shape + (n,))


def momentum_terms_numpy(
    robot: Robot, q: ArrayLike, dq: ArrayLike
) -> tuple[NDArray[np.float64], NDArray[np.float64]]:
    """:func:`momentum_terms` of a robot's links by the regressor (numpy), never the kernel.

    Same parameters, results, shapes and errors as :func:`momentum_terms` on a Robot.
    """
    shape, q2, dq2 = _states(robot, q, dq)
    p, b = _terms_numpy(robot, q2, dq2)
    n = robot.n
    return p.reshape(shape + (n,)), b.reshape(shape + (n,))


def _terms_numpy(
    robot: Robot, q2: NDArray[np.float64], dq2: NDArray[np.float64]
) -> tuple[NDArray[np.float64], NDArray[np.float64]]:
    Yp, Yc = _regressor(robot, q2, dq2)
    phi = robot.phi.reshape(-1)
    Yg = torque_regressor(robot, q2, np.zeros_like(q2), np.zeros_like(q2))
    return Yp @ phi, (Yg - Yc) @ phi


def _regressor(
    robot: Robot, q2: NDArray[np.float64], dq2: NDArray[np.float64]
) -> tuple[NDArray[np.float64], NDArray[np.float64]]:
    """``(Y_p, Y_c)``, each (B, n, 10 n), for validated (B, n) states (module docstring)."""
    B, n = q2.shape
    T = link_poses(robot, q2)
    R0, o = T[:, 1:, :3, :3], T[:, 1:, :3, 3]
    z = (R0 @ robot.axes[:, :, None])[..., 0]
    w, v, prev = np.zeros((B, 3)), np.zeros((B, 3)), np.zeros((B, 3))
    Wb, Vb = np.empty((B, n, 3)), np.empty((B, n, 3))
    for i in range(n):  # link velocities in the base frame (v: of the link's origin)
        v = v + cross(w, o[:, i] - prev)
        if robot.prismatic[i]:
            v = v + z[:, i] * dq2[:, i, None]
        else:
            w = w + z[:, i] * dq2[:, i, None]
        Wb[:, i], Vb[:, i], prev = w, v, o[:, i]
    Rt = np.swapaxes(R0, -1, -2)
    wl, vl = (Rt @ Wb[..., None])[..., 0], (Rt @ Vb[..., None])[..., 0]
    K = np.zeros((B, n, 6, 10))  # (P; L) of the link about its origin, link axes
    K[..., :3, 0] = vl
    K[..., :3, 1:4] = skew(wl)
    K[..., 3:, 1:4] = -skew(vl)
    K[..., 3:, 4:] = inertia_operator(wl)
    H = np.empty_like(K)  # about the base origin, base axes
    H[..., :3, :] = R0 @ K[..., :3, :]
    H[..., 3:, :] = R0 @ K[..., 3:, :] + skew(o) @ H[..., :3, :]
    pri = robot.prismatic[:, None]
    s0 = cross(o, z)
    A = np.concatenate([np.where(pri, z, s0), np.where(pri, 0.0, z)], axis=-1)
    vO = Vb - cross(Wb, o)  # velocity of the body point at the base origin
    Ac = np.concatenate(
        [
            np.where(pri, cross(Wb, z), cross(Wb, s0) + cross(vO, z)),
            np.where(pri, 0.0, cross(Wb, z)),
        ],
        axis=-1,
    )
    Hs = H.transpose(0, 2, 1, 3).reshape(B, 6, 10 * n)
    mask = np.repeat(np.triu(np.ones((n, n))), 10, axis=1)
    return (A @ Hs) * mask, (Ac @ Hs) * mask


def momentum_regressor(
    robot: Robot, q: ArrayLike, dq: ArrayLike
) -> tuple[NDArray[np.float64], NDArray[np.float64]]:
    """Regressors of ``p`` and ``g - C^T dq`` in the standard parameters.

    .. math:: p = Y_p(q, \\dot q)\\, \\phi, \\qquad g - C^T \\dot q = Y_\\beta(q, \\dot q)\\, \\phi

    Parameters
    ----------
    robot : Robot
    q, dq : array_like, shape (..., n)

    Returns
    -------
    Y_p, Y_beta : ndarray, shape (..., n, 10 n)
        Columns labelled by ``robot.param_labels``.

    Raises
    ------
    ShapeError, NonFiniteError
    """
    shape, q2, dq2 = _states(robot, q, dq)
    Yp, Yc = _regressor(robot, q2, dq2)
    Yg = torque_regressor(robot, q2, np.zeros_like(q2), np.zeros_like(q2))
    w = (robot.n, 10 * robot.n)
    return Yp.reshape(shape + w), (Yg - Yc).reshape(shape + w)


def base_momentum_regressor(
    model: ObserverModel, q: ArrayLike, dq: ArrayLike
) -> tuple[NDArray[np.float64], NDArray[np.float64]]:
    """:func:`momentum_regressor` over an identified model's base parameters.

    ``p = Y_p beta (+ M_r dq for rotor inertias known, not identified)`` and
    ``g - C^T dq = Y_beta beta``; the model's terms in the base (identified rotor
    inertias, standard parameters after the links') give their own momentum columns
    (:meth:`~dynid.regressors.terms.ModelTerm.momentum_columns`: ``K_k^T (K_k dq)`` for
    rotor ``k``).

    Returns
    -------
    Y_p, Y_beta : ndarray, shape (..., n, r)

    Raises
    ------
    ShapeError
        A model without base parameters (a robot's own parameters), base parameters over
        other terms than the model's, bad shapes.
    """
    from ..exceptions import ShapeError

    if model.base is None:
        raise ShapeError("the model has no base parameters (a robot's own link parameters)")
    robot = model.robot
    shape, q2, dq2 = _states(robot, q, dq)
    n, B = robot.n, q2.shape[0]
    Yp, Yc = _regressor(robot, q2, dq2)
    Yg = torque_regressor(robot, q2, np.zeros_like(q2), np.zeros_like(q2))
    p_std = model.base.n_std
    Fp, Fb = np.zeros((B, n, p_std)), np.zeros((B, n, p_std))
    Fp[..., : 10 * n], Fb[..., : 10 * n] = Yp, Yg - Yc
    start = 10 * n
    for term in model.base_terms:  # each term's own columns, in the base's order
        k = len(term.labels)
        if start + k > p_std:
            break
        Fp[..., start : start + k] = term.momentum_columns(q2, dq2)
        # constant inertia: its torque without acceleration is all it adds to g - C^T dq
        Fb[..., start : start + k] = term.torque_columns(q2, dq2, np.zeros_like(q2))
        start += k
    if start != p_std:
        raise ShapeError(
            f"the base's {p_std} standard parameters are not the links' {10 * n} and those "
            f"of the model's terms in the base ({start - 10 * n})"
        )
    idx = np.asarray(model.base.independent)
    r = idx.size
    return Fp[..., idx].reshape(shape + (n, r)), Fb[..., idx].reshape(shape + (n, r))
