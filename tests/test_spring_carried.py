"""The identified joint spring carried downstream of identification: the consistent fit,
``feasible.json``, validation, the observer (its residual and its uncertainty),
simulation and the robot exports.

References: simulated recordings of the planar 2R arm (``tests/conftest.py``) whose torques
hold a known spring ``k (q - q0)`` about the middle of the joints' limits, classical friction
and sensor noise (the stiffnesses judged against the truth, the torques on a recording the
fit did not see against its noise); MuJoCo's passive spring force for the MJCF export;
the observer's own residual at other stiffnesses for the spring's uncertainty.
"""

from __future__ import annotations

import warnings

import numpy as np
import pytest

from dynid.dynamics.rnea import rnea
from dynid.exceptions import DataError, DynidWarning, ShapeError, WrongTypeError
from dynid.feasibility.convex.fit import identify_consistent
from dynid.friction.model import ClassicalFriction
from dynid.identification.structure import Structure
from dynid.io.export import save_robot
from dynid.io.feasible import load_feasible_spring
from dynid.io.feasible_bundle import save_feasible_bundle
from dynid.io.model_json import save_model_json
from dynid.io.robot_file import load_robot
from dynid.io.torque_log import save_torque_log
from dynid.model.stiffness import JointStiffness
from dynid.observer.model import from_identified, from_robot
from dynid.simulation.measurement import SensorNoise, sample_times, simulate_measurement
from dynid.simulation.trajectories import random_fourier
from dynid.workflows.validate import ValidateOptions, validate_files

from conftest import planar_2r, recordings, said_warnings

K = np.array([4.0, 2.0])  # the truth's stiffnesses [N m/rad]
LOWER, UPPER = np.array([-2.0, -2.2]), np.array([2.6, 2.8])  # q0 = (0.3, 0.3) rad
NOISE = 0.05  # torque noise [N m]


@pytest.fixture(scope="module")
def arm():
    """The 2R arm with finite limits (so the spring's rest position is not zero)."""
    return planar_2r().replace(q_min=LOWER, q_max=UPPER)


def _spring_logs(arm):
    """Three noisy recordings of the arm with the spring and classical friction (seeds 11,
    12, 13)."""
    q0 = (LOWER + UPPER) / 2
    fr = ClassicalFriction(np.array([0.3, 0.2]), np.array([0.4, 0.3]), np.zeros(2))
    noise = SensorNoise(tau_std=NOISE, q_std=1e-5, dq_std=1e-3)
    return recordings(
        arm,
        (11, 12, 13),
        friction=fr,
        duration=6.0,
        noise=noise,
        added=lambda log: K * (log.q - q0),
    )


@pytest.fixture(scope="module")
def fitted(arm, tmp_path_factory):
    """``identify --consistent --terms viscous,coulomb,spring`` on two recordings of the
    arm with a spring, judged on a third; its files and the held-out recording."""
    logs = _spring_logs(arm)
    out = tmp_path_factory.mktemp("spring")
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", DynidWarning)
        res = identify_consistent(
            arm, logs[:2], structure=Structure.parse("viscous,coulomb,spring"), validate_on=logs[2]
        )
        save_feasible_bundle(out, res)
    save_torque_log(out / "held.csv", logs[2])
    save_torque_log(out / "train.csv", logs[0])
    save_model_json(out / "identification.json", res.identified)
    return res, out


def test_the_consistent_fit_recovers_the_spring_and_reaches_the_floor(fitted):
    """The consistent fit holds the spring: both stiffnesses within 4 of the least-squares
    standard deviations of the truth (and 3 %), ``>= 0``, about the middle of the limits;
    its held-out error is the least-squares fit's (the noise: about 0.37 %)."""
    res, _ = fitted
    assert res.spring is not None
    std = np.asarray(res.identified.terms["spring"].std)
    k = res.spring.k
    assert np.all(np.abs(k - K) < 4 * std) and np.all(np.abs(k - K) < 0.03 * K), (k, std)
    assert np.all(k >= 0)
    np.testing.assert_array_equal(res.spring.q0, (LOWER + UPPER) / 2)
    h = res.heldout
    assert h is not None and h.heldout_percent < 1.05 * h.ls_heldout_percent, h


