"""Validation of a dynamic model, with or without friction, against a measured torque log.

The prediction is ``tau_hat = M ddq + c + g (+ tau_f(dq))`` from a rigid-body model (an
:class:`~dynid.identification.model.IdentifiedModel`, a :class:`~dynid.model.robot.Robot`
through RNEA, or a callable; see :data:`~dynid.friction.fit.TorqueModel`) and an optional
friction model (:mod:`dynid.friction.model`). The log is prepared as for the friction fit
(states low-pass filtered with zero phase, ``ddq`` from the filtered ``dq``, edges trimmed,
measured torques kept unfiltered by default), and the per-joint RMS, MSE and relative
error of :mod:`dynid.identification.metrics` are computed without and with friction
(Gaz et al. 2019, Sec. VI, Fig. 3 and Table II). With unfiltered torques the RMS of a
correct model equals the sensor noise.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
from numpy.typing import NDArray

from ..exceptions import ShapeError
from ..identification.log import DEFAULT_CUTOFF_HZ, TorqueLog
from ..identification.metrics import TorqueErrors, torque_errors
from ..identification.model import IdentifiedModel
from ..model.robot import Robot
from .fit import TorqueModel, friction_residual
from .model import ClassicalFriction, FrictionModel, SigmoidFriction

__all__ = ["Validation", "own_friction", "validate"]


def own_friction(model: TorqueModel) -> FrictionModel | None:
    """The friction that comes with a model: an IdentifiedModel's classical ``friction``,
    a Robot's sigmoid ``friction``, or None."""
    if isinstance(model, IdentifiedModel) and model.friction is not None:
        return ClassicalFriction.from_array(model.friction)
    if isinstance(model, Robot) and model.friction is not None:
        return SigmoidFriction.from_array(model.friction)
    return None


@dataclass(frozen=True, slots=True, eq=False)
class Validation:
    """Predicted against measured torques on a prepared log.

    Attributes
    ----------
    log : TorqueLog
        Prepared log (filtered states, ``ddq``, trimmed).
    tau_model : ndarray, shape (N, n)
        Rigid-body prediction [N m].
    tau_friction : ndarray, shape (N, n), or None
        Friction prediction [N m].
    without_friction : TorqueErrors
        Errors of ``tau_model``.
    with_friction : TorqueErrors or None
        Errors of ``tau_model + tau_friction``.
    friction : FrictionModel or None
    """

    log: TorqueLog
    tau_model: NDArray[np.float64]
    tau_friction: NDArray[np.float64] | None
    without_friction: TorqueErrors
    with_friction: TorqueErrors | None
    friction: FrictionModel | None

    @property
    def tau_hat(self) -> NDArray[np.float64]:
        """The full prediction [N m] (N, n), friction included when given."""
        if self.tau_friction is None:
            return self.tau_model
        return self.tau_model + self.tau_friction

    @property
    def errors(self) -> TorqueErrors:
        """Errors of the full prediction (with friction when given)."""
        return self.with_friction if self.with_friction is not None else self.without_friction

    def as_dict(self) -> dict[str, object]:
        """JSON-ready summary: ``rms``, ``mse``, ``relative_error_percent`` of the full
        prediction, plus ``without_friction`` (and ``with_friction``) blocks."""
        out: dict[str, object] = dict(self.errors.as_dict())
        out["friction_model"] = None if self.friction is None else self.friction.kind
        out["without_friction"] = self.without_friction.as_dict()
        if self.with_friction is not None:
            out["with_friction"] = self.with_friction.as_dict()
        return out


def validate(
    model: TorqueModel,
    log: TorqueLog,
    *,
    friction: FrictionModel | None = None,
    cutoff_hz: float | None = DEFAULT_CUTOFF_HZ,
    trim_s: float | None = None,
    filter_tau: bool = False,
    max_gap_s: float | None = None,
) -> Validation:
    """Compare a model's torques with a measured log, without and with friction.

    Parameters
    ----------
    model : TorqueModel
        Rigid-body model (IdentifiedModel, Robot or callable ``f(q, dq, ddq)``).
    log : TorqueLog
        Measured log (e.g. the validation sinusoids, Gaz et al. 2019 eq. 31).
    friction : FrictionModel, optional
        Friction added to the prediction (e.g. :func:`own_friction` of the model, or a
        fitted sigmoid).
    cutoff_hz, trim_s, filter_tau, max_gap_s
        Preparation of the log (:func:`~dynid.friction.fit.friction_residual`).

    Returns
    -------
    Validation

    Raises
    ------
    ShapeError
        The friction model's joint count differs from the log's.
    DataError
        From the preparation of the log.
    """
    if friction is not None and friction.n != log.n:
        raise ShapeError(f"friction model has {friction.n} joints; the log has {log.n}")
    res = friction_residual(
        model, log, cutoff_hz=cutoff_hz, trim_s=trim_s, filter_tau=filter_tau, max_gap_s=max_gap_s
    )
    p, tau_model = res.log, res.tau_model
    # free what is no longer needed before the friction torques (a long log's raw signals,
    # when the caller holds no other reference, and the residual)
    del res, log
    without = torque_errors(p.tau, tau_model)
    tf = with_ = None
    if friction is not None:
        tf = np.empty(p.dq.shape)
        step = 65_536  # blocks of rows: a long log needs no full-size temporaries
        for k in range(0, p.dq.shape[0], step):
            tf[k : k + step] = friction.torques(p.dq[k : k + step])
        tau_hat = tau_model + tf
        with_ = torque_errors(p.tau, tau_hat)
        del tau_hat
    return Validation(
        log=p,
        tau_model=tau_model,
        tau_friction=tf,
        without_friction=without,
        with_friction=with_,
        friction=friction,
    )
