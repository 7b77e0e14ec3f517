"""Exports of feasible parameters: URDF (dynid and Pinocchio), feasible.json, TOML, report, bounds.

Reference: Pinocchio (``buildModelFromUrdf``, CRBA, generalized gravity) on the exported
URDF, against the identified model's M and g; round trips against the written robot.
"""

from __future__ import annotations

import json

import numpy as np
import pytest

import dynid
from dynid.exceptions import DataError
from dynid.feasibility.bounds import default_bounds, panda_bounds
from dynid.feasibility.penalty import RetrievalOptions, retrieve_from_coefficients
from dynid.identification.model import IdentifiedModel
from dynid.io.bounds_file import bounds_from_dict, load_bounds, save_bounds
from dynid.io.export import save_robot
from dynid.io.feasible import feasible_to_dict, load_feasible_json, save_feasible_json
from dynid.io.report_json import report_to_dict, save_report_json
from dynid.io.robot.urdf import save_urdf, urdf_from_robot
from dynid.regressors.base import base_parameters

from conftest import given_fit, random_states, robot_data_urdf


@pytest.fixture(scope="module")
def retrieved():
    """Identified (noise-free) Panda model and feasible parameters retrieved from it."""
    panda = dynid.panda()
    base = base_parameters(panda)
    beta = base.beta_from_phi(panda.phi)
    model = IdentifiedModel(panda, base, given_fit(beta))
    res = retrieve_from_coefficients(
        panda, base, beta, options=RetrievalOptions(runs=3), workers=1, seed=0
    )
    assert res.feasible
    return model, res


def _pin_M_g(path, gravity, q):
    pin = pytest.importorskip("pinocchio")
    model = pin.buildModelFromUrdf(str(path))
    model.gravity.linear = np.asarray(gravity)
    data = model.createData()
    Ms, gs = [], []
    for qv in q:
        qk = np.zeros(model.nq)  # continuous joints have (cos, sin) coordinates in Pinocchio
        for k, j in enumerate(model.joints[1:]):
            if j.nq == 2:
                qk[j.idx_q : j.idx_q + 2] = np.cos(qv[k]), np.sin(qv[k])
            else:
                qk[j.idx_q] = qv[k]
        M = pin.crba(model, data, qk)
        Ms.append(np.triu(M) + np.triu(M, 1).T)
        gs.append(pin.computeGeneralizedGravity(model, data, qk).copy())
    return np.array(Ms), np.array(gs)


def test_exported_urdf_matches_identified_model_in_dynid_and_pinocchio(retrieved, tmp_path):
    """The URDF of the retrieved robot loads in dynid and Pinocchio with the identified M and g."""
    model, res = retrieved
    path = save_urdf(tmp_path / "robot.urdf", res.robot)
    back = dynid.Robot.from_urdf(path)
    assert back.joint_names == res.robot.joint_names and back.link_names[:8] == res.robot.link_names
    np.testing.assert_allclose(back.phi, res.robot.phi, atol=1e-15)
    np.testing.assert_allclose(back.T_parent_joint, res.robot.T_parent_joint, atol=1e-15)
    np.testing.assert_allclose(
        back.frame("flange").T_link_frame, res.robot.frame("flange").T_link_frame, atol=1e-15
    )
    np.testing.assert_array_equal(back.q_min, res.robot.q_min)
    np.testing.assert_array_equal(back.tau_max, res.robot.tau_max)
    q = random_states(res.robot, 100, 11)[0]
    M_id, g_id = model.mass_matrix(q), model.gravity_torques(q)
    scale_M, scale_g = np.abs(M_id).max(), np.abs(g_id).max()
    np.testing.assert_allclose(dynid.mass_matrix(back, q), M_id, atol=1e-9 * scale_M)
    np.testing.assert_allclose(dynid.gravity_torques(back, q), g_id, atol=1e-9 * scale_g)
    M_pin, g_pin = _pin_M_g(path, res.robot.gravity, q)
    np.testing.assert_allclose(M_pin, M_id, atol=1e-9 * scale_M)
    np.testing.assert_allclose(g_pin, g_id, atol=1e-9 * scale_g)


