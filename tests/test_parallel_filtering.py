"""The columns that step at a velocity reversal go through the torques' low-pass at the
rate the torques were filtered at, before decimation, with the samples trimmed at the
ends ("parallel filtering and decimation", Gautier and Khalil).

References: the recording itself, its velocities low-passed, the sign taken and low-passed
at its own rate (scipy's Butterworth through ``dynid.signals.lowpass``) and read at the
prepared samples; and the ground truth of exact simulated recordings.
"""

from __future__ import annotations

import numpy as np

from dynid import signals
from dynid.friction.model import ClassicalFriction
from dynid.identification.log_rows import stepped_filtered
from dynid.identification.prepare import Preprocessing, trimmed_margins
from dynid.identification.prepared_log import prepare_torque_log
from dynid.identification.selection import identify_recordings
from dynid.identification.structure import Structure
from dynid.model.drive import Drive
from dynid.regressors.terms import LinearFriction

from conftest import recordings

FV, FC = np.linspace(0.6, 0.2, 7), np.linspace(3.0, 1.0, 7)
FRICTION = ClassicalFriction(FV, FC, np.zeros(7))
ARMATURE = np.array([0.3, 0.3, 0.2, 0.2, 0.1, 0.1, 0.1])


def test_stepped_columns_are_the_recordings_filtered_at_its_own_rate(panda):
    """The Coulomb columns at the prepared (decimated) samples equal the recording's sign
    of its low-passed velocities, low-passed at its own rate: to 1e-9 from the states at
    every sample (the log's ``fine`` states), to 1e-4 of the step inside the log and 1e-2
    at its ends from states interpolated between the decimated samples (a log too long to
    hold them); those filtered at the decimated rate without the trimmed samples were 10
    times further off inside and 20 times at the ends."""
    (log,) = recordings(panda, (5,), friction=FRICTION, duration=6.0, fs=1000.0)
    p = prepare_torque_log(panda, log)
    assert p.decimate > 1 and p.fine is not None and p.head is None
    prep = Preprocessing(cutoff_hz=p.cutoff_hz, decimate=p.decimate)
    head, tail = trimmed_margins(log, prep)
    assert head is not None and tail is not None
    term = LinearFriction(Drive.identity(7))
    steps = np.asarray(term.steps)
    dq = signals.lowpass(log.dq, log.sample_rate, p.cutoff_hz, axis=0)
    want = signals.lowpass(np.sign(dq), log.sample_rate, p.cutoff_hz, axis=0)
    want = want[np.searchsorted(log.t, p.log.t - 1e-9)]
    rows = slice(0, p.log.n_samples)
    fine, got, old = (  # column j acts in the row of joint j
        np.einsum("kjj->kj", stepped_filtered((term,), logs, steps, p.cutoff_hz, k, rows, None, f))
        for logs, k, f in (
            ((None, p.log, None), p.decimate, (p.fine, p.fine_start)),
            ((head, p.log, tail), p.decimate, None),
            ((None, p.log, None), 1, None),
        )
    )
    assert np.abs(fine - want).max() < 1e-9
    edge = int(np.ceil(2.0 * p.log.sample_rate / p.cutoff_hz))  # two periods of the cut-off
    inside = slice(edge, -edge)
    assert np.abs(got - want)[inside].max() < 1e-4
    assert np.abs(got - want).max() < 1e-2
    assert np.abs(old - want)[inside].max() > 10 * np.abs(got - want)[inside].max()
    assert np.abs(old - want).max() > 20 * np.abs(got - want).max()


def test_exact_recordings_with_coulomb_friction_give_the_true_coefficients(panda):
    """Exact recordings at 1 kHz whose torques hold armature, viscous and Coulomb friction:
    the fit of that structure recovers them to 1e-3 (the Coulomb columns filtered at the
    decimated rate gave rotor inertias off by up to 2 % of their value)."""
    logs = recordings(
        panda, (11, 12), friction=FRICTION, armature=ARMATURE, duration=8.0, fs=1000.0
    )
    model = identify_recordings(panda, logs, structure=Structure(True, ("viscous", "coulomb")))
    fr = model.friction
    assert fr is not None
    params = np.asarray(fr.params)
    np.testing.assert_allclose(params[:, 0], FV, rtol=1e-3)
    np.testing.assert_allclose(params[:, 1], FC, rtol=1e-3)
    arm = model.terms["rotor_inertia"]
    free = arm.kept
    assert free.sum() >= 5
    np.testing.assert_allclose(arm.values[free], ARMATURE[free], rtol=1e-3)
