"""The files of ``dynid observe``: ``thresholds.json``, ``events.json`` and ``residuals.csv``.

``thresholds.json`` (schema ``dynid-thresholds/1``)::

    {"schema": "dynid-thresholds/1", "dynid_version": ..., "joints": ["joint1", ...],
     "contact": [...], "collision": [...],            # N m per joint
     "rule": {"margin": 1.5, "quantile": 1.0, "collision_factor": 2.0,
              "standstill_margin": true,      # false or absent: fixed levels only
              "rest_margin": {                # absent: the Coulomb level at every rest
                  "level": [...],  # N m per joint, the margin at a settled rest is
                                   # min(Coulomb level, level); null: too few rests
                  "rests": [...],  # rests counted per joint
                  "settle_s": s, "min_rests": k, "min_rest_s": s}},
     "uncertainty": null | {"k_sigma": 3.0, "noise": [...]},
     "observer": {"gain": [...], "discretisation": "exact", "rule": "trapezoid"},
     "calibration": {"samples": N, "data": [file names], "model": ...,
                     "model_files": [...], "model_sha256": "...",  # what the model was
                     "at_rest": [...],    # N m per joint, with the standstill margin
                     "duration_s": T,     # s, the calibration logs' total duration
                     "sample_rate_hz": f, # Hz, the logs' sample rate (absent: not
                                          # recorded; observe warns at another rate)
                     "velocities": "measured" | "derived" | "mixed",  # the logs'
                     "false_alarms": k,   # events on them (null: not counted)
                     "residual_level": x, # the 95th percentile of max_j |r_j| / contact_j
                                          # over them, in shares of the threshold
                     "detectable": [...], # N m per joint, the smallest torque detected
                                          # while the joint moves (the largest contact
                                          # threshold along the motion)
                     "collision_moving": [...],  # N m per joint, the largest collision
                                          # threshold along the motion
                     "peak": [...],       # N m per joint, the largest |r| read
                     "sigma_max": [...],  # N m per joint, the largest sigma (uncertainty)
                     "model_check": {     # the model judged on the logs as validate does
                         "relative_error_percent": e, "noise_floor_percent": f,
                         "verdict": {"level", "label", "reason", "ratio"},
                         "fitted": [k, m]},   # k of the m logs the model's training
                                          # recordings (in-sample)
                     "beyond_identification": [  # absent: none; a log's joint moved
                         {"log", "joint", "speed", "identified"}]},  # > 3 x as fast as
                                          # the identification's data [rad/s]
     "units": {...}}

``events.json`` (schema ``dynid-events/1``): ``events``, a list of ``{"start", "end"}``
[s], ``joints`` (1-based) and ``joint_names`` (the same joints by name), ``peak`` [N m]
(one per joint, signed), ``level`` (``contact``, ``collision``, or ``load``: a carried
load's pick, an external force) and ``log`` (the name of the event's log, one log or
several), with the model's ``joints`` (names), the data
files, their sample counts, durations and the time their events cover (``data``,
``samples``, ``duration_s`` and ``flagged_s`` [s]: lists with one entry per log in
``data``'s order, a one-entry list for one log), the model's files and their SHA-256
(``model_files``, ``model_sha256``) and the units. ``dropped`` (detecting with the event
rules recorded) holds the crossings over the contact threshold that the minimum duration
dropped, which are not events: ``min_duration_s`` and ``merge_s`` [s], ``count`` (all of them) and
``crossings`` (those furthest over the threshold, at most
:data:`~dynid.observer.events.MAX_DROPPED` per log), each ``{"start", "end",
"duration_s"}`` [s], ``joints`` and ``joint_names`` (over the threshold), ``joint`` (the
one furthest over it, 1-based), ``peak`` [N m] and ``ratio`` (``|r| / contact``) per
joint, ``rule`` (``isolated`` or ``short``) and ``log``. ``beyond_identification`` (when
any log moves a joint more than 3 times as fast as the model's identification data) holds
``{"log", "joint", "speed", "identified"}`` [rad/s] per such log and joint.

``residuals.csv``: a dynid CSV table (comment lines, ``# rows: N``, a header) with ``t``
[s], ``r1 .. rn`` [N m] and, with a frame, ``fx, fy, fz`` [N], ``mx, my, mz`` [N m] and
``damped`` (1 near a singular configuration of the joints that move the frame); the
units line says what was estimated there: the wrench, or the force of a point contact
(``--wrench force``: ``mx, my, mz`` written 0). ``events.json`` then says it too
(``wrench``: the frame, the estimate and the components determined), and each event its
``damped_share`` (0 to 1: the share of its samples where the estimate was damped, near a
singular configuration, where the wrench is unreliable) and ``unexplained_share`` (0 to
1, null: no sample: the share of its ``|r|`` the estimate leaves unexplained,
``sqrt(sum |r - J^T w|^2 / sum |r|^2)``; large for a contact on another link than the
frame's). Events of a log with labelled contacts say whether they were counted as a
``false_alarm``; ``score`` lists them per log (``false_alarm_events``, ``{"start",
"end"}`` [s]) with the leads of those that run into a missed contact (``early_ms``).
``trust`` (:mod:`dynid.observer.trust`) says how far to trust the events: ``level``
(good, fair or poor) and its line ``summary``, the residual's level outside the events
and labelled contacts in shares of the contact threshold (``quiet_level``, its 95th
percentile; ``above_half``, the share of that time ``quiet_s`` [s] above half of it), the
calibration's level and false alarms per minute beside it (``calibration_level``,
``calibration_false_alarms_per_min``; null: not recorded), the false alarms counted
against labels and per minute of contact-free time (null: no labels) and the
``reasons`` that lowered it.
"""

