"""An identified model to and from JSON, with the kinematics it is valid for.

Layout of the file (top-level keys)::

    schema, dynid_version, route, seed,
    rank, condition_number, relative_error_percent, residual_rms, sigma, n_rows, rtol,
    scaled_condition_number, dropped_rows, pruned, std_estimator,
    coefficients: [{"name", "expression", "value", "std", "std_percent", "kept",
        ["description", "z"]}, ...],
    covariance: (r x r) covariance of the values, or null,
    covariance_with_terms: with appended terms, the (c x c) covariance of the values and
        the appended terms' coefficients in order (the columns of the model's regressor),
        or null; older files have none,
    base: {"std_labels", "independent", "dependent", "K_d", "rank", "rtol", "gap"},
    terms: the model terms beside the links, in the order stacked (:mod:`dynid.regressors.
        terms`): [{"name", "kind" (a key of TERM_KINDS), "definition" (the term's own
        record), "labels", "values", "std", "kept"}, ...]; older files have none (their
        friction and rotor inertias are read into terms),
    friction: null or the parameters (n, k) of the one friction term's law (metadata
        friction_law, default classical: fv N m s/rad, fc N m, fo N m; per motor with a
        drive whose friction acts at the motors); null with two friction terms (a copy of
        terms for readers of the friction alone),
    drive: null or the drive train (dynid-drive/1: side, effort, transmission rows, offset,
        torque_constant, rotor_inertia "identify" or values, friction_at); with identified
        rotor inertias base.std_labels continue with Ia1 .. Ia_n after the links' 10 n,
    robot: the kinematics (:mod:`dynid.io.robot_json`),
    vs_description: where the description holds link inertials, the identified base
        parameters against its own (:mod:`dynid.identification.vs_description`): source,
        rms_z, n_compared, threshold, beyond [{"name", "z"}], said; each coefficient
        then holds its ``description`` value and ``z`` (null where not compared),
    metadata: the identification's record (IdentificationInfo, flat): route, reference,
        n_rows, dropped_rows, pruned, max_std_percent, std_estimator, estimator, rtol,
        rank_gap, identifiability, [seed], static: n_configurations,
        rows_per_configuration, data; classical: cutoff_hz, trim_s, decimate,
        sample_rate_hz, n_samples_log, n_samples_used, duration_s, n_nan_rows,
        n_duplicates, n_gaps, friction_labels, friction_std, friction_kept (the appended
        terms' coefficients, as in terms), [friction_band, friction_law] (with one friction
        term), [heldout];
        [column_map], [notes], drive; unknown keys are kept,
    units, conventions

``condition_number`` is that of the unscaled regressor (the figure Gaz et al. report),
``scaled_condition_number`` that of the column-scaled one; ``base.gap`` the singular
values either side of the rank cut (relative to the largest; optional on reading, as is
``scaled_condition_number``). ``rank`` is the rank of the fit (the kept coefficients; all
of them without pruning), ``base.rank`` the number of base parameters. ``value`` is the
identified base parameter ``beta_k`` in SI units (the unit of its expression: kg, kg m or
kg m^2); ``std`` its standard deviation, ``std_percent`` ``100 std / |value|`` (``null``
when undefined: removed coefficients); ``kept`` is false for coefficients removed by
pruning (their value is 0). ``expression`` writes the coefficient in the standard
parameters (``m<i>`` kg, ``mc<i>x`` kg m, ``J<i>xx`` kg m^2 about the link origin, link
axes).

Floats are written with Python's shortest round-trip representation, so
:func:`load_model_json` rebuilds a model whose predictions are bit-identical.
"""

from __future__ import annotations

from collections.abc import Mapping
from dataclasses import fields
from pathlib import Path
from typing import Any

import numpy as np
from numpy.typing import NDArray

from .. import __version__, _checks
from ..friction.laws import LAWS
from ..identification.info import IdentificationInfo, LogInfo, StaticInfo
from ..identification.least_squares import LeastSquaresFit
from ..identification.model import IdentifiedModel, IdentifiedTerm
from ..identification.vs_description import description_comparison
from ..model.drive import Drive
from ..model.units import units_said
from ..regressors.base import BaseParameters
from .drive_file import drive_from_record
from .json_files import finite_or_none, load_json
from .model_terms import (
    FRICTION_LAWS,
    TERM_RECORD,
    friction_metadata,
    older_terms,
    terms_from_list,
    terms_to_list,
)
from .robot_json import ROBOT_RECORD, robot_from_dict, robot_to_dict
from .schema import Field, Format, Record, check, fault, save_document

