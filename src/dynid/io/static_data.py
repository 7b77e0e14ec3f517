"""Static data sets (``q``, ``M(q)``, ``g(q)`` at rest) to and from CSV and NPZ files.

CSV: one row per configuration. Leading lines starting with ``#`` are comments; the first
states the units, ``# rows: N`` the number of rows written, an optional
``# metadata: {...}`` line holds the data set's metadata as JSON. Then a header and the
rows. A UTF-8 byte-order mark (spreadsheet exports) is accepted. Columns (any order when read):

* ``q1 .. qn``: joint positions [rad] (m for a prismatic joint);
* ``M<i>_<j>`` for ``i >= j`` (1-based): the lower triangle of the inertia matrix
  [kg m^2] (kg m or kg in prismatic rows and columns), written in ``np.tril_indices``
  order (``M1_1, M2_1, M2_2, M3_1, ...``); the upper triangle follows by symmetry;
* ``g1 .. gn``: gravity torques [N m] (N).

NPZ: arrays ``q`` (N, n), ``M`` (N, n, n), ``g`` (N, n) and optionally ``n_rows`` (N)
and ``metadata`` (a JSON string); read with ``allow_pickle=False``.

Files are written atomically (:mod:`dynid.io.atomic`) and record their row count; when
a file states one, loading checks it, so a file cut short (a copy interrupted, a disk
full) is refused rather than read as a smaller data set.

Loading checks everything and raises :class:`~dynid.exceptions.DataError` naming the
column, key, line or row: missing or extra columns (keys), duplicated columns, cells that
are not numbers, NaN or inf, a non-symmetric ``M`` (NPZ), a joint count different from the
robot's, a row count different from the recorded one. With ``drop_invalid=True`` rows
with bad values are dropped instead, logged as a warning with their count and where they
are, and the count is returned (structural problems still raise).
"""

from __future__ import annotations

import logging
import re
import zipfile
from collections.abc import Mapping
from pathlib import Path
from typing import Any

import numpy as np
from numpy.typing import NDArray

from .. import _checks
from ..exceptions import DataError
from ..identification.consistency import recorded_robot_mismatch
from ..identification.data import DEFAULT_SYMMETRY_RTOL, StaticDataset
from ..model.robot import Robot
from ..regressors.static import static_labels
from .atomic import open_atomic
from .column_hint import holdings, static_map
from .input_files import regular_file
from .json_files import dumps, loads
from .npz_files import check_npz

__all__ = [
    "data_row_lines",
    "static_columns",
    "save_static_data",
    "load_static_data",
    "save_static_csv",
    "load_static_csv",
    "save_static_npz",
    "load_static_npz",
]

_log = logging.getLogger(__name__)

UNITS_LINE = (
    "# dynid static data set, one row per configuration: q<i> [rad] (m if prismatic), "
    "M<i>_<j> lower triangle (i >= j, 1-based) of M [kg m^2], g<i> [N m]"
)
_META_PREFIX = "# metadata:"
_ROWS_PREFIX = "# rows:"
_NPZ_KEYS = ("q", "M", "g")


def static_columns(n: int) -> tuple[str, ...]:
    """Column names for ``n`` joints: ``q1..qn``, ``M1_1, M2_1, M2_2, ...``, ``g1..gn``."""
    return tuple(f"q{k}" for k in range(1, n + 1)) + static_labels(n)


# ---------------------------------------------------------------------------- dispatch
def save_static_data(path: str | Path, data: StaticDataset) -> Path:
    """Write a data set to ``.csv`` or ``.npz`` (by the extension); returns the path."""
    path = Path(path)
    suffix = path.suffix.lower()
    if suffix == ".csv":
        return save_static_csv(path, data)
    if suffix == ".npz":
        return save_static_npz(path, data)
    raise DataError(f"static data file must end in .csv or .npz; got {path.name!r}")


