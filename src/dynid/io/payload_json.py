"""payload.json: an identified load, also in libfranka's ``setLoad`` convention.

:func:`payload_to_dict` / :func:`save_payload_json` write::

    {"schema": "dynid-payload/1", "dynid_version": ..., "robot": ..., "frame": "flange",
     "route": "static M and g", "mass": 0.8, "com": [x, y, z],
     "inertia": [xx, xy, xz, yy, yz, zz] | null,
     "std": {"mass": ..., "com": [...], "inertia": [...] | null},
     "load_mass": ..., "F_x_Cload": [...], "load_inertia": [9 numbers, column-major],
     "with_tool": "robot_with_payload.toml", "inertia_identified": true,
     "constraint_active": false, "pseudo_inertia_margin": ..., "rank": 10,
     "condition_number": ..., "residual_rms": ..., "noise_rms": ... | null,
     "judged_residual": {"kind": "difference", "residual_rms": ..., "noise_rms": ...,
                         "states_noise_rms": ... | null, "ratio": ...,
                         "matched": ...} | null,
     "n_rows": ..., "notes": [...], "plausible": true, "doubts": [...],
     "inertia_determined": true, "undetermined_inertia": ["Izz", ...],
     "torque_scale": {"value": ..., "std": ..., "mass": ..., "std_mass": ...,
                      "data": "loaded"} | null,
     "preprocessing": {"cutoff_hz": ..., "cutoff_source": "model", "decimate": ...,
                       "max_gap_s": null} | null,
     "friction_terms": "viscous + coulomb + offset" | null,
     "recordings": [{"file": ..., "pieces": ..., "samples": ..., "duration_s": ...}],
     "units": {...}, "conventions": {...}}

``mass`` [kg]; ``com`` [m] in the given frame; ``inertia`` about the CoM in the frame's axes
[kg m^2]. ``load_mass``, ``F_x_Cload`` (CoM in the flange frame [m]) and ``load_inertia``
(inertia about the CoM in flange axes, 3x3 column-major) are libfranka's
``Robot::setLoad`` arguments: the load carried into the flange frame when the frame is on
the flange's link and its mass and CoM are not in doubt; null otherwise (and
``load_inertia`` null when the inertia was not identified or the data do not determine
it). ``doubts`` says why an estimate is not plausible
(:mod:`dynid.feasibility.payload_doubts`: a mass not significantly above zero, a CoM
farther than the arm is long, torques of another scale than the arm description's
(``torque_scale``), a fit of torque logs whose ``judged_residual`` ratio is above 3 (the
residual over its noise floor: the torque noise and the states' noise through the arm's
model): such a load is not
handed to a controller; inertia elements
not determined, ``undetermined_inertia``: its inertia is not). ``residual_rms`` [N m for
torque logs] is the fit's, ``noise_rms`` [N m] what the torque noise alone leaves after
the low-pass (null for static data). ``judged_residual`` is the residual the load's doubt
was judged on (:mod:`dynid.feasibility.payload_difference`): ``kind`` ``fit`` (the fit's
residual against ``noise_rms`` and ``states_noise_rms``) or ``difference`` (with
``--unloaded`` logs of the same motion: the loaded fit's residual less the unloaded arm's
at matched states, against the noise of both), its RMS, the torque noise and the states'
noise through the arm's model (:mod:`dynid.feasibility.payload_floor`; null: not known)
[N m], their ``ratio`` (each sample weighed against its own noise; a doubt above 3) and
the part of
the loaded samples ``matched`` to the unloaded trajectory [1]; null for static data.
``torque_scale`` is the factor ``value`` [1] (with its ``std``) between the measured
torques and the arm description's (:mod:`dynid.feasibility.payload_scale`), fitted on the
``loaded`` data beside the load or on the data without it (``unloaded``), and the load's
``mass`` [kg] (``std_mass``) if the description is right (the torques divided by the
factor); null with an identified model (its scale was fitted to the same sensors) or a
description without inertial parameters. A factor more than 5 % and 3 standard deviations
from 1 is a doubt; ``judged`` is false when the fit with the factor leaves more than 3 x
its noise floor (``noise_rms`` and the states' noise; the factor then takes torques the
arm's model lacks: neither a doubt nor a load to trust). ``torque_scale_unchecked`` says
why a robot's description was not compared with the torques (its drive's rotor inertias
to be identified), null otherwise. ``constants_checked`` (a drive of motor currents): the
torque constants' error the load's mass and first moments carry, ``finding`` (the note)
and, from an identified arm's record, ``checked`` (the motors, from 1, its data checked
only to ``within_percent`` [%]), ``corrected`` and ``unchecked``; null for torques.
``known_mass`` (``--known-mass``): the load's true ``mass`` [kg] and the ``factor`` [1]
the identified mass reads over it (with its ``std``): the torques' scale; null when not
given.
``preprocessing`` is how torque logs were prepared (cut-off [Hz] and where it came from:
``given``, ``model`` (the identification's) or ``motion``; decimation; longest gap
bridged [s], null for the default rule; ``torque_delay_s``, the torques' lag behind the
positions [s] of an identified arm's identification, when not 0); null for static data.
``friction_terms`` names the friction estimated beside the load from torque logs as
``dynid identify`` names a structure (the classical ``viscous + coulomb + offset``, or the
one chosen on held-out data or given by ``--terms``:
:mod:`dynid.feasibility.payload_friction`); null for static data. Floats use Python's
shortest round-trip representation.
"""