from __future__ import annotations

import contextlib
from collections.abc import Callable, Iterator, Sequence
from pathlib import Path
from typing import Any

import numpy as np
from numpy.typing import NDArray

from .. import __version__
from .._checks import text
from ..exceptions import DataError, DynidError
from ..model.units import JointKinds, unit_said, units_said
from ..observer.calibration_check import ModelCheck
from ..observer.carried_load import CarriedLoad, load_words
from ..observer.detection import ContactEvent, Thresholds, undetected_at_rest
from ..observer.residual import ObserverOptions
from ..observer.results import LogObservation, ObserveResult
from ..observer.scoring import ContactScore, MissedContact, labels_lead
from ..observer.thresholds import ModelFingerprint, RestMargin
from ..observer.trust import CalibratedOn
from ..observer.unmodelled_load import LOAD_FRAME
from ..observer.wrench import FULL, WrenchKind, wrench_rank
from .atomic import open_atomic
from .schema import Field, Format, Record, load_document, save_document

__all__ = [
    "DROPPED",
    "EVENTS",
    "EVENTS_SCHEMA",
    "SCORE",
    "ResidualTables",
    "THRESHOLDS",
    "THRESHOLDS_SCHEMA",
    "load_thresholds",
    "log_labels",
    "observation_names",
    "residual_names",
    "residuals_csv",
    "save_events",
    "save_observation",
    "save_residuals_csv",
    "save_thresholds",
]

THRESHOLDS_SCHEMA = "dynid-thresholds/1"
EVENTS_SCHEMA = "dynid-events/1"
_N, _NM = ("n",), "N m"
_NUMBER = Field("number", required=True)
#: ``thresholds.json``'s ``rule.rest_margin``: the standstill margin at settled rests
#: calibrated from the calibration's rests (:class:`~dynid.observer.thresholds.RestMargin`)
_REST_MARGIN = Record(
    {
        "level": Field("numbers", required=True, shape=_N, low=0.0, unit=_NM, null_items=True),
        "rests": Field("numbers", required=True, shape=_N, low=0.0),
        "settle_s": Field("number", required=True, low=0.0, unit="s"),
        "min_rests": Field("integer", required=True),
        "min_rest_s": Field("number", required=True, low=0.0, unit="s"),
    }
)
#: The logs moved beyond the identification's speeds (``beyond_identification`` of
#: ``events.json`` and of ``thresholds.json``'s ``calibration``): one entry per log and joint.
BEYOND_IDENTIFICATION = Field(
    "objects",
    record=Record(
        {
            "log": Field("string", required=True),
            "joint": Field("string", required=True),
            "speed": Field("number", required=True, low=0.0, unit="rad/s"),
            "identified": Field("number", required=True, low=0.0, unit="rad/s"),
        }
    ),
)

#: ``thresholds.json``: every per-joint list of the same length n
THRESHOLDS = Format(
    THRESHOLDS_SCHEMA,
    Record(
        {
            "dynid_version": Field("string"),
            "joints": Field("strings"),
            "contact": Field("numbers", required=True, shape=_N, low=0.0, unit=_NM),
            "collision": Field("numbers", required=True, shape=_N, low=0.0, unit=_NM),
            "rule": Field(
                "object",
                required=True,
                record=Record(
                    {
                        "margin": _NUMBER,
                        "quantile": _NUMBER,
                        "collision_factor": _NUMBER,
                        "standstill_margin": Field("bool"),
                        "rest_margin": Field("object", record=_REST_MARGIN),
                    }
                ),
            ),
            "uncertainty": Field(
                "object",
                nullable=True,
                record=Record(
                    {
                        "k_sigma": _NUMBER,
                        "noise": Field("numbers", required=True, shape=_N, low=0.0, unit=_NM),
                    }
                ),
            ),
            "observer": Field(
                "object",
                required=True,
                record=Record(
                    {
                        "gain": Field("numbers", required=True, shape=_N, unit="1/s"),
                        "discretisation": Field(
                            "string", required=True, choices=("exact", "euler")
                        ),
                        "rule": Field("string", required=True, choices=("rectangle", "trapezoid")),
                    }
                ),
            ),
            "calibration": Field(
                "object",
                record=Record(
                    {
                        "samples": Field("integer", low=0),
                        "sample_rate_hz": Field("number", low=0.0, unit="Hz"),
                        "velocities": Field("string", choices=("measured", "derived", "mixed")),
                        "model_check": Field("object"),
                        "beyond_identification": BEYOND_IDENTIFICATION,
                    },
                    open=True,
                ),
            ),
            "units": Field("any"),
        }
    ),
    "thresholds file (dynid observe --calibrate)",
)

