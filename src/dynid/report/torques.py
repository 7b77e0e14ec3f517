"""The answers of ``dynid validate`` and ``dynid friction``: how well the model predicts the
log's torques, without and with friction, and which friction law the data chose.

validate: the verdict the command printed (validation.json ``verdict``: the error against
the sensor-noise floor, at the floor / usable / poor / unusable,
:mod:`dynid.identification.verdict`; the worst joint's error can lower a good one), the
relative error with and without friction, the errors per joint, the measured against the
predicted torques. friction: per
motor or joint the law written and its parameters with their units (the model's own
friction kept: each of its parts), every candidate law's training and held-out error (the
chosen one marked), the friction curve over the data.
"""

from __future__ import annotations

from typing import Any

from ..identification.verdict import (
    FAIR_PERCENT,
    FLOOR_FAIR,
    FLOOR_GOOD,
    GOOD_PERCENT,
    JOINT_FAIR,
    JOINT_GOOD,
    LEVELS,
    NOISY_FLOOR_PERCENT,
    SYSTEMATIC_RATIO,
    UNUSABLE_PERCENT,
    joint_levels,
    judge_prediction,
)
from ..io.validation_json import STATIC_VALIDATION_SCHEMA
from .constants import constants_facts
from .delay import delay_facts, delay_section
from .html import (
    capitalised,
    cell,
    esc,
    figure,
    file_unit,
    is_number,
    percent,
    section,
    table,
    verdict,
)
from .motion import outside_facts, outside_section, split_reason
from .run import Answer, RunFiles
from .springs import spring_facts, springs_section
from .static_check import static_answer

__all__ = ["friction_answer", "validate_answer"]


def _names(doc: dict, n: int) -> list[str]:
    names = doc.get("joint_names")
    if isinstance(names, list) and len(names) == n:
        return [str(x) for x in names]
    return [f"joint {j + 1}" for j in range(n)]


def _figures(run: RunFiles, wanted: tuple[tuple[str, str], ...]) -> tuple[str, frozenset[str]]:
    found = [(run.png(f), caption) for f, caption in wanted]
    shown = [(rel, caption) for rel, caption in found if rel is not None]
    html = "".join(figure(rel, run.files[rel], caption) for rel, caption in shown)
    return (f'<div class="figures">{html}</div>' if html else ""), frozenset(r for r, _ in shown)


