"""Recorded velocity and acceleration columns checked against the derivative of what they
derive from.

A new user's FR3 log whose velocity columns lagged the positions by one sample was
identified "at the noise floor" with six base parameters more than 3 std off the truth; ten
samples' lag was read as a torque delay; velocity columns of zeros gave a rank error blaming
the trajectory (all joints) or fv4 3.3 for 0.2 and a torque-scale hint (joints 5-7);
acceleration columns that were a finite difference of the noisy velocities raised the
held-out noise floor from 0.48 % to 1.81 % without a word.

References: a simulated Panda (its own model, sensor noise) at 500 Hz, whose velocity
columns are shifted by a known number of samples, by a known fraction of one (a cubic
spline of the true velocities), zeroed or made a backward difference of the positions;
its fit with the velocities derived from the positions, or from the clean log; accelerations
the true ones, a finite difference of the noisy velocities, or the true ones with white
noise of known std.
"""

from __future__ import annotations

import logging

import numpy as np
import pytest
from scipy.interpolate import CubicSpline

import dynid
from dynid.exceptions import DataError, DynidWarning
from dynid.identification.derivative_columns import (
    DDQ_NOISE_RATIO,
    MAX_LAG_SAMPLES,
    acceleration_noise_ratio,
    velocity_lag,
)
from dynid.identification.log import TorqueLog
from dynid.io.columns import parse_column_map
from dynid.io.torque_log import save_torque_log
from dynid.simulation.measurement import sample_times, simulate_measurement
from dynid.simulation.trajectories import random_fourier
from dynid.workflows.identify import IdentifyOptions, identify_files
from dynid.workflows.recordings import read_recordings

FS = 500.0


@pytest.fixture(scope="module")
def sim():
    """The Panda's true trajectory and its noisy measurement (with true accelerations)."""
    panda = dynid.panda()
    traj = random_fourier(panda, np.random.default_rng(11))(sample_times(6.0, FS))
    g = simulate_measurement(panda, traj, rng=np.random.default_rng(12), with_ddq=True)
    return panda, traj, g


def _lagged(x: np.ndarray, k: int) -> np.ndarray:
    """``x`` with each row the one ``k`` samples earlier (the first repeated)."""
    return np.vstack([np.repeat(x[:1], k, axis=0), x[:-k]])


def test_clean_and_known_lags_are_read_to_a_fraction_of_a_sample(sim):
    """The noisy log's own velocities read no lag (to 0.05 sample); velocities moved by a
    known time (a spline of the true ones) read that time, integer or not; a backward
    difference of the positions reads half a sample and passes."""
    _, traj, g = sim
    clean = velocity_lag(TorqueLog(g.t, g.q, g.dq, g.tau))
    assert clean is not None and abs(clean.lag_samples) < 0.05
    assert clean.lag_joints == tuple(range(7)) and clean.still == ()
    spline = CubicSpline(traj.t, traj.dq, axis=0)
    for lag in (0.3, 1.0, 2.5, 10.0, -1.0):
        dq = spline(g.t - lag / FS)
        got = velocity_lag(TorqueLog(g.t, g.q, dq, g.tau))
        assert got is not None and abs(got.lag_samples - lag) < 0.05, (lag, got)
    back = np.vstack([g.dq[:1], np.diff(g.q, axis=0) * FS])
    got = velocity_lag(TorqueLog(g.t, g.q, back, g.tau))
    assert got is not None and abs(got.lag_samples - 0.5) < 0.05
    assert abs(got.lag_samples) < MAX_LAG_SAMPLES


