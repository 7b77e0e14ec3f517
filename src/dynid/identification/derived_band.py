"""The standstill band of velocities derived from positions (a log without velocity columns).

The band of measured velocities is :data:`~dynid.identification.velocity_noise.NOISE_BAND_STD`
times their white-noise std (:func:`~dynid.identification.velocity_noise.velocity_noise_std`).
Velocities derived from positions are smooth: that estimate finds next to nothing on them
(1e-7 rad/s on a 200 Hz log whose positions carry 1e-5 rad of noise), while they depart
from the true velocity by the positions' noise passed through the derivative filter. Their
band is that noise:

.. math:: b = \\mathrm{NOISE\\_BAND\\_STD} \\; g \\; \\sigma_q

with ``sigma_q`` the positions' white-noise std (the same second- and third-difference
estimate, read on the positions, the median over windows of :data:`WINDOW` samples) and
``g`` the noise gain of the filters that derived the velocities
(:func:`~dynid.signals.derivative_noise_gain`). The observer reads the same band for its
own derivative (:func:`~dynid.observer.friction.derived_velocity_bands`).
"""

from __future__ import annotations

from collections.abc import Sequence

import numpy as np
from numpy.typing import NDArray

from ..signals import derivative_noise_gain
from .velocity_noise import noise_band, velocity_noise_std

__all__ = ["WINDOW", "derived_velocity_band", "position_noise_std"]

#: Consecutive samples per estimate of the positions' noise (the median of the windows'
#: estimates: a long log in bounded memory).
WINDOW = 1 << 16


def position_noise_std(q: NDArray[np.float64]) -> list[NDArray[np.float64]]:
    """The white-noise std [rad] (m,) of positions ``q`` (N, m) per window of
    :data:`WINDOW` samples (windows of fewer than 4 samples left out)."""
    N = q.shape[0]
    return [velocity_noise_std(q[a : a + WINDOW]) for a in range(0, N, WINDOW) if N - a >= 4]


def derived_velocity_band(
    pieces: Sequence[tuple[NDArray[np.float64], NDArray[np.float64]]],
    cutoff_hz: float,
    *,
    lowpassed: bool,
) -> NDArray[np.float64] | None:
    """The velocity noise band [rad/s] (m,) of velocities derived from positions.

    Parameters
    ----------
    pieces : sequence of (ndarray, ndarray)
        ``(t, q)`` of each piece: times (N,) [s] and positions (N, m) [rad] (of the joints,
        or of the motors ``q K^T``).
    cutoff_hz : float
        The cut-off [Hz] the velocities were derived at
        (:func:`~dynid.signals.filtered_derivative`).
    lowpassed : bool
        The derived velocities were low-passed again at that cut-off (identification's
        preparation).

    Returns
    -------
    ndarray, shape (m,), or None
        ``NOISE_BAND_STD g sigma_q``, the median over every window of every piece; None
        when no piece has 4 samples.
    """
    est = []
    for t, q in pieces:
        if q.shape[0] < 4:
            continue
        gain = derivative_noise_gain(float(np.median(np.diff(t))), cutoff_hz, lowpassed=lowpassed)
        est += [gain * s for s in position_noise_std(q)]
    if not est:
        return None
    return np.asarray(noise_band(np.median(np.stack(est), axis=0)), dtype=np.float64)
