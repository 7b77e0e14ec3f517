"""Validation of user input at the public boundary.

Public functions convert array_like input once, here, to float64 and check shape and
finiteness; internal functions trust validated arrays.
"""

from __future__ import annotations

import json
import math
import re
import unicodedata
from collections.abc import Iterable, Iterator, Mapping
from typing import Any, Generic, TypeVar

import numpy as np
from numpy.typing import ArrayLike, NDArray

from .exceptions import DynidError, NonFiniteError, ShapeError, WrongTypeError

#: arrays up to this size are checked element by element in Python (a numpy reduction
#: costs about 2 us whatever the size, the Python loop 40 ns an element)
_SMALL = 32


def finite(name: str, x: NDArray[np.float64]) -> None:
    """Raise :class:`NonFiniteError` naming ``name`` and the first bad index."""
    if x.size <= _SMALL and all(map(math.isfinite, x.ravel().tolist())):
        return
    if not np.isfinite(x).all():
        if x.ndim == 0:
            raise NonFiniteError(f"{name} must be finite; got {x.item()}")
        idx = tuple(int(i) for i in np.argwhere(~np.isfinite(x))[0])
        raise NonFiniteError(
            f"{name} must be finite; got {x[idx]} at index {idx if len(idx) > 1 else idx[0]}"
        )


def type_name(value: Any) -> str:
    """The type of ``value`` as a message names it (``dict``, ``ndarray of complex128``,
    ``None``)."""
    if isinstance(value, np.ndarray):
        return f"ndarray of {value.dtype}"
    return "None" if value is None else type(value).__name__


def wrong_type(name: str, value: Any, expected: str) -> WrongTypeError:
    """The one-line :class:`WrongTypeError` of an argument: ``"{name}: expected
    {expected}, got {type}"``."""
    return WrongTypeError(f"{name}: expected {expected}, got {type_name(value)}")


def of_type(name: str, value: Any, kind: type | tuple[type, ...], expected: str) -> Any:
    """``value`` when it is an instance of ``kind``.

    Raises
    ------
    WrongTypeError
        It is not (:func:`wrong_type`).
    """
    if not isinstance(value, kind):
        raise wrong_type(name, value, expected)
    return value


def one_or_many(name: str, value: Any, kind: type | tuple[type, ...], expected: str) -> list[Any]:
    """``value`` as a list of ``kind``: one instance, or a list or tuple of them.

    Raises
    ------
    WrongTypeError
        ``value`` is neither, or an item is not an instance (named by its index).
    """
    if isinstance(value, kind):
        return [value]
    if not isinstance(value, list | tuple):
        raise wrong_type(name, value, expected)
    for i, item in enumerate(value):
        if not isinstance(item, kind):
            raise WrongTypeError(
                f"{name}: expected {expected}, got a {type(value).__name__} holding "
                f"{type_name(item)} at index {i}"
            )
    return list(value)


def checked_rng(rng: Any, name: str = "rng") -> np.random.Generator:
    """``rng`` when it is a :class:`numpy.random.Generator` (the one source of randomness).

    Raises
    ------
    WrongTypeError
        It is not (a seed given as an int: ``np.random.default_rng(seed)`` makes one).
    """
    out: np.random.Generator = of_type(
        name, rng, np.random.Generator, "a numpy.random.Generator (np.random.default_rng(seed))"
    )
    return out


#: what an array argument must be
_REAL = "a real numeric array_like"


def as_array(name: str, x: ArrayLike, *, allow_nonfinite: bool = False) -> NDArray[np.float64]:
    """Convert to a float64 array (a copy when needed) and check finiteness.

    Raises
    ------
    WrongTypeError
        ``x`` is None, text, complex or of no numeric type.
    ShapeError
        ``x`` does not form an array (ragged nested sequences).
    NonFiniteError
        ``x`` holds NaN or infinity (unless ``allow_nonfinite``).
    """
    if x is None or isinstance(x, str | bytes | complex):  # numpy reads None as NaN
        raise wrong_type(name, x, _REAL)
    if isinstance(x, np.ndarray | np.generic) and x.dtype.kind not in "biuf":
        if x.dtype.kind == "c" or x.dtype.kind in "USV":  # cast silently / not numbers
            raise wrong_type(name, x, _REAL)
    try:
        a = np.asarray(x, dtype=np.float64)
    except TypeError as exc:
        raise wrong_type(name, x, _REAL) from exc
    except ValueError as exc:
        raise ShapeError(f"{name} must be numeric array_like; got {type(x).__name__}") from exc
    if not allow_nonfinite:
        finite(name, a)
    return a


