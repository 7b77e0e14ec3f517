"""Simulated contacts: an external wrench on a link over a time window.

A :class:`Contact` pushes with the wrench ``w = [f; m]`` (force [N], moment [N m], base
axes) at the origin of a frame of the robot (a link's frame, ``flange``, a tool) from
``start`` to ``end`` [s], switched on and off linearly over ``ramp`` seconds (0: a step).
The external joint torque is

.. math:: \\tau_{ext}(t) = \\sum_c s_c(t)\\, J_c(q)^T w_c

with ``J_c`` the frame's geometric Jacobian (:func:`dynid.kinematics.jacobian.jacobian`,
rows ``v, w``) and ``s_c`` the window. The simulated arm still follows its trajectory (its
controller compensates the contact), so the motors give
``tau = M ddq + c + g + tau_f - tau_ext`` (:mod:`dynid.simulation.measurement`): the
momentum observer's residual of an exact model then converges to ``tau_ext``.
"""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import dataclass

import numpy as np
from numpy.typing import ArrayLike, NDArray

from .. import _checks
from ..exceptions import OptionError
from ..kinematics.jacobian import jacobian
from ..model.robot import Robot

__all__ = ["Contact", "contact_torques"]


@dataclass(frozen=True, slots=True)
class Contact:
    """An external wrench at a frame over a time window (module docstring).

    Attributes
    ----------
    frame : str
        A frame of the robot (``link4``, ``flange``).
    wrench : tuple of float
        ``fx, fy, fz`` [N] then ``mx, my, mz`` [N m] in base axes, at the frame's origin; 3
        values are a force alone.
    start, end : float
        Window [s], ``start < end``.
    ramp : float
        Rise and fall time [s] (linear), at most half the window; 0: a step.

    Raises
    ------
    OptionError
        Not 3 or 6 finite wrench values, an empty window, a ramp longer than half of it.
    """

    frame: str
    wrench: tuple[float, ...]
    start: float
    end: float
    ramp: float = 0.0

    def __post_init__(self) -> None:
        w = np.asarray(self.wrench, dtype=np.float64).reshape(-1)
        if w.size not in (3, 6) or not np.all(np.isfinite(w)):
            raise OptionError(
                f"contact wrench must be 3 or 6 finite numbers; got {_checks.short(self.wrench)}"
            )
        object.__setattr__(
            self, "wrench", tuple(float(x) for x in np.concatenate([w, np.zeros(6 - w.size)]))
        )
        if not (np.isfinite(self.start) and np.isfinite(self.end) and self.start < self.end):
            raise OptionError(
                f"contact window must have start < end [s]; got {self.start}, {self.end}"
            )
        if not 0.0 <= self.ramp <= 0.5 * (self.end - self.start):
            raise OptionError(
                f"contact ramp must be in [0, half the window] [s]; got {self.ramp} for "
                f"[{self.start}, {self.end}]"
            )

    def profile(self, t: ArrayLike) -> NDArray[np.float64]:
        """The window ``s(t)`` in [0, 1] (..., as ``t``): 1 on ``[start + ramp, end - ramp]``,
        0 before ``start`` and from ``end`` on."""
        ta = np.asarray(t, dtype=np.float64)
        if self.ramp == 0.0:
            return ((ta >= self.start) & (ta < self.end)).astype(np.float64)
        up = (ta - self.start) / self.ramp
        down = (self.end - ta) / self.ramp
        return np.clip(np.minimum(up, down), 0.0, 1.0)


def contact_torques(
    robot: Robot, contacts: Sequence[Contact], t: ArrayLike, q: ArrayLike
) -> NDArray[np.float64]:
    """External joint torques ``tau_ext`` (N, n) [N m] of ``contacts`` at times ``t`` (N,)
    and positions ``q`` (N, n).

    Raises
    ------
    ShapeError, NonFiniteError, UnknownNameError
        Bad shapes, NaN, a frame the robot does not have.
    """
    ta = _checks.as_array("t", t)
    qa = _checks.as_exact("q", q, (ta.shape[0], robot.n))
    out = np.zeros(qa.shape)
    for c in contacts:
        s = c.profile(ta)
        on = np.flatnonzero(s)
        if on.size == 0:
            robot.frame(c.frame)  # an unknown frame is an error even outside its window
            continue
        J = jacobian(robot, qa[on], c.frame)
        out[on] += s[on, None] * (np.swapaxes(J, -1, -2) @ np.asarray(c.wrench))
    return out
