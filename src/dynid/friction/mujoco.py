"""The sigmoid friction approximated by what MuJoCo's joints hold: Coulomb and viscous.

MuJoCo joints carry a symmetric dry friction ``frictionloss`` [N m] (a constraint, so
the friction torque lies in ``[-f_c, f_c]`` at rest) and a viscous ``damping``
[N m s/rad]. The sigmoid of Gaz et al. 2019 (eq. 25, :mod:`dynid.friction.model`) is
neither: it saturates at ``phi1 (1 - s0)`` for large positive velocities and at
``-phi1 s0`` for large negative ones, ``s0 = 1 / (1 + exp(-phi2 phi3))``. The
approximation keeps its odd part,

.. math:: \\tau_{odd}(\\dot q) = (\\tau_f(\\dot q) - \\tau_f(-\\dot q)) / 2
          \\approx f_c \\, \\mathrm{sign}(\\dot q) + f_v \\dot q,

fitted by non-negative least squares on ``n_points`` velocities spread evenly over
``(0, dq_max]``. The even part (the offset ``phi1 (1/2 - s0)`` at large speeds and the
sigmoid's curvature) has no MuJoCo counterpart and is returned as ``offset`` (the
velocity-independent torque [N m] dropped at large speeds) so that callers can report it.
"""

from __future__ import annotations

from dataclasses import dataclass, replace

import numpy as np
from numpy.typing import ArrayLike, NDArray

from .. import _checks
from ..exceptions import ShapeError
from .laws.base import MjcfTerms, odd_coulomb_viscous
from .laws.sigmoid import odd_part
from .model import FrictionModel, FrictionSum, friction_parts

__all__ = [
    "CoulombViscous",
    "DriveJointTerms",
    "coupled_coulomb_left_out",
    "coulomb_viscous_from_sigmoid",
    "drive_joint_terms",
    "joint_coulomb_viscous",
    "joint_rms_difference",
    "law_velocity_range",
    "unheld_friction",
]


@dataclass(frozen=True, slots=True)
class CoulombViscous:
    """Per-joint Coulomb and viscous friction fitted to a sigmoid.

    Attributes
    ----------
    coulomb : ndarray, shape (n,)
        Dry friction ``f_c`` [N m] (MuJoCo ``frictionloss``).
    viscous : ndarray, shape (n,)
        Viscous coefficient ``f_v`` [N m s/rad] (MuJoCo ``damping``).
    offset : ndarray, shape (n,)
        Even part of the sigmoid at ``dq_max``, ``(tau_f(dq_max) + tau_f(-dq_max)) / 2``
        [N m]: what the approximation drops.
    rms_error : ndarray, shape (n,)
        RMS difference between the odd part of the sigmoid and the fit over the grid [N m].
    dq_max : ndarray, shape (n,)
        Upper end of the velocity grid [rad/s].
    """

    coulomb: NDArray[np.float64]
    viscous: NDArray[np.float64]
    offset: NDArray[np.float64]
    rms_error: NDArray[np.float64]
    dq_max: NDArray[np.float64]


def coulomb_viscous_from_sigmoid(
    friction: ArrayLike, dq_max: ArrayLike, *, n_points: int = 200
) -> CoulombViscous:
    """Fit ``f_c sign(dq) + f_v dq`` to the odd part of sigmoid friction, per joint.

    Parameters
    ----------
    friction : array_like, shape (n, 3)
        Sigmoid parameters ``phi1 [N m], phi2 [s/rad], phi3 [rad/s]`` per joint.
    dq_max : array_like, shape (n,)
        Velocity range of the fit [rad/s] per joint; non-finite entries use 2 rad/s.
    n_points : int
        Grid points per joint in ``(0, dq_max]``.

    Returns
    -------
    CoulombViscous
        ``coulomb >= 0`` and ``viscous >= 0`` (non-negative least squares).

    Raises
    ------
    ShapeError
        ``friction`` is not (n, 3) or ``dq_max`` not (n,).
    """
    f = _checks.as_array("friction", friction)
    if f.ndim != 2 or f.shape[1] != 3:
        raise ShapeError(f"friction must have shape (n, 3); got {f.shape}")
    n = f.shape[0]
    vmax = _checks.as_exact("dq_max", dq_max, (n,), allow_nonfinite=True)
    vmax = np.where(np.isfinite(vmax) & (vmax > 0), vmax, 2.0)
    coulomb, viscous, offset, rms = odd_part(f, vmax, n_points)
    return CoulombViscous(coulomb, viscous, offset, rms, vmax)


