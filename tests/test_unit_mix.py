"""A recording in degrees among recordings in radians is refused before any fit.

Reference: simulated Panda logs in radians (the robot's own model), one of them rewritten
in degrees (``x 180 / pi`` on its positions, and on its velocities or not), and the Panda's
joint limits. Before, a recording whose positions and velocities were both in degrees
passed every check across recordings (its velocities agree with its positions' derivative)
and ``identify`` ended in a model of 76 % training error with exit 0, its first warning
blaming "currents logged as torques".
"""

from __future__ import annotations

import warnings
from pathlib import Path

import numpy as np
import pytest

import dynid
from dynid.cli.__main__ import main
from dynid.exceptions import DataError
from dynid.identification.log import TorqueLog
from dynid.identification.sanity import check_torque_log
from dynid.io.torque_log import save_torque_log
from dynid.simulation.measurement import sample_times, simulate_measurement
from dynid.simulation.trajectories import random_fourier
from dynid.workflows.recordings import LIMIT_MARGIN, Recorded, check_degrees

DEG = 180.0 / np.pi


@pytest.fixture(scope="module")
def panda():
    return dynid.panda()


@pytest.fixture(scope="module")
def logs(panda):
    t = sample_times(4.0, 200.0)
    out = []
    for seed in (1, 2, 3):
        traj = random_fourier(panda, np.random.default_rng(seed))(t)
        g = simulate_measurement(panda, traj, rng=np.random.default_rng(seed + 10))
        out.append(TorqueLog(g.t, g.q, g.dq, g.tau))
    return out


def _deg(log: TorqueLog, velocities: bool = True) -> TorqueLog:
    return TorqueLog(log.t, log.q * DEG, log.dq * DEG if velocities else log.dq, log.tau)


def _rec(*logs: TorqueLog) -> Recorded:
    return Recorded(tuple(logs), tuple(Path(f"r{k}.csv") for k in range(len(logs))))


def test_the_recording_in_degrees_is_named_with_the_columns_to_convert(panda, logs):
    # its positions are 180/pi times its own in radians: the scale against the others'
    # (other motions) is near that factor, and its positions fit the limits in degrees
    assert np.all(logs[1].q >= panda.q_min - LIMIT_MARGIN)
    assert np.all(logs[1].q <= panda.q_max + LIMIT_MARGIN)
    with pytest.raises(DataError, match=r"r1.csv: its positions and velocities look like") as e:
        check_degrees(_rec(logs[0], _deg(logs[1]), logs[2]), panda)
    assert "convert its q and dq to radians" in str(e.value)
    assert "hint: --units r1.csv:q=deg,r1.csv:dq=deg/s reads it in degrees" in str(e.value)
    with pytest.raises(DataError, match=r"hint: --units tau=-1,r1.csv:q=deg,r1.csv:dq=deg/s "):
        check_degrees(_rec(logs[0], _deg(logs[1]), logs[2]), panda, "tau=-1")
    with pytest.raises(DataError, match=r"r0.csv: its positions look like degrees") as e:
        check_degrees(_rec(_deg(logs[0], velocities=False), logs[1]), panda)
    assert "convert its q to radians" in str(e.value)


def test_recordings_in_radians_pass(panda, logs):
    """Other motions, one at rest and one of positions shifted within the limits: none is
    taken for degrees; all in degrees (nothing to compare with) is the single log's
    finding."""
    rest = TorqueLog(
        logs[2].t, np.broadcast_to(logs[2].q[0], logs[2].q.shape), 0 * logs[2].dq, logs[2].tau
    )
    check_degrees(_rec(*logs, rest), panda)
    check_degrees(_rec(*(_deg(g) for g in logs)), panda)
    found = check_torque_log(panda, _deg(logs[0]))
    assert len(found) == 1 and found[0].startswith("positions look like degrees"), found


def test_identify_refuses_it_in_one_line_before_any_fit(panda, logs, tmp_path, capsys):
    paths = [tmp_path / f"rad{k}.csv" for k in (1, 2)] + [tmp_path / "deg3.csv"]
    for p, g in zip(paths, (logs[0], logs[1], _deg(logs[2])), strict=True):
        save_torque_log(p, g)
    argv = ["identify", "--robot", "panda", "--no-figures", "--out", str(tmp_path / "i")]
    with warnings.catch_warnings():
        warnings.simplefilter("error")  # no warning before the refusal
        assert main([*argv, "--data", *map(str, paths)]) == 2
    err = [s for s in capsys.readouterr().err.splitlines() if s.strip()]
    assert len(err) == 1 and "error: deg3.csv: its positions and velocities look like" in err[0]
    assert not (tmp_path / "i").exists()
