"""The torques' lag behind the positions: read from a fit's residual
(:mod:`dynid.identification.torque_delay`, :mod:`dynid.friction.delay_check`) and taken out
before filtering (``torque_delay_s``, :func:`~dynid.identification.prepare.states_in_step`),
against a simulated Panda whose torques lag by a known 2 ms (classical friction the model
holds, sensor noise) and against closed forms."""

from __future__ import annotations

import dataclasses
import warnings

import numpy as np
import pytest

from dynid.exceptions import DynidWarning, OptionError
from dynid.friction.delay_check import logs_delay
from dynid.friction.model import ClassicalFriction
from dynid.friction.validation import own_friction, validate_torques
from dynid.identification.log import TorqueLog
from dynid.identification.prepare import Preprocessing, prepare_log, states_in_step
from dynid.identification.selection import identify_recordings
from dynid.identification.structure import Structure
from dynid.identification.torque_delay import torque_delay
from dynid.io.model_json import load_model_json, save_model_json
from dynid.simulation.measurement import SensorNoise, sample_times, simulate_measurement
from dynid.simulation.trajectories import random_fourier
from dynid.workflows.identify import IdentifyOptions

DELAY = 0.002  # s
VISCOUS = np.array([0.6, 0.5, 0.4, 0.4, 0.15, 0.12, 0.1])  # N m s/rad
COULOMB = np.array([0.8, 0.7, 0.6, 0.6, 0.3, 0.25, 0.2])  # N m
NOISE = SensorNoise(tau_std=0.05, q_std=1e-5, dq_std=1e-3)
STRUCTURE = "viscous + coulomb"


def _log(panda, seed: int, delay: float) -> TorqueLog:
    """6 s of the Panda at 500 Hz on the Fourier trajectory of ``seed``, classical
    friction and sensor noise, its torques those of ``delay`` [s] earlier (the same noise
    drawn at the delayed and the true instants)."""
    t = sample_times(6.0, 500.0)
    traj = random_fourier(panda, np.random.default_rng(seed))
    fr = ClassicalFriction(VISCOUS, COULOMB, np.zeros(7))

    def at(times: np.ndarray) -> TorqueLog:
        rng = np.random.default_rng(seed + 100)
        return simulate_measurement(panda, traj(times), rng=rng, noise=NOISE, friction=fr)

    log = at(t)
    return log if delay == 0 else dataclasses.replace(log, tau=at(t - delay).tau)


def _fit(panda, logs, delay: float = 0.0):
    """The model of :data:`STRUCTURE` fitted to ``logs`` with ``torque_delay_s=delay``."""
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", DynidWarning)
        return identify_recordings(
            panda, logs, structure=Structure.parse(STRUCTURE), torque_delay_s=delay
        )


@pytest.fixture(scope="module")
def late(panda):
    """Two recordings to fit and one to judge, their torques 2 ms late."""
    return [_log(panda, s, DELAY) for s in (71, 72, 73)]


@pytest.fixture(scope="module")
def fits(panda, late):
    """The fits of the late recordings without and with ``torque_delay_s``."""
    return _fit(panda, late[:2]), _fit(panda, late[:2], DELAY)


def _viscous(model) -> tuple[np.ndarray, np.ndarray]:
    """Each joint's viscous coefficient [N m s/rad] and its standard deviation."""
    term = model.terms["friction"]
    idx = [term.labels.index(f"fv{j + 1}") for j in range(7)]
    return term.values[idx], term.std[idx]


def test_states_in_step_is_earlier_states() -> None:
    """The states read ``delay`` earlier: a sine's positions and velocities at ``t -
    delay`` to the spline's error; the torques untouched; no delay returns the log."""
    t = np.arange(0.0, 2.0, 0.002)
    w = 2 * np.pi * np.array([0.5, 1.3])
    q, dq = np.sin(w * t[:, None]), w * np.cos(w * t[:, None])
    tau = np.random.default_rng(5).normal(size=q.shape)
    log = TorqueLog(t=t, q=q, dq=dq, tau=tau)
    moved = states_in_step(log, 0.003)
    inner = slice(5, -5)
    np.testing.assert_allclose(moved.q[inner], np.sin(w * (t[inner, None] - 0.003)), atol=1e-9)
    np.testing.assert_allclose(moved.dq[inner], w * np.cos(w * (t[inner, None] - 0.003)), atol=1e-7)
    np.testing.assert_array_equal(moved.tau, tau)
    assert states_in_step(log, 0.0) is log


def test_delay_trims_the_ends_it_moves_past() -> None:
    """A delay longer than the filter's edge trims at least that much at each end."""
    t = np.arange(0.0, 1.0, 0.01)
    log = TorqueLog(t=t, q=np.sin(t)[:, None], dq=np.cos(t)[:, None], tau=np.sin(t)[:, None])
    out = prepare_log(log, Preprocessing(cutoff_hz=None, torque_delay_s=0.035))
    assert out.t[0] >= 0.035 - 1e-12 and out.t[-1] <= t[-1] - 0.035 + 1e-12


