"""Drive trains: gear ratios, a coupled wrist, encoder offsets, rotor inertia, motor friction,
motor currents (issue 17).

The reference torques come from Pinocchio's RNEA on example-robot-data's UR5 plus the drive
terms written out here, independently of dynid:
``tau = rnea(q, dq, ddq) + K^T diag(Ia) K ddq + K^T (fv * dqm + fc * sign(dqm) + fo)``,
``dqm = K dq``; a motor-side log records ``qm = K (q - offset)``, ``dqm``, ``ddqm`` and
``tau_m = K^-T tau`` (or the currents ``tau_m / kt``).
"""

from __future__ import annotations

import warnings

import numpy as np
import pytest

import dynid
from dynid.exceptions import DataError, DynidWarning, ModelError
from dynid.identification.classical import identify_from_log
from dynid.identification.log import TorqueLog
from dynid.io.drive_file import drive_from_mapping, load_drive
from dynid.io.torque_log import save_torque_log
from dynid.model.drive import Drive
from dynid.regressors.terms import RotorInertia

from conftest import robot_data_urdf

pin = pytest.importorskip("pinocchio")

GEAR = np.array([101.0, 101.0, 101.0, 81.0, 81.0, 51.0])
# motor 6 turns with joints 5 and 6 (a coupled wrist): qm6 = 51 q6 + 30 q5
COUPLING = [(6, 5, 30.0)]
IA = np.array([3.0e-5, 3.0e-5, 2.5e-5, 1.2e-5, 1.0e-5, 0.8e-5])  # [kg m^2] at the motors
FV = np.array([2.0e-4, 1.5e-4, 1.2e-4, 0.6e-4, 0.5e-4, 0.4e-4])  # [N m s/rad] at the motors
FC = np.array([0.03, 0.03, 0.025, 0.012, 0.01, 0.008])  # [N m] at the motors
FO = np.array([0.002, -0.001, 0.0015, 0.0005, -0.0004, 0.0003])  # [N m] at the motors
OFFSET = np.array([0.01, -0.02, 0.015, 0.0, 0.03, -0.01])  # [rad]
KT = np.array([0.12, 0.12, 0.1, 0.07, 0.07, 0.05])  # [N m / A] at the motors


def _ur5() -> tuple[dynid.Robot, object, object]:
    path = robot_data_urdf("ur_description/urdf/ur5_robot.urdf")
    robot = dynid.Robot.from_urdf(path, "base_link", "tool0")
    model = pin.buildModelFromUrdf(path)
    model.gravity.linear = np.asarray(robot.gravity)
    return robot, model, model.createData()


def _drive(**kw: object) -> Drive:
    kw.setdefault("side", "motor")
    kw.setdefault("offset", OFFSET)
    return Drive.from_gears(GEAR, COUPLING, **kw)


def _trajectory(n: int, seed: int, duration: float = 6.0, fs: float = 250.0):
    """Sums of sinusoids with their exact derivatives: t (N,), q, dq, ddq (N, n)."""
    rng = np.random.default_rng(seed)
    t = np.arange(0.0, duration, 1.0 / fs)
    w = 2 * np.pi * rng.uniform(0.1, 0.6, (4, n))
    a = rng.uniform(0.1, 0.5, (4, n))
    ph = rng.uniform(0, 2 * np.pi, (4, n))
    arg = t[:, None, None] * w[None] + ph[None]
    q = np.sum(a * np.sin(arg), axis=1)
    dq = np.sum(a * w * np.cos(arg), axis=1)
    ddq = -np.sum(a * w**2 * np.sin(arg), axis=1)
    return t, q, dq, ddq


def _exact_fit(robot: dynid.Robot, log: TorqueLog, drive: Drive):
    """The paper's terms fitted by least squares to an exact log with its accelerations:
    no low-pass, every sample."""
    return identify_from_log(
        robot, log, cutoff_hz=None, decimate=1, drive=drive, structure="classical",
        estimator="ols",
    )  # fmt: skip


def _joint_torques(model, data, q, dq, ddq) -> np.ndarray:
    """Reference joint torques: Pinocchio's RNEA plus the drive terms, written out."""
    K = Drive.from_gears(GEAR, COUPLING, offset=OFFSET).transmission
    tau = np.array([pin.rnea(model, data, *s) for s in zip(q, dq, ddq, strict=True)])
    dqm, ddqm = dq @ K.T, ddq @ K.T
    tau += (IA * ddqm) @ K
    tau += (FV * dqm + FC * np.sign(dqm) + FO) @ K
    return tau


def _motor_log(model, data, seed: int, currents: bool = False) -> tuple[TorqueLog, np.ndarray]:
    """A motor-side log (exact ddq) and its joint torques."""
    t, q, dq, ddq = _trajectory(6, seed)
    tau = _joint_torques(model, data, q, dq, ddq)
    K = Drive.from_gears(GEAR, COUPLING).transmission
    tau_m = np.linalg.solve(K.T, tau.T).T
    effort = tau_m / KT if currents else tau_m
    log = TorqueLog(t, (q - OFFSET) @ K.T, dq @ K.T, effort, ddq @ K.T)
    return log, tau


