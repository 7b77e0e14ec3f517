"""Measured data files as every workflow reads them: the kind of a file, torque logs and
static data read strictly (through a column map for files of other tools), checked
against the robot they belong to.

The policies, the same for the Python API and every command:

* a torque log whose cleaning dropped rows (NaN/inf, a repeated timestamp) is an error
  unless ``drop_invalid``; so is a log with another joint count than the robot's;
* a static data file must have the robot's joint count and, when it records the robot
  it was acquired with, be of that robot (:func:`dynid.io.static_data.load_static_data`);
* a model records the column map its data were read with (``info.column_map``);
  a log validated against it is read the same way (:func:`recorded_columns`).
"""

from __future__ import annotations

import contextlib
import dataclasses
import hashlib
import logging
import re
import shlex
import warnings
import zipfile
from collections.abc import Callable, Mapping, Sequence
from pathlib import Path
from typing import Any, Literal, TypeVar

import numpy as np

from .. import _checks
from .._checks import caller_level
from ..exceptions import DataError, DynidError, DynidWarning, OptionError
from ..exceptions import in_file as about_file
from ..identification.data import StaticDataset
from ..identification.log import MILLISECONDS_HINT, TorqueLog
from ..identification.unit_mix import unit_findings
from ..io.bag_hint import ROBOT, bag_hint, several_bags_hint
from ..io.column_hint import commanded_torques, missing_joints
from ..io.columns import (
    ColumnMap,
    header_names,
    load_column_map,
    load_mapped_static_data,
    load_mapped_torque_log,
    parse_column_map,
)
from ..io.input_files import regular_file
from ..io.static_data import load_static_data
from ..io.torque_log import load_torque_log
from ..model.drive import Drive
from ..model.robot import Robot
from ..progress import NOTE

__all__ = [
    "ColumnSpec",
    "DataKind",
    "check_file_entries",
    "column_map",
    "data_files",
    "data_kind",
    "in_file",
    "read_static_file",
    "read_torque_log",
    "recorded_columns",
    "with_import_robot",
]

_log = logging.getLogger(__name__)

#: What a data file holds.
DataKind = Literal["static", "torque_log"]

#: ``--columns``/``--units`` as typed (text or a TOML file; units), or None.
ColumnSpec = tuple[str | None, str | None]

_T = TypeVar("_T")

#: A column only static data hold: ``M<i>_<j>`` or ``g<i>``.
_STATIC_COLUMN = re.compile(r"M[1-9]\d*_[1-9]\d*|g[1-9]\d*")


def in_file(path: Path, fit: Callable[[], _T]) -> _T:
    """``fit()``, a :class:`~dynid.exceptions.DynidError` it raises naming the file when it
    names none (:func:`dynid.exceptions.in_file`: the same error, of the same class).

    Raises
    ------
    DynidError
        Whatever ``fit`` raises, its message starting with a file's name (``path.name``
        unless the error names its own; an option's error is left to name its flag).
    """
    with about_file(path.name):
        return fit()


def column_map(
    columns: str | None = None,
    units: str | None = None,
    *,
    cutoff_hz: float | None = None,
    drive: Drive | None = None,
    robot: Robot | None = None,
) -> ColumnMap | None:
    """The column map of ``--columns`` (text or a ``.toml`` file) and ``--units``, or None;
    the units declared logged once as a note (:meth:`~dynid.io.columns.ColumnMap.unit_note`),
    never a warning per file.

    Parameters
    ----------
    columns : str, optional
        ``'q=position_{i0},tau=effort_{i0}'`` or a TOML file with ``[columns]`` and
        ``[units]``.
    units : str, optional
        ``'q=deg,tau=mNm,t=ms'``; added to (and overriding) a TOML file's units.
    cutoff_hz : float, optional
        Cut-off [Hz] of the velocities derived from positions (default: the library's).
    drive : Drive, optional
        The drive the logs are read through: ``tau`` in ``A`` or ``mA`` needs one whose
        effort is current.
    robot : Robot, optional
        The robot the logs are read for: a unit of ``q``, ``dq``, ``ddq`` scales the
        joints of its kind alone (a length's the prismatic joints, an angle's the
        revolute ones: :meth:`~dynid.io.columns.ColumnMap.for_robot`), said in a note
        when the robot has both kinds.

    Raises
    ------
    DataError
        A malformed map or unit (named); a unit whose kind matches none of ``robot``'s
        joints (``q=mm`` for an arm of revolute joints alone).
    OptionError
        ``tau`` in a current's unit without a drive of effort = "current", or in a
        torque's unit with one.
    """
    if columns is None and units is None:
        return None
    kw = {} if cutoff_hz is None else {"velocity_cutoff_hz": cutoff_hz}
    if columns is not None and columns.lower().endswith(".toml"):
        cmap = load_column_map(columns, **kw)
        if units is not None:
            extra = parse_column_map(None, units)
            cmap = dataclasses.replace(
                cmap,
                factors={**cmap.factors, **extra.factors},
                names={**cmap.names, **extra.names},
                flips={**cmap.flips, **extra.flips},
                file_flips={**cmap.file_flips, **extra.file_flips},
                file_signs={**cmap.file_signs, **extra.file_signs},
                file_units={**cmap.file_units, **extra.file_units},
            )
    else:
        cmap = parse_column_map(columns, units, **kw)
    check_current_unit(cmap, drive)
    if (note := cmap.unit_note()) is not None:
        _log.info(note)
    if robot is not None:
        cmap = cmap.for_robot(robot.prismatic)
        for said in cmap.kind_notes(robot.joint_names):
            _log.log(NOTE, "%s", said)
    return cmap


