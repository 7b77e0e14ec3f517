"""What the demo (``dynid demo``) prints and writes per stage, and the paper's numbers.

Each stage of :func:`dynid.pipeline.run_demo` has a ``format_*`` (the printed text) and a
``save_*`` (its files under the stage's folder, returned); :func:`save_paper_comparison`
writes ``paper.json``, dynid's results beside the published ones, which the run's
``report.html`` opens with.
"""

from __future__ import annotations

from pathlib import Path

import numpy as np

from ..io.feasible import save_feasible_json
from ..io.feasible_bundle import save_feasible_bundle
from ..io.friction_json import save_friction_json
from ..io.json_files import save_json
from ..io.model_json import save_model_json
from ..io.report_json import save_report_json
from ..io.static_data import save_static_data
from ..io.validation_json import save_validation_json
from ..model.robot import Robot
from ..pipeline import (
    ConsistentSetup,
    ConsistentStageResult,
    DemoResult,
    KinematicsStageResult,
)
from ..pipeline.paper import paper_comparison
from ..pipeline.stages import FeasibleStageResult, FrictionStageResult, IdentificationStageResult
from ..plots.feasible import plot_consistent, plot_newton_euler_validation
from ..plots.kinematics import plot_ik_path
from .common import format_joint_table, format_matrix, save_figure
from .figures import save_friction_figure, save_retrieval_figure, save_validation_figures
from .summaries import (
    format_identification,
    format_newton_euler_rms,
    format_retrieval,
    format_rms_table,
)


# ---------------------------------------------------------------------- stage 1
def format_kinematics(robot: Robot, res: KinematicsStageResult) -> str:
    """The printed lines of stage 1: pose, flange pose, Jacobian, IK goal and solution."""
    ik = res.ik
    status = "converged" if ik.converged else "did NOT converge"
    return "\n".join(
        [
            f"neutral pose PANDA_NEUTRAL_Q:\n{format_joint_table(robot, res.q)}",
            f"flange pose T_base_flange [m]:\n{format_matrix(res.T_base_flange)}",
            f"  roll, pitch, yaw [rad]: {format_matrix(res.rpy)}",
            "flange Jacobian, base frame (rows vx vy vz [m/rad], wx wy wz [rad/rad]):",
            format_matrix(res.J),
            f"IK goal for a tool at {res.tool_xyz} m in the flange, T_base_tool [m]:",
            format_matrix(res.T_base_tool_goal),
            f"IK {status} in {ik.iterations} steps of {res.options.dt} s ({ik.restarts} "
            f"restarts): position error {ik.position_error:.2e} m, "
            f"orientation error {ik.orientation_error:.2e} rad",
            f"solution q:\n{format_joint_table(robot, ik.q)}",
        ]
    )


def save_kinematics(out: Path, robot: Robot, res: KinematicsStageResult) -> list[Path]:
    """``out/ik_joint_motion.png``: the simulated joint motion of the IK solve."""
    path = save_figure(
        lambda: plot_ik_path(
            res.ik.path,
            joint_names=robot.joint_names,
            dt=res.options.dt,
            title="Inverse kinematics: simulated joint motion (tool 0.1 m along flange z)",
        ),
        out / "ik_joint_motion.png",
        dpi=120,
    )
    return [] if path is None else [path]


# ---------------------------------------------------------------------- stage 2
def save_identification_stage(out_dir: Path, res: IdentificationStageResult) -> list[Path]:
    """Write the demo's identification stage: ``out_dir/static.csv`` (the data) and
    ``out_dir/identification.json`` (the model, with the seed); returns the two paths."""
    out_dir = Path(out_dir)
    return [
        save_static_data(out_dir / "static.csv", res.data),
        save_model_json(out_dir / "identification.json", res.model, seed=res.seed),
    ]


