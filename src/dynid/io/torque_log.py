"""Reading and writing torque logs as CSV or NPZ.

CSV: comment lines (``#``) with the units and the row count, then a header naming the
columns, then one row per sample::

    # dynid torque log; units: t [s], q [rad], dq [rad/s], tau [N m], ddq [rad/s^2]
    # rows: N
    t,q1,...,qn,dq1,...,dqn,tau1,...,taun[,ddq1,...,ddqn]

(``tau [A]`` when the ``tau`` columns hold the motor currents a drive with ``effort =
"current"`` logs.) Columns are found by name, in any order; ``n`` is the number of ``q`` columns
(``q1..qn``, no gap). A duplicated column, a joint signal's column outside ``1..n``, or an
incomplete ``ddq1..ddqn`` set is an error (a wrong column silently used is a wrong
answer); any other column (labels, a vendor's estimates) is ignored with a warning; the
true external torques ``tau_ext1..n`` that ``dynid simulate --contact`` writes are named
once as ground truth (not read as data; ``dynid observe`` compares its residual with
them). Empty cells and ``nan`` read as NaN. A UTF-8 byte-order mark is accepted. NPZ:
arrays ``t`` (N,), ``q``, ``dq``, ``tau``, optionally ``ddq`` (N, n) and ``n_rows``,
loaded with ``allow_pickle=False``; other arrays are ignored with a warning (``tau_ext``
named as ground truth).

Strict by default: a row holding NaN or inf, or repeating the previous timestamp, raises
:class:`~dynid.exceptions.DataError` naming the first such row and the count. With
``drop_invalid=True`` such rows are dropped, and a warning says how many and where
(``log.cleaning`` counts them). Timestamps running backwards are always rejected. When
the file records its row count (``# rows:``, ``n_rows``), a different count is an error
(a file cut short). Malformed files raise :class:`~dynid.exceptions.DataError` naming
the file, the column and the line.

Writing is atomic (:mod:`dynid.io.atomic`) with 17 significant digits, so a round trip is
exact; a log whose velocities were derived from its positions is written without them
(positions and torques only), so that no reader takes them for measured ones. The CSV
body is read by :func:`dynid.io.csv_tables.csv_table` (numpy's C reader, straight into
arrays allocated once), so a long log needs about the memory of its arrays.
"""

from __future__ import annotations

import logging
import re
import zipfile
from collections.abc import Callable, Iterable
from pathlib import Path

import numpy as np
from numpy.typing import NDArray

from .. import _checks
from ..exceptions import DataError
from ..identification.log import (
    DEFAULT_CUTOFF_HZ,
    TorqueLog,
    velocity_note,
    with_derived_velocities,
)
from .atomic import open_atomic
from .bag_hint import bag_hint
from .column_hint import column_hint, no_torques, position_count, time_column
from .csv_tables import ROWS_PREFIX, csv_table
from .joint_state_csv import import_hint
from .npz_files import check_npz
from .static_data import check_row_count

__all__ = [
    "LABEL_COLUMNS",
    "declared_tau_unit",
    "load_torque_log",
    "save_torque_log",
    "save_torque_log_pieces",
    "torque_log_columns",
]

_log = logging.getLogger(__name__)


#: A ``tau`` column's unit declared in a comment line: ``tau [A]``, ``tau (mA)``.
_TAU_UNIT = re.compile(r"\btau\s*[\[(]\s*([^\])]+?)\s*[\])]")


def declared_tau_unit(path: str | Path, lines: int = 20) -> str | None:
    """The unit the comment lines (``#``) at the top of a CSV log give its ``tau``
    columns (``"A"`` in dynid's own ``units: ... tau [A]``, or another tool's ``tau [A]
    (motor current)``), or None: none said, not a CSV, or unreadable. Only the first
    ``lines`` lines are read."""
    path = Path(path)
    if path.suffix.lower() != ".csv":
        return None
    try:
        with open(path, encoding="utf-8", errors="replace") as f:
            head = [f.readline() for _ in range(lines)]
    except OSError:
        return None
    for line in head:
        if not line.lstrip().startswith("#"):
            break
        if (m := _TAU_UNIT.search(line)) is not None:
            return m.group(1).strip()
    return None


def _units(tau_unit: str) -> str:
    """The units line of a torque log whose ``tau`` columns are in ``tau_unit``."""
    return f"# dynid torque log; units: t [s], q [rad], dq [rad/s], tau [{tau_unit}], ddq [rad/s^2]"


