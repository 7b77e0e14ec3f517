"""The recordings' checks and preparation made once per run
(:mod:`dynid.identification.shared_preparation`).

References: counts of the calls made; the warnings a call gives, counted.
"""

from __future__ import annotations

import warnings

import numpy as np
import pytest

from dynid.exceptions import DynidWarning
from dynid.friction.model import ClassicalFriction
from dynid.identification import prepared_log, recording_offsets
from dynid.identification.once_per_run import once_per_run, shared_run
from dynid.identification.recording_offsets import identify_with_offsets
from dynid.simulation.measurement import SensorNoise

from conftest import planar_2r, recordings


def test_a_call_is_made_once_within_the_block_its_warnings_said_each_time():
    """Within shared_run, equal arguments (by value) compute once and read the
    result back with the first call's warnings said again; other arguments, a call that
    raised, an argument without a digest and every call outside the block compute."""
    runs = []

    @once_per_run
    def prepare(x, *, cutoff=1.0):
        runs.append(cutoff)
        if cutoff == -1.0:
            raise ValueError("negative")
        warnings.warn(f"said at {cutoff}", DynidWarning, stacklevel=2)
        return x.sum(), cutoff

    x = np.linspace(0.0, 1.0, 5)
    with shared_run():
        with warnings.catch_warnings(record=True) as said:
            warnings.simplefilter("always")
            first = prepare(x, cutoff=2.0)
            again = prepare(x.copy(), cutoff=2.0)
        assert again is first
        assert [str(w.message) for w in said] == ["said at 2.0", "said at 2.0"]
        with warnings.catch_warnings():
            warnings.simplefilter("ignore")
            prepare(x, cutoff=3.0)
            for _ in range(2):
                with pytest.raises(ValueError, match="negative"):
                    prepare(x, cutoff=-1.0)
                prepare(x, cutoff={4.0})  # no digest: computed
    assert runs == [2.0, 3.0, -1.0, {4.0}, -1.0, {4.0}]
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        prepare(x, cutoff=2.0)
        prepare(x, cutoff=2.0)
    assert runs[-2:] == [2.0, 2.0]


def test_results_beyond_the_budget_are_computed_again(monkeypatch):
    """A result whose arrays exceed the memory the block may hold (a quarter of
    DYNID_MAX_STACK_BYTES) is computed again on every call, a small one once."""
    monkeypatch.setenv("DYNID_MAX_STACK_BYTES", str(4 * 8000))
    runs = []

    @once_per_run
    def prepare(size):
        runs.append(size)
        return np.zeros(size)

    with shared_run():
        for size in (500, 500, 2000, 2000):  # 4,000 and 16,000 bytes against 8,000
            assert prepare(size).shape == (size,)
    assert runs == [500, 2000, 2000]


def test_the_offsets_check_reads_the_fits_preparation_back(monkeypatch):
    """Regression: identify_with_offsets prepared the three recordings the fit had just
    prepared a second time, with the cut-off the fit read (the same pieces, filter and
    trim): each piece is now filtered once, the recordings prepared twice as before (the
    fit's, the offsets' check)."""
    robot = planar_2r()
    friction = ClassicalFriction(np.array([0.3, 0.2]), np.array([0.8, 0.5]), np.array([0.4, -0.3]))
    logs = recordings(
        robot, (1, 2, 3), friction=friction, duration=3.0, noise=SensorNoise(tau_std=0.02)
    )
    pieces, prepared = [], []

    def counted(f, into):
        def call(*args, **kw):
            into.append(1)
            return f(*args, **kw)

        return call

    still = counted(prepared_log.still_friction, pieces)
    monkeypatch.setattr(prepared_log, "still_friction", still)
    monkeypatch.setattr(
        recording_offsets,
        "prepare_recordings",
        counted(recording_offsets.prepare_recordings, prepared),
    )
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", DynidWarning)
        model = identify_with_offsets(robot, logs)
    assert "offset" in model.info.extra["terms"]
    assert len(prepared) == 1  # the offsets' check prepared the recordings again
    assert len(pieces) == 3  # each recording's piece filtered once
