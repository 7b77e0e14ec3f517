"""Friction that dissipates: identified friction laws checked within the velocity limits.

A friction torque opposes the motion: ``f(v) v >= 0`` at every velocity ``v`` the joint
(motor) reaches, the offset ``fo`` left aside (a constant torque, not friction of the
motion). Friction identified together with the links is a least-squares fit without
bounds, and a law with a term that grows faster than the others (``fq v |v|``) or a
Stribeck bump (``fsp``) can turn negative inside the limits: a model whose friction pushes
the arm. :func:`friction_violations` names every joint (motor) where it does, with its
coefficients below zero, for the structure selection to skip such a candidate and for
``identify`` to warn. Friction that pushes at every velocity (:attr:`Violation.everywhere`:
``fv6 = -0.14, fc6 = -0.30``) is the signature of a torque logged with the opposite sign on
that joint, when the data need it (:func:`reversed_sign_finding`): the sign flip that the
gravity check of :mod:`~dynid.identification.sanity` cannot see on a joint gravity does
not load.

The hint of that finding adds to the sign flips ``--units`` applied already, when given
(:class:`ReversedSignError`, :meth:`ReversedSignError.beside`): ``tau2=-1,...,tau5=-1``
applied and joints 1 and 6 found are every joint, told ``--units tau=-1``, as the sign
check of the torques against the model's tells every joint opposite.

The velocity limit of a motor is ``sum_j |K_mj| dq_max_j`` (``K`` the drive's friction
transmission, the identity at the joints); joints without a limit are not checked.
"""

from __future__ import annotations

import re
import warnings
from collections.abc import Callable, Mapping, Sequence
from dataclasses import dataclass
from typing import TYPE_CHECKING, Any

import numpy as np
from numpy.typing import ArrayLike, NDArray

from .._checks import caller_level
from ..exceptions import DataError, DynidWarning
from ..regressors.terms import PART_LABELS, LinearFriction, ModelTerm

if TYPE_CHECKING:
    from .model import IdentifiedModel
    from .structure import Structure

__all__ = [
    "GRID",
    "SIGNIFICANCE",
    "NegativeViscous",
    "ReversedSignError",
    "Violation",
    "friction_columns",
    "friction_violations",
    "negative_viscous",
    "power_violations",
    "reversed_sign_finding",
    "speed_limits",
    "warn_unphysical",
]

#: Velocities checked per joint (motor), evenly over ``[-v_max, v_max]``.
GRID = 401


#: Standard deviations by which each coefficient is moved towards zero before the check:
#: friction that pushes the arm only within the fit's uncertainty (a Coulomb level of
#: -0.002 N m on a joint without Coulomb friction) is not a violation.
SIGNIFICANCE = 3.0


@dataclass(frozen=True, slots=True)
class Violation:
    """Friction of one joint (motor) that is not dissipative within its velocity limit.

    Attributes
    ----------
    joint : int
        The joint (motor) index, from 0.
    place : str
        ``"joint"`` or ``"motor"``: where the friction acts.
    labels : tuple of str
        The coefficients below zero (every coefficient of the joint when none is), as
        ``--terms`` leaves them out (``fv6``).
    values : tuple of float
        Their values, moved towards zero by their uncertainty (:data:`SIGNIFICANCE`).
    speed : float
        The largest ``|v|`` [rad/s] where ``f(v) v < 0``.
    limit : float
        The joint's (motor's) velocity limit [rad/s].
    everywhere : bool
        ``f(v) v < 0`` at every velocity checked but 0: friction that puts energy in at
        every speed, as a torque of the opposite sign gives.
    """

    joint: int
    place: str
    labels: tuple[str, ...]
    values: tuple[float, ...]
    speed: float
    limit: float
    everywhere: bool

    @property
    def coefficients(self) -> str:
        """``"fv6 = -0.142, fc6 = -0.298"``."""
        return ", ".join(f"{k} = {x:.3g}" for k, x in zip(self.labels, self.values, strict=True))

    def __str__(self) -> str:
        """``"fq3 = -0.12 (joint 3: f(v) v < 0 at |v| = 2.1 rad/s, limit 2.18 rad/s)"``."""
        return (
            f"{self.coefficients} ({self.place} {self.joint + 1}: f(v) v < 0 at |v| = "
            f"{self.speed:.3g} rad/s, limit {self.limit:.3g} rad/s)"
        )


