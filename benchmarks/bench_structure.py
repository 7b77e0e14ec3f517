"""The model's structure chosen on held-out data vs the one fixed structure it replaces.

* dynid, structure chosen: ``identify_recordings`` on a 20 s, 1 kHz log of the Panda
  (20 001 samples, 7 joints, a random Fourier trajectory, armature and viscous friction in
  the simulated torques): the log prepared once, the largest model fitted once per
  armature choice, every candidate structure (32) judged on the folds' normal equations,
  the chosen one fitted. Target: under 3 s.
* reference: ``identify_from_log`` with the paper's fixed structure (viscous, Coulomb and
  offset friction) on the same log, the route the default replaces.

Before timing, the chosen structure is checked to be the simulated one (armature and
viscous friction). Timing: ``timeit`` autorange (>= 0.2 s per repeat), >= 5 repeats,
median with min and max (``common.measure_pair``, the two interleaved).

usage: python benchmarks/bench_structure.py [--duration 20] [--rate 1000] [--repeats 5] [--json]
"""

from __future__ import annotations

import sys
import warnings
from pathlib import Path

import numpy as np

sys.path.insert(0, str(Path(__file__).resolve().parent))

from common import Case, bench_parser, measure_pair, report  # noqa: E402

import dynid  # noqa: E402
from dynid.exceptions import DynidWarning  # noqa: E402
from dynid.friction.model import ClassicalFriction  # noqa: E402
from dynid.identification.classical import identify_from_log  # noqa: E402
from dynid.identification.selection import identify_recordings  # noqa: E402
from dynid.identification.structure import candidate_structures  # noqa: E402
from dynid.simulation.measurement import sample_times, simulate_measurement  # noqa: E402
from dynid.simulation.trajectories import random_fourier  # noqa: E402
from dynid.simulation.unmodelled import UnmodelledEffects  # noqa: E402


def main(argv: list[str] | None = None) -> int:
    p = bench_parser(__doc__)
    p.add_argument("--duration", type=float, default=20.0, help="log length [s] (default 20)")
    p.add_argument("--rate", type=float, default=1000.0, help="sample rate [Hz] (default 1000)")
    args = p.parse_args(argv)
    warnings.simplefilter("ignore", DynidWarning)
    robot = dynid.panda()
    t = sample_times(args.duration, args.rate)
    log = simulate_measurement(
        robot,
        random_fourier(robot, np.random.default_rng(1))(t),
        rng=np.random.default_rng(2),
        friction=ClassicalFriction(np.linspace(0.3, 0.1, 7), np.zeros(7), np.zeros(7)),
        effects=UnmodelledEffects(
            rotor_inertia=np.linspace(0.3, 0.05, 7), torque_offset=np.zeros(7)
        ),
    )
    chosen = identify_recordings(robot, [log])
    name = (chosen.info.selection or {}).get("chosen")
    if name != "links + armature + viscous":
        print(f"structure chosen: {name!r}, simulated: links + armature + viscous", file=sys.stderr)
        return 1
    ours, ref = measure_pair(
        lambda: identify_recordings(robot, [log]),
        lambda: identify_from_log(robot, log, structure="classical", estimator="ols"),
        min_time=args.min_time,
        repeats=args.repeats,
    )
    cases = [
        Case(
            f"structure chosen on held-out data ({len(candidate_structures())} candidates)",
            t.size,
            ours,
            ref,
            ref_name="fixed structure",
            note=f"chosen: {name}",
        )
    ]
    report("model structure", cases, args, {"duration_s": args.duration, "rate_hz": args.rate})
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
