"""Payload identification on a known arm: static M and g, g only, torque logs, difference.

References: a ground-truth load added with ``Robot.with_tool`` and simulated measurements
of the loaded arm; the published Panda as the arm (Gaz et al. 2019); a statistical check
of the reported standard deviations over seeded repetitions.
"""

from __future__ import annotations

import dataclasses
import json

import numpy as np
import pytest
from scipy.spatial.transform import Rotation

import dynid
from dynid.cli.__main__ import main
from dynid.exceptions import (
    DataError,
    ModelError,
    RankDeficientError,
    ShapeError,
    UnknownNameError,
)
from dynid.feasibility.lmi import pseudo_inertia_margin
from dynid.feasibility.payload import (
    identify_payload,
    link_params_from_frame,
    robot_with_payload,
)
from dynid.identification.data import StaticDataset
from dynid.io.drive_file import drive_of_robot_file
from dynid.io.model_json import load_model_json
from dynid.io.payload_json import payload_to_dict
from dynid.io.static_data import save_static_csv
from dynid.model.inertia import inertia6_from_matrix, phi_from_inertial
from dynid.signals import lowpass_noise_gain
from dynid.simulation.measurement import simulate_measurement
from dynid.simulation.trajectories import random_fourier, sinusoid_trajectory, uniform_times

MASS = 0.83
COM = np.array([0.012, -0.021, 0.064])


def _inertia(seed=1):
    R = Rotation.random(random_state=seed).as_matrix()
    return R @ np.diag([0.0021, 0.0032, 0.0043]) @ R.T


def _static(robot, n, noise, seed):
    ctrl = dynid.SimulatedController(robot, relative_noise=noise, rng=np.random.default_rng(seed))
    return dynid.acquire_static(ctrl, n, np.random.default_rng(seed + 100))


def _errors(est, mass=MASS, com=COM, inertia=None):
    I = _inertia() if inertia is None else inertia
    return (
        est.mass - mass,
        est.com - com,
        inertia6_from_matrix(est.inertia) - inertia6_from_matrix(I),
    )


def test_noise_free_static_data_give_the_load():
    """300 noise-free static M, g on the published Panda: mass 1 %, CoM 2 mm, inertia 10 %."""
    arm = dynid.panda()
    data = _static(arm.with_tool(np.eye(4), MASS, COM, _inertia(), name="load"), 300, 0.0, 1)
    est = identify_payload(arm, data)
    dm, dc, dI = _errors(est)
    assert abs(dm) < 0.01 * MASS and np.max(np.abs(dc)) < 2e-3
    assert np.max(np.abs(dI)) < 0.1 * np.max(np.abs(_inertia()))
    # noise-free and consistent: the estimate is exact to round-off
    assert abs(dm) < 1e-10 and np.max(np.abs(dc)) < 1e-10 and np.max(np.abs(dI)) < 1e-10
    assert est.rank == 10 and not est.constraint_active and est.margin > 0


def test_reported_std_covers_the_error_at_relative_noise_1e4():
    """Over 20 seeded runs at 1e-4 noise the errors in units of their std have RMS about 1."""
    arm = dynid.panda()
    loaded = arm.with_tool(np.eye(4), MASS, COM, _inertia(), name="load")
    z = []
    for seed in range(20):
        est = identify_payload(arm, _static(loaded, 300, 1e-4, 10 + seed))
        dm, dc, dI = _errors(est)
        z.append(np.concatenate([[dm / est.std_mass], dc / est.std_com, dI / est.std_inertia]))
    z = np.array(z)
    rms = np.sqrt(np.mean(z**2))
    assert 0.7 < rms < 1.4, rms
    assert np.mean(np.abs(z) < 3) > 0.97


def test_gravity_only_gives_mass_and_com():
    """g alone: mass and CoM, no inertia (NaN std), and the notes say so."""
    arm = dynid.panda()
    data = _static(arm.with_tool(np.eye(4), MASS, COM, _inertia(), name="load"), 300, 1e-4, 2)
    est = identify_payload(arm, data, gravity_only=True)
    dm, dc, _ = _errors(est)
    assert abs(dm) < 4 * est.std_mass and np.all(np.abs(dc) < 4 * est.std_com)
    assert not est.inertia_identified and np.all(np.isnan(est.std_inertia))
    assert est.covariance.shape == (4, 4) and any("g only" in s for s in est.notes)


