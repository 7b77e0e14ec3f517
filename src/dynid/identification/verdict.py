"""How well a model predicts measured torques, in four levels a person can act on.

The relative error ``100 ||tau - tau_hat||_F / ||tau||_F`` [%] of unfiltered torques is
weighed against the noise floor when it is known (the smallest error any model can reach
on those torques: the noise's norm over the torques', [%]; the sensors' noise, and in
``validate`` also that the model's inputs put into its prediction,
:mod:`~dynid.identification.input_noise`, then weighed sample by sample):

============  ===========================================  ================================
level         when                                         what to do
============  ===========================================  ================================
good          at most 1.5 x the noise floor ("at the        nothing: only noise is left
              noise floor"); without a floor, below 5 %
fair          at most 3 x the floor, or below 15 %          use it; effects outside the
              ("usable")                                    model remain (see residuals)
poor          below 50 %                                    add model terms, excite more,
                                                            check the drive
unusable      50 % or more (unless within 3 x a noise       check the data first: another
              floor that high), 100 % or more, or torques  robot, other units, other sign
              anti-correlated with the model's (opposite
              sign)
============  ===========================================  ================================

Static data (``kind="static"``: a controller's ``M`` and ``g`` at configurations, no
motion and no drive) are judged by the same thresholds, and the reasons speak of ``M``
and ``g``: a poor model's miss what the data hold (another arm's links, a tool the
description lacks, other units), not model terms, excitation or the drive.

Torques mostly noise (a floor of 33 % or more, :data:`NOISY_FLOOR_PERCENT`: a prediction
of no torque at all is then within 3 x the floor) cannot tell a good model from a poor
one: within 3 x such a floor the verdict is usable, with that said, never at the floor
(a servo arm's coarse current steps the size of its torques: 59.9 % at 1.06 x a floor of
55.8 % read "unusable" for a model 3 % off the truth).

The pooled error is dominated by the joints of the largest torques: a wrist whose noise is
a hundredth of the shoulder's can err ten times its noise within a pooled error at the
floor, and so can a shoulder of 40 N m whose error is 2 % of its torque. Each joint is
judged by :func:`joint_levels`: good within :data:`SYSTEMATIC_RATIO` (1.25) x its noise
(below 10 % relative error where its noise is not known; within 1.5 x or below 10 % where
its noise is mostly the states' through the model, an estimate), usable below 25 % or
within 3 x, else poor. With the joints' errors known, the level is also the worst joint's, never
worse than ``poor``, and the reason names the joints judged worse than good, each with its
ratio to its noise and its RMS error [N m]: "only noise is left" is said only when no joint
is above its own noise. Below 0.01 % pooled error the joints are judged in relative terms
alone (a noise read from round-off says nothing) and the level is at worst ``usable``.
An error below 0.01 % is good whatever the floor: a floor read from exact data is the
round-off and filter error of the preparation, not a sensor's.

At 50 % the model explains less than three quarters of the torques' square; at 100 % it
errs as much as predicting no torque at all. The thresholds are this library's rules of
thumb (1.5 and 3 x the floor, 5 and 15 %; 1.25 x the noise, 10 and 25 % per joint), the
same for ``dynid validate``'s verdict line, its exit status, ``dynid identify``'s
held-out judgement and the verdicts of the HTML reports.
"""

from __future__ import annotations

import dataclasses
import math
from collections.abc import Sequence
from dataclasses import dataclass
from typing import Literal

import numpy as np
from numpy.typing import ArrayLike, NDArray

from ..exceptions import ShapeError

