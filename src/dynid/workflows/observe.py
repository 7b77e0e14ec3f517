"""Collision detection on log files: the entry point of ``dynid observe``, with every policy
the command applies, so that the Python API behaves as the command does.

* The model: an ``identification.json`` (``--model``; its own friction, drive and rotor
  inertias, and the covariance of its base parameters) or a robot (``--params``: a
  ``feasible.json`` with the drive and the friction identified with it, or a URDF/TOML
  robot, a TOML with the drive of its ``[drive]`` table); ``--friction friction.json``
  replaces the friction (the law ``dynid friction`` chose, with its standstill band).
  The drive is read as ``validate`` reads it: ``--drive`` for a robot without one (and
  in place of a TOML's ``[drive]`` table), refused when it differs from the one an
  identified model or a ``feasible.json`` holds (:func:`observer_drive`).
* Logs are read strictly with the model's joint count (extra columns ignored, with a
  warning), through the column map the model's data were read with when none is given, and
  brought to the joint side through the model's drive. A log is cut at its gaps (steps
  longer than ``max_gap``, default the model's identification's, else
  :func:`~dynid.identification.log.default_max_gap`, as ``identify`` cuts): the observer
  starts again on each piece and no event spans a cut (one warning names the file and the
  times). Rows dropped for NaN or inf (``drop_invalid``, or the model's identification
  dropped them: :mod:`dynid.workflows.as_identified`; refused otherwise, the row named)
  are bridged as ``identify``
  bridges them: the observer carries on across the step they leave when it is within
  that rule (its update takes any step), and a longer one is a gap. A position that
  jumps more than its velocity explains over a regular time step (samples lost without a
  gap in the stamps, an encoder glitch) cuts the log there too, with a warning
  (:mod:`dynid.observer.pieces`).
  Several logs are checked together: one in other units than the others is refused, one
  far outside the joint limits warned about (:mod:`dynid.workflows.recordings`).
* One-sample torque spikes (a sensor or logging fault, by the rule ``identify`` replaces
  them by before fitting: :func:`~dynid.identification.spikes.despiked`) are replaced by
  the line between their neighbours before the observer runs, with a warning per log
  naming the joints, the counts and the times
  (:func:`~dynid.workflows.recordings.despiked_recordings`): the residual of a 30 N m
  spike of 1 ms crosses a collision threshold for tens of ms, while a contact lasts
  several samples and stays. Calibration and detection alike; a log sampled below
  :data:`SPIKE_RATE_HZ` keeps them (a short impact can be one sample there), said so.
* ``calibrate``: the residuals of every (collision-free) log give the thresholds; with an
  identified model that has a covariance, they also grow with the model's uncertainty
  (``uncertainty``, default on); the standstill margin of the model's friction (its
  Coulomb level where the law's Coulomb term is off, through the observer's lag) is left
  out of the residuals they read and added to the thresholds (``standstill``, default on;
  :mod:`dynid.observer.detection`). A log whose torques have the opposite sign to the
  model's on some joint or every joint, read from its residual
  (:mod:`dynid.observer.sign`), is refused naming the file and the joints; detecting
  warns about one.
* Otherwise the thresholds (``thresholds.json``) fix the observer (gains, discretisation,
  rule) and the detection; runs over the threshold closer than ``merge_s`` are one event,
  contact-level events shorter than ``min_duration_s`` are dropped, and so is an isolated
  crossing before runs are joined (:mod:`dynid.observer.events`); the true external
  torques ``tau_ext1..n`` that ``dynid simulate --contact`` writes beside a log are kept
  for the figure.
* A log with labelled contacts has its events scored against them
  (:mod:`dynid.observer.scoring`, ``label_tolerance_s``): a label column (the ``label``
  of the column map, else ``collision``, ``contact`` or ``label``;
  :func:`~dynid.workflows.observe_detect.contact_labels`), else the true external torques
  of a simulated log (:func:`~dynid.workflows.observe_detect.scored`).
* With a frame, each event's share of the residual the wrench there leaves unexplained,
  and a warning naming the events it does not fit
  (:mod:`dynid.observer.wrench_fit`).
"""

from __future__ import annotations

import contextlib
import copy
import dataclasses
import hashlib
import logging
import warnings
from collections.abc import Callable, Iterator, Mapping, Sequence
from dataclasses import dataclass
from functools import partial
from pathlib import Path

import numpy as np
from numpy.typing import NDArray

from .. import _checks
from .._checks import caller_level
from ..exceptions import DataError, DynidError, DynidWarning, OptionError, ShapeError
from ..exceptions import in_file as about_file
from ..friction.fit import same_drive
from ..friction.model import FrictionModel, FrictionSum, own_at_motors_note, placed_friction
from ..identification.info import IdentificationInfo
from ..identification.log import TorqueLog, joint_side_log
from ..identification.model import IdentifiedModel
from ..identification.spikes import SPIKES_BEFORE_OBSERVER
from ..io.columns import ColumnMap
from ..io.drive_file import drive_of_robot_file, load_drive
from ..io.feasible import load_feasible_drive, load_feasible_linear_friction
from ..io.friction_json import load_friction_json
from ..io.model_json import load_model_json
from ..io.observer_files import load_thresholds
from ..io.robot_file import load_robot
from ..model.drive import Drive
from ..model.robot import Robot
from ..model.units import unit_said
from ..observer.calibration_check import (
    CalibrationCheck,
    ModelCheck,
    calibration_false_alarms,
    calibration_quiet,
    collision_level,
    detectable,
)
from ..observer.detection import Thresholds, calibrate
from ..observer.events import DEFAULT_MERGE_S, DEFAULT_MIN_DURATION_S
from ..observer.gain_noise import GainNoiseTally
from ..observer.model import ObserverModel, from_identified, from_robot
from ..observer.residual import DEFAULT_GAIN, ObserverOptions
from ..observer.results import LogObservation, ObserveResult
from ..observer.scoring import DEFAULT_TOLERANCE_S
from ..observer.sign import TorqueSign, opposite_finding, unexplained_finding
from ..observer.thresholds import (
    ModelFingerprint,
    log_rate,
    mixed_velocities,
    rate_mismatch,
    velocity_mismatch,
)
from ..observer.trust import QuietResidual
from ..observer.unmodelled import FrictionTally
from ..observer.unmodelled_load import LoadTally
from ..observer.wrench import wrench_kind, wrench_rank
from ..progress import NOTE
from .as_identified import identification_beside, read_as_identified
from .data_files import (
    ColumnSpec,
    column_map,
    data_files,
    in_file,
    read_torque_log,
    recorded_columns,
)
from .observe_detect import (
    ResidualSink,
    contact_labels,
    counted_events,
    detected_log,
    true_torques,
)
from .observe_logs import (
    ObservedBlock,
    PreparedLog,
    Series,
    margin_series,
    observed_blocks,
    prepared_log,
    recording_note,
    speeds_of,
)
from .recordings import (
    Recorded,
    check_derived_velocities,
    check_limits,
    check_signs,
    check_torque_unit,
    check_unit_findings,
    check_units,
    despiked_recordings,
    given_start,
    given_units,
    note_unread_columns,
    unwrapped_recorded,
    usable_recorded,
)

