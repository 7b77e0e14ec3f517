"""Fitting joint friction to the torque residual of a rigid-body model (Gaz et al. 2019, Sec. VI).

The friction torque is what the rigid-body model leaves unexplained,

.. math:: r_j = \\tau_{meas,j} - \\hat\\tau_j(q, \\dot q, \\ddot q) \\approx \\tau_{f,j}(\\dot q_j)

where ``tau_hat`` is an identified model (:class:`~dynid.identification.model.IdentifiedModel`
``.torques``), a :class:`~dynid.model.robot.Robot` (its own link parameters through RNEA)
or any callable ``f(q, dq, ddq) -> tau`` on (N, n) arrays. The log is first prepared
(:func:`~dynid.identification.log.prepare_log`): the states are low-pass filtered with
zero phase and ``ddq`` is the derivative of the filtered ``dq``; the measured torques are
kept unfiltered by default (``filter_tau=False``), because filtering them would smear the
fast friction reversals that the friction model, evaluated on the velocity, keeps sharp.
The residual then holds the friction plus the sensor noise, and the RMS after
compensation is at the noise level for a correct model.

* **sigmoid** (eq. 25): per joint, Nelder-Mead (``scipy.optimize.minimize``) on the mean
  squared residual. The variables are scaled, ``z = (phi1 / s1, ln(phi2 / s2), phi3 / s3)``
  (``phi2`` stays positive), and the start comes from a grid over ``phi2`` and ``phi3``
  with ``phi1`` solved in closed form for each grid point (the model is linear in
  ``phi1``).
* **classical** (eq. 24): per joint, linear least squares on ``(dq, sign dq, 1)``.

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
import scipy.linalg
import scipy.special
from numpy.typing import ArrayLike, NDArray

from .. import _checks
from ..dynamics.rnea import rnea
from ..exceptions import ConvergenceError, DataError, DynidWarning, OptionError, ShapeError
from ..identification.log import DEFAULT_CUTOFF_HZ, TorqueLog, joint_side_log, prepare_log
from ..identification.model import IdentifiedModel
from ..identification.sanity import (
    moving_joints,
    velocity_noise_std,
)
from ..model.drive import Drive
from ..model.robot import Robot
from .model import ClassicalFriction, DriveFriction, FrictionModel, SigmoidFriction

__all__ = [
    "FrictionFit",
    "FrictionResidual",
    "TorqueModel",
    "fit_classical",
    "fit_friction",
    "fit_sigmoid",
    "fit_friction_through",
    "friction_residual",
    "model_drive",
    "moving_joints",
    "rigid_body_torques",
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
BLOCK_SAMPLES = 50_000


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
        raise ShapeError(
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
        White-noise std of the measured (unfiltered) velocities [rad/s]
        (:func:`velocity_noise_std` of the log before preparation); None when unknown.
    """

    log: TorqueLog
    tau_model: NDArray[np.float64]
    residual: NDArray[np.float64]
    dq_noise_std: NDArray[np.float64] | None = None

    @property
    def dq(self) -> NDArray[np.float64]:
        """Filtered joint velocities [rad/s] (N, n)."""
        return self.log.dq


def model_drive(model: TorqueModel, drive: Drive | None) -> Drive | None:
    """The drive a log is read through: an identified model's own, or ``drive``.

    Raises
    ------
    DataError
        ``drive`` differs from the one the model was identified with.
    """
    own = model.drive if isinstance(model, IdentifiedModel) else None
    if drive is None or own is None:
        return own if drive is None else drive
    if drive.as_dict() != own.as_dict():
        raise DataError(
            "the drive given differs from the one the model was identified with "
            f"({own.describe()}); hint: leave out --drive to use the model's"
        )
    return own


def friction_residual(
    model: TorqueModel,
    log: TorqueLog,
    *,
    cutoff_hz: float | None = DEFAULT_CUTOFF_HZ,
    trim_s: float | None = None,
    max_gap_s: float | None = None,
    filter_tau: bool = False,
    drive: Drive | None = None,
) -> FrictionResidual:
    """Prepare ``log`` and compute the torque residual of ``model``.

    Parameters
    ----------
    model : TorqueModel
    log : TorqueLog
    cutoff_hz, trim_s, filter_tau, max_gap_s
        Passed to :func:`~dynid.identification.log.prepare_log` (``cutoff_hz=None``: no
        filtering).
    drive : Drive, optional
        The drive the log was recorded through; default: an identified model's own
        (:func:`model_drive`). The residual is in joint torques.

    Returns
    -------
    FrictionResidual
    """
    log = joint_side_log(log, model_drive(model, drive))
    p = prepare_log(
        log, cutoff_hz=cutoff_hz, trim_s=trim_s, filter_tau=filter_tau, max_gap_s=max_gap_s
    )
    assert p.ddq is not None  # prepare_log always fills ddq
    tau_m = rigid_body_torques(model, p.q, p.dq, p.ddq)
    noise = _checks.frozen(velocity_noise_std(log.dq))
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
            stacklevel=3,
        )
    return moving


