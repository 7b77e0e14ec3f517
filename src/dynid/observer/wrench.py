"""The external wrench at a frame from the residual, by damped least squares.

The residual estimates the external joint torque ``tau_ext = J(q)^T w`` of a wrench
``w = [f; m]`` (force [N], moment [N m], base axes) at a frame's origin, ``J`` its
geometric Jacobian (:func:`dynid.kinematics.jacobian.jacobian`, rows ``v, w``):

.. math:: \\hat w = (J J^T + \\lambda^2 E)^{-1} J r, \\qquad
          \\lambda^2 = \\lambda_{max}^2 \\big(1 - (\\sigma_{min} / \\epsilon)^2\\big)
          \\text{ where } \\sigma_{min} < \\epsilon \\text{, else } 0

(Nakamura and Hanafusa 1986; Chiaverini 1997): plain least squares away from singular
configurations, damped near them, where ``sigma_min``, the smallest singular value of ``J``,
falls below ``epsilon``; those samples are flagged. A frame with fewer than six joints before
it never determines a whole wrench: every sample is then flagged.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
from numpy.typing import ArrayLike, NDArray

from .. import _checks
from ..exceptions import OptionError
from ..kinematics.jacobian import jacobian
from ..model.robot import Robot

__all__ = ["WrenchEstimate", "external_wrench"]


@dataclass(frozen=True, slots=True, eq=False)
class WrenchEstimate:
    """External wrenches at a frame.

    Attributes
    ----------
    frame : str
    wrench : ndarray, shape (..., 6)
        ``fx, fy, fz`` [N], ``mx, my, mz`` [N m], base axes, at the frame's origin.
    sigma_min : ndarray, shape (...)
        Smallest singular value of the frame's Jacobian.
    damped : ndarray of bool, shape (...)
        Near a singular configuration (``sigma_min < epsilon``): the estimate is damped.
    """

    frame: str
    wrench: NDArray[np.float64]
    sigma_min: NDArray[np.float64]
    damped: NDArray[np.bool_]


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
        Smallest singular value below which the solution is damped (> 0).
    damping : float
        Largest damping ``lambda_max`` (> 0).

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
    J = jacobian(robot, qa, frame)
    JJ = J @ np.swapaxes(J, -1, -2)
    s2 = np.clip(np.linalg.eigvalsh(JJ)[..., 0], 0.0, None)  # sigma_min^2
    smin = np.sqrt(s2)
    damped = smin < epsilon
    lam2 = np.where(damped, damping**2 * (1.0 - s2 / epsilon**2), 0.0)
    A = JJ + lam2[..., None, None] * np.eye(6)
    b = (J @ ra[..., None])[..., 0]
    w = np.asarray(np.linalg.solve(A, b[..., None])[..., 0], dtype=np.float64)
    return WrenchEstimate(frame, w, smin, damped)