def test_drive_maps_motor_states_and_torques_by_power_conservation():
    """q = K^-1 qm + offset, dq = K^-1 dqm, tau = K^T tau_m, and the inverse maps back."""
    d = _drive(effort="current", torque_constant=KT)
    rng = np.random.default_rng(0)
    q, dq = rng.normal(size=(2, 5, 6))
    qm, dqm = d.recorded_states(q, dq)
    np.testing.assert_allclose(qm, (q - OFFSET) @ d.transmission.T, rtol=1e-14)
    back = d.joint_states(qm, dqm)
    np.testing.assert_allclose(back[0], q, rtol=0, atol=1e-13)
    np.testing.assert_allclose(back[1], dq, rtol=0, atol=1e-13)
    tau = rng.normal(size=(5, 6))
    i = d.recorded_efforts(tau)
    np.testing.assert_allclose(d.joint_torques(i), tau, rtol=0, atol=1e-12)
    # the motor power equals the joint power
    np.testing.assert_allclose(np.sum(i * KT * dqm, axis=1), np.sum(tau * dq, axis=1), atol=1e-12)


def test_identify_motor_side_coupled_wrist_predicts_held_out_torques_to_round_off():
    """Noise-free motor-side torques with exact ddq: held-out joint torques to 1e-6 relative,
    and the rotor of motor 2..6 identified (its own base parameter or in a combination)."""
    robot, model, data = _ur5()
    train, _ = _motor_log(model, data, seed=1)
    held, tau_held = _motor_log(model, data, seed=2)
    drive = _drive()
    m = _exact_fit(robot, train, drive)
    assert "Ia1" in m.base.std_labels
    assert any("Ia6" in e for e in m.base.expressions)
    h = dynid.identification.log.joint_side_log(held, drive)
    tau_hat = dynid.model_torques(m, h.q, h.dq, h.ddq)
    err = np.linalg.norm(tau_hat - tau_held) / np.linalg.norm(tau_held)
    assert err < 1e-6


def test_identify_motor_currents_with_torque_constants():
    """Motor currents times the torque constants give the same model as motor torques."""
    robot, model, data = _ur5()
    train, _ = _motor_log(model, data, seed=1, currents=True)
    held, tau_held = _motor_log(model, data, seed=3)
    drive = _drive(effort="current", torque_constant=KT)
    m = _exact_fit(robot, train, drive)
    h = dynid.identification.log.joint_side_log(held, _drive())
    tau_hat = dynid.model_torques(m, h.q, h.dq, h.ddq)
    assert np.linalg.norm(tau_hat - tau_held) / np.linalg.norm(tau_held) < 1e-6


def test_without_the_coupling_the_fit_is_worse():
    """The coupled rotor's inertia and friction are what a diagonal drive cannot represent."""
    robot, model, data = _ur5()
    train, _ = _motor_log(model, data, seed=1)
    held, tau_held = _motor_log(model, data, seed=2)
    wrong = Drive.from_gears(GEAR, side="motor", offset=OFFSET)
    # the log is the coupled one: read it as joint torques through the true transmission
    h = dynid.identification.log.joint_side_log(held, _drive())
    tr = dynid.identification.log.joint_side_log(train, _drive())
    m = _exact_fit(robot, tr, Drive.from_gears(GEAR, offset=0 * OFFSET))
    assert wrong.n == 6
    tau_hat = dynid.model_torques(m, h.q, h.dq, h.ddq)
    assert np.linalg.norm(tau_hat - tau_held) / np.linalg.norm(tau_held) > 1e-4


@pytest.mark.parametrize(
    ("table", "match"),
    [
        ({"gear_ratio": [1, 2]}, "list of 3 numbers"),
        ({"gear_ratio": [1, 0, 1]}, "singular"),
        (
            {"coupling": [[4, 1, 2.0]]},
            r"key 'coupling\[0\].motor': expected an integer in \[1, 3\]; got 4",
        ),
        ({"coupling": [[1, 1, 2.0]]}, "gear_ratio"),
        ({"effort": "current"}, "torque_constant"),
        ({"side": "motors"}, "key 'side': expected one of 'joint', 'motor'; got 'motors'"),
        ({"gear": [1, 2, 3]}, "key 'gear': unknown key; allowed: coupling, effort"),
        ({"offset": [0, True, 0]}, r"key 'offset\[1\]': expected a number; got True"),
        ({"rotor_inertia": [0.1, -0.1, 0.0]}, "rotor_inertia must be >= 0"),
        ({"rotor_inertia": "fit"}, "'identify', a number or a list"),
        ({"schema": "dynid-drive/9"}, "schema"),
    ],
)
def test_drive_file_errors_name_the_key(table, match):
    """A wrong drive description is one DataError naming the key, before any computation."""
    with pytest.raises(DataError, match=match):
        drive_from_mapping(table, 3, source="drive.toml")


