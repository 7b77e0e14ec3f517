"""The rows of a data set, stacked or left in blocks, and the blocks without information.

:func:`stack_dataset` concatenates a data set's regressor blocks (:class:`RegressorStack`)
and drops those whose regressor is zero for this robot (``g1`` of the Panda, its joint-1
axis along gravity), with a warning when their data are not zero; a log too long to stack
is left in blocks (:class:`StreamedRows`), read again at every pass of the fit.
"""

from __future__ import annotations

import dataclasses
import itertools
import logging
import warnings
from collections.abc import Callable, Iterable, Iterator
from dataclasses import dataclass

import numpy as np
from numpy.typing import NDArray

from .._checks import caller_level
from ..exceptions import DynidWarning, ShapeError
from ..model.robot import Robot
from .dataset import Dataset, ModelColumns, RegressorBlock
from .holdout import HeldOut, Normals
from .solvers import block_grams
from .streaming import BlockSource

__all__ = [
    "DEFAULT_FIT_RTOL",
    "Judge",
    "RegressorStack",
    "StreamedRows",
    "informative_blocks",
    "selected_columns",
    "stack_dataset",
]

_log = logging.getLogger(__name__)

#: Rank tolerance of the fit (diagonal of R, column-scaled) when none is given: the base
#: parameters' columns are independent by construction, so only degenerate data fall below.
DEFAULT_FIT_RTOL = 1e-10

#: A dropped block whose data exceed this fraction of the largest |y| triggers a warning:
#: the robot says the rows are identically zero, the data say otherwise.
_DROPPED_DATA_RTOL = 1e-6


@dataclass(frozen=True, slots=True, eq=False)
class RegressorStack:
    """Blocks concatenated: ``W`` (m, c) column-major, ``y`` (m,), ``groups`` (m,).

    Attributes
    ----------
    W, y, groups : ndarray
        Every block's rows, in block order.
    rows : ndarray of int, shape (k, 3)
        ``(start, stop, first)`` of each block.
    labels : tuple of str
        Each block's label.
    kept : ndarray of bool, shape (k,)
        False for the blocks dropped (no information).
    grams : ndarray, shape (k, c, c), optional
        Each block's Gram matrix ``W_b^T W_b`` (None for a single block).
    """

    W: NDArray[np.float64]
    y: NDArray[np.float64]
    groups: NDArray[np.intp]
    rows: NDArray[np.intp]
    labels: tuple[str, ...]
    kept: NDArray[np.bool_]
    grams: NDArray[np.float64] | None = None

    @property
    def dropped(self) -> tuple[str, ...]:
        """Labels of the blocks dropped."""
        return tuple(self.labels[k] for k in np.flatnonzero(~self.kept))

    @property
    def used_rows(self) -> NDArray[np.intp]:
        """``(start, stop, first)`` of the blocks kept."""
        return self.rows[self.kept]

    @property
    def n_rows(self) -> int:
        """Rows used (in the kept blocks)."""
        r = self.used_rows
        return int(np.sum(r[:, 1] - r[:, 0]))

    def used(self) -> NDArray[np.intp]:
        """Indices of the rows used, block after block."""
        return np.concatenate(
            [np.arange(a, b) for a, b, _ in self.used_rows] + [np.zeros(0, dtype=np.intp)]
        )

    def select(self, blocks: NDArray[np.bool_]) -> RegressorStack:
        """The stack with only the kept blocks among ``blocks`` (k,) used (held-out fits)."""
        return dataclasses.replace(self, kept=self.kept & np.asarray(blocks, dtype=bool))


#: Held-out judgement of a fit (:mod:`dynid.identification.holdout`): called with the stack,
#: the model's columns, the columns fitted (c,) and the estimates over every column (c,);
#: returns the folds' normal equations over every column, or None when the data are too
#: short to judge.
@dataclass(frozen=True, slots=True, eq=False)
class StreamedRows:
    """A data set's rows left in blocks, too many to stack (a long torque log): ``source``
    yields ``(W, y, groups)`` again for every pass of the fit
    (:mod:`dynid.identification.streaming`).

    Attributes
    ----------
    source : BlockSource
    n_rows : int
        Rows over all blocks (0 until the fit has counted them).
    dropped : tuple of str
        Labels of the noise groups dropped (no information); empty for a torque log,
        whose blocks are not judged.
    normals : tuple of Normals, optional
        The unweighted normal equations of the rows of each fold, gathered by the fit's
        pass (:func:`~dynid.identification.core.identify`'s ``fold_labels``).
    """

    source: BlockSource
    n_rows: int = 0
    dropped: tuple[str, ...] = ()
    normals: tuple[Normals, ...] | None = None


Judge = Callable[
    [RegressorStack | StreamedRows, ModelColumns, NDArray[np.bool_], NDArray[np.float64]],
    HeldOut | None,
]


def informative_blocks(ss: NDArray[np.float64], rtol: float) -> NDArray[np.bool_]:
    """Blocks with information, from the sums of squares ``ss[j, k]`` of column j, block k.

    A block is uninformative when the norm of its column-scaled regressor is at most
    ``rtol`` times the largest block's.
    """
    col = ss.sum(axis=1)
    block = np.sqrt(np.sum(ss / np.where(col > 0, col, 1.0)[:, None], axis=0))
    return block > rtol * float(np.max(block, initial=0.0))


