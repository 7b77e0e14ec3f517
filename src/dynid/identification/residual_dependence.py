"""What a systematic residual depends on: its joint's position or its velocity.

A joint whose prediction errs more than :data:`~dynid.identification.verdict.SYSTEMATIC_RATIO`
times its noise holds an effect the model lacks. Where that effect is a smooth function of
the joint's own position (a gravity-compensation spring, a cable, a counterbalance) or of
its own velocity (friction the law misses), the mean residual in bins of that coordinate
shows it without a refit: over ``B`` bins of equal counts, the binned means' RMS about the
overall mean is the part of the residual that follows the coordinate, less the noise the
means keep (``(B - 1) sigma^2 / N`` of its square, ``sigma`` the joint's noise, ``N`` the
samples). The larger of the two parts, against the residual's RMS, is the diagnosis
(:func:`residual_dependence`); :func:`dependence_hint` says it in one line per joint, and
:func:`outside_model_note` why a consistent fit that least squares' residual pulls predicts
worse. The same two parts decide whether a stiffness fitted beside the model's columns
(:func:`~dynid.identification.residual_spring.residual_spring`) may be called a spring
(:func:`judged_springs`, which ``identify``'s held-out verdict and ``validate`` both use):
only where the residual follows the joint's position at least as much as its velocity.

A Panda whose model lacks the Stribeck bump of joints 2 and 4, judged on a recording the
fit did not see: joint 4's residual, 0.18 N m RMS, follows its velocity (0.091 N m) more than
its position (0.053 N m), and the 0.37 N m/rad stiffness fitted beside the model's columns
(13 standard deviations clear) is not called a spring; joint 2's likewise (0.086 against
0.033 N m, 1.17 N m/rad).

A Baxter shoulder with a spring of 30 N m/rad the rigid-body model lacks: 0.74 N m RMS
held-out residual against 0.30 N m noise, of which the binned position explains most and
the velocity little.
"""

from __future__ import annotations

from collections.abc import Collection, Mapping, Sequence
from dataclasses import dataclass, replace
from typing import TYPE_CHECKING

import numpy as np
from numpy.typing import NDArray

from ..model.robot import Robot
from ..model.units import joint_unit
from ..regressors.terms import PART_LABELS, LinearFriction
from .gravity_tilt import GravityTilt
from .recording_level import level_clause
from .residual_spring import ResidualSpring
from .rests import MIN_REST_S, lasting_rests
from .velocity_noise import MIN_MOTION, noise_band, velocity_noise_std
from .verdict import ROUND_OFF_PERCENT, SYSTEMATIC_RATIO, Verdict, with_hint

if TYPE_CHECKING:
    from .model import IdentifiedModel

__all__ = [
    "BINS",
    "acceleration_led",
    "at_rests",
    "at_standstill",
    "cannot_hold_note",
    "Dependence",
    "dependence_hint",
    "friction_left_out",
    "held_terms",
    "judged_springs",
    "offsets_of",
    "outside_model_note",
    "ROUND_OFF",
    "position_led",
    "residual_dependence",
    "round_off",
    "round_off_note",
    "reversal_led",
    "still_led",
    "with_dependence_hint",
]

#: The ``--terms`` name of a model term's kind (:attr:`~dynid.regressors.terms.ModelTerm.kind`)
#: where it differs from the term's own name: the rotor inertias are the ``armature``.
_TERM_WORDS = {"rotor_inertia": "armature"}
#: Bins of equal counts over a joint's position or velocity.
BINS = 20
#: Joints the hint describes at most, the farthest above their noise first.
NAMED = 3
#: Fewest samples per bin for a diagnosis.
MIN_PER_BIN = 10
#: A coordinate names the residual when it explains at least this share of its part above
#: the noise (RMS).
FOLLOWS = 0.5
#: The whole residual's RMS over the torques' RMS below which a prediction is exact to
#: round-off (:data:`~dynid.identification.verdict.ROUND_OFF_PERCENT`): its error over a
#: noise floor itself at the file's rounding says nothing of the model.
ROUND_OFF = ROUND_OFF_PERCENT / 100.0
#: A joint's residual is the holding torque at rest when its RMS over the samples of its
#: rests (:func:`at_rests`) is at least this many times that over the other samples, the
#: rests carrying at least :data:`FOLLOWS` of its mean square above the noise
#: (:func:`still_led`).
STILL_RATIO = 2.0


def at_standstill(dq: NDArray[np.float64]) -> NDArray[np.bool_]:
    """Which samples (N, n) of each joint are at standstill: ``|dq|`` within the
    velocities' noise band (:func:`~dynid.identification.velocity_noise.noise_band` of
    their :func:`~dynid.identification.velocity_noise.velocity_noise_std`, at least
    :data:`~dynid.identification.velocity_noise.MIN_MOTION`) [rad/s]. There the friction
    is static, anything within its limits (a holding torque that depends on the last
    motion), which no term of a model of the velocity holds."""
    V = np.asarray(dq, dtype=np.float64)
    if V.shape[0] < 8:
        return np.zeros(V.shape, dtype=bool)
    band = np.maximum(noise_band(velocity_noise_std(V)), MIN_MOTION)
    out: NDArray[np.bool_] = np.abs(V) <= band
    return out


