"""Static identification (Gaz et al. 2019, Sec. IV-A): simulated controller, paper, Pinocchio."""

from __future__ import annotations

import json
import re
from pathlib import Path

import numpy as np
import pytest

import dynid
from dynid.exceptions import (
    DataError,
    DynidWarning,
    LimitError,
    NonFiniteError,
    RankDeficientError,
    ShapeError,
)
from dynid.identification.data import StaticDataset
from dynid.identification.least_squares import fit_least_squares
from dynid.identification.static import (
    basis_transform,
    coefficients_in_basis,
    identify_static,
    informative_static_rows,
)
from dynid.regressors.base import base_parameters
from dynid.regressors.static import static_regressor, static_vector
from dynid.simulation.controller import (
    SimulatedController,
    acquire_static,
    sample_configurations,
)

from conftest import random_states, robot_data_urdf

DATA = Path(__file__).parent / "data"

#: dynid order (m, mcx, mcy, mcz, Jxx, Jxy, Jxz, Jyy, Jyz, Jzz) from Pinocchio's
#: (m, mcx, mcy, mcz, Ixx, Ixy, Iyy, Ixz, Iyz, Izz)
PIN_TO_DYNID = np.array([0, 1, 2, 3, 4, 5, 7, 6, 8, 9])


@pytest.fixture(scope="module")
def panda_base():
    return base_parameters(dynid.panda())


@pytest.fixture(scope="module")
def noise_free():
    """The Panda identified from 1010 exact controller readings (base computed inside)."""
    robot = dynid.panda()
    data = acquire_static(SimulatedController(robot), 1010, np.random.default_rng(101))
    return robot, data, identify_static(robot, data)


# ------------------------------------------------------------------ Panda, noise-free
def test_panda_rank_is_43_after_the_joint1_gravity_row_is_dropped(noise_free):
    """Rank 43 (Gaz et al. 2019); g1 is dropped because gravity is along the joint-1 axis."""
    robot, data, model = noise_free
    assert model.fit.rank == model.base.rank == 43
    assert model.info.dropped_rows == ("g1",)
    assert model.info.route == "static"
    assert model.info.static is not None and model.info.static.n_configurations == 1010
    assert model.fit.n_rows == model.info.n_rows == 1010 * 34
    # independent reason: g1 vanishes for any parameters, since gravity is along joint 1's axis
    q, _, _ = random_states(robot, 50, seed=102)
    phi = np.random.default_rng(103).normal(size=(7, 10))
    np.testing.assert_allclose(
        dynid.gravity_torques(robot.with_params(phi), q)[:, 0], 0.0, atol=1e-12
    )


def test_informative_rows_flag_only_g1_of_the_panda(panda_base):
    """informative_static_rows on the base regressor: every row but g1 carries information."""
    robot = dynid.panda()
    q = sample_configurations(robot, 20, np.random.default_rng(104))
    info = informative_static_rows(panda_base.reduce(static_regressor(robot, q)))
    assert info.shape == (35,)
    assert np.flatnonzero(~info).tolist() == [28]  # static_labels(7)[28] == "g1"


def test_noise_free_coefficients_equal_those_of_the_true_parameters(noise_free):
    """beta from exact data equals base.beta_from_phi(phi_true) to 1e-9 relative."""
    robot, _, model = noise_free
    true = model.base.beta_from_phi(robot.phi)
    np.testing.assert_allclose(model.beta, true, rtol=1e-9, atol=1e-9 * np.abs(true).max())
    assert model.fit.relative_error_percent < 1e-9


def test_noise_free_model_predicts_true_m_g_c_tau_on_held_out_states(noise_free):
    """M^, g^, c^, tau^ equal the truth at 1000 held-out random states."""
    robot, _, model = noise_free
    q, dq, ddq = random_states(robot, 1000, seed=105)
    pairs = [
        (model.mass_matrix(q), dynid.mass_matrix(robot, q)),
        (model.gravity_torques(q), dynid.gravity_torques(robot, q)),
        (model.coriolis(q, dq), dynid.coriolis(robot, q, dq)),
        (model.torques(q, dq, ddq), dynid.rnea(robot, q, dq, ddq)),
    ]
    for got, want in pairs:
        assert got.shape == want.shape
        np.testing.assert_allclose(got, want, rtol=0, atol=1e-9 * np.abs(want).max())


