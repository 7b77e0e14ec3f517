"""Per-joint detection thresholds and their value at every sample.

:class:`Thresholds` holds what :func:`~dynid.observer.detection.calibrate` computed (fixed
levels, or ``k sigma + nu`` with the model's uncertainty, and whether the standstill
margin is added: :mod:`dynid.observer.detection`); :func:`threshold_series` gives both
levels, contact and collision, at the samples of a log or of a block of it.

Thresholds fit the residual of their calibration's sample rate: the velocities' noise
(derived from the positions or measured), which the residual passes times the gain
through ``M(q) dq``, and the observer's discretisation change with it. On a simulated
UR5 the wrist's contact threshold was 0.071 N m calibrated at 1 kHz and 0.123 N m at
100 Hz. :attr:`Thresholds.sample_rate_hz` records the calibration's rate;
:func:`rate_mismatch` says a log sampled more than :data:`RATE_TOLERANCE` away from it.
For the same reason :attr:`Thresholds.velocities` records whether the calibration logs'
velocities were measured or derived from the positions (a low-pass and differences: far
less noise), and :func:`velocity_mismatch` says a log whose velocities are the other kind,
or any log where the calibration held both kinds (``mixed``): one set of thresholds for
both is set by the noisier kind, which :func:`mixed_velocities` says at the calibration.
"""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import dataclass, field

import numpy as np
from numpy.typing import ArrayLike, NDArray

from .. import _checks
from ..exceptions import DataError, ShapeError
from .residual import ObserverOptions
from .trust import CalibratedOn

__all__ = [
    "RATE_TOLERANCE",
    "ModelFingerprint",
    "RestMargin",
    "Thresholds",
    "log_rate",
    "mixed_velocities",
    "rate_mismatch",
    "threshold_series",
    "velocity_mismatch",
]

