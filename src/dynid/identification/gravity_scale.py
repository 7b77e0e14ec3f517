"""An identified model's gravity torques against the robot description's: one factor on
every joint is a scale the fit cannot see.

A log of currents read through a torque constant that is off by a factor ``c`` (a guessed
``torque_constant``), or torques from a sensor of another scale, is fitted as well as the
right one: every identified inertial parameter is scaled by ``1/c`` and the model predicts
the log to its noise. Only something outside the log tells: the robot description's
masses. Its gravity torques at the logged configurations ``g_d(q)`` against the identified
model's ``g_m(q)``, per joint that gravity loads
(:func:`~dynid.identification.model_sign.gravity_loaded`): the least-squares factor ``r_j`` of
``g_m ~ r_j g_d``, linear in the identified base parameters, so that the fit's parameter
covariance gives theirs (:func:`gravity_ratio_covariance`). A factor at least :data:`OFF`
away from 1 on average (``1 + OFF`` or more, or its inverse or less), with the shapes
agreeing (correlation at least :data:`SHAPE`), is judged against one factor on every
joint: the factors' chi-square about their weighted common factor, over their covariance
plus :data:`DESCRIBED` of the factor per joint (the error even a good description's masses
keep). Within :data:`LEVEL` of the chi-square's tail, and within :data:`UNIFORM` of their
mean, it is a scale (a sensor's, a torque constant's): the finding
(:func:`gravity_scale_words`) names it with its standard deviation and what to change, for
the user to judge (the description may be uniformly off instead). Factors that differ by
more are the description's masses, off joint by joint (a cable, a motor left out of the
CAD, a URDF's inertials not its arm's), where a torque scale is one factor on every joint:
the model, fitted to the torques as logged, is right as it is, and a note says so
(:func:`gravity_masses_words`), offering no scale. Unless their common factor lies far
beyond what those masses make (:attr:`GravityRatios.beyond_masses`): farther from 1 than
a description's masses are off together (:data:`~.drive_gains.MASSES`) and
:data:`~.drive_gains.AGREE` times farther than the joints spread about it (masses off
joint by joint move each joint's factor about as much as they move the common one; a
torque constant moves every joint alike), and one factor leaves no more of the gravity
torques than a mass at the flange does (a load's levers make the factors differ). Then
both hold: the masses' error, small, and a scale of the torques, large, which the finding
names first (:func:`beyond_masses_words`; an SO-100 servo arm of link masses 15 % off its
description, its currents read through constants 2.45 times the true ones: factors 2.33
to 2.42, a spread of 2.1 % beyond their 0.05 % uncertainty, once called the masses' with
a 0.41 kg mass at its gripper; a 0.1 kg load at the gripper instead gives 1.44 to 2.04,
as far apart as they are from 1, and stays the masses' note, naming the load).
"""

from __future__ import annotations

import dataclasses
from collections.abc import Sequence
from dataclasses import dataclass

import numpy as np
from numpy.typing import NDArray

from ..dynamics.terms import gravity_torques
from ..model.drive import Drive
from ..model.placeholders import placeholder_words
from ..model.robot import Robot
from ..regressors.torque import torque_regressor
from .drive_gains import AGREE, MASSES, corrected_constants
from .model import IdentifiedModel
from .model_sign import gravity_loaded

__all__ = [
    "AGREE",
    "DESCRIBED",
    "GRAVITY_SCALE",
    "GravityRatios",
    "LEVEL",
    "OFF",
    "SHAPE",
    "UNIFORM",
    "at_the_motors",
    "beyond_masses_words",
    "gravity_masses_words",
    "flange_mass",
    "flange_mass_of",
    "gravity_ratio_covariance",
    "gravity_ratios",
    "gravity_scale_factor",
    "gravity_scale_finding",
    "gravity_scale_words",
    "recorded_scale",
]

