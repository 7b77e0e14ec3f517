"""A load at the arm's flange that the model lacks, read from the residual.

A load of mass ``m`` whose centre of mass lies at ``c`` in the flange's axes that the
model lacks (a gripper, a tool, a part carried) reads in the residual as the external
torque of its weight. Its inertial terms aside (the arm's motion is slow next to ``g``),

.. math:: r = J_v(q)^T g\\, m + J_\\omega(q)^T \\big((R(q)\\, m c) \\times g\\big)
          = Y(q)\\, \\theta, \\qquad \\theta = (m, m c)

(``J`` the flange's geometric Jacobian, ``R`` its rotation, ``g`` the robot's gravity,
base axes): linear in ``theta``, four unknowns for any joint count. :class:`LoadTally`
fits it by least squares over running normal equations, a block of samples at a time,
on the samples under the contact threshold at every joint (contacts left out), each
joint's residual and regressor divided by its contact threshold at that sample, so that
the joints weigh alike and the samples where the threshold rises (the standstill margin
at a reversal, the model's uncertainty) weigh less. The load is *seen*
(:attr:`UnmodelledLoad.seen`) where the fit explains more than :data:`LOAD_SHARE` of the
residual's sum of squares there and its torque's RMS reaches :data:`LOAD_LEVEL` of the
contact threshold on some joint: what the load adds to the noise decides false alarms.
On a simulated UR5 whose model lacks a 0.1 kg load the fit gave 0.099 kg and
explained 59 % of the residual, reaching 37 % of the elbow's threshold (7 false alarms in
58 s); with 0.3 kg, 0.28 kg and 89 %; on the same arm without a load it explained 0.04 %
to 0.2 % of the residual of four logs, at 1.4 % of a threshold at most.

The same residual comes from the last link's mass or first moments identified wrong: the
note (:func:`load_note`) points to ``dynid payload`` for a load, to identifying the
model again otherwise.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
from numpy.typing import ArrayLike, NDArray

from ..kinematics.forward import fk
from ..kinematics.jacobian import jacobian
from ..model.robot import Robot

__all__ = ["LOAD_LEVEL", "LOAD_SHARE", "LoadTally", "UnmodelledLoad", "load_note"]

#: Share of the residual's sum of squares under the threshold that the load's fit must
#: explain to be seen (module docstring).
LOAD_SHARE = 0.25
#: RMS of the fitted load's torque, as a fraction of the contact threshold, that some
#: joint must reach for the load to be seen (module docstring).
LOAD_LEVEL = 0.15
#: Samples under the threshold below which nothing is said.
LOAD_SAMPLES = 200
#: The frame the load is fitted at.
LOAD_FRAME = "flange"


def load_regressor(robot: Robot, q: ArrayLike) -> NDArray[np.float64]:
    """``Y(q)`` (N, n, 4) [N m per kg, N m per kg m] of the module docstring: the
    external joint torques of the weight of a load ``theta = (m, m c)`` at the flange,
    ``c`` in the flange's axes [m]."""
    qa = np.asarray(q, dtype=np.float64).reshape(-1, robot.n)
    J = jacobian(robot, qa, LOAD_FRAME)
    R = fk(robot, qa, LOAD_FRAME)[..., :3, :3]
    g = np.asarray(robot.gravity, dtype=np.float64)
    minus_g_cross = -np.array([[0.0, -g[2], g[1]], [g[2], 0.0, -g[0]], [-g[1], g[0], 0.0]])
    mass = np.einsum("kji,j->ki", J[:, :3, :], g)  # J_v^T g
    # J_w^T ((-[g]x) R): two batched products (a three-operand einsum ran one loop over
    # every sample's 5 indices, most of the detection's time on a long log)
    moment = np.swapaxes(J[:, 3:, :], 1, 2) @ (minus_g_cross @ R)
    return np.concatenate([mass[..., None], moment], axis=2)


@dataclass(frozen=True, slots=True, eq=False)
class UnmodelledLoad:
    """The fit of a load at the flange to the residual (module docstring).

    Attributes
    ----------
    mass : float
        [kg]; negative: the model's flange is heavier than the arm's.
    com : ndarray, shape (3,)
        Its centre of mass in the flange's axes [m] (NaN with a zero mass).
    share : float
        Share (0 to 1) of the residual's sum of squares under the threshold that the fit
        explains (each joint's divided by its contact threshold).
    level : ndarray, shape (n,)
        RMS over those samples of the fitted load's torque per joint, as a fraction of
        the joint's contact threshold at each sample.
    samples : int
        Samples read.
    """

    mass: float
    com: NDArray[np.float64]
    share: float
    level: NDArray[np.float64]
    samples: int

    @property
    def seen(self) -> bool:
        """The fit explains more than :data:`LOAD_SHARE` of the residual and reaches
        :data:`LOAD_LEVEL` of the contact threshold on some joint, on enough samples."""
        return (
            self.samples >= LOAD_SAMPLES
            and self.share > LOAD_SHARE
            and float(np.max(self.level, initial=0.0)) >= LOAD_LEVEL
        )


