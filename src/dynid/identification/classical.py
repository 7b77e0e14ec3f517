"""Classical identification from the torque log of an exciting trajectory (Gaz et al. 2019).

Sec. IV-B of the paper:

.. math:: \\tau_k = Y_b(q_k, \\dot q_k, \\ddot q_k)\\, \\beta + F(\\dot q_k)\\, f,
          \\qquad f_j = (f_{v,j}, f_{c,j}, f_{o,j})

stacked over samples ``k`` and solved by ordinary least squares
(:func:`~dynid.identification.least_squares.fit_least_squares`, the same estimator and
statistics as the static route). ``Y_b`` is the torque regressor reduced to the base
parameters of ``base_parameters(robot, kind="torque")``; ``F`` holds the classical
friction of each joint (eq. 24), ``fv dq_j + fc sign(dq_j) + fo`` in the row of joint
``j`` only. Columns are ordered ``beta1 .. beta_r`` then ``fv1, fc1, fo1, fv2, ...``;
rows sample-major (row ``k n + j`` is sample ``k``, joint ``j``).

Pipeline: :func:`~dynid.identification.log.prepare_log` (resample if needed, zero-phase
low-pass of ``q``, ``dq``, ``tau``, ``ddq`` from the filtered ``dq``, trim the edges), then
**decimation**: after the low-pass at ``cutoff_hz`` the signals hold nothing above a few
times the cutoff, so keeping every ``k``-th sample with ``fs / k >= 10 cutoff_hz`` loses no
information and divides the cost of the regressor and of the least squares by ``k``
(the "parallel filtering and decimation" of Gautier, Khalil and coworkers). The
statistics then also assume less correlated residuals. ``decimate=1`` keeps every sample.
Gaz et al. report a condition number of 122 and a relative error of 1.4 % for this route
on the real Panda.
"""

from __future__ import annotations

import dataclasses
import warnings
from typing import Any, Literal

import numpy as np
from numpy.typing import NDArray

from .. import _checks
from ..exceptions import DynidWarning, OptionError, RankDeficientError, ShapeError
from ..model.drive import Drive
from ..model.robot import Robot
from ..regressors.base import BaseParameters, base_parameters, identifiability
from ..regressors.terms import (
    LinearFriction,
    ModelTerm,
    base_term_columns,
    drive_terms,
    friction_labels,
)
from ..regressors.torque import torque_regressor_prepared
from .estimators import Estimator, EstimatorName, estimator_named, row_weights
from .holdout import DEFAULT_FOLDS, HeldOut, block_labels, block_normals, cross_validate
from .least_squares import LeastSquaresFit, conditioning_advice
from .log import DEFAULT_CUTOFF_HZ, TorqueLog, joint_side_log, prepare_log
from .model import IdentifiedModel
from .sanity import check_torque_log, moving_joints

__all__ = ["friction_labels", "friction_regressor", "identify_from_log", "auto_decimation"]

_ = friction_labels  # re-exported: the labels of friction_regressor


def friction_regressor(dq: NDArray[np.float64]) -> NDArray[np.float64]:
    """Regressor ``F`` (..., n, 3 n) of the classical friction at the joints, columns
    :func:`~dynid.regressors.terms.friction_labels`.

    ``F[..., j, 3 j : 3 j + 3] = (dq_j, sign(dq_j), 1)``; zero elsewhere.
    """
    return LinearFriction(Drive.identity(dq.shape[-1])).torque_columns(dq, dq, dq)


def auto_decimation(fs: float, cutoff_hz: float | None) -> int:
    """Largest ``k`` with ``fs / k >= 10 cutoff_hz`` (1 without filtering)."""
    if cutoff_hz is None:
        return 1
    return max(1, int(np.floor(fs / (10.0 * cutoff_hz))))


def _split_fit(fit: LeastSquaresFit, r: int) -> LeastSquaresFit:
    """The fit restricted to its first ``r`` coefficients; global statistics kept."""
    return dataclasses.replace(
        fit,
        beta=fit.beta[:r],
        std=fit.std[:r],
        std_percent=fit.std_percent[:r],
        kept=fit.kept[:r],
        covariance=None if fit.covariance is None else fit.covariance[:r, :r],
    )


