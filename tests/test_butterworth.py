"""The low-pass filter's design and zero-phase run (:mod:`dynid.butterworth`) against
scipy.signal (an independent implementation) and the Butterworth closed forms."""

from __future__ import annotations

import os
import subprocess
import sys

import numpy as np
import pytest
import scipy.signal

from dynid import _kernels
from dynid.butterworth import butter_sos, sosfilt, steady_states, zero_phase

DESIGNS = [(1000.0, 5.0), (1000.0, 50.0), (100.0, 6.0), (200.0, 99.0), (1000.0, 0.3)]


def _response(sos, f, fs):
    """The complex gain of the sections ``sos`` at the frequencies ``f`` [Hz]."""
    z = np.exp(-1j * 2 * np.pi * np.asarray(f) / fs)[:, None]
    b = sos[:, 0] + sos[:, 1] * z + sos[:, 2] * z**2
    a = sos[:, 3] + sos[:, 4] * z + sos[:, 5] * z**2
    return np.prod(b / a, axis=1)


@pytest.mark.parametrize("order", range(1, 9))
@pytest.mark.parametrize(("fs", "fc"), DESIGNS)
def test_the_design_is_butterworths(order, fs, fc):
    """Unit gain at rest, 1/sqrt(2) at the cut-off (the bilinear transform's pre-warped
    closed form), zero at Nyquist, the response of scipy.signal.butter at every frequency
    to 1e-10; an even order's sections scipy's coefficients themselves."""
    sos = butter_sos(order, fc, fs)
    assert sos.shape == ((order + 1) // 2, 6) and not sos.flags.writeable
    h = np.abs(_response(sos, [0.0, fc, fs / 2], fs))
    assert h[0] == pytest.approx(1.0, abs=1e-9)
    assert h[1] == pytest.approx(2**-0.5, abs=1e-9)
    assert h[2] < 1e-9
    ref = scipy.signal.butter(order, fc, btype="low", fs=fs, output="sos")
    f = np.linspace(0.0, fs / 2, 257)
    assert np.allclose(_response(sos, f, fs), _response(ref, f, fs), rtol=0, atol=1e-10)
    if order % 2 == 0:
        assert np.allclose(sos, ref, rtol=1e-12, atol=0)


@pytest.mark.parametrize("order", [1, 2, 3, 4, 6])
def test_the_steady_states_hold_a_step(order):
    """A step from the steady states of its height leaves every output at its height (the
    defining property), as scipy.signal.sosfilt_zi's states."""
    sos = butter_sos(order, 7.0, 500.0)
    zi = steady_states(sos)
    x = np.full((300, 2), [1.5, -3.0])
    y = sosfilt(sos, x, zi[:, :, None] * x[0])
    assert np.allclose(y, x, rtol=1e-11, atol=0)
    assert np.allclose(zi, scipy.signal.sosfilt_zi(np.array(sos)), rtol=1e-9, atol=1e-15)


def test_the_sections_run_as_scipys_bit_for_bit(monkeypatch):
    """Compiled and fallback runs give scipy.signal.sosfilt's numbers and final states bit
    for bit, NaN included."""
    rng = np.random.default_rng(3)
    sos = np.array(butter_sos(4, 6.0, 1000.0))
    x = np.cumsum(rng.standard_normal((2000, 5)), axis=0)
    x[700, 1] = np.nan
    zi = rng.standard_normal((2, 2, 5))
    want, zf = scipy.signal.sosfilt(sos, x, axis=0, zi=zi)
    compiled = _kernels.load("filters") is not None
    for kernels in (True, False) if compiled else (False,):
        with monkeypatch.context() as mp:
            if not kernels:
                mp.setitem(_kernels.CACHE.modules, "filters", None)
            z = zi.copy()
            got = sosfilt(sos, x, z)
        assert np.array_equal(got, want, equal_nan=True), kernels
        assert np.array_equal(z, zf, equal_nan=True), kernels


@pytest.mark.parametrize("pad", [0, 1, 17, 1999])
def test_the_zero_phase_run_is_sosfiltfilts(pad):
    """Forward and backward with an odd extension of ``pad`` samples: scipy's sosfiltfilt
    to 1e-12 of the signal's scale."""
    rng = np.random.default_rng(4)
    sos = np.array(butter_sos(4, 20.0, 1000.0))
    x = np.cumsum(rng.standard_normal((2000, 3)), axis=0)
    want = scipy.signal.sosfiltfilt(
        sos, x, axis=0, padtype="odd" if pad else None, padlen=pad if pad else None
    )
    got = zero_phase(sos, x, pad)
    assert got.shape == x.shape
    assert np.max(np.abs(got - want)) <= 1e-12 * np.max(np.abs(want))


def test_the_low_pass_loads_no_scipy_signal():
    """A command's filtering imports no scipy.signal (0.4 s of its start), in a fresh
    process, the kernels on as by default."""
    code = (
        "import sys, numpy as np; from dynid.signals import lowpass, lowpass_noise_gain; "
        "lowpass(np.random.default_rng(0).random((500, 2)), 1000.0, 10.0); "
        "lowpass_noise_gain(1000.0, 10.0); print('scipy.signal' in sys.modules)"
    )
    env = {k: v for k, v in os.environ.items() if k != "DYNID_NO_NUMBA"}
    done = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, env=env)
    assert done.returncode == 0, done.stderr
    assert done.stdout.strip() == "False"
