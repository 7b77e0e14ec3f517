"""The model's structure: which terms beside the links' parameters, and their columns.

A joint-torque log of a real arm holds more than the rigid links: the rotors' inertia
(an armature ``I_a ddq`` per joint, or the rotors of a drive), viscous and Coulomb friction,
torque offsets, friction laws with a shape (a smooth Coulomb's width, one for every joint
or one per joint, and a Stribeck velocity), and a spring per joint (a gravity
compensator, a cable: :class:`~dynid.regressors.spring.JointSpring`).
A :class:`Structure` names the terms: ``armature`` (per joint ``I_a ddq`` without a drive,
the drive's rotor inertias with one) and the parts of the joint (motor) friction
(:data:`~dynid.regressors.terms.FRICTION_PARTS`); :func:`structure_terms` makes its model
terms, :func:`candidate_structures` the candidates that
:mod:`dynid.identification.selection` judges on held-out data, and
:func:`largest_terms` / :func:`candidate_columns` the one model that holds them all and
each candidate's columns in it.
"""

from __future__ import annotations

import math
from collections.abc import Collection, Mapping, Sequence
from dataclasses import dataclass, replace
from typing import Any

import numpy as np
from numpy.typing import NDArray

from ..exceptions import OptionError
from ..model.drive import Drive
from ..regressors.spring import SPRING_LABEL, JointSpring, spring_mask
from ..regressors.terms import (
    FRICTION_PARTS,
    PART_LABELS,
    LinearFriction,
    ModelTerm,
    RotorInertia,
)

__all__ = [
    "ERROR_FLOOR_PERCENT",
    "FRICTION_LADDER",
    "JOINT_PREFIX",
    "MIN_WIDTH",
    "SMOOTH_WIDTHS",
    "SMOOTH_STRIBECK_WIDTHS",
    "STRIBECK_COARSE",
    "STRIBECK_VELOCITIES",
    "Structure",
    "candidate_columns",
    "candidate_structures",
    "column_labels",
    "check_placement",
    "coefficient_labels",
    "friction_placements",
    "joint_side_joints",
    "own_rotors",
    "regressor_group",
    "largest_terms",
    "smooth_stribeck_candidates",
    "smooth_width",
    "smooth_width_grid",
    "structure_terms",
    "vst_layers",
    "width_key",
    "width_text",
]

#: Held-out errors [%] closer than this count as equal, and a training error at or below it
#: is round-off (a fit to exact data): the folds are judged through their normal equations
#: about the fit's coefficients (:attr:`~.holdout.Normals.origin`), whose round-off on exact
#: data is near 1e-10 % (a simulated UR10: 5e-12 % to 6e-10 %). A floor of 1e-4 % (the
#: round-off without that origin) let an exact arm lose rotor inertias that cost 2e-5 %.
ERROR_FLOOR_PERCENT = 1e-8

#: The classical friction candidates, simplest first.
FRICTION_LADDER: tuple[tuple[str, ...], ...] = (
    (),
    ("offset",),
    ("viscous",),
    ("viscous", "offset"),
    ("viscous", "coulomb"),
    ("viscous", "coulomb", "offset"),
)
#: Widths of the smooth Coulomb candidates, in multiples of each joint's standstill band
#: (the band of the velocities as prepared, at least :data:`MIN_WIDTH`): ``tanh(dq / w)``
#: reaches 76 % of ``fc`` at ``dq = w``. The narrowest (0.3 bands: about the velocity
#: noise's standard deviation) predicts a sharp Coulomb law best where the velocity
#: crosses zero in motion (the expected sign given the noise); the standstill band of
#: ``coulomb`` best at rest; the held-out data choose. The widest (30 to 300 bands: 0.045
#: to 0.45 rad/s at a band of 1.5 mrad/s) are the friction's own rounding, as in the
#: sigmoid of the Panda's published model (``tanh(phi2 dq / 2)``: ``2 / phi2`` of 0.12 to
#: 0.39 rad/s).
SMOOTH_WIDTHS = (0.3, 1.0, 3.0, 10.0, 30.0, 100.0, 300.0)
#: Stribeck velocities [rad/s] of the Stribeck candidates.
STRIBECK_VELOCITIES = (0.02, 0.03, 0.05, 0.07, 0.1, 0.15, 0.2)
#: The Stribeck velocities [rad/s] judged where the data cannot tell the candidates at
#: every one of :data:`STRIBECK_VELOCITIES` apart (neighbours too alike: slow motion).
STRIBECK_COARSE = (0.02, 0.05, 0.1, 0.2)
#: Widths (in standstill bands, as :data:`SMOOTH_WIDTHS`) of the Stribeck candidates
#: whose Coulomb term and bump take the smooth sign ``tanh(dq / w)`` (the narrowest: the
#: expected sign of a sharp law given the noise, where the bump sits; the banded sign
#: switches the bump off right where it is largest); the search then adds the bump at the
#: width of the best smooth law (:mod:`dynid.identification.bumps`).
SMOOTH_STRIBECK_WIDTHS = (0.3,)
#: Smallest smooth width [rad/s] (a noise-free log has no standstill band).
MIN_WIDTH = 1e-3

_CLASSICAL = ("viscous", "coulomb", "offset")
_PLACEMENTS = ("", "motor", "joint", "both")
#: The prefix of the labels of the friction at the joints beside that at the motors.
JOINT_PREFIX = "j"
#: The label of a joint's armature (rotor inertia): ``Ia3``.
ARMATURE_LABEL = "Ia"


