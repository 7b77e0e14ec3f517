"""The standstill margin at rest, calibrated from the rests of a collision-free log.

Inside a friction law's standstill band the true friction can lie anywhere in
``[-f_c, f_c]`` (:func:`~dynid.observer.friction.standstill_margin`), so the thresholds add
the Coulomb level there (:mod:`dynid.observer.detection`). What an arm holds at rest is a
property of the arm: one whose motors hold static friction (stiction) shows a residual up
to ``f_c`` at a rest; one whose friction vanishes at rest shows none, and the Coulomb level
then hides every push below it (a Z1 in motor currents: a 1.73 N m push at rest on joint 2,
whose margin was 0.6 N m, missed).

A joint is *at rest* where every motor that moves it lies inside its friction's standstill
band (a smooth sign's width, the velocity noise band where wider: :func:`at_rest`); its rest has
*settled* once it has lasted :data:`SETTLE_TIME_CONSTANTS` time constants of the observer's
lag (``10 / K_O``: 0.2 s at ``K_O = 50`` 1/s), when what the residual shows is what the arm
holds, not the lag of the motion before (a joint creeping inside its band for longer reads
as a rest: what its friction does there raises the calibrated level, towards the Coulomb
level); and it stays settled until that long before the
joint leaves the band (the velocities read that far ahead, as a controller knows when its
own motion starts): at the start of a motion, still inside the band, the friction breaks
away anywhere in ``[-f_c, f_c]`` whatever the arm holds at rest, and the Coulomb level is
back in place by then. The calibration reads the residual of every joint
at its settled rests (:class:`RestTally`): its largest value beyond what the threshold
already covers (``|r|`` less ``k sigma``), times the thresholds' own safety margin, less
the level the threshold has there without the standstill margin (the noise floor ``nu``, or
the fixed contact level) is the *calibrated rest level*. A joint with at least
:data:`MIN_RESTS` separate rests settled for at least :data:`MIN_REST_S` seconds each has
its standstill margin at settled rests taken as ``min(Coulomb level, calibrated rest
level)``; with fewer, its Coulomb level stays (the bound that holds whatever the arm does).
With a held friction drawn anywhere in ``[-f_c, f_c]`` at each rest, ten rests leave a
calibrated level below ``f_c`` with a chance of ``(1/1.5)^10 = 1.7 %`` at most.

:class:`~dynid.observer.thresholds.RestMargin` (in the thresholds, ``thresholds.json``'s
``rule.rest_margin``) records the levels and the rests counted; thresholds without it
(a file of an earlier version) keep the Coulomb level everywhere.
"""

from __future__ import annotations

import numpy as np
from numpy.typing import NDArray

from ..friction.model import FrictionModel, FrictionSum, friction_parts
from ..identification.rests import MIN_REST_S
from ..model.units import JointKinds, joint_unit
from .friction import canonical_friction
from .thresholds import RestMargin

__all__ = [
    "MIN_RESTS",
    "MIN_REST_S",
    "SETTLE_TIME_CONSTANTS",
    "RestClock",
    "RestTally",
    "at_rest",
    "rest_margin_lines",
    "settle_seconds",
]

#: Separate settled rests per joint a calibration needs to calibrate its rest level.
MIN_RESTS = 10
#: Time constants ``1 / K_O`` of the observer's lag after a joint enters its standstill
#: band before its rest is settled: the last of a motion creeps inside the band for up to
#: half of it (a quintic stop of 0.8 s moving a joint 0.01 rad: 0.13 s at 0.01 rad/s), its
#: friction anywhere in ``[-f_c, f_c]``, and ``exp(-5)`` (0.7 %) of that is left after the
#: other half.
SETTLE_TIME_CONSTANTS = 10.0


def settle_seconds(gains: NDArray[np.float64]) -> float:
    """Seconds [s] after entering the standstill band before a rest is settled:
    :data:`SETTLE_TIME_CONSTANTS` over the smallest observer gain ``gains`` (n,) [1/s]."""
    return float(SETTLE_TIME_CONSTANTS / np.min(gains))


