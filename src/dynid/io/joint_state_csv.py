"""Torque logs from CSV exports of a ``sensor_msgs/JointState`` topic.

Two layouts, told apart by their header (:func:`joint_state_layout`):

* ``rostopic echo -p /joint_states`` (ROS 1): ``%time`` (receive time [ns]),
  ``field.header.stamp`` [ns], ``field.name0 ..``, ``field.position0 ..``,
  ``field.velocity0 ..``, ``field.effort0 ..`` (a field the first message left empty has
  no columns). Each row is a message; its ``field.name*`` cells give its joint order, which
  may differ between rows (rows are grouped by it). A row with more or fewer cells than
  the header (a message of another length) is short.
* A PlotJuggler CSV export: ``__time`` [s], ``<topic>/<joint>/position`` (``velocity``,
  ``effort``) and optionally ``<topic>/header/stamp`` [s]. The export merges every topic
  it holds on one time axis: a row in which ``topic`` has no position is another topic's
  sample (counted as skipped); a blank cell of the topic's joints makes the row short.

Stamps are read from their text to the nanosecond (an epoch in float64 seconds keeps
only about 0.2 us). The rows then follow :mod:`dynid.io.joint_states`: joints matched by
name, unset stamps replaced by receive times, short, non-finite, out-of-order and
repeated-stamp rows counted.
"""

from __future__ import annotations

import csv
import re
from collections.abc import Iterator, Mapping, Sequence
from decimal import Decimal, InvalidOperation
from pathlib import Path

import numpy as np
from numpy.typing import NDArray

from ..exceptions import DataError
from ..identification.log import DEFAULT_CUTOFF_HZ
from ..progress import report
from .input_files import regular_file
from .joint_states import JointStateImport, JointStateMessages, assemble

__all__ = ["import_hint", "joint_state_layout", "load_joint_state_csv", "plotjuggler_topics"]

_FIELDS = ("position", "velocity", "effort")
#: Rows converted to arrays at a time (bounded memory whatever the file's length).
_BLOCK = 65_536


def joint_state_layout(names: Sequence[str]) -> str | None:
    """The JointState export a CSV header is: ``"rostopic"`` (``rostopic echo -p``),
    ``"plotjuggler"``, or None."""
    if "field.name0" in names and "field.position0" in names:
        return "rostopic"
    if names and names[0] == "__time" and any(_pj_column(c) for c in names):
        return "plotjuggler"
    return None


def import_hint(names: Sequence[str], file: str = "FILE") -> str:
    """For the message of a torque-log reader given such an export (its header
    ``names``, its name ``file``): ``; hint: ...`` how to read it (``dynid import``), or
    nothing for another header."""
    layout = joint_state_layout(names)
    if layout is None:
        return ""
    what = "rostopic echo -p" if layout == "rostopic" else "PlotJuggler"
    return (
        f"; hint: a CSV export of a JointState topic ({what}): `dynid import {file} --robot "
        "ROBOT --out log.csv` makes a torque log of it, joints matched by name"
    )


def _pj_column(name: str) -> tuple[str, str, str] | None:
    """``(topic, joint, field)`` of a PlotJuggler JointState column, or None."""
    m = re.fullmatch(r"(.*)/([^/]+)/(position|velocity|effort)", name)
    if m is None or m.group(2) == "header":
        return None
    return m.group(1), m.group(2), m.group(3)


def plotjuggler_topics(names: Sequence[str]) -> list[str]:
    """The JointState topics of a PlotJuggler header, in column order."""
    return list(dict.fromkeys(c[0] for n in names if (c := _pj_column(n)) is not None))


def _ns(text: str, unit_ns: int) -> int:
    """A stamp's text, in units of ``unit_ns`` nanoseconds (1: ns; 10**9: seconds), as
    integer nanoseconds, exactly; blank: 0 (unset)."""
    text = text.strip()
    if not text:
        return 0
    if unit_ns == 1 and text.lstrip("-").isdigit():
        return int(text)
    try:
        return int(Decimal(text) * unit_ns)
    except InvalidOperation:
        raise ValueError(f"not a time stamp: {text[:30]!r}") from None


