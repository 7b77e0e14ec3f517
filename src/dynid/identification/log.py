"""Torque logs: time-stamped joint positions, velocities and torques, and their preparation.

A :class:`TorqueLog` holds ``t`` (N,) [s], ``q`` (N, n) [rad], ``dq`` (N, n) [rad/s],
``tau`` (N, n) [N m] (measured link-side joint torques, friction included) and optionally
``ddq`` (N, n) [rad/s^2]. Its arrays are read-only.

Validation and cleaning (what is handled and what is rejected):

* ``TorqueLog(...)`` is strict: shapes must agree, every value must be finite and
  ``t`` strictly increasing; otherwise :class:`~dynid.exceptions.DataError` (or
  ``ShapeError``/``NonFiniteError``) names the array and the first bad row.
* :meth:`TorqueLog.from_raw` cleans a recorded log first: rows holding NaN or inf
  anywhere are dropped and counted; rows whose timestamp repeats the previous one are
  removed (the first is kept) and counted; a timestamp *smaller* than its predecessor
  (time running backwards) is rejected with a DataError naming the row, since no safe
  repair exists. The counts, the gaps and the timing jitter are kept in
  :class:`LogCleaning`.
* Gaps (dropped samples: a step longer than ``gap_factor`` times the median step that
  spans two periods or more of the stamps' grid, :func:`~dynid.signals.grid_steps`) are
  reported in ``cleaning.gaps``, the samples they drop in ``cleaning.n_dropped``, and the
  stamps' jitter about their grid in ``cleaning.stamp_jitter_s`` (at 100 Hz with 2 ms of
  jitter, 3.8 % of the steps are longer than 1.5 periods with no sample dropped: jitter,
  not gaps). :func:`~dynid.identification.prepare.prepare_log`
  resamples the log onto a uniform grid, bridging gaps up to ``max_gap_s`` by linear
  interpolation (default :func:`default_max_gap`: 2.5 median steps, at least 0.02 s, so
  any rate from 10 Hz up works), and rejects longer ones (a DataError with the gap's
  times; hint: split the log or raise ``max_gap_s``).

:func:`~dynid.identification.prepare.prepare_log` turns a raw log into the input of
identification and validation: resample (when not uniform), zero-phase low-pass ``q``,
``dq`` (and a given ``ddq``) and, unless ``filter_tau=False``, ``tau`` with the same
filter; differentiate the filtered ``dq`` to get ``ddq`` (when not given); trim the
filter edges (:mod:`dynid.signals`). A zero-phase filter adds no delay, so the signals
stay aligned in time.
"""

from __future__ import annotations

import hashlib
from dataclasses import dataclass, field
from typing import Any

import numpy as np
from numpy.typing import ArrayLike, NDArray

from .. import _checks, signals
from .._times import said_times
from ..exceptions import DataError, ShapeError
from ..model.drive import Drive

__all__ = [
    "MILLISECONDS_HINT",
    "DEFAULT_CUTOFF_HZ",
    "OBSERVER_CUTOFF_HZ",
    "LogCleaning",
    "TorqueLog",
    "default_max_gap",
    "jitter_text",
    "log_digest",
    "timing_notes",
    "joint_side_log",
    "recorded_side_log",
    "velocity_note",
    "with_derived_velocities",
]


def log_digest(log: TorqueLog) -> str:
    """The SHA-256 (hex) of a log's samples as read: its times [s], positions [rad],
    velocities [rad/s] and torques [N m], float64 in order; the same recording read the
    same way gives the same digest whatever its file is called."""
    h = hashlib.sha256()
    for a in (log.t, log.q, log.dq, log.tau):
        h.update(np.ascontiguousarray(a, dtype=np.float64).tobytes())
    return h.hexdigest()