def format_identification_stage(res: IdentificationStageResult) -> str:
    """The demo's identification stage: the summary table and the errors to the truth."""
    return "\n".join(
        [
            format_identification(res.model),
            f"  rank {res.rank}, condition number {res.condition_number:.3g}, "
            f"relative error {res.relative_error_percent:.3g} %, dropped rows "
            f"{res.dropped_rows}; largest coefficient error {res.max_abs_error:.2e} "
            f"({res.max_error_in_std:.2f} std)",
        ]
    )


# ---------------------------------------------------------------------- stage 3
def save_friction_stage(out_dir: Path, res: FrictionStageResult) -> list[Path]:
    """Write the demo's friction stage under ``out_dir``: ``friction.json``,
    ``validation.json``, ``friction.png`` and the validation figures; returns the paths."""
    out_dir = Path(out_dir)
    names = list(res.truth.joint_names)
    save_friction_json(
        out_dir / "friction.json", res.fit, metadata={"seed": res.seed, "source": "demo, sinusoids"}
    )
    save_validation_json(out_dir / "validation.json", res.validation, seed=res.seed)
    files: list[Path | None] = [out_dir / "friction.json", out_dir / "validation.json"]
    files.append(
        save_friction_figure(
            out_dir / "friction.png",
            res.residual,
            res.fit,
            names=names,
            reference=res.reference_friction,
            reference_label="true (published) friction",
            title="sigmoid friction fitted to the residual of the identified model",
        )
    )
    files += save_validation_figures(
        out_dir,
        res.validation,
        names=names,
        noise_std=float(np.max(res.noise.tau_std)),  # one level for every joint: the largest
        title="validation on the sinusoids of Gaz et al. 2019 (eq. 31)",
    )
    return [f for f in files if f is not None]


def format_friction_stage(res: FrictionStageResult) -> str:
    """The demo's friction stage: the limit note (if the sinusoids were scaled), the
    per-joint RMS without and with friction, the relative errors."""
    lines = []
    if not res.limits.ok:
        lines.append(f"the sinusoids of Table I as published exceed the limits:\n{res.limits}")
        lines.append(
            f"amplitudes scaled by {res.scale:.4f}: the scaled motion is within the limits "
            "at every sample"
            if res.scaled_limits.ok
            else f"amplitudes scaled by {res.scale:.4f}; still exceeded:\n{res.scaled_limits}"
        )
    lines.append(
        "friction fitted on the sinusoids' first log, validated on the next (the motion "
        "continued: each joint's sinusoid at another phase, states the fit did not see)"
    )
    names = list(res.truth.joint_names)
    lines.append(
        format_rms_table(
            names,
            {
                "RMS no friction [N m]": res.rms_without_friction,
                "RMS + friction [N m]": res.rms_with_friction,
            },
        )
    )
    lines.append(
        f"relative error: {res.relative_error_percent_without:.2f} % without friction, "
        f"{res.relative_error_percent_with:.2f} % with (sensor noise {res.noise.tau_std} N m)"
    )
    return "\n".join(lines)


# ---------------------------------------------------------------------- stage 4
def save_feasible_stage(out_dir: Path, res: FeasibleStageResult) -> list[Path]:
    """Write the demo's feasible stage under ``out_dir``: the files of
    :func:`~dynid.io.feasible_bundle.save_feasible_bundle` (with the seed), retrieval.png,
    ``feasible_validation.json`` and ``feasible_validation.png``."""
    out_dir = Path(out_dir)
    files = save_feasible_bundle(out_dir, res.retrieval, seed=res.seed)
    files += save_retrieval_figure(out_dir, res.retrieval)
    doc = res.validation.as_dict() | {"seed": res.seed}
    files.append(save_json(out_dir / "feasible_validation.json", doc))
    fig = save_figure(
        lambda: plot_newton_euler_validation(
            res.validation,
            title="Newton-Euler with the retrieved feasible parameters (validation trajectory)",
        ),
        out_dir / "feasible_validation.png",
    )
    return files + ([fig] if fig is not None else [])


