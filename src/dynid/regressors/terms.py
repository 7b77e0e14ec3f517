"""Model terms beyond the rigid links: regressor columns that identification stacks.

The joint torques of an arm are linear in every parameter of the model:

.. math:: \\tau = Y(q, \\dot q, \\ddot q)\\, \\phi + \\sum_t Y_t(q, \\dot q, \\ddot q)\\, \\theta_t

with ``Y`` the rigid-body regressor (:mod:`dynid.regressors.torque`) and one block ``Y_t``
per extra term ``t``. A term is an object with the :class:`ModelTerm` protocol: its labels
and units, its torque columns, its columns of the static regressor ``[tril M; g]`` (None when
it does not act at rest), whether it regroups with the link parameters (``in_base``: its
columns join the rigid-body ones before the base parameters are found, as a rotor inertia
regroups with its link's ``Izz``) and which of its parameters a physically consistent model
keeps non-negative, what it is (:meth:`ModelTerm.friction`: a friction law's parameters;
:meth:`ModelTerm.inertia`: rotor inertias; None for neither) and its place in files
(:attr:`ModelTerm.kind`, the key of :data:`TERM_KINDS`, and :meth:`ModelTerm.definition`).
Adding a term (a spring, a payload) is one class and its line in :data:`TERM_KINDS`
(``ARCHITECTURE.md``, "Adding a model term").

Terms of a :class:`~dynid.model.drive.Drive`:

* :class:`RotorInertia`: ``K^T diag(I_a) K ddq``, labels ``Ia1 .. Ia_n`` [kg m^2], in the
  base (the rotor of a base joint with a vertical axis regroups with link 1's ``J1zz``);
* :class:`LinearFriction`: ``K^T (f_v K dq + f_c sign(K dq) + f_o)`` per motor (or per joint
  with ``friction_at="joint"``), labels ``fv1, fc1, fo1, fv2, ...`` (Gaz et al. 2019, eq. 24
  at the motors); appended after the base parameters.

Rows are sample-major as everywhere (row ``k n + j`` of a stack is sample ``k``, joint ``j``).
"""

from __future__ import annotations

import functools
from collections.abc import Callable, Mapping
from dataclasses import dataclass, replace
from typing import Any, Protocol

import numpy as np
from numpy.typing import NDArray

from ..exceptions import OptionError
from ..model.drive import Drive
from ..model.stiffness import JointStiffness
from .friction_columns import distinct_rows, smooth_sign, standstill_sign, stribeck_decay
from .spring import JointSpring

__all__ = [
    "FRICTION_PARTS",
    "TERM_KINDS",
    "FrictionValues",
    "LinearFriction",
    "ModelTerm",
    "PART_LABELS",
    "RotorInertia",
    "base_term_columns",
    "drive_terms",
    "friction_labels",
    "term_from_definition",
]


@dataclass(frozen=True, slots=True, eq=False)
class FrictionValues:
    """A friction term's identified coefficients as the parameters of a registry law.

    The identification layer names the law; the friction layer makes the one friction type
    of it (:func:`dynid.friction.model.friction_of`).

    Attributes
    ----------
    law : str
        The registry law (:mod:`dynid.friction.laws`): ``"classical"`` (``fv, fc, fo``),
        ``"smooth"`` (``fv, fc, fo``, ``tanh(v / band)``), ``"quadratic"``
        (``fv, fq, fc, fo``) or ``"stribeck"`` (``fv, fc, fs, vst, fo``).
    params : ndarray, shape (n, k)
        The law's parameters per motor (joint), in its units.
    band : ndarray, shape (n,)
        The standstill band [rad/s] the law is evaluated with (the smooth law's width);
        zeros for the plain ``sign``.
    drive : Drive or None
        Where the law acts: None at the joints, a drive at its motors (``K^T f(K dq)``).
    """

    law: str
    params: NDArray[np.float64]
    band: NDArray[np.float64]
    drive: Drive | None = None