__all__ = [
    "LogObservation",
    "ObserveOptions",
    "ObserveResult",
    "default_tip_hint",
    "friction_source",
    "load_observer_model",
    "model_fingerprint",
    "observe_files",
    "observer_drive",
    "read_log_as_identified",
]

_log = logging.getLogger(__name__)


#: Logs sampled at or above this rate [Hz] have their one-sample torque spikes replaced
#: before the observer runs: a sample lasts 2 ms or less, and an impact of a robot arm
#: lasts several. Below it a short impact can be one sample, and the spikes are kept.
SPIKE_RATE_HZ = 500.0


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
    drive : Drive or Path, optional
        The drive the logs were recorded through (a drive TOML, or a robot TOML with a
        ``[drive]`` table), as ``validate`` takes it (:func:`observer_drive`).
    calibrate : bool
        Compute thresholds from ``data`` (collision-free logs).
    thresholds : Path, optional
        ``thresholds.json`` to detect with (required unless ``calibrate``).
    frame : str, optional
        Also estimate the external wrench at this frame.
    wrench : str
        What is estimated at ``frame`` (:data:`~dynid.observer.wrench.WRENCH_KINDS`):
        ``full``, the wrench (force and moment, 6 unknowns: the least-norm one where fewer
        than six joints move the frame), or ``force``, the force of a point contact at the
        frame's origin (moment zero, 3 unknowns, which three joints or more determine).
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
        Runs over the threshold closer than this [s] are one event
        (:data:`~dynid.observer.events.DEFAULT_MERGE_S`).
    min_duration_s : float
        Contact-level events shorter than this [s] are dropped, and so are isolated
        crossings shorter than it, before runs are joined
        (:data:`~dynid.observer.events.DEFAULT_MIN_DURATION_S`); ``merge_s = 0`` and
        ``min_duration_s = 0``: every run over the threshold is an event.
    columns : (str or None, str or None)
        ``--columns``/``--units``; default: those the model's data were read with.
    drop_invalid : bool
        Drop rows with NaN/inf or a repeated timestamp instead of failing (the observer
        carries on across the step they leave, or starts again after it when it is longer
        than ``max_gap``); False: as the model's identification did
        (:func:`~dynid.workflows.as_identified.read_as_identified`, with a note), else
        refused.
    max_gap : float, optional
        Longest step [s] the observer integrates over (rows dropped with
        ``drop_invalid`` included); the log is cut at longer ones; default: the model's
        identification's (a note names it), else the default rule.
    base, tip : str, optional
        The chain of a ``params`` URDF with several leaves (its root and only leaf by
        default).
    snap_angles : bool
        Read a ``params`` URDF's joint angles rounded near multiples of pi/2 as those
        multiples (:func:`dynid.io.robot.urdf.load_urdf`).
    torque_delay_s : float, optional
        How far the torques lag the positions [s]: each log's states are read that much
        earlier (:func:`~dynid.identification.prepare.states_in_step`, as identify,
        validate and friction read them); default: the delay the model was identified
        with (``identification.json``'s ``metadata.torque_delay_s``), 0 for a robot file.
    q_start : tuple of float, optional
        The joint positions [rad] at the first sample of one motor-side log whose motor
        encoders wrap every turn (:func:`~dynid.workflows.recordings.given_start`).
    keep_series : bool
        When calibrating: keep every log's residual (and its std and margin) in the
        result, for figures. False: only the calibration's running statistics, a block of
        samples at a time (bounded memory on a long log); the result's logs then hold no
        series, and with a ``quantile`` below 1 the observer runs over the logs a second
        time, a block at a time, to count the thresholds' false alarms on them.
        Detecting: False keeps no series (the events, the residual tables of the ``sink``
        and the summaries a block at a time); True keeps them too.
    figure_points : int, optional
        Detecting: keep every k-th sample of the residual, its thresholds and the true
        torques, at most this many, for a figure (``LogObservation.figure``).
    label_tolerance_s : float
        Detecting a log with labelled contacts (a label column, or the true torques of a
        simulated log): how long after a contact's end [s] an event may start and still
        detect it and, of a label column (made by hand), how long before its start
        (:mod:`dynid.observer.scoring`; the true torques keep the exact lead, 0.02 s).
    loads : bool
        Detecting: read a long event that a weight at the flange explains as a carried
        load (:mod:`~dynid.observer.carried_load`: an event of level ``load``, the
        detection run again without its torque for the contacts on top); False
        (``--no-loads``): no event is read as a load.
    """

    data: tuple[Path, ...]
    model: Path | None = None
    params: str | Path | None = None
    friction: Path | None = None
    drive: Drive | Path | None = None
    calibrate: bool = False
    thresholds: Path | None = None
    frame: str | None = None
    wrench: str = "full"
    gain: float | tuple[float, ...] = DEFAULT_GAIN
    discretisation: str = "exact"
    rule: str = "trapezoid"
    margin: float = 1.5
    quantile: float = 1.0
    collision_factor: float = 2.0
    k_sigma: float = 3.0
    uncertainty: bool = True
    standstill: bool = True
    merge_s: float = DEFAULT_MERGE_S
    min_duration_s: float = DEFAULT_MIN_DURATION_S
    columns: ColumnSpec = (None, None)
    drop_invalid: bool = False
    max_gap: float | None = None
    base: str | None = None
    tip: str | None = None
    snap_angles: bool = False
    q_start: tuple[float, ...] | None = None
    torque_delay_s: float | None = None
    keep_series: bool = True
    figure_points: int | None = None
    label_tolerance_s: float = DEFAULT_TOLERANCE_S
    loads: bool = True


def load_observer_model(
    model: Path | None,
    params: str | Path | None,
    friction: Path | None = None,
    *,
    base: str | None = None,
    tip: str | None = None,
    drive: Drive | Path | None = None,
    snap_angles: bool = False,
) -> tuple[ObserverModel, Mapping[str, str | None] | None]:
    """The observer model of ``--model`` or ``--params`` (and ``--friction``), with the
    column map the model's data were read with (None for a robot); ``base`` and ``tip``
    choose the chain of a ``params`` URDF, ``snap_angles`` snaps its rounded angles;
    ``drive`` the one given (``--drive``,
    :func:`observer_drive`).

    Raises
    ------
    OptionError
        Neither or both of ``model`` and ``params``; ``base``, ``tip`` or ``snap_angles``
        with another model than a URDF.
    DataError
        A file that is not what it should be (named), a ``drive`` other than the one the
        model or the ``feasible.json`` holds.
    """
    if (model is None) == (params is None):
        raise OptionError("give one of --model identification.json and --params ROBOT")
    if (base is not None or tip is not None or snap_angles) and not str(params).lower().endswith(
        ".urdf"
    ):
        given = "--model" if model is not None else f"--params {params}"
        raise OptionError(
            f"--base/--tip/--snap-angles read the chain of a --params URDF; {given} holds "
            "its own chain"
        )
    fr: FrictionModel | FrictionSum | None | str = "model"
    if model is not None:
        ident = load_model_json(model)
        held = ident.drive
        own = same_drive(
            _drive(drive, ident.robot.n), held, "the model", "the one the model was identified with"
        )
        if friction is not None:  # a file: where the drive puts a robot's own, as simulated
            fr = placed_friction(load_friction_json(friction), own)
        obs = from_identified(ident, fr)
        if own is not held:  # a model without one: its logs are read through it
            obs = dataclasses.replace(obs, drive=own)
        return obs, ident.info.column_map
    spec = str(params)
    robot = load_robot(spec, base=base, tip=tip, snap_angles=snap_angles, what="--params")
    if spec.lower().endswith(".json") and friction is None:
        lin = load_feasible_linear_friction(spec)
        fr = "robot" if lin is None else lin
    chain = default_tip_hint(spec, robot, tip)
    with _said_with(chain):
        own = observer_drive(spec, robot.n, drive)
    if friction is not None:  # a file: where the drive puts a robot's own, as simulated
        loaded = load_friction_json(friction)
        if loaded.n != robot.n:
            raise DataError(
                f"friction for {loaded.n} joints; the model has {robot.n}"
                + ("" if chain is None else f"; {chain}"),
                file=Path(friction).name,
            )
        fr = placed_friction(loaded, own)
    if fr in ("model", "robot") and (said := own_at_motors_note(robot, own)) is not None:
        _log.log(NOTE, said)
    obs = from_robot(robot, friction="robot" if fr == "model" else fr, drive=own)
    return _read_as_beside(obs, spec)


def _read_as_beside(
    obs: ObserverModel, params: str
) -> tuple[ObserverModel, Mapping[str, str | None] | None]:
    """``obs`` of a ``params`` ``feasible.json`` that reads its logs as the
    ``identification.json`` beside it records (its torque delay, invalid rows and gap rule:
    :func:`~dynid.workflows.as_identified.identification_beside`, with a note), with its
    column map; ``obs`` as it is, and None, without one."""
    own = identification_beside(params, obs.robot) if params.lower().endswith(".json") else None
    if own is None or own.info.log is None:
        return obs, None
    _log.log(
        NOTE,
        "%s: the logs read as identification.json beside it records (its --columns/--units, "
        "torque delay, --drop-invalid and gap rule), as --model reads them; each given "
        "replaces its part",
        Path(params).name,
    )
    log = own.info.log
    obs = dataclasses.replace(obs, torque_delay_s=float(log.torque_delay_s), logs_read=log)
    return obs, own.info.column_map


def default_tip_hint(params: str, robot: Robot, tip: str | None) -> str | None:
    """What a joint-count error says of a ``params`` URDF read to its default tip (no
    ``tip``): the chain's joints, its last joint and link, and ``--tip``; None otherwise (a
    chain chosen, another kind of robot). A Z1's default leaf brings in its gripper's
    joint, and the 6-joint drive file was blamed instead."""
    if tip is not None or not params.lower().endswith(".urdf"):
        return None
    return (
        f"the model is {Path(params).name}'s chain to its only leaf ({robot.n} joints, the "
        f"last {robot.joint_names[-1]} moving {robot.link_names[-1]}); hint: end it "
        "earlier with --tip LINK"
    )


@contextlib.contextmanager
def _said_with(hint: str | None) -> Iterator[None]:
    """A :class:`DataError` or :class:`ShapeError` raised inside ends with ``hint`` (the
    chain a URDF's default tip gave: :func:`default_tip_hint`)."""
    try:
        yield
    except (DataError, ShapeError) as exc:
        if hint is None or not exc.args:
            raise
        err = copy.copy(exc)
        err.args = (f"{exc.args[0]}; {hint}", *exc.args[1:])
        raise err from None


def observer_drive(params: str | Path, n: int, drive: Drive | Path | None = None) -> Drive | None:
    """The drive a ``--params`` robot's logs are read through, by ``validate``'s rule:
    the one a ``feasible.json`` holds (``drive`` must then be the same), else ``drive``
    (a :class:`~dynid.model.drive.Drive` or a TOML file of one), else the ``[drive]``
    table of a robot TOML (its gear ratios, currents and rotor inertias), else none.

    Raises
    ------
    DataError
        An unreadable drive file, a ``drive`` that differs from the ``feasible.json``'s
        (each field named).
    """
    given = _drive(drive, n)
    spec = str(params)
    if spec.lower().endswith(".json"):
        name = Path(spec).name
        return same_drive(given, load_feasible_drive(spec), name, f"the one {name} holds")
    return given if given is not None else drive_of_robot_file(spec, n)


def _drive(drive: Drive | Path | None, n: int) -> Drive | None:
    """A drive given as one or as a TOML file of one (for ``n`` joints)."""
    return load_drive(drive, n) if isinstance(drive, str | Path) else drive


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
    them), ``frame``, ``merge_s``, ``min_duration_s`` and ``label_tolerance_s`` when
    calibrating (no wrench or event is computed), ``wrench`` without ``frame`` (or not
    one of its kinds)."""
    default = ObserveOptions(data=())
    wrench_kind(opts.wrench)
    if opts.frame is None and opts.wrench != default.wrench:
        raise OptionError(
            "says what is estimated at {frame}; give the frame", field="wrench", others=("frame",)
        )
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
    else:
        for name in ("merge_s", "min_duration_s", "label_tolerance_s", "loads"):
            if getattr(opts, name) != getattr(default, name):
                raise OptionError(
                    "applies when detecting (events); calibrating finds none", field=name
                )


def _observer_options(opts: ObserveOptions, thresholds: Thresholds | None) -> ObserverOptions:
    if thresholds is not None:
        return thresholds.options
    return ObserverOptions(opts.gain, opts.discretisation, opts.rule)  # type: ignore[arg-type]


def observe_files(opts: ObserveOptions, sink: ResidualSink | None = None) -> ObserveResult:
    """Calibrate thresholds on collision-free logs, or detect contacts in logs (module
    docstring).

    Detecting runs a block of samples at a time (:mod:`dynid.workflows.observe_detect`):
    ``sink`` (:class:`~dynid.io.observer_files.ResidualTables`) receives every log's
    residual table as it is computed; the series themselves are kept with
    ``opts.keep_series`` only.

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
    _checks.of_type("opts", opts, ObserveOptions, "an ObserveOptions")
    if not opts.data:
        raise OptionError("give one or more --data logs")
    if opts.calibrate == (opts.thresholds is not None):
        raise OptionError("give --calibrate (collision-free logs) or --thresholds thresholds.json")
    _refuse_unused(opts)
    model, recorded = load_observer_model(
        opts.model,
        opts.params,
        opts.friction,
        base=opts.base,
        tip=opts.tip,
        drive=opts.drive,
        snap_angles=opts.snap_angles,
    )
    drop, gap = read_as_identified(model.logs_read, opts.drop_invalid, opts.max_gap)
    opts = dataclasses.replace(opts, drop_invalid=drop, max_gap=gap)  # as identify read them
    fingerprint = model_fingerprint(opts)
    given = _given_thresholds(opts, model, fingerprint)
    own = friction_source(opts) if model.friction is not None else None
    options = _observer_options(opts, given)
    wants_std = (
        opts.uncertainty and model.covariance is not None
        if given is None
        else given.uses_uncertainty and model.covariance is not None
    )
    wants_margin = opts.standstill if given is None else given.standstill
    files = data_files(opts.data)
    columns, cmap = _model_columns(model, recorded, opts.columns, files)  # said once
    if cmap is not None and cmap.mapped("tau_ext"):
        _log.log(NOTE, "%s", _reference_note(cmap))
    read = _read_logs(
        files, model, cmap, _Reading(opts.drop_invalid, opts.q_start, opts.max_gap),
        among=opts.calibrate, recorded=recorded, units=(columns[1], opts.columns[1]),
    )  # fmt: skip
    read, _ = despiked_recordings(
        read, model.robot.joint_names, SPIKES_BEFORE_OBSERVER, min_rate_hz=SPIKE_RATE_HZ
    )
    if given is None:
        cal = _calibrated(read, model, cmap, opts, options, wants_std, wants_margin)
        th = _recorded_calibration(cal.thresholds, read.logs, fingerprint)
        return dataclasses.replace(cal, thresholds=th, fingerprint=fingerprint, friction_source=own)
    paths = tuple(map(Path, read.paths))
    logs = []
    unmodelled = (
        None
        if model.friction is not None
        else FrictionTally(model.n, np.asarray(options.gain, dtype=np.float64))
    )
    load = LoadTally(model.robot)
    kind = wrench_kind(opts.wrench)
    if opts.frame is not None:  # an unknown frame, a frame on the base: before any log
        wrench_rank(model.robot, opts.frame, kind)
    assert opts.thresholds is not None
    _warn_mismatches(paths, read.logs, given, opts.thresholds.name)
    for k, (path, log) in enumerate(zip(paths, read.logs, strict=True)):
        rows = log.t.shape[0]
        table = None
        if sink is not None:
            table = sink.table(
                paths, k, rows, model.n, opts.frame, kind, unit=unit_said(model.robot, "N m")
            )
        with about_file(path.name):
            prep = prepared_log(
                path, log, model, opts.max_gap, read.joint_side[k], _delay(opts, model)
            )
            labels = contact_labels(prep, cmap)
        logs.append(
            detected_log(
                prep,
                model,
                cmap,
                given,
                options,
                wants=(wants_std, wants_margin),
                merge_s=opts.merge_s,
                min_duration_s=opts.min_duration_s,
                frame=opts.frame,
                keep_series=opts.keep_series,
                figure_points=opts.figure_points,
                table=table,
                retable=None
                if sink is None
                else partial(sink.table, paths, k, rows, model.n, opts.frame, kind),
                kind=kind,
                labels=labels,
                tolerance_s=opts.label_tolerance_s,
                unmodelled=unmodelled,
                load=load,
                loads=opts.loads,
            )  # fmt: skip
        )
        logs[-1] = dataclasses.replace(logs[-1], speed_max=speeds_of(prep, model))
    return ObserveResult(
        model, given, tuple(logs), fingerprint, own, opts.frame, kind,
        min_duration_s=opts.min_duration_s, merge_s=opts.merge_s,
        unmodelled=None if unmodelled is None else unmodelled.result(),
        load=load.result(),
    )  # fmt: skip


