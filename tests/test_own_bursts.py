"""Of one or two recordings, where no recording can be judged against the others, a short
burst in the fit's own residual (a contact, a logging fault) is cut out of its recording and
the structure chosen and fitted again on the rest; a clean recording, a point-to-point log
with rests and a log holding a smooth effect the model lacks (a spring, a tilted base) are
not cut.

Regression: a 6-DoF arm's one recording with a 20 N m burst on joint 2 for 0.1 s, fitted
whole: training error 10.97 % for a 1.12 % floor, a clean recording predicted at 5.15 %
(its floor 1.13 %), the burst named nowhere.

References: a simulated planar 2R arm (and the Panda) with known viscous and Coulomb
friction and sensor noise; a burst added at a known time on a known joint; a spring of
known stiffness added to the torques; the Panda's gravity tilted by a known angle; a
held-out recording exact to round-off (its true torques and accelerations), predicted by
the models.
"""

from __future__ import annotations

import dataclasses

import numpy as np
import pytest

import dynid
from dynid.friction.model import ClassicalFriction, friction_of
from dynid.identification.selection import fitted_logs, identify_recordings
from dynid.identification.structure import Structure
from dynid.simulation.measurement import SensorNoise, sample_times, simulate_measurement
from dynid.simulation.trajectories import random_fourier
from dynid.simulation.unmodelled import UnmodelledEffects

from conftest import planar_2r, point_to_point, recordings, said_warnings

FV = np.array([0.3, 0.2])  # N m s/rad
FC = np.array([0.8, 0.5])  # N m
FRICTION = ClassicalFriction(FV, FC, np.zeros(2))
T0, JOINT, BURST = 3.0, 1, 20.0  # the burst's start [s] (0.1 s long), joint, size [N m]
SAID = "the fit's own residual"


@pytest.fixture(scope="module")
def arm():
    return planar_2r().replace(q_min=(-2.5, -2.5), q_max=(2.5, 2.5))


def _noisy(arm, seeds, **kw):
    """Noisy 6 s recordings of the arm at 200 Hz with the true friction."""
    return recordings(
        arm, seeds, friction=FRICTION, duration=6.0, fs=200.0, noise=SensorNoise(), **kw
    )


def _burst(log, t0=T0, joint=JOINT, length=0.1):
    """``log`` with ``BURST`` N m on ``joint`` over ``t0 <= t < t0 + length`` s."""
    tau = log.tau.copy()
    tau[(log.t >= t0) & (log.t < t0 + length), joint] += BURST
    return dataclasses.replace(log, tau=tau)


def _reversals(log, joint=JOINT):
    """The times [s] where ``joint``'s true velocity changes sign (an exact log's)."""
    s = np.sign(log.dq[:, joint])
    return log.t[np.flatnonzero(s[:-1] != s[1:])]


def _error_percent(model, log):
    """The model's relative error [%] predicting ``log``'s true torques."""
    tau = model.torques(log.q, log.dq, log.ddq)
    tau = tau + sum(friction_of(f).torques(log.dq) for f in model.frictions)
    return 100 * np.sqrt(np.mean((tau - log.tau) ** 2) / np.mean(log.tau**2))


def _span(warned):
    """The span [s] a warning names first."""
    head = warned.split("sits in t = ")[1]
    return tuple(float(x) for x in head.split(" s ")[0].split(" to "))


def test_one_recording_with_a_burst_is_cut_and_the_span_named(arm):
    """One recording, the structure chosen: the warning names the recording, the span
    (within 2 samples of 3.0 to 3.1 s), joint 2 and its peak; the span with the filter's
    edge beside it is cut out (recorded as an outlying recording's cut); the model
    predicts the exact held-out recording within the noise floor, where the fit that keeps
    the burst (keep_outlying) stands several times above it."""
    (log,) = _noisy(arm, [1])
    (held,) = recordings(arm, [9], friction=FRICTION, duration=6.0, fs=200.0)
    model, said = said_warnings(identify_recordings, arm, [_burst(log)], ["b.csv"])
    kept, said_kept = said_warnings(
        identify_recordings, arm, [_burst(log)], ["b.csv"], keep_outlying=True
    )
    (warned,) = [m for m in said if SAID in m]
    assert warned.startswith("b.csv: ") and "out of b.csv" in warned
    t0, t1 = _span(warned)
    assert abs(t0 - T0) <= 0.011 and abs(t1 - (T0 + 0.1)) <= 0.011, (t0, t1)
    assert f"s on {arm.joint_names[JOINT]} (up to " in warned
    peak = float(warned.split("(up to ")[1].split(" N m")[0])
    assert 15 < peak < 25, peak
    assert not [m for m in said_kept if SAID in m]
    ((a, b),) = model.info.recordings[0]["cut_out"]
    assert 2.8 < a < T0 and T0 + 0.1 < b < 3.3, (a, b)
    assert model.info.recordings[0]["cut_samples"] > 20
    assert model.info.selection["cut_out_spans"] == [{"file": "b.csv", "intervals": [[a, b]]}]
    (cut,) = fitted_logs(model, [log])
    assert not np.any((cut.t >= T0) & (cut.t < T0 + 0.1))
    floor = model.info.heldout["noise_floor_percent"]
    err, err_kept = _error_percent(model, held), _error_percent(kept, held)
    assert err < floor and err_kept > 3 * floor, (err, err_kept, floor)
    assert model.fit.relative_error_percent < 1.5 * floor < kept.fit.relative_error_percent


