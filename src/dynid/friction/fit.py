"""Fitting joint friction to the torque residual of a rigid-body model (Gaz et al. 2019, Sec. VI).

The friction torque is what the rigid-body model leaves unexplained,

.. math:: r_j = \\tau_{meas,j} - \\hat\\tau_j(q, \\dot q, \\ddot q) \\approx \\tau_{f,j}(\\dot q_j)

where ``tau_hat`` is an identified model (:class:`~dynid.identification.model.IdentifiedModel`
``.torques``), a :class:`~dynid.model.robot.Robot` (its own link parameters through RNEA)
or any callable ``f(q, dq, ddq) -> tau`` on (N, n) arrays. The log is first prepared
(:func:`~dynid.identification.prepare.prepare_log`): the states are low-pass filtered with
zero phase and ``ddq`` is the derivative of the filtered ``dq``; the measured torques are
kept unfiltered by default (``filter_tau=False``), because filtering them would smear the
fast friction reversals that the friction model, evaluated on the velocity, keeps sharp.
The residual then holds the friction plus the sensor noise, and the RMS after
compensation is at the noise level for a correct model.

Each law of the registry (:mod:`dynid.friction.laws`: classical eq. 24, smooth Coulomb,
asymmetric, Stribeck, the sigmoid of eq. 25) is fitted joint by joint by its own
deterministic fit (:func:`fit_law`); Coulomb terms are off where ``|dq|`` is inside the
joint's velocity noise band (the standstill rule, :mod:`dynid.friction.laws.base`).
Which law predicts held-out data best is :func:`~dynid.friction.select.select_friction`.

A joint whose velocity never leaves its noise band carries no information on its
friction: fitted anyway, the sigmoid's span ``phi1`` runs off to millions of N m. Such a
joint gets no parameters (zero friction) and a :class:`~dynid.exceptions.DynidWarning`
names it (:func:`moving_joints`: at least 1 % of its samples beyond
:data:`NOISE_BAND_STD` times the white-noise std of the measured velocity, and beyond
:data:`MIN_MOTION`); a log in which no joint moves is a
:class:`~dynid.exceptions.DataError`.

The result reports the per-joint RMS of the residual before and after subtracting the
fitted friction, and which joints were identified.
"""

from __future__ import annotations

import warnings
from collections.abc import Callable
from dataclasses import dataclass, replace

import numpy as np
from numpy.typing import ArrayLike, NDArray

from .. import _checks
from .._checks import caller_level
from ..dynamics.rnea import rnea
from ..exceptions import ConvergenceError, DataError, DynidWarning, ShapeError, WrongTypeError
from ..identification.log import TorqueLog, checked_log, joint_side_log
from ..identification.model import IdentifiedModel
from ..identification.motor_constants import read_at_the_joints
from ..identification.prepare import MEASURED, Preprocessing, prepare_log
from ..identification.recordings import standstill_band
from ..identification.structure import smooth_width
from ..identification.velocity_noise import (
    NOISE_BAND_STD,
    moving_joints,
    noise_band,
    velocity_noise_std,
)
from ..model.drive import Drive
from ..model.robot import Robot
from .laws import FrictionLaw, law_named
from .laws.base import _LinearFit
from .model import FrictionModel, FrictionSum

__all__ = [
    "FrictionFit",
    "FrictionResidual",
    "TorqueModel",
    "fit_classical",
    "fit_friction",
    "fit_sigmoid",
    "fit_friction_through",
    "fit_law",
    "fit_law_through",
    "friction_residual",
    "model_drive",
    "same_drive",
    "moving_joints",
    "rigid_body_torques",
    "torques_through",
    "velocity_noise_std",
]

#: A rigid-body torque model: identified, a robot's own parameters, or a callable
#: ``f(q, dq, ddq) -> tau`` on (N, n) arrays [rad, rad/s, rad/s^2 -> N m].
TorqueModel = IdentifiedModel | Robot | Callable[..., NDArray[np.float64]]


