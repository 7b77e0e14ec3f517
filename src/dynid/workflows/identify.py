"""Identify from a data file: the entry point of ``dynid identify``, with every check the
command applies, so that the Python API behaves as the command does.

* The file's kind (static data or a torque log, :func:`~.data_files.data_kind`) picks the
  route; the data are read strictly and checked against the robot
  (:mod:`dynid.workflows.data_files`: joint count, recorded robot, log cleaning).
* Static data: configurations outside the joint limits and a relative error far above
  the recorded noise level are :class:`~dynid.exceptions.DynidWarning` warnings.
* ``std`` (standard deviations) is honoured on both routes and with the consistent fit
  (default: robust for static data, hac for torque logs; the consistent fit's data term is
  the residual itself whichever is reported); the consistent fit refuses
  ``max_std_percent`` (it prunes nothing), and the prior, its weight, objective, margin
  and mass band apply to the consistent fit only (:class:`IdentifyOptions`).
* The column map the data were read with is recorded in the model (``info.column_map``).
* From torque logs, the held-out prediction (:mod:`dynid.friction.heldout_torques`: the
  last time block, every recording predicted by the fit of the others, or the
  ``validate_on`` log, every sample) is made
  from the logs read for the fit, each file read once, and returned with the model.
* From torque logs, where the held-out verdict names a tilted base, the identification is
  made again with the gravity vector the data read as and the model held out better kept,
  its robot carrying that gravity (:mod:`~dynid.workflows.gravity_refit`; a level arm is
  identified once).
* Torque logs once read go through :func:`identify_logs`, the entry point of a caller that
  holds :class:`~dynid.identification.log.TorqueLog` objects: the structure search, a
  current log's torque constants judged first (:mod:`~dynid.workflows.gains_first`), and
  the consistent fit of the model the search kept; where the constants were judged first,
  that is the corrected search's model, fitted to the efforts its factors correct (its
  drive's torque constants times them), whose held-out verdict names the factors.

Every refusal of an option is an :class:`~dynid.exceptions.OptionError` carrying the
option's field; the command line names it by its flag.
"""

from __future__ import annotations

import dataclasses
import logging
import warnings
from collections.abc import Callable, Sequence
from dataclasses import dataclass
from pathlib import Path
from typing import Any, Literal

from .._checks import caller_level
from ..exceptions import DataError, DynidError, DynidWarning, OptionError
from ..feasibility.convex import (
    DEFAULT_SDP_MARGIN,
    ConsistentResult,
    SDPOptions,
    consistent_from_identified,
    identify_consistent,
)
from ..feasibility.payload_arm import model_structure
from ..friction.delay_check import logs_delay
from ..friction.heldout_torques import HeldOutTorques, heldout_torques
from ..identification.confounded_offset import with_confounded_offsets
from ..identification.consistency import fit_mismatch, limit_violations
from ..identification.constants_checked import CONSTANTS_CHECKED, constants_record
from ..identification.core import model_loose, shared_bases
from ..identification.data import StaticDataset
from ..identification.dissipation import ReversedSignError
from ..identification.estimators import ESTIMATORS, EstimatorName
from ..identification.gravity_scale import (
    GRAVITY_SCALE,
    gravity_masses_words,
    gravity_scale_factor,
    gravity_scale_words,
)
from ..identification.least_squares import LOOSE_ADVICE, STD_METHODS, StdMethod, loose_note
from ..identification.log import TorqueLog, checked_log, checked_logs
from ..identification.model import IdentifiedModel
from ..identification.motor_constants import shared_gear_ratio
from ..identification.once_per_run import shared_run
from ..identification.recording_offsets import identify_with_offsets
from ..identification.residual_dependence import outside_model_note, round_off_note
from ..identification.selection import fitted_logs, identify_recordings
from ..identification.static import identify_static
from ..identification.static_flange import data_flange_note
from ..identification.structure import Structure
from ..identification.torque_delay import TorqueDelay
from ..identification.training_range import endless_joints, outside_training
from ..model.drive import Drive
from ..model.robot import Robot, checked_robot
from ..progress import NOTE
from .data_files import (
    ColumnSpec,
    check_file_entries,
    column_map,
    data_files,
    data_kind,
    in_file,
    read_static_file,
    read_torque_log,
)
from .gains_first import (
    UNKNOWN_SCALE,
    CorrectedSearch,
    gains_first,
    reason_to_judge_first,
    unknown_scale,
)
from .gravity_refit import FittedGravity, refit_gravity
from .options import (
    Cutoff,
    check_band,
    check_choice,
    check_count,
    check_cutoff,
    check_number,
    checked_options,
    library_cutoff,
    only_with,
    refused_with,
    velocity_cutoff,
)
from .prior import load_prior
from .recordings import (
    Recorded,
    check_derived_velocities,
    check_limits,
    check_sign_map,
    check_signs,
    check_torque_unit,
    check_unit_findings,
    check_units,
    checked_accelerations,
    given_start,
    given_units,
    note_unread_columns,
    unwrapped_recorded,
    usable_recorded,
)
from .static_outliers import without_outlying

__all__ = [
    "ColumnSpec",
    "IdentifyOptions",
    "IdentifyResult",
    "data_files",
    "identify_files",
    "identify_logs",
    "parsed_terms",
]

_log = logging.getLogger(__name__)


def _columns(spec: ColumnSpec | None, cutoff_hz: Cutoff, drive: Drive | None, robot: Robot) -> Any:
    cut = velocity_cutoff(cutoff_hz)
    return None if spec is None else column_map(*spec, cutoff_hz=cut, drive=drive, robot=robot)


