"""The exciting-trajectory form: a Fourier series between (1 - cos) ramps, at rest at both ends.

Form (Gaz et al. 2019, supplementary material Sec. II). Per joint ``j``, ``L`` harmonics of
``w_f`` between two ramps of ``T / 2`` each (``T = ramp``); with ``tau = t - T / 2``:

.. math:: \\dot q_j(\\tau) = \\sum_{l=1}^{L} a_{jl} \\cos(l w_f \\tau) + b_{jl} \\sin(l w_f \\tau),
          \\quad 0 \\le \\tau \\le D

and ``q_j`` its integral. The ramp in, ``dq = (A / 2) (1 - cos(2 pi t / T))`` for
``0 <= t <= T / 2`` with ``A = dq(tau = 0)``, starts at rest at ``q_start``; the ramp out,
``dq = (V / 2) (1 + cos(2 pi u / T))`` for ``0 <= u <= T / 2`` with ``V = dq(tau = D)``,
ends at rest. Total length ``D + T`` (the paper: ``D = 20`` s, ``T = 1`` s,
``w_f = 0.15 pi`` rad/s, ``L = 5``). The velocity is continuous; the acceleration is
continuous when ``ddq(tau = 0) = ddq(tau = D) = 0``, which the optimiser imposes (the
paper's own trajectory has steps there).

:class:`ExcitingTrajectory` holds the coefficients and samples the motion at any times; its
design for identification is :func:`~dynid.simulation.excitation.optimise_excitation`.
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import Any

import numpy as np
from numpy.typing import ArrayLike, NDArray

from .. import _checks
from ..exceptions import OptionError, ShapeError
from .trajectories import Trajectory, uniform_times

__all__ = ["ExcitingTrajectory"]


@dataclass(frozen=True, slots=True, eq=False)
class ExcitingTrajectory:
    """Fourier-series joint motion between (1 - cos) ramps, starting and ending at rest.

    Attributes
    ----------
    w_f : float
        Base angular frequency [rad/s].
    a, b : ndarray, shape (n, L)
        Cosine and sine velocity coefficients [rad/s].
    q_start : ndarray, shape (n,)
        Rest position at ``t = 0`` [rad].
    duration : float
        Length ``D`` of the Fourier part [s].
    ramp : float
        ``T``: the two ramps together [s] (``T / 2`` each).
    """

    w_f: float
    a: NDArray[np.float64]
    b: NDArray[np.float64]
    q_start: NDArray[np.float64]
    duration: float
    ramp: float = 1.0

    def __post_init__(self) -> None:
        if not (self.w_f > 0 and self.duration > 0 and self.ramp > 0):
            raise OptionError(
                f"w_f, duration and ramp must be positive; got {self.w_f}, {self.duration}, "
                f"{self.ramp}"
            )
        a = _checks.as_array("a", self.a)
        if a.ndim != 2:
            raise ShapeError(f"a must have shape (n, L); got {a.shape}")
        object.__setattr__(self, "a", _checks.frozen(a))
        object.__setattr__(self, "b", _checks.frozen(_checks.as_exact("b", self.b, a.shape)))
        q0 = _checks.as_exact("q_start", self.q_start, (a.shape[0],))
        object.__setattr__(self, "q_start", _checks.frozen(q0))
        for k in ("w_f", "duration", "ramp"):
            object.__setattr__(self, k, float(getattr(self, k)))

    @property
    def n(self) -> int:
        """Number of joints."""
        return self.a.shape[0]

    @property
    def total_duration(self) -> float:
        """``duration + ramp`` [s]."""
        return self.duration + self.ramp

    def __call__(self, t: ArrayLike) -> Trajectory:
        """Samples at times ``t`` (N,) [s]; at rest at ``q_start`` before 0 and at the end after."""
        t = _checks.as_array("t", t)
        if t.ndim != 1:
            raise ShapeError(f"t must have shape (N,); got {t.shape}")
        Pq, Pd, Pa = _basis(t, self.w_f, self.a.shape[1], self.duration, self.ramp)
        c = np.concatenate([self.a, self.b], axis=1)  # (n, 2L)
        q = self.q_start + Pq @ c.T
        return Trajectory(t=t, q=q, dq=Pd @ c.T, ddq=Pa @ c.T)

    def sample(self, fs: float = 1000.0) -> Trajectory:
        """Samples at ``k / fs`` over ``[0, total_duration]`` (N,)."""
        return self(uniform_times(self.total_duration, fs))

    def to_dict(self) -> dict[str, Any]:
        """Plain numbers (JSON), with the form's parameters and units."""
        return {
            "form": "Fourier series between (1 - cos) ramps (Gaz et al. 2019, suppl. Sec. II)",
            "w_f_rad_s": self.w_f,
            "base_frequency_hz": self.w_f / (2 * np.pi),
            "harmonics": int(self.a.shape[1]),
            "duration_s": self.duration,
            "ramp_s": self.ramp,
            "total_duration_s": self.total_duration,
            "a_rad_s": self.a.tolist(),
            "b_rad_s": self.b.tolist(),
            "q_start_rad": self.q_start.tolist(),
        }

    @classmethod
    def from_dict(cls, d: dict[str, Any]) -> ExcitingTrajectory:
        """Inverse of :meth:`to_dict`."""
        return cls(
            w_f=float(d["w_f_rad_s"]),
            a=np.asarray(d["a_rad_s"], dtype=np.float64),
            b=np.asarray(d["b_rad_s"], dtype=np.float64),
            q_start=np.asarray(d["q_start_rad"], dtype=np.float64),
            duration=float(d["duration_s"]),
            ramp=float(d["ramp_s"]),
        )


