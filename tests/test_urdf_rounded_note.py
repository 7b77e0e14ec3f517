"""A URDF angle written rounded (the UR5's elbow at rpy="3.1416 0 0"): named in a note."""

from __future__ import annotations

import logging
import warnings

import numpy as np
import pytest

from dynid.cli.__main__ import main
from dynid.exceptions import DynidWarning
from dynid.io.robot.urdf import load_urdf
from dynid.progress import NOTE
from dynid.regressors.base import base_parameters

from conftest import robot_data_urdf

_ELBOW = '<origin rpy="0.0 0.0 0.0" xyz="0.0 -0.1197 0.425"/>'


def _ur5(tmp_path, rpy: str, name: str, exact: bool = False) -> str:
    """The UR5 of example-robot-data with the elbow joint's origin at ``rpy`` (``exact``:
    its own right angles, written to 12 digits, to full precision too)."""
    text = open(robot_data_urdf("ur_description/urdf/ur5_robot.urdf")).read()
    assert text.count(_ELBOW) == 1
    if exact:
        text = text.replace("1.57079632679", repr(np.pi / 2)).replace("3.14159265359", repr(np.pi))
    path = tmp_path / name
    path.write_text(text.replace(_ELBOW, f'<origin rpy="{rpy}" xyz="0.0 -0.1197 0.425"/>'))
    return str(path)


@pytest.fixture
def ur5_files(tmp_path):
    return _ur5(tmp_path, "3.1416 0 0", "ur5_mod.urdf"), _ur5(
        tmp_path, repr(np.pi) + " 0 0", "ur5_exact.urdf", exact=True
    )


def _notes(caplog) -> list[str]:
    return [r.getMessage() for r in caplog.records if r.levelno == NOTE and "rounded" in r.message]


def test_rounded_elbow_is_a_note_and_snapping_gives_the_exact_robot(ur5_files, caplog):
    """As written: one short note (not a warning) naming the elbow, 7.3e-06 rad off, read as
    written, harmless, and the option; the expressions hold sin(3.1416 - pi) * mc3y, which
    the exact angles do not. Snapped: one note saying so, transforms of the exact file to
    1e-12, and the exact file's expressions."""
    rounded, exact_file = ur5_files
    caplog.set_level(NOTE)
    with warnings.catch_warnings():
        warnings.simplefilter("error", DynidWarning)
        written = load_urdf(rounded, tip_link="tool0")
        (note,) = _notes(caplog)
        caplog.clear()
        snapped = load_urdf(rounded, tip_link="tool0", snap_angles=True)
        (snap_note,) = _notes(caplog)
        caplog.clear()
        exact = load_urdf(exact_file, tip_link="tool0")
    assert _notes(caplog) == []  # the exact angles: nothing to say
    assert "elbow_joint (7.3e-06 rad off), read as written" in note
    assert "harmless here" in note and "--snap-angles" in note  # short: the leftovers unsaid
    assert "coefficients" not in note and len(note) < 400
    assert "elbow_joint (7.3e-06 rad off), snapped" in snap_note
    np.testing.assert_allclose(snapped.T_parent_joint, exact.T_parent_joint, rtol=0, atol=1e-12)
    assert np.abs(written.T_parent_joint - exact.T_parent_joint).max() > 1e-6
    leftover = f"{np.sin(3.1416 - np.pi):.10g}*mc3y"  # 7.346410207e-06
    assert any(leftover in e for e in base_parameters(written).expressions)
    assert base_parameters(snapped).expressions == base_parameters(exact).expressions
    assert not any("e-06" in e for e in base_parameters(snapped).expressions)


