"""Work shared within one run: a memo held in a context variable for the length of a
``with`` block, and the keys its entries are found by.

``scoped(var, make)`` sets ``var`` to ``make()`` for the block when it holds nothing (an
outer block's memo is shared by the nested ones) and drops it at the block's end, so that
nothing is held between runs and no global cache can serve stale data. ``value_key(x)``
is a hashable key of a value by what it holds (arrays by their bytes, dataclasses by
their fields); ``value_digest(x)`` a short digest of that key, for a memo whose entries
would otherwise hold a copy of large inputs.
"""

from __future__ import annotations

import dataclasses
import hashlib
import pickle
from collections.abc import Callable, Hashable, Iterator, Mapping
from contextlib import contextmanager
from contextvars import ContextVar
from typing import Any, TypeVar

import numpy as np

__all__ = ["scoped", "value_digest", "value_key"]

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


def value_digest(x: Any) -> bytes:
    """A 32-byte BLAKE2b digest of ``x`` as :func:`value_key` reads it, mappings too (equal
    values, equal digests; TypeError where :func:`value_key` raises one)."""
    h = hashlib.blake2b(digest_size=32)
    _feed(h, x)
    return h.digest()


def _feed(h: Any, x: Any) -> None:
    """Feed ``x`` to the hash ``h`` as :func:`value_key` reads it (a mapping item by item, in
    the order of its keys' reprs), an array's bytes without a copy where it is
    contiguous."""
    if isinstance(x, np.ndarray):
        a = np.ascontiguousarray(x)
        h.update(pickle.dumps(("array", a.shape, a.dtype.str)))
        h.update(a.data.cast("B") if a.size else b"")
        return
    if dataclasses.is_dataclass(x) and not isinstance(x, type):
        h.update(pickle.dumps(("dataclass", type(x).__qualname__, len(dataclasses.fields(x)))))
        for f in dataclasses.fields(x):
            _feed(h, getattr(x, f.name))
        return
    if isinstance(x, Mapping):
        h.update(pickle.dumps(("mapping", len(x))))
        for k in sorted(x, key=repr):
            _feed(h, k)
            _feed(h, x[k])
        return
    if isinstance(x, tuple | list):
        h.update(pickle.dumps(("sequence", len(x))))
        for v in x:
            _feed(h, v)
        return
    h.update(pickle.dumps(value_key(x)))
