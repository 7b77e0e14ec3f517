"""The schema codec of dynid's files: what is written reads back equal, and every format
refuses an unknown key, a wrong type and a value out of its limits in one wording.

The documents are drawn from the declarations themselves (any document a format admits), so
the round trip covers every key of every format, not the values one writer happens to write.
"""

from __future__ import annotations

import json
import re
import tempfile
from pathlib import Path
from typing import Any

import numpy as np
import pytest
from hypothesis import HealthCheck, given, settings
from hypothesis import strategies as st

from dynid.exceptions import DataError
from dynid.feasibility.bounds import default_bounds
from dynid.friction.laws import LAWS
from dynid.io import schema
from dynid.io.bounds_file import BOUNDS_RECORD, BOUNDS_SCHEMA, bounds_from_dict, bounds_to_dict
from dynid.io.drive_file import DRIVE_JSON, drive_from_mapping
from dynid.io.excitation import EXCITATION, OBSTACLES, load_obstacles
from dynid.io.feasible import FEASIBLE, load_feasible_json, save_feasible_json
from dynid.io.friction_json import FORMAT, _record, load_friction_json, save_friction_json
from dynid.io.model_json import MODEL
from dynid.io.observer_files import EVENTS, THRESHOLDS, load_thresholds, save_thresholds
from dynid.io.robot.toml import ROBOT_TOML, robot_from_toml_string
from dynid.io.robot_json import ROBOT_RECORD, ROBOT_SCHEMA
from dynid.io.schema import Field, Format, Record, check, load_document, save_document
from dynid.model.drive import DRIVE_SCHEMA
from dynid.observer.detection import Thresholds
from dynid.observer.residual import ObserverOptions

from conftest import planar_2r

#: every format with a declaration, as files (the records read inside other files too)
FORMATS = {
    "thresholds": THRESHOLDS,
    "events": EVENTS,
    "feasible": FEASIBLE,
    "obstacles": OBSTACLES,
    "excitation": EXCITATION,
    "model": MODEL,
    "robot": Format(ROBOT_SCHEMA, ROBOT_RECORD, "robot description"),
    "robot-toml": Format("dynid-robot-toml", ROBOT_TOML, "robot description (TOML)"),
    "bounds": Format(BOUNDS_SCHEMA, BOUNDS_RECORD, "bounds file"),
    "drive": Format(DRIVE_SCHEMA, DRIVE_JSON, "drive record"),
    **{f"friction-{k}": Format(FORMAT, _record(k), "friction file") for k in LAWS},
}

_FLOATS = {"allow_nan": False, "allow_infinity": False}
_ANY = st.none() | st.booleans() | st.integers(-1000, 1000) | st.text(max_size=4)


def _number(f: Field) -> st.SearchStrategy[Any]:
    return st.floats(f.low, f.high, **_FLOATS) | st.integers(
        -(10**6) if f.low is None else int(np.ceil(f.low)),
        10**6 if f.high is None else int(np.floor(f.high)),
    )


def _count(s: int | str | None, sizes: dict[str, int]) -> st.SearchStrategy[int]:
    if isinstance(s, str):
        return st.just(sizes[s])
    return st.integers(0, 3) if s is None else st.just(s)


@st.composite
def _value(draw: Any, f: Field, sizes: dict[str, int]) -> Any:
    """Any value ``f`` admits (``sizes``: the file's named sizes, drawn once)."""
    if f.nullable and draw(st.booleans()):
        return None
    if f.choices:
        return draw(st.sampled_from(f.choices))
    shape = f.shape or (None,)
    if f.kind == "number":
        return draw(_number(f))
    if f.kind == "integer":
        low = -(10**6) if f.low is None else int(f.low)
        return draw(st.integers(low, 10**6 if f.high is None else int(f.high)))
    if f.kind == "bool":
        return draw(st.booleans())
    if f.kind == "string":
        return draw(st.text(min_size=int(f.non_empty), max_size=6))
    if f.kind in ("strings", "bools"):
        item = st.text(max_size=4) if f.kind == "strings" else st.booleans()
        k = draw(_count(shape[0], sizes))
        return draw(st.lists(item, min_size=max(k, int(f.non_empty)), max_size=max(k, 1)))
    if f.kind == "numbers":
        leaf = _number(f) | st.none() if f.null_items else _number(f)

        def level(depth: int) -> Any:
            if depth == len(shape):
                return draw(leaf)
            k = draw(_count(shape[depth], sizes))
            return [level(depth + 1) for _ in range(max(k, int(f.non_empty)))]

        return level(0)
    record = f.record or Record({}, open=True)
    if f.kind == "object":
        return draw(_document(record, sizes))
    if f.kind == "objects":
        k = draw(_count(shape[0], sizes))
        return [draw(_document(record, sizes)) for _ in range(max(k, int(f.non_empty)))]
    if f.kind == "named":
        names = draw(st.lists(st.text(max_size=4), max_size=3, unique=True))
        return {name: draw(_document(record, sizes)) for name in names}
    return draw(_ANY)


