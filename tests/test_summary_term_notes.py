"""The summary's tables of the terms identified with the links say what is true of them:
a rotor inertia left out without a drive reads "-" (no motor holds it), and a viscous
coefficient fitted below zero is named with how far it lies from zero.

References: exact recordings of the Panda with a known classical friction (the friction
coefficients come back to rounding), and the coefficients' values and standard deviations
given by hand.
"""

from __future__ import annotations

import numpy as np
import pytest

import dynid
from dynid.cli.summaries import term_lines
from dynid.friction.model import ClassicalFriction
from dynid.identification.dissipation import negative_viscous
from dynid.identification.selection import identify_recordings
from dynid.identification.structure import Structure

from conftest import recordings

FV = np.array([0.05, -0.04, 0.05, 0.05, 0.05, 0.05, 0.05])  # N m s/rad; joint 2 pushes
FC = np.full(7, 0.3)  # N m


@pytest.fixture(scope="module")
def model():
    """Exact recordings with the friction above, identified without a drive, the armature
    of joints 3 and 4 left out."""
    panda = dynid.panda()
    logs = recordings(panda, (1, 2), friction=ClassicalFriction(FV, FC, np.zeros(7)), duration=4.0)
    terms = Structure.parse("links + armature + viscous + coulomb - Ia3 - Ia4")
    return identify_recordings(panda, logs, cutoff_hz=None, structure=terms)


def _table(lines: list[str], head: str) -> dict[int, list[str]]:
    at = next(k for k, x in enumerate(lines) if x.startswith(head))
    return {int(r.split()[0]): r.split()[1:] for r in lines[at + 2 : at + 9]}


def test_a_rotor_left_out_without_a_drive_reads_left_out_not_the_motors(model):
    """Regression: a link-side log without a drive, the armature of joints 3-7 left out by
    the structure choice, read "motor's" with a line that the motor's fc holds fc_motor +
    fc_joint / gear ratio, true only with a geared drive; they read "-" now."""
    lines = term_lines(model)
    rows = _table(lines, "rotor_inertia identified")
    assert rows[3] == ["-"] and rows[4] == ["-"], rows
    assert not any("motor's" in x or "gear ratio" in x for x in lines), lines


def test_a_negative_viscous_coefficient_beyond_its_std_is_said_to_misfit(model):
    """Regression: least squares printed fv below zero on five joints without a word; the
    summary now names each (joint 2's true -0.04 back) and says the law misfits there."""
    fit = model.terms["friction"]
    k = fit.labels.index("fv2")
    np.testing.assert_allclose(fit.values[k], FV[1], atol=1e-6)
    said = [x for x in term_lines(model) if "viscous friction below zero" in x]
    assert len(said) == 1, said
    assert "fv2 -0.04" in said[0] and "std from 0" in said[0]
    assert "the friction law misfits there" in said[0]
    assert "fv1" not in said[0] and "indistinguishable" not in said[0]


def test_negative_viscous_tells_within_its_std_from_beyond():
    """Only kept viscous coefficients below zero are named; zero within 3 std of the value
    is indistinguishable from 0, beyond it is not (values given by hand; a true zero lies
    beyond one std on a third of the joints)."""
    labels = ("fv1", "fc1", "fv2", "fc2", "fv3", "fv4", "jfv5")
    values = np.array([-0.025, -0.3, -0.05, 0.3, 0.02, -0.2, -0.1])
    std = np.array([0.02, 0.01, 0.005, 0.01, 0.01, 0.01, 0.01])
    kept = np.array([True, True, True, True, True, False, True])
    found = negative_viscous(labels, values, std, kept)
    assert [f.label for f in found] == ["fv1", "fv2"]
    assert [f.indistinguishable for f in found] == [True, False]
    assert found[1].stds == pytest.approx(10.0)
    (joint,) = negative_viscous(labels, values, std, kept, prefix="j")
    assert joint.label == "jfv5" and not joint.indistinguishable
