"""``feasible.json``: the feasible link parameters of a retrieval or a consistent fit.

:func:`save_feasible_json` and :func:`load_feasible_json`: the parameters of every moving
link, in the schema of the robot description's inertials (:mod:`dynid.io.robot.toml`):
``mass`` [kg], ``com`` [m] in the link frame, ``inertia`` ``[xx, xy, xz, yy, yz, zz]``
[kg m^2] **about the CoM**, link-frame axes. It also holds the robot's kinematics
(:mod:`dynid.io.robot_json`) and the friction of the fitted model
(:func:`fitted_robot`: the input robot's sigmoid only when the fit identified no friction
and was not on a torque log; the friction identified with the links in ``linear_friction``,
:mod:`dynid.io.law_friction`), so that it loads back as a complete
:class:`~dynid.model.robot.Robot` (:func:`load_feasible_json`: its friction the identified
one, acting where it was identified; :func:`dynid.model_torques` of it with the file's
drive predicts the fit's torques)::

    {"schema": "dynid-feasible-parameters/1", "dynid_version": ..., "name": ...,
     "links": [{"name": "link1", "mass": 4.97, "com": [...], "inertia": [...]}, ...],
     "friction": null | {"model": "sigmoid", "phi1": [...], "phi2": [...], "phi3": [...]},
     "linear_friction": null | {"model": "classical", "fv": [...], "fc": [...], "fo": [...],
         "standstill_band": [...]} (a smooth law's "width": [...], its tanh's),
     "joint_friction": {"model": "classical", "fv": [...], ...} (with friction at the motors
         and at the joints of a coupled drive: the part at the joints),
     "drive": null | {dynid-drive/1 record, rotor_inertia: the identified values},
     "combined": {"fv6": "fv6 + 0.0005556*jfv7", ...} (only when friction coefficients
         hold one left out as structurally combined with them),
     "set_by_prior": {"mass": [true, ...], "com": [[true, false, true], ...],
         "parameters": ["m2", ...], "prior_share": {"m1": 1.0, ...} | null} (of an
         identified model's coefficients: which values the prior sets, not the data),
     "spring": {"k": [...], "q0": [...]} (only with a spring term: the stiffnesses
         identified with the links, :mod:`dynid.io.spring_record`),
     "column_map": {"columns": ..., "units": "tau2=-1"} (how the fit's data were read;
         ``payload --params`` reads its logs so unless given --columns/--units),
     "unknown_scale": {"motors": [6, 7], "joints": [...], "factor": [1.10, null],
         "finding": ...} (the motors whose torque constants the data leave unknown beside
         those judged off; the robot files written of it say so at their top),
     "armature_left_out": ["Ia4", "Ia6"] (only when the identified structure left some
         rotor inertias out and kept others: those left out, 0 in ``drive``, which the
         data did not determine; the robot files written of it say so at their top,
         :func:`armature_left_out_note`),
     "kinematics": {...}, "feasible": true, "relative_residual": ..., "seed": ...,
     "violated": [...], "heldout": {...}, "units": {...}, "conventions": {...}}

A result whose constraints do not all hold, or whose held-out error is more than the
tolerance above least squares', is written with ``"feasible": false``, the constraints it
violates in ``violated`` and the judgement in ``heldout``: :func:`fit_rejection` says why in
one line, :func:`load_feasible_json` warns with it, and ``dynid export`` refuses such a file
unless told otherwise; the robot files written of it say why at their top
(:func:`rejection_caveat`).
"""

from __future__ import annotations

import warnings
from collections.abc import Mapping, Sequence
from pathlib import Path
from typing import Any

import numpy as np
from numpy.typing import NDArray

from .. import __version__, _checks
from .._checks import caller_level
from ..exceptions import DataError, DynidWarning, ModelError, ShapeError
from ..feasibility.constraints import Constraint
from ..feasibility.result import FeasibleResult
from ..friction.laws import LAWS
from ..friction.model import (
    Friction,
    FrictionSum,
    SigmoidFriction,
    friction_parts,
    sigmoid_parameters,
)
from ..model.drive import Drive
from ..model.inertia import (
    INERTIA_ORDER,
    inertia6_from_matrix,
    inertial_problems,
    matrix_from_inertia6,
)
from ..model.robot import MAX_LINK_MASS, MAX_LINK_OFFSET, Robot
from ..model.stiffness import JointStiffness
from ..regressors.terms import RotorInertia
from .drive_file import drive_from_record
from .json_files import finite_or_none, load_json
from .law_friction import law_friction, law_record
from .robot_json import ROBOT_RECORD, robot_from_dict, robot_to_dict
from .schema import Field, Format, Record, check, fault, load_document, save_document
from .spring_record import SPRING_FIELD, SPRING_FORMULA, spring_from_record, spring_record