def test_validate_params_feasible_predicts_the_spring(fitted):
    """``validate --params feasible.json`` on the held-out recording: at the noise on each
    joint (RMS within 1.15 x its noise) with the spring the file holds; the same robot
    without it (the spring dropped, as before) is many times its noise."""
    _, out = fitted
    robot = load_robot(out / "feasible.json")
    ratios = []
    for r in (robot, robot.with_spring(None)):
        with warnings.catch_warnings():
            warnings.simplefilter("ignore", DynidWarning)
            v = validate_files(
                r, out / "held.csv", ValidateOptions(), feasible=out / "feasible.json"
            )
        ratios.append(v.validation.errors.rms / v.noise_rms)
    assert np.all(ratios[0] < 1.15), ratios
    assert np.all(ratios[1] > 3.0), ratios


def test_the_mjcf_export_is_mujocos_passive_spring(fitted):
    """The exported MJCF loaded in MuJoCo: ``qfrc_spring`` at random positions is
    ``-k (q - q0)`` of the identified spring to 1e-10 (MuJoCo's sign: the spring's own
    torque, the opposite of the motors'); the file read back holds the same spring."""
    mujoco = pytest.importorskip("mujoco")
    res, out = fitted
    m = mujoco.MjModel.from_xml_path(str(out / "robot.xml"))
    d = mujoco.MjData(m)
    rng = np.random.default_rng(5)
    for q in rng.uniform(LOWER, UPPER, (5, 2)):
        d.qpos[:] = q
        mujoco.mj_forward(m, d)
        np.testing.assert_allclose(d.qfrc_spring, -res.spring.k * (q - res.spring.q0), atol=1e-10)
    back = load_robot(out / "robot.xml").spring  # read by MuJoCo's compiler
    assert back is not None
    np.testing.assert_allclose(back.k, res.spring.k, rtol=1e-15)
    np.testing.assert_allclose(back.q0, res.spring.q0, rtol=1e-15)


def test_toml_and_feasible_round_trips_give_the_spring_torques(fitted, tmp_path):
    """``robot.toml``'s ``[spring]`` table and ``feasible.json``'s ``spring`` read back to
    the identified torques ``k (q - q0)``; the robot read from them carries the spring
    into the observer and into a simulation (``tau - rnea`` of an exact log is it)."""
    res, out = fitted
    rng = np.random.default_rng(6)
    q = rng.uniform(LOWER, UPPER, (20, 2))
    want = res.spring.k * (q - res.spring.q0)
    for path in (out / "robot.toml", out / "feasible.json"):
        robot = load_robot(path)
        assert robot.spring is not None
        np.testing.assert_allclose(robot.spring.torques(q), want, rtol=0, atol=1e-12)
        held = from_robot(robot).position_torques(q)
        np.testing.assert_allclose(held, want, rtol=0, atol=1e-12)
    spring = load_feasible_spring(out / "feasible.json")
    assert spring is not None
    np.testing.assert_allclose(spring.torques(q), want, rtol=0, atol=1e-12)
    robot = load_robot(out / "robot.toml")
    t = sample_times(0.5, 200.0)
    log = simulate_measurement(
        robot,
        random_fourier(robot, np.random.default_rng(7))(t),
        rng=np.random.default_rng(8),
        noise=SensorNoise.none(),
        friction=None,
        with_ddq=True,
    )
    tau_s = log.tau - rnea(robot, log.q, log.dq, log.ddq)
    np.testing.assert_allclose(tau_s, res.spring.k * (log.q - res.spring.q0), atol=1e-9)
    save_robot(tmp_path / "again.toml", robot, friction=False)  # written back from a TOML
    again = load_robot(tmp_path / "again.toml").spring
    assert again is not None
    np.testing.assert_array_equal(again.k, res.spring.k)


def test_the_observer_with_the_fitted_spring_raises_no_alarm_on_free_motion(fitted, tmp_path):
    """``observe`` calibrated on a training recording of the spring arm, detecting on the
    held-out one (free motion, no contact): with the fitted spring (``feasible.json``, and
    ``identification.json`` with its uncertainty) no event and every residual under its
    threshold; the same thresholds with the spring left out of ``feasible.json`` take the
    spring's torque for contacts."""
    import json

    from dynid.io.observer_files import save_thresholds
    from dynid.workflows.observe import ObserveOptions, observe_files

    _, out = fitted
    doc = json.loads((out / "feasible.json").read_text())
    del doc["spring"]
    (tmp_path / "nospring.json").write_text(json.dumps(doc))
    train, held = (out / "train.csv",), (out / "held.csv",)
    runs = {
        "identified": ({"model": out / "identification.json"}, None),
        "feasible": ({"params": out / "feasible.json"}, {"params": tmp_path / "nospring.json"}),
    }
    found = {}
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", DynidWarning)  # another model than calibrated
        for name, (src, without) in runs.items():
            cal = observe_files(ObserveOptions(data=train, calibrate=True, **src))
            assert cal.thresholds.uses_uncertainty == (name == "identified")
            th = save_thresholds(tmp_path / f"{name}.json", cal.thresholds, joints=("a", "b"))
            for key, spec in ((name, src), (f"{name} without", without)):
                if spec is not None:
                    x = observe_files(ObserveOptions(data=held, thresholds=th, **spec)).logs[0]
                    found[key] = (len(x.events), float(np.nanmax(x.peak_ratio)))
    assert found["identified"][0] == 0 and found["feasible"][0] == 0, found
    assert found["identified"][1] < 1.0 and found["feasible"][1] < 1.0, found
    assert found["feasible without"][0] >= 1 and found["feasible without"][1] > 3.0, found


