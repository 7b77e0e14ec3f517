"""Retrieve feasible link parameters from files: the entry point of ``dynid retrieve``.

Every method of :data:`~dynid.feasibility.methods.METHODS` (``sdp``, the convex retrieval;
``penalty``, Gaz et al.'s Algorithm 1) and both sources (an identified model's
``identification.json``, the method's "from coefficients"; static data, its "from data")
go through :func:`retrieve_files`, which applies the command's checks for the Python API
too: static data must be of the robot (joint count, recorded robot), the prior's joints
must be the robot's, a friction file on the robot must be sigmoid friction.
"""

from __future__ import annotations

from collections.abc import Callable, Mapping
from dataclasses import dataclass, replace
from pathlib import Path
from typing import Any, Literal

from .. import _checks
from .._parallel import available_cores
from ..exceptions import DynidError, OptionError
from ..feasibility.bounds import Bounds, default_bounds
from ..feasibility.convex import DEFAULT_SDP_MARGIN, SDPOptions
from ..feasibility.methods import METHODS
from ..feasibility.methods import method as consistent_method
from ..feasibility.penalty import RetrievalOptions, RetrievalProgress
from ..feasibility.result import FeasibleResult
from ..friction.model import FrictionModel, combined
from ..identification.core import shared_bases
from ..identification.model import IdentifiedModel
from ..identification.static_flange import data_flange_note, model_flange_note
from ..io.bounds_file import load_bounds
from ..io.friction_json import load_friction_json
from ..io.model_json import load_model_json
from ..model.robot import Robot
from .data_files import ColumnSpec, check_file_entries, column_map, read_static_file
from .options import check_band, check_choice, check_count, check_number, checked_options
from .prior import load_prior
from .static_outliers import without_outlying

__all__ = [
    "Retrieval",
    "RetrieveOptions",
    "load_bounds_for",
    "load_model_with_friction",
    "retrieve_files",
]


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
    if not isinstance(fr, FrictionModel) or fr.kind != "sigmoid" or fr.drive is not None:
        raise OptionError(
            f"{Path(path).name} holds {fr.kind} friction; sigmoid friction goes on the robot "
            "(the law a robot description holds): give a friction.json of the sigmoid law "
            "(`dynid friction --friction-model sigmoid`), or none",
            field="friction",
        )
    return robot.with_friction(fr)


def load_model_with_friction(
    path: str | Path, friction: str | Path | None = None
) -> IdentifiedModel:
    """The identified model ``path`` (identification.json), its robot carrying the
    sigmoid friction of ``friction`` (friction.json) when given.

    Raises
    ------
    DynidError
        A malformed file; a friction file that is not sigmoid friction, or given for a
        model that holds friction of its own (identified with the links).
    """
    model = load_model_json(path)
    own = combined(model.frictions)
    if friction is not None and own is not None:
        raise OptionError(
            f"applies to a model without friction (static data); {Path(path).name} holds "
            f"{own.kind} friction identified with the links, which feasible.json and the "
            "exports carry: leave it out",
            field="friction",
        )
    robot = _with_friction(model.robot, friction)
    if robot is model.robot:
        return model
    return IdentifiedModel(robot, model.base, model.fit, model.terms, model.info, drive=model.drive)


#: Options of the penalty method only, and of the convex method only (the prior: the
#: penalty method's pull towards one is too weak to make a plausible link of an
#: implausible one, and the command documents the prior for the convex method alone).
PENALTY_ONLY = ("runs", "stages", "workers")
CONVEX_ONLY = ("margin", "objective", "prior", "prior_base", "prior_tip", "prior_weight")


