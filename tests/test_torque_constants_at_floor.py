"""Torque constants judged where the fit is at the noise floor, and a load weighed through a
model whose torque constants are off.

References: a simulated Panda (joint viscous and Coulomb friction, armature) logged as
joint-side currents through known torque constants, its torque noise large enough for a
held-out verdict at the floor with joint 2's constant guessed 1.15 times the true one and
joint 4's 0.85 times (the true factor to multiply joint 2's by is 1 / 1.15); the Panda
carrying a known load (mass, CoM), logged through torque constants 100 times too small
and 2 % too large.
"""

from __future__ import annotations

import dataclasses
import json
import re
import warnings

import numpy as np
import pytest

import dynid
from dynid.cli.__main__ import main
from dynid.exceptions import DynidWarning
from dynid.friction.model import ClassicalFriction
from dynid.io.torque_log import save_torque_log
from dynid.model.drive import Drive
from dynid.simulation.measurement import SensorNoise, sample_times, simulate_measurement
from dynid.simulation.trajectories import random_fourier
from dynid.simulation.unmodelled import UnmodelledEffects
from dynid.workflows.identify import IdentifyOptions, identify_logs

#: Each joint's true torque per current [N m/A] of the simulated joint-side drive.
KT = np.array([2.0, 2.0, 2.0, 2.0, 1.0, 1.0, 1.0])
#: Datasheet-like constants over the true ones: within 2 %.
NEAR = [1.02, 0.98, 1.01, 1.0, 0.99, 1.02, 0.98]
#: The terms fitted (the truth's): the search is not what these tests judge.
TERMS = "armature,viscous,coulomb"


def _currents(robot: dynid.Robot, duration: float, noise: float, seed: int, rate=200.0):
    """A joint-side current log (``tau [A]``) of ``robot`` at ``rate`` [Hz] with joint friction
    (viscous 0.4, Coulomb 0.3) and armature, torque noise ``noise`` [N m]."""
    n = robot.n
    log = simulate_measurement(
        robot,
        random_fourier(robot, np.random.default_rng(seed))(sample_times(duration, rate)),
        rng=np.random.default_rng(seed + 100),
        noise=SensorNoise(noise, 1e-5, 1e-3),
        friction=ClassicalFriction(np.full(n, 0.4), np.full(n, 0.3), np.zeros(n)),
        effects=UnmodelledEffects(
            rotor_inertia=np.array([0.3, 0.3, 0.2, 0.2, 0.1, 0.1, 0.1]), torque_offset=np.zeros(n)
        ),
    )
    return dataclasses.replace(log, tau=log.tau / KT)


def _drive(factors) -> Drive:
    """A joint-side current drive whose torque constants are the true ones times
    ``factors``."""
    kt = KT * np.asarray(factors, dtype=np.float64)
    return dataclasses.replace(Drive.identity(7), effort="current", torque_constant=kt)


@pytest.fixture(scope="module")
def noisy_currents(panda):
    """20 s of currents at 200 Hz whose torque noise (2 N m) hides a 15 % constant in the
    error."""
    return _currents(panda, 20.0, 2.0, 3)


#: Joint 2's constant 1.15 times the true one, joint 4's 0.85 times.
OFF = [1.0, 1.15, 1.0, 0.85, 1.0, 1.0, 1.0]


def _fitted(panda, log, factors):
    """identify on ``log`` read through ``_drive(factors)``, its terms given (nothing judged
    first)."""
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", DynidWarning)
        got = identify_logs(panda, log, IdentifyOptions(drive=_drive(factors), terms=TERMS))
    assert got.heldout is not None
    return got


@pytest.fixture(scope="module")
def fits(panda, noisy_currents):
    """The noisy log fitted through the constants ``OFF`` and ``NEAR``."""
    return {
        "off": _fitted(panda, noisy_currents, OFF),
        "near": _fitted(panda, noisy_currents, NEAR),
    }


def test_a_constant_15_percent_off_is_read_at_the_noise_floor(fits):
    """Joint 2's constant 1.15 times the true one, joint 4's 0.85: the held-out verdict is
    at the floor; joint 2's and joint 4's factors lie within 3 std of the truths 1 / 1.15
    and 1 / 0.85 (regression: 0.861 and 1.080 +- 0.017, five std off, while the efforts
    of the motors left out entered the fit as noisy regressors), and joint 2's is said
    with the reason it is not named: clear of 1 by over 5 in-sample std, within 5
    spreads over the folds (0.126 from 1, spread 0.03), the floor's rule."""
    held = fits["off"].heldout
    verdict, gains = held.verdict, held.gains
    assert verdict.level == "good"
    assert gains is not None and gains.floor and gains.heldout_std is not None
    for k, truth in ((1, 1 / 1.15), (3, 1 / 0.85)):
        std = max(gains.std[k], gains.heldout_std[k])
        assert std < 0.12 and abs(gains.factor[k] - truth) < 3 * std, (k, gains.factor, std)
    assert abs(gains.factor[1] - 1.0) > 5 * gains.std[1]
    if 1 not in gains.named:
        assert abs(gains.factor[1] - 1.0) < 5 * gains.heldout_std[1]
        assert "within 5 times its spread over the folds" in gains.unnamed_reason(1)


