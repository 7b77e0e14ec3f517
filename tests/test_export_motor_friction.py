"""Friction at the motors of a geared or coupled drive as the URDF and MJCF exports write it.

A law at the motors acts at the motors' velocities, ``K dq`` (gear ratio times the joint's):
the viscous and Coulomb friction a joint of the file holds is its reflection through the
drive (``G^2 fv``, ``G fc`` for a diagonal drive), fitted to the law where it acts.
References: the closed-form joint torque ``G fv G dq + G fc tanh(G dq / v_s)`` fitted by
scipy's NNLS at the joints, MuJoCo's compiled model, Pinocchio-style reading of the URDF
(:func:`dynid.io.robot.urdf.load_urdf`) and the torques of a simulated geared arm.
"""

from __future__ import annotations

import re
import warnings

import mujoco
import numpy as np
import pytest
from scipy.optimize import nnls

from dynid.exceptions import DynidWarning
from dynid.friction.laws import law_named
from dynid.friction.model import ClassicalFriction
from dynid.friction.mujoco import coupled_coulomb_left_out
from dynid.friction.validation import validate_torques
from dynid.io.robot.export_options import ExportOptions
from dynid.io.robot.mjcf import mjcf_from_robot
from dynid.io.robot.urdf import export_urdf, load_urdf
from dynid.model.drive import Drive
from dynid.simulation.measurement import SensorNoise

from conftest import planar_2r, recordings

G = 100.0  # gear ratio
FV_M, FC_M = np.array([2e-5, 1.5e-5]), np.array([4e-3, 3e-3])  # at the motors: N m s/rad, N m
VS_M = np.array([1.0, 1.5])  # the smooth law's width at the motors [rad/s]
DQ_MAX = np.array([2.5, 2.5])  # the joints' velocity limits [rad/s]


def _arm():
    return planar_2r().replace(q_min=-DQ_MAX, q_max=DQ_MAX, dq_max=DQ_MAX, ddq_max=4 * DQ_MAX)


def _motor_law(vs=VS_M, drive=None):
    """The smooth law ``fv v + fc tanh(v / v_s)`` at the motors of a gear-G drive."""
    drive = drive or Drive.from_gears([G, G], side="joint", friction_at="motor")
    return law_named("smooth").model(np.column_stack([FV_M, FC_M, 0 * FV_M]), vs).at(drive)


def _joint_fit(vs):
    """The nonnegative ``fv dq + fc sign(dq)`` closest (scipy's NNLS) to the law's joint
    torque ``G fv G dq + G fc tanh(G dq / v_s)`` over ``(0, dq_max]``, and its RMS [N m]."""
    out = []
    for j in range(2):
        v = np.linspace(0.0, DQ_MAX[j], 201)[1:]
        tau = G * FV_M[j] * G * v + G * FC_M[j] * np.tanh(G * v / vs[j])
        x, res = nnls(np.column_stack([v, np.ones_like(v)]), tau)
        out.append((x[0], x[1], res / np.sqrt(v.size)))
    return np.array(out).T  # (3, 2): damping, friction, rms


def _warnings(fn, *args, **kw):
    with warnings.catch_warnings(record=True) as got:
        warnings.simplefilter("always")
        out = fn(*args, **kw)
    return out, [str(w.message) for w in got if issubclass(w.category, DynidWarning)]