#: Default cutoff of the zero-phase low-pass for identification and validation [Hz].
#: Gaz et al. 2019 filtered at 1 Hz; that attenuates the paper's own validation sinusoid
#: of joint 7 (period 1.06 s, 0.94 Hz) by 40 % and the harmonics the nonlinear dynamics
#: add to the torques, so the default here is higher. Choose the cutoff well above the
#: highest frequency of the trajectory (several times its highest harmonic).
DEFAULT_CUTOFF_HZ = 5.0

#: Cut-off [Hz] at which ``dynid observe`` derives the velocities of a log without them,
#: above the observer's own bandwidth (:data:`dynid.observer.friction.DERIVED_CUTOFF_HZ`
#: says why), named here for :func:`velocity_note`.
OBSERVER_CUTOFF_HZ = 20.0

_SIGNALS = ("q", "dq", "tau", "ddq")

#: Shortest gap :func:`~dynid.identification.prepare.prepare_log` refuses to bridge by default
#: [s] (Panda: 20 samples).
MIN_MAX_GAP_S = 0.02


#: Gaps whose start times [s] :func:`timing_notes` lists, the first ones.
GAPS_SAID = 5
#: Stamps are said to be jittered when their jitter about their grid exceeds this fraction
#: of a period (a uniform log written with 15 digits stays below it).
JITTER_SAID = 1e-3


def jitter_text(jitter_s: float, period_s: float) -> str | None:
    """``stamps jittered, std 2.0 ms at a 10 ms period``, or None when the jitter is below
    :data:`JITTER_SAID` periods (or unknown)."""
    if not (np.isfinite(jitter_s) and np.isfinite(period_s)) or jitter_s <= JITTER_SAID * period_s:
        return None
    return f"stamps jittered, std {jitter_s * 1e3:.2g} ms at a {period_s * 1e3:.3g} ms period"


def timing_notes(c: LogCleaning, t0: float | None = None) -> list[str]:
    """What a reader says of a log's timestamps: their jitter (its size, and the samples
    dropped or none) and the gaps that drop samples (count, the first :data:`GAPS_SAID`
    start times [s] with their offsets from the log's first stamp ``t0`` [s] when given,
    samples, longest [ms])."""
    notes = []
    jitter = jitter_text(c.stamp_jitter_s, c.period_s)
    if jitter is not None:  # steps long by jitter alone are no gaps
        dropped = "no sample dropped" if not c.n_dropped else f"{c.n_dropped} sample(s) dropped"
        notes.append(
            f"{jitter} ({dropped}); identify, friction and validate resample them onto a "
            "uniform grid"
        )
    if c.gaps:
        at = said_times([a for a, _ in c.gaps], t0, shown=GAPS_SAID)
        notes.append(
            f"{len(c.gaps)} gap(s) in time of dropped samples at {at} "
            f"({c.n_dropped} dropped; longest {max(b - a for a, b in c.gaps) * 1e3:.3g} ms)"
        )
    return notes


def default_max_gap(dt_median: float) -> float:
    """Longest gap bridged by default [s]: 2.5 median steps (one or two lost samples), at
    least :data:`MIN_MAX_GAP_S`."""
    return max(MIN_MAX_GAP_S, 2.5 * float(dt_median))


@dataclass(frozen=True, slots=True)
class LogCleaning:
    """What :meth:`TorqueLog.from_raw` found and did.

    Attributes
    ----------
    n_input_rows : int
        Rows before cleaning.
    n_nan_rows : int
        Rows dropped because they held NaN or inf.
    n_duplicates : int
        Rows dropped because their timestamp repeated the previous one.
    gaps : tuple of (float, float)
        ``(t_before, t_after)`` [s] of each step longer than ``gap_factor`` times the
        median step that holds dropped samples (spans two periods or more of the stamps'
        grid, :func:`~dynid.signals.grid_steps`; a step long by jitter alone is none).
    dt_median : float
        Median time step [s].
    dt_jitter : float
        Standard deviation of the steps (gaps excluded) over the median step.
    invalid_after : tuple of float
        Time [s] of the kept row before each run of rows dropped for NaN or inf (where a
        reader that must not bridge them cuts the log).
    n_dropped : int
        Samples missing from the stamps' grid (the periods the steps span beyond one).
    period_s : float
        Period of the stamps' grid [s] (``1 / sample_rate(t)``).
    stamp_jitter_s : float
        Standard deviation of the stamps about their grid [s] (0 for uniform stamps).
    """

    n_input_rows: int = 0
    n_nan_rows: int = 0
    n_duplicates: int = 0
    gaps: tuple[tuple[float, float], ...] = ()
    dt_median: float = float("nan")
    dt_jitter: float = 0.0
    invalid_after: tuple[float, ...] = ()
    n_dropped: int = 0
    period_s: float = float("nan")
    stamp_jitter_s: float = 0.0