def _given_thresholds(
    opts: ObserveOptions, model: ObserverModel, fingerprint: ModelFingerprint
) -> Thresholds | None:
    """The thresholds of ``opts.thresholds`` (None: calibrating), refused for another
    joint count and warned when calibrated with another model."""
    given = None if opts.thresholds is None else load_thresholds(opts.thresholds)
    if given is not None and given.n != model.n:
        spec = None if opts.params is None else str(opts.params)
        chain = None if spec is None else default_tip_hint(spec, model.robot, opts.tip)
        raise OptionError(
            f"{opts.thresholds}: thresholds for {given.n} joints; the model has {model.n}"
            + ("" if chain is None else f"; {chain}")
        )
    if given is not None and given.model is not None and given.model.sha256 != fingerprint.sha256:
        assert opts.thresholds is not None
        said = friction_difference(opts.thresholds.name, given.model, fingerprint)
        warnings.warn(
            said
            or f"{opts.thresholds.name} was calibrated with {given.model}, not with this "
            f"model ({fingerprint}): thresholds fit the residual of their own model; "
            "calibrate again with this one",
            DynidWarning,
            stacklevel=caller_level(),
        )
    return given


def _recorded_calibration(
    th: Thresholds, logs: Sequence[TorqueLog], fingerprint: ModelFingerprint
) -> Thresholds:
    """``th`` with what they were calibrated on: the model, the logs' sample rate [Hz]
    (the median of theirs) and their velocities (measured, derived or mixed)."""
    rates = [r for r in (log_rate(log.t) for log in logs) if r is not None]
    kinds = {bool(log.dq_derived) for log in logs}
    velocities = "mixed" if len(kinds) > 1 else ("derived" if True in kinds else "measured")
    rate = float(np.median(rates)) if rates else None
    return dataclasses.replace(th, model=fingerprint, sample_rate_hz=rate, velocities=velocities)


