"""The armature chosen per joint (``- Ia3``), as friction coefficients are.

References: exact simulated torques of a Panda whose joints 3 and 5 have no armature and
the others a known one, with viscous friction; the structure chosen on held-out data and the
identified armatures against those values.
"""

from __future__ import annotations

import numpy as np
import pytest

import dynid
from dynid.exceptions import OptionError
from dynid.friction.model import ClassicalFriction
from dynid.identification.selection import identify_recordings
from dynid.identification.structure import Structure
from dynid.io.model_json import model_from_dict, model_to_dict
from dynid.simulation.measurement import SensorNoise, sample_times, simulate_measurement
from dynid.simulation.trajectories import random_fourier
from dynid.simulation.unmodelled import UnmodelledEffects

ARMATURE = np.array([0.30, 0.25, 0.0, 0.15, 0.0, 0.08, 0.05])  # kg m^2; none on 3 and 5
FV = np.linspace(0.3, 0.1, 7)  # N m s/rad


@pytest.fixture(scope="module")
def logs():
    panda = dynid.panda()
    t = sample_times(3.0, 500.0)
    return panda, [
        simulate_measurement(
            panda,
            random_fourier(panda, np.random.default_rng(s))(t),
            rng=np.random.default_rng(s),
            noise=SensorNoise.none(),
            friction=ClassicalFriction(FV, np.zeros(7), np.zeros(7)),
            effects=UnmodelledEffects(rotor_inertia=ARMATURE, torque_offset=np.zeros(7)),
            with_ddq=True,
        )
        for s in (31, 32, 33)
    ]


def test_joints_without_armature_are_left_out(logs):
    """The default chooses the armature and viscous friction, without the armature of
    joints 3 and 5; the other joints' armatures come back where they are base parameters
    of their own."""
    panda, recs = logs
    model = identify_recordings(panda, recs, cutoff_hz=None)
    chosen = Structure.parse(model.info.selection["chosen"])
    assert chosen.armature and chosen.friction == ("viscous",), chosen.name
    assert {"Ia3", "Ia5"} <= set(chosen.drop) and not set(chosen.drop) - {"Ia1", "Ia3", "Ia5"}
    rotor = model.terms["rotor_inertia"]
    assert "Ia3" not in rotor.labels and "Ia5" not in rotor.labels
    assert model.rotor_inertia[2] == 0.0 and model.rotor_inertia[4] == 0.0
    own = rotor.kept
    held = [int(lab[2:]) - 1 for lab in rotor.labels]
    np.testing.assert_allclose(rotor.values[own], ARMATURE[held][own], atol=1e-6)
    np.testing.assert_allclose(model.friction.params[:, 0], FV, atol=1e-6)
    assert model.fit.relative_error_percent < 1e-6
    back = model_from_dict(model_to_dict(model))
    assert back.terms["rotor_inertia"].labels == rotor.labels
    np.testing.assert_array_equal(back.rotor_inertia, model.rotor_inertia)


def test_an_armature_left_out_by_hand(logs):
    """``--terms armature,viscous,-ia3,-ia5`` (either case) is the same model, and a joint
    without armature in a structure without it is refused."""
    panda, recs = logs
    terms = Structure.parse("armature, viscous, -ia3, -Ia5")
    assert terms.drop == ("Ia3", "Ia5") and terms.name == "links + armature + viscous - Ia3 - Ia5"
    model = identify_recordings(panda, recs, cutoff_hz=None, structure=terms)
    assert model.rotor_inertia[2] == 0.0 and model.fit.relative_error_percent < 1e-6
    with pytest.raises(OptionError, match="Ia3"):
        Structure.parse("viscous, -Ia3")
    assert Structure.parse("armature, " + ", ".join(f"-Ia{j}" for j in range(1, 8))).collapsed(
        7
    ) == Structure(friction=())


def test_a_regrouped_armature_names_the_base_parameter_that_holds_it(logs):
    """Joints 1 and 2's armatures regroup with ``J1zz`` and ``J2zz`` (the classical
    ``ZZ1R``, ``ZZ2R``: a rotor turning with the joint adds to the link's inertia about its
    axis), the others are their own: the summary, identification.json and the report name
    that base parameter instead of showing 0, and its identified value holds Ia1 (exact
    data: the truth's combination with Ia1 = 0.30, not without it)."""
    from dynid.cli.summaries import term_lines
    from dynid.report.model_terms import terms_sections

    panda, recs = logs
    model = identify_recordings(
        panda, recs, cutoff_hz=None, structure=Structure.parse("armature, viscous, -ia3, -ia5")
    )
    held = model.regrouped_in("rotor_inertia")
    labels = model.terms["rotor_inertia"].labels
    holder = held[labels.index("Ia1")]
    assert holder and "+" not in holder and model.base.holding("J1zz") == (holder,)
    assert model.base.holding("J2zz") == (held[labels.index("Ia2")],)
    assert not any(held[labels.index(lab)] for lab in ("Ia4", "Ia6", "Ia7"))
    k = model.base.labels.index(holder)
    phi = np.concatenate([panda.phi.reshape(-1), np.zeros(model.base.n_std - 70)])
    ia1 = model.base.std_labels.index("Ia1")
    without = model.base.beta_from_phi(phi)[k]
    phi[ia1] = ARMATURE[0]
    np.testing.assert_allclose(model.fit.beta[k], model.base.beta_from_phi(phi)[k], atol=1e-6)
    assert abs(model.fit.beta[k] - without) > 0.29
    from dynid.cli.summaries import columns_text

    # Ia4, Ia6, Ia7 are base parameters of their own: counted among the base, said so
    assert f"{model.base.rank} base parameters (3 of them rotor inertias of their own)" in (
        columns_text(model)
    )
    lines = "\n".join(term_lines(model))
    legend = next(x for x in lines.splitlines() if "regrouped with link inertias" in x)
    assert f"  1      in {holder}" in lines and holder in legend
    doc = model_to_dict(model)
    term = next(t for t in doc["terms"] if t["name"] == "rotor_inertia")
    assert term["regrouped_in"][labels.index("Ia1")] == holder
    html = "".join(terms_sections(doc))
    assert f"in {holder} (regrouped)" in html
    assert model_from_dict(doc).regrouped_in("rotor_inertia") == held