@dataclass(frozen=True, slots=True, eq=False)
class TorqueLog:
    """Time-stamped joint measurements; arrays read-only.

    Attributes
    ----------
    t : ndarray, shape (N,)
        Strictly increasing sample times [s].
    q : ndarray, shape (N, n)
        Joint positions [rad].
    dq : ndarray, shape (N, n)
        Joint velocities [rad/s].
    tau : ndarray, shape (N, n)
        Measured link-side joint torques [N m] (friction included).
    ddq : ndarray, shape (N, n), or None
        Joint accelerations [rad/s^2] when measured or already computed.
    cleaning : LogCleaning
        What cleaning found (all zeros for a log built directly).
    dq_derived : bool
        True when ``dq`` was derived from ``q`` (a log that records positions only,
        :func:`with_derived_velocities`): identification derives it again at its own
        cut-off (:func:`~dynid.identification.prepared_log.prepare_torque_log`), never at a
        reader's default.

    Raises
    ------
    ShapeError
        Inconsistent shapes, or fewer than 2 samples.
    NonFiniteError
        NaN or inf in an array (name and first bad index in the message).
    DataError
        ``t`` not strictly increasing (the message gives the row).
    """

    t: NDArray[np.float64]
    q: NDArray[np.float64]
    dq: NDArray[np.float64]
    tau: NDArray[np.float64]
    ddq: NDArray[np.float64] | None = None
    cleaning: LogCleaning = field(default_factory=LogCleaning)
    dq_derived: bool = False

    def __post_init__(self) -> None:
        t = _checks.as_array("t", self.t)
        if t.ndim != 1 or t.shape[0] < 2:
            raise ShapeError(f"t must have shape (N,) with N >= 2; got {t.shape}")
        dt = np.diff(t)
        bad = np.flatnonzero(dt <= 0)
        if bad.size:
            k = int(bad[0])
            what = "repeats" if dt[k] == 0 else "is before"
            raise DataError(
                f"timestamps must be strictly increasing; row {k + 1} "
                f"(t = {float(t[k + 1])!r}) {what} row {k} (t = {float(t[k])!r}); "
                "hint: TorqueLog.from_raw drops duplicates"
            )
        q = _checks.as_array("q", self.q)
        if q.ndim != 2 or q.shape[0] != t.shape[0]:
            raise ShapeError(f"q must have shape ({t.shape[0]}, n) like t; got {q.shape}")
        object.__setattr__(self, "t", _checks.frozen(t))
        object.__setattr__(self, "q", _checks.frozen(q))
        for attr in ("dq", "tau", "ddq"):
            v = getattr(self, attr)
            if v is not None:
                object.__setattr__(self, attr, _checks.frozen(_checks.as_exact(attr, v, q.shape)))

    @property
    def n(self) -> int:
        """Number of joints."""
        return self.q.shape[1]

    @property
    def n_samples(self) -> int:
        """Number of samples N."""
        return self.t.shape[0]

    @property
    def duration(self) -> float:
        """``t[-1] - t[0]`` [s]."""
        return float(self.t[-1] - self.t[0])

    @property
    def sample_rate(self) -> float:
        """Nominal sample rate [Hz] (:func:`dynid.signals.sample_rate`)."""
        return signals.sample_rate(self.t)

    def __len__(self) -> int:
        return self.n_samples

    def select(self, rows: ArrayLike | slice) -> TorqueLog:
        """A log of the given rows (bool mask, increasing indices, or a slice: views of
        this log's arrays, no copy), ``cleaning`` kept."""
        r = rows if isinstance(rows, slice) else np.asarray(rows)
        pick = lambda x: None if x is None else x[r]  # noqa: E731
        return TorqueLog(
            self.t[r],
            self.q[r],
            self.dq[r],
            self.tau[r],
            pick(self.ddq),
            self.cleaning,
            self.dq_derived,
        )

    @classmethod
    def from_raw(
        cls,
        t: ArrayLike,
        q: ArrayLike,
        dq: ArrayLike,
        tau: ArrayLike,
        ddq: ArrayLike | None = None,
        *,
        gap_factor: float = 1.5,
    ) -> TorqueLog:
        """Clean a recorded log: drop NaN rows and duplicate timestamps, find gaps.

        Parameters
        ----------
        t : array_like, shape (N,)
            Timestamps [s]; equal consecutive values are duplicates.
        q, dq, tau : array_like, shape (N, n)
        ddq : array_like, shape (N, n), optional
        gap_factor : float
            A step longer than ``gap_factor`` times the median step is a gap when it spans
            two periods or more of the stamps' grid (:func:`~dynid.signals.grid_steps`).

        Returns
        -------
        TorqueLog
            With ``cleaning`` filled in.

        Raises
        ------
        ShapeError
            Inconsistent shapes.
        DataError
            A timestamp smaller than the previous one (the row is named), or fewer than
            2 rows left.
        """
        t = _checks.as_array("t", t, allow_nonfinite=True)
        if t.ndim != 1:
            raise ShapeError(f"t must have shape (N,); got {t.shape}")
        N = t.shape[0]
        arrays = {}
        for k, v in (("q", q), ("dq", dq), ("tau", tau), ("ddq", ddq)):
            if v is None:
                continue
            a = _checks.as_array(k, v, allow_nonfinite=True)
            if a.ndim != 2 or a.shape[0] != N:
                raise ShapeError(f"{k} must have shape ({N}, n) like t; got {a.shape}")
            arrays[k] = a
        n = arrays["q"].shape[1]
        for k, a in arrays.items():
            if a.shape[1] != n:
                raise ShapeError(f"{k} must have shape ({N}, {n}) like q; got {a.shape}")
        finite = np.isfinite(t)
        for a in arrays.values():
            for j in range(a.shape[1]):  # a column at a time: no (N, n) temporary
                finite &= np.isfinite(a[:, j])
        # a log without invalid rows or duplicates (the usual one) takes no index arrays
        rows: NDArray[np.intp] | None = None if finite.all() else np.flatnonzero(finite)
        del finite
        n_nan = 0 if rows is None else N - rows.size
        skipped = (  # a kept row, then invalid ones
            np.zeros(0, np.intp) if rows is None else rows[np.flatnonzero(np.diff(rows) > 1)]
        )
        if rows is not None and rows.size == 0:  # every row invalid
            raise DataError(f"fewer than 2 valid rows left of {N} ({n_nan} with NaN/inf)")
        tt = t if rows is None else t[rows]
        dt = np.diff(tt)
        back = np.flatnonzero(dt < 0)
        if back.size:
            i = int(back[0])
            raise DataError(
                f"timestamps run backwards at row {i + 1 if rows is None else int(rows[i + 1])}: "
                f"t = {float(tt[i + 1])!r} after t = {float(tt[i])!r}; the log is out of order "
                "and cannot be repaired safely"
            )
        n_dup = int(np.count_nonzero(dt == 0))
        if n_dup:
            keep = np.concatenate([[True], dt > 0])
            rows = np.flatnonzero(keep) if rows is None else rows[keep]
            tt = t[rows]
            dt = np.diff(tt)
        if tt.shape[0] < 2:
            raise DataError(f"fewer than 2 valid rows left of {N} ({n_nan} with NaN/inf)")
        h = float(np.median(dt))
        steps, period, stamp_jitter = signals.grid_steps(tt)
        gap = (dt > gap_factor * h) & (steps >= 2)
        gaps = tuple((float(tt[i]), float(tt[i + 1])) for i in np.flatnonzero(gap))
        jitter = float(np.std(dt[~gap]) / h) if np.any(~gap) else 0.0
        cleaning = LogCleaning(
            n_input_rows=N,
            n_nan_rows=int(n_nan),
            n_duplicates=n_dup,
            gaps=gaps,
            dt_median=h,
            dt_jitter=jitter,
            invalid_after=tuple(float(t[i]) for i in skipped),
            n_dropped=int(np.sum(steps - 1)),
            period_s=period,
            stamp_jitter_s=stamp_jitter,
        )
        if rows is None:  # nothing dropped: no copy of a large log
            tt, pick = t, (lambda a: a)
        else:
            pick = lambda a: a[rows]  # noqa: E731
        return cls(
            t=tt,
            q=pick(arrays["q"]),
            dq=pick(arrays["dq"]),
            tau=pick(arrays["tau"]),
            ddq=pick(arrays["ddq"]) if "ddq" in arrays else None,
            cleaning=cleaning,
        )


