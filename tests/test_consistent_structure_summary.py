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
from dynid.workflows.identify import IdentifyOptions, identify_files


@pytest.fixture(scope="module")
def consistent(tmp_path_factory):
    robot = dynid.panda()
    d = tmp_path_factory.mktemp("consistent")
    for s in (1, 2, 3):
        traj = random_fourier(robot, np.random.default_rng(s))(sample_times(5.0, 400.0))
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
