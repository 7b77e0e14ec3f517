"""Column mapping and unit scaling for torque logs and static data of other tools.

A :class:`ColumnMap` names, per quantity, the column template of a file and its unit:

* quantities: torque logs ``t, q, dq, tau, ddq``; static data ``q, M, g``;
* templates: ``{i}`` is the joint number from 1, ``{i0}`` from 0 (``position_{i0}``
  reads ``position_0 .. position_{n-1}``); ``M`` needs a row and a column index,
  ``{i}``/``{j}`` or ``{i0}``/``{j0}`` (either triangle, or both: a full matrix is
  checked for symmetry by the data set), or one flat index of the whole matrix, ``{k0}``
  from 0 or ``{k}`` from 1, column-major (``k0 = i0 + n j0``, as libfranka's
  ``std::array<double, 49>`` and Eigen store it: ``M=M{k0}`` reads ``M0 .. M48``; every
  entry read, so symmetry is checked); a template of ``M`` with one index alone is
  refused (it would read one column per row). A quantity not mapped keeps dynid's name
  (``q{i}``, ``tau{i}``, ``M{i}_{j}``, ...). In an NPZ file a template names an array;
* units (converted to SI on reading): ``t`` in ``s, ms, us, ns``; ``q`` in ``rad, deg``
  (``m, mm`` for prismatic joints); ``dq`` in ``rad/s, deg/s`` (``m/s, mm/s``); ``ddq``
  in ``rad/s^2, deg/s^2`` (``m/s^2, mm/s^2``): once the robot is known
  (:meth:`ColumnMap.for_robot`) a length unit scales the prismatic joints' columns alone,
  an angle unit the revolute joints' alone, and a quantity given twice, one length and one
  angle unit (``q=mm,q=deg``; in TOML a list, ``q = ["mm", "deg"]``), reads each kind of
  joint in its own; ``tau`` and ``g`` in ``Nm, N m, N, mNm,
  mN m``, ``tau`` also in ``A, mA`` (motor currents, read through a drive whose effort
  is current); ``M`` in ``kg m^2, g m^2``; or a number, the factor to SI. A unit given
  is the user's word, not a finding: the map says it once (:meth:`ColumnMap.unit_note`),
  not each file;
* sign flips of single joints: ``tau2=-1`` (also ``q3``, ``dq3``, ``ddq3``; joints from 1)
  flips that joint's column as it is read, after its quantity's unit (a controller whose
  convention differs on some joints; ``tau=-1`` flips every joint); prefixed by a file's
  name, ``rec2.csv:tau4=-1``, it flips that joint in that file only (a recording logged
  with another convention among several).

* ``none`` for ``dq`` or ``ddq`` reads the log without those columns, present or not
  (``--columns dq=none``): velocities derived from the positions as for a log without
  them (recorded velocities that lag the positions, or zeros written where they were not
  logged); ``dq=none`` leaves out the acceleration columns too (derived from the derived
  velocities), ``ddq=none`` those alone (a finite difference of noisy velocities).

Written on the command line as ``--columns 'q=position_{i0},tau=effort_{i0}'`` and
``--units 'q=deg,tau=mNm'``, or as a TOML file with tables ``[columns]`` and ``[units]``.

A torque log without velocities (``dq`` neither mapped nor present) gets them from the
zero-phase filtered derivative of the positions (:func:`dynid.signals.filtered_derivative`,
cutoff ``velocity_cutoff_hz``), after cleaning; the returned notes say so.
"""

from __future__ import annotations

import dataclasses
import math
import re
import warnings
from collections.abc import Mapping, Sequence
from dataclasses import dataclass, field
from itertools import chain
from pathlib import Path
from typing import Any

import numpy as np
from numpy.typing import NDArray

from .. import _checks
from .._checks import caller_level
from ..exceptions import DataError, DynidWarning
from ..identification.data import StaticDataset
from ..identification.log import (
    DEFAULT_CUTOFF_HZ,
    TorqueLog,
    velocity_note,
    with_derived_velocities,
)
from ..model.robot import Robot
from .bag_hint import bag_hint
from .column_hint import guessed_map, joint_families, no_torques, static_map
from .csv_tables import csv_table
from .input_files import file_text, regular_file
from .joint_state_csv import import_hint
from .npz_files import check_npz
from .torque_log import LABEL_COLUMNS, _where

__all__ = [
    "CURRENT_UNITS",
    "IGNORED",
    "LEFT_OUT",
    "LABEL_COLUMNS",
    "ColumnMap",
    "MappedLog",
    "MappedStatic",
    "conversion_notes",
    "header_names",
    "load_column_map",
    "parse_column_map",
    "load_mapped_static_data",
    "load_mapped_torque_log",
    "load_joint_columns",
    "load_external_torques",
    "load_label_column",
    "load_time_column",
    "unread_columns",
    "unread_note",
]

_DEFAULT = {
    "t": "t",
    "q": "q{i}",
    "dq": "dq{i}",
    "tau": "tau{i}",
    "ddq": "ddq{i}",
    "M": "M{i}_{j}",
    "g": "g{i}",
    "label": "label",
    "tau_ext": "tau_ext{i}",
}
#: The template that reads a log without a quantity's columns (``--columns dq=none``).
IGNORED = "none"
#: What a note says of a log read with ``dq=none`` (rather than "no velocity columns").
LEFT_OUT = "velocity columns left out (--columns dq=none)"
#: The quantities :data:`IGNORED` applies to.
_IGNORABLE = ("dq", "ddq")
_TIME = {"s": 1.0, "ms": 1e-3, "us": 1e-6, "ns": 1e-9}
_ANGLE = {"rad": 1.0, "deg": math.pi / 180, "m": 1.0, "mm": 1e-3}
#: The units of ``q`` that are lengths (a prismatic joint's); the others are angles.
_LENGTH = ("m", "mm")
#: The joint quantities whose named unit applies to the joints of its kind alone.
_JOINT_QUANTITIES = ("q", "dq", "ddq")
_TORQUE = {"Nm": 1.0, "N m": 1.0, "N": 1.0, "mNm": 1e-3, "mN m": 1e-3}
#: Motor currents for ``tau`` [A]: a drive of effort = "current" makes them torques.
CURRENT_UNITS = {"A": 1.0, "mA": 1e-3}
_UNITS: dict[str, dict[str, float]] = {
    "t": _TIME,
    "q": _ANGLE,
    "dq": {k + "/s": v for k, v in _ANGLE.items()},
    "ddq": {k + "/s^2": v for k, v in _ANGLE.items()},
    "tau": {**_TORQUE, **CURRENT_UNITS},
    "g": _TORQUE,
    "M": {"kg m^2": 1.0, "g m^2": 1e-3},
    "tau_ext": _TORQUE,
}


def _to_factor(quantity: str, unit: Any) -> float:
    if isinstance(unit, int | float) and not isinstance(unit, bool):
        f = float(unit)
    else:
        table = _UNITS[quantity]
        key = str(unit).strip()
        try:
            return _to_factor(quantity, _checks.decimal(key))
        except ValueError:
            pass
        if key not in table:
            raise DataError(
                f"unknown unit {unit!r} for {quantity!r}; use one of {sorted(table)} "
                "or a number (the factor to SI)"
            )
        f = table[key]
    if not (math.isfinite(f) and f != 0.0):
        raise DataError(f"unit factor of {quantity!r} must be finite and non-zero; got {unit!r}")
    return f