#: The hint of a positions-only log whose time steps look like milliseconds
#: (:func:`with_derived_velocities`): a reader that can check the other units reads it
#: again in ms and says every unit found at once
#: (:func:`dynid.workflows.data_files.read_torque_log`).
MILLISECONDS_HINT = "hint: --units t=ms"


def with_derived_velocities(log: TorqueLog, cutoff_hz: float = DEFAULT_CUTOFF_HZ) -> TorqueLog:
    """The log with ``dq`` from the zero-phase filtered derivative of ``q``
    (:func:`dynid.signals.filtered_derivative`, low-pass at ``cutoff_hz`` [Hz], or at a
    quarter of the rate where ``cutoff_hz`` is not below half of it:
    :func:`dynid.signals.below_nyquist`; the 5 Hz default refused a 10 Hz servo log); for
    logs that record positions only (whatever ``log.dq`` holds is replaced). ``ddq`` is
    kept.

    Raises
    ------
    DataError
        A log sampled at less than twice ``cutoff_hz`` whose time steps look like another
        unit (0.5 to 100 units: milliseconds, the hint ``--units t=ms``; microseconds,
        nanoseconds): its rate and the hint.
    """
    fc = cutoff_hz
    if log.t.shape[0] > 1:
        dt = float(np.median(np.diff(log.t)))
        hint = _time_unit_hint(dt)
        if dt > 0 and cutoff_hz >= 0.5 / dt and hint:
            raise DataError(
                f"positions only, sampled at {1 / dt:.3g} Hz: velocities cannot be derived at "
                f"{cutoff_hz:g} Hz (above half the rate){hint}"
            )
        if dt > 0:
            fc = signals.below_nyquist(cutoff_hz, signals.sample_rate(log.t))
    dq = signals.filtered_derivative(log.t, log.q, fc)
    return TorqueLog(log.t, log.q, dq, log.tau, log.ddq, log.cleaning, dq_derived=True)


