"""The answer of ``dynid demo``: does dynid reproduce the paper (Gaz et al. 2019)?

Read from ``paper.json`` (:func:`dynid.pipeline.paper.paper_comparison`): Table III's 43
coefficients, dynid's (with standard deviations, in the paper's basis) beside the
published ones; the sigmoid friction beside the published; the validation errors per joint
with the validation figure (Fig. 3); the retrieved links beside the published ``p_hat``.
Each table has the difference in a column.
"""

from __future__ import annotations

from .html import cell, esc, figure, is_number, number, section, table, verdict
from .run import Answer, RunFiles

__all__ = ["answer"]

#: Differences within this many standard deviations, beyond the table's rounding, count as
#: agreement.
AGREE_STD = 3.0
#: Half a unit of the last decimal Table III prints (4 decimals).
ROUNDING = 0.5e-4


def answer(run: RunFiles) -> Answer | None:
    """The demo's verdict and the paper's tables beside dynid's, or None without paper.json."""
    doc = run.doc("paper.json")
    if doc is None or not isinstance(doc.get("table_iii"), list):
        return None
    rows = doc["table_iii"]
    comparable = [
        r for r in rows if is_number(r.get("difference")) and not r.get("transcription_error")
    ]
    agree = sum(1 for r in comparable if _agrees(r))
    worst = max(comparable, key=lambda r: abs(r["difference"]), default=None)
    wrong = sum(1 for r in rows if r.get("transcription_error"))
    printed = len(rows) - sum(1 for r in rows if r.get("published") is None)
    facts = [
        f"Table III: <b>{agree} of the {len(comparable)}</b> coefficients compared agree with "
        f"the published value (within its rounding, &plusmn;{ROUNDING:g}, and {AGREE_STD:g} "
        "std)"
        + (
            f"; largest difference {number(worst['difference'], 3)} (coefficient {worst['index']})"
            if worst
            else ""
        )
        + f"; the paper prints {printed} of the {len(rows)}, {wrong} of them with a "
        "transcription error (not compared; marked in the table)",
    ]
    fr = [r for r in doc.get("friction") or [] if is_number(r.get("difference"))]
    if fr:
        rel = max(abs(r["difference"]) / max(abs(r["published"]), 1e-12) for r in fr)
        facts.append(f"Friction: largest relative difference to the published {100 * rel:.2g} %")
    links = doc.get("links") or []
    if links:
        dm = max(abs(r["mass_difference"]) for r in links)
        facts.append(
            f"Retrieved links: masses within {number(dm, 3)} kg of the published p_hat (the "
            "coefficients do not determine the links: every consistent set that reproduces "
            "them is an answer, the paper's p_hat one of them)"
        )
    val = doc.get("validation") or []
    if val:
        worst_v = max(r["rms_with_friction"] for r in val)
        facts.append(
            f"Validation: RMS error with friction at most {number(worst_v, 3)} N m per joint "
            f"(sensor noise {number(max(r['sensor_noise'] for r in val), 3)} N m)"
        )
    level = "good" if comparable and agree == len(comparable) else "fair"
    head = "dynid reproduces the paper on the simulated Panda."
    if level != "good":
        head = "dynid's results differ from the paper's in places (see the tables)."
    fig = run.png("validation_torques.png")
    sections = (_table_iii(rows), _friction(fr), _validation(run, val, fig), _links(links))
    return Answer(
        verdict(level, esc(head), facts),
        sections,
        frozenset({fig} if fig is not None else set()),
    )


def _agrees(row: dict) -> bool:
    """The difference within the printed value's rounding plus AGREE_STD std."""
    d, s = row.get("difference"), row.get("dynid_std")
    if not is_number(d):
        return False
    return abs(d) <= ROUNDING + AGREE_STD * (s if is_number(s) else 0.0)


def _table_iii(rows: list[dict]) -> str:
    body = []
    for r in rows:
        d, s = r.get("difference"), r.get("dynid_std")
        note = (
            "transcription error in the paper"
            if r.get("transcription_error")
            else "not printed (----)"
            if r.get("published") is None
            else "agrees"
            if _agrees(r)
            else "differs"
        )
        body.append(
            [
                str(r.get("index")),
                f'<span class="expr">{esc(r.get("expression", ""))}</span>',
                cell(r.get("dynid")),
                cell(s),
                cell(r.get("published")),
                cell(d),
                cell(abs(d) / s if is_number(d) and is_number(s) and s > 0 else None),
                esc(note),
            ]
        )
    headers = [
        "#",
        "expression (Table III)",
        "dynid",
        "dynid std",
        "published pi(p_hat)",
        "difference (dynid - published)",
        "|difference| / std",
        "note",
    ]
    return section(
        "table-iii",
        "Table III: the 43 dynamic coefficients (SI: kg, kg m, kg m^2)",
        table(headers, body, cls="coefficients"),
    )


def _friction(rows: list[dict]) -> str:
    if not rows:
        return ""
    body = [
        [
            esc(r["joint"]),
            esc(f"{r['parameter']} [{r['unit']}]"),
            cell(r["dynid"]),
            cell(r["published"]),
            cell(r["difference"]),
        ]
        for r in rows
    ]
    headers = ["joint", "sigmoid parameter [unit]", "dynid", "published", "difference"]
    return section("friction-paper", "Friction (supplementary Table I)", table(headers, body))


def _validation(run: RunFiles, rows: list[dict], fig: str | None) -> str:
    parts = []
    if fig is not None:
        parts.append(
            figure(
                fig,
                run.files[fig],
                "Measured and predicted torques on the validation sinusoids (Fig. 3 of the paper)",
            )
        )
    if rows:
        body = [
            [
                esc(r["joint"]),
                cell(r["rms_without_friction"]),
                cell(r["rms_with_friction"]),
                cell(r["rms_with_friction"] - r["rms_without_friction"]),
                cell(r["sensor_noise"]),
            ]
            for r in rows
        ]
        headers = [
            "joint",
            "RMS without friction [N m]",
            "RMS with friction [N m]",
            "difference [N m]",
            "sensor noise [N m]",
        ]
        parts.append(table(headers, body))
    return section("validation", "Validation (Sec. VI, Fig. 3)", *parts) if parts else ""


def _links(rows: list[dict]) -> str:
    if not rows:
        return ""
    body = [
        [
            esc(r["link"]),
            cell(r["mass"]),
            cell(r["mass_published"]),
            cell(r["mass_difference"]),
            cell(r["com"]),
            cell(r["com_published"]),
            cell(r["com_distance"]),
        ]
        for r in rows
    ]
    headers = [
        "link",
        "mass, dynid [kg]",
        "mass, published [kg]",
        "difference [kg]",
        "CoM x, y, z, dynid [m]",
        "CoM x, y, z, published [m]",
        "CoM distance [m]",
    ]
    return section(
        "links-paper",
        "Retrieved links against the published p_hat (Tables VIII, IX)",
        table(headers, body),
    )
