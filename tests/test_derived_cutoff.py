"""The hint of a cut-off too high for velocities derived from positions: a positions-only
log validated at a cut-off well above the one read from its motion was judged "effects
outside the model remain" while the derived accelerations' noise made the error; now the
verdict says to lower --cutoff.

Reference: a simulated Panda log (the robot's own model, torque noise 0.05 N m, position
noise 2e-4 rad) validated with the robot that made it, so that any error above the noise
floor comes from the preparation, not the model.
"""

from __future__ import annotations

import re
import warnings

import numpy as np
import pytest

import dynid
from dynid.exceptions import DynidWarning
from dynid.identification.derived_cutoff import derived_cutoff_hint, with_derived_cutoff_hint
from dynid.identification.log import TorqueLog, with_derived_velocities
from dynid.identification.trim import common_cutoff
from dynid.identification.verdict import Verdict
from dynid.io.torque_log import save_torque_log
from dynid.simulation.measurement import SensorNoise, sample_times, simulate_measurement
from dynid.simulation.trajectories import random_fourier
from dynid.workflows.validate import ValidateOptions, validate_files


@pytest.fixture(scope="module")
def logs(tmp_path_factory):
    """The same 20 s, 100 Hz Panda log twice: positions only, and with measured velocities."""
    panda = dynid.panda()
    rng = np.random.default_rng(11)
    traj = random_fourier(panda, rng)(sample_times(20.0, 100.0))
    log = simulate_measurement(panda, traj, rng=rng, noise=SensorNoise(q_std=2e-4))
    d = tmp_path_factory.mktemp("derived")
    measured = TorqueLog(log.t, log.q, log.dq, log.tau)
    save_torque_log(d / "measured.csv", measured)
    save_torque_log(d / "positions.csv", with_derived_velocities(measured))
    return panda, d


def _verdict(panda, path, cutoff_hz):
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", DynidWarning)  # "no velocity columns"
        return validate_files(panda, [path], ValidateOptions(cutoff_hz=cutoff_hz)).verdict


def test_a_positions_only_log_above_its_motions_cut_off_is_told_to_lower_it(logs):
    """At 10 Hz, 1.8 times the 5.5 Hz read from the motion, the true model of a
    positions-only log is at a noise floor the derived states raise (the floor counts
    their noise through the model), and the verdict names the cut-off and the remedy; at
    the motion's cut-off, or with measured velocities at 10 Hz, the model is at the floor
    and nothing is said."""
    panda, d = logs
    high = _verdict(panda, d / "positions.csv", 10.0)
    low = _verdict(panda, d / "positions.csv", None)
    assert high.level == "good" and "a floor raised because" in high.reason, high.reason
    floor = lambda v: float(v.reason.split("noise floor of ")[1].split(" %")[0])  # noqa: E731
    assert floor(high) > 1.3 * floor(low), (high.reason, low.reason)
    assert re.search(r"derived from the positions at 10 Hz, 1.8 times .* \(5.5 Hz\)", high.reason)
    assert "hint: lower --cutoff (toward 5.5 Hz)" in high.reason
    for path, cutoff in ((d / "positions.csv", None), (d / "measured.csv", 10.0)):
        v = _verdict(panda, path, cutoff)
        assert v.level == "good" and "--cutoff" not in v.reason, (path.name, v)


def test_the_hint_needs_derived_velocities_and_a_cut_off_well_above_the_motions(logs):
    """None for measured velocities, without a cut-off or within 1.5 times the motion's;
    a verdict at the floor is left as it is."""
    from dynid.io.torque_log import load_torque_log

    _, d = logs
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", DynidWarning)
        pos, meas = load_torque_log(d / "positions.csv"), load_torque_log(d / "measured.csv")
    motion = common_cutoff([pos])
    assert pos.dq_derived and not meas.dq_derived
    assert derived_cutoff_hint([pos], 1.6 * motion) is not None
    assert derived_cutoff_hint([pos], 1.4 * motion) is None
    assert derived_cutoff_hint([pos], None) is None
    assert derived_cutoff_hint([meas], 3.0 * motion) is None
    good = Verdict("good", "at the noise floor", "error 0.5 %", 1.1)
    assert with_derived_cutoff_hint(good, [pos], 3.0 * motion) is good


def test_positions_logged_in_milliseconds_are_told_so_not_a_cutoff_error():
    """Regression (a positions-only log with its time in ms, 500 Hz read as 0.5 Hz, failed
    with "cutoff_hz must lie in (0, fs/2) = (0, 0.25) Hz; got 5 Hz", before any check could
    say milliseconds): the error gives the rate and the hint --units t=ms. A log sampled in
    seconds too slowly for the cut-off (it was refused: a 10 Hz servo log at the reader's
    5 Hz) has its velocities derived at a quarter of its rate: the sine's closed-form
    derivative inside the filter's edges."""
    from dynid.exceptions import DataError
    from dynid.signals import filtered_derivative

    t = np.arange(200) * 2.0  # ms
    q = np.sin(2 * np.pi * t[:, None] / 1000.0) * np.ones((1, 2))
    log = TorqueLog(t, q, np.zeros_like(q), np.zeros_like(q))
    with pytest.raises(DataError, match=r"sampled at 0\.5 Hz.*steps of 2 look like milli.*t=ms"):
        with_derived_velocities(log, 5.0)
    slow = TorqueLog(t / 200.0, q, np.zeros_like(q), np.zeros_like(q))  # 100 Hz, in seconds
    dq = with_derived_velocities(slow, 60.0).dq
    true = 2 * np.pi * 0.2 * np.cos(2 * np.pi * 0.2 * slow.t)  # q = sin(2 pi 0.2 t)
    inner = slice(20, -20)  # 0.2 s: beyond two periods of 25 Hz
    np.testing.assert_allclose(dq[inner, 0], true[inner], atol=1e-3)
    np.testing.assert_allclose(dq, filtered_derivative(slow.t, slow.q, 25.0), atol=1e-12)


def test_a_positions_only_file_too_slow_for_its_cutoff_is_named(tmp_path):
    """The error of a positions-only log read through a column map names its file (with
    several recordings it did not say which)."""
    from dynid.exceptions import DataError
    from dynid.io.columns import load_mapped_torque_log, parse_column_map

    t = np.arange(100) * 2.0  # ms, read as s
    q = np.sin(t[:, None] / 300.0) * np.ones((1, 2))
    body = np.column_stack([t, q, np.zeros_like(q)])
    np.savetxt(tmp_path / "slow.csv", body, delimiter=",", comments="",
               header="time_ms,pos_1,pos_2,effort_1,effort_2", fmt="%.17g")  # fmt: skip
    cmap = parse_column_map("t=time_ms,q=pos_{i},tau=effort_{i}", None)
    with pytest.raises(DataError, match=r"^slow\.csv: positions only, sampled at 0\.5 Hz"):
        load_mapped_torque_log(tmp_path / "slow.csv", cmap)
