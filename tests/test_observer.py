"""The momentum observer against truths: Pinocchio's M, C and g, the regressor path, a
simulated contact's external torque, the first-order lag and the friction laws."""

from __future__ import annotations

import dataclasses

import numpy as np
import pytest

import dynid
from dynid.friction.laws import LAWS
from dynid.friction.model import DriveFriction
from dynid.identification.model import IdentifiedModel
from dynid.model.drive import Drive
from dynid.observer import (
    ObserverModel,
    base_momentum_regressor,
    from_identified,
    from_robot,
    momentum_regressor,
    momentum_terms,
)
from dynid.observer.friction import canonical_friction
from dynid.observer.residual import (
    MomentumObserver,
    ObserverOptions,
    first_order_lag,
    observe,
)
from dynid.observer.terms import momentum_terms_numpy
from dynid.regressors.base import base_parameters
from dynid.regressors.terms import RotorInertia
from dynid.simulation.contact import Contact, contact_torques
from dynid.simulation.measurement import SensorNoise, simulate_measurement
from dynid.simulation.trajectories import (
    GAZ2019_SINUSOID_AMPLITUDES,
    GAZ2019_SINUSOID_PERIODS,
    centered_start,
    sinusoid_trajectory,
    uniform_times,
)

from conftest import given_fit, pinocchio_panda_urdf, random_states

GEARS = np.array([100.0, 100.0, 100.0, 100.0, 80.0, 80.0, 50.0])
IA = np.array([3e-5, 3e-5, 2.5e-5, 2.5e-5, 1e-5, 1e-5, 8e-6])


def panda_trajectory(duration: float, fs: float = 1000.0):
    robot = dynid.panda()
    A, P = GAZ2019_SINUSOID_AMPLITUDES, GAZ2019_SINUSOID_PERIODS
    t = uniform_times(duration, fs)
    return sinusoid_trajectory(t, centered_start(robot, A, P), A, P)


@pytest.fixture(scope="module")
def identified() -> IdentifiedModel:
    """An identified Panda with geared motors whose rotor inertias were identified: the
    exact base parameters of the built-in Panda and IA, a covariance of 1 % of each."""
    robot = dynid.panda()
    drive = Drive.from_gears(GEARS)
    base = base_parameters(robot, kind="torque", terms=(RotorInertia(drive),))
    beta = base.beta_from_phi(np.concatenate([robot.phi.reshape(-1), IA]))
    std = 0.01 * np.abs(beta) + 1e-9
    fit = given_fit(beta, std, covariance=np.diag(std**2))
    return IdentifiedModel(robot=robot, base=base, fit=fit, drive=drive)


@pytest.fixture(scope="module")
def pin_panda():
    """Pinocchio's Panda (fingers locked) with the built-in Panda's inertials and gravity."""
    pin = pytest.importorskip("pinocchio")
    robot = dynid.panda()
    full = pin.buildModelFromUrdf(pinocchio_panda_urdf())
    lock = [full.getJointId(n) for n in ("panda_finger_joint1", "panda_finger_joint2")]
    model = pin.buildReducedModel(full, lock, pin.neutral(full))
    model.gravity.linear[:] = robot.gravity
    for i in range(1, 8):
        model.inertias[i] = pin.Inertia(robot.mass[i - 1], robot.com[i - 1], robot.inertia[i - 1])
    return pin, model, model.createData()


def test_momentum_and_coriolis_transpose_equal_pinocchio_with_rotor_terms(pin_panda, identified):
    """p = (M + armature) dq and g - C^T dq equal Pinocchio's crba, computeCoriolisMatrix
    and computeGeneralizedGravity (armature = the rotors' K^2 I_a) on 50 random states."""
    pin, model, data = pin_panda
    model.armature[:] = GEARS**2 * IA
    obs = from_identified(identified)
    q, dq, _ = random_states(dynid.panda(), 50, seed=3)
    p, beta = momentum_terms(obs, q, dq)
    for k in range(q.shape[0]):
        M = pin.crba(model, data, q[k])
        M = np.triu(M) + np.triu(M, 1).T
        C = pin.computeCoriolisMatrix(model, data, q[k], dq[k])
        g = pin.computeGeneralizedGravity(model, data, q[k])
        np.testing.assert_allclose(p[k], M @ dq[k], rtol=0, atol=1e-10)
        np.testing.assert_allclose(beta[k], g - C.T @ dq[k], rtol=0, atol=1e-10)