def test_drive_file_and_robot_toml_drive_table(tmp_path):
    """A drive file and a robot TOML's [drive] table give the same drive."""
    text = (
        'side = "motor"\ngear_ratio = [100, 80]\ncoupling = [[2, 1, 20]]\n'
        'offset = [0.1, 0.0]\neffort = "current"\ntorque_constant = [0.1, 0.2]\n'
    )
    f = tmp_path / "drive.toml"
    f.write_text('schema = "dynid-drive/1"\n' + text)
    d = load_drive(f, 2)
    np.testing.assert_array_equal(d.transmission, [[100.0, 0.0], [20.0, 80.0]])
    assert d.friction_place == "motor" and d.identifies_rotor_inertia
    r = tmp_path / "arm.toml"
    r.write_text(
        'name = "two"\n[[joints]]\nname = "j1"\nparent = "l0"\nchild = "l1"\n'
        '[[joints]]\nname = "j2"\nparent = "l1"\nchild = "l2"\n[drive]\n' + text
    )
    d2 = load_drive(r, 2)
    np.testing.assert_array_equal(d2.transmission, d.transmission)
    with pytest.raises(
        DataError, match="bad.toml: key 'schema': missing; expected 'dynid-drive/1'"
    ):
        (tmp_path / "bad.toml").write_text(text)
        load_drive(tmp_path / "bad.toml", 2)


def test_drive_model_errors():
    """A singular transmission and currents without constants are ModelErrors."""
    with pytest.raises(ModelError, match="singular"):
        Drive(transmission=np.ones((2, 2)), offset=np.zeros(2))
    with pytest.raises(ModelError, match="torque_constant"):
        Drive(transmission=np.eye(2), offset=np.zeros(2), effort="current")


def _write_positions_only_csv(path, log: TorqueLog) -> None:
    n = log.n
    head = ["t"] + [f"q{j + 1}" for j in range(n)] + [f"tau{j + 1}" for j in range(n)]
    table = np.column_stack([log.t, log.q, log.tau])
    np.savetxt(path, table, delimiter=",", header=",".join(head), comments="", fmt="%.17g")


@pytest.mark.parametrize("currents", [False, True])
def test_cli_motor_side_positions_only_identify_then_validate(tmp_path, currents):
    """`identify --drive` on a motor-side log with positions and torques (or currents) only,
    then `validate --model` on a held-out log with no other option: held-out joint torques
    within 2 % (the 5 Hz low-pass smears the reflected Coulomb steps, about 3 N m at the
    joints; with exact velocities the same pipeline gives 1.14 %), against 13 % without the
    identified friction."""
    from dynid.cli.__main__ import main

    robot, model, data = _ur5()
    path = robot_data_urdf("ur_description/urdf/ur5_robot.urdf")
    train, _ = _motor_log(model, data, seed=1, currents=currents)
    held, _ = _motor_log(model, data, seed=2, currents=currents)
    _write_positions_only_csv(tmp_path / "log.csv", train)
    _write_positions_only_csv(tmp_path / "held.csv", held)
    coupling = ", ".join(f"[{m}, {j}, {v}]" for m, j, v in COUPLING)
    extra = f'effort = "current"\ntorque_constant = {KT.tolist()}\n' if currents else ""
    (tmp_path / "drive.toml").write_text(
        f'schema = "dynid-drive/1"\nside = "motor"\ngear_ratio = {GEAR.tolist()}\n'
        f"coupling = [{coupling}]\noffset = {OFFSET.tolist()}\n{extra}"
    )
    args = ["identify", "--robot", path, "--base", "base_link", "--tip", "tool0"]
    args += ["--drive", str(tmp_path / "drive.toml"), "--data", str(tmp_path / "log.csv")]
    assert main([*args, "--out", str(tmp_path / "r"), "--no-figures", "-q"]) == 0
    assert (
        main(
            [
                "validate",
                "--model",
                str(tmp_path / "r" / "identification.json"),
                "--data",
                str(tmp_path / "held.csv"),
                "--out",
                str(tmp_path / "v"),
                "-q",
                "--no-figures",
            ]
        )
        == 0
    )
    import json

    doc = json.loads((tmp_path / "v" / "validation.json").read_text())
    assert doc["relative_error_percent"] < 2.0
    assert doc["without_friction"]["relative_error_percent"] > 10.0
    m = json.loads((tmp_path / "r" / "identification.json").read_text())
    assert m["drive"]["side"] == "motor" and "Ia6" in m["base"]["std_labels"]


def test_static_route_identifies_rotor_inertia_of_the_controller_model():
    """The controller's M with rotor inertia diag(Ia) (a direct drive, K = 1): with the drive
    the held-out M matches to round-off and Ia2..Ia7 are recovered; without it the links
    cannot absorb the rotors (M off by more than 1e-3 relative)."""
    from dynid.identification.static import identify_static
    from dynid.simulation.controller import SimulatedController, acquire_static
    from dynid.simulation.unmodelled import UnmodelledEffects

    robot = dynid.panda()
    ia = np.array([0.05, 0.04, 0.06, 0.03, 0.02, 0.025, 0.01])
    fx = UnmodelledEffects(rotor_inertia=ia, torque_offset=np.zeros(7))
    ctrl = SimulatedController(robot, effects=fx)
    data = acquire_static(ctrl, 300, np.random.default_rng(4))
    held = acquire_static(ctrl, 50, np.random.default_rng(5))
    m = identify_static(robot, data, drive=Drive.identity(7))
    err = np.abs(m.mass_matrix(held.q) - held.M).max() / np.abs(held.M).max()
    assert err < 1e-9
    assert any(e.startswith("J1zz") and "Ia1" in e for e in m.base.expressions)
    # the rotors of joints 3..7 are base parameters of their own (joint 2's regroups with
    # J2zz): 43 + 5 base parameters, each recovered
    assert m.base.rank == 48
    for k in range(2, 7):
        b = m.base.expressions.index(f"Ia{k + 1}")
        assert abs(m.fit.beta[b] - ia[k]) < 1e-9
    plain = identify_static(robot, data)
    err0 = np.abs(plain.mass_matrix(held.q) - held.M).max() / np.abs(held.M).max()
    assert err0 > 1e-3


