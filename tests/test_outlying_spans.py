"""An outlying recording's warning says where in it the residual stands off (time span
and joints), not only that the recording is left out.

Regression: three recordings, one with a 0.2 s torque burst on one joint, and the warning
named the recording without saying where the burst was. References: a residual built
with a known burst (closed form); a simulated planar 2R arm with known friction and
sensor noise, a burst added at a known time on a known joint.
"""

from __future__ import annotations

import dataclasses

import numpy as np

from dynid.friction.model import ClassicalFriction
from dynid.identification.outlying_spans import outlying_spans, spans_text
from dynid.identification.recordings import prepare_recordings
from dynid.identification.selection import select_structure
from dynid.simulation.measurement import SensorNoise

from conftest import planar_2r, recordings, said_warnings


def test_a_burst_is_one_span_on_its_joint():
    """Gaussian noise (0.05 N m) with 30 N m on joint 2 over 3.0 <= t < 3.2 s: one span
    from 3.0 to 3.19 s on joint 2, its peak the burst's, nearly all the squared residual;
    said with the joint's name and the times."""
    rng = np.random.default_rng(3)
    t = np.arange(0.0, 8.0, 0.01)
    e = 0.05 * rng.standard_normal((t.size, 2))
    burst = (t >= 3.0) & (t < 3.2)
    e[burst, 1] += 30.0
    (span,) = [s for s in outlying_spans(t, e) if s.share > 0.01]
    assert span.joints == (1,)
    assert abs(span.t0 - 3.0) < 1e-9 and abs(span.t1 - 3.19) < 1e-9
    assert abs(span.peak - 30.0) < 0.3 and span.share > 0.99
    text = spans_text(outlying_spans(t, e), ("shoulder", "elbow"))
    assert text.startswith("t = 3.000 to 3.190 s on elbow (up to")


def test_the_outlying_recording_s_warning_names_the_burst_s_time_and_joint():
    """Three noisy recordings of a planar 2R arm, the second with 20 N m added to joint 2
    over 2.0 <= t < 2.2 s: the warning that leaves it out says its residual stands off
    from about 2.0 to 2.2 s on that joint."""
    arm = planar_2r()
    fr = ClassicalFriction(np.array([0.3, 0.2]), np.array([0.8, 0.5]), np.zeros(2))
    logs = recordings(arm, [1, 2, 3], friction=fr, duration=4.0, fs=200.0, noise=SensorNoise())
    tau = logs[1].tau.copy()
    tau[(logs[1].t >= 2.0) & (logs[1].t < 2.2), 1] += 20.0
    logs[1] = dataclasses.replace(logs[1], tau=tau)
    data = prepare_recordings(arm, logs, ["a.csv", "burst.csv", "c.csv"])
    sel, said = said_warnings(select_structure, arm, data)
    assert sel is not None and sel.outlying == ("burst.csv",)
    (warned,) = [m for m in said if m.startswith("burst.csv: held-out error")]
    head = "stands off burst.csv's at t = "
    assert head in warned, warned
    t0, t1 = (float(x) for x in warned.split(head)[1].split(" s ")[0].split(" to "))
    assert 1.95 <= t0 <= 2.05 and 2.1 <= t1 <= 2.25, (t0, t1)
    assert warned.split(head)[1].split(" on ")[1].startswith(f"{arm.joint_names[1]} (up to")


def test_short_spans_that_hold_nearly_all_the_residual_are_cut_with_a_margin():
    """Closed form: a recording 17.5 x the others' median with 99.8 % of its squared
    residual in one 0.09 s span: cut, widened by the margin on both sides (the rest would
    stand at 17.5 sqrt(0.002) = 0.78 x); with 90 % in it (rest 5.5 x), with the span over
    most of the recording, or with an interval the preparation would bridge: not cut."""
    from dynid.identification.outlying_spans import Span, cut_intervals, without_intervals

    t = np.arange(0.0, 10.0, 0.005)
    burst = (Span(5.005, 5.095, (1,), 30.0, 0.998),)
    np.testing.assert_allclose(cut_intervals(burst, 17.5, t, 0.1, 0.0125), [[4.905, 5.195]])
    assert cut_intervals((Span(5.005, 5.095, (1,), 30.0, 0.9),), 17.5, t, 0.1, 0.0125) == ()
    assert cut_intervals((Span(1.0, 8.0, (1,), 30.0, 0.998),), 17.5, t, 0.1, 0.0125) == ()
    assert cut_intervals(burst, 17.5, t, 0.1, 0.5) == ()
    # two spans whose margins overlap are one interval; a noise span below 1 % stays
    two = (Span(5.0, 5.05, (1,), 30.0, 0.6), Span(5.1, 5.15, (0,), 20.0, 0.399))
    noise = Span(8.0, 8.0, (0,), 0.2, 1e-4)
    np.testing.assert_allclose(cut_intervals((*two, noise), 10.0, t, 0.1, 0.0125), [[4.9, 5.25]])
    keep = without_intervals(t, ((4.9, 5.25),))
    assert keep.sum() == t.size - np.count_nonzero((t >= 4.9) & (t <= 5.25))