def at_rests(dq: NDArray[np.float64], t: Sequence[NDArray[np.float64]] | None) -> NDArray[np.bool_]:
    """Which samples (N, n) of each joint are at a rest: inside the standstill band
    (:func:`at_standstill`) for at least :data:`~dynid.identification.rests.MIN_REST_S`
    (:func:`~dynid.identification.rests.lasting_rests`, ``t`` each piece's times [s]). A
    reversal passes through the band in a few samples and is no rest: its friction steps,
    it holds nothing. Without times none is (a rest cannot be told from a reversal)."""
    V = np.asarray(dq, dtype=np.float64)
    if t is None:
        return np.zeros(V.shape, dtype=bool)
    return lasting_rests(at_standstill(V), t)


@dataclass(frozen=True, slots=True)
class Dependence:
    """How much of a joint's residual follows its own position and velocity.

    Attributes
    ----------
    joint : int
        The joint's index.
    rms : float
        The residual's RMS [N m].
    noise : float
        The joint's noise RMS [N m].
    position, velocity : float
        The RMS [N m] of the residual's binned means over the joint's position, velocity
        (about the overall mean, the noise they keep taken out).
    mean : float
        The residual's mean [N m] (a constant: an offset).
    ratio : float
        The joint's error over its noise as the verdict judges it (each sample weighed by
        its own noise), or ``rms / noise``: what orders the joints.
    acceleration : float
        The RMS [N m] of the residual's binned means over the joint's acceleration, as
        ``position`` (0 where the accelerations were not given).
    still_share : float
        The share of the samples at which the joint rests (:func:`at_rests`).
    still, moving : float
        The residual's RMS [N m] over the samples at rest and over the others (0 where
        there are none).
    reversal_share : float
        The share of the samples at which the joint passes through its standstill band
        without resting (:func:`at_standstill`, not :func:`at_rests`): its reversals.
    reversal, off_reversal : float
        The residual's RMS [N m] over those samples and over the others (0 where there are
        none).
    """

    joint: int
    rms: float
    noise: float
    position: float
    velocity: float
    mean: float
    ratio: float = float("nan")
    acceleration: float = 0.0
    still_share: float = 0.0
    still: float = 0.0
    moving: float = 0.0
    reversal_share: float = 0.0
    reversal: float = 0.0
    off_reversal: float = 0.0

    def __post_init__(self) -> None:
        if not np.isfinite(self.ratio):
            object.__setattr__(self, "ratio", self.rms / self.noise if self.noise > 0 else np.inf)

    @property
    def systematic(self) -> float:
        """The residual's RMS above the noise [N m]: ``sqrt(rms^2 - noise^2)``."""
        return float(np.sqrt(max(self.rms**2 - self.noise**2, 0.0)))


def _binned(x: NDArray[np.float64], e: NDArray[np.float64], var: float) -> float:
    """The RMS [N m] of ``e``'s means in :data:`BINS` bins of equal counts over ``x``, about
    ``e``'s mean, less the noise of variance ``var`` the means keep."""
    order = np.argsort(x, kind="stable")
    parts = np.array_split(e[order], BINS)
    m = float(np.mean(e))
    s2 = sum(p.size * (float(np.mean(p)) - m) ** 2 for p in parts) / e.size
    return float(np.sqrt(max(s2 - (BINS - 1) * var / e.size, 0.0)))


def _parts(
    Q: NDArray[np.float64], V: NDArray[np.float64], E: NDArray[np.float64], j: int, var: float
) -> tuple[float, float]:
    """Joint ``j``'s residual's parts [N m] that follow its position and its velocity."""
    return _binned(Q[:, j], E[:, j], var), _binned(V[:, j], E[:, j], var)


def still_led(d: Dependence) -> bool:
    """Whether joint ``d``'s residual concentrates at its rests: its RMS there at least
    :data:`STILL_RATIO` times that elsewhere, the samples at rest carrying at least
    :data:`FOLLOWS` of its mean square above the noise. The holding torque at rest (static
    friction, anything within its limits): no spring's, whatever follows the position
    (a 7-DoF arm resting 51 % of a point-to-point log had been told of a spring on
    joint 2 whose term made the held-out error worse, 7.79 to 8.75 %). Reversals are no
    rests (:func:`at_rests`): a UR5 validated on motion without rests had been told of the
    holding torque at rest over the 0.14 % of samples its elbow spent in its band there."""
    if d.still_share <= 0.0 or d.still < STILL_RATIO * d.moving:
        return False
    above = d.rms**2 - d.noise**2
    return above > 0 and d.still_share * (d.still**2 - d.noise**2) >= FOLLOWS * above


