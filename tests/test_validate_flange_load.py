"""A load at the flange the model lacks is named first by validate's verdict.

A Talos arm's log carrying a 0.8 kg payload its model lacked was judged "poor, 10.9 x the
noise floor" with a spring on joint 6 and armature on joints 5 and 7 blamed, and nothing
said of the load. The references: recordings of the Panda simulated with a known rigid
load fixed at the flange (mass, CoM, inertia), validated with the robot without it; the
same arm without the load (clean), with rotor inertias the robot lacks, and with friction
the validation leaves out.
"""

from __future__ import annotations

import numpy as np
import pytest

from dynid.io.torque_log import save_torque_log
from dynid.observer.residual_load import residual_load
from dynid.simulation.measurement import SensorNoise
from dynid.workflows.validate import ValidateOptions, validate_files

from conftest import recordings

#: The load's mass [kg], CoM [m] in the flange's axes and inertia about it [kg m^2].
MASS, COM, INERTIA = 0.8, np.array([0.02, -0.01, 0.06]), np.diag([2e-3, 2e-3, 1e-3])
#: Rotor inertias [kg m^2] at the Panda's joints that the robot validated lacks.
ARMATURE = np.array([0.4, 0.4, 0.3, 0.3, 0.05, 0.05, 0.03])
SAID = "a load at the flange the model lacks"


def _validated(robot, truth, tmp_path, seed=11, **kw):
    """``robot`` validated on a noisy 4 s recording of ``truth`` (its own friction)."""
    fr = kw.pop("options", ValidateOptions())
    (log,) = recordings(
        truth, (seed,), friction=robot.friction, duration=4.0, noise=SensorNoise(), **kw
    )
    path = save_torque_log(tmp_path / "rec.csv", log)
    return validate_files(robot, path, fr, label="robot panda")


def test_a_load_the_model_lacks_is_named_first_with_its_mass(panda, tmp_path):
    """The Panda carrying 0.8 kg (CoM 6 cm out) its robot lacks: the verdict names the
    load first, its mass within 2 % and its CoM within 5 mm of the truth, the command that
    measures it, and no joint's residual as a cause of its own; validation.json keeps it."""
    truth = panda.with_tool(np.eye(4), MASS, COM, INERTIA, name="load")
    res = _validated(panda, truth, tmp_path)
    load = res.flange_load
    assert res.verdict.level != "good" and load is not None and load.named
    assert load.mass == pytest.approx(MASS, rel=0.02)
    assert np.max(np.abs(load.com - COM)) < 5e-3
    reason = res.verdict.reason
    assert SAID in reason and "`dynid payload --robot panda --data" in reason
    after = reason.split(SAID, 1)[0]
    assert "follows its" not in after and "spring" not in after
    assert f"{MASS:.2f} kg" in reason
    kept = res.metadata()["flange_load"]
    assert kept["named"] and kept["mass"] == pytest.approx(MASS, rel=0.02)


def test_no_load_is_fitted_or_named_on_the_clean_arm(panda, tmp_path):
    """The robot validated on its own recording is at the floor: no load judged or said;
    the fit on its residual gives no mass clear of zero and explains little."""
    res = _validated(panda, panda, tmp_path)
    assert res.verdict.level == "good" and res.flange_load is None
    assert SAID not in res.verdict.reason
    parts = res.validation.parts
    load = residual_load(
        panda, [v.log.q for v in parts], [v.log.dq for v in parts], [v.log.ddq for v in parts],
        [v.log.tau - v.tau_hat for v in parts], res.noise_rms,
    )  # fmt: skip
    assert load is not None and not load.named and load.explained < 0.2


def test_a_missing_armature_is_not_read_as_a_load(panda, tmp_path):
    """Rotor inertias the robot lacks (the wrist's look like a flange's inertia): the
    verdict is poor and names the accelerations, not a load."""
    res = _validated(panda, panda, tmp_path, armature=ARMATURE)
    assert res.verdict.level != "good" and res.flange_load is not None
    assert not res.flange_load.named and SAID not in res.verdict.reason
    assert "follows its acceleration" in res.verdict.reason


def test_friction_left_out_is_not_read_as_a_load(panda, tmp_path):
    """The robot validated without the friction its recording holds: no load named."""
    res = _validated(panda, panda, tmp_path, options=ValidateOptions(friction="none"))
    assert res.verdict.level != "good" and res.flange_load is not None
    assert not res.flange_load.named and SAID not in res.verdict.reason


def test_the_joints_are_diagnosed_on_what_the_load_leaves(panda, tmp_path):
    """The load and a tenth of the rotor inertias both missing: the load is named first,
    the accelerations' residual said after it, on what the load leaves."""
    truth = panda.with_tool(np.eye(4), MASS, COM, INERTIA, name="load")
    res = _validated(panda, truth, tmp_path, armature=ARMATURE / 10)
    assert res.flange_load is not None and res.flange_load.named
    assert res.flange_load.mass == pytest.approx(MASS, rel=0.03)
    head, rest = res.verdict.reason.split(SAID, 1)
    assert "follows its" not in head and "what it leaves: " in rest
    assert "follows its acceleration" in rest.split("what it leaves: ", 1)[1]