@pytest.mark.parametrize("rate", [200.0, 100.0], ids=["20s-200Hz", "15s-100Hz"])
def test_constants_within_2_percent_name_nothing_at_the_floor(panda, fits, rate):
    """Datasheet constants within 2 % of the true ones: the gains are judged at the floor
    (recorded) and none is named, the verdict says nothing of them; at 100 Hz (15 s,
    1.4 N m of noise), joint 4 read 0.857 (std 0.012 in-sample, 0.075 over the folds) and
    was named, before a factor at the floor had to be clear of 1 over the folds too."""
    if rate == 200.0:
        held = fits["near"].heldout
    else:
        held = _fitted(panda, _currents(panda, 15.0, 1.4, 3, rate), NEAR).heldout
    assert held.verdict.level == "good" and held.gains is not None
    assert held.gains.named == ()
    assert "torque_constant" not in held.verdict.reason
    assert held.as_dict()["drive_gains"]["named"] == []


@pytest.fixture(scope="module")
def other_currents(panda, tmp_path_factory):
    """Another 20 s current log of the Panda (noise 2 N m), written as a file."""
    other = tmp_path_factory.mktemp("other") / "other.csv"
    save_torque_log(other, _currents(panda, 20.0, 2.0, 8))
    other.write_text(other.read_text().replace("tau [N m]", "tau [A]"))
    return other


@pytest.mark.parametrize("which", ["off", "near"])
def test_validate_judges_the_constants_at_the_noise_floor(fits, other_currents, which):
    """A model fitted to the currents through joint 2's constant 1.15 times the true one
    and joint 4's 0.85 (its terms given: nothing judged first), validated on another 20 s
    log: the verdict is at the floor and names joint 2's factor within 3 std (in-sample and
    over the time blocks) of the truth 1 / 1.15 (it named nothing: at the floor the gains
    were not judged); through constants within 2 %, nothing is named."""
    from dynid.workflows.validate import validate_files

    with warnings.catch_warnings():
        warnings.simplefilter("ignore", DynidWarning)
        got = validate_files(fits[which].model, other_currents)
    gains = got.gains
    assert got.verdict.level == "good" and gains is not None and gains.floor
    if which == "near":
        assert gains.named == () and "torque_constant" not in got.verdict.reason
        return
    assert 1 in gains.named and gains.heldout_std is not None
    std = max(gains.std[1], gains.heldout_std[1])
    assert std < 0.03 and abs(gains.factor[1] - 1 / 1.15) < 3 * std
    assert "torque_constant of joint 2 looks" in got.verdict.reason


def _loaded_files(tmp_path, kt_given):
    """Current logs of the Panda without and with a 1.5 kg load (CoM 5 cm along the
    flange's z), and a drive file of torque constants ``kt_given``."""
    arm = dynid.panda()
    loaded = arm.with_tool(np.eye(4), 1.5, np.array([0.0, 0.0, 0.05]), np.eye(3) * 2e-3)
    for name, robot, seed in (("arm.csv", arm, 21), ("load.csv", loaded, 22)):
        log = _currents(robot, 5.0, 0.05, seed)
        save_torque_log(tmp_path / name, log)
        text = (tmp_path / name).read_text().replace("tau [N m]", "tau [A]")
        (tmp_path / name).write_text(text)
    kt = ", ".join(f"{k:.17g}" for k in kt_given)
    (tmp_path / "drive.toml").write_text(
        'schema = "dynid-drive/1"\nside = "joint"\neffort = "current"\n'
        f"gear_ratio = [1, 1, 1, 1, 1, 1, 1]\ntorque_constant = [{kt}]\n"
        'rotor_inertia = "identify"\n'
    )
    return tmp_path / "drive.toml"


@pytest.fixture(scope="module")
def heavy_constants(tmp_path_factory):
    """The folder of :func:`_loaded_files` with constants 2 % too large on every joint."""
    folder = tmp_path_factory.mktemp("constants_102")
    _loaded_files(folder, KT * 1.02)
    return folder