@dataclass(frozen=True, slots=True, eq=False)
class FrictionFit:
    """Result of a friction fit.

    Attributes
    ----------
    friction : SigmoidFriction or ClassicalFriction
        Fitted parameters per joint.
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
    """

    friction: FrictionModel
    rms_before: NDArray[np.float64]
    rms_after: NDArray[np.float64]
    converged: NDArray[np.bool_]
    iterations: NDArray[np.int_]
    n_samples: int
    identified: NDArray[np.bool_]

    @property
    def kind(self) -> str:
        """``"sigmoid"`` or ``"classical"``."""
        return self.friction.kind


def _sigmoid_basis(dq: NDArray[np.float64], phi2: float, phi3: float) -> NDArray[np.float64]:
    return scipy.special.expit(phi2 * (dq + phi3)) - scipy.special.expit(phi2 * phi3)


def _fit_sigmoid_joint(
    dq: NDArray[np.float64], r: NDArray[np.float64], *, maxiter: int
) -> tuple[NDArray[np.float64], bool, int]:
    """(phi1, phi2, phi3), success, iterations for one joint's (N,) velocity and residual."""
    scale = float(np.sqrt(np.mean(r**2))) or 1.0
    rs = r / scale
    # start: grid over (phi2, phi3), phi1 by closed-form least squares (on a subsample)
    step = max(1, dq.size // 4000)
    dg, rg = dq[::step], rs[::step]
    best = (np.inf, 1.0, 10.0, 0.0)
    for phi2 in np.geomspace(1.0, 100.0, 15):
        for phi3 in np.linspace(-0.1, 0.1, 9):
            b = _sigmoid_basis(dg, phi2, phi3)
            bb = float(b @ b)
            if bb <= 0:
                continue
            a = float(b @ rg) / bb
            sse = float(np.sum((rg - a * b) ** 2))
            if sse < best[0]:
                best = (sse, a, phi2, phi3)
    _, a0, s2, p30 = best
    s1 = a0 if abs(a0) > 1e-6 else 1.0
    s3 = 0.05

    def cost(z: NDArray[np.float64]) -> float:
        e = rs - z[0] * s1 * _sigmoid_basis(dq, s2 * np.exp(z[1]), z[2] * s3)
        return float(np.mean(e**2))

    from scipy.optimize import minimize  # imported here: slow to import, rarely needed

    z0 = np.array([1.0, 0.0, p30 / s3])
    res = minimize(
        cost, z0, method="Nelder-Mead", options={"xatol": 1e-7, "fatol": 1e-12, "maxiter": maxiter}
    )
    z = res.x
    phi = np.array([z[0] * s1 * scale, s2 * np.exp(z[1]), z[2] * s3])
    return phi, bool(res.success), int(res.nit)


def fit_sigmoid(
    dq: NDArray[np.float64],
    residual: NDArray[np.float64],
    *,
    maxiter: int = 4000,
    dq_noise_std: ArrayLike | None = None,
) -> FrictionFit:
    """Per-joint Nelder-Mead fit of the sigmoid (eq. 25) to a residual.

    Parameters
    ----------
    dq : array_like, shape (N, n)
        Joint velocities [rad/s].
    residual : array_like, shape (N, n)
        Torque residual [N m].
    maxiter : int
        Nelder-Mead iteration limit per joint.
    dq_noise_std : array_like, shape (n,), optional
        White-noise std of the measured velocities [rad/s]
        (:attr:`FrictionResidual.dq_noise_std`). Joints whose ``dq`` does not leave the
        noise band (:func:`moving_joints`) get zero friction; None: no noise, only
        :data:`MIN_MOTION` bounds the band.

    Returns
    -------
    FrictionFit

    Raises
    ------
    ShapeError, NonFiniteError
    DataError
        No joint moves beyond its velocity noise band.
    ConvergenceError
        The optimiser returned non-finite parameters.

    Warns
    -----
    DynidWarning
        Some joints do not move (named, 1-based): their friction is set to zero.
    """
    dq, residual = _pair(dq, residual)
    moving = _identifiable(dq, dq_noise_std)
    n = dq.shape[1]
    P = np.zeros((n, 3))
    ok = np.ones(n, bool)
    it = np.zeros(n, int)
    for j in np.flatnonzero(moving):
        P[j], ok[j], it[j] = _fit_sigmoid_joint(dq[:, j], residual[:, j], maxiter=maxiter)
    if not np.all(np.isfinite(P)):
        raise ConvergenceError(f"sigmoid fit gave non-finite parameters: {P.tolist()}")
    fr = SigmoidFriction.from_array(P)
    return _result(fr, dq, residual, ok, it, moving)


def fit_classical(
    dq: NDArray[np.float64],
    residual: NDArray[np.float64],
    *,
    dq_noise_std: ArrayLike | None = None,
) -> FrictionFit:
    """Per-joint linear least squares of ``fv dq + fc sign(dq) + fo`` (eq. 24) to a residual.

    Parameters
    ----------
    dq : array_like, shape (N, n)
        Joint velocities [rad/s].
    residual : array_like, shape (N, n)
        Torque residual [N m].
    dq_noise_std : array_like, shape (n,), optional
        As in :func:`fit_sigmoid`.

    Returns
    -------
    FrictionFit

    Raises
    ------
    ShapeError, NonFiniteError
    DataError
        No joint moves beyond its velocity noise band.

    Warns
    -----
    DynidWarning
        Some joints do not move (named, 1-based): their friction is set to zero.
    """
    dq, residual = _pair(dq, residual)
    moving = _identifiable(dq, dq_noise_std)
    n = dq.shape[1]
    P = np.zeros((n, 3))
    for j in np.flatnonzero(moving):
        A = np.stack([dq[:, j], np.sign(dq[:, j]), np.ones(dq.shape[0])], axis=1)
        P[j] = scipy.linalg.lstsq(A, residual[:, j])[0]
    fr = ClassicalFriction.from_array(P)
    return _result(fr, dq, residual, np.ones(n, bool), np.zeros(n, int), moving)


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
    cutoff_hz: float | None = DEFAULT_CUTOFF_HZ,
    trim_s: float | None = None,
    filter_tau: bool = False,
) -> FrictionFit:
    """Fit a friction model to the residual of ``model`` on a torque log.

    Parameters
    ----------
    model : TorqueModel
        Rigid-body model (friction not included): IdentifiedModel, Robot or callable.
    log : TorqueLog
        Measured log of a trajectory that visits both signs of every joint velocity.
    kind : {"sigmoid", "classical"}
    cutoff_hz, trim_s, filter_tau
        Preparation of the log (:func:`friction_residual`).

    Returns
    -------
    FrictionFit

    Raises
    ------
    ShapeError
        Unknown ``kind`` or joint counts that differ.
    DataError
        From the preparation of the log; no joint moves beyond its velocity noise band.

    Warns
    -----
    DynidWarning
        Some joints do not move: their friction is set to zero (:func:`fit_sigmoid`).
    """
    if kind not in ("sigmoid", "classical"):
        raise ShapeError(f"kind must be 'sigmoid' or 'classical'; got {kind!r}")
    res = friction_residual(model, log, cutoff_hz=cutoff_hz, trim_s=trim_s, filter_tau=filter_tau)
    if kind == "sigmoid":
        return fit_sigmoid(res.dq, res.residual, dq_noise_std=res.dq_noise_std)
    return fit_classical(res.dq, res.residual, dq_noise_std=res.dq_noise_std)


