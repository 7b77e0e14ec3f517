"""The momentum observer against truths: Pinocchio's M, C and g, the regressor path, a
simulated contact's external torque, the first-order lag and the friction laws."""

from __future__ import annotations

import numpy as np
import pytest

import dynid
from dynid.friction.laws import LAWS
from dynid.friction.model import DriveFriction
from dynid.identification.least_squares import LeastSquaresFit
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

from conftest import pinocchio_panda_urdf, random_states

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
    r = base.rank
    fit = LeastSquaresFit(
        beta=beta, std=std, std_percent=100 * std / np.abs(beta), kept=np.ones(r, bool),
        rank=r, condition_number=1.0, relative_error_percent=0.0, residual_rms=0.0,
        sigma=0.0, n_rows=0, rtol=1e-10, covariance=np.diag(std**2),
    )  # fmt: skip
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
            np.testing.assert_allclose(f, fr.torques(dq), rtol=0, atol=1e-12)