def _heldout(
    paths: Sequence[Path],
    kind: str,
    folds: int | None,
    validate_on: str | Path | None,
    robot: Robot,
    cmap: Any,
    drop_invalid: bool,
) -> dict[str, Any]:
    """``folds``/``validate_on`` of the torque-log routes (the log read as ``paths[0]``
    is, and checked with the recordings: :func:`_read_logs`); refused for static data,
    ``folds`` with several recordings (each recording is a fold), ``validate_on`` one of
    the recordings (or a copy)."""
    if folds is None and validate_on is None:
        return {}
    path = paths[0]
    if kind != "torque_log":
        raise OptionError(
            f"applies to torque logs, not static data ({path.name})",
            field="folds" if folds is not None else "validate_on",
        )
    if folds is not None and len(paths) > 1:
        raise OptionError(
            f"sets time blocks of one recording; with {len(paths)} recordings each one is "
            "left out in turn (the folds are the recordings)",
            field="folds",
        )
    kw: dict[str, Any] = {} if folds is None else {"folds": folds}
    if validate_on is not None:
        try:  # the same file, however named, or a copy of one of the recordings
            data_files([*paths, Path(validate_on)])
        except DataError:
            raise OptionError(
                f"{Path(validate_on).name} is one of the recordings fitted (or a copy of one): "
                "judged on it, the held-out error is the training error; hint: a recording "
                "the fit does not see",
                field="validate_on",
            ) from None
        kw["validate_on"] = read_torque_log(
            validate_on,
            robot.n,
            columns=cmap,
            drop_invalid=drop_invalid,
            owner=f"robot {robot.name!r}",
            robot=robot,
        )
    return kw


def _record(model: IdentifiedModel, opt: IdentifyOptions) -> IdentifiedModel:
    """The model with the column map its data were read with (``info.column_map``) and,
    of torque logs, whether their invalid rows were dropped (``info.log.drop_invalid``)."""
    info, spec = model.info, opt.columns
    if opt.drop_invalid and info.log is not None:
        info = dataclasses.replace(info, log=dataclasses.replace(info.log, drop_invalid=True))
    if spec is not None and spec != (None, None):
        info = dataclasses.replace(info, column_map={"columns": spec[0], "units": spec[1]})
    return model if info is model.info else dataclasses.replace(model, info=info)


def parsed_terms(terms: str | Structure | None) -> Structure | Literal["auto"]:
    """``terms``: ``"auto"``/None (chosen on held-out data) or the terms named
    (``"viscous,smooth:10,offset"``, :meth:`~dynid.identification.structure.Structure.parse`).

    Raises
    ------
    OptionError
        An empty list, a term named twice, or one unknown (``field`` ``terms``).
    """
    if terms is None or terms == "auto":
        return "auto"
    if isinstance(terms, Structure):
        return terms
    words = [w.strip() for w in terms.replace("+", ",").split(",")]
    if not any(words):
        raise OptionError(
            "is empty: name the terms (viscous,coulomb), links for none, or auto", field="terms"
        )
    names = [w.partition(":")[0] for w in words if w]
    twice = sorted({w for w in names if names.count(w) > 1})
    if twice:
        raise OptionError(f"names {', '.join(twice)} twice", field="terms")
    return Structure.parse(terms)


#: Options of the one-step consistent fit only (refused without ``consistent``).
CONSISTENT_ONLY = (
    "prior",
    "prior_base",
    "prior_tip",
    "prior_weight",
    "objective",
    "margin",
    "total_mass",
)


