"""Static identification of the Panda: dynid end to end vs the static regressor in Pinocchio.

Cases (the reference is Pinocchio on example-robot-data's Panda with the fingers locked,
looping from Python over the samples and building the stacked static regressor
``[tril M; g]`` only: per sample ``computeJointTorqueRegressor`` with unit accelerations
and gravity off for the n columns of M, then at rest with gravity for g, n + 1 calls):

* ``identify, end to end``: ``identify_static`` on ``--n`` configurations (1010, as in
  Gaz et al. 2019): static regressor, base parameters computed from the robot's
  structure (in every call: nothing is cached between calls), reduction to them, check of
  the rows, least squares, standard deviations and metrics;
* ``identify, base given``: the same with the base parameters computed beforehand (once
  per robot);
* ``static regressor, batch``: ``static_regressor`` on the same configurations;
* ``static regressor, 1 configuration``.

Before timing, the regressors are checked to agree (after Pinocchio's inertia-order
permutation) and the identified coefficients to equal those of the true parameters. The
warm-up calls compile dynid's numba kernels (or load them from numba's disk cache), so
compilation is not timed.

Run ``python benchmarks/bench_identification.py [--json [PATH]] [--n 1010]``.
"""

from __future__ import annotations

import sys
from pathlib import Path
from typing import Any

import numpy as np

sys.path.insert(0, str(Path(__file__).resolve().parent))
from common import Case, bench_parser, check_close, measure, pinocchio_panda, report  # noqa: E402

import dynid  # noqa: E402
from dynid.identification.static import identify_static  # noqa: E402
from dynid.regressors.base import base_parameters  # noqa: E402
from dynid.regressors.static import static_regressor  # noqa: E402
from dynid.simulation.controller import SimulatedController, acquire_static  # noqa: E402

#: dynid order (m, mcx, mcy, mcz, Jxx, Jxy, Jxz, Jyy, Jyz, Jzz) from Pinocchio's
#: (m, mcx, mcy, mcz, Ixx, Ixy, Iyy, Ixz, Iyz, Izz)
PIN_TO_DYNID = np.array([0, 1, 2, 3, 4, 5, 7, 6, 8, 9])


def pinocchio_static_regressor(
    model: Any, data: Any, q: np.ndarray, gravity: np.ndarray
) -> np.ndarray:
    """(N, s, 10 n) stacked static regressor from Pinocchio; rows as dynid's static_labels."""
    import pinocchio as pin

    N, n = q.shape
    i, j = np.tril_indices(n)
    E = np.eye(n)
    z = np.zeros(n)
    out = np.empty((N, i.size + n, 10 * n))
    for s in range(N):
        model.gravity.linear[:] = 0.0
        cols = np.stack(
            [pin.computeJointTorqueRegressor(model, data, q[s], z, E[k]) for k in range(n)]
        )
        model.gravity.linear[:] = gravity
        out[s, : i.size] = cols[j, i]  # M[i, j] = Y_i(q, 0, e_j)
        out[s, i.size :] = pin.computeJointTorqueRegressor(model, data, q[s], z, z)
    return out


def main(argv: list[str] | None = None) -> int:
    parser = bench_parser(__doc__)
    parser.add_argument("--n", type=int, default=1010, help="configurations (default 1010)")
    args = parser.parse_args(argv)
    robot = dynid.panda()
    data = acquire_static(SimulatedController(robot), args.n, np.random.default_rng(0))
    model, pdata = pinocchio_panda(robot)

    def pin_regressor(q: np.ndarray) -> np.ndarray:
        return pinocchio_static_regressor(model, pdata, q, robot.gravity)

    Yp = pin_regressor(data.q)
    Yp = Yp.reshape(Yp.shape[:-1] + (robot.n, 10))[..., PIN_TO_DYNID].reshape(Yp.shape)
    check_close("static regressor", static_regressor(robot, data.q), Yp, atol=1e-9)
    result = identify_static(robot, data)
    base = result.base
    true = base.beta_from_phi(robot.phi)
    check_close("identified coefficients", result.beta, true, atol=1e-9)

    kw = {"min_time": args.min_time, "repeats": args.repeats}
    q1 = data.q[:1]
    note = "reference: Pinocchio builds the stacked static regressor only (n + 1 calls/sample)"
    cases = [
        Case(
            "identify, end to end",
            args.n,
            measure(lambda: identify_static(robot, data), **kw),
            measure(lambda: pin_regressor(data.q), **kw),
            note=note,
        ),
        Case(
            "identify, base given",
            args.n,
            measure(lambda: identify_static(robot, data, base=base), **kw),
            measure(lambda: pin_regressor(data.q), **kw),
            note=note,
        ),
        Case(
            "static regressor, batch",
            args.n,
            measure(lambda: static_regressor(robot, data.q), **kw),
            measure(lambda: pin_regressor(data.q), **kw),
        ),
        Case(
            "static regressor, 1 configuration",
            1,
            measure(lambda: static_regressor(robot, q1[0]), **kw),
            measure(lambda: pin_regressor(q1), **kw),
        ),
    ]
    base_time = measure(lambda: base_parameters(robot), **kw)
    extra = {
        "configurations": args.n,
        "identification": {
            "rank": result.fit.rank,
            "condition_number": result.fit.condition_number,
            "max_coefficient_error": float(np.max(np.abs(result.beta - true))),
        },
        "base_parameters_s": {
            "median": base_time.median,
            "min": base_time.min,
            "max": base_time.max,
        },
        "target": "identify, end to end: ref/dynid >= 2",
    }
    report(f"static identification: dynid vs pinocchio (Panda, N = {args.n})", cases, args, extra)
    return 0


if __name__ == "__main__":
    sys.exit(main())
