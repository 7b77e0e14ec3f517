"""The scale of the measured torques against an arm description's: a factor the load carries.

A torque constant or gear ratio off by a factor ``a`` (a servo's current-to-torque
constant), or a sensor of another scale, makes every measured torque ``a`` times the true
one, the load's included: the load's mass comes out ``a`` times too large, and the fit
does not show it (its columns absorb the factor). An arm description whose links do not
come from these torques (a robot file, a ``feasible.json``) tells it: the measured
quantities are ``a`` times its modelled ones ``y_arm`` (rigid body, rotors, and the
friction subtracted) plus the load's and the friction's,

.. math:: y = a \\, y_{arm} + Y A \\phi' \\; (+ F f), \\qquad \\phi' = a \\phi,

fitted with the column ``y_arm`` beside the load's (:func:`torque_scale`): the fit of the
target ``y - y_arm`` of the load's estimate with one column more, its coefficient
``a - 1``. The load's estimate is not changed (the factor is only a doubt): with the
difference method (data without the load), ``a`` is fitted on those data alone,
``y_0 = a y_{0,arm} (+ F f)``, where no load's column shares it. An identified model's
scale was fitted to the same sensors: it tells nothing, and no factor is estimated.

Standard deviations as the load's (:mod:`dynid.feasibility.payload`): HC1, widened for
filtered rows' serial correlation (Newey-West) and to the spread over held-out time blocks
where that is larger. :func:`scale_doubts` says when the factor differs from 1 by more
than :data:`SCALE_SIGMAS` of its standard deviations and either by more than
:data:`SCALE_OFF` or by enough to move the load's mass by more than that share
(:meth:`TorqueScale.off`).
"""

from __future__ import annotations

from collections.abc import Mapping
from dataclasses import dataclass
from typing import Any

import numpy as np
from numpy.typing import NDArray

from ..exceptions import RankDeficientError
from ..identification.least_squares import fit_least_squares
from ..model.drive import Drive
from .payload_doubts import misfit_above
from .payload_fit import (
    block_jackknife_covariance,
    held_out_widening,
    serial_correlation_factor,
)

__all__ = [
    "SCALE_OFF",
    "SCALE_SIGMAS",
    "TorqueScale",
    "constants_note",
    "known_mass_scale",
    "scale_doubts",
    "scale_mass",
    "torque_scale",
    "unjudged_ratio",
]

#: Relative distance from 1 of a factor that makes a doubt.
SCALE_OFF = 0.05
#: Standard deviations by which the factor must differ from 1 to make a doubt.
SCALE_SIGMAS = 3.0


@dataclass(frozen=True, slots=True)
class TorqueScale:
    """The factor between the measured torques and the arm description's.

    Attributes
    ----------
    value : float
        ``a`` [1]: measured = ``a`` x modelled.
    std : float
        Its standard deviation [1].
    mass : float
        The load's mass [kg] if the description is right: the torques divided by ``a``
        (the fit's load mass with the factor, or the difference method's, over ``a``).
    std_mass : float
        Its standard deviation [kg] (first order).
    data : str
        ``"loaded"`` (fitted beside the load's columns) or ``"unloaded"`` (on the data
        without the load).
    residual_rms : float
        The RMS residual of the fit with the factor [units of the rows: N m for torque
        logs]: a factor that leaves torques far above their noise is the arm's model
        error absorbed, not a scale (:func:`scale_doubts`).
    """

    value: float
    std: float
    mass: float
    std_mass: float
    data: str
    residual_rms: float = float("nan")

    def off(self, mass: float) -> bool:
        """``a`` differs from 1 by more than :data:`SCALE_SIGMAS` standard deviations, and
        by more than :data:`SCALE_OFF` or enough to move the load's estimated ``mass`` [kg]
        from :attr:`mass` by more than :data:`SCALE_OFF` of it and :data:`SCALE_SIGMAS` of
        its standard deviations (without data free of the load, a factor of 0.95 moved a
        0.83 kg load to 0.50 kg: the arm's torques, not the load's, carry the factor)."""
        d = abs(self.value - 1.0)
        if not d > SCALE_SIGMAS * self.std:
            return False
        shift = abs(mass - self.mass)
        return d > SCALE_OFF or (
            shift > SCALE_OFF * abs(self.mass) and shift > SCALE_SIGMAS * self.std_mass
        )