_COUNT = Field("integer", required=True, low=0)
_S = Field("number", required=True, low=0.0, unit="s")
#: A score of detected events against labelled contacts (:mod:`dynid.observer.scoring`).
_SCORE_FIELDS = {
    "source": Field("string", required=True),
    "tolerance_s": _S,
    "lead_s": Field("number", low=0.0, unit="s"),
    "labelled": _COUNT,
    "detected": _COUNT,
    "missed": _COUNT,
    "false_alarms": _COUNT,
    "contact_free_s": _S,
    "false_alarms_per_min": Field("number", nullable=True, low=0.0, unit="1/min"),
    "delay_median_ms": Field("number", nullable=True, unit="ms"),
    "delay_max_ms": Field("number", nullable=True, unit="ms"),
    "delays_look_ahead": Field("bool"),
    "early_ms": Field("numbers", shape=(None,), low=0.0, unit="ms"),
    "labels_lead_ms": Field("number", nullable=True, low=0.0, unit="ms"),
    "missed_contacts": Field(
        "objects",
        required=True,
        record=Record(
            {
                "start": Field("number", required=True, unit="s"),
                "end": Field("number", required=True, unit="s"),
                "peak": Field("number", nullable=True, low=0.0, unit=_NM),
                "reason": Field(
                    "string",
                    choices=("below_at_rest", "below_moving", "dropped_crossing", "unexplained"),
                ),
                "joint": Field("integer", low=1),
                "joint_name": Field("string", nullable=True),
                "torque": Field("number", low=0.0, unit=_NM),
                "threshold": Field("number", low=0.0, unit=_NM),
                "at": Field("number", unit="s"),
                "torque_source": Field("string", choices=("true", "residual")),
            }
        ),
    ),
}
#: ``events.json``'s ``score``: in total, and per log with labels (``logs``).
SCORE = Record(
    {
        **_SCORE_FIELDS,
        "logs": Field(
            "objects",
            required=True,
            record=Record(
                {
                    "log": Field("string", required=True),
                    **_SCORE_FIELDS,
                    "contacts": Field("numbers", required=True, shape=(None, 2), unit="s"),
                    "false_alarm_events": Field(
                        "objects",
                        record=Record(
                            {
                                "start": Field("number", required=True, unit="s"),
                                "end": Field("number", required=True, unit="s"),
                            }
                        ),
                    ),
                }
            ),
        ),
    }
)
_SHARE = Field("number", nullable=True, low=0.0)
#: ``events.json``'s ``trust``: how far to trust the events (:mod:`dynid.observer.trust`).
TRUST = Record(
    {
        "level": Field("string", required=True, choices=("good", "fair", "poor")),
        "summary": Field("string", required=True),
        "quiet_level": _SHARE,
        "above_half": Field("number", nullable=True, low=0.0, high=1.0),
        "quiet_s": _S,
        "calibration_level": _SHARE,
        "calibration_false_alarms_per_min": Field("number", nullable=True, low=0.0, unit="1/min"),
        "false_alarms": Field("integer", nullable=True, low=0),
        "false_alarms_per_min": Field("number", nullable=True, low=0.0, unit="1/min"),
        "reasons": Field("strings"),
    }
)
#: ``events.json``'s ``dropped``: crossings the minimum duration dropped (not events).
DROPPED = Record(
    {
        "min_duration_s": _S,
        "merge_s": _S,
        "count": _COUNT,
        "crossings": Field(
            "objects",
            required=True,
            record=Record(
                {
                    "start": Field("number", required=True, unit="s"),
                    "end": Field("number", required=True, unit="s"),
                    "duration_s": _S,
                    "joints": Field("numbers", required=True, shape=(None,)),
                    "joint_names": Field("strings"),
                    "joint": Field("integer", required=True, low=1),
                    "peak": Field("numbers", required=True, shape=(None,), unit=_NM),
                    "ratio": Field("numbers", required=True, shape=(None,), low=0.0),
                    "rule": Field("string", required=True, choices=("isolated", "short")),
                    "log": Field("string"),
                }
            ),
        ),
    }
)
#: ``events.json``: the events, the crossings dropped and the score declared; the logs
#: (``data``, ``samples``, ``duration_s``, ``flagged_s``) as lists with one entry per log
#: in ``data``'s order, one log or several (a reader indexes or sums them alike); the
#: model's metadata (``model``, ``source``, ...) kept unchecked.
EVENTS = Format(
    EVENTS_SCHEMA,
    Record(
        {
            "dynid_version": Field("string"),
            "joints": Field("strings"),
            "events": Field(
                "objects",
                required=True,
                record=Record(
                    {
                        "start": Field("number", required=True, unit="s"),
                        "end": Field("number", required=True, unit="s"),
                        "joints": Field("numbers", required=True, shape=(None,)),
                        "joint_names": Field("strings"),
                        "peak": Field("numbers", required=True, shape=(None,), unit=_NM),
                        "level": Field(
                            "string", required=True, choices=("contact", "collision", "load")
                        ),
                        "log": Field("string"),
                        "damped_share": Field("number", low=0.0, high=1.0),
                        "unexplained_share": Field("number", nullable=True, low=0.0, high=1.0),
                        "false_alarm": Field("bool"),
                    }
                ),
            ),
            "data": Field("strings"),
            "samples": Field("numbers", shape=(None,), low=0),
            "duration_s": Field("numbers", shape=(None,), low=0.0, unit="s"),
            "flagged_s": Field("numbers", shape=(None,), low=0.0, unit="s"),
            "trust": Field("object", record=TRUST),
            "score": Field("object", record=SCORE),
            "dropped": Field("object", record=DROPPED),
            "beyond_identification": BEYOND_IDENTIFICATION,
            "units": Field("any"),
        },
        open=True,
    ),
    "events file (dynid observe --thresholds)",
)


