"""Classical identification of a 20 s, 1 kHz torque log: dynid end to end vs Pinocchio's regressor.

* dynid, end to end: ``identify_from_log`` on a 20 s log at 1 kHz of the Panda (20 001
  samples, 7 joints) following a random Fourier trajectory: zero-phase low-pass of
  ``q, dq, tau``, ``ddq`` by differentiation, edge trimming, decimation after the filter
  (default: to 10 times the cutoff), base parameters from the robot's structure, torque
  regressor reduced to them, classical friction columns, least squares with statistics.
  Target: under 1 s.
* dynid, the same on every sample (``decimate=1``, the (N, 7, 70) regressor of ~19 600
  samples).
* dynid, the same on every sample with the regressor read in blocks of rows
  (``DYNID_MAX_STACK_BYTES=0``, as a log too long to stack is fitted); reference: the same
  fit stacked (target, issue 28: within 1.2 times its time; one process, one core, so
  time is CPU time).
* dynid, the torque regressor alone on the prepared samples.
* dynid with drive terms: the same log recorded on the motor side of a drive train (gear
  ratios 100, motor 7 coupled to joint 6, rotor inertias and friction at the motors
  identified with the links); reference: today's route without a drive on the joint-side
  log. Target: under 1 s.
* Pinocchio (reference): building that same torque regressor from Python, one
  ``computeJointTorqueRegressor`` call per sample, looped over the samples (no filtering,
  no least squares), for the ratio.

Before timing, dynid's regressor is checked against Pinocchio's (after the inertia-order
permutation) and the identified model against the simulated truth (held-out torques at
the sensor noise). Timing: ``timeit`` autorange (>= 0.2 s per repeat), >= 5 repeats,
median with min and max (``common.measure``). The least squares use the BLAS: on a
machine busy with other work its threads contend and the timings spread widely; run with
``OPENBLAS_NUM_THREADS=1`` for stable numbers (the header shows the setting).

usage: python benchmarks/bench_classical.py [--duration 20] [--rate 1000] [--repeats 5] [--json]
"""

from __future__ import annotations

import dataclasses
import os
import sys
from pathlib import Path
from typing import Any

import numpy as np

sys.path.insert(0, str(Path(__file__).resolve().parent))

from common import (  # noqa: E402
    Case,
    bench_parser,
    check_close,
    measure,
    pinocchio_panda,
    report,
)

import dynid  # noqa: E402
from dynid.friction.validation import own_friction  # noqa: E402
from dynid.identification.classical import identify_from_log  # noqa: E402
from dynid.identification.prepare import prepare_log  # noqa: E402
from dynid.model.drive import Drive  # noqa: E402
from dynid.regressors.base import base_parameters  # noqa: E402
from dynid.regressors.torque import torque_regressor  # noqa: E402
from dynid.simulation.measurement import sample_times, simulate_measurement  # noqa: E402
from dynid.simulation.trajectories import random_fourier  # noqa: E402

#: dynid order (m, mcx, mcy, mcz, Jxx, Jxy, Jxz, Jyy, Jyz, Jzz) from Pinocchio's
#: (m, mcx, mcy, mcz, Ixx, Ixy, Iyy, Ixz, Iyz, Izz)
PIN_TO_DYNID = np.array([0, 1, 2, 3, 4, 5, 7, 6, 8, 9])


def pinocchio_torque_regressor(pin, model, data, q, dq, ddq) -> np.ndarray:
    """(N, n, 10 n) torque regressor, one Pinocchio call per sample, dynid column order."""
    N, n = q.shape
    Y = np.empty((N, n, 10 * n))
    for s in range(N):
        Yp = pin.computeJointTorqueRegressor(model, data, q[s], dq[s], ddq[s])
        Y[s] = Yp.reshape(n, n, 10)[:, :, PIN_TO_DYNID].reshape(n, 10 * n)
    return Y


