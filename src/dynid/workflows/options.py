"""Checks shared by the entry points' typed options (``XOptions.__post_init__``): each
refusal an :class:`~dynid.exceptions.OptionError` carrying the field at fault, which the
command line names by its flag."""

from __future__ import annotations

import math
from collections.abc import Iterable
from typing import Any, Literal, TypeVar

from .. import _checks
from ..exceptions import OptionError

__all__ = [
    "NO_FILTER",
    "Cutoff",
    "check_band",
    "check_choice",
    "check_cutoff",
    "check_count",
    "check_number",
    "checked_options",
    "library_cutoff",
    "velocity_cutoff",
    "only_with",
    "refused_with",
]

_O = TypeVar("_O")


def checked_options(options: object, kind: type[_O], name: str = "options") -> _O:
    """An entry point's ``options``: ``kind()`` for None, else ``options`` when it is a
    ``kind`` (a dict of the same fields is not: ``kind(**fields)`` makes one).

    Raises
    ------
    WrongTypeError
        Anything else (``"options: expected an IdentifyOptions, got dict"``).
    """
    if options is None:
        return kind()
    article = "an" if kind.__name__[:1] in "AEIOU" else "a"
    out: _O = _checks.of_type(name, options, kind, f"{article} {kind.__name__}")
    return out


#: ``cutoff_hz`` of the options that turns the low-pass off (``--cutoff none``): the
#: states and torques are used as recorded, the accelerations differentiated from them.
NO_FILTER: Literal["none"] = "none"
#: A cut-off option: a frequency [Hz], :data:`NO_FILTER`, or None (the command's default).
Cutoff = float | Literal["none"] | None


def check_cutoff(options: Any, field: str = "cutoff_hz") -> None:
    """``options.field`` is None, :data:`NO_FILTER` or a positive finite frequency [Hz].

    Raises
    ------
    OptionError
        Anything else; ``field`` set.
    """
    if getattr(options, field) != NO_FILTER:
        check_number(options, field)


def library_cutoff(value: Cutoff, default: Any) -> Any:
    """The ``cutoff_hz`` a library call takes for the option ``value``: None (no filter)
    for :data:`NO_FILTER`, ``default`` (``"auto"``, ``"recorded"``) for None, else the
    frequency [Hz]."""
    return None if value == NO_FILTER else default if value is None else value


def velocity_cutoff(value: Cutoff) -> float | None:
    """The cut-off [Hz] of velocities derived from positions through a column map for the
    option ``value``: the frequency given, else None (the library's default; velocities
    derived from positions are always filtered, also under :data:`NO_FILTER`)."""
    return None if value is None or value == NO_FILTER else float(value)


def check_number(
    options: Any,
    field: str,
    *,
    low: float = 0.0,
    high: float = math.inf,
    low_open: bool = True,
    high_open: bool = False,
    optional: bool = True,
) -> None:
    """``options.field`` is a finite number in the range (None passes if ``optional``).

    Raises
    ------
    OptionError
        Not a number, not finite, or outside the range; ``field`` set.
    """
    v = getattr(options, field)
    if v is None and optional:
        return
    ok = isinstance(v, int | float) and not isinstance(v, bool) and math.isfinite(v)
    ok = ok and (v > low if low_open else v >= low) and (v < high if high_open else v <= high)
    if not ok:
        lo = f"{'>' if low_open else '>='} {low:g}"
        hi = "" if math.isinf(high) else f" and {'<' if high_open else '<='} {high:g}"
        raise OptionError(f"must be a finite number {lo}{hi}; got {v!r}", field=field)


def check_band(options: Any, field: str) -> None:
    """``options.field`` is None or ``(MIN, MAX)`` with ``0 <= MIN <= MAX``, finite (a
    total-mass band [kg]).

    Raises
    ------
    OptionError
        Anything else; ``field`` set.
    """
    band = getattr(options, field)
    if band is not None and not (
        len(band) == 2 and all(math.isfinite(float(b)) for b in band) and 0.0 <= band[0] <= band[1]
    ):
        raise OptionError(f"must be MIN,MAX with 0 <= MIN <= MAX; got {band}", field=field)


def check_count(options: Any, field: str, *, low: int = 1, optional: bool = True) -> None:
    """``options.field`` is an integer ``>= low`` (None passes if ``optional``).

    Raises
    ------
    OptionError
        Not an integer, or below ``low``; ``field`` set.
    """
    v = getattr(options, field)
    if v is None and optional:
        return
    if not (isinstance(v, int) and not isinstance(v, bool) and v >= low):
        raise OptionError(f"must be an integer >= {low}; got {v!r}", field=field)


def check_choice(
    options: Any, field: str, choices: Iterable[str], *, optional: bool = True
) -> None:
    """``options.field`` is one of ``choices`` (None passes if ``optional``).

    Raises
    ------
    OptionError
        Another value; ``field`` set.
    """
    v = getattr(options, field)
    allowed = tuple(choices)
    if (v is None and optional) or v in allowed:
        return
    raise OptionError(f"must be one of {', '.join(allowed)}; got {v!r}", field=field)


def only_with(options: Any, fields: Iterable[str], switch: str, *, unset: Any = None) -> None:
    """The ``fields`` (those not ``unset``) apply only with ``options.switch`` on.

    Raises
    ------
    OptionError
        One of them given with ``switch`` off: ``field`` the first, the others and the
        switch in ``others``.
    """
    if getattr(options, switch):
        return
    given = [f for f in fields if getattr(options, f) is not unset]
    if not given:
        return
    rest = tuple(given[1:])
    verb = "apply" if rest else "applies"
    listed = "".join(", {" + f + "}" for f in rest)
    reason = f"{listed} {verb} to {{{switch}}} only; add {{{switch}}} or leave "
    raise OptionError(
        reason.lstrip() + ("them out" if rest else "it out"),
        field=given[0],
        others=(*rest, switch),
    )


def refused_with(options: Any, fields: Iterable[str], switch: str, why: str) -> None:
    """The ``fields`` (those not None) do not apply with ``options.switch`` on (``why``).

    Raises
    ------
    OptionError
        The first of them given with ``switch`` on; ``field`` set.
    """
    if not getattr(options, switch):
        return
    for f in fields:
        if getattr(options, f) is not None:
            raise OptionError(f"does not apply to {{{switch}}} ({why})", field=f, others=(switch,))