__all__ = [
    "MODEL",
    "MODEL_SCHEMA",
    "info_from_dict",
    "info_to_dict",
    "load_model_json",
    "model_from_dict",
    "model_to_dict",
    "save_model_json",
]

MODEL_SCHEMA = "dynid-identified-model/1"

_FIT_SCALARS = (
    "rank",
    "condition_number",
    "relative_error_percent",
    "residual_rms",
    "sigma",
    "n_rows",
    "rtol",
    "scaled_condition_number",
)


def _jsonable(x: Any) -> Any:
    if isinstance(x, Mapping):
        return {str(k): _jsonable(v) for k, v in x.items()}
    if isinstance(x, (list, tuple)):
        return [_jsonable(v) for v in x]
    if isinstance(x, np.ndarray):
        return _jsonable(x.tolist())
    if isinstance(x, (bool, np.bool_)):
        return bool(x)
    if isinstance(x, (int, np.integer)):
        return int(x)
    if isinstance(x, (float, np.floating)):
        return finite_or_none(x)
    if x is None or isinstance(x, str):
        return x
    return str(x)


def model_to_dict(model: IdentifiedModel, *, seed: int | None = None) -> dict[str, Any]:
    """The JSON-ready dictionary of an identified model (layout in the module docstring).

    ``seed`` defaults to ``model.info.seed`` or the data set's recorded seed.
    """
    fit, base, info = model.fit, model.base, model.info
    if seed is None:
        seed = info.seed if info.seed is not None else dict(info.data).get("seed")
    coefficients = [
        {
            "name": base.labels[k],
            "expression": base.expressions[k],
            "value": float(fit.beta[k]),
            "std": float(fit.std[k]),
            "std_percent": finite_or_none(fit.std_percent[k]),
            "kept": bool(fit.kept[k]),
        }
        for k in range(base.rank)
    ]
    vs = description_comparison(model)
    if vs is not None:  # the description's own base parameters, and the distance in stds
        for c, d, z in zip(coefficients, vs.values, vs.z, strict=True):
            c["description"], c["z"] = finite_or_none(d), finite_or_none(z)
    out: dict[str, Any] = {
        "schema": MODEL_SCHEMA,
        "dynid_version": __version__,
        "route": info.route,
        "seed": seed,
    }
    out.update({k: _jsonable(getattr(fit, k)) for k in _FIT_SCALARS})
    out["dropped_rows"] = list(info.dropped_rows)
    out["pruned"] = list(info.pruned)
    out["std_estimator"] = info.std
    out["coefficients"] = coefficients
    out["covariance"] = None if fit.covariance is None else np.asarray(fit.covariance).tolist()
    full = model.coefficient_covariance() if model.appended else None
    out["covariance_with_terms"] = None if full is None else full.tolist()
    out["base"] = {
        "std_labels": list(base.std_labels),
        "independent": base.independent.tolist(),
        "dependent": base.dependent.tolist(),
        "K_d": base.K_d.tolist(),
        "rank": base.rank,
        "rtol": base.rtol,
        "gap": None if base.gap is None else list(base.gap),
    }
    out["terms"] = terms_to_list(model)
    frictions = model.frictions
    out["friction"] = frictions[0].params.tolist() if len(frictions) == 1 else None
    out["drive"] = None if model.drive is None else model.drive.as_dict()
    out["robot"] = robot_to_dict(model.description, inertials=True)
    if vs is not None:
        out["vs_description"] = _jsonable(vs.as_dict())
    out["metadata"] = info_to_dict(info, model.drive) | friction_metadata(model)
    law = LAWS[frictions[0].law if len(frictions) == 1 else "classical"]
    units = {
        "value": "SI of each expression: m kg, mc kg m, J kg m^2",
        "std": "as value",
        "std_percent": "%",
        "description": "as value",
        "z": "standard deviations (std)",
        "relative_error_percent": "%",
        "residual_rms": "N m, kg m^2 for M rows" if info.route == "static" else "N m",
        "sigma": "as residual_rms",
        "friction": ", ".join(f"{p} {u}" for p, u in zip(law.params, law.units, strict=True)),
    }
    out["units"] = units_said(model.description, units, ("residual_rms", "friction"))
    out["conventions"] = {
        "standard_parameters": "per link m, mcx, mcy, mcz, Jxx, Jxy, Jxz, Jyy, Jyz, Jzz; J about "
        "the link origin, link axes",
        "beta": "beta = phi_b + K_d phi_d (base.independent, base.dependent)",
        "reference": "Gaz et al. 2019, IEEE RA-L 4(4):4147-4154",
    }
    return out


