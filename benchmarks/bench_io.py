"""Scale of the file route: a 5,000,001-row torque log, and static data of a 50-joint arm,
under a 4 GB address-space limit.

``dynid simulate`` writes a log of ``--rows`` samples at 1 kHz (the Panda on a seeded
Fourier trajectory, with sensor noise); then, each in its own process under
``RLIMIT_AS`` of ``--limit-gb`` GiB (where the platform has it), ``dynid identify``,
``dynid identify --consistent`` and ``dynid validate --robot panda`` read it (strictly:
columns, row count, NaN, repeated timestamps), filter and decimate it and fit or predict.
The classical route streams its regressor over blocks of rows (the stacked regressor of
a 5-million-row log is 1.75 million rows of 65 columns); the same identification with the
regressor stacked whole (``DYNID_MAX_STACK_BYTES`` raised, no limit) is timed beside it
for the ratio. The time is the wall-clock time of the process, the CPU time its user +
system time, the memory its peak resident set size (``os.wait4``). Targets (issue 20):
every command succeeds under 4 GiB. There is no reference library here: the checks are
that every command succeeds, that the streamed and the stacked fits agree and that
validate finds the relative error the sensor noise implies (< 1 %).

Static data of a long chain: ``dynid acquire-static`` writes ``--static-n`` (1010)
configurations of a seeded 50-joint revolute arm (a TOML robot written here; 1325 rows of
``[tril M; g]`` per configuration, 500 standard parameters), and ``dynid identify``
reads them under the same limit (the stacked regressor would be 3.7 GB, the Gram matrices
of its rows 1.3 GB); the check is that the noise-free data are fitted to rounding
(relative error below 1e-6 %). ``--static-joints 0`` skips it. ``simulate`` computes and
writes the log in blocks of samples, so its memory does not grow with the log.

``python benchmarks/bench_io.py [--rows N] [--data LOG] [--limit-gb G] [--dir DIR] [--keep]
[--static-joints J] [--static-n N] [--json [PATH]]``
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

#: The address-space limit of issue 20 [GiB] under which every command must succeed.
TARGET_LIMIT_GB = 4.0


def run(cmd: list[str], *, limit_gb: float | None = None, env: dict | None = None) -> dict:
    """Run ``cmd`` (under an address-space limit of ``limit_gb`` GiB when given and the
    platform has RLIMIT_AS); return its exit code, wall time [s], CPU time [s] (user +
    system) and peak resident memory [MiB]."""

    def limit() -> None:
        import resource

        cap = int(limit_gb * 2**30)  # type: ignore[operator]
        resource.setrlimit(resource.RLIMIT_AS, (cap, cap))

    pre = limit if limit_gb is not None and _has_rlimit_as() else None
    t0 = time.perf_counter()
    proc = subprocess.Popen(
        cmd,
        stdout=subprocess.DEVNULL,
        stderr=subprocess.PIPE,
        preexec_fn=pre,
        env=None if env is None else {**os.environ, **env},
    )
    err = proc.stderr.read().decode() if proc.stderr else ""
    _, status, usage = os.wait4(proc.pid, 0)
    seconds = time.perf_counter() - t0
    proc.returncode = os.waitstatus_to_exitcode(status)
    kib = usage.ru_maxrss if sys.platform.startswith("linux") else usage.ru_maxrss / 1024.0
    return {
        "exit_code": proc.returncode,
        "seconds": seconds,
        "cpu_seconds": usage.ru_utime + usage.ru_stime,
        "peak_mb": kib / 1024.0,
        "limit_gb": limit_gb if pre is not None else None,
        "stderr": err.strip()[-500:],
    }


def _has_rlimit_as() -> bool:
    try:
        import resource
    except ImportError:  # not on Windows
        return False
    return hasattr(resource, "RLIMIT_AS")


def _arm_toml(path: Path, n: int) -> None:
    """A seeded revolute arm of ``n`` joints (random modified DH constants and inertias)."""
    import numpy as np

    import dynid
    from dynid.io.robot.toml import save_toml

    rng = np.random.default_rng(0)
    a, alpha = rng.uniform(0.05, 0.2, n), rng.choice([-np.pi / 2, np.pi / 2, 0.0], n)
    a[0] = alpha[0] = 0.0
    A = rng.normal(size=(n, 3, 3))
    robot = dynid.Robot.from_mdh(
        a,
        rng.uniform(0.0, 0.1, n),
        alpha,
        mass=rng.uniform(0.5, 2.0, n),
        com=rng.uniform(-0.05, 0.05, (n, 3)),
        inertia=0.01 * (A @ A.transpose(0, 2, 1) + np.eye(3)),
        q_min=np.full(n, -2.8),
        q_max=np.full(n, 2.8),
        name=f"arm{n}",
    )
    save_toml(path, robot)


def _static(work: Path, dynid: list[str], joints: int, n_conf: int, lim: float) -> dict:
    """acquire-static and identify of a long arm's static data, each under the limit."""
    arm, data = work / f"arm{joints}.toml", work / f"static{joints}.csv"
    _arm_toml(arm, joints)
    out: dict[str, dict] = {}
    out[f"acquire-static {joints} joints"] = run(
        dynid
        + ["acquire-static", "--robot", str(arm), "--n", str(n_conf), "--seed", "1"]
        + ["--out", str(data)],
        limit_gb=lim,
    )
    ident = work / f"static{joints}-id"
    out[f"identify static {joints} joints"] = run(
        dynid
        + ["identify", "--robot", str(arm), "--data", str(data), "--no-figures"]
        + ["--out", str(ident)],
        limit_gb=lim,
    )
    if out[f"identify static {joints} joints"]["exit_code"] == 0:
        doc = json.loads((ident / "identification.json").read_text())
        err = float(doc["relative_error_percent"])
        out[f"identify static {joints} joints"]["relative_error_percent"] = err
        if not err < 1e-6:
            out[f"identify static {joints} joints"]["exit_code"] = -1
            out[f"identify static {joints} joints"]["stderr"] = f"relative error {err} %"
    return out


