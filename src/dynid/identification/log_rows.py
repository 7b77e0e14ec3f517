"""The regressor rows of a prepared torque log: sample-major blocks over the model's columns.

Row ``k n + j`` is sample ``k``, joint ``j`` (its noise group ``j``); the columns that step
at a velocity reversal go through the torques' low-pass ("parallel filtering", Gautier and
Khalil), and the known rotor torques of a drive are subtracted from the targets.
"""

from __future__ import annotations

from collections.abc import Callable, Hashable, Iterator
from contextlib import contextmanager
from contextvars import ContextVar
from functools import lru_cache, partial
from typing import Any, Protocol

import numpy as np
from numpy.typing import NDArray

from .. import _checks, signals
from .._memo import scoped, value_digest, value_key
from ..exceptions import DataError
from ..model.drive import Drive
from ..model.robot import Robot
from ..regressors.base import BaseParameters
from ..regressors.terms import LinearFriction, ModelTerm, base_term_columns
from ..regressors.torque import torque_regressor_prepared
from .dataset import ModelColumns, RegressorBlock
from .log import TorqueLog
from .streaming import BLOCK_ROWS, max_stack_bytes, streams
from .velocity_noise import moving_joints

#: Cycles of the cut-off frequency after which the zero-phase Butterworth low-pass has
#: forgotten a block's edge (its slowest pole decays as ``exp(-0.38 * 2 pi f_c t)``; 14
#: cycles left differences of 4e-8 in the smallest estimates of a 12 s log read in blocks
#: of 16,384 rows, 20 leave rounding): each block is computed this much beyond its ends,
#: filtered, trimmed.
_SETTLE_CYCLES = 20.0

__all__ = [
    "SteppingColumns",
    "friction_regressor",
    "log_blocks",
    "parallel_filtered",
    "shared_steps",
    "still_columns",
    "stepped_columns",
    "still_friction",
    "term_regressor",
]


class _Shared:
    """The columns already computed while :func:`shared_steps` is active: key -> (what the
    key's ids name, kept alive while the entry lives; the columns, read only), and the
    bytes held per pool (the stepping columns; the link columns and states): at most
    :func:`~dynid.identification.streaming.max_stack_bytes` each, the memory a stacked
    regressor may take (a log streamed in blocks keeps none)."""

    def __init__(self) -> None:
        self.held: dict[Hashable, tuple[Any, Any]] = {}
        self.nbytes = {"steps": 0, "states": 0}
        self.budget = max_stack_bytes()

    def hold(self, key: Hashable, refs: Any, value: Any, pool: str = "steps") -> None:
        """Hold ``value`` (an array or a tuple of arrays and None, made read only) under
        ``key`` when the budget of its ``pool`` allows."""
        arrays = [a for a in (value if isinstance(value, tuple) else (value,)) if a is not None]
        size = sum(a.nbytes for a in arrays)
        if self.nbytes[pool] + size <= self.budget:
            for a in arrays:
                a.flags.writeable = False
            self.held[key] = (refs, value)
            self.nbytes[pool] += size


def _held(key: Hashable, refs: Any, compute: Callable[[], Any]) -> Any:
    """``compute()`` (states, link columns), read back from :func:`shared_steps` when it
    holds ``key`` and held there otherwise (``refs``: the objects whose ids ``key``
    names, kept alive with it); computed each time outside the block."""
    shared = _SHARED.get()
    if shared is None:
        return compute()
    if key in shared.held:
        return shared.held[key][1]
    value = compute()
    shared.hold(key, refs, value, "states")
    return value


_SHARED: ContextVar[_Shared | None] = ContextVar("_SHARED", default=None)


@contextmanager
def shared_steps() -> Iterator[None]:
    """Within the block, a term's stepping columns filtered on a span of a log, the states
    interpolated there, and the link columns at states of equal values
    (:func:`term_regressor`) are computed once and read back by every later regressor
    holding them (the candidate structures' regressors share their links and most
    friction terms, and the held-out judgement's rows as measured the fit's states): the
    same numbers, not recomputed. Nested blocks share the outer one's; the columns are
    dropped at its end."""
    with scoped(_SHARED, _Shared):
        yield