def test_noisy_motor_torques_give_errors_of_the_order_of_their_std():
    """Motor-torque noise of 0.01 N m: the base parameters (rotors included) and the motor
    friction deviate from the truth by about one reported standard deviation."""
    robot, model, data = _ur5()
    t, q, dq, ddq = _trajectory(6, 2, duration=12.0, fs=500.0)
    tau = _joint_torques(model, data, q, dq, ddq)
    K = Drive.from_gears(GEAR, COUPLING).transmission
    noise = np.random.default_rng(0).normal(0.0, 0.01, tau.shape)
    log = TorqueLog(
        t, (q - OFFSET) @ K.T, dq @ K.T, np.linalg.solve(K.T, tau.T).T + noise, ddq @ K.T
    )
    m = _exact_fit(robot, log, _drive())
    beta = m.base.beta_from_phi(np.concatenate([robot.phi.reshape(-1), IA]))
    f_true = np.stack([FV, FC, FO], axis=1).reshape(-1)
    r = m.base.rank
    z = np.concatenate(
        [(m.fit.beta - beta) / m.fit.std, (m.joint_fit.beta[r:] - f_true) / m.joint_fit.std[r:]]
    )
    assert 0.4 < np.sqrt(np.mean(z**2)) < 2.0
    assert np.abs(z).max() < 4.5


@pytest.mark.slow
def test_cli_consistent_fit_with_a_coupled_drive_keeps_the_rotors_out_of_the_links(tmp_path):
    """simulate (motor side, known rotors) -> identify --consistent --drive (rotors
    identified, >= 0) -> feasible.json and robot.toml keep the drive with the identified
    rotor inertias (within 5 % of the truth; 0.05 N m of noise), robot.xml carries them as
    armature, and validate --params predicts a held-out log as well as the unconstrained
    fit. The prior weight is given: 1e6, the weight the automatic search picks on this log
    (the top of its range); the search itself is test_heldout_consistent.py's subject."""
    import json

    from dynid.cli.__main__ import main

    path = robot_data_urdf("ur_description/urdf/ur5_robot.urdf")
    R = ["--robot", path, "--base", "base_link", "--tip", "tool0"]
    coupling = ", ".join(f"[{m}, {j}, {v}]" for m, j, v in COUPLING)
    text = (
        f'schema = "dynid-drive/1"\nside = "motor"\ngear_ratio = {GEAR.tolist()}\n'
        f"coupling = [{coupling}]\noffset = {OFFSET.tolist()}\n"
    )
    (tmp_path / "drive.toml").write_text(text)
    (tmp_path / "truth.toml").write_text(text + f"rotor_inertia = {IA.tolist()}\n")
    sim = [*R, "--drive", str(tmp_path / "truth.toml"), "--trajectory", "fourier"]
    sim += ["--duration", "10", "--rate", "250", "--noise", "0.05", "-q"]
    for seed, name in ((1, "log.csv"), (2, "held.csv")):
        out = ["--seed", str(seed), "--out", str(tmp_path / name)]
        assert main(["simulate", *sim, *out]) == 0
    args = ["identify", *R, "--drive", str(tmp_path / "drive.toml"), "--consistent"]
    args += ["--prior", path, "--prior-weight", "1e6", "--data", str(tmp_path / "log.csv")]
    assert main([*args, "--out", str(tmp_path / "c"), "-q", "--no-figures"]) == 0
    feas = json.loads((tmp_path / "c" / "feasible.json").read_text())
    ia = np.array(feas["drive"]["rotor_inertia"])
    np.testing.assert_allclose(ia, IA, rtol=0.05)
    assert load_drive(tmp_path / "c" / "robot.toml", 6).rotor_inertia == pytest.approx(ia)
    mj = pytest.importorskip("mujoco")
    model = mj.MjModel.from_xml_path(str(tmp_path / "c" / "robot.xml"))
    K = Drive.from_gears(GEAR, COUPLING).transmission
    np.testing.assert_allclose(model.dof_armature, np.diag(K.T @ np.diag(ia) @ K), rtol=1e-12)
    # export from feasible.json keeps the drive's armature and the friction identified
    # with the links (reflected from the motors), as identify --consistent wrote it
    xml = tmp_path / "e.xml"
    assert (
        main(["export", "--params", str(tmp_path / "c" / "feasible.json"), "--out", str(xml)]) == 0
    )
    exported = mj.MjModel.from_xml_path(str(xml))
    np.testing.assert_allclose(exported.dof_armature, model.dof_armature, rtol=1e-12)
    np.testing.assert_allclose(exported.dof_damping, model.dof_damping, rtol=1e-12)
    for src, out in (("--params", "c/feasible.json"), ("--model", "c/identification.json")):
        v = ["validate", src, str(tmp_path / out), "--data", str(tmp_path / "held.csv")]
        assert main([*v, "--out", str(tmp_path / out.replace("/", "_")), "-q", "--no-figures"]) == 0
    err = {
        k: json.loads((tmp_path / f"c_{k}.json" / "validation.json").read_text())[
            "relative_error_percent"
        ]
        for k in ("feasible", "identification")
    }
    assert err["feasible"] < 1.05 * err["identification"] + 0.05