def _floats(
    cells: list[list[str]], cols: list[int], header: list[str]
) -> tuple[NDArray[np.float64], NDArray[np.bool_]]:
    """Cells ``cols`` of each row as floats (N, len(cols)) and where they are blank; a
    row too short for a column is blank there.

    Raises
    ------
    ValueError
        A cell that is not a number (``nan`` and ``inf`` are numbers), named with its
        column.
    """
    width = max(cols) + 1
    text = np.array(
        [[r[c] for c in cols] if len(r) >= width else [""] * len(cols) for r in cells],
        dtype=str,
    ).reshape(len(cells), len(cols))
    text = np.char.strip(text)
    blank = text == ""
    try:
        values = np.where(blank, "0", text).astype(np.float64)  # numpy's C reader
    except ValueError:
        for k, c in enumerate(cols):  # the first cell that is not a number, named
            for cell in text[:, k]:
                try:
                    float(cell or 0)
                except ValueError:
                    raise ValueError(
                        f"column {header[c]!r}: {cell[:20]!r} is not a number"
                    ) from None
        raise
    return values, blank


def _rows(path: Path) -> Iterator[list[str]]:
    """The file's rows, without blank lines and comment lines (``#``).

    Raises
    ------
    DataError
        Text that is not CSV (a NUL byte, an unclosed quote at the end), with its line.
    """
    with open(path, newline="", encoding="utf-8", errors="replace") as f:
        reader = csv.reader(f)
        try:
            for row in reader:
                if row and not row[0].startswith("#"):
                    yield row
        except csv.Error as exc:
            at = f"line {reader.line_num}"
            raise DataError(f"not CSV text ({exc})", file=path.name, at=at) from None


def load_joint_state_csv(
    path: str | Path,
    robot_joints: Sequence[str],
    *,
    topic: str = "/joint_states",
    joints: Sequence[str] | None = None,
    velocity_cutoff_hz: float = DEFAULT_CUTOFF_HZ,
    gap_factor: float = 1.5,
    past_tip: Mapping[str, tuple[str | None, str]] | None = None,
) -> JointStateImport:
    """Read a CSV export of a JointState topic (module docstring) into a torque log.

    Parameters
    ----------
    path : str or Path
        The CSV file (``rostopic echo -p`` or PlotJuggler).
    robot_joints : sequence of str
        The robot's joint names; the log's columns follow this order.
    topic : str
        The JointState topic of a PlotJuggler export (``rostopic echo -p`` writes one
        topic, unnamed: ``topic`` only names it in messages).
    joints, velocity_cutoff_hz, gap_factor, past_tip
        As :func:`~dynid.io.rosbag.load_joint_state_bag`.

    Returns
    -------
    JointStateImport

    Raises
    ------
    DataError
        Not a JointState export (the header's first columns are named), the topic not in
        a PlotJuggler export (its topics listed), a cell that is not a number (its line
        and column), and the errors of :func:`~dynid.io.joint_states.assemble`.
    """
    path = Path(path)
    regular_file(path)
    rows = _rows(path)
    try:
        header = next(rows)
    except StopIteration:
        msg = "empty file; expected a CSV export of a JointState topic"
        raise DataError(msg, file=path.name) from None
    header = [h.strip() for h in header]
    layout = joint_state_layout(header)
    if layout is None:
        raise DataError(
            "not a CSV export of a JointState topic (rostopic echo -p: %time, field.name0, "
            f"field.position0, ...; PlotJuggler: __time, <topic>/<joint>/position, ...); the "
            f"header has {header[:6]}{' ...' if len(header) > 6 else ''}",
            file=path.name,
        )
    msgs = JointStateMessages(0)
    reader = _rostopic_blocks if layout == "rostopic" else _plotjuggler_blocks
    n_total = 0
    try:
        for n_rows, block in reader(path.name, header, rows, topic):
            for stamp, recv, key, values, blank in block:
                msgs.add_block(stamp, recv, key, values, blank)
            n_total += n_rows
            report(f"reading {path.name}: {n_total:,} rows")
    except ValueError as exc:
        where = f"data rows {n_total + 1}-{n_total + _BLOCK}"
        raise DataError(f"{exc} (in {where})", file=path.name) from None
    name = topic if layout == "plotjuggler" else "the exported topic"
    return assemble(
        path.name,
        name,
        msgs,
        n_total,
        robot_joints,
        joints,
        velocity_cutoff_hz,
        gap_factor,
        source="file",
        past_tip=past_tip,
    )