class SteppingColumns(Protocol):
    """What :func:`stepped_filtered` needs of a term: its columns at joint states (a
    :class:`~dynid.regressors.terms.ModelTerm`, or another signal that steps at a
    reversal, such as a known friction's torques). Which columns step is read from
    ``steps`` (bool per label) when the object has it, else none do."""

    @property
    def labels(self) -> tuple[str, ...]:
        """One label per column."""
        ...

    def torque_columns(
        self, q: NDArray[np.float64], dq: NDArray[np.float64], ddq: NDArray[np.float64]
    ) -> NDArray[np.float64]:
        """Joint-torque columns (B, n, p) of (B, n) joint states."""
        ...


def friction_regressor(dq: NDArray[np.float64]) -> NDArray[np.float64]:
    """Regressor ``F`` (..., n, 3 n) of the classical friction at the joints, columns
    :func:`~dynid.regressors.terms.friction_labels`.

    ``F[..., j, 3 j : 3 j + 3] = (dq_j, sign(dq_j), 1)``; zero elsewhere.
    """
    return _joint_friction(dq.shape[-1]).torque_columns(dq, dq, dq)


@lru_cache(maxsize=16)
def _joint_friction(n: int) -> LinearFriction:
    """The classical friction of ``n`` joints without a transmission, built once per ``n``
    (frozen; checking its drive costs more than the columns of a short trajectory)."""
    return LinearFriction(Drive.identity(n))


