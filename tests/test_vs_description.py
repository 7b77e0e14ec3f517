"""The identified base parameters against the description's: Pinocchio, a closed form and a
simulated arm whose link 5 is 10 % heavier than described."""

from __future__ import annotations

import re

import numpy as np
import pytest

import dynid
from dynid.cli.summaries import format_identification
from dynid.exceptions import OptionError
from dynid.identification.model import IdentifiedModel, IdentifiedTerm
from dynid.identification.static import identify_static
from dynid.identification.vs_description import described_inertials, description_comparison
from dynid.io.model_json import load_model_json, model_to_dict, save_model_json
from dynid.model.drive import Drive
from dynid.regressors.base import base_parameters
from dynid.regressors.terms import RotorInertia
from dynid.report.identify import _coefficients_section
from dynid.simulation.controller import SimulatedController, acquire_static

from conftest import given_fit, pinocchio_panda_model, planar_2r, random_states

#: dynid order (m, mcx, mcy, mcz, Jxx, Jxy, Jxz, Jyy, Jyz, Jzz) from Pinocchio's
#: (m, mcx, mcy, mcz, Ixx, Ixy, Iyy, Ixz, Iyz, Izz)
PIN_TO_DYNID = np.array([0, 1, 2, 3, 4, 5, 7, 6, 8, 9])


def _model(robot, base, beta, std, terms=None):
    """An identified model of ``robot`` holding ``beta`` with standard deviations ``std``."""
    fit = given_fit(beta, std, n_rows=10 * base.rank)
    return IdentifiedModel(robot=robot, base=base, fit=fit, terms=terms or {})


@pytest.fixture(scope="module")
def heavier_link5():
    """The Panda described as published, identified from noisy static data of an arm whose
    link 5 is 10 % heavier (mass, first moments and inertia: the same CoM and shape)."""
    described = dynid.panda()
    phi = np.array(described.phi).reshape(7, 10)
    phi[4] *= 1.1
    truth = described.with_params(phi)
    control = SimulatedController(truth, relative_noise=1e-3, rng=np.random.default_rng(51))
    data = acquire_static(control, 150, np.random.default_rng(52))
    return described, truth, identify_static(described, data)


def test_description_values_are_pinocchios_torques_in_the_base():
    """The Panda's description values solve Pinocchio's base-regressor rows for Pinocchio's
    RNEA torques of the published inertials (Gaz et al. 2019) at random states."""
    pin = pytest.importorskip("pinocchio")
    robot = dynid.panda()
    base = base_parameters(robot)
    model = pinocchio_panda_model(robot)
    model.gravity.linear[:] = robot.gravity
    data = model.createData()
    q, dq, ddq = random_states(robot, 30, seed=53)
    W, tau = [], []
    for s in range(len(q)):
        Y = pin.computeJointTorqueRegressor(model, data, q[s], dq[s], ddq[s])
        W.append(Y.reshape(7, 7, 10)[:, :, PIN_TO_DYNID].reshape(7, 70)[:, base.independent])
        tau.append(pin.rnea(model, data, q[s], dq[s], ddq[s]).copy())
    beta_pin = np.linalg.lstsq(np.vstack(W), np.concatenate(tau), rcond=None)[0]
    vs = description_comparison(_model(robot, base, beta_pin, np.full(base.rank, 0.01)))
    assert vs is not None and vs.source == "panda"
    np.testing.assert_allclose(vs.values, beta_pin, rtol=1e-9, atol=1e-11)
    np.testing.assert_allclose(vs.z, 0.0, atol=1e-7)  # identified == described


def test_planar_arm_description_values_in_closed_form():
    """A planar 2R arm's base parameters: J1zz + m2 l1^2, mc1x + m2 l1, J2zz, mc2x, with
    J about the link origins (I + m (l/2)^2) and mc1y = mc2y = 0; z from given stds."""
    l1, l2, m1, m2, I1, I2 = 0.7, 0.5, 2.0, 1.5, 0.05, 0.03
    robot = planar_2r(l1, l2, m1, m2, I1, I2)
    base = base_parameters(robot)
    closed = {
        "J1zz": I1 + m1 * (l1 / 2) ** 2 + m2 * l1**2,
        "mc1x": m1 * l1 / 2 + m2 * l1,
        "mc1y": 0.0,
        "J2zz": I2 + m2 * (l2 / 2) ** 2,
        "mc2x": m2 * l2 / 2,
        "mc2y": 0.0,
    }
    first = [e.split()[0] for e in base.expressions]
    assert sorted(first) == sorted(closed)
    want = np.array([closed[f] for f in first])
    beta = want + np.arange(1, base.rank + 1) * 1e-3
    vs = description_comparison(_model(robot, base, beta, np.full(base.rank, 2e-4)))
    np.testing.assert_allclose(vs.values, want, atol=1e-12)
    np.testing.assert_allclose(vs.z, np.arange(1, base.rank + 1) * 5.0, rtol=1e-9)
    assert vs.beyond == tuple(range(base.rank - 1, -1, -1))[: sum(vs.z > 3)]


