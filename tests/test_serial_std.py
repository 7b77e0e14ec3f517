"""Standard deviations for serially correlated residuals (``std="hac"``,
:mod:`dynid.identification.serial`): the Bartlett meat against its definition, blocks against
rows held whole, and the reported standard deviations against the spread of the estimates
over noise seeds of one simulated arm (a filtered, decimated log: coloured residuals)."""

from __future__ import annotations

import warnings

import numpy as np

from dynid.identification.engine import HeldRows, fit_rows
from dynid.identification.estimators import OLS, WLS
from dynid.identification.selection import identify_recordings
from dynid.identification.serial import Serial, SerialMeat, hac_lag, serial_meat
from dynid.identification.streamed import fit_streamed
from dynid.identification.structure import Structure
from dynid.simulation.measurement import (
    SensorNoise,
    UnmodelledEffects,
    sample_times,
    simulate_measurement,
)
from dynid.simulation.trajectories import random_fourier

from conftest import planar_2r


def _bartlett(scores: np.ndarray, serial: Serial) -> np.ndarray:
    """Newey-West's sum over the lags, pair by pair, within each piece (the reference)."""
    n, L = serial.rows_per_sample, serial.lag
    ends = [*serial.starts[1:], scores.shape[0]]
    out = np.zeros((scores.shape[1],) * 2)
    for a, b in zip(serial.starts, ends, strict=True):
        S = scores[a:b].reshape(-1, n, scores.shape[1]).sum(axis=1)
        out += S.T @ S
        for lag in range(1, L + 1):
            G = S[lag:].T @ S[:-lag]
            out += (1 - lag / (L + 1)) * (G + G.T)
    return out


def test_meat_is_bartlett_sum_within_pieces() -> None:
    """The moving-sum meat, fed in uneven blocks, equals Newey-West's lag sum per piece."""
    rng = np.random.default_rng(0)
    serial = Serial(rows_per_sample=3, lag=4, starts=(0, 30, 96))
    scores = rng.normal(size=(150, 5))
    acc = SerialMeat(serial, 5)
    for a, b in [(0, 7), (7, 31), (31, 32), (32, 150)]:  # blocks cut inside samples
        acc.add(scores[a:b])
    np.testing.assert_allclose(acc.result(), _bartlett(scores, serial), rtol=1e-12, atol=1e-12)


def test_products_fed_in_blocks_are_bartlett_sum_within_pieces() -> None:
    """Rows and residuals fed as products (whole samples summed without the scores written
    out, blocks cut inside samples and across pieces, leading columns zero) give Newey-West's
    lag sum per piece, at a window and without one."""
    rng = np.random.default_rng(2)
    W, e = rng.normal(size=(150, 5)), rng.normal(size=150)
    W[:40, :2] = 0.0  # the rows of the first blocks start at column 2
    for lag in (0, 4):
        serial = Serial(rows_per_sample=3, lag=lag, starts=(0, 30, 96))
        blk = np.array([[0, 7, 2], [7, 40, 2], [40, 41, 0], [41, 150, 0]])
        got = serial_meat(W, blk, e, serial)
        ref = _bartlett(W * e[:, None], serial)
        np.testing.assert_allclose(got, ref, rtol=1e-12, atol=1e-12)


def test_lag_zero_one_row_is_hc1() -> None:
    """Window 0, one row a sample: the meat is White's ``W^T diag(e^2) W``."""
    rng = np.random.default_rng(1)
    W, e = rng.normal(size=(40, 3)), rng.normal(size=40)
    blk = np.array([[0, 40, 0]])
    np.testing.assert_allclose(
        serial_meat(W, blk, e, Serial()), (W * e[:, None]).T @ (W * e[:, None])
    )


def test_lag_from_cutoff() -> None:
    """Two periods of the cut-off at the decimated rate; none without a filter."""
    assert hac_lag(5.0, 50.0) == 20
    assert hac_lag(None, 1000.0) == 0


