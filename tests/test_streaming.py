"""Least squares over blocks of rows (identification/streaming.py, issue 20 item 5).

References: the engine on the same rows stacked (identification/engine.py, HeldRows:
(a different algorithm: the whole regressor, semi-normal equations or one QR) and
numpy's lstsq (SVD) for the ordinary and weighted estimates.
"""

from __future__ import annotations

import numpy as np
import pytest

from dynid.exceptions import NonFiniteError, OptionError, RankDeficientError, ShapeError
from dynid.identification.engine import fit_stacked
from dynid.identification.estimators import IRLS, OLS, WLS, Residuals, Weights
from dynid.identification.streamed import fit_streamed
from dynid.identification.streaming import (
    group_factors,
    max_stack_bytes,
    streams,
)


def _problem(seed: int, m: int = 6000, c: int = 6, k: int = 3, weak: float = 1.0):
    """Rows in ``k`` noise groups of very different noise, columns of very different
    scale, 3 % of the rows hit by outliers."""
    rng = np.random.default_rng(seed)
    W = rng.normal(size=(m, c)) * np.logspace(-2, 2, c)
    W[:, 2] *= weak
    beta = rng.normal(size=c)
    groups = np.arange(m) % k
    sig = np.logspace(-2, 0, k)
    y = W @ beta + rng.normal(size=m) * sig[groups]
    bad = rng.choice(m, m // 33, replace=False)
    y[bad] += rng.normal(scale=20.0, size=bad.size)
    return W, y, groups


def _source(W, y, g, step: int):
    return lambda: (
        (W[a : a + step], y[a : a + step], g[a : a + step]) for a in range(0, y.size, step)
    )


def _same(a, b, rtol=1e-10):
    np.testing.assert_allclose(a.beta, b.beta, rtol=rtol, atol=1e-13)
    np.testing.assert_allclose(a.std, b.std, rtol=rtol, atol=1e-15)
    np.testing.assert_array_equal(a.kept, b.kept)
    for f in ("sigma", "relative_error_percent", "residual_rms", "condition_number"):
        assert getattr(a, f) == pytest.approx(getattr(b, f), rel=1e-9), f
    assert a.scaled_condition_number == pytest.approx(b.scaled_condition_number, rel=1e-9)
    assert a.n_rows == b.n_rows and a.rank == b.rank


@pytest.mark.parametrize("est", [OLS(), WLS(), IRLS()], ids=["ols", "wls", "irls"])
@pytest.mark.parametrize("cov", ["classical", "robust"])
def test_streamed_fit_equals_the_stacked_fit(est, cov):
    """Blocks of 700 rows (groups split unevenly across them) give the stacked estimator's
    estimates, standard deviations and statistics to 1e-10 relative."""
    W, y, g = _problem(3)
    ref = fit_stacked(W, y, g, est, rtol=1e-10, std=cov)
    got = fit_streamed(_source(W, y, g, 700), est, rtol=1e-10, std=cov)
    _same(got, ref)


@pytest.mark.parametrize("est", [OLS(), WLS(), IRLS()], ids=["ols", "wls", "irls"])
def test_streamed_pruning_equals_the_stacked_pruning(est):
    """With --max-std-percent the same coefficients are removed and the re-fit agrees."""
    W, y, g = _problem(4, weak=1e-4)  # column 2's coefficient is lost in the noise
    ref = fit_stacked(W, y, g, est, rtol=1e-10, std="robust", max_std_percent=30.0)
    assert not np.all(ref.kept)
    got = fit_streamed(_source(W, y, g, 999), est, rtol=1e-10, std="robust", max_std_percent=30.0)
    _same(got, ref)


def test_ordinary_and_weighted_estimates_equal_lstsq():
    """OLS equals numpy's SVD least squares; the factors of the groups reproduce each
    group's residual norm, and the weighted factor the weighted least squares."""
    W, y, g = _problem(5, k=4)
    F = group_factors(_source(W, y, g, 512))
    fit = fit_streamed(_source(W, y, g, 512), OLS(), rtol=1e-10)
    ref = np.linalg.lstsq(W, y, rcond=None)[0]
    np.testing.assert_allclose(fit.beta, ref, rtol=1e-11)
    e = y - W @ ref
    np.testing.assert_allclose(
        F.residual_ss(ref), [np.sum(e[g == j] ** 2) for j in range(4)], rtol=1e-10
    )
    w = np.array([1.0, 2.0, 0.5, 3.0])
    Rw = F.combined(w)
    c = W.shape[1]
    wref = np.linalg.lstsq(W * w[g][:, None], y * w[g], rcond=None)[0]
    np.testing.assert_allclose(np.linalg.solve(Rw[:c, :c], Rw[:c, c]), wref, rtol=1e-10)
    assert F.n_rows == y.size and list(F.rows) == [np.sum(g == j) for j in range(4)]


def test_rank_deficiency_and_bad_blocks_are_named():
    """A dependent column is named; NaN and ragged blocks are refused."""
    rng = np.random.default_rng(6)
    W = rng.normal(size=(400, 3))
    W[:, 2] = 2 * W[:, 0]
    y = rng.normal(size=400)
    g = np.zeros(400, dtype=np.intp)
    with pytest.raises(RankDeficientError, match="a, c|c, a"):
        fit_streamed(_source(W, y, g, 100), OLS(), rtol=1e-10, labels=("a", "b", "c"))
    W[5, 1] = np.nan
    with pytest.raises(NonFiniteError, match="regressor"):
        fit_streamed(_source(W, y, g, 100), OLS(), rtol=1e-10)
    with pytest.raises(ShapeError):
        fit_streamed(lambda: iter([(W[:10], y[:9], g[:10])]), OLS(), rtol=1e-10)


class _Cauchy:
    """A user's estimator, not built in: Cauchy weights ``1 / sqrt(1 + (e / k)^2)`` of
    every row with a fixed scale ``k``, reweighted until the estimate moves less than 1e-13."""

    name = "cauchy"
    weighted = True
    per_row = True
    k = 0.5

    def reweight(self, res: Residuals) -> Weights | None:
        if res.step > 0 and not res.moved(1e-13):
            return None
        return Weights(row=self.row_weights(res.e, res.groups, res.n_columns))

    def row_weights(self, e, groups, n_columns):
        return 1.0 / np.sqrt(1.0 + (e / self.k) ** 2)


def test_a_users_estimator_fits_on_rows_read_in_blocks():
    """An estimator written outside the package fits on blocks as on the stacked rows; the
    estimate is a stationary point of the Cauchy loss (its gradient vanishes to rounding)
    and scipy's least_squares(loss="cauchy") minimiser to its own tolerance."""
    from scipy.optimize import least_squares

    W, y, g = _problem(8, m=1500, c=4)
    est = _Cauchy()
    stacked = fit_stacked(W, y, g, est, rtol=1e-10, std="robust")
    got = fit_streamed(_source(W, y, g, 100), est, rtol=1e-10, std="robust")
    _same(got, stacked, rtol=1e-8)
    x0 = np.linalg.lstsq(W, y, rcond=None)[0]
    ref = least_squares(
        lambda b: W @ b - y, x0, loss="cauchy", f_scale=est.k, xtol=1e-15, ftol=1e-15, gtol=1e-15
    ).x
    e = y - W @ np.asarray(got.beta)
    grad = W.T @ (e / (1.0 + (e / est.k) ** 2))
    assert np.linalg.norm(grad) < 1e-10 * np.linalg.norm(W.T @ e)
    np.testing.assert_allclose(got.beta, ref, rtol=1e-5)


def test_stack_limit_from_the_environment(monkeypatch):
    """DYNID_MAX_STACK_BYTES sets when a route streams; a bad value is one OptionError."""
    monkeypatch.setenv("DYNID_MAX_STACK_BYTES", "8000")
    assert max_stack_bytes() == 8000
    assert streams(101, 9) and not streams(100, 9)  # 8 bytes x 100 x (9 + 1)
    monkeypatch.setenv("DYNID_MAX_STACK_BYTES", "lots")
    with pytest.raises(OptionError, match="DYNID_MAX_STACK_BYTES"):
        max_stack_bytes()


@pytest.mark.parametrize("decimate", [1, 5])
def test_a_filtered_log_read_in_blocks_equals_the_log_stacked(monkeypatch, decimate):
    """A log read in several blocks whose friction columns go through the torques' low-pass
    (parallel filtering, at the rate before decimation) gives the stacked fit's estimates
    to 1e-9: each span of blocks is filtered with enough of its neighbours' samples that
    its edges are the whole log's."""
    import dynid
    from dynid.identification import log_rows
    from dynid.identification.classical import identify_from_log
    from dynid.simulation.measurement import sample_times, simulate_measurement
    from dynid.simulation.trajectories import random_fourier

    robot = dynid.panda()
    traj = random_fourier(robot, np.random.default_rng(3))(sample_times(12.0, 1000.0))
    log = simulate_measurement(robot, traj, rng=np.random.default_rng(4))
    kw = {"decimate": decimate, "cutoff_hz": 20.0, "structure": "classical", "estimator": "ols"}
    ref = identify_from_log(robot, log, **kw)
    monkeypatch.setenv("DYNID_MAX_STACK_BYTES", "0")  # 12 000 samples: 3 blocks of rows
    monkeypatch.setattr(log_rows, "STEP_SPAN", 700)  # a span of stepping columns per block
    got = identify_from_log(robot, log, **kw)
    np.testing.assert_allclose(got.fit.beta, ref.fit.beta, rtol=1e-9, atol=1e-12)
    np.testing.assert_allclose(got.friction.params, ref.friction.params, rtol=1e-9, atol=1e-12)
    h, hr = got.info.heldout, ref.info.heldout
    assert h["heldout_error_percent"] == pytest.approx(hr["heldout_error_percent"], rel=1e-9)
