"""Collision detection on log files: the entry point of ``dynid observe``, with every policy
the command applies, so that the Python API behaves as the command does.

* The model: an ``identification.json`` (``--model``; its own friction, drive and rotor
  inertias, and the covariance of its base parameters) or a robot (``--params``: a
  ``feasible.json`` with the drive and the friction identified with it, or a URDF/TOML
  robot); ``--friction friction.json`` replaces the friction (the law ``dynid friction``
  chose, with its standstill band).
* Logs are read strictly with the model's joint count (extra columns ignored, with a
  warning), through the column map the model's data were read with when none is given, and
  brought to the joint side through the model's drive. A log is cut at its gaps (steps
  longer than ``max_gap``, default :func:`~dynid.identification.log.default_max_gap`, as
  ``identify`` cuts) and after rows dropped for NaN or inf (``drop_invalid``; refused
  otherwise, the row named): the observer starts again on each piece and no event spans a
  cut (one warning names the file and the times); a position that jumps more than its
  velocity explains over a regular time step (samples lost without a gap in the stamps, an
  encoder glitch) cuts the log there too, with a warning (:mod:`dynid.observer.pieces`).
  Several logs are checked together: one in other units than the others is refused, one
  far outside the joint limits warned about (:mod:`dynid.workflows.recordings`).
* ``calibrate``: the residuals of every (collision-free) log give the thresholds; with an
  identified model that has a covariance, they also grow with the model's uncertainty
  (``uncertainty``, default on); the standstill margin of the model's friction (its
  Coulomb level where the law's Coulomb term is off, through the observer's lag) is left
  out of the residuals they read and added to the thresholds (``standstill``, default on;
  :mod:`dynid.observer.detection`).
* Otherwise the thresholds (``thresholds.json``) fix the observer (gains, discretisation,
  rule) and the detection; the true external torques ``tau_ext1..n`` that
  ``dynid simulate --contact`` writes beside a log are kept for the figure.
"""

from __future__ import annotations

import dataclasses
import warnings
from collections.abc import Callable, Iterator, Mapping
from dataclasses import dataclass
from pathlib import Path

import numpy as np
from numpy.typing import NDArray

from ..exceptions import DataError, DynidWarning, OptionError
from ..exceptions import in_file as about_file
from ..friction.model import FrictionModel, FrictionSum
from ..identification.log import (
    DEFAULT_CUTOFF_HZ,
    TorqueLog,
    default_max_gap,
    joint_side_log,
)
from ..identification.pieces import unwrapped, wrappable
from ..io.columns import load_joint_columns
from ..io.feasible import load_feasible_drive, load_feasible_linear_friction
from ..io.friction_json import load_friction_json
from ..io.model_json import load_model_json
from ..io.observer_files import load_thresholds
from ..io.robot_file import load_robot
from ..observer.detection import (
    Thresholds,
    calibrate,
    detect,
    residual_std_blocks,
    standstill_blocks,
)
from ..observer.model import ObserverModel, from_identified, from_robot
from ..observer.pieces import PositionJump, pieces, position_jumps
from ..observer.residual import DEFAULT_GAIN, MomentumObserver, ObserverOptions
from ..observer.results import LogObservation, ObserveResult
from ..observer.wrench import external_wrench
from ..signals import edge_seconds, filtered_derivative
from .data_files import (
    ColumnSpec,
    column_map,
    data_files,
    in_file,
    read_torque_log,
    recorded_columns,
)
from .recordings import Recorded, check_limits, check_units

__all__ = [
    "LogObservation",
    "ObserveOptions",
    "ObserveResult",
    "load_observer_model",
    "observe_files",
]