# ------------------------------------------------------------------ the paper's basis
def _paper_table():
    return json.loads((DATA / "gaz2019_coefficients.json").read_text())


def _paper_matrix(table, labels):
    """The 43 printed expressions as a (43, 70) linear map of the standard parameters."""
    consts = table["definitions"]["constants"]
    exprs = []
    for c in table["coefficients"]:
        e = re.sub(r"\bc(\d)([xyz])\*m\1\b", r"mc\1\2", c["expression"]).replace("^", "**")
        assert not re.search(r"\bc\d[xyz]\b", e), e  # every c_i appears as m_i c_i
        exprs.append(compile(e, "<expr>", "eval"))
    zero = {lab: 0.0 for lab in labels}

    def value(expr, x):
        env = dict(consts)
        env.update(zero)
        env.update(dict(zip(labels, x, strict=True)))
        return eval(expr, {"__builtins__": {}}, env)

    A = np.array([[value(e, np.eye(len(labels))[j]) for j in range(len(labels))] for e in exprs])
    x = np.random.default_rng(106).normal(size=len(labels))  # the map is linear
    np.testing.assert_allclose([value(e, x) for e in exprs], A @ x, atol=1e-12)
    return A


def test_identified_coefficients_match_the_paper_in_its_basis(noise_free):
    """Our beta for the published p_hat, mapped to Table III's 43 expressions, matches it."""
    robot, _, model = noise_free
    table = _paper_table()
    A = _paper_matrix(table, robot.param_labels)
    pi = coefficients_in_basis(model.base, model.beta, A)
    recomputed = np.array(
        [c["pi_of_p_hat_recomputed_from_printed_p_hat"] for c in table["coefficients"]]
    )
    # the recomputed column is printed with 6 decimals
    np.testing.assert_allclose(pi, recomputed, rtol=0, atol=1e-6)
    printed = np.array(
        [np.nan if c["pi_of_p_hat"] is None else c["pi_of_p_hat"] for c in table["coefficients"]]
    )
    typo = np.array(table["transcription_errors"]["indices"]) - 1
    check = np.isfinite(printed)
    check[typo] = False
    assert check.sum() == 43 - 2 - 4
    np.testing.assert_allclose(pi[check], printed[check], rtol=0, atol=0.5e-4 + 1e-9)
    # the four documented transcription errors are real, not a tolerance artefact
    assert np.all(np.abs(pi[typo] - printed[typo]) > 1e-4)
    # and the map is invertible: the paper's 43 coefficients are a basis of ours
    assert np.linalg.matrix_rank(basis_transform(model.base, A)) == 43


def test_basis_transform_rejects_a_combination_that_is_not_identifiable(panda_base):
    """m1 alone is not a function of the base parameters: RankDeficientError names the row."""
    labels = dynid.panda().param_labels
    A = np.zeros((2, 70))
    A[0, labels.index("J7zz")] = 1.0
    A[1, labels.index("m1")] = 1.0
    with pytest.raises(RankDeficientError, match=r"row 1 \('m1'\) of A is not a combination"):
        basis_transform(panda_base, A, labels=("J7zz", "m1"))
    with pytest.raises(ShapeError, match=r"A must have shape \(k, 70\)"):
        basis_transform(panda_base, np.zeros((2, 69)))


# ------------------------------------------------------------------ noise and statistics
@pytest.mark.filterwarnings("ignore:.*indistinguishable from zero")  # expected: weak coefficients
def test_reported_std_agrees_with_the_spread_over_30_noise_seeds(panda_base):
    """Relative noise 1e-3: the robust std matches the scatter of beta over 30 seeds."""
    robot = dynid.panda()
    q = sample_configurations(robot, 400, np.random.default_rng(107))
    betas, stds = [], []
    for seed in range(30):
        M, g = SimulatedController(robot, 1e-3, rng=np.random.default_rng(1000 + seed)).read(q)
        model = identify_static(robot, StaticDataset(q, M, g), base=panda_base)
        betas.append(model.beta)
        stds.append(model.fit.std)
    betas, stds = np.array(betas), np.array(stds)
    ratio = betas.std(axis=0, ddof=1) / stds.mean(axis=0)
    # the sample std of 30 draws scatters by ~13 % (1 / sqrt(2 * 29))
    assert 0.85 < np.median(ratio) < 1.15
    assert 0.55 < ratio.min() and ratio.max() < 1.6
    # unbiased: the mean over seeds is within a few standard errors of the truth
    z = (betas.mean(axis=0) - panda_base.beta_from_phi(robot.phi)) / (
        stds.mean(axis=0) / np.sqrt(30)
    )
    assert np.max(np.abs(z)) < 4.5