@dataclass(frozen=True, slots=True)
class ColumnMap:
    """Column templates and unit factors per quantity (module docstring).

    Attributes
    ----------
    columns : mapping of str to str
        Quantity -> template (``position_{i0}``); missing quantities keep dynid's names.
    factors : mapping of str to float
        Quantity -> factor to SI (degrees: ``pi / 180``); missing: 1.
    velocity_cutoff_hz : float
        Cutoff [Hz] of the low-pass before differentiating positions into velocities.
    names : mapping of str to str
        Quantity -> the unit as given (``"mA"``, ``"0.001"``), for messages.
    flips : mapping of str to tuple of int
        Quantity -> the joints (from 0) whose columns are read with the opposite sign
        (``--units tau2=-1,tau3=-1``: ``{"tau": (1, 2)}``).
    file_flips : mapping of str to mapping of str to tuple of int
        A file's name -> its own flips, added to ``flips`` when that file is read
        (``--units rec2.csv:tau4=-1``: ``{"rec2.csv": {"tau": (3,)}}``, :meth:`for_file`).
    file_signs : mapping of str to tuple of str
        A file's name -> the quantities read with the opposite sign on every joint of
        that file alone, its factor negated when that file is read (``--units
        rec2.csv:tau=-1``: ``{"rec2.csv": ("tau",)}``, :meth:`for_file`).
    prismatic : tuple of bool, optional
        The kind of each joint of the robot the files are read for (:meth:`for_robot`):
        a length unit of ``q``, ``dq``, ``ddq`` (``mm``, ``mm/s``) then scales the
        prismatic joints' columns alone, an angle unit (``deg``, ``deg/s``) the revolute
        joints' alone; None (not known): a unit scales every joint's.
    lengths : mapping of str to str
        Quantity -> the length unit given beside its angle unit (``--units q=mm,q=deg``:
        ``{"q": "mm"}``, ``names`` holding ``{"q": "deg"}``): the prismatic joints' columns
        read in it, the revolute joints' in the angle unit (the robot's kinds needed,
        :meth:`for_robot`).
    file_units : mapping of str to mapping of str to str or tuple of str
        A file's name -> its own units, quantity -> the unit as given (or a joint
        quantity's length and angle units, ``("mm", "deg")``), in place of every file's
        for that file alone (``--units rec4.csv:t=ms``: ``{"rec4.csv": {"t": "ms"}}``,
        :meth:`for_file`): recordings logged in different units read in one run.
    """

    columns: Mapping[str, str] = field(default_factory=dict)
    factors: Mapping[str, float] = field(default_factory=dict)
    velocity_cutoff_hz: float = DEFAULT_CUTOFF_HZ
    names: Mapping[str, str] = field(default_factory=dict)
    flips: Mapping[str, tuple[int, ...]] = field(default_factory=dict)
    file_flips: Mapping[str, Mapping[str, tuple[int, ...]]] = field(default_factory=dict)
    file_signs: Mapping[str, tuple[str, ...]] = field(default_factory=dict)
    prismatic: tuple[bool, ...] | None = None
    lengths: Mapping[str, str] = field(default_factory=dict)
    file_units: Mapping[str, Mapping[str, str | tuple[str, ...]]] = field(default_factory=dict)

    def __post_init__(self) -> None:
        for key in list(self.columns) + list(self.factors):
            if key not in _DEFAULT:
                raise DataError(f"unknown quantity {key!r}; expected one of {list(_DEFAULT)}")
        if "M" in self.columns:
            _check_matrix_template(str(self.columns["M"]))
        for key, tpl in self.columns.items():
            if str(tpl).strip().lower() == IGNORED and key not in _IGNORABLE:
                raise DataError(
                    f"{key}={tpl}: only the recorded derivatives can be left out "
                    f"({', '.join(f'{k}={IGNORED}' for k in _IGNORABLE)}); {key!r} is read "
                    "from its columns"
                )
        own = [*(k for f in self.file_flips.values() for k in f), *chain(*self.file_signs.values())]
        for key in [*self.flips, *own]:
            if key not in _FLIPPABLE:
                raise DataError(f"a joint's sign flips one of {list(_FLIPPABLE)}; got {key!r}")
        object.__setattr__(
            self,
            "file_flips",
            _checks.frozen_mapping(
                {k: _checks.frozen_mapping(dict(v)) for k, v in self.file_flips.items()}
            ),
        )
        for units in self.file_units.values():
            _own_factors(units)  # each unit checked as every file's is
        object.__setattr__(
            self,
            "file_units",
            _checks.frozen_mapping(
                {k: _checks.frozen_mapping(dict(v)) for k, v in self.file_units.items()}
            ),
        )
        object.__setattr__(self, "flips", _checks.frozen_mapping(dict(self.flips)))
        signs = {k: tuple(v) for k, v in self.file_signs.items()}
        object.__setattr__(self, "file_signs", _checks.frozen_mapping(signs))
        object.__setattr__(self, "columns", _checks.frozen_mapping(dict(self.columns)))
        object.__setattr__(self, "factors", _checks.frozen_mapping(dict(self.factors)))
        object.__setattr__(self, "names", _checks.frozen_mapping(dict(self.names)))
        object.__setattr__(self, "lengths", _checks.frozen_mapping(dict(self.lengths)))

    @classmethod
    def from_units(
        cls, columns: Mapping[str, str], units: Mapping[str, Any], **kw: Any
    ) -> ColumnMap:
        """Map from templates and unit names (``{"q": "deg", "tau": "mNm"}``; one length
        and one angle unit of ``q``, ``dq`` or ``ddq`` as a pair, ``{"q": ["mm", "deg"]}``),
        single joints' sign flips (``{"tau2": -1}``) and a file's own entries, prefixed by
        its name: sign flips (``{"rec2.csv:tau4": -1}``, ``{"rec2.csv:tau": -1}``) or units
        (``{"rec4.csv:t": "ms"}``)."""
        own = {k: u for k, u in units.items() if ":" in k}
        units, lengths = _split_kinds({k: u for k, u in units.items() if ":" not in k})
        flips: dict[str, set[int]] = {}
        files: dict[str, dict[str, set[int]]] = {}
        whole: dict[str, set[str]] = {}  # a file's quantities negated on every joint
        file_units: dict[str, dict[str, str | tuple[str, ...]]] = {}
        for key, u in own.items():
            name, _, quantity = (x.strip() for x in key.rpartition(":"))
            if not name:
                raise DataError(f"{key}={u}: a file's own entry starts with its name (FILE:t=ms)")
            if quantity in _FLIPPABLE and _is_sign(u):
                if _sign_flip(key, u):  # (FILE:tau=1: read as it is)
                    whole.setdefault(name, set()).add(quantity)
            elif (joint := _joint_key(quantity)) is not None:
                if _sign_flip(quantity, u):
                    files.setdefault(name, {}).setdefault(joint[0], set()).add(joint[1])
            else:
                said = tuple(str(v) for v in u) if isinstance(u, list | tuple) else str(u)
                try:
                    _own_factors({quantity: said})
                except DataError as exc:
                    raise DataError(f"--units {key}: {exc}") from None
                file_units.setdefault(name, {})[quantity] = said
        for key, u in units.items():
            if (joint := _joint_key(key)) is not None:
                if _sign_flip(key, u):
                    flips.setdefault(joint[0], set()).add(joint[1])
            else:
                _check_quantity(key, u)
        given = {k: u for k, u in units.items() if _joint_key(k) is None}
        factors = {k: _to_factor(k, u) for k, u in given.items()}
        names = {k: str(u) for k, u in given.items()}
        signs = {k: tuple(sorted(v)) for k, v in flips.items()}
        per_file = {f: {k: tuple(sorted(v)) for k, v in d.items()} for f, d in files.items()}
        return cls(
            dict(columns),
            factors,
            names=names,
            flips=signs,
            file_flips=per_file,
            file_signs={f: tuple(sorted(q)) for f, q in whole.items()},
            lengths=lengths,
            file_units=file_units,
            **kw,
        )

    def for_file(self, name: str) -> ColumnMap:
        """The map the file ``name`` is read with: the flips of every file and its own
        (:attr:`file_flips`, kept as its only entry for the notes), its own units in place
        of every file's (:attr:`file_units`), without the other files' own entries."""
        if not self.file_flips and not self.file_signs and not self.file_units:
            return self
        own = self.file_flips.get(name, {})
        flips = {
            k: tuple(sorted({*self.flips.get(k, ()), *own.get(k, ())})) for k in {*self.flips, *own}
        }
        units = self.file_units.get(name, {})
        factors, names, lengths = _own_factors(units)
        factors = {**self.factors, **factors}
        names = {**self.names, **names}
        lengths = {**{k: v for k, v in self.lengths.items() if k not in units}, **lengths}
        negated = self.file_signs.get(name, ())
        factors = {**factors, **{k: -float(factors.get(k, 1.0)) for k in negated}}
        return ColumnMap(
            self.columns,
            factors,
            self.velocity_cutoff_hz,
            names=names,
            flips=flips,
            file_flips={name: own} if own else {},
            file_signs={name: negated} if negated else {},
            prismatic=self.prismatic,
            lengths=lengths,
            file_units={name: units} if units else {},
        )

    def unknown_files(self, names: Sequence[str]) -> tuple[str, ...]:
        """The files named by a file's own entry that are not among ``names``."""
        return tuple(f for f in self.own_files if f not in set(names))

    @property
    def own_files(self) -> tuple[str, ...]:
        """The files named by a file's own entry (``rec2.csv:tau4=-1``,
        ``rec2.csv:tau=-1``, ``rec4.csv:t=ms``), in the order given."""
        return tuple(dict.fromkeys([*self.file_flips, *self.file_signs, *self.file_units]))

    @property
    def tau_is_current(self) -> bool:
        """Whether ``tau`` was declared in a current's unit (``A``, ``mA``)."""
        return str(self.names.get("tau", "")).strip() in CURRENT_UNITS

    @property
    def tau_is_torque(self) -> bool:
        """Whether ``tau`` was declared in a torque's unit (``Nm``, ``mNm``)."""
        return str(self.names.get("tau", "")).strip() in _TORQUE

    def unit_note(self) -> str | None:
        """One line saying the units declared and their factors (``tau in mA: x 0.001 to
        A``), or None when none scales a quantity."""
        parts = []
        for k, f in self.factors.items():
            if f in (1.0, -1.0):  # (a sign flip is the note of each file read)
                continue
            given = self.names.get(k, f"{f:.17g}")
            to = "A" if k == "tau" and self.tau_is_current else "SI"
            parts.append(f"{k} in {given} (x {f:.17g} to {to})")
        for k, length in self.lengths.items():
            parts.append(f"{k} in {length} (x {_UNITS[k][length]:.17g} to SI)")
        own = []
        for name, units in self.file_units.items():
            factors, names, lengths = _own_factors(units)
            said = [f"{k} in {names[k]} (x {f:.17g} to SI)" for k, f in factors.items()]
            said += [f"{k} in {u} (x {_UNITS[k][u]:.17g} to SI)" for k, u in lengths.items()]
            own.append(f"{name} alone: " + ", ".join(said))
        if not parts and not own:
            return None
        return "data read with --units " + "; ".join([", ".join(parts)] * bool(parts) + own)

    def template(self, quantity: str) -> str:
        """The column template of a quantity."""
        return self.columns.get(quantity, _DEFAULT[quantity])

    def factor(self, quantity: str) -> float:
        """The factor to SI of a quantity."""
        return float(self.factors.get(quantity, 1.0))

    def unit_kind(self, quantity: str) -> str | None:
        """``"length"`` or ``"angle"``: the kind of the unit named for ``q``, ``dq`` or
        ``ddq`` (``mm/s`` a length's, ``deg/s`` an angle's); None for another quantity,
        none named, or a number (a factor scales every joint)."""
        name = str(self.names.get(quantity, "")).strip()
        if quantity not in _JOINT_QUANTITIES or name not in _UNITS[quantity]:
            return None
        return "length" if name.partition("/")[0] in _LENGTH else "angle"

    def for_robot(self, prismatic: Sequence[bool] | NDArray[np.bool_]) -> ColumnMap:
        """The map that reads the files of a robot whose joints are ``prismatic`` (n,):
        each named unit of ``q``, ``dq``, ``ddq`` scales the joints of its kind alone
        (:attr:`prismatic`, :meth:`joint_factors`).

        Raises
        ------
        DataError
            A unit whose kind matches none of the joints (``q=mm`` for an arm of revolute
            joints alone), naming the entry and the joints' kind.
        """
        kinds = tuple(bool(p) for p in prismatic)
        for quantity in _JOINT_QUANTITIES:
            for kind, unit in self._kinds_given(quantity):
                wanted = kind == "length"
                if any(p == wanted for p in kinds):
                    continue
                said = f"--units {quantity}={unit}"
                other = "revolute (rad, deg)" if wanted else "prismatic (m, mm)"
                raise DataError(
                    f"{said}: a {kind} unit reads the {'prismatic' if wanted else 'revolute'} "
                    f"joints' columns; the robot's {len(kinds)} joint(s) are all {other}; "
                    f"hint: leave out {quantity}={unit}, or pass the robot the data were "
                    "recorded with"
                )
        if kinds == self.prismatic:
            return self
        return dataclasses.replace(self, prismatic=kinds)

    def _kinds_given(self, quantity: str) -> list[tuple[str, str]]:
        """The (kind, unit) pairs named for ``quantity``: its unit of :meth:`unit_kind`
        and the length unit given beside it (:attr:`lengths`)."""
        kind = self.unit_kind(quantity)
        out = [] if kind is None else [(kind, str(self.names[quantity]).strip())]
        return out + ([("length", self.lengths[quantity])] if quantity in self.lengths else [])

    def joint_factors(self, quantity: str, count: int) -> float | NDArray[np.float64]:
        """The factor to SI of ``quantity``: one number for every joint, or per joint
        (``count``,) where a named unit applies to the joints of its kind alone
        (:meth:`for_robot`; the others read in SI, their sign kept; joints beyond the
        robot's, which no reader keeps, at the unit's factor; a quantity of two units,
        :attr:`lengths`, each kind of joint at its own).

        Raises
        ------
        DataError
            A quantity of two units read without the robot's kinds (:meth:`for_robot`).
        """
        f = self.factor(quantity)
        if quantity in self.lengths:
            if self.prismatic is None:
                raise DataError(
                    f"--units {quantity}={self.lengths[quantity]},{quantity}="
                    f"{self.names[quantity]}: the joints' kinds are needed to read each in its "
                    "own unit; give the robot"
                )
            length = _UNITS[quantity][self.lengths[quantity]]
            kinds = np.array([*self.prismatic, *[False] * max(0, count - len(self.prismatic))])
            return np.where(kinds[:count], length, f)
        kind = self.unit_kind(quantity)
        if self.prismatic is None or kind is None or f in (1.0, -1.0):
            return f
        match = np.array([p == (kind == "length") for p in self.prismatic], dtype=bool)
        match = np.concatenate([match, np.ones(max(0, count - match.size), dtype=bool)])
        return np.where(match[:count], f, math.copysign(1.0, f))

    def kind_notes(self, joint_names: Sequence[str]) -> tuple[str, ...]:
        """One line per named unit of ``q``, ``dq``, ``ddq`` that applies to some joints
        alone (:meth:`for_robot`): ``q=mm applied to the prismatic joint rail; the revolute
        joints read in rad``; nothing for a robot of one kind of joint or a map without
        the robot's kinds."""
        if self.prismatic is None or len(set(self.prismatic)) < 2:
            return ()
        out = []
        si = {"q": ("rad", "m"), "dq": ("rad/s", "m/s"), "ddq": ("rad/s^2", "m/s^2")}
        for quantity in _JOINT_QUANTITIES:
            given = self._kinds_given(quantity)
            for kind, unit in given:
                wanted = kind == "length"
                which = [
                    n for n, p in zip(joint_names, self.prismatic, strict=False) if p == wanted
                ]
                kinds = ("prismatic", "revolute") if wanted else ("revolute", "prismatic")
                s = "s" if len(which) > 1 else ""
                rest = (
                    ""
                    if len(given) > 1
                    else f"; the {kinds[1]} joints read in {si[quantity][0 if wanted else 1]}"
                )
                out.append(
                    f"{quantity}={unit} applied to the {kinds[0]} joint{s} {', '.join(which)}"
                    + rest
                )
        return tuple(out)

    def mapped(self, quantity: str) -> bool:
        """Whether the quantity was given a template."""
        return quantity in self.columns

    def ignored(self, quantity: str) -> bool:
        """Whether the log is read without the columns of ``quantity`` (``dq=none``;
        ``ddq`` also with ``dq=none``: accelerations from the derived velocities)."""
        said = {k for k, v in self.columns.items() if str(v).strip().lower() == IGNORED}
        return quantity in said or (quantity == "ddq" and "dq" in said)


