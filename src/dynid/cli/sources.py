"""The model a command compares with data or carries a load on (``--model``, ``--robot``
or ``--params``); kept apart from :mod:`.common`, which the kinematics commands import:
these load the identification and feasibility packages (scipy). The data are read by the
command's workflow (:mod:`dynid.workflows.recordings`)."""

from __future__ import annotations

import argparse

from ..exceptions import DynidError
from ..identification.model import IdentifiedModel
from ..io.feasible import load_feasible_json
from ..io.model_json import load_model_json
from ..model.robot import Robot
from .common import load_robot

__all__ = ["load_model_source", "params_as_robot"]


def params_as_robot(args: argparse.Namespace) -> argparse.Namespace:
    """``args`` with a ``--params`` that names a robot description (a ``.urdf``, a robot
    ``.toml``, an MJCF ``.xml`` or a built-in name: anything but a ``feasible.json``) given
    as ``--robot`` instead, which reads it with its drive and friction, as ``observe
    --params`` and ``export --params`` read such files; ``args`` itself otherwise."""
    params = getattr(args, "params", None)
    if params is None or str(params).lower().endswith(".json"):
        return args
    return argparse.Namespace(**{**vars(args), "robot": str(params), "params": None})


def load_model_source(args: argparse.Namespace) -> tuple[IdentifiedModel | Robot, str]:
    """The rigid-body model and a label, from --model, --robot or --params (a robot
    description given as --params: :func:`params_as_robot` first)."""
    if args.model is not None:
        return load_model_json(args.model), str(args.model.name)
    if args.robot is not None:
        return load_robot(args), f"robot {args.robot}"
    if args.params is not None:
        return load_feasible_json(args.params), str(args.params.name)
    raise DynidError(
        "give one model source: --model identification.json, --robot ROBOT "
        "or --params feasible.json"
    )
