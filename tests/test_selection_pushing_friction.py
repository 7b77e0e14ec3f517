"""Friction fitted below zero that the data do not determine is left out of the structure.

References: noisy simulated recordings of a Panda with known viscous friction on joints
1-5 and none on joints 6 and 7 (velocities and accelerations derived from the positions
through the low-pass, as in a real log); hand-computed relative standard deviations.
"""

from __future__ import annotations

import warnings

import numpy as np
import pytest

import dynid
from dynid.friction.model import ClassicalFriction
from dynid.identification.candidates import DETERMINED_STD_PERCENT, loose_pushing
from dynid.identification.recordings import prepare_recordings
from dynid.identification.selection import identify_recordings, select_structure
from dynid.identification.structure import Structure
from dynid.simulation.measurement import SensorNoise

from conftest import recordings

FV = np.array([0.3, 0.25, 0.2, 0.15, 0.1, 0.0, 0.0])  # N m s/rad
VISCOUS = Structure(friction=("viscous",))


def test_loose_pushing_names_undetermined_friction_below_zero():
    """Viscous, Coulomb and quadratic coefficients below zero with a relative standard
    deviation above 20 % are named (``fv1``: 0.1 / 0.2 = 50 %); one determined to 10 %, one
    above zero, an offset or a Stribeck bump below zero, and a label with a column above
    zero are not."""
    labels = ["", "fv1", "fv2", "fv3", "fc1", "fq2", "fo1", "fsp1", "jfv7", "fc2", "fc2"]
    x = np.array([-1.0, -0.2, -0.2, 0.2, -0.05, -0.01, -0.3, -0.4, -0.02, -0.1, 0.1])
    sd = np.array([5.0, 0.1, 0.02, 0.1, 0.05, 0.002, 0.3, 0.4, 0.01, 0.5, 0.5])
    use = np.ones(x.size, dtype=bool)
    got = loose_pushing(x, sd, use, labels)
    assert [lab for lab, _, _ in got] == ["fv1", "fc1", "jfv7"]
    np.testing.assert_allclose([r for _, _, r in got], [50.0, 100.0, 50.0], rtol=1e-12)
    assert [v for _, v, _ in got] == [-0.2, -0.05, -0.02]
    use[1] = False  # a column not in use is not the candidate's
    assert [lab for lab, _, _ in loose_pushing(x, sd, use, labels)] == ["fc1", "jfv7"]


@pytest.mark.parametrize("seed", [1, 3])
def test_undetermined_viscous_below_zero_is_left_out(seed):
    """Regression: a geared UR10 without joint friction kept ``fv2 = -0.23`` at 36 % (the
    held-out error of its ols fits missed it) under a rule that says a coefficient
    determined to 20 % is kept. The viscous coefficients of joints 6 and 7 (true value 0)
    come out below zero and not determined: left out, said in a note, and the rule says
    so; those of joints 1-5 stay and match the truth within 5 %."""
    panda = dynid.panda()
    logs = recordings(
        panda,
        (seed, seed + 50),
        friction=ClassicalFriction(FV, np.zeros(7), np.zeros(7)),
        duration=3.0,
        noise=SensorNoise(),
    )
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        data = prepare_recordings(panda, logs, None)
    sel = select_structure(panda, data, candidates=[VISCOUS], per_joint=False)
    assert sel is not None and sel.chosen.friction == ("viscous",)
    zero = {f"fv{j + 1}" for j in np.flatnonzero(FV == 0)}
    assert sel.chosen.drop and set(sel.chosen.drop) <= zero, sel.chosen.name
    assert "friction below zero not determined to 20 % left out" in sel.rule
    assert any(n.startswith(", ".join(sel.chosen.drop) + " left out of") for n in sel.notes)
    chosen = next(c for c in sel.candidates if c.structure == sel.chosen)
    assert not chosen.loose_pushing
    model = identify_recordings(panda, logs, structure=sel.chosen, estimator="ols")
    fit = model.joint_fit
    r = model.base.rank
    fv = np.where(fit.kept[r : r + 7], fit.beta[r : r + 7], 0.0)
    np.testing.assert_allclose(fv[:5], FV[:5], rtol=0.05)
    held = [k for k in range(5, 7) if f"fv{k + 1}" not in sel.chosen.drop]
    stds = 100 * fit.std[r:][held] / np.abs(fv[held])
    assert np.all((fv[held] > 0) | (stds <= DETERMINED_STD_PERCENT))