def test_the_residual_uncertainty_holds_the_springs(fitted):
    """The observer model of the identified spring carries the stiffnesses' variances
    (``std**2``); with the covariance a direction ``e e^T`` in the stiffnesses alone the
    propagated std is ``|r(k + e) - r(k)|``, the observer run on the model with the
    stiffnesses moved (the residual is linear in them): the spring's uncertainty goes
    through the observer's filter exactly."""
    import dataclasses

    from dynid.observer.detection import residual_std
    from dynid.observer.residual import ObserverOptions, observe

    res, _ = fitted
    ident = res.identified
    model = from_identified(ident, friction=None)
    spring = ident.terms["spring"]
    assert model.position_covariance is not None
    np.testing.assert_allclose(np.diag(model.position_covariance), spring.std**2, rtol=1e-15)
    rng = np.random.default_rng(21)
    t = np.arange(0.0, 1.5, 1e-3)
    w, phase = np.array([2.0, 3.0]), rng.uniform(0.0, 1.0, 2)
    q = (LOWER + UPPER) / 2 + 1.5 * np.sin(np.outer(t, w) + phase)
    dq = 1.5 * w * np.cos(np.outer(t, w) + phase)
    tau = rng.normal(size=q.shape)
    e = np.array([0.3, -0.2])  # N m/rad
    opts = ObserverOptions(gain=30.0)
    ((term, values),) = model.position_terms
    moved = dataclasses.replace(model, position_terms=((term, values + e),))
    r0 = observe(model, t, q, dq, tau, opts).r
    r1 = observe(moved, t, q, dq, tau, opts).r
    cov = np.zeros_like(np.asarray(model.covariance))
    one = dataclasses.replace(model, covariance=cov, position_covariance=np.outer(e, e))
    s = residual_std(one, t, q, dq, opts)
    assert np.abs(r1 - r0).max() > 0.1
    np.testing.assert_allclose(s, np.abs(r1 - r0), rtol=0, atol=1e-9)
    without = dataclasses.replace(one, position_covariance=None)
    np.testing.assert_allclose(residual_std(without, t, q, dq, opts), 0.0, atol=1e-12)


def test_a_priors_spring_is_said_to_be_unused_and_changes_nothing(arm, fitted):
    """A prior robot with a [spring] (k = 100 N m/rad, 25 and 50 times the truth): the
    consistent fit is the one with the description's prior, to the bit (stiffnesses and
    links from the data; a prior holds the links' inertials only), and a note says the
    prior's spring is not used, where it was ignored without a word."""
    res, _ = fitted
    logs = _spring_logs(arm)
    prior = arm.with_spring(JointStiffness(np.array([100.0, 100.0]), (LOWER + UPPER) / 2))
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", DynidWarning)
        got = identify_consistent(
            arm, logs[:2], structure=Structure.parse("viscous,coulomb,spring"),
            validate_on=logs[2], prior=prior,
        )  # fmt: skip
    assert got.spring is not None and res.spring is not None
    np.testing.assert_array_equal(got.spring.k, res.spring.k)
    np.testing.assert_array_equal(got.robot.phi, res.robot.phi)
    said = [x for x in got.notes if "joint spring" in x]
    assert len(said) == 1 and "k = 100, 100 N m/rad) is not used" in said[0], got.notes
    assert not [x for x in res.notes if "joint spring" in x]