def rigid_body_torques(
    model: TorqueModel, q: NDArray[np.float64], dq: NDArray[np.float64], ddq: NDArray[np.float64]
) -> NDArray[np.float64]:
    """``M ddq + c + g`` [N m] (N, n) of a :data:`TorqueModel`, friction not included.

    Long logs are evaluated in blocks of :data:`BLOCK_SAMPLES` samples, so the memory of
    the intermediate kinematics (and of an identified model's regressor, ~2.4 kB per
    sample for the Panda) stays bounded whatever the log's length.
    """
    N = q.shape[0] if q.ndim == 2 else 0
    if N > BLOCK_SAMPLES:
        out = np.empty(q.shape)
        for a in range(0, N, BLOCK_SAMPLES):
            b = slice(a, a + BLOCK_SAMPLES)
            out[b] = _rigid_body_torques(model, q[b], dq[b], ddq[b])
        return out
    return _rigid_body_torques(model, q, dq, ddq)


#: Samples per block in :func:`rigid_body_torques`.
BLOCK_SAMPLES = 16_384


def torques_through(
    model: TorqueModel,
    drive: Drive | None,
    q: NDArray[np.float64],
    dq: NDArray[np.float64],
    ddq: NDArray[np.float64],
) -> NDArray[np.float64]:
    """The model's torques [N m] (N, n) on a log read through ``drive``, friction not
    included: :func:`rigid_body_torques`, plus a robot's joint spring
    (:attr:`~dynid.model.robot.Robot.spring`, ``k (q - q0)``) and the drive's known rotor
    torques ``K^T diag(I_a) K ddq`` for a robot's links or a callable (an identified
    model's torques hold its spring and rotors already). Validation and the friction fit's
    residual both read the model so, so that a robot's own friction scores the same in both.
    """
    tau = rigid_body_torques(model, q, dq, ddq)
    if isinstance(model, Robot) and model.spring is not None:
        tau = tau + model.spring.torques(q)
    if drive is None or drive.rotor_inertia is None or isinstance(model, IdentifiedModel):
        return tau
    if not isinstance(model, Robot):  # a callable's array is its own: not changed here
        tau = np.array(tau)
    for a in range(0, q.shape[0], BLOCK_SAMPLES):
        b = slice(a, a + BLOCK_SAMPLES)
        tau[b] += drive.rotor_torques(ddq[b], drive.rotor_inertia)
    return tau


def _rigid_body_torques(
    model: TorqueModel, q: NDArray[np.float64], dq: NDArray[np.float64], ddq: NDArray[np.float64]
) -> NDArray[np.float64]:
    if isinstance(model, IdentifiedModel):
        tau = model.torques(q, dq, ddq)
    elif isinstance(model, Robot):
        tau = rnea(model, q, dq, ddq)
    elif callable(model):
        tau = _checks.as_array("model(q, dq, ddq)", model(q, dq, ddq))
    else:
        raise WrongTypeError(
            f"model must be an IdentifiedModel, a Robot or a callable; got {type(model).__name__}"
        )
    if tau.shape != q.shape:
        raise ShapeError(f"model torques must have shape {q.shape}; got {tau.shape}")
    return tau


