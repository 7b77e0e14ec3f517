"""How far to trust a detection's events: one verdict from what the observer already knows.

Events alone do not say whether they are contacts or the model's misfit on this log. The
residual *outside the events* does: on a log the model fits, it stays well under the
contact threshold there (the thresholds were calibrated as a margin over it); on a log it
misfits, it sits close under the threshold and crosses it now and then, and those
crossings are false alarms. Per sample, ``rho = max_j |r_j| / contact_j(t)`` (the
threshold in force: uncertainty and standstill margin included) is read outside every
event and labelled contact, each widened by :data:`SETTLE_LAGS` time constants of the
observer's lag (:func:`guard_s`), as a histogram (:class:`QuietResidual`: exact to
:data:`RATIO_STEP`, summed over logs and blocks). Its :data:`LEVEL_QUANTILE` quantile is
the residual's *level* outside events, in shares of the threshold.

A calibration records the same level over its collision-free logs beside its false alarms
there (:class:`CalibratedOn`, ``thresholds.json``'s ``calibration``), so a detection
compares the two: :func:`trust_verdict` says ``good``, ``fair`` or ``poor`` in one line
from the level (against :data:`FAIR_LEVEL` and :data:`POOR_LEVEL`, and against the
calibration's), the time events cover, the thresholds' origin and, where the log has
labelled contacts, the false alarms counted against them per minute of contact-free time
beside the calibration's rate.
"""

from __future__ import annotations

from collections.abc import Iterable, Sequence
from dataclasses import dataclass
from typing import Any, Literal

import numpy as np
from numpy.typing import ArrayLike, NDArray

__all__ = [
    "FAIR_LEVEL",
    "LEVEL_QUANTILE",
    "POOR_LEVEL",
    "RATIO_STEP",
    "SETTLE_LAGS",
    "CalibratedOn",
    "QuietResidual",
    "TrustVerdict",
    "guard_s",
    "quiet_residual",
    "sample_ratio",
    "trust_verdict",
]

#: Width of the histogram's bins of ``|r| / contact threshold``.
RATIO_STEP = 0.01
#: Bins up to a ratio of 2; one more holds every larger ratio.
_BINS = 200
#: The quantile of the ratio outside events said as the residual's level there.
LEVEL_QUANTILE = 0.95
#: Time constants of the observer's lag an event or a labelled contact is widened by on
#: each side before the residual outside it is read (0.7 % of a step left).
SETTLE_LAGS = 5.0
#: A level outside events above this share of the threshold: fair at best (a model that
#: fits sits under it: on a simulated Panda with its own model, 45 to 49 %, the
#: calibration's 47 %).
FAIR_LEVEL = 0.55
#: A level outside events above this share of the threshold: poor, false alarms expected
#: (above the calibration's largest ``|r|``, which its margin of 1.5 puts at 67 %).
POOR_LEVEL = 0.7
#: A level this many times the calibration's, and above :data:`HALF`: fair at best.
FAIR_FACTOR = 1.2
#: Half the threshold: under it the residual is far from raising events.
HALF = 0.5
#: A level this many times the calibration's: poor.
POOR_FACTOR = 1.4
#: Events covering more than this share of the logs leave too little outside them: poor.
FLAGGED_SHARE = 0.5
#: Labelled false alarms per minute of contact-free time above both this and twice the
#: calibration's rate: poor.
RATE_FLOOR_PER_MIN = 1.0


@dataclass(frozen=True, slots=True, eq=False)
class QuietResidual:
    """The residual outside events as a histogram of ``rho`` (module docstring).

    Attributes
    ----------
    counts : ndarray of int, shape (201,)
        Samples per bin of ``rho``: ``[k, k + 1) * RATIO_STEP`` for ``k < 200``, the last
        every ``rho >= 2``.
    seconds : float
        The time those samples cover [s] (their count times the log's median step).
    """

    counts: NDArray[np.int64]
    seconds: float

    @staticmethod
    def empty() -> QuietResidual:
        return QuietResidual(np.zeros(_BINS + 1, dtype=np.int64), 0.0)

    @property
    def samples(self) -> int:
        return int(self.counts.sum())

    @staticmethod
    def pooled(parts: Iterable[QuietResidual]) -> QuietResidual:
        """Every histogram of ``parts`` summed (an empty one for none)."""
        out = QuietResidual.empty()
        for q in parts:
            out = out.plus(q)
        return out

    def plus(self, other: QuietResidual) -> QuietResidual:
        """Both histograms pooled (logs or calibration logs)."""
        return QuietResidual(self.counts + other.counts, self.seconds + other.seconds)

    def level(self, q: float = LEVEL_QUANTILE) -> float | None:
        """The ``q`` quantile of ``rho`` (the upper edge of its bin; None: no sample)."""
        total = self.samples
        if not total:
            return None
        k = int(np.searchsorted(np.cumsum(self.counts), q * total, side="left"))
        return round(min(k + 1, _BINS + 1) * RATIO_STEP, 6)

    def above(self, share: float = 0.5) -> float | None:
        """The share (0 to 1) of the samples with ``rho`` at or above ``share`` (None: no
        sample)."""
        total = self.samples
        if not total:
            return None
        k = int(round(share / RATIO_STEP))
        return float(self.counts[k:].sum() / total)