@dataclass(frozen=True, slots=True)
class IdentifyOptions:
    """How :func:`identify_files` identifies a robot from its data.

    Attributes
    ----------
    terms : str or Structure, optional
        Torque logs: the model's terms beside the links (``"armature,viscous"``,
        :class:`~dynid.identification.structure.Structure`); default ``"auto"``: chosen
        on held-out data (:mod:`dynid.identification.selection`).
    columns : (str or None, str or None), optional
        Column names and units of a file of another tool (recorded in the model).
    drop_invalid : bool
        Drop invalid rows (counted, named) instead of failing.
    max_std_percent : float, optional
        Remove the coefficients above this relative standard deviation [%] and re-fit.
    rtol : float, optional
        Fixed relative rank tolerance, 0 < rtol < 1 (default: the first clear gap).
    std : {"classical", "robust", "hac"}, optional
        Standard deviations (default robust for static data, hac for a log; with
        ``consistent`` too, those of the unconstrained fit it returns).
    estimator : {"auto", "ols", "wls", "irls"}
        Least squares: ordinary, weighted by the noise level, or Huber-reweighted;
        ``"auto"`` (default): of a torque log, ordinary or weighted chosen on held-out data
        (:mod:`dynid.identification.estimator_choice`), of static data ordinary.
    drive : Drive, optional
        The drive train the data were recorded through.
    cutoff_hz : float or "none", optional
        Torque logs: zero-phase low-pass cut-off [Hz] (default: read from the log); also
        the cut-off of velocities derived from positions through ``columns``.
        ``"none"`` (:data:`~dynid.workflows.options.NO_FILTER`): no low-pass, every
        sample kept (no decimation); recorded, so that validate and friction reuse it.
    max_gap_s : float, optional
        Torque logs: longest gap bridged by interpolation [s]; a longer one cuts the log.
    torque_delay_s : float, optional
        Torque logs: how far the torques lag the positions [s] (positive: the torques
        late): each piece's torques read that much later before filtering
        (:attr:`~dynid.identification.prepare.Preprocessing.torque_delay_s`); recorded, so
        that validate and friction reuse it.
    q_start : tuple of float, optional
        Torque logs: the joint positions [rad] at the first sample of one motor-side log
        whose motor encoders wrap every turn: the motors' whole turns are those that put
        the joints nearest them (:func:`~dynid.workflows.recordings.given_start`).
    folds : int, optional
        Torque logs: contiguous time blocks of the held-out judgement (>= 2).
    validate_on : str or Path, optional
        Torque logs: judge on this separate log (read as the data) instead of time blocks.
    keep_outlying : bool
        Torque logs: fit the recordings found outlying too (default: the structure is
        chosen without them and the final fit leaves them out,
        :func:`~dynid.identification.selection.identify_recordings`). Static data: fit
        the configurations found outlying too (default: left out,
        :func:`~dynid.workflows.static_outliers.without_outlying`).
    consistent : bool
        Also identify physically consistent link parameters in one step (convex).
    prior : str, Path or Robot, optional
        ``consistent``: the prior link parameters (``"panda"``, ``"fr3"``, a robot file or
        a ``feasible.json``, :func:`~dynid.workflows.prior.load_prior`); default the
        robot's own inertials (generic without any).
    prior_base, prior_tip : str, optional
        ``consistent``: the chain of a URDF prior.
    prior_weight : float, optional
        ``consistent``: weight of the distance to the prior (>= 0; default automatic).
    objective : {"logdet", "euclidean"}, optional
        ``consistent``: distance to the prior (default log-det).
    margin : float, optional
        ``consistent``: every link's lambda_min(J) >= margin tr(J), 0 <= margin < 0.25.
    total_mass : (float, float), optional
        ``consistent``: band [kg] on the total mass, 0 <= min <= max.

    Raises
    ------
    OptionError
        A value out of its range or choices; a consistent-only option without
        ``consistent``; ``max_std_percent`` with it (``field`` names it).
    """

    terms: str | Structure | None = None
    columns: ColumnSpec | None = None
    drop_invalid: bool = False
    max_std_percent: float | None = None
    rtol: float | None = None
    std: StdMethod | None = None
    estimator: EstimatorName | Literal["auto"] = "auto"
    drive: Drive | None = None
    cutoff_hz: Cutoff = None
    max_gap_s: float | None = None
    torque_delay_s: float | None = None
    q_start: tuple[float, ...] | None = None
    folds: int | None = None
    validate_on: str | Path | None = None
    keep_outlying: bool = False
    consistent: bool = False
    prior: str | Path | Robot | None = None
    prior_base: str | None = None
    prior_tip: str | None = None
    prior_weight: float | None = None
    objective: str | None = None
    margin: float | None = None
    total_mass: tuple[float, float] | None = None

    @property
    def static_estimator(self) -> EstimatorName:
        """The estimator of static data: ``"auto"`` is ordinary least squares there (the
        choice on held-out folds is made of torque logs)."""
        return "ols" if self.estimator == "auto" else self.estimator

    def __post_init__(self) -> None:
        for name in ("max_std_percent", "max_gap_s"):
            check_number(self, name)
        check_number(self, "torque_delay_s", low=-1.0, high=1.0)
        check_cutoff(self)
        check_number(self, "rtol", high=1.0, high_open=True)
        check_number(self, "prior_weight", low_open=False)
        check_number(self, "margin", low_open=False, high=0.25, high_open=True)
        check_count(self, "folds", low=2)
        check_choice(self, "estimator", (*ESTIMATORS, "auto"), optional=False)
        check_choice(self, "std", STD_METHODS)
        check_choice(self, "objective", ("logdet", "euclidean"))
        check_band(self, "total_mass")
        only_with(self, CONSISTENT_ONLY, "consistent")
        refused_with(
            self,
            ("max_std_percent",),
            "consistent",
            "nothing is pruned; its data term is the residual itself, weighted by the estimator",
        )
        refused_with(
            self,
            ("torque_delay_s",),
            "consistent",
            "the one-step consistent fit prepares its logs without a delay; identify without "
            "--consistent, then dynid retrieve",
        )
        if self.terms is not None and not isinstance(self.terms, Structure):
            parsed_terms(
                self.terms
            )  # parsed now: a misspelt term is refused before any file is read

    def sdp(self) -> SDPOptions:
        """The settings of the convex fit (``consistent``)."""
        return SDPOptions(
            objective=self.objective or "logdet",
            prior_weight=self.prior_weight,
            margin=DEFAULT_SDP_MARGIN if self.margin is None else self.margin,
        )


@dataclass(frozen=True, slots=True, eq=False)
class IdentifyResult:
    """Result of :func:`identify_files`.

    Attributes
    ----------
    model : IdentifiedModel
        The unconstrained fit (with the column map its data were read with); of a current
        log whose torque constants were judged first, the corrected search's model,
        fitted to the efforts the factors correct (its drive holds the corrected
        constants; its held-out verdict names the factors).
    consistent : ConsistentResult or None
        With ``consistent``: the physically consistent link parameters (``feasible``
        says whether they satisfy every constraint); where the torque constants were
        judged first, of the corrected search's model, fitted to the efforts the factors
        correct (``drive``: the corrected constants; a note names the factors).
    files : tuple of Path
        The data files read, in order.
    heldout : HeldOutTorques or None
        Torque logs: the unconstrained fit's prediction of the data it held out, every
        sample (:func:`~dynid.friction.heldout_torques.heldout_torques`; ``heldout.json``
        and the held-out figures); None for static data, or when it could not be made (a
        :class:`~dynid.exceptions.DynidWarning` says why).
    torque_delay : TorqueDelay or None
        Torque logs: the lag of the torques behind the positions the fit's residual on its
        own recordings points to (:func:`~dynid.friction.delay_check.logs_delay`; beyond
        the ``torque_delay_s`` given); None for static data or the consistent fit. When
        :attr:`~dynid.identification.torque_delay.TorqueDelay.named`, the model's notes
        say it and ``identification.json``'s metadata hold it (``torque_delay``).
    gravity : FittedGravity or None
        Torque logs: the gravity vector fitted where the held-out verdict of the
        description's named a tilted base and the model identified with the vector the
        data read as predicts the held-out data better
        (:func:`~dynid.workflows.gravity_refit.refit_gravity`): ``model.robot`` carries it,
        a note says it and ``identification.json``'s metadata hold it
        (``gravity_fitted``); None otherwise (a level arm: fitted once, as before).
    """

    model: IdentifiedModel
    consistent: ConsistentResult | None
    files: tuple[Path, ...]
    heldout: HeldOutTorques | None = None
    torque_delay: TorqueDelay | None = None
    gravity: FittedGravity | None = None


