"""The force of a point contact at a frame (``external_wrench(kind="force")``, ``dynid
observe --wrench force``) against independent references: forces pushed through
Pinocchio's Jacobians of the Panda and of a 5-joint arm, the closed-form least-squares
force of a wrench with a moment, and a contact simulated by ``dynid simulate --contact``."""

from __future__ import annotations

import dataclasses
import json
import re

import numpy as np
import pytest

import dynid
from dynid.cli.__main__ import main
from dynid.io.robot.urdf import save_urdf
from dynid.observer.wrench import (
    FORCE,
    FULL,
    chain_length,
    estimate_words,
    external_wrench,
    underdetermined_note,
)

from conftest import pinocchio_panda_urdf, random_states

#: A push at the 5-joint arm's flange [N] (base axes) and its window [s].
PUSH, PUSH_S = (3.0, -2.0, -4.0), (2.0, 2.6)


def arm5() -> dynid.Robot:
    """A 5R arm of a tabletop arm's proportions (a pan, three pitch joints, a roll) whose
    flange is off the roll axis: a chain of 0.40 m."""
    h = np.pi / 2
    inertia = [np.eye(3) * v for v in (4e-4, 8e-4, 6e-4, 2e-4, 1e-4)]
    return dynid.Robot.from_mdh(
        a=[0.0, 0.03, 0.11, 0.13, 0.0],
        d=[0.1, 0.0, 0.0, 0.0, 0.05],
        alpha=[0.0, -h, 0.0, 0.0, h],
        flange=(0.02, 0.08, 0.0, 0.0),
        mass=[0.4, 0.3, 0.25, 0.12, 0.1],
        com=[[0, 0, -0.03], [0.05, 0, 0], [0.06, 0, 0], [0.03, 0, 0], [0, 0, 0.03]],
        inertia=inertia,
        q_min=[-2.5] * 5,
        q_max=[2.5] * 5,
        dq_max=[3.0] * 5,
        tau_max=[5.0] * 5,
        name="arm5",
    )


def _pin_jacobians(urdf: str, frame: str, q: np.ndarray, lock: tuple[str, ...] = ()):
    """Pinocchio's Jacobians (S, 6, n) of ``frame`` (rows v, w; base axes, at its origin)."""
    pin = pytest.importorskip("pinocchio")
    model = pin.buildModelFromUrdf(urdf)
    if lock:
        model = pin.buildReducedModel(
            model, [model.getJointId(j) for j in lock], pin.neutral(model)
        )
    data, fid = model.createData(), model.getFrameId(frame)
    out = []
    for qs in q:
        pin.computeJointJacobians(model, data, qs)
        pin.updateFramePlacements(model, data)
        out.append(pin.getFrameJacobian(model, data, fid, pin.LOCAL_WORLD_ALIGNED))
    return np.array(out)


@pytest.fixture(scope="module")
def arm5_urdf(tmp_path_factory):
    path = tmp_path_factory.mktemp("arm5") / "arm5.urdf"
    save_urdf(path, arm5())
    return path


def _panda_flange(q: np.ndarray) -> np.ndarray:
    fingers = ("panda_finger_joint1", "panda_finger_joint2")
    return _pin_jacobians(pinocchio_panda_urdf(), "panda_link8", q, fingers)


def test_force_at_the_panda_flange_is_recovered_through_pinocchios_jacobian():
    """tau = J_v^T f with Pinocchio's J_v of the flange (7 joints): the force back to
    round-off where not damped, the moment exactly 0, 3 components determined, and
    sigma_min the third singular value of J_v / L."""
    robot = dynid.panda()
    q, _, _ = random_states(robot, 30, seed=40)
    f = np.random.default_rng(41).normal(size=(30, 3)) * 10.0
    Jv = _panda_flange(q)[:, :3]
    r = (np.swapaxes(Jv, -1, -2) @ f[..., None])[..., 0]
    est = external_wrench(robot, q, r, "flange", kind="force")
    assert est.kind is FORCE and est.determined == 3
    ok = ~est.damped
    assert ok.sum() >= 25
    np.testing.assert_allclose(est.wrench[ok, :3], f[ok], rtol=0, atol=1e-9)
    assert np.all(est.wrench[:, 3:] == 0.0)
    s = np.linalg.svd(Jv / chain_length(robot, "flange"), compute_uv=False)
    np.testing.assert_allclose(est.sigma_min, s[:, 2], rtol=1e-10)


