"""The observer on a geared arm (gear ratios 50 to 100, rotor inertias, a coupled wrist,
a steep sigmoid friction at the motors): on exact data the residual is the lagged external
torque, and with sensor noise the calibration's thresholds stay near the noise while the
motors' friction, evaluated at noisy velocities, swings by its whole step at reversals."""

from __future__ import annotations

import numpy as np
import pytest

import dynid
from dynid.friction.laws import LAWS
from dynid.friction.model import LawFriction
from dynid.identification.log import TorqueLog, joint_side_log
from dynid.model.drive import Drive
from dynid.observer import from_identified, from_robot, observe
from dynid.observer.detection import calibrate, detect, standstill_series
from dynid.observer.friction import standstill_margin
from dynid.observer.residual import ObserverOptions, first_order_lag
from dynid.simulation.measurement import SensorNoise, simulate_measurement
from dynid.simulation.trajectories import random_fourier, uniform_times

GEARS = [100.0, 100.0, 80.0, 80.0, 50.0, 50.0, 50.0]
ROTORS = [1.5e-4, 1.5e-4, 1e-4, 1e-4, 3e-5, 3e-5, 2e-5]
PHI = [[8.0, 30.0, 0.0]] * 4 + [[2.0, 30.0, 0.0]] * 3  # sigmoid per motor: N m, s/rad, rad/s
HIT = (2.0, 2.5, 0, 93.6)  # a step contact: start, end [s], joint (0-based), torque [N m]
K_O = 50.0


def _drive() -> Drive:
    return Drive.from_gears(
        GEARS, [(7, 6, 50.0)], side="joint", rotor_inertia=np.array(ROTORS), friction_at="motor"
    )


def _friction(drive: Drive) -> LawFriction:
    return LawFriction(LAWS["sigmoid"], np.array(PHI), drive=drive)


def _log(
    seed: int, noise: SensorNoise, contact: bool = False, fs: float = 1000.0
) -> tuple[TorqueLog, np.ndarray]:
    """A 5 s joint-side log of the Panda behind the drive, with the true external torques
    (N, 7) a step contact takes from the measured torques."""
    robot, drive = dynid.panda(), _drive()
    rng = np.random.default_rng(seed)
    traj = random_fourier(robot, rng, n_harmonics=3, w_f=2 * np.pi * 0.1)(uniform_times(5.0, fs))
    log = simulate_measurement(
        robot, traj, rng=rng, noise=noise, friction=_friction(drive), drive=drive
    )
    log = joint_side_log(log, drive)
    ext = np.zeros_like(log.tau)
    if contact:
        a, b, j, size = HIT
        ext[(log.t >= a) & (log.t < b), j] = size
    return TorqueLog(t=log.t, q=log.q, dq=log.dq, tau=log.tau - ext), ext


@pytest.fixture(scope="module")
def model():
    drive = _drive()
    return from_robot(dynid.panda(), friction=_friction(drive), drive=drive)


def test_exact_data_give_the_lagged_external_torque(model):
    """No noise: the residual is the external step through K_O / (s + K_O) (the closed
    form, first_order_lag), with and without the contact, off by the trapezoid rule's
    truncation alone: below 1e-7 of the largest torque at 1 kHz and four times smaller at
    2 kHz (second order: no model error left)."""
    opts = ObserverOptions(gain=K_O)
    for contact in (False, True):
        err = []
        for fs in (1000.0, 2000.0):
            log, ext = _log(1, SensorNoise(tau_std=0.0, q_std=0.0, dq_std=0.0), contact, fs)
            r = observe(model, log.t, log.q, log.dq, log.tau, opts).r
            truth = first_order_lag(log.t, ext, K_O)
            err.append(np.max(np.abs(r - truth)))
            scale = float(np.max(np.abs(log.tau)))
        assert err[0] < 1e-7 * scale and 3.5 < err[0] / err[1] < 4.5


