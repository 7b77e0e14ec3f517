"""The model a command compares with data or carries a load on (``--model``, ``--robot``
or ``--params``) and the log it is compared with (``--data``); kept apart from
:mod:`.common`, which the kinematics commands import: these load the identification and
feasibility packages (scipy)."""

from __future__ import annotations

import argparse
from typing import Any

from ..exceptions import DynidError
from ..identification.log import TorqueLog
from ..identification.model import IdentifiedModel
from ..io.feasible import load_feasible_json
from ..io.model_json import load_model_json
from ..model.robot import Robot
from ..workflows.data_files import column_map, read_torque_log, recorded_columns
from .common import load_robot

__all__ = ["load_model_source", "read_data_log"]


def load_model_source(args: argparse.Namespace) -> tuple[IdentifiedModel | Robot, str]:
    """The rigid-body model and a label, from --model, --robot or --params."""
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


def read_data_log(
    args: argparse.Namespace, n: int, *, owner: str, recorded: Any = None
) -> TorqueLog:
    """``--data`` read as a torque log of ``n`` joints (:func:`~dynid.workflows.data_files.
    read_torque_log`), through ``--columns``/``--units``, or those a model recorded
    (``recorded``, its ``info.column_map``) when none are given
    (:func:`~dynid.workflows.data_files.recorded_columns`)."""
    columns, units = recorded_columns(
        recorded, getattr(args, "columns", None), getattr(args, "units", None)
    )
    return read_torque_log(
        args.data,
        n,
        columns=column_map(columns, units, cutoff_hz=getattr(args, "cutoff", None)),
        drop_invalid=bool(getattr(args, "drop_invalid", False)),
        owner=owner,
    )