def load_static_data(
    path: str | Path, robot: Robot | None = None, *, drop_invalid: bool = False
) -> tuple[StaticDataset, int]:
    """Read a ``.csv`` or ``.npz`` static data set of ``robot``.

    Parameters
    ----------
    path : str or Path
        The file (:func:`load_static_csv`, :func:`load_static_npz`).
    robot : Robot, optional
        The robot the data belong to: the file must have ``robot.n`` joints and, when it
        records the robot it was acquired with (``metadata`` ``robot`` and
        ``kinematics``, as ``dynid acquire-static`` writes them), that robot must be this
        one (name and kinematics).
    drop_invalid : bool
        Drop invalid rows (counted) instead of raising.

    Returns
    -------
    data : StaticDataset
        ``q`` (N, n) [rad], ``M`` (N, n, n) [kg m^2], ``g`` (N, n) [N m] and metadata.
    n_dropped : int
        Rows dropped (0 unless ``drop_invalid``).

    Raises
    ------
    DataError
        A file that is not ``.csv``/``.npz``, a bad file (:func:`load_static_csv`), or
        data recorded with another robot than ``robot`` (named, with the hint to pass
        ``--robot`` for the arm that recorded them).
    """
    path = Path(path)
    suffix = path.suffix.lower()
    if suffix == ".csv":
        data, n_dropped = load_static_csv(path, robot, drop_invalid=drop_invalid)
    elif suffix == ".npz":
        data, n_dropped = load_static_npz(path, robot, drop_invalid=drop_invalid)
    else:
        raise DataError(f"static data file must end in .csv or .npz; got {path.name!r}")
    mismatch = None if robot is None else recorded_robot_mismatch(robot, data.metadata)
    if mismatch is not None:
        raise DataError(
            f"{mismatch}; hint: pass --robot for the arm that recorded the data", file=path.name
        )
    return data, n_dropped


# ---------------------------------------------------------------------------- CSV
def save_static_csv(path: str | Path, data: StaticDataset) -> Path:
    """Write a data set as CSV (full float64 precision, ``%.17g``); returns the path."""
    path = Path(path)
    n = data.n
    i, j = np.tril_indices(n)
    table = np.concatenate([data.q, data.M[:, i, j], data.g], axis=1)
    header = ",".join(static_columns(n))
    lines = [UNITS_LINE, f"{_ROWS_PREFIX} {len(table)}"]
    if data.metadata:
        lines.append(f"{_META_PREFIX} {dumps(dict(data.metadata), indent=None)}")
    with open_atomic(path, "w") as fh:
        fh.write("\n".join(lines) + "\n" + header + "\n")
        np.savetxt(fh, table, fmt="%.17g", delimiter=",")
    return path


