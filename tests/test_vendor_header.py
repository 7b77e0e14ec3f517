"""A vendor API's header: the joint's number inside the names, units at their ends.

Reference: a simulated Panda log (the robot's own model) written as a Kinova Kortex logger
writes one: ``timestamp_us, joint_{i0}_position_deg, joint_{i0}_velocity_degps,
joint_{i0}_torque_Nm, joint_{i0}_current_A``. Before, the header got no ``--columns``
suggestion (the docs promise one for a header whose signals can be told by their names),
the current columns were dropped without a word, and the wrap note said ``[-pi, pi]`` of
joints recorded in ``[0, 360)`` degrees.
"""

from __future__ import annotations

import logging
import re
from pathlib import Path

import numpy as np
import pytest

import dynid
from dynid.exceptions import DataError
from dynid.identification.log import TorqueLog
from dynid.identification.pieces import wrapped_finding
from dynid.io.column_hint import guessed_map, unit_entries
from dynid.progress import NOTE
from dynid.simulation.measurement import sample_times, simulate_measurement
from dynid.simulation.trajectories import random_fourier
from dynid.workflows.recordings import read_recordings

DEG = 180.0 / np.pi


@pytest.fixture(scope="module")
def truth():
    panda = dynid.panda()
    t = sample_times(2.0, 500.0)
    traj = random_fourier(panda, np.random.default_rng(5))(t)
    g = simulate_measurement(panda, traj, rng=np.random.default_rng(6))
    return panda, TorqueLog(g.t, g.q, g.dq, g.tau)


def _kortex_csv(path: Path, log: TorqueLog) -> Path:
    n = log.n
    head = ["timestamp_us"]
    for what in ("position_deg", "velocity_degps", "torque_Nm", "current_A"):
        head += [f"joint_{j}_{what}" for j in range(n)]
    rows = np.column_stack(
        [8.1e9 + log.t * 1e6, log.q * DEG, log.dq * DEG, log.tau, log.tau / 11.0]
    )
    np.savetxt(path, rows, delimiter=",", header=",".join(head), comments="", fmt="%.17g")
    return path


def test_the_header_is_offered_the_map_and_units_that_read_it(truth, tmp_path, caplog):
    """The refusal of the header holds --columns and --units; read with them the file is
    the simulated log (t, q, dq, tau to round-off), the currents named in one note."""
    panda, log = truth
    path = _kortex_csv(tmp_path / "k.csv", log)
    with pytest.raises(DataError) as e:
        read_recordings([path], panda)
    msg = str(e.value)
    cols = re.search(r"--columns '([^']+)'", msg).group(1)
    units = re.search(r"--units '([^']+)'", msg).group(1)
    assert cols == (
        "t=timestamp_us,q=joint_{i0}_position_deg,dq=joint_{i0}_velocity_degps,"
        "tau=joint_{i0}_torque_Nm"
    ), msg
    assert units == "t=us,q=deg,dq=deg/s", msg
    with caplog.at_level(NOTE):
        ok = read_recordings([path], panda, columns=(cols, units)).logs[0]
    np.testing.assert_allclose(ok.t - ok.t[0], log.t - log.t[0], atol=1e-6)
    np.testing.assert_allclose(ok.q, log.q, atol=1e-12)
    np.testing.assert_allclose(ok.dq, log.dq, atol=1e-12)
    np.testing.assert_allclose(ok.tau, log.tau, atol=1e-12)
    said = [r.getMessage() for r in caplog.records if "current" in r.getMessage()]
    assert said == [
        "k.csv: column(s) joint_0_current_A..joint_6_current_A named by no --columns "
        "entry: not read"
    ], said
    assert all(r.levelno == NOTE for r in caplog.records if "current" in r.getMessage())
    assert not [r for r in caplog.records if r.levelno >= logging.WARNING]


def test_the_guess_of_a_mapped_file_says_the_units_its_names_end_with():
    names = ["timestamp_us", *(f"joint_{j}_position_deg" for j in range(3))]
    names += [f"joint_{j}_torque_mNm" for j in range(3)]
    assert guessed_map(names) == (
        "--columns 't=timestamp_us,q=joint_{i0}_position_deg,tau=joint_{i0}_torque_mNm' "
        "--units 't=us,q=deg,tau=mNm'"
    )
    assert unit_entries({"tau": "present_current_{i}"}) == ["tau=A"]
    assert unit_entries({"q": "position{i}", "dq": "velocity_rad_s{i}"}) == []
    assert unit_entries({"q": "pos_deg_{i0}", "dq": "vel_deg_s_{i0}"}) == ["q=deg", "dq=deg/s"]


def test_the_wrap_note_says_the_range_the_data_show(truth):
    """Positions recorded in [0, 360) degrees (np.mod of the truth) are said to be wrapped
    into [0, 2 pi); those wrapped by angle(exp(i q)) into [-pi, pi]."""
    _, log = truth
    q = log.q + np.linspace(0.0, 8.0, log.n_samples)[:, None]  # several whole turns
    vendor = TorqueLog(log.t, np.mod(q, 2 * np.pi), log.dq, log.tau)
    assert "recorded wrapped into [0, 2 pi)" in wrapped_finding([0, 3], log=vendor)
    ros = TorqueLog(log.t, np.angle(np.exp(1j * q)), log.dq, log.tau)
    assert "recorded wrapped into [-pi, pi]" in wrapped_finding([0, 3], log=ros)