#: Keys of the ``metadata`` object read into typed fields (others are kept in ``extra``).
_LOG_KEYS = tuple(f.name for f in fields(LogInfo))
#: Keys older files wrote that the model already holds elsewhere (fit, drive): not kept.
_DERIVED_KEYS = (
    "drive",
    "condition_number",
    "scaled_condition_number",
    "relative_error_percent",
)


def info_to_dict(info: IdentificationInfo, drive: Drive | None = None) -> dict[str, Any]:
    """The ``metadata`` object of ``identification.json``: the keys of earlier files, flat.

    ``drive`` is written under ``"drive"`` as before (the top-level ``drive`` is the one
    read back).
    """
    out: dict[str, Any] = dict(info.extra)
    out.update(
        {
            "route": info.route,
            "reference": info.reference,
            "n_rows": info.n_rows,
            "dropped_rows": list(info.dropped_rows),
            "pruned": list(info.pruned),
            "max_std_percent": info.max_std_percent,
            "std_estimator": info.std,
            "estimator": info.estimator,
            "rtol": info.rtol,
            "rank_gap": None if info.rank_gap is None else list(info.rank_gap),
            "identifiability": dict(info.identifiability),
        }
    )
    if info.seed is not None:
        out["seed"] = info.seed
    if info.static is not None:
        out["n_configurations"] = info.static.n_configurations
        out["rows_per_configuration"] = info.static.rows_per_configuration
    if info.route == "static" or info.data:
        out["data"] = dict(info.data)
    if info.log is not None:
        out.update({k: getattr(info.log, k) for k in _LOG_KEYS})
    if info.heldout is not None:
        out["heldout"] = dict(info.heldout)
    if info.column_map is not None:
        out["column_map"] = dict(info.column_map)
    if info.notes:
        out["notes"] = list(info.notes)
    if info.selection is not None:
        out["selection"] = dict(info.selection)
    if info.estimator_choice is not None:
        out["estimator_choice"] = dict(info.estimator_choice)
    if info.recordings:
        out["recordings"] = [dict(r) for r in info.recordings]
    if info.combined:
        out["combined"] = dict(info.combined)
    if drive is not None:
        out["drive"] = drive.as_dict()
    return _jsonable(out)


def info_from_dict(
    meta: Mapping[str, Any], *, source: str = "identified model"
) -> IdentificationInfo:
    """The :class:`IdentificationInfo` of a file's ``metadata`` object (any version).

    Raises
    ------
    DataError
        A known entry of the wrong type or value (named).
    """
    check(meta, _META, source, at="metadata")
    m = dict(meta)
    route, std = m.pop("route", None), m.pop("std_estimator", None)
    try:
        static, log = _route_parts(m)
        gap = m.pop("rank_gap", None)
        seed = m.pop("seed", None)
        return IdentificationInfo(
            route=route,
            reference=str(m.pop("reference", "")),
            n_rows=int(m.pop("n_rows", 0)),
            dropped_rows=tuple(str(x) for x in m.pop("dropped_rows", ())),
            pruned=tuple(str(x) for x in m.pop("pruned", ())),
            max_std_percent=_opt_float(m.pop("max_std_percent", None)),
            std=std,
            estimator=str(m.pop("estimator", "ols")),
            rtol=_opt_float(m.pop("rtol", None)),
            rank_gap=None if gap is None else (float(gap[0]), float(gap[1])),
            identifiability={str(k): str(v) for k, v in dict(m.pop("identifiability", {})).items()},
            seed=None if seed is None else int(seed),
            data=dict(m.pop("data", {})),
            static=static,
            log=log,
            heldout=None if m.get("heldout") is None else dict(m.pop("heldout")),
            column_map=None if m.get("column_map") is None else dict(m.pop("column_map")),
            notes=tuple(str(x) for x in m.pop("notes", ())),
            selection=None if m.get("selection") is None else dict(m.pop("selection")),
            estimator_choice=(
                None if m.get("estimator_choice") is None else dict(m.pop("estimator_choice"))
            ),
            recordings=tuple(dict(r) for r in m.pop("recordings", ())),
            combined={str(k): str(v) for k, v in dict(m.pop("combined", {})).items()},
            extra={k: v for k, v in m.items() if k not in _DERIVED_KEYS + _FRICTION_KEYS},
        )
    except (TypeError, ValueError, IndexError) as exc:
        raise fault(source, "metadata", f"malformed ({exc})") from exc


