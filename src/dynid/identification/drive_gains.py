"""Per-motor gains of the logged efforts, identified with the model: torque constants (or
torque sensors' scales) that are off by a different factor on each joint.

A log of currents read through guessed torque constants, or of torque sensors with a
scale error each, gives efforts ``e`` that are the true torques divided by a gain ``g_m``
per motor (a log recorded on the joint side: per joint). The true joint torques
``sum_m g_m E_m`` (``E_m``: motor ``m``'s logged effort mapped to the joints,
:func:`effort_columns`) are the model's ``W theta`` (rigid-body base parameters, friction,
rotor inertia, the model's terms), which is linear and homogeneous in ``(g, theta)``
jointly (the known approach of identifying drive gains with the dynamic parameters,
Khalil and Dombre, *Modeling, Identification and Control of Robots*, ch. 12). With each
joint's rows in units of its noise, the model's columns projected out leave ``S g ~ 0``
(``S``: the gains' normal matrix after the projection, ``m x m``); ``g`` is the
eigenvector of ``S``'s smallest eigenvalue (noise in the efforts adds about a multiple of
the identity to ``S``, which leaves its eigenvectors). The data fix the gains' ratios, not
their common scale: that is the robot description's masses (the fitted model's gravity
torques against the description's, pooled over the joints gravity loads; as
:mod:`~dynid.identification.gravity_scale` does for one factor on every joint), else the
gains are relative (geometric mean 1). The factors' covariance counts that scale's own
noise (the parameters fitted again to the log it is read from) beside the ratios', and the
efforts of motors left out enter every fit instrumented by the model's columns (noisy
regressors would bias the parameters the others share).

A motor's gain is determined where its joints' equations share link parameters with the
others' (the base parameters of a serial arm: a link's appear in every joint before it); one
whose equation is its own (its friction and rotor, parameters of its own link alone, or a
joint that never moved) is not, and its standard deviation says so
(:attr:`DriveGains.determined`); a gain the data leave loose in-sample is left out (its
effort a free column, like a motor whose effort the model's columns hold) and the others
fitted again, so that a loose gain's sign does not stop the finding. The finding
(:attr:`DriveGains.named`) names the determined motors whose gain differs from 1 by at least
:data:`OFF` and :data:`SIGNIFICANT` standard deviations, when the gains differ between
joints (a common factor alone is :mod:`~dynid.identification.gravity_scale`'s) and fitting
them brings the error's part above the noise down to at most :data:`EXPLAINED` of what it
was (:attr:`DriveGains.explains`), and only where fitting that motor's gain improves the
prediction of data the fit did not see: the gains and the model's columns fitted on every
fold but one (leave one recording out with several, contiguous time blocks otherwise: the
folds of the structure selection) predict the fold left out better than the same fit with
that motor's gain held at 1, by more than the standard error of the difference paired over
the folds (:attr:`DriveGains.heldout_gain`). An in-sample standard deviation alone does not
tell a wrong torque constant from model error a gain takes up in-sample (a simulated Panda's
wrist motor 6 with its true constant came out 0.68 +- 0.02)."""

from __future__ import annotations

import dataclasses
from dataclasses import dataclass
from typing import Any, Literal

import numpy as np
from numpy.typing import ArrayLike, NDArray

from .solvers import tall_r

__all__ = [
    "AGREE",
    "CALIBRATED_FOLDS",
    "CONSTANTS_DOC",
    "DETERMINED",
    "EXPLAINED",
    "LINKED",
    "MASSES",
    "OFF",
    "RAISE",
    "SIGNIFICANT",
    "DriveGains",
    "corrected_constants",
    "drive_gains",
    "effort_columns",
    "few_folds",
]

#: Relative distance from 1 of a gain the finding names.
OFF = 0.10
#: Largest relative distance from 1 of a factor a robot description's masses make on
#: every joint together (links 15 % off each: the joints' factors within 5 % of 1): a
#: common factor beyond it is the efforts' scale (a torque constant's, a unit's).
MASSES = 0.20
#: Smallest ratio of a common factor's distance from 1 to the largest distance of the
#: joints' (motors') factors from it, both of logarithms, for it to be the efforts' scale
#: beside the masses' error: masses off joint by joint move each joint's factor about as
#: much as they move the common one; a torque constant moves every joint alike.
AGREE = 5.0
#: Smallest ratio of a gain's distance from 1 to its standard deviation.
SIGNIFICANT = 5.0
#: Largest relative standard deviation of a determined gain.
DETERMINED = 0.2
#: Largest share of the error above the noise (RMS) the fitted gains may leave.
EXPLAINED = 0.5
#: Smallest energy above the noise (per row, relative to the noise's) of a motor's effort
#: with the model's columns projected out, for its gain to be fitted.
LINKED = 0.25
#: Smallest rise of the squared error ratio (to the noise's) when a named motor's gain is
#: held at 1.
RAISE = 0.02
#: Where the docs say what the data check of a current log's torque constants.
CONSTANTS_DOC = "docs: tutorials/motor-currents.md#what-the-data-check"
#: The folds the rules on a gain's spread over the folds were set on (the time blocks of one
#: recording, :data:`~dynid.identification.holdout.DEFAULT_FOLDS`): a spread from fewer is
#: widened to the same confidence (:func:`few_folds`).
CALIBRATED_FOLDS = 5
#: Relative tolerance of the model columns' rank (pivoted QR of the scaled columns).
_RANK_RTOL = 1e-10


