"""The standstill margin on a log without velocities (derived from the positions): a
geared Panda with a sharp Coulomb friction at the motors and noisy motor positions. The
derived velocities are smooth, so the noise band estimated on them, like the standstill
band an identification on them finds, is next to zero and the margin never applied: the
motor reversals were taken for contacts. The band of the position noise through the
derivative filter bounds them: no event on free logs, the contact found at its time."""

from __future__ import annotations

import warnings
from pathlib import Path

import numpy as np
import pytest

import dynid
from dynid.friction.laws import LAWS
from dynid.friction.model import ClassicalFriction, LawFriction
from dynid.identification.log import TorqueLog, joint_side_log, with_derived_velocities
from dynid.model.drive import Drive
from dynid.observer import from_robot
from dynid.observer.detection import calibrate, detect, standstill_blocks
from dynid.observer.friction import derived_velocity_bands
from dynid.observer.residual import ObserverOptions
from dynid.signals import filtered_derivative
from dynid.simulation.measurement import SensorNoise, simulate_measurement
from dynid.simulation.trajectories import random_fourier, uniform_times
from dynid.workflows.observe_logs import observed_blocks, prepared_log

from conftest import point_to_point

GEARS = [100.0, 100.0, 100.0, 100.0, 80.0, 80.0, 80.0]
FC = [0.04, 0.04, 0.03, 0.03, 0.015, 0.015, 0.015]  # Coulomb at the motors [N m]
HIT = (3.0, 3.5, 1, 8.0)  # a step contact: start, end [s], joint (0-based), torque [N m]
Q_STD = 1e-4  # joint position noise [rad]: 1e-2 rad at a motor behind a gear of 100
OPTS = ObserverOptions()


def _friction(drive: Drive) -> LawFriction:
    params = np.array([[2e-4, fc, 0.0] for fc in FC])
    return LawFriction(LAWS["classical"], params, band=np.full(7, 1e-5), drive=drive)


def _drive() -> Drive:
    return Drive.from_gears(GEARS, side="joint", friction_at="motor")


def _log(seed: int, contact: bool = False) -> TorqueLog:
    """A 6 s log of the Panda behind the drive at 1 kHz, its velocities derived from the
    noisy positions (no velocity columns), with a step contact taken from the torques."""
    robot, drive = dynid.panda(), _drive()
    rng = np.random.default_rng(seed)
    traj = random_fourier(robot, rng, n_harmonics=2, w_f=2 * np.pi * 0.2)(uniform_times(6.0))
    noise = SensorNoise(tau_std=0.02, q_std=Q_STD, dq_std=0.0)
    log = joint_side_log(
        simulate_measurement(robot, traj, rng=rng, noise=noise, friction=_friction(drive),
                             drive=drive), drive,
    )  # fmt: skip
    tau = np.array(log.tau)
    if contact:
        a, b, j, size = HIT
        tau[(log.t >= a) & (log.t < b), j] -= size
    return with_derived_velocities(TorqueLog(t=log.t, q=log.q, dq=log.dq, tau=tau))


@pytest.fixture(scope="module")
def runs():
    """Per log: its times, residual, the margin of the derived band and the margin of
    the band estimated on the derived velocities (the defect), each over the samples
    the observer runs on."""
    drive = _drive()
    model = from_robot(dynid.panda(), friction=_friction(drive), drive=drive)
    out = {}
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        for name, seed, contact in (("cal", 1, False), ("free", 2, False), ("hit", 3, True)):
            prep = prepared_log(Path(f"{name}.csv"), _log(seed, contact), model, None)
            ((a, b),) = prep.spans
            blocks = list(observed_blocks(prep, model, OPTS, False, True))
            r = np.concatenate([x.r for x in blocks])
            w = np.zeros_like(r)
            for x in blocks:
                if x.margin is not None:
                    w[x.a - a : x.a - a + x.r.shape[0]] = x.margin
            t, dq = prep.log.t[a:b], prep.dq[a:b]
            old = np.zeros_like(r)
            for c, m in standstill_blocks(model, t, dq, OPTS):
                old[c : c + m.shape[0]] = m
            out[name] = (t, r, w, old)
    return out