_SIGNALS = ("q", "dq", "tau", "ddq")


def torque_log_columns(n: int, *, with_ddq: bool = False, with_dq: bool = True) -> list[str]:
    """Column names ``t, q1..qn, dq1..dqn, tau1..taun`` (then ``ddq1..ddqn``; without
    ``dq1..dqn`` when not ``with_dq``)."""
    cols = ["t"]
    for k in ("q",) + (("dq",) if with_dq else ()) + ("tau",) + (("ddq",) if with_ddq else ()):
        cols += [f"{k}{j}" for j in range(1, n + 1)]
    return cols


def save_torque_log(path: str | Path, log: TorqueLog, *, tau_unit: str = "N m") -> Path:
    """Write ``log`` to ``path`` (``.csv`` or ``.npz``, by suffix); returns the path.

    A log whose velocities were derived from its positions (``log.dq_derived``) is written
    without them, positions and torques only: a reader derives them again at its own
    cut-off (every command does), never taking them for measured ones. ``tau_unit``: the
    unit a CSV's units line gives the ``tau`` columns (``"N m"``, or ``"A"`` for motor
    currents, :attr:`~dynid.model.drive.Drive.effort_unit`).

    Raises
    ------
    DataError
        Unknown suffix.
    """
    return save_torque_log_pieces(
        path,
        lambda: (log,),
        n=log.n,
        n_rows=log.n_samples,
        with_ddq=log.ddq is not None,
        with_dq=not log.dq_derived,
        tau_unit=tau_unit,
    )


def save_torque_log_pieces(
    path: str | Path,
    pieces: Callable[[], Iterable[TorqueLog]],
    *,
    n: int,
    n_rows: int,
    with_ddq: bool = False,
    extra: tuple[str, Callable[[], Iterable[NDArray[np.float64]]]] | None = None,
    with_dq: bool = True,
    tau_unit: str = "N m",
) -> Path:
    """Write a log given in consecutive pieces (never held whole) to ``path`` (``.csv``
    or ``.npz``, by suffix), as :func:`save_torque_log` writes the pieces joined.

    Parameters
    ----------
    pieces : callable
        ``pieces()`` yields the pieces in order, the same at every call: one pass for a
        CSV, one per array for an NPZ (each array is one member of the archive).
    n : int
        Joints.
    n_rows : int
        Samples over all pieces (recorded in the file).
    with_ddq : bool
        Whether the pieces hold accelerations (written as ``ddq``).
    extra : (str, callable), optional
        ``(name, pieces)``: one more (N, n) signal beside the log, ``pieces()`` yielding
        its rows piece by piece like ``pieces``: columns ``name1..namen`` (the array
        ``name`` in an NPZ), which readers of the log ignore.
    with_dq : bool
        Whether the velocities are written (not: positions and torques only, whose
        readers derive the velocities).
    tau_unit : str
        The unit of the ``tau`` columns said in a CSV's units line: ``"N m"``, or ``"A"``
        for the currents of a drive with ``effort = "current"``
        (:attr:`~dynid.model.drive.Drive.effort_unit`).

    Raises
    ------
    DataError
        Unknown suffix, or pieces of another joint count or total length.
    """
    path = Path(path)
    suffix = path.suffix.lower()
    if suffix == ".npz":
        names = ["t", "q"] + (["dq"] if with_dq else []) + ["tau"] + (["ddq"] if with_ddq else [])
        names += [] if extra is None else [extra[0]]
        with open_atomic(path, "wb") as f, zipfile.ZipFile(f, "w", allowZip64=True) as zf:
            for name in names:
                shape = (n_rows,) if name == "t" else (n_rows, n)
                with zf.open(f"{name}.npy", "w", force_zip64=True) as member:
                    header = {"descr": "<f8", "fortran_order": False, "shape": shape}
                    np.lib.format.write_array_header_1_0(member, header)
                    rows = 0
                    if extra is not None and name == extra[0]:
                        for x in extra[1]():
                            rows += x.shape[0]
                            member.write(np.ascontiguousarray(x, dtype="<f8").tobytes())
                    for log in () if extra is not None and name == extra[0] else pieces():
                        a = np.ascontiguousarray(getattr(log, name), dtype="<f8")
                        rows += _piece_rows(path, log, n)
                        member.write(a.tobytes())
                    _check_written(path, rows, n_rows)
            with zf.open("n_rows.npy", "w") as member:
                np.lib.format.write_array(member, np.array(n_rows))
        return path
    if suffix != ".csv":
        raise DataError(f"torque log must be a .csv or .npz file; got {path.name!r}")
    preamble = "\n".join(
        [
            _units(tau_unit),
            f"{ROWS_PREFIX} {n_rows}",
            ",".join(
                torque_log_columns(n, with_ddq=with_ddq, with_dq=with_dq)
                + ([] if extra is None else [f"{extra[0]}{j}" for j in range(1, n + 1)])
            ),
        ]
    )
    with open_atomic(path, "w") as fh:
        fh.write(preamble + "\n")
        rows = 0
        more = iter(()) if extra is None else iter(extra[1]())
        for log in pieces():
            rows += _piece_rows(path, log, n)
            parts = [log.t[:, None], log.q] + ([log.dq] if with_dq else []) + [log.tau]
            if with_ddq:
                assert log.ddq is not None
                parts.append(log.ddq)
            if extra is not None:
                parts.append(next(more))
            step = 100_000  # bounded memory: format the table in blocks of rows
            for start in range(0, log.n_samples, step):
                block = np.concatenate([x[start : start + step] for x in parts], axis=1)
                np.savetxt(fh, block, delimiter=",", fmt="%.17g")
        _check_written(path, rows, n_rows)
    return path


