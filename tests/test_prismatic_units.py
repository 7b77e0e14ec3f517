"""``--units`` on a robot of prismatic and revolute joints: a length unit (``q=mm``,
``dq=mm/s``) scales the prismatic joints' columns alone, an angle unit the revolute
joints' alone, both given (``q=mm,q=deg``) each its own kind; the truth is Pinocchio's
inverse dynamics of the arm's URDF. The units dynid prints and writes are the joint's
own: N, m/s, N s/m for the rail.

Regression: ``--units q=mm,dq=mm/s`` scaled every joint by 0.001, the revolute ones
included, and a UR5 on a rail was identified 87.8 % off on held-out data, without a word;
``--units q=mm`` alone was told its time column looked like ms.
"""

from __future__ import annotations

import logging
from pathlib import Path

import numpy as np
import pytest

import dynid
from dynid.exceptions import DataError
from dynid.io.columns import parse_column_map
from dynid.workflows.data_files import read_torque_log
from dynid.workflows.identify import IdentifyOptions, identify_files

pin = pytest.importorskip("pinocchio")

#: Degrees per radian.
_DEG = 180.0 / np.pi

#: A carriage on a rail along x (prismatic) carrying a pendulum swinging about y.
_URDF = """<?xml version="1.0"?>
<robot name="rail_arm">
  <link name="world"/>
  <link name="carriage">
    <inertial><origin xyz="0.02 0.01 0.03"/><mass value="12.0"/>
      <inertia ixx="0.2" ixy="0" ixz="0" iyy="0.3" iyz="0" izz="0.25"/></inertial>
  </link>
  <link name="arm">
    <inertial><origin xyz="0.05 0.0 -0.3"/><mass value="3.0"/>
      <inertia ixx="0.09" ixy="0.001" ixz="0.002" iyy="0.1" iyz="0" izz="0.02"/></inertial>
  </link>
  <joint name="rail" type="prismatic">
    <parent link="world"/><child link="carriage"/><axis xyz="1 0 0"/>
    <limit lower="0" upper="1.5" effort="2000" velocity="1.0"/>
  </joint>
  <joint name="swing" type="revolute">
    <parent link="carriage"/><child link="arm"/><origin xyz="0 0 0.1"/><axis xyz="0 1 0"/>
    <limit lower="-2.5" upper="2.5" effort="200" velocity="3.0"/>
  </joint>
</robot>
"""


def _motion(t: np.ndarray, phase: float) -> tuple[np.ndarray, ...]:
    """Positions [m, rad], velocities and accelerations of a sum of two sines per joint."""
    w = 2 * np.pi * np.array([[0.3, 0.7], [0.5, 1.1]])  # (joint, harmonic) [rad/s]
    a = np.array([[0.3, 0.1], [0.8, 0.4]])
    c = np.array([0.7, 0.0])
    arg = w[None] * t[:, None, None] + phase * np.array([[1.0, 2.0], [3.0, 1.5]])
    q = c + np.sum(a * np.sin(arg), axis=2)
    dq = np.sum(a * w * np.cos(arg), axis=2)
    ddq = -np.sum(a * w**2 * np.sin(arg), axis=2)
    return q, dq, ddq


def _torques(urdf: Path, q: np.ndarray, dq: np.ndarray, ddq: np.ndarray) -> np.ndarray:
    """Pinocchio's inverse dynamics [N, N m] (gravity along -z)."""
    model = pin.buildModelFromUrdf(str(urdf))
    data = model.createData()
    return np.array([pin.rnea(model, data, *s).copy() for s in zip(q, dq, ddq, strict=True)])


def _write(path: Path, t, q, dq, tau, scale: float, swing: float = 1.0) -> None:
    """A log with the rail's position and velocity times ``scale`` (1000: mm, mm/s), the
    swing's times ``swing`` (180 / pi: deg, deg/s)."""
    k = np.array([scale, swing])
    rows = np.column_stack([t, q * k, dq * k, tau])
    header = "t,q1,q2,dq1,dq2,tau1,tau2"
    np.savetxt(path, rows, delimiter=",", header=header, comments="", fmt="%.12g")


