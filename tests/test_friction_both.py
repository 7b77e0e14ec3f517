"""Friction at the motors and at the joints of a coupled drive at once (``at:both``).

References: exact simulated torques of a Panda whose wrist is coupled (motor 7 turns with
joints 6 and 7) and whose friction acts at its motors, ``K^T f_m(K dq)``, and at joint 7,
``f_j(dq_7)`` (the joint no motor turns alone), with known coefficients; the model chosen on
held-out data and its coefficients against those values.
"""

from __future__ import annotations

import contextlib
import io
import json
import re

import numpy as np
import pytest

import dynid
from dynid.cli.__main__ import main
from dynid.feasibility.convex.data_term import coefficient_term
from dynid.feasibility.convex.fit import consistent_from_identified
from dynid.friction.model import ClassicalFriction, FrictionSum, friction_of
from dynid.friction.validation import own_friction
from dynid.identification.selection import identify_recordings
from dynid.identification.structure import Structure, friction_placements, joint_side_joints
from dynid.io.feasible import (
    load_feasible_drive,
    load_feasible_json,
    load_feasible_linear_friction,
)
from dynid.io.feasible_bundle import save_feasible_bundle
from dynid.io.model_json import model_from_dict, model_to_dict
from dynid.io.torque_log import save_torque_log
from dynid.model.drive import Drive
from dynid.observer.model import from_identified
from dynid.observer.residual import ObserverOptions, observe

from conftest import recordings

FV = np.linspace(0.3, 0.1, 7)  # N m s/rad, at the motors
FC = np.linspace(0.6, 0.2, 7)  # N m
JFV, JFC = 0.15, 0.25  # joint 7's own bearing, at the joint


def _drive() -> Drive:
    return Drive.from_gears(np.ones(7), [(7, 6, 0.8)], rotor_inertia=np.zeros(7))


def _logs(panda, joint_side: bool):
    """Two exact recordings: classical friction at the motors, and (``joint_side``) viscous
    and Coulomb friction at joint 7."""
    drive = _drive()
    motor = ClassicalFriction(FV, FC, np.zeros(7)).at(drive)
    z = np.zeros(7)
    joint = ClassicalFriction(z + np.eye(7)[6] * JFV, z + np.eye(7)[6] * JFC, z)
    added = (lambda log: joint.torques(log.dq)) if joint_side else None
    logs = recordings(panda, (91, 92), friction=motor, drive=drive, duration=4.0, added=added)
    return logs, motor, joint


def test_a_drive_that_says_where_its_friction_acts_is_not_searched_elsewhere():
    """The placements judged: every one through a coupled drive that does not say where
    its friction acts; only the drive's own (``""``) where it says (``friction_at``), and
    through a drive without coupling (the same model either side)."""
    coupled = _drive()
    assert friction_placements(coupled) == ("motor", "joint", "both")
    for at in ("motor", "joint"):
        said = Drive.from_gears(
            np.ones(7), [(7, 6, 0.8)], rotor_inertia=np.zeros(7), friction_at=at
        )
        assert friction_placements(said) == ("",)
        assert said.friction_place == at
    assert friction_placements(Drive.from_gears(np.full(7, 50.0))) == ("",)
    assert friction_placements(None) == ("",)


@pytest.fixture(scope="module")
def both(panda):
    logs, motor, joint = _logs(panda, joint_side=True)
    return identify_recordings(panda, logs, cutoff_hz=None, drive=_drive()), motor, joint


def test_the_joints_no_motor_turns_alone_get_friction_at_the_joint():
    """Motor 6 turns joint 6 alone (its friction at the motor is joint 6's at the joint);
    motor 7 turns joints 6 and 7: only joint 7 gets friction at the joint."""
    assert joint_side_joints(_drive()) == (6,)
    diff = Drive(transmission=np.array([[1.0, 1.0], [1.0, -1.0]]), offset=np.zeros(2))
    assert joint_side_joints(diff) == (0, 1)