def _warn_mismatches(
    paths: Sequence[Path], logs: Sequence[TorqueLog], given: Thresholds, name: str
) -> None:
    """A warning per log whose sample rate or kind of velocities is not the one the
    thresholds of the file ``name`` were calibrated on."""
    for path, log in zip(paths, logs, strict=True):
        if (other := rate_mismatch(log_rate(log.t), given, name)) is not None:
            warnings.warn(f"{path.name}: {other}", DynidWarning, stacklevel=caller_level())
        if (other := velocity_mismatch(bool(log.dq_derived), given, name)) is not None:
            warnings.warn(f"{path.name}: {other}", DynidWarning, stacklevel=caller_level())


def model_fingerprint(opts: ObserveOptions) -> ModelFingerprint:
    """The files ``opts`` reads the model from (``model`` or ``params``, ``friction``,
    ``drive``) by name, and a SHA-256 of their content and of the chain (``base``,
    ``tip``): a built-in robot's name stands for its file, a :class:`Drive` given as one
    for its arrays."""
    h = hashlib.sha256()
    files, roles = [], []
    for what, src in (
        ("model", opts.model),
        ("params", opts.params),
        ("friction", opts.friction),
        ("drive", opts.drive),
    ):
        if src is None:
            continue
        h.update(f"\0{what}\0".encode())
        roles.append(what)
        if isinstance(src, Drive):
            for f in dataclasses.fields(src):
                h.update(f"{f.name}={getattr(src, f.name)!r};".encode())
                if isinstance(v := getattr(src, f.name), np.ndarray):
                    h.update(np.ascontiguousarray(v, dtype=np.float64).tobytes())
            files.append("a drive")
        elif Path(src).is_file():
            h.update(Path(src).read_bytes())
            files.append(Path(src).name)
        else:  # a built-in robot's name
            h.update(str(src).encode())
            files.append(str(src))
    h.update(f"\0base={opts.base}\0tip={opts.tip}".encode())
    return ModelFingerprint(tuple(files), h.hexdigest(), tuple(roles))


