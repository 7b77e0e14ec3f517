"""A warning the library logs reads as the command's own line on stderr (as
``dynid CMD: warning: ...`` of :meth:`dynid.cli.console.Console.warn`), in a process of its
own where no logging is set up before the command."""

from __future__ import annotations

import os
import subprocess
import sys
from pathlib import Path


def _dynid(*args: str, cwd: Path) -> subprocess.CompletedProcess[str]:
    src = str(Path(__file__).resolve().parents[1] / "src")
    env = {**os.environ, "OPENBLAS_NUM_THREADS": "1", "MPLBACKEND": "Agg", "PYTHONPATH": src}
    return subprocess.run(
        [sys.executable, "-m", "dynid", *args],
        cwd=cwd,
        env=env,
        capture_output=True,
        text=True,
        timeout=300,
        check=False,
    )


def test_a_logged_warning_reads_as_the_commands_warning(tmp_path):
    made = _dynid("acquire-static", "--n", "40", "--seed", "3", "--out", "s.csv", cwd=tmp_path)
    assert made.returncode == 0, made.stderr
    lines = (tmp_path / "s.csv").read_text().splitlines()
    first = next(i for i, s in enumerate(lines) if s and s[0] in "-0123456789")
    cells = lines[first + 1].split(",")
    lines[first + 1] = ",".join(["nan", *cells[1:]])
    (tmp_path / "s.csv").write_text("\n".join(lines) + "\n")
    run = _dynid("identify", "--data", "s.csv", "--drop-invalid", "--out", "fit", cwd=tmp_path)
    assert run.returncode == 0, run.stderr
    said = [s for s in run.stderr.splitlines() if "dropped 1 invalid row" in s]
    assert len(said) == 1 and said[0].startswith("dynid identify: warning: s.csv: "), said
    assert not any(s.startswith(("WARNING ", "INFO ")) for s in run.stderr.splitlines())
    # the run's report lists it once among the warnings, and its last line says where it is
    assert run.stdout.splitlines()[-1] == f"report: {Path('fit') / 'report.html'}"
    report = (tmp_path / "fit" / "report.html").read_text()
    assert report.count("dropped 1 invalid row") == 1
