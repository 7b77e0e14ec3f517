"""Retrieve feasible link parameters from files: the entry point of ``dynid retrieve``.

Every method of :data:`~dynid.feasibility.methods.METHODS` (``sdp``, the convex retrieval;
``penalty``, Gaz et al.'s Algorithm 1) and both sources (an identified model's
``identification.json``, the method's "from coefficients"; static data, its "from data")
go through :func:`retrieve_file`, which applies the command's checks for the Python API
too: static data must be of the robot (joint count, recorded robot), the prior's joints
must be the robot's, a friction file on the robot must be sigmoid friction.
"""

from __future__ import annotations

from collections.abc import Callable
from pathlib import Path
from typing import Any, Literal

from ..exceptions import DynidError
from ..feasibility.bounds import Bounds, default_bounds
from ..feasibility.convex import SDPOptions
from ..feasibility.methods import method as consistent_method
from ..feasibility.penalty import RetrievalOptions, RetrievalProgress
from ..feasibility.result import FeasibleResult
from ..identification.model import IdentifiedModel
from ..io.bounds_file import load_bounds
from ..io.friction_json import load_friction_json
from ..io.model_json import load_model_json
from ..model.robot import Robot
from .data_files import read_static_file
from .prior import load_prior

__all__ = ["load_bounds_for", "load_model_with_friction", "retrieve_file"]


def load_bounds_for(
    robot: Robot, path: str | Path | None = None, *, total_mass_band: bool = True
) -> Bounds:
    """The bounds of ``--bounds`` (a JSON/TOML file) or the default ones for ``robot``;
    without ``total_mass_band`` (``--no-total-mass``) the total-mass band is dropped.

    Raises
    ------
    DataError
        A malformed bounds file (named).
    """
    bounds = load_bounds(path, robot) if path is not None else default_bounds(robot)
    return bounds if total_mass_band else bounds.with_total_mass(None)


def _with_friction(robot: Robot, path: str | Path | None) -> Robot:
    if path is None:
        return robot
    fr = load_friction_json(path)
    if fr.kind == "none":  # no friction: nothing to put on the robot
        return robot
    if fr.kind != "sigmoid" or fr.drive is not None:  # what the robot files hold
        raise DynidError(
            f"{Path(path).name} holds {fr.kind} friction; --friction puts sigmoid friction on "
            "the robot (the law a robot description holds): give a friction.json of "
            "`dynid friction --friction-model sigmoid`, or none"
        )
    return robot.with_friction(fr.as_array())


def load_model_with_friction(
    path: str | Path, friction: str | Path | None = None
) -> IdentifiedModel:
    """The identified model ``path`` (identification.json), its robot carrying the
    sigmoid friction of ``friction`` (friction.json) when given.

    Raises
    ------
    DynidError
        A malformed file; a friction file that is not sigmoid friction.
    """
    model = load_model_json(path)
    robot = _with_friction(model.robot, friction)
    if robot is model.robot:
        return model
    return IdentifiedModel(
        robot, model.base, model.fit, model.friction, model.info, drive=model.drive
    )


def retrieve_file(
    source: str | Path,
    *,
    kind: Literal["model", "static"] = "model",
    robot: Robot | None = None,
    method: str = "sdp",
    prior: str | Path | None = None,
    prior_base: str | None = None,
    prior_tip: str | None = None,
    bounds: str | Path | None = None,
    total_mass_band: bool = True,
    total_mass: tuple[float, float] | None = None,
    friction: str | Path | None = None,
    sdp_options: SDPOptions | None = None,
    options: SDPOptions | RetrievalOptions | None = None,
    workers: int | None = None,
    seed: int | None = 0,
    progress: Callable[[RetrievalProgress], None] | None = None,
) -> FeasibleResult:
    """Feasible link parameters from an identified model or from static data.

    Parameters
    ----------
    source : str or Path
        ``identification.json`` (``kind="model"``) or static data ``.csv``/``.npz``
        (``kind="static"``, the single-step variant).
    kind : {"model", "static"}
        What ``source`` is.
    robot : Robot, optional
        Static data: the robot the data were recorded with (required).
    method : str
        A name of :data:`~dynid.feasibility.methods.METHODS`: ``"sdp"``, the convex
        retrieval with a prior, or ``"penalty"``, the penalty method (Algorithm 1).
    prior, prior_base, prior_tip
        ``--prior`` and its URDF chain (:func:`~dynid.workflows.prior.load_prior`).
    bounds : str or Path, optional
        Bounds file (default: :func:`~dynid.feasibility.bounds.default_bounds`).
    total_mass_band : bool
        False drops the bounds' total-mass band (``--no-total-mass``).
    total_mass : (float, float), optional
        Band on the total mass [kg].
    friction : str or Path, optional
        friction.json (sigmoid) put on the robot (exported with it).
    sdp_options : SDPOptions, optional
        The convex method's options (as ``options``).
    options : SDPOptions or RetrievalOptions, optional
        The method's options (its ``options_type``).
    workers, seed, progress
        The penalty method's processes, seed and per-run callback; ``workers`` is refused
        by a method that runs in this process (the convex one).

    Returns
    -------
    FeasibleResult
        The method's: ConsistentResult (sdp) or RetrievalResult (penalty).

    Raises
    ------
    DynidError
        A bad file; static data without a robot or of another robot; a prior whose
        joints differ from the robot's; an unknown method, options of another method,
        ``workers`` for the convex method.
    """
    m = consistent_method(method)
    if sdp_options is not None and (m.name != "sdp" or options is not None):
        raise DynidError("sdp_options are the convex method's options; pass one set, as options")
    if kind == "model":
        model = load_model_with_friction(source, friction)
        robot = model.robot
    elif robot is None:
        raise DynidError("retrieving from static data needs the robot that recorded them")
    else:
        robot = _with_friction(robot, friction)
        data = read_static_file(source, robot)
    prior_robot = load_prior(prior, robot, base=prior_base, tip=prior_tip)
    common: dict[str, Any] = {
        "prior": prior_robot,
        "bounds": load_bounds_for(robot, bounds, total_mass_band=total_mass_band),
        "total_mass": total_mass,
        "options": sdp_options if options is None and m.name == "sdp" else options,
        "workers": workers,
        "seed": seed,
        "progress": progress,
    }
    if kind == "model":
        return m.from_coefficients(model, **common)
    return m.from_data(robot, data, **common)
