"""Torque constants given at the motors where a joint-side log's drive wants them at the
joints.

On a joint-side log of currents (``side = "joint"``, ``effort = "current"``) a drive's
``torque_constant`` is each joint's torque per ampere: the motor's constant times its gear
ratio. A datasheet's constant, per ampere at the motor, reads every joint's torques its
gear ratio times too small; the gains per motor (:mod:`~dynid.identification.drive_gains`)
then come out as the gear ratios times one common factor, the description's masses'
error (a 6-axis arm of gear ratios 30, 30, 30, 20, 20, 20 whose description lacked a
0.28 kg gripper and had masses 15 % off: factors 24.3, 24.4, 24.4, 16.3, 16.0, their ratios
to the gear ratios 0.80 to 0.82, the wrist motor's gain not determined). Corrected by those
factors the model is off by the masses' error, 19 %, and the undetermined motor by its gear
ratio; corrected by the gear ratios, by neither: the constants were right, at the motor.
:func:`gear_ratio_pattern` tells the pattern; :meth:`GearRatioPattern.sentence` says it.

Over gear ratios all equal the gains cannot tell the pattern from the masses' error: one
factor on every joint. The factor itself can, when the gear ratio is larger than any error
of a description's masses: the torques of a joint-side log are the robot's gravity torques
(:func:`~dynid.identification.sanity.gravity_torque_scale`) over a factor within
:data:`_COMMON` of the gear ratio, and a gear ratio above :data:`SHARED_MIN` puts that
range clear of :data:`_COMMON` itself (a servo arm of gear ratio 345 on every joint, its
motors' constants in the drive file: its torques 0.0029 times the gravity torques).
:func:`shared_gear_ratio` tells it; identification then reads the currents through
``torque_constant x gear_ratio`` with a warning (:meth:`SharedGearRatio.sentence`).
"""

from __future__ import annotations

import dataclasses
from collections.abc import Sequence
from dataclasses import dataclass

import numpy as np
from numpy.typing import NDArray

from ..model.drive import Drive
from ..model.robot import Robot
from .drive_gains import MASSES, DriveGains
from .gravity_scale import gravity_ratios
from .log import TorqueLog, joint_side_log
from .model import IdentifiedModel
from .sanity import gravity_torque_scale

__all__ = [
    "SHARED_MIN",
    "SPREAD",
    "GearRatioPattern",
    "SharedGearRatio",
    "gear_ratio_pattern",
    "read_at_the_joints",
    "shared_gear_ratio",
]

#: Largest spread (largest over smallest, less one) of the determined motors' gains over
#: their gear ratios for the gains to follow the gear ratios.
SPREAD = 0.15
#: Range of the common factor (gain over gear ratio): the description's masses are that
#: far off at most.
_COMMON = (1.0 / 3.0, 3.0)
#: Smallest ratio between the largest and smallest gear ratio of the determined motors:
#: gains uniform over equal gear ratios are one common factor, not this pattern's.
_DISTINCT = 1.2
#: Smallest gear ratio shared by every joint whose factor the description's masses cannot
#: make: above it ``[G / 3, 3 G]`` and :data:`_COMMON` do not meet.
SHARED_MIN = _COMMON[1] / _COMMON[0]
#: Most configurations the fitted model's gravity ratios are read at.
_SAMPLES = 2_000


@dataclass(frozen=True, slots=True)
class GearRatioPattern:
    """Gains per motor that follow the drive's gear ratios.

    Attributes
    ----------
    gear_ratio : ndarray, shape (n,)
        Each joint's gear ratio [-] (the transmission's diagonal, its magnitude).
    common : ndarray, shape (k,)
        The determined motors' gains over their gear ratios [-].
    motors : tuple of int
        The determined motors (from 0).
    """

    gear_ratio: NDArray[np.float64]
    common: NDArray[np.float64]
    motors: tuple[int, ...]

    def sentence(self) -> str:
        """The finding in words (``torque_constant looks given at the motors: ...``)."""
        lo, hi = float(self.common.min()), float(self.common.max())
        span = f"{lo:#.3g}" if f"{lo:#.3g}" == f"{hi:#.3g}" else f"{lo:#.3g} to {hi:#.3g}"
        which = ", ".join(str(k + 1) for k in self.motors)
        return (
            "torque_constant looks given at the motors: the currents' gains follow the gear "
            f"ratios (gain / gear ratio {span} on motor(s) {which}, the rest the "
            "description's masses' error); on a joint-side log (side = \"joint\") "
            "torque_constant is each joint's torque per A, the motor's constant times its "
            "gear ratio: the currents are read through torque_constant x gear_ratio"
        )