@dataclass(frozen=True, slots=True, eq=False)
class DriveGains:
    """The per-motor gains a torque log points to (module docstring).

    Attributes
    ----------
    factor : ndarray, shape (m,)
        Each motor's gain: the true effort over the logged one (a torque constant to
        multiply by it) [-]; scaled by the description's masses when :attr:`scaled`, else
        relative (geometric mean 1 over the determined motors).
    cov : ndarray, shape (m, m)
        Their covariance [-] (white residual assumed: a lower bound), at the
        description's scale (:attr:`scaled`) with that scale's own noise counted (the
        parameters fitted again to the log it is read from), else at the geometric mean's,
        where only ratios of gains are determined by the data (:attr:`std`,
        :meth:`ratio_std`).
    scaled : bool
        Whether the common scale is the robot description's (its gravity torques).
    ratio_fixed : float
        The weighted residual's RMS over the noise [-] of the model's columns fitted with
        every gain 1 (the efforts as logged).
    ratio_fitted : float
        The same with the gains fitted.
    ratio_held : ndarray, shape (m,), optional
        The weighted residual's RMS over the noise with the gains fitted but motor
        ``k``'s held at 1 (the constant as logged), the parameters fitted again; NaN where
        not fitted. A gain whose holding raises ``ratio^2`` by less than :data:`RAISE`
        is no finding's, whatever its standard deviation (a long log makes a systematic
        error of a few percent of the noise many standard deviations).
    effort : {"current", "torque"}
        What the log holds, for the finding's words: motor currents through a drive's
        torque constants, or torques (sensors' scales).
    per : {"joint", "motor"}
        Whose efforts the gains scale, for the finding's words: a joint-side log's joints
        or a motor-side log's motors.
    heldout_gain : ndarray, shape (m,), optional
        Per motor, how much fitting its gain improves the held-out prediction: the mean over
        the folds of the held-out weighted residual's mean square over the noise's [-] with
        its gain held at 1 minus that with it fitted (the gains and the model's columns
        fitted on the other folds); NaN where not fitted; None without folds.
    heldout_se : ndarray, shape (m,), optional
        The standard error [-] of :attr:`heldout_gain`, of the differences paired over the
        folds.
    heldout_std : ndarray, shape (m,), optional
        Each motor's gain's standard deviation [-] from its spread over the folds (the
        delete-a-fold jackknife of the gains fitted on every fold but one, at the scale of
        :attr:`factor`, widened by :func:`few_folds` from fewer than
        :data:`CALIBRATED_FOLDS` folds: a spread of two recordings' gains is half their
        distance): what the in-sample :attr:`cov` misses where the residual is not white
        (model error a gain takes up differently in each part of the log); NaN where not
        fitted; None without folds.
    applied : bool
        The model was fitted to the efforts these factors correct (``identify`` judging a
        current log's torque constants first): its drive holds the corrected constants, and
        the finding says to put them in the drive file, not to identify again.
    floor : bool
        Judged where the prediction is at the noise floor, which says nothing of the
        factors: a gain is named only where it lies :data:`SIGNIFICANT` times its spread
        over the folds (:attr:`heldout_std`) from 1 as well (none without folds): a Panda's
        15 s current log at 100 Hz through constants within 2 % of the true ones read
        joint 4's 0.857, std 0.012 in-sample but 0.075 over the folds, and named it.
    constants : ndarray, shape (m,), optional
        The torque constants [N m/A] the currents were read through (the drive's, as the
        identification used them), for the corrected values the finding gives; None for
        a log of torques.
    """

    factor: NDArray[np.float64]
    cov: NDArray[np.float64]
    scaled: bool
    ratio_fixed: float
    ratio_fitted: float
    ratio_held: NDArray[np.float64] | None = None
    effort: Literal["current", "torque"] = "torque"
    per: Literal["joint", "motor"] = "joint"
    heldout_gain: NDArray[np.float64] | None = None
    heldout_se: NDArray[np.float64] | None = None
    heldout_std: NDArray[np.float64] | None = None
    applied: bool = False
    floor: bool = False
    constants: NDArray[np.float64] | None = None

    def ratio_std(self, k: int, r: int) -> float:
        """The standard deviation [-] of motor ``k``'s gain relative to motor ``r``'s,
        ``factor[k] / factor[r]``, times ``factor[r]``: ``k``'s gain with ``r``'s held
        (first-order propagation of :attr:`cov`)."""
        f = self.factor
        grad = np.zeros(f.size)
        grad[k] += 1.0 / f[r]
        grad[r] -= f[k] / f[r] ** 2
        cov = np.nan_to_num(self.cov, nan=0.0)  # the motors left out: no part
        return float(abs(f[r]) * np.sqrt(max(float(grad @ cov @ grad), 0.0)))

    @property
    def std(self) -> NDArray[np.float64]:
        """Each motor's standard deviation [-]: the smallest of :meth:`ratio_std` over the
        other motors (a gain is determined against the one it shares most with); at the
        description's scale (:attr:`scaled`) that of the factor itself, the scale's own
        noise counted (:attr:`cov`'s diagonal); infinite for a single motor."""
        out = self._ratio_min()
        if not self.scaled:
            return out
        own = np.sqrt(np.abs(np.diagonal(self.cov)))
        return np.where(np.isfinite(own) & np.isfinite(out), own, out)

    def _ratio_min(self) -> NDArray[np.float64]:
        """Each motor's smallest :meth:`ratio_std` over the other motors (m,) [-]."""
        m = self.factor.size
        out = np.full(m, np.inf)
        fitted = np.isfinite(self.factor) & (self.factor != 0)
        for k in np.flatnonzero(fitted):
            for r in np.flatnonzero(fitted):
                if r != k:
                    out[k] = min(out[k], self.ratio_std(int(k), int(r)))
        return out

    @property
    def determined(self) -> NDArray[np.bool_]:
        """The motors (m,) whose gain the data determine: fitted (not NaN) and of relative
        standard deviation at most :data:`DETERMINED`, in-sample (:attr:`std`) and over
        the folds (:attr:`heldout_std`: a gain fitted to model error that differs along
        the log spreads over the folds however small its in-sample standard deviation);
        whether a determined gain is a finding is :attr:`named`'s, judged on held-out
        data."""
        f = np.nan_to_num(self.factor, nan=0.0)
        std = self._ratio_min()  # the data's; the common scale is the description's
        if self.heldout_std is not None:
            std = np.where(np.isnan(self.heldout_std), std, np.fmax(std, self.heldout_std))
        return np.isfinite(self.factor) & (std <= DETERMINED * np.abs(f))

    @property
    def uneven(self) -> bool:
        """Whether the determined gains differ between motors: two of them differ by at
        least :data:`OFF` of the smaller and :data:`SIGNIFICANT` standard deviations of
        their difference (any pair: the largest and smallest alone may hold a loose wrist
        motor whose difference is within its standard deviation)."""
        js = np.flatnonzero(self.determined)
        for hi in js:
            for lo in js:
                gap = float(self.factor[hi] - self.factor[lo])
                if gap > 0 and gap >= OFF * float(self.factor[lo]):
                    if gap >= SIGNIFICANT * self.ratio_std(int(hi), int(lo)):
                        return True
        return False

    @property
    def common(self) -> float | None:
        """The determined motors' common factor [-] (geometric mean) where it is the
        efforts' scale beyond the description's masses' error: the gains at the
        description's scale (:attr:`scaled`), at least two determined, not :attr:`uneven`,
        their common factor farther from 1 than :data:`MASSES` and :data:`AGREE` times
        farther than any of them from it (logarithms; an SO-100's currents through
        constants 2.45 times the true ones: 0.405 to 0.419); None otherwise. A load the
        description lacks gives such a factor too (the gains see the efforts' scale
        against the model's, not where it comes from): the gravity torques tell them
        apart (:mod:`~dynid.identification.gravity_scale`)."""
        js = np.flatnonzero(self.determined)
        if not self.scaled or js.size < 2 or self.uneven or np.any(self.factor[js] <= 0):
            return None
        logs = np.log(self.factor[js])
        mid = float(np.mean(logs))
        if abs(mid) < max(np.log1p(MASSES), AGREE * float(np.max(np.abs(logs - mid)))):
            return None
        return float(np.exp(mid))

    @property
    def explains(self) -> bool:
        """Whether the efforts as logged leave an error above the noise and fitting the
        gains leaves at most :data:`EXPLAINED` of its part above the noise (RMS,
        ``sqrt(ratio^2 - 1)``). Both fits are in-sample: the parameters fitted again to
        the log judged take much of a prediction's error (a held-out error 13 x the noise
        is 1.1 x in-sample), so the error being above the noise is the verdict's to say.
        At the noise floor (:attr:`floor`) there is no error above the noise to explain:
        True where the gains fitted lower the in-sample error at all, and each motor is
        judged by its spread over the folds (a UR5 model fitted to currents through joint
        2's constant 1.15 times the true one, validated on another recording: 1.0 x the
        noise in-sample with the constants as logged, 0.66 with the gains fitted, joint 2's
        0.872 +- 0.021 over the time blocks, the truth 0.870)."""
        if self.floor:
            return self.ratio_fitted < self.ratio_fixed
        before = np.sqrt(max(self.ratio_fixed**2 - 1.0, 0.0))
        after = np.sqrt(max(self.ratio_fitted**2 - 1.0, 0.0))
        return before > 0 and after <= EXPLAINED * before

    @property
    def improves(self) -> NDArray[np.bool_]:
        """The motors (m,) whose fitted gain improves the held-out prediction by more
        than its standard error (:attr:`heldout_gain` above :attr:`heldout_se`); every
        motor without folds."""
        if self.heldout_gain is None or self.heldout_se is None:
            return np.ones(self.factor.size, dtype=bool)
        gain = np.nan_to_num(self.heldout_gain, nan=-np.inf)
        return gain > np.nan_to_num(self.heldout_se, nan=np.inf)

    @property
    def named(self) -> tuple[int, ...]:
        """The motors (from 0) the finding names: the gains uneven and explaining the
        error (:attr:`uneven`, :attr:`explains`), each determined motor whose gain is at
        least :data:`OFF` from 1 and :data:`SIGNIFICANT` standard deviations clear of it
        (relative gains: from their geometric mean) and whose fitting improves the
        held-out prediction (:attr:`improves`)."""
        if not (self.uneven and self.explains):
            return ()
        return tuple(int(k) for k in np.flatnonzero(self._off() & self.improves))

    def _off(self) -> NDArray[np.bool_]:
        """The determined motors (m,) whose gain is at least :data:`OFF` from 1, by
        :data:`SIGNIFICANT` standard deviations, and whose holding at 1 raises the
        in-sample error by :data:`RAISE` (:attr:`ratio_held`)."""
        d, std = np.abs(np.nan_to_num(self.factor, nan=1.0) - 1.0), self.std
        if self.floor:  # at the floor, clear of 1 over the folds too
            spread = np.full(d.size, np.inf) if self.heldout_std is None else self.heldout_std
            std = np.fmax(std, np.nan_to_num(spread, nan=np.inf))
        ok = self.determined & (d >= OFF) & (d >= SIGNIFICANT * std)
        if self.ratio_held is not None:  # the error depends on it
            held = np.nan_to_num(self.ratio_held, nan=0.0)
            ok &= held**2 - self.ratio_fitted**2 >= RAISE
        return np.asarray(ok, dtype=bool)

    @property
    def unconfirmed(self) -> tuple[int, ...]:
        """The motors (from 0) off by in-sample measures (:attr:`named`'s but for the
        held-out judgement) whose fitting does not improve the held-out prediction: model
        error a gain takes up in-sample, not a finding."""
        if not (self.uneven and self.explains):
            return ()
        return tuple(int(k) for k in np.flatnonzero(self._off() & ~self.improves))

    @property
    def vague(self) -> tuple[int, ...]:
        """The motors (from 0) neither :attr:`named` nor :attr:`unconfirmed` whose gain
        reads at least :data:`OFF` from 1 yet spreads over the folds by at least
        :data:`OFF` (:attr:`heldout_std`): determined too loosely to be a finding, too
        loosely to vouch for the constant either (a UR5 trial's wrist motor 4 through a
        constant 0.85 times the true one: 1.13 in-sample, 0.17 over the folds)."""
        if self.heldout_std is None:
            return ()
        said = set(self.named) | set(self.unconfirmed)
        d = np.abs(np.nan_to_num(self.factor, nan=1.0) - 1.0)
        spread = np.nan_to_num(self.heldout_std, nan=0.0)
        wide = self.determined & (d >= OFF) & (spread >= OFF * np.abs(self.factor))
        return tuple(int(k) for k in np.flatnonzero(wide) if int(k) not in said)

    @property
    def quiet(self) -> tuple[int, ...]:
        """The determined motors (from 0) neither :attr:`named`, :attr:`unconfirmed` nor
        :attr:`vague` whose gain reads at least :data:`OFF` from 1 by :data:`SIGNIFICANT`
        in-sample standard deviations: left out by the error's indifference to them
        (holding the gain at 1 raises it by less than :data:`RAISE`, the joints' own
        friction and rotor taking the factor) or, at the floor, by their spread over the
        folds; determined too loosely to be a finding, too loosely to vouch for the
        constant (a simulated xArm7's wrist motor 6 through a constant 1/1.12 times the
        true one: 1.10, std 0.012 in-sample, 0.045 over the folds, holding it at 1 left
        the error as it was)."""
        if not (self.uneven and self.explains):
            return ()
        said = set(self.named) | set(self.unconfirmed) | set(self.vague)
        d = np.abs(np.nan_to_num(self.factor, nan=1.0) - 1.0)
        off = self.determined & (d >= OFF) & (d >= SIGNIFICANT * self.std)
        return tuple(int(k) for k in np.flatnonzero(off) if int(k) not in said)

    @property
    def unknown_scale(self) -> tuple[int, ...]:
        """The motors (from 0) whose effort's scale the data leave unknown: not
        :attr:`determined`, or read at least :data:`OFF` from 1 and not named
        (:attr:`unconfirmed`, :attr:`vague`, :attr:`quiet`); their joints' torques, and
        the rotor inertias and friction fitted to them, carry that unknown factor."""
        loose = set(np.flatnonzero(~self.determined).tolist())
        off = set(self.unconfirmed) | set(self.vague) | set(self.quiet)
        return tuple(sorted(int(k) for k in loose | off))

    def unnamed_reason(self, k: int) -> str:
        """Why motor ``k``'s determined factor (from 0) is not :attr:`named`, in words that
        name no motor (the same for each motor it holds for): the documented rules that
        hold first, less than :data:`OFF` from 1 (where :attr:`scaled`, the common scale
        is the description's masses', which the data do not check) and, at the noise floor,
        within :data:`SIGNIFICANT` spreads over the folds of 1; else the factors not
        :attr:`uneven`, not :attr:`explains`, its holding at 1 not raising the error by
        :data:`RAISE`, or its fitting not predicting held-out data better."""
        d = abs(float(self.factor[k]) - 1.0)
        said = []
        if d < OFF:
            said.append(
                f"it is within {100 * OFF:g} % of 1"
                + (" (the description's masses are rarely truer)" if self.scaled else "")
            )
        spread = np.inf if self.heldout_std is None else float(self.heldout_std[k])
        if self.floor and not d >= SIGNIFICANT * spread:
            said.append(
                f"at the noise floor it is within {SIGNIFICANT:g} times its spread over the "
                "folds of 1"
            )
        if said:
            return ", and ".join(said)
        if not self.uneven:
            return (
                f"the determined factors do not differ by {100 * OFF:g} % (a factor common "
                "to all is the gravity scale's)"
            )
        if not self.explains:
            return "fitting the gains does not bring the error above the noise down"
        held = np.nan if self.ratio_held is None else float(self.ratio_held[k])
        if np.isfinite(held) and held**2 - self.ratio_fitted**2 < RAISE:
            return "holding it at 1 leaves the error as it is"
        return "fitting it does not predict the data left out better than its standard error"

    def constants_words(self) -> str | None:
        """One line for a log of motor currents: which motors' torque constants the data
        check (:attr:`determined`: the true over those the currents were read through
        (:attr:`constants`), at the description's
        masses' scale where :attr:`scaled`, which the data do not check, else relative),
        why each that is not named needs no change to the drive file
        (:meth:`unnamed_reason`, the motors of one reason together: a factor read 0.92 +-
        0.02 of a constant that is right is within the description's masses' error), and
        which the data cannot check (:attr:`unknown_scale` not determined: those motors'
        torques are as right as the drive file's constants); None for a log of torques."""
        if self.effort != "current":
            return None
        unit, std, spread = self.per, self.std, self.heldout_std
        checked = np.flatnonzero(self.determined)  # the uncertainty each is read with: _read
        parts = [f"these data check no {unit}'s constant"]
        if checked.size:
            reads = ", ".join(
                f"{unit} {k + 1} " + _read(float(self.factor[k]), float(std[k]), spread, int(k))
                for k in checked
            )
            scale = (
                "on the description's masses' scale" if self.scaled else "relative to each other"
            )
            parts = [f"true over read-through ({scale}): {reads}"]
        if self.named:
            parts.append(f"{unit}(s) {_ids(self.named)} named above, with the fix")
        why: dict[str, list[int]] = {}
        common = self.common
        if common is not None:
            parts.append(_common_words(self, common))
        for k in checked:
            if k not in self.named and common is None:
                why.setdefault(self.unnamed_reason(int(k)), []).append(int(k))
        parts += [
            f"no change to the drive file for {unit}(s) {_ids(ks)}: {reason}"
            for reason, ks in why.items()
        ]
        unchecked = [k for k in self.unknown_scale if not self.determined[k]]
        if unchecked:
            why_not = (
                "one guessed as the others' is off alike"
                if common
                else "their torques as right as their constants"
            )
            parts.append(
                f"{unit}(s) {_ids(unchecked)} not checked by these data ({why_not}; a known "
                "payload or a torque sensor checks them)"
            )
        return f"torque constants: {'; '.join(parts)} ({CONSTANTS_DOC})"

    def as_dict(self) -> dict[str, Any]:
        """JSON-ready: ``factor`` and ``std`` per motor (null where left out), ``scaled``,
        ``ratio_fixed``, ``ratio_fitted``, ``ratio_held`` (per motor), ``determined`` and
        ``named`` (the motors' indices from 0), ``unknown_scale`` (the motors, from 0,
        whose effort's scale the data leave unknown), ``heldout_gain``, ``heldout_se`` and
        ``heldout_std`` (per motor; null without folds), ``effort``, ``per``,
        ``applied`` (the model was fitted to the efforts the factors correct), ``floor``
        (judged at the noise floor) and ``constants`` (:meth:`constants_words`, null for a
        log of torques)."""

        def listed(x: NDArray[np.float64] | None) -> list[float | None] | None:
            if x is None:
                return None
            return [float(v) if np.isfinite(v) else None for v in x]

        return {
            "factor": listed(self.factor),
            "std": listed(self.std),
            "scaled": self.scaled,
            "ratio_fixed": self.ratio_fixed,
            "ratio_fitted": self.ratio_fitted,
            "ratio_held": listed(self.ratio_held),
            "determined": [int(k) for k in np.flatnonzero(self.determined)],
            "named": list(self.named),
            "unknown_scale": list(self.unknown_scale),
            "heldout_gain": listed(self.heldout_gain),
            "heldout_se": listed(self.heldout_se),
            "heldout_std": listed(self.heldout_std),
            "effort": self.effort,
            "per": self.per,
            "applied": self.applied,
            "floor": self.floor,
            "constants": self.constants_words(),
        }

    def sentence(self) -> str | None:
        """The finding in words, or None when :attr:`named` is empty: of currents, a
        drive's torque constants (``torque_constant of motor 2 looks 0.667 times the true
        one: multiply it by 1.5``; ``of joint 2`` where each motor turns its own joint one
        to one, :attr:`per`); of torques, the sensors' scales (``the torques of joint
        2 read 0.667 times the true ones``); relative gains (:attr:`scaled` false) as the
        factors between the motors, their common one not known."""
        named, what, std = self.named, self.effort, self.std
        if not named:
            return None
        unit = self.per
        said = (
            f"a gain per {unit} explains the residual (fitted with the model's columns, the "
            f"error falls from {self.ratio_fixed:.3g} to {self.ratio_fitted:.3g} x the noise): "
        )
        if not self.scaled:
            what_of = "torque_constant" if what == "current" else "torques"
            said += (
                f"the {unit}s' {what_of} are off by different factors: multiply "
                + ", ".join(
                    f"{unit} {k + 1}'s by {self.factor[k]:.3g} (std {std[k]:.2g})" for k in named
                )
                + " (relative to each other, their geometric mean 1: without the robot "
                "description's masses the common factor is not known; an identification "
                "with them names it)"
            )
        elif what == "current":
            said += "; ".join(
                f"torque_constant of {unit} {k + 1} looks {1 / self.factor[k]:.3g} times the "
                f"true one: multiply it by {self.factor[k]:.3g} (std {std[k]:.2g})"
                for k in named
            )
            said += " (the common scale from the description's masses)"
        else:
            said += "; ".join(
                f"the torques of {unit} {k + 1} read {1 / self.factor[k]:.3g} times the true "
                f"ones: scale them by {self.factor[k]:.3g} (std {std[k]:.2g})"
                for k in named
            )
            said += " (the common scale from the description's masses)"
        kept = self.unconfirmed
        if kept:
            said += "; " + ", ".join(
                f"{unit} {k + 1}'s {self.factor[k]:.3g} (std {std[k]:.2g})" for k in kept
            )
            said += (
                " not named: fitting it does not improve the prediction of the held-out "
                "data by more than its standard error"
            )
        vague = self.vague
        if vague:
            spread = self.heldout_std
            assert spread is not None  # vague motors have a spread over the folds
            said += "; " + ", ".join(
                f"{unit} {k + 1}'s {self.factor[k]:.3g} (spread {spread[k]:.2g} over the folds)"
                for k in vague
            )
            said += (
                " not named either: the data leave it that uncertain, so its torque_constant "
                "may be off by that much unseen"
            )
        quiet = self.quiet
        if quiet:
            spread = self.heldout_std
            said += "; " + ", ".join(
                f"{unit} {k + 1}'s {self.factor[k]:.3g} (std {std[k]:.2g}"
                + ("" if spread is None else f", {spread[k]:.2g} over the folds")
                + ")"
                for k in quiet
            )
            held = self.ratio_held
            indifferent = held is not None and all(
                held[k] ** 2 - self.ratio_fitted**2 < RAISE for k in quiet
            )
            said += " not named: " + (
                "holding it at 1 leaves the error as it is (its joints' own friction and "
                "rotor take the factor)"
                if indifferent
                else f"over the folds it lies within {SIGNIFICANT:g} spreads of 1"
            )
            said += ", so its torque_constant may be off by that much unseen"

        loose = ", ".join(str(k + 1) for k in np.flatnonzero(~self.determined))
        if loose:
            said += f"; the data do not determine the gain of {unit}(s) {loose}"
        if what == "current" and self.applied:
            return said + (
                ": the model is fitted to the currents these factors correct, and "
                "identification.json's drive holds the corrected torque_constant: put it in "
                "the drive file to read other logs through it"
            )
        if what == "current":
            return said + ": change torque_constant in the drive file and identify again"
        return said + (
            f': a scale per {unit} is a drive file with effort = "current" and these factors '
            "as torque_constant (units='tau=...' scales every joint alike)"
        )


