"""The pieces a recording's cuts leave out, said once with the --max-gap that keeps them.

References: the gaps written into the simulated logs (their number and lengths), and
prepare_recordings run again with the --max-gap the warning hints.
"""

from __future__ import annotations

import warnings

import numpy as np
import pytest

import dynid
from dynid.exceptions import DynidWarning
from dynid.identification.cut_loss import bridging_gap
from dynid.identification.recordings import prepare_recordings
from dynid.simulation.measurement import SensorNoise, sample_times, simulate_measurement
from dynid.simulation.trajectories import random_fourier

RATE = 100.0  # Hz


def _with_drops(seed: int, duration: float, drops: list[tuple[float, float]]):
    """A 100 Hz log of the Panda with the samples inside each ``(start, end)`` [s] dropped."""
    robot = dynid.panda()
    traj = random_fourier(robot, np.random.default_rng(seed))(sample_times(duration, RATE))
    log = simulate_measurement(
        robot, traj, rng=np.random.default_rng(seed + 1), noise=SensorNoise.none()
    )
    keep = np.ones(log.n_samples, dtype=bool)
    for a, b in drops:
        keep &= ~((log.t > a + 1e-9) & (log.t < b - 1e-9))
    return robot, log.select(np.flatnonzero(keep))


def _left_out(robot, logs, **kw):
    """prepare_recordings at 5 Hz, 0.5 s trimmed, and its warnings about pieces left out."""
    with warnings.catch_warnings(record=True) as caught:
        warnings.simplefilter("always", DynidWarning)
        rec = prepare_recordings(robot, logs, ["a.csv"], cutoff_hz=5.0, trim_s=0.5, **kw)
    return rec, [str(w.message) for w in caught if "left out" in str(w.message)]


def test_pieces_left_out_at_short_gaps_are_said_once_with_the_max_gap_that_keeps_them():
    """Regression (dropped samples cut a log into 46 pieces, 19 left out each with its own
    warning, none suggesting --max-gap): two samples dropped at 2.0, 2.6, 5.0 and 5.5 s
    leave two pieces under twice the trim; one warning names both, the 4 cuts of 0.03 s
    and --max-gap 0.035, with which no piece is left out and more samples are used."""
    drops = [(t, t + 0.03) for t in (2.0, 2.6, 5.0, 5.5)]
    robot, log = _with_drops(3, 8.0, drops)
    rec, said = _left_out(robot, [log])
    assert len(said) == 1, said
    (line,) = said
    assert "a.csv: piece t = 2.030-2.600 s" in line and "a.csv: piece t = 5.030-5.500 s" in line
    assert "cut at 4 gap(s) of 0.03-0.03 s (3-3 sample steps of 0.01 s)" in line
    assert line.endswith("hint: --max-gap 0.035 bridges the 4 short one(s)")
    assert len(rec.skipped) == 2  # the record keeps a line per piece
    kept, none = _left_out(robot, [log], max_gap_s=0.035)
    assert none == [] and kept.skipped == ()
    assert kept.n_samples > rec.n_samples


def test_holes_of_seconds_are_said_without_a_max_gap_hint():
    """Two holes of 2 s leave a 0.5 s piece: said with the samples lost, no --max-gap."""
    robot, log = _with_drops(4, 10.0, [(2.0, 4.0), (4.5, 6.5)])
    _, said = _left_out(robot, [log])
    assert len(said) == 1 and "cut at 2 gap(s) of 2-2 s" in said[0]
    assert "--max-gap" not in said[0]


@pytest.mark.parametrize(
    "gaps, step, expected",
    [
        ([0.024, 0.027], 0.009, 0.032),  # a jittery 111 Hz clock: 0.027 + 0.0045, up
        ([0.03, 2.0], 0.01, 0.035),  # the hole of 2 s stays a cut
        ([1.5, 2.0], 0.01, None),  # holes only: no hint
    ],
)
def test_bridging_gap_covers_the_short_gaps_only(gaps, step, expected):
    """The longest gap of at most 10 steps plus half a step, rounded up to 2 digits."""
    got = bridging_gap(np.array(gaps), step)
    assert got == expected if expected is None else got == pytest.approx(expected, rel=1e-12)
