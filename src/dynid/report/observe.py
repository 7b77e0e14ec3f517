"""The answer of a run that watched a log for events (collision detection): the residuals,
the thresholds and the events, from ``events.json``, ``thresholds.json``,
``residuals.png`` and ``residuals.csv`` when the run wrote them. A calibration
(``thresholds.json`` recording its ``calibration``, no events file) judges no events: its
answer says what it calibrated.

The files' layouts belong to the command that writes them; this page reads them
generically: the events are the records of ``events.json`` (a list, or the list under
``events``), the thresholds the file's tables.

A detection's answer opens with how far to trust its events (``events.json``'s
``trust``: :mod:`~dynid.observer.trust`), its level the box's and its badge ``trust good``,
``trust fair`` or ``trust poor``; what was found follows as the first fact.

The run's notes (:attr:`~dynid.observer.results.ObserveResult.notes`, in the run summary)
are facts of the answer: a model without friction whose residual shows the arm's friction
(its size per joint, and the ``dynid friction`` command that identifies it) lowers a
clean result to usable, the thresholds and the residual holding that friction.
"""

from __future__ import annotations

from pathlib import Path
from typing import Any

from .._times import stamp_text
from ..identification.verdict import LEVELS
from .html import (
    capitalised,
    cell,
    esc,
    figure,
    file_unit,
    href,
    is_number,
    number,
    section,
    table,
    verdict,
)
from .json_tables import json_section
from .motion import beyond_fact
from .run import Answer, RunFiles

__all__ = ["answer"]


def _events(doc: Any) -> list | None:
    if isinstance(doc, list):
        return doc
    if isinstance(doc, dict) and isinstance(doc.get("events"), list):
        return doc["events"]
    return None


def _model_check(cal: dict) -> tuple[str, str] | None:
    """The model behind the thresholds (``calibration.model_check``: judged on the
    calibration logs as ``dynid validate`` judges it) as a fact (HTML) and its level, or
    None where the file has none."""
    m = cal.get("model_check")
    v = m.get("verdict") if isinstance(m, dict) else None
    if not (isinstance(m, dict) and isinstance(v, dict)):
        return None
    err, floor = m.get("relative_error_percent"), m.get("noise_floor_percent")
    if not (is_number(err) and is_number(floor) and v.get("level") in LEVELS):
        return None
    from ..observer.calibration_check import model_words  # here: any run's page loads this

    ratio = v.get("ratio")
    got = m.get("fitted")
    fitted: list[Any] = got if isinstance(got, list) else []
    counted = len(fitted) == 2 and all(map(is_number, fitted))
    said = model_words(
        err,
        floor,
        v["level"],
        str(v.get("label", v["level"])),
        ratio if is_number(ratio) else None,
        tuple(int(x) for x in fitted) if counted else (),
    )
    return f"<b>Model</b>: {esc(said)}", str(v["level"])


def _calibration(doc: Any) -> tuple[str, list[str]] | None:
    """Whether a calibrated observer is good enough, from ``thresholds.json``'s
    ``calibration``: the escaped headline (the logs, the false alarms the thresholds raise
    on them and their rate per minute, the smallest detectable torque's range), how well
    the model behind them predicts the logs' torques (:func:`_model_check`) and the
    per-joint table (smallest torque detected while moving and at rest, the largest
    ``|r|`` read, the thresholds), or None when the file records no calibration."""
    cal = doc.get("calibration") if isinstance(doc, dict) else None
    if not isinstance(cal, dict):
        return None
    logs = [str(d) for d in cal.get("data") or ()]
    said = "Thresholds calibrated on "
    duration = cal.get("duration_s")
    if is_number(duration):
        said += f"{duration:.3g} s ({cal.get('samples', '?')} samples)"
    else:
        said += f"{cal.get('samples', 'the')} samples"
    said += f" of {len(logs)} collision-free log" + ("s" if len(logs) != 1 else "")
    said += f" ({', '.join(logs)})" if logs else ""
    alarms = cal.get("false_alarms")
    if is_number(alarms):
        said += f": {int(alarms)} false alarm{'s' if alarms != 1 else ''} on them"
        if is_number(duration) and duration > 0:
            said += f" ({60.0 * alarms / duration:.3g} per minute)"
    moving = cal.get("detectable") if _numbers(cal.get("detectable")) else doc.get("contact")
    if _numbers(moving):
        u = file_unit(doc, "contact")
        said += f"; an external torque above {_span(moving)} {u} is detected while a joint moves"
    rest = cal.get("at_rest")
    if _numbers(rest):
        said += f", above {_span(rest)} {file_unit(doc, 'contact')} on a joint at rest"
    facts = [m[0]] if (m := _model_check(cal)) is not None else []
    return esc(said + "."), facts + ([_joint_table(doc, cal)] if _numbers(moving) else [])