#: The keys of ``metadata`` that describe the appended terms (read with the terms).
_FRICTION_KEYS = (
    "friction_labels",
    "friction_std",
    "friction_kept",
    "friction_band",
    "friction_law",
)


def _route_parts(m: dict[str, Any]) -> tuple[StaticInfo | None, LogInfo | None]:
    """The static and log parts of a ``metadata`` object (their keys removed)."""
    static = log = None
    if "n_configurations" in m:
        n_conf = int(m.pop("n_configurations"))
        static = StaticInfo(n_conf, int(m.pop("rows_per_configuration", 0)))
    if "decimate" in m:
        vals = {k: m.pop(k) for k in _LOG_KEYS if k in m}
        if vals.get("speed_max") is not None:
            vals["speed_max"] = tuple(float(x) for x in vals["speed_max"])
        for key in ("position_range", "velocity_range"):
            if vals.get(key) is not None:
                vals[key] = tuple((float(a), float(b)) for a, b in vals[key])
        log = LogInfo(**vals)
    return static, log


def _opt_float(x: Any) -> float | None:
    return None if x is None else float(x)


def _covariance(c: Any, r: int, source: str) -> NDArray[np.float64] | None:
    """The (r, r) covariance of a file, or None when the file has none (older files)."""
    if c is None:
        return None
    a = np.asarray(c, dtype=np.float64)
    if a.shape != (r, r):
        raise fault(
            source, "covariance", f"expected an {r} x {r} matrix (base.rank); got {a.shape}"
        )
    return _frozen(0.5 * (a + a.T))


def _covariance_with_terms(
    c: Any, r: int, terms: Mapping[str, IdentifiedTerm], source: str
) -> NDArray[np.float64] | None:
    """The (c, c) covariance of the base parameters and the appended ``terms``'
    coefficients of a file, or None when it has none (older files, no appended term)."""
    if c is None:
        return None
    width = r + sum(len(t.labels) for t in terms.values() if not t.term.in_base)
    a = np.asarray(c, dtype=np.float64)
    if a.shape != (width, width):
        want = f"an {width} x {width} matrix (base.rank and the appended terms' coefficients)"
        raise fault(source, "covariance_with_terms", f"expected {want}; got {a.shape}")
    return _frozen(0.5 * (a + a.T))


