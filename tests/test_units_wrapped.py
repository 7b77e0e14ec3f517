"""The units check across recordings reads a continuous joint recorded wrapped into
[-pi, pi) as the motion it is: its whole-turn jumps are not velocity; and a recording at
rest has no velocity unit to compare (its velocities and positions' derivative are noise)."""

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


def _at_rest(log: TorqueLog, rng: np.random.Generator) -> TorqueLog:
    """The arm held at ``log``'s first pose: encoder noise of 2e-5 rad on the positions,
    2e-3 rad/s on the velocities (as a UR10's), the torques held as they were."""
    N, n = log.q.shape
    q = log.q[0] + rng.normal(0.0, 2e-5, (N, n))
    return TorqueLog(log.t, q, rng.normal(0.0, 2e-3, (N, n)), log.tau)


def test_a_recording_at_rest_is_not_taken_for_other_units(logs):
    """Beside moving recordings, one at rest: its velocities against the positions'
    derivative (noise against noise, about 0.02 times the others') were refused as
    'recorded in other units'."""
    rest = _at_rest(logs[2], np.random.default_rng(7))
    check_units(Recorded((logs[0], logs[1], rest), (Path("a"), Path("b"), Path("rest"))))
    check_units(Recorded((logs[0], rest), (Path("a"), Path("rest"))))


def test_velocities_in_other_units_beside_a_recording_at_rest_are_named(logs):
    rest = _at_rest(logs[2], np.random.default_rng(7))
    deg = TorqueLog(logs[1].t, logs[1].q, logs[1].dq * 180.0 / np.pi, logs[1].tau)
    rec = Recorded((logs[0], deg, rest), (Path("a"), Path("deg"), Path("rest")))
    with pytest.raises(DataError, match="deg: its velocities against the derivative"):
        check_units(rec)