def test_the_band_of_derived_velocities_is_the_position_noise_through_the_filter():
    """White position noise of std s through the derivative filter: the derived
    velocities' std (measured on a long record) times 5 is the band, at every motor
    (through the gears)."""
    drive = _drive()
    rng = np.random.default_rng(0)
    t = uniform_times(30.0)
    q = Q_STD * rng.standard_normal((t.shape[0], 7))
    (band,) = derived_velocity_bands(_friction(drive), t, q, 5.0)
    v = filtered_derivative(t, q, 5.0)[2000:-2000] * np.array(GEARS)  # motor velocities
    np.testing.assert_allclose(band, 5.0 * v.std(axis=0), rtol=0.1)


def test_no_false_event_at_motor_reversals_and_the_contact_is_found(runs):
    """Calibrated on one free log (margin 2 over its largest residual: a short log): the
    margin of the band estimated on the derived velocities left events at motor reversals
    outside the contact (the defect, as measured on a geared Panda, with the velocities
    derived at 5 Hz); the derived band's margin leaves none on a free log and the contact
    alone on the contact log, found within the observer's lag (K_O = 50/s) of its
    start."""
    _, r, w, old = runs["cal"]
    th = calibrate([r], OPTS, standstill=[w], margin=2.0)
    a, b, j, _ = HIT
    t, r, w, old = runs["hit"]
    (event,) = detect(t, r, th, standstill=w)
    assert a <= event.start <= a + 0.015 and (j + 1) in event.joints
    t, r, w, old = runs["free"]
    assert detect(t, r, th, standstill=w) == []


def test_a_log_with_rests_and_derived_velocities_raises_no_event_at_the_moves_starts():
    """A Panda with sharp Coulomb friction (1-3 N m), positions only, observed with the
    smooth law an identification on such logs chooses: calibrated on a free Fourier log,
    detection on point-to-point moves with rests. Velocities derived at 5 Hz rose 0.1-0.2 s
    before each move and crossed zero before it stopped, and the model's Coulomb step fired
    early (16 events at the moves' starts and ends); derived at the observer's cut-off
    (20 Hz), none."""
    robot = dynid.panda()
    fv, fc = np.linspace(0.6, 0.2, 7), np.linspace(3.0, 1.0, 7)
    fr = ClassicalFriction(fv, fc, np.zeros(7))
    # the law identify chooses on such logs: a smooth Coulomb 3 mrad/s wide
    smooth = LAWS["smooth"].model(np.column_stack([fv, fc, np.zeros(7)]), np.full(7, 3e-3))
    model = from_robot(robot, friction=smooth)
    noise = SensorNoise(tau_std=0.05, q_std=2e-5, dq_std=0.0)

    def observed(name: str, traj) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
        log = simulate_measurement(robot, traj, rng=np.random.default_rng(7), noise=noise,
                                   friction=fr)  # fmt: skip
        log = with_derived_velocities(TorqueLog(t=log.t, q=log.q, dq=log.dq, tau=log.tau))
        prep = prepared_log(Path(name), log, model, None)
        ((a, b),) = prep.spans
        blocks = list(observed_blocks(prep, model, OPTS, False, True))
        r = np.concatenate([x.r for x in blocks])
        w = np.zeros_like(r)
        for x in blocks:
            w[x.a - a : x.a - a + x.r.shape[0]] = x.margin
        return prep.log.t[a:b], r, w

    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        _, r, w = observed("free.csv", random_fourier(robot, np.random.default_rng(3))(
            uniform_times(10.0, 500.0)))  # fmt: skip
        th = calibrate([r], OPTS, standstill=[w])
        t, r, w = observed("moves.csv", point_to_point(robot, 4))
    assert detect(t, r, th, standstill=w) == []
