"""A rigid load at the flange that a model lacks, read from a prediction's residual.

A load fixed at the flange that the model lacks (a tool, a part carried) adds its
rigid-body torques to the measured ones: the residual, measured less predicted, is
``e = Y_L(q, dq, ddq) theta + (the rest)``, ``theta = (m, m c, J)`` in the flange's axes
(``Y_L`` the torque regressor's columns of the flange's link mapped to the flange's
parameters: :func:`~dynid.observer.carried_load.rigid_load_regressor`, negated, the
regressor ``dynid payload`` fits). :func:`residual_load` fits ``e`` with these ten
columns and nothing else, each joint's residual and columns divided by its noise (the
joints weigh alike), over every sample the verdict judges, and names the load
(:attr:`ResidualLoad.named`) where

* ``m > 0``, at least :data:`MASS_STDS` standard deviations above zero (the rule ``dynid
  payload`` warns by; the misfit's, widened for its serial correlation by Newey-West over
  :data:`~dynid.identification.serial.LAG_PERIODS` periods of the cut-off) and above the
  largest change the misfit above the noise can make in it
  (:attr:`ResidualLoad.mass_misfit`): no other effect the fit leaves can have made it;
* the fit explains at least :data:`EXPLAINED` of the residual's sum of squares above the
  noise (the noise's expected share taken out): more than every other effect together,
  so the load is the first cause and the joints' own diagnoses are made on what it
  leaves, as a coordinate names a joint's residual when it explains half of its part
  above the noise (:data:`~dynid.identification.residual_dependence.FOLLOWS`).

Both are needed: on a simulated Panda whose robot lacks its rotor inertias, the ten
columns explain 32 to 55 % of the residual above the noise (the wrist's armature is a
flange inertia about its axis), with masses of -0.005 to 0.09 kg, up to 3.0 standard
deviations but at most 0.3 of the misfit's bound; lacking its friction, 12 to 26 %, 0.11
kg at 5 standard deviations, 0.45 of the bound. A 0.8 kg load on it: 0.80 kg, 100 %, the
bound 0.004 kg; with a tenth of the rotor inertias missing too, 0.80 to 0.81 kg.

On a Talos arm's 30 s log carrying a 0.8 kg load (CoM 0.09 m below the flange) its model
lacks, 10.9 x the noise floor: 0.800 kg (bound 0.019 kg), CoM z -0.090 m, 100 % of the
residual above the noise (``dynid payload`` gave 0.801 kg); the model on logs of the arm
without the load: at most 1.2 % explained and no mass above 0.0001 kg.
"""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import dataclass

import numpy as np
from numpy.typing import NDArray

from ..feasibility.payload_fit import serial_correlation_factor
from ..identification.serial import hac_lag
from ..model.robot import Robot
from .carried_load import rigid_load_regressor
from .unmodelled_load import LOAD_FRAME

__all__ = ["EXPLAINED", "MASS_STDS", "ResidualLoad", "load_hint", "residual_load"]

#: Standard deviations the fitted mass must lie above zero to be named (``dynid
#: payload``'s own rule for a mass).
MASS_STDS = 3.0
#: Share of the residual's sum of squares above the noise the load must explain: more than
#: every other effect together (module docstring).
EXPLAINED = 0.5
#: Samples of the load's regressor computed at a time.
BLOCK = 4096
#: Fewest samples for a fit of the ten parameters.
MIN_SAMPLES = 200


@dataclass(frozen=True, slots=True, eq=False)
class ResidualLoad:
    """A rigid load at the flange fitted to a prediction's residual.

    Attributes
    ----------
    theta : ndarray, shape (10,)
        ``(m, m c, J)`` [kg, kg m, kg m^2]: mass, first moments and inertia about the
        flange's origin, in the flange's axes (the order of :func:`dynid.param_labels`).
    mass_std : float
        The mass's standard deviation [kg] (the misfit's, widened for its serial
        correlation).
    mass_misfit : float
        The largest change [kg] the misfit above the noise can make in the mass: an
        effect the load does not explain, as large as the misfit, along the estimator's
        row (Cauchy-Schwarz: ``sqrt(G_mm (||r||^2 - rows))``, each joint over its noise,
        ``G`` the inverse normal matrix; the bound ``dynid payload`` judges its own fit
        by, :func:`~dynid.feasibility.payload_fit.misfit_covariance`).
    explained : float
        Share of the residual's sum of squares above the noise that the load explains
        (each joint over its noise), at most 1.
    whole : float
        Share of the residual's whole sum of squares it explains.
    residual : list of ndarray, each (N_k, n)
        What the load leaves of the residual [N m], per piece.
    frame : str
        The frame the load is fitted at.
    """

    theta: NDArray[np.float64]
    mass_std: float
    mass_misfit: float
    explained: float
    whole: float
    residual: list[NDArray[np.float64]]
    frame: str = LOAD_FRAME

    @property
    def mass(self) -> float:
        """The load's mass [kg]."""
        return float(self.theta[0])

    @property
    def com(self) -> NDArray[np.float64]:
        """The load's centre of mass [m] in the flange's axes (NaN at zero mass)."""
        m = self.mass
        return self.theta[1:4] / m if m != 0 else np.full(3, np.nan)

    @property
    def named(self) -> bool:
        """Whether the residual is the load's (module docstring)."""
        clear = self.mass > max(MASS_STDS * self.mass_std, self.mass_misfit)
        return bool(self.mass > 0 and clear and self.explained >= EXPLAINED)

    def sentence(self, command: str, stand_in: str | None = None) -> str:
        """The load in words, with the ``command`` that measures it; ``stand_in``, the
        model's placeholder links in words (:func:`~dynid.model.placeholders.placeholder_words`),
        named first as the likelier cause: their missing masses weigh as a load would."""
        c = ", ".join(f"{x:+.3f}" for x in self.com)
        first = (
            ""
            if stand_in is None
            else (
                f"first the description's {stand_in}: their real masses, which the model "
                "lacks, weigh on the joints as a load at the flange does (give the links "
                "their masses, or identify the arm: a consistent fit's prior puts the generic "
                "cylinder in their place); else "
            )
        )
        return (
            f"{first}a load at the flange the model lacks: a rigid body of {self.mass:.2f} kg "
            f"(std {self.mass_std:.2g} kg; CoM ({c}) m in the flange's axes) explains "
            f"{100 * self.explained:.0f} % of the residual above the noise; measure it with "
            f"{command}"
        )

    def as_dict(self) -> dict[str, object]:
        """The record ``validation.json`` keeps as ``flange_load``."""
        return {
            "named": self.named,
            "frame": self.frame,
            "mass": self.mass,
            "mass_std": self.mass_std,
            "mass_misfit": self.mass_misfit,
            "com": [float(x) for x in self.com],
            "theta": [float(x) for x in self.theta],
            "explained": self.explained,
            "explained_whole": self.whole,
        }