def _common_words(gains: DriveGains, common: float) -> str:
    """The part of :meth:`DriveGains.constants_words` naming the determined motors' common
    factor ``common`` [-] (:attr:`DriveGains.common`) as their torque constants' with its
    fix: the corrected values (:func:`corrected_constants`) where the constants read through
    are known, else the factor to multiply them by."""
    js = np.flatnonzero(gains.determined)
    fix = (
        f"multiply torque_constant by {common:.3g}"
        if gains.constants is None
        else corrected_constants(gains.constants, common)
    )
    return (
        f"{gains.per}s {_ids(js)} share one factor beyond the description's masses' error: "
        f"{fix}, unless a load the description lacks makes it"
    )


def corrected_constants(constants: ArrayLike, factor: float) -> str:
    """The fix of torque constants ``constants`` (m,) [N m/A] the currents were read
    through, all off by one ``factor`` [-] (the true over the read), in words a user copies
    into the drive file: ``torque_constant = [0.7159, 0.7159] (0.415 times the 1.725 the
    currents were read through)``; the one function both findings of such a factor (the
    held-out gains' and the gravity torques') write it with."""
    kt = np.asarray(constants, dtype=np.float64)
    fixed = ", ".join(f"{v:.4g}" for v in kt * factor)
    read = f"{kt[0]:.4g}" if np.allclose(kt, kt[0]) else f"[{', '.join(f'{v:.4g}' for v in kt)}]"
    return (
        f"torque_constant = [{fixed}] ({factor:.3g} times the {read} the currents were read "
        "through)"
    )


