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
4. **model**: the fit, the terms with their coefficients and the record of what was done, as an
   :class:`~dynid.identification.model.IdentifiedModel`.

A data set is anything with the :class:`Dataset` protocol: static data
(:class:`~dynid.identification.data.StaticDataset`) and prepared torque logs
(:class:`~dynid.identification.prepared_log.PreparedLog`). Its blocks come as an iterator so
that a long log can be read in pieces; they are concatenated here.
"""

from __future__ import annotations

import dataclasses
import logging
import warnings
from collections.abc import Hashable, Iterator
from contextlib import contextmanager
from contextvars import ContextVar
from typing import Any

import numpy as np
from numpy.typing import NDArray

from .._checks import caller_level
from .._memo import scoped, value_key
from ..exceptions import DynidWarning, OptionError, RankDeficientError, ShapeError
from ..model.drive import Drive
from ..model.robot import Robot
from ..regressors.base import BaseParameters, base_parameters, identifiability
from ..regressors.terms import ModelTerm, drive_terms
from .dataset import Dataset, ModelColumns, RegressorBlock, RegressorKind
from .engine import HeldRows, Rows, fit_rows
from .estimators import Estimator, EstimatorName, estimator_named
from .fold_offsets import FOLD_RTOL, fold_fits
from .holdout import HeldOut, cross_validate
from .info import IdentificationInfo, Route
from .least_squares import (
    LeastSquaresFit,
    StdMethod,
    checked_std,
    conditioning_advice,
    loose_coefficients,
)
from .model import IdentifiedModel, IdentifiedTerm
from .serial import Serial
from .stacking import (
    DEFAULT_FIT_RTOL,
    Judge,
    RegressorStack,
    StreamedRows,
    informative_blocks,
    selected_columns,
    stack_dataset,
)
from .streamed import BlockRows
from .structural import StructuralRank, structural_rank

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
    "model_advice",
    "model_loose",
    "model_columns",
    "shared_bases",
    "stack_dataset",
]

_log = logging.getLogger(__name__)


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
    OptionError
        Two terms of the same name.
    """
    if terms is None:
        terms = drive_terms(drive, robot.n, friction=data.moving)
    names = [t.name for t in terms]
    twice = sorted({x for x in names if names.count(x) > 1})
    if twice:
        raise OptionError(f"model terms named {twice} twice; each term needs its own name")
    p = 10 * robot.n + sum(len(t.labels) for t in terms if t.in_base)
    if base is None:
        base = _structural_base(robot, data.regressor_kind, rtol, terms)
    elif base.n_std != p:
        raise ShapeError(
            f"base was built for {base.n_std} standard parameters; robot {robot.name!r} has {p}"
        )
    return ModelColumns(base=base, terms=tuple(terms), drive=drive)


#: The base parameters :func:`model_columns` computed while :func:`shared_bases` is
#: active: key -> (the robot, the base parameters).
_BASES: ContextVar[dict[Hashable, tuple[Robot, BaseParameters]] | None] = ContextVar(
    "_BASES", default=None
)


@contextmanager
def shared_bases() -> Iterator[None]:
    """Within the block, the structural base parameters of one robot, regressor kind, rank
    tolerance and terms in the base are computed once by :func:`model_columns` and read
    back by every later call (the candidate structures' regressors differ in their
    friction, not in their base: 13 regressors of a Panda log, 2 bases); the same
    numbers, each call its own arrays. Nested blocks share the outer one's; the bases are
    dropped at its end."""
    with scoped(_BASES, dict):
        yield