@st.composite
def _document(draw: Any, record: Record, sizes: dict[str, int]) -> dict[str, Any]:
    """Any document ``record`` admits: its required keys, and some of the others."""
    return {
        k: draw(_value(f, sizes))
        for k, f in record.fields.items()
        if f.required or draw(st.booleans())
    }


@st.composite
def _file(draw: Any, fmt: Format) -> dict[str, Any]:
    sizes = {"n": draw(st.integers(1, 4)), "L": draw(st.integers(1, 3))}
    return {**draw(_document(fmt.record, sizes)), "schema": fmt.tag}


@pytest.mark.parametrize("name", sorted(FORMATS))
def test_any_document_a_format_admits_reads_back_equal(name):
    """save_document then load_document gives back the very document, every key of the format
    drawn (floats exactly: shortest round-trip representation)."""
    fmt = FORMATS[name]

    @settings(max_examples=25, deadline=None, suppress_health_check=list(HealthCheck))
    @given(doc=_file(fmt))
    def round_trip(doc: dict[str, Any]) -> None:
        with tempfile.TemporaryDirectory() as d:
            path = save_document(Path(d) / "f.json", fmt, doc)
            back = load_document(path, fmt)
        assert back == doc
        assert json.dumps(back, sort_keys=True) == json.dumps(doc, sort_keys=True)

    round_trip()


_GAINS = st.lists(st.floats(0.1, 1e3, **_FLOATS), min_size=1, max_size=7)


@settings(max_examples=30, deadline=None, suppress_health_check=list(HealthCheck))
@given(
    gain=_GAINS,
    data=st.data(),
    k_sigma=st.none() | st.floats(0.0, 10.0, **_FLOATS),
)
def test_thresholds_written_read_back_equal(gain, data, k_sigma):
    """Any thresholds (any joint count, with or without the uncertainty term) read back
    bit-identical."""
    n = len(gain)
    vec = st.lists(st.floats(0.0, 1e4, **_FLOATS), min_size=n, max_size=n)
    th = Thresholds(
        contact=np.array(data.draw(vec)),
        collision=np.array(data.draw(vec)),
        margin=data.draw(st.floats(1.0, 5.0)),
        quantile=data.draw(st.floats(0.5, 1.0)),
        collision_factor=data.draw(st.floats(1.0, 5.0)),
        options=ObserverOptions(
            gain=tuple(gain),
            discretisation=data.draw(st.sampled_from(("exact", "euler"))),
            rule=data.draw(st.sampled_from(("rectangle", "trapezoid"))),
        ),
        samples=data.draw(st.integers(0, 10**9)),
        k_sigma=k_sigma,
        noise=None if k_sigma is None else np.array(data.draw(vec)),
    )
    with tempfile.TemporaryDirectory() as d:
        back = load_thresholds(save_thresholds(Path(d) / "t.json", th, joints=["j"] * n))
    for key in ("contact", "collision", "noise"):
        a, b = getattr(th, key), getattr(back, key)
        assert (a is None and b is None) or np.array_equal(a, b)
    assert (back.margin, back.quantile, back.collision_factor, back.samples, back.k_sigma) == (
        th.margin, th.quantile, th.collision_factor, th.samples, th.k_sigma
    )  # fmt: skip
    assert back.options == th.options


