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

Pipeline: :func:`~dynid.identification.prepare.prepare_log` (resample if needed, zero-phase
low-pass of ``q``, ``dq``, ``tau``, ``ddq`` from the filtered ``dq``, trim the edges), then
**decimation**: after the low-pass at ``cutoff_hz`` the signals hold nothing above a few
times the cutoff, so keeping every ``k``-th sample with ``fs / k >= 10 cutoff_hz`` loses no
information and divides the cost of the regressor and of the least squares by ``k``
(the "parallel filtering and decimation" of Gautier, Khalil and coworkers). The
statistics then also assume less correlated residuals. ``decimate=1`` keeps every sample.
By default the cut-off and the decimation are read from the log
(:mod:`dynid.identification.rate`: 10 times the motion's highest significant frequency,
and at least 10 % of the samples kept).
Gaz et al. report a condition number of 122 and a relative error of 1.4 % for this route
on the real Panda.
"""

from __future__ import annotations

import warnings
from collections.abc import Iterator
from dataclasses import dataclass
from typing import Any, Literal

import numpy as np
from numpy.typing import NDArray

from .. import signals
from ..exceptions import DataError, DynidWarning, OptionError, ShapeError
from ..model.drive import Drive
from ..model.robot import Robot
from ..regressors.base import BaseParameters
from ..regressors.terms import (
    drive_terms,
    friction_labels,
)
from .core import (
    Judge,
    ModelColumns,
    RegressorBlock,
    RegressorStack,
    StreamedRows,
    identify,
    selected_columns,
)
from .estimators import (
    Estimator,
    EstimatorName,
    estimator_named,
    row_weights,
)
from .holdout import DEFAULT_FOLDS, HeldOut, Normals, block_labels, block_normals
from .info import IdentificationInfo, LogInfo
from .least_squares import StdMethod
from .log import LogCleaning, TorqueLog, joint_side_log
from .log_rows import (
    friction_regressor,
    log_blocks,
    parallel_filtered,
    still_columns,
    still_friction,
    term_regressor,
)
from .model import IdentifiedModel
from .prepare import measured_torques, prepare_log
from .rate import cutoff_from_motion, decimation, motion_frequency
from .sanity import (
    check_torque_log,
    moving_joints,
    opposite_sign,
    too_few_samples,
    velocity_noise_std,
)
from .streaming import BlockSource, normals_by_label

__all__ = [
    "PreparedLog",
    "log_blocks",
    "parallel_filtered",
    "still_columns",
    "auto_decimation",
    "friction_labels",
    "friction_regressor",
    "identify_from_log",
    "prepare_torque_log",
    "term_regressor",
]

_ = friction_labels  # re-exported: the labels of friction_regressor


def auto_decimation(fs: float, cutoff_hz: float | None) -> int:
    """Largest ``k`` with ``fs / k >= 10 cutoff_hz`` (1 without filtering)."""
    if cutoff_hz is None:
        return 1
    return max(1, int(np.floor(fs / (10.0 * cutoff_hz))))


def identify_from_log(
    robot: Robot,
    log: TorqueLog,
    *,
    cutoff_hz: float | Literal["auto"] | None = "auto",
    trim_s: float | None = None,
    max_gap_s: float | None = None,
    decimate: int | None = None,
    max_std_percent: float | None = None,
    friction: bool = True,
    base: BaseParameters | None = None,
    rtol: float | None = None,
    drive: Drive | None = None,
    estimator: EstimatorName | Estimator = "ols",
    std: StdMethod = "classical",
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
    cutoff_hz : float, "auto" or None
        Zero-phase low-pass cutoff [Hz] (:func:`~dynid.identification.prepare.prepare_log`);
        ``"auto"`` (default) reads it from the motion
        (:func:`~dynid.identification.rate.cutoff_from_motion`); None for noise-free data
        (then ``ddq`` of the log is used if present, else differentiated).
    trim_s : float, optional
        Seconds dropped at each end after filtering (default ``2 / cutoff_hz``).
    max_gap_s : float, optional
        Longest gap bridged [s] (:func:`~dynid.identification.prepare.prepare_log`).
    decimate : int, optional
        Keep every ``decimate``-th sample after filtering; default
        :func:`~dynid.identification.rate.decimation` (at least 10 % of the samples).
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
    prepared = prepare_torque_log(
        robot,
        log,
        cutoff_hz=cutoff_hz,
        trim_s=trim_s,
        max_gap_s=max_gap_s,
        decimate=decimate,
        drive=drive,
    )
    return identify(
        robot,
        prepared,
        drive=drive,
        terms=drive_terms(drive, robot.n, friction=friction),
        base=base,
        estimator=estimator,
        std=std,
        max_std_percent=max_std_percent,
        rtol=rtol,
        judge=_judge(robot, prepared, estimator, folds, validate_on, prepared.cutoff_hz, trim_s),
        fold_labels=_fold_labels(prepared, folds) if validate_on is None else None,
    )


def _fold_labels(prepared: PreparedLog, folds: int) -> NDArray[np.intp] | None:
    """The fold of every row of the prepared log (contiguous time blocks), or None when the
    log is too short for them."""
    try:
        return np.repeat(block_labels(prepared.log.n_samples, folds), prepared.n)
    except OptionError:
        return None


def _judge(
    robot: Robot,
    prepared: PreparedLog,
    estimator: EstimatorName | Estimator,
    folds: int,
    validate_on: TorqueLog | None,
    cutoff_hz: float | None,
    trim_s: float | None,
) -> Judge:
    """The held-out judgement of the classical route: ``folds`` contiguous time blocks of
    the log, or the separate log ``validate_on`` prepared the same way; rows weighted as the
    estimator weighs them (:func:`~dynid.identification.estimators.row_weights`)."""
    n = prepared.n
    est = estimator_named(estimator)

    def judge(
        stack: RegressorStack | StreamedRows,
        columns: ModelColumns,
        cols: NDArray[np.bool_],
        beta: NDArray[Any],
    ) -> HeldOut | None:
        b = np.asarray(beta)[cols]
        if isinstance(stack, StreamedRows):
            source = selected_columns(stack.source, cols)
            return _held_out_streamed(source, b, cols, columns, stack.normals)
        W, y = (stack.W if cols.all() else stack.W[:, cols]), stack.y
        rw = row_weights(est, W, y, stack.groups, b)
        if validate_on is None:
            return _held_out(W * rw[:, None], y * rw, n, folds, cols)
        rate = prepared.sample_rate_hz / prepared.decimate
        vW, vy = _validation_rows(robot, validate_on, columns, cols, cutoff_hz, trim_s, rate)
        vw = row_weights(est, vW, vy, np.tile(np.arange(n), vy.size // n), b)
        return HeldOut.separate(
            block_normals(W * rw[:, None], y * rw, np.zeros(y.size, dtype=np.intp))[0],
            block_normals(vW * vw[:, None], vy * vw, np.zeros(vy.size, dtype=np.intp))[0],
        ).expanded(cols)

    def _held_out_streamed(
        source: BlockSource,
        b: NDArray[np.float64],
        cols: NDArray[np.bool_],
        columns: ModelColumns,
        stack_normals: tuple[Normals, ...] | None,
    ) -> HeldOut | None:
        """The judgement of rows left in blocks (a long log), from their normal equations
        (those of the folds gathered by the fit's pass when it was given them)."""
        if validate_on is None and stack_normals is not None:
            return HeldOut.k_fold(stack_normals).expanded(cols)
        e = np.concatenate([y - W @ b for W, y, _ in source()])
        N = e.size // n
        rw = est.row_weights(e, np.tile(np.arange(n, dtype=np.intp), N), b.size)
        del e
        if validate_on is None:
            try:
                labels = np.repeat(block_labels(N, folds), n)
            except OptionError:
                return None
            return HeldOut.k_fold(normals_by_label(source, labels, rw)).expanded(cols)
        rate = prepared.sample_rate_hz / prepared.decimate
        vW, vy = _validation_rows(robot, validate_on, columns, cols, cutoff_hz, trim_s, rate)
        vw = row_weights(est, vW, vy, np.tile(np.arange(n), vy.size // n), b)
        return HeldOut.separate(
            normals_by_label(source, np.zeros(N * n, dtype=np.intp), rw)[0],
            block_normals(vW * vw[:, None], vy * vw, np.zeros(vy.size, dtype=np.intp))[0],
        ).expanded(cols)

    return judge


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
    columns: ModelColumns,
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
    drive = columns.drive
    p = prepare_log(joint_side_log(log, drive), cutoff_hz=cutoff_hz, trim_s=trim_s)
    step = max(1, int(round(log.sample_rate / rate_hz)))
    sl = slice(None, None, step)
    assert p.ddq is not None
    q, dq, ddq, tau = p.q[sl], p.dq[sl], p.ddq[sl], p.tau[sl]
    Y, _ = term_regressor(robot, columns.base, columns.terms, q, dq, ddq)
    if cutoff_hz is not None:
        Y = parallel_filtered(Y, columns.step_columns(), p.t[sl], cutoff_hz)
    if drive is not None and drive.rotor_inertia is not None:
        tau = tau - drive.rotor_torques(ddq, drive.rotor_inertia)
    return Y.reshape(q.shape[0] * robot.n, -1)[:, cols], tau.reshape(-1)


@dataclass(frozen=True, slots=True, eq=False)
class PreparedLog:
    """A torque log ready for identification (the :class:`~dynid.identification.core.Dataset`
    of the classical route): joint side, filtered, decimated, with ``ddq``.

    Attributes
    ----------
    log : TorqueLog
        The prepared samples: ``q`` [rad], ``dq`` [rad/s], ``ddq`` [rad/s^2], ``tau`` [N m]
        on the joint side of ``drive``, every ``decimate``-th sample.
    drive : Drive, optional
        The drive the log was read through.
    still : ndarray of bool, shape (n,)
        Joints (motors, where the drive's friction acts there) whose velocity never leaves
        its noise band in the raw log: their viscous and Coulomb friction is not fitted.
    cutoff_hz, trim_s : float or None
        Low-pass cutoff [Hz] and seconds trimmed at the start.
    motion_frequency_hz : float or None
        The motion's highest significant frequency [Hz] when the cut-off was read from it
        (:mod:`dynid.identification.rate`), else None.
    resampled : bool
        The timestamps were not uniform: the log was resampled onto a uniform grid.
    decimate : int
    sample_rate_hz : float
        Of the raw log.
    raw : TorqueLog
        The raw log's counts (``n_samples``, ``duration``, ``cleaning``).
    torque_noise_std : ndarray, shape (n,), or None
        White-noise std [N m] per joint of the raw log's joint-side torques
        (:func:`~dynid.identification.sanity.velocity_noise_std`, which reads any signal's).
    tau_raw : ndarray, shape like ``log.tau``, or None
        The joint-side torques at the prepared samples as measured, not low-passed (None
        when the log was not filtered): the held-out judgement predicts them, as
        ``dynid validate`` does.
    """

    log: TorqueLog
    drive: Drive | None
    still: NDArray[np.bool_]
    cutoff_hz: float | None
    trim_s: float
    decimate: int
    sample_rate_hz: float
    n_samples_log: int
    duration_s: float
    cleaning: LogCleaning
    motion_frequency_hz: float | None = None
    resampled: bool = False
    torque_noise_std: NDArray[np.float64] | None = None
    tau_raw: NDArray[np.float64] | None = None

    @property
    def route(self) -> Literal["classical"]:
        """``"classical"`` (Gaz et al. 2019, Sec. IV-B)."""
        return "classical"

    @property
    def regressor_kind(self) -> Literal["torque"]:
        """Joint torques."""
        return "torque"

    @property
    def moving(self) -> bool:
        """True: friction acts."""
        return True

    @property
    def n(self) -> int:
        """Joints."""
        return self.log.n

    @property
    def source(self) -> str:
        """``"torque log of N samples"``."""
        return f"torque log of {self.log.n_samples} samples"

    @property
    def hint(self) -> str:
        """What to do when the trajectory does not excite every column."""
        return (
            "hint: a trajectory that moves every joint at varied speeds in both directions "
            "excites them (dynid excite optimises one); a joint that never moves leaves its "
            "friction unidentifiable"
        )

    def check_robot(self, robot: Robot) -> None:
        """Raise :class:`ShapeError` unless the log has ``robot.n`` joints."""
        if self.n != robot.n:
            raise ShapeError(f"log has {self.n} joints; robot {robot.name!r} has {robot.n}")

    def frozen_columns(self, columns: ModelColumns) -> NDArray[np.bool_]:
        """The viscous and Coulomb columns of the joints (motors) that never move."""
        return still_columns(columns, self.still)

    def blocks(self, robot: Robot, columns: ModelColumns) -> Iterator[RegressorBlock]:
        """One block (:func:`log_blocks`); several when the log is too long to stack."""
        if columns.drive is not self.drive:
            raise OptionError("the log was prepared for another drive than the model's")
        yield from log_blocks(robot, self.log, columns, cutoff_hz=self.cutoff_hz)

    def record(self, n_rows: int) -> IdentificationInfo:
        """Filtering, decimation and sample counts."""
        return IdentificationInfo(
            reference="Gaz et al. 2019, Sec. IV-B, eq. 24 (classical friction)",
            log=LogInfo(
                cutoff_hz=self.cutoff_hz,
                trim_s=self.trim_s,
                decimate=self.decimate,
                sample_rate_hz=self.sample_rate_hz,
                n_samples_log=self.n_samples_log,
                n_samples_used=self.log.n_samples,
                duration_s=self.duration_s,
                n_nan_rows=self.cleaning.n_nan_rows,
                n_duplicates=self.cleaning.n_duplicates,
                n_gaps=len(self.cleaning.gaps),
                cutoff_source="given" if self.motion_frequency_hz is None else "motion",
                motion_frequency_hz=self.motion_frequency_hz,
                resampled=self.resampled,
            ),
        )


def prepare_torque_log(
    robot: Robot,
    log: TorqueLog,
    *,
    cutoff_hz: float | Literal["auto"] | None = "auto",
    trim_s: float | None = None,
    max_gap_s: float | None = None,
    decimate: int | None = None,
    drive: Drive | None = None,
    check: bool = True,
) -> PreparedLog:
    """Read a torque log through the drive, check it, filter and decimate it.

    The checks of :func:`~dynid.identification.sanity.check_torque_log` (sign, units,
    frozen joints) are warned first (unless ``check`` is False: a piece of a recording
    checked whole); then :func:`~dynid.identification.prepare.prepare_log`
    and every ``decimate``-th sample (default :func:`~dynid.identification.rate.decimation`;
    the cut-off ``"auto"``: :func:`~dynid.identification.rate.cutoff_from_motion`).
    Parameters as in
    :func:`identify_from_log`.

    Raises
    ------
    ShapeError
        ``log.n != robot.n`` or ``decimate < 1``.
    DataError
        From :func:`~dynid.identification.prepare.prepare_log`.

    Warns
    -----
    DynidWarning
        The findings of the checks.
    """
    n = robot.n
    if log.n != n:
        raise ShapeError(f"log has {log.n} joints; robot {robot.name!r} has {n}")
    if drive is not None:
        drive.check(n)
    fs = log.sample_rate
    jlog = joint_side_log(log, drive)
    if (few := too_few_samples(jlog)) is not None:
        raise DataError(few)
    if check and (opposite := opposite_sign(robot, jlog)) is not None:
        raise DataError(opposite)  # a fit would negate the masses
    for finding in check_torque_log(robot, jlog) if check else ():  # said first
        warnings.warn(finding, DynidWarning, stacklevel=3)
    still = still_friction(jlog, drive)
    f_q = None
    if cutoff_hz == "auto":
        f_q = motion_frequency(jlog.q, fs, moving_joints(jlog.dq))
        cutoff_hz = cutoff_from_motion(jlog.q, jlog.dq, fs)
    k = decimation(fs, cutoff_hz) if decimate is None else int(decimate)
    if k < 1:
        raise ShapeError(f"decimate must be >= 1; got {decimate}")
    same = dict(cutoff_hz=cutoff_hz, trim_s=trim_s, max_gap_s=max_gap_s, decimate=k)
    prepared = prepare_log(jlog, **same)  # type: ignore[arg-type]
    raw = None
    if cutoff_hz is not None:  # the torques as measured at the same samples
        raw = measured_torques(jlog, **same)  # type: ignore[arg-type]
    noise = velocity_noise_std(jlog.tau) if jlog.n_samples >= 3 else None
    del jlog
    return PreparedLog(
        log=prepared,
        drive=drive,
        still=still,
        cutoff_hz=cutoff_hz,
        trim_s=float(prepared.t[0] - log.t[0]),
        decimate=k,
        sample_rate_hz=fs,
        n_samples_log=log.n_samples,
        duration_s=log.duration,
        cleaning=log.cleaning,
        motion_frequency_hz=f_q,
        resampled=not signals.is_uniform(log.t),
        torque_noise_std=noise,
        tau_raw=None if raw is None or raw.shape != prepared.tau.shape else raw,
    )
