"""Progress of long runs: a 10-minute 1 kHz log kept identify silent for 112 s (validate 25 s,
observe --calibrate 53 s). The library tells its steps to the callback of
:func:`dynid.progress.reporting` (reading, preparing, the structure search's regressors,
the passes over the rows, the predictions, the observer); the command line prints them on
a terminal, throttled, and never with -q.

The run here is short: the throttle's thresholds are set to zero and the regressor is read
in blocks (``DYNID_MAX_STACK_BYTES=0``), as a long log's is.
"""

from __future__ import annotations

import re
import sys

import numpy as np
import pytest

import dynid
from dynid.cli import console
from dynid.cli.__main__ import main
from dynid.io.torque_log import save_torque_log
from dynid.progress import report, reporting, rows_read, stage
from dynid.simulation.measurement import sample_times, simulate_measurement
from dynid.simulation.trajectories import random_fourier


@pytest.fixture(scope="module")
def log_file(tmp_path_factory):
    """A 6 s, 200 Hz Panda log (its own model, sensor noise)."""
    panda = dynid.panda()
    rng = np.random.default_rng(21)
    log = simulate_measurement(panda, random_fourier(panda, rng)(sample_times(6.0, 200.0)), rng=rng)
    path = tmp_path_factory.mktemp("progress") / "long.csv"
    save_torque_log(path, log)
    return path


@pytest.fixture
def terminal(monkeypatch):
    """Every step shown at once, the regressor read in blocks."""
    monkeypatch.setattr(console, "PROGRESS_AFTER_S", 0.0)
    monkeypatch.setattr(console, "PROGRESS_EVERY_S", 0.0)
    monkeypatch.setenv("DYNID_MAX_STACK_BYTES", "0")


def _identify(path, out, *extra, tty=True, monkeypatch):
    """``identify`` with stderr a terminal (``tty``) or not: the stream the test sees."""
    monkeypatch.setattr(sys.stderr, "isatty", lambda: tty, raising=False)
    argv = ["identify", "--robot", "panda", "--data", str(path), "--no-figures"]
    return main([*argv, "--out", str(out), *extra])


def test_a_long_identify_shows_its_steps_on_a_terminal(
    log_file, tmp_path, terminal, capsys, monkeypatch
):
    """Reading, preparing, each regressor of the structure search with the rows of its
    passes, and the final fit are printed as the command's own lines with the elapsed
    time; the summary on stdout is unchanged by them."""
    assert _identify(log_file, tmp_path / "id", monkeypatch=monkeypatch) == 0
    out, err = capsys.readouterr()
    lines = [s for s in err.splitlines() if s.startswith("dynid identify: ") and "warning" not in s]
    said = "\n".join(lines)
    assert "dynid identify: reading long.csv: 1,201 of 1,201 rows (" in said, said
    assert "dynid identify: preparing long.csv (" in said, said
    assert re.search(
        r"structure search, regressor 1 of \d+: a pass over the rows, [\d,]+ of [\d,]+ read", said
    )
    assert "the fit of the structure chosen: a pass over the rows" in said, said
    assert all(s.endswith(" s)") for s in lines), lines
    assert "dynid identify" not in out


def test_no_progress_with_q_nor_off_a_terminal(log_file, tmp_path, terminal, capsys, monkeypatch):
    """-q prints no progress; nor does a run whose stderr is a file or a pipe (the
    structure given: the search is not what is tested)."""
    terms = ("--terms", "viscous,coulomb")
    assert _identify(log_file, tmp_path / "q", "-q", *terms, monkeypatch=monkeypatch) == 0
    assert "reading long.csv" not in capsys.readouterr().err
    pipe = tmp_path / "pipe"
    assert _identify(log_file, pipe, *terms, tty=False, monkeypatch=monkeypatch) == 0
    assert "reading long.csv" not in capsys.readouterr().err


def test_steps_within_a_stage_carry_its_name_and_nothing_is_told_without_a_callback():
    """report() without reporting() does nothing; within stage() a step is prefixed."""
    report("unheard")  # no callback: no error, nothing
    heard: list[str] = []
    with reporting(heard.append):
        report("reading")
        with stage("search"):
            report("pass")
        report("after")
    report("unheard again")
    assert heard == ["reading", "search", "search: pass", "after"]


def test_passes_over_the_rows_say_how_many_rows_there_are(
    log_file, tmp_path, terminal, capsys, monkeypatch
):
    """A pass over the rows said only the rows read so far ("155,610 read"), with no total
    to tell how far it had got; now it says "of" the rows the fit reads, the count the
    summary gives, and the last pass reaches it."""
    terms = ("--terms", "viscous,coulomb")
    assert _identify(log_file, tmp_path / "id", *terms, monkeypatch=monkeypatch) == 0
    out, err = capsys.readouterr()
    rows = int(re.search(r"([\d,]+) rows\b", out)[1].replace(",", ""))  # the summary's count
    passes = re.findall(r"the fit: a pass over the rows, ([\d,]+) of ([\d,]+) read", err)
    assert passes, err
    assert {int(total.replace(",", "")) for _, total in passes} == {rows}
    assert int(passes[-1][0].replace(",", "")) == rows


def test_a_stage_gives_its_rows_to_its_passes_alone():
    """rows_read tells the total of the stage it runs in, not an enclosing stage's nor one
    it has passed."""
    heard: list[str] = []
    with reporting(heard.append):
        with stage("fit", rows=20):
            rows_read(10)
            rows_read(30)  # beyond the stage's rows: another set, no total
            with stage("inner"):
                rows_read(5)
        rows_read(7)
    assert heard == [
        "fit",
        "fit: a pass over the rows, 10 of 20 read",
        "fit: a pass over the rows, 30 read",
        "fit: inner",
        "inner: a pass over the rows, 5 read",
        "a pass over the rows, 7 read",
    ]
