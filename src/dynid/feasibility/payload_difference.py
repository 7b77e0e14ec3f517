"""The residual a load's doubt is judged on: the fit's, or what the load leaves beyond the arm.

Without a recording free of the load, the fit's residual is judged against the noise
floor: the torque noise after the low-pass and the states' noise through the arm's model
(:mod:`~dynid.feasibility.payload_floor`; :class:`JudgedResidual` of kind ``"fit"``):
torques the arm's model lacks go into the load.

With a recording of the same motion without the load (``--unloaded``), the arm's model
misses the same torques ``e(q, dq, ddq)`` in both (a joint spring, another friction law,
an armature left out): the loaded fit leaves ``r1 = e(x1) + p(x1) + n1`` (``p`` what the
load's model does not explain), the arm identified without the load leaves
``r0 = e(x0) + n0``. At matched states ``x0 = x1`` the difference ``r1 - r0 = p + n1 - n0``
holds the load's misfit alone; it is judged against the noise of both,
``sqrt(s1^2 + s0^2)``, and the states' noise through the model of both (the loaded
samples' twice: at matched states the two are alike) (:class:`JudgedResidual` of kind
``"difference"``).

Matching (:func:`matched_residual`): each state ``x = (q, dq, ddq)`` (joints taken as
still zeroed, as in the rows) is scaled per coordinate by the unloaded samples' spread
(RMS about the mean); a loaded sample's nearest unloaded sample, then the closest point on
the segments to its neighbours in the same piece, gives ``r0`` interpolated along the
unloaded trajectory (a motion repeated with a time shift of part of a sample). A sample
is matched when that point lies within :data:`MATCH_DISTANCE` of it (RMS over the
coordinates, in units of their spread); with fewer than :data:`MIN_MATCHED` of the loaded
samples matched, the motions are not the same and the fit's residual is judged.
"""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import dataclass
from typing import Literal

import numpy as np
from numpy.typing import NDArray

from ..identification.prepared_log import PreparedLog
from ..identification.solvers import scaled_lstsq

__all__ = [
    "MATCH_DISTANCE",
    "MIN_MATCHED",
    "JudgedResidual",
    "arm_residual",
    "judged_residual",
    "loaded_floor_rms",
    "matched_residual",
    "piece_states",
]

#: A loaded sample's state within this RMS distance (per coordinate, in units of its spread
#: over the unloaded samples) of the unloaded trajectory is matched.
MATCH_DISTANCE = 0.05
#: The part of the loaded samples that must be matched for the difference to be judged.
MIN_MATCHED = 0.5


@dataclass(frozen=True, slots=True)
class JudgedResidual:
    """The residual a load's doubt is judged on (module docstring).

    Attributes
    ----------
    kind : {"fit", "difference"}
        ``"fit"``: the load's fit residual; ``"difference"``: the loaded fit's residual
        less the unloaded arm's at matched states.
    residual_rms : float
        [N m].
    noise_rms : float or None
        What the torque noise alone leaves in it [N m]: the loaded rows' after the
        low-pass, or of both recordings (``"difference"``); None when not known.
    matched : float
        Part of the loaded samples matched to the unloaded recording (0 without one).
    states_rms : float or None
        What the states' noise through the arm's model leaves in it [N m]
        (:mod:`~dynid.feasibility.payload_floor`; of both recordings for
        ``"difference"``); None when not known.
    weighted : float or None
        The residual over both noises with each sample weighed against its own noise
        (:func:`~dynid.feasibility.payload_floor.floor_ratio`); None: the plain quotient.
    """

    kind: Literal["fit", "difference"]
    residual_rms: float
    noise_rms: float | None
    matched: float = 0.0
    states_rms: float | None = None
    weighted: float | None = None

    @property
    def floor_rms(self) -> float | None:
        """The noise floor [N m]: ``noise_rms`` and ``states_rms``, root sum of squares;
        None when the torque noise is not known."""
        if not self.noise_rms:
            return None
        return float(np.hypot(self.noise_rms, self.states_rms or 0.0))

    @property
    def ratio(self) -> float | None:
        """The residual over the noise floor: ``weighted`` when known, else
        ``residual_rms / floor_rms``; None when the noise is not known."""
        if self.weighted is not None:
            return self.weighted
        floor = self.floor_rms
        return self.residual_rms / floor if floor else None

    @property
    def what(self) -> str:
        """The residual in words, for messages."""
        if self.kind == "fit":
            return "the fit"
        return (
            "the loaded fit's residual less the unloaded arm's at matched states "
            f"({100 * self.matched:.0f} % of the samples matched)"
        )


def loaded_floor_rms(noise_rms: float | None, judged: JudgedResidual | None) -> float | None:
    """The loaded recordings' noise floor [N m]: their torque noise after the low-pass
    ``noise_rms`` and the states' noise through the arm's model that ``judged`` holds
    (of the loaded samples: half the variance of a difference's), root sum of squares;
    ``noise_rms`` when the states' noise is not known."""
    if not noise_rms or judged is None or not judged.states_rms:
        return noise_rms
    states = judged.states_rms / (np.sqrt(2.0) if judged.kind == "difference" else 1.0)
    return float(np.hypot(noise_rms, states))