def _read(factor: float, std: float, spread: NDArray[np.float64] | None, k: int) -> str:
    """A factor with its uncertainty, the larger of its in-sample standard deviation
    ``std`` and its spread over the folds (``spread[k]``), said where that is the larger:
    ``0.932 +- 0.074 (over the folds)``."""
    over = np.nan if spread is None else float(spread[k])
    if not over > std:
        return f"{factor:.3g} +- {std:.2g}"
    return f"{factor:.3g} +- {over:.2g} (over the folds)"


def _ids(motors: Any) -> str:
    """Motors from 0 as the summary counts them, from 1: ``1, 4, 5``."""
    return ", ".join(str(int(k) + 1) for k in motors)


def effort_columns(tau: ArrayLike, transmission: ArrayLike | None = None) -> NDArray[np.float64]:
    """Each motor's logged effort mapped to the joints: the columns of its gain.

    ``tau = sum_m E_m`` with ``E_m[:, j] = tau_m[:, m] K[m, j]`` and ``tau_m = K^-T tau``
    the motors' torques (:class:`~dynid.model.drive.Drive`: ``tau = K^T tau_m``).

    Parameters
    ----------
    tau : array_like, shape (N, n)
        The joint torques [N m] as read from the log (the efforts through the drive).
    transmission : array_like, shape (n, n), optional
        ``K`` of a motor-side log; None: each joint its own (a joint-side log).

    Returns
    -------
    ndarray, shape (N, n, n)
        [N m]: ``[:, j, m]`` motor ``m``'s part of joint ``j``'s torque.
    """
    T = np.asarray(tau, dtype=np.float64)
    if transmission is None:
        return T[:, :, None] * np.eye(T.shape[1])
    K = np.asarray(transmission, dtype=np.float64)
    motor = np.linalg.solve(K.T, T.T).T
    return motor[:, None, :] * K.T[None, :, :]