def reversal_led(d: Dependence) -> bool:
    """Whether joint ``d``'s residual concentrates at its reversals, the brief passes
    through its standstill band (:attr:`Dependence.reversal_share`), by the test of
    :func:`still_led`: friction's step there, which the model places where its own
    velocity leaves its Coulomb term's band (or smooths it) while the torques step at the
    true reversal (:mod:`~dynid.identification.friction_steps`); no holding torque."""
    if d.reversal_share <= 0.0 or d.reversal < STILL_RATIO * d.off_reversal:
        return False
    above = d.rms**2 - d.noise**2
    return above > 0 and d.reversal_share * (d.reversal**2 - d.noise**2) >= FOLLOWS * above


def _still(R: NDArray[np.bool_], E: NDArray[np.float64], j: int) -> tuple[float, float, float]:
    """Joint ``j``'s share of samples at rest (``R``, :func:`at_rests`) and the residual's
    RMS [N m] there and elsewhere."""
    rest = R[:, j]
    if not rest.any() or rest.all():
        return 0.0, 0.0, 0.0
    e = E[:, j]
    return (
        float(np.mean(rest)),
        float(np.sqrt(np.mean(e[rest] ** 2))),
        float(np.sqrt(np.mean(e[~rest] ** 2))),
    )


def acceleration_led(d: Dependence) -> bool:
    """Whether joint ``d``'s residual follows its acceleration more than its position and
    its velocity, by at least :data:`FOLLOWS` of its part above the noise: an inertia the
    model lacks at the joint (a rotor's, the armature ``I_a ddq``), which a motion of a
    few harmonics also shows against the position (``ddq`` near ``-w^2 q``), less."""
    top = max(d.position, d.velocity)
    return d.acceleration > top and d.acceleration >= FOLLOWS * d.systematic


def position_led(d: Dependence) -> bool:
    """Whether joint ``d``'s residual follows its position at least as much as its
    velocity: the one test of a spring's (or another position-dependent effect's) against
    friction's, for the hint's words and the springs named alike."""
    return d.position >= d.velocity


def residual_dependence(
    q: Sequence[NDArray[np.float64]],
    dq: Sequence[NDArray[np.float64]],
    error: Sequence[NDArray[np.float64]],
    noise_rms: NDArray[np.float64],
    ratios: NDArray[np.float64] | None = None,
    ddq: Sequence[NDArray[np.float64]] | None = None,
    t: Sequence[NDArray[np.float64]] | None = None,
) -> tuple[Dependence, ...]:
    """Each joint above :data:`~dynid.identification.verdict.SYSTEMATIC_RATIO` x its noise,
    its residual's dependence on its own position and velocity, and acceleration when
    given (module docstring).

    Parameters
    ----------
    q, dq : sequence of ndarray, each (N_k, n)
        The positions [rad] and velocities [rad/s] the model was evaluated at, per piece.
    error : sequence of ndarray, each (N_k, n)
        Measured less predicted torques at the same samples [N m].
    noise_rms : ndarray, shape (n,)
        Each joint's noise [N m] (the sensors' and the states' through the model).
    ratios : ndarray, shape (n,), optional
        Each joint's error over its noise as the verdict judges it (the samples weighed by
        their own noise: :attr:`~dynid.identification.input_noise.NoiseFloor.joint_ratios`),
        which then says which joints are above their noise, so that the joints named are
        the verdict's; default ``rms / noise_rms``.
    ddq : sequence of ndarray, each (N_k, n), optional
        The accelerations [rad/s^2] at the same samples: the part that follows them
        (:attr:`Dependence.acceleration`).
    t : sequence of ndarray, each (N_k,), optional
        The samples' times [s], per piece: the rests (:func:`at_rests`), over which a
        residual is told as the holding torque; without them no sample is at rest.

    Returns
    -------
    tuple of Dependence
        One per joint above its noise, in joint order; empty with fewer than
        ``MIN_PER_BIN`` samples per bin.
    """
    Q = np.concatenate([np.asarray(x, dtype=np.float64) for x in q])
    V = np.concatenate([np.asarray(x, dtype=np.float64) for x in dq])
    E = np.concatenate([np.asarray(x, dtype=np.float64) for x in error])
    A = None if ddq is None else np.concatenate([np.asarray(x, dtype=np.float64) for x in ddq])
    s = np.asarray(noise_rms, dtype=np.float64)
    if E.shape[0] < BINS * MIN_PER_BIN or not np.all(np.isfinite(s)):
        return ()
    rms = np.sqrt(np.mean(E**2, axis=0))
    judged = rms / s if ratios is None else np.asarray(ratios, dtype=np.float64)
    out, R = [], at_rests(V, t)
    passes = at_standstill(V) & ~R  # inside the band without resting: the reversals
    for j in np.flatnonzero((judged > SYSTEMATIC_RATIO) & (rms > s)):  # a part to diagnose
        position, velocity = _parts(Q, V, E, int(j), float(s[j]) ** 2)
        share, still, moving = _still(R, E, int(j))
        through = _still(passes, E, int(j))
        out.append(
            Dependence(
                joint=int(j),
                rms=float(rms[j]),
                noise=float(s[j]),
                position=position,
                velocity=velocity,
                mean=float(np.mean(E[:, j])),
                ratio=float(judged[j]),
                acceleration=0.0 if A is None else _binned(A[:, j], E[:, j], float(s[j]) ** 2),
                still_share=share,
                still=still,
                moving=moving,
                reversal_share=through[0],
                reversal=through[1],
                off_reversal=through[2],
            )
        )
    return tuple(out)