def _label_order(label: str) -> tuple[int, str]:
    """Joint first, then the label: ``fv2 < fo2 < fv3``."""
    prefix = label.rstrip("0123456789")
    return int(label[len(prefix) :]), prefix


def _checked_per_joint(
    value: float | tuple[float, ...], n: int, law: str, what: str, one: str
) -> tuple[float, ...]:
    """A law's shape (one for every joint, or one per joint) for each of ``n`` joints
    (motors): :func:`_per_joint`, its count checked.

    Raises
    ------
    OptionError
        Values per joint given for another number of joints (naming ``--terms law:...``).
    """
    if not isinstance(value, float) and len(value) != n:
        raise OptionError(
            f"--terms {law}:{width_text(value)}: {len(value)} {what} for {n} joints "
            f"(motors); give {one}, or one per joint separated by '/'"
        )
    return _per_joint(value, n)


@dataclass(frozen=True, slots=True)
class Structure:
    """The terms of a model beside the links' parameters.

    Attributes
    ----------
    armature : bool
        An inertia ``I_a`` [kg m^2] per joint on the joint's acceleration (``I_a ddq``;
        with a drive, the rotor inertias at the motors: ``K^T diag(I_a) K ddq``).
    friction : tuple of str
        The parts of the friction per joint (motor) held, linear in their coefficients
        (:data:`~dynid.regressors.terms.FRICTION_PARTS`: ``viscous``, ``coulomb``,
        ``smooth``, ``stribeck``, ``offset``); empty for none.
    width : float or tuple of float
        With ``smooth``: its width in multiples of each joint's (motor's) standstill band,
        one for every joint, or one per joint (motor) in order (a tuple whose widths are
        all equal is the one width: ``(3, 3)`` is ``3``).
    vst : float or tuple of float
        With ``stribeck``: the Stribeck velocity [rad/s], one for every joint, or one per
        joint (motor) in order (a tuple whose velocities are all equal is the one:
        :mod:`dynid.identification.stribeck_joints` chooses them).
    at : {"", "motor", "joint", "both"}
        Where the friction acts: ``""`` where the drive says (the joints without a drive),
        else at the drive's motors (``K^T f(K dq)``), at the joints (``f(dq)``), or
        ``"both"``: at the motors and, with the same parts but the offset (the motors'
        offsets ``K^T f_o`` span every constant torque already), at the joints that no
        motor turns alone (:func:`joint_side_joints`; labels ``jfv7, ...``), a coupled
        wrist with bearings on both sides. They differ only through a coupled transmission
        (:func:`friction_placements`).
    drop : tuple of str
        Coefficients left out on single joints (motors), by label: ``"fo3"`` is joint 3
        without an offset, ``"fc5"`` joint 5 without Coulomb friction (``fv``, ``fq``,
        ``fc``, ``fsp``, ``fo``; 1-based; ``jfc7``: joint 7's Coulomb friction at the joint
        with ``at="both"``), ``"Ia3"`` (or ``ia3``) joint 3 (motor 3) without armature;
        every other joint holds every term.
    spring : bool
        A linear stiffness ``k_j (q_j - q0_j)`` [N m/rad] per joint (labels ``k1 .. k_n``,
        :class:`~dynid.regressors.spring.JointSpring`) about a fixed ``q0`` (the middle of
        the joint's limits, :func:`structure_terms`): the spring's true rest position only
        adds a constant torque, which the offset (``offset``) absorbs.
    """

    armature: bool = False
    friction: tuple[str, ...] = _CLASSICAL
    width: float | tuple[float, ...] = 0.0
    vst: float | tuple[float, ...] = 0.0
    at: str = ""
    drop: tuple[str, ...] = ()
    spring: bool = False

    def __post_init__(self) -> None:
        if self.at not in _PLACEMENTS:
            raise OptionError(f"--terms at:{self.at}: friction acts at 'motor', 'joint' or 'both'")
        bad = [p for p in self.friction if p not in FRICTION_PARTS]
        if bad:
            raise OptionError(
                f"names unknown model term(s) {bad}; terms are armature, spring, "
                + ", ".join(FRICTION_PARTS)
                + " (or links for none)",
                field="terms",
            )
        parts = tuple(p for p in FRICTION_PARTS if p in self.friction)
        if "smooth" in parts and "coulomb" in parts:
            raise OptionError(": smooth replaces coulomb; give one of them", field="terms")
        object.__setattr__(self, "width", _one_or_per_joint(self.width))
        if "smooth" in parts and not self.width:
            object.__setattr__(self, "width", 1.0)
        object.__setattr__(self, "vst", _one_or_per_joint(self.vst, "stribeck"))
        if "stribeck" in parts and not self.vst:
            object.__setattr__(self, "vst", 0.05)
        if "stribeck" in parts and not {"coulomb", "smooth"} & set(parts):
            parts = tuple(p for p in FRICTION_PARTS if p in parts + ("coulomb",))
        object.__setattr__(self, "friction", parts)
        if not parts:
            object.__setattr__(self, "at", "")
        held = {PART_LABELS[p] for p in parts}
        if self.at == "both":
            held |= {JOINT_PREFIX + PART_LABELS[p] for p in self.joint_parts}
        if self.armature:
            held.add(ARMATURE_LABEL)
        if self.spring:  # a joint's spring left out: -k3
            held.add(SPRING_LABEL)
        drops = [ARMATURE_LABEL + d[2:] if d.lower().startswith("ia") else d for d in self.drop]
        object.__setattr__(self, "drop", tuple(drops))
        for lab in self.drop:
            prefix = lab.rstrip("0123456789")
            if prefix not in held:
                some = sorted(held)[0] if held else ""
                raise OptionError(
                    f"--terms -{lab}: {prefix or lab!r} is none of the coefficients of the "
                    + (
                        f"terms given ({', '.join(sorted(held))}); e.g. -{some}3 leaves out "
                        f"joint 3's {some}"
                        if held
                        else "terms given: they hold no friction and no armature"
                    )
                )
            if prefix == lab or not int(lab[len(prefix) :]) >= 1:
                raise OptionError(
                    f"--terms -{lab}: give the joint number from 1 after the label "
                    f"(-{prefix}3 leaves out joint 3's {prefix})"
                )
        object.__setattr__(self, "drop", tuple(sorted(set(self.drop), key=_label_order)))

    def without(self, labels: Collection[str]) -> Structure:
        """The same structure with those of the coefficients ``labels`` (``"fc3"``) that
        it holds left out too (:attr:`drop`); itself when it holds none of them."""
        held = {PART_LABELS[p] for p in self.friction}
        if self.at == "both":
            held |= {JOINT_PREFIX + PART_LABELS[p] for p in self.joint_parts}
        mine = tuple(
            lab
            for lab in sorted(labels, key=_label_order)
            if lab.rstrip("0123456789") in held and lab not in self.drop
        )
        return replace(self, drop=self.drop + mine) if mine else self

    def collapsed(self, n: int, joints: Sequence[int] = ()) -> Structure:
        """The same model with a part whose coefficients :attr:`drop` leaves out on every
        one of ``n`` joints removed from :attr:`friction` (``viscous + offset - fo1 - fo2``
        on two joints is ``viscous``); Coulomb friction stays with a Stribeck part. With
        ``at="both"`` a part held at the joints too goes only when also left out there on
        every one of ``joints`` (0-based, :func:`joint_side_joints`; none given: it stays)."""
        drop, parts = set(self.drop), list(self.friction)
        for p in reversed(self.friction):  # a Stribeck part before the Coulomb it goes with
            labels = {f"{PART_LABELS[p]}{j + 1}" for j in range(n)}
            if self.at == "both" and p in self.joint_parts:  # removed at both places
                labels |= {f"{JOINT_PREFIX}{PART_LABELS[p]}{j + 1}" for j in joints}
                labels |= set() if joints else {"the joints unknown"}
            if labels <= drop and not (p in ("coulomb", "smooth") and "stribeck" in parts):
                parts.remove(p)
                drop -= labels
        rotors = {f"{ARMATURE_LABEL}{j + 1}" for j in range(n)}
        armature = self.armature and not rotors <= drop
        drop -= set() if armature else rotors
        if len(parts) == len(self.friction) and armature == self.armature:
            return self
        width = self.width if "smooth" in parts else 0.0
        vst = self.vst if "stribeck" in parts else 0.0
        return replace(
            self, armature=armature, friction=tuple(parts), drop=tuple(drop), width=width, vst=vst
        )

    def widths(self, n: int) -> tuple[float, ...]:
        """The smooth Coulomb's width [bands] of each of ``n`` joints (motors).

        Raises
        ------
        OptionError
            Widths per joint given for another number of joints.
        """
        return _checked_per_joint(self.width, n, "smooth", "widths", "one width")

    def with_width(self, joint: int, width: float, n: int) -> Structure:
        """The same structure with the smooth Coulomb of ``joint`` (0-based, of ``n``) at
        ``width`` [bands], the other joints' as they are."""
        w = list(self.widths(n))
        w[joint] = float(width)
        return replace(self, width=tuple(w))

    def vsts(self, n: int) -> tuple[float, ...]:
        """The Stribeck velocity [rad/s] of each of ``n`` joints (motors).

        Raises
        ------
        OptionError
            Velocities per joint given for another number of joints.
        """
        return _checked_per_joint(self.vst, n, "stribeck", "Stribeck velocities", "one")

    def with_vst(self, joint: int, vst: float, n: int) -> Structure:
        """The same structure with the Stribeck velocity of ``joint`` (0-based, of ``n``)
        at ``vst`` [rad/s], the other joints' as they are."""
        v = list(self.vsts(n))
        v[joint] = float(vst)
        return replace(self, vst=tuple(v))

    def armature_mask(self, n: int) -> tuple[bool, ...]:
        """Which of the ``n`` rotor inertias the armature holds: all but :attr:`drop`
        (``Ia3``); empty when every one is.

        Raises
        ------
        OptionError
            A rotor of :attr:`drop` beyond ``n``.
        """
        mine = [lab for lab in self.drop if lab.startswith(ARMATURE_LABEL)]
        if not mine:
            return ()
        every = [f"{ARMATURE_LABEL}{j + 1}" for j in range(n)]
        beyond = [lab for lab in mine if lab not in every]
        if beyond:
            raise OptionError(f"--terms -{beyond[0]}: the arm has {n} joints")
        return tuple(lab not in mine for lab in every)

    def mask(self, n: int) -> tuple[bool, ...]:
        """Which of the ``len(friction) n`` coefficients (joint by joint, the parts in
        order) are held: all but :attr:`drop`; empty when every one is.

        Raises
        ------
        OptionError
            A coefficient of :attr:`drop` on a joint beyond ``n``.
        """
        return self._mask(n, "", range(n), self.friction)

    @property
    def joint_parts(self) -> tuple[str, ...]:
        """With ``at="both"``: the parts of the friction at the joints (all but the offset)."""
        return tuple(p for p in self.friction if p != "offset")

    def joint_mask(self, n: int, joints: Sequence[int]) -> tuple[bool, ...]:
        """With ``at="both"``: which coefficients the friction at the joints holds, the
        ``joints`` (0-based, :func:`joint_side_joints`) but :attr:`drop` (``jfc7``).

        Raises
        ------
        OptionError
            A coefficient of :attr:`drop` at the joints on a joint beyond ``n`` or on a
            joint that has no friction at the joint.
        """
        parts = self.joint_parts
        return self._mask(n, JOINT_PREFIX, joints, parts) or (True,) * (len(parts) * n)

    def _mask(
        self, n: int, prefix: str, joints: Sequence[int], parts: Sequence[str]
    ) -> tuple[bool, ...]:
        """The mask of the coefficients labelled ``prefix...`` on ``joints``, empty when
        every one of the ``n`` joints holds every part."""
        mine = [lab for lab in self.drop if lab.startswith(prefix + "f")]
        if not mine and len(joints) == n:
            return ()
        every = [f"{prefix}{PART_LABELS[p]}{j + 1}" for j in range(n) for p in parts]
        held = [f"{prefix}{PART_LABELS[p]}{j + 1}" for j in joints for p in parts]
        beyond = [lab for lab in mine if lab not in held]
        if beyond:
            where = " at the joints" if prefix else ""
            raise OptionError(
                f"--terms -{beyond[0]}: no such coefficient{where} (the arm has {n} joints"
                + (f"; friction at the joints on {[j + 1 for j in joints]})" if prefix else ")")
            )
        return tuple(lab in held and lab not in mine for lab in every)

    @property
    def terms(self) -> tuple[str, ...]:
        """The term names held, e.g. ``("armature", "viscous", "smooth:3")``."""
        shape = {
            "smooth": f"smooth:{width_text(self.width)}",
            "stribeck": f"stribeck:{width_text(self.vst)}",
        }
        where = (f"at:{self.at}",) if self.at and self.friction else ()
        return (
            (("armature",) if self.armature else ())
            + (("spring",) if self.spring else ())
            + tuple(shape.get(p, p) for p in self.friction)
            + where
            + tuple(f"-{lab}" for lab in self.drop)
        )

    @property
    def name(self) -> str:
        """``"links + armature + viscous"``; ``"links + viscous + offset - fo3"`` with a
        coefficient left out."""
        kept = [t for t in self.terms if not t.startswith("-")]
        return " + ".join(["links", *kept]) + "".join(f" - {lab}" for lab in self.drop)

    @classmethod
    def parse(cls, text: str) -> Structure:
        """From ``"armature,viscous,coulomb"`` (``"links"`` or ``""`` for none);
        ``smooth:W`` gives the smooth Coulomb's width in standstill bands (``smooth:W1/W2/..``
        one per joint or motor), ``stribeck:V`` the Stribeck velocity [rad/s]
        (``stribeck:V1/V2/..`` one per joint or motor), ``at:joint``
        or ``at:motor`` where the friction acts; ``spring`` a stiffness per joint.

        Raises
        ------
        OptionError
            An unknown term name or a shape that is not a positive number.
        """
        text = text.replace(" - ", ",-").replace("+", ",")
        words = [w.strip() for w in text.split(",") if w.strip()]
        words = [w for w in words if w != "links"]
        shapes: dict[str, tuple[float, ...]] = {}
        names = []
        at = ""
        drop = []
        for w in words:
            name, _, value = w.partition(":")
            if name == "at":
                at = value
                continue
            if name.startswith("-"):
                drop.append(name[1:].strip())
                continue
            if value:
                shapes[name] = _shape(w, name, value)
            names.append(name)
        return cls(
            armature="armature" in names,
            friction=tuple(w for w in names if w not in ("armature", "spring")),
            width=shapes["smooth"] if "smooth" in shapes else 0.0,
            vst=shapes.get("stribeck", 0.0),
            at=at,
            drop=tuple(drop),
            spring="spring" in names,
        )


