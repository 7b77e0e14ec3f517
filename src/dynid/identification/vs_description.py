"""The identified base parameters beside the robot description's own.

A description with link inertials (a URDF's ``<inertial>`` elements, a TOML robot's, the
built-in Panda's and FR3's published ones of Gaz et al. 2019) has base parameters of its
own: its standard parameters ``phi_d`` through the identification's base map,

.. math:: \\beta_d = P \\phi_d, \\qquad
          z_k = (\\hat\\beta_k - \\beta_{d,k}) / \\sigma_k,

``sigma_k`` the identified coefficient's standard deviation (the fit's estimator: robust,
HAC or classical). ``z`` says how many standard deviations of the data's own uncertainty
the identification stands from the description: within about 3 over most base parameters
when the description is the arm's (and the fit's standard deviations are right), large
where a link's inertial is off. The rigid-body base parameters only: one whose expression
holds a coefficient of a term in the base (a rotor inertia ``Ia1`` regrouped as ``J1zz +
... + Ia1``), which the description does not give, has no description value.

A description without inertials (every mass and inertia zero: a kinematic URDF) or with
placeholders (every link of three or more the same inertial, a URDF's ``mass 1`` copied
to each link) is not compared (:func:`described_inertials`). Nor is a coefficient left out
(pruned) or one whose standard deviation is zero or not finite (exact data): its ``z`` is
NaN.
"""

from __future__ import annotations

import re
from dataclasses import dataclass

import numpy as np
from numpy.typing import NDArray

from .. import _checks
from ..exceptions import OptionError
from ..model.robot import Robot
from .model import IdentifiedModel

__all__ = [
    "BEYOND",
    "DescriptionComparison",
    "described_inertials",
    "description_comparison",
]

#: ``|z|`` above this names a base parameter in the summary (standard deviations).
BEYOND = 3.0
#: At most this many base parameters beyond :data:`BEYOND` are named in the summary.
NAMED = 5


@dataclass(frozen=True, slots=True, eq=False)
class DescriptionComparison:
    """An identified model's base parameters against its description's.

    Attributes
    ----------
    source : str
        The description's name (the robot's).
    labels, expressions : tuple of str, length r
        The base parameters (``beta1``) and their expressions in the standard parameters.
    values : ndarray, shape (r,)
        The description's base parameters ``P phi_d`` [SI of each expression: kg, kg m,
        kg m^2]; NaN where the expression holds a term's coefficient the description
        does not give (a rotor inertia).
    z : ndarray, shape (r,)
        ``(identified - description) / std`` [standard deviations]; NaN where not
        compared (no description value, the coefficient pruned, its std zero or NaN).
    threshold : float
        ``|z|`` above which a base parameter is named (:data:`BEYOND`).
    """

    source: str
    labels: tuple[str, ...]
    expressions: tuple[str, ...]
    values: NDArray[np.float64]
    z: NDArray[np.float64]
    threshold: float = BEYOND

    @property
    def compared(self) -> NDArray[np.bool_]:
        """(r,): the base parameters with a finite ``z``."""
        out: NDArray[np.bool_] = np.isfinite(self.z)
        return out

    @property
    def n_compared(self) -> int:
        """How many base parameters have a finite ``z``."""
        return int(np.sum(self.compared))

    @property
    def rms_z(self) -> float | None:
        """The root mean square of the finite ``z``; None without any."""
        z = self.z[self.compared]
        return float(np.sqrt(np.mean(z**2))) if z.size else None

    @property
    def beyond(self) -> tuple[int, ...]:
        """The indices of the base parameters with ``|z|`` above :attr:`threshold`,
        largest ``|z|`` first."""
        z = np.where(self.compared, np.abs(self.z), 0.0)
        idx = np.flatnonzero(z > self.threshold)
        return tuple(int(k) for k in idx[np.argsort(-z[idx], kind="stable")])

    def sentence(self, *, width: int = 28) -> str:
        """The summary's one line: ``against the description's inertials (panda): RMS z
        1.36 over 43 base parameters; beyond 3 std: beta4 = J2xz (+4.1), ...``, ``z`` to
        0.1 std, at most :data:`NAMED` named, each expression cut to its terms within
        ``width`` characters (``J4zz + 0.15426225*m5 + ...``)."""
        head = f"against the description's inertials ({self.source})"
        without = int(np.sum(~np.isfinite(self.values)))
        lacks = (
            f"; {without} hold a rotor inertia, which the description does not give"
            if without
            else ""
        )
        rms = self.rms_z
        if rms is None:
            return (
                f"{head}: no standard deviations to weigh the differences by "
                f"(exact data, or every coefficient pruned){lacks}"
            )
        said = f"{head}: RMS z {rms:.3g} over {self.n_compared} base parameters{lacks}"
        far = self.beyond
        if not far:
            return said + f"; none beyond {self.threshold:g} std"
        names = [
            f"{self.labels[k]} = {_cut(self.expressions[k], width)} ({self.z[k]:+.1f})"
            for k in far[:NAMED]
        ]
        more = f" and {len(far) - NAMED} more" if len(far) > NAMED else ""
        return said + f"; beyond {self.threshold:g} std: " + ", ".join(names) + more

    def as_dict(self) -> dict[str, object]:
        """The summary as ``identification.json``'s ``vs_description`` holds it: ``source``,
        ``rms_z`` (null without any), ``n_compared``, ``threshold``, ``beyond`` (each
        ``name`` and ``z``, largest first) and ``said`` (:meth:`sentence`)."""
        return {
            "source": self.source,
            "rms_z": self.rms_z,
            "n_compared": self.n_compared,
            "threshold": self.threshold,
            "beyond": [{"name": self.labels[k], "z": float(self.z[k])} for k in self.beyond],
            "said": self.sentence(),
        }


