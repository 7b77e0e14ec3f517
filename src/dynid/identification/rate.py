"""The low-pass cut-off and the decimation of a torque log, read from the log itself.

A fixed cut-off suits one kind of log: 5 Hz fits a slow exciting trajectory sampled at
1 kHz, but on a fast motion it distorts the accelerations, and on a 5 kHz log with the
decimation that follows from it (``fs / k >= 10 cutoff``) it keeps one sample in a
hundred. The classical route therefore reads both from the data by default:

* **cut-off** ``= CUTOFF_MULTIPLE (10) x f_q``, ``f_q`` the motion's highest significant
  frequency: per moving joint, the frequency below which ``SIGNIFICANT_POWER`` (99.9 %) of
  the power of ``q`` lies (its mean and linear trend removed, a Hann window against
  leakage), the largest over the joints. The torques hold products of the motion's
  harmonics (``M(q) ddq``, ``dq^T C dq``, ``sin q`` in ``g``), hence the multiple. Clamped
  to ``[MIN_CUTOFF_HZ, fs / 4]``. A log whose joints do not move falls back to
  :data:`~dynid.identification.log.DEFAULT_CUTOFF_HZ`.
* **decimation** ``k``: the largest with ``fs / k >= 10 cutoff`` (the filtered signals
  hold nothing above a few times the cut-off), but keeping at least ``MIN_KEPT_SHARE``
  (10 %) of the samples: ``k <= 10``.

A recording cut into pieces at its gaps (:mod:`dynid.identification.recordings`) keeps
its time axis: the motion went on through a cut-out stretch. Its motion frequency is read
from its pieces on that axis (:func:`bridged`: one uniform grid, each cut-out stretch
bridged by the cubic that meets its ends' positions and velocities, for this reading
only), with the frequency resolution of the
whole recording: a piece of 1.6 s cannot tell 0.6 Hz from 1.5 Hz on its own, and the
pieces' own readings, read at their coarse resolution, put the cut-off at 2-4 times the
whole log's.

Both are printed by ``identify`` and recorded in ``identification.json``
(``metadata.cutoff_hz``, ``cutoff_source``, ``motion_frequency_hz``, ``decimate``);
``validate`` reuses the recorded cut-off.
"""

from __future__ import annotations

import math
from collections.abc import Sequence

import numpy as np
from numpy.typing import NDArray

from .log import DEFAULT_CUTOFF_HZ
from .velocity_noise import moving_joints

__all__ = [
    "BRIDGE_GROWTH",
    "CUTOFF_MULTIPLE",
    "MIN_CUTOFF_HZ",
    "MIN_KEPT_SHARE",
    "SIGNIFICANT_POWER",
    "bridged",
    "cutoff_from_motion",
    "decimation",
    "motion_frequency",
]

#: The cut-off is this multiple of the motion's highest significant frequency.
CUTOFF_MULTIPLE = 10.0
#: Share of the power of ``q`` below the significant frequency.
SIGNIFICANT_POWER = 0.999
#: Lowest cut-off chosen from the data [Hz].
MIN_CUTOFF_HZ = 1.0
#: Decimation keeps at least this share of the samples.
MIN_KEPT_SHARE = 0.1
#: A recording's pieces are bridged (:func:`bridged`) while the grid holds at most this
#: many times their samples (cut-out stretches at most as long as what was kept).
BRIDGE_GROWTH = 2.0


def _white_noise_power(p: NDArray[np.float64], f: NDArray[np.floating], fs: float) -> float:
    """The power per bin of the positions' white noise in the spectrum ``p`` at the
    frequencies ``f``: the mean power above ``fs / 4`` (where no cut-off is chosen, far
    above any arm's motion), read from its median (``ln 2`` of the mean, for the
    exponential distribution of a noise bin's power) so that a harmonic there does not
    count. The power is summed less that noise per bin, unclipped, so that the noise adds
    nothing on average (clipped at zero, a third of it stays). A joint whose motion is
    nearly a linear trend over the log keeps little power once the trend is removed, and
    its noise then held more than 0.1 % of it: 1.5 s of a Panda's motion read 181 Hz
    instead of 2 Hz, and the cut-off went to ``fs / 4``."""
    high = p[f > fs / 4.0]
    return float(np.median(high)) / math.log(2.0) if high.size >= 16 else 0.0