def drive_gains(
    columns: ArrayLike,
    tau: ArrayLike,
    noise_rms: ArrayLike,
    transmission: ArrayLike | None = None,
    gravity_columns: ArrayLike | None = None,
    gravity: ArrayLike | None = None,
    folds: ArrayLike | None = None,
) -> DriveGains | None:
    """The per-motor gains that make the logged efforts the model's torques (module
    docstring).

    The gains are the generalized eigenvector of the smallest eigenvalue of ``(S, C)``:
    ``S`` the efforts' normal matrix with the model's columns projected out, ``C`` the
    covariance the noise puts into it per sample (each joint's noise on a joint-side log;
    on a motor-side log each motor's, read from the joints' through ``K``), which makes
    the estimate consistent where the noise differs between the effort columns (a coupled
    motor's effort reaches two joints).

    Parameters
    ----------
    columns : array_like, shape (N, n, p)
        The model's regressor at the samples (base parameters, friction, rotor inertia and
        terms) [N m per parameter unit].
    tau : array_like, shape (N, n)
        The joint torques [N m] as read from the log (the efforts through the drive).
    noise_rms : array_like, shape (n,)
        Each joint's noise [N m].
    transmission : array_like, shape (n, n), optional
        ``K`` of a motor-side log (a gain per motor); None: a gain per joint.
    gravity_columns : array_like, shape (N, n, p), optional
        ``columns`` at rest (zero velocity and acceleration), the links' gravity alone
        (the other columns zero) [N m per parameter unit].
    gravity : array_like, shape (N, n), optional
        The description's gravity torques [N m] at the samples, zero on the joints gravity
        does not load: with ``gravity_columns``, they fix the gains' common scale.
    folds : array_like of int, shape (N,), optional
        The held-out fold of each sample (a recording's, or a contiguous time block's),
        for :attr:`DriveGains.heldout_gain`; None: :data:`~dynid.identification.holdout.
        DEFAULT_FOLDS` contiguous time blocks (none when too few samples).

    Returns
    -------
    DriveGains or None
        None with fewer rows than columns, a noise that is not positive, efforts the
        model's columns hold exactly, or a motor whose gain comes out negative (a torque
        of the opposite sign, which the sign checks of
        :mod:`~dynid.identification.recorded_signs` judge).
    """
    W = np.asarray(columns, dtype=np.float64)
    s = np.asarray(noise_rms, dtype=np.float64)
    E = effort_columns(tau, transmission)
    N, n, p = W.shape
    m = E.shape[-1]
    if not np.all(np.isfinite(s) & (s > 0)) or N * n <= p + m:
        return None
    A = (W / s[:, None]).reshape(N * n, p)
    B = (E / s[:, None]).reshape(N * n, m)
    # the efforts of motors left out enter the fits as instruments (noise-free columns)
    D = np.hstack([B, _instrumented(W / s[:, None], E / s[:, None]).reshape(N * n, m)])
    labels = _fold_labels(N, folds)
    parts = None if labels is None else _fold_rows(A, D, np.repeat(labels, n))
    whole = _Rows.of(A, D) if parts is None else _Rows.stacked(parts)
    norms = np.concatenate([np.linalg.norm(A, axis=0), np.linalg.norm(D, axis=0)])
    norms[norms == 0] = 1.0  # the columns' pivoted QR scaled (a zero column as it is)
    ones = np.ones(m)
    # the efforts with the model's columns projected out
    model = whole.split(*_columns(p, np.ones(m, dtype=bool)), norms)
    dof = N * n - model.rank - (m - 1)
    fixed = model.square(ones) / max(dof, 1)
    if not fixed > 0:
        return None
    C = _noise_covariance(s, transmission)
    active = _linked(whole, norms, C, N)
    described = _Described.of(
        W / s[:, None], E / s[:, None], gravity_columns, gravity, s, transmission
    )
    while True:
        fit = _Eigen.of(whole, norms, B, C, active, described)
        loose = active & ~fit.sure()
        if not loose.any() or active.sum() - loose.sum() < 2:
            break
        active = active & ~loose  # their efforts free columns, the others fitted again
    factor, cov, scaled, g = fit.factor, fit.cov, fit.scaled, fit.g
    if np.any(factor[active] <= 0):  # a motor of the opposite sign: the sign checks name it
        return None
    held = _held_ratios(factor, g, active, fit.split, fit.dof)
    gain = se = spread = None
    if labels is not None and parts is not None:
        gain, se, spread = _heldout(parts, norms, C, active, labels, described, factor)
    fitted = fit.fitted
    found = DriveGains(
        factor, cov, scaled, float(np.sqrt(fixed)), float(np.sqrt(fitted)), held,
        heldout_gain=gain, heldout_se=se, heldout_std=spread,
    )  # fmt: skip
    sure = found.determined
    if scaled or not sure.any():
        return found
    found = _relative(found, sure)  # geometric mean 1 over the determined
    right = found.determined & ~np.isin(np.arange(m), found.named)
    if found.named and right.any():  # the motors named off, at the scale of those right
        found = _relative(found, right)
    return found


def _relative(found: DriveGains, over: NDArray[np.bool_]) -> DriveGains:
    """``found``'s relative gains scaled to a geometric mean of 1 over the motors ``over``:
    the motors it names are off, and the scale of those it leaves is the one to correct
    them to (a UR5's motor 2 read 0.81 at the mean of all six, 0.77 of the five others,
    the truth 0.769; a constant corrected by 0.81 was left 5 % off, "at the noise floor")."""
    mean = float(np.exp(np.mean(np.log(found.factor[over]))))
    spread = None if found.heldout_std is None else found.heldout_std / mean
    return dataclasses.replace(
        found, factor=found.factor / mean, cov=found.cov / mean**2, heldout_std=spread
    )