def test_friction_on_both_sides_is_chosen_and_comes_back(both):
    """Exact data with friction at the motors and at joint 7: the default judges the three
    placements and keeps both, the coefficients back to 1e-6."""
    model, motor, joint = both
    sel = model.info.selection
    names = [c["name"] for c in sel["candidates"]]
    assert "links + viscous + coulomb + at:both" in names
    assert Structure.parse(sel["chosen"]).at == "both", sel["chosen"]
    assert list(model.terms) == ["friction", "joint friction"]
    m, j = model.terms["friction"], model.terms["joint friction"]
    assert j.labels[:2] == ("jfv7", "jfc7") and not any(lab.startswith("jfo") for lab in j.labels)
    np.testing.assert_allclose(m.friction.params[:, :2], motor.params[:, :2], atol=1e-6)
    np.testing.assert_allclose(j.friction.params[6, :2], [JFV, JFC], atol=1e-6)
    assert j.friction.drive is None and m.friction.drive is not None
    assert model.fit.relative_error_percent < 1e-6
    # every consumer takes both: the model's own friction is their sum
    own = own_friction(model)
    assert isinstance(own, FrictionSum) and len(own.parts) == 2
    v = np.random.default_rng(5).uniform(-1, 1, (20, 7))
    np.testing.assert_allclose(own.torques(v), motor.torques(v) + joint.torques(v), atol=1e-6)
    np.testing.assert_allclose(
        own.torques(v), friction_of(m.friction).torques(v) + friction_of(j.friction).torques(v)
    )


def test_both_frictions_are_written_and_read_back(both):
    model, _, _ = both
    d = model_to_dict(model)
    assert d["friction"] is None and [t["name"] for t in d["terms"]] == list(model.terms)
    back = model_from_dict(d)
    for name, t in model.terms.items():
        assert back.terms[name].labels == t.labels
        np.testing.assert_array_equal(back.terms[name].values, t.values)
    v = np.random.default_rng(6).uniform(-1, 1, (5, 7))
    np.testing.assert_array_equal(own_friction(back).torques(v), own_friction(model).torques(v))


def test_the_consistent_fit_keeps_both_dissipative(both):
    """The data term of the consistent fit holds both terms' coefficients and keeps every
    viscous and Coulomb coefficient ``>= 0``."""
    model, _, _ = both
    term = coefficient_term(model, with_friction=True)
    labels = term.labels[term.r :]
    assert labels == model.terms["friction"].labels + ("jfv7", "jfc7")
    assert labels[:4] == ("fv1", "fc1", "fv2", "fc2") and term.nonnegative().all()
    fr = term.frictions(term.x_hat[term.r :])
    assert [f.drive is None for f in fr] == [False, True]


def test_motor_friction_alone_does_not_choose_both(panda):
    """Exact data with friction at the motors only: the friction at the joints adds nothing
    within one standard error, and the simpler placement is kept."""
    logs, motor, _ = _logs(panda, joint_side=False)
    model = identify_recordings(panda, logs, cutoff_hz=None, drive=_drive())
    chosen = Structure.parse(model.info.selection["chosen"])
    assert chosen.at == "motor", model.info.selection["chosen"]
    assert list(model.terms) == ["friction"]
    np.testing.assert_allclose(model.friction.params[:, :2], motor.params[:, :2], atol=1e-6)


