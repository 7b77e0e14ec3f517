"""Which model ``dynid observe`` runs with, said to the user: thresholds record the files
of the model they were calibrated with (names and a SHA-256 of their content) and warn when
they are used with another; a URDF's own ``<dynamics>`` friction, used when no
``--friction`` is given, is named in a note; a joint-count error of a URDF read to its
default tip names the chain and ``--tip``; the note of a log without velocities gives the
observer's cut-off, and a sign flipped by ``--units tau=-1`` is a note."""

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
    (d / "changed.urdf").write_text((d / "arm.urdf").read_text().replace("0.4", "0.41", 1))
    _, said = _run(d, "changed.urdf", thresholds=th)
    (warned,) = [s for s in said if "calibrated with" in s]
    assert "thresholds.json was calibrated with arm.urdf (sha256 " in warned
    assert "not with this model (changed.urdf (sha256 " in warned


def test_thresholds_calibrated_with_another_friction_say_which_option_differs(files, tmp_path):
    """A detection run without the --friction the thresholds were calibrated with (or with
    one they were calibrated without) is told that --friction is missing (or added), not
    that two hashes differ."""
    d = files
    _run(d, "arm.urdf", friction=d / "other.json", out=tmp_path)
    rec = json.loads((tmp_path / "thresholds.json").read_text())["calibration"]
    assert rec["model_roles"] == ["params", "friction"]
    th = tmp_path / "thresholds.json"
    _, said = _run(d, "arm.urdf", thresholds=th)
    (warned,) = [s for s in said if "calibrated with" in s]
    assert warned.startswith(
        "thresholds.json was calibrated with --friction other.json, and this run has no "
        "--friction: give --friction other.json as then"
    )
    assert "sha256" not in warned
    _, said = _run(d, "arm.urdf", friction=d / "other.json", thresholds=th)
    assert not [s for s in said if "calibrated with" in s]
    cal2 = tmp_path / "without"
    _run(d, "arm.urdf", out=cal2)
    _, said = _run(d, "arm.urdf", friction=d / "other.json", thresholds=cal2 / "thresholds.json")
    (warned,) = [s for s in said if "calibrated with" in s]
    assert "calibrated without --friction, and this run gives --friction other.json" in warned


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


def test_a_joint_count_error_of_a_urdf_s_default_tip_names_the_chain_and_tip(files):
    """A URDF read to its only leaf (a Z1's gripper joint made 7 joints) blamed the 6-joint
    friction, drive or thresholds file alone; the error now names the chain's joint count,
    its last joint and link and --tip. With --tip given, no such hint."""
    from dynid.exceptions import DataError, OptionError
    from dynid.io.robot_file import load_robot

    d = files
    robot = load_robot(str(d / "arm.urdf"))
    save_friction_json(d / "six.json", ClassicalFriction(FV[:6], FC[:6], np.zeros(6)))
    chain = (
        f"the model is arm.urdf's chain to its only leaf ({robot.n} joints, the last "
        f"{robot.joint_names[-1]} moving {robot.link_names[-1]}); hint: end it earlier with "
        "--tip LINK"
    )
    with pytest.raises(DataError) as err:
        _run(d, "arm.urdf", friction=d / "six.json")
    assert str(err.value) == f"six.json: friction for 6 joints; the model has 7; {chain}"
    (d / "six.toml").write_text(
        'schema = "dynid-drive/1"\nside = "joint"\ngear_ratio = 1\n'
        "rotor_inertia = [0.1, 0.1, 0.1, 0.1, 0.1, 0.1]\n"
    )
    opts = ObserveOptions(data=(d / "free.csv",), params=str(d / "arm.urdf"),
                          drive=d / "six.toml", calibrate=True)  # fmt: skip
    with pytest.raises(DataError, match=r"rotor_inertia.*7 numbers.*; " + "the model is arm"):
        observe_files(opts)
    th = d / "th6.json"
    th.write_text(
        json.dumps(
            {
                "schema": "dynid-thresholds/1",
                "contact": [1.0] * 6,
                "collision": [2.0] * 6,
                "rule": {"margin": 1.5, "quantile": 1.0, "collision_factor": 2.0},
                "observer": {"gain": [50.0] * 6, "discretisation": "exact", "rule": "trapezoid"},
            }
        )  # fmt: skip
    )
    with pytest.raises(OptionError, match=r"thresholds for 6 joints; the model has 7; the model"):
        _run(d, "arm.urdf", thresholds=th)
    tip = robot.link_names[-1]
    opts = ObserveOptions(data=(d / "free.csv",), params=str(d / "arm.urdf"), tip=tip,
                          friction=d / "six.json", calibrate=True)  # fmt: skip
    with pytest.raises(DataError) as err:
        observe_files(opts)
    assert "--tip" not in str(err.value)