def test_links_only_and_the_retrievals_of_a_model_with_rotors():
    """links_only() drops the rotors that are base parameters of their own (M of the links
    plus those rotors is the full model's M); the penalty method refuses a model with rotors;
    the convex retrieval identifies them (>= 0) next to the links."""
    from dynid.exceptions import ModelError
    from dynid.feasibility.convex import retrieve_sdp
    from dynid.feasibility.penalty import retrieve
    from dynid.identification.static import identify_static
    from dynid.simulation.controller import SimulatedController, acquire_static
    from dynid.simulation.unmodelled import UnmodelledEffects

    robot = dynid.panda()
    ia = np.array([0.05, 0.04, 0.06, 0.03, 0.02, 0.025, 0.01])
    ctrl = SimulatedController(
        robot, effects=UnmodelledEffects(rotor_inertia=ia, torque_offset=np.zeros(7))
    )
    data = acquire_static(ctrl, 200, np.random.default_rng(6))
    drive = Drive.identity(7)
    m = identify_static(robot, data, drive=drive)
    links = m.links_only()
    assert links.base.rank == 43 and links.base.n_std == 70 and links.drive is None
    assert not any("Ia" in e for e in links.base.expressions)
    q = data.q[:5]
    rotors = drive.rotor_mass_matrix(m.rotor_inertia)
    np.testing.assert_allclose(links.mass_matrix(q) + rotors, m.mass_matrix(q), atol=1e-12)
    with pytest.raises(ModelError, match="--method sdp"):
        retrieve(m, workers=1)
    res = retrieve_sdp(m, prior=robot)
    assert res.feasible and res.drive is not None
    np.testing.assert_allclose(res.rotor_inertia[2:], ia[2:], rtol=1e-4)
    np.testing.assert_allclose(res.drive.rotor_inertia, res.rotor_inertia)
    assert np.all(res.rotor_inertia >= 0)


def test_friction_fitted_per_motor_through_the_coupled_drive(tmp_path):
    """The residual of an identified model on a held-out motor-side log, mapped to the
    motors (K^-T r at K dq), gives back the motors' own viscous, Coulomb and offset friction;
    friction.json keeps the drive and loads back to the same joint torques."""
    from dynid.friction.fit import fit_friction_through, friction_residual
    from dynid.friction.model import DriveFriction
    from dynid.identification.prepare import Preprocessing
    from dynid.io.friction_json import load_friction_json, save_friction_json

    robot, model, data = _ur5()
    train, _ = _motor_log(model, data, seed=1)
    held, _ = _motor_log(model, data, seed=2)
    m = _exact_fit(robot, train, _drive())
    unfiltered = Preprocessing(cutoff_hz=None, filter_tau=False)
    res = friction_residual(m, held, unfiltered)  # read through the model's drive
    fit = fit_friction_through(res, m.drive, "classical")
    assert isinstance(fit.friction, DriveFriction)
    law = fit.friction
    np.testing.assert_allclose(law.fv, FV, rtol=1e-6)
    np.testing.assert_allclose(law.fc, FC, rtol=1e-6)
    np.testing.assert_allclose(law.fo, FO, rtol=1e-5, atol=1e-9)
    assert np.all(fit.rms_after < 1e-6 * fit.rms_before)
    path = save_friction_json(tmp_path / "friction.json", fit)
    back = load_friction_json(path)
    assert isinstance(back, DriveFriction)
    h = dynid.identification.log.joint_side_log(held, _drive())
    np.testing.assert_allclose(back.torques(h.dq), fit.friction.torques(h.dq), rtol=1e-14)


