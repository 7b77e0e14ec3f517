"""The consistent-parameter methods, in one registry: :data:`METHODS`.

A method answers two questions, with one signature for every method
(:class:`ConsistentMethod`):

* **from coefficients** (two-step): physically consistent link parameters that reproduce an
  :class:`~dynid.identification.model.IdentifiedModel`'s coefficients;
* **from data** (one step): the same straight from static data or a torque log, with no
  separate identification.

Both return a :class:`~dynid.feasibility.result.FeasibleResult`, which files, reports,
figures and the comparison of methods read. ``dynid retrieve --method NAME`` and
:func:`dynid.workflows.retrieve.retrieve_files` take any name of :data:`METHODS`.

* ``sdp``, the convex method (:mod:`dynid.feasibility.convex`): from coefficients
  :func:`~dynid.feasibility.convex.fit.retrieve_sdp`, from a torque log or static data
  :func:`~dynid.feasibility.convex.fit.identify_consistent`;
* ``penalty``, the paper's method (:mod:`dynid.feasibility.penalty`): from coefficients
  :func:`~dynid.feasibility.penalty.fit.retrieve`, from static data
  :func:`~dynid.feasibility.penalty.fit.retrieve_from_static`.

Adding a method: a module whose ``METHOD`` has the :class:`ConsistentMethod` protocol, and
one line in :data:`METHODS`.
"""

from __future__ import annotations

from collections.abc import Callable, Mapping
from types import MappingProxyType
from typing import Any, Protocol

from ..exceptions import OptionError
from ..identification.model import IdentifiedModel
from ..model.robot import Robot
from .bounds import Bounds
from .convex.fit import METHOD as CONVEX
from .penalty.fit import METHOD as PENALTY
from .result import FeasibleResult

__all__ = ["METHODS", "ConsistentMethod", "method"]


class ConsistentMethod(Protocol):
    """A method of physically consistent link parameters (an entry of :data:`METHODS`).

    Attributes
    ----------
    name : str
        Its key in :data:`METHODS` and ``--method``; the result's ``method``.
    description : str
        One line, for ``--method``'s help.
    options_type : type
        The frozen dataclass of its settings (``options=``).
    parallel : bool
        Runs over worker processes: it takes ``workers`` (and reports each finished run to
        ``progress``); a method that does not refuses ``workers`` (an
        :class:`~dynid.exceptions.OptionError`).
    """

    name: str
    description: str
    options_type: type
    parallel: bool

    def from_coefficients(
        self,
        model: IdentifiedModel,
        *,
        prior: Any = None,
        bounds: Bounds | None = None,
        total_mass: tuple[float, float] | None = None,
        options: Any = None,
        workers: int | None = None,
        seed: int | None = 0,
        progress: Callable[[Any], None] | None = None,
    ) -> FeasibleResult:
        """Consistent link parameters reproducing ``model``'s coefficients.

        ``prior``: a :class:`~dynid.feasibility.prior.Prior` or a robot with inertials
        (None: the method's default); ``bounds`` (None:
        :func:`~dynid.feasibility.bounds.default_bounds`) and ``total_mass`` [kg] (over
        the bounds' band); ``options`` of :attr:`options_type`; ``workers``, ``seed`` and
        ``progress`` for a method with independent runs.
        """
        ...

    def from_data(
        self,
        robot: Robot,
        data: Any,
        *,
        prior: Any = None,
        bounds: Bounds | None = None,
        total_mass: tuple[float, float] | None = None,
        options: Any = None,
        workers: int | None = None,
        seed: int | None = 0,
        progress: Callable[[Any], None] | None = None,
    ) -> FeasibleResult:
        """Consistent link parameters of ``robot`` straight from ``data`` (a
        :class:`~dynid.identification.data.StaticDataset` or a
        :class:`~dynid.identification.log.TorqueLog`; a method that cannot fit a kind
        raises :class:`~dynid.exceptions.WrongTypeError`). Other parameters as
        :meth:`from_coefficients`."""
        ...


#: every consistent-parameter method, by name (the first is the default)
METHODS: Mapping[str, ConsistentMethod] = MappingProxyType({m.name: m for m in (CONVEX, PENALTY)})


def method(name: str) -> ConsistentMethod:
    """The method ``name`` of :data:`METHODS`.

    Raises
    ------
    OptionError
        No method of that name (the message lists them).
    """
    try:
        return METHODS[name]
    except (KeyError, TypeError):
        raise OptionError(
            f"unknown consistent-parameter method {name!r}; choose from {', '.join(METHODS)}"
        ) from None
