"""Is a calibrated observer good enough: its false alarms on the calibration logs and the
smallest external torque it detects.

A calibration answers two questions beside its thresholds. *False alarms*: the events the
detector (:func:`~dynid.observer.events.detect`, the default event rules) raises on the
collision-free logs the thresholds came from, per minute of them; with ``--quantile`` 1
none by construction (every sample's ``|r|`` lies under ``margin`` times the largest), with
a lower quantile the samples above it may raise some. *Smallest detectable torque*: a
constant external torque ``A`` on joint ``j`` moves its residual to ``A`` after the
observer's lag and crosses the contact threshold once ``A`` exceeds it, so the smallest
torque detected wherever the joint moves along the calibration motion is the largest
contact threshold there, ``nu_j + k max_t sigma_j(t)`` (``nu`` the noise floor, ``sigma``
the model's uncertainty propagated along the motion: :mod:`~dynid.observer.detection`), or
the fixed threshold without the uncertainty; the standstill margin aside (a joint at rest:
:func:`~dynid.observer.detection.undetected_at_rest`). *The model behind them*: the
thresholds hold the model's error on the calibration logs beside the sensors' noise, so
the model is judged on those logs as ``dynid validate`` judges it
(:class:`ModelCheck`, :func:`model_words`): a poor model makes wide thresholds.
"""

from __future__ import annotations

from collections.abc import Iterable
from dataclasses import dataclass

import numpy as np
from numpy.typing import ArrayLike, NDArray

from ..identification.verdict import Verdict
from .events import detect
from .thresholds import Thresholds, threshold_series
from .trust import QuietResidual, quiet_residual, sample_ratio

__all__ = [
    "CalibrationCheck",
    "ModelCheck",
    "calibration_false_alarms",
    "calibration_quiet",
    "collision_level",
    "detectable",
    "model_words",
]


@dataclass(frozen=True, slots=True)
class ModelCheck:
    """The observer's model judged on the calibration logs as ``dynid validate`` judges a
    model on a log (:func:`~dynid.workflows.validate.validate_files`: the error against the
    noise floor of the sensors and of the states through the model, each joint against its
    noise).

    Attributes
    ----------
    verdict : Verdict
        validate's verdict (:func:`~dynid.identification.verdict.judge_prediction`).
    error_percent : float
        The relative error of the model's torques with its friction on the logs [%].
    floor_percent : float
        The noise floor of the same torques [%].
    fitted : tuple of int
        ``(k, m)``: ``k`` of the ``m`` calibration logs are recordings the model was
        identified from (judged in-sample); ``(0, m)`` or ``()`` none.
    """

    verdict: Verdict
    error_percent: float
    floor_percent: float
    fitted: tuple[int, ...] = ()

    def words(self) -> str:
        """:func:`model_words` of this judgement."""
        v = self.verdict
        return model_words(
            self.error_percent, self.floor_percent, v.level, v.label, v.ratio, self.fitted
        )


def model_words(
    error_percent: float,
    floor_percent: float,
    level: str,
    label: str,
    ratio: float | None,
    fitted: tuple[int, ...] = (),
) -> str:
    """``"the model predicts the calibration logs' torques to 3.21 %, 1.04 x the noise
    floor of 3.09 % (validate's verdict: at the noise floor)"``, and for a poor or
    unusable model that the thresholds are wide because of it: the sentence of a
    :class:`ModelCheck` (``ratio``: the verdict's, each sample against its own noise;
    ``fitted`` ``(k, m)``: ``k`` of the ``m`` logs are the model's own training
    recordings, said, since a judgement on them is in-sample)."""
    said = f"the model predicts the calibration logs' torques to {error_percent:.3g} %"
    if ratio is not None:
        said += f", {ratio:.3g} x the noise floor of {floor_percent:.3g} %"
    said += f" (validate's verdict: {label}"
    if len(fitted) == 2 and fitted[0] > 0:
        k, m = fitted
        whose = "all are" if k == m else f"{k} of {m} are"
        said += (
            f"; {whose} the identification's own recordings, so in-sample: dynid validate "
            "on a recording left out of the fit judges the model"
        )
    said += ")"
    if level in ("poor", "unusable"):
        said += (
            ": the thresholds are wide because of the model's error, not the sensors' "
            "noise; a better model (dynid identify on these logs) narrows them"
        )
    elif level == "fair":
        said += (
            ": the thresholds hold the model's error beside the sensors' noise; a better "
            "model narrows them"
        )
    return said


