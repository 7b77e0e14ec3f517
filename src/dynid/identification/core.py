"""One identification core: base parameters (and model terms) from any data set.

Every route is the same steps over a :class:`Dataset`:

1. **columns** (:func:`model_columns`): the base parameters of the data's regressor kind
   (``"static"``: rows ``[tril M; g]``; ``"torque"``: joint torques) with the model terms
   (:mod:`dynid.regressors.terms`: a drive's rotor inertia, friction), in the order
   ``beta1 .. beta_r`` then every appended term's parameters;
2. **stack** (:func:`stack_dataset`): the data's regressor blocks ``W`` (rows, columns)
   with targets ``y`` and a noise group per row, stacked; a block whose regressor is zero
   for this robot (``g1`` of the Panda, its joint-1 axis along gravity) carries no
   information and is dropped, with a warning when its data are not zero;
3. **fit** (:func:`fit_stack`): an estimator (:mod:`dynid.identification.estimators`)
   solves ``W x = y``; columns the data cannot excite (the friction of a joint that never
   moves) are left out and reported as not kept;
4. **model**: the fit, the friction and the record of what was done, as an
   :class:`~dynid.identification.model.IdentifiedModel`.

A data set is anything with the :class:`Dataset` protocol: static data
(:class:`~dynid.identification.data.StaticDataset`) and prepared torque logs
(:class:`~dynid.identification.classical.PreparedLog`). Its blocks come as an iterator so
that a long log can be read in pieces; they are concatenated here.
"""

from __future__ import annotations

import dataclasses
import itertools
import logging
import warnings
from collections.abc import Callable, Iterable, Iterator
from dataclasses import dataclass
from typing import Any, Literal, Protocol

import numpy as np
from numpy.typing import NDArray

from ..exceptions import DynidWarning, OptionError, RankDeficientError, ShapeError
from ..model.drive import Drive
from ..model.robot import Robot
from ..regressors.base import BaseParameters, base_parameters, identifiability
from ..regressors.terms import ModelTerm, drive_terms
from .engine import HeldRows, Rows, fit_rows
from .estimators import Estimator, EstimatorName, estimator_named
from .holdout import HeldOut, cross_validate
from .info import FrictionInfo, IdentificationInfo, Route
from .least_squares import (
    LeastSquaresFit,
    StdMethod,
    block_grams,
    checked_std,
    conditioning_advice,
)
from .model import IdentifiedModel
from .streaming import BlockRows, BlockSource

__all__ = [
    "DEFAULT_FIT_RTOL",
    "Dataset",
    "Judge",
    "ModelColumns",
    "RegressorBlock",
    "RegressorKind",
    "RegressorStack",
    "Route",
    "StreamedRows",
    "fit_stack",
    "identify",
    "informative_blocks",
    "model_columns",
    "stack_dataset",
]

_log = logging.getLogger(__name__)

#: Which regressor a data set stacks (the kind of :func:`~dynid.regressors.base.
#: base_parameters`).
RegressorKind = Literal["static", "torque"]

#: Rank tolerance of the fit (diagonal of R, column-scaled) when none is given: the base
#: parameters' columns are independent by construction, so only degenerate data fall below.
DEFAULT_FIT_RTOL = 1e-10

#: A dropped block whose data exceed this fraction of the largest |y| triggers a warning:
#: the robot says the rows are identically zero, the data say otherwise.
_DROPPED_DATA_RTOL = 1e-6


