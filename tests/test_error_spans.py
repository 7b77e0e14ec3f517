"""``validate``'s verdict says when most of the error above the noise sits in one short span
(a contact, a logging fault): a UR5 log with a 50 N m burst on the elbow for 0.2 s was
judged "poor 35.3 %" and blamed on a position-dependent effect of the elbow, never saying
that the rest of the recording sat at the noise floor."""

from __future__ import annotations

import dataclasses
import json

import numpy as np

from dynid.friction.model import ClassicalFriction
from dynid.identification.error_spans import CONTACT_CLAUSE
from dynid.io.torque_log import save_torque_log
from dynid.simulation.measurement import SensorNoise
from dynid.workflows.validate import ValidateOptions, validate_files

from conftest import planar_2r, recordings

FS = 500.0  # [Hz]
T0, T1, JOINT, BURST = 3.0, 3.2, 1, 20.0  # the burst's span [s], joint and size [N m]


def _log(tmp_path, name, added=None):
    """A noisy 6 s recording of the planar 2R arm (true torques, no friction), ``added``
    (N, 2) [N m] on its torques, saved as a CSV file."""
    (log,) = recordings(
        planar_2r(), [7], friction=None, duration=6.0, added=added, noise=SensorNoise(), fs=FS
    )
    return save_torque_log(tmp_path / name, log)


def _burst(log):
    """``BURST`` N m on joint ``JOINT`` from ``T0`` to ``T1`` s."""
    out = np.zeros_like(log.tau)
    out[(log.t >= T0) & (log.t <= T1), JOINT] = BURST
    return out


def test_a_burst_on_one_joint_is_placed_in_its_span_and_the_rest_at_the_noise(tmp_path):
    """The true arm on a log with a 20 N m burst on joint 2 from 3.0 to 3.2 s: the verdict
    starts with the span (within 5 samples of the truth) and its joint, says the rest of
    the recording is at the noise, and ``error_spans`` records it."""
    res = validate_files(planar_2r(), _log(tmp_path, "burst.csv", _burst))
    found = res.error_spans
    assert found is not None, res.verdict.reason
    (span,) = found.spans
    assert abs(span.t0 - T0) <= 5 / FS and abs(span.t1 - T1) <= 5 / FS, span
    assert span.joints == (JOINT,)
    assert found.share > 0.9 and 0.8 < found.rest_ratio < 1.3, found
    assert res.verdict.level != "good"
    assert res.verdict.reason.startswith(f"{100 * found.share:.0f} % of the error above the noise")
    assert "on joint2 (up to" in res.verdict.reason, res.verdict.reason
    assert "a contact or a logging fault there, not the model" in res.verdict.reason
    assert "follows its position" not in res.verdict.reason  # no term diagnosed from it
    assert "the model misses effects" not in res.verdict.reason  # the span clears it
    record = json.loads(json.dumps(res.metadata()))["error_spans"]
    assert record["spans"][0]["joints"] == [JOINT] and record["file"] == "burst.csv"


def test_a_clean_log_has_no_span(tmp_path):
    """The true arm on the same log without the burst: at the noise floor, no span."""
    res = validate_files(planar_2r(), _log(tmp_path, "clean.csv"))
    assert res.verdict.level == "good", res.verdict.reason
    assert res.error_spans is None
    assert res.metadata()["error_spans"] is None


def test_a_missing_term_is_not_placed_in_a_span(tmp_path):
    """Viscous friction (2 N m s/rad) the model does not hold: an error far above the
    noise, spread over the motion, is not put down to a span."""
    res = validate_files(planar_2r(), _log(tmp_path, "visc.csv", lambda log: 2.0 * log.dq))
    assert res.verdict.level != "good", res.verdict.reason
    assert res.error_spans is None, res.verdict.reason
    assert "of the error above the noise sits in t =" not in res.verdict.reason


#: Joint 2's true Coulomb friction [N m], stepping at each of its velocity reversals.
COULOMB = np.array([0.0, 0.8])
#: The positions' encoder step [rad] of the reversal logs.
COUNT = 2.4e-5


def _reversal_log(tmp_path, name, pulse=None):
    """A 6 s noise-free recording of the planar 2R arm (seed 11) with ``COULOMB`` friction
    as ``sign`` of the true velocity (no band), positions quantized to ``COUNT`` and saved
    without velocities, ``pulse`` (t0, t1, torque [N m]) added to joint 2; with the true
    times [s] of joint 2's reversals."""
    truth = ClassicalFriction(np.zeros(2), COULOMB, np.zeros(2))
    (log,) = recordings(planar_2r(), [11], friction=truth, duration=6.0, fs=FS)
    tau = log.tau.copy()
    if pulse is not None:
        tau[(log.t >= pulse[0]) & (log.t <= pulse[1]), 1] += pulse[2]
    positions = dataclasses.replace(
        log, q=np.round(log.q / COUNT) * COUNT, tau=tau, ddq=None, dq_derived=True
    )
    reversals = log.t[1:][np.diff(np.sign(log.dq[:, 1])) != 0]
    return save_torque_log(tmp_path / name, positions), reversals


def _banded_model():
    """The true friction with a 1e-3 rad/s standstill band: it steps a few samples away
    from the truth's instant at a reversal."""
    return ValidateOptions(
        friction=ClassicalFriction(np.zeros(2), COULOMB, np.zeros(2), band=np.full(2, 1e-3))
    )


def test_friction_at_reversals_is_said_as_friction_not_a_contact(tmp_path):
    """The Coulomb step at the reversals, which the banded model places a few samples off
    (the spans the trial blamed on "a contact or a logging fault"): each span lies at a
    true reversal of joint 2, is recorded as one, and the verdict names friction at
    joint2's velocity reversals, no contact."""
    path, reversals = _reversal_log(tmp_path, "reversals.csv")
    res = validate_files(planar_2r(), path, _banded_model())
    found = res.error_spans
    assert found is not None, res.verdict.reason
    for span in found.spans:
        assert span.joints == (JOINT,)
        assert np.min(np.abs(reversals - span.t0)) <= 3 / FS, (span, reversals)
        assert span.peak <= 1.1 * COULOMB[JOINT], span
    assert found.reversal == (True,) * len(found.spans) and not found.contact
    assert "friction at joint2's velocity reversals" in res.verdict.reason
    assert CONTACT_CLAUSE not in res.verdict.reason, res.verdict.reason
    record = json.loads(json.dumps(res.metadata()))["error_spans"]
    assert all(s["reversal"] for s in record["spans"])


def test_a_pulse_away_from_reversals_is_still_a_contact(tmp_path):
    """The same log with 2 N m on joint 2 from 3.00 to 3.05 s (0.2 s from its nearest
    reversal): the pulse's span, within 3 samples of its truth, is named a contact."""
    path, reversals = _reversal_log(tmp_path, "pulse.csv", pulse=(3.0, 3.05, 2.0))
    assert np.min(np.abs(reversals - 3.025)) > 0.2, reversals  # the pulse is away from them
    res = validate_files(planar_2r(), path, _banded_model())
    found = res.error_spans
    assert found is not None, res.verdict.reason
    first = found.spans[0]
    assert abs(first.t0 - 3.0) <= 3 / FS and abs(first.t1 - 3.05) <= 3 / FS, first
    assert first.joints == (JOINT,) and found.reversal[0] is False and found.contact
    assert f"on joint2 (up to {first.peak:.3g} N m): {CONTACT_CLAUSE}" in res.verdict.reason
