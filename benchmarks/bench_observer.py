"""The momentum observer on the Panda: dynid's compiled step and batch against the same
residual computed with Pinocchio.

Reference (one sample): ``pinocchio.crba`` (symmetrised), ``computeCoriolisMatrix`` and
``computeGeneralizedGravity`` on example-robot-data's Panda with the fingers locked and the
inertials and gravity of ``dynid.panda()``, then the update in numpy:
``p = M dq``, ``u = tau + C^T dq - g``, ``r += gamma ((p - p_prev) / T - (u + u_prev) / 2 - r)``
with ``gamma = 1 - exp(-K_O T)`` (dynid's default: exact discretisation, trapezoid rule).
Both run without friction (the same model; dynid's friction is part of its compiled step).

Cases:

* ``step``: ``MomentumObserver.step(q, dq, tau, t)`` against the Pinocchio step, one sample
  per call, repeats alternated (the target: dynid in at most half Pinocchio's time);
* ``batch``: ``MomentumObserver.run`` over ``--batch`` samples against a Python loop of
  the Pinocchio step over them (the target: over 1 M samples/s).

Both residuals are checked to agree (1e-9 N m) over 2000 samples first.

Run ``python benchmarks/bench_observer.py [--json out.json] [--batch N]``.
"""

from __future__ import annotations

import sys
from pathlib import Path

import numpy as np

sys.path.insert(0, str(Path(__file__).resolve().parent))
from common import (  # noqa: E402  (the folder of this script)
    Case,
    bench_parser,
    check_close,
    measure,
    measure_pair,
    pinocchio_panda,
    random_states,
    report,
)

GAIN = 50.0


class PinocchioObserver:
    """The residual with Pinocchio's M, C and g and the update in numpy (module docstring)."""

    def __init__(self, model, data, n: int) -> None:
        self.model, self.data = model, data
        self.started = False
        self.t = 0.0
        self.p, self.u, self.r = np.zeros(n), np.zeros(n), np.zeros(n)

    def step(self, q, dq, tau, t):
        import pinocchio as pin

        model, data = self.model, self.data
        M = pin.crba(model, data, q)
        M = np.triu(M) + np.triu(M, 1).T
        C = pin.computeCoriolisMatrix(model, data, q, dq)
        g = pin.computeGeneralizedGravity(model, data, q)
        p = M @ dq
        u = tau + C.T @ dq - g
        if not self.started:
            self.started, self.t, self.p, self.u = True, t, p, u
            self.r = np.zeros_like(p)
            return self.r.copy()
        T = t - self.t
        gam = -np.expm1(-GAIN * T)
        self.r = self.r + gam * ((p - self.p) / T - 0.5 * (u + self.u) - self.r)
        self.t, self.p, self.u = t, p, u
        return self.r.copy()


def main(argv: list[str] | None = None) -> int:
    args = bench_parser(__doc__).parse_args(argv)

    import dynid
    from dynid.observer import from_robot
    from dynid.observer.residual import MomentumObserver, ObserverOptions

    robot = dynid.panda()
    model, data = pinocchio_panda(robot)
    obs_model = from_robot(robot, friction=None)
    opts = ObserverOptions(gain=GAIN)
    N = args.batch
    Q, DQ, TAU = random_states(robot, N, seed=0)
    t = np.arange(N) * 1e-3

    # the answers agree first
    k = min(N, 2000)
    ours = MomentumObserver(obs_model, opts).run(t[:k], Q[:k], DQ[:k], TAU[:k])
    ref = PinocchioObserver(model, data, robot.n)
    theirs = np.array([ref.step(Q[i], DQ[i], TAU[i], t[i]) for i in range(k)])
    check_close("observer residual", ours, theirs, atol=1e-9)
    steps = MomentumObserver(obs_model, opts)
    mine = np.array([steps.step(Q[i], DQ[i], TAU[i], t[i]) for i in range(k)])
    check_close("observer step", mine, theirs, atol=1e-9)

    timed = {"min_time": args.min_time, "repeats": args.repeats}
    obs = MomentumObserver(obs_model, opts)
    pobs = PinocchioObserver(model, data, robot.n)
    q, dq, tau = Q[1], DQ[1], TAU[1]
    clock = {"ours": 0.0, "ref": 0.0}

    def ours_step():
        clock["ours"] += 1e-3
        return obs.step(q, dq, tau, clock["ours"])

    def ref_step():
        clock["ref"] += 1e-3
        return pobs.step(q, dq, tau, clock["ref"])

    d_step, r_step = measure_pair(ours_step, ref_step, **timed)

    batch = MomentumObserver(obs_model, opts)

    def ours_batch():
        batch.reset()
        return batch.run(t, Q, DQ, TAU)

    def ref_batch():
        o = PinocchioObserver(model, data, robot.n)
        return [o.step(Q[i], DQ[i], TAU[i], t[i]) for i in range(N)]

    d_batch = measure(ours_batch, warmup=1, **timed)
    r_batch = measure(ref_batch, warmup=0, min_time=args.min_time, repeats=min(args.repeats, 3))
    cases = [
        Case("observer step, 1 sample", 1, d_step, r_step, note="target: ref/dynid >= 2"),
        Case(
            "observer batch",
            N,
            d_batch,
            r_batch,
            note="reference: a Python loop of the Pinocchio step; target: 1 M samples/s",
        ),
    ]
    extra = {
        "step_ratio_pinocchio_over_dynid": r_step.median / d_step.median,
        "batch_samples_per_s": {
            "median": N / d_batch.median,
            "best": N / d_batch.min,
            "worst": N / d_batch.max,
        },
    }
    report("observer", cases, args, extra)
    return 0


if __name__ == "__main__":
    sys.exit(main())