def judged_springs(
    springs: ResidualSpring | None,
    q: NDArray[np.float64],
    dq: NDArray[np.float64],
    error: NDArray[np.float64],
) -> ResidualSpring | None:
    """``springs`` with the joints whose residual follows their velocity more than their
    position (:func:`position_led` false) marked
    :attr:`~dynid.identification.residual_spring.ResidualSpring.velocity_led`, which
    :attr:`~dynid.identification.residual_spring.ResidualSpring.named` then leaves out:
    friction the law misses is no spring, whatever stiffness a fit beside the model's
    columns gives it.

    Parameters
    ----------
    springs : ResidualSpring or None
        The stiffness per joint fitted beside the model's columns; None passes through.
    q, dq : ndarray, shape (N, n)
        Positions [rad] and velocities [rad/s] of the residual's samples.
    error : ndarray, shape (N, n)
        Measured less predicted torques at the same samples [N m] (the residual judged).

    Returns
    -------
    ResidualSpring or None
        ``springs`` judged; ``springs`` itself with fewer than ``MIN_PER_BIN`` samples per
        bin.
    """
    if springs is None or not springs.named:
        return springs
    Q, V, E = (np.asarray(x, dtype=np.float64) for x in (q, dq, error))
    if E.shape[0] < BINS * MIN_PER_BIN:
        return springs
    rms = np.sqrt(np.mean(E**2, axis=0))
    led = []
    for j in springs.named:
        position, velocity = _parts(Q, V, E, j, float(springs.noise[j]) ** 2)
        d = Dependence(j, float(rms[j]), float(springs.noise[j]), position, velocity, 0.0)
        if not position_led(d):
            led.append(j)
    return replace(springs, velocity_led=tuple(sorted(set(springs.velocity_led) | set(led))))


def _remedy(terms: Collection[str]) -> str:
    """What to add to the model for a residual that follows a joint's position, given the
    model's ``terms``: the spring, the offset that places its rest position, or neither."""
    if "spring" not in terms:
        return (
            "try adding spring to --terms of dynid identify, with offset: the spring's rest "
            "position"
        )
    if "offset" not in terms:
        return (
            "the model's spring acts about the middle of the joint's limits: add offset to "
            "--terms of dynid identify so that its rest position is identified"
        )
    return "beyond the model's linear spring: a spring that is not linear, a cable"


#: What to add to a model without the armature for a residual that follows a joint's
#: acceleration (a model that holds it is told its inertia is off: :func:`_sentence`).
_INERTIA_REMEDY = (
    "add armature to --terms of dynid identify, or give a drive file with rotor_inertia (--drive)"
)


def _constant(
    d: Dependence,
    head: str,
    offset: tuple[str, bool] | None,
    lacks: str | None = None,
    level: Sequence[float] | None = None,
) -> str:
    """Joint ``d``'s residual that is a constant over the samples judged, in words, told
    with the model's own offset (``offset``: its label and whether the model holds it,
    :func:`offsets_of`): an offset the structure chosen on held-out data left out, or one
    the model holds, is no offset the fit missed but a level that changes along the motion
    (the Panda's last 1.1 s of a 5 s log: 0.21 N m on joint 4, whose true friction has no
    offset); ``lacks``: the robot file the model was read from, which holds no offset
    (``"a URDF"``). ``level``: the constant per recording where it is one steady constant
    over each (:mod:`~.recording_level`): the recording's own torque offset, said so."""
    if level is not None and offset is not None:
        return level_clause(head, d.mean, d.rms, level, offset)
    said = f"{head}{abs(d.mean):.2g} of {d.rms:.2g} N m RMS residual is a constant"
    if offset is None:
        return f"{said} (an offset{'' if lacks is None else f', which {lacks} cannot hold'})"
    label, held = offset
    why = (
        f"beyond the model's offset {label}"
        if held
        else f"but the model left its offset {label} out (an offset predicted held-out data no "
        "better)"
    )
    return (
        f"{said} over these samples, {why}: a level that changes along the motion (friction "
        "the law misses at these speeds, a drift), not one offset"
    )


def _share_percent(share: float) -> str:
    """``share`` (0..1) in percent to 2 significant digits (``"0.43"``, ``"51"``), 3 near
    all (``"99.7"``): a share above 0 is never said as ``"0"``, below 1 never as ``"100"``."""
    p = 100.0 * share
    return f"{p:.2g}" if p < 99.5 else f"{p:.3g}"