#: Relative distance from 1 of the common factor that makes a finding (above ``1 + OFF`` or
#: below its inverse: a factor and its inverse alike).
OFF = 0.10
#: Largest relative spread of the loaded joints' factors about their mean for "the same".
UNIFORM = 0.05
#: Smallest correlation of a loaded joint's identified and described gravity torques.
SHAPE = 0.98
#: Relative standard deviation [-] of a joint's factor added to the fit's: the error of a
#: description's masses even a good one keeps (a scale is named through it): 0.5 %.
DESCRIBED = 0.005
#: Chi-square tail probability below which the joints' factors are not one factor.
LEVEL = 1e-3
#: Configurations used at most (spread over the logs).
_SAMPLES = 2_000
#: The key of an identified model's metadata that records the finding (``factor`` [-] and
#: ``finding``, its sentence), for the commands that read the model.
GRAVITY_SCALE = "gravity_scale"


def recorded_scale(model: object) -> tuple[float, str] | None:
    """The factor [-] of ``model``'s gravity torques to its description's and the finding's
    sentence, as ``identify`` recorded them in its metadata (:data:`GRAVITY_SCALE`), or
    None: not an identified model, no finding recorded (or a record of another form)."""
    if not isinstance(model, IdentifiedModel):
        return None
    got = model.info.extra.get(GRAVITY_SCALE)
    if not isinstance(got, dict):
        return None
    factor, said = got.get("factor"), got.get("finding")
    if not isinstance(factor, int | float) or not isinstance(said, str) or not factor > 0:
        return None
    return float(factor), said


def gravity_ratios(
    robot: Robot, model: IdentifiedModel, q: NDArray[np.float64]
) -> tuple[NDArray[np.float64], NDArray[np.float64], NDArray[np.bool_]]:
    """Per joint: the factor ``r_j`` of the model's gravity torques to the description's
    at the configurations ``q`` (N, n) [rad] (least squares, means kept: gravity has an
    absolute level), their correlation, and which joints gravity loads (the others' entries
    are NaN)."""
    loaded = gravity_loaded(robot, q)
    gd = gravity_torques(robot, q)
    gm = model.gravity_torques(q)
    r = np.full(robot.n, np.nan)
    c = np.full(robot.n, np.nan)
    for j in np.flatnonzero(loaded):
        d, m = gd[:, j], gm[:, j]
        r[j] = float(d @ m / (d @ d))
        sd, sm = np.std(d), np.std(m)
        c[j] = float(np.mean((d - d.mean()) * (m - m.mean())) / (sd * sm)) if sd * sm > 0 else 0
    return r, c, loaded


@dataclass(frozen=True)
class GravityRatios:
    """The identified model's gravity torques over the description's, per loaded joint,
    judged against one factor on every joint (module docstring).

    Attributes
    ----------
    factor : float
        The common factor [-], weighted by the joints' covariance (plus :data:`DESCRIBED`).
    factor_std : float
        Its standard deviation [-] from the fit's parameter covariance; NaN without one.
    ratios : ndarray, shape (n,)
        Each joint's factor [-]; NaN on the joints gravity does not load.
    ratio_std : ndarray, shape (n,)
        Their standard deviations [-] from the fit's covariance; NaN without one, and off
        the loaded joints.
    joints : ndarray of int
        The loaded joints (from 0).
    chi2 : float
        The ratios' chi-square about ``factor`` (``len(joints) - 1`` degrees of freedom).
    one_factor : bool
        Whether they are one factor: chi-square within :data:`LEVEL`, spread within
        :data:`UNIFORM`.
    flange : tuple of (float, ndarray), optional
        The mass [kg] at the last link and its position (3,) [m] that make up the
        difference (:func:`flange_mass`), for factors that differ and are no scale.
    beyond_masses : bool
        Factors that differ (not :attr:`one_factor`) whose common factor is a scale all the
        same: farther from 1 than :data:`~.drive_gains.MASSES` and
        :data:`~.drive_gains.AGREE` times
        farther than the joints' largest distance from it (:attr:`spread`), both of
        logarithms, and explaining the gravity torques as well as a mass at the flange
        (module docstring).
    """

    factor: float
    factor_std: float
    ratios: NDArray[np.float64]
    ratio_std: NDArray[np.float64]
    joints: NDArray[np.intp]
    chi2: float
    one_factor: bool
    flange: tuple[float, NDArray[np.float64]] | None = None
    beyond_masses: bool = False

    @property
    def spread(self) -> float:
        """The loaded joints' largest relative distance [-] from the common factor
        (``exp(max |log r_j - log factor|) - 1``)."""
        d = np.abs(np.log(self.ratios[self.joints] / self.factor))
        return float(np.expm1(np.max(d)))

    @property
    def scale(self) -> bool:
        """Whether the factor is the torques' scale: :attr:`one_factor` or
        :attr:`beyond_masses`."""
        return self.one_factor or self.beyond_masses


