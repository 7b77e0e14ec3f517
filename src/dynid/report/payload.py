"""The answer of ``payload``: the load's mass, centre of mass and inertia, how well each is
known, and whether the fit explains the torques to their noise.

The headline covers all three: the mass with its relative standard deviation, the CoM
with its largest standard deviation, the inertia with its largest one, or the elements
the data do not determine (``undetermined_inertia`` of ``payload.json``). The level:

* not a load to trust (poor): a doubt about the mass or the CoM (no setLoad values), a
  residual above :data:`~dynid.identification.verdict.FLOOR_FAIR` times its noise floor
  (the torque noise left after the low-pass and the states' noise through the arm's
  model, ``judged_residual``'s ratio) among them (effects outside the arm's model, which
  the mass and CoM take too: :func:`~dynid.feasibility.payload_doubts.misfit_doubts`), or with
  ``--unloaded`` logs of the same motion the residual judged (``judged_residual``: the
  loaded fit's less the unloaded arm's at matched states) above that times the noise of
  both;
* usable, with reservations (fair), each reason listed: inertia elements not determined,
  a mass known to 5 % or worse, the physical-consistency constraint active (the
  least-squares estimate was not a body), motor currents read through torque constants
  that nothing checked or the identification checked only to a tolerance
  (``constants_checked``: the mass and CoM carry their error, which the std leaves out);
* good otherwise.

The residual is given in N m beside that noise (``noise_rms``) for torque logs, and the
measured torques' scale against the arm description's (``torque_scale``) when known.
"""

from __future__ import annotations

from typing import Any

from ..identification.verdict import FLOOR_FAIR, FLOOR_GOOD
from .html import capitalised, cell, esc, is_number, number, section, table, verdict
from .run import Answer, RunFiles

__all__ = ["MASS_SURE", "payload_answer"]

#: Relative standard deviation of the mass below which it is known.
MASS_SURE = 0.05


def payload_answer(run: RunFiles) -> Answer | None:
    """payload's verdict (module docstring) and its parameters with their standard
    deviations, or None without payload.json."""
    doc = run.doc("payload.json")
    if doc is None or not is_number(doc.get("mass")):
        return None
    std: dict[str, Any] = doc["std"] if isinstance(doc.get("std"), dict) else {}
    m, sm = doc["mass"], std.get("mass")
    rel = abs(sm / m) if is_number(sm) and m else None
    frame = esc(doc.get("frame", ""))
    undetermined = [str(x) for x in doc.get("undetermined_inertia") or []]
    doubts = [str(x) for x in doc.get("doubts") or []]
    # the inertia is judged only when the mass and CoM are not in doubt (its one line
    # last), and is not determined when the fit leaves the torques above the noise
    ratio = _judged_ratio(doc)
    misfit = ratio is not None and ratio > FLOOR_FAIR
    load_doubts = doubts if misfit or not undetermined else []
    facts = [
        f"Mass <b>{number(m)} kg</b>"
        + (f" &plusmn; {number(sm, 2)} kg (1 std)" if is_number(sm) else "")
        + f", centre of mass {cell(doc.get('com'))} m in {frame}",
        _residual_fact(doc),
        f"Physically consistent: pseudo-inertia margin {cell(doc.get('pseudo_inertia_margin'))}"
        + (
            "; the constraint is active (the unconstrained fit was not a body)"
            if doc.get("constraint_active")
            else ""
        ),
        f"From {esc(doc.get('route', ''))}: rank {cell(doc.get('rank'))}, condition number "
        f"{cell(doc.get('condition_number'))}",
    ]
    scale = _scale_fact(doc)
    if scale:
        facts.append(scale)
    if doc.get("inertia_identified") is False:
        facts.append("Inertia not identified from these data (mass and CoM only)")
    head = _headline(doc, std, rel, undetermined)
    if load_doubts:
        facts = [esc(capitalised(d)) for d in load_doubts] + facts
        label = "not a load to trust"
        return Answer(verdict("poor", esc(head), facts, label), (_section(doc, std, frame),))
    reasons = _reservations(doc, rel, undetermined)
    if reasons:
        facts = ["Reservations: " + esc("; ".join(reasons)) + "."] + facts
    level = "fair" if reasons else "good"
    return Answer(verdict(level, esc(head), facts), (_section(doc, std, frame),))


def _noise_ratio(doc: dict[str, Any]) -> float | None:
    """The fit's residual over its noise floor (the torque noise after the low-pass, and
    the states' noise through the arm's model when ``judged_residual`` holds it), when
    known."""
    if (states := _states_noise(doc)) is not None:
        return float(states["ratio"])
    r, n = doc.get("residual_rms"), doc.get("noise_rms")
    return r / n if is_number(r) and is_number(n) and n > 0 else None


