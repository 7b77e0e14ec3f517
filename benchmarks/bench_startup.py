"""Start-up: one command line call on one configuration, end to end, in a fresh process.

* dynid: ``dynid fk --robot panda --q=... --json`` (the console script of this Python),
  wall time from process start to exit. Target (issue 11): under 0.8 s with a warm cache.
* reference: a fresh Python process that imports Pinocchio, loads example-robot-data's
  Panda URDF, computes the flange pose of the same configuration and prints it as JSON:
  the same task written with Pinocchio (``panda_link8`` is dynid's flange).
* floor: ``python -c "import numpy"``, the start of any numpy program here.

Both answers are checked to agree (1e-12) before timing. Each call is one fresh process;
``--repeats`` runs each (median, min, max); one untimed run of each warms the file cache.

usage: python benchmarks/bench_startup.py [--repeats 7] [--json]
"""

from __future__ import annotations

import json
import subprocess
import sys
import time
from pathlib import Path

import numpy as np

sys.path.insert(0, str(Path(__file__).resolve().parent))
from common import Case, Timing, bench_parser, check_close, panda_urdf, report  # noqa: E402

import dynid  # noqa: E402

Q = (0.1, -0.7, 0.2, -2.3, 0.1, 1.6, 0.7)

_PIN = """
import json, sys
import numpy as np
import pinocchio as pin
full = pin.buildModelFromUrdf(sys.argv[1])
lock = [full.getJointId(n) for n in ("panda_finger_joint1", "panda_finger_joint2")]
model = pin.buildReducedModel(full, lock, pin.neutral(full))
data = model.createData()
q = np.array([float(x) for x in sys.argv[2].split(",")])
pin.framesForwardKinematics(model, data, q)
print(json.dumps({"T": data.oMf[model.getFrameId("panda_link8")].homogeneous.tolist()}))
"""


def _dynid_command() -> list[str]:
    """The ``dynid`` console script next to this Python, else ``python -m dynid``."""
    script = Path(sys.executable).with_name("dynid")
    return [str(script)] if script.exists() else [sys.executable, "-m", "dynid"]


def _run(cmd: list[str]) -> tuple[float, str]:
    """Wall seconds of one process and its stdout (raises on a non-zero exit)."""
    t0 = time.perf_counter()
    out = subprocess.run(cmd, capture_output=True, text=True, check=True)
    return time.perf_counter() - t0, out.stdout


def _timing(cmd: list[str], repeats: int) -> tuple[Timing, str]:
    _run(cmd)  # warm the file cache
    runs = [_run(cmd) for _ in range(repeats)]
    s = np.array([t for t, _ in runs])
    return Timing(float(np.median(s)), float(s.min()), float(s.max()), 1, repeats), runs[0][1]


def main(argv: list[str] | None = None) -> int:
    p = bench_parser(__doc__)
    p.set_defaults(repeats=7)
    args = p.parse_args(argv)
    qs = ",".join(repr(x) for x in Q)
    ours_cmd = [*_dynid_command(), "fk", "--robot", "panda", f"--q={qs}", "--json"]
    ref_cmd = [sys.executable, "-c", _PIN, panda_urdf(), qs]
    floor_cmd = [sys.executable, "-c", "import numpy"]
    ours, out = _timing(ours_cmd, args.repeats)
    ref, out_ref = _timing(ref_cmd, args.repeats)
    floor, _ = _timing(floor_cmd, args.repeats)
    T, T_ref = np.array(json.loads(out)["T"]), np.array(json.loads(out_ref)["T"])
    check_close("flange pose, CLI vs Pinocchio", T, T_ref, atol=1e-12)
    check_close("flange pose, CLI vs library", T, dynid.fk(dynid.panda(), np.array(Q)), 1e-12)
    case = Case(
        "dynid fk --json, one configuration",
        n=1,
        dynid=ours,
        ref=ref,
        ref_name="python + pinocchio",
        note="reference: a fresh Python process: import pinocchio, load the URDF, fk, print",
    )
    report(
        "start-up: one command line call, end to end (fresh processes)",
        [case],
        args,
        extra={
            "dynid_fk_median_s": round(ours.median, 3),
            "python_import_numpy_median_s": round(floor.median, 3),
            "target_s": 0.8,
            "meets_target": bool(ours.median < 0.8),
        },
    )
    return 0


if __name__ == "__main__":
    sys.exit(main())