def motion_frequency(
    q: NDArray[np.float64], fs: float, moving: NDArray[np.bool_] | None = None
) -> float:
    """The highest significant frequency of the motion [Hz] (module docstring).

    Parameters
    ----------
    q : ndarray, shape (N, n)
        Joint positions [rad or m], uniformly sampled.
    fs : float
        Sample rate [Hz].
    moving : ndarray of bool, shape (n,), optional
        Joints to look at; default all.

    Returns
    -------
    float
        0 when no joint is looked at or the log is too short (fewer than 8 samples).
        Joints whose motion is a linear trend alone (power below 1e-6 of the largest
        joint's once the trend is removed, or below its positions' white noise) are not
        looked at.

    Notes
    -----
    The positions' white noise is taken out of the spectrum before the power is summed
    (:func:`_white_noise_power`). The spectrum is that of the first ``N'`` samples,
    ``N'`` the longest length up to the log's own whose transform is fast
    (:func:`scipy.fft.prev_fast_len`; a length with a large prime factor, 5,000,001 =
    3 x 47 x 35461, would take Bluestein's transform, about 16 times the signal's memory):
    a few samples of a long log at most are left out.
    """
    cols = np.arange(q.shape[1]) if moving is None else np.flatnonzero(moving)
    if q.shape[0] < 8 or cols.size == 0:
        return 0.0
    import scipy.fft  # imported here: it costs most of ``import dynid`` otherwise

    N = int(scipy.fft.prev_fast_len(q.shape[0], real=True))  # no Bluestein transform
    s = np.linspace(-1.0, 1.0, N)  # the trend's slope column (the other one: the mean)
    ss = float(s @ s)
    window = np.hanning(N)
    f = np.fft.rfftfreq(N, 1.0 / fs)
    total = np.zeros(cols.size)
    found = np.zeros(cols.size)
    for k, j in enumerate(cols):  # one joint at a time: a long log's spectra never held whole
        y = q[:N, j]
        # mean and linear trend removed: least squares on the orthogonal columns 1 and s
        x = y - float(np.mean(y))
        x -= (float(s @ y) / ss) * s
        p = np.abs(scipy.fft.rfft(x * window)) ** 2
        del x
        noise = _white_noise_power(p, f, fs)
        cum = np.cumsum(p - noise)  # unclipped: the noise sums to about 0
        total[k] = float(cum[-1]) if cum[-1] > noise * p.size else 0.0  # else noise's
        found[k] = f[min(int(np.argmax(cum >= SIGNIFICANT_POWER * total[k])), f.size - 1)]
    out = 0.0
    for k in range(cols.size):
        if total[k] > 1e-6 * float(total.max()) and total[k] > 0:  # not a trend alone
            out = max(out, float(found[k]))
    return out


def cutoff_from_motion(q: NDArray[np.float64], dq: NDArray[np.float64], fs: float) -> float:
    """The cut-off [Hz] read from the motion (module docstring): ``CUTOFF_MULTIPLE`` times
    :func:`motion_frequency` over the moving joints, in ``[MIN_CUTOFF_HZ, fs / 4]``;
    :data:`~dynid.identification.log.DEFAULT_CUTOFF_HZ` (at most ``fs / 4``) when no joint
    moves."""
    f = motion_frequency(q, fs, moving_joints(dq))
    c = CUTOFF_MULTIPLE * f if f > 0 else DEFAULT_CUTOFF_HZ
    return float(min(max(c, MIN_CUTOFF_HZ), fs / 4.0))


