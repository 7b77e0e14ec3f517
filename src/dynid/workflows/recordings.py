"""Several torque recordings read for a model: the ``--data a.csv b.csv ...`` (or a
folder) of ``validate``, ``friction`` and ``payload`` (``identify`` and ``observe`` apply
:func:`check_limits` and :func:`check_units` to the logs they read).

Every recording is read strictly (:func:`~.data_files.read_torque_log`, through the
column map the model's data were read with when none is given), and each problem is one
line naming the file, never a recording dropped silently:

* an empty file, NaN/inf or a repeated timestamp (without ``drop_invalid``), another
  joint count than the model's: the reader's error, naming the file;
* a time column in ms, us or ns (:func:`~dynid.identification.angle_time_units.time_unit_finding`)
  and positions in degrees, checked together (:func:`check_unit_findings`): one error
  naming the file, every unit found and one hint, ``--units t=ms,q=deg``;
* a recording whose velocity columns lag the derivative of its positions (by 0.75 sample
  or more) or hold no motion (zeros, a constant) on joints whose positions move
  (:func:`usable_velocities`, as each route reads its logs): a warning naming it, the
  joints and the lag in samples and ms, and its velocities derived from the positions
  instead, as ``--columns dq=none`` reads it (:func:`usable_recorded`, after the unit
  checks);
* acceleration columns much noisier than the derivative of the velocities at the cut-off
  (a finite difference of noisy velocities): left out, with a note naming the file and the
  ratio; a note says whenever acceleration columns are used
  (:func:`checked_accelerations`);
* a recording in other units than the others (its torques, or its velocities against the
  derivative of its positions on the joints that move, a power of ten away from the other
  recordings'): an error naming it (a recording at rest, or without velocity columns, has
  no velocity ratio to compare);

Every check reads the recordings with their joints recorded wrapped into ``[-pi, pi]``
unwrapped by the preparation's rule (:func:`unwrapped_recorded`), not a whole turn's jump.
* a recording in degrees among recordings in radians (positions and velocities both in
  degrees pass the check above): an error naming it and the columns to convert
  (:mod:`~dynid.identification.unit_mix`);
* a recording with joints in degrees (one joint's column written in degrees: its
  positions span more than the joint can travel and fit its limits read in degrees): an
  error naming it, the joints and the conversion (``identify``, ``validate``, ``observe``
  alike);
* a recording whose torques read as mN m (or kN m) taken for N m, about 1000 times the
  model's gravity torques, unless the column map says the torques' unit (``--units
  tau=...``, or the model's recorded one): an error naming it and ``--units tau=mNm``
  (:func:`check_torque_unit`; ``identify`` and ``observe`` alike);
* a recording whose positions lie far outside the model's joint limits (of another robot):
  a warning naming it; torques beyond the model's effort limits: a note naming the joints
  (:mod:`~dynid.identification.effort_limits`);
* one-sample torque spikes (:func:`~dynid.identification.spikes.despiked`, the rule
  ``identify`` applies before fitting): replaced by :func:`despiked_recordings`
  (``validate`` before judging, ``observe`` before the observer runs), with a warning per
  file naming the joints, the counts and the times.

Pieces too short to filter are the preparation's (:mod:`dynid.friction.recordings`).
"""

from __future__ import annotations

import dataclasses
import logging
import warnings
from collections.abc import Sequence
from dataclasses import dataclass
from pathlib import Path
from typing import Any

import numpy as np
from numpy.typing import NDArray

from .._checks import caller_level
from ..exceptions import DataError, DynidWarning, OptionError
from ..identification.angle_time_units import GivenUnits, units_with
from ..identification.derivative_columns import (
    DDQ_NOISE_RATIO,
    SCALE_OFF,
    acceleration_noise_ratio,
    velocity_finding,
)
from ..identification.effort_limits import effort_limit_finding
from ..identification.log import (
    DEFAULT_CUTOFF_HZ,
    TorqueLog,
    joint_side_log,
    velocity_note,
    with_derived_velocities,
)
from ..identification.model_sign import every_joint_entry, sign_confirmed
from ..identification.pieces import unwrapped_log, with_start_turns, wrappable
from ..identification.recorded_signs import SignFinding, recording_sign_findings
from ..identification.reversed_among import reversed_among
from ..identification.sanity import too_few_samples, torque_unit_finding
from ..identification.spikes import despiked, spike_finding
from ..identification.time_units_among import time_units_hint, time_units_said
from ..identification.unit_mix import (
    LIMIT_MARGIN,
    degrees_among_radians,
    joints_in_degrees,
    time_unit_read,
    unit_findings,
)
from ..identification.velocity_noise import moving_joints
from ..identification.velocity_scale import acceleration_rate_factors
from ..io.columns import (
    CURRENT_UNITS,
    LEFT_OUT,
    ColumnMap,
    header_names,
    parse_column_map,
    unread_columns,
    unread_note,
)
from ..io.sign_entries import tau_negated, units_negating, units_reading
from ..io.torque_log import declared_tau_unit
from ..model.drive import Drive
from ..model.robot import Robot
from ..progress import NOTE
from ..signals import sample_rate
from .data_files import (
    ColumnSpec,
    check_file_entries,
    column_map,
    data_files,
    in_file,
    read_torque_log,
    recorded_columns,
)

__all__ = [
    "UNIT_RATIO",
    "Recorded",
    "check_degrees",
    "check_derived_velocities",
    "usable_recorded",
    "usable_velocities",
    "checked_accelerations",
    "check_limits",
    "check_sign_map",
    "check_signs",
    "sign_findings",
    "warn_signs",
    "recorded_sign_map_findings",
    "check_torque_unit",
    "check_unit_findings",
    "given_units",
    "note_unread_columns",
    "check_units",
    "despiked_recordings",
    "given_start",
    "read_recordings",
    "unwrapped_recorded",
]

_log = logging.getLogger(__name__)

#: Ratio of a recording's torque scale (or velocity unit) to the other recordings' median
#: beyond which it is taken to be in another unit (a power of ten: mN m, ms, degrees).
UNIT_RATIO = 30.0


