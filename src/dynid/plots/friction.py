"""Figures of friction fits: torque residual against joint velocity (Gaz et al. 2019, Fig. 4).

matplotlib is imported inside the functions; they return a Figure and never show it.
"""

from __future__ import annotations

from collections.abc import Sequence
from typing import TYPE_CHECKING

import numpy as np

from ..friction.fit import FrictionFit, FrictionResidual
from ..friction.laws.base import Friction
from ..friction.model import FrictionModel, FrictionSum
from .layout import tight_layout
from .style import COLOURS

if TYPE_CHECKING:  # pragma: no cover
    from matplotlib.figure import Figure

__all__ = ["plot_friction_fit"]


def _curve(
    friction: FrictionModel | FrictionSum, V: np.ndarray, j: int, motors: bool
) -> np.ndarray:
    """Column ``j`` of the friction at velocities ``V`` (N, n): at the motors (``motors``)
    the law of motor ``j`` at motor velocities [rad/s, N m], else the joint torques."""
    if motors and isinstance(friction, Friction) and friction.at_motors:
        return np.asarray(friction.law.torques(V, friction.params, friction.band))[:, j]
    return np.asarray(friction.torques(V))[:, j]


def plot_friction_fit(
    residual: FrictionResidual,
    fit: FrictionFit,
    *,
    reference: FrictionModel | None = None,
    reference_label: str = "reference",
    joint_names: Sequence[str] | None = None,
    max_points: int = 4000,
    ncols: int = 4,
    title: str | None = None,
    fig: Figure | None = None,
) -> Figure:
    """Per joint: residual torque against velocity, with the fitted friction curve.

    Parameters
    ----------
    residual : FrictionResidual
        From :func:`dynid.friction.fit.friction_residual` (the data the fit used).
    fit : FrictionFit
        The fitted model, drawn over the visited velocity range.
    reference : FrictionModel, optional
        A second curve (e.g. the ground truth or the published parameters).
    reference_label : str
    joint_names : sequence of str, optional
    max_points : int
        Residual samples drawn per joint (evenly strided).
    ncols : int
        Panels per row.
    title : str, optional
    fig : Figure, optional

    Returns
    -------
    matplotlib.figure.Figure
        One panel per joint, or per motor where the friction was fitted at the motors of
        a drive (one law per motor: the residual ``K^-T r`` against the motor velocity
        ``K dq``, the law's own curve); velocity [rad/s] on x, torque [N m] on y, each
        axis naming its side; the title of each panel names it on one line and gives the
        joint's RMS before and after compensation on the next.
    """
    import matplotlib.pyplot as plt

    fr = fit.friction
    motors = isinstance(fr, Friction) and fr.at_motors
    dq, r = residual.dq, residual.residual
    n = dq.shape[1]
    names = list(joint_names) if joint_names is not None else [f"joint {j + 1}" for j in range(n)]
    side = "motor" if motors else "joint"
    if isinstance(fr, Friction) and motors:
        K = fr.transmission  # motor velocities per joint velocity where the law acts
        dq = np.asarray(dq @ K.T, dtype=np.float64)  # r = K^T f(K dq): f at the motors
        r = np.asarray(np.linalg.solve(K.T, r.T).T, dtype=np.float64)
    ncols = max(1, min(ncols, n))
    nrows = int(np.ceil(n / ncols))
    if fig is None:
        fig = plt.figure(figsize=(3.4 * ncols, 3.1 * nrows + 0.6))
    else:
        fig.clear()
    axes = fig.subplots(nrows, ncols, squeeze=False)
    step = max(1, int(np.ceil(dq.shape[0] / max_points)))
    for j in range(n):
        ax = axes[j // ncols, j % ncols]
        ax.plot(
            dq[::step, j],
            r[::step, j],
            ".",
            ms=1.5,
            color=COLOURS["samples"],
            alpha=0.5,
            rasterized=True,
            label="residual (measured - model)",
        )
        lo, hi = float(dq[:, j].min()), float(dq[:, j].max())
        v = np.linspace(lo, hi, 400)
        V = np.zeros((v.size, n))
        V[:, j] = v
        ax.plot(
            v,
            _curve(fr, V, j, motors),
            color=COLOURS["friction"],
            lw=1.8,
            label=f"fitted {fit.kind}",
        )
        if reference is not None:
            ax.plot(
                v,
                _curve(reference, V, j, motors),
                color=COLOURS["reference"],
                lw=1.0,
                ls="--",
                label=reference_label,
            )
        ax.axhline(0.0, color="0.7", lw=0.5)
        ax.axvline(0.0, color="0.7", lw=0.5)
        who = f"motor {j + 1} ({names[j]})" if motors else names[j]
        ax.set_title(  # two lines: a drive's long joint names ran into the next title
            f"{who}\n{'joint ' if motors else ''}RMS {fit.rms_before[j]:.3f} -> "
            f"{fit.rms_after[j]:.3f} N m",
            fontsize=9,
        )
        ax.set_xlabel(f"{side} velocity [rad/s]", fontsize=8)
        ax.set_ylabel(f"{side} torque [N m]", fontsize=8)
        ax.tick_params(labelsize=7)
        ax.grid(alpha=0.3)
    for k in range(n, nrows * ncols):
        axes[k // ncols, k % ncols].set_axis_off()
    handles, labels = axes[0, 0].get_legend_handles_labels()
    if n < nrows * ncols:
        spare = axes[-1, -1]
        spare.legend(handles, labels, loc="center", fontsize=9, markerscale=6, frameon=False)
        tight_layout(fig, rect=(0, 0, 1, 0.97 if title else 1.0))
    else:
        fig.legend(
            handles, labels, loc="lower center", ncol=len(labels), markerscale=6, frameon=False
        )
        tight_layout(fig, rect=(0, 0.05, 1, 0.97 if title else 1.0))
    if title:
        fig.suptitle(title, fontsize=11)
    return fig
