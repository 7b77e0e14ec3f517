"""Bounded memory on long logs (issue 20 item 5).

References: the whole-array signal steps (scipy's zero-phase filter, numpy's gradient) and
the error formulas written out with numpy; a subprocess under an address-space limit
(RLIMIT_AS) for the command line.
"""

from __future__ import annotations

import numpy as np
import pytest
import scipy.signal

from dynid.exceptions import ShapeError
from dynid.friction.model import ClassicalFriction
from dynid.friction.validation import BLOCK_SAMPLES, validate_torques
from dynid.identification.log import TorqueLog, prepare_log


def _log(seed: int, N: int, n: int = 3) -> TorqueLog:
    rng = np.random.default_rng(seed)
    t = np.arange(N) * 1e-3
    q = np.cumsum(rng.normal(size=(N, n)), axis=0) * 1e-3
    return TorqueLog(t, q, rng.normal(size=(N, n)), rng.normal(size=(N, n)))


@pytest.mark.parametrize("filter_tau", [True, False])
def test_decimated_preparation_equals_the_whole_array_steps(filter_tau):
    """prepare_log(decimate=k), which works column by column, equals the zero-phase
    Butterworth of scipy on whole arrays, numpy's gradient of the filtered dq, trimmed
    and every k-th sample taken."""
    log = _log(1, 12_000)
    fs, cut, k = 1000.0, 5.0, 20
    sos = scipy.signal.butter(4, cut, fs=fs, output="sos")
    pad = int(np.ceil(fs / cut))

    def lp(x):
        return scipy.signal.sosfiltfilt(sos, x, axis=0, padtype="odd", padlen=pad)

    dq = lp(log.dq)
    ref = {"q": lp(log.q), "dq": dq, "ddq": np.gradient(dq, log.t, axis=0, edge_order=2)}
    ref["tau"] = lp(log.tau) if filter_tau else log.tau
    keep = (log.t >= log.t[0] + 2 / cut) & (log.t <= log.t[-1] - 2 / cut)
    p = prepare_log(log, cutoff_hz=cut, filter_tau=filter_tau, decimate=k)
    np.testing.assert_array_equal(p.t, log.t[keep][::k])
    for name, x in ref.items():
        np.testing.assert_allclose(getattr(p, name), x[keep][::k], rtol=0, atol=1e-12)


def test_prepare_log_refuses_a_bad_decimation():
    with pytest.raises(ShapeError, match="decimate"):
        prepare_log(_log(2, 1000), decimate=0)


def test_validation_of_a_long_log_sums_its_errors_by_blocks():
    """A log longer than one block: the errors with friction equal those written out with
    numpy on the whole arrays."""
    N = BLOCK_SAMPLES + 20_001
    log = _log(3, N)
    fr = ClassicalFriction.from_array(
        np.array([[0.5, 0.2, 0.01], [0.3, 0.1, 0.0], [1.0, 0.0, 0.2]])
    )

    def model(q, dq, ddq):
        return 0.1 * q + 0.01 * ddq

    val = validate_torques(model, log, friction=fr, cutoff_hz=5.0)
    p = val.log
    hat = 0.1 * p.q + 0.01 * p.ddq + fr.torques(p.dq)
    e = p.tau - hat
    np.testing.assert_allclose(val.with_friction.rms, np.sqrt(np.mean(e**2, axis=0)), rtol=1e-12)
    np.testing.assert_allclose(
        val.with_friction.relative_error_percent,
        100 * np.linalg.norm(e) / np.linalg.norm(p.tau),
        rtol=1e-12,
    )
    np.testing.assert_allclose(
        val.with_friction.relative_error_percent_per_joint,
        100 * np.linalg.norm(e, axis=0) / np.linalg.norm(p.tau, axis=0),
        rtol=1e-12,
    )
    assert val.with_friction.n_samples == p.n_samples