def _delay(opts: ObserveOptions, model: ObserverModel) -> float:
    """The torques' delay [s] the logs are prepared with: ``--torque-delay``, else the
    model's own (:attr:`~dynid.observer.model.ObserverModel.torque_delay_s`)."""
    return model.torque_delay_s if opts.torque_delay_s is None else float(opts.torque_delay_s)


def friction_difference(
    name: str, calibrated: ModelFingerprint, now: ModelFingerprint
) -> str | None:
    """The warning when the thresholds ``name`` were calibrated with another ``--friction``
    file than ``now`` runs with (one given and not the other, or two names), or None:
    the same friction by name, or the roles not recorded (a file of an earlier version)."""
    if not calibrated.roles or not now.roles:
        return None
    then, here = calibrated.given_as("friction"), now.given_as("friction")
    if then == here:
        return None
    tail = "thresholds fit the residual of the model they were calibrated with"
    if here is None:
        return (
            f"{name} was calibrated with --friction {then}, and this run has no --friction: "
            f"give --friction {then} as then, or calibrate again without it ({tail})"
        )
    if then is None:
        return (
            f"{name} was calibrated without --friction, and this run gives --friction {here}: "
            f"leave it out as then, or calibrate again with it ({tail})"
        )
    return (
        f"{name} was calibrated with --friction {then}, this run gives --friction {here}: "
        f"give {then} as then, or calibrate again with {here} ({tail})"
    )


def friction_source(opts: ObserveOptions) -> str | None:
    """The robot file (or built-in name) whose own friction the model holds: a
    ``params`` URDF or TOML without ``friction`` (a ``feasible.json``'s friction was
    identified with it), else None."""
    if opts.params is None or opts.friction is not None:
        return None
    spec = str(opts.params)
    return None if spec.lower().endswith(".json") else Path(spec).name


def _reference_note(cmap: ColumnMap) -> str:
    """What a ``tau_ext`` mapped (``--columns tau_ext=NAME``) is taken for: the truth the
    residual is scored and its RMS error measured against, whatever the columns hold."""
    tpl = cmap.template("tau_ext")
    return (
        f"tau_ext read from {tpl} (--columns tau_ext={tpl}): taken as the true external "
        "torques, the score and RMS r - tau_ext are against them; a robot's own estimate "
        "(libfranka's tau_ext_hat_filtered) carries its own model's errors, which count "
        "here as the observer's"
    )