def identify_files(
    robot: Robot,
    data: str | Path | Sequence[str | Path],
    options: IdentifyOptions | None = None,
) -> IdentifyResult:
    """The base parameters (and, from a torque log, the model's terms) of ``robot`` from
    ``data``; with ``options.consistent`` also physically consistent link parameters.

    Parameters
    ----------
    robot : Robot
        The robot the data belong to.
    data : str, Path or a sequence of them
        Static data (``q, M, g``), or one or more torque logs (a folder: its ``.csv``
        and ``.npz`` files), each ``.csv`` or ``.npz``.
    options : IdentifyOptions, optional

    Returns
    -------
    IdentifyResult

    Raises
    ------
    DataError
        A bad file, data of another robot or joint count, invalid rows without
        ``drop_invalid``.
    OptionError
        ``folds``, ``validate_on`` or ``terms`` with static data, ``max_gap_s`` with
        static data and ``consistent``; an unreadable prior (``field`` names it).
    """
    checked_robot(robot)
    opt = checked_options(options, IdentifyOptions)
    paths = data_files(data)
    prior = _prior(robot, opt)
    path = paths[0]
    cmap = _columns(opt.columns, opt.cutoff_hz, opt.drive, robot)
    check_file_entries(cmap, [*paths, *([] if opt.validate_on is None else [opt.validate_on])])
    kind = data_kind(path, cmap)
    heldout = _heldout(paths, kind, opt.folds, opt.validate_on, robot, cmap, opt.drop_invalid)
    if kind != "torque_log":
        _one_static_file(paths, opt)
        static = read_static_file(path, robot, columns=cmap, drop_invalid=opt.drop_invalid)
        with shared_bases():  # the outlier search's base parameters are the fit's
            return _static_files(robot, paths, static, opt, prior)
    separate = heldout.get("validate_on")
    logs = _read_logs(robot, paths, cmap, opt, separate)
    read = dataclasses.replace(  # the logs read with the file options; the prior loaded
        opt, columns=None, drop_invalid=False, q_start=None, validate_on=None, prior=prior
    )

    def fit() -> IdentifyResult:
        try:
            return identify_logs(
                robot, logs, read, names=[p.name for p in paths], validate_on=separate
            )
        except ReversedSignError as exc:  # its hint beside the flips --units applied
            if (applied := _applied_flips(cmap)) is None:
                raise
            spec = opt.columns or (None, None)
            toml = str(spec[0] or "").lower().endswith(".toml")  # its own flips: unknown text
            raise exc.beside(applied, None if toml else spec[1]) from None

    got = in_file(path, fit) if len(paths) == 1 else fit()
    result = got.consistent
    if result is not None and result.identified is not None:
        result = dataclasses.replace(result, identified=_record(result.identified, opt))
    model = _record(got.model, opt)
    return IdentifyResult(model, result, tuple(paths), got.heldout, got.torque_delay, got.gravity)


def _applied_flips(cmap: Any) -> tuple[int, ...] | None:
    """The joints (from 0) whose torque columns the column map flips for every file
    (``--units tau2=-1``), or None when a file's own flips or a negated unit make the
    whole reading unknown to a hint."""
    if cmap is None:
        return ()
    if cmap.file_flips or cmap.file_signs or cmap.factor("tau") < 0:
        return None
    return tuple(cmap.flips.get("tau", ()))


def identify_logs(
    robot: Robot,
    logs: TorqueLog | Sequence[TorqueLog],
    options: IdentifyOptions | None = None,
    *,
    names: Sequence[str] | None = None,
    validate_on: TorqueLog | None = None,
) -> IdentifyResult:
    """What ``dynid identify`` does with torque logs once it has read them: the model's
    structure chosen on held-out data (or ``options.terms``), a current log's torque
    constants judged first when the structure chosen points to them
    (:mod:`~dynid.workflows.gains_first`), the held-out prediction and its verdict, the
    torques' delay, and with ``options.consistent`` the physically consistent fit of the
    same structure; :func:`identify_files` reads its files and calls this.

    Parameters
    ----------
    robot : Robot
        The robot the logs belong to.
    logs : TorqueLog or sequence of TorqueLog
        One or more recordings (SI units, read through ``options.drive`` when given).
    options : IdentifyOptions, optional
        As :func:`identify_files`; the options of files (``columns``, ``drop_invalid``,
        ``q_start``, ``validate_on``) are refused: read the files with them, or give the
        separate log as ``validate_on``.
    names : sequence of str, optional
        One name per recording, for messages and the record.
    validate_on : TorqueLog, optional
        A separate recording the held-out judgement is made on.

    Returns
    -------
    IdentifyResult
        ``files`` empty.

    Raises
    ------
    OptionError
        An option of files, or ``folds`` with several recordings.
    DataError, RankDeficientError
        As :func:`~dynid.identification.selection.identify_recordings`.
    """
    checked_robot(robot)
    opt = checked_options(options, IdentifyOptions)
    for name in ("columns", "drop_invalid", "q_start", "validate_on"):
        if getattr(opt, name) not in (None, False):
            raise OptionError(
                "applies to files (identify_files); with logs already read, read them with "
                "it (or give the separate log as validate_on)",
                field=name,
            )
    logs = checked_logs(logs)
    if validate_on is not None:
        checked_log(validate_on, "validate_on")
    if opt.folds is not None and len(logs) > 1:
        raise OptionError(
            f"sets time blocks of one recording; with {len(logs)} recordings each one is "
            "left out in turn (the folds are the recordings)",
            field="folds",
        )
    kw: dict[str, Any] = {} if opt.folds is None else {"folds": opt.folds}
    if validate_on is not None:
        kw["validate_on"] = validate_on
    shared = shared_gear_ratio(robot, logs, opt.drive)
    if shared is None:
        return _fit_logs(robot, logs, names, opt, kw, _prior(robot, opt))
    opt = dataclasses.replace(opt, drive=shared.corrected(opt.drive))  # type: ignore[arg-type]
    got = _fit_logs(robot, logs, names, opt, kw, _prior(robot, opt))
    said = shared.with_fit(robot, got.model, [log.q for log in logs]).sentence()
    warnings.warn(said, DynidWarning, stacklevel=caller_level())
    info = got.model.info
    info = dataclasses.replace(info, notes=(*info.notes, said))
    return dataclasses.replace(got, model=dataclasses.replace(got.model, info=info))


