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
* Gaps (dropped samples: a step longer than ``gap_factor`` times the median step) are
  reported in ``cleaning.gaps``. :func:`prepare_log` resamples the log onto a uniform
  grid, bridging gaps up to ``max_gap_s`` by linear interpolation (default
  :func:`default_max_gap`: 2.5 median steps, at least 0.02 s, so any rate from 10 Hz
  up works), and rejects longer ones (a DataError with the gap's times; hint: split the
  log or raise ``max_gap_s``).

:func:`prepare_log` turns a raw log into the input of identification and validation:
resample (when not uniform), zero-phase low-pass ``q``, ``dq`` (and a given ``ddq``) and,
unless ``filter_tau=False``, ``tau`` with the same filter; differentiate the filtered
``dq`` to get ``ddq`` (when not given); trim the filter edges (:mod:`dynid.signals`). A
zero-phase filter adds no delay, so the signals stay aligned in time.
"""

from __future__ import annotations

import warnings
from collections.abc import Iterator
from dataclasses import dataclass, field
from typing import Any

import numpy as np
from numpy.typing import ArrayLike, NDArray

from .. import _checks, signals
from ..exceptions import DataError, DynidWarning, ShapeError
from ..model.drive import Drive

__all__ = [
    "DEFAULT_CUTOFF_HZ",
    "LogCleaning",
    "TorqueLog",
    "default_max_gap",
    "joint_side_log",
    "PREPARE_BLOCK_SAMPLES",
    "SETTLE_CYCLES",
    "prepare_log",
    "prepared_blocks",
    "recorded_side_log",
    "velocity_note",
    "with_derived_velocities",
]

#: Default cutoff of the zero-phase low-pass for identification and validation [Hz].
#: Gaz et al. 2019 filtered at 1 Hz; that attenuates the paper's own validation sinusoid
#: of joint 7 (period 1.06 s, 0.94 Hz) by 40 % and the harmonics the nonlinear dynamics
#: add to the torques, so the default here is higher. Choose the cutoff well above the
#: highest frequency of the trajectory (several times its highest harmonic).
DEFAULT_CUTOFF_HZ = 5.0

_SIGNALS = ("q", "dq", "tau", "ddq")

#: Shortest gap :func:`prepare_log` refuses to bridge by default [s] (Panda: 20 samples).
MIN_MAX_GAP_S = 0.02


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
        median step.
    dt_median : float
        Median time step [s].
    dt_jitter : float
        Standard deviation of the steps (gaps excluded) over the median step.
    invalid_after : tuple of float
        Time [s] of the kept row before each run of rows dropped for NaN or inf (where a
        reader that must not bridge them cuts the log).
    """

    n_input_rows: int = 0
    n_nan_rows: int = 0
    n_duplicates: int = 0
    gaps: tuple[tuple[float, float], ...] = ()
    dt_median: float = float("nan")
    dt_jitter: float = 0.0
    invalid_after: tuple[float, ...] = ()


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
        cut-off (:func:`~dynid.identification.classical.prepare_torque_log`), never at a
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
        """Nominal sample rate [Hz] (inverse median step)."""
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
            A step longer than ``gap_factor`` times the median step is a gap.

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
        gap = dt > gap_factor * h
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


def with_derived_velocities(log: TorqueLog, cutoff_hz: float = DEFAULT_CUTOFF_HZ) -> TorqueLog:
    """The log with ``dq`` from the zero-phase filtered derivative of ``q``
    (:func:`dynid.signals.filtered_derivative`, low-pass at ``cutoff_hz`` [Hz]); for logs that
    record positions only (whatever ``log.dq`` holds is replaced). ``ddq`` is kept."""
    dq = signals.filtered_derivative(log.t, log.q, cutoff_hz)
    return TorqueLog(log.t, log.q, dq, log.tau, log.ddq, log.cleaning, dq_derived=True)