__all__ = [
    "FEASIBLE",
    "FEASIBLE_SCHEMA",
    "armature_left_out",
    "armature_left_out_note",
    "load_armature_left_out",
    "feasible_to_dict",
    "fit_rejection",
    "load_fit_rejection",
    "rejection_caveat",
    "result_rejection",
    "load_feasible_drive",
    "load_feasible_json",
    "fitted_robot",
    "combined_coefficients",
    "feasible_drive",
    "feasible_linear_friction",
    "load_feasible_linear_friction",
    "load_feasible_spring",
    "robot_from_feasible_dict",
    "save_feasible_json",
]

FEASIBLE_SCHEMA = "dynid-feasible-parameters/1"

_UNITS = {"mass": "kg", "com": "m", "inertia": "kg m^2"}
_CONVENTIONS = {
    "com": "centre of mass in the link frame",
    "inertia": "about the CoM, link-frame axes, order " + " ".join(INERTIA_ORDER),
    "friction": "tau_f = phi1/(1+exp(-phi2 (dq+phi3))) - phi1/(1+exp(-phi2 phi3)) "
    "[phi1 N m, phi2 s/rad, phi3 rad/s] (Gaz et al. 2019, eq. 25)",
}
#: the farthest a link's centre of mass may lie from its frame [m], as in the robot
#: readers (1e300 overflowed the parallel-axis inertia into NaN)
MAX_COM_DISTANCE = MAX_LINK_OFFSET
_M = MAX_LINK_MASS
_LINK = Record(
    {
        "name": Field("string"),
        "mass": Field("number", required=True, low=-_M, high=_M, unit="kg"),
        "com": Field(
            "numbers",
            required=True,
            shape=(3,),
            low=-MAX_COM_DISTANCE,
            high=MAX_COM_DISTANCE,
            unit="m",
        ),
        "inertia": Field("numbers", required=True, shape=(6,), unit="kg m^2"),
    }
)
_PER_JOINT = Field("numbers", required=True, shape=("n",))
#: friction of a registry law identified with the links: ``model`` and one list per parameter
_LAW_FRICTION = Field(
    "object",
    nullable=True,
    record=Record({"model": Field("string", required=True, choices=tuple(LAWS))}, open=True),
)
#: ``feasible.json`` (module docstring; n: the joint count)
FEASIBLE = Format(
    FEASIBLE_SCHEMA,
    Record(
        {
            "dynid_version": Field("string"),
            "name": Field("string"),
            "links": Field("objects", required=True, record=_LINK),
            "friction": Field(
                "object",
                nullable=True,
                record=Record(
                    {"model": Field("string", choices=("sigmoid",))}
                    | {f"phi{k}": _PER_JOINT for k in (1, 2, 3)}
                ),
            ),
            "linear_friction": _LAW_FRICTION,
            "joint_friction": _LAW_FRICTION,
            "kinematics": Field("object", record=ROBOT_RECORD),
            "units": Field("any"),
            "conventions": Field("any"),
            "drive": Field("object", nullable=True),
            "method": Field("string"),
            "feasible": Field("bool"),
            "relative_residual": Field("number", nullable=True),
            "seed": Field("integer", nullable=True),
            "violated": Field("strings"),
            "heldout": Field("object", nullable=True),
            "combined": Field("object"),
            "set_by_prior": Field("object"),
            "spring": SPRING_FIELD,
            "column_map": Field("object"),
            "unknown_scale": Field("object"),
            "armature_left_out": Field("strings"),
        }
    ),
    "feasible-parameter file",
)


