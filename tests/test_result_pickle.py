"""The public results pickle and deep-copy (multiprocessing sends them through pickle):
an identified model's terms, a robot's frames, a data set's metadata and a column map's
entries were read-only ``mappingproxy`` objects, which neither pickle nor deepcopy takes."""

import copy
import dataclasses
import math
import pickle
from collections.abc import Mapping

import numpy as np
import pytest

import dynid
from dynid.friction.model import ClassicalFriction
from dynid.io.columns import ColumnMap
from dynid.workflows.identify import IdentifyOptions, identify_logs

from conftest import planar_2r, recordings

ARMATURE = np.array([0.01, 0.02])  # [kg m^2]
FRICTION = ClassicalFriction(np.array([0.5, 0.3]), np.array([1.0, 0.5]), np.zeros(2))


def assert_same(a, b, at="result"):
    """``b`` equals ``a`` field by field: dataclasses by their fields, arrays by dtype,
    shape and value (NaN equal to NaN), mappings by their keys in order."""
    assert type(a) is type(b), at
    if dataclasses.is_dataclass(a):
        for f in dataclasses.fields(a):
            assert_same(getattr(a, f.name), getattr(b, f.name), f"{at}.{f.name}")
    elif isinstance(a, np.ndarray):
        assert a.dtype == b.dtype and a.shape == b.shape, at
        assert np.array_equal(a, b, equal_nan=a.dtype.kind in "fc"), at
    elif isinstance(a, Mapping):
        assert list(a) == list(b), at
        for k in a:
            assert_same(a[k], b[k], f"{at}[{k!r}]")
    elif isinstance(a, list | tuple):
        assert len(a) == len(b), at
        for i, (x, y) in enumerate(zip(a, b, strict=True)):
            assert_same(x, y, f"{at}[{i}]")
    elif isinstance(a, float) and math.isnan(a):
        assert math.isnan(b), at
    elif type(a).__eq__ is object.__eq__ and hasattr(a, "__dict__"):
        assert_same(vars(a), vars(b), at)
    else:
        assert a == b, at


def round_trips(obj):
    """``obj`` through pickle and through deepcopy."""
    return pickle.loads(pickle.dumps(obj)), copy.deepcopy(obj)


@pytest.fixture(scope="module")
def identified():
    """A 2R arm with rotor inertias and friction identified from an exact 1 s log."""
    robot = planar_2r()
    logs = recordings(robot, [1], friction=FRICTION, duration=1.0, armature=ARMATURE)
    return identify_logs(robot, logs, IdentifyOptions(terms="armature,viscous,coulomb"))


def test_identify_result_and_model_pickle_and_deepcopy(identified):
    """The trial's pickle.dump(identify_logs(...)) failed: "cannot pickle 'mappingproxy'"."""
    for got in (*round_trips(identified), *round_trips(identified.model)):
        model = got if isinstance(got, dynid.IdentifiedModel) else got.model
        assert_same(identified.model, model)
        assert list(model.terms) == ["rotor_inertia", "friction"]
    (model, _) = round_trips(identified.model)
    rng = np.random.default_rng(3)
    q, dq, ddq = (rng.uniform(-2.0, 2.0, (20, 2)) for _ in range(3))
    # the truth's rotor inertia of joint 2 (joint 1's is regrouped with J1zz), recovered
    # by the copy as by the original (exact log)
    np.testing.assert_allclose(model.rotor_inertia[1], ARMATURE[1], rtol=1e-6)
    np.testing.assert_array_equal(model.torques(q, dq, ddq), identified.model.torques(q, dq, ddq))


def test_the_terms_stay_read_only(identified):
    """The picklable mapping is as read-only as the proxy it replaces."""
    terms = pickle.loads(pickle.dumps(identified.model)).terms
    with pytest.raises(TypeError):
        terms["spring"] = terms["friction"]  # type: ignore[index]
    with pytest.raises(AttributeError):
        terms._items = {}  # type: ignore[attr-defined]
    assert_same(dict(identified.model.terms), dict(terms))


def test_robot_frames_data_and_column_maps_pickle_and_deepcopy(panda):
    """A robot with a tool frame, static data with metadata and a column map with flips."""
    robot = panda.with_frame("tcp", np.diag([1.0, -1.0, -1.0, 1.0]))
    rng = np.random.default_rng(0)
    q = rng.uniform(-1.0, 1.0, (3, 7))
    data = dynid.StaticDataset(
        q=q, M=dynid.mass_matrix(panda, q), g=dynid.gravity_torques(panda, q), metadata={"k": 1}
    )
    cmap = ColumnMap.from_units({"q": "q{i}"}, {"tau2": -1})
    for obj in (robot, data, cmap):
        for got in round_trips(obj):
            assert_same(obj, got)