@dataclass(frozen=True, slots=True, eq=False)
class _Eigen:
    """The gains of the ``active`` motors fitted in-sample (:func:`drive_gains`), the
    others' efforts free columns beside the model's: ``g`` at the efforts' energy,
    ``factor`` and ``cov`` (m,) at the common scale (NaN on the motors left out),
    ``scaled`` as :func:`_common_scale` says, the model's columns and the free efforts
    fitted to the active efforts (``split``), the residual's degrees of freedom and its
    mean square per row with the gains fitted (``fitted``)."""

    g: NDArray[np.float64]
    factor: NDArray[np.float64]
    cov: NDArray[np.float64]
    scaled: bool
    split: _Split
    dof: int
    fitted: float

    @classmethod
    def of(
        cls,
        whole: _Rows,
        norms: NDArray[np.float64],
        B: NDArray[np.float64],
        C: NDArray[np.float64],
        active: NDArray[np.bool_],
        described: _Described | None,
    ) -> _Eigen:
        m = B.shape[1]
        p = whole.R.shape[1] - 2 * m
        split = whole.split(*_columns(p, active), norms)
        lam, V, g = _smallest(split.S, C[np.ix_(active, active)])
        a = int(active.sum())
        dof = whole.rows - split.rank - (a - 1)
        # per noisy row at g' C g = 1: the noise lies in the active motors' rows alone (a
        # simulated UR10's two of six: the variance over every row said 3 times too small)
        rows = (whole.rows - split.rank) * a / max(m, 1) - (a - 1)
        var = max(float(lam[0]), 0.0) / max(rows, 1.0)
        gap = np.maximum(lam[1:] - lam[0], 1e-300)
        cov_a = (V[:, 1:] / gap) @ V[:, 1:].T * var
        # the gains scaled so that the torques they give carry the logged efforts' energy
        c = float(np.linalg.norm(B[:, active] @ np.ones(int(active.sum()))))
        c /= max(float(np.linalg.norm(B[:, active] @ g)), 1e-300)
        g = g * c
        fitted = split.square(g) / max(dof, 1)
        full = np.full(m, np.nan)
        full[active] = g
        cov = np.full((m, m), np.nan)
        cov[np.ix_(active, active)] = _scaled_cov(full, cov_a * c**2, described)
        factor, scaled = _common_scale(full, described)
        return cls(g, factor, cov, scaled, split, dof, fitted)

    def sure(self) -> NDArray[np.bool_]:
        """The motors (m,) whose gain is fitted and determined in-sample (relative standard
        deviation of its ratios at most :data:`DETERMINED`, :attr:`DriveGains.std`): a
        gain the data leave loose (a wrist motor whose equation is nearly its own: 0.0 +-
        and 90 +- of a Panda's motors 6 and 7 beside joints 2 and 4 guessed 1.4 and 0.7
        times) is left out and the others fitted again, rather than its sign stopping the
        finding."""
        found = DriveGains(self.factor, self.cov, self.scaled, 1.0, 1.0)
        return np.isfinite(self.factor) & (found._ratio_min() <= DETERMINED * np.abs(self.factor))


def _scaled_cov(
    g: NDArray[np.float64], cov_g: NDArray[np.float64], described: _Described | None
) -> NDArray[np.float64]:
    """The covariance (a, a) of the fitted gains ``g`` (m,; NaN on the motors left out)
    at their common scale (:func:`_common_scale`), from ``cov_g`` (a, a) that of the
    active gains' direction at ``g``'s own scale: first order in ``f = g / s(g)`` with the
    description's scale ``s`` its own noise beside, ``J cov_g J' + f f' var(s) / s^2``
    (the two independent: the direction is read from the efforts' part outside the model's
    columns, the scale from the part inside); without a description's scale, ``cov_g``
    at the geometric mean's. The scale's own noise, read from one log's parameters fitted
    again, is the part a ratio's standard deviation misses (a simulated UR10's current
    log through its exact constants: motor 2's factor 0.0048 in-sample without it, 0.013
    over noise seeds)."""
    active = np.isfinite(g)
    ga = g[active]
    scale = None if described is None else _scale_of(g, described)
    if scale is None:
        factor, _ = _common_scale(g, described)
        return np.asarray(cov_g * (np.linalg.norm(factor[active]) / np.linalg.norm(ga)) ** 2)
    v = scale.value
    J = np.eye(ga.size) / v - np.outer(ga, scale.grad[active]) / v**2
    f = ga / v
    return np.asarray(J @ cov_g @ J.T + np.outer(f, f) * scale.var / v**2)


def _fold_labels(samples: int, folds: ArrayLike | None) -> NDArray[np.intp] | None:
    """The fold (N,) of each sample: ``folds`` as given, else contiguous time blocks
    (:func:`~dynid.identification.holdout.block_labels`); None for fewer than two folds
    or samples too few to cut."""
    from .holdout import DEFAULT_FOLDS, MIN_BLOCK_SAMPLES, block_labels

    if folds is not None:
        labels = np.asarray(folds, dtype=np.intp)
        return labels if np.unique(labels).size >= 2 else None
    if samples < DEFAULT_FOLDS * MIN_BLOCK_SAMPLES:
        return None
    return block_labels(samples, DEFAULT_FOLDS)


def _heldout(
    parts: list[_Rows],
    norms: NDArray[np.float64],
    C: NDArray[np.float64],
    active: NDArray[np.bool_],
    labels: NDArray[np.intp],
    described: _Described | None,
    whole: NDArray[np.float64],
) -> tuple[NDArray[np.float64], NDArray[np.float64], NDArray[np.float64]]:
    """Per motor, :attr:`DriveGains.heldout_gain`, :attr:`DriveGains.heldout_se` and
    :attr:`DriveGains.heldout_std` (the folds' gains at the scale of ``whole``, the gains
    fitted on every row: the description's, else the same geometric mean over the active
    motors; jackknife ``(K - 1) / K sum (g_f - mean g)^2`` over the ``K`` folds, widened by
    :func:`few_folds` for fewer than :data:`CALIBRATED_FOLDS`): on
    each fold, the gains (of the ``active`` motors; the others' efforts free columns beside
    the model's) and the parameters fitted on the other folds' rows (``parts``: each
    fold's rows factored, in the order of ``np.unique(labels)``), the fold's weighted
    residual's mean square with every gain as fitted and with motor ``k``'s held at 1 (the
    description's scale from ``described`` on the training rows, else the geometric mean),
    the parameters fitted again on the training rows."""
    m = active.size
    p = parts[0].R.shape[1] - 2 * m
    x, y = _columns(p, active)
    motors = np.flatnonzero(active)
    diffs: list[NDArray[np.float64]] = []
    gains: list[NDArray[np.float64]] = []
    for i, f in enumerate(np.unique(labels)):
        train = _Rows.stacked([q for j, q in enumerate(parts) if j != i])
        fold = train.split(x, y, norms)
        g = _smallest(fold.S, C[np.ix_(active, active)])[2]
        full = np.full(m, np.nan)
        full[active] = g
        factor, scaled = _common_scale(full, described, labels != f)
        if not np.all(factor[active] > 0):
            continue
        if not scaled:
            factor = factor * np.exp(np.mean(np.log(whole[active] / factor[active])))
        gains.append(factor)
        unit = g / factor[active]  # a gain of 1 at the scale of g, per motor (all equal)
        test = parts[i]
        base = test.mean_square(fold.residual(g))
        d = np.full(m, np.nan)
        for r, k in enumerate(motors):
            h = g.copy()
            h[r] = unit[r]
            d[k] = test.mean_square(fold.residual(h)) - base
        diffs.append(d)
    if len(diffs) < 2:
        return np.full(m, np.nan), np.full(m, np.nan), np.full(m, np.nan)
    D, F = np.asarray(diffs), np.asarray(gains)
    K = F.shape[0]
    spread = np.sqrt((K - 1) / K * np.sum((F - F.mean(axis=0)) ** 2, axis=0)) * few_folds(K)
    return np.mean(D, axis=0), np.std(D, axis=0, ddof=1) / np.sqrt(D.shape[0]), spread


def few_folds(folds: int) -> float:
    """The factor [-] that widens a jackknife spread over ``folds`` folds to the width it
    has at the same confidence from :data:`CALIBRATED_FOLDS` folds, the count the rules
    on the spread (:data:`SIGNIFICANT`, :data:`DETERMINED`) were set on: the ratio of
    Student's t quantiles at 97.5 % with ``folds - 1`` and ``CALIBRATED_FOLDS - 1`` degrees
    of freedom, 1 from that count on (a spread from 2 folds is half the distance between
    two values: 4.58 times; from 3 folds 1.55 times). Regression: a simulated TIAGo arm's
    wrist motor 6 through its exact torque constant read 0.56 +- 0.10 over two recordings
    (4.4 spreads from 1, a hair from being applied)."""
    if folds >= CALIBRATED_FOLDS:
        return 1.0
    import scipy.stats

    t = scipy.stats.t.ppf(0.975, [max(folds - 1, 1), CALIBRATED_FOLDS - 1])
    return float(t[0] / t[1])


