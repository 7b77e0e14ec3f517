"""The folds' normal equations gathered in one pass equal those of the rows written out."""

from __future__ import annotations

import numpy as np
import pytest

from dynid.identification.holdout import block_normals, rows_labelled
from dynid.identification.streaming import normals_by_label_scaled


def _direct(W, y, w, origin):
    """``(W^T W, W^T y, y^T y, |y - W origin|^2)`` of the rows times ``w``, by numpy alone."""
    Ww, yw = W * w[:, None], y * w
    r = yw - Ww @ origin
    return Ww.T @ Ww, Ww.T @ yw, yw @ yw, r @ r


@pytest.mark.parametrize("shuffled", [False, True])
def test_plain_and_noise_scaled_normals_are_those_of_the_rows(shuffled):
    """Sample-major rows (row ``k n + j`` of joint ``j``, summed per joint in one Gram each)
    and rows whose groups follow no pattern give, per fold, the plain rows' and the rows
    times their group's scale normal equations and residual at the origin."""
    rng = np.random.default_rng(7)
    n, m, p, k = 7, 240, 11, 3
    W, y = rng.normal(size=(n * m, p)), rng.normal(size=n * m)
    g = np.tile(np.arange(n), m)
    if shuffled:
        g = rng.permutation(g)
    labels = np.repeat(np.minimum(np.arange(m) * k // m, k - 1), n)
    scale, origin = rng.uniform(0.5, 3.0, n), rng.normal(size=p)
    plain, scaled = normals_by_label_scaled(lambda: iter([(W, y, g)]), labels, None, scale, origin)
    for j in range(k):
        sel = labels == j
        for got, w in ((plain[j], np.ones(sel.sum())), (scaled[j], scale[g[sel]])):
            G, b, c, e = _direct(W[sel], y[sel], w, origin)
            np.testing.assert_allclose(got.G, G, rtol=1e-12, atol=1e-10)
            np.testing.assert_allclose(got.b, b, rtol=1e-12, atol=1e-10)
            assert got.c == pytest.approx(c, rel=1e-12)
            assert got.sse0 == pytest.approx(e, rel=1e-12)
            assert got.rows == sel.sum()


def test_block_normals_of_contiguous_and_scattered_folds_are_those_of_the_rows():
    """Folds of contiguous rows (read as slices) and folds of scattered rows give each
    fold's normal equations as the rows selected by a mask do."""
    rng = np.random.default_rng(8)
    W, y, origin = rng.normal(size=(90, 6)), rng.normal(size=90), rng.normal(size=6)
    for labels in (np.repeat(np.arange(3), 30), rng.permutation(np.repeat(np.arange(3), 30))):
        assert isinstance(rows_labelled(labels, 1), slice) == (labels[30:60] == 1).all()
        for j, got in enumerate(block_normals(W, y, labels, origin)):
            G, b, c, e = _direct(W[labels == j], y[labels == j], np.ones(30), origin)
            np.testing.assert_allclose(got.G, G, rtol=1e-12, atol=1e-10)
            np.testing.assert_allclose(got.b, b, rtol=1e-12, atol=1e-10)
            assert (got.c, got.rows) == (pytest.approx(c, rel=1e-12), 30)
            assert got.sse0 == pytest.approx(e, rel=1e-12)
