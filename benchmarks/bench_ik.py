"""Inverse kinematics: dynid.ik vs a closed-loop IK written with Pinocchio (same goals).

200 reachable goals (flange poses of seeded random configurations within the limits) are
solved from the neutral pose. The reference is the damped least-squares CLIK loop of
Pinocchio's own inverse-kinematics example (log6 error, frame Jacobian in the local frame,
unit step) run from Python: a per-solve time on the same goals, not the same algorithm.
Both must reach every goal they report as converged to 1e-6 m / 1e-6 rad.
"""

from __future__ import annotations

import sys
import time
from pathlib import Path

import numpy as np

sys.path.insert(0, str(Path(__file__).resolve().parent))
from common import Case, Timing, bench_parser, pinocchio_panda, random_states, report  # noqa: E402

import dynid  # noqa: E402


def _timing(samples: list[float]) -> Timing:
    a = np.asarray(samples)
    return Timing(float(np.median(a)), float(a.min()), float(a.max()), 1, len(a))


def main(argv: list[str] | None = None) -> int:
    args = bench_parser(__doc__).parse_args(argv)
    import pinocchio as pin

    robot = dynid.panda()
    model, data = pinocchio_panda(robot)
    fid = model.getFrameId("panda_link8")
    q_true, _, _ = random_states(robot, 200, seed=0)
    goals = dynid.fk(robot, q_true)
    q0 = np.array(dynid.PANDA_NEUTRAL_Q)
    dynid.ik(robot, goals[0], q0)  # warm-up (compile or load the kernel)

    def pin_ik(T: np.ndarray) -> tuple[bool, int]:
        goal = pin.SE3(T[:3, :3], T[:3, 3])
        q = q0.copy()
        for i in range(1000):
            pin.forwardKinematics(model, data, q)
            pin.updateFramePlacement(model, data, fid)
            err = pin.log6(data.oMf[fid].actInv(goal)).vector
            if np.linalg.norm(err[:3]) < 1e-6 and np.linalg.norm(err[3:]) < 1e-6:
                return True, i
            J = pin.computeFrameJacobian(model, data, q, fid, pin.LOCAL)
            J = -pin.Jlog6(data.oMf[fid].actInv(goal)) @ J
            dq = -J.T @ np.linalg.solve(J @ J.T + 1e-12 * np.eye(6), err)
            q = np.clip(pin.integrate(model, q, dq), robot.q_min, robot.q_max)
        return False, 1000

    ours, ref, its, ok_ours, ok_ref = [], [], [], 0, 0
    for T in goals:
        t0 = time.perf_counter()
        res = dynid.ik(robot, T, q0)
        ours.append(time.perf_counter() - t0)
        its.append(res.iterations)
        ok_ours += bool(res.converged and res.position_error < 1e-6)
        t0 = time.perf_counter()
        ok, _ = pin_ik(T)
        ref.append(time.perf_counter() - t0)
        ok_ref += ok
    case = Case(
        "ik, one goal from the neutral pose",
        n=1,
        dynid=_timing(ours),
        ref=_timing(ref),
        ref_name="pinocchio CLIK",
        note="median [min, max] over 200 goals, one solve each",
    )
    report(
        "inverse kinematics (Panda flange, 200 goals)",
        [case],
        args,
        extra={
            "converged_dynid": f"{ok_ours}/200",
            "converged_pinocchio_clik": f"{ok_ref}/200",
            "dynid_median_iterations": float(np.median(its)),
            "dynid_p90_ms": float(np.percentile(ours, 90) * 1e3),
            "target": "typical solve < 1 ms",
        },
    )
    return 0


if __name__ == "__main__":
    sys.exit(main())