def _smallest(
    S: NDArray[np.float64], C: NDArray[np.float64]
) -> tuple[NDArray[np.float64], NDArray[np.float64], NDArray[np.float64]]:
    """The generalized eigenvalues and eigenvectors of ``(S, C)`` (``V' C V = I``; ``S``
    the efforts' normal matrix with the model's columns projected out, :attr:`_Split.S`)
    and the gains: the eigenvector of the smallest, its sign making them sum positive."""
    import scipy.linalg  # here: the command's start loads no scipy

    lam, V = scipy.linalg.eigh(S, C)
    return lam, V, V[:, 0] * np.sign(np.sum(V[:, 0]))


@dataclass(frozen=True, slots=True, eq=False)
class _Rows:
    """Rows of the model's columns and the efforts, ``D = [A | B]`` (rows, k), held as the
    upper triangular factor ``R`` (k, k) of their QR ``D = Q R`` (``Q`` never formed):
    ``Q`` keeps norms, so a least-squares fit of some of ``D``'s columns to others is the
    same fit of those columns of ``R``, and the factor of several sets of rows is that of
    their factors stacked (tall-skinny QR, :func:`~dynid.identification.solvers.tall_r`;
    Demmel et al. 2012). One pass over each fold's rows serves every fit on them."""

    R: NDArray[np.float64]
    rows: int

    @classmethod
    def of(cls, A: NDArray[np.float64], B: NDArray[np.float64]) -> _Rows:
        """The factor of ``[A | B]`` (rows, k)."""
        return cls(_square(tall_r(A, np.ones(A.shape[1]), B)), A.shape[0])

    @classmethod
    def stacked(cls, parts: list[_Rows]) -> _Rows:
        """The factor of the rows of ``parts`` together."""
        if len(parts) == 1:
            return parts[0]
        R = np.vstack([q.R for q in parts])
        k = R.shape[1]
        R = _square(tall_r(R[:, : k - 1], np.ones(k - 1), R[:, k - 1]))
        return cls(R, sum(q.rows for q in parts))

    def split(self, x: NDArray[np.intp], y: NDArray[np.intp], norms: NDArray[np.float64]) -> _Split:
        """The columns ``x`` of ``D`` (scaled by ``norms[x]``) fitted to the columns ``y``:
        the pivoted QR of ``R[:, x] / norms[x]`` (the same factor and pivots as that of
        the rows themselves, :func:`~dynid.identification.solvers.tall_pivoted_qr`), its
        rank from the diagonal at relative tolerance :data:`_RANK_RTOL`."""
        import scipy.linalg

        Q, R, piv = scipy.linalg.qr(self.R[:, x] / norms[x], pivoting=True)
        d = np.abs(np.diag(R))
        r = int(np.count_nonzero(d > _RANK_RTOL * max(float(d[0]) if d.size else 0.0, 1e-300)))
        T = Q.T @ self.R[:, y]
        cols = x[piv[:r]]
        return _Split(R[:r, :r], cols, norms[cols], T[:r], T[r:], y, self.R.shape[1])

    def lstsq(
        self, x: NDArray[np.intp], y: NDArray[np.intp], h: NDArray[np.float64]
    ) -> NDArray[np.float64]:
        """The least-squares solution of least norm (SVD, ``np.linalg.lstsq``'s cut-off of
        the rows themselves) of the columns ``x`` of ``D`` fitted to ``D[:, y] @ h``."""
        rcond = np.finfo(np.float64).eps * max(self.rows, x.size)
        x_ls = np.linalg.lstsq(self.R[:, x], self.R[:, y] @ h, rcond=rcond)[0]
        return np.asarray(x_ls, dtype=np.float64)

    def mean_square(self, v: NDArray[np.float64]) -> float:
        """The mean square over the rows of ``D @ v``, ``v`` (k,)."""
        return float(np.sum((self.R @ v) ** 2)) / self.rows


def _square(R: NDArray[np.float64]) -> NDArray[np.float64]:
    """The factor ``R`` (r, k) of rows fewer than its columns (r < k) padded with zero rows
    to (k, k)."""
    k = R.shape[1]
    if R.shape[0] >= k:
        return R[:k]
    return np.vstack([R, np.zeros((k - R.shape[0], k))])


@dataclass(frozen=True, slots=True, eq=False)
class _Split:
    """Columns ``x`` of factored rows :class:`_Rows` fitted to columns ``y``: ``R`` (r, r)
    the triangular factor of the ``r`` independent columns ``cols`` (pivot order, scaled
    by ``norms``), ``T`` (r, q) the ``y`` columns in their orthonormal basis, ``rest``
    (k - r, q) the ``y`` columns' part outside it (the efforts with the model's columns
    projected out: ``rest' rest`` their normal matrix ``S``)."""

    R: NDArray[np.float64]
    cols: NDArray[np.intp]
    norms: NDArray[np.float64]
    T: NDArray[np.float64]
    rest: NDArray[np.float64]
    y: NDArray[np.intp]
    k: int

    @property
    def rank(self) -> int:
        """The rank of the ``x`` columns."""
        return int(self.R.shape[0])

    @property
    def S(self) -> NDArray[np.float64]:
        """The ``y`` columns' normal matrix (q, q) with the ``x`` columns projected out."""
        return self.rest.T @ self.rest

    def square(self, h: NDArray[np.float64]) -> float:
        """``h' S h``: the sum of squares of ``D[:, y] @ h`` less the ``x`` columns fitted."""
        return float(np.sum((self.rest @ h) ** 2))

    def residual(self, h: NDArray[np.float64]) -> NDArray[np.float64]:
        """The coefficients (k,) of ``D``'s columns that give ``D[:, y] @ h`` less the
        ``x`` columns fitted to it (the basic solution of the pivoted QR: the
        pseudo-inverse's fit where the ``x`` columns have full rank)."""
        import scipy.linalg

        v = np.zeros(self.k)
        v[self.y] = h
        if self.rank:
            v[self.cols] -= scipy.linalg.solve_triangular(self.R, self.T @ h) / self.norms
        return v


def _columns(p: int, active: NDArray[np.bool_]) -> tuple[NDArray[np.intp], NDArray[np.intp]]:
    """The columns of ``D = [A | B | B_hat]`` (``A``: ``p`` model columns, ``B`` the ``m``
    efforts, ``B_hat`` the same instrumented, :func:`_instrumented`) fitted, the model's
    and the instrumented efforts of the motors not ``active``, and those they are fitted
    to, the active motors' efforts. The efforts left out enter instrumented: as logged,
    their noise is noise in the regressors, which shrinks their coefficients and biases
    the parameters the active motors share (a simulated UR10's current log of 1 % noise
    through its exact constants, motors 1, 4, 5 and 6 left out: motor 2's gain 0.947 over
    noise seeds, 1.000 without noise)."""
    m = active.size
    x = np.concatenate([np.arange(p), p + m + np.flatnonzero(~active)])
    return x, p + np.flatnonzero(active)


def _fold_rows(
    A: NDArray[np.float64], B: NDArray[np.float64], rows: NDArray[np.intp]
) -> list[_Rows]:
    """Each fold's rows of ``[A | B]`` factored (the folds in increasing order; ``rows``
    the fold of each row)."""
    return [_Rows.of(A[rows == f], B[rows == f]) for f in np.unique(rows)]


def _held_ratios(
    factor: NDArray[np.float64],
    g: NDArray[np.float64],
    active: NDArray[np.bool_],
    split: _Split,
    dof: int,
) -> NDArray[np.float64]:
    """Per motor, the weighted residual's RMS over the noise with its gain held at 1
    (:attr:`DriveGains.ratio_held`): ``g`` the gains of the ``active`` motors at the
    scale of the efforts, ``factor`` at the description's, ``split`` the columns fitted
    again."""
    motors = np.flatnonzero(active)
    unit = float(g[0] / factor[motors[0]])  # a gain of 1 at the scale of g
    held = np.full(factor.size, np.nan)
    for i, k in enumerate(motors):
        h = g.copy()
        h[i] = unit
        held[k] = np.sqrt(split.square(h) / max(dof, 1))
    return held