def _piece_rows(path: Path, log: TorqueLog, n: int) -> int:
    """The samples of a piece of a log of ``n`` joints written to ``path``."""
    if log.n != n:
        raise DataError(f"a piece of the log has {log.n} joints; expected {n}", file=path.name)
    return log.n_samples


def _check_written(path: Path, rows: int, n_rows: int) -> None:
    """Refuse a written log whose pieces hold another number of rows than recorded."""
    if rows != n_rows:
        raise DataError(f"the pieces held {rows} rows; {n_rows} were recorded", file=path.name)


def load_torque_log(
    path: str | Path,
    *,
    gap_factor: float = 1.5,
    drop_invalid: bool = False,
    joints: int | None = None,
) -> TorqueLog:
    """Read a torque log from a ``.csv`` or ``.npz`` file, strictly, as the file holds it.

    A log read for an identified model, through the column map, units, torque signs and
    drive its data were read with (``--units tau3=-1``), is read by
    :func:`dynid.workflows.observe.read_log_as_identified`; this reads none of that.

    Parameters
    ----------
    path : str or Path
    gap_factor : float
        Steps longer than this times the median step are recorded as gaps.
    drop_invalid : bool
        Drop rows holding NaN or inf and rows repeating the previous timestamp (a warning
        gives the count and the first rows) instead of raising.
    joints : int, optional
        The joint count of the chain the log is read for: the columns a header's hint
        names (``q1..q5`` for a 5-joint chain whose servo log holds a sixth, the
        gripper's); None: the header's own count.

    Returns
    -------
    TorqueLog
        ``log.cleaning`` counts what was dropped and lists the gaps.

    Raises
    ------
    DataError
        Unknown suffix; a missing or duplicated column or array, a joint signal outside
        ``1..n``; an incomplete
        ``ddq`` set; a non-numeric cell, a row with the wrong number of fields (the line);
        a row count other than the recorded one; NaN/inf or repeated timestamps unless
        ``drop_invalid``; timestamps running backwards.
    OSError
        The file cannot be read.
    """
    path = Path(path)
    suffix = path.suffix.lower()
    if suffix == ".npz":
        arrays, lines = _read_npz(path), None
    elif suffix == ".csv":
        arrays, lines = _read_csv(path, joints)
    else:
        raise DataError(f"torque log must be a .csv or .npz file{bag_hint(path)}", file=path.name)
    _check_rows(path, arrays, lines, drop_invalid)
    derive = "dq" not in arrays
    if derive:
        arrays["dq"] = np.zeros_like(arrays["q"])
    try:
        log = TorqueLog.from_raw(**arrays, gap_factor=gap_factor)
        if derive:
            # (-v; the commands say it once for every such recording they read:
            # dynid.workflows.recordings.check_derived_velocities)
            _log.info("%s: %s", path.name, velocity_note(DEFAULT_CUTOFF_HZ))
            log = with_derived_velocities(log, DEFAULT_CUTOFF_HZ)
        return log
    except DataError as exc:
        raise DataError(str(exc), file=path.name) from exc


