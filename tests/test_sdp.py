"""Convex retrieval and one-step consistent identification.

References: the coefficients of known (perturbed, consistent) Panda parameter sets, held-out
torques of a simulated robot with effects outside the rigid-body model, the pseudo-inertia
margin computed independently of the solver, and the unconstrained least squares.
"""

from __future__ import annotations

import numpy as np
import pytest

import dynid
from dynid.exceptions import InfeasibleError, ModelError, ShapeError
from dynid.feasibility.bounds import panda_bounds
from dynid.feasibility.convex import SDPOptions, identify_consistent, retrieve_sdp
from dynid.feasibility.lmi import pseudo_inertia_margin
from dynid.feasibility.prior import generic_prior, prior_from_robot
from dynid.friction.validation import own_friction
from dynid.identification.prepare import MEASURED, prepare_log
from dynid.identification.structure import Structure
from dynid.io.bounds_file import bounds_from_dict
from dynid.progress import reporting
from dynid.simulation.measurement import SensorNoise, sample_times, simulate_measurement
from dynid.simulation.trajectories import random_fourier
from dynid.simulation.unmodelled import UnmodelledEffects

from conftest import exact_model, perturbed_robot, robot_data_urdf


def test_exact_coefficients_of_perturbed_pandas_are_met_with_plausible_masses():
    """beta to 1e-9, margins >= 1e-4, masses >= 0.3 kg, median mass error <= 0.7 of the prior's."""
    robot = dynid.panda()
    ours, prior_err = [], []
    for seed in range(8):
        truth = perturbed_robot(robot, np.random.default_rng(seed))
        model = exact_model(robot, truth)
        res = retrieve_sdp(model, prior=robot)
        beta = model.beta
        P = model.base.projection
        assert np.linalg.norm(P @ res.phi.reshape(-1) - beta) <= 1e-9 * np.linalg.norm(beta)
        assert res.fit == "equality" and res.feasible
        assert pseudo_inertia_margin(res.phi).min() >= 1e-4 * (1 - 1e-9)
        assert res.mass.min() >= 0.3
        # the retrieved robot reproduces the truth's M and g (the coefficients fix them)
        q = np.random.default_rng(100 + seed).uniform(robot.q_min, robot.q_max, (20, 7))
        np.testing.assert_allclose(
            dynid.mass_matrix(res.robot, q), dynid.mass_matrix(truth, q), atol=1e-9
        )
        mt = truth.mass
        ours.append(np.median(np.abs(res.mass - mt)[1:] / mt[1:]))
        prior_err.append(np.median(np.abs(robot.mass - mt)[1:] / mt[1:]))
    assert np.median(ours) <= 0.7 * np.median(prior_err)


def test_noisy_static_coefficients_with_model_error_give_a_strictly_consistent_set():
    """Rotor inertia and a gravity tilt make beta inconsistent; the result is still consistent
    and says how far the data are from a rigid body."""
    robot = dynid.panda()
    eff = UnmodelledEffects.typical(7, np.random.default_rng(3))
    ctl = dynid.SimulatedController(
        robot, relative_noise=1e-4, rng=np.random.default_rng(1), effects=eff
    )
    data = dynid.acquire_static(ctl, 300, np.random.default_rng(2))
    with pytest.warns(dynid.DynidWarning, match="g1"):
        model = dynid.identify_static(robot, data)
    # the unconstrained coefficients admit no consistent set (the equality is infeasible)
    exact = retrieve_sdp(model, prior=robot, options=SDPOptions(fit="equality"))
    assert exact.status == "infeasible" and not exact.feasible
    assert exact.relative_residual > 1e-6
    res = retrieve_sdp(model, prior=robot)
    assert res.fit == "weighted" and res.feasible
    assert pseudo_inertia_margin(res.phi).min() >= 1e-4 * (1 - 1e-9)
    assert res.residual_ratio > 1.0 and res.relative_residual < 0.05
    assert any("not consistent with a rigid body" in s or "prior weight" in s for s in res.notes)