def test_the_consistent_result_holds_both_and_exports_them(panda, tmp_path):
    """The one-step consistent fit of exact data with friction on both sides: its friction
    is the sum of both (the truth, to round-off), feasible.json holds the part at the joints
    as ``joint_friction`` and reads back the same sum (on the robot ``load_feasible_json``
    gives too, which predicts the recording's torques), and URDF and MJCF add both to each
    joint's damping and dry friction."""
    logs, motor, joint = _logs(panda, joint_side=True)
    terms = Structure.parse("viscous, coulomb, offset, at:both")
    model = identify_recordings(panda, logs, cutoff_hz=None, drive=_drive(), structure=terms)
    res = consistent_from_identified(panda, model, prior=panda)
    assert isinstance(res.friction, FrictionSum) and res.feasible
    v = np.random.default_rng(7).uniform(-1, 1, (20, 7))
    np.testing.assert_allclose(
        res.friction.torques(v), motor.torques(v) + joint.torques(v), atol=1e-6
    )
    files = save_feasible_bundle(tmp_path, res)
    doc = json.loads((tmp_path / "feasible.json").read_text())
    np.testing.assert_allclose(doc["joint_friction"]["fv"], np.eye(7)[6] * JFV, atol=1e-6)
    back = load_feasible_linear_friction(tmp_path / "feasible.json")
    np.testing.assert_allclose(back.torques(v), res.friction.torques(v), atol=1e-12)
    # the robot read back carries that sum: its torques are the truth's (regression: none)
    robot = load_feasible_json(tmp_path / "feasible.json")
    np.testing.assert_allclose(robot.friction.torques(v), back.torques(v), atol=1e-12)
    log = logs[0]
    drive = load_feasible_drive(tmp_path / "feasible.json")
    tau = dynid.model_torques(robot, log.q, log.dq, log.ddq, drive=drive)
    assert np.linalg.norm(tau - log.tau) <= 1e-6 * np.linalg.norm(log.tau)
    urdf = next(p for p in files if p.suffix == ".urdf").read_text()
    # diag(K^T diag(fv) K) of the motors plus the joint's own: joint 6 feels motor 7 too
    assert _damping(urdf, 5) == pytest.approx(FV[5] + 0.8**2 * FV[6], abs=1e-6)
    assert _damping(urdf, 6) == pytest.approx(FV[6] + JFV, abs=1e-6)


def _damping(urdf: str, j: int) -> float:
    """The ``damping`` of the ``j``-th ``<dynamics>`` of a URDF text (0-based)."""
    return float(re.findall(r'<dynamics damping="([^"]+)"', urdf)[j])


def test_the_observer_takes_both(both, panda):
    """The momentum observer of the model (its friction the sum, evaluated in Python) sees
    no external torque on exact data of the truth; with the motors' friction alone it sees
    the joint's own friction."""
    model, _, _ = both
    log = _logs(panda, joint_side=True)[0][0]
    obs = from_identified(model)
    assert isinstance(obs.friction, FrictionSum)
    opts = ObserverOptions(gain=40.0)
    r = observe(obs, log.t, log.q, log.dq, log.tau, opts).r[200:]
    motor_only = obs.with_friction(friction_of(model.terms["friction"].friction))
    r_motor = observe(motor_only, log.t, log.q, log.dq, log.tau, opts).r[200:]
    assert np.abs(r).max() < 1e-3 < 0.1 < np.abs(r_motor[:, 6]).max()


