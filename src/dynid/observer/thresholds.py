"""Per-joint detection thresholds and their value at every sample.

:class:`Thresholds` holds what :func:`~dynid.observer.detection.calibrate` computed (fixed
levels, or ``k sigma + nu`` with the model's uncertainty, and whether the standstill
margin is added: :mod:`dynid.observer.detection`); :func:`threshold_series` gives both
levels, contact and collision, at the samples of a log or of a block of it.
"""

from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np
from numpy.typing import ArrayLike, NDArray

from .. import _checks
from ..exceptions import DataError, ShapeError
from .residual import ObserverOptions

__all__ = ["ModelFingerprint", "Thresholds", "threshold_series"]


@dataclass(frozen=True, slots=True)
class ModelFingerprint:
    """What a model was made of: the files (or names) it was read from and a SHA-256 of
    their content and of the chain chosen in them
    (:func:`~dynid.workflows.observe.model_fingerprint`).

    Attributes
    ----------
    files : tuple of str
        The model's files by name (``identification.json``; ``z1.urdf``,
        ``friction.json``, ``drive.toml``), or a built-in robot's name.
    sha256 : str
        Hex digest: equal for the same content, whatever the files are called.
    roles : tuple of str
        What each of ``files`` was given as (``model``, ``params``, ``friction``,
        ``drive``); empty: not recorded (a file of an earlier version).
    """

    files: tuple[str, ...]
    sha256: str
    roles: tuple[str, ...] = ()

    def given_as(self, role: str) -> str | None:
        """The file given as ``role`` (``friction``), or None: none given, or the roles
        not recorded (:attr:`roles`)."""
        return next((f for f, r in zip(self.files, self.roles, strict=False) if r == role), None)

    def __str__(self) -> str:
        return f"{' + '.join(self.files)} (sha256 {self.sha256[:12]})"


@dataclass(frozen=True, slots=True, eq=False)
class Thresholds:
    """Per-joint detection thresholds (:mod:`dynid.observer.detection`); arrays read-only.

    Attributes
    ----------
    contact, collision : ndarray, shape (n,)
        Fixed thresholds [N m] (the distribution rule).
    margin, quantile, collision_factor : float
        The rule's parameters.
    k_sigma : float or None
        ``k`` of the uncertainty-grown threshold; None: fixed thresholds only.
    noise : ndarray, shape (n,), or None
        Its noise floor ``nu`` [N m] (the contact level's).
    standstill : bool
        The lagged standstill margin of the model's friction is added to both levels
        (calibrated without it).
    options : ObserverOptions
        The observer the thresholds were calibrated with (the residual they apply to).
    samples : int
        Calibration samples.
    model : ModelFingerprint or None
        The model they were calibrated with (None: not recorded, a file of an earlier
        version).
    """

    contact: NDArray[np.float64]
    collision: NDArray[np.float64]
    margin: float
    quantile: float
    collision_factor: float
    options: ObserverOptions
    samples: int
    k_sigma: float | None = None
    noise: NDArray[np.float64] | None = field(default=None)
    standstill: bool = False
    model: ModelFingerprint | None = None

    def __post_init__(self) -> None:
        n = np.shape(self.contact)[0]
        for name in ("contact", "collision") + (("noise",) if self.noise is not None else ()):
            a = _checks.as_exact(name, getattr(self, name), (n,))
            if np.any(a < 0):
                raise DataError(f"thresholds: {name} must be >= 0 [N m]; got {a.tolist()}")
            object.__setattr__(self, name, _checks.frozen(a))

    @property
    def n(self) -> int:
        """Joints."""
        return int(self.contact.shape[0])

    @property
    def uses_uncertainty(self) -> bool:
        """Whether the thresholds grow with the model's uncertainty."""
        return self.k_sigma is not None and self.noise is not None


def threshold_series(
    thresholds: Thresholds,
    N: int,
    std: ArrayLike | None = None,
    standstill: ArrayLike | None = None,
) -> tuple[NDArray[np.float64], NDArray[np.float64]]:
    """The contact and collision thresholds at every sample, each (N, n) [N m]: fixed, or
    ``k sigma + nu`` (and its ``collision_factor`` multiple) when ``std`` (N, n) is given
    and the thresholds use the model's uncertainty; plus the standstill margin
    ``standstill`` (N, n) when given and the thresholds use it.

    ``std`` and ``standstill`` are NaN where the observer did not run (the edges of a
    piece whose velocities are derived from the positions, where the residual is NaN
    too): the thresholds are NaN at those samples.

    Raises
    ------
    ShapeError
        ``std`` or ``standstill`` not (N, n), or infinite.
    """
    n = thresholds.n
    if std is not None and thresholds.uses_uncertainty:
        assert thresholds.k_sigma is not None and thresholds.noise is not None
        s = _unobserved_nan("std", std, (N, n))
        c = thresholds.k_sigma * s + thresholds.noise
        k = thresholds.collision_factor * c
    else:
        c = np.broadcast_to(thresholds.contact, (N, n)).copy()
        k = np.broadcast_to(thresholds.collision, (N, n)).copy()
    if standstill is not None and thresholds.standstill:
        w = _unobserved_nan("standstill", standstill, (N, n))
        c, k = c + w, k + w
    return c, k


def _unobserved_nan(name: str, x: ArrayLike, shape: tuple[int, int]) -> NDArray[np.float64]:
    """``x`` of ``shape``, finite or NaN (a sample not observed), never infinite."""
    a = _checks.as_exact(name, x, shape, allow_nonfinite=True)
    if np.any(np.isinf(a)):
        raise ShapeError(f"{name} must be finite or NaN (not observed); got inf")
    return a
