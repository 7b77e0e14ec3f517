"""The answer of ``dynid validate`` on static data (validation.json of schema
``dynid-static-validation/1``): how well the model's ``M(q)`` and ``g(q)`` match the
file's at its configurations, the errors per joint, the figure.
"""

from __future__ import annotations

from typing import Any

from ..identification.verdict import LEVELS
from .html import capitalised, cell, esc, figure, is_number, percent, section, table, verdict
from .run import Answer, RunFiles

__all__ = ["static_answer"]


def static_answer(run: RunFiles, doc: dict[str, Any]) -> Answer | None:
    """The verdict box, the errors per joint and the figure, or None without errors."""
    best = doc.get("relative_error_percent")
    judged = doc.get("verdict")
    if not is_number(best) or not isinstance(judged, dict) or judged.get("level") not in LEVELS:
        return None
    level, label = str(judged["level"]), str(judged.get("label") or judged["level"])
    floor = doc.get("noise_floor_percent")
    facts = [
        f"<b>{esc(capitalised(label))}</b>: {esc(str(judged.get('reason', '')))}",
        f"Relative error of M {percent(doc.get('m_error_percent'))}, of g "
        f"{percent(doc.get('g_error_percent'))}, over the stacked entries [tril M; g] "
        f"<b>{percent(best)}</b>",
        f"Judged on {cell(doc.get('n_configurations'))} static configurations of "
        f"{esc(str(doc.get('data', 'the file')))}, model {esc(str(doc.get('model', '')))}"
        + (
            f": noise floor {percent(floor)} (the data's recorded noise and the model's "
            "coefficients')"
            if is_number(floor)
            else ": the data record no noise (a controller's own model): below 5 % is good"
        ),
    ]
    head = f"The model's M(q) and g(q) match the data's to {percent(best)}."
    rel = run.png("validation_static.png")
    figs = "" if rel is None else figure(rel, run.files[rel], "Model against data: g, M, per joint")
    shown = frozenset() if rel is None else frozenset({rel})
    return Answer(verdict(level, head, facts, label), (_joints(doc), figs), shown)


def _joints(doc: dict[str, Any]) -> str:
    g, m = doc.get("g_rms") or [], doc.get("m_rms") or []
    p, f = doc.get("relative_error_percent_per_joint") or [], doc.get("joint_floor_percent")
    names = doc.get("joint_names") or [f"joint {j + 1}" for j in range(len(g))]
    if not (len(g) == len(m) == len(p) == len(names)) or not g:
        return ""
    floors = f if isinstance(f, list) and len(f) == len(g) else [None] * len(g)
    unit = (doc.get("units") or {}).get("g_rms", "N m")
    rows = [
        [esc(str(n)), cell(a), cell(b), cell(c), cell(d)]
        for n, a, b, c, d in zip(names, g, m, p, floors, strict=True)
    ]
    headers = [
        "joint",
        f"RMS error of g [{esc(str(unit))}]",
        "RMS error of row j of M [kg m^2]",
        "relative error [%]",
        "noise floor [%]",
    ]
    return section("errors", "Errors per joint", table(headers, rows))
