"""Identify a load on a known arm from files: the entry point of ``dynid payload``, with
every policy the command applies, so that the Python API behaves as the command does.

* The data's kind (static data or torque logs, :func:`~.data_files.data_kind`) picks the
  route; static data come in one file, torque logs in one or more (a folder: its data
  files), read as :mod:`dynid.workflows.recordings` reads them (each problem one line
  naming the file).
* Each torque recording, and each piece of one cut at a gap longer than ``max_gap_s``
  (continuous joints recorded wrapped unwrapped first), is filtered and differentiated on
  its own (:func:`~dynid.feasibility.payload.identify_payload` with the pieces); a piece
  too short to filter is left out with a warning naming its file, a recording without
  one is an error naming it.
* ``gravity_only`` applies to static data; ``unloaded`` (the difference method) is data
  of the same kind, one file.
"""

from __future__ import annotations

import warnings
from collections.abc import Sequence
from dataclasses import dataclass
from pathlib import Path
from typing import Any

import numpy as np

from ..exceptions import DataError, DynidWarning
from ..feasibility.payload import PayloadEstimate, identify_payload
from ..identification.log import DEFAULT_CUTOFF_HZ, TorqueLog, prepare_log
from ..identification.model import IdentifiedModel
from ..identification.recordings import skipped_piece, split_at_gaps, unwrapped
from ..model.robot import Robot
from .data_files import ColumnSpec, column_map, data_kind, in_file, read_static_file
from .identify import data_files
from .recordings import read_recordings

__all__ = ["PayloadFileResult", "identify_payload_files"]


@dataclass(frozen=True, slots=True, eq=False)
class PayloadFileResult:
    """Result of :func:`identify_payload_files`.

    Attributes
    ----------
    estimate : PayloadEstimate
    kind : str
        ``"static"`` or ``"torque_log"``.
    recordings : tuple of dict
        Torque logs: per file, ``file``, ``pieces`` and ``samples`` used; static data:
        empty.
    skipped : tuple of str
        One line per piece left out (too short to filter).
    """

    estimate: PayloadEstimate
    kind: str
    recordings: tuple[dict[str, Any], ...] = ()
    skipped: tuple[str, ...] = ()

    def describe(self) -> str:
        """``"a.csv: 2 pieces, 3000 samples; ..."`` (empty for static data)."""
        return "; ".join(
            f"{r['file']}: {r['pieces']} piece{'s' if r['pieces'] != 1 else ''}, "
            f"{r['samples']} samples"
            for r in self.recordings
        )


