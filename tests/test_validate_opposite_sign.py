"""``validate`` on a log with one joint's torque of the opposite sign names that joint
and the ``--units`` entry that reads it, by the rule ``identify`` and ``observe`` refuse
such a log by (it once called joint 4's doubled torque "a constant (an offset)" and gave
no hint); a log with a real offset on a joint is still called an offset."""

from __future__ import annotations

import dataclasses
import json
import warnings

import numpy as np
import pytest

import dynid
from dynid.cli.__main__ import main
from dynid.exceptions import DynidWarning
from dynid.io.torque_log import save_torque_log
from dynid.progress import NOTE
from dynid.simulation.measurement import SensorNoise
from dynid.workflows.validate import ValidateOptions, validate_files

from conftest import recordings

NOISE = 0.05  # the simulated torque sensors' noise [N m]
NONE = ValidateOptions(friction="none")


@pytest.fixture(scope="module")
def panda_logs(tmp_path_factory):
    """The Panda's own model and two of its noisy recordings without friction (its true
    torques: the model is the simulation's truth), one saved as it is read (a.csv), one
    with tau4 negated (flip.csv), one with 3 N m added to tau4 (offset.csv)."""
    robot = dynid.panda()
    a, b = recordings(
        robot, (11, 12), friction=None, duration=6.0, noise=SensorNoise(tau_std=NOISE), fs=200.0
    )
    d = tmp_path_factory.mktemp("opposite")
    sign = np.ones(robot.n)
    sign[3] = -1.0
    shift = np.zeros(robot.n)
    shift[3] = 3.0
    save_torque_log(d / "a.csv", a)
    save_torque_log(d / "flip.csv", dataclasses.replace(b, tau=b.tau * sign))
    save_torque_log(d / "offset.csv", dataclasses.replace(b, tau=b.tau + shift))
    return robot, d


def _validate(robot, files, options=NONE):
    """validate_files of the true robot on ``files``, its warnings kept."""
    with warnings.catch_warnings(record=True) as caught:
        warnings.simplefilter("always", DynidWarning)
        result = validate_files(robot, files, options)
    return result, [str(w.message) for w in caught]


def test_flipped_joint_is_named_with_its_units_hint_not_an_offset(panda_logs):
    """flip.csv (tau4 negated): the verdict opens with joint4's opposite sign and
    --units tau4=-1, calls nothing an offset, and validation.json records the finding."""
    robot, d = panda_logs
    result, said = _validate(robot, d / "flip.csv")
    (name, finding), *more = result.opposite_sign
    assert (name, more) == ("flip.csv", [])
    assert "torque sign of joint4 is probably opposite" in finding
    assert "--units tau4=-1 " in finding
    reason = result.verdict.reason
    assert reason.startswith(f"flip.csv: {finding}")
    assert "offset" not in reason
    assert result.metadata()["opposite_sign"] == {"flip.csv": finding}
    assert any(s.startswith("flip.csv: ") and "tau4=-1" in s for s in said)


def test_clean_log_names_no_joint(panda_logs):
    """a.csv, as the true model's torques plus sensor noise: no sign finding, no key in
    validation.json, and the verdict at the noise floor."""
    robot, d = panda_logs
    result, _ = _validate(robot, d / "a.csv")
    assert result.opposite_sign == ()
    assert "opposite_sign" not in result.metadata()
    assert result.verdict.level == "good"


def test_real_offset_is_still_called_an_offset(panda_logs):
    """offset.csv (3 N m added to tau4): no sign finding, and joint4's residual is said to
    be a constant (an offset) of about 3 N m."""
    robot, d = panda_logs
    result, _ = _validate(robot, d / "offset.csv")
    assert result.opposite_sign == ()
    reason = result.verdict.reason
    assert "joint4: 3 of 3 N m RMS residual is a constant (an offset)" in reason


def test_one_flipped_recording_among_others_gets_its_own_units_entry(panda_logs):
    """a.csv and flip.csv together: the hint flips flip.csv's tau4 alone
    (--units flip.csv:tau4=-1), and following it validates both at the noise floor."""
    robot, d = panda_logs
    files = [d / "a.csv", d / "flip.csv"]
    result, _ = _validate(robot, files)
    ((name, finding),) = result.opposite_sign
    assert name == "flip.csv" and "--units flip.csv:tau4=-1 " in finding
    hinted = dataclasses.replace(NONE, columns=(None, "flip.csv:tau4=-1"))
    again, _ = _validate(robot, files, hinted)
    assert again.opposite_sign == ()
    assert again.verdict.level == "good"
    assert np.max(again.validation.errors.rms) < 1.5 * NOISE