def read_log_as_identified(
    path: str | Path, model: IdentifiedModel, *, drop_invalid: bool = False
) -> TorqueLog:
    """The torque log ``path`` read as ``dynid observe --model`` reads a log for ``model``
    (the same reading and checks), at the joints: ``q, dq, tau`` as
    :meth:`~dynid.observer.residual.MomentumObserver.step` takes them.

    * Through the column map the model's data were read with (``info.column_map``: its
      ``--columns``, and its ``--units``: units, factors and torque signs such as
      ``tau3=-1``), said in a note (:func:`~dynid.workflows.data_files.recorded_columns`).
    * Rows with NaN/inf or a repeated timestamp dropped where ``drop_invalid``, or where
      the identification dropped them (a note: :func:`~dynid.workflows.as_identified.
      read_as_identified`); refused otherwise, the row named.
    * Checked as a detection log: units, joint limits, torques of the opposite sign to the
      model's or in mN m (:mod:`dynid.workflows.recordings`).
    * Brought to the joints through the model's drive (a motor-side log's motor angles,
      velocities and torques or currents).

    A log without velocity columns has ``dq`` from the positions through a zero-phase
    low-pass, which uses later samples: an online loop cannot have it (its own velocity
    estimate, causal, is noisier and needs thresholds calibrated on it). What ``observe``
    does after reading is left to the loop: the log is not cut at its gaps, its torque
    spikes are kept and a model's torque delay is not applied.

    Parameters
    ----------
    path : str or Path
        A torque log (``.csv``/``.npz``), or another tool's file the model's column map
        reads.
    model : IdentifiedModel
        The model the log is read for (``load_model_json``).
    drop_invalid : bool
        Drop invalid rows (counted in a warning) even where the identification did not.

    Returns
    -------
    TorqueLog
        ``t`` (N,) [s], ``q``, ``dq``, ``tau`` (N, n) at the joints [rad, rad/s, N m].

    Raises
    ------
    DataError
        A bad file, invalid rows unless dropped, another joint count, a log in degrees or
        of the opposite torque sign (each names the file and the ``--units`` that reads it).
    """
    _checks.of_type("model", model, IdentifiedModel, "an IdentifiedModel (load_model_json)")
    obs = from_identified(model, None)
    drop, gap = read_as_identified(obs.logs_read, drop_invalid, None)
    recorded = model.info.column_map
    files = [Path(path)]
    columns, cmap = _model_columns(obs, recorded, (None, None), files)
    read = _read_logs(
        files, obs, cmap, _Reading(drop, None, gap), recorded=recorded, units=(columns[1], None)
    )
    return joint_side_log(read.logs[0], obs.drive)


def _model_columns(
    model: ObserverModel,
    recorded: Mapping[str, str | None] | None,
    given: ColumnSpec,
    files: Sequence[Path],
) -> tuple[ColumnSpec, ColumnMap | None]:
    """The ``--columns``/``--units`` the ``files`` are read with for ``model`` (``given``,
    else the ``recorded`` ones, said once: :func:`~dynid.workflows.data_files.
    recorded_columns`) and their column map."""
    columns = recorded_columns(recorded, *given, files)
    return columns, column_map(*columns, drive=model.drive, robot=model.robot)


@dataclass(frozen=True, slots=True)
class _Reading:
    """How logs are read: invalid rows dropped, the joint positions [rad] at a wrapped
    motor-side log's first sample, the longest gap bridged [s] (None: the rule)."""

    drop_invalid: bool
    q_start: tuple[float, ...] | None
    max_gap: float | None


def _read_logs(
    paths: Sequence[Path],
    model: ObserverModel,
    cmap: ColumnMap | None,
    how: _Reading,
    *,
    among: bool = False,
    recorded: Mapping[str, str | None] | None = None,
    units: tuple[str | None, str | None] = (None, None),
) -> Recorded:
    """The logs ``paths`` read strictly for the model through ``cmap`` (of the ``--units``
    text ``units[0]``, for the unit findings' hint; ``units[1]`` the one given); a log in
    other units than the others, with joints in degrees, with torques of the opposite sign
    to the model's (``among``: calibration logs, judged against each other) or in mN m
    read as N m refused (the model's ``recorded`` column map, when it looks wrong for a
    file, named first), and one far outside the joint limits warned about, each naming the
    file (:mod:`dynid.workflows.recordings`)."""
    logs = [
        read_torque_log(
            p,
            model.n,
            columns=cmap,
            drop_invalid=how.drop_invalid,
            owner="the model",
            robot=model.robot,
            drive=model.drive,
        )
        for p in map(Path, paths)
    ]
    names = [Path(p).name for p in paths]
    logs = list(given_start(logs, names, model.robot, model.drive, how.q_start, how.max_gap))
    read = Recorded(tuple(logs), tuple(map(Path, paths)), model.drive)  # mapped once
    checked = unwrapped_recorded(read, model.robot, how.max_gap)  # as prepared_log reads
    check_unit_findings(checked, model.robot, given_units(cmap, units[0]))
    check_limits(checked, model.robot)
    read, checked = usable_recorded(read, checked, model.robot, how.max_gap)
    check_units(checked)
    check_derived_velocities(read, cmap)
    note_unread_columns(read, cmap)
    # detection logs hold contacts; a model's recorded sign map judged first
    check_signs(checked, model.robot, among=among, recorded=recorded, units=units[1])
    check_torque_unit(checked, model.robot, cmap)
    return read


def _judge_sign(name: str, sign: TorqueSign, noise: GainNoiseTally, names: Sequence[str]) -> None:
    """A calibration log's torques read against the model's through its residual
    (:mod:`dynid.observer.sign`): refused where their sign is opposite, a warning where the
    model leaves most of them unexplained beside the velocities' noise through the gain
    (``noise``, that log's).

    Raises
    ------
    DataError
        Torques of the opposite sign to the model's on some joint or every joint."""
    if (opposite := opposite_finding(sign, names)) is not None:
        raise DataError(opposite, file=name)
    found = noise.result()
    gain_noise = None if found is None else found.predicted
    if (unexplained := unexplained_finding(sign, names, gain_noise)) is not None:
        warnings.warn(f"{name}: {unexplained}", DynidWarning, stacklevel=caller_level())


