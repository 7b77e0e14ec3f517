"""The one friction type: every law through ``Friction`` as through its registry module, at
the joints and through a coupled drive; the constructors; a robot holding any law; exports."""

from __future__ import annotations

import importlib
import json
import warnings

import numpy as np
import pytest

import dynid
from dynid.exceptions import DynidWarning, ShapeError, WrongTypeError
from dynid.friction.laws import LAWS
from dynid.friction.model import (
    ClassicalFriction,
    DriveFriction,
    Friction,
    SigmoidFriction,
    robot_friction,
)
from dynid.model.drive import Drive

#: Parameters (2 joints) per law, within each law's bounds.
PARAMS = {
    "none": np.zeros((2, 0)),
    "classical": np.array([[0.1, 0.3, 0.02], [0.2, 0.5, -0.04]]),
    "smooth": np.array([[0.1, 0.3, 0.02], [0.2, 0.5, -0.04]]),
    "quadratic": np.array([[0.1, 0.05, 0.3, 0.02], [0.2, 0.02, 0.5, -0.04]]),
    "asymmetric": np.array([[0.1, 0.15, 0.3, 0.25], [0.2, 0.1, 0.5, 0.6]]),
    "stribeck": np.array([[0.1, 0.3, 0.5, 0.05, 0.02], [0.2, 0.5, 0.6, 0.1, -0.04]]),
    "smooth_stribeck": np.array([[0.1, 0.3, 0.5, 0.05, 0.02], [0.2, 0.5, 0.6, 0.1, -0.04]]),
    "sigmoid": np.array([[0.8, 20.0, 0.01], [1.2, 30.0, -0.02]]),
}
BAND = np.array([0.004, 0.006])
#: A coupled wrist: motor 2 turns with joints 1 and 2.
K = np.array([[50.0, 0.0], [-30.0, 40.0]])


def _velocities():
    rng = np.random.default_rng(4)
    return np.concatenate([rng.normal(0, 0.5, (30, 2)), [[0.0, 0.0], [0.003, -0.005]]])


def test_the_table_covers_every_law():
    assert set(PARAMS) == set(LAWS)


@pytest.mark.parametrize("name", sorted(LAWS))
def test_each_law_evaluates_as_its_registry_module_at_the_joints(name):
    law, P, dq = LAWS[name], PARAMS[name], _velocities()
    band = BAND if law.standstill else np.zeros(2)
    fr = law.model(P, BAND)
    assert isinstance(fr, Friction) and fr.kind == name and fr.drive is None
    np.testing.assert_array_equal(fr.band, band)
    np.testing.assert_allclose(fr.torques(dq), law.torques(dq, P, band), rtol=0, atol=1e-15)
    module = importlib.import_module(f"dynid.friction.laws.{name}")
    if hasattr(module, "columns"):  # a linear law: its regressor times its parameters
        C = module.columns(dq, band)
        np.testing.assert_allclose(fr.torques(dq), np.einsum("sjk,jk->sj", C, P), atol=1e-15)
    # a single sample: (n,) in, (n,) out
    np.testing.assert_allclose(fr.torques(dq[0]), law.torques(dq[:1], P, band)[0], atol=1e-15)


@pytest.mark.parametrize("name", sorted(LAWS))
def test_each_law_through_a_coupled_drive_is_kt_f_of_k_dq(name):
    """At the motors: ``tau_f = K^T f(K dq)``, the sum written out motor by motor."""
    law, P, dq = LAWS[name], PARAMS[name], _velocities()
    band = BAND if law.standstill else np.zeros(2)
    fr = law.model(P, BAND, Drive(K, np.zeros(2)))
    assert fr.at_motors
    expect = np.zeros_like(dq)
    for s in range(dq.shape[0]):
        v = np.array([K[m] @ dq[s] for m in range(2)])  # motor velocities
        f = law.torques(v[None, :], P, band)[0]  # friction torque per motor
        expect[s] = [sum(K[m, j] * f[m] for m in range(2)) for j in range(2)]
    np.testing.assert_allclose(fr.torques(dq), expect, rtol=1e-13, atol=1e-14)
    # the same law with the drive's friction at the joints is the law at the joints
    at_joints = fr.at(Drive(K, np.zeros(2), friction_at="joint"))
    np.testing.assert_allclose(at_joints.torques(dq), law.torques(dq, P, band), atol=1e-15)


