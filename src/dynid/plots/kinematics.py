"""Figures of kinematics: the joint motion simulated by inverse kinematics.

matplotlib is imported inside the functions (never by ``import dynid``). Figures are made
with :class:`matplotlib.figure.Figure` directly, without pyplot, so no GUI backend is
touched and ``fig.savefig`` renders with Agg; the functions never show a figure.
"""

from __future__ import annotations

from collections.abc import Sequence
from typing import TYPE_CHECKING

import numpy as np
from numpy.typing import ArrayLike

from .. import _checks
from ..exceptions import ShapeError

if TYPE_CHECKING:  # pragma: no cover
    from matplotlib.axes import Axes
    from matplotlib.figure import Figure

__all__ = ["plot_ik_path"]


def plot_ik_path(
    path: ArrayLike,
    *,
    joint_names: Sequence[str] | None = None,
    q_min: ArrayLike | None = None,
    q_max: ArrayLike | None = None,
    dt: float | None = None,
    title: str | None = None,
    ax: Axes | None = None,
) -> Figure:
    """Joint positions along an inverse-kinematics simulation, one line per joint.

    Parameters
    ----------
    path : array_like, shape (k + 1, n)
        Joint positions [rad or m] after each step, e.g. :attr:`IKResult.path`.
    joint_names : sequence of str, optional
        Legend labels (default ``joint 1 .. n``).
    q_min, q_max : array_like, shape (n,), optional
        Position limits; drawn as dotted lines in each joint's colour where finite.
    dt : float, optional
        Simulation step [s]; the x axis is then time [s] instead of the iteration.
    title : str, optional
    ax : matplotlib.axes.Axes, optional
        Drawn into; a new figure by default.

    Returns
    -------
    matplotlib.figure.Figure
        The figure that holds the axes.

    Raises
    ------
    ShapeError
        ``path`` is not 2-D, or ``joint_names``/limits do not have ``n`` entries.
    NonFiniteError
        ``path`` holds NaN or inf.
    """
    P = _checks.as_array("path", path)
    if P.ndim != 2 or P.shape[0] < 1:
        raise ShapeError(f"path must have shape (k + 1, n); got {P.shape}")
    n = P.shape[1]
    names = [f"joint {i + 1}" for i in range(n)] if joint_names is None else list(joint_names)
    if len(names) != n:
        raise ShapeError(f"joint_names must have {n} entries; got {len(names)}")
    limits = []
    for label, lim in (("q_min", q_min), ("q_max", q_max)):
        if lim is not None:
            limits.append(_checks.as_exact(label, lim, (n,), allow_nonfinite=True))

    from matplotlib.figure import Figure

    if ax is None:
        fig = Figure(figsize=(8.0, 4.5), layout="constrained")
        ax = fig.add_subplot()
    else:
        parent = ax.figure  # a Figure, or a SubFigure inside one: return the whole Figure
        fig = parent if isinstance(parent, Figure) else parent.figure
    x = np.arange(P.shape[0], dtype=float)
    if dt is not None:
        x = x * dt
    for j in range(n):
        (line,) = ax.plot(
            x, P[:, j], lw=1.4, marker="." if P.shape[0] <= 40 else None, label=names[j]
        )
        for lim in limits:
            if np.isfinite(lim[j]):
                ax.axhline(lim[j], color=line.get_color(), lw=0.6, ls=":")
    ax.set_xlabel("time [s]" if dt is not None else "iteration")
    ax.set_ylabel("joint position [rad]")
    ax.set_xlim(x[0], x[-1] if x[-1] > x[0] else x[0] + 1.0)
    ax.grid(True, lw=0.3, alpha=0.6)
    ax.legend(loc="center left", bbox_to_anchor=(1.0, 0.5), fontsize="small", frameon=False)
    if title:
        ax.set_title(title)
    return fig
