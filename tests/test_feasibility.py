"""Feasibility constraints, the penalised objective, Algorithm 1 and the Newton-Euler validation.

References: closed forms of the inertia of a thin rod, a solid box (any orientation) and
of impossible tensors; the identified model's own torques (Y_b beta) for the retrieved
parameters; Pinocchio-independent identities only (the exports are cross-checked with
Pinocchio in test_export.py).
"""

from __future__ import annotations

import importlib.util
import sys
from pathlib import Path

import numpy as np
import pytest

import dynid
from dynid.exceptions import DataError, InfeasibleError, ShapeError, WrongTypeError
from dynid.feasibility.bounds import Bounds, default_bounds, kinematic_bounds, panda_bounds
from dynid.feasibility.constraints import (
    UserConstraint,
    feasibility_report,
    is_physically_valid,
    link_params,
    user_constraints,
)
from dynid.feasibility.penalty import (
    RetrievalOptions,
    coefficient_problem,
    phi_from_params,
    retrieve,
    retrieve_from_coefficients,
    retrieve_from_static,
)
from dynid.friction.validation import validate_newton_euler
from dynid.identification.model import IdentifiedModel
from dynid.regressors.base import base_parameters

from conftest import exact_model, perturbed_robot, random_states, robot_data_urdf

EXAMPLES = Path(__file__).resolve().parents[1] / "examples"
PHYSICAL = ("mass_positive", "inertia_positive_definite", "triangle_inequality")


# ------------------------------------------------------------------------ helpers
def _rotation(rng: np.random.Generator) -> np.ndarray:
    Q, R = np.linalg.qr(rng.normal(size=(3, 3)))
    Q = Q * np.sign(np.diag(R))
    return Q if np.linalg.det(Q) > 0 else -Q


def _one_link(m: float, I: np.ndarray, c=(0.0, 0.0, 0.0)):
    return (np.array([m]), np.array([c], dtype=float), I[None])


def _noise_free_model(robot: dynid.Robot, kept: np.ndarray | None = None) -> IdentifiedModel:
    """An IdentifiedModel holding the exact coefficients of ``robot``'s own parameters."""
    return exact_model(robot, robot, kept=kept)


def _torque_rel_error(a: dynid.Robot, model: IdentifiedModel, seed: int) -> float:
    q, dq, ddq = random_states(a, 1000, seed)
    tau_a = dynid.rnea(a, q, dq, ddq)
    tau_b = model.torques(q, dq, ddq)
    return float(np.max(np.abs(tau_a - tau_b)) / np.max(np.abs(tau_b)))


def _physical_min_margin(result) -> float:
    return min(result.report.min_margin(n) for n in PHYSICAL)


# ------------------------------------------------------------------------ closed forms
def test_thin_rod_violates_nothing():
    """A thin rod (one principal moment 0, triangle inequality tight) is physically valid."""
    rng = np.random.default_rng(1)
    m, L = 2.0, 0.8
    R = _rotation(rng)
    I = R @ np.diag([0.0, m * L**2 / 12, m * L**2 / 12]) @ R.T
    rep = feasibility_report(_one_link(m, I, (0.1, 0.0, 0.0)))
    assert rep.ok and is_physically_valid(_one_link(m, I))
    assert abs(rep.min_margin("inertia_positive_definite")) < 1e-15
    assert abs(rep.min_margin("triangle_inequality")) < 1e-15


def test_solid_box_margins_match_closed_form():
    """A rotated solid box a x b x c: lambda_min = m (a^2 + b^2) / 12 (smallest two sides),
    triangle margin = m a^2 / 12 (a the shortest side)."""
    rng = np.random.default_rng(2)
    m, (a, b, c) = 3.0, (0.1, 0.2, 0.3)
    I0 = m / 12 * np.diag([b * b + c * c, a * a + c * c, a * a + b * b])
    R = _rotation(rng)
    rep = feasibility_report(_one_link(m, R @ I0 @ R.T))
    assert rep.ok
    np.testing.assert_allclose(
        rep.min_margin("inertia_positive_definite"), m * (a * a + b * b) / 12, rtol=1e-12
    )
    np.testing.assert_allclose(rep.min_margin("triangle_inequality"), m * a * a / 12, rtol=1e-12)
    np.testing.assert_allclose(rep.min_margin("mass_positive"), m)