@dataclass(frozen=True, slots=True)
class ObserveOptions:
    """What ``dynid observe`` was asked (module docstring).

    Attributes
    ----------
    data : tuple of Path
        Torque logs (``.csv``/``.npz``), or other tools' files read through ``columns``; a
        folder stands for its ``.csv`` and ``.npz`` files in name order.
    model : Path, optional
        ``identification.json`` (exactly one of ``model`` and ``params``).
    params : str or Path, optional
        A robot: ``feasible.json``, a ``.urdf``/``.toml`` file or a built-in name.
    friction : Path, optional
        ``friction.json`` replacing the model's friction.
    calibrate : bool
        Compute thresholds from ``data`` (collision-free logs).
    thresholds : Path, optional
        ``thresholds.json`` to detect with (required unless ``calibrate``).
    frame : str, optional
        Also estimate the external wrench at this frame.
    gain : float or tuple of float
        ``K_O`` [1/s] when calibrating (else the thresholds' own).
    discretisation, rule : str
        Of the observer when calibrating (:class:`~dynid.observer.residual.ObserverOptions`).
    margin, quantile, collision_factor, k_sigma : float
        The calibration rule (:func:`~dynid.observer.detection.calibrate`).
    uncertainty : bool
        Let the thresholds grow with the model's uncertainty when the model has a
        covariance.
    standstill : bool
        When calibrating: add the standstill margin of the model's friction to the
        thresholds (the thresholds keep the choice).
    merge_s : float
        Events closer than this [s] are one.
    columns : (str or None, str or None)
        ``--columns``/``--units``; default: those the model's data were read with.
    drop_invalid : bool
        Drop rows with NaN/inf or a repeated timestamp instead of failing (the observer
        starts again after rows dropped for NaN/inf).
    max_gap : float, optional
        Longest step [s] the observer integrates over; the log is cut at longer ones.
    base, tip : str, optional
        The chain of a ``params`` URDF with several leaves (its root and only leaf by
        default).
    keep_series : bool
        When calibrating: keep every log's residual (and its std and margin) in the
        result, for figures. False: only the calibration's running statistics, a block of
        samples at a time (bounded memory on a long log); the result's logs then hold no
        series. Detecting always keeps them (events, ``residuals.csv``).
    """

    data: tuple[Path, ...]
    model: Path | None = None
    params: str | Path | None = None
    friction: Path | None = None
    calibrate: bool = False
    thresholds: Path | None = None
    frame: str | None = None
    gain: float | tuple[float, ...] = DEFAULT_GAIN
    discretisation: str = "exact"
    rule: str = "trapezoid"
    margin: float = 1.5
    quantile: float = 1.0
    collision_factor: float = 2.0
    k_sigma: float = 3.0
    uncertainty: bool = True
    standstill: bool = True
    merge_s: float = 0.05
    columns: ColumnSpec = (None, None)
    drop_invalid: bool = False
    max_gap: float | None = None
    base: str | None = None
    tip: str | None = None
    keep_series: bool = True


def load_observer_model(
    model: Path | None,
    params: str | Path | None,
    friction: Path | None = None,
    *,
    base: str | None = None,
    tip: str | None = None,
) -> tuple[ObserverModel, Mapping[str, str | None] | None]:
    """The observer model of ``--model`` or ``--params`` (and ``--friction``), with the
    column map the model's data were read with (None for a robot); ``base`` and ``tip``
    choose the chain of a ``params`` URDF.

    Raises
    ------
    OptionError
        Neither or both of ``model`` and ``params``; ``base`` or ``tip`` with another
        model than a URDF.
    DataError
        A file that is not what it should be (named).
    """
    if (model is None) == (params is None):
        raise OptionError("give one of --model identification.json and --params ROBOT")
    if (base is not None or tip is not None) and not str(params).lower().endswith(".urdf"):
        given = "--model" if model is not None else f"--params {params}"
        raise OptionError(
            f"--base/--tip choose the chain of a --params URDF; {given} holds its own chain"
        )
    fr: FrictionModel | FrictionSum | None | str
    fr = "model" if friction is None else load_friction_json(friction)
    if model is not None:
        ident = load_model_json(model)
        return from_identified(ident, fr), ident.info.column_map
    spec = str(params)
    robot = load_robot(spec, base=base, tip=tip, what="--params")
    drive = None
    if spec.lower().endswith(".json"):
        drive = load_feasible_drive(spec)
        if friction is None:
            lin = load_feasible_linear_friction(spec)
            fr = "robot" if lin is None else lin
    return from_robot(robot, friction="robot" if fr == "model" else fr, drive=drive), None


#: The calibration's options, which a thresholds file fixes (with their defaults).
_CALIBRATION_FIELDS = (
    "gain",
    "discretisation",
    "rule",
    "margin",
    "quantile",
    "collision_factor",
    "k_sigma",
    "uncertainty",
    "standstill",
)


