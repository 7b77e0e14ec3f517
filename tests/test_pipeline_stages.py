"""The library pipeline (dynid.pipeline): what stages hand on, and what a stage refuses."""

from __future__ import annotations

from typing import get_args

import numpy as np
import pytest

import dynid
from dynid.identification.model import IdentifiedModel
from dynid.io.model_json import load_model_json, save_model_json
from dynid.pipeline import friction_stage, kinematics_only

from conftest import exact_model


def _model(robot: dynid.Robot) -> IdentifiedModel:
    """Exact coefficients of ``robot``'s own parameters."""
    return exact_model(robot, robot)


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


def test_run_demo_chains_the_stages_and_reports_progress(monkeypatch):
    """run_demo runs stages 1-6 in order, hands stages 3, 4 and 6 the kinematics-only model
    and the fitted friction, and brackets every stage with started/finished events."""
    import dynid.pipeline.demo as demo
    from dynid.pipeline import STAGES, StageFinished, StageKind, StageStarted, run_demo

    robot = dynid.panda()
    model = _model(robot)
    calls = []

    class Fit:
        friction = "fitted friction"

    def stage(name, result):
        def run(*args, **kw):
            calls.append((name, args, kw))
            return result

        return run

    ident = type("Ident", (), {"model": model})()
    fric = type("Fric", (), {"fit": Fit()})()
    monkeypatch.setattr(demo, "kinematics_stage", stage("kinematics", "k"))
    monkeypatch.setattr(demo, "identification_stage", stage("identification", ident))
    monkeypatch.setattr(demo, "friction_stage", stage("friction", fric))
    monkeypatch.setattr(demo, "feasible_stage", stage("feasible", "f"))
    monkeypatch.setattr(demo, "consistent_stage", stage("consistent", "c"))
    monkeypatch.setattr(demo, "collision_stage", stage("collision", "x"))
    events = []
    res = run_demo(robot, 7, progress=events.append)
    assert [c[0] for c in calls] == [
        "kinematics",
        "identification",
        "friction",
        "feasible",
        "consistent",
        "collision",
    ]
    assert [(type(e), e.number) for e in events] == [
        (t, k) for k in range(1, 7) for t in (StageStarted, StageFinished)
    ]
    # every event says which stage it is; a finished stage's result is the field of its kind
    kinds = [e.stage.kind for e in events[::2]]
    assert kinds == [c[0] for c in calls] == [s.kind for s in STAGES]
    assert set(kinds) == set(get_args(StageKind))
    for e in events[1::2]:
        assert e.result is getattr(res, e.stage.kind)
    np.testing.assert_array_equal(calls[0][1][1], robot.q_neutral)
    handed = calls[2][1][0]
    assert not np.any(handed.robot.phi) and calls[2][2]["truth"] is robot
    assert calls[3][1][0] is handed and calls[3][2]["truth"] is robot
    assert calls[3][2]["friction"] == "fitted friction" and calls[3][2]["seed"] == 7
    assert (res.kinematics, res.feasible, res.consistent, res.seed) == ("k", "f", "c", 7)
    assert res.collision == "x" and calls[5][1][:2] == (handed, "fitted friction")
    assert calls[5][2]["truth"] is robot


def test_collision_stage_finds_the_push_with_the_identified_model():
    """Stage 6 with the exact model and the true friction: one event, at the push, found
    within 20 ms, the residual within 0.2 N m (RMS) of the true external torque's lag."""
    from dynid.pipeline import collision_stage

    robot = dynid.panda()
    model = kinematics_only(_model(robot))
    res = collision_stage(model, robot.friction, 0, truth=robot)
    assert len(res.events) == 1 and res.delay is not None and 0 <= res.delay < 0.02
    assert np.all(res.residual_error_rms < 0.2)


def test_demo_help_lists_every_stage(capsys):
    """Regression: `dynid demo --help` listed stages 1-5 while the demo runs a sixth, the
    collision detection; every stage the pipeline runs is listed by number and kind."""
    from dynid.cli.__main__ import main
    from dynid.pipeline import STAGES

    assert main(["demo", "--help"]) == 0
    text = capsys.readouterr().out
    for stage in STAGES:
        assert f"{stage.number}. {stage.kind}" in text, (stage, text)