class ModelTerm(Protocol):
    """What identification needs of a model term (module docstring)."""

    @property
    def name(self) -> str:
        """Short name, unique in a model: its key in the model's terms, files and summaries."""
        ...

    @property
    def kind(self) -> str:
        """Its key in :data:`TERM_KINDS` (how a file names the class that reads it back)."""
        ...

    @property
    def in_base(self) -> bool:
        """True when it regroups with the link parameters (its columns enter the base)."""
        ...

    @property
    def labels(self) -> tuple[str, ...]:
        """One label per parameter."""
        ...

    @property
    def units(self) -> tuple[str, ...]:
        """One SI unit per parameter."""
        ...

    @property
    def nonnegative(self) -> NDArray[np.bool_]:
        """Parameters a physically consistent model keeps ``>= 0``."""
        ...

    def dissipation_rows(self, dq_max: NDArray[np.float64]) -> NDArray[np.float64]:
        """Rows ``G`` (m, p): a physically consistent model keeps ``G values >= 0`` beside
        :attr:`nonnegative` (friction that opposes the motion at the velocities the joints
        reach, ``dq_max`` (n,) [rad/s]); (0, p) for none. Linear in the coefficients, so
        a convex fit keeps them."""
        ...

    def torque_columns(
        self, q: NDArray[np.float64], dq: NDArray[np.float64], ddq: NDArray[np.float64]
    ) -> NDArray[np.float64]:
        """Joint-torque columns (B, n, p) of (B, n) joint states."""
        ...

    def static_columns(self, n_samples: int) -> NDArray[np.float64] | None:
        """Columns (p, n (n + 1) / 2 + n, N) of the static regressor, or None."""
        ...

    def momentum_columns(
        self, q: NDArray[np.float64], dq: NDArray[np.float64]
    ) -> NDArray[np.float64]:
        """Columns (B, n, p) of the term's part of the generalized momentum ``M dq`` of
        (B, n) joint states, per unit coefficient (the momentum observer's regressor);
        zeros for a term without inertia."""
        ...

    def friction(self, values: NDArray[np.float64]) -> FrictionValues | None:
        """The coefficients (p,) as a friction law's parameters; None: not friction."""
        ...

    def inertia(self, values: NDArray[np.float64]) -> NDArray[np.float64] | None:
        """The coefficients (p,) as rotor inertias [kg m^2] at the motors of the model's
        drive; None: not rotor inertias."""
        ...

    def stiffness(self, values: NDArray[np.float64]) -> JointStiffness | None:
        """The coefficients (p,) as joint springs (stiffness and rest position); None: not
        a spring."""
        ...

    def definition(self) -> dict[str, Any]:
        """JSON-ready: what :data:`TERM_KINDS` needs beside the model's drive to rebuild it."""
        ...


def friction_labels(n: int) -> tuple[str, ...]:
    """``fv1, fc1, fo1, fv2, ...`` for ``n`` joints (or motors)."""
    return tuple(f"{k}{j + 1}" for j in range(n) for k in ("fv", "fc", "fo"))


