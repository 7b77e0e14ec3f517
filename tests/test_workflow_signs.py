"""``validate`` and ``observe`` judge a recording's signs by the one rule ``identify``
refuses by: a motor recorded reversed (position and current negated), and one recording's
motor current negated where the links barely load it, told among several recordings by
its own friction and rotor; ``validate`` names them at the start of its verdict and in
validation.json, ``observe`` refuses them.

References: simulated motor-side current logs of the geared Panda with its coupled wrist
(motor friction and rotor inertias the description lacks, sensor noise: the truth), the
same logs with chosen columns negated.
"""

from __future__ import annotations

import dataclasses
import warnings

import numpy as np
import pytest

import dynid
from dynid.exceptions import DataError, DynidWarning
from dynid.identification.log import TorqueLog
from dynid.io.torque_log import save_torque_log
from dynid.workflows.observe import ObserveOptions, observe_files
from dynid.workflows.validate import ValidateOptions, validate_files

from conftest import geared_recordings


def _negated(log: TorqueLog, motion: list[int], torque: list[int]) -> TorqueLog:
    """``log`` with the position and velocity columns ``motion`` and the current columns
    ``torque`` (from 0) negated."""
    m, t = np.ones(log.n), np.ones(log.n)
    m[motion], t[torque] = -1.0, -1.0
    return dataclasses.replace(log, q=log.q * m, dq=log.dq * m, tau=log.tau * t)


@pytest.fixture(scope="module")
def geared(tmp_path_factory):
    """Two 3 s motor-side current logs of the geared Panda with its coupled wrist: as
    recorded (clean/a.csv, clean/b.csv), b with motor 5's current negated beside a
    (flip/b.csv, flip/a.csv), a with motor 6 recorded reversed (rev.csv); and the drive
    file's drive (rotor inertias to identify) they are read through."""
    (a, b), drive = geared_recordings(dynid.panda(), (71, 72))
    d = tmp_path_factory.mktemp("signs")
    for sub in ("clean", "flip"):
        (d / sub).mkdir()
        save_torque_log(d / sub / "a.csv", a)
    save_torque_log(d / "clean" / "b.csv", b)
    save_torque_log(d / "flip" / "b.csv", _negated(b, [], [4]))
    save_torque_log(d / "rev.csv", _negated(a, [5], [5]))
    return d, drive


def _validate(files, drive):
    """validate_files of the Panda's description through ``drive`` (no friction added),
    its warnings kept."""
    with warnings.catch_warnings(record=True) as caught:
        warnings.simplefilter("always", DynidWarning)
        result = validate_files(dynid.panda(), files, ValidateOptions(friction="none", drive=drive))
    return result, [str(w.message) for w in caught]


def test_validate_names_a_motor_recorded_reversed_with_its_columns(geared):
    """rev.csv (motor 6's position and current negated): the verdict opens with it and
    --units q6=-1,tau6=-1, validation.json records it under reversed_columns, a warning
    names the file."""
    d, drive = geared
    result, said = _validate(d / "rev.csv", drive)
    assert result.verdict.reason.startswith("rev.csv: motor 6 looks recorded reversed"), (
        result.verdict.reason
    )
    assert "--units q6=-1,tau6=-1" in result.verdict.reason
    meta = result.metadata()
    assert list(meta["reversed_columns"]) == ["rev.csv"] and "opposite_sign" not in meta
    assert any(s.startswith("rev.csv: motor 6 looks recorded reversed") for s in said), said


def test_validate_names_one_recordings_motor_of_the_opposite_sign(geared):
    """flip/b.csv (motor 5's current negated, a motor the links barely load) beside a.csv:
    named at the start of the verdict with b.csv's own --units entry, in opposite_sign."""
    d, drive = geared
    result, _ = _validate([d / "flip" / "a.csv", d / "flip" / "b.csv"], drive)
    reason = result.verdict.reason
    assert reason.startswith("b.csv: the torques of motor 5 have the opposite sign"), reason
    assert "--units b.csv:tau5=-1" in reason, reason
    assert list(result.metadata()["opposite_sign"]) == ["b.csv"]


def test_validate_of_clean_recordings_names_nothing(geared):
    """a.csv and b.csv as recorded: no sign finding, no key in validation.json."""
    d, drive = geared
    result, said = _validate([d / "clean" / "a.csv", d / "clean" / "b.csv"], drive)
    meta = result.metadata()
    assert "opposite_sign" not in meta and "reversed_columns" not in meta
    assert not any("reversed" in s or "opposite sign" in s for s in said), said


@pytest.mark.parametrize(
    ("files", "match"),
    [(["rev.csv"], "q6=-1,tau6=-1"), (["flip/a.csv", "flip/b.csv"], "b.csv:tau5=-1")],
)
def test_observe_refuses_a_reversed_motor_and_one_recordings_flipped_motor(geared, files, match):
    """observe on rev.csv, or on a.csv with flip/b.csv: refused with the --units entries."""
    d, drive = geared
    opts = ObserveOptions(
        data=tuple(d / f for f in files), params="panda", drive=drive, calibrate=True
    )
    with warnings.catch_warnings():  # rev.csv's joint 6 lies beyond its limits: warned
        warnings.simplefilter("ignore", DynidWarning)
        with pytest.raises(DataError, match=match):
            observe_files(opts)


def test_one_flipped_recording_alone_is_named_against_the_identified_models_friction(geared):
    """A model identified on clean/a.csv (its motor friction and rotors dissipate and are
    positive), validated on flip/b.csv alone (motor 5's current negated): named, its hint
    --units tau5=-1; on clean/b.csv alone, nothing is named."""
    from dynid.identification.selection import identify_recordings
    from dynid.io.torque_log import load_torque_log

    d, drive = geared
    a = load_torque_log(d / "clean" / "a.csv")
    model = identify_recordings(dynid.panda(), [a], ["a.csv"], drive=drive, std="classical")
    opts = ValidateOptions(drive=drive)
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", DynidWarning)
        flipped = validate_files(model, d / "flip" / "b.csv", opts)
        clean = validate_files(model, d / "clean" / "b.csv", opts)
    reason = flipped.verdict.reason
    assert reason.startswith("b.csv: the torques of motor 5 have the opposite sign to the"), reason
    assert "--units tau5=-1" in reason, reason
    assert "opposite_sign" not in clean.metadata(), clean.verdict.reason


def test_the_command_writes_reversed_columns_and_says_it_first_in_the_report(geared, tmp_path):
    """dynid validate --drive on rev.csv: validation.json's reversed_columns holds the
    finding with --units q6=-1,tau6=-1 and the report's headline names the file."""
    import json

    from dynid.cli.__main__ import main
    from dynid.io.drive_file import drive_toml

    d, drive = geared
    (tmp_path / "drive.toml").write_text(drive_toml(drive).removeprefix("[drive]\n"))
    out = tmp_path / "v"
    args = ["validate", "--robot", "panda", "--drive", str(tmp_path / "drive.toml")]
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", DynidWarning)
        main([*args, "--no-friction", "--data", str(d / "rev.csv"), "--out", str(out)])
    doc = json.loads((out / "validation.json").read_text())
    assert "--units q6=-1,tau6=-1 " in doc["reversed_columns"]["rev.csv"]
    page = (out / "report.html").read_text()
    assert "rev.csv: columns look recorded reversed" in page