@settings(max_examples=30, deadline=None, suppress_health_check=list(HealthCheck))
@given(
    P=st.lists(st.tuples(*(st.floats(0.0, 1e3, **_FLOATS),) * 3), min_size=1, max_size=7).map(
        np.array
    ),
    band=st.floats(0.0, 0.1, **_FLOATS),
)
def test_friction_written_reads_back_equal(P, band):
    """A classical friction model with a standstill band reads back bit-identical."""
    fr = LAWS["classical"].model(P, np.full(len(P), band))
    with tempfile.TemporaryDirectory() as d:
        back = load_friction_json(save_friction_json(Path(d) / "f.json", fr))
    assert back.kind == "classical"
    np.testing.assert_array_equal(back.as_array(), P)
    np.testing.assert_array_equal(back.band, np.full(len(P), band))


# -- one wording ------------------------------------------------------------------------------

_ONE = re.compile(
    r"^(?P<file>[^:]+): key '(?P<key>[^']+)': (unknown key; allowed: |expected .+; got )"
)


def _thresholds(path: Path) -> dict[str, Any]:
    th = Thresholds(
        contact=np.ones(2),
        collision=np.full(2, 2.0),
        margin=1.5,
        quantile=1.0,
        collision_factor=2.0,
        options=ObserverOptions(gain=(10.0, 10.0)),
        samples=100,
    )
    return json.loads(save_thresholds(path, th, joints=["a", "b"]).read_text())


def _friction(path: Path) -> dict[str, Any]:
    fr = LAWS["classical"].model(np.ones((2, 3)), np.full(2, 0.01))
    return json.loads(save_friction_json(path, fr).read_text())


def _feasible(path: Path) -> dict[str, Any]:
    return json.loads(save_feasible_json(path, planar_2r()).read_text())


def _obstacles(path: Path) -> dict[str, Any]:
    return {
        "schema": "dynid-obstacles/1",
        "planes": [{"name": "floor", "point": [0, 0, 0], "normal": [0, 0, 1]}],
    }


def _bounds(path: Path) -> dict[str, Any]:
    return bounds_to_dict(default_bounds(planar_2r()))


_ROBOT = planar_2r()


def _set(path: list[Any], value: Any) -> Any:
    def edit(doc: dict[str, Any]) -> None:
        target = doc
        for k in path[:-1]:
            target = target[k]
        target[path[-1]] = value

    return edit


# (format, valid document, edit, the key path named, the fault)
_CASES = [
    ("thresholds", _thresholds, _set(["rule", "gane"], 1), "rule.gane", "unknown"),
    ("thresholds", _thresholds, _set(["contact", 1], "1"), "contact[1]", "type"),
    ("thresholds", _thresholds, _set(["collision", 0], -1.0), "collision[0]", "limit"),
    ("friction", _friction, _set(["joints", 0, "fw"], 1), "joints[0].fw", "unknown"),
    ("friction", _friction, _set(["joints", 1, "fc"], True), "joints[1].fc", "type"),
    ("friction", _friction, _set(["joints", 0, "standstill_band"], -0.1),
     "joints[0].standstill_band", "limit"),
    ("feasible", _feasible, _set(["links", 0, "masss"], 1), "links[0].masss", "unknown"),
    ("feasible", _feasible, _set(["links", 1, "com"], [0, 0]), "links[1].com", "type"),
    ("feasible", _feasible, _set(["links", 0, "mass"], 1e12), "links[0].mass", "limit"),
    ("feasible", _feasible, _set(["kinematics", "limits", "q_min", 0], "a"),
     "kinematics.limits.q_min[0]", "type"),
    ("obstacles", _obstacles, _set(["plane"], []), "plane", "unknown"),
    ("obstacles", _obstacles, _set(["planes", 0, "normal", 2], None), "planes[0].normal[2]",
     "type"),
    ("bounds", _bounds, _set(["links", 0, "com"], [0, 0, 0]), "links[0].com", "unknown"),
    ("bounds", _bounds, _set(["links", 0, "mass", 1], "2"), "links[0].mass[1]", "type"),
]  # fmt: skip
_READ = {
    "thresholds": load_thresholds,
    "friction": load_friction_json,
    "feasible": load_feasible_json,
    "obstacles": load_obstacles,
    "bounds": lambda p: bounds_from_dict(json.loads(p.read_text()), _ROBOT, source=p.name),
}


