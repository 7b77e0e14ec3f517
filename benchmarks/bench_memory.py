"""Peak memory of every command on a long log: ``simulate``, reading it, ``identify``,
``identify --consistent``, ``validate``, ``observe`` and static data of a long chain.

Each case runs in its own process; its peak resident set size comes from ``os.wait4``
(the kernel's ``ru_maxrss``, what ``/usr/bin/time -v`` prints as "Maximum resident set
size"). The cases, on a log of ``--rows`` samples (5,000,001 by default) at 1 kHz of the
Panda on a seeded Fourier series with sensor noise:

* ``simulate`` of the paper's sinusoids and of the Fourier series, written as CSV
  (computed and written in blocks of samples);
* reading the log as a ``--columns`` CSV (``dynid.io.columns``), its columns renamed as
  another tool writes them (``time_s, pos_0.., vel_0.., eff_0..``, a text column the map
  does not name, no ``# rows:`` line), and dynid's own CSV of it;
* ``identify`` (streamed least squares, the log prepared in blocks, the held-out
  figures' data), ``identify --consistent`` and ``validate --robot panda`` (the log
  prepared and predicted a block at a time);
* ``observe --calibrate`` of the Panda's own parameters (the momentum observer's batch
  path a block at a time, the thresholds from running maxima; with ``--no-figures`` no
  full-length residual is kept) and ``observe --thresholds`` with those thresholds
  (detection a block at a time: the events carried across blocks, ``residuals.csv``
  written a block at a time, no full-length series with ``--no-figures``: 1.15-1.28 GB on
  the 5-million-row log, met; it was 3.0 GB with the series kept whole);
* static data of a long chain (``--static-joints`` 50, ``--static-n`` 200 configurations
  written by ``acquire-static``): the single-step problem of ``retrieve --static
  --method penalty`` (``static_problem``; its residual on the arm's own exact data must be
  rounding).

Target (issue 28): every case under ``--target-gb`` (1.5 GB); each line says whether it
is met (last measured: largest peak 1.49 GB, ``identify``, whose stepping friction columns
are filtered before decimation, a few tens of MB a span; 1.45 GB before).
The checks: the ``--columns`` read gives the same log as dynid's own CSV (sums of every
signal equal); validate finds the relative error the sensor noise implies (< 1 %).
Time: ``bench_io.py``.

Long (about half an hour on two cores): ``run_all.py --short`` skips it.
``--data LOG`` measures an existing log of the Panda (``simulate`` is not run).

``python benchmarks/bench_memory.py [--rows N] [--data LOG] [--dir DIR] [--keep]
[--target-gb G] [--static-joints J] [--static-n N] [--json [PATH]]``
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
from bench_io import _arm_toml  # noqa: E402
from common import environment, format_environment  # noqa: E402

#: Peak memory allowed on the 5-million-row log [GB] (issue 28).
TARGET_GB = 1.5
#: The columns of a log written by another tool, as ``--columns`` maps them.
COLUMNS = "t=time_s,q=pos_{i0},dq=vel_{i0},tau=eff_{i0}"


def run(cmd: list[str]) -> dict:
    """Run ``cmd``; its exit code, wall time [s], CPU time [s], peak resident memory [MB]
    and standard output."""
    t0 = time.perf_counter()
    with tempfile.TemporaryFile() as fo, tempfile.TemporaryFile() as fe:
        proc = subprocess.Popen(cmd, stdout=fo, stderr=fe)
        _, status, usage = os.wait4(proc.pid, 0)
        fo.seek(0)
        fe.seek(0)
        out, err = fo.read(), fe.read().decode(errors="replace")
    kib = usage.ru_maxrss if sys.platform.startswith("linux") else usage.ru_maxrss / 1024.0
    return {
        "exit_code": os.waitstatus_to_exitcode(status),
        "seconds": time.perf_counter() - t0,
        "cpu_seconds": usage.ru_utime + usage.ru_stime,
        "peak_mb": kib * 1024 / 1e6,
        "stderr": err.strip()[-500:],
        "stdout": out.decode(),
    }


#: A process that reads a log (``--columns`` CSV or dynid's own) and prints its sums.
READ = """
import json, sys
from dynid.io.columns import load_mapped_torque_log, parse_column_map
from dynid.io.torque_log import load_torque_log
path, cmap = sys.argv[1], sys.argv[2]
log = load_torque_log(path) if cmap == "-" else load_mapped_torque_log(
    path, parse_column_map(cmap), n=7).log