def validate_answer(run: RunFiles) -> Answer | None:
    """validate's verdict, errors per joint and figures, or None without validation.json."""
    doc = run.doc("validation.json")
    if doc is None:
        return None
    if doc.get("schema") == STATIC_VALIDATION_SCHEMA:  # static data: M and g at configurations
        return static_answer(run, doc)
    without, with_ = doc.get("without_friction") or {}, doc.get("with_friction")
    best = doc.get("relative_error_percent")
    if not is_number(best):
        return None
    judged: dict[str, Any] = doc["verdict"] if isinstance(doc.get("verdict"), dict) else {}
    floor = doc.get("noise_floor_percent")
    added = _added(doc)
    if judged.get("level") in LEVELS:  # the command's own verdict
        level, label = str(judged["level"]), str(judged.get("label") or judged["level"])
        reason = str(judged.get("reason", ""))
    else:  # a file without one (older, or the demo's): judged on its errors alone
        v = judge_prediction(best, floor if is_number(floor) else None)
        level, label, reason = v.level, v.label, v.reason
    judged_level = level
    if level in ("good", "fair"):  # the words of the level: "at the noise floor", "usable"
        label = label if level == "good" else "usable, with reservations"
    else:
        label = {"poor": "poor: improve the model", "unusable": "unusable: check the data"}[level]
    reason, outside, hedge = split_reason(reason)  # each said apart (.motion)
    names = _names(doc, len(doc["rms"])) if isinstance(doc.get("rms"), list) else []
    facts = [
        f"<b>{esc(capitalised(label))}</b>: {esc(reason)}",
        *outside_facts(doc, names, outside, hedge),
        f"Relative error without {added} {percent(without.get('relative_error_percent'))}"
        + (
            f", with {added}"
            + ("" if added == "offsets" else f" ({esc(doc.get('friction_model'))})")
            + " "
            f"<b>{percent(with_.get('relative_error_percent'))}</b>"
            if isinstance(with_, dict)
            else " (no friction model given)"
        ),
        f"Judged on {cell(doc.get('n_samples'))} samples of {esc(doc.get('data', 'the log'))}, "
        f"model {esc(doc.get('model', ''))}: at the noise floor up to {FLOOR_GOOD:g} x the "
        f"noise floor"
        + (
            f" ({percent(floor)})"
            if is_number(floor)
            else f" (not measured: below {GOOD_PERCENT:g} % is good)"
        )
        + f", usable up to {FLOOR_FAIR:g} x or below {FAIR_PERCENT:g} %, poor below "
        f"{UNUSABLE_PERCENT:g} %, unusable from {UNUSABLE_PERCENT:g} % or with torques of "
        f"the opposite sign; torques mostly noise (a floor of {NOISY_FLOOR_PERCENT:.3g} % or "
        "more) are at best usable",
    ]
    facts[1:1] = spring_facts(doc)  # where the verdict names a spring: its stiffness
    facts[1:1] = constants_facts(doc)  # a current log's: which constants the data check
    facts[:0] = delay_facts(doc)  # a named lag first: the hints after it may be the lag
    per = (with_ if isinstance(with_, dict) else without).get("relative_error_percent_per_joint")
    if isinstance(per, list) and per and all(is_number(p) for p in per):
        ratio = _noise_ratios(doc, len(per))
        j = max(range(len(per)), key=lambda k: (ratio[k], per[k]))
        known = ratio[j] if ratio[j] < float("inf") else float("nan")
        joint = joint_levels([per[j]], [known], _rough(doc, j))[0]
        if LEVELS.index(joint) > LEVELS.index(level) and level != "unusable":
            level = joint
        noise = f", {ratio[j]:.3g} x its noise" if ratio[j] < float("inf") else ""
        ranked = (
            "Worst joint against its own noise (the largest error over its noise, as the "
            "verdict weighs it; another joint's relative error can be larger)"
            if ratio[j] < float("inf")
            else "Worst joint by relative error"
        )
        facts.append(
            f"{ranked} {esc(_names(doc, len(per))[j])}: relative error "
            f"<b>{percent(per[j])}</b>{noise} (per joint judged good within "
            f"{SYSTEMATIC_RATIO:g} x its noise, or below {JOINT_GOOD:g} % where its noise is "
            f"not known; usable below {JOINT_FAIR:g} % or {FLOOR_FAIR:g} x its noise)"
        )
    rms = doc.get("rms")
    if isinstance(rms, list) and rms:
        worst = max(range(len(rms)), key=lambda j: rms[j])
        facts.append(
            f"Largest RMS error {cell(rms[worst])} N m on {esc(_names(doc, len(rms))[worst])}"
        )
    head = (
        f"The model does not explain the log's torques: error {percent(best)}."
        if level == "unusable"
        else f"The model predicts the log's torques to {percent(best)}."
    )
    if isinstance(doc.get("reversed_columns"), dict) and doc["reversed_columns"]:  # likelier
        files = ", ".join(esc(str(k)) for k in doc["reversed_columns"])
        head = (
            f"{files}: columns look recorded reversed (--units flips them; below); as read: "
            f"{head[0].lower()}{head[1:]}"
        )
    if isinstance(doc.get("opposite_sign"), dict) and doc["opposite_sign"]:  # the likelier cause
        files = ", ".join(esc(str(k)) for k in doc["opposite_sign"])
        head = (
            f"The torques of {files} have the opposite sign (to the model's or to the other "
            "recordings') on some joints or on all (--units flips them; below); as read: "
            f"{head[0].lower()}{head[1:]}"
        )
    if isinstance(doc.get("sign_map"), str):  # the likelier cause, said before the error
        whose = "given" if "the sign map given" in doc["sign_map"] else "model's recorded"
        head = (
            f"The {whose} sign map looks wrong for this file (--units "
            f"{'reads it right' if whose == 'given' else 'overrides it'}; below); as read: "
            f"{head[0].lower()}{head[1:]}"
        )
    figs, shown = _figures(
        run,
        (
            ("validation_torques.png", "Measured and predicted torques"),
            ("validation_rms.png", f"RMS error per joint, without and with {added}"),
        ),
    )
    shown_label = label if level == judged_level else None  # a worse joint: the level's own
    sections = (
        _joint_errors(doc), delay_section(doc), springs_section(doc), figs,
        outside_section(doc, names),
    )  # fmt: skip
    return Answer(verdict(level, head, facts, shown_label), sections, shown)


def _noise_ratios(doc: dict, n: int) -> list[float]:
    """Per joint, the error over the noise as the verdict weighed it (validation.json
    ``joint_ratios``: the numbers of its reason), else the RMS error over the noise
    (``rms`` and ``noise_rms``); inf where neither is known."""
    weighed = doc.get("joint_ratios")
    if isinstance(weighed, list) and len(weighed) == n and all(map(is_number, weighed)):
        return [float(r) for r in weighed]
    rms, noise = doc.get("rms"), doc.get("noise_rms")
    if not (isinstance(rms, list) and isinstance(noise, list) and len(rms) == len(noise) == n):
        return [float("inf")] * n
    return [
        r / s if is_number(r) and is_number(s) and s > 0 else float("inf")
        for r, s in zip(rms, noise, strict=True)
    ]


