"""Figures of the feasible-parameter retrieval and its Newton-Euler validation.

* :func:`plot_newton_euler_validation`: per joint, the measured torques and the torques
  of RNEA with the feasible parameters plus friction, and those of the identified model
  when given (Gaz et al. 2019, Fig. 5).
* :func:`plot_retrieval`: the stage objective of every run (log scale) and the margins
  of the physical constraints per link.

matplotlib is imported inside the functions (never by ``import dynid``); the functions
return a Figure and never show it. Use the ``Agg`` backend for files.
"""

from __future__ import annotations

from collections.abc import Sequence
from typing import TYPE_CHECKING, Any

import numpy as np

from ..feasibility.convex import ConsistentResult
from ..feasibility.penalty import RetrievalResult
from ..feasibility.result import FeasibleResult
from ..friction.validation import NewtonEulerValidation
from .layout import tight_layout
from .style import COLOURS

if TYPE_CHECKING:  # pragma: no cover
    from matplotlib.axes import Axes
    from matplotlib.figure import Figure

__all__ = ["plot_consistent", "plot_newton_euler_validation", "plot_retrieval"]


def _stride(N: int, max_points: int) -> slice:
    return slice(None, None, max(1, int(np.ceil(N / max_points))))


def plot_newton_euler_validation(
    validation: NewtonEulerValidation,
    *,
    joint_names: Sequence[str] | None = None,
    max_points: int = 4000,
    ncols: int = 2,
    title: str | None = None,
    fig: Figure | None = None,
) -> Figure:
    """Measured against Newton-Euler torques per joint (Gaz et al. 2019, Fig. 5).

    Parameters
    ----------
    validation : NewtonEulerValidation
        From :func:`dynid.friction.validation.validate_newton_euler`.
    joint_names : sequence of str, optional
        Panel titles (default ``validation.joint_names``).
    max_points : int
        Samples drawn per line (evenly strided; the RMS uses every sample).
    ncols : int
        Panels per row.
    title : str, optional
    fig : Figure, optional
        Drawn into (cleared first); a new figure by default.

    Returns
    -------
    matplotlib.figure.Figure
        One panel per joint: time from the log's first sample [s] on x, torque [N m] on
        y; the RMS error of each prediction in the panel title.
    """
    import matplotlib.pyplot as plt

    v = validation
    n = v.tau.shape[1]
    names = list(joint_names) if joint_names is not None else list(v.joint_names)
    nrows = int(np.ceil(n / ncols))
    if fig is None:
        fig = plt.figure(figsize=(5.0 * ncols, 2.1 * nrows + 0.6))
    else:
        fig.clear()
    axes: list[Axes] = list(fig.subplots(nrows, ncols, sharex=True, squeeze=False).ravel())
    s = _stride(v.t.shape[0], max_points)
    t = v.t[s] - v.t[0]  # from the log's start (a log of absolute stamps too)
    label_ne = "Newton-Euler, feasible p" + (" + friction" if v.tau_friction is not None else "")
    for j in range(n):
        ax = axes[j]
        ax.plot(t, v.tau[s, j], color=COLOURS["measured"], lw=0.6, label="measured")
        ax.plot(t, v.tau_model[s, j], color=COLOURS["consistent"], lw=1.0, label=label_ne)
        parts = [f"NE {v.errors.rms[j]:.3g}"]
        if v.tau_reference is not None and v.errors_reference is not None:
            ax.plot(
                t,
                v.tau_reference[s, j],
                color=COLOURS["model"],
                lw=0.9,
                ls="--",
                label="identified model",
            )
            parts.append(f"identified {v.errors_reference.rms[j]:.3g}")
        ax.set_title(f"{names[j]}: RMS [N m] " + ", ".join(parts), fontsize=8)
        ax.set_ylabel("torque [N m]", fontsize=8)
        ax.tick_params(labelsize=7)
        ax.grid(True, lw=0.3)
    for j in range(n):  # x labels on the lowest panel of every column
        if j + ncols >= n:
            axes[j].set_xlabel("time from the log's start [s]", fontsize=8)
            axes[j].tick_params(labelbottom=True)
    handles, labels = axes[0].get_legend_handles_labels()
    if n < len(axes):  # an empty slot holds the legend
        for ax in axes[n + 1 :]:
            ax.set_visible(False)
        axes[n].axis("off")
        axes[n].legend(handles, labels, loc="center", fontsize=9, frameon=False)
        top = 0.96
    else:
        fig.legend(
            handles,
            labels,
            loc="upper center",
            ncol=len(labels),
            fontsize=8,
            frameon=False,
            bbox_to_anchor=(0.5, 0.96),
        )
        top = 0.93
    fig.suptitle(title or "Validation of the feasible parameters (Newton-Euler)", fontsize=10)
    tight_layout(fig, rect=(0, 0, 1, top))
    return fig


