"""dynid.io.json_files: numpy arrays and lists of plain numbers written as they are, a NaN
named by its key path."""

from __future__ import annotations

import json
import math

import numpy as np
import pytest

from dynid.exceptions import NonFiniteError
from dynid.io.json_files import dumps, jsonable


def test_arrays_and_lists_of_numbers_are_written_as_json_writes_their_python_numbers():
    """Float, integer and boolean arrays, tuples, lists mixing numpy scalars and booleans:
    the text is the standard library's for the same Python numbers (built here element
    by element), booleans stay ``true``, integers stay integers."""
    rng = np.random.default_rng(0)
    a = rng.normal(size=(4, 5))
    doc = {
        "a": a,
        "i": np.arange(6, dtype=np.int32).reshape(2, 3),
        "b": np.array([True, False]),
        "t": (1, 2.5, -3),
        "mixed": [1, True, np.float64(0.5), np.int64(7), None, "x"],
        "nested": [[0.25, 1], [np.bool_(False)]],
    }
    expected = {
        "a": [[float(v) for v in row] for row in a],
        "i": [[0, 1, 2], [3, 4, 5]],
        "b": [True, False],
        "t": [1, 2.5, -3],
        "mixed": [1, True, 0.5, 7, None, "x"],
        "nested": [[0.25, 1], [False]],
    }
    assert dumps(doc) == json.dumps(expected, indent=1, allow_nan=False)
    got = jsonable(doc)
    assert type(got["t"]) is list and type(got["mixed"][1]) is bool
    assert all(type(v) is int for row in got["i"] for v in row)


@pytest.mark.parametrize("bad", [math.nan, math.inf, -math.inf])
def test_a_non_finite_number_is_named_by_its_key_path(bad):
    """In an array, a list of floats or a tuple: the error names the element."""
    m = np.zeros((2, 3))
    m[1, 2] = bad
    with pytest.raises(NonFiniteError, match=r"^m\[1\]\[2\] is "):
        jsonable({"m": m})
    with pytest.raises(NonFiniteError, match=r"^r\.s\[2\] is "):
        jsonable({"r": {"s": [0.0, 1.0, bad]}})
    with pytest.raises(NonFiniteError, match=r"^t\[0\] is "):
        jsonable({"t": (bad, 1)})
