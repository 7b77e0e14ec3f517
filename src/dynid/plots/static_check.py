"""The figure of ``dynid validate`` on static data: a model's ``M(q)`` and ``g(q)``
against the data's at held-out configurations.

matplotlib is imported inside the function (never by ``import dynid``).
"""

from __future__ import annotations

from collections.abc import Sequence
from typing import TYPE_CHECKING

import numpy as np

from ..identification.static_validation import StaticValidation
from .layout import tight_layout
from .style import COLOURS

if TYPE_CHECKING:
    from matplotlib.figure import Figure

__all__ = ["plot_static_validation"]


def plot_static_validation(
    result: StaticValidation,
    *,
    joint_names: Sequence[str] | None = None,
    title: str | None = None,
) -> Figure:
    """Predicted against measured entries: every ``g_j`` (left, one colour per joint,
    [N m]) and every entry of ``tril M`` (middle, [kg m^2]), on the diagonal where the
    model is exact; each joint's relative error [%] (right, over ``g_j`` and row ``j`` of
    ``M``), with each joint's noise floor where the data record their noise.

    Returns
    -------
    matplotlib.figure.Figure
        One row of three axes.
    """
    import matplotlib.pyplot as plt

    n = result.g_rms.size
    names = list(joint_names) if joint_names is not None else [f"joint {j + 1}" for j in range(n)]
    k = result.measured.shape[1] - n  # the rows of tril M
    fig, (ag, am, ae) = plt.subplots(1, 3, figsize=(14, 4.4))
    for j in range(n):
        ag.plot(result.measured[:, k + j], result.predicted[:, k + j], ".", ms=3, label=names[j])
    am.plot(result.measured[:, :k].ravel(), result.predicted[:, :k].ravel(), ".", ms=2,
            color=COLOURS["model"])  # fmt: skip
    for ax, what, unit in ((ag, "g", "N m"), (am, "M (lower triangle)", "kg m^2")):
        lo, hi = ax.get_xlim()
        ax.plot([lo, hi], [lo, hi], "-", color=COLOURS["reference"], lw=0.8)
        ax.set_xlabel(f"{what} of the data [{unit}]")
        ax.set_ylabel(f"{what} of the model [{unit}]")
    ag.legend(fontsize=7, markerscale=3, loc="upper left")
    ae.bar(np.arange(n), result.joint_percent, color=COLOURS["model"])
    if result.joint_floor_percent is not None:
        ae.plot(np.arange(n), result.joint_floor_percent, "_", ms=22, mew=2,
                color=COLOURS["reference"], label="each joint's noise floor")  # fmt: skip
        ae.legend(fontsize=8)
    ae.set_xticks(np.arange(n), names, rotation=45, ha="right", fontsize=8)
    ae.set_ylabel("relative error of g_j and row j of M [%]")
    ae.set_title(f"{result.relative_error_percent:.3g} % over all", fontsize=9)
    if title:
        fig.suptitle(title)
    tight_layout(fig)
    return fig