def test_classical_and_robust_std_match_their_formulas():
    """fit_least_squares std: classical sigma^2 (W^T W)^-1 and HC1 sandwich, against numpy."""
    rng = np.random.default_rng(108)
    m, r = 400, 6
    W = rng.normal(size=(m, r)) * np.logspace(-2, 1, r)
    y = W @ rng.normal(size=r) + rng.normal(size=m) * np.linspace(0.01, 1.0, m)
    G = np.linalg.inv(W.T @ W)  # reference only
    beta = G @ W.T @ y
    e = y - W @ beta
    classical = np.sqrt(np.diag(G) * (e @ e) / (m - r))
    robust = np.sqrt(np.diag(G @ (W.T * e**2) @ W @ G) * m / (m - r))
    a = fit_least_squares(W, y)
    b = fit_least_squares(W, y, std="robust")
    np.testing.assert_allclose(a.beta, beta, rtol=1e-10)
    np.testing.assert_allclose(a.std, classical, rtol=1e-10)
    np.testing.assert_allclose(b.std, robust, rtol=1e-10)
    # the full covariance is kept (semi-normal path here; the QR path below)
    np.testing.assert_allclose(a.covariance, G * (e @ e) / (m - r), rtol=1e-9, atol=1e-14)
    np.testing.assert_allclose(
        b.covariance, G @ (W.T * e**2) @ W @ G * m / (m - r), rtol=1e-9, atol=1e-14
    )
    short = slice(0, 3 * r)  # too few rows for the semi-normal path: QR with pivoting
    Gs = np.linalg.inv(W[short].T @ W[short])
    es = y[short] - W[short] @ (Gs @ W[short].T @ y[short])
    c = fit_least_squares(W[short], y[short])
    np.testing.assert_allclose(c.covariance, Gs * (es @ es) / (2 * r), rtol=1e-8, atol=1e-14)


@pytest.mark.filterwarnings("ignore:.*indistinguishable from zero")  # expected: weak coefficients
def test_pruning_removes_uncertain_coefficients_and_refits_the_rest(panda_base):
    """With max_std_percent removed coefficients are 0 and the rest is the LS fit without them."""
    robot = dynid.panda()
    rng = np.random.default_rng(109)
    data = acquire_static(SimulatedController(robot, 1e-2, rng=rng), 300, rng)
    full = identify_static(robot, data, base=panda_base)
    model = identify_static(robot, data, base=panda_base, max_std_percent=5.0)
    removed = full.fit.std_percent > 5.0
    assert removed.any()
    np.testing.assert_array_equal(model.fit.kept, ~removed)
    assert model.info.pruned == tuple(panda_base.labels[k] for k in np.flatnonzero(removed))
    np.testing.assert_array_equal(model.beta[removed], 0.0)
    # independent re-fit: sample-major stack from the public regressor, g1 dropped
    Yb = panda_base.reduce(static_regressor(robot, data.q))
    y = static_vector(data.M, data.g)
    keep_rows = np.arange(35) != 28
    W = Yb[:, keep_rows][:, :, ~removed].reshape(-1, int((~removed).sum()))
    ref = np.linalg.lstsq(W, y[:, keep_rows].reshape(-1), rcond=None)[0]
    np.testing.assert_allclose(model.beta[~removed], ref, rtol=1e-8, atol=1e-12)


