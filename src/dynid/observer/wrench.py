"""The external wrench at a frame from the residual, by damped least squares.

The residual estimates the external joint torque ``tau_ext = J(q)^T w`` of a wrench
``w = [f; m]`` (force [N], moment [N m], base axes) at a frame's origin, ``J`` its
geometric Jacobian (:func:`dynid.kinematics.jacobian.jacobian`, rows ``v, w``), ``k`` the
joints that move the frame (at most six) and ``D J = U S V^T`` the first ``k`` singular
triplets of the Jacobian with its linear rows divided by the chain's length ``L``
(``D = diag(E / L, E)``, :func:`chain_length`), so that its singular values are free of
units and ``epsilon`` means the same on a 0.4 m arm as on a 1 m one:

.. math:: \\hat w = D \\sum_{i \\le k} \\frac{\\sigma_i}{\\sigma_i^2 + \\lambda^2} u_i v_i^T r,
          \\qquad
          \\lambda^2 = \\lambda_{max}^2 \\big(1 - (\\sigma_k / \\epsilon)^2\\big)
          \\text{ where } \\sigma_k < \\epsilon \\text{, else } 0

(Nakamura and Hanafusa 1986; Chiaverini 1997): plain least squares away from singular
configurations, damped near them, where ``sigma_k`` falls below ``epsilon``; those samples
are flagged. Away from them, with six joints or more, this is ``(J J^T)^{-1} J r``. A frame
moved by fewer than six joints (a 5-joint arm) never determines a whole wrench: ``k``
joint torques fix only the ``k`` components in the range of ``J`` (which turns with the
pose), and the estimate is the least-norm wrench that explains them (in the norm
``L^2 |f|^2 + |m|^2``), zero
along the wrenches the joints cannot feel (``J^T a = 0``); that is no singularity and is
not flagged (:func:`underdetermined_note`).
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
from numpy.typing import ArrayLike, NDArray

from .. import _checks
from ..exceptions import OptionError
from ..kinematics.forward import fk, link_poses
from ..kinematics.jacobian import jacobian
from ..model.robot import Robot

__all__ = [
    "WrenchEstimate",
    "chain_length",
    "external_wrench",
    "underdetermined_note",
    "wrench_rank",
]


@dataclass(frozen=True, slots=True, eq=False)
class WrenchEstimate:
    """External wrenches at a frame.

    Attributes
    ----------
    frame : str
    wrench : ndarray, shape (..., 6)
        ``fx, fy, fz`` [N], ``mx, my, mz`` [N m], base axes, at the frame's origin.
    sigma_min : ndarray, shape (...)
        Smallest of the ``determined`` singular values of the frame's Jacobian, its linear
        rows divided by the chain's length (unitless; module docstring).
    damped : ndarray of bool, shape (...)
        Near a singular configuration (``sigma_min < epsilon``): the estimate is damped.
    determined : int
        Wrench components the joint torques determine: the joints moving the frame, at
        most 6; with fewer the wrench is the least-norm one (module docstring).
    """

    frame: str
    wrench: NDArray[np.float64]
    sigma_min: NDArray[np.float64]
    damped: NDArray[np.bool_]
    determined: int = 6


def external_wrench(
    robot: Robot,
    q: ArrayLike,
    r: ArrayLike,
    frame: str = "flange",
    *,
    epsilon: float = 0.05,
    damping: float = 0.05,
) -> WrenchEstimate:
    """The wrench at ``frame`` whose joint torques best explain the residual ``r``.

    Parameters
    ----------
    robot : Robot
    q : array_like, shape (..., n)
        Joint positions [rad].
    r : array_like, shape (..., n)
        Residual (external joint torques) [N m].
    frame : str
        A frame of the robot (``flange``, a link).
    epsilon : float
        Smallest singular value below which the solution is damped (> 0, unitless: a
        lever of ``epsilon`` times the chain's length).
    damping : float
        Largest damping ``lambda_max`` (> 0, unitless).

    Returns
    -------
    WrenchEstimate

    Raises
    ------
    ShapeError, NonFiniteError, UnknownNameError
        Bad shapes, NaN, an unknown frame.
    OptionError
        ``epsilon`` or ``damping`` not positive.
    """
    if not (np.isfinite(epsilon) and epsilon > 0 and np.isfinite(damping) and damping > 0):
        raise OptionError(f"epsilon and damping must be > 0; got {epsilon}, {damping}")
    qa = _checks.as_batch("q", q, (robot.n,))
    ra = _checks.as_exact("r", r, qa.shape)
    k = wrench_rank(robot, frame)
    D = np.repeat([1.0 / chain_length(robot, frame), 1.0], 3)
    J = D[:, None] * jacobian(robot, qa, frame)
    U, s, Vt = np.linalg.svd(J, full_matrices=False)  # s descending, (..., min(6, n))
    U, s, Vt = U[..., :k], s[..., :k], Vt[..., :k, :]
    smin = s[..., -1]
    damped = smin < epsilon
    lam2 = np.where(damped, damping**2 * (1.0 - smin**2 / epsilon**2), 0.0)
    gain = s / (s**2 + lam2[..., None])
    coef = gain * (Vt @ ra[..., None])[..., 0]
    w = np.asarray(D * (U @ coef[..., None])[..., 0], dtype=np.float64)
    return WrenchEstimate(frame, w, smin, damped, k)


def chain_length(robot: Robot, frame: str) -> float:
    """The length [m] of the chain that moves ``frame``: the distances from each joint's
    origin to the next one's and from the last to the frame, summed (at ``q = 0``; fixed
    for revolute joints); 1 m for a frame on the joints' origins.

    Raises
    ------
    UnknownNameError
        An unknown frame.
    """
    k = robot.frame(frame).link
    T = link_poses(robot, np.zeros(robot.n))
    p = np.vstack([T[1 : k + 1, :3, 3], fk(robot, np.zeros(robot.n), frame)[None, :3, 3]])
    length = float(np.sum(np.linalg.norm(np.diff(p, axis=0), axis=1)))
    return length if length > 0.0 else 1.0


def wrench_rank(robot: Robot, frame: str) -> int:
    """The wrench components at ``frame`` that joint torques determine: the joints that
    move it (those up to its link), at most 6.

    Raises
    ------
    UnknownNameError
        An unknown frame.
    OptionError
        A frame on the base (no joint moves it).
    """
    k = min(6, int(robot.frame(frame).link))
    if k == 0:
        raise OptionError(f"frame {frame!r} is fixed to the base: no joint torque tells its wrench")
    return k


def underdetermined_note(robot: Robot, frame: str) -> str | None:
    """One line when the joint torques cannot determine a whole wrench at ``frame`` (fewer
    than six joints move it), saying what the estimate is; None otherwise.

    Raises
    ------
    UnknownNameError
        An unknown frame.
    """
    k = wrench_rank(robot, frame)
    if k >= 6:
        return None
    return (
        f"{k} joint torques determine only {k} of the 6 wrench components at {frame} (those "
        f"in the range of its Jacobian, turning with the pose): the wrench written is the "
        f"least-norm one that explains the residual, blind to any wrench the joints do not "
        f"feel (J^T a = 0), so a force's components can differ from the true ones; 'damped' "
        f"flags only poses where the {k} joints lose one more direction"
    )