def save_thresholds(
    path: str | Path,
    thresholds: Thresholds,
    *,
    joints: Sequence[str],
    calibration: dict[str, Any] | None = None,
    robot: JointKinds | None = None,
) -> Path:
    """Write ``thresholds.json`` (module docstring; its units per joint kind of
    ``robot``, :func:`~dynid.model.units.unit_said`); returns the path."""
    th, o = thresholds, thresholds.options
    doc = {
        "dynid_version": __version__,
        "joints": list(joints),
        "contact": th.contact.tolist(),
        "collision": th.collision.tolist(),
        "rule": {
            "margin": th.margin,
            "quantile": th.quantile,
            "collision_factor": th.collision_factor,
            "standstill_margin": th.standstill,
            **({} if th.rest is None else {"rest_margin": _rest_margin(th.rest)}),
        },
        "uncertainty": None
        if not th.uses_uncertainty or th.noise is None
        else {"k_sigma": th.k_sigma, "noise": th.noise.tolist()},
        "observer": {
            "gain": o.gains(th.n).tolist(),
            "discretisation": o.discretisation,
            "rule": o.rule,
        },
        "calibration": {
            "samples": th.samples,
            **({} if th.sample_rate_hz is None else {"sample_rate_hz": th.sample_rate_hz}),
            **({} if th.velocities is None else {"velocities": th.velocities}),
            **_fingerprint(th.model),
            **(calibration or {}),
        },
        "units": units_said(
            robot, {"contact": "N m", "collision": "N m", "noise": "N m", "gain": "1/s"}
        ),
    }
    return save_document(path, THRESHOLDS, doc)


def _rest_margin(rest: RestMargin) -> dict[str, Any]:
    """``rule.rest_margin`` of the thresholds' :class:`RestMargin` (a level not calibrated
    written null)."""
    return {
        "level": [float(v) if np.isfinite(v) else None for v in rest.level],
        "rests": [int(k) for k in rest.rests],
        "settle_s": rest.settle_s,
        "min_rests": rest.min_rests,
        "min_rest_s": rest.min_rest_s,
    }


def _rest_of(rule: dict[str, Any]) -> RestMargin | None:
    """The :class:`RestMargin` of ``rule.rest_margin`` (None: absent, a file of an earlier
    version: the Coulomb level at every rest)."""
    d = rule.get("rest_margin")
    if d is None:
        return None
    return RestMargin(
        level=np.array([np.nan if v is None else v for v in d["level"]], dtype=float),
        rests=np.array(d["rests"], dtype=np.int64),
        settle_s=float(d["settle_s"]),
        min_rests=int(d["min_rests"]),
        min_rest_s=float(d["min_rest_s"]),
    )


def _fingerprint(model: ModelFingerprint | None) -> dict[str, Any]:
    """The keys a model's fingerprint is written as (none without one)."""
    if model is None:
        return {}
    roles = {"model_roles": list(model.roles)} if model.roles else {}
    return {"model_files": list(model.files), "model_sha256": model.sha256, **roles}


def load_thresholds(path: str | Path) -> Thresholds:
    """Read ``thresholds.json``.

    Raises
    ------
    DataError
        Not a thresholds file (schema), an unknown key, a missing or malformed entry (named).
    """
    path = Path(path)
    d = load_document(path, THRESHOLDS)
    rule, obs, unc = d["rule"], d["observer"], d.get("uncertainty")
    cal = d.get("calibration", {})
    rate = cal.get("sample_rate_hz")
    files, sha = cal.get("model_files"), cal.get("model_sha256")
    model = None
    if isinstance(sha, str) and isinstance(files, list):
        roles = cal.get("model_roles")
        ok = isinstance(roles, list) and len(roles) == len(files)
        model = ModelFingerprint(
            tuple(str(f) for f in files), sha, tuple(str(r) for r in roles) if ok else ()
        )
    try:
        return Thresholds(
            contact=np.array(d["contact"], dtype=float),
            collision=np.array(d["collision"], dtype=float),
            margin=float(rule["margin"]),
            quantile=float(rule["quantile"]),
            collision_factor=float(rule["collision_factor"]),
            options=ObserverOptions(
                gain=tuple(float(g) for g in obs["gain"]),
                discretisation=obs["discretisation"],
                rule=obs["rule"],
            ),
            samples=int(d.get("calibration", {}).get("samples", 0)),
            k_sigma=None if unc is None else float(unc["k_sigma"]),
            noise=None if unc is None else np.array(unc["noise"], dtype=float),
            standstill=bool(rule.get("standstill_margin", False)),
            rest=_rest_of(rule),
            model=model,
            sample_rate_hz=None if rate is None else float(rate),
            velocities=cal.get("velocities"),
            detectable=_numbers_or_none(cal.get("detectable"), len(d["contact"])),
            calibrated=_calibrated_on(cal),
        )
    except DynidError as exc:
        raise DataError(str(exc), file=path.name) from None