#: The quantities whose single joints' columns ``--units`` can flip (``tau2=-1``).
_FLIPPABLE = ("q", "dq", "ddq", "tau")


def _check_quantity(key: str, unit: Any) -> None:
    """Refuse a ``--units`` entry of an unknown quantity or of ``label`` (no unit).

    Raises
    ------
    DataError
        Naming the entry and the quantities.
    """
    if key not in _DEFAULT:
        raise DataError(f"unknown quantity {key!r}; expected one of {list(_DEFAULT)}")
    if key == "label":
        raise DataError(
            f"label={unit}: a label column has no unit (nonzero is in contact); give "
            "its name with --columns label=NAME"
        )


def _own_factors(
    units: Mapping[str, Any],
) -> tuple[dict[str, float], dict[str, str], dict[str, str]]:
    """A file's own units (quantity -> unit, or a joint quantity's pair of a length and
    an angle unit) as :meth:`ColumnMap.from_units` reads every file's: the factors to SI,
    the units as given and the length units given beside an angle unit.

    Raises
    ------
    DataError
        An unknown quantity or unit, two units that are not one length and one angle unit.
    """
    kept, lengths = _split_kinds(
        {k: list(u) if isinstance(u, tuple) else u for k, u in units.items()}
    )
    for k, u in kept.items():
        _check_quantity(k, u)
    factors = {k: _to_factor(k, u) for k, u in kept.items()}
    return factors, {k: str(u) for k, u in kept.items()}, lengths


