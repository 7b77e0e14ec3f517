"""The identification core: one pipeline over any data set with the Dataset protocol."""

from __future__ import annotations

import dataclasses
import json
from collections.abc import Iterator
from pathlib import Path
from typing import Literal

import numpy as np
import pytest

import dynid
from dynid.exceptions import RankDeficientError, WrongTypeError
from dynid.identification.core import (
    ModelColumns,
    RegressorBlock,
    identify,
    model_columns,
    stack_dataset,
)
from dynid.identification.data import StaticDataset
from dynid.identification.estimators import Residuals, Weights, row_weights
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

    serial = None

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
        assert info.log is not None
        assert (info.log.decimate, info.log.cutoff_hz) == (meta["decimate"], meta["cutoff_hz"])
        fr = model.terms["friction"]
        assert list(fr.labels) == meta["friction_labels"]
        assert [None if np.isnan(x) else x for x in fr.std] == meta["friction_std"]
    again = model_to_dict(model)["metadata"]
    derived = {"condition_number", "scaled_condition_number", "relative_error_percent"}
    assert {k: again[k] for k in meta if k not in derived} == {
        k: v for k, v in meta.items() if k not in derived
    }
    assert info_from_dict(again) == info


@dataclasses.dataclass(frozen=True)
class _Huber:
    """A user's estimator: Huber's M-estimator with a fixed threshold ``k`` [N m], a
    row-weighting policy reweighted until the estimate stops moving (the protocol of
    dynid.identification.estimators, defined outside it)."""

    k: float
    name: str = "huber"
    weighted: bool = True
    per_row: bool = True

    def row_weights(self, e: np.ndarray, groups: np.ndarray, n_columns: int) -> np.ndarray:
        return np.sqrt(np.minimum(1.0, self.k / np.maximum(np.abs(e), 1e-300)))

    def reweight(self, res: Residuals) -> Weights | None:
        if res.step >= 500 or (res.step > 0 and not res.moved(1e-14)):
            return None
        return Weights(row=self.row_weights(res.e, res.groups, res.n_columns))


@pytest.mark.filterwarnings("ignore:.*indistinguishable from zero")  # OLS: a zero coefficient
def test_a_users_estimator_with_the_protocol_is_taken_by_identify():
    """A Huber estimator written outside dynid, on torques with noise and one gross outlier:
    identify returns scipy's least_squares(loss="huber") minimiser to 1e-9, which the
    outlier moves OLS away from by far more."""
    from scipy.optimize import least_squares

    robot = planar_2r()
    data = _TorqueRows(robot, 40, seed=4)
    rng = np.random.default_rng(5)
    data.tau = data.tau + 0.01 * rng.normal(size=data.tau.shape)
    data.tau[7, 1] += 3.0  # one gross outlier [N m]
    est = _Huber(k=0.02)
    model = identify(robot, data, estimator=est)
    ols = identify(robot, data)
    assert model.info.estimator == "huber"

    base = base_parameters(robot, kind="torque")
    Yb = base.reduce(torque_regressor(robot, data.q, data.dq, data.ddq))
    W = np.concatenate([Yb[:, j, :] for j in range(robot.n)])  # the data set's block order
    y = np.concatenate([data.tau[:, j] for j in range(robot.n)])
    x0 = np.linalg.lstsq(W, y, rcond=None)[0]
    ref = least_squares(
        lambda b: W @ b - y, x0, loss="huber", f_scale=est.k, xtol=1e-15, ftol=1e-15, gtol=1e-15
    ).x
    scale = np.linalg.norm(ref)
    assert np.linalg.norm(model.beta - ref) < 1e-9 * scale
    assert np.linalg.norm(ols.beta - ref) > 1e3 * np.linalg.norm(model.beta - ref)
    truth = base.beta_from_phi(robot.phi)
    assert np.linalg.norm(model.beta - truth) < 0.2 * np.linalg.norm(ols.beta - truth)
    # held-out data are judged with the estimator's own row weights
    w = row_weights(est, W, y, np.zeros(y.size, dtype=np.intp), np.asarray(model.beta))
    assert w[40 + 7] < 0.1 and np.median(w) == 1.0


def test_an_object_without_the_estimator_protocol_is_refused():
    """An estimator object lacking row_weights is a WrongTypeError naming the protocol."""

    class _NoWeights:
        name = "half"

        def fit(self, W, y, groups, **kw):
            raise AssertionError("never called")

    with pytest.raises(WrongTypeError, match="the Estimator protocol"):
        identify(planar_2r(), _TorqueRows(planar_2r(), 10, seed=6), estimator=_NoWeights())
