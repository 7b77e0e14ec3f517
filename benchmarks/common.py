"""Shared timing, environment header and reporting for the ``bench_*.py`` scripts.

Every benchmark times dynid and a reference (Pinocchio) in one process on the same inputs,
checks first that both give the same answer, and prints the ratio (STYLE.md section 9).
A script built on this module (``benchmarks/bench_<topic>.py``, found by ``run_all.py``)
looks like::

    sys.path.insert(0, str(Path(__file__).resolve().parent))  # this folder
    from common import Case, bench_parser, check_close, measure, report

    args = bench_parser(__doc__).parse_args(argv)
    check_close("rnea", ours(), reference(), atol=1e-10)
    case = Case("rnea, 1 sample", n=1,
                dynid=measure(ours, min_time=args.min_time, repeats=args.repeats),
                ref=measure(reference, min_time=args.min_time, repeats=args.repeats))
    report("dynamics", [case], args)

API
---
``measure(fn, *, min_time=0.2, repeats=5, warmup=3) -> Timing``
    Calls ``fn()`` ``warmup`` times, then ``timeit.Timer.autorange`` picks the number of
    calls per repeat (a repeat lasts at least 0.2 s, scaled up to ``min_time``) and
    ``timeit.Timer.repeat`` runs ``repeats`` repeats. The garbage collector is off while
    timing (timeit's default).
``measure_pair(ours, ref, **same) -> (Timing, Timing)``
    :func:`measure` of both with their repeats alternated, so that both see the same load
    drift (the single-sample cases, whose ratios drift most).
``Timing(median, min, max, number, repeats)``
    Seconds per call over the repeats; ``timing.per(k)`` divides by ``k`` (per sample).
``Case(name, n, dynid, ref, ref_name="pinocchio", note="")``
    One comparison: ``n`` samples per call, the two timings per call; ``case.speedup`` is
    ``ref.median / dynid.median`` per sample (> 1: dynid is faster).
``check_close(name, ours, ref, atol)``
    Raises ``AssertionError`` naming the case when the answers differ by more than ``atol``.
``environment() -> dict`` and ``format_environment(env) -> str``
    Python, numpy, scipy, pinocchio, numba and dynid versions, whether dynid uses its
    compiled kernels, the CPU model, the logical CPU count, the BLAS library and its thread
    setting (the ``*_NUM_THREADS`` variables; unset means the library's default, usually
    one thread per CPU).
``bench_parser(description) -> argparse.ArgumentParser``
    The common options: ``--json [PATH]``, ``--repeats`` (default 5), ``--min-time``
    (default 0.2 s), ``--batch`` (samples of the batched cases, default 100000).
    ``--json`` alone prints one JSON object on stdout instead of the table (the convention
    every ``bench_*.py`` follows, which :mod:`run_all` relies on); ``--json PATH`` prints
    the table and also writes the JSON to PATH.
``format_cases(cases) -> str``
    The table: per-sample median [min, max] of dynid and the reference, and the speed-up.
``report(topic, cases, args, extra=None) -> dict``
    Prints the header, the ``extra`` items (JSON-ready values; dicts print as
    ``key value, ...``) and the table, or only the JSON with ``--json``; writes the JSON
    file when asked; returns the JSON record.
``panda_urdf() -> str`` and ``pinocchio_panda(robot) -> (model, data)``
    example-robot-data's Panda with the fingers locked, and the inertials and gravity of
    ``robot`` (the built-in :func:`dynid.panda`), as ``tests/test_reference_pinocchio.py``
    builds it.
``random_states(robot, n, seed) -> (q, dq, ddq)``
    Seeded states, ``q`` uniform within the position limits.

Run a script directly (``python benchmarks/bench_dynamics.py``) or all of them with
``python benchmarks/run_all.py`` (``make bench``).
"""

from __future__ import annotations

import argparse
import importlib
import json
import math
import os
import platform
import statistics
import sys
import timeit
from collections.abc import Callable, Sequence
from dataclasses import asdict, dataclass
from pathlib import Path
from typing import Any