def test_simulated_controller_noise_is_relative_symmetric_and_seeded():
    """Noise multiplies each entry by 1 + eps z (z ~ N(0, 1), shared by M_ij and M_ji)."""
    robot = dynid.panda()
    q = sample_configurations(robot, 400, np.random.default_rng(110))
    eps = 1e-2
    M0, g0 = dynid.mass_matrix(robot, q), dynid.gravity_torques(robot, q)
    M, g = SimulatedController(robot, eps, rng=np.random.default_rng(111)).read(q)
    np.testing.assert_array_equal(M, np.swapaxes(M, 1, 2))
    i, j = np.tril_indices(7)
    z = np.concatenate(
        [((M / M0 - 1.0) / eps)[:, i, j].ravel(), ((g[:, 1:] / g0[:, 1:] - 1.0) / eps).ravel()]
    )
    assert abs(z.mean()) < 0.02 and abs(z.std() - 1.0) < 0.02
    assert np.all(np.abs(g[:, 0]) <= 2 * np.abs(g0[:, 0]))  # (round-off) zeros stay zero
    M2, g2 = SimulatedController(robot, eps, rng=np.random.default_rng(111)).read(q)
    np.testing.assert_array_equal(M, M2)
    np.testing.assert_array_equal(g, g2)
    with pytest.raises(ValueError, match="relative_noise must be finite and >= 0"):
        SimulatedController(robot, -1e-3)


def test_sample_configurations_stay_inside_the_limits_with_margin():
    """Uniform samples respect q_min + margin <= q <= q_max - margin and are reproducible."""
    robot = dynid.panda()
    q = sample_configurations(robot, 5000, np.random.default_rng(112), margin=0.1)
    assert q.shape == (5000, 7)
    assert np.all(q >= robot.q_min + 0.1) and np.all(q <= robot.q_max - 0.1)
    # uniform: the sample mean of each joint is the middle of its shrunk range
    mid = 0.5 * (robot.q_min + robot.q_max)
    half = 0.5 * (robot.q_max - robot.q_min) - 0.1
    assert np.all(np.abs(q.mean(axis=0) - mid) < 4 * half / np.sqrt(3 * 5000))
    np.testing.assert_array_equal(
        q, sample_configurations(robot, 5000, np.random.default_rng(112), margin=0.1)
    )
    with pytest.raises(LimitError, match="joint joint4 has range"):
        sample_configurations(robot, 3, np.random.default_rng(0), margin=1.6)
    with pytest.raises(ValueError, match="n must be a positive integer"):
        sample_configurations(robot, 0)
    with pytest.raises(ValueError, match="margin must be finite and >= 0"):
        sample_configurations(robot, 3, margin=-0.1)


# ------------------------------------------------------------------ a robot from URDF
def test_ur5_from_urdf_identified_from_pinocchio_m_and_g():
    """UR5 (example-robot-data): rank equals that of Pinocchio's stacked regressor; M, g match."""
    pin = pytest.importorskip("pinocchio")
    path = robot_data_urdf("ur_description/urdf/ur5_robot.urdf")
    robot = dynid.Robot.from_urdf(path, tip_link="tool0")
    model = pin.buildModelFromUrdf(path)
    model.gravity.linear[:] = robot.gravity
    pdata = model.createData()
    n = model.nv
    assert n == robot.n == 6

    def m_and_g(q):
        M = np.empty((len(q), n, n))
        g = np.empty((len(q), n))
        for s in range(len(q)):
            Mu = pin.crba(model, pdata, q[s])
            M[s] = np.triu(Mu) + np.triu(Mu, 1).T  # crba fills the upper triangle
            g[s] = pin.computeGeneralizedGravity(model, pdata, q[s])
        return M, g

    rng = np.random.default_rng(113)
    q = rng.uniform(-np.pi, np.pi, (300, n))
    M, g = m_and_g(q)
    ident = identify_static(robot, StaticDataset(q, M, g))
    # the same stacked regressor from Pinocchio: unit accelerations without gravity, then rest
    i, j = np.tril_indices(n)
    rows = []
    zero = np.zeros(n)
    for s in range(len(q)):
        model.gravity.linear[:] = 0.0
        cols = np.stack(
            [pin.computeJointTorqueRegressor(model, pdata, q[s], zero, e) for e in np.eye(n)]
        )
        model.gravity.linear[:] = robot.gravity
        grav = pin.computeJointTorqueRegressor(model, pdata, q[s], zero, zero)
        rows.append(np.vstack([cols[j, i], grav]))
    W = np.concatenate(rows)
    Ws = W / np.where(np.linalg.norm(W, axis=0) > 0, np.linalg.norm(W, axis=0), 1.0)
    assert ident.fit.rank == ident.base.rank == np.linalg.matrix_rank(Ws)
    assert ident.info.dropped_rows == ("g1",)
    # Pinocchio's regressor times its parameters reproduces its M and g (the data)
    phi_pin = np.concatenate([model.inertias[k].toDynamicParameters() for k in range(1, n + 1)])
    np.testing.assert_allclose(W @ phi_pin, static_vector(M, g).reshape(-1), atol=1e-10)
    # held-out predictions
    qh = rng.uniform(-np.pi, np.pi, (200, n))
    Mh, gh = m_and_g(qh)
    np.testing.assert_allclose(ident.mass_matrix(qh), Mh, rtol=0, atol=1e-9 * np.abs(Mh).max())
    np.testing.assert_allclose(ident.gravity_torques(qh), gh, rtol=0, atol=1e-9 * np.abs(gh).max())
    # and the coefficients are those of Pinocchio's parameters (after the inertia permutation)
    phi = phi_pin.reshape(n, 10)[:, PIN_TO_DYNID].reshape(-1)
    true = ident.base.beta_from_phi(phi)
    np.testing.assert_allclose(ident.beta, true, rtol=0, atol=1e-9 * np.abs(true).max())