def test_closed_form_delay_of_a_sine() -> None:
    """A residual that is exactly ``-delta d(tau)/dt`` of a sine gives ``delta``."""
    t = np.arange(0.0, 4.0, 0.002)
    tau = np.column_stack([np.sin(3 * t), 2 * np.cos(2 * t)])
    rng = np.random.default_rng(8)
    e = -0.004 * np.gradient(tau, t, axis=0) + 1e-4 * rng.normal(size=tau.shape)
    found = torque_delay([t], [tau], [e])
    assert found is not None
    assert abs(found.delay_s - 0.004) < 3 * found.std_s + 1e-6
    assert found.named


def test_estimates_a_two_ms_delay(panda, late, fits) -> None:
    """The 2 ms delay read from the fit's residual to within 0.3 ms, and named."""
    found = logs_delay(fits[0], late[:2])
    assert found is not None
    assert abs(found.delay_s - DELAY) < 3e-4, found
    assert found.named
    assert f"--torque-delay {1e3 * found.delay_s:.2g}" in found.sentence()


def test_torque_delay_restores_viscous_and_heldout(panda, late, fits) -> None:
    """With ``torque_delay_s`` the viscous coefficients are within 3 std of the truth
    (joint 2's is not without it), the delay left is not named and the held-out error
    on the third recording drops."""
    plain, shifted = fits
    fv, sd = _viscous(shifted)
    assert np.all(np.abs(fv - VISCOUS) < 3 * sd), (fv, sd)
    fv0, sd0 = _viscous(plain)
    assert abs(fv0[1] - VISCOUS[1]) > 3 * sd0[1]
    left = logs_delay(shifted, late[:2])
    assert left is not None and not left.named

    def heldout(model) -> float:
        v = validate_torques(model, late[2], friction=own_friction(model))
        return float(np.sqrt(np.mean((v.log.tau - v.tau_model - v.tau_friction) ** 2)))

    assert heldout(shifted) < 0.97 * heldout(plain)


def test_no_delay_no_false_alarm(panda) -> None:
    """Recordings in step, noisy, with friction the model holds: no delay named."""
    logs = [_log(panda, s, 0.0) for s in (74, 75)]
    found = logs_delay(_fit(panda, logs), logs)
    assert found is not None
    assert not found.named, found


def test_delay_recorded_and_reused(tmp_path, fits) -> None:
    """identification.json records the delay; the model read back prepares with it."""
    path = save_model_json(tmp_path / "identification.json", fits[1])
    back = load_model_json(path)
    assert back.info.log is not None
    assert back.info.log.preprocessing.torque_delay_s == pytest.approx(DELAY)


def test_option_refused_with_consistent() -> None:
    """``torque_delay_s`` does not apply to the one-step consistent fit."""
    with pytest.raises(OptionError, match="consistent"):
        IdentifyOptions(torque_delay_s=0.002, consistent=True)


def test_friction_prepares_with_the_recorded_delay(fits, late) -> None:
    """``friction``'s pieces of a model identified with a delay hold the states that
    much earlier (``q - delay dq`` to second order) unless told 0."""
    from dynid.friction.recordings import prepare_pieces

    with warnings.catch_warnings():
        warnings.simplefilter("ignore", DynidWarning)
        moved = prepare_pieces(fits[1], [late[2]]).logs[0]
        kept = prepare_pieces(fits[1], [late[2]], torque_delay_s=0.0).logs[0]
    np.testing.assert_array_equal(moved.t, kept.t)
    assert moved.ddq is not None
    want = kept.q - DELAY * kept.dq
    assert np.max(np.abs(moved.q - want)) < 2 * DELAY**2 * np.max(np.abs(kept.ddq))


def test_command_line_reads_milliseconds() -> None:
    """``--torque-delay 2`` is 0.002 s for identify, validate and friction, and in the
    options identify and friction build from the flags."""
    from dynid.cli.__main__ import build_parser
    from dynid.cli.common import options_from
    from dynid.workflows.friction import FrictionOptions

    parser = build_parser()
    for command, cls, need in (
        ("identify", IdentifyOptions, ["--robot", "panda"]),
        ("validate", None, ["--model", "m.json"]),
        ("friction", FrictionOptions, ["--model", "m.json"]),
    ):
        given = [command, *need, "--data", "x.csv", "--out", "o", "--torque-delay", "2"]
        args = parser.parse_args(given)
        assert args.torque_delay == pytest.approx(0.002)
        if cls is not None:
            assert options_from(args, cls).torque_delay_s == pytest.approx(0.002)


