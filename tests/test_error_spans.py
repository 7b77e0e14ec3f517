"""``validate``'s verdict says when most of the error above the noise sits in one short span
(a contact, a logging fault): a UR5 log with a 50 N m burst on the elbow for 0.2 s was
judged "poor 35.3 %" and blamed on a position-dependent effect of the elbow, never saying
that the rest of the recording sat at the noise floor."""

from __future__ import annotations

import json

import numpy as np

from dynid.io.torque_log import save_torque_log
from dynid.simulation.measurement import SensorNoise
from dynid.workflows.validate import validate_files

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