def _refuse_unused(opts: ObserveOptions) -> None:
    """Options that do not apply: the calibration's with ``thresholds`` (the file fixes
    them), ``frame`` and ``merge_s`` when calibrating (no wrench or event is computed)."""
    default = ObserveOptions(data=())
    if opts.thresholds is not None:
        for name in _CALIBRATION_FIELDS:
            if getattr(opts, name) != getattr(default, name):
                raise OptionError(
                    f"is a calibration option; {opts.thresholds.name} fixes it (calibrate "
                    "again to change it)",
                    field=name,
                )
    elif opts.frame is not None:
        raise OptionError(
            "applies when detecting (the wrench of residuals.csv); calibrating writes "
            "thresholds only",
            field="frame",
        )
    elif opts.merge_s != default.merge_s:
        raise OptionError(
            "applies when detecting (joins events); calibrating finds none", field="merge_s"
        )


def _observer_options(opts: ObserveOptions, thresholds: Thresholds | None) -> ObserverOptions:
    if thresholds is not None:
        return thresholds.options
    return ObserverOptions(opts.gain, opts.discretisation, opts.rule)  # type: ignore[arg-type]


def observe_files(opts: ObserveOptions) -> ObserveResult:
    """Calibrate thresholds on collision-free logs, or detect contacts in logs (module
    docstring).

    Returns
    -------
    ObserveResult

    Raises
    ------
    OptionError
        No log, neither or both of ``calibrate`` and ``thresholds``, no model or two.
    DataError
        A bad file (named), thresholds of another joint count.
    """
    if not opts.data:
        raise OptionError("give one or more --data logs")
    if opts.calibrate == (opts.thresholds is not None):
        raise OptionError("give --calibrate (collision-free logs) or --thresholds thresholds.json")
    _refuse_unused(opts)
    model, recorded = load_observer_model(
        opts.model, opts.params, opts.friction, base=opts.base, tip=opts.tip
    )
    given = None if opts.thresholds is None else load_thresholds(opts.thresholds)
    if given is not None and given.n != model.n:
        raise OptionError(
            f"{opts.thresholds}: thresholds for {given.n} joints; the model has {model.n}"
        )
    options = _observer_options(opts, given)
    wants_std = (
        opts.uncertainty and model.covariance is not None
        if given is None
        else given.uses_uncertainty and model.covariance is not None
    )
    wants_margin = opts.standstill if given is None else given.standstill
    columns = recorded_columns(recorded, *opts.columns)  # (names, units), said once
    read = _read_logs(data_files(opts.data), model, columns, opts)
    if given is None:
        return _calibrated(
            read, model, columns[0] is not None, opts, options, wants_std, wants_margin
        )
    logs = [
        _observe_log(p, log, model, columns[0] is not None, opts, options, wants_std, wants_margin)
        for p, log in zip(read.paths, read.logs, strict=True)
    ]
    found = tuple(
        dataclasses.replace(
            x,
            events=detect(
                x.t,
                x.series,
                given,
                std=x.std,
                standstill=x.standstill,
                merge_s=opts.merge_s,
                restarts=x.restarts,
            ),
        )
        for x in logs
    )
    return ObserveResult(model, given, found)


def _read_logs(
    paths: list[Path],
    model: ObserverModel,
    columns: tuple[str | None, str | None],
    opts: ObserveOptions,
) -> Recorded:
    """The logs ``paths`` read strictly for the model; a log in other units than the others
    refused and one far outside the joint limits warned about, each naming the file
    (:mod:`dynid.workflows.recordings`)."""
    cmap = column_map(*columns)
    logs = [
        read_torque_log(p, model.n, columns=cmap, drop_invalid=opts.drop_invalid, owner="the model")
        for p in map(Path, paths)
    ]
    read = Recorded(tuple(logs), tuple(map(Path, paths)))
    check_limits(read, model.robot, model.drive)
    check_units(read)
    return read


