"""Run the demonstration pipeline on the built-in Panda and write its results to --out.

Stages (each prints what it does and lists the files it writes):
  1. kinematics  the flange pose and the geometric Jacobian at the neutral pose
                 PANDA_NEUTRAL_Q; one inverse-kinematics solve for a tool 0.1 m along z
                 of the flange, to a goal drawn from --seed near the neutral pose; a plot
                 of the simulated joint motion (ik_joint_motion.png).

  2. identification  1010 static configurations from the simulated controller (M(q), g(q)
                 with relative noise), the 43 base parameters by least squares, summary
                 table (identification/).
  3. friction    validation of the identified model on the paper's sinusoids, sigmoid
                 friction fit per joint, validation with friction; per-joint RMS before and
                 after, figures (friction/).
  4. feasible    feasible link parameters from the coefficients (penalty-based global
                 optimisation), URDF/TOML/JSON export, Newton-Euler validation (feasible/).
  5. consistent  beyond the paper: a simulated Panda whose parameters differ from the
                 published ones by up to 20 %, with rotor inertia and a gravity tilt that
                 no rigid body reproduces; its coefficients identified as in stage 2, then
                 the convex (LMI) retrieval with the published set as prior against the
                 penalty method (without and with that prior): residual, margins, distance
                 to the truth and to the prior, time (consistent/).

Finally report.md gathers the tables and figures.

Runs headless (figures are rendered with Agg); the first run also compiles the numba
kernels (cached on disk for later runs).

Example:
  dynid demo --out out --seed 0
"""

from __future__ import annotations

import argparse
import sys
import time
from pathlib import Path
from typing import Any

import numpy as np

from ..feasibility.retrieve import RetrievalProgress
from ..io.atomic import write_text
from ..io.json_files import save_json
from ..model.panda import panda
from ..model.robot import Robot
from ..pipeline import (
    ConsistentSetup,
    ConsistentStageResult,
    DemoResult,
    KinematicsStageResult,
    StageFinished,
    StageStarted,
    run_demo,
)
from .common import (
    add_seed_option,
    add_subcommand,
    format_joint_table,
    format_matrix,
    save_figure,
)

NAME = "demo"
#: ``--out`` is a folder: its files are one output set (:mod:`dynid.io.run_output`).
OUTPUT = "folder"


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
    from ..plots.kinematics import plot_ik_path

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


# ---------------------------------------------------------------------- stage 5
def format_consistent_setup(setup: ConsistentSetup) -> str:
    """The line that describes stage 5's simulated truth."""
    e = setup.effects
    return (
        "truth: the published Panda with every parameter scaled by up to +-20 %; rotor inertia "
        + " ".join(f"{x:.3f}" for x in e.rotor_inertia)
        + f" kg m^2, gravity tilted {np.degrees(e.gravity_tilt):.2f} deg"
    )


def format_consistent(res: ConsistentStageResult) -> str:
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
    from ..io.feasible import save_feasible_json, save_report_json
    from ..plots.feasible import plot_consistent

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


# ---------------------------------------------------------------------- report
def _table(header: list[str], rows: list[list[str]]) -> str:
    lines = ["| " + " | ".join(header) + " |", "|" + "---|" * len(header)]
    return "\n".join(lines + ["| " + " | ".join(r) + " |" for r in rows])


