"""Columns no data can identify told from columns the data do not excite.

Reference: a planar 2R arm whose two joints are turned by a differential (``K = G [[1, 1],
[1, -1]]``, as a PR2 wrist), with exact simulated torques of known viscous friction at its
motors and at its joints. Its damping ``K^T diag(fv) K + diag(jfv)`` has three independent
entries for four coefficients: in closed form, ``(fv1, fv2, jfv1, jfv2) = (1, 1, -2 G^2,
-2 G^2)`` changes no torque, whatever the motion.
"""

from __future__ import annotations

import json
import re

import numpy as np
import pytest

from dynid.exceptions import RankDeficientError
from dynid.friction.model import ClassicalFriction
from dynid.identification.selection import identify_recordings
from dynid.identification.structure import Structure
from dynid.model.drive import Drive

from conftest import planar_2r, recordings

G = 30.0  # the differential's gear ratio
FV = np.array([0.02, 0.03])  # N m s/rad, at the motors (1e-5 of the PR2 times 2000)
JFV = np.array([4.0, 6.0])  # N m s/rad, at the joints


def _drive() -> Drive:
    return Drive.from_gears([G, -G], [(1, 2, G), (2, 1, G)], rotor_inertia=np.zeros(2))


def _logs():
    """Two exact recordings: viscous friction at both motors and at both joints."""
    robot, drive = planar_2r(), _drive()
    motor = ClassicalFriction(FV, np.zeros(2), np.zeros(2)).at(drive)
    joint = ClassicalFriction(JFV, np.zeros(2), np.zeros(2))
    logs = recordings(
        robot,
        (3, 4),
        friction=motor,
        drive=drive,
        duration=6.0,
        added=lambda g: joint.torques(g.dq),
    )
    return robot, drive, logs


def _coefficients(combination: str) -> dict[str, float]:
    """``{"jfv2": 1.0, "fv2": -0.0005556, ...}`` of ``"jfv2 - 0.0005556*fv2 + 1*jfv1"``."""
    first, *rest = combination.split(" ")
    out = {first: 1.0}
    for sign, term in zip(rest[::2], rest[1::2], strict=True):
        c, _, lab = term.rpartition("*")
        out[lab] = (1.0 if sign == "+" else -1.0) * (float(c) if c else 1.0)
    return out


def test_the_differentials_viscous_friction_at_both_sides_is_structurally_dependent():
    """Regression (PR2 trial: 'not excited by the data ... dynid excite optimises one' for a
    combination no trajectory separates): the error names the combination of the closed
    form (motors 1 / (2 G^2) of a joint's), says it is structural and gives the fix,
    never more excitation."""
    robot, drive, logs = _logs()
    with pytest.raises(RankDeficientError) as err:
        identify_recordings(
            robot, logs, cutoff_hz=None, drive=drive, structure=Structure.parse("viscous,at:both")
        )
    exc, msg = err.value, str(err.value)
    assert len(exc.structural) == 1 and exc.structural == exc.combinations
    c = _coefficients(exc.structural[0])
    assert set(c) == {"fv1", "fv2", "jfv1", "jfv2"}
    top = max(c, key=lambda k: abs(c[k]))  # normalise to the closed form's (1, 1, -2G^2, -2G^2)
    closed = {"fv1": 1.0, "fv2": 1.0, "jfv1": -2 * G**2, "jfv2": -2 * G**2}
    for k, v in c.items():
        assert v / c[top] == pytest.approx(closed[k] / closed[top], rel=1e-3)
    assert "structurally not identifiable" in msg and "excite" not in msg.split("rtol")[1]
    assert re.search(r"--terms viscous,at:both,-j?fv[12] ", msg), msg


def test_the_default_choice_says_the_combination_left_out_is_structural():
    """The candidates' note names the combination as structural, not as unexcited data,
    and the coefficient left out is one of it, of the candidates with friction at both
    sides only (the placement whose columns are dependent)."""
    robot, drive, logs = _logs()
    model = identify_recordings(robot, logs, cutoff_hz=None, drive=drive)
    notes = [n for n in model.info.selection["notes"] if "structurally not identifiable" in n]
    assert len(notes) == 1 and "do not excite" not in notes[0], notes
    assert notes[0].endswith(
        "left out of the candidates without armature, friction at the motors and the joints"
    ), notes


