"""``identify --consistent`` on a torque log says which structure its fit uses (the one
chosen on held-out data, as it was chosen) and prints the offsets with the other friction
coefficients.

Reference: the selection's own table (the held-out errors printed are its entries) and
the friction table of the result (fv, fc, fo per joint).
"""

from __future__ import annotations

import warnings

import numpy as np
import pytest

import dynid
from dynid.cli.summaries import format_consistent
from dynid.exceptions import DynidWarning
from dynid.io.torque_log import save_torque_log
from dynid.simulation.measurement import SensorNoise, sample_times, simulate_measurement
from dynid.simulation.trajectories import random_fourier
from dynid.simulation.unmodelled import UnmodelledEffects
from dynid.workflows.identify import IdentifyOptions, identify_files


@pytest.fixture(scope="module")
def consistent(tmp_path_factory):
    robot = dynid.panda()
    d = tmp_path_factory.mktemp("consistent")
    for s in (1, 2, 3):
        traj = random_fourier(robot, np.random.default_rng(s))(sample_times(5.0, 200.0))
        log = simulate_measurement(
            robot, traj, rng=np.random.default_rng(s + 100), noise=SensorNoise()
        )
        save_torque_log(d / f"r{s}.csv", log)
    opt = IdentifyOptions(consistent=True, prior="panda")
    with warnings.catch_warnings():  # large deviations of a short log's coefficients
        warnings.simplefilter("ignore", DynidWarning)
        return identify_files(robot, sorted(d.glob("*.csv")), opt).consistent


def test_the_consistent_summary_names_its_structure_against_the_chosen_one(consistent):
    text = format_consistent(consistent)
    sel = consistent.identified.info.selection
    held = {c["name"]: c["heldout_error_percent"] for c in sel["candidates"]}
    # the structure chosen, its law and leave-outs as they are
    assert f"structure of the consistent fit: {sel['chosen']} (" in text
    line = next(x for x in text.splitlines() if x.startswith("structure chosen on held-out"))
    assert sel["chosen"] in line
    assert f"held-out error {held[sel['chosen']]:.4g} %" in line
    assert "consistent fit's structure:" not in line


def test_the_consistent_summary_prints_the_offsets(consistent):
    text = format_consistent(consistent)
    line = next(x for x in text.splitlines() if x.startswith("friction at the joints"))
    fo = [float(x) for x in line.split("fo [N m]:")[1].split()]
    np.testing.assert_allclose(fo, consistent.friction.fo, rtol=1e-3, atol=1e-9)


@pytest.fixture(scope="module")
def with_rotors(tmp_path_factory):
    """The Panda with rotor inertias, identified with its armature at a given weight."""
    robot = dynid.panda()
    traj = random_fourier(robot, np.random.default_rng(5))(sample_times(6.0, 200.0))
    ia = np.array([0.3, 0.3, 0.2, 0.2, 0.1, 0.1, 0.05])
    log = simulate_measurement(
        robot, traj, rng=np.random.default_rng(6), noise=SensorNoise(),
        effects=UnmodelledEffects(ia, np.zeros(7)),
    )  # fmt: skip
    path = save_torque_log(tmp_path_factory.mktemp("rotors") / "log.csv", log)
    opt = IdentifyOptions(
        terms="armature,viscous,coulomb", consistent=True, prior="panda", prior_weight=1.0
    )
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", DynidWarning)
        return identify_files(robot, path, opt).consistent


def test_the_summary_marks_the_rotors_and_masses_the_prior_decides(with_rotors):
    """Joint 1 turns about the vertical: its rotor's column is link 1's ``J1zz`` column
    (``tau1 = (J1zz + ... + Ia1) ddq1``), so the data give Ia1 only in that sum and the
    prior splits it: marked ``*``. A rotor that is a base parameter of its own (the
    expression ``Ia3``) is not marked. Link 1's mass acts on nothing (it turns about a
    vertical axis through the base): named in the note. The line on the residual says the
    held-out error decides. Without a drive (joint-side torques, the armature term) the
    line says armature (joint side), not rotor inertia at the motors (regression)."""
    r = with_rotors
    text = format_consistent(r)
    assert "rotor inertia at the motors" not in text, text
    line = next(x for x in text.splitlines() if x.startswith("armature (joint side) [kg m^2]"))
    values = line.split(":")[1].split()
    own = {e.strip() for e in r.identified.base.expressions}
    assert values[0].endswith("*")
    for j in range(7):
        if f"Ia{j + 1}" in own:
            assert not values[j].endswith("*")
    assert any(f"Ia{j}" in own for j in range(2, 8))  # one of its own at least
    assert "  * rotor(s) 1" in text and "the prior and the constraints decide its share" in text
    note = next(x for x in text.splitlines() if x.startswith("note: masses the data do not give"))
    assert "m1" in note.split("(unidentifiable: ")[1].split(")")[0].split(", ")
    status = next(x for x in text.splitlines() if x.startswith(("CONSISTENT", "NOT CONSIST")))
    assert "judged on held-out data (below)" in status and "does not decide" in status