def test_force_at_a_5_joint_arm_is_recovered_where_the_full_wrench_is_not(arm5_urdf):
    """Regression (a 5-joint arm: a push at its gripper read with spurious moments and a
    wrong force by the least-norm wrench): tau = J_v^T f with Pinocchio's Jacobian of
    the arm's URDF gives the force back to round-off; the full estimate misses it."""
    robot = arm5()
    q = np.random.default_rng(42).uniform(-2.5, 2.5, (40, 5))
    f = np.random.default_rng(43).normal(size=(40, 3)) * 5.0
    Jv = _pin_jacobians(str(arm5_urdf), "flange", q)[:, :3]
    r = (np.swapaxes(Jv, -1, -2) @ f[..., None])[..., 0]
    est = external_wrench(robot, q, r, "flange", kind="force")
    ok = ~est.damped
    assert ok.sum() >= 30
    np.testing.assert_allclose(est.wrench[ok, :3], f[ok], rtol=0, atol=1e-9)
    full = external_wrench(robot, q, r, "flange")
    assert full.determined == 5 and full.kind is FULL
    err = np.linalg.norm(full.wrench[ok, :3] - f[ok], axis=1) / np.linalg.norm(f[ok], axis=1)
    assert np.median(err) > 0.1  # the least-norm wrench puts part of the force in a moment
    assert np.median(np.linalg.norm(full.wrench[ok, 3:], axis=1)) > 0.05


def test_force_estimate_flags_and_damps_by_its_own_rank(arm5_urdf):
    """The force's flag is its own: sigma_min the third singular value of Pinocchio's
    J_v / L, damped exactly where it is under epsilon (not where the 5 joints lose a
    wrench direction), and a damped force never longer than the true one (the damping
    only shrinks it)."""
    robot = arm5()
    q = np.random.default_rng(44).uniform(-2.5, 2.5, (400, 5))
    f = np.random.default_rng(45).normal(size=(400, 3)) * 5.0
    Jv = _pin_jacobians(str(arm5_urdf), "flange", q)[:, :3]
    r = (np.swapaxes(Jv, -1, -2) @ f[..., None])[..., 0]
    est = external_wrench(robot, q, r, "flange", kind="force", epsilon=0.05)
    s3 = np.linalg.svd(Jv / chain_length(robot, "flange"), compute_uv=False)[:, 2]
    np.testing.assert_allclose(est.sigma_min, s3, rtol=1e-9, atol=1e-12)
    np.testing.assert_array_equal(est.damped, s3 < 0.05)
    assert 0 < est.damped.sum() < 100
    full = external_wrench(robot, q, r, "flange")
    assert not np.array_equal(est.damped, full.damped)
    d = est.damped
    lengths = np.linalg.norm(est.wrench[d, :3], axis=1)
    assert np.all(lengths <= np.linalg.norm(f[d], axis=1) + 1e-12)


def test_force_estimate_of_a_wrench_with_a_moment_is_its_least_squares_force():
    """The limit (documented): a wrench with a 1 N m moment at the Panda's flange, tau =
    J^T w (Pinocchio), is read as the force that best explains tau, the closed form
    (J_v J_v^T)^-1 J_v tau, off the true force; the full estimate recovers it."""
    robot = dynid.panda()
    q, _, _ = random_states(robot, 30, seed=46)
    w = np.tile([5.0, 0.0, -10.0, 0.0, 1.0, 0.0], (30, 1))
    J = _panda_flange(q)
    r = (np.swapaxes(J, -1, -2) @ w[..., None])[..., 0]
    est = external_wrench(robot, q, r, "flange", kind="force")
    ok = ~est.damped
    assert ok.sum() >= 25
    Jv = J[:, :3]
    ref = np.linalg.solve(Jv @ np.swapaxes(Jv, -1, -2), (Jv @ r[..., None]))[..., 0]
    np.testing.assert_allclose(est.wrench[ok, :3], ref[ok], rtol=0, atol=1e-9)
    assert np.median(np.linalg.norm(ref - w[:, :3], axis=1)) > 1.0
    full = external_wrench(robot, q, r, "flange")
    np.testing.assert_allclose(full.wrench[~full.damped], w[~full.damped], rtol=0, atol=1e-8)


