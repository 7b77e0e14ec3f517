"""Recordings whose friction and sensor offsets differ (warm and cold, offsets that shift)
are said to disagree; alike recordings are not.

Reference: simulated Panda recordings with sensor noise and classical friction whose
coefficients are scaled by 0.8, 1.0 and 1.2 and whose offsets shift between recordings
(the truth the structure chosen cannot hold in one set of coefficients); the same motions
with one friction as the control.
"""

from __future__ import annotations

import warnings

import numpy as np
import pytest

from dynid.exceptions import DynidWarning
from dynid.friction.model import ClassicalFriction
from dynid.identification.selection import identify_recordings
from dynid.report.identify import _structure_section
from dynid.simulation.measurement import SensorNoise, sample_times, simulate_measurement
from dynid.simulation.trajectories import random_fourier

VISCOUS = np.array([0.3, 0.3, 0.2, 0.2, 0.05, 0.05, 0.03])  # N m s/rad
COULOMB = np.array([0.5, 0.5, 0.4, 0.4, 0.2, 0.2, 0.1])  # N m
OFFSET = np.array([0.2, -0.3, 0.1, 0.2, -0.1, 0.05, -0.05])  # N m


def _logs(panda, scales, shifts):
    out = []
    for seed, scale, shift in zip((1, 2, 3), scales, shifts, strict=True):
        traj = random_fourier(panda, np.random.default_rng(seed))(sample_times(6.0, 500.0))
        friction = ClassicalFriction(scale * VISCOUS, scale * COULOMB, OFFSET + shift)
        out.append(
            simulate_measurement(
                panda,
                traj,
                rng=np.random.default_rng(seed + 100),
                noise=SensorNoise(),
                friction=friction,
            )  # fmt: skip
        )
    return out


def _notes(panda, logs):
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", DynidWarning)
        sel = identify_recordings(panda, logs, ["a.csv", "b.csv", "c.csv"]).info.selection
    return sel, [n for n in sel["notes"] if n.startswith("the recordings disagree")]


@pytest.mark.parametrize(
    ("scales", "shifts", "said"),
    [((0.8, 1.0, 1.2), (-0.3, 0.0, 0.3), True), ((1.0, 1.0, 1.0), (0.0, 0.0, 0.0), False)],
)
def test_recordings_whose_friction_and_offsets_differ_are_said_to_disagree(
    panda, scales, shifts, said
):
    """Regression: recordings of friction 20 % apart and offsets 0.3 N m apart were
    judged with no word (none outlying) and the standard deviations, computed within
    them, said nothing of it; now a note says the recordings disagree, with their
    held-out errors against the floor; recordings of one friction get none."""
    sel, notes = _notes(panda, _logs(panda, scales, shifts))
    per = [r["heldout_error_percent"] for r in sel["heldout_per_recording"]]
    assert sel["outlying_recordings"] == []
    assert bool(notes) is said, (per, sel["notes"])
    report = _structure_section({"metadata": {"selection": sel}})
    assert ("The recordings disagree" in report) is said
    if said:
        assert f"{min(per):.3g} to {max(per):.3g} %" in notes[0]
        assert "standard deviations" in notes[0]
