"""Payload identification on an arm with armature: the arm's whole model is subtracted.

References: a loaded Panda simulated with a per-joint armature (a drive of gear ratio 1
with known rotor inertias) and viscous friction; the load put on with ``Robot.with_tool``
is the truth the estimates are compared with, within a few of their standard deviations.
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
from dynid.exceptions import DynidWarning, ModelError
from dynid.feasibility.payload import identify_payload
from dynid.feasibility.payload_arm import arm_model
from dynid.feasibility.payload_doubts import arm_length, undetermined_inertia
from dynid.feasibility.payload_fit import serial_correlation_factor
from dynid.identification.log import TorqueLog
from dynid.identification.selection import identify_recordings
from dynid.identification.structure import Structure
from dynid.io.model_json import save_model_json
from dynid.io.payload_json import payload_to_dict
from dynid.io.torque_log import save_torque_log
from dynid.model.drive import Drive
from dynid.model.inertia import inertia6_from_matrix
from dynid.signals import lowpass_noise_gain
from dynid.simulation.measurement import simulate_measurement
from dynid.simulation.trajectories import random_fourier, sinusoid_trajectory, uniform_times

IA = np.array([0.08, 0.08, 0.06, 0.09, 0.1, 0.03, 0.06])  # armature [kg m^2]
MASS, COM = 0.73, np.array([0.01, -0.02, 0.06])
INERTIA = np.diag([0.0025, 0.003, 0.0017])
ARM = dynid.panda().with_friction(None)
DRIVE = dataclasses.replace(Drive.identity(7), rotor_inertia=IA)
VISCOUS = dynid.ClassicalFriction(np.linspace(0.6, 0.1, 7), np.zeros(7), np.zeros(7))


def _log(robot, seed, noise=None):
    """8 s at 200 Hz of ``robot`` with the armature and viscous friction."""
    traj = random_fourier(ARM, np.random.default_rng(seed), q0=dynid.PANDA_NEUTRAL_Q)(
        uniform_times(8.0, 200.0)
    )
    kw = {} if noise is None else {"noise": noise}
    return simulate_measurement(
        robot, traj, rng=np.random.default_rng(seed + 1), friction=VISCOUS, drive=DRIVE, **kw
    )


LOADED = ARM.with_tool(np.eye(4), MASS, COM, INERTIA, name="load")


def _z(est):
    """The errors of mass, CoM and inertia in their standard deviations (10,)."""
    err = np.r_[
        est.mass - MASS,
        est.com - COM,
        inertia6_from_matrix(est.inertia) - inertia6_from_matrix(INERTIA),
    ]
    return err / np.r_[est.std_mass, est.std_com, est.std_inertia]


@pytest.fixture(scope="module")
def logs():
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", DynidWarning)
        return [_log(LOADED, s) for s in (1, 3)], [_log(ARM, s) for s in (5, 7)]


def test_the_armature_is_the_arms_not_the_loads(logs):
    """With the drive's rotor inertias the load is found within 4 of its standard
    deviations; without them (the old behaviour) the armature is carried by the load's
    inertia: its diagonal comes out more than 5 times the true one."""
    loaded, _ = logs
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", DynidWarning)
        right = identify_payload(ARM, loaded, drive=DRIVE)
        wrong = identify_payload(ARM, loaded)
    assert np.max(np.abs(_z(right))) < 4.0
    assert np.all(np.diag(wrong.inertia) > 5 * np.diag(INERTIA))
    assert right.preprocessing["cutoff_source"] == "motion"
    assert right.plausible and not right.doubts


def test_an_identified_model_with_armature_and_the_difference_method(logs):
    """The arm identified from unloaded recordings (armature, viscous friction): as the
    arm (its own prediction), and by the difference method with the model's structure and
    with the structure chosen on held-out data (several unloaded recordings): the load
    within 5 of its standard deviations (which leave out the unloaded fit's uncertainty),
    its mass to 1 % and its CoM to 1 mm."""
    loaded, unloaded = logs
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", DynidWarning)
        model = identify_recordings(ARM, unloaded, structure=Structure.parse("armature,viscous"))
        found = [
            identify_payload(model, loaded),
            identify_payload(ARM, loaded, unloaded=unloaded),
        ]
    for est in found:
        assert np.max(np.abs(_z(est))) < 5.0
        assert abs(est.mass - MASS) < 0.01 * MASS
        assert np.max(np.abs(est.com - COM)) < 1e-3
    assert found[0].preprocessing["cutoff_source"] == "model"
    assert found[0].preprocessing["cutoff_hz"] == model.info.log.cutoff_hz
    assert "armature" in " ".join(found[1].notes)  # the unloaded arm's terms, chosen


def test_no_load_is_warned_about_not_handed_on(logs, tmp_path, capsys):
    """Unloaded data on the arm's exact model (a drive file of gear ratio 1 with the rotor
    inertias): the mass is noise, not 3 standard deviations above zero; a warning says so
    and payload.json has no setLoad values."""
    _, unloaded = logs
    for k, log in enumerate(unloaded):
        save_torque_log(tmp_path / f"u{k}.csv", log)
    (tmp_path / "drive.toml").write_text(
        'schema = "dynid-drive/1"\ngear_ratio = [1, 1, 1, 1, 1, 1, 1]\n'
        f"rotor_inertia = {IA.tolist()}\n"
    )
    argv = ["payload", "--robot", "panda", "--drive", str(tmp_path / "drive.toml"), "--data"]
    argv += [str(tmp_path / "u0.csv"), str(tmp_path / "u1.csv"), "--out", str(tmp_path / "p")]
    with warnings.catch_warnings(record=True) as caught:
        warnings.simplefilter("always")
        assert main(argv) == 0
    d = json.loads((tmp_path / "p" / "payload.json").read_text())
    assert d["plausible"] is False and d["load_mass"] is None and d["F_x_Cload"] is None
    assert d["mass"] < 3 * d["std"]["mass"]
    printed = capsys.readouterr()
    assert any("not significantly above zero" in str(w.message) for w in caught) or (
        "not significantly above zero" in printed.err
    )
    assert "no setLoad values written" in printed.out


def test_insignificant_mass_and_far_com_are_doubts():
    """The doubts of an estimate, against their definitions: the Panda is 1.32 m long
    (the distances between its joint frames, 0.333, 0.316, 0.0825, hypot(0.0825, 0.384)
    and 0.088, and the flange's 0.107: Franka's published kinematics)."""
    from dynid.feasibility.payload_doubts import doubts_about

    panda = dynid.panda()
    expected = 0.333 + 0.316 + 0.0825 + np.hypot(0.0825, 0.384) + 0.088 + 0.107
    assert arm_length(panda) == pytest.approx(expected, abs=1e-9)
    assert doubts_about(panda, "flange", 0.5, 0.01, np.array([0, 0, 0.05])) == ()
    (line,) = doubts_about(panda, "flange", 0.0012, 0.00076, np.array([0, 0, -0.02]))
    assert "not significantly above zero" in line and "1.6 std" in line
    (line,) = doubts_about(panda, "flange", 0.5, 0.01, np.array([0, 0, -2.09]))
    assert "farther than the arm is long (1.32 m)" in line


def test_serial_correlation_factor_of_filtered_noise():
    """White noise: factor 1; white noise averaged over 5 samples (a moving mean): its
    long-run variance ratio is 5 (the sum of the autocorrelations 1, 0.8, ..., 0.2 on
    both sides), Bartlett weights at 20 lags bring it near 5."""
    rng = np.random.default_rng(0)
    e = rng.standard_normal((40_000, 2))
    assert serial_correlation_factor(e, 2, 20)[0] == pytest.approx(1.0, abs=0.1)
    smooth = np.stack([np.convolve(c, np.ones(5) / 5, mode="valid") for c in e.T], axis=1)
    f, lags = serial_correlation_factor(smooth, 2, 20)
    exact = 1 + 2 * sum((1 - k / 21) * (5 - k) / 5 for k in range(1, 5))
    assert lags == 20 and f == pytest.approx(exact, rel=0.05)


def test_a_robot_whose_rotor_inertias_are_to_be_identified_is_refused():
    """A drive with rotor_inertia = "identify" on a robot: the arm's rotors are unknown."""
    with pytest.raises(ModelError, match="rotor inertias are to be identified"):
        arm_model(ARM, drive=Drive.identity(7))