def feasible_to_dict(
    source: FeasibleResult | Robot,
    *,
    seed: int | None = None,
    column_map: Mapping[str, Any] | None = None,
    unknown_scale: Mapping[str, Any] | None = None,
) -> dict[str, Any]:
    """The link parameters (and kinematics, friction) of a consistent result or a robot.

    Parameters
    ----------
    source : FeasibleResult or Robot
        A result (either method) also records ``method``, ``feasible``,
        ``relative_residual`` and its seed; the classical friction identified with the links
        (``linear_friction``: ``fv, fc >= 0``; per motor with a drive whose friction acts
        at the motors), its drive's record (``drive``, the identified rotor inertias
        [kg m^2] in ``rotor_inertia``) and its held-out judgement (``heldout``) when it has
        them.
    seed : int, optional
        Recorded when ``source`` is a Robot.

    Returns
    -------
    dict
        JSON-ready (module docstring).

    Warns
    -----
    DynidWarning
        The robot's friction is another law than the sigmoid at the joints, which the file
        does not hold (``friction.json`` does): it is left out.
    """
    result: FeasibleResult | None = None
    if isinstance(source, Robot):
        robot = source
    else:
        result, robot = source, fitted_robot(source)
    I6 = inertia6_from_matrix(robot.inertia)
    links = [
        {
            "name": robot.link_names[i + 1],
            "mass": float(robot.mass[i]),
            "com": [float(x) for x in robot.com[i]],
            "inertia": [float(x) for x in I6[i]],
        }
        for i in range(robot.n)
    ]
    fr = None
    P = sigmoid_parameters(robot.friction)
    if P is not None:  # what the format holds (module docstring)
        fr = {"model": "sigmoid"} | {f"phi{k + 1}": [float(x) for x in P[:, k]] for k in range(3)}
    elif robot.friction is not None and result is None:  # a result's is linear_friction
        warnings.warn(
            f"feasible.json: the robot's {robot.friction.kind} friction is not part of the file "
            "(which holds the sigmoid at the joints) and is not written; save it as friction.json",
            DynidWarning,
            stacklevel=caller_level(),
        )
    parts = friction_parts(None if result is None else result.friction)
    drive = None if result is None else result.drive
    conventions = {k: v for k, v in _CONVENTIONS.items() if k != "friction" or fr is not None}
    for key, part in zip(("linear_friction", "joint_friction"), parts, strict=False):
        conventions[key] = part.law.formula + (
            " (at the motors: K^T f(K dq))" if _at_motors(part) else ""
        )
    d: dict[str, Any] = {
        "schema": FEASIBLE_SCHEMA,
        "dynid_version": __version__,
        "name": robot.name,
        "links": links,
        "friction": fr,
        "linear_friction": law_record(parts[0]) if parts else None,
        "kinematics": robot_to_dict(robot),
        "units": _UNITS,
        "conventions": conventions,
        "drive": None if drive is None else drive.as_dict(),
    }
    if len(parts) > 1:
        d["joint_friction"] = law_record(parts[1])
    spring = robot.spring if result is None else result.spring
    if spring is not None:
        d["spring"] = spring_record(spring)
        conventions["spring"] = SPRING_FORMULA
    combined = combined_coefficients(result)
    if combined:  # not the motors' (joints') own friction alone: said beside the values
        d["combined"] = combined
        conventions["combined"] = (
            "friction coefficients that hold one left out as structurally dependent on them "
            "(no data tell them apart), not their own values alone: "
            + "; ".join(f"{lab} holds {expr}" for lab, expr in combined.items())
        )
    if column_map is not None:  # how the data were read: payload reads its logs so
        d["column_map"] = dict(column_map)
    if unknown_scale is not None:
        d["unknown_scale"] = dict(unknown_scale)
    if left := armature_left_out(result):
        d["armature_left_out"] = list(left)
    if result is None:
        return d if seed is None else d | {"seed": seed}
    marks = prior_marks_record(result)
    if marks is not None:
        d["set_by_prior"] = marks
        conventions["set_by_prior"] = SET_BY_PRIOR
    d["method"] = result.method
    d["relative_residual"] = finite_or_none(result.relative_residual)
    d["seed"] = result.seed
    return d | _judgement(result)


#: What ``set_by_prior`` means (``conventions``).
SET_BY_PRIOR = (
    "true: the prior sets the value, not the data: the data give only combinations holding "
    "it (the base parameters), or too little of it (the prior's share above one half); "
    "a CoM component when its first moment or the link's mass is; parameters: the standard "
    "parameters so set, prior_share: each one's share of the prior, 0 (the data's) to 1"
)