#: The index fields of a template of ``M``: row, column, flat (column-major).
_ROW, _COL, _FLAT = ("i", "i0"), ("j", "j0"), ("k", "k0")


def _check_matrix_template(tpl: str) -> None:
    """Refuse a template of ``M`` that names a column without both a row and a column
    index, or a flat one (``M{i0}``: one column read for a whole row of M).

    Raises
    ------
    DataError
        A row index alone, a column index alone, a flat index beside a row or column one.
    """
    fields = set(re.findall(r"\{(\w*)\}", tpl))
    if not fields:  # an NPZ array's name
        return
    row, col, flat = (bool(fields & set(f)) for f in (_ROW, _COL, _FLAT))
    if (row and col and not flat) or (flat and not row and not col):
        return
    raise DataError(
        f"M={tpl}: a template of M needs a row and a column index (M{{i0}}_{{j0}}, "
        "M{i}_{j}), or one flat index of the n*n matrix, column-major as libfranka and "
        "Eigen store it (M{k0}: M0..M48 for 7 joints, from 0; M{k} from 1); "
        f"got {'no column index' if row else 'no row index'}; hint: --columns M=M{{k0}} "
        "reads libfranka's flat array"
    )


def _fill_matrix(template: str, i: int, j: int, n: int) -> str:
    """The column of ``M[i, j]`` (from 0) of an ``n``-joint arm: ``{i}``/``{j}`` (from
    1), ``{i0}``/``{j0}`` (from 0), or the flat column-major index ``{k0} = i + n j``
    (``{k}`` from 1)."""
    try:
        return template.format(i=i + 1, i0=i, j=j + 1, j0=j, k=i + n * j + 1, k0=i + n * j)
    except (KeyError, IndexError, ValueError) as exc:
        raise DataError(
            f"column template {template!r} of M: use {{i}}/{{j}} (from 1), {{i0}}/{{j0}} "
            "(from 0) or a flat {k0}/{k}"
        ) from exc


def _joint_key(key: str) -> tuple[str, int] | None:
    """``("tau", 1)`` for ``"tau2"`` (a flippable quantity and a joint from 1), else
    None."""
    m = re.fullmatch(r"(ddq|dq|q|tau)([1-9][0-9]*)", key.strip())
    return None if m is None else (m.group(1), int(m.group(2)) - 1)


def _is_sign(value: Any) -> bool:
    """Whether ``value`` is a sign, ``1`` or ``-1``."""
    try:
        return _checks.decimal(str(value).strip()) in (1.0, -1.0)
    except ValueError:
        return False


def _sign_flip(key: str, value: Any) -> bool:
    """Whether a single joint's entry flips its sign (``-1``) or keeps it (``1``).

    Raises
    ------
    DataError
        Another value: a joint's scale is not a unit (a drive's torque constants are).
    """
    try:
        f = _checks.decimal(str(value).strip())
    except ValueError:
        f = math.nan
    if f in (1.0, -1.0):
        return f == -1.0
    quantity = key.strip().rstrip("0123456789")
    unit = str(value).strip()
    kind = ""
    if quantity in _JOINT_QUANTITIES and unit in _UNITS[quantity]:
        kind = (
            f"; hint: --units {quantity}={unit} (a length unit scales the prismatic joints' "
            "columns alone, an angle unit the revolute joints')"
        )
    raise DataError(
        f"{key}={value}: a single joint's entry flips its sign ({key}=-1); its unit is its "
        f"quantity's (a joint's scale: a drive's torque_constant or gear_ratio){kind}"
    )


def _pairs(text: str, what: str) -> dict[str, str | list[str]]:
    """``key=value`` entries of ``text``; a joint quantity's (``q``, ``dq``, ``ddq``)
    given twice of ``--units`` as the pair of its values (``q=mm,q=deg``: ``["mm",
    "deg"]``, judged by :func:`_split_kinds`), any other key given twice refused."""
    out: dict[str, str | list[str]] = {}
    for part in text.split(","):
        part = part.strip()
        if not part:
            continue
        key, sep, value = part.partition("=")
        key, value = key.strip(), value.strip()
        if not sep or not key or not value:
            raise DataError(f"{what} must read 'quantity=value,...'; got {part!r} in {text!r}")
        if key in out:
            held = out[key]
            if what == "--units" and key.rpartition(":")[2].strip() in _JOINT_QUANTITIES:
                out[key] = [held, value] if isinstance(held, str) else [*held, value]
                continue
            raise DataError(f"{what}: {key!r} is given twice in {_checks.short(text)}")
        out[key] = value
    return out


def _split_kinds(units: Mapping[str, Any]) -> tuple[dict[str, Any], dict[str, str]]:
    """``units`` with each joint quantity given two units (``{"q": ["mm", "deg"]}``) kept
    at its angle unit, and those quantities' length units (``{"q": "mm"}``).

    Raises
    ------
    DataError
        Two units of a quantity that are not one length and one angle unit (``q=deg,
        q=rad``, a number among them, a third), or two units of another quantity, in one
        line.
    """
    kept: dict[str, Any] = {}
    lengths: dict[str, str] = {}
    for key, value in units.items():
        if not isinstance(value, list | tuple):
            kept[key] = value
            continue
        said = ",".join(f"{key}={v}" for v in value)
        if key not in _JOINT_QUANTITIES:
            raise DataError(
                f"--units {said}: {key!r} takes one unit; only q, dq and ddq take two, one "
                "for the prismatic joints and one for the revolute ones"
            )
        names = [str(v).strip() for v in value]
        table = _UNITS[key]
        kinds = ["length" if n.partition("/")[0] in _LENGTH else "angle" for n in names]
        if len(names) != 2 or any(n not in table for n in names) or kinds[0] == kinds[1]:
            ex = {"q": ("mm", "deg"), "dq": ("mm/s", "deg/s"), "ddq": ("mm/s^2", "deg/s^2")}[key]
            lengths_of = ", ".join(n for n in table if n.partition("/")[0] in _LENGTH)
            raise DataError(
                f"--units {said}: two units of {key} must be one length unit for the "
                f"prismatic joints ({lengths_of}) and one angle unit for the revolute ones; "
                f"hint: --units {key}={ex[0]},{key}={ex[1]}"
            )
        lengths[key] = names[kinds.index("length")]
        kept[key] = names[kinds.index("angle")]
    return kept, lengths


def parse_column_map(columns: str | None = None, units: str | None = None, **kw: Any) -> ColumnMap:
    """Map from ``'q=position_{i0},tau=effort_{i0}'`` and ``'q=deg,tau=mNm'``.

    Raises
    ------
    DataError
        Malformed text, a quantity given twice (but ``q``, ``dq`` or ``ddq`` of ``--units``
        in one length and one angle unit, ``q=mm,q=deg``), an unknown quantity or unit.
    """
    cols = {k: str(v) for k, v in _pairs(columns or "", "--columns").items()}
    unit = _pairs(units or "", "--units")
    return ColumnMap.from_units(cols, unit, **kw)


def load_column_map(path: str | Path, **kw: Any) -> ColumnMap:
    """Map from a TOML file with tables ``[columns]`` and ``[units]``.

    Raises
    ------
    DataError
        Not TOML, other tables or keys, an unknown quantity or unit.
    """
    path = Path(path)
    d = _checks.parse_toml(file_text(path), path.name, DataError)
    extra = sorted(set(d) - {"columns", "units", "velocity_cutoff_hz"})
    if extra:
        raise DataError(f"unknown key(s) {extra}; expected [columns], [units]", file=path.name)
    if "velocity_cutoff_hz" in d:
        kw.setdefault("velocity_cutoff_hz", float(d["velocity_cutoff_hz"]))
    try:
        return ColumnMap.from_units(
            {k: str(v) for k, v in d.get("columns", {}).items()}, d.get("units", {}), **kw
        )
    except DataError as exc:
        raise DataError(str(exc), file=path.name) from exc


# ------------------------------------------------------------------------------ tables
def _fill(template: str, i: int, j: int | None = None) -> str:
    d = {"i": i + 1, "i0": i}
    if j is not None:
        d.update(j=j + 1, j0=j)
    try:
        return template.format(**d)
    except (KeyError, IndexError, ValueError) as exc:
        raise DataError(
            f"column template {template!r}: use {{i}} (from 1) or {{i0}} (from 0)"
            + (" and {j}/{j0}" if j is not None else "")
        ) from exc


