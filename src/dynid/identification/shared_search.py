"""A structure search made once per run: the same prepared recordings searched with the
same options read back, not searched again.

The spring trial (:mod:`dynid.identification.spring_candidate`) fits the recordings again
with a spring on the joints the held-out residual names; that fit begins with the search
without the spring, on the same recordings prepared alike, which the first fit has just
made (a Panda's three 5 s recordings: 7.3 s to identify with the trial, 3.6 s without).
Within :func:`shared_searches`, :func:`searched_once` keys a search by a digest of its
arguments (:func:`~dynid._memo.value_digest`: the prepared arrays by their bytes, the
robot, drive, candidates and options by their fields) and returns the choice the first
call made; the choice is a small record, and nothing else is held. Outside the block
every search runs.
"""

from __future__ import annotations

import functools
from collections.abc import Callable, Iterator
from contextlib import contextmanager
from contextvars import ContextVar
from typing import Any, TypeVar

from .._memo import scoped, value_digest

__all__ = ["searched_once", "shared_searches"]

F = TypeVar("F", bound=Callable[..., Any])

_SEARCHES: ContextVar[dict[bytes, Any] | None] = ContextVar("dynid_searches", default=None)


@contextmanager
def shared_searches() -> Iterator[None]:
    """Within the block, a search of :func:`searched_once` called again with equal
    arguments returns the first call's result (module docstring). Nested blocks share the
    outer one's; what it holds is dropped at its end."""
    with scoped(_SEARCHES, dict):
        yield


def searched_once(search: F) -> F:
    """``search`` read back within :func:`shared_searches` where it was called with equal
    arguments (positional and keyword, by value); run as it is outside the block or where
    an argument has no digest."""

    @functools.wraps(search)
    def once(*args: Any, **kw: Any) -> Any:
        memo = _SEARCHES.get()
        if memo is None:
            return search(*args, **kw)
        try:
            key = value_digest((search.__qualname__, args, sorted(kw.items())))
        except TypeError:  # an argument without a value key: searched every time
            return search(*args, **kw)
        if key not in memo:
            memo[key] = search(*args, **kw)
        return memo[key]

    return once  # type: ignore[return-value]
