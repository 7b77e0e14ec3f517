"""Dynamics and kinematics of the Panda: dynid against Pinocchio, one sample and batches.

Cases (the reference is Pinocchio on example-robot-data's Panda with the fingers locked
and the inertials and gravity of ``dynid.panda()``):

* ``rnea``: ``dynid.rnea`` vs ``pinocchio.rnea``; one sample per call, then a batch of
  ``--batch`` samples in one dynid call vs a Python loop of ``pinocchio.rnea`` over them
  (also the numpy reference path of dynid on the same batch);
* ``mass_matrix`` vs ``pinocchio.crba``; ``gravity_torques`` vs
  ``pinocchio.computeGeneralizedGravity``;
* ``fk`` (flange pose) vs ``pinocchio.forwardKinematics`` + ``updateFramePlacements`` and
  reading the frame's pose;
* ``jacobian`` (flange, base frame) vs ``pinocchio.computeFrameJacobian``
  (``LOCAL_WORLD_ALIGNED``);
* ``coriolis`` vs ``pinocchio.nonLinearEffects`` without gravity; ``forward_dynamics`` vs
  ``pinocchio.aba`` (the torques are the random accelerations' values).

Every case checks that both give the same answer before timing it; the kernels are loaded
first (single samples use them once loaded). The header also gives the time of dynid's
first one-sample calls in this process (the numpy path: no kernel is loaded for them) and,
in a fresh process with an empty numba cache, the first batch calls' compile time.

Run ``python benchmarks/bench_dynamics.py [--json out.json] [--batch N]``.
"""

from __future__ import annotations

import json
import os
import subprocess
import sys
import tempfile
import time
from pathlib import Path

import numpy as np

sys.path.insert(0, str(Path(__file__).resolve().parent))
from common import (  # noqa: E402  (the folder of this script)
    Case,
    bench_parser,
    check_close,
    measure_pair,
    pinocchio_panda,
    random_states,
    report,
)

_FIRST_CALLS = """
import json, time
import numpy as np
import dynid
robot = dynid.panda()
q = np.zeros((2, robot.n))
out = {}
for name, f in (("rnea", lambda: dynid.rnea(robot, q, q, q)),
                ("mass_matrix", lambda: dynid.mass_matrix(robot, q)),
                ("gravity_torques", lambda: dynid.gravity_torques(robot, q)),
                ("fk", lambda: dynid.fk(robot, q)),
                ("jacobian", lambda: dynid.jacobian(robot, q))):
    t = time.perf_counter()
    f()
    out[name] = time.perf_counter() - t
print(json.dumps(out))
"""


def first_calls_in_process() -> dict[str, float]:
    """Seconds of the first rnea, mass_matrix, gravity_torques, fk and jacobian calls."""
    import dynid

    robot = dynid.panda()
    q = np.zeros(robot.n)
    out = {}
    for name, f in (
        ("rnea", lambda: dynid.rnea(robot, q, q, q)),
        ("mass_matrix", lambda: dynid.mass_matrix(robot, q)),
        ("gravity_torques", lambda: dynid.gravity_torques(robot, q)),
        ("fk", lambda: dynid.fk(robot, q)),
        ("jacobian", lambda: dynid.jacobian(robot, q)),
    ):
        t = time.perf_counter()
        f()
        out[name] = time.perf_counter() - t
    return out


def cold_compile_times() -> dict[str, float] | None:
    """First batch-call seconds in a fresh process with an empty numba cache (None: no numba)."""
    try:
        import numba  # noqa: F401
    except ImportError:
        return None
    with tempfile.TemporaryDirectory() as cache:
        env = dict(os.environ, NUMBA_CACHE_DIR=cache)
        env.pop("DYNID_NO_NUMBA", None)
        out = subprocess.run(
            [sys.executable, "-c", _FIRST_CALLS], env=env, capture_output=True, text=True
        )
    if out.returncode != 0:
        raise RuntimeError(f"compile-time probe failed:\n{out.stderr}")
    return json.loads(out.stdout)


