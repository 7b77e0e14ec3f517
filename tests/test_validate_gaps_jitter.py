"""validate and friction say where a held-out log was cut and how jittered its stamps are,
as identify says them: a log with a 0.3 s gap and jittered stamps was "g.csv: 2 pieces,
N samples", without the gap's time or length or the jitter.

Reference: the log is simulated at stamps built here (a robot clock at 1000 s, jitter of
known std, a stretch of samples cut out between two known stamps)."""

from __future__ import annotations

import json
import re
import warnings

import numpy as np
import pytest

from dynid.cli.__main__ import main
from dynid.exceptions import DynidWarning
from dynid.io.robot_file import load_robot
from dynid.io.torque_log import save_torque_log
from dynid.simulation.measurement import SensorNoise, sample_times, simulate_measurement
from dynid.simulation.trajectories import random_fourier

from conftest import SO101_URDF

ROBOT = ["--robot", str(SO101_URDF), "--snap-angles"]
RATE = 500.0
JITTER = 2e-5  # [s], 1 % of the 2 ms period


@pytest.fixture(scope="module")
def gapped(tmp_path_factory):
    """g.csv: 5 s of the robot's motion at 500 Hz, stamps jittered and offset by 1000 s,
    the samples between 3.0 s and 3.3 s cut out; and the stamps before and after the cut."""
    robot = load_robot(str(SO101_URDF), snap_angles=True)
    t = sample_times(5.0, RATE, jitter_std=JITTER, rng=np.random.default_rng(5))
    t = t[(t < 3.0) | (t > 3.3)] + 1000.0
    log = simulate_measurement(
        robot,
        random_fourier(robot, np.random.default_rng(4))(t),
        rng=np.random.default_rng(6),
        noise=SensorNoise(tau_std=0.005),
        friction=None,
        with_ddq=False,
    )
    d = tmp_path_factory.mktemp("gaps")
    save_torque_log(d / "g.csv", log)
    before = float(t[t < 1003.0][-1])
    after = float(t[t > 1003.3][0])
    return d, before, after - before


def _said_gap(text):
    """The stamp, the offset and the length [s] of the gap a printed line names."""
    m = re.search(
        r"g\.csv: 2 pieces, \d+ samples, cut at the gap\(s\) after t = ([\d.]+) s "
        r"\(([\d.]+) s into g\.csv; ([\d.]+) s long\)",
        text,
    )
    assert m is not None, text
    return tuple(float(x) for x in m.groups())


def _said_jitter(text):
    """The jitter std [s] a printed line names."""
    m = re.search(r"stamps jittered, std ([\d.]+) ms at a 2 ms period", text)
    assert m is not None, text
    return float(m.group(1)) * 1e-3


@pytest.mark.parametrize("command", ["validate", "friction"])
def test_a_held_out_logs_gap_and_jitter_are_named(gapped, tmp_path, capsys, command):
    """The printed line names the gap's last stamp before it (to the ms), its offset into
    the file and its length (3 digits), and the stamps' jitter (to 30 %), as identify
    says them; validation.json's recording (friction.json's) records the gap."""
    d, before, length = gapped
    out = tmp_path / "v"
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", DynidWarning)
        main([command, *ROBOT, "--data", str(d / "g.csv"), "--out", str(out), "--no-figures"])
    text = capsys.readouterr().out
    stamp, into, said = _said_gap(text)
    assert stamp == pytest.approx(before, abs=1e-3)
    assert into == pytest.approx(before - 1000.0, abs=1e-3)
    assert said == pytest.approx(length, rel=5e-3)
    assert _said_jitter(text) == pytest.approx(JITTER, rel=0.3)
    m = re.search(r"(\d+) sample\(s\) missing from the stamps' grid \(dropped, the gaps'", text)
    assert m is not None and int(m[1]) == round(length * RATE) - 1, text  # the gap's samples
    name = "validation.json" if command == "validate" else "friction.json"
    doc = json.loads((out / name).read_text())
    (gap,) = (doc if command == "validate" else doc["metadata"])["recordings"][0]["gaps"]
    assert gap == pytest.approx([before, length], abs=1e-6)


def test_a_long_hole_among_many_dropped_samples_is_said_before_them():
    """Regression: a recording cut at five 0.03 s gaps, then a 2 s hole at t = 35 s, said
    the first four gaps "and 2 more": the hole only in the JSON. The four longest are
    said, in time order, the hole among them, and the rest with their longest length;
    the report's table says the same."""
    from dynid.identification.pieces import gaps_text
    from dynid.report.page import _pieces

    gaps = [[1.0, 0.03], [5.0, 0.03], [9.0, 0.03], [12.0, 0.03], [20.0, 0.03], [35.0, 2.0]]
    said = gaps_text(gaps, 0.0, "rec1.csv")
    assert "t = 35.000 s (2 s long)" in said, said
    assert said.endswith("and 2 more, at most 0.03 s long"), said
    stamps = [float(x) for x in re.findall(r"t = ([\d.]+) s", said)]
    assert stamps == sorted(stamps) and len(stamps) == 4, said
    row = _pieces({"pieces": 7, "gaps": gaps, "file": "rec1.csv"})
    assert "t = 35.000 s, 2 s long" in row and "2 more, at most 0.03 s long" in row, row
