"""The library pipeline (dynid.pipeline): what stages hand on, and what a stage refuses."""

from __future__ import annotations

import numpy as np
import pytest

import dynid
from dynid.identification.least_squares import LeastSquaresFit
from dynid.identification.model import IdentifiedModel
from dynid.io.model_json import load_model_json, save_model_json
from dynid.pipeline import friction_stage, kinematics_only
from dynid.regressors.base import base_parameters


def _model(robot: dynid.Robot) -> IdentifiedModel:
    base = base_parameters(robot)
    r = base.rank
    fit = LeastSquaresFit(
        base.beta_from_phi(robot.phi),
        np.zeros(r),
        np.zeros(r),
        np.ones(r, bool),
        r,
        1.0,
        0.0,
        0.0,
        0.0,
        0,
        1e-10,
    )
    return IdentifiedModel(robot, base, fit)


def test_kinematics_only_keeps_what_an_identification_file_records(tmp_path):
    """kinematics_only drops link parameters, friction and neutral pose, like a saved model."""
    model = _model(dynid.panda())
    kept = kinematics_only(model)
    loaded = load_model_json(save_model_json(tmp_path / "identification.json", model))
    for robot in (kept.robot, loaded.robot):
        assert not np.any(robot.phi) and robot.friction is None and robot.q_neutral is None
    np.testing.assert_array_equal(kept.robot.T_parent_joint, loaded.robot.T_parent_joint)
    np.testing.assert_array_equal(kept.beta, model.beta)
    assert kept.robot.frames.keys() == loaded.robot.frames.keys()


def test_friction_stage_refuses_a_truth_without_link_parameters():
    """A model read back from a file cannot play the real robot: the stage asks for truth=."""
    with pytest.raises(dynid.DynidError, match="pass truth="):
        friction_stage(kinematics_only(_model(dynid.panda())), seed=0)
