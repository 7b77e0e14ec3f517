"""Physically consistent parameters: the convex (SDP) retrieval against the penalty method.

* Two-step, the paper's setting: the 43 coefficients of a Panda whose parameters differ from
  the published ones by up to 20 % (exact coefficients), the published set as prior.
  dynid's convex retrieval (``retrieve_sdp``, Clarabel) against the paper's penalty method
  (``retrieve``, 10 runs of 5 stages on 2 processes) measured in the same run. Target: the
  convex retrieval under 2 s.
* Two-step on noisy coefficients with model error (rotor inertia, gravity tilt; 1010 static
  configurations at 1e-4 noise): the automatic prior weight searches about a dozen solves.
* One-step on a 20 s, 1 kHz torque log (classical route with friction): default decimation
  and ``decimate=1``. Target: under 10 s.
* One-step on a short noisy log (3 s, 0.5 N m torque noise, rotor inertia and offsets):
  the held-out weight search (46 solves), against the formulation it replaced measured in
  the same run (cvxpy's ``log_det`` with the weight in its cost, Clarabel's default gap, a
  new solver object each solve: Clarabel stalled at the small weights and SCS answered).

Before timing, each result is checked: coefficients met to 1e-9 (exact case), every link's
pseudo-inertia margin at least 1e-4 of its trace. The reference of every case is the
penalty method on the same coefficients (``ref/dynid`` > 1: the convex method is faster).
The penalty method takes seconds per call, so this benchmark times each case over a few
repeats (``--repeats``, default 3) without autorange.

usage: python benchmarks/bench_consistent.py [--repeats 3] [--json]
"""

from __future__ import annotations

import contextlib
import statistics
import sys
import time
import warnings
from collections.abc import Iterator
from pathlib import Path

import numpy as np

sys.path.insert(0, str(Path(__file__).resolve().parent))

from common import Case, Timing, bench_parser, check_close, report  # noqa: E402

import dynid  # noqa: E402
from dynid.feasibility.compare import perturbed_robot  # noqa: E402
from dynid.feasibility.convex import (  # noqa: E402
    identify_consistent,  # noqa: E402
    problem,
    retrieve_sdp,  # noqa: E402
    solvers,
)
from dynid.feasibility.lmi import pseudo_inertia_margin  # noqa: E402
from dynid.feasibility.penalty import retrieve  # noqa: E402
from dynid.identification.least_squares import LeastSquaresFit  # noqa: E402
from dynid.identification.model import IdentifiedModel  # noqa: E402
from dynid.regressors.base import base_parameters  # noqa: E402
from dynid.simulation.measurement import (  # noqa: E402
    SensorNoise,
    sample_times,
    simulate_measurement,
)
from dynid.simulation.trajectories import random_fourier  # noqa: E402
from dynid.simulation.unmodelled import UnmodelledEffects  # noqa: E402


def timed(fn, repeats: int) -> Timing:
    """Seconds per call over ``repeats`` calls (one warm-up call first)."""
    fn()
    t = []
    for _ in range(repeats):
        t0 = time.perf_counter()
        fn()
        t.append(time.perf_counter() - t0)
    return Timing(statistics.median(t), min(t), max(t), 1, repeats)


def exact_model(robot, truth) -> IdentifiedModel:
    base = base_parameters(robot, kind="static")
    r = base.rank
    z = np.zeros(r)
    fit = LeastSquaresFit(
        base.beta_from_phi(truth.phi), z, z, np.ones(r, bool), r, 1.0, 0.0, 0.0, 0.0, 0, 1e-10
    )
    return IdentifiedModel(robot=robot, base=base, fit=fit)


@contextlib.contextmanager
def previous_formulation() -> Iterator[None]:
    """The convex problem as it was built before the prior weight moved into the log-det's
    cones: ``c (-log det X)`` through cvxpy's ``log_det``, Clarabel's default duality gap
    and a new solver object (so a new compilation) at each solve."""
    import cvxpy as cp

    saved = (problem.weighted_neg_log_det, problem.gap_tolerance, problem.clarabel, problem.scs)
    problem.weighted_neg_log_det = lambda X, c: (-c * cp.log_det(X), [])
    problem.gap_tolerance = lambda v, scale, weighted: 1e-8
    problem.clarabel, problem.scs = solvers.clarabel.__wrapped__, solvers.scs.__wrapped__
    try:
        yield
    finally:
        (problem.weighted_neg_log_det, problem.gap_tolerance, problem.clarabel, problem.scs) = saved