def test_momentum_regressor_path_equals_the_recursive_path(identified):
    """The base momentum regressor times beta equals the compiled RNEA-like pass (rotor
    columns included), and the standard regressor times phi equals it on a robot."""
    obs = from_identified(identified)
    q, dq, _ = random_states(dynid.panda(), 40, seed=4)
    p, beta = momentum_terms(obs, q, dq)
    Yp, Yb = base_momentum_regressor(obs, q, dq)
    np.testing.assert_allclose(Yp @ obs.beta, p, rtol=0, atol=1e-10)
    np.testing.assert_allclose(Yb @ obs.beta, beta, rtol=0, atol=1e-10)
    robot = dynid.panda()
    Sp, Sb = momentum_regressor(robot, q, dq)
    p0, b0 = momentum_terms(robot, q, dq)
    np.testing.assert_allclose(Sp @ robot.phi.reshape(-1), p0, rtol=0, atol=1e-10)
    np.testing.assert_allclose(Sb @ robot.phi.reshape(-1), b0, rtol=0, atol=1e-10)
    assert Sp.shape == (40, 7, 70) and Yp.shape == (40, 7, identified.base.rank)


@pytest.mark.parametrize("shape", [(), (1,), (3, 2)])
def test_momentum_terms_keep_the_batch_shape_and_equal_the_numpy_twin(shape):
    """Kernel and numpy twin agree to 1e-12 on an arm with a prismatic joint, any batch."""
    robot = dynid.Robot.from_mdh(
        a=[0.0, 0.3, 0.05], d=[0.4, 0.1, 0.2], alpha=[0.3, -np.pi / 2, np.pi / 2],
        theta=[0.0, 0.3, -0.2], joint_types="RPR", mass=[2.0, 1.5, 0.7],
        com=[[0.01, 0.02, 0.1], [0.1, -0.02, 0.0], [0.0, 0.03, 0.05]],
        inertia=[np.diag([0.02, 0.03, 0.01])] * 3, gravity=[0.3, -0.5, -9.7],
    )  # fmt: skip
    rng = np.random.default_rng(5)
    q, dq = rng.normal(size=shape + (3,)), rng.normal(size=shape + (3,))
    p, b = momentum_terms(robot, q, dq)
    pn, bn = momentum_terms_numpy(robot, q, dq)
    assert p.shape == b.shape == shape + (3,)
    np.testing.assert_allclose(p, pn, rtol=0, atol=1e-12)
    np.testing.assert_allclose(b, bn, rtol=0, atol=1e-12)
    M = dynid.mass_matrix(robot, q)
    np.testing.assert_allclose(p, (M @ dq[..., None])[..., 0], rtol=0, atol=1e-12)


