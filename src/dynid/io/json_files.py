"""Strict JSON: the one reader and writer of dynid's JSON files, and their one number policy.

The policy, the same for every file: a JSON number is finite. A field that may have no
value (no limit, no obstacle, a percentage of zero) is written ``null``, on purpose, through
:func:`finite_or_none`, and file-formats.md says so for that field; any other NaN or infinite
number is a fault, and writing it raises :class:`~dynid.exceptions.NonFiniteError` naming
its key path (``rms[3]``) and writes nothing. ``NaN``/``Infinity`` are never written
(strict parsers reject them) and never read.

Writing (:func:`dumps`, :func:`save_json`): numpy arrays and scalars become lists and
numbers. Files are written atomically (:mod:`dynid.io.atomic`), indented, UTF-8, with a
``schema`` key first.

Reading (:func:`load_json`): UTF-8 with or without a byte-order mark; ``NaN``,
``Infinity``, numbers that overflow a float (integers of more than 308 digits included),
duplicated keys, nesting too deep for the parser and a top level other than an object
are rejected with a :class:`~dynid.exceptions.DataError` naming the file; the
``schema`` key must be one of the accepted ones.
"""

from __future__ import annotations

import json
import math
from collections.abc import Iterable, Mapping
from pathlib import Path
from typing import Any

import numpy as np

from .. import _checks
from .._checks import text
from ..exceptions import DataError, NonFiniteError
from .atomic import write_text
from .input_files import file_bytes

__all__ = ["dumps", "finite_or_none", "jsonable", "load_json", "loads", "save_json"]


def jsonable(x: Any, where: str = "") -> Any:
    """``x`` with numpy types converted; raises :class:`NonFiniteError` on NaN/inf."""
    if isinstance(x, Mapping):
        return {
            text(str(k)): jsonable(v, f"{where}.{k}" if where else str(k)) for k, v in x.items()
        }
    if isinstance(x, np.ndarray):
        if x.dtype.kind in "biu" or (x.dtype.kind == "f" and np.isfinite(x).all()):
            return x.tolist()  # Python numbers already (a NaN is named element by element)
        return jsonable(x.tolist(), where)
    if isinstance(x, (list, tuple)):
        if all(type(v) is int or (type(v) is float and math.isfinite(v)) for v in x):
            return list(x)  # plain numbers: as they are (one check, no call per number)
        return [jsonable(v, f"{where}[{i}]") for i, v in enumerate(x)]
    if isinstance(x, (bool, np.bool_)):
        return bool(x)
    if isinstance(x, (int, np.integer)):
        return int(x)
    if isinstance(x, (float, np.floating)):
        v = float(x)
        if not math.isfinite(v):
            raise NonFiniteError(f"{where or 'value'} is {v}; JSON has no NaN or infinity")
        return v
    if x is None:
        return x
    if isinstance(x, str | Path):  # a file name of an ASCII locale: its characters
        return text(str(x))
    raise DataError(f"{where or 'value'}: cannot write a {type(x).__name__} as JSON")


def finite_or_none(x: Any) -> Any:
    """``x`` with every number that is not finite replaced by None (JSON ``null``).

    The one way a writer states "no value" for a field that may have none (module
    docstring): recursively through mappings, lists, tuples and arrays; other values are
    returned as they are (numpy integers and booleans are converted by :func:`jsonable`).
    """
    if isinstance(x, Mapping):
        return {str(k): finite_or_none(v) for k, v in x.items()}
    if isinstance(x, np.ndarray):
        return finite_or_none(x.tolist())
    if isinstance(x, (list, tuple)):
        return [finite_or_none(v) for v in x]
    if isinstance(x, (float, np.floating)):
        v = float(x)
        return v if math.isfinite(v) else None
    return x


def dumps(obj: Any, *, indent: int | None = 1) -> str:
    """Strict JSON text of ``obj`` (see the module docstring)."""
    return json.dumps(jsonable(obj), indent=indent, allow_nan=False)


