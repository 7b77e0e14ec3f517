"""``--data a --data b`` is ``--data a b`` on every command (the second kept alone before)."""

from __future__ import annotations

import pytest

from dynid.cli.__main__ import build_parser


@pytest.mark.parametrize("command", ["identify", "validate", "friction", "payload", "observe"])
def test_data_given_twice_keeps_both(command):
    parser = build_parser((command,))
    extra = {
        "identify": ["--out", "o"],
        "validate": ["--model", "m.json", "--out", "o"],
        "friction": ["--model", "m.json", "--out", "o"],
        "payload": ["--model", "m.json", "--out", "o"],
        "observe": ["--model", "m.json", "--calibrate", "--out", "o"],
    }[command]
    args = parser.parse_args([command, *extra, "--data", "a.csv", "--data", "b.csv", "c.csv"])
    assert [p.name for p in args.data] == ["a.csv", "b.csv", "c.csv"]