def _time_unit_hint(dt: float) -> str:
    """What a median time step ``dt`` read as seconds looks like, with the ``--units`` that
    reads it so: milliseconds for 0.5 to 100 (:data:`MILLISECONDS_HINT`), microseconds to
    1e5 and nanoseconds to 1e8 (arms logged at 10 Hz to a few kHz); "" otherwise."""
    for unit, hi, hint in (
        ("milliseconds", 100.0, MILLISECONDS_HINT),
        ("microseconds", 1e5, "hint: --units t=us"),
        ("nanoseconds", 1e8, "hint: --units t=ns"),
    ):
        if 0.5 <= dt <= hi:
            return f"; its time steps of {dt:g} look like {unit}; {hint}"
    return ""


def velocity_note(cutoff_hz: float) -> str:
    """The note said when :func:`with_derived_velocities` derives a log's velocities at
    ``cutoff_hz`` [Hz] (the reader's): each step derives them again at its own cut-off, the
    observer at :data:`OBSERVER_CUTOFF_HZ`; a cut-off not below half the log's rate at a
    quarter of the rate (:func:`dynid.signals.below_nyquist`)."""
    return (
        "no velocity columns: velocities derived from the positions (zero-phase low-pass, "
        "then central differences) at the cut-off of the step that prepares the log "
        "(identification, validation and friction at theirs, "
        f"{cutoff_hz:g} Hz when the log is read alone; the observer at "
        f"{OBSERVER_CUTOFF_HZ:g} Hz; a cut-off at or above half the log's sample rate, "
        "where no filter holds, lowered to a quarter of the rate)"
    )


