"""A structure given (``--terms``) over several recordings: each recording is judged under
it as the structure's search judges them, and one outlying is named with its span; a
torque burst is cut out of it (the span with the filter's edge beside it), a residual
spread over the recording leaves it out of the final fit; ``keep_outlying`` keeps it.

Regression: a 6-DoF arm's three recordings, one with a 30 N m burst on joint 2 for 0.1 s,
fitted all three when the structure was given (training error 15.4 %, 13.4 % on a fourth
recording for a 1.01 % floor); the search left it out.

References: a simulated planar 2R arm with known viscous and Coulomb friction and sensor
noise; a burst added at a known time on a known joint of one recording, or a 0.5 kg load
at the flange throughout another; a held-out
recording exact to round-off (its true torques and accelerations), predicted by the
models; the friction the logs were simulated with.
"""

from __future__ import annotations

import dataclasses

import numpy as np
import pytest

from dynid.cli.structure_table import per_recording_lines
from dynid.friction.model import ClassicalFriction, friction_of
from dynid.identification.selection import fitted_logs, identify_recordings
from dynid.identification.structure import Structure
from dynid.simulation.measurement import SensorNoise

from conftest import planar_2r, recordings, said_warnings

FV = np.array([0.3, 0.2])  # N m s/rad
FC = np.array([0.8, 0.5])  # N m
FRICTION = ClassicalFriction(FV, FC, np.zeros(2))
NAMES = ["a.csv", "burst.csv", "c.csv"]
GIVEN = Structure(friction=("viscous", "coulomb"))


@pytest.fixture(scope="module")
def arm():
    return planar_2r()


@pytest.fixture(scope="module")
def logs(arm):
    """Three noisy recordings of the arm (4 s at 200 Hz), the second with 20 N m added to
    joint 2 over 2.0 <= t < 2.1 s, and a held-out recording exact to round-off."""
    kw = dict(friction=FRICTION, duration=4.0, fs=200.0)
    train = recordings(arm, [1, 2, 3], noise=SensorNoise(), **kw)
    clean = list(train)
    tau = train[1].tau.copy()
    tau[(train[1].t >= 2.0) & (train[1].t < 2.1), 1] += 20.0
    train[1] = dataclasses.replace(train[1], tau=tau)
    (held,) = recordings(arm, [9], **kw)
    return train, held, clean


def _error_percent(model, log):
    """The model's relative error [%] predicting ``log``'s true torques (links and
    friction)."""
    tau = model.torques(log.q, log.dq, log.ddq)
    tau = tau + sum(friction_of(f).torques(log.dq) for f in model.frictions)
    return 100 * np.sqrt(np.mean((tau - log.tau) ** 2) / np.mean(log.tau**2))