@dataclass(frozen=True, slots=True, eq=False)
class FrictionResidual:
    """Prepared log and the residual of a rigid-body model.

    Attributes
    ----------
    log : TorqueLog
        The prepared (filtered, trimmed, with ``ddq``) log.
    tau_model : ndarray, shape (N, n)
        Rigid-body torques of the model [N m].
    residual : ndarray, shape (N, n)
        ``log.tau - tau_model`` [N m].
    dq_noise_std : ndarray, shape (n,), optional
        White-noise std of the prepared (low-passed) velocities [rad/s], read from the log
        before preparation as identification reads it: its standstill band
        (:func:`~dynid.identification.recordings.standstill_band`) over
        :data:`~dynid.identification.velocity_noise.NOISE_BAND_STD`; None when unknown.
    recording : ndarray of int, shape (N,), optional
        The recording of each sample when the residual holds several
        (:func:`~dynid.friction.recordings.pieces_residual`); None: one recording.
    """

    log: TorqueLog
    tau_model: NDArray[np.float64]
    residual: NDArray[np.float64]
    dq_noise_std: NDArray[np.float64] | None = None
    recording: NDArray[np.intp] | None = None

    @property
    def dq(self) -> NDArray[np.float64]:
        """Filtered joint velocities [rad/s] (N, n)."""
        return self.log.dq


def _short(value: object, limit: int = 40) -> str:
    """``repr(value)``, cut to ``limit`` characters."""
    text = repr(value)
    return text if len(text) <= limit else text[: limit - 3] + "..."


def model_drive(model: TorqueModel, drive: Drive | None) -> Drive | None:
    """The drive a log is read through: an identified model's own, or ``drive``.

    Raises
    ------
    DataError
        ``drive`` differs from the one the model was identified with.
    """
    own = model.drive if isinstance(model, IdentifiedModel) else None
    return same_drive(drive, own, "the model", "the one the model was identified with")


#: The fields of a drive that say how a log records the effort, not the arm's mechanics:
#: a log of currents is read through another drive's than the model's torques.
LOGGING_FIELDS = ("effort", "torque_constant")


def same_drive(drive: Drive | None, own: Drive | None, whose: str, what: str) -> Drive | None:
    """``own`` (a model's or a file's drive), the same as ``drive`` when both are given,
    else the one given; ``own`` read as ``drive`` records the effort when they differ in
    :data:`LOGGING_FIELDS` alone (a model identified from torques, a log of motor
    currents with their torque constants).

    Raises
    ------
    DataError
        ``drive`` differs from ``own`` in its mechanics: each differing field named with
        ``whose`` value (``what`` names the drive: "the one the model was identified
        with").
    """
    if drive is None or own is None:
        return own if drive is None else drive
    mine, theirs = drive.as_dict(), own.as_dict()
    if mine != theirs:
        keys = sorted(k for k in {*mine, *theirs} if mine.get(k) != theirs.get(k))
        if set(keys) <= set(LOGGING_FIELDS):
            if (g := read_at_the_joints(drive, own)) is not None:
                warnings.warn(  # the drive file as identify corrected it: its reading kept
                    f"the drive given holds the motors' torque constants; {whose} reads the "
                    f"currents through them times the gear ratio every joint shares, {g:.4g}, "
                    f"as identify did (torque_constant looks given at the motors): read so; "
                    f"hint: put {whose}'s torque_constant in the drive file",
                    DynidWarning,
                    stacklevel=caller_level(),
                )
                return own
            if own.effort == "current" and own.torque_constant is not None:
                warnings.warn(  # currents read through other constants than the fit's
                    f"the drive given reads the currents through torque_constant = "
                    f"{_short(mine.get('torque_constant'))}, {whose} through "
                    f"{_short(theirs.get('torque_constant'))} (identified through them); "
                    f"hint: leave out --drive to read them through {whose}'s",
                    DynidWarning,
                    stacklevel=caller_level(),
                )
            return replace(own, effort=drive.effort, torque_constant=drive.torque_constant)
        given = ", ".join(
            f"{k} = {_short(mine.get(k))} ({whose}'s {_short(theirs.get(k))})" for k in keys
        )
        raise DataError(
            f"the drive given differs from {what}: {given}; "
            f"hint: leave out --drive to use {whose}'s"
        )
    return own