def _ar_rows(seed: int, n_samples: int = 600, n: int = 2) -> tuple[np.ndarray, np.ndarray]:
    """Smooth regressor rows of ``n`` joints a sample with AR(1) errors (rho 0.8)."""
    rng = np.random.default_rng(seed)
    t = np.arange(n_samples) / 50.0
    W = np.column_stack([np.sin(t), np.cos(0.7 * t), np.ones_like(t)])
    W = np.repeat(W, n, axis=0) * rng.uniform(0.5, 1.5, (n * n_samples, 1))
    u = rng.normal(size=n * n_samples)
    e = np.empty_like(u)
    e[:n] = u[:n]
    for k in range(n, u.size):
        e[k] = 0.8 * e[k - n] + 0.6 * u[k]
    return W, W @ np.array([1.0, -2.0, 0.5]) + e


def test_blocks_equal_rows_held() -> None:
    """Rows read in blocks give the HAC standard deviations of the rows held (OLS, WLS)."""
    W, y = _ar_rows(3)
    g = np.tile(np.arange(2), y.size // 2)
    serial = Serial(2, 6, (0, 500))
    blocks = [(0, 210), (210, 500), (500, 1200)]
    source = lambda: ((W[a:b], y[a:b], g[a:b]) for a, b in blocks)  # noqa: E731
    for est in (OLS(), WLS()):
        held = fit_rows(HeldRows(W, y, g, serial=serial), est, rtol=1e-10, std="hac")
        streamed = fit_streamed(source, est, rtol=1e-10, std="hac", serial=serial)
        np.testing.assert_allclose(streamed.std, held.std, rtol=1e-9)


def _identified_2r(seeds: range, std: str) -> tuple[np.ndarray, np.ndarray]:
    """Estimates and reported standard deviations (seeds, c) of a planar 2R arm, one
    trajectory, 20 s at 500 Hz, sensor noise drawn per seed; its torques filtered and
    decimated (cut-off from the motion, 5.5 Hz; every 9th sample kept)."""
    robot = planar_2r()
    traj = random_fourier(robot, np.random.default_rng(3))(sample_times(20.0, 500.0))
    effects = UnmodelledEffects(rotor_inertia=np.full(2, 0.02), torque_offset=np.zeros(2))
    structure = Structure(True, ("viscous", "coulomb"))
    betas, stds = [], []
    for s in seeds:
        log = simulate_measurement(
            robot, traj, rng=np.random.default_rng(1000 + s), noise=SensorNoise(),
            friction=None, effects=effects,
        )  # fmt: skip
        with warnings.catch_warnings():
            warnings.simplefilter("ignore")
            fit = identify_recordings(robot, [log], structure=structure, std=std).joint_fit
        assert fit is not None
        betas.append(fit.beta)
        stds.append(fit.std)
    return np.array(betas), np.array(stds)


def test_hac_std_matches_spread_over_seeds() -> None:
    """Coloured residuals: the reported (HAC) standard deviation of every coefficient
    matches the spread of the estimates over 60 noise seeds within [0.7, 1.4]; the
    classical ones understated it about 2.2 times (0.88 for one small Coulomb level)."""
    B, S = _identified_2r(range(60), "hac")
    ratio = B.std(axis=0, ddof=1) / np.sqrt(np.mean(S**2, axis=0))
    # 60 seeds: the empirical std's relative error is 1 / sqrt(118) ~ 9 %; 3.5 of them
    assert np.all((ratio > 0.7) & (ratio < 1.4)), ratio
    assert 0.85 < np.median(ratio) < 1.2, ratio


def test_structure_search_stds_follow_the_models() -> None:
    """The search's dissipation check scales the candidates' classical standard deviations
    (from normal equations) to the model's own: 1 for a model fitted with classical ones,
    above 1.4 on every coefficient of a filtered log fitted with HAC ones."""
    from dynid.identification.candidates import std_inflation

    robot = planar_2r()
    traj = random_fourier(robot, np.random.default_rng(3))(sample_times(20.0, 500.0))
    log = simulate_measurement(
        robot, traj, rng=np.random.default_rng(7), noise=SensorNoise(), friction=None
    )
    structure = Structure(True, ("viscous",))
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        classical = identify_recordings(robot, [log], structure=structure, std="classical")
        hac = identify_recordings(robot, [log], structure=structure)
    np.testing.assert_allclose(std_inflation(classical, 1e-10), 1.0, rtol=1e-8)
    assert np.all(std_inflation(hac, 1e-10) > 1.4)