import numpy as np

__all__ = [
    "Case",
    "Timing",
    "bench_parser",
    "check_close",
    "environment",
    "format_cases",
    "format_environment",
    "measure",
    "panda_urdf",
    "pinocchio_panda",
    "random_states",
    "report",
]


@dataclass(frozen=True)
class Timing:
    """Seconds per call: median, min and max over ``repeats`` repeats of ``number`` calls."""

    median: float
    min: float
    max: float
    number: int
    repeats: int

    def per(self, k: int) -> Timing:
        """The same timing divided by ``k`` (seconds per sample for ``k`` samples per call)."""
        return Timing(self.median / k, self.min / k, self.max / k, self.number, self.repeats)


def measure(
    fn: Callable[[], Any], *, min_time: float = 0.2, repeats: int = 5, warmup: int = 3
) -> Timing:
    """Time ``fn()``: warm up, autorange to ``min_time`` s per repeat, ``repeats`` repeats."""
    for _ in range(warmup):
        fn()
    timer = timeit.Timer(fn)
    number, t = timer.autorange()  # calls per repeat so that a repeat takes >= 0.2 s
    if t < min_time:
        number = math.ceil(number * min_time / t * 1.05)
    per_call = [t / number for t in timer.repeat(repeat=repeats, number=number)]
    return Timing(statistics.median(per_call), min(per_call), max(per_call), number, repeats)


def measure_pair(
    ours: Callable[[], Any],
    ref: Callable[[], Any],
    *,
    min_time: float = 0.2,
    repeats: int = 5,
    warmup: int = 3,
) -> tuple[Timing, Timing]:
    """:func:`measure` of two functions with their repeats interleaved (ours, ref, ours, ...).

    On a shared machine the load drifts within seconds; alternating the repeats exposes
    both functions to the same drift, so their ratio holds better than two runs in turn.
    """
    timers, numbers = [], []
    for fn in (ours, ref):
        for _ in range(warmup):
            fn()
        timer = timeit.Timer(fn)
        number, t = timer.autorange()
        if t < min_time:
            number = math.ceil(number * min_time / t * 1.05)
        timers.append(timer)
        numbers.append(number)
    per_call: list[list[float]] = [[], []]
    for _ in range(repeats):
        for k in (0, 1):
            per_call[k].append(timers[k].timeit(numbers[k]) / numbers[k])
    a, b = (
        Timing(statistics.median(p), min(p), max(p), numbers[k], repeats)
        for k, p in enumerate(per_call)
    )
    return a, b


@dataclass(frozen=True)
class Case:
    """One timed comparison; timings are per call of ``n`` samples."""

    name: str
    n: int
    dynid: Timing
    ref: Timing
    ref_name: str = "pinocchio"
    note: str = ""

    @property
    def speedup(self) -> float:
        """Reference time over dynid time (> 1: dynid is faster)."""
        return self.ref.median / self.dynid.median

    def record(self) -> dict[str, Any]:
        """JSON-ready record: per-call and per-sample seconds of both, and the speed-up."""
        return {
            "name": self.name,
            "samples_per_call": self.n,
            "dynid": asdict(self.dynid),
            "reference": self.ref_name,
            "ref": asdict(self.ref),
            "dynid_per_sample_s": self.dynid.median / self.n,
            "ref_per_sample_s": self.ref.median / self.n,
            "speedup": self.speedup,
            "note": self.note,
        }


def check_close(name: str, ours: Any, ref: Any, atol: float) -> None:
    """Raise ``AssertionError`` naming ``name`` when ``|ours - ref| > atol`` anywhere."""
    a, b = np.asarray(ours, dtype=float), np.asarray(ref, dtype=float)
    if a.shape != b.shape:
        raise AssertionError(f"{name}: shapes differ, dynid {a.shape} vs reference {b.shape}")
    err = float(np.max(np.abs(a - b))) if a.size else 0.0
    if not err <= atol:
        raise AssertionError(f"{name}: answers differ by {err:.3g} > {atol:g}; not timing it")