@dataclass(frozen=True, slots=True, eq=False)
class ModelColumns:
    """The columns of a model: base parameters, then the appended terms' parameters.

    Attributes
    ----------
    base : BaseParameters
        Over the link parameters and the ``in_base`` terms (rotor inertias).
    terms : tuple of ModelTerm
        Every term; those not ``in_base`` (friction) append their columns after ``beta``.
    drive : Drive, optional
        The drive the data are read through (known rotor inertias are subtracted).
    """

    base: BaseParameters
    terms: tuple[ModelTerm, ...] = ()
    drive: Drive | None = None

    @property
    def appended(self) -> tuple[ModelTerm, ...]:
        """The terms whose columns follow the base parameters."""
        return tuple(t for t in self.terms if not t.in_base)

    @property
    def labels(self) -> tuple[str, ...]:
        """One label per column: ``base.labels`` then the appended terms' labels."""
        out = self.base.labels
        for t in self.appended:
            out = out + t.labels
        return out

    def appended_term(self, name: str) -> tuple[ModelTerm, slice] | None:
        """The appended term named ``name`` with its columns, or None."""
        c = self.base.rank
        for t in self.appended:
            if t.name == name:
                return t, slice(c, c + len(t.labels))
            c += len(t.labels)
        return None

    def step_columns(self) -> NDArray[np.bool_]:
        """(c,): the columns that step where a velocity reverses (a term's ``steps``)."""
        return self._per_column("steps", False).astype(bool)

    def motion_columns(self) -> NDArray[np.intp]:
        """(c,): the joint (motor) whose motion each column needs to be identified, -1 for
        none (a term's ``needs_motion``; the base parameters need none of their own)."""
        return self._per_column("needs_motion", -1).astype(np.intp)

    def _per_column(self, attr: str, fill: bool | int) -> NDArray[Any]:
        """An optional per-parameter property ``attr`` of the appended terms over every
        column, ``fill`` for the base parameters and the terms without it."""
        out = [np.full(self.base.rank, fill)]
        for t in self.appended:
            v = getattr(t, attr, None)
            out.append(np.full(len(t.labels), fill) if v is None else np.asarray(v))
        return np.concatenate(out)


@dataclass(frozen=True, slots=True, eq=False)
class RegressorBlock:
    """Rows of the stacked regressor of one kind, with their targets and noise groups.

    Attributes
    ----------
    W : ndarray, shape (m, c)
        Regressor rows over the model's columns (:class:`ModelColumns` order).
    y : ndarray, shape (m,)
        Measured targets (SI: N m, kg m^2).
    groups : ndarray of int, shape (m,)
        Noise group of each row (joint of a torque log, row of ``[tril M; g]``).
    label : str
        What the rows are (``"g1"``); names a dropped block.
    first : int
        ``W[:, :first]`` is exactly zero (products over the rows skip those columns).
    group_labels : tuple of str
        Set on a block of rows of many groups that is one of several pieces of data too
        large to stack (static data of a long chain): the name of every group. The core
        then fits the pieces in passes (:class:`StreamedRows`), never concatenated, and
        drops the groups without information by these names.
    """

    W: NDArray[np.float64]
    y: NDArray[np.float64]
    groups: NDArray[np.intp]
    label: str = ""
    first: int = 0
    group_labels: tuple[str, ...] = ()