@dataclass(frozen=True, slots=True)
class _Table:
    name: str
    columns: dict[str, NDArray[np.float64]]  # CSV column or NPZ array by name
    #: quantity -> (its column names in joint order, their (N, n) array): the columns of a
    #: CSV read side by side, so that a long log's vectors are not stacked again
    groups: dict[str, tuple[list[str], NDArray[np.float64]]] = field(default_factory=dict)
    #: the quantities whose groups were scaled to SI as they were read (in place)
    scaled: set[str] = field(default_factory=set)
    #: every column (CSV header) or array (NPZ) of the file, read or not, in file order
    header: list[str] = field(default_factory=list)
    #: (line number of data row 0, rows) of a CSV whose rows map to lines one to one
    lines: tuple[int, int] | None = None

    def has(self) -> str:
        """``the file has [...]`` for messages: its first 12 columns (or arrays)."""
        names = self.header or list(self.columns)
        return f"the file has {names[:12]}{'...' if len(names) > 12 else ''}"


def _read_table(path: Path, cmap: ColumnMap, quantities: tuple[str, ...]) -> _Table:
    """The columns (CSV) or arrays (NPZ) of a file; of a CSV only those that the map's
    templates of ``quantities`` name, read by the strict reader of torque logs
    (:func:`~dynid.io.csv_tables.csv_table`: one pass, a chunk of text at a time)."""
    regular_file(path)  # not a device that never ends
    suffix = path.suffix.lower()
    if suffix == ".npz":
        check_npz(path)
        try:
            with np.load(path, allow_pickle=False) as npz:
                raw = {k: np.asarray(npz[k]) for k in npz.files}
            complex_ = [k for k, a in raw.items() if np.iscomplexobj(a)]
            arrays = {k: a.astype(np.float64) for k, a in raw.items() if k not in complex_}
        except ValueError as exc:
            raise DataError(
                f"not a numeric NPZ file without pickles ({exc})", file=path.name
            ) from exc
        if complex_:
            raise DataError(f"array {complex_[0]!r} holds complex numbers", file=path.name)
        return _Table(path.name, arrays, header=list(raw))
    if suffix != ".csv":
        raise DataError(f"expected a .csv or .npz file{bag_hint(path)}", file=path.name)

    def layout(names: list[str], line: int) -> dict[str, list[int]]:
        dup = sorted({c for c in names if names.count(c) > 1})
        if dup:
            raise DataError(
                f"duplicate column(s) {_checks.names(dup)}", file=path.name, at=f"line {line}"
            )
        wanted = _referenced(names, cmap, quantities)
        if not wanted:
            raise DataError(
                f"no column the map names (templates "
                f"{[cmap.template(k) for k in quantities]}); the file has {names[:12]}"
                f"{'...' if len(names) > 12 else ''}"
                + (
                    import_hint(names, path.name)
                    or _guessed_hint(names, path.name, cmap)
                    or "; hint: map them with --columns"
                ),
                file=path.name,
                at=f"line {line}",
            )
        header[:] = names
        groups_of.update(_grouped(names, cmap, quantities))
        grouped = {c for cols in groups_of.values() for c in cols}
        index = {c: k for k, c in enumerate(names)}
        out = {key: [index[c] for c in cols] for key, cols in groups_of.items()}
        return out | {c: [k] for k, c in enumerate(names) if c in wanted and c not in grouped}

    groups_of: dict[str, list[str]] = {}  # layout key -> its columns, filled by layout()
    header: list[str] = []  # every column, filled by layout()

    arrays, lines = csv_table(path, layout, "a header naming the columns", freeze=False)
    table = _Table(path.name, {}, header=header, lines=lines)
    for key in list(arrays):  # one at a time: scaled in place, then its immutable copy
        a = arrays.pop(key)
        if key.startswith(_GROUP):
            names, quantity = groups_of[key], key[len(_GROUP) :]
            if cmap.factor(quantity) != 1.0:
                a *= cmap.joint_factors(quantity, len(names))
                table.scaled.add(quantity)
            a = _checks.frozen(a)
            table.groups[quantity] = (names, a)
            table.columns.update({c: a[:, k] for k, c in enumerate(names)})
        else:
            table.columns[key] = _checks.frozen(a)[:, 0]
    return table


#: Prefix of the arrays of :func:`_grouped` (not a column name: CSV names are stripped).
_GROUP = " group "


def _grouped(
    names: list[str], cmap: ColumnMap, quantities: tuple[str, ...]
) -> dict[str, list[str]]:
    """The columns of each joint quantity (``{i}``/``{i0}`` templates, joint order), to be
    read side by side into one (N, n) array; each column in one group at most."""
    present = set(names)
    out: dict[str, list[str]] = {}
    taken: set[str] = set()
    for quantity in quantities:
        tpl = cmap.template(quantity)
        if "{i" not in tpl or "{j" in tpl:
            continue
        cols: list[str] = []
        while (c := _fill(tpl, len(cols))) in present and c not in taken:
            cols.append(c)
        if cols:
            out[_GROUP + quantity] = cols
            taken.update(cols)
    return out


def _referenced(names: list[str], cmap: ColumnMap, quantities: tuple[str, ...]) -> set[str]:
    """The column names a map's templates of ``quantities`` can name (every column when a
    template is more than ``{i}``, ``{i0}``, ``{j}``, ``{j0}``, ``{k}``, ``{k0}`` in
    text)."""
    patterns = []
    for quantity in quantities:
        tpl = cmap.template(quantity)
        parts = re.split(r"(\{i0?\}|\{j0?\}|\{k0?\})", tpl)
        text = "".join(parts[::2])  # the template without its joint fields
        if "{" in text or "}" in text:  # another format field: read every column
            return set(names)
        patterns.append("".join(r"\d+" if k % 2 else re.escape(p) for k, p in enumerate(parts)))
    rx = re.compile("|".join(f"(?:{p})" for p in patterns)) if patterns else None
    return {c for c in names if rx is not None and rx.fullmatch(c)}


def _vector(table: _Table, cmap: ColumnMap, quantity: str, n: int | None) -> NDArray | None:
    """(N, n) array of a joint quantity in SI, or None when its columns are absent."""
    tpl = cmap.template(quantity)
    if "{" not in tpl:  # an NPZ array, or one CSV column per quantity is not a vector
        if tpl not in table.columns:
            return None
        a = table.columns[tpl]
        a = a[:, None] if a.ndim == 1 else a
        if n is not None and a.shape[1] != n:
            raise DataError(f"{tpl!r} has {a.shape[1]} joints; expected {n}", file=table.name)
        return _flipped(a * cmap.joint_factors(quantity, a.shape[1]), cmap, quantity, table.name)
    if n is None:
        n = 0
        while _fill(tpl, n) in table.columns:
            n += 1
        if n == 0:
            return None
    names = [_fill(tpl, i) for i in range(n)]
    missing = [c for c in names if c not in table.columns]
    if len(missing) == n:
        return None
    if missing:
        raise DataError(
            f"missing column(s) {_checks.names(missing)} for {quantity!r} ({tpl!r})"
            + _recount_hint(table, cmap, n),
            file=table.name,
        )
    group = table.groups.get(quantity)
    # the columns of a group scaled as read are in SI (the first n of the group: names)
    f = 1.0 if quantity in table.scaled else cmap.joint_factors(quantity, n)
    if group is not None and group[0] == names:  # read side by side: no copy when in SI
        a = group[1] if np.all(f == 1.0) else _checks.frozen(group[1] * f)
    else:
        a = np.stack([table.columns[c] for c in names], axis=1) * f
    return _flipped(a, cmap, quantity, table.name)


def _recount_hint(table: _Table, cmap: ColumnMap, n: int) -> str:
    """``; hint: --columns '...'``: the whole map, with each joint quantity whose columns
    are there numbered the other way (``q0..q6`` for ``q{i}``: ``q=q{i0}``); empty when
    none is."""
    spec = dict(cmap.columns)
    for quantity in ("q", "dq", "tau", "ddq"):
        tpl = cmap.template(quantity)
        other = tpl.replace("{i}", "{i0}") if "{i}" in tpl else tpl.replace("{i0}", "{i}")
        if other == tpl or "{j" in tpl:
            continue
        have = [_fill(tpl, i) in table.columns for i in range(n)]
        if not all(have) and all(_fill(other, i) in table.columns for i in range(n)):
            spec[quantity] = other
    if spec == dict(cmap.columns):
        return ""
    text = ",".join(f"{k}={spec[k]}" for k in _DEFAULT if k in spec)
    first = 0 if any("{i0}" in spec[k] and spec[k] != cmap.columns.get(k) for k in spec) else 1
    return f"; hint: the file numbers the joints from {first}: --columns '{text}' reads them"