def _shape(word: str, name: str, value: str) -> tuple[float, ...]:
    """The shape of the term ``word`` (``smooth:0.3/1``): positive numbers, one or (a
    smooth width, a Stribeck velocity) one per joint separated by ``/``.

    Raises
    ------
    OptionError
        A shape that is not a positive number, or several but of a smooth width or a
        Stribeck velocity.
    """
    parts = value.split("/")
    if len(parts) > 1 and name not in ("smooth", "stribeck"):
        raise OptionError(
            f"{word}: one shape; only smooth and stribeck take one per joint", field="terms"
        )
    try:
        out = tuple(float(x) for x in parts)
    except ValueError:
        out = (-1.0,)
    if not all(x > 0 and math.isfinite(x) for x in out):
        raise OptionError(
            f"{word}: the shape must be a positive number"
            + (" (one per joint separated by '/')" if len(parts) > 1 else ""),
            field="terms",
        )
    return out


def _one_or_per_joint(
    width: float | Sequence[float], name: str = "smooth"
) -> float | tuple[float, ...]:
    """A smooth width (a Stribeck velocity, ``name``) as :attr:`Structure.width`
    (:attr:`Structure.vst`) holds it: one float, or a tuple of floats when they differ."""
    if isinstance(width, (int, float, np.floating, np.integer)):
        return float(width)
    w = tuple(float(x) for x in width)
    if not all(x > 0 and math.isfinite(x) for x in w) or not w:
        raise OptionError(
            f"{name}:{width_text(w)}: the shapes must be positive numbers", field="terms"
        )
    return w[0] if len(set(w)) == 1 else w