def main(argv: list[str] | None = None) -> int:
    p = bench_parser(__doc__)
    p.add_argument("--duration", type=float, default=20.0, help="log length [s] (default 20)")
    p.add_argument("--rate", type=float, default=1000.0, help="sample rate [Hz] (default 1000)")
    args = p.parse_args(argv)
    import pinocchio as pin

    robot = dynid.panda()
    series = random_fourier(robot, np.random.default_rng(0))
    traj = series(sample_times(args.duration, args.rate))
    log = simulate_measurement(robot, traj, rng=np.random.default_rng(1), friction=None)
    prepared = prepare_log(log)
    q, dq, ddq = prepared.q, prepared.dq, prepared.ddq

    # --- agreement before timing
    model, data = pinocchio_panda(robot)
    check_close(
        "torque regressor (first 500 samples)",
        torque_regressor(robot, q[:500], dq[:500], ddq[:500]),
        pinocchio_torque_regressor(pin, model, data, q[:500], dq[:500], ddq[:500]),
        atol=1e-9,
    )
    ident = identify_from_log(robot, log, structure="classical", estimator="ols")
    held = random_fourier(robot, np.random.default_rng(2))(sample_times(10.0, args.rate))
    meas = simulate_measurement(robot, held, rng=np.random.default_rng(3), friction=None)
    pred = ident.torques(held.q, held.dq, held.ddq)
    pred = pred + own_friction(ident).torques(held.dq)
    rms = np.sqrt(np.mean((meas.tau - pred) ** 2, axis=0))
    check_close("held-out torque RMS vs 0.05 N m sensor noise", rms, np.full(7, 0.05), atol=0.01)
    beta = base_parameters(robot, kind="torque").beta_from_phi(robot.phi)

    # --- timing
    N = log.n_samples
    kw = dict(min_time=args.min_time, repeats=args.repeats)
    ref = measure(lambda: pinocchio_torque_regressor(pin, model, data, q, dq, ddq), **kw)
    end_to_end = measure(
        lambda: identify_from_log(robot, log, structure="classical", estimator="ols"), **kw
    )
    every = measure(
        lambda: identify_from_log(robot, log, decimate=1, structure="classical", estimator="ols"),
        **kw,
    )
    every_model = identify_from_log(robot, log, decimate=1, structure="classical", estimator="ols")
    regressor = measure(lambda: torque_regressor(robot, q, dq, ddq), **kw)

    def in_blocks() -> Any:
        old = os.environ.get("DYNID_MAX_STACK_BYTES")
        os.environ["DYNID_MAX_STACK_BYTES"] = "0"
        try:
            return identify_from_log(robot, log, decimate=1, structure="classical", estimator="ols")
        finally:
            if old is None:
                del os.environ["DYNID_MAX_STACK_BYTES"]
            else:
                os.environ["DYNID_MAX_STACK_BYTES"] = old

    streamed = in_blocks()
    scale = float(np.max(np.abs(every_model.beta)))
    check_close("read in blocks vs stacked", streamed.beta, every_model.beta, atol=1e-9 * scale)
    blocks = measure(in_blocks, **kw)
    truth = Drive.from_gears(
        np.full(7, 100.0), [(7, 6, 20.0)], side="motor", rotor_inertia=np.full(7, 3e-5)
    )
    drive = dataclasses.replace(truth, rotor_inertia=None)  # identified
    motor_log = simulate_measurement(
        robot, traj, rng=np.random.default_rng(1), friction=None, drive=truth
    )
    with_drive = measure(
        lambda: identify_from_log(
            robot, motor_log, drive=drive, structure="classical", estimator="ols"
        ),
        **kw,
    )
    note = f"reference: Pinocchio regressor only, Python loop over the {len(q)} prepared samples"
    cases = [
        Case(f"identify_from_log, {args.duration:g} s log", N, end_to_end, ref, note=note),
        Case("identify_from_log, decimate=1", N, every, ref, note=note),
        Case(
            "identify_from_log, decimate=1, read in blocks",
            N,
            blocks,
            every,
            ref_name="stacked",
            note="reference: the same fit with the regressor stacked (target: ref/dynid >= 1/1.2)",
        ),
        Case("torque regressor only", len(q), regressor, ref, note=note),
        Case(
            "identify_from_log with a coupled drive (motor side, rotors)",
            N,
            with_drive,
            end_to_end,
            ref_name="no drive",
            note="reference: the same route without drive terms on the joint-side log",
        ),
    ]
    extra = {
        "samples": N,
        "joints": robot.n,
        "end_to_end_median_s": round(end_to_end.median, 4),
        "target_s": 1.0,
        "meets_target": bool(end_to_end.median < 1.0),
        "with_drive_median_s": round(with_drive.median, 4),
        "with_drive_meets_target": bool(with_drive.median < 1.0),
        "blocks_over_stacked": round(blocks.median / every.median, 3),
        "decimation": ident.info.log.decimate if ident.info.log else None,
        "rows_in_least_squares": ident.info.n_rows,
        "condition_number": round(ident.fit.condition_number, 2),
        "relative_error_percent": round(ident.fit.relative_error_percent, 4),
        "median_relative_beta_error_percent": round(
            float(np.median(100 * np.abs(ident.beta - beta) / np.abs(beta))), 3
        ),
        "heldout_rms_Nm": [round(float(x), 4) for x in rms],
    }
    report("classical identification (20 s, 1 kHz torque log)", cases, args, extra)
    return 0


if __name__ == "__main__":
    sys.exit(main())