def as_batch(name: str, x: ArrayLike, tail: tuple[int, ...], **kw: Any) -> NDArray[np.float64]:
    """Convert ``x`` and check that its trailing axes equal ``tail`` (leading axes are batch)."""
    a = as_array(name, x, **kw)
    k = len(tail)
    if a.ndim < k or a.shape[a.ndim - k :] != tail:
        want = ", ".join(["..."] + [str(t) for t in tail])
        raise ShapeError(f"{name} must have shape ({want}); got {a.shape}")
    return a


def as_exact(name: str, x: ArrayLike, shape: tuple[int, ...], **kw: Any) -> NDArray[np.float64]:
    """Convert ``x`` and check that its shape equals ``shape`` exactly."""
    a = as_array(name, x, **kw)
    if a.shape != shape:
        raise ShapeError(f"{name} must have shape {shape}; got {a.shape}")
    return a


def _read_only_throughout(a: Any) -> bool:
    """True for a read-only array whose memory nobody can write to: its chain of bases ends
    in a read-only buffer (the bytes of :func:`frozen`, a memory map opened read-only), not
    in an array that owns its data (whoever holds that one may make it writable again)."""
    while isinstance(a, np.ndarray):
        if a.flags.writeable or a.base is None:
            return False
        a = a.base
    try:
        return memoryview(a).readonly
    except TypeError:
        return False


def frozen(a: NDArray[Any]) -> NDArray[Any]:
    """``a`` as an array nobody can write to: ``a`` itself when it already is one (a large
    log is not copied again), else a copy kept in an immutable ``bytes`` buffer.

    A read-only copy that owned its data could be made writable again by anyone holding
    it (``setflags(write=True)``); over ``bytes`` numpy refuses. So a model built from the
    caller's arrays cannot change behind its back, and what is derived from it once (the
    compiled kernels' packed constants) stays valid.
    """
    if _read_only_throughout(a):
        return a
    if a.dtype.hasobject:  # no bytes for Python objects: a read-only copy
        b = np.array(a, copy=True)
        b.setflags(write=False)
        return b
    return np.frombuffer(a.tobytes(), dtype=a.dtype).reshape(a.shape)


_K = TypeVar("_K")
_V = TypeVar("_V")


class FrozenMapping(Mapping[_K, _V], Generic[_K, _V]):
    """A read-only mapping (a copy of the one given) that pickles and copies.

    It stands where a frozen result holds a mapping (an identified model's terms, a
    robot's frames, a data set's metadata): :class:`types.MappingProxyType` is read-only
    too but cannot be pickled or deep-copied, so neither could the results holding one
    (no ``multiprocessing``, no ``copy.deepcopy``).
    """

    __slots__ = ("_items",)
    _items: dict[_K, _V]

    def __init__(self, items: Mapping[_K, _V] | Iterable[tuple[_K, _V]] = ()) -> None:
        object.__setattr__(self, "_items", dict(items))

    def __getitem__(self, key: _K) -> _V:
        return self._items[key]

    def __iter__(self) -> Iterator[_K]:
        return iter(self._items)

    def __len__(self) -> int:
        return len(self._items)

    def __setattr__(self, name: str, value: Any) -> None:
        raise AttributeError(f"{type(self).__name__} is read-only")

    def __repr__(self) -> str:
        return f"{type(self).__name__}({self._items!r})"

    def __reduce__(self) -> tuple[Any, tuple[dict[_K, _V]]]:
        return type(self), (dict(self._items),)


def frozen_mapping(items: Mapping[_K, _V]) -> FrozenMapping[_K, _V]:
    """``items`` as a :class:`FrozenMapping`: itself when it is one, else a read-only copy."""
    return items if isinstance(items, FrozenMapping) else FrozenMapping(items)


#: Longest echo of a user's input in an error message [characters]: a value, a key or a
#: header line of megabytes is cut to this, with a note of its length.
ECHO_LIMIT = 200


def plain(value: Any) -> Any:
    """``value`` with numpy's scalars as Python's (in tuples, lists and dicts too) and an
    array as a list: what a message echoes reads ``0.5``, not ``np.float64(0.5)`` (numpy
    2's repr of its scalars)."""
    if isinstance(value, np.generic):
        return value.item()
    if isinstance(value, np.ndarray):
        out: Any = value.tolist()
        return out
    if isinstance(value, tuple | list):
        return type(value)(plain(v) for v in value)
    if isinstance(value, dict):
        return {plain(k): plain(v) for k, v in value.items()}
    return value


