"""The prior of a consistent fit, named as on the command line, checked against the robot."""

from __future__ import annotations

import logging
from pathlib import Path

import numpy as np

from ..exceptions import DynidError
from ..io.robot_file import load_robot
from ..model.builtin import BUILTIN_ROBOTS, builtin_robot
from ..model.robot import Robot

__all__ = ["load_prior"]

_log = logging.getLogger(__name__)


def load_prior(
    spec: str | Path | None, robot: Robot, *, base: str | None = None, tip: str | None = None
) -> Robot | None:
    """The prior robot ``spec`` (``--prior``) for ``robot``, or None (the generic prior).

    Parameters
    ----------
    spec : str or Path, optional
        ``'panda'``, ``'fr3'``, a ``.urdf`` (chain ``base`` to ``tip``, default: the
        robot's first and last link names), a ``.toml`` or a ``feasible.json``.
    robot : Robot
        The robot being identified.
    base, tip : str, optional
        ``--prior-base``/``--prior-tip``: the URDF chain.

    Returns
    -------
    Robot or None
        A file's prior is named after the file (reports name it). Joint frames that
        differ from the robot's are logged as a warning: the prior's link parameters are
        used in the robot's link frames as they are.

    Raises
    ------
    DynidError
        An unreadable prior (the message starts with ``--prior``) or joint types other
        than the robot's.
    """
    if spec is None:
        return None
    spec = str(spec)
    if spec in BUILTIN_ROBOTS:
        prior = builtin_robot(spec)
    else:
        path = Path(spec)
        try:
            prior = load_robot(
                path,
                base=base or robot.link_names[0],
                tip=tip or robot.link_names[-1],
                what="--prior",
            )
        except DynidError as exc:
            hint = (
                " (name the chain with --prior-base/--prior-tip)" if path.suffix == ".urdf" else ""
            )
            msg = str(exc) if str(exc).startswith("--prior") else f"--prior {path.name}: {exc}"
            raise DynidError(msg + hint) from None
        prior = prior.replace(name=path.name)
    pk, rk = ("".join("P" if x else "R" for x in r.prismatic) for r in (prior, robot))
    if pk != rk:
        raise DynidError(f"--prior {spec}: joints {pk}; the robot's are {rk}")
    if not np.allclose(prior.T_parent_joint, robot.T_parent_joint, atol=1e-3):
        _log.warning(
            "--prior %s: its joint frames differ from the robot's by up to %.3g m; its link "
            "parameters are used in the robot's link frames as they are",
            spec,
            float(np.max(np.abs(prior.T_parent_joint - robot.T_parent_joint))),
        )
    return prior