def width_text(width: float | Sequence[float]) -> str:
    """A smooth width as ``--terms`` writes it: ``3``, or ``0.3/1/3`` one per joint."""
    if isinstance(width, (int, float)):
        return f"{width:g}"
    return "/".join(f"{x:g}" for x in width)


def width_key(width: float | Sequence[float]) -> tuple[float, ...]:
    """A sort key of smooth widths, one or per joint."""
    return (float(width),) if isinstance(width, (int, float)) else tuple(width)


def friction_placements(drive: Drive | None) -> tuple[str, ...]:
    """Where the candidates' friction may act: at the motors, at the joints or both for a
    drive whose transmission couples joints (a coupled wrist: one motor turns with two
    joints, so ``K^T f(K dq)`` and ``f(dq)`` are different models) and that does not say
    where itself (``friction_at`` not given); ``("",)``, where the drive says, otherwise
    (through a diagonal ``K`` both are the same model up to the units of the
    coefficients; a drive file's ``friction_at`` is the user's word)."""
    if drive is None or drive.friction_at is not None:
        return ("",)
    return ("motor", "joint", "both") if drive.is_coupled else ("",)


def joint_side_joints(drive: Drive) -> tuple[int, ...]:
    """The joints (0-based) that friction at the joints adds to friction at the motors:
    those that no motor turns alone. A motor whose row of ``K`` is ``k e_j`` puts
    ``k f(k dq_j)`` on joint ``j`` alone, the same columns as friction at joint ``j``, so
    such a joint's friction at the joint would repeat them."""
    K = np.asarray(drive.transmission)
    alone = {int(np.flatnonzero(row)[0]) for row in K if np.count_nonzero(row) == 1}
    return tuple(j for j in range(drive.n) if j not in alone)