def save_json(path: str | Path, obj: Mapping[str, Any], *, schema: str | None = None) -> Path:
    """Write ``obj`` as strict JSON, atomically; ``schema`` is put first when given.

    Raises
    ------
    NonFiniteError
        A NaN or infinite number (the message names the file and the key path).
    """
    path = Path(path)
    doc = (
        dict(obj)
        if schema is None
        else {"schema": schema, **{k: v for k, v in obj.items() if k != "schema"}}
    )
    try:
        text = dumps(doc)
    except (DataError, NonFiniteError) as exc:
        raise type(exc)(str(exc), file=path.name) from None
    return write_text(path, text + "\n")


def _no_constant(name: str) -> Any:
    raise ValueError(f"{name} is not a JSON number")


def _finite_float(text: str) -> float:
    v = float(text)
    if not math.isfinite(v):
        raise ValueError(f"number {text} overflows a float")
    return v


def _float_range_int(text: str) -> int:
    if len(text.lstrip("-")) > 308:  # beyond 1.8e308 no number of dynid's means anything
        raise ValueError(f"an integer of {len(text.lstrip('-'))} digits overflows a float")
    return int(text)


def _unique_keys(pairs: list[tuple[str, Any]]) -> dict[str, Any]:
    d: dict[str, Any] = {}
    for k, v in pairs:
        if k in d:
            raise ValueError(f"duplicated key {_checks.short(k)}")
        d[k] = v
    return d


def loads(text: str) -> Any:
    """Parse strict JSON text (no NaN/Infinity, no overflow, no duplicated key).

    Raises
    ------
    ValueError
        Not strict JSON (:class:`json.JSONDecodeError` for the syntax), including
        integers beyond the float range and nesting too deep for the parser.
    """
    try:
        return json.loads(
            text,
            parse_constant=_no_constant,
            parse_float=_finite_float,
            parse_int=_float_range_int,
            object_pairs_hook=_unique_keys,
        )
    except RecursionError:
        raise ValueError("arrays or objects nested too deeply") from None


def load_json(
    path: str | Path, *, schema: str | Iterable[str] | None = None, what: str = "JSON file"
) -> dict[str, Any]:
    """Read a strict JSON object from ``path`` and check its ``schema`` key.

    Parameters
    ----------
    path : str or Path
    schema : str or iterable of str, optional
        Accepted values of the top-level ``schema`` key; None accepts any (or none).
    what : str
        What the file should be, for messages ("identified model").

    Raises
    ------
    DataError
        Not UTF-8, not strict JSON (the line and column), not an object, wrong schema;
        not a regular file or too large (:mod:`dynid.io.input_files`).
    OSError
        The file cannot be read.
    """
    path = Path(path)
    raw = file_bytes(path)
    try:
        text = raw.decode("utf-8-sig")
    except UnicodeDecodeError as exc:
        raise DataError(f"not a UTF-8 text file ({exc.reason})", file=path.name) from None
    try:
        d = loads(text)
    except json.JSONDecodeError as exc:
        raise DataError(
            f"not a JSON file ({exc.msg} at line {exc.lineno}, column {exc.colno})", file=path.name
        ) from None
    except ValueError as exc:
        raise DataError(f"not strict JSON ({_checks.one_line(str(exc))})", file=path.name) from None
    if not isinstance(d, dict):
        raise DataError(f"expected a JSON object ({what}); got {type(d).__name__}", file=path.name)
    if schema is not None:
        ok = (schema,) if isinstance(schema, str) else tuple(schema)
        got = d.get("schema")
        if got not in ok:
            raise DataError(  # the wording of dynid.io.schema
                f"key 'schema': expected {' or '.join(map(repr, ok))} "
                f"({'an' if what[:1] in 'aeiou' else 'a'} {what}); got {_checks.short(got)}",
                file=path.name,
            )
    return d