def format_feasible_stage(res: FeasibleStageResult) -> str:
    """The demo's feasible stage: the retrieval summary, the Newton-Euler RMS table and the
    largest difference to the identified model."""
    return "\n".join(
        [
            format_retrieval(res.retrieval),
            format_newton_euler_rms(res.validation),
            "max |NE(feasible) - identified model| on the validation states: "
            f"{res.max_torque_difference:.3g} N m",
        ]
    )


# ---------------------------------------------------------------------- stage 5
def format_consistent_setup(setup: ConsistentSetup) -> str:
    """The line that describes stage 5's simulated truth."""
    e = setup.effects
    return (
        "truth: the published Panda with every parameter scaled by up to +-20 %; rotor inertia "
        + " ".join(f"{x:.3f}" for x in e.rotor_inertia)
        + f" kg m^2, gravity tilted {np.degrees(e.gravity_tilt):.2f} deg"
    )


def format_consistent_stage(res: ConsistentStageResult) -> str:
    """Stage 5's comparison table and the convex method's notes."""
    table = [
        f"{'method':<16} {'consistent':>10} {'residual':>9} {'min J margin':>12} "
        f"{'lightest [kg]':>13} {'mass err truth':>14} {'dist. prior':>11} {'time [s]':>8}"
    ]
    for r in res.rows:
        table.append(
            f"{r.name:<16} {str(r.feasible):>10} {r.relative_residual:>9.2e} "
            f"{r.min_margin['pseudo_inertia']:>12.2e} {r.lightest_link:>13.3f} "
            f"{100 * (r.mass_error_truth or 0):>13.1f}% {100 * r.mass_distance_prior:>10.1f}% "
            f"{r.time:>8.2f}"
        )
    table.append(
        f"{'prior itself':<16} {'':>10} {'':>9} {'':>12} {'':>13} "
        f"{100 * res.prior_mass_error_truth:>13.1f}%"
    )
    table.append(rotor_line(res))
    table += [f"  note: {note}" for note in res.notes]
    return "\n".join(table)


def rotor_line(res: ConsistentStageResult) -> str:
    """The rotor inertias the convex method identified, against the truth."""
    ia = res.rows[0].result.rotor_inertia
    if ia is None:
        return "rotor inertia: not identified"
    return (
        "rotor inertia identified with the links (convex, >= 0) [kg m^2]: "
        + " ".join(f"{x:.3f}" for x in ia)
        + "; truth "
        + " ".join(f"{x:.3f}" for x in res.effects.rotor_inertia)
        + " (joint 1's regroups with J1zz: the prior splits it)"
    )


def save_consistent(out: Path, res: ConsistentStageResult) -> list[Path]:
    """``feasible.json``, ``report.json`` (convex method), ``comparison.json`` and
    ``comparison.png`` under ``out``."""
    sdp = res.rows[0].result
    files = [
        save_feasible_json(out / "feasible.json", sdp),
        save_report_json(out / "report.json", sdp, seed=res.seed),
    ]
    doc = {"seed": res.seed, "methods": [r.as_dict() for r in res.rows]}
    files.append(save_json(out / "comparison.json", doc))
    fig = save_figure(
        lambda: plot_consistent(
            [r.result for r in res.rows], labels=[r.name for r in res.rows], truth=res.truth
        ),
        out / "comparison.png",
        dpi=120,
    )
    return files + ([] if fig is None else [fig])


# ---------------------------------------------------------------------- the paper
def save_paper_comparison(out: Path, demo: DemoResult) -> Path:
    """``out/paper.json``: dynid's results beside the paper's published values
    (:func:`dynid.pipeline.paper.paper_comparison`), which report.html opens with."""
    doc = {"seed": demo.seed, **paper_comparison(demo)}
    return save_json(Path(out) / "paper.json", doc, schema="dynid-paper-comparison/1")