def check_placement(structure: Structure, drive: Drive | None) -> None:
    """A friction placement (:attr:`Structure.at`) given by hand needs a drive that
    couples joints, the one case where friction at the motors and at the joints differ.

    Raises
    ------
    OptionError
        ``at`` without such a drive (``field`` ``terms``).
    """
    if structure.at and (drive is None or not drive.is_coupled):
        raise OptionError(
            f"at:{structure.at}: friction at the motors and at the joints differ only through "
            "a drive that couples joints; "
            + ("no drive given" if drive is None else "this drive couples none"),
            field="terms",
        )


def candidate_structures(
    armature: bool = True, placements: Sequence[str] = ("",)
) -> tuple[Structure, ...]:
    """The candidates, simplest first: every classical ladder of :data:`FRICTION_LADDER`,
    the smooth Coulomb at each of :data:`SMOOTH_WIDTHS` (with viscous friction, without
    and with offsets), the quadratic viscous law and the Stribeck law at each of
    :data:`STRIBECK_VELOCITIES` (with viscous friction, Coulomb friction and offsets; with
    the banded sign, and with the smooth sign at each of :data:`SMOOTH_STRIBECK_WIDTHS`:
    :func:`smooth_stribeck_candidates`; the search adds them at the width it chooses),
    without and (``armature``) with the armature, the friction at each of ``placements``
    (:func:`friction_placements`; the model without friction once; at ``"both"`` the
    classical ladder alone)."""
    arms = (False, True) if armature else (False,)
    out = []
    for a in arms:
        for i, at in enumerate(placements):
            out += [Structure(a, f, at=at if f else "") for f in FRICTION_LADDER if f or not i]
            if at == "both":
                continue
            out += [
                Structure(a, ("viscous", "smooth") + o, width=w, at=at)
                for o in ((), ("offset",))
                for w, _ in smooth_width_grid(())
            ]
            out.append(Structure(a, ("viscous", "quadratic", "coulomb", "offset"), at=at))
            out += [
                Structure(a, _CLASSICAL + ("stribeck",), vst=v, at=at) for v in STRIBECK_VELOCITIES
            ]
            out += [
                c
                for w in SMOOTH_STRIBECK_WIDTHS
                for c in smooth_stribeck_candidates(Structure(a, ("smooth",), w, at=at))
            ]
    return tuple(out)


def smooth_stribeck_candidates(
    smooth: Structure, vsts: Sequence[float] = STRIBECK_VELOCITIES
) -> tuple[Structure, ...]:
    """The smooth-sign Stribeck candidates (viscous friction, the smooth Coulomb with its
    bump, offsets) at the smooth width of ``smooth`` (one, or one per joint), with its
    armature and placement, at each Stribeck velocity of ``vsts`` [rad/s]."""
    parts = ("viscous", "smooth", "stribeck", "offset")
    return tuple(Structure(smooth.armature, parts, smooth.width, v, at=smooth.at) for v in vsts)


def smooth_width_grid(band: Sequence[float]) -> tuple[tuple[float, tuple[float, ...]], ...]:
    """The smooth Coulomb's candidate widths, the one grid of ``identify``'s structure
    search (:func:`candidate_structures`) and of ``dynid friction``'s smooth law
    (:func:`~dynid.friction.select.choose_smooth_width`): per factor of
    :data:`SMOOTH_WIDTHS` [standstill bands], narrowest first, the widths [rad/s] per
    joint of ``band`` (n,) [rad/s] (:func:`smooth_width`)."""
    return tuple((f, smooth_width(band, f)) for f in SMOOTH_WIDTHS)