def test_notes_and_words_say_what_the_joints_determine():
    """At the 5-joint flange the wrench's note points to the force, which needs none; at
    a frame 2 joints move the force too is the least-norm one; the words name what was
    estimated."""
    robot = arm5()
    full = underdetermined_note(robot, "flange")
    assert full is not None and "5 of the 6 wrench components" in full
    assert full.endswith("is determined: --wrench force")
    assert underdetermined_note(robot, "flange", "force") is None
    two = underdetermined_note(robot, "link2", "force")  # its origin on joint 2's axis
    assert two is not None and "1 of the 3 force components" in two and "--wrench" not in two
    assert "the 2 joints moving link2 determine (structurally" in two
    words = estimate_words(robot, "flange", "force")
    assert words.startswith("the force of a point contact (moment zero) at flange's origin")
    assert "3 components from 5 joints" in words
    assert "5 determined, the least-norm estimate" in estimate_words(robot, "flange")
    with pytest.raises(dynid.OptionError, match="wrench must be one of full, force; got 'torque'"):
        external_wrench(robot, np.zeros(5), np.zeros(5), "flange", kind="torque")


@pytest.fixture(scope="module")
def observed(tmp_path_factory, arm5_urdf):
    """The 5-joint arm: a free log and a pushed one (dynid simulate, 500 Hz), thresholds
    from the free one, and the pushed one observed at the flange with each --wrench."""
    d = tmp_path_factory.mktemp("observe_force")
    sim = ["simulate", "--robot", str(arm5_urdf), "--trajectory", "fourier", "--duration", "4"]
    sim += ["--rate", "500", "--noise", "0.005", "-q"]
    push = f"flange:{','.join(map(str, PUSH))}:{PUSH_S[0]},{PUSH_S[1]}"
    assert main([*sim, "--seed", "1", "--out", str(d / "free.csv")]) == 0
    assert main([*sim, "--seed", "2", "--contact", push, "--out", str(d / "hit.csv")]) == 0
    obs = ["observe", "--params", str(arm5_urdf), "--no-figures"]
    assert (
        main([*obs, "--data", str(d / "free.csv"), "--calibrate", "-q", "--out", str(d / "cal")])
        == 0
    )
    obs += ["--thresholds", str(d / "cal" / "thresholds.json"), "--data", str(d / "hit.csv")]
    for kind in ("full", "force"):
        argv = [*obs, "--frame", "flange", "--wrench", kind, "--out", str(d / kind)]
        assert main(argv) == 0
    return d


def _push_rows(path):
    table = np.loadtxt(path, delimiter=",", comments="#", skiprows=3)
    t = table[:, 0]
    on = (t > PUSH_S[0] + 0.1) & (t < PUSH_S[1] - 0.05)  # past the observer's lag
    return table[on, 6:9], table[on, 9:12], table[on, 12]


def test_observe_wrench_force_reads_a_simulated_push_on_a_5_joint_arm(observed):
    """dynid observe --frame flange --wrench force on the simulated push: its force within
    0.2 N of the true one on every sample past the lag (torque noise 0.005 N m), the
    moment columns 0, none damped; the default full wrench reads it more than 1 N off."""
    force, moment, damped = _push_rows(observed / "force" / "residuals.csv")
    assert np.abs(force - PUSH).max() < 0.2
    assert np.all(moment == 0.0) and not damped.any()
    full, _, _ = _push_rows(observed / "full" / "residuals.csv")
    assert np.median(np.linalg.norm(full - PUSH, axis=1)) > 1.0


