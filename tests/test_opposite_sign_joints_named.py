"""The refusal of torques of the opposite sign never lists a joint of positive correlation
among those "anti-correlated on every joint judged": a joint the friction check calls
opposite is named apart, with what told it.

Regression: a UR5 log negated whole read "anti-correlated ... on every joint judged
(..., wrist_1_joint +0.18, ...)".

Reference: a simulated UR5 (example-robot-data) with known friction and rotor inertias
whose torques are negated on every joint.
"""

from __future__ import annotations

import dataclasses
import re

import numpy as np

import dynid
from dynid.friction.model import ClassicalFriction
from dynid.identification.model_sign import opposite_sign
from dynid.simulation.measurement import SensorNoise

from conftest import recordings, robot_data_urdf


def test_a_joint_of_positive_correlation_is_named_apart():
    """Seed 6, 4 s: every joint's torques negated; the finding lists only negative
    correlations under "every joint judged", names wrist_1 apart ("every joint judged
    but wrist_1_joint") with its positive correlation and its friction's evidence, and
    still hints --units tau=-1."""
    ur5 = dynid.Robot.from_urdf(
        robot_data_urdf("ur_description/urdf/ur5_robot.urdf"), tip_link="tool0"
    )
    friction = ClassicalFriction(
        np.array([6.0, 5.0, 3.0, 1.0, 0.8, 0.6]),
        np.array([8.0, 7.0, 4.0, 1.5, 1.2, 1.0]),
        np.array([0.5, -1.0, 0.7, 0.2, -0.15, 0.1]),
    )
    (log,) = recordings(
        ur5,
        (6,),
        friction=friction,
        duration=4.0,
        fs=250.0,
        armature=[0.45, 0.4, 0.3, 0.2, 0.15, 0.1],
        noise=SensorNoise(0.05, 1e-5, 1e-3),
    )
    said = opposite_sign(ur5, dataclasses.replace(log, tau=-log.tau))
    assert said is not None
    listed = said.split("on every joint judged", 1)[1].split(")")[0]
    corr = [float(x) for x in re.findall(r" ([+-]\d\.\d\d)", listed)]
    assert corr and all(c < 0 for c in corr), said
    assert "on every joint judged but wrist_1_joint (" in said, said
    told = said.split("; wrist_1_joint: correlation ", 1)[1]
    assert float(told[:5]) >= 0 and "friction would push the arm" in told[:200], said
    assert "--units tau=-1" in said