@dataclass(frozen=True, slots=True)
class NegativeViscous:
    """A viscous coefficient fitted below zero: friction that pushes in proportion to the
    velocity, not dissipative by itself (the law's other parts may still make the whole
    friction dissipative within the limits: :func:`friction_violations` judges that).

    Attributes
    ----------
    label : str
        The coefficient (``fv2``; ``jfv7`` at a joint beside the motors).
    value : float
        Its value [N m s/rad], below zero.
    std : float
        Its standard deviation [N m s/rad].
    """

    label: str
    value: float
    std: float

    @property
    def indistinguishable(self) -> bool:
        """Whether zero lies within :data:`SIGNIFICANCE` standard deviations of the
        value: indistinguishable from 0 (a true zero lies beyond one std on 32 % of the
        joints: a geared arm without joint viscous friction read "the friction law
        misfits" at 1.3 std)."""
        return abs(self.value) < SIGNIFICANCE * self.std

    @property
    def stds(self) -> float:
        """Standard deviations from zero (``inf`` for a std of 0)."""
        return abs(self.value) / self.std if self.std > 0 else float("inf")


def negative_viscous(
    labels: Sequence[str],
    values: NDArray[np.float64],
    std: NDArray[np.float64],
    kept: NDArray[np.bool_],
    prefix: str = "",
) -> tuple[NegativeViscous, ...]:
    """The viscous coefficients of one friction term fitted below zero (kept ones only).

    Parameters
    ----------
    labels : sequence of str
        The term's coefficient labels (``fv1, fc1, ...``; ``prefix`` before them).
    values, std : ndarray, shape (k,)
        Their values and standard deviations (``N m s/rad`` for a viscous one).
    kept : ndarray of bool, shape (k,)
        Whether each was fitted (False: left out or regrouped).
    prefix : str
        The term's label prefix (``"j"`` for friction at the joints beside the motors).

    Returns
    -------
    tuple of NegativeViscous
        In the order of ``labels``.
    """
    stem = prefix + PART_LABELS["viscous"]
    return tuple(
        NegativeViscous(lab, float(v), float(s))
        for lab, v, s, k in zip(labels, values, std, kept, strict=True)
        if k and lab.rstrip("0123456789") == stem and v < 0
    )


def friction_violations(
    terms: Sequence[tuple[LinearFriction, NDArray[np.float64]]],
    dq_max: NDArray[np.float64],
    std: Sequence[NDArray[np.float64]] | None = None,
) -> tuple[Violation, ...]:
    """Where identified friction is not dissipative within the velocity limits, beyond
    its uncertainty.

    Parameters
    ----------
    terms : sequence of (LinearFriction, ndarray)
        The friction terms of one model (acting at one place) with their coefficients
        (in the order of the term's ``labels``); their torques add up.
    dq_max : ndarray, shape (n,)
        Joint velocity limits [rad/s] (``inf``: none).
    std : sequence of ndarray, optional
        The coefficients' standard deviations, one array per term: each coefficient is
        moved :data:`SIGNIFICANCE` of them towards zero (not past it) before the check.

    Returns
    -------
    tuple of Violation
        One per joint (motor) where ``f(v) v < 0`` for some ``|v| <= v_max``; as text
        ``"fq3 = -0.12 (joint 3: f(v) v < 0 at |v| = 2.1 rad/s, limit 2.18 rad/s)"``,
        naming the coefficients below zero (else every coefficient of the joint).
    """
    if not terms:
        return ()
    drive = terms[0][0].drive
    n = drive.n
    parts: list[tuple[LinearFriction, int, str, float]] = []  # (term, joint, part, value)
    coefficients: list[dict[str, float]] = [{} for _ in range(n)]
    for k, (term, values) in enumerate(terms):
        every = [(j, p) for j in range(n) for p in term.parts]
        mask = term.mask or (True,) * len(every)
        held = [jp for jp, h in zip(every, mask, strict=True) if h]
        x_all = np.asarray(values, dtype=np.float64)
        if std is not None:
            shrink = SIGNIFICANCE * np.abs(np.asarray(std[k], dtype=np.float64))
            x_all = np.sign(x_all) * np.maximum(np.abs(x_all) - shrink, 0.0)
        for (j, p), x in zip(held, x_all, strict=True):
            if p == "offset" or x == 0.0:
                continue
            parts.append((term, j, p, float(x)))
            lab = f"{PART_LABELS[p]}{j + 1}"
            coefficients[j][lab] = coefficients[j].get(lab, 0.0) + float(x)

    def torques(v: NDArray[np.float64]) -> NDArray[np.float64]:
        f = np.zeros_like(v)
        cols = {id(t): t.part_columns(v) for t in {id(t): t for t, *_ in parts}.values()}
        for term, j, p, x in parts:
            f[:, j] += x * cols[id(term)][:, j, term.parts.index(p)]
        return f

    where = "motor" if drive.friction_place == "motor" else "joint"
    vmax = speed_limits(drive.friction_transmission, dq_max)
    return power_violations(torques, vmax, coefficients, where)