def decimation(fs: float, cutoff_hz: float | None) -> int:
    """Largest ``k`` with ``fs / k >= 10 cutoff_hz`` that keeps at least ``MIN_KEPT_SHARE``
    of the samples (1 without filtering)."""
    if cutoff_hz is None:
        return 1
    return max(1, min(int(math.floor(fs / (10.0 * cutoff_hz))), int(round(1 / MIN_KEPT_SHARE))))


def bridged(
    t: Sequence[NDArray[np.float64]],
    q: Sequence[NDArray[np.float64]],
    dq: Sequence[NDArray[np.float64]],
    turns: NDArray[np.bool_] | None = None,
) -> tuple[NDArray[np.float64], float] | None:
    """The positions of the pieces of one recording on one uniform grid, for reading the
    motion's frequency over the recording's whole time axis (module docstring).

    Parameters
    ----------
    t : sequence of ndarray, shape (N_k,)
        Each piece's timestamps [s], pieces in time order.
    q, dq : sequence of ndarray, shape (N_k, n)
        Each piece's positions [rad or m] and velocities [rad/s or m/s].
    turns : ndarray of bool, shape (n,), optional
        Columns that may have been unwrapped piece by piece: each piece is moved by the
        whole turns that make its first sample nearest to the previous piece's last.

    Returns
    -------
    (ndarray, shape (M, n), float) or None
        The positions at the median step from the first sample to the last: linear
        between the samples of a piece, and over each cut-out stretch the cubic that meets
        the positions and velocities at both of its ends (a straight line there would put
        kinks, fast motion, into the spectrum); and the grid's rate [Hz]. None when the
        grid would hold more than :data:`BRIDGE_GROWTH` times the samples (the stretches
        cut out are longer than what was kept).
    """
    n_kept = sum(int(a.size) for a in t)
    step = float(np.median(np.concatenate([np.diff(a) for a in t])))
    if not step > 0:
        return None
    m = int(math.floor((float(t[-1][-1]) - float(t[0][0])) / step)) + 1
    if m > BRIDGE_GROWTH * n_kept:
        return None
    grid = float(t[0][0]) + step * np.arange(m)
    tt = np.concatenate(list(t))
    n = q[0].shape[1]
    turn = np.zeros(n, bool) if turns is None else np.asarray(turns, dtype=bool)
    spans = [  # each cut-out stretch: (grid rows inside it, t_a, t_b, s in [0, 1])
        (rows, float(a[-1]), float(b[0]), (grid[rows] - float(a[-1])) / float(b[0] - a[-1]))
        for a, b in zip(t[:-1], t[1:], strict=True)
        for rows in [np.flatnonzero((grid > a[-1]) & (grid < b[0]))]
    ]
    out = np.empty((m, n))
    for j in range(n):  # one joint at a time: a long log's columns never copied whole
        parts: list[NDArray[np.float64]] = []
        shift = 0.0
        for k, a in enumerate(q):
            col = a[:, j]
            if k and turn[j]:
                gap = float(col[0]) + shift - float(parts[-1][-1])
                shift -= 2 * np.pi * round(gap / (2 * np.pi))
            parts.append(col + shift if shift else col)
        out[:, j] = np.interp(grid, tt, np.concatenate(parts))
        for k, (rows, ta, tb, x) in enumerate(spans):  # cubic Hermite over the stretch
            h = tb - ta
            qa, qb = float(parts[k][-1]), float(parts[k + 1][0])
            va, vb = float(dq[k][-1, j]), float(dq[k + 1][0, j])
            out[rows, j] = (
                (2 * x**3 - 3 * x**2 + 1) * qa
                + (x**3 - 2 * x**2 + x) * h * va
                + (-2 * x**3 + 3 * x**2) * qb
                + (x**3 - x**2) * h * vb
            )
    return out, 1.0 / step