def test_a_given_structure_cuts_the_burst_out_and_names_its_span(arm, logs):
    """The structure given: the burst recording named in one warning with its span (about
    2.0 to 2.1 s on joint 2), that span cut out of it with the filter's edge beside it and
    the rest fitted; the fit predicts the exact held-out recording within the noise floor
    (the fit that keeps the burst: several times over), its friction within 10 % of the
    truth and within 2 % of the fit of the same recordings simulated without the burst
    (the noise's share: fv1 0.28 for 0.3 in both); the record holds each recording's
    held-out error and the interval cut."""
    train, held, clean = logs
    model, said = said_warnings(identify_recordings, arm, train, NAMES, structure=GIVEN)
    kept, said_kept = said_warnings(
        identify_recordings, arm, train, NAMES, structure=GIVEN, keep_outlying=True
    )
    (warned,) = [m for m in said if m.startswith("burst.csv: held-out error")]
    assert "with the structure given" in warned and "out of burst.csv" in warned
    head = "stands off burst.csv's at t = "
    assert head in warned, warned
    t0, t1 = (float(x) for x in warned.split(head)[1].split(" s ")[0].split(" to "))
    assert 1.95 <= t0 <= 2.05 and 2.05 <= t1 <= 2.15, (t0, t1)
    assert warned.split(head)[1].split(" on ")[1].startswith(f"{arm.joint_names[1]} (up to")
    assert any("keeps it" in m for m in said_kept if m.startswith("burst.csv: held-out"))
    assert model.info.selection is None  # given, not chosen
    recs = model.info.recordings
    assert not any(r.get("left_out") for r in recs) and "cut_out" not in recs[0]
    ((a, b),) = recs[1]["cut_out"]
    assert 1.8 < a < 2.0 and 2.1 < b < 2.3, (a, b)  # the burst and the filter's edge
    (cut,) = fitted_logs(model, train)[1:2]
    assert not np.any((cut.t >= 2.0) & (cut.t < 2.1)) and cut.n_samples < train[1].n_samples
    assert not any(r.get("cut_out") for r in kept.info.recordings)
    assert recs[1]["sha256"] == kept.info.recordings[1]["sha256"]  # the file as read
    assert model.info.extra["outlying_recordings"] == ["burst.csv"]
    per = {r["file"]: r["heldout_error_percent"] for r in model.info.extra["heldout_per_recording"]}
    assert list(per) == NAMES and per["burst.csv"] < 1.5 * max(per["a.csv"], per["c.csv"])
    err, err_kept = _error_percent(model, held), _error_percent(kept, held)
    floor = model.info.heldout["noise_floor_percent"]  # of the noisy recordings fitted
    assert err < floor and err_kept > 3 * floor, (err, err_kept, floor)
    unburst = identify_recordings(arm, clean, NAMES, structure=GIVEN)
    np.testing.assert_allclose(model.friction.params[:, 0], FV, rtol=0.1)
    np.testing.assert_allclose(model.friction.params[:, 1], FC, rtol=0.1)
    fitted, alone = model.friction.params[:, :2], unburst.friction.params[:, :2]
    np.testing.assert_allclose(fitted, alone, rtol=0.02)
    (line,) = per_recording_lines(model.info.extra, given=True)
    assert line.startswith("held-out error of the structure given per recording")
    assert "% (outlying: its spans cut out), c.csv " in line, line


def test_a_given_structure_leaves_a_recording_out_whose_residual_is_spread(arm):
    """The structure given, one recording carrying an unknown 0.5 kg load throughout: no
    short span holds its residual, so it is left out whole (named in the warning); the
    fit of the other two predicts the exact held-out recording within the noise floor."""
    loaded = arm.with_tool(np.eye(4), 0.5, (0.05, 0.0, 0.0), np.diag([1e-3] * 3), name="load")
    kw = dict(friction=FRICTION, duration=4.0, fs=200.0)
    a, c = recordings(arm, [1, 3], noise=SensorNoise(), **kw)
    (load,) = recordings(loaded, [2], noise=SensorNoise(), **kw)
    (held,) = recordings(arm, [9], **kw)
    names = ["a.csv", "load.csv", "c.csv"]
    model, said = said_warnings(identify_recordings, arm, [a, load, c], names, structure=GIVEN)
    (warned,) = [m for m in said if m.startswith("load.csv: held-out error")]
    assert "leaves it out" in warned and "cut_out" not in warned
    assert [bool(r.get("left_out")) for r in model.info.recordings] == [False, True, False]
    assert fitted_logs(model, [a, load, c]) == [a, c]
    assert model.info.extra["cut_out_spans"] == []
    assert _error_percent(model, held) < model.info.heldout["noise_floor_percent"]


def test_a_given_structure_over_recordings_alike_is_fitted_on_all(arm, logs):
    """Three recordings alike, the structure given: none named, none left out, the model
    that of keep_outlying to round-off."""
    train, held, _ = logs
    clean = [train[0], train[2], held]
    model, said = said_warnings(identify_recordings, arm, clean, NAMES, structure=GIVEN)
    kept, _ = said_warnings(
        identify_recordings, arm, clean, NAMES, structure=GIVEN, keep_outlying=True
    )
    assert model.info.extra["outlying_recordings"] == []
    assert not any("left_out" in r for r in model.info.recordings)
    np.testing.assert_allclose(model.fit.beta, kept.fit.beta, rtol=1e-12, atol=1e-12)
    assert not [m for m in said if "held-out error" in m]