def test_cli_model_preprocessing_recorded_and_several_unloaded_files(logs, tmp_path):
    """--model: its cut-off reused and recorded in payload.json; --unloaded takes several
    files, the arm identified from them with the model's terms. Regression (--unloaded
    gave numbers identical to its absence, silently): --unloaded with the recordings the
    model was identified from re-identifies the model itself, which a note says (the route
    no difference, the estimate the one without); one of them alone makes another arm."""
    loaded, unloaded = logs
    for k, log in enumerate(loaded):
        save_torque_log(tmp_path / f"l{k}.csv", log)
    for k, log in enumerate(unloaded):
        save_torque_log(tmp_path / f"u{k}.csv", log)
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", DynidWarning)
        model = identify_recordings(ARM, unloaded, structure=Structure.parse("armature,viscous"))
    save_model_json(tmp_path / "id.json", model)
    data = [str(tmp_path / "l0.csv"), str(tmp_path / "l1.csv")]
    argv = ["payload", "--model", str(tmp_path / "id.json"), "--data", *data, "-q"]
    assert main(argv + ["--out", str(tmp_path / "p")]) == 0
    d = json.loads((tmp_path / "p" / "payload.json").read_text())
    assert d["preprocessing"]["cutoff_hz"] == pytest.approx(model.info.log.cutoff_hz)
    assert d["preprocessing"]["cutoff_source"] == "model" and d["plausible"] is True
    assert abs(d["mass"] - MASS) < 0.01 * MASS and d["load_mass"] == d["mass"]
    argv = ["payload", "--model", str(tmp_path / "id.json"), "--data", *data, "--unloaded"]
    argv += [str(tmp_path / "u0.csv"), str(tmp_path / "u1.csv"), "-q"]
    assert main(argv + ["--out", str(tmp_path / "q")]) == 0
    same = json.loads((tmp_path / "q" / "payload.json").read_text())
    assert same["route"] == d["route"] == "2 torque logs" and same["inertia"] == d["inertia"]
    assert any("is the --model's own (the same recordings" in note for note in same["notes"])
    argv[-3:] = [str(tmp_path / "u0.csv"), "-q"]
    assert main(argv + ["--out", str(tmp_path / "r")]) == 0
    d = json.loads((tmp_path / "r" / "payload.json").read_text())
    assert "difference" in d["route"] and abs(d["mass"] - MASS) < 0.01 * MASS
    assert any("links + armature + viscous (given)" in note for note in d["notes"])