@pytest.mark.parametrize(
    ("fmt", "make", "edit", "key", "fault"), _CASES, ids=[f"{c[0]}-{c[4]}" for c in _CASES]
)
def test_every_format_refuses_in_one_wording(tmp_path, fmt, make, edit, key, fault):
    """An unknown key, a wrong type and a value out of its limits: one DataError, one line
    ``FILE: key 'PATH': ...`` naming the file and the key path, in every format."""
    path = tmp_path / f"{fmt}.json"
    doc = make(path)
    edit(doc)
    path.write_text(json.dumps(doc))
    with pytest.raises(DataError) as info:
        _READ[fmt](path)
    msg = str(info.value)
    m = _ONE.match(msg)
    assert m is not None, msg
    assert (m["file"], m["key"]) == (path.name, key), msg
    assert ("unknown key" in msg) == (fault == "unknown"), msg
    if fault == "limit":
        assert re.search(r"expected a number (>=|<=|in) ", msg), msg
    assert "\n" not in msg


@pytest.mark.parametrize(
    ("edit", "key", "fault"),
    [
        (("velocity = 2.0", "velocty = 2.0"), "joints[0].limits.velocty", "unknown"),
        (("mass = 1.5", 'mass = "1.5"'), "joints[0].inertial.mass", "type"),
        (("mass = 1.5", "mass = 1e12"), "joints[0].inertial.mass", "limit"),
    ],
)
def test_a_robot_description_is_refused_in_the_same_wording(edit, key, fault):
    """The TOML robot description goes through the same codec: an unknown key, a wrong type
    and a value out of its limits in the one wording."""
    text = (
        '[[joints]]\nname = "j"\ntype = "revolute"\nparent = "a"\nchild = "b"\n'
        "limits = { velocity = 2.0 }\n"
        "inertial = { mass = 1.5, com = [0, 0, 0], inertia = [1, 0, 0, 1, 0, 1] }\n"
    )
    assert robot_from_toml_string(text).mass[0] == 1.5
    with pytest.raises(DataError) as info:
        robot_from_toml_string(text.replace(*edit), source="arm.toml")
    msg = str(info.value)
    m = _ONE.match(msg)
    assert m is not None and (m["file"], m["key"]) == ("arm.toml", key), msg
    assert ("unknown key" in msg) == (fault == "unknown"), msg
    if fault == "limit":
        assert re.search(r"expected a number (>=|<=|in) ", msg), msg


def test_a_drive_table_is_refused_in_the_same_wording():
    """TOML tables (a drive description) go through the same check and wording."""
    for table, key in (({"gear": [1, 2]}, "gear"), ({"offset": [0, "1"]}, "offset[1]")):
        with pytest.raises(DataError) as info:
            drive_from_mapping(table, 2, source="drive.toml")
        m = _ONE.match(str(info.value))
        assert m is not None and (m["file"], m["key"]) == ("drive.toml", key), str(info.value)
    with pytest.raises(
        DataError, match=r"key 'coupling\[0\].joint': expected an integer in \[1, 2\]; got 3"
    ):
        drive_from_mapping({"coupling": [[1, 3, 0.5]]}, 2, source="drive.toml")


def test_check_names_sizes_once_for_the_whole_file():
    """A named size is bound by its first use: a second per-joint list of another length
    is refused, naming the size it should have had."""
    rec = Record({"a": Field("numbers", shape=("n",)), "b": Field("numbers", shape=("n",))})
    assert check({"a": [1, 2, 3], "b": [4, 5, 6]}, rec, "f.json") == {"n": 3}
    with pytest.raises(
        DataError, match=r"^f.json: key 'b': expected a list of 3 numbers; got \[4, 5\]$"
    ):
        check({"a": [1, 2, 3], "b": [4, 5]}, rec, "f.json")
    with pytest.raises(DataError, match=r"^f.json: key 'a': missing; expected a list of numbers$"):
        check({}, Record({"a": Field("numbers", required=True)}), "f.json")
    with pytest.raises(DataError, match=r"expected a finite number; got inf"):
        check({"a": [float("inf")]}, rec, "f.json")
    assert schema.describe(Field("numbers", shape=("n", 4, 4), unit="m"), {"n": 7}) == (
        "a 7 x 4 x 4 nested list of numbers [m]"
    )


def test_a_writer_never_writes_what_its_reader_refuses(tmp_path):
    """save_document checks before writing: a document its format refuses leaves no file."""
    with pytest.raises(DataError, match=r"^t.json: key 'contact': missing"):
        save_document(tmp_path / "t.json", THRESHOLDS, {"collision": [1.0]})
    assert not (tmp_path / "t.json").exists()
