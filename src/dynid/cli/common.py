"""Options and helpers shared by the subcommands: robot selection, vectors, JSON output."""

from __future__ import annotations

import argparse
import json
import sys
from pathlib import Path
from typing import Any

import numpy as np

from ..exceptions import DynidError, ShapeError
from ..model.panda import panda
from ..model.robot import Robot


def add_robot_options(p: argparse.ArgumentParser) -> None:
    """``--robot panda|FILE.urdf|FILE.toml`` with ``--base``/``--tip`` for URDF chains."""
    p.add_argument("--robot", default="panda", help="'panda', a .urdf or a .toml file (default: panda)")
    p.add_argument("--base", default=None, help="URDF base link of the chain (default: the root)")
    p.add_argument("--tip", default=None, help="URDF tip link of the chain (default: the only leaf)")


def load_robot(args: argparse.Namespace) -> Robot:
    """The robot named by ``--robot`` (and ``--base``/``--tip`` for a URDF)."""
    spec = args.robot
    if spec == "panda":
        return panda()
    path = Path(spec)
    if path.suffix.lower() == ".urdf":
        return Robot.from_urdf(path, base_link=args.base, tip_link=args.tip)
    if path.suffix.lower() == ".toml":
        return Robot.from_toml(path)
    raise DynidError(f"--robot must be 'panda', a .urdf or a .toml file; got {spec!r}")


def parse_vector(text: str, name: str, size: int | None = None) -> np.ndarray:
    """Comma-separated floats; ``size`` checks the count."""
    try:
        v = np.array([float(x) for x in text.replace(" ", "").split(",") if x != ""])
    except ValueError:
        raise ShapeError(f"{name} must be comma-separated numbers; got {text!r}") from None
    if size is not None and v.shape != (size,):
        raise ShapeError(f"{name} must have {size} values; got {v.size}")
    return v


def print_json(obj: Any) -> None:
    """One JSON object on stdout."""
    json.dump(obj, sys.stdout, default=_jsonable)
    sys.stdout.write("\n")


def _jsonable(x: Any) -> Any:
    if isinstance(x, np.ndarray):
        return x.tolist()
    if isinstance(x, np.generic):
        return x.item()
    raise TypeError(f"not JSON serialisable: {type(x).__name__}")


def format_matrix(A: np.ndarray, fmt: str = "{:+.6f}") -> str:
    """A readable fixed-width table of a 2-D array."""
    return "\n".join("  ".join(fmt.format(v) for v in row) for row in np.atleast_2d(A))