def _flipped(a: NDArray, cmap: ColumnMap, quantity: str, name: str) -> NDArray:
    """``a`` (N, n) with the joints ``cmap`` flips of ``quantity`` negated.

    Raises
    ------
    DataError
        A flip names a joint the file does not hold.
    """
    joints = cmap.flips.get(quantity, ())
    if not joints:
        return a
    if max(joints) >= a.shape[1]:
        raise DataError(
            f"--units {quantity}{max(joints) + 1}=-1 names joint {max(joints) + 1}; the file "
            f"has {a.shape[1]} joints of {quantity!r}",
            file=name,
        )
    out = np.array(a, dtype=np.float64)
    out[:, list(joints)] *= -1.0
    return _checks.frozen(out)


def _check_distinct(table: _Table, cmap: ColumnMap, quantities: tuple[str, ...], n: int) -> None:
    """Refuse a column (or NPZ array) that the templates of two quantities both name
    (``tau = "q{i}"``: the positions were read as torques too)."""
    owner: dict[str, str] = {}
    for quantity in quantities:
        if cmap.ignored(quantity):
            continue
        tpl = cmap.template(quantity)
        if "{" not in tpl:
            names = [tpl]
        elif quantity == "M":
            names = [_fill_matrix(tpl, i, j, n) for i in range(n) for j in range(n)]
        else:
            names = [_fill(tpl, i) for i in range(n)]
        for c in names:
            if c in table.columns and owner.setdefault(c, quantity) != quantity:
                raise DataError(
                    f"column {c!r} is named by the templates of both "
                    f"{owner[c]!r} and {quantity!r}; each column holds one quantity: fix --columns",
                    file=table.name,
                )


def _need(table: _Table, cmap: ColumnMap, quantity: str, n: int | None) -> NDArray:
    a = _vector(table, cmap, quantity, n)
    if a is None:
        tpl = cmap.template(quantity)
        first = _fill(tpl, 0) if "{" in tpl else tpl
        none = ""
        if quantity == "tau" and n and table.name.lower().endswith(".csv"):
            used = {*_names(cmap, "t", 1), *_names(cmap, "q", n), *_names(cmap, "dq", n)}
            none = no_torques(table.header, n, used | _names(cmap, "ddq", n))
        if none:
            raise DataError(f"no column {first!r} for 'tau' ({tpl!r}): {none}", file=table.name)
        raise DataError(
            f"no column {first!r} for {quantity!r} (template {tpl!r}); {table.has()}"
            + _map_hint(table, cmap, "; hint: map it with --columns"),
            file=table.name,
        )
    return a


def _names(cmap: ColumnMap, quantity: str, n: int) -> set[str]:
    """The columns ``cmap`` names for ``quantity`` of ``n`` joints."""
    tpl = cmap.template(quantity)
    return {_fill(tpl, i) for i in range(n)} if "{" in tpl else {tpl}


def _map_hint(table: _Table, cmap: ColumnMap, otherwise: str) -> str:
    """``; hint: ...`` for a torque log ``cmap`` does not read: the import a header of
    another tool needs, else the whole ``--columns`` map guessed from a CSV's header (the
    templates given kept, :func:`~dynid.io.column_hint.guessed_map`), else ``otherwise``."""
    if hint := import_hint(table.header, table.name):
        return hint
    return _guessed_hint(table.header, table.name, cmap) or otherwise


def _guessed_hint(header: Sequence[str], name: str, cmap: ColumnMap) -> str:
    """``; hint: --columns '...' --units '...' reads the file``: the map guessed from a
    CSV's header (:func:`~dynid.io.column_hint.guessed_map`, the templates given kept) with
    the ``--units`` given kept and the units the names say added for the quantities
    without one given; empty when nothing is guessed. A header of dynid's own names
    (``t, q1.., dq1.., tau1..``: the empty map, ``--columns ''``) is said to be one."""
    guess = guessed_map(header, cmap.columns) if name.lower().endswith(".csv") else ""
    if not guess:
        return ""
    spec, _, said = guess.partition(" --units ")
    units = dict(e.split("=", 1) for e in said.strip("'").split(",") if "=" in e)
    units.update(_given_units(cmap))
    text = ",".join(f"{k}={v}" for k, v in [*units.items(), *cmap.lengths.items()])
    with_units = f" --units '{text}'" if text else ""
    if spec == "--columns ''":
        return (
            "; hint: the file has dynid's own column names (t, q1.., dq1.., tau1..), not "
            f"those of the map: --columns ''{with_units} (an empty map) reads them as they are"
        )
    return f"; hint: {spec}{with_units} reads the file"


def _given_units(cmap: ColumnMap) -> dict[str, str]:
    """The ``--units`` entries ``cmap`` was made from, key -> value as typed again
    (``{"t": "us", "tau": "-1", "tau2": "-1", "rec2.csv:tau": "-1"}``): each quantity's
    unit, each joint's and each file's sign flip; an entry that changed nothing
    (``tau2=1``) is left out."""
    out = dict(cmap.names)
    out |= {f"{k}{j + 1}": "-1" for k, joints in cmap.flips.items() for j in joints}
    for f, own in cmap.file_flips.items():
        out |= {f"{f}:{k}{j + 1}": "-1" for k, joints in own.items() for j in joints}
    out |= {f"{f}:{k}": "-1" for f, signs in cmap.file_signs.items() for k in signs}
    for f, units in cmap.file_units.items():
        out |= {  # a pair typed as two entries (rec4.csv:q=mm,rec4.csv:q=deg)
            f"{f}:{k}": u if isinstance(u, str) else f",{f}:{k}=".join(u) for k, u in units.items()
        }
    return out


@dataclass(frozen=True, slots=True)
class MappedLog:
    """A torque log read through a column map, and what was done to it.

    Attributes
    ----------
    log : TorqueLog
    notes : tuple of str
        What the reader should be warned of (velocities derived from the positions).
    conversions : tuple of str
        The units converted as the map asked (:func:`conversion_notes`), said as notes.
    invalid_rows : str
        The first rows holding NaN or inf, which cleaning dropped, as the strict reader
        names them: ``row 55 (line 58), row 303 (line 306), ...``; empty for none.
    unread : tuple of str
        The file's columns (arrays) the map names for no quantity and no command reads
        (:func:`unread_columns`: a vendor's motor currents beside its torques), said in
        one note.
    """

    log: TorqueLog
    notes: tuple[str, ...] = ()
    conversions: tuple[str, ...] = ()
    invalid_rows: str = ""
    unread: tuple[str, ...] = ()


def unread_columns(header: Sequence[str], columns: ColumnMap) -> tuple[str, ...]:
    """The columns of a file of header ``header`` that a torque log read through
    ``columns`` leaves unread: named by none of its quantities' templates (``t, q, dq, tau,
    ddq``; a quantity left out, ``dq=none``, names none), and neither contact labels nor
    external torques (``tau_ext``'s template, mapped or dynid's ``tau_ext1..n``), which
    ``dynid observe`` reads."""
    quantities = ("t", "q", "dq", "tau", "ddq", "tau_ext")
    read = _referenced(list(header), columns, quantities)
    label = {columns.template("label")} if columns.mapped("label") else set(LABEL_COLUMNS)
    return tuple(c for c in header if c not in read and c not in label)


#: A column whose name says external joint torques (libfranka's ``tau_ext_hat_filtered_0``,
#: ``external_torque_1``, ``ext_tau3``).
_EXTERNAL = re.compile(r"(?i).*(tau_?ext|ext(ernal)?_?(tau|torque|effort)).*")


def unread_note(unread: Sequence[str], n: int) -> str:
    """One line naming the columns ``unread`` (a family of ``n`` joints' columns as
    ``first..last``) of a file read through ``--columns``, and of a family whose name says
    external joint torques (``tau_ext_hat_filtered_0..6``) the ``--columns tau_ext=``
    entry that has ``observe`` read it as its reference."""
    families = joint_families(list(unread), n)
    grouped = {c for cols in families.values() for c in cols}
    shown = [f"{cols[0]}..{cols[-1]}" for cols in families.values()]
    shown += [c for c in unread if c not in grouped]
    said = f"column(s) {', '.join(shown)} named by no --columns entry: not read"
    external = [tpl for tpl, cols in families.items() if _EXTERNAL.fullmatch(cols[0])]
    if external:
        said += (
            f"; {families[external[0]][0]}..{families[external[0]][-1]} look like external "
            f"joint torques: --columns tau_ext={external[0]} has observe compare its residual "
            "with them, taken as the reference (an estimate of the robot's own, such as "
            "libfranka's tau_ext_hat_filtered, is scored as if it were the truth)"
        )
    return said