@pytest.mark.filterwarnings("ignore:.*indistinguishable from zero")  # expected: weak coefficients
def test_one_step_on_a_log_with_model_error_predicts_held_out_torques_like_least_squares():
    """Held-out torque RMS within 10 % of the unconstrained identification's, of the
    structure given (classical friction)."""
    robot = dynid.panda()
    eff = UnmodelledEffects.typical(7, np.random.default_rng(4))

    def log(seed: int, duration: float) -> dynid.TorqueLog:
        rng = np.random.default_rng(seed)
        traj = random_fourier(robot, rng, n_harmonics=5)(sample_times(duration, 1000.0))
        return simulate_measurement(robot, traj, rng=rng, noise=SensorNoise(), effects=eff)

    classical = Structure.parse("viscous,coulomb,offset")  # given: not chosen on held-out data
    res = identify_consistent(robot, log(5, 20.0), prior=robot, structure=classical)
    assert res.kind == "log" and res.feasible and res.friction is not None
    assert pseudo_inertia_margin(res.phi).min() >= 1e-4 * (1 - 1e-9)
    p = prepare_log(log(15, 10.0), MEASURED)
    ols = res.identified
    assert ols is not None and ols.friction is not None
    own = own_friction(ols)
    assert own is not None and own.law.name == res.friction.law.name
    tau_ols = ols.torques(p.q, p.dq, p.ddq) + own.torques(p.dq)
    tau_c = dynid.rnea(res.robot, p.q, p.dq, p.ddq) + res.friction.torques(p.dq)
    rms_ols = np.sqrt(np.mean((tau_ols - p.tau) ** 2))
    rms_c = np.sqrt(np.mean((tau_c - p.tau) ** 2))
    assert rms_c <= 1.1 * rms_ols


def test_one_step_on_static_data_without_model_error_reproduces_m_and_g():
    """Static one-step with noise: M and g of the result within the noise of the truth's;
    each solve is told to a progress callback."""
    robot = dynid.panda()
    ctl = dynid.SimulatedController(robot, relative_noise=1e-4, rng=np.random.default_rng(7))
    data = dynid.acquire_static(ctl, 200, np.random.default_rng(8))
    told: list[str] = []
    with reporting(told.append):  # a fit of minutes on a long log was silent throughout
        res = identify_consistent(robot, data, prior=robot)
    assert any(t.startswith("the consistent fit") and "solving at prior weight" in t for t in told)
    assert res.kind == "static" and res.feasible and res.residual_ratio <= 1.01 + 1e-9
    q = np.random.default_rng(9).uniform(robot.q_min, robot.q_max, (50, 7))
    g_true = dynid.gravity_torques(robot, q)
    g = dynid.gravity_torques(res.robot, q)
    assert np.max(np.abs(g - g_true)) < 1e-2 * np.max(np.abs(g_true))


def test_generic_prior_of_a_ur5_is_consistent_and_retrieval_runs_without_a_prior():
    """UR5 from its URDF: the cylinders are strictly consistent; exact coefficients are met
    with them and with the default prior (the URDF's own inertials)."""
    ur5 = dynid.Robot.from_urdf(
        robot_data_urdf("ur_description/urdf/ur5_robot.urdf"),
        base_link="base_link",
        tip_link="tool0",
    )
    pr = generic_prior(ur5, total_mass=(15.0, 25.0))
    assert pseudo_inertia_margin(pr.phi).min() > 2e-4
    natural = generic_prior(ur5).mass.sum()  # scaled into the band, to its nearer end
    assert pr.mass.sum() == pytest.approx(min(max(natural, 15.0), 25.0))
    model = exact_model(ur5, ur5)
    res = retrieve_sdp(model, prior=generic_prior(ur5))  # a prior from the kinematics
    assert res.feasible and res.prior.generic
    assert res.relative_residual < 1e-9
    own = retrieve_sdp(model)  # without one: the description's inertials
    assert own.feasible and own.prior.source == "description"
    assert own.relative_residual < 1e-9


def test_a_prior_mass_above_the_generic_bound_is_kept_not_capped():
    """A UR5 whose shoulder link weighs 25 kg (a PR2's weighs 25.8 kg), above the generic
    bound of 10.4 kg from its length: with its description as the prior, exact
    coefficients give the shoulder's 25 kg (it was capped at 10.43 kg), and a note says
    which bound gave way. A bounds file's own mass bounds still hold."""
    ur5 = dynid.Robot.from_urdf(
        robot_data_urdf("ur_description/urdf/ur5_robot.urdf"),
        base_link="base_link",
        tip_link="tool0",
    )
    mass = ur5.mass.copy()
    mass[0] = 25.0
    heavy = ur5.with_inertials(mass, ur5.com, ur5.inertia * (mass / ur5.mass)[:, None, None])
    model = exact_model(ur5, heavy)
    res = retrieve_sdp(model, prior=heavy)
    assert res.feasible and res.mass[0] == pytest.approx(25.0, rel=1e-3)
    said = "link 1: the prior's mass 25 kg lies above the generic bound"
    assert any(said in n for n in res.notes)
    given = bounds_from_dict({"links": [{"name": ur5.link_names[1], "mass": [0.5, 12.0]}]}, ur5)
    capped = retrieve_sdp(model, prior=heavy, bounds=given)
    assert capped.mass[0] <= 12.0 * (1 + 1e-6)


