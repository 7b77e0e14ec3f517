"""Figure of an exciting trajectory: joint motion within the limits and the swept workspace.

matplotlib is imported inside the function (never by ``import dynid``); the figure is made
with :class:`matplotlib.figure.Figure` directly and never shown.
"""

from __future__ import annotations

from typing import TYPE_CHECKING

import numpy as np

from ..model.robot import Robot
from ..simulation.collision import Obstacles, capsule_segments
from ..simulation.trajectories import Trajectory

if TYPE_CHECKING:  # pragma: no cover
    from matplotlib.figure import Figure

__all__ = ["plot_excitation"]


def plot_excitation(
    robot: Robot,
    traj: Trajectory,
    *,
    obstacles: Obstacles | None = None,
    title: str | None = None,
    stride_s: float = 0.1,
) -> Figure:
    """Joint positions and velocities (as fractions of their limits) and the swept arm.

    Left: ``q`` mapped to [-1, 1] over ``[q_min, q_max]`` and ``dq / dq_max`` against
    time. Right: the capsule segments every ``stride_s`` seconds projected on the x-z and
    x-y planes of the base frame [m], with the obstacle planes and boxes.
    """
    from matplotlib.figure import Figure

    t, q, dq = np.asarray(traj.t), np.asarray(traj.q), np.asarray(traj.dq)
    fig = Figure(figsize=(12, 7), layout="constrained")
    gs = fig.add_gridspec(2, 2)
    ax_q, ax_v = fig.add_subplot(gs[0, 0]), fig.add_subplot(gs[1, 0])
    ax_xz, ax_xy = fig.add_subplot(gs[0, 1]), fig.add_subplot(gs[1, 1])
    finite = np.isfinite(robot.q_min) & np.isfinite(robot.q_max)
    mid = np.where(finite, 0.5 * (robot.q_min + robot.q_max), 0.0)
    half = np.where(finite, 0.5 * (robot.q_max - robot.q_min), np.pi)
    vmax = np.where(np.isfinite(robot.dq_max), robot.dq_max, 1.0)
    for j in range(robot.n):
        ax_q.plot(t, (q[:, j] - mid[j]) / half[j], lw=0.8, label=robot.joint_names[j])
        ax_v.plot(t, dq[:, j] / vmax[j], lw=0.8)
    for ax, name in ((ax_q, "position / range"), (ax_v, "velocity / limit")):
        ax.axhline(1.0, color="k", lw=0.6, ls="--")
        ax.axhline(-1.0, color="k", lw=0.6, ls="--")
        ax.set_ylabel(name)
        ax.grid(alpha=0.3)
    ax_v.set_xlabel("t [s]")
    ax_q.legend(ncol=4, fontsize=7, loc="lower right")
    step = max(1, int(round(stride_s / max(float(np.median(np.diff(t))), 1e-9))))
    seg = capsule_segments(robot, q[::step])  # (k, n + 1, 2, 3)
    for ax, (a, b), lab in ((ax_xz, (0, 2), "z [m]"), (ax_xy, (0, 1), "y [m]")):
        for c in range(seg.shape[1]):
            xs = seg[:, c, :, a].T
            ys = seg[:, c, :, b].T
            ax.plot(xs, ys, color=f"C{c % 10}", lw=0.4, alpha=0.25)
        ax.set_xlabel("x [m]")
        ax.set_ylabel(lab)
        ax.set_aspect("equal", adjustable="datalim")
        ax.grid(alpha=0.3)
    if obstacles is not None:
        for pl in obstacles.planes:
            if abs(pl.normal[2]) > 0.9:  # a floor or table: a line in the x-z view
                ax_xz.axhline(pl.point[2], color="k", lw=1.2)
        for bx in obstacles.boxes:
            from matplotlib.patches import Rectangle

            ctr, sz = bx.center, bx.size
            ax_xz.add_patch(
                Rectangle((ctr[0] - sz[0] / 2, ctr[2] - sz[2] / 2), sz[0], sz[2], fc="0.7")
            )
            ax_xy.add_patch(
                Rectangle((ctr[0] - sz[0] / 2, ctr[1] - sz[1] / 2), sz[0], sz[1], fc="0.7")
            )
    ax_xz.set_title("swept capsules (side view)")
    ax_xy.set_title("swept capsules (top view)")
    fig.suptitle(title or f"exciting trajectory of {robot.name}")
    return fig