def at_rest(
    friction: FrictionModel | FrictionSum | None,
    dq: NDArray[np.float64],
    bands: tuple[NDArray[np.float64], ...] | None = None,
) -> NDArray[np.bool_]:
    """Per sample and joint (..., n): every motor moving the joint (each part of
    ``friction`` through its transmission) inside its standstill band, the width ``v_s``
    of its smooth sign ``tanh(v / v_s)`` (inside it the Coulomb term is below 76 % of its
    level) or its velocity noise band ``bands`` (one (n,) array per part, [rad/s]),
    whichever is widest;
    all False without friction or for a law without a canonical form (no margin to
    calibrate). ``dq`` [rad/s] (..., n)."""
    v = np.asarray(dq, dtype=np.float64)
    parts = friction_parts(friction)
    if not parts:
        return np.zeros(v.shape, dtype=bool)
    out = np.ones(v.shape, dtype=bool)
    each = bands if bands is not None else (None,) * len(parts)
    for part, b in zip(parts, each, strict=True):
        canon = canonical_friction(part, v.shape[-1])
        if canon is None:
            return np.zeros(v.shape, dtype=bool)
        K, F = canon
        width = np.maximum(F[:, 5], F[:, 9])  # the band, a smooth sign's width
        if b is not None:
            width = np.maximum(width, np.asarray(b))
        inside = np.abs(v @ K.T) <= width  # per motor
        moves = np.abs(K) > 0  # (motors, joints)
        # a joint is at rest when no motor moving it is outside its band
        out &= ~((~inside).astype(np.float64) @ moves.astype(np.float64)).astype(bool)
    return out


class RestClock:
    """The settled part of each joint's rests (module docstring), carried from block to
    block of one piece: at rest for ``settle_s`` seconds or more already, and for
    ``settle_s`` seconds or more still (or to the piece's end)."""

    def __init__(self, n: int, settle_s: float) -> None:
        self.settle_s = settle_s
        self._since = np.full(n, np.nan)  # time the current rest began, NaN: moving

    def settled(
        self, t: NDArray[np.float64], rest: NDArray[np.bool_], m: int
    ) -> NDArray[np.float64]:
        """Seconds [s] (m, n) into the settled part of the rest at the first ``m`` of the
        times ``t`` (w,) [s], NaN outside it, from the rest mask ``rest`` (w, n)
        (:func:`at_rest`) of a window reaching ``settle_s`` past the block, or to the
        piece's end (a rest that reaches it does not end)."""
        w, n = rest.shape
        out = np.full((m, n), np.nan)
        k = np.arange(w)
        for j in range(n):
            x = rest[:, j]
            if not x[:m].any():
                self._since[j] = np.nan
                continue
            start = x & ~np.concatenate([[False], x[:-1]])
            run = np.maximum.accumulate(np.where(start, k, 0))[:m]  # its rest's first sample
            begin = t[run]
            if x[0] and np.isfinite(self._since[j]):  # a rest carried from the last block
                begin[run == 0] = self._since[j]
            out_next = np.minimum.accumulate(np.where(x, w, k)[::-1])[::-1][:m]  # moving again
            # no end in the window: settle_s or more ahead, or none before the piece's end
            end = np.where(out_next < w, t[np.minimum(out_next, w - 1)], np.inf)
            into = t[:m] - begin - self.settle_s
            keep = x[:m] & (into >= 0.0) & (end - t[:m] >= self.settle_s)
            out[keep, j] = into[keep]
            self._since[j] = begin[-1] if x[m - 1] else np.nan
        return out


