"""Logged torques beyond the description's effort limits are named in a note (a simulated
TALOS arm logged at 1.7 x its URDF's effort said nothing), against the Panda's published
limits (87 N m on joints 1-4, 12 N m on 5-7)."""

from __future__ import annotations

import dataclasses
import logging
from pathlib import Path

import numpy as np

import dynid
from dynid.identification.effort_limits import effort_limit_finding
from dynid.identification.log import TorqueLog
from dynid.workflows.recordings import Recorded, check_limits


def _log(tau: np.ndarray) -> TorqueLog:
    """A log at rest mid-way between the Panda's joint limits, with torques ``tau``."""
    robot, n = dynid.panda(), len(tau)
    q = np.tile(0.5 * (robot.q_min + robot.q_max), (n, 1))
    return TorqueLog(np.arange(n) * 1e-3, q, np.zeros((n, 7)), tau)


def _alternating(peaks: list[float], n: int = 2000) -> np.ndarray:
    """Torques at +-peak, alternating sample by sample (every sample at the peak)."""
    sign = np.where(np.arange(n) % 2 == 0, 1.0, -1.0)[:, None]
    return sign * np.asarray(peaks)[None, :]


def test_torques_within_the_limits_say_nothing():
    tau = _alternating([80.0, 87.0, 60.0, 40.0, 12.0, 11.0, 5.0])
    assert effort_limit_finding(dynid.panda(), [tau]) is None


def test_a_joint_past_its_limit_is_named_with_peak_limit_and_ratio():
    tau = _alternating([80.0, 40.0, 60.0, 40.0, 20.4, 11.0, 5.0])
    said = effort_limit_finding(dynid.panda(), [tau[:1000], tau[1000:]])
    assert said is not None
    joint = dynid.panda().joint_names[4]
    assert f"{joint} (peak 20.4 N m, limit 12 N m: 1.7 x)" in said
    assert dynid.panda().joint_names[0] not in said  # 80 of 87


def test_one_spike_is_not_a_peak():
    tau = _alternating([10.0] * 7)
    tau[500, 4] = 100.0  # one sample of 2000, a sensor's spike
    assert effort_limit_finding(dynid.panda(), [tau]) is None


def test_a_prismatic_joint_is_said_in_newtons():
    robot = dynid.panda()
    rail = dataclasses.replace(robot, prismatic=np.r_[True, np.zeros(6, bool)])
    tau = _alternating([200.0, 0, 0, 0, 0, 0, 0])
    said = effort_limit_finding(rail, [tau])
    assert said is not None and "(peak 200 N, limit 87 N: 2.3 x)" in said


def test_the_commands_check_notes_it(caplog):
    tau = _alternating([10.0, 10.0, 10.0, 10.0, 24.0, 1.0, 1.0])
    rec = Recorded((_log(tau),), (Path("arm.csv"),))
    with caplog.at_level(logging.INFO):
        check_limits(rec, dynid.panda())
    said = [r.getMessage() for r in caplog.records if "effort limits" in r.getMessage()]
    assert len(said) == 1 and "(peak 24 N m, limit 12 N m: 2 x)" in said[0]


def test_a_limit_at_the_largest_float_is_no_limit():
    """An export writes a joint without a limit as the largest float: no overflow, no note."""
    robot = dataclasses.replace(dynid.panda(), tau_max=np.full(7, np.finfo(float).max))
    with np.errstate(over="raise"):
        assert effort_limit_finding(robot, [_alternating([100.0] * 7)]) is None
