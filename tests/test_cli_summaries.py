"""The tables the commands print: columns aligned whatever the names' lengths."""

from __future__ import annotations

from types import SimpleNamespace

import numpy as np

from dynid.cli.structure_table import selection_lines
from dynid.cli.summaries import format_newton_euler_rms, format_rms_table


def _column_ends(line: str) -> list[int]:
    """Where each run of non-blank characters ends (the right edges of right-aligned cells)."""
    ends, inside = [], False
    for k, ch in enumerate(line + " "):
        if ch != " " and not inside:
            inside = True
        elif ch == " " and inside:
            inside = False
            ends.append(k)
    return ends


def test_the_rms_table_stays_aligned_with_long_joint_names():
    """Joint names longer than the first column (and a short one) keep every value's right
    edge under its header's (a long name pushed its row's values right)."""
    names = ["j1", "a_very_long_joint_name_of_a_wrist", "elbow"]
    cols = {"RMS[Nm]": np.array([0.1, 22.5, 3.0]), "a_long_column_title_[Nm]_of_a_tool": np.ones(3)}
    lines = format_rms_table(names, cols).splitlines()
    assert len({len(s) for s in lines}) == 1, lines
    ends = _column_ends(lines[0])[-2:]  # the two value columns (the header's words end there)
    for line in lines[1:]:
        assert _column_ends(line)[-2:] == ends, lines


def test_the_newton_euler_table_stays_aligned_with_short_and_long_names():
    """The Newton-Euler table: names shorter than 'joint' align too."""
    errors = SimpleNamespace(rms=np.array([0.5, 1.25]), relative_error_percent=3.0)
    reference = SimpleNamespace(rms=np.array([0.4, 1.0]))
    val = SimpleNamespace(
        joint_names=("j1", "j2"),
        errors=errors,
        errors_reference=reference,
        friction_kind="",
    )
    lines = format_newton_euler_rms(val).splitlines()[:-1]
    assert len({len(s) for s in lines}) == 1, lines
    assert _column_ends(lines[1])[-2:] == _column_ends(lines[2])[-2:]
    assert _column_ends(lines[0])[-1] == _column_ends(lines[1])[-1]


def test_the_structure_table_stays_aligned_with_a_long_structure_name():
    """A structure name over the usual width keeps the numbers of every row aligned."""
    cands = [
        {"name": n, "n_params": 40, "train_error_percent": 1.5, "heldout_error_percent": 2.0}
        | {"heldout_se_percent": 0.1}
        for n in ("base", "base + armature + viscous + coulomb on every joint of the arm")
    ]
    sel = {"validation": "5 folds", "chosen": "base", "rule": "lowest", "candidates": cands}
    lines = selection_lines(sel)[1:]
    assert len({len(s) for s in lines}) == 1, lines


def test_the_structure_table_lists_every_coefficient_the_per_joint_search_left_out():
    """A per-joint structure whose search left viscous friction out on every joint: the
    name no longer holds ``viscous`` and its ``- fo2`` alone would hide that; the left-out
    column lists every coefficient left out from where the search started (``fv1-7``)."""
    row = {"n_params": 40, "train_error_percent": 1.5, "heldout_error_percent": 2.0}
    row |= {"heldout_se_percent": 0.1}
    left = [f"fv{j}" for j in range(1, 8)] + ["fo2"]
    cands = [
        row | {"name": "links + viscous + coulomb + offset"},
        row | {"name": "links + coulomb + offset - fo2", "left_out": left},
    ]
    chosen = cands[1]["name"]
    sel = {"validation": "5 folds", "chosen": chosen, "rule": "lowest", "candidates": cands}
    lines = selection_lines(sel)
    assert lines[1].endswith("  coefficients left out")
    assert lines[3].startswith("  * links + coulomb + offset ") and lines[3].endswith("  fv1-7 fo2")
    assert lines[2].rstrip() == lines[2] and not lines[2].endswith("fo2")


def test_the_structure_table_has_no_left_out_column_when_no_row_shown_fills_it():
    """Regression (a garbled last header printed over an empty column): a coefficient left
    out only by a candidate the table does not show (a shape other than its law's best)
    gives no left-out column; a row shown that leaves one out gives a short header."""
    row = {"n_params": 40, "train_error_percent": 1.5, "heldout_se_percent": 0.1}
    cands = [
        row | {"name": "links + viscous + smooth:0.3", "heldout_error_percent": 2.0},
        row | {"name": "links + viscous + smooth:1", "heldout_error_percent": 3.0},
    ]
    cands[1]["left_out"] = ["fo1", "fo2"]  # reached from smooth:1 + offset: every fo left out
    sel = {"validation": "5 folds", "chosen": cands[0]["name"], "rule": "r", "candidates": cands}
    lines = selection_lines(sel)
    assert lines[1].endswith("se vs best"), lines[1]
    assert all(line.rstrip() == line for line in lines), lines
    cands[1]["heldout_error_percent"] = 1.0  # now the law's best: shown, with fo1 fo2
    lines = selection_lines(sel)
    assert lines[1].endswith("  coefficients left out"), lines[1]
    assert any(line.endswith("  fo1 fo2") for line in lines[2:]), lines


