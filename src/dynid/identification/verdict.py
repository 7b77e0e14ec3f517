"""How well a model predicts measured torques, in four levels a person can act on.

The relative error ``100 ||tau - tau_hat||_F / ||tau||_F`` [%] of unfiltered torques is
weighed against the sensor-noise floor when it is known (the smallest error any model can
reach on those torques: the noise's norm over the torques', [%]):

============  ===========================================  ================================
level         when                                         what to do
============  ===========================================  ================================
good          at most 1.5 x the noise floor ("at the        nothing: only noise is left
              noise floor"); without a floor, below 5 %
fair          at most 3 x the floor, or below 15 %          use it; effects outside the
              ("usable")                                    model remain (see residuals)
poor          below 50 %                                    add model terms, excite more,
                                                            check the drive
unusable      50 % or more, or torques anti-correlated      check the data first: another
              with the model's (opposite sign)              robot, other units, other sign
============  ===========================================  ================================

The pooled error is dominated by the joints of the largest torques: a wrist whose noise is
a hundredth of the shoulder's can err ten times its noise within a pooled error at the
floor. With each joint's error over its own noise known (``joint_ratios``), the level is
also the worst joint's (the same thresholds, 1.5 and 3 x), never worse than ``poor``, and
the reason names the joints above 1.5 x.

At 50 % the model explains less than three quarters of the torques' square; at 100 % it
errs as much as predicting no torque at all. The thresholds are this library's rules of
thumb (1.5 and 3 x the floor, 5 and 15 %), the same for ``dynid validate``'s verdict line,
its exit status and the verdicts of the HTML reports.
"""

from __future__ import annotations

import math
from collections.abc import Sequence
from dataclasses import dataclass
from typing import Literal

import numpy as np
from numpy.typing import ArrayLike

__all__ = [
    "FAIR_PERCENT",
    "FLOOR_FAIR",
    "FLOOR_GOOD",
    "GOOD_PERCENT",
    "LEVELS",
    "UNUSABLE_PERCENT",
    "Verdict",
    "judge_prediction",
    "pooled_verdict",
    "worst",
]

Level = Literal["good", "fair", "poor", "unusable"]
#: The levels, best first.
LEVELS: tuple[Level, ...] = ("good", "fair", "poor", "unusable")
#: Error / noise floor: at the floor up to FLOOR_GOOD, usable up to FLOOR_FAIR.
FLOOR_GOOD, FLOOR_FAIR = 1.5, 3.0
#: Relative error [%]: good below GOOD_PERCENT (without a floor), usable below FAIR_PERCENT.
GOOD_PERCENT, FAIR_PERCENT = 5.0, 15.0
#: Relative error [%] from which the model does not explain the torques.
UNUSABLE_PERCENT = 50.0


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


def worst(*levels: Level) -> Level:
    """The worst of ``levels`` (``"good"`` when none)."""
    return max(levels, key=LEVELS.index, default="good")


def judge_prediction(
    error_percent: float,
    floor_percent: float | None = None,
    *,
    opposite_sign: bool = False,
    joint_ratios: ArrayLike | None = None,
    joint_names: Sequence[str] | None = None,
) -> Verdict:
    """The level of a prediction (module docstring): :func:`pooled_verdict`, made worse by
    the worst of ``joint_ratios`` (each joint's RMS error over its torque noise), the
    joints above :data:`FLOOR_GOOD` named (``joint_names``, default 1-based numbers)."""
    v = pooled_verdict(error_percent, floor_percent, opposite_sign=opposite_sign)
    if joint_ratios is None or np.size(joint_ratios) == 0 or v.level in ("poor", "unusable"):
        return v
    r = np.asarray(joint_ratios, dtype=np.float64)
    bad = np.flatnonzero(np.isfinite(r) & (r > FLOOR_GOOD))
    if bad.size == 0:
        return v
    names = list(joint_names) if joint_names is not None else [str(j + 1) for j in range(r.size)]
    worst_r = float(np.max(r[bad]))
    level: Level = "fair" if worst_r <= FLOOR_FAIR else "poor"
    if LEVELS.index(level) <= LEVELS.index(v.level):
        return v
    which = ", ".join(f"{names[j]} at {r[j]:.2g} x" for j in bad)
    what = (
        "effects outside the model remain there"
        if level == "fair"
        else ("the model misses effects the data show there (model terms, excitation, the drive)")
    )
    label = "usable" if level == "fair" else "poor"
    return Verdict(
        level,
        label,
        f"{v.reason.split(':')[0]}; joint(s) {which} their noise: {what}",
        v.ratio,
    )


def pooled_verdict(
    error_percent: float,
    floor_percent: float | None = None,
    *,
    opposite_sign: bool = False,
) -> Verdict:
    """The level of a prediction of relative error ``error_percent`` [%] (module docstring).

    Parameters
    ----------
    error_percent : float
        Relative error of the unfiltered torques [%].
    floor_percent : float, optional
        The sensor-noise floor of the same torques [%]; None or 0: unknown.
    opposite_sign : bool
        The measured torques are anti-correlated with the model's.

    Returns
    -------
    Verdict
    """
    e = float(error_percent)
    floor = float(floor_percent) if floor_percent is not None else 0.0
    known = math.isfinite(floor) and floor > 0
    r = e / floor if known and math.isfinite(e) else None
    at = f" ({r:.2f} x the noise floor of {floor:.3g} %)" if r is not None else ""
    if opposite_sign:
        return Verdict(
            "unusable",
            "unusable",
            f"the measured torques are anti-correlated with the model's (error {e:.3g} %): "
            "a log of the opposite torque sign, or of another robot",
            r,
        )
    if not math.isfinite(e) or e >= UNUSABLE_PERCENT:
        what = (
            "100 % or more: worse than predicting no torque"
            if e >= 100.0
            else f"{UNUSABLE_PERCENT:g} % or more: a quarter or more of the torques' energy "
            "unexplained"
        )
        return Verdict(
            "unusable",
            "unusable",
            f"the model does not explain the torques: error {e:.3g} % ({what}); a log of "
            "another robot, in other units or of another sign?",
            r,
        )
    if r is not None and r <= FLOOR_GOOD:
        return Verdict("good", "at the noise floor", f"error {e:.3g} %{at}: only noise is left", r)
    if r is None and e < GOOD_PERCENT:
        return Verdict("good", "good", f"error {e:.3g} % (below {GOOD_PERCENT:g} %)", r)
    if (r is not None and r <= FLOOR_FAIR) or e < FAIR_PERCENT:
        return Verdict(
            "fair", "usable", f"error {e:.3g} %{at}: effects outside the model remain", r
        )
    return Verdict(
        "poor",
        "poor",
        f"error {e:.3g} %{at}: the model misses effects the data show (model terms, "
        "excitation, the drive)",
        r,
    )
