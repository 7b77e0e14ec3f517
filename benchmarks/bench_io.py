"""Scale of the file route: validate a 2,000,001-row torque log; time and peak memory.

``dynid simulate`` writes a log of ``--rows`` samples at 1 kHz (the Panda on the sinusoids
of Gaz et al. 2019, with sensor noise); then ``dynid validate --robot panda`` reads it
(strictly: columns, row count, NaN, repeated timestamps), filters it, computes the
rigid-body and friction torques and writes validation.json. Each command runs in its own
process; the time is the wall-clock time of the process, the memory its peak resident
set size (``os.wait4``). Targets (issue 12): under 30 s and under 1.5 GB for the
validation. There is no reference library here: the check is that validate succeeds and
finds the relative error the sensor noise implies (< 1 %).

``python benchmarks/bench_io.py [--rows N] [--dir DIR] [--keep] [--json [PATH]]``
"""

from __future__ import annotations

import argparse
import json
import os
import shutil
import subprocess
import sys
import tempfile
import time
from pathlib import Path

sys.path.insert(0, str(Path(__file__).resolve().parent))  # this folder
from common import environment, format_environment  # noqa: E402

#: Targets of issue 12 for the validation of a 2,000,001-row log.
TARGET_SECONDS = 30.0
TARGET_PEAK_MB = 1500.0


def run(cmd: list[str]) -> dict:
    """Run ``cmd``; return its exit code, wall time [s], CPU time [s] (user + system: what
    the time would be on an idle machine, as long as the command is single-threaded) and
    peak resident memory [MiB]."""
    t0 = time.perf_counter()
    proc = subprocess.Popen(cmd, stdout=subprocess.DEVNULL, stderr=subprocess.PIPE)
    _, status, usage = os.wait4(proc.pid, 0)
    seconds = time.perf_counter() - t0
    err = proc.stderr.read().decode() if proc.stderr else ""
    proc.returncode = os.waitstatus_to_exitcode(status)
    kib = usage.ru_maxrss if sys.platform.startswith("linux") else usage.ru_maxrss / 1024.0
    return {
        "exit_code": proc.returncode,
        "seconds": seconds,
        "cpu_seconds": usage.ru_utime + usage.ru_stime,
        "peak_mb": kib / 1024.0,
        "stderr": err.strip()[-500:],
    }


def main(argv: list[str] | None = None) -> int:
    p = argparse.ArgumentParser(description=(__doc__ or "").strip().splitlines()[0])
    p.add_argument("--rows", type=int, default=2_000_001, help="samples of the log")
    p.add_argument("--dir", type=Path, default=None, help="work folder (default: temporary)")
    p.add_argument("--keep", action="store_true", help="keep the log and the results")
    p.add_argument("--json", nargs="?", const="-", default=None, metavar="PATH")
    args = p.parse_args(argv)
    work = Path(tempfile.mkdtemp(prefix="dynid-bench-io-")) if args.dir is None else args.dir
    work.mkdir(parents=True, exist_ok=True)
    log = work / "log.csv"
    dynid = [sys.executable, "-m", "dynid"]
    duration = (args.rows - 1) / 1000.0
    try:
        sim = run(
            dynid
            + ["simulate", "--duration", f"{duration:.3f}", "--rate", "1000", "--seed", "1"]
            + ["--out", str(log)]
        )
        if sim["exit_code"] != 0:
            print(f"simulate failed: {sim['stderr']}", file=sys.stderr)
            return 1
        size_mb = log.stat().st_size / 1e6
        val = run(
            dynid
            + ["validate", "--robot", "panda", "--data", str(log), "--out", str(work / "val")]
            + ["--no-figures"]
        )
        if val["exit_code"] != 0:
            print(f"validate failed: {val['stderr']}", file=sys.stderr)
            return 1
        doc = json.loads((work / "val" / "validation.json").read_text())
        rel = float(doc["relative_error_percent"])
        if not rel < 1.0:
            print(f"validate found a relative error of {rel} %, expected < 1 %", file=sys.stderr)
            return 1
    finally:
        if not args.keep and args.dir is None:
            shutil.rmtree(work, ignore_errors=True)
    record = {
        "topic": "io",
        "environment": environment(),
        "rows": args.rows,
        "file_mb": size_mb,
        "simulate": {k: sim[k] for k in ("seconds", "cpu_seconds", "peak_mb")},
        "validate": {k: val[k] for k in ("seconds", "cpu_seconds", "peak_mb")},
        "load_average": os.getloadavg()[0],
        "relative_error_percent": rel,
        "targets": {"seconds": TARGET_SECONDS, "peak_mb": TARGET_PEAK_MB},
        "meets_targets": val["seconds"] < TARGET_SECONDS and val["peak_mb"] < TARGET_PEAK_MB,
    }
    if args.json == "-":
        print(json.dumps(record))
        return 0
    print(format_environment(record["environment"]))
    print(f"torque log: {args.rows:,} rows at 1 kHz, {size_mb:.0f} MB of CSV")
    print(f"load average at the end {record['load_average']:.2f} (a busy machine: wall > CPU)")
    print(f"{'command':<10} {'wall [s]':>9} {'CPU [s]':>8} {'peak memory [MiB]':>18}")
    for name in ("simulate", "validate"):
        r = record[name]
        print(f"{name:<10} {r['seconds']:>9.1f} {r['cpu_seconds']:>8.1f} {r['peak_mb']:>18.0f}")
    print(
        f"validate: relative error {rel:.3f} %; targets < {TARGET_SECONDS:g} s and "
        f"< {TARGET_PEAK_MB:g} MB: {'met' if record['meets_targets'] else 'NOT met'}"
    )
    if args.json:
        Path(args.json).write_text(json.dumps(record) + "\n")
    return 0


if __name__ == "__main__":
    sys.exit(main())