def _structural_base(
    robot: Robot, kind: RegressorKind, rtol: float | None, terms: tuple[ModelTerm, ...]
) -> BaseParameters:
    """:func:`~dynid.regressors.base.base_parameters` of ``robot`` (random states, seeded),
    read from :func:`shared_bases` when it holds them."""
    held = _BASES.get()
    if held is None:
        return base_parameters(robot, kind=kind, rtol=rtol, terms=terms)
    try:  # what the base depends on: the robot (immutable), kind, rtol, terms in the base
        extra = tuple((type(t).__qualname__, value_key(t)) for t in terms if t.in_base)
    except TypeError:  # a term that does not hash: computed each time
        return base_parameters(robot, kind=kind, rtol=rtol, terms=terms)
    key = (id(robot), kind, rtol, extra)
    if key not in held or held[key][0] is not robot:
        held[key] = (robot, base_parameters(robot, kind=kind, rtol=rtol, terms=terms))
    b = held[key][1]
    return dataclasses.replace(  # arrays of its own: a caller cannot change the held ones
        b, independent=b.independent.copy(), dependent=b.dependent.copy(), K_d=b.K_d.copy()
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
    serial: Serial | None = None,
) -> LeastSquaresFit:
    """Fit the stacked rows with an estimator; ``frozen`` columns are left out (0, not kept);
    ``serial`` the rows' time structure (``std="hac"``; the data set's ``serial``).

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
    return _fitted(stack, labels, est, std, max_std_percent, rtol, frozen, serial=serial)[0]


def _fitted(
    stack: RegressorStack | StreamedRows,
    labels: tuple[str, ...],
    est: Estimator,
    std: StdMethod,
    max_std_percent: float | None,
    rtol: float,
    frozen: NDArray[np.bool_] | None,
    fold_labels: NDArray[np.intp] | None = None,
    serial: Serial | None = None,
) -> tuple[LeastSquaresFit, RegressorStack | StreamedRows]:
    """:func:`fit_stack`, and the stack with what the fit's pass learnt of rows read in
    blocks (their count; the normal equations of the ``fold_labels`` when the estimator
    does not weigh)."""
    cols = np.ones(len(labels), dtype=bool) if frozen is None else ~np.asarray(frozen, bool)
    kept_labels = tuple(lab for lab, c in zip(labels, cols, strict=True) if c)
    rows = _rows(stack, cols, est, None if est.weighted else fold_labels, serial)
    fit = fit_rows(
        rows, est, rtol=rtol, std=std, max_std_percent=max_std_percent, labels=kept_labels
    )
    if isinstance(rows, BlockRows):
        assert isinstance(stack, StreamedRows)
        normals = rows.factors.normals
        stack = dataclasses.replace(stack, n_rows=fit.n_rows, normals=normals)
    return (fit if cols.all() else _expanded(fit, cols)), stack


def _rows(
    stack: RegressorStack | StreamedRows,
    cols: NDArray[np.bool_],
    est: Estimator,
    fold_labels: NDArray[np.intp] | None = None,
    serial: Serial | None = None,
) -> Rows:
    """The stack's rows over the columns ``cols`` (c,), as the engine takes them."""
    if isinstance(stack, StreamedRows):
        source = selected_columns(stack.source, cols)
        return BlockRows(
            source, by_group=est.weighted, per_row=est.per_row, labels=fold_labels, serial=serial
        )
    W, rows = stack.W, stack.used_rows
    grams = None if stack.grams is None else stack.grams[stack.kept]
    if not cols.all():
        W = W[:, cols]
        rows = rows.copy()
        rows[:, 2] = 0
        grams = None if grams is None else grams[:, cols][:, :, cols]
    gram = None if grams is None else grams.sum(axis=0)
    if serial is not None and not stack.kept.all():
        serial = None  # blocks dropped: the rows' time structure no longer holds (static)
    return HeldRows(W, stack.y, stack.groups, rows, gram, serial)