def test_static_regressor_with_a_prismatic_joint_matches_rnea():
    """Closed-form static regressor of an RPR arm times random phi equals RNEA's [tril M; g]."""
    rng = np.random.default_rng(116)
    robot = dynid.Robot.from_mdh(
        [0.0, 0.1, 0.2],
        [0.3, 0.0, 0.1],
        [0.0, np.pi / 2, -np.pi / 2],
        joint_types="RPR",
        gravity=(0.3, -1.0, -9.8),
    )
    q = rng.uniform(-2.0, 2.0, (40, 3))
    Y = static_regressor(robot, q)
    for _ in range(3):
        phi = rng.normal(size=30)
        other = robot.with_params(phi)
        want = static_vector(dynid.mass_matrix(other, q), dynid.gravity_torques(other, q))
        np.testing.assert_allclose(Y @ phi, want, atol=1e-12 * np.abs(want).max())


# ------------------------------------------------------------------ bad data
def test_too_few_configurations_raise_rank_deficient_error_with_rank_found_and_needed(
    noise_free, panda_base
):
    """1 and 2 configurations cannot identify 43 coefficients; the message gives both ranks."""
    robot, data, _ = noise_free
    # one configuration: 34 rows, fewer than the 43 unknowns
    with pytest.raises(
        RankDeficientError, match=r"1 configuration\(s\) \(34 rows\) has rank \d+ < 43 needed"
    ):
        identify_static(robot, data.select([0]), base=panda_base)
    # two: 68 rows but still rank deficient (the rank found is that of numpy's SVD)
    two = data.select([0, 1])
    W = panda_base.reduce(static_regressor(robot, two.q))[:, np.arange(35) != 28].reshape(-1, 43)
    rank = np.linalg.matrix_rank(W / np.linalg.norm(W, axis=0))
    assert rank < 43
    with pytest.raises(
        RankDeficientError, match=rf"2 configuration\(s\) \(68 rows\) has rank {rank} < 43 needed"
    ):
        identify_static(robot, two, base=panda_base)


def test_static_dataset_rejects_nan_naming_the_row():
    """NaN in M raises NonFiniteError with the row and the entry."""
    rng = np.random.default_rng(114)
    q = rng.normal(size=(10, 3))
    M = np.tile(np.eye(3), (10, 1, 1))
    M[6, 2, 1] = np.nan
    with pytest.raises(NonFiniteError, match=r"M must be finite; got nan in row 6, entry \(2, 1\)"):
        StaticDataset(q, M, np.zeros((10, 3)))
    g = np.zeros((10, 3))
    g[4, 0] = np.inf
    with pytest.raises(NonFiniteError, match=r"g must be finite; got inf in row 4"):
        StaticDataset(q, np.tile(np.eye(3), (10, 1, 1)), g)