def gear_ratio_pattern(gains: DriveGains, drive: Drive) -> GearRatioPattern | None:
    """The pattern of constants given at the motors (module docstring), or None.

    Parameters
    ----------
    gains : DriveGains
        The gains per joint of a joint-side current log (:attr:`DriveGains.factor` at the
        description's scale, :attr:`DriveGains.scaled`).
    drive : Drive
        The drive the log was read through: joint side, currents, a diagonal transmission
        (no coupling) of gear ratios not all equal.

    Returns
    -------
    GearRatioPattern or None
        The pattern when at least two determined motors of gear ratios at least
        :data:`_DISTINCT` apart have gains over their gear ratios within :data:`SPREAD` of
        each other and within :data:`_COMMON` of one.
    """
    if drive.side != "joint" or drive.effort != "current" or not gains.scaled:
        return None
    ratio = np.abs(np.diag(np.asarray(drive.transmission, dtype=np.float64)))
    if drive.is_coupled or gains.factor.shape != ratio.shape:
        return None
    motors = np.flatnonzero(gains.determined)
    if motors.size < 2 or ratio[motors].max() < _DISTINCT * ratio[motors].min():
        return None
    common = gains.factor[motors] / ratio[motors]
    if not np.all(np.isfinite(common)) or common.min() <= 0:
        return None
    if common.max() > (1.0 + SPREAD) * common.min():
        return None
    mid = float(np.exp(np.mean(np.log(common))))
    if not _COMMON[0] <= mid <= _COMMON[1]:
        return None
    return GearRatioPattern(ratio, common, tuple(int(k) for k in motors))