def test_every_k_th_row_reads_the_same_delay_as_every_row():
    """Torques 3 ms late on smooth motion at 1 kHz (closed form: the residual is
    -delta d(tau)/dt plus white noise): fitted on every 4th row (the derivative taken at
    the full rate), the delay is the one every row gives, within twice its standard
    deviation, and both within 3 std of the truth."""
    rng = np.random.default_rng(7)
    t = np.arange(30_000) / 1000.0
    w = np.array([0.7, 1.3, 2.1])
    tau = np.sin(np.outer(t, w) + np.array([0.0, 1.0, 2.0])) * np.array([10.0, 5.0, 2.0])
    late = np.sin(np.outer(t - 0.003, w) + np.array([0.0, 1.0, 2.0])) * np.array([10.0, 5.0, 2.0])
    error = late - tau + rng.normal(0.0, 0.05, tau.shape)
    full = torque_delay([t], [tau], [error], lag=5)
    sub = torque_delay([t], [tau], [error], lag=5, every=4)
    assert full is not None and sub is not None
    assert abs(full.delay_s - 0.003) < 3 * full.std_s
    assert abs(sub.delay_s - 0.003) < 3 * sub.std_s
    assert abs(sub.delay_s - full.delay_s) < 2 * sub.std_s and sub.std_s < 3 * full.std_s


def test_observe_takes_the_model_s_delay_out_of_a_free_log(tmp_path, panda, fits) -> None:
    """``observe`` prepares a log with the delay its model was identified with (2 ms):
    on a collision-free log, torques 2 ms late, the residual (the truth's external torque
    0) is smaller than with ``--torque-delay 0``; ``--torque-delay 2`` reads 0.002 s and
    gives the same."""
    from dynid.cli.__main__ import build_parser
    from dynid.io.torque_log import save_torque_log
    from dynid.workflows.observe import ObserveOptions, observe_files

    model = save_model_json(tmp_path / "identification.json", fits[1])
    t = sample_times(6.0, 500.0)  # a log without noise: what is left is the model's error
    traj = random_fourier(panda, np.random.default_rng(76))
    fr = ClassicalFriction(VISCOUS, COULOMB, np.zeros(7))
    quiet = SensorNoise(tau_std=0.0, q_std=0.0, dq_std=0.0)
    rng = np.random.default_rng(76)
    free = simulate_measurement(panda, traj(t), rng=rng, noise=quiet, friction=fr)
    free = dataclasses.replace(free, tau=simulate_measurement(
        panda, traj(t - DELAY), rng=rng, noise=quiet, friction=fr).tau)  # fmt: skip
    data = save_torque_log(tmp_path / "free.csv", free)
    args = build_parser().parse_args(
        ["observe", "--model", "m.json", "--data", "x.csv", "--calibrate", "--out", "o",
         "--torque-delay", "2"]
    )  # fmt: skip
    assert args.torque_delay == pytest.approx(DELAY)

    def rms(delay: float | None) -> np.ndarray:
        opts = ObserveOptions(data=(data,), model=model, calibrate=True, uncertainty=False,
                              torque_delay_s=delay)  # fmt: skip
        with warnings.catch_warnings():
            warnings.simplefilter("ignore", DynidWarning)
            (log,) = observe_files(opts).logs
        assert log.r is not None
        return np.sqrt(np.nanmean(np.square(log.r), axis=0))

    recorded, given, none = rms(None), rms(DELAY), rms(0.0)
    np.testing.assert_array_equal(recorded, given)
    assert np.sqrt(np.mean(recorded**2)) < 0.5 * np.sqrt(np.mean(none**2))


@pytest.mark.parametrize("delay_ms", [2.9, 5.0])
def test_observe_moving_the_states_finds_no_position_jump(panda, delay_ms):
    """Regression: a clean log prepared for the observer with its states read 2.9 or 5 ms
    earlier warned "position jumps more than the recorded velocity explains (joint 2 ...
    at t = 0.002 s)": the spline's extrapolated first samples were checked for jumps. The
    jumps are looked for in the log as recorded; the moved ends are left unobserved."""
    from pathlib import Path

    from dynid.observer.model import from_robot
    from dynid.workflows.observe_logs import prepared_log

    t = sample_times(3.0, 500.0)
    traj = random_fourier(panda, np.random.default_rng(81))
    log = simulate_measurement(panda, traj(t), rng=np.random.default_rng(82))  # sensor noise
    with warnings.catch_warnings():
        warnings.simplefilter("error", DynidWarning)
        prep = prepared_log(
            Path("sim.csv"), log, from_robot(panda), None, torque_delay_s=delay_ms / 1e3
        )
    (span,) = prep.spans
    assert prep.log.t[span[0]] >= delay_ms / 1e3 and prep.log.t[span[1] - 1] <= 3.0 - delay_ms / 1e3


def test_the_model_columns_are_projected_out_as_by_lstsq_with_its_rank_cut():
    """The delay's and the residual's parts the model's columns take (a tall matrix with a
    repeated column, rank 29 of 30) are numpy lstsq's at rcond 1e-10: the same fitted
    columns from the blocked triangular factor."""
    from dynid.identification.torque_delay import _projected

    rng = np.random.default_rng(5)
    A = rng.normal(size=(9000, 30))
    A[:, 7] = A[:, 3]
    A /= np.linalg.norm(A, axis=0)
    B = A @ rng.normal(size=(30, 2)) + rng.normal(size=(9000, 2))
    ref = np.linalg.lstsq(A, B, rcond=1e-10)[0]
    np.testing.assert_allclose(A @ _projected(A, B), A @ ref, rtol=0, atol=1e-12)
