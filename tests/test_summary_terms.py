"""The summary prints the terms identified with the links, per joint, with their values."""

from __future__ import annotations

import numpy as np
import pytest

from dynid.cli.summaries import format_identification, term_lines
from dynid.friction.model import ClassicalFriction
from dynid.identification.selection import identify_recordings
from dynid.identification.structure import Structure

from conftest import recordings


def test_the_friction_identified_with_the_links_is_printed_per_joint(panda):
    """Exact data of an arm with viscous and Coulomb friction, joint 4 without Coulomb:
    the summary's table gives each joint's coefficients as simulated (they were only in
    identification.json), joint 4's Coulomb left out."""
    fv, fc = np.linspace(0.6, 0.2, 7), np.linspace(3.0, 1.0, 7)
    fc[3] = 0.0
    logs = recordings(
        panda, (91, 92), friction=ClassicalFriction(fv, fc, np.zeros(7)), duration=4.0
    )
    structure = Structure(False, ("viscous", "coulomb"), drop=("fc4",))
    model = identify_recordings(panda, logs, structure=structure, cutoff_hz=None)
    lines = term_lines(model)
    assert lines[0].startswith("friction identified with the links")
    assert lines[1].split() == [
        "joint", "fv", "[N", "m", "s/rad]", "fc", "[N", "m]", "band", "[rad/s]",
    ]  # fmt: skip
    rows = {int(r.split()[0]): r.split()[1:] for r in lines[2:9]}
    assert sorted(rows) == list(range(1, 8))
    band = model.terms["friction"].term.band
    for j in range(7):
        printed_fv = float(rows[j + 1][0])
        assert abs(printed_fv - fv[j]) < 1e-3 * fv[j]
        if j == 3:
            assert rows[j + 1][-2] == "-"
        else:
            assert abs(float(rows[j + 1][3]) - fc[j]) < 1e-3 * fc[j]
        assert float(rows[j + 1][-1]) == pytest.approx(band[j], rel=5e-3)
    assert lines[9].startswith("  band: the standstill band")
    assert "\n".join(lines) in format_identification(model)