def _states_noise(doc: dict[str, Any]) -> dict[str, Any] | None:
    """``judged_residual`` of the fit when it holds the states' noise through the arm's
    model (``states_noise_rms``) and its ratio, else None."""
    j = doc.get("judged_residual")
    if not isinstance(j, dict) or j.get("kind") != "fit" or not is_number(j.get("ratio")):
        return None
    return j if is_number(j.get("states_noise_rms")) else None


def _judged(doc: dict[str, Any]) -> dict[str, Any] | None:
    """``judged_residual`` when it is the difference from the unloaded arm's, else None."""
    j = doc.get("judged_residual")
    ok = isinstance(j, dict) and j.get("kind") == "difference" and is_number(j.get("ratio"))
    return j if ok else None


def _judged_ratio(doc: dict[str, Any]) -> float | None:
    """The ratio the load's doubt was judged on: the difference's, else the fit's."""
    j = _judged(doc)
    return float(j["ratio"]) if j is not None else _noise_ratio(doc)


def _residual_fact(doc: dict[str, Any]) -> str:
    """The residual RMS in N m beside the torque noise (torque logs), or in the rows' units."""
    r = doc.get("residual_rms")
    ratio = _noise_ratio(doc)
    if ratio is not None:
        said = "at the noise floor" if ratio <= FLOOR_GOOD else "close to it"
        if ratio > FLOOR_FAIR:
            said = "effects outside the arm's model remain"
        noise = f"torque noise after the low-pass ({number(doc['noise_rms'], 2)} N m)"
        if (states := _states_noise(doc)) is not None:
            noise += (
                " and the states' noise through the arm's model "
                f"({number(states['states_noise_rms'], 2)} N m)"
            )
        fact = (
            f"Residual RMS {number(doc['residual_rms'], 2)} N m, {number(ratio, 3)} x the "
            f"{noise}: {said}"
        )
        if (j := _judged(doc)) is not None:
            common = j["ratio"] <= FLOOR_FAIR
            fact += (
                f"; judged on the difference from the unloaded arm's residual at matched "
                f"states: {number(j['ratio'], 3)} x the noise of both recordings ("
                + (
                    "the arm's misfit is common to both, not the load's)"
                    if common
                    else "the load does not explain what changed between them)"
                )
            )
        return fact
    static_m = str(doc.get("route", "")).startswith("static M")
    unit = " (rows of M [kg m^2] and g [N m])" if static_m else " N m"
    return f"Residual RMS {cell(r)}{esc(unit)}"


def _scale_fact(doc: dict[str, Any]) -> str | None:
    """The measured torques against the arm description's (``torque_scale``), or None."""
    t = doc.get("torque_scale")
    if not isinstance(t, dict) or not is_number(t.get("value")):
        return None
    where = "the data without the load" if t.get("data") == "unloaded" else "the loaded data"
    unjudged = (
        f"; not judged: the fit with the factor leaves more than {FLOOR_FAIR:g} x the torque "
        "noise, the "
        "factor takes torques the arm's model lacks"
        if t.get("judged") is False
        else ""
    )
    return (
        f"Measured torques {number(t['value'], 4)} x the arm description's (std "
        f"{cell(t.get('std'))}, on {where}){esc(unjudged)}"
    )


def _headline(
    doc: dict[str, Any], std: dict[str, Any], rel: float | None, undetermined: list[str]
) -> str:
    """``The payload weighs 1.2 kg (known to 0.12 %), its centre of mass is known to 0.1 mm
    and its inertia to 0.00066 kg m^2.`` (the largest standard deviations; or which of the
    inertia's elements are not determined)."""
    m = doc["mass"]
    parts = [
        f"The payload weighs {number(m)} kg"
        + (f" ({_known_words(doc)} {100 * rel:.2g} %)" if rel else "")
    ]
    sc = std.get("com")
    if isinstance(sc, list) and sc and all(is_number(x) for x in sc):
        parts.append(f"its centre of mass is known to {1000 * max(sc):.2g} mm")
    si = std.get("inertia")
    if doc.get("inertia_identified") is False:
        parts.append("its inertia is not identified")
    elif undetermined:
        parts.append(f"its inertia is not determined ({', '.join(undetermined)})")
    elif isinstance(si, list) and si and all(is_number(x) for x in si):
        parts.append(f"its inertia to {number(max(si), 2)} kg m^2")
    return ", ".join(parts[:-1]) + (" and " if len(parts) > 1 else "") + parts[-1] + "."