def test_impossible_tensor_violates_triangle_inequality():
    """Principal moments (1, 1, 3) are positive but no body has them (1 + 1 < 3)."""
    rep = feasibility_report(_one_link(1.0, np.diag([1.0, 1.0, 3.0])))
    assert not rep.ok
    assert [c.name for c in rep.violated] == ["triangle_inequality"]
    np.testing.assert_allclose(rep.min_margin("triangle_inequality"), 2.5 - 3.0)
    assert "triangle_inequality" in str(rep)


def test_negative_moment_violates_positive_definiteness():
    """A negative principal moment violates positive definiteness (and the triangle inequality)."""
    rep = feasibility_report(_one_link(1.0, np.diag([-0.1, 1.0, 1.0])))
    names = {c.name for c in rep.violated}
    assert names == {"inertia_positive_definite", "triangle_inequality"}
    np.testing.assert_allclose(rep.min_margin("inertia_positive_definite"), -0.1)


def test_zero_mass_is_not_positive():
    """The mass must be strictly positive."""
    rep = feasibility_report(_one_link(0.0, np.zeros((3, 3))))
    assert [c.name for c in rep.violated] == ["mass_positive"]


def test_bounds_and_total_mass_margins_closed_form():
    """Box and total-mass margins are the distances to the nearest face."""
    b = Bounds(
        mass_min=[0.0],
        mass_max=[2.0],
        com_min=[[-0.1, -0.1, -0.1]],
        com_max=[[0.1, 0.2, 0.1]],
        inertia_min=[[0, -1, -1, 0, -1, 0]],
        inertia_max=[[1, 1, 1, 1, 1, 1]],
        total_mass=(1.0, 1.8),
    )
    I = np.diag([0.2, 0.3, 0.4])
    rep = feasibility_report(_one_link(1.5, I, (0.05, 0.15, -0.02)), b)
    got = {c.name: c.margin for c in rep.constraints}
    np.testing.assert_allclose(got["com_in_box"], 0.05)
    np.testing.assert_allclose(got["mass_in_bounds"], 0.5)
    np.testing.assert_allclose(got["inertia_in_bounds"], 0.2)
    np.testing.assert_allclose(got["total_mass_min"], 0.5)
    np.testing.assert_allclose(got["total_mass_max"], 0.3)
    assert rep.ok
    rep2 = feasibility_report(_one_link(1.5, I, (0.15, 0.0, 0.0)), b, total_mass=(1.6, 3.0))
    assert {c.name for c in rep2.violated} == {"com_in_box", "total_mass_min"}


def test_published_panda_is_valid_and_identified_equivalent_is_reported_not_rejected():
    """The published p_hat is valid; an identified model's equivalent parameter set is held
    (a Robot) and reported infeasible rather than rejected."""
    panda = dynid.panda()
    assert is_physically_valid(panda)
    assert feasibility_report(panda, panda_bounds()).ok
    eq = _noise_free_model(panda).equivalent_robot
    rep = feasibility_report(eq)
    assert not rep.ok and not is_physically_valid(eq)
    assert len(rep.constraints) == 3 * panda.n


def test_link_params_accepts_robot_phi_and_inertials():
    """Robot, phi (n, 10) or (10 n,) and (mass, com, inertia) give the same parameters."""
    panda = dynid.panda()
    p = link_params(panda)
    np.testing.assert_allclose(link_params(panda.phi.reshape(-1)), p, atol=1e-15)
    np.testing.assert_allclose(link_params((panda.mass, panda.com, panda.inertia)), p, atol=1e-15)
    np.testing.assert_allclose(phi_from_params(p), panda.phi, atol=1e-15)
    with pytest.raises(ShapeError, match="phi must have shape"):
        link_params(np.zeros((3, 7)))


def test_default_bounds_contain_the_true_parameters():
    """Panda bounds contain p_hat; generic kinematic bounds contain the Panda and UR5 values."""
    panda = dynid.panda()
    assert default_bounds(panda).total_mass == (16.0, 20.0)
    assert feasibility_report(panda, kinematic_bounds(panda)).ok
    ur5 = dynid.Robot.from_urdf(
        robot_data_urdf("ur_description/urdf/ur5_robot.urdf"), "base_link", "tool0"
    )
    b = default_bounds(ur5)
    assert b.total_mass is None and b.link_names == ur5.link_names[1:]
    assert feasibility_report(ur5, b).ok