def test_the_report_shows_both_frictions(both, tmp_path):
    """identification.json of an ``at:both`` model has no top-level ``friction`` (null): the
    HTML report reads its ``terms`` and shows a table for the friction at the motors and one
    for the friction at the joints, each value that of the model with its std."""
    from html.parser import HTMLParser

    from dynid.io.model_json import save_model_json
    from dynid.report import RunSummary, render_html_report

    model, _, _ = both
    p = save_model_json(tmp_path / "identification.json", model)
    page = render_html_report(RunSummary(command="identify"), {p.name: p}, out=tmp_path)

    class Tables(HTMLParser):
        def __init__(self) -> None:
            super().__init__(convert_charrefs=True)
            self.rows: list[list[str]] = []
            self.headings: list[str] = []
            self._h2 = False

        def handle_starttag(self, tag, attrs):
            self._h2 = tag == "h2"
            if tag == "tr":
                self.rows.append([])
            elif tag in ("td", "th"):
                self.rows[-1].append("")

        def handle_data(self, data):
            if self._h2:
                self.headings.append(data)
            elif self.rows and self.rows[-1]:
                self.rows[-1][-1] += data

        def handle_endtag(self, tag):
            self._h2 = False if tag == "h2" else self._h2

    t = Tables()
    t.feed(page)
    assert any("at the motors" in h for h in t.headings), t.headings
    assert any("at the joints" in h for h in t.headings), t.headings
    joint = model.terms["joint friction"]
    header = next(r for r in t.rows if r and r[0] == "joint" and "jfv [N m s/rad]" in r)
    row7 = next(r for r in t.rows if len(r) == len(header) and r[0].endswith("joint7"))
    fv = float(row7[header.index("jfv [N m s/rad]")].split("\u00b1")[0])
    assert fv == pytest.approx(joint.values[0], rel=1e-3) and fv == pytest.approx(JFV, abs=1e-3)
    motors = [r for r in t.rows if r and r[0].startswith("motor ")]
    assert len(motors) == 7  # fv, fc at each motor


def test_friction_selection_judges_the_sum_on_held_out_data(both, panda, tmp_path):
    """``dynid friction`` on the recordings the at:both model was identified from: its own
    friction (the sum) is a candidate, refitted part by part on the other recording (exact
    data: held-out error at round-off, below every single law, which cannot hold friction
    at the motors and at joint 7 at once). Regression: the sum was chosen but
    friction.json held the best single law at the motors, losing the joints' friction (a
    coupled wrist's bearing friction validated at 6 times its noise); it is now kept and
    written part by part, and reads back with the same torques."""
    from dynid.friction.recordings import pieces_residual, prepare_pieces
    from dynid.friction.select import OWN, select_friction
    from dynid.io.friction_json import load_friction_json, save_friction_json

    model, _, _ = both
    logs = _logs(panda, joint_side=True)[0]
    pieces = prepare_pieces(model, logs, ["a.csv", "b.csv"], cutoff_hz=None, max_gap_s=None)
    res = pieces_residual(model, pieces)
    own = own_friction(model)
    sel = select_friction(res, pieces.drive, own=own, own_fitted_here=True)
    scores = {s.name: s for s in sel.scores}
    assert sel.chosen == OWN and sel.scores[-1].name == OWN
    assert scores[OWN].heldout_error_percent < 1e-6
    assert min(s.heldout_error_percent for s in sel.scores if s.name != OWN) > 1e-3
    assert sel.fit.friction is own
    assert any(p.endswith("@joints") for p in scores[OWN].params)
    back = load_friction_json(save_friction_json(tmp_path / "friction.json", sel.fit))
    assert isinstance(back, FrictionSum) and back.kind == own.kind
    dq = np.random.default_rng(5).uniform(-2, 2, (40, 7))
    np.testing.assert_allclose(back.torques(dq), own.torques(dq), rtol=1e-12, atol=1e-12)


def test_a_part_left_out_at_the_motors_stays_named_while_the_joints_hold_it():
    """The per-joint search leaving out viscous friction at every motor of an ``at:both``
    model: the joints still hold ``jfv7``, so the name keeps ``viscous`` and its left-out
    coefficients (it read ``links + coulomb + offset + at:both``, which drops ``jfv7``);
    left out at joint 7 as well, viscous goes from the name."""
    motors = "".join(f", -fv{j}" for j in range(1, 8))
    s = Structure.parse("viscous, coulomb, offset, at:both" + motors)
    kept = s.collapsed(7, joint_side_joints(_drive()))
    assert kept == s and "viscous" in kept.name and " - fv7" in kept.name
    assert kept.joint_mask(7, (6,))[2 * 6]  # jfv7 held (joint by joint: jfv, jfc)
    assert s.collapsed(7) == s  # the joints unknown: nothing at both places is removed
    gone = Structure.parse("viscous, coulomb, offset, at:both, -jfv7" + motors)
    assert gone.collapsed(7, (6,)) == Structure.parse("coulomb, offset, at:both")


