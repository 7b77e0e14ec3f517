"""A torque log prepared for identification: read through the drive, checked, filtered,
differentiated and decimated (:func:`prepare_torque_log`), and the data set of the
classical route it is (:class:`PreparedLog`, a
:class:`~dynid.identification.dataset.Dataset`; a recording's pieces,
:class:`~dynid.identification.recordings.Recordings`, are made of them).

The signals are those of a :class:`~dynid.identification.log.TorqueLog`: ``q`` [rad],
``dq`` [rad/s], ``ddq`` [rad/s^2], ``tau`` [N m] on the joint side of the drive, rows the
samples.
"""

from __future__ import annotations

import warnings
from collections.abc import Iterator
from dataclasses import dataclass
from typing import Any, Literal

import numpy as np
from numpy.typing import NDArray

from .. import signals
from .._checks import caller_level
from ..exceptions import DataError, DynidWarning, OptionError, ShapeError
from ..model.drive import Drive
from ..model.robot import Robot
from .dataset import ModelColumns, RegressorBlock, TorqueRoute
from .info import IdentificationInfo, LogInfo
from .log import LogCleaning, TorqueLog, joint_side_log
from .log_rows import less_known_rotors, log_blocks, still_columns, still_friction
from .model_sign import opposite_sign
from .prepare import (
    Preprocessing,
    grid_samples,
    measured_torques,
    prepare_log,
    prepared_and_fine,
    resamples,
    trimmed_margins,
)
from .rate import cutoff_from_motion, decimation, motion_frequency
from .sanity import check_torque_log, too_few_samples
from .serial import Serial, hac_lag
from .training_range import motion_ranges
from .velocity_noise import moving_joints, signal_noise_std

__all__ = ["MAX_FINE_BYTES", "PreparedLog", "prepare_torque_log"]

#: The largest full-rate prepared log (``t``, ``q``, ``dq``, ``ddq``, ``tau``) [bytes] a
#: decimated log holds for its stepping columns (:attr:`PreparedLog.fine`): a 7-joint log
#: of 19 minutes at 1 kHz; a longer one has its states interpolated between its decimated
#: samples.
MAX_FINE_BYTES = 256 << 20