def torque_scale(
    y: NDArray[np.float64],
    y_arm: NDArray[np.float64],
    W: NDArray[np.float64],
    kept: NDArray[np.bool_] | None,
    n: int,
    *,
    p: int,
    lags: int | None,
    held_out: bool,
    load: tuple[float, float] | None = None,
) -> TorqueScale | None:
    """The factor ``a`` of ``y + y_arm = a y_arm + W x`` (module docstring).

    Parameters
    ----------
    y : ndarray, shape (m,)
        The measured rows minus the description's ``y_arm`` [SI of the rows].
    y_arm : ndarray, shape (m,)
        The description's modelled rows.
    W : ndarray, shape (m, c)
        The other columns: the load's ``p`` first (``p = 0``: data without the load),
        then the friction's.
    kept : ndarray of bool, shape (c,), optional
        The columns of ``W`` fitted.
    n : int
        Rows per sample.
    p : int
        The load's columns in ``W``; its mass is the first.
    lags : int, optional
        Filtered rows: the Newey-West lags (the samples per cut-off period); None: none.
    held_out : bool
        Widen to the spread over held-out time blocks (torque logs).
    load : (float, float), optional
        ``p = 0``: the load's mass [kg] and its standard deviation, divided by ``a``.

    Returns
    -------
    TorqueScale or None
        None when the description models no torques (no inertial parameters) or the
        columns do not determine ``a`` (rank deficient).
    """
    if not np.any(y_arm) or (p == 0 and load is None):
        return None
    A = np.concatenate([y_arm[:, None], W], axis=1)
    used = np.ones(A.shape[1], dtype=bool)
    if kept is not None:
        used[1:] = kept
    try:
        fit = fit_least_squares(A, y, kept=used, rtol=1e-10, std="robust")
    except RankDeficientError:
        return None
    beta = np.asarray(fit.beta)
    cov = np.asarray(fit.covariance)
    if lags:
        factor, _ = serial_correlation_factor(y - A[:, used] @ beta[used], n, lags)
        cov = cov * factor
    if held_out:
        jack = block_jackknife_covariance(A[:, used], y, n)
        if jack is not None:
            full = np.zeros_like(cov)
            full[np.ix_(used, used)] = jack
            cov = held_out_widening(cov, full)[0]
    a = 1.0 + float(beta[0])
    if p:
        x = float(beta[1])
        grad = np.array([-x / a**2, 1.0 / a])
        mass, std_mass = x / a, float(np.sqrt(max(grad @ cov[:2, :2] @ grad, 0.0)))
    else:
        m, sm = load or (np.nan, np.nan)  # given with p = 0 (checked above)
        mass = m / a
        std_mass = float(np.hypot(sm / a, m * np.sqrt(cov[0, 0]) / a**2))
    std = float(np.sqrt(max(cov[0, 0], 0.0)))
    return TorqueScale(
        a, std, mass, std_mass, "loaded" if p else "unloaded", float(fit.residual_rms)
    )


def constants_note(
    drive: Drive | None,
    mass: float,
    std_mass: float,
    checked: Mapping[str, Any] | None = None,
) -> str | None:
    """The note of a load weighed from motor currents (``drive`` logs currents): its mass
    ``mass`` [kg] and standard deviation ``std_mass`` [kg] hold the torques' noise and the
    arm's model, not the drive's torque constants, through which every torque is read: a
    relative error ``e`` of them, common to the joints, makes the load's torques and its
    mass ``1 + e`` times the true (a UR5's datasheet constants about 2 % off: 1.217 kg
    +- 0.0036 for 1.2); None for a log of torques. ``checked``: what the identification's
    data told of the constants (:func:`~dynid.identification.constants_checked.
    constants_record`), said first: those checked only to within a tolerance, those not
    checked (a UR10's constants 5 % high on motor 2 and 5 % low on motor 4, neither checked:
    2.579 kg, std 0.019, for 2.5)."""
    if drive is None or drive.effort != "current":
        return None
    per = 0.01 * mass
    sigmas = f", {per / std_mass:.2g} std" if std_mass > 0 else ""
    rel = f"{100 * std_mass / mass:.2g} %" if mass > 0 else f"{std_mass:.2g} kg"
    moved = (
        f"a relative error of the constants common to the joints moves the mass by as much "
        f"({per:.2g} kg{sigmas}, per 1 %)"
    )
    said = _checked_words(checked)
    if said is None:
        return (
            f"the mass's std ({std_mass:.2g} kg) leaves out the error of the drive's "
            "torque_constant: the load's torques are the currents times it, so its mass and "
            f"first moments carry that error: {moved}"
        )
    return (
        f"the load's torques are the currents through torque constants {said}: its mass and "
        f"first moments carry the constants' error, and the mass is known to that, not to "
        f"its std's {rel} ({std_mass:.2g} kg): {moved}; hint: weigh a load of known mass "
        "(--known-mass), or correct the drive file and identify again"
    )