@dataclass(frozen=True, slots=True, eq=False)
class Recorded:
    """The recordings as read, and on the joint side.

    Attributes
    ----------
    logs : tuple of TorqueLog
    paths : tuple of Path
    drive : Drive or None
        The drive they were recorded through.
    sides : tuple of TorqueLog
        The logs in joint positions and torques through ``drive``
        (:func:`~dynid.identification.log.joint_side_log`; the logs themselves without
        it or through a drive of another joint count), mapped once when made (default)
        for every check and for the observer.
    wrapped : tuple of tuple of int, optional
        Per recording, the joints (0-based) recorded wrapped and unwrapped for the checks
        (:func:`unwrapped_recorded`); None when nothing was unwrapped.
    """

    logs: tuple[TorqueLog, ...]
    paths: tuple[Path, ...]
    drive: Drive | None = None
    sides: tuple[TorqueLog, ...] | None = None
    wrapped: tuple[tuple[int, ...], ...] | None = None

    def __post_init__(self) -> None:
        if self.sides is None:
            object.__setattr__(self, "sides", tuple(_joint_side(g, self.drive) for g in self.logs))

    @property
    def names(self) -> tuple[str, ...]:
        """The files' names."""
        return tuple(p.name for p in self.paths)

    @property
    def joint_side(self) -> tuple[TorqueLog, ...]:
        """:attr:`sides`, typed."""
        assert self.sides is not None  # set when made
        return self.sides

    def select(self, rows: slice) -> Recorded:
        """The recordings ``rows`` (a slice), their joint-side logs not mapped again."""
        wrapped = None if self.wrapped is None else self.wrapped[rows]
        return Recorded(
            self.logs[rows], self.paths[rows], self.drive, self.joint_side[rows], wrapped
        )


def read_recordings(
    data: str | Path | Sequence[str | Path],
    robot: Robot,
    *,
    recorded: Any = None,
    columns: ColumnSpec | None = None,
    drop_invalid: bool = False,
    cutoff_hz: float | None = None,
    owner: str | None = None,
    drive: Drive | None = None,
    q_start: Sequence[float] | None = None,
    max_gap_s: float | None = None,
    reference: Robot | None = None,
    signs: bool = False,
    sign_map: bool = False,
) -> Recorded:
    """The torque logs of ``data`` (files, or folders of ``.csv``/``.npz`` files) of
    ``robot``, read and checked (module docstring).

    Parameters
    ----------
    data : str, Path or a sequence of them
    robot : Robot
        The model's robot (joint count, limits).
    recorded : mapping, optional
        The column map the model's data were read with (``info.column_map``).
    columns : (str or None, str or None), optional
        ``--columns`` and ``--units``.
    drop_invalid : bool
        Drop invalid rows (counted) instead of failing.
    cutoff_hz : float, optional
        Cut-off [Hz] of velocities derived from positions through a column map.
    owner : str, optional
        What has ``robot.n`` joints, for messages.
    drive : Drive, optional
        The drive the recordings were recorded through: the joint limits are checked on
        their joint-side positions (a motor-side log holds motor angles).
    q_start, max_gap_s : optional
        The joint positions [rad] at the first sample of one motor-side recording whose
        motors were recorded wrapped, and the gap rule cutting it (:func:`given_start`).
    reference : Robot, optional
        A robot whose link parameters give the model's gravity torques (an identified
        model's ``equivalent_robot``) for :func:`check_torque_unit`; default ``robot``.
    signs : bool
        Warn of a recording of the opposite torque sign, naming its joints and the
        ``--units`` entries (:func:`warn_signs`, against ``reference``), as ``validate``
        does before judging it.
    sign_map : bool
        Refuse a recording whose torques the ``--units`` applied (those given, else
        ``recorded``'s) read with the wrong sign, with the ``--units`` that read it right
        (:func:`check_sign_map`, against ``reference``): before a fit, whose own sign
        check of the torques as read would hint the very flip applied.

    Returns
    -------
    Recorded

    Raises
    ------
    DataError
        No file, a bad file, another joint count, invalid rows without ``drop_invalid``,
        other columns than the model's, a recording in other units than the others, in
        degrees among recordings in radians or in mN m read as N m (each names the file).
    """
    paths = data_files(data)
    names, units = recorded_columns(recorded, *(columns or (None, None)), paths)
    cmap = column_map(names, units, cutoff_hz=cutoff_hz, drive=drive, robot=robot)
    mine, toml = columns or (None, None), str((columns or (None,))[0] or "").lower()
    if mine[1] is not None or toml.endswith(".toml"):  # the user's units, not the model's
        check_file_entries(cmap, paths)  # recorded map (it names its own files)

    def read(p: Path) -> TorqueLog:
        return read_torque_log(
            p,
            robot.n,
            columns=cmap,
            drop_invalid=drop_invalid,
            owner=owner,
            robot=robot,
            drive=drive,
        )

    logs = tuple(in_file(p, lambda p=p: read(p)) for p in paths)  # type: ignore[misc]
    logs = checked_accelerations(logs, [p.name for p in paths], cutoff_hz)
    logs = given_start(logs, [p.name for p in paths], robot, drive, q_start, max_gap_s)
    out = Recorded(logs, tuple(paths), drive)
    checked = unwrapped_recorded(out, robot, max_gap_s)  # as the preparation reads them
    check_unit_findings(checked, robot, given_units(cmap, units))  # the units, named first
    check_limits(checked, robot)
    out, checked = usable_recorded(out, checked, robot, max_gap_s)  # units known right
    check_units(checked)
    check_derived_velocities(out, cmap)
    note_unread_columns(out, cmap)
    if sign_map:
        check_sign_map(checked, robot if reference is None else reference, mine[1], recorded)
    if signs:  # said, naming the joints: the verdict judges the log as it is
        warn_signs(checked, robot if reference is None else reference)
    check_torque_unit(checked, robot if reference is None else reference, cmap)
    return out