def sample_ratio(r: ArrayLike, contact: ArrayLike) -> NDArray[np.float64]:
    """``rho`` (m,) of a block: the largest ``|r_j| / contact_j`` over the joints of each
    sample, ``r`` and ``contact`` (m, n) [N m] (NaN where the observer did not run, or
    the threshold is not positive)."""
    ra, ca = np.asarray(r, dtype=np.float64), np.asarray(contact, dtype=np.float64)
    with np.errstate(divide="ignore", invalid="ignore"):
        ratio = np.where(ca > 0, np.abs(ra) / ca, np.nan)
    seen = np.all(np.isfinite(ratio), axis=1) if ratio.size else np.zeros(ra.shape[0], bool)
    out = np.full(ra.shape[0], np.nan)
    if seen.any():
        out[seen] = ratio[seen].max(axis=1)
    return out


def guard_s(gains: ArrayLike) -> float:
    """How far [s] an event's residual takes to settle: :data:`SETTLE_LAGS` time
    constants ``1 / K_O`` of the slowest joint (``gains`` [1/s])."""
    return SETTLE_LAGS / float(np.min(np.asarray(gains, dtype=np.float64)))


def quiet_residual(
    t: ArrayLike,
    ratio: ArrayLike,
    spans: Iterable[tuple[float, float]] = (),
    guard: float = 0.0,
    step: float | None = None,
) -> QuietResidual:
    """The histogram of ``ratio`` (N,) (:func:`sample_ratio`; NaN: not observed) at times
    ``t`` (N,) [s] outside every span ``(start, end)`` [s] (events, labelled contacts)
    widened by ``guard`` [s] on each side; ``step`` [s] the time a sample stands for
    (default: the median step of ``t``)."""
    ta = np.asarray(t, dtype=np.float64).reshape(-1)
    rho = np.asarray(ratio, dtype=np.float64).reshape(-1)
    keep = np.isfinite(rho)
    for a, b in spans:
        lo, hi = np.searchsorted(ta, a - guard, "left"), np.searchsorted(ta, b + guard, "right")
        keep[lo:hi] = False
    bins = np.minimum((rho[keep] / RATIO_STEP).astype(np.int64), _BINS)
    counts = np.bincount(bins, minlength=_BINS + 1).astype(np.int64)
    if step is None:
        steps = np.diff(ta)
        step = float(np.median(steps[steps > 0])) if np.any(steps > 0) else 0.0
    return QuietResidual(counts, float(keep.sum()) * step)


@dataclass(frozen=True, slots=True)
class CalibratedOn:
    """What thresholds were calibrated on (``thresholds.json``'s ``calibration``).

    Attributes
    ----------
    data : tuple of str
        The collision-free logs' names.
    duration_s : float or None
        Their total duration [s].
    false_alarms : int or None
        The events the thresholds raise on them (None: not counted).
    level : float or None
        The residual's :data:`LEVEL_QUANTILE` level over them in shares of the threshold
        (:meth:`QuietResidual.level`; None: not recorded, a file of an earlier version).
    """

    data: tuple[str, ...] = ()
    duration_s: float | None = None
    false_alarms: int | None = None
    level: float | None = None

    @property
    def false_alarms_per_min(self) -> float | None:
        if self.false_alarms is None or not (self.duration_s or 0.0) > 0:
            return None
        assert self.duration_s is not None
        return 60.0 * self.false_alarms / self.duration_s

    def named(self) -> str:
        """``"free.csv"``, ``"a.csv, b.csv"``, ``"4 logs"``: the logs in a few words."""
        if not self.data:
            return "its logs"
        return ", ".join(self.data) if len(self.data) <= 2 else f"{len(self.data)} logs"


@dataclass(frozen=True, slots=True)
class TrustVerdict:
    """How far to trust a detection's events (module docstring).

    Attributes
    ----------
    level : {"good", "fair", "poor"}
    words : str
        The one line: ``"trust: good - ..."``.
    quiet_level : float or None
        The residual's level outside events, in shares of the threshold.
    above_half : float or None
        The share of the time outside events with the residual above half the threshold.
    quiet_s : float
        The time outside events [s].
    calibration_level : float or None
        The calibration's level (None: not recorded).
    calibration_per_min : float or None
        The calibration's false alarms per minute of its logs.
    false_alarms : int or None
        False alarms counted against labelled contacts (None: no labels).
    false_alarms_per_min : float or None
        Per minute of contact-free time.
    reasons : tuple of str
        What lowered the verdict, as short keys (``level``, ``worse``, ``flagged``,
        ``false_alarms``, ``uncalibrated``).
    """

    level: Literal["good", "fair", "poor"]
    words: str
    quiet_level: float | None
    above_half: float | None
    quiet_s: float
    calibration_level: float | None
    calibration_per_min: float | None
    false_alarms: int | None
    false_alarms_per_min: float | None
    reasons: tuple[str, ...]

    def as_dict(self) -> dict[str, Any]:
        """``events.json``'s ``trust``."""
        return {
            "level": self.level,
            "summary": self.words,
            "quiet_level": self.quiet_level,
            "above_half": self.above_half,
            "quiet_s": self.quiet_s,
            "calibration_level": self.calibration_level,
            "calibration_false_alarms_per_min": self.calibration_per_min,
            "false_alarms": self.false_alarms,
            "false_alarms_per_min": self.false_alarms_per_min,
            "reasons": list(self.reasons),
        }