def flange_mass(
    robot: Robot, model: IdentifiedModel, q: NDArray[np.float64]
) -> tuple[float, NDArray[np.float64]] | None:
    """The point mass [kg] and its position (3,) [m, last link's frame] at the last link
    whose gravity torques make up the model's less the description's at the
    configurations ``q`` (N, n) [rad] (:func:`flange_mass_of` the model's gravity
    torques), or None. A hand or a tool the description lacks reads so (a Panda carrying
    its 0.73 kg hand, which the built-in description holds not), and so do its last links
    heavier than described (its links 5-7 16 % so: 0.63 kg near link 7's origin leaves 0.2
    % of the difference), which gravity torques alone cannot tell apart."""
    return flange_mass_of(robot, q, model.gravity_torques(q))


def flange_mass_of(
    robot: Robot, q: NDArray[np.float64], g: NDArray[np.float64]
) -> tuple[float, NDArray[np.float64]] | None:
    """The point mass [kg] and its position (3,) [m, last link's frame] at the last link
    whose gravity torques make up ``g`` (N, n) [N m] (a model's, or a controller's static
    data) less ``robot``'s description's at the configurations ``q`` (N, n) [rad] (least
    squares of the last link's mass and first moment columns over the joints gravity
    loads), or None: a mass not positive, or one that leaves over a tenth of that
    difference's energy."""
    loaded = gravity_loaded(robot, q)
    diff = (np.asarray(g, dtype=np.float64) - gravity_torques(robot, q))[:, loaded].ravel()
    last = 10 * (robot.n - 1)
    zero = np.zeros_like(q)
    Y = torque_regressor(robot, q, zero, zero)[:, loaded, last : last + 4].reshape(-1, 4)
    x, *_ = np.linalg.lstsq(Y, diff, rcond=None)
    rest = diff - Y @ x
    if not x[0] > 0 or float(rest @ rest) > _FLANGE_REST * float(diff @ diff):
        return None
    return float(x[0]), np.asarray(x[1:] / x[0], dtype=np.float64)


#: The share of the difference a mass at the flange may leave (:func:`flange_mass`).
_FLANGE_REST = 0.1


def gravity_ratio_covariance(
    model: IdentifiedModel, q: NDArray[np.float64], gd: NDArray[np.float64], js: NDArray[np.intp]
) -> NDArray[np.float64] | None:
    """The covariance (k, k) [-] of the loaded joints' ``js`` (k,) factors
    (:func:`gravity_ratios`) at the configurations ``q`` (N, n) [rad], the description's
    gravity torques there ``gd`` (N, n) [N m]: each factor is ``a_j . beta`` with ``a_j =
    g_d,j^T Y_g,j / |g_d,j|^2`` (``Y_g``: the gravity rows of the base regressor), so its
    covariance is ``A Sigma A^T`` over the fit's (``Sigma``); None without it."""
    cov = model.fit.covariance
    if cov is None:
        return None
    robot = model.robot
    Y = torque_regressor(robot, q, np.zeros_like(q), np.zeros_like(q))  # (N, n, 10 n)
    ind = np.asarray(model.base.independent)
    links = ind < 10 * robot.n  # the base's rotor inertias carry no gravity
    A = np.zeros((js.size, ind.size))
    for i, j in enumerate(js):
        d = gd[:, j]
        A[i, links] = d @ Y[:, j, ind[links]] / (d @ d)
    return A @ np.asarray(cov, dtype=np.float64) @ A.T