def described_inertials(robot: Robot) -> bool:
    """Whether ``robot``'s description holds link inertials to compare with: some mass or
    inertia not zero, and not every link the same inertial on an arm of three links or
    more (a placeholder copied to each link; two links alike may be an arm's own)."""
    _checks.of_type("robot", robot, Robot, "a Robot (dynid.panda(), Robot.from_urdf(...))")
    phi = np.asarray(robot.phi, dtype=np.float64).reshape(robot.n, 10)
    if not np.any(phi):
        return False
    return robot.n < 3 or not np.all(phi == phi[0])


def description_comparison(
    model: IdentifiedModel, *, threshold: float = BEYOND
) -> DescriptionComparison | None:
    """The identified base parameters of ``model`` against its description's (module
    docstring); None when the description holds no inertials (:func:`described_inertials`).

    Parameters
    ----------
    model : IdentifiedModel
        The identification; its description is :attr:`IdentifiedModel.description` (the
        robot identified with, or the inertials a model read from a file kept).
    threshold : float
        ``|z|`` above which a base parameter is named [standard deviations].

    Returns
    -------
    DescriptionComparison or None

    Raises
    ------
    OptionError
        ``threshold`` not a positive finite number.
    """
    model = _checks.of_type("model", model, IdentifiedModel, "an IdentifiedModel")
    if isinstance(threshold, bool) or not isinstance(threshold, int | float):
        raise OptionError(f"must be a number; got {_checks.short(threshold)}", field="threshold")
    if not (np.isfinite(threshold) and threshold > 0):
        raise OptionError(
            f"must be finite and above 0; got {_checks.short(threshold)}", field="threshold"
        )
    described = model.description
    if not described_inertials(described):
        return None
    base, fit = model.base, model.fit
    links = 10 * described.n
    phi = np.zeros(base.n_std)
    phi[:links] = np.asarray(described.phi, dtype=np.float64).reshape(-1)
    values = base.beta_from_phi(phi)
    terms = np.any(base.projection[:, links:] != 0.0, axis=1)  # a rotor inertia in it
    values = np.where(terms, np.nan, values)
    std = np.asarray(fit.std, dtype=np.float64)
    ok = np.asarray(fit.kept, dtype=bool) & ~terms & np.isfinite(std) & (std > 0.0)
    z = np.full(base.rank, np.nan)
    z[ok] = (np.asarray(fit.beta)[ok] - values[ok]) / std[ok]
    return DescriptionComparison(
        source=described.name,
        labels=base.labels,
        expressions=base.expressions,
        values=_checks.frozen(values),
        z=_checks.frozen(z),
        threshold=threshold,
    )


def _cut(expression: str, width: int) -> str:
    """``expression`` whole when it fits in ``width`` characters, else its leading terms
    that do, then `` + ...`` (the first term at least)."""
    if len(expression) <= width:
        return expression
    cuts = [m.start() for m in re.finditer(r" [+-] ", expression) if m.start() <= width]
    return (expression[: cuts[-1]] if cuts else expression.split(" ")[0]) + " + ..."