def test_a_cad_prior_violating_the_triangle_inequality_is_repaired_and_reported():
    """The impossible link is floored onto the margin, and a note names it."""
    robot = dynid.panda()
    m, c, I = robot.mass.copy(), robot.com.copy(), robot.inertia.copy()
    I[3] = np.diag([0.01, 0.01, 0.05])  # Izz > Ixx + Iyy
    bad = robot.with_inertials(m, c, I)
    pr = prior_from_robot(bad, source="cad.urdf", total_mass=(30.0, 40.0))
    assert 4 in pr.repaired
    assert any("4 (link4" in s and "floored" in s for s in pr.notes)
    assert any("outside the band" in s for s in pr.notes)
    assert pseudo_inertia_margin(pr.phi).min() >= 2e-4 * (1 - 1e-9)


def test_bad_inputs_raise_one_clear_error():
    """Contradictory band, prior of another robot, bad options, a prior without inertials."""
    robot = dynid.panda()
    model = exact_model(robot, robot)
    with pytest.raises(InfeasibleError, match="cannot be met"):
        retrieve_sdp(model, prior=robot, total_mass=(100.0, 120.0))
    ur5 = dynid.Robot.from_urdf(
        robot_data_urdf("ur_description/urdf/ur5_robot.urdf"),
        base_link="base_link",
        tip_link="tool0",
    )
    with pytest.raises(ShapeError, match="6 links"):
        retrieve_sdp(model, prior=ur5)
    with pytest.raises(ModelError, match="objective"):
        SDPOptions(objective="l1")
    with pytest.raises(ModelError, match="prior weight"):
        SDPOptions(prior_weight=-1.0)
    with pytest.raises(ModelError, match="no link inertials"):
        prior_from_robot(robot.with_params(np.zeros(70)))


def test_a_user_constraint_and_the_euclidean_objective_are_honoured():
    """Link 7's CoM kept within 1 cm of its axis (second-order cone), Euclidean pull."""
    import cvxpy as cp

    robot = dynid.panda()
    truth = perturbed_robot(robot, np.random.default_rng(11))
    model = exact_model(robot, truth)

    def com7_near_axis(phi, J):
        return [cp.norm(phi[6][1:3]) <= 0.01 * phi[6][0]]

    res = retrieve_sdp(
        model,
        prior=robot,
        bounds=panda_bounds(),
        options=SDPOptions(objective="euclidean"),
        constraints=[com7_near_axis],
    )
    assert res.feasible
    assert np.linalg.norm(res.com[6, :2]) <= 0.01 + 1e-7


def test_an_arm_with_a_prismatic_joint_is_retrieved_from_noisy_static_data():
    """RPR arm (closed-form bodies): one-step on static data gives a consistent set whose M and
    g match the truth's at held-out configurations to the noise level."""
    rng = np.random.default_rng(41)
    robot = dynid.Robot.from_mdh(
        [0.0, 0.1, 0.2],
        [0.3, 0.0, 0.1],
        [0.0, np.pi / 2, -np.pi / 2],
        joint_types="RPR",
        q_min=[-2.0, 0.0, -2.0],
        q_max=[2.0, 0.5, 2.0],
    )
    box = lambda m, a: np.diag(m / 12.0 * (np.sum(a**2) - a**2))  # noqa: E731 (uniform boxes)
    dims = [np.array([0.1, 0.1, 0.3]), np.array([0.08, 0.08, 0.5]), np.array([0.3, 0.06, 0.06])]
    truth = robot.with_inertials(
        [3.0, 2.0, 1.0],
        [[0.0, 0.0, -0.1], [0.0, 0.0, -0.2], [0.1, 0.0, 0.0]],
        np.stack([box(m, a) for m, a in zip([3.0, 2.0, 1.0], dims, strict=True)]),
    )
    ctl = dynid.SimulatedController(truth, relative_noise=1e-4, rng=rng)
    data = dynid.acquire_static(ctl, 300, rng)
    res = identify_consistent(robot, data)  # generic prior from the kinematics
    assert res.feasible and res.robot.prismatic[1]
    assert pseudo_inertia_margin(res.phi).min() >= 1e-4 * (1 - 1e-9)
    q = rng.uniform(robot.q_min, robot.q_max, (50, 3))
    g = dynid.gravity_torques(truth, q)
    np.testing.assert_allclose(dynid.gravity_torques(res.robot, q), g, atol=1e-2 * np.abs(g).max())
    M = dynid.mass_matrix(truth, q)
    np.testing.assert_allclose(dynid.mass_matrix(res.robot, q), M, atol=1e-2 * np.abs(M).max())


