"""Reading and writing torque logs as CSV or NPZ.

CSV: an optional comment line (``#``) with the units, then a header naming the columns,
then one row per sample::

    # dynid torque log; units: t [s], q [rad], dq [rad/s], tau [N m], ddq [rad/s^2]
    t,q1,...,qn,dq1,...,dqn,tau1,...,taun[,ddq1,...,ddqn]

Columns are found by name (any order; other columns are ignored); ``n`` is the number of
``q`` columns. Empty cells and ``nan`` read as NaN. NPZ: arrays ``t`` (N,), ``q``, ``dq``,
``tau`` and optionally ``ddq`` (N, n), loaded with ``allow_pickle=False``.

Reading cleans the log with :meth:`~dynid.identification.log.TorqueLog.from_raw`: rows
with NaN are dropped and counted, duplicate timestamps removed and counted, gaps
recorded (``log.cleaning``); timestamps running backwards are rejected. Malformed files
raise :class:`~dynid.exceptions.DataError` naming the file, the column and the line.
Writing uses 17 significant digits, so a round trip is exact.
"""

from __future__ import annotations

import io
from pathlib import Path

import numpy as np
from numpy.typing import NDArray

from ..exceptions import DataError
from ..identification.log import TorqueLog

__all__ = ["read_torque_log", "write_torque_log", "torque_log_columns"]

_UNITS = "# dynid torque log; units: t [s], q [rad], dq [rad/s], tau [N m], ddq [rad/s^2]"


def torque_log_columns(n: int, *, with_ddq: bool = False) -> list[str]:
    """Column names ``t, q1..qn, dq1..dqn, tau1..taun`` (then ``ddq1..ddqn``)."""
    cols = ["t"]
    for k in ("q", "dq", "tau") + (("ddq",) if with_ddq else ()):
        cols += [f"{k}{j}" for j in range(1, n + 1)]
    return cols


def write_torque_log(path: str | Path, log: TorqueLog) -> Path:
    """Write ``log`` to ``path`` (``.csv`` or ``.npz``, by suffix); returns the path.

    Raises
    ------
    DataError
        Unknown suffix.
    """
    path = Path(path)
    suffix = path.suffix.lower()
    if suffix == ".npz":
        arrays = {"t": log.t, "q": log.q, "dq": log.dq, "tau": log.tau}
        if log.ddq is not None:
            arrays["ddq"] = log.ddq
        with open(path, "wb") as f:
            np.savez(f, **arrays)
        return path
    if suffix != ".csv":
        raise DataError(f"torque log must be a .csv or .npz file; got {path.name!r}")
    parts = [log.t[:, None], log.q, log.dq, log.tau]
    if log.ddq is not None:
        parts.append(log.ddq)
    data = np.concatenate(parts, axis=1)
    header = _UNITS + "\n" + ",".join(torque_log_columns(log.n, with_ddq=log.ddq is not None))
    np.savetxt(path, data, delimiter=",", fmt="%.17g", header=header, comments="")
    return path


def read_torque_log(path: str | Path, *, gap_factor: float = 1.5) -> TorqueLog:
    """Read a torque log from a ``.csv`` or ``.npz`` file and clean it.

    Parameters
    ----------
    path : str or Path
    gap_factor : float
        Steps longer than this times the median step are recorded as gaps.

    Returns
    -------
    TorqueLog
        Cleaned (``log.cleaning`` says what was dropped).

    Raises
    ------
    DataError
        Unknown suffix, missing column or array, a non-numeric cell, a row with the wrong
        number of fields, timestamps running backwards.
    OSError
        The file cannot be read.
    """
    path = Path(path)
    suffix = path.suffix.lower()
    if suffix == ".npz":
        return _read_npz(path, gap_factor)
    if suffix == ".csv":
        return _read_csv(path, gap_factor)
    raise DataError(f"torque log must be a .csv or .npz file; got {path.name!r}")