@pytest.fixture(scope="module")
def logs(tmp_path_factory: pytest.TempPathFactory) -> dict[str, Path]:
    """Two training logs and a held-out one, in SI and with the rail in mm."""
    d = tmp_path_factory.mktemp("rail")
    urdf = d / "rail_arm.urdf"
    urdf.write_text(_URDF)
    t = np.arange(0.0, 8.0, 0.004)
    out = {"urdf": urdf}
    for name, phase in (("a", 0.0), ("b", 1.0), ("held", 2.0)):
        q, dq, ddq = _motion(t, phase)
        tau = _torques(urdf, q, dq, ddq)
        for unit, scale, swing in (("si", 1.0, 1.0), ("mm", 1e3, 1.0), ("mmdeg", 1e3, _DEG)):
            out[f"{name}_{unit}"] = d / f"{name}_{unit}.csv"
            _write(out[f"{name}_{unit}"], t, q, dq, tau, scale, swing)
        out[f"{name}_truth"] = (q, dq, ddq, tau)  # type: ignore[assignment]
    return out


def _robot(logs: dict[str, Path]) -> dynid.Robot:
    return dynid.Robot.from_urdf(logs["urdf"], tip_link="arm")


def _heldout_error(model, logs) -> float:
    """The model's torques on the held-out states against Pinocchio's [% RMS]."""
    q, dq, ddq, tau = logs["held_truth"]
    pred = model.torques(q, dq, ddq)
    return 100 * float(np.sqrt(np.mean((pred - tau) ** 2) / np.mean(tau**2)))


def test_a_length_unit_scales_the_prismatic_joint_alone(logs):
    """q=mm,dq=mm/s reads the rail in mm and the revolute joint in rad (was: both x 0.001)."""
    robot = _robot(logs)
    cmap = parse_column_map(None, "q=mm,dq=mm/s")
    log = read_torque_log(logs["a_mm"], robot.n, columns=cmap, robot=robot)
    q, dq, _, _ = logs["a_truth"]
    np.testing.assert_allclose(log.q, q, rtol=1e-9, atol=1e-12)
    np.testing.assert_allclose(log.dq, dq, rtol=1e-9, atol=1e-12)


def test_the_identified_model_predicts_as_the_si_logs_does(logs):
    """The rail in mm identifies the model of the SI log: held-out torques at Pinocchio's."""
    robot = _robot(logs)
    errors = {}
    for unit, units in (("si", None), ("mm", "q=mm,dq=mm/s")):
        opts = IdentifyOptions(terms="links", columns=(None, units), estimator="ols")
        res = identify_files(robot, [logs[f"a_{unit}"], logs[f"b_{unit}"]], opts)
        errors[unit] = _heldout_error(res.model, logs)
    assert errors["si"] < 0.5
    assert errors["mm"] == pytest.approx(errors["si"], abs=0.05)


def test_the_note_names_the_joints_a_unit_applied_to(logs, caplog):
    """A note says q=mm applied to the prismatic joint rail, the revolute joints in rad."""
    from dynid.workflows.data_files import column_map

    with caplog.at_level(logging.DEBUG, logger="dynid"):
        column_map(None, "q=mm,dq=mm/s", robot=_robot(logs))
    said = " | ".join(r.getMessage() for r in caplog.records)
    assert "q=mm applied to the prismatic joint rail; the revolute joints read in rad" in said
    assert "dq=mm/s applied to the prismatic joint rail; the revolute joints read in rad/s" in said


def test_a_length_unit_on_an_arm_of_revolute_joints_is_refused(planar2r):
    """q=mm for an arm of revolute joints alone is refused in one line."""
    from dynid.workflows.data_files import column_map

    with pytest.raises(DataError, match=r"--units q=mm: a length unit .* all revolute") as err:
        column_map(None, "q=mm", robot=planar2r)
    assert "\n" not in str(err.value)


def test_an_angle_unit_leaves_the_prismatic_joint_in_metres(logs, tmp_path):
    """q=deg,dq=deg/s scales the revolute joint alone: the rail stays in m."""
    robot = _robot(logs)
    q, dq, _, tau = logs["a_truth"]
    t = np.arange(q.shape[0]) * 0.004
    path = tmp_path / "deg.csv"
    k = np.array([1.0, 180 / np.pi])
    np.savetxt(
        path,
        np.column_stack([t, q * k, dq * k, tau]),
        delimiter=",",
        header="t,q1,q2,dq1,dq2,tau1,tau2",
        comments="",
        fmt="%.12g",
    )
    cmap = parse_column_map(None, "q=deg,dq=deg/s")
    log = read_torque_log(path, robot.n, columns=cmap, robot=robot)
    np.testing.assert_allclose(log.q, q, rtol=1e-9, atol=1e-12)