__all__ = [
    "FAIR_PERCENT",
    "FLOOR_FAIR",
    "FLOOR_GOOD",
    "GOOD_PERCENT",
    "JOINT_FAIR",
    "JOINT_GOOD",
    "LEVELS",
    "NEGLIGIBLE_PERCENT",
    "NOISY_FLOOR_PERCENT",
    "ROUND_OFF_PERCENT",
    "NOISE_FLOOR_SHARE",
    "SYSTEMATIC_RATIO",
    "UNUSABLE_PERCENT",
    "Verdict",
    "VerdictKind",
    "joint_levels",
    "joint_ratios",
    "judge_prediction",
    "pooled_verdict",
    "with_caveat",
    "with_hint",
    "with_replaced_spikes",
    "worst",
]

Level = Literal["good", "fair", "poor", "unusable"]
#: The levels, best first.
LEVELS: tuple[Level, ...] = ("good", "fair", "poor", "unusable")
#: Error / noise floor: at the floor up to FLOOR_GOOD, usable up to FLOOR_FAIR.
FLOOR_GOOD, FLOOR_FAIR = 1.5, 3.0
#: Relative error [%]: good below GOOD_PERCENT (without a floor), usable below FAIR_PERCENT.
GOOD_PERCENT, FAIR_PERCENT = 5.0, 15.0
#: Relative error [%] from which the model does not explain the torques (unless its noise
#: floor explains it: within FLOOR_FAIR x a floor that high).
UNUSABLE_PERCENT = 50.0
#: A noise floor [%] from which a prediction of no torque at all is within FLOOR_FAIR x it:
#: the torques are mostly noise and cannot tell a good model from a poor one (coarse
#: current steps of a servo against torques of their size); a verdict on them is at best
#: usable.
NOISY_FLOOR_PERCENT = 100.0 / FLOOR_FAIR
#: Relative error [%] of a joint: good below JOINT_GOOD, usable below JOINT_FAIR (or
#: within FLOOR_GOOD, FLOOR_FAIR x its noise).
JOINT_GOOD, JOINT_FAIR = 10.0, 25.0
#: A joint's RMS error over its noise above which its residual is systematic, not noise.
#: Noise alone gives 1 +- 1 / sqrt(2 N) over N samples (+-0.01 at 5 000, +-0.05 at 200)
#: and a correct model's leave-one-out prediction about sqrt(1 + p / (n N)) (p
#: coefficients, n joints: 1.00-1.15 on the Panda, PR2 and Baxter simulations); 1.25 is a
#: systematic residual of 0.75 x the noise RMS (sqrt(1.25^2 - 1)). A Baxter shoulder spring
#: the rigid-body model lacks left 2.4 x on its joint within a pooled 1.35 x the floor.
SYSTEMATIC_RATIO = 1.25
#: Relative error [%] below which a prediction is good whatever its noise floor.
NEGLIGIBLE_PERCENT = 0.01
#: Relative error [%] of a joint below which its residual is round-off, never systematic
#: whatever its ratio to a noise floor itself at round-off: noise-free logs of the geared
#: Panda with its coupled wrist, written to CSV and filtered, left 2e-5 to 4e-4 % per joint
#: at 5 to 40 x their floor; a noisy log leaves its noise, 0.1 % and more.
ROUND_OFF_PERCENT = 1e-3
#: A joint's torque noise counts at least this share of the largest joint's: a joint whose
#: noise estimate is next to nothing (a quantised or filtered sensor) must not outweigh
#: every other (the whitened judgement of the structure choice and the verdict).
NOISE_FLOOR_SHARE = 1e-2


#: The data a verdict judges: torques (a log) or a controller's static ``M`` and ``g``.
VerdictKind = Literal["torques", "static"]


@dataclass(frozen=True, slots=True)
class _Words:
    """What a verdict's reasons name for one kind of data (:data:`VerdictKind`)."""

    quantity: str  # what the model predicts
    nothing: str  # the prediction of nothing
    energy: str  # the quantity's square
    misses: str  # a poor model's miss, "{there}" where the joints are named
    check: str  # an unusable model's data to check
    beyond: str  # a joint at 100 % or more
    finer: str  # data that would tell, where they are mostly noise


