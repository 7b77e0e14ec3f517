"""The convex fit's solver: Clarabel answers at every prior weight of a held-out search on a
short noisy log, and the log-det divergence with its weight in the cones.

References: numpy's log-determinant; the simulated truth's recording judged on held-out
data (blocks of the log the fit did not see); Clarabel's own statuses.
"""

from __future__ import annotations

import types

import numpy as np
import pytest

from dynid.feasibility.convex import identify_consistent
from dynid.feasibility.convex import problem as convex_problem
from dynid.feasibility.convex.problem import ConvexProblem, fallback_note, weighted_neg_log_det
from dynid.friction.model import ClassicalFriction
from dynid.simulation.measurement import SensorNoise

from conftest import planar_2r, recordings

pytestmark = pytest.mark.filterwarnings("ignore::dynid.DynidWarning")


@pytest.mark.parametrize("c", [1.0, 1e-2, 1e-4])
def test_weighted_neg_log_det_is_the_weighted_log_det(c):
    """At a fixed X the term's minimum is ``-c log det X + 4 c log c`` (numpy's slogdet), to
    Clarabel's absolute gap (1e-8) a few times over."""
    import cvxpy as cp

    rng = np.random.default_rng(5)
    G = rng.normal(size=(4, 4))
    X0 = G @ G.T + 0.5 * np.eye(4)
    X = cp.Variable((4, 4), symmetric=True)
    term, cons = weighted_neg_log_det(X, c)
    prob = cp.Problem(cp.Minimize(term), [*cons, X == X0])
    prob.solve(solver=convex_problem.clarabel())
    want = -c * np.linalg.slogdet(X0)[1] + 4.0 * c * np.log(c)
    assert prob.status == "optimal"
    assert prob.value == pytest.approx(want, rel=1e-6, abs=1e-7)


def test_short_noisy_log_is_solved_by_clarabel_at_every_prior_weight(monkeypatch):
    """Regression: on a 3 s noisy log of the planar 2R Clarabel stalled at the held-out
    search's small prior weights (1e-4 and 1e-2: InsufficientProgress, the log-det's cones
    scaled by the weight) and SCS answered. Every solve now ends ``optimal`` at Clarabel's
    first attempt, and the fit is accepted on the held-out blocks."""
    arm = planar_2r()
    friction = ClassicalFriction(np.array([0.2, 0.1]), np.array([0.3, 0.2]), np.zeros(2))
    logs = recordings(
        arm, (6,), friction=friction, duration=3.0, noise=SensorNoise(0.05, 1e-4, 1e-3)
    )
    seen: list[tuple[float, str, int]] = []
    real = ConvexProblem.solve

    def spy(self: ConvexProblem, w: float) -> str:
        before = self.retried
        status = real(self, w)
        seen.append((w, status, self.retried - before))
        return status

    monkeypatch.setattr(ConvexProblem, "solve", spy)
    res = identify_consistent(arm, logs, prior=arm)
    assert len(seen) >= 30 and min(w for w, _, _ in seen) <= 1e-4
    assert [(w, s, r) for w, s, r in seen if s != "optimal" or r] == []
    assert not any("second attempt" in n for n in res.notes)
    j = res.heldout
    assert j is not None and j.accepted
    assert j.heldout_percent <= (1 + j.tolerance) * j.ls_heldout_percent


def test_fallback_note_counts_the_retried_solves_once():
    """No note without a retry; one line with the counts (and SCS's share) otherwise."""
    ok = types.SimpleNamespace(solves=6, retried=0, by_scs=0)
    bad = types.SimpleNamespace(solves=6, retried=2, by_scs=1)
    assert fallback_note([ok, ok]) is None
    note = fallback_note([ok, bad])
    assert note is not None and "2 of 12 solves" in note and "1 of them by SCS" in note