def despiked_recordings(
    rec: Recorded, joint_names: Sequence[str], before: str, min_rate_hz: float = 0.0
) -> tuple[Recorded, tuple[int, ...]]:
    """The recordings with their one-sample torque spikes replaced by the line between their
    neighbours (:func:`~dynid.identification.spikes.despiked`, the rule ``identify``
    applies before fitting), a warning per recording with spikes naming it, the joints,
    the counts, the times and ``before`` what they were replaced
    (:func:`~dynid.identification.spikes.spike_finding`); and the torque samples replaced
    per recording. A recording sampled below ``min_rate_hz`` [Hz] keeps its spikes, said
    in its warning (``observe``: at 100 Hz a short impact can be one sample)."""
    logs, counts = [], []
    for name, log in zip(rec.names, rec.logs, strict=True):
        rate = sample_rate(log.t) if log.n_samples > 1 else np.inf
        kept = (
            f"kept: at {rate:.3g} Hz, below {min_rate_hz:g} Hz, a short impact can be one "
            "sample (events at their times may be faults)"
            if rate < min_rate_hz
            else None
        )
        found = spike_finding(name, log, tuple(joint_names), before=before, kept=kept)
        if found is not None:
            warnings.warn(found, DynidWarning, stacklevel=caller_level())
        if kept is not None:
            logs.append(log)
            counts.append(0)
            continue
        clean, per_joint = despiked(log)
        logs.append(clean)
        counts.append(sum(per_joint))
    assert rec.sides is not None  # made in __post_init__
    sides = tuple(  # only a recording whose spikes were replaced mapped anew
        side if new is old else _joint_side(new, rec.drive)
        for new, old, side in zip(logs, rec.logs, rec.sides, strict=True)
    )
    return Recorded(tuple(logs), rec.paths, rec.drive, sides), tuple(counts)


def given_start(
    logs: Sequence[TorqueLog],
    names: Sequence[str],
    robot: Robot,
    drive: Drive | None,
    q_start: Sequence[float] | None,
    max_gap_s: float | None = None,
) -> tuple[TorqueLog, ...]:
    """The recordings with the whole turns of motors recorded wrapped set from the joint
    positions ``q_start`` (n,) [rad] at the first sample (``--q-start``,
    :func:`~dynid.identification.pieces.with_start_turns`; the pieces after a gap longer
    than ``max_gap_s`` from the joints' limits); the recordings as they are without it.

    Raises
    ------
    OptionError
        ``q_start`` with several recordings (it is one log's first sample), without a
        motor-side drive, of another joint count, or for a log whose motors did not wrap.
    DataError
        The turns are not told (:func:`~dynid.identification.pieces.start_turns`; the
        file named).
    """
    if q_start is None:
        return tuple(logs)
    if len(logs) != 1:
        raise OptionError(
            f"gives the joint positions at the first sample of one recording; got {len(logs)} "
            f"({', '.join(names)}); hint: give one recording with --q-start (one at a time), "
            "or log the motors' multi-turn angles or the joint positions (a joint-side log) "
            "to read several",
            field="q_start",
        )
    return (with_start_turns(names[0], logs[0], robot, drive, np.asarray(q_start), max_gap_s),)


def unwrapped_recorded(rec: Recorded, robot: Robot, max_gap_s: float | None = None) -> Recorded:
    """The recordings with their joints recorded wrapped into ``[-pi, pi]`` unwrapped by
    the rule the preparation applies (:func:`~dynid.identification.pieces.unwrapped_log`,
    cut at the gaps longer than ``max_gap_s`` [s]), for the checks across recordings:
    they read the positions every later step reads, not a whole turn's jump. A motor-side
    log is as it is (its motors' turns are the preparation's, or ``--q-start``'s);
    ``rec`` itself when nothing was wrapped."""
    if rec.drive is not None and rec.drive.side == "motor":
        return rec
    turns = wrappable(robot)
    pairs = zip(rec.names, rec.logs, strict=True)
    done = [unwrapped_log(name, log, turns, max_gap_s) for name, log in pairs]
    if not any(joints for _, joints in done):
        return rec
    logs, wrapped = zip(*done, strict=True)
    return Recorded(tuple(logs), rec.paths, rec.drive, wrapped=tuple(wrapped))