def test_a_feasible_json_as_robot_brings_its_drive_and_identified_friction(panda, tmp_path):
    """``validate --robot feasible.json`` reads the file's drive (its rotor inertias) and
    the friction identified with the links, as ``--params feasible.json`` does: both give
    the same errors on a recording (before, the robot kept the input's sigmoid and no
    drive, so motor-side data were read as joint angles)."""
    logs, _, _ = _logs(panda, joint_side=False)
    terms = Structure.parse("viscous, coulomb, offset")
    model = identify_recordings(panda, logs, cutoff_hz=None, drive=_drive(), structure=terms)
    res = consistent_from_identified(panda, model, prior=panda)
    save_feasible_bundle(tmp_path, res)
    save_torque_log(tmp_path / "rec.csv", logs[1])
    got = {}
    for how in ("--robot", "--params"):
        out = tmp_path / how.strip("-")
        argv = ["validate", how, str(tmp_path / "feasible.json"), "--data"]
        argv += [str(tmp_path / "rec.csv"), "--out", str(out), "--no-figures", "-q"]
        assert main(argv) == 0
        got[how] = json.loads((out / "validation.json").read_text())["relative_error_percent"]
    assert got["--robot"] == pytest.approx(got["--params"], rel=1e-9)
    assert got["--robot"] < 0.5


def test_validate_refuses_a_drive_other_than_the_one_feasible_json_holds(panda, tmp_path):
    """``validate --params feasible.json --drive other.toml``: the file's drive (its rotor
    inertias identified with the links) was replaced silently by the one given (a trial:
    0.705 % -> 4.94 % without a word); now one line names the file and what differs."""
    logs, _, _ = _logs(panda, joint_side=False)
    terms = Structure.parse("viscous, coulomb, offset")
    model = identify_recordings(panda, logs, cutoff_hz=None, drive=_drive(), structure=terms)
    save_feasible_bundle(tmp_path, consistent_from_identified(panda, model, prior=panda))
    save_torque_log(tmp_path / "rec.csv", logs[1])
    (tmp_path / "other.toml").write_text(
        'schema = "dynid-drive/1"\nside = "joint"\ngear_ratio = [1, 1, 1, 1, 1, 1, 1]\n'
    )
    argv = ["validate", "--params", str(tmp_path / "feasible.json"), "--data"]
    argv += [str(tmp_path / "rec.csv"), "--drive", str(tmp_path / "other.toml")]
    err = io.StringIO()
    with contextlib.redirect_stderr(err):
        code = main([*argv, "--out", str(tmp_path / "v"), "--no-figures"])
    lines = [s for s in err.getvalue().splitlines() if s.strip()]
    assert code == 2 and len(lines) == 1, lines
    assert "differs from the one feasible.json holds: friction_at" in lines[0]
    assert not (tmp_path / "v").exists()


def test_the_summary_says_which_joints_friction_the_motors_hold(both):
    """The summary's table of the friction at the joints: joints 1-6, each turned by one
    motor alone (:func:`joint_side_joints`), read "motor's" with one line saying their
    friction at the joint is identified in the motor's; they read "-" (left out), and a
    user holding a datasheet read the motor's Coulomb 35 % high. Joint 7 holds its own."""
    from dynid.cli.summaries import term_lines

    model, _, _ = both
    lines = term_lines(model)
    at = next(k for k, x in enumerate(lines) if x.startswith("joint friction identified"))
    rows = {int(r.split()[0]): r.split()[1:] for r in lines[at + 2 : at + 9]}
    assert all(rows[j][:2] == ["motor's", "motor's"] for j in range(1, 7)), rows
    assert rows[7][0] != "motor's"
    said = lines[at + 9]
    assert said.startswith("  motor's: a motor turns joint(s) 1, 2, 3, 4, 5, 6 alone")
