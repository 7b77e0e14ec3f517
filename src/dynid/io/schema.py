"""File formats from their schemas: one strict check of a parsed document, one wording.

A :class:`Format` names a JSON file's ``schema`` tag and its :class:`Record`: each key a
:class:`Field` declaring its kind, the sizes of a list of numbers (a name such as ``"n"``
is bound by its first use, so that every per-joint list must have the same length), its
unit and its limits. :func:`load_document` and :func:`save_document` are the reader and writer of
such a file; :func:`check` checks any parsed mapping (a TOML table included) against a
record. Every fault is a :class:`~dynid.exceptions.DataError` in one wording, naming the
file (or source) and the key path::

    thresholds.json: key 'rule.margin': expected a number >= 1; got -2.0
    thresholds.json: key 'observer.gane': unknown key; allowed: discretisation, gain, rule
    friction.json: key 'joints': missing; expected a non-empty list of objects

The check refuses only what the declaration says; relations between keys (a link name the
robot has, a singular transmission) stay with the reader that builds the object.
"""

from __future__ import annotations

import math
from collections.abc import Mapping
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any, Literal

from .. import _checks
from ..exceptions import DataError, NonFiniteError
from .json_files import jsonable, load_json, save_json

__all__ = [
    "Field",
    "Format",
    "Record",
    "check",
    "describe",
    "fault",
    "load_document",
    "save_document",
]

Kind = Literal[
    "number",
    "integer",
    "bool",
    "string",
    "strings",
    "bools",
    "numbers",
    "object",
    "objects",
    "named",
    "any",
]


@dataclass(frozen=True)
class Field:
    """One key of a file.

    Attributes
    ----------
    kind : str
        ``number`` (finite, never a boolean or a string), ``integer``, ``bool``, ``string``,
        ``strings`` and ``bools`` (lists of them, of ``shape[0]`` entries when given),
        ``numbers`` (nested lists of numbers of ``shape``),
        ``object`` (the keys of ``record``), ``objects`` (a list of such objects, of
        ``shape[0]`` entries when given), ``named`` (an object of names, each value an
        object of ``record``) or ``any`` (not checked: metadata).
    required : bool
        A missing key is refused.
    nullable : bool
        ``null`` is accepted (no value, on purpose).
    shape : tuple of int, str or None
        ``numbers``: the size of each nesting level; a name is one size for the whole file,
        bound by its first use (or given to :func:`check`); None any size.
    low, high : float, optional
        Inclusive limits of a number (every entry of ``numbers``).
    choices : tuple
        The accepted values (strings or numbers).
    record : Record, optional
        The keys inside an ``object``, ``objects`` or ``named`` value.
    null_items : bool
        ``numbers``: an entry may be ``null`` (no limit).
    non_empty : bool
        ``objects``, ``strings``, ``numbers``: an empty list is refused; ``string``: an
        empty string.
    unit : str
        The SI unit, for messages and the format's documentation.
    infinite : bool
        ``number``: ``inf`` and ``-inf`` are accepted (no limit: a TOML file's ``inf``);
        NaN never is.
    """

    kind: Kind
    required: bool = False
    nullable: bool = False
    shape: tuple[int | str | None, ...] = ()
    low: float | None = None
    high: float | None = None
    choices: tuple[Any, ...] = ()
    record: Record | None = None
    null_items: bool = False
    non_empty: bool = False
    unit: str = ""
    infinite: bool = False


@dataclass(frozen=True)
class Record:
    """The keys of one object. ``open``: keys not declared are kept unchecked (metadata)."""

    fields: Mapping[str, Field]
    open: bool = False


@dataclass(frozen=True)
class Format:
    """A JSON file: its ``schema`` tag (``older``: tags still read), its record, and what it
    is ("thresholds file (dynid observe --calibrate)") for messages."""

    tag: str
    record: Record
    what: str
    older: tuple[str, ...] = ()
    top: Record = field(init=False, repr=False, compare=False)

    def __post_init__(self) -> None:
        fields = {"schema": Field("string", required=True), **self.record.fields}
        object.__setattr__(self, "top", Record(fields, self.record.open))


def fault(source: str, at: str, text: str) -> DataError:
    """The one wording: ``"<source>: key '<at>': <text>"`` (the error's ``file``: ``source``)."""
    return DataError(f"key {at!r}: {text}", file=source)


def _limits(f: Field) -> str:
    if f.low is not None and f.high is not None:
        return f" in [{f.low:g}, {f.high:g}]"
    if f.low is not None:
        return f" >= {f.low:g}"
    if f.high is not None:
        return f" <= {f.high:g}"
    return ""


def _size(s: int | str | None, sizes: Mapping[str, int]) -> str:
    if isinstance(s, str):
        return str(sizes.get(s, s))
    return "" if s is None else str(s)