def _calibrated(
    read: Recorded,
    model: ObserverModel,
    cmap: ColumnMap | None,
    opts: ObserveOptions,
    options: ObserverOptions,
    wants_std: bool,
    wants_margin: bool,
) -> ObserveResult:
    """The thresholds of the collision-free logs ``read``: their residuals a block at a
    time into :func:`~dynid.observer.detection.calibrate` (running maxima), each log's
    series kept only with ``opts.keep_series``.

    Raises
    ------
    DataError
        A log whose torques have the opposite sign to the model's on some joint or every
        joint (:mod:`dynid.observer.sign`, from its residual), naming the file and the
        joints: its thresholds would be blind there."""
    logs: list[LogObservation] = []
    names = model.robot.joint_names
    tally = GainNoiseTally(model, np.asarray(options.gain, dtype=np.float64))
    unmodelled = (
        None
        if model.friction is not None
        else FrictionTally(model.n, np.asarray(options.gain, dtype=np.float64))
    )
    sigma_max = np.zeros(model.n) if wants_std else None
    r_max = np.zeros(model.n)  # the largest |r| of every log
    kinds: dict[bool, NDArray[np.float64]] = {}  # read past the margin, per velocity kind
    # no series: the residual's level and false alarms read on a second pass
    again: list[PreparedLog] | None = [] if not opts.keep_series else None
    kept: list[PreparedLog] = []  # with the series: their margins again once calibrated

    def blocks() -> Iterator[ObservedBlock]:
        for path, log, side in zip(read.paths, read.logs, read.joint_side, strict=True):
            prep = prepared_log(Path(path), log, model, opts.max_gap, side, _delay(opts, model))
            if again is not None:
                again.append(prep)
            if opts.keep_series and wants_margin:
                kept.append(prep)
            keep = Series.new(prep, model.n, wants_std, wants_margin) if opts.keep_series else None
            peak = np.zeros(model.n)
            sign = TorqueSign(model.n)
            mine = GainNoiseTally(model, tally.gain)
            q, dq = prep.log.q, prep.dq
            seen = model.friction
            if unmodelled is not None:
                unmodelled.new_log()
            for blk in observed_blocks(prep, model, options, wants_std, wants_margin):
                if blk.friction is not None and blk.friction is not model.friction:
                    seen = blk.friction  # banded for the velocity noise (a note says so)
                if blk.margin is not None:
                    np.maximum(peak, blk.margin.max(axis=0), out=peak)
                if keep is not None:
                    keep.put(blk)
                rows = slice(blk.a, blk.a + blk.r.shape[0])
                sign.add(prep.log.tau[rows], blk.r)
                mine.add(q[rows], dq[rows], blk.r)
                if np.isfinite(blk.r).any():
                    np.fmax(r_max, np.nanmax(np.abs(blk.r), axis=0), out=r_max)
                    _read_past(kinds.setdefault(bool(log.dq_derived), np.zeros(model.n)), blk)
                if sigma_max is not None and blk.std is not None and np.isfinite(blk.std).any():
                    np.fmax(sigma_max, np.nanmax(blk.std, axis=0), out=sigma_max)
                if unmodelled is not None:  # the friction the model misses, at speed
                    unmodelled.add(prep.log.t[rows], dq[rows], blk.r)
                yield blk
            _judge_sign(Path(path).name, sign, mine, names)
            tally.merge(mine)
            logs.append(_observation(prep, model, cmap, opts, keep, peak, seen))

    # calibrate reads a block's residual, then its margin and std: these two come from the
    # block the residual was last read from (one block held; itertools.tee would keep up
    # to 57 blocks, its links' size)
    current: list[ObservedBlock] = []

    def residuals() -> Iterator[NDArray[np.float64]]:
        for x in blocks():
            current[:] = [x]
            yield x.r

    def beside(
        what: Callable[[ObservedBlock], NDArray[np.float64]],
    ) -> Iterator[NDArray[np.float64]]:
        while current:
            yield what(current[0])

    std = beside(_std) if wants_std else None
    margins = beside(lambda x: _margin(x, model.n)) if wants_margin else None
    settled = beside(lambda x: _settled(x, model.n)) if wants_margin else None
    th = calibrate(
        residuals(), options, std=std, standstill=margins, rest=settled, margin=opts.margin,
        quantile=opts.quantile, collision_factor=opts.collision_factor, k_sigma=opts.k_sigma,
    )  # fmt: skip
    _warn_mixed(read, kinds, model)
    if kept and th.rest is not None and np.any(th.rest.calibrated):  # the margins applied
        logs[:] = [
            dataclasses.replace(x, standstill=margin_series(p, model, options, th.rest))
            for x, p in zip(logs, kept, strict=True)
        ]
    counted = None
    if again is not None:  # the observer again, a block at a time: no series kept
        wants = (wants_std, wants_margin)
        passes = [counted_events(p, model, th, options, wants) for p in again]
        counted = (sum(k for k, _ in passes), QuietResidual.pooled(q for _, q in passes))
    return ObserveResult(
        model,
        th,
        tuple(logs),
        gain_noise=tally.result(),
        unmodelled=None if unmodelled is None else unmodelled.result(),
        check=dataclasses.replace(
            _checked(th, logs, sigma_max, r_max, counted), model=_model_check(opts, model, read)
        ),
    )


def _read_past(peak: NDArray[np.float64], blk: ObservedBlock) -> None:
    """``peak`` (n,) [N m] raised to the largest ``|r|`` of ``blk`` past its standstill
    margin, as the calibration reads it (:func:`~dynid.observer.detection.calibrate`)."""
    a = np.abs(blk.r) if blk.margin is None else np.clip(np.abs(blk.r) - blk.margin, 0.0, None)
    np.fmax(peak, np.nanmax(a, axis=0), out=peak)


