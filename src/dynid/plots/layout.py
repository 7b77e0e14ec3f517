"""Lay out a figure's panels as ``Figure.tight_layout`` does, each panel measured once.

``tight_layout(fig, rect=...)`` gives the subplot parameters of matplotlib's
``fig.tight_layout(rect=...)``, the same to the last bit. Given a ``rect``, matplotlib
measures every panel twice (once for the margins, once more to fit them into ``rect``) at
the same positions, and a measure computes every tick and tick label of the panel; here the
second pass reads the first's boxes. matplotlib is imported by the caller (never by
``import dynid``).
"""

from __future__ import annotations

from typing import TYPE_CHECKING, Any

if TYPE_CHECKING:  # pragma: no cover
    from matplotlib.figure import Figure

__all__ = ["tight_layout"]


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