def _prior(robot: Robot, opt: IdentifyOptions) -> Robot | None:
    """The consistent fit's prior (``opt.prior`` read: :func:`~.prior.load_prior`)."""
    prior = opt.prior
    if opt.consistent and not isinstance(prior, Robot) and prior is not None:
        return load_prior(prior, robot, base=opt.prior_base, tip=opt.prior_tip)
    return prior if isinstance(prior, Robot) else None


def _fit_logs(
    robot: Robot,
    logs: Sequence[TorqueLog],
    names: Sequence[str] | None,
    opt: IdentifyOptions,
    heldout: dict[str, Any],
    prior: Robot | None,
) -> IdentifyResult:
    """The torque-log route of :func:`identify_logs` (``heldout``: the held-out
    judgement's ``folds``/``validate_on``): the search (:func:`_searched`), made again
    with the gravity vector the data read as where its held-out verdict names a tilted
    base (:func:`~dynid.workflows.gravity_refit.refit_gravity`: the model held out better
    kept, its robot carrying that gravity, a note saying so), the gravity scale's warning,
    and either the consistent fit of the model the search kept (:func:`_consistent_of`) or
    the torques' delay."""

    def search(robot: Robot) -> tuple[IdentifiedModel, HeldOutTorques | None, Any]:
        def fitted(
            structure: Structure | Literal["auto"], drive: Drive | None, spring: Sequence[int] = ()
        ) -> IdentifiedModel:
            return identify_with_offsets(
                robot,
                logs,
                names,
                fit=identify_recordings,
                structure=structure,
                max_std_percent=opt.max_std_percent,
                rtol=opt.rtol,
                max_gap_s=opt.max_gap_s,
                torque_delay_s=opt.torque_delay_s or 0.0,
                drive=drive,
                estimator=opt.estimator,
                std=opt.std or "hac",  # the consistent fit's data term is the residual itself
                cutoff_hz=library_cutoff(opt.cutoff_hz, "auto"),
                keep_outlying=opt.keep_outlying,
                spring_joints=spring,
                **heldout,
            )

        # the spring trial's fit repeats the search without it; the offsets' check and the
        # spring trial prepare the recordings the fit prepared
        with shared_run():
            return _searched(fitted, parsed_terms(opt.terms), opt.drive, logs, separate)

    separate = heldout.get("validate_on")
    kept = refit_gravity(robot, search)
    robot, (model, held, first), gravity = kept.robot, kept.searched, kept.gravity
    said, model = _loose_at_floor(kept.said, model, held)
    _say_once(said)  # the kept search's, each once as the default filter says them
    if gravity is not None:
        note = gravity.note()
        info = dataclasses.replace(
            model.info,
            notes=(*model.info.notes, note),
            extra={**model.info.extra, "gravity_fitted": gravity.as_dict()},
        )
        model = dataclasses.replace(model, info=info)
    logs = fitted_logs(model, logs)  # without the recordings found outlying
    model = _say_gravity_scale(robot, model, logs, opt.drive, held)
    model = _with_unknown_scale(model, held, robot.joint_names)
    model = _with_confounded(model, held)
    if opt.consistent:
        result = _consistent_of(robot, model, held, first, opt, prior)
        return IdentifyResult(model, result, (), held, None, gravity)
    model, delay = _with_torque_delay(model, logs, () if held is None else held.prepared)
    return IdentifyResult(model, None, (), held, delay, gravity)


def _consistent_of(
    robot: Robot,
    model: IdentifiedModel,
    held: HeldOutTorques | None,
    first: CorrectedSearch | None,
    opt: IdentifyOptions,
    prior: Robot | None,
) -> ConsistentResult:
    """The one-step consistent fit of the search's ``model``
    (:func:`~dynid.feasibility.convex.fit.consistent_from_identified`, as
    :func:`~dynid.feasibility.convex.fit.identify_consistent` makes it); where the torque
    constants were judged first (``first``), of the corrected search's model, fitted to
    the efforts its factors correct (its drive, the drive's torque constants times them,
    is the result's; a note names the factors); least squares' own held-out residual
    (``held``) said where the consistent fit's judgement rejects it
    (:func:`_with_outside_model_note`)."""
    result = consistent_from_identified(
        robot, model, kind="log", prior=prior, total_mass=opt.total_mass, options=opt.sdp()
    )
    if first is not None:
        result = dataclasses.replace(result, notes=(first.consistent_note(), *result.notes))
    unknown = model.info.extra.get(UNKNOWN_SCALE)
    if unknown is not None:  # fitted to the same efforts: the same unknown factors
        result = dataclasses.replace(result, notes=(*result.notes, unknown["finding"]))
    return _with_outside_model_note(result, held, robot.joint_names)


def _with_unknown_scale(
    model: IdentifiedModel, held: HeldOutTorques | None, joint_names: Sequence[str]
) -> IdentifiedModel:
    """``model`` with a note and its metadata's ``unknown_scale`` naming the motors whose
    effort's scale the data leave unknown beside those judged off
    (:func:`~dynid.workflows.gains_first.unknown_scale`), and, for a log of currents, its
    metadata's ``constants_checked``: which motors' constants the data checked, and to what
    (:func:`~dynid.identification.constants_checked.constants_record`), which a load
    weighed through them carries; as it was otherwise."""
    gains = None if held is None else held.gains
    checked = constants_record(gains)  # what a payload weighed through them carries
    if checked is not None:
        extra = {**model.info.extra, CONSTANTS_CHECKED: checked}
        model = dataclasses.replace(model, info=dataclasses.replace(model.info, extra=extra))
    found = unknown_scale(gains, model.drive, joint_names)
    if found is None:
        return model
    said = found.sentence()
    info = dataclasses.replace(
        model.info,
        notes=(*model.info.notes, said),
        extra={**model.info.extra, UNKNOWN_SCALE: found.as_dict()},
    )
    return dataclasses.replace(model, info=info)