def retried(res) -> str:
    """The result's note on second attempts, or "none"."""
    return next((n for n in res.notes if "second attempt" in n), "none")


def main(argv: list[str] | None = None) -> int:
    p = bench_parser(__doc__)
    p.set_defaults(repeats=3)
    args = p.parse_args(argv)
    robot = dynid.panda()
    rng = np.random.default_rng(0)
    truth = perturbed_robot(robot, rng)
    exact = exact_model(robot, truth)
    effects = UnmodelledEffects.typical(7, rng)
    ctrl = dynid.SimulatedController(truth, relative_noise=1e-4, rng=rng, effects=effects)
    data = dynid.acquire_static(ctrl, 1010, rng)
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        noisy = dynid.identify_static(robot, data)
    traj = random_fourier(robot, rng, n_harmonics=5)(sample_times(20.0, 1000.0))
    log = simulate_measurement(robot, traj, rng=rng, effects=effects)
    short_traj = random_fourier(robot, np.random.default_rng(0), n_harmonics=5)
    short = simulate_measurement(
        robot,
        short_traj(sample_times(3.0, 1000.0)),
        rng=np.random.default_rng(50),
        noise=SensorNoise(0.5, 1e-4, 1e-3),
        effects=UnmodelledEffects.typical(7, np.random.default_rng(0)),
    )

    # --- agreement before timing
    res = retrieve_sdp(exact, prior=robot)
    P = exact.base.projection
    nb = float(np.linalg.norm(exact.beta))
    check_close("beta (exact)", P @ res.phi.reshape(-1), exact.beta, 1e-9 * nb)
    for name, r in (
        ("exact", res),
        ("noisy", retrieve_sdp(noisy, prior=robot)),
        ("one-step", identify_consistent(robot, log, prior=robot)),
    ):
        m = float(pseudo_inertia_margin(r.phi).min())
        if not m >= 1e-4 * (1 - 1e-9):
            raise AssertionError(f"{name}: smallest pseudo-inertia margin {m:.3g} < 1e-4")

    # the short noisy log: both formulations choose the same weight, the same held-out error
    def short_fit():
        with warnings.catch_warnings():
            warnings.simplefilter("ignore")
            return identify_consistent(robot, short, prior=robot)

    def short_fit_before():
        with previous_formulation():
            return short_fit()

    now, before = short_fit(), short_fit_before()
    assert now.heldout is not None and before.heldout is not None
    check_close(
        "prior weight (short log)", np.log10(now.prior_weight), np.log10(before.prior_weight), 1e-9
    )
    check_close(
        "held-out error % (short log)",
        now.heldout.heldout_percent,
        before.heldout.heldout_percent,
        1e-3,
    )

    # --- timing
    k = args.repeats
    penalty_exact = timed(lambda: retrieve(exact, workers=2, seed=0), k)
    penalty_noisy = timed(lambda: retrieve(noisy, workers=2, seed=0), k)
    note = "reference: penalty method (10 runs x 5 stages, 2 processes) on the same coefficients"
    cases = [
        Case(
            "two-step SDP, exact beta",
            1,
            timed(lambda: retrieve_sdp(exact, prior=robot), k),
            penalty_exact,
            "penalty",
            note,
        ),
        Case(
            "two-step SDP, noisy beta, auto weight",
            1,
            timed(lambda: retrieve_sdp(noisy, prior=robot), k),
            penalty_noisy,
            "penalty",
            note,
        ),
        Case(
            "one-step, 20 s log",
            1,
            timed(lambda: identify_consistent(robot, log, prior=robot), k),
            penalty_noisy,
            "penalty",
            "reference: the penalty method on the noisy static coefficients (two-step)",
        ),
        Case(
            "one-step, 20 s log, decimate=1",
            1,
            timed(lambda: identify_consistent(robot, log, prior=robot, decimate=1), k),
            penalty_noisy,
            "penalty",
            "reference: the penalty method on the noisy static coefficients (two-step)",
        ),
        Case(
            "one-step, 3 s noisy log, held-out search",
            1,
            timed(short_fit, k),
            timed(short_fit_before, k),
            "before",
            "reference: the previous formulation (log_det's weight in its cost, new solver "
            "object each solve) in the same run",
        ),
    ]
    extra = {
        "targets_s": {"two-step": 2.0, "one-step": 10.0},
        "log_samples": log.n_samples,
        "short_log_second_attempts": {"now": retried(now), "before": retried(before)},
    }
    report("consistent parameters: convex (SDP) vs penalty", cases, args, extra)
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