def load_static_csv(
    path: str | Path, robot: Robot | None = None, *, drop_invalid: bool = False
) -> tuple[StaticDataset, int]:
    """Read a static data set from CSV.

    Parameters
    ----------
    path : str or Path
    robot : Robot, optional
        When given, the file must have ``robot.n`` joints.
    drop_invalid : bool
        Drop rows with a wrong cell count, a cell that is not a number, NaN or inf
        (logged, counted) instead of raising.

    Returns
    -------
    data : StaticDataset
        ``q`` (N, n) [rad], ``M`` (N, n, n) [kg m^2] (symmetric), ``g`` (N, n) [N m];
        metadata from the file plus ``file`` (its name) and ``dropped_invalid_rows``.
    n_dropped : int
        Rows dropped (0 unless ``drop_invalid``).

    Raises
    ------
    DataError
        No header, duplicated, missing or extra columns (named), a joint count different
        from the robot's, a bad row (its line number and column) unless ``drop_invalid``,
        or no valid row at all.
    """
    path = Path(path)
    regular_file(path)
    try:
        text = path.read_text(encoding="utf-8-sig")
    except UnicodeDecodeError as exc:
        raise DataError(f"not a UTF-8 text file ({exc.reason})", file=path.name) from exc
    meta: dict[str, Any] = {}
    n_recorded: int | None = None
    header: list[str] | None = None
    header_line = 0
    rows: list[tuple[int, list[str]]] = []
    for lineno, raw in enumerate(text.splitlines(), start=1):
        line = raw.strip()
        if not line:
            continue
        if line.startswith("#"):
            if header is None and line.startswith(_META_PREFIX):
                meta = _parse_meta(path, f"line {lineno}", line[len(_META_PREFIX) :])
            elif header is None and line.startswith(_ROWS_PREFIX):
                n_recorded = _parse_rows(path, lineno, line[len(_ROWS_PREFIX) :])
            continue
        cells = [c.strip() for c in line.split(",")]
        if header is None:
            header, header_line = cells, lineno
        else:
            rows.append((lineno, cells))
    if header is None:
        raise DataError(
            f"no header line found; expected columns {_expected_hint(robot)}", file=path.name
        )
    check_row_count(path, n_recorded, len(rows))
    n = _check_columns(path, header, header_line, robot)
    cols = static_columns(n)
    where = {name: header.index(name) for name in cols}
    order = np.array([where[c] for c in cols])
    good: list[list[float]] = []
    bad: list[str] = []
    for lineno, cells in rows:
        reason = None
        if len(cells) != len(header):
            reason = f"has {len(cells)} cells, the header {len(header)}"
            values = None
        else:
            values = []
            for k in order:
                try:
                    v = _checks.decimal(cells[k])
                except ValueError:
                    reason = f"column {header[k]!r}: {cells[k]!r} is not a number"
                    break
                if not np.isfinite(v):
                    reason = f"column {header[k]!r} holds {cells[k]}"
                    break
                values.append(v)
        if reason is not None:
            msg = f"line {lineno} (row {len(good) + len(bad)}) {reason}"
            if not drop_invalid:
                raise DataError(
                    f"row {len(good) + len(bad)} {reason}; hint: fix the file or pass "
                    "--drop-invalid (drop_invalid=True) to drop such rows",
                    file=path.name,
                    at=f"line {lineno}",
                )
            bad.append(msg)
            continue
        assert values is not None
        good.append(values)
    table = np.array(good, dtype=np.float64).reshape(len(good), len(cols))
    return _finish(path, table, n, meta, bad)


def _check_columns(path: Path, header: list[str], line: int, robot: Robot | None) -> int:
    """Validate the header; return the joint count."""
    dup = sorted({c for c in header if header.count(c) > 1})
    if dup:
        raise DataError(
            f"duplicated columns {_checks.names(dup)}", file=path.name, at=f"line {line}"
        )
    if robot is not None and (guess := static_map(header, robot.n)):
        expected = static_columns(robot.n)
        if any(c not in header for c in expected):  # another tool's names: the map that reads them
            raise DataError(
                f"the columns {holdings(header)} are not dynid's static format "
                f"({_expected_hint(robot)}); hint: {guess} reads them ({{i0}}: joints from 0; "
                "{k0}: M as one flat column-major array, k = i + n j from 0, as libfranka's)",
                file=path.name,
                at=f"line {line}",
            )
    qcols = [c for c in header if re.fullmatch(r"q[1-9]\d*", c)]
    if not qcols:
        raise DataError(
            f"no joint position columns q1..qn; got columns "
            f"{header[:8]}{' ...' if len(header) > 8 else ''}",
            file=path.name,
            at=f"line {line}",
        )
    n_file = max(int(c[1:]) for c in qcols)
    n = robot.n if robot is not None else n_file
    if robot is not None and n_file != robot.n:
        raise DataError(
            f"data for {n_file} joints (columns q1..q{n_file}); robot "
            f"{robot.name!r} has {robot.n}; hint: pass the robot the data were recorded with",
            file=path.name,
        )
    expected = static_columns(n)
    missing = [c for c in expected if c not in header]
    extra = [c for c in header if c not in expected]
    if missing:
        raise DataError(
            f"missing columns {_checks.names(missing)}; expected q1..q{n}, M<i>_<j> (i >= j) "
            f"and g1..g{n}",
            file=path.name,
            at=f"line {line}",
        )
    if extra:
        raise DataError(
            f"unexpected columns {_checks.names(extra)}; expected q1..q{n}, M<i>_<j> (i >= j) "
            f"and g1..g{n} only",
            file=path.name,
            at=f"line {line}",
        )
    return n


