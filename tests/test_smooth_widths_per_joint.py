"""The smooth Coulomb's width chosen per joint on held-out data.

One width factor for every joint is a compromise where joints round their friction
differently (a geared arm's motors, a sharp bearing beside a harmonic drive). The
reference: the simulated friction (a smooth Coulomb law per joint at widths of 0.005 and
0.1 rad/s; sigmoids of two steepnesses at a geared Panda's motors), the exact torques of
recordings the fit never saw, and the noise floor.
"""

from __future__ import annotations

import json
import warnings

import numpy as np
import pytest

import dynid
from dynid.cli.__main__ import main
from dynid.cli.structure_table import selection_lines
from dynid.cli.summaries import term_lines
from dynid.exceptions import DynidWarning, OptionError
from dynid.friction.laws import LAWS
from dynid.friction.model import LawFriction
from dynid.friction.recordings import validate_recordings
from dynid.friction.validation import own_friction
from dynid.identification.selection import identify_recordings
from dynid.identification.structure import Structure, structure_terms
from dynid.io.torque_log import save_torque_log
from dynid.model.drive import Drive
from dynid.simulation.measurement import SensorNoise

from conftest import recordings

SHARP, ROUND = 0.005, 0.1  # [rad/s]
NOISE = SensorNoise(tau_std=0.05, q_std=1e-5, dq_std=1e-3)


def _truth(widths: np.ndarray):
    """Viscous and smooth Coulomb friction of the Panda's joints at ``widths`` [rad/s]."""
    n = widths.size
    P = np.column_stack([np.linspace(0.3, 0.1, n), np.linspace(2.0, 0.5, n), np.zeros(n)])
    return LAWS["smooth"].model(P, widths)


#: A geared Panda (the wrist's last motor turning with joint 6 too), its rotors known.
GEARED = Drive.from_gears(
    [100.0, 100.0, 80.0, 80.0, 50.0, 50.0, 50.0],
    [(7, 6, 50.0)],
    side="joint",
    rotor_inertia=np.array([1.5e-4, 1.5e-4, 1e-4, 1e-4, 3e-5, 3e-5, 2e-5]),
    friction_at="motor",
)


def _identified(truth, drive=None):
    """The model identified by default from three noisy 7 s recordings of the Panda with
    ``truth`` friction (through ``drive``), and those recordings."""
    robot = dynid.panda()
    logs = recordings(robot, (1, 2, 3), friction=truth, duration=7.0, noise=NOISE, drive=drive)
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", DynidWarning)
        return identify_recordings(robot, logs, drive=drive), logs


def _chosen(truth, drive=None):
    """The model of :func:`_identified`, the one of the best single smooth width fitted on
    the same recordings, that candidate, and two exact new recordings (7 s each)."""
    robot = dynid.panda()
    model, logs = _identified(truth, drive)
    new = recordings(robot, (4, 5), friction=truth, duration=7.0, drive=drive)
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", DynidWarning)
        cands = model.info.selection["candidates"]
        single = min(
            (c for c in cands if "/" not in c["name"] and "smooth:" in c["name"]),
            key=lambda c: c["heldout_whitened_percent"],
        )
        given = Structure.parse(",".join(single["terms"]))
        one = identify_recordings(robot, logs, drive=drive, structure=given)
    return model, one, single, new


@pytest.fixture(scope="module")
def alternating():
    return _chosen(_truth(np.array([SHARP, ROUND] * 3 + [SHARP])))


def _new_error(model, new, drive=None) -> float:
    """The relative error [%] of ``model`` (its own friction) on exact new recordings."""
    val = validate_recordings(model, new, friction=own_friction(model), drive=drive)
    return float(val.errors.relative_error_percent)


def test_per_joint_widths_parse_print_and_collapse():
    """``smooth:W1/W2/..`` holds one width per joint, prints back as given, and equal
    widths are the one width."""
    s = Structure.parse("links + viscous + smooth:0.3/1/3 + offset")
    assert s.width == (0.3, 1.0, 3.0) and s.widths(3) == (0.3, 1.0, 3.0)
    assert s.terms == ("viscous", "smooth:0.3/1/3", "offset")
    assert Structure.parse(",".join(s.terms)) == s
    assert Structure.parse("smooth:3/3/3") == Structure.parse("smooth:3")
    assert s.with_width(1, 0.3, 3).widths(3) == (0.3, 0.3, 3.0)
    assert Structure(friction=("smooth",), width=(2, 2)).width == 2.0


@pytest.mark.parametrize(
    ("text", "match"),
    [
        ("viscous,smooth:0.3/-1", "positive number"),
        ("viscous,smooth:0.3/x", "positive number"),
        ("coulomb,stribeck:0.02/0", "positive number"),
        ("viscous,coulomb:1/2", "only smooth and stribeck take one per joint"),
    ],
)
def test_bad_per_joint_widths_are_refused(text, match):
    """A per-joint width or Stribeck velocity that is not a positive number, or per-joint
    shapes of another term, are refused in one line naming the term."""
    with pytest.raises(OptionError, match=match):
        Structure.parse(text)


def test_per_joint_widths_for_another_joint_count_are_refused():
    """Three widths on a two-joint arm: refused naming the term and the counts."""
    with pytest.raises(OptionError, match=r"smooth:0.3/1/3: 3 widths for 2 joints"):
        structure_terms(Structure.parse("smooth:0.3/1/3"), None, 2, (0.01, 0.01))