def test_urdf_export_without_limits_and_with_a_prismatic_joint(tmp_path):
    """Unlimited revolute joints become continuous, limits read back; Pinocchio agrees on M, g."""
    rng = np.random.default_rng(12)
    robot = dynid.Robot.from_mdh(
        [0.0, 0.3, 0.2],
        [0.1, 0.0, 0.05],
        [0.0, np.pi / 2, 0.0],
        joint_types="RPR",
        mass=[1.0, 2.0, 0.5],
        com=rng.uniform(-0.05, 0.05, (3, 3)),
        inertia=np.stack([np.diag(rng.uniform(0.01, 0.02, 3)) for _ in range(3)]),
        q_min=[-np.inf, -0.2, -1.0],
        q_max=[np.inf, 0.3, 1.0],
        name="rpr",
    )
    text = urdf_from_robot(robot)
    assert 'type="continuous"' in text and 'type="prismatic"' in text
    path = tmp_path / "rpr.urdf"
    path.write_text(text)
    back = dynid.Robot.from_urdf(path)
    np.testing.assert_allclose(back.phi, robot.phi, atol=1e-15)
    assert back.q_min[0] == -np.inf and back.q_max[1] == 0.3
    assert np.all(back.prismatic == robot.prismatic)
    q = np.column_stack(
        [rng.uniform(-3, 3, 20), rng.uniform(-0.2, 0.3, 20), rng.uniform(-1, 1, 20)]
    )
    M_pin, g_pin = _pin_M_g(path, robot.gravity, q)
    np.testing.assert_allclose(M_pin, dynid.mass_matrix(robot, q), atol=1e-12)
    np.testing.assert_allclose(g_pin, dynid.gravity_torques(robot, q), atol=1e-12)


def test_urdf_export_of_a_urdf_robot_with_all_frames(tmp_path):
    """UR5 from URDF, exported with all its frames, reloads with its own tip name, same frames."""
    ur5 = dynid.Robot.from_urdf(
        robot_data_urdf("ur_description/urdf/ur5_robot.urdf"), "base_link", "tool0"
    )
    path = save_urdf(tmp_path / "ur5.urdf", ur5, all_frames=True)
    back = dynid.Robot.from_urdf(path, tip_link="tool0")
    np.testing.assert_allclose(back.phi, ur5.phi, atol=1e-15)
    assert back.link_names == ur5.link_names and back.joint_names == ur5.joint_names
    for name, f in ur5.frames.items():
        g = back.frame(name)
        assert g.link == f.link
        np.testing.assert_allclose(g.T_link_frame, f.T_link_frame, atol=1e-12)


def test_feasible_json_round_trip(retrieved, tmp_path):
    """feasible.json holds mass, CoM, inertia about the CoM per link; loads back as the robot."""
    _, res = retrieved
    path = save_feasible_json(tmp_path / "feasible.json", res)
    d = json.loads(path.read_text())
    assert d["feasible"] is True and len(d["links"]) == 7
    assert (
        set(d["links"][0]) == {"name", "mass", "com", "inertia"}
        and len(d["links"][0]["inertia"]) == 6
    )
    np.testing.assert_allclose([x["mass"] for x in d["links"]], res.mass, rtol=1e-15)
    back = load_feasible_json(path)
    np.testing.assert_allclose(back.phi, res.robot.phi, atol=1e-15)
    np.testing.assert_array_equal(back.T_parent_joint, res.robot.T_parent_joint)
    np.testing.assert_array_equal(back.friction.params, res.robot.friction.params)
    assert back.friction.kind == res.robot.friction.kind == "sigmoid"
    on = load_feasible_json(path, robot=dynid.panda().with_friction(None))
    np.testing.assert_allclose(on.phi, res.robot.phi, atol=1e-15)
    assert on.friction is None


def test_feasible_json_errors(retrieved, tmp_path):
    """Wrong schema, a mismatched robot and malformed values raise DataError."""
    _, res = retrieved
    d = feasible_to_dict(res)
    bad = tmp_path / "bad.json"
    bad.write_text(json.dumps(d | {"schema": "other"}))
    with pytest.raises(DataError, match="schema"):
        load_feasible_json(bad)
    good = save_feasible_json(tmp_path / "f.json", res)
    ur5 = dynid.Robot.from_urdf(
        robot_data_urdf("ur_description/urdf/ur5_robot.urdf"), "base_link", "tool0"
    )
    with pytest.raises(DataError, match="got 7 links"):
        load_feasible_json(good, robot=ur5)
    d2 = json.loads(json.dumps(d))
    d2["links"][2]["com"] = [0.0, 0.0]
    bad.write_text(json.dumps(d2))
    with pytest.raises(
        DataError, match=r"bad.json: key 'links\[2\].com': expected a list of 3 numbers"
    ):
        load_feasible_json(bad)


