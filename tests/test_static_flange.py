"""Static data of an arm whose controller's model holds a hand the description lacks: the
mass at the flange named (identify, retrieve --static, retrieve --model), none without the
hand or against a prior that holds it; retrieve --static reads another tool's columns.

References: Pinocchio's M(q) (crba) and g(q) on example-robot-data's Panda holding dynid's
Panda inertials, with a 0.73 kg hand added to link 7 (its centre of mass 0.137 m along z7,
0.03 m past the flange, as a Franka hand sits).
"""

from __future__ import annotations

import json

import numpy as np
import pytest

import dynid
from dynid.cli.__main__ import main
from dynid.identification.data import StaticDataset
from dynid.identification.static_flange import data_flange_note, model_flange_note
from dynid.io.static_data import save_static_data
from dynid.workflows.identify import identify_files

from conftest import pinocchio_panda_model, pinocchio_panda_static

HAND_MASS = 0.73
HAND_COM = np.array([-0.01, 0.0, 0.137])  # [m] in link 7's frame


def _truth(N: int, hand: bool, seed: int = 3):
    """Pinocchio's ``(q, M, g, model)`` at ``N`` configurations within the Panda's limits,
    with the hand on link 7 or without."""
    pin = pytest.importorskip("pinocchio")
    load = None
    if hand:
        load = pin.Inertia(HAND_MASS, HAND_COM, np.diag([0.001, 0.0025, 0.0017]))
    q, M, g = pinocchio_panda_static(seed, N, margin=0.9, load=load)
    return q, M, g, pinocchio_panda_model(None, load)


def _said(notes, what="a mass of about"):
    return [n for n in notes if what in n]


@pytest.mark.parametrize("hand", [True, False])
def test_identify_names_the_hand_of_static_data_and_nothing_without_it(tmp_path, hand):
    """identify on static data: with the hand, one note naming about 0.73 kg at its centre
    of mass and the payload hint, in the model's notes (so retrieve --model can say it
    again from its gravity torques); without it, none."""
    q, M, g, _ = _truth(40, hand)
    path = save_static_data(tmp_path / "static.csv", StaticDataset(q, M, g))
    model = identify_files(dynid.panda(), path).model
    said = _said(model.info.notes)
    again = model_flange_note(model)  # retrieve --model's check, at configurations of its own
    if not hand:
        assert said == [] and again is None
        return
    assert len(said) == 1 and "about 0.73 kg at (-0.010, +0.000, +0.137) m in link7" in said[0]
    assert "dynid payload" in said[0] and "the robot description's" in said[0]
    assert again is not None and "about 0.73 kg at (-0.010, +0.000, +0.137)" in again


def test_a_prior_that_holds_the_hand_names_nothing():
    """Against a prior whose link 7 holds the hand (Pinocchio's link 7 with it), the data
    are the prior's: no note; against the description without it, the note."""
    q, _, g, model = _truth(30, True)
    robot = dynid.panda()
    held = robot.with_inertials(
        [model.inertias[i + 1].mass for i in range(7)],
        [model.inertias[i + 1].lever for i in range(7)],
        [model.inertias[i + 1].inertia for i in range(7)],
    )
    assert data_flange_note(robot, q, g, held) is None
    said = data_flange_note(robot, q, g)
    assert said is not None and "a mass of about 0.73 kg" in said


def _libfranka_csv(path, q, M, g, degrees: bool = False) -> None:
    """A libfranka-style dump: q0..q6 (in degrees when ``degrees``), M0..M48 column-major,
    g0..g6."""
    names = [f"q{i}" for i in range(7)] + [f"M{k}" for k in range(49)] + [f"g{i}" for i in range(7)]
    flat = M.transpose(0, 2, 1).reshape(len(q), 49)
    table = np.concatenate([np.degrees(q) if degrees else q, flat, g], axis=1)
    np.savetxt(path, table, delimiter=",", header=",".join(names), comments="", fmt="%.17g")


def test_retrieve_static_reads_a_libfranka_dump_with_columns_and_units(tmp_path, capsys):
    """retrieve --static with --columns/--units (q in degrees, M flat column-major): the
    data read as identify reads them (the hand's 0.73 kg and centre of mass come out of the
    positions converted), the note in the summary, the map recorded in feasible.json."""
    q, M, g, _ = _truth(30, True)
    _libfranka_csv(tmp_path / "franka.csv", q, M, g, degrees=True)
    cols, units = "q=q{i0},M=M{k0},g=g{i0}", "q=deg"
    out = tmp_path / "f"
    argv = ["retrieve", "--static", str(tmp_path / "franka.csv"), "--robot", "panda"]
    rc = main([*argv, "--columns", cols, "--units", units, "--no-figures", "--out", str(out)])
    text = capsys.readouterr().out
    assert rc == 0
    assert "about 0.73 kg at (-0.010, +0.000, +0.137) m in link7" in text
    recorded = json.loads((out / "feasible.json").read_text())["column_map"]
    assert recorded == {"columns": cols, "units": units}


def test_retrieve_model_refuses_columns_in_one_line(tmp_path, capsys):
    """--columns/--units apply to --static: with --model, one line, exit code 2."""
    argv = ["retrieve", "--model", str(tmp_path / "identification.json"), "--out", str(tmp_path)]
    assert main([*argv, "--columns", "q=q{i0},M=M{k0},g=g{i0}"]) == 2
    err = [ln for ln in capsys.readouterr().err.splitlines() if "error" in ln]
    assert len(err) == 1 and "--columns applies to --static only" in err[0]


def test_validate_judges_static_data_and_names_the_hand_the_description_lacks(tmp_path, capsys):
    """validate on static data (Pinocchio's M and g of the Panda with its hand, a file that
    records no noise) judges the model's M and g there: the description without the hand
    errs on g by the hand's gravity torques, which the verdict does not call good; with
    the hand's torques subtracted, round-off."""
    q, M, g, _ = _truth(12, True)
    path = save_static_data(tmp_path / "heldout.csv", StaticDataset(q, M, g))
    out = tmp_path / "v"
    assert main(["validate", "--robot", "panda", "--data", str(path), "--out", str(out)]) == 0
    doc = json.loads((out / "validation.json").read_text())
    assert doc["schema"] == "dynid-static-validation/1" and doc["verdict"]["level"] != "good"
    g0 = dynid.gravity_torques(dynid.panda(), q)
    expected = 100 * np.linalg.norm(g0 - g) / np.linalg.norm(g)  # the hand's share of g
    assert doc["g_error_percent"] == pytest.approx(expected, rel=1e-9)