def log_blocks(
    robot: Robot,
    log: TorqueLog,
    columns: ModelColumns,
    *,
    stream: bool | None = None,
    cutoff_hz: float | None = None,
    upsample: int = 1,
    edges: tuple[TorqueLog | None, TorqueLog | None] = (None, None),
    stamps: NDArray[np.float64] | None = None,
    fine: tuple[TorqueLog, int] | None = None,
) -> Iterator[RegressorBlock]:
    """The regressor rows of a prepared log over ``columns``: sample-major (row ``k n + j``
    is sample ``k``, joint ``j``, its noise group ``j``); known rotor torques of
    ``columns.drive`` subtracted. One block, or blocks of :data:`BLOCK_ROWS` rows when
    ``stream`` (default: when the regressor exceeds ``DYNID_MAX_STACK_BYTES``).

    ``cutoff_hz``: the low-pass the log's torques went through, at ``upsample`` times the
    log's rate (the rate before decimation). The columns that step at a reversal (Coulomb,
    smooth, Stribeck friction) then go through the same zero-phase low-pass at that rate
    (:func:`stepped_filtered`): a filtered torque rounds the step of Coulomb friction at a
    reversal, and ``sign(dq)`` left sharp would bias every friction coefficient, as would
    a step placed on the decimated samples or a filter that does not see the samples
    trimmed before and after the log (``edges``: prepared alike; a 1 kHz log decimated to
    100 Hz: rotor inertias off by 2-3 % on exact data). ``stamps``: the instants [s] the
    log was measured at when they were not uniform (its torques interpolated linearly onto
    the grid before the low-pass): the stepping columns are computed there and
    interpolated alike. ``fine``: the log prepared at every sample of its grid and the
    index there of its first sample (:func:`~dynid.identification.prepare.fine_states`):
    the stepping columns are computed from those states rather than from states
    interpolated between the decimated ones. The rows equal those of the log filtered
    whole, in blocks too."""
    assert log.ddq is not None  # prepare_log always fills ddq
    N, n = log.n_samples, log.n
    drive = columns.drive
    if stream is None:
        stream = streams(N * n, len(columns.labels))
    step = max(1, BLOCK_ROWS // n) if stream else N
    steps = columns.step_columns()
    filtered = cutoff_hz is not None and bool(steps.any())
    held: NDArray[np.float64] | None = None  # the stepping columns of the rows lo:hi
    lo = hi = 0
    for a in range(0, N, step):
        b = slice(a, a + step)
        q, dq, ddq, tau = log.q[b], log.dq[b], log.ddq[b], log.tau[b]
        Y, _ = term_regressor(robot, columns.base, columns.terms, q, dq, ddq)
        if filtered:  # a span of STEP_SPAN rows at once: its margins cost once, not per block
            assert cutoff_hz is not None
            if held is None or a + Y.shape[0] > hi:
                lo, hi = a, min(N, a + max(step, STEP_SPAN))
                held = stepped_filtered(
                    columns.appended, (edges[0], log, edges[1]), steps[columns.base.rank :],
                    cutoff_hz, upsample, slice(lo, hi), stamps, fine,
                )  # fmt: skip
            Y[..., steps] = held[a - lo : a - lo + Y.shape[0]]
        tau = less_known_rotors(tau, ddq, drive)
        m = Y.shape[0]
        W = Y.reshape(m * n, -1)
        _checks.finite("regressor", W)
        yield RegressorBlock(W=W, y=tau.reshape(-1), groups=np.tile(np.arange(n), m))


def less_known_rotors(
    tau: NDArray[np.float64], ddq: NDArray[np.float64], drive: Drive | None
) -> NDArray[np.float64]:
    """The torques ``tau`` [N m] (N, n) less the rotor torques of ``drive``'s known rotor
    inertias at the accelerations ``ddq`` [rad/s^2] (N, n): what the fit's rows target
    (:func:`log_blocks`); ``tau`` itself without a drive or known rotor inertias."""
    if drive is None or drive.rotor_inertia is None:
        return tau
    return tau - drive.rotor_torques(ddq, drive.rotor_inertia)


#: Prepared samples whose stepping columns are filtered at once (with their margins):
#: bounds the up-sampled columns held to a few tens of MB whatever the log's length.
STEP_SPAN = 4_096


def stepped_columns(
    term: SteppingColumns,
    log: TorqueLog,
    *,
    cutoff_hz: float | None = None,
    upsample: int = 1,
    edges: tuple[TorqueLog | None, TorqueLog | None] = (None, None),
    stamps: NDArray[np.float64] | None = None,
    fine: tuple[TorqueLog, int] | None = None,
) -> NDArray[np.float64]:
    """One term's columns (N, n, p) at every sample of a prepared log, those that step at
    a reversal low-passed as the log's torques were (:func:`stepped_filtered`), as
    :func:`log_blocks` computes them; the keywords are :func:`log_blocks`' (a
    :class:`~dynid.identification.prepared_log.PreparedLog`'s ``filtering``). Another
    fit on low-passed torques (a payload's friction) takes its rows from here."""
    assert log.ddq is not None  # prepared logs are differentiated
    Y = np.array(term.torque_columns(log.q, log.dq, log.ddq), dtype=np.float64)
    steps = np.asarray(getattr(term, "steps", np.zeros(len(term.labels), bool)), dtype=bool)
    if cutoff_hz is not None and steps.any():
        Y[..., steps] = stepped_filtered(
            (term,), (edges[0], log, edges[1]), steps, cutoff_hz, upsample,
            slice(0, log.n_samples), stamps, fine,
        )  # fmt: skip
    return Y


def stepped_filtered(
    terms: tuple[SteppingColumns, ...],
    logs: tuple[TorqueLog | None, TorqueLog, TorqueLog | None],
    steps: NDArray[np.bool_],
    cutoff_hz: float,
    upsample: int,
    rows: slice,
    stamps: NDArray[np.float64] | None = None,
    fine: tuple[TorqueLog, int] | None = None,
) -> NDArray[np.float64]:
    """The columns ``steps`` (c,) of the appended ``terms`` at the prepared samples
    ``rows`` of a log, computed as its torques were filtered. ``logs``: the samples trimmed
    before the log (or None), the log, those trimmed after it (or None), at one decimated
    step. The states are interpolated (cubic spline of the low-passed, hence band-limited,
    signals) onto ``upsample`` times that rate, the columns computed there and low-passed
    at ``cutoff_hz`` (:func:`parallel_filtered`), then every ``upsample``-th sample kept
    ("parallel filtering and decimation", Gautier and Khalil). A log measured at the
    instants ``stamps`` [s] (not uniform: its torques were interpolated linearly onto the
    grid) has its columns computed at those instants and interpolated so too, which puts
    a reversal's step where the torques have it. Each span of :data:`STEP_SPAN` samples is
    computed with :data:`_SETTLE_CYCLES` periods of the cut-off on either side, where the
    filter has forgotten the window's edges. ``fine``: the log prepared at every sample
    of its grid and the index there of ``log``'s first sample (``log`` is every
    ``upsample``-th sample from there): its states are read instead of interpolated, and
    ``logs``' margins are not needed. (m, n, steps.sum())."""
    from scipy.interpolate import CubicSpline  # here: a robot model loads no scipy

    head, log, tail = logs
    h = 0 if head is None else head.n_samples
    N, n = log.n_samples, log.n
    total = h + N + (0 if tail is None else tail.n_samples)
    a, b = rows.indices(N)[:2]
    k = max(1, int(upsample))
    rate = signals.sample_rate(log.t)
    pad = int(np.ceil(_SETTLE_CYCLES * rate / cutoff_hz))
    out = np.empty((b - a, n, int(steps.sum())))
    for s in range(a, b, STEP_SPAN):
        e = min(b, s + STEP_SPAN)
        if fine is None:  # the states interpolated between the decimated samples
            lo, hi = max(0, s + h - pad), min(total, e + h + pad)
            tw, x = _joined(logs, lo, hi)
            grid = tw[0] + np.arange((hi - lo - 1) * k + 1) * (1.0 / (k * rate))
            keep = slice((s + h - lo) * k, (e + h - lo - 1) * k + 1, k)
        else:  # the states at every sample of the grid, as the torques were filtered
            f, start = fine
            lo = max(0, start + s * k - pad * k)
            hi = min(f.n_samples, start + (e - 1) * k + 1 + pad * k)
            tw, x = _joined((f,), lo, hi)
            grid = tw
            keep = slice(start + s * k - lo, start + (e - 1) * k + 1 - lo, k)

        def compute(
            which: list[int],
            tw: NDArray[np.float64] = tw,
            x: NDArray[np.float64] = x,
            grid: NDArray[np.float64] = grid,
            keep: slice = keep,
            span: tuple[int, int] = (s, e),
        ) -> list[NDArray[np.float64]]:
            """The columns of ``terms[which]`` on this span, from the states there."""

            def interpolated() -> tuple[NDArray[np.float64], NDArray[np.float64] | None]:
                """The states where the columns are computed, and those instants [s] when
                the torques were measured there (None: on ``grid``)."""
                if stamps is not None and tw.shape[0] > 1:  # where the torques were measured
                    i0 = max(int(np.searchsorted(stamps, grid[0], side="right")) - 1, 0)
                    i1 = int(np.searchsorted(stamps, grid[-1], side="left")) + 1
                    at = stamps[i0:i1]
                    return CubicSpline(tw, x, axis=0)(at), at
                if grid is not tw and k > 1 and tw.shape[0] > 1:
                    return CubicSpline(tw, x, axis=0)(np.minimum(grid, tw[-1])), None
                return x, None

            where = _span_key(logs, span, cutoff_hz, k, stamps, fine)
            xs, at = _held(("states", where), (logs, stamps, fine), interpolated)
            onto = None if at is None else partial(_interpolated, at, grid)
            states = (xs[:, :n], xs[:, n : 2 * n], xs[:, 2 * n :])
            rate_k = k * rate
            return [
                _filtered_columns(terms[i], states, cutoff_hz, rate_k, keep, onto) for i in which
            ]

        got = _span_columns(terms, logs, (s, e), cutoff_hz, k, stamps, fine, compute)
        out[s - a : e - a] = np.concatenate(got, axis=-1)[..., steps]
    return out


def _span_columns(
    terms: tuple[SteppingColumns, ...],
    logs: tuple[TorqueLog | None, TorqueLog, TorqueLog | None],
    span: tuple[int, int],
    cutoff_hz: float,
    k: int,
    stamps: NDArray[np.float64] | None,
    fine: tuple[TorqueLog, int] | None,
    compute: Callable[[list[int]], list[NDArray[np.float64]]],
) -> list[NDArray[np.float64]]:
    """Each term's filtered columns on the prepared samples ``span`` of a log: those
    :func:`shared_steps` holds read back, the others from ``compute`` (the indices of the
    terms wanted -> their columns) and held."""
    shared = _SHARED.get()
    if shared is None:
        return compute(list(range(len(terms))))
    refs = (logs, stamps, fine)
    where = _span_key(logs, span, cutoff_hz, k, stamps, fine)
    keys: list[Hashable | None] = []
    for t in terms:
        try:
            keys.append((type(t).__qualname__, value_key(t), where))
        except TypeError:  # a term that does not hash: computed each time
            keys.append(None)
    got: list[NDArray[np.float64] | None] = [
        None if key is None or key not in shared.held else shared.held[key][1] for key in keys
    ]
    missing = [i for i, g in enumerate(got) if g is None]
    if missing:
        for i, cols in zip(missing, compute(missing), strict=True):
            got[i] = cols
            key = keys[i]
            if key is not None:
                shared.hold(key, refs, cols)
    return [g for g in got if g is not None]


def _span_key(
    logs: tuple[TorqueLog | None, TorqueLog, TorqueLog | None],
    span: tuple[int, int],
    cutoff_hz: float,
    k: int,
    stamps: NDArray[np.float64] | None,
    fine: tuple[TorqueLog, int] | None,
) -> Hashable:
    """What a span's filtered columns depend on beside their terms, by the ids of the
    logs and arrays (held alive with the entry) for :func:`shared_steps`."""
    return (
        tuple(id(g) for g in logs),
        span,
        float(cutoff_hz),
        k,
        id(stamps),
        None if fine is None else (id(fine[0]), fine[1]),
    )


def _filtered_columns(
    term: SteppingColumns,
    states: tuple[NDArray[np.float64], ...],
    cutoff_hz: float,
    rate: float,
    keep: slice,
    onto: Callable[[NDArray[np.float64]], NDArray[np.float64]] | None = None,
) -> NDArray[np.float64]:
    """A term's columns (m, n, p) at the samples ``keep`` of the fine grid at ``rate``
    [Hz], those that step low-passed there first (:func:`parallel_filtered`); zeros for a
    term without such columns. ``states`` are on that grid, or at other instants that
    ``onto`` interpolates a column from onto it. Friction's parts are filtered per motor
    before they are placed (a linear map), not its mostly zero columns."""
    if onto is None:
        onto = _same
    m = len(range(*keep.indices(onto(states[0][:, :1]).shape[0])))
    steps = np.asarray(getattr(term, "steps", np.zeros(len(term.labels), bool)), dtype=bool)
    if not steps.any():
        return np.zeros((m, states[0].shape[1], len(term.labels)))
    if isinstance(term, LinearFriction):
        P = onto(term.part_columns(term.drive.motor_velocities(states[1])))  # (M, n, k)
        stepping = np.array([p in ("coulomb", "smooth", "stribeck") for p in term.parts])
        flat = P[..., stepping].reshape(P.shape[0], -1)
        flat = parallel_filtered(flat[:, None, :], np.ones(flat.shape[1], bool), None,
                                 cutoff_hz, rate=rate)[:, 0, :]  # fmt: skip
        Pk = P[keep]
        Pk[..., stepping] = flat[keep].reshape(m, P.shape[1], -1)
        return term.placed(Pk)
    A = onto(term.torque_columns(*states))
    flat = A.reshape(A.shape[0], -1)  # the signals (joint, column), a view
    used = np.flatnonzero(np.tile(steps, A.shape[1]) & flat.any(axis=0))
    sig = parallel_filtered(flat[:, used][:, None, :], np.ones(used.size, bool), None,
                            cutoff_hz, rate=rate)[:, 0, :]  # fmt: skip
    got = np.array(flat[keep])
    got[:, used] = sig[keep]
    return got.reshape(m, A.shape[1], -1)


def _same(x: NDArray[np.float64]) -> NDArray[np.float64]:
    """``x`` as it is (columns already on the fine grid)."""
    return x


def _interpolated(
    at: NDArray[np.float64], grid: NDArray[np.float64], x: NDArray[np.float64]
) -> NDArray[np.float64]:
    """``x`` (M, ...) at the instants ``at`` (M,) [s] interpolated linearly onto ``grid``
    (G,): as :func:`dynid.signals.resample_uniform` puts a log's torques on its grid."""
    flat = x.reshape(x.shape[0], -1)
    out = np.empty((grid.shape[0], flat.shape[1]))
    for c in range(flat.shape[1]):
        out[:, c] = np.interp(grid, at, flat[:, c])
    return out.reshape((grid.shape[0],) + x.shape[1:])


def _joined(
    logs: tuple[TorqueLog | None, ...], lo: int, hi: int
) -> tuple[NDArray[np.float64], NDArray[np.float64]]:
    """Times (m,) and states ``[q, dq, ddq]`` (m, 3 n) of the samples ``lo:hi`` of the
    logs read one after another (None: no samples)."""
    t, x, start = [], [], 0
    for g in logs:
        if g is None:
            continue
        assert g.ddq is not None
        a, b = max(lo - start, 0), min(hi - start, g.n_samples)
        if a < b:
            t.append(g.t[a:b])
            x.append(np.concatenate([g.q[a:b], g.dq[a:b], g.ddq[a:b]], axis=1))
        start += g.n_samples
    return np.concatenate(t), np.concatenate(x)


def parallel_filtered(
    Y: NDArray[np.float64],
    cols: NDArray[np.bool_],
    t: NDArray[np.float64] | None,
    cutoff_hz: float,
    *,
    rate: float | None = None,
) -> NDArray[np.float64]:
    """``Y`` (N, n, c) with its columns ``cols`` (c,) low-passed along time at
    ``cutoff_hz`` (:func:`dynid.signals.lowpass`, the filter of the torques): the
    "parallel filtering" of Gautier and Khalil, the regressor and the torques through the
    same filter, for the columns that step at a reversal (the smooth ones are left as
    computed from the filtered states). The samples are at the times ``t`` (N,) [s] or at
    ``rate`` [Hz]. Left as it is where the rate is too low for the cut-off (below 2.2
    times it) or the samples too few to filter."""
    idx = np.flatnonzero(cols)
    if idx.size == 0 or Y.shape[0] < 2:
        return Y
    if rate is None:
        assert t is not None
        rate = signals.sample_rate(t)
    fs = float(rate)
    if not cutoff_hz < 0.45 * fs:
        return Y
    try:
        Y[..., idx] = signals.lowpass(Y[..., idx], fs, cutoff_hz, axis=0)
    except DataError:  # too few samples for the filter's padding
        pass
    return Y


def still_columns(columns: ModelColumns, still: NDArray[np.bool_]) -> NDArray[np.bool_]:
    """Columns (c,) that need the motion of a joint (motor) flagged in ``still`` (n,)."""
    need = columns.motion_columns()
    return (need >= 0) & np.asarray(still, dtype=bool)[np.maximum(need, 0)]


def still_friction(log: TorqueLog, drive: Drive | None) -> NDArray[np.bool_]:
    """Joints (motors, where the drive's friction acts there) whose velocity never leaves
    its noise band: their viscous and Coulomb friction is not fitted from noise."""
    if drive is None:
        return ~moving_joints(log.dq)
    return ~moving_joints(log.dq @ drive.friction_transmission.T)


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
    each term that is not ``in_base`` (friction). Returns it with its labels. Within
    :func:`shared_steps`, the link columns at states of equal values are computed once.
    """
    ind = np.asarray(base.independent)
    rigid = ind[ind < 10 * robot.n]
    appended = [t for t in terms if not t.in_base]
    width = ind.size + sum(len(t.labels) for t in appended)
    if _SHARED.get() is None:
        Y = torque_regressor_prepared(robot, q, dq, ddq, robot.gravity, columns=rigid, width=width)
    else:  # the states by value: the rows as measured share the fit's states
        Y = np.empty(q.shape + (width,))
        Y[..., : rigid.size] = _held(
            ("links", id(robot), rigid.tobytes(), value_digest((q, dq, ddq))),
            robot,
            lambda: torque_regressor_prepared(robot, q, dq, ddq, robot.gravity, columns=rigid),
        )
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