def _joint_table(doc: dict, cal: dict) -> str:
    """Per joint: the contact level while moving (the smallest external torque detected,
    the largest contact threshold along the motion) and at rest, the collision level while
    moving and the largest ``|r|`` the calibration read [N m], each as the file holds it
    (``detectable``, ``at_rest``, ``collision_moving``, ``peak``; a file without
    ``collision_moving`` shows no collision column), and, where the levels grow with the
    model's uncertainty, the fixed levels of the file's ``contact`` and ``collision``
    beside them, named as such."""
    fixed, u = isinstance(doc.get("uncertainty"), dict), file_unit(doc, "contact")
    moving = cal.get("detectable") if _numbers(cal.get("detectable")) else doc.get("contact")
    given = [
        (f"contact level, moving (smallest torque detected) [{u}]", moving),
        (f"at rest [{u}]", cal.get("at_rest")),
        (f"collision level, moving [{u}]", cal.get("collision_moving")),
        (
            f"contact --no-uncertainty (fixed, not applied here) [{u}]",
            doc.get("contact") if fixed else None,
        ),
        (
            f"collision --no-uncertainty (fixed, not applied here) [{u}]",
            doc.get("collision") if fixed else None,
        ),
        *_read_columns(doc, cal),
    ]
    columns = [(h, v) for h, v in given if isinstance(v, list) and _numbers(v)]
    n = len(columns[0][1])
    names = doc.get("joints")
    if not (isinstance(names, list) and len(names) == n):
        names = [f"joint{j + 1}" for j in range(n)]
    rows = [
        [esc(names[j])] + [number(v[j]) if j < len(v) else "" for _, v in columns] for j in range(n)
    ]
    heads = ["joint", *(h for h, _ in columns)]
    if (words := _rest_margin_words(doc, n)) is not None:
        heads.append("standstill margin at rest")
        rows = [row + [esc(w)] for row, w in zip(rows, words, strict=True)]
    return table(heads, rows, cls="calibration")


def _rest_margin_words(doc: dict, n: int) -> list[str] | None:
    """Per joint, the standstill margin at a settled rest as ``rule.rest_margin`` holds it
    (:class:`~dynid.observer.thresholds.RestMargin`): its calibrated level and the rests it
    was read from, or the Coulomb bound for too few rests, in the calibration printout's
    words; None for a file without it."""
    rule = doc.get("rule")
    got = rule.get("rest_margin") if isinstance(rule, dict) else None
    if not isinstance(got, dict):
        return None
    level, rests, need = got.get("level"), got.get("rests"), got.get("min_rests")
    if not (isinstance(level, list) and isinstance(rests, list) and len(level) == len(rests) == n):
        return None
    return [
        f"min(Coulomb bound, {v:.3g} N m): calibrated from {k} rests"
        if is_number(v)
        else f"Coulomb bound: too few rests ({k} of the {need} needed)"
        for v, k in zip(level, rests, strict=True)
    ]


def _read_columns(doc: dict, cal: dict) -> list[tuple[str, Any]]:
    """The residual the calibration read per joint, as the summary names it: the ``|r|``
    (or its quantile) the rule read past the standstill margin, ``contact / margin`` of
    the file's rule; and the largest ``|r|`` (``peak``), where the margin applied named as
    the raw one, with the margin on (a joint at rest reads it over its threshold's
    base, and raises no alarm for it)."""
    got = doc.get("rule")
    rule: dict = got if isinstance(got, dict) else {}
    contact, margin, q = doc.get("contact"), rule.get("margin"), rule.get("quantile", 1.0)
    still = bool(rule.get("standstill_margin", False))
    u = file_unit(doc, "contact")
    out: list[tuple[str, Any]] = []
    if _numbers(contact) and is_number(margin) and margin > 0 and is_number(q):
        read = "|r| read" if q == 1.0 else f"|r| quantile {q:g}"
        read += " past the standstill margin" if still else ""
        out.append(
            (
                f"{read} (the fixed contact level is {margin:g} x it) [{u}]",
                [c / margin for c in contact or ()],
            )
        )
    raw = (
        f"largest raw |r|, standstill margin not taken off [{u}]" if still else f"largest |r| [{u}]"
    )
    if still or q != 1.0 or not out:  # else the one read is the raw largest
        out.append((raw, cal.get("peak")))
    return out


