"""Closed-form trajectories (sinusoids, Fourier series), limit reports and scaling."""

from __future__ import annotations

import numpy as np
import pytest

from dynid.exceptions import DataError, LimitError, OptionError, ShapeError
from dynid.simulation.limits import check_limits, scale_into_limits
from dynid.simulation.trajectories import (
    GAZ2019_SINUSOID_AMPLITUDES,
    GAZ2019_SINUSOID_PERIODS,
    FourierSeries,
    Trajectory,
    centered_start,
    random_fourier,
    sinusoid_trajectory,
    uniform_times,
)

H = 1e-4  # step of the finite differences [s]


def _central(x, h=H):
    return (x[2:] - x[:-2]) / (2 * h)


def _fd_check(traj):
    """dq is the derivative of q and ddq the derivative of dq (central differences)."""
    scale_v = np.max(np.abs(traj.ddq)) + 1.0
    scale_a = np.max(np.abs(traj.ddq)) * 50 + 1.0
    np.testing.assert_allclose(_central(traj.q), traj.dq[1:-1], atol=1e-6 * scale_v)
    np.testing.assert_allclose(_central(traj.dq), traj.ddq[1:-1], atol=1e-6 * scale_a)


def test_sinusoid_derivatives_match_finite_differences(panda):
    """q, dq, ddq of the sinusoids are consistent and dq = A sin(2 pi t / T) (eq. 31)."""
    t = np.arange(20001) * H
    q0 = centered_start(panda)
    traj = sinusoid_trajectory(t, q0)
    np.testing.assert_allclose(traj.q[0], q0, atol=0)
    A, T = np.array(GAZ2019_SINUSOID_AMPLITUDES), np.array(GAZ2019_SINUSOID_PERIODS)
    np.testing.assert_allclose(traj.dq, A * np.sin(2 * np.pi * t[:, None] / T), atol=1e-14)
    _fd_check(traj)


def test_centered_start_puts_each_sweep_in_the_middle_of_its_range(panda):
    """Each joint's sweep [min q, max q] over a full period is centred in its limits."""
    A, T = np.array(GAZ2019_SINUSOID_AMPLITUDES), np.array(GAZ2019_SINUSOID_PERIODS)
    traj = sinusoid_trajectory(np.linspace(0, 60, 60001), centered_start(panda))
    mid = 0.5 * (traj.q.max(axis=0) + traj.q.min(axis=0))
    np.testing.assert_allclose(mid, 0.5 * (panda.q_min + panda.q_max), atol=1e-5)
    np.testing.assert_allclose(traj.q.max(0) - traj.q.min(0), np.abs(A) * T / np.pi, rtol=1e-6)


def test_fourier_derivatives_match_finite_differences_and_period(panda):
    """The Fourier series is consistent in q, dq, ddq and periodic with 2 pi / w_f."""
    rng = np.random.default_rng(4)
    series = FourierSeries(
        2 * np.pi * 0.2, rng.normal(size=(7, 4)), rng.normal(size=(7, 4)), np.zeros(7)
    )
    t = np.arange(10001) * H
    _fd_check(series(t))
    a, b = series(t), series(t + series.period)
    np.testing.assert_allclose(b.q, a.q, atol=1e-9)
    np.testing.assert_allclose(b.ddq, a.ddq, atol=1e-9)
    # the mean position over a period is q0
    tp = np.linspace(0, series.period, 4001)[:-1]
    np.testing.assert_allclose(series(tp).q.mean(axis=0), series.q0, atol=1e-9)


def test_fourier_bounds_hold_at_every_sample():
    """The analytic bounds of |q - q0|, |dq|, |ddq| are never exceeded."""
    rng = np.random.default_rng(5)
    series = FourierSeries(1.0, rng.normal(size=(3, 5)), rng.normal(size=(3, 5)), [0.1, 0.2, 0.3])
    tr = series(np.linspace(0, series.period, 20001))
    pb, vb, ab = series.bounds()
    assert np.all(np.abs(tr.q - series.q0).max(0) <= pb + 1e-12)
    assert np.all(np.abs(tr.dq).max(0) <= vb + 1e-12)
    assert np.all(np.abs(tr.ddq).max(0) <= ab + 1e-12)


def test_random_fourier_stays_inside_the_limits(panda):
    """Seeded random coefficients, scaled per joint, respect every limit over a period."""
    for seed in range(5):
        series = random_fourier(panda, np.random.default_rng(seed), margin=0.9)
        tr = series(np.linspace(0, series.period, 20001))
        assert check_limits(panda, tr).ok
        # each joint uses its budget: one of the three bounds is active
        pb, vb, ab = series.bounds()
        room = np.minimum(series.q0 - panda.q_min, panda.q_max - series.q0)
        use = np.max([pb / room, vb / panda.dq_max, ab / panda.ddq_max], axis=0)
        np.testing.assert_allclose(use, 0.9, rtol=1e-9)


def test_random_fourier_starts_a_continuous_joint_at_zero_without_a_warning(panda):
    """A joint without position limits starts at 0, the others in the middle of their
    range; no numpy warning (``inf + -inf`` was computed and discarded)."""
    import dataclasses
    import warnings

    lo, hi = np.array(panda.q_min), np.array(panda.q_max)
    lo[6], hi[6] = -np.inf, np.inf
    robot = dataclasses.replace(panda, q_min=lo, q_max=hi)
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        series = random_fourier(robot, np.random.default_rng(0))
    np.testing.assert_allclose(series.q0[:6], 0.5 * (lo[:6] + hi[:6]))
    assert series.q0[6] == 0.0


