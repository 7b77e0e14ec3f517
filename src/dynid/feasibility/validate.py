"""Newton-Euler validation of retrieved feasible parameters (Gaz et al. 2019, Fig. 5).

Feasible link parameters are a physical body set, so they can drive a standard
Newton-Euler inverse dynamics (RNEA, :func:`dynid.rnea`) or a simulator. The validation
predicts the joint torques of a trajectory the friction was *not* fitted on,

.. math:: \\hat\\tau = \\mathrm{RNEA}(q, \\dot q, \\ddot q; \\hat p) + \\tau_f(\\dot q)

and compares them with the measured ones, per joint (RMS). The friction convention is
:mod:`dynid.friction.model`'s: ``tau = M ddq + c + g + tau_f(dq)``, the sigmoid of eq. 25,
``tau_f = phi1 / (1 + exp(-phi2 (dq + phi3))) - phi1 / (1 + exp(-phi2 phi3))`` as held in
``Robot.friction`` (columns ``phi1 [N m], phi2 [s/rad], phi3 [rad/s]``). Optionally the
identified Lagrangian model ``Y_b beta`` is evaluated on the same states for comparison.

The arrays are taken as given (no filtering): prepare a recorded log first
(:func:`dynid.identification.log.prepare_log`) when ``ddq`` must be differentiated.

The physical-validity check (Drake's ``IsPhysicallyValid``) lives in
:mod:`dynid.feasibility.constraints` (``validate``); it is re-exported here as
:func:`is_physically_valid`.
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import Any

import numpy as np
from numpy.typing import ArrayLike, NDArray

from .. import _checks
from ..dynamics.rnea import rnea
from ..exceptions import OptionError, ShapeError
from ..friction.model import ClassicalFriction, SigmoidFriction
from ..identification.metrics import TorqueErrors, torque_errors
from ..identification.model import IdentifiedModel
from ..model.robot import Robot
from .constraints import validate as is_physically_valid

__all__ = ["NewtonEulerValidation", "is_physically_valid", "validate_newton_euler"]


@dataclass(frozen=True, slots=True, eq=False)
class NewtonEulerValidation:
    """Predicted against measured torques on a validation trajectory.

    Attributes
    ----------
    t : ndarray, shape (N,)
        Sample times [s].
    tau : ndarray, shape (N, n)
        Measured torques [N m].
    tau_rigid : ndarray, shape (N, n)
        RNEA torques with the feasible parameters [N m], friction excluded.
    tau_friction : ndarray, shape (N, n), or None
        Friction torques [N m] (None without a friction model).
    tau_reference : ndarray, shape (N, n), or None
        Identified model's torques ``Y_b beta`` (+ the same friction) [N m], if given.
    errors : TorqueErrors
        Of ``tau_model`` (rigid + friction) against ``tau``: per-joint ``rms`` [N m], ...
    errors_rigid : TorqueErrors
        Of ``tau_rigid`` alone.
    errors_reference : TorqueErrors or None
        Of ``tau_reference``.
    joint_names : tuple of str
    friction_kind : str or None
        ``"sigmoid"``, ``"classical"`` or None.
    """

    t: NDArray[np.float64]
    tau: NDArray[np.float64]
    tau_rigid: NDArray[np.float64]
    tau_friction: NDArray[np.float64] | None
    tau_reference: NDArray[np.float64] | None
    errors: TorqueErrors
    errors_rigid: TorqueErrors
    errors_reference: TorqueErrors | None
    joint_names: tuple[str, ...]
    friction_kind: str | None

    @property
    def tau_model(self) -> NDArray[np.float64]:
        """Full prediction, RNEA plus friction [N m] (N, n)."""
        return self.tau_rigid if self.tau_friction is None else self.tau_rigid + self.tau_friction

    @property
    def rms(self) -> NDArray[np.float64]:
        """Per-joint RMS error of the full prediction [N m] (n,)."""
        return self.errors.rms

    def as_dict(self) -> dict[str, Any]:
        """JSON-ready summary (floats and lists)."""
        out: dict[str, Any] = {
            "joint_names": list(self.joint_names),
            "friction_model": self.friction_kind,
            "newton_euler": self.errors.as_dict(),
            "newton_euler_no_friction": self.errors_rigid.as_dict(),
            "units": {"rms": "N m", "mse": "N^2 m^2", "relative_error_percent": "%"},
        }
        if self.errors_reference is not None:
            out["identified_model"] = self.errors_reference.as_dict()
        return out


def _friction_model(robot: Robot, friction: Any) -> SigmoidFriction | ClassicalFriction | None:
    if isinstance(friction, str):
        if friction != "robot":
            raise OptionError(
                "friction must be 'robot', None, a friction model or an (n, 3) array; "
                f"got {friction!r}"
            )
        return None if robot.friction is None else SigmoidFriction.from_array(robot.friction)
    if friction is None or isinstance(friction, (SigmoidFriction, ClassicalFriction)):
        model = friction
    else:
        model = SigmoidFriction.from_array(friction)
    if model is not None and model.n != robot.n:
        raise ShapeError(f"friction model has {model.n} joints; robot {robot.name!r} has {robot.n}")
    return model


def validate_newton_euler(
    robot: Robot,
    t: ArrayLike,
    q: ArrayLike,
    dq: ArrayLike,
    ddq: ArrayLike,
    tau: ArrayLike,
    *,
    friction: Any = "robot",
    reference: IdentifiedModel | None = None,
) -> NewtonEulerValidation:
    """Compare Newton-Euler torques of a parameter set (plus friction) with measurements.

    .. math:: \\hat\\tau_k = \\mathrm{RNEA}(q_k, \\dot q_k, \\ddot q_k) + \\tau_f(\\dot q_k),
              \\quad \\mathrm{RMS}_j = \\sqrt{\\tfrac{1}{N}
              \\textstyle\\sum_k (\\tau_{kj} - \\hat\\tau_{kj})^2}

    Parameters
    ----------
    robot : Robot
        Kinematics, gravity and the (feasible) link parameters, e.g.
        ``RetrievalResult.robot``.
    t : array_like, shape (N,)
        Sample times [s].
    q, dq, ddq : array_like, shape (N, n)
        Joint positions [rad], velocities [rad/s], accelerations [rad/s^2].
    tau : array_like, shape (N, n)
        Measured joint torques [N m] (friction included).
    friction : "robot", None, SigmoidFriction, ClassicalFriction or array_like (n, 3)
        ``"robot"`` (default) uses ``robot.friction`` (sigmoid; none if the robot has
        none); an (n, 3) array is sigmoid ``phi1, phi2, phi3`` per joint.
    reference : IdentifiedModel, optional
        An identified model evaluated on the same states (with the same friction), for
        comparison.

    Returns
    -------
    NewtonEulerValidation

    Raises
    ------
    ShapeError
        Shapes disagree (``t`` (N,), the others (N, n)) or the friction model has another
        joint count.
    NonFiniteError
        NaN or inf in an input.
    """
    n = robot.n
    t = _checks.as_array("t", t)
    if t.ndim != 1:
        raise ShapeError(f"t must have shape (N,); got {t.shape}")
    N = t.shape[0]
    arrs = [
        _checks.as_exact(k, v, (N, n))
        for k, v in (("q", q), ("dq", dq), ("ddq", ddq), ("tau", tau))
    ]
    q, dq, ddq, tau = arrs
    fr = _friction_model(robot, friction)
    tau_rigid = rnea(robot, q, dq, ddq)
    tau_f = None if fr is None else fr.torques(dq)
    full = tau_rigid if tau_f is None else tau_rigid + tau_f
    tau_ref = errs_ref = None
    if reference is not None:
        if reference.robot.n != n:
            raise ShapeError(f"reference model has {reference.robot.n} joints; robot has {n}")
        tau_ref = reference.torques(q, dq, ddq)
        if tau_f is not None:
            tau_ref = tau_ref + tau_f
        errs_ref = torque_errors(tau, tau_ref)
    return NewtonEulerValidation(
        t=_checks.frozen(t),
        tau=_checks.frozen(tau),
        tau_rigid=_checks.frozen(tau_rigid),
        tau_friction=None if tau_f is None else _checks.frozen(tau_f),
        tau_reference=None if tau_ref is None else _checks.frozen(tau_ref),
        errors=torque_errors(tau, full),
        errors_rigid=torque_errors(tau, tau_rigid),
        errors_reference=errs_ref,
        joint_names=robot.joint_names,
        friction_kind=None if fr is None else fr.kind,
    )