def check_current_unit(cmap: ColumnMap | None, drive: Drive | None) -> None:
    """Refuse ``tau`` declared a current (``--units tau=mA``) unless ``drive`` makes
    currents torques (effort = "current", with its torque constants), and ``tau`` declared
    a torque (``--units tau=Nm``) with such a drive (its columns would be read as currents
    all the same).

    Raises
    ------
    OptionError
        Naming ``--units`` and the drive's effort.
    """
    if cmap is not None and cmap.tau_is_torque and drive is not None and drive.effort == "current":
        raise OptionError(
            f"--units tau={cmap.names['tau']} declares torques, but the drive's effort is "
            "'current': its tau columns are read as motor currents and turned into torques "
            "by its torque_constant; hint: leave tau's unit out (amperes), --units tau=mA "
            'for milliamperes, or a drive file with effort = "torque" for a log of torques'
        )
    if cmap is None or not cmap.tau_is_current:
        return
    if drive is None or drive.effort != "current":
        has = "no --drive" if drive is None else f"the drive's effort is {drive.effort!r}"
        raise OptionError(
            f"--units tau={cmap.names['tau']} declares motor currents, but {has}; give a "
            '--drive with effort = "current" and its torque_constant, or torques\' units '
            "(--units tau=Nm, tau=mNm, or a factor to N m)"
        )


def data_kind(path: str | Path, columns: ColumnMap | None = None) -> DataKind:
    """``"static"`` or ``"torque_log"``.

    A CSV whose header names static data's columns (``M<i>_<j>`` or ``g<i>``) and no
    ``t`` is static data, any other CSV (one without a header line or whose header names
    neither kind included) a torque log, whose reader names what is wrong in the words it
    uses whatever the other files given; an NPZ with ``t``/``tau`` is a torque log; with a
    column map, mapping ``t``, ``dq``, ``ddq`` or ``tau`` makes a torque log and mapping
    ``M`` or ``g`` static data.

    Raises
    ------
    DataError
        Neither ``.csv`` nor ``.npz``, an unreadable NPZ, not a regular file (a device, a
        pipe).
    OSError
        Missing, unreadable, a folder.
    """
    path = Path(path)
    regular_file(path)  # not a device that never ends (nor a folder, nor missing)
    if columns is not None:
        if any(columns.mapped(k) for k in ("t", "dq", "tau", "ddq")):
            return "torque_log"
        if any(columns.mapped(k) for k in ("M", "g")):
            return "static"
    suffix = path.suffix.lower()
    if suffix == ".csv":
        with path.open(encoding="utf-8-sig", errors="replace") as fh:
            for line in fh:
                s = line.strip()
                if s and not s.startswith("#"):
                    cols = [c.strip() for c in s.split(",")]
                    static = any(_STATIC_COLUMN.fullmatch(c) for c in cols)
                    return "static" if static and "t" not in cols else "torque_log"
        return "torque_log"  # no header line: its reader says so
    if suffix == ".npz":
        try:
            with np.load(path, allow_pickle=False) as z:
                keys = set(z.files)
        except (ValueError, EOFError, zipfile.BadZipFile) as exc:
            raise DataError(f"not a readable NPZ file ({exc})", file=path.name) from exc
        except (AttributeError, TypeError):  # a single .npy array: np.load gives an array
            raise DataError("a single array, not an NPZ archive", file=path.name) from None
        return "torque_log" if "t" in keys or "tau" in keys else "static"
    raise DataError(f"a data file must be .csv or .npz{bag_hint(path)}", file=path.name)


