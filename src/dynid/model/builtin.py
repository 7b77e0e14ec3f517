"""The robots dynid knows by name (``--robot panda``, ``--robot fr3``): one table.

Every option that names a robot (``--robot``, ``--prior``, ``--params``) and
:func:`dynid.io.robot_file.load_robot` read :data:`BUILTIN_ROBOTS`; adding a robot is one
module in :mod:`dynid.model` and one entry here. A robot whose link parameters are not
its own (the FR3's are the Panda's) is said so where its name is resolved
(:func:`builtin_robot`, a log record of level :data:`~dynid.progress.NOTE`, which the
command line prints once per run).
"""

from __future__ import annotations

import logging
from collections.abc import Callable, Mapping
from dataclasses import dataclass
from types import MappingProxyType

from ..exceptions import UnknownNameError
from ..progress import NOTE
from .fr3 import FR3_PARAMETER_NOTE, fr3
from .panda import panda
from .robot import Robot

__all__ = ["BuiltinRobot", "BUILTIN_ROBOTS", "builtin_robot"]

_log = logging.getLogger(__name__)


@dataclass(frozen=True, slots=True)
class BuiltinRobot:
    """A robot known by name.

    Attributes
    ----------
    name : str
        The name as the user types it (``--robot NAME``).
    make : callable
        Builds the :class:`~dynid.model.robot.Robot`.
    summary : str
        One line: what the robot is and where its numbers come from.
    parameter_note : str or None
        Said wherever the robot's link parameters are used (as a prior, say) when they
        are not the robot's own; None when they are.
    """

    name: str
    make: Callable[[], Robot]
    summary: str
    parameter_note: str | None = None


#: The built-in robots by name.
BUILTIN_ROBOTS: Mapping[str, BuiltinRobot] = MappingProxyType(
    {
        "panda": BuiltinRobot(
            "panda",
            panda,
            "Franka Emika Panda: MDH kinematics, feasible link parameters and friction of "
            "Gaz et al. 2019, Franka's Panda limits",
        ),
        "fr3": BuiltinRobot(
            "fr3",
            fr3,
            "Franka Research 3: the Panda's kinematics and flange, Franka's FR3 limits, the "
            "Panda's link parameters and friction",
            FR3_PARAMETER_NOTE,
        ),
    }
)


def builtin_robot(name: str, *, parameters: bool = True) -> Robot:
    """The built-in robot ``name`` (``"panda"``, ``"fr3"``); its
    :attr:`~BuiltinRobot.parameter_note`, when it has one, is logged at level
    :data:`~dynid.progress.NOTE` unless ``parameters`` is False (the caller uses the
    kinematics and limits alone: forward kinematics, Jacobians, inverse kinematics).

    Raises
    ------
    UnknownNameError
        ``name`` is not in :data:`BUILTIN_ROBOTS`; the message lists the names.
    """
    try:
        entry = BUILTIN_ROBOTS[name]
    except (KeyError, TypeError):
        raise UnknownNameError(
            f"unknown built-in robot {name!r}; available: {sorted(BUILTIN_ROBOTS)}"
        ) from None
    if entry.parameter_note and parameters:
        _log.log(NOTE, "%s", entry.parameter_note)
    return entry.make()