def _checked_words(checked: Mapping[str, Any] | None) -> str | None:
    """``the identification's data checked only to 10 % (motor(s) 3) and not at all (motor(s)
    1, 2, 4, 5, 6)`` from a record of
    :func:`~dynid.identification.constants_checked.constants_record`; None without one."""
    if not checked:
        return None
    unit = str(checked.get("per", "motor"))
    within, parts = float(checked["within_percent"]), []
    if checked["checked"]:
        parts.append(f"only to {within:g} % ({unit}(s) {_listed(checked['checked'])})")
    if checked.get("corrected"):
        parts.append(f"off, the fix said ({unit}(s) {_listed(checked['corrected'])})")
    if checked["unchecked"]:
        parts.append(f"not at all ({unit}(s) {_listed(checked['unchecked'])})")
    if not parts:
        return None
    return "the identification's data checked " + " and ".join(parts)


def _listed(ks: Any) -> str:
    """``1, 2, 4`` of a list of numbers."""
    return ", ".join(str(int(k)) for k in ks)


def known_mass_scale(mass: float, std_mass: float, known: float) -> tuple[float, float]:
    """The torques' scale a load of ``known`` mass [kg] reads: ``mass / known`` (the
    measured over the true, as :attr:`TorqueScale.value`), with its standard deviation
    from the load's ``std_mass`` [kg]; the drive's torque constants are off by that factor
    in common (their relative error's mean over the joints the load loads)."""
    return mass / known, std_mass / known


def scale_mass(scale: TorqueScale) -> str:
    """The load's mass at the description's scale in words: ``m / a = 0.8313 kg (std
    0.00086)`` on data without the load (the difference method's mass over the factor),
    ``0.829 kg (fitted beside the factor, over it; std 0.0014)`` on the loaded data, where
    it is not the printed mass over ``a`` (the arm's torques carry the factor too)."""
    if scale.data == "unloaded":
        return f"m / a = {scale.mass:.4g} kg (std {scale.std_mass:.2g})"
    return f"{scale.mass:.4g} kg (fitted beside the factor, over it; std {scale.std_mass:.2g})"


def unjudged_ratio(scale: TorqueScale, noise_rms: float | None) -> float | None:
    """The residual of the fit with the factor over the torque noise ``noise_rms`` [N m]
    when above :data:`~dynid.identification.verdict.FLOOR_FAIR`: the factor then takes
    torques the arm's model does not explain, and is not judged (no doubt, no load at the
    description's scale to trust); None at or below it, or with no noise known."""
    return misfit_above(scale.residual_rms, noise_rms)


def scale_doubts(
    scale: TorqueScale | None,
    mass: float,
    drive: Drive | None = None,
    noise_rms: float | None = None,
) -> tuple[str, ...]:
    """The doubt about a load of ``mass`` [kg] whose torques are ``scale.value`` times the
    description's (:meth:`TorqueScale.off`), with the remedy as the user gives it (a drive
    of currents: its ``torque_constant``; else ``--units tau=``); empty when none, and when
    the fit with the factor leaves more than :data:`~dynid.identification.verdict.
    FLOOR_FAIR` times the torque noise ``noise_rms`` [N m] (torque logs): the factor then
    absorbs torques the arm's model does not explain (an unmodelled spring on a Panda
    shoulder read as 0.969 with the load's mass moved by 16 %, at 6.9 x the noise), which
    no unit would fix; the residual's own doubts speak of it."""
    if scale is None or not scale.off(mass) or unjudged_ratio(scale, noise_rms) is not None:
        return ()
    a = scale.value
    where = "the data without the load" if scale.data == "unloaded" else "the loaded data"
    if drive is not None and drive.effort == "current":
        remedy = f"multiply the drive file's torque_constant by {1 / a:.4g}"
    elif drive is not None and not drive.is_identity:
        remedy = (
            f"check the drive file's gear_ratio, or read the torques with --units tau={1 / a:.4g}"
        )
    else:
        remedy = f"read the torques with --units tau={1 / a:.4g}"
    return (
        f"the measured torques are {a:.4g} x the arm model's (std {scale.std:.2g}, on "
        f"{where}): a torque constant or gear ratio off by that factor, or the arm's "
        f"masses are; if the arm's description is right, the load is {scale_mass(scale)}, "
        f"not {mass:.4g} kg; hint: {remedy}, "
        "or fix the arm's masses"
        + (
            ", or record the same motions without the load and give them with --unloaded "
            "(the arm is then identified from them)"
            if scale.data == "loaded"
            else ""
        ),
    )
