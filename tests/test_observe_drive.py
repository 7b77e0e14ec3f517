"""``dynid observe --params robot.toml`` reads the logs through the TOML's ``[drive]``
table, as ``validate`` does: motor currents become joint torques (gear ratio times torque
constant) and the rotor inertias join the mass matrix (``K^T diag(I_a) K``). Judged
against the simulated contact's true external torque (``tau_ext``, written beside the log)
and the closed form of the rotor mass; ``--drive`` follows validate's rule."""

from __future__ import annotations

import dataclasses
import json

import numpy as np
import pytest

import dynid
from dynid.cli.__main__ import main
from dynid.exceptions import DataError
from dynid.io.model_json import save_model_json
from dynid.io.robot.toml import save_toml
from dynid.model.drive import Drive
from dynid.observer.residual import first_order_lag
from dynid.workflows.observe import load_observer_model, observer_drive

from conftest import exact_model

GEARS = np.array([100.0, 100.0, 80.0, 80.0, 50.0, 50.0, 50.0])
KT = np.array([0.5, 0.5, 0.4, 0.4, 0.2, 0.2, 0.2])  # N m / A at the motor
ROTORS = np.array([2e-5, 2e-5, 1.5e-5, 1.5e-5, 5e-6, 5e-6, 5e-6])  # kg m^2
PUSH = (1.5, 2.5)  # s: a 15 N push down on link 4


def _drive(rotors: np.ndarray | None = ROTORS) -> Drive:
    return Drive.from_gears(
        GEARS, side="joint", effort="current", torque_constant=KT, rotor_inertia=rotors
    )


@pytest.fixture(scope="module")
def logs(tmp_path_factory):
    """The Panda without friction behind a drive recording motor currents (robot.toml with
    its [drive] table): a free log and a log with a push, each 3 s at 1 kHz."""
    d = tmp_path_factory.mktemp("observe_drive")
    save_toml(d / "robot.toml", dynid.panda().with_friction(None), drive=_drive())
    save_toml(d / "robot_noIa.toml", dynid.panda().with_friction(None), drive=_drive(None))
    sim = ["simulate", "--robot", str(d / "robot.toml"), "--trajectory", "fourier", "-q"]
    sim += ["--duration", "3", "--no-friction"]
    assert main([*sim, "--seed", "2", "--out", str(d / "free.csv")]) == 0
    push = f"link4:0,0,-15:{PUSH[0]},{PUSH[1]}"
    assert main([*sim, "--seed", "3", "--contact", push, "--out", str(d / "hit.csv")]) == 0
    return d


def test_the_toml_drive_gives_the_rotor_mass_of_its_closed_form(logs):
    """The observer model of a TOML with a [drive] table holds that drive and the rotor
    mass diag(gear^2 I_a); without rotor inertias in the table, none."""
    model, _ = load_observer_model(None, str(logs / "robot.toml"))
    assert model.drive is not None and model.drive.effort == "current"
    np.testing.assert_allclose(model.rotor_mass, np.diag(GEARS**2 * ROTORS), rtol=1e-12)
    bare, _ = load_observer_model(None, str(logs / "robot_noIa.toml"))
    np.testing.assert_array_equal(bare.rotor_mass, np.zeros((7, 7)))


def test_currents_are_read_through_the_toml_drive_and_the_push_is_its_true_torque(logs):
    """Calibrated on the free log and run on the pushed one, the residual during the push
    is the simulated tau_ext through the observer's lag K_O / (s + K_O) (mean within
    0.01 N m, RMS within the sensors' noise, 0.2 N m), and the one event starts within
    20 ms of the push: currents read as N m gave residuals of the torque constant's and
    gear's scale, and without the rotor inertias the residual follows the motion."""
    p = ["observe", "--params", str(logs / "robot.toml"), "--no-figures", "-q"]
    assert (
        main([*p, "--data", str(logs / "free.csv"), "--calibrate", "--out", str(logs / "c")]) == 0
    )
    th = ["--thresholds", str(logs / "c" / "thresholds.json")]
    assert main([*p, *th, "--data", str(logs / "hit.csv"), "--out", str(logs / "o")]) == 0
    table = np.loadtxt(logs / "o" / "residuals.csv", delimiter=",", comments="#", skiprows=3)
    t, r = table[:, 0], table[:, 1:8]
    head = (logs / "hit.csv").read_text().splitlines()[2].split(",")
    ext = np.loadtxt(logs / "hit.csv", delimiter=",", comments="#", skiprows=3)
    ext = ext[:, [head.index(f"tau_ext{j}") for j in range(1, 8)]]
    lag = first_order_lag(t, ext, 50.0)  # K_O / (s + K_O), the exact model's residual
    on = (t > PUSH[0] - 0.2) & (t < PUSH[1] + 0.2)
    assert np.abs(ext[on]).max() > 2.0  # the push loads the joints
    err = r[on] - lag[on]
    assert np.all(np.abs(err.mean(axis=0)) < 0.01)
    assert np.all(np.sqrt(np.mean(err**2, axis=0)) < 0.2)
    events = json.loads((logs / "o" / "events.json").read_text())["events"]
    assert len(events) == 1 and 0 <= events[0]["start"] - PUSH[0] < 0.02