def test_residual_of_a_simulated_contact_converges_to_the_true_external_torque():
    """Exact data, the true model: r follows K_O/(s + K_O) of tau_ext = J^T w to 1e-3 N m
    over the whole log (a step contact on link 5, friction of the Panda)."""
    robot = dynid.panda()
    traj = panda_trajectory(6.0)
    contact = Contact("link5", (5.0, 0.0, -20.0, 0.0, 1.0, 0.0), 2.0, 4.0)
    log = simulate_measurement(
        robot, traj, rng=np.random.default_rng(0), noise=SensorNoise.none(), contacts=(contact,)
    )
    tau_ext = contact_torques(robot, (contact,), traj.t, traj.q)
    assert np.abs(tau_ext).max() > 5.0  # a contact the residual must find
    res = observe(from_robot(robot), log.t, log.q, log.dq, log.tau, ObserverOptions(gain=40.0))
    truth = first_order_lag(log.t, tau_ext, 40.0)
    assert np.abs(res.r - truth).max() < 1e-3
    # the residual against the truth the log stores: the lag's own error, per joint
    from pathlib import Path

    from dynid.observer.results import LogObservation

    seen = LogObservation(Path("x.csv"), log.t, res.r, None, [], None, tau_ext)
    lag_rms = np.sqrt(np.mean((truth - tau_ext) ** 2, axis=0))
    np.testing.assert_allclose(seen.truth_error(), lag_rms, atol=1e-3)
    assert np.max(lag_rms) > 0.1  # the lag is what is left: the comparison is not trivial


def test_step_equals_batch_and_the_numpy_path_with_variable_sample_times(identified):
    """step() sample by sample, run() over the log and the numpy path give the same
    residual on jittered sample times, per-joint gains, Euler and exact."""
    rng = np.random.default_rng(6)
    traj = panda_trajectory(0.5)
    t = traj.t + np.r_[0.0, rng.uniform(-3e-4, 3e-4, traj.t.size - 1)]
    tau = rng.normal(size=traj.q.shape)
    model = from_identified(identified)
    for disc in ("exact", "euler"):
        opts = ObserverOptions(gain=tuple(np.linspace(20, 80, 7)), discretisation=disc)
        batch = observe(model, t, traj.q, traj.dq, tau, opts).r
        obs = MomentumObserver(model, opts)
        steps = np.array([obs.step(traj.q[k], traj.dq[k], tau[k], t[k]) for k in range(t.size)])
        np.testing.assert_allclose(steps, batch, rtol=0, atol=1e-9)
        slow = MomentumObserver(model, opts)
        numpy_r = slow._run_numpy(t, traj.q, traj.dq, slow._u(traj.q, traj.dq, tau, friction=True))
        np.testing.assert_allclose(numpy_r, batch, rtol=0, atol=1e-9)


def test_euler_rectangle_is_de_lucas_integral_form():
    """With Euler and the rectangle rule the residual equals r_k = K (p_k - I_k - p_0),
    I_k = I_{k-1} + T_k (tau_k - tau_f + C^T dq - g + r_{k-1}), written out."""
    rng = np.random.default_rng(7)
    traj = panda_trajectory(0.3)
    tau = rng.normal(size=traj.q.shape) * 3
    model = from_robot(dynid.panda())
    K = 30.0
    r = observe(model, traj.t, traj.q, traj.dq, tau, ObserverOptions(K, "euler", "rectangle")).r
    p, beta = momentum_terms(model, traj.q, traj.dq)
    u = tau - model.friction.torques(traj.dq) - beta
    I, ref = np.zeros(7), np.zeros_like(r)
    for k in range(1, traj.t.size):
        I = I + (traj.t[k] - traj.t[k - 1]) * (u[k] + ref[k - 1])
        ref[k] = K * (p[k] - I - p[0])
    np.testing.assert_allclose(r, ref, rtol=0, atol=1e-9)


class _CubicLaw:
    """A law outside the registry (no canonical form): ``tau_f = fk dq^3``."""

    name, params, units, formula = "cubic", ("fk",), ("N m s^3/rad^3",), "fk dq^3"

    @staticmethod
    def torques(dq, P, band):
        return P[:, 0] * np.asarray(dq) ** 3


