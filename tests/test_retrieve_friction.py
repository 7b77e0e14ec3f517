"""``dynid retrieve`` of a torque-log identification keeps the friction identified with
the links: the links are retrieved, the friction is the model's (its files hold both)."""

from __future__ import annotations

import warnings

import numpy as np

from dynid.cli.__main__ import main
from dynid.exceptions import DynidWarning
from dynid.friction.model import ClassicalFriction
from dynid.identification.selection import identify_recordings
from dynid.identification.structure import Structure
from dynid.io.feasible import load_feasible_linear_friction
from dynid.io.model_json import save_model_json

from conftest import recordings


def test_retrieve_keeps_the_friction_identified_with_the_links(panda, tmp_path):
    """Exact data of a Panda with viscous and Coulomb friction: the friction in the
    retrieval's feasible.json is the true one to 1e-6 (it was left out: no friction at
    all in the files of a two-step retrieval)."""
    fr = ClassicalFriction(np.linspace(0.3, 0.1, 7), np.linspace(0.6, 0.2, 7), np.zeros(7))
    logs = recordings(panda, (5, 6), friction=fr, duration=4.0)
    model = identify_recordings(
        panda, logs, cutoff_hz=None, structure=Structure(False, ("viscous", "coulomb"))
    )
    path = save_model_json(tmp_path / "identification.json", model)
    out = tmp_path / "ret"
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", DynidWarning)
        assert main(["retrieve", "--model", str(path), "--out", str(out), "-q"]) in (0, 1)
    got = load_feasible_linear_friction(out / "feasible.json")
    assert got is not None
    v = np.random.default_rng(0).uniform(-2.0, 2.0, (50, 7))
    np.testing.assert_allclose(got.torques(v), fr.torques(v), atol=1e-6)