@dataclass(frozen=True, slots=True, eq=False)
class RotorInertia:
    """Rotor inertias ``I_a`` [kg m^2] at the motors: ``K^T diag(I_a) K ddq``.

    Attributes
    ----------
    drive : Drive
        The transmission ``K`` (a direct drive for an armature ``I_a ddq`` per joint).
    mask : tuple of bool
        Which of the ``n`` rotors the term holds (a joint without armature: False, its
        inertia 0); empty: all.
    """

    drive: Drive
    name: str = "rotor_inertia"
    in_base: bool = True
    kind: str = "rotor_inertia"
    mask: tuple[bool, ...] = ()

    def __post_init__(self) -> None:
        if self.mask and len(self.mask) != self.drive.n:
            raise OptionError(f"mask must have {self.drive.n} entries; got {len(self.mask)}")

    @property
    def _held(self) -> NDArray[np.bool_]:
        """(n,): the rotors held."""
        return np.asarray(self.mask, dtype=bool) if self.mask else np.ones(self.drive.n, bool)

    @property
    def labels(self) -> tuple[str, ...]:
        """``Ia1 .. Ia_n`` (the rotors held)."""
        return tuple(lab for lab, h in zip(self.drive.rotor_labels, self._held, strict=True) if h)

    @property
    def units(self) -> tuple[str, ...]:
        """kg m^2 each."""
        return ("kg m^2",) * len(self.labels)

    @property
    def nonnegative(self) -> NDArray[np.bool_]:
        """Every rotor inertia is ``>= 0``."""
        return np.ones(len(self.labels), dtype=bool)

    def dissipation_rows(self, dq_max: NDArray[np.float64]) -> NDArray[np.float64]:
        """(0, p): nothing beside :attr:`nonnegative`."""
        return np.zeros((0, len(self.labels)))

    def torque_columns(
        self, q: NDArray[np.float64], dq: NDArray[np.float64], ddq: NDArray[np.float64]
    ) -> NDArray[np.float64]:
        """(B, n, p): column ``k`` is ``K[k]^T (K[k] . ddq)`` (the rotors held)."""
        return self.drive.rotor_columns(ddq)[..., self._held]

    def momentum_columns(
        self, q: NDArray[np.float64], dq: NDArray[np.float64]
    ) -> NDArray[np.float64]:
        """(B, n, p): column ``k`` is ``K[k]^T (K[k] . dq)``, rotor ``k``'s momentum at
        the joints (the rotors held); constant inertia, so the torque is its derivative."""
        return self.drive.rotor_columns(dq)[..., self._held]

    def static_columns(self, n_samples: int) -> NDArray[np.float64]:
        """(p, s, N): ``tril(K[k] K[k]^T)`` in the rows of ``M``, zero in those of ``g``."""
        n = self.drive.n
        i, j = np.tril_indices(n)
        C = np.zeros((n, i.size + n, n_samples))
        C[:, : i.size, :] = self.drive.rotor_mass_columns()[:, i, j][:, :, None]
        return C[self._held]

    def friction(self, values: NDArray[np.float64]) -> None:
        """None: not friction."""
        return None

    def inertia(self, values: NDArray[np.float64]) -> NDArray[np.float64]:
        """The rotor inertias ``I_a`` (n,) [kg m^2]: the values, 0 for the rotors not held."""
        out = np.zeros(self.drive.n)
        out[self._held] = values
        return out

    def stiffness(self, values: NDArray[np.float64]) -> None:
        """None: not a spring."""
        return None

    def definition(self) -> dict[str, Any]:
        """``mask`` (the model's drive is all it needs beside it)."""
        return {"mask": list(self.mask)}

    @classmethod
    def from_definition(
        cls, name: str, definition: Mapping[str, Any], drive: Drive | None, n: int
    ) -> RotorInertia:
        """Rebuilt for the model's ``drive`` (a direct drive of ``n`` joints when None)."""
        mask = tuple(bool(x) for x in definition.get("mask", ()))
        return cls(Drive.identity(n) if drive is None else drive, name=name, mask=mask)


#: The parts of :class:`LinearFriction`, in column order: viscous ``fv v``, quadratic
#: viscous ``fq v |v|``, Coulomb
#: ``fc s(v)`` (0 inside the standstill band), smooth Coulomb ``fc tanh(v / w)`` (instead
#: of ``coulomb``), the Stribeck bump ``(fs - fc) s(v) exp(-(v / v_st)^2)`` (beside
#: ``coulomb``) and the offset ``fo`` (:mod:`dynid.regressors.friction_columns`).
FRICTION_PARTS = ("viscous", "quadratic", "coulomb", "smooth", "stribeck", "offset")
#: The label of each part's coefficients (``fv3``: joint 3's viscous friction).
PART_LABELS = {"viscous": "fv", "quadratic": "fq", "coulomb": "fc", "smooth": "fc"}
PART_LABELS |= {"stribeck": "fsp", "offset": "fo"}
_PART_UNIT = {p: "N m" for p in FRICTION_PARTS}
#: Velocities checked evenly (and as many geometrically) by
#: :meth:`LinearFriction.dissipation_rows`, and the velocity limit [rad/s] it assumes for a
#: joint without one.
DISSIPATION_GRID = 16
DISSIPATION_VMAX = 10.0
_PART_UNIT |= {"viscous": "N m s/rad", "quadratic": "N m s^2/rad^2"}