def joint_side_log(log: TorqueLog, drive: Drive | None) -> TorqueLog:
    """The log in joint coordinates and joint torques [N m], through a drive.

    A motor-side log becomes ``q = K^-1 q_m + q_0``, ``dq = K^-1 dq_m`` (and ``ddq``),
    ``tau = K^T tau_m``; currents are multiplied by the torque constants first
    (:class:`~dynid.model.drive.Drive`). The log itself when there is nothing to convert.

    Raises
    ------
    ShapeError
        The drive is for another number of joints.
    """
    if drive is None or drive.is_identity:
        return log
    return _mapped(log, drive, drive.joint_states, drive.joint_torques)


def recorded_side_log(log: TorqueLog, drive: Drive) -> TorqueLog:
    """Inverse of :func:`joint_side_log`: a joint-side log as the drive records it (motor
    positions and torques, or currents; encoder offsets removed)."""
    return _mapped(log, drive, drive.recorded_states, drive.recorded_efforts)


def _mapped(log: TorqueLog, drive: Drive, states: Any, efforts: Any) -> TorqueLog:
    """The log with its positions and rates mapped by ``states`` and its torques by
    ``efforts`` (one direction of the drive)."""
    drive.check(log.n)
    rates = (log.dq,) if log.ddq is None else (log.dq, log.ddq)
    q, *mapped = states(log.q, *rates)
    return TorqueLog(
        t=log.t,
        q=q,
        dq=mapped[0],
        tau=efforts(log.tau),
        ddq=mapped[1] if log.ddq is not None else None,
        cleaning=log.cleaning,
        dq_derived=log.dq_derived,
    )


#: How a message says what a torque log argument must be.
LOG_EXPECTED = (
    "a TorqueLog (dynid.io.torque_log.load_torque_log(path), or TorqueLog(t, q, dq, tau))"
)
#: How a message says what an argument of one or more torque logs must be.
LOGS_EXPECTED = "a TorqueLog or a sequence of TorqueLog"


def checked_log(log: object, name: str = "log") -> TorqueLog:
    """``log`` when it is a :class:`TorqueLog`: the check of a public function's log
    argument at its entry.

    Raises
    ------
    WrongTypeError
        It is not (``"log: expected a TorqueLog (...), got dict"``).
    """
    out: TorqueLog = _checks.of_type(name, log, TorqueLog, LOG_EXPECTED)
    return out


def checked_logs(logs: object, name: str = "logs") -> list[TorqueLog]:
    """``logs`` (one :class:`TorqueLog`, or a list or tuple of them) as a list.

    Raises
    ------
    WrongTypeError
        Neither, or an item is not a TorqueLog (named by its index).
    """
    return _checks.one_or_many(name, logs, TorqueLog, LOGS_EXPECTED)
