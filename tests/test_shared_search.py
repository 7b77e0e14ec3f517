"""The spring's search reads back what the search without it computed.

References: simulated planar 2R recordings with sensor noise, classical friction and a
spring ``k (q2 - q0)`` on joint 2 whose stiffness is known (the truth); the same search
made from scratch, outside any shared block (every recording prepared and every candidate
fitted again), as the slow path the one read back must equal; an arm without a spring as
the control.
"""

from __future__ import annotations

import warnings

import numpy as np

from dynid.exceptions import DynidWarning
from dynid.friction.model import ClassicalFriction
from dynid.identification import selection, shared_search
from dynid.identification.selection import identify_recordings
from dynid.identification.shared_search import shared_searches
from dynid.simulation.measurement import SensorNoise
from dynid.workflows.identify import identify_logs

from conftest import planar_2r, recordings

K, Q0 = 20.0, 0.3  # the spring on joint 2: N m/rad, rad
NOISE = SensorNoise(tau_std=0.05, q_std=1e-5, dq_std=1e-3)
FRICTION = ClassicalFriction(np.array([0.3, 0.2]), np.array([0.5, 0.4]), np.zeros(2))


def _spring(log):
    added = np.zeros_like(log.q)
    added[:, 1] = K * (log.q[:, 1] - Q0)
    return added


def _counted(monkeypatch):
    """The searches made (each a regressor per candidate group fitted) and the
    recordings prepared, counted."""
    made = {"searches": 0, "prepared": 0}
    search, prepare = selection._searched, shared_search.prepare_recordings

    def counted_search(*a, **kw):
        made["searches"] += 1
        return search(*a, **kw)

    def counted_prepare(*a, **kw):
        made["prepared"] += 1
        return prepare(*a, **kw)

    monkeypatch.setattr(selection, "_searched", counted_search)
    monkeypatch.setattr(shared_search, "prepare_recordings", counted_prepare)
    return made


def test_the_spring_search_reads_back_the_first_and_chooses_as_made_again(monkeypatch):
    """Regression: the spring's trial made the whole identification again, the search
    without the spring inside it (a Baxter's run 20 s against 9 s without the trial).
    Within one shared block, after the search without a spring, the search with a spring
    on joint 2 prepares no recording again and fits only the spring's candidates (one
    search more, not two); its choice, table and coefficients equal those of the same
    search made from scratch, and its stiffness is within 1 % of the truth."""
    arm = planar_2r()
    logs = recordings(
        arm, (11, 12, 13), friction=FRICTION, duration=2.5, noise=NOISE, added=_spring
    )
    made = _counted(monkeypatch)
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", DynidWarning)
        slow = identify_recordings(arm, logs, spring_joints=(1,))
        assert made == {"searches": 2, "prepared": 1}  # without a spring, then with one
        with shared_searches():
            identify_recordings(arm, logs)  # the search without a spring
            fast = identify_recordings(arm, logs, spring_joints=(1,))
    assert made == {"searches": 4, "prepared": 2}  # the block's: one search, one preparation
    assert fast.info.selection["chosen"] == slow.info.selection["chosen"]
    assert fast.info.selection["candidates"] == slow.info.selection["candidates"]
    for got, want in ((fast.fit, slow.fit), (fast.joint_fit, slow.joint_fit)):
        assert got is not None and want is not None
        np.testing.assert_array_equal(got.beta, want.beta)
        np.testing.assert_array_equal(got.std, want.std)
    assert fast.spring is not None and slow.spring is not None
    np.testing.assert_array_equal(fast.spring.k, slow.spring.k)
    assert abs(fast.spring.k[1] - K) < 0.01 * K, fast.spring.k


def test_an_arm_without_a_spring_is_searched_once(monkeypatch):
    """The control: the workflow on recordings without a spring searches once and
    prepares the recordings once for the fit (the residual names no spring: no trial, no
    cost)."""
    arm = planar_2r()
    logs = recordings(arm, (11, 12, 13), friction=FRICTION, duration=2.5, noise=NOISE)
    made = _counted(monkeypatch)
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", DynidWarning)
        model = identify_logs(arm, logs).model
    assert model.spring is None
    assert made["searches"] == 1, made