def test_two_recordings_one_with_a_burst_the_structure_given(arm):
    """Two recordings, the structure given: the burst's recording alone is cut, recorded
    in the metadata as the three-recording check records it, the friction within 10 % of
    the truth."""
    a, b = _noisy(arm, [1, 2])
    given = Structure(friction=("viscous", "coulomb"))
    model, said = said_warnings(
        identify_recordings, arm, [a, _burst(b)], ["a.csv", "b.csv"], structure=given
    )
    (warned,) = [m for m in said if SAID in m]
    assert warned.startswith("b.csv: ")
    recs = model.info.recordings
    assert "cut_out" not in recs[0] and len(recs[1]["cut_out"]) == 1
    assert model.info.extra["cut_out_spans"][0]["file"] == "b.csv"
    np.testing.assert_allclose(model.friction.params[:, 0], FV, rtol=0.1)
    np.testing.assert_allclose(model.friction.params[:, 1], FC, rtol=0.1)


def _point_to_point(arm):
    """A noisy point-to-point log of the arm (eight moves, each with a 1 s rest)."""
    traj = point_to_point(arm, 3, fs=200.0)
    rng = np.random.default_rng(103)
    return simulate_measurement(arm, traj, rng=rng, noise=SensorNoise(), friction=FRICTION)


def _spring(log):
    """A spring on each joint (4 and 2 N m/rad) the model lacks: spread over the motion."""
    return np.column_stack([4.0 * (log.q[:, 0] - 0.2), 2.0 * (log.q[:, 1] + 0.1)])


@pytest.mark.parametrize("kind", ["clean", "two clean", "point to point", "spring"])
def test_a_recording_without_a_burst_is_not_cut(arm, kind):
    """A clean recording (and two), a point-to-point log with rests, a recording with a
    spring the model lacks (its residual 20 x the noise, spread over the motion): none
    cut, no warning, the model that of keep_outlying."""
    logs = {
        "clean": lambda: _noisy(arm, [1]),
        "two clean": lambda: _noisy(arm, [1, 2]),
        "point to point": lambda: [_point_to_point(arm)],
        "spring": lambda: _noisy(arm, [1], added=_spring),
    }[kind]()
    names = [f"r{i}.csv" for i in range(len(logs))]
    model, said = said_warnings(identify_recordings, arm, logs, names)
    kept = identify_recordings(arm, logs, names, keep_outlying=True)
    assert not [m for m in said if SAID in m]
    assert not any("cut_out" in r for r in model.info.recordings)
    assert model.info.selection["cut_out_spans"] == []
    np.testing.assert_allclose(model.fit.beta, kept.fit.beta, rtol=1e-12, atol=1e-12)


def test_a_pandas_coulomb_steps_at_reversals_are_not_cut():
    """Two 4 s Panda recordings with Coulomb friction of 3 to 1 N m, the structure given:
    the fit on filtered torques and the model's sharp step leave single samples 27 times
    the noise at the joints' reversals, friction's, not a burst: not cut."""
    pan = dynid.panda()
    fr = ClassicalFriction(np.linspace(0.6, 0.2, 7), np.linspace(3.0, 1.0, 7), np.zeros(7))
    logs = recordings(pan, (61, 62), friction=fr, duration=4.0, noise=SensorNoise())
    given = Structure(friction=("viscous", "coulomb"))
    model, said = said_warnings(identify_recordings, pan, logs, structure=given, estimator="ols")
    assert not [m for m in said if SAID in m]
    assert not any("cut_out" in r for r in model.info.recordings)


