"""Velocity columns in another angle unit than the positions, and time units given wrong.

Reference: a simulated Panda log (the robot's own model, its velocities the exact
derivative of its positions) written as a vendor API writes one: stamps in microseconds,
positions in degrees, velocities in degrees per second. Before, read with ``--units
t=us,q=deg`` (``dq=deg/s`` forgotten) it passed every check and was fitted with
velocities 57.3 times too fast (a Kinova log so read: exit 0, "usable 17.8 %", gravity 62 %
off; with two files, "velocity columns lag by 12.86 samples"); read with ``--units t=ms``
on its microsecond stamps it was told "looks like ms; hint: --units t=ms", the unit given.
"""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest

import dynid
from dynid.exceptions import DataError
from dynid.identification.angle_time_units import GivenUnits, units_with
from dynid.identification.derivative_columns import velocity_finding
from dynid.identification.log import TorqueLog
from dynid.identification.velocity_scale import joint_rate_factors, velocity_scale_finding
from dynid.simulation.measurement import sample_times, simulate_measurement
from dynid.simulation.trajectories import random_fourier
from dynid.workflows.recordings import read_recordings

DEG = 180.0 / np.pi


@pytest.fixture(scope="module")
def truth():
    panda = dynid.panda()
    t = sample_times(3.0, 500.0)
    traj = random_fourier(panda, np.random.default_rng(3))(t)
    g = simulate_measurement(panda, traj, rng=np.random.default_rng(4))
    return panda, TorqueLog(g.t, g.q, g.dq, g.tau, traj.ddq)


def _vendor_csv(
    path: Path, log: TorqueLog, q_scale: float, dq_scale: float, ddq_scale: float | None = None
) -> Path:
    """Stamps in us from a boot clock, positions and velocities times the scales given
    (and accelerations, with ``ddq_scale``)."""
    n = log.n
    head = ["t", *(f"q{j + 1}" for j in range(n))]
    head += [*(f"dq{j + 1}" for j in range(n)), *(f"tau{j + 1}" for j in range(n))]
    cols = [8.1e9 + log.t * 1e6, log.q * q_scale, log.dq * dq_scale, log.tau]
    if ddq_scale is not None:
        head += [f"ddq{j + 1}" for j in range(n)]
        cols.append(log.ddq * ddq_scale)
    rows = np.column_stack(cols)
    np.savetxt(path, rows, delimiter=",", header=",".join(head), comments="", fmt="%.17g")
    return path


def test_velocities_in_deg_s_beside_positions_read_from_degrees_are_refused(truth, tmp_path):
    """``--units t=us,q=deg`` on a file of deg/s velocities: one line, the scale (180/pi
    to 3 digits) and the whole --units to run again; read with it, the simulated log."""
    panda, log = truth
    path = _vendor_csv(tmp_path / "k.csv", log, DEG, DEG)
    with pytest.raises(DataError) as e:
        read_recordings([path], panda, columns=(None, "t=us,q=deg,tau=-1"))
    msg = str(e.value)
    assert "\n" not in msg and msg.count("hint:") == 1
    assert msg.startswith("k.csv: its velocity columns are 57.3 times the derivative"), msg
    assert "velocities in degrees per second read as rad/s" in msg and "not a lag" in msg
    assert msg.endswith("hint: --units t=us,q=deg,dq=deg/s,tau=-1"), msg
    ok = read_recordings([path], panda, columns=(None, "t=us,q=deg,dq=deg/s"))
    np.testing.assert_allclose(ok.logs[0].t - ok.logs[0].t[0], log.t - log.t[0], atol=1e-6)
    np.testing.assert_allclose(ok.logs[0].q, log.q, atol=1e-12)
    np.testing.assert_allclose(ok.logs[0].dq, log.dq, atol=1e-12)


def test_velocities_57_times_slower_name_the_column_read_wrong(truth, tmp_path):
    """The other direction: rad/s velocities read with ``dq=deg/s`` are told ``dq=rad/s``
    (radians read as degrees would be ``q=deg``: positions in degrees, velocities rad/s)."""
    panda, log = truth
    path = _vendor_csv(tmp_path / "r.csv", log, DEG, 1.0)
    with pytest.raises(DataError) as e:
        read_recordings([path], panda, columns=(None, "t=us,q=deg,dq=deg/s"))
    msg = str(e.value)
    assert "0.0175 times the derivative" in msg and "radians per second read as deg/s" in msg
    assert msg.endswith("hint: --units t=us,q=deg,dq=rad/s"), msg
    ok = read_recordings([path], panda, columns=(None, "t=us,q=deg,dq=rad/s"))
    np.testing.assert_allclose(ok.logs[0].dq, log.dq, atol=1e-12)