def _payload(tmp_path, kt_given, capsys, *more, files=None):
    """identify (the arm's logs) and payload --model (the load's) through ``kt_given``
    (``more``: payload's further options; ``files``: the folder of :func:`_loaded_files`
    already written): payload.json and the payload's printed summary."""
    if files is None:
        _loaded_files(tmp_path, kt_given)
    src = tmp_path if files is None else files
    drive = src / "drive.toml"
    common = ["--robot", "panda", "--drive", str(drive), "--terms", TERMS, "-q", "--no-figures"]
    argv = ["identify", "--data", str(src / "arm.csv"), "--out", str(tmp_path / "id")]
    assert main(argv + common) == 0
    capsys.readouterr()
    model = str(tmp_path / "id" / "identification.json")
    argv = ["payload", "--model", model, "--data", str(src / "load.csv"), *more]
    assert main(argv + ["--out", str(tmp_path / "p")]) == 0
    printed = capsys.readouterr()
    return json.loads((tmp_path / "p" / "payload.json").read_text()), printed


def test_a_load_weighed_through_motor_constants_is_doubted_and_not_set(tmp_path, capsys):
    """Torque constants 100 times too small (given at the motors): identify records its
    gravity-scale finding, and payload --model, whose load comes out 100 times too light,
    warns with the load at the description's scale (the truth 1.5 kg) and writes no
    setLoad values (it wrote the light load as setLoad's mass, with no warning)."""
    d, printed = _payload(tmp_path, KT / 100.0, capsys)
    assert abs(d["mass"] - 0.015) < 0.001
    assert d["load_mass"] is None and d["F_x_Cload"] is None
    (doubt,) = [s for s in d["doubts"] if "the arm's model records" in s]
    assert "multiply it by 100" in doubt or "multiply it by 99" in doubt
    at_scale = float(doubt.split(" kg at the description's scale")[0].rsplit(" ", 1)[1])
    assert abs(at_scale - 1.5) < 0.05
    assert "no setLoad values written" in printed.out + printed.err


def test_the_mass_note_names_the_constants_the_identification_did_not_check(
    tmp_path, capsys, heavy_constants
):
    """Regression (a load read 3 % heavy through constants the identification had not
    checked was "known to 0.74 %", with no caveat): constants 2 % too large on every joint
    read the 1.5 kg load about 2 % heavy, beyond its std. identify records which joints'
    constants its data checked, and to what (metadata ``constants_checked``); payload
    --model says the mass and first moments carry the constants' error, names those
    joints, and records it in payload.json; --known-mass 1.5 reads the factor 1.02 (the
    truth) within its std, clear of 1."""
    d, printed = _payload(tmp_path, None, capsys, "--known-mass", "1.5", files=heavy_constants)
    assert abs(d["mass"] / 1.5 - 1.02) < 0.01
    ident = json.loads((tmp_path / "id" / "identification.json").read_text())
    recorded = ident["metadata"]["constants_checked"]
    c = d["constants_checked"]
    assert {k: c[k] for k in recorded} == recorded
    assert sorted(c["checked"] + c["corrected"] + c["unchecked"]) == list(range(1, 8))
    assert c["within_percent"] == 10.0 and c["per"] == "joint"
    note = c["finding"]
    assert note in d["notes"] and "carry the constants' error" in printed.out
    assert "its mass and first moments carry the constants' error" in note
    assert f"({0.01 * d['mass']:.2g} kg" in note and "per 1 %" in note
    assert c["checked"] and c["unchecked"]  # 1 to 6 within 10 %, 7 its own rotor and friction
    assert f"only to 10 % (joint(s) {', '.join(map(str, c['checked']))})" in note
    assert f"not at all (joint(s) {', '.join(map(str, c['unchecked']))})" in note
    k = d["known_mass"]
    assert k["mass"] == 1.5 and abs(k["factor"] - 1.02) < 3 * k["std"] < 0.02
    assert "known    1.5 kg: the torques read" in printed.out
    assert d["load_mass"] is not None
    page = (tmp_path / "p" / "report.html").read_text()
    assert "x the known 1.5 kg" in page and "&lt;span" not in page  # escaped once