def test_validate_reads_a_log_as_the_model_was_identified(tmp_path):
    """identify records --columns/--units (and the drive); validate --model reuses them on
    a log of the same kind without being told, and refuses other ones."""
    from dynid.cli.__main__ import main

    robot, model, data = _ur5()
    path = robot_data_urdf("ur_description/urdf/ur5_robot.urdf")
    for seed, name in ((1, "log.csv"), (2, "held.csv")):
        log, _ = _motor_log(model, data, seed=seed)
        head = ["time"] + [f"pos_{j}" for j in range(1, 7)] + [f"eff_{j}" for j in range(1, 7)]
        table = np.column_stack([log.t * 1e3, log.q, log.tau * 1e3])  # ms and mN m
        np.savetxt(tmp_path / name, table, delimiter=",", header=",".join(head), comments="")
    coupling = ", ".join(f"[{m}, {j}, {v}]" for m, j, v in COUPLING)
    (tmp_path / "drive.toml").write_text(
        f'schema = "dynid-drive/1"\nside = "motor"\ngear_ratio = {GEAR.tolist()}\n'
        f"coupling = [{coupling}]\noffset = {OFFSET.tolist()}\n"
    )
    cols = ["--columns", "t=time,q=pos_{i},tau=eff_{i}", "--units", "t=ms,tau=mNm"]
    args = ["identify", "--robot", path, "--base", "base_link", "--tip", "tool0", *cols]
    args += ["--drive", str(tmp_path / "drive.toml"), "--data", str(tmp_path / "log.csv")]
    assert main([*args, "--out", str(tmp_path / "r"), "--no-figures", "-q"]) == 0
    val = ["validate", "--model", str(tmp_path / "r" / "identification.json")]
    val += ["--data", str(tmp_path / "held.csv"), "--no-figures", "-q"]
    assert main([*val, "--out", str(tmp_path / "v")]) == 0
    import json

    doc = json.loads((tmp_path / "v" / "validation.json").read_text())
    assert doc["relative_error_percent"] < 2.0
    assert main([*val, "--out", str(tmp_path / "v2"), "--units", "t=s,tau=mNm"]) == 2


def test_urdf_export_writes_identified_friction_as_dynamics(tmp_path):
    """Classical friction reflected from the motors of a diagonal drive: the URDF chain holds
    <dynamics damping="k^2 fv" friction="|k| fc"> per joint."""
    import xml.etree.ElementTree as ET

    from dynid.friction.model import ClassicalFriction, DriveFriction
    from dynid.io.export import save_robot

    robot, _, _ = _ur5()
    drive = Drive.from_gears(GEAR, side="motor")
    fr = DriveFriction(ClassicalFriction(FV, FC, FO), drive)
    path = save_robot(tmp_path / "arm.urdf", robot, friction=fr)
    dyn = [j.find("dynamics") for j in ET.parse(path).getroot().iter("joint")]
    dyn = [d for d in dyn if d is not None]
    assert len(dyn) == 6
    np.testing.assert_allclose([float(d.get("damping")) for d in dyn], GEAR**2 * FV, rtol=1e-14)
    np.testing.assert_allclose([float(d.get("friction")) for d in dyn], GEAR * FC, rtol=1e-14)


@pytest.mark.parametrize(
    ("ratio", "ia"),
    [(1.0, 1e-2), (10.0, 1e-3), (50.0, 1e-4), (100.0, 3e-5), (150.0, 1e-5), (200.0, 1e-7)],
)
def test_geared_coupled_arm_base_is_complete_for_every_gear_ratio(ratio, ia):
    """Gear ratios ``ratio * (1, 1, 1, 0.8, 0.8, 0.5)``, motor 6 on joint 5 too, rotor
    inertias ``ia`` identified, friction at the motors, exact motor-side log: the base is
    the structural one of ratio 1 (rotor columns 1 to 40,000 times larger do not push the
    link columns below the rank cut) and held-out joint torques (Pinocchio's RNEA plus the
    drive terms) are predicted to 1e-6 relative."""
    robot, model, data = _ur5()
    gear = ratio * np.array([1.0, 1.0, 1.0, 0.8, 0.8, 0.5])
    drive = Drive.from_gears(gear, [(6, 5, 0.3 * ratio)], side="motor")
    K = drive.transmission
    rotor = ia * np.linspace(1.5, 0.5, 6)

    def log(seed: int) -> tuple[TorqueLog, np.ndarray]:
        _, q, dq, ddq = _trajectory(6, seed, duration=4.0)
        tau = np.array([pin.rnea(model, data, *s) for s in zip(q, dq, ddq, strict=True)])
        dqm, ddqm = dq @ K.T, ddq @ K.T
        tau += (rotor * ddqm) @ K + (FV * dqm + FC * np.sign(dqm) + FO) @ K
        t = np.arange(q.shape[0]) / 250.0
        return TorqueLog(t, q @ K.T, dqm, np.linalg.solve(K.T, tau.T).T, ddqm), tau

    (train, _), (held, tau_held) = log(1), log(2)
    m = _exact_fit(robot, train, drive)
    one = Drive.from_gears(np.ones(6), [(6, 5, 0.6)], side="motor")
    ref = dynid.base_parameters(robot, kind="torque", terms=(RotorInertia(one),))
    assert m.base.rank == ref.rank == 40
    np.testing.assert_array_equal(m.base.independent, ref.independent)
    h = dynid.identification.log.joint_side_log(held, drive)
    tau_hat = dynid.model_torques(m, h.q, h.dq, h.ddq)
    assert np.linalg.norm(tau_hat - tau_held) / np.linalg.norm(tau_held) < 1e-6