@functools.lru_cache(maxsize=256)
def _friction_labels(
    prefix: str, n: int, parts: tuple[str, ...], mask: tuple[bool, ...]
) -> tuple[str, ...]:
    """The labels of :attr:`LinearFriction.labels` (the structure search asks a term's
    thousands of times): the parts per joint (motor), those of ``mask`` (empty: all)."""
    every = [f"{prefix}{PART_LABELS[p]}{j + 1}" for j in range(n) for p in parts]
    if not mask:
        return tuple(every)
    return tuple(lab for lab, h in zip(every, mask, strict=True) if h)


@dataclass(frozen=True, slots=True, eq=False)
class LinearFriction:
    """Friction linear in its coefficients, where the drive says (motors or joints).

    Attributes
    ----------
    drive : Drive
        Where the friction acts (its motors, or the joints with ``friction_at="joint"``).
    parts : tuple of str
        Which of :data:`FRICTION_PARTS` the term holds (default viscous, Coulomb and offset:
        eq. 24 of Gaz et al. 2019); ``smooth`` replaces ``coulomb``, ``stribeck`` goes
        with it.
    band : tuple of float
        Standstill band [rad/s] per motor (joint): ``s(v)`` is 0 where ``|v|`` is inside
        it; empty for none (the plain ``sign``).
    width : tuple of float
        The smooth Coulomb's width ``w`` [rad/s] per motor (joint), with ``smooth``.
    vst : float or tuple of float
        The Stribeck velocity [rad/s], with ``stribeck``: one for every motor (joint), or
        one per motor (joint) in order (a tuple whose velocities are all equal is the one).
    name : str
        The term's name (``"friction"``; another for a second friction term of a model).
    mask : tuple of bool
        Which of the ``k n`` coefficients (motor by motor, the parts in order) the term
        holds, when a motor (joint) holds fewer parts than ``parts``; empty: all. The
        coefficients left out are 0 in :meth:`as_array`.
    prefix : str
        Put before every label (``"j"``: ``jfv7``), for a second friction term of a model
        (friction at the joints beside friction at the motors).
    """

    drive: Drive
    parts: tuple[str, ...] = ("viscous", "coulomb", "offset")
    band: tuple[float, ...] = ()
    width: tuple[float, ...] = ()
    vst: float | tuple[float, ...] = 0.0
    name: str = "friction"
    in_base: bool = False
    mask: tuple[bool, ...] = ()
    kind: str = "linear_friction"
    prefix: str = ""

    def __post_init__(self) -> None:
        if not self.parts or any(p not in FRICTION_PARTS for p in self.parts):
            raise OptionError(f"friction parts must be among {FRICTION_PARTS}; got {self.parts}")
        if "smooth" in self.parts and "coulomb" in self.parts:
            raise OptionError("friction parts: smooth replaces coulomb; give one of them")
        if "quadratic" in self.parts and {"smooth", "stribeck"} & set(self.parts):
            raise OptionError(
                "friction parts: quadratic and smooth or stribeck are laws of their own; give one"
            )
        for key, v in (("band", self.band), ("width", self.width)):
            if v and len(v) != self.drive.n:
                raise OptionError(f"{key} must have {self.drive.n} entries; got {len(v)}")
        if "smooth" in self.parts and not self.width:
            raise OptionError("the smooth Coulomb part needs its width (one per joint)")
        if not isinstance(self.vst, float):
            v = tuple(float(x) for x in np.ravel(self.vst))
            if len(v) != self.drive.n and len(v) != 1:
                raise OptionError(f"vst must have 1 or {self.drive.n} entries; got {len(v)}")
            object.__setattr__(self, "vst", v[0] if len(set(v)) == 1 else v)
        if "stribeck" in self.parts and not min(self.vsts) > 0:
            raise OptionError(f"the Stribeck part needs a Stribeck velocity > 0; got {self.vst}")
        order = tuple(p for p in FRICTION_PARTS if p in self.parts)
        if self.mask:
            if len(self.mask) != len(self.parts) * self.drive.n:
                raise OptionError(
                    f"mask must have {len(self.parts) * self.drive.n} entries; got {len(self.mask)}"
                )
            grid = np.reshape(np.asarray(self.mask, dtype=bool), (self.drive.n, -1))
            index = [self.parts.index(p) for p in order]  # the mask in the parts' order
            object.__setattr__(self, "mask", tuple(bool(x) for x in grid[:, index].ravel()))
        object.__setattr__(self, "parts", order)

    @property
    def vsts(self) -> tuple[float, ...]:
        """The Stribeck velocity [rad/s] of each motor (joint)."""
        if isinstance(self.vst, float):
            return (self.vst,) * self.drive.n
        return self.vst

    @property
    def _held(self) -> NDArray[np.bool_]:
        """(k n,): the coefficients held (:attr:`mask`, or all)."""
        if self.mask:
            return np.asarray(self.mask, dtype=bool)
        return np.ones(len(self.parts) * self.drive.n, dtype=bool)

    @property
    def law(self) -> str:
        """The registry law the coefficients are parameters of (:meth:`as_array`):
        ``"smooth_stribeck"`` (a Stribeck part beside the smooth Coulomb), ``"stribeck"``,
        ``"smooth"``, ``"quadratic"`` or ``"classical"``."""
        if {"smooth", "stribeck"} <= set(self.parts):
            return "smooth_stribeck"
        for law in ("stribeck", "smooth", "quadratic"):
            if law in self.parts:
                return law
        return "classical"

    @property
    def law_band(self) -> tuple[float, ...]:
        """The band the law is evaluated with: the smooth law's width, else the band."""
        return self.width if "smooth" in self.parts else self.band

    @property
    def labels(self) -> tuple[str, ...]:
        """``fv1, fc1, fo1, fv2, ...`` (the parts held, per joint or motor)."""
        return _friction_labels(self.prefix, self.drive.n, self.parts, self.mask)

    @property
    def units(self) -> tuple[str, ...]:
        """N m s/rad for ``fv``, N m for the others, per joint (motor)."""
        every = tuple(_PART_UNIT[p] for p in self.parts) * self.drive.n
        return tuple(u for u, h in zip(every, self._held, strict=True) if h)

    @property
    def nonnegative(self) -> NDArray[np.bool_]:
        """The viscous ``fv`` and the Coulomb level ``fc`` (plain or smooth) are ``>= 0``.

        Not sign-constrained: the offset ``fo`` (a constant torque, not friction of the
        motion), the Stribeck excess ``fsp = fs - fc`` (friction that rises from its
        standstill level, ``fs < fc``, is physical as well as a breakaway peak) and the
        quadratic viscous ``fq`` (a viscous friction that saturates within the limits):
        what keeps these physical is :meth:`dissipation_rows`.
        """
        free = ("offset", "stribeck", "quadratic")
        return np.tile([p not in free for p in self.parts], self.drive.n)[self._held]

    def dissipation_rows(self, dq_max: NDArray[np.float64]) -> NDArray[np.float64]:
        """Rows ``G`` (m, p): ``G values >= 0`` says the friction opposes the motion,
        ``f(v) >= 0`` for ``0 < v <= v_max`` of every motor (joint), the offset left aside
        (its column is zero in ``G``: a constant torque of either sign, not friction; every
        other part is odd in ``v``, so the negative velocities follow).

        ``v_max`` of a motor is ``sum_j |K_mj| dq_max_j`` (:data:`DISSIPATION_VMAX` [rad/s]
        where a joint has no limit); the velocities checked: :data:`DISSIPATION_GRID` evenly
        up to ``v_max`` and as many spaced geometrically from ``1e-4 v_max`` (the Stribeck
        bump near standstill), those inside the standstill band left out (``f = 0`` there).
        """
        n, k = self.drive.n, len(self.parts)
        K = np.abs(np.asarray(self.drive.friction_transmission, dtype=np.float64))
        limit = np.broadcast_to(np.asarray(dq_max, dtype=np.float64), (K.shape[1],))
        limit = np.where(np.isfinite(limit), limit, DISSIPATION_VMAX)
        vmax = np.array([float(np.sum(K[m] * limit)) for m in range(n)])
        g = DISSIPATION_GRID
        unit = np.concatenate([np.linspace(1.0 / g, 1.0, g), np.geomspace(1e-4, 1.0, g)])
        v = unit[:, None] * vmax[None, :]  # (s, n)
        band = np.asarray(self.band, dtype=np.float64) if self.band else np.zeros(n)
        F = self.part_columns(v)  # (s, n, k)
        if "offset" in self.parts:  # not friction: the constant torque is of either sign
            F[..., self.parts.index("offset")] = 0.0
        rows = []
        for m in range(n):
            moving = v[:, m] > band[m]
            G = np.zeros((int(moving.sum()), n * k))
            G[:, m * k : (m + 1) * k] = F[moving, m, :]
            rows.append(G)
        every = np.concatenate(rows) if rows else np.zeros((0, n * k))
        G = every[:, self._held]
        return distinct_rows(G[np.any(G != 0.0, axis=1)])

    def part_columns(self, v: NDArray[np.float64]) -> NDArray[np.float64]:
        """(..., n, k): each part's column (:attr:`parts` in order) at the motor (joint)
        velocities ``v`` (..., n), with the term's standstill band and width."""
        n = v.shape[-1]
        band = np.asarray(self.band, dtype=np.float64) if self.band else np.zeros(n)

        def sign() -> NDArray[np.float64]:  # the Coulomb part's sign, which the bump shares
            if "smooth" in self.parts:
                return smooth_sign(v, np.asarray(self.width))
            return standstill_sign(v, band)

        col = {
            "viscous": lambda: v,
            "quadratic": lambda: v * np.abs(v),
            "coulomb": lambda: standstill_sign(v, band),
            "smooth": lambda: smooth_sign(v, np.asarray(self.width)),
            "stribeck": lambda: sign() * stribeck_decay(v, np.asarray(self.vsts)),
            "offset": lambda: np.ones_like(v),
        }
        return np.stack([col[p]() for p in self.parts], axis=-1)

    @property
    def needs_motion(self) -> NDArray[np.intp]:
        """(p,): the motor (joint) whose motion each column needs, -1 for none (the offset)."""
        k = len(self.parts)
        j = np.repeat(np.arange(self.drive.n), k)
        every = np.where(np.tile([p != "offset" for p in self.parts], self.drive.n), j, -1)
        return every[self._held]

    @property
    def steps(self) -> NDArray[np.bool_]:
        """(p,): the columns that step where the velocity reverses (Coulomb, smooth
        Coulomb, Stribeck), which a torque filtered at a cut-off sees rounded
        (:func:`~dynid.identification.classical.parallel_filtered`)."""
        steps = np.tile([p in ("coulomb", "smooth", "stribeck") for p in self.parts], self.drive.n)
        return steps[self._held]

    def as_array(self, params: NDArray[np.float64]) -> NDArray[np.float64]:
        """The coefficients (p,) as the parameters (n, k) of :attr:`law`: ``fv, fc, fo``
        (classical, smooth), ``fv, fq, fc, fo`` (quadratic) or ``fv, fc, fs, vst, fo``
        (Stribeck, ``fs = fc + fsp``); 0 for parts not held."""
        n, k = self.drive.n, len(self.parts)
        every = np.zeros(n * k)
        every[self._held] = params
        c = dict(zip(self.parts, np.reshape(every, (n, k)).T, strict=True))
        z = np.zeros(n)
        fc = c.get("coulomb", c.get("smooth", z))
        if "stribeck" in self.parts:
            cols = [c.get("viscous", z), fc, fc + c["stribeck"], np.array(self.vsts)]
            return np.column_stack(cols + [c.get("offset", z)])
        if self.law == "quadratic":
            return np.column_stack([c.get("viscous", z), c["quadratic"], fc, c.get("offset", z)])
        return np.column_stack([c.get("viscous", z), fc, c.get("offset", z)])

    def torque_columns(
        self, q: NDArray[np.float64], dq: NDArray[np.float64], ddq: NDArray[np.float64]
    ) -> NDArray[np.float64]:
        """(B, n, k n): motor ``m``'s columns of the parts held at ``v = (K dq)_m``,
        mapped by ``K^T`` onto the joints (``K = 1`` at the joints)."""
        return self.placed(self.part_columns(self.drive.motor_velocities(dq)))

    def placed(self, parts: NDArray[np.float64]) -> NDArray[np.float64]:
        """(B, n, p): the columns of :meth:`part_columns` ``parts`` (B, n, k), each motor's
        in its own columns, mapped by ``K^T`` onto the joints (a linear map: a part
        filtered along time gives the columns filtered)."""
        n, k = parts.shape[-2], len(self.parts)
        F = np.zeros(parts.shape[:-1] + (k * n,))
        m = np.arange(n)
        for i in range(k):
            F[..., m, k * m + i] = parts[..., i]
        if self.mask:
            F = F[..., self._held]
        if self.drive.friction_place == "joint":
            return F
        return np.einsum("mj,...mc->...jc", self.drive.transmission, F)

    def momentum_columns(
        self, q: NDArray[np.float64], dq: NDArray[np.float64]
    ) -> NDArray[np.float64]:
        """(B, n, p) zeros: friction holds no momentum."""
        return np.zeros(np.shape(dq) + (len(self.labels),))

    def static_columns(self, n_samples: int) -> None:
        """None: friction does not act at rest."""
        return None

    def friction(self, values: NDArray[np.float64]) -> FrictionValues:
        """The coefficients (p,) as the parameters of :attr:`law` (:meth:`as_array`), with
        its band and where it acts."""
        n = self.drive.n
        band = np.asarray(self.law_band, dtype=np.float64) if self.law_band else np.zeros(n)
        at_motors = self.drive.friction_place == "motor"
        return FrictionValues(
            self.law, self.as_array(np.asarray(values)), band, self.drive if at_motors else None
        )

    def inertia(self, values: NDArray[np.float64]) -> None:
        """None: not rotor inertias."""
        return None

    def values_of(self, params: NDArray[np.float64]) -> NDArray[np.float64]:
        """The coefficients (p,) of the law's parameters (n, k): the inverse of
        :meth:`as_array` (``fsp = fs - fc``)."""
        P = np.asarray(params, dtype=np.float64)
        names: dict[str, tuple[str, ...]] = {"classical": ("fv", "fc", "fo")}
        names |= {"smooth": ("fv", "fc", "fo"), "quadratic": ("fv", "fq", "fc", "fo")}
        names["stribeck"] = names["smooth_stribeck"] = ("fv", "fc", "fs", "vst", "fo")
        col = dict(zip(names[self.law], P.T, strict=True))
        part = {"viscous": col["fv"], "coulomb": col["fc"], "smooth": col["fc"]}
        part |= {"offset": col["fo"], "quadratic": col.get("fq"), "stribeck": None}
        if "stribeck" in self.parts:
            part["stribeck"] = col["fs"] - col["fc"]
        every = np.column_stack([part[p] for p in self.parts]).ravel()
        return every[self._held]

    def stiffness(self, values: NDArray[np.float64]) -> None:
        """None: not a spring."""
        return None

    def definition(self) -> dict[str, Any]:
        """``parts``, ``band``, ``width``, ``vst`` (one number, or a list of one per motor
        or joint), ``mask``, ``at`` (``"motor"`` or ``"joint"``: where it acts) and
        ``prefix``."""
        return {
            "parts": list(self.parts),
            "band": list(self.band),
            "width": list(self.width),
            "vst": self.vst if isinstance(self.vst, float) else list(self.vst),
            "mask": list(self.mask),
            "at": self.drive.friction_place,
            "prefix": self.prefix,
        }

    @classmethod
    def from_definition(
        cls, name: str, definition: Mapping[str, Any], drive: Drive | None, n: int
    ) -> LinearFriction:
        """Rebuilt acting where ``definition["at"]`` says, through the model's ``drive`` (a
        direct drive of ``n`` joints when None)."""
        d = dict(definition)
        at = Drive.identity(n) if drive is None else drive
        if d.get("at", at.friction_place) != at.friction_place:
            at = replace(at, friction_at=d["at"])
        return cls(
            at,
            parts=tuple(str(p) for p in d.get("parts", ("viscous", "coulomb", "offset"))),
            band=tuple(float(x) for x in d.get("band", ())),
            width=tuple(float(x) for x in d.get("width", ())),
            vst=_vst_of(d.get("vst", 0.0)),
            name=name,
            mask=tuple(bool(x) for x in d.get("mask", ())),
            prefix=str(d.get("prefix", "")),
        )