@dataclass(frozen=True, slots=True)
class DriveJointTerms:
    """What MuJoCo's joints can hold of a drive train: per-joint diagonal terms.

    Attributes
    ----------
    armature : ndarray, shape (n,)
        ``diag(K^T diag(I_a) K)`` [kg m^2]: the rotors' inertia reflected to each joint.
    damping : ndarray, shape (n,)
        ``diag(K^T diag(f_v) K)`` [N m s/rad] of friction at the motors (``f_v`` itself at
        the joints).
    frictionloss : ndarray, shape (n,)
        ``|K_jj| f_c,j`` [N m]: each joint's own motor's Coulomb friction.
    notes : tuple of str
        What MuJoCo cannot express and is dropped (a coupled rotor's off-diagonal inertia,
        coupled friction, an asymmetry), one line each.
    offset : ndarray, shape (n,), or None
        The friction law's velocity-independent torque [N m] per joint (per motor at the
        motors), which MJCF cannot hold either; None when not computed.
    """

    armature: NDArray[np.float64]
    damping: NDArray[np.float64]
    frictionloss: NDArray[np.float64]
    notes: tuple[str, ...] = ()
    offset: NDArray[np.float64] | None = None


def drive_joint_terms(
    K: NDArray[np.float64],
    rotor_inertia: NDArray[np.float64] | None,
    fv: NDArray[np.float64] | None,
    fc: NDArray[np.float64] | None,
    *,
    friction_at_motor: bool = True,
) -> DriveJointTerms:
    """MuJoCo's joint terms (armature, damping, frictionloss) of a drive train.

    ``K`` (n, n) is the transmission (:mod:`dynid.model.drive`); ``rotor_inertia`` (n,)
    [kg m^2] at the motors; ``fv`` [N m s/rad], ``fc`` [N m] per motor (per joint when
    ``friction_at_motor`` is False). The reflected inertia ``K^T diag(I_a) K`` and viscous
    friction ``K^T diag(f_v) K`` are exact on the diagonal; their off-diagonal parts (a
    coupled wrist) and the coupled Coulomb terms have no MuJoCo counterpart and are named
    in ``notes``.
    """
    n = K.shape[0]
    Kf = K if friction_at_motor else np.eye(n)
    notes: list[str] = []

    def reflected(
        d: NDArray[np.float64], T: NDArray[np.float64], what: str, unit: str
    ) -> NDArray[np.float64]:
        A = T.T @ (d[:, None] * T)
        off = A - np.diag(np.diag(A))
        if np.any(np.abs(off) > 1e-12 * max(float(np.abs(A).max()), 1e-300)):
            i, j = np.unravel_index(int(np.argmax(np.abs(off))), off.shape)
            notes.append(
                f"{what}: the coupling's off-diagonal terms have no per-joint term and are "
                f"dropped (largest: joints {i + 1}-{j + 1}, {A[i, j]:.4g} {unit})"
            )
        return np.diag(A).copy()

    z = np.zeros(n)
    arm = (
        z
        if rotor_inertia is None
        else reflected(np.asarray(rotor_inertia), K, "armature", "kg m^2")
    )
    damp = (
        z
        if fv is None
        else reflected(np.asarray(fv), Kf, "viscous friction (damping)", "N m s/rad")
    )
    loss = z
    if fc is not None:
        fcv = np.asarray(fc)
        loss = np.abs(np.diag(Kf)) * fcv
        left = coupled_coulomb_left_out(Kf, fcv)
        if np.any(left > 0):
            notes.append(_coupled_coulomb_note(Kf, left))
    return DriveJointTerms(arm, damp, loss, tuple(notes))


