"""Write a figure to a file: the one place figures are saved.

``save_figure(make_figure, path, dpi=...)`` renders with the Agg backend, writes atomically
(temporary file, then rename; the format from the suffix) and closes the figure.
"""

from __future__ import annotations

from collections.abc import Callable
from pathlib import Path
from typing import Any

from ..io.atomic import open_atomic

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
        with open_atomic(path, "wb") as fh:
            fig.savefig(fh, format=path.suffix.lstrip(".") or "png", dpi=dpi)
    finally:
        plt.close(fig)
    return path
