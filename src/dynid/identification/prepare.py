"""Preparing a torque log for identification and validation: resample onto a uniform grid,
zero-phase low-pass, differentiate, trim the filter's edges and decimate
(:func:`prepare_log`), whole or in blocks of bounded memory (:func:`prepared_blocks`), or
only its torques as measured (:func:`measured_torques`); the three read one record of
the settings, :class:`Preprocessing` (an identified model's:
:attr:`~dynid.identification.info.LogInfo.preprocessing`).

The signals are those of a :class:`~dynid.identification.log.TorqueLog`: ``t`` [s], ``q``
[rad or m], ``dq`` [rad/s or m/s], ``tau`` [N m or N], ``ddq`` [rad/s^2 or m/s^2], rows the
samples.
"""

from __future__ import annotations

import warnings
from collections.abc import Iterable, Iterator
from dataclasses import dataclass, replace

import numpy as np
from numpy.typing import NDArray

from .. import signals
from .._checks import caller_level
from .._times import said_time
from ..exceptions import DataError, DynidWarning, ShapeError
from .log import _SIGNALS, DEFAULT_CUTOFF_HZ, TorqueLog, default_max_gap
from .velocity_noise import at_round_off

__all__ = [
    "MEASURED",
    "PREPARE_BLOCK_SAMPLES",
    "SETTLE_CYCLES",
    "Preprocessing",
    "at_instants",
    "at_measured_samples",
    "dropped_places",
    "fine_states",
    "grid_samples",
    "prepared_and_fine",
    "measured_instants",
    "measured_torques",
    "nearest_samples",
    "prepare_log",
    "prepared_blocks",
    "resamples",
    "states_in_step",
    "trimmed_margins",
]


@dataclass(frozen=True, slots=True)
class Preprocessing:
    """How a torque log is prepared (:func:`prepare_log`): the settings of the steps, with
    their defaults, in one record.

    Attributes
    ----------
    cutoff_hz : float or None
        Zero-phase low-pass cut-off [Hz]; None skips filtering (noise-free or pre-filtered
        data). Default :data:`~dynid.identification.log.DEFAULT_CUTOFF_HZ`.
    trim_s : float, optional
        Seconds dropped at each end [s]; default ``2 / cutoff_hz`` when filtering, else 0
        (:func:`~dynid.signals.edge_seconds`).
    fs : float, optional
        Rate of the uniform grid [Hz]; default the log's median rate.
    max_gap_s : float, optional
        Longest gap bridged by interpolation [s]; default
        :func:`~dynid.identification.log.default_max_gap` of the median step.
    jitter_rtol : float
        Relative step tolerance under which the log counts as uniform.
    filter_tau : bool
        Low-pass the torques too (identification: less noise per decimated sample).
        False keeps the measured torques (resampled and trimmed only), as the friction
        fit and the validation do: a filtered torque smears the fast friction reversals
        that the friction model, evaluated on the velocities, keeps sharp.
    decimate : int
        Keep every ``decimate``-th sample after trimming (the classical route's
        decimation, :func:`~dynid.identification.rate.decimation`).
    torque_delay_s : float
        How far the torques lag the positions [s] (sensor filtering, bus latency; positive:
        the torques late): before filtering, the positions, velocities (and accelerations)
        are read at ``t - torque_delay_s`` (:func:`states_in_step`), so that each torque
        is paired with the states it belongs to, and the samples at whose ends that
        instant falls outside the piece are trimmed (the trim is at least
        ``|torque_delay_s|``). The torques themselves are not interpolated: their noise, which
        the validation's floor reads, stays as measured. Default 0: as recorded.

    Raises
    ------
    ShapeError
        ``decimate`` not an integer >= 1.
    DataError
        ``trim_s < 0``; ``torque_delay_s`` not finite.
    """

    cutoff_hz: float | None = DEFAULT_CUTOFF_HZ
    trim_s: float | None = None
    fs: float | None = None
    max_gap_s: float | None = None
    jitter_rtol: float = 1e-6
    filter_tau: bool = True
    decimate: int = 1
    torque_delay_s: float = 0.0

    def __post_init__(self) -> None:
        if int(self.decimate) != self.decimate or self.decimate < 1:
            raise ShapeError(f"decimate must be an integer >= 1; got {self.decimate}")
        if self.trim_s is not None and self.trim_s < 0:
            raise DataError(f"seconds must be >= 0; got {self.trim_s}")
        if not np.isfinite(self.torque_delay_s):
            raise DataError(f"torque delay must be finite; got {self.torque_delay_s}")


