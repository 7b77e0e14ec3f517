"""How much of a calibration residual is the velocities' noise times the observer's gain.

The residual reads the momentum ``p = M(q) dq`` itself, not filtered: white noise ``n`` of
std ``sigma_k`` on the measured velocity ``dq_k`` reaches ``r_j`` as ``K_O,j (M(q) n)_j``
(above the gain's bandwidth the observer passes ``p`` with gain ``K_O``), of variance

.. math:: s_j^2 = K_{O,j}^2 \\overline{\\textstyle\\sum_k M_{jk}(q)^2 \\sigma_k^2}

(the bar: the mean over the samples). It grows in proportion to the gain, and so do the
thresholds calibrated on a residual it dominates: a larger gain shortens the observer's lag
but raises those thresholds as much, so it does not detect sooner (a Panda at 2e-3 rad/s of
velocity noise: contact thresholds of joint 1 0.72, 1.79 and 5.6 N m at gains 20, 50 and
150). :class:`GainNoiseTally` adds up ``s_j^2`` and the residual's mean square over the
calibration's blocks (``sigma`` estimated on each block's velocities by
:func:`~dynid.identification.velocity_noise.velocity_noise_std`; velocities derived from positions
through a low-pass show no white noise and give about 0); :class:`GainNoise` names the
joints where ``s_j^2`` makes up at least :data:`DOMINANT` of the residual's mean square.
"""

from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np
from numpy.typing import ArrayLike, NDArray

from ..identification.velocity_noise import velocity_noise_std
from .model import ObserverModel

__all__ = ["DOMINANT", "GainNoise", "GainNoiseTally"]

#: Share of the residual's mean square from the velocities' noise times the gain above
#: which that noise dominates a joint's calibration (and so its thresholds).
DOMINANT = 0.5
#: Every this-many-th sample of a block evaluates ``M(q)`` (it changes slowly).
_THIN = 10


@dataclass(frozen=True, slots=True)
class GainNoise:
    """The velocities' noise through the gain against the calibration residual, per joint.

    Attributes
    ----------
    gain : ndarray, shape (n,)
        ``K_O`` [1/s].
    predicted : ndarray, shape (n,)
        RMS [N m] of ``K_O (M(q) n)``, the velocities' noise in the residual (module
        docstring).
    residual : ndarray, shape (n,)
        RMS [N m] of the calibration residual.
    """

    gain: NDArray[np.float64]
    predicted: NDArray[np.float64]
    residual: NDArray[np.float64]

    @property
    def share(self) -> NDArray[np.float64]:
        """``predicted^2 / residual^2`` per joint, at most 1 (0 for a zero residual)."""
        with np.errstate(divide="ignore", invalid="ignore"):
            s = np.where(self.residual > 0, (self.predicted / self.residual) ** 2, 0.0)
        return np.asarray(np.clip(s, 0.0, 1.0), dtype=np.float64)

    @property
    def dominated(self) -> tuple[int, ...]:
        """The joints (0-based) whose residual the velocities' noise dominates
        (:data:`DOMINANT`)."""
        return tuple(int(j) for j in np.flatnonzero(self.share >= DOMINANT))


@dataclass(slots=True)
class GainNoiseTally:
    """Running sums of :class:`GainNoise` over the blocks of the calibration logs.

    Attributes
    ----------
    model : ObserverModel
        Its mass matrix (with the rotors') maps the velocities' noise to the momentum.
    gain : ndarray, shape (n,)
        ``K_O`` [1/s].
    """

    model: ObserverModel
    gain: NDArray[np.float64]
    _pred: NDArray[np.float64] = field(init=False)
    _res: NDArray[np.float64] = field(init=False)
    _count: NDArray[np.float64] = field(init=False)

    def __post_init__(self) -> None:
        n = self.model.n
        self.gain = np.broadcast_to(np.asarray(self.gain, dtype=np.float64), (n,)).copy()
        self._pred, self._res, self._count = np.zeros(n), np.zeros(n), np.zeros(n)

    def add(self, q: ArrayLike, dq: ArrayLike, r: ArrayLike) -> None:
        """One block: positions ``q`` [rad], measured velocities ``dq`` [rad/s] and the
        residual ``r`` [N m], each (N, n); rows where ``r`` is not finite (a piece's edges
        the observer did not run on) are left out, and a block of fewer than 4 such rows."""
        R = np.asarray(r, dtype=np.float64)
        ok = np.all(np.isfinite(R), axis=1)
        if np.count_nonzero(ok) < 4:
            return
        Q, V, R = np.asarray(q)[ok], np.asarray(dq)[ok], R[ok]
        sigma = velocity_noise_std(V)
        M = self.model.mass_matrix(Q[::_THIN])
        var = np.mean(np.einsum("sjk,k->sj", M**2, sigma**2), axis=0)
        N = R.shape[0]
        self._pred += N * self.gain**2 * var
        self._res += np.sum(R**2, axis=0)
        self._count += N

    def merge(self, other: GainNoiseTally) -> None:
        """Add the sums of ``other`` (another log's, of the same gain and joints)."""
        self._pred += other._pred
        self._res += other._res
        self._count += other._count

    def result(self) -> GainNoise | None:
        """The RMS of both over every block added (None before any)."""
        if not np.any(self._count):
            return None
        c = np.maximum(self._count, 1.0)
        return GainNoise(self.gain, np.sqrt(self._pred / c), np.sqrt(self._res / c))