def _calibrated_on(cal: dict[str, Any]) -> CalibratedOn | None:
    """What the thresholds were calibrated on (``calibration``'s ``data``,
    ``duration_s``, ``false_alarms`` and ``residual_level``); None: a file that records
    no calibration logs."""
    data = cal.get("data")
    if not isinstance(data, list) or not data:
        return None

    def number(key: str) -> float | None:
        v = cal.get(key)
        if not isinstance(v, (int, float)) or isinstance(v, bool) or not np.isfinite(v):
            return None
        return float(v)

    alarms = number("false_alarms")
    return CalibratedOn(
        tuple(str(x) for x in data),
        number("duration_s"),
        None if alarms is None else int(alarms),
        number("residual_level"),
    )


def _numbers_or_none(x: Any, n: int) -> NDArray[np.float64] | None:
    """``x`` as an array of ``n`` finite numbers, else None (absent or not of that
    form: a file of an earlier version)."""
    if not isinstance(x, list) or len(x) != n:
        return None
    if not all(isinstance(v, (int, float)) and not isinstance(v, bool) for v in x):
        return None
    a = np.array(x, dtype=float)
    return a if np.all(np.isfinite(a)) else None


def save_events(
    path: str | Path,
    events: Sequence[ContactEvent],
    *,
    meta: dict[str, Any] | None = None,
    logs: Sequence[str] | None = None,
    joints: Sequence[str] | None = None,
    damped: Sequence[float] | None = None,
    unexplained: Sequence[float] | None = None,
    false_alarm: Sequence[bool | None] | None = None,
    robot: JointKinds | None = None,
) -> Path:
    """Write ``events.json`` (schema ``dynid-events/1``; ``logs``: each event's log name,
    written as its ``log``; ``joints``: the model's joint names, written beside the
    model's and each event's 1-based joints; ``damped``: each event's share of samples
    where the wrench estimate was damped, written as its ``damped_share``;
    ``unexplained``: the share of its residual the estimate leaves, its
    ``unexplained_share`` (NaN written null); ``false_alarm``: whether the score counted
    it a false alarm, None where its log was not scored; ``robot``: the peaks' units per
    joint kind, :func:`~dynid.model.units.unit_said`); returns the path."""
    doc = {
        "dynid_version": __version__,
        **({} if joints is None else {"joints": list(joints)}),
        "events": [
            {
                "start": e.start,
                "end": e.end,
                "joints": list(e.joints),
                **({} if joints is None else {"joint_names": [joints[j - 1] for j in e.joints]}),
                "peak": list(e.peak),
                "level": e.level,
                **({} if logs is None else {"log": logs[k]}),
                **({} if damped is None else {"damped_share": damped[k]}),
                **({} if unexplained is None else {"unexplained_share": _finite(unexplained[k])}),
                **(
                    {}
                    if false_alarm is None or false_alarm[k] is None
                    else {"false_alarm": bool(false_alarm[k])}
                ),
            }
            for k, e in enumerate(events)
        ],
        **(meta or {}),
        "units": {"start": "s", "end": "s", "peak": unit_said(robot, "N m"), "joints": "1-based"}
        | {k: "s" for k in ("duration_s", "flagged_s") if k in (meta or {})}
        | ({"dropped": _dropped_units(robot)} if "dropped" in (meta or {}) else {}),
    }
    return save_document(path, EVENTS, doc)


def _finite(x: float) -> float | None:
    """``x``, None where NaN."""
    return float(x) if np.isfinite(x) else None


def _dropped_units(robot: JointKinds | None) -> str:
    """The units of ``events.json``'s ``dropped`` (its peaks' per joint kind)."""
    peak = unit_said(robot, "N m")
    return f"start, end, duration_s, min_duration_s, merge_s: s; peak: {peak}; ratio: 1"


def save_residuals_csv(
    path: str | Path,
    t: NDArray[np.float64],
    r: NDArray[np.float64],
    *,
    wrench: NDArray[np.float64] | None = None,
    damped: NDArray[np.bool_] | None = None,
    frame: str | None = None,
    kind: WrenchKind = FULL,
    loads: Sequence[CarriedLoad] = (),
    unit: str = "N m",
) -> Path:
    """Write ``residuals.csv``: ``t, r1..rn`` (``r`` in ``unit``; and the wrench at
    ``frame``, or the force alone: ``kind``; the ``loads`` whose torque ``r`` lacks said in
    its header); returns the path."""
    with residuals_csv(
        path,
        t.shape[0],
        r.shape[1],
        frame=frame if wrench is not None else None,
        kind=kind,
        loads=loads,
        unit=unit,
    ) as put:
        put(t, r, wrench, damped)
    return Path(path)


