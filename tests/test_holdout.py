"""Held-out judgement from block normal equations.

References: explicit refits of the raw rows without each block (numpy lstsq), and the
squared error of a candidate computed on the raw rows.
"""

from __future__ import annotations

import numpy as np
import pytest

from dynid.exceptions import OptionError
from dynid.identification.holdout import (
    HeldOut,
    _factored,
    block_labels,
    block_normals,
    cross_validate,
    shared_eigen,
)


def test_block_labels_are_contiguous_equal_blocks_and_refuse_short_logs():
    lab = block_labels(103, 5)
    assert lab[0] == 0 and lab[-1] == 4
    assert np.all(np.diff(lab) >= 0)  # contiguous, in time order
    counts = np.bincount(lab)
    assert counts.max() - counts.min() <= 1
    with pytest.raises(OptionError, match="--folds"):
        block_labels(40, 5)
    with pytest.raises(OptionError, match="--folds"):
        block_labels(100, 1)


def test_k_fold_errors_equal_explicit_refits_without_each_block():
    rng = np.random.default_rng(3)
    m, p = 600, 6
    W = rng.normal(size=(m, p))
    y = W @ rng.normal(size=p) + 0.3 * rng.normal(size=m) + 0.5 * np.sin(np.arange(m) / 50)
    lab = block_labels(m, 4)
    held = HeldOut.k_fold(block_normals(W, y, lab))
    sse, ss = 0.0, 0.0
    for j in range(4):
        tr, te = lab != j, lab == j
        x = np.linalg.lstsq(W[tr], y[tr], rcond=None)[0]
        np.testing.assert_allclose(held.train[j].solve(), x, rtol=1e-9, atol=1e-12)
        sse += float(np.sum((W[te] @ x - y[te]) ** 2))
        ss += float(np.sum(y[te] ** 2))
    err = cross_validate(held)
    np.testing.assert_allclose(err.heldout_percent, 100 * np.sqrt(sse / ss), rtol=1e-9)
    x_all = np.linalg.lstsq(W, y, rcond=None)[0]
    ref = 100 * np.linalg.norm(W @ x_all - y) / np.linalg.norm(y)
    np.testing.assert_allclose(err.training_percent, ref, rtol=1e-9)
    assert err.heldout_percent > err.training_percent  # fitting the held-out rows helps
    # any candidate's error on a block is the quadratic form
    x = rng.normal(size=p)
    te = lab == 2
    np.testing.assert_allclose(held.test[2].sse(x), np.sum((W[te] @ x - y[te]) ** 2), rtol=1e-9)
    assert held.training_share == pytest.approx(0.75, abs=0.01)


def test_a_separate_log_and_restricted_and_expanded_columns():
    rng = np.random.default_rng(4)
    W, Wv = rng.normal(size=(300, 5)), rng.normal(size=(200, 5))
    beta = rng.normal(size=5)
    y, yv = W @ beta + 0.1 * rng.normal(size=300), Wv @ beta + 0.1 * rng.normal(size=200)
    zero = np.zeros(300, dtype=np.intp)
    held = HeldOut.separate(
        block_normals(W, y, zero)[0], block_normals(Wv, yv, np.zeros(200, dtype=np.intp))[0]
    )
    x = np.linalg.lstsq(W, y, rcond=None)[0]
    ref = 100 * np.linalg.norm(Wv @ x - yv) / np.linalg.norm(yv)
    assert cross_validate(held).heldout_percent == pytest.approx(ref, rel=1e-9)
    assert held.training_share == 1.0 and held.scheme == "file"
    # columns 1 and 3 only, through an expansion over 7 columns and back
    mask = np.array([False, True, False, True, False, False, False])
    sub = block_normals(W[:, [1, 3]], y, zero)[0]
    back = sub.expanded(mask).restricted(np.flatnonzero(mask))
    np.testing.assert_allclose(back.solve(), np.linalg.lstsq(W[:, [1, 3]], y, rcond=None)[0])


def test_shared_eigen_solves_rows_of_the_same_gram_with_their_own_targets():
    """Within shared_eigen, two sets of rows with one W^T W and other targets each solve
    to their own least squares (numpy lstsq on the rows), the second from the first's
    eigendecomposition; the standard deviations too (sigma^2 (W^T W)^-1)."""
    rng = np.random.default_rng(11)
    W = rng.normal(size=(300, 5))
    ys = [W @ rng.normal(size=5) + 0.1 * rng.normal(size=300) for _ in range(2)]
    with shared_eigen():
        for y in ys:
            n = block_normals(W, y, np.zeros(300, np.intp))[0]
            x, sd = n.solve_with_std()
            ref = np.linalg.lstsq(W, y, rcond=None)[0]
            r = y - W @ ref
            var = (r @ r) / (300 - 5) * np.diag(np.linalg.inv(W.T @ W))
            np.testing.assert_allclose(x, ref, rtol=1e-10, atol=1e-12)
            assert sd is not None
            np.testing.assert_allclose(sd, np.sqrt(var), rtol=1e-8)


@pytest.mark.parametrize("case", ["well-conditioned", "ill-conditioned", "rank-deficient"])
def test_normal_equations_solve_as_lstsq_whichever_factorisation(case):
    """Normals.solve_with_std predicts as numpy's least squares on the rows: a
    well-conditioned G by Cholesky (its coefficients and classical standard deviations
    those of numpy's inverse too), an ill-conditioned one (cond 1.6e8 scaled: to cond *
    eps) or a singular one (a repeated column) by its eigenpairs."""
    rng = np.random.default_rng(12)
    W = rng.normal(size=(400, 6)) * np.logspace(-3, 3, 6)  # scales: column scaling undoes
    if case == "ill-conditioned":
        W[:, 5] = W[:, 4] * 1e3 + 10.0 * rng.normal(size=400)
    if case == "rank-deficient":
        W[:, 5] = 2.0 * W[:, 4]
    y = W @ rng.normal(size=6) + 0.1 * rng.normal(size=400)
    n = block_normals(W, y, np.zeros(400, np.intp))[0]
    assert (_factored(n.G, 1e-10)[2] is None) == (case == "well-conditioned")
    x, sd = n.solve_with_std()
    assert sd is not None
    d = np.linalg.norm(W, axis=0)
    ref = np.linalg.lstsq(W / d, y, rcond=1e-10)[0] / d  # minimum norm in scaled columns
    tol = 1e-10 if case == "well-conditioned" else 1e-7  # cond(G) * eps: 2e-15, 4e-8
    np.testing.assert_allclose(W @ x, W @ ref, rtol=tol, atol=1e-12 * np.abs(y).max())
    if case == "well-conditioned":
        np.testing.assert_allclose(x, ref, rtol=1e-10)
        r = y - W @ ref
        var = (r @ r) / (400 - 6) * np.diag(np.linalg.inv(W.T @ W))
        np.testing.assert_allclose(sd, np.sqrt(var), rtol=1e-6)