def speed_limits(transmission: ArrayLike, dq_max: ArrayLike) -> NDArray[np.float64]:
    """The velocity limit [rad/s] (n,) of each motor (joint) where friction acts:
    ``sum_j |K_mj| dq_max_j`` over the joints it moves (``K`` the friction transmission
    (n, n), the identity at the joints; ``dq_max`` (n,) the joint limits, ``inf``: none)."""
    K = np.abs(np.asarray(transmission, dtype=np.float64))
    n = K.shape[0]
    limit = np.broadcast_to(np.asarray(dq_max, dtype=np.float64), (n,))
    return np.array([float(np.sum(K[m, K[m] != 0] * limit[K[m] != 0])) for m in range(n)])


def power_violations(
    torques: Callable[[NDArray[np.float64]], NDArray[np.float64]],
    vmax: NDArray[np.float64],
    coefficients: Sequence[Mapping[str, float]],
    place: str = "joint",
) -> tuple[Violation, ...]:
    """Where friction ``f`` is not dissipative: ``f(v) v < 0`` at some ``|v| <= v_max``,
    on :data:`GRID` velocities per motor (joint) evenly over ``[-v_max, v_max]``; the one
    check of identified friction (:func:`friction_violations`) and of the laws
    ``dynid friction`` fits (:func:`~dynid.friction.dissipative.law_violations`).

    Parameters
    ----------
    torques : callable
        ``torques(v (s, n)) -> (s, n)``: the friction torques [N m] at the motor (joint)
        velocities ``v`` [rad/s], offsets (velocity-independent torques) left out.
    vmax : ndarray, shape (n,)
        Velocity limits [rad/s] (:func:`speed_limits`; not finite: not checked).
    coefficients : sequence of mapping
        Per motor (joint), its coefficients by label (``{"fc3": -2.97}``): a violation
        names those below zero, else all of them.
    place : str
        ``"joint"`` or ``"motor"``: where the friction acts.

    Returns
    -------
    tuple of Violation
        One per motor (joint) where the friction puts energy in.
    """
    vmax = np.asarray(vmax, dtype=np.float64)
    grid = np.linspace(-1.0, 1.0, GRID)
    v = grid[:, None] * np.where(np.isfinite(vmax), vmax, 0.0)[None, :]
    power = np.asarray(torques(v), dtype=np.float64) * v
    scale = np.max(np.abs(power), axis=0)
    out = []
    for j in range(vmax.shape[0]):
        if not np.isfinite(vmax[j]) or scale[j] == 0.0:
            continue
        bad = power[:, j] < -1e-9 * scale[j]
        if not bad.any():
            continue
        at = float(np.max(np.abs(v[bad, j])))
        neg = {k: x for k, x in coefficients[j].items() if x < 0} or dict(coefficients[j])
        everywhere = bool(np.all(bad[grid != 0.0]))
        out.append(
            Violation(j, place, tuple(neg), tuple(neg.values()), at, float(vmax[j]), everywhere)
        )
    return tuple(out)


def _named(v: Violation, names: Sequence[str]) -> str:
    return names[v.joint] if v.place == "joint" else f"motor {v.joint + 1}"


def reversed_sign_finding(
    violations: Sequence[Violation],
    names: Sequence[str],
    instead: Structure | None = None,
    coupled: frozenset[int] = frozenset(),
    applied: Sequence[int] | None = None,
    text: str | None = None,
) -> str | None:
    """The finding that the torques of some joints (motors) have the opposite sign to the
    model's, read from friction that puts energy in at every speed
    (:attr:`Violation.everywhere`), or None.

    Parameters
    ----------
    violations : sequence of Violation
        Of a fit whose held-out error needs that friction (the structure selection's
        best candidate, predicting better than any without it).
    names : sequence of str
        The joint names (a motor is named by its number).
    instead : Structure, optional
        The structure without that friction, for the user whose sign is right (a
        controller's compensation) to give with ``--terms``.
    coupled : frozenset of int
        The joints (motors) a drive couples to another: there the coupling's sign is
        named too (a coupling of the wrong sign left ``fv6 = -0.247`` on a wrist, and the
        hint to flip ``tau6`` came back after it was followed).
    applied : sequence of int, optional
        The joints (from 0) whose torque columns ``--units`` flipped already
        (``tau2=-1``): the hint gives the flips to read every column right, those and the
        ones found (``--units tau=-1`` in place of them when that is every joint); None
        when not known (the hint flips the joints found, beside whatever was given).
    text : str, optional
        The ``--units`` text given, which the hint beside ``applied`` is written into.
    """
    flipped = [v for v in violations if v.everywhere]
    if not flipped:
        return None
    which = ", ".join(_named(v, names) for v in flipped)
    its = "it" if len(flipped) == 1 else "them"
    linked = [v for v in flipped if v.joint in coupled]
    return (
        f"the friction identified on {which} puts energy into the arm at every velocity up "
        f"to the limit ({'; '.join(v.coefficients for v in flipped)}): the torque sign of "
        f"{which} is probably opposite to the model's (the check of the torques against "
        f"the model's does not tell it on a joint whose torques gravity and the links "
        f"barely make); hint: "
        + _flip_hint([v.joint for v in flipped], len(names), applied, its, text)
        + (
            f"; or the drive's coupling of {', '.join(_named(v, names) for v in linked)} has "
            "the wrong sign (a flipped column there makes the coupled one push instead)"
            if linked
            else ""
        )
        + (
            ""
            if instead is None
            else "; if the sign is right (a controller's compensation), --terms "
            f"{','.join(instead.terms) or 'links'} fits without that friction"
        )
    )


