"""The strict reader of dynid's CSV tables (torque logs, ``--columns`` logs, trajectories).

A table is comment lines (``#``; ``# rows: N`` is checked against the rows found), a header
naming the columns, then one row of numbers per line. The reader makes two passes over the
file in binary blocks: the first counts the lines (an upper bound of the rows), so that the
output arrays are allocated once at their final size; the second parses the rows a block
at a time with numpy's C number reader, only the columns some output array takes, straight
into those arrays. Memory: the output arrays (immutable without a copy), one block of text
and its table of numbers, whatever the file's size and whether it records its row count.
"""

from __future__ import annotations

import io
import warnings
from collections.abc import Callable
from pathlib import Path
from typing import IO

import numpy as np
from numpy.typing import NDArray

from .. import _checks
from ..exceptions import DataError
from ..progress import report
from .input_files import regular_file
from .static_data import check_row_count

__all__ = ["csv_table", "ROWS_PREFIX"]

#: The comment line that records the row count of a table.
ROWS_PREFIX = "# rows:"

#: Bytes of CSV text parsed at a time (bounded memory whatever the file size).
_CHUNK_BYTES = 32 << 20


def csv_table(
    path: Path,
    layout_of: Callable[[list[str], int], dict[str, list[int]]],
    expected: str,
    *,
    freeze: bool = True,
) -> tuple[dict[str, NDArray[np.float64]], tuple[int, int] | None]:
    """Read a dynid CSV table: comment lines (``# rows: N`` checked), a header, numbers.

    Parameters
    ----------
    path : Path
    layout_of : callable
        ``layout_of(names, line)`` checks the header's column names (found on ``line``)
        and returns, per output array, the indices of its columns (only these columns are
        parsed; the others may hold anything but a comma).
    expected : str
        The header expected, for the message when there is none.
    freeze : bool
        Return the arrays immutable (as :func:`dynid._checks.frozen` wants them, no copy);
        False: writable, for a caller that changes them in place (units) and then
        freezes them itself.

    Returns
    -------
    arrays : dict of str to ndarray, shape (N, k) each, read-only unless not ``freeze``
    lines : (int, int) or None
        Line number of data row 0 and the row count, when rows map to lines one to one.

    Raises
    ------
    DataError
        No header, a refused header, no row, a malformed row (its line), a declared row
        count the file cannot hold (refused before anything is allocated) or other than
        the rows found, a file that grew while it was read.
    """
    regular_file(path)
    with open(path, "rb") as fb:
        recorded = None
        lineno = 0
        names: list[str] | None = None
        while raw := fb.readline():
            lineno += 1
            try:
                s = raw.decode("utf-8-sig" if lineno == 1 else "utf-8").strip()
            except UnicodeDecodeError as exc:
                raise DataError(
                    f"not UTF-8 text ({exc.reason})", file=path.name, at=f"line {lineno}"
                ) from None
            if not s:
                continue
            if s.startswith("#"):
                if s.startswith(ROWS_PREFIX):
                    recorded = _rows(path, lineno, s[len(ROWS_PREFIX) :])
                continue
            names = [c.strip() for c in s.split(",")]
            break
        if names is None:
            raise DataError(f"no header line found; expected columns {expected}", file=path.name)
        if len(names) == 1:  # another delimiter: its first row tells the decimal mark
            at = fb.tell()
            _check_delimiter(path, names, lineno, fb.readline().decode("utf-8", "replace"))
            fb.seek(at)
        layout = layout_of(names, lineno)
        first = lineno + 1
        start = fb.tell()
        size = fb.seek(0, io.SEEK_END) - start
        _check_declared_rows(path, recorded, len(names), size)
        fb.seek(start)
        # rows <= lines, and a row holds at least a separator per cell (or its newline)
        capacity = min(_count_lines(fb), size // len(names) + 1)
        fb.seek(start)
        arrays, one_to_one = _parse(path, fb, names, layout, capacity, first, freeze)
    N = next(iter(arrays.values())).shape[0]
    if N == 0:
        raise DataError("no data rows after the header", file=path.name)
    check_row_count(path, recorded, N)
    return arrays, ((first, N) if one_to_one else None)


#: Delimiters of other tools' tables, by the name a message gives them.
_OTHER_DELIMITERS = (("\t", "tab"), (";", "semicolon"), ("|", "vertical bar"))


def _check_delimiter(path: Path, names: list[str], lineno: int, row: str = "") -> None:
    """Refuse a header of one column that holds another delimiter (a tab- or
    semicolon-separated file), naming it, before its column names are judged; the first
    ``row`` holding commas as well: decimal commas, which the hint converts first."""
    if len(names) != 1:
        return
    for sep, what in _OTHER_DELIMITERS:
        if sep in names[0]:
            hint = f"replace each {what} with a comma"
            if sep in row and "," in row:  # 0,05;2,15: commas are the decimal mark
                hint = (
                    f"the numbers have decimal commas: replace each comma with a point, then {hint}"
                )
            raise DataError(
                f"the header holds {what}s and no comma: a {what}-separated file; dynid "
                f"reads comma-separated files; hint: {hint}",
                file=path.name,
                at=f"line {lineno}",
            )


def _count_lines(fb: IO[bytes]) -> int:
    """The lines from the position of ``fb`` to its end (a last line without a newline
    counted), read in blocks."""
    lines, last = 0, b"\n"
    while block := fb.read(_CHUNK_BYTES):
        lines += block.count(b"\n")
        last = block[-1:]
    return lines + (last != b"\n")


def _check_declared_rows(path: Path, recorded: int | None, width: int, size: int) -> None:
    """Refuse a ``# rows:`` count that ``size`` bytes of rows of ``width`` cells cannot
    hold (each row is at least one character and a separator per cell), before the
    arrays for that count are allocated."""
    if recorded is not None and recorded > size // (2 * width):
        raise DataError(
            f"the file records {recorded} rows but its {size} bytes of data hold "
            f"at most {size // (2 * width)}; it is incomplete or was edited; regenerate it, or, "
            "if rows were removed on purpose, correct or delete its '# rows:' line",
            file=path.name,
        )


def _parse(
    path: Path,
    fb: IO[bytes],
    names: list[str],
    layout: dict[str, list[int]],
    capacity: int,
    first: int,
    freeze: bool,
) -> tuple[dict[str, NDArray[np.float64]], bool]:
    """Parse the data rows a chunk of text at a time straight into the per-signal arrays
    (allocated for ``capacity`` rows, returned cut to the rows found; read-only when
    ``freeze``), and say whether rows map to lines one to one (no blank or comment line
    skipped).

    Frozen arrays are filled in buffers that only they hold and then seen through read-only
    views of those buffers (:func:`dynid._checks.frozen` keeps them as they are): never
    copied, so that a long log is held once.

    Each chunk is read by numpy's C number reader, only the columns ``layout`` takes; a
    chunk that is not a clean table of numbers there (an empty cell, a comment line, a
    short row, a word) is read line by line, to NaN for an empty cell, or to an error
    naming the line. Memory: the arrays and one chunk, whatever the file.
    """
    width = len(names)
    used = sorted({c for cols in layout.values() for c in cols})
    at = {c: i for i, c in enumerate(used)}
    take = {k: [at[c] for c in cols] for k, cols in layout.items()}
    buffers = {k: bytearray(8 * capacity * len(c)) for k, c in layout.items()} if freeze else {}
    out = {
        k: np.frombuffer(buffers[k], np.float64).reshape(capacity, len(c))
        if freeze
        else np.empty((capacity, len(c)))
        for k, c in layout.items()
    }
    row, line = 0, first
    tail = b""
    one_to_one = True
    while True:
        chunk = fb.read(_CHUNK_BYTES)
        last = not chunk
        buf = tail + chunk
        if last:
            buf, tail = buf.rstrip() + b"\n", b""
            if buf == b"\n":
                break
        else:
            cut = buf.rfind(b"\n") + 1
            buf, tail = buf[:cut], buf[cut:]
            if not buf:
                continue
        lines = buf.count(b"\n")
        fast = _fast_table(buf, width, used)
        if fast is None:
            table, skipped = _slow_table(path, buf, line, names, used)
        else:
            table, skipped = fast
        one_to_one = one_to_one and not skipped
        del buf
        line += lines
        rows = table.shape[0]
        if row + rows > capacity:
            raise DataError("the file grew while it was read; read it again", file=path.name)
        for k, cols in take.items():
            out[k][row : row + rows] = table[:, cols]
        row += rows
        report(f"reading {path.name}: {row:,} of {capacity:,} rows")
        if last:
            break
    if not freeze:
        return {k: a[:row] for k, a in out.items()}, one_to_one
    out.clear()  # the writable views gone: the buffers are reached read-only only
    return {
        k: np.frombuffer(memoryview(buffers[k]).toreadonly(), np.float64).reshape(capacity, len(c))[
            :row
        ]
        for k, c in layout.items()
    }, one_to_one


def _fast_table(buf: bytes, width: int, used: list[int]) -> tuple[NDArray[np.float64], bool] | None:
    """The columns ``used`` of the rows of ``buf`` (whole lines) as a table (rows,
    len(used)) by numpy's C reader, and whether blank lines were skipped; None unless
    every row has ``width`` cells, numbers in the columns used."""
    skipped = False
    if b"\r" in buf:
        buf = buf.replace(b"\r\n", b"\n")
    if buf.startswith(b"\n") or b"\n\n" in buf:  # blank lines: skipped
        skipped = True
        while b"\n\n" in buf:
            buf = buf.replace(b"\n\n", b"\n")
        buf = buf.lstrip(b"\n")
        if not buf:
            return np.empty((0, len(used))), skipped
    rows = buf.count(b"\n")
    if b"#" in buf:
        return None
    if len(used) < width:  # other columns (text, labels): not parsed
        if buf.count(b",") != rows * (width - 1):
            return None
        try:
            table = np.loadtxt(
                io.BytesIO(buf),
                delimiter=",",
                usecols=used,
                comments=None,
                ndmin=2,
                encoding="latin-1",  # whatever the other columns hold; numbers are ASCII
            )
        except ValueError:
            return None
        return table, skipped
    if b",," in buf:
        return None
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        try:
            flat = np.fromstring(buf.replace(b"\n", b","), dtype=np.float64, sep=",")
        except (ValueError, DeprecationWarning):
            return None
    if flat.size != rows * width:
        return None
    return flat.reshape(rows, width), skipped


def _slow_table(
    path: Path, buf: bytes, first: int, names: list[str], used: list[int]
) -> tuple[NDArray[np.float64], bool]:
    """The columns ``used`` of the rows of ``buf`` read line by line (the first is line
    ``first``): blank and comment lines skipped (said by the flag), an empty cell NaN,
    anything else a number or an error naming the line."""
    width = len(names)
    try:
        text = buf.decode("utf-8")
    except UnicodeDecodeError as exc:
        line = first + buf[: exc.start].count(b"\n")
        raise DataError(
            f"not UTF-8 text ({exc.reason})", file=path.name, at=f"line {line}"
        ) from None
    lines = text.split("\n")[:-1]
    del text
    table = np.full((len(lines), len(used)), np.nan)  # 8 bytes a cell, not a Python float
    rows = 0
    skipped = False
    for i, raw in enumerate(lines, start=first):
        s = raw.strip()
        if not s or s.startswith("#"):
            skipped = True
            continue
        cells = s.split(",")
        if len(cells) != width:
            raise DataError(
                f"expected {width} fields like the header; got {len(cells)}",
                file=path.name,
                at=f"line {i}",
            )
        for m, k in enumerate(used):
            c = cells[k].strip()
            if c:
                try:
                    table[rows, m] = _checks.decimal(c)
                except ValueError:
                    raise DataError(
                        f"not a number: {c[:40]!r}",
                        file=path.name,
                        at=f"line {i}, column {names[k]!r}",
                    ) from None
        rows += 1
    return table[:rows], skipped


def _rows(path: Path, lineno: int, text: str) -> int:
    try:
        return _checks.integer(text)
    except ValueError:
        raise DataError(
            "'# rows:' must give an integer", file=path.name, at=f"line {lineno}"
        ) from None
