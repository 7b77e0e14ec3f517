"""The held-out judgement of the candidates' models: the folds' normal equations.

:func:`heldout_judge` gives :func:`~dynid.identification.core.identify` its judge: the
normal equations of every fold (:class:`~dynid.identification.holdout.HeldOut`), fitted on
the rows as prepared and judged on the torques as measured (one more pass over
:meth:`~dynid.identification.recordings.Recordings.measured_blocks`), and the same judged
rows with each joint's torques in units of its own noise (:func:`inverse_noise`), which
the structure choice reads: pooled in N m, a wrist whose noise is a hundredth of the
shoulder's would not count.
"""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import replace
from typing import Any

import numpy as np
from numpy.typing import NDArray

from ..exceptions import OptionError
from ..model.robot import Robot
from .core import Judge, ModelColumns, RegressorStack, StreamedRows, selected_columns
from .estimators import Estimator, row_weights
from .holdout import HeldOut, Normals, block_normals
from .recordings import Recordings
from .streaming import BlockSource, normals_by_label_scaled
from .verdict import NOISE_FLOOR_SHARE

__all__ = ["NOISE_FLOOR_SHARE", "heldout_judge", "inverse_noise"]


def heldout_judge(
    robot: Robot,
    data: Recordings,
    estimator: Estimator,
    folds: int,
    validation: Recordings | None,
) -> tuple[Judge, str, NDArray[np.intp] | None]:
    """The held-out judgement over the recordings' folds (or a separate recording), how,
    and the fold of every row (None with a separate recording or too few samples)."""
    try:
        labels, how = data.fold_labels(folds)
    except OptionError:
        labels, how = None, "none (too few samples for held-out blocks)"
    if validation is not None:
        how = "a separate recording"
    scheme = "recordings" if len(data.names) > 1 else "blocks"
    parts = data.part_labels(folds) if labels is not None and validation is None else None
    measured_ok = data.measured  # judged on the torques as measured: one more pass
    inv_noise = inverse_noise(data)

    def judge(
        stack: RegressorStack | StreamedRows,
        columns: ModelColumns,
        cols: NDArray[np.bool_],
        beta: NDArray[Any],
    ) -> HeldOut | None:
        b = np.asarray(beta)[cols]
        rows = selected_columns(_rows(data, robot, columns), cols)  # read only when passed
        normals: Callable[[NDArray[np.intp]], tuple[Normals, ...]]
        if isinstance(stack, StreamedRows) and stack.normals is not None and validation is None:
            assert labels is not None  # the fit gathered the folds' normals by these labels
            source = rows if measured_ok else selected_columns(stack.source, cols)
            plain, white, held_parts = _judged_normals(
                lambda lab: normals_by_label_scaled(source, lab, None, inv_noise, b), labels, parts
            )
            judged = plain if measured_ok else None
            held = replace(HeldOut.k_fold(stack.normals, judged), scheme=scheme, whitened=white)
            return held.with_parts(*held_parts).expanded(cols)
        if isinstance(stack, StreamedRows):  # rows in blocks: one pass per set of labels
            source = selected_columns(stack.source, cols)
            e = np.concatenate([y - W @ b for W, y, _ in source()])
            rw = estimator.row_weights(e, np.tile(np.arange(data.n), e.size // data.n), b.size)
            m = e.size
            normals = lambda lab: normals_by_label_scaled(source, lab, rw, None, b)[0]  # noqa: E731
            fitted = source
        else:
            W = stack.W if cols.all() else stack.W[:, cols]
            rw = row_weights(estimator, W, stack.y, stack.groups, b)
            m = stack.y.size
            ones = bool((rw == 1.0).all())  # OLS: the rows as they are, not a copy
            Ww, yw = (W, stack.y) if ones else (W * rw[:, None], stack.y * rw)
            normals = lambda lab: block_normals(Ww, yw, lab, b)  # noqa: E731
            fitted = lambda: iter([(W, stack.y, stack.groups)])  # noqa: E731
        if validation is not None:
            test, test_white = _normals(robot, validation, columns, cols)
            one = np.zeros(m, np.intp)  # the training error on the torques as measured too
            whole = normals_by_label_scaled(rows, one, origin=b)[0][0] if measured_ok else None
            held = HeldOut.separate(normals(one)[0], test, whole)
            held = held if test_white is None else replace(held, whitened=(test_white,))
        elif labels is None:
            return None
        else:
            # the whitened rows in units of each joint's noise alone: the estimator's
            # weights (its own estimate of each joint's residual level, at the largest
            # model) would make a joint's error vanish with the terms it loses; the
            # measured rows judged unweighted too, the error of the torques as measured
            # (weighted, an irls fit read 40 % above the same model's plain error)
            judged_rows = rows if measured_ok else fitted
            weights = None if measured_ok else rw
            plain, white, held_parts = _judged_normals(
                lambda lab: normals_by_label_scaled(judged_rows, lab, weights, inv_noise, b),
                labels,
                parts,
            )
            judged = plain if measured_ok else None
            held = replace(HeldOut.k_fold(normals(labels), judged), scheme=scheme, whitened=white)
            held = held.with_parts(*held_parts)
        return held.expanded(cols)

    return judge, how, (labels if validation is None else None)


_Pass = Callable[[NDArray[np.intp]], tuple[tuple[Normals, ...], tuple[Normals, ...]]]


def _judged_normals(
    by_label: _Pass,
    labels: NDArray[np.intp],
    parts: tuple[NDArray[np.intp], tuple[int, ...]] | None,
) -> tuple[tuple[Normals, ...], tuple[Normals, ...], tuple[tuple[Normals, ...], tuple[int, ...]]]:
    """The judged rows' normal equations per fold, plain and whitened (``by_label``: one
    pass over the rows by a labelling), from one pass by the folds' blocks ``parts``
    (:meth:`~.recordings.Recordings.part_labels`: the labels and each block's fold) when
    given, summed per fold; and the whitened blocks with their folds (empty without
    ``parts`` or whitened rows)."""
    if parts is None:
        plain, white = by_label(labels)
        return plain, white, ((), ())
    fine, fold = parts
    plain, white = by_label(fine)
    if not white:
        return _per_fold(plain, fold), white, ((), ())
    return _per_fold(plain, fold), _per_fold(white, fold), (white, fold)


def _per_fold(blocks: tuple[Normals, ...], fold: tuple[int, ...]) -> tuple[Normals, ...]:
    """The normal equations of ``blocks`` summed per fold (``fold``: each block's, every
    fold 0 .. k-1 present)."""
    out: list[Normals] = []
    for f in range(max(fold) + 1):
        mine = [blk for blk, g in zip(blocks, fold, strict=True) if g == f]
        total = mine[0]
        for blk in mine[1:]:
            total = total + blk
        out.append(total)
    return tuple(out)


def inverse_noise(data: Recordings) -> NDArray[np.float64] | None:
    """Per joint, one over the torque noise std [1/(N m)] of the recordings (the samples'
    mean square over the pieces, at least :data:`NOISE_FLOOR_SHARE` of the largest
    joint's); None when a piece's noise is not known or no joint has any."""
    noise = [p.torque_noise_std for p in data.pieces]
    if not noise or any(x is None for x in noise):
        return None
    counts = np.array([p.log.n_samples for p in data.pieces], dtype=np.float64)
    var = np.asarray(noise, dtype=np.float64) ** 2
    sigma = np.sqrt(counts @ var / counts.sum())
    top = float(np.max(sigma)) if sigma.size else 0.0
    if not (np.all(np.isfinite(sigma)) and top > 0):
        return None
    return 1.0 / np.maximum(sigma, NOISE_FLOOR_SHARE * top)


def _rows(data: Recordings, robot: Robot, columns: ModelColumns) -> BlockSource:
    """The recordings' rows as measured (:meth:`~.recordings.Recordings.measured_blocks`),
    a source of blocks for a pass."""
    return lambda: ((b.W, b.y, b.groups) for b in data.measured_blocks(robot, columns))


def _normals(
    robot: Robot,
    data: Recordings,
    columns: ModelColumns,
    cols: NDArray[np.bool_],
) -> tuple[Normals, Normals | None]:
    """The normal equations of a separate recording over the fitted columns, on its rows
    as measured (:meth:`~.recordings.Recordings.measured_blocks`), unweighted (the error
    of the torques as measured, whatever the estimator); and those of its rows with each
    joint in units of its own noise (:func:`inverse_noise`; None when not known), as the
    folds are whitened."""
    blocks = list(data.measured_blocks(robot, columns))
    W = np.concatenate([blk.W for blk in blocks])[:, cols]
    y = np.concatenate([blk.y for blk in blocks])
    g = np.concatenate([blk.groups for blk in blocks])
    one = np.zeros(y.size, np.intp)
    inv = inverse_noise(data)
    white = None if inv is None else block_normals(W * inv[g][:, None], y * inv[g], one)[0]
    return block_normals(W, y, one)[0], white