def prior_marks_record(result: FeasibleResult) -> dict[str, Any] | None:
    """``set_by_prior`` of ``feasible.json``: per link whether the prior sets its mass and
    each CoM component, the standard parameters it sets and each one's prior share (None
    when not computed); None without a determination (static data)."""
    det = result.determined
    if det is None or det.n != result.robot.n:
        return None
    mass, com = det.link_marks()
    return {
        "mass": [bool(x) for x in mass],
        "com": [[bool(x) for x in row] for row in com],
        "parameters": [lab for lab, b in zip(det.labels, det.by_prior, strict=True) if b],
        "prior_share": None
        if det.prior_share is None
        else dict(zip(det.labels, det.prior_share, strict=True)),
    }


def _judgement(result: FeasibleResult) -> dict[str, Any]:
    """``feasible``, ``violated`` and ``heldout`` of ``feasible.json``: whether the fit
    was accepted, and why not."""
    d: dict[str, Any] = {
        "feasible": bool(result.feasible),
        "violated": [_violated_text(c) for c in result.report.violated],
    }
    if result.heldout is not None:
        d["heldout"] = result.heldout.as_dict()
    return d


def _violated_text(c: Constraint) -> str:
    """A violated constraint as ``feasible.json``'s ``violated`` holds it:
    ``mass_positive (link 3) by 0.2 kg`` (how far outside, in its unit)."""
    return f"{c.name}{f' (link {c.link})' if c.link else ''} by {-c.margin:.3g} {c.unit}"


def fit_rejection(d: Mapping[str, Any]) -> str | None:
    """Why the fit a ``feasible.json`` document holds was not accepted, in one line, from
    what the file records; None for an accepted fit or a robot written as the file.

    The held-out judgement (``heldout``: the fit's held-out torque error against least
    squares' and the tolerance) when it refused the fit, and the other constraints that do
    not hold (``violated``); a file of a version that did not record them says that its
    constraints do not all hold. Such as ``held-out torque error 2.52 %, 7.79 % above
    least squares' 2.34 % (tolerance 5 %)``.
    """
    if d.get("feasible", True) is not False:
        return None
    parts = []
    held = d.get("heldout")
    judged = isinstance(held, Mapping) and held.get("accepted") is False
    if judged and isinstance(held, Mapping):
        try:
            ls = float(held["least_squares"]["heldout_error_percent"])
            own = float(held["consistent"]["heldout_error_percent"])
            over, tol = 100 * (float(held["ratio"]) - 1), 100 * float(held["tolerance"])
            parts.append(
                f"held-out torque error {own:.3g} %, {over:.3g} % above least squares' "
                f"{ls:.3g} % (tolerance {tol:g} %)"
            )
        except (KeyError, TypeError, ValueError):
            parts.append("its held-out error is above the tolerance of least squares'")
    violated = [
        str(v) for v in d.get("violated") or () if not (judged and str(v).startswith("data_fit"))
    ]
    if violated:
        parts.append("violated: " + "; ".join(violated[:4]) + (" ..." if len(violated) > 4 else ""))
    if not parts:
        parts.append("its constraints do not all hold (report.json beside it names them)")
    return ", ".join(parts)


def result_rejection(result: FeasibleResult) -> str | None:
    """:func:`fit_rejection` of a result, as its ``feasible.json`` would say it."""
    return fit_rejection(_judgement(result))


def rejection_caveat(reason: str) -> str:
    """The comment at the top of a robot file written from a fit that was not accepted
    (``reason``: :func:`fit_rejection`)."""
    return f"NOT ACCEPTED: these parameters come from a fit that was not accepted ({reason})"


def combined_coefficients(result: FeasibleResult | None) -> dict[str, str]:
    """The identified model's coefficients that hold a structurally combined one left out
    (:attr:`~dynid.identification.info.IdentificationInfo.combined`), when the result has
    the model."""
    model = getattr(result, "identified", None)
    return {} if model is None else dict(model.info.combined)


def fitted_robot(result: FeasibleResult) -> Robot:
    """The result's robot with the friction of the fitted model, as the files hold it, and
    the joint springs identified with the links (``result.spring``).

    The friction identified with the links (``result.friction``; none when it acts at the
    motors and at the joints, which a robot does not hold: ``feasible.json`` keeps both
    parts); none after a one-step fit of a torque log whose structure had no friction (the
    input robot's friction was not part of the fit); the input robot's own friction for a
    retrieval or a fit of static data, which identify none.
    """
    f = result.friction
    robot = result.robot if result.spring is None else result.robot.with_spring(result.spring)
    if f is not None:
        return robot.with_friction(None if isinstance(f, FrictionSum) else f)
    return robot.with_friction(None) if result.kind == "log" else robot