#: Relative difference between a log's sample rate and the calibration's above which
#: :func:`rate_mismatch` speaks (module docstring).
RATE_TOLERANCE = 0.2


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
class RestMargin:
    """The standstill margin at settled rests, calibrated from the calibration's rests
    (:mod:`dynid.observer.rest_margin`); arrays read-only.

    Attributes
    ----------
    level : ndarray, shape (n,)
        The calibrated rest level [N m] per joint: the standstill margin at a settled rest
        is ``min(Coulomb level, level)``; NaN: too few rests, the Coulomb level kept.
    rests : ndarray, shape (n,)
        Separate rests of at least ``min_rest_s`` settled seconds each that the
        calibration logs held, per joint.
    settle_s : float
        Seconds [s] inside the standstill band before a rest is settled (the level applies).
    min_rests : int
        Rests a joint needed for its level to be calibrated.
    min_rest_s : float
        Settled seconds [s] a rest needed to count.
    """

    level: NDArray[np.float64]
    rests: NDArray[np.int64]
    settle_s: float
    min_rests: int
    min_rest_s: float

    def __post_init__(self) -> None:
        n = np.shape(self.level)[0]
        level = _checks.as_exact("rest level", self.level, (n,), allow_nonfinite=True)
        if np.any(np.isinf(level)) or np.any(level < 0):
            raise DataError(f"thresholds: rest levels must be >= 0 [N m] or null; got {level}")
        rests = np.asarray(self.rests)
        if rests.shape != (n,) or np.any(rests < 0):
            raise DataError(f"thresholds: rests must be {n} counts >= 0; got {rests.tolist()}")
        if not (np.isfinite(self.settle_s) and self.settle_s >= 0):
            raise DataError(f"thresholds: settle_s must be >= 0 [s]; got {self.settle_s}")
        object.__setattr__(self, "level", _checks.frozen(level))
        object.__setattr__(self, "rests", _checks.frozen(rests.astype(np.int64)))

    @property
    def calibrated(self) -> NDArray[np.bool_]:
        """Per joint (n,): a rest level was calibrated (enough rests)."""
        return np.asarray(np.isfinite(self.level))

    def at_rest(self, coulomb: NDArray[np.float64]) -> NDArray[np.float64]:
        """The standstill margin (n,) [N m] at a settled rest of joints whose Coulomb
        bound there is ``coulomb`` (n,) [N m]: the smaller of the two where calibrated."""
        return np.asarray(np.fmin(coulomb, self.level))


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
    sample_rate_hz : float or None
        The calibration logs' sample rate [Hz] (:func:`log_rate`; the median over the
        logs); None: not recorded (a file of an earlier version).
    velocities : {"measured", "derived", "mixed"} or None
        The calibration logs' velocities: columns of the logs, derived from the positions,
        or some of each; None: not recorded (a file of an earlier version).
    rest : RestMargin or None
        The standstill margin at settled rests, calibrated from the calibration's rests
        (:mod:`dynid.observer.rest_margin`); None: the Coulomb level at every rest (a
        calibration without the rests read, a file of an earlier version).
    detectable : ndarray, shape (n,), or None
        The calibration's smallest torque detected while each joint moves [N m]
        (``thresholds.json``'s ``calibration.detectable``,
        :func:`~dynid.observer.calibration_check.detectable`), read back with the file;
        None: not recorded (the fixed ``contact`` stands for it).
    calibrated : CalibratedOn or None
        What they were calibrated on, read back with the file: the logs, their duration,
        the false alarms raised on them and the residual's level there
        (:mod:`~dynid.observer.trust`); None: not recorded (thresholds made otherwise).
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
    sample_rate_hz: float | None = None
    velocities: str | None = None
    rest: RestMargin | None = None
    detectable: NDArray[np.float64] | None = field(default=None)
    calibrated: CalibratedOn | None = None

    def __post_init__(self) -> None:
        if self.velocities not in (None, "measured", "derived", "mixed"):
            raise DataError(
                "thresholds: velocities must be measured, derived or mixed; got "
                f"{self.velocities!r}"
            )
        if self.sample_rate_hz is not None and not (
            np.isfinite(self.sample_rate_hz) and self.sample_rate_hz > 0
        ):
            raise DataError(f"thresholds: sample_rate_hz must be > 0; got {self.sample_rate_hz}")
        n = np.shape(self.contact)[0]
        given = tuple(x for x in ("noise", "detectable") if getattr(self, x) is not None)
        for name in ("contact", "collision", *given):
            a = _checks.as_exact(name, getattr(self, name), (n,))
            if np.any(a < 0):
                raise DataError(f"thresholds: {name} must be >= 0 [N m]; got {a.tolist()}")
            object.__setattr__(self, name, _checks.frozen(a))
        if self.rest is not None and self.rest.level.shape != (n,):
            raise DataError(
                f"thresholds: rest levels for {self.rest.level.shape[0]} joints; {n} here"
            )

    @property
    def n(self) -> int:
        """Joints."""
        return int(self.contact.shape[0])

    @property
    def uses_uncertainty(self) -> bool:
        """Whether the thresholds grow with the model's uncertainty."""
        return self.k_sigma is not None and self.noise is not None


def log_rate(t: ArrayLike) -> float | None:
    """The sample rate [Hz] of a log at times ``t`` (N,) [s]: one over its median
    positive step; None with fewer than two distinct samples."""
    steps = np.diff(np.asarray(t, dtype=np.float64).reshape(-1))
    steps = steps[steps > 0]
    return 1.0 / float(np.median(steps)) if steps.size else None


def rate_mismatch(rate_hz: float | None, thresholds: Thresholds, name: str) -> str | None:
    """One line when a log sampled at ``rate_hz`` [Hz] differs from the thresholds'
    calibration rate by more than :data:`RATE_TOLERANCE` (module docstring), ``name``
    the thresholds file; None otherwise, or when either rate is not known."""
    cal = thresholds.sample_rate_hz
    if rate_hz is None or cal is None or abs(rate_hz / cal - 1.0) <= RATE_TOLERANCE:
        return None
    return (
        f"sampled at {rate_hz:.4g} Hz, {name} calibrated at {cal:.4g} Hz: the residual's "
        "noise (the velocities' through M(q) dq times the gain) changes with the rate, so "
        f"the thresholds may be too low (false alarms) or too high (contacts missed); hint: "
        f"calibrate at this rate, on collision-free logs sampled at {rate_hz:.4g} Hz"
    )