def _flagged(doc: Any) -> str:
    """``", 15.1 s flagged (50.3 % of 30 s logged)"``: the time the events cover and its
    share of the logs (``events.json``'s ``flagged_s`` and ``duration_s``, summed over its
    logs; :func:`~dynid.observer.results.flagged_words`), or nothing where the file has
    none. The count alone misleads: fewer events can cover more time."""
    if not isinstance(doc, dict):
        return ""
    flagged, logged = doc.get("flagged_s"), doc.get("duration_s")
    if not (isinstance(flagged, list) and isinstance(logged, list)):
        return ""
    if not (_numbers(flagged) and _numbers(logged)):
        return ""
    from ..observer.results import flagged_words

    return ", " + flagged_words(float(sum(flagged)), float(sum(logged)))


def _scored(doc: Any) -> str | None:
    """The events against the labelled contacts in one escaped sentence (``events.json``'s
    ``score``: counts, false alarms per minute of contact-free time, delays, and beside
    them, where ``delays_look_ahead``, that a zero-phase filter's delays are shorter than
    an online observer's; then the missed contacts and why, :func:`_missed_said`), or None
    where the file has none."""
    sc = doc.get("score") if isinstance(doc, dict) else None
    keys = ("labelled", "detected", "missed", "false_alarms")
    if not isinstance(sc, dict) or not all(is_number(sc.get(k)) for k in keys):
        return None
    said = (
        f"Against the labelled contacts ({sc.get('source', '?')}): {sc['labelled']} labelled, "
        f"{sc['detected']} detected, {sc['missed']} missed; {sc['false_alarms']} false "
        "alarm(s)"
    )
    if is_number(rate := sc.get("false_alarms_per_min")):
        said += f" ({rate:.3g} per minute of contact-free time)"
    if is_number(mid := sc.get("delay_median_ms")) and is_number(top := sc.get("delay_max_ms")):
        said += f"; delay median {mid:.0f} ms, max {top:.0f} ms"
        if sc.get("delays_look_ahead") is True:  # beside the delay it qualifies
            from ..observer.scoring import LOOK_AHEAD_WORDS  # here: any run's page loads this

            said += f" ({LOOK_AHEAD_WORDS})"
    return esc(said + "." + _missed_said(sc))


def _trust(doc: Any) -> tuple[str, str] | None:
    """How far to trust the events (``events.json``'s ``trust``,
    :mod:`~dynid.observer.trust`): its line after the level (escaped; the badge says the
    level) and its level, or None where the file has none."""
    got = doc.get("trust") if isinstance(doc, dict) else None
    if not isinstance(got, dict) or got.get("level") not in ("good", "fair", "poor"):
        return None
    said = str(got.get("summary", ""))
    if not said.startswith("trust: "):
        return None
    level = str(got["level"])
    rest = said.removeprefix(f"trust: {level}").lstrip(" -")
    return esc(capitalised(rest)), level


def _worse(level: str, trust: str) -> str:
    """The box's level: the trust's where the answer is a finding (events found), else
    the worse of the two."""
    order = ("good", "fair", "poor", "unusable")
    if level not in order:
        return trust
    return max(level, trust, key=order.index)


#: Missed contacts a report names at most (events.json holds them all).
MISSED_SHOWN = 10


def _missed_said(sc: dict) -> str:
    """The missed contacts of ``events.json``'s ``score`` (per log in ``logs``), each with
    its times and, where read, why it was missed (``reason``, the joint, its torque and
    the threshold compared), as sentences; empty without one."""
    rows = []
    for log in sc.get("logs") or []:
        if not isinstance(log, dict):
            continue
        for m in log.get("missed_contacts") or []:
            if isinstance(m, dict) and is_number(m.get("start")) and is_number(m.get("end")):
                rows.append(
                    f"{log.get('log', '?')} {m['start']:.3f} s to {m['end']:.3f} s" + _why(m)
                )
    if not rows:
        return ""
    more = len(rows) - MISSED_SHOWN
    tail = f"; and {more} more in events.json" if more > 0 else ""
    return " Missed: " + "; ".join(rows[:MISSED_SHOWN]) + tail + "."