def smooth_width(band: Sequence[float], factor: float | Sequence[float]) -> tuple[float, ...]:
    """The smooth Coulomb's width [rad/s] per joint: ``factor`` standstill bands (one for
    every joint, or one per joint), at least ``factor`` times :data:`MIN_WIDTH`."""
    k = (factor,) * len(band) if isinstance(factor, (int, float)) else tuple(factor)
    return tuple(f * max(float(b), MIN_WIDTH) for f, b in zip(k, band, strict=True))


def structure_terms(
    structure: Structure,
    drive: Drive | None,
    n: int,
    band: Sequence[float] = (),
    bands: Mapping[str, Sequence[float]] | None = None,
    gain: float = 1.0,
    rest: Sequence[float] = (),
) -> tuple[Drive | None, tuple[ModelTerm, ...]]:
    """The model's drive and terms of ``structure``: without a drive, an armature is the
    rotor inertia of a direct drive (``K = 1``); friction acts where the structure says
    (:attr:`Structure.at`: the drive's ``friction_at`` is set to it), with the velocity
    noise band [rad/s] of the raw velocities per motor (joint) where it acts:
    ``bands["motor"]`` or ``bands["joint"]``, else ``band``. The Coulomb sign's standstill
    band is ``gain`` times it (the noise the filtered velocities keep:
    :attr:`~dynid.identification.recordings.Recordings.band_gain`), and so does a smooth
    Coulomb's width. A spring acts about ``rest`` [rad] (n,) (default zeros; identify
    passes the middle of each joint's limits, zero for a joint without).

    Raises
    ------
    OptionError
        An armature asked of a drive whose rotor inertias are known (given in its file).
    """
    model_drive, terms = _rotor_terms(structure.armature, drive, n, structure.armature_mask(n))
    if structure.spring:
        q0 = tuple(float(x) for x in rest) if rest else (0.0,) * n
        terms.append(JointSpring(q0, mask=spring_mask(structure.drop, n)))
    if structure.friction:
        model_drive, at, b = _placed(structure.at, model_drive, n, band, bands)
        terms.append(
            LinearFriction(
                at,
                parts=structure.friction,
                band=_times(b, gain),
                width=smooth_width(_times(b, gain), structure.widths(n))
                if "smooth" in structure.friction
                else (),
                vst=structure.vst,
                mask=structure.mask(n),
            )
        )
        if structure.at == "both" and structure.joint_parts:
            jt, jb = _at_joints(at, n, band, bands)
            terms.append(
                LinearFriction(
                    jt,
                    parts=structure.joint_parts,
                    band=_times(jb, gain),
                    width=smooth_width(_times(jb, gain), structure.widths(n))
                    if "smooth" in structure.friction
                    else (),
                    vst=structure.vst,
                    name="joint friction",
                    mask=structure.joint_mask(n, joint_side_joints(at)),
                    prefix=JOINT_PREFIX,
                )
            )
    return model_drive, tuple(terms)


def _times(band: Sequence[float], gain: float) -> tuple[float, ...]:
    """``gain * band``, per joint."""
    return tuple(gain * float(b) for b in band)


def _at_joints(
    at: Drive, n: int, band: Sequence[float], bands: Mapping[str, Sequence[float]] | None
) -> tuple[Drive, tuple[float, ...]]:
    """The drive of the friction at the joints beside that at the motors of ``at``, and
    the standstill band at the joints."""
    b = tuple((bands or {}).get("joint", band))
    return replace(at, friction_at="joint"), b or (0.0,) * n


def _rotor_terms(
    armature: bool, drive: Drive | None, n: int, mask: tuple[bool, ...] = ()
) -> tuple[Drive | None, list[Any]]:
    """The model's drive and its rotor term (an armature without a drive: ``K = 1``), the
    rotors of ``mask`` (default all)."""
    model_drive = drive
    if armature and drive is None:
        model_drive = Drive.identity(n)
    terms: list[ModelTerm] = []
    if model_drive is not None and model_drive.identifies_rotor_inertia:
        if armature:
            terms.append(RotorInertia(model_drive, mask=mask))
    elif armature:
        raise OptionError(
            "the armature term identifies the rotor inertias, which the drive file gives; "
            "drop 'armature' from --terms or set rotor_inertia = \"identify\""
        )
    return model_drive, terms


def _placed(
    where: str,
    model_drive: Drive | None,
    n: int,
    band: Sequence[float],
    bands: Mapping[str, Sequence[float]] | None,
) -> tuple[Drive | None, Drive, tuple[float, ...]]:
    """The model's drive with its friction placed ``where``, the drive the friction term
    acts through, and the standstill band there."""
    at = Drive.identity(n) if model_drive is None else model_drive
    where = "motor" if where == "both" else where  # the friction at the joints beside it
    if where and model_drive is not None and where != model_drive.friction_place:
        model_drive = at = replace(model_drive, friction_at=where)  # type: ignore[arg-type]
    b = tuple((bands or {}).get(str(at.friction_place), band))
    return model_drive, at, b or (0.0,) * n


