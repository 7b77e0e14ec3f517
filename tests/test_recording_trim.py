"""validate and the friction fit prepare a recording as identify does: the same cut-off,
the same trim at each piece's ends (half a period of the cut-off for a motion a decade
below it, :func:`dynid.identification.trim.edge_seconds`), the same decimation, so that a
model is compared on the samples identify judged it on.

Reference: the sample times of a simulated Panda recording, and the trim rule written out
(``t[0] + 0.5 / f_c <= t <= t[-1] - 0.5 / f_c``).
"""

from __future__ import annotations

import warnings

import numpy as np
import pytest

import dynid
from dynid.exceptions import DynidWarning
from dynid.friction.recordings import prepare_pieces, validate_recordings
from dynid.identification.recordings import prepare_recordings
from dynid.identification.selection import identify_recordings
from dynid.identification.structure import Structure
from dynid.simulation.measurement import sample_times, simulate_measurement
from dynid.simulation.trajectories import random_fourier


@pytest.fixture(scope="module")
def recorded():
    """A 6 s, 250 Hz noisy Panda recording and the model identify fits on it."""
    robot = dynid.panda()
    traj = random_fourier(robot, np.random.default_rng(11))(sample_times(6.0, 250.0))
    log = simulate_measurement(robot, traj, rng=np.random.default_rng(12))
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", DynidWarning)
        model = identify_recordings(
            robot, [log], ["r.csv"], structure=Structure.parse("viscous,coulomb")
        )
        data = prepare_recordings(robot, [log], ["r.csv"])  # identify's rows, as it prepares
    return robot, log, model, data


def test_identify_trims_half_a_period_of_its_cut_off(recorded):
    """identify's rows: those more than half a period of the cut-off from the ends, every
    k-th (its decimation), as the rule written out keeps them."""
    _, log, model, data = recorded
    info = model.info.log
    half = 0.5 / info.cutoff_hz
    keep = (log.t >= log.t[0] + half) & (log.t <= log.t[-1] - half)
    np.testing.assert_array_equal(data.pieces[0].log.t, log.t[keep][:: info.decimate])
    assert info.trim_s == pytest.approx(half, abs=0.004)  # as kept, on the 4 ms grid


def test_validate_and_friction_judge_the_rows_identify_held_out(recorded):
    """On the same recording: validate's samples (every one) are identify's rows before
    decimation, the friction fit's (decimated as recorded) are identify's rows, with the
    same states; before, both trimmed two periods of the cut-off (a quarter more rows
    lost at each end)."""
    _, log, model, data = recorded
    k = model.info.log.decimate
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", DynidWarning)
        val = validate_recordings(model, [log], ["r.csv"])
        fr = prepare_pieces(model, [log], ["r.csv"])
    ident = data.pieces[0].log
    np.testing.assert_array_equal(val.parts[0].log.t[::k], ident.t)
    np.testing.assert_array_equal(fr.logs[0].t, ident.t)
    np.testing.assert_allclose(fr.logs[0].q, ident.q, rtol=0, atol=1e-12)
    np.testing.assert_allclose(fr.logs[0].dq, ident.dq, rtol=0, atol=1e-12)
    assert val.pieces.cutoff_hz == data.cutoff_hz


def test_a_robot_is_validated_on_the_rows_identify_would_prepare(recorded):
    """A robot (no recorded cut-off): validate reads the cut-off from the motion as identify
    does and trims as identify would."""
    robot, log, _, data = recorded
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", DynidWarning)
        val = validate_recordings(robot, [log], ["r.csv"])
    assert val.pieces.cutoff_hz == data.cutoff_hz
    k = data.pieces[0].decimate
    np.testing.assert_array_equal(val.parts[0].log.t[::k], data.pieces[0].log.t)
