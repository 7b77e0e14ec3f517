"""Identify a load on a known arm from files: the entry point of ``dynid payload``, with
every policy the command applies, so that the Python API behaves as the command does.

* The data's kind (static data or torque logs, :func:`~.data_files.data_kind`) picks the
  route; static data come in one file, torque logs in one or more (a folder: its data
  files), read as :mod:`dynid.workflows.recordings` reads them (each problem one line
  naming the file; an identified model's recorded column map unless one is given).
* The arm is its model's whole prediction (:mod:`dynid.feasibility.payload_arm`): an
  identified model's armature or rotor inertias and friction, a robot's drive (the one
  given, or the ``[drive]`` table of its TOML) and own friction, or the drive and friction
  stored in a ``feasible.json``.
* Torque logs are prepared as identification prepared the model's (its recorded cut-off
  and decimation unless ``cutoff_hz`` is given; each recording, and each piece of one cut
  at a gap longer than ``max_gap_s``, on its own); what was used is recorded.
* Torque logs: the friction estimated beside the load is the classical, or the one
  ``identify`` chooses from the same recordings when the classical leaves more than
  3 x the torque noise, or ``terms`` (:mod:`dynid.feasibility.payload_friction`).
* ``gravity_only`` applies to static data; ``unloaded`` (the difference method) is data
  of the same kind: one static file, or one or more torque logs.
"""

from __future__ import annotations

import dataclasses
from collections.abc import Sequence
from dataclasses import dataclass
from pathlib import Path
from typing import Any, Literal

from ..exceptions import DataError, ModelError, OptionError
from ..feasibility.payload import (
    PayloadEstimate,
    identify_payload,
    model_with_payload,
    robot_with_payload,
)
from ..feasibility.payload_arm import ArmFriction
from ..feasibility.payload_friction import friction_structure
from ..identification.model import IdentifiedModel, kinematics_of
from ..identification.pieces import recording_line
from ..identification.spikes import SPIKES_BEFORE_FIT
from ..identification.structure import Structure
from ..io.feasible import (
    load_feasible_column_map,
    load_feasible_drive,
    load_feasible_linear_friction,
)
from ..model.drive import Drive
from ..model.robot import Robot
from .as_identified import identification_beside, read_as_identified
from .data_files import ColumnSpec, column_map, data_kind, in_file, read_static_file
from .export import ExportRobotOptions, RobotExport, export_robot
from .identify import data_files, parsed_terms
from .options import Cutoff, library_cutoff, velocity_cutoff
from .recordings import despiked_recordings, read_recordings

__all__ = ["PayloadFileResult", "identify_payload_files"]


@dataclass(frozen=True, slots=True, eq=False)
class PayloadFileResult:
    """Result of :func:`identify_payload_files`.

    Attributes
    ----------
    estimate : PayloadEstimate
    kind : str
        ``"static"`` or ``"torque_log"``.
    """

    estimate: PayloadEstimate
    kind: str

    @property
    def recordings(self) -> tuple[Any, ...]:
        """Torque logs: per file, ``file``, ``pieces``, ``samples`` and ``duration_s``
        used; static data: empty."""
        return tuple(self.estimate.recordings)

    @property
    def skipped(self) -> tuple[str, ...]:
        """One line per piece left out (too short to filter)."""
        return self.estimate.skipped

    def robot_with_load(self, arm: Robot) -> Robot:
        """The robot ``arm`` carrying the load: the estimated load added to the link of its
        frame.

        Raises
        ------
        ModelError
            ``arm`` is an identified model: its base parameters are combinations of the
            links' parameters, not a robot's links (:meth:`model_with_load`).
        """
        if isinstance(arm, IdentifiedModel):
            raise ModelError(
                "an identified model holds base parameters (combinations of the links' "
                "parameters), not a robot's links: its model with the load is "
                "model_with_load (a robot of links: dynid retrieve or identify --consistent)"
            )
        return robot_with_payload(arm, self.estimate)

    def model_with_load(self, model: IdentifiedModel) -> IdentifiedModel:
        """The identified model ``model`` carrying the load: the load's parameters added to
        its base parameters, its friction, rotor inertias, offsets and drive kept
        (:func:`~dynid.feasibility.payload.model_with_payload`)."""
        return model_with_payload(model, self.estimate)

    def export_with_load(
        self, robot: str | Path, out: str | Path, options: ExportRobotOptions | None = None
    ) -> RobotExport:
        """What ``dynid export`` writes of the robot file ``robot`` (a ``feasible.json``
        with its friction and drive, a robot TOML with its ``[drive]``, a URDF, a built-in
        name) to ``out``, the robot carrying the load (:func:`~.export.export_robot`)."""
        plan = export_robot(robot, out, options)
        return dataclasses.replace(plan, robot=self.robot_with_load(plan.robot))

    def describe(self) -> str:
        """``"a.csv: 2 pieces, 3000 samples, cut at the gap(s) after ..."``, a line per
        recording with its gaps and its stamps' jitter as ``identify`` says them
        (:func:`~dynid.identification.pieces.recording_line`; empty for static data)."""
        return "\n".join(recording_line(r) for r in self.recordings)