def _sentence(
    d: Dependence,
    name: str,
    terms: Collection[str] = (),
    springs: ResidualSpring | None = None,
    offsets: Mapping[int, tuple[str, bool]] | None = None,
    left_out: Mapping[int, tuple[str, ...]] | None = None,
    inertia: str | None = None,
    still_as: str | None = None,
    lacks: str | None = None,
    levels: Mapping[int, Sequence[float]] | None = None,
) -> str:
    """One joint's diagnosis in words (a residual that concentrates at the joint's rests
    first (:func:`at_rests`; their share of the samples to 2 significant digits): the
    holding torque at rest, its why said once, ``still_as`` the joint it was said
    at; then one that concentrates at its reversals (:func:`reversal_led`): friction's
    step there; then a residual that follows the acceleration:
    an inertia the model lacks, with ``inertia`` the remedy where the caller knows it,
    else :data:`_INERTIA_REMEDY`; a model that holds the armature, its
    inertia off the model's); ``terms`` the model's term names (:func:`held_terms`),
    so that the remedy names what the model lacks, not what it holds; ``springs`` the
    stiffness per joint fitted with the model (its named joints' said with their
    stiffness, a position dependence no spring explains said so); ``offsets`` the model's
    offset per joint (:func:`offsets_of`), with which a constant residual is told;
    ``left_out`` its friction coefficients left out per joint (:func:`friction_left_out`):
    a residual that follows the velocity there is that friction, not one the law misses
    (a model fitted to two FR3 recordings of opposite signs on joint 7 had dropped fv7 and
    fc7, and its validation had suggested comparing the laws); ``lacks``: the robot file
    the model was read from, which holds no offset and no friction beyond viscous and
    Coulomb (``"a URDF"``), named with a constant residual and one that follows the
    velocity (:func:`cannot_hold_note`); ``levels``: per joint, the constant of each
    recording where the residual is one steady constant over each (:mod:`~.recording_level`),
    told as the recording's own torque offset."""
    head = f"{name}: "
    if still_led(d):
        said = (
            f"{head}{d.rms:.2g} N m RMS residual, {d.still:.2g} over the "
            f"{_share_percent(d.still_share)} % of samples at rest (inside the velocity "
            f"band for {MIN_REST_S:g} s or more) against {d.moving:.2g} elsewhere: the "
            "holding torque at rest"
        )
        if still_as is not None:
            return f"{said}, as {still_as}"
        return (
            f"{said} (static friction, anything within its limits, which no term of the "
            "model holds; no spring or friction term fits it: judge the model on moving "
            "samples, or record without rests)"
        )
    if reversal_led(d):
        return (
            f"{head}{d.rms:.2g} N m RMS residual, {d.reversal:.2g} over the "
            f"{_share_percent(d.reversal_share)} % of samples at its velocity reversals "
            f"(brief passes through the standstill band, no rest) against "
            f"{d.off_reversal:.2g} elsewhere: friction's step at the reversals, which the "
            "model places where its velocity leaves its Coulomb term's band (or smooths it) "
            "while the torques step at the reversal itself"
        )
    if acceleration_led(d):
        said = (
            f"{head}{d.acceleration:.2g} of {d.rms:.2g} N m RMS residual follows its acceleration"
        )
        if inertia is None and "armature" in terms:
            return (
                f"{said}: the joint's inertia is off the model's, which holds the armature "
                "(a base parameter that groups it with the link inertias counts: the sum "
                "fitted off, its standard deviation says by how much the data allow, or an "
                "inertia beyond the links and rotors)"
            )
        return (
            f"{said}: an inertia the model lacks at the joint, most likely a rotor's "
            f"(armature) ({inertia or _INERTIA_REMEDY})"
        )
    named = springs is not None and d.joint in springs.named  # judged_springs judged it
    follows = f"{head}{d.position:.2g} of {d.rms:.2g} N m RMS residual follows its position"
    if named:
        assert springs is not None
        return (
            f"{follows}: {springs.sentence(d.joint)} outside the rigid-body model, fitted "
            f"with the model's columns to these torques ({_remedy(terms)})"
        )
    if position_led(d) and d.position >= FOLLOWS * d.systematic:
        if springs is None or "spring" in terms:
            if "spring" not in terms:
                why = "a spring, a cable or a counterbalance outside the rigid-body model; "
                return f"{follows} ({why}{_remedy(terms)})"
            return f"{follows} ({_remedy(terms)})"
        k = float(springs.stiffness[d.joint])
        return (
            f"{follows}, but a linear spring fitted there with the model's columns explains "
            f"little of it ({k:.2g} N m/rad): the links' parameters pulled by an effect on "
            "another joint, or a dependence that is not a spring's"
        )
    gone = (left_out or {}).get(d.joint)
    if d.velocity >= FOLLOWS * d.systematic and gone:
        return (
            f"{head}{d.velocity:.2g} of {d.rms:.2g} N m RMS residual follows its velocity: "
            f"friction the model left out there ({', '.join(gone)} dropped by its fit: the "
            f"recordings it was identified from may disagree in {name}'s torque sign, which "
            "averages its friction to nothing (dynid identify names such recordings), or "
            "show too little of it)"
        )
    if d.velocity >= FOLLOWS * d.systematic:
        return (
            f"{head}{d.velocity:.2g} of {d.rms:.2g} N m RMS residual follows its velocity "
            f"(friction the law misses{'' if lacks is None else f' or {lacks} cannot hold'}; "
            "dynid friction compares the laws on held-out data, and --terms of dynid "
            "identify takes the one it chooses)"
        )
    if abs(d.mean) >= FOLLOWS * d.systematic:
        level = (levels or {}).get(d.joint)
        return _constant(d, head, (offsets or {}).get(d.joint), lacks, level)
    return (
        f"{head}of {d.rms:.2g} N m RMS residual, {d.position:.2g} follows its position and "
        f"{d.velocity:.2g} its velocity: the rest depends on other joints' motion"
    )


