"""Effects outside the rigid-body model that real arms show, for simulated measurements.

Identified coefficients of a real robot are never exactly those of a rigid body: the motors'
rotors add their reflected inertia to the diagonal of ``M``, torque sensors carry offsets,
and the base is never exactly level. A simulated robot that has none of these gives
coefficients that a consistent parameter set reproduces exactly, which real data never
allow. :class:`UnmodelledEffects` adds them to the simulated controller
(:class:`~dynid.simulation.controller.SimulatedController`) and to simulated torque logs
(:func:`~dynid.simulation.measurement.simulate_measurement`):

.. math:: \\tilde M(q) = M(q) + \\mathrm{diag}(I_a), \\qquad
          \\tilde\\tau = \\mathrm{rnea}_{R g}(q, \\dot q, \\ddot q) + I_a \\ddot q + \\tau_0

with ``I_a`` the rotor inertia reflected to the link side [kg m^2], ``tau_0`` a constant
torque-sensor offset per joint [N m] (torque logs only: the controller's ``M`` and ``g`` are
model outputs, not sensor readings) and ``R`` a rotation of the gravity vector by
``gravity_tilt`` [rad] about ``tilt_axis`` (base frame), applied to both.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np
from numpy.typing import ArrayLike, NDArray

from .. import _checks
from ..exceptions import ShapeError
from ..model.robot import Robot

__all__ = ["UnmodelledEffects"]


@dataclass(frozen=True, slots=True, eq=False)
class UnmodelledEffects:
    """Rotor inertia, torque offsets and a gravity tilt (module docstring).

    Attributes
    ----------
    rotor_inertia : array_like, shape (n,)
        Reflected rotor inertia per joint [kg m^2] (>= 0).
    torque_offset : array_like, shape (n,)
        Constant torque-sensor offset per joint [N m].
    gravity_tilt : float
        Angle of the true gravity from the model's [rad].
    tilt_axis : array_like, shape (3,)
        Axis of that rotation in the base frame (normalised).
    """

    rotor_inertia: NDArray[np.float64]
    torque_offset: NDArray[np.float64]
    gravity_tilt: float = 0.0
    tilt_axis: ArrayLike = (1.0, 0.0, 0.0)

    def __post_init__(self) -> None:
        ia = _checks.as_array("rotor_inertia", self.rotor_inertia)
        off = _checks.as_array("torque_offset", self.torque_offset)
        if ia.ndim != 1 or off.shape != ia.shape:
            raise ShapeError(
                f"rotor_inertia and torque_offset must have shape (n,); got {ia.shape}, {off.shape}"
            )
        if np.any(ia < 0):
            raise ShapeError(f"rotor_inertia must be >= 0; got {ia.tolist()}")
        ax = _checks.as_exact("tilt_axis", self.tilt_axis, (3,))
        if not np.linalg.norm(ax) > 0 or not math.isfinite(self.gravity_tilt):
            raise ShapeError("tilt_axis must be non-zero and gravity_tilt finite")
        object.__setattr__(self, "rotor_inertia", _checks.frozen(ia))
        object.__setattr__(self, "torque_offset", _checks.frozen(off))
        object.__setattr__(self, "tilt_axis", _checks.frozen(ax / np.linalg.norm(ax)))
        object.__setattr__(self, "gravity_tilt", float(self.gravity_tilt))

    @classmethod
    def typical(cls, n: int, rng: np.random.Generator) -> UnmodelledEffects:
        """Illustrative orders of magnitude (not measurements of any arm): rotor inertia
        drawn in 0.02..0.1 kg m^2, offsets in -0.3..0.3 N m, a 0.3 degree tilt about a random
        horizontal axis."""
        a = rng.uniform(0.0, 2.0 * math.pi)
        return cls(
            rotor_inertia=rng.uniform(0.02, 0.1, n),
            torque_offset=rng.uniform(-0.3, 0.3, n),
            gravity_tilt=math.radians(0.3),
            tilt_axis=np.array([math.cos(a), math.sin(a), 0.0]),
        )

    def as_dict(self) -> dict[str, list[float] | float]:
        """JSON-ready: ``rotor_inertia`` [kg m^2], ``torque_offset`` [N m], ``gravity_tilt``
        [rad], ``tilt_axis``."""
        return {
            "rotor_inertia": [float(x) for x in self.rotor_inertia],
            "torque_offset": [float(x) for x in self.torque_offset],
            "gravity_tilt": self.gravity_tilt,
            "tilt_axis": [float(x) for x in np.asarray(self.tilt_axis)],
        }

    def describe(self) -> str:
        """One line: rotor inertia, offsets and tilt."""
        return (
            "rotor inertia "
            + " ".join(f"{x:.3f}" for x in self.rotor_inertia)
            + " kg m^2; torque offsets "
            + " ".join(f"{x:+.3f}" for x in self.torque_offset)
            + f" N m; gravity tilted {math.degrees(self.gravity_tilt):.2f} deg about the "
            + "axis ("
            + ", ".join(f"{x:.2f}" for x in np.asarray(self.tilt_axis))
            + ") of the base ("
            + " and ".join(
                f"{math.degrees(self.gravity_tilt) * float(c):.2f} deg about {a}"
                for c, a in zip(np.asarray(self.tilt_axis)[:2], "xy", strict=True)
            )
            + " to first order)"
        )

    @property
    def n(self) -> int:
        """Number of joints."""
        return int(self.rotor_inertia.shape[0])

    def check(self, robot: Robot) -> None:
        """Raise ShapeError when the effects are for another number of joints."""
        if self.n != robot.n:
            raise ShapeError(f"unmodelled effects are for {self.n} joints; robot has {robot.n}")

    def true_robot(self, robot: Robot) -> Robot:
        """``robot`` with the tilted gravity ``R g``."""
        if self.gravity_tilt == 0.0:
            return robot
        k, t = np.asarray(self.tilt_axis, dtype=np.float64), self.gravity_tilt
        K = np.array([[0.0, -k[2], k[1]], [k[2], 0.0, -k[0]], [-k[1], k[0], 0.0]])
        R = np.eye(3) + math.sin(t) * K + (1.0 - math.cos(t)) * K @ K
        return robot.with_gravity(R @ robot.gravity)

    def mass_matrix_term(self) -> NDArray[np.float64]:
        """``diag(I_a)`` (n, n) [kg m^2]."""
        return np.diag(self.rotor_inertia)

    def torques(self, ddq: ArrayLike) -> NDArray[np.float64]:
        """``I_a ddq + tau_0`` [N m]: (..., n) -> (..., n)."""
        a = _checks.as_batch("ddq", ddq, (self.n,))
        return a * self.rotor_inertia + self.torque_offset