@dataclass(frozen=True, slots=True)
class RetrieveOptions:
    """How :func:`retrieve_files` retrieves feasible link parameters.

    Attributes
    ----------
    method : str
        A name of :data:`~dynid.feasibility.methods.METHODS`: ``"sdp"``, the convex
        retrieval with a prior, or ``"penalty"``, the penalty method (Algorithm 1).
    prior : str, Path or Robot, optional
        Convex method: the prior link parameters
        (:func:`~dynid.workflows.prior.load_prior`); default the model's robot's own
        inertials (generic without any).
    prior_base, prior_tip : str, optional
        Convex method: the chain of a URDF prior.
    prior_weight : float, optional
        Weight of the distance to the prior (>= 0; default: the method's).
    objective : {"logdet", "euclidean"}, optional
        Convex method: distance to the prior (default log-det).
    margin : float, optional
        Convex method: lambda_min(J) >= margin tr(J), 0 <= margin < 0.25.
    bounds : str or Path, optional
        Bounds file (default: :func:`~dynid.feasibility.bounds.default_bounds`).
    total_mass_band : bool
        False drops the bounds' total-mass band.
    total_mass : (float, float), optional
        Band on the total mass [kg], 0 <= min <= max.
    friction : str or Path, optional
        friction.json (sigmoid) put on the robot (exported with it).
    runs, stages : int, optional
        Penalty method: independent runs and stages per run (default: its own).
    workers : int, optional
        Penalty method: worker processes (capped at the cores and the runs, with a note).
    seed : int or None
        Penalty method: the seed of the runs.
    drop_invalid : bool
        Static data: drop the rows holding NaN or inf (said in a warning) instead of
        refusing the file.
    columns : (str or None, str or None), optional
        Static data: the column names and units of a file of another tool (``--columns``,
        ``--units``), read as ``identify`` reads them
        (:func:`~dynid.workflows.data_files.column_map`); recorded with the result
        (:attr:`Retrieval.column_map`).

    Raises
    ------
    OptionError
        An unknown method; an option of the other method; a value out of its range;
        ``total_mass`` without ``total_mass_band``; ``prior_weight`` with the penalty
        method and no prior (``field`` names it).
    """

    method: str = "sdp"
    prior: str | Path | Robot | None = None
    prior_base: str | None = None
    prior_tip: str | None = None
    prior_weight: float | None = None
    objective: str | None = None
    margin: float | None = None
    bounds: str | Path | None = None
    total_mass_band: bool = True
    total_mass: tuple[float, float] | None = None
    friction: str | Path | None = None
    runs: int | None = None
    stages: int | None = None
    workers: int | None = None
    seed: int | None = 0
    drop_invalid: bool = False
    columns: ColumnSpec | None = None

    def __post_init__(self) -> None:
        check_choice(self, "method", METHODS, optional=False)
        for name in ("runs", "stages", "workers"):
            check_count(self, name)
        check_count(self, "seed", low=0)
        check_number(self, "prior_weight", low_open=False)
        check_number(self, "margin", low_open=False, high=0.25, high_open=True)
        check_choice(self, "objective", ("logdet", "euclidean"))
        check_band(self, "total_mass")
        other = {"sdp": PENALTY_ONLY, "penalty": CONVEX_ONLY}.get(self.method, ())
        method = "penalty" if self.method == "sdp" else "sdp"
        for name in other:
            if getattr(self, name) is not None:
                raise OptionError(
                    f"applies to {{method}} {method} only; leave it out",
                    field=name,
                    others=("method",),
                )
        if self.total_mass is not None and not self.total_mass_band:
            raise OptionError(
                "sets the band {total_mass_band} drops; give one of them",
                field="total_mass",
                others=("total_mass_band",),
            )

    def method_options(self) -> SDPOptions | RetrievalOptions:
        """The settings of the method (its ``options_type``).

        Raises
        ------
        OptionError
            Runs, stages or a prior weight the penalty method refuses.
        """
        if self.method != "penalty":
            return SDPOptions(
                objective=self.objective or "logdet",
                prior_weight=self.prior_weight,
                margin=DEFAULT_SDP_MARGIN if self.margin is None else self.margin,
            )
        every = {"runs": self.runs, "stages": self.stages, "prior_weight": self.prior_weight}
        given: dict[str, Any] = {k: v for k, v in every.items() if v is not None}
        try:
            return RetrievalOptions(**given)
        except ValueError as exc:
            raise OptionError(f"(penalty method): {exc}", field=_refused(given)) from None


def _refused(given: dict[str, Any]) -> str:
    """The first of the penalty method's ``given`` settings it refuses on its own (else
    the first given)."""
    for k, v in given.items():
        try:
            RetrievalOptions(**{k: v})
        except ValueError:
            return k
    return next(iter(given))


