"""Evaluate an identified model: M(q), g(q), and c(q, dq), tau(q, dq, ddq) when given.

Reads DIR/identification.json (from `dynid identify`) and evaluates, at one state,
M [kg m^2] and g [N m]; with --dq also c [N m] (Coriolis and centrifugal torques); with
--dq and --ddq also tau = M ddq + c + g [N m] (friction not included). Vectors are
comma-separated, in rad, rad/s, rad/s^2; write --q=-0.1,... when the first value is
negative.

example:
  dynid predict --model result/identification.json --q=0,-0.785,0,-2.356,0,1.571,0.785 --json
"""

from __future__ import annotations

import argparse
from pathlib import Path

from ..exceptions import DynidError
from ..io.model_json import load_model_json
from .common import add_subcommand, format_matrix, parse_vector
from .console import Console

NAME = "predict"


def register(subparsers: argparse._SubParsersAction) -> argparse.ArgumentParser:
    """Add the ``predict`` subcommand."""
    p = add_subcommand(
        subparsers, NAME, __doc__, help="M, g (and c, tau) of an identified model at one state"
    )
    p.add_argument("--model", type=Path, required=True, help="identification.json")
    p.add_argument("--q", required=True, help="joint positions [rad], comma-separated")
    p.add_argument("--dq", default=None, help="joint velocities [rad/s]")
    p.add_argument("--ddq", default=None, help="joint accelerations [rad/s^2] (needs --dq)")
    p.add_argument("--json", action="store_true", help="print one JSON object")
    return p


def run(args: argparse.Namespace, console: Console) -> int:
    """Evaluate and print; returns the exit code."""
    model = load_model_json(args.model)
    n = model.robot.n
    q = parse_vector(args.q, "--q", n)
    out = {"M": model.mass_matrix(q), "g": model.gravity_torques(q)}
    if args.ddq is not None and args.dq is None:
        raise DynidError("--ddq needs --dq (tau = M ddq + c + g)")
    if args.dq is not None:
        dq = parse_vector(args.dq, "--dq", n)
        out["c"] = model.coriolis(q, dq)
        if args.ddq is not None:
            ddq = parse_vector(args.ddq, "--ddq", n)
            out["tau"] = model.torques(q, dq, ddq)
    if args.json:
        console.json(out)
        return 0
    console.print(f"M(q) [kg m^2]:\n{format_matrix(out['M'])}")
    for key, label in (("g", "g(q) [N m]"), ("c", "c(q, dq) [N m]"), ("tau", "tau [N m]")):
        if key in out:
            console.print(f"{label}:\n{format_matrix(out[key])}")
    return 0