def test_acceleration_columns_are_converted_alike_or_named_alone(truth, tmp_path):
    """Accelerations in deg/s^2 beside velocities in deg/s: with dq=deg/s forgotten the
    hint converts both; with ddq=deg/s^2 alone forgotten it names the accelerations (57.3
    times the derivative of the velocities), not their noise; read so, the simulation."""
    panda, log = truth
    path = _vendor_csv(tmp_path / "a.csv", log, DEG, DEG, DEG)
    with pytest.raises(DataError) as e:
        read_recordings([path], panda, columns=(None, "t=us,q=deg"))
    assert str(e.value).endswith("hint: --units t=us,q=deg,dq=deg/s,ddq=deg/s^2"), str(e.value)
    with pytest.raises(DataError) as e:
        read_recordings([path], panda, columns=(None, "t=us,q=deg,dq=deg/s"))
    msg = str(e.value)
    assert "its acceleration columns are 57.3 times the derivative of its velocities" in msg
    assert msg.endswith("hint: --units t=us,q=deg,dq=deg/s,ddq=deg/s^2"), msg
    ok = read_recordings([path], panda, columns=(None, "t=us,q=deg,dq=deg/s,ddq=deg/s^2"))
    np.testing.assert_allclose(ok.logs[0].ddq, log.ddq, atol=1e-10)


def test_rate_factors_are_the_units_ratio_and_agreeing_columns_pass(truth):
    """k of dq/dt ~ k dq is 1 for the simulated log (within 2 %, a 10 ms average of its
    differences) and pi/180 for its velocities in deg/s; nothing is found for the former."""
    panda, log = truth
    k = joint_rate_factors(log)
    np.testing.assert_allclose(k, 1.0, rtol=0.02)
    fast = TorqueLog(log.t, log.q, log.dq * DEG, log.tau)
    np.testing.assert_allclose(joint_rate_factors(fast), 1 / DEG, rtol=0.02)
    assert velocity_scale_finding(panda, log) is None
    said = velocity_scale_finding(panda, fast, GivenUnits("q=rad", {}))
    assert said is not None and said.endswith("hint: --units dq=deg/s")


def test_a_scale_is_not_reported_as_a_lag(truth):
    """The lag check reads columns of the positions' scale only: the velocities in deg/s
    (no lag: the exact derivative) are said to be off that scale, never to lag or lead."""
    panda, log = truth
    fast = TorqueLog(log.t, log.q, log.dq * DEG, log.tau)
    found = velocity_finding(fast, panda.joint_names)
    assert found is not None and "57.3 times it" in found and "not a lag" in found
    assert " lag the " not in found and " lead the " not in found
    assert velocity_finding(log) is None


def test_a_time_unit_given_wrong_is_told_from_the_data(truth, tmp_path):
    """Microsecond stamps read with ``--units t=ms``: the data say us (1000 times as read),
    and the hint is that, in the --units given, not the t=ms already given."""
    panda, log = truth
    path = _vendor_csv(tmp_path / "m.csv", log, DEG, DEG)
    with pytest.raises(DataError) as e:
        read_recordings([path], panda, columns=(None, "t=ms,q=deg,dq=deg/s,tau=-1"))
    msg = str(e.value)
    assert "looks like us, not ms" in msg and "1000 times too long" in msg, msg
    assert msg.endswith("hint: --units t=us,q=deg,dq=deg/s,tau=-1"), msg


def test_units_with_writes_an_entry_beside_its_neighbour():
    assert units_with("t=us,q=deg,tau=-1", {"dq": "deg/s"}) == "t=us,q=deg,dq=deg/s,tau=-1"
    assert units_with("t=ms,q=deg", {"t": "us"}) == "t=us,q=deg"
    assert units_with("tau=-1", {"t": "us"}) == "t=us,tau=-1"
    assert units_with(None, {"dq": "deg/s", "ddq": "deg/s^2"}) == "dq=deg/s,ddq=deg/s^2"