_WORDS: dict[str, _Words] = {
    "torques": _Words(
        "the torques",
        "no torque",
        "the torques' energy",
        "the model misses effects the data show{there} (model terms, excitation, the drive)",
        "a log of another robot, in other units or of another sign?",
        "a log of another robot, or other kinematics?",
        "a recording of larger torques or finer torque readings",
    ),
    "static": _Words(
        "M and g",
        "zero M and g",
        "their square",
        "the model's M and g miss what the data hold{there} (another arm's links, a tool "
        "the description lacks, other units)",
        "data of another robot, in other units, or a tool the description lacks?",
        "data of another robot, or other kinematics?",
        "data of finer readings",
    ),
}


@dataclass(frozen=True, slots=True)
class Verdict:
    """A judgement of a prediction.

    Attributes
    ----------
    level : {"good", "fair", "poor", "unusable"}
    label : str
        The level in words: ``"at the noise floor"``, ``"good"``, ``"usable"``, ``"poor"``,
        ``"unusable"``.
    reason : str
        One clause: the numbers it was judged on and what they mean.
    ratio : float or None
        Error over the noise floor, when the floor is known.
    """

    level: Level
    label: str
    reason: str
    ratio: float | None = None

    @property
    def unusable(self) -> bool:
        """The model does not explain the torques."""
        return self.level == "unusable"

    def __str__(self) -> str:
        """The verdict as the commands print it: ``"label: reason"``."""
        return f"{self.label}: {self.reason}"


def worst(*levels: Level) -> Level:
    """The worst of ``levels`` (``"good"`` when none)."""
    return max(levels, key=LEVELS.index, default="good")


def joint_ratios(rms: ArrayLike, noise_rms: ArrayLike) -> NDArray[np.float64]:
    """Each joint's RMS error over its torque noise, the noise counted at least
    :data:`NOISE_FLOOR_SHARE` of the largest joint's.

    Parameters
    ----------
    rms, noise_rms : array_like, shape (n,)
        RMS prediction error and sensor noise per joint [N m].

    Returns
    -------
    ndarray, shape (n,)
        Error over noise; inf where the noise is zero on every joint and the error is not.
    """
    e = np.asarray(rms, dtype=np.float64)
    s = np.asarray(noise_rms, dtype=np.float64)
    least = NOISE_FLOOR_SHARE * float(np.max(s, initial=0.0))
    with np.errstate(divide="ignore", invalid="ignore"):
        r = e / np.maximum(s, least)
    return np.where(e == 0, 0.0, r)