def test_toml_round_trip(retrieved, tmp_path):
    """The retrieved robot written as dynid TOML reads back with the same parameters."""
    _, res = retrieved
    path = tmp_path / "robot.toml"
    save_robot(path, res.robot)
    back = dynid.Robot.from_toml(path)
    np.testing.assert_allclose(back.phi, res.robot.phi, atol=1e-14)
    np.testing.assert_allclose(back.T_parent_joint, res.robot.T_parent_joint, atol=1e-15)
    np.testing.assert_allclose(back.friction.params, res.robot.friction.params)


def test_report_json_lists_every_constraint(retrieved, tmp_path):
    """report.json holds the residual, every constraint margin, stage costs, time and seed."""
    _, res = retrieved
    path = save_report_json(tmp_path / "report.json", res, source="test")
    d = json.loads(path.read_text())
    assert d == json.loads(json.dumps(report_to_dict(res) | {"source": "test"}))
    assert len(d["constraints"]) == len(res.report.constraints)
    assert d["relative_residual"] == res.relative_residual and d["seed"] == 0
    assert len(d["stage_costs"]) == res.options.stages and d["run_time_s"] > 0
    assert d["min_margin"]["triangle_inequality"] > 0 and len(d["runs"]) == 3


@pytest.mark.parametrize("suffix", [".json", ".toml"])
def test_bounds_file_round_trip(tmp_path, suffix):
    """Bounds written as JSON or TOML read back identical (band included and removed)."""
    panda = dynid.panda()
    for b in (panda_bounds(), panda_bounds().with_total_mass(None)):
        path = save_bounds(tmp_path / f"b{suffix}", b)
        back = load_bounds(path, panda)
        np.testing.assert_array_equal(back.lower, b.lower)
        np.testing.assert_array_equal(back.upper, b.upper)
        assert back.total_mass == b.total_mass


def test_partial_bounds_file_fills_defaults_and_rejects_unknowns(tmp_path):
    """Missing entries come from default_bounds; unknown keys and links raise DataError."""
    panda = dynid.panda()
    b = bounds_from_dict({"links": [{"name": "link3", "mass": [1.0, 4.0]}]}, panda)
    ref = default_bounds(panda)
    assert (b.mass_min[2], b.mass_max[2]) == (1.0, 4.0)
    np.testing.assert_array_equal(b.com_min, ref.com_min)
    assert b.total_mass == ref.total_mass
    assert bounds_from_dict({"total_mass": None}, panda).total_mass is None
    with pytest.raises(
        DataError, match=r"bounds: key 'links\[0\].masss': unknown key; allowed: com_max"
    ):
        bounds_from_dict({"links": [{"name": "link3", "masss": [1, 2]}]}, panda)
    with pytest.raises(
        DataError,
        match=r"key 'links\[0\].name': expected a link of the robot \(link1, .*; got 'link9'",
    ):
        bounds_from_dict({"links": [{"name": "link9"}]}, panda)
    with pytest.raises(DataError, match="must not exceed"):
        bounds_from_dict({"links": [{"name": "link1", "mass": [3.0, 1.0]}]}, panda)
    (tmp_path / "b.yaml").write_text("x")
    with pytest.raises(DataError, match=".json or .toml"):
        load_bounds(tmp_path / "b.yaml", panda)


def test_bounds_file_values_are_lists_of_finite_numbers():
    """A bound of the wrong length, a boolean or an infinite number is one DataError naming
    the link, the key and the entry."""
    panda = dynid.panda()
    for value, message in (
        ([1.0], r"b.json: key 'links\[0\].mass': expected a list of 2 numbers \[kg\]; got \[1.0\]"),
        ([1.0, True], r"b.json: key 'links\[0\].mass\[1\]': expected a number \[kg\]; got True"),
        (
            [0.0, float("inf")],
            r"b.json: key 'links\[0\].mass\[1\]': expected a finite number; got inf",
        ),
    ):
        with pytest.raises(DataError, match=message):
            bounds_from_dict({"links": [{"name": "link3", "mass": value}]}, panda, source="b.json")