def coupled_coulomb_left_out(K: ArrayLike, fc: ArrayLike) -> NDArray[np.float64]:
    """The largest joint torque [N m] (n,) that per-joint Coulomb friction leaves out of
    Coulomb friction at the motors of a coupled drive, at any joint velocities.

    Motor ``m`` turns at ``(K dq)_m`` and its friction ``fc_m sign((K dq)_m)`` acts on the
    joints through ``K^T``: joint ``j`` feels ``sum_m K_mj fc_m sign((K dq)_m)``. A file's
    joint holds ``|K_jj| fc_j sign(dq_j)``, its own motor's friction with the sign of its
    own velocity. Left out, at most

    .. math:: \\sum_{m \\ne j} |K_{mj}| f_{c,m} + 2 |K_{jj}| f_{c,j} [\\text{motor } j
              \\text{ turned by another joint}],

    the other motors' friction, and the own motor's counted twice where its sign follows
    other joints too (a slow joint ``j`` while a coupled joint turns its motor the other
    way). The bound is reached when the signs can be set independently (one coupled motor,
    as a wrist's: any joint velocity limits reach it, joint ``j`` slow enough); zero on a
    diagonal ``K``.

    Parameters
    ----------
    K : array_like, shape (n, n)
        Motor velocities per joint velocity where the friction acts.
    fc : array_like, shape (n,)
        Coulomb friction per motor [N m] (its magnitude is used).

    Returns
    -------
    ndarray, shape (n,)
    """
    T = np.asarray(K, dtype=np.float64)
    f = np.abs(np.asarray(fc, dtype=np.float64))
    own = np.abs(np.diag(T)) * f
    other = np.abs(T).T @ f - own
    turned = np.any((T - np.diag(np.diag(T))) != 0, axis=1)  # motor j follows other joints
    return np.asarray(other + 2.0 * own * turned, dtype=np.float64)


def _coupled_coulomb_note(K: NDArray[np.float64], left: NDArray[np.float64]) -> str:
    """The line naming the joints where :func:`coupled_coulomb_left_out` is not zero,
    largest first, and the coupled motors' velocities their friction's sign follows."""

    def velocity(m: int) -> str:
        terms = [
            f"{'-' if K[m, k] < 0 else '+'} {abs(K[m, k]):.4g} dq{k + 1}"
            for k in np.flatnonzero(K[m])
        ]
        first = terms[0][2:] if terms[0][0] == "+" else "-" + terms[0][2:]
        return f"motor {m + 1} turning at {' '.join([first, *terms[1:]])}"

    coupled = np.flatnonzero(np.any((K - np.diag(np.diag(K))) != 0, axis=1))
    order = [int(j) for j in np.argsort(-left, kind="stable") if left[j] > 0]
    where = ", ".join(f"{left[j]:.4g} N m at joint {j + 1}" for j in order)
    motors = " and ".join(velocity(int(m)) for m in coupled)
    return (
        "Coulomb friction of coupled motors has no per-joint term in URDF or MJCF (a motor's "
        f"follows the sign of the motor's velocity, {motors}, "
        "and a joint holds its own motor's with the sign of the joint's velocity, "
        f"|K_jj| fc_j sign(dq_j)) and is left out up to {where}"
    )