def test_random_fourier_rejects_start_outside_limits(panda):
    """A q0 on or outside a position limit raises LimitError naming the joint."""
    q0 = 0.5 * (panda.q_min + panda.q_max)
    q0[3] = panda.q_max[3]
    with pytest.raises(LimitError, match="joint4"):
        random_fourier(panda, np.random.default_rng(0), q0=q0)


def test_check_limits_reports_the_table_i_velocity_violations(panda):
    """Table I's 2.21 rad/s on joints 1 and 2 exceeds Franka's 2.175 rad/s; nothing else does."""
    traj = sinusoid_trajectory(uniform_times(10.0, 1000.0), centered_start(panda))
    report = check_limits(panda, traj)
    assert not report.ok
    got = {(v.kind, v.joint_name, np.sign(v.value)) for v in report.violations}
    assert got == {
        ("velocity", "joint1", 1.0),
        ("velocity", "joint1", -1.0),
        ("velocity", "joint2", 1.0),
        ("velocity", "joint2", -1.0),
    }
    for v in report.violations:
        assert abs(v.value) == pytest.approx(2.21, abs=1e-5)
        assert abs(v.limit) == 2.175
        assert 0 < v.fraction < 0.1 and v.first_time <= v.time
    assert "joint1" in str(report)


def test_check_limits_reports_position_and_acceleration(panda):
    """A start beyond the upper limit and a fast sinusoid appear in the report."""
    q0 = 0.5 * (panda.q_min + panda.q_max)
    q0[0] = panda.q_max[0] + 0.1
    A = np.zeros(7)
    A[6] = 1.0
    T = np.ones(7)
    T[6] = 0.2  # ddq amplitude 2 pi / 0.2 = 31 rad/s^2 > 20
    report = check_limits(panda, sinusoid_trajectory(uniform_times(1.0), q0, A, T))
    kinds = {(v.kind, v.joint) for v in report.violations}
    assert ("position", 0) in kinds and ("acceleration", 6) in kinds
    pos = next(v for v in report.violations if v.kind == "position")
    assert pos.limit == panda.q_max[0] and pos.value > pos.limit


def test_scale_into_limits_amplitude_scales_the_sinusoid_amplitudes(panda):
    """Amplitude scaling of Table I gives the sinusoids with A * s, s = 0.95 * 2.175 / 2.21."""
    t = uniform_times(10.0, 1000.0)
    q0 = centered_start(panda)
    traj = sinusoid_trajectory(t, q0)
    scaled, s = scale_into_limits(panda, traj, method="amplitude", margin=0.95)
    assert s == pytest.approx(0.95 * 2.175 / 2.21, rel=1e-4)
    ref = sinusoid_trajectory(t, q0, s * np.array(GAZ2019_SINUSOID_AMPLITUDES))
    np.testing.assert_allclose(scaled.q, ref.q, atol=1e-12)
    np.testing.assert_allclose(scaled.ddq, ref.ddq, atol=1e-12)
    assert check_limits(panda, scaled).ok


def test_scale_into_limits_time_stretches_and_keeps_positions(panda):
    """Time scaling by k divides dq by k and ddq by k^2, positions unchanged."""
    traj = sinusoid_trajectory(uniform_times(10.0, 1000.0), centered_start(panda))
    scaled, k = scale_into_limits(panda, traj, method="time", margin=0.95)
    assert k == pytest.approx(2.21 / (0.95 * 2.175), rel=1e-4)
    np.testing.assert_allclose(scaled.q, traj.q)
    np.testing.assert_allclose(scaled.dq * k, traj.dq)
    np.testing.assert_allclose(scaled.ddq * k**2, traj.ddq)
    assert scaled.duration == pytest.approx(k * traj.duration)
    assert check_limits(panda, scaled).ok
    # an admissible trajectory is returned unchanged
    same, one = scale_into_limits(panda, scaled, method="time")
    assert one == 1.0 and same is scaled


def test_scale_into_limits_time_cannot_fix_positions(panda):
    """Time scaling raises LimitError when positions are out of range."""
    q0 = 0.5 * (panda.q_min + panda.q_max)
    q0[2] = panda.q_max[2] - 0.01  # joint 3 moves upwards (A3 > 0)
    traj = sinusoid_trajectory(uniform_times(5.0), q0)
    with pytest.raises(LimitError, match="time scaling cannot fix position limits"):
        scale_into_limits(panda, traj, method="time")
    scaled, s = scale_into_limits(panda, traj, method="amplitude", margin=1.0)
    assert check_limits(panda, scaled).ok
    assert s == pytest.approx(0.01 / (1.2 * 2.98 / np.pi), rel=1e-3)


def test_trajectory_rejects_bad_input(panda):
    """Shapes must agree, times must increase, the scaling method must be known."""
    t = np.arange(4.0)
    z = np.zeros((4, 2))
    with pytest.raises(ShapeError, match="dq must have shape"):
        Trajectory(t, z, np.zeros((4, 3)), z)
    with pytest.raises(DataError, match="strictly increasing"):
        Trajectory(np.array([0.0, 1.0, 1.0, 2.0]), z, z, z)
    z7 = np.zeros((4, 7))
    with pytest.raises(OptionError, match="method must be"):
        scale_into_limits(panda, Trajectory(t, z7 - 1.0, z7 + 3.0, z7), method="speed")