def number_text(x: Any) -> str:
    """A number as a message says it: the shortest text that reads back as the same float
    (``0.002``, ``1e-05``), a numpy scalar as a Python one."""
    return repr(float(x))


def short(value: Any, limit: int = ECHO_LIMIT) -> str:
    """``repr(value)`` cut to ``limit`` characters (with the length of what was cut), numpy
    scalars written as Python's (:func:`plain`)."""
    value = plain(value)
    if isinstance(value, int) and not isinstance(value, bool) and value.bit_length() > 600:
        return f"an integer of about {int(value.bit_length() * math.log10(2)) + 1} digits"
    big = isinstance(value, str | bytes) and len(value) > limit
    text = repr(value[:limit] if big else value)
    if len(text) <= limit and not big:
        return text
    unit = "characters" if isinstance(value, str) else "bytes" if big else "items"
    size = f" ({len(value)} {unit})" if hasattr(value, "__len__") else ""
    return text[: limit - 3] + "..." + size


#: How many names :func:`names` lists before ``and k more``.
NAMES_SHOWN = 8
#: Longest name :func:`names` writes as it is [characters].
_NAME_LIMIT = 60


def names(items: Iterable[str], shown: int = NAMES_SHOWN) -> str:
    """Names (columns, arrays) for a message in plain text, as dynid's messages name them:
    ``tau6, tau7``, the first ``shown`` and then ``and k more``. A name plain text would
    garble (empty, holding white space, a comma, a quote or a control character, or longer
    than 60 characters) is quoted and cut as :func:`short` echoes it."""
    listed = [str(s) for s in items]

    def one(s: str) -> str:
        plain = 0 < len(s) <= _NAME_LIMIT and re.search(r"[\s,'\"]", s) is None
        return s if plain and control_character(s) is None else short(s, _NAME_LIMIT)

    text = ", ".join(one(s) for s in listed[:shown])
    return text + (f" and {len(listed) - shown} more" if len(listed) > shown else "")