@pytest.mark.parametrize("k", [1, 10])
def test_lagging_velocities_are_derived_again_naming_the_lag(sim, tmp_path, k):
    """Velocity columns one or ten samples late: one warning naming the file, the lag in
    samples and ms, and that the velocities are derived from the positions instead; the
    log read is then the one --columns dq=none reads (the clean log's so read, bit for
    bit)."""
    panda, _, g = sim
    path = save_torque_log(tmp_path / "lag.csv", TorqueLog(g.t, g.q, _lagged(g.dq, k), g.tau))
    with pytest.warns(DynidWarning) as said:
        rec = read_recordings([path], panda)
    got = rec.logs[0]
    msg = [str(w.message) for w in said if "velocity columns" in str(w.message)]
    assert len(msg) == 1 and msg[0].startswith("lag.csv: ") and "\n" not in msg[0], msg
    assert f"lag the derivative of its positions by {k}.0" in msg[0], msg
    assert f"({k * 1000 / FS:.3g} ms" in msg[0] and "not a torque delay" in msg[0]
    assert "velocities derived from the positions instead" in msg[0]
    clean = save_torque_log(tmp_path / "clean.csv", TorqueLog(g.t, g.q, g.dq, g.tau))
    ref = read_recordings([clean], panda, columns=("dq=none", None)).logs[0]
    assert got.dq_derived and ref.dq_derived and got.ddq is None
    np.testing.assert_array_equal(got.dq, ref.dq)
    side = rec.joint_side[0]  # what observe prepares from (regression: the lagging log's)
    assert side.dq_derived, "the joint-side log kept the lagging velocity columns"
    np.testing.assert_array_equal(side.dq, ref.dq)


@pytest.mark.parametrize("joints", [tuple(range(7)), (4, 5, 6)])
def test_velocity_columns_of_zeros_are_derived_again_naming_the_joints(sim, tmp_path, joints):
    """Velocity columns of zeros (every joint, or joints 5-7) while the positions move: a
    warning naming exactly those joints, the velocities derived from the positions; a
    constant column is found too."""
    panda, _, g = sim
    dq = g.dq.copy()
    dq[:, list(joints)] = 0.0
    path = save_torque_log(tmp_path / "zero.csv", TorqueLog(g.t, g.q, dq, g.tau))
    with pytest.warns(DynidWarning) as said:
        rec = read_recordings([path], panda)
    got = rec.logs[0]
    msg = " ".join(str(w.message) for w in said)
    named = ", ".join(f"joint {j + 1}" for j in joints)
    assert f"hold no motion (zero or constant) on {named}, whose positions move" in msg, msg
    assert "velocities derived from the positions instead" in msg and "lag the" not in msg
    assert got.dq_derived
    dq[:, 2] = 0.7
    found = velocity_lag(TorqueLog(g.t, g.q, dq, g.tau))
    assert found is not None and found.still == tuple(sorted({2, *joints}))


def test_a_lagging_log_fits_as_the_clean_log(sim, tmp_path):
    """identify on the one-sample lag (its velocities derived again, said) fits as the
    clean log read with dq=none bit for bit, and as the clean log's recorded velocities
    within 3 std on every base parameter."""
    panda, _, g = sim
    lag = save_torque_log(tmp_path / "lag.csv", TorqueLog(g.t, g.q, _lagged(g.dq, 1), g.tau))
    clean = save_torque_log(tmp_path / "clean.csv", TorqueLog(g.t, g.q, g.dq, g.tau))
    with pytest.warns(DynidWarning, match="lag.csv: its velocity columns lag"):
        fixed = identify_files(panda, [lag], IdentifyOptions(terms="viscous")).model.fit
    same = identify_files(
        panda, [clean], IdentifyOptions(terms="viscous", columns=("dq=none", None))
    ).model.fit
    ref = identify_files(panda, [clean], IdentifyOptions(terms="viscous")).model.fit
    np.testing.assert_array_equal(fixed.beta, same.beta)
    sd = np.hypot(fixed.std, ref.std)
    assert np.all(np.abs(fixed.beta - ref.beta) < 3 * sd), np.abs(fixed.beta - ref.beta) / sd


