"""Run every ``bench_*.py`` of this folder, one fresh process each (``make bench``).

``python benchmarks/run_all.py [--json DIR] [--only NAME ...] [--short] [-- ARGS ...]``

Scripts are found by name (``bench_*.py``) and run in name order, each with this Python in
its own process, so that one benchmark's imports, compiled code and memory do not affect
the next; their output is shown as it comes.

``--json DIR``
    Run each script with ``--json`` (every ``bench_*.py`` then prints one JSON object
    instead of its table) and save that output as ``DIR/<script name>.json``.
``--only NAME ...``
    Run only these scripts (``dynamics`` or ``bench_dynamics.py`` for ``bench_dynamics.py``).
``-- ARGS ...``
    Pass ARGS to every script run (for example ``-- --repeats 7``); the scripts' options
    differ, so combine this with ``--only``.
``--short``
    Skip the long scripts of :data:`LONG` (``bench_memory.py``: every command's peak
    memory on a 5-million-row log, about half an hour), run by default so that ``make
    bench`` prints every command's peak and whether the target is met.

The exit code is non-zero when a script fails, for example because dynid and the
reference disagree.
"""

from __future__ import annotations

import argparse
import json
import subprocess
import sys
import time
from pathlib import Path

HERE = Path(__file__).resolve().parent


#: Scripts that take many minutes: skipped with ``--short`` (unless named by ``--only``).
LONG = ("bench_memory.py",)


def scripts() -> list[Path]:
    """The benchmark scripts of this folder, sorted by name."""
    return sorted(HERE.glob("bench_*.py"))


def main(argv: list[str] | None = None) -> int:
    argv = list(sys.argv[1:] if argv is None else argv)
    passed: list[str] = []
    if "--" in argv:
        cut = argv.index("--")
        argv, passed = argv[:cut], argv[cut + 1 :]
    p = argparse.ArgumentParser(description=(__doc__ or "").strip().splitlines()[0])
    p.add_argument("--json", metavar="DIR", help="save each script's JSON as DIR/<script>.json")
    p.add_argument("--only", nargs="+", metavar="NAME", help="run only these scripts")
    p.add_argument("--short", action="store_true", help=f"skip {', '.join(LONG)}")
    args = p.parse_args(argv)
    found = scripts()
    if args.only:
        want = {n.removeprefix("bench_").removesuffix(".py") for n in args.only}
        found = [s for s in found if s.stem.removeprefix("bench_") in want]
    elif args.short:
        skipped = [s.name for s in found if s.name in LONG]
        found = [s for s in found if s.name not in LONG]
        if skipped:
            print(f"skipped (long; run without --short): {', '.join(skipped)}", flush=True)
    if not found:
        print("no benchmark scripts to run", file=sys.stderr)
        return 1
    out_dir = Path(args.json) if args.json else None
    if out_dir is not None:
        out_dir.mkdir(parents=True, exist_ok=True)
    failed = []
    for script in found:
        cmd = [sys.executable, str(script), *passed]
        print(f"\n>>> {script.name}", flush=True)
        t = time.perf_counter()
        if out_dir is None:
            rc = subprocess.run(cmd).returncode
        else:
            res = subprocess.run([*cmd, "--json"], stdout=subprocess.PIPE, text=True)
            rc = res.returncode
            if rc == 0:
                try:
                    json.loads(res.stdout)
                except ValueError:
                    print(f"{script.name} did not print one JSON object", file=sys.stderr)
                    rc = 1
                (out_dir / f"{script.stem}.json").write_text(res.stdout)
        status = "ok" if rc == 0 else f"FAILED (exit code {rc})"
        print(f"<<< {script.name}: {status}, {time.perf_counter() - t:.1f} s", flush=True)
        if rc != 0:
            failed.append(script.name)
    if failed:
        print(f"\nfailed: {', '.join(failed)}", file=sys.stderr)
        return 1
    return 0


if __name__ == "__main__":
    sys.exit(main())
