"""The torques' lag behind the positions, read from a model's prediction of prepared logs.

:func:`validations_delay` hands the pieces of a validation (each prepared on its own, so
that no derivative spans a gap) to :func:`~dynid.identification.torque_delay.torque_delay`:
the rigid-body prediction's time derivative, the residual with the model's friction, and,
for an identified model, its own columns
(:func:`~dynid.friction.heldout_torques.beside_columns`) fitted beside the delay's, on at
most :data:`ROWS` rows, and, of a robot description, each joint's viscous, Coulomb, offset
and rotor-inertia columns (:func:`friction_columns`: a description's friction ten times off,
proportional to the velocity as the gravity torques' derivative is, read as the torques
leading by 155 ms on an xArm7 whose torques were in step; with them, -0.001 ms +- 0.17 ms, and
a true 10 ms lag 10.4 ms +- 0.4 ms); beside them, of any model, the tilt of the gravity
vector's (:func:`~dynid.identification.gravity_tilt.tilt_columns` of the description's
links, which a model read back from its file holds in
:attr:`~dynid.identification.model.IdentifiedModel.description`): a base off level, which
the held-out verdict names, leaves a residual that the delay's column would otherwise take
in part (a UR5 tilted 0.3 deg, its torques in step, read as 0.37 ms late, +- 0.1 ms; with
the tilt's columns, -0.007 ms +- 0.014 ms).
:func:`logs_delay` prepares whole logs first, as the identification cut them (``identify``
reads the fit's residual on its own recordings), or takes them as its held-out prediction
of each recording prepared them. Torques whose scale is grossly off the prediction's
(:func:`torque_scale` outside ``1 / SCALE_OFF .. SCALE_OFF``: another unit, currents read
as torques) give no delay: the residual is then the prediction's own shape, and its
projection on the prediction's derivative is no lag (an xArm's currents validated against
its torques read as leading by 143 ms, +- 31 ms).
"""

from __future__ import annotations

from collections.abc import Sequence

import numpy as np
from numpy.typing import NDArray

from ..exceptions import DynidError
from ..identification.gravity_tilt import tilt_columns
from ..identification.log import TorqueLog
from ..identification.model import IdentifiedModel
from ..identification.pieces import split_at_gaps, unwrapped, wrappable
from ..identification.serial import hac_lag
from ..identification.torque_delay import TorqueDelay, torque_delay
from ..model.drive import Drive
from ..model.robot import Robot
from ..regressors.terms import LinearFriction
from .fit import model_drive
from .heldout_torques import beside_columns
from .validation import Validation, own_friction, validate_torques, validated

__all__ = [
    "ROWS",
    "SCALE_OFF",
    "friction_columns",
    "logs_delay",
    "torque_scale",
    "validations_delay",
]

#: The most rows the delay is fitted on: a longer log gives every k-th sample (its
#: derivative taken at the full rate first), so that the check's columns stay a few tens
#: of MB beside a streamed fit of any length.
ROWS = 10_000

#: The factor beyond which the torques' scale against the prediction is grossly off
#: (:func:`torque_scale`): no delay is read from such a residual.
SCALE_OFF = 3.0


def torque_scale(parts: Sequence[Validation]) -> float:
    """``a`` of ``tau ~ a tau_hat`` [1], least squares over every sample and joint of
    ``parts``: the logged torques against the prediction with the model's friction (1:
    the same scale; 0.01: currents of torque constant times gear ratio 100 read as N m;
    nan: no prediction)."""
    num = den = 0.0
    for v in parts:
        hat = v.tau_model if v.tau_friction is None else v.tau_model + v.tau_friction
        num += float(np.sum(v.log.tau * hat))
        den += float(np.sum(hat * hat))
    return num / den if den > 0 else float("nan")


def friction_columns(log: TorqueLog, rows: NDArray[np.intp]) -> NDArray[np.float64]:
    """Each joint's viscous, Coulomb, offset and rotor-inertia columns (M, n, 4 n) at the
    rows ``rows`` (M,) of the prepared ``log`` (``dq`` [rad/s], ``sign(dq)``, 1 and
    ``ddq`` [rad/s^2] on the joint's own row; without ``ddq``, the first three): the terms a
    robot description holds wrong or not at all (a URDF's ``damping`` ten times the true
    viscous friction, no rotors), fitted beside the delay's column so that the residual they
    leave is not read as a lag (:func:`validations_delay`)."""
    q, dq = log.q[rows], log.dq[rows]
    drive = Drive.identity(q.shape[-1])
    ddq = np.zeros_like(dq) if log.ddq is None else log.ddq[rows]
    friction = LinearFriction(drive).torque_columns(q, dq, ddq)
    if log.ddq is None:
        return np.asarray(friction, dtype=np.float64)
    return np.concatenate([friction, drive.rotor_columns(ddq)], axis=-1)