def identify(
    robot: Robot,
    data: Dataset,
    *,
    drive: Drive | None = None,
    terms: tuple[ModelTerm, ...] | None = None,
    base: BaseParameters | None = None,
    estimator: EstimatorName | Estimator = "ols",
    std: StdMethod = "hac",
    max_std_percent: float | None = None,
    rtol: float | None = None,
    judge: Judge | None = None,
    fold_labels: NDArray[np.intp] | None = None,
    advise: bool = True,
) -> IdentifiedModel:
    """Identify the base parameters (and the appended terms: friction) from a data set.

    Parameters
    ----------
    robot : Robot
        Kinematics and gravity the data belong to; its inertial parameters are not used.
    data : Dataset
        Static data (:class:`~dynid.identification.data.StaticDataset`) or a prepared
        torque log (:func:`~dynid.identification.prepared_log.prepare_torque_log`).
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
    std : {"hac", "robust", "classical"}
        Standard deviations from the heteroskedasticity-and-autocorrelation-consistent
        covariance over the data's samples and pieces (default, ``data.serial``,
        :mod:`dynid.identification.serial`: a filtered log's residual is correlated over
        several samples; HC1 for data without a time structure), the
        heteroscedasticity-consistent (HC1) one, or ``sigma^2 (W^T W)^-1`` (Gaz et al.
        2019; understates a filtered log's spread 2 to 3 times).
    max_std_percent : float, optional
        Remove coefficients with a larger relative standard deviation and re-fit once.
    rtol : float, optional
        Rank tolerance of the base parameters (default: at the first clear gap of the
        singular values) and of the fit (default :data:`DEFAULT_FIT_RTOL`).
    judge : callable, optional
        Held-out judgement (:data:`Judge`): its folds are kept (``holdout``) and their
        errors recorded (``heldout``).
    fold_labels : ndarray of int, shape (m,), optional
        The judge's label of every row (its folds), in block order: on rows read in blocks
        with an estimator that does not weigh, the fit's pass gathers their normal
        equations (``StreamedRows.normals``, handed to the judge) so that the judgement
        needs no pass of its own.
    advise : bool
        Warn the fit's conditioning advice (default); False: a caller that fits several
        models and keeps one warns the advice of the one it keeps (:func:`model_advice`),
        so that no warning names the coefficients of a fit it did not keep.

    Returns
    -------
    IdentifiedModel
        ``fit`` over the ``r`` base parameters (global statistics of the whole fit);
        ``terms`` every model term with its coefficients; ``joint_fit`` over every column
        when terms are appended (friction).

    Raises
    ------
    OptionError
        ``max_std_percent`` not positive, or ``std`` not one of ``"hac"``, ``"robust"``,
        ``"classical"``.
    ShapeError, DataError
        Data of another robot, or ``base`` of another size.
    RankDeficientError
        The data do not excite every column; ``rank``, ``needed`` and ``dependent`` say
        how and the message adds the data's hint.

    Warns
    -----
    DynidWarning
        Dropped blocks holding data; with ``advise``, an ill-conditioned regressor or
        coefficients above 1000 % std (:func:`~dynid.identification.least_squares.
        conditioning_advice`).
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
        fit, stack = _fitted(
            stack, labels, est, std, max_std_percent, fit_rtol, frozen, fold_labels, data.serial
        )
    except RankDeficientError as exc:
        structural = None
        if data.regressor_kind == "torque":
            structural = structural_rank(robot, columns, ~frozen)
        raise _rank_error(exc, data, columns, stack, fit_rtol, structural) from exc
    held = None if judge is None else judge(stack, columns, ~frozen, fit.beta)
    for msg in conditioning_advice(fit, labels, what=_what(data)) if advise else ():
        warnings.warn(msg, DynidWarning, stacklevel=caller_level())
    info = _record(data, columns, fit, stack, est.name, std, max_std_percent, rtol)
    if held is not None:
        kept = np.flatnonzero(fit.kept)
        sub = held.restricted(kept)  # an offset a fold cannot tell apart left out there
        xs = fold_fits(sub, FOLD_RTOL, labels, kept)
        errors = cross_validate(sub, fit=np.asarray(fit.beta)[kept], xs=xs)
        info = dataclasses.replace(info, heldout=errors.as_dict())
    return _model(robot, columns, fit, info, held)


def check_options(*, std: str, max_std_percent: float | None) -> None:
    """Raise :class:`OptionError` for an unknown ``std`` or a non-positive threshold."""
    if max_std_percent is not None and not max_std_percent > 0:
        raise OptionError(f"max_std_percent must be positive or None; got {max_std_percent}")
    checked_std(std)


def model_advice(model: IdentifiedModel, what: str = "the trajectory") -> list[str]:
    """The conditioning advice of ``model``'s fit over every column
    (:func:`~dynid.identification.least_squares.conditioning_advice`, the base parameters'
    labels then the appended terms'), as :func:`identify` warns it; ``what`` names the
    data ("the trajectory", "the configurations")."""
    fit = model.joint_fit if model.joint_fit is not None else model.fit
    labels = model.base.labels + tuple(lab for t in model.appended for lab in t.labels)
    return conditioning_advice(fit, labels, what=what)


def model_loose(model: IdentifiedModel) -> list[tuple[str, float]]:
    """The kept coefficients of ``model``'s fit over every column whose relative standard
    deviation is above 1000 % (:func:`~dynid.identification.least_squares.
    loose_coefficients`), each label and its deviation [%], as :func:`model_advice` warns
    them."""
    fit = model.joint_fit if model.joint_fit is not None else model.fit
    labels = model.base.labels + tuple(lab for t in model.appended for lab in t.labels)
    return loose_coefficients(fit, labels)


def _what(data: Dataset) -> str:
    return "the configurations" if data.regressor_kind == "static" else "the trajectory"


def _rank_error(
    exc: RankDeficientError,
    data: Dataset,
    columns: ModelColumns,
    stack: RegressorStack | StreamedRows,
    rtol: float,
    structural: StructuralRank | None = None,
) -> RankDeficientError:
    """The estimator's rank error said for the data, with the data's hint; combinations
    that vanish at every state (``structural``) are said to be the model's, with no hint
    of more excitation when they are all the data lack."""
    needed = exc.needed if exc.needed is not None else len(columns.labels)
    what = "the base parameters" + "".join(f" and {t.name}" for t in columns.appended)
    cols = ", ".join(exc.dependent) or "none named"
    combos = "; ".join(exc.combinations) or cols
    rows = f"{stack.n_rows} rows" if stack.n_rows else "rows read in blocks"
    head = (
        f"{data.source} ({rows}) has rank {exc.rank} < {needed} needed for {what} (rtol={rtol:g})"
    )
    rank = needed if exc.rank is None else exc.rank
    said: tuple[str, ...] = ()
    redundant = exc.redundant
    if structural is not None and structural.rank < structural.needed:
        whole = needed - rank <= structural.needed - structural.rank  # all the data lack
        said = exc.combinations if whole and exc.combinations else structural.combinations
        redundant = exc.redundant if whole else structural.redundant
        why = (
            f"{head}: structurally not identifiable, the model's columns are dependent at "
            f"every motion (rank {structural.rank} of {structural.needed} at random states), "
            f"no trajectory separates {'; '.join(said)}{columns.base.meaning(said)}; leave "
            "one coefficient of each combination out"
        )
        if not whole:
            why += (
                f"; and not excited by the data besides: {combos}"
                f"{columns.base.meaning(exc.combinations)}; nearly dependent columns: "
                f"{cols}; {data.hint}"
            )
    else:
        why = (
            f"{head}, the model's structural rank; not excited by the data: "
            f"{combos}{columns.base.meaning(exc.combinations)}; nearly dependent columns: "
            f"{cols}; {data.hint}"
        )
    return RankDeficientError(
        why,
        rank=exc.rank,
        needed=needed,
        dependent=exc.dependent,
        combinations=exc.combinations,
        redundant=redundant,
        structural=said,
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
    )


def _model(
    robot: Robot,
    columns: ModelColumns,
    fit: LeastSquaresFit,
    info: IdentificationInfo,
    held: HeldOut | None,
) -> IdentifiedModel:
    """The identified model: the base parameters' fit, the terms with their coefficients
    (those in the base derived by the model from its fit) and the full fit."""
    r = columns.base.rank
    terms, c = {}, r
    for t in columns.terms:
        k = len(t.labels)
        if t.in_base:  # the model derives its values from the fit
            terms[t.name] = IdentifiedTerm(t, np.zeros(k), np.zeros(k), np.zeros(k, dtype=bool))
            continue
        terms[t.name] = IdentifiedTerm(
            t, fit.beta[c : c + k], fit.std[c : c + k], fit.kept[c : c + k]
        )
        c += k
    appended = bool(columns.appended)
    return IdentifiedModel(
        robot=robot,
        base=columns.base,
        fit=_split_fit(fit, r) if appended else fit,
        terms=terms,
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