def held_terms(model: IdentifiedModel | Robot) -> frozenset[str]:
    """The names of the terms ``model`` holds beside the rigid bodies, as ``--terms`` names
    them: an identified model's terms (``spring``, ``armature``: its rotor inertias, also
    where a base parameter groups one with the link inertias, ``J1zz + ... + Ia1``) and
    its friction's parts (``viscous``, ``coulomb``, ``offset``, ...); a robot's ``spring``
    when it has one."""
    if isinstance(model, Robot):
        return frozenset({"spring"} if model.spring is not None else ())
    out = set(model.terms)
    for t in model.terms.values():
        out.update(getattr(t.term, "parts", ()) or ())
        if t.term.kind in _TERM_WORDS:  # its --terms name; held even where a base
            out.add(_TERM_WORDS[t.term.kind])  # parameter groups it with the links
    return frozenset(out)


def offsets_of(model: IdentifiedModel | Robot) -> dict[int, tuple[str, bool]]:
    """The joints whose friction has an offset part, each with the offset's label and
    whether the model holds it (``{3: ("fo4", False)}``: joint 4's offset left out by the
    structure chosen on held-out data, or pruned); friction at coupled motors, whose
    offsets are no one joint's, and a robot's own friction give none."""
    if isinstance(model, Robot):
        return {}
    out: dict[int, tuple[str, bool]] = {}
    for t in model.terms.values():
        term = t.term
        if not isinstance(term, LinearFriction) or "offset" not in term.parts:
            continue
        kept = {lab for lab, k in zip(term.labels, t.kept, strict=True) if k}
        coupled = set(term.drive.coupled)
        for j in range(term.drive.n):
            label = f"{term.prefix}{PART_LABELS['offset']}{j + 1}"
            if j not in coupled and not (j in out and out[j][1]):
                out[j] = (label, label in kept)
    return out


def friction_left_out(model: IdentifiedModel | Robot) -> dict[int, tuple[str, ...]]:
    """The joints whose friction the model left out in part, each with the labels of the
    velocity-dependent coefficients left out (``{6: ("fv7", "fc7")}``: the structure
    chosen on held-out data dropped them on joint 7, or they were pruned); offsets are
    :func:`offsets_of`'s. Friction at coupled motors, no one joint's, and a robot's own
    friction give none."""
    if isinstance(model, Robot):
        return {}
    out: dict[int, tuple[str, ...]] = {}
    for t in model.terms.values():
        term = t.term
        if not isinstance(term, LinearFriction):
            continue
        kept = {lab for lab, k in zip(term.labels, t.kept, strict=True) if k}
        coupled = set(term.drive.coupled)
        for j in range(term.drive.n):
            labels = [f"{term.prefix}{PART_LABELS[p]}{j + 1}" for p in term.parts]
            gone = [
                lab
                for p, lab in zip(term.parts, labels, strict=True)
                if p != "offset" and lab not in kept
            ]
            if j not in coupled and gone:
                out[j] = out.get(j, ()) + tuple(gone)
    return out


