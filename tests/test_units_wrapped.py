"""The units check across recordings reads a continuous joint recorded wrapped into
[-pi, pi) as the motion it is: its whole-turn jumps are not velocity."""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest

import dynid
from dynid.exceptions import DataError
from dynid.identification.log import TorqueLog
from dynid.simulation.measurement import sample_times, simulate_measurement
from dynid.simulation.trajectories import random_fourier
from dynid.workflows.recordings import Recorded, check_units


@pytest.fixture(scope="module")
def logs():
    panda = dynid.panda()
    t = sample_times(4.0, 200.0)
    out = []
    for seed in (1, 2, 3):
        log = simulate_measurement(
            panda,
            random_fourier(panda, np.random.default_rng(seed))(t),
            rng=np.random.default_rng(seed),
        )
        out.append(TorqueLog(log.t, log.q, log.dq, log.tau))
    return out


def _wrapped(log: TorqueLog, joint: int, turns: float) -> TorqueLog:
    """``log`` with ``joint`` moved by ``turns`` and wrapped into [-pi, pi), as a
    continuous joint's encoder gives it."""
    q = log.q.copy()
    q[:, joint] = np.mod(q[:, joint] + 2 * np.pi * turns + 6.0 * log.t + np.pi, 2 * np.pi) - np.pi
    dq = log.dq.copy()
    dq[:, joint] += 6.0  # the joint turns on: a wrap every second
    return TorqueLog(log.t, q, dq, log.tau)


def test_wrapped_joints_are_not_taken_for_other_units(logs):
    """Two recordings with a joint wrapped (it turns through +-pi every second) beside a
    third: the velocities against the positions' derivative were 0.01-0.7 times the
    others' and the recording was refused as 'recorded in other units'."""
    wrapped = [_wrapped(logs[0], 0, 0.3), _wrapped(logs[1], 0, 0.7), logs[2]]
    check_units(Recorded(tuple(wrapped), tuple(Path(f"r{k}.csv") for k in range(3))))


def test_velocities_in_other_units_are_still_named(logs):
    deg = TorqueLog(logs[1].t, logs[1].q, logs[1].dq * 180.0 / np.pi, logs[1].tau)
    rec = Recorded((_wrapped(logs[0], 0, 0.3), deg, logs[2]), (Path("a"), Path("b"), Path("c")))
    with pytest.raises(DataError, match="b: its velocities against the derivative"):
        check_units(rec)