@dataclass(frozen=True, slots=True, eq=False)
class PreparedLog(TorqueRoute):
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
        (:func:`~dynid.identification.velocity_noise.signal_noise_std`, which reads any signal's).
    tau_raw : ndarray, shape like ``log.tau``, or None
        The joint-side torques at the prepared samples as measured, not low-passed (None
        when the log was not filtered): the held-out judgement predicts them, as
        ``dynid validate`` does.
    head, tail : TorqueLog or None
        The samples trimmed before and after ``log``, prepared alike at the same decimated
        step (:func:`~dynid.identification.prepare.trimmed_margins`): the parallel
        filtering of the columns that step at a reversal reads them near the ends; None
        without filtering or for a margin of fewer than 2 samples.
    stamps : ndarray, shape (N,), or None
        The instants [s] the raw log was measured at, when they were not uniform (the
        log resampled onto a grid): the stepping columns are computed there and
        interpolated onto the grid as the torques were, and the held-out judgement reads
        each prepared sample at its own measured instant
        (:func:`~dynid.identification.prepare.measured_instants`). None otherwise.
    fine : TorqueLog or None
        The log prepared at every sample of its grid, none trimmed
        (:func:`~dynid.identification.prepare.fine_states`): ``log`` is
        ``fine[fine_start :: decimate]``. The stepping columns are computed from it when
        it is held (a filtered, decimated log whose states fit in
        :data:`MAX_FINE_BYTES`), else from states
        interpolated between the decimated samples and the margins ``head``, ``tail``.
    fine_start : int
        The index in ``fine`` of the first prepared sample.
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
    head: TorqueLog | None = None
    tail: TorqueLog | None = None
    stamps: NDArray[np.float64] | None = None
    fine: TorqueLog | None = None
    fine_start: int = 0

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

    @property
    def lag(self) -> int:
        """The HAC window [samples] of its residual (:func:`~.serial.hac_lag` of the
        cut-off at the decimated rate)."""
        return hac_lag(self.cutoff_hz, self.sample_rate_hz / self.decimate)

    @property
    def serial(self) -> Serial:
        """One piece of samples of ``n`` rows, window :attr:`lag`."""
        return Serial(self.n, self.lag)

    def targets(self, tau: NDArray[np.float64] | None = None) -> NDArray[np.float64]:
        """The torques [N m] (N, n) the fit's rows target (:func:`log_blocks`): ``tau``
        (default the prepared log's; the raw torques of the same samples) less the rotor
        torques of the drive's known rotor inertias, which the rows take off."""
        out = self.log.tau if tau is None else tau
        return out if self.log.ddq is None else less_known_rotors(out, self.log.ddq, self.drive)

    def blocks(self, robot: Robot, columns: ModelColumns) -> Iterator[RegressorBlock]:
        """One block (:func:`log_blocks`); several when the log is too long to stack."""
        if columns.drive is not self.drive:
            raise OptionError("the log was prepared for another drive than the model's")
        yield from log_blocks(robot, self.log, columns, **self.filtering)

    @property
    def filtering(self) -> dict[str, Any]:
        """How :func:`log_blocks` filters the columns that step at a reversal as the
        torques were: the cut-off, the decimation and the trimmed margins."""
        return {
            "cutoff_hz": self.cutoff_hz,
            "upsample": self.decimate,
            "edges": (self.head, self.tail),
            "stamps": self.stamps,
            "fine": None if self.fine is None else (self.fine, self.fine_start),
        }

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
                n_dropped=self.cleaning.n_dropped,
                stamp_jitter_s=self.cleaning.stamp_jitter_s,
                cutoff_source="given" if self.motion_frequency_hz is None else "motion",
                motion_frequency_hz=self.motion_frequency_hz,
                resampled=self.resampled,
                speed_max=tuple(float(x) for x in np.max(np.abs(self.log.dq), axis=0)),
                position_range=motion_ranges([self.log.q]),
                velocity_range=motion_ranges([self.log.dq]),
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
    torque_delay_s: float = 0.0,
) -> PreparedLog:
    """Read a torque log through the drive, check it, filter and decimate it.

    The checks of :func:`~dynid.identification.sanity.check_torque_log` (sign, units,
    frozen joints) are warned first (unless ``check`` is False: a piece of a recording
    checked whole); then :func:`~dynid.identification.prepare.prepare_log`
    and every ``decimate``-th sample (default :func:`~dynid.identification.rate.decimation`;
    the cut-off ``"auto"``: :func:`~dynid.identification.rate.cutoff_from_motion`).
    Parameters as in
    :func:`~dynid.identification.classical.identify_from_log`; ``torque_delay_s`` [s] as
    :attr:`~dynid.identification.prepare.Preprocessing.torque_delay_s`.

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
    for finding in check_torque_log(robot, jlog, drive) if check else ():  # said first
        warnings.warn(finding, DynidWarning, stacklevel=caller_level())
    still = still_friction(jlog, drive)
    f_q = None
    if cutoff_hz == "auto":
        f_q = motion_frequency(jlog.q, fs, moving_joints(jlog.dq))
        cutoff_hz = cutoff_from_motion(jlog.q, jlog.dq, fs)
    k = decimation(fs, cutoff_hz) if decimate is None else int(decimate)
    if k < 1:
        raise ShapeError(f"decimate must be >= 1; got {decimate}")
    prep = Preprocessing(
        cutoff_hz=cutoff_hz,
        trim_s=trim_s,
        max_gap_s=max_gap_s,
        decimate=k,
        torque_delay_s=torque_delay_s,
    )
    raw = stamps = None
    head = tail = fine = None
    start = 0
    held = cutoff_hz is not None and k > 1  # the states the torques were filtered at
    if held and grid_samples(jlog, prep) * (1 + 4 * n) * 8 <= MAX_FINE_BYTES:
        prepared, fine, start = prepared_and_fine(jlog, prep)  # filtered once for both
    else:
        prepared = prepare_log(jlog, prep)
    if cutoff_hz is not None:  # the torques as measured at the same samples
        raw = measured_torques(jlog, prep)
        if fine is None:
            head, tail = trimmed_margins(jlog, prep)
        stamps = jlog.t if resamples(jlog, prep) else None
    noise = signal_noise_std(jlog.tau, jlog.t) if jlog.n_samples >= 3 else None
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
        head=head,
        tail=tail,
        stamps=stamps,
        fine=fine,
        fine_start=start,
    )