def with_import_robot(message: str, options: Sequence[str]) -> str:
    """``message`` with the robot of each ``dynid import`` it suggests
    (:data:`~dynid.io.bag_hint.ROBOT`)
    given as ``options``: the run's own robot options as typed (``["--robot", "arm.urdf",
    "--base", "b", "--tip", "t"]``), so that the import reads the same chain (a URDF of
    several leaves needs its ``--tip``), or ``["--model", "id/identification.json"]``;
    unchanged without ``--robot`` or ``--model`` among them."""
    if "--robot" not in options and "--model" not in options:
        return message
    return re.sub(
        r"(dynid import (?:\S+ )+?)" + re.escape(ROBOT),
        lambda m: m.group(1) + shlex.join(options),
        message,
    )


def check_file_entries(cmap: ColumnMap | None, paths: Sequence[str | Path]) -> None:
    """Refuse a file's own ``--units`` entry (``rec2.csv:tau4=-1``) that names none of
    ``paths`` (a typo would otherwise leave the file unflipped).

    Raises
    ------
    DataError
        Naming the entry's file and the files given.
    """
    names = [Path(p).name for p in paths]
    if cmap is not None and (bad := cmap.unknown_files(names)):
        raise DataError(
            f"--units {bad[0]}:...: {bad[0]} is none of the files given "
            f"({', '.join(names[:4])}{', ...' if len(names) > 4 else ''}); a file's own entry "
            "names it as --data does, without its folder"
        )


def read_torque_log(
    path: str | Path,
    n: int | None = None,
    *,
    columns: ColumnMap | None = None,
    drop_invalid: bool = False,
    owner: str | None = None,
    robot: Robot | None = None,
    drive: Drive | None = None,
) -> TorqueLog:
    """The torque log ``path``, read strictly, with ``n`` joints.

    A log of positions only whose time steps look like milliseconds cannot be read (its
    rate is too low to derive velocities); with ``robot`` it is read again with its time
    in ms to check its positions too, and a log in degrees as well is refused with both
    units said at once (``--units t=ms,q=deg``;
    :func:`~dynid.identification.unit_mix.unit_findings`).

    Parameters
    ----------
    path : str or Path
        A dynid torque log (CSV/NPZ), or a file of another tool read through ``columns``.
    n : int, optional
        Joint count the log must have.
    columns : ColumnMap, optional
        Column names and units of another tool's file (its notes are logged as warnings,
        the units it converts as notes).
    drop_invalid : bool
        Drop rows with NaN/inf or a repeated timestamp (logged) instead of failing.
    owner : str, optional
        What has ``n`` joints, for the message (default ``"the robot"``).
    robot : Robot, optional
        The robot of ``n`` joints: a log of fewer joints is told which joints of its chain
        it lacks (a gripper's, say) and the ``--tip`` link before them.
    drive : Drive, optional
        The drive the log was recorded through (its positions judged at the joints).

    Returns
    -------
    TorqueLog
        ``t`` (N,) [s], ``q``, ``dq``, ``tau`` (N, n) [rad, rad/s, N m].

    Raises
    ------
    DataError
        A bad file; invalid rows without ``drop_invalid``; another joint count than ``n``;
        a time column in ms, with the other units found.
    """
    try:
        return _read_torque_log(Path(path), n, columns, drop_invalid, owner, robot)
    except DataError as exc:
        if robot is None or MILLISECONDS_HINT not in str(exc):
            raise
        said = _units_in_ms(Path(path), n, columns, robot, drive, exc)
        if said is None:
            raise
        raise DataError(said, file=Path(path).name) from exc