def test_the_constructors_are_the_closed_forms_of_gaz_et_al():
    """Eq. 24 and eq. 25 of Gaz et al. 2019 written out."""
    dq = _velocities()
    fv, fc, fo = PARAMS["classical"].T
    classical = ClassicalFriction(fv, fc, fo, BAND)
    s = np.where(np.abs(dq) > BAND, np.sign(dq), 0.0)
    np.testing.assert_allclose(classical.torques(dq), fv * dq + fc * s + fo, atol=1e-15)
    p1, p2, p3 = PARAMS["sigmoid"].T
    sigmoid = SigmoidFriction(p1, p2, p3)
    expect = p1 / (1 + np.exp(-p2 * (dq + p3))) - p1 / (1 + np.exp(-p2 * p3))
    np.testing.assert_allclose(sigmoid.torques(dq), expect, rtol=1e-13, atol=1e-15)
    # parameters by name, the constructors answer isinstance as the classes did
    np.testing.assert_array_equal(classical.fc, fc)
    np.testing.assert_array_equal(sigmoid.phi2, p2)
    assert isinstance(classical, ClassicalFriction) and not isinstance(classical, SigmoidFriction)
    coupled = DriveFriction(classical, Drive(K, np.zeros(2)))
    assert isinstance(coupled, DriveFriction) and not isinstance(classical, DriveFriction)
    with pytest.raises(AttributeError, match="no attribute 'phi1'"):
        _ = classical.phi1


def _two_joints() -> dynid.Robot:
    return dynid.Robot.from_mdh(
        a=[0, 0.3], d=[0.3, 0], alpha=[0, np.pi / 2], theta=[0, 0], mass=[1.0, 1.0]
    )


def test_a_robot_holds_any_law():
    robot = _two_joints()
    classical = ClassicalFriction.from_array(PARAMS["classical"], BAND)
    r = robot.with_friction(classical)
    assert r.friction is classical and robot_friction(r) is classical
    # a variant keeps it; the sigmoid is held the same way, as the one type
    assert r.with_gravity([0, 0, -1.0]).friction is classical
    sigmoid = SigmoidFriction.from_array(PARAMS["sigmoid"])
    s = r.with_friction(sigmoid)
    assert s.friction is sigmoid
    assert r.with_friction(None).friction is None
    # a bare array names no law: refused, with the constructor to call
    with pytest.raises(WrongTypeError, match=r"not an array of shape \(2, 3\).*from_array"):
        r.replace(friction=PARAMS["sigmoid"])
    with pytest.raises(WrongTypeError, match="not an array"):
        robot.with_friction(PARAMS["sigmoid"])
    with pytest.raises(ShapeError, match="friction has 7 joints; robot has 2"):
        robot.with_friction(dynid.panda().friction)


@pytest.mark.parametrize("name", sorted(LAWS))
def test_a_robot_with_any_law_pickles(name):
    """Robots go to worker processes: each law, with its drive, pickles and evaluates the same."""
    import pickle

    fr = LAWS[name].model(PARAMS[name], BAND, Drive(K, np.zeros(2)))
    back = pickle.loads(pickle.dumps(_two_joints().with_friction(fr))).friction
    dq = _velocities()
    np.testing.assert_array_equal(back.torques(dq), fr.torques(dq))


def test_a_simulation_applies_the_robots_own_law():
    """``friction="robot"`` with a classical law on the robot: tau = rnea + eq. 24."""
    from dynid.simulation.measurement import SensorNoise, simulate_measurement
    from dynid.simulation.trajectories import Trajectory

    robot = _two_joints()
    classical = ClassicalFriction.from_array(PARAMS["classical"])
    rng = np.random.default_rng(5)
    t = np.arange(20) * 1e-2
    q, dq, ddq = rng.normal(0, 0.5, (3, 20, 2))
    log = simulate_measurement(
        robot.with_friction(classical),
        Trajectory(t, q, dq, ddq),
        rng=rng,
        noise=SensorNoise.none(),
    )
    fv, fc, fo = PARAMS["classical"].T
    expect = dynid.rnea(robot, q, dq, ddq) + fv * dq + fc * np.sign(dq) + fo
    np.testing.assert_allclose(log.tau, expect, rtol=1e-12, atol=1e-12)


def _dynamics(path):
    """``(damping, friction)`` of each joint's ``<dynamics>`` in a URDF file: (n, 2)."""
    import xml.etree.ElementTree as ET

    dyn = [j.find("dynamics") for j in ET.parse(path).getroot().iter("joint")]
    return np.array(
        [[float(d.get("damping")), float(d.get("friction"))] for d in dyn if d is not None]
    )


def test_urdf_writes_any_law_and_says_in_one_line_what_it_drops(tmp_path):
    """The asymmetric law: URDF's damping and friction are its means; the asymmetry and the
    offset are named in one warning."""
    from dynid.io.export import save_robot

    robot = _two_joints()
    fr = LAWS["asymmetric"].model(PARAMS["asymmetric"])
    with pytest.warns(DynidWarning) as record:
        save_robot(tmp_path / "r.urdf", robot, friction=fr)
    lines = [str(w.message) for w in record if issubclass(w.category, DynidWarning)]
    assert len(lines) == 1 and "asymmetry" in lines[0] and "offset" in lines[0]
    P = PARAMS["asymmetric"]
    np.testing.assert_allclose(_dynamics(tmp_path / "r.urdf"), [
        [(P[j, 0] + P[j, 1]) / 2, (P[j, 2] + P[j, 3]) / 2] for j in range(2)
    ], rtol=1e-15)  # fmt: skip
    # the robot's own classical law is written with friction=True, without a warning
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        plain = ClassicalFriction(P[:, 0], P[:, 2], np.zeros(2))
        save_robot(tmp_path / "own.urdf", robot.with_friction(plain), friction=True)
    np.testing.assert_allclose(_dynamics(tmp_path / "own.urdf"), P[:, [0, 2]], rtol=1e-15)