def fit_friction_through(
    res: FrictionResidual, drive: Drive | None, kind: str = "sigmoid"
) -> FrictionFit:
    """Fit a friction law where the drive says it acts (the motors of a gear train).

    At the motors the joint residual ``r`` becomes motor torques ``K^-T r`` at the motor
    velocities ``K dq`` (exact: ``K`` is invertible), each motor is fitted on its own
    (:func:`fit_sigmoid` or :func:`fit_classical`), and the result is a
    :class:`~dynid.friction.model.DriveFriction` whose RMS before and after are those of
    the joint torques. Without a drive (or with friction at the joints) the joints are fitted.

    Raises
    ------
    OptionError
        ``kind`` is neither ``"sigmoid"`` nor ``"classical"``.
    """
    fit_law = {"sigmoid": fit_sigmoid, "classical": fit_classical}.get(kind)
    if fit_law is None:
        raise OptionError(f"friction model must be 'sigmoid' or 'classical'; got {kind!r}")
    if drive is None or drive.friction_at == "joint":
        return fit_law(res.dq, res.residual, dq_noise_std=res.dq_noise_std)
    K = drive.transmission
    v = drive.motor_velocities(res.dq)
    r = np.asarray(np.linalg.solve(K.T, res.residual.T).T, dtype=np.float64)
    noise = None if res.dq_noise_std is None else np.sqrt((K**2) @ res.dq_noise_std**2)
    fit = fit_law(v, r, dq_noise_std=noise)
    law = fit.friction
    assert isinstance(law, SigmoidFriction | ClassicalFriction)  # a law per motor
    fr = DriveFriction(law, drive)
    after = res.residual - fr.torques(res.dq)
    return replace(
        fit,
        friction=fr,
        rms_before=np.sqrt(np.mean(res.residual**2, axis=0)),
        rms_after=np.sqrt(np.mean(after**2, axis=0)),
    )