@dataclass(frozen=True, slots=True, eq=False)
class Retrieval:
    """Result of :func:`retrieve_files`.

    Attributes
    ----------
    result : FeasibleResult
        The method's: ConsistentResult (sdp) or RetrievalResult (penalty).
    notes : tuple of (str, str)
        What was adjusted, as (field, what): the worker processes capped at the cores
        and the runs (``("workers", "64: using 2 (2 cores, 10 runs)")``).
    column_map : mapping, optional
        How the data were read (``{"columns": ..., "units": ...}``): the static data's
        ``columns`` given, or the identified model's record (``info.column_map``); for
        ``feasible.json``.
    """

    result: FeasibleResult
    notes: tuple[tuple[str, str], ...] = ()
    column_map: Mapping[str, str | None] | None = None


@shared_bases()  # static data: the outlier search's base parameters are the fit's
def retrieve_files(
    source: str | Path,
    options: RetrieveOptions | None = None,
    *,
    kind: Literal["model", "static"] = "model",
    robot: Robot | None = None,
    progress: Callable[[RetrievalProgress], None] | None = None,
) -> Retrieval:
    """Feasible link parameters from an identified model or from static data.

    Parameters
    ----------
    source : str or Path
        ``identification.json`` (``kind="model"``) or static data ``.csv``/``.npz``
        (``kind="static"``, the single-step variant).
    options : RetrieveOptions, optional
    kind : {"model", "static"}
        What ``source`` is.
    robot : Robot, optional
        Static data: the robot the data were recorded with (required).
    progress : callable, optional
        Penalty method: called with each finished run.

    Returns
    -------
    Retrieval

    Raises
    ------
    DynidError
        A bad file; static data without a robot or of another robot; a prior whose
        joints differ from the robot's.
    OptionError
        Options the method refuses (``field`` names them).
    """
    _checks.of_type("source", source, (str, Path), "a path (str or Path) of a file")
    opt = checked_options(options, RetrieveOptions)
    m = consistent_method(opt.method)
    method_options = opt.method_options()
    spec = None if opt.columns in (None, (None, None)) else opt.columns
    if kind == "model":
        if spec is not None:
            raise OptionError(
                "applies to static data (a file of another tool); an identified model holds "
                "no rows: leave it out",
                field="columns",
            )
        model = load_model_with_friction(source, opt.friction)
        if opt.prior is None:  # the description's inertials, as in the fit's own run
            model = replace(model, robot=model.description, description_phi=None)
        robot = model.robot
    elif robot is None:
        raise DynidError("retrieving from static data needs the robot that recorded them")
    else:
        robot = _with_friction(robot, opt.friction)
        cmap = None if spec is None else column_map(*spec, robot=robot)
        check_file_entries(cmap, [source])
        data = read_static_file(source, robot, columns=cmap, drop_invalid=opt.drop_invalid)
        data = without_outlying(robot, Path(source), data, keep_flag="")
    prior = opt.prior
    if not isinstance(prior, Robot):
        prior = load_prior(prior, robot, base=opt.prior_base, tip=opt.prior_tip)
    workers, notes = opt.workers, []
    if workers is not None and isinstance(method_options, RetrievalOptions):
        cores = available_cores()
        cap = min(cores, method_options.runs)
        if workers > cap:
            notes.append(
                ("workers", f"{workers}: using {cap} ({cores} cores, {method_options.runs} runs)")
            )
            workers = cap
    common: dict[str, Any] = {
        "prior": prior,
        "bounds": load_bounds_for(robot, opt.bounds, total_mass_band=opt.total_mass_band),
        "total_mass": opt.total_mass,
        "options": method_options,
        "workers": workers,
        "seed": opt.seed,
        "progress": progress,
    }
    given = prior if opt.prior is not None else None
    if kind == "model":
        result = m.from_coefficients(model, **common)  # with the model's friction, drive
        hand = model_flange_note(model, given) if _static_route(model) else None
        return Retrieval(_noted(result, hand), tuple(notes), model.info.column_map)
    hand = data_flange_note(robot, data.q, data.g, given)
    read = None if spec is None else {"columns": spec[0], "units": spec[1]}
    return Retrieval(_noted(m.from_data(robot, data, **common), hand), tuple(notes), read)


def _static_route(model: IdentifiedModel) -> bool:
    """Whether ``model`` was identified from static data (its gravity torques a
    controller's model's)."""
    return model.info.route == "static"


def _noted(result: FeasibleResult, said: str | None) -> FeasibleResult:
    """``result`` with ``said`` (a mass at the flange the description lacks,
    :mod:`dynid.identification.static_flange`) first in its notes; ``result`` for None."""
    return result if said is None else replace(result, notes=(said, *result.notes))