def _calibrated(
    read: Recorded,
    model: ObserverModel,
    mapped: bool,
    opts: ObserveOptions,
    options: ObserverOptions,
    wants_std: bool,
    wants_margin: bool,
) -> ObserveResult:
    """The thresholds of the collision-free logs ``read``: their residuals a block at a
    time into :func:`~dynid.observer.detection.calibrate` (running maxima), each log's
    series kept only with ``opts.keep_series``."""
    logs: list[LogObservation] = []

    def blocks() -> Iterator[_Block]:
        for path, log in zip(read.paths, read.logs, strict=True):
            prep = _prepared(Path(path), log, model, opts)
            keep = _Series.new(prep, model.n, wants_std, wants_margin) if opts.keep_series else None
            peak = np.zeros(model.n)
            for blk in _blocks(prep, model, options, wants_std, wants_margin):
                if blk.margin is not None:
                    np.maximum(peak, blk.margin.max(axis=0), out=peak)
                if keep is not None:
                    keep.put(blk)
                yield blk
            logs.append(_observation(prep, model, mapped, opts, keep, peak))

    # calibrate reads a block's residual, then its margin and std: these two come from the
    # block the residual was last read from (one block held; itertools.tee would keep up
    # to 57 blocks, its links' size)
    current: list[_Block] = []

    def residuals() -> Iterator[NDArray[np.float64]]:
        for x in blocks():
            current[:] = [x]
            yield x.r

    def beside(what: Callable[[_Block], NDArray[np.float64]]) -> Iterator[NDArray[np.float64]]:
        while current:
            yield what(current[0])

    std = beside(_std) if wants_std else None
    margins = beside(lambda x: _margin(x, model.n)) if wants_margin else None
    r = residuals()
    th = calibrate(
        r,
        options,
        std=std,
        standstill=margins,
        margin=opts.margin,
        quantile=opts.quantile,
        collision_factor=opts.collision_factor,
        k_sigma=opts.k_sigma,
    )
    return ObserveResult(model, th, tuple(logs))


def _std(x: _Block) -> NDArray[np.float64]:
    assert x.std is not None
    return x.std


def _margin(x: _Block, n: int) -> NDArray[np.float64]:
    return np.zeros((x.r.shape[0], n)) if x.margin is None else x.margin


@dataclass(frozen=True, slots=True)
class _Prepared:
    """A log brought to the joints, with the velocities and the spans the observer runs
    on (:func:`_prepared`)."""

    path: Path
    log: TorqueLog
    dq: NDArray[np.float64]
    spans: list[tuple[int, int]]


@dataclass(frozen=True, slots=True)
class _Block:
    """The residual of samples ``[a, a + len(r))`` of a log, their std and margin."""

    a: int
    r: NDArray[np.float64]
    std: NDArray[np.float64] | None
    margin: NDArray[np.float64] | None


@dataclass(frozen=True, slots=True)
class _Series:
    """Full-length series of a log filled block by block (NaN where not observed)."""

    r: NDArray[np.float64]
    std: NDArray[np.float64] | None
    margin: NDArray[np.float64] | None

    @staticmethod
    def new(prep: _Prepared, n: int, wants_std: bool, wants_margin: bool) -> _Series:
        N = prep.log.t.shape[0]
        r = np.full((N, n), np.nan)
        return _Series(
            r,
            np.full_like(r, np.nan) if wants_std else None,
            np.zeros(r.shape) if wants_margin else None,  # untouched where it stays 0
        )

    def put(self, blk: _Block) -> None:
        k = slice(blk.a, blk.a + blk.r.shape[0])
        self.r[k] = blk.r
        if self.std is not None and blk.std is not None:
            self.std[k] = blk.std
        if self.margin is not None and blk.margin is not None:
            self.margin[k] = blk.margin


def _observe_log(
    path: Path,
    log: TorqueLog,
    model: ObserverModel,
    mapped: bool,
    opts: ObserveOptions,
    options: ObserverOptions,
    wants_std: bool,
    wants_margin: bool = False,
) -> LogObservation:
    """The residual (and its std, the wrench, the stored true torques) of one log, as
    read (``mapped``: through a column map)."""
    prep = _prepared(Path(path), log, model, opts)
    keep = _Series.new(prep, model.n, wants_std, wants_margin)
    peak = np.zeros(model.n)
    for blk in _blocks(prep, model, options, wants_std, wants_margin):
        keep.put(blk)
        if blk.margin is not None:
            np.maximum(peak, blk.margin.max(axis=0), out=peak)
    return _observation(prep, model, mapped, opts, keep, peak)


def _prepared(path: Path, log: TorqueLog, model: ObserverModel, opts: ObserveOptions) -> _Prepared:
    """The log at the joints, unwrapped, cut at its gaps and jumps, with the velocities
    and the spans the observer runs on (warnings name the file)."""
    log = joint_side_log(log, model.drive)
    log, turned = unwrapped(log, wrappable(model.robot))  # joints whose limits span a turn
    if turned:  # M(q) is periodic; velocities derived across a wrap are not
        warnings.warn(
            f"{path.name}: joint(s) {', '.join(str(j + 1) for j in turned)} recorded wrapped "
            "into [-pi, pi] (jumps of a whole turn): unwrapped",
            DynidWarning,
            stacklevel=4,
        )
    starts = _pieces(path, log, opts)
    dq = _piece_velocities(log, starts)  # of a log of positions: from the unwrapped ones
    cut = _cut_at_jumps(path, log, dq, starts)
    if cut != starts and log.dq_derived:  # derived again, never across a jump
        dq = _piece_velocities(log, cut)
    return _Prepared(path, log, dq, _observed_spans(path, log, cut))