#: The default preparation (:class:`Preprocessing` with its defaults).
_DEFAULT = Preprocessing()

#: The preparation of validation and of the friction fit by default: the default cut-off,
#: the torques kept as measured (``filter_tau=False``).
MEASURED = Preprocessing(filter_tau=False)


def prepare_log(log: TorqueLog, prep: Preprocessing = _DEFAULT) -> TorqueLog:
    """Resample, zero-phase filter, differentiate, trim and decimate a torque log.

    Steps (:mod:`dynid.signals`):

    1. If the steps of ``t`` differ from their median by more than ``prep.jitter_rtol``
       (jitter, gaps) or ``prep.fs`` differs from the log's rate, resample every signal
       linearly onto ``t[0] + k / fs``.
    2. If ``prep.cutoff_hz`` is given, low-pass ``q``, ``dq``, ``tau`` (and ``ddq`` if the
       log has it) with the zero-phase Butterworth (order 4 applied twice); ``tau`` only if
       ``prep.filter_tau``.
    3. If the log has no ``ddq``: ``ddq`` = derivative of the (filtered) ``dq``
       (second-order differences; of order 8 for velocities not filtered and exact to
       round-off, :func:`~dynid.signals.exact_derivative`). A log whose ``dq`` was derived
       from ``q`` (``log.dq_derived``) gets it derived again at ``cutoff_hz`` first, so that
       velocities, accelerations, positions and torques share one cut-off.
    4. Drop ``prep.trim_s`` seconds at each end (default ``2 / cutoff_hz`` when
       filtering, else 0).
    5. Keep every ``prep.decimate``-th sample of what is left.

    Steps 2-5 run one column at a time, so that a long log needs, beside its own arrays,
    the decimated result and a few full-length columns (not full-length copies of every
    filtered signal); the values are those of the steps applied to whole arrays.

    Parameters
    ----------
    log : TorqueLog
    prep : Preprocessing
        The settings of the steps (default: :class:`Preprocessing` ``()``).

    Returns
    -------
    TorqueLog
        Uniformly sampled, with ``ddq``; ``cleaning`` is carried over.

    Raises
    ------
    DataError
        A gap longer than ``prep.max_gap_s``; a cutoff not below the Nyquist frequency; too
        few samples to filter, or nothing left after trimming.

    Warns
    -----
    DynidWarning
        The default cutoff :data:`DEFAULT_CUTOFF_HZ` is not below the log's Nyquist
        frequency (a log slower than 10 Hz): a quarter of the rate is used instead.
    """
    log = states_in_step(log, prep.torque_delay_s)
    plan = _plan(log, prep)
    n_out = len(plan.out)
    parts = _windows(plan, PREPARE_BLOCK_SAMPLES)
    if len(parts) == 1:  # short: the whole log at once
        out = _prepared_window(log, plan, *parts[0], prep.filter_tau)
    else:  # long: block by block into the result (one block's temporaries at a time)
        out = {}
        o = 0
        for w in parts:
            piece = _prepared_window(log, plan, *w, prep.filter_tau)
            m = piece["t"].shape[0]
            for k, v in piece.items():
                if k not in out:
                    out[k] = np.empty((n_out,) + v.shape[1:])
                out[k][o : o + m] = v
            o += m
        for v in out.values():
            v.setflags(write=False)  # kept by TorqueLog without a copy
    return _as_log(out, log)