class RestTally:
    """The residual at the settled rests of calibration blocks, a block at a time (module
    docstring): the largest ``|r|`` and ``(|r| - k sigma)^+`` per joint (every value with
    a ``quantile`` below 1) and the rests counted."""

    def __init__(self, n: int, settle_s: float, quantile: float, k_sigma: float) -> None:
        self.n, self.settle_s, self.quantile, self.k_sigma = n, settle_s, quantile, k_sigma
        self.rests = np.zeros(n, dtype=np.int64)
        self._top = np.zeros(n)
        self._top_excess = np.zeros(n)
        self._kept: list[NDArray[np.float64]] = []
        self._kept_excess: list[NDArray[np.float64]] = []
        self._prev = np.full(n, np.nan)

    def add(
        self,
        r: NDArray[np.float64],
        settled: NDArray[np.float64],
        std: NDArray[np.float64] | None = None,
    ) -> None:
        """One block: residual ``r`` (m, n) [N m], seconds into the settled part of a rest
        ``settled`` (m, n) [s] (:class:`RestClock`; NaN elsewhere), the residual's std
        ``std`` (m, n) [N m]. A rest counts once its settled part reaches
        :data:`MIN_REST_S`."""
        a = np.abs(r)
        inside = np.isfinite(settled) & np.isfinite(a)
        before = np.concatenate([self._prev[None], settled[:-1]])
        with np.errstate(invalid="ignore"):
            self.rests += np.count_nonzero(
                (settled >= MIN_REST_S) & ~(before >= MIN_REST_S), axis=0
            )
        if settled.shape[0]:
            self._prev = settled[-1].copy()
        x = np.where(inside, a, 0.0)
        e = x if std is None else np.where(inside, np.clip(a - self.k_sigma * std, 0.0, None), 0.0)
        if self.quantile < 1.0:
            self._kept.append(np.where(inside, a, np.nan))
            self._kept_excess.append(np.where(inside, e, np.nan))
        elif x.shape[0]:
            np.maximum(self._top, x.max(axis=0), out=self._top)
            np.maximum(self._top_excess, e.max(axis=0), out=self._top_excess)

    def result(
        self,
        margin: float,
        contact: NDArray[np.float64],
        noise: NDArray[np.float64] | None,
    ) -> RestMargin:
        """The calibrated rest levels [N m] of the joints with :data:`MIN_RESTS` rests
        (NaN for the others: their Coulomb level stays): ``margin`` times the largest
        (or ``quantile``) settled ``|r|`` less the fixed ``contact`` level (n,), and, with
        the model's uncertainty, ``margin`` times the largest ``(|r| - k sigma)^+`` less its
        noise floor ``noise`` (n,): the larger of the two, so that either threshold holds."""
        top, excess = self._top, self._top_excess
        if self.quantile < 1.0 and self._kept:
            with np.errstate(all="ignore"):
                A, E = np.concatenate(self._kept), np.concatenate(self._kept_excess)
                seen = np.isfinite(A).any(axis=0)
                top = np.where(seen, np.nanquantile(np.where(seen, A, 0.0), self.quantile, 0), 0)
                excess = np.where(
                    seen, np.nanquantile(np.where(seen, E, 0.0), self.quantile, 0), 0.0
                )
        level = np.clip(margin * top - contact, 0.0, None)
        if noise is not None:
            level = np.maximum(level, np.clip(margin * excess - noise, 0.0, None))
        enough = self.rests >= MIN_RESTS
        return RestMargin(
            level=np.where(enough, level, np.nan),
            rests=self.rests.copy(),
            settle_s=self.settle_s,
            min_rests=MIN_RESTS,
            min_rest_s=MIN_REST_S,
        )


def rest_margin_lines(
    rest: RestMargin,
    coulomb: NDArray[np.float64],
    names: list[str],
    margin: float,
    robot: JointKinds | None = None,
) -> list[str]:
    """What the standstill margin is at a settled rest, one line per joint whose Coulomb
    bound ``coulomb`` (n,) [N m] (:func:`~dynid.observer.friction.standstill_margin` at
    rest; of a smooth law, zero at rest, what its steps change within the velocity noise
    band: the largest margin the calibration applied) is not zero, and why: calibrated
    from the rests, the Coulomb bound which the rests reach, or the Coulomb bound for too
    few rests; ``margin`` the thresholds' safety
    factor, ``names`` the joints' (a prismatic joint of ``robot`` said in N)."""
    head = (
        f"standstill margin at rest (a joint inside its standstill band for {rest.settle_s:g} s "
        f"or more): min(Coulomb bound, {margin:g} x the residual at the calibration's rests "
        "beyond the threshold), calibrated where the logs hold "
        f"{rest.min_rests} rests or more of {rest.min_rest_s:g} s each:"
    )
    out = [head]
    for j, name in enumerate(names):
        c, level, k = float(coulomb[j]), float(rest.level[j]), int(rest.rests[j])
        if c <= 0.0:
            continue
        u = "N m" if robot is None else joint_unit("N m", bool(robot.prismatic[j]))
        if not np.isfinite(level):
            out.append(
                f"  {name}: Coulomb bound {c:.3g} {u}: too few rests ({k} of the "
                f"{rest.min_rests} needed)"
            )
        elif level < c:
            out.append(
                f"  {name}: {level:.3g} {u} calibrated from {k} rests (Coulomb bound {c:.3g} {u})"
            )
        else:
            out.append(
                f"  {name}: Coulomb bound {c:.3g} {u}: its {k} rests reach it (calibrated "
                f"{level:.3g} {u}: the friction held at rest)"
            )
    return out if len(out) > 1 else []