def _evaluated(expression: str, truth: dict[str, float]) -> float:
    """``"jfv1 + 1800*fv1"`` at the true coefficients."""
    return sum(c * truth[lab] for lab, c in _coefficients(expression).items())


@pytest.mark.filterwarnings("ignore::dynid.exceptions.DynidWarning")  # the exports' losses
def test_the_coefficients_holding_the_one_left_out_are_marked_combined_with_the_truth(tmp_path):
    """Regression (PR2 trial: motor fv6, fv7 printed 2.663e-5 +-0.74 % against a true 1e-5,
    holding fv + jfv7 / (2 G^2), as if determined alone): every coefficient of the
    combination is recorded with what it holds, which equals its fitted value at the
    true coefficients; the table, identification.json, a consistent fit's notes,
    feasible.json and the robot exports say so."""
    from dynid.cli.summaries import term_lines
    from dynid.feasibility.convex.fit import consistent_from_identified
    from dynid.io.model_json import model_from_dict, model_to_dict

    robot, drive, logs = _logs()
    model = identify_recordings(robot, logs, cutoff_hz=None, drive=drive)
    truth = {"fv1": FV[0], "fv2": FV[1], "jfv1": JFV[0], "jfv2": JFV[1]}
    combined = model.info.combined
    left = [lab for lab in truth if not any(lab in t.labels for t in model.terms.values())]
    assert len(left) == 1 and set(combined) == set(truth) - set(left)
    for t in model.terms.values():
        for lab, v in zip(t.labels, t.values, strict=True):
            assert v == pytest.approx(_evaluated(combined[lab], truth), rel=1e-6), lab
    assert model_from_dict(model_to_dict(model)).info.combined == combined
    lines = term_lines(model)
    assert sum(line.endswith("combined") or " combined " in line for line in lines) == 3
    assert any(f"{lab} holds {combined[lab]}" in line for line in lines for lab in combined)
    res = consistent_from_identified(robot, model)
    assert any("structurally dependent" in n for n in res.notes)
    from dynid.io.feasible import load_feasible_json, save_feasible_json

    path = save_feasible_json(tmp_path / "feasible.json", res)
    doc = json.loads(path.read_text())
    assert doc["combined"] == combined and "fv2 holds" in doc["conventions"]["combined"]
    assert load_feasible_json(path).n == 2
    from dynid.io.feasible_bundle import save_feasible_bundle

    (tmp_path / "bundle").mkdir()
    for f in save_feasible_bundle(tmp_path / "bundle", res):
        if f.suffix in (".urdf", ".xml", ".toml"):  # the exports' leading comment says it
            assert "fv2 holds" in "".join(f.read_text().split("\n", 3)[:3]), f.name


def _columns(text: str, drive: Drive | None):
    """The model columns of the structure ``text`` of the planar 2R arm (no data)."""
    from dynid.identification.dataset import ModelColumns
    from dynid.identification.structure import structure_terms
    from dynid.regressors.base import base_parameters

    robot = planar_2r()
    model_drive, terms = structure_terms(Structure.parse(text), drive, robot.n)
    base = base_parameters(robot, kind="torque", terms=terms)
    return robot, ModelColumns(base=base, terms=terms, drive=model_drive)


@pytest.mark.parametrize(
    ("text", "lost"),
    [
        ("viscous,at:both", 1),  # the closed form's combination
        ("viscous,coulomb,at:both", 1),  # the signs at the motors and joints differ
        ("viscous,coulomb,stribeck:0.002", 0),  # a narrow bump is not structurally zero
        ("viscous,smooth:3,offset", 0),
    ],
)
def test_the_structural_rank_loses_only_the_dependent_combinations(text, lost):
    """At random states the columns lose exactly the combinations that vanish at every
    motion: one for viscous friction at both sides of the differential, none for a
    Stribeck bump of 0.002 rad/s (uniform speeds in [-2, 2] lost it: rank 11 of 12) or a
    smooth Coulomb law at the joints."""
    from dynid.identification.structural import structural_rank

    robot, columns = _columns(text, _drive() if "at:" in text else None)
    s = structural_rank(robot, columns)
    assert s.needed == len(columns.labels) and s.needed - s.rank == lost
    assert len(s.combinations) == len(s.redundant) == lost