class LoadTally:
    """Running normal equations of the load's fit over the blocks of one or more logs
    (module docstring).

    Parameters
    ----------
    robot : Robot
    """

    def __init__(self, robot: Robot) -> None:
        self.robot = robot
        n = robot.n
        self._AtA = np.zeros((4, 4))
        self._Atb = np.zeros(4)
        self._btb = 0.0
        self._joint = np.zeros((n, 4, 4))  # per joint: sum of a a^T, for its RMS
        self._count = 0

    def add(self, q: ArrayLike, r: ArrayLike, contact: ArrayLike) -> None:
        """One block: positions ``q`` [rad], residual ``r`` [N m] and the contact
        threshold at each sample [N m] (:func:`~dynid.observer.thresholds.threshold_series`),
        each (N, n). A sample is read where every joint's ``|r|`` is under its threshold
        (finite); each joint's residual and regressor are divided by its threshold there,
        so that a sample where the standstill margin or the model's uncertainty raise it
        weighs less."""
        R = np.asarray(r, dtype=np.float64)
        C = np.asarray(contact, dtype=np.float64)
        with np.errstate(invalid="ignore"):
            ok = np.all(np.abs(R) <= C, axis=1) & np.all(C > 0, axis=1)
        if not ok.any():
            return
        A = load_regressor(self.robot, np.asarray(q, dtype=np.float64)[ok])
        A = A / C[ok][:, :, None]
        b = R[ok] / C[ok]
        rows = A.reshape(-1, A.shape[-1])  # sample-major rows, as the stacked regressor
        self._AtA += rows.T @ rows
        self._Atb += rows.T @ b.reshape(-1)
        self._btb += float(np.sum(b * b))
        per_joint = A.transpose(1, 0, 2)  # (n, K, 4)
        self._joint += np.swapaxes(per_joint, 1, 2) @ per_joint
        self._count += int(np.count_nonzero(ok))

    def result(self) -> UnmodelledLoad | None:
        """The fit of every block added; None before any sample was read."""
        if self._count == 0 or not self._btb > 0:
            return None
        theta = np.linalg.lstsq(self._AtA, self._Atb, rcond=None)[0]
        explained = float(theta @ self._Atb)  # least squares: |A theta|^2 = theta^T A^T b
        level = np.sqrt(np.maximum(np.einsum("i,jil,l->j", theta, self._joint, theta), 0.0))
        level = level / np.sqrt(self._count)
        mass = float(theta[0])
        com = np.asarray(theta[1:] / mass if mass != 0 else np.full(3, np.nan), dtype=np.float64)
        return UnmodelledLoad(
            mass, com, min(max(explained / self._btb, 0.0), 1.0), level, self._count
        )


def load_note(
    load: UnmodelledLoad | None, names: list[str] | tuple[str, ...], *, identified: bool = True
) -> str | None:
    """One line when the residual follows the weight of a load at the flange
    (:attr:`UnmodelledLoad.seen`): its mass and centre of mass, how much of the residual
    it explains and of which joint's threshold, and what to do (``identified``: the model
    is an identification.json, which ``dynid payload`` extends to its
    ``model_with_payload.json``; else a robot, to its ``robot_with_payload.toml``); None
    otherwise."""
    if load is None or not load.seen:
        return None
    j = int(np.argmax(load.level))
    c = ", ".join(f"{x:+.3g}" for x in load.com)
    if load.mass > 0:
        what = (
            f"a load of {load.mass:.2g} kg at the flange (CoM {c} m, flange axes) the model lacks"
        )
        todo = (
            "identify it with dynid payload on collision-free logs recorded with it (its "
            + (
                "model_with_payload.json for --model"
                if identified
                else "robot_with_payload.toml for --params"
            )
            + ") or identify the model again with it"
        )
    else:
        what = f"{-load.mass:.2g} kg at the flange that the model holds and the arm does not"
        todo = "identify the model again on logs of the arm as it is now"
    return (
        f"the residual off contacts follows the weight of {what}: it explains "
        f"{100.0 * load.share:.2g} % of the residual under the threshold and reaches "
        f"{100.0 * load.level[j]:.2g} % (RMS) of {names[j]}'s contact threshold, which "
        f"raises false alarms; {todo}, then calibrate again"
    )