def _warn_mixed(
    read: Recorded, kinds: Mapping[bool, NDArray[np.float64]], model: ObserverModel
) -> None:
    """A warning when the calibration logs ``read`` hold both kinds of velocities
    (measured and derived from the positions), with the largest ``|r|`` read past the
    margin on each kind's logs, ``kinds`` [N m] (:func:`~dynid.observer.thresholds.
    mixed_velocities`)."""
    if len(kinds) < 2:
        return
    names = {k: [Path(p).name for p, x in zip(read.paths, read.logs, strict=True)
                 if bool(x.dq_derived) is k] for k in (False, True)}  # fmt: skip
    said = mixed_velocities(
        names[False], names[True], kinds[False], kinds[True], model.robot.joint_names,
        unit_said(model.robot, "N m"),
    )  # fmt: skip
    warnings.warn(said, DynidWarning, stacklevel=caller_level())


@contextlib.contextmanager
def _unsaid() -> Iterator[None]:
    """Warnings and notes left unsaid: a second reading of the logs this run has read and
    said its findings on."""
    before = logging.root.manager.disable
    logging.disable(NOTE)
    try:
        with warnings.catch_warnings():
            warnings.simplefilter("ignore", DynidWarning)
            yield
    finally:
        logging.disable(before)


def _model_check(opts: ObserveOptions, model: ObserverModel, read: Recorded) -> ModelCheck | None:
    """The observer's model judged on the calibration logs ``read`` as ``dynid validate``
    judges it (:func:`~dynid.workflows.validate.validate_files`, the model and friction
    read as this run read them, the logs not read again; its warnings, this run's own
    reading's, not said twice), or None where validate cannot judge it (a log too short
    to filter)."""
    from .validate import ValidateOptions, validate_files  # the calibration's alone

    friction = "own" if opts.friction is None else opts.friction
    options = ValidateOptions(
        friction=friction,
        columns=opts.columns,
        drop_invalid=opts.drop_invalid,
        max_gap_s=opts.max_gap,
        drive=model.drive,
        q_start=opts.q_start,
        torque_delay_s=_delay(opts, model),
    )
    feasible = None
    try:
        with _unsaid():
            if opts.model is not None:
                judged: IdentifiedModel | Robot = load_model_json(opts.model)
            else:
                spec = str(opts.params)
                judged = load_robot(
                    spec, base=opts.base, tip=opts.tip, snap_angles=opts.snap_angles
                )
                feasible = spec if spec.lower().endswith(".json") else None
            got = validate_files(judged, opts.data, options, feasible=feasible, recorded=read)
    except DynidError:
        return None
    error = float(got.validation.errors.relative_error_percent)
    names = [Path(p).name for p in opts.data]
    fitted = () if (record := _fitted_record(judged, feasible)) is None else record.fitted_on(names)
    count = (len(fitted), len(opts.data))
    return ModelCheck(got.verdict, error, float(got.noise_floor_percent), count)


def _fitted_record(
    judged: IdentifiedModel | Robot, feasible: str | None
) -> IdentificationInfo | None:
    """The record of the recordings ``judged`` was fitted on: an identified model's own,
    or that of the ``identification.json`` beside a ``feasible.json`` (``identify
    --consistent`` writes both: :func:`~dynid.workflows.as_identified.identification_beside`,
    as ``validate --params`` finds it); None for a robot file."""
    if isinstance(judged, IdentifiedModel):
        return judged.info
    own = None if feasible is None else identification_beside(feasible, judged)
    return None if own is None else own.info


def _checked(
    th: Thresholds,
    logs: list[LogObservation],
    sigma_max: NDArray[np.float64] | None,
    peak: NDArray[np.float64],
    counted: tuple[int, QuietResidual] | None = None,
) -> CalibrationCheck:
    """The calibration's false alarms on its own logs and the residual's level there in
    shares of the threshold (read on their series when kept; ``counted`` on a second pass
    of the observer when not; no false alarm by construction with the largest ``|r|``)
    and its smallest detectable torques (:mod:`~dynid.observer.calibration_check`);
    ``peak`` the largest ``|r|`` [N m]."""
    kept = all(x.r is not None for x in logs)
    count, level = None, None
    if kept:
        series = [(x.t, x.series, x.std, x.standstill) for x in logs]
        count = calibration_false_alarms(th, series)
        level = calibration_quiet(th, series).level()
    elif counted is not None:
        count, level = counted[0], counted[1].level()
    if not kept and th.quantile >= 1.0:
        count = 0  # every sample's |r| lies under margin (>= 1) times the largest
    duration = float(sum(x.duration() for x in logs))
    moving = detectable(th, sigma_max)
    collision = collision_level(th, sigma_max)
    return CalibrationCheck(
        duration, count, sigma_max, moving, peak, collision=collision, level=level
    )


def _std(x: ObservedBlock) -> NDArray[np.float64]:
    assert x.std is not None
    return x.std


def _margin(x: ObservedBlock, n: int) -> NDArray[np.float64]:
    return np.zeros((x.r.shape[0], n)) if x.margin is None else x.margin


def _settled(x: ObservedBlock, n: int) -> NDArray[np.float64]:
    return np.full((x.r.shape[0], n), np.nan) if x.settled is None else x.settled


def _observation(
    prep: PreparedLog,
    model: ObserverModel,
    cmap: ColumnMap | None,
    opts: ObserveOptions,
    keep: Series | None,
    peak: NDArray[np.float64],
    seen: FrictionModel | FrictionSum | None,
) -> LogObservation:
    """A log's observation from its series (None: not kept), its margin's peak and the
    friction it was observed with (``seen``)."""
    path, log = prep.path, prep.log

    def run() -> LogObservation:
        ext = None if keep is None else true_torques(prep, model, cmap)
        return LogObservation(
            path,
            log.t,
            None if keep is None else keep.r,
            None if keep is None else keep.std,
            [],
            None,
            ext,
            None if keep is None else keep.margin,
            tuple(a for a, _ in prep.spans),
            peak,
            friction=None if seen is model.friction else seen,
            recording=recording_note(prep),
            speed_max=speeds_of(prep, model),
        )

    return in_file(path, run)
