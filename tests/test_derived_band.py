"""The standstill band of a log without velocity columns (velocities derived from the
positions) and what the summary says of it.

References: the noise the derived velocities actually carry (white position noise of the
same std through the same filters, measured on a long record; a quantized motion's derived
velocities less the unquantized motion's); the smooth Coulomb's width
in closed form (``K`` bands, at least ``K`` times 1 mrad/s).
"""

from __future__ import annotations

import warnings

import numpy as np
import pytest

import dynid
from dynid.cli.summaries import term_lines
from dynid.exceptions import DynidWarning
from dynid.identification.derived_band import derived_velocity_band
from dynid.identification.log import TorqueLog, with_derived_velocities
from dynid.identification.recordings import prepare_recordings
from dynid.io.torque_log import save_torque_log
from dynid.signals import filtered_derivative, lowpass
from dynid.simulation.measurement import SensorNoise, sample_times, simulate_measurement
from dynid.simulation.trajectories import random_fourier
from dynid.workflows.identify import IdentifyOptions, identify_files

Q_STD, FS, CUTOFF = 1e-5, 200.0, 4.0


def _positions_only(seed: int) -> TorqueLog:
    """A 12 s Panda log at 200 Hz whose velocities are derived from positions with white
    noise of std ``Q_STD`` (a log without velocity columns, as read)."""
    robot = dynid.panda()
    traj = random_fourier(robot, np.random.default_rng(seed))(sample_times(12.0, FS))
    noise = SensorNoise(tau_std=0.05, q_std=Q_STD, dq_std=0.0)
    log = simulate_measurement(robot, traj, rng=np.random.default_rng(seed + 10), noise=noise)
    return with_derived_velocities(TorqueLog(t=log.t, q=log.q, dq=log.dq, tau=log.tau))


def _derived_noise_std() -> float:
    """The std [rad/s] of velocities prepared from white position noise of std Q_STD:
    derived at the cut-off and low-passed again, measured away from the ends."""
    rng = np.random.default_rng(0)
    t = np.arange(200_000) / FS
    e = Q_STD * rng.standard_normal((t.size, 1))
    v = lowpass(filtered_derivative(t, e, CUTOFF), FS, CUTOFF)[2000:-2000]
    return float(v.std())


def test_the_band_of_derived_velocities_is_their_noise_not_the_near_zero_estimate():
    """Derived velocities are smooth, so the noise estimate of measured ones gave a band
    of about 1e-7 rad/s; the band of the velocities as prepared (``band_gain band``) is
    5 std of the noise the positions put into them."""
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", DynidWarning)
        rec = prepare_recordings(dynid.panda(), [_positions_only(1)], cutoff_hz=CUTOFF)
    np.testing.assert_allclose(rec.band_gain * rec.band, 5.0 * _derived_noise_std(), rtol=0.1)


@pytest.mark.filterwarnings("ignore::dynid.exceptions.DynidWarning")
def test_the_friction_table_gives_each_joint_band_and_smooth_width(tmp_path):
    """The summary's friction table has the band and the smooth width in rad/s per joint,
    those of the model (``smooth:30``: 30 bands, at least 30 mrad/s), and says what the
    two are."""
    path = save_torque_log(tmp_path / "log.csv", _positions_only(2))
    opt = IdentifyOptions(terms="viscous,smooth:30,offset", cutoff_hz=CUTOFF)
    model = identify_files(dynid.panda(), path, opt).model
    term = model.terms["friction"].term
    width = 30.0 * np.maximum(np.asarray(term.band), 1e-3)
    np.testing.assert_allclose(term.width, width, rtol=1e-12)
    np.testing.assert_allclose(term.band, 5.0 * _derived_noise_std(), rtol=0.1)
    lines = term_lines(model)
    head = next(x for x in lines if x.strip().startswith("joint  fv"))
    assert head.split()[-4:] == ["band", "[rad/s]", "width", "[rad/s]"]
    rows = [x.split() for x in lines if x[:2] == "  " and x.split()[0].isdigit()][-7:]
    np.testing.assert_allclose([float(r[-2]) for r in rows], term.band, rtol=5e-3)
    np.testing.assert_allclose([float(r[-1]) for r in rows], term.width, rtol=5e-3)
    said = "\n".join(lines)
    assert "smooth:30 = 30 x max(band, 0.001 rad/s)" in said
    assert "the positions' noise through the derivative filter" in said


#: The slow joint's encoder step [rad] (14 bits a turn) and its log's rate [Hz].
STEP, SLOW_FS = 2 * np.pi / 2**14, 500.0


def _slow_columns() -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """20 s at ``SLOW_FS`` of a smooth motion (0.1 rad/s RMS: 0.5 encoder steps a sample)
    quantized to ``STEP``, and the same motion with white noise of std ``STEP / sqrt(12)``
    (not quantized): times (N,), the positions as logged (N, 2) and without their error
    (N, 2)."""
    rng = np.random.default_rng(5)
    t = np.arange(int(20 * SLOW_FS)) / SLOW_FS
    f = np.array([0.13, 0.29, 0.41])  # [Hz]
    x = 0.3 + sum(0.1 / (2 * np.pi * k) * np.sin(2 * np.pi * k * t + rng.uniform(0, 6)) for k in f)
    white = x + STEP / np.sqrt(12) * rng.standard_normal(t.size)
    return t, np.column_stack([np.round(x / STEP) * STEP, white]), np.column_stack([x, x])


def test_a_quantized_slow_joints_derived_velocities_keep_their_sign_and_its_band_stays_narrow():
    """Why a quantized column's band is not floored at its rounding (a floor of
    ``5 g step / sqrt(12)`` was tried twice: the true sharp Coulomb structure of quantized
    positions-only logs predicted worse, held out and against the truth): the rounding puts
    ``g step / sqrt(12)`` into the derived velocities as white noise of that std would
    (within 0.7-1.4), but it keeps a monotone motion monotone, so the derived velocity has
    the sign of the unquantized motion's at every sample where white noise flips some;
    the band read on the quantized column stays far below the noisy one's."""
    t, logged, exact = _slow_columns()
    v = lowpass(filtered_derivative(t, np.column_stack([logged, exact]), CUTOFF), SLOW_FS, CUTOFF)
    v = v[2000:-2000]
    error = v[:, :2] - v[:, 2:]
    white = 5.0 * error.std(axis=0)[1]  # 5 std of the white noise's derived error
    assert 0.7 < error.std(axis=0)[0] / error.std(axis=0)[1] < 1.4
    flips = np.mean(np.sign(v[:, :2]) != np.sign(v[:, 2:]), axis=0)
    assert flips[0] == 0.0 and flips[1] > 0.0, flips
    band = derived_velocity_band([(t, logged)], CUTOFF, lowpassed=True)
    assert band is not None
    assert band[0] < 0.01 * white and band[1] == pytest.approx(white, rel=0.1)


def test_the_friction_table_says_why_a_band_is_near_zero():
    """Under identify's friction table, bands below 1e-6 rad/s (a quantized wrist's
    1.8e-15) are named by their joint with why no band is needed; bands of measured noise
    (2e-3 rad/s) add nothing."""
    from dynid.cli.summaries import _scales_lines

    lines = _scales_lines({"band": (2e-3, 1.83e-15, 0.0)}, None)
    (said,) = [x for x in lines if "near 0" in x]
    assert "(2, 3)" in said and "quantized" in said and "sign" in said
    assert not any("near 0" in x for x in _scales_lines({"band": (2e-3, 8.8e-3)}, None))
