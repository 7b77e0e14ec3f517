"""What the identification core takes: a data set, the model's columns, regressor blocks.

A data set is anything with the :class:`Dataset` protocol: static data
(:class:`~dynid.identification.data.StaticDataset`) and prepared torque logs
(:class:`~dynid.identification.prepared_log.PreparedLog`); the core
(:func:`~dynid.identification.core.identify`) fits the regressor blocks it gives over the
:class:`ModelColumns`.
"""

from __future__ import annotations

from collections.abc import Iterator
from dataclasses import dataclass
from typing import Any, Literal, Protocol

import numpy as np
from numpy.typing import NDArray

from ..model.drive import Drive
from ..model.robot import Robot
from ..regressors.base import BaseParameters
from ..regressors.terms import ModelTerm
from .info import IdentificationInfo, Route
from .serial import Serial

__all__ = [
    "Dataset",
    "ModelColumns",
    "RegressorBlock",
    "RegressorKind",
    "Route",
    "TorqueRoute",
]

#: Which regressor a data set stacks (the kind of :func:`~dynid.regressors.base.
#: base_parameters`).
RegressorKind = Literal["static", "torque"]


@dataclass(frozen=True, slots=True, eq=False)
class ModelColumns:
    """The columns of a model: base parameters, then the appended terms' parameters.

    Attributes
    ----------
    base : BaseParameters
        Over the link parameters and the ``in_base`` terms (rotor inertias).
    terms : tuple of ModelTerm
        Every term; those not ``in_base`` (friction) append their columns after ``beta``.
    drive : Drive, optional
        The drive the data are read through (known rotor inertias are subtracted).
    """

    base: BaseParameters
    terms: tuple[ModelTerm, ...] = ()
    drive: Drive | None = None

    @property
    def appended(self) -> tuple[ModelTerm, ...]:
        """The terms whose columns follow the base parameters."""
        return tuple(t for t in self.terms if not t.in_base)

    @property
    def labels(self) -> tuple[str, ...]:
        """One label per column: ``base.labels`` then the appended terms' labels."""
        out = self.base.labels
        for t in self.appended:
            out = out + t.labels
        return out

    def step_columns(self) -> NDArray[np.bool_]:
        """(c,): the columns that step where a velocity reverses (a term's ``steps``)."""
        return self._per_column("steps", False).astype(bool)

    def motion_columns(self) -> NDArray[np.intp]:
        """(c,): the joint (motor) whose motion each column needs to be identified, -1 for
        none (a term's ``needs_motion``; the base parameters need none of their own)."""
        return self._per_column("needs_motion", -1).astype(np.intp)

    def _per_column(self, attr: str, fill: bool | int) -> NDArray[Any]:
        """An optional per-parameter property ``attr`` of the appended terms over every
        column, ``fill`` for the base parameters and the terms without it."""
        out = [np.full(self.base.rank, fill)]
        for t in self.appended:
            v = getattr(t, attr, None)
            out.append(np.full(len(t.labels), fill) if v is None else np.asarray(v))
        return np.concatenate(out)


@dataclass(frozen=True, slots=True, eq=False)
class RegressorBlock:
    """Rows of the stacked regressor of one kind, with their targets and noise groups.

    Attributes
    ----------
    W : ndarray, shape (m, c)
        Regressor rows over the model's columns (:class:`ModelColumns` order).
    y : ndarray, shape (m,)
        Measured targets (SI: N m, kg m^2).
    groups : ndarray of int, shape (m,)
        Noise group of each row (joint of a torque log, row of ``[tril M; g]``).
    label : str
        What the rows are (``"g1"``); names a dropped block.
    first : int
        ``W[:, :first]`` is exactly zero (products over the rows skip those columns).
    group_labels : tuple of str
        Set on a block of rows of many groups that is one of several pieces of data too
        large to stack (static data of a long chain): the name of every group. The core
        then fits the pieces in passes (:class:`StreamedRows`), never concatenated, and
        drops the groups without information by these names.
    """

    W: NDArray[np.float64]
    y: NDArray[np.float64]
    groups: NDArray[np.intp]
    label: str = ""
    first: int = 0
    group_labels: tuple[str, ...] = ()


class Dataset(Protocol):
    """What the core needs of data (module docstring)."""

    @property
    def route(self) -> Route:
        """``"static"`` or ``"classical"``: recorded in the model."""
        ...

    @property
    def regressor_kind(self) -> RegressorKind:
        """The regressor it stacks: ``"static"`` or ``"torque"``."""
        ...

    @property
    def moving(self) -> bool:
        """True when the data move (friction acts and can be identified)."""
        ...

    @property
    def source(self) -> str:
        """The data in a few words, for messages (``"static regressor of 5 configuration(s)"``)."""
        ...

    @property
    def hint(self) -> str:
        """What to do when the data do not excite every column (ends a rank error)."""
        ...

    def check_robot(self, robot: Robot) -> None:
        """Raise unless the data belong to a robot with ``robot.n`` joints."""
        ...

    def frozen_columns(self, columns: ModelColumns) -> NDArray[np.bool_]:
        """Columns (c,) the data cannot excite (left out of the fit)."""
        ...

    def blocks(self, robot: Robot, columns: ModelColumns) -> Iterator[RegressorBlock]:
        """The regressor blocks over ``columns`` with their targets."""
        ...

    def record(self, n_rows: int) -> IdentificationInfo:
        """The data's part of the model's record (reference, counts, preparation), given
        the rows used; the core fills in the rest."""
        ...

    @property
    def serial(self) -> Serial | None:
        """The time structure of the rows of :meth:`blocks` (rows per sample, pieces, the
        HAC window) for ``std="hac"`` (:mod:`dynid.identification.serial`); None: the
        rows are independent."""
        ...


class TorqueRoute:
    """What every data set of joint-torque logs says of itself (a mixin of slotted
    dataclasses): the classical route, the torque regressor, friction acting."""

    __slots__ = ()

    @property
    def route(self) -> Literal["classical"]:
        """``"classical"`` (Gaz et al. 2019, Sec. IV-B)."""
        return "classical"

    @property
    def regressor_kind(self) -> Literal["torque"]:
        """Joint torques."""
        return "torque"

    @property
    def moving(self) -> bool:
        """True: friction acts."""
        return True
