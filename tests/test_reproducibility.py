"""The same seed gives byte-identical files, command after command (issue 12 keeps it)."""

from __future__ import annotations

import contextlib
import io

from dynid.cli.__main__ import main


def _run(argv: list[str]) -> None:
    with contextlib.redirect_stdout(io.StringIO()), contextlib.redirect_stderr(io.StringIO()):
        assert main(argv) == 0


def _pipeline(d) -> list[bytes]:
    _run(["acquire-static", "--n", "60", "--noise", "1e-4", "--seed", "7", "--out", f"{d}/s.csv"])
    _run(["acquire-static", "--n", "60", "--noise", "1e-4", "--seed", "7", "--out", f"{d}/s.npz"])
    _run(["simulate", "--duration", "3", "--rate", "200", "--seed", "7", "--out", f"{d}/log.csv"])
    _run(["simulate", "--duration", "3", "--rate", "200", "--seed", "7", "--out", f"{d}/log.npz"])
    _run(["identify", "--data", f"{d}/s.csv", "--out", f"{d}/res"])
    _run(
        [
            "validate",
            "--robot",
            "panda",
            "--data",
            f"{d}/log.csv",
            "--no-figures",
            "--out",
            f"{d}/v",
        ]
    )
    names = ["s.csv", "s.npz", "log.csv", "log.npz", "res/identification.json", "v/validation.json"]
    return [(d / n).read_bytes() for n in names]


def test_same_seed_gives_byte_identical_files(tmp_path):
    """Two runs of acquire-static, simulate, identify and validate with one seed write the
    same bytes (CSV, NPZ and JSON)."""
    (tmp_path / "a").mkdir()
    (tmp_path / "b").mkdir()
    a, b = _pipeline(tmp_path / "a"), _pipeline(tmp_path / "b")
    assert [x == y for x, y in zip(a, b, strict=True)] == [True] * len(a)