def test_a_joints_unit_entry_hints_the_quantitys(logs):
    """q1=mm is refused with the hint --units q=mm (which scales the prismatic joints)."""
    with pytest.raises(DataError, match=r"q1=mm: .*hint: --units q=mm \(a length unit"):
        parse_column_map(None, "q1=mm")


def test_velocities_in_mm_s_forgotten_are_said_before_a_time_unit(logs):
    """q=mm without dq=mm/s: the hint is dq=mm/s, not the time column in ms."""
    robot = _robot(logs)
    opts = IdentifyOptions(terms="links", columns=(None, "q=mm"), estimator="ols")
    with pytest.raises(DataError) as err:
        identify_files(robot, [logs["a_mm"], logs["b_mm"]], opts)
    said = str(err.value)
    assert "prismatic joint rail are 1000 times the derivative" in said
    assert "hint: --units q=mm,dq=mm/s" in said
    assert "t=ms" not in said


MIXED = "q=mm,q=deg,dq=mm/s,dq=deg/s"


def test_a_length_and_an_angle_unit_read_each_kind_of_joint(logs):
    """q=mm,q=deg,dq=mm/s,dq=deg/s reads the rail in mm and the swing in degrees (was:
    refused, 'q' given twice)."""
    robot = _robot(logs)
    log = read_torque_log(
        logs["a_mmdeg"], robot.n, columns=parse_column_map(None, MIXED), robot=robot
    )
    q, dq, _, _ = logs["a_truth"]
    np.testing.assert_allclose(log.q, q, rtol=1e-9, atol=1e-12)
    np.testing.assert_allclose(log.dq, dq, rtol=1e-9, atol=1e-12)


def test_a_toml_list_gives_both_units(logs, tmp_path):
    """q = ["mm", "deg"] in a TOML map reads as q=mm,q=deg does."""
    from dynid.io.columns import load_column_map

    path = tmp_path / "map.toml"
    path.write_text('[units]\nq = ["mm", "deg"]\ndq = ["deg/s", "mm/s"]\n')
    robot = _robot(logs)
    log = read_torque_log(logs["a_mmdeg"], robot.n, columns=load_column_map(path), robot=robot)
    np.testing.assert_allclose(log.q, logs["a_truth"][0], rtol=1e-9, atol=1e-12)


def test_the_mixed_log_identifies_the_model_of_the_si_log(logs):
    """Rail in mm and swing in degrees: held-out torques at Pinocchio's, as the SI log's."""
    robot = _robot(logs)
    errors = {}
    for unit, units in (("si", None), ("mmdeg", MIXED)):
        opts = IdentifyOptions(terms="links", columns=(None, units), estimator="ols")
        res = identify_files(robot, [logs[f"a_{unit}"], logs[f"b_{unit}"]], opts)
        errors[unit] = _heldout_error(res.model, logs)
    assert errors["si"] < 0.5
    assert errors["mmdeg"] == pytest.approx(errors["si"], abs=0.05)


@pytest.mark.parametrize(
    ("units", "match"),
    [
        (
            "q=deg,q=rad",
            r"--units q=deg,q=rad: two units of q must be one length unit .*"
            r"hint: --units q=mm,q=deg$",
        ),
        ("q=mm,q=0.001", r"--units q=mm,q=0.001: two units of q must be one length"),
        ("q=mm,q=deg,q=rad", r"--units q=mm,q=deg,q=rad: two units of q"),
        ("dq=mm/s,dq=m/s", r"--units dq=mm/s,dq=m/s: .*hint: --units dq=mm/s,dq=deg/s$"),
        ("t=ms,t=us", r"--units: 't' is given twice"),
    ],
)
def test_an_ambiguous_pair_of_units_is_refused_in_one_line(units, match):
    """Two units of one quantity that are not a length and an angle are refused."""
    with pytest.raises(DataError, match=match) as err:
        parse_column_map(None, units)
    assert "\n" not in str(err.value)