def identify_payload_files(
    arm: Robot | IdentifiedModel,
    data: str | Path | Sequence[str | Path],
    *,
    unloaded: str | Path | Sequence[str | Path] | None = None,
    frame: str = "flange",
    gravity_only: bool = False,
    columns: ColumnSpec | None = None,
    drop_invalid: bool = False,
    cutoff_hz: Cutoff = None,
    max_gap_s: float | None = None,
    drive: Drive | None = None,
    feasible: str | Path | None = None,
    q_start: tuple[float, ...] | None = None,
    terms: str | Structure | None = None,
) -> PayloadFileResult:
    """The load fixed to ``frame`` from data recorded with it (module docstring).

    Parameters
    ----------
    arm : Robot or IdentifiedModel
        The arm without the load.
    data : str, Path or a sequence of them
        Static data (one file) or one or more torque logs (a folder: its data files).
    unloaded : str, Path or a sequence of them, optional
        The same kind of data without the load (difference method): one static file, or
        one or more torque logs.
    frame, gravity_only
        As :func:`~dynid.feasibility.payload.identify_payload`.
    columns : (str or None, str or None), optional
        ``--columns`` and ``--units`` of files of another tool (default: an identified
        model's recorded ones, or those a ``feasible`` file records).
    drop_invalid : bool
        Drop invalid rows (counted) instead of failing; False: torque logs as an
        identified ``arm``'s identification did
        (:func:`~dynid.workflows.as_identified.read_as_identified`, with a note).
    cutoff_hz : float or "none", optional
        Torque logs: zero-phase low-pass cut-off [Hz]; default: the identification's
        recorded one (with its decimation; none if it was identified without), else the one
        read from the motion; ``"none"`` (:data:`~dynid.workflows.options.NO_FILTER`): none.
        Refused with static data, which are not filtered.
    max_gap_s : float, optional
        Torque logs: longest gap bridged [s]; a longer one cuts a log into pieces; default:
        an identified ``arm``'s recorded one (a note names it), else the default rule.
    drive : Drive, optional
        The drive the data were recorded through, for an arm without one (a robot's known
        rotor inertias come from it).
    feasible : str or Path, optional
        The ``feasible.json`` the robot ``arm`` was read from: its drive and friction are
        the arm's.
    q_start : tuple of float, optional
        Torque logs: the joint positions [rad] at the first sample of the one motor-side
        log ``data`` whose encoders wrap (:func:`~dynid.workflows.recordings.given_start`).
    terms : str or Structure, optional
        Torque logs: the friction beside the load, as ``identify``'s ``terms`` names it
        (default ``"auto"``; :func:`~dynid.feasibility.payload.identify_payload`).

    Returns
    -------
    PayloadFileResult

    Raises
    ------
    UnknownNameError
        ``frame`` is not a frame of the arm.
    DataError
        A bad file; several static data files; ``gravity_only`` with torque logs; a
        recording in other units, read with the wrong torque sign by the ``--units``
        applied (hinting those that read it right) or without a piece long enough to filter
        (each named); one ``arm`` was identified from, without ``unloaded``.
    OptionError
        ``terms`` with static data, or naming an unknown term, an armature or a spring.
    """
    kin = kinematics_of(arm, "arm")
    structure = _friction_terms(terms)
    kin.frame(frame)  # an unknown frame is the option's error, not a file's
    paths = data_files(data)
    base = None if unloaded is None else data_files(unloaded)
    friction: ArmFriction = "own"
    if feasible is not None:
        drive = drive or load_feasible_drive(feasible)
        friction = load_feasible_linear_friction(feasible) or "own"
    recorded = arm.info.log if isinstance(arm, IdentifiedModel) else None
    given = velocity_cutoff(cutoff_hz)
    known = given if cutoff_hz is not None or recorded is None else recorded.cutoff_hz
    read_drive = arm.drive if isinstance(arm, IdentifiedModel) and drive is None else drive
    cmap = column_map(*(columns or (None, None)), cutoff_hz=known, drive=read_drive)
    kind = data_kind(paths[0], cmap)
    common: dict[str, Any] = dict(frame=frame, drive=drive, friction=friction)
    if kind != "torque_log":
        _logs_only(q_start=q_start, terms=terms, cutoff_hz=cutoff_hz)
        return _static(arm, kin, paths, base, cmap, drop_invalid, gravity_only, common)
    if gravity_only:
        raise DataError("--gravity-only applies to static data (q, g), not to a torque log")
    drop_invalid, max_gap_s = read_as_identified(_logs_read(arm, feasible), drop_invalid, max_gap_s)
    read_as: dict[str, Any] = dict(
        recorded=_recorded_columns(arm, feasible), columns=columns, drop_invalid=drop_invalid,
        cutoff_hz=known, drive=read_drive, sign_map=True,
    )  # fmt: skip
    rec = read_recordings(
        paths, kin, owner=f"robot {kin.name!r}", q_start=q_start, max_gap_s=max_gap_s, **read_as
    )
    rec, _ = despiked_recordings(rec, kin.joint_names, SPIKES_BEFORE_FIT)  # as identify
    without_rec = None
    if base is not None:
        without_rec = read_recordings(base, kin, owner=f"robot {kin.name!r}", **read_as)
        without_rec, _ = despiked_recordings(without_rec, kin.joint_names, SPIKES_BEFORE_FIT)
    fit = lambda: identify_payload(  # noqa: E731
        arm,
        rec.logs,
        names=rec.names,
        unloaded=None if without_rec is None else without_rec.logs,
        unloaded_names=None if without_rec is None else without_rec.names,
        cutoff_hz=library_cutoff(cutoff_hz, "recorded"),
        max_gap_s=max_gap_s,
        terms=structure,
        **common,
    )
    est = in_file(paths[0], fit) if len(paths) == 1 else fit()
    return PayloadFileResult(est, "torque_log")