def _predicted_heldout(
    model: IdentifiedModel, logs: Sequence[TorqueLog], separate: TorqueLog | None
) -> HeldOutTorques | None:
    """The held-out prediction of ``model`` fitted to ``logs`` (``separate``: the
    ``validate_on`` log, with the joints it takes outside the training's positions and
    velocities: :func:`~dynid.identification.training_range.outside_training`), from the
    logs as the fit took them (without those it left out,
    :func:`~dynid.identification.selection.fitted_logs`); one it cannot make (every
    held-out piece too short to filter) is a warning, never a failed identification."""
    logs = fitted_logs(model, logs)
    try:
        held = heldout_torques(model, logs[-1], separate=separate, others=logs[:-1])
    except DynidError as exc:
        warnings.warn(
            f"skipped the held-out prediction (heldout.json and its figures): {exc}",
            DynidWarning,
            stacklevel=caller_level(),
        )
        return None
    record = model.info.log
    if held is None or separate is None or record is None:
        return held
    ranges, log = (record.position_range, record.velocity_range), held.validation.log
    robot = model.robot
    turns = endless_joints(robot.q_min, robot.q_max, robot.prismatic)
    return dataclasses.replace(held, outside=outside_training(*ranges, [log.q], [log.dq], turns))


def _say_gravity_scale(
    robot: Robot,
    model: IdentifiedModel,
    logs: Sequence[TorqueLog],
    drive: Drive | None,
    held: HeldOutTorques | None = None,
) -> IdentifiedModel:
    """``model``, warned about and recording it when its gravity torques are one factor off
    the description's on every loaded joint
    (:func:`~dynid.identification.gravity_scale.gravity_scale_finding`: a warning, and
    ``gravity_scale`` in its metadata, ``factor`` and ``finding``, which ``payload`` reads:
    a load weighed through the model carries the factor); with a note in its notes when the
    joints' factors differ beyond their uncertainty, their common factor within what the
    description's masses make
    (:func:`~dynid.identification.gravity_scale.gravity_masses_words`: the description's
    masses, not the torques, are off; nothing to change); not when the held-out verdict
    names a factor per motor (``held.gains``, which holds the common one too): one
    judgement of the efforts' scale. Where the held-out gains read the current log's
    torque constants off by one common factor (:attr:`~dynid.identification.drive_gains.
    DriveGains.common`), the warning's fix is that factor, the one their line names: fitted
    with every motor's currents at once, it lies nearer the truth than the gravity torques'
    ratio (an SO-100 servo arm through constants 2.45 times the true ones, its link
    masses up to 15 % off: 0.415 against 0.421, the truth 0.408)."""
    if held is not None and held.gains is not None and held.gains.named:
        return model
    q = [log.q if drive is None else drive.joint_states(log.q)[0] for log in logs]
    factor = gravity_scale_factor(robot, model, q)
    if factor is None:
        return model
    if not factor.scale:
        said = gravity_masses_words(robot, factor)
        _log.log(NOTE, "%s", said)
        info = dataclasses.replace(model.info, notes=(*model.info.notes, said))
        return dataclasses.replace(model, info=info)
    gains = None if held is None else held.gains
    fix = None if gains is None or gains.effort != "current" else gains.common
    found = gravity_scale_words(robot, factor, drive, fix)
    warnings.warn(found, DynidWarning, stacklevel=caller_level())
    info = dataclasses.replace(
        model.info,
        notes=(*model.info.notes, found),
        extra={**model.info.extra, GRAVITY_SCALE: {"factor": factor.factor, "finding": found}},
    )
    return dataclasses.replace(model, info=info)


def _flange_note(robot: Robot, path: Path, data: Any, prior: Robot | None) -> str | None:
    """The note of a mass at the flange that static data ``data`` (read from ``path``)
    hold and the description (``prior``'s inertials where one is given) lacks
    (:func:`~dynid.identification.static_flange.data_flange_note`), said; or None."""
    said = data_flange_note(robot, data.q, data.g, prior)
    if said is not None:
        _log.log(NOTE, "%s: %s", path.name, said)
    return said


def _noted(model: IdentifiedModel, said: str | None) -> IdentifiedModel:
    """``model`` with ``said`` in its notes (``model`` itself for None)."""
    if said is None:
        return model
    return dataclasses.replace(
        model, info=dataclasses.replace(model.info, notes=(*model.info.notes, said))
    )


def _static_files(
    robot: Robot,
    paths: Sequence[Path],
    static: StaticDataset,
    opt: IdentifyOptions,
    prior: Robot | None,
) -> IdentifyResult:
    """:func:`identify_files` of the static data ``static`` read from ``paths[0]``: its
    outlying configurations left out, fitted unconstrained and, with
    ``opt.consistent``, consistent."""
    path = paths[0]
    static = without_outlying(robot, path, static, keep=opt.keep_outlying, drive=opt.drive)
    hand = _flange_note(robot, path, static, prior)
    if not opt.consistent:
        model = _noted(_static(robot, path, static, opt), hand)
        return IdentifyResult(model, None, tuple(paths))
    consistent, unconstrained = _consistent_static(robot, path, static, opt, prior)
    unconstrained = _noted(unconstrained, hand)
    consistent = dataclasses.replace(consistent, identified=unconstrained)
    return IdentifyResult(unconstrained, consistent, tuple(paths))