def _why(m: dict) -> str:
    """`` (joint4 stood still: true torque 0.5 N m against the threshold in force at 1.2
    s, 0.84 N m)``: a missed contact's reason in ``events.json``, empty without one."""
    reason, name = m.get("reason"), m.get("joint_name") or f"joint {m.get('joint')}"
    torque, level = m.get("torque"), m.get("threshold")
    if not (isinstance(reason, str) and is_number(torque) and is_number(level)):
        return ""
    at = f" at {m['at']:.3f} s" if is_number(m.get("at")) else ""
    if reason == "dropped_crossing":
        return (
            f" (a crossing dropped as shorter than the minimum duration: {name}{at}, "
            f"residual's peak {torque:.3g} N m)"
        )
    what = "true torque" if m.get("torque_source") == "true" else "residual"
    size = f"{what} {torque:.3g} N m against the threshold in force{at}, {level:.3g} N m"
    if reason == "below_at_rest":
        return f" ({name} stood still: {size}, its standstill margin included)"
    if reason == "below_moving":
        return f" ({name}: {size})"
    return f" (unexplained: {name}'s {size}, over it)"


#: Dropped crossings a report names at most (events.json holds more).
DROPPED_SHOWN = 5


def _damped(doc: Any) -> str | None:
    """The events whose wrench estimate was damped (``damped_share`` of ``events.json``:
    near a singular configuration, where the wrench is unreliable) as a fact (HTML), or
    None where none was."""
    events = _events(doc)
    if not events or not isinstance(doc, dict):
        return None
    got = doc.get("wrench")
    wrench: dict = got if isinstance(got, dict) else {}
    shares = [(k, e.get("damped_share")) for k, e in enumerate(events, 1) if isinstance(e, dict)]
    hit = [(k, v) for k, v in shares if is_number(v) and v > 0]
    if not hit:
        return None
    noun = "force" if wrench.get("estimate") == "force" else "wrench"
    said = ", ".join(f"event {k} {100.0 * v:.3g} %" for k, v in hit)
    return (
        f"<b>Damped {esc(noun)}</b>: the {esc(noun)} at {esc(str(wrench.get('frame', '?')))} "
        f"was estimated near a singular configuration (damped least squares) on {esc(said)} "
        f"of the event's samples: the {esc(noun)} there is unreliable (the residual and the "
        "detection are not)"
    )


def _dropped(doc: Any) -> tuple[int, str | None]:
    """The crossings over the contact threshold that the minimum duration dropped
    (``events.json``'s ``dropped``): their count and one escaped sentence naming those
    furthest over the threshold (time, joint, peak, ratio, duration against the minimum);
    ``(0, None)`` where the file has none."""
    drop = doc.get("dropped") if isinstance(doc, dict) else None
    if not isinstance(drop, dict) or not is_number(count := drop.get("count")) or not count:
        return 0, None
    from ..observer.results import dropped_words

    least = drop.get("min_duration_s")
    least = float(least) if is_number(least) else None
    named = []
    for c in drop.get("crossings") or ():
        try:
            j = int(c["joint"]) - 1
            names = c.get("joint_names") or []
            joint = dict(zip(c["joints"], names, strict=False)).get(j + 1, f"joint {j + 1}")
            ratio = float(c["ratio"][j])
            words = dropped_words(
                float(c["start"]), float(c["end"]), str(joint), float(c["peak"][j]), ratio,
                str(c["rule"]), least,
            )  # fmt: skip
        except (KeyError, IndexError, TypeError, ValueError):
            continue
        named.append((ratio, str(c.get("log", "?")), float(c["start"]), words))
    shown = sorted(named, key=lambda x: -x[0])[:DROPPED_SHOWN]  # the furthest over, by time
    shown.sort(key=lambda x: (x[1], x[2]))
    said = (
        f"{int(count)} crossing(s) over the contact threshold dropped as shorter than the "
        f"minimum duration{'' if least is None else f' ({least:g} s, --min-duration)'}; "
        "not contacts"
    )
    if shown:
        said += ": " + "; ".join(f"{log}: {words}" for _, log, _, words in shown)
    return int(count), esc(said + ".")


def _first_stamp(path: Path) -> float | None:
    """The first time stamp [s] of a residual table (``residuals.csv``: comment lines, a
    header, then ``t, r1, ...``): the log's first observed sample, from which its figure
    draws time; None when the file has no row."""
    try:
        with open(path, encoding="utf-8", errors="replace") as fh:
            rows = (line for line in fh if line.strip() and not line.startswith("#"))
            next(rows, None)  # the header
            first = next(rows, None)
        return None if first is None else float(first.split(",")[0])
    except (OSError, ValueError):
        return None


