"""The structure's held-out judgement predicts the torques as measured, with the columns
that step at a reversal as the model applies them; checked against a direct computation
of that judgement, written out here: two noisy recordings, each left out in turn, the fit
on the low-passed rows (the Coulomb columns through the torques' low-pass at the
recording's own rate, before decimation: the "parallel filtering and decimation" of the
fit) predicting the other recording's measured torques from the sharp Coulomb columns,
``100 sqrt(sum SSE / sum ||tau||^2)``."""

from __future__ import annotations

import warnings

import numpy as np
import pytest

from dynid import signals
from dynid.exceptions import DynidWarning
from dynid.friction.model import ClassicalFriction
from dynid.identification.recordings import prepare_recordings
from dynid.identification.selection import identify_recordings
from dynid.identification.streaming import streams
from dynid.identification.structure import Structure
from dynid.regressors.torque import torque_regressor_numpy
from dynid.simulation.measurement import SensorNoise

from conftest import recordings


def _rows(robot, base, band, labels, piece, raw, cutoff_hz):
    """The rows (sample-major) of one prepared piece: the rigid base columns (numpy
    reference regressor), ``dq_j`` and ``sign(dq_j)`` (0 within the standstill band) in the
    row of joint ``j``; with the Coulomb columns as fitted and as the model applies them
    (sharp); the low-passed and the measured torques. The fitted Coulomb columns come from
    the ``raw`` recording: its velocities low-passed, the sign taken and low-passed at its
    own rate (as its torques were), then read at the piece's samples."""
    log = piece.log
    N, n = log.q.shape
    Y = torque_regressor_numpy(robot, log.q, log.dq, log.ddq)[..., np.asarray(base.independent)]
    fs = 1.0 / float(np.median(np.diff(raw.t)))
    at = np.searchsorted(raw.t, log.t - 1e-9)
    np.testing.assert_allclose(raw.t[at], log.t, rtol=0, atol=1e-12)
    dq_full = signals.lowpass(raw.dq, fs, cutoff_hz, axis=0)
    F = np.zeros((N, n, len(labels)))
    Ff = np.zeros((N, n, len(labels)))
    for c, label in enumerate(labels):
        j = int(label[2:]) - 1
        v = log.dq[:, j]
        if label.startswith("fv"):
            F[:, j, c] = Ff[:, j, c] = v
        else:
            assert label.startswith("fc")
            F[:, j, c] = np.where(np.abs(v) > band[j], np.sign(v), 0.0)
            w = dq_full[:, j]
            step = np.where(np.abs(w) > band[j], np.sign(w), 0.0)
            Ff[:, j, c] = signals.lowpass(step, fs, cutoff_hz)[at]
    fitted = np.concatenate([Y, Ff], axis=-1).reshape(N * n, -1)
    measured = np.concatenate([Y, F], axis=-1).reshape(N * n, -1)
    return fitted, log.tau.reshape(-1), measured, np.asarray(piece.tau_raw).reshape(-1)


@pytest.mark.parametrize("stack_bytes", [None, "100000"], ids=["stacked", "in-blocks"])
def test_heldout_error_of_a_structure_is_the_direct_one_on_measured_torques(
    panda, monkeypatch, stack_bytes
):
    fr = ClassicalFriction(np.linspace(0.6, 0.2, 7), np.linspace(3.0, 1.0, 7), np.zeros(7))
    logs = recordings(panda, (61, 62), friction=fr, duration=4.0, noise=SensorNoise())
    if stack_bytes is not None:  # rows too many to stack: fitted and judged in blocks
        monkeypatch.setenv("DYNID_MAX_STACK_BYTES", stack_bytes)
    structure = Structure(friction=("viscous", "coulomb"))
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", DynidWarning)
        # ordinary least squares, as the direct fit below (the estimator chosen on these
        # folds is wls: the states' noise through the model differs by joint)
        model = identify_recordings(panda, logs, structure=structure, estimator="ols")
        data = prepare_recordings(panda, logs)
    term = model.terms["friction"].term
    band = np.asarray(term.band)
    assert band.size == 7 and np.all(band > 0)
    assert len(data.pieces) == 2  # one piece per recording: leave one recording out
    rows = [
        _rows(panda, model.base, band, term.labels, p, raw, data.cutoff_hz)
        for p, raw in zip(data.pieces, logs, strict=True)
    ]
    assert streams(data.n_samples * 7, rows[0][0].shape[1]) == (stack_bytes is not None)
    sse = norm = 0.0
    for k, (_, _, Wm, ym) in enumerate(rows):
        Wf, yf = rows[1 - k][0], rows[1 - k][1]
        x = np.linalg.lstsq(Wf, yf, rcond=None)[0]
        sse += float(np.sum((ym - Wm @ x) ** 2))
        norm += float(np.sum(ym**2))
    want = 100.0 * np.sqrt(sse / norm)
    held = model.info.heldout
    assert held["scheme"] == "recordings" and held["folds"] == 2
    # the fit's columns are computed from the decimated velocities interpolated between
    # their samples: equal to 2e-7 inside a recording, they differ where it starts and ends
    # at rest, its velocity at the standstill band (rel 3e-4 here; the columns filtered at
    # the decimated rate were 20 % off: 0.843 % against 0.699 %)
    assert held["heldout_error_percent"] == pytest.approx(want, rel=1e-3)
    # the measured torques are what is judged: the low-passed ones give another error
    sse_f = sum(
        float(np.sum((r[1] - r[0] @ np.linalg.lstsq(o[0], o[1], rcond=None)[0]) ** 2))
        for r, o in ((rows[0], rows[1]), (rows[1], rows[0]))
    )
    filtered = 100.0 * np.sqrt(sse_f / sum(float(np.sum(r[1] ** 2)) for r in rows))
    assert abs(filtered - want) > 1e-3 * want


def test_a_weighted_estimator_is_judged_on_the_torques_as_measured_unweighted(panda):
    """irls: each recording's fold fit (the estimator's, from the model's own folds)
    predicting the other recording's measured torques, unweighted, is the held-out error
    printed (its Huber and per-joint weights in the judgement made a UR5's 0.279 % read
    0.398 %, where the same model predicted a new recording to 0.252 %)."""
    fr = ClassicalFriction(np.linspace(0.6, 0.2, 7), np.linspace(3.0, 1.0, 7), np.zeros(7))
    logs = recordings(panda, (63, 64), friction=fr, duration=4.0, noise=SensorNoise())
    structure = Structure(friction=("viscous", "coulomb"))
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", DynidWarning)
        model = identify_recordings(panda, logs, structure=structure, estimator="irls")
        data = prepare_recordings(panda, logs)
    term = model.terms["friction"].term
    band = np.asarray(term.band)
    rows = [
        _rows(panda, model.base, band, term.labels, p, raw, data.cutoff_hz)
        for p, raw in zip(data.pieces, logs, strict=True)
    ]
    assert model.holdout is not None and model.holdout.folds == 2
    sse = norm = 0.0
    for k, (_, _, Wm, ym) in enumerate(rows):
        x = model.holdout.train[k].solve()  # the fit without recording k
        sse += float(np.sum((ym - Wm @ x) ** 2))
        norm += float(np.sum(ym**2))
    want = 100.0 * np.sqrt(sse / norm)
    assert model.info.heldout["heldout_error_percent"] == pytest.approx(want, rel=1e-3)