def identify_from_log(
    robot: Robot,
    log: TorqueLog,
    *,
    cutoff_hz: float | None = DEFAULT_CUTOFF_HZ,
    trim_s: float | None = None,
    max_gap_s: float | None = None,
    decimate: int | None = None,
    max_std_percent: float | None = None,
    friction: bool = True,
    base: BaseParameters | None = None,
    rtol: float | None = None,
    drive: Drive | None = None,
    estimator: EstimatorName | Estimator = "ols",
    std: Literal["classical", "robust"] = "classical",
    folds: int = DEFAULT_FOLDS,
    validate_on: TorqueLog | None = None,
) -> IdentifiedModel:
    """Identify base parameters (and linear friction) from a torque log.

    Parameters
    ----------
    robot : Robot
        Kinematics and gravity; its inertial parameters are not used.
    log : TorqueLog
        Measured ``t``, ``q``, ``dq``, ``tau`` (``ddq`` optional) of an exciting trajectory.
    cutoff_hz : float or None
        Zero-phase low-pass cutoff [Hz] (:func:`~dynid.identification.log.prepare_log`);
        None for noise-free data (then ``ddq`` of the log is used if present, else
        differentiated).
    trim_s : float, optional
        Seconds dropped at each end after filtering (default ``2 / cutoff_hz``).
    max_gap_s : float, optional
        Longest gap bridged [s] (:func:`~dynid.identification.log.prepare_log`).
    decimate : int, optional
        Keep every ``decimate``-th sample after filtering; default
        :func:`auto_decimation`.
    max_std_percent : float, optional
        Remove coefficients with a larger relative standard deviation and re-fit (the
        paper used 30 %).
    friction : bool
        Identify ``fv, fc, fo`` per joint together with the base parameters.
    base : BaseParameters, optional
        Base parameters to use; default ``base_parameters(robot, kind="torque")``.
    rtol : float, optional
        Relative rank tolerance of the base parameters and of the least squares; default:
        the base parameters' rank from the first clear gap of the singular values
        (:func:`dynid.regressors.base.rank_from_gap`) and ``1e-10`` for the fit.
    drive : Drive, optional
        The drive train (:mod:`dynid.model.drive`): the log is read on its side and with its
        effort (motor positions and torques or currents become joint ones), its rotor
        inertias are identified with the links (or subtracted when known) and the friction
        acts where it says (the motors for a gear train). Default: link-side torques of a
        direct drive.
    estimator : {"ols", "wls", "irls"} or Estimator
        Ordinary, per-joint weighted or Huber-robust least squares
        (:mod:`dynid.identification.estimators`).
    std : {"classical", "robust"}
        Standard deviations from ``sigma^2 (W^T W)^-1`` (default) or the
        heteroscedasticity-consistent estimate.
    folds : int
        Contiguous time blocks of the held-out judgement
        (:mod:`dynid.identification.holdout`); a log too short for them is not judged.
    validate_on : TorqueLog, optional
        A separate recording (same joints, read the same way) that the held-out error is
        measured on instead of the blocks.

    Returns
    -------
    IdentifiedModel
        ``fit`` holds the ``r`` base parameters (with the statistics of the whole fit:
        condition number, relative error, sigma); ``friction`` (n, 3) columns
        ``fv, fc, fo`` or None; ``metadata`` the route, filter settings, sample counts,
        the friction labels and their standard deviations, ``heldout`` the training and
        held-out errors of least squares; ``holdout`` the folds' normal equations.

    Raises
    ------
    ShapeError
        ``log.n != robot.n`` or ``decimate < 1``.
    DataError
        From the preparation of the log (gaps, too short, bad cutoff).
    RankDeficientError
        The trajectory does not excite every base parameter (and friction column); the
        message names the nearly dependent columns.

    Warns
    -----
    DynidWarning
        Ill-conditioned regressor or coefficients above 1000 % std
        (:func:`~dynid.identification.least_squares.conditioning_advice`).
    """
    n = robot.n
    if log.n != n:
        raise ShapeError(f"log has {log.n} joints; robot {robot.name!r} has {n}")
    if drive is not None:
        drive.check(n)
    fs = log.sample_rate
    jlog = joint_side_log(log, drive)
    for finding in check_torque_log(robot, jlog):  # sign, units, frozen joints: said first
        warnings.warn(finding, DynidWarning, stacklevel=2)
    still = _still_friction(jlog, drive) if friction else np.zeros(0, dtype=bool)
    prepared = prepare_log(jlog, cutoff_hz=cutoff_hz, trim_s=trim_s, max_gap_s=max_gap_s)
    del jlog
    k = auto_decimation(fs, cutoff_hz) if decimate is None else int(decimate)
    if k < 1:
        raise ShapeError(f"decimate must be >= 1; got {decimate}")
    sl = slice(None, None, k)
    assert prepared.ddq is not None  # prepare_log always fills ddq
    q, dq, ddq, tau = prepared.q[sl], prepared.dq[sl], prepared.ddq[sl], prepared.tau[sl]
    terms = drive_terms(drive, n, friction=friction)
    bp = base_parameters(robot, kind="torque", rtol=rtol, terms=terms) if base is None else base
    N = q.shape[0]
    Yb, labels = term_regressor(robot, bp, terms, q, dq, ddq)
    W = Yb.reshape(N * n, -1)
    if drive is not None and drive.rotor_inertia is not None:  # known: not identified
        tau = tau - drive.rotor_torques(ddq, drive.rotor_inertia)
    y = tau.reshape(-1)
    r = bp.rank
    fit_rtol = 1e-10 if rtol is None else rtol
    est = estimator_named(estimator)
    if std not in ("classical", "robust"):
        raise OptionError(f"std must be 'classical' or 'robust'; got {std!r}")
    # the viscous and Coulomb columns of a joint (motor) that never moves are not fitted
    cols = np.ones(W.shape[1], dtype=bool)
    if still.any():
        cols[bp.rank :][np.repeat(still, 3) & (np.arange(3 * n) % 3 != 2)] = False
        W = W[:, cols]
    try:
        _checks.finite("regressor", W)
        fit = est.fit(
            W,
            y,
            np.tile(np.arange(n), N),  # row k n + j: joint j
            rtol=fit_rtol,
            covariance=std,
            max_std_percent=max_std_percent,
            labels=tuple(lab for lab, c in zip(labels, cols, strict=True) if c),
        )
    except RankDeficientError as exc:
        raise RankDeficientError(
            f"torque log: {exc}; hint: a trajectory that moves every joint at varied "
            "speeds in both directions excites them (dynid excite optimises one); a joint "
            "that never moves leaves its friction unidentifiable"
        ) from exc
    rw = row_weights(est, W, y, np.tile(np.arange(n), N), fit.beta)
    held = _held_out(W * rw[:, None], y * rw, n, folds, cols)
    if validate_on is not None:
        vW, vy = _validation_rows(
            robot, validate_on, drive, bp, terms, cols, cutoff_hz, trim_s, fs / k
        )
        vw = row_weights(est, vW, vy, np.tile(np.arange(n), vy.size // n), fit.beta)
        held = HeldOut.separate(
            block_normals(W * rw[:, None], y * rw, np.zeros(y.size, dtype=np.intp))[0],
            block_normals(vW * vw[:, None], vy * vw, np.zeros(vy.size, dtype=np.intp))[0],
        ).expanded(cols)
    if not cols.all():
        fit = _expanded(fit, cols)
    for msg in conditioning_advice(fit, labels, what="the trajectory"):
        warnings.warn(msg, DynidWarning, stacklevel=2)
    fr = None
    meta: dict[str, Any] = {
        "route": "classical",
        "reference": "Gaz et al. 2019, Sec. IV-B, eq. 24 (classical friction)",
        "pruned": [labels[j] for j in np.flatnonzero(~np.asarray(fit.kept))],
        "max_std_percent": max_std_percent,
        "std_estimator": std,
        "estimator": est.name,
        "dropped_rows": [],
        "cutoff_hz": cutoff_hz,
        "trim_s": float(prepared.t[0] - log.t[0]),
        "decimate": k,
        "sample_rate_hz": fs,
        "n_samples_log": log.n_samples,
        "n_samples_used": int(N),
        "n_rows": int(N * n),
        "duration_s": log.duration,
        "n_nan_rows": log.cleaning.n_nan_rows,
        "n_duplicates": log.cleaning.n_duplicates,
        "n_gaps": len(log.cleaning.gaps),
        "condition_number": fit.condition_number,
        "scaled_condition_number": fit.scaled_condition_number,
        "relative_error_percent": fit.relative_error_percent,
        "rank_gap": None if bp.gap is None else list(bp.gap),
        "identifiability": dict(zip(bp.std_labels, identifiability(bp), strict=True)),
    }
    if drive is not None:
        meta["drive"] = drive.as_dict()
    if held is not None:
        meta["heldout"] = cross_validate(held.restricted(np.flatnonzero(fit.kept))).as_dict()
    if friction:
        fb = np.asarray(fit.beta[r:]).reshape(n, 3)
        fr = fb
        meta["friction_labels"] = list(friction_labels(n))
        meta["friction_std"] = [float(x) for x in fit.std[r:]]
        meta["friction_kept"] = [bool(x) for x in fit.kept[r:]]
    return IdentifiedModel(
        robot=robot,
        base=bp,
        fit=_split_fit(fit, r) if friction else fit,
        friction=fr,
        metadata=meta,
        joint_fit=fit if friction else None,
        drive=drive,
        holdout=held,
    )


def _held_out(
    W: NDArray[np.float64],
    y: NDArray[np.float64],
    n: int,
    folds: int,
    cols: NDArray[np.bool_],
) -> HeldOut | None:
    """The k-fold time blocks of the rows (sample-major, ``n`` rows a sample) over all the
    columns (``cols`` those of ``W``, rows weighted as the estimator weighs them); None
    when the log is too short for them."""
    N = y.size // n
    try:
        labels = np.repeat(block_labels(N, folds), n)
    except OptionError:
        return None
    return HeldOut.k_fold(block_normals(W, y, labels)).expanded(cols)


def _validation_rows(
    robot: Robot,
    log: TorqueLog,
    drive: Drive | None,
    bp: BaseParameters,
    terms: tuple[ModelTerm, ...],
    cols: NDArray[np.bool_],
    cutoff_hz: float | None,
    trim_s: float | None,
    rate_hz: float,
) -> tuple[NDArray[np.float64], NDArray[np.float64]]:
    """Regressor and torques of a validation log, prepared as the identification's was
    (decimated to about ``rate_hz``)."""
    if log.n != robot.n:
        raise ShapeError(
            f"--validate-on log has {log.n} joints; robot {robot.name!r} has {robot.n}"
        )
    p = prepare_log(joint_side_log(log, drive), cutoff_hz=cutoff_hz, trim_s=trim_s)
    step = max(1, int(round(log.sample_rate / rate_hz)))
    sl = slice(None, None, step)
    assert p.ddq is not None
    q, dq, ddq, tau = p.q[sl], p.dq[sl], p.ddq[sl], p.tau[sl]
    Y, _ = term_regressor(robot, bp, terms, q, dq, ddq)
    if drive is not None and drive.rotor_inertia is not None:
        tau = tau - drive.rotor_torques(ddq, drive.rotor_inertia)
    return Y.reshape(q.shape[0] * robot.n, -1)[:, cols], tau.reshape(-1)


def _still_friction(log: TorqueLog, drive: Drive | None) -> NDArray[np.bool_]:
    """Joints (motors, where the drive's friction acts there) whose velocity never leaves
    its noise band: their viscous and Coulomb friction is not fitted from noise."""
    if drive is None:
        return ~moving_joints(log.dq)
    return ~moving_joints(log.dq @ drive.friction_transmission.T)


def _expanded(fit: LeastSquaresFit, cols: NDArray[np.bool_]) -> LeastSquaresFit:
    """A fit over the columns ``cols`` selected, written over all of them (0 and not kept
    for the others)."""
    k = cols.size

    def put(v: NDArray[Any], fill: Any) -> NDArray[Any]:
        out = np.full(k, fill, dtype=np.asarray(v).dtype)
        out[cols] = v
        return out

    cov = None
    if fit.covariance is not None:
        cov = np.zeros((k, k))
        cov[np.ix_(cols, cols)] = fit.covariance
    return dataclasses.replace(
        fit,
        beta=put(fit.beta, 0.0),
        std=put(fit.std, 0.0),
        std_percent=put(fit.std_percent, np.nan),
        kept=put(fit.kept, False),
        covariance=cov,
        weakest=put(fit.weakest, 0.0) if np.size(fit.weakest) == cols.sum() else fit.weakest,
        effect_percent=put(fit.effect_percent, 0.0)
        if np.size(fit.effect_percent) == cols.sum()
        else fit.effect_percent,
    )


def term_regressor(
    robot: Robot,
    base: BaseParameters,
    terms: tuple[ModelTerm, ...],
    q: NDArray[np.float64],
    dq: NDArray[np.float64],
    ddq: NDArray[np.float64],
) -> tuple[NDArray[np.float64], tuple[str, ...]]:
    """The regressor (N, n, r + p_t) of the base parameters and the appended terms.

    Columns: the independent base columns in ``base.independent`` order (link parameters
    from the compiled regressor, then those of the ``in_base`` terms), then every column of
    each term that is not ``in_base`` (friction). Returns it with its labels.
    """
    ind = np.asarray(base.independent)
    rigid = ind[ind < 10 * robot.n]
    appended = [t for t in terms if not t.in_base]
    width = ind.size + sum(len(t.labels) for t in appended)
    Y = torque_regressor_prepared(robot, q, dq, ddq, robot.gravity, columns=rigid, width=width)
    c = rigid.size
    for t, sel in base_term_columns(terms, ind, robot.n):
        if sel.size:
            Y[..., c : c + sel.size] = t.torque_columns(q, dq, ddq)[..., sel]
            c += sel.size
    labels = base.labels
    for t in appended:
        Y[..., c : c + len(t.labels)] = t.torque_columns(q, dq, ddq)
        c += len(t.labels)
        labels = labels + t.labels
    return Y, labels
