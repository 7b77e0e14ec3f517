"""A residual that follows the accelerations is named an inertia the model lacks.

``validate --params robot.urdf`` of a model identified with an armature (which a URDF
cannot hold; the export warned) gave 1.11 %, 3.01 x the noise floor, "usable", and called
each joint's residual a spring (it follows the position too: ``ddq`` near ``-w^2 q``). The
references: residuals made here as a known inertia times the accelerations, or a known
spring times the positions, of a Fourier motion; recordings simulated with known rotor
inertias that the robot validated lacks.
"""

from __future__ import annotations

import numpy as np
import pytest

from dynid.identification.residual_dependence import (
    acceleration_led,
    dependence_hint,
    position_led,
    residual_dependence,
)
from dynid.io.torque_log import save_torque_log
from dynid.simulation.measurement import SensorNoise
from dynid.workflows.validate import ValidateOptions, validate_files
from dynid.workflows.validate_hints import URDF_INERTIA

from conftest import recordings

#: The rotor inertias [kg m^2] at the Panda's joints the validated robot lacks.
ARMATURE = np.array([0.4, 0.4, 0.3, 0.3, 0.05, 0.05, 0.03])


def _motion(rng, n=3000):
    """A Fourier motion of one joint over 6 s: positions, velocities, accelerations."""
    t = np.linspace(0.0, 6.0, n)
    w = 2 * np.pi * 0.2 * np.arange(1, 6)
    a, b = rng.normal(0, 0.2, 5), rng.normal(0, 0.2, 5)
    q = (
        a[:, None] / w[:, None] * np.sin(w[:, None] * t)
        - b[:, None] / w[:, None] * np.cos(w[:, None] * t)
    ).sum(0)
    dq = (a[:, None] * np.cos(w[:, None] * t) + b[:, None] * np.sin(w[:, None] * t)).sum(0)
    ddq = (
        -a[:, None] * w[:, None] * np.sin(w[:, None] * t)
        + b[:, None] * w[:, None] * np.cos(w[:, None] * t)
    ).sum(0)
    return q[:, None], dq[:, None], ddq[:, None]


@pytest.mark.parametrize("seed", [1, 2, 3])
def test_an_inertia_residual_follows_the_acceleration_and_a_spring_the_position(seed):
    """``0.5 ddq`` plus noise reads as following the acceleration (not a spring); ``20 q``
    plus noise as following the position, not the acceleration."""
    rng = np.random.default_rng(seed)
    q, dq, ddq = _motion(rng)
    noise = 0.05
    inertia = 0.5 * ddq + rng.normal(0, noise, ddq.shape)
    spring = 20.0 * (q - q.mean()) + rng.normal(0, noise, q.shape)
    (d,) = residual_dependence([q], [dq], [inertia], np.array([noise]), ddq=[ddq])
    assert acceleration_led(d)
    said = dependence_hint([q], [dq], [inertia], np.array([noise]), ["j1"], ddq=[ddq])
    assert "follows its acceleration" in said and "armature to --terms" in said
    (d,) = residual_dependence([q], [dq], [spring], np.array([noise]), ddq=[ddq])
    assert not acceleration_led(d) and position_led(d)


def test_validate_of_a_urdf_without_the_armature_names_the_rotor_inertia(panda, tmp_path):
    """The Panda with rotor inertias (ARMATURE) the robot lacks, validated as a URDF's robot:
    the verdict says the residual follows the accelerations, a rotor inertia, and that a
    URDF holds none (the MJCF, a drive file with rotor_inertia); as another robot's, the
    remedy is the armature term."""
    (log,) = recordings(
        panda, (11,), friction=panda.friction, duration=4.0, armature=ARMATURE, noise=SensorNoise()
    )
    path = save_torque_log(tmp_path / "rec.csv", log)
    urdf = validate_files(panda, path, ValidateOptions(), label="robot robot.urdf").verdict
    assert urdf.level != "good"
    assert "follows its acceleration" in urdf.reason and URDF_INERTIA in urdf.reason
    assert "follows its position" not in urdf.reason
    other = validate_files(panda, path, ValidateOptions(), label="robot panda").verdict
    assert "follows its acceleration" in other.reason and URDF_INERTIA not in other.reason
