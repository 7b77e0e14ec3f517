"""A burst cut out of a recording is said once, as a cut burst: not also as a gap of the
recording (its record's ``gaps``, the summary's ``cut at the gap(s)`` and ``longer
gap(s)``) nor as ``outlying there``.

Regression: a recording with a 0.1 s burst cut out was listed with ``cut at the gap(s)
after t = 2.908 s (0.376 s long)`` and ``...cut out: outlying there``, and the header
counted the cut among the longer gaps.

References: a simulated planar 2R arm with known friction and sensor noise, sampled without
gaps; a burst of 20 N m added on joint 2 at a known time.
"""

from __future__ import annotations

import dataclasses

import numpy as np
import pytest

from dynid.cli.summaries import format_identification
from dynid.friction.model import ClassicalFriction
from dynid.identification.selection import identify_recordings
from dynid.identification.structure import Structure
from dynid.simulation.measurement import SensorNoise

from conftest import planar_2r, recordings, said_warnings

FRICTION = ClassicalFriction(np.array([0.3, 0.2]), np.array([0.8, 0.5]), np.zeros(2))
T0 = 3.0  # the burst's start [s], 0.1 s long


@pytest.fixture(scope="module")
def model():
    """Two noisy 5 s recordings (200 Hz, no gaps), the second with the burst, the
    structure given."""
    arm = planar_2r().replace(q_min=(-2.5, -2.5), q_max=(2.5, 2.5))
    a, b = recordings(arm, [1, 2], friction=FRICTION, duration=5.0, fs=200.0, noise=SensorNoise())
    tau = b.tau.copy()
    tau[(b.t >= T0) & (b.t < T0 + 0.1), 1] += 20.0
    given = Structure(friction=("viscous", "coulomb"))
    got, _ = said_warnings(
        identify_recordings,
        arm,
        [a, dataclasses.replace(b, tau=tau)],
        ["a.csv", "b.csv"],
        structure=given,
    )
    return got


def test_the_cut_is_no_gap_of_the_recording(model):
    """The record of the recording cut holds the interval cut out and no gap (it was
    sampled without one)."""
    rec = model.info.recordings[1]
    ((a, b),) = rec["cut_out"]
    assert a < T0 < T0 + 0.1 < b and "gaps" not in rec


def test_the_summary_says_the_cut_once_as_a_burst(model):
    """The recording's line names the cut burst once (no gap, no ``outlying there``); the
    header counts one burst cut out and no longer gap."""
    text = format_identification(model)
    (line,) = [x for x in text.splitlines() if x.startswith("recording b.csv")]
    assert line.count("cut out as a burst the model does not hold") == 1
    assert "cut at the gap" not in line and "outlying there" not in line
    head = text.splitlines()[0]
    assert "1 burst(s) cut out" in head and "longer gap" not in head
