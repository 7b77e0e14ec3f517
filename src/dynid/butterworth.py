"""The Butterworth low-pass of :func:`dynid.signals.lowpass`: its design as second-order
sections and its zero-phase (forward and backward) run.

Design (the bilinear transform with the cut-off pre-warped, as ``scipy.signal.butter``):
the analog prototype's ``N`` poles ``p_k = -w exp(i pi m / (2 N))``, ``m = -N+1, -N+3, ...,
N-1``, at the warped cut-off ``w = 2 f_s tan(pi f_c / f_s)``, map to ``z_k = (2 f_s +
p_k) / (2 f_s - p_k)``, the ``N`` zeros to ``z = -1``, the gain ``k = w^N / prod(2 f_s -
p_k)`` (unit gain at rest). Each conjugate pair is a section ``(1 + z^-1)^2 / (1 - 2
Re(z_k) z^-1 + |z_k|^2 z^-2)`` (an odd order's real pole a first-order one), ordered
from the pole farthest from the unit circle (the gain in the first section), as
``scipy.signal.zpk2sos`` orders them (which puts an odd order's single zero elsewhere:
the same filter, the coefficients of the sections not the same).

Run (as ``scipy.signal.sosfiltfilt``): the signal continued at each end by its odd
extension, each section started in the steady state of a step of the first sample's
height, filtered forward, then backward from the steady state of the last output.

The sections run compiled (:mod:`dynid._kernels.filters`), else through
``scipy.signal.sosfilt`` (``DYNID_NO_NUMBA``, or without numba): the same numbers, bit for
bit. This module imports no scipy: ``scipy.signal`` alone costs about 0.4 s of a
command's start.
"""

from __future__ import annotations

import functools

import numpy as np
from numpy.typing import NDArray

from . import _kernels

__all__ = ["butter_sos", "steady_states", "sosfilt", "zero_phase"]


@functools.lru_cache(maxsize=64)
def butter_sos(order: int, cutoff_hz: float, fs: float) -> NDArray[np.float64]:
    """The second-order sections (s, 6) (rows ``b0 b1 b2 1 a1 a2``, ``s = ceil(order /
    2)``; read only) of the digital low-pass Butterworth filter of ``order`` with its -3 dB
    cut-off ``cutoff_hz`` [Hz] at the rate ``fs`` [Hz], ``0 < cutoff_hz < fs / 2``
    (module docstring); designed once per order, cut-off and rate."""
    # at the rate 2 (the cut-off a fraction of the Nyquist frequency), as scipy designs
    m = np.arange(-order + 1, order, 2)
    w = 4.0 * np.tan(np.pi * (2.0 * cutoff_hz / fs) / 2.0)  # the warped cut-off
    p = -np.exp(1j * np.pi * m / (2 * order)) * w
    gain = w**order * float(np.real(1.0 / np.prod(4.0 - p)))
    z = (4.0 + p) / (4.0 - p)
    upper = z[z.imag > 0]  # one of each conjugate pair
    real = z[z.imag == 0].real
    rows = [(1.0, 2.0, 1.0, 1.0, -2.0 * c.real, abs(c) ** 2) for c in upper]
    rows += [(1.0, 1.0, 0.0, 1.0, -r, 0.0) for r in real]
    poles = [abs(c) for c in upper] + [abs(r) for r in real]
    sos = np.array([rows[i] for i in np.argsort(poles, kind="stable")], dtype=np.float64)
    sos[0, :3] *= gain
    sos.flags.writeable = False
    return sos


def steady_states(sos: NDArray[np.float64]) -> NDArray[np.float64]:
    """The states (s, 2) of the sections ``sos`` (s, 6) in the steady state of a unit
    step held since ever (``scipy.signal.sosfilt_zi``): section ``j``'s ``(I - A) z = B``
    of its transposed direct form, times the gain at rest of the sections before it."""
    zi = np.empty((sos.shape[0], 2))
    scale = 1.0
    for j, (b0, b1, b2, _, a1, a2) in enumerate(sos):
        z0 = (b1 - a1 * b0 + b2 - a2 * b0) / (1.0 + a1 + a2)
        zi[j] = scale * z0, scale * (b2 - a2 * b0 - a2 * z0)
        scale *= (b0 + b1 + b2) / (1.0 + a1 + a2)
    return zi


def sosfilt(
    sos: NDArray[np.float64], x: NDArray[np.float64], zi: NDArray[np.float64]
) -> NDArray[np.float64]:
    """``x`` (m, k) through the sections ``sos`` (s, 6) along its first axis from the
    states ``zi`` (s, 2, k) (updated to the last sample's)."""
    out = np.empty(x.shape)
    mod = _kernels.load("filters")
    if mod is not None:
        mod.sections(sos, np.ascontiguousarray(x, dtype=np.float64), zi, out)
        return out
    import scipy.signal  # the reference path: numba missing or turned off

    y, zf = scipy.signal.sosfilt(np.array(sos), x, axis=0, zi=zi)  # it wants it writable
    zi[...] = zf
    return np.asarray(y, dtype=np.float64)


def zero_phase(sos: NDArray[np.float64], x: NDArray[np.float64], pad: int) -> NDArray[np.float64]:
    """``x`` (m, k) filtered forward and backward along its first axis by the sections
    ``sos`` (s, 6), continued at each end by ``pad`` samples of its odd extension
    (``2 x_0 - x_i``; ``0 <= pad < m``; module docstring)."""
    if pad:
        x = np.concatenate([2.0 * x[:1] - x[pad:0:-1], x, 2.0 * x[-1:] - x[-2 : -pad - 2 : -1]])
    zi = steady_states(sos)[:, :, None]
    y = sosfilt(sos, x, zi * x[0])
    y = sosfilt(sos, y[::-1], zi * y[-1])[::-1]
    return y[pad : y.shape[0] - pad]