def test_both_units_on_an_arm_of_revolute_joints_are_refused(planar2r):
    """q=mm,q=deg on an arm of revolute joints alone: the length unit reads no joint."""
    from dynid.workflows.data_files import column_map

    with pytest.raises(DataError, match=r"--units q=mm: a length unit .* all revolute"):
        column_map(None, "q=mm,q=deg", robot=planar2r)


def test_the_velocity_hint_keeps_both_units(logs):
    """dq=deg/s forgotten beside q=mm,q=deg,dq=mm/s: the hint adds it, keeping dq=mm/s
    (was: --units dq=1.745329252e-05, 'converts every joint alike')."""
    robot = _robot(logs)
    opts = IdentifyOptions(terms="links", columns=(None, "q=mm,q=deg,dq=mm/s"), estimator="ols")
    with pytest.raises(DataError, match=r"hint: --units q=mm,q=deg,dq=mm/s,dq=deg/s$"):
        identify_files(robot, [logs["a_mmdeg"], logs["b_mmdeg"]], opts)


# ------------------------------------------------------------- units printed and written
@pytest.fixture(scope="module")
def rail_fit(logs):
    """The rail arm identified with viscous friction from the SI logs."""
    import warnings

    opts = IdentifyOptions(terms="links,viscous", estimator="ols")
    with warnings.catch_warnings():  # the frictionless logs' fv: zero, to its noise
        warnings.simplefilter("ignore", dynid.exceptions.DynidWarning)
        return identify_files(_robot(logs), [logs["a_si"], logs["b_si"]], opts)


def test_a_units_spelling_follows_the_joint_kind(logs, planar2r):
    """The rail's force in N, its viscous coefficient in N s/m, its armature in kg; an
    arm of revolute joints keeps N m (its output byte for byte)."""
    from dynid.model.units import joint_units, unit_said, values_said

    robot = _robot(logs)
    assert joint_units(robot, "N m s/rad") == ["N s/m", "N m s/rad"]
    assert unit_said(robot, "N m") == "N m (rail: N)"
    assert unit_said(robot, "kg m^2") == "kg m^2 (rail: kg)"
    assert unit_said(robot, "rad/s") == "rad/s (rail: m/s)"
    assert unit_said(robot, "1/s") == "1/s"
    assert values_said(robot, ["0.96", "0.059"], "N m") == "0.96 N, 0.059 N m"
    assert unit_said(planar2r, "N m s/rad") == "N m s/rad"
    assert values_said(planar2r, ["0.96", "0.059"], "N m") == "0.96, 0.059 N m"


def test_identify_writes_and_prints_the_rails_units(rail_fit, tmp_path):
    """identification.json, heldout.json, the summary and the report say N and N s/m for
    the rail (were: N m and N m s/rad for every joint)."""
    import json

    from dynid.cli.summaries import format_identification
    from dynid.io.model_json import save_model_json
    from dynid.report.model_terms import terms_sections

    doc = json.loads(save_model_json(tmp_path / "identification.json", rail_fit.model).read_text())
    assert doc["units"]["residual_rms"] == "N m (rail: N)"
    assert doc["units"]["friction"].endswith("(rail: fv N s/m, fc N, fo N)")
    assert rail_fit.heldout is not None
    assert rail_fit.heldout.as_dict()["units"]["rms"] == "N m (rail: N)"
    assert "fv [N m s/rad (rail: N s/m)]" in format_identification(rail_fit.model)
    assert "fv [N m s/rad (rail: N s/m)]" in "".join(terms_sections(doc))


def test_friction_and_validate_write_the_rails_units(rail_fit, logs, tmp_path):
    """friction.json, its table and validation.json say N (and N s/m) for the rail."""
    import json

    from dynid.cli.summaries import format_friction_rms
    from dynid.io.friction_json import save_friction_json
    from dynid.io.validation_json import save_validation_json
    from dynid.workflows.friction import FrictionOptions, fit_friction_files
    from dynid.workflows.validate import validate_files

    robot = _robot(logs)
    res = fit_friction_files(rail_fit.model, [logs["a_si"]], FrictionOptions(law="classical"))
    path = save_friction_json(tmp_path / "friction.json", res.fit, robot=robot)
    units = json.loads(path.read_text())["units"]
    assert (units["fv"], units["rms_after"]) == ("N m s/rad (rail: N s/m)", "N m (rail: N)")
    table = format_friction_rms(list(robot.joint_names), res.fit, None, robot=robot)
    assert "RMS after [N m (rail: N)]" in table
    val = validate_files(rail_fit.model, [logs["held_si"]])
    path = save_validation_json(tmp_path / "validation.json", val.validation, robot=robot)
    units = json.loads(path.read_text())["units"]
    assert (units["rms"], units["mse"]) == ("N m (rail: N)", "N^2 m^2 (rail: N^2)")