def test_bounds_reject_inconsistent_values():
    """A lower bound above its upper bound, a negative mass or a bad band raise ValueError."""
    b = panda_bounds()
    lo, hi = b.lower, b.upper
    with pytest.raises(ValueError, match="must not exceed"):
        Bounds.from_arrays(hi, lo)
    lo2 = lo.copy()
    lo2[0, 0] = -1.0
    with pytest.raises(ValueError, match="mass_min must be >= 0"):
        Bounds.from_arrays(lo2, hi)
    with pytest.raises(ValueError, match="total_mass"):
        b.with_total_mass((5.0, 1.0))
    with pytest.raises(ShapeError):
        Bounds.from_arrays(lo[:, :9], hi[:, :9])


def test_user_constraints_are_normalised_and_checked():
    """Callables, (name, callable) pairs and UserConstraint are accepted; others raise."""

    def com_x_nonneg(p):
        return max(0.0, -float(p[0, 1]))

    ucs = user_constraints(
        [com_x_nonneg, ("named", com_x_nonneg), UserConstraint("u", com_x_nonneg, 1)]
    )
    assert [u.name for u in ucs] == ["com_x_nonneg", "named", "u"]
    with pytest.raises(TypeError, match="extra\\[0\\]"):
        user_constraints([3.0])
    rep = feasibility_report(_one_link(1.0, np.eye(3) * 0.1, (-0.2, 0, 0)), extra=[com_x_nonneg])
    (c,) = rep.select("com_x_nonneg")
    assert not c.satisfied and c.margin == pytest.approx(-0.2)


# ------------------------------------------------------------------------ penalty
def test_penalty_jacobians_match_finite_differences():
    """Analytic Jacobians of the data residual and of the violations match central differences."""
    rng = np.random.default_rng(3)
    panda = dynid.panda()
    base = base_parameters(panda)
    prob = coefficient_problem(panda, base, base.beta_from_phi(panda.phi))
    for _ in range(3):
        z = rng.uniform(0.05, 0.95, prob.dim)
        h = 1e-6
        E = np.eye(prob.dim) * h
        J = prob.residual_jacobian(z)
        Jn = np.stack(
            [
                (prob.residual(z + E[k]) - prob.residual(z - E[k])) / (2 * h)
                for k in range(prob.dim)
            ],
            1,
        )
        np.testing.assert_allclose(J, Jn, atol=1e-6 * np.abs(J).max())
        K = prob.violation_jacobian(z, band=np.inf)  # every row, signed slacks
        Kn = np.stack(
            [(prob.slacks(z + E[k]) - prob.slacks(z - E[k])) / (2 * h) for k in range(prob.dim)], 1
        )
        np.testing.assert_allclose(K, Kn, atol=1e-6 * np.abs(K).max())


def test_coefficient_problem_errors():
    """Wrong coefficient count raises ShapeError; no kept coefficient raises DataError."""
    panda = dynid.panda()
    base = base_parameters(panda)
    with pytest.raises(ShapeError, match="beta must have shape"):
        coefficient_problem(panda, base, np.zeros(3))
    with pytest.raises(DataError, match="no kept"):
        coefficient_problem(panda, base, np.zeros(base.rank), kept=np.zeros(base.rank, bool))


def test_options_validate_schedule():
    """The xi schedule starts at 0 and has one weight per stage; bad settings raise."""
    assert RetrievalOptions(stages=3).schedule() == (0.0, 1.0, 100.0)
    with pytest.raises(ValueError, match="one weight per stage"):
        RetrievalOptions(stages=3, xi=(0.0, 1.0))
    with pytest.raises(ValueError):
        RetrievalOptions(runs=0)


# ------------------------------------------------------------------------ retrieval
@pytest.fixture(scope="module")
def panda_retrieval():
    """Retrieval from the noise-free coefficients of dynid.panda() wrapped in an IdentifiedModel."""
    panda = dynid.panda()
    model = _noise_free_model(panda)
    return panda, model, retrieve(model, options=RetrievalOptions(runs=4), workers=1, seed=0)