def _pct(x: float) -> str:
    return f"{100.0 * x:.0f} %"


def trust_verdict(
    quiet: QuietResidual,
    calibrated: CalibratedOn | None,
    *,
    flagged_share: float = 0.0,
    labelled: tuple[int, float] | None = None,
) -> TrustVerdict:
    """The trust verdict of a detection (module docstring).

    Parameters
    ----------
    quiet : QuietResidual
        The residual outside events and labelled contacts, every log pooled.
    calibrated : CalibratedOn or None
        What the thresholds were calibrated on (None: thresholds of unknown origin).
    flagged_share : float
        The share (0 to 1) of the logs' time the events cover.
    labelled : (int, float) or None
        The false alarms counted against labelled contacts and the contact-free time
        [s] (None: no labels).
    """
    level, above = quiet.level(), quiet.above(HALF)
    cal_level = None if calibrated is None else calibrated.level
    cal_rate = None if calibrated is None else calibrated.false_alarms_per_min
    rate = None
    if labelled is not None and labelled[1] > 0:
        rate = 60.0 * labelled[0] / labelled[1]
    high = level is not None and level > FAIR_LEVEL
    worse = False
    if level is not None and cal_level is not None:
        worse = level > max(FAIR_FACTOR * cal_level, HALF)
    more = rate is not None and rate > max(2.0 * (cal_rate or 0.0), RATE_FLOOR_PER_MIN)
    checks = {
        "flagged": flagged_share > FLAGGED_SHARE,
        "level": high,
        "worse": worse,
        "false_alarms": more,
        "uncalibrated": calibrated is None,
    }
    reasons = [k for k, v in checks.items() if v]
    poor = flagged_share > FLAGGED_SHARE or more
    if level is not None:
        limit = POOR_LEVEL if cal_level is None else min(POOR_LEVEL, POOR_FACTOR * cal_level)
        poor = poor or level > max(limit, FAIR_LEVEL)
    verdict: Literal["good", "fair", "poor"] = "poor" if poor else "fair" if reasons else "good"
    parts = [_level_words(level, above, quiet.seconds, flagged_share)]
    parts.append(_calibration_words(calibrated, level, cal_level, cal_rate))
    if labelled is not None:
        parts.append(
            f"against the labels {labelled[0]} false alarm{'s' if labelled[0] != 1 else ''}"
            + ("" if rate is None else f", {rate:.2g} per minute of contact-free time")
        )
    advice = _advice(verdict, reasons)
    words = f"trust: {verdict} - " + "; ".join(p for p in parts if p) + advice
    return TrustVerdict(
        verdict, words, level, above, quiet.seconds, cal_level, cal_rate,
        None if labelled is None else labelled[0], rate, tuple(reasons),
    )  # fmt: skip


def _level_words(
    level: float | None, above: float | None, seconds: float, flagged_share: float
) -> str:
    if level is None:
        return f"events cover {_pct(flagged_share)} of the logs, no residual outside them"
    said = f"outside events the residual sits at {_pct(level)} of the threshold"
    said += f" (95 % of {seconds:.3g} s; above half of it {_pct(above or 0.0)} of the time)"
    if flagged_share > FLAGGED_SHARE:
        said = f"events cover {_pct(flagged_share)} of the logs; " + said
    return said


def _calibration_words(
    calibrated: CalibratedOn | None,
    level: float | None,
    cal_level: float | None,
    cal_rate: float | None,
) -> str:
    if calibrated is None:
        return "thresholds of unknown origin (no calibration recorded)"
    rate = "" if cal_rate is None else f"{cal_rate:.2g} false alarms per minute, "
    said = f"calibrated on {calibrated.named()}"
    if cal_level is None:
        return said + (f" ({rate[:-2]})" if rate else "")
    said += f" ({rate}residual at {_pct(cal_level)})"
    if level is not None and cal_level > 0:
        said += f": this log's misfit is {level / cal_level:.2g} x the calibration's"
    return said


def _advice(verdict: str, reasons: Sequence[str]) -> str:
    if verdict == "good":
        return ""
    if verdict == "poor":
        return (
            ": expect false alarms; the model misfits this log (check it with dynid "
            "validate, or calibrate on logs like it)"
        )
    if reasons == ["uncalibrated"]:
        return ": calibrate the thresholds on collision-free logs (--calibrate)"
    return ": some events may be false alarms"