def test_a_law_without_a_canonical_form_is_evaluated_in_python():
    """A law the canonical form does not know: the observer subtracts its own torques, and
    its residual equals that of the same torques subtracted from the measured ones first."""
    from dynid.friction.model import LawFriction

    model = LawFriction(_CubicLaw(), np.array([[0.3], [0.2], [0.8]]), np.zeros(3))
    assert canonical_friction(model, 3) is None
    robot = dynid.Robot.from_mdh(
        a=[0, 0.3, 0.3], d=[0.3, 0, 0], alpha=[0, np.pi / 2, 0], theta=[0, 0, 0],
        mass=[1.0, 1.0, 1.0],
    )  # fmt: skip
    obs = MomentumObserver(ObserverModel(robot, np.zeros((3, 3)), model))
    assert obs._python_friction
    rng = np.random.default_rng(3)
    t = np.arange(50) * 1e-3
    q, dq, tau = rng.normal(size=(3, 50, 3))
    bare = MomentumObserver(ObserverModel(robot, np.zeros((3, 3)), None))
    expected = bare.run(t, q, dq, tau - model.torques(dq))
    np.testing.assert_allclose(obs.run(t, q, dq, tau), expected, rtol=0, atol=1e-12)


@pytest.mark.parametrize("name", sorted(LAWS))
def test_every_friction_law_has_a_canonical_form_equal_to_its_torques(name):
    """The compiled step's canonical friction equals each law's own torques, with a band,
    and through a coupled drive at the motors."""
    rng = np.random.default_rng(8)
    law = LAWS[name]
    lo = np.maximum(np.asarray(law.lower, float), -2.0)
    hi = np.minimum(np.asarray(law.upper, float), 2.0)
    P = rng.uniform(lo, hi, (3, len(law.params))) if law.params else np.zeros((3, 0))
    for band in (np.zeros(3), np.array([0.01, 0.02, 0.0])):
        model = law.model(P, band)
        drive = Drive.from_gears([10.0, 20.0, 5.0], coupling=[(3, 2, 4.0)])
        for fr in (model, DriveFriction(model, drive)):
            K, F = canonical_friction(fr, 3)
            dq = np.concatenate([rng.normal(size=(200, 3)), np.array([[0.0, 0.005, -0.015]])])
            v = dq @ K.T
            f = np.zeros_like(v)
            robot = dynid.Robot.from_mdh(
                a=[0, 0.3, 0.3], d=[0.3, 0, 0], alpha=[0, np.pi / 2, 0], theta=[0, 0, 0],
                mass=[1.0, 1.0, 1.0],
            )  # fmt: skip
            obs = MomentumObserver(ObserverModel(robot, np.zeros((3, 3)), fr))
            assert not obs._python_friction
            q = np.zeros(3)
            for k in range(dq.shape[0]):  # the step subtracts tau_f: read it back
                obs.reset()
                obs.step(q, dq[k], np.zeros(3), 0.0)
                f[k] = -obs._S[2 + 3 : 2 + 6] - momentum_terms(robot, q, dq[k])[1]
            np.testing.assert_allclose(f, fr.torques(dq), rtol=1e-15, atol=1e-12)


# ---------------------------------------------------------------------- detection


def test_detection_delay_of_a_step_contact_is_within_one_sample_of_the_formula():
    """A step of A on one joint crosses theta after ln(A / (A - theta)) / K_O (one sample)."""
    from dynid.observer.detection import calibrate, detect

    robot = dynid.panda()
    traj = panda_trajectory(3.0)
    K, T = 25.0, 1e-3
    ext = np.zeros_like(traj.q)
    on = traj.t >= 1.5
    A = 8.0
    ext[on, 3] = A  # a torque step on joint 4 (a wrench whose J^T w is e_4 A)
    log = simulate_measurement(robot, traj, rng=np.random.default_rng(1), noise=SensorNoise.none())
    opts = ObserverOptions(gain=K)
    model = from_robot(robot)
    quiet = observe(model, log.t, log.q, log.dq, log.tau, opts).r
    th = calibrate([quiet], opts)
    th = type(th)(
        np.full(7, 3.0), np.full(7, 6.0), th.margin, th.quantile, 2.0, opts, th.samples
    )  # theta = 3 N m on every joint
    r = observe(model, log.t, log.q, log.dq, log.tau - ext, opts).r
    events = detect(log.t, r, th)
    assert len(events) == 1 and events[0].joints == (4,) and events[0].level == "collision"
    delay = events[0].start - 1.5
    expected = np.log(A / (A - 3.0)) / K
    assert abs(delay - expected) <= T
    assert events[0].peak[3] == pytest.approx(A, abs=1e-3)