def test_static_dataset_rejects_non_symmetric_m_and_bad_shapes():
    """A non-symmetric M names its row; shapes are checked."""
    q = np.zeros((5, 2))
    M = np.tile(np.eye(2), (5, 1, 1))
    M[3, 0, 1] = 0.5
    with pytest.raises(DataError, match=r"M must be symmetric; row 3"):
        StaticDataset(q, M, np.zeros((5, 2)))
    with pytest.raises(ShapeError, match=r"M must have shape \(5, 2, 2\)"):
        StaticDataset(q, np.zeros((5, 3, 3)), np.zeros((5, 2)))
    with pytest.raises(ShapeError, match=r"q must have shape \(N, n\)"):
        StaticDataset(np.zeros(7), np.zeros((1, 7, 7)), np.zeros((1, 7)))


def test_wrong_joint_count_raises_data_error(noise_free):
    """Wrong joint count (DataError), base of another robot (ShapeError), bad options."""
    from conftest import planar_2r

    _, data, _ = noise_free
    with pytest.raises(DataError, match=r"static data set has 7 joints .* robot 'planar2r' has 2"):
        identify_static(planar_2r(), data)
    robot = dynid.panda()
    with pytest.raises(ShapeError, match="base was built for 20 standard parameters"):
        identify_static(robot, data, base=base_parameters(planar_2r()))
    with pytest.raises(ValueError, match="max_std_percent must be positive"):
        identify_static(robot, data, max_std_percent=0.0)
    with pytest.raises(ValueError, match="std must be 'classical' or 'robust'"):
        identify_static(robot, data, std="sandwich")  # type: ignore[arg-type]


@pytest.mark.filterwarnings("ignore:.*indistinguishable from zero")  # expected: weak coefficients
def test_gravity_mismatch_between_data_and_robot_warns():
    """Data recorded with tilted gravity but identified with upright gravity: g1 is not zero."""
    robot = dynid.panda()
    tilted = robot.with_gravity([1.0, 0.0, -9.75])
    data = acquire_static(SimulatedController(tilted), 100, np.random.default_rng(115))
    with pytest.warns(DynidWarning, match=r"rows \['g1'\] carry no information"):
        identify_static(robot, data)


# ------------------------------------------------------------------ least-squares routes
def _spy_qr(monkeypatch):
    """Count the calls of the QR route of fit_least_squares."""
    from dynid.identification import least_squares as ls

    calls = []
    real = ls._solve_qr

    def spy(*args, **kwargs):
        calls.append(args[0].shape)
        return real(*args, **kwargs)

    monkeypatch.setattr(ls, "_solve_qr", spy)
    return calls


def _tall_problem(seed, m=3000, r=12, cond=10.0):
    """Tall W with columns of very different scales, scaled condition about ``cond``.

    The coefficients times the column scales are of one size, so that each coefficient
    is determined to the same relative accuracy.
    """
    rng = np.random.default_rng(seed)
    U = np.linalg.qr(rng.normal(size=(m, r)))[0]
    V = np.linalg.qr(rng.normal(size=(r, r)))[0]
    scale = np.logspace(-3, 3, r)
    W = (U * np.logspace(0, -np.log10(cond), r)) @ V.T * scale
    beta = rng.uniform(1.0, 2.0, r) * rng.choice([-1.0, 1.0], r) / scale
    y = W @ beta + 1e-3 * np.std(W @ beta) * rng.normal(size=m) * rng.uniform(0.1, 2.0, m)
    return W, y


