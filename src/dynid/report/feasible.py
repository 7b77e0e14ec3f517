"""The answer of a consistent fit or retrieval (``retrieve``, ``identify --consistent``):
are the link parameters physically consistent, how close to the coefficients, how far from
the prior.

The verdict: consistent or not, the residual on the coefficients, the smallest margin of
the constraints, the total mass against its band, the bounds the result sits on, the links
found implausible (either of the last two: not good, usable with reservations), what the
coefficients hold (link base parameters and rotor inertias). Below it: per link the mass
with its bounds, the prior's mass and the difference, the centre of mass with its box, the
pseudo-inertia margin and whether the data or the prior give the mass; per motor the rotor
inertia and whether the data or the prior give it; the constraints that are not satisfied;
the figures (``retrieval.png``, ``comparison.png``).
"""

from __future__ import annotations

from typing import Any

from .html import capitalised, cell, esc, figure, is_number, number, section, table, verdict
from .identify import used_structure
from .run import Answer, RunFiles

__all__ = ["answer"]

#: Relative residual on the coefficients below which the consistent set reproduces them.
RESIDUAL_GOOD = 0.05


def _at(v: Any, k: int) -> Any:
    return v[k] if isinstance(v, list) and k < len(v) else None


def answer(run: RunFiles) -> Answer | None:
    """The verdict and link table of feasible.json (with report.json), or None."""
    feas, rep = run.doc("feasible.json"), run.doc("report.json") or {}
    if feas is None or not isinstance(feas.get("links"), list):
        return None
    ok = bool(feas.get("feasible"))
    res = feas.get("relative_residual")
    facts = [
        f"Physically consistent: <b>{'yes' if ok else 'no'}</b> (method {esc(feas.get('method'))}"
        + (
            f", solver {esc(rep['solver'])} {esc(rep.get('status', ''))}"
            if rep.get("solver")
            else ""
        )
        + ")",
        f"Relative residual on the coefficients <b>{cell(res)}</b> (reproduces them below "
        f"{RESIDUAL_GOOD:g})",
    ]
    margins: dict[str, Any] = rep["min_margin"] if isinstance(rep.get("min_margin"), dict) else {}
    constraints = [c for c in rep.get("constraints") or [] if isinstance(c, dict)]
    failed = [c for c in constraints if c.get("satisfied") is False]
    if constraints:
        facts.append(
            f"Constraints: {len(constraints) - len(failed)} of {len(constraints)} satisfied"
            + (
                f"; smallest pseudo-inertia margin (lambda_min(J) / tr(J)) "
                f"{cell(margins['pseudo_inertia'])}"
                if is_number(margins.get("pseudo_inertia"))
                else ""
            )
        )
    masses = [link.get("mass") for link in feas["links"] if is_number(link.get("mass"))]
    band = rep.get("total_mass")
    facts.append(
        f"Total mass {number(sum(masses))} kg"
        + (f" (band {cell(band)} kg)" if isinstance(band, list) else "")
    )
    facts += _structure_fact(run, feas)
    facts += _coefficients_fact(rep.get("determined"))
    for note in rep.get("on_bound") or []:
        facts.append("On a bound: " + esc(note))
    held = rep.get("heldout")
    if isinstance(held, dict):
        facts.append(
            "Held-out: " + cell({k: v for k, v in held.items() if not isinstance(v, (list, dict))})
        )
    implausible = [
        n for n in rep.get("notes") or [] if isinstance(n, str) and n.startswith("implausible")
    ]
    facts += [esc(capitalised(n)) for n in implausible]
    good = ok and is_number(res) and res < RESIDUAL_GOOD
    plain = good and not rep.get("on_bound") and not implausible
    level = "poor" if not ok else "good" if plain else "fair"
    head = (
        "The link parameters are physically consistent"
        + (" and reproduce the identified coefficients" if good else "")
        + ("; some links are implausible." if implausible else ".")
        if ok
        else "No physically consistent set satisfies the constraints: the closest one is shown."
    )
    figs = [
        (run.png(f), c)
        for f, c in (("retrieval.png", "Retrieved links"), ("comparison.png", "Methods compared"))
    ]
    shown = frozenset(r for r, _ in figs if r is not None)
    fig_html = "".join(figure(r, run.files[r], c) for r, c in figs if r is not None)
    sections = (
        _links_table(feas, rep),
        _rotors_table(rep.get("determined")),
        _violations(rep),
        f'<div class="figures">{fig_html}</div>' if fig_html else "",
    )
    return Answer(verdict(level, head, facts), sections, shown)


def _structure_fact(run: RunFiles, feas: dict) -> list[str]:
    """The one-step fit of a torque log: the structure it used (the identified model's,
    as the identify part of the page names it) and the friction identified with the links
    (its law and where it acts, as ``feasible.json`` holds it)."""
    used = used_structure(run.docs.get("identification.json"))
    laws = [
        (feas[k], "the joints" if k == "joint_friction" else _where(feas))
        for k in ("linear_friction", "joint_friction")
        if isinstance(feas.get(k), dict)
    ]
    if used is None and not laws:
        return []
    friction = " + ".join(f"{esc(rec.get('model'))} law at {w}" for rec, w in laws) or "none"
    said = f"friction identified with the links: {friction}"
    if used is None:
        return [capitalised(said)]
    return [f"Structure of the consistent fit: <b>{esc(used)}</b>; {said}"]