def test_panda_retrieval_is_feasible_with_margin_and_matches_the_coefficients(panda_retrieval):
    """Noise-free Panda: every constraint holds with margin, residual <= 1e-4, and RNEA with
    the retrieved parameters equals the identified model's torques on 1000 random states."""
    panda, model, res = panda_retrieval
    assert res.feasible and res.report.ok
    assert res.relative_residual <= 1e-4
    margin_target = res.options.margin * res.bounds.inertia_scale().min()
    assert _physical_min_margin(res) >= 0.5 * margin_target > 0
    for c in res.report.constraints:
        assert c.margin > 0, c
    assert _torque_rel_error(res.robot, model, seed=4) <= 1e-3
    assert len(res.runs) == 4 and res.stage_costs.shape == (res.options.stages,)
    assert res.robot.friction is not None  # carried over from the input robot
    # distance from the true parameters, per link (not identifiable, so only recorded)
    d = res.distance_from(panda)
    assert d.mass.shape == d.com.shape == d.inertia.shape == (panda.n,)
    assert np.all(np.isfinite(d.mass)) and np.all(np.isfinite(d.inertia))
    total = float(np.sum(res.mass))
    assert 16.0 < total < 20.0


def test_penalty_retrieval_says_its_implausible_links():
    """Regression: the penalty method said nothing of implausible links (run on a Panda's
    coefficients it put 0.158 kg in link 7, under 1 % of 17.3 kg); a link 7 of 0.1 kg in
    the coefficients (the description's 0.74) is now a note, as the convex method's; the
    notes name exactly the links under 1 % of the retrieved total."""
    panda = dynid.panda()
    m = panda.mass.copy()
    m[-1] = 0.1
    model = exact_model(panda, panda.with_inertials(m, panda.com, panda.inertia))
    res = retrieve(model, options=RetrievalOptions(runs=2), workers=1, seed=0)
    light = [name for name, x in zip(panda.link_names[1:], res.mass, strict=True)
             if x < 0.01 * float(np.sum(res.mass))]  # fmt: skip
    said = [s for s in res.notes if "weighs" in s]
    assert light == ["link7"] and abs(res.mass[-1] - 0.1) < 0.02, res.mass
    assert len(said) == 1 and said[0].startswith("implausible: link7 weighs"), said
    assert said[0].endswith("under 1 % of the total"), said  # the prior's link is not light


def test_pruned_coefficients_are_ignored():
    """A coefficient removed by pruning (kept False) does not enter the objective."""
    panda = dynid.panda()
    kept = np.ones(base_parameters(panda).rank, bool)
    kept[[3, 10]] = False
    model = _noise_free_model(panda, kept)
    res = retrieve(model, options=RetrievalOptions(runs=2), workers=1, seed=1)
    assert res.feasible and res.relative_residual <= 1e-4


def test_ur5_from_urdf_retrieval():
    """UR5 from URDF (generic kinematic bounds): feasible, exact coefficients, same torques."""
    ur5 = dynid.Robot.from_urdf(
        robot_data_urdf("ur_description/urdf/ur5_robot.urdf"), "base_link", "tool0"
    )
    model = _noise_free_model(ur5)
    res = retrieve(model, options=RetrievalOptions(runs=3), workers=1, seed=0)
    assert res.feasible and res.relative_residual <= 1e-4
    assert _physical_min_margin(res) > 0
    assert _torque_rel_error(res.robot, model, seed=5) <= 1e-3
    assert res.distance_from(ur5).mass.shape == (6,)


def test_contradictory_total_mass_band_is_reported_infeasible():
    """A total-mass band of 1..3 kg contradicts the Panda's first moments: feasible False,
    the least-violating solution and its margins are returned; require_feasible raises."""
    panda = dynid.panda()
    model = _noise_free_model(panda)
    opts = RetrievalOptions(runs=2)
    res = retrieve(model, total_mass=(1.0, 3.0), options=opts, workers=1, seed=0)
    assert not res.feasible and not res.report.ok and res.report.violated
    assert res.total_mass == (1.0, 3.0)
    assert len(res.report.select("total_mass_max")) == 1  # the band is reported with its margin
    assert len(res.report.select("data_fit")) == 1
    assert res.best_run == min(res.runs, key=lambda r: (r.violation, r.stage_costs[-1])).index
    assert np.all(np.isfinite(res.mass))
    with pytest.raises(InfeasibleError, match="no feasible parameters"):
        retrieve(
            model,
            total_mass=(1.0, 3.0),
            options=RetrievalOptions(runs=1, stages=2),
            workers=1,
            seed=0,
            require_feasible=True,
        )