def test_the_structure_table_shows_each_shaped_law_at_its_best_shape():
    """Candidates that differ only in a smooth width or a Stribeck velocity: the table
    shows the one with the lowest held-out error of each law (and the one chosen), and one
    line counts the others, which the file keeps."""
    row = {"n_params": 40, "train_error_percent": 1.5, "heldout_se_percent": 0.1}
    names = ["links + viscous + coulomb"]
    names += [f"links + viscous + smooth:{w}" for w in (0.3, 1, 3)]
    names += [f"links + viscous + coulomb + stribeck:{v}" for v in (0.02, 0.05)]
    held = [5.0, 4.0, 3.0, 3.5, 2.5, 2.0]
    pairs = zip(names, held, strict=True)
    cands = [row | {"name": n, "heldout_error_percent": h} for n, h in pairs]
    chosen = "links + viscous + smooth:0.3"  # the simplest within one standard error
    sel = {"validation": "5 folds", "chosen": chosen, "rule": "rule", "candidates": cands}
    lines = selection_lines(sel)
    rows = [line[4:].split("  ")[0].strip() for line in lines[2:] if line.startswith("  ")]
    shown = [r for r in rows if r.startswith("links")]
    assert shown == [names[0], chosen, names[2], names[5]], lines
    said = "  (2 more candidate(s) of a smooth or Stribeck law"
    assert any(line.startswith(said) for line in lines)


def test_a_per_joint_structure_and_its_every_joint_structure_read_apart():
    """The every-joint structure and the per-joint one of the same terms (the coefficients
    left out in their own column): their names differ, the per-joint one marked ", per
    joint" (two rows read alike, 71 and 65 parameters)."""
    row = {"train_error_percent": 0.3, "heldout_se_percent": 0.03}
    full = "links + viscous + smooth:10 + stribeck:0.0803 + offset"
    pruned = f"{full} - fo1 - fo3"
    cands = [
        row | {"name": full, "n_params": 71, "heldout_error_percent": 0.2978},
        row | {"name": pruned, "n_params": 69, "heldout_error_percent": 0.2979},
    ]
    sel = {"validation": "2 recordings", "chosen": pruned, "rule": "rule", "candidates": cands}
    lines = selection_lines(sel)
    rows = [line[4:].split("  ")[0].strip() for line in lines[2:] if line.startswith("  ")]
    assert rows == [full, f"{full}, per joint"], lines
    assert lines[-1].endswith("  fo1 fo3"), lines


def test_skipped_shapes_of_one_law_show_their_best_and_are_counted():
    """Seven Stribeck velocities of one law, all skipped (their bump below zero), beside
    the chosen law: one row marked x (the lowest held-out error of them), and the line
    below counts the six others as marked x, so that the note's count of skipped
    candidates is accounted for (an iiwa's table showed 37 x rows of 57)."""
    row = {"n_params": 71, "train_error_percent": 1.2, "heldout_se_percent": 0.01}
    chosen = "links + viscous + smooth:3 + offset"
    speeds = (0.02, 0.03, 0.05, 0.07, 0.1, 0.15, 0.2)
    held = (1.28, 1.22, 1.17, 1.16, 1.17, 1.19, 1.21)
    skipped = [
        row | {"name": f"links + viscous + smooth:3 + stribeck:{v} + offset",
               "heldout_error_percent": h, "negative_bump": ["fsp1"]}
        for v, h in zip(speeds, held, strict=True)
    ]  # fmt: skip
    cands = [row | {"name": chosen, "heldout_error_percent": 1.23}, *skipped]
    note = "7 candidate(s) marked x skipped: their Stribeck bump is below zero"
    sel = {"validation": "4 recordings", "chosen": chosen, "rule": "rule", "candidates": cands}
    lines = selection_lines(sel | {"notes": [note]})
    marks = {line[4:].split("  ")[0].strip(): line[2] for line in lines[2:] if line[2] in "*x "}
    assert marks == {chosen: "*", skipped[3]["name"]: "x"}, lines
    assert any("(6 more candidate(s)" in line and "6 of them marked x" in line for line in lines)