_NUMBER = Field("number", required=True, nullable=True)
_COEFFICIENT = Record(
    {
        "name": Field("string", required=True),
        "expression": Field("string", required=True),
        "value": Field("number", required=True),
        "std": Field("number", required=True, low=0.0),
        "std_percent": Field("number", required=True, nullable=True, unit="%"),
        "kept": Field("bool", required=True),
        "description": Field("number", nullable=True),
        "z": Field("number", nullable=True, unit="std"),
    }
)
#: ``vs_description``: the identified base parameters against the description's
_VS_DESCRIPTION = Record(
    {
        "source": Field("string", required=True),
        "rms_z": Field("number", required=True, nullable=True, low=0.0),
        "n_compared": Field("integer", required=True, low=0),
        "threshold": Field("number", required=True, low=0.0),
        "beyond": Field(
            "objects",
            required=True,
            record=Record({"name": Field("string", required=True), "z": _NUMBER}),
        ),
        "said": Field("string", required=True),
    }
)
_BASE = Record(
    {
        "std_labels": Field("strings", required=True),
        "independent": Field("any", required=True),  # indices: checked by _base_indices
        "dependent": Field("any", required=True),
        "K_d": Field("numbers", required=True, shape=(None, None)),
        "rank": Field("integer", required=True, low=0),
        "rtol": Field("number", required=True),
        "gap": Field("numbers", nullable=True, shape=(2,)),
    }
)
#: the typed keys of ``metadata`` (others are kept as they are)
_META = Record(
    {
        "route": Field("string", nullable=True, choices=("static", "classical")),
        "std_estimator": Field("string", nullable=True, choices=("classical", "robust", "hac")),
        "friction_law": Field("string", choices=tuple(FRICTION_LAWS)),
        "friction_std": Field("numbers", null_items=True),
        "friction_band": Field("numbers", null_items=True),
        "friction_kept": Field("bools"),
        "rank_gap": Field("numbers", nullable=True, shape=(2,)),
        "speed_max": Field("numbers", nullable=True, shape=(None,), low=0),
        "position_range": Field("numbers", nullable=True, shape=(None, 2)),
        "velocity_range": Field("numbers", nullable=True, shape=(None, 2)),
    },
    open=True,
)
#: ``identification.json`` (module docstring; n joints)
MODEL = Format(
    MODEL_SCHEMA,
    Record(
        {
            "robot": Field("object", required=True, record=ROBOT_RECORD),
            "dynid_version": Field("string"),
            "route": Field("string", nullable=True),
            "seed": Field("any"),
            "rank": Field("integer", required=True, low=0),
            "condition_number": _NUMBER,
            "relative_error_percent": _NUMBER,
            "residual_rms": _NUMBER,
            "sigma": _NUMBER,
            "n_rows": Field("integer", required=True, low=0),
            "rtol": _NUMBER,
            "scaled_condition_number": Field("number", nullable=True),
            "dropped_rows": Field("any"),
            "pruned": Field("any"),
            "std_estimator": Field("any"),
            "coefficients": Field("objects", required=True, record=_COEFFICIENT),
            "covariance": Field("numbers", nullable=True, shape=(None, None)),
            "covariance_with_terms": Field("numbers", nullable=True, shape=(None, None)),
            "base": Field("object", required=True, record=_BASE),
            "terms": Field("objects", record=TERM_RECORD),
            "friction": Field("numbers", nullable=True, shape=("n", None)),
            "drive": Field("object", nullable=True),
            "metadata": Field("object", nullable=True, record=_META),
            "vs_description": Field("object", nullable=True, record=_VS_DESCRIPTION),
            "units": Field("any"),
            "conventions": Field("any"),
        }
    ),
    "identified model (dynid identify)",
)


def model_from_dict(d: Mapping[str, Any], *, source: str = "identified model") -> IdentifiedModel:
    """Rebuild an :class:`IdentifiedModel` from :func:`model_to_dict` output.

    ``source``: the file named in messages.

    Raises
    ------
    DataError
        Wrong schema, an unknown key (at the top or in a coefficient; the metadata keep
        theirs), or a field missing, of the wrong type or inconsistent (the key named,
        :mod:`dynid.io.schema`).
    """
    if not isinstance(d, Mapping) or d.get("schema") != MODEL_SCHEMA:
        got = _checks.short(d.get("schema")) if isinstance(d, Mapping) else "no object"
        raise fault(source, "schema", f"expected {MODEL_SCHEMA!r} ({MODEL.what}); got {got}")
    check(d, MODEL.top, source)
    robot = robot_from_dict(d["robot"], source=source, at="robot")
    b, coefs = d["base"], d["coefficients"]
    r = b["rank"]
    if len(coefs) != r:
        want = f"one per base parameter ({r}, base.rank)"
        raise fault(source, "coefficients", f"expected {want}; got {len(coefs)}")
    drive = d.get("drive")
    if drive is not None:
        drive = drive_from_record(drive, robot.n, source=source, at="drive")
    metadata = d.get("metadata") or {}
    if d.get("terms") is not None:
        terms = terms_from_list(d["terms"], drive, robot.n, source)
        p = 10 * robot.n + sum(len(t.labels) for t in terms.values() if t.term.in_base)
    else:
        terms = older_terms(d.get("friction"), metadata, drive, robot.n, source)
        p = 10 * robot.n + (robot.n if drive is not None and drive.identifies_rotor_inertia else 0)
    independent, dependent, K_d = _base_indices(b, r, p, source)
    if len(b["std_labels"]) != p:
        rotor = " with the rotor inertias" if p > 10 * robot.n else ""
        want = f"{p} labels (the robot's {robot.n} joints{rotor})"
        raise fault(source, "base.std_labels", f"expected {want}; got {len(b['std_labels'])}")
    base = BaseParameters(
        std_labels=tuple(b["std_labels"]),
        independent=_frozen(independent),
        dependent=_frozen(dependent),
        K_d=_frozen(K_d),
        rank=r,
        rtol=float(b["rtol"]),
        labels=tuple(c["name"] for c in coefs),
        expressions=tuple(c["expression"] for c in coefs),
        gap=None if b.get("gap") is None else (float(b["gap"][0]), float(b["gap"][1])),
    )
    kept = np.array([c["kept"] for c in coefs], dtype=bool)
    pct = [c["std_percent"] if c["std_percent"] is not None else (np.inf if c["kept"] else np.nan)
           for c in coefs]  # fmt: skip
    fit = LeastSquaresFit(
        beta=_frozen(np.array([c["value"] for c in coefs], dtype=float)),
        std=_frozen(np.array([c["std"] for c in coefs], dtype=float)),
        std_percent=_frozen(np.array(pct, dtype=float)),
        kept=_frozen(kept),
        rank=d["rank"],
        condition_number=_float(d["condition_number"]),
        relative_error_percent=_float(d["relative_error_percent"]),
        residual_rms=_float(d["residual_rms"]),
        sigma=_float(d["sigma"]),
        n_rows=d["n_rows"],
        rtol=_float(d["rtol"]),
        covariance=_covariance(d.get("covariance"), r, source),
        scaled_condition_number=_float(d.get("scaled_condition_number")),
    )
    info = info_from_dict(metadata, source=source)
    kept = d["robot"].get("phi")  # the description's inertials: the default prior
    description = None if kept is None else np.array(kept, dtype=float).reshape(robot.n, 10)
    return IdentifiedModel(
        robot=robot,
        base=base,
        fit=fit,
        terms=terms,
        info=info,
        drive=drive,
        description_phi=description,
        recorded_covariance=_covariance_with_terms(
            d.get("covariance_with_terms"), r, terms, source
        ),
    )