class Dataset(Protocol):
    """What the core needs of data (module docstring)."""

    @property
    def route(self) -> Route:
        """``"static"`` or ``"classical"``: recorded in the model."""
        ...

    @property
    def regressor_kind(self) -> RegressorKind:
        """The regressor it stacks: ``"static"`` or ``"torque"``."""
        ...

    @property
    def moving(self) -> bool:
        """True when the data move (friction acts and can be identified)."""
        ...

    @property
    def source(self) -> str:
        """The data in a few words, for messages (``"static regressor of 5 configuration(s)"``)."""
        ...

    @property
    def hint(self) -> str:
        """What to do when the data do not excite every column (ends a rank error)."""
        ...

    def check_robot(self, robot: Robot) -> None:
        """Raise unless the data belong to a robot with ``robot.n`` joints."""
        ...

    def frozen_columns(self, columns: ModelColumns) -> NDArray[np.bool_]:
        """Columns (c,) the data cannot excite (left out of the fit)."""
        ...

    def blocks(self, robot: Robot, columns: ModelColumns) -> Iterator[RegressorBlock]:
        """The regressor blocks over ``columns`` with their targets."""
        ...

    def record(self, n_rows: int) -> IdentificationInfo:
        """The data's part of the model's record (reference, counts, preparation), given
        the rows used; the core fills in the rest."""
        ...


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
    """

    source: BlockSource
    n_rows: int = 0
    dropped: tuple[str, ...] = ()


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


def model_columns(
    robot: Robot,
    data: Dataset,
    *,
    drive: Drive | None = None,
    terms: tuple[ModelTerm, ...] | None = None,
    base: BaseParameters | None = None,
    rtol: float | None = None,
) -> ModelColumns:
    """The model's columns for ``data``: ``terms`` (default: the drive's rotor inertia, and
    friction when the data move) and ``base`` (default: the structural base parameters of
    the data's regressor kind).

    Raises
    ------
    ShapeError
        ``base`` was built for another number of standard parameters.
    """
    if terms is None:
        terms = drive_terms(drive, robot.n, friction=data.moving)
    p = 10 * robot.n + sum(len(t.labels) for t in terms if t.in_base)
    if base is None:
        base = base_parameters(robot, kind=data.regressor_kind, rtol=rtol, terms=terms)
    elif base.n_std != p:
        raise ShapeError(
            f"base was built for {base.n_std} standard parameters; robot {robot.name!r} has {p}"
        )
    return ModelColumns(base=base, terms=tuple(terms), drive=drive)


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
    _warn_dropped(robot, stack.dropped, np.max(np.abs(y_out)), np.max(np.abs(stack.y)), 5)
    return stack


def _warn_dropped(
    robot: Robot, dropped: tuple[str, ...], big: float, top: float, level: int
) -> None:
    """Warn when rows without information hold data (``big`` of the largest ``top``),
    ``level`` frames above (at the caller of :func:`identify`)."""
    if big > _DROPPED_DATA_RTOL * top:
        warnings.warn(
            f"rows {list(dropped)} carry no information for robot {robot.name!r} (its "
            f"regressor is zero there) but the data reach |{big:.3g}|; hint: check the "
            "gravity vector and the kinematics against the source of the data",
            DynidWarning,
            stacklevel=level,
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
    _warn_dropped(robot, dropped, float(ymax[~info].max()), float(ymax.max()), 6)

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


def fit_stack(
    stack: RegressorStack | StreamedRows,
    labels: tuple[str, ...],
    *,
    estimator: EstimatorName | Estimator = "ols",
    std: StdMethod = "classical",
    max_std_percent: float | None = None,
    rtol: float = DEFAULT_FIT_RTOL,
    frozen: NDArray[np.bool_] | None = None,
) -> LeastSquaresFit:
    """Fit the stacked rows with an estimator; ``frozen`` columns are left out (0, not kept).

    The one engine (:func:`~dynid.identification.engine.fit_rows`) on the rows held
    (:class:`~dynid.identification.engine.HeldRows`, the blocks' Gram matrices reused and
    their zero columns skipped) or read in blocks
    (:class:`~dynid.identification.streaming.BlockRows`).

    Raises
    ------
    RankDeficientError
        From the estimator (``rank``, ``needed``, ``dependent`` set).
    NonFiniteError
        NaN or inf in the regressor.
    """
    est = estimator_named(estimator)
    cols = np.ones(len(labels), dtype=bool) if frozen is None else ~np.asarray(frozen, bool)
    kept_labels = tuple(lab for lab, c in zip(labels, cols, strict=True) if c)
    fit = fit_rows(
        _rows(stack, cols, est),
        est,
        rtol=rtol,
        std=std,
        max_std_percent=max_std_percent,
        labels=kept_labels,
    )
    return fit if cols.all() else _expanded(fit, cols)


def _rows(
    stack: RegressorStack | StreamedRows, cols: NDArray[np.bool_], est: Estimator
) -> Rows:
    """The stack's rows over the columns ``cols`` (c,), as the engine takes them."""
    if isinstance(stack, StreamedRows):
        source = selected_columns(stack.source, cols)
        return BlockRows(source, by_group=est.weighted, per_row=est.per_row)
    W, rows = stack.W, stack.used_rows
    grams = None if stack.grams is None else stack.grams[stack.kept]
    if not cols.all():
        W = W[:, cols]
        rows = rows.copy()
        rows[:, 2] = 0
        grams = None if grams is None else grams[:, cols][:, :, cols]
    gram = None if grams is None else grams.sum(axis=0)
    return HeldRows(W, stack.y, stack.groups, rows, gram)


def selected_columns(source: BlockSource, cols: NDArray[np.bool_]) -> BlockSource:
    """The blocks of ``source`` with only the columns ``cols`` (c,) bool."""
    if np.all(cols):
        return source
    return lambda: ((W[:, cols], y, g) for W, y, g in source())


def identify(
    robot: Robot,
    data: Dataset,
    *,
    drive: Drive | None = None,
    terms: tuple[ModelTerm, ...] | None = None,
    base: BaseParameters | None = None,
    estimator: EstimatorName | Estimator = "ols",
    std: StdMethod = "classical",
    max_std_percent: float | None = None,
    rtol: float | None = None,
    judge: Judge | None = None,
) -> IdentifiedModel:
    """Identify the base parameters (and the appended terms: friction) from a data set.

    Parameters
    ----------
    robot : Robot
        Kinematics and gravity the data belong to; its inertial parameters are not used.
    data : Dataset
        Static data (:class:`~dynid.identification.data.StaticDataset`) or a prepared
        torque log (:func:`~dynid.identification.classical.prepare_torque_log`).
    drive : Drive, optional
        The drive train: its rotor inertias are identified with the links (known ones
        subtracted) and its friction acts where it says.
    terms : tuple of ModelTerm, optional
        The model terms; default :func:`~dynid.regressors.terms.drive_terms` of ``drive``
        with friction when the data move.
    base : BaseParameters, optional
        The base parameters to identify; default the structural ones of the data's
        regressor kind (``rtol`` as below).
    estimator : {"ols", "wls", "irls"} or Estimator
        :mod:`dynid.identification.estimators`.
    std : {"classical", "robust"}
        Standard deviations from ``sigma^2 (W^T W)^-1`` or the heteroscedasticity-consistent
        (HC1) covariance.
    max_std_percent : float, optional
        Remove coefficients with a larger relative standard deviation and re-fit once.
    rtol : float, optional
        Rank tolerance of the base parameters (default: at the first clear gap of the
        singular values) and of the fit (default :data:`DEFAULT_FIT_RTOL`).
    judge : callable, optional
        Held-out judgement (:data:`Judge`): its folds are kept (``holdout``) and their
        errors recorded (``heldout``).

    Returns
    -------
    IdentifiedModel
        ``fit`` over the ``r`` base parameters (global statistics of the whole fit);
        ``joint_fit`` over every column and ``friction`` (n, 3) when friction is appended.

    Raises
    ------
    OptionError
        ``max_std_percent`` not positive, or ``std`` not ``"classical"``/``"robust"``.
    ShapeError, DataError
        Data of another robot, or ``base`` of another size.
    RankDeficientError
        The data do not excite every column; ``rank``, ``needed`` and ``dependent`` say
        how and the message adds the data's hint.

    Warns
    -----
    DynidWarning
        Dropped blocks holding data, an ill-conditioned regressor or coefficients above
        1000 % std (:func:`~dynid.identification.least_squares.conditioning_advice`).
    """
    data.check_robot(robot)
    check_options(std=std, max_std_percent=max_std_percent)
    if drive is not None:
        drive.check(robot.n)
    columns = model_columns(robot, data, drive=drive, terms=terms, base=base, rtol=rtol)
    fit_rtol = DEFAULT_FIT_RTOL if rtol is None else rtol
    stack = stack_dataset(robot, data, columns, rtol=fit_rtol)
    labels = columns.labels
    _log.info("%s: %d rows, %d columns", data.source, stack.n_rows, len(labels))
    est = estimator_named(estimator)
    frozen = data.frozen_columns(columns)
    try:
        fit = fit_stack(
            stack,
            labels,
            estimator=est,
            std=std,
            max_std_percent=max_std_percent,
            rtol=fit_rtol,
            frozen=frozen,
        )
    except RankDeficientError as exc:
        raise _rank_error(exc, data, columns, stack, fit_rtol) from exc
    if isinstance(stack, StreamedRows):
        stack = dataclasses.replace(stack, n_rows=fit.n_rows)
    held = None if judge is None else judge(stack, columns, ~frozen, fit.beta)
    for msg in conditioning_advice(fit, labels, what=_what(data)):
        warnings.warn(msg, DynidWarning, stacklevel=2)
    info = _record(data, columns, fit, stack, est.name, std, max_std_percent, rtol)
    if held is not None:
        errors = cross_validate(held.restricted(np.flatnonzero(fit.kept)))
        info = dataclasses.replace(info, heldout=errors.as_dict())
    return _model(robot, columns, fit, info, held)


def check_options(*, std: str, max_std_percent: float | None) -> None:
    """Raise :class:`OptionError` for an unknown ``std`` or a non-positive threshold."""
    if max_std_percent is not None and not max_std_percent > 0:
        raise OptionError(f"max_std_percent must be positive or None; got {max_std_percent}")
    checked_std(std)


def _what(data: Dataset) -> str:
    return "the configurations" if data.regressor_kind == "static" else "the trajectory"


def _rank_error(
    exc: RankDeficientError,
    data: Dataset,
    columns: ModelColumns,
    stack: RegressorStack | StreamedRows,
    rtol: float,
) -> RankDeficientError:
    """The estimator's rank error said for the data, with the data's hint."""
    needed = exc.needed if exc.needed is not None else len(columns.labels)
    what = "the base parameters" + "".join(f" and {t.name}" for t in columns.appended)
    cols = ", ".join(exc.dependent) or "none named"
    combos = "; ".join(exc.combinations) or cols
    rows = f"{stack.n_rows} rows" if stack.n_rows else "rows read in blocks"
    return RankDeficientError(
        f"{data.source} ({rows}) has rank {exc.rank} < {needed} needed for "
        f"{what} (rtol={rtol:g}), the model's structural rank; not excited by the data: "
        f"{combos}{columns.base.meaning(exc.combinations)}; nearly dependent columns: "
        f"{cols}; {data.hint}",
        rank=exc.rank,
        needed=needed,
        dependent=exc.dependent,
        combinations=exc.combinations,
    )


def _record(
    data: Dataset,
    columns: ModelColumns,
    fit: LeastSquaresFit,
    stack: RegressorStack | StreamedRows,
    estimator: str,
    std: StdMethod,
    max_std_percent: float | None,
    rtol: float | None,
) -> IdentificationInfo:
    """The model's record: the data's own part, then what was fitted and how."""
    labels, base = columns.labels, columns.base
    pruned = tuple(labels[k] for k in np.flatnonzero(~np.asarray(fit.kept)))
    if pruned:
        _log.info("pruned %d coefficient(s): %s", len(pruned), pruned)
    found = columns.appended_term("friction")
    friction = None
    if found is not None:
        term, sl = found
        friction = FrictionInfo(
            labels=labels[sl],
            std=tuple(float(x) for x in fit.std[sl]),
            kept=tuple(bool(x) for x in fit.kept[sl]),
            band=tuple(float(b) for b in getattr(term, "law_band", ())),
            law=str(getattr(term, "law", "classical")),
        )
    return dataclasses.replace(
        data.record(stack.n_rows),
        route=data.route,
        n_rows=stack.n_rows,
        dropped_rows=stack.dropped,
        pruned=pruned,
        max_std_percent=max_std_percent,
        std=std,
        estimator=estimator,
        rtol=rtol,
        rank_gap=base.gap,
        identifiability=dict(zip(base.std_labels, identifiability(base), strict=True)),
        friction=friction,
    )


def _model(
    robot: Robot,
    columns: ModelColumns,
    fit: LeastSquaresFit,
    info: IdentificationInfo,
    held: HeldOut | None,
) -> IdentifiedModel:
    """The identified model: the base parameters' fit, friction and the full fit."""
    r = columns.base.rank
    found = columns.appended_term("friction")
    friction = None
    if found is not None:
        term, sl = found
        as_array = getattr(term, "as_array", None)
        beta = np.asarray(fit.beta[sl])
        friction = beta.reshape(robot.n, 3) if as_array is None else as_array(beta)
    appended = bool(columns.appended)
    return IdentifiedModel(
        robot=robot,
        base=columns.base,
        fit=_split_fit(fit, r) if appended else fit,
        friction=friction,
        info=info,
        joint_fit=fit if appended else None,
        drive=columns.drive,
        holdout=held,
    )


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
    n_sel = int(cols.sum())
    return dataclasses.replace(
        fit,
        beta=put(fit.beta, 0.0),
        std=put(fit.std, 0.0),
        std_percent=put(fit.std_percent, np.nan),
        kept=put(fit.kept, False),
        covariance=cov,
        weakest=put(fit.weakest, 0.0) if np.size(fit.weakest) == n_sel else fit.weakest,
        effect_percent=put(fit.effect_percent, 0.0)
        if np.size(fit.effect_percent) == n_sel
        else fit.effect_percent,
    )