def _log_starts(doc: dict, run: RunFiles) -> dict[str, float]:
    """Each log's first observed stamp [s] by its name in ``events.json`` (``data``), read
    from its residual table (``residuals.csv``, ``residuals_<name>.csv`` for several:
    :func:`~dynid.io.observer_files.residual_names`); a log without one is left out."""
    from ..io.observer_files import residual_names  # here: any run's page loads this

    logs = [str(x) for x in doc.get("data") or () if isinstance(x, str)]
    out = {}
    for log, stem in zip(logs, residual_names(logs) if logs else [], strict=True):
        path = run.files.get(f"{stem}.csv")
        t0 = None if path is None else _first_stamp(path)
        if t0 is not None:
            out[log] = t0
    return out


def _events_parts(name: str, run: RunFiles) -> list[str]:
    """The events of ``events.json`` as a table whose times read to the millisecond
    (HTML), then the rest of the file as tables. Start and end are seconds from the
    first sample of the event's log, the axis of its residual figure, with the log's
    clock said once above the table and each start as the log holds it beside them (to
    find the row in the log, or in another record on the same clock; the column left out
    when every log starts at 0, where it would repeat the start); a log whose first
    stamp no residual table gives keeps its stamps, to the millisecond. Events of a scored
    log say whether they counted as a detection or a false alarm (``false_alarm``), and
    with a wrench, the share of the residual it leaves unexplained
    (``unexplained_share``)."""
    doc = run.docs[name]
    events = _events(doc)
    if not isinstance(doc, dict) or not events or not all(isinstance(e, dict) for e in events):
        return [json_section(name, doc)]
    starts = _log_starts(doc, run)
    rows = []
    for k, e in enumerate(events, 1):
        log = str(e.get("log", ""))
        a, b, t0 = e.get("start"), e.get("end"), starts.get(log)
        if not (is_number(a) and is_number(b)):
            return [json_section(name, doc)]
        into = t0 is not None and t0 != 0.0
        t0 = t0 if into and t0 is not None else 0.0
        rows.append(
            [
                str(k), esc(log), esc(e.get("level", "")),
                esc(", ".join(map(str, e.get("joint_names") or e.get("joints") or ()))),
                stamp_text(a - t0), stamp_text(b - t0),
                f"{1e3 * (b - a):.0f}", stamp_text(a) if into else "",
                cell(e.get("peak")),
            ]
        )  # fmt: skip
    said = "; ".join(f"{esc(log)}: t = {stamp_text(t0)} s" for log, t0 in starts.items() if t0)
    head = (
        f"<p>start and end: seconds from the log's first sample, as on the residual "
        f"figure's axis; the log's clock at that sample: {said}.</p>"
        if said
        else ""
    )
    headers = [
        "#", "log", "level", "joints", "start [s]", "end [s]", "duration [ms]",
        "start on the log's clock [s]", f"peak [{file_unit(doc, 'peak')}]",
    ]  # fmt: skip
    if any("false_alarm" in e for e in events):  # scored against labels: which were false
        headers.append("scored")
        for row, e in zip(rows, events, strict=True):
            f = e.get("false_alarm")
            row.append("" if f is None else "false alarm" if f is True else "detection")
    if any(is_number(e.get("unexplained_share")) for e in events):
        headers.append("|r| unexplained by the wrench [%]")
        for row, e in zip(rows, events, strict=True):
            v = e.get("unexplained_share")
            row.append(f"{100.0 * v:.3g}" if is_number(v) else "")
    clock = headers.index("start on the log's clock [s]")
    if not any(row[clock] for row in rows):  # every log starts at 0: nothing to show
        headers.pop(clock)
        rows = [row[:clock] + row[clock + 1 :] for row in rows]
    rest = {k: v for k, v in doc.items() if k != "events"}
    return [head + table(headers, rows, cls="events"), json_section(name, rest)]


#: Words of the note of a model without friction whose residual shows the arm's.
FRICTION_FOUND = "friction is in the logs"
#: Words of a note on a figure left out (the page's banner says it).
_FIGURE_SKIPPED = "skipped the figure "


def _notes(run: RunFiles) -> list[str]:
    """The run's notes as facts (HTML), the friction a model without friction leaves in
    the residual first, its opening words bold; a figure's note left to the banner."""
    from ..observer.results import NO_FRICTION  # here: a page of any run loads this module

    notes = [n for n in run.summary.notes if _FIGURE_SKIPPED not in n]
    notes.sort(key=lambda n: not n.startswith(NO_FRICTION))
    out = []
    for n in notes:
        head, rest = (n.split(": ", 1) + [""])[:2] if ": " in n else (n, "")
        said = esc(capitalised(head))
        out.append(f"<b>Note: {said}</b>" + (f": {esc(rest)}" if rest else ""))
    return out