def validations_delay(
    model: IdentifiedModel | Robot, parts: Sequence[Validation]
) -> TorqueDelay | None:
    """The delay of the torques behind the positions in ``parts`` (one
    :class:`~dynid.friction.validation.Validation` per prepared piece, of ``model``), or
    None when it cannot be read (too few samples, no prediction that changes) or the
    torques' scale is grossly off the prediction's (:func:`torque_scale` outside
    ``1 / SCALE_OFF .. SCALE_OFF``, or of the opposite sign). Fitted
    beside the tilt of the gravity vector's columns and, of an identified model, its own,
    of a robot description each joint's friction and rotor columns (module docstring)."""
    scale = torque_scale(parts)
    if not 1.0 / SCALE_OFF <= scale <= SCALE_OFF:  # nan too
        return None
    t, predicted, error, columns = [], [], [], []
    every = max(-(-sum(v.log.n_samples for v in parts) // ROWS), 1)  # every k-th row fitted
    robot = model.description if isinstance(model, IdentifiedModel) else model
    for v in parts:
        log = v.log
        hat = v.tau_model if v.tau_friction is None else v.tau_model + v.tau_friction
        t.append(log.t)
        predicted.append(v.tau_model)
        error.append(log.tau - hat)
        rows = np.arange(0, log.n_samples, every)
        tilt = tilt_columns(robot, log.q[rows])  # the description's links; zero without
        if isinstance(model, IdentifiedModel):
            beside = beside_columns(model, log)
            if beside is not None:
                columns.append(np.concatenate([beside(rows), tilt], axis=-1))
        else:
            columns.append(np.concatenate([friction_columns(log, rows), tilt], axis=-1))
    if not t:
        return None
    cols: list[NDArray[np.float64]] | None = columns if len(columns) == len(t) else None
    lag = _lag(model, parts)
    return torque_delay(t, predicted, error, cols, lag, every=every)


def logs_delay(
    model: IdentifiedModel,
    logs: Sequence[TorqueLog],
    prepared: Sequence[TorqueLog] = (),
) -> TorqueDelay | None:
    """:func:`validations_delay` of ``logs`` (as read), each cut at the identification's
    gaps, its wrapped joints unwrapped and every piece prepared as the model's validation
    prepares it (:func:`~dynid.friction.validation.validate_torques`: the recorded
    cut-off and delay); a piece too short to prepare left out.

    ``prepared``: those pieces already prepared so (joint side, every sample: the
    held-out prediction's, :attr:`~dynid.friction.heldout_torques.HeldOutTorques.
    prepared`), predicted without preparing ``logs`` again; the same delay.
    """
    friction = own_friction(model)
    if prepared:
        drive = model_drive(model, None)
        return validations_delay(model, [validated(model, p, friction, drive) for p in prepared])
    gap = None if model.info.log is None else model.info.log.max_gap_s
    turns = wrappable(model.robot, model.drive)
    parts = []
    for log in logs:
        for piece in split_at_gaps(log, gap):
            try:
                parts.append(validate_torques(model, unwrapped(piece, turns)[0], friction=friction))
            except DynidError:
                continue
    return validations_delay(model, parts)


def _lag(model: IdentifiedModel | Robot, parts: Sequence[Validation]) -> int:
    """The Newey-West window [samples]: two periods of the model's cut-off at the pieces'
    rate (:func:`~dynid.identification.serial.hac_lag`)."""
    cutoff = None
    if isinstance(model, IdentifiedModel) and model.info.log is not None:
        cutoff = model.info.log.cutoff_hz
    dt = [float(np.median(np.diff(v.log.t))) for v in parts if v.log.n_samples > 1]
    if not dt:
        return 0
    return hac_lag(cutoff if cutoff is not None else 0.25 / min(dt), 1.0 / min(dt))
