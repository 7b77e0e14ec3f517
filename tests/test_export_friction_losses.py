"""What the URDF and MJCF exports hold of an identified friction model, and what they say
they leave out.

URDF's ``<dynamics damping friction>`` (read back, as Pinocchio reads it, as viscous and
sharp Coulomb friction at the joints) and MJCF's ``damping``/``frictionloss`` hold
``fv dq + fc sign(dq)``. References: the closed forms of the laws (what is lost is
``fc (tanh(dq / v_s) - sign(dq)) + fo`` for the smooth law), Pinocchio's reading of the
files, MuJoCo's compiled model, the vendor template's own text.
"""

from __future__ import annotations

import re
import warnings

import numpy as np
import pytest

from dynid.exceptions import DynidWarning
from dynid.friction.laws import law_named
from dynid.friction.model import ClassicalFriction
from dynid.io.robot.export_options import ExportOptions
from dynid.io.robot.mjcf import mjcf_from_robot
from dynid.io.robot.urdf import export_urdf, load_urdf
from dynid.model.drive import Drive

from conftest import planar_2r, robot_data_urdf

FV, FC = np.array([0.9, 0.3]), np.array([0.7, 0.2])  # N m s/rad, N m
FO = np.array([0.3, -0.44])  # N m
BAND = np.array([0.004, 0.006])  # rad/s


def _arm():
    lim = np.array([2.5, 2.5])
    return planar_2r().replace(q_min=-lim, q_max=lim, dq_max=lim, ddq_max=4 * lim)


def _warnings(fn, *args, **kw):
    with warnings.catch_warnings(record=True) as got:
        warnings.simplefilter("always")
        out = fn(*args, **kw)
    return out, [str(w.message) for w in got if issubclass(w.category, DynidWarning)]


def test_urdf_export_of_smooth_friction_names_everything_it_leaves_out(tmp_path):
    """The smooth law with a band and offsets: the URDF reads back the viscous and Coulomb
    friction closest to the law over the velocity range, and the one warning names the
    rounding, the offsets and the files that hold the model."""
    smooth = law_named("smooth").model(np.column_stack([FV, FC, FO]), BAND)
    path, lines = _warnings(
        export_urdf, tmp_path / "robot.urdf", _arm(), ExportOptions(friction=smooth)
    )
    assert len(lines) == 1 and lines[0].startswith("URDF export: robot.urdf holds"), lines
    toml = "a TOML export (robot.toml, not written) would hold it exactly"
    for said in ("tanh(dq / width)", "sign's width", "0.006 rad/s at joint 2", "offsets fo",
                 "-0.44 N m at joint 2", toml):  # fmt: skip
        assert said in lines[0], (said, lines[0])
    assert "feasible.json" not in lines[0]  # none was written or read
    back = load_urdf(path).friction
    # the URDF holds the nonnegative fv dq + fc sign(dq) closest to the law's odd part over
    # the velocity range (scipy's NNLS on the same grid), not fc tanh's fc as a sharp step
    from scipy.optimize import nnls

    vmax = np.asarray(_arm().dq_max)
    for j in range(2):
        v = np.linspace(0.0, vmax[j], 201)[1:]
        x, _ = nnls(np.column_stack([v, np.ones_like(v)]), FV[j] * v + FC[j] * np.tanh(v / BAND[j]))
        np.testing.assert_allclose(back.as_array()[j, :2], x, atol=1e-9)
    assert "closest to the law over the velocity range" in lines[0]


def test_a_narrow_smooth_law_is_said_once_not_as_an_approximation(tmp_path):
    """A smooth law of width 0.0003 rad/s: the viscous and Coulomb terms written hold it to
    round-off over the velocity range (2e-10 N m RMS): the export said so in a paragraph of
    its own beside the rounding's; now the warning names the rounding alone, and the file
    reads back the law's fv and fc."""
    narrow = np.array([0.0003, 0.0002])  # rad/s
    smooth = law_named("smooth").model(np.column_stack([FV, FC, 0 * FV]), narrow)
    path, lines = _warnings(
        export_urdf, tmp_path / "robot.urdf", _arm(), ExportOptions(friction=smooth)
    )
    assert len(lines) == 1 and "tanh(dq / width)" in lines[0], lines
    assert "closest to the law over the velocity range" not in lines[0], lines[0]
    np.testing.assert_allclose(
        load_urdf(path).friction.as_array()[:, :2], np.column_stack([FV, FC]), atol=1e-6
    )