def test_a_robot_description_holds_another_law_as_a_friction_table(tmp_path):
    """Another law than the sigmoid is the description's ``[friction]`` table, its band and
    (at the motors) its drive with it; it reads back to the same torques."""
    from dynid.io.robot.toml import robot_from_toml_string, toml_from_robot

    dq = _velocities()
    for fr in (
        LAWS["classical"].model(PARAMS["classical"], BAND),
        LAWS["classical"].model(PARAMS["classical"], BAND, Drive(K, np.zeros(2))),
    ):
        with warnings.catch_warnings():
            warnings.simplefilter("error")
            back = robot_from_toml_string(toml_from_robot(_two_joints().with_friction(fr)))
        np.testing.assert_allclose(back.friction.torques(dq), fr.torques(dq), rtol=0, atol=1e-15)


def test_friction_json_of_the_sigmoid_has_no_band_and_reads_back(tmp_path):
    """The file format is unchanged: the sigmoid has no standstill band, the classical law
    keeps its band, a law per motor its drive."""
    from dynid.io.friction_json import load_friction_json, save_friction_json

    sig = SigmoidFriction.from_array(PARAMS["sigmoid"])
    doc = json.loads(save_friction_json(tmp_path / "s.json", sig).read_text())
    assert "standstill_band" not in doc["joints"][0] and doc["drive"] is None
    cl = LAWS["classical"].model(PARAMS["classical"], BAND, Drive(K, np.zeros(2)))
    back = load_friction_json(save_friction_json(tmp_path / "c.json", cl))
    dq = _velocities()
    np.testing.assert_allclose(back.torques(dq), cl.torques(dq), rtol=0, atol=1e-15)
    np.testing.assert_array_equal(back.band, BAND)
    np.testing.assert_array_equal(back.drive.transmission, K)


def test_a_robot_with_quadratic_friction_goes_through_simulate_identify_observe():
    """A robot holding the quadratic law (not the sigmoid): the simulation adds the law's
    closed form (fv dq + fq dq |dq| + fc sign(dq) + fo), identification recovers its
    coefficients from the noise-free log, and the momentum observer of the robot and of the
    identified model both explain the log (no external torque), which without the friction
    they do not."""
    from dynid.friction.validation import own_friction
    from dynid.identification.selection import identify_recordings
    from dynid.identification.structure import Structure
    from dynid.observer.model import from_identified, from_robot
    from dynid.observer.residual import observe
    from dynid.simulation.measurement import SensorNoise, sample_times, simulate_measurement
    from dynid.simulation.trajectories import random_fourier

    from conftest import planar_2r

    P = np.array([[0.3, 0.2, 0.5, 0.05], [0.2, 0.1, 0.3, -0.02]])  # fv, fq, fc, fo
    robot = planar_2r().with_friction(LAWS["quadratic"].model(P))
    traj = random_fourier(robot, np.random.default_rng(3))(sample_times(4.0, 200.0))
    exact = SensorNoise(tau_std=0.0, q_std=0.0, dq_std=0.0)
    log = simulate_measurement(
        robot, traj, rng=np.random.default_rng(4), noise=exact, with_ddq=True
    )
    q, dq, ddq = (np.asarray(x) for x in (traj.q, traj.dq, traj.ddq))
    fv, fq, fc, fo = P.T
    closed = fv * dq + fq * dq * np.abs(dq) + fc * np.sign(dq) + fo
    np.testing.assert_allclose(log.tau, dynid.rnea(robot, q, dq, ddq) + closed, atol=1e-12)

    parts = Structure.parse("viscous,quadratic,coulomb,offset")
    model = identify_recordings(robot, [log], structure=parts, cutoff_hz=None)
    identified = own_friction(model)
    assert identified is not None and identified.kind == "quadratic"
    np.testing.assert_allclose(identified.params, P, atol=1e-9)

    for observer in (from_robot(robot), from_identified(model)):
        r = observe(observer, log.t, log.q, log.dq, log.tau).r
        assert np.max(np.abs(r)) < 1e-3, np.max(np.abs(r))
    rigid = observe(from_robot(robot, friction=None), log.t, log.q, log.dq, log.tau).r
    assert np.max(np.abs(rigid)) > 0.1


def test_feasible_json_says_it_does_not_hold_another_law():
    from dynid.io.feasible import feasible_to_dict

    robot = _two_joints().with_friction(ClassicalFriction.from_array(PARAMS["classical"]))
    with pytest.warns(DynidWarning, match="classical friction is not part of the file"):
        d = feasible_to_dict(robot)
    assert d["friction"] is None
    sigmoid = SigmoidFriction.from_array(PARAMS["sigmoid"])
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        d = feasible_to_dict(robot.with_friction(sigmoid))
    assert d["friction"]["phi2"] == list(PARAMS["sigmoid"][:, 1])