def joint_levels(
    percent: ArrayLike | None, ratios: ArrayLike | None, rough: ArrayLike | None = None
) -> tuple[Level, ...]:
    """Each joint's level: good within :data:`SYSTEMATIC_RATIO` x its noise (where the
    ratio is unknown, below :data:`JOINT_GOOD` % relative error; below
    :data:`ROUND_OFF_PERCENT` %, round-off, whatever the ratio), fair below
    :data:`JOINT_FAIR` % or within :data:`FLOOR_FAIR` x, else poor. A joint whose error
    is a few percent of large torques is not good when that is twice its noise: the
    residual is systematic. A ``rough`` joint, whose noise is mostly the states' noise
    through the model (an estimate: a friction step blurred by the velocities' noise at
    reversals), is good within :data:`FLOOR_GOOD` x it or below :data:`JOINT_GOOD` %.

    Parameters
    ----------
    percent : array_like, shape (n,), optional
        Relative error per joint [%]; None: unknown (judged on ``ratios`` alone).
    ratios : array_like, shape (n,), optional
        RMS error over torque noise per joint (:func:`joint_ratios`); None: unknown
        (judged on ``percent`` alone). A NaN is unknown too; a joint unknown in both is
        good (nothing to judge it by).
    rough : array_like of bool, shape (n,), optional
        The joints whose noise is mostly the states' through the model (default none).

    Returns
    -------
    tuple of {"good", "fair", "poor"}

    Raises
    ------
    ShapeError
        ``percent`` and ``ratios`` of different joint counts.
    """
    if percent is None and ratios is None:
        return ()
    p = None if percent is None else np.asarray(percent, dtype=np.float64).ravel()
    r = None if ratios is None else np.asarray(ratios, dtype=np.float64).ravel()
    n = p.size if p is not None else r.size  # type: ignore[union-attr]
    p = np.full(n, np.nan) if p is None else p
    r = np.full(n, np.nan) if r is None else r
    if p.size != r.size:
        raise ShapeError(f"percent has {p.size} joints, ratios {r.size}")
    est = np.zeros(n, bool) if rough is None else np.asarray(rough, dtype=bool).ravel()
    if est.size != n:
        raise ShapeError(f"rough has {est.size} joints, ratios {n}")
    unknown = np.isnan(p) & np.isnan(r)
    relative = (np.isnan(r) | est) & (p < JOINT_GOOD)  # judged in relative terms too
    relative |= p < ROUND_OFF_PERCENT  # round-off over a floor at round-off: no residual
    limit = np.where(est, FLOOR_GOOD, SYSTEMATIC_RATIO)
    p, r = np.where(np.isnan(p), np.inf, p), np.where(np.isnan(r), np.inf, r)
    levels: list[Level] = []
    for pj, rj, none, small, lim in zip(p, r, unknown, relative, limit, strict=True):
        if none or small or rj <= lim:
            levels.append("good")
        elif pj < JOINT_FAIR or rj <= FLOOR_FAIR:
            levels.append("fair")
        else:
            levels.append("poor")
    return tuple(levels)


def judge_prediction(
    error_percent: float,
    floor_percent: float | None = None,
    *,
    opposite_sign: bool = False,
    joint_ratios: ArrayLike | None = None,
    joint_percent: ArrayLike | None = None,
    joint_names: Sequence[str] | None = None,
    floor_parts: str | None = None,
    ratio: float | None = None,
    joint_rms: ArrayLike | None = None,
    joint_rough: ArrayLike | None = None,
    kind: VerdictKind = "torques",
) -> Verdict:
    """The level of a prediction (module docstring): :func:`pooled_verdict`, made worse by
    the worst of :func:`joint_levels` (``joint_ratios``: each joint's RMS error over its
    torque noise; ``joint_percent``: its relative error [%]; either may be None), the
    joints judged worse than good named below a poor pooled level (``joint_names``,
    default 1-based numbers) with
    their RMS error ``joint_rms`` [N m] when given (``joint_rough``: the joints whose
    noise is mostly the states', :func:`joint_levels`); ``floor_parts`` and ``ratio`` as
    :func:`pooled_verdict`'s. Below :data:`NEGLIGIBLE_PERCENT` the joints are judged on
    ``joint_percent`` alone. ``kind``: the data judged, whose words the reasons use (module
    docstring)."""
    v = pooled_verdict(
        error_percent,
        floor_percent,
        opposite_sign=opposite_sign,
        floor_parts=floor_parts,
        ratio=ratio,
        kind=kind,
    )
    negligible = float(error_percent) < NEGLIGIBLE_PERCENT
    if negligible and joint_percent is not None:  # a noise of round-off says nothing
        levels = joint_levels(joint_percent, None)
    else:
        levels = joint_levels(joint_percent, joint_ratios, joint_rough)
    if not levels or v.level in ("poor", "unusable"):
        return v
    bad = [j for j, lv in enumerate(levels) if lv != "good"]
    if not bad:
        return v
    level = worst(*(levels[j] for j in bad))
    if negligible:
        level = min(level, "fair", key=LEVELS.index)  # never poor: near-exact data
    level = worst(level, v.level)  # the joints named even where the pooled level holds
    names = (
        list(joint_names) if joint_names is not None else [str(j + 1) for j in range(len(levels))]
    )
    which = _named_joints(bad, names, joint_ratios, joint_percent, joint_rms)
    w = _WORDS[kind]
    what = (
        "effects outside the model remain there"
        if level == "fair"
        else w.misses.format(there=" there")
    )
    p = None if joint_percent is None else np.asarray(joint_percent, dtype=np.float64).ravel()
    if p is not None and any(p[j] >= 100.0 for j in bad):  # worse than no torque at all
        what += f"; at 100 % or more: {w.beyond}"
    label = "usable" if level == "fair" else "poor"
    pooled = v.reason.split(":")[0]
    if LEVELS.index(level) > LEVELS.index(v.level):  # the help's pooled rule alone says better
        pooled += f", {_POOLED_WORDS[v.level]} pooled and judged by its worst joint"
    return Verdict(level, label, f"{pooled}; joint(s) {which}: {what}", v.ratio)