def velocity_note(cutoff_hz: float) -> str:
    """The note said when :func:`with_derived_velocities` derives a log's velocities."""
    return (
        "no velocity columns: velocities derived from the positions (zero-phase low-pass, "
        "then central differences) at the cut-off of the step that prepares the log "
        f"(identification, validation, friction; {cutoff_hz:g} Hz when read alone)"
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


def prepare_log(
    log: TorqueLog,
    *,
    cutoff_hz: float | None = DEFAULT_CUTOFF_HZ,
    trim_s: float | None = None,
    fs: float | None = None,
    max_gap_s: float | None = None,
    jitter_rtol: float = 1e-6,
    filter_tau: bool = True,
    decimate: int = 1,
) -> TorqueLog:
    """Resample, zero-phase filter, differentiate, trim and decimate a torque log.

    Steps (:mod:`dynid.signals`):

    1. If the steps of ``t`` differ from their median by more than ``jitter_rtol``
       (jitter, gaps) or ``fs`` differs from the log's rate, resample every signal
       linearly onto ``t[0] + k / fs``.
    2. If ``cutoff_hz`` is given, low-pass ``q``, ``dq``, ``tau`` (and ``ddq`` if the log
       has it) with the zero-phase Butterworth (order 4 applied twice); ``tau`` only if
       ``filter_tau``.
    3. If the log has no ``ddq``: ``ddq`` = derivative of the (filtered) ``dq``
       (second-order differences). A log whose ``dq`` was derived from ``q``
       (``log.dq_derived``) gets it derived again at ``cutoff_hz`` first, so that
       velocities, accelerations, positions and torques share one cut-off.
    4. Drop ``trim_s`` seconds at each end (default ``2 / cutoff_hz`` when filtering,
       else 0).
    5. Keep every ``decimate``-th sample of what is left.

    Steps 2-5 run one column at a time, so that a long log needs, beside its own arrays,
    the decimated result and a few full-length columns (not full-length copies of every
    filtered signal); the values are those of the steps applied to whole arrays.

    Parameters
    ----------
    log : TorqueLog
    cutoff_hz : float or None
        Low-pass cutoff [Hz]; None skips filtering (noise-free or pre-filtered data).
    trim_s : float, optional
        Seconds dropped at each end.
    fs : float, optional
        Rate of the uniform grid [Hz]; default the log's median rate.
    max_gap_s : float, optional
        Longest gap bridged by interpolation [s]; default :func:`default_max_gap` of the
        median step.
    jitter_rtol : float
        Relative step tolerance under which the log counts as uniform.
    filter_tau : bool
        Low-pass the torques too (identification: less noise per decimated sample).
        False keeps the measured torques (resampled and trimmed only), as the friction
        fit and the validation do: a filtered torque smears the fast friction reversals
        that the friction model, evaluated on the velocities, keeps sharp.
    decimate : int
        Keep every ``decimate``-th sample after trimming (the classical route's
        decimation, :func:`~dynid.identification.classical.auto_decimation`).

    Returns
    -------
    TorqueLog
        Uniformly sampled, with ``ddq``; ``cleaning`` is carried over.

    Raises
    ------
    DataError
        A gap longer than ``max_gap_s``; a cutoff not below the Nyquist frequency; too few
        samples to filter, or nothing left after trimming.
    ShapeError
        ``decimate < 1``.

    Warns
    -----
    DynidWarning
        The default cutoff :data:`DEFAULT_CUTOFF_HZ` is not below the log's Nyquist
        frequency (a log slower than 10 Hz): a quarter of the rate is used instead.
    """
    plan = _plan(log, cutoff_hz, trim_s, fs, max_gap_s, jitter_rtol, decimate)
    n_out = len(plan.out)
    if n_out < 2:
        raise DataError(
            f"fewer than 2 samples left after trimming {plan.trim_s:g} s at each end and keeping "
            f"every {decimate}-th"
        )
    parts = _windows(plan, PREPARE_BLOCK_SAMPLES)
    if len(parts) == 1:  # short: the whole log at once
        out = _prepared_window(log, plan, *parts[0], filter_tau)
    else:  # long: block by block into the result (one block's temporaries at a time)
        out = {}
        o = 0
        for w in parts:
            piece = _prepared_window(log, plan, *w, filter_tau)
            m = piece["t"].shape[0]
            for k, v in piece.items():
                if k not in out:
                    out[k] = np.empty((n_out,) + v.shape[1:])
                out[k][o : o + m] = v
            o += m
        for v in out.values():
            v.setflags(write=False)  # kept by TorqueLog without a copy
    return TorqueLog(
        t=out["t"],
        q=out["q"],
        dq=out["dq"],
        tau=out["tau"],
        ddq=out["ddq"],
        cleaning=log.cleaning,
    )


def prepared_blocks(
    log: TorqueLog,
    *,
    cutoff_hz: float | None = DEFAULT_CUTOFF_HZ,
    trim_s: float | None = None,
    fs: float | None = None,
    max_gap_s: float | None = None,
    jitter_rtol: float = 1e-6,
    filter_tau: bool = True,
    decimate: int = 1,
    block_samples: int | None = None,
) -> Iterator[TorqueLog]:
    """:func:`prepare_log` in consecutive blocks of at most ``block_samples`` prepared
    samples (default :data:`PREPARE_BLOCK_SAMPLES`): their concatenation is
    :func:`prepare_log`'s log (to about 1e-14 of each signal's scale), and only one block's
    samples and temporaries are held at a time (a long log validated without its prepared
    copy).

    Each block is resampled, filtered and differentiated over a window that reaches
    :data:`SETTLE_CYCLES` periods of the cut-off beyond its ends (twice that for velocities
    derived from positions, which are filtered twice), where the zero-phase filter's
    response to the window's edges has decayed to rounding, then cut to the block.

    Parameters and errors as :func:`prepare_log`; ``block_samples`` must be >= 1.
    """
    if block_samples is not None and block_samples < 1:
        raise ShapeError(f"block_samples must be >= 1; got {block_samples}")
    plan = _plan(log, cutoff_hz, trim_s, fs, max_gap_s, jitter_rtol, decimate)
    if len(plan.out) < 2:
        raise DataError(
            f"fewer than 2 samples left after trimming {plan.trim_s:g} s at each end and keeping "
            f"every {decimate}-th"
        )
    size = PREPARE_BLOCK_SAMPLES if block_samples is None else int(block_samples)
    for w in _windows(plan, size):
        out = _prepared_window(log, plan, *w, filter_tau)
        yield TorqueLog(
            t=out["t"],
            q=out["q"],
            dq=out["dq"],
            tau=out["tau"],
            ddq=out["ddq"],
            cleaning=log.cleaning,
        )


#: Prepared samples per block of :func:`prepare_log` and :func:`prepared_blocks`.
PREPARE_BLOCK_SAMPLES = 1 << 16

#: Periods of the cut-off by which a block's window reaches beyond the block: the slowest
#: pole of the order-4 Butterworth decays as ``exp(-0.38 * 2 pi f_c t)``, so that the
#: zero-phase filter of the window equals the whole log's there to rounding (as the
#: parallel filtering of the regressor's blocks, :mod:`dynid.identification.log_rows`).
SETTLE_CYCLES = 20.0


@dataclass(frozen=True, slots=True)
class _Plan:
    """What :func:`prepare_log` does to a log: the uniform grid, the cut-off, the samples
    kept (``out``, indices into the grid) and the margin of a block's window."""

    t: NDArray[np.float64]  # the uniform grid (the log's own times when uniform)
    uniform: bool
    rate: float
    cutoff_hz: float | None
    trim_s: float
    out: range
    pad: int
    derived: bool  # dq derived again from q at the cut-off


def _plan(
    log: TorqueLog,
    cutoff_hz: float | None,
    trim_s: float | None,
    fs: float | None,
    max_gap_s: float | None,
    jitter_rtol: float,
    decimate: int,
) -> _Plan:
    """Steps 1 and 4-5 of :func:`prepare_log` decided: the checks, the grid, the rows."""
    t = log.t
    dt = np.diff(t)
    _check_gaps(t, dt, max_gap_s)
    if int(decimate) != decimate or decimate < 1:
        raise ShapeError(f"decimate must be an integer >= 1; got {decimate}")
    rate = signals.sample_rate(t) if fs is None else float(fs)
    uniform = signals.is_uniform(t, rtol=jitter_rtol) and abs(rate * np.median(dt) - 1.0) < 1e-9
    del dt
    if not uniform:  # the grid of signals.resample_uniform
        m = int(np.floor((t[-1] - t[0]) * rate * (1.0 + 1e-12))) + 1
        t = t[0] + np.arange(m) / rate
    cutoff_hz = _usable_cutoff(cutoff_hz, rate, log.n_samples)
    if trim_s is None:
        trim_s = signals.edge_seconds(cutoff_hz) if cutoff_hz is not None else 0.0
    if trim_s < 0:
        raise DataError(f"seconds must be >= 0; got {trim_s}")
    # the samples of signals.trim_edges (t increases): its first and last, no mask of them
    first = int(np.searchsorted(t, t[0] + trim_s, side="left"))
    last = int(np.searchsorted(t, t[-1] - trim_s, side="right")) - 1
    if last - first + 1 < 2:
        raise DataError(f"fewer than 2 samples left after trimming {trim_s:g} s at each end")
    out = range(first, last + 1, int(decimate))
    derived = log.dq_derived and cutoff_hz is not None
    pad = 2  # the central differences' neighbours
    if cutoff_hz is not None:
        pad += int(np.ceil(SETTLE_CYCLES * rate / cutoff_hz)) * (2 if derived else 1)
    return _Plan(t, bool(uniform), rate, cutoff_hz, float(trim_s), out, pad, derived)


def _windows(plan: _Plan, size: int) -> list[tuple[int, int, slice]]:
    """``(lo, hi, rows)`` per block of at most ``size`` kept samples: the window
    ``lo:hi`` of the grid to prepare and the block's rows in it; one window of the whole
    grid when the blocks would not save its length."""
    out, M = plan.out, plan.t.shape[0]
    if len(out) <= size or M <= 4 * plan.pad + size * out.step:
        return [(0, M, slice(out.start, out.stop, out.step))]
    found = []
    for i in range(0, len(out), size):
        a, b = out[i], out[min(i + size, len(out)) - 1] + 1
        lo, hi = max(0, a - plan.pad), min(M, b + plan.pad)
        found.append((lo, hi, slice(a - lo, b - lo, out.step)))
    return found


def _prepared_window(
    log: TorqueLog, plan: _Plan, lo: int, hi: int, rows: slice, filter_tau: bool
) -> dict[str, NDArray[np.float64]]:
    """Steps 1-5 of :func:`prepare_log` on the window ``lo:hi`` of the grid, the rows
    ``rows`` of it kept."""
    tw = plan.t[lo:hi]
    data = {}
    for name in _SIGNALS:
        x = getattr(log, name)
        if x is None:
            continue
        if plan.uniform:
            data[name] = x[lo:hi]
        else:  # linear interpolation from the samples around the window only
            a = max(int(np.searchsorted(log.t, tw[0], side="right")) - 1, 0)
            b = min(int(np.searchsorted(log.t, tw[-1], side="left")) + 1, log.n_samples)
            ts = log.t[a:b]
            data[name] = np.stack([np.interp(tw, ts, x[a:b, j]) for j in range(x.shape[1])], 1)
    if plan.derived:  # positions only: dq at this cut-off
        assert plan.cutoff_hz is not None
        data["dq"] = signals.filtered_derivative(tw, data["q"], plan.cutoff_hz)
    return _conditioned(tw, data, rows, plan.rate, plan.cutoff_hz, filter_tau)


def _check_gaps(t: NDArray[np.float64], dt: NDArray[np.float64], max_gap_s: float | None) -> None:
    """Refuse a gap longer than ``max_gap_s`` (default :func:`default_max_gap`) [s]."""
    if max_gap_s is None:
        max_gap_s = default_max_gap(float(np.median(dt)))
    big = np.flatnonzero(dt > max_gap_s * (1.0 + 1e-9))
    if big.size:
        k = int(big[0])
        raise DataError(
            f"gap of {dt[k]:.4g} s in the log between t = {t[k]:.6g} s and t = {t[k + 1]:.6g} s "
            f"exceeds the longest gap bridged, {max_gap_s:g} s; hint: split the log at the gap "
            "or raise max_gap_s (--max-gap)"
        )


def _usable_cutoff(cutoff_hz: float | None, rate: float, n_samples: int) -> float | None:
    """The cut-off [Hz] to filter at: the default one moved below the Nyquist frequency of a
    slow log (with a warning pointing at the caller of :func:`prepare_log`, through
    :func:`_plan`); refused for a log too
    short to filter."""
    if cutoff_hz is not None and cutoff_hz == DEFAULT_CUTOFF_HZ and cutoff_hz >= rate / 2:
        warnings.warn(
            f"the default cutoff {DEFAULT_CUTOFF_HZ:g} Hz is not below the Nyquist frequency "
            f"of this {rate:.4g} Hz log; filtering at {rate / 4:.4g} Hz instead (choose with "
            "cutoff_hz / --cutoff)",
            DynidWarning,
            stacklevel=4,
        )
        cutoff_hz = rate / 4
    if cutoff_hz is not None and n_samples <= 15:
        raise DataError(
            f"the log has {n_samples} samples; the zero-phase filter needs more than 15: "
            "record a longer log"
        )
    return cutoff_hz


def _conditioned(
    t: NDArray[np.float64],
    data: dict[str, NDArray[np.float64]],
    rows: slice,
    rate: float,
    cutoff_hz: float | None,
    filter_tau: bool,
) -> dict[str, NDArray[np.float64]]:
    """Steps 2-5 of :func:`prepare_log`, one column at a time: the signals (and ``ddq``
    from the filtered ``dq`` when absent) low-passed, at the samples ``rows``, read-only.

    A signal that needs no filtering and no decimation is returned as a view of its input.
    """

    def frozen(a: NDArray[np.float64]) -> NDArray[np.float64]:
        a.setflags(write=False)  # so that TorqueLog keeps it without a copy
        return a

    out = {"t": frozen(np.array(t[rows]))}
    derive = "ddq" not in data
    for name, x in data.items():
        filtered = cutoff_hz is not None and (filter_tau or name != "tau")
        if not filtered and not (derive and name == "dq"):
            out[name] = frozen(x[rows]) if rows.step == 1 else frozen(np.array(x[rows]))
            continue
        y = np.empty((len(range(*rows.indices(x.shape[0]))), x.shape[1]))
        dy = np.empty(y.shape) if derive and name == "dq" else None
        for j in range(x.shape[1]):
            col = np.ascontiguousarray(x[:, j])
            if filtered:
                assert cutoff_hz is not None
                col = signals.lowpass(col, rate, cutoff_hz)
            y[:, j] = col[rows]
            if dy is not None:
                dy[:, j] = signals.derivative(t, col)[rows]
        out[name] = frozen(y)
        if dy is not None:
            out["ddq"] = frozen(dy)
    return out