def _version(module: str) -> str:
    try:
        return str(importlib.import_module(module).__version__)
    except Exception:  # not installed, or broken: the header says so
        return "not available"


def _cpu_model() -> str:
    try:
        with open("/proc/cpuinfo") as f:
            for line in f:
                if line.startswith("model name"):
                    return line.split(":", 1)[1].strip()
    except OSError:
        pass
    return platform.processor() or platform.machine()


def _blas() -> str:
    try:
        blas = np.show_config(mode="dicts")["Build Dependencies"]["blas"]
        return f"{blas.get('name', '?')} {blas.get('version', '')}".strip()
    except Exception:  # older numpy: no dict mode
        return "unknown"


def environment() -> dict[str, Any]:
    """Versions, CPU and BLAS threads of this process (the benchmark header)."""
    import dynid
    from dynid.dynamics.rnea import kernels

    threads = {
        k: os.environ[k]
        for k in ("OMP_NUM_THREADS", "OPENBLAS_NUM_THREADS", "MKL_NUM_THREADS")
        if k in os.environ
    }
    return {
        "python": platform.python_version(),
        "numpy": np.__version__,
        "scipy": _version("scipy"),
        "pinocchio": _version("pinocchio"),
        "numba": _version("numba"),
        "dynid": dynid.__version__,
        "dynid_kernels": "numba" if kernels() is not None else "numpy",
        "cpu": _cpu_model(),
        "cpu_count": os.cpu_count(),
        "blas": _blas(),
        "blas_threads": threads or f"library default (cpu_count {os.cpu_count()})",
        "platform": platform.platform(terse=True),
    }


def format_environment(env: dict[str, Any]) -> str:
    """The header lines for :func:`environment`'s dictionary."""
    return "\n".join(
        [
            f"Python {env['python']}, numpy {env['numpy']}, scipy {env['scipy']}, "
            f"pinocchio {env['pinocchio']}, numba {env['numba']}, dynid {env['dynid']} "
            f"(dynamics path: {env['dynid_kernels']})",
            f"CPU {env['cpu']} ({env['cpu_count']} logical CPUs), {env['platform']}",
            f"BLAS {env['blas']}, threads: {env['blas_threads']}",
        ]
    )


def bench_parser(description: str | None) -> argparse.ArgumentParser:
    """Argument parser with the options every benchmark takes."""
    p = argparse.ArgumentParser(
        description=(description or "").strip().splitlines()[0] if description else None
    )
    p.add_argument(
        "--json",
        nargs="?",
        const="-",
        metavar="PATH",
        help="print one JSON object instead of the table; with PATH, write it there too",
    )
    p.add_argument("--repeats", type=int, default=5, help="timed repeats (default 5)")
    p.add_argument(
        "--min-time",
        type=float,
        default=0.2,
        help="seconds per repeat, at least; never below autorange's 0.2 (default 0.2)",
    )
    p.add_argument(
        "--batch", type=int, default=100_000, help="samples of the batched cases (default 100000)"
    )
    return p


def _fmt(seconds: float) -> str:
    for unit, scale in (("s", 1.0), ("ms", 1e-3), ("us", 1e-6)):
        if seconds >= scale:
            return f"{seconds / scale:.3g} {unit}"
    return f"{seconds / 1e-9:.3g} ns"


def _fmt_extra(v: Any) -> str:
    if isinstance(v, dict):
        return ", ".join(
            f"{k} {x:.3g}" if isinstance(x, float) else f"{k} {x}" for k, x in v.items()
        )
    return "n/a" if v is None else str(v)


