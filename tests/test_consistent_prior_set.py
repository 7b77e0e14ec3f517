"""The consistent fit marks the parameters the prior sets (the data give them only in
combinations, or hardly at all) and leaves unmarked those the data determine.

Ground truth: a planar 2R arm whose coefficients ``beta = P phi`` are drawn about the truth
with a known covariance (1 % of each coefficient). Its second link's mass enters the data
only in combinations (``mc1x + l1 m2``, ``J1zz + l1^2 m2``), so it must be marked; its first
moment ``mc2x`` and inertia ``J2zz`` are coefficients on their own and must not be.
Re-solving the fit with the prior's ``m2`` 10 % heavier is the independent check: the marked
values move with the prior (as the linearised sensitivity predicts), the unmarked ones stay
within their standard deviation of the truth.
"""

from __future__ import annotations

import warnings

import numpy as np
import pytest

from dynid.cli.summaries import format_consistent
from dynid.exceptions import DynidWarning
from dynid.feasibility.convex import SDPOptions, retrieve_sdp
from dynid.feasibility.convex.data_term import coefficient_term
from dynid.feasibility.determined import DATA, PRIOR_MARK, SUM
from dynid.feasibility.prior_share import prior_sensitivity
from dynid.identification.model import IdentifiedModel
from dynid.io.feasible import feasible_to_dict
from dynid.model.inertia import inertial_from_phi, phi_from_inertial
from dynid.regressors.base import base_parameters

from conftest import given_fit, planar_2r


@pytest.fixture(scope="module")
def fits():
    truth = planar_2r()
    base = base_parameters(truth)
    beta = base.beta_from_phi(truth.phi)
    std = 0.01 * np.abs(beta) + 1e-4
    noisy = beta + std * np.random.default_rng(1).standard_normal(beta.size)
    fit = given_fit(
        noisy, std, relative_error_percent=1.0, residual_rms=1.0, sigma=1.0,
        n_rows=10 * beta.size, covariance=np.diag(std**2),
    )  # fmt: skip
    model = IdentifiedModel(robot=truth, base=base, fit=fit)
    m, c, inertia = inertial_from_phi(truth.phi)  # a prior off the truth, as a URDF is
    prior = truth.with_params(phi_from_inertial(m * [0.9, 1.1], 1.05 * c, 1.1 * inertia))
    heavier = prior.phi.copy()
    heavier[1, 0] *= 1.1  # the prior's m2 + 10 % (its first moment and inertia kept)
    opts = SDPOptions(prior_weight=1.0)
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", DynidWarning)
        a = retrieve_sdp(model, prior=prior, options=opts)
        b = retrieve_sdp(model, prior=truth.with_params(heavier), options=opts)
    return truth, model, prior, heavier, a, b, std


def _data_std(model, std, j):
    """The standard deviation of standard parameter ``j`` the data give alone: ``c^T beta``
    with ``P^T c = e_j``; None when ``e_j`` is outside the row space of ``P``."""
    P = model.base.projection
    e = np.eye(P.shape[1])[j]
    c = np.linalg.lstsq(P.T, e, rcond=None)[0]
    if not np.allclose(P.T @ c, e, atol=1e-9):
        return None
    return float(np.sqrt(c @ np.diag(std**2) @ c))


def test_mass_only_in_combination_is_marked_and_moves_with_the_prior(fits):
    truth, model, prior, heavier, a, b, std = fits
    det = a.determined
    lab = list(det.labels)
    m2 = lab.index("m2")
    assert det.source[m2] == SUM and det.by_prior[m2]
    mass, com = det.link_marks()
    assert mass[1] and com[1].all()  # c = (m c) / m: the prior's mass sets it too
    dprior = heavier[1, 0] - prior.phi[1, 0]
    moved = b.phi[1, 0] - a.phi[1, 0]
    assert moved > 0.2 * dprior  # follows its prior (36 %): set by it, not measured
    # what moved is marked
    got = (b.phi - a.phi).reshape(-1)
    big = np.abs(got) > 1e-3 * np.abs(a.phi.reshape(-1)).max()
    assert big.any() and all(det.by_prior[j] for j in np.flatnonzero(big))


def test_sensitivity_to_the_prior_matches_re_solving(fits):
    """``d value / d prior``, linearised at the solution, against the solver re-run with the
    prior's m2 0.1 % heavier (at 10 % the log-det divergence bends it: 0.36 against 0.55)."""
    truth, model, prior, _, a, _, _ = fits
    step = prior.phi.copy()
    step[1, 0] *= 1.001
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", DynidWarning)
        c = retrieve_sdp(model, prior=truth.with_params(step), options=SDPOptions(prior_weight=1.0))
    term = coefficient_term(model)
    K = prior_sensitivity(term.P, term.A, a.phi, prior.phi, 1.0)
    pred, got = K @ (step - prior.phi).reshape(-1), (c.phi - a.phi).reshape(-1)
    big = np.abs(got) > 0.05 * np.abs(got).max()  # above the solver's tolerance
    assert big.sum() >= 4  # m2 and the parameters it is combined with
    np.testing.assert_allclose(pred[big], got[big], rtol=0.02)


def test_unmarked_parameters_stay_within_their_std_of_the_truth(fits):
    truth, model, prior, heavier, a, b, std = fits
    det = a.determined
    unmarked = [j for j, x in enumerate(det.by_prior) if not x]
    assert {"mc2x", "J2zz"} <= {det.labels[j] for j in unmarked}
    for j in unmarked:
        assert det.source[j] == DATA and det.prior_share[j] < 0.05
        s = _data_std(model, std, j)
        assert s is not None
        for res in (a, b):
            assert abs(res.phi.reshape(-1)[j] - truth.phi.reshape(-1)[j]) < 3 * s
        assert abs(b.phi.reshape(-1)[j] - a.phi.reshape(-1)[j]) < 0.1 * s


def test_determined_record_names_what_the_prior_sets(fits):
    det = fits[4].determined
    d = det.as_dict()
    assert "m2" in d["set_by_prior"] and "mc2x" not in d["set_by_prior"]
    assert 0.5 < d["prior_share"]["m2"] <= 1.0 and d["prior_share"]["mc2x"] < 0.05


def test_summary_and_feasible_json_mark_what_the_prior_sets(fits):
    res = fits[4]
    text = format_consistent(res)
    rows = [ln.split() for ln in text.splitlines() if ln.startswith(("link1 ", "link2 "))]
    assert len(rows) == 2 and all(r[1].endswith(PRIOR_MARK) for r in rows)  # both masses
    (legend,) = [ln for ln in text.splitlines() if ln.startswith(f"{PRIOR_MARK} set by the prior")]
    assert legend.startswith(f"{PRIOR_MARK} set by the prior, not measured: ")
    # a marked mass moves with its combinations (two trials read a mass 21 % off the prior,
    # marked, as a contradiction): the legend says so
    assert "its value is the prior's, moved with those combinations" in legend
    d = feasible_to_dict(res)
    assert d["set_by_prior"]["mass"] == [True, True]
    assert "m2" in d["set_by_prior"]["parameters"]
    assert "mc2x" not in d["set_by_prior"]["parameters"]
    assert "set_by_prior" in d["conventions"]