def largest_terms(
    cands: Sequence[Structure],
    arm: bool,
    drive: Drive | None,
    n: int,
    band: Sequence[float],
    bands: Mapping[str, Sequence[float]] | None = None,
    gain: float = 1.0,
    drop: Collection[str] = (),
    rest: Sequence[float] = (),
) -> tuple[Drive | None, list[tuple[ModelTerm, Any]]]:
    """The terms of every candidate with ``armature == arm`` at once (their friction at
    one place: :attr:`Structure.at`; bands as :func:`structure_terms`), each with what it
    stands for:
    ``("classical", parts)``, ``("smooth", width)``, ``("stribeck", vst)`` or
    ``("smooth_stribeck", (width, vst))`` (the bump alone: its smooth Coulomb term is the
    ``smooth`` one); a candidate is a choice of their columns. The friction coefficients
    labelled in ``drop`` (``"fc3"``: every term's) are left out of every term. A spring
    the candidates hold (``("spring", None)``) acts about ``rest`` [rad] (n,)."""
    mine = [c for c in cands if c.armature == arm]
    places = {c.at for c in mine if c.friction}
    if len(places) > 1:
        raise OptionError(f"largest_terms: one friction placement at a time; got {places}")
    model_drive, terms = _rotor_terms(arm, drive, n)
    model_drive, at, b = _placed(places.pop() if places else "", model_drive, n, band, bands)
    out: list[tuple[ModelTerm, Any]] = [(t, None) for t in terms]
    classical = tuple(p for p in _CLASSICAL + ("quadratic",) if any(p in c.friction for c in mine))
    if classical:
        t = LinearFriction(at, parts=classical, band=_times(b, gain))
        out.append((t, ("classical", t.parts)))  # the parts in the term's column order
    if classical and any(c.at == "both" for c in mine):
        jt, jb = _at_joints(at, n, band, bands)
        joints = joint_side_joints(at)
        parts = tuple(p for p in classical if p != "offset")
        mask = tuple(j in joints for j in range(n) for _ in parts)
        t = LinearFriction(
            jt,
            parts=parts,
            band=_times(jb, gain),
            name="joint friction",
            mask=mask,
            prefix=JOINT_PREFIX,
        )
        out.append((t, ("classical", t.parts)))
    for w in sorted({w for c in mine if "smooth" in c.friction for w in c.widths(n)}):
        t = LinearFriction(
            at,
            ("smooth",),
            band=_times(b, gain),
            width=smooth_width(_times(b, gain), w),
            name=f"friction smooth {w:g}",
        )
        out.append((t, ("smooth", w)))
    for v in vst_layers([c.vsts(n) for c in mine if _banded_stribeck(c)]):
        t = LinearFriction(
            at,
            ("stribeck",),
            band=_times(b, gain),
            vst=_positive(v),
            name=f"friction stribeck {width_text(v)}",
            mask=() if isinstance(v, float) else tuple(x > 0 for x in v),
        )
        out.append((t, ("stribeck", v)))
    bump_widths = {c.width for c in mine if _smooth_stribeck(c)}
    for bw in sorted(bump_widths, key=width_key):
        mine_w = [c.vsts(n) for c in mine if _smooth_stribeck(c) and c.width == bw]
        for v in vst_layers(mine_w):
            on = (True,) * n if isinstance(v, float) else tuple(x > 0 for x in v)
            t = LinearFriction(
                at,
                ("smooth", "stribeck"),
                band=_times(b, gain),
                width=smooth_width(_times(b, gain), bw),
                vst=_positive(v),
                name=f"friction smooth {width_text(bw)} stribeck {width_text(v)}",
                # the bump alone: the smooth Coulomb is the term above
                mask=tuple(x for h in on for x in (False, h)),
            )
            out.append((t, ("smooth_stribeck", (bw, v))))
    if drop:
        out = [(t if what is None else _without(t, drop), what) for t, what in out]
    if any(c.spring for c in mine):  # a fixed part: every candidate of a search holds it
        q0 = tuple(float(x) for x in rest) or (0.0,) * n
        out.append((JointSpring(q0, mask=spring_mask(mine[0].drop, n)), ("spring", None)))
    return model_drive, out


def _without(t: Any, drop: Collection[str]) -> Any:
    """The friction term ``t`` without its coefficients labelled in ``drop``."""
    every = [f"{t.prefix}{PART_LABELS[p]}{j + 1}" for j in range(t.drive.n) for p in t.parts]
    held = t.mask or (True,) * len(every)
    mask = tuple(h and lab not in drop for h, lab in zip(held, every, strict=True))
    return t if mask == tuple(held) else replace(t, mask=mask)


def regressor_group(c: Structure) -> tuple[bool, str, str]:
    """The candidates that share one regressor (:func:`largest_terms`): one per armature
    choice and friction placement (friction at the motors and at the joints of a coupled
    drive, together, would be dependent columns), the Stribeck laws apart: banded
    (``"stribeck"``) and on the smooth sign of each width (``"smooth_stribeck:0.3"``).
    Their bumps differ from each other only near rest, where the bump is 1 and the
    difference of two bumps that of two Coulomb columns, and a grid of Stribeck
    velocities holds close neighbours: together, or with the smooth laws, they would be
    nearly dependent columns, and the data's rank decision would cost every shaped law."""
    if _smooth_stribeck(c):
        return c.armature, c.at, f"smooth_stribeck:{width_text(c.width)}"
    return c.armature, c.at, "stribeck" if _banded_stribeck(c) else ""


def _banded_stribeck(c: Structure) -> bool:
    return "stribeck" in c.friction and "smooth" not in c.friction


def _smooth_stribeck(c: Structure) -> bool:
    return {"smooth", "stribeck"} <= set(c.friction)