def _read_npz(path: Path, gap_factor: float) -> TorqueLog:
    try:
        npz = np.load(path, allow_pickle=False)
    except ValueError as exc:
        raise DataError(f"{path.name}: not a readable NPZ file without pickles ({exc})") from exc
    with npz:
        missing = [k for k in ("t", "q", "dq", "tau") if k not in npz.files]
        if missing:
            raise DataError(
                f"{path.name}: missing array(s) {missing}; expected t, q, dq, tau (optional ddq); "
                f"found {sorted(npz.files)}"
            )
        arrays = {}
        for k in ("t", "q", "dq", "tau", "ddq"):
            if k not in npz.files:
                continue
            try:
                arrays[k] = np.asarray(npz[k])
            except ValueError as exc:  # object arrays need pickles, which are refused
                raise DataError(f"{path.name}: array {k!r} cannot be read ({exc})") from exc
    for k, a in arrays.items():
        if not np.issubdtype(a.dtype, np.number):
            raise DataError(f"{path.name}: array {k!r} must be numeric; got dtype {a.dtype}")
    try:
        return TorqueLog.from_raw(**arrays, gap_factor=gap_factor)
    except DataError as exc:
        raise DataError(f"{path.name}: {exc}") from exc


def _header(path: Path, lines: list[str]) -> tuple[int, list[str]]:
    for i, line in enumerate(lines):
        s = line.strip()
        if s and not s.startswith("#"):
            return i, [c.strip() for c in s.split(",")]
    raise DataError(f"{path.name}: no header line (t,q1,...,dq1,...,tau1,...) found")


def _slow_parse(path: Path, lines: list[str], first: int, width: int, names: list[str]) -> NDArray:
    rows = []
    for i in range(first, len(lines)):
        s = lines[i].strip()
        if not s or s.startswith("#"):
            continue
        cells = s.split(",")
        if len(cells) != width:
            raise DataError(
                f"{path.name}, line {i + 1}: expected {width} fields like the header; "
                f"got {len(cells)}"
            )
        row = []
        for c, name in zip(cells, names, strict=True):
            c = c.strip()
            if c == "":
                row.append(np.nan)
                continue
            try:
                row.append(float(c))
            except ValueError:
                raise DataError(
                    f"{path.name}, line {i + 1}, column {name!r}: not a number: {c!r}"
                ) from None
        rows.append(row)
    return np.array(rows, dtype=np.float64).reshape(-1, width)


def _read_csv(path: Path, gap_factor: float) -> TorqueLog:
    text = path.read_text()
    lines = text.splitlines()
    h, names = _header(path, lines)
    index = {c: k for k, c in enumerate(names)}
    n = 0
    while f"q{n + 1}" in index:
        n += 1
    if "t" not in index or n == 0:
        raise DataError(
            f"{path.name}: header must name columns t, q1..qn, dq1..dqn, tau1..taun; "
            f"got {names[:8]}..."
        )
    need = torque_log_columns(n)
    missing = [c for c in need if c not in index]
    if missing:
        raise DataError(f"{path.name}: missing column(s) {missing} (n = {n} from q1..q{n})")
    with_ddq = all(f"ddq{j}" in index for j in range(1, n + 1))
    body = "\n".join(lines[h + 1 :])
    try:
        data = np.loadtxt(io.StringIO(body), delimiter=",", ndmin=2, comments="#")
        if data.size and data.shape[1] != len(names):
            raise ValueError("width")
    except ValueError:
        data = _slow_parse(path, lines, h + 1, len(names), names)
    if data.shape[0] == 0:
        raise DataError(f"{path.name}: no data rows after the header")
    col = lambda k: data[:, [index[c] for c in k]]  # noqa: E731
    qs = [f"q{j}" for j in range(1, n + 1)]
    arrays = {
        "t": data[:, index["t"]],
        "q": col(qs),
        "dq": col(["d" + c for c in qs]),
        "tau": col([f"tau{j}" for j in range(1, n + 1)]),
    }
    if with_ddq:
        arrays["ddq"] = col(["dd" + c for c in qs])
    try:
        return TorqueLog.from_raw(**arrays, gap_factor=gap_factor)
    except DataError as exc:
        raise DataError(f"{path.name}: {exc}") from exc