def _units_in_ms(
    path: Path,
    n: int | None,
    columns: ColumnMap | None,
    robot: Robot,
    drive: Drive | None,
    exc: DataError,
) -> str | None:
    """The unit findings of ``path`` read with its time column in ms, the finding of
    ``exc`` first, when another unit is found too; None otherwise (or when the time
    column's unit was given, or the file cannot be read so either)."""
    if columns is not None and columns.factor("t") != 1.0:
        return None
    cm = columns if columns is not None else ColumnMap()
    if robot.n == n or n is None:
        cm = cm.for_robot(robot.prismatic)
    ms = dataclasses.replace(cm, factors={**cm.factors, "t": 1e-3}, names={**cm.names, "t": "ms"})
    try:
        log = load_mapped_torque_log(path, ms, n=n).log
    except DynidError:
        return None
    if n is not None and log.n != n:
        return None
    first = str(exc).removeprefix(f"{exc.file}: ") if exc.file else str(exc)
    found = unit_findings(robot, log, drive, ("ms", 1e-3), first)
    return None if found is None or found == first else found


def _read_torque_log(
    path: Path,
    n: int | None,
    columns: ColumnMap | None,
    drop_invalid: bool,
    owner: str | None,
    robot: Robot | None,
) -> TorqueLog:
    """:func:`read_torque_log`'s reading."""
    if columns is None:
        log = load_torque_log(path, drop_invalid=drop_invalid, joints=n)
    else:
        if robot is not None and n in (None, robot.n):  # each unit for its joints' kind
            columns = columns.for_robot(robot.prismatic)
        try:
            mapped = load_mapped_torque_log(path, columns, n=n)
        except DataError as exc:  # a chain past the log's joints: say how to cut it
            beyond = _chain_beyond(path, columns, n, owner, robot, exc)
            if beyond is None:
                raise
            raise beyond from exc
        said_of = commanded_torques(columns.template("tau"), header_names(path), mapped.log.n)
        if said_of is not None:  # a controller's torque read as measured: once per run
            warnings.warn(said_of, DynidWarning, stacklevel=caller_level())
        for note in mapped.conversions:  # as asked: a note
            _log.log(NOTE, "%s: %s", path.name, note)
        for note in mapped.notes:  # velocities derived: said once for every such recording
            _log.info("%s: %s", path.name, note)  # (recordings.check_derived_velocities)
        c = mapped.log.cleaning
        if c.n_nan_rows or c.n_duplicates:
            said = []  # as the strict reader says it (dynid.io.torque_log)
            if c.n_nan_rows:
                rows = f": {mapped.invalid_rows}" if mapped.invalid_rows else ""
                said.append(
                    f"{c.n_nan_rows} row(s) of {c.n_input_rows} holding NaN, inf or an "
                    f"empty cell{rows}"
                )
            if c.n_duplicates:
                said.append(
                    f"{c.n_duplicates} row(s) of {c.n_input_rows} repeating the previous timestamp"
                )
            if not drop_invalid:
                raise DataError(
                    f"{'; '.join(said)}; hint: fix the file or pass --drop-invalid "
                    "(drop_invalid=True) to drop them",
                    file=path.name,
                )
            for what in said:
                _log.warning("%s: dropped %s", path.name, what)
        log = mapped.log
    if n is not None and log.n != n:
        chain = robot if robot is not None and robot.n == n else None
        missing = "" if columns is not None else missing_joints(header_names(path), log.n, n)
        if missing:  # the robot's joints whose columns the file lacks, and how to map others
            raise DataError(
                f"the log has {log.n} joints; {owner or 'the robot'} has {n}: {missing}; or "
                + (
                    "pass the robot the log was recorded with"
                    if chain is None
                    else _joint_count_hint(log, chain).replace("; hint: ", ": ", 1)
                ),
                file=path.name,
            )
        raise DataError(
            f"the log has {log.n} joints; {owner or 'the robot'} has {n}; "
            + _joint_count_hint(log, robot if robot is not None and robot.n == n else None),
            file=path.name,
        )
    return log


def _chain_beyond(
    path: Path,
    columns: ColumnMap,
    n: int | None,
    owner: str | None,
    robot: Robot | None,
    exc: DataError,
) -> DataError | None:
    """The error of a mapped log whose columns stop short of ``robot``'s ``n`` joints (a
    6-joint log of an arm whose URDF chain runs on to a gripper joint: ``q7`` missing),
    with the log's own count and the ``--tip`` or ``--base`` that cuts the chain to it
    (:func:`_joint_count_hint`); None when the log read without a count has not fewer
    joints, or ``exc`` gives a hint of its own (the columns numbered from 0)."""
    if robot is None or robot.n != n or "hint:" in str(exc):
        return None
    try:
        log = load_mapped_torque_log(path, columns).log
    except DynidError:
        return None
    if not 0 < log.n < robot.n:
        return None
    said = str(exc).removeprefix(f"{exc.file}: ") if exc.file else str(exc)
    return DataError(
        f"the log has {log.n} joints; {owner or 'the robot'} has {n}: {said}; "
        + _joint_count_hint(log, robot),
        file=path.name,
    )