def describe(f: Field, sizes: Mapping[str, int] | None = None) -> str:
    """What ``f`` accepts, as the messages say it ("a list of 7 numbers >= 0 [rad/s]")."""
    sizes = sizes or {}
    unit = f" [{f.unit}]" if f.unit else ""
    if f.choices:
        text = "one of " + ", ".join(map(repr, f.choices))
    elif f.kind == "number":
        text = f"a {'number or inf' if f.infinite else 'number'}{_limits(f)}{unit}"
    elif f.kind == "integer":
        text = f"an integer{_limits(f)}"
    elif f.kind == "bool":
        text = "true or false"
    elif f.kind == "string":
        text = "a non-empty string" if f.non_empty else "a string"
    elif f.kind in ("strings", "bools"):
        count = _size(f.shape[0], sizes) if f.shape else ""
        item = "strings" if f.kind == "strings" else "true or false values"
        text = (
            f"a {'non-empty ' if f.non_empty else ''}list of {count + ' ' if count else ''}{item}"
        )
    elif f.kind == "numbers":
        dims = [_size(s, sizes) for s in f.shape] or [""]
        if len(dims) == 1:
            count = f"{dims[0]} " if dims[0] else ""
            text = f"a list of {count}numbers{_limits(f)}{unit}"
        else:
            text = f"a {' x '.join(d or 'any' for d in dims)} nested list of numbers{unit}"
        if f.null_items:
            text += " or nulls"
    elif f.kind == "object":
        text = "an object"
    elif f.kind == "objects":
        count = _size(f.shape[0], sizes) if f.shape else ""
        text = (
            f"a {'non-empty ' if f.non_empty else ''}list of {count + ' ' if count else ''}objects"
        )
    elif f.kind == "named":
        text = "an object of named objects"
    else:
        text = "any value"
    return text + (" or null" if f.nullable else "")


def _got(v: Any) -> str:
    if isinstance(v, list):
        return f"a list of {len(v)} entries" if len(v) > 8 else _checks.short(v)
    return "null" if v is None else _checks.short(v)


def check(
    doc: Any,
    record: Record,
    source: str,
    *,
    at: str = "",
    sizes: dict[str, int] | None = None,
) -> dict[str, int]:
    """Check a parsed mapping against ``record``; returns the sizes bound (``{"n": 7}``).

    Parameters
    ----------
    doc : Any
        The parsed document (a JSON object, a TOML table).
    record : Record
    source : str
        The file (or table) named in messages.
    at : str
        The key path of ``doc`` inside its file ("" at the top).
    sizes : dict, optional
        Sizes known beforehand (``{"n": robot.n}``); updated with those bound here.

    Raises
    ------
    DataError
        An unknown key, a missing required key, a wrong type, size or choice, a number
        out of its limits: ``"<source>: key '<path>': ..."`` (:func:`fault`).
    """
    sizes = {} if sizes is None else sizes
    if not isinstance(doc, Mapping):
        raise fault(source, at or "(top level)", f"expected an object; got {_got(doc)}")
    if not record.open:
        for key in doc:
            if key not in record.fields:
                allowed = ", ".join(sorted(record.fields))
                raise fault(source, _join(at, str(key)), f"unknown key; allowed: {allowed}")
    for key, f in record.fields.items():
        where = _join(at, key)
        if key not in doc:
            if f.required:
                raise fault(source, where, f"missing; expected {describe(f, sizes)}")
            continue
        _value(doc[key], f, source, where, sizes)
    return sizes


def _join(at: str, key: str) -> str:
    return f"{at}.{key}" if at else key


def _value(v: Any, f: Field, source: str, at: str, sizes: dict[str, int]) -> None:
    if v is None:
        if not f.nullable and f.kind != "any":
            raise fault(source, at, f"expected {describe(f, sizes)}; got null")
        return
    if f.kind == "any":
        return
    ok = True
    if f.kind == "number":
        _number(v, f, source, at)
    elif f.kind == "integer":
        ok = isinstance(v, int) and not isinstance(v, bool) and _within(v, f)
    elif f.kind == "bool":
        ok = isinstance(v, bool)
    elif f.kind == "string":
        ok = isinstance(v, str) and bool(v or not f.non_empty)
    elif f.kind in ("strings", "bools"):
        item = str if f.kind == "strings" else bool
        ok = isinstance(v, list) and all(isinstance(x, item) for x in v)
        ok = ok and _count(v, f, sizes)
    elif f.kind == "numbers":
        _numbers(v, f, 0, source, at, sizes)
    elif f.kind == "object":
        check(v, f.record or Record({}, open=True), source, at=at, sizes=sizes)
    elif f.kind in ("objects", "named"):
        _objects(v, f, source, at, sizes)
    if not ok:
        raise fault(source, at, f"expected {describe(f, sizes)}; got {_got(v)}")
    if f.choices and v not in f.choices:
        raise fault(source, at, f"expected {describe(f, sizes)}; got {_got(v)}")


