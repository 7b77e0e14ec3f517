"""The figures the commands write (skipped with a note when they cannot be drawn, see
:func:`~dynid.cli.common.save_figure`): retrieval, friction fit, torque validation, the
identification's torques on held-out data (predicted by the library, drawn here).

The plotting modules are called through their module (``feasible_plots.plot_consistent``)
so that a test can replace a plotting function."""

from __future__ import annotations

from pathlib import Path
from typing import Any

from ..feasibility.convex import ConsistentResult
from ..friction.fit import FrictionFit, FrictionResidual
from ..friction.heldout_torques import HeldOutTorques
from ..friction.validation import Validation
from ..identification.static_validation import StaticValidation
from ..io.observer_files import log_labels, observation_names
from ..observer.detection import threshold_series
from ..observer.results import ObserveResult
from ..plots import feasible as feasible_plots
from ..plots import friction as friction_plots
from ..plots import identification as identification_plots
from ..plots import observer as observer_plots
from ..plots import static_check as static_plots
from ..plots import torques as torque_plots
from .common import save_figure

__all__ = [
    "save_friction_figure",
    "save_heldout_figures",
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


def save_static_validation_figure(
    out: Path, result: StaticValidation, *, names: list[str], title: str | None = None
) -> list[Path]:
    """Write ``validation_static.png`` under ``out`` (skipped without matplotlib)."""
    path = save_figure(
        lambda: static_plots.plot_static_validation(result, joint_names=names, title=title),
        out / "validation_static.png",
    )
    return [] if path is None else [path]


def save_validation_figures(
    out: Path,
    validation: Validation,
    *,
    names: list[str],
    prefix: str = "validation",
    noise_std: float | None = None,
    title: str | None = None,
    t0: float | None = None,
    recordings: list[tuple[str, float, float]] | tuple[tuple[str, float, float], ...] = (),
) -> list[Path]:
    """Write ``<prefix>_torques.png`` (Fig. 3) and ``<prefix>_rms.png`` under ``out``
    (those skipped are left out); time drawn from ``t0`` [s] (default: the first sample),
    or, of several ``recordings`` (name, first and last stamp [s]) pooled in
    ``validation``, each from its own start."""
    paths = [
        save_figure(
            lambda: torque_plots.plot_torque_validation(
                validation, joint_names=names, title=title, t0=t0, recordings=recordings
            ),
            out / f"{prefix}_torques.png",
            dpi=100,
        ),
        save_figure(
            lambda: torque_plots.plot_validation_rms(
                validation, joint_names=names, noise_std=noise_std, title=title
            ),
            out / f"{prefix}_rms.png",
        ),
    ]
    return [p for p in paths if p is not None]


def save_heldout_figures(
    out: Path, held: HeldOutTorques, recordings: list[str] | tuple[str, ...] = ()
) -> list[Path]:
    """The held-out prediction of a torque log's identification (made by the library,
    :attr:`~dynid.workflows.identify.IdentifyResult.heldout`) drawn under ``out``:
    ``heldout_torques.png`` (measured and predicted torques; each of several held-out
    recordings from its own start, named by ``recordings``, the file names in the fit's
    order) and ``heldout_residuals.png`` (residual histograms against the sensor noise);
    those skipped are left out."""
    names = list(held.joint_names)
    spans = (
        [(r, float(x.t[0]), float(x.t[-1])) for r, x in zip(recordings, held.logs, strict=True)]
        if len(held.logs) > 1 and len(recordings) == len(held.logs)
        else []
    )
    paths = [
        save_figure(
            lambda: torque_plots.plot_torque_validation(
                held.validation,
                joint_names=names,
                title=f"Held-out: {held.block}",
                t0=float(held.logs[0].t[0]) if held.logs else None,
                recordings=spans,
            ),
            Path(out) / "heldout_torques.png",
            dpi=100,
        ),
        save_figure(
            lambda: identification_plots.plot_residual_histograms(held),
            Path(out) / "heldout_residuals.png",
        ),
    ]
    return [p for p in paths if p is not None]


def save_observer_figures(out: Path, result: ObserveResult, *, names: list[str]) -> list[Path]:
    """``out/<residuals name>.png`` of every log: residual, thresholds, events, and the true
    external torques stored beside a simulated log (those skipped are left out). Everything
    a figure computes is done inside :func:`~dynid.cli.common.save_figure`, so that a
    figure that fails is skipped with a note and never fails the command."""
    paths = []
    labels = log_labels([x.path for x in result.logs])
    for x, stem, label in zip(result.logs, observation_names(result.logs), labels, strict=True):
        if x.figure is None and x.r is None:  # a calibration that kept no series
            continue

        def draw(x: Any = x, lab: str = label) -> Any:
            if x.figure is not None:  # a detection's every k-th sample
                f = x.figure
                t, r, contact, collision, ext = f.t, f.r, f.contact, f.collision, f.tau_ext
            else:  # a calibration's whole series, NaN where not observed
                t, r, ext = x.t, x.r, x.tau_ext
                contact, collision = threshold_series(
                    result.thresholds, t.shape[0], x.std, x.standstill
                )
            return observer_plots.plot_residuals(
                t, r, contact, collision, events=x.events, tau_ext=ext, joint_names=names,
                title=f"momentum observer on {lab}: residual, thresholds, events",
                labelled=() if x.score is None else x.score.intervals,
            )  # fmt: skip

        fig = save_figure(draw, Path(out) / f"{stem}.png")
        if fig is not None:
            paths.append(fig)
    return paths