def test_urdf_and_mjcf_hold_motor_friction_reflected_through_the_gears(tmp_path):
    """Regression: a smooth law at the motors was fitted over the joints' velocity range
    (10 rad/s for motors turning 3450 rad/s), so the SO-101's shoulder read damping 1.80
    and friction 0.051 instead of 0.208 and 0.084 (345^2 fv, 345 fc). Now the URDF and
    the URDF holds the law's reflection, the NNLS fit of the joint torque over the joint's
    range, within 1 % of G^2 fv and G fc; MuJoCo's compiled MJCF, whose dry friction is a
    ramp that holds the rounding, exactly G^2 fv and G fc."""
    law = _motor_law()
    damping, friction, _ = _joint_fit(VS_M)
    path, lines = _warnings(export_urdf, tmp_path / "r.urdf", _arm(), ExportOptions(friction=law))
    back = load_urdf(path).friction
    np.testing.assert_allclose(back.fv, damping, rtol=1e-9)
    np.testing.assert_allclose(back.fc, friction, rtol=1e-9)
    np.testing.assert_allclose(back.fv, G**2 * FV_M, rtol=1e-2)
    np.testing.assert_allclose(back.fc, G * FC_M, rtol=1e-2)
    assert len(lines) == 1 and "friction at the motors" in lines[0], lines
    (text, _), mj_lines = _warnings(mjcf_from_robot, _arm(), friction=law)
    model = mujoco.MjModel.from_xml_string(text)
    np.testing.assert_allclose(model.dof_damping, G**2 * FV_M, rtol=1e-9)
    np.testing.assert_allclose(model.dof_frictionloss, G * FC_M, rtol=1e-9)
    assert len(mj_lines) == 1 and "friction at the motors" in mj_lines[0], mj_lines


def test_a_sigmoid_at_the_motors_is_fitted_over_the_motors_velocities(tmp_path):
    """Gaz et al.'s sigmoid (eq. 25) at the motors of a gear-100 drive: the URDF holds the
    NNLS fit of its joint torque's odd part, ``G (s(G dq) - s(-G dq)) / 2``, over the
    joint's range (closed form here); the fit over the motors' first 2.5 rad/s had written
    joint 1's damping 14.3 for 0.0008."""
    P = np.array([[8e-3, 2.0, 0.1], [6e-3, 1.5, -0.2]])  # phi1 [N m], phi2 [s/rad], phi3 [rad/s]
    drive = Drive.from_gears([G, G], side="joint", friction_at="motor")
    law = law_named("sigmoid").model(P).at(drive)

    def s(v, p):
        return p[0] / (1 + np.exp(-p[1] * (v + p[2]))) - p[0] / (1 + np.exp(-p[1] * p[2]))

    path, _ = _warnings(export_urdf, tmp_path / "r.urdf", _arm(), ExportOptions(friction=law))
    back = load_urdf(path).friction
    for j in range(2):
        v = np.linspace(0.0, DQ_MAX[j], 201)[1:]
        odd = G * (s(G * v, P[j]) - s(-G * v, P[j])) / 2
        x, _ = nnls(np.column_stack([v, np.ones_like(v)]), odd)
        np.testing.assert_allclose([back.fv[j], back.fc[j]], x, rtol=1e-7, atol=1e-12)


def test_the_exported_urdf_predicts_a_geared_arm_as_the_model_does(tmp_path):
    """A planar arm with gear-100 drives and smooth friction at the motors, simulated with
    sensor noise: the URDF read back (friction at the joints) predicts the torques within
    0.15 % (points) of the model's own error (0.23 %, against 3.7 % without friction; the
    sharp sign written misses the law's rounding over about 0.01 rad/s at the joints). The
    terms fitted over the joints' range had given 75 %."""
    law = _motor_law()
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", DynidWarning)
        path = export_urdf(tmp_path / "r.urdf", _arm(), ExportOptions(friction=law))
        urdf = load_urdf(path).replace(gravity=_arm().gravity)  # URDF holds no gravity
    (log,) = recordings(_arm(), [7], friction=law, duration=6.0, noise=SensorNoise(tau_std=0.02))
    floor = validate_torques(_arm(), log, friction=None, cutoff_hz=20.0)
    model = validate_torques(_arm(), log, friction=law, cutoff_hz=20.0)
    written = validate_torques(urdf, log, friction=urdf.friction, cutoff_hz=20.0)
    e_model = model.errors.relative_error_percent
    e_urdf = written.errors.relative_error_percent
    assert floor.errors.relative_error_percent > 3 * e_model  # friction matters here
    assert abs(e_urdf - e_model) < 0.15, (e_urdf, e_model)