@dataclass(frozen=True, slots=True, eq=False)
class CalibrationCheck:
    """What a calibration says of the observer (module docstring).

    Attributes
    ----------
    duration_s : float
        The calibration logs' total duration [s].
    false_alarms : int or None
        Events on the calibration logs against their thresholds (None: not counted;
        ``dynid observe`` counts them whether or not it keeps the residual).
    sigma_max : ndarray, shape (n,), or None
        The largest ``sigma_j(t)`` over the calibration samples [N m] (None: thresholds
        without the uncertainty).
    detectable : ndarray, shape (n,)
        The smallest external torque detected wherever the joint moves [N m].
    peak : ndarray, shape (n,)
        The largest ``|r|`` of the calibration logs [N m].
    model : ModelCheck or None
        The model judged on the calibration logs (None: not judged).
    collision : ndarray, shape (n,), or None
        The collision level wherever the joint moves [N m]: the largest collision
        threshold along the motion (:func:`collision_level`; None: not given).
    level : float or None
        The residual's level over the calibration logs in shares of the contact threshold
        (:meth:`~dynid.observer.trust.QuietResidual.level` of :func:`calibration_quiet`),
        which a detection's trust verdict compares its own with; None: not read.
    """

    duration_s: float
    false_alarms: int | None
    sigma_max: NDArray[np.float64] | None
    detectable: NDArray[np.float64]
    peak: NDArray[np.float64]
    model: ModelCheck | None = None
    collision: NDArray[np.float64] | None = None
    level: float | None = None

    @property
    def false_alarms_per_min(self) -> float | None:
        """False alarms per minute of the calibration logs (None: not counted, or no
        time logged)."""
        if self.false_alarms is None or not self.duration_s > 0:
            return None
        return 60.0 * self.false_alarms / self.duration_s


def detectable(thresholds: Thresholds, sigma_max: ArrayLike | None) -> NDArray[np.float64]:
    """The smallest external torque [N m] (n,) detected wherever a joint moves: ``nu +
    k sigma_max`` for thresholds with the uncertainty (``sigma_max`` (n,) [N m], the
    largest ``sigma`` over the calibration), else the fixed contact threshold."""
    if thresholds.uses_uncertainty and sigma_max is not None:
        assert thresholds.noise is not None and thresholds.k_sigma is not None
        s = np.asarray(sigma_max, dtype=np.float64)
        return np.asarray(thresholds.noise + thresholds.k_sigma * s, dtype=np.float64)
    return np.array(thresholds.contact, dtype=np.float64)


def collision_level(thresholds: Thresholds, sigma_max: ArrayLike | None) -> NDArray[np.float64]:
    """The collision level [N m] (n,) wherever a joint moves: ``collision_factor`` times
    :func:`detectable` for thresholds with the uncertainty, else the fixed collision
    threshold; the one number the summary, ``thresholds.json`` and the report give."""
    if thresholds.uses_uncertainty and sigma_max is not None:
        return np.asarray(thresholds.collision_factor * detectable(thresholds, sigma_max))
    return np.array(thresholds.collision, dtype=np.float64)


def calibration_false_alarms(
    thresholds: Thresholds,
    logs: Iterable[tuple[NDArray[np.float64], NDArray[np.float64], NDArray | None, NDArray | None]],
) -> int:
    """Events the default rules raise on the calibration logs, each ``(t, r, std,
    standstill)``: times [s] (N,), residual, its std and standstill margin [N m] (N, n;
    None where the thresholds do not use them)."""
    count = 0
    for t, r, std, still in logs:
        std = std if thresholds.uses_uncertainty else None
        still = still if thresholds.standstill else None
        count += len(detect(t, r, thresholds, std=std, standstill=still))
    return count


def calibration_quiet(
    thresholds: Thresholds,
    logs: Iterable[tuple[NDArray[np.float64], NDArray[np.float64], NDArray | None, NDArray | None]],
) -> QuietResidual:
    """The residual of the calibration logs, each ``(t, r, std, standstill)`` as
    :func:`calibration_false_alarms` takes them, against the thresholds in force at each
    sample: every sample's ``max_j |r_j| / contact_j`` pooled
    (:func:`~dynid.observer.trust.quiet_residual`; a collision-free log holds no event to
    leave out)."""
    parts = []
    for t, r, std, still in logs:
        std = std if thresholds.uses_uncertainty else None
        still = still if thresholds.standstill else None
        contact, _ = threshold_series(thresholds, r.shape[0], std, still)
        parts.append(quiet_residual(t, sample_ratio(r, contact)))
    return QuietResidual.pooled(parts)
