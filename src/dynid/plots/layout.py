"""Lay out a figure's panels as ``Figure.tight_layout`` does, each panel measured once.

``tight_layout(fig, rect=...)`` gives the subplot parameters of matplotlib's
``fig.tight_layout(rect=...)``, the same to the last bit. Given a ``rect``, matplotlib
measures every panel twice (once for the margins, once more to fit them into ``rect``) at
the same positions, and a measure computes every tick and tick label of the panel; here the
second pass reads the first's boxes. matplotlib is imported by the caller (never by
``import dynid``).

``ticks_once(fig)``: within the block, each axis of the figure's panels computes its ticks
and their labels' boxes once per measure and per draw, not twice (matplotlib computes them
again to place the axis label); the same numbers, so the same layout and pixels.
"""

from __future__ import annotations

from collections.abc import Iterator
from contextlib import contextmanager
from typing import TYPE_CHECKING, Any

if TYPE_CHECKING:  # pragma: no cover
    from matplotlib.figure import Figure

__all__ = ["ticks_once", "tight_layout"]


def tight_layout(fig: Figure, *, rect: tuple[float, float, float, float] | None = None) -> None:
    """Apply ``fig.tight_layout(rect=rect)`` with each Axes' tight box [pixels] measured
    once per renderer.

    Parameters
    ----------
    fig : Figure
        Laid out in place (its subplot parameters).
    rect : (left, bottom, right, top), optional
        The rectangle in figure coordinates [0-1] the panels with their labels fit into
        (default: the whole figure).
    """
    measured = [_measured_once(ax) for ax in fig.axes]
    try:
        with ticks_once(fig):
            fig.tight_layout(rect=rect)
    finally:
        for ax, had_own in zip(fig.axes, measured, strict=True):
            if not had_own:
                del ax.get_tightbbox  # the class's method again


def _measured_once(ax: Any) -> bool:
    """Give ``ax`` a ``get_tightbbox`` that returns its first answer for the same
    renderer and arguments; False when it had none of its own (to be removed after)."""
    if "get_tightbbox" in vars(ax):  # already replaced: leave it as it is
        return True
    measure = ax.get_tightbbox
    boxes: dict[Any, Any] = {}

    def once(renderer: Any = None, *args: Any, **kwargs: Any) -> Any:
        try:
            key = (id(renderer), args, tuple(sorted(kwargs.items())))
            hash(key)
        except TypeError:  # an argument that cannot be a key (a list of artists)
            return measure(renderer, *args, **kwargs)
        if key not in boxes:
            boxes[key] = measure(renderer, *args, **kwargs)
        return boxes[key]

    ax.get_tightbbox = once
    return False


#: The methods of a matplotlib ``Axis`` that :func:`ticks_once` reads once per scope, and
#: the ones whose call is that scope (a measure, a draw).
_ONCE = ("_update_ticks", "_get_ticklabel_bboxes")
_SCOPES = ("get_tightbbox", "draw")


@contextmanager
def ticks_once(fig: Figure) -> Iterator[None]:
    """Within the block, each x and y axis of ``fig``'s panels computes its ticks
    (``_update_ticks``) and their labels' boxes once per measure (``get_tightbbox``) and
    per draw, where matplotlib computes both twice: once for the axis, once more to place
    its label beside them (the boxes of the axis' label group, itself alone unless the
    labels were aligned). Nothing changes the ticks between the two, so the answers are
    the same. A matplotlib without these methods is left as it is."""
    axes = [a for ax in fig.axes for a in (ax.xaxis, ax.yaxis)]
    axes = [a for a in axes if all(hasattr(a, m) for m in _ONCE + _SCOPES)]
    for axis in axes:
        _read_once(axis)
    try:
        yield
    finally:
        for axis in axes:
            for m in _ONCE + _SCOPES:
                vars(axis).pop(m, None)  # the class's methods again


def _read_once(axis: Any) -> None:
    """Give ``axis`` instance methods for :func:`ticks_once`: in a call of a scope's
    method, the first answer of each of :data:`_ONCE` for the same arguments is read back;
    outside one, they are the class's."""
    memo: dict[Any, Any] = {}
    active = [0]

    def scoped(method: Any) -> Any:
        def call(*args: Any, **kwargs: Any) -> Any:
            active[0] += 1
            try:
                return method(*args, **kwargs)
            finally:
                active[0] -= 1
                if not active[0]:
                    memo.clear()

        return call

    def update_ticks(method: Any) -> Any:
        def call() -> Any:
            if not active[0]:
                return method()
            if "ticks" not in memo:
                memo["ticks"] = method()
            return memo["ticks"]

        return call

    def label_boxes(method: Any) -> Any:
        def call(ticks: Any, renderer: Any) -> Any:
            held = memo.get("boxes")
            if not active[0] or ticks is not memo.get("ticks"):
                return method(ticks, renderer)
            if held is None or held[0] is not renderer:
                held = memo["boxes"] = (renderer, method(ticks, renderer))
            return held[1]

        return call

    for name in _SCOPES:
        setattr(axis, name, scoped(getattr(axis, name)))
    axis._update_ticks = update_ticks(axis._update_ticks)
    axis._get_ticklabel_bboxes = label_boxes(axis._get_ticklabel_bboxes)