def test_no_event_on_collision_free_noisy_logs_with_an_identified_model():
    """Thresholds calibrated on one collision-free noisy log raise no event on two others
    (other noise, other motion), with a model identified from a fourth; a 15 N push is
    found."""
    from dynid.identification.classical import identify_from_log
    from dynid.observer.detection import calibrate, detect
    from dynid.simulation.trajectories import random_fourier

    robot = dynid.panda()
    noise = SensorNoise()

    def log_of(seed, duration=8.0, contacts=()):
        rng = np.random.default_rng(seed)
        series = random_fourier(robot, rng, n_harmonics=4, w_f=2 * np.pi * 0.125)
        traj = series(uniform_times(duration, 1000.0))
        return simulate_measurement(robot, traj, rng=rng, noise=noise, contacts=contacts)

    model = from_identified(
        identify_from_log(robot, log_of(10, 16.0), structure="classical", estimator="ols")
    )
    model = model.with_friction(from_robot(robot).friction)  # the simulated friction
    opts = ObserverOptions(gain=30.0)
    cal = log_of(11)
    th = calibrate([observe(model, cal.t, cal.q, cal.dq, cal.tau, opts).r], opts)
    for seed in (12, 13):
        other = log_of(seed)
        r = observe(model, other.t, other.q, other.dq, other.tau, opts).r
        assert detect(other.t, r, th) == []
    push = Contact("link6", (0.0, 0.0, -15.0), 4.0, 4.5)
    hit = log_of(12, contacts=(push,))
    r = observe(model, hit.t, hit.q, hit.dq, hit.tau, opts).r
    events = detect(hit.t, r, th)
    assert len(events) == 1 and 4.0 <= events[0].start <= 4.2


def test_residual_std_is_the_residual_change_of_a_parameter_direction(identified):
    """With Sigma = e e^T the propagated std equals |r(beta + e) - r(beta)| (the residual
    is linear in beta): the covariance goes through the momentum regressor exactly."""
    from dynid.observer.detection import BLOCK, residual_std

    traj = panda_trajectory(0.02 + BLOCK * 1e-3)  # more than one block
    tau = np.random.default_rng(9).normal(size=traj.q.shape)
    model = from_identified(identified, friction=None)
    e = np.zeros(identified.base.rank)
    e[[3, 10, 20]] = [0.02, -0.01, 0.005]
    opts = ObserverOptions(gain=20.0)
    r0 = observe(model, traj.t, traj.q, traj.dq, tau, opts).r
    moved = IdentifiedModel(
        robot=identified.robot,
        base=identified.base,
        fit=type(identified.fit)(**{**_fields(identified.fit), "beta": identified.fit.beta + e}),
        drive=identified.drive,
    )
    r1 = observe(from_identified(moved, friction=None), traj.t, traj.q, traj.dq, tau, opts).r
    one = dataclasses.replace(model, covariance=np.outer(e, e))
    s = residual_std(one, traj.t, traj.q, traj.dq, opts)
    np.testing.assert_allclose(s, np.abs(r1 - r0), rtol=0, atol=1e-9)


def _fields(obj):
    import dataclasses

    return {f.name: getattr(obj, f.name) for f in dataclasses.fields(obj)}