def save_model_json(path: str | Path, model: IdentifiedModel, *, seed: int | None = None) -> Path:
    """Write an identified model as strict JSON (indented, UTF-8, atomic); returns the path.

    Raises
    ------
    NonFiniteError
        A NaN or infinite number (named).
    """
    return save_document(path, MODEL, model_to_dict(model, seed=seed))


def load_model_json(path: str | Path) -> IdentifiedModel:
    """Read an identified model written by :func:`save_model_json`.

    Raises
    ------
    DataError
        Not JSON, or not an identified model (see :func:`model_from_dict`).
    """
    path = Path(path)
    d = load_json(path, schema=MODEL_SCHEMA, what=MODEL.what)
    return model_from_dict(d, source=path.name)


def _base_indices(
    b: Mapping[str, Any], r: int, p: int, source: str
) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """``independent`` (r,), ``dependent`` (p - r,) and ``K_d`` (r, p - r), checked: integer
    indices of the p standard parameters, each exactly once, K_d of that shape."""
    ind, dep = b["independent"], b["dependent"]
    want = f"an index in 0..{p - 1} (the robot has {p} standard parameters)"
    for name, v in (("base.independent", ind), ("base.dependent", dep)):
        if not isinstance(v, list):
            raise fault(source, name, f"expected a list of indices; got {_checks.short(v)}")
        for k, x in enumerate(v):
            if isinstance(x, bool) or not isinstance(x, int) or not 0 <= x < p:
                raise fault(source, f"{name}[{k}]", f"expected {want}; got {_checks.short(x)}")
    if len(ind) != r:
        raise fault(source, "base.independent", f"expected {r} indices (base.rank); got {len(ind)}")
    if sorted(ind + dep) != list(range(p)):
        want = f"with base.dependent each of the {p} parameter indices exactly once"
        raise fault(source, "base.independent", f"expected {want}; got {_checks.short(ind)}")
    K_d = np.asarray(b["K_d"], dtype=np.float64)
    if K_d.size == 0 and len(dep) == 0:
        K_d = K_d.reshape(r, 0)
    if K_d.shape != (r, len(dep)):
        raise fault(source, "base.K_d", f"expected shape {(r, len(dep))}; got {K_d.shape}")
    return np.asarray(ind, dtype=np.intp), np.asarray(dep, dtype=np.intp), K_d


def _float(x: Any) -> float:
    """A checked number; ``null`` as NaN (a value the fit has none of)."""
    return float("nan") if x is None else float(x)


def _frozen(a: np.ndarray) -> np.ndarray:
    return _checks.frozen(a)
