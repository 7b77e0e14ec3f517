"""Measured torques of the opposite sign to the observer model's, read from the residual.

The residual estimates the external joint torques, ``dr/dt = K_O (tau_ext - r)`` with
``tau_ext = tau_model - tau`` (:mod:`dynid.observer.residual`): ``tau + r`` is the model's
torque as the observer sees it (through its lag, plus the measured torque's part faster
than ``K_O``). On a collision-free log it follows the measured torque, correlation near
``+1``; on a joint whose measured torque has the opposite sign to the model's it is its
negative, correlation near ``-1``, and the residual there is twice the torque: thresholds
calibrated on it are blind on that joint. The check sees every joint the model moves, the
joints gravity does not load included (a wrist), where the gravity check of
:mod:`dynid.identification.sanity` tells nothing (that check refuses a sign flipped on
any joint gravity loads, before the residual is read).

A joint is called opposite when the correlation is below :data:`OPPOSITE_CORRELATION`.
A model without torques on a joint (no parameters, no friction) gives ``tau + r`` equal
to the measured torque's fast part, whose correlation with it is never negative: such a
joint is never called opposite.

:class:`TorqueSign` keeps running sums over the blocks of a log (one block's temporaries)
and :func:`opposite_finding` makes the one-line finding.
"""

from __future__ import annotations

from collections.abc import Sequence

import numpy as np
from numpy.typing import ArrayLike, NDArray

from .. import _checks
from ..exceptions import ShapeError

__all__ = [
    "OPPOSITE_CORRELATION",
    "UNEXPLAINED_SHARE",
    "TorqueSign",
    "opposite_finding",
    "unexplained_finding",
]

#: A joint whose measured torque correlates with the model's below this is of the opposite
#: sign (module docstring).
OPPOSITE_CORRELATION = -0.5


class TorqueSign:
    """Per joint, the correlation of the measured torques ``tau`` with the model's
    ``tau + r`` over a log fed a block of samples at a time (module docstring).

    Parameters
    ----------
    n : int
        Joints.

    Examples
    --------
    >>> s = TorqueSign(2)
    >>> t = np.linspace(0.0, 1.0, 50)
    >>> tau = np.stack([np.sin(6 * t), np.cos(6 * t)], axis=1)
    >>> s.add(tau, np.stack([0.01 * tau[:, 0], -2.0 * tau[:, 1]], axis=1))
    >>> s.opposite().tolist()
    [False, True]
    """

    def __init__(self, n: int) -> None:
        self.n = int(n)
        self._count = 0
        self._mean = np.zeros((2, self.n))  # tau, model
        self._m2 = np.zeros((3, self.n))  # sums of squares: tau, model, cross

    def add(self, tau: ArrayLike, r: ArrayLike) -> None:
        """Add a block: measured torques ``tau`` (m, n) [N m] and the residual ``r`` (m, n)
        [N m] of the same samples (rows where ``r`` is NaN, not observed, are skipped).

        Raises
        ------
        ShapeError
            Shapes that disagree.
        """
        ta = _checks.as_array("tau", tau, allow_nonfinite=True)
        if ta.ndim != 2 or ta.shape[1] != self.n:
            raise ShapeError(f"tau must have shape (m, {self.n}); got {ta.shape}")
        ra = _checks.as_exact("r", r, ta.shape, allow_nonfinite=True)
        seen = np.all(np.isfinite(ra), axis=1) & np.all(np.isfinite(ta), axis=1)
        k = int(np.count_nonzero(seen))
        if k == 0:
            return
        x = np.stack([ta[seen], ta[seen] + ra[seen]])  # (2, k, n)
        mean = x.mean(axis=1)
        d = x - mean[:, None, :]
        m2 = np.stack([(d[0] ** 2).sum(0), (d[1] ** 2).sum(0), (d[0] * d[1]).sum(0)])
        # Chan et al.'s pairwise update: the sums about the joint mean, no cancellation
        total = self._count + k
        delta = mean - self._mean
        w = self._count * k / total
        self._m2 += m2 + w * np.stack([delta[0] ** 2, delta[1] ** 2, delta[0] * delta[1]])
        self._mean += delta * (k / total)
        self._count = total

    def correlation(self) -> NDArray[np.float64]:
        """Per joint (n,): the correlation of ``tau`` with ``tau + r``; 0 where either is
        constant or nothing was observed."""
        with np.errstate(invalid="ignore", divide="ignore"):
            c = self._m2[2] / np.sqrt(self._m2[0] * self._m2[1])
        return np.where(np.isfinite(c), c, 0.0)

    @property
    def count(self) -> int:
        """The samples observed so far."""
        return self._count

    def torque_spread(self) -> NDArray[np.float64]:
        """Per joint (n,): the measured torques' spread, ``sqrt(sum (tau - mean)^2)``
        [N m]."""
        return np.sqrt(np.maximum(self._m2[0], 0.0))

    def unexplained(self) -> NDArray[np.float64]:
        """Per joint (n,): the residual's spread over the measured torques', ``std(r) /
        std(tau)`` (``r`` the model's ``tau + r`` minus ``tau``); 0 where the torques are
        constant or nothing was observed."""
        tau, model, cross = self._m2
        with np.errstate(invalid="ignore", divide="ignore"):
            u = np.sqrt(np.maximum(model + tau - 2.0 * cross, 0.0) / tau)
        return np.where(np.isfinite(u), u, 0.0)

    def opposite(self) -> NDArray[np.bool_]:
        """Per joint (n,): its measured torques have the opposite sign to the model's."""
        out: NDArray[np.bool_] = self.correlation() < OPPOSITE_CORRELATION
        return out


