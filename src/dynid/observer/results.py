"""What an observation of logs gives: every log's residual and events, and the thresholds.

:class:`ObserveResult` is what :func:`dynid.workflows.observe.observe_files` returns and
what :func:`dynid.io.observer_files.save_observation` writes.
"""

from __future__ import annotations

from dataclasses import dataclass
from pathlib import Path

import numpy as np
from numpy.typing import NDArray

from .detection import ContactEvent, Thresholds
from .model import ObserverModel
from .wrench import WrenchEstimate

__all__ = ["LogObservation", "ObserveResult"]


@dataclass(frozen=True, slots=True, eq=False)
class LogObservation:
    """The residual of one log and what was found in it.

    Attributes
    ----------
    path : Path
    t : ndarray, shape (N,)
    r : ndarray, shape (N, n)
        Residual [N m].
    std : ndarray, shape (N, n), or None
        Its standard deviation from the model's uncertainty (when used).
    events : list of ContactEvent
        Empty when calibrating.
    wrench : WrenchEstimate or None
        At ``frame``, when one was given.
    tau_ext : ndarray, shape (N, n), or None
        The true external torques stored beside the log (a simulated contact).
    standstill : ndarray, shape (N, n), or None
        The lagged standstill margin of the model's friction
        (:func:`~dynid.observer.detection.standstill_series`), when the thresholds use it.
    restarts : tuple of int
        First sample of each piece the observer ran on (the log cut at its gaps).
    """

    path: Path
    t: NDArray[np.float64]
    r: NDArray[np.float64]
    std: NDArray[np.float64] | None
    events: list[ContactEvent]
    wrench: WrenchEstimate | None
    tau_ext: NDArray[np.float64] | None
    standstill: NDArray[np.float64] | None = None
    restarts: tuple[int, ...] = (0,)

    def truth_error(self) -> NDArray[np.float64] | None:
        """RMS [N m] (n,) per joint of the residual against the true external torques
        ``r - tau_ext`` (the observer's first-order lag included), over the samples the
        observer ran on; None without ``tau_ext``."""
        if self.tau_ext is None:
            return None
        e = self.r - self.tau_ext
        ran = np.all(np.isfinite(e), axis=1)
        if not ran.any():
            return None
        out: NDArray[np.float64] = np.sqrt(np.mean(e[ran] ** 2, axis=0))
        return out


@dataclass(frozen=True, slots=True, eq=False)
class ObserveResult:
    """What :func:`observe_files` computed: the model, the thresholds (calibrated or read)
    and every log's observation."""

    model: ObserverModel
    thresholds: Thresholds
    logs: tuple[LogObservation, ...]