def _linked(
    whole: _Rows, norms: NDArray[np.float64], C: NDArray[np.float64], samples: int
) -> NDArray[np.bool_]:
    """The motors (m,) whose effort keeps a part above the noise once the model's columns
    and the other left-out efforts are projected out (energy per row at least
    :data:`LINKED` of the noise's, ``C``'s diagonal): the others' gains their own columns
    take (left out one at a time, the weakest first)."""
    m = C.shape[0]
    p = whole.R.shape[1] - 2 * m
    active = np.ones(m, dtype=bool)
    while active.sum() > 2:
        split = whole.split(*_columns(p, active), norms)
        rows = samples * (1.0 - split.rank / whole.rows)  # the samples the projection leaves
        above = np.sum(split.rest**2, axis=0) / (rows * np.diag(C)[active]) - 1.0
        k = int(np.argmin(above))
        if above[k] >= LINKED:
            break
        active[np.flatnonzero(active)[k]] = False
    return active


def _noise_covariance(
    s: NDArray[np.float64], transmission: ArrayLike | None
) -> NDArray[np.float64]:
    """The covariance (m, m) the noise puts into one sample's effort columns, each joint's
    rows in units of its noise ``s`` (n,) [N m]: the identity on a joint-side log; on a
    motor-side log, each motor's noise ``sigma_m`` from ``s_j^2 = sum_m sigma_m^2 K_mj^2``
    (non-negative least squares), then ``sigma_m^2 sum_j K_mj^2 / s_j^2`` on the diagonal."""
    if transmission is None:
        return np.eye(s.size)
    K = np.asarray(transmission, dtype=np.float64)
    import scipy.optimize

    var, _ = scipy.optimize.nnls((K**2).T, s**2)
    diag = var * np.sum(K**2 / s**2, axis=1)
    return np.diag(np.maximum(diag, 1e-12 * max(float(diag.max()), 1e-300)))


@dataclass(frozen=True, slots=True, eq=False)
class _Described:
    """The rows the gains' common scale is read from (:func:`_common_scale`): ``A`` (N, n,
    p) the model's columns and ``B`` (N, n, m) the efforts per motor, each joint's rows in
    units of its noise, ``G`` (N, n, p) the model's columns at rest (the links' gravity
    alone) [N m per parameter unit], ``gd`` (N, n) the description's gravity torques
    [N m], zero on the joints gravity does not load, ``M`` (n, n, m) each joint's noise
    in units of its own through each motor's gain (``M[j, l, k]``: joint ``l``'s noise in
    joint ``j``'s effort per unit of motor ``k``'s gain: ``K^T diag(g) K^-T``, scaled)."""

    A: NDArray[np.float64]
    B: NDArray[np.float64]
    G: NDArray[np.float64]
    gd: NDArray[np.float64]
    M: NDArray[np.float64]

    @classmethod
    def of(
        cls,
        A: NDArray[np.float64],
        B: NDArray[np.float64],
        gravity_columns: ArrayLike | None,
        gravity: ArrayLike | None,
        noise: NDArray[np.float64],
        transmission: ArrayLike | None,
    ) -> _Described | None:
        """The rows, or None without the description's gravity."""
        if gravity_columns is None or gravity is None:
            return None
        G = np.asarray(gravity_columns, dtype=np.float64)
        n = noise.size
        K = np.eye(n) if transmission is None else np.asarray(transmission, dtype=np.float64)
        Kit = np.linalg.inv(K).T  # small (n, n): the motors' torques from the joints'
        M = K.T[:, None, :] * Kit.T[None, :, :] * (noise[None, :, None] / noise[:, None, None])
        return cls(A, B, G, np.asarray(gravity, dtype=np.float64), M)


@dataclass(frozen=True, slots=True, eq=False)
class _Scale:
    """The gains' common scale (:func:`_common_scale`) at gains ``g`` (m,): its ``value``,
    its gradient ``grad`` (m,) in the gains (zero on the motors left out) and ``var``, the
    variance the efforts' noise puts into it at ``g`` (the refit's parameters' own part,
    the noise of the rows the scale is read from)."""

    value: float
    grad: NDArray[np.float64]
    var: float


def _scale_of(
    g: NDArray[np.float64], described: _Described, samples: NDArray[np.bool_] | None = None
) -> _Scale | None:
    """The description's scale of the gains ``g`` (m, NaN on the motors left out): the
    parameters fitted to the efforts the gains weigh, ``x = X^+ B g`` at the ``samples``
    (N,) given (default all), their gravity torques over the description's, pooled over the
    loaded joints: ``a' x = w' B g`` with ``w = X^+' a``, linear in ``g`` and in the
    efforts' noise (each row's through :attr:`_Described.M`); None where the description's
    gravity torques and the fitted ones do not agree in sign."""
    fitted = np.isfinite(g)
    d = described
    at = slice(None) if samples is None else np.asarray(samples, dtype=bool)
    A, B = d.A[at], d.B[at]
    N, n, p = A.shape
    free = _instrumented(A, B[..., ~fitted])
    X = np.concatenate([A, free], axis=-1).reshape(N * n, -1)
    gd = d.gd[at]
    loaded = np.any(gd != 0, axis=0)
    dd = gd[:, loaded]
    norm = float(np.sum(dd * dd))
    if not norm > 0:
        return None
    a = np.zeros(X.shape[1])
    a[:p] = np.einsum("ij,ijk->k", dd, d.G[at][:, loaded]) / norm
    U, sv, Vt = np.linalg.svd(X, full_matrices=False)
    keep = sv > np.finfo(np.float64).eps * max(X.shape) * (sv[0] if sv.size else 0.0)
    w = U[:, keep] @ ((Vt[keep] @ a) / sv[keep])  # the rows' weights in the scale
    gz = np.where(fitted, g, 0.0)
    grad = np.where(fitted, w @ B.reshape(N * n, -1), 0.0)
    value = float(grad @ gz)
    if not value > 0:
        return None
    row_var = np.einsum("jlk,k->jl", d.M, gz) ** 2  # (n, n): joint l's noise in joint j
    var = float(np.sum(w.reshape(N, n) ** 2 * row_var.sum(axis=1)))
    return _Scale(value, grad, var)


def _common_scale(
    g: NDArray[np.float64],
    described: _Described | None,
    samples: NDArray[np.bool_] | None = None,
) -> tuple[NDArray[np.float64], bool]:
    """The gains ``g`` (m,) at the description's scale and True (:func:`_scale_of`);
    without a description's gravity, or where it does not agree in sign with the fitted
    parameters', at geometric mean 1 over the positive gains, and False. ``g`` is NaN on
    the motors left out, whose efforts are free columns beside the model's, each
    instrumented by the model's columns (:func:`_instrumented`)."""
    fitted = np.isfinite(g)
    if described is not None:
        scale = _scale_of(g, described, samples)
        if scale is not None:
            return g / scale.value, True
    pos = g[fitted & (np.nan_to_num(g) > 0)]
    mean = float(np.exp(np.mean(np.log(pos)))) if pos.size else 1.0
    return g / mean, False


def _instrumented(A: NDArray[np.float64], B: NDArray[np.float64]) -> NDArray[np.float64]:
    """The efforts ``B`` (N, n, f) of the motors left out, each joint's rows fitted by the
    model's columns ``A`` (N, n, p) on that joint (least squares, its own coefficients per
    joint): the part the motion explains, without the efforts' noise (two-stage least
    squares, the model's columns the instruments). Fitted as logged, their noise is noise
    in the regressors: the least squares shrinks their coefficients and the parameters
    take up the rest (a simulated 6-axis arm's current log of 1 % noise, motors 1 and 6
    left out, every constant exact: gains 0.937 to 0.945, std 0.002)."""
    out = np.zeros_like(B)
    rcond = np.finfo(np.float64).eps * max(A.shape[0], A.shape[-1])
    for j in range(A.shape[1]):
        reached = np.any(B[:, j] != 0, axis=0)
        if reached.any():
            c = np.linalg.lstsq(A[:, j], B[:, j][:, reached], rcond=rcond)[0]
            out[:, j, reached] = A[:, j] @ c
    return out