def _rough(doc: dict, j: int) -> list[bool] | None:
    """Whether joint ``j``'s noise is mostly the states' through the model
    (validation.json ``input_noise_rms`` above ``sensor_noise_rms``), as a one-joint
    list; None where the file does not say."""
    s, i = doc.get("sensor_noise_rms"), doc.get("input_noise_rms")
    if not (isinstance(s, list) and isinstance(i, list) and len(s) == len(i) > j):
        return None
    if not (is_number(s[j]) and is_number(i[j])):
        return None
    return [bool(i[j] > s[j])]


def _added(doc: dict) -> str:
    """What the model's friction adds (validation.json ``friction_terms``: offsets are not
    friction); "friction" in a file without the key (or with another value)."""
    words = doc.get("friction_terms")
    return words if words in ("offsets", "friction and offsets") else "friction"


def _joint_errors(doc: dict) -> str:
    w = doc.get("without_friction") or {}
    f = doc.get("with_friction") or {}
    r0, r1 = w.get("rms") or [], f.get("rms") or []
    p0 = w.get("relative_error_percent_per_joint") or []
    p1 = f.get("relative_error_percent_per_joint") or []
    if not r0:
        return ""
    rows = []
    for j, name in enumerate(_names(doc, len(r0))):
        row = [esc(name), cell(r0[j]), cell(p0[j] if j < len(p0) else None)]
        if r1:
            gain = 100.0 * (1 - r1[j] / r0[j]) if r0[j] > 0 else None
            row += [cell(r1[j]), cell(p1[j] if j < len(p1) else None), cell(gain)]
        rows.append(row)
    added = _added(doc)
    u = file_unit(doc, "rms")
    headers = ["joint", f"RMS without {added} [{u}]", "relative error without [%]"]
    if r1:
        headers += [
            f"RMS with {added} [{u}]",
            "relative error with [%]",
            f"{added} {'lowers' if added == 'friction' else 'lower'} RMS by [%]",
        ]
    return section("errors", "Errors per joint", table(headers, rows))


def friction_answer(run: RunFiles) -> Answer | None:
    """friction's verdict, the law and parameters per joint (per motor at the motors), the
    candidates, the figure."""
    doc = run.doc("friction.json")
    if doc is None or not isinstance(doc.get("joints"), list):
        return None
    joints = doc["joints"]
    sel: dict[str, Any] = doc["selection"] if isinstance(doc.get("selection"), dict) else {}
    cands = [c for c in sel.get("candidates") or [] if isinstance(c, dict)]
    chosen = next((c for c in cands if c.get("model") == sel.get("chosen")), None)
    none = next((c for c in cands if c.get("model") == "none"), None)
    written = _written(doc)
    facts = []
    if chosen is not None:
        rule = sel.get("rule") or "the lowest held-out error"
        facts.append(
            f"Held-out error of {esc(_candidate_name(chosen, written))} "
            f"<b>{percent(chosen.get('heldout_error_percent'))}</b>"
            f" ({esc(sel.get('method', ''))}, {cell(sel.get('folds'))} folds, the rigid-body "
            f"model as given); kept of {len(cands)} candidates as {esc(rule)}"
            + (
                f"; without friction {percent(none.get('heldout_error_percent'))}"
                if none is not None
                else ""
            )
        )
    unidentified = [j for j, r in enumerate(joints) if r.get("identified") is False]
    converged = _get_list(doc, "metadata", "converged")
    stalled = [j for j, c in enumerate(converged) if c is False]
    names = _names(doc, len(joints))
    if unidentified:
        facts.append(
            "Not identified (joint did not move enough): "
            + esc(", ".join(names[j] for j in unidentified))
        )
    if stalled:
        facts.append("Fit did not converge: " + esc(", ".join(names[j] for j in stalled)))
    before = [r.get("rms_before") for r in joints if is_number(r.get("rms_before"))]
    after = [r.get("rms_after") for r in joints if is_number(r.get("rms_after"))]
    if before and after:
        facts.append(
            f"Largest residual RMS over the joints {cell(max(before))} N m before friction, "
            f"{cell(max(after))} N m after (on the recordings the friction was fitted to)"
        )
    level = (
        "poor"
        if unidentified and len(unidentified) == len(joints)
        else ("fair" if unidentified or stalled else "good")
    )
    head = f"Friction law chosen: {esc(written)}."
    figs, shown = _figures(run, (("friction.png", "Friction against velocity over the data"),))
    sections = (  # the figure first: the tables of a sum and its RMS would push it down
        figs,
        *_law_tables(doc, names),
        _rms_table(joints, names, file_unit(doc, "rms_before")),
        _candidates_table(cands, sel.get("chosen")),
    )
    return Answer(verdict(level, head, facts), sections, shown)


