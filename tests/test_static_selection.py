"""Static configurations chosen from a pool (issue 9)."""

from __future__ import annotations

import numpy as np
import pytest

import dynid
from dynid.cli.__main__ import main
from dynid.exceptions import OptionError
from dynid.io.static_data import load_static_data
from dynid.regressors.base import base_parameters
from dynid.regressors.static import static_regressor
from dynid.simulation.collision import Obstacles, capsule_model, obstacle_distances, self_distances
from dynid.simulation.controller import DEFAULT_MARGIN
from dynid.simulation.static_selection import select_static_configurations


def _cond(robot, q, base):
    return np.linalg.cond(static_regressor(robot, q)[..., base.independent].reshape(-1, base.rank))


def test_selection_beats_random_configurations_and_stays_admissible():
    """300 chosen of 1500: lower condition number than 300 random ones (3 draws), within the
    limits and free of collisions; the reported numbers are numpy's."""
    robot = dynid.panda()
    base = base_parameters(robot)
    sel = select_static_configurations(
        robot, 300, np.random.default_rng(71), obstacles=Obstacles.floor()
    )
    assert sel.q.shape == (300, 7) and sel.pool_size == 1500
    assert sel.condition_number == pytest.approx(_cond(robot, sel.q, base), rel=1e-8)
    for seed in (72, 73, 74):
        q = np.random.default_rng(seed).uniform(robot.q_min, robot.q_max, (300, 7))
        assert sel.condition_number < 0.85 * _cond(robot, q, base)
    assert np.all(sel.q >= robot.q_min + DEFAULT_MARGIN - 1e-12)
    assert np.all(sel.q <= robot.q_max - DEFAULT_MARGIN + 1e-12)
    caps = capsule_model(robot)
    assert self_distances(robot, sel.q, caps).min() >= 0
    assert obstacle_distances(robot, sel.q, Obstacles.floor(), caps).min() >= 0


def test_selection_is_reproducible_and_validates_its_options():
    """The same seed gives the same configurations; bad options raise OptionError."""
    robot = dynid.panda()
    a = select_static_configurations(robot, 40, np.random.default_rng(75), batches=5, exchange=3)
    b = select_static_configurations(robot, 40, np.random.default_rng(75), batches=5, exchange=3)
    np.testing.assert_array_equal(a.q, b.q)
    with pytest.raises(OptionError, match="pool_factor >= 2"):
        select_static_configurations(robot, 10, np.random.default_rng(0), pool_factor=1)


def test_acquire_static_pool_writes_the_chosen_configurations(tmp_path, capsys):
    """acquire-static --pool: a data file of the chosen configurations, numbers printed."""
    out = tmp_path / "chosen.csv"
    assert (
        main(["acquire-static", "--n", "60", "--pool", "3", "--seed", "4", "--out", str(out)]) == 0
    )
    text = capsys.readouterr().out
    assert "chose 60 of 180 configurations: condition number" in text
    data, _ = load_static_data(out, dynid.panda())
    assert data.n_configurations == 60
    np.testing.assert_allclose(data.M, dynid.mass_matrix(dynid.panda(), data.q), rtol=1e-12)


@pytest.mark.slow
def test_1010_chosen_configurations_beat_1010_random_ones_and_the_papers():
    """Issue 9: 1010 of 5050 chosen beat 1010 random ones (3 draws) and the paper's 48.9."""
    robot = dynid.panda()
    base = base_parameters(robot)
    sel = select_static_configurations(robot, 1010, np.random.default_rng(76))
    for seed in (77, 78, 79):
        q = np.random.default_rng(seed).uniform(robot.q_min, robot.q_max, (1010, 7))
        assert sel.condition_number < 0.85 * _cond(robot, q, base)
    assert sel.condition_number < 48.9
