"""The regressor rows of a prepared torque log: sample-major blocks over the model's columns.

Row ``k n + j`` is sample ``k``, joint ``j`` (its noise group ``j``); the columns that step
at a velocity reversal go through the torques' low-pass ("parallel filtering", Gautier and
Khalil), and the known rotor torques of a drive are subtracted from the targets.
"""

from __future__ import annotations

from collections.abc import Iterator

import numpy as np
from numpy.typing import NDArray

from .. import _checks, signals
from ..exceptions import DataError
from ..model.drive import Drive
from ..model.robot import Robot
from ..regressors.base import BaseParameters
from ..regressors.terms import LinearFriction, ModelTerm, base_term_columns
from ..regressors.torque import torque_regressor_prepared
from .dataset import ModelColumns, RegressorBlock
from .log import TorqueLog
from .sanity import moving_joints
from .streaming import BLOCK_ROWS, streams

#: Cycles of the cut-off frequency after which the zero-phase Butterworth low-pass has
#: forgotten a block's edge (its slowest pole decays as ``exp(-0.38 * 2 pi f_c t)``; 14
#: cycles left differences of 4e-8 in the smallest estimates of a 12 s log read in blocks
#: of 16,384 rows, 20 leave rounding): each block is computed this much beyond its ends,
#: filtered, trimmed.
_SETTLE_CYCLES = 20.0

__all__ = [
    "friction_regressor",
    "log_blocks",
    "parallel_filtered",
    "still_columns",
    "still_friction",
    "term_regressor",
]


def friction_regressor(dq: NDArray[np.float64]) -> NDArray[np.float64]:
    """Regressor ``F`` (..., n, 3 n) of the classical friction at the joints, columns
    :func:`~dynid.regressors.terms.friction_labels`.

    ``F[..., j, 3 j : 3 j + 3] = (dq_j, sign(dq_j), 1)``; zero elsewhere.
    """
    return LinearFriction(Drive.identity(dq.shape[-1])).torque_columns(dq, dq, dq)


def log_blocks(
    robot: Robot,
    log: TorqueLog,
    columns: ModelColumns,
    *,
    stream: bool | None = None,
    cutoff_hz: float | None = None,
) -> Iterator[RegressorBlock]:
    """The regressor rows of a prepared log over ``columns``: sample-major (row ``k n + j``
    is sample ``k``, joint ``j``, its noise group ``j``); known rotor torques of
    ``columns.drive`` subtracted. One block, or blocks of :data:`BLOCK_ROWS` rows when
    ``stream`` (default: when the regressor exceeds ``DYNID_MAX_STACK_BYTES``).

    ``cutoff_hz``: the low-pass the log's torques went through. The columns of the
    appended terms (friction) then go through the same zero-phase low-pass, at the log's
    rate (:func:`parallel_filtered`): a filtered torque rounds the step of Coulomb friction
    at a reversal, and ``sign(dq)`` left sharp would bias every friction coefficient. In
    blocks, each block's rows are computed with the samples of :data:`_SETTLE_CYCLES` periods
    of the cut-off on either side, so that they equal the rows of the log filtered whole."""
    assert log.ddq is not None  # prepare_log always fills ddq
    N, n = log.n_samples, log.n
    drive = columns.drive
    if stream is None:
        stream = streams(N * n, len(columns.labels))
    step = max(1, BLOCK_ROWS // n) if stream else N
    steps = columns.step_columns()
    pad = 0  # samples computed beyond each block so that its filtered columns are the whole log's
    if cutoff_hz is not None and step < N and steps.any():
        pad = int(np.ceil(_SETTLE_CYCLES * signals.sample_rate(log.t) / cutoff_hz))
    # the filtered columns of several blocks at once (a span), so that the margins cost at
    # most a quarter of the samples filtered, not twice a block's
    span = step * max(1, -(-8 * pad // step))
    A: NDArray[np.float64] | None = None
    lo = hi = 0
    for a in range(0, N, step):
        b = slice(a, a + step)
        q, dq, ddq, tau = log.q[b], log.dq[b], log.ddq[b], log.tau[b]
        Y, _ = term_regressor(robot, columns.base, columns.terms, q, dq, ddq)
        if cutoff_hz is not None and pad == 0:
            Y = parallel_filtered(Y, steps, log.t[b], cutoff_hz)
        elif cutoff_hz is not None:  # the appended terms' columns (all that step) with margins
            if A is None or a + q.shape[0] > hi - pad and hi < N:  # the next span
                lo, hi = max(0, a - pad), min(N, a + span + pad)
                w = slice(lo, hi)
                A = np.concatenate(
                    [t.torque_columns(log.q[w], log.dq[w], log.ddq[w]) for t in columns.appended],
                    axis=-1,
                )
                A = parallel_filtered(A, steps[Y.shape[-1] - A.shape[-1] :], log.t[w], cutoff_hz)
            Y[..., Y.shape[-1] - A.shape[-1] :] = A[a - lo : a - lo + q.shape[0]]
        if drive is not None and drive.rotor_inertia is not None:  # known: subtracted
            tau = tau - drive.rotor_torques(ddq, drive.rotor_inertia)
        m = Y.shape[0]
        W = Y.reshape(m * n, -1)
        _checks.finite("regressor", W)
        yield RegressorBlock(W=W, y=tau.reshape(-1), groups=np.tile(np.arange(n), m))


def parallel_filtered(
    Y: NDArray[np.float64], cols: NDArray[np.bool_], t: NDArray[np.float64], cutoff_hz: float
) -> NDArray[np.float64]:
    """``Y`` (N, n, c) with its columns ``cols`` (c,) low-passed along time at
    ``cutoff_hz`` (:func:`dynid.signals.lowpass`, the filter of the torques): the
    "parallel filtering" of Gautier and Khalil, the regressor and the torques through the
    same filter, for the columns that step at a reversal (the smooth ones are left as
    computed from the filtered states). Left as it is where the rate is too low for the
    cut-off (below 2.2 times it) or the samples too few to filter."""
    idx = np.flatnonzero(cols)
    if idx.size == 0 or Y.shape[0] < 2:
        return Y
    fs = signals.sample_rate(t)
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
