"""Model terms as data in the identified model: the terms mapping, its views and its file.

References: exact simulated torques of a Panda whose armature and friction are known; the
terms' coefficients against those values, and a file (current and older layout) read back.
"""

from __future__ import annotations

from types import SimpleNamespace

import numpy as np
import pytest

import dynid
from dynid.exceptions import DataError, OptionError
from dynid.friction.model import ClassicalFriction, friction_of
from dynid.identification.core import identify, model_columns
from dynid.identification.recordings import prepare_recordings
from dynid.identification.selection import identify_recordings
from dynid.identification.structure import Structure
from dynid.io.model_json import model_from_dict, model_to_dict
from dynid.model.drive import Drive
from dynid.regressors.spring import JointSpring
from dynid.regressors.terms import TERM_KINDS, LinearFriction, RotorInertia

from conftest import recordings

ARMATURE = np.array([0.30, 0.25, 0.20, 0.15, 0.10, 0.08, 0.05])  # kg m^2
FV = np.linspace(0.3, 0.1, 7)  # N m s/rad
FC = np.linspace(0.5, 0.2, 7)  # N m
FO = np.array([0.0, 0.0, 0.0, 0.1, 0.0, -0.2, 0.0])  # N m


@pytest.fixture(scope="module")
def model(panda):
    """Armature and classical friction (no offset on joints 1-3, 5, 7) from exact data."""
    fr = ClassicalFriction(FV, FC, FO)
    logs = recordings(panda, (11, 12), friction=fr, armature=ARMATURE, duration=3.0)
    terms = Structure.parse("armature, viscous, coulomb, offset - fo1 - fo2 - fo3 - fo5 - fo7")
    return identify_recordings(panda, logs, cutoff_hz=None, structure=terms)


def test_the_model_holds_its_terms_in_the_order_stacked(model):
    """The rotor inertias (in the base) then the friction (appended), each with its
    coefficients: the friction's are the true ones, the rotor term gives the true
    inertias where they are base parameters of their own."""
    assert list(model.terms) == ["rotor_inertia", "friction"]
    rotor, fr = model.terms["rotor_inertia"], model.terms["friction"]
    assert isinstance(rotor.term, RotorInertia) and isinstance(fr.term, LinearFriction)
    assert fr.labels[:3] == ("fv1", "fc1", "fv2") and "fo4" in fr.labels and "fo5" not in fr.labels
    assert model.appended == (fr,)
    want = {"fv": FV, "fc": FC, "fo": FO}
    truth = [want[lab[:2]][int(lab[2:]) - 1] for lab in fr.labels]
    np.testing.assert_allclose(fr.values, truth, atol=1e-7)
    own = rotor.kept  # the rotors that are base parameters of their own
    assert own.sum() >= 5
    np.testing.assert_allclose(rotor.values[own], ARMATURE[own], atol=1e-7)
    np.testing.assert_array_equal(model.rotor_inertia, rotor.values)
    # the friction view: the classical law's table, and the one friction type of it
    assert model.friction is not None and model.friction.law == "classical"
    np.testing.assert_allclose(model.friction.params, np.column_stack([FV, FC, FO]), atol=1e-7)
    v = np.random.default_rng(3).uniform(-1, 1, (9, 7))
    np.testing.assert_allclose(
        friction_of(model.friction).torques(v), ClassicalFriction(FV, FC, FO).torques(v), atol=1e-6
    )
    # a term's torques are its columns times its coefficients
    q = np.random.default_rng(4).uniform(-1, 1, (5, 7))
    np.testing.assert_allclose(
        fr.torques(q, v[:5], q), ClassicalFriction(FV, FC, FO).torques(v[:5]), atol=1e-6
    )


def test_links_only_drops_the_base_terms_by_their_labels(model):
    """The links' model keeps no rotor label in any expression and keeps the friction."""
    links = model.links_only()
    assert not any("Ia" in e for e in links.base.expressions)
    assert list(links.terms) == ["friction"] and links.rotor_inertia is None
    assert links.base.rank == int(np.sum(np.asarray(model.base.independent) < 70))