def _static(robot: Robot, path: Path, data: Any, opt: IdentifyOptions) -> IdentifiedModel:
    """The unconstrained fit of static data ``data`` read from ``path``; configurations
    outside the joint limits and a relative error far above the recorded noise warned."""
    outside = limit_violations(robot, data.q)
    if outside is not None:
        warnings.warn(f"{path.name}: {outside}", DynidWarning, stacklevel=caller_level())
    model = in_file(
        path,
        lambda: identify_static(
            robot,
            data,
            max_std_percent=opt.max_std_percent,
            rtol=opt.rtol,
            std=opt.std or "robust",
            drive=opt.drive,
            estimator=opt.static_estimator,
        ),
    )
    misfit = fit_mismatch(model.fit.relative_error_percent, data.metadata)
    if misfit is not None:
        warnings.warn(f"{path.name}: {misfit}", DynidWarning, stacklevel=caller_level())
    return _record(model, opt)


def _searched(
    fitted: Callable[..., IdentifiedModel],
    structure: Structure | Literal["auto"],
    drive: Drive | None,
    logs: Sequence[TorqueLog],
    separate: TorqueLog | None,
) -> tuple[IdentifiedModel, HeldOutTorques | None, CorrectedSearch | None]:
    """The model of ``structure``, its held-out prediction and the corrected search
    (None: not run, or no factor named); chosen (``"auto"``) through
    a current log's drive and pointing to the torque constants
    (:func:`~dynid.workflows.gains_first.reason_to_judge_first`), chosen again on the
    efforts corrected by the factors the richest structure names
    (:func:`~dynid.workflows.gains_first.gains_first`: its factors are the held-out
    verdict's), fitted to those efforts (its drive's torque constants times the factors),
    with a note saying so; the first model's warnings said only when it is kept."""
    current = drive is not None and drive.effort == "current"
    if structure != "auto" or not current:
        model = fitted(structure, drive)
        held = _predicted_heldout(model, logs, separate)
        if structure == "auto":
            model, held = _spring_judged(fitted, model, held, drive, logs, separate)
        return model, held, None
    with warnings.catch_warnings(record=True) as said:
        warnings.simplefilter("always")
        model = fitted(structure, drive)
        held = _predicted_heldout(model, logs, separate)
    why = reason_to_judge_first(model, held)
    chosen = model_structure(model)
    first = None if why is None else gains_first(fitted, drive, logs, separate, why, chosen)
    if first is None:
        for w in said:
            warnings.warn_explicit(w.message, w.category, w.filename, w.lineno)
        return model, held, None
    _say_once(first.said)
    model = first.searched  # fitted to the corrected efforts: no term takes up the constants
    info = dataclasses.replace(
        model.info,
        notes=(*model.info.notes, first.note()),
        extra={**model.info.extra, "gains_first": first.note()},
    )
    model = dataclasses.replace(model, info=info)
    held = _predicted_heldout(model, logs, separate)
    if held is not None and first.pattern is None:  # one judgement of the efforts' scale
        gains = None if first.gains is None else dataclasses.replace(first.gains, applied=True)
        held = dataclasses.replace(held, gains=gains, springs=None, tilt=None)
    return model, held, first


def _spring_judged(
    fitted: Callable[..., IdentifiedModel],
    model: IdentifiedModel,
    held: HeldOutTorques | None,
    drive: Drive | None,
    logs: Sequence[TorqueLog],
    separate: TorqueLog | None,
) -> tuple[IdentifiedModel, HeldOutTorques | None]:
    """The structure chosen again with a spring on the joints the held-out residual of
    ``model`` names (``held.springs``) judged as a candidate on the same folds
    (:func:`~dynid.identification.spring_candidate.with_spring`: kept only where the
    choice without it predicts worse beyond one standard error), and its held-out
    prediction; ``model`` and ``held`` as they are where none is named."""
    named = () if held is None or held.springs is None else held.springs.named
    if not named:
        return model, held
    model = fitted("auto", drive, named)
    return model, _predicted_heldout(model, logs, separate)


def _with_confounded(model: IdentifiedModel, held: HeldOutTorques | None) -> IdentifiedModel:
    """``model`` with a note per torque offset left out that its training data cannot tell
    from a link parameter (:func:`~dynid.identification.confounded_offset.
    with_confounded_offsets`, on the held-out prediction's prepared pieces: of one
    recording held out in time blocks, the whole of it as predicted), each said."""
    if held is None:
        return model
    blocks = model.holdout is not None and model.holdout.scheme == "blocks"
    pieces = held.prepared or ((held.validation.log,) if blocks else ())
    if not pieces:
        return model
    model, said = with_confounded_offsets(model, pieces)
    for note in said:
        _log.log(NOTE, "%s", note)
    return model


def _loose_at_floor(
    said: Sequence[warnings.WarningMessage], model: IdentifiedModel, held: HeldOutTorques | None
) -> tuple[list[warnings.WarningMessage], IdentifiedModel]:
    """The warnings ``said`` and ``model``; where the held-out verdict is at the noise
    floor, without the warning on coefficients above 1000 % std
    (:data:`~dynid.identification.least_squares.LOOSE_ADVICE`), said instead in one note
    (:func:`~dynid.identification.least_squares.loose_note`, in the model's notes): they
    do not change its predictions (a UR5's runs warned one to three of them, each time)."""
    if held is None or held.verdict.level != "good":
        return list(said), model
    kept = [w for w in said if LOOSE_ADVICE not in str(w.message)]
    loose = model_loose(model)
    if not loose:
        return kept, model
    note = loose_note(loose)
    _log.log(NOTE, "%s", note)
    info = dataclasses.replace(model.info, notes=(*model.info.notes, note))
    return kept, dataclasses.replace(model, info=info)


def _say_once(said: Sequence[warnings.WarningMessage]) -> None:
    """Warn each of ``said`` whose category and text no earlier one had (the corrected
    search and the refit of its structure find the same things)."""
    seen: set[tuple[type[Warning], str]] = set()
    for w in said:
        key = (w.category, str(w.message))
        if key not in seen:
            seen.add(key)
            warnings.warn_explicit(w.message, w.category, w.filename, w.lineno)