def _blocks(
    prep: _Prepared,
    model: ObserverModel,
    options: ObserverOptions,
    wants_std: bool,
    wants_margin: bool,
) -> Iterator[_Block]:
    """The residual of every observed span, :data:`_OBSERVE_BLOCK` samples at a time (one
    observer per piece, its state carried from block to block), with the std and the
    standstill margin of the same samples (errors name the file)."""
    t, q, tau, dq = prep.log.t, prep.log.q, prep.log.tau, prep.dq
    with about_file(prep.path.name):
        for a, b in prep.spans:
            obs = MomentumObserver(model, options)
            stds = _rechunked(
                residual_std_blocks(model, t[a:b], q[a:b], dq[a:b], options)
                if wants_std
                else iter(()),
                _OBSERVE_BLOCK,
            )
            margins = (
                standstill_blocks(model, t[a:b], dq[a:b], options, _OBSERVE_BLOCK)
                if wants_margin
                else iter(())
            )
            pending = next(margins, None)
            for c in range(a, b, _OBSERVE_BLOCK):
                d = min(c + _OBSERVE_BLOCK, b)
                m = None
                if pending is not None and pending[0] == c - a:
                    m, pending = pending[1], next(margins, None)
                yield _Block(
                    c,
                    obs.run(t[c:d], q[c:d], dq[c:d], tau[c:d]),
                    next(stds) if wants_std else None,
                    m,
                )


def _rechunked(
    blocks: Iterator[tuple[int, NDArray[np.float64]]], size: int
) -> Iterator[NDArray[np.float64]]:
    """Consecutive blocks ``(first sample, array)`` cut again into arrays of ``size``
    samples (the last shorter): the std's blocks as the observer's."""
    pending: list[NDArray[np.float64]] = []
    have = 0
    for _, x in blocks:
        pending.append(x)
        have += x.shape[0]
        while have >= size:
            cat = np.concatenate(pending)
            yield cat[:size]
            pending, have = [cat[size:]], cat.shape[0] - size
    if have:
        yield np.concatenate(pending)


def _observation(
    prep: _Prepared,
    model: ObserverModel,
    mapped: bool,
    opts: ObserveOptions,
    keep: _Series | None,
    peak: NDArray[np.float64],
) -> LogObservation:
    """A log's observation from its series (None: not kept) and its margin's peak."""
    path, log = prep.path, prep.log

    def run() -> LogObservation:
        wrench = None
        if opts.frame is not None and keep is not None:
            wrench = external_wrench(model.robot, log.q, keep.r, opts.frame)
        ext = None
        if keep is not None and path.suffix.lower() in (".csv", ".npz") and not mapped:
            ext = load_joint_columns(path, "tau_ext", model.n)
            if ext is not None and ext.shape[0] != log.t.shape[0]:
                ext = None  # rows were dropped: not aligned with the log
        return LogObservation(
            path,
            log.t,
            None if keep is None else keep.r,
            None if keep is None else keep.std,
            [],
            wrench,
            ext,
            None if keep is None else keep.margin,
            tuple(a for a, _ in prep.spans),
            peak,
        )

    return in_file(path, run)


#: Samples the observer runs on at a time (its state carried from block to block).
_OBSERVE_BLOCK = 1 << 16


def _piece_velocities(log: TorqueLog, starts: list[int]) -> NDArray[np.float64]:
    """The velocities the observer runs on: the log's, or, for a log of positions only,
    derived from the positions of each piece on its own (never across a gap)."""
    if not log.dq_derived:
        return np.asarray(log.dq)
    dq = np.array(log.dq)
    for a, b in zip(starts, [*starts[1:], log.t.shape[0]], strict=True):
        try:
            dq[a:b] = filtered_derivative(log.t[a:b], log.q[a:b], DEFAULT_CUTOFF_HZ)
        except DataError:  # too short to filter: its span is not observed
            dq[a:b] = np.nan
    return dq


