"""Smooth Coulomb widths too alike their neighbours near rest to share one regressor with
them are judged each in a regressor of their own, not left out.

A motor-side log without velocity columns of a geared arm has a standstill band at the
motors of five times the noise of the velocities derived from its positions (gear ratio
times the joints'). The narrow smooth widths (the expected sign of a sharp Coulomb law
given that noise) and the banded sign then differ only within a few bands of rest: in one
regressor their columns are nearly dependent, and leaving the narrow widths out left the
banded sign alone, which switches the motors' friction off where they still turn.

Reference: the exact torques (no torque noise) of new recordings of the simulated arm
(planar 2R behind gears 80 and 50, its second motor turning with the first joint too,
sharp Coulomb, viscous friction and offsets at the motors).
"""

from __future__ import annotations

import warnings

import numpy as np
import pytest

from dynid.exceptions import DynidWarning, RankDeficientError
from dynid.friction.model import ClassicalFriction
from dynid.friction.recordings import validate_recordings
from dynid.friction.validation import own_friction
from dynid.identification import largest as largest_module
from dynid.identification.log import TorqueLog, with_derived_velocities
from dynid.identification.recordings import prepare_recordings
from dynid.identification.selection import identify_recordings, select_structure
from dynid.identification.structure import SMOOTH_WIDTHS, Structure
from dynid.model.drive import Drive
from dynid.simulation.measurement import SensorNoise, sample_times, simulate_measurement
from dynid.simulation.trajectories import random_fourier

from conftest import planar_2r

DRIVE = Drive.from_gears(
    [80.0, 50.0],
    [(2, 1, 30.0)],
    side="motor",
    rotor_inertia=np.array([1e-4, 5e-5]),
    friction_at="motor",
)
# at the motors: fv [N m s/rad], fc [N m] (the sharp sign of the true velocity), fo [N m]
TRUTH = ClassicalFriction(np.array([1e-4, 5e-5]), np.array([0.05, 0.03]), np.array([2e-3, -1e-3]))


def _log(seed: int, tau_std: float = 0.02) -> TorqueLog:
    """A 20 s motor-side log at 500 Hz with 1e-5 rad of noise on the joints' positions
    (1e-3 rad at the motors) and ``tau_std`` [N m] on the joints' torques, without
    velocity columns (derived from the positions, as read)."""
    robot = planar_2r()
    traj = random_fourier(robot, np.random.default_rng(seed))(sample_times(20.0, 500.0))
    log = simulate_measurement(
        robot,
        traj,
        rng=np.random.default_rng(seed + 100),
        noise=SensorNoise(tau_std=tau_std, q_std=1e-5, dq_std=0.0),
        friction=TRUTH,
        drive=DRIVE,
    )
    return with_derived_velocities(log)


@pytest.fixture(scope="module")
def logs() -> list[TorqueLog]:
    return [_log(seed) for seed in (1, 2, 3)]


def _exact_error(model: object) -> float:
    """The relative error [%] of ``model`` (its own friction) on the exact torques of three
    new recordings, pooled."""
    new = [_log(seed, tau_std=0.0) for seed in (4, 5, 6)]
    val = validate_recordings(model, new, friction=own_friction(model), drive=DRIVE)
    return float(val.errors.relative_error_percent)


def _selection(logs):
    """The structure selection on ``logs`` and the smooth widths [bands] it judged at the
    motors (viscous and smooth friction)."""
    robot = planar_2r()
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", DynidWarning)
        sel = select_structure(robot, prepare_recordings(robot, logs, drive=DRIVE), drive=DRIVE)
    assert sel is not None
    judged = {
        c.structure.width
        for c in sel.candidates
        # the drive says its friction acts at the motors: the candidates are judged there
        # alone, at the drive's own place ("")
        if c.structure.at == "" and c.structure.friction == ("viscous", "smooth")
    }
    return sel, judged


def test_narrow_smooth_widths_at_the_motors_are_judged_and_predict_a_sharp_law(logs):
    """Regression (a geared motor-side log without velocity columns: the narrow widths
    left out, the banded sign chosen): every width is judged, the narrowest chosen, and it
    predicts the exact torques of new recordings better than the banded sign."""
    robot = planar_2r()
    sel, judged = _selection(logs)
    assert judged == set(SMOOTH_WIDTHS)
    assert "smooth" in sel.chosen.friction and sel.chosen.width == 0.3
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", DynidWarning)
        chosen = identify_recordings(robot, logs, drive=DRIVE)
        sign = Structure(friction=("viscous", "coulomb", "offset"), at="motor")
        banded = identify_recordings(robot, logs, drive=DRIVE, structure=sign)
    assert _exact_error(chosen) < 0.85 * _exact_error(banded)


def test_a_width_the_shared_regressor_cannot_tell_apart_is_judged_in_its_own(logs, monkeypatch):
    """Where the shared regressor cannot tell the 1-band width from the others (made so
    here: the data of this arm tell them apart since the columns are filtered before
    decimation), that width, the first left out as
    :data:`~dynid.identification.largest.SMOOTH_THINNING` orders, is judged in a
    regressor of its own, said in one note, rather than dropped."""
    fit = largest_module._fit_group

    def alike(robot, data, group, *rest):  # the 1-band width beside others: rank deficient
        widths = {c.width for c in group if "smooth" in c.friction}
        if 1.0 in widths and len(widths) > 1:
            raise RankDeficientError("alike", rank=1, needed=2)
        return fit(robot, data, group, *rest)

    monkeypatch.setattr(largest_module, "_fit_group", alike)
    sel, judged = _selection(logs)
    assert judged == set(SMOOTH_WIDTHS)
    assert any("judged each in a regressor of its own" in n for n in sel.notes), sel.notes
