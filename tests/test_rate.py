"""The cut-off and the decimation read from the log, and the summary that says them.

References: closed-form spectra (sums of sinusoids), a noise-free held-out recording of the
simulated arm (its measured torques), the recorded file contents.
"""

from __future__ import annotations

import json

import numpy as np
import pytest

import dynid
from dynid.cli.__main__ import main
from dynid.friction.validation import own_friction
from dynid.identification.classical import auto_decimation, identify_from_log
from dynid.identification.log import DEFAULT_CUTOFF_HZ
from dynid.identification.rate import cutoff_from_motion, decimation, motion_frequency
from dynid.io.torque_log import save_torque_log
from dynid.simulation.measurement import SensorNoise, sample_times, simulate_measurement
from dynid.simulation.trajectories import random_fourier

pytestmark = pytest.mark.filterwarnings("ignore::dynid.DynidWarning")


def test_a_joint_nearly_a_trend_under_noise_does_not_read_as_fast_motion():
    """Regression: a joint whose motion is nearly a straight line over a short log keeps
    little power once the trend is removed, and its position noise (1e-4 rad) held more
    than 0.1 % of it: 1.5 s of a Panda's motion read 181 Hz and the cut-off went to
    fs / 4 (250 Hz), with accelerations as noisy as that. The noise's power is taken
    out: the sinusoids' 1.33 Hz is read, as without noise."""
    fs = 1000.0
    t = np.arange(0, 1.5, 1 / fs)
    rng = np.random.default_rng(3)
    q = np.stack(
        [0.3 * np.sin(2 * np.pi * 1.33 * t), 0.22 * t + 0.002 * np.sin(2 * np.pi * 1.33 * t)],
        axis=1,
    )
    exact = motion_frequency(q, fs)
    assert exact == pytest.approx(1.33, abs=0.7)  # the bins of 1.5 s are 0.67 Hz apart
    noisy = q + rng.normal(0.0, 1e-4, q.shape)
    assert motion_frequency(noisy, fs) == exact
    assert cutoff_from_motion(noisy, np.gradient(q, t, axis=0), fs) == pytest.approx(10 * exact)


def test_motion_frequency_of_sinusoids_and_the_cutoff_it_gives():
    fs = 1000.0
    t = np.arange(0, 20.0, 1 / fs)
    q = np.stack(
        [np.sin(2 * np.pi * 0.3 * t) + 0.5 * np.sin(2 * np.pi * 1.2 * t), 0.2 * t, 0 * t + 0.1],
        axis=1,
    )
    dq = np.gradient(q, t, axis=0)
    # joint 2 moves at constant speed (a trend, no oscillation), joint 3 never moves
    assert motion_frequency(q, fs) == pytest.approx(1.2, abs=0.1)
    assert cutoff_from_motion(q, dq, fs) == pytest.approx(12.0, abs=1.0)
    still = np.zeros_like(q) + 0.3
    assert cutoff_from_motion(still, np.zeros_like(q), fs) == DEFAULT_CUTOFF_HZ
    # never above a quarter of the rate
    fast = np.sin(2 * np.pi * 30.0 * t)[:, None]  # 10 x 30 Hz > 250 Hz
    assert cutoff_from_motion(fast, np.gradient(fast, t, axis=0), fs) == fs / 4


def test_decimation_keeps_ten_times_the_cutoff_and_a_tenth_of_the_samples():
    assert decimation(1000.0, 20.0) == 5  # 200 Hz >= 10 x 20 Hz
    assert decimation(5000.0, 5.0) == 10  # not 100: at least 10 % of the samples
    assert decimation(100.0, 20.0) == 1
    assert decimation(1000.0, None) == 1


def _traj(seed: int, fs: float, duration: float) -> tuple[np.random.Generator, object]:
    rng = np.random.default_rng(seed)
    traj = random_fourier(dynid.panda(), rng, n_harmonics=5, w_f=2 * np.pi * 0.3)
    return rng, traj(sample_times(duration, fs))


