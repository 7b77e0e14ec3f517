"""The noise floor a load's fit is judged against: the torques' noise and the states'.

A perfect arm and load model still leaves two noises in the fit's residual: the torque
sensors' noise after the low-pass, and the noise of the prepared states carried through
the arm's model (:mod:`~dynid.identification.input_noise`: the accelerations' noise times
the mass matrix, the velocities' noise through the friction law). The second is what
``identify`` and ``validate`` count in their floor beside the first. Recorded velocities
with noise through a steep Coulomb law (a smooth sign of width 0.02 rad/s: its slope
``fc / width`` turns 3 mrad/s of filtered velocity noise into 0.1 N m near a reversal)
leave a residual many times the torques' noise alone; judged against the torques' noise
alone, a 1.5 kg load estimated within 0.2 % read 8.9 x and was refused.

* :func:`states_noise_var`: the states' noise variance through the arm's model at each
  prepared sample;
* :func:`floor_ratio`: the residual over both noises, each sample weighed against its
  own noise (:func:`~dynid.identification.input_noise.noise_floor`, the engine of the
  held-out and validation verdicts), and the RMS of the states' part.
"""

from __future__ import annotations

from collections.abc import Sequence

import numpy as np
from numpy.typing import NDArray

from ..identification.input_noise import input_noise_var, noise_floor, state_noise
from ..identification.log import TorqueLog, joint_side_log
from ..identification.recordings import Recordings
from ..model.drive import Drive
from ..signals import lowpass_noise_gain
from .payload_arm import ArmModel

__all__ = ["STATES_SHARE", "floor_ratio", "sensor_variances", "states_noise_var"]

#: The states' noise through the model counts in the floor from this share of the torques'
#: noise (RMS over samples and joints) on: below it the floor moves by under 0.5 %, and the
#: residual is judged against the torques' noise alone (exact or clean states).
STATES_SHARE = 0.1


def states_noise_var(
    arm: ArmModel,
    rec: Recordings,
    logs: Sequence[TorqueLog],
    drive: Drive | None,
    still: NDArray[np.bool_],
) -> list[NDArray[np.float64]] | None:
    """Per prepared piece of ``rec``, the variance [N^2 m^2] (N_p, n) the states' noise
    puts into the arm's prediction at each sample
    (:func:`~dynid.identification.input_noise.input_noise_var`, the arm's friction
    included): the noise of the recordings ``logs`` as read (joint side of ``drive``),
    prepared at ``rec``'s cut-off (:func:`~dynid.identification.input_noise.state_noise`);
    ``still`` joints (n,) are at rest in the rows and put none. None when the states'
    noise is not known (no piece of 8 samples)."""
    noise = state_noise([joint_side_log(log, drive) for log in logs], rec.cutoff_hz)
    if noise is None:
        return None
    moving = ~still
    noise = type(noise)(noise.dq * moving, noise.ddq * moving, noise.derived)

    def rigid(
        q: NDArray[np.float64], dq: NDArray[np.float64], ddq: NDArray[np.float64]
    ) -> NDArray[np.float64]:
        return np.asarray(arm.torques(q, dq * moving, ddq * moving, with_friction=False))

    own = arm.friction
    fr = None if own is None else (lambda v: np.asarray(own.torques(v * moving)))
    out = []
    for piece in rec.pieces:
        log = piece.log
        assert log.ddq is not None  # prepared: differentiated
        out.append(input_noise_var(rigid, fr, log.q, log.dq * moving, log.ddq * moving, noise))
    return out


def sensor_variances(rec: Recordings) -> list[NDArray[np.float64] | None]:
    """Per prepared piece of ``rec``, its torque sensors' white-noise variance per joint
    after the low-pass [N^2 m^2] (n,) (None: not read)."""
    out: list[NDArray[np.float64] | None] = []
    for p in rec.pieces:
        g = lowpass_noise_gain(p.sample_rate_hz, p.cutoff_hz)
        out.append(None if p.torque_noise_std is None else (g * p.torque_noise_std) ** 2)
    return out


def floor_ratio(
    tau: Sequence[NDArray[np.float64]],
    residual: Sequence[NDArray[np.float64]],
    sensor_var: Sequence[NDArray[np.float64] | None],
    states_var: Sequence[NDArray[np.float64]],
) -> tuple[float | None, float | None]:
    """The residual over the noise floor of pieces, each sample weighed against its own
    noise, and the RMS [N m] of the states' noise through the model over every sample and
    joint.

    The floor is the torque sensors' noise and the states' noise through the model
    (:func:`~dynid.identification.input_noise.noise_floor`): each sample's squared error
    is weighed by its joint's mean noise variance over its own, so that the states' noise
    at a few reversals does not excuse an error spread over the moving samples; a constant
    noise gives the plain quotient of the residual's and the noise's RMS.

    Parameters
    ----------
    tau, residual : sequence of ndarray, each (N_p, n)
        Each piece's torques and the fit's residual there [N m].
    sensor_var : sequence of ndarray (n,) or None
        Each piece's torque noise variance after the low-pass [N^2 m^2].
    states_var : sequence of ndarray, each (N_p, n)
        The states' noise variance through the model at each sample
        (:func:`states_noise_var`) [N^2 m^2].

    Returns
    -------
    (float or None, float or None)
        The ratio (None: no noise known) and the states' RMS [N m]; below
        :data:`STATES_SHARE` of the torques' noise, the plain quotient of the residual's
        and the torques' noise's RMS and None (the states' noise not counted).
    """
    inputs = [(1, V) for V in states_var]
    fl = noise_floor(tau, residual, sensor_var, inputs)
    states = 0.0 if fl.input_rms is None else float(np.sqrt(np.mean(fl.input_rms**2)))
    sensors = float(np.sqrt(np.mean(fl.sensor_rms**2)))
    if fl.ratio is not None and states >= STATES_SHARE * sensors:
        return fl.ratio, states
    count = sum(r.size for r in residual)
    rms = float(np.sqrt(sum(np.sum(r**2) for r in residual) / max(count, 1)))
    return (rms / sensors if sensors > 0 else None), None
