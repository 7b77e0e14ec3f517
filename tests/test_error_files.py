"""An error about a file names it once: ``DynidError(text, file=name)`` writes the prefix and
records the file, and ``in_file`` names the file in an error that names none, by that record
and never by the message's first characters."""

from __future__ import annotations

import pickle

import pytest

from dynid.exceptions import (
    DataError,
    DynidError,
    OptionError,
    RankDeficientError,
    ShapeError,
    in_file,
    named_file,
)
from dynid.io.robot.toml import robot_from_toml_string


def test_an_error_about_a_file_says_which_and_where():
    e = DataError("not a number: 'abc'", file="log.csv", at="line 5, column 'tau1'")
    assert str(e) == "log.csv, line 5, column 'tau1': not a number: 'abc'"
    assert e.file == "log.csv"
    assert DataError("plain").file is None
    back = pickle.loads(pickle.dumps(e))  # as a worker process hands it back
    assert (str(back), back.file, type(back)) == (str(e), "log.csv", DataError)


def test_in_file_names_the_file_once():
    """An error naming its own file keeps it; one naming none gets the file, even when its
    text happens to start with the file's name (a string check would have skipped it)."""
    with pytest.raises(DataError) as info, in_file("arm.csv"):
        raise DataError("expected 7 fields", file="other.csv")
    assert str(info.value) == "other.csv: expected 7 fields" and info.value.file == "other.csv"
    with pytest.raises(ShapeError) as info, in_file("model"):
        raise ShapeError("model has 3 joints; robot 'r' has 2")
    assert str(info.value) == "model: model has 3 joints; robot 'r' has 2"
    assert info.value.file == "model" and isinstance(info.value.__cause__, ShapeError)


def test_naming_the_file_keeps_the_errors_class_and_attributes():
    exc = RankDeficientError("rank 3 of 5", rank=3, needed=5, dependent=("a", "b"))
    out = named_file(exc, "log.csv")
    assert type(out) is RankDeficientError and str(out) == "log.csv: rank 3 of 5"
    assert (out.rank, out.needed, out.dependent, out.file) == (3, 5, ("a", "b"), "log.csv")
    assert exc.file is None and str(exc) == "rank 3 of 5"  # the original is left as it was
    option = OptionError("must be positive", field="cutoff_hz")
    assert named_file(option, "log.csv") is option  # named by its flag, not by the file


def test_a_reader_error_is_named_once_through_the_command_line_wrapper():
    """A robot file that is not TOML: one prefix (the reader's), not the reader's and the
    wrapper's (``bad.toml: bad.toml is not valid TOML`` before)."""
    with pytest.raises(DynidError) as info, in_file("bad.toml"):
        robot_from_toml_string("name = \n", source="bad.toml")
    assert str(info.value).startswith("bad.toml: not valid TOML (")
    assert str(info.value).count("bad.toml") == 1
