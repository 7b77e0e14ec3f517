"""The structure search on a log where one joint never reverses.

Reference: simulated Panda recordings with known viscous and Coulomb friction and sensor
noise whose joint 3 turns one way only; its Coulomb friction and a torque offset are then
the same column. The search leaves out that joint's coefficient and chooses among the
rest; the model is judged on a recording it was not fitted to, against its noise.
"""

from __future__ import annotations

import warnings

import numpy as np
import pytest

from dynid.exceptions import DynidWarning, RankDeficientError
from dynid.friction.model import ClassicalFriction
from dynid.friction.validation import own_friction
from dynid.identification.largest import LeftOut
from dynid.identification.selection import identify_recordings
from dynid.identification.structure import Structure
from dynid.simulation.measurement import SensorNoise, sample_times, simulate_measurement
from dynid.simulation.trajectories import Trajectory, random_fourier

NOISE = 0.05  # N m
FRICTION = ClassicalFriction(np.linspace(0.3, 0.1, 7), np.linspace(0.6, 0.2, 7), np.zeros(7))
ONE_WAY = 2  # joint 3 (0-based): its velocity stays positive


def _one_way(robot, seed: int, duration: float = 6.0) -> Trajectory:
    """The random Fourier trajectory of ``seed`` with joint 3 turning one way only
    (``dq3 = 0.25 + 0.1 cos(2 t)`` rad/s, always positive)."""
    traj = random_fourier(robot, np.random.default_rng(seed))(sample_times(duration, 500.0))
    t = traj.t
    q, dq, ddq = (np.array(a) for a in (traj.q, traj.dq, traj.ddq))
    q[:, ONE_WAY] = -0.8 + 0.25 * t + 0.05 * np.sin(2 * t)
    dq[:, ONE_WAY] = 0.25 + 0.1 * np.cos(2 * t)
    ddq[:, ONE_WAY] = -0.2 * np.sin(2 * t)
    return Trajectory(t, q, dq, ddq)


@pytest.fixture(scope="module")
def one_way_logs(panda):
    """Two training logs and one held out, each with joint 3 turning one way only."""
    return [
        simulate_measurement(
            panda,
            _one_way(panda, seed),
            rng=np.random.default_rng(seed + 100),
            noise=SensorNoise(tau_std=NOISE),
            friction=FRICTION,
        )
        for seed in (1, 2, 3)
    ]


def test_a_joint_that_never_reverses_does_not_abort_the_default_search(panda, one_way_logs):
    """Regression (the default search aborted with "rank < needed ... fc3 + 1*fo3" while
    a structure without offsets identified the same log): joint 3's Coulomb friction and
    its offset are one column; the search leaves the offset out (so that the candidates
    without an offset keep joint 3's Coulomb friction: leaving fc3 out of them put 1.098
    for 0.15 kg m^2 in a UR5's rotor inertia), says so in one note, and the model it
    chooses predicts a held-out log to its noise."""
    *logs, test = one_way_logs
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", DynidWarning)
        model = identify_recordings(panda, logs, ["a.csv", "b.csv"])
    sel = model.info.selection
    notes = [n for n in sel["notes"] if "do not excite" in n]
    assert len(notes) == 1 and "fo3 left out of every candidate" in notes[0], sel["notes"]
    chosen = Structure.parse(sel["chosen"])
    assert {"viscous"} <= set(chosen.friction), sel["chosen"]
    held = _one_way(panda, 3)
    tau = model.torques(held.q, held.dq, held.ddq) + own_friction(model).torques(held.dq)
    rms = np.sqrt(np.mean((test.tau - tau) ** 2, axis=0))
    assert np.all(rms < 1.3 * NOISE), rms


def test_a_fixed_structure_the_log_cannot_identify_names_the_terms_without_it(panda, one_way_logs):
    """Regression (the hint did not say how to leave the column out): a structure given
    by hand whose Coulomb friction and offset are one column on joint 3 is refused with
    the ``--terms`` that leaves one of them out, and that structure identifies the log."""
    logs = one_way_logs[:2]
    given = Structure(False, ("viscous", "coulomb", "offset"))
    with pytest.raises(RankDeficientError, match=r"--terms viscous,coulomb,offset,-f[co]3") as e:
        identify_recordings(panda, logs, structure=given)
    fewer = given.without(e.value.redundant)
    assert fewer.drop in (("fc3",), ("fo3",))
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", DynidWarning)
        model = identify_recordings(panda, logs, structure=fewer)
    labels = model.terms["friction"].labels
    assert len(labels) == 20 and fewer.drop[0] not in labels, labels


def test_a_chosen_smooth_width_is_not_named_as_left_out():
    """Regression (a note named the chosen ``smooth:0.3`` as left out): the smooth widths
    the data do not tell apart are left out of the smooth candidates' regressor, while the
    width 0.3 is judged, and chosen, with the smooth-sign Stribeck candidates (their bumps
    left out); the note names the widths 1 and 3 as left out and 0.3 as kept."""
    smooth, bumps = (True, "", ""), (True, "", "smooth_stribeck:0.3")
    left = LeftOut("smooth", "with armature", smooth, (0.3, 1.0, 3.0), (), False, ("r",))
    chosen = Structure.parse("links + armature + viscous + smooth:0.3")
    note = left.note(chosen, bumps)
    assert "at the widths 1, 3 bands" in note and "widths 0.3" not in note, note
    assert "the width 0.3, chosen, was kept" in note and "smooth-sign Stribeck" in note, note
    # a choice elsewhere (no armature, another width) leaves the note as it was
    for other, group in ((chosen, (False, "", "smooth_stribeck:0.3")), (chosen, smooth)):
        assert left.note(other, group).startswith(
            "the smooth candidates with armature at the widths 0.3, 1, 3 bands"
        )


def test_the_offset_is_left_out_in_place_of_the_coulomb_coefficient_it_equals():
    """Where a combination the data do not excite holds a joint's Coulomb coefficient and
    its offset (one constant column), the offset is the one left out; a Coulomb coefficient
    named by another combination stays as named (the solver named fc3 on a UR5 log and took
    the Coulomb friction from the candidates without an offset too)."""
    from dynid.identification.one_way_friction import offset_instead as _offset_instead

    assert _offset_instead("fc3", ("fc3 + 1*fo3",)) == "fo3"
    assert _offset_instead("jfc2", ("0.5*jfc2 - jfo2",)) == "jfo2"
    assert _offset_instead("fc3", ("fc3 - 0.2*fv3",)) == "fc3"
    assert _offset_instead("fc3", ("fc13 + fo13", "fc3 + fo1")) == "fc3"
    assert _offset_instead("fv4", ("fv4 + fo4",)) == "fv4"