def test_load_in_another_frame_and_franka_convention(tmp_path):
    """A load given in a rotated TCP frame is found there; setLoad values are in the flange."""
    T = np.eye(4)
    T[:3, :3] = Rotation.from_euler("z", -np.pi / 4).as_matrix()
    T[:3, 3] = [0.0, 0.0, 0.1034]
    arm = dynid.panda().with_frame("tcp", T)
    loaded = arm.with_tool(np.eye(4), MASS, COM, _inertia(), parent="tcp", name="load")
    est = identify_payload(arm, _static(loaded, 200, 0.0, 3), frame="tcp")
    np.testing.assert_allclose(est.com, COM, atol=1e-10)

    d = payload_to_dict(est, arm)
    R, p = T[:3, :3], T[:3, 3]
    np.testing.assert_allclose(d["F_x_Cload"], R @ COM + p, atol=1e-10)
    I_fl = R @ _inertia() @ R.T
    np.testing.assert_allclose(np.reshape(d["load_inertia"], (3, 3), order="F"), I_fl, atol=1e-10)


def test_link_params_from_frame_matches_with_tool():
    """phi_link = A phi_F equals the standard parameters Robot.with_tool adds to the link."""
    arm = dynid.panda()
    T = np.eye(4)
    T[:3, :3] = Rotation.random(random_state=4).as_matrix()
    T[:3, 3] = [0.03, -0.01, 0.12]
    tooled = arm.with_tool(T, MASS, COM, _inertia(), name="load")
    A = link_params_from_frame(arm.frame("flange").T_link_frame @ T)
    np.testing.assert_allclose(
        A @ phi_from_inertial(MASS, COM, _inertia()), tooled.phi[6] - arm.phi[6], atol=1e-14
    )


def test_inconsistent_least_squares_is_projected_by_the_lmi():
    """A load no body can have (triangle inequality violated) comes out consistent.
    Regression (an inertia the LMI set on its bound was handed to setLoad as determined):
    the whole inertia is called not determined, a warning says the bound set it, and
    setLoad's inertia is not written."""
    arm = dynid.panda()
    bad = np.diag([0.001, 0.001, 0.004])  # 0.001 + 0.001 < 0.004
    A = link_params_from_frame(arm.frame("flange").T_link_frame)
    phi = np.array(arm.phi)
    phi[6] += A @ phi_from_inertial(MASS, COM, bad)
    data = _static(arm.with_params(phi), 100, 0.0, 5)
    with pytest.warns(dynid.DynidWarning, match=r"set it on its bound, not the data"):
        est = identify_payload(arm, data, margin=1e-6)
    assert est.constraint_active and any("LMI" in s for s in est.notes)
    assert est.undetermined == ("Ixx", "Ixy", "Ixz", "Iyy", "Iyz", "Izz")
    assert not est.plausible and payload_to_dict(est, arm)["load_inertia"] is None
    assert pseudo_inertia_margin(est.phi) >= 1e-6 * (1 - 1e-4)
    lam = np.linalg.eigvalsh(est.inertia)
    assert lam[0] + lam[1] >= lam[2] - 1e-9 and abs(est.mass - MASS) < 0.05 * MASS


def test_torque_log_route_with_friction():
    """A noise-free log of the loaded arm with classical friction: the load to 1e-6."""
    arm = dynid.panda().with_friction(None)
    loaded = arm.with_tool(np.eye(4), MASS, COM, _inertia(), name="load")
    traj = random_fourier(arm, np.random.default_rng(6), q0=dynid.PANDA_NEUTRAL_Q)(
        uniform_times(10.0, 200.0)
    )
    fr = dynid.ClassicalFriction(np.full(7, 0.1), np.full(7, 0.3), np.linspace(-0.1, 0.1, 7))
    log = simulate_measurement(
        loaded,
        traj,
        rng=np.random.default_rng(7),
        noise=dynid.SensorNoise.none(),
        friction=fr,
        with_ddq=True,
    )
    est = identify_payload(arm, log, cutoff_hz=None)
    dm, dc, dI = _errors(est)
    assert abs(dm) < 1e-6 and np.max(np.abs(dc)) < 1e-6 and np.max(np.abs(dI)) < 1e-6
    np.testing.assert_allclose(est.friction[:, 1], 0.3, atol=1e-6)