def load_mapped_torque_log(
    path: str | Path, columns: ColumnMap, *, n: int | None = None, gap_factor: float = 1.5
) -> MappedLog:
    """Read a torque log (CSV or NPZ) through a column map; SI out.

    Parameters
    ----------
    path : str or Path
    columns : ColumnMap
        Read as :meth:`ColumnMap.for_file` of the file's name gives.
    n : int, optional
        Expected joint count (default: the number of position columns).
    gap_factor : float
        See :meth:`TorqueLog.from_raw`.

    Returns
    -------
    MappedLog
        The cleaned log; velocities from the filtered derivative of the positions when the
        file has none or the map leaves them out (``dq=none``; said in ``notes``).

    Raises
    ------
    DataError
        Missing columns (named with the template), a column named by two quantities'
        templates, a malformed file, a joint count other than ``n``, time running backwards.
    """
    path = Path(path)
    columns = columns.for_file(path.name)
    table = _read_table(path, columns, ("t", "q", "dq", "tau", "ddq"))
    t = table.columns.get(columns.template("t"))
    if t is None:
        raise DataError(
            f"no time column {columns.template('t')!r}; {table.has()}"
            + _map_hint(table, columns, "; hint: map it with --columns t=NAME"),
            file=path.name,
        )
    t = t if columns.factor("t") == 1.0 else _checks.frozen(t * columns.factor("t"))
    q = _need(table, columns, "q", n)
    n = q.shape[1]
    tau = _need(table, columns, "tau", n)
    dq = None if columns.ignored("dq") else _vector(table, columns, "dq", n)
    ddq = None if columns.ignored("ddq") else _vector(table, columns, "ddq", n)
    _check_distinct(table, columns, ("t", "q", "dq", "tau", "ddq"), n)
    said = conversion_notes(
        columns, [k for k in _DEFAULT if k in {**columns.factors, **columns.flips}]
    )
    unread = unread_columns(table.header, columns)
    ok = np.isfinite(t)
    for a in (q, dq, tau, ddq):
        if a is not None:
            ok &= np.all(np.isfinite(a), axis=1)
    invalid = "" if ok.all() else _where(np.flatnonzero(~ok), table.lines)
    try:
        if dq is not None:
            log = TorqueLog.from_raw(t, q, dq, tau, ddq, gap_factor=gap_factor)
            return MappedLog(log, (), said, invalid, unread)
        raw = TorqueLog.from_raw(t, q, np.zeros_like(q), tau, ddq, gap_factor=gap_factor)
    except DataError as exc:
        raise DataError(str(exc), file=path.name) from exc
    notes = (velocity_note(columns.velocity_cutoff_hz),)
    if columns.ignored("dq"):
        notes = (notes[0].replace("no velocity columns", LEFT_OUT, 1),)
    try:
        log = with_derived_velocities(raw, columns.velocity_cutoff_hz)
    except DataError as exc:  # a rate too low for the cut-off: the file named
        raise DataError(str(exc), file=path.name) from exc
    return MappedLog(log, notes, said, invalid, unread)


def conversion_notes(columns: ColumnMap, quantities: Sequence[str]) -> tuple[str, ...]:
    """The sign flips of reading through ``columns``, one line per quantity of
    ``quantities`` whose factor is negative: ``tau sign flipped (--units tau=-1)`` (a
    sign convention, not a unit; ``and scaled by ...`` for another negative factor). The
    units declared are the map's one note (:meth:`ColumnMap.unit_note`), not said per file."""
    out = []
    for k in quantities:
        f = columns.factor(k)
        whole = [n for n, q in columns.file_signs.items() if k in q]  # a file's own entry
        if whole:
            unit = columns.names.get(k)  # every file's unit, as given
            flag = f"{whole[0]}:{k}=-1" + ("" if unit is None else f",{k}={unit}")
        else:
            flag = f"{k}={f:.17g}"
        if f < 0:
            scaled = "" if f == -1.0 else f" and scaled by {-f:.17g} to SI"
            out.append(f"{k} sign flipped{scaled} (--units {flag})")
        if joints := columns.flips.get(k, ()):
            own = {f: set(d.get(k, ())) for f, d in columns.file_flips.items()}
            which = ", ".join(f"{k}{j + 1}" for j in joints)
            flags = ",".join(  # a file's own entry as given (ColumnMap.for_file)
                "".join(f"{f}:" for f, js in own.items() if j in js) + f"{k}{j + 1}=-1"
                for j in joints
            )
            out.append(f"{which} sign flipped (--units {flags})")
    return tuple(out)


def load_joint_columns(path: str | Path, name: str, n: int) -> NDArray[np.float64] | None:
    """The columns ``name1 .. namen`` (CSV) or the array ``name`` (NPZ) of a log, (N, n), as
    stored (no unit scaling), or None when the file has none: a signal kept beside the log
    (the true external torques ``tau_ext`` of ``dynid simulate --contact``, a vendor's
    estimate).

    Raises
    ------
    DataError
        A malformed file, some but not all of the columns.
    """
    cmap = ColumnMap({"tau": name if Path(path).suffix.lower() == ".npz" else name + "{i}"})
    try:
        table = _read_table(Path(path), cmap, ("tau",))
    except DataError as exc:
        if "no column the map names" in str(exc):
            return None
        raise
    return _vector(table, cmap, "tau", n)


def load_external_torques(
    path: str | Path, columns: ColumnMap | None, n: int
) -> tuple[str, NDArray[np.float64] | None, NDArray[np.float64]] | None:
    """The external joint torques stored beside a log and the times of its rows: the
    columns ``columns`` maps ``tau_ext`` to (``--columns tau_ext=tau_ext_hat_filtered_{i0}``,
    in the unit of ``--units tau_ext=``), else dynid's ``tau_ext1 .. tau_extn`` (CSV) or
    array ``tau_ext`` (NPZ) that ``dynid simulate --contact`` writes. Rows as stored (NaN
    kept): the caller aligns them with the cleaned log by their times.

    Parameters
    ----------
    path : str or Path
    columns : ColumnMap, optional
        The map the log is read with (its ``t`` template and unit too:
        :meth:`ColumnMap.for_file` of the file's name).
    n : int
        The joint count.

    Returns
    -------
    (str, ndarray (N,) or None, ndarray (N, n)) or None
        Where they were read (``columns tau_ext1..tau_ext7``), ``t`` [s] (None: no time
        column) and the torques [N m]; None when the file has none.

    Raises
    ------
    DataError
        A ``tau_ext`` mapped that the file lacks, some but not all of its columns, a
        malformed file.
    """
    path = Path(path)
    cmap = (columns or ColumnMap()).for_file(path.name)
    mapped = cmap.mapped("tau_ext")
    tpl = cmap.template("tau_ext")
    if not mapped and path.suffix.lower() == ".npz":
        tpl = "tau_ext"
    own = ColumnMap(
        {"t": cmap.template("t"), "tau_ext": tpl},
        {k: cmap.factor(k) for k in ("t", "tau_ext")},
    )
    try:
        table = _read_table(path, own, ("t", "tau_ext"))
    except DataError as exc:
        if mapped or "no column the map names" not in str(exc):
            raise
        return None
    ext = _vector(table, own, "tau_ext", n)
    if ext is None:
        if not mapped:
            return None
        first = _fill(tpl, 0) if "{" in tpl else tpl
        raise DataError(
            f"no column {first!r} for 'tau_ext' (--columns tau_ext={tpl}); {table.has()}",
            file=path.name,
        )
    t = table.columns.get(own.template("t"))
    t = None if t is None else np.asarray(t, dtype=np.float64).reshape(-1) * own.factor("t")
    said = [_fill(tpl, 0), _fill(tpl, n - 1)] if "{" in tpl else [tpl]
    return f"columns {'..'.join(said)}" if len(said) > 1 else f"array {tpl!r}", t, ext


def load_time_column(path: str | Path) -> NDArray[np.float64] | None:
    """The times ``t`` [s] (N,) of a log's rows as stored (NaN kept, no row dropped), the
    column (CSV) or array (NPZ) ``t``, or None when the file has none: what aligns a signal
    kept beside the log (:func:`load_joint_columns`) with the rows a reader kept.

    Raises
    ------
    DataError
        A malformed file.
    """
    try:
        table = _read_table(Path(path), ColumnMap({"t": "t"}), ("t",))
    except DataError as exc:
        if "no column the map names" in str(exc):
            return None
        raise
    if "t" not in table.columns:
        return None
    return np.asarray(table.columns["t"], dtype=np.float64).reshape(-1)