def test_per_joint_widths_are_each_joint_s_factor_of_its_band():
    """The model's smooth width [rad/s] per joint is that joint's factor times its band
    (at least 1 mrad/s)."""
    band = (0.002, 0.0005, 0.004)
    _, terms = structure_terms(Structure.parse("viscous,smooth:0.3/10/100"), None, 3, band)
    np.testing.assert_allclose(terms[0].width, [0.3 * 0.002, 10 * 0.001, 100 * 0.004])


def test_different_widths_are_chosen_per_joint_and_predict_closer_to_the_floor(alternating):
    """Joints alternately sharp (0.005 rad/s) and round (0.1 rad/s): the default search
    chooses a width per joint, wider on every round joint than on every sharp one, whose
    held-out error is nearer the noise floor than the best single width's, and which
    predicts exact new recordings better than that width does."""
    model, one, single, new = alternating
    chosen = Structure.parse(",".join(model.info.extra["terms"]))
    w = np.array(chosen.widths(7))
    assert min(w[1::2]) > max(w[0::2]), w
    sel = model.info.selection
    mine = next(c for c in sel["candidates"] if c["name"] == sel["chosen"])
    floor = model.info.heldout["noise_floor_percent"]
    assert mine["heldout_error_percent"] - floor < 0.5 * (single["heldout_error_percent"] - floor)
    assert _new_error(model, new) < 0.6 * _new_error(one, new)


def test_the_summary_names_the_widths_chosen_per_joint(alternating):
    """The choice line and the marked row of the structure table name the widths per
    joint, and the friction table says each joint's width is its own factor."""
    model = alternating[0]
    name = model.info.selection["chosen"]
    lines = selection_lines(model.info.selection)
    assert "/" in name and name in lines[0]
    # a coefficient left out on single joints stands in the table's own column
    assert any(line.startswith(f"  * {name.partition(' - ')[0]} ") for line in lines), lines
    assert any("K_j x max(band_j" in line for line in term_lines(model)), term_lines(model)


def test_a_geared_arm_s_motors_get_their_own_widths():
    """Regression (a geared arm with friction at the motors: one width for every motor a
    compromise, 1.1 % held out at a noise floor of 0.4 %): sigmoids at the motors, steep
    on motors 1, 3, 5 and 7 and shallow on the others, get wider widths at motors 2 and 4
    than at 1 and 3, a held-out error nearer the floor than the best single width's, and
    a better prediction of exact new recordings."""
    steep = [30.0, 0.3] * 3 + [30.0]  # phi2 [s/rad] at the motors
    phi = np.column_stack([[0.04, 0.04, 0.03, 0.03, 0.01, 0.01, 0.01], steep, np.zeros(7)])
    model, one, single, new = _chosen(LawFriction(LAWS["sigmoid"], phi, drive=GEARED), GEARED)
    w = Structure.parse(",".join(model.info.extra["terms"])).widths(7)
    assert min(w[1], w[3]) > max(w[0], w[2]), w
    sel = model.info.selection
    mine = next(c for c in sel["candidates"] if c["name"] == sel["chosen"])
    floor = model.info.heldout["noise_floor_percent"]
    assert mine["heldout_error_percent"] - floor < 0.5 * (single["heldout_error_percent"] - floor)
    assert _new_error(model, new, GEARED) < 0.5 * _new_error(one, new, GEARED)


def test_equal_widths_keep_one_width():
    """Every joint at 0.005 rad/s: the per-joint search keeps one width for all (the
    chosen structure holds no per-joint width)."""
    model, _ = _identified(_truth(np.full(7, SHARP)))
    chosen = Structure.parse(",".join(model.info.extra["terms"]))
    assert not isinstance(chosen.width, tuple), chosen.name


def test_per_joint_widths_given_with_terms_come_back_through_validate(panda, tmp_path):
    """``--terms viscous,smooth:5/100/..`` (velocity noise so low that every band is the
    1 mrad/s floor: the truth's 0.005 and 0.1 rad/s) is recorded in identification.json
    at those widths, and ``validate`` predicts an exact new recording with them better
    than with one width for all."""
    widths = np.array([SHARP, ROUND] * 3 + [SHARP])
    quiet = SensorNoise(tau_std=0.05, q_std=1e-6, dq_std=1e-4)
    logs = recordings(panda, (8,), friction=_truth(widths), duration=6.0, noise=quiet)
    new = recordings(panda, (9,), friction=_truth(widths), duration=6.0)
    files = [str(tmp_path / "r.csv"), str(tmp_path / "new.csv")]
    save_torque_log(files[0], logs[0])
    save_torque_log(files[1], new[0])
    errors = {}
    for tag, terms in (("per", "viscous,smooth:5/100/5/100/5/100/5"), ("one", "viscous,smooth:5")):
        out = tmp_path / tag
        with warnings.catch_warnings():
            warnings.simplefilter("ignore", DynidWarning)
            assert main(["identify", "--robot", "panda", "--data", files[0], "--terms", terms,
                         "--out", str(out), "-q", "--no-figures"]) == 0  # fmt: skip
            model = str(out / "identification.json")
            assert main(["validate", "--model", model, "--data", files[1],
                         "--out", str(out / "val"), "-q", "--no-figures"]) == 0  # fmt: skip
        errors[tag] = json.loads((out / "val" / "validation.json").read_text())
    doc = json.loads((tmp_path / "per" / "identification.json").read_text())
    assert "smooth:5/100/5/100/5/100/5" in doc["metadata"]["terms"]
    smooth = next(t["definition"] for t in doc["terms"] if "smooth" in t["definition"]["parts"])
    np.testing.assert_allclose(smooth["width"], widths, rtol=1e-12)
    per, one = (errors[k]["relative_error_percent"] for k in ("per", "one"))
    assert per < 0.5 * one, (per, one)