def friction_residual(
    model: TorqueModel,
    log: TorqueLog,
    prep: Preprocessing = MEASURED,
    *,
    drive: Drive | None = None,
) -> FrictionResidual:
    """Prepare ``log`` and compute the torque residual of ``model``.

    Parameters
    ----------
    model : TorqueModel
    log : TorqueLog
    prep : Preprocessing
        The preparation of the log (:func:`~dynid.identification.prepare.prepare_log`);
        default :data:`MEASURED` (the default cut-off, the torques as measured).
    drive : Drive, optional
        The drive the log was recorded through; default: an identified model's own
        (:func:`model_drive`). The residual is in joint torques.

    Returns
    -------
    FrictionResidual
    """
    d = model_drive(model, drive)
    log = joint_side_log(log, d)
    p = prepare_log(log, prep)
    assert p.ddq is not None  # prepare_log always fills ddq
    tau_m = torques_through(model, d, p.q, p.dq, p.ddq)
    noise = _checks.frozen(standstill_band([log], prep.cutoff_hz) / NOISE_BAND_STD)
    return FrictionResidual(log=p, tau_model=tau_m, residual=p.tau - tau_m, dq_noise_std=noise)


def _identifiable(dq: NDArray[np.float64], noise_std: ArrayLike | None) -> NDArray[np.bool_]:
    """The moving joints; warn about the others, raise when none moves."""
    moving = moving_joints(dq, 0.0 if noise_std is None else noise_std)
    still = [int(j) + 1 for j in np.flatnonzero(~moving)]
    if not moving.any():
        raise DataError(
            f"no joint moves beyond its velocity noise band (largest |dq| "
            f"{float(np.max(np.abs(dq))):.3g} rad/s): friction cannot be fitted from this log; "
            "hint: record a trajectory that moves every joint in both directions"
        )
    if still:
        warnings.warn(
            f"joint(s) {still} never move beyond their velocity noise band: their friction is "
            "not identifiable from this log and is set to zero; hint: record a trajectory "
            "that moves them",
            DynidWarning,
            stacklevel=caller_level(),
        )
    return moving


@dataclass(frozen=True, slots=True, eq=False)
class FrictionFit:
    """Result of a friction fit.

    Attributes
    ----------
    friction : Friction or FrictionSum
        The fitted law with its parameters per joint (per motor at the motors of a drive);
        a model's own friction at the motors and at the joints kept as it is (a sum).
    rms_before : ndarray, shape (n,)
        RMS of the residual without friction compensation [N m].
    rms_after : ndarray, shape (n,)
        RMS of the residual minus the fitted friction [N m].
    converged : ndarray of bool, shape (n,)
        Optimiser success per joint (always True for the linear classical fit).
    iterations : ndarray of int, shape (n,)
        Optimiser iterations per joint (0 for the classical fit).
    n_samples : int
        Samples used.
    identified : ndarray of bool, shape (n,)
        Joints whose friction was fitted; the others never left their velocity noise
        band and have zero friction (:func:`moving_joints`).
    covariance : ndarray, shape (n, k, k), or None
        Of a law linear in its ``k`` parameters: each joint's (motor's) covariance of its
        parameters [their units squared], ``s^2 (A^T A)^+`` of its columns ``A`` and
        residual variance ``s^2`` (the samples taken as independent: a lower bound on a
        filtered log); zero for a joint not fitted. None for another law or a model's own
        friction.
    """

    friction: FrictionModel | FrictionSum
    rms_before: NDArray[np.float64]
    rms_after: NDArray[np.float64]
    converged: NDArray[np.bool_]
    iterations: NDArray[np.int_]
    n_samples: int
    identified: NDArray[np.bool_]
    covariance: NDArray[np.float64] | None = None

    @property
    def kind(self) -> str:
        """``"sigmoid"`` or ``"classical"``."""
        return self.friction.kind