def _vst_of(value: Any) -> float | tuple[float, ...]:
    """A Stribeck velocity [rad/s] as a file holds it: one number (every file before the
    velocity per joint), or a list of one per motor (joint)."""
    if isinstance(value, (list, tuple)):
        return tuple(float(x) for x in value)
    return float(value)


def drive_terms(drive: Drive | None, n: int, *, friction: bool = True) -> tuple[ModelTerm, ...]:
    """The extra terms of an arm of ``n`` joints: the rotor inertia of a drive (when it is
    identified) and, with ``friction``, linear friction where the drive says (at the joints
    without a drive)."""
    terms: list[ModelTerm] = []
    if drive is not None and drive.identifies_rotor_inertia:
        terms.append(RotorInertia(drive))
    if friction:
        terms.append(LinearFriction(Drive.identity(n) if drive is None else drive))
    return tuple(terms)


def base_term_columns(
    terms: tuple[ModelTerm, ...], independent: NDArray[np.intp], n_links: int
) -> list[tuple[ModelTerm, NDArray[np.intp]]]:
    """Which parameters of each ``in_base`` term are independent base columns.

    The standard parameters of a base continue after the ``10 n_links`` link parameters
    with the labels of the ``in_base`` terms in order (:func:`dynid.regressors.base.
    base_parameters`); returns each such term with the indices of its own parameters that
    are in ``independent``, in that order.
    """
    ind = np.asarray(independent, dtype=np.intp)
    start, out = 10 * n_links, []
    for t in terms:
        if t.in_base:
            k = len(t.labels)
            out.append((t, ind[(ind >= start) & (ind < start + k)] - start))
            start += k
    return out


#: Reads a term back from a file: ``(name, definition, the model's drive, n joints)``.
TermReader = Callable[[str, Mapping[str, Any], Drive | None, int], ModelTerm]

#: Every kind of model term, by :attr:`ModelTerm.kind`: its reader from files.
TERM_KINDS: dict[str, TermReader] = {
    "rotor_inertia": RotorInertia.from_definition,
    "linear_friction": LinearFriction.from_definition,
    "joint_spring": JointSpring.from_definition,
}


def term_from_definition(
    kind: str, name: str, definition: Mapping[str, Any], drive: Drive | None, n: int
) -> ModelTerm:
    """The term of ``kind`` (:data:`TERM_KINDS`) rebuilt from its :meth:`~ModelTerm.definition`.

    Raises
    ------
    OptionError
        An unknown kind.
    """
    if kind not in TERM_KINDS:
        raise OptionError(f"unknown model term kind {kind!r}; known: {sorted(TERM_KINDS)}")
    return TERM_KINDS[kind](name, definition, drive, n)
