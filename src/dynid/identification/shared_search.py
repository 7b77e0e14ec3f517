"""What one search computed, read back by a search made again within the same run.

Where the held-out residual names a joint spring, the identification runs once more with
the spring as a fixed part of every candidate (:mod:`.spring_candidate`): on the same
recordings, prepared alike, the same search without the spring comes first. Within
:func:`shared_searches`, :func:`once` makes each such step once and gives back what it
made the first time: the prepared recordings (:func:`prepared_once`) and the structure
search's selection (:func:`~.selection.select_structure`), found by the objects they were
made from (held, and checked to be the very objects) and the values of their options;
the stepping columns, base parameters and factorisations the searches share
(:func:`~.log_rows.shared_steps`, :func:`~.core.shared_bases`,
:func:`~.holdout.shared_eigen`) stay held for the whole block too. The warnings a step
said are said again each time it is read back, as when it was made again. Nothing is held
past the block's end: the same numbers as made again, not recomputed (a Baxter arm's run
with a shoulder spring: 20.1 s to 15.0 s).
"""

from __future__ import annotations

import warnings
from collections.abc import Callable, Hashable, Iterator, Sequence
from contextlib import contextmanager
from contextvars import ContextVar
from typing import Any, TypeVar

from .._memo import scoped, value_key
from ..model.drive import Drive
from ..model.robot import Robot
from .core import shared_bases
from .holdout import shared_eigen
from .log import TorqueLog
from .log_rows import shared_steps
from .recordings import Recordings, prepare_recordings

__all__ = ["once", "prepared_once", "shared_searches"]

T = TypeVar("T")

#: key -> (the objects the key's ids name, kept alive while the entry lives; what was
#: made; the warnings said while it was made).
_Held = dict[Hashable, tuple[tuple[Any, ...], Any, list[warnings.WarningMessage]]]
_HELD: ContextVar[_Held | None] = ContextVar("_SHARED_SEARCHES", default=None)


@contextmanager
def shared_searches() -> Iterator[None]:
    """Within the block, :func:`once` makes each step once (module docstring), and the
    stepping columns, base parameters and factorisations are shared by every search in
    it. Nested blocks share the outer one's; all is dropped at its end."""
    with scoped(_HELD, dict), shared_steps(), shared_bases(), shared_eigen():
        yield


def _said(said: Sequence[warnings.WarningMessage]) -> None:
    """Each of ``said`` warned again, through the filters active here."""
    for w in said:
        warnings.warn_explicit(w.message, w.category, w.filename, w.lineno)


def once(what: str, objects: tuple[Any, ...], values: tuple[Any, ...], make: Callable[[], T]) -> T:
    """``make()``, or within :func:`shared_searches` what it gave the first time for the
    same ``what``, the very ``objects`` (by identity) and equal ``values`` (by
    :func:`~dynid._memo.value_key`), its warnings said again; made each time outside the
    block or when a value does not hash."""
    held = _HELD.get()
    if held is None:
        return make()
    try:
        key = (what, tuple(id(o) for o in objects), value_key(values))
    except TypeError:
        return make()
    got = held.get(key)
    if got is not None and all(a is b for a, b in zip(got[0], objects, strict=True)):
        _said(got[2])
        return got[1]
    with warnings.catch_warnings(record=True) as said:
        warnings.simplefilter("always")
        try:
            out = make()
        except BaseException:
            _said(said)
            raise
    held[key] = (objects, out, list(said))
    _said(said)
    return out


def prepared_once(
    robot: Robot,
    logs: Sequence[TorqueLog],
    names: Sequence[str] | None,
    drive: Drive | None = None,
    **kw: Any,
) -> Recordings:
    """:func:`~.recordings.prepare_recordings` of ``logs`` (``kw`` as it takes them), made
    once within :func:`shared_searches` (:func:`once`)."""
    return once(
        "prepared",
        (robot, drive, *logs),
        (None if names is None else tuple(names), sorted(kw.items())),
        lambda: prepare_recordings(robot, logs, names, drive=drive, **kw),
    )