def identify_payload_files(
    arm: Robot | IdentifiedModel,
    data: str | Path | Sequence[str | Path],
    *,
    unloaded: str | Path | None = None,
    frame: str = "flange",
    gravity_only: bool = False,
    columns: ColumnSpec | None = None,
    drop_invalid: bool = False,
    cutoff_hz: float | None = None,
    max_gap_s: float | None = None,
) -> PayloadFileResult:
    """The load fixed to ``frame`` from data recorded with it (module docstring).

    Parameters
    ----------
    arm : Robot or IdentifiedModel
        The arm without the load.
    data : str, Path or a sequence of them
        Static data (one file) or one or more torque logs (a folder: its data files).
    unloaded : str or Path, optional
        The same kind of data without the load (difference method), one file.
    frame, gravity_only
        As :func:`~dynid.feasibility.payload.identify_payload`.
    columns : (str or None, str or None), optional
        ``--columns`` and ``--units`` of files of another tool.
    drop_invalid : bool
        Drop invalid rows (counted) instead of failing.
    cutoff_hz : float or None
        Torque logs: zero-phase low-pass cut-off [Hz] (also of velocities derived from
        positions through ``columns``); default
        :data:`~dynid.identification.log.DEFAULT_CUTOFF_HZ`. Refused with static data, which
        are not filtered.
    max_gap_s : float, optional
        Torque logs: longest gap bridged [s]; a longer one cuts a log into pieces.

    Returns
    -------
    PayloadFileResult

    Raises
    ------
    UnknownNameError
        ``frame`` is not a frame of the arm.
    DataError
        A bad file; several static data files; ``gravity_only`` with torque logs; a
        recording in other units or without a piece long enough to filter (each named).
    """
    kin = arm.robot if isinstance(arm, IdentifiedModel) else arm
    kin.frame(frame)  # an unknown frame is the option's error, not a file's
    paths = data_files(data)
    given = cutoff_hz
    cutoff_hz = DEFAULT_CUTOFF_HZ if cutoff_hz is None else cutoff_hz
    cmap = column_map(*(columns or (None, None)), cutoff_hz=cutoff_hz)
    kind = data_kind(paths[0], cmap)
    if kind != "torque_log":
        if given is not None:
            raise DataError(
                "--cutoff applies to torque logs (their low-pass); static data are not filtered"
            )
        if len(paths) > 1:
            raise DataError(
                f"{paths[0].name} holds static data: give one static data file ({len(paths)} given)"
            )
        if unloaded is not None and data_kind(unloaded, cmap) != "static":
            raise DataError(f"{Path(unloaded).name}: --unloaded must be static data like --data")
        static = read_static_file(
            paths[0], kin, columns=cmap, drop_invalid=drop_invalid, require_M=not gravity_only
        )
        base = (
            None
            if unloaded is None
            else read_static_file(
                unloaded, kin, columns=cmap, drop_invalid=drop_invalid, require_M=not gravity_only
            )
        )
        est = in_file(
            paths[0],
            lambda: identify_payload(
                arm, static, frame=frame, gravity_only=gravity_only, unloaded=base, cutoff_hz=None
            ),
        )
        return PayloadFileResult(est, "static")
    if gravity_only:
        raise DataError("--gravity-only applies to static data (q, g), not to a torque log")
    owner = f"robot {kin.name!r}"
    rec = read_recordings(
        paths, kin, columns=columns, drop_invalid=drop_invalid, cutoff_hz=cutoff_hz, owner=owner
    )
    pieces, summary, skipped = _pieces(kin, rec.logs, rec.names, cutoff_hz, max_gap_s)
    without = None
    if unloaded is not None:
        without = read_recordings(
            unloaded, kin, columns=columns, drop_invalid=drop_invalid, cutoff_hz=cutoff_hz
        ).logs[0]
    fit = lambda: identify_payload(  # noqa: E731
        arm, pieces, frame=frame, unloaded=without, cutoff_hz=cutoff_hz, max_gap_s=max_gap_s
    )
    est = in_file(paths[0], fit) if len(paths) == 1 else fit()
    return PayloadFileResult(est, "torque_log", summary, skipped)


def _pieces(
    robot: Robot,
    logs: Sequence[TorqueLog],
    names: Sequence[str],
    cutoff_hz: float | None,
    max_gap_s: float | None,
) -> tuple[list[TorqueLog], tuple[dict[str, Any], ...], tuple[str, ...]]:
    """Every recording unwrapped and cut at its gaps; the pieces long enough to filter,
    the pieces and samples per file, and a line per piece left out."""
    revolute = ~np.asarray(robot.prismatic, dtype=bool)
    kept: list[TorqueLog] = []
    summary, skipped = [], []
    for name, log in zip(names, logs, strict=True):
        log, joints = unwrapped(log, revolute)
        if joints:
            warnings.warn(
                f"{name}: joint(s) {', '.join(str(j + 1) for j in joints)} recorded wrapped "
                "into [-pi, pi] (jumps of a whole turn): unwrapped",
                DynidWarning,
                stacklevel=3,
            )
        mine = []
        for piece in split_at_gaps(log, max_gap_s):
            try:
                prepare_log(piece, cutoff_hz=cutoff_hz, max_gap_s=max_gap_s)  # long enough?
            except DataError as exc:
                skipped.append(skipped_piece(name, piece, exc, stacklevel=4))
                continue
            mine.append(piece)
        if not mine:
            raise DataError(
                f"{name}: no piece long enough to filter at {cutoff_hz:.4g} Hz (gaps longer than "
                "--max-gap cut a recording into pieces); hint: record longer stretches "
                "without gaps, or raise --max-gap"
            )
        kept += mine
        summary.append(
            {"file": name, "pieces": len(mine), "samples": sum(p.n_samples for p in mine)}
        )
    return kept, tuple(summary), tuple(skipped)