def _joint_count_hint(log: TorqueLog, robot: Robot | None) -> str:
    """The hint of ``log`` for ``robot`` of another joint count. With more joints in the
    chain: the joints it holds beyond the log's at either end, the chain cut at its base
    (``--base``, a torso lift below an arm) or at its tip (``--tip``, a gripper's), the one
    whose limits hold more of the log's positions first (:func:`_within_share`). With
    fewer: the chain's first and last joints, for a chain that starts or ends one too
    soon."""
    n_log = log.n
    if robot is None or n_log <= 0:
        return "hint: pass the robot the log was recorded with"
    if n_log > robot.n:
        return (
            "hint: pass the robot the log was recorded with (its chain runs from "
            f"{robot.link_names[0]} through {robot.joint_names[0]}..{robot.joint_names[-1]} "
            f"to {robot.link_names[-1]}; the log's {n_log - robot.n} more joint(s) lie "
            f"outside it: a URDF's chain starts earlier with --base, a link below "
            f"{robot.link_names[0]}, or ends later with --tip)"
        )
    k = robot.n - n_log
    tip = (
        _within_share(log, robot, slice(0, n_log)),
        f"--tip {robot.link_names[n_log]} (leaves out {', '.join(robot.joint_names[n_log:])})",
    )
    base = (
        _within_share(log, robot, slice(k, robot.n)),
        f"--base {robot.link_names[k]} (leaves out {', '.join(robot.joint_names[:k])})",
    )
    first, second = sorted((tip, base), key=lambda c: -c[0])
    return (
        f"its chain holds {k} joint(s) beyond the log's; hint: cut the URDF's chain with "
        f"{first[1]} ({100 * first[0]:.3g} % of the log's positions within those joints' "
        f"limits) or {second[1]} ({100 * second[0]:.3g} %), or pass the robot the log was "
        "recorded with"
    )


def _within_share(log: TorqueLog, robot: Robot, joints: slice) -> float:
    """The share (0 to 1) of ``log``'s positions (every joint's samples) within the limits
    of ``robot``'s ``joints`` [rad or m], with a slack of 5 % of each limit's span: a log
    of the arm's joints read against a torso lift's limits falls outside them."""
    lo = np.asarray(robot.q_min, dtype=np.float64)[joints]
    hi = np.asarray(robot.q_max, dtype=np.float64)[joints]
    slack = 0.05 * np.where(np.isfinite(hi - lo), hi - lo, 0.0)
    q = np.asarray(log.q, dtype=np.float64)
    inside = (q >= lo - slack) & (q <= hi + slack)
    return float(np.mean(inside)) if inside.size else 0.0


def read_static_file(
    path: str | Path,
    robot: Robot,
    *,
    columns: ColumnMap | None = None,
    drop_invalid: bool = False,
    require_M: bool = True,
) -> StaticDataset:
    """Static data ``q, M, g`` of ``robot`` from ``path``, read strictly.

    A dynid file is read by :func:`~dynid.io.static_data.load_static_data` (its recorded
    robot checked against ``robot``); a file of another tool through ``columns`` (notes
    logged as warnings, the units converted as notes), as is one without ``M`` columns
    when ``require_M`` is False (gravity torques only: ``M`` zero).

    Raises
    ------
    DataError
        A bad file, another joint count than ``robot.n``, data recorded with another robot.
    """
    path = Path(path)
    if columns is not None or not require_M:
        mapped = load_mapped_static_data(
            path, columns or ColumnMap(), robot, require_M=require_M, drop_invalid=drop_invalid
        )
        for note in mapped.conversions:  # as asked: a note
            _log.log(NOTE, "%s: %s", path.name, note)
        for note in mapped.notes:
            _log.warning("%s: %s", path.name, note)
        return mapped.data
    data, _ = load_static_data(path, robot, drop_invalid=drop_invalid)
    return data