def test_motor_sigmoid_at_noisy_velocities_is_bounded_not_calibrated(model):
    """With sensor noise the friction at the measured motor velocities swings by up to its
    whole step (phi1 times the gear) near each reversal. Read as collision-free residual it
    raised the thresholds above the 93.6 N m contact (the defect); its bound within the
    velocity noise band is left out of the calibration and added near reversals only: the
    thresholds stay within 3 N m (a few residual noise levels), the contact is found
    within the delay of a step contact and a separate free log raises nothing."""
    opts = ObserverOptions(gain=K_O)
    cal, _ = _log(3, SensorNoise())
    free, _ = _log(2, SensorNoise())
    hit, _ = _log(4, SensorNoise(), contact=True)
    runs = {}
    for name, log in (("cal", cal), ("free", free), ("hit", hit)):
        r = np.asarray(observe(model, log.t, log.q, log.dq, log.tau, opts).r)
        runs[name] = (log, r, standstill_series(model, log.t, log.dq, opts))
    log, r, w = runs["cal"]
    plain = calibrate([r], opts)
    a, b, j, size = HIT
    assert plain.contact[j] > size  # the defect: a 93.6 N m contact below the threshold
    th = calibrate([r], opts, standstill=[w])
    assert np.all(th.contact < 3.0)
    log, r, w = runs["free"]
    assert detect(log.t, r, th, standstill=w) == []
    log, r, w = runs["hit"]
    (event,) = detect(log.t, r, th, standstill=w)
    k = int(np.searchsorted(log.t, a))
    theta = th.contact[j] + w[k : k + 50, j].max()  # over the next 50 ms
    delay = np.log(size / (size - theta)) / K_O + 1e-3  # one sample
    assert a <= event.start <= a + delay and (j + 1) in event.joints


def test_the_noise_bound_of_a_sigmoid_is_its_change_across_the_band():
    """A sigmoid phi1 sigma(phi2 v) of a motor behind a gear: at v (motor) the bound is the
    larger of |f(v + b) - f(v)| and |f(v - b) - f(v)| (the closed form), times the gear at
    the joint; none without a band."""
    drive = Drive.from_gears([100.0], friction_at="motor")
    fr = LawFriction(LAWS["sigmoid"], np.array([[2.0, 30.0, 0.0]]), drive=drive)
    b = 0.05  # rad/s at the motor
    vm = np.array([0.0, 0.02, -0.1, 1.0])

    def f(v):
        return 2.0 / (1.0 + np.exp(-30.0 * v))

    want = 100.0 * np.maximum(np.abs(f(vm + b) - f(vm)), np.abs(f(vm - b) - f(vm)))
    got = standstill_margin(fr, vm[:, None] / 100.0, (np.array([b]),))[:, 0]
    np.testing.assert_allclose(got, want, rtol=1e-12, atol=1e-12)
    assert not np.any(standstill_margin(fr, vm[:, None] / 100.0))


def test_rotor_terms_give_their_own_momentum_columns():
    """An identified model whose rotor term carries its drive (a coupled wrist, rotor 7
    not held) while the model has none: the observer asks the term, so ``p`` and the
    momentum regressor over the base parameters both equal ``M_links dq + K^T diag(I_a) K
    dq`` (the closed form; the drive's labels are not the model's to match)."""
    from dynid.dynamics.terms import mass_matrix
    from dynid.identification.least_squares import LeastSquaresFit
    from dynid.identification.model import IdentifiedModel, IdentifiedTerm
    from dynid.observer.terms import base_momentum_regressor, momentum_terms
    from dynid.regressors.base import base_parameters
    from dynid.regressors.terms import RotorInertia

    robot, drive = dynid.panda(), Drive.from_gears(GEARS, [(7, 6, 50.0)])
    held = (True,) * 6 + (False,)
    term = RotorInertia(drive, mask=held)
    base = base_parameters(robot, kind="torque", terms=(term,))
    ia = np.array(ROTORS)
    beta = base.beta_from_phi(np.concatenate([robot.phi.reshape(-1), ia[:6]]))
    r = base.rank
    fit = LeastSquaresFit(
        beta=beta, std=np.ones(r), std_percent=np.ones(r), kept=np.ones(r, bool), rank=r,
        condition_number=1.0, relative_error_percent=0.0, residual_rms=0.0, sigma=0.0,
        n_rows=0, rtol=1e-10, covariance=np.eye(r),
    )  # fmt: skip
    blank = IdentifiedTerm(term, np.zeros(6), np.zeros(6), np.zeros(6, bool))
    ident = IdentifiedModel(robot=robot, base=base, fit=fit, terms={term.name: blank})
    assert ident.drive is None  # the term carries the drive
    obs = from_identified(ident)
    rng = np.random.default_rng(5)
    q, dq = rng.uniform(-1.0, 1.0, (6, 7)), rng.uniform(-1.0, 1.0, (6, 7))
    K = drive.transmission
    Mr = K.T @ np.diag(np.where(held, ia, 0.0)) @ K
    want = np.einsum("bij,bj->bi", mass_matrix(robot, q), dq) + dq @ Mr.T
    p, _ = momentum_terms(obs, q, dq)
    np.testing.assert_allclose(p, want, rtol=1e-10, atol=1e-12)
    Yp, _ = base_momentum_regressor(obs, q, dq)
    np.testing.assert_allclose(Yp @ beta, want, rtol=1e-10, atol=1e-12)