@pytest.mark.parametrize("std", ["classical", "robust"])
def test_semi_normal_route_equals_the_qr_route_on_a_well_conditioned_problem(monkeypatch, std):
    """Issue 3: CSNE (tall, cond <= 100) and pivoted QR give the same fit to 1e-10."""
    from dynid.identification import solvers

    W, y = _tall_problem(120)
    calls = _spy_qr(monkeypatch)
    fast = fit_least_squares(W, y, std=std)
    assert calls == []  # the semi-normal route was taken
    monkeypatch.setattr(solvers, "_CSNE_MAX_COND", 0.0)  # force the QR route
    qr = fit_least_squares(W, y, std=std)
    assert len(calls) == 1
    assert fast.rank == qr.rank == 12 and fast.n_rows == qr.n_rows == 3000
    np.testing.assert_allclose(fast.beta, qr.beta, rtol=1e-10)
    np.testing.assert_allclose(fast.std, qr.std, rtol=1e-10)
    np.testing.assert_allclose(fast.std_percent, qr.std_percent, rtol=1e-10)
    names = ("condition_number", "scaled_condition_number", "relative_error_percent")
    for name in names + ("residual_rms", "sigma"):
        assert getattr(fast, name) == pytest.approx(getattr(qr, name), rel=1e-8)
    # independent reference: numpy's SVD least squares and the condition numbers of W D^-1
    # and of W itself (issue 9: the paper's figure is the unscaled one)
    np.testing.assert_allclose(fast.beta, np.linalg.lstsq(W, y, rcond=None)[0], rtol=1e-10)
    Ws = W / np.linalg.norm(W, axis=0)
    assert fast.scaled_condition_number == pytest.approx(np.linalg.cond(Ws), rel=1e-8)
    assert fast.condition_number == pytest.approx(np.linalg.cond(W), rel=1e-8)


def test_ill_conditioned_or_rank_deficient_regressor_takes_the_qr_route(monkeypatch):
    """Above the guard the fit is the QR route's; a rank-deficient W raises as before."""
    calls = _spy_qr(monkeypatch)
    W, y = _tall_problem(121, cond=1e6)
    fit = fit_least_squares(W, y, std="robust")
    assert len(calls) == 1 and fit.rank == 12 and fit.scaled_condition_number > 1e5
    # a duplicated column: rank 3 of 4, the QR route's message
    rng = np.random.default_rng(122)
    A = rng.normal(size=(2000, 3))
    Wd = np.column_stack([A, 2.0 * A[:, 1]])
    with pytest.raises(RankDeficientError, match=r"Regressor rank 3 < 4 at rtol=1e-10"):
        fit_least_squares(Wd, A @ [1.0, 2.0, 3.0])
    assert len(calls) == 2


def test_rank_guard_leaves_a_large_rtol_to_the_qr_rank_decision(monkeypatch):
    """With cond * rtol >= 0.1 the QR route decides the rank (here: rank deficient)."""
    calls = _spy_qr(monkeypatch)
    W, y = _tall_problem(123, cond=50.0)
    assert fit_least_squares(W, y, rtol=1e-3).rank == 12
    assert len(calls) == 0
    with pytest.raises(RankDeficientError, match=r"Regressor rank \d+ < 12 at rtol=0.5"):
        fit_least_squares(W, y, rtol=0.5)
    assert len(calls) == 1


def test_non_finite_tall_regressor_raises_non_finite_error():
    """NaN or inf in a tall W is reported as before (found through its Gram matrix)."""
    W, y = _tall_problem(124)
    W[1234, 5] = np.nan
    with pytest.raises(NonFiniteError, match=r"W must be finite; got nan at index \(1234, 5\)"):
        fit_least_squares(W, y)
    W[1234, 5] = np.inf
    with pytest.raises(NonFiniteError, match=r"W must be finite; got inf"):
        fit_least_squares(W, y, std="robust")