def plot_retrieval(
    result: RetrievalResult, *, title: str | None = None, fig: Figure | None = None
) -> Figure:
    """Stage objectives of every run and the physical constraint margins per link.

    Parameters
    ----------
    result : RetrievalResult
    title : str, optional
    fig : Figure, optional
        Drawn into (cleared first); a new figure by default.

    Returns
    -------
    matplotlib.figure.Figure
        Left: stage objective ``F_k`` (log scale) against the stage, one line per run
        (the kept run bold, infeasible runs dotted). Right: per link, the margins of the
        triangle inequality and of positive definiteness [kg m^2] (log scale; violated
        constraints drawn in red at their absolute value).
    """
    import matplotlib.pyplot as plt

    if fig is None:
        fig = plt.figure(figsize=(10.0, 3.8))
    else:
        fig.clear()
    ax1, ax2 = fig.subplots(1, 2)
    floor = 1e-300
    for run in result.runs:
        k = np.arange(1, len(run.stage_costs) + 1)
        best = run.index == result.best_run
        ax1.semilogy(
            k,
            np.maximum(run.stage_costs, floor),
            lw=2.0 if best else 0.8,
            ls="-" if run.feasible else ":",
            color="tab:blue" if best else "0.5",
            marker="o" if best else None,
            ms=3,
        )
    ax1.set_xticks(np.arange(1, len(result.stage_costs) + 1))
    ax1.set_xlabel("stage k")
    ax1.set_ylabel("stage objective F_k")
    ax1.set_title(
        f"{len(result.runs)} runs, {result.n_feasible_runs} feasible; kept run {result.best_run}",
        fontsize=9,
    )
    ax1.grid(True, lw=0.3)
    names = ("triangle_inequality", "inertia_positive_definite")
    n = result.mass.shape[0]
    width = 0.38
    for off, name, color in (
        (-width / 2, names[0], "tab:blue"),
        (width / 2, names[1], "tab:green"),
    ):
        cons = result.report.select(name)
        m = np.array([c.margin for c in cons])
        ok = np.array([c.satisfied for c in cons])
        x = np.array([c.link for c in cons], dtype=float) + off
        ax2.bar(
            x[ok],
            np.maximum(np.abs(m[ok]), floor),
            width,
            color=color,
            label=name.replace("_", " "),
        )
        if (~ok).any():
            ax2.bar(x[~ok], np.abs(m[~ok]), width, color="tab:red", label=f"{name} (violated)")
    ax2.set_yscale("log")
    all_m = np.abs([c.margin for name in names for c in result.report.select(name)])
    pos = all_m[all_m > 0]
    if pos.size:
        ax2.set_ylim(pos.min() / 3.0, pos.max() * 3.0)
    ax2.set_xticks(np.arange(1, n + 1))
    ax2.set_xlabel("link")
    ax2.set_ylabel("margin [kg m^2]")
    ax2.set_title(f"relative residual {result.relative_residual:.2e}", fontsize=9)
    ax2.legend(fontsize=7)
    ax2.grid(True, axis="y", lw=0.3)
    fig.suptitle(title or "Feasible-parameter retrieval", fontsize=10)
    tight_layout(fig)
    return fig