_Block = tuple[NDArray[np.int64], NDArray[np.int64], tuple[str, ...], NDArray, NDArray]


def _chunks(rows: Iterator[list[str]]) -> Iterator[list[list[str]]]:
    """The rows, :data:`_BLOCK` at a time."""
    block: list[list[str]] = []
    for row in rows:
        block.append(row)
        if len(block) == _BLOCK:
            yield block
            block = []
    if block:
        yield block


def _rostopic_blocks(
    name: str, header: list[str], rows: Iterator[list[str]], topic: str
) -> Iterator[tuple[int, list[_Block]]]:
    """Blocks of ``rostopic echo -p`` rows, grouped by their joint-name cells; a row of
    another width than the header's is a short message (under the last joint-name list
    seen)."""
    col = {h: i for i, h in enumerate(header)}
    w = 0
    while f"field.name{w}" in col:
        w += 1
    names = [col[f"field.name{k}"] for k in range(w)]
    fields = [[col.get(f"field.{f}{k}", -1) for k in range(w)] for f in _FIELDS]
    stamp_col, recv_col = col.get("field.header.stamp", -1), col.get("%time", -1)
    width = len(header)
    last: tuple[str, ...] = ()
    for cells in _chunks(rows):
        groups: dict[tuple[str, ...] | None, list[int]] = {}
        for r, row in enumerate(cells):
            key = tuple(row[c] for c in names) if len(row) == width else None
            last = key or last
            groups.setdefault(key, []).append(r)
        out = []
        for key, idx in groups.items():
            sub = [cells[r] for r in idx]
            stamp = np.array([_ns(r[stamp_col], 1) if stamp_col >= 0 else 0 for r in sub])
            recv = np.array([_ns(r[recv_col], 1) if recv_col >= 0 else 0 for r in sub])
            values = np.zeros((3, len(sub), w))
            blank = np.ones((3, len(sub), w), dtype=bool)
            if key is not None:
                for f, cols in enumerate(fields):
                    if min(cols, default=-1) >= 0:
                        values[f], blank[f] = _floats(sub, cols, header)
            elif not last:
                continue  # (no message of the header's width yet: nothing to be short of)
            block = (stamp.astype(np.int64), recv.astype(np.int64), key or last, values, blank)
            out.append(block)
        yield len(cells), out


def _plotjuggler_blocks(
    name: str, header: list[str], rows: Iterator[list[str]], topic: str
) -> Iterator[tuple[int, list[_Block]]]:
    """Blocks of PlotJuggler rows that hold the topic's positions."""
    topic = topic.rstrip("/")
    cols = {(c[1], c[2]): i for i, h in enumerate(header) if (c := _pj_column(h)) and c[0] == topic}
    if not cols:
        raise DataError(
            f"no JointState topic {topic!r} in the PlotJuggler export; it has "
            f"{plotjuggler_topics(header) or 'none'} (--topic)",
            file=name,
        )
    key = tuple(dict.fromkeys(j for j, _ in cols))
    fields = [[cols.get((j, f), -1) for j in key] for f in _FIELDS]
    hdr = {h: i for i, h in enumerate(header)}
    stamp_col = hdr.get(f"{topic}/header/stamp", -1)
    w = len(key)
    for cells in _chunks(rows):
        values = np.zeros((3, len(cells), w))
        blank = np.ones((3, len(cells), w), dtype=bool)
        for f, fc in enumerate(fields):
            if min(fc) >= 0:
                values[f], blank[f] = _floats(cells, fc, header)
        mine = ~np.all(blank[0], axis=1)  # the topic's rows: another topic's leave it blank
        sub = [r for r, m in zip(cells, mine, strict=True) if m]
        recv = np.array([_ns(r[0], 10**9) for r in sub], dtype=np.int64)
        stamp = (
            np.array([_ns(r[stamp_col], 10**9) for r in sub], dtype=np.int64)
            if stamp_col >= 0
            else recv.copy()
        )
        block = (stamp, recv, key, values[:, mine], blank[:, mine]) if sub else None
        yield len(cells), [block] if block is not None else []