def joint_coulomb_viscous(
    friction: FrictionModel | FrictionSum, dq_max: ArrayLike | None = None, *, sharp: bool = True
) -> DriveJointTerms:
    """Per-joint Coulomb (``frictionloss``, URDF ``friction``) and viscous (``damping``)
    coefficients of a friction model, at the joints or reflected from the motors of a drive
    (:func:`drive_joint_terms`).

    Each law of the registry maps itself (:attr:`~dynid.friction.laws.base.FrictionLaw.mjcf`:
    the classical law's ``fv`` and ``fc``, the asymmetric law's means, ...) over the
    velocities where it acts (:func:`law_velocity_range`: a law at the motors of a drive over
    the motors' range, ``sum_j |K_mj| dq_max_j``); what MJCF cannot hold (an offset, an
    asymmetry, a Stribeck peak, coupled terms) is named in ``notes``, a law approximated
    with the RMS difference at the joints (:func:`joint_rms_difference`).

    Parameters
    ----------
    friction : FrictionModel
    dq_max : array_like, shape (n,), optional
        Velocity range of the joints [rad/s] (default 2 rad/s).
    sharp : bool
        True (URDF): the Coulomb term is a sharp ``sign(dq)``, and a smooth law's
        ``fc tanh(dq / width)`` is refitted as viscous and sharp Coulomb friction. False
        (MJCF, whose ``frictionloss`` is a ramp of a slope the file sets,
        :mod:`dynid.friction.mujoco_soft`): the smooth law's ``fv`` and ``fc`` as they are;
        only negative terms are refitted.

    Returns
    -------
    DriveJointTerms
        Of a :class:`~dynid.friction.model.FrictionSum`: the sum of its parts' (each
        reflected from where it acts).
    """
    if isinstance(friction, FrictionSum):
        each = [joint_coulomb_viscous(p, dq_max, sharp=sharp) for p in friction.parts]
        z = np.zeros(friction.n)
        return DriveJointTerms(
            np.sum([t.armature for t in each], axis=0),
            np.sum([t.damping for t in each], axis=0),
            np.sum([t.frictionloss for t in each], axis=0),
            tuple(x for t in each for x in t.notes),
            np.sum([z if t.offset is None else t.offset for t in each], axis=0),
        )
    n = friction.n
    vmax = np.full(n, 2.0) if dq_max is None else _checks.as_exact("dq_max", dq_max, (n,))
    vlaw = law_velocity_range(friction, vmax)
    terms = friction.law.mjcf(friction.as_array(), vlaw)
    notes = (f"{friction.kind} friction: {terms.dropped} has no per-joint term",) * bool(
        terms.dropped
    )
    terms, negative, refit = _dissipative(friction, terms, vlaw, sharp)
    z = np.zeros(n)
    jt = DriveJointTerms(z, terms.damping, terms.frictionloss, (), terms.offset)
    if friction.drive is not None:
        d = friction.drive
        jt = replace(
            drive_joint_terms(
                d.transmission,
                None,
                terms.damping,
                terms.frictionloss,
                friction_at_motor=d.friction_place == "motor",
            ),
            offset=terms.offset,
        )
    if refit.size:
        notes += _refit_note(friction, jt, terms, vmax, negative, refit)
    return replace(jt, notes=notes + jt.notes)


def law_velocity_range(friction: FrictionModel, dq_max: ArrayLike) -> NDArray[np.float64]:
    """The velocities [rad/s] (n,) up to which a law acts where it is placed: the joints'
    ``dq_max`` (n,) at the joints, ``sum_j |K_mj| dq_max_j`` at motor ``m`` of a drive
    (the rule of the dissipation check,
    :meth:`~dynid.regressors.terms.LinearFriction.dissipation_rows`)."""
    limit = np.asarray(dq_max, dtype=np.float64)
    return np.asarray(np.abs(friction.transmission) @ limit, dtype=np.float64)