from __future__ import annotations

from pathlib import Path
from typing import Any

import numpy as np

from .. import __version__, spatial
from ..feasibility.payload import PayloadEstimate
from ..feasibility.payload_scale import known_mass_scale, unjudged_ratio
from ..model.inertia import INERTIA_ORDER, inertia6_from_matrix
from ..model.robot import Robot
from ..model.units import unit_said
from .json_files import save_json

__all__ = ["PAYLOAD_SCHEMA", "payload_to_dict", "save_payload_json"]

PAYLOAD_SCHEMA = "dynid-payload/1"


def _num(x: float) -> float | None:
    x = float(x)
    return x if np.isfinite(x) else None


def _list(a: Any) -> list[float | None]:
    return [_num(x) for x in np.asarray(a, dtype=float).reshape(-1)]


def payload_to_dict(
    est: PayloadEstimate,
    robot: Robot,
    *,
    with_tool: str | None = None,
    known_mass: float | None = None,
) -> dict[str, Any]:
    """The payload.json document of an estimate on ``robot`` (module docstring);
    ``known_mass`` [kg]: the load's true mass, given (``known_mass``)."""
    d: dict[str, Any] = {
        "schema": PAYLOAD_SCHEMA,
        "dynid_version": __version__,
        "robot": robot.name,
        "frame": est.frame,
        "route": est.route,
        "mass": _num(est.mass),
        "com": _list(est.com),
        "inertia": _list(inertia6_from_matrix(est.inertia)) if est.inertia_identified else None,
        "std": {
            "mass": _num(est.std_mass),
            "com": _list(est.std_com),
            "inertia": _list(est.std_inertia) if est.inertia_identified else None,
        },
    }
    fl, fr = robot.frame("flange"), robot.frame(est.frame)
    if fl.link == fr.link and not est.doubts:
        T_flange_frame = spatial.inverse_transform(fl.T_link_frame) @ fr.T_link_frame
        R, p = T_flange_frame[:3, :3], T_flange_frame[:3, 3]
        I_fl = R @ est.inertia @ R.T
        d["load_mass"] = _num(est.mass)
        d["F_x_Cload"] = _list(R @ est.com + p)
        d["load_inertia"] = _list(I_fl.T) if est.inertia_determined else None
    else:
        d["load_mass"] = d["F_x_Cload"] = d["load_inertia"] = None
    d.update(
        {
            "with_tool": with_tool,
            "inertia_identified": est.inertia_identified,
            "constraint_active": est.constraint_active,
            "pseudo_inertia_margin": _num(est.margin),
            "rank": int(est.rank),
            "condition_number": _num(est.condition_number),
            "residual_rms": _num(est.residual_rms),
            "noise_rms": None if est.noise_rms is None else _num(est.noise_rms),
            "judged_residual": _judged(est),
            "n_rows": int(est.n_rows),
            "notes": list(est.notes),
            "plausible": est.plausible,
            "doubts": list(est.doubts + est.inertia_doubts),
            "inertia_determined": est.inertia_determined,
            "undetermined_inertia": list(est.undetermined),
            "torque_scale": _scale(est),
            "torque_scale_unchecked": est.scale_unchecked or None,
            "constants_checked": (
                None if est.constants_checked is None else dict(est.constants_checked)
            ),
            "known_mass": _known(est, known_mass),
            "preprocessing": dict(est.preprocessing) or None,
            "friction_terms": est.friction_terms or None,
            "recordings": [dict(r) for r in est.recordings],
            "units": {
                "mass": "kg",
                "com": "m",
                "inertia": "kg m^2",
                "residual_rms": f"{(u := unit_said(robot, 'N m'))} (torque logs); the rows' SI "
                "units (static data)",
                "noise_rms": u,
                "judged_residual": (
                    f"residual_rms, noise_rms, states_noise_rms: {u}; ratio, matched: 1"
                ),
                "torque_scale": "value, std: 1; mass, std_mass: kg",
            },
            "conventions": {
                "com": f"centre of mass in frame {est.frame!r}",
                "inertia": "about the CoM, frame axes, order " + " ".join(INERTIA_ORDER),
                "load_inertia": "libfranka setLoad: about the CoM, flange axes, column-major",
                "F_x_Cload": "libfranka setLoad: CoM in the flange frame",
                "setLoad": "null when the frame is not on the flange's link or the mass or "
                "CoM is in doubt (doubts); load_inertia null too when the inertia is not "
                "identified or not determined (undetermined_inertia)",
            },
        }
    )
    return d