def dependence_hint(
    q: Sequence[NDArray[np.float64]],
    dq: Sequence[NDArray[np.float64]],
    error: Sequence[NDArray[np.float64]],
    noise_rms: NDArray[np.float64],
    joint_names: Sequence[str],
    terms: Collection[str] = (),
    tilt: GravityTilt | None = None,
    ratios: NDArray[np.float64] | None = None,
    springs: ResidualSpring | None = None,
    offsets: Mapping[int, tuple[str, bool]] | None = None,
    left_out: Mapping[int, tuple[str, ...]] | None = None,
    ddq: Sequence[NDArray[np.float64]] | None = None,
    inertia: str | None = None,
    lacks: str | None = None,
    prismatic: Sequence[bool] | None = None,
    levels: Mapping[int, Sequence[float]] | None = None,
    t: Sequence[NDArray[np.float64]] | None = None,
) -> str | None:
    """:func:`residual_dependence` in words, one clause per joint above its noise joined by
    ``"; "`` (``"right_s1: 0.41 of 0.59 N m RMS residual follows its position (...)"``),
    the :data:`NAMED` farthest above their noise first, or None when no joint is above
    its noise.

    ``tilt``: the tilt of the gravity vector the residual points to
    (:func:`~dynid.identification.gravity_tilt.gravity_tilt` of the pieces concatenated);
    when it explains the residual (:attr:`~dynid.identification.gravity_tilt.GravityTilt.
    named`) it is said first and the joints are diagnosed on what it leaves (a residual
    the tilt explains is no spring's); a tilt without ``rows`` (judged on a held-out
    block's whole log) is said alone. ``ratios``: the verdict's per joint
    (:func:`residual_dependence`). ``springs``: the stiffness per joint fitted with the
    model (:func:`~dynid.identification.residual_spring.residual_spring`), which names a
    spring's joint with its stiffness and says where a position dependence is no
    spring's. ``offsets``: the model's offset per joint (:func:`offsets_of`), with which a
    constant residual is told; ``left_out``: the friction coefficients the model left out
    per joint (:func:`friction_left_out`), named where the residual follows the velocity;
    ``ddq``: the accelerations [rad/s^2] at the samples (pieces as ``q``), with which a
    residual that follows them is said to be an inertia the model lacks (a rotor's),
    ``inertia`` the remedy said where the caller knows it (a URDF holds no armature);
    ``lacks``: the robot file the model was read from (``"a URDF"``), whose missing
    offsets and friction are named with the joints and said once after them
    (:func:`cannot_hold_note`); ``prismatic``: the joints' kinds, a prismatic joint's
    clause in its own units (N, N/m: :func:`~dynid.model.units.joint_unit`); ``levels``:
    per joint, each recording's constant where the residual is one steady constant over
    each (:mod:`~.recording_level`), told as the recording's own offset; ``t``: the
    samples' times [s] (pieces as ``q``), which tell the joints' rests from their
    reversals (:func:`at_rests`; without them no residual is said to be the holding
    torque at rest)."""
    if tilt is not None and tilt.named and tilt.rows.size == 0:
        return tilt.sentence()  # judged on other samples (a block's whole log): said alone
    if tilt is not None and tilt.named:
        rows = np.asarray(tilt.rows)
        ends = np.cumsum([len(p) for p in q])
        cut = np.searchsorted(rows, ends[:-1])  # the rows kept, piece by piece

        def kept(x: Sequence[NDArray[np.float64]]) -> list[NDArray[np.float64]]:
            return np.split(np.concatenate([np.asarray(p, dtype=np.float64) for p in x])[rows], cut)

        rest = dependence_hint(
            kept(q), kept(dq), np.split(tilt.rest, cut), noise_rms, joint_names, terms,
            offsets=offsets, left_out=left_out, ddq=None if ddq is None else kept(ddq),
            inertia=inertia, lacks=lacks, prismatic=prismatic, levels=levels,
            t=None if t is None else kept(t),
        )  # fmt: skip
        return tilt.sentence() + ("" if rest is None else f"; what it leaves: {rest}")
    found = residual_dependence(q, dq, error, noise_rms, ratios, ddq, t)
    if not found:
        return None
    worst = sorted(found, key=lambda d: d.ratio, reverse=True)
    clauses, first, still = [], None, None  # the inertia's remedy said once, as the rest's
    for d in worst[:NAMED]:
        remedy = inertia if first is None else f"as for {first}"
        name = joint_names[d.joint]
        clause = _sentence(d, name, terms, springs, offsets, left_out, remedy, still, lacks, levels)
        rail = prismatic is not None and d.joint < len(prismatic) and bool(prismatic[d.joint])
        clauses.append(joint_unit(clause, rail))  # its N m and rad said as N and m
        if first is None and acceleration_led(d) and not still_led(d):
            first = name
        if still is None and still_led(d):
            still = name
    said = "; ".join(clauses)
    more = len(worst) - NAMED
    said += f" ({more} more joint(s) above their noise)" if more > 0 else ""
    return said + ("" if lacks is None else cannot_hold_note(said, lacks))


def cannot_hold_note(said: str, lacks: str) -> str:
    """``; a URDF holds no torque offsets: validate ...``: what the robot file ``lacks``
    (``"a URDF"``) cannot hold of what the joints' diagnoses ``said`` name (an offset, a
    friction beyond viscous and Coulomb: :func:`dependence_hint`), and the model that
    holds it; empty when they name neither."""
    held = (
        ("no torque offsets", f"an offset, which {lacks} cannot hold"),
        ("no friction beyond viscous and Coulomb", f"misses or {lacks} cannot hold"),
    )
    what = [words for words, mark in held if mark in said]
    if not what:
        return ""
    return (
        f"; {lacks} holds {' and '.join(what)}: validate the identification's feasible.json "
        "(--params) or identification.json (--model) for the full model"
    )


