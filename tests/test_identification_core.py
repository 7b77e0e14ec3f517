"""The identification core: one pipeline over any data set with the Dataset protocol."""

from __future__ import annotations

import json
from collections.abc import Iterator
from pathlib import Path
from typing import Literal

import numpy as np
import pytest

import dynid
from dynid.exceptions import RankDeficientError
from dynid.identification.core import (
    ModelColumns,
    RegressorBlock,
    identify,
    model_columns,
    stack_dataset,
)
from dynid.identification.data import StaticDataset
from dynid.identification.info import IdentificationInfo
from dynid.io.model_json import info_from_dict, load_model_json, model_to_dict
from dynid.regressors.base import base_parameters
from dynid.regressors.torque import torque_regressor

from conftest import planar_2r, random_states


class _TorqueRows:
    """A minimal data set of exact joint torques (no filtering): the protocol, nothing else."""

    route: Literal["classical"] = "classical"
    regressor_kind: Literal["torque"] = "torque"
    moving = False  # no friction in the data
    source = "test torques"
    hint = "hint: more samples"

    def __init__(self, robot: dynid.Robot, n_samples: int, seed: int) -> None:
        self.q, self.dq, self.ddq = random_states(robot, n_samples, seed)
        self.tau = dynid.rnea(robot, self.q, self.dq, self.ddq)

    def check_robot(self, robot: dynid.Robot) -> None:
        assert robot.n == self.q.shape[1]

    def frozen_columns(self, columns: ModelColumns) -> np.ndarray:
        return np.zeros(len(columns.labels), dtype=bool)

    def blocks(self, robot: dynid.Robot, columns: ModelColumns) -> Iterator[RegressorBlock]:
        Y = torque_regressor(robot, self.q, self.dq, self.ddq)  # (N, n, 10 n)
        Yb = columns.base.reduce(Y)
        for j in range(robot.n):  # one block per joint, to exercise the stacking
            yield RegressorBlock(
                W=Yb[:, j, :], y=self.tau[:, j], groups=np.full(len(self.q), j), label=f"j{j}"
            )

    def record(self, n_rows: int) -> IdentificationInfo:
        return IdentificationInfo(reference="exact torques", notes=(f"{len(self.q)} samples",))


def test_a_new_data_set_needs_only_the_protocol_and_recovers_the_base_parameters():
    """Exact torques of the planar 2R through a hand-written data set: beta = P phi."""
    robot = planar_2r()
    data = _TorqueRows(robot, 40, seed=1)
    model = identify(robot, data)
    base = base_parameters(robot, kind="torque")
    want = base.beta_from_phi(robot.phi)
    np.testing.assert_allclose(model.beta, want, rtol=1e-9, atol=1e-12)
    assert model.friction is None and model.fit.n_rows == 80
    assert model.info.route == "classical" and model.info.notes == ("40 samples",)
    assert model.info.n_rows == 80 and model.info.reference == "exact torques"


def test_static_blocks_stack_to_the_rows_of_tril_m_and_g():
    """Stacked static blocks times the true base parameters give [tril M; g] of the robot."""
    robot = planar_2r()
    q = random_states(robot, 6, seed=2)[0]
    M, g = dynid.mass_matrix(robot, q), dynid.gravity_torques(robot, q)
    data = StaticDataset(q, M, g)
    cols = model_columns(robot, data)
    stack = stack_dataset(robot, data, cols)
    beta = cols.base.beta_from_phi(robot.phi)
    i, j = np.tril_indices(2)
    want = np.concatenate([M[:, i, j], g], axis=1).T.reshape(-1)  # row kind, then sample
    np.testing.assert_allclose(stack.W @ beta, want, atol=1e-12)
    np.testing.assert_allclose(stack.y, want, atol=0)
    assert stack.labels == ("M1_1", "M2_1", "M2_2", "g1", "g2")


def test_rank_error_carries_rank_needed_and_dependent_columns():
    """Two static configurations of the Panda: the error's rank is numpy's, 43 needed."""
    panda = dynid.panda()
    q = random_states(panda, 2, seed=3)[0]
    data = StaticDataset(q, dynid.mass_matrix(panda, q), dynid.gravity_torques(panda, q))
    base = base_parameters(panda, kind="static")
    with pytest.raises(RankDeficientError) as info:
        identify(panda, data, base=base)
    exc = info.value
    from dynid.regressors.static import static_regressor

    W = base.reduce(static_regressor(panda, q))[:, np.arange(35) != 28].reshape(-1, 43)
    assert exc.needed == 43
    assert exc.rank == np.linalg.matrix_rank(W / np.linalg.norm(W, axis=0))
    assert exc.dependent and set(exc.dependent) <= set(base.labels)
    assert f"nearly dependent columns: {exc.dependent[0]}" in str(exc)


@pytest.mark.parametrize(
    "name", ["identification_static_v1.json", "identification_classical_v1.json"]
)
def test_identification_files_of_the_previous_version_load_with_their_record(name):
    """A file whose metadata was a free dictionary loads into the typed record, and saving
    it again writes the same metadata entries (those the fit already holds aside)."""
    path = Path(__file__).parent / "data" / name
    meta = json.loads(path.read_text())["metadata"]
    model = load_model_json(path)
    info = model.info
    assert info.route == meta["route"] and info.reference == meta["reference"]
    assert list(info.dropped_rows) == meta["dropped_rows"] and list(info.pruned) == meta["pruned"]
    assert info.std == meta["std_estimator"] and info.estimator == meta["estimator"]
    assert dict(info.identifiability) == meta["identifiability"]
    if meta["route"] == "static":
        assert info.static is not None and info.log is None
        assert info.static.n_configurations == meta["n_configurations"]
        assert dict(info.data) == meta["data"] and info.seed is None
    else:
        assert info.log is not None and info.friction is not None
        assert (info.log.decimate, info.log.cutoff_hz) == (meta["decimate"], meta["cutoff_hz"])
        assert list(info.friction.labels) == meta["friction_labels"]
        assert list(info.friction.std) == meta["friction_std"]
    again = model_to_dict(model)["metadata"]
    derived = {"condition_number", "scaled_condition_number", "relative_error_percent"}
    assert {k: again[k] for k in meta if k not in derived} == {
        k: v for k, v in meta.items() if k not in derived
    }
    assert info_from_dict(again) == info