def _where(rows: NDArray[np.intp], lines: tuple[int, int] | None) -> str:
    """``row 12 (line 15), row 40 (line 43), ...`` for the first few rows."""

    def one(r: int) -> str:
        return f"row {r} (line {lines[0] + r})" if lines is not None else f"row {r}"

    shown = ", ".join(one(int(r)) for r in rows[:5])
    return shown + (", ..." if rows.size > 5 else "")


def _check_rows(
    path: Path,
    arrays: dict[str, NDArray[np.float64]],
    lines: tuple[int, int] | None,
    drop_invalid: bool,
) -> None:
    """NaN/inf rows and repeated timestamps: raise, or (``drop_invalid``) report them.

    ``lines`` is (line number of data row 0, rows) when rows map to lines one to one.
    """
    t = arrays["t"]
    ok = np.isfinite(t)
    for k in _SIGNALS:
        if k in arrays:
            for c in range(arrays[k].shape[1]):  # a column at a time: no (N, n) temporary
                ok &= np.isfinite(arrays[k][:, c])
    bad = np.flatnonzero(~ok)
    if bad.size:
        good = np.flatnonzero(ok)
        tg = t[good]
        dup = good[1:][tg[1:] == tg[:-1]]
    else:  # every row valid (the usual log): no index of them
        dup = np.flatnonzero(t[1:] == t[:-1]) + 1
    hint = "fix the file or pass --drop-invalid (drop_invalid=True) to drop such rows"
    if bad.size and not drop_invalid:
        r = int(bad[0])
        col = "t"
        for k in (k for k in _SIGNALS if k in arrays and np.isfinite(t[r])):
            j = np.flatnonzero(~np.isfinite(arrays[k][r]))
            if j.size:
                col = f"{k}{int(j[0]) + 1}"
                break
        raise DataError(
            f"{bad.size} row(s) hold NaN, inf or an empty cell; first "
            f"{_where(bad[:1], lines)} in {col!r}; hint: {hint}",
            file=path.name,
        )
    if dup.size and not drop_invalid:
        raise DataError(
            f"{dup.size} row(s) repeat the previous timestamp; first "
            f"{_where(dup[:1], lines)} (t = {float(t[dup[0]])!r}); hint: {hint}",
            file=path.name,
        )
    if bad.size:
        _log.warning(
            "%s: dropped %d row(s) of %d holding NaN, inf or an empty cell: %s",
            path.name,
            bad.size,
            t.size,
            _where(bad, lines),
        )
    if dup.size:
        _log.warning(
            "%s: dropped %d row(s) of %d repeating the previous timestamp: %s",
            path.name,
            dup.size,
            t.size,
            _where(dup, lines),
        )


def _read_npz(path: Path) -> dict[str, NDArray[np.float64]]:
    check_npz(path)
    try:
        npz = np.load(path, allow_pickle=False)
    except (ValueError, OSError, EOFError, zipfile.BadZipFile) as exc:
        raise DataError(f"not a readable NPZ file without pickles ({exc})", file=path.name) from exc
    if not hasattr(npz, "files"):
        raise DataError("a single .npy array, not an NPZ archive of arrays", file=path.name)
    arrays = {}
    try:
        with npz:
            missing = [k for k in ("t", "q", "tau") if k not in npz.files]
            if missing:
                raise DataError(
                    f"missing array(s) {_checks.names(missing)}; expected t, q, tau (optional "
                    f"dq, derived from q when absent, and ddq); found "
                    f"{_checks.names(sorted(npz.files))}",
                    file=path.name,
                )
            extra = sorted(set(npz.files) - {"t", "n_rows", *_SIGNALS})
            _say_unread(path.name, "array(s)", extra)
            n_rows = None
            for k in ("t", "n_rows", *_SIGNALS):
                if k not in npz.files:
                    continue
                try:
                    a = np.asarray(npz[k])
                except ValueError as exc:  # object arrays need pickles, which are refused
                    raise DataError(f"array {k!r} cannot be read ({exc})", file=path.name) from exc
                if k == "n_rows":
                    if a.shape != () or not np.issubdtype(a.dtype, np.integer):
                        raise DataError("array 'n_rows' must be one integer", file=path.name)
                    n_rows = int(a)
                    continue
                if not np.issubdtype(a.dtype, np.number) or np.iscomplexobj(a):
                    raise DataError(
                        f"array {k!r} must be real numbers; got dtype {a.dtype}", file=path.name
                    )
                arrays[k] = _checks.frozen(a.astype(np.float64, copy=False))  # kept as is
                del a
    except (zipfile.BadZipFile, EOFError, OSError) as exc:
        raise DataError(f"not a readable NPZ file ({exc})", file=path.name) from exc
    t = arrays["t"]
    if t.ndim != 1:
        raise DataError(f"array 't' must have shape (N,); got {t.shape}", file=path.name)
    check_row_count(path, n_rows, t.shape[0])
    for k in _SIGNALS:
        if k in arrays and (arrays[k].ndim != 2 or arrays[k].shape[0] != t.shape[0]):
            raise DataError(
                f"array {k!r} must have shape ({t.shape[0]}, n) like t; got {arrays[k].shape}",
                file=path.name,
            )
    return arrays