def _log(seed: int, fs: float, duration: float, noise: SensorNoise) -> dynid.TorqueLog:
    rng, traj = _traj(seed, fs, duration)
    return simulate_measurement(dynid.panda(), traj, rng=rng, noise=noise)


@pytest.mark.slow
def test_a_5_khz_log_uses_more_samples_and_predicts_better_than_the_fixed_5_hz():
    """Motion up to 1.5 Hz at 5 kHz: the cut-off from the data (about 15 Hz) keeps 10 times
    the samples of 5 Hz with its decimation, predicts a noise-free held-out recording as
    well (the friction columns are filtered as the torques are, so the low cut-off no longer
    biases the friction: both models improved by 5-12 % with that)."""
    robot = dynid.panda()
    log = _log(1, 5000.0, 10.0, SensorNoise())
    rng, traj = _traj(2, 5000.0, 5.0)
    other = simulate_measurement(robot, traj, rng=rng, noise=SensorNoise.none())
    s = slice(None, None, 10)
    q, dq, ddq, tau = traj.q[s], traj.dq[s], traj.ddq[s], other.tau[s]

    def error(model: dynid.IdentifiedModel) -> float:
        fr = own_friction(model)  # with the model's standstill band
        assert fr is not None
        pred = model.torques(q, dq, ddq) + fr.torques(dq)
        return float(np.linalg.norm(pred - tau) / np.linalg.norm(tau))

    fixed = identify_from_log(
        robot,
        log,
        cutoff_hz=5.0,
        decimate=auto_decimation(5000.0, 5.0),
        structure="classical",
        estimator="ols",
    )
    auto = identify_from_log(robot, log, structure="classical", estimator="ols")
    la, lf = auto.info.log, fixed.info.log
    assert la is not None and lf is not None
    assert la.cutoff_source == "motion" and la.cutoff_hz is not None and 10 <= la.cutoff_hz <= 20
    assert la.n_samples_used >= 10 * lf.n_samples_used
    assert error(auto) < 1.05 * error(fixed)
    # (the held-out errors inside each fit are not compared: they are relative to torques
    # filtered at different cut-offs, the lower one removing more of the sensor noise)
    assert auto.info.heldout is not None and fixed.info.heldout is not None


def test_summary_counts_validate_reuses_the_cutoff_and_resampling_is_said(tmp_path, capsys):
    """identify prints the base parameters, friction columns and rank separately, the
    cut-off it read from the log and the held-out error; validate filters with the recorded
    cut-off; a log with a gap says it was resampled."""
    log = _log(3, 500.0, 12.0, SensorNoise())
    keep = np.ones(log.n_samples, dtype=bool)
    keep[3000] = False  # one dropped sample: a gap the preparation bridges
    path = save_torque_log(tmp_path / "log.csv", log.select(np.flatnonzero(keep)))
    out = tmp_path / "id"
    terms = ["--terms", "viscous,coulomb,offset"]  # 14 friction, 7 offset columns
    assert main(["identify", "--data", str(path), *terms, "--no-figures", "--out", str(out)]) == 0
    text = capsys.readouterr().out
    meta = json.loads((out / "identification.json").read_text())["metadata"]
    r = len(json.loads((out / "identification.json").read_text())["coefficients"])
    assert (
        f"columns: {r} base parameters and 14 friction and 7 offset columns, rank {r + 21} of "
        f"{r + 21}" in text
    )
    assert meta["cutoff_source"] == "motion" and meta["cutoff_hz"] != DEFAULT_CUTOFF_HZ
    assert f"{meta['cutoff_hz']:.3g} Hz low-pass (10 x the motion's" in text
    assert "resampled onto a uniform grid, 1 gap(s) bridged" in text and meta["resampled"]
    assert "held-out error" in text and meta["heldout"]["folds"] == 5
    val = tmp_path / "v"
    args = ["validate", "--model", str(out / "identification.json"), "--data", str(path)]
    assert main([*args, "--no-figures", "--out", str(val)]) == 0
    assert json.loads((val / "validation.json").read_text())["cutoff_hz"] == meta["cutoff_hz"]