def test_geared_arm_with_default_filtering_predicts_held_out_torques_to_1e_6(monkeypatch):
    """Gear ratios 200 x (1, 1, 1, 0.8, 0.8, 0.5) and a coupled wrist, friction at the
    motors, an exact 500 Hz motor-side log identified with the default preparation of a
    noisy one (the cut-off read from the motion, given: an exact log is otherwise fitted
    unfiltered; 1 in k samples kept): held-out joint torques to 1e-6. The Coulomb columns
    computed from states interpolated between the kept samples (a log too long to hold
    every sample's states) put the motors' reversals off the torques' steps: 3.8e-5."""
    import dynid.identification.prepared_log as prepared_log
    from dynid.identification.rate import cutoff_from_motion

    robot, model, data = _ur5()
    gear = 200.0 * np.array([1.0, 1.0, 1.0, 0.8, 0.8, 0.5])
    drive = Drive.from_gears(gear, [(6, 5, 60.0)], side="motor")
    K = drive.transmission
    rotor = 1e-5 * np.linspace(1.5, 0.5, 6)

    def log(seed: int) -> tuple[TorqueLog, np.ndarray]:
        t, q, dq, ddq = _trajectory(6, seed, duration=6.0, fs=500.0)
        tau = np.array([pin.rnea(model, data, *s) for s in zip(q, dq, ddq, strict=True)])
        dqm, ddqm = dq @ K.T, ddq @ K.T
        tau += (rotor * ddqm) @ K + (FV * dqm + FC * np.sign(dqm) + FO) @ K
        return TorqueLog(t, q @ K.T, dqm, np.linalg.solve(K.T, tau.T).T, ddqm), tau

    (train, _), (held, tau_held) = log(1), log(2)
    h = dynid.identification.log.joint_side_log(held, drive)
    j = dynid.identification.log.joint_side_log(train, drive)
    cutoff = cutoff_from_motion(j.q, j.dq, 500.0)

    def error() -> float:
        m = identify_from_log(
            robot, train, drive=drive, cutoff_hz=cutoff, structure="classical", estimator="ols"
        )
        own = dynid.friction.validation.own_friction(m)
        tau_hat = m.torques(h.q, h.dq, h.ddq) + own.torques(h.dq)
        return float(np.linalg.norm(tau_hat - tau_held) / np.linalg.norm(tau_held))

    assert error() < 1e-6
    monkeypatch.setattr(prepared_log, "MAX_FINE_BYTES", 0)
    assert error() > 1e-5


def test_gear_ratio_1_in_a_drive_file_identifies_a_joint_side_armature(tmp_path):
    """``gear_ratio = 1`` (the documented default, one number for every joint) with
    ``rotor_inertia = "identify"``: a direct drive whose rotor term is a joint-side
    armature ``I_a ddq``; on an exact joint-side UR5 log with armature and friction
    (Pinocchio's RNEA plus both, written out), held-out torques to 1e-6 relative."""
    f = tmp_path / "armature.toml"
    f.write_text('schema = "dynid-drive/1"\ngear_ratio = 1\nrotor_inertia = "identify"\n')
    drive = load_drive(f, 6)
    np.testing.assert_array_equal(drive.transmission, np.eye(6))
    assert drive.identifies_rotor_inertia and drive.friction_place == "joint"
    np.testing.assert_array_equal(Drive.from_gears(1, n=6).transmission, np.eye(6))
    robot, model, data = _ur5()
    armature = np.array([0.3, 0.3, 0.2, 0.05, 0.05, 0.04])  # [kg m^2]

    def log(seed: int) -> tuple[TorqueLog, np.ndarray]:
        _, q, dq, ddq = _trajectory(6, seed, duration=4.0)
        tau = np.array([pin.rnea(model, data, *s) for s in zip(q, dq, ddq, strict=True)])
        tau += armature * ddq + 2.0 * dq + 3.0 * np.sign(dq)
        return TorqueLog(np.arange(q.shape[0]) / 250.0, q, dq, tau, ddq), tau

    (train, _), (held, tau_held) = log(1), log(2)
    m = _exact_fit(robot, train, drive)
    assert "Ia6" in m.base.std_labels
    tau_hat = m.torques(held.q, held.dq, held.ddq)
    tau_hat = tau_hat + dynid.friction.validation.own_friction(m).torques(held.dq)
    assert np.linalg.norm(tau_hat - tau_held) / np.linalg.norm(tau_held) < 1e-6


def test_validate_checks_the_joint_limits_of_a_motor_side_log_at_the_joints(tmp_path):
    """A motor-side log holds motor angles (the gear ratio times the joint's): validating
    the model identified through the drive checks the limits on the joint-side positions,
    so the log raises no "far outside the limits" warning, and the held-out torques come
    back to round-off."""
    from dynid.workflows.validate import ValidateOptions, validate_files

    robot, model, data = _ur5()
    train, _ = _motor_log(model, data, seed=1)
    held, _ = _motor_log(model, data, seed=2)
    assert np.max(np.abs(held.q)) > 10 * np.max(np.abs(robot.q_max))  # motor angles
    m = _exact_fit(robot, train, _drive())
    path = tmp_path / "held.csv"
    save_torque_log(path, held)
    with warnings.catch_warnings():
        warnings.simplefilter("error", DynidWarning)
        res = validate_files(m, path, ValidateOptions(friction="own", cutoff_hz=20.0))
    assert res.validation.errors.relative_error_percent < 1.0