def recorded_columns(
    recorded: Mapping[str, Any] | None,
    columns: str | None,
    units: str | None,
    files: Sequence[str | Path] | None = None,
) -> tuple[str | None, str | None]:
    """The ``--columns`` and ``--units`` to read a log with for a model identified with
    the column map ``recorded`` (its ``info.column_map``): each as given, else as recorded
    (another file may be written in other units or with other names); logged where the
    recorded one is used (a note when it holds sign flips alone, ``--units tau2=-1``: the
    arm's convention, which every log of it shares) or one given differs from it, not
    where the recorded map is a file's own entries (``rec3.csv:tau6=-1``) naming none of
    the ``files`` read (nothing of it applies to them)."""
    if recorded is None:
        return columns, units
    rec = (recorded.get("columns"), recorded.get("units"))
    given = (columns, units)
    used = tuple(g if g is not None else r for g, r in zip(given, rec, strict=True))
    if used == rec and used != given and _applies(rec, files):
        _log.log(  # the arm's own convention and units its checks judge: reused as it should be
            NOTE if _checked_units(str(rec[1] or "")) else logging.WARNING,
            "reading the data as the model's data were read (%s); a file of other names or "
            "units is read with its own --columns/--units (%s)",
            _read_with(*used),
            _another_file(str(rec[1] or "")),
        )
    elif used != rec and not _reads_alike(used, rec, files):
        _log.warning(
            "reading the data with %s; the model's data were read with %s",
            _read_with(*used),
            _read_with(*rec),
        )
    return used[0], used[1]


#: Quantities whose named units a file read wrongly with them gets refused for: times
#: (:mod:`~dynid.identification.angle_time_units`), angles and their derivatives (the
#: degrees and velocity-scale checks); a torque's unit or factor has no such check short
#: of the gravity scale, so reusing one stays a warning.
_CHECKED_QUANTITIES = ("t", "q", "dq", "ddq")


def _checked_units(units: str) -> bool:
    """True when a ``--units`` text holds only sign flips (``tau2=-1,rec2.csv:tau=-1``) and
    named units of :data:`_CHECKED_QUANTITIES` (``t=us,q=deg,dq=deg/s``): a new file they
    do not fit is refused with its own hint, so reusing them is a note (a column map of
    other names fails on the first missing column just as plainly); none (a column map
    alone, a libfranka log's ``t=time,q=q_{i0},...``) is a note too."""
    if not units.strip():
        return True
    try:
        parsed = parse_column_map(None, units)
    except DataError:
        return False
    said = dict(parsed.names)
    signs = (parsed.flips, parsed.file_flips, parsed.file_signs)
    if not said and not any(signs):
        return False
    return all(
        unit in ("-1", "1", "+1")
        or (quantity in _CHECKED_QUANTITIES and not unit[:1].isdigit() and unit[:1] not in "+-.")
        for quantity, unit in said.items()
    )


def _reads_alike(
    used: tuple[Any, ...], rec: tuple[Any, ...], files: Sequence[str | Path] | None
) -> bool:
    """Whether ``used`` and the recorded ``(columns, units)`` read every one of ``files``
    alike (None: not known, so they may not): the recorded entries of files not read here
    (``rec2.csv:tau1=-1`` of a training file) change nothing of them."""
    if files is None:
        return False
    try:
        a, b = parse_column_map(*used), parse_column_map(*rec)
    except DataError:
        return False
    for name in (Path(f).name for f in files):
        x, y = a.for_file(name), b.for_file(name)
        if (dict(x.columns), dict(x.factors), dict(x.flips)) != (
            dict(y.columns),
            dict(y.factors),
            dict(y.flips),
        ):
            return False
    return True


def _applies(rec: tuple[Any, Any], files: Sequence[str | Path] | None) -> bool:
    """Whether the recorded ``(columns, units)`` say anything of the ``files`` read (None:
    not known, so it may): no when they are only a file's own entries naming none."""
    if files is None or rec[0] is not None:
        return True
    cmap = parse_column_map(None, rec[1])
    if cmap.factors or cmap.flips:  # entries for every file
        return True
    names = [Path(f).name for f in files]
    return len(cmap.unknown_files(names)) < len(cmap.own_files)


def _another_file(units: str) -> str:
    """How to read a file unlike the recorded ``units``: SI torques where those declare
    torques in another unit; a file's own entries (``rec2.csv:tau4=-1``) hold for a file
    of that name only."""
    cmap = parse_column_map(None, units or None)
    said = ["e.g. --units tau=Nm for SI torques"] if cmap.tau_is_torque else []
    if cmap.own_files:
        said.append(
            f"a file's own entries ({', '.join(f'{f}:...' for f in cmap.own_files)}) hold "
            "for a file of that name"
        )
    return "; ".join(said) or "given, they replace the recorded ones"