def test_undetermined_inertia_against_its_definition():
    """A moment under 3 std above zero, and a product whose std exceeds a third of half
    the third moment (``|Ixy| <= Izz / 2``), are named; tighter ones, and an inertia not
    identified (NaN std), are not."""
    I = np.array([[0.004, 0.0002, 0.0], [0.0002, 0.005, 0.0], [0.0, 0.0, 0.002]])
    std = np.array([1e-4, 3.4e-4, 1e-4, 1e-4, 1e-4, 6.7e-4])  # Ixy: 3.4e-4 > 0.001 / 3
    assert undetermined_inertia(I, std) == ("Ixy", "Izz")
    assert undetermined_inertia(I, np.array([1e-4, 3.3e-4, 1e-4, 1e-4, 1e-4, 6.6e-4])) == ()
    assert undetermined_inertia(I, np.full(6, np.nan)) == ()


def _slow_or_fast(amplitude, seed):
    """10 s at 500 Hz of the Panda carrying the load, every joint a sinusoid of
    ``amplitude`` [rad/s] times the fast pattern, default sensor noise (0.05 N m)."""
    fast = np.array([2.21, -2.21, 1.2, 1.5, -2.3, 2.1, -2.5])
    arm = dynid.panda()
    traj = sinusoid_trajectory(
        uniform_times(10.0, 500.0), q0=dynid.PANDA_NEUTRAL_Q, amplitudes=amplitude * fast
    )
    loaded = arm.with_tool(np.eye(4), MASS, COM, INERTIA, name="load")
    return arm, simulate_measurement(loaded, traj, rng=np.random.default_rng(seed))


def test_an_inertia_the_motion_does_not_determine_is_a_doubt_not_a_setload_value():
    """Regression: a load whose inertia the data did not determine (std about the value)
    was written to setLoad with ``plausible: true`` and no doubt. Turned slowly (0.14-0.3
    rad/s) the load's mass is known to 0.2 % but Ixx, Iyy, Ixy are not: a warning names
    them, the estimate is not plausible, and payload.json keeps setLoad's mass and CoM
    without its inertia; turned fast, every element is determined and handed on. The
    residual is compared with the torque noise after the low-pass (0.05 N m through the
    filter's noise gain)."""
    for scale, seed in ((0.135, 21), (1.0, 22)):
        arm, log = _slow_or_fast(scale, seed)
        with warnings.catch_warnings(record=True) as caught:
            warnings.simplefilter("always")
            est = identify_payload(arm, log)
        doc = payload_to_dict(est, arm)
        floor = 0.05 * lowpass_noise_gain(500.0, est.preprocessing["cutoff_hz"])
        assert abs(est.noise_rms / floor - 1) < 0.05 and est.residual_rms < 2 * est.noise_rms
        assert doc["load_mass"] == est.mass and abs(est.mass - MASS) < 0.01 * MASS
        said = [str(w.message) for w in caught if "inertia is not determined" in str(w.message)]
        if scale < 1:
            assert {"Ixx", "Iyy", "Ixy"} <= set(est.undetermined)
            assert len(said) == 1 and said[0].startswith(
                "the load's inertia is not determined: Ixx"
            )
            assert not est.plausible and doc["doubts"] == said and doc["load_inertia"] is None
            assert doc["inertia_determined"] is False
        else:
            assert est.undetermined == () and not said and est.plausible
            assert doc["load_inertia"] is not None and doc["inertia_determined"] is True