def fit_law(
    law: str | FrictionLaw,
    dq: ArrayLike,
    residual: ArrayLike,
    *,
    dq_noise_std: ArrayLike | None = None,
    warn: bool = True,
    width: float | None = None,
) -> FrictionFit:
    """Fit a law of the registry (:mod:`dynid.friction.laws`) to a residual, joint by joint.

    Parameters
    ----------
    law : str or FrictionLaw
        Registry name (``"classical"``, ``"sigmoid"``, ...) or the law.
    dq : array_like, shape (N, n)
        Joint velocities [rad/s].
    residual : array_like, shape (N, n)
        Torque residual [N m].
    dq_noise_std : array_like, shape (n,), optional
        White-noise std of the measured velocities [rad/s]
        (:attr:`FrictionResidual.dq_noise_std`). It sets each joint's standstill band
        (:func:`~dynid.identification.velocity_noise.noise_band`): Coulomb terms are off inside it,
        in the fit and in the fitted model. Joints whose ``dq`` does not leave the band
        (:func:`moving_joints`) get zero friction; None: no noise (no band; only
        :data:`~dynid.identification.velocity_noise.MIN_MOTION` tells still joints).
    warn : bool
        Warn about joints that do not move (False: silently zero, as in cross-validation).
    width : float, optional
        The smooth Coulomb's width in standstill bands: the law's band becomes
        :func:`~dynid.identification.structure.smooth_width` of it (a factor of
        :func:`~dynid.identification.structure.smooth_width_grid`, the grid ``identify``
        searches); None: the standstill band itself.

    Returns
    -------
    FrictionFit

    Raises
    ------
    ShapeError, NonFiniteError
    OptionError
        Unknown law name.
    DataError
        No joint moves beyond its velocity noise band.
    ConvergenceError
        The fit returned non-finite parameters.

    Warns
    -----
    DynidWarning
        Some joints do not move (named, 1-based): their friction is set to zero.
    """
    lw = law_named(law) if isinstance(law, str) else law
    dq, residual = _pair(dq, residual)
    n = dq.shape[1]
    noise = np.zeros(n) if dq_noise_std is None else np.broadcast_to(dq_noise_std, (n,))
    band = noise_band(noise)
    lb = band if width is None else np.asarray(smooth_width(band.tolist(), width), dtype=np.float64)
    if warn:
        moving = _identifiable(dq, noise)
    else:
        moving = moving_joints(dq, noise)
        if not moving.any():
            raise DataError("no joint moves beyond its velocity noise band")
    P = np.zeros((n, len(lw.params)))
    ok = np.ones(n, bool)
    it = np.zeros(n, int)
    for j in np.flatnonzero(moving):
        jf = lw.fit(dq[:, j], residual[:, j], float(lb[j]))
        P[j], ok[j], it[j] = jf.params, jf.converged, jf.iterations
    if not np.all(np.isfinite(P)):
        raise ConvergenceError(f"{lw.name} friction fit gave non-finite parameters: {P.tolist()}")
    fit = _result(lw.model(P, lb), dq, residual, ok, it, moving)
    if not isinstance(lw.fit, _LinearFit):
        return fit
    return replace(fit, covariance=_linear_covariance(lw.fit, dq, residual, lb, P, moving))


def _linear_covariance(
    lf: _LinearFit,
    dq: NDArray[np.float64],
    residual: NDArray[np.float64],
    band: NDArray[np.float64],
    P: NDArray[np.float64],
    moving: NDArray[np.bool_],
) -> NDArray[np.float64]:
    """(n, k, k): each moving joint's ``s^2 (A^T A)^+`` (:class:`FrictionFit`), zero for
    the others."""
    n, k = P.shape
    out = np.zeros((n, k, k))
    for j in np.flatnonzero(moving):
        A = lf.columns(dq[:, j : j + 1], band[j : j + 1])[:, 0, :]
        e = residual[:, j] - A @ P[j]
        s2 = float(e @ e) / max(A.shape[0] - k, 1)
        out[j] = s2 * np.linalg.pinv(A.T @ A)
    return out