def test_a_robots_own_friction_acts_where_its_drive_puts_it_in_every_comparison():
    """Simulation puts a robot's own friction, given per joint, at the motors when its
    drive's friction acts there (``K^T f(K dq)``); validating that robot on its own log, and
    its observer at rest of contacts, must place it the same: the torques come back exactly
    (before, validation added the law at the joints and the error was that of the friction)."""
    from dynid.friction.model import ClassicalFriction
    from dynid.friction.validation import own_friction, validate_torques
    from dynid.observer.model import from_robot
    from dynid.simulation.measurement import SensorNoise, sample_times, simulate_measurement
    from dynid.simulation.trajectories import centered_start, sinusoid_trajectory

    robot, _, _ = _ur5()
    n = robot.n
    fr = ClassicalFriction(np.full(n, 0.02), np.full(n, 0.05), np.zeros(n))
    robot = robot.with_friction(fr)
    drive = Drive.from_gears(GEAR, COUPLING, side="motor", friction_at="motor")
    t = sample_times(3.0, 250.0)
    periods = np.array([3.1, 2.3, 2.9, 1.7, 2.1, 1.3])
    A = np.full(n, 0.4)
    traj = sinusoid_trajectory(t, centered_start(robot, A, periods), A, periods)
    log = simulate_measurement(
        robot,
        traj,
        rng=np.random.default_rng(0),
        noise=SensorNoise.none(),
        with_ddq=True,
        drive=drive,
    )
    v = validate_torques(
        robot, log, friction=own_friction(robot, drive), cutoff_hz=None, drive=drive
    )
    assert v.with_friction is not None
    assert v.with_friction.relative_error_percent < 1e-8
    # the law at the joints instead differs by the motors' friction seen through the gears
    at_joints = validate_torques(robot, log, friction=fr, cutoff_hz=None, drive=None)
    assert at_joints.errors.relative_error_percent > 1.0
    obs = from_robot(robot, drive=drive)
    assert obs.friction is not None and obs.friction.drive is drive


def test_a_robots_own_friction_is_placed_in_one_place_as_written_out():
    """``own_friction(robot, drive)`` is the robot's per-joint law acting where the drive
    puts it, against the torques written out here with ``K`` built from the gears and the
    coupling: ``K^T (fv dqm + fc sign(dqm) + fo)``, ``dqm = K dq``, with friction at the
    motors; ``fv dq + fc sign(dq) + fo`` with it at the joints or without a drive. The
    observer and payload identification read that same friction."""
    from dynid.feasibility.payload_arm import arm_model
    from dynid.friction.model import ClassicalFriction
    from dynid.friction.validation import own_friction
    from dynid.observer.model import from_robot

    robot, _, _ = _ur5()
    robot = robot.with_friction(ClassicalFriction(FV, FC, FO))
    K = np.diag(GEAR)
    K[5, 4] = 30.0  # qm6 = 51 q6 + 30 q5
    dq = np.random.default_rng(3).uniform(-1.0, 1.0, (40, robot.n))
    dqm = dq @ K.T
    at_motors = (FV * dqm + FC * np.sign(dqm) + FO) @ K
    at_joints = FV * dq + FC * np.sign(dq) + FO
    motor = _drive(friction_at="motor", rotor_inertia=IA)
    joint = _drive(friction_at="joint", rotor_inertia=IA)
    for drive, want in ((motor, at_motors), (joint, at_joints), (None, at_joints)):
        own = own_friction(robot, drive)
        assert own is not None
        np.testing.assert_allclose(own.torques(dq), want, rtol=1e-12, atol=1e-15)
        obs = from_robot(robot, drive=drive).friction
        assert obs is not None
        np.testing.assert_allclose(obs.torques(dq), want, rtol=1e-12, atol=1e-15)
        arm = arm_model(robot, drive=drive).friction
        assert arm is not None
        np.testing.assert_allclose(arm.torques(dq), want, rtol=1e-12, atol=1e-15)
    # the robot description holds the law per joint: without a drive it is returned as held
    assert own_friction(robot) is robot.friction


def test_a_simulated_current_log_says_its_unit(tmp_path):
    """Regression: simulate with a drive whose effort is "current" wrote "tau [N m]" over
    columns of currents; it writes "tau [A]", and the columns times the torque constants
    are the joint torques of the same simulation written without the drive."""
    from dynid.cli.__main__ import main
    from dynid.io.torque_log import load_torque_log

    kt = [8.0, 8.0, 6.0, 4.0, 2.0, 2.0, 1.0]
    (tmp_path / "cur.toml").write_text(
        f'schema = "dynid-drive/1"\nside = "joint"\neffort = "current"\ntorque_constant = {kt}\n'
    )
    sim = ["simulate", "--robot", "panda", "--trajectory", "fourier", "--duration", "1"]
    sim += ["--rate", "200", "--noise", "0", "--q-noise", "0", "--dq-noise", "0", "-q"]
    cur, tau = tmp_path / "cur.csv", tmp_path / "tau.csv"
    assert main([*sim, "--drive", str(tmp_path / "cur.toml"), "--out", str(cur)]) == 0
    assert main([*sim, "--out", str(tau)]) == 0
    assert "tau [A]" in cur.read_text().splitlines()[0]
    assert "tau [N m]" in tau.read_text().splitlines()[0]
    np.testing.assert_allclose(
        load_torque_log(cur).tau * kt, load_torque_log(tau).tau, rtol=1e-12, atol=1e-12
    )