def test_difference_method_removes_arm_model_error():
    """A wrong arm model biases the direct estimate; the difference method does not."""
    truth = dynid.panda()
    phi = np.array(truth.phi)
    phi[5] *= 1.05  # the real link 6 is 5 % heavier than the model says
    real = truth.with_params(phi)
    loaded = real.with_tool(np.eye(4), MASS, COM, _inertia(), name="load")
    data, unloaded = _static(loaded, 300, 0.0, 8), _static(real, 300, 0.0, 9)
    direct = identify_payload(truth, data)
    diff = identify_payload(truth, data, unloaded=unloaded)
    assert abs(direct.mass - MASS) > 0.01 * MASS
    assert abs(diff.mass - MASS) < 1e-8 and np.max(np.abs(diff.com - COM)) < 1e-8
    assert "difference" in diff.route


def test_robot_with_payload_reproduces_the_loaded_arm():
    """The robot carrying the estimate has the loaded arm's g and M."""
    arm = dynid.panda()
    loaded = arm.with_tool(np.eye(4), MASS, COM, _inertia(), name="load")
    data = _static(loaded, 100, 0.0, 10)
    tool = robot_with_payload(arm, identify_payload(arm, data))
    q = data.q[:20]
    np.testing.assert_allclose(
        dynid.gravity_torques(tool, q), dynid.gravity_torques(loaded, q), atol=1e-10
    )
    np.testing.assert_allclose(dynid.mass_matrix(tool, q), dynid.mass_matrix(loaded, q), atol=1e-10)


def test_payload_errors():
    """Unknown frame, a frame on the base, other joint counts or kinds, a negative g-only mass."""
    arm = dynid.panda()
    data = _static(arm, 30, 0.0, 11)
    with pytest.raises(UnknownNameError, match="Unknown frame 'gripper'"):
        identify_payload(arm, data, frame="gripper")
    with pytest.raises(ModelError, match="on the base"):
        identify_payload(arm, data, frame="link0")
    with pytest.raises(ShapeError, match="data have 2 joints"):
        identify_payload(arm, StaticDataset(data.q[:, :2], data.M[:, :2, :2], data.g[:, :2]))
    log = simulate_measurement(
        arm,
        random_fourier(arm, np.random.default_rng(1))(uniform_times(2.0, 100.0)),
        rng=np.random.default_rng(2),
    )
    with pytest.raises(ShapeError, match="same kind"):
        identify_payload(arm, data, unloaded=log)
    lighter = arm.with_params(np.array(arm.phi) * np.r_[np.ones(6), 0.9][:, None])
    with pytest.raises(DataError, match="not positive"):
        identify_payload(arm, _static(lighter, 60, 0.0, 12), gravity_only=True)
    # the full route too: its LMI turned a negative mass into a load of about 1e-22 kg
    with pytest.raises(DataError, match="not positive"):
        identify_payload(arm, _static(lighter, 60, 0.0, 12))


def test_cli_payload_writes_payload_json_and_the_robot(tmp_path, capsys):
    """dynid payload: payload.json with std and setLoad values; g-only files without M."""
    arm = dynid.panda()
    data = _static(arm.with_tool(np.eye(4), MASS, COM, _inertia(), name="load"), 200, 1e-4, 13)
    save_static_csv(tmp_path / "loaded.csv", data)
    assert (
        main(
            [
                "payload",
                "--robot",
                "panda",
                "--data",
                str(tmp_path / "loaded.csv"),
                "--out",
                str(tmp_path / "p"),
            ]
        )
        == 0
    )
    d = json.loads((tmp_path / "p" / "payload.json").read_text())
    assert (
        d["schema"] == "dynid-payload/1" and len(d["inertia"]) == 6 and len(d["load_inertia"]) == 9
    )
    assert abs(d["mass"] - MASS) < 4 * d["std"]["mass"] and d["load_mass"] == d["mass"]
    assert d["F_x_Cload"] == d["com"]
    tool = dynid.Robot.from_toml(tmp_path / "p" / d["with_tool"])
    np.testing.assert_allclose(tool.phi[6, 0], arm.phi[6, 0] + d["mass"], rtol=1e-12)
    # g only, from a file that holds q and g only, with other column names
    names = [f"pos{i}" for i in range(7)] + [f"grav{i}" for i in range(7)]
    table = np.concatenate([data.q, data.g], axis=1)
    np.savetxt(tmp_path / "g.csv", table, delimiter=",", header=",".join(names), comments="")
    argv = [
        "payload",
        "--robot",
        "panda",
        "--data",
        str(tmp_path / "g.csv"),
        "--gravity-only",
        "--columns",
        "q=pos{i0},g=grav{i0}",
        "--out",
        str(tmp_path / "g"),
    ]
    assert main(argv) == 0
    d = json.loads((tmp_path / "g" / "payload.json").read_text())
    assert d["inertia"] is None and d["load_inertia"] is None and d["std"]["inertia"] is None
    assert "g only" in capsys.readouterr().out
    assert main(argv[:-2] + ["--frame", "nope", "--out", str(tmp_path / "x")]) == 2
    assert capsys.readouterr().err.startswith("dynid payload: error: Unknown frame")