def _basis(
    t: NDArray[np.float64], w_f: float, L: int, D: float, T: float
) -> tuple[NDArray[np.float64], NDArray[np.float64], NDArray[np.float64]]:
    """Maps (N, 2L) from the coefficients ``[a, b]`` of one joint to ``q - q_start``, dq, ddq."""
    lw = w_f * np.arange(1, L + 1)
    h = 0.5 * T
    tau = np.clip(t - h, 0.0, D)
    s, c = np.sin(tau[:, None] * lw), np.cos(tau[:, None] * lw)
    # Fourier part relative to its start (q = 0 at tau = 0)
    Fq = np.concatenate([s / lw, (1.0 - c) / lw], axis=1)
    Fd = np.concatenate([c, s], axis=1)
    Fa = np.concatenate([-s * lw, c * lw], axis=1)
    sD, cD = np.sin(D * lw), np.cos(D * lw)
    A_row = np.concatenate([np.ones(L), np.zeros(L)])  # dq at tau = 0
    V_row = np.concatenate([cD, sD])  # dq at tau = D
    qD_row = np.concatenate([sD / lw, (1.0 - cD) / lw])
    w = 2 * np.pi / T
    t_in = np.clip(t, 0.0, h)
    u = np.clip(t - h - D, 0.0, h)
    # ramp in: q = A/2 (t - sin(w t)/w) over [0, h], then A T / 4 from there on
    ramp_q_in = 0.5 * (t_in - np.sin(w * t_in) / w)
    ramp_d_in = np.where(t <= h, 0.5 * (1 - np.cos(w * t_in)), 0.0)
    ramp_a_in = np.where(t <= h, 0.5 * w * np.sin(w * t_in), 0.0)
    # ramp out: dq = V/2 (1 + cos(w u)), q = V/2 (u + sin(w u)/w)
    out = t > h + D
    ramp_q_out = 0.5 * (u + np.sin(w * u) / w)
    ramp_d_out = np.where(out, 0.5 * (1 + np.cos(w * u)), 0.0)
    ramp_a_out = np.where(out, -0.5 * w * np.sin(w * u), 0.0)
    inside = (t > h) & (t <= h + D)
    Pq = ramp_q_in[:, None] * A_row + Fq + ramp_q_out[:, None] * V_row
    Pq[t <= h] = ramp_q_in[t <= h, None] * A_row  # before the Fourier part starts
    Pq[out] = (h / 2) * A_row + qD_row + ramp_q_out[out, None] * V_row
    Pd = np.where(inside[:, None], Fd, 0.0) + ramp_d_in[:, None] * A_row
    Pd += ramp_d_out[:, None] * V_row
    Pa = np.where(inside[:, None], Fa, 0.0) + ramp_a_in[:, None] * A_row
    Pa += ramp_a_out[:, None] * V_row
    return Pq, Pd, Pa