def fit_sigmoid(
    dq: NDArray[np.float64],
    residual: NDArray[np.float64],
    *,
    dq_noise_std: ArrayLike | None = None,
) -> FrictionFit:
    """Per-joint fit of the sigmoid (eq. 25) to a residual: :func:`fit_law` with
    ``"sigmoid"`` (Nelder-Mead, :mod:`dynid.friction.laws.sigmoid`).

    Parameters
    ----------
    dq : array_like, shape (N, n)
        Joint velocities [rad/s].
    residual : array_like, shape (N, n)
        Torque residual [N m].
    dq_noise_std : array_like, shape (n,), optional
        As in :func:`fit_law`.

    Returns
    -------
    FrictionFit

    Raises
    ------
    ShapeError, NonFiniteError, DataError, ConvergenceError
        As :func:`fit_law`.
    """
    return fit_law("sigmoid", dq, residual, dq_noise_std=dq_noise_std)


def fit_classical(
    dq: NDArray[np.float64],
    residual: NDArray[np.float64],
    *,
    dq_noise_std: ArrayLike | None = None,
) -> FrictionFit:
    """Per-joint bounded least squares of ``fv dq + fc s(dq) + fo`` (eq. 24) to a residual:
    :func:`fit_law` with ``"classical"`` (``fv, fc >= 0``; ``s`` is 0 in the standstill band).

    Parameters
    ----------
    dq : array_like, shape (N, n)
        Joint velocities [rad/s].
    residual : array_like, shape (N, n)
        Torque residual [N m].
    dq_noise_std : array_like, shape (n,), optional
        As in :func:`fit_law`.

    Returns
    -------
    FrictionFit

    Raises
    ------
    ShapeError, NonFiniteError, DataError
        As :func:`fit_law`.
    """
    return fit_law("classical", dq, residual, dq_noise_std=dq_noise_std)


def _pair(dq: ArrayLike, residual: ArrayLike) -> tuple[NDArray[np.float64], NDArray[np.float64]]:
    a = _checks.as_array("dq", dq)
    b = _checks.as_array("residual", residual)
    if a.ndim != 2 or a.shape != b.shape or a.shape[0] < 4:
        raise ShapeError(
            f"dq and residual must both have shape (N, n), N >= 4; got {a.shape}, {b.shape}"
        )
    return a, b


def _result(
    fr: FrictionModel,
    dq: NDArray[np.float64],
    residual: NDArray[np.float64],
    ok: NDArray[np.bool_],
    it: NDArray[np.int_],
    identified: NDArray[np.bool_],
) -> FrictionFit:
    after = residual - fr.torques(dq)
    return FrictionFit(
        friction=fr,
        rms_before=_checks.frozen(np.sqrt(np.mean(residual**2, axis=0))),
        rms_after=_checks.frozen(np.sqrt(np.mean(after**2, axis=0))),
        converged=_checks.frozen(ok),
        iterations=_checks.frozen(it),
        n_samples=dq.shape[0],
        identified=_checks.frozen(identified),
    )


def fit_friction(
    model: TorqueModel,
    log: TorqueLog,
    *,
    kind: str = "sigmoid",
    prep: Preprocessing = MEASURED,
) -> FrictionFit:
    """Fit a friction law to the residual of ``model`` on a torque log.

    Parameters
    ----------
    model : TorqueModel
        Rigid-body model (friction not included): IdentifiedModel, Robot or callable.
    log : TorqueLog
        Measured log of a trajectory that visits both signs of every joint velocity.
    kind : str
        A law of the registry (:mod:`dynid.friction.laws`); the choice among them on
        held-out data is :func:`~dynid.friction.select.select_friction`.
    prep : Preprocessing
        Preparation of the log (:func:`friction_residual`).

    Returns
    -------
    FrictionFit

    Raises
    ------
    OptionError
        Unknown ``kind``.
    WrongTypeError
        ``log`` is not a :class:`~dynid.identification.log.TorqueLog`.
    ShapeError
        Joint counts that differ.
    DataError
        From the preparation of the log; no joint moves beyond its velocity noise band.

    Warns
    -----
    DynidWarning
        Some joints do not move: their friction is set to zero (:func:`fit_law`).
    """
    law = law_named(kind)
    checked_log(log)
    res = friction_residual(model, log, prep)
    return fit_law(law, res.dq, res.residual, dq_noise_std=res.dq_noise_std)


