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
  6. collision   beyond the paper, its future work: the model of stage 2 with the friction
                 of stage 3 runs the momentum observer on two simulated 8 s motions of the
                 Panda; a free one calibrates the thresholds, in the other a push of 15 N
                 on link 6 from 4 s to 4.5 s is searched for: the events found, the delay
                 and the residual's error against the true external torque (printed only).

Finally paper.json sets dynid's results beside the paper's published values (Table III's
43 coefficients with their standard deviations, the friction, the retrieved links, the
validation errors); report.html opens with those tables and the figures.

Runs headless (figures are rendered with Agg); the first run also compiles the numba
kernels (cached on disk for later runs).

Example:
  dynid demo --out out --seed 0
"""

from __future__ import annotations

import argparse
import sys
import time
from collections.abc import Callable
from pathlib import Path
from typing import Any

from ..feasibility.penalty import RetrievalProgress
from ..model.panda import panda
from ..model.robot import Robot
from ..pipeline import ConsistentSetup, StageFinished, StageKind, StageStarted, run_demo
from .common import add_seed_option, add_subcommand, output_path
from .console import Console
from .demo_stages import (
    format_consistent_setup,
    format_consistent_stage,
    format_feasible_stage,
    format_friction_stage,
    format_identification_stage,
    format_kinematics,
    save_consistent,
    save_feasible_stage,
    save_friction_stage,
    save_identification_stage,
    save_kinematics,
    save_paper_comparison,
)
from .summaries import format_collision_stage, progress_printer

NAME = "demo"
#: ``--out`` is a folder: its files are one output set (:mod:`dynid.outputs.run_output`).
OUTPUT = "folder"


class _Renderer:
    """The ``progress`` callback of :func:`~dynid.pipeline.run_demo`: prints each stage and
    writes its files as soon as it finishes."""

    def __init__(self, out: Path, robot: Robot, console: Console) -> None:
        self.out, self.robot, self.console = out, robot, console
        self.files: list[Path] = []
        self.started = time.perf_counter()
        self._runs = None if console.quiet else progress_printer(sys.stdout)

    def _record(self, paths: list[Path]) -> None:
        """Record the files written; name the figures."""
        self.files += paths
        for path in paths:
            if path.suffix == ".png":
                self.console.print(f"  wrote {path}")

    def __call__(self, event: Any) -> None:
        if isinstance(event, StageStarted):
            self.started = time.perf_counter()
            self.console.print(f"\n== stage {event.number}: {event.title}")
        elif isinstance(event, RetrievalProgress):
            if self._runs is not None:
                self._runs(event)
        elif isinstance(event, ConsistentSetup):
            self.console.print(format_consistent_setup(event))
        elif isinstance(event, StageFinished):
            self.finished(event.stage.kind, event.result)

    def finished(self, kind: StageKind, res: Any) -> None:
        """Print the result of the stage of ``kind`` and write its files."""
        _RENDER[kind](self, res)

    def kinematics(self, res: Any) -> None:
        self.console.print(format_kinematics(self.robot, res))
        self._record(save_kinematics(self.out, self.robot, res))

    def identification(self, res: Any) -> None:
        self.files += save_identification_stage(self.out / "identification", res)
        self.console.print(format_identification_stage(res))

    def friction(self, res: Any) -> None:
        self.files += save_friction_stage(self.out / "friction", res)
        self.console.print(format_friction_stage(res))

    def feasible(self, res: Any) -> None:
        files = save_feasible_stage(self.out / "feasible", res)
        self.files += files
        self.console.print(format_feasible_stage(res))
        self.console.print(
            f"retrieval stage: {time.perf_counter() - self.started:.1f} s; wrote "
            f"{len(files)} files in {self.out / 'feasible'}"
        )

    def consistent(self, res: Any) -> None:
        self.console.print(format_consistent_stage(res))
        self._record(save_consistent(self.out / "consistent", res))

    def collision(self, res: Any) -> None:
        self.console.print(format_collision_stage(res))


#: What the demo prints and writes of each kind of stage.
_RENDER: dict[StageKind, Callable[[_Renderer, Any], None]] = {
    "kinematics": _Renderer.kinematics,
    "identification": _Renderer.identification,
    "friction": _Renderer.friction,
    "feasible": _Renderer.feasible,
    "consistent": _Renderer.consistent,
    "collision": _Renderer.collision,
}


def register(subparsers: argparse._SubParsersAction) -> argparse.ArgumentParser:
    """Add the ``demo`` subcommand."""
    p = add_subcommand(
        subparsers, NAME, __doc__, help="run the demonstration pipeline on the built-in Panda"
    )
    p.add_argument(
        "--out", type=output_path, default=Path("out"), help="output folder (default: out)"
    )
    add_seed_option(p)
    return p


def run(args: argparse.Namespace, console: Console) -> int:
    """Run every stage in order (:func:`dynid.pipeline.run_demo`), print and save each."""
    robot = panda()
    console.print(f"dynid demo: {robot!r}, seed {args.seed}, output in {args.out}")
    t0 = time.perf_counter()
    render = _Renderer(args.out, robot, console)
    demo = run_demo(robot, args.seed, progress=render)
    render.files.append(save_paper_comparison(args.out, demo))
    console.print(f"\nthe paper's numbers beside dynid's: {render.files[-1]}")
    console.print(
        f"\ndone in {time.perf_counter() - t0:.0f} s: {len(render.files)} files in {args.out}"
    )
    return 0