def _one_factor(
    r: NDArray[np.float64], C: NDArray[np.float64] | None
) -> tuple[float, float, float, bool]:
    """The common factor of the ratios ``r`` (k,) [-] of covariance ``C`` (k, k) (None:
    unknown, :data:`DESCRIBED` alone), its standard deviation from ``C`` (NaN without),
    their chi-square about it, and whether they are one factor (module docstring)."""
    import scipy.linalg  # here: the command's start loads no scipy
    import scipy.stats

    k = r.size
    known = np.zeros((k, k)) if C is None else C
    ceff = known + (DESCRIBED * float(np.mean(r))) ** 2 * np.eye(k)
    fac = scipy.linalg.cho_factor(ceff)
    w = scipy.linalg.cho_solve(fac, np.ones(k))
    w = w / w.sum()
    factor = float(w @ r)
    d = r - factor
    chi2 = float(d @ scipy.linalg.cho_solve(fac, d))
    std = float(np.sqrt(max(w @ known @ w, 0.0))) if C is not None else float("nan")
    agree = chi2 <= scipy.stats.chi2.isf(LEVEL, k - 1) and np.max(np.abs(r - np.mean(r))) <= (
        UNIFORM * np.mean(r)
    )
    return factor, std, chi2, bool(agree)


def gravity_scale_factor(
    robot: Robot, model: IdentifiedModel, q: Sequence[NDArray[np.float64]]
) -> GravityRatios | None:
    """``model``'s gravity torques over ``robot``'s description's (module docstring) at
    the configurations ``q`` (one (N, n) array [rad] per log), judged against one factor
    (:attr:`GravityRatios.one_factor`); None where there is nothing to say: no inertial
    parameters in the description, fewer than 2 loaded joints, shapes that differ or
    factors not positive, factors within :data:`OFF` of 1 on average (between ``1 / (1 +
    OFF)`` and ``1 + OFF``)."""
    if not np.any(robot.phi) or not q:
        return None
    every = np.concatenate([np.asarray(a, dtype=np.float64) for a in q])
    qs = every[:: max(1, every.shape[0] // _SAMPLES)]
    r, c, loaded = gravity_ratios(robot, model, qs)
    js = np.flatnonzero(loaded)
    if js.size < 2 or np.any(c[js] < SHAPE) or np.any(r[js] <= 0):
        return None
    if abs(np.log(float(np.mean(r[js])))) < np.log1p(OFF):
        return None
    C = gravity_ratio_covariance(model, qs, gravity_torques(robot, qs), js)
    factor, std, chi2, agree = _one_factor(r[js], C)
    se = np.full(robot.n, np.nan)
    if C is not None:
        se[js] = np.sqrt(np.clip(np.diag(C), 0.0, None))
    found = GravityRatios(factor, std, r, se, js, chi2, agree)
    if agree:
        return found
    far = abs(np.log(factor)) >= max(np.log1p(MASSES), AGREE * np.log1p(found.spread))
    if far and _scale_explains(robot, qs, model.gravity_torques(qs)):
        return dataclasses.replace(found, beyond_masses=True)
    return dataclasses.replace(found, flange=flange_mass(robot, model, qs))


def _scale_explains(robot: Robot, q: NDArray[np.float64], g: NDArray[np.float64]) -> bool:
    """Whether one factor on the description's gravity torques explains the gravity
    torques ``g`` (N, n) [N m] at the configurations ``q`` (N, n) [rad] at least as well
    as the description's plus a point mass at the last link (its mass and first moments,
    :func:`flange_mass_of`'s fit), on the joints gravity loads: a load the description
    lacks makes the joints' factors differ by its levers (an SO-101 of link masses 15 %
    off carrying 0.1 kg: 12 % of the torques left by a factor, 0.2 % by the mass), a
    torque constant by the masses' error (2.45 times: 1.4 % by the factor, 1.6 % by a
    mass, 0.54 kg on a 0.47 kg arm)."""
    loaded = gravity_loaded(robot, q)
    gd = gravity_torques(robot, q)[:, loaded].ravel()
    gm = np.asarray(g, dtype=np.float64)[:, loaded].ravel()
    by_factor = gm - (gd @ gm / (gd @ gd)) * gd
    last = 10 * (robot.n - 1)
    zero = np.zeros_like(q)
    Y = torque_regressor(robot, q, zero, zero)[:, loaded, last : last + 4].reshape(-1, 4)
    x, *_ = np.linalg.lstsq(Y, gm - gd, rcond=None)
    by_mass = gm - gd - Y @ x
    return float(by_factor @ by_factor) <= float(by_mass @ by_mass)


def gravity_scale_finding(
    robot: Robot,
    model: IdentifiedModel,
    q: Sequence[NDArray[np.float64]],
    drive: Drive | None = None,
) -> str | None:
    """The finding (module docstring) of ``model`` identified from logs at the
    configurations ``q`` (one (N, n) array per log) of ``robot``, or None: no inertial
    parameters in the description, fewer than 2 loaded joints, factors that differ between
    joints within what the description's masses make (:func:`gravity_masses_words` says
    those: not :attr:`GravityRatios.scale`) or lie within :data:`OFF` of 1.
    ``drive``: the drive the log was read through (a log of currents: its torque constant
    is named)."""
    found = gravity_scale_factor(robot, model, q)
    if found is None or not found.scale:
        return None
    return gravity_scale_words(robot, found, drive)


def _std(x: float) -> str:
    """`` (std 0.0012)``, or nothing for a standard deviation not known (NaN)."""
    return "" if not np.isfinite(x) else f" (std {x:.2g})"


def gravity_scale_words(
    robot: Robot, found: GravityRatios, drive: Drive | None = None, fix: float | None = None
) -> str:
    """:func:`gravity_scale_finding`'s sentence of the factor :func:`gravity_scale_factor`
    ``found`` (one factor on every loaded joint, or beyond the masses' error: then
    :func:`beyond_masses_words`) of ``robot``. ``fix``: the torque constants' correction
    [-] (true over read) where another estimate of the same factor is judged better (the
    held-out gains' common factor, :attr:`~.drive_gains.DriveGains.common`): the finding
    then names that one, so that the two agree; else ``1 / found.factor``."""
    if found.beyond_masses:
        return beyond_masses_words(robot, found, drive, fix)
    mean, r, js = found.factor, found.ratios, found.joints
    names = ", ".join(robot.joint_names[j] for j in js)
    said = (
        f"the identified gravity torques are {mean:.3g}{_std(found.factor_std)} times the "
        f"robot description's on every joint gravity loads ({names}: {r[js].min():.3g} to "
        f"{r[js].max():.3g}), one factor the fit cannot see (it predicts the log as well)"
    )
    if drive is not None and drive.effort == "current" and drive.torque_constant is not None:
        k = 1 / mean if fix is None else fix
        return (
            f"{said}; if the description's masses are right, the torque constants are off: "
            f"{corrected_constants(drive.torque_constant, k)}{at_the_motors(drive, k)}"
        )
    currents = (
        '; or the log holds motor currents: a drive with effort = "current" and each '
        "motor's torque_constant"
        if not 0.5 <= mean <= 2.0
        else ""
    )
    return (
        f"{said}; if the description's masses are right, the torques are {1 / mean:.3g} "
        f"times too small (a sensor scale: units='tau={1 / mean:.3g}'){currents}"
    )


#: A factor [-] within this relative distance of 1000 is an effort unit's (mA read as A,
#: mN m as N m).
_UNIT_TOL = 0.15


def beyond_masses_words(
    robot: Robot, found: GravityRatios, drive: Drive | None = None, fix: float | None = None
) -> str:
    """The finding of factors :func:`gravity_scale_factor` ``found`` that differ between
    the loaded joints of ``robot`` and share a common factor beyond the masses' error
    (:attr:`GravityRatios.beyond_masses`): the torques' scale first, with its fix
    (``drive``'s torque constants corrected, :func:`~.drive_gains.corrected_constants`, by
    ``fix`` where given, :func:`gravity_scale_words`, else by ``1 / found.factor``; an
    effort unit's near 1000), then why the masses do not make it."""
    mean, r, js = found.factor, found.ratios, found.joints
    k = 1.0 / mean if fix is None else fix
    unit = abs(np.log(mean / 1000.0)) < np.log1p(_UNIT_TOL)
    current = drive is not None and drive.effort == "current"
    if current and unit:
        lead = (
            f"the currents read {mean:.3g} times the description's gravity torques on every "
            "joint: currents in mA read as A (units='tau=mA' reads them, the drive as it is)"
        )
    elif current:
        assert drive is not None and drive.torque_constant is not None  # a drive of currents
        lead = (
            "the torque constants look off by one factor on every motor: put "
            f"{corrected_constants(drive.torque_constant, k)} in the drive file"
            f"{at_the_motors(drive, k)} and identify again"
        )
    else:
        which = " (mN m read as N m: units='tau=mNm')" if unit else ""
        lead = (
            f"the torques look {mean:.3g} times the true ones on every joint{which}: scale "
            f"them by {k:.3g} (units='tau={k:.3g}') and identify again"
            + (
                '; or the log holds motor currents: a drive with effort = "current" and '
                "each motor's torque_constant"
                if not unit and not 0.5 <= mean <= 2.0
                else ""
            )
        )
    each = ", ".join(f"{robot.joint_names[j]} {r[j]:.4g}" for j in js)
    return (
        f"{lead}. Why: the identified gravity torques are {r[js].min():.3g} to "
        f"{r[js].max():.3g} times the description's ({each}), within "
        f"{100 * found.spread:.2g} % of each other, too far from 1 for an error of its "
        f"masses (over {100 * MASSES:g} %, and {AGREE:g} times that spread), and no load at "
        "the flange fits them better"
    )


def gravity_masses_words(robot: Robot, found: GravityRatios) -> str:
    """The note of factors :func:`gravity_scale_factor` ``found`` that differ between the
    loaded joints of ``robot`` (not one factor): the description's masses are off joint by
    joint, and the model, fitted to the torques as logged, needs no change."""
    r, se, js = found.ratios, found.ratio_std, found.joints
    each = ", ".join(
        f"{robot.joint_names[j]} {r[j]:.4g}"
        + ("" if not np.isfinite(se[j]) else f" +- {se[j]:.1g}")
        for j in js
    )
    return (
        f"the identified gravity torques are {r[js].min():.3g} to {r[js].max():.3g} times the "
        f"robot description's on the joints gravity loads ({each}): factors that differ "
        f"between joints beyond their uncertainty (chi-square {found.chi2:.3g} on "
        f"{js.size - 1} degrees of freedom, {100 * DESCRIBED:.3g} % of the factor per joint "
        "added for the description's own error), where a scale of the torques (a sensor's, "
        "a torque constant's) is one factor on every joint: the description's link masses "
        "look off (its inertials not the arm's); the identified model, fitted to the torques "
        f"as logged, is right as it is and needs no change{_at_the_flange(robot, found)}"
    )


def _at_the_flange(robot: Robot, found: GravityRatios) -> str:
    """A clause naming the mass at the flange that makes up the difference
    (:func:`flange_mass`), or nothing; where the description has placeholder links
    (:mod:`dynid.model.placeholders`), they are named first: their missing masses look
    like a load at the flange."""
    if found.flange is None:
        return ""
    m, c = found.flange
    at = ", ".join(f"{v:+.3f}" for v in c)
    stand_in = placeholder_words(robot)
    first = (
        ""
        if stand_in is None
        else f"first the description's {stand_in}, whose real masses it lacks; else "
    )
    return (
        f"; a mass of about {m:.3g} kg at ({at}) m in {robot.link_names[-1]}'s frame makes up the "
        f"difference: {first}a hand or a tool the description lacks (the built-in panda and "
        "fr3 hold none), or its last links heavier than described (gravity alone cannot tell "
        "them apart), which the fit carries in its parameters"
    )


def at_the_motors(drive: Drive, factor: float) -> str:
    """A clause when ``factor``, the torque constants' correction, is near the gear ratio
    every joint of a joint-side ``drive`` shares (within 1/3 to 3 times): constants given
    at the motors, where ``side = "joint"`` wants each joint's torque per A."""
    ratio = np.abs(np.diag(np.asarray(drive.transmission, dtype=np.float64)))
    if drive.side != "joint" or drive.is_coupled:
        return ""
    if not np.allclose(ratio, ratio[0]) or ratio[0] == 1 or not 1 / 3 <= factor / ratio[0] <= 3:
        return ""
    return (
        f" (near the gear ratio, {ratio[0]:.4g}: torque_constant looks given at the motors; on "
        "a joint-side log, side = \"joint\", it is each joint's torque per A, the motor's "
        "constant times its gear ratio)"
    )