def prepared_blocks(
    log: TorqueLog, prep: Preprocessing = _DEFAULT, *, block_samples: int | None = None
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
    log = states_in_step(log, prep.torque_delay_s)
    plan = _plan(log, prep)
    size = PREPARE_BLOCK_SAMPLES if block_samples is None else int(block_samples)
    for w in _windows(plan, size):
        out = _prepared_window(log, plan, *w, prep.filter_tau)
        yield _as_log(out, log)


def measured_torques(log: TorqueLog, prep: Preprocessing = _DEFAULT) -> NDArray[np.float64]:
    """The torques [N m] (M, n) at the samples of :func:`prepare_log` ``(log, prep)`` as
    measured, not low-passed: of a log that is not uniform, those of the measured sample
    nearest each (:func:`measured_instants`; :func:`at_instants` moves the prepared states
    there), not interpolated between two (``prep.filter_tau`` is not read)."""
    plan = _plan(log, prep)
    idx = np.asarray(plan.out)
    if plan.uniform:
        return np.array(log.tau[idx])
    return np.array(log.tau[nearest_samples(plan.t[idx], log.t)])


def states_in_step(log: TorqueLog, torque_delay_s: float) -> TorqueLog:
    """``log`` with its positions, velocities (and accelerations) read ``torque_delay_s``
    [s] earlier, ``q(t - torque_delay_s)``, by a cubic spline through its own samples (an
    extrapolation over the first or last ``|torque_delay_s|``, which :func:`prepare_log`
    trims): torques that lag the positions by ``torque_delay_s`` paired with the states they
    belong to, the torques as measured (:attr:`Preprocessing.torque_delay_s`). ``log``
    itself for a delay of 0. A log whose velocities are derived from its positions gets
    them derived again from the moved positions."""
    if torque_delay_s == 0.0:
        return log
    from scipy.interpolate import CubicSpline  # here: a robot model loads no scipy

    t = log.t - float(torque_delay_s)
    moved = {
        name: CubicSpline(log.t, x, axis=0)(t)
        for name in ("q", "dq", "ddq")
        if (x := getattr(log, name)) is not None
    }
    return replace(log, **moved)


def nearest_samples(t: NDArray[np.float64], stamps: NDArray[np.float64]) -> NDArray[np.intp]:
    """The index (M,) of the instant of ``stamps`` (N,) [s], increasing, nearest each time
    of ``t`` (M,) [s] (the earlier one on a tie)."""
    i = np.clip(np.searchsorted(stamps, t), 1, max(stamps.shape[0] - 1, 1))
    return np.where(t - stamps[i - 1] <= stamps[i] - t, i - 1, i).astype(np.intp)


def measured_instants(t: NDArray[np.float64], stamps: NDArray[np.float64]) -> NDArray[np.float64]:
    """The measured instants [s] (M,) the prepared times ``t`` (M,) are judged at: the
    instant of ``stamps`` nearest each (:func:`nearest_samples`; next to a dropped sample
    two prepared times may share one)."""
    return stamps[nearest_samples(t, stamps)]


def at_instants(p: TorqueLog, t: NDArray[np.float64]) -> TorqueLog:
    """The prepared log ``p`` (uniform, with ``ddq``) with its positions, velocities and
    accelerations moved to the instants ``t`` (one per sample, each within about a step of
    the sample's own: :func:`_moved`); its times and torques as they are (the torques:
    those measured at ``t``; the times keep the samples' order where two share an
    instant)."""
    q, dq, ddq = _moved(p, np.arange(p.n_samples), t)
    return TorqueLog(t=p.t, q=q, dq=dq, tau=p.tau, ddq=ddq, cleaning=p.cleaning)


def _moved(
    p: TorqueLog, rows: NDArray[np.intp], t: NDArray[np.float64]
) -> tuple[NDArray[np.float64], NDArray[np.float64], NDArray[np.float64]]:
    """Positions, velocities and accelerations (M, n) of the prepared log ``p`` (uniform,
    with ``ddq``) at the instants ``t`` (M,) [s], each moved from the sample ``rows`` (M,)
    near it by their Taylor series to the third derivative (read by central differences
    of ``ddq``). The error is of order ``(2 pi f dt)^2`` of ``ddq`` for a motion of
    frequency ``f`` moved by ``dt``: 1e-4 at 1 Hz and 2 ms, where a linear step reads 1 %."""
    assert p.ddq is not None  # prepare_log always fills ddq
    d = (np.asarray(t, dtype=np.float64) - p.t[rows])[:, None]
    dddq = np.gradient(p.ddq, p.t, axis=0, edge_order=2) if p.n_samples > 2 else 0 * p.ddq
    q, dq, ddq, j = p.q[rows], p.dq[rows], p.ddq[rows], dddq[rows]
    return (
        q + d * (dq + d / 2 * (ddq + d / 3 * j)),
        dq + d * (ddq + d / 2 * j),
        ddq + d * j,
    )


def grid_samples(log: TorqueLog, prep: Preprocessing = _DEFAULT) -> int:
    """Samples :func:`prepare_log` keeps within the trimmed edges before decimation, on the
    grid it reads ``log`` on: its own samples, or the uniform grid it resamples them onto
    (which holds the places of dropped samples too)."""
    out = _plan(log, prep).out
    return out.stop - out.start


def dropped_places(log: TorqueLog, prep: Preprocessing = _DEFAULT) -> int:
    """The samples dropped between ``log``'s stamps within the trimmed edges: the nominal
    periods its span holds, less its steps (a 1 kHz log of 1,000 stamps over 1.002 s: 2).
    Counted over the span, not step by step: a step of 1.6 periods is jitter of +-0.3 of a
    period at 100 Hz as well as a dropped sample (counting such steps told 68 dropped
    where 20 were). What the uniform grid :func:`prepare_log` resamples onto holds beyond
    the samples (:func:`grid_samples`) apart from these is the grid's ends against
    jittered stamps, not samples dropped (0 for a uniform log)."""
    plan = _plan(log, prep)
    if plan.uniform:
        return 0
    t = log.t
    a = int(np.searchsorted(t, t[0] + plan.trim_s, side="left"))
    b = int(np.searchsorted(t, t[-1] - plan.trim_s, side="right"))
    if b - a < 2:
        return 0
    return max(0, int(np.rint((t[b - 1] - t[a]) * plan.rate)) - (b - a - 1))


def resamples(log: TorqueLog, prep: Preprocessing = _DEFAULT) -> bool:
    """Whether :func:`prepare_log` resamples ``log`` onto a grid of other instants than
    its own (jittered or dropped samples, or another rate ``prep.fs``)."""
    return not _plan(log, prep).uniform


def at_measured_samples(blocks: Iterable[TorqueLog], log: TorqueLog) -> Iterator[TorqueLog]:
    """Consecutive prepared ``blocks`` of ``log`` (its uniform grid, as
    :func:`prepared_blocks` yields them, torques not filtered) read at the samples of
    ``log`` itself: at each measured instant nearer a block's grid than the next block's
    (the first block: from its first grid time; the last: up to its last), the positions,
    velocities and accelerations moved from the nearest grid sample (:func:`_moved`), the
    torques as measured. A log of jittered or dropped samples is then judged on its own samples: the
    linear grid smears a torque step (Coulomb friction at a reversal) between two stamps
    and averages a sample's noise with its neighbour's (an xArm7 at 100 Hz, stamps +-2 ms:
    the true model's error 1.79 % on the grid, 0.80 % on uniform stamps). A block with
    fewer than 2 measured samples (a log's last few) is left out."""
    it = iter(blocks)
    p = next(it, None)
    a = int(np.searchsorted(log.t, p.t[0], side="left")) if p is not None else 0
    while p is not None:
        nxt = next(it, None)
        if nxt is not None:  # up to the midpoint: each instant moved from its nearest sample
            b = int(np.searchsorted(log.t, 0.5 * (p.t[-1] + nxt.t[0]), side="left"))
        else:
            b = int(np.searchsorted(log.t, p.t[-1], side="right"))
        if b - a >= 2:
            t = log.t[a:b]
            q, dq, ddq = _moved(p, nearest_samples(t, p.t), t)
            yield TorqueLog(t=t, q=q, dq=dq, tau=log.tau[a:b], ddq=ddq, cleaning=log.cleaning)
        p, a = nxt, b


def trimmed_margins(
    log: TorqueLog, prep: Preprocessing = _DEFAULT
) -> tuple[TorqueLog | None, TorqueLog | None]:
    """The samples :func:`prepare_log` trims, prepared as it prepares the kept ones: the
    signals at every ``prep.decimate``-th sample of the grid before its first kept sample
    and after its last, in phase with them (the head's last sample one decimated step
    before the first kept one). A column filtered as the torques were (the parallel
    filtering of :mod:`~dynid.identification.log_rows`) needs them: the torques near
    the kept ends were filtered with what came before and after. None for a margin of
    fewer than 2 such samples."""
    log = states_in_step(log, prep.torque_delay_s)
    plan = _plan(log, prep)
    out, M = plan.out, plan.t.shape[0]
    k = out.step
    head_rows = range(out.start % k, out.start, k)
    tail_rows = range(out[-1] + k, M, k)

    def margin(rows: range) -> TorqueLog | None:
        if len(rows) < 2:
            return None
        lo, hi = max(0, rows.start - plan.pad), min(M, rows[-1] + 1 + plan.pad)
        piece = _prepared_window(
            log, plan, lo, hi, slice(rows.start - lo, rows[-1] + 1 - lo, k), prep.filter_tau
        )
        return _as_log(piece, log)

    return margin(head_rows), margin(tail_rows)


def fine_states(log: TorqueLog, prep: Preprocessing = _DEFAULT) -> tuple[TorqueLog, int]:
    """The log prepared as :func:`prepare_log` prepares it but at every sample of its
    grid, none trimmed or left out (but ``|prep.torque_delay_s|`` at each end, whose states
    were read beyond the log), and the index in it of the first kept sample: the kept
    samples are ``fine[start :: prep.decimate]``. The columns that step at a
    reversal are computed from these states, at the rate the torques were filtered at
    (:mod:`~dynid.identification.log_rows`), rather than from states interpolated
    between the decimated samples, whose reversals land off the torques' steps (exact
    data of a geared arm, gear ratio 200, decimated 1 in 9: held-out error 1.8e-5, 2e-7
    at every sample)."""
    fine_prep = replace(prep, trim_s=0.0, decimate=1)
    # a torque delay trims the fine log too: its first sample is not the grid's
    start = _plan(log, prep).out.start - _plan(log, fine_prep).out.start
    return prepare_log(log, fine_prep), start


def prepared_and_fine(
    log: TorqueLog, prep: Preprocessing = _DEFAULT
) -> tuple[TorqueLog, TorqueLog, int]:
    """:func:`prepare_log` and :func:`fine_states` of one log, the same arrays as the two
    calls give: when the whole grid is filtered at once (a log of at most
    :data:`PREPARE_BLOCK_SAMPLES` samples on its grid, no ``prep.torque_delay_s``), the
    grid is filtered and differentiated once and the prepared log is the fine one's kept
    samples (``fine[start :: prep.decimate]``, a copy); else the two calls. Filtering the
    log once rather than twice halves the preparation of a recording's piece."""
    plan = _plan(log, prep)
    fine_prep = replace(prep, trim_s=0.0, decimate=1)
    whole = len(_windows(_plan(log, fine_prep), PREPARE_BLOCK_SAMPLES)) == 1
    if prep.torque_delay_s != 0.0 or not whole:
        fine, start = fine_states(log, prep)
        return prepare_log(log, prep), fine, start
    fine = prepare_log(log, fine_prep)
    out = plan.out
    kept = {
        k: np.array(v[out.start : out.stop : out.step])
        for k in ("t", "q", "dq", "tau", "ddq")
        if (v := getattr(fine, k)) is not None
    }
    for v in kept.values():
        v.setflags(write=False)  # kept by TorqueLog without a copy
    return _as_log(kept, log), fine, out.start


def _as_log(out: dict[str, NDArray[np.float64]], log: TorqueLog) -> TorqueLog:
    """The prepared signals ``out`` as a log, with ``log``'s cleaning record."""
    return TorqueLog(
        t=out["t"], q=out["q"], dq=out["dq"], tau=out["tau"], ddq=out["ddq"], cleaning=log.cleaning
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


def _plan(log: TorqueLog, prep: Preprocessing) -> _Plan:
    """Steps 1 and 4-5 of :func:`prepare_log` decided: the checks, the grid, the rows."""
    t = log.t
    dt = np.diff(t)
    _check_gaps(t, dt, prep.max_gap_s)
    fs, decimate = prep.fs, prep.decimate
    rate = signals.sample_rate(t) if fs is None else float(fs)
    h = float(np.median(dt))
    off = max(1e-9, signals.stamp_resolution(t) / h)  # a step's error from the stamps' floats
    uniform = signals.is_uniform(t, rtol=prep.jitter_rtol) and abs(rate * h - 1.0) < off
    del dt
    if not uniform:  # the grid of signals.resample_uniform
        m = int(np.floor((t[-1] - t[0]) * rate * (1.0 + 1e-12))) + 1
        t = t[0] + np.arange(m) / rate
    cutoff_hz = _usable_cutoff(prep.cutoff_hz, rate, log.n_samples)
    trim_s = prep.trim_s
    if trim_s is None:
        trim_s = signals.edge_seconds(cutoff_hz) if cutoff_hz is not None else 0.0
    trim_s = max(trim_s, abs(prep.torque_delay_s))  # torques read beyond the piece dropped
    # the samples of signals.trim_edges (t increases): its first and last, no mask of them
    first = int(np.searchsorted(t, t[0] + trim_s, side="left"))
    last = int(np.searchsorted(t, t[-1] - trim_s, side="right")) - 1
    if last - first + 1 < 2:
        raise DataError(f"fewer than 2 samples left after trimming {trim_s:g} s at each end")
    out = range(first, last + 1, int(decimate))
    if len(out) < 2:
        raise DataError(
            f"fewer than 2 samples left after trimming {trim_s:g} s at each end and keeping "
            f"every {decimate}-th"
        )
    derived = log.dq_derived and cutoff_hz is not None
    # the central differences' neighbours (an exact log's unfiltered: signals.exact_derivative's)
    pad = 2 if cutoff_hz is not None else signals.EXACT_DERIVATIVE_ORDER // 2
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
            f"gap of {dt[k]:.4g} s in the log between {said_time(t[k], t[0])} and "
            f"{said_time(t[k + 1], t[0])} "
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
            stacklevel=caller_level(),
        )
        cutoff_hz = rate / 4
    if cutoff_hz is not None and n_samples <= 15:
        raise DataError(
            f"the log has {n_samples} samples; the zero-phase filter needs more than 15: "
            "record a longer log"
        )
    return cutoff_hz


def _derivative(
    t: NDArray[np.float64], x: NDArray[np.float64], *, exact: bool
) -> NDArray[np.float64]:
    """The derivative of the column ``x`` (N,) at the uniform times ``t`` (N,) [s]:
    :func:`~dynid.signals.exact_derivative` where ``exact`` (not filtered) and ``x`` is
    exact to round-off (:func:`~dynid.identification.velocity_noise.at_round_off`: a
    noise-free simulation's velocities, whose second-order differences err by
    ``(2 pi f dt)^2 / 6``), else :func:`~dynid.signals.derivative`."""
    n_exact = signals.EXACT_DERIVATIVE_ORDER + 1
    if exact and x.shape[0] >= n_exact and at_round_off(x[:, None], t)[0]:
        return signals.exact_derivative(t, x)
    return signals.derivative(t, x)


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
                dy[:, j] = _derivative(t, col, exact=not filtered)[rows]
        out[name] = frozen(y)
        if dy is not None:
            out["ddq"] = frozen(dy)
    return out