def plot_consistent(
    results: Sequence[FeasibleResult],
    *,
    labels: Sequence[str] | None = None,
    truth: Any = None,
    fig: Figure | None = None,
) -> Figure:
    """Masses and pseudo-inertia margins per link of one or more parameter sets.

    Left: link masses [kg] of each result (bars), the prior's (of the first convex result,
    open markers) and ``truth``'s (a Robot, crosses) when given. Right: the margin
    ``lambda_min(J)/tr(J)`` of each link's pseudo-inertia (log scale), with the convex
    method's margin as a dashed line; a link whose margin is not positive (not physically
    consistent), which a log scale cannot show, is a hatched red bar over the whole height,
    named in the legend and the title only when there is one.

    Parameters
    ----------
    results : sequence of FeasibleResult
        :class:`~dynid.feasibility.convex.result.ConsistentResult` or
        :class:`~dynid.feasibility.penalty.result.RetrievalResult`.
    labels : sequence of str, optional
        Legend entries (default the results' ``method``).
    truth : Robot, optional
    """
    import matplotlib.pyplot as plt

    if fig is None:
        fig = plt.figure(figsize=(11, 4))
    ax1, ax2 = fig.subplots(1, 2)
    names = labels or [r.method for r in results]
    n = results[0].robot.n
    x = np.arange(1, n + 1)
    w = 0.8 / len(results)
    floor = 1e-7
    inconsistent = False
    for k, (res, name) in enumerate(zip(results, names, strict=True)):
        off = (k - (len(results) - 1) / 2) * w
        colour = f"C{k}" if k < 3 else f"C{k + 1}"  # C3 is red: kept for the inconsistent
        ax1.bar(x + off, res.robot.mass, width=w, label=name, color=colour)
        mg = np.asarray(res.pseudo_inertia_margin, dtype=float)
        ok = mg > 0
        ax2.bar(x[ok] + off, mg[ok], width=w, label=name, color=colour)
        if np.any(~ok):  # the whole height: a log scale has no place for margins <= 0
            ax2.bar(
                x[~ok] + off,
                np.full(int((~ok).sum()), 1.0 - floor / 2),
                bottom=floor / 2,
                width=w,
                color="tab:red",
                alpha=0.5,
                hatch="//",
                edgecolor=colour,
                label=None if inconsistent else "not physically consistent (margin <= 0)",
            )
            inconsistent = True
    convex = [r for r in results if isinstance(r, ConsistentResult)]  # a prior, a margin
    prior = convex[0].prior if convex else None
    if prior is not None:
        ax1.plot(x, prior.mass, "o", mfc="none", mec="k", label=f"prior ({prior.source})")
    if truth is not None:
        ax1.plot(x, truth.mass, "kx", ms=8, label="truth")
    eps = convex[0].options.margin if convex else None
    if eps is not None:
        ax2.axhline(eps, ls="--", color="k", lw=0.8, label=f"margin {eps:g}")
    ax1.set_xlabel("link")
    ax1.set_ylabel("mass [kg]")
    ax1.set_xticks(x)
    ax1.set_ylim(top=1.25 * ax1.get_ylim()[1])
    ax1.legend(fontsize=8, loc="upper right", ncol=2)
    ax2.set_yscale("log")
    ax2.set_ylim(floor / 2, 1.0)
    ax2.set_xlabel("link")
    ax2.set_ylabel("lambda_min(J) / tr(J)")
    ax2.set_xticks(x)
    ax2.legend(fontsize=8, loc="upper right", ncol=2)
    title = "pseudo-inertia margin per link"
    ax2.set_title(title + (" (red: not physically consistent)" if inconsistent else ""), fontsize=9)
    tight_layout(fig)
    return fig