def test_the_velocity_note_gives_the_cut_off_the_observer_derives_at(tmp_path):
    """The note of a log without velocities said "the observer at its own; 5 Hz when read
    alone" while the observer derives them at 20 Hz: the note gives the cut-off whose
    derivative the observer runs on (recomputed here from the positions)."""
    from pathlib import Path

    from dynid.identification.log import velocity_note, with_derived_velocities
    from dynid.observer import from_robot
    from dynid.signals import filtered_derivative
    from dynid.workflows.observe_logs import prepared_log

    robot = dynid.panda()
    rng = np.random.default_rng(3)
    traj = random_fourier(robot, rng, n_harmonics=3, w_f=2 * np.pi / 3)(uniform_times(3.0))
    log = simulate_measurement(robot, traj, rng=rng, noise=SensorNoise(dq_std=0.0))
    log = with_derived_velocities(log)  # as a reader derives them (5 Hz)
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        prep = prepared_log(Path("pos.csv"), log, from_robot(robot), None)
    said = velocity_note(5.0)
    hz = float(said.split("the observer at ")[1].split(" Hz")[0])
    np.testing.assert_allclose(prep.dq, filtered_derivative(log.t, log.q, hz), atol=1e-12)
    assert not np.allclose(prep.dq, log.dq, atol=1e-6)  # not the reader's 5 Hz


def test_a_sign_flip_of_the_torques_is_a_note_not_a_unit_warning(files, tmp_path, caplog):
    """--units tau=-1 is a sign convention: it warned "tau scaled by -1 to SI"; now one
    note, "tau sign flipped (--units tau=-1)", printed as the command's note and in the
    report, and no warning of it (a unit's factor to SI is the map's one note, not a
    line per file)."""
    import logging

    from dynid.cli.__main__ import main
    from dynid.cli.console import LogFormat
    from dynid.identification.log import TorqueLog
    from dynid.io.columns import conversion_notes, parse_column_map
    from dynid.io.torque_log import load_torque_log
    from dynid.progress import NOTE

    d = files
    log = load_torque_log(d / "free.csv")
    save_torque_log(tmp_path / "flip.csv", TorqueLog(t=log.t, q=log.q, dq=log.dq, tau=-log.tau))
    argv = ["observe", "--params", str(d / "arm.urdf"), "--data", str(tmp_path / "flip.csv")]
    argv += ["--units", "tau=-1", "--calibrate", "--no-figures", "--out", str(tmp_path / "c")]
    with caplog.at_level(NOTE):
        assert main(argv) == 0
    said = [r for r in caplog.records if "flip.csv: tau" in r.getMessage()]
    assert [(r.levelno, r.getMessage()) for r in said] == [
        (NOTE, "flip.csv: tau sign flipped (--units tau=-1)")
    ]
    printed = LogFormat("observe").format(said[0])
    assert printed == "dynid observe: note: flip.csv: tau sign flipped (--units tau=-1)"
    assert not [r for r in caplog.records if r.levelno >= logging.WARNING and "scaled" in r.msg]
    report = (tmp_path / "c" / "report.html").read_text()
    assert "<b>note</b> flip.csv: tau sign flipped (--units tau=-1)" in report
    deg = parse_column_map(None, "q=deg,tau=-1")
    assert conversion_notes(deg, ["q", "tau"]) == ("tau sign flipped (--units tau=-1)",)