def _with_torque_delay(
    model: IdentifiedModel, logs: Sequence[TorqueLog], prepared: Sequence[TorqueLog] = ()
) -> tuple[IdentifiedModel, TorqueDelay | None]:
    """``model`` and the torques' delay its residual on ``logs`` points to
    (:func:`~dynid.friction.delay_check.logs_delay`; from ``prepared``, the held-out
    prediction's pieces of them, when it kept them), said in the model's notes and
    recorded in its metadata when named."""
    delay = logs_delay(model, logs, prepared)
    if delay is None or not delay.named:
        return model, delay
    info = dataclasses.replace(
        model.info,
        notes=(*model.info.notes, delay.sentence()),
        extra={**model.info.extra, "torque_delay": delay.as_dict()},
    )
    return dataclasses.replace(model, info=info), delay


def _read_logs(
    robot: Robot,
    paths: list[Path],
    cmap: Any,
    opt: IdentifyOptions,
    heldout: TorqueLog | None = None,
) -> list[Any]:
    """The torque logs ``paths``, read strictly for ``robot`` (recorded through
    ``opt.drive``); a recording in degrees among recordings in radians, with joints in
    degrees, in other units than the others, or in mN m read as N m, refused, and one far
    outside the joint limits warned about, naming it
    (:func:`~dynid.workflows.recordings.check_limits`,
    :func:`~dynid.workflows.recordings.check_units`,
    :func:`~dynid.workflows.recordings.check_torque_unit`); the whole turns of wrapped motors
    from ``q_start`` (:func:`given_start`). The held-out log of ``opt.validate_on``
    (``heldout``, read) is checked with them, and its sign too
    (:func:`~dynid.workflows.recordings.check_signs`; the fit checks the recordings'):
    judged on torques in other units or of the other sign, a held-out error says nothing.
    A recording the ``--units`` given read with the wrong torque sign is refused with the
    ``--units`` that read it right (:func:`~dynid.workflows.recordings.check_sign_map`)."""
    logs = [
        read_torque_log(
            p,
            robot.n,
            columns=cmap,
            drop_invalid=opt.drop_invalid,
            owner=f"robot {robot.name!r}",
            robot=robot,
            drive=opt.drive,
        )
        for p in paths
    ]
    names = [p.name for p in paths]
    logs = list(checked_accelerations(logs, names, velocity_cutoff(opt.cutoff_hz)))
    logs = list(given_start(logs, names, robot, opt.drive, opt.q_start, opt.max_gap_s))
    held: list[tuple[TorqueLog, Path]] = []
    if heldout is not None and opt.validate_on is not None:
        held.append((heldout, Path(opt.validate_on)))
    rec = Recorded((*logs, *(g for g, _ in held)), (*paths, *(p for _, p in held)), opt.drive)
    check_derived_velocities(rec, cmap)
    note_unread_columns(rec, cmap)
    checked = unwrapped_recorded(rec, robot, opt.max_gap_s)  # as the preparation reads them
    check_unit_findings(checked, robot, given_units(cmap, (opt.columns or (None, None))[1]))
    check_limits(checked, robot)
    rec, checked = usable_recorded(rec, checked, robot, opt.max_gap_s)
    check_units(checked)
    # every file's sign under the --units given (the fit's check of the torques as read
    # would hint the flip applied), then the held-out log's as read (the fit checks the rest)
    check_sign_map(checked, robot, (opt.columns or (None, None))[1])
    check_signs(checked.select(slice(len(logs), None)), robot)
    check_torque_unit(checked, robot, cmap)
    return list(rec.logs[: len(logs)])


def _one_static_file(paths: list[Path], opt: IdentifyOptions) -> None:
    """Static data come in one file, and have no terms to choose, no filter and no gaps."""
    if len(paths) > 1:
        raise DataError(
            f"{paths[0].name} holds static data: give one static data file ({len(paths)} given)"
        )
    if opt.terms is not None and opt.terms != "auto":
        raise OptionError(
            f"applies to torque logs, not static data ({paths[0].name})", field="terms"
        )
    given = {n: getattr(opt, n) is not None for n in ("cutoff_hz", "max_gap_s", "torque_delay_s")}
    given |= {"q_start": opt.q_start is not None}
    for name in (n for n, said in given.items() if said):
        raise OptionError(f"applies to torque logs, not static data ({paths[0].name})", field=name)


def _with_outside_model_note(
    result: ConsistentResult, held: HeldOutTorques | None, names: Sequence[str]
) -> ConsistentResult:
    """``result`` with the note that least squares' own held-out residual is systematic
    (:func:`~dynid.identification.residual_dependence.outside_model_note`) first, when its
    held-out judgement rejected it, or that it is exact to round-off, no systematic one
    (:func:`~dynid.identification.residual_dependence.round_off_note`); else ``result``
    itself."""
    if held is None or result.heldout is None or result.heldout.accepted:
        return result
    said: str | None
    if (exact := held.round_off) is not None:
        said = round_off_note(exact, "least squares' held-out prediction") + (
            ": the consistent fit's larger error is its constraints' and its prior's"
        )
    else:
        said = outside_model_note(held.systematic, names, held.terms)
    return result if said is None else dataclasses.replace(result, notes=(said, *result.notes))


def _consistent_static(
    robot: Robot, path: Path, data: Any, opt: IdentifyOptions, prior: Robot | None
) -> tuple[ConsistentResult, IdentifiedModel]:
    """The one-step consistent fit of static data ``data`` read from ``path``
    (:func:`~dynid.feasibility.convex.fit.identify_consistent`) and its unconstrained fit
    (``identified``), with the column map the data were read with."""
    result = in_file(
        path,
        lambda: identify_consistent(
            robot,
            data,
            rtol=opt.rtol,
            drive=opt.drive,
            estimator=opt.static_estimator,
            std=opt.std,
            prior=prior,
            total_mass=opt.total_mass,
            options=opt.sdp(),
        ),
    )
    if result.identified is None:  # pragma: no cover - identify_consistent always sets it
        raise DataError("the one-step identification returned no unconstrained fit")
    model = _record(result.identified, opt)
    return dataclasses.replace(result, identified=model), model