def test_external_wrench_recovers_the_contact_wrench_and_flags_singular_configurations():
    """J^T w back to w at the flange on random states (7 joints); the stretched-out arm
    (a singular configuration) is flagged and damped."""
    from dynid.observer.wrench import external_wrench

    robot = dynid.panda()
    q, _, _ = random_states(robot, 30, seed=10)
    w = np.random.default_rng(11).normal(size=(30, 6)) * [10, 10, 10, 1, 1, 1]
    J = dynid.jacobian(robot, q, "flange")
    r = (np.swapaxes(J, -1, -2) @ w[..., None])[..., 0]
    est = external_wrench(robot, q, r, "flange")
    ok = ~est.damped
    assert ok.sum() >= 15
    np.testing.assert_allclose(est.wrench[ok], w[ok], rtol=0, atol=1e-8)
    straight = np.zeros(7)
    assert external_wrench(robot, straight, np.ones(7), "flange").damped


def test_wrench_of_fewer_than_six_joints_is_least_norm_not_flagged_singular():
    """Regression (a 5-joint arm: damped on 99 % of samples, called near a singularity):
    at a frame 5 or 3 joints move, the wrench is the least-norm one in L^2 |f|^2 + |m|^2
    (closed form W^-1 J (J^T W^-1 J)^-1 r), explains r exactly, is flagged only near a
    singular pose, and a note says what is determined."""
    from dynid.observer.wrench import chain_length, external_wrench, underdetermined_note

    robot = dynid.panda()
    q, _, _ = random_states(robot, 30, seed=12)
    r = np.random.default_rng(13).normal(size=(30, 7))
    for frame, k in (("link5", 5), ("link3", 3)):
        J = dynid.jacobian(robot, q, frame)[..., :k]
        r_k = r[:, :k]  # the joints after the frame feel nothing
        est = external_wrench(robot, q, r * (np.arange(7) < k), frame)
        assert est.determined == k
        ok = ~est.damped
        assert ok.sum() >= 25
        Winv = np.diag(np.repeat([chain_length(robot, frame) ** -2, 1.0], 3))
        Jt = np.swapaxes(J, -1, -2)
        ref = (Winv @ J @ np.linalg.solve(Jt @ Winv @ J, r_k[..., None]))[..., 0]
        np.testing.assert_allclose(est.wrench[ok], ref[ok], rtol=0, atol=1e-8)
        back = (Jt @ est.wrench[..., None])[..., 0]
        np.testing.assert_allclose(back[ok], r_k[ok], rtol=0, atol=1e-8)
        note = underdetermined_note(robot, frame)
        assert note is not None and f"{k} of the 6 wrench components" in note
        assert "least-norm" in note and "singular" not in note.split("'damped'")[0]
    assert underdetermined_note(robot, "flange") is None


def test_wrench_flags_do_not_depend_on_the_arm_size():
    """Regression (a 0.4 m arm damped on 99 % of samples by a threshold set for a 1 m
    one): the Panda shrunk to 0.4 of its size flags the same samples, with the same
    moments and the forces over 0.4 (its levers are 0.4 as long)."""
    from dataclasses import replace

    from dynid.model.robot import Frame
    from dynid.observer.wrench import external_wrench

    robot = dynid.panda()
    c = 0.4
    T = np.array(robot.T_parent_joint)
    T[..., :3, 3] *= c
    frames = {}
    for name, f in robot.frames.items():
        Tf = np.array(f.T_link_frame)
        Tf[:3, 3] *= c
        frames[name] = Frame(f.link, Tf, f.joint)
    small = replace(robot, T_parent_joint=T, frames=frames)
    q, _, _ = random_states(robot, 40, seed=14)
    r = np.random.default_rng(15).normal(size=(40, 7))
    for frame in ("flange", "link5"):
        big, tiny = external_wrench(robot, q, r, frame), external_wrench(small, q, r, frame)
        np.testing.assert_array_equal(tiny.damped, big.damped)
        assert 0 < (~big.damped).sum()
        np.testing.assert_allclose(tiny.wrench[:, :3] * c, big.wrench[:, :3], rtol=1e-9)
        np.testing.assert_allclose(tiny.wrench[:, 3:], big.wrench[:, 3:], rtol=1e-9)