def test_retrieval_is_reproducible_whatever_the_number_of_workers():
    """Same seed: identical runs with 1 and 2 worker processes; progress reported per run."""
    panda = dynid.panda()
    base = base_parameters(panda)
    beta = base.beta_from_phi(panda.phi)
    opts = RetrievalOptions(runs=3, stages=3)
    seen = []
    a = retrieve_from_coefficients(
        panda, base, beta, options=opts, workers=1, seed=7, progress=seen.append
    )
    b = retrieve_from_coefficients(panda, base, beta, options=opts, workers=2, seed=7)
    assert [p.done for p in seen] == [1, 2, 3] and seen[-1].total == 3
    for ra, rb in zip(a.runs, b.runs, strict=True):
        np.testing.assert_array_equal(ra.p, rb.p)
        np.testing.assert_array_equal(ra.stage_costs, rb.stage_costs)
    assert a.best_run == b.best_run and b.workers == 2
    one = RetrievalOptions(runs=1, stages=3)  # another seed's first run: one is enough
    c = retrieve_from_coefficients(panda, base, beta, options=one, workers=1, seed=8)
    assert not np.array_equal(c.runs[0].p, a.runs[0].p)


def test_user_constraint_example_works():
    """The shipped example's cylinder constraint holds on the retrieved CoM of link 7."""
    spec = importlib.util.spec_from_file_location(
        "feasible_com_in_cylinder", EXAMPLES / "feasible_com_in_cylinder.py"
    )
    mod = importlib.util.module_from_spec(spec)
    sys.modules[spec.name] = mod
    spec.loader.exec_module(mod)
    cyl = mod.CoMInCylinder(link=7, radius=0.02, z_min=0.0, z_max=0.107)
    panda = dynid.panda()
    base = base_parameters(panda)
    res = retrieve_from_coefficients(
        panda,
        base,
        base.beta_from_phi(panda.phi),
        extra=[UserConstraint("cyl", cyl, 7)],
        options=RetrievalOptions(runs=3),
        workers=1,
        seed=0,
    )
    assert res.feasible and res.relative_residual <= 1e-4
    c7 = res.com[6]
    assert np.hypot(c7[0], c7[1]) <= 0.02 + 1e-9 and 0.0 <= c7[2] <= 0.107
    assert res.report.select("cyl")[0].satisfied


def test_single_step_static_retrieval():
    """Single-step variant on noise-free static data: feasible, ||Y_s phi - s|| / ||s|| <= 1e-4,
    and the torques of the retrieved parameters equal the true ones."""
    panda = dynid.panda()
    rng = np.random.default_rng(6)
    q = random_states(panda, 60, 6)[0]
    M, g = dynid.mass_matrix(panda, q), dynid.gravity_torques(panda, q)
    res = retrieve_from_static(
        panda, (q, M, g), options=RetrievalOptions(runs=3), workers=1, seed=0
    )
    assert res.kind == "static" and res.feasible
    assert res.relative_residual <= 1e-4
    qs, dq, ddq = random_states(panda, 1000, int(rng.integers(100)))
    a, b = dynid.rnea(res.robot, qs, dq, ddq), dynid.rnea(panda, qs, dq, ddq)
    assert np.max(np.abs(a - b)) / np.max(np.abs(b)) <= 1e-3


# ------------------------------------------------------------------------ validation
def test_newton_euler_validation_of_exact_data():
    """RNEA + the robot's sigmoid friction reproduce exact torques (RMS ~ 0); without
    friction the RMS equals that of the friction torques."""
    panda = dynid.panda()
    q, dq, ddq = random_states(panda, 300, 7)
    t = np.arange(300) * 1e-3
    fr = panda.friction
    tau = dynid.rnea(panda, q, dq, ddq) + fr.torques(dq)
    val = validate_newton_euler(panda, t, q, dq, ddq, tau, reference=_noise_free_model(panda))
    assert val.friction_kind == "sigmoid"
    assert np.max(val.rms) < 1e-10 and np.max(val.errors_reference.rms) < 1e-9
    np.testing.assert_allclose(
        val.errors_rigid.rms, np.sqrt(np.mean(fr.torques(dq) ** 2, axis=0)), rtol=1e-10
    )
    none = validate_newton_euler(panda, t, q, dq, ddq, tau, friction=None)
    assert none.tau_friction is None and none.friction_kind is None
    assert set(val.as_dict()) >= {"newton_euler", "newton_euler_no_friction", "identified_model"}