def test_a_drive_given_follows_validates_rule(logs, tmp_path):
    """--drive replaces a TOML's [drive] table (as validate's --drive does), gives a URDF or
    built-in robot and an identified model without a drive the drive their logs are read
    through, and is refused, naming the field, beside a model identified with another."""
    other = _drive(ROTORS * 2)
    assert observer_drive(str(logs / "robot.toml"), 7, other) is other
    assert observer_drive(str(logs / "robot.toml"), 7).rotor_inertia.tolist() == ROTORS.tolist()
    (tmp_path / "d.toml").write_text(_drive_file())
    assert observer_drive("panda", 7, tmp_path / "d.toml").effort == "current"
    panda = dynid.panda()
    save_model_json(tmp_path / "bare.json", exact_model(panda, panda))
    model, _ = load_observer_model(tmp_path / "bare.json", None, drive=tmp_path / "d.toml")
    assert model.drive is not None and model.drive.torque_constant.tolist() == KT.tolist()
    held = dataclasses.replace(exact_model(panda, panda), drive=_drive())
    save_model_json(tmp_path / "held.json", held)
    with pytest.raises(DataError, match="drive given differs.*rotor_inertia"):
        load_observer_model(tmp_path / "held.json", None, drive=tmp_path / "d.toml")


def test_a_model_of_torques_reads_a_log_of_currents_through_the_logging_fields(logs):
    """A model whose drive records torques, given a drive that differs in how the log
    records the effort alone (currents, torque constants): the log is read through the
    model's drive with those fields (``validate --drive`` was refused, "the drive given
    differs", and leaving it out read amperes as N m); the model is the simulation's, so
    the error is at the noise floor. A drive of other gears is refused as before."""
    from dynid.friction.fit import model_drive
    from dynid.workflows.validate import ValidateOptions, validate_files

    panda = dynid.panda().with_friction(None)
    torques = Drive.from_gears(GEARS, side="joint", rotor_inertia=ROTORS)
    model = dataclasses.replace(exact_model(panda, panda), drive=torques)
    read = model_drive(model, _drive())
    assert read is not None and read.effort == "current"
    assert read.torque_constant.tolist() == KT.tolist()
    assert read.rotor_inertia.tolist() == ROTORS.tolist()
    res = validate_files(model, logs / "free.csv", ValidateOptions(friction="none", drive=_drive()))
    assert res.verdict.level == "good", res.verdict.reason
    with pytest.raises(DataError, match="drive given differs.*transmission"):
        model_drive(model, Drive.from_gears(2 * GEARS, side="joint", rotor_inertia=ROTORS))


def _drive_file() -> str:
    """A drive file (dynid-drive/1) of the drive's gears and currents."""
    vec = ", ".join
    return (
        'schema = "dynid-drive/1"\nside = "joint"\neffort = "current"\n'
        f"gear_ratio = [{vec(map(repr, GEARS.tolist()))}]\n"
        f"torque_constant = [{vec(map(repr, KT.tolist()))}]\n"
    )


def test_each_log_is_mapped_to_the_joint_side_once(logs, tmp_path, monkeypatch):
    """observe mapped every log through the drive five times (the degrees, limits, sign and
    unit checks and the observer each on its own); now once per log, the checks and the
    observer reading the same joint-side log (the check of columns recorded reversed maps
    its own samples, within the derivative's edges, with chosen columns negated), and once
    more for the calibration's judgement of the model, validate's prediction on the same
    logs, which are not read again."""
    calls = []
    through = Drive.joint_torques

    def counted(self, effort):
        calls.append(effort.shape[0])
        return through(self, effort)

    monkeypatch.setattr(Drive, "joint_torques", counted)
    p = ["observe", "--params", str(logs / "robot.toml"), "--no-figures", "-q", "--calibrate"]
    data = [str(logs / "free.csv"), str(logs / "hit.csv")]
    assert main([*p, "--data", *data, "--out", str(tmp_path / "c")]) == 0
    rows = [len((logs / f).read_text().splitlines()) - 3 for f in ("free.csv", "hit.csv")]
    assert sorted(c for c in calls if c in rows) == sorted(2 * rows), (calls, rows)