def test_observe_writes_and_prints_the_rails_units(rail_fit, logs, tmp_path):
    """thresholds.json, events.json, residuals.csv and observe's table say N for the rail
    (were: N m for every joint)."""
    import json

    from dynid.cli.summaries import format_observation
    from dynid.io.model_json import save_model_json
    from dynid.io.observer_files import save_observation
    from dynid.workflows.observe import ObserveOptions, observe_files

    model = save_model_json(tmp_path / "identification.json", rail_fit.model)
    names = list(_robot(logs).joint_names)
    cal = observe_files(ObserveOptions(data=(logs["a_si"],), model=model, calibrate=True))
    (path,) = save_observation(tmp_path, cal, joints=names, calibrating=True)
    units = json.loads(path.read_text())["units"]
    assert (units["contact"], units["gain"]) == ("N m (rail: N)", "1/s")
    assert "contact --no-uncertainty [N m (rail: N)]" in format_observation(
        cal, names, calibrating=True
    )
    opts = ObserveOptions(data=(logs["held_si"],), model=model, thresholds=path)
    found = observe_files(opts)
    events, table = save_observation(tmp_path, found, joints=names, calibrating=False)
    assert json.loads(events.read_text())["units"]["peak"] == "N m (rail: N)"
    assert table.read_text().startswith("# dynid residuals; units: t [s], r [N m (rail: N)]")


def test_a_verdicts_hint_says_the_rails_force_in_newtons():
    """A residual that follows the rail's velocity is said in N (was: N m)."""
    from dynid.identification.residual_dependence import dependence_hint

    rng = np.random.default_rng(3)
    t = np.linspace(0.0, 10.0, 4000)
    q = np.column_stack([0.5 * np.sin(t), np.sin(0.7 * t)])
    dq = np.column_stack([0.5 * np.cos(t), 0.7 * np.cos(0.7 * t)])
    error = np.column_stack([30.0 * dq[:, 0], np.zeros_like(t)])
    error += 0.01 * rng.standard_normal(error.shape)
    noise = np.array([0.01, 0.01])
    said = dependence_hint([q], [dq], [error], noise, ["rail", "swing"], prismatic=(True, False))
    assert said is not None and said.startswith("rail: ")
    assert " N RMS residual follows its velocity" in said and "N m" not in said
    plain = dependence_hint([q], [dq], [error], noise, ["rail", "swing"])
    assert plain is not None and " N m RMS residual follows its velocity" in plain


def test_payload_writes_and_prints_the_rails_units(logs):
    """payload.json's residual units and payload's residual line say N for the rail (were:
    N m)."""
    from dynid.cli.payload import residual_line
    from dynid.feasibility.payload import PayloadEstimate
    from dynid.io.payload_json import payload_to_dict
    from dynid.model.units import unit_said

    robot = _robot(logs)
    z3, z6, i3 = np.zeros(3), np.zeros(6), 0.01 * np.eye(3)
    est = PayloadEstimate(
        frame="arm", link=robot.n - 1, phi=np.r_[1.5, np.zeros(9)], mass=1.5, com=z3,
        inertia=i3, std_mass=0.01, std_com=z3, std_inertia=z6, covariance=np.eye(4),
        route="torque log, gravity and dynamics", inertia_identified=False,
        constraint_active=False, margin=1e-6, rank=4, condition_number=10.0,
        residual_rms=0.012, n_rows=100, friction=None, notes=(), noise_rms=0.01,
    )  # fmt: skip
    units = payload_to_dict(est, robot)["units"]
    assert units["noise_rms"] == "N m (rail: N)"
    line = residual_line(est, unit_said(robot, "N m"))
    assert line.startswith("residual RMS 0.012 N m (rail: N), 1.2 x the torque noise (0.01 N m")