def test_the_rms_difference_said_is_at_the_joints_over_their_range(tmp_path):
    """A smooth law at the motors whose width is a fifth of the motors' range: the warning's
    RMS difference is the joint torque's, G times the motors', over the joint's range
    (the NNLS fit's residual at the joints, to the 3 digits printed); the export used to
    print the motors' RMS over the joints' range (4.5e-05 N m where the written terms
    missed the shoulder's friction by 9 N m)."""
    wide = 0.2 * G * DQ_MAX
    law = _motor_law(vs=wide)
    _, _, rms = _joint_fit(wide)
    path, lines = _warnings(export_urdf, tmp_path / "r.urdf", _arm(), ExportOptions(friction=law))
    said = re.search(
        r"RMS difference at the joints up to ([0-9.e+-]+) N m, at joint (\d)", lines[0]
    )
    assert said is not None, lines
    j = int(np.argmax(rms))
    assert int(said.group(2)) == j + 1
    assert float(said.group(1)) == pytest.approx(rms[j], rel=5e-3)


def test_coupled_motor_friction_is_written_on_the_diagonal_and_the_rest_is_named(tmp_path):
    """A coupled wrist (motor 2 turned by joint 1 as well, K_21 = 30) with classical
    friction at its motors: URDF and MJCF hold diag(K^T diag(fv) K) and |K_jj| fc_j, and
    the warning names the viscous coupling dropped (K_21 K_22 fv_2) and the Coulomb friction
    of motor 2 on joint 1 (|K_21| fc_2) and on joint 2, whose motor's sign follows
    30 dq1 + G dq2 rather than dq2 (2 G fc_2), which no per-joint term holds; the warning
    used to name joint 1 alone, with the smaller number."""
    drive = Drive.from_gears([G, G], [(2, 1, 30.0)], side="joint", friction_at="motor")
    law = ClassicalFriction(FV_M, FC_M, 0 * FV_M).at(drive)
    K = drive.transmission
    path, lines = _warnings(export_urdf, tmp_path / "r.urdf", _arm(), ExportOptions(friction=law))
    back = load_urdf(path).friction
    np.testing.assert_allclose(back.fv, [G**2 * FV_M[0] + 30.0**2 * FV_M[1], G**2 * FV_M[1]])
    np.testing.assert_allclose(back.fc, np.abs(np.diag(K)) * FC_M)
    assert len(lines) == 1, lines
    assert f"largest: joints 1-2, {30.0 * G * FV_M[1]:.4g}" in lines[0], lines[0]
    said = f"up to {2 * G * FC_M[1]:.4g} N m at joint 2, {30.0 * FC_M[1]:.4g} N m at joint 1"
    assert said in lines[0], lines[0]
    assert "motor 2 turning at 30 dq1 + 100 dq2" in lines[0], lines[0]
    (text, _), mj_lines = _warnings(mjcf_from_robot, _arm(), friction=law)
    model = mujoco.MjModel.from_xml_string(text)
    np.testing.assert_allclose(model.dof_damping, back.fv, rtol=1e-12)
    np.testing.assert_allclose(model.dof_frictionloss, back.fc, rtol=1e-12)
    assert "Coulomb friction of coupled motors" in mj_lines[0], mj_lines


def _wrist_drive_K():
    """The transmission of a UR5-like arm with a coupled wrist: gears 120/120/100/80/60/50,
    motor 6 also turned by joint 5 with ratio 30."""
    K = np.diag([120.0, 120.0, 100.0, 80.0, 60.0, 50.0])
    K[5, 4] = 30.0
    return K


def test_coupled_coulomb_left_out_is_the_largest_difference_over_velocities():
    """Regression (a coupled wrist's export warned of 0.36 N m at joint 5 where joint 6
    missed 1.2 N m): the bound equals the largest |K^T (fc sign(K dq)) - |K_jj| fc_j
    sign(dq_j)| over velocities within 3.15 rad/s, computed directly with numpy."""
    rng = np.random.default_rng(46)
    K = _wrist_drive_K()
    fc = np.array([0.06, 0.06, 0.045, 0.02, 0.015, 0.012])
    dq = rng.choice([-1.0, 1.0], (20000, 6)) * 3.15 * 10 ** rng.uniform(-3, 0, (20000, 6))
    full = np.sign(dq @ K.T) * fc @ K
    diag = np.abs(np.diag(K)) * fc * np.sign(dq)
    direct = np.abs(full - diag).max(axis=0)
    bound = coupled_coulomb_left_out(K, fc)
    np.testing.assert_allclose(bound, direct, rtol=1e-12, atol=1e-15)
    np.testing.assert_allclose(bound[4:], [30 * fc[5], 2 * 50 * fc[5]], rtol=1e-12)
    assert not np.any(coupled_coulomb_left_out(np.diag(np.diag(K)), fc))