def format_cases(cases: Sequence[Case]) -> str:
    """A table: per-sample median [min, max] of dynid and the reference, and the speed-up."""
    head = (
        f"{'case':<34} {'samples':>8}  {'dynid per sample':<28} "
        f"{'reference per sample':<28} {'ref/dynid':>9}"
    )
    lines = [head, "-" * len(head)]
    for c in cases:
        d, r = c.dynid.per(c.n), c.ref.per(c.n)
        ds = f"{_fmt(d.median)} [{_fmt(d.min)}, {_fmt(d.max)}]"
        rs = f"{_fmt(r.median)} [{_fmt(r.min)}, {_fmt(r.max)}]"
        lines.append(f"{c.name:<34} {c.n:>8}  {ds:<28} {rs:<28} {c.speedup:>9.2f}")
        if c.note:
            lines.append(f"    {c.note}")
    lines.append(
        "median [min, max] over the repeats; ref/dynid > 1 means dynid is faster "
        "(the reference is Pinocchio unless the note says otherwise)"
    )
    return "\n".join(lines)


def report(
    topic: str,
    cases: Sequence[Case],
    args: argparse.Namespace,
    extra: dict[str, Any] | None = None,
) -> dict[str, Any]:
    """Print the header and table (or the JSON with ``--json``); return the JSON record."""
    env = environment()
    record = {
        "topic": topic,
        "environment": env,
        "timing": {"min_time_s": args.min_time, "repeats": args.repeats},
        "extra": extra or {},
        "cases": [c.record() for c in cases],
    }
    text = json.dumps(record, indent=2) + "\n"
    if args.json == "-":
        sys.stdout.write(text)
    else:
        print(f"== {topic} ==")
        print(format_environment(env))
        print(f"timing: timeit autorange >= {args.min_time} s per repeat, {args.repeats} repeats")
        for k, v in (extra or {}).items():
            print(f"{k}: {_fmt_extra(v)}")
        print(format_cases(cases))
        if args.json:
            Path(args.json).write_text(text)
    sys.stdout.flush()
    return record


# ---------------------------------------------------------------- reference models
def _robot_data_file(rel: str) -> Path:
    """A file of example-robot-data (the installed package or its share folder)."""
    import importlib.util

    spec = importlib.util.find_spec("example_robot_data")
    roots = []
    if spec is not None and spec.submodule_search_locations:
        roots += [Path(p) for p in spec.submodule_search_locations]
    roots += [
        Path(p) / "cmeel.prefix" / "share" / "example-robot-data" / "robots" for p in sys.path
    ]
    for root in roots:
        for cand in (root / rel, root / "robots" / rel):
            if cand.exists():
                return cand
    raise FileNotFoundError(f"example-robot-data file {rel} not found; install example-robot-data")


def panda_urdf() -> str:
    """Path of example-robot-data's Panda URDF."""
    return str(_robot_data_file("panda_description/urdf/panda.urdf"))


def pinocchio_panda(robot: Any) -> tuple[Any, Any]:
    """Pinocchio's Panda (fingers locked) with ``robot``'s inertials and gravity: (model, data)."""
    import pinocchio as pin

    full = pin.buildModelFromUrdf(panda_urdf())
    lock = [full.getJointId(n) for n in ("panda_finger_joint1", "panda_finger_joint2")]
    model = pin.buildReducedModel(full, lock, pin.neutral(full))
    model.gravity.linear[:] = robot.gravity
    for i in range(1, robot.n + 1):
        model.inertias[i] = pin.Inertia(robot.mass[i - 1], robot.com[i - 1], robot.inertia[i - 1])
    return model, model.createData()


def random_states(robot: Any, n: int, seed: int) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """``n`` seeded states: q uniform within the limits, dq in [-2, 2], ddq in [-5, 5]."""
    rng = np.random.default_rng(seed)
    lo = np.where(np.isfinite(robot.q_min), robot.q_min, -np.pi)
    hi = np.where(np.isfinite(robot.q_max), robot.q_max, np.pi)
    q = rng.uniform(lo, hi, (n, robot.n))
    dq = rng.uniform(-2.0, 2.0, (n, robot.n))
    ddq = rng.uniform(-5.0, 5.0, (n, robot.n))
    return q, dq, ddq