def _numbers(v: Any) -> bool:
    return isinstance(v, list) and bool(v) and all(is_number(x) for x in v)


def _span(v: Any) -> str:
    """``"0.0716 to 1"``: the smallest and largest of ``v`` (a hyphen reads as a minus)."""
    return f"{min(v):.3g} to {max(v):.3g}"


def answer(run: RunFiles) -> Answer | None:
    """The events found, the thresholds and the residuals, or None without those files."""
    names = ("events.json", "thresholds.json", "residuals.png", "residuals.csv")
    found = {n: run.png(n) for n in names}
    if all(v is None for v in found.values()):
        return None
    events = _events(run.docs.get(found["events.json"] or ""))
    facts = []
    label = None
    calibrated = _calibration(run.docs.get(found["thresholds.json"] or ""))
    dropped, said = _dropped(run.docs.get(found["events.json"] or ""))
    if events is None and calibrated is not None:  # a calibration judges no events
        head, facts = calibrated[0], list(calibrated[1])
        level, label = "info", "thresholds calibrated"
        model = _model_check(run.docs[found["thresholds.json"] or ""]["calibration"])
        if model is not None and model[1] in ("poor", "unusable"):  # wide: the model's
            article = "an" if model[1][0] in "aeiou" else "a"
            level, label = model[1], f"thresholds calibrated on {article} {model[1]} model"
    elif events is None:
        head, level = esc("The run wrote residuals; no events file to judge."), "fair"
    elif events:
        head = f"{len(events)} event{'s' if len(events) != 1 else ''} detected"
        head += _flagged(run.docs.get(found["events.json"] or "")) + "."
        head, level = esc(head), "info"
    elif dropped:
        head = esc(
            f"No event, but {dropped} crossing(s) of a threshold too short to count "
            "(below the minimum duration)."
        )
        level, label = "info", "no event"
    else:
        head, level = esc("No event: every residual stayed below its threshold."), "good"
    found_head = None
    if (trust := _trust(run.docs.get(found["events.json"] or ""))) is not None:
        found_head = head  # what was found: the first fact, below how far to trust it
        head, level = trust[0], _worse(level, trust[1])
        label = label or f"trust {trust[1]}"  # a label of its own ("no event") kept
    if said is not None:
        facts.append(said)
    if (scored := _scored(run.docs.get(found["events.json"] or ""))) is not None:
        facts.append(scored)
    if (damped := _damped(run.docs.get(found["events.json"] or ""))) is not None:
        facts.append(damped)
    if events is None and calibrated is not None and found["residuals.png"] is not None:
        facts.append("The residual over the calibration with its thresholds: the figure below")
    notes = _notes(run)
    where = found["events.json"] if events is not None else found["thresholds.json"]
    fast = beyond_fact(run.docs.get(where or ""), run.summary.notes)  # the model extrapolates
    facts[0:0] = notes + ([fast] if fast is not None else [])  # before the tables
    if found_head is not None:
        facts.insert(0, found_head)
    if level == "good" and any(FRICTION_FOUND in n for n in notes):  # thresholds hold it
        level = "fair"
    if found["thresholds.json"] is not None:
        facts.append("Thresholds: every entry in the table below (from thresholds.json)")
    if found["residuals.csv"] is not None:
        rel = found["residuals.csv"]
        facts.append(f'Residuals over time: <a href="{href(rel)}">{esc(rel)}</a>')
    sections = []
    name = found["events.json"]
    if name is not None and name in run.docs:
        sections.append(section("events", "Events", *_events_parts(name, run)))
    if found["residuals.png"] is not None:
        rel = found["residuals.png"]
        title = "Residuals and thresholds" + (" over the calibration" if events is None else "")
        fig = figure(rel, run.files[rel], title)
        sections.append(section("residuals", "Residuals", fig))
    name = found["thresholds.json"]
    if name is not None and name in run.docs:
        sections.append(section("thresholds", "Thresholds", json_section(name, run.docs[name])))
    shown = frozenset(r for r in (found["residuals.png"],) if r is not None)
    return Answer(
        verdict(level, head, facts or ["Residuals, thresholds and events below"], label),
        tuple(sections),
        shown,
    )
