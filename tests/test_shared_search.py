"""A structure search made once per run (:mod:`dynid.identification.shared_search`), and
the digest it keys searches by (:func:`dynid._memo.value_digest`).

References: counts of the calls a search makes; arrays differing in one byte.
"""

from __future__ import annotations

import dataclasses
import warnings

import numpy as np
import pytest

from dynid._memo import value_digest
from dynid.exceptions import DynidWarning
from dynid.identification import selection as selection_module
from dynid.identification.once_per_run import once_per_run, shared_run
from dynid.identification.selection import identify_recordings
from dynid.simulation.measurement import SensorNoise

from conftest import recordings


@dataclasses.dataclass(frozen=True)
class _Data:
    x: np.ndarray
    names: dict


def test_the_digest_reads_values_not_identities():
    """Equal arrays, dataclasses and mappings (in any order) give equal digests; one byte
    changed, another shape or another type of array a different one."""
    a = np.arange(12.0).reshape(3, 4)
    first = value_digest(_Data(a, {"b": 1, "a": (2.0, "x")}))
    assert first == value_digest(_Data(a.copy(), {"a": (2.0, "x"), "b": 1}))
    assert first == value_digest(_Data(np.asfortranarray(a), {"a": (2.0, "x"), "b": 1}))
    changed = a.copy()
    changed[2, 3] = np.nextafter(changed[2, 3], np.inf)
    assert first != value_digest(_Data(changed, {"b": 1, "a": (2.0, "x")}))
    assert first != value_digest(_Data(a.reshape(4, 3), {"b": 1, "a": (2.0, "x")}))
    assert first != value_digest(_Data(a.astype(np.float32), {"b": 1, "a": (2.0, "x")}))
    assert value_digest((1, 2)) != value_digest([(1, 2)])
    with pytest.raises(TypeError):
        value_digest(({1},))


def test_a_search_is_made_once_within_the_block_and_every_time_outside():
    """Within shared_run, equal arguments (by value) run the search once and read its
    result back; other arguments run it again; outside the block, and with an argument
    that has no digest, every call runs."""
    runs = []

    @once_per_run
    def search(data, *, folds=5):
        runs.append(folds)
        return {"folds": folds, "sum": float(np.sum(data))}

    data = np.linspace(0.0, 1.0, 7)
    with shared_run():
        first = search(data, folds=5)
        assert search(data.copy(), folds=5) is first
        search(data, folds=4)
        with shared_run():  # nested: the outer memo
            assert search(data, folds=4)["folds"] == 4
        search(data, folds={3})  # no digest: run
        search(data, folds={3})
    assert runs == [5, 4, {3}, {3}]
    search(data, folds=5)
    search(data, folds=5)
    assert runs[-2:] == [5, 5]


def test_the_spring_trial_reads_the_search_without_the_spring_back(panda, monkeypatch):
    """Regression: the spring trial fits the recordings again with a spring on the joints
    the first fit's held-out residual names, and repeated the search without the spring
    that the first fit had just made. Three noisy recordings of a Panda, fitted without a
    spring and then with one tried on joint 2, within one shared block: two searches made
    (without the spring, then with it), the first fit's choice among the second's
    candidates."""
    made = []
    inner = selection_module.select_structure.__wrapped__

    def counted(*args, **kw):
        made.append(kw.get("candidates") is not None)
        return inner(*args, **kw)

    monkeypatch.setattr(selection_module, "select_structure", once_per_run(counted))
    noise = SensorNoise(tau_std=0.05, q_std=1e-5, dq_std=1e-3)
    logs = recordings(panda, (61, 62, 63), friction=panda.friction, duration=2.5, noise=noise)
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", DynidWarning)
        with shared_run():
            plain = identify_recordings(panda, logs)
            sprung = identify_recordings(panda, logs, spring_joints=(1,))
    assert made == [False, True], made
    assert sprung.info.selection["spring_candidate"]["joints"] == [2]
    chosen = plain.info.selection["chosen"]  # the first fit's choice, read back as judged
    assert any(c["name"] == chosen for c in sprung.info.selection["candidates"])