def candidate_columns(structure: Structure, model: Any, terms: list[tuple[ModelTerm, Any]]) -> Any:
    """The columns (bool, over the base parameters and every appended term) of one
    candidate among the terms of :func:`largest_terms` of ``model`` (an identified model
    over them): the base parameters but the armature's rotors that :attr:`Structure.drop`
    leaves out (:func:`own_rotors`), the appended terms' columns the structure holds."""
    rotors = own_rotors(model.base, model.robot.n)
    base = np.ones(model.base.rank, dtype=bool)
    base[[rotors[lab] for lab in structure.drop if lab in rotors]] = False
    use = [base]
    for t, what in terms:
        if t.in_base or what is None:
            continue
        kind, shape = what
        if kind == "classical":
            part = {PART_LABELS[p]: p for p in shape}
            on = np.array([part[_stem(lab)] in structure.friction for lab in t.labels])
        elif kind == "smooth":  # one column per joint: those whose width it is
            held = "smooth" in structure.friction
            widths = structure.widths(len(t.labels)) if held else ()
            on = np.array([held and w == shape for w in widths or (0.0,) * len(t.labels)])
        elif kind == "spring":
            on = np.full(len(t.labels), structure.spring)
        elif kind == "stribeck":
            on = _at_vst(_banded_stribeck(structure), structure, shape, t)
        else:
            bw, v = shape
            on = _at_vst(_smooth_stribeck(structure) and structure.width == bw, structure, v, t)
        if structure.drop:
            on &= np.array([lab not in structure.drop for lab in t.labels])
        use.append(on)
    return np.concatenate(use)


def _at_vst(
    held: bool, structure: Structure, layer: float | tuple[float, ...], t: Any
) -> NDArray[np.bool_]:
    """Which columns of the Stribeck term ``t`` (of velocities ``layer`` [rad/s], one or
    one per joint) ``structure`` uses: none unless ``held``, else those of the joints
    whose Stribeck velocity ``layer`` holds."""
    n = t.drive.n
    if not held:
        return np.zeros(len(t.labels), dtype=bool)
    mine, theirs = structure.vsts(n), _per_joint(layer, n)
    return np.array([mine[_joint_of(lab)] == theirs[_joint_of(lab)] for lab in t.labels])


def _joint_of(label: str) -> int:
    """``fsp3`` -> 2: the 0-based joint (motor) of a coefficient's label."""
    return int(label[len(label.rstrip("0123456789")) :]) - 1


def _per_joint(v: float | tuple[float, ...], n: int) -> tuple[float, ...]:
    """One shape for every of ``n`` joints, or one per joint: one per joint."""
    return (v,) * n if isinstance(v, float) else v


def _positive(v: float | tuple[float, ...]) -> float | tuple[float, ...]:
    """A layer of :func:`vst_layers` with its empty places (0) at another joint's
    velocity: the term needs one everywhere, its mask leaves those columns out."""
    return v if isinstance(v, float) else tuple(x if x > 0 else max(v) for x in v)


def vst_layers(vsts: Sequence[tuple[float, ...]]) -> list[float | tuple[float, ...]]:
    """The Stribeck columns a regressor holds for candidates of Stribeck velocities
    ``vsts`` [rad/s] (one tuple per candidate, one per joint), as layers of velocities:
    layer ``k`` holds each joint's ``k``-th velocity (ascending) among the candidates',
    0 where a joint has fewer (its column left out); one number where every joint's is
    the same (the grid's laws: one layer per velocity, as many columns as joints). A
    candidate's columns are those of its own velocity on each joint
    (:func:`candidate_columns`)."""
    if not vsts:
        return []
    n = len(vsts[0])
    per = [sorted({v[j] for v in vsts}) for j in range(n)]
    out: list[float | tuple[float, ...]] = []
    for k in range(max(len(p) for p in per)):
        layer = tuple(p[k] if k < len(p) else 0.0 for p in per)
        out.append(layer[0] if len(set(layer)) == 1 else layer)
    return out


def column_labels(model: Any, terms: list[tuple[ModelTerm, Any]]) -> tuple[str, ...]:
    """The label of each column of :func:`candidate_columns` that a per-joint structure
    may leave out (the rotors of :func:`own_rotors`, ``Ia3``; the appended terms', ``fv1``,
    ``fc1`` at every width), ``""`` for the others (the links' base parameters)."""
    out = [""] * model.base.rank
    for lab, k in own_rotors(model.base, model.robot.n).items():
        out[k] = lab
    for t, what in terms:
        if not t.in_base and what is not None:
            out += t.labels
    return tuple(out)


def own_rotors(base: Any, n_links: int) -> dict[str, int]:
    """The armature's rotors that are base parameters of their own (``beta_k = Ia_j``, not
    regrouped with a link's ``Jzz``): label to base column. Only those a candidate can
    leave out."""
    p = 10 * n_links
    K_d = np.asarray(base.K_d)
    out = {}
    for k, idx in enumerate(np.asarray(base.independent)):
        if idx >= p and not np.any(K_d[k]):
            out[str(base.std_labels[idx])] = k
    return out


def _stem(label: str) -> str:
    """``jfv7`` -> ``fv``: a friction label without its prefix and joint."""
    return label.rstrip("0123456789").removeprefix(JOINT_PREFIX)


def coefficient_labels(structure: Structure, n: int, rotors: Sequence[str] = ()) -> tuple[str, ...]:
    """The labels of the coefficients ``structure`` holds on ``n`` joints (motors) that a
    per-joint structure may leave out, joint by joint: ``fv1, fc1, fv2, ...`` and, with the
    armature, its ``rotors`` (:func:`own_rotors`: ``Ia3``), those of :attr:`Structure.drop`
    left out."""
    every = [f"{PART_LABELS[p]}{j + 1}" for j in range(n) for p in structure.friction]
    every += list(rotors) if structure.armature else []
    return tuple(lab for lab in every if lab not in structure.drop)