def test_a_link_heavier_than_described_stands_out_alone(heavier_link5):
    """Link 5 10 % heavier: the base parameters holding link 5's parameters lie far from the
    description's (their shift over std as simulated), all others within 4 std of it."""
    described, truth, model = heavier_link5
    vs = description_comparison(model)
    truth_vs = description_comparison(
        _model(truth, model.base, model.fit.beta, model.fit.std)
    )  # the simulated arm's own base parameters, as described by the truth
    shift = (truth_vs.values - vs.values) / model.fit.std
    link5 = np.array(
        [bool(re.search(r"\b(m5|mc5[xyz]|J5[xyz]{2})\b", e)) for e in model.base.expressions]
    )
    assert link5.sum() >= 5 and not link5.all()
    assert np.max(np.abs(vs.z[~link5])) < 4.0
    assert np.sqrt(np.mean(vs.z[~link5] ** 2)) < 1.6
    assert np.max(np.abs(vs.z[link5])) > 50.0
    np.testing.assert_array_less(np.abs(vs.z - shift), 4.0)  # the known shift, to the noise
    far = vs.beyond
    assert far and all(link5[k] for k in far if abs(shift[k]) > 8) and link5[far[0]]
    said = vs.sentence()
    assert said.startswith("against the description's inertials (panda): RMS z ")
    assert f"{model.base.labels[far[0]]} = " in said and "beyond 3 std: " in said
    assert " more" in said  # only the largest few named


def test_the_table_the_file_and_the_report_hold_it(heavier_link5, tmp_path):
    """The printed table has the description's value and z per base parameter and the
    summary line; identification.json holds both per coefficient and vs_description (read
    back under its schema); the report's coefficients table shows them."""
    _, _, model = heavier_link5
    vs = description_comparison(model)
    text = format_identification(model)
    header = next(line for line in text.splitlines() if line.lstrip().startswith("#"))
    assert re.search(r"std %\s+description\s+z\s+kept\s+expression", header)
    k = vs.beyond[0]
    row = next(
        line for line in text.splitlines() if line.split()[:2] == [str(k + 1), f"beta{k + 1}"]
    )
    assert f"{vs.values[k]:+.6g}" in row and f"{vs.z[k]:+.1f}" in row
    assert vs.sentence() in text.splitlines()
    path = save_model_json(tmp_path / "identification.json", model)
    doc = model_to_dict(load_model_json(path))
    c = doc["coefficients"][k]
    assert c["description"] == pytest.approx(vs.values[k]) and c["z"] == pytest.approx(vs.z[k])
    assert doc["vs_description"]["beyond"][0] == {
        "name": f"beta{k + 1}",
        "z": pytest.approx(vs.z[k]),
    }
    assert (
        doc["vs_description"]["n_compared"] == 43 and doc["vs_description"]["said"] == vs.sentence()
    )
    html = _coefficients_section(doc)
    assert "z [std]" in html and "description&#x27;s value" in html and "RMS z" in html


def test_no_column_without_inertials_or_with_placeholders(heavier_link5):
    """A kinematic description (every inertial zero) and one with the same inertial on
    every link are not compared: no column, no summary line, no keys in the file."""
    described, _, model = heavier_link5
    same = np.tile(np.array(described.phi).reshape(7, 10)[3], (7, 1))
    for robot in (described.with_params(np.zeros((7, 10))), described.with_params(same)):
        assert not described_inertials(robot)
        other = _model(robot, model.base, model.fit.beta, model.fit.std)
        assert description_comparison(other) is None
        assert "description" not in format_identification(other)
        doc = model_to_dict(other)
        assert "vs_description" not in doc and "z" not in doc["coefficients"][0]
    assert described_inertials(planar_2r(l1=0.5, m1=1.5, I1=0.03))  # two links alike: its own


def test_base_parameters_holding_a_rotor_inertia_have_no_description_value():
    """With rotor inertias identified in the base (J1zz + ... + Ia1, Ia2) the description
    has no value for those, and they are left out of the z; the rest are compared."""
    robot = planar_2r()
    term = RotorInertia(Drive.from_gears(1.0, n=2))
    base = base_parameters(robot, terms=[term])
    rotor = np.array(["Ia" in e for e in base.expressions])
    assert rotor.sum() == 2 and base.n_std == 22
    held = {term.name: IdentifiedTerm(term, np.zeros(2), np.full(2, np.nan), np.zeros(2, bool))}
    model = _model(robot, base, np.ones(base.rank), np.full(base.rank, 0.1), held)
    vs = description_comparison(model)
    assert np.all(np.isnan(vs.values[rotor])) and np.all(np.isnan(vs.z[rotor]))
    assert np.all(np.isfinite(vs.z[~rotor])) and vs.n_compared == base.rank - 2
    assert "2 hold a rotor inertia, which the description does not give" in vs.sentence()


def test_exact_data_and_a_bad_threshold():
    """Standard deviations of zero (exact data) leave z undefined, said so; a threshold
    that is not a positive number is refused."""
    robot = planar_2r()
    base = base_parameters(robot)
    model = _model(robot, base, np.ones(base.rank), np.zeros(base.rank))
    vs = description_comparison(model)
    assert vs.n_compared == 0 and vs.rms_z is None and vs.as_dict()["rms_z"] is None
    assert "no standard deviations to weigh the differences by" in vs.sentence()
    with pytest.raises(OptionError, match=r"^threshold must be finite and above 0; got -1"):
        description_comparison(model, threshold=-1.0)
    with pytest.raises(OptionError, match=r"^threshold must be a number; got '3'"):
        description_comparison(model, threshold="3")  # type: ignore[arg-type]