@contextlib.contextmanager
def residuals_csv(
    path: str | Path,
    rows: int,
    n: int,
    *,
    frame: str | None = None,
    kind: WrenchKind = FULL,
    loads: Sequence[CarriedLoad] = (),
    unit: str = "N m",
) -> Iterator[Callable[..., None]]:
    """``residuals.csv`` written a block of rows at a time: yields ``put(t, r, wrench=None,
    damped=None)`` for consecutive blocks ``t`` (m,), ``r`` (m, n) and, with ``frame``,
    the wrench (m, 6) and its flag (m,), its units line saying what was estimated
    (``kind``) and the carried loads whose torque the residual lacks
    (:func:`load_header`), the residual in ``unit`` (:func:`~dynid.model.units.unit_said`:
    ``N m (rail: N)`` on an arm with a prismatic joint); the file (``rows`` in its header)
    appears when the block ends normally (atomic), the bytes of :func:`save_residuals_csv`
    of the whole."""
    names = ["t"] + [f"r{j + 1}" for j in range(n)]
    units = f"t [s], r [{unit}]"
    if frame is not None:
        names += ["fx", "fy", "fz", "mx", "my", "mz", "damped"]
        units += f"; {_estimate_units(frame, kind)}"
    with open_atomic(Path(path), "w") as fh:
        if loads:  # on the first line: readers skip three lines before the data
            units += "; " + load_header(loads)
        fh.write(f"# dynid residuals; units: {units}\n# rows: {rows}\n")
        fh.write(",".join(names) + "\n")

        def put(
            t: NDArray[np.float64],
            r: NDArray[np.float64],
            wrench: NDArray[np.float64] | None = None,
            damped: NDArray[np.bool_] | None = None,
        ) -> None:
            parts = [t[:, None], r]
            if frame is not None:
                assert wrench is not None
                flag = np.zeros(t.shape[0]) if damped is None else damped.astype(float)
                parts += [wrench, flag[:, None]]
            table = np.concatenate(parts, axis=1)
            for a in range(0, table.shape[0], _CSV_ROWS):
                np.savetxt(fh, table[a : a + _CSV_ROWS], delimiter=",", fmt="%.17g")

        yield put


def load_header(loads: Sequence[CarriedLoad]) -> str:
    """The words of ``residuals.csv``'s first line on the carried loads whose torque the
    residual lacks: ``r less the torque of loads carried at the flange (through the
    observer's lag): 1.222 kg from 2.998 s to 4.504 s (event 3.004 s .. 4.536 s)``, their
    pick and release [s] (``through the whole log`` for a load held throughout)."""
    each = [
        f"{ld.mass:.4g} kg "
        + (
            "through the whole log"
            if ld.whole
            else f"from {ld.picked:.3f} s to {ld.released:.3f} s"
        )
        + f" (event {ld.start:.3f} s .. {ld.end:.3f} s)"
        for ld in loads
    ]
    return (
        f"r less the torque of loads carried at the {LOAD_FRAME} (through the observer's "
        f"lag): {', '.join(each)}"
    )


#: Rows of ``residuals.csv`` formatted at a time.
_CSV_ROWS = 100_000


def _estimate_units(frame: str, kind: WrenchKind) -> str:
    """The units line's words on the wrench columns at ``frame``: what was estimated."""
    moment = "m [N m]" if kind.rows == 6 else "m [N m] written 0"
    return (
        f"{kind.what} at {frame}'s origin (--wrench {kind.name}): f [N], {moment}, base "
        f"axes (least-norm where fewer than {kind.rows} joints move the frame); damped: 1 "
        "near a singular configuration of those joints"
    )


class ResidualTables:
    """The residual tables of ``dynid observe`` in the folder ``out``, each written a block
    at a time while the log is observed (:func:`dynid.workflows.observe.observe_files`'s
    ``sink``): ``residuals.csv`` for one log, ``residuals_<name>.csv`` for several
    (:func:`residual_names`). ``written`` lists the files in order."""

    def __init__(self, out: str | Path) -> None:
        self.out = Path(out)
        self.written: list[Path] = []

    @contextlib.contextmanager
    def table(
        self,
        paths: Sequence[str | Path],
        index: int,
        rows: int,
        n: int,
        frame: str | None,
        kind: WrenchKind = FULL,
        loads: Sequence[CarriedLoad] = (),
        unit: str = "N m",
    ) -> Iterator[Callable[..., None]]:
        """The writer of log ``index`` of ``paths`` (:func:`residuals_csv`; ``loads``:
        those whose torque the residual lacks; ``unit``: the residual's)."""
        path = self.out / f"{residual_names(paths)[index]}.csv"
        with residuals_csv(path, rows, n, frame=frame, kind=kind, loads=loads, unit=unit) as put:
            yield put
        if path not in self.written:
            self.written.append(path)


def log_labels(paths: Sequence[str | Path]) -> list[str]:
    """How each log is named to the user: its file name, or, for logs of one file name in
    different folders, the shortest end of its path that tells them apart
    (``a/free.csv``, ``b/free.csv``)."""
    parts = [Path(p).parts for p in paths]
    out = []
    for k, mine in enumerate(parts):
        depth = 1
        while depth < len(mine) and any(
            o[-depth:] == mine[-depth:] for i, o in enumerate(parts) if i != k
        ):
            depth += 1
        out.append(text("/".join(mine[-depth:])))
    return out


def observation_names(logs: Sequence[LogObservation]) -> list[str]:
    """The name stem of each log's files (:func:`residual_names` of their paths)."""
    return residual_names([x.path for x in logs])