def _read_with(columns: str | None, units: str | None) -> str:
    """``--columns`` and ``--units`` as the user types them, those given only ("the
    default column names and units" for neither)."""
    given = [f"{flag} {v}" for flag, v in (("--columns", columns), ("--units", units)) if v]
    return ", ".join(given) or "the default column names and units"


def data_files(paths: str | Path | Sequence[str | Path]) -> list[Path]:
    """The data files of ``--data``: the paths given, a folder standing for its ``.csv``
    and ``.npz`` files in name order (its other files, hidden ones and folders apart,
    named in a logged note, and so are its sub-folders that hold data files: not read).

    Raises
    ------
    WrongTypeError
        Neither a path nor a list or tuple of paths (a :class:`TorqueLog` read already:
        ``identify_logs``, ``validate_torques``).
    DataError
        No path, a folder without data files, a file named twice (however written), two
        files of identical content, or two or more ROS bags (the one ``dynid import``
        that converts them all).
    """
    given = _checks.one_or_many("data", paths, (str, Path), PATHS_EXPECTED)
    if said := several_bags_hint(given):  # one import for them all, not the first's
        raise DataError(said)
    out: list[Path] = []
    for p in map(Path, given):
        if p.is_dir():
            found = sorted(f for f in p.iterdir() if f.suffix.lower() in (".csv", ".npz"))
            if not found:
                raise DataError(
                    f"{p.name}: the folder holds no .csv or .npz data file{bag_hint(p, ': ')}"
                )
            other = sorted(
                f.name
                for f in p.iterdir()
                if f not in found and not f.name.startswith(".") and not f.is_dir()
            )
            if other:  # a recording of another extension is never left out unsaid
                _log.warning(
                    "%s: %d file(s) neither .csv nor .npz left out: %s",
                    p.name,
                    len(other),
                    ", ".join(other[:5]) + (", ..." if len(other) > 5 else ""),
                )
            nested = sorted(
                f.name
                for f in p.iterdir()
                if f.is_dir() and not f.name.startswith(".") and _holds_data(f)
            )
            if nested:  # not read (a folder stands for its own files): said
                _log.warning(
                    "%s: sub-folder(s) holding data files left out (not read): %s; hint: "
                    "give them to --data as well",
                    p.name,
                    ", ".join(nested[:5]) + (", ..." if len(nested) > 5 else ""),
                )
            out += found
        else:
            out.append(p)
    if not out:
        raise DataError("no data file given")
    real = [p.resolve() for p in out]  # one file named two ways (a.csv, ./d/../a.csv)
    twice = sorted({p.name for p, r in zip(out, real, strict=True) if real.count(r) > 1})
    if twice:
        raise DataError(f"{', '.join(twice)}: data file given twice")
    _refuse_copies(out)
    return out


def _holds_data(folder: Path) -> bool:
    """Whether ``folder`` holds a ``.csv`` or ``.npz`` file (not looking deeper)."""
    try:
        return any(f.suffix.lower() in (".csv", ".npz") for f in folder.iterdir())
    except OSError:  # unreadable: not ours to judge
        return False


def _refuse_copies(paths: list[Path]) -> None:
    """Refuse two files of identical content (a recording copied under another name): it
    would count twice in the fit, and judge itself when one recording is left out.
    Only files of equal size are read (hashed in blocks)."""
    sizes: dict[int, list[Path]] = {}
    for p in paths:
        with contextlib.suppress(OSError):  # missing or unreadable: its reader says so
            if p.is_file() and (n := p.stat().st_size) > 0:
                sizes.setdefault(n, []).append(p)
    for group in (g for g in sizes.values() if len(g) > 1):
        first: dict[str, Path] = {}
        for p in group:
            h = hashlib.sha1()
            with contextlib.suppress(OSError), p.open("rb") as fh:
                while block := fh.read(1 << 20):
                    h.update(block)
            if (seen := first.setdefault(h.hexdigest(), p)) is not p:
                raise DataError(
                    f"{p.name}: the same content as {seen.name} (a copy of one recording); "
                    "it would count twice and judge itself when one recording is left out; "
                    "hint: give it once"
                )


#: How a message says what a ``data`` argument of files must be.
PATHS_EXPECTED = (
    "a path (str or Path) or a list of paths (logs already read: identify_logs, validate_torques)"
)