def _scales(log: TorqueLog) -> tuple[float, float]:
    """The RMS torque [N m] and ``k`` of ``d q / dt ~ k dq`` (1 when ``t``, ``q`` and
    ``dq`` share their units) of a log, on at most 20 000 samples. The positions'
    differences of half a turn or more (a continuous joint recorded wrapped into
    [-pi, pi), a jump) are left out: they are not motion; so are the joints whose
    velocities are their noise (a joint at rest: ``k`` of noise against noise, any
    number); ``k`` is NaN when no joint moves, and for velocities derived from the
    positions (they are that derivative: nothing to compare)."""
    step = max(1, log.n_samples // 20_000)
    t, q, dq, tau = log.t[::step], log.q[::step], log.dq[::step], log.tau[::step]
    rms = float(np.sqrt(np.mean(tau**2)))
    if t.size < 5 or log.dq_derived:
        return rms, float("nan")
    dqdt = np.diff(q, axis=0) / np.diff(t)[:, None]
    mid = 0.5 * (dq[1:] + dq[:-1])
    keep = (np.abs(np.diff(q, axis=0)) < np.pi) & moving_joints(dq)
    num = float(np.sum(np.where(keep, dqdt * mid, 0.0)))
    den = float(np.sum(np.where(keep, mid * mid, 0.0)))
    return rms, num / den if den > 0 else float("nan")


def usable_velocities(logs: Sequence[TorqueLog], names: Sequence[str]) -> tuple[TorqueLog, ...]:
    """The logs whose velocity columns lag the derivative of their positions or hold no
    motion where the positions move
    (:func:`~dynid.identification.derivative_columns.velocity_finding`) read as
    ``--columns dq=none`` reads them: the velocities derived from the positions, the
    acceleration columns left out, with a warning naming the file and the finding. A real
    arm's log is then fitted, not refused: a logger whose velocities are a filtered
    estimate a few samples late is common, and its positions give what it lost (a one-sample
    lag at 1 kHz: 6 of 43 base parameters of a simulated FR3 beyond 3 std of the truth; 0
    with the velocities derived)."""
    out = []
    for name, log in zip(names, logs, strict=True):
        found = velocity_finding(log)
        if found is None:
            out.append(log)
            continue
        said = found.split("; hint:")[0]
        warnings.warn(
            f"{name}: {said}: velocities derived from the positions instead, as --columns "
            "dq=none reads the log (its acceleration columns left out too)",
            DynidWarning,
            stacklevel=caller_level(),
        )
        positions = TorqueLog(log.t, log.q, log.dq, log.tau, None, log.cleaning)
        out.append(with_derived_velocities(positions, DEFAULT_CUTOFF_HZ))
    return tuple(out)


def usable_recorded(
    rec: Recorded, checked: Recorded, robot: Robot, max_gap_s: float | None = None
) -> tuple[Recorded, Recorded]:
    """``rec`` with :func:`usable_velocities` and its unwrapped form (``checked``, as
    :func:`unwrapped_recorded` makes it), both as given when no recording's velocities
    were replaced. After the unit checks: a log in other units is named for them first
    (its velocities against a derivative read in other units would read as no motion)."""
    logs = usable_velocities(rec.logs, rec.names)
    if all(a is b for a, b in zip(logs, rec.logs, strict=True)):
        return rec, checked
    rec = dataclasses.replace(rec, logs=logs, sides=None)  # the joint side made again
    return rec, unwrapped_recorded(rec, robot, max_gap_s)


def checked_accelerations(
    logs: Sequence[TorqueLog], names: Sequence[str], cutoff_hz: float | None = None
) -> tuple[TorqueLog, ...]:
    """The logs with acceleration columns noisier than the derivative of their velocities
    at ``cutoff_hz`` [Hz] (None: the motion's, ``identify``'s default) by more than
    :data:`~dynid.identification.derivative_columns.DDQ_NOISE_RATIO` on some joint
    (:func:`~dynid.identification.derivative_columns.acceleration_noise_ratio`) left out,
    the accelerations derived from the velocities instead, with a note naming each and the
    ratio; a note names the logs whose acceleration columns are used (exact to round-off,
    or no noisier than that): without it nothing said a recorded ``ddq`` was read. Columns
    off the scale of the velocities' derivative
    (:func:`~dynid.identification.velocity_scale.acceleration_rate_factors`, beyond
    :data:`~dynid.identification.derivative_columns.SCALE_OFF`) are kept for the unit
    check (:func:`check_unit_findings`) to name: their noise is their unit's."""
    out, used = [], []
    for name, log in zip(names, logs, strict=True):
        k = acceleration_rate_factors(log)
        if log.ddq is None or np.any(np.abs(np.log(k[np.isfinite(k)])) > np.log(SCALE_OFF)):
            out.append(log)  # columns in another unit: the unit check names it, not noise
            continue
        ratio = acceleration_noise_ratio(log, cutoff_hz)
        worst = float(np.max(ratio)) if ratio is not None and ratio.size else 0.0
        if worst > DDQ_NOISE_RATIO:
            _log.log(
                NOTE,
                "%s: acceleration columns left out: their noise is %.3g times that of the "
                "derivative of the velocities at the cut-off (above %g: a finite difference "
                "of noisy velocities?); accelerations derived from the velocities",
                name,
                worst,
                DDQ_NOISE_RATIO,
            )
            out.append(dataclasses.replace(log, ddq=None))
            continue
        used.append(name)
        out.append(log)
    if used:
        which = ", ".join(used) if len(used) <= 4 else f"{len(used)} recordings ({used[0]}, ...)"
        _log.log(
            NOTE,
            "%s: acceleration columns used as recorded (exact, or no noisier than %g times "
            "the derivative of the velocities); --columns ddq=none derives them instead",
            which,
            DDQ_NOISE_RATIO,
        )
    return tuple(out)


def check_units(rec: Recorded) -> None:
    """Refuse a recording whose torque scale or velocity unit is a power of ten away from
    the median of the other recordings' (several recordings only; of two, the second is
    named). The velocity unit is compared among the recordings with velocity columns only:
    velocities derived from the positions are their derivative by construction. ``rec`` as
    the preparation reads it (:func:`unwrapped_recorded`).

    Raises
    ------
    DataError
        Naming the recording, the ratio and the recordings it was compared with.
    """
    if len(rec.logs) < 2:
        return
    scales = np.array([_scales(log) for log in rec.logs])
    for col, what in (
        (0, "torques (RMS)"),
        (1, "velocities against the derivative of the positions"),
    ):
        x = np.abs(scales[:, col])
        worst, ratio, others = -1, 1.0, ""
        for r in range(len(x)):
            rest = np.delete(x, r)
            rest = rest[np.isfinite(rest) & (rest > 0)]
            if not (np.isfinite(x[r]) and x[r] > 0 and rest.size):
                continue
            k = float(x[r] / np.median(rest))
            if abs(np.log(k)) >= abs(np.log(ratio)) - 1e-6:  # a tie: the later named
                worst, ratio = r, k
        if worst >= 0 and not 1 / UNIT_RATIO <= ratio <= UNIT_RATIO:
            names = [n for i, n in enumerate(rec.names) if i != worst]
            others = ", ".join(names) if len(names) <= 3 else "the other recordings"
            raise DataError(
                f"its {what} are {ratio:.3g} times those of {others}: "
                "recorded in other units? hint: every recording is read with the same "
                "units; convert it or leave it out",
                file=rec.names[worst],
            )


def check_derived_velocities(rec: Recorded, cmap: ColumnMap | None = None) -> None:
    """Say once, as a note, every recording without velocity columns (``dq_derived``),
    naming them: four positions-only logs gave four copies of one long line; and a
    warning it was, though nothing is wrong with such a log (an industrial controller
    logs positions only)."""
    names = [n for n, log in zip(rec.names, rec.logs, strict=True) if log.dq_derived]
    if not names:
        return
    cutoff = DEFAULT_CUTOFF_HZ if cmap is None else cmap.velocity_cutoff_hz
    which = ", ".join(names) if len(names) <= 4 else f"{len(names)} recordings ({names[0]}, ...)"
    said = velocity_note(cutoff)
    if cmap is not None and cmap.ignored("dq"):
        said = said.replace("no velocity columns", LEFT_OUT, 1)
    _log.log(NOTE, "%s: %s", which, said)


def note_unread_columns(rec: Recorded, cmap: ColumnMap | None) -> None:
    """Say once, as a note, the columns of the recordings read through ``cmap`` that no
    entry maps (:func:`~dynid.io.columns.unread_columns`: a vendor's motor currents beside
    its torques), the recordings of the same ones named together; they were dropped
    without a word."""
    if cmap is None:
        return
    said: dict[str, list[str]] = {}
    for path, log in zip(rec.paths, rec.logs, strict=True):
        unread = unread_columns(header_names(path), cmap.for_file(path.name))
        if unread:
            said.setdefault(unread_note(unread, log.n), []).append(path.name)
    for note, names in said.items():
        which = (
            ", ".join(names) if len(names) <= 4 else f"{len(names)} recordings ({names[0]}, ...)"
        )
        _log.log(NOTE, "%s: %s", which, note)


def given_units(cmap: ColumnMap | None, text: str | None) -> GivenUnits:
    """The units the logs were read with (``cmap``'s factors: of ``q``, ``dq``, ``ddq``
    the revolute joints' and the prismatic joints', each kind read in its own unit or in
    SI, :meth:`~dynid.io.columns.ColumnMap.joint_factors`; a file's own units, ``--units
    rec4.csv:t=ms``, its own: :meth:`GivenUnits.of`) and the ``--units`` text given, for
    the unit findings' hint."""
    if cmap is None:
        return GivenUnits(text)
    own = {f: _given_units(cmap.for_file(f), text) for f in cmap.file_units}
    return dataclasses.replace(_given_units(cmap, text), files=own)


def _given_units(cmap: ColumnMap, text: str | None) -> GivenUnits:
    """:func:`given_units` of the files ``cmap`` reads alike."""
    factors = {k: cmap.factor(k) for k in ("t", "q", "dq", "ddq")}
    lengths = dict(factors)
    kinds = cmap.prismatic
    for k in ("q", "dq", "ddq"):
        if kinds is None or len(set(kinds)) < 2:  # a unit read every joint
            continue
        f = np.atleast_1d(cmap.joint_factors(k, len(kinds)))
        f = np.broadcast_to(f, (len(kinds),))
        factors[k] = float(f[~np.asarray(kinds)][0])
        lengths[k] = float(f[np.asarray(kinds)][0])
    return GivenUnits(text, factors, lengths)


def check_unit_findings(rec: Recorded, robot: Robot, given: GivenUnits | None = None) -> None:
    """Refuse a recording whose time column (ms, us, ns), positions (degrees) or velocity
    columns (another angle unit than the positions) are in other units than read with
    (``given``, each file's own: :meth:`~dynid.identification.angle_time_units.GivenUnits.of`),
    every unit found said at once with one ``--units`` hint, the whole option to run again
    (:func:`~dynid.identification.unit_mix.unit_findings`): a log in ms and degrees was
    told ``--units t=ms`` and, run again, ``--units q=deg``. Of several recordings whose
    time columns are in different units, the hint reads each in its own (``--units
    rec4.csv:t=ms``, :func:`~dynid.identification.time_units_among.time_units_hint`).

    A recording in degrees among recordings in radians is said first
    (:func:`check_degrees`): the file and the ``--units`` entry of its own that reads it.

    Raises
    ------
    DataError
        Naming the recording, what each unit finding rests on and the ``--units`` hint.
    """
    given = given or GivenUnits()
    check_degrees(rec, robot, given.text)
    for name, log, side in zip(rec.names, rec.logs, rec.joint_side, strict=True):
        own = given.of(name)
        if (found := unit_findings(robot, log, rec.drive, side=side, given=own)) is None:
            continue
        if len(rec.logs) > 1:
            pairs = zip(rec.names, rec.logs, strict=True)
            units = [time_unit_read(robot, x, given.of(n)) for n, x in pairs]
            if (text := time_units_hint(rec.names, units, given.text)) is not None:
                bare = unit_findings(
                    robot, log, rec.drive, side=side, given=dataclasses.replace(own, text=None)
                )
                found = _with_time_units(found, bare or "", text, time_units_said(rec.names, units))
        raise DataError(found, file=name)


def _with_time_units(found: str, bare: str, text: str, said: str) -> str:
    """The finding ``found`` with its hint the ``--units`` ``text`` that reads each
    recording's time column in its own unit, the file's other entries (of ``bare``, its
    finding's hint without the ``--units`` given) written into it, and ``said``, the
    recordings' time units."""
    hint = bare.partition("; hint: ")[2]
    first, _, rest = hint.partition("; ")
    if first.startswith("--units "):
        pairs = (e.partition("=") for e in first.removeprefix("--units ").split(","))
        text = units_with(text, [(k, v) for k, _, v in pairs if k.strip() != "t"])
    else:
        rest = hint
    return (
        f"{found.partition('; hint: ')[0]}; hint: --units {text} (the recordings' time "
        f"columns differ: {said})" + (f"; {rest}" if rest else "")
    )


def check_degrees(rec: Recorded, robot: Robot, units: str | None = None) -> None:
    """Refuse a recording in degrees among recordings in radians
    (:func:`~dynid.identification.unit_mix.degrees_among_radians`), naming it and the
    file's own ``--units`` entries that read it (``rec2.csv:q=deg``), written into the
    ``--units`` given, ``units``.

    Raises
    ------
    DataError
        Naming the recording, the scales, the ``--units`` hint and the columns to convert.
    """
    found = degrees_among_radians(robot, list(rec.joint_side), rec.names, LIMIT_MARGIN)
    if found is None:
        return
    said = found[1]
    if units:
        what, _, hint = said.partition("; hint: --units ")
        entries, _, rest = hint.partition(" ")
        pairs = [e.partition("=") for e in entries.split(",")]
        said = f"{what}; hint: --units {units_with(units, [(k, v) for k, _, v in pairs])} {rest}"
    raise DataError(said, file=rec.names[found[0]])


def sign_findings(
    rec: Recorded, robot: Robot, skip: Sequence[str] = (), reference: Any = None
) -> dict[str, str]:
    """Per recording (by name), its sign finding, by the one rule ``identify`` refuses by
    (:func:`~dynid.identification.recorded_signs.recording_sign_findings`): columns recorded
    reversed (a motor mounted the other way: its position and effort negated), its
    (joint-side) torques of the opposite sign to the robot's on every joint gravity loads
    or on some, or a motor (joint) the links barely load of the opposite sign to the other
    recordings' (and to ``reference``, a model's own ``fv, fc, Ia`` (n, 3), when given),
    told by its own friction and rotor; each naming the joints (motors) and the
    ``--units`` entries that read them (the recording's own, ``rec2.csv:tau4=-1``, when
    another reads right). The one rule :func:`check_signs` refuses by and
    :func:`warn_signs` warns by. Recordings too short to judge and those named in ``skip``
    are left out; empty when every recording reads right."""
    return {f.name: f.text for f in _sign_findings(rec, robot, skip, reference)}


def _sign_findings(
    rec: Recorded,
    robot: Robot,
    skip: Sequence[str] = (),
    reference: Any = None,
    among: bool = True,
) -> tuple[SignFinding, ...]:
    """:func:`sign_findings` as found (``among``: the recordings' own friction compared),
    then, among the recordings not found so, a motor recorded reversed in one of them
    that the others tell (:func:`~dynid.identification.reversed_among.reversed_among`: a
    wrist's, which the description's torques over the whole arm cannot)."""
    keep = [
        k
        for k, (name, log) in enumerate(zip(rec.names, rec.joint_side, strict=True))
        if name not in skip and too_few_samples(log) is None
    ]
    if not keep:
        return ()
    drive = rec.drive if rec.drive is not None and rec.drive.n == robot.n else None
    found = recording_sign_findings(
        robot,
        [rec.logs[k] for k in keep],
        [rec.names[k] for k in keep],
        drive,
        sides=[rec.joint_side[k] for k in keep],
        reference=reference,
        among=among,
    )
    if not among:
        return found
    said = {f.name for f in found}
    rest = [k for k in keep if rec.names[k] not in said]
    wrist = reversed_among(robot, [rec.logs[k] for k in rest], [rec.names[k] for k in rest], drive)
    return found if wrist is None else (*found, wrist)


def warn_signs(
    rec: Recorded, robot: Robot, skip: Sequence[str] = (), reference: Any = None
) -> tuple[SignFinding, ...]:
    """Warn of each recording :func:`sign_findings` finds (columns recorded reversed, or
    torques of the opposite sign; the findings :func:`check_signs` refuses with), naming
    the file, and return them, each with its kind (``"reversed"`` columns, ``"opposite"``
    torques): ``validate`` judges such a log
    "unusable" and writes its files, and said only "of another sign?" without the joints
    or the ``--units`` entries that read them. The recordings ``skip`` (by name) are left
    out (their sign said otherwise: :func:`recorded_sign_map_findings`); ``reference``
    as :func:`sign_findings`."""
    found = _sign_findings(rec, robot, skip, reference)
    for f in found:
        warnings.warn(f"{f.name}: {f.text}", DynidWarning, stacklevel=caller_level())
    return found


def recorded_sign_map_findings(
    rec: Recorded, robot: Robot, recorded: Any, units: str | None
) -> dict[str, str]:
    """Per recording (by name), the finding that the torque signs the applied ``--units``
    negate look wrong for it: the model's recorded ones (``tau=-1``, ``tau3=-1``, applied
    because no ``units`` were given) or ``units`` as given. A negated joint whose torques
    the robot's rigid-body torques confirm as the file holds them and not as read
    (:func:`~dynid.identification.model_sign.sign_confirmed`): a file already in dynid's
    sign read with the model's ``tau=-1``. Said first, naming the joints and the
    ``--units`` that reads the file right given those applied (``tau=1``; of that file
    alone, ``b.csv:tau=-1`` beside the applied ones, when the other recordings read
    right), where the generic sign check would ask for the very flip applied; the verdict
    judges the torques as read. Empty without such a recording.

    Parameters
    ----------
    rec : Recorded
        The recordings as read (with the applied map).
    robot : Robot
        The robot whose torques confirm a sign (an identified model's equivalent links).
    recorded : mapping, optional
        The model's ``info.column_map`` (``columns``, ``units``).
    units : str, optional
        ``--units`` as given: it replaces the recorded map, and is judged in its place.
    """
    said = units if units is not None else None if recorded is None else recorded.get("units")
    if not isinstance(said, str) or not said.strip():
        return {}
    try:
        cmap = parse_column_map(None, said)
    except DataError:  # not a plain --units text: nothing to judge
        return {}
    found: dict[str, tuple[tuple[int, ...], tuple[int, ...], tuple[int, ...]]] = {}
    wanted: dict[str, set[int]] = {}  # each file's torques to read negated
    for name, log in zip(rec.names, rec.logs, strict=True):
        negated = tau_negated(cmap.for_file(name), log.tau.shape[1])
        wanted[name] = set(negated)
        if not negated or too_few_samples(log) is not None:
            continue
        sign = np.ones(log.tau.shape[1])
        sign[list(negated)] = -1.0
        held = dataclasses.replace(log, tau=log.tau * sign)  # as the file holds them
        as_read = sign_confirmed(robot, [_joint_side(log, rec.drive)])
        as_held = sign_confirmed(robot, [_joint_side(held, rec.drive)])
        ks = [k for k in negated if k < robot.n]
        wrong = tuple(k for k in ks if as_held[k] and not as_read[k])
        if wrong:
            found[name] = (negated, wrong, tuple(k for k in ks if as_read[k]))
    for name, f in found.items():  # (which joints confirm it may differ: a load's wrist)
        wanted[name] ^= set(_undone(*f, robot.n))
    hint = units_reading(said, wanted, robot.n) if found else None  # reads every file
    return {
        name: _sign_map_finding(
            _SignMap(name, said, units is None, robot.joint_names, len(rec.names) == 1, hint),
            *f,
        )
        for name, f in found.items()
    }


def _undone(
    negated: tuple[int, ...], wrong: tuple[int, ...], right: tuple[int, ...], n: int
) -> tuple[int, ...]:
    """The joints whose negation a file's hint undoes (:func:`_sign_map_finding`): every
    one negated when the map negates all ``n`` and none is confirmed as read (``right``:
    the file in dynid's sign, its joints the model cannot tell with it), else those
    confirmed as the file holds them (``wrong``)."""
    return negated if not right and len(negated) == n else wrong


@dataclass(frozen=True, slots=True)
class _SignMap:
    """Whose sign map a finding judges (:func:`recorded_sign_map_findings`): the file's
    ``name``, the applied ``units``, whether they are the model's ``recorded`` ones, the
    robot's joint ``names``, whether the hint may read every file (``every``: one
    recording) or names this file's own entry, and the ``--units`` that read every file
    right (``hint``, :func:`~dynid.io.sign_entries.units_reading`; None where a file's
    own entries cannot)."""

    name: str
    units: str
    recorded: bool
    names: Sequence[str]
    every: bool
    hint: str | None = None


def _sign_map_finding(
    m: _SignMap, negated: tuple[int, ...], wrong: tuple[int, ...], right: tuple[int, ...]
) -> str:
    """The words of :func:`recorded_sign_map_findings` for one recording: the torques of
    ``negated`` joints read negated, ``wrong`` of them confirmed as the file holds them,
    ``right`` as read."""
    undo = _undone(negated, wrong, right, len(m.names))
    whole = undo == negated and len(negated) == len(m.names)  # in dynid's sign throughout
    hint = units_negating(m.units, [k for k in negated if k not in undo], len(m.names))
    alone = ""  # the hint reads every file; with others that read right, this one's own
    if m.hint is not None:
        hint = m.hint
    elif not m.every and whole and m.name not in m.units:
        hint = f"{m.units},{every_joint_entry(m.name)}"
    elif not m.every:
        alone = " (for this file alone: they read every file given)"
    joints = ", ".join(f"{m.names[k]} (tau{k + 1})" for k in wrong)
    whose = "the model's recorded sign map" if m.recorded else "the sign map given"
    untold = [k for k in negated if k not in wrong and k not in right]
    if whole:
        head = (
            f"the file looks already in dynid's sign: {whose} (--units {m.units}) negates "
            f"every joint's torques, and those of {joints} match the model's as the file "
            "holds them and are opposite once negated (judged negated"
            + (
                f"; the sign of {', '.join(m.names[k] for k in untold)}, whose torques the "
                "model's do not explain, is not told by this check)"
                if untold
                else ")"
            )
        )
        reads = "as it holds every joint's torques"
    else:
        head = (
            f"{whose} (--units {m.units}) looks wrong for this file: the torques of {joints} "
            "match the model's as the file holds them and are opposite once negated, and "
            "are judged negated"
        )
        reads = "without " + ", ".join(f"tau{k + 1}=-1" for k in undo)
    return f"{m.name}: {head}; hint: --units {hint} reads the file {reads}{alone}" + (
        " (a --units given replaces the recorded map)" if m.recorded else ""
    )


def check_signs(
    rec: Recorded,
    robot: Robot,
    *,
    among: bool = True,
    recorded: Any = None,
    units: str | None = None,
) -> None:
    """Refuse a recording :func:`sign_findings` finds (columns recorded reversed, or
    torques of the opposite sign to the robot's or, on a motor the links barely load, to
    the other recordings'), as ``identify`` does: thresholds calibrated on it, or
    residuals of it, would be of the wrong sign. ``among`` False: the recordings' own
    friction and rotors are not compared (logs that may hold contacts: their external
    torques go into a motor's own terms, which one log of a push read as a flipped joint 3).
    A recording for which the model's recorded sign map (``recorded``, applied without
    ``units`` given) looks wrong is refused with that finding instead
    (:func:`recorded_sign_map_findings`: its hint reads the file without the flips; the
    generic one would ask for the flip already applied).

    Raises
    ------
    DataError
        Naming the recording, the joints and the remedy (``--units tau=-1``, or the
        columns to flip, ``q6=-1,tau6=-1`` for a column recorded reversed; of that
        recording alone, ``rec2.csv:tau2=-1``, when the others read right).
    """
    for name, log in zip(rec.names, rec.joint_side, strict=True):
        if (few := too_few_samples(log)) is not None:  # before the correlations
            raise DataError(few, file=name)
    for f in _sign_findings(rec, robot, among=among):
        wrong = recorded_sign_map_findings(rec, robot, recorded, units).get(f.name)
        said = f.text if wrong is None else wrong.removeprefix(f"{f.name}: ")
        raise DataError(said, file=f.name)  # (the finding named the file: once)


def check_sign_map(rec: Recorded, robot: Robot, units: str | None, recorded: Any = None) -> None:
    """Refuse a recording whose torques the applied ``--units`` read with the wrong sign
    (:func:`recorded_sign_map_findings`): ``units`` as given, else the model's
    ``recorded`` ones (its ``info.column_map``). A file already in dynid's sign read with
    ``tau=-1``, or a joint's ``tau3=-1`` its file does not need, confirmed by the robot's
    rigid-body torques. The finding names the joints and hints the ``--units`` that read
    the files right given those applied (``tau=1``; ``tau=-1,b.csv:tau=-1`` when the
    other recordings read right), where the generic sign check of the torques as read
    would hint the very flip applied. Nothing when the units applied negate no torque."""
    for name, said in recorded_sign_map_findings(rec, robot, recorded, units).items():
        raise DataError(said.removeprefix(f"{name}: "), file=name)


def check_torque_unit(rec: Recorded, robot: Robot, cmap: ColumnMap | None) -> None:
    """Refuse a recording whose (joint-side) torques read as mN m (or kN m) taken for N m
    (:func:`~dynid.identification.sanity.torque_unit_finding`), as the opposite sign and
    degrees are refused, unless the column map ``cmap`` they were read with says the
    torques' unit (``--units tau=Nm`` reads such torques as they are, with the finding
    warned). Refuse as well a CSV whose comment lines say its ``tau`` columns are motor
    currents (``tau [A]``, :func:`~dynid.io.torque_log.declared_tau_unit`) read without a
    drive of ``effort = "current"``: read as torques, the currents of a 6-joint arm gave
    "usable: error 6.8 %" and motor friction 25-250 % off, with no word.

    Raises
    ------
    DataError
        Naming the recording, the factor and ``--units tau=mNm``; or the unit its file
        declares and the drive that reads it.
    """
    if cmap is not None and "tau" in cmap.factors:
        return
    current = rec.drive is not None and rec.drive.effort == "current"
    for path in () if current else rec.paths:
        if (unit := declared_tau_unit(path)) is not None and unit in CURRENT_UNITS:
            raise DataError(
                f"its comment lines give the tau columns in {unit} (motor currents), but "
                + ("no --drive reads them" if rec.drive is None else "the drive's effort is "
                   f"{rec.drive.effort!r}")
                + "; hint: a --drive file with effort = \"current\" and each motor's "
                "torque_constant [N m/A], or --units tau=Nm if the columns are torques",
                file=path.name,
            )  # fmt: skip
    for name, log in zip(rec.names, rec.joint_side, strict=True):
        if (found := torque_unit_finding(robot, log, rec.drive)) is not None:
            raise DataError(found, file=name)


def _joint_side(log: TorqueLog, drive: Drive | None) -> TorqueLog:
    return log if drive is None or drive.n != log.n else joint_side_log(log, drive)


def check_limits(rec: Recorded, robot: Robot) -> None:
    """Refuse a recording in degrees among recordings in radians (:func:`check_degrees`)
    and a recording with joints in degrees
    (:func:`~dynid.identification.unit_mix.joints_in_degrees`); warn about a recording
    whose (joint-side) positions lie far outside the joint limits (:data:`LIMIT_MARGIN`
    beyond them), naming it; note torques beyond the effort limits
    (:func:`~dynid.identification.effort_limits.effort_limit_finding`); a joint recorded
    wrapped (:attr:`Recorded.wrapped`) is left to the preparation's warning, which names
    its jumps and its limits.

    Raises
    ------
    DataError
        A recording in degrees among recordings in radians, or with joints in degrees
        (naming the file, the joints and the conversion).
    """
    check_degrees(rec, robot)
    sides = rec.joint_side
    motor = rec.drive is not None and rec.drive.side == "motor"
    for name, log, read in zip(rec.names, sides, rec.logs, strict=True):
        recorded = read if motor and read is not log else None  # the file's motor angles
        if (found := joints_in_degrees(robot, log, LIMIT_MARGIN, recorded))[0]:
            raise DataError(found[1], file=name)
    lo = np.asarray(robot.q_min) - LIMIT_MARGIN
    hi = np.asarray(robot.q_max) + LIMIT_MARGIN
    wrapped = rec.wrapped or ((),) * len(sides)
    for name, log, turned, read in zip(rec.names, sides, wrapped, rec.logs, strict=True):
        q = log.q
        qmin, qmax = np.min(q, axis=0), np.max(q, axis=0)
        bad = np.setdiff1d(np.flatnonzero((qmin < lo) | (qmax > hi)), turned)  # said: wrapped
        if bad.size:
            j = int(bad[0])
            more = [robot.joint_names[k] for k in bad[1:]]
            also = f" (and {', '.join(more)} outside theirs)" if more else ""
            warnings.warn(
                f"{name}: joint {robot.joint_names[j]} spans [{qmin[j]:.4g}, {qmax[j]:.4g}], "
                f"far outside the limits of robot {robot.name!r} [{robot.q_min[j]:.4g}, "
                f"{robot.q_max[j]:.4g}]{also}: a recording of another robot, or in other "
                f"units?{_negated_hint(qmin[bad], qmax[bad], lo[bad], hi[bad])}"
                f"{_counts_hint(read.q[:, bad])}",
                DynidWarning,
                stacklevel=caller_level(),
            )
    if (said := effort_limit_finding(robot, [log.tau for log in sides])) is not None:
        _log.log(NOTE, "%s", said)


def _negated_hint(
    qmin: NDArray[np.float64],
    qmax: NDArray[np.float64],
    lo: NDArray[np.float64],
    hi: NDArray[np.float64],
) -> str:
    """A hint for joints whose positions (spans ``qmin``..``qmax`` [rad]) lie outside the
    limits ``lo``..``hi`` (with their margin) but within them negated: recorded reversed
    (a motor or encoder mounted the other way), which the sign checks judge; empty
    otherwise (a TIAGo arm's motor 4 logged reversed was said to be another robot's)."""
    if not np.all((-qmax >= lo) & (-qmin <= hi)):
        return ""
    return "; negated, they lie within them: recorded reversed? (the sign checks judge it)"


def _counts_hint(q: NDArray[np.float64]) -> str:
    """A hint for positions (as recorded) far outside the limits that are whole numbers
    spanning more than a few units: an encoder's counts (a servo's 0..4095 for a turn),
    read as radians; empty otherwise."""
    if q.size == 0 or float(np.ptp(q)) < 8.0 or not np.all(q == np.round(q)):
        return ""
    turn = 2 ** int(np.ceil(np.log2(max(float(np.max(np.abs(q))) + 1.0, 2.0))))
    return (
        f"; the positions are whole numbers ({np.min(q):.0f} to {np.max(q):.0f}): encoder "
        f"counts? --units q=FACTOR reads them in radians, 2 pi over the counts per turn "
        f"(for {turn} counts: --units q={2 * np.pi / turn:.10g}; a joint's zero away from "
        "count 0 is a drive file's offset)"
    )