def _count(v: list[Any], f: Field, sizes: dict[str, int]) -> bool:
    """Whether the list ``v`` has the length ``f.shape[0]`` says (a name bound here)."""
    if f.non_empty and not v:
        return False
    s = f.shape[0] if f.shape else None
    if isinstance(s, str):
        s = sizes.setdefault(s, len(v))
    return s is None or len(v) == s


def _within(x: float, f: Field) -> bool:
    return (f.low is None or x >= f.low) and (f.high is None or x <= f.high)


def _number(v: Any, f: Field, source: str, at: str) -> None:
    unit = f" [{f.unit}]" if f.unit else ""
    want = f"a {'number or inf' if f.infinite else 'number'}{_limits(f)}{unit}"
    if isinstance(v, bool) or not isinstance(v, int | float):
        raise fault(source, at, f"expected {want}; got {_got(v)}")
    try:
        x = float(v)
    except OverflowError:
        raise fault(source, at, f"expected a finite number; got {_got(v)}") from None
    if math.isnan(x) or (math.isinf(x) and not f.infinite):
        raise fault(source, at, f"expected a finite number; got {_got(v)}")
    if not _within(x, f):
        raise fault(source, at, f"expected {want}; got {_got(v)}")


def _numbers(v: Any, f: Field, depth: int, source: str, at: str, sizes: dict[str, int]) -> None:
    if depth == (len(f.shape) if f.shape else 1):
        if v is None and f.null_items:
            return
        _number(v, f, source, at)
        return
    if not isinstance(v, list):
        raise fault(source, at, f"expected {_level(f, depth, sizes)}; got {_got(v)}")
    s = f.shape[depth] if f.shape else None
    if isinstance(s, str) and s not in sizes:
        sizes[s] = len(v)
    want = sizes[s] if isinstance(s, str) else s
    if (want is not None and len(v) != want) or (f.non_empty and not v):
        raise fault(source, at, f"expected {_level(f, depth, sizes)}; got {_got(v)}")
    for i, x in enumerate(v):
        _numbers(x, f, depth + 1, source, f"{at}[{i}]", sizes)


def _level(f: Field, depth: int, sizes: Mapping[str, int]) -> str:
    """The description of ``f`` from nesting level ``depth`` down."""
    rest = f.shape[depth:] if f.shape else ()
    sub = Field("numbers", shape=rest, low=f.low, high=f.high, unit=f.unit, null_items=f.null_items)
    return describe(sub, sizes)


def _objects(v: Any, f: Field, source: str, at: str, sizes: dict[str, int]) -> None:
    record = f.record or Record({}, open=True)
    if f.kind == "named":
        if not isinstance(v, Mapping):
            raise fault(source, at, f"expected {describe(f, sizes)}; got {_got(v)}")
        for name, item in v.items():
            check(item, record, source, at=f"{at}.{name}", sizes=sizes)
        return
    if not isinstance(v, list) or not _count(v, f, sizes):
        raise fault(source, at, f"expected {describe(f, sizes)}; got {_got(v)}")
    for i, item in enumerate(v):
        check(item, record, source, at=f"{at}[{i}]", sizes=sizes)


def load_document(
    path: str | Path, fmt: Format, *, sizes: dict[str, int] | None = None
) -> dict[str, Any]:
    """Read a strict JSON file of format ``fmt`` and check it (:func:`check`).

    Raises
    ------
    DataError
        Not strict JSON, another ``schema`` (:func:`~dynid.io.json_files.load_json`), or
        content that ``fmt`` refuses (the file and the key path named).
    OSError
        The file cannot be read.
    """
    path = Path(path)
    d = load_json(path, schema=(fmt.tag, *fmt.older), what=fmt.what)
    check(d, fmt.top, path.name, sizes=sizes)
    return d


def save_document(path: str | Path, fmt: Format, doc: Mapping[str, Any]) -> Path:
    """Write ``doc`` as a file of format ``fmt`` (``schema`` first), atomically, after
    checking it as :func:`load_document` will: a writer never writes what its reader refuses.

    Raises
    ------
    NonFiniteError
        A NaN or infinite number where the format has no ``null`` (the key path named).
    DataError
        ``doc`` does not follow ``fmt`` (a fault of the writer; nothing is written).
    """
    path = Path(path)
    try:
        plain = jsonable({"schema": fmt.tag, **{k: v for k, v in doc.items() if k != "schema"}})
    except (DataError, NonFiniteError) as exc:
        raise type(exc)(str(exc), file=path.name) from None
    check(plain, fmt.top, path.name)
    return save_json(path, plain)