def test_only_the_urdf_export_says_it_leaves_the_spring_out(arm, tmp_path):
    """URDF has no spring: its export warns and comments that the spring is left out,
    naming the stiffnesses and the exports that hold it; the MJCF and TOML exports hold it
    and say nothing of it."""
    robot = arm.with_spring(JointStiffness(np.array([4.0, 0.0]), np.array([0.3, 0.3])))
    _, said = said_warnings(save_robot, tmp_path / "r.urdf", robot)
    spring = [s for s in said if "spring" in s]
    assert len(spring) == 1 and "joint1 4" in spring[0], said
    assert "leaves out the joint spring" in (tmp_path / "r.urdf").read_text()
    for name in ("r.xml", "r.toml"):
        _, said = said_warnings(save_robot, tmp_path / name, robot)
        assert not [s for s in said if "spring" in s], said
        assert "leaves out" not in (tmp_path / name).read_text()
    text = (tmp_path / "r.xml").read_text()
    assert 'stiffness="4.0" springref="0.3"' in text and 'stiffness="0" springref="0.3"' in text


def test_springs_of_the_wrong_shape_or_sign_are_refused(arm, tmp_path):
    """A spring of unequal ``k`` and ``q0``, a non-finite value, another joint count than
    the robot's, and a negative stiffness in a TOML ``[spring]`` table are each refused
    with a message naming what is wrong."""
    with pytest.raises(ShapeError, match="k and q0 must be"):
        JointStiffness(np.ones(2), np.zeros(3))
    with pytest.raises(ShapeError, match="must be finite"):
        JointStiffness(np.array([1.0, np.nan]), np.zeros(2))
    with pytest.raises(ShapeError, match="spring has 3 joints; robot has 2"):
        arm.with_spring(JointStiffness(np.ones(3), np.zeros(3)))
    with pytest.raises(WrongTypeError, match="must be a JointStiffness"):
        arm.replace(spring=np.ones(2))
    path = save_robot(tmp_path / "r.toml", arm, friction=False)
    path.write_text(path.read_text() + "\n[spring]\nk = [1.0, -2.0]\nq0 = [0.0, 0.0]\n")
    with pytest.raises(DataError, match=r"key 'spring.k\[1\]': expected a number >= 0"):
        load_robot(path)


def test_the_mjcf_spring_reference_holds_the_joints_offset(arm, tmp_path):
    """Regression (a spring identified about the middle of the limits with the offset that
    places its rest position, fo2 = +12 N m, was written as springref = 0 with the offset
    dropped: 12 N m off at every position in MuJoCo, 60 % held-out error): MuJoCo's
    ``qfrc_spring + fo`` equals ``-(k (q - q0) + fo)`` to 1e-10 on the joint with a spring,
    whose offset the warning no longer names; the joint without one keeps its offset named."""
    mujoco = pytest.importorskip("mujoco")
    k, q0, fo = np.array([30.0, 0.0]), np.array([0.3, 0.3]), np.array([12.0, 0.5])
    robot = arm.with_spring(JointStiffness(k, q0))
    fr = ClassicalFriction(np.array([0.3, 0.2]), np.array([0.4, 0.3]), fo)
    _, said = said_warnings(save_robot, tmp_path / "r.xml", robot, friction=fr)
    offsets = [s for s in said if "offsets fo" in s]
    assert offsets and "+0.5 N m at joint 2" in offsets[0], said
    m = mujoco.MjModel.from_xml_path(str(tmp_path / "r.xml"))
    d = mujoco.MjData(m)
    for q in np.random.default_rng(9).uniform(LOWER, UPPER, (5, 2)):
        d.qpos[:] = q
        mujoco.mj_forward(m, d)
        assert abs(-d.qfrc_spring[0] - (k[0] * (q[0] - q0[0]) + fo[0])) < 1e-10


def test_simulate_says_the_springs_it_puts_in_the_torques(tmp_path, capsys):
    """Regression (simulate from a robot with a [spring] table never said so): the
    command names each joint's spring among its notes."""
    import dynid
    from dynid.cli.__main__ import main

    k = np.zeros(7)
    k[1] = 30.0
    robot = dynid.panda().with_spring(JointStiffness(k, np.full(7, -0.4)))
    save_robot(tmp_path / "p.toml", robot, friction=False)
    argv = ["simulate", "--robot", str(tmp_path / "p.toml"), "--duration", "0.5"]
    assert main([*argv, "--rate", "100", "--out", str(tmp_path / "x.csv")]) == 0
    said = capsys.readouterr()
    assert "joint springs in the torques, k (q - q0): joint2 30 N m/rad about -0.4 rad" in (
        said.out + said.err
    )