def test_specifications_that_exclude_the_robot_are_reported_not_hidden():
    """A margin above the truth's fails data_fit and names the options; a total-mass band the
    data leave open is met and the bounds that decided it are named; a bad covariance is refused."""
    import dataclasses

    from dynid.exceptions import DataError

    robot = dynid.panda()
    ctl = dynid.SimulatedController(robot, relative_noise=1e-4, rng=np.random.default_rng(51))
    data = dynid.acquire_static(ctl, 200, np.random.default_rng(52))
    model = dynid.identify_static(robot, data)
    tight = retrieve_sdp(model, prior=robot, options=SDPOptions(margin=0.02, prior_weight=1.0))
    assert not tight.feasible and tight.residual_ratio > 1.1
    assert any("--margin" in s for s in tight.notes)
    heavy = retrieve_sdp(model, prior=robot, total_mass=(19.5, 20.0))
    assert heavy.robot.mass.sum() >= 19.5 - 1e-6
    assert any("decided by the bound, not the data" in s and "total mass" in s for s in heavy.notes)
    no_cov = dataclasses.replace(model, fit=dataclasses.replace(model.fit, covariance=None))
    assert any("no covariance" in s for s in retrieve_sdp(no_cov, prior=robot).notes)
    bad = dataclasses.replace(
        model, fit=dataclasses.replace(model.fit, covariance=-np.asarray(model.fit.covariance))
    )
    with pytest.raises(DataError, match="not positive semidefinite"):
        retrieve_sdp(bad, prior=robot)


def test_implausible_note_says_when_the_prior_holds_the_same_inertia():
    """Regression: an implausible radius of gyration was blamed on absorbed rotor inertia or
    unseen inertia even when the prior (a UR5's URDF) held it itself; with the prior's link
    implausible too the note says "the prior has it too", else it keeps the causes."""
    robot = dynid.panda()
    I = robot.inertia.copy()
    I[-1] *= 20.0  # link 7: radius of gyration sqrt(tr(I) / 2 m) = 0.61 m, extent 0.15 m
    truth = robot.with_inertials(robot.mass, robot.com, I)
    rg = np.sqrt(np.trace(I[-1]) / (2.0 * robot.mass[-1]))
    model = exact_model(robot, truth)
    same = [s for s in retrieve_sdp(model, prior=truth).notes if s.startswith("implausible")]
    assert len(same) == 1 and same[0].startswith("implausible: link7 has a radius of gyration")
    assert same[0].endswith(f"the prior has it too ({rg:.3g} m)"), same
    own = [s for s in retrieve_sdp(model, prior=robot).notes if s.startswith("implausible")]
    assert len(own) == 1 and own[0].startswith("implausible: link7 has a radius of gyration")
    assert "prior" not in own[0] and "rotor inertia the link absorbed" in own[0], own


def test_a_light_link_the_prior_holds_too_is_not_called_implausible():
    """Regression: a UR10's wrist 3 link, 0.202 kg of 28 kg, was noted "implausible ...
    under 1 % of the total; the prior has it too" although it is the arm's own; a light
    link the prior holds alike is no finding."""
    robot = dynid.panda()
    m = robot.mass.copy()
    m[-1] = 0.1  # under 1 % of the Panda's 18 kg
    truth = robot.with_inertials(m, robot.com, robot.inertia)
    model = exact_model(robot, truth)
    got = retrieve_sdp(model, prior=truth)
    assert abs(got.robot.mass[-1] - 0.1) < 0.01  # light indeed, as the description's
    light = [s for s in got.notes if "weighs" in s]
    assert light == [], light