def test_cli_payload_on_an_identified_arm(tmp_path):
    """--model identification.json (the arm identified without the load) as the known arm."""
    arm = dynid.panda()
    save_static_csv(tmp_path / "arm.csv", _static(arm, 300, 0.0, 14))
    loaded = arm.with_tool(np.eye(4), MASS, COM, _inertia(), name="load")
    save_static_csv(tmp_path / "loaded.csv", _static(loaded, 300, 0.0, 15))
    assert (
        main(["identify", "--data", str(tmp_path / "arm.csv"), "--out", str(tmp_path / "id"), "-q"])
        == 0
    )
    model = tmp_path / "id" / "identification.json"
    argv = ["payload", "--model", str(model), "--data", str(tmp_path / "loaded.csv")]
    assert main(argv + ["--out", str(tmp_path / "p"), "-q"]) == 0
    d = json.loads((tmp_path / "p" / "payload.json").read_text())
    assert abs(d["mass"] - MASS) < 1e-8 and np.max(np.abs(np.subtract(d["com"], COM))) < 1e-8
    # the model carrying the load predicts the loaded arm (its base parameters; a TOML of
    # its equivalent robot, links of mass 0 holding first moments, lost gravity: 71.8 %)
    assert d["with_tool"] == "model_with_payload.json"
    assert not (tmp_path / "p" / "robot_with_payload.toml").exists()
    carried = load_model_json(tmp_path / "p" / d["with_tool"])
    q = _static(arm, 20, 0.0, 16).q
    np.testing.assert_allclose(
        carried.gravity_torques(q), dynid.gravity_torques(loaded, q), atol=1e-8
    )
    np.testing.assert_allclose(carried.mass_matrix(q), dynid.mass_matrix(loaded, q), atol=1e-8)
    # its description carries the load as well (the checks against the description read
    # it: without the load, a loaded arm's torques read as torque constants 1.34 x off)
    np.testing.assert_allclose(
        dynid.gravity_torques(carried.description, q), dynid.gravity_torques(loaded, q), atol=1e-8
    )


def test_the_robot_with_the_load_keeps_the_arms_drive_and_friction(tmp_path):
    """robot_with_payload.toml of a robot TOML holds its [drive] (rotor inertias) and
    friction, as `dynid export` writes them (it had the links alone: an xArm7's file
    without its friction and rotor inertias predicted its own load's log to 25.4 %)."""
    arm = dynid.panda()
    drive = tmp_path / "drive.toml"
    drive.write_text(
        'schema = "dynid-drive/1"\nside = "joint"\ngear_ratio = [100, 100, 100, 100, 50, 50, 50]'
        "\nrotor_inertia = [3e-5, 3e-5, 3e-5, 3e-5, 1e-5, 1e-5, 1e-5]\n"
    )
    assert (
        main(
            [
                "export",
                "--params",
                "panda",
                "--drive",
                str(drive),
                "--out",
                str(tmp_path / "arm.toml"),
                "-q",
            ]
        )
        == 0
    )
    loaded = arm.with_tool(np.eye(4), MASS, COM, _inertia(), name="load")
    data = _static(loaded, 200, 0.0, 17)
    rotors = np.diag(np.array([100.0] * 4 + [50.0] * 3) ** 2 * ([3e-5] * 4 + [1e-5] * 3))
    save_static_csv(tmp_path / "loaded.csv", dataclasses.replace(data, M=data.M + rotors))
    argv = [
        "payload",
        "--robot",
        str(tmp_path / "arm.toml"),
        "--data",
        str(tmp_path / "loaded.csv"),
    ]
    assert main([*argv, "--out", str(tmp_path / "p"), "-q"]) == 0
    written = tmp_path / "p" / "robot_with_payload.toml"
    robot = dynid.Robot.from_toml(written)
    np.testing.assert_allclose(robot.phi, loaded.phi, atol=1e-8)
    held, own = drive_of_robot_file(written, 7), drive_of_robot_file(tmp_path / "arm.toml", 7)
    assert held is not None and own is not None
    for name in ("transmission", "rotor_inertia"):
        np.testing.assert_array_equal(getattr(held, name), getattr(own, name))
    own_friction = dynid.Robot.from_toml(tmp_path / "arm.toml").friction
    assert robot.friction.kind == own_friction.kind == "sigmoid"
    np.testing.assert_array_equal(robot.friction.params, own_friction.params)


