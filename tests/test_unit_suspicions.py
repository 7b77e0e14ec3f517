"""Every unit suspicion of a log said in one pass, with one ``--units`` hint.

Reference: a simulated Panda log (the robot's own model) written as a vendor would: time
in milliseconds, positions in degrees, positions only, motor angles through a gear of 50.
Before, the first run said "time steps of 5 look like milliseconds; hint: --units t=ms"
and only the next one "positions in degrees ... hint: --units q=deg", quoting joint-side
spans the file does not hold.
"""

from __future__ import annotations

import re
from pathlib import Path

import numpy as np
import pytest

import dynid
from dynid.exceptions import DataError
from dynid.identification.log import TorqueLog
from dynid.model.drive import Drive
from dynid.simulation.measurement import sample_times, simulate_measurement
from dynid.simulation.trajectories import random_fourier
from dynid.workflows.recordings import Recorded, check_unit_findings, read_recordings

DEG = 180.0 / np.pi
GEAR = 50.0


@pytest.fixture(scope="module")
def truth():
    panda = dynid.panda()
    t = sample_times(3.0, 200.0)
    traj = random_fourier(panda, np.random.default_rng(7))(t)
    g = simulate_measurement(panda, traj, rng=np.random.default_rng(8))
    return panda, TorqueLog(g.t, g.q, g.dq, g.tau)


def _vendor_csv(path: Path, t: np.ndarray, q: np.ndarray, tau: np.ndarray) -> Path:
    """Time in ms, positions only (degrees as given), torques: the header dynid reads."""
    n = q.shape[1]
    head = ["t", *(f"q{j + 1}" for j in range(n)), *(f"tau{j + 1}" for j in range(n))]
    rows = np.column_stack([t * 1e3, q, tau])
    np.savetxt(path, rows, delimiter=",", header=",".join(head), comments="", fmt="%.17g")
    return path


def test_milliseconds_and_degrees_are_said_in_one_error(truth, tmp_path):
    """A positions-only log in ms and degrees is refused once, with both findings and
    --units t=ms,q=deg; read with that hint it is the simulated log (t, q to 1e-12)."""
    panda, log = truth
    path = _vendor_csv(tmp_path / "v.csv", log.t, log.q * DEG, log.tau)
    with pytest.raises(DataError) as e:
        read_recordings([path], panda)
    msg = str(e.value)
    assert msg.startswith("v.csv: ") and "look like milliseconds" in msg
    assert "positions in degrees" in msg and msg.endswith("hint: --units t=ms,q=deg")
    assert msg.count("hint:") == 1
    ok = read_recordings([path], panda, columns=(None, "t=ms,q=deg"))
    np.testing.assert_allclose(ok.logs[0].t, log.t, atol=1e-12)
    np.testing.assert_allclose(ok.logs[0].q, log.q, atol=1e-12)


def test_motor_side_degrees_quote_the_files_values(truth, tmp_path):
    """Through a motor-side drive (gear 50) the spans said are the file's motor angles,
    the joint-side ones said as such: numpy's min and max of the file's columns."""
    panda, log = truth
    drive = Drive(np.diag(np.full(7, GEAR)), np.zeros(7), side="motor")
    path = _vendor_csv(tmp_path / "m.csv", log.t, GEAR * log.q * DEG, log.tau / GEAR)
    with pytest.raises(DataError) as e:
        read_recordings([path], panda, drive=drive)
    msg = str(e.value)
    assert msg.endswith("hint: --units t=ms,q=deg")
    cols = np.loadtxt(path, delimiter=",", skiprows=1)
    j = int(re.search(r"motor (\d) spans", msg).group(1))
    lo, hi = cols[:, j].min(), cols[:, j].max()  # column j: q_j (t first)
    assert f"motor {j} spans [{lo:.4g}, {hi:.4g}] in the file" in msg
    joint = f"[{lo / GEAR:.4g}, {hi / GEAR:.4g}] at the joint side"
    assert joint in msg


def test_recorded_velocities_in_ms_and_degrees_are_said_in_one_error(truth):
    """A log with velocities whose time is in ms and positions in degrees (velocities in
    deg/s per second of the true clock) is refused with both findings and one hint."""
    panda, log = truth
    ms = TorqueLog(log.t * 1e3, log.q * DEG, log.dq * DEG, log.tau)
    with pytest.raises(DataError) as e:
        check_unit_findings(Recorded((ms,), (Path("r.csv"),)), panda)
    msg = str(e.value)
    assert "the time column looks like ms" in msg and "degrees" in msg
    assert re.search(r"hint: --units t=ms,q=deg(,dq=deg/s)?$", msg), msg


@pytest.mark.parametrize(("scale", "unit"), [(1e6, "us"), (1e9, "ns")])
def test_a_time_column_in_us_or_ns_is_named_with_its_units(truth, tmp_path, scale, unit):
    """Regression: positions only with stamps in us (epoch, 4000 per 4 ms step) were refused
    as "sampled at 0.00025 Hz" without a hint; the error now names the unit and the
    --units entry, and read with it the log is the simulated one."""
    panda, log = truth
    n = log.q.shape[1]
    path = tmp_path / f"{unit}.csv"
    head = ["t", *(f"q{j + 1}" for j in range(n)), *(f"tau{j + 1}" for j in range(n))]
    rows = np.column_stack([np.round(log.t * scale), log.q, log.tau])
    np.savetxt(path, rows, delimiter=",", header=",".join(head), comments="", fmt="%.17g")
    with pytest.raises(DataError, match=rf"look like {'micro' if unit == 'us' else 'nano'}"):
        read_recordings([path], panda)
    with pytest.raises(DataError, match=rf"hint: --units t={unit}"):
        read_recordings([path], panda)
    ok = read_recordings([path], panda, columns=(None, f"t={unit}"))
    np.testing.assert_allclose(ok.logs[0].t, log.t, atol=1e-9)
