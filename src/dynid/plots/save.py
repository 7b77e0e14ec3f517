"""Write a figure to a file: the one place figures are saved.

``save_figure(make_figure, path, dpi=...)`` renders with the Agg backend, writes atomically
(temporary file, then rename; the format from the suffix) and closes the figure. A figure
laid out once by ``tight_layout`` is drawn once: matplotlib leaves a placeholder layout
engine behind it, for which ``savefig`` would first draw the whole figure without output.
Each axis computes its ticks once per draw (:func:`~dynid.plots.layout.ticks_once`).
"""

from __future__ import annotations

from collections.abc import Callable
from pathlib import Path
from typing import Any

from ..io.atomic import open_atomic
from .layout import ticks_once

__all__ = ["save_figure"]


def save_figure(make_figure: Callable[[], Any], path: Path, *, dpi: int = 110) -> Path:
    """Render ``make_figure()`` to ``path`` atomically and close the figure; returns ``path``.

    Raises
    ------
    ImportError
        matplotlib is not installed (checked before ``make_figure`` is called).
    """
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    path = Path(path)
    fig = make_figure()
    try:
        _drop_placeholder_layout(fig)
        with open_atomic(path, "wb") as fh, ticks_once(fig):
            fig.savefig(fh, format=path.suffix.lstrip(".") or "png", dpi=dpi)
    finally:
        plt.close(fig)
    return path


def _drop_placeholder_layout(fig: Any) -> None:
    """Remove the do-nothing layout engine ``fig.tight_layout()`` leaves on ``fig``, so that
    ``savefig`` draws the figure once instead of twice (a draw without output first, to lay
    out an engine that lays out nothing); a real engine (``layout="constrained"``) is kept."""
    import matplotlib
    from matplotlib.layout_engine import PlaceHolderLayoutEngine

    rc = matplotlib.rcParams  # with these set, None would mean a layout engine again
    if rc["figure.autolayout"] or rc["figure.constrained_layout.use"]:
        return
    if isinstance(fig.get_layout_engine(), PlaceHolderLayoutEngine):
        fig.set_layout_engine(None)