#: What a parameter's source (``report.json``'s ``determined``) says on the page.
_SOURCE = {
    "data": "the data",
    "sum": "the prior (the data give it only in a sum with link inertias)",
    "prior": "the prior (the data do not excite it)",
}

#: The same for a link's mass.
_MASS_SOURCE = _SOURCE | {
    "sum": "the data in sums with other link parameters, split by the prior",
}


def _mass_from(det: Any, k: int) -> str:
    """Where link ``k``'s mass (from 0) comes from: its source, a poorly excited one the
    prior sets named so, and the prior's share in the value when it was computed."""
    if not isinstance(det, dict):
        return "?"
    lab = f"m{k + 1}"
    src = (det.get("source") or {}).get(lab, "")
    shares = det.get("prior_share")
    share = shares.get(lab) if isinstance(shares, dict) else None
    text = _MASS_SOURCE.get(src, "?")
    if src == "data" and lab in (det.get("set_by_prior") or ()):
        text = "the prior (the data excite it too little)"
    if is_number(share):
        text += f"; the prior's share {100 * share:.0f} %"
    return text


def _coefficients_fact(det: Any) -> list[str]:
    """``Coefficients: 43 link base parameters + 5 rotor inertias (armatures)``, the rotors
    the prior gives named."""
    if not isinstance(det, dict) or not is_number(det.get("link_base_parameters")):
        return []
    text = f"Coefficients: <b>{cell(det['link_base_parameters'])}</b> link base parameters"
    src = det.get("rotor_source")
    if isinstance(src, list):
        text += f" + <b>{cell(det.get('rotor_inertias'))}</b> rotor inertias (armatures)"
        prior = [str(m + 1) for m, s in enumerate(src) if s in ("sum", "prior")]
        if prior:
            text += f"; rotor inertia(s) of motor(s) {', '.join(prior)} taken from the prior"
    return [text]


def _rotors_table(det: Any) -> str:
    """Per motor the rotor inertia retrieved and where its value comes from."""
    if not isinstance(det, dict) or not isinstance(det.get("rotor_source"), list):
        return ""
    ia = det.get("rotor_inertia")
    rows = [
        [
            cell(m + 1),
            cell(_at(ia, m)),
            esc(_SOURCE.get(s, "not in the model") if s else "not in the model"),
        ]
        for m, s in enumerate(det["rotor_source"])
    ]
    return section(
        "rotors",
        "Rotor inertias (armatures)",
        table(["motor", "rotor inertia [kg m^2]", "value from"], rows),
    )


def _where(feas: dict) -> str:
    drive = feas.get("drive")
    at = drive.get("friction_at") if isinstance(drive, dict) else None
    return "the motors" if at == "motor" else "the joints"


def _links_table(feas: dict, rep: dict) -> str:
    bounds = {
        b.get("name"): b
        for b in (rep.get("bounds") or {}).get("links") or []
        if isinstance(b, dict)
    }
    prior = (rep.get("prior") or {}).get("mass") if isinstance(rep.get("prior"), dict) else None
    margin = rep.get("pseudo_inertia_margin")
    det = rep.get("determined")
    source = det.get("source") if isinstance(det, dict) else None
    rows = []
    for k, link in enumerate(feas["links"]):
        b = bounds.get(link.get("name"), {})
        m, pm = link.get("mass"), _at(prior, k)
        box = (
            "; ".join(
                f"{number(lo, 3)}..{number(hi, 3)}"
                for lo, hi in zip(b["com_min"], b["com_max"], strict=False)
            )
            if isinstance(b.get("com_min"), list) and isinstance(b.get("com_max"), list)
            else None
        )
        inertia = link.get("inertia")
        diag = (
            [inertia[0], inertia[3], inertia[5]]
            if isinstance(inertia, list) and len(inertia) == 6
            else None
        )
        rows.append(
            [
                esc(link.get("name", k + 1)),
                cell(m),
                cell(b.get("mass")),
                cell(pm),
                cell(m - pm if is_number(m) and is_number(pm) else None),
                cell(link.get("com")),
                esc(box) if box else cell(None),
                cell(diag),
                cell(_at(margin, k)),
            ]
            + ([esc(_mass_from(det, k))] if isinstance(source, dict) else [])
        )
    headers = [
        "link",
        "mass [kg]",
        "mass bounds [kg]",
        "prior mass [kg]",
        "mass - prior [kg]",
        "centre of mass x, y, z [m]",
        "CoM box x; y; z [m]",
        "inertia xx, yy, zz about the CoM [kg m^2]",
        "pseudo-inertia margin",
    ] + (["mass from"] if isinstance(source, dict) else [])
    return section("links", "Physical parameters per link", table(headers, rows))


def _violations(rep: dict) -> str:
    bad = [
        c
        for c in rep.get("constraints") or []
        if isinstance(c, dict) and c.get("satisfied") is False
    ]
    if not bad:
        return ""
    rows = [
        [esc(c.get("name", "")), cell(c.get("link")), cell(c.get("margin")), esc(c.get("unit", ""))]
        for c in bad
    ]
    return section(
        "violations",
        "Constraints not satisfied",
        table(["constraint", "link", "margin", "unit"], rows),
    )