def test_observer_refuses_bad_inputs_with_the_documented_errors():
    """NaN (NonFiniteError), a time that does not increase (DataError, the state kept), a
    wrong shape (ShapeError), bad gains and options (OptionError)."""
    from dynid.exceptions import DataError, NonFiniteError, OptionError, ShapeError

    model = from_robot(dynid.panda())
    obs = MomentumObserver(model)
    q = np.full(7, 0.1)
    obs.step(q, q, q, 0.0)
    r1 = obs.step(q, q, q, 0.001)
    with pytest.raises(DataError, match="t must increase"):
        obs.step(q, q, q, 0.001)
    with pytest.raises(NonFiniteError):
        obs.step(np.full(7, np.nan), q, q, 0.002)
    with pytest.raises(ShapeError):
        obs.step(q[:6], q, q, 0.002)
    np.testing.assert_array_equal(obs.residual, r1)  # nothing above moved the state
    assert obs.step(list(q), q, q, 0.002).shape == (7,)  # a list is validated, then taken
    with pytest.raises(DataError, match="sample 2"):
        observe(model, [0.0, 0.1, 0.1], np.zeros((3, 7)), np.zeros((3, 7)), np.zeros((3, 7)))
    with pytest.raises(OptionError, match="K_O"):
        ObserverOptions(gain=-1.0)
    with pytest.raises(OptionError, match="discretisation"):
        ObserverOptions(discretisation="tustin")
    with pytest.raises(ShapeError, match="observer gains"):
        MomentumObserver(model, ObserverOptions(gain=(1.0, 2.0)))
    with pytest.raises(OptionError, match="contact window"):
        Contact("link5", (0.0, 0.0, 1.0), 2.0, 1.0)


def test_the_std_filter_kernel_gives_lfilters_numbers_bit_for_bit(monkeypatch):
    """The compiled first-order filter of the residual's std is scipy.signal.lfilter with
    ``b = [gam]``, ``a = [1, gam - 1]`` from the same state, bit for bit (NaN included),
    its final state too; so is the fallback without the kernels."""
    import scipy.signal

    from dynid import _kernels
    from dynid.observer.residual import first_order_filtered

    compiled = _kernels.load("observer") is not None
    rng = np.random.default_rng(7)
    for _ in range(20):
        m, n, r = int(rng.integers(1, 200)), int(rng.integers(1, 8)), int(rng.integers(1, 40))
        gam = -np.expm1(-rng.uniform(1.0, 200.0, n) * 1e-3)
        x = rng.standard_normal((m, n, r)) * 10.0 ** rng.uniform(-4, 4)
        x[rng.integers(0, m), 0, 0] = np.nan
        z0 = rng.standard_normal((n, r))
        want, zw = np.empty_like(x), np.empty_like(z0)
        for j in range(n):
            want[:, j, :], zf = scipy.signal.lfilter(
                [gam[j]], [1.0, gam[j] - 1.0], x[:, j, :], axis=0, zi=z0[j][None]
            )
            zw[j] = zf[0]
        for kernels in (True, False) if compiled else (False,):
            with monkeypatch.context() as mp:
                if not kernels:
                    mp.setitem(_kernels.CACHE.modules, "observer", None)
                got, z = np.empty_like(x), z0.copy()
                first_order_filtered(gam, x, z, got)
            assert np.array_equal(got, want, equal_nan=True), kernels
            assert np.array_equal(z, zw, equal_nan=True), kernels


def test_another_friction_keeps_every_other_field():
    """ObserverModel.with_friction replaces the friction alone: the torque delay and the
    logs' reading the model was identified with stay (a copy field by field dropped them)."""
    read = object()  # the identification's LogInfo, opaque here
    model = dataclasses.replace(from_robot(dynid.panda()), torque_delay_s=0.003, logs_read=read)
    other = model.with_friction(None)
    assert other.friction is None and other.torque_delay_s == 0.003
    assert other.logs_read is read and other.robot is model.robot