#: The pooled level in the words of a verdict judged by its worst joint instead.
_POOLED_WORDS = {
    "good": f"within {FLOOR_GOOD:g} x the floor",
    "fair": "usable",
    "poor": "poor",
    "unusable": "unusable",
}


def _named_joints(
    bad: list[int],
    names: Sequence[str],
    ratios: ArrayLike | None,
    percent: ArrayLike | None,
    rms: ArrayLike | None,
) -> str:
    """The joints ``bad`` in words: ``"2 at 2.43 x (0.738 N m RMS, 1.9 %) their noise"``
    (each part when known), or ``"2 at 12 %"`` without ratios."""
    r = None if ratios is None else np.asarray(ratios, dtype=np.float64).ravel()
    p = None if percent is None else np.asarray(percent, dtype=np.float64).ravel()
    e = None if rms is None else np.asarray(rms, dtype=np.float64).ravel()
    if r is None:
        return ", ".join(f"{names[j]} at {p[j]:.3g} %" for j in bad)  # type: ignore[index]
    out = []
    for j in bad:
        parts = ([] if e is None else [f"{e[j]:.3g} N m RMS"]) + (
            [] if p is None else [f"{p[j]:.3g} %"]
        )
        out.append(f"{names[j]} at {r[j]:.3g} x" + (f" ({', '.join(parts)})" if parts else ""))
    return ", ".join(out) + " their noise"


