"""The model's structure chosen on held-out data vs the one fixed structure it replaces.

* dynid, structure chosen: ``identify_recordings`` on a 20 s, 1 kHz log of the Panda
  (20 001 samples, 7 joints, a random Fourier trajectory, armature and viscous friction in
  the simulated torques): the log prepared once, the largest model fitted once per
  armature choice, every candidate structure (32) judged on the folds' normal equations,
  the chosen one fitted. Target: under 3 s.
* reference: ``identify_from_log`` with the paper's fixed structure (viscous, Coulomb and
  offset friction) on the same log, the route the default replaces.
* ``--stribeck``: the simulated friction a Stribeck law whose velocity differs per joint
  (0.08 rad/s on joints 1-2, 0.1 on the others; ``fs = 2 fc``) with sensor noise instead,
  whose search also refines the Stribeck velocity and chooses one per joint
  (:mod:`dynid.identification.stribeck_joints`).
* the same log prepared again at the cut-off the search read, as the offsets' check of
  ``identify`` prepares the recordings the fit has just prepared: read back within one
  run (:mod:`dynid.identification.once_per_run`) against prepared again (the
  reference: a run without the shared block).

Before timing, the chosen structure is checked to be the simulated one (armature and
viscous friction; with ``--stribeck``, a Stribeck law with its velocity per joint).
Timing: ``timeit`` autorange (>= 0.2 s per repeat), >= 5 repeats, median with min and max
(``common.measure_pair``, the two interleaved).

usage: python benchmarks/bench_structure.py [--duration 20] [--rate 1000] [--stribeck]
       [--repeats 5] [--json]
"""

from __future__ import annotations

import contextvars
import re
import sys
import warnings
from pathlib import Path

import numpy as np

sys.path.insert(0, str(Path(__file__).resolve().parent))

from common import Case, bench_parser, measure_pair, report  # noqa: E402

import dynid  # noqa: E402
from dynid.exceptions import DynidWarning  # noqa: E402
from dynid.friction.laws import LAWS  # noqa: E402
from dynid.friction.model import ClassicalFriction, LawFriction  # noqa: E402
from dynid.identification.classical import identify_from_log  # noqa: E402
from dynid.identification.once_per_run import shared_run  # noqa: E402
from dynid.identification.recordings import prepare_recordings  # noqa: E402
from dynid.identification.selection import identify_recordings  # noqa: E402
from dynid.identification.structure import candidate_structures  # noqa: E402
from dynid.simulation.measurement import (  # noqa: E402
    SensorNoise,
    sample_times,
    simulate_measurement,
)
from dynid.simulation.trajectories import random_fourier  # noqa: E402
from dynid.simulation.unmodelled import UnmodelledEffects  # noqa: E402


def main(argv: list[str] | None = None) -> int:
    p = bench_parser(__doc__)
    p.add_argument("--duration", type=float, default=20.0, help="log length [s] (default 20)")
    p.add_argument("--rate", type=float, default=1000.0, help="sample rate [Hz] (default 1000)")
    p.add_argument("--stribeck", action="store_true", help="a Stribeck law per joint instead")
    args = p.parse_args(argv)
    warnings.simplefilter("ignore", DynidWarning)
    robot = dynid.panda()
    t = sample_times(args.duration, args.rate)
    log = _log(robot, t, args.stribeck)
    chosen = identify_recordings(robot, [log])
    name = (chosen.info.selection or {}).get("chosen")
    want = "links + armature + viscous"
    if (name != want) if not args.stribeck else not re.search(r"stribeck:[0-9.]+/", str(name)):
        want = "a Stribeck law per joint" if args.stribeck else want
        print(f"structure chosen: {name!r}, simulated: {want}", file=sys.stderr)
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
    again = _prepared_again(robot, log, chosen.info.log.cutoff_hz, args)
    if again is None:
        return 1
    cases.append(again)
    extra = {"duration_s": args.duration, "rate_hz": args.rate, "stribeck": args.stribeck}
    report("model structure", cases, args, extra)
    return 0


def _prepared_again(robot: dynid.Robot, log: dynid.TorqueLog, cutoff_hz: float | None, args):
    """The log prepared again at ``cutoff_hz`` within the block that prepared it once
    against prepared again outside it (a fresh context), the two checked equal first."""

    def again():
        return prepare_recordings(robot, [log], cutoff_hz=cutoff_hz)

    def fresh():
        return contextvars.Context().run(again)

    with shared_run():
        read, made = again(), fresh()
        same = all(
            np.array_equal(getattr(a.log, k), getattr(b.log, k))
            for a, b in zip(read.pieces, made.pieces, strict=True)
            for k in ("t", "q", "dq", "ddq", "tau")
        )
        if not same:
            print("the preparation read back differs from the one made again", file=sys.stderr)
            return None
        ours, ref = measure_pair(again, fresh, min_time=args.min_time, repeats=args.repeats)
    return Case(
        "recordings prepared again in one run (offsets' check)",
        log.n_samples,
        ours,
        ref,
        ref_name="prepared again",
        note=f"{len(read.pieces)} piece(s) at {cutoff_hz:.3g} Hz",
    )


def _log(robot: dynid.Robot, t: np.ndarray, stribeck: bool) -> dynid.TorqueLog:
    """The simulated log: armature and viscous friction, exact; or (``stribeck``) a
    Stribeck law whose velocity differs per joint, with sensor noise."""
    trajectory = random_fourier(robot, np.random.default_rng(1))(t)
    if not stribeck:
        return simulate_measurement(
            robot,
            trajectory,
            rng=np.random.default_rng(2),
            friction=ClassicalFriction(np.linspace(0.3, 0.1, 7), np.zeros(7), np.zeros(7)),
            effects=UnmodelledEffects(
                rotor_inertia=np.linspace(0.3, 0.05, 7), torque_offset=np.zeros(7)
            ),
        )
    fc = np.linspace(0.8, 0.3, 7)
    vst = [0.08, 0.08, 0.1, 0.1, 0.1, 0.1, 0.1]
    P = np.column_stack([np.linspace(0.6, 0.1, 7), fc, 2.0 * fc, vst, np.zeros(7)])
    return simulate_measurement(
        robot,
        trajectory,
        rng=np.random.default_rng(2),
        friction=LawFriction(LAWS["stribeck"], P),
        noise=SensorNoise(tau_std=0.05, q_std=2e-5, dq_std=2e-3),
        with_ddq=False,
    )


if __name__ == "__main__":
    raise SystemExit(main())