def _parse_rows(path: Path, lineno: int, text: str) -> int:
    try:
        n = _checks.integer(text)
    except ValueError:
        raise DataError(
            "'# rows:' must give an integer", file=path.name, at=f"line {lineno}"
        ) from None
    if n < 0:
        raise DataError(f"'# rows:' must be >= 0; got {n}", file=path.name, at=f"line {lineno}")
    return n


def check_row_count(path: Path, recorded: int | None, found: int) -> None:
    """Raise :class:`DataError` when a file holds fewer or more rows than it recorded."""
    if recorded is not None and recorded != found:
        raise DataError(
            f"the file records {recorded} rows but holds {found}; it is "
            "incomplete or was edited (a write or copy cut short?); regenerate it, or, if "
            "rows were removed on purpose, correct or delete its '# rows:' line",
            file=path.name,
        )


def _parse_meta(path: Path, where: str, text: str) -> dict[str, Any]:
    try:
        meta = loads(text)
    except ValueError as exc:
        raise DataError(f"metadata is not strict JSON ({exc})", file=path.name, at=where) from exc
    if not isinstance(meta, dict):
        raise DataError("metadata must be a JSON object", file=path.name, at=where)
    return meta


def _expected_hint(robot: Robot | None) -> str:
    n = "n" if robot is None else str(robot.n)
    return f"q1..q{n}, M<i>_<j> (i >= j), g1..g{n}"


# ---------------------------------------------------------------------------- NPZ
def save_static_npz(path: str | Path, data: StaticDataset) -> Path:
    """Write a data set as NPZ (``q``, ``M``, ``g``, ``metadata`` as JSON); returns the path."""
    path = Path(path)
    meta = dumps(dict(data.metadata), indent=None)
    with open_atomic(path, "wb") as fh:
        np.savez(
            fh,
            q=data.q,
            M=data.M,
            g=data.g,
            n_rows=np.array(data.q.shape[0]),
            metadata=np.array(meta),
        )
    return path


def load_static_npz(
    path: str | Path, robot: Robot | None = None, *, drop_invalid: bool = False
) -> tuple[StaticDataset, int]:
    """Read a static data set from NPZ (``allow_pickle=False``).

    Same parameters, returns and errors as :func:`load_static_csv`; rows with NaN or inf
    or a non-symmetric ``M`` are the droppable ones. Missing or extra keys, or arrays of
    the wrong shape, raise :class:`DataError` naming the key.
    """
    path = Path(path)
    check_npz(path)
    try:
        with np.load(path, allow_pickle=False) as z:
            keys = set(z.files)
            missing = [k for k in _NPZ_KEYS if k not in keys]
            extra = sorted(keys - set(_NPZ_KEYS) - {"metadata", "n_rows"})
            if missing:
                raise DataError(
                    f"missing arrays {_checks.names(missing)}; expected q, M, g", file=path.name
                )
            if extra:
                raise DataError(
                    f"unexpected arrays {_checks.names(extra)}; expected q, M, g (and metadata)",
                    file=path.name,
                )
            arrays = {k: np.asarray(z[k]) for k in _NPZ_KEYS}
            meta_text = str(z["metadata"]) if "metadata" in keys else "{}"
            n_recorded = _npz_rows(path, z) if "n_rows" in keys else None
    except (AttributeError, TypeError):  # a single .npy array: np.load gives an array
        raise DataError("a single array, not an NPZ archive of q, M, g", file=path.name) from None
    except (zipfile.BadZipFile, OSError, ValueError, EOFError, KeyError) as exc:
        if isinstance(exc, DataError):
            raise
        raise DataError(f"not a readable NPZ file of arrays ({exc})", file=path.name) from exc
    for k, a in arrays.items():
        if not np.issubdtype(a.dtype, np.number) or np.iscomplexobj(a):
            raise DataError(
                f"array {k!r} must be real numbers; got dtype {a.dtype}", file=path.name
            )
    q, M, g = (arrays[k].astype(np.float64) for k in _NPZ_KEYS)
    if q.ndim != 2 or q.shape[0] < 1:
        raise DataError(f"array 'q' must have shape (N, n); got {q.shape}", file=path.name)
    N, n = q.shape
    check_row_count(path, n_recorded, N)
    if robot is not None and n != robot.n:
        raise DataError(
            f"data for {n} joints (q of shape {q.shape}); robot {robot.name!r} "
            f"has {robot.n}; hint: pass the robot the data were recorded with",
            file=path.name,
        )
    if M.shape != (N, n, n):
        raise DataError(f"array 'M' must have shape {(N, n, n)}; got {M.shape}", file=path.name)
    if g.shape != (N, n):
        raise DataError(f"array 'g' must have shape {(N, n)}; got {g.shape}", file=path.name)
    meta = _parse_meta(path, "array 'metadata'", meta_text)
    i, j = np.tril_indices(n)
    bad: list[str] = []
    ok = np.ones(N, bool)
    for name, a in (("q", q), ("M", M), ("g", g)):
        fin = np.isfinite(a.reshape(N, -1)).all(axis=1)
        for s in np.flatnonzero(ok & ~fin):
            bad.append(f"row {s}: {name} holds NaN or inf")
        ok &= fin
    Mf = np.where(np.isfinite(M), M, 0.0)
    asym = np.max(np.abs(Mf - np.swapaxes(Mf, 1, 2)), axis=(1, 2))
    sym = asym <= DEFAULT_SYMMETRY_RTOL * np.max(np.abs(Mf), axis=(1, 2))
    for s in np.flatnonzero(ok & ~sym):
        bad.append(f"row {s}: M is not symmetric (max |M - M^T| = {asym[s]:.3g})")
    ok &= sym
    if bad and not drop_invalid:
        first = min(bad, key=lambda b: int(b.split(":")[0].split()[1]))
        raise DataError(
            f"{first} ({len(bad)} bad row(s) in all); hint: fix the file or pass "
            "--drop-invalid (drop_invalid=True) to drop such rows",
            file=path.name,
        )
    table = np.concatenate([q, M[:, i, j], g], axis=1)[ok]
    return _finish(path, table, n, meta, bad)