def _known_words(doc: dict[str, Any]) -> str:
    """``known to`` before the mass's relative std, or, where the mass carries torque
    constants nothing checked (:func:`_constants_reservation`), ``its std alone, the torque
    constants' error aside,``: the std is not what the mass is known to there."""
    if _constants_reservation(doc) is None:
        return "known to"
    return "its std alone, the torque constants' error aside:"


def _reservations(doc: dict[str, Any], rel: float | None, undetermined: list[str]) -> list[str]:
    """Why the estimate is usable with reservations (module docstring); empty: good."""
    out = []
    if undetermined:
        out.append(
            f"the data do not determine the inertia's {', '.join(undetermined)} "
            "(setLoad's inertia not written)"
        )
    if rel is None or rel >= MASS_SURE:
        out.append(
            "the mass is known to " + (f"{100 * rel:.2g} %" if rel is not None else "no std")
        )
    ratio = _noise_ratio(doc)
    if ratio is not None and ratio > FLOOR_FAIR and _judged(doc) is not None:
        out.append(
            f"the fit leaves {number(ratio, 3)} x the torque noise: the arm's model misses "
            "torques in both recordings, which cancel in their difference"
        )
    elif ratio is not None and ratio > FLOOR_FAIR:  # a file written without its doubt
        out.append(
            f"the fit leaves {number(ratio, 3)} x the torque noise: the arm's model misses "
            "torques the load's parameters may absorb"
        )
    if doc.get("constraint_active"):
        out.append("the least-squares estimate was not a physical body (the constraint moved it)")
    constants = _constants_reservation(doc)
    if constants:
        out.append(constants)
    return out


def _plain(v: Any) -> str:
    """A value for a sentence the verdict escapes as a whole: a number as text, else its
    string (never a table cell's HTML)."""
    return number(v) if is_number(v) else str(v)


def _constants_reservation(doc: dict[str, Any]) -> str | None:
    """The torque constants' error the mass and CoM carry (``constants_checked``: motor
    currents read through constants the identification's data checked only to a tolerance
    or not at all, or that nothing here checked), or None: torques, or constants checked
    (a known mass given, or the torques' scale judged against the description)."""
    c = doc.get("constants_checked")
    if not isinstance(c, dict):
        return None
    known = doc.get("known_mass")
    if isinstance(known, dict) and is_number(known.get("factor")) and is_number(known.get("std")):
        f, sf = known["factor"], known["std"]
        if abs(f - 1.0) <= 3 * sf:
            return None
        return (
            f"the mass reads {number(f, 4)} x the known {_plain(known.get('mass'))} kg: the "
            "torque constants are off by about that factor, which the mass and centre of "
            "mass carry"
        )
    loose, unchecked = c.get("checked") or [], c.get("unchecked") or []
    if loose or unchecked:
        said = []
        if loose:
            said.append(f"only to {_plain(c.get('within_percent'))} % on motor(s) {_ids(loose)}")
        if unchecked:
            said.append(f"not at all on motor(s) {_ids(unchecked)}")
        return (
            "the mass and centre of mass carry the torque constants' error, which the "
            f"identification's data checked {' and '.join(said)} (a known mass checks it)"
        )
    t = doc.get("torque_scale")
    if isinstance(t, dict) and t.get("judged") is not False:
        a, sa = t.get("value"), t.get("std")
        if is_number(a) and is_number(sa) and abs(a - 1.0) > 3 * sa:
            return (
                f"the torques read {number(a, 4)} x the arm description's, {100 * abs(a - 1):.2g} "
                "% off 1 and clear of it: the mass carries about that factor"
            )
        return None
    return (
        "the mass and centre of mass carry the drive's torque constants' error, which nothing "
        "here checked (a known mass checks it)"
    )


def _ids(ks: list[Any]) -> str:
    """``1, 2, 4``."""
    return ", ".join(str(k) for k in ks)


def _section(doc: dict[str, Any], std: dict[str, Any], frame: str) -> str:
    """The table of the load's parameters with their standard deviations."""
    rows = []
    for key, unit in (("mass", "kg"), ("com", "m"), ("inertia", "kg m^2")):
        rows.append([esc(key), cell(doc.get(key)), cell(std.get(key)), esc(unit)])
    body = table(["quantity", "value", "std", "unit"], rows)
    note = f"<p>CoM in {frame}; inertia about the CoM, order xx xy xz yy yz zz.</p>"
    return section("payload", "Payload", note, body)