def _judged(est: PayloadEstimate) -> dict[str, Any] | None:
    """``judged_residual`` of the document (module docstring), or None."""
    j = est.judged
    if j is None:
        return None
    return {
        "kind": j.kind,
        "residual_rms": _num(j.residual_rms),
        "noise_rms": None if j.noise_rms is None else _num(j.noise_rms),
        "states_noise_rms": None if j.states_rms is None else _num(j.states_rms),
        "ratio": None if j.ratio is None else _num(j.ratio),
        "matched": _num(j.matched),
    }


def _scale(est: PayloadEstimate) -> dict[str, Any] | None:
    """``torque_scale`` of the document (module docstring), or None."""
    t = est.torque_scale
    if t is None:
        return None
    return {
        "value": _num(t.value),
        "std": _num(t.std),
        "mass": _num(t.mass),
        "std_mass": _num(t.std_mass),
        "data": t.data,
        "judged": unjudged_ratio(t, est.floor_rms) is None,
    }


def _known(est: PayloadEstimate, known: float | None) -> dict[str, Any] | None:
    """``known_mass`` of the document (module docstring), or None."""
    if known is None:
        return None
    a, std = known_mass_scale(est.mass, est.std_mass, known)
    return {"mass": _num(known), "factor": _num(a), "std": _num(std)}


def save_payload_json(
    path: str | Path,
    est: PayloadEstimate,
    robot: Robot,
    *,
    with_tool: str | None = None,
    known_mass: float | None = None,
) -> Path:
    """Write :func:`payload_to_dict` to ``path``; returns the path."""
    return save_json(path, payload_to_dict(est, robot, with_tool=with_tool, known_mass=known_mass))
