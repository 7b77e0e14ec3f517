"""The model's structure: which terms beside the links' parameters, and their columns.

A joint-torque log of a real arm holds more than the rigid links: the rotors' inertia
(an armature ``I_a ddq`` per joint, or the rotors of a drive), viscous and Coulomb friction,
torque offsets, friction laws with a shape (a smooth Coulomb's width, a Stribeck velocity).
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
from collections.abc import Sequence
from dataclasses import dataclass
from typing import Any

import numpy as np

from ..exceptions import OptionError
from ..model.drive import Drive
from ..regressors.terms import FRICTION_PARTS, LinearFriction, ModelTerm, RotorInertia

__all__ = [
    "ERROR_FLOOR_PERCENT",
    "FRICTION_LADDER",
    "MIN_WIDTH",
    "SMOOTH_WIDTHS",
    "STRIBECK_VELOCITIES",
    "Structure",
    "candidate_columns",
    "candidate_structures",
    "largest_terms",
    "smooth_width",
    "structure_terms",
]

#: Held-out errors [%] closer than this count as equal: the folds are judged through their
#: normal equations, whose round-off on exact data is near 1e-6 %.
ERROR_FLOOR_PERCENT = 1e-4

#: The classical friction candidates, simplest first.
FRICTION_LADDER: tuple[tuple[str, ...], ...] = (
    (),
    ("viscous",),
    ("viscous", "offset"),
    ("viscous", "coulomb"),
    ("viscous", "coulomb", "offset"),
)
#: Widths of the smooth Coulomb candidates, in multiples of each joint's standstill band
#: (at least :data:`MIN_WIDTH`): ``tanh(dq / w)`` reaches 76 % of ``fc`` at ``dq = w``.
SMOOTH_WIDTHS = (1.0, 3.0, 10.0)
#: Stribeck velocities [rad/s] of the Stribeck candidates.
STRIBECK_VELOCITIES = (0.02, 0.05, 0.1, 0.2)
#: Smallest smooth width [rad/s] (a noise-free log has no standstill band).
MIN_WIDTH = 1e-3

_CLASSICAL = ("viscous", "coulomb", "offset")


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
    width : float
        With ``smooth``: its width in multiples of each joint's standstill band.
    vst : float
        With ``stribeck``: the Stribeck velocity [rad/s].
    """

    armature: bool = False
    friction: tuple[str, ...] = _CLASSICAL
    width: float = 0.0
    vst: float = 0.0

    def __post_init__(self) -> None:
        bad = [p for p in self.friction if p not in FRICTION_PARTS]
        if bad:
            raise OptionError(
                f"names unknown model term(s) {bad}; terms are armature, "
                + ", ".join(FRICTION_PARTS)
                + " (or links for none)",
                field="terms",
            )
        parts = tuple(p for p in FRICTION_PARTS if p in self.friction)
        if "smooth" in parts and "coulomb" in parts:
            raise OptionError(": smooth replaces coulomb; give one of them", field="terms")
        if "smooth" in parts and not self.width > 0:
            object.__setattr__(self, "width", 1.0)
        if "stribeck" in parts and not self.vst > 0:
            object.__setattr__(self, "vst", 0.05)
        if "stribeck" in parts and "coulomb" not in parts:
            parts = tuple(p for p in FRICTION_PARTS if p in parts + ("coulomb",))
        object.__setattr__(self, "friction", parts)

    @property
    def terms(self) -> tuple[str, ...]:
        """The term names held, e.g. ``("armature", "viscous", "smooth:3")``."""
        shape = {"smooth": f"smooth:{self.width:g}", "stribeck": f"stribeck:{self.vst:g}"}
        return (("armature",) if self.armature else ()) + tuple(
            shape.get(p, p) for p in self.friction
        )

    @property
    def name(self) -> str:
        """``"links + armature + viscous"``."""
        return " + ".join(("links",) + self.terms)

    @classmethod
    def parse(cls, text: str) -> Structure:
        """From ``"armature,viscous,coulomb"`` (``"links"`` or ``""`` for none);
        ``smooth:W`` gives the smooth Coulomb's width in standstill bands, ``stribeck:V``
        the Stribeck velocity [rad/s].

        Raises
        ------
        OptionError
            An unknown term name or a shape that is not a positive number.
        """
        words = [w.strip() for w in text.replace("+", ",").split(",") if w.strip()]
        words = [w for w in words if w != "links"]
        shapes: dict[str, float] = {}
        names = []
        for w in words:
            name, _, value = w.partition(":")
            if value:
                try:
                    shapes[name] = float(value)
                except ValueError:
                    shapes[name] = -1.0
                if not shapes[name] > 0 or not math.isfinite(shapes[name]):
                    raise OptionError(f"{w}: the shape must be a positive number", field="terms")
            names.append(name)
        return cls(
            armature="armature" in names,
            friction=tuple(w for w in names if w != "armature"),
            width=shapes.get("smooth", 0.0),
            vst=shapes.get("stribeck", 0.0),
        )