def test_payload_report_covers_mass_com_and_inertia_and_weighs_the_residual(tmp_path, capsys):
    """Regression: the report's headline gave the mass alone, 'usable, with reservations'
    without a reason, and the residual without a unit. On a slowly turned load: the
    headline names the mass, the CoM and the inertia's undetermined elements; the
    reservation says which; the residual is in N m against the torque noise; the command
    prints it too."""
    arm, log = _slow_or_fast(0.135, 21)
    save_torque_log(tmp_path / "slow.csv", log)
    argv = ["payload", "--robot", "panda", "--data", str(tmp_path / "slow.csv")]
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", DynidWarning)
        assert main([*argv, "--out", str(tmp_path / "p")]) == 0
    printed = capsys.readouterr().out
    assert re.search(r"residual RMS \S+ N m, \S+ x the torque noise \(\S+ N m after", printed)
    assert "Ixx      " in printed and "not determined" in printed
    html = (tmp_path / "p" / "report.html").read_text(encoding="utf-8")
    box = re.search(r'<section class="verdict.*?</section>', html, re.S)
    assert box is not None
    text = " ".join(re.sub(r"<[^>]+>", " ", box.group(0)).split())
    assert re.search(r"usable, with reservations The payload weighs 0\.7\d* kg \(known to", text)
    assert "its centre of mass is known to" in text
    assert "its inertia is not determined (Ixx, Ixy" in text
    assert "Reservations: the data do not determine the inertia&#x27;s Ixx" in text
    assert re.search(r"Residual RMS \S+ N m, \S+ x the torque noise after the low-pass", text)


def test_a_load_fitted_far_above_the_noise_is_not_a_load_to_trust_printed_and_reported(
    tmp_path, capsys
):
    """Regression (a fit that left tens of times the torque noise handed its mass and CoM
    to setLoad as a usable load): a spring the arm's model lacks on joint 2 (5 N m/rad)
    makes the command print the mass and CoM in doubt with the ratio, write no setLoad
    values, and the report call it not a load to trust, naming the ratio."""
    arm, log = _slow_or_fast(1.0, 22)
    half = slice(0, log.t.size // 2)  # 5 s
    tau = log.tau[half] + 5.0 * (log.q[half, 1:2] - 0.2) * [0, 1, 0, 0, 0, 0, 0]
    q, dq = log.q[half], log.dq[half]
    save_torque_log(tmp_path / "spring.csv", TorqueLog(t=log.t[half], q=q, dq=dq, tau=tau))
    argv = ["payload", "--robot", "panda", "--data", str(tmp_path / "spring.csv")]
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", DynidWarning)
        assert main([*argv, "--out", str(tmp_path / "p")]) == 0
    printed = capsys.readouterr().out
    assert re.search(r"mass +\S+ kg +\(std \S+\) +in doubt", printed)
    assert "over 3 x, torques the arm's model leaves" in printed
    assert "not a load to trust: no setLoad values written" in printed
    doc = json.loads((tmp_path / "p" / "payload.json").read_text())
    # judged against the torque noise and the states' noise through the arm's model
    ratio = doc["judged_residual"]["ratio"]
    assert doc["residual_rms"] / doc["noise_rms"] > ratio > 10
    assert doc["load_mass"] is None and doc["F_x_Cload"] is None
    html = (tmp_path / "p" / "report.html").read_text(encoding="utf-8")
    box = re.search(r'<section class="verdict.*?</section>', html, re.S)
    assert box is not None
    text = " ".join(re.sub(r"<[^>]+>", " ", box.group(0)).split())
    assert "not a load to trust" in text and f"{ratio:.3g} x the torque noise" in text


@pytest.mark.parametrize(
    "own, bare, how, printed",
    [
        (0.0027012, 0.0027003, "as well (within 1 %) as with it", ("0.0027", "0.002701")),
        (0.0030, 0.0027, "better", ("0.0027", "0.003")),
    ],
)
def test_friction_residuals_equal_in_print_are_not_called_better(own, bare, how, printed):
    """Regression (payload: the classical friction "fits better", residual RMS 0.0027 N m
    against 0.0027): residuals within 1 % fit "as well", printed with the digits that tell
    them apart; a 10 % lower one is "better"."""
    from dynid.feasibility.payload_rows import own_friction_note

    note = own_friction_note("smooth", own, bare)
    assert f"estimated alongside {how} (residual RMS {printed[0]} N m; {printed[1]} with" in note
    kept = own_friction_note("smooth", bare, own)  # the arm's own fits no worse: subtracted
    assert "subtracted" in kept and "better" not in kept