def joint_rms_difference(
    friction: FrictionModel | FrictionSum,
    damping: ArrayLike,
    frictionloss: ArrayLike,
    dq_max: ArrayLike,
    n_points: int = 200,
) -> NDArray[np.float64]:
    """RMS difference [N m] (n,) at each joint between the odd part of the model's joint
    friction torque, ``(tau_f(dq) - tau_f(-dq)) / 2`` with that joint moving alone (a law
    at the motors reflected through its drive, ``K^T f(K dq)``), and the written
    ``frictionloss_j sign(dq_j) + damping_j dq_j``, on ``n_points`` velocities spread evenly
    over ``(0, dq_max_j]`` [rad/s]: what a joint of a URDF or MJCF file misses of the law."""
    n = friction.n
    fv = np.asarray(damping, dtype=np.float64)
    fc = np.asarray(frictionloss, dtype=np.float64)
    vmax = np.asarray(dq_max, dtype=np.float64)
    rms = np.zeros(n)
    for j in range(n):
        v = np.linspace(vmax[j] / n_points, vmax[j], n_points)
        grid = np.zeros((n_points, n))
        grid[:, j] = v
        odd = 0.5 * (friction.torques(grid)[:, j] - friction.torques(-grid)[:, j])
        rms[j] = float(np.sqrt(np.mean((fc[j] + fv[j] * v - odd) ** 2)))
    return rms


#: RMS difference at a joint [N m] over its velocity range below which the viscous and
#: Coulomb terms written for a smooth law hold it to round-off (a width of 0.0003 rad/s:
#: 2e-10 N m), no note of its own: the rounding over the standstill band is said once, by
#: :func:`unheld_friction`.
ROUND_OFF_NM = 1e-6


def _dissipative(
    friction: FrictionModel, terms: MjcfTerms, vlaw: NDArray[np.float64], sharp: bool = True
) -> tuple[MjcfTerms, NDArray[np.intp], NDArray[np.intp]]:
    """``terms`` with every motor (joint) whose ``damping`` or ``frictionloss`` came out
    negative (a law identified with the links whose viscous part is negative beside a
    larger smooth Coulomb part: dissipative as a whole, not term by term), and every one of
    a smooth-sign law, replaced by the nonnegative ``fv dq + fc sign(dq)`` closest to the
    law's odd part over ``(0, vlaw]``, the velocities where the law acts
    (:func:`~dynid.friction.laws.base.odd_coulomb_viscous`; the smooth-sign laws only when
    ``sharp``, the Coulomb term written as a sharp sign); with the motors (joints)
    negative and those replaced. MuJoCo and URDF readers take a negative damping as a
    joint that pushes."""
    negative = (terms.damping < 0) | (terms.frictionloss < 0)
    # a smooth sign's rounding (tanh over a width) written as the sharp sign would cost
    # every reversal: its odd part is fitted as the sigmoid's is
    P = friction.as_array()
    band = np.asarray(friction.band, dtype=np.float64)
    band = band if band.size == P.shape[0] else np.zeros(P.shape[0])
    smooth = (band > 0) & (friction.kind in ("smooth", "smooth_stribeck")) & sharp
    bad = np.flatnonzero(negative | smooth)
    damping, loss = terms.damping.copy(), terms.frictionloss.copy()
    for m in bad:

        def torque(v: NDArray[np.float64], m: int = int(m)) -> NDArray[np.float64]:
            grid = np.zeros((v.size, P.shape[0]))
            grid[:, m] = v
            return friction.law.torques(grid, P, band)[:, m]

        top = float(vlaw[m]) if np.isfinite(vlaw[m]) else 2.0
        loss[m], damping[m], _, _ = odd_coulomb_viscous(torque, top)
    replaced = replace(terms, damping=damping, frictionloss=loss)
    return replaced, np.flatnonzero(negative), bad