@pytest.mark.parametrize("std", ["classical", "robust"])
def test_fit_on_row_blocks_equals_the_fit_on_the_stacked_rows(std):
    """Row blocks (rows used, leading zero columns skipped) give the fit of those rows."""
    from dynid.identification.least_squares import _fit

    W, y = _tall_problem(125, m=4000, r=8)
    blocks = np.array([[0, 1000, 0], [1500, 2500, 3], [2500, 3000, 3], [3200, 4000, 6]])
    for a, b, c in blocks:
        W[a:b, :c] = 0.0  # the structure the blocks declare
    rows = np.concatenate([np.arange(a, b) for a, b, _ in blocks])
    ref = fit_least_squares(W[rows], y[rows], std=std)
    got = _fit(W, y, rtol=1e-10, std=std, blocks=blocks)
    G = W[rows].T @ W[rows]
    with_gram = _fit(W, y, rtol=1e-10, std=std, blocks=blocks, gram=G)
    keep = np.arange(8) != 4
    pruned = _fit(W, y, kept=keep, rtol=1e-10, std=std, blocks=blocks, gram=G)
    ref_pruned = fit_least_squares(W[rows], y[rows], kept=keep, std=std)
    for fit, want in ((got, ref), (with_gram, ref), (pruned, ref_pruned)):
        assert fit.n_rows == want.n_rows == rows.size
        np.testing.assert_allclose(fit.beta, want.beta, rtol=1e-12)
        np.testing.assert_allclose(fit.std, want.std, rtol=1e-12)
        assert fit.sigma == pytest.approx(want.sigma, rel=1e-12)
        assert fit.relative_error_percent == pytest.approx(want.relative_error_percent, rel=1e-12)


def test_identify_static_is_the_same_with_the_numpy_regressor(monkeypatch, noise_free):
    """The compiled static-regressor kernel and the numpy path give the same fit (1e-12)."""
    from dynid.regressors import static as static_module

    robot, _, _ = noise_free
    data = acquire_static(
        SimulatedController(robot, 1e-3, rng=np.random.default_rng(126)),
        300,
        np.random.default_rng(127),
    )
    base = base_parameters(robot)
    compiled = identify_static(robot, data, base=base)
    monkeypatch.setattr(static_module, "_kernel", lambda: None)
    numpy_path = identify_static(robot, data, base=base)
    assert compiled.info.dropped_rows == numpy_path.info.dropped_rows == ("g1",)
    np.testing.assert_allclose(compiled.beta, numpy_path.beta, rtol=1e-12, atol=1e-15)
    np.testing.assert_allclose(compiled.fit.std, numpy_path.fit.std, rtol=1e-10)


@pytest.mark.parametrize("m", [300, 2048 * 3 + 5, 2048 * 2 + 40])
def test_tall_qr_in_blocks_gives_numpys_triangular_factor(m):
    """The blocked (tall-skinny) factor of [W / scale, y] equals numpy's QR's R up to the
    signs of its rows, a short last block included (5 rows under 41 columns)."""
    from dynid.identification.solvers import tall_r

    rng = np.random.default_rng(m)
    W = rng.normal(size=(m, 40)) * np.logspace(-3, 3, 40)
    y = rng.normal(size=m)
    scale = np.linalg.norm(W, axis=0)
    R = tall_r(W, scale, y)
    ref = np.linalg.qr(np.column_stack([W / scale, y]), mode="r")
    signs = np.sign(np.diag(R)) * np.sign(np.diag(ref))
    np.testing.assert_allclose(R * signs[:, None], ref, rtol=0, atol=1e-12 * np.abs(ref).max())


def test_tall_pivoted_qr_in_blocks_gives_scipys_factors():
    """The blocked pivoted QR of a tall matrix (three blocks and a short one, a column
    nearly repeated) gives scipy's pivots, its R up to the signs of the rows, an
    orthonormal Q and Q R = X[:, piv]."""
    import scipy.linalg

    from dynid.identification.solvers import tall_pivoted_qr

    rng = np.random.default_rng(3)
    X = rng.normal(size=(2048 * 3 + 7, 50)) * np.logspace(-2, 2, 50)
    X[:, 3] = 2.0 * X[:, 5] + 1e-9 * X[:, 7]
    Q, R, piv = tall_pivoted_qr(X)
    Qr, Rr, pr = scipy.linalg.qr(X, mode="economic", pivoting=True)
    np.testing.assert_array_equal(piv, pr)
    signs = np.sign(np.diag(R)) * np.sign(np.diag(Rr))
    np.testing.assert_allclose(R * signs[:, None], Rr, rtol=0, atol=1e-12 * np.abs(Rr).max())
    np.testing.assert_allclose(Q.T @ Q, np.eye(50), rtol=0, atol=1e-13)
    np.testing.assert_allclose(Q @ R, X[:, piv], rtol=0, atol=1e-12 * np.abs(X).max())
