"""Work made once per run: a structure search, the recordings' checks and their
preparation, called again with equal arguments, read back rather than computed again.

:func:`~dynid.identification.recording_offsets.identify_with_offsets` prepares the
recordings the fit has just prepared a second time, with the cut-off the fit read (the
same cut-off, trim and pieces), and the spring trial
(:mod:`~dynid.identification.spring_candidate`) prepares them once more and begins with
the search without the spring that the first fit made: each time the sign checks of the
whole recordings, their torque findings, every piece's filtering (a Panda's three 5 s
recordings: 0.44 s a time, of which the sign checks 0.33 s) and a structure search (7.3 s
to identify with the spring trial, 3.6 s without). Within :func:`shared_run`,
:func:`once_per_run` keys a call by a digest of its arguments
(:func:`~dynid._memo.value_digest`: arrays by their bytes, the robot, drive, candidates
and options by their fields) and returns the first call's result, the warnings it gave
said again; outside the block every call runs. The results held take at most a quarter
of :func:`~dynid.identification.streaming.max_stack_bytes` (the memory a stacked regressor
may take; 32 MB by default, the Panda's three recordings 2.1 MB): a long log's
preparation beyond it is made again, not held for the run beside its fit; a search's
choice is a small record, and no regressor is ever held.
"""

from __future__ import annotations

import dataclasses
import functools
import warnings
from collections.abc import Callable, Iterator
from contextlib import contextmanager
from contextvars import ContextVar
from typing import Any, TypeVar

import numpy as np

from .._memo import scoped, value_digest
from .streaming import max_stack_bytes

__all__ = ["once_per_run", "shared_run"]

F = TypeVar("F", bound=Callable[..., Any])


class _Held:
    """The results held while :func:`shared_run` is active: digest -> (result,
    the warnings its call gave), and the bytes of their arrays, at most ``budget``
    (module docstring)."""

    def __init__(self) -> None:
        self.held: dict[bytes, tuple[Any, tuple[warnings.WarningMessage, ...]]] = {}
        self.nbytes = 0
        self.budget = max_stack_bytes() // 4


_HELD: ContextVar[_Held | None] = ContextVar("dynid_once_per_run", default=None)


@contextmanager
def shared_run() -> Iterator[None]:
    """Within the block, a call of :func:`once_per_run` made again with equal arguments
    returns the first call's result (module docstring). Nested blocks share the outer
    one's; what it holds is dropped at its end."""
    with scoped(_HELD, _Held):
        yield


def once_per_run(compute: F) -> F:
    """``compute`` read back within :func:`shared_run` where it was called with
    equal arguments (positional and keyword, by value), the warnings its first call gave
    said again in their order; run as it is outside the block or where an argument has no
    digest. An exception is never held: a call that raised runs again."""

    @functools.wraps(compute)
    def once(*args: Any, **kw: Any) -> Any:
        memo = _HELD.get()
        if memo is None:
            return compute(*args, **kw)
        try:
            key = value_digest((compute.__module__, compute.__qualname__, args, sorted(kw.items())))
        except TypeError:  # an argument without a value key: computed every time
            return compute(*args, **kw)
        if key in memo.held:
            value, said = memo.held[key]
            for w in said:
                warnings.warn_explicit(w.message, w.category, w.filename, w.lineno)
            return value
        with warnings.catch_warnings(record=True) as caught:
            warnings.simplefilter("always")
            value = compute(*args, **kw)
        size = _nbytes(value)
        if memo.nbytes + size <= memo.budget:
            memo.held[key] = (value, tuple(caught))
            memo.nbytes += size
        for w in caught:
            warnings.warn_explicit(w.message, w.category, w.filename, w.lineno)
        return value

    return once  # type: ignore[return-value]


def _nbytes(value: Any, depth: int = 0) -> int:
    """The bytes of the arrays ``value`` holds (in its dataclass fields, sequences and
    mappings, a few levels deep)."""
    if isinstance(value, np.ndarray):
        return int(value.nbytes)
    if depth > 4:
        return 0
    if dataclasses.is_dataclass(value) and not isinstance(value, type):
        items: Any = (getattr(value, f.name, None) for f in dataclasses.fields(value))
    elif isinstance(value, dict):
        items = value.values()
    elif isinstance(value, tuple | list):
        items = value
    else:
        return 0
    return sum(_nbytes(v, depth + 1) for v in items)
