"""Excitation design: the optimiser's gradient against the finite differences it replaced.

The Panda's design at the defaults (20 s, 5 harmonics of 0.075 Hz, 77 variables, the floor,
its self-collision pairs) from a seeded random start. The reference is the gradient
scipy's L-BFGS-B took before: forward differences of the objective evaluated one
variable at a time (78 evaluations, steps of 1e-4). dynid's: the ``cond`` criterion's
chain rule through the samples (:mod:`dynid.simulation.excitation_gradient`), and the
same forward differences evaluated in one batch (``logdet``'s). The answers are checked
first: the batch equals the one-at-a-time differences, the chain rule agrees with both
to their own truncation error.

The last line gives the whole design's time (``optimise_excitation`` at the defaults,
seed 0) with its condition number and iterations.
"""

from __future__ import annotations

import sys
import time
from pathlib import Path

import numpy as np

sys.path.insert(0, str(Path(__file__).resolve().parent))
from common import Case, bench_parser, check_close, measure_pair, report  # noqa: E402

import dynid  # noqa: E402
from dynid.regressors.base import base_parameters  # noqa: E402
from dynid.simulation.collision import Obstacles, capsule_model  # noqa: E402
from dynid.simulation.excitation import (  # noqa: E402
    ExcitationOptions,
    _fd_steps,
    _preferred_rest,
    _Problem,
    optimise_excitation,
)
from dynid.simulation.excitation_gradient import objective_gradient  # noqa: E402


def _problem(robot: dynid.Robot) -> _Problem:
    """The optimisation problem of the default design (the floor as obstacle)."""
    opts = ExcitationOptions().sized_for(robot)
    caps = capsule_model(robot, opts.radii, clearance=opts.self_clearance)
    base = base_parameters(robot, kind="torque")
    return _Problem(robot, opts, Obstacles.floor(), caps, base, _preferred_rest(robot, None))


def one_at_a_time(prob: _Problem, x: np.ndarray) -> np.ndarray:
    """The reference: scipy's forward differences, one evaluation per variable."""
    h = _fd_steps(x)
    f0 = prob.objective(x)
    g = np.empty(len(x))
    for i in range(len(x)):
        xi = x.copy()
        xi[i] = x[i] + h[i]
        g[i] = (prob.objective(xi) - f0) / (xi[i] - x[i])
    return g


def main(argv: list[str] | None = None) -> int:
    args = bench_parser(__doc__).parse_args(argv)
    robot = dynid.panda()
    prob = _problem(robot)
    rng = np.random.default_rng(0)
    x = prob.initial(rng.standard_normal(prob.n * 2 * prob.L), 0.3 * rng.standard_normal(prob.n))

    # --- agreement before timing
    ref = one_at_a_time(prob, x)
    scale = float(np.abs(ref).max())
    check_close(
        "batched forward differences", prob.finite_difference_gradient(x)[1], ref, 1e-6 * scale
    )
    check_close(
        "chain rule (truncation of the 1e-4 steps)",
        objective_gradient(prob, x)[1],
        ref,
        2e-3 * scale,
    )

    kw = dict(min_time=args.min_time, repeats=args.repeats)
    chain, old = measure_pair(
        lambda: objective_gradient(prob, x), lambda: one_at_a_time(prob, x), **kw
    )
    batch, old_b = measure_pair(
        lambda: prob.finite_difference_gradient(x), lambda: one_at_a_time(prob, x), **kw
    )
    cases = [
        Case(
            "gradient (cond): chain rule through the samples",
            n=1,
            dynid=chain,
            ref=old,
            ref_name="one at a time",
        ),
        Case(
            "gradient (logdet): finite differences in one batch",
            n=1,
            dynid=batch,
            ref=old_b,
            ref_name="one at a time",
        ),
    ]
    t0, c0 = time.perf_counter(), time.process_time()
    res = optimise_excitation(robot, np.random.default_rng(0))
    wall, cpu = time.perf_counter() - t0, time.process_time() - c0
    report(
        "excitation design (Panda, 20 s, 5 harmonics, 77 variables)",
        cases,
        args,
        extra={
            "variables": len(x),
            "design_wall_s": round(wall, 2),
            "design_cpu_s": round(cpu, 2),
            "design_condition_number": round(res.condition_number, 2),
            "design_iterations": res.iterations,
            "design_status": res.status,
        },
    )
    return 0


if __name__ == "__main__":
    sys.exit(main())
