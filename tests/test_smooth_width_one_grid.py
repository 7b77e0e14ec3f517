"""``dynid friction``'s smooth law and ``identify``'s smooth Coulomb candidates search one
grid of widths: ``friction`` had fitted the law at 1x the standstill band (the plain
sign on a noise-free log), ``identify`` chose among its own multiples of it.

Reference: a Panda simulated with a known smooth Coulomb law ``fc tanh(dq / v_s)``, its
width one of the grid's (30 bands of the noise-free floor, 0.03 rad/s).
"""

from __future__ import annotations

import numpy as np
import pytest

import dynid
from dynid.friction.fit import fit_friction_through, friction_residual
from dynid.friction.laws import LAWS
from dynid.friction.select import choose_smooth_width, select_friction
from dynid.identification.prepare import Preprocessing
from dynid.identification.recordings import prepare_recordings
from dynid.identification.selection import select_structure
from dynid.identification.structure import (
    MIN_WIDTH,
    SMOOTH_WIDTHS,
    Structure,
    smooth_width,
    smooth_width_grid,
)
from dynid.simulation.measurement import SensorNoise

from conftest import recordings

TRUE_FACTOR = 30.0


@pytest.fixture(scope="module")
def smooth_log():
    """A Panda log (exact, 4 s) whose friction is ``0.1 dq + 0.4 tanh(dq / 0.03)``."""
    panda = dynid.panda()
    P = np.tile([0.1, 0.4, 0.0], (7, 1))
    truth = LAWS["smooth"].model(P, np.full(7, TRUE_FACTOR * MIN_WIDTH))
    return panda, recordings(panda, (3,), friction=truth, duration=4.0)[0]


def test_the_grid_is_identify_s_factors_times_the_band():
    """The one grid: every factor of SMOOTH_WIDTHS with its widths per joint, floored at
    MIN_WIDTH bands (closed form)."""
    band = [0.0, 2e-3, 0.5]
    grid = smooth_width_grid(band)
    assert [f for f, _ in grid] == list(SMOOTH_WIDTHS)
    for f, w in grid:
        np.testing.assert_allclose(w, [f * MIN_WIDTH, f * 2e-3, f * 0.5], rtol=1e-15)
        assert w == smooth_width(band, f)


def test_friction_and_identify_choose_the_same_width(smooth_log):
    """On the same log, identify's selection among its smooth candidates and the friction
    command's smooth law (by name and in the automatic comparison) choose the true width,
    30 bands; the friction fitted at it holds the true coefficients to 1e-6."""
    panda, log = smooth_log
    data = prepare_recordings(panda, [log], cutoff_hz=None)
    cands = [Structure(False, ("viscous", "smooth", "offset"), width=w) for w in SMOOTH_WIDTHS]
    sel = select_structure(panda, data, candidates=cands, per_joint=False)
    assert sel is not None and sel.chosen.width == TRUE_FACTOR
    res = friction_residual(panda, log, Preprocessing(cutoff_hz=None, filter_tau=False))
    assert choose_smooth_width(res) == TRUE_FACTOR
    fit = fit_friction_through(res, None, "smooth", width=choose_smooth_width(res))
    np.testing.assert_allclose(fit.friction.band, TRUE_FACTOR * MIN_WIDTH, rtol=1e-12)
    np.testing.assert_allclose(fit.friction.as_array()[:, :2], [[0.1, 0.4]] * 7, atol=1e-6)
    auto = select_friction(res, candidates=["classical", "smooth"])
    assert auto.chosen == "smooth"
    np.testing.assert_allclose(auto.fit.friction.band, TRUE_FACTOR * MIN_WIDTH, rtol=1e-12)


def test_the_same_width_on_a_noisy_log():
    """With sensor noise (standstill band about 1.3 mrad/s) and a true width of 0.15 rad/s
    (about 110 bands), identify's selection and the friction command both choose 100
    bands."""
    panda = dynid.panda()
    P = np.tile([0.1, 0.4, 0.0], (7, 1))
    truth = LAWS["smooth"].model(P, np.full(7, 0.15))
    log = recordings(panda, (3,), friction=truth, duration=4.0, noise=SensorNoise())[0]
    data = prepare_recordings(panda, [log], cutoff_hz=20.0)
    cands = [Structure(False, ("viscous", "smooth", "offset"), width=w) for w in SMOOTH_WIDTHS]
    sel = select_structure(panda, data, candidates=cands, per_joint=False)
    res = friction_residual(panda, log, Preprocessing(cutoff_hz=20.0, filter_tau=False))
    assert sel is not None and sel.chosen.width == choose_smooth_width(res) == 100.0