def main(argv: list[str] | None = None) -> int:
    p = argparse.ArgumentParser(description=(__doc__ or "").strip().splitlines()[0])
    p.add_argument("--rows", type=int, default=5_000_001, help="samples of the log")
    p.add_argument("--data", type=Path, default=None, help="an existing log (no simulate)")
    p.add_argument("--limit-gb", type=float, default=TARGET_LIMIT_GB, help="RLIMIT_AS [GiB]")
    p.add_argument("--dir", type=Path, default=None, help="work folder (default: temporary)")
    p.add_argument("--keep", action="store_true", help="keep the log and the results")
    p.add_argument("--json", nargs="?", const="-", default=None, metavar="PATH")
    p.add_argument("--static-joints", type=int, default=50, help="joints of the arm (0: skip)")
    p.add_argument("--static-n", type=int, default=1010, help="static configurations")
    args = p.parse_args(argv)
    work = Path(tempfile.mkdtemp(prefix="dynid-bench-io-")) if args.dir is None else args.dir
    work.mkdir(parents=True, exist_ok=True)
    log = work / "log.csv" if args.data is None else args.data
    dynid = [sys.executable, "-m", "dynid"]
    duration = (args.rows - 1) / 1000.0
    lim = args.limit_gb
    results: dict[str, dict] = {}
    try:
        if args.data is None:
            results["simulate"] = run(
                dynid
                + ["simulate", "--trajectory", "fourier", "--duration", f"{duration:.3f}"]
                + ["--rate", "1000", "--seed", "1", "--out", str(log)],
                limit_gb=lim,
            )
        data = ["--robot", "panda", "--data", str(log), "--no-figures"]
        results["identify"] = run(
            dynid + ["identify", *data, "--out", str(work / "id")], limit_gb=lim
        )
        results["identify --consistent"] = run(
            dynid + ["identify", "--consistent", *data, "--out", str(work / "cons")], limit_gb=lim
        )
        results["validate"] = run(
            dynid + ["validate", *data, "--out", str(work / "val")], limit_gb=lim
        )
        results["identify, stacked"] = run(
            dynid + ["identify", *data, "--out", str(work / "id-stacked")],
            env={"DYNID_MAX_STACK_BYTES": str(1 << 50)},
        )
        if args.static_joints:
            results.update(_static(work, dynid, args.static_joints, args.static_n, lim))
        failed = [k for k, r in results.items() if r["exit_code"] != 0]
        for k in failed:
            print(f"{k} failed: {results[k]['stderr']}", file=sys.stderr)
        if failed:
            return 1
        doc = json.loads((work / "id" / "identification.json").read_text())
        ref = json.loads((work / "id-stacked" / "identification.json").read_text())
        agree = max(
            abs(x["value"] - y["value"]) / max(abs(y["value"]), 1e-12)
            for x, y in zip(doc["coefficients"], ref["coefficients"], strict=True)
        )
        rel = float(
            json.loads((work / "val" / "validation.json").read_text())["relative_error_percent"]
        )
        if not rel < 1.0:
            print(f"validate found a relative error of {rel} %, expected < 1 %", file=sys.stderr)
            return 1
        size_mb = log.stat().st_size / 1e6
        n_rows = int(doc["metadata"]["n_samples_log"])
    finally:
        if not args.keep and args.dir is None:
            shutil.rmtree(work, ignore_errors=True)
    keys = ("seconds", "cpu_seconds", "peak_mb", "limit_gb")
    record = {
        "topic": "io",
        "environment": environment(),
        "rows": n_rows,
        "file_mb": size_mb,
        "commands": {k: {f: r[f] for f in keys} for k, r in results.items()},
        "streamed_vs_stacked": {
            "peak_ratio": results["identify"]["peak_mb"] / results["identify, stacked"]["peak_mb"],
            "cpu_ratio": results["identify"]["cpu_seconds"]
            / results["identify, stacked"]["cpu_seconds"],
            "max_relative_difference_beta": agree,
        },
        "load_average": os.getloadavg()[0],
        "relative_error_percent": rel,
        "target_limit_gb": TARGET_LIMIT_GB,
        "meets_targets": lim <= TARGET_LIMIT_GB and _has_rlimit_as(),
    }
    if args.json == "-":
        print(json.dumps(record))
        return 0
    print(format_environment(record["environment"]))
    print(f"torque log: {n_rows:,} rows at 1 kHz, {size_mb:.0f} MB of CSV")
    print(f"load average at the end {record['load_average']:.2f} (a busy machine: wall > CPU)")
    print(f"{'command':<24} {'wall [s]':>9} {'CPU [s]':>8} {'peak [MiB]':>11} {'limit':>7}")
    for name, r in record["commands"].items():
        shown = "none" if r["limit_gb"] is None else f"{r['limit_gb']:g} GiB"
        print(
            f"{name:<24} {r['seconds']:>9.1f} {r['cpu_seconds']:>8.1f} {r['peak_mb']:>11.0f} "
            f"{shown:>7}"
        )
    s = record["streamed_vs_stacked"]
    print(
        f"identify streamed / stacked: peak memory x{s['peak_ratio']:.2f}, CPU "
        f"x{s['cpu_ratio']:.2f}, estimates agree to {s['max_relative_difference_beta']:.1e}"
    )
    print(
        f"validate: relative error {rel:.3f} %; every command under {lim:g} GiB: "
        f"{'met' if record['meets_targets'] else 'NOT measured under the limit'}"
    )
    if args.json:
        Path(args.json).write_text(json.dumps(record) + "\n")
    return 0


if __name__ == "__main__":
    sys.exit(main())