def velocity_mismatch(derived: bool, thresholds: Thresholds, name: str) -> str | None:
    """One line when a log's velocities (``derived`` from its positions, else measured)
    are of the other kind than the calibration logs' (module docstring), ``name`` the
    thresholds file, or of either kind where the calibration's were ``mixed`` (set partly on
    the other kind); None otherwise, or when the calibration's are not recorded."""
    cal = thresholds.velocities
    kind = "derived" if derived else "measured"
    if cal == "mixed":
        other = "measured" if derived else "derived"
        return (
            f"velocities {kind}, {name} calibrated on logs of both kinds: its thresholds were "
            f"set partly on {other} velocities, whose residual's noise is not this log's (the "
            "noisier kind sets them), so they may be too high (contacts missed) or too low "
            f"(false alarms); hint: calibrate on collision-free logs with {kind} velocities "
            "alone"
        )
    if cal not in ("measured", "derived") or cal == kind:
        return None
    return (
        f"velocities {kind}, {name} calibrated on {cal} ones: the residual's noise (the "
        "velocities' through M(q) dq times the gain) is not the same, so the thresholds may "
        "be too low (false alarms) or too high (contacts missed); hint: calibrate on "
        f"collision-free logs with {kind} velocities"
    )


def mixed_velocities(
    measured: Sequence[str],
    derived: Sequence[str],
    read_measured: ArrayLike,
    read_derived: ArrayLike,
    joints: Sequence[str],
    unit: str = "N m",
) -> str:
    """One line for a calibration on logs of both kinds of velocities: which logs hold
    which, and what one set of thresholds for both costs (module docstring).

    Parameters
    ----------
    measured, derived : sequence of str
        The logs (names) whose velocities are columns of theirs, or derived from the
        positions.
    read_measured, read_derived : array_like, shape (n,)
        The largest ``|r|`` read past the standstill margin [N m] on the logs of each kind,
        per joint: the thresholds are ``margin`` times the larger (the noisier kind's).
    joints : sequence of str
        The joints' names (n).
    unit : str
        The unit the torques are said in.

    Returns
    -------
    str
        The warning: the noisier kind, its largest ratio to the other and that joint's
        two levels, and the hint to calibrate per kind.
    """
    m = np.asarray(read_measured, dtype=np.float64)
    d = np.asarray(read_derived, dtype=np.float64)
    tiny = np.finfo(np.float64).tiny
    up = np.nan_to_num(m / np.maximum(d, tiny), nan=1.0)
    down = np.nan_to_num(d / np.maximum(m, tiny), nan=1.0)
    noisy, quiet, ratio = (
        ("measured", "derived", up) if up.max() >= down.max() else ("derived", "measured", down)
    )
    hi, lo = (m, d) if noisy == "measured" else (d, m)
    j = int(np.argmax(ratio))
    return (
        f"velocities measured in {', '.join(measured)} and derived from the positions in "
        f"{', '.join(derived)}: one set of thresholds for both is set by the noisier kind, "
        f"here the {noisy} ones (the largest |r| read on the logs of {noisy} velocities is up "
        f"to {ratio[j]:.3g} x that on the {quiet} ones: {joints[j]} {hi[j]:.3g} against "
        f"{lo[j]:.3g} {unit}), so a detection on a log of {quiet} velocities is up to that much "
        "less sensitive than thresholds of its own kind would make it; hint: calibrate per "
        "kind, on collision-free logs of the kind the detection will see (these thresholds "
        "record velocities: mixed, which a detection warns of)"
    )


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
