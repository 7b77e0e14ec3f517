"""A prior's link that is physically valid but within the margin is *held at the margin*,
not *repaired*: only a link that breaks a physical condition (no positive semidefinite
pseudo-inertia: the triangle inequality; a mass at or below zero) is repaired.

References: a uniform solid box (closed-form inertia, a real body whose thinness puts
``lambda_min(J) / tr(J)`` at 3.3e-7); the triangle inequality of the principal moments;
the Unitree Z1's URDF of example-robot-data (link05 at 0.000199 against 0.0002).
"""

from __future__ import annotations

import numpy as np

import dynid
from dynid.feasibility.prior import DEFAULT_PRIOR_MARGIN, default_prior, prior_from_robot

from conftest import robot_data_urdf


def _with_link(robot, i, mass, inertia):
    """``robot`` with link ``i`` (0-based) of ``mass`` [kg] and CoM ``inertia`` [kg m^2]."""
    m, c, I = robot.mass.copy(), robot.com.copy(), robot.inertia.copy()
    m[i], I[i] = mass, inertia
    return robot.with_inertials(m, c, I)


def test_a_thin_box_is_held_at_the_margin_and_a_broken_link_repaired():
    """A 1 kg box 0.3 x 0.2 x 0.002 m (valid, thin) on link 3 is held; an inertia with
    Izz > Ixx + Iyy on link 5 and a negative mass on link 6 are repaired; each said so."""
    a, b, c = 0.3, 0.2, 0.002
    box = np.diag([b**2 + c**2, a**2 + c**2, a**2 + b**2]) / 12.0
    moments = np.linalg.eigvalsh(box)
    assert moments[0] > 0 and moments[2] <= moments[0] + moments[1]  # a body: valid
    robot = _with_link(dynid.panda(), 2, 1.0, box)
    robot = _with_link(robot, 4, 1.0, np.diag([0.01, 0.01, 0.05]))  # Izz > Ixx + Iyy
    robot = _with_link(robot, 5, -0.5, robot.inertia[5])
    pr = prior_from_robot(robot, source="cad.urdf")
    assert 3 in pr.held and not set(pr.held) & set(pr.repaired)  # the Panda's 2, 5, 6 too
    assert pr.repaired == (5, 6)
    held = [n for n in pr.notes if "held at the margin" in n]
    assert len(held) == 1 and "3 (link3" in held[0] and "physically valid" in held[0]
    broken = [n for n in pr.notes if "not physically consistent" in n]
    assert len(broken) == 1 and "5 (link5" in broken[0] and "repaired" in broken[0]
    assert not any("3 (link3" in n for n in broken)


def test_the_z1s_link05_is_held_at_the_margin_not_repaired():
    """The untouched Z1 URDF: its link05 (lambda_min(J)/tr(J) 0.000199, a valid body by
    the triangle inequality) is held at the margin; the prior's note says no link was
    repaired (before: 'link(s) 5 repaired')."""
    robot = dynid.Robot.from_urdf(robot_data_urdf("z1_description/urdf/z1.urdf"), tip_link="link06")
    moments = np.linalg.eigvalsh(robot.inertia[4])
    assert moments[0] >= 0 and moments[2] <= moments[0] + moments[1]
    pr = default_prior(robot)
    assert pr.held == (5,) and pr.repaired == ()
    assert "link(s) 5 held at the margin" in pr.notes[0] and "repaired" not in pr.notes[0]
    assert not any("repaired" in n for n in pr.notes)
    assert any("5 (link05: 0.000199)" in n for n in pr.notes)
    assert DEFAULT_PRIOR_MARGIN == 2e-4