def piece_states(
    pieces: Sequence[PreparedLog], still: NDArray[np.bool_]
) -> tuple[NDArray[np.float64], NDArray[np.int64]]:
    """The states ``[q, dq, ddq]`` [rad, rad/s, rad/s^2] (N, 3 n) of prepared pieces, the
    velocities and accelerations of ``still`` joints (n,) zeroed as in the load's rows,
    and the piece of each sample (N,)."""
    xs, labels = [], []
    for k, piece in enumerate(pieces):
        log = piece.log
        ddq = np.zeros_like(log.dq) if log.ddq is None else log.ddq
        xs.append(np.concatenate([log.q, log.dq * ~still, ddq * ~still], axis=1))
        labels.append(np.full(log.q.shape[0], k))
    return np.concatenate(xs), np.concatenate(labels)


def arm_residual(
    W: NDArray[np.float64], y: NDArray[np.float64], kept: NDArray[np.bool_], n: int
) -> NDArray[np.float64]:
    """The arm's residual [N m] (N, n) on rows without the load: the targets ``y`` (N n,)
    less the classical friction columns of ``W`` (N n, 10 + 3 n; those ``kept``) fitted
    to them, as the load's fit corrects its own (the load's 10 columns left out)."""
    F = W[:, 10:][:, kept[10:]]
    return (y - F @ scaled_lstsq(F, y)).reshape(-1, n)


def matched_residual(
    x1: NDArray[np.float64],
    x0: NDArray[np.float64],
    labels0: NDArray[np.int64],
    r0: NDArray[np.float64],
) -> tuple[NDArray[np.float64], NDArray[np.float64]]:
    """``r0`` (N0, n) interpolated along the unloaded trajectory at the states ``x1``
    (N1, d) of the loaded samples (module docstring), and each one's distance from it
    (N1,), RMS over the ``d`` coordinates in units of their spread over ``x0`` (N0, d);
    ``labels0`` (N0,) the piece of each unloaded sample."""
    from scipy.spatial import cKDTree  # as the rest of the package: scipy on first use

    spread = np.sqrt(np.mean((x0 - x0.mean(axis=0)) ** 2, axis=0))
    s = np.where(spread > 0, spread, 1.0)
    a, b = x0 / s, x1 / s
    j = cKDTree(a).query(b)[1]
    best_d = np.full(b.shape[0], np.inf)
    best_r = np.empty((b.shape[0], r0.shape[1]))
    last = a.shape[0] - 1
    for lo, hi in ((j - 1, j), (j, j + 1)):
        lo, hi = np.clip(lo, 0, last), np.clip(hi, 0, last)
        same = labels0[lo] == labels0[hi]
        lo = np.where(same, lo, j)
        hi = np.where(same, hi, j)
        seg = a[hi] - a[lo]
        den = np.einsum("ij,ij->i", seg, seg)
        t = np.einsum("ij,ij->i", b - a[lo], seg) / np.where(den > 0, den, 1.0)
        t = np.clip(np.where(den > 0, t, 0.0), 0.0, 1.0)
        d = np.linalg.norm(b - a[lo] - t[:, None] * seg, axis=1)
        closer = d < best_d
        best_d = np.where(closer, d, best_d)
        r = r0[lo] + t[:, None] * (r0[hi] - r0[lo])
        best_r[closer] = r[closer]
    return best_r, best_d / np.sqrt(a.shape[1])


def judged_residual(
    r1: NDArray[np.float64],
    noise1: float | None,
    x1: NDArray[np.float64] | None = None,
    x0: NDArray[np.float64] | None = None,
    labels0: NDArray[np.int64] | None = None,
    r0: NDArray[np.float64] | None = None,
    noise0: float | None = None,
) -> tuple[JudgedResidual, NDArray[np.float64]]:
    """The residual a load's doubt is judged on (module docstring) and its rows (flat,
    the loaded samples matched, or all).

    Parameters
    ----------
    r1 : ndarray, shape (N1, n)
        The load's fit residual per loaded sample [N m].
    noise1 : float or None
        What the torque noise leaves in ``r1`` [N m] (None: not known).
    x1, x0 : ndarray, shape (N1, 3 n) and (N0, 3 n), optional
        The loaded and unloaded samples' states (:func:`piece_states`); None without an
        unloaded recording.
    labels0 : ndarray, shape (N0,), optional
        The piece of each unloaded sample.
    r0 : ndarray, shape (N0, n), optional
        The arm's residual on the unloaded samples (:func:`arm_residual`) [N m].
    noise0 : float or None
        What the torque noise leaves in ``r0`` [N m].
    """
    fit = JudgedResidual("fit", float(np.sqrt(np.mean(r1**2))), noise1)
    if x1 is None or x0 is None or labels0 is None or r0 is None:
        return fit, r1.ravel()
    at, dist = matched_residual(x1, x0, labels0, r0)
    ok = dist < MATCH_DISTANCE
    part = float(np.mean(ok))
    if part < MIN_MATCHED:
        return JudgedResidual("fit", fit.residual_rms, noise1, part), r1.ravel()
    d = (r1[ok] - at[ok]).ravel()
    both = None if not noise1 or not noise0 else float(np.hypot(noise1, noise0))
    return JudgedResidual("difference", float(np.sqrt(np.mean(d**2))), both, part), d