def _flagged(sign: TorqueSign, mask: NDArray[np.bool_], names: Sequence[str]) -> list[int]:
    """The joints ``mask`` (n,) flags, for a finding naming them by ``names``.

    Raises
    ------
    ShapeError
        ``names`` not one per joint.
    """
    if len(names) != sign.n:
        raise ShapeError(f"names must hold {sign.n} joint names; got {len(names)}")
    return [int(k) for k in np.flatnonzero(mask)]


def opposite_finding(sign: TorqueSign, names: Sequence[str]) -> str | None:
    """The one-line finding of the joints of opposite sign (naming them, their
    correlations and the remedy: ``--units tau=-1`` when every joint is, the entries that
    flip their columns alone otherwise, ``--units tau2=-1``), or None when there is none.

    Raises
    ------
    ShapeError
        ``names`` not one per joint.
    """
    bad = _flagged(sign, sign.opposite(), names)
    if not bad:
        return None
    corr = sign.correlation()
    said = ", ".join(f"{corr[k]:+.2f} on {names[k]}" for k in bad)
    if len(bad) == sign.n:
        return (
            f"the measured torques of every joint are anti-correlated with the model's "
            f"torques (correlation {said}): the torque sign is probably opposite to the "
            "model's, and the residual is about twice the torque; hint: --units tau=-1 reads "
            "them flipped"
        )
    which = ", ".join(names[k] for k in bad)
    return (
        f"the measured torques of {which} are anti-correlated with the model's torques "
        f"(correlation {said}) while the other joints' agree: their torque sign is "
        "probably opposite to the model's (or the model is wrong there), and the residual "
        f"there is about twice the torque; hint: --units {','.join(f'tau{k + 1}=-1' for k in bad)} "
        f"reads {'it' if len(bad) == 1 else 'them'} flipped (beside the torques' unit, if one "
        "is given)"
    )


#: A residual whose spread is above this share of the measured torques' on a joint: the
#: model explains too little of the log there to calibrate on it.
UNEXPLAINED_SHARE = 0.5


def unexplained_finding(
    sign: TorqueSign, names: Sequence[str], gain_noise: ArrayLike | None = None
) -> str | None:
    """The one-line finding of the joints whose residual spreads over more than
    :data:`UNEXPLAINED_SHARE` of their measured torques' spread (the model, its drive or
    its friction do not fit the log: thresholds calibrated on it detect nothing smaller),
    among the joints whose torques vary (a tenth of the largest spread), or None.

    ``gain_noise`` (n,) [N m], the RMS of the velocities' noise through the observer's gain
    in the residual (:class:`~dynid.observer.gain_noise.GainNoise`), is taken out of the
    residual's spread first: that part is the gain's, not the model's error (a Baxter arm at
    the noise floor of its torques, 0.3 rad/s of velocity noise: 100 % of the residual of
    its shoulder), and the calibration's summary names it on its own.

    Raises
    ------
    ShapeError
        ``names`` or ``gain_noise`` not one per joint.
    """
    spread = sign.torque_spread()
    u = sign.unexplained()
    if gain_noise is not None:
        s = _checks.as_exact("gain_noise", gain_noise, (sign.n,))
        count = max(sign.count, 1)
        mine = np.maximum(u**2 - count * s**2 / np.maximum(spread**2, 1e-300), 0.0)
        u = np.where(spread > 0, np.sqrt(mine), u)
    varies = spread > 0.1 * float(spread.max(initial=0.0))
    bad = _flagged(sign, (u > UNEXPLAINED_SHARE) & varies, names)
    if not bad:
        return None
    said = ", ".join(f"{names[k]} {u[k]:.3g}" for k in bad)
    noise = "" if gain_noise is None else ", the velocities' noise through the gain taken out"
    return (
        f"the model leaves most of the measured torques unexplained (the residual's spread "
        f"over the torques'{noise}: {said}): thresholds calibrated on it detect only contacts "
        "larger than the model's error; hint: check the model, its drive and friction on "
        "this log with dynid validate"
    )