def main(argv: list[str] | None = None) -> int:
    p = bench_parser(__doc__)
    p.add_argument(
        "--no-compile-time",
        action="store_true",
        help="skip the fresh-process probe of numba's compile time",
    )
    args = p.parse_args(argv)
    first = first_calls_in_process()  # before anything else touches the kernels

    import pinocchio as pin

    import dynid
    from dynid.dynamics.rnea import kernels as dynamics_kernels
    from dynid.dynamics.rnea import rnea_numpy
    from dynid.kinematics.forward import kernels as kinematics_kernels

    # single samples take the kernels once they are loaded (a batch call loads them; a
    # one-shot call stays on the numpy path): load them before timing
    dynamics_kernels(), kinematics_kernels()
    robot = dynid.panda()
    model, data = pinocchio_panda(robot)
    fid = model.getFrameId("panda_link8")  # dynid's flange
    LWA = pin.ReferenceFrame.LOCAL_WORLD_ALIGNED
    N = args.batch
    Q, DQ, DDQ = random_states(robot, N, seed=0)
    q, dq, ddq = Q[0].copy(), DQ[0].copy(), DDQ[0].copy()
    timed = {"min_time": args.min_time, "repeats": args.repeats}
    timed_batch = dict(timed, warmup=1)

    def pin_loop(f, width):
        def run():
            out = np.empty((N,) + width)
            for k in range(N):
                out[k] = f(k)
            return out

        return run

    def sym(M):
        return np.triu(M) + np.triu(M, 1).T  # crba fills the upper triangle

    def pin_fk(x):
        pin.forwardKinematics(model, data, x)
        pin.updateFramePlacements(model, data)
        return data.oMf[fid].homogeneous

    def pin_jac(x):
        return pin.computeFrameJacobian(model, data, x, fid, LWA)

    pin_rnea_loop = pin_loop(lambda k: pin.rnea(model, data, Q[k], DQ[k], DDQ[k]), (7,))
    pin_crba_loop = pin_loop(lambda k: sym(pin.crba(model, data, Q[k])), (7, 7))
    pin_crba_raw = pin_loop(lambda k: pin.crba(model, data, Q[k]), (7, 7))
    pin_grav_loop = pin_loop(lambda k: pin.computeGeneralizedGravity(model, data, Q[k]), (7,))
    pin_fk_loop = pin_loop(lambda k: pin_fk(Q[k]), (4, 4))
    pin_jac_loop = pin_loop(lambda k: pin_jac(Q[k]), (6, 7))
    model0, data0 = pinocchio_panda(robot.with_gravity([0.0, 0.0, 0.0]))  # c(q, dq)
    pin_cor_loop = pin_loop(lambda k: pin.nonLinearEffects(model0, data0, Q[k], DQ[k]), (7,))
    pin_aba_loop = pin_loop(lambda k: pin.aba(model, data, Q[k], DQ[k], DDQ[k]), (7,))

    specs = [
        # name, samples, dynid call, pinocchio call, pinocchio answer for the check, atol
        (
            "rnea, 1 sample",
            1,
            lambda: dynid.rnea(robot, q, dq, ddq),
            lambda: pin.rnea(model, data, q, dq, ddq),
            None,
            1e-10,
        ),
        (
            "rnea, batch",
            N,
            lambda: dynid.rnea(robot, Q, DQ, DDQ),
            pin_rnea_loop,
            None,
            1e-10,
        ),
        (
            "rnea, batch, numpy path",
            N,
            lambda: rnea_numpy(robot, Q, DQ, DDQ),
            pin_rnea_loop,
            None,
            1e-10,
        ),
        (
            "mass_matrix, 1 sample",
            1,
            lambda: dynid.mass_matrix(robot, q),
            lambda: pin.crba(model, data, q),
            lambda: sym(pin.crba(model, data, q)),
            1e-10,
        ),
        (
            "mass_matrix, batch",
            N,
            lambda: dynid.mass_matrix(robot, Q),
            pin_crba_raw,
            pin_crba_loop,
            1e-10,
        ),
        (
            "gravity_torques, 1 sample",
            1,
            lambda: dynid.gravity_torques(robot, q),
            lambda: pin.computeGeneralizedGravity(model, data, q),
            None,
            1e-10,
        ),
        (
            "gravity_torques, batch",
            N,
            lambda: dynid.gravity_torques(robot, Q),
            pin_grav_loop,
            None,
            1e-10,
        ),
        ("fk flange, 1 sample", 1, lambda: dynid.fk(robot, q), lambda: pin_fk(q), None, 1e-12),
        ("fk flange, batch", N, lambda: dynid.fk(robot, Q), pin_fk_loop, None, 1e-12),
        (
            "jacobian flange, 1 sample",
            1,
            lambda: dynid.jacobian(robot, q),
            lambda: pin_jac(q),
            None,
            1e-12,
        ),
        ("jacobian flange, batch", N, lambda: dynid.jacobian(robot, Q), pin_jac_loop, None, 1e-12),
        (
            "coriolis, 1 sample",
            1,
            lambda: dynid.coriolis(robot, q, dq),
            lambda: pin.nonLinearEffects(model0, data0, q, dq),
            None,
            1e-10,
        ),
        ("coriolis, batch", N, lambda: dynid.coriolis(robot, Q, DQ), pin_cor_loop, None, 1e-10),
        (
            "forward_dynamics, 1 sample",
            1,
            lambda: dynid.forward_dynamics(robot, q, dq, ddq),
            lambda: pin.aba(model, data, q, dq, ddq),
            None,
            1e-8,
        ),
        (
            "forward_dynamics, batch",
            N,
            lambda: dynid.forward_dynamics(robot, Q, DQ, DDQ),
            pin_aba_loop,
            None,
            1e-8,
        ),
    ]
    notes = {
        "rnea, batch": "reference: Python loop of pinocchio.rnea over the samples",
        "rnea, batch, numpy path": "dynid's numpy reference path (rnea_numpy), not the kernel",
        "mass_matrix, 1 sample": "pinocchio.crba fills the upper triangle only (timed as is)",
        "fk flange, 1 sample": "reference: forwardKinematics + updateFramePlacements + oMf read",
        "coriolis, 1 sample": "reference: nonLinearEffects of the model without gravity",
        "forward_dynamics, 1 sample": "reference: pinocchio.aba (dynid: RNEA, CRBA, Cholesky)",
    }
    cases = []
    for name, n, ours, ref, ref_answer, atol in specs:
        check_close(name, ours(), (ref_answer or ref)(), atol)
        kw = timed_batch if n > 1 else timed
        cases.append(Case(name, n, *measure_pair(ours, ref, **kw), note=notes.get(name, "")))
    cold = None if args.no_compile_time else cold_compile_times()
    extra = {
        "batch samples": N,
        "first dynid one-sample calls in this process, s (numpy path)": first,
        "first dynid batch calls in a fresh process with an empty numba cache, s (compile)": (
            "skipped" if args.no_compile_time else cold
        ),
    }
    report("dynamics: dynid vs pinocchio (Panda, 7 joints)", cases, args, extra)
    return 0


if __name__ == "__main__":
    sys.exit(main())
