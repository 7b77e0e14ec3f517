"""The Stribeck velocity refined between the grid's points on held-out data
(:mod:`dynid.identification.shape_refinement`).

References: closed forms (a parabola's vertex); a simulated Panda whose Stribeck velocity
lies between two of the grid's, with sensor noise, judged on recordings the fit did not see.
"""

from __future__ import annotations

import math
import warnings

import numpy as np
import pytest

import dynid
from dynid.exceptions import DynidWarning
from dynid.friction.laws import LAWS
from dynid.friction.model import LawFriction
from dynid.identification.recordings import prepare_recordings
from dynid.identification.selection import identify_recordings, select_structure
from dynid.identification.shape_refinement import refined_shape
from dynid.identification.structure import STRIBECK_VELOCITIES, Structure
from dynid.simulation.measurement import SensorNoise

from conftest import recordings

VST = 0.12  # rad/s, between the grid's 0.1 and 0.15


def test_the_search_reaches_a_parabola_s_vertex_in_few_fits():
    """Held-out errors a parabola in ln v with its vertex at 0.083 rad/s (closed form):
    the search, started from the grid's scores, tries only between 0.07 and 0.1 and
    reaches the vertex within 1 % in at most three fits."""
    x0 = math.log(0.083)

    def error(v: float) -> float:
        return 1.0 + (math.log(v) - x0) ** 2

    calls: list[float] = []

    def judged(v: float) -> float:
        calls.append(v)
        return error(v)

    grid = {v: error(v) for v in STRIBECK_VELOCITIES}
    tried = refined_shape(grid, 0.07, judged)
    assert tried == tuple(calls) and 1 <= len(tried) <= 3
    assert all(0.05 < v < 0.1 for v in tried)
    assert abs(math.log(min(tried, key=error)) - x0) < 0.01


def test_the_search_stops_where_the_grid_point_is_the_minimum():
    """Held-out errors whose minimum is the grid point itself (a parabola centred on
    0.1 rad/s): no fit is spent, or those spent score no better than the grid's."""
    grid = {v: 1.0 + math.log(v / 0.1) ** 2 for v in STRIBECK_VELOCITIES}
    tried = refined_shape(grid, 0.1, lambda v: 1.0 + math.log(v / 0.1) ** 2)
    assert all(abs(math.log(v / 0.1)) < 0.02 for v in tried)


@pytest.fixture(scope="module")
def between():
    """Noisy recordings of a Panda with Stribeck friction at 0.12 rad/s and the structure
    chosen among the banded Stribeck laws of the grid."""
    panda = dynid.panda()
    fc = np.linspace(0.8, 0.3, 7)
    fv = np.linspace(0.6, 0.1, 7)
    P = np.column_stack([fv, fc, 2.0 * fc, np.full(7, VST), np.zeros(7)])
    truth = LawFriction(LAWS["stribeck"], P)
    noisy = SensorNoise(tau_std=0.05, q_std=2e-5, dq_std=2e-3)
    logs = recordings(panda, (81, 82, 83), friction=truth, duration=4.0, noise=noisy)
    cands = [
        Structure(False, ("viscous", "coulomb", "stribeck"), vst=v) for v in STRIBECK_VELOCITIES
    ]
    sel = select_structure(
        panda, prepare_recordings(panda, logs), candidates=cands, per_joint=False
    )
    return panda, logs, P, sel


def test_a_stribeck_velocity_between_grid_points_is_refined(between):
    """Regression (the grid's nearest point, 0.1 rad/s, taken for a true 0.12): the
    chosen Stribeck velocity is within 5 % of the truth, and predicts the held-out
    recordings at least as well as every grid point."""
    _, _, _, sel = between
    assert sel is not None
    assert abs(sel.chosen.vst / VST - 1) < 0.05, sel.chosen.vst
    grid = [c for c in sel.candidates if c.structure.vst in STRIBECK_VELOCITIES]
    mine = next(c for c in sel.candidates if c.structure == sel.chosen)
    assert mine.score <= min(c.score for c in grid)


def test_the_viscous_coefficient_is_unbiased_at_the_refined_velocity(between):
    """Fitted at the refined velocity, every joint's viscous coefficient is within three
    standard deviations of the truth's (the simulated one)."""
    panda, logs, P, sel = between
    with warnings.catch_warnings():  # a link parameter the short logs hardly excite
        warnings.simplefilter("ignore", DynidWarning)
        model = identify_recordings(panda, logs, structure=sel.chosen)
    term = model.terms["friction"]
    fv = {lab: (x, s) for lab, x, s in zip(term.labels, term.values, term.std, strict=True)}
    for j in range(7):
        x, s = fv[f"fv{j + 1}"]
        assert abs(x - P[j, 0]) < 3 * s, (j + 1, x, P[j, 0], s)