def _flip_hint(
    found: Sequence[int],
    n: int,
    applied: Sequence[int] | None,
    its: str,
    text: str | None = None,
) -> str:
    """The ``--units`` of :func:`reversed_sign_finding`'s hint: the joints ``found`` (from
    0) flipped beside the flips ``applied`` (a joint in both read as it is), ``tau=-1``
    when that is every one of the ``n`` joints; written into the ``--units`` text given,
    ``text``, when known (the whole option to run again)."""
    entries = ",".join(f"tau{j + 1}=-1" for j in found)
    if applied is None or not applied:
        return f"--units {entries} reads {its} flipped (beside the torques' unit, if one is given)"
    given = ",".join(f"tau{j + 1}=-1" for j in sorted(applied))
    every = sorted(set(applied) ^ set(found))
    now = "tau=-1" if every == list(range(n)) else ",".join(f"tau{j + 1}=-1" for j in every)
    if text is not None:
        kept = [e.strip() for e in text.split(",") if e.strip()]
        kept = [e for e in kept if not re.fullmatch(r"tau\d+", e.partition("=")[0].strip())]
        option = ",".join([*kept, *([now] if now else [])])
    else:
        option = now or "without the tau flips"
    if now == "tau=-1":
        return (
            f"--units {option} (tau=-1 in place of {given}: with {entries} every joint's "
            "torque reads flipped)"
        )
    return f"--units {option} ({now or 'no flip'} in place of {given}: {entries} flipped too)"


class ReversedSignError(DataError):
    """:func:`reversed_sign_finding` raised, with what says it again beside the sign
    flips ``--units`` applied (:meth:`beside`), which the fit does not know."""

    def __init__(
        self,
        violations: Sequence[Violation],
        names: Sequence[str],
        instead: Structure | None = None,
        coupled: frozenset[int] = frozenset(),
    ) -> None:
        self.violations, self.names = tuple(violations), tuple(names)
        self.instead, self.coupled = instead, coupled
        super().__init__(reversed_sign_finding(violations, names, instead, coupled))

    def beside(self, applied: Sequence[int], text: str | None = None) -> DataError:
        """The same finding, its hint given the joints (from 0) ``--units`` flipped and
        the ``--units`` text given (``text``, when known)."""
        said = reversed_sign_finding(
            self.violations, self.names, self.instead, self.coupled, applied, text
        )
        return DataError(said)


def friction_columns(
    terms: Sequence[tuple[ModelTerm, Any]] | Sequence[ModelTerm], r: int
) -> list[tuple[LinearFriction, slice]]:
    """The friction terms among ``terms`` (those not in the base, appended after the
    ``r`` base parameters in order) with their columns."""
    out, k = [], r
    for item in terms:
        t = item[0] if isinstance(item, tuple) else item
        if t.in_base:
            continue
        m = len(t.labels)
        if isinstance(t, LinearFriction):
            out.append((t, slice(k, k + m)))
        k += m
    return out


def warn_unphysical(model: IdentifiedModel, terms: Sequence[ModelTerm]) -> None:
    """A warning, one line per joint (motor), where the identified friction is not
    dissipative within the robot's velocity limits."""
    fit = model.joint_fit
    if fit is None:
        return
    beta = np.where(np.asarray(fit.kept, dtype=bool), np.asarray(fit.beta, dtype=float), 0.0)
    sd = np.nan_to_num(np.asarray(fit.std, dtype=float))
    columns = friction_columns(terms, model.base.rank)
    terms_x = [(t, beta[sl]) for t, sl in columns]
    for v in friction_violations(terms_x, model.robot.dq_max, [sd[sl] for _, sl in columns]):
        sign = (
            f"; friction that pushes at every speed is what a torque of the opposite sign "
            f"gives: check the sign of tau{v.joint + 1}"
            if v.everywhere
            else ""
        )
        warnings.warn(
            f"identified friction not dissipative within the velocity limits: {v}; "
            "the friction pushes the arm there (--terms without that part, or with "
            f"the part left out on that joint: -LABEL){sign}",
            DynidWarning,
            stacklevel=caller_level(),
        )
