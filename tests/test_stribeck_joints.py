"""The Stribeck velocity chosen per joint on held-out data
(:mod:`dynid.identification.stribeck_joints`).

References: simulated ground truth (a Panda whose Stribeck law has velocities that differ
between joints, and one whose joints share one, with sensor noise, judged on recordings
the fit did not see); the Stribeck column's closed form ``sign(dq) exp(-(dq / vst_j)^2)``.
"""

from __future__ import annotations

import json
import warnings

import numpy as np
import pytest

import dynid
from dynid.cli.summaries import format_identification
from dynid.exceptions import DynidWarning
from dynid.friction.laws import LAWS
from dynid.friction.model import LawFriction, friction_of
from dynid.identification.recordings import prepare_recordings
from dynid.identification.selection import identify_recordings, select_structure
from dynid.identification.structure import STRIBECK_VELOCITIES, Structure
from dynid.io.model_json import load_model_json, save_model_json
from dynid.model.drive import Drive
from dynid.regressors.terms import LinearFriction
from dynid.simulation.measurement import SensorNoise

from conftest import recordings

#: A TALOS-like arm: the shoulder's two joints at 0.08 rad/s, the others at 0.1.
SPLIT = np.array([0.08, 0.08, 0.1, 0.1, 0.1, 0.1, 0.1])
_CANDIDATES = [
    Structure(False, ("viscous", "coulomb", "stribeck"), vst=v) for v in STRIBECK_VELOCITIES
]


def _truth(vst: np.ndarray) -> np.ndarray:
    """The Stribeck law's parameters (7, 5): fv, fc, fs = 2 fc, vst, fo = 0."""
    fc = np.linspace(0.8, 0.3, 7)
    return np.column_stack([np.linspace(0.6, 0.1, 7), fc, 2.0 * fc, vst, np.zeros(7)])


def _selected(vst: np.ndarray, per_joint: bool = True):
    panda = dynid.panda()
    P = _truth(vst)
    noisy = SensorNoise(tau_std=0.05, q_std=2e-5, dq_std=2e-3)
    logs = recordings(
        panda, (81, 82, 83), friction=LawFriction(LAWS["stribeck"], P), duration=4.0, noise=noisy
    )
    data = prepare_recordings(panda, logs)
    out = [
        select_structure(panda, data, candidates=_CANDIDATES, per_joint=p) for p in (False, True)
    ]
    return panda, logs, P, out


@pytest.fixture(scope="module")
def split():
    return _selected(SPLIT)


def _peaks(panda, logs, structure) -> np.ndarray:
    """The identified Stribeck peak ``fs = fc + fsp`` [N m] per joint."""
    with warnings.catch_warnings():  # a link parameter the short logs hardly excite
        warnings.simplefilter("ignore", DynidWarning)
        model = identify_recordings(panda, logs, structure=structure)
    fr = model.friction
    assert fr is not None
    return np.asarray(fr.params)[:, 2]


def test_each_joint_s_stribeck_velocity_is_recovered(split):
    """Regression (one velocity for all: 0.0934 rad/s on every joint, joints 1-2 17 %
    off): each joint's Stribeck velocity is within 15 % of its own truth, and the
    shoulder's two are told from the others."""
    _, _, _, (common, mine) = split
    assert common is not None and mine is not None
    assert isinstance(common.chosen.vst, float)
    v = np.array(mine.chosen.vsts(7))
    assert np.all(np.abs(v / SPLIT - 1) < 0.15), v
    assert max(v[:2]) < min(v[2:5]), v
    assert any("Stribeck velocity chosen per joint" in n for n in mine.notes)
    assert "stribeck:" in mine.chosen.name and "/" in mine.chosen.name


def test_the_stribeck_peaks_come_closer_to_the_truth(split):
    """The peaks ``fs`` fitted at the velocities per joint are closer to the simulated
    ones on the shoulder's joints (5-7 % low at the common velocity) and no farther
    overall."""
    panda, logs, P, (common, mine) = split
    one = np.abs(_peaks(panda, logs, common.chosen) / P[:, 2] - 1)
    per = np.abs(_peaks(panda, logs, mine.chosen) / P[:, 2] - 1)
    assert np.all(per[:2] < one[:2]), (per, one)
    assert per[:2].max() < 0.03, per
    assert per.sum() < one.sum(), (per, one)


def test_joints_that_share_one_velocity_keep_one():
    """No spurious split: a law whose joints share 0.08 rad/s keeps one velocity."""
    _, _, _, (_, mine) = _selected(np.full(7, 0.08))
    assert mine is not None
    assert isinstance(mine.chosen.vst, float), mine.chosen.vst
    assert abs(mine.chosen.vst / 0.08 - 1) < 0.05


def test_the_per_joint_column_is_the_closed_form():
    """Each joint's Stribeck column at its own velocity: ``sign(dq) exp(-(dq / vst_j)^2)``."""
    vst = (0.05, 0.2)
    t = LinearFriction(Drive.identity(2), parts=("coulomb", "stribeck"), vst=vst)
    dq = np.array([[0.1, -0.1], [-0.03, 0.4]])
    cols = t.torque_columns(np.zeros_like(dq), dq, np.zeros_like(dq))
    want = np.sign(dq) * np.exp(-((dq / np.array(vst)) ** 2))
    np.testing.assert_allclose(cols[:, [0, 1], [1, 3]], want, rtol=1e-12)
    assert t.as_array(np.ones(4))[:, 3].tolist() == list(vst)


def test_per_joint_velocities_are_written_and_read_back(split, tmp_path):
    """identification.json records the velocity of each joint and the summary says them;
    a file written with one number (before velocities per joint) still loads, every joint
    at it."""
    panda, logs, _, (_, mine) = split
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", DynidWarning)
        model = identify_recordings(panda, logs, structure=mine.chosen)
    said = "/".join(f"{v:.3g}" for v in mine.chosen.vsts(7))
    assert f"vst = {said} rad/s (per joint)" in format_identification(model)
    path = save_model_json(tmp_path / "identification.json", model)
    back = load_model_json(path)
    want = mine.chosen.vsts(7)
    assert back.terms["friction"].term.vst == want
    fr = back.friction
    assert fr is not None
    np.testing.assert_allclose(fr.params[:, 3], want)
    # the friction model validate, observe and the exports evaluate: each joint at its own
    dq = np.full((1, 7), 0.07)  # rad/s, beyond the standstill band
    fv, fc, fs, vst, fo = fr.params.T
    law = fv * dq + fc + (fs - fc) * np.exp(-((dq / np.array(want)) ** 2)) + fo
    np.testing.assert_allclose(friction_of(fr).torques(dq), law, rtol=1e-9, atol=1e-12)
    doc = json.loads(path.read_text())
    term = next(t for t in doc["terms"] if t["name"] == "friction")
    assert term["definition"]["vst"] == list(want)
    term["definition"]["vst"] = 0.09  # as older files hold it
    path.write_text(json.dumps(doc))
    old = load_model_json(path)
    assert old.terms["friction"].term.vst == 0.09
    np.testing.assert_allclose(old.friction.params[:, 3], 0.09)


def test_a_velocity_per_joint_is_given_and_named():
    """``stribeck:V1/V2`` gives one per joint, written back the same way; one repeated is
    the one velocity."""
    s = Structure.parse("viscous,coulomb,stribeck:0.08/0.1")
    assert s.vsts(2) == (0.08, 0.1)
    assert "stribeck:0.08/0.1" in s.name
    assert Structure.parse(s.name) == s
    assert Structure.parse("coulomb,stribeck:0.1/0.1").vst == 0.1