def round_off(
    error: Sequence[NDArray[np.float64]], torques: Sequence[NDArray[np.float64]] | None
) -> float | None:
    """The RMS of the residuals ``error`` over that of the measured ``torques`` (pieces of
    (N_k, n) [N m], every joint pooled) when below :data:`ROUND_OFF`: a prediction exact to
    round-off, whose residual is no systematic one; None above it or without torques."""
    if torques is None or not len(error):
        return None
    e = np.concatenate([np.asarray(x, dtype=np.float64).ravel() for x in error])
    t = np.concatenate([np.asarray(x, dtype=np.float64).ravel() for x in torques])
    scale = float(np.sqrt(np.mean(t**2))) if t.size else 0.0
    if not e.size or not scale > 0 or not np.all(np.isfinite(e)):
        return None
    relative = float(np.sqrt(np.mean(e**2))) / scale
    return relative if relative < ROUND_OFF else None


def round_off_note(relative: float, what: str = "the prediction") -> str:
    """``what`` is exact to round-off: its residual ``relative`` of the torques' RMS
    (:func:`round_off`) said in words, not called systematic."""
    return (
        f"{what} is exact to round-off (residual {relative:.2g} of the torques' RMS): what "
        "is above a noise floor itself at round-off is no systematic residual, no effect "
        "outside the model"
    )


def with_dependence_hint(
    verdict: Verdict,
    q: Sequence[NDArray[np.float64]],
    dq: Sequence[NDArray[np.float64]],
    error: Sequence[NDArray[np.float64]],
    noise_rms: NDArray[np.float64],
    joint_names: Sequence[str],
    terms: Collection[str] = (),
    tilt: GravityTilt | None = None,
    ratios: NDArray[np.float64] | None = None,
    springs: ResidualSpring | None = None,
    torques: Sequence[NDArray[np.float64]] | None = None,
    offsets: Mapping[int, tuple[str, bool]] | None = None,
    left_out: Mapping[int, tuple[str, ...]] | None = None,
    ddq: Sequence[NDArray[np.float64]] | None = None,
    inertia: str | None = None,
    lacks: str | None = None,
    prismatic: Sequence[bool] | None = None,
    levels: Mapping[int, Sequence[float]] | None = None,
    t: Sequence[NDArray[np.float64]] | None = None,
) -> Verdict:
    """``verdict`` with :func:`dependence_hint` appended when it is above the noise floor
    (not ``"good"``) and a joint is above its noise; else ``verdict`` itself; with the
    measured ``torques`` (pieces as ``error``), a residual exact to round-off
    (:func:`round_off`) is said so instead of diagnosed. ``terms``: the
    model's (:func:`held_terms`); ``tilt``: the tilt of the gravity vector the residual
    points to, said first when it explains it; ``ratios``: the verdict's per joint, which
    say which joints are above their noise; ``springs``: the stiffness per joint fitted
    with the model, said for a spring's joint; ``offsets``: the model's offset per joint
    (:func:`offsets_of`), with which a constant residual is told; ``left_out``: its
    friction coefficients left out per joint (:func:`friction_left_out`); ``ddq`` and
    ``inertia``: the accelerations and the remedy of a residual that follows them;
    ``lacks``: the robot file the model was read from; ``prismatic``: the joints' kinds
    (:func:`dependence_hint`); ``levels``: each recording's constant per joint where it is
    one (:mod:`~.recording_level`); ``t``: the samples' times [s], which tell rests from
    reversals (:func:`at_rests`)."""
    if verdict.level == "good":
        return verdict
    if (exact := round_off(error, torques)) is not None:
        return with_hint(verdict, round_off_note(exact))
    said = dependence_hint(
        q, dq, error, noise_rms, joint_names, terms, tilt, ratios, springs, offsets, left_out,
        ddq, inertia, lacks, prismatic, levels, t,
    )  # fmt: skip
    return with_hint(verdict, said)


def outside_model_note(
    found: Sequence[Dependence], joint_names: Sequence[str], terms: Collection[str] = ()
) -> str | None:
    """Why a physically consistent fit predicts held-out torques worse than least squares
    when least squares itself leaves a systematic residual (``found``:
    :func:`residual_dependence` of its held-out prediction): an effect outside the
    rigid-body model pulls the links' parameters, which least squares may bend to and the
    consistent fit may not; the :data:`NAMED` farthest above their noise first. None when
    ``found`` is empty."""
    if not found:
        return None
    found = sorted(found, key=lambda d: d.ratio, reverse=True)
    more = len(found) - NAMED
    found = found[:NAMED]
    which = ", ".join(
        f"{joint_names[d.joint]} ({d.ratio:.3g} x its noise, {d.rms:.3g} N m RMS)" for d in found
    ) + (f" and {more} more joint(s)" if more > 0 else "")
    return (
        f"least squares itself leaves a systematic residual on {which}: an effect outside "
        "the rigid-body model there pulls the links' parameters, and the consistent fit "
        "cannot absorb it; model it before the constraints are blamed: "
        + "; ".join(_sentence(d, joint_names[d.joint], terms) for d in found)
    )