def stack_dataset(
    robot: Robot, data: Dataset, columns: ModelColumns, *, rtol: float = DEFAULT_FIT_RTOL
) -> RegressorStack | StreamedRows:
    """Concatenate the data's blocks and drop those without information; a torque log
    that comes in several blocks (too long to stack) is left in them (:class:`StreamedRows`).

    A seam for held-out judgement: :meth:`RegressorStack.select` keeps some blocks for
    :func:`fit_stack`.

    Warns
    -----
    DynidWarning
        A dropped block holds non-zero data (gravity or kinematics differ from the source's).
    """
    blocks = iter(data.blocks(robot, columns))
    head = list(itertools.islice(blocks, 2))
    source: BlockSource = lambda: ((b.W, b.y, b.groups) for b in data.blocks(robot, columns))  # noqa: E731
    if head and head[0].group_labels:  # pieces of many groups: streamed, groups judged
        labels = head[0].group_labels
        del head, blocks
        return _streamed_groups(robot, source, labels, rtol)
    if data.route == "classical" and len(head) > 1:  # a long log: blocks of rows, streamed
        del head, blocks
        return StreamedRows(source)
    stack = _concatenated(itertools.chain(head, blocks), len(columns.labels))
    if stack.rows.shape[0] < 2:
        return stack
    grams = block_grams(stack.W, stack.rows)
    info = informative_blocks(np.einsum("kjj->jk", grams), rtol)
    stack = dataclasses.replace(stack, kept=info, grams=grams)
    if info.all():
        return stack
    y_out = np.concatenate([stack.y[a:b] for a, b, _ in stack.rows[~info]])
    _warn_dropped(robot, stack.dropped, np.max(np.abs(y_out)), np.max(np.abs(stack.y)))
    return stack


def _warn_dropped(robot: Robot, dropped: tuple[str, ...], big: float, top: float) -> None:
    """Warn when rows without information hold data (``big`` of the largest ``top``),
    at the user's call (:func:`~dynid._checks.caller_level`)."""
    if big > _DROPPED_DATA_RTOL * top:
        warnings.warn(
            f"rows {list(dropped)} carry no information for robot {robot.name!r} (its "
            f"regressor is zero there) but the data reach |{big:.3g}|; hint: check the "
            "gravity vector and the kinematics against the source of the data",
            DynidWarning,
            stacklevel=caller_level(),
        )
    _log.info("dropping rows without information: %s", ", ".join(dropped))


def _streamed_groups(
    robot: Robot, source: BlockSource, labels: tuple[str, ...], rtol: float
) -> StreamedRows:
    """Rows of many noise groups left in blocks, the groups without information dropped
    as the stacked route drops its blocks (:func:`informative_blocks` on each group's
    column sums of squares, one pass)."""
    k = len(labels)
    ss: NDArray[np.float64] | None = None
    ymax = np.zeros(k)
    for W, y, g in source():
        if ss is None:
            ss = np.zeros((W.shape[1], k))
        for j in range(W.shape[1]):  # one column at a time: no squared copy of the block
            ss[j] += np.bincount(g, W[:, j] ** 2, minlength=k)
        np.maximum.at(ymax, g, np.abs(y))
    if ss is None:
        raise ShapeError("no regressor rows: the data hold no block")
    info = informative_blocks(ss, rtol)
    if info.all():
        return StreamedRows(source)
    dropped = tuple(lab for lab, ok in zip(labels, info, strict=True) if not ok)
    _warn_dropped(robot, dropped, float(ymax[~info].max()), float(ymax.max()))

    def kept() -> Iterator[tuple[NDArray[np.float64], NDArray[np.float64], NDArray[np.intp]]]:
        for W, y, g in source():
            sel = info[g]
            yield W[sel], y[sel], g[sel]

    return StreamedRows(kept, dropped=dropped)


def _concatenated(blocks: Iterable[RegressorBlock], c: int) -> RegressorStack:
    """One stack of the blocks, every block kept."""
    blks = list(blocks)
    for b in blks:
        if b.W.ndim != 2 or b.W.shape[1] != c or b.y.shape != (b.W.shape[0],):
            raise ShapeError(
                f"a regressor block must be (m, {c}) with y (m,); got {b.W.shape}, {b.y.shape}"
            )
    sizes = np.array([b.W.shape[0] for b in blks], dtype=np.intp)
    stops = np.cumsum(sizes)
    rows = np.column_stack([stops - sizes, stops, [b.first for b in blks]]).astype(np.intp)
    if len(blks) == 1:
        W, y, groups = blks[0].W, blks[0].y, blks[0].groups
    else:
        W = np.empty((int(stops[-1]) if blks else 0, c), order="F")
        for b, (a, e, _) in zip(blks, rows, strict=True):
            W[a:e] = b.W
        y = np.concatenate([b.y for b in blks] + [np.zeros(0)])
        groups = np.concatenate([b.groups for b in blks] + [np.zeros(0, np.intp)])
    return RegressorStack(
        W,
        y,
        np.asarray(groups, dtype=np.intp),
        rows,
        tuple(b.label for b in blks),
        np.ones(len(blks), dtype=bool),
    )


def selected_columns(source: BlockSource, cols: NDArray[np.bool_]) -> BlockSource:
    """The blocks of ``source`` with only the columns ``cols`` (c,) bool."""
    if np.all(cols):
        return source
    return lambda: ((W[:, cols], y, g) for W, y, g in source())
