"""One filtering of a log for its prepared and its full-rate states
(:func:`dynid.identification.prepare.prepared_and_fine`): the same arrays as
:func:`prepare_log` and :func:`fine_states` each filtering it, and the states a smooth
motion's closed form has."""

from __future__ import annotations

import numpy as np
import pytest

from dynid.identification.log import TorqueLog
from dynid.identification.prepare import (
    Preprocessing,
    fine_states,
    prepare_log,
    prepared_and_fine,
)


def _log(rng, *, jitter=0.0, derived=False, n=3, rate=500.0, seconds=4.0):
    """A sinusoidal motion sampled at ``rate`` with noise (stamps jittered by ``jitter``
    of a step), its closed form's amplitudes and periods."""
    N = int(seconds * rate)
    t = np.arange(N) / rate + jitter / rate * rng.uniform(-1, 1, N)
    t[0] = 0.0
    A = rng.uniform(0.2, 0.6, n)
    w = 2 * np.pi / rng.uniform(1.5, 3.0, n)
    q = A * np.sin(w * t[:, None])
    dq = A * w * np.cos(w * t[:, None]) + 1e-3 * rng.standard_normal((N, n))
    tau = q + 0.01 * rng.standard_normal((N, n))
    log = TorqueLog(t, q + 1e-5 * rng.standard_normal((N, n)), dq, tau, dq_derived=derived)
    return log, A, w


def _same(a: TorqueLog, b: TorqueLog) -> None:
    for name in ("t", "q", "dq", "ddq", "tau"):
        np.testing.assert_array_equal(getattr(a, name), getattr(b, name), err_msg=name)


@pytest.mark.parametrize(
    ("jitter", "derived", "delay"),
    [(0.0, False, 0.0), (0.2, False, 0.0), (0.0, True, 0.0), (0.0, False, 0.004)],
)
def test_one_filtering_gives_the_arrays_of_two(jitter, derived, delay):
    """Uniform, jittered, positions-only and delayed logs: the prepared and the fine log
    equal those of prepare_log and fine_states bit for bit, and the kept samples are the
    fine log's every decimate-th from its start."""
    rng = np.random.default_rng(11)
    log, _, _ = _log(rng, jitter=jitter, derived=derived)
    prep = Preprocessing(cutoff_hz=8.0, decimate=7, torque_delay_s=delay)
    prepared, fine, start = prepared_and_fine(log, prep)
    _same(prepared, prepare_log(log, prep))
    fine_ref, start_ref = fine_states(log, prep)
    _same(fine, fine_ref)
    assert start == start_ref
    np.testing.assert_array_equal(fine.t[start::7][: prepared.n_samples], prepared.t)
    np.testing.assert_array_equal(fine.q[start::7][: prepared.n_samples], prepared.q)
    assert not prepared.q.flags.writeable


def test_fine_states_of_a_delayed_log_start_at_its_first_kept_sample():
    """A torque delay of 4 ms trims 2 samples of the 500 Hz fine log: the index of the
    first kept sample counts from the fine log's first (it read the states 2 samples off
    the torques' before)."""
    log, _, _ = _log(np.random.default_rng(13))
    prep = Preprocessing(cutoff_hz=8.0, decimate=7, torque_delay_s=0.004)
    fine, start = fine_states(log, prep)
    assert fine.t[0] == pytest.approx(0.004)
    assert fine.t[start] == prepare_log(log, prep).t[0]


def test_shared_states_follow_the_motion():
    """The prepared positions, velocities and accelerations of a sinusoid (noise of 1e-5
    rad and 1e-3 rad/s) are its closed form's away from the trimmed ends."""
    rng = np.random.default_rng(12)
    log, A, w = _log(rng)
    prepared, fine, _ = prepared_and_fine(log, Preprocessing(cutoff_hz=8.0, decimate=5))
    t = prepared.t[:, None]
    assert np.max(np.abs(prepared.q - A * np.sin(w * t))) < 1e-4
    assert np.max(np.abs(prepared.dq - A * w * np.cos(w * t))) < 2e-3
    assert np.max(np.abs(prepared.ddq + A * w**2 * np.sin(w * t))) < 5e-2
    assert fine.n_samples == log.n_samples