def _annotated_hint(names: list[str]) -> str:
    """A hint for a header whose names carry units (``q1 [rad]``, ``tau1 (Nm)``): the
    ``--columns`` map that reads them (``q=q{i} [rad]``), or nothing."""
    found: dict[str, str] = {}
    for c in names:
        m = re.fullmatch(r"(t|q|dq|tau|ddq)([1-9]\d*)?(\s*[\[(].*[\])])", c.strip())
        if m and m.group(1) not in found and (m.group(1) == "t") == (m.group(2) is None):
            found[m.group(1)] = m.group(1) + ("{i}" if m.group(2) else "") + m.group(3)
    if "t" not in found or "q" not in found:
        return ""
    spec = ",".join(f"{k}={found[k]}" for k in ("t", "q", "dq", "tau", "ddq") if k in found)
    return f"; hint: names with units are read by --columns '{spec}' (and --units if not SI)"


def _columns(
    path: Path, names: list[str], line: int, joints: int | None = None
) -> tuple[int, bool]:
    """Check the header; return the joint count n and whether ddq columns are present
    (``joints``: the chain's joint count, the columns a hint names; None: the header's)."""
    at = f"line {line}"
    dup = sorted({c for c in names if names.count(c) > 1})
    if dup:
        raise DataError(
            f"duplicated column(s) {_checks.names(dup)}; each column must appear once",
            file=path.name,
            at=at,
        )
    qs = sorted(int(c[1:]) for c in names if re.fullmatch(r"q[1-9]\d*", c))
    n = len(qs)
    if "t" not in names or n == 0:
        hint = _annotated_hint(names) or import_hint(names, path.name)
        time = "t" if "t" in names else time_column(names)
        if not hint and time is not None and (k := position_count(names)):
            named = {s: all(f"{s}{j}" in names for j in range(1, k + 1)) for s in _SIGNALS}
            signals = [s for s in ("q", "tau") if not named[s]]  # q0..q6 counts from 0
            optional = ["dq"] if not named["dq"] else []
            unit = re.search(r"(ms|us|ns)$", time.lower())
            hint = column_hint(names, k, signals, {time}, optional, named=joints)
            hint = hint.split("; hint: ", 1)[-1]
            if not signals and time != "t":  # the joints' columns named right, not the time
                hint = (
                    f"--columns 't={time}'"
                    + (f" --units t={unit[1]}" if unit else "")
                    + f" reads {time} as the time, or name it t"
                )
            elif time != "t" and "--columns '" in hint:  # the time column mapped too
                hint = hint.replace("--columns '", f"--columns 't={time},", 1)
                if unit and "--units '" in hint:  # one --units (currents: tau=A)
                    hint = hint.replace("--units '", f"--units 't={unit[1]},", 1)
                elif unit:
                    hint = hint.replace("' reads them", f"' --units t={unit[1]} reads them", 1)
            hint = f"; hint: {hint}"
        raise DataError(
            f"header must name columns t, q1..qn, dq1..dqn, tau1..taun; "
            f"got {_checks.names(names)}{hint}",
            file=path.name,
            at=at,
        )
    if qs != list(range(1, n + 1)):
        gap = sorted(set(range(1, max(qs) + 1)) - set(qs))
        raise DataError(
            f"joint position columns must be q1..qn; missing q{gap[0]}", file=path.name, at=at
        )
    need = torque_log_columns(n)
    if not any(f"dq{j}" in names for j in range(1, n + 1)):  # positions only
        need = [c for c in need if not c.startswith("dq")]
    missing = [c for c in need if c not in names]
    if missing:
        gone = [s for s in _SIGNALS[1:3] if all(f"{s}{j}" in missing for j in range(1, n + 1))]
        used = {"t", *need, *(f"ddq{j}" for j in range(1, n + 1))}
        none = no_torques(names, n, used) if "tau" in gone else ""
        raise DataError(
            f"missing column(s) {_span(missing)} (n = {n} from q1..q{n})"
            + (f": {none}" if none else column_hint(names, n, gone, used)),
            file=path.name,
        )
    ddq = [f"ddq{j}" for j in range(1, n + 1)]
    have = [c for c in ddq if c in names]
    if have and len(have) != n:
        raise DataError(
            f"accelerations must be all of ddq1..ddq{n} or none; got only {_checks.names(have)}",
            file=path.name,
            at=at,
        )
    unknown = [c for c in names if c not in set(need) | set(ddq)]
    signals = [c for c in unknown if re.fullmatch(r"(q|dq|tau|ddq)\d+", c)]
    if signals:
        raise DataError(
            f"unknown column(s) {_checks.names(signals)}; a torque log has t, q1..q{n}, "
            f"dq1..dq{n} (optional: derived from q when absent), tau1..tau{n} and optionally "
            f"ddq1..ddq{n}",
            file=path.name,
            at=at,
        )
    _say_unread(path.name, "column(s)", unknown)
    return n, bool(have)