def fit_friction_through(
    res: FrictionResidual,
    drive: Drive | None,
    kind: str = "sigmoid",
    *,
    warn: bool = True,
    width: float | None = None,
) -> FrictionFit:
    """Fit a friction law where the drive says it acts: :func:`fit_law_through` on the
    residual of :func:`friction_residual`.

    Parameters
    ----------
    res : FrictionResidual
    drive : Drive or None
    kind : str
        A law of the registry (:mod:`dynid.friction.laws`).
    warn, width
        As in :func:`fit_law`.

    Returns
    -------
    FrictionFit

    Raises
    ------
    OptionError
        ``kind`` is not a law of the registry.
    DataError
        No joint moves beyond its velocity noise band.
    """
    return fit_law_through(
        kind, res.dq, res.residual, drive, dq_noise_std=res.dq_noise_std, warn=warn, width=width
    )


def fit_law_through(
    law: str | FrictionLaw,
    dq: ArrayLike,
    residual: ArrayLike,
    drive: Drive | None,
    *,
    dq_noise_std: ArrayLike | None = None,
    warn: bool = True,
    width: float | None = None,
) -> FrictionFit:
    """Fit a friction law where the drive says it acts (the motors of a gear train).

    At the motors the joint residual ``r`` becomes motor torques ``K^-T r`` at the motor
    velocities ``K dq`` (exact: ``K`` is invertible), each motor is fitted on its own
    (:func:`fit_law`, the motor velocity noise ``sqrt(K^2 sigma^2)`` setting the standstill
    band), and the result is a :class:`~dynid.friction.model.Friction` at the drive whose RMS
    before and after are those of the joint torques. Without a drive (or with friction at
    the joints) the joints are fitted.

    Parameters
    ----------
    law : str or FrictionLaw
        A law of the registry (:mod:`dynid.friction.laws`).
    dq : array_like, shape (N, n)
        Joint velocities [rad/s].
    residual : array_like, shape (N, n)
        Joint torque residual [N m].
    drive : Drive or None
    dq_noise_std : array_like, shape (n,), optional
        White-noise std of the measured joint velocities [rad/s].
    warn, width
        As in :func:`fit_law`.

    Returns
    -------
    FrictionFit

    Raises
    ------
    OptionError
        ``law`` is not a law of the registry.
    ShapeError, DataError, ConvergenceError
        As :func:`fit_law`.
    """
    if drive is None or drive.friction_place == "joint":
        return fit_law(law, dq, residual, dq_noise_std=dq_noise_std, warn=warn, width=width)
    dq, residual = _pair(dq, residual)
    K = drive.transmission
    v = drive.motor_velocities(dq)
    r = np.asarray(np.linalg.solve(K.T, residual.T).T, dtype=np.float64)
    noise = None if dq_noise_std is None else np.sqrt((K**2) @ np.asarray(dq_noise_std) ** 2)
    fit = fit_law(law, v, r, dq_noise_std=noise, warn=warn, width=width)
    assert isinstance(fit.friction, FrictionModel)  # fit_law fits one law
    fr = fit.friction.at(drive)  # the law per motor
    after = residual - fr.torques(dq)
    return replace(
        fit,
        friction=fr,
        rms_before=np.sqrt(np.mean(residual**2, axis=0)),
        rms_after=np.sqrt(np.mean(after**2, axis=0)),
    )