def test_cli_names_the_rounded_elbow_once_without_verbose(ur5_files, capsys, monkeypatch):
    """fk of the rounded file: the note on stderr once without -v; with --snap-angles the
    note says snapped and the pose equals the exact file's."""
    rounded, exact_file = ur5_files
    root = logging.getLogger()  # a process without logging of its own, as the command's
    monkeypatch.setattr(root, "handlers", [])
    monkeypatch.setattr(root, "level", root.level)
    args = ["--tip", "tool0", "--q", "0.1,0.2,0.3,0.4,0.5,0.6", "--json"]
    assert main(["fk", "--robot", rounded, *args]) == 0
    err = capsys.readouterr().err
    assert err.count("rounded near multiples of pi/2") == 1
    assert "note:" in err and "elbow_joint (7.3e-06 rad off), read as written" in err
    assert main(["fk", "--robot", rounded, "--snap-angles", *args]) == 0
    out, err = capsys.readouterr()
    assert err.count("elbow_joint (7.3e-06 rad off), snapped") == 1
    assert main(["fk", "--robot", exact_file, *args]) == 0
    exact = capsys.readouterr()
    assert "rounded" not in exact.err
    np.testing.assert_allclose(_pose(out), _pose(exact.out), rtol=0, atol=1e-12)


def _pose(out: str) -> np.ndarray:
    """The numbers of fk's JSON line, flattened."""
    import json

    def flat(x):
        if isinstance(x, dict):
            return [v for k in sorted(x) for v in flat(x[k])]
        if isinstance(x, list):
            return [v for e in x for v in flat(e)]
        return [x] if isinstance(x, float | int) and not isinstance(x, bool) else []

    return np.array(flat(json.loads(out)), dtype=float)


def test_a_prior_read_from_the_rounded_file_adds_no_note(ur5_files, caplog):
    """The prior's URDF is read snapped for its inertials: no note of its own."""
    from dynid.workflows.prior import load_prior

    rounded, _ = ur5_files
    caplog.set_level(logging.DEBUG)
    robot = load_urdf(rounded, tip_link="tool0", snap_angles=True)
    caplog.clear()
    load_prior(rounded, robot)
    assert _notes(caplog) == []


def test_data_recorded_as_written_read_snapped_names_the_rounding(ur5_files):
    """Kinematics recorded with the elbow as written, checked against the snapped robot:
    the mismatch (7.35e-06, sin of the rounding) is named as a rounded angle read two ways;
    a real difference (5 mm in a link) is not."""
    from dynid.identification.consistency import kinematics_record, recorded_robot_mismatch

    rounded, _ = ur5_files
    written = load_urdf(rounded, tip_link="tool0")
    snapped = load_urdf(rounded, tip_link="tool0", snap_angles=True)
    msg = recorded_robot_mismatch(snapped, {"kinematics": kinematics_record(written)})
    assert msg is not None and f"{abs(np.sin(3.1416 - np.pi)):.3g}" in msg
    assert "--snap-angles to both commands or to neither" in msg
    T = written.T_parent_joint.copy()
    T[2, 0, 3] += 5e-3
    other = {"kinematics": {"T_parent_joint": T.tolist()}}
    assert "--snap-angles" not in recorded_robot_mismatch(written, other)


def test_export_into_the_rounded_template_names_the_rounding_once(
    ur5_files, tmp_path, capsys, monkeypatch
):
    """Exported into the rounded file as template, whose joints' friction is replaced: the
    rounding is named once (the robot read), not a second time for the template read back
    for its joint names; the written elbow keeps its rounded angle (the template's text) and
    its inertials are the robot's."""
    rounded, _ = ur5_files
    text = open(rounded).read()
    template = tmp_path / "vendor.urdf"  # a vendor's friction, which --no-friction removes
    template.write_text(text.replace('damping="0.0" friction="0.0"', 'damping="2" friction="1"'))
    root = logging.getLogger()
    monkeypatch.setattr(root, "handlers", [])
    monkeypatch.setattr(root, "level", root.level)
    out = tmp_path / "out.urdf"
    chain = ["--base", "base_link", "--tip", "tool0"]
    args = ["export", "--params", rounded, *chain, "--urdf-template", str(template)]
    args += ["--no-friction", "--out", str(out)]
    assert main(args) == 0
    err = capsys.readouterr().err
    assert err.count("rounded near multiples of pi/2") == 1
    assert 'rpy="3.1416 0 0"' in out.read_text()
    back = load_urdf(str(out), tip_link="tool0")
    np.testing.assert_allclose(back.phi, load_urdf(rounded, tip_link="tool0").phi, atol=1e-9)
