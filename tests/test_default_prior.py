"""The consistent fit's default prior is the robot's own description's inertials.

Regression: without ``--prior`` the consistent fit pulled towards solid cylinders and
ignored the ``--robot`` description's inertials: a 7-joint arm of 10.77 kg came out at
13.44 kg (link 7 at 0.58 kg for 0.158 kg), its rotor inertia Ia5 at 3e-9 where least
squares gave 0.0128 +- 13 %, while the description as ``--prior`` gave 10.76 kg.

References: simulated ground truth (the planar 2R arm of ``conftest``; its description's
inertials 15-20 % off, as a CAD model's are), the generic prior of the same kinematics.
"""

from __future__ import annotations

import numpy as np
import pytest

import dynid
from dynid.feasibility.convex import identify_consistent
from dynid.feasibility.convex.data_term import DataTerm
from dynid.feasibility.convex.result import moved_note
from dynid.feasibility.prior import default_prior, generic_prior, prior_from_robot
from dynid.identification.structure import Structure
from dynid.simulation.measurement import sample_times, simulate_measurement
from dynid.simulation.trajectories import random_fourier

from conftest import planar_2r

pytestmark = pytest.mark.filterwarnings("ignore::dynid.DynidWarning")


def test_default_prior_is_the_descriptions_inertials_or_generic_without_them():
    """A robot with consistent inertials is its own prior (named in a note); one with none
    gets the generic prior; an inconsistent link is repaired and said."""
    panda = dynid.panda()
    pr = default_prior(panda)
    assert pr.source == "description" and "link inertials of the robot's description" in pr.notes[0]
    np.testing.assert_allclose(pr.phi, prior_from_robot(panda).phi, rtol=0, atol=0)
    bare = panda.with_params(np.zeros_like(panda.phi))
    gen = default_prior(bare)
    assert gen.generic and "has no link inertials" in gen.notes[0]
    np.testing.assert_allclose(gen.phi, generic_prior(bare).phi, rtol=0, atol=0)
    phi = np.array(panda.phi).reshape(panda.n, 10)
    phi[6, 4] = phi[6, 7] + phi[6, 9] + 1.0  # J_xx above J_yy + J_zz: no body has it
    bad = default_prior(panda.with_params(phi.reshape(-1)))
    assert 7 in bad.repaired and 7 not in pr.repaired
    assert any("floored" in n and "7 (" in n for n in bad.notes)


def test_consistent_fit_without_a_prior_finds_the_true_masses_from_the_description():
    """Simulated 2R arm (2.0 + 1.5 kg), its description 2.3 + 1.7 kg: the default prior gives
    masses within 5 % of the truth; the generic cylinders, which it used, put link 1 at
    nearly twice its mass."""
    truth = planar_2r()
    desc = planar_2r(m1=2.3, m2=1.7, I1=0.06, I2=0.035)
    rng = np.random.default_rng(1)
    traj = random_fourier(truth, rng, n_harmonics=5)(sample_times(6.0, 100.0))
    log = simulate_measurement(truth, traj, rng=rng)
    links = Structure.parse("links")
    res = identify_consistent(desc, log, structure=links)
    assert res.prior.source == "description"
    np.testing.assert_allclose(res.mass, [2.0, 1.5], rtol=0.05)
    gen = identify_consistent(desc, log, prior=generic_prior(desc), structure=links)
    assert abs(gen.mass[0] - 2.0) > 0.3


def test_moved_note_names_determined_coefficients_pulled_away_from_the_data():
    """A coefficient determined to 10 % moved by 8 of its standard deviations is named with
    its values; one moved by 2, or undetermined (200 %), is not."""
    term = DataTerm(
        P=np.eye(3, 20),
        x_hat=np.array([0.0128, 1.0, 0.01]),
        A=np.eye(3),
        dof=100,
        exact=False,
        labels=("Ia5", "b2", "b3"),
        std=np.array([0.00128, 0.1, 0.02]),
    )
    note = moved_note(term, np.array([0.0128 - 8 * 0.00128, 1.2, 0.2]))
    assert note is not None and "moves 1 coefficient(s)" in note
    assert "Ia5 0.0128 +- 10 % -> 0.00256 (8 sd)" in note
    assert moved_note(term, term.x_hat) is None


def test_prior_generic_still_asks_for_the_cylinders():
    """``--prior generic`` takes the solid cylinders of the kinematics, as the default did
    before it took the description's inertials: each link's mass and first moment are the
    cylinder's (closed form: the generic prior of the same kinematics), whatever the
    description holds; an unknown name lists 'generic' among the choices."""
    from dynid.exceptions import OptionError
    from dynid.workflows.prior import load_prior

    panda = dynid.panda()
    prior = load_prior("generic", panda)
    assert prior is not None and prior.name.startswith("generic")
    np.testing.assert_allclose(prior.phi, generic_prior(panda).phi, rtol=0, atol=0)
    assert not np.allclose(prior.phi[:, 0], panda.phi[:, 0])
    with pytest.raises(OptionError, match="'generic' or 'panda'"):
        load_prior("cylinders", panda)


def test_a_generic_prior_given_by_name_does_not_bound_the_masses():
    """``--prior generic`` is a guess, as the default's cylinders are: its masses do not
    bound the fit's to a factor of 3 around them (a UR5's wrist link, 1.22 kg, was held at
    the cylinder's 5.03 kg / 3 = 1.68 kg "at its lower bound"); the kinematic bounds alone
    hold (0 to the link's generic maximum), while a description's prior still bounds."""
    from dynid.feasibility.bounds import kinematic_bounds
    from dynid.feasibility.convex.problem import mass_bounds
    from dynid.workflows.prior import load_prior

    robot = planar_2r()
    given = prior_from_robot(load_prior("generic", robot))
    bounds = kinematic_bounds(robot)
    assert given.generic and generic_prior(robot).generic
    lo, hi, _ = mass_bounds(given, bounds, 3.0)
    np.testing.assert_array_equal(lo, bounds.mass_min)
    np.testing.assert_array_equal(hi, bounds.mass_max)
    own = prior_from_robot(robot)
    lo, hi, _ = mass_bounds(own, bounds, 3.0)
    np.testing.assert_allclose(lo, np.maximum(bounds.mass_min, own.mass / 3.0))