def test_the_constants_line_says_a_factor_clear_of_1_in_sample_and_why_not_named(fits):
    """Constants within 2 % of the true ones (joint 4's exact): joint 4 reads within 3
    in-sample standard deviations of its truth 1 (regression: 0.925 +- 0.014, while the
    efforts of the motors left out entered the fit as noisy regressors), and within 3
    spreads over the folds; the line says why it is not named (under 10 %, within 5
    spreads at the floor) with an uncertainty that holds the truth, and names the joints
    the data cannot check (5 to 7: their own rotor and friction) as right as the drive
    file's constants."""
    gains = fits["near"].heldout.gains
    assert gains is not None and gains.floor and gains.heldout_std is not None
    words = gains.constants_words()
    assert words is not None
    k = 3  # joint 4: the drive file's constant is the true one
    assert abs(gains.factor[k] - 1.0) < 3 * gains.std[k]  # in-sample: an honest std
    assert abs(gains.factor[k] - 1.0) < 3 * gains.heldout_std[k]  # and over the folds
    assert f"joint 4 {gains.factor[k]:.3g} +- {gains.heldout_std[k]:.2g} (over the folds" in words
    said = re.search(r"no change to the drive file for joint\(s\) ([\d, ]+): ([^;]+)", words)
    assert said is not None and "4" in said[1].split(", "), words
    assert "it is within 10 % of 1" in said[2]
    assert "at the noise floor it is within 5 times its spread over the folds of 1" in said[2]
    assert "joint(s) 5, 6, 7 not checked by these data (their torques as right" in words


def test_validate_and_identify_print_the_constants_line(fits, other_currents, tmp_path, capsys):
    """``dynid validate`` of a current log prints the line after its verdict (and
    validation.json's ``drive_gains`` records it); ``dynid identify`` prints it after its
    held-out verdict (heldout.json's ``drive_gains`` records it); each report's verdict
    box says it."""
    from dynid.io.model_json import save_model_json

    model = save_model_json(tmp_path / "identification.json", fits["near"].model)
    argv = ["validate", "--model", str(model), "--data", str(other_currents)]
    assert main([*argv, "--no-figures", "--out", str(tmp_path / "v")]) == 0
    out = capsys.readouterr().out.splitlines()
    verdict = next(i for i, line in enumerate(out) if line.startswith("verdict: "))
    assert out[verdict + 1].startswith("torque constants: true over read-through")
    doc = json.loads((tmp_path / "v" / "validation.json").read_text())
    assert doc["drive_gains"]["constants"] == out[verdict + 1]
    page = (tmp_path / "v" / "report.html").read_text()
    assert "Torque constants: true over read-through" in page
    kt = ", ".join(f"{x:.17g}" for x in KT * np.asarray(NEAR))
    drive = tmp_path / "drive.toml"
    drive.write_text(
        f'schema = "dynid-drive/1"\nside = "joint"\neffort = "current"\n'
        f"gear_ratio = [1, 1, 1, 1, 1, 1, 1]\ntorque_constant = [{kt}]\n"
    )
    argv = ["identify", "--robot", "panda", "--drive", str(drive), "--terms", TERMS]
    argv += ["--data", str(other_currents), "--no-figures", "--out", str(tmp_path / "i")]
    assert main(argv) == 0
    out = capsys.readouterr().out.splitlines()
    verdict = next(i for i, line in enumerate(out) if line.startswith("held-out verdict"))
    assert out[verdict + 1].startswith("torque constants: true over read-through")
    doc = json.loads((tmp_path / "i" / "heldout.json").read_text())
    assert doc["drive_gains"]["constants"] == out[verdict + 1]
    page = (tmp_path / "i" / "report.html").read_text()
    assert "Torque constants: true over read-through" in page


def test_a_robot_with_rotors_to_identify_says_why_its_scale_is_not_checked(
    tmp_path, capsys, heavy_constants
):
    """Regression (the torques' scale line, documented as printed in every case, was left
    out without a word): payload --robot through a drive of currents whose rotor inertias
    are to be identified (the default) cannot compare the torques with the description's;
    one line says why, payload.json records it, and the report names the constants' error
    the mass carries (constants 2 % too large: the load reads about 2 % heavy)."""
    src = heavy_constants
    argv = ["payload", "--robot", "panda", "--drive", str(src / "drive.toml"), "--no-figures"]
    argv += ["--terms", "viscous,coulomb", "--data", str(src / "load.csv")]
    argv += ["--unloaded", str(src / "arm.csv")]
    assert main([*argv, "--out", str(tmp_path / "p")]) == 0
    printed = capsys.readouterr().out
    d = json.loads((tmp_path / "p" / "payload.json").read_text())
    assert abs(d["mass"] / 1.5 - 1.02) < 0.01 and d["torque_scale"] is None
    assert (
        'rotor inertias are to be identified (rotor_inertia = "identify")'
        in (d["torque_scale_unchecked"])
    )
    assert "torques  not checked against the arm description's: the drive's rotor" in printed
    assert "its mass and first moments carry that error" in d["constants_checked"]["finding"]
    page = (tmp_path / "p" / "report.html").read_text()
    assert "which nothing here checked" in page
    assert "the torque constants&#x27; error aside" in page and "(known to" not in page