def test_noisy_acceleration_columns_are_left_out_with_a_note(sim, tmp_path, caplog):
    """Accelerations that are a finite difference of the noisy velocities hold several
    times the noise of the velocities' derivative at the cut-off (about 0.2 fs / fc): left
    out with a note naming the file and the ratio, the held-out noise floor then the one of
    the log without them (equal to 1e-9); the true accelerations (exact) and the true ones
    with white noise 0.3 times the derivative's are used, said in a note."""
    panda, traj, g = sim
    fd = np.gradient(g.dq, g.t, axis=0)
    base = TorqueLog(g.t, g.q, g.dq, g.tau)
    ratio = acceleration_noise_ratio(TorqueLog(g.t, g.q, g.dq, g.tau, fd), None)
    assert ratio is not None and np.all(ratio > DDQ_NOISE_RATIO), ratio
    assert acceleration_noise_ratio(TorqueLog(g.t, g.q, g.dq, g.tau, traj.ddq), None) is None
    opt = IdentifyOptions(terms="viscous")
    noisy = save_torque_log(tmp_path / "fd.csv", TorqueLog(g.t, g.q, g.dq, g.tau, fd))
    plain = save_torque_log(tmp_path / "plain.csv", base)
    with caplog.at_level(logging.INFO):
        got = identify_files(panda, [noisy], opt)
    said = " ".join(r.getMessage() for r in caplog.records)
    assert "fd.csv: acceleration columns left out" in said, said
    ref = identify_files(panda, [plain], opt)
    assert got.heldout is not None and ref.heldout is not None
    assert got.heldout.noise_floor_percent == pytest.approx(
        ref.heldout.noise_floor_percent, rel=1e-9
    )
    np.testing.assert_allclose(got.model.fit.beta, ref.model.fit.beta, rtol=1e-9, atol=1e-12)
    small = acceleration_noise_ratio(TorqueLog(g.t, g.q, g.dq, g.tau, fd), None)
    assert small is not None
    # white noise of 0.3 / ratio of the finite difference's std: 0.3 times the derivative's
    sd = 0.3 * np.std(fd - traj.ddq, axis=0) / small
    mild = traj.ddq + np.random.default_rng(3).normal(size=fd.shape) * sd
    r = acceleration_noise_ratio(TorqueLog(g.t, g.q, g.dq, g.tau, mild), None)
    assert r is not None and np.all(r < 1.0), r
    caplog.clear()
    used = save_torque_log(tmp_path / "mild.csv", TorqueLog(g.t, g.q, g.dq, g.tau, mild))
    with caplog.at_level(logging.INFO):
        read_recordings([used], panda)
    said = " ".join(r.getMessage() for r in caplog.records)
    assert "mild.csv: acceleration columns used as recorded" in said, said


def test_dq_none_and_ddq_none_read_without_the_columns(sim, tmp_path):
    """--columns dq=none leaves out the velocity and acceleration columns, ddq=none the
    latter alone; none for another quantity is refused."""
    _, traj, g = sim
    path = save_torque_log(tmp_path / "a.csv", TorqueLog(g.t, g.q, g.dq, g.tau, traj.ddq))
    from dynid.io.columns import load_mapped_torque_log

    full = load_mapped_torque_log(path, parse_column_map()).log
    assert full.ddq is not None and not full.dq_derived
    no_dq = load_mapped_torque_log(path, parse_column_map("dq=none"))
    assert no_dq.log.dq_derived and no_dq.log.ddq is None
    assert no_dq.notes[0].startswith("velocity columns left out (--columns dq=none)")
    no_ddq = load_mapped_torque_log(path, parse_column_map("ddq=None")).log
    assert no_ddq.ddq is None and not no_ddq.dq_derived
    np.testing.assert_array_equal(no_ddq.dq, full.dq)
    with pytest.raises(DataError, match="only the recorded derivatives can be left out"):
        parse_column_map("tau=none")
