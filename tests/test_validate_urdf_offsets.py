"""What a URDF cannot hold is said where ``validate --params robot.urdf`` names it.

A Baxter trial validated its identified model's URDF export: the verdict called three
joints' residuals constants "(an offset)" without saying that a URDF holds no torque
offsets, nor which file holds the full model. The reference: recordings simulated here
with a known constant torque on one joint, which the validated robot lacks.
"""

from __future__ import annotations

import re

import numpy as np

from dynid.identification.residual_dependence import dependence_hint
from dynid.io.torque_log import save_torque_log
from dynid.simulation.measurement import SensorNoise
from dynid.workflows.validate import ValidateOptions, validate_files

from conftest import recordings

#: The constant torque [N m] on joint 4 the validated robot lacks.
OFFSET = np.array([0.0, 0.0, 0.0, 1.5, 0.0, 0.0, 0.0])
#: What the verdict says once after the joints for a URDF's robot.
FULL_MODEL = (
    "a URDF holds no torque offsets: validate the identification's feasible.json "
    "(--params) or identification.json (--model) for the full model"
)


def test_validate_of_a_urdf_says_it_holds_no_offset(panda, tmp_path):
    """The Panda with 1.5 N m on joint 4, validated as a URDF's robot: joint 4's residual
    is the constant (1.5 N m to 5 %), "an offset, which a URDF cannot hold", and the
    line says once which files hold the full model; as a built-in robot's, "(an offset)"
    alone."""
    (log,) = recordings(
        panda,
        (11,),
        friction=panda.friction,
        duration=4.0,
        added=lambda log: np.broadcast_to(OFFSET, log.tau.shape),
        noise=SensorNoise(),
    )
    path = save_torque_log(tmp_path / "rec.csv", log)
    urdf = validate_files(panda, path, ValidateOptions(), label="robot robot.urdf").verdict
    name = panda.joint_names[3]
    said = re.search(
        rf"{name}: ([0-9.]+) of [0-9.]+ N m RMS residual is a constant \(an offset, which a "
        r"URDF cannot hold\)",
        urdf.reason,
    )
    assert said is not None, urdf.reason
    np.testing.assert_allclose(float(said[1]), OFFSET[3], rtol=0.05)
    assert urdf.reason.endswith(f"; {FULL_MODEL}"), urdf.reason
    assert urdf.reason.count(FULL_MODEL) == 1
    other = validate_files(panda, path, ValidateOptions(), label="robot panda").verdict
    assert f"{name}: " in other.reason and "is a constant (an offset)" in other.reason
    assert "URDF" not in other.reason, other.reason


def test_a_friction_residual_of_a_urdf_names_what_the_file_holds():
    """A residual of Coulomb friction (0.8 tanh(dq / 0.05) N m plus noise) on a joint of a
    URDF's robot: "friction the law misses or a URDF cannot hold", and the note names
    friction beyond viscous and Coulomb (no offset); without the file, neither."""
    rng = np.random.default_rng(7)
    t = np.linspace(0.0, 6.0, 3000)[:, None]
    q, dq = 0.5 * np.sin(2.1 * t), 1.05 * np.cos(2.1 * t)
    noise = 0.05
    error = 0.8 * np.tanh(dq / 0.05) + rng.normal(0.0, noise, dq.shape)
    args = ([q], [dq], [error], np.array([noise]), ["j1"])
    said = dependence_hint(*args, lacks="a URDF")
    assert said is not None and "(friction the law misses or a URDF cannot hold;" in said, said
    assert said.endswith(
        "; a URDF holds no friction beyond viscous and Coulomb: validate the "
        "identification's feasible.json (--params) or identification.json (--model) for "
        "the full model"
    ), said
    plain = dependence_hint(*args)
    assert plain is not None and "URDF" not in plain and "follows its velocity" in plain