def test_newton_euler_validation_shape_errors():
    """Arrays of the wrong shape and a friction model for another joint count raise ShapeError."""
    panda = dynid.panda()
    q, dq, ddq = random_states(panda, 10, 8)
    t = np.arange(10) * 1e-3
    with pytest.raises(ShapeError, match="tau must have shape"):
        validate_newton_euler(panda, t, q, dq, ddq, np.zeros((10, 6)))
    two = dynid.SigmoidFriction.from_array(np.ones((2, 3)))
    with pytest.raises(ShapeError, match="friction model has 2 joints"):
        validate_newton_euler(panda, t, q, dq, ddq, np.zeros((10, 7)), friction=two)
    with pytest.raises(WrongTypeError, match="SigmoidFriction.from_array"):  # a bare array
        validate_newton_euler(panda, t, q, dq, ddq, np.zeros((10, 7)), friction=np.ones((7, 3)))


def test_feasible_figures_render(panda_retrieval):
    """The retrieval and validation figures draw headless and return Figures."""
    pytest.importorskip("matplotlib")
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    from dynid.plots.feasible import plot_newton_euler_validation, plot_retrieval

    panda, model, res = panda_retrieval
    q, dq, ddq = random_states(panda, 50, 9)
    tau = dynid.rnea(panda, q, dq, ddq)
    val = validate_newton_euler(res.robot, np.arange(50) * 1e-2, q, dq, ddq, tau, reference=model)
    f1 = plot_newton_euler_validation(val)
    f2 = plot_retrieval(res)
    assert len([a for a in f1.axes if a.get_visible()]) >= panda.n and len(f2.axes) == 2
    plt.close(f1)
    plt.close(f2)


def test_penalty_method_with_a_prior_lands_near_the_truth_and_still_meets_the_coefficients():
    """Prior term (weight 1e-6): coefficients to 1e-5, masses far closer to a perturbed truth."""
    robot = dynid.panda()
    truth = perturbed_robot(robot, np.random.default_rng(2))
    model = exact_model(robot, truth)
    opts = RetrievalOptions(runs=2, stages=4)
    plain = retrieve(model, options=opts, workers=1, seed=0)
    pulled = retrieve(model, options=opts, workers=1, seed=0, prior=robot)
    assert pulled.feasible and pulled.relative_residual < 1e-5
    err = lambda r: np.median(np.abs(r.mass - truth.mass)[1:] / truth.mass[1:])  # noqa: E731
    assert err(pulled) < 0.5 * err(plain)
    assert pulled.mass.min() > 0.3


def test_static_problem_in_blocks_of_configurations_is_the_stacked_one(monkeypatch):
    """The single-step problem accumulated a few configurations at a time (the R factor of
    [W, y] block by block; a 50-joint arm's stacked regressor was 4.5 GB for 200
    configurations) is the stacked one: its unweighted part reproduces
    ||Y_s phi - s||^2 of the full static regressor for any phi, and the weighted part has
    the normal equations and the offset of the problem built in one block."""
    from dynid.feasibility.penalty.objective import static_problem
    from dynid.regressors.static import static_regressor, static_vector

    panda = dynid.panda()
    q = random_states(panda, 40, 9)[0]
    M, g = dynid.mass_matrix(panda, q), dynid.gravity_torques(panda, q)
    s = static_vector(M, g).reshape(-1) + 1e-3 * np.random.default_rng(2).normal(size=40 * 35)
    s = s.reshape(40, 35)
    Mn, gn = np.zeros_like(M), s[:, 28:]
    i, j = np.tril_indices(7)
    Mn[:, i, j] = Mn[:, j, i] = s[:, :28]
    base = base_parameters(panda)
    whole = static_problem(panda, q, Mn, gn, base=base)
    monkeypatch.setenv("DYNID_MAX_STACK_BYTES", str(3 * 8 * 35 * (base.rank + 1) * 4))
    blocks = static_problem(panda, q, Mn, gn, base=base)
    Y = static_regressor(panda, q).reshape(-1, 70)
    for phi in np.random.default_rng(3).normal(size=(3, 70)):
        ref = float(np.sum((Y @ phi - s.reshape(-1)) ** 2))
        got = float(np.sum((blocks.report_A @ phi - blocks.report_b) ** 2)) + blocks.report_offset
        assert got == pytest.approx(ref, rel=1e-10)
    np.testing.assert_allclose(blocks.A.T @ blocks.A, whole.A.T @ whole.A, rtol=1e-9, atol=1e-12)
    np.testing.assert_allclose(blocks.A.T @ blocks.b, whole.A.T @ whole.b, rtol=1e-9, atol=1e-12)
    assert blocks.offset == pytest.approx(whole.offset, rel=1e-8)
