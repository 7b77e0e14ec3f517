"""Evaluate an identified model: M(q), g(q), and c(q, dq), tau(q, dq, ddq) when given.

Reads the identification.json that `dynid identify` writes into its --out folder, or
with --params the feasible link parameters of feasible.json (from `dynid retrieve` or
`identify --consistent`; its drive's rotor inertias included), and evaluates, at one
state, M [kg m^2] and g [N m]; with --dq also c [N m] (Coriolis and centrifugal
torques); with --dq and --ddq also tau = M ddq + c + g [N m] (friction not included).
Vectors are comma-separated, in rad, rad/s, rad/s^2; write --q=-0.1,... when the first
value is negative.

example:
  dynid predict --model result/identification.json --q=0,-0.785,0,-2.356,0,1.571,0.785 --json
"""

from __future__ import annotations

import argparse
from pathlib import Path

from ..workflows.predict import load_predicting
from .common import add_subcommand, format_matrix, parse_vector
from .console import Console

NAME = "predict"


def register(subparsers: argparse._SubParsersAction) -> argparse.ArgumentParser:
    """Add the ``predict`` subcommand."""
    p = add_subcommand(
        subparsers, NAME, __doc__, help="M, g (and c, tau) of an identified model at one state"
    )
    src = p.add_mutually_exclusive_group(required=True)
    src.add_argument("--model", type=Path, help="identification.json (dynid identify)")
    src.add_argument(
        "--params", type=Path, help="feasible.json (dynid retrieve, identify --consistent)"
    )
    p.add_argument("--q", required=True, help="joint positions [rad], comma-separated")
    p.add_argument("--dq", default=None, help="joint velocities [rad/s]")
    p.add_argument("--ddq", default=None, help="joint accelerations [rad/s^2] (needs --dq)")
    p.add_argument("--json", action="store_true", help="print one JSON object")
    return p


def run(args: argparse.Namespace, console: Console) -> int:
    """Evaluate and print; returns the exit code."""
    model = load_predicting(args.model, args.params)
    q = parse_vector(args.q, "--q", model.n)
    dq = None if args.dq is None else parse_vector(args.dq, "--dq", model.n)
    ddq = None if args.ddq is None else parse_vector(args.ddq, "--ddq", model.n)
    out = model.terms(q, dq, ddq)
    if args.json:
        console.json(out)
        return 0
    console.print(f"M(q) [kg m^2]:\n{format_matrix(out['M'])}")
    for key, label in (("g", "g(q) [N m]"), ("c", "c(q, dq) [N m]"), ("tau", "tau [N m]")):
        if key in out:
            console.print(f"{label}:\n{format_matrix(out[key])}")
    return 0