print(json.dumps({k: float(getattr(log, k).sum()) for k in ("t", "q", "dq", "tau")}))
"""


#: A process that builds the single-step penalty problem of static data and prints its
#: relative residual (the arm's own exact data: rounding) and its rows (the base parameters).
STATIC = """
import json, sys
import dynid
from dynid.feasibility.penalty.objective import static_problem
from dynid.io.static_data import load_static_data
robot = dynid.Robot.from_toml(sys.argv[1])
data = load_static_data(sys.argv[2], robot)[0]
p = static_problem(robot, data.q, data.M, data.g)
res = (p.report_offset ** 0.5) / p.report_norm
print(json.dumps({"rows": int(p.A.shape[0]), "relative_residual": res}))
"""


def renamed(log: Path, out: Path) -> None:
    """``log`` (dynid's CSV) with the header of another tool and an extra text column,
    rewritten a line at a time (the benchmark itself holds no log in memory)."""
    with open(log, encoding="utf-8") as src, open(out, "w", encoding="utf-8") as dst:
        for line in src:
            if line.startswith("#"):
                continue
            names = line.rstrip("\n").split(",")
            break
        new = []
        for c in names:
            if c == "t":
                new.append("time_s")
            else:
                kind, k = c.rstrip("0123456789"), int(c[len(c.rstrip("0123456789")) :]) - 1
                new.append({"q": "pos", "dq": "vel", "tau": "eff"}[kind] + f"_{k}")
        dst.write(",".join(new) + ",status\n")
        for line in src:
            dst.write(line.rstrip("\n") + ",ok\n")


def _static(work: Path, dynid: list[str], joints: int, n_conf: int) -> dict:
    """acquire-static of a long arm, then the penalty problem of its static data."""
    arm, data = work / f"arm{joints}.toml", work / f"static{joints}.csv"
    _arm_toml(arm, joints)
    out = {}
    cmd = ["acquire-static", "--robot", str(arm), "--n", str(n_conf), "--seed", "1"]
    out[f"acquire-static {joints} joints"] = run(dynid + cmd + ["--out", str(data)])
    if out[f"acquire-static {joints} joints"]["exit_code"] == 0:
        key = f"retrieve --static problem {joints} j."
        out[key] = r = run([sys.executable, "-c", STATIC, str(arm), str(data)])
        if r["exit_code"] == 0:
            res = json.loads(r["stdout"])["relative_residual"]
            if not res < 1e-9:
                r["exit_code"], r["stderr"] = -1, f"relative residual {res} on exact data"
    return out


def _commands(work: Path, dynid: list[str], log: Path) -> dict[str, dict]:
    """identify, identify --consistent, validate, observe --calibrate and observe
    --thresholds (detection with the thresholds just calibrated) of the log."""
    data = ["--data", str(log), "--no-figures"]
    out: dict[str, dict] = {}
    ident = ["identify", "--robot", "panda", *data]
    out["identify"] = run(dynid + ident + ["--out", str(work / "id")])
    out["identify --consistent"] = run(dynid + ident + ["--consistent", "--out", str(work / "c")])
    out["validate"] = run(
        dynid + ["validate", "--robot", "panda", *data, "--out", str(work / "val")]
    )
    out["observe --calibrate"] = run(
        dynid + ["observe", "--params", "panda", "--calibrate", *data, "--out", str(work / "obs")]
    )
    thresholds = ["--thresholds", str(work / "obs" / "thresholds.json")]
    out["observe --thresholds"] = run(
        dynid + ["observe", "--params", "panda", *thresholds, *data, "--out", str(work / "det")]
    )
    return out


def main(argv: list[str] | None = None) -> int:
    p = argparse.ArgumentParser(description=(__doc__ or "").strip().splitlines()[0])
    p.add_argument("--rows", type=int, default=5_000_001, help="samples of the log")
    p.add_argument("--data", type=Path, default=None, help="an existing log (no simulate)")
    p.add_argument("--dir", type=Path, default=None, help="work folder (default: temporary)")
    p.add_argument("--keep", action="store_true", help="keep the logs and the results")
    p.add_argument("--target-gb", type=float, default=TARGET_GB, help="peak allowed [GB]")
    p.add_argument("--static-joints", type=int, default=50, help="joints of the arm (0: skip)")
    p.add_argument("--static-n", type=int, default=200, help="static configurations")
    p.add_argument("--json", nargs="?", const="-", default=None, metavar="PATH")
    args = p.parse_args(argv)
    work = Path(tempfile.mkdtemp(prefix="dynid-bench-mem-")) if args.dir is None else args.dir
    work.mkdir(parents=True, exist_ok=True)
    dynid = [sys.executable, "-m", "dynid"]
    duration = f"{(args.rows - 1) / 1000.0:.3f}"
    log = work / "log.csv" if args.data is None else args.data
    other = work / "other.csv"
    results: dict[str, dict] = {}
    try:
        if args.data is None:
            sim = ["simulate", "--duration", duration, "--rate", "1000", "--seed", "1"]
            results["simulate (sinusoids)"] = run(dynid + sim + ["--out", str(work / "sin.csv")])
            (work / "sin.csv").unlink(missing_ok=True)
            results["simulate (fourier)"] = run(
                dynid + sim + ["--trajectory", "fourier", "--out", str(log)]
            )
        if log.exists():
            renamed(log, other)
            read = [sys.executable, "-c", READ]
            results["read --columns log"] = run(read + [str(other), COLUMNS])
            other.unlink(missing_ok=True)
            results["read the log"] = run(read + [str(log), "-"])
            results.update(_commands(work, dynid, log))
        if args.static_joints:
            results.update(_static(work, dynid, args.static_joints, args.static_n))
        failed = [k for k, r in results.items() if r["exit_code"] != 0]
        for k in failed:
            print(f"{k} failed: {results[k]['stderr']}", file=sys.stderr)
        if failed or "read the log" not in results:
            return 1
        a = json.loads(results["read --columns log"]["stdout"])
        b = json.loads(results["read the log"]["stdout"])
        if a != b:
            print(f"the --columns log differs from the log: {a} != {b}", file=sys.stderr)
            return 1
        rel = float(
            json.loads((work / "val" / "validation.json").read_text())["relative_error_percent"]
        )
        if not rel < 1.0:
            print(f"validate found a relative error of {rel} %, expected < 1 %", file=sys.stderr)
            return 1
        size_mb = log.stat().st_size / 1e6
    finally:
        if not args.keep and args.dir is None:
            shutil.rmtree(work, ignore_errors=True)
    worst = max(r["peak_mb"] for r in results.values()) / 1e3
    record = {
        "topic": "memory",
        "environment": environment(),
        "rows": args.rows,
        "file_mb": size_mb,
        "commands": {
            k: {
                **{f: r[f] for f in ("seconds", "cpu_seconds", "peak_mb")},
                "meets_target": r["peak_mb"] / 1e3 < args.target_gb,
            }
            for k, r in results.items()
        },
        "relative_error_percent": rel,
        "peak_gb": worst,
        "target_gb": args.target_gb,
        "meets_target": worst < args.target_gb,
        "load_average": os.getloadavg()[0],
    }
    if args.json == "-":
        print(json.dumps(record))
        return 0 if record["meets_target"] else 1
    print(format_environment(record["environment"]))
    print(f"log: {args.rows:,} rows at 1 kHz, {size_mb:.0f} MB of CSV")
    print(f"load average at the end {record['load_average']:.2f} (a busy machine: wall > CPU)")
    w = max(len(k) for k in record["commands"])
    target = f"target < {args.target_gb:g} GB"
    print(f"{'command':<{w}} {'wall [s]':>9} {'CPU [s]':>8} {'peak [MB]':>10}  {target}")
    for name, r in record["commands"].items():
        print(
            f"{name:<{w}} {r['seconds']:>9.1f} {r['cpu_seconds']:>8.1f} {r['peak_mb']:>10.0f}  "
            f"{'met' if r['meets_target'] else 'NOT met'}"
        )
    print(
        f"--columns log = the log; validate: relative error {rel:.3f} %; largest peak "
        f"{worst:.2f} GB, {target} for every command: "
        f"{'met' if record['meets_target'] else 'NOT met'}"
    )
    if args.json:
        Path(args.json).write_text(json.dumps(record) + "\n")
    return 0 if record["meets_target"] else 1


if __name__ == "__main__":
    sys.exit(main())