def _observed_spans(path: Path, log: TorqueLog, starts: list[int]) -> list[tuple[int, int]]:
    """The samples ``[a, b)`` the observer runs on: every piece; for a log of positions
    only, each piece without the first and last ``2 / cut-off`` seconds, where the derived
    velocities carry the low-pass's transient (a note says so; their residual is NaN)."""
    ends = [*starts[1:], log.t.shape[0]]
    if not log.dq_derived:
        return list(zip(starts, ends, strict=True))
    edge = edge_seconds(DEFAULT_CUTOFF_HZ)
    spans = []
    for a, b in zip(starts, ends, strict=True):
        t = log.t[a:b]
        inside = np.flatnonzero((t >= t[0] + edge) & (t <= t[-1] - edge))
        if inside.size > 1:
            spans.append((a + int(inside[0]), a + int(inside[-1]) + 1))
    warnings.warn(
        f"{path.name}: velocities derived from the positions of each piece: the first and "
        f"last {edge:g} s of each piece (the low-pass's transient) are not observed (NaN "
        "residuals)" + ("" if spans else "; no piece is long enough: nothing is observed"),
        DynidWarning,
        stacklevel=4,
    )
    return spans


def _pieces(path: Path, log: TorqueLog, opts: ObserveOptions) -> list[int]:
    """First sample of each piece the observer runs on (module docstring), with a
    warning of the cuts (file and times)."""
    c = log.cleaning
    dt = np.diff(log.t)
    limit = opts.max_gap
    if limit is None:
        limit = default_max_gap(float(np.median(dt)) if dt.size else 1.0)
    starts = [int(k) for k in pieces(log.t, limit, c.invalid_after)]
    if len(starts) > 1:
        at = ", ".join(f"{log.t[k]:.6g}" for k in starts[1:6])
        more = f" and {len(starts) - 6} more" if len(starts) > 6 else ""
        why = f"gaps longer than {limit:.3g} s" + (
            f" or after {c.n_nan_rows} row(s) dropped for NaN/inf" if c.invalid_after else ""
        )
        warnings.warn(
            f"{path.name}: cut at {why}: the observer starts again at t = {at}{more} s "
            "(no event spans a cut)",
            DynidWarning,
            stacklevel=4,
        )
    return starts


def _cut_at_jumps(
    path: Path, log: TorqueLog, dq: NDArray[np.float64], starts: list[int]
) -> list[int]:
    """The pieces cut again where positions jump more than the velocities ``dq`` explain
    (:func:`~dynid.observer.pieces.position_jumps`) over one regular time step (a stretch
    of samples lost without a gap in the stamps, an encoder glitch), with a warning naming
    the file, the joints and the times: the observer starts again there, so that no event
    is made of the jump (a lost stretch of 0.2 s was a 'collision' on every joint). A
    glitch's jump back is found in the next pass (at most three). A jump across a gap
    bridged by ``--max-gap`` is warned about only (bridging was asked for)."""
    dt = np.diff(log.t)
    regular = 1.5 * float(np.median(dt)) if dt.size else np.inf
    found: list[PositionJump] = []
    bridged: list[PositionJump] = []
    cut = list(starts)
    for _ in range(3):
        jumps = [x for x in position_jumps(log.t, log.q, dq, cut) if x not in found + bridged]
        at: set[int] = set()
        for x in jumps:
            k = int(np.searchsorted(log.t, x.t))
            if k > 0 and log.t[k] - log.t[k - 1] > regular:
                bridged.append(x)
            elif k not in cut:
                found.append(x)
                at.add(k)
        if not at:
            break
        cut = sorted(set(cut) | at)
    for jumps, what in (
        (
            found,
            "samples lost without a gap in the time stamps, or an encoder glitch; the "
            "observer starts again after each jump (no event spans one)",
        ),
        (bridged, "across a gap bridged by --max-gap: the residual after it is not to be trusted"),
    ):
        if not jumps:
            continue
        jumps.sort(key=lambda x: (x.t, x.joint))
        listed = ", ".join(
            f"joint {x.joint + 1} by {x.size:+.3g} at t = {x.t:.6g} s" for x in jumps[:3]
        )
        more = f" and {len(jumps) - 3} more" if len(jumps) > 3 else ""
        warnings.warn(
            f"{path.name}: position jumps more than the recorded velocity explains "
            f"({listed}{more}): {what}",
            DynidWarning,
            stacklevel=4,
        )
    return cut