def test_report_headline_and_json_name_the_flipped_file(panda_logs, tmp_path):
    """dynid validate on flip.csv: validation.json's opposite_sign holds the finding and
    the report's headline says the file's torques have the opposite sign."""
    _, d = panda_logs
    out = tmp_path / "v"
    args = ["validate", "--robot", "panda", "--no-friction", "--data", str(d / "flip.csv")]
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", DynidWarning)
        assert main([*args, "--out", str(out), "--no-figures"]) == 1  # unusable
    doc = json.loads((out / "validation.json").read_text())
    assert "--units tau4=-1 " in doc["opposite_sign"]["flip.csv"]
    page = (out / "report.html").read_text()
    head = page[page.index('class="headline"') :].split("</p>")[0]
    assert "The torques of flip.csv have the opposite sign" in head


def test_a_model_identified_with_a_files_own_flip_validates_other_files(panda_logs, caplog):
    """A model identified with ``--units flip.csv:tau4=-1`` (flip.csv's own entry) reads a
    new file as recorded, the entry holding for flip.csv alone: validate on a.csv runs,
    at the noise level with no sign finding (it was refused: "flip.csv is none of the
    files given"), and on flip.csv the recorded entry reads it right."""
    from dynid.workflows.identify import IdentifyOptions, identify_files

    robot, d = panda_logs
    opts = IdentifyOptions(columns=(None, "flip.csv:tau4=-1"), terms="links")
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", DynidWarning)
        model = identify_files(robot, [d / "a.csv", d / "flip.csv"], opts).model
    for name in ("a.csv", "flip.csv"):
        caplog.clear()
        with caplog.at_level(NOTE):
            result, said = _validate(model, d / name)
        assert not any("opposite" in s for s in said), said
        np.testing.assert_allclose(result.validation.errors.rms, NOISE, rtol=0.25)
        # the recorded entry is said where it applies, not on another file
        told = any(
            "as the model's data were read" in r.getMessage() and r.levelno == NOTE
            for r in caplog.records
        )
        assert told is (name == "flip.csv")


def test_torques_declared_in_n_m_through_a_current_drive_are_refused(panda_logs):
    """``--units tau=Nm`` with a drive whose effort is current was accepted and the
    column read as amperes all the same; it is refused in one line naming the drive's
    effort and what to give instead."""
    from dynid.exceptions import OptionError
    from dynid.model.drive import Drive
    from dynid.workflows.data_files import column_map

    drive = Drive(np.eye(7), np.zeros(7), effort="current", torque_constant=np.ones(7))
    with pytest.raises(OptionError, match="declares torques, but the drive's effort is 'current'"):
        column_map(None, "tau=Nm", drive=drive)
    assert column_map(None, "tau=mA", drive=drive).factor("tau") == pytest.approx(1e-3)


def test_observe_says_a_models_recorded_flip_looks_wrong_for_a_file_read_right(
    panda_logs, tmp_path
):
    """A model identified with ``--units tau4=-1`` (all of its files flipped) observes a log
    recorded the right way: refused naming the recorded map as wrong for this file, with
    the --units that reads it without the flip (it asked for ``--units tau4=-1``, the flip
    already applied), as validate says it."""
    from dynid.exceptions import DataError
    from dynid.io.model_json import save_model_json
    from dynid.workflows.identify import IdentifyOptions, identify_files
    from dynid.workflows.observe import ObserveOptions, observe_files

    robot, d = panda_logs
    opts = IdentifyOptions(columns=(None, "tau4=-1"), terms="links")
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", DynidWarning)
        model = identify_files(robot, d / "flip.csv", opts).model
    path = save_model_json(tmp_path / "identification.json", model)
    observe = ObserveOptions(data=(d / "a.csv",), model=path, calibrate=True)
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", DynidWarning)
        with pytest.raises(DataError) as caught:
            observe_files(observe)
    said = str(caught.value)
    assert "the model's recorded sign map (--units tau4=-1) looks wrong" in said, said
    assert "reads the file without tau4=-1" in said, said