def write_report(out: Path, demo: DemoResult, files: list[Path]) -> Path:
    """``out/report.md``: the tables and figures of every stage, with links to the files
    (``files``: those written by the stages)."""
    from .. import __version__

    names = demo.robot.joint_names
    ik = demo.kinematics.ik
    parts = [
        "# dynid demo: the paper on the simulated Panda",
        f"dynid {__version__}, seed {demo.seed}. Gaz et al., IEEE RA-L 4(4), 2019.",
        "## 1. Kinematics",
        f"IK with a tool 0.1 m along the flange z: converged {ik.converged} in "
        f"{ik.iterations} steps, position error {ik.position_error:.2e} m, "
        f"orientation error {ik.orientation_error:.2e} rad.",
        "![IK joint motion](ik_joint_motion.png)",
    ]
    i = demo.identification
    parts += [
        "## 2. Identification from M(q) and g(q) at static configurations",
        _table(
            [
                "configurations",
                "rank",
                "condition number",
                "relative error [%]",
                "dropped rows",
                "largest error / std",
            ],
            [
                [
                    str(i.n_configurations),
                    str(i.rank),
                    f"{i.condition_number:.3g}",
                    f"{i.relative_error_percent:.3g}",
                    ", ".join(i.dropped_rows),
                    f"{i.max_error_in_std:.2f}",
                ]
            ],
        ),
        "Coefficients, expressions and standard deviations: "
        "[identification/identification.json](identification/identification.json).",
    ]
    f = demo.friction
    rows = [
        [n, f"{a:.4f}", f"{b:.4f}"]
        for n, a, b in zip(names, f.rms_without_friction, f.rms_with_friction, strict=True)
    ]
    parts += [
        "## 3. Validation on sinusoids and joint friction",
        _table(["joint", "RMS without friction [N m]", "RMS with friction [N m]"], rows),
        f"Relative error {f.relative_error_percent_without:.3g} % without friction, "
        f"{f.relative_error_percent_with:.3g} % with.",
        "![torques](friction/validation_torques.png)",
        "![friction](friction/friction.png)",
    ]
    e = demo.feasible
    r4 = e.retrieval
    rows = [[n, f"{a:.4f}"] for n, a in zip(names, e.rms_newton_euler, strict=True)]
    parts += [
        "## 4. Feasible link parameters and Newton-Euler validation",
        f"Feasible: {e.feasible}; relative residual on the coefficients "
        f"{e.relative_residual:.2e}; total mass {e.total_mass:.3f} kg; "
        f"{float(r4.run_time):.1f} s on {int(r4.workers)} worker(s). Smallest margins: "
        + ", ".join(f"{k} {v:.2e}" for k, v in e.min_margin.items())
        + ".",
        _table(["joint", "RMS Newton-Euler + friction [N m]"], rows),
        "Files: [feasible.json](feasible/feasible.json), [robot.urdf](feasible/robot.urdf), "
        "[robot.toml](feasible/robot.toml), [report.json](feasible/report.json).",
    ]
    parts += [
        f"![{p.stem}](feasible/{p.name})"
        for p in sorted(files)
        if p.parent.name == "feasible" and p.suffix == ".png"
    ]
    c = demo.consistent
    rows5 = [
        [
            m["method"],
            str(m["feasible"]),
            f"{m['relative_residual']:.2e}",
            f"{m['min_margin']['pseudo_inertia']:.2e}",
            f"{m['min_margin']['triangle_inequality']:.2e}",
            f"{m['lightest_link_kg']:.3f}",
            f"{100 * m['median_mass_error_truth']:.1f}",
            f"{100 * m['median_mass_distance_prior']:.1f}",
            f"{m['time_s']:.2f}",
        ]
        for m in (row.as_dict() for row in c.rows)
    ]
    parts += [
        "## 5. Physically consistent parameters: convex (LMI) and penalty methods",
        "A simulated Panda whose parameters differ from the published ones by up to 20 %, "
        "with rotor inertia on the diagonal of M and a tilted gravity (no rigid body "
        "reproduces its coefficients exactly); 1010 static configurations, 1e-4 noise. "
        "Prior: the published parameters.",
        _table(
            [
                "method",
                "consistent",
                "residual on beta",
                "min lambda(J)/tr(J)",
                "min triangle [kg m^2]",
                "lightest link [kg]",
                "median mass error vs truth [%]",
                "median mass distance to prior [%]",
                "time [s]",
            ],
            rows5,
        ),
        f"The prior itself is {100 * c.prior_mass_error_truth:.1f} % off the true masses "
        "(median over links 2-7).",
        "The rotor inertias are model terms identified with the links (the controller's M "
        "holds them): " + rotor_line(c) + ". The penalty method fits the links alone.",
        "Notes of the convex method: " + "; ".join(c.notes),
        "![comparison](consistent/comparison.png)",
    ]
    return write_text(out / "report.md", "\n\n".join(parts) + "\n")


class _Renderer:
    """The ``progress`` callback of :func:`~dynid.pipeline.run_demo`: prints each stage and
    writes its files as soon as it finishes."""

    def __init__(self, out: Path, robot: Robot) -> None:
        from .retrieve import progress_printer

        self.out, self.robot = out, robot
        self.files: list[Path] = []
        self.started = time.perf_counter()
        self._runs = progress_printer(sys.stdout)

    def _record(self, paths: list[Path]) -> None:
        """Record the files written; name the figures."""
        self.files += paths
        for path in paths:
            if path.suffix == ".png":
                print(f"  wrote {path}")

    def __call__(self, event: Any) -> None:
        if isinstance(event, StageStarted):
            self.started = time.perf_counter()
            print(f"\n== stage {event.number}: {event.title}")
        elif isinstance(event, RetrievalProgress):
            self._runs(event)
        elif isinstance(event, ConsistentSetup):
            print(format_consistent_setup(event))
        elif isinstance(event, StageFinished):
            self.finished(event.number, event.result)

    def finished(self, number: int, res: Any) -> None:
        from . import friction, identify, retrieve

        out = self.out
        if number == 1:
            print(format_kinematics(self.robot, res))
            self._record(save_kinematics(out, self.robot, res))
        elif number == 2:
            self.files += identify.save_demo_stage(out / "identification", res)
            print(identify.format_summary(res.model))
            print(
                f"  rank {res.rank}, condition number {res.condition_number:.3g}, "
                f"relative error {res.relative_error_percent:.3g} %, dropped rows "
                f"{res.dropped_rows}; largest coefficient error {res.max_abs_error:.2e} "
                f"({res.max_error_in_std:.2f} std)"
            )
        elif number == 3:
            self.files += friction.save_demo_stage(out / "friction", res)
            print(friction.format_demo_stage(res))
        elif number == 4:
            files = retrieve.save_demo_stage(out / "feasible", res)
            self.files += files
            print(retrieve.format_demo_stage(res))
            print(
                f"retrieval stage: {time.perf_counter() - self.started:.1f} s; wrote "
                f"{len(files)} files in {out / 'feasible'}"
            )
        elif number == 5:
            print(format_consistent(res))
            self._record(save_consistent(out / "consistent", res))


def register(subparsers: argparse._SubParsersAction) -> argparse.ArgumentParser:
    """Add the ``demo`` subcommand."""
    p = add_subcommand(
        subparsers, NAME, __doc__, help="run the demonstration pipeline on the built-in Panda"
    )
    p.add_argument("--out", type=Path, default=Path("out"), help="output folder (default: out)")
    add_seed_option(p)
    return p


def run(args: argparse.Namespace) -> int:
    """Run every stage in order (:func:`dynid.pipeline.run_demo`), print and save each."""
    robot = panda()
    print(f"dynid demo: {robot!r}, seed {args.seed}, output in {args.out}")
    t0 = time.perf_counter()
    render = _Renderer(args.out, robot)
    demo = run_demo(robot, args.seed, progress=render)
    report = write_report(args.out, demo, render.files)
    render.files.append(report)
    print(f"\nreport: {report} ({time.perf_counter() - t0:.0f} s)")
    print(f"\ndone: {len(render.files)} files in {args.out}")
    return 0
