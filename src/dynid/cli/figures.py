"""The figures the commands write (skipped with a note when they cannot be drawn, see
:func:`~dynid.cli.common.save_figure`): retrieval, friction fit, torque validation.

The plotting modules are called through their module (``feasible_plots.plot_consistent``)
so that a test can replace a plotting function."""

from __future__ import annotations

from pathlib import Path
from typing import Any

from ..feasibility.sdp import ConsistentResult
from ..friction.fit import FrictionFit, FrictionResidual
from ..friction.validation import Validation
from ..io.observer_files import observation_names
from ..observer.detection import threshold_series
from ..observer.results import ObserveResult
from ..plots import feasible as feasible_plots
from ..plots import friction as friction_plots
from ..plots import observer as observer_plots
from ..plots import torques as torque_plots
from .common import save_figure

__all__ = [
    "save_friction_figure",
    "save_observer_figures",
    "save_retrieval_figure",
    "save_validation_figures",
]


def save_retrieval_figure(folder: Path, result: Any) -> list[Path]:
    """``folder/retrieval.png`` of a retrieval or consistent fit (none if skipped)."""
    fig = save_figure(
        lambda: (
            feasible_plots.plot_consistent([result])
            if isinstance(result, ConsistentResult)
            else feasible_plots.plot_retrieval(result)
        ),
        Path(folder) / "retrieval.png",
    )
    return [] if fig is None else [fig]


def save_friction_figure(
    path: Path, residual: FrictionResidual, fit: FrictionFit, *, names: list[str], **kw: Any
) -> Path | None:
    """Write the residual-vs-velocity figure (Fig. 4) to ``path`` (None: skipped)."""
    return save_figure(
        lambda: friction_plots.plot_friction_fit(residual, fit, joint_names=names, **kw), path
    )


def save_validation_figures(
    out: Path,
    validation: Validation,
    *,
    names: list[str],
    prefix: str = "validation",
    noise_std: float | None = None,
    title: str | None = None,
) -> list[Path]:
    """Write ``<prefix>_torques.png`` (Fig. 3) and ``<prefix>_rms.png`` under ``out``
    (those skipped are left out)."""
    rms = {"without friction": validation.without_friction.rms}
    if validation.with_friction is not None:
        rms["with friction"] = validation.with_friction.rms
    paths = [
        save_figure(
            lambda: torque_plots.plot_torque_validation(validation, joint_names=names, title=title),
            out / f"{prefix}_torques.png",
            dpi=100,
        ),
        save_figure(
            lambda: torque_plots.plot_rms_comparison(rms, noise_std=noise_std, title=title),
            out / f"{prefix}_rms.png",
        ),
    ]
    return [p for p in paths if p is not None]


def save_observer_figures(out: Path, result: ObserveResult, *, names: list[str]) -> list[Path]:
    """``out/<residuals name>.png`` of every log: residual, thresholds, events, and the true
    external torques stored beside a simulated log (those skipped are left out)."""
    paths = []
    for x, stem in zip(result.logs, observation_names(result.logs), strict=True):
        contact, collision = threshold_series(result.thresholds, x.t.shape[0], x.std)

        def draw(x: Any = x, c: Any = contact, k: Any = collision) -> Any:
            return observer_plots.plot_residuals(
                x.t, x.r, c, k, events=x.events, tau_ext=x.tau_ext, joint_names=names,
                title=f"momentum observer on {x.path.name}: residual, thresholds, events",
            )  # fmt: skip

        fig = save_figure(draw, Path(out) / f"{stem}.png")
        if fig is not None:
            paths.append(fig)
    return paths