def _at_motors(friction: Friction) -> bool:
    return friction.drive is not None and friction.drive.friction_place == "motor"


def save_feasible_json(path: str | Path, source: FeasibleResult | Robot, **recorded: Any) -> Path:
    """Write ``feasible.json`` (see :func:`feasible_to_dict`, whose ``column_map`` and
    ``unknown_scale`` ``recorded`` passes on); returns the path.

    Raises
    ------
    NonFiniteError
        A NaN or infinite number in the parameters (named).
    """
    return save_document(path, FEASIBLE, feasible_to_dict(source, **recorded))


def robot_from_feasible_dict(
    d: Mapping[str, Any], robot: Robot | None = None, *, source: str = "feasible parameters"
) -> Robot:
    """A robot with the link parameters of a :func:`feasible_to_dict` dictionary and the
    model terms identified with them.

    The friction identified with the links (``linear_friction``, with ``joint_friction``
    their :class:`~dynid.friction.model.FrictionSum`; per motor through the file's drive
    where its friction acts at the motors: :func:`feasible_linear_friction`) and the joint
    springs (``spring``) are the fitted model's, which its links predict torques with:
    they are put on the robot in either case below.

    Parameters
    ----------
    d : mapping
    robot : Robot, optional
        Kinematics to put the parameters on (its link names must match the file's); its
        own friction and spring are kept where the file holds none identified (the
        sigmoid ``friction`` of a retrieval, the input robot's, is not put on it). Default:
        the kinematics held in the file, with its friction (the identified one, else the
        sigmoid ``friction``) and springs.
    source : str
        The file named in messages.

    Raises
    ------
    DataError
        Wrong schema, an unknown key, a missing or malformed field, a mass beyond
        ``MAX_LINK_MASS`` or a CoM beyond :data:`MAX_COM_DISTANCE` (:mod:`dynid.io.schema`),
        link names that do not match ``robot``, a friction law's parameter missing or not
        one per joint.

    Warns
    -----
    DynidWarning
        A link whose parameters are not physically consistent (kept as given).
    """
    if not isinstance(d, Mapping) or d.get("schema") != FEASIBLE_SCHEMA:
        got = _checks.short(d.get("schema")) if isinstance(d, Mapping) else "no object"
        raise fault(source, "schema", f"expected {FEASIBLE_SCHEMA!r} ({FEASIBLE.what}); got {got}")
    check(d, FEASIBLE.top, source)
    links = d["links"]
    if robot is None:
        if "kinematics" not in d:
            raise fault(source, "kinematics", "missing; pass the robot the parameters are of")
        robot = robot_from_dict(d["kinematics"], source=source, at="kinematics")
        fr = d.get("friction")
        if fr is not None:
            F = np.array([fr[f"phi{k}"] for k in (1, 2, 3)], dtype=float).T
            try:
                robot = robot.with_friction(SigmoidFriction.from_array(F))
            except (ModelError, ShapeError) as exc:
                raise fault(source, "friction", str(exc)) from exc
    if len(links) != robot.n:
        raise fault(
            source,
            "links",
            f"expected one per link of robot {robot.name!r} ({robot.n}); got {len(links)} links",
        )
    robot = _with_identified_terms(d, robot, source)
    mass = np.empty(robot.n)
    com = np.empty((robot.n, 3))
    I6 = np.empty((robot.n, 6))
    for i, link in enumerate(links):
        name = link.get("name")
        if name is not None and name != robot.link_names[i + 1]:
            raise fault(
                source,
                f"links[{i}].name",
                f"expected {robot.link_names[i + 1]!r} (robot {robot.name!r}); got {name!r}",
            )
        mass[i], com[i], I6[i] = link["mass"], link["com"], link["inertia"]
        _check_link(f"{source}: links[{i}]", mass[i], I6[i])
    try:
        return robot.with_inertials(mass, com, I6)
    except (ModelError, ShapeError) as exc:
        raise DataError(str(exc), file=source) from exc


