"""What every method of physically consistent parameters returns: :class:`FeasibleResult`.

The convex fit (:class:`~dynid.feasibility.convex.result.ConsistentResult`, two-step and one-step)
and the paper's penalty method (:class:`~dynid.feasibility.penalty.result.RetrievalResult`,
Gaz et al. 2019, Algorithm 1) derive from it. It holds what both mean the same way: the
robot with the consistent link parameters, how far they are from the identified
coefficients, every constraint with its margin, the bounds, the run time, the seed, what
the user should know, and what was identified beside the links (classical friction, rotor
inertias, the drive, the held-out judgement; None for a method that does not identify
them). Whoever needs only that (``feasible.json``, ``report.json``, the output folder,
the comparison of methods, the figures) takes a :class:`FeasibleResult`.

A method adds its own entries of ``report.json`` through one hook,
:meth:`FeasibleResult.report_fields`, and names among them those whose numbers may have
no value (:attr:`FeasibleResult.nullable_fields`, written ``null``).
"""

from __future__ import annotations

from collections.abc import Mapping
from dataclasses import dataclass
from types import MappingProxyType
from typing import Any, ClassVar

import numpy as np
from numpy.typing import NDArray

from ..friction.model import Friction, FrictionSum
from ..model.drive import Drive
from ..model.inertia import params_from_inertial
from ..model.robot import Robot
from ..model.stiffness import JointStiffness
from .bounds import Bounds
from .constraints import FeasibilityReport
from .determined import Determined
from .heldout import HeldOutJudgement
from .lmi import pseudo_inertia_margin

__all__ = ["FeasibleResult"]


@dataclass(frozen=True, slots=True, eq=False, kw_only=True)
class FeasibleResult:
    """Physically consistent link parameters, whichever method found them.

    Attributes
    ----------
    robot : Robot
        The input robot (kinematics, limits, sigmoid friction) with the consistent link
        parameters.
    relative_residual : float
        How far the parameters are from the identified coefficients, relative:
        ``||P phi - beta|| / ||beta||`` over the kept coefficients (the penalty method's
        single-step variant: ``||Y_s phi - s|| / ||s||`` on the static data) [1].
    feasible : bool
        Every constraint of ``report`` holds.
    report : FeasibilityReport
        Every constraint with its margin: the physical ones (Gaz et al. 2019, eq. 16), the
        bounds, the total-mass band and ``data_fit``; the convex method adds
        ``pseudo_inertia`` (``lambda_min(J)/tr(J)``).
    run_time : float
        Wall time [s].
    bounds : Bounds
        The bounds used.
    total_mass : (float, float) or None
        The total-mass band used [kg].
    kind : str
        What was fitted: ``"coefficients"`` (two-step), ``"static"`` or ``"log"``
        (one-step, from the data).
    seed : int or None
        The penalty method's seed (recorded for files; the convex method uses none).
    notes : tuple of str
        What the user should know (one line each).
    friction : Friction, FrictionSum or None
        The friction identified with the links (:mod:`dynid.friction.model`: its law,
        parameters, band and where it acts; the law of the structure of the one-step fit
        on a torque log, at the motors with a drive whose friction acts there; a
        :class:`~dynid.friction.model.FrictionSum` of friction at the motors and at the
        joints of a coupled drive); None when the method fits the links alone.
    rotor_inertia : ndarray, shape (n,), or None
        Rotor inertias at the motors identified with the links [kg m^2] (0 for a rotor the
        model's armature leaves out); None otherwise.
    spring : JointStiffness or None
        The joint springs identified with the links (stiffness ``>= 0`` [N m/rad] about the
        term's rest positions, :mod:`dynid.model.stiffness`); None without a spring term.
    drive : Drive or None
        The drive train of the data, its rotor inertias the identified ones.
    heldout : HeldOutJudgement or None
        Training and held-out errors against least squares and the acceptance, when the
        data held held-out folds.
    determined : Determined or None
        Of an identified model's coefficients: how many are link base parameters and how
        many rotor inertias, and which retrieved parameters (masses, rotor inertias) the
        data determine and which the prior decides (:mod:`dynid.feasibility.determined`);
        None from static data.
    method : str
        Class attribute: ``"sdp"`` or ``"penalty"``.
    nullable_fields : frozenset of str
        Class attribute: keys of :meth:`report_fields` whose numbers may be NaN (no
        value), written ``null``; any other NaN is a fault when written.
    field_units : mapping of str to str
        Class attribute: units of :meth:`report_fields`' entries, for ``report.json``'s
        ``units``.
    """

    robot: Robot
    relative_residual: float
    feasible: bool
    report: FeasibilityReport
    run_time: float
    bounds: Bounds
    total_mass: tuple[float, float] | None
    kind: str
    seed: int | None = None
    notes: tuple[str, ...] = ()
    friction: Friction | FrictionSum | None = None
    rotor_inertia: NDArray[np.float64] | None = None
    drive: Drive | None = None
    spring: JointStiffness | None = None
    heldout: HeldOutJudgement | None = None
    determined: Determined | None = None

    method: ClassVar[str] = ""
    nullable_fields: ClassVar[frozenset[str]] = frozenset()
    field_units: ClassVar[Mapping[str, str]] = MappingProxyType({})

    @property
    def mass(self) -> NDArray[np.float64]:
        """Link masses [kg], (n,)."""
        return self.robot.mass

    @property
    def com(self) -> NDArray[np.float64]:
        """CoMs in the link frames [m], (n, 3)."""
        return self.robot.com

    @property
    def inertia(self) -> NDArray[np.float64]:
        """Inertias about the CoMs, link axes [kg m^2], (n, 3, 3)."""
        return self.robot.inertia

    @property
    def phi(self) -> NDArray[np.float64]:
        """Standard parameters (n, 10): ``m, m c, I`` about the link origin."""
        return self.robot.phi

    @property
    def p(self) -> NDArray[np.float64]:
        """Decision layout (n, 10): ``m, c, I`` about the CoM (order ``xx xy xz yy yz zz``)."""
        return params_from_inertial(self.mass, self.com, self.inertia)

    @property
    def pseudo_inertia_margin(self) -> NDArray[np.float64]:
        """``lambda_min(J_i) / tr(J_i)`` of every link's pseudo-inertia [1], (n,); positive
        for a physically consistent link (Wensing, Kim, Slotine 2018)."""
        return pseudo_inertia_margin(self.phi)

    def report_fields(self) -> dict[str, Any]:
        """The method's own entries of ``report.json``, beside the shared ones.

        Returns
        -------
        dict
            Key to a JSON value (numbers, strings, lists, dicts; numpy arrays allowed). A
            number of an entry named in :attr:`nullable_fields` may be NaN (written
            ``null``). No key of the shared part (``relative_residual``, ``feasible``,
            ``constraints``, ...) is repeated.
        """
        return {}