def _refit_note(
    friction: FrictionModel,
    written: DriveJointTerms,
    motor: MjcfTerms,
    vmax: NDArray[np.float64],
    negative: NDArray[np.intp],
    refit: NDArray[np.intp],
) -> tuple[str, ...]:
    """The line saying that the law of the motors (joints) ``refit`` (per motor as
    ``motor`` holds it, reflected to the joints as ``written``) was written as the
    closest nonnegative viscous and Coulomb friction, with the largest RMS difference at
    the joints they turn (:func:`joint_rms_difference`, joint-side torques over the
    joints' range ``vmax``; of a coupled drive, each joint's own motor's law alone, the
    coupling being said by :func:`drive_joint_terms`); none for a narrow smooth law held
    to round-off (its rounding is said by :func:`unheld_friction`)."""
    turned = np.any(friction.transmission[refit] != 0, axis=0)
    own, damping, loss = friction, written.damping, written.frictionloss
    T = friction.transmission
    if friction.drive is not None and np.any(T != np.diag(np.diag(T))):
        # each joint against its own motor's law; the coupling is said by drive_joint_terms
        d = np.diag(T)
        own = friction.at(replace(friction.drive, transmission=np.diag(d)))
        damping, loss = d**2 * motor.damping, np.abs(d) * motor.frictionloss
    rms = joint_rms_difference(own, damping, loss, vmax)
    rms = np.where(turned, rms, 0.0)
    j = int(np.argmax(rms))
    if not negative.size and rms[j] < ROUND_OFF_NM:
        return ()
    where = ", ".join(str(m + 1) for m in negative)
    said = f" (a negative viscous or Coulomb term on {where})" if where else ""
    return (
        f"{friction.kind} friction{said}: written as the nonnegative viscous and Coulomb "
        f"friction closest to the law over the velocity range (RMS difference at the "
        f"joints up to {rms[j]:.3g} N m, at joint {j + 1} moving alone)",
    )


def unheld_friction(
    friction: FrictionModel | FrictionSum,
    dq_max: ArrayLike | None = None,
    offset_held: NDArray[np.bool_] | None = None,
    *,
    sharp: bool = True,
) -> tuple[str, ...]:
    """What per-joint viscous and sharp Coulomb friction (MJCF ``damping`` and
    ``frictionloss``, URDF ``<dynamics damping friction>``) cannot hold of a friction
    model beyond the law's own losses (:func:`joint_coulomb_viscous`'s ``notes``), one
    line each: the smooth law's ``tanh(dq / width)`` rounding, a standstill band, the
    offsets ``fo`` [N m], and that the friction acts at the motors (written reflected to
    the joints). Empty when the coefficients hold the model exactly. ``offset_held`` (n,):
    the joints whose offset the file holds otherwise (a joint spring's reference, MJCF's
    ``springref``), left out of the offsets' line. ``sharp=False``: the file holds the
    smooth law's rounding as its dry friction's slope (MJCF,
    :mod:`dynid.friction.mujoco_soft`), not named here.
    """
    notes: list[str] = []
    for p in friction_parts(friction):
        if p.kind == "none":
            continue
        what = "motor" if p.at_motors else "joint"
        where = " at the motors" if p.at_motors else ""
        band = np.asarray(p.band)
        if np.any(band > 0):
            j = int(np.argmax(band))
            if p.kind in ("smooth", "smooth_stribeck"):
                if sharp:
                    notes.append(
                        f"the {p.kind} law's rounding fc tanh(dq / width){where} (the smooth "
                        f"sign's width up to {band[j]:.3g} rad/s at {what} {j + 1}; written "
                        "as plain Coulomb friction)"
                    )
            else:
                notes.append(
                    f"the standstill band{where} (no Coulomb friction for |dq| up to "
                    f"{band[j]:.3g} rad/s at {what} {j + 1})"
                )
        vmax = np.full(p.n, 2.0) if dq_max is None else np.asarray(dq_max, dtype=np.float64)
        offset = np.asarray(p.law.mjcf(p.as_array(), law_velocity_range(p, vmax)).offset)
        if offset_held is not None and not p.at_motors:
            offset = np.where(offset_held, 0.0, offset)
        if p.kind != "sigmoid" and np.any(offset != 0):  # the sigmoid's: its law's note
            j = int(np.argmax(np.abs(offset)))
            notes.append(f"the offsets fo{where} (up to {offset[j]:+.3g} N m at {what} {j + 1})")
        if p.at_motors:
            notes.append("friction at the motors (written reflected to the joints)")
    return tuple(notes)