@pytest.mark.parametrize(
    ("law", "params", "band", "said"),
    [
        ("classical", [FV, FC, 0 * FV], BAND, "standstill band (no Coulomb friction"),
        ("quadratic", [FV, [0.1, 0.0], FC, 0 * FV], None, "quadratic viscous term"),
        ("stribeck", [FV, FC, 1.5 * FC, [0.05, 0.05], 0 * FV], None, "Stribeck peak"),
    ],
)
def test_urdf_export_names_a_band_a_quadratic_term_a_stribeck_peak(
    tmp_path, law, params, band, said
):
    """Each shape the URDF's sign cannot hold is named (no offset: none named)."""
    fr = law_named(law).model(np.column_stack(params), band)
    _, lines = _warnings(export_urdf, tmp_path / "r.urdf", _arm(), ExportOptions(friction=fr))
    assert len(lines) == 1 and said in lines[0] and "offsets" not in lines[0], lines


def test_urdf_export_of_what_it_holds_says_nothing_and_motors_are_named(tmp_path):
    """Classical friction at the joints without band or offset: held exactly, no warning;
    at the motors of a gear-10 drive it is written reflected (100 fv, 10 fc, exact for a
    diagonal drive) and its place is named."""
    fr = ClassicalFriction(FV, FC, 0 * FV)
    path, lines = _warnings(export_urdf, tmp_path / "a.urdf", _arm(), ExportOptions(friction=fr))
    assert lines == []
    back = load_urdf(path).friction
    np.testing.assert_allclose(back.fv, FV, atol=1e-12)
    np.testing.assert_allclose(back.fc, FC, atol=1e-12)
    drive = Drive.from_gears([10.0, 10.0], side="motor", friction_at="motor")
    motor = fr.at(drive)
    path, lines = _warnings(export_urdf, tmp_path / "m.urdf", _arm(), ExportOptions(friction=motor))
    assert len(lines) == 1 and "friction at the motors" in lines[0], lines
    back = load_urdf(path).friction
    np.testing.assert_allclose(back.fv, 100 * FV, rtol=1e-12)
    np.testing.assert_allclose(back.fc, 10 * FC, rtol=1e-12)


def _z1():
    path = robot_data_urdf("z1_description/urdf/z1.urdf")
    if path is None:
        pytest.skip("example-robot-data's Z1 not installed")
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", DynidWarning)
        return path, load_urdf(path, tip_link="link06")


_DYN = re.compile(r"<dynamics\b[^>]*/>")


def test_urdf_export_names_each_rotor_inertia_it_drops_on_a_line_of_its_own(tmp_path):
    """Regression: the rotor inertias URDF cannot hold (held-out 3.29 % for an xArm7's URDF
    export against 0.643 % for its MJCF) were named only at the end of the friction's long
    warning; now a warning of their own names each joint's armature K^T diag(I_a) K and the
    exports that hold it."""
    ia = np.array([0.2, 0.05])  # kg m^2 at the motors
    drive = Drive.from_gears([3.0, 2.0], rotor_inertia=ia, side="joint")
    smooth = law_named("smooth").model(np.column_stack([FV, FC, FO]), BAND)
    opts = ExportOptions(friction=smooth, drive=drive)
    _, lines = _warnings(export_urdf, tmp_path / "robot.urdf", _arm(), opts)
    assert len(lines) == 2 and lines[0].startswith("URDF export: robot.urdf holds"), lines
    assert "rotor" not in lines[0]
    rotors = lines[1]
    assert rotors.startswith("URDF export: robot.urdf leaves out the drive's rotor inertias")
    names = _arm().joint_names
    for name, g, i in zip(names, (3.0, 2.0), ia, strict=True):  # armature g^2 I_a
        assert f"{name} {g**2 * i:.4g}" in rotors, rotors
    assert "an MJCF export (robot.xml, not written) would hold them as armature" in rotors
    assert "a TOML export (robot.toml, not written) as its [drive] table" in rotors
    _, alone = _warnings(export_urdf, tmp_path / "r.urdf", _arm(), ExportOptions(drive=drive))
    assert len(alone) == 1 and alone[0].startswith("URDF export: r.urdf leaves out"), alone