@dataclass(frozen=True, slots=True)
class SharedGearRatio:
    """Torque constants given at the motors over one gear ratio shared by every joint
    (module docstring).

    Attributes
    ----------
    gear_ratio : float
        The gear ratio every joint shares [-].
    common : ndarray, shape (k,)
        Per recording, its torques as logged over the description's gravity torques times
        the gear ratio [-]: friction and the rotors' inertia in them as well as the masses'
        error (a simulated 6-axis arm of exact masses, 0.1 kg m^2 reflected rotor inertia
        and friction: 1.1 to 1.14).
    fitted : ndarray, shape (j,), optional
        Per joint gravity loads, the fitted model's gravity torques over the description's
        [-] (:func:`~dynid.identification.gravity_scale.gravity_ratios`), the currents read
        through the corrected constants: the masses' error alone (the same arm: 1.00);
        None before the fit.
    """

    gear_ratio: float
    common: NDArray[np.float64]
    fitted: NDArray[np.float64] | None = None

    def corrected(self, drive: Drive) -> Drive:
        """``drive`` with each torque constant times the gear ratio."""
        assert drive.torque_constant is not None  # a drive of currents
        kt = np.asarray(drive.torque_constant, dtype=np.float64) * self.gear_ratio
        return dataclasses.replace(drive, torque_constant=kt)

    def with_fit(
        self, robot: Robot, model: IdentifiedModel, q: Sequence[NDArray[np.float64]]
    ) -> SharedGearRatio:
        """The finding with :attr:`fitted` read from ``model`` (identified from the currents
        read through :meth:`corrected`) at the joint positions ``q`` (one (N, n) array [rad]
        per recording); unchanged where gravity loads no joint or a ratio is not positive."""
        every = np.concatenate([np.asarray(a, dtype=np.float64) for a in q])
        qs = every[:: max(1, every.shape[0] // _SAMPLES)]
        r, _, loaded = gravity_ratios(robot, model, qs)
        if not loaded.any() or not np.all(r[loaded] > 0):
            return self
        return dataclasses.replace(self, fitted=r[loaded])

    def sentence(self) -> str:
        """The finding and what was done, in words: the factor beyond the gear ratio the
        fitted model's gravity torques read (:attr:`fitted`), else that of the torques as
        logged, which is not the masses' alone."""
        ratios = self.common if self.fitted is None else self.fitted
        lo, hi = float(ratios.min()), float(ratios.max())
        span = f"{lo:#.3g}" if f"{lo:#.3g}" == f"{hi:#.3g}" else f"{lo:#.3g} to {hi:#.3g}"
        g = f"{self.gear_ratio:.4g}"
        far = abs(float(np.mean(np.log(ratios)))) >= np.log1p(MASSES)
        if far:
            why = (
                f"beyond the description's masses' error ({100 * MASSES:g} %): a further "
                "factor of the constants, which the gravity torques of the fitted model name"
            )
        elif self.fitted is None:
            why = "the currents as logged: friction and the rotors' inertia with the masses' error"
        else:
            why = "the fitted model's gravity torques over the description's: the masses' error"
        return (
            f"torque_constant looks given at the motors: the currents read through it are "
            f"1/{g} (the gear ratio every joint shares) times the description's gravity "
            f"torques, times {span} ({why}); on a joint-side log it is each joint's torque "
            f"per A, so the currents are read through torque_constant x {g}"
            + (
                ""
                if far
                else " (identification.json's drive holds them: put them in the drive file)"
            )
        )


def shared_gear_ratio(
    robot: Robot, logs: Sequence[TorqueLog], drive: Drive | None
) -> SharedGearRatio | None:
    """Constants given at the motors over a shared gear ratio (module docstring), or None.

    Parameters
    ----------
    robot : Robot
        With its inertial parameters (the description's gravity torques).
    logs : sequence of TorqueLog
        The recordings as read (currents [A]).
    drive : Drive or None
        The drive they are read through: joint side, currents, no coupling, one gear
        ratio above :data:`SHARED_MIN` on every joint.

    Returns
    -------
    SharedGearRatio or None
        When every recording's torques over the gravity torques, times the gear ratio, lie
        within :data:`_COMMON`.
    """
    if drive is None or (g := _shared(drive)) is None:
        return None
    scales = [gravity_torque_scale(robot, joint_side_log(log, drive)) for log in logs]
    if not scales or any(a is None or not a > 0 for a in scales):
        return None
    common = np.asarray(scales, dtype=np.float64) * g
    if common.min() < _COMMON[0] or common.max() > _COMMON[1]:
        return None
    return SharedGearRatio(g, common)


def _shared(drive: Drive) -> float | None:
    """The gear ratio every joint of a joint-side ``drive`` of currents without coupling
    shares, when it is above :data:`SHARED_MIN`; None otherwise."""
    if drive.side != "joint" or drive.effort != "current" or drive.is_coupled:
        return None
    ratio = np.abs(np.diag(np.asarray(drive.transmission, dtype=np.float64)))
    if not np.allclose(ratio, ratio[0], rtol=1e-9, atol=0.0) or ratio[0] <= SHARED_MIN:
        return None
    return float(ratio[0])


def read_at_the_joints(given: Drive, own: Drive) -> float | None:
    """The gear ratio ``own``'s torque constants are ``given``'s times, when a model's drive
    ``own`` holds the constants its identification read times one shared gear ratio
    (:func:`shared_gear_ratio`) and ``given`` is the drive file as written, the motors'
    constants in it; None otherwise (other fields differ, or another factor)."""
    if given.torque_constant is None or own.torque_constant is None:
        return None
    mine, theirs = given.as_dict(), own.as_dict()  # effort and side alike, as every other
    if any(mine.get(k) != theirs.get(k) for k in {*mine, *theirs} - {"torque_constant"}):
        return None
    if (g := _shared(own)) is None:
        return None
    kt = np.asarray(own.torque_constant, dtype=np.float64)
    given_kt = np.asarray(given.torque_constant, dtype=np.float64)
    return g if np.allclose(kt, given_kt * g, rtol=1e-9) else None