def _sinusoid_log(amplitudes, seed):
    """A 10 s log at 500 Hz of the Panda carrying the load, sinusoids of ``amplitudes``
    [rad/s], with the default sensor noise (1e-4 rad, 1e-3 rad/s, 0.05 N m)."""
    arm = dynid.panda()
    loaded = arm.with_tool(np.eye(4), MASS, COM, _inertia(), name="load")
    traj = sinusoid_trajectory(
        uniform_times(10.0, 500.0), q0=dynid.PANDA_NEUTRAL_Q, amplitudes=amplitudes
    )
    return arm, simulate_measurement(loaded, traj, rng=np.random.default_rng(seed))


def test_a_load_that_rotates_about_one_axis_is_refused_not_fitted_from_noise():
    """Only joint 1 moves: the load rotates about one fixed axis, which excites 7 of its
    10 parameters (m, m c and the inertia's column about that axis); the other 3 were
    fitted from position noise (a 0.73 kg load came out as 0.31 kg, its CoM 1.3 m away).
    No joint moves: gravity at one pose leaves 3 (m and the horizontal moments)."""
    arm, log = _sinusoid_log([1.5, 0, 0, 0, 0, 0, 0], 21)
    with pytest.raises(RankDeficientError, match=r"rank 8 of 10; unexcited .*hint: a log that"):
        identify_payload(arm, log)
    arm, log = _sinusoid_log(np.zeros(7), 22)
    with pytest.raises(RankDeficientError, match=r"rank [0-3] of 10; unexcited"):
        identify_payload(arm, log)


def test_a_joint_that_never_moves_gets_no_friction_from_a_payload_log():
    """Joint 4 stays inside its velocity noise band: its fv, fc are zero (not fitted from
    noise) and said so; with the arm's friction left out of its model (``friction=None``)
    the moving joints' Coulomb friction estimated alongside is the arm's (0.3 N m,
    published sigmoid near its plateau), and the load is still found."""
    amplitudes = [2.21, -2.21, 1.2, 0.0, -2.3, 2.1, -2.5]
    arm, log = _sinusoid_log(amplitudes, 23)
    est = identify_payload(arm, log, friction=None)
    assert np.all(est.friction[3, :2] == 0.0)
    assert np.all(est.friction[[0, 1, 2, 4, 5, 6], 1] > 0.1)
    assert any("joint(s) 4 never leave" in note for note in est.notes)
    assert abs(est.mass - MASS) < 0.05 * MASS


@pytest.mark.parametrize("own", [False, True], ids=["estimated-alongside", "arm's-own"])
def test_coulomb_friction_on_low_passed_torques_leaves_the_inertia_determined(own):
    """Coulomb steps left sharp against low-passed torques lost the load's inertia (std
    about its value, residual 20 x the noise); filtered as the torques were, each inertia
    element is within 3 std of the truth, its std under a tenth of the load's largest
    moment and the residual at the noise floor. Both places the step enters: the classical
    friction estimated alongside (arm without friction) and the arm's own steep sigmoid."""
    fc = np.linspace(2.0, 0.5, 7)  # [N m]
    truth = dynid.SigmoidFriction(2 * fc, np.full(7, 300.0), np.zeros(7))
    if not own:
        truth = dynid.ClassicalFriction(np.full(7, 0.5), fc, np.zeros(7))
    arm = dynid.panda().with_friction(truth if own else None)
    loaded = arm.with_tool(np.eye(4), MASS, COM, _inertia(), name="load")
    traj = random_fourier(arm, np.random.default_rng(6), q0=dynid.PANDA_NEUTRAL_Q)(
        uniform_times(10.0, 500.0)
    )
    log = simulate_measurement(loaded, traj, rng=np.random.default_rng(7), friction=truth)
    est = identify_payload(arm, log)
    _, _, dI = _errors(est)
    floor = 0.05 * lowpass_noise_gain(500.0, est.preprocessing["cutoff_hz"])
    assert est.residual_rms < 1.5 * floor
    assert np.all(np.abs(dI) < 3 * est.std_inertia)
    assert np.all(est.std_inertia < 0.1 * 0.0043)