def _logs_read(arm: Robot | IdentifiedModel, feasible: str | Path | None) -> Any:
    """How the arm's own logs were read (:class:`~dynid.identification.info.LogInfo`): an
    identified model's record, else that of the ``identification.json`` beside a
    ``feasible`` file (:func:`~dynid.workflows.as_identified.identification_beside`), else
    None."""
    if isinstance(arm, IdentifiedModel):
        return arm.info.log
    if feasible is None or Path(feasible).suffix.lower() != ".json":
        return None
    own = identification_beside(feasible, arm)
    return None if own is None else own.info.log


def _logs_only(**given: Any) -> None:
    """Refuse the options of torque logs ``given`` (their values; None or ``"auto"``:
    not given) with static data: ``cutoff_hz`` a DataError (as before), the others an
    OptionError naming the field."""
    for name, value in given.items():
        if value is None or value == "auto":
            continue
        if name == "cutoff_hz":
            raise DataError(
                "--cutoff applies to torque logs (their low-pass); static data are not filtered"
            )
        raise OptionError("applies to torque logs, not static data", field=name)


def _friction_terms(terms: str | Structure | None) -> Structure | Literal["auto"]:
    """``terms`` parsed as identify parses them, an armature or a spring refused
    (:func:`~dynid.feasibility.payload_friction.friction_structure`) before a file is read."""
    structure = parsed_terms(terms)
    return friction_structure(structure) if isinstance(structure, Structure) else structure


def _static(
    arm: Robot | IdentifiedModel,
    kin: Robot,
    paths: list[Path],
    base: list[Path] | None,
    cmap: Any,
    drop_invalid: bool,
    gravity_only: bool,
    common: dict[str, Any],
) -> PayloadFileResult:
    """The static route of :func:`identify_payload_files`: one file with the load, and at
    most one without."""
    for given in (paths, base or []):
        if len(given) > 1:
            raise DataError(
                f"{given[0].name} holds static data: give one static data file ({len(given)} given)"
            )
    if base is not None and data_kind(base[0], cmap) != "static":
        raise DataError("--unloaded must be static data like --data", file=base[0].name)

    def read(p: Path) -> Any:
        return read_static_file(
            p, kin, columns=cmap, drop_invalid=drop_invalid, require_M=not gravity_only
        )

    static = read(paths[0])
    without = None if base is None else read(base[0])
    est = in_file(
        paths[0],
        lambda: identify_payload(
            arm, static, gravity_only=gravity_only, unloaded=without, **common
        ),
    )
    return PayloadFileResult(est, "static")


def _recorded_columns(
    arm: Robot | IdentifiedModel, feasible: str | Path | None
) -> dict[str, Any] | None:
    """How the arm's own data were read: an identified model's recorded column map, else
    the one a ``feasible.json`` records (its fit's: the sign flips and units reused as
    with ``--model``), else None."""
    if isinstance(arm, IdentifiedModel):
        return None if arm.info.column_map is None else dict(arm.info.column_map)
    if feasible is None or Path(feasible).suffix.lower() != ".json":
        return None
    return load_feasible_column_map(feasible)
