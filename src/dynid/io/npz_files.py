"""Size checks of an NPZ archive before any array is read (zip bombs, absurd headers).

An NPZ file is a zip of ``.npy`` members. numpy allocates each member's array from the
shape its header declares and inflates compressed members without a bound, so a 5.8 MB
file can demand 6 GB, and a header declaring 1e12 rows is allocated before the read
fails. :func:`check_npz` reads only the zip directory and the members' ``.npy`` headers
and refuses, with a :class:`~dynid.exceptions.DataError` naming the file, the member and
the limit:

* a total uncompressed size above :data:`MAX_NPZ_BYTES` (4 GiB; the environment
  variable ``DYNID_MAX_NPZ_BYTES`` raises it, in bytes);
* a member larger than 1 MiB compressed more than :data:`MAX_COMPRESSION_RATIO` (100)
  times: numbers measured by a sensor compress a few times at most, a bomb a thousand;
* a header whose shape needs more bytes than the member holds (a file cut short or
  edited), or an object dtype (pickles, refused anyway).

A file that is not a zip is left to the reader (``np.load`` reads a single ``.npy``).
"""

from __future__ import annotations

import os
import zipfile
from pathlib import Path

import numpy as np

from .. import _checks
from ..exceptions import DataError
from .input_files import regular_file

__all__ = ["MAX_COMPRESSION_RATIO", "MAX_NPZ_BYTES", "check_npz"]

#: Largest total uncompressed size of an NPZ archive read [bytes] (4 GiB), unless the
#: environment variable ``DYNID_MAX_NPZ_BYTES`` gives another.
MAX_NPZ_BYTES = 4 << 30
#: Largest compression ratio of a member above :data:`_RATIO_FLOOR` bytes.
MAX_COMPRESSION_RATIO = 100.0
_RATIO_FLOOR = 1 << 20
_ENV = "DYNID_MAX_NPZ_BYTES"


def _limit() -> int:
    text = os.environ.get(_ENV)
    if text is None:
        return MAX_NPZ_BYTES
    try:
        value = int(text)
    except ValueError:
        raise DataError(f"{_ENV} must be a number of bytes; got {text[:40]!r}") from None
    return value


def check_npz(path: str | Path) -> None:
    """Refuse an NPZ archive whose arrays would take absurd memory (module docstring).

    Raises
    ------
    DataError
        The archive's uncompressed size exceeds the limit, a member's compression ratio
        exceeds :data:`MAX_COMPRESSION_RATIO`, a member's header declares more data than
        the member holds, a member holds Python objects, or two members share a name.
    """
    path = Path(path)
    regular_file(path)  # not a device that never ends
    if not zipfile.is_zipfile(path):
        return
    try:
        with zipfile.ZipFile(path) as zf:
            infos = zf.infolist()
            names = [i.filename for i in infos]
            dup = sorted({n for n in names if names.count(n) > 1})
            if dup:  # numpy reads the last one of a name silently
                raise DataError(
                    f"duplicated array(s) {_checks.names(dup)}; an array may appear once",
                    file=path.name,
                )
            total = sum(i.file_size for i in infos)
            limit = _limit()
            if total > limit:
                raise DataError(
                    f"its arrays would take {total / 2**30:.3g} GiB uncompressed, "
                    f"above the limit of {limit / 2**30:.3g} GiB; hint: set the environment "
                    f"variable {_ENV} (bytes) to read it",
                    file=path.name,
                )
            for info in infos:
                _check_member(path, zf, info)
    except (zipfile.BadZipFile, OSError, EOFError) as exc:
        raise DataError(f"not a readable NPZ file ({exc})", file=path.name) from None


def _check_member(path: Path, zf: zipfile.ZipFile, info: zipfile.ZipInfo) -> None:
    name = info.filename
    ratio = info.file_size / max(info.compress_size, 1)
    if info.file_size > _RATIO_FLOOR and ratio > MAX_COMPRESSION_RATIO:
        raise DataError(
            f"member {name!r} inflates {ratio:.0f} times ({info.file_size} bytes "
            f"from {info.compress_size}), above {MAX_COMPRESSION_RATIO:g}: not measured data "
            "(a zip bomb?)",
            file=path.name,
        )
    if not name.endswith(".npy"):
        return
    with zf.open(info) as fh:
        try:
            version = np.lib.format.read_magic(fh)
            if version == (1, 0):
                shape, _, dtype = np.lib.format.read_array_header_1_0(fh)
            else:
                shape, _, dtype = np.lib.format.read_array_header_2_0(fh)
        except (ValueError, EOFError, SyntaxError) as exc:
            raise DataError(
                f"member {name!r} is not a .npy array ({exc})", file=path.name
            ) from None
        header = fh.tell()
    if dtype.hasobject:
        raise DataError(
            f"array {name[:-4]!r} holds Python objects (pickles refused)", file=path.name
        )
    need = int(np.prod(shape, dtype=object)) * dtype.itemsize
    if need > info.file_size - header:
        raise DataError(
            f"array {name[:-4]!r} declares shape {shape} ({need} bytes) but holds "
            f"{info.file_size - header} bytes; the file is incomplete or was edited",
            file=path.name,
        )