def residual_names(paths: Sequence[str | Path]) -> list[str]:
    """The name stem of the files of the logs ``paths``: ``residuals`` for one log,
    ``residuals_<stem>`` for several, the stem of :func:`log_labels` (``residuals_a_free``
    for ``a/free.csv`` beside ``b/free.csv``; numbered where two still agree)."""
    if len(paths) == 1:
        return ["residuals"]
    out: list[str] = []
    for label in log_labels(paths):
        name = "residuals_" + str(Path(label).with_suffix("")).replace("/", "_")
        k, base = 2, name
        while name in out:
            name, k = f"{base}_{k}", k + 1
        out.append(name)
    return out


def save_observation(
    out: str | Path,
    result: ObserveResult,
    *,
    joints: Sequence[str],
    calibrating: bool,
    meta: dict[str, Any] | None = None,
    residuals: bool = True,
) -> list[Path]:
    """The files of ``dynid observe`` in the folder ``out``; returns them.

    Calibrating: ``thresholds.json``, its calibration with ``at_rest`` where the standstill
    margin raises a joint's threshold at rest
    (:func:`~dynid.observer.detection.undetected_at_rest`). Detecting: ``events.json``
    (every log's events, each with its log's name and its joints' names) and, with
    ``residuals``, a residual table per log from its series (:func:`observation_names`;
    False: written while observing, :class:`ResidualTables`).
    """
    out = Path(out)
    meta = dict(meta or {})
    if calibrating:
        cal = {"data": log_labels([x.path for x in result.logs]), **meta}
        check = result.check
        moving = None if check is None else check.detectable
        rest = undetected_at_rest(result.model, result.thresholds, moving)
        level = result.thresholds.contact if moving is None else moving
        if result.thresholds.standstill and np.any(rest > level):
            cal["at_rest"] = rest.tolist()  # the thresholds of a joint standing still
        if (check := result.check) is not None:  # is the observer good enough
            cal |= {
                "duration_s": check.duration_s,
                "false_alarms": check.false_alarms,
                "detectable": check.detectable.tolist(),
                "peak": check.peak.tolist(),
                **({} if check.level is None else {"residual_level": check.level}),
            }
            if check.collision is not None:
                cal["collision_moving"] = check.collision.tolist()
            if check.sigma_max is not None:
                cal["sigma_max"] = check.sigma_max.tolist()
            if check.model is not None:  # the model behind the thresholds
                cal["model_check"] = _model_check_info(check.model)
        cal |= _beyond_info(result, cal["data"])
        return [
            save_thresholds(
                out / "thresholds.json",
                result.thresholds,
                joints=joints,
                calibration=cal,
                robot=result.model.robot,
            )
        ]
    paths = []
    events: list[ContactEvent] = []
    logs_of: list[str] = []
    for x, name in zip(result.logs, observation_names(result.logs), strict=True):
        if not residuals:
            break
        w = x.wrench
        paths.append(
            save_residuals_csv(
                out / f"{name}.csv",
                x.t,
                x.series,
                wrench=None if w is None else w.wrench,
                damped=None if w is None else w.damped,
                frame=None if w is None else w.frame,
                kind=FULL if w is None else w.kind,
                loads=x.loads,
                unit=unit_said(result.model.robot, "N m"),
            )  # fmt: skip
        )
    labels = log_labels([x.path for x in result.logs])
    shares: list[float] | None = None if result.frame is None else []
    left: list[float] | None = None if result.frame is None else []
    false: list[bool | None] = []
    for x, label in zip(result.logs, labels, strict=True):
        events += x.events
        logs_of += [label] * len(x.events)
        if shares is not None:
            shares += x.damped if x.damped is not None else [0.0] * len(x.events)
        if left is not None:
            left += x.unexplained if x.unexplained is not None else [np.nan] * len(x.events)
        sc = x.score
        false += [None if sc is None else k in sc.false_events for k in range(len(x.events))]
    info = {
        "data": labels,
        "samples": [int(x.t.shape[0]) for x in result.logs],
        "duration_s": [x.duration() for x in result.logs],
        "flagged_s": [x.flagged_seconds() for x in result.logs],
        **_fingerprint(result.fingerprint),
        **({} if result.frame is None else {"wrench": _estimate_info(result)}),
        **({} if (trust := result.trust()) is None else {"trust": trust.as_dict()}),
        **({} if (total := result.score()) is None else {"score": _score_info(result, total)}),
        **({} if result.min_duration_s is None else {"dropped": _dropped_info(result, joints)}),
        **_loads_info(result, labels),
        **_beyond_info(result, labels),
        **meta,
    }
    paths.insert(
        0,
        save_events(
            out / "events.json",
            events,
            meta=info,
            logs=logs_of,
            joints=joints,
            damped=shares,
            unexplained=left,
            false_alarm=None if all(f is None for f in false) else false,
            robot=result.model.robot,
        ),
    )
    return paths


def _model_check_info(m: ModelCheck) -> dict[str, Any]:
    """``calibration.model_check``: the model behind the thresholds judged on the
    calibration logs as validate judges it, and how many of them it was fitted on."""
    v = m.verdict
    return {
        "relative_error_percent": m.error_percent,
        "noise_floor_percent": m.floor_percent,
        "verdict": {"level": v.level, "label": v.label, "reason": v.reason, "ratio": v.ratio},
        "fitted": list(m.fitted),
    }


