"""What ``identify --consistent`` records in report.json and prints: every recording fitted,
the weight search that chose the prior's weight, and the armature named as such.

Reference: two simulated Panda recordings with sensor noise, classical friction and
armature at the joints (no drive); the files the command was given and the held-out search
``feasible.json`` holds beside report.json.
"""

from __future__ import annotations

import json

import numpy as np
import pytest

from dynid.cli.__main__ import main
from dynid.friction.model import ClassicalFriction
from dynid.io.torque_log import save_torque_log
from dynid.simulation.measurement import SensorNoise

from conftest import recordings

VISCOUS = np.array([0.3, 0.3, 0.2, 0.2, 0.05, 0.05, 0.03])  # N m s/rad
COULOMB = np.array([0.5, 0.5, 0.4, 0.4, 0.2, 0.2, 0.1])  # N m
ARMATURE = np.array([0.3, 0.25, 0.2, 0.15, 0.1, 0.08, 0.05])  # kg m^2


@pytest.fixture(scope="module")
def run(panda, tmp_path_factory):
    """identify --consistent on two recordings: the output folder and the printed text."""
    tmp = tmp_path_factory.mktemp("sources")
    logs = recordings(
        panda,
        (31, 32),
        friction=ClassicalFriction(VISCOUS, COULOMB, np.zeros(7)),
        armature=ARMATURE,
        duration=4.0,
        noise=SensorNoise(tau_std=0.05, q_std=1e-5, dq_std=1e-3),
    )
    paths = [save_torque_log(tmp / f"rec{i}.csv", log) for i, log in enumerate(logs)]
    out = tmp / "out"
    args = ["identify", "--data", *map(str, paths), "--consistent", "--prior", "panda"]
    args += ["--terms", "armature,viscous,coulomb", "--no-figures", "--out", str(out)]
    return out, paths, args


def test_report_json_records_every_recording_and_the_weight_search(run, capsys):
    """Regression: report.json of identify --consistent on four recordings said
    ``"source": "rec1.csv"`` and ``"weight_search": []`` while the held-out search had
    tried six weights: it now lists every recording fitted and the search that chose the
    weight (the held-out one, as ``heldout.weight_search`` holds it); the summary names the
    armature at the joints, not the rotor inertia at the motors, without a drive."""
    out, paths, args = run
    assert main(args) in (0, 1)
    text = capsys.readouterr().out
    rep = json.loads((out / "report.json").read_text())
    assert rep["sources"] == [str(p) for p in paths] and "source" not in rep, rep.get("sources")
    held = rep["heldout"]["weight_search"]
    assert len(held) >= 2 and rep["weight_search"] == held, (rep["weight_search"], held)
    assert rep["weight_search_on"] == "heldout"
    assert rep["prior_weight"] in [w for w, _ in held]
    assert "rotor inertia at the motors" not in text, text
    assert "armature (joint side) [kg m^2] (>= 0): " in text, text