def _mass_diagonal_2r_at_zero() -> np.ndarray:
    """The planar 2R arm's M_11 and M_22 [kg m^2] at q = 0 (the middle of +-2.5 rad), in
    closed form: I1 + m1 (l1/2)^2 + I2 + m2 (l1^2 + (l2/2)^2 + l1 l2) and I2 + m2 (l2/2)^2."""
    l1, l2, m1, m2, i1, i2 = 0.7, 0.5, 2.0, 1.5, 0.05, 0.03
    return np.array(
        [
            i1 + m1 * (l1 / 2) ** 2 + i2 + m2 * (l1**2 + (l2 / 2) ** 2 + l1 * l2),
            i2 + m2 * (l2 / 2) ** 2,
        ]
    )


def test_urdf_export_names_an_armature_without_gears_only_when_not_negligible(tmp_path):
    """Regression: identify without a drive warned that robot.urdf leaves out "the drive's
    rotor inertias" of 1e-7 kg m^2; an armature below 0.1 % of its joint's M_jj at the
    middle of the ranges is not named now, and one above is named as the armature, with
    its share of the joint's inertia with it, M_jj + armature (closed form of the 2R
    arm)."""
    diag = _mass_diagonal_2r_at_zero()
    below = Drive.from_gears([1.0, 1.0], rotor_inertia=0.99e-3 * diag, side="joint")
    _, lines = _warnings(export_urdf, tmp_path / "a.urdf", _arm(), ExportOptions(drive=below))
    assert lines == []
    ia = np.array([0.5e-3, 1.5e-3]) * diag  # joint 2 above the rule
    above = Drive.from_gears([1.0, 1.0], rotor_inertia=ia, side="joint")
    _, lines = _warnings(export_urdf, tmp_path / "b.urdf", _arm(), ExportOptions(drive=above))
    assert len(lines) == 1, lines
    assert lines[0].startswith("URDF export: b.urdf leaves out the armature (rotor inertia")
    assert "drive's" not in lines[0]
    assert f"joint2 {ia[1]:.4g} (0.15 % of the joint's inertia)" in lines[0], lines[0]
    assert f"joint1 {ia[0]:.4g} (0.05 % of the joint's inertia)" in lines[0], lines[0]
    big = Drive.from_gears([1.0, 1.0], rotor_inertia=14.0 * diag, side="joint")  # a wrist's
    _, lines = _warnings(export_urdf, tmp_path / "c.urdf", _arm(), ExportOptions(drive=big))
    assert "(93 % of the joint's inertia)" in lines[0], lines[0]  # 14 / 15, not 1.4e+03 %
    huge = Drive.from_gears([1.0, 1.0], rotor_inertia=250.0 * diag, side="joint")  # a servo's
    _, lines = _warnings(export_urdf, tmp_path / "d.urdf", _arm(), ExportOptions(drive=huge))
    assert "(99.6 % of the joint's inertia)" in lines[0], lines[0]  # 250 / 251, not 1e+02 %