# ---------------------------------------------------------------------------- common
def _finish(
    path: Path, table: NDArray[np.float64], n: int, meta: Mapping[str, Any], bad: list[str]
) -> tuple[StaticDataset, int]:
    """Data set from the valid rows ``[q, tril M, g]`` of a file."""
    if bad:
        _log.warning(
            "%s: dropped %d invalid row(s) of %d: %s%s",
            path.name,
            len(bad),
            len(bad) + len(table),
            "; ".join(bad[:5]),
            "; ..." if len(bad) > 5 else "",
        )
    if len(table) == 0:
        raise DataError(f"no valid configuration ({len(bad)} invalid row(s))", file=path.name)
    i, j = np.tril_indices(n)
    q = table[:, :n]
    M = np.zeros((len(table), n, n))
    M[:, i, j] = table[:, n : n + i.size]
    M[:, j, i] = table[:, n : n + i.size]
    g = table[:, n + i.size :]
    info = dict(meta)
    info["file"] = path.name
    info["dropped_invalid_rows"] = len(bad)
    return StaticDataset(q, M, g, info), len(bad)


def _npz_rows(path: Path, z: Any) -> int:
    a = np.asarray(z["n_rows"])
    if a.shape != () or not np.issubdtype(a.dtype, np.integer) or int(a) < 0:
        raise DataError(f"array 'n_rows' must be one integer >= 0; got {a!r}", file=path.name)
    return int(a)


def data_row_lines(path: str | Path, n_rows: int) -> tuple[int, ...] | None:
    """The line (from 1) of each data row of a CSV file of static data, dynid's or another
    tool's: the lines after the header that are neither empty nor comments; None for an
    NPZ file, or when the file holds another number of rows than ``n_rows`` (rows were
    dropped as they were read: which ones, the lines cannot tell)."""
    path = Path(path)
    if path.suffix.lower() != ".csv":
        return None
    lines: list[int] = []
    header = False
    with path.open(encoding="utf-8-sig", errors="replace") as fh:
        for k, raw in enumerate(fh, start=1):
            s = raw.strip()
            if not s or s.startswith("#"):
                continue
            if header:
                lines.append(k)
            header = True
    return tuple(lines) if len(lines) == n_rows else None