def test_the_terms_are_written_and_read_back(model):
    """identification.json holds every term (kind, definition, coefficients); reading it
    gives the same terms and bit-identical predictions."""
    d = model_to_dict(model)
    assert [t["kind"] for t in d["terms"]] == ["rotor_inertia", "linear_friction"]
    assert set(t["kind"] for t in d["terms"]) <= set(TERM_KINDS)
    back = model_from_dict(d)
    assert list(back.terms) == list(model.terms)
    for name, t in model.terms.items():
        u = back.terms[name]
        assert u.labels == t.labels and type(u.term) is type(t.term)
        np.testing.assert_array_equal(u.values, t.values)
        np.testing.assert_array_equal(u.kept, t.kept)
        np.testing.assert_array_equal(np.isnan(u.std), np.isnan(t.std))
    np.testing.assert_array_equal(back.friction.params, model.friction.params)
    q = np.random.default_rng(5).uniform(-1, 1, (4, 7))
    np.testing.assert_array_equal(back.torques(q, q, q), model.torques(q, q, q))


def test_an_older_file_without_terms_is_read_into_terms(model):
    """A file of an earlier version (friction as the law's table and its labels in the
    metadata, no terms): the friction term is rebuilt with its mask, and the rotor term
    from the drive."""
    d = model_to_dict(model)
    del d["terms"]
    back = model_from_dict(d)
    assert list(back.terms) == ["rotor_inertia", "friction"]
    fr = back.terms["friction"]
    assert fr.labels == model.terms["friction"].labels
    np.testing.assert_array_equal(fr.values, model.terms["friction"].values)
    np.testing.assert_array_equal(back.rotor_inertia, model.rotor_inertia)


def test_a_term_whose_labels_disagree_with_its_definition_is_refused(model):
    d = model_to_dict(model)
    d["terms"][1]["labels"] = d["terms"][1]["labels"][:-1]
    with pytest.raises(DataError, match=r"terms\[1\]\.labels"):
        model_from_dict(d)
    d = model_to_dict(model)
    d["terms"][1]["kind"] = "spring?"
    with pytest.raises(DataError, match="kind"):
        model_from_dict(d)


def test_a_joint_spring_is_one_module_and_one_registry_line(panda):
    """The worked example of ARCHITECTURE.md: exact torques with a spring
    ``k_j (q_j - q0_j)`` and viscous friction; the spring term identified with the links
    gives the true stiffnesses, its torques are ``k (q - q0)``, and the file reads it back
    by its kind."""
    k = np.array([2.0, 0.0, 1.5, 3.0, 0.5, 1.0, 0.25])  # N m/rad
    q0 = np.array([0.1, -0.2, 0.0, -1.5, 0.0, 1.6, 0.7])  # rad
    logs = recordings(
        panda,
        (21, 22),
        friction=ClassicalFriction(FV, np.zeros(7), np.zeros(7)),
        duration=3.0,
        added=lambda log: k * (log.q - q0),
    )
    data = prepare_recordings(panda, logs, cutoff_hz=None)
    spring = JointSpring(tuple(q0))
    friction = LinearFriction(Drive.identity(7), parts=("viscous",))
    model = identify(panda, data, terms=(spring, friction))
    assert list(model.terms) == ["spring", "friction"] and "joint_spring" in TERM_KINDS
    np.testing.assert_allclose(model.terms["spring"].values, k, atol=1e-6)
    np.testing.assert_allclose(model.terms["friction"].values, FV, atol=1e-6)
    q = np.random.default_rng(8).uniform(-1, 1, (4, 7))
    np.testing.assert_allclose(model.terms["spring"].torques(q, q, q), k * (q - q0), atol=1e-6)
    # the model's torques hold the spring (not the friction): those of the truth
    truth = dynid.rnea(panda, q, q, q) + k * (q - q0)
    np.testing.assert_allclose(model.torques(q, q, q), truth, atol=1e-5)
    assert model.friction is not None  # the spring is not friction
    back = model_from_dict(model_to_dict(model))
    assert isinstance(back.terms["spring"].term, JointSpring)
    np.testing.assert_array_equal(back.terms["spring"].term.q0, q0)
    np.testing.assert_array_equal(back.terms["spring"].values, model.terms["spring"].values)


def test_two_terms_of_one_name_are_refused():
    """Terms are keyed by name in the model and its file: two of one name are refused
    before anything is fitted."""
    data = SimpleNamespace(moving=True, regressor_kind="torque")
    twice = (LinearFriction(Drive.identity(7)), LinearFriction(Drive.identity(7), ("viscous",)))
    with pytest.raises(OptionError, match="friction"):
        model_columns(dynid.panda(), data, terms=twice)
