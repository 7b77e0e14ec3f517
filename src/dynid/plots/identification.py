"""Figures of an identification on held-out data: the residuals against the sensor noise
(the measured against predicted torques are :func:`dynid.plots.torques.plot_torque_validation`
of the same prediction).

The prediction itself, :class:`~dynid.friction.heldout_torques.HeldOutTorques`, is made by
the library (:func:`~dynid.friction.heldout_torques.heldout_torques`, returned by
:func:`~dynid.workflows.identify.identify_files`); this module only draws it.

matplotlib is imported inside the plotting functions (never by ``import dynid``).
"""

from __future__ import annotations

from typing import TYPE_CHECKING

import numpy as np
from numpy.typing import NDArray

from .layout import tight_layout
from .style import COLOURS

if TYPE_CHECKING:  # pragma: no cover
    from matplotlib.figure import Figure

    from ..friction.heldout_torques import HeldOutTorques

__all__ = ["plot_residual_histograms"]


def _histogram_range(e: NDArray[np.float64], noise: float) -> tuple[float, float]:
    """The residual range [N m] a histogram shows: the central 99.5 % of ``e`` widened by a
    fifth, and at least 5 times the sensor ``noise`` either side, so that a few samples
    at velocity reversals do not squash the distribution into one bin."""
    a, b = (float(x) for x in np.quantile(e, [0.0025, 0.9975]))
    pad = 0.2 * (b - a)
    lo, hi = min(a - pad, -5.0 * noise), max(b + pad, 5.0 * noise)
    if not hi > lo:
        lo, hi = lo - 1.0, hi + 1.0
    return lo, hi


def plot_residual_histograms(h: HeldOutTorques, *, title: str | None = None) -> Figure:
    """Per joint, the histogram of the held-out residual (measured minus predicted) with
    the normal density of the sensor noise over it.

    Returns
    -------
    matplotlib.figure.Figure
        One panel per joint; residual [N m] on x, density [1/(N m)] on y.
    """
    import matplotlib.pyplot as plt

    e = h.validation.log.tau - h.validation.tau_hat
    n = e.shape[1]
    cols = min(n, 4)
    rows = int(np.ceil(n / cols))
    fig, axes = plt.subplots(rows, cols, figsize=(3.2 * cols, 2.5 * rows), squeeze=False)
    for j, ax in enumerate(axes.ravel()):
        if j >= n:
            ax.set_visible(False)
            continue
        s = float(h.noise_rms[j])
        lo, hi = _histogram_range(e[:, j], s)
        inside = (e[:, j] >= lo) & (e[:, j] <= hi)
        ax.hist(e[inside, j], bins=40, range=(lo, hi), density=True, color=COLOURS["model"],
                alpha=0.6, histtype="stepfilled", label="residual")  # fmt: skip
        ax.set_xlim(lo, hi)
        if s > 0:
            x = np.linspace(lo, hi, 200)
            ax.plot(
                x,
                np.exp(-0.5 * (x / s) ** 2) / (s * np.sqrt(2 * np.pi)),
                "k-",
                lw=1.0,
                label="sensor noise",
            )
        out = int(e.shape[0] - inside.sum())
        ax.set_title(
            f"{h.joint_names[j]}: RMS {np.sqrt(np.mean(e[:, j] ** 2)):.3g} N m"
            + (f"\n{out} sample(s) beyond the axis" if out else ""),
            fontsize=9,
        )
        ax.set_xlabel("residual [N m]", fontsize=8)
        ax.tick_params(labelsize=7)
    axes[0, 0].set_ylabel("density [1/(N m)]", fontsize=8)
    axes[0, 0].legend(fontsize=7)
    fig.suptitle(title or f"Residuals on held-out data ({h.block})", fontsize=10)
    tight_layout(fig)
    return fig
