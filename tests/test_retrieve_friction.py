"""``dynid retrieve`` of a torque-log identification keeps the friction identified with
the links: the links are retrieved, the friction is the model's (its files hold both)."""

from __future__ import annotations

import json
import warnings
import xml.etree.ElementTree as ET

import numpy as np

from dynid.cli.__main__ import main
from dynid.exceptions import DynidWarning
from dynid.friction.model import ClassicalFriction
from dynid.identification.selection import identify_recordings
from dynid.identification.structure import Structure
from dynid.io.feasible import load_feasible_linear_friction
from dynid.io.model_json import save_model_json
from dynid.model.drive import Drive

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


def test_retrieve_of_a_geared_model_writes_its_rotor_inertias_as_armature(panda, tmp_path):
    """A coupled drive whose rotor inertias were identified with friction at the motors:
    the retrieval's MJCF had no armature (the friction's drive, without the identified
    inertias, was taken for the file's); now ``armature = diag(K^T diag(I_a) K)`` of the
    drive feasible.json holds."""
    gears = np.array([50.0, 50.0, 40.0, 40.0, 30.0, 30.0, 30.0])
    ia = np.array([5e-5, 5e-5, 4e-5, 4e-5, 2e-5, 2e-5, 2e-5])
    truth = Drive.from_gears(gears, [(7, 6, 20.0)], rotor_inertia=ia)
    fr = ClassicalFriction(np.full(7, 1e-3), np.zeros(7), np.zeros(7)).at(truth)
    logs = recordings(panda, (7, 8), friction=fr, drive=truth, duration=4.0)
    given = Drive.from_gears(gears, [(7, 6, 20.0)], rotor_inertia=None)
    model = identify_recordings(
        panda, logs, cutoff_hz=None, drive=given, structure=Structure(True, ("viscous",))
    )
    path = save_model_json(tmp_path / "identification.json", model)
    out = tmp_path / "ret"
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", DynidWarning)
        assert main(["retrieve", "--model", str(path), "--out", str(out), "-q"]) in (0, 1)
    drive = json.loads((out / "feasible.json").read_text())["drive"]
    K = np.asarray(given.transmission)
    want = np.diag(K.T @ np.diag(drive["rotor_inertia"]) @ K)
    xml = ET.parse(out / "robot.xml")
    got = [float(j.get("armature")) for j in xml.iter("joint") if j.get("armature")]
    np.testing.assert_allclose(got, want, rtol=1e-6)