def test_a_tilted_panda_is_not_cut_and_its_burst_is():
    """The Panda, 8 s at 200 Hz: its gravity tilted by 0.05 rad (the level model's residual
    spread over the motion) is not cut; the level arm with a 0.1 s burst on joint 2 at
    4.0 s is, the span named (the structure given: one fit each)."""
    pan = dynid.panda()
    t = sample_times(8.0, 200.0)
    given = Structure(friction=("viscous", "coulomb"))

    def log(tilt):
        eff = UnmodelledEffects(np.zeros(7), np.zeros(7), gravity_tilt=tilt) if tilt else None
        traj = random_fourier(pan, np.random.default_rng(1))(t)
        rng = np.random.default_rng(101)
        return simulate_measurement(
            pan, traj, rng=rng, noise=SensorNoise(), friction=None, effects=eff
        )

    tilted, said = said_warnings(identify_recordings, pan, [log(0.05)], ["t.csv"], structure=given)
    assert not [m for m in said if SAID in m] and "cut_out" not in tilted.info.recordings[0]
    assert tilted.fit.relative_error_percent > 3.0  # the tilt left in the residual
    burst, said = said_warnings(
        identify_recordings, pan, [_burst(log(0.0), 4.0)], ["p.csv"], structure=given
    )
    (warned,) = [m for m in said if SAID in m]
    t0, t1 = _span(warned)
    assert abs(t0 - 4.0) <= 0.02 and abs(t1 - 4.1) <= 0.02, (t0, t1)  # a decimated step
    assert f"s on {pan.joint_names[JOINT]} (up to " in warned
    assert len(burst.info.recordings[0]["cut_out"]) == 1


def test_a_burst_at_a_reversal_is_cut(arm):
    """Regression: a burst that sits at a joint's reversal was left out of the judgement
    as friction's step there and never cut (the arm's exact held-out recording predicted
    at 10.3 % for a 0.40 % floor). A 0.2 s burst of 20 N m centred on joint 2's reversal
    (40 times its Coulomb step): named, cut out around the reversal, the exact held-out
    recording predicted within the noise floor, where the fit that keeps it stands
    several times above."""
    (exact,) = recordings(arm, [1], friction=FRICTION, duration=6.0, fs=200.0)
    (at,) = [r for r in _reversals(exact) if 1.5 < r < 4.5]
    (log,) = _noisy(arm, [1])
    (held,) = recordings(arm, [9], friction=FRICTION, duration=6.0, fs=200.0)
    burst = _burst(log, at - 0.1, length=0.2)
    model, said = said_warnings(identify_recordings, arm, [burst], ["b.csv"])
    kept = identify_recordings(arm, [burst], ["b.csv"], keep_outlying=True)
    (warned,) = [m for m in said if SAID in m]
    t0, t1 = _span(warned)
    assert t0 < at < t1 and abs(t0 - (at - 0.1)) <= 0.011, (t0, t1, at)
    assert f"s on {arm.joint_names[JOINT]} (up to " in warned
    ((a, b),) = model.info.recordings[0]["cut_out"]
    assert a < at - 0.1 and at + 0.1 < b, (a, b, at)
    floor = model.info.heldout["noise_floor_percent"]
    err, err_kept = _error_percent(model, held), _error_percent(kept, held)
    assert err < floor and err_kept > 5 * floor, (err, err_kept, floor)


def test_a_pandas_burst_at_a_reversal_is_cut_and_its_coulomb_steps_are_not():
    """Regression: two 8 s Panda recordings with Coulomb friction of 3 to 1 N m, the
    structure given; a 20 N m burst over 0.2 s centred on joint 2's reversal in the second
    (where its Coulomb step leaves single samples 50 times the noise) was never cut (an
    exact held-out recording at 3.7 % for a 0.37 % floor). Now it is, the one interval
    around that reversal; the Coulomb steps at the other reversals are not cut, neither
    in the clean recordings nor beside the burst."""
    pan = dynid.panda()
    fr = ClassicalFriction(np.linspace(0.6, 0.2, 7), np.linspace(3.0, 1.0, 7), np.zeros(7))
    kw = {"friction": fr, "duration": 8.0, "fs": 200.0}
    exact = recordings(pan, (61, 62), **kw)
    at = _reversals(exact[1])[1]
    logs = recordings(pan, (61, 62), noise=SensorNoise(), **kw)
    (held,) = recordings(pan, [63], **kw)
    given = Structure(friction=("viscous", "coulomb"))
    fit = {"structure": given, "estimator": "ols"}
    clean, said = said_warnings(identify_recordings, pan, logs, ["a.csv", "b.csv"], **fit)
    assert not [m for m in said if SAID in m]
    assert not any("cut_out" in r for r in clean.info.recordings)
    logs[1] = _burst(logs[1], at - 0.1, length=0.2)
    model, said = said_warnings(identify_recordings, pan, logs, ["a.csv", "b.csv"], **fit)
    kept = identify_recordings(pan, logs, ["a.csv", "b.csv"], keep_outlying=True, **fit)
    (warned,) = [m for m in said if SAID in m]
    assert warned.startswith("b.csv: ")
    recs = model.info.recordings
    assert "cut_out" not in recs[0]
    ((a, b),) = recs[1]["cut_out"]
    assert a < at - 0.1 and at + 0.1 < b < at + 0.5, (a, b, at)
    floor = model.info.heldout["noise_floor_percent"]
    err, err_kept = _error_percent(model, held), _error_percent(kept, held)
    assert err < 1.5 * floor and err_kept > 5 * floor, (err, err_kept, floor)