def test_a_coupled_smooth_law_says_its_rounding_and_its_coupling_apart(tmp_path):
    """A smooth law at the motors of a coupled drive (motor 2 turned by joint 1, K_21 = 30):
    the refit's RMS difference is each joint's own motor's law against its reflection of
    the terms fitted per motor (scipy's NNLS over the motor's range), no longer joint 1
    moving alone turning motor 2 too; the coupling is said on its own, 2 |K_22| fc_2 at joint 2 and
    |K_21| fc_2 at joint 1 from the Coulomb friction read back from the URDF."""
    wide = 0.2 * G * DQ_MAX
    drive = Drive.from_gears([G, G], [(2, 1, 30.0)], side="joint", friction_at="motor")
    law = _motor_law(vs=wide, drive=drive)
    rms = np.zeros(2)
    for j, top in enumerate(np.abs(drive.transmission) @ DQ_MAX):  # each motor's range
        u = np.linspace(0.0, top, 201)[1:]
        (fv, fc), _ = nnls(
            np.column_stack([u, np.ones_like(u)]), FV_M[j] * u + FC_M[j] * np.tanh(u / wide[j])
        )
        v = np.linspace(0.0, DQ_MAX[j], 201)[1:]
        own = G * (FV_M[j] * G * v + FC_M[j] * np.tanh(G * v / wide[j]))
        rms[j] = np.sqrt(np.mean((own - G * G * fv * v - G * fc) ** 2))
    path, lines = _warnings(export_urdf, tmp_path / "r.urdf", _arm(), ExportOptions(friction=law))
    said = re.search(
        r"RMS difference at the joints up to ([0-9.e+-]+) N m, at joint (\d)", lines[0]
    )
    assert said is not None, lines
    assert int(said.group(2)) == int(np.argmax(rms)) + 1
    assert float(said.group(1)) == pytest.approx(rms.max(), rel=5e-3)
    fc2 = load_urdf(path).friction.fc[1] / G  # motor 2's Coulomb friction as written
    left = re.search(
        r"left out up to ([0-9.e+-]+) N m at joint 2, ([0-9.e+-]+) N m at joint 1", lines[0]
    )
    assert left is not None, lines[0]
    assert float(left.group(1)) == pytest.approx(2 * G * fc2, rel=1e-3)
    assert float(left.group(2)) == pytest.approx(30.0 * fc2, rel=1e-3)


def test_coupled_coulomb_left_out_bounds_any_coupling():
    """Drives with couplings of either sign on several motors: no velocities within the
    limits leave out more than the bound (direct numpy over sampled velocities), and a
    drive whose one coupled motor has a negative entry reaches it."""
    rng = np.random.default_rng(47)
    dq = rng.choice([-1.0, 1.0], (20000, 4)) * 10 ** rng.uniform(-3, 0.5, (20000, 4))
    for trial in range(5):
        K = np.diag(rng.uniform(20, 120, 4)) * rng.choice([-1.0, 1.0], 4)
        for m, j in [(3, 2), (2, 1), (3, 0)][: trial % 3 + 1]:
            K[m, j] = rng.uniform(-40, 40)
        fc = rng.uniform(0.01, 0.1, 4)
        full = np.sign(dq @ K.T) * fc @ K
        direct = np.abs(full - np.abs(np.diag(K)) * fc * np.sign(dq)).max(axis=0)
        bound = coupled_coulomb_left_out(K, fc)
        assert np.all(direct <= bound * (1 + 1e-12)), (trial, direct, bound)
        if trial % 3 == 0:  # motor 4 alone coupled (to joint 3): every sign reachable
            np.testing.assert_allclose(direct, bound, rtol=1e-12)
