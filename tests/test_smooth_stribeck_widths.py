"""The Stribeck bump on the smooth sign found at the width of the friction's own rounding.

The reference: a simulated smooth Stribeck law (a smooth Coulomb of 0.01 rad/s, 10 of the
1 mrad/s bands, with a bump of ``fs = 1.5 fc`` at 0.05 rad/s), its parameters, the noise
floor of the recordings' known torque noise, and the exact torques of recordings the fit
never saw; the width walk alone against scores laid out by hand.
"""

from __future__ import annotations

import warnings
from types import SimpleNamespace

import numpy as np
import pytest

from dynid.exceptions import DynidWarning
from dynid.friction.laws import LAWS
from dynid.friction.recordings import validate_recordings
from dynid.friction.validation import own_friction
from dynid.identification.bumps import bump_widths
from dynid.identification.selection import identify_recordings
from dynid.simulation.measurement import SensorNoise

from conftest import recordings

WIDTHS = (0.3, 1.0, 3.0, 10.0, 30.0, 100.0, 300.0)  # bands


def _cand(width: float, score: float, unphysical: tuple[str, ...] = ()) -> SimpleNamespace:
    """A judged candidate as the walk reads it: its width, score and dissipation."""
    return SimpleNamespace(
        structure=SimpleNamespace(width=width), score=score, skipped=bool(unphysical)
    )


def _walk(start: SimpleNamespace, scores: dict[float, float], unphysical=()) -> list[float]:
    """The widths whose bumps :func:`bump_widths` judges from ``start``, the bump at each
    width scoring ``scores[width]``; one better than another by more than 0.1."""
    asked: list[float] = []

    def at_width(w):
        asked.append(w)
        return [_cand(w, scores[w], unphysical if w in (30.0,) else ())]

    bump_widths(start, WIDTHS, at_width, lambda c, than: c.score < than.score - 0.1)
    return asked


def test_the_walk_follows_falling_errors_each_way_and_stops():
    """From a smooth law at 3 bands whose bump helps, the walk goes wider while the error
    falls (10), stops at the first width that does not (30), and tries the narrower side
    once; a bump that does not help, or a width per joint, is judged at the start alone."""
    scores = {0.3: 2.0, 1.0: 1.8, 3.0: 1.5, 10.0: 1.0, 30.0: 1.05, 100.0: 0.5, 300.0: 0.4}
    assert _walk(_cand(3.0, 2.0), scores) == [3.0, 1.0, 10.0, 30.0]
    assert _walk(_cand(3.0, 1.55), scores) == [3.0]
    assert _walk(_cand((3.0, 10.0), 2.0), {(3.0, 10.0): 1.0}) == [(3.0, 10.0)]
    # a bump that is not dissipative is no step: the walk stops before it
    scores[30.0] = 0.1
    assert _walk(_cand(3.0, 2.0), scores, unphysical=("fsp1",)) == [3.0, 1.0, 10.0, 30.0]


@pytest.fixture(scope="module")
def rounded(panda):
    """The model identified by default from three noisy 6 s recordings of the Panda with a
    smooth Stribeck law of 10 bands, the truth's parameters, two exact new recordings."""
    robot = panda
    n = robot.n
    fc = np.linspace(2.0, 0.5, n)
    P = np.column_stack([np.linspace(0.3, 0.1, n), fc, 1.5 * fc, np.full(n, 0.05), np.zeros(n)])
    truth = LAWS["smooth_stribeck"].model(P, np.full(n, 0.01))
    noise = SensorNoise(tau_std=0.05, q_std=1e-5, dq_std=1e-4)  # bands under 1 mrad/s
    logs = recordings(robot, (1, 2, 3), friction=truth, duration=6.0, noise=noise)
    new = recordings(robot, (4, 5), friction=truth, duration=6.0)
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", DynidWarning)
        model = identify_recordings(robot, logs)
    return model, P, new


def test_a_rounded_stribeck_law_is_found_at_its_own_width(rounded):
    """Regression (a smooth Coulomb rounded over 10 bands with a Stribeck bump: the grid's
    bumps sat at 0.3 bands only, so the default chose ``smooth:0.3 + stribeck:0.1``, 2.3 x
    the noise floor held out, 0.9 % on exact new recordings): the default search chooses
    the bump at 10 bands and 0.05 rad/s, held out within 10 % of the noise floor, its
    coefficients within 2 % of the truth's, and predicts exact new recordings within
    0.1 %."""
    model, P, new = rounded
    sel = model.info.selection
    assert "smooth:10 + stribeck:0.05" in sel["chosen"], sel["chosen"]
    mine = next(c for c in sel["candidates"] if c["name"] == sel["chosen"])
    floor = model.info.heldout["noise_floor_percent"]
    assert mine["heldout_error_percent"] < 1.1 * floor, (mine["heldout_error_percent"], floor)
    fv, fc, fs = model.friction.params[:, :3].T
    np.testing.assert_allclose(fv, P[:, 0], rtol=0.02)
    np.testing.assert_allclose(fc, P[:, 1], rtol=0.02)
    np.testing.assert_allclose(fs - fc, P[:, 2] - P[:, 1], rtol=0.02)
    val = validate_recordings(model, new, friction=own_friction(model))
    assert float(val.errors.relative_error_percent) < 0.1


def test_no_bump_is_tried_without_coulomb_friction(panda):
    """Viscous friction alone (no Coulomb term to ride on): no smooth-sign Stribeck law
    beyond the grid's (0.3 bands) is judged, so no fit is spent on one, and viscous
    friction without a sign is chosen."""
    noise = SensorNoise(tau_std=0.05, q_std=1e-5, dq_std=1e-3)
    truth = LAWS["classical"].model(np.column_stack([np.linspace(0.3, 0.1, 7), np.zeros((7, 2))]))
    logs = recordings(panda, (6, 7), friction=truth, duration=4.0, noise=noise)
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", DynidWarning)
        sel = identify_recordings(panda, logs).info.selection
    assert sel["chosen"].startswith("links + viscous"), sel["chosen"]
    assert not any(law in sel["chosen"] for law in ("coulomb", "smooth", "stribeck"))
    bumps = [c["name"] for c in sel["candidates"] if "+ stribeck:" in c["name"]]
    assert bumps and all("smooth:0.3 + stribeck" in b or "coulomb" in b for b in bumps), bumps