def _with_identified_terms(d: Mapping[str, Any], robot: Robot, source: str) -> Robot:
    """``robot`` with the friction and the joint springs the checked document ``d`` holds
    identified with its links, each where ``d`` holds it (the robot's own kept else)."""
    try:
        spring = spring_from_record(d.get("spring"))
    except ShapeError as exc:
        raise fault(source, "spring", str(exc)) from exc
    if spring is not None:
        robot = robot.with_spring(spring)
    identified = feasible_linear_friction(d, source)
    return robot if identified is None else robot.with_friction(identified)


def _check_link(where: str, mass: float, I6: NDArray[np.float64]) -> None:
    """Warn, as the URDF reader does, on parameters that are not physically consistent, a
    negative mass included (kept: those of an infeasible result are not consistent)."""
    problems = inertial_problems(mass, matrix_from_inertia6(I6))
    if problems:
        warnings.warn(
            f"{where} is physically inconsistent: {'; '.join(problems)}; kept as given",
            DynidWarning,
            stacklevel=caller_level(),
        )


def load_feasible_json(path: str | Path, robot: Robot | None = None) -> Robot:
    """Read ``feasible.json``: a Robot with the feasible link parameters and the model
    terms identified with them, which :func:`dynid.model_torques` (with the file's drive,
    :func:`load_feasible_drive`, for its rotor inertias) predicts the fit's torques with.

    Its friction is the one identified with the links (:func:`load_feasible_linear_friction`:
    ``linear_friction``, per motor through the file's drive where it acts at the motors,
    plus ``joint_friction`` as a :class:`~dynid.friction.model.FrictionSum`), else the
    sigmoid ``friction`` the file holds; its springs the file's ``spring``. With ``robot``
    None the kinematics stored in the file are used; otherwise the parameters are put on
    ``robot`` (link names must match) with the friction and springs identified with them,
    ``robot``'s own kept where the file holds none identified
    (:func:`robot_from_feasible_dict`). This is what ``dynid validate --params
    feasible.json`` loads.

    Raises
    ------
    DataError
        Not JSON, or not a feasible-parameter file (see :func:`robot_from_feasible_dict`).

    Warns
    -----
    DynidWarning
        The file holds a fit that was not accepted (:func:`fit_rejection` says why): its
        parameters are used as given.
    """
    d = load_json(path)
    out = robot_from_feasible_dict(d, robot, source=Path(path).name)
    rejected = fit_rejection(d)
    if rejected is not None:
        warnings.warn(
            f"{Path(path).name} holds a fit that was not accepted ({rejected}): its "
            "parameters are used as given",
            DynidWarning,
            stacklevel=caller_level(),
        )
    return out


def unknown_scale_caveat(finding: str) -> str:
    """The comment at the top of a robot file whose fit's efforts carry an unknown scale on
    some joints (``finding``: ``unknown_scale.finding`` of ``feasible.json``)."""
    return f"UNKNOWN SCALE: {finding}"


def load_unknown_scale_caveat(path: str | Path) -> str | None:
    """:func:`unknown_scale_caveat` of the file ``path``'s ``unknown_scale``, or None."""
    found = load_document(path, FEASIBLE).get("unknown_scale")
    return None if not found else unknown_scale_caveat(str(found.get("finding", "")))


def armature_left_out(result: FeasibleResult | None) -> tuple[str, ...]:
    """The rotor inertias (``Ia4``) the structure of ``result``'s identified model left
    out while it held others (its rotor-inertia term's ``mask``): the data did not
    determine them, and the fit's drive holds 0 there. Empty when it held every rotor or
    none, or ``result`` carries no identified model (a consistent fit carries it)."""
    model = getattr(result, "identified", None)
    terms = () if model is None else [t.term for t in model.terms.values()]
    for term in terms:
        if isinstance(term, RotorInertia) and any(term.mask) and not all(term.mask):
            labels = term.drive.rotor_labels
            return tuple(lab for lab, held in zip(labels, term.mask, strict=True) if not held)
    return ()


def load_armature_left_out(path: str | Path) -> tuple[str, ...]:
    """:func:`armature_left_out` as the file ``path`` records it (``armature_left_out``;
    empty in a file without it)."""
    return tuple(load_document(path, FEASIBLE).get("armature_left_out") or ())