def pooled_verdict(
    error_percent: float,
    floor_percent: float | None = None,
    *,
    opposite_sign: bool = False,
    floor_parts: str | None = None,
    ratio: float | None = None,
    kind: VerdictKind = "torques",
) -> Verdict:
    """The level of a prediction of relative error ``error_percent`` [%] (module docstring).

    Parameters
    ----------
    error_percent : float
        Relative error of the unfiltered torques [%].
    floor_percent : float, optional
        The noise floor of the same torques [%]: their sensors' noise, and the noise the
        model's inputs put into its prediction when known
        (:mod:`~dynid.identification.input_noise`); None or 0: unknown.
    opposite_sign : bool
        The measured torques are anti-correlated with the model's.
    floor_parts : str, optional
        What the floor is made of, said after it (``", of which the torques' noise ..."``;
        no colon: the reason is cut at its first).
    ratio : float, optional
        The error over the floor when it is not ``error_percent / floor_percent``: weighed
        sample by sample against a noise that varies (default: that quotient).
    kind : {"torques", "static"}
        The data judged: a torque log's torques, or static data's ``M`` and ``g``, whose
        words the reasons use (module docstring).

    Returns
    -------
    Verdict
    """
    e, w = float(error_percent), _WORDS[kind]
    floor = float(floor_percent) if floor_percent is not None else 0.0
    known = math.isfinite(floor) and floor > 0
    r = e / floor if known and math.isfinite(e) else None
    if r is not None and ratio is not None and math.isfinite(ratio):
        r = float(ratio)
    parts = floor_parts or ""
    at = f" ({r:.3g} x the noise floor of {floor:.3g} %{parts})" if r is not None else ""
    if opposite_sign:
        return Verdict(
            "unusable",
            "unusable",
            f"the measured torques are anti-correlated with the model's (error {e:.3g} %): "
            "a log of the opposite torque sign, or of another robot",
            r,
        )
    explained = r is not None and r <= FLOOR_FAIR and e < 100.0  # by a floor that high
    if not math.isfinite(e) or (e >= UNUSABLE_PERCENT and not explained):
        what = (
            f"100 % or more: worse than predicting {w.nothing}"
            if e >= 100.0
            else f"{UNUSABLE_PERCENT:g} % or more: a quarter or more of {w.energy} unexplained"
        )
        return Verdict(
            "unusable",
            "unusable",
            f"the model does not explain {w.quantity}: error {e:.3g} % ({what}); {w.check}",
            r,
        )
    if r is not None and r <= FLOOR_FAIR and floor >= NOISY_FLOOR_PERCENT:
        return Verdict(
            "fair",
            "usable",
            f"error {e:.3g} %{at}: {w.quantity} are mostly noise, {floor:.3g} % of them, so "
            f"these data cannot tell a good model from a poor one (a prediction of {w.nothing} "
            f"would be {100.0 / floor:.3g} x the floor); judge it on {w.finer}",
            r,
        )
    if r is not None and r <= FLOOR_GOOD:
        return Verdict("good", "at the noise floor", f"error {e:.3g} %{at}: only noise is left", r)
    if e < NEGLIGIBLE_PERCENT:
        return Verdict(
            "good", "good", f"error {e:.3g} %{at}: below {NEGLIGIBLE_PERCENT:g} %, negligible", r
        )
    if r is None and e < GOOD_PERCENT:
        return Verdict("good", "good", f"error {e:.3g} % (below {GOOD_PERCENT:g} %)", r)
    if (r is not None and r <= FLOOR_FAIR) or e < FAIR_PERCENT:
        return Verdict(
            "fair", "usable", f"error {e:.3g} %{at}: effects outside the model remain", r
        )
    return Verdict(
        "poor",
        "poor",
        f"error {e:.3g} %{at}: {w.misses.format(there='')}",
        r,
    )


def with_caveat(verdict: Verdict, caveat: str | None) -> Verdict:
    """``verdict`` with a ``caveat`` on what the data it was judged on can tell: a verdict
    at the noise floor (``"good"``) is ``"fair"`` (usable) with the caveat, a worse one
    keeps its level and gets the caveat appended; ``verdict`` itself without one."""
    if caveat is None:
        return verdict
    if verdict.level == "good":
        return Verdict(
            "fair", "usable", f"{verdict.reason} on these data, but {caveat}", verdict.ratio
        )
    return Verdict(verdict.level, verdict.label, f"{verdict.reason}; {caveat}", verdict.ratio)


def with_hint(verdict: Verdict, hint: str | None, joiner: str = "; ") -> Verdict:
    """``verdict`` with ``hint`` appended to its reason (after ``joiner``) when it is above
    the noise floor (not ``"good"``) and there is a hint; else ``verdict`` itself."""
    if verdict.level == "good" or hint is None:
        return verdict
    return Verdict(verdict.level, verdict.label, f"{verdict.reason}{joiner}{hint}", verdict.ratio)


def with_replaced_spikes(verdict: Verdict, count: int, detail: str = "") -> Verdict:
    """``verdict`` with its reason saying that it was judged with ``count`` one-sample torque
    spikes replaced (:func:`~dynid.identification.spikes.despiked`), ``detail`` appended
    (``", as the fit replaced them"``, the files); ``verdict`` itself when ``count`` is 0."""
    if count <= 0:
        return verdict
    said = (
        f"{verdict.reason}; judged with {count} one-sample torque spike(s) replaced by the "
        f"line between their neighbours{detail}"
    )
    return dataclasses.replace(verdict, reason=said)