def test_template_dynamics_are_replaced_by_the_identified_friction(tmp_path):
    """A vendor template with damping/friction 1-2 on every joint: patched, the chain's
    <dynamics> hold the identified fv and fc (read back to 1e-12, Pinocchio reads the
    same), the gripper's stay, and every other byte is the template's but dynid's comment
    at the top."""
    pin = pytest.importorskip("pinocchio")
    path, chain = _z1()
    text = open(path).read()
    assert chain.friction is not None and np.all(chain.friction.fv >= 1.0)  # the vendor's
    fv, fc = np.linspace(0.2, 1.5, 6), np.linspace(0.1, 1.2, 6)
    fr = ClassicalFriction(fv, fc, np.zeros(6))
    options = ExportOptions(template=path, tip="link06", merged="keep", friction=fr)
    out, lines = _warnings(export_urdf, tmp_path / "z1.urdf", chain, options)
    assert lines == []
    head, header, rest = out.read_text().split("\n", 2)
    assert "the joints' friction as <dynamics damping friction> (identified)" in header
    patched = f"{head}\n{rest}"  # without dynid's comment at the top
    inertial = re.compile(r"<inertial\b.*?</inertial>", re.S)
    assert _DYN.sub("", inertial.sub("", patched)) == _DYN.sub("", inertial.sub("", text))
    assert len(_DYN.findall(patched)) == len(_DYN.findall(text))
    assert _DYN.findall(patched)[-1] == _DYN.findall(text)[-1]  # the gripper's joint
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", DynidWarning)
        back = load_urdf(out, tip_link="link06").friction
    np.testing.assert_allclose(back.fv, fv, rtol=0, atol=1e-12)
    np.testing.assert_allclose(back.fc, fc, rtol=0, atol=1e-12)
    model = pin.buildModelFromUrdf(str(out))
    idx = [model.joints[model.getJointId(n)].idx_v for n in chain.joint_names]
    np.testing.assert_allclose(np.asarray(model.damping)[idx], fv, rtol=0, atol=1e-12)
    np.testing.assert_allclose(np.asarray(model.friction)[idx], fc, rtol=0, atol=1e-12)


def test_template_dynamics_are_removed_when_the_model_has_no_friction(tmp_path):
    """Without friction the chain's <dynamics> go (one line says so): read back, the arm
    has no friction, and Pinocchio reads zeros."""
    pin = pytest.importorskip("pinocchio")
    path, chain = _z1()
    options = ExportOptions(template=path, tip="link06", merged="move", friction=False)
    out, lines = _warnings(export_urdf, tmp_path / "z1.urdf", chain, options)
    assert len(lines) == 1 and "joint1, joint2, joint3, joint4, joint5, joint6" in lines[0]
    assert "is removed" in lines[0], lines
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", DynidWarning)
        assert load_urdf(out, tip_link="link06").friction is None
    model = pin.buildModelFromUrdf(str(out))
    idx = [model.joints[model.getJointId(n)].idx_v for n in chain.joint_names]
    np.testing.assert_array_equal(np.asarray(model.damping)[idx], 0.0)
    np.testing.assert_array_equal(np.asarray(model.friction)[idx], 0.0)


def test_mjcf_export_names_the_offsets_it_drops():
    """Classical friction with offsets: MuJoCo compiles damping = fv and frictionloss = fc
    exactly, and one warning names the offsets (the largest, 0.44 N m at joint 2) and no
    file, none being written beside it."""
    mujoco = pytest.importorskip("mujoco")
    fr = ClassicalFriction(FV, FC, FO)
    (text, approx), lines = _warnings(mjcf_from_robot, _arm(), friction=fr)
    assert len(lines) == 1 and lines[0].startswith("MJCF export: "), lines
    assert "offsets fo (up to -0.44 N m at joint 2)" in lines[0], lines[0]
    assert "; mj_inverse's friction (" in lines[0]  # at the reversals: its own note
    assert "robot.toml" not in lines[0] and "feasible.json" not in lines[0]  # none written
    model = mujoco.MjModel.from_xml_string(text)
    np.testing.assert_array_equal(model.dof_damping, FV)
    np.testing.assert_array_equal(model.dof_frictionloss, FC)
    np.testing.assert_array_equal(approx.offset, FO)
    (_, _), lines = _warnings(mjcf_from_robot, _arm(), friction=ClassicalFriction(FV, FC, 0 * FV))
    assert len(lines) == 1 and lines[0].startswith("MJCF export: mj_inverse's friction ("), lines