def candidate_structures(armature: bool = True) -> tuple[Structure, ...]:
    """The candidates, simplest first: every classical ladder of :data:`FRICTION_LADDER`,
    the smooth Coulomb at each of :data:`SMOOTH_WIDTHS` (with viscous friction, without
    and with offsets), the quadratic viscous law and the Stribeck law at each of
    :data:`STRIBECK_VELOCITIES` (with viscous friction, Coulomb friction and offsets),
    without and (``armature``) with the armature."""
    arms = (False, True) if armature else (False,)
    out = []
    for a in arms:
        out += [Structure(a, f) for f in FRICTION_LADDER]
        out += [
            Structure(a, ("viscous", "smooth") + o, width=w)
            for o in ((), ("offset",))
            for w in SMOOTH_WIDTHS
        ]
        out.append(Structure(a, ("viscous", "quadratic", "coulomb", "offset")))
        out += [Structure(a, _CLASSICAL + ("stribeck",), vst=v) for v in STRIBECK_VELOCITIES]
    return tuple(out)


def smooth_width(band: Sequence[float], factor: float) -> tuple[float, ...]:
    """The smooth Coulomb's width [rad/s] per joint: ``factor`` standstill bands, at least
    ``factor`` times :data:`MIN_WIDTH`."""
    return tuple(factor * max(float(b), MIN_WIDTH) for b in band)


def structure_terms(
    structure: Structure, drive: Drive | None, n: int, band: Sequence[float] = ()
) -> tuple[Drive | None, tuple[ModelTerm, ...]]:
    """The model's drive and terms of ``structure``: without a drive, an armature is the
    rotor inertia of a direct drive (``K = 1``); friction acts where the drive says, with the
    standstill ``band`` [rad/s] per joint (motor).

    Raises
    ------
    OptionError
        An armature asked of a drive whose rotor inertias are known (given in its file).
    """
    model_drive = drive
    if structure.armature and drive is None:
        model_drive = Drive.identity(n)
    terms: list[ModelTerm] = []
    if model_drive is not None and model_drive.identifies_rotor_inertia:
        if structure.armature:
            terms.append(RotorInertia(model_drive))
    elif structure.armature:
        raise OptionError(
            "the armature term identifies the rotor inertias, which the drive file gives; "
            "drop 'armature' from --terms or set rotor_inertia = \"identify\""
        )
    if structure.friction:
        at = Drive.identity(n) if model_drive is None else model_drive
        b = tuple(band) if band else (0.0,) * n
        terms.append(
            LinearFriction(
                at,
                parts=structure.friction,
                band=b,
                width=smooth_width(b, structure.width) if "smooth" in structure.friction else (),
                vst=structure.vst,
            )
        )
    return model_drive, tuple(terms)


def largest_terms(
    cands: Sequence[Structure], arm: bool, drive: Drive | None, n: int, band: Sequence[float]
) -> tuple[Drive | None, list[tuple[ModelTerm, Any]]]:
    """The terms of every candidate with ``armature == arm`` at once, each with what it
    stands for: ``("classical", parts)``, ``("smooth", width)`` or ``("stribeck", vst)``;
    a candidate is a choice of their columns."""
    mine = [c for c in cands if c.armature == arm]
    model_drive, terms = structure_terms(Structure(arm, ()), drive, n, band)
    at = Drive.identity(n) if model_drive is None else model_drive
    b = tuple(band) if band else (0.0,) * n
    out: list[tuple[ModelTerm, Any]] = [(t, None) for t in terms]
    classical = tuple(p for p in _CLASSICAL + ("quadratic",) if any(p in c.friction for c in mine))
    if classical:
        t = LinearFriction(at, parts=classical, band=b)
        out.append((t, ("classical", t.parts)))  # the parts in the term's column order
    for w in sorted({c.width for c in mine if "smooth" in c.friction}):
        t = LinearFriction(
            at, ("smooth",), band=b, width=smooth_width(b, w), name=f"friction smooth {w:g}"
        )
        out.append((t, ("smooth", w)))
    for v in sorted({c.vst for c in mine if "stribeck" in c.friction}):
        t = LinearFriction(at, ("stribeck",), band=b, vst=v, name=f"friction stribeck {v:g}")
        out.append((t, ("stribeck", v)))
    return model_drive, out


def candidate_columns(
    structure: Structure, r: int, terms: list[tuple[ModelTerm, Any]], n: int
) -> Any:
    """The columns (bool, over the base parameters and every appended term) of one
    candidate among the terms of :func:`largest_terms`."""
    use = [np.ones(r, dtype=bool)]
    for t, what in terms:
        if t.in_base or what is None:
            continue
        kind, shape = what
        if kind == "classical":
            mask = np.array([p in structure.friction for p in shape])
            use.append(np.tile(mask, n))
        elif kind == "smooth":
            on = "smooth" in structure.friction and structure.width == shape
            use.append(np.full(len(t.labels), on))
        else:
            on = "stribeck" in structure.friction and structure.vst == shape
            use.append(np.full(len(t.labels), on))
    return np.concatenate(use)