def _regressor(robot: Robot, q: NDArray, dq: NDArray, ddq: NDArray) -> NDArray[np.float64]:
    """The load's torques' regressor (N, n, 10) on the samples, a :data:`BLOCK` at a time:
    what it adds to the measured torques (the observer's, negated)."""
    out = np.empty((q.shape[0], robot.n, 10))
    for a in range(0, q.shape[0], BLOCK):
        b = slice(a, a + BLOCK)
        out[b] = -rigid_load_regressor(robot, q[b], dq[b], ddq[b])
    return out


def residual_load(
    robot: Robot,
    q: Sequence[NDArray[np.float64]],
    dq: Sequence[NDArray[np.float64]],
    ddq: Sequence[NDArray[np.float64]],
    error: Sequence[NDArray[np.float64]],
    noise_rms: NDArray[np.float64],
    *,
    cutoff_hz: float | None = None,
    rate_hz: float | None = None,
) -> ResidualLoad | None:
    """The rigid load at the flange that best explains ``error`` (module docstring).

    Parameters
    ----------
    robot : Robot
        The arm, its ``flange`` frame where the load is fitted.
    q, dq, ddq : sequence of ndarray, each (N_k, n)
        Positions [rad], velocities [rad/s] and accelerations [rad/s^2] of the samples,
        per piece.
    error : sequence of ndarray, each (N_k, n)
        Measured less predicted torques at the same samples [N m].
    noise_rms : ndarray, shape (n,)
        Each joint's noise [N m]: its residual's and columns' weight.
    cutoff_hz : float, optional
        The states' low-pass cut-off [Hz], with ``rate_hz`` the samples' rate [Hz]: the
        window of the misfit's serial correlation; None: taken as white.

    Returns
    -------
    ResidualLoad or None
        None with fewer than :data:`MIN_SAMPLES` samples, a noise not positive, or
        columns of no rank (an arm that does not move).
    """
    s = np.asarray(noise_rms, dtype=np.float64)
    count = sum(int(np.shape(e)[0]) for e in error)
    if count < MIN_SAMPLES or not np.all(np.isfinite(s) & (s > 0)):
        return None
    AtA, Atb, btb, regs = np.zeros((10, 10)), np.zeros(10), 0.0, []
    for qk, vk, ak, ek in zip(q, dq, ddq, error, strict=True):
        Y = _regressor(robot, np.asarray(qk), np.asarray(vk), np.asarray(ak)) / s[:, None]
        b = np.asarray(ek, dtype=np.float64) / s
        A = Y.reshape(-1, 10)
        AtA += A.T @ A
        Atb += A.T @ b.ravel()
        btb += float(np.sum(b * b))
        regs.append(Y)
    scale = np.sqrt(np.diag(AtA))
    if not np.all(scale > 0):
        return None
    K = AtA / np.outer(scale, scale)
    theta = np.linalg.lstsq(K, Atb / scale, rcond=1e-12)[0] / scale
    left = [
        np.asarray(e, dtype=np.float64) - (Y @ theta) * s for e, Y in zip(error, regs, strict=True)
    ]
    rows = count * s.size
    misfit = max(btb - float(theta @ Atb), 0.0)
    lag = 0 if rate_hz is None else hac_lag(cutoff_hz, rate_hz)
    widen = max(serial_correlation_factor(r / s, s.size, lag)[0] for r in left)
    sigma2 = misfit / max(rows - 10, 1) * widen
    cov00 = float(np.linalg.pinv(K, rcond=1e-12)[0, 0]) / scale[0] ** 2
    above = btb - rows  # the noise's expected sum of squares: one per row (weighed)
    explained = float(theta @ Atb)
    return ResidualLoad(
        theta=theta,
        mass_std=float(np.sqrt(max(sigma2 * cov00, 0.0))),
        mass_misfit=float(np.sqrt(cov00 * max(misfit - rows, 0.0))),
        explained=min(explained / above, 1.0) if above > 0 else 0.0,
        whole=explained / btb if btb > 0 else 0.0,
        residual=left,
    )


def load_hint(load: ResidualLoad | None, command: str, stand_in: str | None = None) -> str | None:
    """:meth:`ResidualLoad.sentence` when the load is named (``stand_in``, the model's
    placeholder links in words, named first), else None."""
    return None if load is None or not load.named else load.sentence(command, stand_in)
