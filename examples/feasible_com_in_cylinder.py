"""Retrieve feasible Panda link parameters with a user constraint: a CoM inside a cylinder.

The identified coefficients of the Panda fix only combinations of its link parameters;
the mass of link 7 and hence its centre of mass are not identifiable on their own
(only ``m7 c7x`` and ``m7 c7y`` are). Here the retrieval (Gaz et al. 2019, Algorithm 1)
is told that the CoM of link 7 lies inside a cylinder about the flange axis z7: radius
2 cm, from the joint-7 axis up to the flange (0 <= z <= 0.107 m). A user constraint is a
callable ``p -> violation >= 0`` on the decision parameters ``p`` (n, 10), per link
``m, cx, cy, cz, Ixx, Ixy, Ixz, Iyy, Iyz, Izz`` (inertia about the CoM); it is zero when
the constraint holds. It is a module-level class so that it pickles for runs in several
processes.

Runs headless in a few seconds::

    python examples/feasible_com_in_cylinder.py
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

import dynid
from dynid.feasibility.constraints import UserConstraint
from dynid.feasibility.penalty import RetrievalOptions, retrieve_from_coefficients
from dynid.regressors.base import base_parameters


@dataclass(frozen=True)
class CoMInCylinder:
    """Distance [m] of link ``link``'s CoM outside a cylinder about the link's z axis.

    The cylinder has radius ``radius`` [m] and spans ``z_min <= z <= z_max`` [m] in the
    link frame; the violation is the radial excess plus the axial excess (0 inside).
    """

    link: int  # 1-based
    radius: float
    z_min: float
    z_max: float

    def __call__(self, p: np.ndarray) -> float:
        cx, cy, cz = p[self.link - 1, 1:4]
        radial = max(0.0, float(np.hypot(cx, cy)) - self.radius)
        axial = max(0.0, self.z_min - float(cz)) + max(0.0, float(cz) - self.z_max)
        return radial + axial


def main(runs: int = 4, workers: int = 1, seed: int = 0) -> dynid.Robot:
    """Retrieve, print the CoM of link 7 and the constraint's margin; return the robot."""
    robot = dynid.panda()
    base = base_parameters(robot)
    beta = base.beta_from_phi(robot.phi)  # noise-free coefficients of the published model
    cylinder = CoMInCylinder(link=7, radius=0.02, z_min=0.0, z_max=0.107)
    result = retrieve_from_coefficients(
        robot,
        base,
        beta,
        extra=[UserConstraint("com7_in_cylinder", cylinder, link=7)],
        options=RetrievalOptions(runs=runs),
        workers=workers,
        seed=seed,
    )
    c7 = result.com[6]
    print(f"feasible: {result.feasible}; relative residual {result.relative_residual:.2e}")
    print(
        f"link 7: mass {result.mass[6]:.4f} kg, CoM {np.round(c7, 4)} m, "
        f"radius {np.hypot(c7[0], c7[1]):.4f} m (cylinder radius {cylinder.radius} m)"
    )
    (con,) = result.report.select("com7_in_cylinder")
    print(f"user constraint {con.name}: violation {-con.margin:.3g} m, satisfied {con.satisfied}")
    print(f"{result.run_time:.1f} s, {result.n_feasible_runs}/{len(result.runs)} runs feasible")
    return result.robot


if __name__ == "__main__":
    main()