def armature_left_out_note(
    joint_names: Sequence[str], drive: Drive | None, left_out: Sequence[str]
) -> str | None:
    """The one sentence a robot export says of the rotor inertias ``left_out``
    (:func:`armature_left_out`) of ``drive``: the joints whose armature
    ``diag(K^T diag(I_a) K)`` [kg m^2] is 0 and that a rotor left out turns, named; None
    when there are none (no drive, nothing left out, or every such joint holds another
    rotor's inertia)."""
    if drive is None or not left_out:
        return None
    ia = np.zeros(drive.n) if drive.rotor_inertia is None else np.asarray(drive.rotor_inertia)
    armature = np.diagonal(drive.rotor_mass_matrix(ia))
    gone = [k for k, lab in enumerate(drive.rotor_labels) if lab in left_out]
    K = np.asarray(drive.transmission)
    joints = [j for j in range(len(joint_names)) if armature[j] == 0.0 and K[gone, j].any()]
    if not joints:
        return None
    holds = "that joint holds" if len(joints) == 1 else "those joints hold"
    return (
        f"armature (rotor inertia) 0 at {', '.join(joint_names[j] for j in joints)}: the "
        f"identified structure left {', '.join(drive.rotor_labels[k] for k in gone)} out, "
        f"which the data did not determine, so {holds} the links' inertia alone; the other "
        "joints' armature is the one identified"
    )


def load_feasible_column_map(path: str | Path) -> dict[str, Any] | None:
    """How the data of the fit ``feasible.json`` holds were read: its ``column_map``
    (``columns`` and ``units``, as ``identification.json`` records it), or None."""
    found = load_document(path, FEASIBLE).get("column_map")
    return None if found is None else dict(found)


def load_fit_rejection(path: str | Path) -> str | None:
    """:func:`fit_rejection` of the file ``path``: why its fit was not accepted, or None.

    Raises
    ------
    DataError
        Not JSON, or not a feasible-parameter file.
    """
    return fit_rejection(load_document(path, FEASIBLE))


def feasible_linear_friction(
    d: Mapping[str, Any], source: str = "feasible parameters"
) -> Friction | FrictionSum | None:
    """The friction identified with the links held by a checked ``feasible.json`` document
    ``d`` (the law's coefficients per joint, or per motor, of a consistent
    identification), or None; ``source`` names the file in errors.

    With a drive whose friction acts at the motors, the law per motor mapped through the
    transmission (a :class:`~dynid.friction.model.Friction` with the drive,
    ``tau_f = K^T f(K dq)``); with ``joint_friction`` too, the sum of both
    (:class:`~dynid.friction.model.FrictionSum`).

    Raises
    ------
    DataError
        A law's parameter missing or not one per joint; a malformed drive.
    """
    if d.get("linear_friction") is None:
        return None
    drive = feasible_drive(d, source)
    at = drive if drive is not None and drive.friction_place == "motor" else None
    n = len(d["links"])
    parts = [law_friction(d["linear_friction"], at, n, source, "linear_friction")]
    if d.get("joint_friction") is not None:
        parts.append(law_friction(d["joint_friction"], None, n, source, "joint_friction"))
    return parts[0] if len(parts) == 1 else FrictionSum(tuple(parts))


def load_feasible_linear_friction(path: str | Path) -> Friction | FrictionSum | None:
    """The friction identified with the links held by ``feasible.json``
    (:func:`feasible_linear_friction`), or None: the friction of the robot
    :func:`load_feasible_json` returns, alone.

    Raises
    ------
    DataError
        A law's parameter missing or not one per joint.
    """
    return feasible_linear_friction(load_document(path, FEASIBLE), Path(path).name)


def load_feasible_spring(path: str | Path) -> JointStiffness | None:
    """The joint springs identified with the links held by ``feasible.json``, or None."""
    return spring_from_record(load_document(path, FEASIBLE).get("spring"))


def feasible_drive(d: Mapping[str, Any], source: str = "feasible parameters") -> Drive | None:
    """The drive train held by a checked ``feasible.json`` document ``d`` (its rotor
    inertias the identified ones), or None; ``source`` names the file in errors."""
    if d.get("drive") is None:
        return None
    return drive_from_record(d["drive"], len(d["links"]), source=source, at="drive")


def load_feasible_drive(path: str | Path) -> Drive | None:
    """The drive train held by ``feasible.json`` (its rotor inertias the identified ones), or
    None."""
    return feasible_drive(load_document(path, FEASIBLE), Path(path).name)