#: The columns (CSV) or arrays (NPZ) of a log read as contact labels (nonzero: in
#: contact) when no ``label`` column is mapped, the first the log has
#: (:func:`dynid.io.columns.load_label_column`).
LABEL_COLUMNS = ("collision", "contact", "label")


def _span(columns: list[str]) -> str:
    """Columns for a message: ``tau1..tau7`` for a run of one signal, else their names."""
    m = [re.fullmatch(r"([a-z]+)(\d+)", c) for c in columns]
    if len(columns) > 2 and all(m) and len({x.group(1) for x in m if x}) == 1:
        idx = [int(x.group(2)) for x in m if x]
        if idx == list(range(idx[0], idx[0] + len(idx))):
            return f"{columns[0]}..{columns[-1]}"
    return _checks.names(columns)


def _say_unread(name: str, kind: str, extra: list[str]) -> None:
    """An informational line for the true external torques a simulation writes
    (``tau_ext``: ground truth, which ``dynid observe`` compares its residual with and says
    so; a log of dynid's own simulation is no cause for a warning) and for a column of
    contact labels (:data:`LABEL_COLUMNS`, which ``dynid observe`` scores its events
    against), a warning for other columns (vendor estimates): kept in the file, not read
    as data."""
    truth = [c for c in extra if re.fullmatch(r"tau_ext\d*", c)]
    labels = [c for c in extra if c in LABEL_COLUMNS]
    rest = [c for c in extra if c not in truth and c not in labels]
    if labels:
        _log.info(
            "%s: %s %s hold contact labels: never read as data (dynid observe scores its "
            "events against them)",
            name,
            kind,
            _checks.names(labels),
        )
    if truth:
        span = truth[0] if len(truth) == 1 else f"{truth[0]}..{truth[-1]}"
        _log.info(
            "%s: %s %s hold the true external torques of a simulation: ground truth, never "
            "read as data (dynid observe reports its residual against them)",
            name,
            kind,
            span,
        )
    if rest:
        _log.warning(
            "%s: %s %s are not torque-log signals: ignored as data", name, kind, _checks.names(rest)
        )


def _read_csv(
    path: Path, joints: int | None = None
) -> tuple[dict[str, NDArray[np.float64]], tuple[int, int] | None]:
    """The arrays of a CSV log, and (line of the first data row, rows) for messages
    (``joints``: the chain's joint count, for a header's hint)."""

    def layout(names: list[str], line: int) -> dict[str, list[int]]:
        n, with_ddq = _columns(path, names, line, joints)
        index = {c: k for k, c in enumerate(names)}
        out = {"t": [index["t"]]}
        for k in _SIGNALS if with_ddq else _SIGNALS[:3]:
            if f"{k}1" in index:  # dq may be absent (positions only)
                out[k] = [index[f"{k}{j}"] for j in range(1, n + 1)]
        return out

    arrays, lines = csv_table(path, layout, "t,q1,...,dq1,...,tau1,...")
    arrays["t"] = arrays["t"].reshape(-1)
    return arrays, lines
