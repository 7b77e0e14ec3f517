"""Which model ``dynid observe`` runs with, said to the user: thresholds record the files
of the model they were calibrated with (names and a SHA-256 of their content) and warn when
they are used with another; a URDF's own ``<dynamics>`` friction, used when no
``--friction`` is given, is named in a note."""

from __future__ import annotations

import json
import shutil
import warnings

import numpy as np
import pytest

import dynid
from dynid.exceptions import DynidWarning
from dynid.friction.model import ClassicalFriction
from dynid.io.friction_json import save_friction_json
from dynid.io.robot.urdf import urdf_from_robot
from dynid.io.torque_log import save_torque_log
from dynid.simulation.measurement import SensorNoise, simulate_measurement
from dynid.simulation.trajectories import random_fourier, uniform_times
from dynid.workflows.observe import ObserveOptions, observe_files

FV = np.array([0.4, 0.4, 0.3, 0.3, 0.2, 0.2, 0.1])  # the URDF's damping [N m s/rad]
FC = np.array([1.5, 2.0, 1.0, 1.0, 0.5, 0.5, 0.3])  # and its friction [N m]


@pytest.fixture(scope="module")
def files(tmp_path_factory):
    """A Panda URDF with <dynamics> friction, a copy of it under another name, a
    friction.json of other coefficients, and a 3 s free log of the URDF's friction."""
    d = tmp_path_factory.mktemp("model_match")
    robot = dynid.panda()
    (d / "arm.urdf").write_text(urdf_from_robot(robot, dynamics=(FV, FC)))
    shutil.copy(d / "arm.urdf", d / "same.urdf")
    truth = ClassicalFriction(FV, FC, np.zeros(7), np.full(7, 5e-3))
    save_friction_json(d / "other.json", ClassicalFriction(FV, 2 * FC, np.zeros(7)))
    rng = np.random.default_rng(1)
    traj = random_fourier(robot, rng, n_harmonics=3, w_f=2 * np.pi / 3)(uniform_times(3.0))
    log = simulate_measurement(robot, traj, rng=rng, noise=SensorNoise(), friction=truth)
    save_torque_log(d / "free.csv", log)
    return d


def _run(d, params, friction=None, thresholds=None, out=None):
    opts = ObserveOptions(
        data=(d / "free.csv",), params=str(d / params), friction=friction,
        calibrate=thresholds is None, thresholds=thresholds, keep_series=False,
    )  # fmt: skip
    with warnings.catch_warnings(record=True) as seen:
        warnings.simplefilter("always")
        result = observe_files(opts)
    if out is not None:
        from dynid.io.observer_files import save_observation

        save_observation(out, result, joints=list(dynid.panda().joint_names), calibrating=True)
    said = [str(w.message) for w in seen if issubclass(w.category, DynidWarning)]
    return result, said


def test_thresholds_warn_when_used_with_another_model_than_their_own(files, tmp_path):
    """Calibrated with arm.urdf, the thresholds record its name and content: detecting with
    the same content under another name (same.urdf) says nothing, with another friction
    file one warning naming both models (it ran silently: only the joint count was
    checked)."""
    d = files
    cal, _ = _run(d, "arm.urdf", out=tmp_path)
    rec = json.loads((tmp_path / "thresholds.json").read_text())["calibration"]
    assert rec["model_files"] == ["arm.urdf"] and len(rec["model_sha256"]) == 64
    th = tmp_path / "thresholds.json"
    _, said = _run(d, "same.urdf", thresholds=th)
    assert not [s for s in said if "calibrated with" in s]
    _, said = _run(d, "arm.urdf", friction=d / "other.json", thresholds=th)
    (warned,) = [s for s in said if "calibrated with" in s]
    assert "thresholds.json was calibrated with arm.urdf (sha256 " in warned
    assert "not with this model (arm.urdf + other.json (sha256 " in warned


def test_a_urdf_s_own_friction_is_named_in_a_note(files):
    """Without --friction the model holds the URDF's <dynamics damping friction>: a note
    names the file and its largest coefficients (as written); with --friction, none."""
    d = files
    result, _ = _run(d, "arm.urdf")
    (note,) = [n for n in result.notes if n.startswith("the friction is")]
    assert note.startswith("the friction is arm.urdf's own <dynamics damping friction>")
    assert f"fc up to {FC.max():.3g} N m, fv up to {FV.max():.3g} N m s/rad" in note
    assert "--friction" in note
    result, _ = _run(d, "arm.urdf", friction=d / "other.json")
    assert not [n for n in result.notes if n.startswith("the friction is")]
