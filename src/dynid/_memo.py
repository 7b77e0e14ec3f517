"""Work shared within one run: a memo held in a context variable for the length of a
``with`` block, and the keys its entries are found by.

``scoped(var, make)`` sets ``var`` to ``make()`` for the block when it holds nothing (an
outer block's memo is shared by the nested ones) and drops it at the block's end, so that
nothing is held between runs and no global cache can serve stale data. ``value_key(x)``
is a hashable key of a value by what it holds (arrays by their bytes, dataclasses by
their fields).
"""

from __future__ import annotations

import dataclasses
from collections.abc import Callable, Hashable, Iterator
from contextlib import contextmanager
from contextvars import ContextVar
from typing import Any, TypeVar

import numpy as np

__all__ = ["scoped", "value_key"]

T = TypeVar("T")


@contextmanager
def scoped(var: ContextVar[T | None], make: Callable[[], T]) -> Iterator[None]:
    """Within the block, ``var`` holds ``make()`` (or the outer block's value, when one is
    active); it holds None again at the block's end."""
    if var.get() is not None:
        yield
        return
    token = var.set(make())
    try:
        yield
    finally:
        var.reset(token)


def value_key(x: Any) -> Hashable:
    """A hashable key of ``x``: arrays by shape, type and bytes, dataclasses by their
    fields, tuples and lists item by item; anything else must hash (TypeError
    otherwise)."""
    if isinstance(x, np.ndarray):
        return ("array", x.shape, x.dtype.str, x.tobytes())
    if dataclasses.is_dataclass(x) and not isinstance(x, type):
        return (type(x).__qualname__,) + tuple(
            value_key(getattr(x, f.name)) for f in dataclasses.fields(x)
        )
    if isinstance(x, tuple | list):
        return tuple(value_key(v) for v in x)
    hash(x)
    return (type(x).__qualname__, x)