def load_label_column(
    path: str | Path, columns: ColumnMap | None = None
) -> tuple[str, NDArray[np.float64], NDArray[np.float64]] | None:
    """The contact labels of a log (nonzero in contact) and the times of its rows.

    The column (CSV) or array (NPZ) that ``columns`` maps ``label`` to
    (``--columns label=collision``), else the first of :data:`LABEL_COLUMNS` the file
    has; the times through the map's ``t`` template and unit. Rows as stored (NaN kept):
    the caller aligns them with the cleaned log by their times.

    Returns
    -------
    (str, ndarray (N,), ndarray (N,)) or None
        The column's name, ``t`` [s] and the labels; None when the file has no label.

    Raises
    ------
    DataError
        A ``label`` mapped that the file lacks or that is not numbers, a malformed file.

    Warns
    -----
    DynidWarning
        A column of a default name that is not numbers (read as no labels).
    """
    path = Path(path)
    cmap = (columns if columns is not None else ColumnMap()).for_file(path.name)
    present = _header(path)
    if cmap.mapped("label"):
        name = cmap.template("label")
        if name not in present:
            raise DataError(
                f"no column {name!r} for 'label' (--columns label={name}); the file has "
                f"{present[:12]}{'...' if len(present) > 12 else ''}",
                file=path.name,
            )
    else:
        found = [c for c in LABEL_COLUMNS if c in present]
        if not found:
            return None
        name = found[0]
    tpl = cmap.template("t")
    try:
        table = _read_table(path, ColumnMap({"t": tpl, "label": name}), ("t", "label"))
    except DataError as exc:
        if cmap.mapped("label"):
            raise
        warnings.warn(
            f"{path.name}: column {name!r} read as no contact labels ({exc}); hint: name the "
            "labels with --columns label=NAME",
            DynidWarning,
            stacklevel=caller_level(),
        )
        return None
    if tpl not in table.columns:
        return None  # the log's reader names the missing time column
    t = np.asarray(table.columns[tpl], dtype=np.float64).reshape(-1) * cmap.factor("t")
    label = np.asarray(table.columns[name], dtype=np.float64).reshape(-1)
    if label.shape != t.shape:
        raise DataError(f"label {name!r} has {label.size} rows; t has {t.size}", file=path.name)
    return name, t, label


def _header(path: Path) -> list[str]:
    """:func:`header_names`."""
    return header_names(path)


def header_names(path: Path) -> list[str]:
    """The column names of a CSV (its first line that is not a comment) or the array
    names of an NPZ file.

    Raises
    ------
    DataError
        Not a regular file; an NPZ file that cannot be read.
    """
    regular_file(path)
    if path.suffix.lower() == ".npz":
        check_npz(path)
        with np.load(path, allow_pickle=False) as z:
            return list(z.files)
    with path.open(encoding="utf-8-sig", errors="replace") as fh:
        for line in fh:
            s = line.strip()
            if s and not s.startswith("#"):
                return [c.strip() for c in s.split(",")]
    return []


@dataclass(frozen=True, slots=True)
class MappedStatic:
    """Static data read through a column map: the data set, what the reader should be
    warned of (``notes``) and the units converted (``conversions``, said as notes)."""

    data: StaticDataset
    notes: tuple[str, ...] = ()
    conversions: tuple[str, ...] = ()


def load_mapped_static_data(
    path: str | Path,
    columns: ColumnMap,
    robot: Robot | None = None,
    *,
    require_M: bool = True,
    drop_invalid: bool = False,
) -> MappedStatic:
    """Read static data ``q, M, g`` (CSV or NPZ) through a column map; SI out.

    ``M`` is read from the lower triangle ``i >= j`` (a column named by ``(i, j)`` or, when
    absent, by ``(j, i)``) and mirrored; NPZ arrays are taken whole. With
    ``require_M=False`` a file without ``M`` (gravity torques only) is read with ``M`` set
    to zero, said in the notes. With ``drop_invalid`` the rows holding NaN or inf are
    dropped, said in the notes with their lines.

    Raises
    ------
    DataError
        Missing columns (named), a column named by two quantities' templates, a joint
        count other than the robot's, NaN rows (without ``drop_invalid``).
    """
    path = Path(path)
    if robot is not None:  # a unit of q for the joints of its kind
        columns = columns.for_robot(robot.prismatic)
    table = _read_table(path, columns, ("q", "g", "M"))
    n = robot.n if robot is not None else None
    tpl_q = columns.template("q")
    if robot is not None and "{" in tpl_q and _fill(tpl_q, robot.n) in table.columns:
        k = robot.n  # more joints than the robot's: their columns were ignored silently
        while _fill(tpl_q, k) in table.columns:
            k += 1
        guess = static_map(table.header, robot.n, columns.columns)
        raise DataError(
            f"data for {k} joints (columns {_fill(tpl_q, 0)}..{_fill(tpl_q, k - 1)}); "
            f"robot {robot.name!r} has {robot.n}; hint: "
            + (
                f"{guess} reads the file" if guess else "pass the robot the data were recorded with"
            ),
            file=path.name,
        )
    q = _static_vector(table, columns, "q", n)
    n = q.shape[1]
    g = _static_vector(table, columns, "g", n)
    _check_distinct(table, columns, ("q", "g", "M"), n)
    tpl = columns.template("M")
    extra: tuple[str, ...] = ()
    first = tpl if "{" not in tpl else _fill_matrix(tpl, 0, 0, n)
    if not require_M and first not in table.columns:
        M = np.zeros((q.shape[0], n, n))
        extra = ("no M columns: M set to zero (gravity torques only)",)
    elif "{" not in tpl:
        if tpl not in table.columns:
            raise DataError(f"no array {tpl!r} for 'M'", file=path.name)
        M = table.columns[tpl] * columns.factor("M")
    else:
        M = _matrix(table, columns, n, q.shape[0])
    bad = ~(np.all(np.isfinite(q), 1) & np.all(np.isfinite(g), 1))
    bad |= ~np.all(np.isfinite(M.reshape(len(M), -1)), 1)
    if bad.any():
        rows = np.flatnonzero(bad)
        where = _where(rows, table.lines)
        if not drop_invalid or rows.size == len(bad):
            raise DataError(
                f"{rows.size} row(s) hold NaN or inf ({where}); hint: fix the file or pass "
                "--drop-invalid (drop_invalid=True) to drop such rows",
                file=path.name,
            )
        q, M, g = q[~bad], M[~bad], g[~bad]
        extra += (f"dropped {rows.size} row(s) holding NaN or inf of {len(bad)}: {where}",)
    said = conversion_notes(columns, list(columns.factors))
    try:  # a full matrix's triangles checked for symmetry, the file named
        data = StaticDataset(q, M, g, {"file": path.name})
    except DataError as exc:
        raise DataError(str(exc), file=path.name) from None
    return MappedStatic(data, extra, said)


def _matrix(table: _Table, cmap: ColumnMap, n: int, rows: int) -> NDArray[np.float64]:
    """``M`` (rows, n, n) [SI] from the columns of its template: each entry ``(i, j)`` from
    its own column, or from ``(j, i)``'s where only one triangle is there (both present:
    read as they are, the data set checks their symmetry).

    Raises
    ------
    DataError
        Neither ``(i, j)`` nor ``(j, i)`` is there (named, with the map that reads the
        file when its header tells one).
    """
    tpl = cmap.template("M")
    M = np.zeros((rows, n, n))
    for i in range(n):
        for j in range(i + 1):
            have = [
                c
                for c in (_fill_matrix(tpl, i, j, n), _fill_matrix(tpl, j, i, n))
                if c in table.columns
            ]
            if not have:
                hint = static_map(table.header, n, cmap.columns) if table.header else ""
                raise DataError(
                    f"no column {_fill_matrix(tpl, i, j, n)!r} for M (template {tpl!r}); "
                    f"{table.has()}" + (f"; hint: {hint} reads the file" if hint else ""),
                    file=table.name,
                )
            M[:, i, j] = table.columns[have[0]]
            M[:, j, i] = table.columns[have[-1]]
    return M * cmap.factor("M")


def _static_vector(table: _Table, cmap: ColumnMap, quantity: str, n: int | None) -> NDArray:
    """:func:`_need` for static data, its error's hint the map that reads the file when its
    header tells one (:func:`~dynid.io.column_hint.static_map`: libfranka's ``q0..q6``)."""
    try:
        return _need(table, cmap, quantity, n)
    except DataError as exc:
        guess = static_map(table.header, n, cmap.columns) if n and table.header else ""
        if not guess:
            raise
        raise DataError(
            f"{str(exc).removeprefix(table.name + ': ').partition('; hint:')[0]}; hint: {guess} "
            "reads the file",
            file=table.name,
        ) from None
