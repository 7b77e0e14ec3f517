"""The prior of a consistent fit, named by a built-in robot or a file, checked against the
robot; every refusal an :class:`~dynid.exceptions.OptionError` of the field ``prior``."""

from __future__ import annotations

import logging
from pathlib import Path

import numpy as np

from .._checks import text
from ..exceptions import DynidError, OptionError
from ..io.robot_file import ROBOT_FILE_SUFFIXES, load_robot
from ..model.builtin import BUILTIN_ROBOTS, builtin_robot
from ..model.robot import Robot

__all__ = ["load_prior"]

_log = logging.getLogger(__name__)


#: The ``--prior`` that asks for a solid cylinder per link from the kinematics (the
#: default prior when the description holds no inertials; the default is else the
#: description's own).
GENERIC = "generic"


def load_prior(
    spec: str | Path | None, robot: Robot, *, base: str | None = None, tip: str | None = None
) -> Robot | None:
    """The prior robot ``spec`` for ``robot``, or None (the default prior: the robot's own
    inertials, or the generic one without any).

    Parameters
    ----------
    spec : str or Path, optional
        ``'generic'`` (a solid cylinder per link,
        :func:`~dynid.feasibility.prior.generic_prior`), ``'panda'``, ``'fr3'``, a
        ``.urdf`` (chain ``base`` to ``tip``, default: the robot's first and last link
        names; its angles rounded near multiples of pi/2 read snapped and not warned
        about: only its inertials are used), a ``.toml`` or a ``feasible.json``.
    robot : Robot
        The robot being identified.
    base, tip : str, optional
        The URDF prior's chain (fields ``prior_base``, ``prior_tip`` of the options).

    Returns
    -------
    Robot or None
        A file's prior is named after the file (reports name it). Joint frames that
        differ from the robot's are logged as a warning: the prior's link parameters are
        used in the robot's link frames as they are.

    Raises
    ------
    OptionError
        A prior of another kind, missing or unreadable, or with joint types other than
        the robot's (``field`` is ``"prior"``); ``base`` or ``tip`` without a URDF prior.
    """
    if base is not None or tip is not None:
        if not (isinstance(spec, str | Path) and Path(spec).suffix.lower() == ".urdf"):
            raise OptionError(
                "applies to a URDF {prior} only; leave it out",
                field="prior_base" if base is not None else "prior_tip",
                others=("prior",),
            )
    if spec is None:
        return None
    spec = str(spec)
    if spec == GENERIC:  # the cylinders the default takes only without inertials
        from ..feasibility.prior import GENERIC_SOURCE, generic_prior

        return robot.with_params(generic_prior(robot).phi).replace(name=GENERIC_SOURCE)
    if spec in BUILTIN_ROBOTS:
        prior = builtin_robot(spec)
    else:
        path = Path(spec)
        if path.suffix.lower() not in ROBOT_FILE_SUFFIXES:
            raise OptionError(
                f"must be {' or '.join(map(repr, (GENERIC, *BUILTIN_ROBOTS)))} or a .urdf, "
                f".toml, .json (feasible.json) or .xml (MJCF) file; got {spec!r}",
                field="prior",
            )
        if not path.exists():
            raise OptionError(f"{path.name}: {path} does not exist", field="prior")
        urdf = path.suffix.lower() == ".urdf"
        try:
            if urdf:
                prior = load_robot(  # its angles snapped: only its inertials are used,
                    path,  # in the robot's frames; their rounding is the robot's to say
                    base=base or robot.link_names[0],
                    tip=tip or robot.link_names[-1],
                    snap_angles=True,
                    note_angles=False,
                )
            else:
                prior = load_robot(path)
        except DynidError as exc:
            hint = " (name the chain with {prior_base}/{prior_tip})" if urdf else ""
            raise OptionError(
                f"{path.name}: {exc}{hint}",
                field="prior",
                others=("prior_base", "prior_tip") if urdf else (),
            ) from None
        prior = prior.replace(name=text(path.name))  # an ASCII locale's name: its characters
    pk, rk = ("".join("P" if x else "R" for x in r.prismatic) for r in (prior, robot))
    if pk != rk:
        raise OptionError(f"{spec}: joints {pk}; the robot's are {rk}", field="prior")
    if not np.allclose(prior.T_parent_joint, robot.T_parent_joint, atol=1e-3):
        _log.warning(
            "the prior %s: its joint frames differ from the robot's by up to %.3g m; its link "
            "parameters are used in the robot's link frames as they are",
            spec,
            float(np.max(np.abs(prior.T_parent_joint - robot.T_parent_joint))),
        )
    return prior