def one_line(text: str, limit: int = 2 * ECHO_LIMIT + 200) -> str:
    """``text`` on one line (line breaks and runs of spaces joined), at most ``limit``
    characters: a longer text keeps its start and its end (where the hint is)."""
    flat = " ".join(text.split())
    if len(flat) <= limit:
        return flat
    tail = min(200, limit // 3)
    cut = len(flat) - (limit - tail - 40)
    return f"{flat[: limit - tail - 40]} ...({cut - tail} characters cut)... {flat[-tail:]}"


#: a number as files write it: ASCII digits, an optional sign, point and exponent, or a
#: spelling of NaN or infinity (refused later, where finiteness is checked)
_DECIMAL = re.compile(
    r"[+-]?(?:(?:\d+\.?\d*|\.\d+)(?:[eE][+-]?\d+)?|inf(?:inity)?|nan)", re.ASCII | re.IGNORECASE
)
_INTEGER = re.compile(r"[+-]?\d+", re.ASCII)


def decimal(text: str) -> float:
    """``float(text)`` for a number in plain ASCII decimal notation only.

    Python's ``float`` also reads underscores between digits (``"1_0"`` is 10.0) and the
    digits of other scripts (``"\\u0661"``, an Arabic-Indic one, is 1.0); in a data file
    they are a typing error, not a number. Surrounding white space is allowed.

    Raises
    ------
    ValueError
        ``text`` is not such a number.
    """
    s = text.strip()
    if _DECIMAL.fullmatch(s) is None:
        raise ValueError(f"not a decimal number: {short(text)}")
    return float(s)


def integer(text: str) -> int:
    """``int(text)`` for ASCII digits with an optional sign only (see :func:`decimal`).

    Raises
    ------
    ValueError
        ``text`` is not such an integer.
    """
    s = text.strip()
    if _INTEGER.fullmatch(s) is None:
        raise ValueError(f"not an integer: {short(text)}")
    return int(s)


_SURROGATE = re.compile("[\ud800-\udfff]")


def text(s: str) -> str:
    """``s`` as text: a name the locale could not decode (under ``LC_ALL=C`` without UTF-8
    mode its UTF-8 bytes are surrogate escapes, ``l\\udcc3\\udcb6g.csv``) back to its
    characters (``l\u00f6g.csv``); bytes that are not UTF-8, and a lone surrogate of any
    other origin, become U+FFFD. Every other string is returned as it is."""
    if _SURROGATE.search(s) is None:
        return s
    try:
        raw = s.encode("utf-8", "surrogateescape")
    except UnicodeEncodeError:  # a surrogate that stands for no byte
        return _SURROGATE.sub("\ufffd", s)
    return raw.decode("utf-8", "replace")


def control_character(name: str) -> str | None:
    """The first control character other than a tab (NUL, a line break, ...) or half of a
    surrogate pair in ``name``, or None: names with one cannot be written to URDF or MJCF and
    break one-line messages and CSV headers."""
    return next((c for c in name if c != "\t" and unicodedata.category(c) in ("Cc", "Cs")), None)


def number(value: Any, where: str, error: type[Exception]) -> float:
    """A finite float from a parsed document's ``value`` (TOML, JSON), strictly.

    Booleans, strings and other types, integers beyond the float range and NaN/inf raise
    ``error`` naming ``where`` (``"joints[2]: key 'axis'"``) and the value, cut short.
    """
    if isinstance(value, bool) or not isinstance(value, int | float):
        raise error(f"{where} must be a number; got {short(value)}")
    try:
        x = float(value)
    except OverflowError:
        raise error(f"{where} must be a finite number; got {short(value)}") from None
    if not math.isfinite(x):
        raise error(f"{where} must be finite; got {short(value)}")
    return x


def numbers(value: Any, size: int, where: str, error: type[Exception]) -> NDArray[np.float64]:
    """A list of ``size`` finite floats from a parsed document, strictly (see :func:`number`).

    Raises ``error`` naming ``where`` when ``value`` is not a list or tuple of that length, or
    names ``where[k]`` for an element that is not a finite number.
    """
    if not isinstance(value, list | tuple) or len(value) != size:
        raise error(f"{where} must be a list of {size} numbers; got {short(value)}")
    return np.array([number(x, f"{where}[{k}]", error) for k, x in enumerate(value)])


def toml_string(text: str) -> str:
    """``text`` as a TOML basic string that reads back equal: JSON's escapes (valid in TOML)
    for quotes, backslashes and control characters, DEL escaped, every other character as it
    is (a ``\\ud83d`` surrogate escape, which JSON writes for characters beyond the BMP when
    asked for ASCII, is not valid TOML)."""
    return json.dumps(text, ensure_ascii=False).replace("\x7f", "\\u007f")


def parse_toml(text: str, file: str, error: type[DynidError]) -> dict[str, Any]:
    """``tomllib.loads(text)``, every parse failure one ``error`` about ``file`` (its
    ``file``): invalid TOML, nesting too deep for the parser, integers of more than 4300
    digits."""
    import tomllib

    try:
        return tomllib.loads(text)
    except tomllib.TOMLDecodeError as exc:
        raise error(f"not valid TOML ({one_line(str(exc))})", file=file) from None
    except RecursionError:
        raise error("not valid TOML (arrays or tables nested too deeply)", file=file) from None
    except ValueError:  # int() refusing a literal of more than 4300 digits
        raise error("not valid TOML (an integer of more than 4300 digits)", file=file) from None


#: Modules a warning's caller frame is never in: the package's own and those that only
#: pass a call through (a context manager's exit, a partial).
_PASS_THROUGH = ("contextlib", "functools")


def caller_level() -> int:
    """The ``stacklevel`` of a library warning that points to the user's call: the first
    frame outside the ``dynid`` package (and outside :data:`_PASS_THROUGH`), counted from
    the function that calls ``warnings.warn(..., stacklevel=caller_level())``; the
    outermost frame where every frame is the package's (a command line run).

    One rule for every warning, whatever the depth of the call that makes it: a fixed
    ``stacklevel`` points into the package as soon as a call is made through another
    entry point."""
    import sys

    frame = sys._getframe(1)  # the function that warns: stacklevel 1
    level = 1
    while frame.f_back is not None and _inside(frame):
        frame = frame.f_back
        level += 1
    return level


def _inside(frame: Any) -> bool:
    """Whether ``frame`` runs code of the package or of :data:`_PASS_THROUGH`."""
    name = str(frame.f_globals.get("__name__", ""))
    return name == "dynid" or name.startswith("dynid.") or name in _PASS_THROUGH