def _parts(doc: dict) -> list[dict[str, Any]]:
    """The laws friction.json holds: its parts (a sum), or the one law at the motors of
    its drive (``friction_at`` motor) or at the joints."""
    if isinstance(doc.get("parts"), list):
        return [p for p in doc["parts"] if isinstance(p, dict)]
    drive = doc.get("drive")
    at = "motor" if isinstance(drive, dict) and drive.get("friction_at") == "motor" else "joint"
    return [
        {"model": doc.get("model"), "at": at, "units": doc.get("units"), "joints": doc["joints"]}
    ]


def _written(doc: dict) -> str:
    """The friction the file holds, in words: ``stribeck at the motors``, ``classical at
    the motors + classical at the joints``."""
    return " + ".join(
        f"{p.get('model')} at the {'motors' if p.get('at') == 'motor' else 'joints'}"
        for p in _parts(doc)
    )


def _candidate_name(c: dict, written: str) -> str:
    """A candidate's name for a sentence: the model's own friction named by what it is."""
    return f"the model's own friction ({written})" if c.get("model") == "own" else str(c["model"])


def _get_list(doc: Any, *keys: str) -> list[Any]:
    for k in keys:
        doc = doc.get(k) if isinstance(doc, dict) else None
    return doc if isinstance(doc, list) else []


_FIT_KEYS = ("rms_before", "rms_after", "identified")


def _law_tables(doc: dict, names: list[str]) -> list[str]:
    """One table of parameters per law the file holds, its rows the motors (``motor 1``)
    or the joints it acts at."""
    out = []
    parts = _parts(doc)
    for i, part in enumerate(parts):
        units: dict[str, Any] = part["units"] if isinstance(part.get("units"), dict) else {}
        rows_in = [r for r in part.get("joints") or [] if isinstance(r, dict)]
        if not rows_in:
            continue
        params = [k for k in rows_in[0] if k not in _FIT_KEYS]
        motors = part.get("at") == "motor"
        label = [f"motor {j + 1}" for j in range(len(rows_in))] if motors else names
        headers = [
            "motor" if motors else "joint",
            "law",
            *(f"{k} [{units[k]}]" if k in units else k for k in params),
        ]
        rows = [
            [esc(label[j]), esc(part.get("model", ""))] + [cell(r.get(k)) for k in params]
            for j, r in enumerate(rows_in)
        ]
        where = "per motor (at the motor's velocity)" if motors else "per joint"
        anchor = "law" if len(parts) == 1 else f"law{i + 1}"
        out.append(section(anchor, f"Law and parameters {where}", table(headers, rows)))
    return out


def _rms_table(joints: list[dict], names: list[str], unit: str = "N m") -> str:
    """The residual RMS per joint before and after the friction [``unit``], and whether
    identified."""
    if not any(is_number(r.get("rms_before")) for r in joints):
        return ""
    rows = [
        [
            esc(names[j]),
            cell(r.get("rms_before")),
            cell(r.get("rms_after")),
            cell(r.get("identified")),
        ]
        for j, r in enumerate(joints)
    ]
    headers = ["joint", f"residual RMS before [{unit}]", f"residual RMS after [{unit}]"]
    headers.append("identified")
    return section("rms", "Residual per joint (the recordings fitted)", table(headers, rows))


def _candidates_table(cands: list[dict], chosen: Any) -> str:
    if not cands:
        return ""
    scaled = any(is_number(c.get("heldout_scaled_percent")) for c in cands)
    rows = [
        [
            "&#10003; chosen" if c.get("model") == chosen else "",
            esc(c.get("model", "")),
            cell(c.get("parameters") or []),
            cell(c.get("train_error_percent")),
            cell(c.get("heldout_error_percent")),
        ]
        + ([cell(c.get("heldout_scaled_percent"))] if scaled else [])
        for c in cands
    ]
    headers = ["", "law", "parameters per joint", "training error [%]", "held-out error [%]"]
    if scaled:
        headers.append("held-out, each joint by its noise [%]")
    marked = [c.get("model") == chosen for c in cands]
    return section("candidates", "Candidate laws", table(headers, rows, marked=marked))