def test_observe_says_which_estimate_it_wrote(observed):
    """The units line of residuals.csv, events.json's wrench and the summary in
    report.html each say whether the wrench or the force alone was estimated."""
    for kind, words in (("force", "the force of a point contact"), ("full", "the wrench")):
        head = (observed / kind / "residuals.csv").read_text().splitlines()[0]
        assert f"(--wrench {kind})" in head
        doc = json.loads((observed / kind / "events.json").read_text())
        assert doc["wrench"] == {
            "frame": "flange",
            "estimate": kind,
            "components": 3 if kind == "force" else 6,
            "determined": 3 if kind == "force" else 5,
        }
        page = re.sub(r"<[^>]+>", "", (observed / kind / "report.html").read_text())
        assert f"estimated (fx..mz of the residual tables): {words}" in page


def test_observe_wrench_needs_a_frame(tmp_path, capsys):
    """--wrench force without --frame is refused, naming both flags."""
    argv = ["observe", "--params", "panda", "--thresholds", str(tmp_path / "t.json")]
    argv += ["--wrench", "force", "--data", str(tmp_path / "x.csv"), "--out", str(tmp_path / "o")]
    assert main(argv) == 2
    (line,) = capsys.readouterr().err.strip().splitlines()
    assert "--wrench says what is estimated at --frame; give the frame" in line


def test_observe_files_takes_the_estimate_as_an_option(observed, arm5_urdf):
    """The Python API as the command: ObserveOptions(wrench="force") gives a result and a
    kept wrench series that say FORCE, the series equal to residuals.csv's columns; a
    wrench without a frame is an OptionError naming its field."""
    from dynid.workflows.observe import ObserveOptions, observe_files

    opts = ObserveOptions(
        data=(observed / "hit.csv",),
        params=str(arm5_urdf),
        thresholds=observed / "cal" / "thresholds.json",
        frame="flange",
        wrench="force",
    )
    result = observe_files(opts)
    (log,) = result.logs
    assert result.wrench is FORCE and log.wrench is not None and log.wrench.kind is FORCE
    table = np.loadtxt(observed / "force" / "residuals.csv", delimiter=",", skiprows=3)
    np.testing.assert_allclose(log.wrench.wrench, table[:, 6:12], rtol=1e-12, atol=1e-12)
    with pytest.raises(dynid.OptionError) as err:
        observe_files(dataclasses.replace(opts, frame=None))
    assert err.value.field == "wrench"


def test_structural_rank_at_the_panda_link4_is_pinocchios_and_the_fit_leaves_what_it_misses():
    """The force at the Panda's link4 origin (on joint 4's axis): Pinocchio's linear
    Jacobian rows have rank 2 at random poses, and so does the estimate (the note says
    2 of 3, structurally); a force there is explained whole (nothing left), while at
    the flange what the wrench leaves of its torques is Pinocchio's least-squares
    residual of J_flange^T w = r."""
    from dynid.observer.wrench import structural_rank

    robot = dynid.panda()
    q, *_ = random_states(robot, 5, seed=4)
    fingers = ("panda_finger_joint1", "panda_finger_joint2")
    J4 = _pin_jacobians(pinocchio_panda_urdf(), "panda_link4", q, fingers)
    assert {int(np.linalg.matrix_rank(J[:3], tol=1e-9)) for J in J4} == {2}
    assert structural_rank(robot, "link4", FORCE) == 2
    note = underdetermined_note(robot, "link4", "force")
    assert note is not None and "only 2 of the 3 force components" in note
    f = np.array([0.0, 50.0, 0.0])
    r = np.einsum("sji,j->si", J4[:, :3], f)
    est = external_wrench(robot, q, r, "link4", kind="force")
    assert est.unexplained is not None and np.all(est.unexplained < 1e-18 * np.sum(r**2, axis=1))
    JF = _panda_flange(q)
    full = external_wrench(robot, q, r, "flange")
    assert not full.damped.all()
    for k in range(q.shape[0]):
        w, *_ = np.linalg.lstsq(JF[k].T, r[k], rcond=None)
        left = float(np.sum((r[k] - JF[k].T @ w) ** 2))
        if not full.damped[k]:
            assert full.unexplained is not None
            assert full.unexplained[k] == pytest.approx(left, rel=1e-6, abs=1e-12)