def _loads_info(result: ObserveResult, labels: Sequence[str]) -> dict[str, Any]:
    """``loads``: the loads carried at the flange over an event of each log (its event
    kept with the level ``load``; :mod:`~dynid.observer.carried_load`), each with its log
    and its line; nothing when none."""
    out = [
        {**ld.as_dict(), "log": label, "summary": load_words(ld)}
        for label, x in zip(labels, result.logs, strict=True)
        for ld in x.loads
    ]
    return {"loads": out} if out else {}


def _beyond_info(result: ObserveResult, labels: Sequence[str]) -> dict[str, Any]:
    """``beyond_identification``: each log and joint moved more than
    :data:`~dynid.identification.motion_range.BEYOND` times as fast as in the model's
    identification data, with both speeds [rad/s] (:meth:`ObserveResult.beyond`);
    nothing when none."""
    by_log = {id(x): label for x, label in zip(result.logs, labels, strict=True)}
    names = result.model.robot.joint_names
    out = [
        {"log": by_log[id(x)], "joint": names[j], "speed": here, "identified": ident}
        for x, joints in result.beyond()
        for j, here, ident in joints
    ]
    return {"beyond_identification": out} if out else {}


def _dropped_info(result: ObserveResult, joints: Sequence[str]) -> dict[str, Any]:
    """``events.json``'s ``dropped`` (:data:`DROPPED`): the crossings every log's minimum
    duration dropped, named by their log and joints."""
    labels = log_labels([x.path for x in result.logs])
    crossings = [
        {
            "start": d.start,
            "end": d.end,
            "duration_s": d.duration,
            "joints": list(d.joints),
            "joint_names": [joints[j - 1] for j in d.joints],
            "joint": d.joint,
            "peak": list(d.peak),
            "ratio": list(d.ratio),
            "rule": d.rule,
            "log": label,
        }
        for x, label in zip(result.logs, labels, strict=True)
        for d in x.dropped
    ]
    return {
        "min_duration_s": result.min_duration_s,
        "merge_s": result.merge_s,
        "count": result.dropped_count(),
        "crossings": crossings,
    }


def _score_record(sc: ContactScore, names: Sequence[str]) -> dict[str, Any]:
    """One score as ``events.json`` writes it (:data:`SCORE`), ``names`` the joints'."""
    return {
        "source": sc.source,
        "tolerance_s": sc.tolerance_s,
        "lead_s": sc.lead_s,
        "labelled": sc.labelled,
        "detected": sc.detected,
        "missed": len(sc.missed),
        "false_alarms": sc.false_alarms,
        "contact_free_s": sc.contact_free_s,
        "false_alarms_per_min": sc.false_alarms_per_min,
        "delay_median_ms": None if sc.delay_median is None else 1e3 * sc.delay_median,
        "delay_max_ms": None if sc.delay_max is None else 1e3 * sc.delay_max,
        "delays_look_ahead": sc.look_ahead,
        "early_ms": [1e3 * d for d in sc.early],
        "labels_lead_ms": None if (lead := labels_lead(sc)) is None else 1e3 * lead[1],
        "missed_contacts": [_missed_record(m, names) for m in sc.missed],
    }


def _missed_record(m: MissedContact, names: Sequence[str]) -> dict[str, Any]:
    """One missed contact as ``events.json`` writes it: its times [s], its largest true
    torque ``peak`` [N m], and where read (:mod:`~dynid.observer.missed_reason`) the
    ``reason``, the ``joint`` (1-based) and ``joint_name``, its ``torque`` and the
    ``threshold`` in force it was compared with [N m] at the time ``at`` [s], and
    ``torque_source`` (``true`` or ``residual``)."""
    out: dict[str, Any] = {"start": m.start, "end": m.end, "peak": m.peak}
    if m.reason is not None and m.joint is not None:
        out.update(
            reason=m.reason,
            joint=m.joint + 1,
            joint_name=names[m.joint] if m.joint < len(names) else None,
            torque=m.torque,
            threshold=m.threshold,
            **({} if m.at is None else {"at": m.at}),
            torque_source="true" if m.true_torque else "residual",
        )
    return out


def _score_info(result: ObserveResult, total: ContactScore) -> dict[str, Any]:
    """``events.json``'s ``score``: the events against the labelled contacts in total and
    per log with labels (``logs``: the log's name, its score and its labelled
    ``contacts``, ``[start, end]`` [s])."""
    labels = log_labels([x.path for x in result.logs])
    names = result.model.robot.joint_names
    per = [
        {
            "log": lab,
            **_score_record(x.score, names),
            "contacts": [list(c) for c in x.score.intervals],
            "false_alarm_events": [
                {"start": x.events[k].start, "end": x.events[k].end} for k in x.score.false_events
            ],
        }
        for x, lab in zip(result.logs, labels, strict=True)
        if x.score is not None
    ]
    return {**_score_record(total, names), "logs": per}


def _estimate_info(result: ObserveResult) -> dict[str, Any]:
    """``events.json``'s ``wrench``: what was estimated at the frame (``full`` or
    ``force``), its components and those the joints moving the frame determine."""
    assert result.frame is not None
    robot, frame, kind = result.model.robot, result.frame, result.wrench
    return {
        "frame": frame,
        "estimate": kind.name,
        "components": kind.rows,
        "determined": wrench_rank(robot, frame, kind),
    }
